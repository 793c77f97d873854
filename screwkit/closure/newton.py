"""Closing one chain by damped Newton steps (Levenberg-Marquardt), batched over configurations.

:func:`file_fit` gives a chain's joint values as its file writes them, where the reference assembly starts;
:func:`newton_solve_chain` closes a chain onto target loop frames from start values;
:func:`solve_newton_chain` adds what a mechanism needs around it: continuation from the
reference assembly along straight platform paths, then from solved neighbouring poses, and
the working-mode check (:func:`determinant_sign`).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from screwkit.closure.chain_kinematics import (
    ChainFrames,
    chain_forward_kinematics,
    chain_jacobian,
    loop_values_from_relative_transform,
    twists_from_axes_and_points,
    wrap_revolute_values,
)
from screwkit.common.rotations import (
    rotation_from_rotation_vector,
    rotation_vector_from_rotation,
)
from screwkit.model.chain import ChainGeometry

__all__ = ["pose_error", "apply_step", "newton_solve_chain", "solve_newton_chain", "determinant_sign", "working_sign",
           "with_point_signs", "branch_kept", "task_rows", "file_fit"]


def pose_error(
    target_rotation: NDArray, target_translation: NDArray, rotation: NDArray, translation: NDArray
) -> NDArray[np.float64]:
    """Small-displacement error ``(rotation vector, translation)`` (..., 6) from a frame to a target.

    The rotation part is ``log(R_target R^T)`` (base-frame axes); the translation part is the
    difference of the origins.
    """
    rotation_error = rotation_vector_from_rotation(target_rotation @ np.swapaxes(rotation, -1, -2))
    return np.concatenate([rotation_error, target_translation - translation], -1)


def apply_step(geometry: ChainGeometry, values: NDArray, step: NDArray) -> NDArray:
    """Add a Newton step; spherical loop DoFs compose on the left (leg-side frame axes)."""
    updated = values + step
    if geometry.loop_type == "spherical":
        start = geometry.n_tree_joints
        composed = rotation_from_rotation_vector(step[..., start:]) @ rotation_from_rotation_vector(values[..., start:])
        updated[..., start:] = rotation_vector_from_rotation(composed)
    return updated


def newton_solve_chain(
    geometry: ChainGeometry,
    target_rotation: NDArray,
    target_translation: NDArray,
    initial_values: NDArray,
    tolerance: float = 1e-11,
    max_iterations: int = 40,
    max_step: float = 0.5,
    length: float = 1.0,
) -> tuple[NDArray[np.float64], NDArray[np.bool_], NDArray[np.float64]]:
    """Close one chain onto target platform-side loop frames by damped Newton steps.

    Levenberg-Marquardt in working units (lengths divided by ``length``, the mechanism's length
    scale, so that the damping, the step limit and the tolerance mean the same for a mechanism
    and any scaled copy): the step solves ``(J^T J + (mu + |e|^2) I) dq = J^T e`` and is kept
    only if it lowers ``|e|``; ``mu`` shrinks after a kept step and grows after a rejected one
    (the ``|e|^2`` term keeps convergence quadratic at singular solutions). Steps are limited
    to ``max_step`` (rad or length scales) so the assembly branch does not jump. Batched: every
    iteration works on all configurations not yet converged or stalled.

    Parameters
    ----------
    target_rotation, target_translation : ndarray, shapes (N, 3, 3) and (N, 3)
        Platform-side loop frames to reach (base frame).
    initial_values : ndarray, shape (N, m)

    Returns
    -------
    values : ndarray, shape (N, m)
    converged : ndarray of bool, shape (N,)
        Whether ``|e| < tolerance``, the rotation vector (rad) and translation (length scales)
        stacked.
    residual : ndarray, shape (N,)
        Final ``|e|`` in rad and m (where not converged: how far the chain misses the target).
    """
    values = np.array(initial_values, dtype=float, copy=True)
    count = values.shape[0]
    n_dofs = geometry.n_dofs
    rows_scale = np.array([1.0, 1.0, 1.0, 1.0 / length, 1.0 / length, 1.0 / length])
    columns_scale = np.where(np.asarray(geometry.dof_prismatic, dtype=bool), length, 1.0)

    def errors(at_values: NDArray, rows: NDArray) -> tuple[ChainFrames, NDArray]:
        frames = chain_forward_kinematics(geometry, at_values)
        return frames, rows_scale * pose_error(target_rotation[rows], target_translation[rows], frames.end_rotation,
                                               frames.end_translation)

    _, error = errors(values, np.arange(count))
    residual = np.linalg.norm(error, axis=-1)
    unscaled = np.linalg.norm(error / rows_scale, axis=-1)  # the same error in rad and m, for reports
    damping = np.full(count, 1e-9)
    active = np.flatnonzero((residual >= tolerance) & np.isfinite(residual))
    if n_dofs == 0:
        return values, residual < tolerance, unscaled
    for _ in range(max_iterations):
        if active.size == 0:
            break
        frames, error = errors(values[active], active)
        norm = residual[active]
        jacobian = rows_scale[:, None] * chain_jacobian(geometry, frames) * columns_scale
        transposed = np.swapaxes(jacobian, -1, -2)
        normal = transposed @ jacobian + (damping[active] + norm**2)[:, None, None] * np.eye(n_dofs)
        step = np.linalg.solve(normal, (transposed @ error[..., None]))[..., 0]
        largest = np.max(np.abs(step), axis=-1)
        step *= np.minimum(1.0, max_step / np.maximum(largest, 1e-300))[:, None]
        candidate = apply_step(geometry, values[active], step * columns_scale)
        _, candidate_error = errors(candidate, active)
        candidate_norm = np.linalg.norm(candidate_error, axis=-1)
        better = candidate_norm < norm
        accepted = active[better]
        values[accepted] = candidate[better]
        residual[accepted] = candidate_norm[better]
        unscaled[accepted] = np.linalg.norm(candidate_error[better] / rows_scale, axis=-1)
        damping[accepted] = np.maximum(damping[accepted] * 0.1, 1e-12)
        damping[active[~better]] = np.maximum(damping[active[~better]] * 10.0, 1e-6)
        active = active[(residual[active] >= tolerance) & (damping[active] < 1e4)]
    return values, residual < tolerance, unscaled


def task_rows(is_planar: bool) -> list[int]:
    """Rows of a twist ``(omega, v)`` that a mechanism's platform can move along: (omega_z, v_x, v_y) when planar."""
    return [2, 3, 4] if is_planar else [0, 1, 2, 3, 4, 5]


def determinant_sign(geometry: ChainGeometry, is_planar: bool, axes: NDArray, points: NDArray):
    """Sign of the determinant of a chain's twist matrix in task space (batched); None if not square.

    For one configuration an int (+1, -1) or None when it is singular there.
    """
    rows = task_rows(is_planar)
    if geometry.n_dofs != len(rows):
        return None
    twists = twists_from_axes_and_points(axes, points, geometry.dof_prismatic)[..., rows]
    sign = np.sign(np.linalg.det(twists))
    if np.ndim(sign) == 0:
        return None if sign == 0 else int(sign)
    return sign


def file_fit(mechanism, index: int) -> tuple[NDArray[np.float64], ChainFrames, float, float]:
    """Chain ``index``'s joint values as the file writes them (tree joints at ``<reference_configuration>`` or 0, the
    loop joint's fitted to the platform's loop frame at home), its frames there with the loop joint at 0, and what the
    fit leaves open (m, rad)."""
    chain = mechanism.chains[index]
    geometry = chain.geometry
    tree = np.array([mechanism.description.reference_configuration.get(name, 0.0)
                     for name in chain.joint_names[: geometry.n_tree_joints]])
    frames = chain_forward_kinematics(geometry, np.concatenate([tree, np.zeros(geometry.n_dofs - tree.size)]))
    rotation, translation = mechanism.loop_targets(index, mechanism.home_rotation, mechanism.home_translation)
    loop, position_gap, rotation_gap = loop_values_from_relative_transform(
        geometry, frames.leg_rotation.T @ rotation, frames.leg_rotation.T @ (translation - frames.leg_translation))
    return np.concatenate([tree, loop]), frames, float(position_gap), float(rotation_gap)


def working_sign(mechanism, index: int, frames: ChainFrames):
    """The sign that names the working mode of chain ``index`` at ``frames`` (batched, as :func:`determinant_sign`):
    its twist matrix's determinant in task space; for a planar chain of two joints on a platform whose task
    coordinates are a point's x and y (a five-bar leg that is the output body's own path, its loop fixed), which has
    no such determinant, the sign of its map from joint rates to that point's velocity (its elbow: the two joints
    and the point on one line where it changes). None for any other chain."""
    geometry = mechanism.chains[index].geometry
    if geometry.n_dofs == len(task_rows(mechanism.is_planar)):
        return determinant_sign(geometry, mechanism.is_planar, frames.axes, frames.points)
    if not (mechanism.is_planar and geometry.n_dofs == 2 and mechanism.task_coordinates == ("x", "y")):
        return None
    platform = frames.end_rotation @ np.swapaxes(geometry.platform_loop_rotation, -1, -2)
    point = frames.end_translation - np.einsum("...ij,j->...i", platform, geometry.platform_loop_translation)
    twists = twists_from_axes_and_points(frames.axes, frames.points, geometry.dof_prismatic)
    velocity = twists[..., 3:] + np.cross(twists[..., :3], point[..., None, :])  # (..., 2 joints, 3) at the point
    sign = np.sign(np.linalg.det(velocity[..., :2]))
    if np.ndim(sign) == 0:
        return None if sign == 0 else int(sign)
    return sign


def with_point_signs(mechanism):
    """``mechanism`` with the working mode of each Newton chain that has a :func:`working_sign` only once its task
    coordinates are known (a planar two-joint chain to a point output) kept: its sign at the reference assembly."""
    chains, changed = list(mechanism.chains), False
    for index, chain in enumerate(chains):
        if chain.closed_form is None and chain.branch is None and chain.reference_values is not None:
            sign = working_sign(mechanism, index, chain_forward_kinematics(chain.geometry, chain.reference_values))
            if sign is not None:
                chains[index], changed = replace(chain, branch=sign, reference_sign=sign), True
    return replace(mechanism, chains=tuple(chains)) if changed else mechanism


def branch_kept(mechanism, index: int, values: NDArray, branch) -> NDArray[np.bool_]:
    """Whether chain ``index`` at joint ``values`` (N, m; NaN read as 0) keeps the working-mode sign ``branch``
    (:func:`working_sign`; every row where ``branch`` is None)."""
    if branch is None:
        return np.ones(values.shape[0], dtype=bool)
    frames = chain_forward_kinematics(mechanism.chains[index].geometry, np.nan_to_num(values))
    return working_sign(mechanism, index, frames) == branch


def _track(mechanism, index, source, values, goal, tolerance, max_iterations):
    """Follow straight platform paths (geodesic in rotation) from ``source`` to ``goal`` poses."""
    geometry = mechanism.chains[index].geometry
    source_rotation, source_translation = source
    goal_rotation, goal_translation = goal
    rotation_step = rotation_vector_from_rotation(np.swapaxes(source_rotation, -1, -2) @ goal_rotation)
    translation_step = goal_translation - source_translation
    distance = np.maximum(
        np.linalg.norm(translation_step, axis=-1) / mechanism.length_scale, np.linalg.norm(rotation_step, axis=-1)
    )
    steps = int(min(64, max(1, math.ceil(float(np.max(distance, initial=0.0)) / 0.1))))
    values = np.array(values, dtype=float, copy=True)
    for step in range(1, steps + 1):
        fraction = step / steps
        rotation = source_rotation @ rotation_from_rotation_vector(fraction * rotation_step)
        translation = source_translation + fraction * translation_step
        targets = mechanism.loop_targets(index, rotation, translation)
        last = step == steps
        values, converged, residual = newton_solve_chain(
            geometry, *targets, values, tolerance if last else 1e-8, max_iterations if last else 12,
            length=mechanism.length_scale
        )
        values = np.where(np.isfinite(values), values, 0.0)
    return values, converged, residual


def _scaled_poses(mechanism, flat_poses: NDArray) -> NDArray:
    """Poses with angles multiplied by the length scale, for nearest-neighbour lookups."""
    scaled = flat_poses.copy()
    scaled[:, mechanism.pose_angular] *= mechanism.length_scale
    return scaled


def solve_newton_chain(mechanism, index, flat_poses, platform, start, branch, tolerance, max_iterations):
    """Newton closure of chain ``index`` at flat poses (N, n_task), with continuation.

    Start values are ``start`` (N, m) where given (finite), else continuation along straight
    platform paths from the reference assembly; configurations that still fail are retried
    from their nearest solved neighbour (twice). ``branch`` (+1/-1/None) is the required sign
    of the chain's twist-matrix determinant. ``tolerance`` is in rad and length scales
    (:func:`newton_solve_chain`), so a scaled copy of a mechanism closes alike.

    Returns
    -------
    values : ndarray (N, m), NaN where not closed
    converged : ndarray (N,) of bool
    residual : ndarray (N,)
        The final loop error norm (m and rad).
    """
    geometry = mechanism.chains[index].geometry
    count = flat_poses.shape[0]
    targets = mechanism.loop_targets(index, *platform)
    values = np.empty((count, geometry.n_dofs))
    converged = np.zeros(count, dtype=bool)
    residual = np.full(count, np.inf)
    given = np.zeros(count, dtype=bool) if start is None else np.all(np.isfinite(start), axis=-1)
    if np.any(given):  # Newton from the given start values
        rows = np.flatnonzero(given)
        values[rows], converged[rows], residual[rows] = newton_solve_chain(
            geometry, targets[0][rows], targets[1][rows], start[rows], tolerance, max_iterations,
            length=mechanism.length_scale
        )
    if not np.all(given):  # continuation from the reference assembly
        rows = np.flatnonzero(~given)
        reference = np.broadcast_to(mechanism.chains[index].reference_values, (rows.size, geometry.n_dofs))
        home = (
            np.broadcast_to(mechanism.home_rotation, (rows.size, 3, 3)),
            np.broadcast_to(mechanism.home_translation, (rows.size, 3)),
        )
        goal = (platform[0][rows], platform[1][rows])
        values[rows], converged[rows], residual[rows] = _track(
            mechanism, index, home, reference, goal, tolerance, max_iterations
        )
    converged &= branch_kept(mechanism, index, values, branch)
    scaled = _scaled_poses(mechanism, flat_poses)
    for _ in range(2):  # continuation from solved neighbours
        failed = np.flatnonzero(~converged)
        solved = np.flatnonzero(converged)
        if failed.size == 0 or solved.size == 0:
            break
        from scipy.spatial import (
            cKDTree,  # scipy loads only when a Newton chain needs neighbours
        )

        _, nearest = cKDTree(scaled[solved]).query(scaled[failed])
        neighbours = solved[nearest]
        source = (platform[0][neighbours], platform[1][neighbours])
        goal = (platform[0][failed], platform[1][failed])
        retried, retried_converged, retried_residual = _track(
            mechanism, index, source, values[neighbours], goal, tolerance, max_iterations
        )
        retried_converged &= branch_kept(mechanism, index, retried, branch)
        better = retried_converged | (retried_residual < residual[failed])
        values[failed[better]] = retried[better]
        residual[failed[better]] = retried_residual[better]
        converged[failed] = retried_converged
    values = wrap_revolute_values(geometry, values)
    values[~converged] = np.nan
    return values, converged, residual
