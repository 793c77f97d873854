"""Batched kinematics: rotations, forward kinematics against Pinocchio, closure solving."""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from helpers import bundled
from screwkit.closure import (
    actuator_values,
    chain_screws,
    closure_residuals,
    forward,
    joint_screws,
    solve,
    solve_one,
    thread_limit,
)
from screwkit.closure.chain_kinematics import chain_forward_kinematics, chain_jacobian, twists_from_axes_and_points
from screwkit.common.rotations import (
    cross,
    rotation_about_axis,
    rotation_from_rotation_vector,
    rotation_from_rpy,
    rotation_vector_from_rotation,
    rpy_from_rotation,
    two_axis_pointing,
    wrap_angle,
)
from screwkit.io.loader import bundled_names, load, load_text
from screwkit.model.pinocchio_bridge import configuration_vector, twist_from_pinocchio_motion
from screwkit.model.urdf_writer import UrdfWriter

CLOSED_FORM_CASES = {
    # mechanism: (scale of the random pose offsets around home, expected solver kind)
    "planar_5rrr": ((0.4, 0.4, 1.5), "planar_rrr"),
    "planar_4rpr": ((0.4, 0.4, 0.8), "planar_rpr"),
    "ups_hexapod_8": ((0.15, 0.15, 0.15, 0.2, 0.2, 0.3), "ups"),
    "rss_hexapod_8": ((0.08, 0.08, 0.08, 0.1, 0.1, 0.15), "rus"),
    "ups_stewart_6": ((0.15, 0.15, 0.15, 0.2, 0.2, 0.3), "ups"),
}


@lru_cache(maxsize=None)
def mechanism(name: str):
    return bundled(name) if name != "random_loops" else random_loops_mechanism()


LOOP_KINDS = (("universal", 4), ("prismatic", 5), ("spherical", 3), ("revolute", 5), ("fixed", 6))
"""Loop type and number of revolute tree joints of each leg of the random test mechanism."""


def random_loops_mechanism():
    """The first seeded :func:`random_legs_mechanism` whose legs are all well conditioned at home."""
    for seed in range(30, 200):
        candidate = random_legs_mechanism(seed)
        smallest = min(
            np.linalg.svd(chain_jacobian(geometry, chain_forward_kinematics(geometry, values)), compute_uv=False)[-1]
            for geometry, values in zip(candidate.geometries, (c.reference_values for c in candidate.chains))
        )
        if smallest > 0.04:
            return candidate
    raise RuntimeError("no well-conditioned random mechanism")


def random_legs_mechanism(seed: int):
    """A spatial mechanism with random serial legs closed by every loop type (closed by construction).

    Each leg has random revolute joints; its loop frame sits at a random offset from the leg's
    last link. The platform-side origins come from Pinocchio's placement of that frame with all
    joint values zero and the platform at its joint origin, so every loop closes there.
    """
    import pinocchio

    def build(successor_origins=None) -> str:
        rng = np.random.default_rng(seed)
        writer = UrdfWriter("random_loops", " random legs closed by every loop type (test only) ")
        writer.link("base_link")
        writer.link("platform")
        writer.joint("platform_joint", "floating", "base_link", "platform", xyz=(0.1, -0.2, 1.0), rpy=(0.2, -0.1, 0.3))
        for leg, (loop_type, n_joints) in enumerate(LOOP_KINDS):
            parent = "base_link"
            angle = 2 * np.pi * leg / len(LOOP_KINDS)
            for joint in range(n_joints):
                child = f"leg_{leg}_link_{joint}"
                writer.link(child)
                xyz = (np.cos(angle), np.sin(angle), 0.0) if joint == 0 else rng.uniform(-0.3, 0.3, 3) + [0, 0, 0.3]
                axis = rng.normal(size=3)
                writer.joint(f"leg_{leg}_joint_{joint}", "revolute", parent, child, xyz=xyz, rpy=rng.uniform(-1, 1, 3),
                             axis=axis / np.linalg.norm(axis), limit=(-3.0, 3.0, 1.0, 1.0))  # fmt: skip
                parent = child
            writer.transmission(f"leg_{leg}_joint_1")
            if leg == 0:  # six actuators for the six DOF (the loader refuses fewer)
                writer.transmission(f"leg_{leg}_joint_2")
            frame = (rng.uniform(-0.2, 0.2, 3), rng.uniform(-1, 1, 3))
            axis, second = rng.normal(size=3), rng.normal(size=3)
            if successor_origins is None:  # the tree only: mark the loop frame to place it
                writer.link(f"leg_{leg}_loop_frame")
                writer.joint(f"leg_{leg}_loop_frame_joint", "fixed", parent, f"leg_{leg}_loop_frame", *frame)
                continue
            writer.loop(
                f"leg_{leg}_loop", loop_type, f"leg_{leg}", parent, frame, "platform", successor_origins[leg],
                axis=None if loop_type in ("spherical", "fixed") else axis / np.linalg.norm(axis),
                second_axis=(np.cross(axis, second) / np.linalg.norm(np.cross(axis, second))
                             if loop_type == "universal" else None),
            )  # fmt: skip
        return writer.text()

    tree = pinocchio.buildModelFromXML(build())
    data = tree.createData()
    pinocchio.framesForwardKinematics(tree, data, pinocchio.neutral(tree))
    platform = data.oMf[tree.getFrameId("platform")]
    origins = []
    for leg in range(len(LOOP_KINDS)):
        relative = platform.inverse() * data.oMf[tree.getFrameId(f"leg_{leg}_loop_frame")]
        origins.append((relative.translation, rpy_from_rotation(relative.rotation)))
    return load_text(build(origins), "random_loops.urdf")


def random_poses(mechanism_, scale, count, seed):
    rng = np.random.default_rng(seed)
    return mechanism_.home_pose + rng.uniform(-1.0, 1.0, (count, mechanism_.n_task)) * np.asarray(scale)


def angular_difference(first, second, prismatic):
    difference = np.asarray(first) - np.asarray(second)
    revolute = ~np.asarray(prismatic)
    difference[..., revolute] = wrap_angle(difference[..., revolute])
    return difference


# -- rotations -----------------------------------------------------------------------------


def test_rotation_vector_round_trip_including_small_and_near_pi_angles():
    rng = np.random.default_rng(0)
    axes = rng.normal(size=(4000, 3))
    axes /= np.linalg.norm(axes, axis=-1, keepdims=True)
    angles = np.concatenate([rng.uniform(0, np.pi, 1000), rng.uniform(0, 1e-7, 1000),
                             np.pi - rng.uniform(0, 1e-6, 1000), rng.uniform(3.0, np.pi, 1000)])
    vectors = axes * angles[:, None]
    rotations = rotation_from_rotation_vector(vectors)
    np.testing.assert_allclose(rotations, Rotation.from_rotvec(vectors).as_matrix(), atol=1e-14)
    recovered = rotation_vector_from_rotation(rotations)
    np.testing.assert_allclose(rotation_from_rotation_vector(recovered), rotations, atol=1e-12)
    ordinary = angles < np.pi - 1e-3
    np.testing.assert_allclose(recovered[ordinary], vectors[ordinary], atol=1e-12)


def test_rpy_matches_fixed_axis_xyz_euler_angles_and_round_trips():
    rng = np.random.default_rng(1)
    rpy = rng.uniform([-np.pi, -np.pi / 2, -np.pi], [np.pi, np.pi / 2, np.pi], (2000, 3))
    rotations = rotation_from_rpy(rpy)
    np.testing.assert_allclose(rotations, Rotation.from_euler("xyz", rpy).as_matrix(), atol=1e-14)
    np.testing.assert_allclose(rpy_from_rotation(rotations), rpy, atol=1e-9)


def test_rpy_rebuild_the_rotation_to_rounding_near_the_gimbal_lock():
    """A frame whose z axis is horizontal and x axis vertical (a converted hinge loop on a Delta's platform) has a
    pitch of 90 deg to rounding: arcsin lost half the digits there, and the written loop missed by 3e-8."""
    rng = np.random.default_rng(8)
    distance = 10.0 ** rng.uniform(-17, -1, 3000)
    rpy = np.column_stack([rng.uniform(-3, 3, 3000), np.sign(rng.normal(size=3000)) * (np.pi / 2 - distance),
                           rng.uniform(-3, 3, 3000)])
    rotations = Rotation.from_euler("xyz", rpy).as_matrix()
    assert np.max(np.abs(rotation_from_rpy(rpy_from_rotation(rotations)) - rotations)) < 1e-13
    locked = rpy_from_rotation(rotation_from_rpy([0.3, np.pi / 2, 0.2]))
    assert locked[0] == pytest.approx(0.0, abs=1e-15) and locked[1] == pytest.approx(np.pi / 2, abs=1e-15)


def test_cross_products_are_numpy_s_bit_for_bit_on_broadcast_batches():
    """The closed-loop graphs' solver takes its cross products from ``cross``: the same numbers as ``np.cross``."""
    rng = np.random.default_rng(5)
    for a_shape, b_shape in (((7, 3), (7, 3)), ((5, 4, 3), (5, 1, 3)), ((3,), (6, 3)), ((2, 1, 3), (4, 3))):
        a, b = rng.normal(size=a_shape) * 1e3, rng.normal(size=b_shape)
        np.testing.assert_array_equal(cross(a, b), np.cross(a, b))


def test_rotation_about_axis_and_wrap_angle():
    rng = np.random.default_rng(2)
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    angles = rng.uniform(-10, 10, 500)
    np.testing.assert_allclose(rotation_about_axis(axis, angles),
                               Rotation.from_rotvec(np.outer(angles, axis)).as_matrix(), atol=1e-13)
    wrapped = wrap_angle(angles)
    assert np.all((wrapped > -np.pi) & (wrapped <= np.pi))
    np.testing.assert_allclose(np.cos(wrapped), np.cos(angles), atol=1e-12)
    np.testing.assert_allclose(np.sin(wrapped), np.sin(angles), atol=1e-12)
    assert wrap_angle(-np.pi) == np.pi


def test_two_axis_pointing_reaches_the_goal_on_one_branch():
    rng = np.random.default_rng(3)
    first = rng.normal(size=(500, 3))
    second = rng.normal(size=(500, 3))
    start = rng.normal(size=(500, 3))
    first, second, start = (vector / np.linalg.norm(vector, axis=-1, keepdims=True)
                            for vector in (first, second, start))
    true_first, true_second = rng.uniform(-np.pi, np.pi, (2, 500))
    rotate = lambda axis, angle: Rotation.from_rotvec(axis * angle[:, None])  # noqa: E731
    goal = (rotate(first, true_first) * rotate(second, true_second)).apply(start)
    errors = []
    for branch in (1.0, -1.0):
        angle_first, angle_second, gap = two_axis_pointing(first, second, start, goal, branch)
        reached = (rotate(first, angle_first) * rotate(second, angle_second)).apply(start)
        errors.append(np.linalg.norm(reached - goal, axis=-1))
        assert np.all(gap > -1e-9)
    assert np.all(np.minimum(*errors) < 1e-7)


def test_twists_from_axes_and_points_equal_a_loop_over_configurations():
    rng = np.random.default_rng(4)
    axes = rng.normal(size=(7, 3, 4, 3))
    points = rng.normal(size=(7, 3, 4, 3))
    prismatic = (False, True, False, False)
    twists = twists_from_axes_and_points(axes, points, prismatic)
    for index in np.ndindex(7, 3):
        for joint in range(4):
            axis, point = axes[index][joint], points[index][joint]
            expected = (np.concatenate([np.zeros(3), axis]) if prismatic[joint]
                        else np.concatenate([axis, np.cross(point, axis)]))
            np.testing.assert_allclose(twists[index][joint], expected, atol=1e-15)


# -- forward kinematics against Pinocchio ---------------------------------------------------


@pytest.mark.parametrize("name", bundled_names() + ("random_loops",))
def test_joint_screws_match_pinocchio_jacobians_and_placements(name):
    import pinocchio

    mechanism_ = mechanism(name)
    model = mechanism_.pinocchio_model
    data = model.createData()
    rng = np.random.default_rng(5)
    count = 6
    joint_values = [
        np.where(chain.prismatic, rng.uniform(-0.3, 0.3, (count, chain.n_joints)),
                 rng.uniform(-np.pi, np.pi, (count, chain.n_joints)))
        for chain in mechanism_.chains
    ]
    screws = joint_screws(mechanism_, joint_values)
    configuration = configuration_vector(mechanism_, joint_values)
    description = mechanism_.description
    loops = {loop.name: loop for loop in description.loops}
    moved = {}
    for sample in range(count):
        pinocchio.computeJointJacobians(model, data, configuration[sample])
        pinocchio.updateFramePlacements(model, data)
        for chain, screws_of_chain in zip(mechanism_.chains, screws):
            for index, joint_name in enumerate(chain.joint_names):
                if not model.existJointName(joint_name):
                    continue
                joint_id = model.getJointId(joint_name)
                column = (pinocchio.getJointJacobian(model, data, joint_id, pinocchio.WORLD)
                          [:, model.joints[joint_id].idx_v])
                np.testing.assert_allclose(screws_of_chain.twists[sample, index], twist_from_pinocchio_motion(column),
                                           atol=1e-12)
                drawn = data.oMi[joint_id].translation
                _assert_on_axis_by_a_constant(screws_of_chain, sample, index, drawn, moved, (chain.name, joint_name))
            loop = loops[chain.loop_name]
            leg_frame = data.oMf[model.getFrameId(loop.predecessor, pinocchio.BODY)]
            leg_rotation = leg_frame.rotation @ loop.predecessor_origin.rotation
            leg_point = leg_frame.translation + leg_frame.rotation @ loop.predecessor_origin.translation
            loop_values = joint_values[mechanism_.chains.index(chain)][
                sample, len(chain.joint_names) - len(_loop_names(chain)) :
            ]
            for offset, (axis, point) in enumerate(_expected_loop_screws(loop, leg_rotation, leg_point, loop_values)):
                index = len(chain.joint_names) - len(_loop_names(chain)) + offset
                twist = screws_of_chain.twists[sample, index]
                if loop.type == "prismatic":
                    np.testing.assert_allclose(twist, np.concatenate([np.zeros(3), axis]), atol=1e-12)
                else:
                    np.testing.assert_allclose(twist, np.concatenate([axis, np.cross(point, axis)]), atol=1e-12)
                _assert_on_axis_by_a_constant(screws_of_chain, sample, index, point, moved, (chain.name, index))
    assert name != "coop_arms" or max(map(abs, moved.values())) > 0.01  # its UR5 files do not draw DH points


def _assert_on_axis_by_a_constant(screws, sample, index, drawn, moved, key):
    """The chain's point of a joint is the point Pinocchio draws, moved along the joint's axis to its canonical point
    (:mod:`screwkit.closure.canonical`) by the same signed distance in every configuration (a constant of the design);
    a prismatic joint is not moved."""
    point, twist = screws.points[sample, index], screws.twists[sample, index]
    axis = twist[:3] if np.linalg.norm(twist[:3]) > 0.5 else np.zeros(3)
    np.testing.assert_allclose(np.cross(point - drawn, axis), 0.0, atol=1e-12)
    offset = float((point - drawn) @ axis)
    np.testing.assert_allclose(offset, moved.setdefault(key, offset), atol=1e-12)
    if not axis.any():
        np.testing.assert_allclose(point, drawn, atol=1e-12)


def _expected_loop_screws(loop, leg_rotation, leg_point, values):
    """Axis and point of each loop DoF, from the leg-side loop frame (independent of screwkit)."""
    if loop.type in ("revolute", "continuous"):
        return [(leg_rotation @ loop.axes[0], leg_point)]
    if loop.type == "prismatic":
        axis = leg_rotation @ loop.axes[0]
        return [(axis, leg_point + axis * values[0])]
    if loop.type == "universal":
        turned = leg_rotation @ Rotation.from_rotvec(loop.axes[0] * values[0]).as_matrix()
        return [(leg_rotation @ loop.axes[0], leg_point), (turned @ loop.axes[1], leg_point)]
    if loop.type == "spherical":
        return [(leg_rotation[:, k], leg_point) for k in range(3)]
    return []


def _loop_motion(loop, values):
    if loop.type in ("revolute", "continuous"):
        return Rotation.from_rotvec(loop.axes[0] * values[0]).as_matrix(), np.zeros(3)
    if loop.type == "prismatic":
        return np.eye(3), loop.axes[0] * values[0]
    if loop.type == "spherical":
        return Rotation.from_rotvec(values).as_matrix(), np.zeros(3)
    if loop.type == "universal":
        rotation = Rotation.from_rotvec(loop.axes[0] * values[0]) * Rotation.from_rotvec(loop.axes[1] * values[1])
        return rotation.as_matrix(), np.zeros(3)
    return np.eye(3), np.zeros(3)


@pytest.mark.parametrize("name", bundled_names() + ("random_loops",))
def test_solved_loops_close_in_pinocchio_forward_kinematics(name):
    """Independent closure check: Pinocchio places both sides of every loop joint."""
    import pinocchio

    mechanism_ = mechanism(name)
    scales = {"coop_arms": (0.03,) * 3 + (0.1,) * 3, "random_loops": (0.003,) * 3 + (0.01,) * 3,
              # lower mobility: offsets in the task coordinates only (x y z; x y; z roll pitch; x y z yaw)
              "delta_4": (0.1,) * 3, "five_bar_3": (0.05,) * 2, "five_bar": (0.05,) * 2, "prs_3_ups": (0.02, 0.2, 0.2),
              "schoenflies_5": (0.04,) * 3 + (0.2,)}
    scale = scales[name] if name in scales else CLOSED_FORM_CASES[name][0]
    solution = solve(mechanism_, random_poses(mechanism_, scale, 8, seed=6))
    assert solution.reachable.sum() >= 4
    if name == "random_loops":
        assert mechanism_.dof == 6 and ({chain.loop_type for chain in mechanism_.chains}
                                        == {kind for kind, _ in LOOP_KINDS})
    configuration = configuration_vector(mechanism_, solution.joint_values, solution.full_poses)
    model, data = mechanism_.pinocchio_model, mechanism_.pinocchio_model.createData()
    loops = {loop.name: loop for loop in mechanism_.description.loops}
    for sample in np.flatnonzero(solution.reachable):
        pinocchio.forwardKinematics(model, data, configuration[sample])
        pinocchio.updateFramePlacements(model, data)
        for index, chain in enumerate(mechanism_.chains):
            loop = loops[chain.loop_name]
            values = solution.joint_values[index][sample, len(chain.joint_names) - len(_loop_names(chain)) :]
            predecessor = data.oMf[model.getFrameId(loop.predecessor, pinocchio.BODY)]
            successor = data.oMf[model.getFrameId(loop.successor, pinocchio.BODY)]
            leg_rotation = predecessor.rotation @ loop.predecessor_origin.rotation
            leg_translation = predecessor.translation + predecessor.rotation @ loop.predecessor_origin.translation
            motion_rotation, motion_translation = _loop_motion(loop, values)
            end_rotation = leg_rotation @ motion_rotation
            end_translation = leg_translation + leg_rotation @ motion_translation
            np.testing.assert_allclose(end_rotation, successor.rotation @ loop.successor_origin.rotation, atol=1e-9)
            np.testing.assert_allclose(
                end_translation, successor.translation + successor.rotation @ loop.successor_origin.translation,
                atol=1e-9,
            )


def _loop_names(chain):
    return [name for name in chain.joint_names if name == chain.loop_name or name.startswith(chain.loop_name + "[")]


# -- closure solving ----------------------------------------------------------------------


@pytest.mark.parametrize("name", sorted(CLOSED_FORM_CASES))
def test_closed_forms_equal_the_newton_solver(name):
    scale, kind = CLOSED_FORM_CASES[name]
    mechanism_ = mechanism(name)
    assert {chain.solver for chain in mechanism_.chains} == {kind}
    poses = random_poses(mechanism_, scale, 150, seed=7)
    closed = solve(mechanism_, poses)
    newton = solve(mechanism_, poses, method="newton")
    assert closed.reachable.sum() >= 60
    np.testing.assert_array_equal(closed.chain_reachable, newton.chain_reachable)
    for chain, first, second in zip(mechanism_.chains, closed.joint_values, newton.joint_values):
        reachable = np.all(np.isfinite(first), axis=-1)
        assert np.all(np.isnan(first[~reachable])) and np.all(np.isnan(second[~reachable]))
        np.testing.assert_allclose(angular_difference(first[reachable], second[reachable], chain.prismatic), 0.0,
                                   atol=1e-9)
    residuals = closure_residuals(mechanism_, closed)
    assert np.nanmax(residuals) < 1e-12
    assert np.nanmax(closure_residuals(mechanism_, newton)) < 1e-10
    for first, second in zip(chain_screws(mechanism_, closed, unreachable="drop"),
                             chain_screws(mechanism_, newton, unreachable="drop")):
        np.testing.assert_allclose(first.twists, second.twists, atol=1e-9)


def test_newton_closes_the_cooperative_arms():
    mechanism_ = mechanism("coop_arms")
    poses = random_poses(mechanism_, (0.05, 0.05, 0.05, 0.3, 0.3, 0.3), 40, seed=8)
    solution = solve(mechanism_, poses)
    assert solution.reachable.all()
    assert np.max(closure_residuals(mechanism_, solution)) < 1e-10
    assert all(chain.solver == "newton" for chain in mechanism_.chains)


@pytest.mark.parametrize("name", sorted(CLOSED_FORM_CASES))
def test_screws_of_a_solution_equal_forward_kinematics_of_its_joint_values(name):
    mechanism_ = mechanism(name)
    solution = solve(mechanism_, random_poses(mechanism_, CLOSED_FORM_CASES[name][0], 50, seed=9))
    mask = solution.reachable
    from_solution = chain_screws(mechanism_, solution, unreachable="drop")
    from_values = joint_screws(mechanism_, [values[mask] for values in solution.joint_values])
    for first, second in zip(from_solution, from_values):
        np.testing.assert_allclose(first.twists, second.twists, atol=1e-12)
        np.testing.assert_allclose(first.points, second.points, atol=1e-12)
        assert first.actuated == second.actuated and first.name == second.name


def test_batched_solve_equals_a_loop_over_single_poses():
    mechanism_ = mechanism("planar_5rrr")
    poses = random_poses(mechanism_, (0.3, 0.3, 1.0), 12, seed=10).reshape(3, 4, 3)
    batched = solve(mechanism_, poses)
    assert batched.reachable.shape == (3, 4) and batched.chain_reachable.shape == (3, 4, 5)
    for index in np.ndindex(3, 4):
        single = solve_one(mechanism_, poses[index])
        for first, second in zip(batched.joint_values, single.joint_values):
            np.testing.assert_allclose(first[index], second, atol=1e-14)
    screws = chain_screws(mechanism_, batched)
    assert screws[0].twists.shape == (3, 4, 3, 6) and screws[0].points.shape == (3, 4, 3, 3)


def _elbow_sides(solution):
    """(c - b) . (z x u) for every chain of a 5-RRR solution, u = (d - b)/|d - b|."""
    sides = []
    for points in solution.joint_points:
        base, elbow, platform = points[..., 0, :2], points[..., 1, :2], points[..., 2, :2]
        direction = platform - base
        perpendicular = np.stack([-direction[..., 1], direction[..., 0]], -1)
        sides.append(np.sum((elbow - base) * perpendicular, -1))
    return np.stack(sides, -1)


def test_five_rrr_working_mode_is_kept_and_explicit_branches_switch_it():
    mechanism_ = mechanism("planar_5rrr")
    poses = random_poses(mechanism_, (0.5, 0.5, np.pi), 400, seed=11)
    solution = solve(mechanism_, poses)
    reachable = solution.reachable
    assert reachable.sum() > 100
    assert np.all(_elbow_sides(solution)[reachable] > 0)
    newton = solve(mechanism_, poses[reachable][:60], method="newton")
    assert np.all(_elbow_sides(newton)[newton.reachable] > 0) and newton.reachable.sum() >= 50
    mirrored = solve(mechanism_, poses, branches=[(-1,)] * 5)
    np.testing.assert_array_equal(mirrored.reachable, reachable)
    assert np.all(_elbow_sides(mirrored)[reachable] < 0)
    assert tuple(chain.branch for chain in mechanism_.chains) == ((1,),) * 5


def test_unreachable_poses_are_nan_and_strict_solving_names_the_chain():
    mechanism_ = mechanism("planar_5rrr")
    solution = solve(mechanism_, [[0.0, 0.0, 0.0], [1.9, 0.0, 0.0]])
    np.testing.assert_array_equal(solution.reachable, [True, False])
    assert np.all(np.isnan(solution.joint_values[2][1])) and np.all(np.isfinite(solution.joint_values[0][1]))
    with pytest.raises(ValueError, match=r"Pose \(x=1\.9, y=0, phi=0 deg\) is unreachable .* "
                                         r"chain 'chain_3' misses closure by 0\.78"):
        solve_one(mechanism_, [1.9, 0.0, 0.0])
    with pytest.raises(ValueError, match="1 of 2 configurations are unreachable"):
        chain_screws(mechanism_, solution)
    dropped = chain_screws(mechanism_, solution, unreachable="drop")
    assert dropped[0].twists.shape == (1, 3, 6)
    filled = chain_screws(mechanism_, solution, unreachable="reference")
    np.testing.assert_allclose(filled[2].twists[1], filled[2].twists[0], atol=1e-12)  # reference = home here
    newton = mechanism("coop_arms")
    with pytest.raises(ValueError, match="chain 'left_arm' misses closure"):
        solve_one(newton, newton.home_pose + [2.0, 0, 0, 0, 0, 0])


@pytest.mark.parametrize(
    ("poses", "message"),
    [
        ([0.0, 0.0],
         r"Expected `poses` with shape \(\.\.\., 3\) for mechanism 'planar_5rrr' \(x, y, phi\), got \(2,\)"),
        ([[0.0, np.nan, 0.0]], r"Expected finite values in `poses`, got nan at index \(0, 1\)"),
        ("abc", "Expected numeric `poses`"),
    ],
)
def test_bad_poses_raise(poses, message):
    with pytest.raises(ValueError, match=message):
        solve(mechanism("planar_5rrr"), poses)


def test_forward_kinematics_recovers_the_pose_from_three_locked_actuators():
    mechanism_ = mechanism("planar_5rrr")
    poses = np.array([[-0.2, 0.0, np.pi / 4], [0.1, 0.15, -0.4], [0.05, -0.2, 1.0]])
    solution = solve(mechanism_, poses)
    actuators = [0, 2, 3]
    all_values = actuator_values(mechanism_, solution.joint_values)
    np.testing.assert_array_equal(all_values[:, 2], solution.joint_values[2][:, 0])  # chain_3_joint_b
    values = all_values[:, actuators]
    recovered = forward(mechanism_, values, poses + [0.02, -0.02, 0.05], actuators=actuators)
    assert recovered.reachable.all()
    np.testing.assert_allclose(recovered.poses, poses, atol=1e-10)


def test_forward_kinematics_of_the_delta_reaches_a_pose_where_newton_stalls_at_the_closure_s_accuracy():
    """From z = -0.7856 m the actuator mismatch of the Delta's pose z = -0.7928 m stalled at 1.04e-11 rad for 30
    steps, just above the 1e-11 asked, and the pose (exactly found) was refused: a path of actuator values that
    screwkit's own inverse kinematics gave failed at its 493rd sample."""
    mechanism_ = mechanism("delta_4")
    target = np.array([0.0, 0.0, -0.7928])
    values = actuator_values(mechanism_, solve(mechanism_, target[None]).joint_values)
    recovered = forward(mechanism_, values, np.array([[0.0, 0.0, -0.7856]]))
    assert recovered.reachable.all()
    np.testing.assert_allclose(recovered.poses[0], target, atol=1e-10)


@pytest.mark.parametrize("name", ["planar_5rrr", "planar_4rpr"])
def test_redundant_actuator_values_rounded_to_nine_digits_give_their_least_squares_pose(name):
    """Rounded values of a redundantly actuated mechanism cannot all be met at once: they were refused as values
    that "disagree with each other". Within ``agreement`` (1e-5) the pose is their least-squares fit, near the pose
    they were computed at; values that do disagree (one off by 1e-3) are still refused."""
    mechanism_ = mechanism(name)
    poses = mechanism_.home_pose + np.array([[0.01, -0.02, 0.1], [-0.03, 0.01, -0.2], [0.0, 0.0, 0.3]])
    exact = actuator_values(mechanism_, solve(mechanism_, poses).joint_values)
    rounded = np.array([[float(f"{value:.9g}") for value in row] for row in exact])
    assert np.max(np.abs(rounded - exact)) > 1e-11  # the rounding is more than the tolerance
    recovered = forward(mechanism_, rounded, mechanism_.home_pose)
    assert recovered.reachable.all()
    np.testing.assert_allclose(recovered.poses, poses, atol=1e-7)
    wrong = rounded.copy()
    wrong[:, 0] += 1e-3
    assert not forward(mechanism_, wrong, mechanism_.home_pose).reachable.any()


@pytest.mark.parametrize("actuators, message", [
    ([0, 1], "Expected at least 3 distinct actuators held (the DOF of 'planar_5rrr'; fewer leave the pose "
             "undetermined), got chain_1:chain_1_joint_b, chain_2:chain_2_joint_b."),
    ([0, 0, 1], "Expected at least 3 distinct actuators held"),
    (["nope"], "Unknown actuator 'nope'; actuators are chain_1:chain_1_joint_b, "),
])
def test_forward_kinematics_refuses_actuators_that_do_not_determine_the_pose(actuators, message):
    """Two held actuators of the 3-DOF 5-RRR gave some pose, marked reachable, that depended on the start; a
    repeated actuator counted twice; an unknown name said "not enough values to unpack (expected 2, got 1)"."""
    mechanism_ = mechanism("planar_5rrr")
    with pytest.raises(ValueError) as raised:
        forward(mechanism_, np.zeros(len(actuators)), mechanism_.home_pose, actuators=actuators)
    assert str(raised.value).startswith(message)


def test_forward_kinematics_of_the_hexapod_with_named_actuators():
    mechanism_ = mechanism("ups_hexapod_8")
    pose = mechanism_.home_pose + [0.05, -0.03, 0.04, 0.1, -0.05, 0.2]
    solution = solve(mechanism_, pose)
    names = mechanism_.actuators[:6]
    values = actuator_values(mechanism_, solution.joint_values)[:6]
    recovered = forward(mechanism_, values, mechanism_.home_pose, actuators=names)
    assert recovered.reachable
    np.testing.assert_allclose(recovered.poses, pose, atol=1e-9)


def test_newton_initial_values_are_used():
    mechanism_ = mechanism("coop_arms")
    poses = random_poses(mechanism_, (0.02,) * 3 + (0.05,) * 3, 5, seed=12)
    first = solve(mechanism_, poses)
    again = solve(mechanism_, poses + 1e-4, initial=first)
    assert again.reachable.all()
    for first_values, second_values in zip(first.joint_values, again.joint_values):
        assert np.max(np.abs(first_values - second_values)) < 0.01


def test_closure_and_screws_of_a_large_batch_keep_their_shapes():
    """Speed is measured by benchmarks/; here only that a large batch goes through whole."""
    mechanism_ = mechanism("planar_5rrr")
    poses = random_poses(mechanism_, (0.5, 0.5, np.pi), 200_000, seed=13)
    solution = solve(mechanism_, poses)
    screws = chain_screws(mechanism_, solution, unreachable="reference")
    assert len(screws) == 5 and screws[0].twists.shape == (200_000, 3, 6)
    assert np.all(np.isfinite(screws[0].twists))


@pytest.mark.parametrize("name", bundled_names())
def test_an_empty_batch_of_poses_gives_empty_results(name):
    mechanism_ = mechanism(name)
    for method in ("auto", "newton"):
        solution = solve(mechanism_, np.zeros((0, mechanism_.n_task)), method=method)
        assert solution.reachable.shape == (0,) and solution.chain_reachable.shape == (0, len(mechanism_.chains))
        for chain, values, screws in zip(mechanism_.chains, solution.joint_values, chain_screws(mechanism_, solution)):
            assert values.shape == (0, chain.n_joints) and screws.twists.shape == (0, chain.n_joints, 6)


def test_thread_limit_bounds_the_nested_pools_and_keeps_results():
    from screwkit.closure.threads import block_threads

    default = block_threads()
    mechanism = load("planar_5rrr")
    rng = np.random.default_rng(3)
    poses = np.column_stack([rng.uniform(-0.3, 0.3, (70_000, 2)), rng.uniform(0, 2 * np.pi, 70_000)])
    free = chain_screws(mechanism, solve(mechanism, poses), unreachable="drop")
    with thread_limit(1):
        assert block_threads() == 1
        limited = chain_screws(mechanism, solve(mechanism, poses), unreachable="drop")
    assert block_threads() == default
    for a, b in zip(free, limited):
        np.testing.assert_array_equal(a.twists, b.twists)
        np.testing.assert_array_equal(a.points, b.points)
