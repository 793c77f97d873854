"""A leg driven by one hinge of a universal joint: the ITI's characteristic point on the actuation wrench.

Gepetto's ``custom_1`` (``tests/data/gallery/published``, BSD-3-Clause) has three legs R-R-S under a foot: a hip
(held), a motor whose hinge meets the knee's at one point O (a universal joint written as two revolutes), a shank to
a ball S on the foot. The leg carries a constraint force along the shank (through O and S) and, as actuation
wrench, the force through S reciprocal to the knee and orthogonal to that constraint (moments about the leg's
platform joint S): along ``f = k - (k . d) d`` (k the knee's axis, d the shank's direction). The paper rotates a
wrench about a characteristic point *on* it (Sec. 2, Eq. 5): the knee's point O, where the rest of the leg meets
the motor's link, is on the motor's own axis and off that force, so the ITI read there was 0 at every pose, without
a word; projected on the force it is S, and ITI = |f . v_S| / (|f| |v_S|), v_S = a x (S - O) for the motor's axis a.

Checked on the model Gepetto's own loader builds (``tests/gepetto_loader.py``), closed by scipy with the motors at
the values screwkit assembles, as written (where the knees are square to the motors and the shanks: ITI 1) and with
the three knees' axes tilted in their joint frames (the same points, the same assembly at the file's
configuration; ITI below 1); and the same in millimetres, in a moved world and with the robot.yaml listed back.

As written, its hips driven too, it opens with six motors (the foot hangs on the first leg's ball, that leg's loop
joint): against the force lines of each leg through its ball, on Gepetto's own model.
"""

from __future__ import annotations

import json
import re

import numpy as np
import pinocchio as pin
import pytest
import yaml
from gepetto_loader import gepetto_model
from rod_lines import closed_by_scipy, joint_line
from test_axis_points import revolutes_moved
from test_gallery_published import GEPETTO
from test_gepetto_joint_types import variants

from helpers import leg_line_otis, screwkit
from screwkit.io import graph_mechanism, read_closed_tree
from screwkit.io.loader import load
from screwkit.studies import indices_at_pose

CUSTOM = GEPETTO / "custom_1"
HIPS = ("mot_1", "mot_3", "mot_4")
LEGS = {"mot_2": ("free_knee1", "to_rotule_1"), "mot_6": ("free_knee3", "to_rotule_3"),
        "mot_5": ("free_knee2", "to_rotule_2")}  # each motor: its knee, its ball on the foot


def tilted(tmp_path, axis: str = "0.45 -0.3 1"):
    """custom_1 with every knee's axis written ``axis`` in its joint frame (the knee's point stays on the motor's
    axis: still a universal joint, oblique)."""
    tmp_path.mkdir(parents=True, exist_ok=True)
    text = (CUSTOM / "robot.urdf").read_text()
    for knee, _ in LEGS.values():
        text, count = re.subn(rf'(<joint name="{knee}" type="revolute">.*?<axis xyz=")0 0 1(")', rf"\g<1>{axis}\g<2>",
                              text, count=1, flags=re.S)
        assert count == 1, knee
    (tmp_path / "robot.urdf").write_text(text)
    (tmp_path / "robot.yaml").write_text((CUSTOM / "robot.yaml").read_text())
    return tmp_path / "robot.urdf"


def screwkit_itis(path, **options):
    """screwkit's ITI of each motor (by joint name) and the motors' values at the file's configuration."""
    graph = graph_mechanism(read_closed_tree(path, lock=HIPS, **options))  # (a ball inside each leg: a graph)
    result = graph.indices()
    itis = {name.split(":")[-1]: float(value) for name, value in zip(result.actuators, result.iti_actuators)}
    motors = {name.split(":")[-1]: value for name, value in result.joint_values.items()
              if name.split(":")[-1] in LEGS}
    return itis, motors, result


def force_line_itis(path, motors: dict[str, float]) -> dict[str, float]:
    """Each motor's ITI from the leg's lines alone, on Gepetto's own reading of ``path`` closed by scipy with the
    hips at 0 and the motors at ``motors``."""
    model = gepetto_model(path, path.parent / "robot.yaml")
    spec = yaml.safe_load((path.parent / "robot.yaml").read_text())
    pairs = [(model.getFrameId(a), model.getFrameId(b)) for a, b in spec["closed_loop"]]
    data, _ = closed_by_scipy(model, pairs, {name: 0.0 for name in HIPS} | motors)
    itis = {}
    for motor, (knee, ball) in LEGS.items():
        origin, a = joint_line(model, data, motor)
        o, k = joint_line(model, data, knee)
        s = data.oMi[model.getJointId(ball)].translation
        assert abs(np.dot(o - origin, np.cross(a, k))) < 1e-9 and np.linalg.norm(np.cross(a, k)) > 0.1  # they meet
        d = (s - o) / np.linalg.norm(s - o)
        f = k - (k @ d) * d
        v = np.cross(a, s - o)
        itis[motor] = abs(f @ v) / (np.linalg.norm(f) * np.linalg.norm(v))
    return itis


@pytest.mark.parametrize("knees", ["as written", "tilted"])
def test_a_motor_that_is_one_hinge_of_a_universal_joint_has_the_force_line_iti(tmp_path, knees):
    path = CUSTOM / "robot.urdf" if knees == "as written" else tilted(tmp_path)
    itis, motors, result = screwkit_itis(path)
    assert sorted(motors) == sorted(LEGS) and result.dof == 3
    expected = force_line_itis(path, motors)
    for motor in LEGS:
        assert itis[motor] == pytest.approx(expected[motor], abs=1e-9), motor
    if knees == "tilted":
        assert all(0.05 < value < 0.99 for value in itis.values()), itis  # neither singular nor trivially 1
    else:
        assert all(value == pytest.approx(1.0, abs=1e-9) for value in itis.values()), itis


def test_the_oblique_universal_input_is_the_same_in_millimetres_in_a_moved_world_and_listed_back(tmp_path):
    (tmp_path / "tilted").mkdir()
    path = tilted(tmp_path / "tilted")
    itis, motors, result = screwkit_itis(path)
    for name, other_path, options in variants(path, tmp_path):
        other, other_motors, other_result = screwkit_itis(other_path, **options)
        assert other == pytest.approx(itis, abs=1e-9), name
        assert other_motors == pytest.approx(motors, abs=1e-8), name
        assert other_result.lmti == pytest.approx(result.lmti, abs=1e-9), name


def test_a_weld_open_in_rotation_alone_says_its_angle_as_gepetto_s_model_has_it():
    """custom_1's two welds are drawn with their origins together and their frames turned apart: the report said
    "gap 2e-14 m" alone, as if they were closed; it now says the angle too, the one Gepetto's own model has between
    the two frames at the file's joint values (all zero)."""
    result = screwkit("info", CUSTOM / "robot.urdf", *[f"--lock={name}" for name in HIPS])
    assert result.returncode == 0, result.stderr
    model = gepetto_model(CUSTOM / "robot.urdf", CUSTOM / "robot.yaml")
    data = model.createData()
    pin.framesForwardKinematics(model, data, pin.neutral(model))
    spec = yaml.safe_load((CUSTOM / "robot.yaml").read_text())
    for first, second in spec["closed_loop"]:
        a, b = (data.oMf[model.getFrameId(name)] for name in (first, second))
        angle = np.degrees(np.linalg.norm(pin.log3(a.rotation.T @ b.rotation)))
        assert angle > 1.0
        line = next(line for line in result.stdout.splitlines() if line.strip().startswith(f"closure {first}-{second}")
                    or line.strip().startswith(f"closure {second}-{first}"))
        assert f" and {angle:.3g} deg at the file's joint values" in line, (angle, line)


def transversal(point, first, second):
    """The line through ``point`` that meets the lines ``first`` and ``second`` (origin, unit axis): its unit
    direction, and the point where it crosses ``first``."""
    n1, n2 = (np.cross(axis, origin - point) for origin, axis in (first, second))
    direction = np.cross(n1, n2) / np.linalg.norm(np.cross(n1, n2))
    (along, _), *_ = np.linalg.lstsq(np.column_stack([direction, -first[1]]), first[0] - point, rcond=None)
    return direction, point + along * direction


def six_motor_indices(path, values: dict[str, float]):
    """custom_1 with its hips driven too, on Gepetto's own reading of ``path`` closed by scipy with the six motors at
    ``values``. In each leg (hip H, motor M, knee K, ball S on the foot) every actuation wrench is a force through S
    reciprocal to the leg's other hinges: the hip's meets M's and K's axes, the motor's H's and K's. Each ITI is
    |u . v_c| / |v_c|, c where the force crosses the hinge after its actuator (M for the hip, K for the motor: where
    the rest of the leg meets the link the actuator turns), v_c = a x (c - o) about the actuator's axis; the OTIs are
    the leg-line OTIs of the six forces at their balls (numpy alone)."""
    model = gepetto_model(path, path.parent / "robot.yaml")
    spec = yaml.safe_load((path.parent / "robot.yaml").read_text())
    pairs = [(model.getFrameId(a), model.getFrameId(b)) for a, b in spec["closed_loop"]]
    data, _ = closed_by_scipy(model, pairs, values)
    itis, starts, ends, names = {}, [], [], []
    for hip, (motor, (knee, ball)) in zip(HIPS, LEGS.items()):
        lines = {name: joint_line(model, data, name) for name in (hip, motor, knee)}
        s = data.oMi[model.getJointId(ball)].translation.copy()
        for driver, after, other in ((hip, motor, knee), (motor, knee, hip)):
            direction, c = transversal(s, lines[after], lines[other])
            origin, axis = lines[driver]
            v = np.cross(axis, c - origin)
            itis[driver] = abs(direction @ v) / np.linalg.norm(v)
            starts.append(c)
            ends.append(s)
            names.append(driver)
    return itis, dict(zip(names, leg_line_otis(starts, ends)))


def six_motors(path, **options):
    """screwkit's ITI and OTI of each motor (by joint name), the LMTI, and the motors' values, as written."""
    mechanism = load(path, **options)
    result = indices_at_pose(mechanism, mechanism.home_pose)
    names = [name.split(":")[-1] for name in mechanism.actuator_names]
    values = {name.split(":")[-1]: value for name, value in result.joint_values.items() if name.split(":")[-1] in names}
    return (dict(zip(names, np.ravel(result.iti_actuators))), dict(zip(names, np.ravel(result.oti_actuators[0]))),
            float(result.lmti), values, result.dof)


def test_the_robot_opens_as_written_with_six_motors_on_three_r_r_r_s_legs(tmp_path):
    """As written, its hips driven: six motors on three R-R-R-S legs, the foot in six DoF. Before, the foot's hanging
    on the first leg's ball made that leg's path "a leg with loops inside it and 2 actuators", refused with the
    advice to hold the hips; the ball is now that leg's loop joint, as the other legs' are. Against the force lines of
    Gepetto's own model closed at the motors' values; in millimetres, in a moved world and listed back; from the
    command line; and with the hips held it still opens."""
    itis, otis, lmti, values, dof = six_motors(CUSTOM / "robot.urdf")
    assert sorted(itis) == sorted(HIPS + tuple(LEGS)) and dof == 6
    expected_itis, expected_otis = six_motor_indices(CUSTOM / "robot.urdf", values)
    assert itis == pytest.approx(expected_itis, abs=1e-9)
    assert otis == pytest.approx(expected_otis, abs=1e-9)
    assert lmti == pytest.approx(min(expected_otis.values()), abs=1e-9)
    assert 0.05 < min(itis.values()) and max(otis.values()) < 0.99  # neither singular nor trivially 1
    for name, other_path, options in variants(CUSTOM / "robot.urdf", tmp_path):
        other = six_motors(other_path, **options)
        assert other[0] == pytest.approx(itis, abs=1e-9), name
        assert other[1] == pytest.approx(otis, abs=1e-9), name
        assert other[3] == pytest.approx(values, abs=1e-8), name
    printed = json.loads(screwkit("analyze", CUSTOM / "robot.urdf", "--json").stdout)
    assert [printed["iti"], printed["lmti"]] == pytest.approx([min(expected_itis.values()), lmti], abs=1e-9)
    held = screwkit("info", CUSTOM / "robot.urdf", *[f"--lock={name}" for name in HIPS])
    assert held.returncode == 0, held.stderr


@pytest.mark.parametrize("joint, distance", [("free_knee1", 0.05), ("free_knee3", -0.2), ("mot_6", 0.1),
                                             ("mot_5", -0.04)])  # hinges only: a ball robot.yaml makes turns about
# its origin, and moved it is another mechanism
def test_a_joint_drawn_elsewhere_along_its_axis_changes_no_index(tmp_path, joint, distance):
    """The same robot with one joint drawn elsewhere on its line (its child's joints moved back): the knee's drawn
    point, projected on the actuation force, moved the ITI point along the force (0.9876 for 1 with the first knee
    5 cm along); the points are now where the hinges meet."""
    itis, motors, result = screwkit_itis(tilted(tmp_path / "as drawn"))
    (tmp_path / "moved").mkdir()
    text = revolutes_moved((tmp_path / "as drawn" / "robot.urdf").read_text(), {joint: distance})
    (tmp_path / "moved" / "robot.urdf").write_text(text)
    (tmp_path / "moved" / "robot.yaml").write_text((CUSTOM / "robot.yaml").read_text())
    other, other_motors, other_result = screwkit_itis(tmp_path / "moved" / "robot.urdf")
    assert other == pytest.approx(itis, abs=1e-9) and other_motors == pytest.approx(motors, abs=1e-8)
    for name in ("oti_actuators", "lmti"):  # (the CTI: see test_gepetto_marcheurs' drawing test)
        np.testing.assert_allclose(getattr(other_result, name), getattr(result, name), atol=1e-9, err_msg=name)
