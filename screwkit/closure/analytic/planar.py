"""The planar closed forms: the platform pose is ``(x, y, angle)`` and every revolute axis is along z.

* :class:`PlanarRevoluteChain` (``planar_rrr``): elbow by the intersection of two circles;
* :class:`PlanarSliderChain` (``planar_rpr``): the leg direction and length;

both built on :class:`PlanarClosedForm`, which solves batches block by block, in threads.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.closure.analytic.results import ClosedFormResult, Rejection
from screwkit.closure.chain_kinematics import ChainFrames, chain_forward_kinematics
from screwkit.closure.threads import for_each_block
from screwkit.common.rotations import wrap_angle
from screwkit.common.tolerances import BOUNDARY_ROUNDING, CLOSURE_TOLERANCE
from screwkit.model.chain import ChainGeometry


def _angle_of(vector: ArrayLike) -> float:
    return math.atan2(float(vector[1]), float(vector[0]))


def _sign_along_z(axis: NDArray, tolerance: float = CLOSURE_TOLERANCE) -> float:
    """+1 or -1 if the unit ``axis`` is +z or -z, else 0."""
    if abs(axis[0]) < tolerance and abs(axis[1]) < tolerance and abs(abs(axis[2]) - 1.0) < tolerance:
        return float(np.sign(axis[2]))
    return 0.0



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
        # a stretched or folded leg (height 0) is reached whatever rounding makes of its height: beyond its reach by
        # less than a 1e-12th of the distance, as the unit or the world frame the file is written in rounds it
        reachable = height_squared >= -BOUNDARY_ROUNDING * np.maximum(1.0, (first * first) * inverse)
        height = np.sqrt(np.maximum(height_squared, 0.0))
        with np.errstate(invalid="ignore"):  # the end on the base joint (delta 0): NaN, an unreachable pose
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
