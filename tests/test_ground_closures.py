"""A four-bar written as one serial chain closed onto the fixed base, as physics-engine files write it (a published
MuJoCo four-bar: crank, coupler and rocker nested, the rocker's far end ``<connect>``-ed to the ground body).

With the rocker as output, its leg is the closure's pin alone, on the base; the crank chain reaches it through the
coupler. Checked against the four-bar's transmission angles at several rocker angles, in millimetres and in a turned
and shifted world; the same loop closed by a ``<weld>`` is rigid and said so; with the coupler as output, the output
is the coupler's pin to the rocker, which turns with the rocker."""

from __future__ import annotations

import json

import numpy as np
import pytest

from helpers import screwkit
from screwkit.closure import solve
from screwkit.io import ImportError_, read_mechanism_file
from screwkit.io.loader import load
from screwkit.studies import indices_at_poses
from screwkit.studies.poses import analyze_solution

A, B, C, D = (np.array(p) for p in ((0.0, 0.0), (0.0513, 0.141), (0.35, 0.3), (0.4, 0.0)))
"""The ground pivots A (crank) and D (rocker), the crank-coupler pin B, the coupler-rocker pin C (m, as drawn)."""


def four_bar_mjcf(scale: float = 1.0, yaw: float = 0.0, shift=(0.0, 0.0, 0.0), closure: str = "connect") -> str:
    """Crank (hinge_1 at A), coupler (hinge_2 at B), rocker (hinge_3 at C) nested on the ground body; the rocker
    pinned to the ground at D by a ``closure`` (``connect``, or ``weld``: rigid). The ground body is turned by
    ``yaw`` about z and shifted by ``shift`` (m) in the world."""

    def at(point):
        return " ".join(repr(float(v)) for v in scale * np.array([*point, 0.0]))

    rocker_end = f'<site name="rocker_end" pos="{at(D - C)}"/>'
    joint = '<joint name="{}" type="hinge" axis="0 0 1"/><geom type="sphere" size="0.01"/>'
    closing = (f'<connect name="pin_D" body1="ground" body2="rocker" anchor="{at(D)}"/>' if closure == "connect"
               else '<weld name="pin_D" body1="ground" body2="rocker"/>')
    return (f'<mujoco model="four_bar"><compiler angle="radian"/><worldbody>'
            f'<body name="ground" pos="{" ".join(repr(scale * v) for v in shift)}" euler="0 0 {yaw!r}">'
            f'<body name="crank" pos="{at(A)}">{joint.format("hinge_1")}'
            f'<body name="coupler" pos="{at(B - A)}">{joint.format("hinge_2")}'
            f'<body name="rocker" pos="{at(C - B)}">{joint.format("hinge_3")}{rocker_end}'
            f'</body></body></body></body></worldbody><equality>{closing}</equality>'
            '<actuator><motor joint="hinge_1"/><motor joint="hinge_2"/></actuator></mujoco>')


def arm(point, through, direction) -> float:
    """The distance from ``point`` to the line through ``through`` along ``direction`` (plane)."""
    u = direction / np.linalg.norm(direction)
    r = point - through
    return abs(r[0] * u[1] - r[1] * u[0])


def expected(theta: float) -> dict:
    """The four-bar's transmission at rocker angle ``theta`` (rad from the drawing), on the branch drawn: crank
    actuated, the wrench is a force along the coupler BC; coupler-crank pin actuated, a force along AC. Each ITI is
    its arm about the actuated pin over the length of the link it drives, each OTI its arm about D over the rocker."""
    turn = np.array([[np.cos(theta), -np.sin(theta)], [np.sin(theta), np.cos(theta)]])
    c = D + turn @ (C - D)
    crank, coupler = np.linalg.norm(B - A), np.linalg.norm(C - B)
    gap = np.linalg.norm(c - A)
    along = (crank**2 - coupler**2 + gap**2) / (2.0 * gap)
    across = np.sqrt(crank**2 - along**2)
    unit = (c - A) / gap
    normal = np.array([-unit[1], unit[0]])
    b = min((A + along * unit + s * across * normal for s in (1.0, -1.0)), key=lambda p: np.linalg.norm(p - B))
    rocker = np.linalg.norm(c - D)
    iti = [arm(A, b, c - b) / crank, arm(b, A, c - A) / coupler]
    oti = [arm(D, b, c - b) / rocker, arm(D, A, c - A) / rocker]
    return {"iti": iti, "oti": oti, "lmti": max(oti), "f_o1": min(oti)}


def assert_transmission(result, row: int, theta: float) -> None:
    """Row ``row`` of ``result`` holds the four-bar's ITIs, LMTI and F_O1 at rocker angle ``theta``."""
    values = expected(theta)
    np.testing.assert_allclose(result.iti_actuators[row], values["iti"], atol=1e-9)
    assert result.lmti[row] == pytest.approx(values["lmti"], abs=1e-9)
    assert result.f_o[1][row] == pytest.approx(values["f_o1"], abs=1e-9)


ANGLES = np.radians([0.0, 8.0, -5.0, 20.0])  # the rocker reaches -6.18 to 53.7 deg


UNITS = {1.0: None, 1000.0: "mm", 1e-3: "km"}
"""The unit a file written ``scale`` times larger than in metres is in: the same mechanism read back."""


@pytest.mark.parametrize("scale, yaw, shift", [(1.0, 0.0, (0.0, 0.0, 0.0)), (1000.0, 0.9, (0.3, -0.2, 1.5)),
                                               (1e-3, -0.6, (2.0, 1.0, -0.5))])
def test_a_four_bar_pinned_to_the_ground_by_its_closure_has_the_transmission_angles(tmp_path, scale, yaw, shift):
    """Refused before: "closure 'pin_D' ties the platform to the fixed base: no leg"."""
    path = tmp_path / "four_bar.xml"
    path.write_text(four_bar_mjcf(scale, yaw, shift))
    mechanism = load(path, output="rocker", length_unit=UNITS[scale])
    assert mechanism.dof == 1 and mechanism.task_coordinates == ("phi",)
    assert mechanism.output_point is None  # the rocker turns about the ground pin: its frame, not that fixed point
    _, report = read_mechanism_file(path, output="rocker")
    assert any(chain.startswith("pin_D: no joint but its loop, loop revolute (closure pin_D)")
               for chain in report.chains)
    assert [name.split(":")[1] for name in mechanism.actuator_names] == ["hinge_1", "hinge_2"]
    poses = mechanism.home_pose + ANGLES[:, None]
    assert solve(mechanism, poses).reachable.all()
    result = indices_at_poses(mechanism, poses, detail=True)
    for row, theta in enumerate(ANGLES):
        assert_transmission(result, row, theta)


def test_the_loop_welded_to_the_ground_is_rigid(tmp_path):
    welded = tmp_path / "welded.xml"
    welded.write_text(four_bar_mjcf(closure="weld"))
    with pytest.raises(ImportError_, match="closure 'pin_D' welds the platform to the fixed base: it cannot move"):
        read_mechanism_file(welded, output="rocker")
    with pytest.raises(ValueError, match="cannot move"):  # the coupler: its legs leave it no motion (DOF 0)
        load(welded, output="coupler")


@pytest.mark.parametrize("scale, yaw, shift", [(1.0, 0.0, (0.0, 0.0, 0.0)), (1000.0, -2.2, (-0.4, 0.7, 0.1)),
                                               (1e-3, 2.5, (0.5, -3.0, 0.2))])  # (at yaws -1, -0.6, 0.4 and
# 1.3 the pin's plane x is nearer its extremum: a step of 0.03 m passes the rocker's reach, whatever the unit)
def test_the_coupler_s_pin_to_the_rocker_moves_as_the_rocker_turns(tmp_path, scale, yaw, shift):
    """With the coupler as output, the rocker's leg is the ground pin, then its joint onto the coupler, its loop
    joint (refused before: "ends on joints hinge_3 beyond the platform"). Its output is the pin C where the legs meet
    (the coupler's turning about it idle): C turns about D with the rocker, so each index is the rocker's, at the
    rocker angle C's position gives."""
    path = tmp_path / "four_bar.xml"
    path.write_text(four_bar_mjcf(scale, yaw, shift))
    mechanism = load(path, output="coupler", length_unit=UNITS[scale])
    assert mechanism.dof == 1 and mechanism.output_point is not None
    _, report = read_mechanism_file(path, output="coupler")
    assert "pin_D: joints pin_D, loop revolute (closure pin_D)" in report.chains
    steps = np.array([0.0, 0.01, -0.005, 0.03])[:, None]
    solution = solve(mechanism, mechanism.home_pose + steps)
    assert solution.reachable.all()
    result = indices_at_poses(mechanism, mechanism.home_pose + steps, detail=True)
    turn = np.array([[np.cos(yaw), -np.sin(yaw)], [np.sin(yaw), np.cos(yaw)]])
    pivot = np.asarray(shift[:2]) + turn @ D  # D in the world, in m whatever the file's unit
    start = None
    for row, full in enumerate(solution.full_poses):
        point = (mechanism.rotation_world_base @ np.array([full[0], full[1], 0.0]) + mechanism.translation_world_base)
        arm = point[:2] - pivot
        start = arm if start is None else start
        assert_transmission(result, row, np.arctan2(start[0] * arm[1] - start[1] * arm[0], start @ arm))


def test_the_command_analyses_the_rocker_as_the_file_is_written(tmp_path):
    path = tmp_path / "four_bar.xml"
    path.write_text(four_bar_mjcf())
    analysed = screwkit("analyze", path, "--output", "rocker", "--pose", "20", "--json")  # deg
    assert analysed.returncode == 0, analysed.stderr
    values, found = expected(ANGLES[3]), json.loads(analysed.stdout)
    assert found["lmti"] == pytest.approx(values["lmti"], abs=1e-9)
    assert found["iti"] == pytest.approx(min(values["iti"]), abs=1e-9)


CENTRE = np.array([0.0, 0.0, 0.5])
FEET = np.array([[0.6 * np.cos(a), 0.6 * np.sin(a), 0.0] for a in np.radians([0.0, 120.0, 240.0])])
HEADS = CENTRE + np.array([[0.25 * np.cos(a), 0.25 * np.sin(a), 0.05] for a in np.radians([40.0, 160.0, 280.0])])


def spherical_mjcf(scale: float = 1.0) -> str:
    """A spherical 3-UPS/S manipulator: three U-P-S legs from FEET to HEADS (the first carries the platform through
    three hinges at its head, the others ``<connect>``-ed to it) and the platform's centre ``<connect>``-ed to the
    ground body: a ball from the base straight onto the platform."""

    def at(vector):
        return " ".join(repr(float(v)) for v in scale * np.asarray(vector))

    legs = []
    for i, (foot, head) in enumerate(zip(FEET, HEADS), start=1):
        along = (head - foot) / np.linalg.norm(head - foot)
        hinges = "".join(f'<joint name="b{axis}_1" type="hinge" axis="{direction}" pos="{at(head - CENTRE)}"/>'
                         for axis, direction in (("x", "1 0 0"), ("y", "0 1 0"), ("z", "0 0 1")))
        end = (f'<body name="platform" pos="{at(CENTRE - foot)}">{hinges}<geom type="sphere" size="0.02"/></body>'
               if i == 1 else "")
        legs.append(f'<body name="leg_{i}" pos="{at(foot)}"><joint name="ux_{i}" type="hinge" axis="1 0 0"/>'
                    f'<joint name="uy_{i}" type="hinge" axis="0 1 0"/><geom type="sphere" size="0.01"/>'
                    f'<body name="rod_{i}"><joint name="slide_{i}" type="slide" axis="{at(along / scale)}"/>'
                    f'<geom type="sphere" size="0.01"/>{end}</body></body>')
    closures = "".join(f'<connect name="head_{i}" body1="rod_{i}" body2="platform" '
                       f'anchor="{at(HEADS[i - 1] - FEET[i - 1])}"/>' for i in (2, 3))
    closures += f'<connect name="centre" body1="ground" body2="platform" anchor="{at(CENTRE)}"/>'
    motors = "".join(f'<motor joint="slide_{i}"/>' for i in (1, 2, 3))
    return (f'<mujoco model="spherical"><compiler angle="radian"/><worldbody><body name="ground">{"".join(legs)}'
            f'</body></worldbody><equality>{closures}</equality><actuator>{motors}</actuator></mujoco>')


@pytest.mark.parametrize("scale", [1.0, 1000.0, 1e-3])
def test_a_platform_on_a_ball_closed_onto_the_base_turns_about_it_with_the_leg_lines_transmission(tmp_path, scale):
    """The centre's ball is a leg of its loop joint alone; the platform turns about it (3 DOF), and each slide's OTI
    is the cosine between its leg line and the velocity of its head under the rotation the other two legs' lines
    allow (about the centre, reciprocal to both)."""
    from scipy.spatial.transform import Rotation

    path = tmp_path / "spherical.xml"
    path.write_text(spherical_mjcf(scale))
    mechanism = load(path, output="platform", length_unit=UNITS[scale])
    assert mechanism.dof == 3 and mechanism.task_coordinates == ("roll", "pitch", "yaw")
    poses = mechanism.home_pose + np.radians([[0.0, 0.0, 0.0], [4.0, -3.0, 6.0], [-5.0, 2.0, -8.0]])
    solution = solve(mechanism, poses)
    assert solution.reachable.all()
    result = analyze_solution(mechanism, solution, detail=True)
    for row, full in enumerate(solution.full_poses):
        turned = Rotation.from_euler("xyz", full[3:]).as_matrix()  # roll, pitch, yaw about the fixed x, y, z
        heads = CENTRE + (HEADS - CENTRE) @ turned.T
        lines = (heads - FEET) / np.linalg.norm(heads - FEET, axis=1)[:, None]
        moments = np.cross(heads - CENTRE, lines)
        expected = []
        for i in range(3):
            j, k = (m for m in range(3) if m != i)
            velocity = np.cross(np.cross(moments[j], moments[k]), heads[i] - CENTRE)
            expected.append(abs(lines[i] @ velocity) / np.linalg.norm(velocity))
        np.testing.assert_allclose(result.at(row).oti_actuators[0], expected, atol=1e-9)
        np.testing.assert_allclose(result.iti_actuators[row], 1.0, atol=1e-9)


def test_a_ball_on_the_base_then_a_hinge_onto_a_spatial_platform_is_refused_in_one_line(tmp_path):
    """The pin and joint of a planar four-bar's rocker are read; a ball's three rotations and a joint, in space, are
    not (never checked against a closed form): refused naming the closure, not read silently."""
    knob = ('<body name="knob"><joint name="knob_hinge" type="hinge" axis="0 0 1" pos="0 0 0"/>'
            '<geom type="sphere" size="0.01"/></body>')
    text = spherical_mjcf().replace('<geom type="sphere" size="0.02"/></body>', '<geom type="sphere" size="0.02"/>'
                                    + knob + "</body>").replace('body1="ground" body2="platform"',
                                                                'body1="ground" body2="knob"')
    path = tmp_path / "knob.xml"
    path.write_text(text)
    with pytest.raises(ImportError_, match="closure 'centre' .3d. joins the fixed base to a body beyond the platform: "
                                           "screwkit reads that leg .* in a planar mechanism only"):
        read_mechanism_file(path, output="platform")


def test_the_four_bar_s_actuators_renamed_and_listed_the_other_way_name_the_same_worst_fault(tmp_path):
    """The crank's pin and the coupler's, renamed so that their order by name is the other way, their motors listed in
    reverse: the same indices, each ITI with its actuator, and the worst fault the same physical actuator."""
    plain = tmp_path / "plain.xml"
    plain.write_text(four_bar_mjcf())
    text = four_bar_mjcf().replace("hinge_1", "z_crank").replace("hinge_2", "a_coupler_pin")
    text = text.replace('<motor joint="z_crank"/><motor joint="a_coupler_pin"/>',
                        '<motor joint="a_coupler_pin"/><motor joint="z_crank"/>')
    renamed = tmp_path / "renamed.xml"
    renamed.write_text(text)
    first, second = load(plain, output="rocker"), load(renamed, output="rocker")
    poses = first.home_pose + ANGLES[:, None]
    before, after = (indices_at_poses(m, poses, detail=True) for m in (first, second))
    names = {"hinge_1": "z_crank", "hinge_2": "a_coupler_pin"}
    order = [[name.split(":")[1] for name in second.actuator_names].index(names[name.split(":")[1]])
             for name in first.actuator_names]
    np.testing.assert_allclose(after.iti_actuators[:, order], before.iti_actuators, atol=1e-12)
    np.testing.assert_allclose(after.lmti, before.lmti, atol=1e-12)
    np.testing.assert_allclose(after.f_o[1], before.f_o[1], atol=1e-12)
    for row in range(len(ANGLES)):
        assert [names[name.split(":")[1]] for name in before.at(row).worst_faults[1]] == \
            [name.split(":")[1] for name in after.at(row).worst_faults[1]]


def test_mujoco_reads_the_test_files_as_the_closed_forms_assume():
    """The closed forms above take the four-bar's pins at A, B, C, closed at D, and the 3-UPS/S closed at its drawing;
    MuJoCo's own reading of the same files: its joint anchors there (in the turned, shifted world), every connect
    closed (constraint residual 0) at the file's configuration."""
    import mujoco

    yaw, shift = 0.9, (0.3, -0.2, 1.5)
    turn = np.array([[np.cos(yaw), -np.sin(yaw), 0.0], [np.sin(yaw), np.cos(yaw), 0.0], [0.0, 0.0, 1.0]])
    for text, anchors in ((four_bar_mjcf(1.0, yaw, shift), [turn @ [*p, 0.0] + shift for p in (A, B, C)]),
                          (spherical_mjcf(), None)):
        model = mujoco.MjModel.from_xml_string(text)
        data = mujoco.MjData(model)
        mujoco.mj_forward(model, data)
        assert data.nefc > 0 and np.abs(data.efc_pos).max() <= 1e-12
        if anchors is not None:
            np.testing.assert_allclose(data.xanchor, anchors, atol=1e-12)
            pin = np.array(model.eq("pin_D").data[:3])  # on the ground body, in its frame
            np.testing.assert_allclose(turn @ pin + shift, turn @ [*D, 0.0] + shift, atol=1e-12)
