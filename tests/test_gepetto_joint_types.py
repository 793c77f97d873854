"""A Gepetto robot.yaml's ``joint_name`` / ``joint_type``: joints of the URDF replaced when loading (``SPHERICAL``: a
ball joint; ``UJOINT_AB``: two revolutes about the joint frame's axes A then B; ``FIXED``: held at 0).

Checked against Gepetto's own reading: the model example-parallel-robots' loader builds (its code copied in
``tests/gepetto_loader.py``) has the same joints, placements and frames as screwkit's, and the ankle of its
``battobot_6d`` (``tests/data/gallery/published``, BSD-3-Clause), closed by scipy on that model with the leg held,
has the rod-line indices screwkit reports: a rod with a universal joint at its crank and a ball at the foot carries
one force, along the line through the two joint centres; ITI = |f . v| / |v| at the crank's universal joint, OTI =
|f . v| / |v| at the rod's ball on the foot, v from the foot twist reciprocal to the other rod's force in the foot's
motion space (its two hinges ankley_left, anklex_left). (In the file, the frame ``foot_right`` is on the leg whose
joints are named ``_left``.)
"""

from __future__ import annotations

import json
import shutil

import numpy as np
import pinocchio as pin
import pytest
import yaml
from gepetto_loader import gepetto_model
from scipy.optimize import least_squares
from test_gallery_published import GEPETTO

from helpers import in_millimetres, one_line_error, screwkit
from screwkit.io import read_mechanism_file
from screwkit.io.gepetto import replaced_joints
from screwkit.io.loader import load
from screwkit.studies import indices_at_pose

BATTOBOT = GEPETTO / "battobot_6d"
HIP = ("hipz_left", "hipx_left", "hipy_left")
KNEE = ("motor_knee_left", "knee_left")
LOCKS = HIP + KNEE
RODS = {"motor_ankle1_left": ("left_spherical_ankle_1_Z", "left_spherical_foot_1"),
        "motor_ankle2_left": ("left_spherical_ankle_2_Z", "left_spherical_foot_2")}
TOLERANCE = 1e-9


def spec_with(tmp_path, change) -> tuple[object, object]:
    """battobot's URDF and its robot.yaml changed by ``change`` (a function of the parsed yaml), in ``tmp_path``."""
    shutil.copy(BATTOBOT / "robot.urdf", tmp_path / "robot.urdf")
    spec = yaml.safe_load((BATTOBOT / "robot.yaml").read_text())
    change(spec)
    (tmp_path / "robot.yaml").write_text(yaml.safe_dump(spec))
    return tmp_path / "robot.urdf", tmp_path / "robot.yaml"


def with_fixed(spec):
    """Two joints held, and the universal joints made balls: with a universal joint before a held one, the loader
    holds another joint (it passes the URDF model's joint id to the model it rebuilds, where the universal joints'
    second hinges have moved the ids on); screwkit holds the joint named."""
    spec["joint_name"] += ["ankley_right", "hipz_right"]
    spec["joint_type"] = ["SPHERICAL"] * len(spec["joint_type"]) + ["FIXED", "FIXED"]


def reordered(spec):
    pairs = list(zip(spec["joint_name"], spec["joint_type"]))[::-1]
    spec["joint_name"], spec["joint_type"] = [p[0] for p in pairs], [p[1] for p in pairs]


@pytest.mark.parametrize("change", [lambda spec: None, with_fixed, reordered], ids=["as written", "FIXED", "reordered"])
def test_the_replaced_joints_are_gepetto_s_own_reading(tmp_path, change):
    urdf, yaml_path = spec_with(tmp_path, change)
    theirs = gepetto_model(urdf, yaml_path)
    spec = yaml.safe_load(yaml_path.read_text())
    ours, notes = replaced_joints(pin.buildModelFromUrdf(str(urdf)), spec["joint_name"], spec["joint_type"], "yaml")
    assert list(ours.names) == list(theirs.names) and list(ours.parents) == list(theirs.parents)
    assert [j.shortname() for j in ours.joints] == [j.shortname() for j in theirs.joints]
    assert any(j.shortname() == "JointModelSpherical" for j in ours.joints)
    assert ("left_spherical_ankle_1_Z" in ours.names) is (change is not with_fixed)
    assert ("ankley_right" in ours.names) is (change is not with_fixed)
    for a, b in zip(ours.jointPlacements, theirs.jointPlacements):
        np.testing.assert_allclose(a.homogeneous, b.homogeneous, atol=1e-15)
    frames = {f.name: (ours.names[f.parentJoint], f.type, f.placement.homogeneous) for f in ours.frames}
    their_frames = {f.name: (theirs.names[f.parentJoint], f.type, f.placement.homogeneous) for f in theirs.frames}
    # with a FIXED joint, the loader's model lacks the frame after the universe's (here the root link's body frame):
    # it deletes frame 0 of the rebuilt model, whose frames then name their parent frames by stale indices for
    # Pinocchio's reduction; every other frame is the same
    assert set(frames) - set(their_frames) == ({ours.frames[1].name} if change is with_fixed else set())
    assert set(their_frames) <= set(frames)
    for name, (parent, kind, placement) in their_frames.items():
        assert (frames[name][0], frames[name][1]) == (parent, kind), name
        np.testing.assert_allclose(frames[name][2], placement, atol=1e-15)
    rng = np.random.default_rng(3)
    q = pin.integrate(ours, pin.neutral(ours), rng.uniform(-1, 1, ours.nv))
    data, their_data = ours.createData(), theirs.createData()
    pin.framesForwardKinematics(ours, data, q)
    pin.framesForwardKinematics(theirs, their_data, q)
    for frame in theirs.frames:
        np.testing.assert_allclose(data.oMf[ours.getFrameId(frame.name)].homogeneous,
                                   their_data.oMf[theirs.getFrameId(frame.name)].homogeneous, atol=1e-12)
    assert any(("replaces left_spherical_ankle_1 by revolute joints left_spherical_ankle_1_Z and "
                "left_spherical_ankle_1_Y (a universal joint)" if change is not with_fixed else
                "holds ankley_right at 0 (FIXED)") in note for note in notes), notes


def closed_by_scipy(model, pairs, held: dict[str, float]):
    """``model`` with every loop (frame ``pairs``) closed by scipy's least squares over the velocity coordinates of
    the joints not ``held`` (those at the given values), from the neutral configuration."""
    data = model.createData()
    start = pin.neutral(model)
    for name, value in held.items():
        start[model.joints[model.getJointId(name)].idx_q] = value
    held_v = {model.joints[model.getJointId(name)].idx_v for name in held}
    free = [index for index in range(model.nv) if index not in held_v]

    def configuration(x):
        step = np.zeros(model.nv)
        step[free] = x
        return pin.integrate(model, start, step)

    def residuals(x):
        pin.framesForwardKinematics(model, data, configuration(x))
        return np.concatenate([pin.log6(data.oMf[a].inverse() * data.oMf[b]).vector for a, b in pairs])

    solved = least_squares(residuals, np.zeros(len(free)), xtol=1e-15, ftol=1e-15, gtol=1e-15)
    assert np.abs(residuals(solved.x)).max() < 1e-10  # every loop closed
    q = configuration(solved.x)
    pin.forwardKinematics(model, data, q)
    return data, q


def centre_and_axis(model, data, name: str) -> tuple[np.ndarray, np.ndarray]:
    joint = model.getJointId(name)
    axis = {"JointModelRX": 0, "JointModelRY": 1, "JointModelRZ": 2}.get(model.joints[joint].shortname())
    return data.oMi[joint].translation.copy(), None if axis is None else data.oMi[joint].rotation[:, axis].copy()


def analysed(path, **options):
    mechanism = load(path, output="foot_right", lock=LOCKS, **options)
    result = indices_at_pose(mechanism, mechanism.home_pose)
    motors = {name.split(":")[-1]: result.joint_values[name] for name in result.joint_values
              if name.split(":")[-1] in RODS}
    _, report = read_mechanism_file(path, output="foot_right", lock=LOCKS, **options)
    note = next(note for note in report.notes if note.startswith("joint knee_left (passive, inside a loop) locked"))
    return result, motors, float(note.split(" locked at ")[1].split(",")[0])


def test_battobot_s_ankle_with_its_leg_locked_has_the_rod_line_indices():
    path = BATTOBOT / "robot.urdf"
    result, motors, knee = analysed(path)
    assert sorted(motors) == sorted(RODS) and result.dof == 2
    model = gepetto_model(path, BATTOBOT / "robot.yaml")
    spec = yaml.safe_load((BATTOBOT / "robot.yaml").read_text())
    pairs = [(model.getFrameId(a), model.getFrameId(b)) for a, b in spec["closed_loop"]]
    data, q = closed_by_scipy(model, pairs, {name: 0.0 for name in LOCKS[:4]} | motors)
    assert q[model.joints[model.getJointId("knee_left")].idx_q] == pytest.approx(knee, abs=1e-8)
    assert abs(knee) > 1e-3  # (the file writes 0, where the knee's loop does not close)
    forces, itis = {}, []
    for motor in sorted(motors):
        (crank, _), (end, _) = (centre_and_axis(model, data, name) for name in RODS[motor])
        force = (end - crank) / np.linalg.norm(end - crank)
        origin, axis = centre_and_axis(model, data, motor)
        velocity = np.cross(axis, crank - origin)
        itis.append(abs(force @ velocity) / np.linalg.norm(velocity))
        forces[motor] = (force, crank, end)
    hinges = [centre_and_axis(model, data, name) for name in ("ankley_left", "anklex_left")]
    space = np.array([np.concatenate([axis, np.cross(point, axis)]) for point, axis in hinges]).T  # (omega, v at 0)

    def power(force, at, twist):
        return force @ (twist[3:] + np.cross(twist[:3], at))

    otis = []
    for motor in sorted(motors):
        force, _, end = forces[motor]
        other, other_at, _ = next(value for key, value in forces.items() if key != motor)
        twist = space @ np.array([-power(other, other_at, space[:, 1]), power(other, other_at, space[:, 0])])
        velocity = twist[3:] + np.cross(twist[:3], end)
        otis.append(abs(force @ velocity) / np.linalg.norm(velocity))
    assert [name.split(":")[-1] for name in result.actuators] == sorted(motors)
    np.testing.assert_allclose(result.iti_actuators, itis, atol=TOLERANCE)
    np.testing.assert_allclose(result.oti_actuators[0], otis, atol=TOLERANCE)
    np.testing.assert_allclose(result.lmti, min(otis), atol=TOLERANCE)
    assert 0.05 < result.lmti < 1.0 and 0.05 < result.iti < 1.0  # neither singular nor trivially 1


def test_battobot_s_ankle_is_the_same_in_millimetres_in_a_moved_world_and_listed_back(tmp_path):
    """The file in mm (--length-unit mm), and hung from a new world frame turned and moved (its root link is
    ``hip_z_axis_2_leg_assembly``), and its robot.yaml's lists written back to front: the same motors' values and
    indices, and the same foot angles but in the moved world."""
    result, motors, _ = analysed(BATTOBOT / "robot.urdf")
    text = (BATTOBOT / "robot.urdf").read_text()
    root = '<link name="hip_z_axis_2_leg_assembly">'
    moved = text.replace(root, '<link name="world"/><joint name="world_to_root" type="fixed"><parent link="world"/>'
                         '<child link="hip_z_axis_2_leg_assembly"/><origin xyz="0.7 -1.3 0.4" rpy="0.3 -1.1 2.0"/>'
                         '</joint>' + root, 1)
    spec = yaml.safe_load((BATTOBOT / "robot.yaml").read_text())
    listed_back = {key: value[::-1] for key, value in spec.items()}  # loops, motors and replaced joints reversed
    for folder, written, options in (("mm", in_millimetres(text), {"length_unit": "mm"}), ("moved", moved, {}),
                                     ("listed back", text, {})):
        (tmp_path / folder).mkdir()
        (tmp_path / folder / "robot.urdf").write_text(written)
        (tmp_path / folder / "robot.yaml").write_text(yaml.safe_dump(listed_back if folder == "listed back" else spec))
        other, other_motors, _ = analysed(tmp_path / folder / "robot.urdf", **options)
        order = [other.actuators.index(name) for name in result.actuators]
        np.testing.assert_allclose(other.iti_actuators[order], result.iti_actuators, atol=1e-9)
        np.testing.assert_allclose(other.oti_actuators[:, order], result.oti_actuators, atol=1e-9)
        np.testing.assert_allclose(other.lmti, result.lmti, atol=1e-9)
        if folder != "moved":  # (in the moved world the foot's angles are measured from another base frame)
            np.testing.assert_allclose(other.poses, result.poses, atol=1e-9)
        assert other_motors == pytest.approx(motors, abs=1e-8)


def test_the_command_line_follows_its_own_lock_suggestions_to_battobot_s_ankle(tmp_path):
    """Each refusal names what to hold next: the hip, then the knee motor with the knee it drives through its
    four-bar; then the ankle is analysed, the report says what the robot.yaml replaced, and the file ``convert``
    writes gives the same indices."""
    path = BATTOBOT / "robot.urdf"
    one_line_error(screwkit("info", path, "--output", "foot_right"), "--lock hipz_left --lock hipx_left --lock "
                   "hipy_left")
    held = [part for name in HIP for part in ("--lock", name)]
    one_line_error(screwkit("info", path, "--output", "foot_right", *held),
                   "actuated joint 'motor_knee_left' drives joint 'knee_left' through a loop",
                   "--lock motor_knee_left --lock knee_left")
    held += ["--lock", "motor_knee_left", "--lock", "knee_left"]
    done = screwkit("analyze", path, "--output", "foot_right", *held, "--json")
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)
    assert report["dof"] == 2 and 0.0 < report["lmti"] < 1.0
    info = screwkit("info", path, "--output", "foot_right", *held)
    assert info.returncode == 0, info.stderr
    assert "robot.yaml's joint_type replaces left_spherical_foot_1 by a ball joint" in info.stdout
    assert "replaces free_knee_left by revolute joints free_knee_left_Y and free_knee_left_Z" in info.stdout
    converted = screwkit("convert", path, tmp_path / "ankle.urdf", "--output", "foot_right", *held)
    assert converted.returncode == 0, converted.stderr
    again = screwkit("analyze", tmp_path / "ankle.urdf", "--json")
    assert again.returncode == 0, again.stderr
    assert json.loads(again.stdout)["iti"] == pytest.approx(report["iti"], abs=1e-12)
    assert json.loads(again.stdout)["lmti"] == pytest.approx(report["lmti"], abs=1e-12)


@pytest.mark.parametrize("change, needle", [
    (lambda spec: spec["joint_type"].__setitem__(0, "BALL"),
     "joint_type[0] ('left_spherical_ankle_1') must be SPHERICAL, FIXED or UJOINT_AB"),
    (lambda spec: spec["joint_type"].__setitem__(0, "UJOINT_ZZ"), "got 'UJOINT_ZZ'"),
    (lambda spec: spec["joint_type"].pop(), "joint_name and joint_type must be two lists of the same length"),
    (lambda spec: spec.__setitem__("joint_type", "SPHERICAL"), "joint_name and joint_type must be two lists"),
    (lambda spec: spec["joint_name"].__setitem__(1, "left_spherical_ankle_1"),
     "joint_name[1] names 'left_spherical_ankle_1' a second time"),
])
def test_a_bad_joint_type_is_refused_in_one_line_naming_the_entry(tmp_path, change, needle):
    urdf, _ = spec_with(tmp_path, change)
    one_line_error(screwkit("info", urdf, "--output", "foot_right"), "robot.yaml", needle)


def test_a_joint_name_that_is_no_joint_is_passed_over_as_gepetto_s_loader_does(tmp_path):
    urdf, yaml_path = spec_with(tmp_path, lambda spec: (spec["joint_name"].append("no_such_joint"),
                                                        spec["joint_type"].append("SPHERICAL")))
    theirs = gepetto_model(urdf, yaml_path)
    _, report = read_mechanism_file(urdf, output="foot_right", lock=LOCKS)
    assert any("joint_name lists no_such_joint, not joints of the URDF: passed over" in note for note in report.notes)
    mechanism = load(urdf, output="foot_right", lock=LOCKS)
    assert mechanism.dof == 2 and "no_such_joint" not in theirs.names


def test_a_fixed_joint_after_universal_joints_is_the_one_named_where_the_loader_holds_another(tmp_path):
    """The loader's slip that the docs record: with the universal joints as written, ``FIXED`` on ankley_right holds
    another joint of its rebuilt model (the URDF model's id of ankley_right names another joint there); screwkit
    holds ankley_right, and the joints left are the loader's with ankley_right instead of the one it held."""
    urdf, yaml_path = spec_with(tmp_path, lambda spec: (spec["joint_name"].append("ankley_right"),
                                                        spec["joint_type"].append("FIXED")))
    theirs = gepetto_model(urdf, yaml_path)
    spec = yaml.safe_load(yaml_path.read_text())
    ours, notes = replaced_joints(pin.buildModelFromUrdf(str(urdf)), spec["joint_name"], spec["joint_type"], "yaml")
    assert "ankley_right" in theirs.names and "ankley_right" not in ours.names
    held_instead = set(ours.names) - set(theirs.names)
    assert len(held_instead) == 1 and ours.njoints == theirs.njoints
    assert set(theirs.names) - set(ours.names) == {"ankley_right"}
    assert "robot.yaml's joint_type holds ankley_right at 0 (FIXED)" in notes
