"""The configuration a file assembles into when its joint values leave its loops open.

Gepetto's published ``robot_delta`` and ``wl16_like`` leave their closures open at the file's joint values (by up to
0.37 m for the 6-SPS leg), and every configuration of a whole family closes them. screwkit takes the one nearest to
the file's values (angles in rad, slides in length scales): a choice the mechanism makes, so the same whether the file
draws a revolute elsewhere on its axis, turns a link's frame about its joint's axis, or is written in millimetres.
The damped steps that reached *a* closed configuration before depended on all three (the Delta's home moved by up
to 4 mm and its ITI by up to 0.095; the 6-SPS leg's LMTI was 0.038 or 0.121).

Checked here against Pinocchio's own Jacobians (the change from the file's values is normal to the closed
configurations: no motion that keeps the loops closed shortens it) and against closed configurations sampled around
it (none is nearer).
"""

from __future__ import annotations

import json
import re
import warnings
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from scipy.spatial.transform import Rotation
from test_axis_points import numbers, origins_in, revolutes_drawn_elsewhere, revolutes_moved, written
from test_gallery import screwkit_residuals
from test_lower_mobility import rpy_matrix

from helpers import in_unit, screwkit
from screwkit.io import read_closed_tree
from screwkit.io.closed_tree import ClosedTree, Closure, _lines_scale, assemble, closure_gaps, joint_kind
from screwkit.io.compound import closed_samples
from screwkit.io.loader import load
from screwkit.studies import indices_at_pose

GEPETTO = Path(__file__).resolve().parent / "data" / "gallery" / "published" / "example_parallel_robots"
OPEN_FILES = ("robot_delta", "wl16_like")


def rpy_of(rotation) -> str:
    """URDF's roll-pitch-yaw (R = Rz Ry Rx, fixed axes) of a rotation matrix, checked to give it back (at a pitch of
    90 degrees any split of the other two does)."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", "Gimbal lock", UserWarning)
        angles = Rotation.from_matrix(rotation).as_euler("xyz")
    np.testing.assert_allclose(rpy_matrix(*angles), rotation, atol=1e-12)
    return written(angles)


def closure_joints(name: str) -> set[str]:
    """The joints whose frames robot.yaml welds (Gepetto's closures are joint frames: drawing one of those
    elsewhere, or turning it, would change the mechanism)."""
    return set(re.findall(r"closedloop\w+", (GEPETTO / name / "robot.yaml").read_text()))


def revolutes(text: str, name: str) -> list:
    """The tree revolutes of the URDF ``text`` but the closure frames (ElementTree elements)."""
    return [joint for joint in ET.fromstring(text).iter("joint") if joint.get("type") in ("revolute", "continuous")
            and joint.get("name") not in closure_joints(name)]


def drawn_along_axes(text: str, name: str, rng) -> str:
    """Every tree revolute but the closure frames drawn elsewhere on its axis (up to 5 cm either way)."""
    return revolutes_moved(text, {joint.get("name"): rng.uniform(-0.05, 0.05) for joint in revolutes(text, name)})


def frames_turned_about_axes(text: str, name: str, rng) -> str:
    """The URDF with every tree revolute's child link frame (but the closure frames) turned about the joint's axis (each
    by its own angle) and every origin written in that frame turned back: every body where it was at every joint
    value, drawn in other frames (written here with ElementTree, not with screwkit's reader)."""
    root = ET.fromstring(text)
    turned = {joint.get("name") for joint in revolutes(text, name)}
    for joint in root.iter("joint"):
        if joint.get("name") not in turned:
            continue
        axis = numbers(joint.find("axis").get("xyz") if joint.find("axis") is not None else "1 0 0")
        turn = Rotation.from_rotvec(rng.uniform(-np.pi, np.pi) * axis / np.linalg.norm(axis)).as_matrix()
        origin = joint.find("origin") if joint.find("origin") is not None else ET.SubElement(joint, "origin")
        origin.set("rpy", rpy_of(rpy_matrix(*numbers(origin.get("rpy", "0 0 0"))) @ turn))
        for inner in origins_in(root, joint.find("child").get("link")):
            inner.set("xyz", written(turn.T @ numbers(inner.get("xyz", "0 0 0"))))
            inner.set("rpy", rpy_of(turn.T @ rpy_matrix(*numbers(inner.get("rpy", "0 0 0")))))
    return ET.tostring(root, encoding="unicode")


def copied(folder: Path, name: str, text: str) -> Path:
    """``text`` as Gepetto's ``name`` (its robot.yaml beside it) in ``folder``."""
    folder.mkdir()
    (folder / "robot.urdf").write_text(text)
    (folder / "robot.yaml").write_text((GEPETTO / name / "robot.yaml").read_text())
    return folder / "robot.urdf"


DRAWINGS = {
    "revolutes elsewhere on their axes": lambda text, name, rng: (drawn_along_axes(text, name, rng), 1.0),
    "link frames turned about their axes": lambda text, name, rng: (frames_turned_about_axes(text, name, rng), 1.0),
    "both, in millimetres": lambda text, name, rng: (in_unit(frames_turned_about_axes(
        drawn_along_axes(text, name, rng), name, rng), "mm", 1000.0), 1000.0),
}


@pytest.mark.parametrize("drawing", DRAWINGS)
@pytest.mark.parametrize("name", OPEN_FILES)
def test_a_file_that_does_not_close_assembles_into_the_same_configuration_however_it_is_drawn(tmp_path, name,
                                                                                            drawing):
    """The home pose's task coordinates (lengths in the file's unit; the platform's frame, where a drawing moves it,
    moves along an axis that is not one of them) and the indices at each file's home pose."""
    source = GEPETTO / name / "robot.urdf"
    text, factor = DRAWINGS[drawing](source.read_text(), name, np.random.default_rng(7))
    assert text != source.read_text()
    original, other = load(source), load(copied(tmp_path / name, name, text))
    lengths = np.array([factor if other.pose_coordinates[k] in "xyz" else 1.0 for k in other.task_indices])
    np.testing.assert_allclose(other.home_pose, lengths * original.home_pose, rtol=0, atol=1e-8 * factor)
    here, there = indices_at_pose(original, original.home_pose), indices_at_pose(other, other.home_pose)
    np.testing.assert_allclose(there.iti_actuators, here.iti_actuators, rtol=0, atol=1e-7)
    np.testing.assert_allclose(there.oti_actuators, here.oti_actuators, rtol=0, atol=1e-7)
    np.testing.assert_allclose([there.lmti, *there.f_o.values()], [here.lmti, *here.f_o.values()], rtol=0,
                               atol=1e-7)


def closure_jacobian(tree, q) -> np.ndarray:
    """The closures' velocity constraints at q from Pinocchio's joint Jacobians: for each closure, the relative
    velocity of its two frames' origin (and, for a weld, their relative angular velocity), world-aligned."""
    model, data = tree.model, tree.model.createData()
    pin.computeJointJacobians(model, data, q)
    rows = []
    for closure in tree.closures:
        motions = []
        for joint, placement in ((closure.joint_a, closure.placement_a), (closure.joint_b, closure.placement_b)):
            jacobian = pin.getJointJacobian(model, data, joint, pin.LOCAL_WORLD_ALIGNED)
            point = data.oMi[joint].homogeneous @ placement
            offset = point[:3, 3] - data.oMi[joint].translation
            linear = jacobian[:3] - np.cross(offset[:, None], jacobian[3:], axis=0)  # v + w x offset
            motions.append((linear, jacobian[3:]))
        rows.append(motions[1][0] - motions[0][0])
        if closure.kind == "6d":
            rows.append(motions[1][1] - motions[0][1])
    return np.vstack(rows)


def lines_weight(tree) -> float:
    """The length that weighs a slide against an angle, computed here with numpy: the root-mean-square distance of the
    revolute axis lines at the file's values (these files have no ball closures) from the point nearest to them."""
    model, data = tree.model, tree.model.createData()
    pin.forwardKinematics(model, data, tree.q_reference)
    lines = []
    for joint in range(1, model.njoints):
        kind, axis = joint_kind(model, joint)
        if kind == "revolute":
            lines.append((data.oMi[joint].translation, data.oMi[joint].rotation @ axis))
    off = [np.eye(3) - np.outer(u, u) for _, u in lines]
    centre = np.linalg.lstsq(sum(off), sum(o @ p for o, (p, _) in zip(off, lines)), rcond=None)[0]
    return float(np.sqrt(np.mean([np.sum((o @ (p - centre)) ** 2) for o, (p, _) in zip(off, lines)])))


@pytest.mark.parametrize("name", OPEN_FILES)
def test_the_assembly_is_the_closed_configuration_nearest_to_the_file_s_values(name):
    """The change x from the file's values (slides in length scales) closes every closure (Pinocchio's placements)
    and has no part along a motion that keeps them closed (the null space of Pinocchio's closure Jacobian, carried
    to the file's configuration): the first-order condition of the nearest. Closed configurations sampled within
    0.2 rad or length scales of it are all farther."""
    tree = read_closed_tree(GEPETTO / name / "robot.urdf")
    q, _ = assemble(tree)
    model = tree.model
    scale = lines_weight(tree)
    gaps = screwkit_residuals(tree, q)
    assert max(float(np.max(np.abs(gap))) for gap in gaps.values()) < 1e-12
    unit = np.ones(model.nv)
    for joint in range(1, model.njoints):
        if joint_kind(model, joint)[0] == "prismatic":
            unit[model.joints[joint].idx_v] = scale
    change = pin.difference(model, tree.q_reference, q)
    x = change / unit
    assert np.linalg.norm(x) > 0.5  # far from closing: the nearest is a real choice
    constraints = closure_jacobian(tree, q) @ pin.dIntegrate(model, tree.q_reference, change, pin.ARG1) * unit
    _, singular, rows = np.linalg.svd(constraints)
    rank = int(np.sum(singular > 1e-9 * singular[0]))
    along_closed = rows[rank:] @ x
    assert np.linalg.norm(along_closed) < 1e-7 * np.linalg.norm(x), np.linalg.norm(along_closed)
    samples = closed_samples(tree, q, scale, count=4)
    assert len(samples) == 4
    distances = [np.linalg.norm(pin.difference(model, tree.q_reference, sample) / unit) for sample in samples]
    assert min(distances) >= np.linalg.norm(x) - 1e-9, (distances, np.linalg.norm(x))


def arm_and_free_platform(length: float, target) -> ClosedTree:
    """A revolute arm of ``length`` about z at the origin whose tip is joined by a ball to a free body, which the
    file places at ``target`` (unturned): the loop is open unless the tip is there."""
    model = pin.Model()
    arm = model.addJoint(0, pin.JointModelRZ(), pin.SE3.Identity(), "arm")
    model.appendBodyToJoint(arm, pin.Inertia.Random(), pin.SE3.Identity())
    free = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "platform")
    model.appendBodyToJoint(free, pin.Inertia.Random(), pin.SE3.Identity())
    tip = np.eye(4)
    tip[0, 3] = length
    q = pin.neutral(model)
    q[1:4] = target
    return ClosedTree("arm_and_free_platform", model, [Closure("ball", arm, tip, free, np.eye(4), "3d")], ["arm"], q)


@pytest.mark.parametrize("length", [1.0, 1e-3, 1e3])
def test_a_free_body_s_translation_is_weighed_in_length_scales(length):
    """A free joint's translation is a length, as a slide is: the nearest closed configuration of the arm and its
    free platform (the platform 0.4 and 0.3 arm lengths off the tip) turns the arm by the angle that minimises
    angle^2 + (platform's move / length scale)^2 (its orientation kept), found here by a bounded scalar search, the
    same in any unit. Weighed in metres, a millimetre arm barely moved its platform and a kilometre one barely
    turned."""
    from scipy.optimize import minimize_scalar

    tree = arm_and_free_platform(length, length * np.array([1.4, 0.3, 0.0]))
    q, _ = assemble(tree)
    # the weight of lengths: the z axis and the ball's centre, midway between the tip and the platform (1.2 L, 0.15 L,
    # 0), each half of that centre's distance from the axis from the point between them
    scale = length * np.hypot(1.2, 0.15) / 2

    def distance(angle):
        tip = length * np.array([np.cos(angle), np.sin(angle), 0.0])
        return angle**2 + np.sum((tip - tree.q_reference[1:4]) ** 2) / scale**2

    expected = minimize_scalar(distance, bounds=(-1.0, 1.0), method="bounded", options={"xatol": 1e-12}).x
    np.testing.assert_allclose(q[0], expected, rtol=0, atol=1e-8)
    np.testing.assert_allclose(q[1:4], length * np.array([np.cos(expected), np.sin(expected), 0.0]), rtol=0,
                               atol=1e-8 * length)
    np.testing.assert_allclose(q[4:], [0.0, 0.0, 0.0, 1.0], atol=1e-7)  # unturned (to the solve's tolerance)


def test_a_ball_closure_written_either_way_round_assembles_the_same(tmp_path):
    """Gepetto's ``wl16_like`` with its closures read as balls (``3d``), each pair written A-B and B-A: the file leaves
    them open, so the two frames of a ball are apart, and the length scale that weighs its slides takes the ball's
    centre midway between them (from the first frame alone, the home moved by 1.9e-3 rad with the order)."""
    source = GEPETTO / "wl16_like"
    yaml = (source / "robot.yaml").read_text()
    pairs = re.findall(r"\['(closedloop\w+)', '(closedloop\w+)'\]", yaml)
    assert len(pairs) == 5
    trees = []
    for name, order in (("forward", pairs), ("swapped", [(b, a) for a, b in pairs])):
        folder = tmp_path / name
        folder.mkdir()
        (folder / "robot.urdf").write_text((source / "robot.urdf").read_text())
        (folder / "robot.yaml").write_text(
            "closed_loop: [" + ", ".join(f"['{a}', '{b}']" for a, b in order) + "]\n"
            + "type: [" + ", ".join(["'3d'"] * len(order)) + "]\n" + yaml[yaml.index("name_mot"):])
        trees.append(read_closed_tree(folder / "robot.urdf"))
    (q, _), (other_q, _) = (assemble(tree) for tree in trees)
    np.testing.assert_allclose(pin.difference(trees[0].model, q, other_q), 0.0, atol=1e-9)


@pytest.mark.parametrize("tilt", [1e-9, 1e-7, 1e-5])
def test_the_length_scale_of_a_planar_mechanism_does_not_follow_the_rounding_of_its_axes(tilt):
    """Five revolutes about (nearly) parallel axes and a slide: the length that weighs the slide (``_lines_scale``),
    the axes' root-mean-square distance from the point nearest to them all, is the one of exactly parallel axes to
    1e-9 (the least-squares point, taken
    from the centroid and undecided along nearly parallel axes, came out 0.103 for axes rounded 1e-7 and 1e-5 rad
    off parallel); compared with the in-plane spread computed here with numpy."""
    rng = np.random.default_rng(1)
    points = np.array([[0, 0, 0], [0.3, 0, 0], [0.3, 0.2, 0], [0.05, 0.25, 0], [0.15, 0.1, 0.0]])
    model, parent, previous = pin.Model(), 0, pin.SE3.Identity()
    for k, point in enumerate(points):
        axis = np.array([0.0, 0.0, 1.0]) + tilt * rng.normal(size=3)
        rotation = pin.Quaternion.FromTwoVectors(np.array([0.0, 0.0, 1.0]), axis / np.linalg.norm(axis)).matrix()
        parent = model.addJoint(parent, pin.JointModelRZ(), previous.inverse() * pin.SE3(rotation, point), f"j{k}")
        previous = pin.SE3(rotation, point)
    model.addJoint(0, pin.JointModelPZ(), pin.SE3.Identity(), "slide")
    data = model.createData()
    pin.forwardKinematics(model, data, pin.neutral(model))
    planar = points[:, :2] - points[:, :2].mean(axis=0)
    expected = np.sqrt(np.mean(np.sum(planar**2, axis=1)))
    assert _lines_scale(model, data) == pytest.approx(expected, rel=1e-9)


def spherical_manipulator(rounding: float, rng, r: float = 0.05, rho: float = 0.03, along=None,
                          unit: float = 1.0, world=None) -> ClosedTree:
    """A 3-RRR spherical parallel manipulator about the origin (motor axes u_i 55 degrees off the downward vertical,
    platform axes w_i, middle axes v_i = u_i x w_i), read as an onshape-to-robot URDF of it is: leg 2 reaches the
    platform, legs 1 and 3 end on balls on their platform axes, 3 cm from the centre. Every axis is drawn through a
    point ``r`` along it moved off the centre by about ``rounding`` (m), and each ball's two frames apart by as much,
    as a CAD export rounds them. ``along``: each joint's frame drawn that much further along its axis (seven lengths,
    the motor and middle joint of each leg, then the platform's: the same lines, the same mechanism); everything
    written in units of 1 / ``unit`` m, and placed by ``world`` (a pin.SE3, default the identity)."""
    shifts = iter(np.zeros(7) if along is None else along)
    world = pin.SE3.Identity() if world is None else world
    beta = np.radians(55.0)
    turns = np.radians([0.0, 120.0, 240.0])
    u = [np.array([np.sin(beta) * np.cos(a), np.sin(beta) * np.sin(a), -np.cos(beta)]) for a in turns]
    w = [np.array([np.sin(0.6) * np.cos(a + 0.3), np.sin(0.6) * np.sin(a + 0.3), np.cos(0.6)]) for a in turns]
    v = [np.cross(a, b) / np.linalg.norm(np.cross(a, b)) for a, b in zip(u, w)]
    model = pin.Model()

    def joint(parent, parent_world, axis, name):
        turn = pin.Quaternion.FromTwoVectors(np.array([0.0, 0.0, 1.0]), axis).matrix()
        placed = world * pin.SE3(turn, unit * ((r + next(shifts)) * axis + rounding * rng.normal(size=3)))
        index = model.addJoint(parent, pin.JointModelRZ(), parent_world.inverse() * placed, name)
        model.appendBodyToJoint(index, pin.Inertia.Random(), pin.SE3.Identity())
        return index, placed

    legs = [joint(*joint(0, pin.SE3.Identity(), u[i], f"motor{i + 1}"), v[i], f"middle{i + 1}") for i in range(3)]
    platform, platform_world = joint(*legs[1], w[1], "platform2")
    closures = []
    for i in (0, 2):
        near, far = (world * pin.SE3(np.eye(3), unit * (rho * w[i] + rounding * rng.normal(size=3))) for _ in range(2))
        closures.append(Closure(f"ball{i + 1}", legs[i][0], (legs[i][1].inverse() * near).homogeneous, platform,
                                (platform_world.inverse() * far).homogeneous, "3d"))
    return ClosedTree("spm", model, closures, ["motor1", "motor2", "motor3"], pin.neutral(model))


@pytest.mark.parametrize("seed, rounding", [(0, 1e-7), (1, 1e-7), (2, 3e-7)])
def test_closures_that_close_only_to_the_file_s_rounding_stay_within_its_order_of_the_file_s_values(seed, rounding):
    """A spherical manipulator whose axes miss their centre by about 0.1-0.3 um: its balls, each on an axis through
    the centre, close only to that rounding (exactly, the mechanism would lock), and its file's values close them
    to within two micrometres. The assembly closes them as well as they close, and moves the joints by the
    rounding's order (its gap over the 3 cm ball radius, at most a few times 1e-5 rad), not along the floor: the
    damped steps crept 3-5 mrad along it, and a slide along every direction closed to that rounding took one of
    these 0.28 um open, beyond the file's rounding (and a published export of such a manipulator 0.5 rad away)."""
    tree = spherical_manipulator(rounding, np.random.default_rng(seed))
    gaps = closure_gaps(tree, tree.q_reference)
    assert 1e-8 < max(gaps.values()) < 2e-6
    q, _ = assemble(tree)
    assert np.max(np.abs(pin.difference(tree.model, tree.q_reference, q))) < 3 * max(gaps.values()) / 0.03
    assert max(closure_gaps(tree, q).values()) < 3e-7
    assert any("at best" in note for note in tree.notes), tree.notes


TURNED_WORLD = pin.SE3(pin.rpy.rpyToMatrix(0.7, -1.1, 2.3), np.array([0.4, -1.3, 2.1]))
"""A world frame the rounded manipulator is placed in, turned and moved."""


@pytest.mark.parametrize("seed", [0, 2, 4, 5])
def test_closures_closed_to_rounding_assemble_the_same_however_drawn_listed_or_scaled(seed):
    """The same rounded manipulator with its joint frames drawn up to 2 cm along their axes, its closures listed in
    the other order, written in millimetres or in kilometres, or turned and moved in the world: the same joint
    values (1e-9 rad; they are the same joints about the same lines). Where the damped steps stopped on the floor
    depended on these (1e-3 rad apart)."""
    rounding = 1e-7 if seed == 0 else 3e-7  # seeds 4 and 5: the first step undoes the whole creep (4e-3 rad)
    reference, _ = assemble(spherical_manipulator(rounding, np.random.default_rng(seed)))
    for draw in range(3):
        along = np.random.default_rng(10 + draw).uniform(-0.02, 0.02, 7)
        q, _ = assemble(spherical_manipulator(rounding, np.random.default_rng(seed), along=along))
        np.testing.assert_allclose(q, reference, atol=1e-9, err_msg=f"drawn along the axes by {along}")
    listed = spherical_manipulator(rounding, np.random.default_rng(seed))
    listed.closures.reverse()
    np.testing.assert_allclose(assemble(listed)[0], reference, atol=1e-9, err_msg="closures in the other order")
    for unit in (1e3, 1e-3):  # written in mm, and in km
        scaled = spherical_manipulator(rounding, np.random.default_rng(seed), unit=unit)
        np.testing.assert_allclose(assemble(scaled)[0], reference, atol=1e-9, err_msg=f"lengths x {unit}")
    turned = spherical_manipulator(rounding, np.random.default_rng(seed), world=TURNED_WORLD)
    np.testing.assert_allclose(assemble(turned)[0], reference, atol=1e-9, err_msg="in a turned and moved world")


@pytest.mark.parametrize("name", OPEN_FILES)
def test_a_file_that_does_not_close_assembles_the_same_with_its_joints_renamed_and_reordered(tmp_path, name):
    """The same robot with every joint renamed so that their order reverses (Pinocchio orders a link's children by
    their joint's name: the tree's velocity coordinates come out in another order) and its closures and motors
    listed in reverse: the nearest closed configuration is the same (the home pose), and actuator by actuator (by
    name, the new names read back) the same ITIs and OTIs, and the same LMTI."""
    source = GEPETTO / name
    text, yaml = (source / "robot.urdf").read_text(), (source / "robot.yaml").read_text()
    names = sorted(joint.get("name") for joint in ET.fromstring(text).iter("joint"))
    renamed = {joint: f"j{len(names) - k:03d}_{joint}" for k, joint in enumerate(names)}
    root = ET.fromstring(text)
    for joint in root.iter("joint"):
        joint.set("name", renamed[joint.get("name")])
    # (a closure names a joint's frame, or a link's, kept)
    lists = {key: re.findall(r"'([^']+)'", re.search(rf"{key}: \[(.*)\]", yaml).group(1))
             for key in ("type", "name_mot")}
    pairs = re.findall(r"\['([^']+)', '([^']+)'\]", yaml.splitlines()[0])  # the closed_loop line
    closures = [f"['{renamed.get(a, a)}', '{renamed.get(b, b)}']" for a, b in reversed(pairs)]
    written = ("closed_loop: [" + ", ".join(closures) + "]\n"
               + "type: [" + ", ".join(f"'{kind}'" for kind in reversed(lists["type"])) + "]\n"
               + "name_mot: [" + ", ".join(f"'{renamed[motor]}'" for motor in reversed(lists["name_mot"])) + "]\n")
    folder = tmp_path / name
    folder.mkdir()
    (folder / "robot.urdf").write_text(ET.tostring(root, encoding="unicode"))
    (folder / "robot.yaml").write_text(written)
    original, other = read_closed_tree(source / "robot.urdf"), read_closed_tree(folder / "robot.urdf")
    assert [re.sub(r"j\d{3}_", "", n) for n in other.model.names] != list(original.model.names)  # another order
    original, other = load(source / "robot.urdf"), load(folder / "robot.urdf")
    np.testing.assert_allclose(other.home_pose, original.home_pose, rtol=0, atol=1e-8)
    here, there = indices_at_pose(original, original.home_pose), indices_at_pose(other, other.home_pose)
    for field in ("iti_actuators", "oti_actuators"):
        by_name = {re.sub(r"j\d{3}_", "", actuator): value
                   for actuator, value in zip(there.actuators, np.ravel(getattr(there, field)))}
        np.testing.assert_allclose([by_name[actuator] for actuator in here.actuators], np.ravel(getattr(here, field)),
                                   rtol=0, atol=1e-7, err_msg=field)
    np.testing.assert_allclose(there.lmti, here.lmti, rtol=0, atol=1e-7)


def spherical_manipulator_onshape(rounding: float, seed: int, unit: float = 1.0, world=None) -> str:
    """:func:`spherical_manipulator` as onshape-to-robot writes it: a URDF of its seven joints (each link's frame its
    joint's, z along the axis), its two balls as ``closing_ball<i>_1`` / ``_2`` frame pairs and an ``effector`` frame
    at the centre, in units of 1 / ``unit`` m, placed by ``world`` (a pin.SE3)."""
    world = pin.SE3.Identity() if world is None else world
    tree = spherical_manipulator(rounding, np.random.default_rng(seed), unit=unit, world=world)
    model, data = tree.model, tree.model.createData()
    pin.forwardKinematics(model, data, tree.q_reference)

    def origin(placement) -> str:
        return f'<origin xyz="{written(placement.translation)}" rpy="{rpy_of(placement.rotation)}"/>'

    def link(name: str) -> str:
        return f'<link name="{name}"><inertial><mass value="0.1"/><inertia ixx="1e-4" ixy="0" ixz="0" ' \
               f'iyy="1e-4" iyz="0" izz="1e-4"/></inertial></link>'

    out = ['<robot name="spm">', link("base")]
    for joint in range(1, model.njoints):
        name, parent = model.names[joint], model.parents[joint]
        out += [link(f"{name}_link"), f'<joint name="{name}" type="revolute">{origin(model.jointPlacements[joint])}'
                f'<parent link="{"base" if parent == 0 else model.names[parent] + "_link"}"/><child '
                f'link="{name}_link"/><axis xyz="0 0 1"/><limit effort="1" velocity="20" lower="-3" upper="3"/>'
                '</joint>']
    frames = [(f"closing_{c.name}_{k + 1}", joint, pin.SE3(placement)) for c in tree.closures
              for k, (joint, placement) in enumerate(((c.joint_a, c.placement_a), (c.joint_b, c.placement_b)))]
    platform = model.getJointId("platform2")
    frames.append(("effector", platform, data.oMi[platform].inverse() * world))
    for name, joint, placement in frames:
        out += [link(name), f'<joint name="{name}_frame" type="fixed">{origin(placement)}<parent '
                f'link="{model.names[joint]}_link"/><child link="{name}"/></joint>']
    return "\n".join(out + ["</robot>"]) + "\n"


@pytest.mark.parametrize("seed", [0, 1])
def test_analyze_reads_a_manipulator_closed_to_rounding_the_same_however_drawn_or_scaled(tmp_path, seed):
    """``screwkit analyze`` as users run it, on the rounded manipulator exported as onshape-to-robot writes it, as
    written, with its revolutes drawn up to 2 cm along their axes (two drawings), and in millimetres: three DOF,
    the same home pose and indices to 1e-9 (where the damped steps stopped creeping along the floor put the home
    poses up to 0.06 rad apart), and the report's line that the closures close only to the rounding."""
    text = spherical_manipulator_onshape(1e-7, seed)  # axes off the centre within FILE_ROUNDING of its size
    files = {"written": text, "in mm": spherical_manipulator_onshape(1e-7, seed, 1000.0)}
    for draw in (1, 2):
        files[f"drawn {draw}"] = revolutes_drawn_elsewhere(text, np.random.default_rng(draw), 0.02)
    found = {}
    for label, content in files.items():
        path = tmp_path / label.replace(" ", "_") / "robot.urdf"
        path.parent.mkdir()
        path.write_text(content)
        run = screwkit("analyze", path, "--json")
        assert run.returncode == 0, (label, run.stderr)
        found[label] = json.loads(run.stdout)
        assert found[label]["dof"] == 3, label
        assert any("at best" in line for line in found[label]["converted"]), (label, found[label]["converted"])
    first = found["written"]
    for label, other in found.items():
        np.testing.assert_allclose(list(other["pose"].values()), list(first["pose"].values()), atol=1e-9,
                                   err_msg=label)
        np.testing.assert_allclose(list(other["iti_actuators"].values()), list(first["iti_actuators"].values()),
                                   atol=1e-9, err_msg=label)
        assert other["lmti"] == pytest.approx(first["lmti"], abs=1e-9), label


def rounded_four_bar(model, closures, tag: str, origin, size: float, rng, rounding: float, crank: float = 1.2,
                     sides=(0.4, 1.0, 0.9, 1.0)) -> int:
    """A planar four-bar (crank a, coupler b, rocker c, ground d, times ``size``) added to ``model`` at ``origin``,
    its coupler closed on its rocker by a ball, every axis tilted and every point moved by about ``rounding`` (of
    its size), as a CAD export writes it: it closes only to that rounding. Returns its crank's joint id."""
    a, b, c, d = (size * side for side in sides)
    ground = np.asarray(origin, dtype=float)
    rocker_at = ground + np.array([d, 0.0, 0.0])
    elbow = ground + a * np.array([np.cos(crank), np.sin(crank), 0.0])
    along = rocker_at - elbow
    length = np.linalg.norm(along)
    unit, normal = along / length, np.array([-along[1], along[0], 0.0]) / length
    foot = (b**2 - c**2 + length**2) / (2 * length)
    joint_point = elbow + foot * unit + np.sqrt(b**2 - foot**2) * normal

    def frame(point):
        axis = np.array([0.0, 0.0, 1.0]) + rounding * rng.normal(size=3)
        turn = pin.Quaternion.FromTwoVectors(np.array([0.0, 0.0, 1.0]), axis / np.linalg.norm(axis)).matrix()
        return pin.SE3(turn, point + rounding * size * rng.normal(size=3))

    at_ground, at_elbow, at_rocker = frame(ground), frame(elbow), frame(rocker_at)
    joints = []
    for parent, placement, name in ((0, at_ground, "crank"), (None, at_ground.inverse() * at_elbow, "coupler"),
                                    (0, at_rocker, "rocker")):
        joints.append(model.addJoint(joints[0] if parent is None else parent, pin.JointModelRZ(), placement,
                                     f"{tag}_{name}"))
        model.appendBodyToJoint(joints[-1], pin.Inertia.Random(), pin.SE3.Identity())
    near, far = (pin.SE3(np.eye(3), joint_point + rounding * size * rng.normal(size=3)) for _ in range(2))
    closures.append(Closure(f"{tag}_ball", joints[1], (at_elbow.inverse() * near).homogeneous, joints[2],
                            (at_rocker.inverse() * far).homogeneous, "3d"))
    return joints[0]


@pytest.mark.parametrize("small, crank, opened", [(1e-3, 0.9, 0.01), (2e-3, 0.9, 0.1), (1.0, 0.01, 0.01)])
def test_on_a_floor_a_small_or_nearly_singular_loop_is_still_closed(small, crank, opened):
    """Beside a rounded 0.5 m four-bar (the floor), a four-bar of 1-2 mm, or one of 1 m at 0.01 rad from its flat
    singular configuration (sides 0.3, 1, 0.5, 0.8), its crank 0.01-0.1 rad off in the file: the assembly closes it
    to its own rounding (1e-7 of its size; its gap measured here from Pinocchio's own placements) and the rounded
    0.5 m one to its. Their weakest closing directions, 1e-3 of the largest, need no large turn: a cut of the
    Jacobian at a fixed 3e-3 of its largest singular value left the small loop open by 1e-6 m or refused the file."""
    rng = np.random.default_rng(3)
    model, closures = pin.Model(), []
    rounded_four_bar(model, closures, "big", [0.0, 0.0, 0.0], 0.5, rng, 1e-7)
    sides = (0.4, 1.0, 0.9, 1.0) if small < 0.5 else (0.3, 1.0, 0.5, 0.8)
    crank_joint = rounded_four_bar(model, closures, "small", [0.2, 0.1, 0.05], small, rng, 1e-7 if small < 0.5
                                   else 0.0, crank=crank, sides=sides)
    q = pin.neutral(model)
    q[model.joints[crank_joint].idx_q] += opened
    tree = ClosedTree("fourbars", model, closures, ["big_crank", "small_crank"], q)
    found, _ = assemble(tree)
    data = model.createData()
    pin.forwardKinematics(model, data, found)
    small_ball = closures[1]
    ends = [(data.oMi[joint].homogeneous @ placement)[:3, 3] for joint, placement in
            ((small_ball.joint_a, small_ball.placement_a), (small_ball.joint_b, small_ball.placement_b))]
    assert np.linalg.norm(ends[0] - ends[1]) < 1e-6 * small  # its own rounding: 1e-7 of its size
    assert closure_gaps(tree, found)["big_ball"] < 1e-6 and any("at best" in note for note in tree.notes)


def tilted_four_bar(opened: float, tilt: float, along=(0.0, 0.0, 0.0)) -> ClosedTree:
    """A 0.5 m planar four-bar (crank 0.2, coupler 0.5, rocker 0.45, ground 0.5) whose rocker axis is tilted by
    ``tilt`` about the rocker's line at the crank angle 1.2: written so, it closes only there, at q = 0. The file's
    joint values are its planar solution ``opened`` rad of crank further, where only an out-of-plane gap of about
    tilt x rocker x opened is open; ``along``: the three joint frames drawn that far along their axes."""
    a, b, c, d = 0.2, 0.5, 0.45, 0.5

    def planar(crank):
        elbow = a * np.array([np.cos(crank), np.sin(crank), 0.0])
        to_rocker = np.array([d, 0.0, 0.0]) - elbow
        length = np.linalg.norm(to_rocker)
        unit, normal = to_rocker / length, np.array([-to_rocker[1], to_rocker[0], 0.0]) / length
        foot = (b**2 - c**2 + length**2) / (2 * length)
        return elbow, elbow + foot * unit + np.sqrt(b**2 - foot**2) * normal

    def angle(vector):
        return float(np.arctan2(vector[1], vector[0]))

    ground, rocker_at, z = np.zeros(3), np.array([d, 0.0, 0.0]), np.array([0.0, 0.0, 1.0])
    (elbow, point), (elbow_file, point_file) = planar(1.2), planar(1.2 + opened)
    line = (point - rocker_at) / np.linalg.norm(point - rocker_at)
    axis = np.cos(tilt) * z + np.sin(tilt) * np.cross(line, z)
    at_ground, at_elbow = pin.SE3(np.eye(3), ground + along[0] * z), pin.SE3(np.eye(3), elbow + along[1] * z)
    at_rocker = pin.SE3(pin.Quaternion.FromTwoVectors(z, axis).matrix(), rocker_at + along[2] * axis)
    model = pin.Model()
    crank = model.addJoint(0, pin.JointModelRZ(), at_ground, "crank")
    coupler = model.addJoint(crank, pin.JointModelRZ(), at_ground.inverse() * at_elbow, "coupler")
    rocker = model.addJoint(0, pin.JointModelRZ(), at_rocker, "rocker")
    for joint in (crank, coupler, rocker):
        model.appendBodyToJoint(joint, pin.Inertia.Random(), pin.SE3.Identity())
    ball = pin.SE3(np.eye(3), point)
    closure = Closure("ball", coupler, (at_elbow.inverse() * ball).homogeneous, rocker,
                      (at_rocker.inverse() * ball).homogeneous, "3d")
    values = [opened, (angle(point_file - elbow_file) - angle(elbow_file)) - (angle(point - elbow) - angle(elbow)),
              angle(point_file - rocker_at) - angle(point - rocker_at)]
    return ClosedTree("tilted", model, [closure], ["crank"], np.array(values))


@pytest.mark.parametrize("opened", [0.003, 0.02, 0.05])
def test_a_weak_closing_direction_within_the_floor_s_reach_is_closed_however_drawn(opened):
    """The four-bar's tilted rocker (1e-5 rad) closes it only at q = 0, 0.003-0.05 rad of crank from the file's
    values: closing that takes less than FLOOR_MOVE, so the assembly closes it there exactly, drawn as written or
    with its frames 0.1-0.2 m along their axes. A full step that way bent the stiff loop open, and the assembly
    stayed where the damped steps had crept (3e-4 to 2e-3 rad off, drawings that far apart)."""
    for along in ((0.0, 0.0, 0.0), (0.1, -0.2, 0.15), (-0.15, 0.2, -0.1)):
        tree = tilted_four_bar(opened, 1e-5, along)
        q, _ = assemble(tree)
        np.testing.assert_allclose(q, 0.0, atol=1e-9, err_msg=f"drawn {along}")
        assert closure_gaps(tree, q)["ball"] < 1e-12


@pytest.mark.parametrize("opened", [0.003, 0.02, 0.05])
def test_a_loop_beside_an_independent_rounded_one_closes_as_it_does_alone(opened):
    """The tilted four-bar above, with a rounded 0.5 m four-bar beside it that shares none of its joints and closes
    only to its rounding (1e-6 to 2e-6 m open): the tilted one still closes at q = 0 exactly, as alone, and the other
    stays on its floor, drawn as written or with the tilted one's frames along their axes and the closures listed the
    other way round. The floor's cut was taken from every closure's residual: the other's, ten times the tilted
    one's, dropped the tilted one's closing direction and slid it back to the file's values (0.003-0.05 rad off)."""
    for along, order in (((0.0, 0.0, 0.0), 1), ((0.1, -0.2, 0.15), -1)):  # also drawn otherwise, listed reversed
        alone = tilted_four_bar(opened, 1e-5, along)
        model, closures = alone.model, list(alone.closures)
        rounded_four_bar(model, closures, "other", [0.1, 0.8, 0.0], 0.5, np.random.default_rng(5), 2e-6, crank=0.9)
        tree = ClosedTree("two loops", model, closures[::order], ["crank", "other_crank"],
                          np.concatenate([alone.q_reference, np.zeros(3)]))
        gap = closure_gaps(tree, tree.q_reference)["other_ball"]
        assert 5e-7 < gap < 5e-6
        q, _ = assemble(tree)
        np.testing.assert_allclose(q[:3], 0.0, atol=1e-9, err_msg=f"drawn {along}, order {order}")
        gaps = closure_gaps(tree, q)
        assert gaps["ball"] < 1e-12 and 0.0 < gaps["other_ball"] <= gap and any("at best" in n for n in tree.notes)


@pytest.mark.parametrize("name", OPEN_FILES)
def test_the_report_of_a_file_in_millimetres_gives_its_lengths_in_millimetres(tmp_path, name):
    """Read with --length-unit mm, a file of another tool is converted as written and scaled after: its report gave
    the file's millimetres labelled metres ("gap 150 m"), and one largest joint change over angles and lengths
    ("4.99 rad or m" for 0.0534 rad). The gaps are now the metre file's times 1000, in mm, and the largest change of an
    angle and of a slide are given apart, each in its unit."""
    source = GEPETTO / name
    (tmp_path / "robot.urdf").write_text(in_unit((source / "robot.urdf").read_text(), "mm", 1000.0))
    (tmp_path / "robot.yaml").write_text((source / "robot.yaml").read_text())
    metres = load(source / "robot.urdf").import_report
    millimetres = load(tmp_path / "robot.urdf", length_unit="mm").import_report
    pattern = re.compile(r"closure (\S+): gap (\S+) (\S+)(?: and (\S+) deg)? at the file's joint values")
    gaps = [pattern.search(line).groups() for line in metres if pattern.search(line)]
    assert gaps and all(unit == "m" for _, _, unit, _ in gaps)
    scaled = [pattern.search(line).groups() for line in millimetres if pattern.search(line)]
    assert [(closure, unit) for closure, _, unit, _ in scaled] == [(closure, "mm") for closure, _, _, _ in gaps]
    np.testing.assert_allclose([float(value) for _, value, _, _ in scaled],
                               [1000.0 * float(value) for _, value, _, _ in gaps], rtol=2e-3)  # printed to 3 digits
    assert [turn for *_, turn in scaled] == [turn for *_, turn in gaps]  # a weld's angle: the same in any unit
    change = re.compile(r"the largest joint change (\S+) rad(?:, (\S+) (\S+))?\)")
    (angle, length, unit), = [change.search(line).groups() for line in metres if change.search(line)]
    (angle_mm, length_mm, unit_mm), = [change.search(line).groups() for line in millimetres if change.search(line)]
    assert angle_mm == angle and (length is None) == (length_mm is None)
    if length is not None:
        assert (unit, unit_mm) == ("m", "mm") and float(length_mm) == pytest.approx(1000 * float(length), rel=2e-3)
