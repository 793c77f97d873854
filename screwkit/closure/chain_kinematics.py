"""Batched forward kinematics and joint screws of one chain (numpy only).

Everything works on whole batches of configurations: the batch lives on leading axes, and a
Python loop only ever runs over joints, never over configurations. Computations are in the
mechanism's **base frame**; :mod:`screwkit.closure.configuration_screws` moves results to the world frame.
Joint screws are a unit direction (``axes``: the rotation axis of a revolute DoF, the sliding
direction of a prismatic one) and a point on the joint (``points``: the joint frame origin);
:func:`twists_from_axes_and_points` turns them into twists ``(omega, v)`` with ``v`` the
velocity of the point at the origin. The chain is closed when

.. math::

    T_{base,leg}(q_{tree}) \\; J_{loop}(q_{loop}) = T_{base,platform} \\; T_{platform,loop}.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.common.compiling import announce_compilation
from screwkit.common.rotations import (
    angle_about_axis,
    rotation_about_axis,
    rotation_angle_to_align,
    rotation_from_rotation_vector,
    rotation_vector_from_rotation,
    skew_matrix,
    wrap_angle,
)
from screwkit.model.chain import ChainGeometry

__all__ = [
    "ChainFrames",
    "LoopCode",
    "LOOP_CODES",
    "chain_forward_kinematics",
    "chain_jacobian",
    "loop_values_from_relative_transform",
    "packed_chains",
    "twists_from_axes_and_points",
    "transform_axes_and_points",
    "wrap_revolute_values",
]

_IDENTITY = np.eye(3)

class LoopCode(IntEnum):
    """The loop joint of a chain as the compiled kernels (:mod:`screwkit.closure.compiled`) read it
    from the packed geometry's ``loop_code`` (plain integers there: ``code == 4`` is spherical)."""

    FIXED = 0
    REVOLUTE = 1  # a continuous joint too
    PRISMATIC = 2
    UNIVERSAL = 3  # two axes at one point
    SPHERICAL = 4


LOOP_CODES = {"fixed": LoopCode.FIXED, "revolute": LoopCode.REVOLUTE, "continuous": LoopCode.REVOLUTE,
              "prismatic": LoopCode.PRISMATIC, "universal": LoopCode.UNIVERSAL, "spherical": LoopCode.SPHERICAL}
"""Code of each loop joint type (URDF type name -> :class:`LoopCode`)."""

COMPILED_FROM = 512
"""Batches of at least this many configurations go through the compiled forward kinematics
(:mod:`screwkit.closure.compiled.frames`); smaller ones, such as single configurations while a
model is built, stay in numpy so that no compiler is loaded for them."""


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


def packed_chains(geometries: list[ChainGeometry]) -> dict:
    """The geometry of chains packed for the compiled kernels: tree joints stacked with offsets."""
    tree = np.cumsum([0] + [g.n_tree_joints for g in geometries])
    dofs = np.cumsum([0] + [g.n_dofs for g in geometries])
    joints = int(tree[-1])

    def stacked(name, shape):
        parts = [np.asarray(getattr(g, name), dtype=float).reshape((-1,) + shape) for g in geometries]
        return np.ascontiguousarray(np.concatenate(parts) if joints else np.zeros((0,) + shape))

    loop_axes = np.zeros((len(geometries), 2, 3))
    for row, geometry in enumerate(geometries):
        axes = np.asarray(geometry.loop_axes, dtype=float).reshape(-1, 3)
        loop_axes[row, :axes.shape[0]] = axes[:2]
    return dict(
        tree_start=tree.astype(np.int64), dof_start=dofs.astype(np.int64),
        joint_rot=stacked("joint_rotations", (3, 3)), joint_trans=stacked("joint_translations", (3,)),
        joint_axis=stacked("joint_axes", (3,)),
        joint_prism=np.array([p for g in geometries for p in g.joint_prismatic], dtype=np.bool_),
        leg_rot=np.array([g.leg_loop_rotation for g in geometries], dtype=float).reshape(-1, 3, 3),
        leg_trans=np.array([g.leg_loop_translation for g in geometries], dtype=float).reshape(-1, 3),
        loop_code=np.array([int(LOOP_CODES[g.loop_type]) for g in geometries], dtype=np.int64),  # ints for numba
        loop_axes=loop_axes,
    )


def _compiled_frames(geometry: ChainGeometry, joint_values: NDArray) -> ChainFrames:
    """:func:`chain_forward_kinematics` through the compiled kernel, configuration by configuration."""
    announce_compilation("screwkit.closure.compiled.frames")
    from screwkit.closure.compiled.frames import chain_frames_kernel  # numba: loaded for large batches only

    batch, m = joint_values.shape[:-1], geometry.n_dofs
    flat = np.ascontiguousarray(joint_values.reshape(-1, m))
    if not flat.flags.writeable:  # the kernel's one signature takes writeable arrays
        flat = flat.copy()
    count = flat.shape[0]
    axes, points = np.empty((count, m, 3)), np.empty((count, m, 3))
    leg_rotation, end_rotation = np.empty((count, 3, 3)), np.empty((count, 3, 3))
    leg_translation, end_translation = np.empty((count, 3)), np.empty((count, 3))
    packed = packed_chains([geometry])
    chain_frames_kernel(flat, packed["tree_start"], packed["dof_start"], packed["joint_rot"], packed["joint_trans"],
                        packed["joint_axis"], packed["joint_prism"], packed["leg_rot"], packed["leg_trans"],
                        packed["loop_code"], packed["loop_axes"], axes, points, leg_rotation, leg_translation,
                        end_rotation, end_translation)
    return ChainFrames(axes.reshape(batch + (m, 3)), points.reshape(batch + (m, 3)),
                       leg_rotation.reshape(batch + (3, 3)), leg_translation.reshape(batch + (3,)),
                       end_rotation.reshape(batch + (3, 3)), end_translation.reshape(batch + (3,)))


def _skew_one(vector: NDArray) -> NDArray:
    """:func:`~screwkit.common.rotations.skew_matrix` of one vector."""
    x, y, z = vector
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def _turn_one(rotation: NDArray, axis: NDArray, angle: float) -> NDArray:
    """:func:`_turn` of one rotation, with the same arithmetic."""
    skew = _skew_one(axis)
    return rotation + np.sin(angle) * (rotation @ skew) + (1.0 - np.cos(angle)) * (rotation @ (skew @ skew))


def _rotation_from_rotation_vector_one(vector: NDArray) -> NDArray:
    """:func:`~screwkit.common.rotations.rotation_from_rotation_vector` of one vector, with the same arithmetic."""
    angle = np.linalg.norm(vector, axis=-1)
    square = np.square(angle)  # as the batched ``angle**2`` computes it
    if angle < 1e-6:
        sine_term, cosine_term = 1.0 - square / 6.0, 0.5 - square / 24.0
    else:
        sine_term, cosine_term = np.sin(angle) / angle, (1.0 - np.cos(angle)) / square
    skew = _skew_one(vector)
    return _IDENTITY + sine_term * skew + cosine_term * (skew @ skew)


def _single_frames(geometry: ChainGeometry, joint_values: NDArray, batch: tuple[int, ...]) -> ChainFrames:
    """:func:`chain_forward_kinematics` of one configuration (m,), returned with the leading ``batch`` axes
    (all of length 1): the same products in the same order as the batched path, without its broadcasting,
    which costs more than the arithmetic for one configuration (the reference assembly of a model)."""
    m, n_tree = geometry.n_dofs, geometry.n_tree_joints
    axes, points = np.empty((m, 3)), np.empty((m, 3))
    rotation, translation = _IDENTITY, np.zeros(3)
    for index in range(n_tree):
        translation = translation + rotation @ geometry.joint_translations[index]
        rotation = rotation @ geometry.joint_rotations[index]
        axis = rotation @ geometry.joint_axes[index]
        axes[index] = axis
        if geometry.joint_prismatic[index]:
            translation = translation + axis * joint_values[index]
        else:
            rotation = _turn_one(rotation, geometry.joint_axes[index], joint_values[index])
        points[index] = translation
    translation = translation + rotation @ geometry.leg_loop_translation
    rotation = rotation @ geometry.leg_loop_rotation
    leg_rotation, leg_translation = rotation, translation
    loop_values = joint_values[n_tree:]
    loop_type = geometry.loop_type
    if loop_type in ("revolute", "continuous"):
        axes[n_tree] = rotation @ geometry.loop_axes[0]
        points[n_tree] = translation
        rotation = _turn_one(rotation, geometry.loop_axes[0], loop_values[0])
    elif loop_type == "prismatic":
        axis = rotation @ geometry.loop_axes[0]
        axes[n_tree] = axis
        translation = translation + axis * loop_values[0]
        points[n_tree] = translation
    elif loop_type == "universal":
        axes[n_tree] = rotation @ geometry.loop_axes[0]
        points[n_tree : n_tree + 2] = translation
        rotation = _turn_one(rotation, geometry.loop_axes[0], loop_values[0])
        axes[n_tree + 1] = rotation @ geometry.loop_axes[1]
        rotation = _turn_one(rotation, geometry.loop_axes[1], loop_values[1])
    elif loop_type == "spherical":
        axes[n_tree : n_tree + 3] = rotation.T
        points[n_tree : n_tree + 3] = translation
        rotation = rotation @ _rotation_from_rotation_vector_one(loop_values)
    return ChainFrames(axes.reshape(batch + (m, 3)), points.reshape(batch + (m, 3)),
                       leg_rotation.reshape(batch + (3, 3)), leg_translation.reshape(batch + (3,)),
                       rotation.reshape(batch + (3, 3)), translation.reshape(batch + (3,)))


def chain_forward_kinematics(geometry: ChainGeometry, joint_values: ArrayLike, *,
                             compiled: bool | None = None) -> ChainFrames:
    """Forward kinematics of one chain for a batch of joint values (..., m), base frame.

    Product of exponentials over the tree joints (each placement then the joint motion),
    then the loop-joint motion (see the module docstring for the loop types). Batches of
    :data:`COMPILED_FROM` configurations or more go through the compiled kernel (about five times
    faster on the hexapods' chains); smaller ones through numpy, where products with the constant placements are single
    BLAS calls over the whole batch. ``compiled`` forces one or the other.
    """
    joint_values = np.asarray(joint_values, dtype=float)
    if joint_values.shape[-1:] != (geometry.n_dofs,):
        raise ValueError(
            f"Expected joint values of chain {geometry.name!r} with shape (..., {geometry.n_dofs}), "
            f"got {joint_values.shape}."
        )
    batch = joint_values.shape[:-1]
    count = int(np.prod(batch, dtype=np.int64))
    if compiled or (compiled is None and count >= COMPILED_FROM):
        return _compiled_frames(geometry, joint_values)
    if count == 1:
        return _single_frames(geometry, joint_values.reshape(geometry.n_dofs), batch)
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


def wrap_revolute_values(geometry: ChainGeometry, values: NDArray) -> NDArray:
    """Wrap the revolute DoFs (tree and 1-DoF/universal loop) of a chain to (-pi, pi]."""
    wrap = np.array([not prismatic for prismatic in geometry.dof_prismatic])
    if geometry.loop_type == "spherical":
        wrap[geometry.n_tree_joints :] = False
    values = np.array(values, dtype=float, copy=True)
    values[..., wrap] = wrap_angle(values[..., wrap])
    return values


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


def _combination(terms: list) -> float:
    """:func:`_linear_combination` of numbers: zero coefficients skipped, the first term as ``plane * coefficient``."""
    total = None
    for coefficient, value in terms:
        if coefficient == 0.0:
            continue
        total = value * coefficient if total is None else total + coefficient * value
    return 0.0 if total is None else total


def _single_twists(axes: NDArray, points: NDArray, prismatic) -> NDArray[np.float64]:
    """:func:`twists_from_axes_and_points` of one configuration (m, 3), with the same arithmetic in numbers."""
    twists = np.zeros((axes.shape[0], 6))
    for joint, (axis, point) in enumerate(zip(axes.tolist(), points.tolist())):
        start = 3 if prismatic[joint] else 0
        twists[joint, start : start + 3] = [value if value != 0.0 else 0.0 for value in axis]
        if prismatic[joint]:
            continue
        (ax, ay, az), (px, py, pz) = axis, point
        twists[joint, 3:] = (_combination([(az, py), (-ay, pz)]), _combination([(ax, pz), (-az, px)]),
                             _combination([(ay, px), (-ax, py)]))
    return twists


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
    if out is None and np.ndim(axes) == 2 and np.ndim(points) == 2:
        return _single_twists(np.asarray(axes, dtype=float), np.asarray(points, dtype=float), prismatic)
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
            rotation[row, 0] * axes_components[0]
            + rotation[row, 1] * axes_components[1]
            + rotation[row, 2] * axes_components[2]
        )
        new_points[row] = (
            rotation[row, 0] * points_components[0]
            + rotation[row, 1] * points_components[1]
            + rotation[row, 2] * points_components[2]
            + translation[row]
        )
    return np.moveaxis(new_axes, (0, 1), (-1, -2)), np.moveaxis(new_points, (0, 1), (-1, -2))

