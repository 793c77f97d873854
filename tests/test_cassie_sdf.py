"""example-robot-data's Cassie in SDFormat (``cassie_v2.sdf``, as published), opened as a user opens it, and what
it found:

* which pose coordinate a mechanism's motion is read in when one barely moves: a coordinate is taken in its order
  (x, y, z, roll, pitch, yaw) only if its rates tell the motions apart within a tenth as well as the best one of
  its kind. The foot, drawn at a pitch of 77 deg and turning about the world's y axis to within 4e-6 rad, read
  roll, whose rate is 1.6e-5 of the pitch's, and was then put at the gimbal lock for any roll asked ("at roll =
  120" and "at roll = 170" were one configuration);
* its legs' joint limits: the file draws the foot's crank and hinge outside theirs, and a biped's other leg too;
* the names its messages give: its legs after their bodies, not after the hinges a reader writes for a ball joint;
  no such hinge guessed as an actuator; the passive joints to lock when the foot moves with its actuator locked."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from screwkit.closure.task_space import choose_task_axes
from screwkit.io import graph_mechanism, read_closed_tree
from screwkit.io.graph_kinematics import rpy_of, solve_poses

CASSIE = Path(__file__).parent / "data" / "gallery" / "published" / "example_robot_data_cassie" / "cassie_v2.sdf"
HIPS = ("left-roll-op", "left-yaw-op", "left-pitch-op", "left-knee-op", "left-knee-shin-joint")
ANGULAR = np.array([False] * 3 + [True] * 3)


def test_a_coordinate_that_barely_moves_is_not_taken_before_one_that_moves():
    """The Cassie foot's rates (x, y, z, roll, pitch, yaw on its one motion): pitch. A rotation at 45 deg between
    roll and pitch: roll, first in order among equals; tilted 30 deg from pitch towards roll: pitch, which it moves
    along faster (one motion's coordinate is the fastest of its kind; of two or more, the first that moves)."""
    foot = np.array([[-2.3e-15], [5.0e-16], [-6.2e-17], [1.59e-5], [1.0], [1.63e-5]])
    assert choose_task_axes(foot, ANGULAR, 1) == (4,)
    for turn, expected in ((np.radians(45.0), 3), (np.radians(30.0), 4), (np.radians(60.0), 3)):
        between = np.array([[0.0], [0.0], [0.0], [np.sin(turn)], [np.cos(turn)], [0.0]])
        assert choose_task_axes(between, ANGULAR, 1) == (expected,)
    slide = np.array([[1e-5], [1.0], [0.0], [0.0], [0.0], [0.0]])  # a slide along y, drawn 1e-5 off
    assert choose_task_axes(slide, ANGULAR, 1) == (1,)
    # two motions: roll passed over for pitch, then yaw barely moving beside pitch: roll is taken after all (the
    # choice never comes short of the DOF while coordinates independent of those chosen are left)
    passed_over = np.array([[0.0, 0.0], [0.0, 0.0], [0.0, 0.0], [0.0, 0.05], [1.0, 0.0], [0.0, 0.001]])
    assert choose_task_axes(passed_over, ANGULAR, 2) == (3, 4)


def cassie_foot(length_unit=None):
    tree = read_closed_tree(CASSIE, output="left-foot", actuate=["left-foot-op"], lock=list(HIPS),
                            length_unit=length_unit)
    return tree, graph_mechanism(tree)


def foot_rotation(tree, graph, q) -> np.ndarray:
    return graph.kinematics.transforms(q[None])[0, tree.model.frames[graph.frame_id].parentJoint][:3, :3] @ np.asarray(
        tree.model.frames[graph.frame_id].placement.rotation)


@pytest.mark.parametrize("length_unit", [None, "mm", "km"])  # the file read in m, and its lengths x 1e-3 and x 1e3
def test_the_published_cassie_s_foot_is_read_in_the_angle_it_turns(length_unit):
    """The foot turns about its hinge (the actuated joint): the task coordinate is pitch, and each pose's foot is the
    file's turned about that hinge's world axis by the change of pitch asked (Rodrigues, numpy alone), whatever the
    unit its lengths are read in."""
    tree, graph = cassie_foot(length_unit)
    assert graph.task_axes == (4,)
    home = foot_rotation(tree, graph, graph.q)
    home_pitch = float(rpy_of(home)[1])
    assert np.degrees(home_pitch) == pytest.approx(77.0, abs=1e-3)
    model, data = tree.model, tree.model.createData()  # the hinge's world axis, as Pinocchio places it
    pin.computeJointJacobians(model, data, graph.q)
    axis = pin.getJointJacobian(model, data, model.getJointId("left-foot-op"), pin.WORLD)[3:,
                                                                                        model.joints[model.getJointId(
                                                                                            "left-foot-op")].idx_v]
    axis = axis / np.linalg.norm(axis)
    asked = np.radians([70.0, 60.0, 45.0, 85.0])
    targets = np.zeros((asked.size, 6))
    targets[:, 4] = asked
    q, reached = solve_poses(tree, graph.q, graph.scale, graph.frame_id, targets, graph.task_axes, limits=False)
    assert reached.all()
    for row, pitch in enumerate(asked):
        turned = foot_rotation(tree, graph, q[row])
        np.testing.assert_allclose(rpy_of(turned)[1], pitch, atol=1e-9)
        relative = turned @ home.T  # a rotation about the hinge's world axis, by the pitch's change
        angle = np.arccos(np.clip((np.trace(relative) - 1) / 2, -1, 1))
        assert angle == pytest.approx(abs(pitch - home_pitch), abs=1e-6)
        spin = np.array([relative[2, 1] - relative[1, 2], relative[0, 2] - relative[2, 0],
                         relative[1, 0] - relative[0, 1]]) / (2 * np.sin(angle))
        assert abs(abs(spin @ axis) - 1.0) < 1e-6


def test_a_roll_asked_at_the_gimbal_lock_is_not_reached():
    """Held in roll (the coordinate the rule no longer takes), the foot met any roll at the gimbal lock, where roll
    and yaw are one angle (120 and 170 deg at one configuration): those poses are not reached now; the file's own
    roll still is, where the file has the foot."""
    tree, graph = cassie_foot()
    home = rpy_of(foot_rotation(tree, graph, graph.q))
    targets = np.zeros((3, 6))
    targets[:, 3] = [np.radians(120.0), np.radians(170.0), home[0]]
    q, reached = solve_poses(tree, graph.q, graph.scale, graph.frame_id, targets, (3,), limits=False)
    assert not reached[0] and not reached[1]
    assert reached[2]
    np.testing.assert_allclose(rpy_of(foot_rotation(tree, graph, q[2])), home, atol=1e-9)


# --- its joint limits: the legs' joints, named with their values ------------------------------------------------

def sdf_limits_deg(name: str) -> tuple[float, float]:
    """A joint's <lower>, <upper> as the SDFormat text writes them (rad), in degrees: read with ElementTree alone."""
    import xml.etree.ElementTree as ElementTree

    text = CASSIE.read_text()
    root = ElementTree.fromstring(text[text.index("<sdf"):])
    joint = next(j for j in root.iter("joint") if j.get("name") == name)
    return tuple(float(np.degrees(float(joint.find(f"axis/limit/{tag}").text))) for tag in ("lower", "upper"))


def test_the_file_s_configuration_beyond_the_legs_limits_is_refused_naming_them():
    """The file draws the foot's crank and hinge at 0, outside their limits (-140 to -35 deg): refused naming both,
    with their values and limits as the file writes them; the other leg's joints, also at 0 but moved by nothing,
    are not named (they made every pose of the foot "a joint is beyond its limits")."""
    _, graph = cassie_foot()
    with pytest.raises(ValueError) as refused:
        graph.reading_notes(limits=True)
    message = str(refused.value)
    for name in ("left-tarsus-crank-joint", "left-foot-op"):
        low, high = sdf_limits_deg(name)
        assert f"{name!r} at 0 deg, limits [{low:.6g}, {high:.6g}] deg" in message, message
    assert "right-" not in message and "--initial JOINT VALUE" in message and "--ignore-limits" in message
    notes = graph.reading_notes(limits=False)
    assert any(note.startswith("limits ignored: 'left-tarsus-crank-joint' at 0 deg") for note in notes), notes


def test_a_pose_beyond_the_limits_names_the_joints_and_their_values():
    """Started inside the limits (--initial on the crank), a pitch the foot reaches only past its hinge's upper
    limit is refused naming the hinge, at the value the continuation reached (checked against the configuration
    solved without limits)."""
    tree = read_closed_tree(CASSIE, output="left-foot", actuate=["left-foot-op"], lock=list(HIPS),
                            initial=[("left-tarsus-crank-joint", -80.0)])
    graph = graph_mechanism(tree)
    assert graph.reading_notes(limits=True) == []
    q, reached = graph.solve(np.radians([[80.0]]), limits=False)
    assert reached[0]
    hinge = np.degrees(q[0, tree.model.joints[tree.model.getJointId("left-foot-op")].idx_q])
    assert hinge > sdf_limits_deg("left-foot-op")[1]
    kind, reason = graph.unreachable(np.radians([80.0]))
    assert kind == "joint limit"
    assert f"'left-foot-op' at {hinge:.6g} deg, limits" in reason and "right-" not in reason, reason


def test_the_command_line_refuses_the_file_s_configuration_and_says_where_it_started(tmp_path):
    from helpers import one_line_error, screwkit

    words = ["analyze", CASSIE, "--output", "left-foot", "--actuate", "left-foot-op"]
    for joint in HIPS:
        words += ["--lock", joint]
    one_line_error(screwkit(*words), "cassie_v2.sdf", "'left-foot-op' at 0 deg", "--ignore-limits")
    ignored = screwkit(*words, "--ignore-limits")
    assert ignored.returncode == 0, ignored.stderr
    assert "limits ignored: 'left-tarsus-crank-joint' at 0 deg" in ignored.stderr
    assert "at the file's configuration (pitch = 76.99" in ignored.stdout.splitlines()[0]
    started = screwkit(*words, "--initial", "left-tarsus-crank-joint", "-80")
    assert started.returncode == 0, started.stderr
    assert ("at the configuration assembled from --initial left-tarsus-crank-joint -80 (pitch = "
            in started.stdout.splitlines()[0])


def test_its_legs_and_guesses_are_named_as_the_file_has_them():
    """The foot's leg starts at a ball joint (left-pitch-rod-joint), which the reader writes as three hinges
    ``_x``, ``_y``, ``_z``: the leg is named after its first body, and the actuators guessed when --actuate is
    not given are no such hinge."""
    tree, graph = cassie_foot()
    assert [leg.name for leg in graph.legs] == ["left-achilles-rod"]
    for lock in ((), HIPS):  # guessed as read, and again once the hips are held (the leg's first joint: the ball)
        guessed = read_closed_tree(CASSIE, output="left-foot", lock=list(lock))
        assert guessed.motors and not any(motor in guessed.split for motor in guessed.motors), guessed.motors


def test_a_foot_its_springs_leave_free_names_the_passive_joints_to_lock():
    """With the knee's shin spring left free, the foot moves with its actuator locked: the refusal lists the legs'
    passive joints as the file names them (the ball once, the springs among them), and holding the spring opens it
    (the test above)."""
    from screwkit.io import ImportError_

    tree = read_closed_tree(CASSIE, output="left-foot", actuate=["left-foot-op"], lock=list(HIPS[:-1]))
    with pytest.raises(ImportError_) as refused:
        graph_mechanism(tree)
    message = str(refused.value)
    assert "moves with every actuator locked" in message
    passive = message.split("the legs' passive joints: ")[1].split(")")[0].split(", ")
    assert "left-knee-shin-joint" in passive and "left-pitch-rod-joint" in passive and "left-foot-op" not in passive
    assert not any(name.endswith(("_x", "_y", "_z")) for name in passive), passive


def test_the_serial_stage_advice_says_to_leave_the_named_actuators_out_of_actuate():
    """The hip's motors named with --actuate and suggested for --lock: the advice says to leave them out of
    --actuate (with both, the next run was refused for naming a joint both ways)."""
    from screwkit.io import ImportError_

    hip = ["left-roll-op", "left-yaw-op", "left-pitch-op"]
    tree = read_closed_tree(CASSIE, output="left-foot", actuate=hip + ["left-knee-op", "left-foot-op"])
    with pytest.raises(ImportError_) as refused:
        graph_mechanism(tree)
    assert (f"--lock {' --lock '.join(hip)} analyses the legs on the body they turn (leave {', '.join(hip)} out "
            "of --actuate)") in str(refused.value), str(refused.value)


def test_a_ball_joint_is_locked_by_its_own_name():
    """--lock names a ball joint as the file does: the three hinges the reader wrote for it are held, the same
    model as naming them."""
    ball = "left-pitch-rod-joint"
    by_name = read_closed_tree(CASSIE, output="left-foot", lock=list(HIPS) + [ball])
    hinges = [hinge for hinge in read_closed_tree(CASSIE).split if hinge.startswith(ball + "_")]
    assert sorted(hinges) == [f"{ball}_{axis}" for axis in "xyz"]
    by_hinges = read_closed_tree(CASSIE, output="left-foot", lock=list(HIPS) + hinges)
    assert list(by_name.model.names) == list(by_hinges.model.names)
    assert not any(name.startswith(ball) for name in by_name.model.names)
    np.testing.assert_array_equal(by_name.q_reference, by_hinges.q_reference)


def test_a_ball_named_with_one_of_its_hinges_is_locked_once():
    """--lock the ball and --lock one of the hinges it is read as: held once, the note naming what was given."""
    ball = "left-pitch-rod-joint"
    tree = read_closed_tree(CASSIE, output="left-foot", lock=list(HIPS) + [ball, f"{ball}_x"])
    assert not any(name.startswith(ball) for name in tree.model.names)
    assert any(note.startswith(f"joints {', '.join(HIPS)}, {ball}, {ball}_x locked") for note in tree.notes)


def test_a_pose_met_only_at_the_gimbal_lock_is_refused_saying_so():
    """Held in roll, the foot meets 120 deg only at the gimbal lock: the refusal says that, not that no closed
    configuration was reached."""
    from dataclasses import replace

    _, graph = cassie_foot()
    kind, reason = replace(graph, task_axes=(3,)).unreachable(np.radians([120.0]))
    assert kind == "closure" and "only at a gimbal lock" in reason, reason


def test_view_reads_a_file_beyond_its_limits_with_ignore_limits(tmp_path):
    """`view` refuses the file's configuration beyond its limits, as every command does, and takes --ignore-limits
    (which its refusal advises): the page is written."""
    from helpers import one_line_error, screwkit

    words = ["view", CASSIE, "--output", "left-foot", "--actuate", "left-foot-op"]
    for joint in HIPS:
        words += ["--lock", joint]
    page = tmp_path / "cassie.html"
    one_line_error(screwkit(*words, "--html", page), "cassie_v2.sdf", "--ignore-limits")
    assert not page.exists()
    done = screwkit(*words, "--html", page, "--ignore-limits")
    assert done.returncode == 0, done.stderr
    assert page.stat().st_size > 0 and "limits ignored: 'left-tarsus-crank-joint' at 0 deg" in done.stderr


def test_info_and_a_file_without_actuators_on_the_command_line():
    """`info` counts one actuator in the singular; a file that marks no actuator (Pinocchio's MJCF Cassie, no
    <actuator>) is refused in one line listing the joints --actuate can name, its foot crank among them."""
    from helpers import one_line_error, screwkit

    words = ["info", CASSIE, "--output", "left-foot", "--actuate", "left-foot-op",
             "--initial", "left-tarsus-crank-joint", "-80"]  # (started inside the crank's limits)
    for joint in HIPS:
        words += ["--lock", joint]
    shown = screwkit(*words)
    assert shown.returncode == 0, shown.stderr
    assert "  1 actuator: " in shown.stdout, shown.stdout
    pinocchio_cassie = CASSIE.parents[1] / "pinocchio_closed_chain" / "closed_chain.xml"
    message = one_line_error(screwkit("info", pinocchio_cassie), "closed_chain.xml", "no <actuator> drives a joint")
    listed = message.rsplit("revolute or prismatic: ", 1)[1].removesuffix(").").split(", ")
    assert "left-foot-crank" in listed and "left-plantar-rod" in listed, listed
