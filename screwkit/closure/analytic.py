"""Closed-form solvers of the chain types that have one (numpy only, batched).

Each solver class recognises its chain type from a :class:`~screwkit.model.chain.ChainGeometry`
(:meth:`from_geometry` returns the solver, or a :class:`Rejection` saying why the chain is not of
that type) and solves whole batches of platform poses block by block, in threads:

* :class:`PlanarRevoluteChain` (``planar_rrr``): elbow by the intersection of two circles;
* :class:`PlanarSliderChain` (``planar_rpr``): the leg direction and length;
* :class:`LegVectorChain` (``ups``): the leg vector, pointed by the universal joint (Paden-Kahan 2);
* :class:`CrankRodChain` (``rus``): the crank angle from a circle-sphere intersection.

Recognition uses :data:`screwkit.common.tolerances.CLOSURE_TOLERANCE`, the tolerance at which a file's
loops must close, so a file written to 6 decimals keeps its closed forms.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from typing import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.closure.chain_kinematics import ChainFrames, chain_forward_kinematics, packed_chains
from screwkit.closure.threads import for_each_block
from screwkit.common.compiling import CLOSED_FORM_KERNEL, prepare_kernels
from screwkit.common.rotations import (
    rotation_about_axis,
    rotation_vector_from_rotation,
    two_axis_pointing,
    wrap_angle,
)
from screwkit.common.tolerances import CLOSURE_TOLERANCE
from screwkit.model.chain import ChainGeometry

__all__ = [
    "ClosedFormResult",
    "Rejection",
    "PlanarRevoluteChain",
    "PlanarSliderChain",
    "LegVectorChain",
    "CrankRodChain",
    "CLOSED_FORMS",
    "closed_form_for",
]


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


@dataclass(frozen=True)
class Rejection:
    """Why a chain is not of a closed-form type (falsy, so ``if solver:`` reads naturally)."""

    kind: str
    reason: str

    def __bool__(self) -> bool:
        return False


def _angle_of(vector: ArrayLike) -> float:
    return math.atan2(float(vector[1]), float(vector[0]))


def _sign_along_z(axis: NDArray, tolerance: float = CLOSURE_TOLERANCE) -> float:
    """+1 or -1 if the unit ``axis`` is +z or -z, else 0."""
    if abs(axis[0]) < tolerance and abs(axis[1]) < tolerance and abs(abs(axis[2]) - 1.0) < tolerance:
        return float(np.sign(axis[2]))
    return 0.0


def _line_intersection(
    first_point: NDArray, first_axis: NDArray, second_point: NDArray, second_axis: NDArray, tolerance: float
) -> NDArray | None:
    """Common point of two non-parallel lines (within ``tolerance``, a length), or None if they are parallel or skew."""
    normal = np.cross(first_axis, second_axis)
    if np.linalg.norm(normal) < CLOSURE_TOLERANCE:
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
    @staticmethod
    def describe_branch(branch) -> str:
        """The working mode in words."""
        sign = float(np.atleast_1d(branch)[0])
        return f"elbow {'left' if sign > 0 else 'right'} of the line from the base joint to the platform joint"

    @classmethod
    def from_geometry(cls, geometry: ChainGeometry, length: float = 1.0) -> PlanarRevoluteChain | Rejection:
        """The solver of an R-R-R chain about z (tree joints R, R; loop R), or why not."""
        if geometry.n_tree_joints != 2 or any(geometry.joint_prismatic):
            return Rejection(cls.kind, "its tree joints are not two revolute joints")
        if geometry.loop_type not in ("revolute", "continuous"):
            return Rejection(cls.kind, f"its loop joint is {geometry.loop_type}, not revolute")
        frames = chain_forward_kinematics(geometry, np.zeros(3))
        signs = np.array([_sign_along_z(axis) for axis in frames.axes])
        if np.any(signs == 0.0) or _sign_along_z(frames.leg_rotation[:, 2]) == 0.0:
            return Rejection(cls.kind, "a joint axis is not along the base z axis")
        if _sign_along_z(geometry.platform_loop_rotation[:, 2]) == 0.0:
            return Rejection(cls.kind, "the platform-side loop frame's z axis is not along the base z axis")
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

    @staticmethod
    def describe_branch(branch) -> str:
        """The working mode in words."""
        sign = float(np.atleast_1d(branch)[0])
        return f"slider pointing {'towards' if sign > 0 else 'away from'} the platform joint"

    @classmethod
    def from_geometry(cls, geometry: ChainGeometry, length: float = 1.0) -> PlanarSliderChain | Rejection:
        """The solver of an R-P-R chain in the x-y plane whose slider runs along the leg, or why not."""
        if geometry.n_tree_joints != 2 or geometry.joint_prismatic != (False, True):
            return Rejection(cls.kind, "its tree joints are not a revolute then a prismatic joint")
        if geometry.loop_type not in ("revolute", "continuous"):
            return Rejection(cls.kind, f"its loop joint is {geometry.loop_type}, not revolute")
        frames = chain_forward_kinematics(geometry, np.zeros(3))
        signs = np.array([_sign_along_z(frames.axes[0]), 1.0, _sign_along_z(frames.axes[2])])
        if signs[0] == 0.0 or signs[2] == 0.0 or abs(frames.axes[1, 2]) > CLOSURE_TOLERANCE:
            return Rejection(cls.kind, "a revolute axis is not along z or the slider leaves the x-y plane")
        if (_sign_along_z(frames.leg_rotation[:, 2]) == 0.0
                or _sign_along_z(geometry.platform_loop_rotation[:, 2]) == 0.0):
            return Rejection(cls.kind, "a loop frame's z axis is not along the base z axis")
        leg = frames.points[2, :2] - frames.points[0, :2]
        slider = frames.axes[1, :2] / np.linalg.norm(frames.axes[1, :2])
        leg_length = np.linalg.norm(leg)
        if leg_length <= CLOSURE_TOLERANCE * length:
            return Rejection(cls.kind, "its base and platform joints coincide")
        if abs(leg[0] * slider[1] - leg[1] * slider[0]) > CLOSURE_TOLERANCE * leg_length:
            return Rejection(cls.kind,
                             "the slider does not run along the line from the base joint to the platform joint")
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
    kernel_kind = -1  # the chain type in the compiled kernel (-1: none, numpy only), and the attributes it takes
    kernel_parameters: tuple[str, ...] = ()

    def solve_compiled(self, platform_rotation: NDArray, platform_translation: NDArray, branch) -> ClosedFormResult:
        """:meth:`solve` for platform frames (N, 3, 3), (N, 3) through the compiled kernel
        (:mod:`screwkit.closure.compiled.closed_form`), block by block in threads: the same result,
        several times faster on large batches."""
        prepare_kernels((CLOSED_FORM_KERNEL,))
        from screwkit.closure.compiled.closed_form import spatial_closed_form_kernel  # numba: large batches only

        geometry = self.geometry
        rotation = np.ascontiguousarray(platform_rotation, dtype=float)
        translation = np.ascontiguousarray(platform_translation, dtype=float)
        count = translation.shape[0]
        values = np.empty((count, geometry.n_dofs))
        axes = np.empty((count, geometry.n_dofs, 3))
        points = np.empty((count, geometry.n_dofs, 3))
        gap = np.empty(count)
        parameters = np.concatenate([np.ravel(getattr(self, name)) for name in self.kernel_parameters]).astype(float)
        signs = np.array([float(sign) for sign in np.atleast_1d(branch)])
        packed = self.packed
        loop_rotation = np.ascontiguousarray(geometry.platform_loop_rotation, dtype=float)
        loop_translation = np.ascontiguousarray(geometry.platform_loop_translation, dtype=float)

        def work(block: slice) -> None:
            spatial_closed_form_kernel(
                self.kernel_kind, parameters, signs, rotation[block], translation[block], loop_rotation,
                loop_translation, packed["tree_start"], packed["dof_start"], packed["joint_rot"],
                packed["joint_trans"], packed["joint_axis"], packed["joint_prism"], packed["leg_rot"],
                packed["leg_trans"], packed["loop_code"], packed["loop_axes"], values[block], axes[block],
                points[block], gap[block])

        for_each_block(count, work)
        return ClosedFormResult(values=values, reachable=gap == 0.0, gap=gap, axes=axes, points=points)

    @cached_property
    def packed(self) -> dict:
        """The chain's geometry packed for the compiled kernels."""
        return packed_chains([self.geometry])

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

    @classmethod
    def _zero_frames(
        cls, geometry: ChainGeometry, prismatic: tuple[bool, ...], universal_joints: tuple[int, int], length: float
    ) -> tuple[ChainFrames, NDArray] | Rejection:
        """Zero-value frames and universal-joint centre, if the chain has the joint pattern and a spherical loop."""
        if geometry.joint_prismatic != prismatic or geometry.loop_type != "spherical":
            pattern = "-".join("P" if p else "R" for p in prismatic)
            return Rejection(cls.kind, f"its joints are not {pattern} closed by a spherical loop joint")
        frames = chain_forward_kinematics(geometry, np.zeros(geometry.n_dofs))
        first, second = universal_joints
        centre = _line_intersection(frames.points[first], frames.axes[first],
                                    frames.points[second], frames.axes[second], CLOSURE_TOLERANCE * length)
        if centre is None:
            return Rejection(cls.kind,
                             f"the axes of joints {first + 1} and {second + 1} do not meet (no universal joint)")
        return frames, centre


class LegVectorChain(SpatialClosedForm):
    """U-P-S chain: universal joint at the base, slider along the leg, spherical loop joint.

    With ``b`` the universal joint centre and ``s`` the platform joint centre, the slider
    value is ``sigma_P |s - b| - l0`` and the universal joint turns the zero-value leg
    direction onto ``sigma_P (s - b)/|s - b|`` (Paden-Kahan subproblem 2, branch
    ``sigma_U``). Branch = ``(sigma_U, sigma_P)``.
    """

    kind = "ups"
    kernel_kind = 0

    @staticmethod
    def describe_branch(branch) -> str:
        """The working mode in words."""
        universal, slider = (int(np.sign(value)) for value in np.atleast_1d(branch))
        return (f"universal-joint branch sigma_U = {universal:+d}, slider pointing "
                f"{'towards' if slider > 0 else 'away from'} the spherical joint (sigma_P = {slider:+d})")
    kernel_parameters = ("centre", "first_axis", "second_axis", "slider_direction", "leg_offset")

    @classmethod
    def from_geometry(cls, geometry: ChainGeometry, length: float = 1.0) -> LegVectorChain | Rejection:
        """The solver of a U-P-S chain whose slider runs along the leg, or why not."""
        found = cls._zero_frames(geometry, (False, False, True), (0, 1), length)
        if isinstance(found, Rejection):
            return found
        frames, centre = found
        leg = frames.leg_translation - centre
        leg_length = np.linalg.norm(leg)
        if leg_length <= CLOSURE_TOLERANCE * length:
            return Rejection(cls.kind, "its universal and spherical joint centres coincide")
        if np.linalg.norm(np.cross(leg, frames.axes[2])) > CLOSURE_TOLERANCE * leg_length:
            return Rejection(cls.kind,
                             "the slider does not run along the leg from the universal to the spherical joint")
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
    kernel_kind = 1

    @staticmethod
    def describe_branch(branch) -> str:
        """The working mode in words."""
        crank, universal = (int(np.sign(value)) for value in np.atleast_1d(branch))
        return f"crank branch sigma_R = {crank:+d}, universal-joint branch sigma_U = {universal:+d}"
    kernel_parameters = ("crank_point", "crank_axis", "crank_vector", "first_universal_axis", "second_universal_axis",
                         "rod_direction", "rod_length")

    @classmethod
    def from_geometry(cls, geometry: ChainGeometry, length: float = 1.0) -> CrankRodChain | Rejection:
        """The solver of an R-U-S chain (a crank, a rod), or why not."""
        found = cls._zero_frames(geometry, (False, False, False), (1, 2), length)
        if isinstance(found, Rejection):
            return found
        frames, centre = found
        crank = centre - frames.points[0]
        crank_perpendicular = crank - (crank @ frames.axes[0]) * frames.axes[0]
        rod = frames.leg_translation - centre
        if np.linalg.norm(crank_perpendicular) <= CLOSURE_TOLERANCE * length:
            return Rejection(cls.kind, "the universal joint sits on the crank axis (no crank)")
        if np.linalg.norm(rod) <= CLOSURE_TOLERANCE * length:
            return Rejection(cls.kind, "its universal and spherical joint centres coincide (no rod)")
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


def closed_form_for(geometry: ChainGeometry, planar: bool, length: float = 1.0) -> tuple[object | None, str]:
    """The first closed form of :data:`CLOSED_FORMS` that fits the chain, and why.

    Parameters
    ----------
    geometry : ChainGeometry
    planar : bool
        Whether the mechanism is planar (only planar closed forms are tried, else only spatial ones).
    length : float
        The mechanism's length scale (m): point coincidences are judged relative to it.

    Returns
    -------
    solver : object or None
        A solver instance, or None when no closed form fits (the chain is solved by Newton).
    reason : str
        Which closed form matched, or for each one tried why it does not fit.
    """
    rejections = []
    for solver_class in CLOSED_FORMS:
        if solver_class.planar != planar:
            continue
        solver = solver_class.from_geometry(geometry, length)
        if not isinstance(solver, Rejection):
            return solver, f"closed form {solver_class.kind}: {solver_class.__doc__.strip().splitlines()[0]}"
        rejections.append(f"not {solver.kind} ({solver.reason})")
    return None, "damped Newton: " + "; ".join(rejections)

