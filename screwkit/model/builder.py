"""From a file's description and its Pinocchio tree to the parts of a mechanism model.

:func:`read_platform` finds the platform joint and the base; :func:`read_chains` finds every
chain (the serial path of tree joints from the base to a ``<loop>`` joint that closes it onto
the platform) with its constant geometry in the base frame, its joint limits and its
actuators (``<transmission>``). Every problem is a one-line ValueError naming the file, the
element and what was expected. Nothing here solves a closure: see :mod:`screwkit.closure`.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from screwkit.model.chain import LOOP_JOINT_DOFS, Chain, ChainGeometry
from screwkit.model.mechanism import PLANAR_TASK_COORDINATES, SPATIAL_TASK_COORDINATES
from screwkit.model.pinocchio_bridge import (
    body_frame,
    joint_axis_local,
    neutral_with_jacobians,
    placement_arrays,
)
from screwkit.model.urdf_description import PLATFORM_JOINT_TYPES, UrdfDescription

__all__ = ["Platform", "read_platform", "read_chains", "chain_order"]


@dataclass(frozen=True)
class Platform:
    """The platform joint and where the platform sits at the reference assembly.

    Attributes mirror :class:`~screwkit.model.mechanism.Mechanism`'s of the same names.
    """

    name: str
    is_planar: bool
    pose_coordinates: tuple[str, ...]
    base_link: str
    platform_link: str
    platform_joint: str
    platform_joint_id: int
    platform_frame_placement: object
    rotation_world_base: NDArray[np.float64]
    translation_world_base: NDArray[np.float64]
    home_rotation: NDArray[np.float64]
    home_translation: NDArray[np.float64]

    def base_relative(self, placement) -> tuple[NDArray, NDArray]:
        """A world placement (pinocchio.SE3) expressed in the base frame."""
        rotation, translation = placement_arrays(placement)
        return (self.rotation_world_base.T @ rotation,
                self.rotation_world_base.T @ (translation - self.translation_world_base))


def read_platform(description: UrdfDescription, model, name: str) -> Platform:
    """The platform joint (exactly one ``floating`` or ``planar`` joint, hanging from a link fixed to the world)."""
    candidates = [joint for joint in description.joints.values() if joint.type in PLATFORM_JOINT_TYPES]
    if len(candidates) != 1:
        found = ", ".join(repr(joint.name) for joint in candidates) or "none"
        hint = ("" if candidates or description.loops else " (a tree with no <loop>: a closed-loop robot of another "
                "tool needs its robot.yaml beside it, closing_<name>_1 / closing_<name>_2 frame pairs as "
                "onshape-to-robot writes them, <gazebo><joint> or <drake:ball_constraint> elements, or an MJCF file; "
                "see docs/other-formats.md)")
        raise description.fail(
            f"<robot name='{name}'>",
            f"expected exactly one floating or planar joint attaching the platform to the base, found {found}{hint}.",
        )
    joint = candidates[0]
    tag = f"<joint name='{joint.name}'>"
    is_planar = joint.type == "planar"
    if is_planar:
        if not np.allclose(joint.axis, [0.0, 0.0, 1.0], atol=1e-9):
            raise description.fail(tag, f"a planar platform joint must have <axis xyz='0 0 1'/>, got {joint.axis}.")
        if not np.allclose(joint.origin.rotation[:, 2], [0.0, 0.0, 1.0], atol=1e-9):
            raise description.fail(tag, "the origin of a planar platform joint may only rotate about z.")
    joint_id = model.getJointId(joint.name)
    base_frame = body_frame(model, joint.parent)
    if base_frame.parentJoint != 0 or model.parents[joint_id] != 0:
        raise description.fail(tag, f"the base link {joint.parent!r} must be fixed to the world "
                                    "(no moving joint above it).")
    rotation_world_base, translation_world_base = placement_arrays(base_frame.placement)
    platform_frame = body_frame(model, joint.child)
    world_rotation, world_translation = placement_arrays(model.jointPlacements[joint_id] * platform_frame.placement)
    return Platform(
        name=name, is_planar=is_planar,
        pose_coordinates=PLANAR_TASK_COORDINATES if is_planar else SPATIAL_TASK_COORDINATES,
        base_link=joint.parent, platform_link=joint.child, platform_joint=joint.name, platform_joint_id=joint_id,
        platform_frame_placement=platform_frame.placement,
        rotation_world_base=rotation_world_base, translation_world_base=translation_world_base,
        home_rotation=rotation_world_base.T @ world_rotation,
        home_translation=rotation_world_base.T @ (world_translation - translation_world_base),
    )


def _loop_names(loop) -> tuple[str, ...]:
    dofs = LOOP_JOINT_DOFS[loop.type]
    if dofs == 3:
        return (f"{loop.name}[x]", f"{loop.name}[y]", f"{loop.name}[z]")
    if dofs == 2:
        return (f"{loop.name}[1]", f"{loop.name}[2]")
    return (loop.name,) * dofs


def chain_order(name: str) -> tuple:
    """The key that orders chains: their names in natural order (``leg_2`` before ``leg_10``).

    Chains are ordered by name, not by where the file lists them, so that everything reported in chain
    or actuator order (actuators, set labels, the first of tied worst faults) is the same for any
    order of the legs in the file.

    >>> sorted(["leg_10", "leg_2", "arm"], key=chain_order)
    ['arm', 'leg_2', 'leg_10']
    """
    return tuple((0, int(part), "") if part.isdigit() else (1, 0, part) for part in re.split(r"(\d+)", name) if part)


def read_chains(description: UrdfDescription, model, platform: Platform) -> tuple[Chain, ...]:
    """Every chain, ordered by name (:func:`chain_order`), with its geometry (base frame), limits and actuators."""
    tag_robot = f"<robot name='{platform.name}'>"
    if not description.loops:
        raise description.fail(tag_robot, "no <loop> joint closes a chain onto the platform.")
    data, _ = neutral_with_jacobians(model)
    platform_inverse = platform.platform_frame_placement.inverse()
    chains, used_by, names = [], {}, set()
    for loop in description.loops:
        tag = f"<loop name='{loop.name}'>"
        frames = {link: body_frame(model, link) for link in (loop.predecessor, loop.successor)}
        on_platform = [link for link, frame in frames.items() if frame.parentJoint == platform.platform_joint_id]
        if len(on_platform) != 1:
            if on_platform:
                problem = f"both {loop.predecessor!r} and {loop.successor!r} are on the platform."
            else:
                problem = (f"chain has no path to the platform: neither {loop.predecessor!r} nor {loop.successor!r} "
                           f"is the platform link {platform.platform_link!r} or fixed to it.")
            raise description.fail(tag, problem)
        if on_platform[0] == loop.predecessor:
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
            if joint_id == platform.platform_joint_id:
                raise description.fail(tag, f"the leg link {leg_link!r} hangs from the platform, not from the base.")
            path.append(joint_id)
            joint_id = model.parents[joint_id]
        path.reverse()
        rotations, translations, joint_axes, prismatic, joint_names, limits = [], [], [], [], [], []
        for index, joint_id in enumerate(path):
            name = model.names[joint_id]
            if name in used_by:
                raise description.fail(tag, f"its chain shares the joint {name!r} with the chain of loop "
                                            f"{used_by[name]!r}; chains must be separate serial chains from the base.")
            used_by[name] = loop.name
            if model.joints[joint_id].nv != 1:
                raise description.fail(f"<joint name='{name}'>",
                                       f"chain of loop {loop.name!r} passes through a joint with "
                                       f"{model.joints[joint_id].nv} DoFs; chain joints must be revolute, continuous "
                                       "or prismatic.")
            axis, is_prismatic = joint_axis_local(model, data, joint_id)
            placement = model.jointPlacements[joint_id]
            rotation, translation = platform.base_relative(placement) if index == 0 else placement_arrays(placement)
            rotations.append(rotation)
            translations.append(translation)
            joint_axes.append(axis)
            prismatic.append(is_prismatic)
            joint_names.append(name)
            limits.append(description.joints[name].limits)
        leg_placement = frames[leg_link].placement
        if path:
            leg_rotation, leg_translation = placement_arrays(leg_placement)
        else:
            leg_rotation, leg_translation = platform.base_relative(leg_placement)
        leg_translation = leg_translation + leg_rotation @ leg_origin.translation
        leg_rotation = leg_rotation @ leg_origin.rotation
        platform_rotation, platform_translation = placement_arrays(platform_inverse * frames[platform_link].placement)
        platform_translation = platform_translation + platform_rotation @ platform_origin.translation
        platform_rotation = platform_rotation @ platform_origin.rotation
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
        if loop.chain in names:
            raise description.fail(tag, f"the chain name {loop.chain!r} is used twice.")
        names.add(loop.chain)
        loop_dofs = LOOP_JOINT_DOFS[loop.type]
        chains.append(Chain(
            name=loop.chain, joint_names=tuple(joint_names) + _loop_names(loop), actuated=(),
            prismatic=geometry.dof_prismatic, loop_name=loop.name, loop_type=loop.type, geometry=geometry,
            tree_joint_ids=tuple(path),
            joint_limits=np.array(limits + [(-np.inf, np.inf)] * loop_dofs, dtype=float).reshape(-1, 2),
        ))
    chains.sort(key=lambda chain: chain_order(chain.name))
    return _with_actuators(description, tuple(chains), platform.name)


def _with_actuators(description: UrdfDescription, chains: tuple[Chain, ...], name: str) -> tuple[Chain, ...]:
    """The chains with their actuated joints from the ``<transmission>`` elements."""
    actuated: dict[int, set[int]] = {index: set() for index in range(len(chains))}
    position = {joint: (c, k) for c, chain in enumerate(chains) for k, joint in enumerate(chain.joint_names)}
    for transmission in description.transmissions:
        tag = f"<transmission name='{transmission.name}'>"
        for joint_name in transmission.joints:
            if joint_name not in position:
                if joint_name in description.joints:
                    raise description.fail(tag, f"drives joint {joint_name!r}, which is in no chain from the base "
                                                "to the platform.")
                raise description.fail(tag, f"names an unknown joint {joint_name!r}.")
            chain_index, joint_index = position[joint_name]
            actuated[chain_index].add(joint_index)
    if not any(actuated.values()):
        raise description.fail(f"<robot name='{name}'>",
                               "no actuators: mark the actuated joints with <transmission> elements.")
    return tuple(replace(chain, actuated=tuple(sorted(actuated[index]))) for index, chain in enumerate(chains))
