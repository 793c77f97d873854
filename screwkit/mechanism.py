"""Closed-loop mechanism model: URDF (+ loops, transmissions) -> Pinocchio -> chains -> screws.

:func:`load` reads a URDF that follows ``docs/urdf-convention.md`` (a bundled name or a file
path), builds the Pinocchio model of its kinematic tree, finds every chain (the serial path of
tree joints from the base to a ``<loop>`` joint that closes it onto the platform), the
actuators (``<transmission>``), the task coordinates and the reference assembly, and returns a
:class:`Mechanism`.

:meth:`Mechanism.solve` closes all chains for a batch of platform poses (closed forms where the
chain type has one, batched damped Newton with continuation otherwise) and
:meth:`Mechanism.chain_screws` turns a :class:`Solution` into one
:class:`~screwkit.chains.ChainScrews` per chain, the hand-over to the math core.

Frames: poses are the platform frame relative to the **base link** frame (the parent link of the
platform's floating/planar joint); screws are world-frame by default (the URDF root frame,
Pinocchio's universe), or base-frame on request.
"""

from __future__ import annotations

import math
import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field, replace
from functools import cached_property
from importlib import resources
from pathlib import Path
from typing import Literal, Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.chains import ChainScrews
from screwkit.kinematics import (
    LOOP_JOINT_DOFS,
    ChainGeometry,
    block_threads,
    chain_forward_kinematics,
    closed_form_for,
    for_each_block,
    loop_values_from_relative_transform,
    newton_solve_chain,
    rotation_about_axis,
    rotation_from_rotation_vector,
    rotation_from_rpy,
    rotation_vector_from_rotation,
    rpy_from_rotation,
    transform_axes_and_points,
    twists_from_axes_and_points,
    wrap_angle,
    wrap_revolute_values,
)
from screwkit.urdf import PLATFORM_JOINT_TYPES, UrdfDescription, read_urdf

PLANAR_TASK_COORDINATES = ("x", "y", "phi")
"""Task coordinates of a planar mechanism: platform position in the base x-y plane (m) and
its rotation about the base z axis (rad)."""
SPATIAL_TASK_COORDINATES = ("x", "y", "z", "roll", "pitch", "yaw")
"""Task coordinates of a spatial mechanism: platform position (m) and orientation
``R = Rz(yaw) Ry(pitch) Rx(roll)`` (rad, fixed axes, the URDF ``rpy`` convention)."""
CLOSURE_TOLERANCE = 1e-6
"""Largest loop-closure gap (m and rad) accepted at the reference configuration."""


def twist_from_pinocchio_motion(motion: ArrayLike) -> NDArray[np.float64]:
    """Reorder Pinocchio motion vectors ``(linear, angular)`` (..., 6) to screwkit twists ``(omega, v)``.

    This is the only place where Pinocchio's ordering is converted. For a Jacobian matrix
    (6, n), pass its transpose.
    """
    motion = np.asarray(motion, dtype=float)
    if motion.shape[-1:] != (6,):
        raise ValueError(f"Expected Pinocchio motion vectors with shape (..., 6), got {motion.shape}.")
    return np.concatenate([motion[..., 3:], motion[..., :3]], axis=-1)


def bundled_names() -> tuple[str, ...]:
    """Names of the mechanisms shipped in :mod:`screwkit.robots`."""
    folder = resources.files("screwkit.robots")
    return tuple(sorted(item.name[: -len(".urdf")] for item in folder.iterdir() if item.name.endswith(".urdf")))


def bundled_path(name: str) -> Path:
    """Path of a bundled URDF; raises ValueError listing the bundled names if unknown."""
    if name not in bundled_names():
        raise ValueError(f"Unknown bundled mechanism {name!r}; bundled are: {', '.join(bundled_names())}.")
    return Path(str(resources.files("screwkit.robots").joinpath(f"{name}.urdf")))


def load(name_or_path: str | os.PathLike) -> Mechanism:
    """Load a mechanism by bundled name (see :func:`bundled_names`) or URDF file path.

    Raises
    ------
    ValueError
        Unknown name or missing file, or a URDF that breaks the convention (the message names
        the file, the element and the problem).
    """
    text = os.fspath(name_or_path)
    looks_like_path = isinstance(name_or_path, os.PathLike) or text.endswith(".urdf") or os.sep in text or "/" in text
    if not looks_like_path:
        path = bundled_path(text)
    else:
        path = Path(text)
        if not path.is_file():
            raise ValueError(
                f"{text}: no such URDF file (bundled mechanisms are: {', '.join(bundled_names())})."
            )
    return Mechanism(read_urdf(path))


@dataclass(frozen=True)
class Chain:
    """One chain: tree joints from the base to the leg end, then the loop joint's DoFs.

    Attributes
    ----------
    name : str
        Chain name (the loop's ``chain`` attribute, else the loop name).
    joint_names : tuple of str
        One name per DoF, base to platform. A loop joint with several DoFs contributes
        ``loop[1]``, ``loop[2]`` (universal) or ``loop[x]``, ``loop[y]``, ``loop[z]`` (spherical).
    actuated : tuple of int
        Indices into ``joint_names`` of the actuated DoFs.
    prismatic : tuple of bool
        Whether each DoF is prismatic.
    loop_name, loop_type : str
        The closing ``<loop>``.
    solver : str
        ``"planar_rrr"``, ``"planar_rpr"``, ``"ups"``, ``"rus"`` (closed forms) or ``"newton"``.
    """

    name: str
    joint_names: tuple[str, ...]
    actuated: tuple[int, ...]
    prismatic: tuple[bool, ...]
    loop_name: str
    loop_type: str
    solver: str

    @property
    def n_joints(self) -> int:
        """Number of DoFs m of the chain."""
        return len(self.joint_names)


@dataclass(frozen=True)
class Solution:
    """Closed-chain configurations of a mechanism for a batch of platform poses.

    Attributes
    ----------
    poses : ndarray, shape (..., n_task)
    joint_values : tuple of ndarray, each shape (..., m_i)
        Per chain, values of its DoFs (rad or m; revolute values wrapped to (-pi, pi],
        spherical loop values as rotation vectors); NaN where the chain is unreachable.
    reachable : ndarray of bool, shape (...)
        Every chain closed (in the requested working mode).
    chain_reachable : ndarray of bool, shape (..., n_chains)
    residuals : ndarray, shape (..., n_chains)
        Where closed, the remaining closure error (0 for closed forms); where not, by how far
        the chain misses (m for closed forms, the final Newton error norm otherwise).
    joint_axes, joint_points : tuple of ndarray, each shape (..., m_i, 3)
        Per chain, joint axes and points in the **base** frame (component-major views for the
        closed forms); meaningful only where the chain is reachable.
    """

    poses: NDArray[np.float64]
    reachable: NDArray[np.bool_]
    chain_reachable: NDArray[np.bool_]
    residuals: NDArray[np.float64]
    joint_axes: tuple[NDArray[np.float64], ...]
    joint_points: tuple[NDArray[np.float64], ...]
    value_sources: tuple = field(repr=False)
    """Per chain, the joint values (..., m_i) or a function computing them flat (N, m_i)."""

    @property
    def batch_shape(self) -> tuple[int, ...]:
        """Shape of the batch of poses."""
        return self.poses.shape[:-1]

    @cached_property
    def joint_values(self) -> tuple[NDArray[np.float64], ...]:
        """Per chain, joint values (..., m_i); computed on first access for the planar closed forms."""
        values = []
        for source in self.value_sources:
            array = source() if callable(source) else np.asarray(source)
            values.append(array.reshape(self.batch_shape + array.shape[-1:]))
        return tuple(values)


class Mechanism:
    """A redundantly actuated closed-loop mechanism read from a URDF.

    Build it with :func:`load`. See the module docstring and ``docs/urdf-convention.md``.

    Attributes
    ----------
    name : str
    path : str
        The URDF file.
    model : pinocchio.Model
        The kinematic tree (loops are not part of it).
    is_planar : bool
        The platform hangs from a ``planar`` joint (else ``floating``).
    task_coordinates : tuple of str
        :data:`PLANAR_TASK_COORDINATES` or :data:`SPATIAL_TASK_COORDINATES`.
    dof : int
        Mobility of the platform at the reference assembly (dimension of the intersection of
        the chains' twist spaces).
    chains : tuple of Chain
        In ``<loop>`` file order.
    actuators : list of (str, str)
        ``(chain name, joint name)`` of every actuated joint, in chain order.
    home_pose : ndarray, shape (n_task,)
        Task coordinates of the reference assembly.
    base_link, platform_link, platform_joint : str
    reference_joint_values : tuple of ndarray
        Per chain, the joint values of the reference assembly.
    branches : tuple
        Per chain, the working mode of the reference assembly: a tuple of +-1 signs for a
        closed-form chain (see the solver classes in :mod:`screwkit.kinematics`), the sign of
        the chain's twist-matrix determinant for a Newton chain (None if not square/singular).
    rotation_world_base, translation_world_base : ndarray
        Placement of the base link frame in the world frame.
    """

    def __init__(self, description: UrdfDescription):
        import pinocchio

        self.description = description
        self.path = description.source
        self.name = description.robot_name or Path(description.source).stem
        try:
            self.model = pinocchio.buildModelFromXML(description.text)
        except Exception as error:  # Pinocchio raises plain RuntimeErrors
            message = str(error).strip().splitlines()[0] if str(error).strip() else type(error).__name__
            raise description.fail(f"<robot name='{self.name}'>", f"Pinocchio cannot build the model: {message}") from None
        self._read_platform(pinocchio)
        self._read_chains(pinocchio)
        self._read_actuators()
        self._read_reference()
        self._choose_solvers()
        self.dof = self._mobility()

    # -- model reading ---------------------------------------------------------------------

    def _read_platform(self, pinocchio) -> None:
        description, model = self.description, self.model
        candidates = [joint for joint in description.joints.values() if joint.type in PLATFORM_JOINT_TYPES]
        if len(candidates) != 1:
            found = ", ".join(repr(joint.name) for joint in candidates) or "none"
            raise description.fail(
                f"<robot name='{self.name}'>",
                f"expected exactly one floating or planar joint attaching the platform to the base, found {found}.",
            )
        joint = candidates[0]
        tag = f"<joint name='{joint.name}'>"
        self.platform_joint, self.base_link, self.platform_link = joint.name, joint.parent, joint.child
        self.is_planar = joint.type == "planar"
        if self.is_planar:
            if not np.allclose(joint.axis, [0.0, 0.0, 1.0], atol=1e-9):
                raise description.fail(tag, f"a planar platform joint must have <axis xyz='0 0 1'/>, got {joint.axis}.")
            if not np.allclose(joint.origin.rotation[:, 2], [0.0, 0.0, 1.0], atol=1e-9):
                raise description.fail(tag, "the origin of a planar platform joint may only rotate about z.")
        self.task_coordinates = PLANAR_TASK_COORDINATES if self.is_planar else SPATIAL_TASK_COORDINATES
        self._platform_joint_id = model.getJointId(joint.name)
        base_frame = model.frames[model.getFrameId(self.base_link, pinocchio.BODY)]
        if base_frame.parentJoint != 0 or model.parents[self._platform_joint_id] != 0:
            raise description.fail(tag, f"the base link {self.base_link!r} must be fixed to the world (no moving joint above it).")
        self.rotation_world_base = np.array(base_frame.placement.rotation)
        self.translation_world_base = np.array(base_frame.placement.translation)
        self._base_is_world = np.allclose(self.rotation_world_base, np.eye(3), atol=1e-15) and not np.any(
            self.translation_world_base
        )
        platform_frame = model.frames[model.getFrameId(self.platform_link, pinocchio.BODY)]
        self._platform_frame_placement = platform_frame.placement
        world_platform = model.jointPlacements[self._platform_joint_id] * platform_frame.placement
        rotation = self.rotation_world_base.T @ np.array(world_platform.rotation)
        translation = self.rotation_world_base.T @ (np.array(world_platform.translation) - self.translation_world_base)
        self._home_rotation, self._home_translation = rotation, translation
        self.home_pose = self.poses_from_transforms(rotation, translation)

    def _base_relative(self, placement) -> tuple[NDArray, NDArray]:
        """A world placement (pinocchio.SE3) expressed in the base frame."""
        rotation = self.rotation_world_base.T @ np.array(placement.rotation)
        translation = self.rotation_world_base.T @ (np.array(placement.translation) - self.translation_world_base)
        return rotation, translation

    def _read_chains(self, pinocchio) -> None:
        description, model = self.description, self.model
        data = model.createData()
        pinocchio.computeJointJacobians(model, data, pinocchio.neutral(model))
        geometries, chains, tree_joints, used_by = [], [], [], {}
        if not description.loops:
            raise description.fail(f"<robot name='{self.name}'>", "no <loop> joint closes a chain onto the platform.")
        for loop in description.loops:
            tag = f"<loop name='{loop.name}'>"
            frames = {
                link: model.frames[model.getFrameId(link, pinocchio.BODY)] for link in (loop.predecessor, loop.successor)
            }
            on_platform = [link for link, frame in frames.items() if frame.parentJoint == self._platform_joint_id]
            if len(on_platform) != 1:
                if on_platform:
                    problem = f"both {loop.predecessor!r} and {loop.successor!r} are on the platform."
                else:
                    problem = (
                        f"chain has no path to the platform: neither {loop.predecessor!r} nor {loop.successor!r} "
                        f"is the platform link {self.platform_link!r} or fixed to it."
                    )
                raise description.fail(tag, problem)
            platform_side_is_predecessor = on_platform[0] == loop.predecessor
            if platform_side_is_predecessor:
                leg_link, leg_origin = loop.successor, loop.successor_origin
                platform_link, platform_origin = loop.predecessor, loop.predecessor_origin
                axes = tuple(reversed(loop.axes))
            else:
                leg_link, leg_origin = loop.predecessor, loop.predecessor_origin
                platform_link, platform_origin = loop.successor, loop.successor_origin
                axes = loop.axes
            path = []
            joint_id = frames[leg_link].parentJoint
            while joint_id != 0:
                if joint_id == self._platform_joint_id:
                    raise description.fail(tag, f"the leg link {leg_link!r} hangs from the platform, not from the base.")
                path.append(joint_id)
                joint_id = model.parents[joint_id]
            path.reverse()
            rotations, translations, joint_axes, prismatic, names = [], [], [], [], []
            for index, joint_id in enumerate(path):
                name = model.names[joint_id]
                if name in used_by:
                    raise description.fail(
                        tag,
                        f"its chain shares the joint {name!r} with the chain of loop {used_by[name]!r}; "
                        "chains must be separate serial chains from the base.",
                    )
                used_by[name] = loop.name
                joint = model.joints[joint_id]
                if joint.nv != 1:
                    raise description.fail(
                        f"<joint name='{name}'>",
                        f"chain of loop {loop.name!r} passes through a joint with {joint.nv} DoFs; "
                        "chain joints must be revolute, continuous or prismatic.",
                    )
                subspace = twist_from_pinocchio_motion(
                    np.array(pinocchio.getJointJacobian(model, data, joint_id, pinocchio.LOCAL))[:, joint.idx_v].T
                )
                if np.linalg.norm(subspace[:3]) > 0.5:
                    joint_axes.append(subspace[:3] / np.linalg.norm(subspace[:3]))
                    prismatic.append(False)
                else:
                    joint_axes.append(subspace[3:] / np.linalg.norm(subspace[3:]))
                    prismatic.append(True)
                placement = model.jointPlacements[joint_id]
                if index == 0:
                    rotation, translation = self._base_relative(placement)
                else:
                    rotation, translation = np.array(placement.rotation), np.array(placement.translation)
                rotations.append(rotation)
                translations.append(translation)
                names.append(name)
            leg_placement = frames[leg_link].placement
            if path:
                leg_rotation = np.array(leg_placement.rotation) @ leg_origin.rotation
                leg_translation = np.array(leg_placement.translation) + np.array(leg_placement.rotation) @ leg_origin.translation
            else:
                base_rotation, base_translation = self._base_relative(leg_placement)
                leg_rotation = base_rotation @ leg_origin.rotation
                leg_translation = base_translation + base_rotation @ leg_origin.translation
            platform_placement = self._platform_frame_placement.inverse() * frames[platform_link].placement
            platform_rotation = np.array(platform_placement.rotation) @ platform_origin.rotation
            platform_translation = (
                np.array(platform_placement.translation) + np.array(platform_placement.rotation) @ platform_origin.translation
            )
            geometry = ChainGeometry(
                name=loop.chain,
                joint_rotations=np.array(rotations).reshape(-1, 3, 3),
                joint_translations=np.array(translations).reshape(-1, 3),
                joint_axes=np.array(joint_axes).reshape(-1, 3),
                joint_prismatic=tuple(prismatic),
                leg_loop_rotation=leg_rotation,
                leg_loop_translation=leg_translation,
                loop_type="revolute" if loop.type == "continuous" else loop.type,
                loop_axes=np.array(axes).reshape(-1, 3),
                platform_loop_rotation=platform_rotation,
                platform_loop_translation=platform_translation,
            )
            loop_names = {0: (), 1: (loop.name,), 2: (f"{loop.name}[1]", f"{loop.name}[2]")}
            loop_names[3] = (f"{loop.name}[x]", f"{loop.name}[y]", f"{loop.name}[z]")
            if any(chain.name == loop.chain for chain in chains):
                raise description.fail(tag, f"the chain name {loop.chain!r} is used twice.")
            geometries.append(geometry)
            tree_joints.append(tuple(path))
            chains.append(
                Chain(
                    name=loop.chain,
                    joint_names=tuple(names) + loop_names[LOOP_JOINT_DOFS[loop.type]],
                    actuated=(),
                    prismatic=geometry.dof_prismatic,
                    loop_name=loop.name,
                    loop_type=loop.type,
                    solver="newton",
                )
            )
        self.geometries = tuple(geometries)
        self.chains = tuple(chains)
        self._tree_joint_ids = tuple(tree_joints)

    def _read_actuators(self) -> None:
        description = self.description
        actuated: dict[int, set[int]] = {index: set() for index in range(len(self.chains))}
        for transmission in description.transmissions:
            tag = f"<transmission name='{transmission.name}'>"
            for joint_name in transmission.joints:
                hits = [
                    (chain_index, chain.joint_names.index(joint_name))
                    for chain_index, chain in enumerate(self.chains)
                    if joint_name in chain.joint_names
                ]
                if not hits:
                    if joint_name in description.joints:
                        raise description.fail(
                            tag, f"drives joint {joint_name!r}, which is in no chain from the base to the platform."
                        )
                    raise description.fail(tag, f"names an unknown joint {joint_name!r}.")
                chain_index, joint_index = hits[0]
                actuated[chain_index].add(joint_index)
        if not any(actuated.values()):
            raise description.fail(
                f"<robot name='{self.name}'>", "no actuators: mark the actuated joints with <transmission> elements."
            )
        self.chains = tuple(
            replace(chain, actuated=tuple(sorted(actuated[index]))) for index, chain in enumerate(self.chains)
        )
        self.actuators = [(chain.name, chain.joint_names[index]) for chain in self.chains for index in chain.actuated]

    def _read_reference(self) -> None:
        description = self.description
        chain_of_joint = {
            self.model.names[joint_id]: index for index, ids in enumerate(self._tree_joint_ids) for joint_id in ids
        }
        for name in description.reference_configuration:
            if name not in chain_of_joint:
                raise description.fail(
                    f"<reference_configuration><joint name='{name}'>", "only joints of the chains can be given a value."
                )
        references, self._reference_frames = [], []
        for index, (chain, geometry) in enumerate(zip(self.chains, self.geometries)):
            tree_values = np.array(
                [description.reference_configuration.get(name, 0.0) for name in chain.joint_names[: geometry.n_tree_joints]]
            )
            frames = chain_forward_kinematics(
                geometry, np.concatenate([tree_values, np.zeros(geometry.n_dofs - geometry.n_tree_joints)])
            )
            target_rotation, target_translation = self._loop_targets(index, self._home_rotation, self._home_translation)
            loop_values, position_gap, rotation_gap = loop_values_from_relative_transform(
                geometry,
                frames.leg_rotation.T @ target_rotation,
                frames.leg_rotation.T @ (target_translation - frames.leg_translation),
            )
            if position_gap > CLOSURE_TOLERANCE or rotation_gap > CLOSURE_TOLERANCE:
                raise description.fail(
                    f"<loop name='{chain.loop_name}'>",
                    f"does not close at the reference configuration: the loop frames are {_tidy(position_gap)} m and "
                    f"{_tidy(rotation_gap)} rad apart (tree joints at their <reference_configuration> values or 0, "
                    "platform at its joint origin).",
                )
            values = wrap_revolute_values(geometry, np.concatenate([tree_values, loop_values]))
            references.append(values)
            self._reference_frames.append(chain_forward_kinematics(geometry, values))
            if self.is_planar:
                self._check_planar(chain, self._reference_frames[-1])
        self.reference_joint_values = tuple(references)
        points = np.concatenate([frames.points for frames in self._reference_frames] + [self._home_translation[None]])
        self.length_scale = max(float(np.max(np.linalg.norm(points, axis=-1))), 1e-3)

    def _check_planar(self, chain: Chain, frames) -> None:
        for name, axis, prismatic in zip(chain.joint_names, frames.axes, chain.prismatic):
            along_normal = abs(axis[2])
            if (prismatic and along_normal > 1e-9) or (not prismatic and abs(along_normal - 1.0) > 1e-9):
                raise self.description.fail(
                    f"<loop name='{chain.loop_name}'>",
                    f"the platform moves in the base x-y plane (planar joint {self.platform_joint!r}) but joint "
                    f"{name!r} of this chain is not a planar joint (revolute about z or prismatic in x-y).",
                )

    def _loop_targets(self, index: int, platform_rotation: NDArray, platform_translation: NDArray):
        geometry = self.geometries[index]
        return (
            platform_rotation @ geometry.platform_loop_rotation,
            platform_translation + platform_rotation @ geometry.platform_loop_translation,
        )

    def _choose_solvers(self) -> None:
        solvers, branches, chains, signs = [], [], [], []
        for index, (chain, geometry) in enumerate(zip(self.chains, self.geometries)):
            solver = closed_form_for(geometry, self.is_planar)
            frames = self._reference_frames[index]
            sign = self._determinant_sign(index, frames.axes, frames.points)
            branch = None
            if solver is not None:
                branch = self._matching_branch(index, solver)
                if branch is None:
                    solver = None
            if solver is None:
                branch = sign
            signs.append(sign)
            solvers.append(solver)
            branches.append(branch)
            chains.append(replace(chain, solver="newton" if solver is None else solver.kind))
        self._solvers = tuple(solvers)
        self._reference_signs = tuple(signs)
        self.branches = tuple(branches)
        self.chains = tuple(chains)

    def _matching_branch(self, index: int, solver) -> tuple[int, ...] | None:
        """The closed-form branch that reproduces the reference assembly, if any."""
        reference = self.reference_joint_values[index]
        for code in range(2**solver.n_branches):
            branch = tuple(1 if (code >> bit) & 1 == 0 else -1 for bit in range(solver.n_branches))
            result = self._closed_form(index, solver, self.home_pose[None], branch)
            if not result.reachable[0]:
                continue
            values = result.values() if callable(result.values) else result.values
            difference = values[0] - reference
            revolute = ~np.asarray(self.geometries[index].dof_prismatic)
            difference[revolute] = wrap_angle(difference[revolute])
            if np.max(np.abs(difference), initial=0.0) < 1e-6:
                return branch
        return None

    def _task_rows(self) -> list[int]:
        return [2, 3, 4] if self.is_planar else [0, 1, 2, 3, 4, 5]

    def _determinant_sign(self, index: int, axes: NDArray, points: NDArray) -> NDArray | int | None:
        """Sign of det of the chain's twist matrix in task space (batched); None/0 if not square."""
        geometry = self.geometries[index]
        rows = self._task_rows()
        if geometry.n_dofs != len(rows):
            return None
        twists = twists_from_axes_and_points(axes, points, geometry.dof_prismatic)[..., rows]
        sign = np.sign(np.linalg.det(twists))
        if np.ndim(sign) == 0:
            return None if sign == 0 else int(sign)
        return sign

    def _mobility(self) -> int:
        rows = self._task_rows()
        complements = []
        for geometry, frames in zip(self.geometries, self._reference_frames):
            twists = twists_from_axes_and_points(frames.axes, frames.points, geometry.dof_prismatic)[:, rows].T
            left, singular, _ = np.linalg.svd(twists)
            rank = int(np.sum(singular > 1e-9 * max(1.0, singular[0] if singular.size else 1.0)))
            complements.append(left[:, rank:].T)
        stacked = np.concatenate(complements, axis=0)
        if stacked.size == 0:
            return len(rows)
        singular = np.linalg.svd(stacked, compute_uv=False)
        return len(rows) - int(np.sum(singular > 1e-9))

    # -- poses -----------------------------------------------------------------------------

    @property
    def n_task(self) -> int:
        """Number of task coordinates (3 planar, 6 spatial)."""
        return len(self.task_coordinates)

    def check_poses(self, poses: ArrayLike) -> NDArray[np.float64]:
        """Poses as a float array (..., n_task) with finite values, or a clear ValueError."""
        try:
            poses = np.asarray(poses, dtype=float)
        except (TypeError, ValueError) as error:
            raise ValueError(f"Expected numeric `poses` for mechanism {self.name!r}: {error}") from None
        if poses.ndim == 0 or poses.shape[-1] != self.n_task:
            raise ValueError(
                f"Expected `poses` with shape (..., {self.n_task}) for mechanism {self.name!r} "
                f"({', '.join(self.task_coordinates)}), got {poses.shape}."
            )
        if not np.all(np.isfinite(poses)):
            bad = tuple(int(i) for i in np.argwhere(~np.isfinite(poses))[0])
            raise ValueError(f"Expected finite values in `poses`, got {poses[bad]} at index {bad}.")
        return poses

    def transforms_from_poses(self, poses: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Platform frames (rotation (..., 3, 3), translation (..., 3)) in the base frame."""
        poses = np.asarray(poses, dtype=float)
        if self.is_planar:
            rotation = rotation_about_axis(np.array([0.0, 0.0, 1.0]), poses[..., 2])
            translation = np.stack(
                [poses[..., 0], poses[..., 1], np.full(poses.shape[:-1], self._home_translation[2])], -1
            )
            return rotation, translation
        return rotation_from_rpy(poses[..., 3:]), poses[..., :3].copy()

    def poses_from_transforms(self, rotation: ArrayLike, translation: ArrayLike) -> NDArray[np.float64]:
        """Task coordinates of platform frames given in the base frame."""
        rotation = np.asarray(rotation, dtype=float)
        translation = np.asarray(translation, dtype=float)
        if self.is_planar:
            return np.stack(
                [translation[..., 0], translation[..., 1], np.arctan2(rotation[..., 1, 0], rotation[..., 0, 0])], -1
            )
        return np.concatenate([translation, rpy_from_rotation(rotation)], -1)

    # -- closure solving -------------------------------------------------------------------

    def solve(
        self,
        poses: ArrayLike,
        *,
        branches: Sequence | None = None,
        initial: Solution | Sequence[ArrayLike] | None = None,
        method: Literal["auto", "newton"] = "auto",
        tolerance: float = 1e-11,
        max_iterations: int = 40,
    ) -> Solution:
        """Close every chain for a batch of platform poses, keeping the working mode.

        Parameters
        ----------
        poses : array_like, shape (..., n_task)
            Platform poses in the task coordinates (m, rad).
        branches : sequence, optional
            Per chain working mode; default :attr:`branches` (the reference assembly). For a
            closed-form chain a tuple of +-1 signs; for a Newton chain the required sign of its
            twist-matrix determinant (None: no check). Newton continuation starts from the
            reference assembly, so another sign also needs ``initial``. With
            ``method="newton"`` closed-form chains keep the reference determinant sign.
        initial : Solution or sequence of array_like, optional
            Start values for Newton chains (per chain, broadcastable to (..., m_i)), e.g. a
            solution at nearby poses. Default: continuation from the reference assembly.
        method : {"auto", "newton"}
            ``"auto"`` uses a closed form for chains that have one; ``"newton"`` forces the
            generic solver everywhere (for checks).
        tolerance : float
            Newton convergence on the closure error norm (rad and m).
        max_iterations : int
            Newton iterations per continuation step.

        Returns
        -------
        Solution
            Unreachable chains (no assembly in the working mode) get NaN joint values and
            ``reachable`` False; solving never raises for an unreachable pose (see
            :meth:`solve_one`).
        """
        poses = self.check_poses(poses)
        if method not in ("auto", "newton"):
            raise ValueError(f"Expected `method` 'auto' or 'newton', got {method!r}.")
        branches = self._check_branches(branches)
        batch = poses.shape[:-1]
        flat = poses.reshape(-1, self.n_task)
        count = flat.shape[0]
        initial_values = self._check_initial(initial, batch)
        cache: dict = {}
        values, axes, points = [], [], []
        reachable = np.empty((len(self.chains), count), dtype=bool)
        residuals = np.empty((len(self.chains), count))
        for index, geometry in enumerate(self.geometries):
            solver = self._solvers[index] if method == "auto" else None
            if solver is not None:
                result = self._closed_form(index, solver, flat, branches[index], cache)
                chain_values, chain_reachable, chain_residual = result.values, result.reachable, result.gap
                chain_axes, chain_points = result.axes, result.points
            else:
                platform = self._platform_cache(flat, cache)
                start = None if initial_values is None else initial_values[index].reshape(count, geometry.n_dofs)
                sign = branches[index] if self._solvers[index] is None else self._reference_signs[index]
                chain_values, chain_reachable, chain_residual = self._newton_chain(
                    index, flat, platform, start, sign, tolerance, max_iterations
                )
                frames = chain_forward_kinematics(geometry, np.nan_to_num(chain_values))
                chain_axes, chain_points = frames.axes, frames.points
            values.append(chain_values if callable(chain_values) else chain_values.reshape(batch + (geometry.n_dofs,)))
            reachable[index] = chain_reachable
            residuals[index] = chain_residual
            axes.append(chain_axes.reshape(batch + chain_axes.shape[-2:]))
            points.append(chain_points.reshape(batch + chain_points.shape[-2:]))
        return Solution(
            poses=poses,
            reachable=np.logical_and.reduce(reachable, axis=0).reshape(batch),
            chain_reachable=reachable.T.reshape(batch + (len(self.chains),)),
            residuals=residuals.T.reshape(batch + (len(self.chains),)),
            joint_axes=tuple(axes),
            joint_points=tuple(points),
            value_sources=tuple(values),
        )

    def _platform_cache(self, flat_poses: NDArray, cache: dict):
        if "platform" not in cache:
            cache["platform"] = self.transforms_from_poses(flat_poses)
        return cache["platform"]

    def _closed_form(self, index: int, solver, flat_poses: NDArray, branch, cache: dict | None = None):
        """Run the closed-form solver of one chain on flat poses (N, n_task)."""
        cache = {} if cache is None else cache
        if solver.planar:
            if "planar" not in cache:
                angle = np.ascontiguousarray(flat_poses[:, 2])
                cosine, sine = np.empty_like(angle), np.empty_like(angle)

                def trigonometry(block: slice) -> None:
                    np.cos(angle[block], out=cosine[block])
                    np.sin(angle[block], out=sine[block])

                for_each_block(angle.shape[0], trigonometry)
                cache["planar"] = (
                    np.ascontiguousarray(flat_poses[:, 0]), np.ascontiguousarray(flat_poses[:, 1]), cosine, sine, angle
                )
            return solver.solve(*cache["planar"], branch)
        return solver.solve(*self._loop_targets(index, *self._platform_cache(flat_poses, cache)), branch)

    def solve_one(self, pose: ArrayLike, **options) -> Solution:
        """Solve a single pose (n_task,); raise ValueError naming the chain if unreachable."""
        pose = self.check_poses(pose)
        if pose.ndim != 1:
            raise ValueError(f"Expected one pose with shape ({self.n_task},), got {pose.shape}.")
        solution = self.solve(pose, **options)
        if not solution.reachable:
            failed = np.flatnonzero(~solution.chain_reachable)
            index = int(failed[0])
            spelled = ", ".join(f"{name}={value:.6g}" for name, value in zip(self.task_coordinates, pose))
            unit = "m" if self._solvers[index] is not None else "(Newton error norm, m and rad)"
            more = f" (and {failed.size - 1} more chain(s))" if failed.size > 1 else ""
            raise ValueError(
                f"Pose ({spelled}) is unreachable for mechanism {self.name!r}: chain {self.chains[index].name!r} "
                f"misses closure by {solution.residuals[index]:.6g} {unit}{more}."
            )
        return solution

    def _check_branches(self, branches) -> tuple:
        if branches is None:
            return self.branches
        branches = tuple(branches)
        if len(branches) != len(self.chains):
            raise ValueError(f"Expected one branch per chain ({len(self.chains)}), got {len(branches)}.")
        checked = []
        for chain, solver, branch in zip(self.chains, self._solvers, branches):
            if solver is not None:
                signs = tuple(int(sign) for sign in np.atleast_1d(branch))
                if len(signs) != solver.n_branches or any(sign not in (1, -1) for sign in signs):
                    raise ValueError(
                        f"Expected {solver.n_branches} sign(s) of +-1 as branch of chain {chain.name!r} "
                        f"({solver.kind}), got {branch!r}."
                    )
                checked.append(signs)
            else:
                if branch is not None and branch not in (1, -1):
                    raise ValueError(f"Expected +1, -1 or None as branch of Newton chain {chain.name!r}, got {branch!r}.")
                checked.append(branch)
        return tuple(checked)

    def _check_initial(self, initial, batch: tuple[int, ...]):
        if initial is None:
            return None
        if isinstance(initial, Solution):
            initial = initial.joint_values
        initial = tuple(initial)
        if len(initial) != len(self.chains):
            raise ValueError(f"Expected initial joint values for {len(self.chains)} chains, got {len(initial)}.")
        arrays = []
        for chain, values in zip(self.chains, initial):
            values = np.asarray(values, dtype=float)
            try:
                arrays.append(np.broadcast_to(values, batch + (chain.n_joints,)))
            except ValueError:
                raise ValueError(
                    f"Expected initial values of chain {chain.name!r} broadcastable to {batch + (chain.n_joints,)}, "
                    f"got {values.shape}."
                ) from None
        return arrays

    def _newton_chain(self, index, flat_poses, platform, start, branch, tolerance, max_iterations):
        """Newton closure of one chain, with continuation from the reference assembly and neighbours."""
        geometry = self.geometries[index]
        count = flat_poses.shape[0]
        targets = self._loop_targets(index, *platform)
        values = np.empty((count, geometry.n_dofs))
        converged = np.zeros(count, dtype=bool)
        residual = np.full(count, np.inf)
        given = np.zeros(count, dtype=bool) if start is None else np.all(np.isfinite(start), axis=-1)
        if np.any(given):  # Newton from the given start values
            rows = np.flatnonzero(given)
            values[rows], converged[rows], residual[rows] = newton_solve_chain(
                geometry, targets[0][rows], targets[1][rows], start[rows], tolerance, max_iterations
            )
        if not np.all(given):  # continuation from the reference assembly
            rows = np.flatnonzero(~given)
            reference = np.broadcast_to(self.reference_joint_values[index], (rows.size, geometry.n_dofs))
            home = (
                np.broadcast_to(self._home_rotation, (rows.size, 3, 3)),
                np.broadcast_to(self._home_translation, (rows.size, 3)),
            )
            goal = (platform[0][rows], platform[1][rows])
            values[rows], converged[rows], residual[rows] = self._track(
                index, home, reference, goal, tolerance, max_iterations
            )
        converged &= self._branch_kept(index, values, branch)
        scaled = self._scaled_poses(flat_poses)
        for _ in range(2):  # continuation from solved neighbours
            failed = np.flatnonzero(~converged)
            solved = np.flatnonzero(converged)
            if failed.size == 0 or solved.size == 0:
                break
            from scipy.spatial import cKDTree

            _, nearest = cKDTree(scaled[solved]).query(scaled[failed])
            neighbours = solved[nearest]
            source = (platform[0][neighbours], platform[1][neighbours])
            goal = (platform[0][failed], platform[1][failed])
            retried, retried_converged, retried_residual = self._track(
                index, source, values[neighbours], goal, tolerance, max_iterations
            )
            retried_converged &= self._branch_kept(index, retried, branch)
            better = retried_converged | (retried_residual < residual[failed])
            values[failed[better]] = retried[better]
            residual[failed[better]] = retried_residual[better]
            converged[failed] = retried_converged
        values = wrap_revolute_values(geometry, values)
        values[~converged] = np.nan
        return values, converged, residual

    def _scaled_poses(self, flat_poses: NDArray) -> NDArray:
        scaled = flat_poses.copy()
        angular = slice(2, 3) if self.is_planar else slice(3, 6)
        scaled[:, angular] *= self.length_scale
        return scaled

    def _branch_kept(self, index: int, values: NDArray, branch) -> NDArray[np.bool_]:
        if branch is None:
            return np.ones(values.shape[0], dtype=bool)
        frames = chain_forward_kinematics(self.geometries[index], np.nan_to_num(values))
        sign = self._determinant_sign(index, frames.axes, frames.points)
        return sign == branch

    def _track(self, index, source, values, goal, tolerance, max_iterations):
        """Follow straight platform paths (geodesic in rotation) from ``source`` to ``goal`` poses."""
        geometry = self.geometries[index]
        source_rotation, source_translation = source
        goal_rotation, goal_translation = goal
        rotation_step = rotation_vector_from_rotation(np.swapaxes(source_rotation, -1, -2) @ goal_rotation)
        translation_step = goal_translation - source_translation
        distance = np.maximum(
            np.linalg.norm(translation_step, axis=-1) / self.length_scale, np.linalg.norm(rotation_step, axis=-1)
        )
        steps = int(min(64, max(1, math.ceil(float(np.max(distance, initial=0.0)) / 0.1))))
        values = np.array(values, dtype=float, copy=True)
        for step in range(1, steps + 1):
            fraction = step / steps
            rotation = source_rotation @ rotation_from_rotation_vector(fraction * rotation_step)
            translation = source_translation + fraction * translation_step
            targets = self._loop_targets(index, rotation, translation)
            last = step == steps
            values, converged, residual = newton_solve_chain(
                geometry, *targets, values, tolerance if last else 1e-8, max_iterations if last else 12
            )
            values = np.where(np.isfinite(values), values, 0.0)
        return values, converged, residual

    # -- screws ----------------------------------------------------------------------------

    def chain_screws(
        self,
        solution: Solution,
        *,
        frame: Literal["world", "base"] = "world",
        unreachable: Literal["raise", "drop", "reference"] = "raise",
    ) -> list[ChainScrews]:
        """Joint screws of every chain at solved configurations, one ChainScrews per chain.

        Parameters
        ----------
        solution : Solution
            From :meth:`solve` or :meth:`forward`.
        frame : {"world", "base"}
            Express twists and points in the world frame (URDF root) or the base link frame.
        unreachable : {"raise", "drop", "reference"}
            What to do with configurations where not all chains closed: raise a ValueError,
            drop them (the batch becomes 1-D over the reachable configurations, in C order of
            ``solution.reachable``), or fill them with the reference assembly's screws (finite
            placeholders: mask the results with ``solution.reachable``).
        """
        if frame not in ("world", "base"):
            raise ValueError(f"Expected `frame` 'world' or 'base', got {frame!r}.")
        if unreachable not in ("raise", "drop", "reference"):
            raise ValueError(f"Expected `unreachable` 'raise', 'drop' or 'reference', got {unreachable!r}.")
        mask = np.asarray(solution.reachable)
        all_reachable = bool(np.all(mask))
        if unreachable == "raise" and not all_reachable:
            first = tuple(int(i) for i in np.argwhere(~mask)[0]) if mask.ndim else ()
            raise ValueError(
                f"{int(np.sum(~mask))} of {mask.size} configurations are unreachable (first at index {first}); "
                "pass unreachable='drop' or 'reference' to chain_screws, or mask the poses."
            )

        # Every chain's twists and points go into one component-major block (6 or 3, J, batch),
        # chain after chain along the joint axis, which analyze() then reads in place.
        batch = (int(mask.sum()),) if not all_reachable and unreachable == "drop" else mask.shape
        starts = np.cumsum([0] + [chain.n_joints for chain in self.chains])
        twist_block = np.zeros((6, starts[-1]) + batch)
        point_block = np.empty((3, starts[-1]) + batch)

        def screws_of_chain(index: int) -> ChainScrews:
            axes, points = solution.joint_axes[index], solution.joint_points[index]
            if not all_reachable and unreachable == "drop":
                axes, points = axes[mask], points[mask]
            elif not all_reachable:
                frames = self._reference_frames[index]
                axes = np.where(mask[..., None, None], axes, frames.axes)
                points = np.where(mask[..., None, None], points, frames.points)
            joints = slice(starts[index], starts[index + 1])
            return self._chain_screws_from_frames(index, axes, points, frame, twist_block[:, joints],
                                                  point_block[:, joints])

        threads = min(len(self.chains), block_threads())
        if mask.size >= 1 << 16 and threads > 1:  # chains in parallel (numpy releases the GIL)
            with ThreadPoolExecutor(threads) as pool:
                return list(pool.map(screws_of_chain, range(len(self.chains))))
        return [screws_of_chain(index) for index in range(len(self.chains))]

    def joint_screws(self, joint_values: Sequence[ArrayLike], *, frame: Literal["world", "base"] = "world") -> list[ChainScrews]:
        """Joint screws at arbitrary joint values (forward kinematics only, no closure).

        ``joint_values`` holds one array (..., m_i) per chain.
        """
        joint_values = tuple(joint_values)
        if len(joint_values) != len(self.chains):
            raise ValueError(f"Expected joint values for {len(self.chains)} chains, got {len(joint_values)}.")
        screws = []
        for index, values in enumerate(joint_values):
            frames = chain_forward_kinematics(self.geometries[index], values)
            screws.append(self._chain_screws_from_frames(index, frames.axes, frames.points, frame))
        return screws

    def _chain_screws_from_frames(self, index: int, axes: NDArray, points: NDArray, frame: str,
                                  twist_block: NDArray | None = None, point_block: NDArray | None = None) -> ChainScrews:
        """Screws of one chain; ``twist_block`` (zeroed) and ``point_block``, (6 or 3, m, ...), receive them."""
        chain = self.chains[index]
        if frame == "world" and not self._base_is_world:
            axes, points = transform_axes_and_points(self.rotation_world_base, self.translation_world_base, axes, points)
        twists = twists_from_axes_and_points(axes, points, chain.prismatic, out=twist_block)
        if point_block is not None:
            point_block[...] = np.moveaxis(points, (-1, -2), (0, 1))
            points = np.moveaxis(point_block, (0, 1), (-1, -2))
        return ChainScrews(twists, points, chain.actuated, chain.name)

    def closure_residuals(self, solution: Solution) -> NDArray[np.float64]:
        """Loop-closure error norm (rad and m) of every chain, recomputed by forward kinematics.

        Returns an array (..., n_chains); NaN where the chain is unreachable.
        """
        rotation, translation = self.transforms_from_poses(solution.poses)
        residuals = []
        for index, geometry in enumerate(self.geometries):
            frames = chain_forward_kinematics(geometry, solution.joint_values[index])
            target_rotation, target_translation = self._loop_targets(index, rotation, translation)
            rotation_error = rotation_vector_from_rotation(target_rotation @ np.swapaxes(frames.end_rotation, -1, -2))
            residuals.append(
                np.sqrt(
                    np.sum(rotation_error**2, -1) + np.sum((target_translation - frames.end_translation) ** 2, -1)
                )
            )
        return np.stack(residuals, -1)

    # -- forward kinematics of the closed mechanism ----------------------------------------

    def forward(
        self,
        actuator_values: ArrayLike,
        initial_pose: ArrayLike,
        *,
        actuators: Sequence[int | tuple[str, str]] | None = None,
        tolerance: float = 1e-12,
        max_iterations: int = 30,
        step: float = 1e-6,
    ) -> Solution:
        """Platform poses for given actuator values (forward kinematics), by damped Newton.

        Only the listed ``actuators`` are held at ``actuator_values``; all others move freely
        (they act as passive joints). With as many listed actuators as DOF this is the forward
        kinematics of a non-redundant submechanism; lock all but one and drive that one to get
        output twists by finite differences.

        Parameters
        ----------
        actuator_values : array_like, shape (..., k)
            Values of the listed actuators (rad or m).
        initial_pose : array_like, shape (..., n_task)
            Start pose (the result stays on the assembly branch reachable from it).
        actuators : sequence, optional
            Indices into :attr:`actuators` or ``(chain, joint)`` names; default all.
        tolerance : float
            Convergence on the largest actuator mismatch.
        step : float
            Central-difference step (m, rad) for the Jacobian d(actuators)/d(pose).

        Returns
        -------
        Solution
            At the poses found; ``reachable`` is False where Newton did not converge.
        """
        selected = self._actuator_indices(actuators)
        targets = np.asarray(actuator_values, dtype=float)
        if targets.shape[-1:] != (len(selected),):
            raise ValueError(f"Expected `actuator_values` with shape (..., {len(selected)}), got {targets.shape}.")
        poses = self.check_poses(initial_pose)
        batch = np.broadcast_shapes(targets.shape[:-1], poses.shape[:-1])
        targets = np.broadcast_to(targets, batch + (len(selected),)).reshape(-1, len(selected))
        poses = np.array(np.broadcast_to(poses, batch + (self.n_task,)).reshape(-1, self.n_task))
        angular = np.array([not self.chains[chain].prismatic[joint] for chain, joint in selected])
        converged = np.zeros(poses.shape[0], dtype=bool)
        active = np.arange(poses.shape[0])
        previous = None

        def mismatch(at_poses, initial):
            solution = self.solve(at_poses, initial=initial, tolerance=1e-13)
            values = np.stack([solution.joint_values[chain][..., joint] for chain, joint in selected], -1)
            return values, solution

        for _ in range(max_iterations):
            if active.size == 0:
                break
            values, solution = mismatch(poses[active], previous)
            error = values - targets[active]
            error[:, angular] = wrap_angle(error[:, angular])
            done = np.all(np.abs(error) < tolerance, axis=-1)
            converged[active[done]] = True
            keep = ~done & np.all(np.isfinite(error), axis=-1)
            active, error = active[keep], error[keep]
            previous = [values_[keep] for values_ in solution.joint_values]
            if active.size == 0:
                break
            jacobian = np.empty((active.size, len(selected), self.n_task))
            for coordinate in range(self.n_task):
                offset = np.zeros(self.n_task)
                offset[coordinate] = step
                plus, _ = mismatch(poses[active] + offset, previous)
                minus, _ = mismatch(poses[active] - offset, previous)
                difference = plus - minus
                difference[:, angular] = wrap_angle(difference[:, angular])
                jacobian[:, :, coordinate] = difference / (2.0 * step)
            update = -np.linalg.pinv(jacobian) @ error[..., None]
            update = update[..., 0]
            largest = np.max(np.abs(update), axis=-1)
            update *= np.minimum(1.0, 0.2 * self.length_scale / np.maximum(largest, 1e-300))[:, None]
            usable = np.all(np.isfinite(update), axis=-1)
            poses[active[usable]] += update[usable]
        solution = self.solve(poses.reshape(batch + (self.n_task,)), tolerance=1e-13)
        converged = converged.reshape(batch)
        return Solution(
            poses=solution.poses,
            reachable=solution.reachable & converged,
            chain_reachable=solution.chain_reachable & converged[..., None],
            residuals=solution.residuals,
            joint_axes=solution.joint_axes,
            joint_points=solution.joint_points,
            value_sources=solution.joint_values,
        )

    def actuator_values(self, joint_values: Sequence[ArrayLike]) -> NDArray[np.float64]:
        """Values (..., n_actuators) of all actuators, in :attr:`actuators` order.

        ``joint_values`` holds one array (..., m_i) per chain, e.g. ``solution.joint_values``.
        """
        joint_values = tuple(joint_values)
        return np.stack(
            [np.asarray(joint_values[chain])[..., joint] for chain, joint in self._actuator_indices(None)], -1
        )

    def _actuator_indices(self, actuators) -> list[tuple[int, int]]:
        if actuators is None:
            actuators = range(len(self.actuators))
        selected = []
        for actuator in actuators:
            if isinstance(actuator, (int, np.integer)):
                if not 0 <= actuator < len(self.actuators):
                    raise ValueError(f"Expected actuator indices in 0..{len(self.actuators) - 1}, got {actuator}.")
                chain_name, joint_name = self.actuators[actuator]
            else:
                chain_name, joint_name = actuator
                if (chain_name, joint_name) not in self.actuators:
                    raise ValueError(f"Unknown actuator {actuator!r}; actuators are {self.actuators}.")
            chain_index = [chain.name for chain in self.chains].index(chain_name)
            selected.append((chain_index, self.chains[chain_index].joint_names.index(joint_name)))
        return selected

    # -- Pinocchio configuration -----------------------------------------------------------

    def configuration_vector(
        self, joint_values: Sequence[ArrayLike], poses: ArrayLike | None = None
    ) -> NDArray[np.float64]:
        """Pinocchio configuration vectors q (..., nq) of the tree.

        Parameters
        ----------
        joint_values : sequence of array_like
            Per chain, values (..., m_i) (e.g. ``solution.joint_values``); the tree joints take
            them (loop-joint values are not part of the tree).
        poses : array_like, shape (..., n_task), optional
            Platform poses for the platform joint (e.g. ``solution.poses``); default the home pose.
            Joints outside every chain keep their reference values.
        """
        import pinocchio

        model = self.model
        joint_values = [np.asarray(values, dtype=float) for values in joint_values]
        poses = self.home_pose if poses is None else self.check_poses(poses)
        batch = np.broadcast_shapes(poses.shape[:-1], *(values.shape[:-1] for values in joint_values))
        reference = pinocchio.neutral(model)
        for name, value in self.description.reference_configuration.items():
            self._set_joint(reference, model.joints[model.getJointId(name)], np.asarray(value))
        configuration = np.array(np.broadcast_to(reference, batch + (model.nq,)))
        for index, joint_ids in enumerate(self._tree_joint_ids):
            for position, joint_id in enumerate(joint_ids):
                self._set_joint(configuration, model.joints[joint_id], joint_values[index][..., position])
        rotation, translation = self.transforms_from_poses(np.broadcast_to(poses, batch + (self.n_task,)))
        world_rotation = self.rotation_world_base @ rotation
        world_translation = self.translation_world_base + translation @ self.rotation_world_base.T
        frame_inverse = self._platform_frame_placement.inverse()
        joint_rotation = world_rotation @ np.array(frame_inverse.rotation)
        joint_translation = world_translation + world_rotation @ np.array(frame_inverse.translation)
        placement = model.jointPlacements[self._platform_joint_id]
        local_rotation = np.array(placement.rotation).T @ joint_rotation
        local_translation = (joint_translation - np.array(placement.translation)) @ np.array(placement.rotation)
        start = model.joints[self._platform_joint_id].idx_q
        if self.is_planar:
            angle = np.arctan2(local_rotation[..., 1, 0], local_rotation[..., 0, 0])
            configuration[..., start : start + 4] = np.stack(
                [local_translation[..., 0], local_translation[..., 1], np.cos(angle), np.sin(angle)], -1
            )
        else:
            configuration[..., start : start + 3] = local_translation
            configuration[..., start + 3 : start + 7] = _quaternion_from_rotation(local_rotation)
        return configuration

    @staticmethod
    def _set_joint(configuration: NDArray, joint, value: NDArray) -> None:
        if joint.nq == 2:  # continuous joint stored as (cos, sin)
            configuration[..., joint.idx_q] = np.cos(value)
            configuration[..., joint.idx_q + 1] = np.sin(value)
        else:
            configuration[..., joint.idx_q] = value

    def __repr__(self) -> str:
        return (
            f"Mechanism(name={self.name!r}, dof={self.dof}, chains={len(self.chains)}, "
            f"actuators={len(self.actuators)}, task_coordinates={self.task_coordinates})"
        )


def _quaternion_from_rotation(rotation: NDArray) -> NDArray[np.float64]:
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


def _tidy(value: float) -> str:
    """A number for messages: 6 significant digits, round-off below 1e-12 shown as 0."""
    value = float(value)
    return "0" if abs(value) < 1e-12 else f"{value:.6g}"
