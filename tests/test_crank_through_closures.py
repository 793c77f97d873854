"""A crank that reaches the platform only through closures is held along that way.

A walking robot's ankle (a published Kangaroo leg) drives its foot by a crank, a bar to a rocker pivoted on the
shin, and a rod from the rocker to the foot. Read as a graph, the leg's path to the platform was its spanning tree's
(base, rocker, rod), on which the crank is not: the rocker's hinge, which carries the crank's whole load, was left
free as a loop beside the path, the crank passed as driving its leg, and its ITI was the rod's line against the
crank's rotation (0.982-0.989 where the crank's own transmission falls to 0.90). The crank moves inside the
four-bar crank-bar-rocker-base: refused, as the same linkage written with the crank on the tree path is
(``screwkit.io.leg_ways``). Driven at the rocker, the linkage reads the textbook values.

The linkage, in the plane y = 0, every pin along y: crank A-B, bar B-C, rocker D-C-E (C closed onto it), rod E-F,
the platform hinged to the base at G and F closed onto it; each closing hinge two connects on its axis.
"""

from __future__ import annotations

import numpy as np
import pytest

from helpers import MJCF_WORLDS, mjcf_variant, mujoco_closed, mujoco_rows, one_line_error, screwkit, sine
from screwkit.io import ImportError_, read_closed_tree
from screwkit.io.graph import graph_mechanism

A, B, C, D = (np.array(p, dtype=float) for p in ((0, 0, 0), (0.05, 0, 0.08), (0.32, 0, 0.12), (0.3, 0, 0)))
E, F, G = (np.array(p, dtype=float) for p in ((0.36, 0, 0.05), (0.62, 0, 0.15), (0.7, 0, 0)))


H1, H2, H3 = (np.array(p, dtype=float) for p in ((0.02, 0, 0.04), (0.4, 0, 0.3), (0.68, 0, 0.12)))
"""A load-free dyad's pins: on the crank, between its two links, on the platform."""


def six_bar(scale: float = 1.0, world=("0 0 0", "1 0 0 0"), crank_on_tree: bool = False,
            motor: str = "crank", from_platform: bool = False, dyad: bool = False) -> str:
    """The MJCF text, every length times ``scale``, its base placed by ``world``; ``crank_on_tree``: the rocker
    nested under the bar (the crank then on the tree path to the platform, the rocker closed onto the base);
    ``from_platform``: the rod, the rocker and the bar hung from the platform, the bar closed onto the crank and the
    rocker onto the base (the crank's closure then ends on a body whose path runs through the platform);
    ``motor``: the driven joint; ``dyad``: two links from the crank to the platform, which carry nothing (three pins
    in the plane) but make the shortest way from the crank to the platform."""
    def at(point) -> str:
        return " ".join(repr(float(v) * scale) for v in point)

    lift = np.array([0.0, 0.04, 0.0])

    def hinge(name, body1, body2, point, origin) -> str:
        return "".join(f'<connect name="{name}{k}" body1="{body1}" body2="{body2}" '
                       f'anchor="{at(point + k * lift - origin)}"/>' for k in (0, 1))

    ball = f'<geom type="sphere" size="{0.005 * scale!r}"/>'

    def joint(name) -> str:
        return f'<joint name="{name}" type="hinge" axis="0 1 0"/>{ball}'

    rod = f'<body name="rod" pos="{at(E - (C if crank_on_tree else D))}">{joint("epin")}</body>'
    if from_platform:
        bar = f'<body name="bar" pos="{at(C - E)}">{joint("cpin")}</body>'
        chain = (f'<body name="rod" pos="{at(F - G)}">{joint("fpin")}<body name="rocker" pos="{at(E - F)}">'
                 f'{joint("epin")}{bar}</body></body>')
        return ('<mujoco model="six_bar"><option><flag contact="disable"/></option><worldbody>'
                f'<body name="base" pos="{world[0]}" quat="{world[1]}"><body name="crank" pos="{at(A)}">'
                f'{joint("crank")}</body><body name="platform" pos="{at(G)}">{joint("gpin")}{chain}</body></body>'
                f'</worldbody><equality>{hinge("bpin", "crank", "bar", B, A)}'
                f'{hinge("dpin", "base", "rocker", D, 0 * D)}</equality>'
                f'<actuator><motor name="m" joint="{motor}"/></actuator></mujoco>')
    if crank_on_tree:
        rocker = f'<body name="rocker" pos="{at(C - B)}">{joint("cpin")}{rod}</body>'
        branches = (f'<body name="crank" pos="{at(A)}">{joint("crank")}<body name="bar" pos="{at(B - A)}">'
                    f'{joint("bpin")}{rocker}</body></body>')
        closures = hinge("dpin", "rocker", "base", D, C)
    else:
        links = (f'<body name="link1" pos="{at(H1 - A)}">{joint("h1pin")}<body name="link2" pos="{at(H2 - H1)}">'
                 f'{joint("h2pin")}</body></body>') if dyad else ""
        branches = (f'<body name="crank" pos="{at(A)}">{joint("crank")}<body name="bar" pos="{at(B - A)}">'
                    f'{joint("bpin")}</body>{links}</body><body name="rocker" pos="{at(D)}">{joint("rocker")}{rod}'
                    '</body>')
        closures = hinge("cpin", "bar", "rocker", C, B) + (hinge("h3pin", "link2", "platform", H3, H2) if dyad else "")
    platform = f'<body name="platform" pos="{at(G)}">{joint("gpin")}</body>'
    return ('<mujoco model="six_bar"><option><flag contact="disable"/></option><worldbody>'
            f'<body name="base" pos="{world[0]}" quat="{world[1]}">{branches}{platform}</body></worldbody>'
            f'<equality>{closures}{hinge("fpin", "rod", "platform", F, E)}</equality>'
            f'<actuator><motor name="m" joint="{motor}"/></actuator></mujoco>')


@pytest.mark.parametrize("variant", sorted(MJCF_WORLDS))
@pytest.mark.parametrize("nesting", ["rocker on the base", "crank on the tree path", "from the platform"])
def test_a_crank_driving_a_four_bar_grounded_on_the_base_is_refused_however_the_file_nests_it(
        tmp_path, variant, nesting):
    path, unit = mjcf_variant(tmp_path, f"six_bar_{nesting.split()[0]}", variant,
                              lambda s, w: six_bar(s, w, crank_on_tree=nesting == "crank on the tree path",
                                                   from_platform=nesting == "from the platform"))
    model, data, _ = mujoco_closed(path)
    assert model.nv - np.linalg.matrix_rank(mujoco_rows(model, data), tol=1e-9) == 1  # one motion, as drawn
    with pytest.raises(ImportError_, match=r"actuated joint 'crank' moves inside a loop of leg '\w+' \(with the other "
                                           r"joints of its path to the platform held it cannot move"):
        graph_mechanism(read_closed_tree(path, output="platform", length_unit=unit))


@pytest.mark.parametrize("variant", sorted(MJCF_WORLDS))
def test_a_load_free_dyad_from_the_crank_to_the_platform_does_not_make_the_crank_s_way(tmp_path, variant):
    """The dyad is the shortest way from the crank to the platform; held, it would leave the rocker free and the crank
    read as driving (ITI 0.7385, neither stage's transmission). It carries nothing (its removal leaves the leg's twist
    systems as they are): the way held is the one through the bar, the rocker and the rod, and the crank is refused as
    without the dyad."""
    path, unit = mjcf_variant(tmp_path, "six_bar_dyad", variant, lambda s, w: six_bar(s, w, dyad=True))
    model, data, _ = mujoco_closed(path)
    assert model.nv - np.linalg.matrix_rank(mujoco_rows(model, data), tol=1e-9) == 1
    with pytest.raises(ImportError_, match=r"actuated joint 'crank' moves inside a loop of leg"):
        graph_mechanism(read_closed_tree(path, output="platform", length_unit=unit))


def test_the_command_says_why_in_one_line(tmp_path):
    path = tmp_path / "six_bar.xml"
    path.write_text(six_bar())
    one_line_error(screwkit("analyze", path, "--output", "platform"), "actuated joint 'crank' moves inside a loop",
                   "--output")


@pytest.mark.parametrize("variant", sorted(MJCF_WORLDS))
def test_driven_at_the_rocker_the_linkage_reads_its_pressure_angles(tmp_path, variant):
    """The rocker on the tree path to the platform: ITI |sin(DE, EF)| (the rod's force on the rocker's pin), OTI
    |sin(EF, GF)| (on the platform's); the crank and the bar hang on the rocker, load-free."""
    path, unit = mjcf_variant(tmp_path, "rocker_driven", variant, lambda s, w: six_bar(s, w, motor="rocker"))
    model, data, anchor = mujoco_closed(path)
    rod = model.body("rod").id
    f = data.xpos[rod] + data.xmat[rod].reshape(3, 3) @ model.eq_data[model.equality("fpin0").id][:3]
    expected = sine(anchor["epin"] - anchor["rocker"], f - anchor["epin"]), sine(f - anchor["epin"], f - anchor["gpin"])
    assert expected == pytest.approx((sine(E - D, F - E), sine(F - E, F - G)), abs=1e-12)
    result = graph_mechanism(read_closed_tree(path, output="platform", length_unit=unit)).indices()
    assert (float(result.iti), float(result.lmti)) == pytest.approx(expected, abs=1e-9)


@pytest.mark.parametrize("scale", [1e-3, 1e3])
@pytest.mark.parametrize("dyad", [False, True])
def test_the_verdicts_do_not_turn_on_the_linkage_s_size(tmp_path, scale, dyad):
    """Every length times 1e-3 or 1e3, read in metres: the crank still refused, with or without the dyad; driven at
    the rocker, the same pressure angles."""
    path = tmp_path / f"six_bar_{scale}.xml"
    path.write_text(six_bar(scale, dyad=dyad))
    with pytest.raises(ImportError_, match=r"actuated joint 'crank' moves inside a loop of leg"):
        graph_mechanism(read_closed_tree(path, output="platform"))
    path.write_text(six_bar(scale, motor="rocker", dyad=dyad))
    result = graph_mechanism(read_closed_tree(path, output="platform")).indices()
    assert (float(result.iti), float(result.lmti)) == pytest.approx((sine(E - D, F - E), sine(F - E, F - G)),
                                                                    abs=1e-9)
