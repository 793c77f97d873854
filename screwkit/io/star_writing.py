"""Writing a closed tree's star (:mod:`screwkit.io.star`) as screwkit's URDF: joint origins and poses, the written
base frame, a compound leg's equivalent constraint chain, the pin of a ball closed on the base itself; and how far
the assembly moved the joints, as the report says it."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from screwkit.common.rotations import rotation_about_axis, rpy_from_rotation
from screwkit.io.closed_tree import inverse, joint_kind, joint_value
from screwkit.io.compound import Reduction
from screwkit.model.urdf_writer import UrdfWriter

__all__ = ["UNLIMITED_SLIDE", "origin_of", "pose_of", "in_base", "joint_motion", "base_frame", "write_equivalent",
           "write_base_pin", "largest_changes"]

UNLIMITED_SLIDE = 1e6
"""Limits (m) written for a prismatic joint the file gives none (URDF requires limits on sliders)."""


def origin_of(matrix: NDArray) -> dict:
    return dict(zip(("xyz", "rpy"), pose_of(matrix)))


def pose_of(matrix: NDArray) -> tuple:
    return tuple(matrix[:3, 3]), tuple(rpy_from_rotation(matrix[:3, :3]))


def joint_motion(model, joint: int, q: NDArray) -> NDArray:
    kind, axis = joint_kind(model, joint)
    motion = np.eye(4)
    value = joint_value(model, joint, q)
    if kind == "revolute":
        motion[:3, :3] = rotation_about_axis(axis, value)
    else:
        motion[:3, 3] = axis * value
    return motion


TIE = 1e-9
"""Components of a plane's normal within this of the largest are a tie, broken towards the world's x, then y: a
normal written on a diagonal (a plane at 45 deg) keeps its frame whatever its rounding (the frame turns by 90 deg
where the nearest world axis changes, at these diagonals, and nowhere else)."""


def base_frame(normal: NDArray | None, point: NDArray) -> NDArray:
    """World frame of the written base: z along a planar mechanism's normal, x and y the world's axes turned with it,
    its origin where the world axis nearest to the normal meets the plane through ``point`` (the world's frame for a
    spatial mechanism).

    The world's axis nearest to the normal (with its sense) is turned onto the normal by the least rotation, and the
    first of the other two world axes with it is the plane's x: a plane whose normal is a world axis has that axis's
    two others (x, y about z; x, -z about y; y, z about x), and one whose normal the file's rounding tilts from it has
    them turned by the tilt, continuously and with every digit (the plane of a five-bar based on ``rpy="0 3.14159
    0"``, its normal 2.65e-6 rad from the world's x, took its x from the world's x, nearly along the normal: 2.3e-11
    rad from perpendicular, and along the world's -z where ``3.1415926`` gave the world's y). The origin: the plane's
    x, y are the world's to second order in the normal's rounding however far the plane is (turned about the world's
    origin, they were not)."""
    frame = np.eye(4)
    if normal is None:
        return frame
    z = normal / np.linalg.norm(normal)
    axis = int(np.flatnonzero(np.abs(z) >= np.max(np.abs(z)) - TIE)[0])  # (x before y before z in a near tie)
    nearest = np.zeros(3)
    nearest[axis] = np.sign(z[axis])
    turn = np.cross(nearest, z)  # the least rotation taking the nearest axis onto z (Rodrigues), at most 55 deg
    first = np.eye(3)[1 if axis == 0 else 0]
    x = first + np.cross(turn, first) + np.cross(turn, np.cross(turn, first)) / (1.0 + float(nearest @ z))
    x -= (x @ z) * z
    x /= np.linalg.norm(x)
    frame[:3, :3] = np.column_stack([x, np.cross(z, x), z])
    frame[axis, 3] = float(z @ point) / z[axis]
    return frame


def write_equivalent(writer: UrdfWriter, name: str, reduction: Reduction, attachment: NDArray, world_base: NDArray,
                      platform_world: NDArray) -> list[str]:
    """An equivalent constraint chain: slides along the reduction's translations, then revolutes along its rotations,
    from the attachment point, welded there to the platform. Returns its joint names."""
    to_base = inverse(world_base)
    point = tuple(in_base(world_base, attachment))
    parent, joints = "base", []
    directions = [("prismatic", d) for d in reduction.translations] + [("continuous", d) for d in reduction.rotations]
    for position, (kind, direction) in enumerate(directions):
        joint = f"{name}_{'slide' if kind == 'prismatic' else 'turn'}_{position + 1}"
        writer.link(f"{joint}_link")
        writer.joint(joint, kind, parent, f"{joint}_link", xyz=point if position == 0 else (0, 0, 0),
                     axis=tuple(to_base[:3, :3] @ direction),
                     limit=(-UNLIMITED_SLIDE, UNLIMITED_SLIDE, 0, 0) if kind == "prismatic" else None)
        parent = f"{joint}_link"
        joints.append(joint)
    end = world_base.copy()
    end[:3, 3] = attachment
    writer.loop(f"{name}_loop", "fixed", name, parent, pose_of(np.eye(4)), "platform",
                pose_of(inverse(platform_world) @ end))
    return joints


def in_base(world_base: NDArray, point: NDArray) -> NDArray[np.float64]:
    """A world point in the written base's frame (``world_base``: that frame in the world)."""
    return (inverse(world_base) @ np.append(point, 1.0))[:3]


def write_base_pin(writer: UrdfWriter, leg, world_base: NDArray, reference: dict) -> list[str]:
    """The pin of a ball closed on the base itself (a leg's one ``base_dofs`` entry in :mod:`screwkit.io.star`; a ball
    is refused before writing), written first in the leg: a revolute through its centre, its frame the base's axes
    there, named after the closure, its link that name and ``_link``. Returns the names written (none or the pin)."""
    if not leg.base_dofs:
        return []
    (_, axis, point), = leg.base_dofs
    origin = np.eye(4)
    origin[:3, 3] = in_base(world_base, point)
    writer.link(f"{leg.closure}_link")
    writer.joint(leg.closure, "continuous", "base", f"{leg.closure}_link", axis=tuple(world_base[:3, :3].T @ axis),
                 **origin_of(origin))
    reference[leg.closure] = 0.0
    return [leg.closure]


def largest_changes(model, change: NDArray, unit: str) -> str:
    """The largest change of a joint angle (rad) and, when a joint slides, of a length (``unit``), between two
    configurations (``change``: Pinocchio's difference, velocity coordinates)."""
    angles, lengths = [0.0], []
    for joint in range(1, model.njoints):
        part = np.abs(change[model.joints[joint].idx_v:model.joints[joint].idx_v + model.joints[joint].nv])
        kind, _ = joint_kind(model, joint)
        slides = {"prismatic": 1, "JointModelFreeFlyer": 3, "JointModelPlanar": 2, "JointModelTranslation": 3}.get(
            kind, 0)  # (Pinocchio's velocity coordinates: the lengths first)
        if slides:
            lengths.append(float(part[:slides].max()))
        angles.append(float(part[slides:].max(initial=0.0)))
    return f"{max(angles):.3g} rad" + (f", {max(lengths):.3g} {unit}" if lengths else "")
