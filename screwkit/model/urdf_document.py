"""A mechanism document as records in document order, and its two readings: the description and the URDF text.

:class:`~screwkit.model.urdf_writer.UrdfWriter` builds a :class:`UrdfDocument`, one record per element
(:class:`LinkRecord`, :class:`JointRecord`, :class:`LoopRecord`, :class:`TransmissionRecord` and the
screwkit extensions), every number already as the text will hold it (:func:`written_number`). The
document is read two ways, with no geometry of their own:

* :meth:`UrdfDocument.description`: the :class:`~screwkit.model.urdf_description.UrdfDescription` the
  safe XML pass (:func:`~screwkit.model.urdf_reader.parse_urdf`) reads from the text, without writing
  or parsing it; its ``text`` is written on first use only;
* :meth:`UrdfDocument.text`: the URDF text, element by element in the order written.

So a design built from its parameters (:meth:`screwkit.studies.design.families.Family.mechanism`)
never goes through a file, and the file of a design that is kept reads back as the same model.
"""

from __future__ import annotations

import xml.etree.ElementTree as ElementTree
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from screwkit.model.urdf_description import (
    AXIS_JOINT_TYPES,
    JointElement,
    LoopElement,
    Origin,
    TransmissionElement,
    UrdfDescription,
)

__all__ = ["UrdfDocument", "LinkRecord", "JointRecord", "LoopRecord", "TransmissionRecord", "ExtensionRecord",
           "written_number", "number_text"]

Triple = tuple[float, float, float]


def written_number(value: float) -> float:
    """The float the text of ``value`` reads back as: values below 1e-15 in magnitude are written 0."""
    value = float(value)
    return 0.0 if abs(value) < 1e-15 else value


def number_text(value: float) -> str:
    """Shortest text that reads back as the same float (integers without '.0', tiny values as 0)."""
    value = written_number(value)
    if value == 0.0:
        return "0"
    if value.is_integer():
        return str(int(value))
    return repr(value)


def written_triple(values) -> Triple:
    """Three numbers as the text holds them (:func:`written_number`)."""
    first, second, third = (written_number(value) for value in values)
    return first, second, third


def _triple_text(values: Triple) -> str:
    return " ".join(number_text(value) for value in values)


def _unit(vector: Triple) -> np.ndarray:
    """A written axis as the reader keeps it: divided by its norm."""
    axis = np.array(vector, dtype=float)
    return axis / np.linalg.norm(axis)


def _origin(xyz: Triple, rpy: Triple) -> Origin:
    return Origin(xyz=np.array(xyz, dtype=float), rpy=np.array(rpy, dtype=float))


def _add_origin(parent: ElementTree.Element, xyz: Triple, rpy: Triple) -> None:
    ElementTree.SubElement(parent, "origin", xyz=_triple_text(xyz), rpy=_triple_text(rpy))


@dataclass(frozen=True)
class LinkRecord:
    """A ``<link>``; ``shape`` is None, ("box", (x, y, z)), ("cylinder", radius, length) or ("sphere", radius)."""

    name: str
    shape: tuple | None = None
    xyz: Triple = (0.0, 0.0, 0.0)
    rpy: Triple = (0.0, 0.0, 0.0)

    def write(self, robot: ElementTree.Element) -> None:
        link = ElementTree.SubElement(robot, "link", name=self.name)
        if self.shape is None:
            return
        visual = ElementTree.SubElement(link, "visual")
        _add_origin(visual, self.xyz, self.rpy)
        geometry = ElementTree.SubElement(visual, "geometry")
        if self.shape[0] == "box":
            ElementTree.SubElement(geometry, "box", size=_triple_text(self.shape[1]))
        elif self.shape[0] == "cylinder":
            ElementTree.SubElement(geometry, "cylinder", radius=number_text(self.shape[1]),
                                   length=number_text(self.shape[2]))
        else:
            ElementTree.SubElement(geometry, "sphere", radius=number_text(self.shape[1]))


@dataclass(frozen=True)
class JointRecord:
    """A tree ``<joint>``: ``axis`` as written (None: no ``<axis>``), ``limit`` (lower, upper, effort, velocity)."""

    name: str
    type: str
    parent: str
    child: str
    xyz: Triple = (0.0, 0.0, 0.0)
    rpy: Triple = (0.0, 0.0, 0.0)
    axis: Triple | None = None
    limit: tuple[float, float, float, float] | None = None

    def write(self, robot: ElementTree.Element) -> None:
        joint = ElementTree.SubElement(robot, "joint", name=self.name, type=self.type)
        ElementTree.SubElement(joint, "parent", link=self.parent)
        ElementTree.SubElement(joint, "child", link=self.child)
        _add_origin(joint, self.xyz, self.rpy)
        if self.axis is not None:
            ElementTree.SubElement(joint, "axis", xyz=_triple_text(self.axis))
        if self.limit is not None:
            lower, upper, effort, velocity = self.limit
            ElementTree.SubElement(joint, "limit", lower=number_text(lower), upper=number_text(upper),
                                   effort=number_text(effort), velocity=number_text(velocity))

    def element(self) -> JointElement:
        """The :class:`JointElement` the reader makes of it."""
        meaningful = self.axis is not None and self.type in AXIS_JOINT_TYPES
        limited = self.limit is not None and self.type in ("revolute", "prismatic")
        return JointElement(name=self.name, type=self.type, parent=self.parent, child=self.child,
                            origin=_origin(self.xyz, self.rpy),
                            axis=_unit(self.axis) if meaningful else np.array([1.0, 0.0, 0.0]),
                            limits=(self.limit[0], self.limit[1]) if limited else (-np.inf, np.inf),
                            drive_limits=(np.inf, np.inf) if self.limit is None else self.limit[2:])


@dataclass(frozen=True)
class LoopRecord:
    """A URDF+ ``<loop>``: the loop frame's (xyz, rpy) in the predecessor and successor links, its axes as written."""

    name: str
    type: str
    chain: str
    predecessor: str
    predecessor_pose: tuple[Triple, Triple]
    successor: str
    successor_pose: tuple[Triple, Triple]
    axis: Triple | None = None
    second_axis: Triple | None = None

    def write(self, robot: ElementTree.Element) -> None:
        loop = ElementTree.SubElement(robot, "loop", name=self.name, type=self.type, chain=self.chain)
        for tag, link, (xyz, rpy) in (("predecessor", self.predecessor, self.predecessor_pose),
                                      ("successor", self.successor, self.successor_pose)):
            side = ElementTree.SubElement(loop, tag, link=link)
            _add_origin(side, xyz, rpy)
        if self.axis is not None:
            ElementTree.SubElement(loop, "axis", xyz=_triple_text(self.axis))
        if self.second_axis is not None:
            ElementTree.SubElement(loop, "axis2", xyz=_triple_text(self.second_axis))

    def element(self) -> LoopElement:
        """The :class:`LoopElement` the reader makes of it."""
        axes: tuple = ()
        if self.type in ("revolute", "continuous", "prismatic", "universal"):
            axes = (_unit(self.axis),)
        if self.type == "universal":
            axes = axes + (_unit(self.second_axis),)
        return LoopElement(name=self.name, type=self.type, predecessor=self.predecessor,
                           predecessor_origin=_origin(*self.predecessor_pose), successor=self.successor,
                           successor_origin=_origin(*self.successor_pose), axes=axes, chain=self.chain)


@dataclass(frozen=True)
class TransmissionRecord:
    """A ``<transmission>`` driving one joint (a simple transmission with its motor)."""

    joint: str

    @property
    def name(self) -> str:
        return f"{self.joint}_transmission"

    def write(self, robot: ElementTree.Element) -> None:
        transmission = ElementTree.SubElement(robot, "transmission", name=self.name)
        ElementTree.SubElement(transmission, "type").text = "transmission_interface/SimpleTransmission"
        joint_element = ElementTree.SubElement(transmission, "joint", name=self.joint)
        ElementTree.SubElement(joint_element, "hardwareInterface").text = "hardware_interface/EffortJointInterface"
        actuator = ElementTree.SubElement(transmission, "actuator", name=f"{self.joint}_motor")
        ElementTree.SubElement(actuator, "mechanicalReduction").text = "1"

    def element(self) -> TransmissionElement:
        return TransmissionElement(name=self.name, joints=(self.joint,))


@dataclass(frozen=True)
class ExtensionRecord:
    """One of screwkit's elements: ``task_coordinates`` (names), ``output`` (type), ``named_pose`` (name,
    values by coordinate) or ``reference_configuration`` (values by joint name)."""

    tag: str
    value: object
    name: str = ""

    def write(self, robot: ElementTree.Element) -> None:
        if self.tag == "task_coordinates":
            ElementTree.SubElement(robot, "task_coordinates", names=" ".join(self.value))
        elif self.tag == "output":
            ElementTree.SubElement(robot, "output", type=self.value)
        elif self.tag == "named_pose":
            ElementTree.SubElement(robot, "named_pose", name=self.name,
                                   **{key: number_text(value) for key, value in self.value.items()})
        else:
            element = ElementTree.SubElement(robot, "reference_configuration")
            for joint, value in self.value.items():
                ElementTree.SubElement(element, "joint", name=joint, value=number_text(value))


@dataclass(frozen=True, eq=False)
class UrdfDocument:
    """A mechanism document: the robot's name, its comment and its elements in document order."""

    robot_name: str
    comment: str
    records: tuple

    def text(self) -> str:
        """The URDF text (every number as :func:`number_text` writes it)."""
        return self._text

    @cached_property
    def _text(self) -> str:
        robot = ElementTree.Element("robot", name=self.robot_name)
        robot.append(ElementTree.Comment(self.comment.replace("--", "- -")))  # "--" may not appear in a comment
        for record in self.records:
            record.write(robot)
        ElementTree.indent(robot, space="  ")
        return '<?xml version="1.0"?>\n' + ElementTree.tostring(robot, encoding="unicode") + "\n"

    def description(self, source: str = "<string>") -> UrdfDescription:
        """What :func:`~screwkit.model.urdf_reader.parse_urdf` reads from :meth:`text`, without the text.

        The description's ``text`` is written from this document when something asks for it (the
        viewer's drawing, a map's tasks)."""
        links, joints, loops, transmissions = [], {}, [], []
        reference, named_poses, task_coordinates, output = {}, {}, None, "frame"
        for record in self.records:
            if isinstance(record, LinkRecord):
                links.append(record.name)
            elif isinstance(record, JointRecord):
                joints[record.name] = record.element()
            elif isinstance(record, LoopRecord):
                loops.append(record.element())
            elif isinstance(record, TransmissionRecord):
                transmissions.append(record.element())
            elif record.tag == "task_coordinates":
                task_coordinates = tuple(record.value)
            elif record.tag == "output":
                output = record.value
            elif record.tag == "named_pose":
                named_poses[record.name] = dict(record.value)
            else:
                reference.update(record.value)
        return UrdfDescription(source=source, robot_name=self.robot_name, links=tuple(links), joints=joints,
                               loops=tuple(loops), transmissions=tuple(transmissions),
                               reference_configuration=reference, named_poses=named_poses,
                               task_coordinates=task_coordinates, output=output, document=self)
