"""A load-free linkage hung on a leg does not move where the leg meets the platform.

A da Vinci arm's remote-centre mechanism doubles its parallelogram: a second pair of links hangs between the first
parallelogram's rocker (or crank) and its coupler. Those two links, pinned at three points, form a dyad that
imposes nothing on the coupler and, unloaded, carries nothing (each of its links can only push along its own pin
line, and the two lines cross). Read as a graph, the dyad's pin on the coupler was averaged with the parallelogram's
into the point a leg meets the platform, which the CTI (and, with the dyad on the crank, the ITI and OTI) is taken
about: a published ECM file read CTI 0.5284 where its parallelogram's is 0.9965. A connection is left out of that
point where leaving it out changes none of the leg's twist systems (``graph_screws._loaded``).

The parallelogram here: crank A-B (driven), coupler B-C (the platform, which translates), rocker D-C; the dyad
F-G-E from the rocker (or the crank) to the coupler; every pin along y, each closure a hinge written as two
connects on its axis. Read as a graph (as the command reads it with the dyad: a leg with a loop inside), with the
dyad and without it the indices are the parallelogram's: ITI = LMTI = 1 (the coupler translates with the crank) and
CTI = |sin(BC, DC)|, from MuJoCo's placement of the pins. (Without the dyad the command reads the linkage as serial
legs, with the point where they meet as the output, by default.)
"""

from __future__ import annotations

import numpy as np
import pytest

from helpers import MJCF_WORLDS, mjcf_variant, mujoco_closed, mujoco_rows, screwkit_json, sine
from screwkit.io import ImportError_, read_closed_tree
from screwkit.io.graph import graph_mechanism

A, B, C, D = (np.array(p, dtype=float) for p in ((0, 0, 0), (0.08, 0, 0.2), (0.38, 0, 0.2), (0.3, 0, 0)))
E, G = np.array([0.25, 0.0, 0.35]), np.array([0.48, 0.0, 0.33])
"""The pins in the plane y = 0: the dyad from F (half way along the rocker or the crank) through G to E on the
coupler."""


def linkage(scale: float = 1.0, world=("0 0 0", "1 0 0 0"), dyad: str | None = "rocker",
            reverse: bool = False, rocker_lift: float = 0.0, washer: bool = False, spacing: float = 0.04,
            end=E, balls: tuple[str, ...] = ()) -> str:
    """The parallelogram's MJCF text, every length times ``scale``, its base placed by ``world``; ``dyad``: the link
    the dyad hangs from ("rocker", "crank" or None); ``reverse``: branches and closures listed the other way round;
    ``rocker_lift``: the rocker's pivot drawn that far above D (no dyad); ``washer``: a second bearing of the pin B, a
    body on the crank hinged at B and closed onto the coupler there; ``spacing``: of a closing hinge's two connects;
    ``end``: the dyad's pin on the coupler; ``balls``: pins made balls (``"bpin"``, ``"cpin"``: one connect)."""
    pivot = D + np.array([0.0, 0.0, rocker_lift])
    def at(point) -> str:
        return " ".join(repr(float(v) * scale) for v in point)

    ball = f'<geom type="sphere" size="{0.005 * scale!r}"/>'
    def joint_text(name) -> str:
        return (f'<joint name="{name}" type="ball"/>' if name in balls else
                f'<joint name="{name}" type="hinge" axis="0 1 0"/>') + ball
    start = D if dyad == "rocker" else A
    f = start + (C - D) / 2
    links = (f'<body name="link1" pos="{at(f - start)}">{joint_text("fpin")}'
             f'<body name="link2" pos="{at(G - f)}">{joint_text("gpin")}</body></body>') if dyad else ""
    crank = (f'<body name="crank" pos="{at(A)}">{joint_text("crank")}'
             + (f'<body name="washer" pos="{at(B - A)}">{joint_text("wpin")}</body>' if washer else "")
             + f'<body name="coupler" pos="{at(B - A)}">{joint_text("bpin")}</body>'
             + (links if dyad == "crank" else "") + '</body>')
    rocker = f'<body name="rocker" pos="{at(pivot)}">{joint_text("rocker")}' + (links if dyad == "rocker" else "") \
        + '</body>'
    lift = np.array([0.0, spacing, 0.0])  # the second point of each closing hinge, along its axis

    def pin(name, body1, body2, point, origin) -> list[str]:
        return [f'<connect name="{name}{k}" body1="{body1}" body2="{body2}" anchor="{at(point + k * lift - origin)}"/>'
                for k in ((0,) if name in balls else (0, 1))]

    closures = pin("cpin", "rocker", "coupler", C, pivot) + (pin("epin", "link2", "coupler", end, G) if dyad else []) \
        + (pin("wpin", "washer", "coupler", B, B) if washer else [])
    branches = [crank, rocker]
    if reverse:
        branches, closures = branches[::-1], closures[::-1]
    return ('<mujoco model="parallelogram"><option><flag contact="disable"/></option><worldbody>'
            f'<body name="base" pos="{world[0]}" quat="{world[1]}">' + "".join(branches) + '</body></worldbody>'
            '<equality>' + "".join(closures) + '</equality><actuator><motor name="m" joint="crank"/></actuator>'
            '</mujoco>')



def _mujoco_sine(path, motions: int = 1) -> float:
    """|sin(BC, DC)| from MuJoCo's placement of the pins, the linkage checked closed and of ``motions`` motions."""
    model, data, anchor = mujoco_closed(path)
    assert model.nv - np.linalg.matrix_rank(mujoco_rows(model, data), tol=1e-9) == motions
    rocker = model.body("rocker").id
    c = data.xpos[rocker] + data.xmat[rocker].reshape(3, 3) @ model.eq_data[model.equality("cpin0").id][:3]
    return sine(c - anchor["bpin"], c - anchor["rocker"])


@pytest.mark.parametrize("variant", sorted(MJCF_WORLDS))
@pytest.mark.parametrize("dyad", [None, "rocker", "crank"])
def test_an_idle_dyad_leaves_the_parallelograms_indices(tmp_path, variant, dyad):
    path, unit = mjcf_variant(tmp_path, f"para_{dyad}", variant, lambda s, w: linkage(s, w, dyad=dyad))
    expected = _mujoco_sine(path)
    assert expected == pytest.approx(sine(C - B, C - D), abs=1e-12)
    result = graph_mechanism(read_closed_tree(path, output="coupler", length_unit=unit)).indices()
    assert (float(result.iti), float(result.lmti)) == pytest.approx((1.0, 1.0), abs=1e-9)
    assert float(result.cti) == pytest.approx(expected, abs=1e-9)


@pytest.mark.parametrize("dyad", ["rocker", "crank"])
def test_the_reading_does_not_turn_on_the_order_the_file_lists_things_in(tmp_path, dyad):
    path = tmp_path / "reversed.xml"
    path.write_text(linkage(dyad=dyad, reverse=True))
    result = graph_mechanism(read_closed_tree(path, output="coupler")).indices()
    assert (float(result.iti), float(result.lmti), float(result.cti)) == pytest.approx(
        (1.0, 1.0, sine(C - B, C - D)), abs=1e-9)


def test_the_command_reads_the_doubled_parallelogram(tmp_path):
    path = tmp_path / "doubled.xml"
    path.write_text(linkage(dyad="crank"))
    result = screwkit_json("analyze", path, "--output", "coupler")
    assert (result["iti"], result["lmti"], result["cti"]) == pytest.approx((1.0, 1.0, sine(C - B, C - D)),
                                                                           abs=1e-9)


def test_the_dyad_taken_as_the_output_is_refused_with_the_loop_through_the_cranks_path(tmp_path):
    """With the dyad's end link as the output, the parallelogram's loop closes on the base through the crank's path:
    held along that path, the crank cannot move (the reason, and the way out, of an excavator's bucket). The refusal
    said instead that the crank's twist is no motion of its leg, "the leg has no serial input", of a crank on the
    base (a published da Vinci PSM with its instrument's link as the output was refused so)."""
    path = tmp_path / "doubled.xml"
    path.write_text(linkage(dyad="crank"))
    with pytest.raises(ImportError_, match="'crank' moves inside a loop of leg 'crank' \\(with the other joints of its "
                                           "path to the platform held it cannot move"):
        graph_mechanism(read_closed_tree(path, output="link2"))


@pytest.mark.parametrize("world", [("0 0 0", "1 0 0 0"), ("0.3 -0.2 0.5", "0.8 0.3 -0.4 0.2"),
                                   ("0 0 0", "0.9 0.2 0.3 0.25")])
def test_a_nearly_translating_coupler_takes_a_translation_as_its_coordinate_in_any_world(tmp_path, world):
    """The rocker's pivot drawn 0.1 mm off the parallelogram's (a file's rounding): the coupler turns 1e-3 rad a unit
    of its translation. In a turned world its translation moves each of x, y and z less than 0.71 length scales a
    unit, and the pitch it barely turns was taken as its task coordinate (a published ECM in a turned world): the
    translations are now judged on all three at once, which no turn of the world changes."""
    path = tmp_path / "slanted.xml"
    path.write_text(linkage(world=world, dyad=None, rocker_lift=1e-4))
    graph = graph_mechanism(read_closed_tree(path, output="coupler"))
    assert graph.task_coordinates[0] in ("x", "y", "z"), graph.task_coordinates


@pytest.mark.parametrize("variant", sorted(MJCF_WORLDS))
def test_a_second_bearing_of_a_pin_beside_the_dyad_leaves_the_dyad_out(tmp_path, variant):
    """A second bearing of the pin B (a washer on the crank, closed onto the coupler at B: MuJoCo gives it an idle
    spin of its own) backs the first up: each is idle beside the other, neither alone. It once cancelled every
    connection's leaving out, the dyad's too, and the crank's dyad came back into the points: ITI 0.998, LMTI 0.997.
    The two bearings are kept (they meet the coupler at one point), the dyad left out."""
    path, unit = mjcf_variant(tmp_path, "washer", variant, lambda s, w: linkage(s, w, dyad="crank", washer=True))
    expected = _mujoco_sine(path, motions=2)  # (the washer's own spin)
    result = graph_mechanism(read_closed_tree(path, output="coupler", length_unit=unit)).indices()
    assert (float(result.iti), float(result.lmti), float(result.cti)) == pytest.approx((1.0, 1.0, expected), abs=1e-9)


@pytest.mark.parametrize("dyad", [None, "rocker"])
def test_a_hinge_written_as_two_connects_reads_the_same_whatever_their_spacing(tmp_path, dyad):
    """Each closing hinge is two connects on its axis; the point where a leg meets the coupler averaged both, so the
    CTI moved with their spacing (a rocker on a ball at its pivot read 0.9285 to 0.8802 as they went 1 mm to 0.4 apart)
    though MuJoCo's mechanism is the same. It is now the foot on the hinge's axis from the leg's joints."""
    values = []
    for spacing, reverse in ((0.001, False), (0.04, False), (0.4, False), (0.4, True)):
        path = tmp_path / f"spaced_{spacing}_{reverse}.xml"
        text = linkage(dyad=dyad, spacing=spacing, reverse=reverse)
        path.write_text(text.replace('<joint name="rocker" type="hinge" axis="0 1 0"/>', '<joint name="rocker" '
                                     'type="ball"/>') if dyad is None else text)
        assert _mujoco_sine(path) == pytest.approx(sine(C - B, C - D), abs=1e-12)
        result = graph_mechanism(read_closed_tree(path, output="coupler")).indices()
        values.append((float(result.iti), float(result.lmti), float(result.cti)))
    for value in values:
        assert value == pytest.approx((1.0, 1.0, sine(C - B, C - D)), abs=1e-9)


@pytest.mark.parametrize("factor", [1e-3, 1e3])
def test_the_dyad_is_left_out_for_the_linkage_scaled_and_its_joints_renamed(tmp_path, factor):
    """Every length times 1e-3 or 1e3, read in metres (a mechanism that much smaller or larger), and every joint and
    the actuator renamed: the same indices, the actuator's under its new name."""
    path = tmp_path / "scaled.xml"
    text = linkage(scale=factor, dyad="crank")
    for name in ("crank", "bpin", "rocker", "fpin", "gpin"):
        text = text.replace(f'joint name="{name}"', f'joint name="{name}_renamed"').replace(
            f'joint="{name}"', f'joint="{name}_renamed"')
    path.write_text(text)
    mechanism = graph_mechanism(read_closed_tree(path, output="coupler"))
    result = mechanism.indices()
    assert mechanism.actuators == ("crank:crank_renamed",)
    assert (float(result.iti), float(result.lmti), float(result.cti)) == pytest.approx(
        (1.0, 1.0, sine(C - B, C - D)), abs=1e-9)


DYAD_ENDS = (E, np.array([0.45, 0.0, 0.3]), np.array([0.6, 0.0, 0.25]))
"""Where the dyad's pin on the coupler may be drawn: it carries none of the in-plane load at any of them."""


@pytest.mark.parametrize("variant", sorted(MJCF_WORLDS))
@pytest.mark.parametrize("dyad, ball", [("rocker", "cpin"), ("crank", "bpin")])
def test_a_dyad_carrying_only_what_every_leg_holds_is_left_out(tmp_path, variant, dyad, ball):
    """A pin of the parallelogram made a ball (the rocker closed on the coupler by one connect, or the coupler on a
    ball at B): the dyad beside it then holds the coupler's out-of-plane turns about that ball, and leaving it out
    changes the leg's twist system, so it was kept and averaged into where the leg meets the coupler. But the other
    leg holds those turns too: they are wrenches every leg holds, which no index releases, and the in-plane load
    (the rocker's force along DC, the crank's drive) enters at the ball alone, the dyad's two links pushing only along
    their own pin lines. With the dyad's pin drawn at three places, its CTI read 0.8461 to 0.8713 on the rocker, and
    its ITI 0.978 to 0.996 and LMTI 0.962 to 0.993 on the crank, for the parallelogram's 1, 1 and |sin(BC, DC)|.
    A connection now counts only where leaving it out frees the leg a twist some leg allows."""
    for k, end in enumerate(DYAD_ENDS):
        path, unit = mjcf_variant(tmp_path, f"{ball}_{k}", variant,
                                  lambda s, w, end=end: linkage(s, w, dyad=dyad, end=end, balls=(ball,)))
        expected = _mujoco_sine(path)
        result = graph_mechanism(read_closed_tree(path, output="coupler", length_unit=unit)).indices()
        assert (float(result.iti), float(result.lmti), float(result.cti)) == pytest.approx((1.0, 1.0, expected),
                                                                                             abs=1e-9)


@pytest.mark.parametrize("dyad, ball", [("rocker", "cpin"), ("crank", "bpin")])
def test_the_dyad_beside_a_ball_is_left_out_whatever_the_order_and_size(tmp_path, dyad, ball):
    """The same listed the other way round, and every length times 1e-3 and 1e3 read in metres."""
    for k, (scale, reverse) in enumerate(((1.0, True), (1e-3, False), (1e3, True))):
        path = tmp_path / f"{ball}_{k}.xml"
        path.write_text(linkage(scale, dyad=dyad, end=DYAD_ENDS[2], balls=(ball,), reverse=reverse))
        result = graph_mechanism(read_closed_tree(path, output="coupler")).indices()
        assert (float(result.iti), float(result.lmti), float(result.cti)) == pytest.approx(
            (1.0, 1.0, sine(C - B, C - D)), abs=1e-9)
