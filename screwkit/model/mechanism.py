"""The mechanism model: an immutable record of a closed-loop mechanism and its platform poses.

A :class:`Mechanism` holds what a file describes (the chains, their joints and actuators, the
platform joint, the reference assembly, named poses) and what was derived from it once when it
was loaded (each chain's closure solver and working mode, the platform's DOF). It never
changes: closure solving (:mod:`screwkit.closure`), screws and indices are functions of a
mechanism and of configurations, as Pinocchio's algorithms are of its ``Model``.
Build one with :func:`screwkit.io.loader.load`.

Frames and coordinates: a **full pose** is the platform frame relative to the **base link** frame
(the parent link of the platform's floating/planar joint) in the pose coordinates
(:data:`PLANAR_TASK_COORDINATES`, :data:`SPATIAL_TASK_COORDINATES`). A mechanism of lower mobility
is driven through its **task coordinates**, the independent subset of them (z, roll, pitch for a
3-PRS; x, y, z for a Delta); the others are *dependent* (parasitic) and follow from the closure.
Every pose a user gives is in task coordinates; metres and radians.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.common.rotations import rotation_about_axis, rotation_from_rpy, rpy_from_rotation
from screwkit.common.units import angle_beyond_limit, angle_limit, is_angular
from screwkit.model.chain import Chain, ChainGeometry
from screwkit.model.urdf_description import UrdfDescription

__all__ = ["Mechanism", "require_mechanism", "PLANAR_TASK_COORDINATES", "SPATIAL_TASK_COORDINATES",
           "PINOCCHIO_TREE"]

PLANAR_TASK_COORDINATES = ("x", "y", "phi")
"""Task coordinates of a planar mechanism: platform position in the base x-y plane (m) and
its rotation about the base z axis (rad)."""
SPATIAL_TASK_COORDINATES = ("x", "y", "z", "roll", "pitch", "yaw")
"""Task coordinates of a spatial mechanism: platform position (m) and orientation
``R = Rz(yaw) Ry(pitch) Rx(roll)`` (rad, fixed axes, the URDF ``rpy`` convention)."""
PINOCCHIO_TREE = ("pinocchio_model", "platform_frame_placement")
"""The attributes of a :class:`Mechanism` that are Pinocchio objects (left out of its stored state)."""


@dataclass(frozen=True, repr=False, eq=False)
class Mechanism:
    """A redundantly actuated closed-loop mechanism (immutable).

    Attributes
    ----------
    name : str
        The robot's name (the file name when the file names none).
    path : str
        The file it was read from.
    description : UrdfDescription
        What the file says (the safe XML pass), lengths in metres.
    pinocchio_model : pinocchio.Model
        The kinematic tree (loops are not part of it).
    is_planar : bool
        The platform hangs from a ``planar`` joint (else ``floating``).
    pose_coordinates : tuple of str
        :data:`PLANAR_TASK_COORDINATES` or :data:`SPATIAL_TASK_COORDINATES`: every coordinate of a
        full pose.
    base_link, platform_link, platform_joint : str
        The links the platform joint connects, and its name.
    platform_joint_id : int
        Pinocchio id of the platform joint.
    platform_frame_placement : pinocchio.SE3
        Placement of the platform link's frame in the platform joint's frame.
    rotation_world_base, translation_world_base : ndarray, shapes (3, 3) and (3,)
        Placement of the base link frame in the world frame (the URDF root).
    home_rotation, home_translation : ndarray, shapes (3, 3) and (3,)
        The platform frame in the base frame at the reference assembly.
    chains : tuple of Chain
        Ordered by name in natural order (``leg_2`` before ``leg_10``), whatever the order of the
        ``<loop>`` elements (:func:`screwkit.model.builder.chain_order`).
    dof : int
        Mobility of the platform at the reference assembly (dimension of the intersection of
        the chains' twist spaces).
    length_scale : float
        A characteristic length of the mechanism (m): the largest distance of a joint of the
        reference assembly, or of the platform's origin, from the centroid of the chains' base joints
        (the same wherever the file draws the mechanism in its base frame, and in any order of its
        chains). Used for step sizes of continuation, closure tolerances, weighing angles against
        lengths along a path, and judging point coincidences relative to the mechanism's size.
    named_poses : dict of str to ndarray
        Documented poses (task coordinates, m and rad): ``home`` (the reference assembly) and
        those of the file's ``<named_pose>`` elements.
    length_unit : str
        The unit the file was written in (converted to metres when read).
    task_axes : tuple of int
        Indices into :attr:`pose_coordinates` of the task coordinates (empty: all of them).
    task_source : str
        Where the task coordinates come from: ``"all"`` (full mobility), ``"declared"`` (the
        file's ``<task_coordinates>``) or ``"inferred"`` (from the motion space at the
        reference assembly).
    output_point : ndarray, shape (3,) or None
        A point output: the point of the platform link (platform frame, m) whose motion is the
        mechanism's output (``<output type="point">``); None for the platform frame.
    instantaneous_dof : int
        Dimension of the platform's motion space at the reference assembly; larger than
        :attr:`dof` when the reference assembly is a constraint singularity.
    held_axes : tuple of int
        Indices into :attr:`pose_coordinates` of dependent coordinates held at their reference-assembly values
        instead of solved: the orientation, when the operation mode followed from a constraint-singular reference
        assembly does not turn the platform (:mod:`screwkit.closure.modes`; on the set where the modes meet the
        closure is a double root, which a solve leaves a few 1e-6 rad off into the other mode).
    assembly_notes : tuple of str
        The loops the file's joint values left open and how far each was (closed at loading).
    import_report : tuple of str
        For a file of another tool (MJCF, URDF + robot.yaml): what the conversion did, line by line
        (platform body, output point or frame and why, loops assembled, joints locked).

    A mechanism read back from the cache of loaded mechanisms (:meth:`from_stored_state`) builds
    :attr:`pinocchio_model` and :attr:`platform_frame_placement` from its description's text when they are
    first used: computing indices needs neither, so such a load does not import Pinocchio.
    """

    name: str
    path: str
    description: UrdfDescription = field(repr=False)
    pinocchio_model: Any = field(repr=False)
    is_planar: bool
    pose_coordinates: tuple[str, ...]
    base_link: str
    platform_link: str
    platform_joint: str
    platform_joint_id: int
    platform_frame_placement: Any = field(repr=False)
    rotation_world_base: NDArray[np.float64] = field(repr=False)
    translation_world_base: NDArray[np.float64] = field(repr=False)
    home_rotation: NDArray[np.float64] = field(repr=False)
    home_translation: NDArray[np.float64] = field(repr=False)
    chains: tuple[Chain, ...]
    dof: int
    length_scale: float
    named_poses: dict[str, NDArray[np.float64]] = field(repr=False)
    length_unit: str = "m"
    task_axes: tuple[int, ...] = ()
    task_source: str = "all"
    output_point: NDArray[np.float64] | None = field(default=None, repr=False)
    instantaneous_dof: int = 0
    held_axes: tuple[int, ...] = ()
    assembly_notes: tuple[str, ...] = ()
    import_report: tuple[str, ...] = ()

    # -- stored state (the cache of loaded mechanisms) ---------------------------------------

    def stored_state(self) -> dict[str, Any]:
        """Every attribute but the Pinocchio tree (:data:`PINOCCHIO_TREE`), to be pickled: numbers, names and
        screwkit's own records only, so that reading it back imports neither Pinocchio nor the file's parser."""
        return {name: value for name, value in vars(self).items() if name not in PINOCCHIO_TREE}

    @classmethod
    def from_stored_state(cls, state: dict[str, Any]) -> Mechanism:
        """The mechanism of a :meth:`stored_state`; its Pinocchio tree is built from the description when first
        used."""
        mechanism = object.__new__(cls)
        vars(mechanism).update(state)
        return mechanism

    def __getattr__(self, name: str) -> Any:
        # called only for an attribute that is not set: the Pinocchio tree of a mechanism from a stored state
        if name in PINOCCHIO_TREE and "description" in vars(self) and "platform_link" in vars(self):
            from screwkit.model.pinocchio_bridge import body_frame, build_model  # Pinocchio: only when asked for

            description = self.description
            model = build_model(description.text, lambda problem: description.fail(f"<robot name='{self.name}'>",
                                                                                   problem))
            object.__setattr__(self, "pinocchio_model", model)
            object.__setattr__(self, "platform_frame_placement", body_frame(model, self.platform_link).placement)
            return vars(self)[name]
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    # -- derived -------------------------------------------------------------------------

    @property
    def task_coordinates(self) -> tuple[str, ...]:
        """The independent coordinates a pose is given in (every pose coordinate at full mobility)."""
        return tuple(self.pose_coordinates[i] for i in self.task_indices)

    @property
    def task_indices(self) -> tuple[int, ...]:
        """Indices into :attr:`pose_coordinates` of the task coordinates."""
        return self.task_axes if self.task_axes else tuple(range(len(self.pose_coordinates)))

    @property
    def dependent_indices(self) -> tuple[int, ...]:
        """Indices into :attr:`pose_coordinates` of the dependent (parasitic) coordinates."""
        return tuple(i for i in range(len(self.pose_coordinates)) if i not in self.task_indices)

    @property
    def n_task(self) -> int:
        """Number of task coordinates."""
        return len(self.task_indices)

    @property
    def n_pose(self) -> int:
        """Number of pose coordinates (3 planar, 6 spatial)."""
        return len(self.pose_coordinates)

    @property
    def home_full_pose(self) -> NDArray[np.float64]:
        """Every pose coordinate of the reference assembly."""
        return self.poses_from_transforms(self.home_rotation, self.home_translation)

    def full_poses(self, task_poses: ArrayLike, dependent: ArrayLike | None = None) -> NDArray[np.float64]:
        """Full poses (..., n_pose) from task poses (..., n_task) and dependent values (default: home's)."""
        task_poses = np.asarray(task_poses, dtype=float)
        full = np.array(np.broadcast_to(self.home_full_pose, task_poses.shape[:-1] + (self.n_pose,)))
        full[..., list(self.task_indices)] = task_poses
        if dependent is not None and self.dependent_indices:
            full[..., list(self.dependent_indices)] = dependent
        return full

    def task_poses(self, full_poses: ArrayLike) -> NDArray[np.float64]:
        """The task coordinates (..., n_task) of full poses (..., n_pose)."""
        return np.asarray(full_poses, dtype=float)[..., list(self.task_indices)]

    @property
    def home_pose(self) -> NDArray[np.float64]:
        """Task coordinates of the reference assembly (a copy)."""
        return np.array(self.named_poses["home"], dtype=float)

    @property
    def actuators(self) -> tuple[tuple[str, str], ...]:
        """``(chain name, joint name)`` of every actuated joint, in chain order: the set A."""
        return tuple((chain.name, chain.joint_names[index]) for chain in self.chains for index in chain.actuated)

    @property
    def actuator_names(self) -> tuple[str, ...]:
        """Every actuator as ``chain:joint``, in :attr:`actuators` order."""
        return tuple(f"{chain}:{joint}" for chain, joint in self.actuators)

    @property
    def geometries(self) -> tuple[ChainGeometry, ...]:
        """Each chain's constant geometry (base frame)."""
        return tuple(chain.geometry for chain in self.chains)

    @property
    def base_is_world(self) -> bool:
        """Whether the base link frame is the world frame."""
        return bool(np.array_equal(self.rotation_world_base, np.eye(3)) and not np.any(self.translation_world_base))

    @property
    def angular(self) -> NDArray[np.bool_]:
        """Which task coordinates are angles (phi, roll, pitch, yaw)."""
        return np.array([is_angular(name) for name in self.task_coordinates])

    @property
    def pose_angular(self) -> NDArray[np.bool_]:
        """Which pose coordinates are angles."""
        return np.array([is_angular(name) for name in self.pose_coordinates])

    def __repr__(self) -> str:
        return (f"Mechanism(name={self.name!r}, dof={self.dof}, chains={len(self.chains)}, "
                f"actuators={len(self.actuators)}, task_coordinates={self.task_coordinates})")

    # -- poses ---------------------------------------------------------------------------

    def check_poses(self, poses: ArrayLike, *, degrees: bool = False, where: str = "`poses`") -> NDArray[np.float64]:
        """Poses as a float array (..., n_task) of finite real values, angles within
        :func:`~screwkit.common.units.angle_limit` (in degrees if ``degrees``) and positions within
        :data:`MAX_REACH_SCALES` length scales of the home pose, or a ValueError naming ``where`` they came from and
        what arrived (:func:`checked_task_poses`)."""
        return checked_task_poses(self, poses, degrees=degrees, where=where)

    def named_pose(self, name: str) -> NDArray[np.float64]:
        """A documented pose by name (m, rad); a ValueError lists the names."""
        if name not in self.named_poses:
            raise ValueError(f"Unknown pose {name!r} of mechanism {self.name!r}; named poses are "
                             f"{', '.join(self.named_poses)}.")
        return np.array(self.named_poses[name], dtype=float)

    def poses_from_degrees(self, values: ArrayLike, where: str = "`poses`") -> NDArray[np.float64]:
        """Task coordinates with angles in degrees -> radians (checked; ``where``: what held them)."""
        poses = self.check_poses(values, degrees=True, where=where).copy()
        poses[..., self.angular] = np.deg2rad(poses[..., self.angular])
        return poses

    def transforms_from_poses(self, poses: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Platform frames (rotation (..., 3, 3), translation (..., 3)) in the base frame, of full poses
        (..., n_pose)."""
        poses = np.asarray(poses, dtype=float)
        if self.is_planar:
            rotation = rotation_about_axis(np.array([0.0, 0.0, 1.0]), poses[..., 2])
            translation = np.stack(
                [poses[..., 0], poses[..., 1], np.full(poses.shape[:-1], self.home_translation[2])], -1
            )
            return rotation, translation
        return rotation_from_rpy(poses[..., 3:]), poses[..., :3].copy()

    def output_positions(self, poses: ArrayLike) -> NDArray[np.float64] | None:
        """Where the point output is (..., 3), in the base frame, at full poses (..., n_pose); None for a frame
        output."""
        if self.output_point is None:
            return None
        rotation, translation = self.transforms_from_poses(poses)
        return translation + rotation @ self.output_point

    def poses_from_transforms(self, rotation: ArrayLike, translation: ArrayLike) -> NDArray[np.float64]:
        """Full poses (pose coordinates) of platform frames given in the base frame."""
        rotation = np.asarray(rotation, dtype=float)
        translation = np.asarray(translation, dtype=float)
        if self.is_planar:
            return np.stack(
                [translation[..., 0], translation[..., 1], np.arctan2(rotation[..., 1, 0], rotation[..., 0, 0])], -1
            )
        return np.concatenate([translation, rpy_from_rotation(rotation)], -1)

    def loop_targets(self, index: int, platform_rotation: NDArray, platform_translation: NDArray):
        """The platform-side loop frame of chain ``index`` (base frame) for platform frames (..., 3, 3), (..., 3)."""
        geometry = self.chains[index].geometry
        return (
            platform_rotation @ geometry.platform_loop_rotation,
            platform_translation + platform_rotation @ geometry.platform_loop_translation,
        )

    # -- actuators -----------------------------------------------------------------------

    def actuator_positions(self, actuators=None) -> list[tuple[int, int]]:
        """``(chain index, joint index)`` of actuators given by index into :attr:`actuators`,
        ``(chain, joint)`` names or ``chain:joint`` names (default: all)."""
        if actuators is None:
            actuators = range(len(self.actuators))
        chain_names = [chain.name for chain in self.chains]
        selected = []
        for actuator in actuators:
            if isinstance(actuator, (int, np.integer)):
                if not 0 <= actuator < len(self.actuators):
                    raise ValueError(f"Expected actuator indices in 0..{len(self.actuators) - 1}, got {actuator}.")
                chain_name, joint_name = self.actuators[actuator]
            else:
                try:
                    chain_name, joint_name = actuator.split(":", 1) if isinstance(actuator, str) else actuator
                except (TypeError, ValueError):  # not a chain:joint name nor a (chain, joint) pair
                    chain_name, joint_name = None, None
                if (chain_name, joint_name) not in self.actuators:
                    raise ValueError(f"Unknown actuator {actuator!r}; actuators are {', '.join(self.actuator_names)}.")
            chain_index = chain_names.index(chain_name)
            selected.append((chain_index, self.chains[chain_index].joint_names.index(joint_name)))
        return selected


def require_mechanism(mechanism: Any, function: str) -> None:
    """A TypeError naming what arrived where a :class:`Mechanism` is expected (a name: load it first)."""
    if isinstance(mechanism, Mechanism):
        return
    if isinstance(mechanism, str):
        raise TypeError(f"{function} expects a Mechanism, got the name {mechanism!r}: load it first, "
                        f"mechanism = screwkit.io.loader.load({mechanism!r}).")
    raise TypeError(f"{function} expects a Mechanism (from screwkit.io.loader.load), got {type(mechanism).__name__} "
                    f"{mechanism!r:.60}.")


MAX_REACH_SCALES = 1e6
"""Farthest a pose's position may be from the mechanism's home pose, in its length scales (a million: 500 km for a
5-RRR of 0.5 m). No robot reaches so far, whereas beyond about 1e150 m the closures' squares overflow and their
answers (a slide's length, a miss by NaN m) would mean nothing; such a pose is refused as an angle beyond
:data:`~screwkit.common.units.MAX_ANGLE_TURNS` is. The bound follows the mechanism, not the world frame or the
length unit of its file."""


def checked_task_poses(mechanism, poses: ArrayLike, *, degrees: bool = False, where: str = "`poses`"
                       ) -> NDArray[np.float64]:
    """``mechanism``'s poses (..., n_task) as a float array of finite real values, angles within
    :func:`~screwkit.common.units.angle_limit` (in degrees if ``degrees``) and positions within
    :data:`MAX_REACH_SCALES` length scales of its home pose, or a ValueError naming ``where`` they came from (an
    argument, an option) and what arrived. For :class:`Mechanism` and the closed-loop graphs alike."""
    name, n_task, coordinates = mechanism.name, mechanism.n_task, tuple(mechanism.task_coordinates)
    try:
        given = np.asarray(poses)
        if given.dtype.kind in "bc":  # float() would take True as 1 and drop an imaginary part
            kind = "boolean" if given.dtype.kind == "b" else "complex"
            raise ValueError(f"expected real numbers (m, {'deg' if degrees else 'rad'}), got {kind} values "
                             f"({given.dtype})")
        poses = given.astype(float)
    except (TypeError, ValueError) as error:
        raise ValueError(f"Expected numeric {where} for mechanism {name!r}: {error}") from None
    if poses.ndim == 0 or poses.shape[-1] != n_task:
        raise ValueError(f"Expected {where} with shape (..., {n_task}) for mechanism {name!r} "
                         f"({', '.join(coordinates)}), got {poses.shape}.")
    if not np.all(np.isfinite(poses)):
        bad = tuple(int(i) for i in np.argwhere(~np.isfinite(poses))[0])
        raise ValueError(f"Expected finite values in {where}, got {poses[bad]} at index {bad}.")
    angular = np.array([is_angular(coordinate) for coordinate in coordinates], dtype=bool)
    angles = poses[..., angular]
    beyond = np.abs(angles) > angle_limit(degrees=degrees)
    if np.any(beyond):
        coordinate = np.array(coordinates)[angular][np.argwhere(beyond)[0][-1]]
        raise angle_beyond_limit(f"{where} ({coordinate})", float(angles[beyond][0]), degrees=degrees)
    reach = MAX_REACH_SCALES * float(mechanism.length_scale)
    offsets = poses[..., ~angular] - np.asarray(mechanism.home_pose, dtype=float)[~angular]
    far = np.abs(offsets) > reach
    if np.any(far):
        at = tuple(int(i) for i in np.argwhere(far)[0])
        coordinate = np.array(coordinates)[~angular][at[-1]]
        sample = "" if len(at) == 1 else f", sample {at[0]}" if len(at) == 2 else f", index {at[:-1]}"
        raise ValueError(f"Expected positions within {MAX_REACH_SCALES:g} length scales ({reach:g} m) of the home "
                         f"pose of mechanism {name!r} in {where} ({coordinate}{sample}), got "
                         f"{poses[..., ~angular][at]:g} m.")
    return poses
