"""Legs with loops inside them: a Delta robot whose forearms are parallelograms of ball-jointed rods.

The file is an MJCF rod-level model (``tests/delta_rods.py``), opened as written: MuJoCo's reading of it agrees
with screwkit's, the graph derivation (:mod:`screwkit.io.graph`) gives each leg the parallelogram's wrench system
(a force along the rods, a couple normal to the parallelogram's plane), and the indices are the textbook pressure
angles of a Delta: ITI = |u . t| (u the rods' direction, t the elbow's velocity direction), OTI_k = |u_k . v_k|
(v_k the translation reciprocal to the other actuators' rod forces), then LMTI and F_O1 by Eqs. 11-12 -- computed
here with numpy from the geometry alone. The same indices in millimetres, in another world frame and with the legs
listed in another order; a Stewart platform opened through the graph gives the indices of the serial-leg path; on
every bundled mechanism the equivalent chain of the graph derivation gives the per-chain actuation wrenches.
"""

from __future__ import annotations

import json

import numpy as np
import pinocchio as pin
import pytest
from delta_rods import ARM, ROD, delta_geometry, delta_rods_mjcf
from test_gallery import GALLERY, assert_same_bodies, mujoco_residuals, mujoco_state, screwkit_residuals

from helpers import (
    assert_indices_close,
    bundled_chain_screws,
    one_line_error,
    random_rotation,
    screwkit,
    screwkit_json,
    translational_pressure_angles,
)
from screwkit.indices.analysis import analyze
from screwkit.io.closed_tree import joint_value
from screwkit.io.graph import graph_mechanism
from screwkit.io.loader import bundled_names, load
from screwkit.io.mjcf import read_mjcf
from screwkit.screw import algebra as screws
from screwkit.screw.chain_screws import ChainScrews
from screwkit.screw.reference import joint_after
from screwkit.studies import indices_at_pose

TOLERANCE = 1e-9
AZIMUTHS = np.radians([90.0, 180.0, 270.0, 0.0])
POSES = [(0.02, -0.03, -0.45), (-0.06, 0.04, -0.52), (0.0, 0.0, -0.40)]


def textbook(centre, azimuths=AZIMUTHS) -> dict:
    """ITI, OTI of every 3-subset, LMTI and F_O1 of the rod-level Delta from its geometry (pressure angles)."""
    base, axes, elbows, attach = delta_geometry(centre, azimuths)
    rods = (attach - elbows) / ROD
    tangents = np.cross(axes, elbows - base) / ARM
    return {**translational_pressure_angles(rods, tangents), "rods": rods, "axes": axes, "elbows": elbows}


def assert_delta_textbook(result, expected: dict) -> None:
    """``result`` holds :func:`textbook`'s ITI per actuator, OTI of every 3-subset, LMTI and F_O1 (<= 1e-9)."""
    np.testing.assert_allclose(result.iti_actuators, expected["iti"], atol=TOLERANCE)
    found = dict(zip(result.submechanisms, result.oti_submechanisms))
    for members, value in expected["oti"].items():
        np.testing.assert_allclose(found[members], value, atol=TOLERANCE, err_msg=str(members))
    np.testing.assert_allclose([result.lmti, result.f_o[1]], [expected["lmti"], expected["f_o1"]], atol=TOLERANCE)


def open_delta(tmp_path, centre=POSES[0], azimuths=AZIMUTHS, name="delta.xml", transform=None):
    path = tmp_path / name
    path.write_text(delta_rods_mjcf(centre, azimuths, transform=transform))
    return path, graph_mechanism(read_mjcf(path))


@pytest.mark.parametrize("placed", [False, True])
def test_mujoco_reads_the_rod_level_delta_as_screwkit_does(tmp_path, placed):
    """Every body where MuJoCo puts it and every closure closed at qpos0 (the file is written closed); also with the
    robot's one world body turned and moved (whose placement Pinocchio's parser alone drops)."""
    transform = (1.0, random_rotation(np.random.default_rng(6)), np.array([0.3, -0.2, 0.5])) if placed else None
    path, graph = open_delta(tmp_path, transform=transform)
    mj_model, mj_data = mujoco_state(path)
    tree = graph.tree
    assert_same_bodies(tree, mj_model, mj_data, tree.q_reference)
    assert max(np.max(np.abs(r)) for r in mujoco_residuals(mj_model, mj_data).values()) < TOLERANCE
    assert max(np.max(np.abs(r)) for r in screwkit_residuals(tree, tree.q_reference).values()) < TOLERANCE
    assert mj_model.nq == tree.model.nq  # four ball joints per leg, the platform's: nothing dropped


@pytest.mark.parametrize("centre", POSES)
def test_each_leg_transmits_a_force_along_its_rods_and_constrains_the_parallelogram_normal(tmp_path, centre):
    """The leg's twist system: every translation and the rotations about the motor axis a and the rods u (five);
    its constraint wrench the couple along a x u; its actuation wrench the force along the rods through the line
    midway between them (the least-norm representative: moments about the platform's rod midpoint)."""
    _, graph = open_delta(tmp_path, centre)
    expected = textbook(centre)
    result = graph.indices()
    assert result.dof == 3 and len(result.actuators) == 4
    for i, chain in enumerate(graph.chains):
        u, a, e = expected["rods"][i], expected["axes"][i], expected["elbows"][i]
        allowed = np.linalg.svd(chain.twists)[2][:5]
        constraint = np.concatenate([np.zeros(3), np.cross(a, u) / np.linalg.norm(np.cross(a, u))])
        # a couple (0, m) does no work on a twist (w, v) when m . w = 0
        assert np.max(np.abs(allowed[:, :3] @ constraint[3:])) < TOLERANCE
        assert len(chain.twists) == 5
        wrench = result.actuation_wrenches[i]
        np.testing.assert_allclose(np.abs(wrench[:3] @ u), 1.0, atol=TOLERANCE)
        np.testing.assert_allclose(wrench[3:], np.cross(e, wrench[:3]), atol=TOLERANCE)


@pytest.mark.parametrize("centre", POSES)
def test_the_indices_are_the_textbook_pressure_angles_of_a_delta(tmp_path, centre):
    _, graph = open_delta(tmp_path, centre)
    assert_delta_textbook(graph.indices(), textbook(centre))


def test_the_same_indices_in_millimetres_in_another_frame_and_with_the_legs_listed_in_another_order(tmp_path):
    _, graph = open_delta(tmp_path)
    reference = graph.indices()
    rotation = random_rotation(np.random.default_rng(4))
    for transform in ((1000.0, np.eye(3), np.zeros(3)), (1.0, rotation, np.array([0.3, -1.2, 2.0])),
                      (25.4, rotation, np.array([-4.0, 0.5, 0.1]))):
        _, moved = open_delta(tmp_path, transform=transform, name="moved.xml")
        result = moved.indices(threshold=1e-6 * transform[0])
        assert_indices_close(reference, result, TOLERANCE, fields=("iti", "iti_actuators", "oti_submechanisms",
                                                                   "lmti", "cti"))
    order = [2, 0, 3, 1]
    _, relabelled = open_delta(tmp_path, azimuths=AZIMUTHS[order], name="relabelled.xml")
    result = relabelled.indices()
    by_azimuth = dict(zip(np.round(np.degrees(AZIMUTHS[order])), result.iti_actuators))
    np.testing.assert_allclose([by_azimuth[a] for a in np.round(np.degrees(AZIMUTHS))], reference.iti_actuators,
                               atol=TOLERANCE)
    np.testing.assert_allclose([result.lmti, result.f_o[1], result.cti], [reference.lmti, reference.f_o[1],
                                                                          reference.cti], atol=TOLERANCE)


def test_a_stewart_platform_through_the_graph_has_the_indices_of_its_serial_legs():
    """Legs without constraint wrenches have one actuation wrench each: the graph path and the serial-leg path
    (:mod:`screwkit.io.star`) give the same indices at the file's configuration, every actuator's OTI included. (The
    file welds each leg's last link to the platform at the platform's origin: the graph path took that weld frame
    as where the leg meets the platform, off five of the six leg lines, and its OTIs of those five were 0.44 to 1
    where the serial legs' are 0.4233; only the submechanism's minimum, the spine leg's, was compared.)"""
    graph = graph_mechanism(read_mjcf(GALLERY / "stewart_cad.xml"))
    mechanism = load(GALLERY / "stewart_cad.xml")
    serial = indices_at_pose(mechanism, mechanism.home_pose)
    result = graph.indices()
    assert result.dof == 6 and [a.split(":")[1] for a in result.actuators] == \
        [a.split(":")[1] for a in serial.actuators]
    assert_indices_close(serial, result, TOLERANCE, fields=("iti", "iti_actuators", "oti_actuators",
                                                            "oti_submechanisms", "lmti"))
    # and the leg lines' own: each leg's force along its line from the base's universal joint B_k to the
    # platform's T_k; T_k the twist reciprocal to the five other lines; OTI_k = |f . v(T_k)| / |v(T_k)|
    model = graph.tree.model
    data = model.createData()
    pin.forwardKinematics(model, data, np.asarray(graph.q).reshape(-1))
    lines = []
    for k in range(1, 7):
        base, top = (data.oMi[model.getJointId(f"{name}{k}")].translation for name in ("r_xb", "r_xt"))
        lines.append(((top - base) / np.linalg.norm(top - base), top))
    expected = []
    for k, (force, top) in enumerate(lines):
        rows = np.array([np.concatenate([np.cross(t, f), f]) for j, (f, t) in enumerate(lines) if j != k])
        omega, v0 = np.split(np.linalg.svd(rows)[2][-1], 2)  # (m_0, f) . (omega, v_0) = 0 for the five
        velocity = v0 + np.cross(omega, top)
        expected.append(abs(force @ velocity) / np.linalg.norm(velocity))
    np.testing.assert_allclose(np.ravel(result.oti_actuators), expected, atol=TOLERANCE)


@pytest.mark.parametrize("name", bundled_names())
def test_the_equivalent_chain_of_the_graph_derivation_gives_the_per_chain_wrenches(name):
    """For a serial leg the graph derivation's equivalent chain -- the actuated joints' twists and a basis of the
    twists the leg allows with them locked, from the null space of the leg's closure Jacobian [J | -I] -- gives
    the same actuation wrenches as the chain's own joints, and the same indices about the same characteristic
    points (<= 1e-12): the basis carries no joint axes, so those points are given, as the graph derivation gives
    its own, each where the wrench axis comes nearest to its joint's axis in the serial chain."""
    chains, poses = bundled_chain_screws(name, 6)
    equivalent = []
    for chain in chains:
        twists, points = chain.twists, chain.points
        rows = np.empty_like(twists)
        for c in range(twists.shape[0]):
            m = twists.shape[1]
            rows[c] = twists[c]
            passive = [j for j in range(m) if j not in chain.actuated]
            if passive:  # the actuated joints' own twists stay; the passive ones become a basis of S_i^0
                closure = np.hstack([twists[c][passive].T, -np.eye(6)])  # leg joint rates and T: J x - T = 0
                _, singular, right = np.linalg.svd(closure)
                null = right[int(np.sum(singular > 1e-12 * singular[0])):, -6:]
                basis = np.linalg.svd(null)[2][:np.linalg.matrix_rank(null, 1e-10)]
                assert len(basis) == len(passive)
                rows[c][passive] = basis
        equivalent.append(ChainScrews(rows, points, chain.actuated, chain.name, chain.joint_names))
    mechanism, options = load(name), {}
    if mechanism.output_point is not None:  # the output as analyze_solution gives it (a five-bar's point)
        from screwkit.closure import solve
        from screwkit.studies.poses import output_points

        points = output_points(mechanism, solve(mechanism, poses).full_poses)
        options = dict(output_point=points, dof=mechanism.dof,
                       planar=mechanism.rotation_world_base[:, 2] if mechanism.is_planar else False)
    reference = analyze(chains, **options)
    if mechanism.output_point is None:
        wrenches = reference.actuation_wrenches
        given = {"iti_points": [], "oti_points": []}
        for chain in chains:
            for k in chain.actuated:
                wrench = wrenches[:, len(given["oti_points"])]
                for name, joint in (("iti_points", joint_after(chain.twists[0], k)), ("oti_points", -1)):
                    line = screws.joint_lines(chain.twists, chain.points, joint)
                    given[name].append(screws.nearest_on_axis(wrench, chain.points[:, joint], line))
        options.update({name: np.stack(points, axis=1) for name, points in given.items()})
    result = analyze(equivalent, **options)
    assert_indices_close(reference, result, 1e-12)
    np.testing.assert_allclose(result.actuation_wrenches, reference.actuation_wrenches, atol=1e-12)


def test_a_leg_whose_actuator_moves_inside_its_loop_is_refused_naming_it(tmp_path):
    """The actuated joint must join the base to the rest of its leg; a rod's ball joint driven is not that (a leg of
    two actuators is read one at a time, and the ball is refused as no actuator)."""
    path = tmp_path / "driven_rod.xml"
    path.write_text(delta_rods_mjcf().replace('<motor name="m_2" joint="motor_2"/>',
                                              '<motor name="m_2" joint="motor_2"/><motor name="m_5" joint="ball_2a"/>'))
    with pytest.raises(ValueError, match=r"actuated joint 'ball_2a' is spherical: an actuator drives one revolute "
                                         r"or prismatic joint"):
        graph_mechanism(read_mjcf(path))


def frame_position(graph) -> np.ndarray:
    """Where the graph's output frame is (world, m)."""
    import pinocchio as pin

    from screwkit.io.output import output_frame

    data = graph.tree.model.createData()
    pin.framesForwardKinematics(graph.tree.model, data, graph.q)
    return np.asarray(data.oMf[output_frame(graph.tree)].translation)


@pytest.mark.parametrize("centre", POSES[1:])
def test_other_poses_are_solved_from_the_file_s_configuration_with_the_textbook_indices(tmp_path, centre):
    """The Delta written at POSES[0], moved by the platform to another pose: the textbook indices there, and those
    of the same Delta written at that pose (so also its working mode)."""
    _, graph = open_delta(tmp_path)
    moved = graph.at_pose(frame_position(graph) + np.subtract(centre, POSES[0]))
    expected, result = textbook(centre), moved.indices()
    np.testing.assert_allclose(result.iti_actuators, expected["iti"], atol=TOLERANCE)
    np.testing.assert_allclose([result.lmti, result.f_o[1]], [expected["lmti"], expected["f_o1"]], atol=TOLERANCE)
    _, written = open_delta(tmp_path, centre, name="there.xml")
    assert_indices_close(written.indices(), result, TOLERANCE)
    with pytest.raises(ValueError, match=r"no closed configuration reached from the current one puts the output "):
        graph.at_pose(frame_position(graph) + np.array([0.0, 0.0, -5.0]))
    with pytest.raises(ValueError, match=r"rpy \[0\.0, 0\.0, 30\.0\] deg"):
        graph.at_pose(frame_position(graph), np.radians([0.0, 0.0, 30.0]))  # a Delta's platform does not turn


def test_another_pose_gives_the_same_indices_in_millimetres_in_another_frame_and_with_the_legs_reordered(tmp_path):
    """at_pose moved by the same displacement (scaled and turned with the world) in a scaled, moved copy and in one
    whose legs are listed in another order: the indices of the original at its moved pose."""
    _, graph = open_delta(tmp_path)
    step = np.subtract(POSES[1], POSES[0])
    reference = graph.at_pose(frame_position(graph) + step).indices()
    rotation = random_rotation(np.random.default_rng(5))
    for scale, turn, shift in ((1e-3, rotation, np.array([0.01, 0.0, -0.02])), (1e3, rotation, np.zeros(3))):
        _, moved = open_delta(tmp_path, transform=(scale, turn, shift), name="moved.xml")
        result = moved.at_pose(frame_position(moved) + scale * turn @ step).indices(threshold=1e-6 * scale)
        assert_indices_close(reference, result, TOLERANCE, fields=("iti", "iti_actuators", "oti_submechanisms",
                                                                   "lmti", "cti"))
    order = [2, 0, 3, 1]
    _, relabelled = open_delta(tmp_path, azimuths=AZIMUTHS[order], name="relabelled.xml")
    result = relabelled.at_pose(frame_position(relabelled) + step).indices()
    by_azimuth = dict(zip(np.round(np.degrees(AZIMUTHS[order])), result.iti_actuators))
    np.testing.assert_allclose([by_azimuth[a] for a in np.round(np.degrees(AZIMUTHS))], reference.iti_actuators,
                               atol=TOLERANCE)
    np.testing.assert_allclose([result.lmti, result.f_o[1]], [reference.lmti, reference.f_o[1]], atol=TOLERANCE)


def test_the_command_line_analyses_a_rod_level_delta_as_written_and_at_other_poses(tmp_path):
    """``screwkit analyze FILE`` opens the file as written (the graph at the file's configuration) and prints the
    textbook indices; ``--pose x y z`` moves the output frame there, ``--actuators`` at the file's motor values
    keeps it; unreachable poses and a wrong count of actuator values are refused in one line."""
    path, graph = open_delta(tmp_path)
    expected = textbook(POSES[0])
    completed = screwkit("analyze", path)
    assert completed.returncode == 0, completed.stderr
    assert "4 actuators, 3 DOF (1 redundant), at the file's configuration" in completed.stdout
    assert f"LMTI (Eq. 11, all actuators)        {expected['lmti']:.4f}" in completed.stdout
    assert "analysed as a graph" in completed.stderr and "Traceback" not in completed.stderr
    at_file = screwkit("analyze", path, "--json")  # its pose is the output frame's there ({} before)
    assert at_file.returncode == 0, at_file.stderr
    assert json.loads(at_file.stdout)["pose"] == pytest.approx(dict(zip("xyz", frame_position(graph))), abs=1e-12)
    target = frame_position(graph) + np.subtract(POSES[1], POSES[0])
    posed = screwkit("analyze", path, "--pose", *[repr(float(v)) for v in target], "--json")
    assert posed.returncode == 0, posed.stderr
    report = json.loads(posed.stdout)
    assert report["lmti"] == pytest.approx(textbook(POSES[1])["lmti"], abs=TOLERANCE)
    assert report["pose"] == pytest.approx(dict(zip("xyz", target)), abs=1e-12)
    one_line_error(screwkit("analyze", path, "--actuators", "0", "0"), "Expected --actuators with 4 values")
    motors = [np.degrees(joint_value(graph.tree.model, leg.actuators[0], graph.q)) for leg in graph.legs
              if leg.actuators]  # the file's own actuator values: the file's pose and indices
    driven = screwkit_json("analyze", path, "--actuators", *[repr(float(v)) for v in motors])
    assert driven["lmti"] == pytest.approx(expected["lmti"], abs=TOLERANCE)
    assert driven["pose"] == pytest.approx(dict(zip("xyz", frame_position(graph))), abs=1e-9)
    one_line_error(screwkit("analyze", path, "--pose", "0", "0", "-5"), "no closed configuration puts the output "
                   "frame at (x=0, y=0, z=-5): it is never farther than")  # as a map or a sweep says it
    one_line_error(screwkit("analyze", path, "--pose", "0", "0"), "--pose takes its task coordinates x y z (m, deg), "
                   "or the output frame's x y z")
    converted = screwkit("convert", path, tmp_path / "out.urdf")
    one_line_error(converted, "inside a leg", "`screwkit analyze`, `info`, `sweep`, `map`, `trajectory` and `view`")


@pytest.mark.parametrize("transform", [None, (1000.0, np.eye(3), np.zeros(3)),
                                       (1.0, np.eye(3), np.array([0.3, -1.2, 2.0]))])
def test_a_delta_whose_rod_pairs_are_trapezoids_is_driven_in_x_y_z(tmp_path, transform):
    """The rod-level Delta, three legs, with its rods 0.06 m apart at the arms and 0.05 m at the platform, as a
    published onshape-to-robot Delta draws its pairs (0.04 and 0.0336 m): no pair is a parallelogram, so the platform
    turns as it moves, and its motion space holds one pure translation (z). The rule took z, then rotations: it read
    z, roll, pitch (the published one roll, pitch, yaw, which tell its motions apart by 0.0015 to x, y, z's 0.98, in
    length scales). Its motions move its frame more than they turn it: it reads x, y, z, in m, in mm and in another
    world frame, and a pose 2 cm off its home in x puts the output frame there (Pinocchio's placement, 1e-9 m) with
    the platform turned (the coupling is real)."""
    path = tmp_path / "trapezoids.xml"
    path.write_text(delta_rods_mjcf(POSES[0], np.radians([90.0, 210.0, 330.0]), transform=transform,
                                    platform_spacing=0.05))
    graph = graph_mechanism(read_mjcf(path))
    assert graph.task_coordinates == ("x", "y", "z")
    scale = 1.0 if transform is None else transform[0]
    home = graph.task_pose()
    target = home + np.array([0.02 * scale, 0.0, 0.0])
    q, reached = graph.solve(target[None])
    assert reached.all()
    model = graph.tree.model
    data = model.createData()
    pin.framesForwardKinematics(model, data, q[0])
    output = pin.SE3(data.oMf[graph.frame_id])  # a copy: data is overwritten below
    np.testing.assert_allclose(output.translation, target, atol=1e-9 * scale)
    pin.framesForwardKinematics(model, data, graph.q)
    turned = data.oMf[graph.frame_id].rotation.T @ output.rotation
    assert np.arccos(np.clip((np.trace(turned) - 1.0) / 2.0, -1.0, 1.0)) > 1e-3


def test_a_position_asked_of_a_delta_turned_a_quarter_turn_is_met_as_in_the_unturned_world(tmp_path):
    """GraphMechanism.at_pose with no orientation holds the position and the task coordinates, not the frame's
    roll, pitch and yaw as they are: the rod Delta's world turned 90 deg about y puts its platform frame at a pitch
    of 90 deg, a gimbal lock of those angles, and no position could be asked there. The same move gives the
    textbook's indices in both worlds (the world-frame invariance of the position asked)."""
    turn = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])  # 90 deg about y
    shift = np.array([0.1, -0.2, 0.3])
    _, plain = open_delta(tmp_path, name="plain.xml")
    _, turned = open_delta(tmp_path, name="turned.xml", transform=(1.0, turn, shift))
    assert abs(np.cos(turned.frame_pose()[4])) < 1e-6  # the frame at the lock
    move = np.array([0.01, -0.015, 0.02])
    here = plain.at_pose(plain.frame_pose()[:3] + move)
    there = turned.at_pose(turned.frame_pose()[:3] + turn @ move)
    np.testing.assert_allclose(there.frame_pose()[:3], turn @ here.frame_pose()[:3] + shift, atol=1e-9)
    expected = textbook(np.array(POSES[0]) + move)
    for graph in (here, there):
        assert_delta_textbook(graph.indices(), expected)


def test_a_platform_no_twist_moves_is_refused_naming_the_legs_that_hold_it():
    """What the refusal of a graph whose platform cannot move names, from each leg's twist system (hand-made here:
    unit rows in working coordinates): a leg that allows no twist on its own; else the legs any one of which left out
    frees the platform; else every leg's dimension."""
    from screwkit.io.graph_screws import LegScrews, locking_legs

    def leg(*axes):
        rows = np.zeros((1, 6, 6))
        rows[0, :len(axes)] = np.eye(6)[list(axes)]
        empty = np.zeros((1, 3))
        return LegScrews(np.zeros((1, 6)), rows, np.array([len(axes)]), rows, np.array([len(axes)]), empty, empty,
                         empty, np.zeros(1))

    class Leg:
        def __init__(self, name):
            self.name = name

    translations_xy, translation_z, rotation_z = leg(3, 4), leg(5), leg(2)
    assert locking_legs([Leg("a"), Leg("b"), Leg("c")], [translations_xy, leg(), translation_z]) == \
        ": leg(s) b allow it no twist on their own"
    assert locking_legs([Leg("a"), Leg("b")], [translations_xy, translation_z]) == \
        ": with any one of legs a, b left out, the others would let it move"
    assert locking_legs([Leg("a"), Leg("b"), Leg("c")], [translations_xy, translation_z, rotation_z]) == \
        ": the legs allow twist systems of dimension 2 (a), 1 (b), 1 (c)"  # (any two left: still none in common)
