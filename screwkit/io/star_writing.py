"""Writing a closed tree's star (:mod:`screwkit.io.star`) as screwkit's URDF: joint origins and poses, the written
base frame, a compound leg's equivalent constraint chain, the pin of a ball closed on the base itself."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from screwkit.common.rotations import rotation_about_axis, rpy_from_rotation
from screwkit.io.closed_tree import inverse, joint_kind, joint_value
from screwkit.io.compound import Reduction
from screwkit.model.urdf_writer import UrdfWriter

__all__ = ["UNLIMITED_SLIDE", "origin_of", "pose_of", "joint_motion", "base_frame", "write_equivalent",
           "write_base_dofs"]

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


def base_frame(normal: NDArray | None, point: NDArray) -> NDArray:
    """World frame of the written base: z along a planar mechanism's normal, its origin where the world axis nearest
    to it meets the plane through ``point`` (the world's for a spatial mechanism): the plane's x, y are then the
    world's to second order in the normal's rounding however far the plane is (turned about the world's origin, they
    were not), and they change with the normal continuously (a threshold on its tilt left a jump there)."""
    frame = np.eye(4)
    if normal is None:
        return frame
    z = normal / np.linalg.norm(normal)
    x = np.array([1.0, 0.0, 0.0]) - z[0] * z
    if np.linalg.norm(x) < 1e-6:
        x = np.array([0.0, 1.0, 0.0]) - z[1] * z
    x, axis = x / np.linalg.norm(x), int(np.argmax(np.abs(z)))
    frame[:3, :3] = np.column_stack([x, np.cross(z, x), z])
    frame[axis, 3] = float(z @ point) / z[axis]
    return frame


def write_equivalent(writer: UrdfWriter, name: str, reduction: Reduction, attachment: NDArray, world_base: NDArray,
                      platform_world: NDArray) -> list[str]:
    """An equivalent constraint chain: slides along the reduction's translations, then revolutes along its rotations,
    from the attachment point, welded there to the platform. Returns its joint names."""
    to_base = inverse(world_base)
    point = tuple((to_base @ np.append(attachment, 1.0))[:3])
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



def write_base_dofs(writer: UrdfWriter, leg, world_base: NDArray, reference: dict) -> list[str]:
    """The joints of a ball closed on the base itself (a leg's ``base_dofs`` in :mod:`screwkit.io.star`), written
    first in the leg: revolutes through its centre, their frames the base's axes there, named after the closure.
    Returns their names (each joint's link is its name and ``_link``)."""
    links = []
    for number, (_, axis, point) in enumerate(leg.base_dofs, start=1):
        name = leg.closure if len(leg.base_dofs) == 1 else f"{leg.closure}_{number}"
        origin = np.eye(4)
        if number == 1:
            origin[:3, 3] = inverse(world_base)[:3, :3] @ point + inverse(world_base)[:3, 3]
        writer.link(f"{name}_link")
        writer.joint(name, "continuous", links[-1] if links else "base", f"{name}_link",
                     axis=tuple(world_base[:3, :3].T @ axis), **origin_of(origin))
        reference[name] = 0.0
        links.append(f"{name}_link")
    return [link[:-len("_link")] for link in links]
