"""The spatial closed forms: a spherical loop joint, targets that are platform-side loop frames.

* :class:`LegVectorChain` (``ups``): the leg vector, pointed by the universal joint (Paden-Kahan 2);
* :class:`CrankRodChain` (``rus``): the crank angle from a circle-sphere intersection;

both built on :class:`SpatialClosedForm`, which solves batches in numpy or, for large batches,
through the compiled kernel (:mod:`screwkit.closure.compiled.closed_form`).
"""

from __future__ import annotations

from enum import IntEnum
from functools import cached_property

import numpy as np
from numpy.typing import NDArray

from screwkit.closure.analytic.results import ClosedFormResult, Rejection
from screwkit.closure.chain_kinematics import ChainFrames, chain_forward_kinematics, packed_chains
from screwkit.closure.threads import for_each_block
from screwkit.common.compiling import CLOSED_FORM_KERNEL, prepare_kernels
from screwkit.common.rotations import (
    rotation_about_axis,
    rotation_vector_from_rotation,
    two_axis_pointing,
    wrap_angle,
)
from screwkit.common.tolerances import BOUNDARY_ROUNDING, CLOSURE_TOLERANCE
from screwkit.model.chain import ChainGeometry


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


class KernelKind(IntEnum):
    """The chain type of a spatial closed form in the compiled kernel
    (:func:`screwkit.closure.compiled.closed_form.spatial_closed_form_kernel`'s ``kind``, an integer there)."""

    NONE = -1  # no compiled form: numpy only
    UPS = 0  # U-P-S: the leg vector
    RUS = 1  # R-U-S: crank and rod


class SpatialClosedForm:
    """Common part of the spatial closed forms (targets are platform-side loop frames).

    Subclasses return the tree-joint values; the spherical loop joint's values and all
    joint axes and points then follow from one forward-kinematics pass.
    """

    kind = ""
    planar = False
    n_branches = 2
    kernel_kind = KernelKind.NONE  # the chain type in the compiled kernel, and the attributes it takes
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
                int(self.kernel_kind), parameters, signs, rotation[block], translation[block], loop_rotation,
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
        """Solve flat batches of targets, shapes (N, 3, 3) and (N, 3), block by block in threads; ``branch``: one
        working mode (a sign per branch) or one per target (N, n_branches)."""
        if np.ndim(branch) == 2:  # a working mode per target (the assembly tries every mode in one batch)
            branch = tuple(np.ascontiguousarray(column, dtype=float) for column in np.asarray(branch).T)
        else:
            branch = tuple(float(sign) for sign in np.atleast_1d(branch))
        geometry = self.geometry
        count, n_tree = target_translation.shape[0], geometry.n_tree_joints
        values = np.empty((count, geometry.n_dofs))
        axes = np.empty((count, geometry.n_dofs, 3))
        points = np.empty((count, geometry.n_dofs, 3))
        gap = np.empty(count)

        def work(block: slice) -> None:
            signs = tuple(sign[block] if isinstance(sign, np.ndarray) else sign for sign in branch)
            tree_values, gap[block] = self._tree_values(target_translation[block], signs)
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
    kernel_kind = KernelKind.UPS

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
        direction = np.asarray(slider_sign)[..., None] * leg / safe[..., None]
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
    kernel_kind = KernelKind.RUS

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
        excess = np.abs(constant) - amplitude  # a stretched or folded rod within rounding of its reach: reached
        excess = np.where(excess > BOUNDARY_ROUNDING * np.maximum(np.abs(constant), amplitude), excess, 0.0)
        gap = excess / np.linalg.norm(perpendicular)
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
