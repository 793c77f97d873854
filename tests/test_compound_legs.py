"""Compound legs: legs joined to each other by closures that do not touch the platform (``screwkit.io.compound``).

The mechanism is a planar parallelogram Delta written here the way Gepetto writes ``robot_delta``:
a URDF tree plus a robot.yaml of ``6d`` welds between coaxial closure pins. Leg 1 (A0 -> A1 -> E0,
the effector hanging from its last joint) and rod 2 (B0 -> B1 -> E0) form a five-bar; the passive
rod 3 (C0 -> C1, a link pinned to rod 2 at B1 and carrying P, then P -> E1 on the effector) closes
two parallelograms, B0 C0 C1 B1 and B1 P E1 E0, so the effector only translates.

The indices are checked against the pressure angles of the **original tree**, closed by Pinocchio
at the actuator values screwkit solved (its joint positions, not screwkit's chains): ITI_i =
|sin(input link, distal link)| and OTI = |sin(distal link 1, distal link 2)|.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from test_io import mjcf_of_tree

from helpers import random_rotation, screwkit
from screwkit.closure import actuator_values, solve
from screwkit.io import ImportError_, read_gepetto, read_mechanism_file
from screwkit.io.closed_tree import assemble, joint_kind
from screwkit.io.loader import load
from screwkit.studies.poses import indices_at_poses

TOLERANCE = 1e-9
A0, B0 = np.array([-0.1, 0.0]), np.array([0.1, 0.0])
PROXIMAL, DISTAL = 0.2, 0.3
OFFSET_C, OFFSET_P = np.array([0.04, 0.03]), np.array([0.05, -0.02])  # C0 - B0 and P - B1


def delta_points(distort: float = 0.0) -> dict[str, np.ndarray]:
    """Joint positions (plane z = 0) at the file's configuration; ``distort`` lengthens rod 3's first link."""
    a1 = A0 + PROXIMAL * np.array([np.cos(-2 * np.pi / 3), np.sin(-2 * np.pi / 3)])
    b1 = B0 + PROXIMAL * np.array([np.cos(-np.pi / 3), np.sin(-np.pi / 3)])
    e0 = np.array([0.0, a1[1] - np.sqrt(DISTAL**2 - (b1[0] - a1[0]) ** 2 / 4)])
    c0 = B0 + OFFSET_C
    c1 = b1 + OFFSET_C + np.array([distort, 0.0])
    p = b1 + OFFSET_P
    return {"A0": A0, "A1": a1, "E0": e0, "B0": B0, "B1": b1, "C0": c0, "C1": c1, "P": p, "E1": e0 + OFFSET_P,
            "effector": e0 + np.array([0.0, -0.05])}


def delta_gepetto(rotation=None, scale: float = 1.0, opening: float = 0.0, distort: float = 0.0,
                  couple_only: bool = False, motors=("mot1_rod1", "mot1_rod2"), idle_loop: bool = False
                  ) -> tuple[str, str]:
    """The parallelogram Delta as a Gepetto-style URDF tree and robot.yaml (every joint frame world-aligned).

    ``rotation``/``scale`` move the whole mechanism; ``opening`` (rad) turns both motors' origins, so q = 0
    leaves the loops open; ``couple_only`` drops rod 3's second half (P, E1): rod 3 is then a dyad pinned
    to rod 2 at B1, which constrains nothing; ``idle_loop`` adds two rods from the base pinned to each other
    (a loop that reaches no leg).
    """
    rotation = np.eye(3) if rotation is None else rotation
    points = delta_points(distort)
    axis = " ".join(repr(float(v)) for v in rotation @ np.array([0.0, 0.0, 1.0]))
    # (joint, parent joint, point, type): a joint's child link is "<joint>_link"
    joints = [("mot1_rod1", None, "A0", "revolute"), ("free1_rod1", "mot1_rod1", "A1", "revolute"),
              ("free2_rod1", "free1_rod1", "E0", "revolute"), ("effector", "free2_rod1", "effector", "fixed"),
              ("closedloop2_B", "free2_rod1", "E0", "revolute"),
              ("mot1_rod2", None, "B0", "revolute"), ("free1_rod2", "mot1_rod2", "B1", "revolute"),
              ("closedloop1_B", "free1_rod2", "B1", "revolute"), ("closedloop2_A", "free1_rod2", "E0", "revolute"),
              ("free1_rod3", None, "C0", "revolute"), ("free2_rod3", "free1_rod3", "C1", "revolute"),
              ("closedloop1_A", "free2_rod3", "B1", "revolute")]
    closures = [("closedloop1_A", "closedloop1_B"), ("closedloop2_B", "closedloop2_A")]
    if not couple_only:
        joints += [("closedloop3_B", "free2_rod1", "E1", "revolute"), ("free3_rod3", "free2_rod3", "P", "revolute"),
                   ("closedloop3_A", "free3_rod3", "E1", "revolute")]
        closures.append(("closedloop3_A", "closedloop3_B"))
    if idle_loop:
        points = dict(points, X0=np.array([-0.3, 0.0]), Y0=np.array([-0.5, 0.0]), Q=np.array([-0.4, -0.1]))
        joints += [("idle_a", None, "X0", "revolute"), ("idle_a_pin", "idle_a", "Q", "revolute"),
                   ("idle_b", None, "Y0", "revolute"), ("idle_b_pin", "idle_b", "Q", "revolute")]
        closures.append(("idle_a_pin", "idle_b_pin"))
    where = {name: point for name, _, point, _ in joints}
    links, elements = ['<link name="built"/>'], []
    for name, parent, point, kind in joints:
        start = np.zeros(2) if parent is None else points[where[parent]]
        xyz = rotation @ (scale * np.append(points[point] - start, 0.0))
        yaw = opening if name.startswith("mot") else 0.0
        links.append(f'<link name="{name}_link"/>')
        elements.append(
            f'<joint name="{name}" type="{kind}"><parent link="{"built" if parent is None else parent + "_link"}"/>'
            f'<child link="{name}_link"/><origin xyz="{" ".join(repr(float(v)) for v in xyz)}" rpy="0 0 {yaw!r}"/>'
            f'<axis xyz="{"0 0 0" if kind == "fixed" else axis}"/>'
            + ('<limit effort="1" velocity="1"/>' if kind == "revolute" else "") + "</joint>")
    urdf = '<?xml version="1.0"?><robot name="delta">' + "".join(links + elements) + "</robot>"
    yaml = (f"closed_loop: {json.dumps([list(pair) for pair in closures])}\n"
            f"type: {json.dumps(['6d'] * len(closures))}\nname_mot: {json.dumps(list(motors))}\n")
    return urdf, yaml


def write(tmp_path, urdf: str, yaml: str):
    (tmp_path / "robot.urdf").write_text(urdf)
    (tmp_path / "robot.yaml").write_text(yaml)
    return tmp_path / "robot.urdf"


def closed_tree_at(tree, q, motors: dict[str, float]) -> np.ndarray:
    """The tree closed (Gauss-Newton on every joint but the motors, held at ``motors``), starting from q; the gaps
    are measured relative to the tree's size."""
    import pinocchio as pin

    model = tree.model
    data = model.createData()
    q = q.copy()
    held = []
    for name, value in motors.items():
        joint = model.joints[model.getJointId(name)]
        q[joint.idx_q] = value
        held.append(joint.idx_v)
    free = [i for i in range(model.nv) if i not in held]
    size = max(np.linalg.norm(placement.translation) for placement in model.jointPlacements)

    def residual(at):
        """Gaps in units of the tree's longest joint offset (the file may be in any unit), rotations."""
        pin.forwardKinematics(model, data, at)
        rows = []
        for closure in tree.closures:
            a = data.oMi[closure.joint_a].homogeneous @ closure.placement_a
            b = data.oMi[closure.joint_b].homogeneous @ closure.placement_b
            rows += [(b[:3, 3] - a[:3, 3]) / size, (b[:3, :3] - a[:3, :3]).ravel()]
        return np.concatenate(rows)

    for _ in range(50):
        error = residual(q)
        if np.linalg.norm(error) < 1e-13:
            break
        jacobian = np.zeros((error.size, model.nv))
        for i in free:
            step = np.zeros(model.nv)
            step[i] = 1e-7
            jacobian[:, i] = (residual(pin.integrate(model, q, step)) - residual(pin.integrate(model, q, -step))) / 2e-7
        q = pin.integrate(model, q, -np.linalg.lstsq(jacobian, error, rcond=None)[0])
    assert np.linalg.norm(residual(q)) < 1e-11
    return q


def tree_pressure_angles(tree, q) -> tuple[np.ndarray, float]:
    """(ITI of both motors, OTI) from the tree's joint positions at q, in the plane across the first motor's axis
    (a file may draw its links at several depths along the pins, as Gepetto's ``robot_delta`` does)."""
    import pinocchio as pin

    model = tree.model
    data = model.createData()
    pin.forwardKinematics(model, data, q)
    motor = model.getJointId("mot1_rod1")
    normal = np.asarray(data.oMi[motor].rotation) @ joint_kind(model, motor)[1]
    across = np.eye(3) - np.outer(normal, normal) / (normal @ normal)

    def at(name):
        return across @ np.asarray(data.oMi[model.getJointId(name)].translation)

    def sine(u, v):
        return float(np.linalg.norm(np.cross(u, v)) / (np.linalg.norm(u) * np.linalg.norm(v)))

    a0, a1, e0 = at("mot1_rod1"), at("free1_rod1"), at("free2_rod1")
    b0, b1, e0b = at("mot1_rod2"), at("free1_rod2"), at("closedloop2_A")
    return np.array([sine(a1 - a0, e0 - a1), sine(b1 - b0, e0b - b1)]), sine(e0 - a1, e0b - b1)


def poses_near_home(mechanism, count=8, spread=0.03, seed=5):
    return mechanism.home_pose + np.random.default_rng(seed).uniform(-spread, spread, (count, 2))


def tree_pressure_angles_at(mechanism, path, poses) -> tuple:
    """The indices of ``mechanism`` at ``poses`` (every one reached), and per pose the pressure angles (ITI of each
    motor, OTI) of the tree of ``path`` (URDF + yaml) closed by Pinocchio at the same actuator values."""
    solution = solve(mechanism, poses)
    assert solution.reachable.all()
    result = indices_at_poses(mechanism, poses, detail=True)
    motors = actuator_values(mechanism, solution.joint_values)
    names = [name.split(":")[-1] for name in mechanism.actuator_names]
    tree = read_gepetto(path, path.parent / "robot.yaml")
    q, _ = assemble(tree)
    angles = [tree_pressure_angles(tree, closed_tree_at(tree, q, dict(zip(names, motors[k]))))
              for k in range(poses.shape[0])]
    return result, angles


def assert_tree_pressure_angles(mechanism, path, poses):
    """The indices at ``poses`` equal the pressure angles of the tree of ``path`` (URDF + yaml) closed at the same
    actuator values."""
    result, angles = tree_pressure_angles_at(mechanism, path, poses)
    for k, (iti, oti) in enumerate(angles):
        np.testing.assert_allclose(result.iti_actuators[k], iti, atol=TOLERANCE)
        np.testing.assert_allclose([result.lmti[k], *result.oti_submechanisms[k]], [oti, oti], atol=TOLERANCE)
    return result


def test_a_parallelogram_leg_opens_and_gives_the_pressure_angles_of_the_original_tree(tmp_path):
    path = write(tmp_path, *delta_gepetto(opening=0.2))
    _, report = read_mechanism_file(path)
    assert all(gap > 0.01 for gap in report.gaps_before.values()), report.gaps_before  # q = 0 is open
    assert any("compound leg joined by closure 'closedloop1_A-closedloop1_B': twist system of dimension 2 (no "
               "rotation beyond translations)" in note and "passive legs free1_rod3 written as the equivalent "
               "constraint chain free1_rod3_equivalent" in note for note in report.notes), report.notes
    mechanism = load(path)
    assert mechanism.is_planar and mechanism.dof == 2 and mechanism.task_coordinates == ("x", "y")
    assert [chain.name for chain in mechanism.chains] == ["free1_rod3_equivalent", "mot1_rod1", "mot1_rod2"]  # by name
    assert mechanism.chains[0].actuated == () and mechanism.chains[0].prismatic == (True, True)
    result = assert_tree_pressure_angles(mechanism, path, poses_near_home(mechanism))
    assert np.all(result.f_o[1] == 0.0)  # two motors, two DOF: non-redundant


@pytest.mark.parametrize("scale", [1e-3, 1e3])
def test_a_compound_leg_gives_the_tree_values_in_any_unit_and_world_frame_and_in_mjcf(tmp_path, scale):
    rotation = random_rotation(np.random.default_rng(int(scale) % 89))
    path = write(tmp_path, *delta_gepetto(rotation, scale))
    tree = read_gepetto(path, tmp_path / "robot.yaml")
    q, _ = assemble(tree)
    (tmp_path / "same.xml").write_text(mjcf_of_tree(tree, q, "effector"))
    for mechanism in (load(path), load(tmp_path / "same.xml")):
        assert mechanism.dof == 2 and [chain.actuated for chain in mechanism.chains] == [(), (0,), (0,)]
        assert_tree_pressure_angles(mechanism, path, poses_near_home(mechanism, spread=0.03 * scale))


def test_a_dyad_pinned_inside_a_leg_constrains_nothing_and_leaves_the_five_bar(tmp_path):
    """A serial chain in disguise: rod 3 only pinned to rod 2 at B1 (two free joints) adds no constraint, so the
    leg is rod 2 and the indices are the five-bar's, computed from the tree."""
    path = write(tmp_path, *delta_gepetto(couple_only=True))
    _, report = read_mechanism_file(path)
    assert any("actuated path mot1_rod2 kept, nothing written for its passive branches: they constrain nothing the "
               "actuated path does not" in note
               for note in report.notes), report.notes
    mechanism = load(path)
    assert [chain.name for chain in mechanism.chains] == ["mot1_rod1", "mot1_rod2"] and mechanism.dof == 2
    poses = poses_near_home(mechanism)
    result = indices_at_poses(mechanism, poses, detail=True)
    motors = actuator_values(mechanism, solve(mechanism, poses).joint_values)
    tree = read_gepetto(path, tmp_path / "robot.yaml")
    q, _ = assemble(tree)
    for k in range(poses.shape[0]):
        iti, oti = tree_pressure_angles(tree, closed_tree_at(tree, q, {"mot1_rod1": motors[k, 0],
                                                                       "mot1_rod2": motors[k, 1]}))
        np.testing.assert_allclose(result.iti_actuators[k], iti, atol=TOLERANCE)
        np.testing.assert_allclose(result.lmti[k], oti, atol=TOLERANCE)


@pytest.mark.parametrize("options, message", [
    (dict(distort=0.02), "cannot be written as serial chains: its constraint is not one of rotations about fixed "
                         "directions"),
    (dict(motors=("mot1_rod1", "mot1_rod2", "free1_rod3")), r"has 2 actuated legs \(mot1_rod2, free1_rod3\), the legs "
                                                            r"from those joints, with actuated joints mot1_rod2, "
                                                            r"free1_rod3: .* --lock holds the others"),
])
def test_a_compound_leg_screwkit_cannot_write_is_refused_by_name(tmp_path, options, message):
    path = write(tmp_path, *delta_gepetto(**options))
    with pytest.raises(ImportError_, match="the compound leg joined by closure 'closedloop1_A-closedloop1_B' "
                                           + message):
        read_mechanism_file(path)


def test_convert_writes_a_compound_leg_that_opens_with_the_same_indices(tmp_path):
    source = write(tmp_path, *delta_gepetto(opening=0.2))
    out = tmp_path / "converted.urdf"
    result = screwkit("convert", source, out, "--json")
    assert result.returncode == 0, result.stderr
    summary = json.loads(result.stdout)
    assert summary["dof"] == 2 and summary["task_coordinates"] == ["x", "y"]
    original = json.loads(screwkit("analyze", source, "--json").stdout)
    converted = json.loads(screwkit("analyze", out, "--json").stdout)
    for key in ("iti", "lmti", "iti_actuators", "pose"):
        assert original[key] == converted[key], key
    again = tmp_path / "again.urdf"  # converting the converted file: screwkit's convention, written back as it is
    assert screwkit("convert", out, again).returncode == 0
    assert json.loads(screwkit("analyze", again, "--json").stdout)["iti_actuators"] == converted["iti_actuators"]


def test_platform_twists_of_a_serial_leg_span_its_joint_twists(tmp_path):
    """The closure-Jacobian null space of rod 2 alone (its closure onto the effector) spans rod 2's three revolute
    twists (axes z through B0, B1, E0, written from the points), in any world frame."""
    import pinocchio as pin

    from screwkit.io.closed_tree import path_to
    from screwkit.io.compound import platform_twists

    rotation = random_rotation(np.random.default_rng(2))
    path = write(tmp_path, *delta_gepetto(rotation, 2.0))
    tree = read_gepetto(path, tmp_path / "robot.yaml")
    q, scale = assemble(tree)
    model = tree.model
    data = model.createData()
    pin.computeJointJacobians(model, data, q)
    platform = model.getJointId("free2_rod1")
    closure = next(c for c in tree.closures if c.name == "closedloop2_B-closedloop2_A")
    spine = set(path_to(model, platform))
    joints = sorted({j for side in (closure.joint_a, closure.joint_b) for j in path_to(model, side)} - spine)
    centre = np.asarray(data.oMi[platform].translation)
    got, rounding = platform_twists(model, data, joints, [closure], platform, False, centre, scale)
    axis = rotation @ np.array([0.0, 0.0, 1.0])
    expected = np.array([np.concatenate([axis, np.cross(data.oMi[model.getJointId(name)].translation - centre, axis)
                                         / scale]) for name in ("mot1_rod2", "free1_rod2", "closedloop2_A")])
    expected = np.linalg.svd(expected, full_matrices=False)[2]
    assert got.shape == (3, 6) and rounding == 0.0  # the file is exact: no singular value between 1e-9 and 1e-5
    np.testing.assert_allclose(got.T @ got, expected.T @ expected, atol=1e-9)


def test_a_loop_that_reaches_no_leg_is_left_out_and_changes_nothing(tmp_path):
    plain = load(write(tmp_path, *delta_gepetto()))
    other = tmp_path / "with_loop"
    other.mkdir()
    path = write(other, *delta_gepetto(idle_loop=True))
    _, report = read_mechanism_file(path)
    assert "closure 'idle_a_pin-idle_b_pin' closes branches that reach no leg: left out (it does not move the " \
           "platform)" in report.notes
    mechanism = load(path)
    assert [chain.name for chain in mechanism.chains] == [chain.name for chain in plain.chains]
    poses = poses_near_home(plain)
    first, second = (indices_at_poses(m, poses, detail=True) for m in (plain, mechanism))
    np.testing.assert_allclose(second.iti_actuators, first.iti_actuators, atol=TOLERANCE)
    np.testing.assert_allclose(second.lmti, first.lmti, atol=TOLERANCE)
