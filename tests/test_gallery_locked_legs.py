"""Gepetto's walking-robot legs (example-parallel-robots, BSD-3-Clause, ``tests/data/gallery/published``): the
parallel ankle under a serial leg, analysed with the leg held by ``--lock``.

``digit_like`` (a hip of three motors, a knee motor driving the shin through a four-bar, and a two-rod ankle) and
``cassie_like`` (the same with a one-rod plantar four-bar) write their knee four-bar open: the passive ``free_knee``
is 0 in the file, where its loop misses by 5-6 cm. screwkit's own messages lead a user to lock the hip and knee
motors and then ``free_knee``; locked at the file's 0 the loop could never close, and the file was refused. A
locked passive joint inside a loop is now held where the loops close with the other locked joints and the motors
held (:func:`screwkit.io.locking.lock_joints`).

Checked with Pinocchio and scipy alone: every loop of the file closed by scipy's least squares with the locked
motors at the file's 0 and the ankle's motors at the values screwkit reports gives ``free_knee`` where screwkit
holds it, and at that configuration the ankle's indices from the rod lines: the actuation wrench of a crank-rod leg
is the force along its rod through the rod's ball centres, ITI = |f . v_crank| / |v_crank| at the crank's ball, and
OTI = |f . v| / |v| at the rod's platform ball, v from the foot twist reciprocal to the other rod's force in the
foot's motion space (its two hinges for digit's ankle, its hinge for cassie's).
"""

from __future__ import annotations

import json
import re
import shutil

import numpy as np
import pinocchio as pin
import pytest
import yaml
from rod_lines import closed_by_scipy, joint_line, two_rod_indices
from scipy.spatial.transform import Rotation
from test_gallery_published import GEPETTO, PUBLISHED

from helpers import one_line_error, screwkit
from screwkit.io import read_mechanism_file
from screwkit.io.loader import load
from screwkit.studies import indices_at_pose

TOLERANCE = 1e-9
DIGIT_LOCKS = ("motor_hip_x", "motor_hip_y", "motor_hip_z", "motor_knee", "free_knee")
CASSIE_LOCKS = ("motor_hip1", "motor_hip2", "motor_tigh", "motor_knee", "free_knee")


def closed_from_file(path, held: dict[str, float]) -> tuple[object, object, np.ndarray]:
    """The file's tree (Pinocchio's own reading) with every loop of its robot.yaml closed by scipy's least squares
    over the joints not ``held`` (those at the given values), from the file's zero configuration."""
    model = pin.buildModelFromUrdf(str(path))
    spec = yaml.safe_load((path.parent / "robot.yaml").read_text())
    data, q = closed_by_scipy(model, [(model.getFrameId(a), model.getFrameId(b)) for a, b in spec["closed_loop"]],
                              held)
    return model, data, q


def analysed(path, locks):
    """screwkit's indices at the file's home pose with ``locks`` held, its actuators' values (rad) and the value it
    holds free_knee at (from the import report)."""
    mechanism = load(path, lock=locks)
    result = indices_at_pose(mechanism, mechanism.home_pose)
    values = {name.split(":")[-1]: value for name, value in result.joint_values.items()}
    motors = {name.split(":")[-1]: values[name.split(":")[-1]] for name in result.actuators}
    _, report = read_mechanism_file(path, lock=locks)
    note = next(note for note in report.notes if note.startswith("joint free_knee (passive, inside a loop) locked"))
    return result, motors, float(note.split(" locked at ")[1].split(",")[0])


def rod_force(model, data, crank_ball: str, platform_ball: str):
    crank, _ = joint_line(model, data, crank_ball)
    end, _ = joint_line(model, data, platform_ball)
    return (end - crank) / np.linalg.norm(end - crank), crank, end


def test_digit_s_ankle_with_its_leg_locked_has_the_rod_line_indices():
    path = GEPETTO / "digit_like" / "robot.urdf"
    result, motors, knee = analysed(path, DIGIT_LOCKS)
    assert sorted(motors) == ["motor_shin1", "motor_shin2"] and result.dof == 2
    held = {name: 0.0 for name in DIGIT_LOCKS[:4]} | motors
    model, data, q = closed_from_file(path, held)
    assert q[model.joints[model.getJointId("free_knee")].idx_q] == pytest.approx(knee, abs=1e-8)
    assert knee == pytest.approx(0.7163546, abs=1e-6)  # (what the file writes: 0)
    legs = {"motor_shin1": ("crank_toe_b_2/2_rev0", "foot_part_toe_b_1/2_2_rev0"),
            "motor_shin2": ("crank_2_toe_b_2/2_2_rev0", "foot_part_toe_b_1/2_rev0")}
    itis, otis = two_rod_indices(model, data, legs, ("free_foot1", "free_foot2"))
    order = [name.split(":")[-1] for name in result.actuators]
    assert order == sorted(motors)
    np.testing.assert_allclose(result.iti_actuators, itis, atol=TOLERANCE)
    np.testing.assert_allclose(result.oti_actuators[0], otis, atol=TOLERANCE)
    np.testing.assert_allclose(result.lmti, min(otis), atol=TOLERANCE)


def test_cassie_s_plantar_four_bar_with_its_leg_locked_has_the_rod_line_indices():
    path = GEPETTO / "cassie_like" / "robot.urdf"
    result, motors, knee = analysed(path, CASSIE_LOCKS)
    assert list(motors) == ["motor_ankle"] and result.dof == 1
    model, data, q = closed_from_file(path, {name: 0.0 for name in CASSIE_LOCKS[:4]} | motors)
    assert q[model.joints[model.getJointId("free_knee")].idx_q] == pytest.approx(knee, abs=1e-8)
    force, crank, end = rod_force(model, data, "servo_gauche_half_planta_rode_rev0", "foot_2_half_planta_rode_2_rev0")
    origin, axis = joint_line(model, data, "motor_ankle")
    foot, hinge = joint_line(model, data, "free_ankle")
    at_crank, at_foot = np.cross(axis, crank - origin), np.cross(hinge, end - foot)
    np.testing.assert_allclose(result.iti_actuators, [abs(force @ at_crank) / np.linalg.norm(at_crank)],
                               atol=TOLERANCE)
    np.testing.assert_allclose(result.lmti, abs(force @ at_foot) / np.linalg.norm(at_foot), atol=TOLERANCE)


@pytest.mark.parametrize("robot, locks, dof, knee", [("digit_like", DIGIT_LOCKS, 2, "0.716354"),
                                                     ("cassie_like", CASSIE_LOCKS, 1, "1.810794")])
def test_the_command_line_follows_its_own_lock_suggestions_to_the_ankle(robot, locks, dof, knee):
    """Each refusal names the next joint to lock (cassie's last one named none: its motor "moves inside a loop");
    with all five the ankle is analysed, and the report says where free_knee is held."""
    path = GEPETTO / robot / "robot.urdf"
    for count, name in enumerate(locks):
        held = [part for lock in locks[:count] for part in ("--lock", lock)]
        refused = screwkit("info", path, *held)
        assert refused.returncode == 1 and f"--lock {name} " in refused.stderr.splitlines()[-1], refused.stderr
    held = [part for lock in locks for part in ("--lock", lock)]
    done = screwkit("analyze", path, *held, "--json")
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout)["dof"] == dof
    info = screwkit("info", path, *held)
    assert f"joint free_knee (passive, inside a loop) locked at {knee}" in info.stdout


def test_a_lock_on_a_file_whose_loop_closes_with_the_locked_joint_where_written_keeps_it_there(tmp_path):
    """Gepetto's five-bar with mot1's crank turned 2.5 rad in the file (written open, 1.9 m apart): the loop closes
    with free1 held at the file's 0 and the motors moved, so --lock free1 holds it there, as before the rule above
    (which first held the motors too, where no free1 closes it, and refused the file)."""
    source = GEPETTO / "5bar_linkage"
    text = (source / "robot.urdf").read_text()
    head = '<joint name="mot1" type="revolute">'
    start = text.index('rpy="', text.index(head)) + len('rpy="')
    end = text.index('"', start)
    turned = Rotation.from_euler("xyz", np.array(text[start:end].split(), dtype=float)) * Rotation.from_euler(
        "z", 2.5)
    path = tmp_path / "robot.urdf"
    path.write_text(text[:start] + " ".join(repr(float(v)) for v in turned.as_euler("xyz")) + text[end:])
    (tmp_path / "robot.yaml").write_text((source / "robot.yaml").read_text())
    mechanism = load(path, lock=("free1",))
    result = indices_at_pose(mechanism, mechanism.home_pose)
    assert mechanism.dof == 1 and result.iti > 0.5
    _, report = read_mechanism_file(path, lock=("free1",))
    assert not any("inside a loop) locked at" in note for note in report.notes)  # free1 kept at the file's 0
    model, data, q = closed_from_file(path, {"free1": 0.0, **{
        name.split(":")[-1]: value for name, value in result.joint_values.items() if name.split(":")[-1] in
        ("mot1", "mot2")}})
    assert q[model.joints[model.getJointId("free1")].idx_q] == 0.0  # and the loop closes there (scipy, above)


def test_links_named_after_their_joints_lock_the_same(tmp_path):
    """MuJoCo names a body after its joint, and a URDF may name a link so: the model then has a body frame and a joint
    frame of one name, and Pinocchio's reduced model (which finds frames by name) refused the lock with its own
    "Several frames match the filter" and no file named. digit_like with each locked joint's child link renamed to
    the joint's name is the same robot: the same five locks give the same indices, and the renamed links keep their
    names (the output body named after its joint is found)."""
    source = GEPETTO / "digit_like"
    renamed = {"hip_y": "motor_hip_x", "hip_x": "motor_hip_y", "hip_z": "motor_hip_z", "shin": "motor_knee",
               "tarsus": "free_knee"}
    text = (source / "robot.urdf").read_text()
    for old, new in renamed.items():
        text = re.sub(rf'(link|name)="{old}"', rf'\1="{new}"', text)
    assert all(text.count(f'"{new}"') >= 3 for new in renamed.values())  # a link, its joint, its child reference
    (tmp_path / "robot.urdf").write_text(text)
    shutil.copy(source / "robot.yaml", tmp_path / "robot.yaml")
    held = [part for lock in DIGIT_LOCKS for part in ("--lock", lock)]
    results = []
    for path in (source / "robot.urdf", tmp_path / "robot.urdf"):
        done = screwkit("analyze", path, *held, "--json")
        assert done.returncode == 0, done.stderr
        results.append(json.loads(done.stdout))
    original, named = results
    for key in ("dof", "actuators", "pose", "iti", "lmti", "f_o", "f_io", "cti", "f_c", "iti_actuators",
                "worst_faults"):
        assert json.dumps(named[key]) == json.dumps(original[key]), key  # the same numbers as written
    one_line_error(screwkit("info", tmp_path / "robot.urdf", *held[:-2]), "--lock free_knee")


def test_menageries_cassie_takes_a_lock_on_a_joint_named_as_its_body():
    """MuJoCo Menagerie's Cassie names each body after its joint: ``--lock left-hip-roll`` was Pinocchio's "Several
    frames match the filter"; it is now held, and the next refusal is screwkit's own line about the legs."""
    refused = screwkit("info", PUBLISHED / "agility_cassie" / "cassie.xml", "--output", "left-foot", "--lock",
                       "left-hip-roll")
    one_line_error(refused, "cassie.xml: leg 'cassie-pelvis' has loops inside it")
    assert "Several frames" not in refused.stderr
