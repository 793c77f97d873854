"""Rotations on plain arrays, batched on leading axes (numpy only).

Rotation matrices are arrays (..., 3, 3), rotation vectors (axis times angle) and roll, pitch,
yaw angles arrays (..., 3). Roll, pitch, yaw follow the URDF ``rpy`` convention:
``R = Rz(yaw) Ry(pitch) Rx(roll)`` (rotations about the fixed x, y, z axes, in that order).
The two Paden-Kahan subproblems used by the closed-form chain solvers are here too.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "cross",
    "wrap_angle",
    "skew_matrix",
    "rotation_about_axis",
    "rotation_with_z_along",
    "rotation_from_rotation_vector",
    "rotation_vector_from_rotation",
    "rotation_from_rpy",
    "rpy_from_rotation",
    "angle_about_axis",
    "rotation_angle_to_align",
    "two_axis_pointing",
    "quaternion_from_rotation",
]

_IDENTITY = np.eye(3)


def wrap_angle(angles: ArrayLike) -> NDArray[np.float64]:
    """Wrap angles to the interval (-pi, pi]."""
    angles = np.asarray(angles, dtype=float)
    wrapped = angles - (2.0 * np.pi) * np.round(angles * (0.5 / np.pi))
    if wrapped.size and np.min(wrapped) <= -np.pi:
        wrapped = np.where(wrapped <= -np.pi, wrapped + 2.0 * np.pi, wrapped)
    return wrapped


def skew_matrix(vectors: ArrayLike) -> NDArray[np.float64]:
    """Cross-product matrices ``[v]`` with ``[v] w = v x w``, shape (..., 3, 3)."""
    vectors = np.asarray(vectors, dtype=float)
    x, y, z = vectors[..., 0], vectors[..., 1], vectors[..., 2]
    zero = np.zeros_like(x)
    return np.stack(
        [np.stack([zero, -z, y], -1), np.stack([z, zero, -x], -1), np.stack([-y, x, zero], -1)], -2
    )


def rotation_about_axis(axis: ArrayLike, angles: ArrayLike) -> NDArray[np.float64]:
    """Rotations by ``angles`` (...,) about one fixed unit ``axis`` (3,), shape (..., 3, 3).

    .. math:: R = I + \\sin q \\, [a] + (1 - \\cos q) [a]^2
    """
    axis = np.asarray(axis, dtype=float)
    angles = np.asarray(angles, dtype=float)
    skew = skew_matrix(axis)
    skew_squared = skew @ skew
    sine = np.sin(angles)[..., None, None]
    versine = (1.0 - np.cos(angles))[..., None, None]
    return _IDENTITY + sine * skew + versine * skew_squared


def rotation_with_z_along(axis: NDArray) -> NDArray[np.float64]:
    """A rotation whose third column is ``axis`` (unit); its first column is perpendicular to x (or to y when the
    axis is near x)."""
    helper = np.array([1.0, 0.0, 0.0]) if abs(axis[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    first = np.cross(helper, axis)
    first /= np.linalg.norm(first)
    return np.column_stack([first, np.cross(axis, first), axis])


def rotation_from_rotation_vector(rotation_vectors: ArrayLike) -> NDArray[np.float64]:
    """Exponential map: rotation vectors (..., 3) to rotation matrices (..., 3, 3)."""
    rotation_vectors = np.asarray(rotation_vectors, dtype=float)
    angle = np.linalg.norm(rotation_vectors, axis=-1)
    small = angle < 1e-6
    safe_angle = np.where(small, 1.0, angle)
    sine_term = np.where(small, 1.0 - angle**2 / 6.0, np.sin(angle) / safe_angle)
    cosine_term = np.where(small, 0.5 - angle**2 / 24.0, (1.0 - np.cos(angle)) / safe_angle**2)
    skew = skew_matrix(rotation_vectors)
    return _IDENTITY + sine_term[..., None, None] * skew + cosine_term[..., None, None] * (skew @ skew)


def rotation_vector_from_rotation(rotations: ArrayLike) -> NDArray[np.float64]:
    """Logarithm map: rotation matrices (..., 3, 3) to rotation vectors (..., 3), angle in [0, pi].

    Accurate for small angles and near pi (where the axis is read from the symmetric part).
    """
    rotations = np.asarray(rotations, dtype=float)
    cosine = np.clip((np.trace(rotations, axis1=-2, axis2=-1) - 1.0) / 2.0, -1.0, 1.0)
    vee = np.stack(
        [
            rotations[..., 2, 1] - rotations[..., 1, 2],
            rotations[..., 0, 2] - rotations[..., 2, 0],
            rotations[..., 1, 0] - rotations[..., 0, 1],
        ],
        -1,
    )
    angle = np.arctan2(0.5 * np.linalg.norm(vee, axis=-1), cosine)  # accurate near 0 and near pi
    small = angle < 1e-4
    scale = np.where(small, 0.5 + angle**2 / 12.0, angle / (2.0 * np.where(small, 1.0, np.sin(angle))))
    result = scale[..., None] * vee
    near_pi = angle > np.pi - 1e-3
    if np.any(near_pi):
        selected = rotations[near_pi]
        selected_angle = angle[near_pi]
        outer = (0.5 * (selected + np.swapaxes(selected, -1, -2)) - cosine[near_pi][:, None, None] * _IDENTITY) / (
            1.0 - cosine[near_pi]
        )[:, None, None]
        diagonal = np.diagonal(outer, axis1=-2, axis2=-1)
        column = np.argmax(diagonal, axis=-1)
        picked = np.take_along_axis(outer, column[:, None, None], axis=-1)[..., 0]
        axis = picked / np.sqrt(np.maximum(np.take_along_axis(diagonal, column[:, None], axis=-1), 1e-300))
        sign = np.where(np.sum(axis * vee[near_pi], axis=-1) < 0.0, -1.0, 1.0)
        result[near_pi] = (sign * selected_angle)[:, None] * axis
    return result


def rotation_from_rpy(rpy: ArrayLike) -> NDArray[np.float64]:
    """Rotation matrices from roll, pitch, yaw (..., 3): ``R = Rz(yaw) Ry(pitch) Rx(roll)``.

    This is the URDF ``rpy`` convention (rotations about the fixed x, y, z axes, in that order).
    """
    rpy = np.asarray(rpy, dtype=float)
    cr, sr = np.cos(rpy[..., 0]), np.sin(rpy[..., 0])
    cp, sp = np.cos(rpy[..., 1]), np.sin(rpy[..., 1])
    cy, sy = np.cos(rpy[..., 2]), np.sin(rpy[..., 2])
    return np.stack(
        [
            np.stack([cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr], -1),
            np.stack([sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr], -1),
            np.stack([-sp, cp * sr, cp * cr], -1),
        ],
        -2,
    )


def rpy_from_rotation(rotations: ArrayLike) -> NDArray[np.float64]:
    """Roll, pitch, yaw (..., 3) of rotation matrices, inverse of :func:`rotation_from_rpy`.

    Pitch is in [-pi/2, pi/2]; at pitch = +-pi/2 (gimbal lock, to 1e-14) roll is zero. Rebuilt by
    :func:`rotation_from_rpy`, the angles give the matrix back to rounding also near the lock: the pitch comes from
    ``atan2`` (``arcsin`` of an entry near 1 loses half the digits, 1.5e-8 rad), and within 0.1 rad of the lock
    the roll is what the matrix leaves once the yaw and pitch are taken off, so an error of the yaw there (the angle
    of two tiny entries) is taken up by the roll, about nearly the same axis.

    >>> rpy_from_rotation(rotation_from_rpy([0.1, -0.2, 0.3])).round(12)
    array([ 0.1, -0.2,  0.3])
    """
    rotations = np.asarray(rotations, dtype=float)
    across = np.hypot(rotations[..., 0, 0], rotations[..., 1, 0])  # cos(pitch)
    pitch = np.arctan2(-rotations[..., 2, 0], across)
    locked = across < 1e-14
    yaw = np.where(
        locked,
        np.arctan2(-rotations[..., 0, 1], rotations[..., 1, 1]),
        np.arctan2(rotations[..., 1, 0], rotations[..., 0, 0]),
    )
    rest = np.swapaxes(rotation_from_rpy(np.stack([np.zeros_like(yaw), pitch, yaw], -1)), -1, -2) @ rotations
    roll = np.where(across > 0.1, np.arctan2(rotations[..., 2, 1], rotations[..., 2, 2]),
                    np.arctan2(rest[..., 2, 1], rest[..., 2, 2]))  # rest: Rx(roll)
    return np.stack([roll, pitch, yaw], -1)


def _dot(a: ArrayLike, b: ArrayLike) -> NDArray[np.float64]:
    """Dot products over the last axis, broadcast (one pass, no temporary product array)."""
    return np.einsum("...i,...i->...", a, b)


def cross(a: NDArray, b: NDArray) -> NDArray[np.float64]:
    """Cross products over the last axis, broadcast, component by component: the numbers of ``np.cross`` (the same
    products and differences), several times faster on batches of 3-vectors."""
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    return np.stack(np.broadcast_arrays(a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0), -1)


def angle_about_axis(axis: ArrayLike, rotations: ArrayLike) -> NDArray[np.float64]:
    """Angle (...,) of the rotation about unit ``axis`` closest to ``rotations`` (..., 3, 3)."""
    axis = np.asarray(axis, dtype=float)
    rotations = np.asarray(rotations, dtype=float)
    vee = np.stack(
        [
            rotations[..., 2, 1] - rotations[..., 1, 2],
            rotations[..., 0, 2] - rotations[..., 2, 0],
            rotations[..., 1, 0] - rotations[..., 0, 1],
        ],
        -1,
    )
    sine = 0.5 * vee @ axis
    cosine = 0.5 * (np.trace(rotations, axis1=-2, axis2=-1) - np.einsum("i,...ij,j->...", axis, rotations, axis))
    return np.arctan2(sine, cosine)


def rotation_angle_to_align(axis: ArrayLike, start: ArrayLike, goal: ArrayLike) -> NDArray[np.float64]:
    """Angle about unit ``axis`` that turns vectors ``start`` towards ``goal`` (Paden-Kahan 1).

    .. math:: \\theta = \\operatorname{atan2}(a \\cdot (u' \\times v'), u' \\cdot v'),\\quad
              u' = u - a (a \\cdot u),\\; v' = v - a (a \\cdot v)
    """
    axis = np.asarray(axis, dtype=float)
    start = np.asarray(start, dtype=float)
    goal = np.asarray(goal, dtype=float)
    start_perpendicular = start - _dot(start, axis)[..., None] * axis
    goal_perpendicular = goal - _dot(goal, axis)[..., None] * axis
    # a . (u' x v') = (a x u') . v'
    return np.arctan2(_dot(cross(axis, start_perpendicular), goal_perpendicular),
                      _dot(start_perpendicular, goal_perpendicular))


def two_axis_pointing(
    first_axis: NDArray, second_axis: NDArray, start: NDArray, goal: NDArray, branch: float
) -> tuple[NDArray, NDArray, NDArray]:
    """Solve ``Rot(first_axis, q1) Rot(second_axis, q2) start = goal`` (Paden-Kahan 2).

    Parameters
    ----------
    first_axis, second_axis : ndarray, shape (..., 3)
        Unit axes through a common point, expressed in the same frame as ``start`` and ``goal``
        (``second_axis`` at ``q1 = 0``).
    start, goal : ndarray, shape (..., 3)
        Unit vectors.
    branch : {+1, -1}
        Sign of the component of the intermediate vector along ``first_axis x second_axis``.

    Returns
    -------
    first_angles, second_angles : ndarray, shape (...,)
    gap : ndarray, shape (...,)
        Negative where ``goal`` cannot be reached (how far ``gamma^2`` is below -1e-12), else 0.
    """
    cross_axes = cross(np.asarray(first_axis, dtype=float), np.asarray(second_axis, dtype=float))
    axes_cosine = _dot(first_axis, second_axis)
    denominator = axes_cosine**2 - 1.0
    second_start = _dot(second_axis, start)
    first_goal = _dot(first_axis, goal)
    alpha = (axes_cosine * second_start - first_goal) / denominator
    beta = (axes_cosine * first_goal - second_start) / denominator
    gamma_squared = (_dot(start, start) - alpha**2 - beta**2 - 2.0 * alpha * beta * axes_cosine) / _dot(cross_axes,
                                                                                                       cross_axes)
    gap = np.where(gamma_squared < -1e-12, gamma_squared, 0.0)  # round-off at the boundary is reachable
    gamma = branch * np.sqrt(np.maximum(gamma_squared, 0.0))
    intermediate = alpha[..., None] * first_axis + beta[..., None] * second_axis + gamma[..., None] * cross_axes
    second_angles = rotation_angle_to_align(second_axis, start, intermediate)
    first_angles = rotation_angle_to_align(first_axis, intermediate, goal)
    return first_angles, second_angles, gap



def quaternion_from_rotation(rotation: NDArray) -> NDArray[np.float64]:
    """Unit quaternions (x, y, z, w) (..., 4) of rotation matrices, Pinocchio's storage order."""
    trace = np.trace(rotation, axis1=-2, axis2=-1)
    w = 0.5 * np.sqrt(np.maximum(1.0 + trace, 0.0))
    x = 0.5 * np.sqrt(np.maximum(1.0 + rotation[..., 0, 0] - rotation[..., 1, 1] - rotation[..., 2, 2], 0.0))
    y = 0.5 * np.sqrt(np.maximum(1.0 - rotation[..., 0, 0] + rotation[..., 1, 1] - rotation[..., 2, 2], 0.0))
    z = 0.5 * np.sqrt(np.maximum(1.0 - rotation[..., 0, 0] - rotation[..., 1, 1] + rotation[..., 2, 2], 0.0))
    x = np.copysign(x, rotation[..., 2, 1] - rotation[..., 1, 2])
    y = np.copysign(y, rotation[..., 0, 2] - rotation[..., 2, 0])
    z = np.copysign(z, rotation[..., 1, 0] - rotation[..., 0, 1])
    return np.stack([x, y, z, w], -1)
