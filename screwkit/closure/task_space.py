"""Task coordinates of any mobility: the independent pose coordinates and the dependent ones.

A mechanism of lower mobility (a 3-PRS: z, roll, pitch; a Delta: x, y, z) is driven through
its **task coordinates**; its other pose coordinates are *dependent* (parasitic) and follow
from the closure of the chains that constrain the platform. :func:`complete_poses` finds them:
batched Levenberg-Marquardt on the dependent coordinates and the joint values of the
constraining chains together, with continuation from the reference assembly.
:func:`infer_task_axes` chooses the task coordinates from the platform's motion space, and
:func:`motion_space_at` gives that space (and so the instantaneous DOF) at closed configurations.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from screwkit.closure.chain_kinematics import (
    chain_forward_kinematics,
    chain_jacobian,
    twists_from_axes_and_points,
    wrap_revolute_values,
)
from screwkit.closure.newton import apply_step, pose_error
from screwkit.model.mechanism import Mechanism
from screwkit.tolerances import MOTION_SPACE_TOLERANCE, NEWTON_TOLERANCE

__all__ = [
    "pose_rates",
    "constraining_chains",
    "complete_poses",
    "close_constraining_chains",
    "motion_space_at",
    "infer_task_axes",
]

TASK_RANK_TOLERANCE = 1e-6
"""A pose coordinate is independent of those chosen before it when the rates of the chosen ones
on an orthonormal basis of the motion space (lengths in units of the length scale) keep a
smallest singular value above this."""


def pose_rates(mechanism: Mechanism, full_poses: NDArray) -> NDArray[np.float64]:
    """d(platform frame)/d(pose coordinates): (N, 6, n_pose), rows (angular velocity, velocity of
    the platform frame's origin), base frame."""
    count = full_poses.shape[0]
    rates = np.zeros((count, 6, mechanism.n_pose))
    if mechanism.is_planar:
        rates[:, 2, 2] = 1.0
        rates[:, 3, 0] = rates[:, 4, 1] = 1.0
        return rates
    pitch, yaw = full_poses[:, 4], full_poses[:, 5]
    zero, one = np.zeros(count), np.ones(count)
    # R = Rz(yaw) Ry(pitch) Rx(roll): omega = z yaw' + Rz(yaw) y pitch' + Rz(yaw) Ry(pitch) x roll'
    rates[:, :3, 3] = np.stack([np.cos(yaw) * np.cos(pitch), np.sin(yaw) * np.cos(pitch), -np.sin(pitch)], -1)
    rates[:, :3, 4] = np.stack([-np.sin(yaw), np.cos(yaw), zero], -1)
    rates[:, :3, 5] = np.stack([zero, zero, one], -1)
    rates[:, 3:, :3] = np.eye(3)
    return rates


def _chain_rank(mechanism: Mechanism, index: int) -> int:
    chain = mechanism.chains[index]
    frames = chain_forward_kinematics(chain.geometry, chain.reference_values)
    twists = twists_from_axes_and_points(frames.axes, frames.points, chain.prismatic)
    twists = twists / np.maximum(np.linalg.norm(twists, axis=-1, keepdims=True), 1e-300)
    rows = [2, 3, 4] if mechanism.is_planar else list(range(6))
    singular = np.linalg.svd(twists[:, rows], compute_uv=False)
    return int(np.sum(singular > MOTION_SPACE_TOLERANCE * max(singular[0], 1e-300))) if singular.size else 0


def constraining_chains(mechanism: Mechanism) -> tuple[int, ...]:
    """Chains whose joints do not span every platform motion: those whose closure ties the dependent coordinates."""
    return tuple(index for index in range(len(mechanism.chains)) if _chain_rank(mechanism, index) < mechanism.n_pose)


def _residuals(mechanism, chains, full_poses, values):
    """Closure errors (N, 6 c) of the constraining chains and their frames."""
    rotation, translation = mechanism.transforms_from_poses(full_poses)
    errors, frames = [], []
    for index, chain_values in zip(chains, values):
        chain_frames = chain_forward_kinematics(mechanism.chains[index].geometry, chain_values)
        target_rotation, target_translation = mechanism.loop_targets(index, rotation, translation)
        errors.append(pose_error(target_rotation, target_translation, chain_frames.end_rotation,
                                 chain_frames.end_translation))
        frames.append(chain_frames)
    return np.concatenate(errors, axis=-1), frames


def _jacobian(mechanism, chains, full_poses, frames, free_axes):
    """d(closure errors)/d(free pose coordinates, joint values): (N, 6 c, len(free) + sum m)."""
    count = full_poses.shape[0]
    rates = pose_rates(mechanism, full_poses)[:, :, list(free_axes)]  # (N, 6, f)
    _, translation = mechanism.transforms_from_poses(full_poses)
    rotation, _ = mechanism.transforms_from_poses(full_poses)
    sizes = [mechanism.chains[index].n_joints for index in chains]
    jacobian = np.zeros((count, 6 * len(chains), len(free_axes) + sum(sizes)))
    column = len(free_axes)
    for row, (index, chain_frames, size) in enumerate(zip(chains, frames, sizes)):
        _, target = mechanism.loop_targets(index, rotation, translation)
        arm = target - translation  # the loop frame's origin relative to the platform frame's
        moved = rates.copy()
        moved[:, 3:] += np.swapaxes(np.cross(np.swapaxes(rates[:, :3], 1, 2), arm[:, None, :]), 1, 2)
        jacobian[:, 6 * row:6 * row + 6, :len(free_axes)] = moved
        jacobian[:, 6 * row:6 * row + 6, column:column + size] = -chain_jacobian(mechanism.chains[index].geometry,
                                                                                  chain_frames)
        column += size
    return jacobian


def close_constraining_chains(mechanism, chains, full_poses, values, free_axes, tolerance, iterations, max_step):
    """Close the constraining chains by moving the free pose coordinates and their joints together.

    Levenberg-Marquardt as :func:`screwkit.closure.newton.newton_solve_chain`, on the unknowns
    (free pose coordinates, joint values of every constraining chain) with lengths in units of
    the length scale; batched over configurations.
    """
    full_poses = np.array(full_poses, dtype=float, copy=True)
    values = [np.array(v, dtype=float, copy=True) for v in values]
    count = full_poses.shape[0]
    error, _ = _residuals(mechanism, chains, full_poses, values)
    residual = np.linalg.norm(error, axis=-1)
    damping = np.full(count, 1e-9)
    active = np.flatnonzero((residual >= tolerance) & np.isfinite(residual))
    sizes = [mechanism.chains[index].n_joints for index in chains]
    scale = np.concatenate([np.where(mechanism.pose_angular[list(free_axes)], 1.0, mechanism.length_scale),
                            np.ones(sum(sizes))])
    for _ in range(iterations):
        if active.size == 0:
            break
        current_poses = full_poses[active]
        current_values = [v[active] for v in values]
        current_error, frames = _residuals(mechanism, chains, current_poses, current_values)
        jacobian = _jacobian(mechanism, chains, current_poses, frames, free_axes) * scale
        transposed = np.swapaxes(jacobian, -1, -2)
        norm = residual[active]
        normal = transposed @ jacobian + (damping[active] + norm**2)[:, None, None] * np.eye(jacobian.shape[-1])
        step = -np.linalg.solve(normal, transposed @ current_error[..., None])[..., 0]
        largest = np.max(np.abs(step), axis=-1)
        step *= np.minimum(1.0, max_step / np.maximum(largest, 1e-300))[:, None]
        step *= scale
        candidate_poses = current_poses.copy()
        candidate_poses[:, list(free_axes)] += step[:, :len(free_axes)]
        candidate_values, column = [], len(free_axes)
        for index, chain_values, size in zip(chains, current_values, sizes):
            candidate_values.append(apply_step(mechanism.chains[index].geometry, chain_values,
                                               step[:, column:column + size]))
            column += size
        candidate_error, _ = _residuals(mechanism, chains, candidate_poses, candidate_values)
        candidate_norm = np.linalg.norm(candidate_error, axis=-1)
        better = candidate_norm < norm
        accepted = active[better]
        full_poses[accepted] = candidate_poses[better]
        for chain_values, candidate in zip(values, candidate_values):
            chain_values[accepted] = candidate[better]
        residual[accepted] = candidate_norm[better]
        damping[accepted] = np.maximum(damping[accepted] * 0.1, 1e-12)
        damping[active[~better]] = np.maximum(damping[active[~better]] * 10.0, 1e-6)
        active = active[(residual[active] >= tolerance) & (damping[active] < 1e4)]
    return full_poses, values, residual < tolerance, residual


def complete_poses(mechanism: Mechanism, task_poses: NDArray, *, start_poses: NDArray | None = None,
                   start_values=None, tolerance: float = NEWTON_TOLERANCE, iterations: int = 40):
    """Full poses (N, n_pose) of task poses (N, n_task): the dependent coordinates that close the chains.

    Continuation from the reference assembly along straight paths in task coordinates (steps of
    at most 0.1 rad and 0.1 length scales), each step closed by Levenberg-Marquardt on the
    dependent coordinates and the joint values of the :func:`constraining_chains` together.

    Returns
    -------
    full_poses : ndarray (N, n_pose)
    values : list of ndarray (N, m_i)
        Joint values of the constraining chains (in :func:`constraining_chains` order).
    converged : ndarray (N,) of bool
    residual : ndarray (N,)
        The closure error norm left (m and rad).
    """
    task_poses = np.asarray(task_poses, dtype=float)
    count = task_poses.shape[0]
    chains = constraining_chains(mechanism)
    free = mechanism.dependent_indices
    if start_poses is None:
        start_poses = np.broadcast_to(mechanism.home_full_pose, (count, mechanism.n_pose))
        start_values = [np.broadcast_to(mechanism.chains[i].reference_values, (count, mechanism.chains[i].n_joints))
                        for i in chains]
    if not chains or not free:
        return mechanism.full_poses(task_poses, np.asarray(start_poses)[:, list(free)]), [], \
            np.ones(count, dtype=bool), np.zeros(count)
    start_task = mechanism.task_poses(start_poses)
    distance = np.abs(task_poses - start_task) / np.where(mechanism.angular, 1.0, mechanism.length_scale)
    steps = int(min(64, max(1, math.ceil(float(np.max(distance, initial=0.0)) / 0.1))))
    poses = np.array(start_poses, dtype=float, copy=True)
    values = [np.array(v, dtype=float, copy=True) for v in start_values]
    converged, residual = np.zeros(count, dtype=bool), np.full(count, np.inf)
    for step in range(1, steps + 1):
        fraction = step / steps
        poses[:, list(mechanism.task_indices)] = start_task + fraction * (task_poses - start_task)
        last = step == steps
        poses, values, converged, residual = close_constraining_chains(
            mechanism, chains, poses, values, free, tolerance if last else 1e-8, iterations if last else 12,
            max_step=0.5)
    values = [wrap_revolute_values(mechanism.chains[i].geometry, v) for i, v in zip(chains, values)]
    return poses, values, converged, residual


def motion_space_at(mechanism: Mechanism, full_poses: NDArray, joint_values) -> tuple[NDArray, NDArray]:
    """The platform's motion space at closed configurations, in pose-coordinate rates.

    Parameters
    ----------
    full_poses : ndarray (N, n_pose)
    joint_values : sequence of ndarray (N, m_i), one per chain

    Returns
    -------
    dof : ndarray (N,) of int
        Instantaneous DOF: dimension of the intersection of the chains' twist spaces.
    rates : ndarray (N, n_pose, n_pose)
        Orthonormal basis (columns, first ``dof`` of them) of the pose-coordinate rates the
        platform can follow (lengths in units of the length scale).
    """
    count = full_poses.shape[0]
    rotation, translation = mechanism.transforms_from_poses(full_poses)
    rows = [2, 3, 4] if mechanism.is_planar else list(range(6))
    total = np.zeros((count, len(rows), len(rows)))
    for chain, values in zip(mechanism.chains, joint_values):
        frames = chain_forward_kinematics(chain.geometry, values)
        twists = twists_from_axes_and_points(frames.axes, frames.points - translation[:, None, :], chain.prismatic)
        twists = np.concatenate([twists[..., :3], twists[..., 3:] / mechanism.length_scale], axis=-1)[..., rows]
        twists = twists / np.maximum(np.linalg.norm(twists, axis=-1, keepdims=True), 1e-300)
        left, singular, _ = np.linalg.svd(np.swapaxes(twists, -1, -2), full_matrices=False)
        mask = singular > MOTION_SPACE_TOLERANCE * np.maximum(singular[..., :1], 1e-300)
        basis = left * mask[..., None, :]
        total += np.eye(len(rows)) - basis @ np.swapaxes(basis, -1, -2)
    eigenvalues, eigenvectors = np.linalg.eigh(total)
    dof = np.sum(eigenvalues <= 1e-8, axis=-1)
    # twists (omega, v / length) about the platform origin -> pose-coordinate rates (lengths / length)
    rates = pose_rates(mechanism, full_poses)
    rates = np.concatenate([rates[:, :3], rates[:, 3:] / mechanism.length_scale], axis=1)[:, rows]
    rates = rates * np.where(mechanism.pose_angular, 1.0, mechanism.length_scale)  # per length-scaled coordinate
    coordinates = np.linalg.pinv(rates) @ eigenvectors
    basis, _ = np.linalg.qr(coordinates)
    return dof, basis


def infer_task_axes(mechanism: Mechanism, full_pose: NDArray, joint_values, dof: int,
                    candidates=None) -> tuple[int, ...]:
    """The first ``dof`` pose coordinates, in order, whose rates are independent on the motion space.

    ``joint_values`` holds one (m_i,) array per chain at the closed configuration ``full_pose``;
    ``candidates`` restricts the coordinates tried (the translations of a point output).
    """
    dofs, basis = motion_space_at(mechanism, full_pose[None], [np.asarray(v)[None] for v in joint_values])
    space = basis[0][:, :int(dofs[0])]
    chosen: list[int] = []
    for axis in (range(mechanism.n_pose) if candidates is None else candidates):
        trial = space[chosen + [axis]]
        singular = np.linalg.svd(trial, compute_uv=False)
        if singular.size and singular[-1] > TASK_RANK_TOLERANCE:
            chosen.append(axis)
        if len(chosen) == dof:
            break
    return tuple(chosen)
