"""Compiled closure of the constraining chains: the dependent pose coordinates of lower-mobility mechanisms.

One numba function runs, for each configuration on its own, the damped Newton iteration
(Levenberg-Marquardt) documented in :func:`screwkit.closure.task_space.close_constraining_chains`,
with the continuation of :func:`screwkit.closure.task_space.complete_poses` inside: unknowns are
the free pose coordinates and the joint values of every constraining chain; residuals are the
chains' closure errors ``(log(R_target R^T), t_target - t)``. The forward kinematics is that of
:func:`screwkit.closure.chain_kinematics.chain_forward_kinematics` written out for one
configuration, and the normal equations are built chain by chain (a chain's six rows touch only
the free coordinates and its own joints) and solved by Cholesky. The Python loop over
configurations of the numpy version becomes a compiled one: nothing else changes.

:func:`close_chains_kernel` is a short driver over named stages that numba inlines (``inline="always"``, so
that it compiles as one function, with the results, bit for bit, of the loops written out in it): the
continuation's predictor (:func:`_predict_step`), the Jacobian (:func:`_jacobian`), the damped normal
equations (:func:`_normal_equations`), the trial step (:func:`_candidate`) and its acceptance (:func:`_accept`).

Geometry comes packed (:func:`screwkit.closure.task_space.packed_geometry`): tree joints of all
chains stacked with offsets, loop joints coded 0 fixed, 1 revolute, 2 prismatic, 3 universal,
4 spherical.
"""

from __future__ import annotations

import math

import numpy as np

from screwkit.closure.compiled.frames import (
    apply,
    exp_map,
    leg_frames,
    log_map,
    matrix_at,
    mul,
    mul_transposed,
)
from screwkit.common.jit import njit


@njit(cache=True, nogil=True, error_model="numpy")
def _platform(pose, planar, planar_z):
    """Platform frame (rotation 9-tuple, translation 3-tuple) of a full pose (rpy ``Rz Ry Rx``; planar
    ``Rz(phi)`` at height ``planar_z``)."""
    if planar:
        c, s = math.cos(pose[2]), math.sin(pose[2])
        return (c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0), (pose[0], pose[1], planar_z)
    cr, sr = math.cos(pose[3]), math.sin(pose[3])
    cp, sp = math.cos(pose[4]), math.sin(pose[4])
    cy, sy = math.cos(pose[5]), math.sin(pose[5])
    return ((cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr,
             sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr,
             -sp, cp * sr, cp * cr), (pose[0], pose[1], pose[2]))


@njit(cache=True, nogil=True, error_model="numpy")
def _pose_rates(pose, planar, free, rates):
    """d(platform twist: angular velocity, origin velocity)/d(free pose coordinates), (6, F)."""
    rates[:, :] = 0.0
    for column in range(free.size):
        axis = free[column]
        if planar:
            if axis == 2:
                rates[2, column] = 1.0
            else:
                rates[3 + axis, column] = 1.0
        elif axis < 3:
            rates[3 + axis, column] = 1.0
        elif axis == 3:
            cp, yaw = math.cos(pose[4]), pose[5]
            rates[0, column] = math.cos(yaw) * cp
            rates[1, column] = math.sin(yaw) * cp
            rates[2, column] = -math.sin(pose[4])
        elif axis == 4:
            rates[0, column], rates[1, column] = -math.sin(pose[5]), math.cos(pose[5])
        else:
            rates[2, column] = 1.0


@njit(cache=True, nogil=True, error_model="numpy")
def _errors(pose, values, planar, planar_z, tree_start, dof_start, joint_rot, joint_trans, joint_axis, joint_prism,
            leg_rot, leg_trans, loop_code, loop_axes, plat_rot, plat_trans, axes, points, ends, targets, error):
    """Closure errors (6 C,) of every constraining chain at (pose, values); returns their norm.

    Also writes each joint DoF's axis and point, each chain's reached loop-frame origin (``ends``)
    and its target (``targets``), base frame, for the Jacobian.
    """
    platform_rotation, platform_translation = _platform(pose, planar, planar_z)
    total = 0.0
    for c in range(loop_code.size):
        _, _, rotation, (t0, t1, t2) = leg_frames(c, values, tree_start, dof_start, joint_rot, joint_trans,
                                                  joint_axis, joint_prism, leg_rot, leg_trans, loop_code, loop_axes,
                                                  axes, points)
        target = mul(platform_rotation, matrix_at(plat_rot, c))
        d0, d1, d2 = apply(platform_rotation, plat_trans[c, 0], plat_trans[c, 1], plat_trans[c, 2])
        targets[c, 0] = platform_translation[0] + d0
        targets[c, 1] = platform_translation[1] + d1
        targets[c, 2] = platform_translation[2] + d2
        ends[c, 0], ends[c, 1], ends[c, 2] = t0, t1, t2
        e0, e1, e2 = log_map(mul_transposed(target, rotation))
        row = 6 * c
        error[row], error[row + 1], error[row + 2] = e0, e1, e2
        error[row + 3], error[row + 4], error[row + 5] = targets[c, 0] - t0, targets[c, 1] - t1, targets[c, 2] - t2
    for k in range(error.size):
        total += error[k] * error[k]
    return math.sqrt(total)


@njit(cache=True, nogil=True, error_model="numpy")
def _cholesky_solve(matrix, rhs, size):
    """Solve matrix x = rhs in place (rhs), matrix (size, size) symmetric positive definite, overwritten."""
    for j in range(size):
        diagonal = matrix[j, j]
        for k in range(j):
            diagonal -= matrix[j, k] * matrix[j, k]
        if not diagonal > 0.0:
            return False
        diagonal = math.sqrt(diagonal)
        matrix[j, j] = diagonal
        for i in range(j + 1, size):
            value = matrix[i, j]
            for k in range(j):
                value -= matrix[i, k] * matrix[j, k]
            matrix[i, j] = value / diagonal
    for i in range(size):
        value = rhs[i]
        for k in range(i):
            value -= matrix[i, k] * rhs[k]
        rhs[i] = value / matrix[i, i]
    for i in range(size - 1, -1, -1):
        value = rhs[i]
        for k in range(i + 1, size):
            value -= matrix[k, i] * rhs[k]
        rhs[i] = value / matrix[i, i]
    return True


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _scratch(chains, n_free, n_values, pose_size, task_size):
    """The scratch of one call: joint axes, points, chain ends and targets, errors (current and candidate), pose
    rates, Jacobian, normal matrix, gradient, candidate pose and values, the task coordinates at the start and the
    previous step's pose and values."""
    size = n_free + n_values
    rows = 6 * chains
    return (np.empty((n_values, 3)), np.empty((n_values, 3)), np.empty((n_values, 3)), np.empty((n_values, 3)),
            np.empty((chains, 3)), np.empty((chains, 3)), np.empty((chains, 3)), np.empty((chains, 3)),
            np.empty(rows), np.empty(rows), np.empty((6, max(n_free, 1))), np.zeros((rows, size)),
            np.empty((size, size)), np.empty(size), np.empty(pose_size), np.empty(n_values), np.empty(task_size),
            np.empty(pose_size), np.empty(n_values))


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _predict_step(pose, value, target, task, free, start_task, step, count, previous_pose, previous_values):
    """Start of continuation step ``step`` of ``count``: the secant predictor (the last step's change again, equal
    steps in task coordinates) for the free coordinates and joint values, the task coordinates moved to their
    fraction of the way from ``start_task`` to ``target``."""
    if step > 1:
        for f in range(free.size):
            change = pose[free[f]] - previous_pose[free[f]]
            previous_pose[free[f]] = pose[free[f]]
            pose[free[f]] += change
        for d in range(value.size):
            change = value[d] - previous_values[d]
            previous_values[d] = value[d]
            value[d] += change
    else:
        previous_pose[:] = pose
        previous_values[:] = value
    fraction = step / count
    for k in range(task.size):
        pose[task[k]] = start_task[k] + fraction * (target[k] - start_task[k])


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _jacobian(pose, planar, planar_z, free, rates, target_points, ends, axes, points, dof_start, dof_prism, jacobian):
    """d(errors)/d(free pose coordinates, joint values), in rad and length scales, chain by chain."""
    n_free = free.size
    _pose_rates(pose, planar, free, rates)
    _, platform_translation = _platform(pose, planar, planar_z)
    for c in range(dof_start.size - 1):
        r0 = 6 * c
        arm0 = target_points[c, 0] - platform_translation[0]
        arm1 = target_points[c, 1] - platform_translation[1]
        arm2 = target_points[c, 2] - platform_translation[2]
        for f in range(n_free):
            w0, w1, w2 = rates[0, f], rates[1, f], rates[2, f]
            jacobian[r0, f] = w0
            jacobian[r0 + 1, f] = w1
            jacobian[r0 + 2, f] = w2
            jacobian[r0 + 3, f] = rates[3, f] + w1 * arm2 - w2 * arm1
            jacobian[r0 + 4, f] = rates[4, f] + w2 * arm0 - w0 * arm2
            jacobian[r0 + 5, f] = rates[5, f] + w0 * arm1 - w1 * arm0
        for d in range(dof_start[c], dof_start[c + 1]):
            column = n_free + d
            a0, a1, a2 = axes[d, 0], axes[d, 1], axes[d, 2]
            if dof_prism[d]:
                jacobian[r0, column] = jacobian[r0 + 1, column] = jacobian[r0 + 2, column] = 0.0
                jacobian[r0 + 3, column] = -a0
                jacobian[r0 + 4, column] = -a1
                jacobian[r0 + 5, column] = -a2
            else:
                p0 = ends[c, 0] - points[d, 0]
                p1 = ends[c, 1] - points[d, 1]
                p2 = ends[c, 2] - points[d, 2]
                jacobian[r0, column] = -a0
                jacobian[r0 + 1, column] = -a1
                jacobian[r0 + 2, column] = -a2
                jacobian[r0 + 3, column] = -(a1 * p2 - a2 * p1)
                jacobian[r0 + 4, column] = -(a2 * p0 - a0 * p2)
                jacobian[r0 + 5, column] = -(a0 * p1 - a1 * p0)


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _normal_equations(jacobian, error, n_free, dof_start, damping, norm, normal, gradient):
    """normal = J^T J + (damping + norm^2) I (both triangles) and gradient = J^T error, chain by chain (a chain's
    rows touch the free columns and its own)."""
    size = gradient.size
    normal[:, :] = 0.0
    gradient[:] = 0.0
    for c in range(dof_start.size - 1):
        r0 = 6 * c
        touched = n_free + dof_start[c + 1] - dof_start[c]
        for a in range(touched):
            i = a if a < n_free else a + dof_start[c]
            g = 0.0
            for r in range(r0, r0 + 6):
                g += jacobian[r, i] * error[r]
            gradient[i] += g
            for b in range(a + 1):
                j = b if b < n_free else b + dof_start[c]
                s = 0.0
                for r in range(r0, r0 + 6):
                    s += jacobian[r, i] * jacobian[r, j]
                normal[i, j] += s
    shift = damping + norm * norm
    for i in range(size):
        normal[i, i] += shift
        for j in range(i):
            normal[j, i] = normal[i, j]


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _candidate(pose, value, gradient, max_step, free, dof_start, loop_code, candidate_pose, candidate_values):
    """The trial point: the Newton step ``gradient`` (scaled so that no entry exceeds ``max_step``) taken from
    (pose, value), composed on the left for the three values of a spherical loop."""
    n_free = free.size
    largest = 0.0
    for i in range(gradient.size):
        largest = max(largest, abs(gradient[i]))
    factor = min(1.0, max_step / max(largest, 1e-300))
    for i in range(pose.size):
        candidate_pose[i] = pose[i]
    for f in range(n_free):
        candidate_pose[free[f]] -= gradient[f] * factor
    for d in range(value.size):
        candidate_values[d] = value[d] - gradient[n_free + d] * factor
    for c in range(loop_code.size):
        if loop_code[c] == 4:  # spherical loop: compose the step on the left
            s = dof_start[c + 1] - 3
            u0 = -gradient[n_free + s] * factor
            u1 = -gradient[n_free + s + 1] * factor
            u2 = -gradient[n_free + s + 2] * factor
            composed = mul(exp_map(u0, u1, u2), exp_map(value[s], value[s + 1], value[s + 2]))
            candidate_values[s], candidate_values[s + 1], candidate_values[s + 2] = log_map(composed)


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _accept(pose, value, error, axes, points, ends, target_points, candidate_pose, candidate_values, candidate_error,
            candidate_axes, candidate_points, candidate_ends, candidate_targets):
    """The trial point becomes the current one, with its errors and what the Jacobian reads."""
    pose[:] = candidate_pose
    value[:] = candidate_values
    error[:] = candidate_error
    axes[:, :] = candidate_axes
    points[:, :] = candidate_points
    ends[:, :] = candidate_ends
    target_points[:, :] = candidate_targets


@njit(cache=True, nogil=True, error_model="numpy")
def close_chains_kernel(poses, values, targets, steps, task, free, planar, planar_z, tree_start, dof_start,
                        joint_rot, joint_trans, joint_axis, joint_prism, dof_prism, leg_rot, leg_trans, loop_code,
                        loop_axes, plat_rot, plat_trans, tolerance, iterations, step_tolerance, step_iterations,
                        max_step, residual):
    """Close the constraining chains of every configuration, in place.

    For configuration n, the task coordinates ``task`` move from ``poses[n, task]`` to
    ``targets[n]`` in ``steps[n]`` equal steps; each step is closed by Levenberg-Marquardt on
    the free pose coordinates and every chain's joint values (``step_tolerance`` and
    ``step_iterations`` for the intermediate steps, ``tolerance`` and ``iterations`` for the
    last). ``residual[n]`` receives the final closure error norm.
    """
    (axes, candidate_axes, points, candidate_points, ends, candidate_ends, target_points, candidate_targets, error,
     candidate_error, rates, jacobian, normal, gradient, candidate_pose, candidate_values, start_task, previous_pose,
     previous_values) = _scratch(loop_code.size, free.size, values.shape[1], poses.shape[1], task.size)
    for n in range(poses.shape[0]):
        pose = poses[n]
        value = values[n]
        for k in range(task.size):
            start_task[k] = pose[task[k]]
        count = steps[n]
        norm = np.inf
        for step in range(1, count + 1):
            _predict_step(pose, value, targets[n], task, free, start_task, step, count, previous_pose,
                          previous_values)
            last = step == count
            limit = tolerance if last else step_tolerance
            norm = _errors(pose, value, planar, planar_z, tree_start, dof_start, joint_rot, joint_trans, joint_axis,
                           joint_prism, leg_rot, leg_trans, loop_code, loop_axes, plat_rot, plat_trans, axes, points,
                           ends, target_points, error)
            damping = 1e-9
            for _ in range(iterations if last else step_iterations):
                if not (norm >= limit and np.isfinite(norm)) or damping >= 1e4:
                    break
                _jacobian(pose, planar, planar_z, free, rates, target_points, ends, axes, points, dof_start, dof_prism,
                          jacobian)
                _normal_equations(jacobian, error, free.size, dof_start, damping, norm, normal, gradient)
                if not _cholesky_solve(normal, gradient, gradient.size):
                    damping *= 10.0
                    continue
                _candidate(pose, value, gradient, max_step, free, dof_start, loop_code, candidate_pose,
                           candidate_values)
                candidate_norm = _errors(candidate_pose, candidate_values, planar, planar_z, tree_start, dof_start,
                                         joint_rot, joint_trans, joint_axis, joint_prism, leg_rot, leg_trans,
                                         loop_code, loop_axes, plat_rot, plat_trans, candidate_axes,
                                         candidate_points, candidate_ends, candidate_targets, candidate_error)
                if candidate_norm < norm:
                    _accept(pose, value, error, axes, points, ends, target_points, candidate_pose, candidate_values,
                            candidate_error, candidate_axes, candidate_points, candidate_ends, candidate_targets)
                    norm = candidate_norm
                    damping = max(damping * 0.1, 1e-12)
                else:
                    damping = max(damping * 10.0, 1e-6)
        residual[n] = norm
