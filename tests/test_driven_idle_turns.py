"""A leg whose closure joins a servo horn to the thigh: the point where the legs meet is on the horn's circle.

The leg (a published rat robot's, NeRmo's, written small here): a hip motor, a knee and an ankle hinge carry the thigh;
a servo's horn is pinned to the thigh by a ``<connect>``. MuJoCo leaves the leg 2 DOF (4 hinges, a connect of rank
2) for its 2 motors. Taken by default as the output, the point where the legs meet is a point of the horn: it moves
on a circle whatever the hip does, and the hip motor's motion, the thigh turning about that point, was counted as
the point output's idle turn. The published leg read "2 actuators, 1 DOF (1 redundant)", F_O1 0.2435, where it
has no redundancy.

Now the idle turns of a point output are checked: free with every actuator held, at the reference assembly and at
closed configurations a step away along each platform motion (the pin drawn on the line of the knee and the ankle,
where the held leg frees the turn to first order, hid it). Where an actuator drives them, a file whose output type
is left to screwkit is read with the frame of the body the closure joins instead, and a point output asked for is
refused: read at the point, the hip alone held it with the servo failed (F_O1 0.9877), where MuJoCo leaves the
point a motion with the servo free and the hip held. A five-bar whose platform turns freely on the pin where its
legs meet keeps its point output and the textbook pressure angles.

The frame reading's indices are the leg's pressure angles as MuJoCo places its joints: the
hip drives the thigh through the lower link, whose line K-A carries its force (ITI = |sin| of upper link to lower
link; with the servo held the thigh turns about the horn's pin P, so OTI = |sin| of the line K-A to the line P-A);
the servo's force through P normal to the horn (ITI = OTI = 1).
"""

from __future__ import annotations

import json
from pathlib import Path

import mujoco
import numpy as np
import pytest

from helpers import MJCF_WORLDS, mjcf_variant, mujoco_rows, one_line_error, screwkit
from screwkit.closure.forward_kinematics import forward
from screwkit.io.loader import load
from screwkit.studies import indices_at_pose

PIN = np.array([0.1, 0.11, 0.0])
"""The horn's pin on the thigh, in the world at the file's configuration."""


def leg_mjcf(scale: float = 1.0, world=("0 0 0", "1 0 0 0"), pin=(0.04, -0.01), reverse: bool = False,
             thigh_first: bool = False) -> str:
    """The leg's MJCF text, every length times ``scale``, its base placed by ``world`` (``pos``, ``quat`` texts), the
    pin at ``pin`` on the horn (from its pivot); ``reverse``: the horn's branch and the servo's motor written first;
    ``thigh_first``: the connect written from the thigh (its anchor on the thigh)."""
    def at(*values) -> str:
        return " ".join(repr(v * scale) for v in values)

    ball = f'<geom type="sphere" size="{0.005 * scale!r}"/>'
    branches = [f'<body name="upper"><joint name="hip" type="hinge" axis="0 0 1"/>{ball}'
                f'<body name="lower" pos="{at(0.1, -0.02, 0)}"><joint name="knee" type="hinge" axis="0 0 1"/>{ball}'
                f'<body name="thigh" pos="{at(0.03, 0.09, 0)}"><joint name="ankle" type="hinge" axis="0 0 1"/>{ball}'
                '</body></body></body>',
                f'<body name="horn" pos="{at(0.06, 0.12, 0)}"><joint name="servo" type="hinge" axis="0 0 1"/>{ball}'
                '</body>']
    motors = ['<motor name="m1" joint="hip"/>', '<motor name="m2" joint="servo"/>']
    if reverse:
        branches, motors = branches[::-1], motors[::-1]
    return (f'<mujoco model="horn_leg"><worldbody><body name="base" pos="{world[0]}" quat="{world[1]}">'
            + "".join(branches) + '</body></worldbody><equality>'
            + (f'<connect name="pin" body1="thigh" body2="horn" anchor="{at(pin[0] - 0.07, pin[1] + 0.05, 0)}"/>'
               if thigh_first else f'<connect name="pin" body1="horn" body2="thigh" anchor="{at(*pin, 0)}"/>')
            + '</equality>'
            '<actuator>' + "".join(motors) + '</actuator></mujoco>')


@pytest.fixture(params=sorted(MJCF_WORLDS))
def leg(request, tmp_path):
    return mjcf_variant(tmp_path, "leg", request.param, leg_mjcf)


def _mujoco_indices(path: Path, values: dict[str, float]) -> tuple[float, float]:
    """The hip's ITI and OTI from MuJoCo's placement of the joints at joint ``values`` (rad), the connect closed."""
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    for name, value in values.items():
        data.qpos[model.jnt_qposadr[model.joint(name).id]] = value
    mujoco.mj_forward(model, data)
    assert np.abs(data.efc_pos).max() < 1e-9 * (1.0 + np.abs(data.xpos).max())  # the loop closed where screwkit put it
    anchor = {name: data.xanchor[model.joint(name).id] for name in ("hip", "knee", "ankle")}
    pin = data.xpos[model.body("horn").id] + data.xmat[model.body("horn").id].reshape(3, 3) @ model.eq_data[0][:3]

    def sine(u, v):
        return float(np.linalg.norm(np.cross(u, v)) / (np.linalg.norm(u) * np.linalg.norm(v)))

    lower = anchor["ankle"] - anchor["knee"]
    return sine(anchor["knee"] - anchor["hip"], lower), sine(lower, anchor["ankle"] - pin)


def test_mujoco_leaves_the_leg_two_motions(tmp_path):
    path = tmp_path / "leg.xml"
    path.write_text(leg_mjcf())
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    jacobian = mujoco_rows(model, data)
    assert model.nv - np.linalg.matrix_rank(jacobian, tol=1e-9) == 2
    assert np.linalg.norm(data.xpos[model.body("horn").id] + model.eq_data[0][:3] - PIN) < 1e-15


def test_the_leg_reads_two_dof_and_its_pressure_angles(leg):
    path, unit = leg
    mechanism = load(path, length_unit=unit)
    assert mechanism.dof == 2 and len(mechanism.actuators) == 2
    assert mechanism.output_point is None
    assert any("not the point where the legs meet" in line for line in mechanism.import_report)
    home = indices_at_pose(mechanism, mechanism.home_pose)
    assert dict(home.f_o) == {1: 0.0}  # no redundancy: one failure leaves the platform uncontrolled
    for change in ((0.0, 0.0), (0.15, -0.1), (-0.08, 0.09)):
        start = np.array([home.joint_values[name] for name in ("hip:hip", "servo:servo")])
        solution = forward(mechanism, start + np.array(change), mechanism.home_pose)  # (rad)
        assert bool(np.ravel(solution.reachable)[0])
        result = indices_at_pose(mechanism, np.ravel(solution.poses))
        values = {name.split(":")[1]: value for name, value in result.joint_values.items()
                  if name.split(":")[1] in ("hip", "knee", "ankle", "servo")}  # (not the converted loop joints)
        iti, oti = _mujoco_indices(path, values)
        assert float(result.iti) == pytest.approx(iti, abs=1e-9)  # the servo's is 1
        assert float(result.lmti) == pytest.approx(oti, abs=1e-9)  # the servo's OTI is 1


def test_a_point_output_asked_for_is_refused(leg):
    path, unit = leg
    with pytest.raises(ValueError, match="an actuator turns the platform about the output point .*\\(--output-type "
                                         "frame"):
        load(path, length_unit=unit, output="thigh", output_type="point")
    model = mujoco.MjModel.from_xml_path(str(path))  # the servo failed (free) and the hip held: the pin still moves
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    free = [model.jnt_dofadr[model.joint(name).id] for name in ("knee", "ankle", "servo")]
    rows = mujoco_rows(model, data)[:, free]
    assert len(free) - np.linalg.matrix_rank(rows, tol=1e-9) == 1


@pytest.mark.parametrize("off", [0.0, 1e-6])
def test_a_pin_on_the_line_of_knee_and_ankle_does_not_hide_the_driven_turn(tmp_path, off):
    """The pin on the line through the knee K and the ankle A (A + (K->A)/2 = (0.145, 0.115), 0.085 and -0.005 from
    the horn's pivot): with both motors held the thigh turns about it to first order, so at the file's
    configuration the turn looks free; a step away it is driven."""
    path = tmp_path / "leg.xml"
    path.write_text(leg_mjcf(pin=(0.085, -0.005 + off)))
    mechanism = load(path)
    assert mechanism.dof == 2 and mechanism.output_point is None


@pytest.mark.parametrize("order", [dict(reverse=True), dict(thigh_first=True), dict(reverse=True, thigh_first=True)])
def test_the_reading_does_not_turn_on_the_order_the_file_lists_things_in(tmp_path, order):
    """Branches, motors and the connect's two bodies in either order: the same platform (the thigh, further from the
    base than the horn; the connect written from the thigh took the horn and refused the leg), the same indices."""
    path = tmp_path / "reversed.xml"
    path.write_text(leg_mjcf(**order))
    mechanism = load(path)
    assert mechanism.dof == 2 and mechanism.output_point is None
    path.with_name("leg.xml").write_text(leg_mjcf())
    reference = load(path.with_name("leg.xml"))
    result, expected = (indices_at_pose(m, m.home_pose) for m in (mechanism, reference))
    assert (float(result.iti), float(result.lmti)) == pytest.approx((float(expected.iti), float(expected.lmti)),
                                                                    abs=1e-12)
    with pytest.raises(ValueError, match="an actuator turns the platform about the output point"):
        load(path, output="thigh", output_type="point")


def five_bar_on_a_pin() -> str:
    """A five-bar whose platform hangs on distal link 1 by a hinge at P, distal link 2 pinned to it there: the
    platform turns freely about P, the point where the legs meet."""
    return ('<mujoco model="pinned"><worldbody><body name="base">'
            '<body name="crank1"><joint name="m1" type="hinge" axis="0 0 1"/><geom type="sphere" size="0.005"/>'
            '<body name="distal1" pos="0.03 0.1 0"><joint name="p1" type="hinge" axis="0 0 1"/>'
            '<geom type="sphere" size="0.005"/><body name="platform" pos="0.07 0.1 0"><joint name="spin" '
            'type="hinge" axis="0 0 1"/><geom type="sphere" size="0.005"/></body></body></body>'
            '<body name="crank2" pos="0.2 0 0"><joint name="m2" type="hinge" axis="0 0 1"/>'
            '<geom type="sphere" size="0.005"/><body name="distal2" pos="-0.03 0.1 0"><joint name="p2" '
            'type="hinge" axis="0 0 1"/><geom type="sphere" size="0.005"/></body></body></body></worldbody>'
            '<equality><connect name="pin" body1="distal2" body2="platform" anchor="-0.07 0.1 0"/></equality>'
            '<actuator><motor joint="m1"/><motor joint="m2"/></actuator></mujoco>')


def test_a_platform_turning_freely_on_the_pin_keeps_its_point_output(tmp_path):
    path = tmp_path / "pinned.xml"
    path.write_text(five_bar_on_a_pin())
    mechanism = load(path, output="platform")
    assert mechanism.dof == 2 and mechanism.output_point is not None
    assert not any(note.startswith("point output:") for note in mechanism.assembly_notes)
    a1, a2, b1, b2, p = (np.array(v) for v in ([0, 0], [0.2, 0], [0.03, 0.1], [0.17, 0.1], [0.1, 0.2]))

    def sine(u, v):
        return abs(float(u[0] * v[1] - u[1] * v[0])) / np.linalg.norm(u) / np.linalg.norm(v)

    result = indices_at_pose(mechanism, mechanism.home_pose)
    np.testing.assert_allclose(sorted(np.ravel(result.iti_actuators)), sorted([sine(b1 - a1, p - b1),
                                                                             sine(b2 - a2, p - b2)]), atol=1e-9)
    assert float(result.lmti) == pytest.approx(sine(p - b1, p - b2), abs=1e-9)


def test_the_command_reads_the_frame_and_refuses_the_point(tmp_path):
    path = tmp_path / "leg.xml"
    path.write_text(leg_mjcf())
    read = screwkit("analyze", path, "--json")
    assert read.returncode == 0, read.stderr
    result = json.loads(read.stdout)
    assert result["dof"] == 2 and result["f_o"] == {"1": 0.0}
    refused = screwkit("analyze", path, "--output", "thigh", "--output-type", "point")
    one_line_error(refused, "an actuator turns the platform about the output point", "--output-type frame")


def test_convert_writes_the_frame_the_analysis_reads(tmp_path):
    """``convert`` refused the leg where ``analyze`` read the frame: both read it now, and the file written reads the
    same indices as the leg itself; a point asked for is refused by both."""
    path, out = tmp_path / "leg.xml", tmp_path / "leg.urdf"
    path.write_text(leg_mjcf())
    converted = screwkit("convert", path, out, "--json")
    assert converted.returncode == 0, converted.stderr
    assert any("not the point where the legs meet" in note for note in json.loads(converted.stdout)["notes"])
    original, written = (json.loads(screwkit("analyze", p, "--json").stdout) for p in (path, out))
    assert written["dof"] == original["dof"] == 2
    for key in ("iti", "lmti", "iti_actuators"):
        assert written[key] == pytest.approx(original[key], abs=1e-12), key
    refused = screwkit("convert", path, tmp_path / "point.urdf", "--output", "thigh", "--output-type", "point")
    one_line_error(refused, "an actuator turns the platform about the output point", "--output-type frame")
    assert not (tmp_path / "point.urdf").exists()
