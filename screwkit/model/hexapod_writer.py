"""Writing a-UPS and a-RSS hexapods (any leg count a) in screwkit's URDF convention.

Used by the bundled files (``python -m screwkit.robots.generate``) and by the design families of
:mod:`screwkit.studies.design.families`. Base joints sit on a circle at z = 0, platform joints on a
circle in the platform frame, both at the a angles of :func:`hexapod_points`; the platform is
``height`` above the base in the reference assembly, where every joint value is zero.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from screwkit.common.rotations import rotation_from_rpy, rpy_from_rotation
from screwkit.model.urdf_document import UrdfDocument
from screwkit.model.urdf_writer import UrdfWriter

__all__ = ["slot_angles", "hexapod_points", "ups_hexapod_document", "ups_hexapod_urdf", "rss_hexapod_document",
           "rss_hexapod_urdf", "unit", "universal_axes"]

Z_AXIS = np.array([0.0, 0.0, 1.0])


def slot_angles(count: int, spread: float = 0.0) -> NDArray[np.float64]:
    """The ``count`` slot angles (rad): ``2 pi k / count``, moved by ``+spread / 2`` for even k and
    ``-spread / 2`` for odd k, so that ``spread`` > 0 gathers the slots in pairs (0: uniform)."""
    k = np.arange(count)
    return 2 * math.pi * k / count + np.where(k % 2 == 0, 0.5, -0.5) * spread


def hexapod_points(legs: int, base_radius: float, platform_radius: float, platform_slots, *,
                   base_spread: float = 0.0, platform_spread: float = 0.0) -> tuple[NDArray, NDArray]:
    """Base points b_i (a, 3) at z = 0 and platform points p_i (a, 3) in the platform frame.

    Leg i runs from base slot i to platform slot ``platform_slots[i]`` (slots at
    :func:`slot_angles`). One leg per uniform slot with ``platform_slots[i] = i + const`` would be
    architecturally singular: the rotationally symmetric set of leg lines spans only 3 dimensions.
    """
    base_angles = slot_angles(legs, base_spread)
    platform_angles = slot_angles(legs, platform_spread)[np.asarray(platform_slots, dtype=int)]
    base = base_radius * np.column_stack([np.cos(base_angles), np.sin(base_angles), np.zeros(legs)])
    platform = platform_radius * np.column_stack([np.cos(platform_angles), np.sin(platform_angles), np.zeros(legs)])
    return base, platform


def unit(vector: NDArray) -> NDArray:
    """``vector`` divided by its norm."""
    return vector / np.linalg.norm(vector)


def universal_axes(direction: NDArray) -> tuple[NDArray, NDArray]:
    """Two unit axes perpendicular to ``direction`` (the first horizontal): a universal joint's."""
    first = unit(np.cross(Z_AXIS, direction))
    return first, np.cross(direction, first)


def _radius(points: NDArray) -> float:
    return float(np.max(np.linalg.norm(points[:, :2], axis=-1)))


def ups_hexapod_urdf(name: str, base: NDArray, platform: NDArray, height: float, comment: str = "") -> str:
    """The URDF text of :func:`ups_hexapod_document`."""
    return ups_hexapod_document(name, base, platform, height, comment).text()


def ups_hexapod_document(name: str, base: NDArray, platform: NDArray, height: float,
                         comment: str = "") -> UrdfDocument:
    """An a-UPS hexapod: U at ``base`` (a, 3), actuated slider along the leg, S at ``platform`` (a, 3,
    platform frame). Slider limits: -0.5 to +0.8 times the reference leg length."""
    writer = UrdfWriter(name, comment)
    writer.link("base_link", ("cylinder", round(_radius(base) + 0.05, 6), 0.01), xyz=(0, 0, -0.02))
    writer.link("platform", ("cylinder", round(_radius(platform) + 0.05, 6), 0.02))
    writer.joint("platform_joint", "floating", "base_link", "platform", xyz=(0, 0, height))
    for i in range(base.shape[0]):
        chain = f"leg_{i + 1}"
        top = platform[i] + np.array([0, 0, height])
        direction = unit(top - base[i])
        length = float(np.linalg.norm(top - base[i]))
        first_axis, second_axis = universal_axes(direction)
        leg_rotation = np.column_stack([direction, first_axis, second_axis])
        writer.link(f"{chain}_cross", ("sphere", 0.03))
        writer.rod(f"{chain}_cylinder", 0.6 * length, radius=0.03)
        writer.rod(f"{chain}_piston", length, radius=0.015)
        writer.joint(f"{chain}_joint_u1", "continuous", "base_link", f"{chain}_cross",
                     xyz=base[i], rpy=rpy_from_rotation(leg_rotation), axis=(0, 1, 0))  # fmt: skip
        writer.joint(f"{chain}_joint_u2", "continuous", f"{chain}_cross", f"{chain}_cylinder", axis=(0, 0, 1))
        writer.joint(f"{chain}_joint_slider", "prismatic", f"{chain}_cylinder", f"{chain}_piston",
                     axis=(1, 0, 0), limit=(-0.5 * length, 0.8 * length, 5000.0, 0.5))  # fmt: skip
        writer.loop(f"{chain}_joint_s", "spherical", chain,
                    f"{chain}_piston", ((length, 0, 0), (0, 0, 0)),
                    "platform", (platform[i], rpy_from_rotation(leg_rotation)))  # fmt: skip
        writer.transmission(f"{chain}_joint_slider")
    return writer.document()


def rss_hexapod_urdf(name: str, base: NDArray, platform: NDArray, height: float, crank: float,
                     comment: str = "") -> str:
    """The URDF text of :func:`rss_hexapod_document`."""
    return rss_hexapod_document(name, base, platform, height, crank, comment).text()


def rss_hexapod_document(name: str, base: NDArray, platform: NDArray, height: float, crank: float,
                         comment: str = "") -> UrdfDocument:
    """An a-RSS hexapod (modelled R-U-S: the rod's idle spin is removed): actuated crank pivots at
    ``base`` (a, 3) with horizontal axes tangent to the base circle, cranks of length ``crank``
    pointing radially outwards in the reference assembly, S at ``platform`` (a, 3, platform frame)."""
    writer = UrdfWriter(name, comment)
    writer.link("base_link", ("cylinder", round(_radius(base) + crank + 0.05, 6), 0.01), xyz=(0, 0, -0.02))
    writer.link("platform", ("cylinder", round(_radius(platform) + 0.05, 6), 0.02))
    writer.joint("platform_joint", "floating", "base_link", "platform", xyz=(0, 0, height))
    for i in range(base.shape[0]):
        chain = f"leg_{i + 1}"
        angle = math.atan2(base[i][1], base[i][0])
        radial = np.array([math.cos(angle), math.sin(angle), 0.0])
        crank_rotation = rotation_from_rpy(np.array([0.0, 0.0, angle]))
        crank_end = base[i] + crank * radial
        top = platform[i] + np.array([0, 0, height])
        direction = unit(top - crank_end)
        rod_length = float(np.linalg.norm(top - crank_end))
        first_axis, second_axis = universal_axes(direction)
        rod_rotation = np.column_stack([direction, first_axis, second_axis])
        writer.rod(f"{chain}_crank", crank, radius=0.03)
        writer.link(f"{chain}_cross", ("sphere", 0.03))
        writer.rod(f"{chain}_rod", rod_length)
        writer.joint(f"{chain}_joint_crank", "revolute", "base_link", f"{chain}_crank",
                     xyz=base[i], rpy=(0, 0, angle), axis=(0, 1, 0),
                     limit=(-math.pi, math.pi, 200.0, 3.0))  # fmt: skip
        writer.joint(f"{chain}_joint_u1", "continuous", f"{chain}_crank", f"{chain}_cross",
                     xyz=(crank, 0, 0), rpy=rpy_from_rotation(crank_rotation.T @ rod_rotation),
                     axis=(0, 1, 0))  # fmt: skip
        writer.joint(f"{chain}_joint_u2", "continuous", f"{chain}_cross", f"{chain}_rod", axis=(0, 0, 1))
        writer.loop(f"{chain}_joint_s", "spherical", chain,
                    f"{chain}_rod", ((rod_length, 0, 0), (0, 0, 0)),
                    "platform", (platform[i], rpy_from_rotation(rod_rotation)))  # fmt: skip
        writer.transmission(f"{chain}_joint_crank")
    return writer.document()
