"""Batched kinematics of serial chains closed onto a platform (numpy only).

Everything here works on whole batches of configurations at once: the batch lives on
leading axes, a Python loop only ever runs over joints, solver iterations or blocks of
configurations, never over single configurations.

Frames and conventions
----------------------
All computations are done in the **base frame** of the mechanism (the frame of the link
the platform joint hangs from); :mod:`screwkit.mechanism` moves results to the world frame.
A chain is a serial chain of 1-DoF tree joints (revolute or prismatic) from the base to the
*leg-side loop frame*, followed by the DoFs of its loop joint, which ends at the
*platform-side loop frame*. The chain is closed when

.. math::

    T_{base,leg}(q_{tree}) \\; J_{loop}(q_{loop}) = T_{base,platform} \\; T_{platform,loop}.

Joint screws are returned as a unit direction (``axes``, the rotation axis of a revolute
DoF, the sliding direction of a prismatic one) and a point on the joint (``points``, the
joint frame origin); :func:`twists_from_axes_and_points` turns them into twists
``(omega, v)`` with ``v`` the velocity of the point at the origin.

Loop joints (one frame per side, URDF+ ``<loop>``):

========== ===== =====================================================================
type       DoFs  motion of the platform-side frame relative to the leg-side frame
========== ===== =====================================================================
fixed      0     none
revolute   1     rotation ``q`` about ``axis``
continuous 1     same as revolute
prismatic  1     translation ``q`` along ``axis``
universal  2     rotation ``q1`` about ``axis`` then ``q2`` about ``axis2``
spherical  3     rotation ``exp([r])`` with ``r`` the rotation vector (3 values); its
                 three twists are rotations about the leg-side frame's x, y and z axes
========== ===== =====================================================================
"""

from __future__ import annotations

import math
import os
from concurrent.futures import ThreadPoolExecutor
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass, field
from typing import Callable, Iterator

import numpy as np
from numpy.typing import ArrayLike, NDArray

LOOP_JOINT_DOFS = {"fixed": 0, "revolute": 1, "continuous": 1, "prismatic": 1, "universal": 2, "spherical": 3}
"""Number of DoFs a loop joint of each supported type adds to its chain."""

_IDENTITY = np.eye(3)
_BLOCK = 1 << 15  # configurations per block in the closed-form fast paths
_WORKERS = max(1, min(4, os.cpu_count() or 1))  # threads for blocks (numpy releases the GIL)
_THREAD_LIMIT: ContextVar[int] = ContextVar("screwkit_thread_limit", default=_WORKERS)


@contextmanager
def thread_limit(threads: int | None) -> Iterator[None]:
    """Within the block, closure solving and screw building use at most ``threads`` threads.

    For callers that already run one task per core (a map's Dask tasks): nested thread
    pools would only compete for the same cores. ``None`` leaves the default (all cores, up
    to 4). The limit is per thread (a context variable).
    """
    if threads is None:
        yield
        return
    token = _THREAD_LIMIT.set(max(1, int(threads)))
    try:
        yield
    finally:
        _THREAD_LIMIT.reset(token)


def block_threads() -> int:
    """Threads the closure and screw computations may use here (see :func:`thread_limit`)."""
    return min(_WORKERS, _THREAD_LIMIT.get())


# ----------------------------------------------------------------------------------------
# Rotations
# ----------------------------------------------------------------------------------------


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

    Pitch is in [-pi/2, pi/2]; at pitch = +-pi/2 (gimbal lock) roll is set to zero.
    """
    rotations = np.asarray(rotations, dtype=float)
    pitch = np.arcsin(np.clip(-rotations[..., 2, 0], -1.0, 1.0))
    locked = np.abs(rotations[..., 2, 0]) > 1.0 - 1e-12
    roll = np.where(locked, 0.0, np.arctan2(rotations[..., 2, 1], rotations[..., 2, 2]))
    yaw = np.where(
        locked,
        np.arctan2(-rotations[..., 0, 1], rotations[..., 1, 1]),
        np.arctan2(rotations[..., 1, 0], rotations[..., 0, 0]),
    )
    return np.stack([roll, pitch, yaw], -1)


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
    start_perpendicular = start - np.sum(start * axis, -1)[..., None] * axis
    goal_perpendicular = goal - np.sum(goal * axis, -1)[..., None] * axis
    return np.arctan2(
        np.sum(axis * np.cross(start_perpendicular, goal_perpendicular), -1),
        np.sum(start_perpendicular * goal_perpendicular, -1),
    )


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
    cross_axes = np.cross(first_axis, second_axis)
    axes_cosine = np.sum(first_axis * second_axis, -1)
    denominator = axes_cosine**2 - 1.0
    alpha = (axes_cosine * np.sum(second_axis * start, -1) - np.sum(first_axis * goal, -1)) / denominator
    beta = (axes_cosine * np.sum(first_axis * goal, -1) - np.sum(second_axis * start, -1)) / denominator
    gamma_squared = (
        np.sum(start * start, -1) - alpha**2 - beta**2 - 2.0 * alpha * beta * axes_cosine
    ) / np.sum(cross_axes * cross_axes, -1)
    gap = np.where(gamma_squared < -1e-12, gamma_squared, 0.0)  # round-off at the boundary is reachable
    gamma = branch * np.sqrt(np.maximum(gamma_squared, 0.0))
    intermediate = alpha[..., None] * first_axis + beta[..., None] * second_axis + gamma[..., None] * cross_axes
    second_angles = rotation_angle_to_align(second_axis, start, intermediate)
    first_angles = rotation_angle_to_align(first_axis, intermediate, goal)
    return first_angles, second_angles, gap


# ----------------------------------------------------------------------------------------
# Chain geometry and forward kinematics
# ----------------------------------------------------------------------------------------


@dataclass(frozen=True)
class ChainGeometry:
    """Constant geometry of one chain, in the base frame, read from the mechanism model.

    Parameters
    ----------
    name : str
        Chain name.
    joint_rotations, joint_translations : ndarray, shapes (k, 3, 3) and (k, 3)
        Placement of each tree joint frame relative to the previous joint frame (the first
        relative to the base frame), at zero joint value.
    joint_axes : ndarray, shape (k, 3)
        Unit axis of each tree joint in its own frame.
    joint_prismatic : tuple of bool
        Whether each tree joint is prismatic (else revolute).
    leg_loop_rotation, leg_loop_translation : ndarray, shapes (3, 3) and (3,)
        Leg-side loop frame relative to the last tree joint frame (the base frame if k = 0).
    loop_type : str
        One of :data:`LOOP_JOINT_DOFS`.
    loop_axes : ndarray, shape (n, 3)
        Unit axes of the loop joint in the leg-side loop frame (1 for revolute/prismatic,
        2 for universal, none otherwise).
    platform_loop_rotation, platform_loop_translation : ndarray, shapes (3, 3) and (3,)
        Platform-side loop frame relative to the platform frame.
    """

    name: str
    joint_rotations: NDArray[np.float64]
    joint_translations: NDArray[np.float64]
    joint_axes: NDArray[np.float64]
    joint_prismatic: tuple[bool, ...]
    leg_loop_rotation: NDArray[np.float64]
    leg_loop_translation: NDArray[np.float64]
    loop_type: str
    loop_axes: NDArray[np.float64]
    platform_loop_rotation: NDArray[np.float64]
    platform_loop_translation: NDArray[np.float64]
    dof_prismatic: tuple[bool, ...] = field(init=False)

    def __post_init__(self):
        loop_prismatic = (self.loop_type == "prismatic",) * LOOP_JOINT_DOFS[self.loop_type]
        object.__setattr__(self, "dof_prismatic", tuple(self.joint_prismatic) + loop_prismatic)

    @property
    def n_tree_joints(self) -> int:
        """Number of tree joints k."""
        return len(self.joint_prismatic)

    @property
    def n_dofs(self) -> int:
        """Number of joint DoFs m of the chain (tree joints plus loop-joint DoFs)."""
        return len(self.dof_prismatic)


@dataclass(frozen=True)
class ChainFrames:
    """Forward-kinematics result of one chain at a batch of configurations (base frame).

    Attributes
    ----------
    axes : ndarray, shape (..., m, 3)
        Unit direction of each joint DoF (rotation axis or sliding direction).
    points : ndarray, shape (..., m, 3)
        Origin of each joint DoF's frame after its motion, as Pinocchio's ``oMi`` (on the axis
        for revolute DoFs; a prismatic joint's origin moves with the slider).
    leg_rotation, leg_translation : ndarray, shapes (..., 3, 3) and (..., 3)
        Leg-side loop frame.
    end_rotation, end_translation : ndarray, shapes (..., 3, 3) and (..., 3)
        Platform-side loop frame as reached through the chain (equal to the platform's
        loop frame when the chain is closed).
    """

    axes: NDArray[np.float64]
    points: NDArray[np.float64]
    leg_rotation: NDArray[np.float64]
    leg_translation: NDArray[np.float64]
    end_rotation: NDArray[np.float64]
    end_translation: NDArray[np.float64]


def _times_constant(matrices: NDArray, constant: NDArray) -> NDArray:
    """``matrices @ constant`` for a batch (..., 3, 3) and one (3,) or (3, k) array, as one BLAS call."""
    shape = matrices.shape
    if matrices.size == 0:
        return np.empty(shape[:-1] + constant.shape[1:])
    if all(stride == 0 for stride in matrices.strides[:-2]):  # one matrix broadcast over the batch
        return np.broadcast_to(matrices[(0,) * (matrices.ndim - 2)] @ constant, shape[:-1] + constant.shape[1:])
    product = np.ascontiguousarray(matrices).reshape(-1, 3) @ constant
    return product.reshape(shape[:-1] + constant.shape[1:])


def _turn(rotation: NDArray, axis: NDArray, angles: NDArray) -> NDArray:
    """``rotation @ Rot(axis, angles)`` = ``R + sin q (R [a]) + (1 - cos q) (R [a]^2)``, batched."""
    skew = skew_matrix(axis)
    sine = np.sin(angles)[..., None, None]
    versine = (1.0 - np.cos(angles))[..., None, None]
    return rotation + sine * _times_constant(rotation, skew) + versine * _times_constant(rotation, skew @ skew)


def chain_forward_kinematics(geometry: ChainGeometry, joint_values: ArrayLike) -> ChainFrames:
    """Forward kinematics of one chain for a batch of joint values (..., m), base frame.

    Product of exponentials over the tree joints (each placement then the joint motion),
    then the loop-joint motion (see the module docstring for the loop types). Products with
    the constant placements are single BLAS calls over the whole batch.
    """
    joint_values = np.asarray(joint_values, dtype=float)
    if joint_values.shape[-1:] != (geometry.n_dofs,):
        raise ValueError(
            f"Expected joint values of chain {geometry.name!r} with shape (..., {geometry.n_dofs}), "
            f"got {joint_values.shape}."
        )
    batch = joint_values.shape[:-1]
    axes = np.empty(batch + (geometry.n_dofs, 3))
    points = np.empty(batch + (geometry.n_dofs, 3))
    rotation = np.broadcast_to(_IDENTITY, batch + (3, 3))
    translation = np.zeros(batch + (3,))
    for index in range(geometry.n_tree_joints):
        translation = translation + _times_constant(rotation, geometry.joint_translations[index])
        rotation = _times_constant(rotation, geometry.joint_rotations[index])
        axis = _times_constant(rotation, geometry.joint_axes[index])
        axes[..., index, :] = axis
        if geometry.joint_prismatic[index]:
            translation = translation + axis * joint_values[..., index, None]
            points[..., index, :] = translation  # the joint frame origin moves with the slider
        else:
            points[..., index, :] = translation
            rotation = _turn(rotation, geometry.joint_axes[index], joint_values[..., index])
    translation = translation + _times_constant(rotation, geometry.leg_loop_translation)
    rotation = _times_constant(rotation, geometry.leg_loop_rotation)
    leg_rotation, leg_translation = rotation, translation
    loop_values = joint_values[..., geometry.n_tree_joints :]
    start = geometry.n_tree_joints
    loop_type = geometry.loop_type
    if loop_type in ("revolute", "continuous"):
        axes[..., start, :] = _times_constant(rotation, geometry.loop_axes[0])
        points[..., start, :] = translation
        rotation = _turn(rotation, geometry.loop_axes[0], loop_values[..., 0])
    elif loop_type == "prismatic":
        axis = _times_constant(rotation, geometry.loop_axes[0])
        axes[..., start, :] = axis
        translation = translation + axis * loop_values[..., 0, None]
        points[..., start, :] = translation
    elif loop_type == "universal":
        axes[..., start, :] = _times_constant(rotation, geometry.loop_axes[0])
        points[..., start : start + 2, :] = translation[..., None, :]
        rotation = _turn(rotation, geometry.loop_axes[0], loop_values[..., 0])
        axes[..., start + 1, :] = _times_constant(rotation, geometry.loop_axes[1])
        rotation = _turn(rotation, geometry.loop_axes[1], loop_values[..., 1])
    elif loop_type == "spherical":
        axes[..., start : start + 3, :] = np.swapaxes(rotation, -1, -2)
        points[..., start : start + 3, :] = translation[..., None, :]
        rotation = rotation @ rotation_from_rotation_vector(loop_values)
    return ChainFrames(axes, points, leg_rotation, leg_translation, np.asarray(rotation), np.asarray(translation))


def loop_values_from_relative_transform(
    geometry: ChainGeometry, relative_rotation: NDArray, relative_translation: NDArray
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Loop-joint values that best match a relative transform, and what is left over.

    Parameters
    ----------
    relative_rotation, relative_translation : ndarray, shapes (..., 3, 3) and (..., 3)
        Platform-side loop frame expressed in the leg-side loop frame.

    Returns
    -------
    values : ndarray, shape (..., n_loop_dofs)
    position_residual : ndarray, shape (...,)
        Distance (m) between the two frame origins after the loop motion.
    rotation_residual : ndarray, shape (...,)
        Angle (rad) between the two frames after the loop motion.
    """
    relative_rotation = np.asarray(relative_rotation, dtype=float)
    relative_translation = np.asarray(relative_translation, dtype=float)
    batch = relative_translation.shape[:-1]
    loop_type = geometry.loop_type
    joint_rotation = np.broadcast_to(_IDENTITY, batch + (3, 3))
    joint_translation = np.zeros(batch + (3,))
    if loop_type == "fixed":
        values = np.zeros(batch + (0,))
    elif loop_type in ("revolute", "continuous"):
        angle = angle_about_axis(geometry.loop_axes[0], relative_rotation)
        values = angle[..., None]
        joint_rotation = rotation_about_axis(geometry.loop_axes[0], angle)
    elif loop_type == "prismatic":
        values = (relative_translation @ geometry.loop_axes[0])[..., None]
        joint_translation = values * geometry.loop_axes[0]
    elif loop_type == "universal":
        first_axis, second_axis = geometry.loop_axes
        first = rotation_angle_to_align(first_axis, second_axis, relative_rotation @ second_axis)
        first_rotation = rotation_about_axis(first_axis, first)
        second = angle_about_axis(second_axis, np.swapaxes(first_rotation, -1, -2) @ relative_rotation)
        values = np.stack([first, second], -1)
        joint_rotation = first_rotation @ rotation_about_axis(second_axis, second)
    elif loop_type == "spherical":
        values = rotation_vector_from_rotation(relative_rotation)
        joint_rotation = rotation_from_rotation_vector(values)
    else:  # pragma: no cover - the URDF pass rejects other types
        raise ValueError(f"Unsupported loop joint type {loop_type!r} in chain {geometry.name!r}.")
    position_residual = np.linalg.norm(relative_translation - joint_translation, axis=-1)
    rotation_residual = np.linalg.norm(
        rotation_vector_from_rotation(np.swapaxes(joint_rotation, -1, -2) @ relative_rotation), axis=-1
    )
    return values, position_residual, rotation_residual


def _constant_value(plane: NDArray) -> float | None:
    """The value of a plane that is one number broadcast (all strides 0), else None."""
    if plane.ndim == 0 or all(stride == 0 for stride in plane.strides):
        return float(plane.flat[0]) if plane.size else 0.0
    return None


def _linear_combination(out: NDArray, terms: list) -> None:
    """``out = sum(coefficient * plane)``; coefficients are arrays or numbers, zero numbers skipped.

    ``out`` must hold zeros on entry (it is left untouched when every term vanishes).
    """
    first = True
    for coefficient, plane in terms:
        if isinstance(coefficient, float) and coefficient == 0.0:
            continue
        if first:
            np.multiply(plane, coefficient, out=out)
            first = False
        else:
            out += coefficient * plane


def twists_from_axes_and_points(
    axes: NDArray, points: NDArray, prismatic: tuple[bool, ...] | NDArray, out: NDArray | None = None
) -> NDArray[np.float64]:
    """Unit joint twists ``(omega, v)`` (..., m, 6) from joint axes and points (..., m, 3).

    .. math::

        \\hat\\$_{revolute} = (a,\\; p \\times a), \\qquad \\hat\\$_{prismatic} = (0,\\; a)

    The result is computed and stored component by component (component-major memory,
    returned as a (..., m, 6) view), which is several times faster than interleaved storage
    for large batches; axis components that are one broadcast number (as for the planar
    closed forms) are used as numbers and zero ones are skipped. ``out``, a zeroed
    component-major array (6, m, ...), receives the result (several chains can so share one
    block of memory that the index kernel reads in place).
    """
    axes_components = np.moveaxis(np.asarray(axes, dtype=float), (-1, -2), (0, 1))
    points_components = np.moveaxis(np.asarray(points, dtype=float), (-1, -2), (0, 1))
    prismatic = np.asarray(prismatic, dtype=bool)
    n_joints = axes_components.shape[1]
    batch = np.broadcast_shapes(axes_components.shape[2:], points_components.shape[2:])
    if out is None:
        twists = np.zeros((6, n_joints) + batch)
    elif out.shape != (6, n_joints) + batch:
        raise ValueError(f"Expected `out` with shape {(6, n_joints) + batch}, got {out.shape}.")
    else:
        twists = out
    for joint in range(n_joints):
        axis = []
        for component in range(3):
            plane = axes_components[component, joint]
            constant = _constant_value(plane)
            axis.append(plane if constant is None else constant)
        angular_rows = range(3, 6) if prismatic[joint] else range(3)
        for row, value in zip(angular_rows, axis):
            if isinstance(value, float):
                if value != 0.0:
                    twists[row, joint] = value
            else:
                twists[row, joint] = value
        if prismatic[joint]:
            continue
        px, py, pz = (points_components[component, joint] for component in range(3))
        ax, ay, az = axis
        negative = [-value if isinstance(value, float) else np.negative(value) for value in axis]
        _linear_combination(twists[3, joint, ...], [(az, py), (negative[1], pz)])
        _linear_combination(twists[4, joint, ...], [(ax, pz), (negative[2], px)])
        _linear_combination(twists[5, joint, ...], [(ay, px), (negative[0], py)])
    return np.moveaxis(twists, (0, 1), (-1, -2))


def transform_axes_and_points(
    rotation: NDArray, translation: NDArray, axes: NDArray, points: NDArray
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Move joint axes and points (..., m, 3) by one rigid transform (rotation, translation).

    Works component by component and keeps the component-major memory layout.
    """
    axes_components = np.moveaxis(np.asarray(axes, dtype=float), (-1, -2), (0, 1))
    points_components = np.moveaxis(np.asarray(points, dtype=float), (-1, -2), (0, 1))
    new_axes = np.empty(np.broadcast_shapes(axes_components.shape, points_components.shape))
    new_points = np.empty_like(new_axes)
    for row in range(3):
        new_axes[row] = (
            rotation[row, 0] * axes_components[0] + rotation[row, 1] * axes_components[1] + rotation[row, 2] * axes_components[2]
        )
        new_points[row] = (
            rotation[row, 0] * points_components[0]
            + rotation[row, 1] * points_components[1]
            + rotation[row, 2] * points_components[2]
            + translation[row]
        )
    return np.moveaxis(new_axes, (0, 1), (-1, -2)), np.moveaxis(new_points, (0, 1), (-1, -2))


# ----------------------------------------------------------------------------------------
# Damped Newton (Levenberg-Marquardt) closure solving
# ----------------------------------------------------------------------------------------


def pose_error(
    target_rotation: NDArray, target_translation: NDArray, rotation: NDArray, translation: NDArray
) -> NDArray[np.float64]:
    """Small-displacement error ``(rotation vector, translation)`` (..., 6) from a frame to a target.

    The rotation part is ``log(R_target R^T)`` (base-frame axes); the translation part is the
    difference of the origins.
    """
    rotation_error = rotation_vector_from_rotation(target_rotation @ np.swapaxes(rotation, -1, -2))
    return np.concatenate([rotation_error, target_translation - translation], -1)


def chain_jacobian(geometry: ChainGeometry, frames: ChainFrames) -> NDArray[np.float64]:
    """Geometric Jacobian (..., 6, m) of the platform-side loop frame, angular rows first.

    Column j is the joint twist with its moment taken at the end-frame origin:
    ``(a, a x (p_end - p_j))`` for revolute DoFs, ``(0, a)`` for prismatic ones.
    """
    arm = frames.end_translation[..., None, :] - frames.points
    prismatic = np.asarray(geometry.dof_prismatic, dtype=bool)
    angular = np.where(prismatic[:, None], 0.0, frames.axes)
    linear = np.where(prismatic[:, None], frames.axes, np.cross(frames.axes, arm))
    return np.swapaxes(np.concatenate([angular, linear], -1), -1, -2)


def _apply_step(geometry: ChainGeometry, values: NDArray, step: NDArray) -> NDArray:
    """Add a Newton step; spherical loop DoFs compose on the left (leg-side frame axes)."""
    updated = values + step
    if geometry.loop_type == "spherical":
        start = geometry.n_tree_joints
        composed = rotation_from_rotation_vector(step[..., start:]) @ rotation_from_rotation_vector(values[..., start:])
        updated[..., start:] = rotation_vector_from_rotation(composed)
    return updated


def wrap_revolute_values(geometry: ChainGeometry, values: NDArray) -> NDArray:
    """Wrap the revolute DoFs (tree and 1-DoF/universal loop) of a chain to (-pi, pi]."""
    wrap = np.array([not prismatic for prismatic in geometry.dof_prismatic])
    if geometry.loop_type == "spherical":
        wrap[geometry.n_tree_joints :] = False
    values = np.array(values, dtype=float, copy=True)
    values[..., wrap] = wrap_angle(values[..., wrap])
    return values


def newton_solve_chain(
    geometry: ChainGeometry,
    target_rotation: NDArray,
    target_translation: NDArray,
    initial_values: NDArray,
    tolerance: float = 1e-11,
    max_iterations: int = 40,
    max_step: float = 0.5,
) -> tuple[NDArray[np.float64], NDArray[np.bool_], NDArray[np.float64]]:
    """Close one chain onto target platform-side loop frames by damped Newton steps.

    Levenberg-Marquardt: the step solves ``(J^T J + (mu + |e|^2) I) dq = J^T e`` and is
    kept only if it lowers ``|e|``; ``mu`` shrinks after a kept step and grows after a
    rejected one (the ``|e|^2`` term keeps convergence quadratic at singular solutions).
    Steps are limited to ``max_step`` (rad or m) so the assembly branch does not jump.
    Batched: every iteration works on all configurations not yet converged or stalled.

    Parameters
    ----------
    target_rotation, target_translation : ndarray, shapes (N, 3, 3) and (N, 3)
        Platform-side loop frames to reach (base frame).
    initial_values : ndarray, shape (N, m)

    Returns
    -------
    values : ndarray, shape (N, m)
    converged : ndarray of bool, shape (N,)
        Whether ``|e| < tolerance`` (rotation vector in rad and translation in m stacked).
    residual : ndarray, shape (N,)
        Final ``|e|`` (where not converged: how far the chain misses the target).
    """
    values = np.array(initial_values, dtype=float, copy=True)
    count = values.shape[0]
    n_dofs = geometry.n_dofs

    def errors(at_values: NDArray, rows: NDArray) -> tuple[ChainFrames, NDArray]:
        frames = chain_forward_kinematics(geometry, at_values)
        return frames, pose_error(target_rotation[rows], target_translation[rows], frames.end_rotation, frames.end_translation)

    _, error = errors(values, np.arange(count))
    residual = np.linalg.norm(error, axis=-1)
    damping = np.full(count, 1e-9)
    active = np.flatnonzero((residual >= tolerance) & np.isfinite(residual))
    if n_dofs == 0:
        return values, residual < tolerance, residual
    for _ in range(max_iterations):
        if active.size == 0:
            break
        frames, error = errors(values[active], active)
        norm = residual[active]
        jacobian = chain_jacobian(geometry, frames)
        transposed = np.swapaxes(jacobian, -1, -2)
        normal = transposed @ jacobian + (damping[active] + norm**2)[:, None, None] * np.eye(n_dofs)
        step = np.linalg.solve(normal, (transposed @ error[..., None]))[..., 0]
        largest = np.max(np.abs(step), axis=-1)
        step *= np.minimum(1.0, max_step / np.maximum(largest, 1e-300))[:, None]
        candidate = _apply_step(geometry, values[active], step)
        _, candidate_error = errors(candidate, active)
        candidate_norm = np.linalg.norm(candidate_error, axis=-1)
        better = candidate_norm < norm
        accepted = active[better]
        values[accepted] = candidate[better]
        residual[accepted] = candidate_norm[better]
        damping[accepted] = np.maximum(damping[accepted] * 0.1, 1e-12)
        damping[active[~better]] = np.maximum(damping[active[~better]] * 10.0, 1e-6)
        active = active[(residual[active] >= tolerance) & (damping[active] < 1e4)]
    return values, residual < tolerance, residual


# ----------------------------------------------------------------------------------------
# Closed-form fast paths
# ----------------------------------------------------------------------------------------


@dataclass(frozen=True)
class ClosedFormResult:
    """Result of a closed-form chain solver for a flat batch of N platform poses.

    Attributes
    ----------
    values : ndarray, shape (N, m), or a function returning it
        Joint values, NaN where unreachable. The planar closed forms return a function: the
        joint values follow from the joint points by a few ``arctan2`` and are only computed
        when asked for (screws need the points only).
    reachable : ndarray of bool, shape (N,)
    gap : ndarray, shape (N,)
        0 where reachable, otherwise by how much the target is out of reach (m).
    axes, points : ndarray, shape (N, m, 3)
        Joint axes and points in the base frame (possibly component-major views).
    """

    values: NDArray[np.float64] | Callable[[], NDArray[np.float64]]
    reachable: NDArray[np.bool_]
    gap: NDArray[np.float64]
    axes: NDArray[np.float64]
    points: NDArray[np.float64]


def for_each_block(count: int, work: Callable[[slice], None]) -> None:
    """Call ``work(block)`` for consecutive slices of ``range(count)``, in threads when large.

    numpy releases the GIL inside its loops, so blocks that fit in cache run in parallel on
    all cores; ``work`` must only write to its own slice of the outputs.
    """
    blocks = [slice(start, min(start + _BLOCK, count)) for start in range(0, count, _BLOCK)]
    workers = block_threads()
    if workers > 1 and len(blocks) > 1:
        with ThreadPoolExecutor(workers) as pool:
            for _ in pool.map(work, blocks):
                pass
    else:
        for block in blocks:
            work(block)


def _angle_of(vector: ArrayLike) -> float:
    return math.atan2(float(vector[1]), float(vector[0]))


def _sign_along_z(axis: NDArray, tolerance: float = 1e-9) -> float:
    """+1 or -1 if the unit ``axis`` is +z or -z, else 0."""
    if abs(axis[0]) < tolerance and abs(axis[1]) < tolerance and abs(abs(axis[2]) - 1.0) < tolerance:
        return float(np.sign(axis[2]))
    return 0.0


def _line_intersection(
    first_point: NDArray, first_axis: NDArray, second_point: NDArray, second_axis: NDArray, tolerance: float = 1e-9
) -> NDArray | None:
    """Common point of two non-parallel lines, or None if they are parallel or skew."""
    normal = np.cross(first_axis, second_axis)
    if np.linalg.norm(normal) < 1e-6:
        return None
    offset = second_point - first_point
    first_parameter = np.dot(np.cross(offset, second_axis), normal) / np.dot(normal, normal)
    second_parameter = np.dot(np.cross(offset, first_axis), normal) / np.dot(normal, normal)
    first_closest = first_point + first_parameter * first_axis
    second_closest = second_point + second_parameter * second_axis
    if np.linalg.norm(first_closest - second_closest) > tolerance:
        return None
    return 0.5 * (first_closest + second_closest)


class PlanarClosedForm:
    """Common part of the planar closed forms: base joint ``b``, middle joint, loop joint ``d``.

    All revolute axes are along the base z axis; angles are measured in the base x-y plane.
    The platform pose is ``(x, y, angle)``; the platform joint is
    ``d = (x, y) + R(angle) d_M``. Work is done block by block (cache-sized, in threads) into
    component-major output arrays. Joint values: with ``Delta`` the rotation of the distal
    link from its zero-value direction, the loop joint value is
    ``q3 = s3 (angle + psi_M - psi_L - Delta)`` (``s3`` the axis sign, ``psi_M`` and ``psi_L``
    the platform-side and leg-side loop frame angles at zero).
    """

    kind = ""
    planar = True
    n_branches = 1

    def __init__(self, geometry: ChainGeometry, frames: ChainFrames, signs: NDArray):
        self.geometry = geometry
        self.signs = signs
        self.base_point = frames.points[0, :2].copy()
        self.middle_point = frames.points[1, :2].copy()
        self.end_point = frames.points[2, :2].copy()
        self.heights = frames.points[:, 2].copy()
        self.loop_offset = _angle_of(geometry.platform_loop_rotation[:, 0]) - _angle_of(frames.leg_rotation[:, 0])
        self.platform_point = geometry.platform_loop_translation[:2].copy()

    def solve(self, x: NDArray, y: NDArray, cosine: NDArray, sine: NDArray, angle: NDArray, branch) -> ClosedFormResult:
        """Solve flat batches of planar platform poses (x, y, angle) in the base frame.

        ``cosine`` and ``sine`` are ``cos(angle)`` and ``sin(angle)`` (shared by all chains).
        """
        branch = float(np.atleast_1d(branch)[0])
        count = x.shape[0]
        point_components = np.zeros((3, 3, count))  # constant zero planes are never written
        axis_components = self._allocate_axes(count)
        gap = np.empty(count)
        platform_x, platform_y = self.platform_point
        constants = [(0, 0, self.base_point[0]), (1, 0, self.base_point[1])]
        constants += [(2, joint, height) for joint, height in enumerate(self.heights)]
        constants = [(row, joint, value) for row, joint, value in constants if value != 0.0]

        def work(block: slice) -> None:
            block_cosine, block_sine = cosine[block], sine[block]
            points = point_components[:, :, block]
            points[0, 2] = x[block] + block_cosine * platform_x - block_sine * platform_y
            points[1, 2] = y[block] + block_sine * platform_x + block_cosine * platform_y
            for row, joint, value in constants:
                points[row, joint] = value
            self._points_block(branch, points, axis_components[:, :, block], gap[block])

        for_each_block(count, work)
        reachable = gap == 0.0

        def values() -> NDArray:
            joint_values = np.empty((3, count))

            def value_work(block: slice) -> None:
                self._values_block(
                    point_components[:, :, block], axis_components[:, :, block], angle[block], joint_values[:, block]
                )

            for_each_block(count, value_work)
            if not np.all(reachable):
                joint_values[:, ~reachable] = np.nan
            return joint_values.T

        return ClosedFormResult(
            values=values,
            reachable=reachable,
            gap=gap,
            axes=np.moveaxis(axis_components, (0, 1), (-1, -2)),
            points=np.moveaxis(point_components, (0, 1), (-1, -2)),
        )

    def _allocate_axes(self, count: int) -> NDArray:
        axis_components = np.zeros((3, 3, 1))
        axis_components[2, :, 0] = self.signs
        return np.broadcast_to(axis_components, (3, 3, count))


class PlanarRevoluteChain(PlanarClosedForm):
    """Planar R-R-R chain: the elbow from the intersection of two circles.

    With base joint ``b``, platform joint ``d`` and link lengths ``a = |c - b|``,
    ``l = |d - c|``, the elbow is

    .. math::

        c = b + \\frac{a^2 - l^2 + r^2}{2 r} u + \\sigma h \\, (z \\times u),\\quad
        r = |d - b|,\\; u = (d - b)/r,\\; h = \\sqrt{a^2 - (\\tfrac{a^2 - l^2 + r^2}{2 r})^2},

    reachable for ``|a - l| <= r <= a + l``. Branch ``sigma = +1`` puts ``c`` on the
    ``+u_perp`` side of the line ``b -> d`` (``u_perp = z x u``).
    """

    kind = "planar_rrr"

    @classmethod
    def from_geometry(cls, geometry: ChainGeometry) -> PlanarRevoluteChain | None:
        if geometry.n_tree_joints != 2 or any(geometry.joint_prismatic):
            return None
        if geometry.loop_type not in ("revolute", "continuous"):
            return None
        frames = chain_forward_kinematics(geometry, np.zeros(3))
        signs = np.array([_sign_along_z(axis) for axis in frames.axes])
        if np.any(signs == 0.0) or _sign_along_z(frames.leg_rotation[:, 2]) == 0.0:
            return None
        if _sign_along_z(geometry.platform_loop_rotation[:, 2]) == 0.0:
            return None
        return cls(geometry, frames, signs)

    def __init__(self, geometry: ChainGeometry, frames: ChainFrames, signs: NDArray):
        super().__init__(geometry, frames, signs)
        self.first_length = float(np.linalg.norm(self.middle_point - self.base_point))
        self.second_length = float(np.linalg.norm(self.end_point - self.middle_point))
        self.first_zero_angle = _angle_of(self.middle_point - self.base_point)
        self.second_zero_angle = _angle_of(self.end_point - self.middle_point)

    def _points_block(self, branch: float, points: NDArray, axes: NDArray, gap: NDArray) -> None:
        base_x, base_y = self.base_point
        first, second = self.first_length, self.second_length
        delta_x = points[0, 2] - base_x
        delta_y = points[1, 2] - base_y
        squared = delta_x * delta_x + delta_y * delta_y
        with np.errstate(divide="ignore", invalid="ignore"):
            inverse = 1.0 / squared
            along = (0.5 * (first * first - second * second)) * inverse + 0.5  # along / distance
            height_squared = (first * first) * inverse - along * along  # (height / distance)^2
        reachable = height_squared >= 0.0
        height = np.sqrt(np.maximum(height_squared, 0.0))
        if branch > 0:
            points[0, 1] = base_x + along * delta_x - height * delta_y
            points[1, 1] = base_y + along * delta_y + height * delta_x
        else:
            points[0, 1] = base_x + along * delta_x + height * delta_y
            points[1, 1] = base_y + along * delta_y - height * delta_x
        gap[:] = 0.0
        if not np.all(reachable):
            unreachable = ~reachable
            distance = np.sqrt(squared[unreachable])
            gap[unreachable] = np.maximum(
                np.maximum(distance - (first + second), abs(first - second) - distance), np.finfo(float).tiny
            )

    def _values_block(self, points: NDArray, axes: NDArray, angle: NDArray, values: NDArray) -> None:
        base_x, base_y = self.base_point
        first_turn = np.arctan2(points[1, 1] - base_y, points[0, 1] - base_x) - self.first_zero_angle
        distal_turn = np.arctan2(points[1, 2] - points[1, 1], points[0, 2] - points[0, 1]) - self.second_zero_angle
        values[0] = wrap_angle(self.signs[0] * first_turn)
        values[1] = wrap_angle(self.signs[1] * (distal_turn - first_turn))
        values[2] = wrap_angle(self.signs[2] * (angle + self.loop_offset - distal_turn))


class PlanarSliderChain(PlanarClosedForm):
    """Planar R-P-R chain whose slider runs from the base joint ``b`` to the platform joint ``d``.

    The leg direction is ``u = sigma (d - b)/|d - b|`` and the slider value
    ``q = sigma |d - b| - l0`` (``l0`` the leg length at zero values); branch ``sigma = +1``
    keeps the slider pointing from ``b`` towards ``d``.
    """

    kind = "planar_rpr"

    @classmethod
    def from_geometry(cls, geometry: ChainGeometry) -> PlanarSliderChain | None:
        if geometry.n_tree_joints != 2 or geometry.joint_prismatic != (False, True):
            return None
        if geometry.loop_type not in ("revolute", "continuous"):
            return None
        frames = chain_forward_kinematics(geometry, np.zeros(3))
        signs = np.array([_sign_along_z(frames.axes[0]), 1.0, _sign_along_z(frames.axes[2])])
        if signs[0] == 0.0 or signs[2] == 0.0 or abs(frames.axes[1, 2]) > 1e-9:
            return None
        if _sign_along_z(frames.leg_rotation[:, 2]) == 0.0 or _sign_along_z(geometry.platform_loop_rotation[:, 2]) == 0.0:
            return None
        leg = frames.points[2, :2] - frames.points[0, :2]
        slider = frames.axes[1, :2] / np.linalg.norm(frames.axes[1, :2])
        if np.linalg.norm(leg) < 1e-9 or abs(leg[0] * slider[1] - leg[1] * slider[0]) > 1e-9:
            return None
        return cls(geometry, frames, signs)

    def __init__(self, geometry: ChainGeometry, frames: ChainFrames, signs: NDArray):
        super().__init__(geometry, frames, signs)
        self.slider_direction = frames.axes[1, :2] / np.linalg.norm(frames.axes[1, :2])
        self.leg_offset = float((self.end_point - self.base_point) @ self.slider_direction)

    def _allocate_axes(self, count: int) -> NDArray:
        axis_components = np.zeros((3, 3, count))
        axis_components[2, 0] = self.signs[0]
        axis_components[2, 2] = self.signs[2]
        return axis_components

    def _points_block(self, branch: float, points: NDArray, axes: NDArray, gap: NDArray) -> None:
        base_x, base_y = self.base_point
        delta_x = points[0, 2] - base_x
        delta_y = points[1, 2] - base_y
        distance = np.sqrt(delta_x * delta_x + delta_y * delta_y)
        gap[:] = 0.0
        gap[distance == 0.0] = np.inf
        inverse = branch / np.maximum(distance, 1e-300)
        unit_x = delta_x * inverse
        unit_y = delta_y * inverse
        slider_x, slider_y = self.slider_direction
        cosine = unit_x * slider_x + unit_y * slider_y
        sine = slider_x * unit_y - slider_y * unit_x
        offset_x, offset_y = self.middle_point - self.base_point
        slide = branch * distance - self.leg_offset  # the slider's joint frame moves with it
        points[0, 1] = base_x + cosine * offset_x - sine * offset_y + slide * unit_x
        points[1, 1] = base_y + sine * offset_x + cosine * offset_y + slide * unit_y
        axes[0, 1], axes[1, 1] = unit_x, unit_y

    def _values_block(self, points: NDArray, axes: NDArray, angle: NDArray, values: NDArray) -> None:
        base_x, base_y = self.base_point
        slider_x, slider_y = self.slider_direction
        unit_x, unit_y = axes[0, 1], axes[1, 1]
        turn = np.arctan2(slider_x * unit_y - slider_y * unit_x, unit_x * slider_x + unit_y * slider_y)
        values[0] = self.signs[0] * turn
        values[1] = (points[0, 2] - base_x) * unit_x + (points[1, 2] - base_y) * unit_y - self.leg_offset
        values[2] = wrap_angle(self.signs[2] * (angle + self.loop_offset - turn))


class SpatialClosedForm:
    """Common part of the spatial closed forms (targets are platform-side loop frames).

    Subclasses return the tree-joint values; the spherical loop joint's values and all
    joint axes and points then follow from one forward-kinematics pass.
    """

    kind = ""
    planar = False
    n_branches = 2

    def solve(self, target_rotation: NDArray, target_translation: NDArray, branch) -> ClosedFormResult:
        """Solve flat batches of targets, shapes (N, 3, 3) and (N, 3), block by block in threads."""
        branch = tuple(float(sign) for sign in np.atleast_1d(branch))
        geometry = self.geometry
        count, n_tree = target_translation.shape[0], geometry.n_tree_joints
        values = np.empty((count, geometry.n_dofs))
        axes = np.empty((count, geometry.n_dofs, 3))
        points = np.empty((count, geometry.n_dofs, 3))
        gap = np.empty(count)

        def work(block: slice) -> None:
            tree_values, gap[block] = self._tree_values(target_translation[block], branch)
            padded = np.concatenate([tree_values, np.zeros(tree_values.shape[:-1] + (geometry.n_dofs - n_tree,))], -1)
            frames = chain_forward_kinematics(geometry, padded)  # spherical axes do not depend on its values
            values[block, :n_tree] = tree_values
            values[block, n_tree:] = rotation_vector_from_rotation(
                np.swapaxes(frames.leg_rotation, -1, -2) @ target_rotation[block]
            )
            axes[block], points[block] = frames.axes, frames.points

        for_each_block(count, work)
        reachable = gap == 0.0
        if not np.all(reachable):
            values[~reachable] = np.nan
        return ClosedFormResult(values=values, reachable=reachable, gap=gap, axes=axes, points=points)

    @staticmethod
    def _zero_frames(
        geometry: ChainGeometry, prismatic: tuple[bool, ...], universal_joints: tuple[int, int]
    ) -> tuple[ChainFrames, NDArray] | None:
        """Zero-value frames and universal-joint centre, if the chain has the joint pattern and a spherical loop."""
        if geometry.joint_prismatic != prismatic or geometry.loop_type != "spherical":
            return None
        frames = chain_forward_kinematics(geometry, np.zeros(geometry.n_dofs))
        first, second = universal_joints
        centre = _line_intersection(frames.points[first], frames.axes[first], frames.points[second], frames.axes[second])
        return None if centre is None else (frames, centre)


class LegVectorChain(SpatialClosedForm):
    """U-P-S chain: universal joint at the base, slider along the leg, spherical loop joint.

    With ``b`` the universal joint centre and ``s`` the platform joint centre, the slider
    value is ``sigma_P |s - b| - l0`` and the universal joint turns the zero-value leg
    direction onto ``sigma_P (s - b)/|s - b|`` (Paden-Kahan subproblem 2, branch
    ``sigma_U``). Branch = ``(sigma_U, sigma_P)``.
    """

    kind = "ups"

    @classmethod
    def from_geometry(cls, geometry: ChainGeometry) -> LegVectorChain | None:
        found = cls._zero_frames(geometry, (False, False, True), (0, 1))
        if found is None:
            return None
        frames, centre = found
        leg = frames.leg_translation - centre
        if np.linalg.norm(leg) < 1e-9 or np.linalg.norm(np.cross(leg, frames.axes[2])) > 1e-9:
            return None
        return cls(geometry, frames, centre)

    def __init__(self, geometry: ChainGeometry, frames: ChainFrames, centre: NDArray):
        self.geometry = geometry
        self.centre = centre
        self.first_axis = frames.axes[0].copy()
        self.second_axis = frames.axes[1].copy()
        self.slider_direction = frames.axes[2].copy()
        self.leg_offset = float((frames.leg_translation - centre) @ self.slider_direction)

    def _tree_values(self, target_translation: NDArray, branch: tuple[float, ...]) -> tuple[NDArray, NDArray]:
        universal_sign, slider_sign = branch
        leg = target_translation - self.centre
        distance = np.linalg.norm(leg, axis=-1)
        safe = np.where(distance > 0.0, distance, 1.0)
        direction = slider_sign * leg / safe[..., None]
        first, second, pointing_gap = two_axis_pointing(
            self.first_axis, self.second_axis, self.slider_direction, direction, universal_sign
        )
        gap = np.where(distance > 0.0, -pointing_gap * distance, np.inf)
        return np.stack([first, second, slider_sign * distance - self.leg_offset], -1), gap


class CrankRodChain(SpatialClosedForm):
    """R-U-S chain: a crank (revolute), a rod with a universal joint at the crank end, S at the platform.

    The crank angle solves ``|s - c(q1)| = l`` with ``c(q1)`` the universal-joint centre on
    its circle: ``A cos q1 + B sin q1 = C``, ``q1 = atan2(B, A) + sigma_R acos(C / sqrt(A^2 + B^2))``;
    the universal joint then points the rod at ``s`` (Paden-Kahan subproblem 2, branch
    ``sigma_U``). Branch = ``(sigma_R, sigma_U)``. This is the RSS leg with the rod's idle
    spin about its own axis removed (it does not move the platform).
    """

    kind = "rus"

    @classmethod
    def from_geometry(cls, geometry: ChainGeometry) -> CrankRodChain | None:
        found = cls._zero_frames(geometry, (False, False, False), (1, 2))
        if found is None:
            return None
        frames, centre = found
        crank = centre - frames.points[0]
        crank_perpendicular = crank - (crank @ frames.axes[0]) * frames.axes[0]
        rod = frames.leg_translation - centre
        if np.linalg.norm(crank_perpendicular) < 1e-9 or np.linalg.norm(rod) < 1e-9:
            return None
        return cls(geometry, frames, centre)

    def __init__(self, geometry: ChainGeometry, frames: ChainFrames, centre: NDArray):
        self.geometry = geometry
        self.crank_point = frames.points[0].copy()
        self.crank_axis = frames.axes[0].copy()
        self.crank_vector = centre - self.crank_point
        self.first_universal_axis = frames.axes[1].copy()
        self.second_universal_axis = frames.axes[2].copy()
        rod = frames.leg_translation - centre
        self.rod_length = float(np.linalg.norm(rod))
        self.rod_direction = rod / self.rod_length

    def _tree_values(self, target_translation: NDArray, branch: tuple[float, ...]) -> tuple[NDArray, NDArray]:
        crank_sign, universal_sign = branch
        axis = self.crank_axis
        along = (self.crank_vector @ axis) * axis
        perpendicular = self.crank_vector - along
        binormal = np.cross(axis, perpendicular)
        offset = target_translation - self.crank_point
        cosine_coefficient = offset @ perpendicular
        sine_coefficient = offset @ binormal
        constant = 0.5 * (
            np.sum(offset * offset, -1) + self.crank_vector @ self.crank_vector - self.rod_length**2
        ) - offset @ along
        amplitude = np.hypot(cosine_coefficient, sine_coefficient)
        gap = np.maximum(np.abs(constant) - amplitude, 0.0) / np.linalg.norm(perpendicular)
        crank = np.arctan2(sine_coefficient, cosine_coefficient) + crank_sign * np.arccos(
            np.clip(constant / np.where(amplitude > 0.0, amplitude, 1.0), -1.0, 1.0)
        )
        crank_rotation = rotation_about_axis(axis, crank)
        centre = self.crank_point + crank_rotation @ self.crank_vector
        rod_local = (np.swapaxes(crank_rotation, -1, -2) @ (target_translation - centre)[..., None])[..., 0]
        rod_local /= np.maximum(np.linalg.norm(rod_local, axis=-1), 1e-300)[..., None]
        first, second, pointing_gap = two_axis_pointing(
            self.first_universal_axis, self.second_universal_axis, self.rod_direction, rod_local, universal_sign
        )
        gap = np.where(gap > 0.0, gap, -pointing_gap * self.rod_length)
        return np.stack([wrap_angle(crank), first, second], -1), gap


CLOSED_FORMS = (PlanarRevoluteChain, PlanarSliderChain, LegVectorChain, CrankRodChain)
"""Closed-form chain solvers tried, in order, for every chain."""


def closed_form_for(geometry: ChainGeometry, planar: bool):
    """The first closed form of :data:`CLOSED_FORMS` that fits the chain, or None."""
    for solver_class in CLOSED_FORMS:
        if solver_class.planar != planar:
            continue
        solver = solver_class.from_geometry(geometry)
        if solver is not None:
            return solver
    return None
