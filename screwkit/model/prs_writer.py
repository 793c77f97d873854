"""Writing 3-PRS mechanisms, optionally made redundant by a fourth, actuated UPS leg, in screwkit's
URDF convention (3 DOF: z, roll, pitch).

Used by the bundled ``prs_3_ups`` (``python -m screwkit.robots.generate``) and by the design family
``prs_ups`` of :mod:`screwkit.studies.design.families`.
"""

from __future__ import annotations

import math

import numpy as np

from screwkit.common.rotations import rpy_from_rotation
from screwkit.model.hexapod_writer import unit, universal_axes
from screwkit.model.urdf_document import UrdfDocument
from screwkit.model.urdf_writer import UrdfWriter

__all__ = ["prs_document", "prs_urdf"]


def prs_urdf(name: str, parameters: dict, with_ups: bool = True, comment: str = "",
             task_coordinates: tuple[str, ...] | None = None,
             named_poses: dict[str, dict[str, float]] | None = None) -> str:
    """The URDF text of :func:`prs_document`."""
    return prs_document(name, parameters, with_ups, comment, task_coordinates, named_poses).text()


def prs_document(name: str, parameters: dict, with_ups: bool = True, comment: str = "",
                 task_coordinates: tuple[str, ...] | None = None,
                 named_poses: dict[str, dict[str, float]] | None = None) -> UrdfDocument:
    """A 3-PRS (vertical actuated sliders, R axes tangential, S at the platform), optionally with a fourth,
    actuated U-P-S leg that adds no constraint (3 DOF: z, roll, pitch; 4 actuators).

    ``task_coordinates`` are written as ``<task_coordinates>`` and ``named_poses`` (name -> task
    coordinate values, m and rad) as ``<named_pose>`` elements.

    ``parameters``: ``base_radius`` (sliders from the axis), ``platform_radius`` (S centres),
    ``link``, ``prs_angles_deg`` (the three chains' angles), ``ups_angle_deg``, ``ups_base_radius``,
    ``stroke`` (slider travel about the reference, m). Raises ValueError when the links cannot
    reach the platform (``link`` <= |base_radius - platform_radius|)."""
    base_radius, platform_radius, link = parameters["base_radius"], parameters["platform_radius"], parameters["link"]
    if not link > abs(base_radius - platform_radius):
        raise ValueError(f"A 3-PRS link of {link:g} m cannot join the {base_radius:g} m slider circle to the "
                         f"{platform_radius:g} m platform circle.")
    height = math.sqrt(link**2 - (base_radius - platform_radius) ** 2)  # platform height at the reference
    writer = UrdfWriter(name, comment)
    writer.link("base_link", ("cylinder", base_radius + 0.08, 0.01), xyz=(0, 0, -0.02))
    writer.link("platform", ("cylinder", platform_radius + 0.02, 0.01))
    writer.joint("platform_joint", "floating", "base_link", "platform", xyz=(0, 0, height))
    lower, upper = parameters["stroke"]
    for i, angle in enumerate(np.deg2rad(parameters["prs_angles_deg"])):
        chain = f"prs_{i + 1}"
        radial = np.array([math.cos(angle), math.sin(angle), 0.0])
        tangent = np.array([-math.sin(angle), math.cos(angle), 0.0])
        base = base_radius * radial
        top = platform_radius * radial + np.array([0.0, 0.0, height])
        direction = unit(top - base)
        # carriage frame: x along the link, y along the R axis (tangent), z = x cross y
        frame = np.column_stack([direction, tangent, np.cross(direction, tangent)])
        writer.link(f"{chain}_carriage", ("box", (0.03, 0.03, 0.03)))
        writer.rod(f"{chain}_link", link, radius=0.008)
        writer.joint(f"{chain}_joint_p", "prismatic", "base_link", f"{chain}_carriage", xyz=base, axis=(0, 0, 1),
                     limit=(lower, upper, 2000.0, 0.5))
        writer.joint(f"{chain}_joint_r", "revolute", f"{chain}_carriage", f"{chain}_link",
                     rpy=rpy_from_rotation(frame), axis=(0, 1, 0), limit=(-1.2, 1.2, 100.0, 2.0))
        writer.loop(f"{chain}_joint_s", "spherical", chain, f"{chain}_link", ((link, 0, 0), (0, 0, 0)),
                    "platform", (top - np.array([0.0, 0.0, height]), rpy_from_rotation(frame)))
        writer.transmission(f"{chain}_joint_p")
    if with_ups:
        angle = math.radians(parameters["ups_angle_deg"])
        radial = np.array([math.cos(angle), math.sin(angle), 0.0])
        base = parameters["ups_base_radius"] * radial
        top = platform_radius * radial + np.array([0.0, 0.0, height])
        direction = unit(top - base)
        length = float(np.linalg.norm(top - base))
        first_axis, second_axis = universal_axes(direction)
        leg_rotation = np.column_stack([direction, first_axis, second_axis])
        chain = "ups"
        writer.link(f"{chain}_cross", ("sphere", 0.012))
        writer.rod(f"{chain}_cylinder", 0.6 * length, radius=0.012)
        writer.rod(f"{chain}_piston", length, radius=0.006)
        writer.joint(f"{chain}_joint_u1", "continuous", "base_link", f"{chain}_cross",
                     xyz=base, rpy=rpy_from_rotation(leg_rotation), axis=(0, 1, 0))
        writer.joint(f"{chain}_joint_u2", "continuous", f"{chain}_cross", f"{chain}_cylinder", axis=(0, 0, 1))
        writer.joint(f"{chain}_joint_slider", "prismatic", f"{chain}_cylinder", f"{chain}_piston",
                     axis=(1, 0, 0), limit=(-0.5 * length, 0.8 * length, 2000.0, 0.5))
        writer.loop(f"{chain}_joint_s", "spherical", chain, f"{chain}_piston", ((length, 0, 0), (0, 0, 0)),
                    "platform", (top - np.array([0.0, 0.0, height]), rpy_from_rotation(leg_rotation)))
        writer.transmission(f"{chain}_joint_slider")
    if task_coordinates is not None:
        writer.task_coordinates(task_coordinates)
    for pose_name, values in (named_poses or {}).items():
        writer.named_pose(pose_name, values)
    return writer.document()
