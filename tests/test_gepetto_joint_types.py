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
import re
import shutil
import xml.etree.ElementTree as ElementTree
from dataclasses import replace

import numpy as np
import pinocchio as pin
import pytest
import yaml
from gepetto_loader import gepetto_model
from rod_lines import closed_by_scipy, joint_line, two_rod_indices
from test_gallery_published import GEPETTO
from universal_ankle import universal_ankle

from helpers import in_millimetres, one_line_error, screwkit
from screwkit.closure import solve
from screwkit.io import LegWithLoops, graph_mechanism, read_closed_tree, read_mechanism_file
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


def analysed(path, **options):
    mechanism = load(path, output="foot_right", lock=LOCKS, **options)
    result = indices_at_pose(mechanism, mechanism.home_pose)
    motors = {name.split(":")[-1]: result.joint_values[name] for name in result.joint_values
              if name.split(":")[-1] in RODS}
    _, report = read_mechanism_file(path, output="foot_right", lock=LOCKS, **options)
    note = next(note for note in report.notes if note.startswith("joint knee_left (passive, inside a loop) locked"))
    return result, motors, float(note.split(" locked at ")[1].split(",")[0])


def rod_line_indices(path, held: dict[str, float], rods: dict, hinges: tuple[str, str]):
    """The ITI and OTI of each actuator (sorted by name) of a two-rod ankle, from the rod lines of Gepetto's own
    reading of ``path`` closed by scipy with the joints ``held`` (the motors among them), and that configuration;
    ``rods``: each motor's crank-end and foot-end joint (at the joint centres), ``hinges``: the foot's two."""
    model = gepetto_model(path, path.parent / "robot.yaml")
    spec = yaml.safe_load((path.parent / "robot.yaml").read_text())
    pairs = [(model.getFrameId(a), model.getFrameId(b)) for a, b in spec["closed_loop"]]
    data, q = closed_by_scipy(model, pairs, held)
    itis, otis = two_rod_indices(model, data, rods, hinges)
    return itis, otis, model, q


def test_battobot_s_ankle_with_its_leg_locked_has_the_rod_line_indices():
    path = BATTOBOT / "robot.urdf"
    result, motors, knee = analysed(path)
    assert sorted(motors) == sorted(RODS) and result.dof == 2
    itis, otis, model, q = rod_line_indices(path, {name: 0.0 for name in LOCKS[:4]} | motors, RODS,
                                            ("ankley_left", "anklex_left"))
    assert q[model.joints[model.getJointId("knee_left")].idx_q] == pytest.approx(knee, abs=1e-8)
    assert abs(knee) > 1e-3  # (the file writes 0, where the knee's loop does not close)
    assert [name.split(":")[-1] for name in result.actuators] == sorted(motors)
    np.testing.assert_allclose(result.iti_actuators, itis, atol=TOLERANCE)
    np.testing.assert_allclose(result.oti_actuators[0], otis, atol=TOLERANCE)
    np.testing.assert_allclose(result.lmti, min(otis), atol=TOLERANCE)
    assert 0.05 < result.lmti < 1.0 and 0.05 < result.iti < 1.0  # neither singular nor trivially 1


DIGIT_LOCKS = ("motor_hip_x", "motor_hip_z", "motor_hip_y", "motor_knee", "free_knee")
DIGIT_RODS = {  # each motor's rod: its crank-end and foot-end joints, as the two files write them
    "digit_like_2legs": {"motor_shin1": ("spherical_free_shin2", "spherical_free_foot2_X"),
                         "motor_shin2": ("spherical_free_shin1", "spherical_free_foot1_X")},
    "digit_like_2legs_6D": {"motor_shin1": ("crank_toe_b_2/2_rev0", "foot_part_toe_b_1/2_2_rev0"),
                            "motor_shin2": ("crank_2_toe_b_2/2_2_rev0", "foot_part_toe_b_1/2_rev0")}}


def digit_ankle(path, *, serial: bool, **options):
    """screwkit's indices of the ankle of a two-legged digit with the leg held, at the file's configuration, and the
    motors' values: ``digit_like_2legs`` (ball joints inside its legs) is a graph mechanism, ``digit_like_2legs_6D``
    (its balls three revolutes, a universal joint at each rod's foot end: a universal loop joint) ``serial`` legs."""
    if serial:
        mechanism = load(path, lock=DIGIT_LOCKS, **options)
        result = indices_at_pose(mechanism, mechanism.home_pose)
    else:
        graph = graph_mechanism(read_closed_tree(path, lock=DIGIT_LOCKS, **options))
        result = replace(graph.indices(), poses=graph.task_pose())
    motors = {name.split(":")[-1]: value for name, value in result.joint_values.items()
              if name.split(":")[-1] in ("motor_shin1", "motor_shin2")}
    return result, motors


@pytest.mark.parametrize("robot", sorted(DIGIT_RODS))
def test_a_two_legged_digit_s_ankle_has_the_rod_line_indices(robot):
    """Both files opened as written (before, the first was refused for its joint_type and the second for the two
    revolutes beyond the foot at each rod's end), with the locks their refusals name."""
    path = GEPETTO / robot / "robot.urdf"
    result, motors = digit_ankle(path, serial=robot.endswith("6D"))
    assert sorted(motors) == ["motor_shin1", "motor_shin2"] and result.dof == 2
    itis, otis, _, _ = rod_line_indices(path, {name: 0.0 for name in DIGIT_LOCKS[:4]} | motors, DIGIT_RODS[robot],
                                        ("free_foot1", "free_foot2"))
    assert [name.split(":")[-1] for name in result.actuators] == sorted(motors)
    np.testing.assert_allclose(np.ravel(result.iti_actuators), itis, atol=TOLERANCE)
    np.testing.assert_allclose(np.ravel(result.oti_actuators), otis, atol=TOLERANCE)
    assert 0.5 < result.lmti < 1.0


def variants(path, tmp_path):
    """The file in mm (read with ``length_unit="mm"``), hung from a new world frame turned and moved, and with its
    robot.yaml's lists written back to front (loops, motors, replaced joints): (name, path, options) of each."""
    text = path.read_text()
    tree = ElementTree.fromstring(text)
    children = {joint.find("child").get("link") for joint in tree.iter("joint")}
    root = next(link.get("name") for link in tree.iter("link") if link.get("name") not in children)
    moved = text.replace(f'<link name="{root}">', '<link name="world"/><joint name="world_to_root" type="fixed">'
                         f'<parent link="world"/><child link="{root}"/><origin xyz="0.7 -1.3 0.4" rpy="0.3 -1.1 2.0"/>'
                         f'</joint><link name="{root}">', 1)
    assert moved != text
    spec = yaml.safe_load((path.parent / "robot.yaml").read_text())
    listed_back = {key: value[::-1] for key, value in spec.items()}
    for name, written, written_spec, options in (("mm", in_millimetres(text), spec, {"length_unit": "mm"}),
                                                 ("moved", moved, spec, {}), ("listed back", text, listed_back, {})):
        (tmp_path / name).mkdir()
        (tmp_path / name / "robot.urdf").write_text(written)
        (tmp_path / name / "robot.yaml").write_text(yaml.safe_dump(written_spec))
        yield name, tmp_path / name / "robot.urdf", options


def ankle(robot: str, path, **options):
    """The indices and motors' values of battobot's ankle or a two-legged digit's, the file at ``path``."""
    if robot == "battobot_6d":
        result, motors, _ = analysed(path, **options)
        return result, motors
    return digit_ankle(path, serial=robot.endswith("6D"), **options)


@pytest.mark.parametrize("robot", ["battobot_6d", "digit_like_2legs_6D", "digit_like_2legs"])
def test_an_ankle_is_the_same_in_millimetres_in_a_moved_world_and_listed_back(tmp_path, robot):
    """The same motors' values and indices; the same foot angles but in the moved world (whose base frame is
    another)."""
    path = GEPETTO / robot / "robot.urdf"
    result, motors = ankle(robot, path)
    for name, other_path, options in variants(path, tmp_path):
        other, other_motors = ankle(robot, other_path, **options)
        order = [other.actuators.index(actuator) for actuator in result.actuators]
        np.testing.assert_allclose(np.ravel(other.iti_actuators)[order], np.ravel(result.iti_actuators), atol=1e-9)
        np.testing.assert_allclose(np.asarray(other.oti_actuators).reshape(-1)[order],
                                   np.asarray(result.oti_actuators).reshape(-1), atol=1e-9)
        np.testing.assert_allclose(other.lmti, result.lmti, atol=1e-9)
        np.testing.assert_allclose(other.cti, result.cti, atol=1e-9, err_msg=name)
        if name != "moved":
            np.testing.assert_allclose(other.poses, result.poses, atol=1e-9)
        assert other_motors == pytest.approx(motors, abs=1e-8), name


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


def test_the_command_line_opens_the_two_legged_digit_whose_rods_end_on_universal_joints(tmp_path):
    """digit_like_2legs_6D: the refusal names the five joints to hold; with them the ankle's rods close on the foot
    through universal loop joints, and the file ``convert`` writes (its <loop type="universal">) gives the same
    indices."""
    path = GEPETTO / "digit_like_2legs_6D" / "robot.urdf"
    one_line_error(screwkit("info", path), " ".join(f"--lock {name}" for name in DIGIT_LOCKS))
    held = [part for name in DIGIT_LOCKS for part in ("--lock", name)]
    info = screwkit("info", path, *held)
    assert info.returncode == 0, info.stderr
    assert "loop motor_shin1_loop (universal)" in info.stdout and "loop motor_shin2_loop (universal)" in info.stdout
    done = screwkit("analyze", path, *held, "--json")
    assert done.returncode == 0, done.stderr
    converted = screwkit("convert", path, tmp_path / "ankle.urdf", *held)
    assert converted.returncode == 0, converted.stderr
    assert '<loop name="motor_shin1_loop" type="universal"' in (tmp_path / "ankle.urdf").read_text()
    again = screwkit("analyze", tmp_path / "ankle.urdf", "--json")
    assert again.returncode == 0, again.stderr
    for key in ("iti", "lmti"):
        assert json.loads(again.stdout)[key] == pytest.approx(json.loads(done.stdout)[key], abs=1e-12)


def test_two_hinges_beyond_the_foot_whose_axes_miss_each_other_go_to_the_graph_reading(tmp_path):
    """A universal loop joint needs its two axes to meet: with the second hinge of one rod's foot end moved 1 cm off
    the first's axis, the serial reading refuses the closure naming both hinges and what it supports; the commands
    then read it as a graph, whose legs may have any joints (2 DOF, the rod's foot end two offset hinges)."""
    source = GEPETTO / "digit_like_2legs_6D"
    text = (source / "robot.urdf").read_text()
    hinge = '<joint name="foot_part_toe_b_1/2_2_rev1" type="revolute">'
    assert text.count(hinge) == 1
    (tmp_path / "robot.urdf").write_text(text.replace(hinge, hinge + '<origin xyz="0 0 0.01" rpy="0 0 0"/>'))
    shutil.copy(source / "robot.yaml", tmp_path / "robot.yaml")
    refusal = re.escape("foot_part_toe_b_1/2_2_rev0 (revolute), foot_part_toe_b_1/2_2_rev1 (revolute) beyond the "
                        "platform") + ".*" + re.escape("two revolute joints whose axes meet (a universal joint)")
    with pytest.raises(LegWithLoops, match=refusal):
        load(tmp_path / "robot.urdf", lock=DIGIT_LOCKS)
    held = [part for name in DIGIT_LOCKS for part in ("--lock", name)]
    opened = screwkit("info", tmp_path / "robot.urdf", *held)
    assert opened.returncode == 0, opened.stderr
    assert "DOF 2; task coordinates: roll (deg), pitch (deg)" in opened.stdout, opened.stdout
    assert "analysed as a graph" in opened.stdout, opened.stdout


UNIVERSAL_ANKLES = {  # universal_ankle's options, and the joint values (deg) the loops are closed with
    "as drawn": ({}, ()),
    "hinges drawn off and turned": ({"off1": 0.03, "off2": -0.02, "turn2": (0.4, -0.7, 1.1),
                                     "angles": (np.radians(20.0), np.radians(-15.0))},
                                    (("uA1", 20.0), ("uB1", -15.0), ("uA2", 20.0), ("uB2", -15.0))),
    "a Hooke joint at 90 deg": ({"rod_aligned": True, "angles": (np.pi / 2, 0.0)}, (("uA1", 90.0), ("uA2", 90.0))),
}


@pytest.mark.parametrize("case", UNIVERSAL_ANKLES)
def test_a_universal_loop_joint_turns_about_the_file_s_hinges_where_they_are_assembled(tmp_path, case):
    """Rods closed on the foot through two hinges whose axes meet (a universal loop joint): at the file's pose and
    another, each of the loop's two joint lines is the line of the file's hinge (Pinocchio, the loader's model
    closed by scipy at the same motor values) -- the second hinge's first, then the first's -- also where the first
    hinge is assembled far from 0 (the Hooke joint, whose second hinge is drawn along the rod at 0: read at 0 it
    would double the ball's turn about the rod, and the ankle was refused as unable to move); and the indices are
    the rod lines'."""
    options, initial = UNIVERSAL_ANKLES[case]
    path = universal_ankle(tmp_path / "ankle", **options)
    mechanism = load(path, output="foot", initial=initial)
    assert mechanism.dof == 2 and [chain.loop_type for chain in mechanism.chains].count("universal") == 2
    model = gepetto_model(path, path.parent / "robot.yaml")
    pairs = [(model.getFrameId(f"rodend{i}"), model.getFrameId(f"uend{i}")) for i in (1, 2)]
    for turn in ((0.0, 0.0), (8.0, -5.0)):
        pose = mechanism.home_pose + np.radians(turn)
        result = indices_at_pose(mechanism, pose)
        motors = {name.split(":")[-1]: value for name, value in result.joint_values.items()
                  if name.split(":")[-1] in ("motor1", "motor2")}
        data, _ = closed_by_scipy(model, pairs, motors)
        solution = solve(mechanism, pose[None])
        for k, chain in enumerate(mechanism.chains):
            if chain.loop_type != "universal":
                continue
            rod = next(name for name in chain.joint_names if name.startswith("motor"))[-1]
            axes = solution.joint_axes[k][0] @ mechanism.rotation_world_base.T
            points = solution.joint_points[k][0] @ mechanism.rotation_world_base.T + mechanism.translation_world_base
            for dof, hinge in ((-2, f"uB{rod}"), (-1, f"uA{rod}")):
                point, axis = joint_line(model, data, hinge)
                assert abs(abs(axes[dof] @ axis) - 1.0) < 1e-9, (case, turn, hinge)
                assert np.linalg.norm(np.cross(points[dof] - point, axis)) < 1e-9, (case, turn, hinge)
        rods = {f"motor{i}": (f"sph{i}", (f"uA{i}", f"uB{i}")) for i in (1, 2)}  # (the universal's centre)
        itis, otis = two_rod_indices(model, data, rods, ("ankle_y", "ankle_x"))
        np.testing.assert_allclose(np.ravel(result.iti_actuators), itis, atol=TOLERANCE)
        np.testing.assert_allclose(np.ravel(result.oti_actuators), otis, atol=TOLERANCE)


def with_mimic(text: str, joint: str, mimicked: str) -> str:
    start = text.index(f'<joint name="{joint}"')
    end = text.index("</joint>", start)
    return text[:end] + f'<mimic joint="{mimicked}" multiplier="1" offset="0"/>' + text[end:]


def test_a_urdf_mimic_is_read_as_a_coupling_not_passed_over(tmp_path):
    """Pinocchio's URDF reader takes a <mimic> joint as independent: read so, the mechanism would silently have a
    mobility the file does not give it. A mimic between joints of battobot's other leg (left out), or tying an
    analysed ankle motor to the other leg's, constrains nothing analysed: said, and the indices are the file's; one
    tying two joints of the ankle is refused naming the element."""
    text = (BATTOBOT / "robot.urdf").read_text()
    expected, _, _ = analysed(BATTOBOT / "robot.urdf")
    for joint, mimicked in (("knee_right", "motor_knee_right"), ("motor_ankle1_left", "motor_ankle1_right")):
        said = (f"ties joint {joint!r} to {mimicked!r}, which constrains no motion of the mechanism analysed (the "
                "branch it ties follows): left out")
        folder = tmp_path / joint
        folder.mkdir()
        (folder / "robot.urdf").write_text(with_mimic(text, joint, mimicked))
        shutil.copy(BATTOBOT / "robot.yaml", folder / "robot.yaml")
        got, _, _ = analysed(folder / "robot.urdf")
        np.testing.assert_allclose(got.iti_actuators, expected.iti_actuators, atol=1e-12)
        np.testing.assert_allclose(got.lmti, expected.lmti, atol=1e-12)
        _, report = read_mechanism_file(folder / "robot.urdf", output="foot_right", lock=LOCKS)
        assert any(f"<joint name='{joint}'><mimic joint='{mimicked}'>: {said}" in note for note in report.notes)
    (tmp_path / "robot.urdf").write_text(with_mimic(text, "anklex_left", "ankley_left"))
    shutil.copy(BATTOBOT / "robot.yaml", tmp_path / "robot.yaml")
    held = [part for name in LOCKS for part in ("--lock", name)]
    one_line_error(screwkit("info", tmp_path / "robot.urdf", "--output", "foot_right", *held),
                   "<joint name='anklex_left'><mimic joint='ankley_left'>: a joint coupling ties joint 'anklex_left' "
                   "to joint 'ankley_left', which holds the mechanism analysed to fewer motions",
                   "remove the element to analyse")
