"""A file whose loops leave the platform no motion ("DOF 0") is refused naming the chains that lock it: those
each of which, left out, lets the others move the platform (a leg whose axes are slightly out of the plane of the
others, as a CAD export's rounding or a cambered axle writes them). And an actuator the reader guessed (the file
marks none) is said to be guessed when it is refused."""

from __future__ import annotations

import numpy as np
import pytest

from helpers import one_line_error, screwkit
from screwkit.io import ImportError_, read_mechanism_file
from screwkit.io.loader import load

BASE_PINS = [np.array([np.cos(a), np.sin(a)]) for a in np.radians([90.0, 210.0, 330.0])]
PLATFORM_PINS = [0.3 * pin for pin in BASE_PINS]
TILTS = ((1.0, 0.0), (-2.0, 2.0), (3.0, 4.0))
"""Each joint of the tilted leg: its axis turned out of z by this many times the tilt, towards this azimuth (rad)."""


def elbows() -> list[np.ndarray]:
    """Each leg's middle pin: off the line from its base pin to its platform pin by 0.25 m."""
    out = []
    for base, tip in zip(BASE_PINS, PLATFORM_PINS):
        d = tip - base
        out.append((base + tip) / 2 + 0.25 * np.array([-d[1], d[0]]) / np.linalg.norm(d))
    return out


def axes(tilted: int | None, tilt_deg: float) -> list[list[np.ndarray]]:
    """Unit joint axes per leg; the leg ``tilted`` has each of its three axes turned out of z."""
    out = []
    for k in range(3):
        leg = []
        for j in range(3):
            t = np.radians(tilt_deg) * TILTS[j][0] if k == tilted else 0.0
            leg.append(np.array([np.sin(t) * np.cos(TILTS[j][1]), np.sin(t) * np.sin(TILTS[j][1]), np.cos(t)]))
        out.append(leg)
    return out


def rrr3(tilted: int | None = None, tilt_deg: float = 3.0, scale: float = 1.0, shift=(0.0, 0.0),
         legs=(0, 1, 2)) -> tuple[str, str]:
    """A planar 3-RRR with a frame output in Gepetto's form (URDF + robot.yaml): leg 1 carries the platform, legs 2
    and 3 are welded to it ('6d'); every joint at zero closes the loops. Lengths times ``scale``, the whole
    mechanism moved by ``shift`` (m, before scaling) in the base's frame; only the legs ``legs`` (leg 1 among
    them) written."""
    shift = np.asarray(shift, dtype=float)

    def xyz(v):
        return " ".join(repr(float(scale * x)) for x in (*v, 0.0))

    links, joints = ['<link name="base"/>', '<link name="platform"/>'], []
    leg_axes = axes(tilted, tilt_deg)
    for k, (base, elbow, tip) in enumerate(zip(BASE_PINS, elbows(), PLATFORM_PINS)):
        if k not in legs:
            continue
        bodies = [f"l{k + 1}a", f"l{k + 1}b", "platform" if k == 0 else f"l{k + 1}c"]
        parents = ["base", bodies[0], bodies[1]]
        offsets = [base + shift, elbow - base, tip - elbow]
        for j, letter in enumerate("abc"):
            axis = " ".join(repr(float(v)) for v in leg_axes[k][j])
            if bodies[j] != "platform":
                links.append(f'<link name="{bodies[j]}"/>')
            joints.append(f'<joint name="leg_{k + 1}_{letter}" type="revolute"><parent link="{parents[j]}"/>'
                          f'<child link="{bodies[j]}"/><origin xyz="{xyz(offsets[j])}"/><axis xyz="{axis}"/>'
                          '<limit lower="-3" upper="3" effort="1" velocity="1"/></joint>')
        if k:
            welded(k + 1, bodies[2], xyz((0.0, 0.0)), xyz(tip - PLATFORM_PINS[0]), links, joints)
    urdf = '<robot name="rrr3">' + "".join(links) + "".join(joints) + "</robot>"
    return urdf, gepetto_yaml([k + 1 for k in legs if k], [f"leg_{k + 1}_a" for k in legs])


def welded(leg: int, body: str, at_end: str, at_platform: str, links: list, joints: list) -> None:
    """Add the frames a Gepetto '6d' closure welds: ``end_<leg>`` on the leg's last body ``body`` (at ``at_end``)
    and ``tip_<leg>`` on the platform (at ``at_platform``; URDF xyz texts)."""
    links += [f'<link name="end_{leg}"/>', f'<link name="tip_{leg}"/>']
    joints.append(f'<joint name="end_{leg}_frame" type="fixed"><parent link="{body}"/><child link="end_{leg}"/>'
                  f'<origin xyz="{at_end}"/></joint>')
    joints.append(f'<joint name="tip_{leg}_frame" type="fixed"><parent link="platform"/><child link="tip_{leg}"/>'
                  f'<origin xyz="{at_platform}"/></joint>')


def gepetto_yaml(closures: list[int], motors: list[str]) -> str:
    """The robot.yaml of legs ``closures`` welded to the platform ('6d') and the actuated joints ``motors``."""
    return (f"closed_loop: [{', '.join(f'[end_{k}, tip_{k}]' for k in closures)}]\n"
            f"type: [{', '.join('6d' for _ in closures)}]\nname_mot: [{', '.join(motors)}]\n")


def write(folder, urdf_yaml):
    (folder / "robot.urdf").write_text(urdf_yaml[0])
    (folder / "robot.yaml").write_text(urdf_yaml[1])
    return folder / "robot.urdf"


def common_motion(legs: list[int], tilted: int | None, tilt_deg: float) -> int:
    """The dimension of the twists every leg of ``legs`` allows the platform at the drawn configuration, from the
    joints' unit screws (axis, pin x axis) written here: the null space of [T_a -T_b 0; T_a 0 -T_c] (T_a of full
    column rank), with no screwkit code."""
    leg_axes = axes(tilted, tilt_deg)
    twists = []
    for k in legs:
        pins = [BASE_PINS[k], elbows()[k], PLATFORM_PINS[k]]
        twists.append(np.column_stack([np.concatenate([w, np.cross(np.append(p, 0.0), w)])
                                       for w, p in zip(leg_axes[k], pins)]))
    first, rest = twists[0], twists[1:]
    blocks = np.zeros((6 * len(rest), 3 * len(twists)))
    for r, other in enumerate(rest):
        blocks[6 * r:6 * r + 6, :3] = first
        blocks[6 * r:6 * r + 6, 3 * (r + 1):3 * (r + 2)] = -other
    singular = np.linalg.svd(blocks, compute_uv=False)
    return int(blocks.shape[1] - np.sum(singular > 1e-9))


def test_the_closed_forms_say_one_leg_locks_the_tilted_mechanism():
    """The premise, computed from the joint screws alone: untilted, the three legs share 3 twists; with leg 3's
    axes tilted, none; leg 3 left out, 3 again; leg 1 or leg 2 left out, still none."""
    assert common_motion([0, 1, 2], None, 3.0) == 3
    assert common_motion([0, 1, 2], 2, 3.0) == 0
    assert common_motion([0, 1], 2, 3.0) == 3
    assert common_motion([0, 2], 2, 3.0) == 0 and common_motion([1, 2], 2, 3.0) == 0


@pytest.mark.parametrize("tilted", [0, 1, 2])
@pytest.mark.parametrize("scale, unit, shift", [(1.0, "m", (0.0, 0.0)), (1000.0, "mm", (0.4, -0.7)),
                                                (1e-3, "km", (-2.0, 1.5))])
def test_the_leg_whose_axes_lock_the_platform_is_named(tmp_path, tilted, scale, unit, shift):
    """Whichever leg is tilted (the platform's own path, or a leg welded to it), in m, mm or km, anywhere in the
    base's frame: the refusal names that leg and its joints, and the 3 DOF the others would leave, and no other."""
    assert common_motion([k for k in range(3) if k != tilted], tilted, 3.0) == 3
    path = write(tmp_path, rrr3(tilted, scale=scale, shift=shift))
    with pytest.raises(ValueError) as refused:
        load(path, output="platform", length_unit=unit)
    message = str(refused.value)
    assert "\n" not in message
    assert "the platform cannot move" in message and "(DOF 0)" in message
    name = f"leg_{tilted + 1}"
    assert (f"without chain {name}_a (joints {name}_a, {name}_b, {name}_c) it would move (3 DOF): a loop with no "
            "motion: a structure, or a joint axis slightly out of line") in message, message
    others = [f"leg_{k + 1}_a" for k in range(3) if k != tilted]
    assert not any(other in message for other in others), message


def test_the_untilted_mechanism_opens_with_three_dof(tmp_path):
    mechanism = load(write(tmp_path, rrr3()), output="platform")
    assert mechanism.dof == 3 and len(mechanism.actuator_names) == 3


def test_a_single_loop_made_rigid_names_every_chain(tmp_path):
    """Two legs, legs 1 and 3 (leg 3 tilted): each left out, the other moves the platform, so both are named, as
    the loop they make (the premise computed from the joint screws)."""
    assert common_motion([0, 2], 2, 3.0) == 0 and common_motion([0], 2, 3.0) == 3
    path = write(tmp_path, rrr3(2, legs=(0, 2)))
    with pytest.raises(ValueError) as refused:
        load(path, output="platform")
    assert ("any one chain left out, the others would let it move (chains leg_1_a (joints leg_1_a, leg_1_b, "
            "leg_1_c), leg_3_a (joints leg_3_a, leg_3_b, leg_3_c))") in str(refused.value), str(refused.value)


def test_the_command_line_refuses_the_rigid_file_in_one_line(tmp_path):
    path = write(tmp_path, rrr3(1))
    one_line_error(screwkit("analyze", path, "--output", "platform"), "robot.urdf", "(DOF 0)",
                   "without chain leg_2_a (joints leg_2_a, leg_2_b, leg_2_c) it would move (3 DOF)")


def rr_legs(count: int):
    """``count`` planar RR legs (a base pin, an elbow pin) in Gepetto's form, leg 1 carrying the platform, the others
    welded to it ('6d'): its URDF, robot.yaml, base pins and platform points."""
    angles = np.radians(np.arange(count) * 360.0 / count + 90.0)
    base = [np.array([np.cos(a), np.sin(a)]) for a in angles]
    tip = [0.3 * b for b in base]
    def xyz(v):
        return " ".join(repr(float(x)) for x in (*v, 0.0))
    links, joints = ['<link name="base"/>', '<link name="platform"/>'], []
    for k in range(count):
        d = tip[k] - base[k]
        elbow = (base[k] + tip[k]) / 2 + 0.25 * np.array([-d[1], d[0]]) / np.linalg.norm(d)
        a, b = f"l{k + 1}a", f"l{k + 1}b"
        links += [f'<link name="{a}"/>', f'<link name="{b}"/>']
        for name, parent, child, offset in ((f"leg_{k + 1}_a", "base", a, base[k]),
                                            (f"leg_{k + 1}_b", a, b, elbow - base[k])):
            joints.append(f'<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/>'
                          f'<origin xyz="{xyz(offset)}"/><axis xyz="0 0 1"/>'
                          '<limit lower="-3" upper="3" effort="1" velocity="1"/></joint>')
        if k == 0:
            joints.append(f'<joint name="platform_frame" type="fixed"><parent link="{b}"/><child link="platform"/>'
                          f'<origin xyz="{xyz(tip[k] - elbow)}"/></joint>')
        else:
            welded(k + 1, b, xyz(tip[k] - elbow), xyz(tip[k] - tip[0]), links, joints)
    urdf = '<robot name="rr">' + "".join(links) + "".join(joints) + "</robot>"
    return urdf, gepetto_yaml(list(range(2, count + 1)), [f"leg_{k + 1}_a" for k in range(count)]), base, tip


def planar_common_motion(legs: list[list[np.ndarray]]) -> int:
    """The dimension of the plane twists (w, v_x, v_y) every leg allows, each leg's twists those of its pins (unit
    turns about z at the pins): numpy alone, as :func:`common_motion` does in space."""
    twists = [np.column_stack([[1.0, pin[1], -pin[0]] for pin in pins]) for pins in legs]
    first, rest = twists[0], twists[1:]
    blocks = np.zeros((3 * len(rest), sum(t.shape[1] for t in twists)))
    column = first.shape[1]
    for r, other in enumerate(rest):
        blocks[3 * r:3 * r + 3, :first.shape[1]] = first
        blocks[3 * r:3 * r + 3, column:column + other.shape[1]] = -other
        column += other.shape[1]
    singular = np.linalg.svd(blocks, compute_uv=False)  # (each leg's pins distinct: its twists independent)
    return int(blocks.shape[1] - np.sum(singular > 1e-9))


@pytest.mark.parametrize("count", [3, 4])
def test_rigid_legs_name_every_chain_or_none(tmp_path, count):
    """Planar RR legs: three leave the platform no motion, and any two of them one (every chain named); four leave
    it none, and any three none (no one chain locks it): the legs' common twists, numpy alone, then the refusal."""
    urdf, yaml, base, tip = rr_legs(count)
    pins = []
    for k in range(count):
        d = tip[k] - base[k]
        pins.append([base[k], (base[k] + tip[k]) / 2 + 0.25 * np.array([-d[1], d[0]]) / np.linalg.norm(d)])
    assert planar_common_motion(pins) == 0
    without = [planar_common_motion(pins[:k] + pins[k + 1:]) for k in range(count)]
    assert without == [1] * count if count == 3 else without == [0] * count
    with pytest.raises(ValueError) as refused:
        load(write(tmp_path, (urdf, yaml)), output="platform")
    message = str(refused.value)
    assert "(DOF 0)" in message
    if count == 3:
        assert "any one chain left out, the others would let it move (chains leg_1_a (joints leg_1_a, leg_1_b), " \
               "leg_2_a (joints leg_2_a, leg_2_b), leg_3_a (joints leg_3_a, leg_3_b))" in message, message
    else:
        assert message.endswith("(DOF 0); no one chain locks it: without any one of them it still cannot "
                                "move."), message


def rrp_onto_another_leg(marked: bool) -> str:
    """tests/sdformat_models.rrp_sdf with leg 2's slide closed onto leg 1's first link instead of the platform (a
    closed-loop transmission); its actuators marked or left to be guessed."""
    from sdformat_models import rrp_sdf

    text = rrp_sdf() if marked else rrp_sdf().replace("<screwkit:actuated/>", "")
    return text.replace("<parent>l2_1</parent><child>platform</child>", "<parent>l2_1</parent><child>l1_0</child>")


def test_a_guessed_actuator_that_cannot_drive_is_said_to_be_guessed(tmp_path):
    """The file marks no actuator: the reader guesses one per branch leaving the base, and the one it cannot use
    is named as guessed, with the option that names the driven joints; a marked one, as the file's; one named with
    --actuate, by the option."""
    guessed = tmp_path / "guessed.sdf"
    guessed.write_text(rrp_onto_another_leg(marked=False))
    with pytest.raises(ImportError_, match=r"guessed actuator 'r1_1' \(the file marks none; --actuate JOINT names "
                                           r"the joints that are driven\) drives through closure 'r2_1_a', which "
                                           "ends on another leg's link"):
        read_mechanism_file(guessed, output="platform")
    marked = tmp_path / "marked.sdf"
    marked.write_text(rrp_onto_another_leg(marked=True))
    with pytest.raises(ImportError_, match="actuated joint 'p_1' drives through closure"):
        read_mechanism_file(marked, output="platform")
    with pytest.raises(ImportError_, match="--actuate r1_1 drives through closure"):
        read_mechanism_file(guessed, output="platform", actuate=["r1_0", "r1_1", "r1_2"])
