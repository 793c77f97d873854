"""Writing mechanisms in screwkit's URDF convention (``docs/urdf-convention.md``).

:class:`UrdfWriter` builds one document with ElementTree: links with primitive visuals, tree
joints, URDF+ ``<loop>`` joints closing the chains, ``<transmission>`` elements marking the
actuators, the optional ``<reference_configuration>`` and ``<named_pose>`` elements. Numbers
are written as the shortest text that reads back as the same float. :func:`planar_rrr_urdf`
writes a whole planar n-RRR (the bundled ``planar_5rrr`` and the designs of
``screwkit design-search``).
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ElementTree

import numpy as np
from numpy.typing import NDArray

__all__ = ["UrdfWriter", "planar_rrr_urdf", "elbow"]


def _number(value: float) -> str:
    """Shortest text that reads back as the same float (integers without '.0', tiny values as 0)."""
    value = float(value)
    if abs(value) < 1e-15:
        return "0"
    if value.is_integer():
        return str(int(value))
    return repr(value)


def _triple(values) -> str:
    return " ".join(_number(value) for value in values)


class UrdfWriter:
    """Builds one URDF document with ElementTree."""

    def __init__(self, name: str, comment: str):
        self.robot = ElementTree.Element("robot", name=name)
        # "--" may not appear inside an XML comment.
        self.robot.append(ElementTree.Comment(comment.replace("--", "- -")))

    def link(self, name: str, shape: tuple | None = None, xyz=(0, 0, 0), rpy=(0, 0, 0)) -> None:
        """A link; ``shape`` is ("box", size3), ("cylinder", radius, length) or ("sphere", radius)."""
        link = ElementTree.SubElement(self.robot, "link", name=name)
        if shape is None:
            return
        visual = ElementTree.SubElement(link, "visual")
        ElementTree.SubElement(visual, "origin", xyz=_triple(xyz), rpy=_triple(rpy))
        geometry = ElementTree.SubElement(visual, "geometry")
        if shape[0] == "box":
            ElementTree.SubElement(geometry, "box", size=_triple(shape[1]))
        elif shape[0] == "cylinder":
            ElementTree.SubElement(geometry, "cylinder", radius=_number(shape[1]), length=_number(shape[2]))
        else:
            ElementTree.SubElement(geometry, "sphere", radius=_number(shape[1]))

    def rod(self, name: str, length: float, radius: float = 0.015) -> None:
        """A link drawn as a cylinder from its origin along its x axis."""
        self.link(name, ("cylinder", radius, length), xyz=(length / 2, 0, 0), rpy=(0, math.pi / 2, 0))

    def joint(self, name, joint_type, parent, child, xyz=(0, 0, 0), rpy=(0, 0, 0), axis=None, limit=None) -> None:
        joint = ElementTree.SubElement(self.robot, "joint", name=name, type=joint_type)
        ElementTree.SubElement(joint, "parent", link=parent)
        ElementTree.SubElement(joint, "child", link=child)
        ElementTree.SubElement(joint, "origin", xyz=_triple(xyz), rpy=_triple(rpy))
        if axis is not None:
            ElementTree.SubElement(joint, "axis", xyz=_triple(axis))
        if limit is not None:
            lower, upper, effort, velocity = limit
            ElementTree.SubElement(
                joint, "limit", lower=_number(lower), upper=_number(upper), effort=_number(effort),
                velocity=_number(velocity)
            )

    def loop(
        self, name, loop_type, chain, predecessor, predecessor_pose, successor, successor_pose, axis=None,
        second_axis=None
    ) -> None:
        """A URDF+ loop joint; poses are (xyz, rpy) of the loop frame in each link frame."""
        loop = ElementTree.SubElement(self.robot, "loop", name=name, type=loop_type, chain=chain)
        for tag, link, (xyz, rpy) in (
            ("predecessor", predecessor, predecessor_pose),
            ("successor", successor, successor_pose),
        ):
            side = ElementTree.SubElement(loop, tag, link=link)
            ElementTree.SubElement(side, "origin", xyz=_triple(xyz), rpy=_triple(rpy))
        if axis is not None:
            ElementTree.SubElement(loop, "axis", xyz=_triple(axis))
        if second_axis is not None:
            ElementTree.SubElement(loop, "axis2", xyz=_triple(second_axis))

    def transmission(self, joint: str) -> None:
        transmission = ElementTree.SubElement(self.robot, "transmission", name=f"{joint}_transmission")
        ElementTree.SubElement(transmission, "type").text = "transmission_interface/SimpleTransmission"
        joint_element = ElementTree.SubElement(transmission, "joint", name=joint)
        ElementTree.SubElement(joint_element, "hardwareInterface").text = "hardware_interface/EffortJointInterface"
        actuator = ElementTree.SubElement(transmission, "actuator", name=f"{joint}_motor")
        ElementTree.SubElement(actuator, "mechanicalReduction").text = "1"

    def task_coordinates(self, names) -> None:
        """``<task_coordinates names="z roll pitch"/>``: the independent coordinates of a lower-mobility mechanism."""
        ElementTree.SubElement(self.robot, "task_coordinates", names=" ".join(names))

    def output(self, output_type: str) -> None:
        """``<output type="point"/>``: the platform frame's origin is a point output (``"frame"``: the default)."""
        ElementTree.SubElement(self.robot, "output", type=output_type)

    def named_pose(self, name: str, values: dict[str, float]) -> None:
        """A ``<named_pose>``: task coordinate values (m, rad) by coordinate name."""
        ElementTree.SubElement(self.robot, "named_pose", name=name, **{k: _number(v) for k, v in values.items()})

    def reference_configuration(self, values: dict[str, float]) -> None:
        element = ElementTree.SubElement(self.robot, "reference_configuration")
        for name, value in values.items():
            ElementTree.SubElement(element, "joint", name=name, value=_number(value))

    def text(self) -> str:
        ElementTree.indent(self.robot, space="  ")
        return '<?xml version="1.0"?>\n' + ElementTree.tostring(self.robot, encoding="unicode") + "\n"


def _angle(vector: NDArray) -> float:
    return math.atan2(vector[1], vector[0])


def elbow(base: NDArray, end: NDArray, proximal: float, distal: float, side: float = 1.0) -> NDArray:
    """Elbow c of an R-R-R leg, on the ``side`` (+1: left, the +u_perp side) of the line base -> end."""
    delta = end - base
    distance = np.linalg.norm(delta)
    along = (proximal**2 - distal**2 + distance**2) / (2 * distance)
    height = side * math.sqrt(proximal**2 - along**2)
    unit = delta / distance
    return base + along * unit + height * np.array([-unit[1], unit[0]])


def rrr_leg(writer: UrdfWriter, chain: str, base: NDArray, end: NDArray, platform_point: NDArray, proximal: float,
            distal: float, side: float) -> None:
    """One actuated planar R-R-R leg ``chain``: base joint at ``base`` (base frame), elbow on the ``side`` of
    the line to ``end`` (the leg's end in the base frame, reference assembly), loop onto the platform at
    ``platform_point`` (platform frame); links, joints, the loop and the transmission."""
    c = elbow(base, end, proximal, distal, side=side)
    first_angle, second_angle = _angle(c - base), _angle(end - c)
    writer.rod(f"{chain}_link_a", proximal)
    writer.rod(f"{chain}_link_l", distal)
    writer.joint(f"{chain}_joint_b", "continuous", "base_link", f"{chain}_link_a",
                 xyz=(base[0], base[1], 0), rpy=(0, 0, first_angle), axis=(0, 0, 1))  # fmt: skip
    writer.joint(f"{chain}_joint_c", "continuous", f"{chain}_link_a", f"{chain}_link_l",
                 xyz=(proximal, 0, 0), rpy=(0, 0, second_angle - first_angle), axis=(0, 0, 1))  # fmt: skip
    writer.loop(f"{chain}_joint_d", "revolute", chain,
                f"{chain}_link_l", ((distal, 0, 0), (0, 0, -second_angle)),
                "platform", ((platform_point[0], platform_point[1], 0), (0, 0, 0)), axis=(0, 0, 1))  # fmt: skip
    writer.transmission(f"{chain}_joint_b")


def planar_rrr_urdf(name: str, base: NDArray, platform: NDArray, proximal, distal, working_mode=1.0,
                    comment: str = "", named_poses: dict[str, tuple[float, ...]] | None = None,
                    output: str = "frame") -> str:
    """URDF of a planar n-RRR: base joints ``base`` (n, 2), platform joints ``platform`` (n, 2) in the
    platform frame, arm lengths (scalars or (n,)), elbows on the ``working_mode`` side (+1: +u_perp)
    in the reference assembly (platform at x = y = phi = 0). Base joints are actuated."""
    base, platform = np.asarray(base, dtype=float), np.asarray(platform, dtype=float)
    count = base.shape[0]
    proximal = np.broadcast_to(np.asarray(proximal, dtype=float), (count,))
    distal = np.broadcast_to(np.asarray(distal, dtype=float), (count,))
    sides = np.broadcast_to(np.asarray(working_mode, dtype=float), (count,))
    reach = float(np.max(np.linalg.norm(base, axis=-1)))
    writer = UrdfWriter(name, comment)
    writer.link("base_link", ("cylinder", round(reach + 0.05, 6), 0.01), xyz=(0, 0, -0.02))
    writer.link("platform", ("cylinder", round(float(np.max(np.linalg.norm(platform, axis=-1))) + 0.02, 6), 0.02))
    writer.joint("platform_joint", "planar", "base_link", "platform", axis=(0, 0, 1))
    for i in range(count):
        rrr_leg(writer, f"chain_{i + 1}", base[i], platform[i], platform[i], float(proximal[i]), float(distal[i]),
                float(sides[i]))
    if output != "frame":
        writer.output(output)
    for pose_name, values in (named_poses or {}).items():
        writer.named_pose(pose_name, dict(zip(("x", "y", "phi") if output == "frame" else ("x", "y"), values)))
    return writer.text()

