"""A safe XML pass over a URDF file for what Pinocchio and yourdfpy do not read.

Pinocchio builds the kinematic tree; this module reads the rest of screwkit's URDF
convention (see ``docs/urdf-convention.md``):

* ``<loop>`` elements (URDF+ loop joints) that close each leg onto the platform,
* ``<transmission>`` elements that mark the actuated joints,
* the optional ``<reference_configuration>`` element (screwkit extension),
* the optional ``<named_pose>`` elements and ``<units length="mm"/>`` (screwkit extensions),
* the tree ``<joint>`` elements (names, types, links, origins, axes, limits) and the tree's
  shape: one root link, one parent per link, no cycle.

Lengths: a file written in another unit (``<units length="mm"/>`` or the ``length_unit``
argument) is converted to metres here, in the description *and* in the text handed to
Pinocchio, so everything downstream is in metres.

Size: files above :data:`MAX_FILE_BYTES` are refused before parsing, and trees of more than
:data:`MAX_LINKS` links or deeper than :data:`MAX_TREE_DEPTH` joints before Pinocchio sees them
(its URDF parser takes time growing with the square of the number of links, and recurses once
per level of the tree, so that a very deep tree overflows the stack and crashes the process);
reading is linear in the file size.

Security: a URDF is data from elsewhere. Any document type declaration (``<!DOCTYPE``)
or entity declaration (``<!ENTITY``) is refused *before* parsing, so entity bombs
("billion laughs") and external entities are never expanded or fetched. Without a DTD,
the parser knows no entities besides the five predefined ones.

Every error is a one-line :class:`ValueError` naming the file, the element and the problem.
"""

from __future__ import annotations

import os
import re
import xml.etree.ElementTree as ElementTree
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from screwkit.common.rotations import rotation_from_rpy
from screwkit.common.units import LENGTH_UNITS, metres_per
from screwkit.model.chain import LOOP_JOINT_DOFS

_DECLARATION = re.compile(rb"<!\s*(DOCTYPE|ENTITY)", re.IGNORECASE)
TREE_JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")
"""Joint types of the URDF specification."""
PLATFORM_JOINT_TYPES = ("floating", "planar")
"""Types of the joint that attaches the platform to the base."""
AXIS_JOINT_TYPES = ("revolute", "continuous", "prismatic", "planar")
"""Joint types whose ``<axis>`` means something (a zero axis is refused on them only)."""
LARGEST_COORDINATE = 1e9
"""The largest magnitude of a number in an ``<origin>`` (in the file's length unit, or rad): a robot a
million kilometres across in metres (or a thousand in millimetres), or an angle of 160 million turns,
is a typo or a corrupted file, and its arithmetic would overflow; it is refused naming the element."""
MAX_FILE_BYTES = 16 * 2**20
"""Largest mechanism file read (16 MiB); larger files are refused before parsing."""
MAX_LINKS = 10_000
"""Most links a mechanism file may have; Pinocchio's model building grows with the square of
their number (10,000 links: about 1 s; 148,000 links: 8.5 min), so more are refused after parsing."""
MAX_TREE_DEPTH = 200
"""Most joints between the root link and any link; Pinocchio's URDF parser recurses once per
level and crashes the process on a stack overflow at a few hundred levels in a thread with a
small stack (about 230 with 512 KiB, 3,800 with 8 MiB), so deeper trees are refused."""


@dataclass(frozen=True)
class Origin:
    """A URDF ``<origin>``: translation ``xyz`` (m) and fixed-axis ``rpy`` angles (rad)."""

    xyz: NDArray[np.float64] = field(default_factory=lambda: np.zeros(3))
    rpy: NDArray[np.float64] = field(default_factory=lambda: np.zeros(3))

    @property
    def rotation(self) -> NDArray[np.float64]:
        """Rotation matrix ``Rz(yaw) Ry(pitch) Rx(roll)``."""
        return rotation_from_rpy(self.rpy)

    @property
    def translation(self) -> NDArray[np.float64]:
        """Translation vector."""
        return np.asarray(self.xyz, dtype=float)


@dataclass(frozen=True)
class JointElement:
    """A tree ``<joint>`` as written in the file."""

    name: str
    type: str
    parent: str
    child: str
    origin: Origin
    axis: NDArray[np.float64]
    limits: tuple[float, float] = (-np.inf, np.inf)
    """Position limits (rad or m): ``<limit lower upper>`` of revolute and prismatic joints, else unlimited."""


@dataclass(frozen=True)
class LoopElement:
    """A URDF+ ``<loop>`` joint closing a chain.

    The loop-joint frame is ``predecessor_origin`` in the predecessor link frame and
    ``successor_origin`` in the successor link frame; at the reference configuration the two
    frames coincide up to the loop joint's own motion. ``axes`` are unit vectors in the loop
    frame (``axis`` and, for a universal joint, ``axis2``).
    """

    name: str
    type: str
    predecessor: str
    predecessor_origin: Origin
    successor: str
    successor_origin: Origin
    axes: tuple[NDArray[np.float64], ...]
    chain: str


@dataclass(frozen=True)
class TransmissionElement:
    """A ``<transmission>`` and the joints it drives."""

    name: str
    joints: tuple[str, ...]


@dataclass(frozen=True)
class UrdfDescription:
    """What the safe XML pass read from one URDF document.

    Attributes
    ----------
    source : str
        File path (or ``"<string>"``) used in error messages.
    text : str
        The document, checked to contain no DTD, for :func:`pinocchio.buildModelFromXML`.
    robot_name : str
    links : tuple of str
    joints : dict of str to JointElement
        Tree joints by name.
    loops : tuple of LoopElement
        In file order (chains are then ordered by name, :func:`screwkit.model.builder.chain_order`).
    transmissions : tuple of TransmissionElement
    reference_configuration : dict of str to float
        Joint values of the reference assembly given in ``<reference_configuration>``.
    named_poses : dict of str to dict of str to float
        ``<named_pose name="..." x="..." ...>``: task coordinate values (m, rad) by pose name.
    length_unit : str
        The unit the file was written in (its lengths are converted to metres here).
    task_coordinates : tuple of str or None
        ``<task_coordinates names="z roll pitch"/>``: the independent coordinates a pose is
        given in, for a mechanism of lower mobility (None: inferred).
    output : str
        ``"frame"`` (the platform frame, the default) or ``"point"`` (``<output type="point"/>``:
        the platform frame's origin is a point output, rotations about it are idle).
    """

    source: str
    text: str
    robot_name: str
    links: tuple[str, ...]
    joints: dict[str, JointElement]
    loops: tuple[LoopElement, ...]
    transmissions: tuple[TransmissionElement, ...]
    reference_configuration: dict[str, float]
    named_poses: dict[str, dict[str, float]] = field(default_factory=dict)
    length_unit: str = "m"
    task_coordinates: tuple[str, ...] | None = None
    output: str = "frame"

    def fail(self, element: str, problem: str) -> ValueError:
        """A one-line error naming this file, an element and a problem."""
        return file_error(self.source, element, problem)


def file_error(source: str, element: str, problem: str) -> ValueError:
    """``ValueError("<file>: <element>: <problem>")``, the form of every URDF error."""
    return ValueError(f"{source}: {element}: {problem}")


def read_urdf(path: str | os.PathLike, *, length_unit: str | None = None,
              max_bytes: int = MAX_FILE_BYTES) -> UrdfDescription:
    """Read and check a URDF file (see :func:`parse_urdf`); files above ``max_bytes`` are refused unread."""
    source = str(path)
    try:
        size = os.path.getsize(path)
        if size > max_bytes:
            raise ValueError(f"{source}: the file has {size:,} bytes, more than the {max_bytes:,} bytes screwkit reads "
                             "(screwkit.model.urdf_reader.MAX_FILE_BYTES).")
        data = Path(path).read_bytes()
    except OSError as error:
        raise ValueError(f"{source}: cannot read the file: {error.strerror or error}.") from None
    return parse_urdf(data, source, length_unit=length_unit, max_bytes=max_bytes)


def parse_urdf(document: str | bytes, source: str = "<string>", *, length_unit: str | None = None,
               max_bytes: int = MAX_FILE_BYTES) -> UrdfDescription:
    """Parse a URDF document, refusing DTDs and entity declarations before parsing.

    Parameters
    ----------
    document : str or bytes
        The XML text.
    source : str
        Name used in error messages (the file path).
    length_unit : str, optional
        The unit the document's lengths are written in (one of
        :data:`screwkit.common.units.LENGTH_UNITS`); overrides the file's ``<units length=...>``;
        default metres.
    max_bytes : int
        Largest document accepted.

    Raises
    ------
    ValueError
        On a DTD or entity declaration, malformed XML, or an element that breaks the
        convention (unknown link, unsupported loop type, missing axis, a cycle in the tree, ...).
    """
    data = document.encode("utf-8") if isinstance(document, str) else bytes(document)
    if len(data) > max_bytes:
        raise ValueError(f"{source}: the document has {len(data):,} bytes, more than the {max_bytes:,} bytes "
                         "screwkit reads (screwkit.model.urdf_reader.MAX_FILE_BYTES).")
    declaration = _DECLARATION.search(data)
    if declaration is not None:
        line = data.count(b"\n", 0, declaration.start()) + 1
        raise ValueError(
            f"{source}: <!{declaration.group(1).decode().upper()}> at line {line}: document type and entity "
            "declarations are refused (entity expansion is unsafe and URDF does not need them)."
        )
    try:
        root = ElementTree.fromstring(data)
    except ElementTree.ParseError as error:
        raise ValueError(f"{source}: malformed XML: {error}.") from None
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as error:
        raise ValueError(f"{source}: the file is not UTF-8 text: {error}.") from None
    if root.tag != "robot":
        raise file_error(source, f"<{root.tag}>", "expected the root element <robot>.")
    unit = _length_unit(root, source, length_unit)
    if unit != "m":
        scale_lengths(root, metres_per(unit))
        for element in root.findall("units"):
            element.set("length", "m")  # the text handed on is in metres
        text = '<?xml version="1.0"?>\n' + ElementTree.tostring(root, encoding="unicode") + "\n"
    return _Reader(source).read(root, text, unit)


def _length_unit(root: ElementTree.Element, source: str, given: str | None) -> str:
    """The document's length unit: ``given``, else ``<units length=...>``, else metres."""
    declared = None
    for element in root.findall("units"):
        declared = (element.get("length") or "").strip()
        if declared not in LENGTH_UNITS:
            raise file_error(source, f"<units length='{declared}'>",
                             f"unknown length unit; expected one of {', '.join(LENGTH_UNITS)}.")
    unit = given if given is not None else (declared or "m")
    if unit not in LENGTH_UNITS:
        raise ValueError(f"Unknown length unit {unit!r}; expected one of {', '.join(LENGTH_UNITS)}.")
    return unit


def _scale_attribute(element: ElementTree.Element | None, attribute: str, factor: float) -> None:
    if element is None or element.get(attribute) is None:
        return
    words = element.get(attribute).split()
    try:
        element.set(attribute, " ".join(repr(float(word) * factor) for word in words))
    except ValueError:
        pass  # left as written: the reader reports it with the element's name


def scale_lengths(root: ElementTree.Element, factor: float) -> None:
    """Multiply every length of a URDF tree by ``factor``, in place.

    Lengths are: ``xyz`` of every ``<origin>``; the limits of prismatic joints; primitive
    sizes (box size, cylinder radius and length, sphere radius) and mesh scales of visual and
    collision geometry; the position values of prismatic joints in ``<reference_configuration>``
    and the x, y, z values of ``<named_pose>``. Angles, masses and inertias are left alone
    (inertias are not used by screwkit).
    """
    for origin in root.iter("origin"):
        _scale_attribute(origin, "xyz", factor)
    prismatic = {joint.get("name") for joint in root.findall("joint") if joint.get("type") == "prismatic"}
    prismatic |= {loop.get("name") for loop in root.findall("loop") if loop.get("type") == "prismatic"}
    for joint in root.findall("joint"):
        if joint.get("name") in prismatic:
            for limit in joint.findall("limit"):
                _scale_attribute(limit, "lower", factor)
                _scale_attribute(limit, "upper", factor)
    for geometry in root.iter("geometry"):
        _scale_attribute(geometry.find("box"), "size", factor)
        _scale_attribute(geometry.find("cylinder"), "radius", factor)
        _scale_attribute(geometry.find("cylinder"), "length", factor)
        _scale_attribute(geometry.find("sphere"), "radius", factor)
        mesh = geometry.find("mesh")
        if mesh is not None:
            if mesh.get("scale") is None:
                mesh.set("scale", "1 1 1")
            _scale_attribute(mesh, "scale", factor)
    for configuration in root.findall("reference_configuration"):
        for joint in configuration.findall("joint"):
            if joint.get("name") in prismatic:
                _scale_attribute(joint, "value", factor)
    for pose in root.findall("named_pose"):
        for coordinate in ("x", "y", "z"):
            _scale_attribute(pose, coordinate, factor)


class _Reader:
    """Element-by-element reading with file-and-element error messages."""

    def __init__(self, source: str):
        self.source = source

    def fail(self, element: str, problem: str) -> ValueError:
        return file_error(self.source, element, problem)

    def read(self, root: ElementTree.Element, text: str, length_unit: str = "m") -> UrdfDescription:
        robot_name = root.get("name", "")
        links: dict[str, None] = {}  # ordered, with constant-time lookups
        link_elements = root.findall("link")
        if len(link_elements) > MAX_LINKS:
            raise self.fail(f"<robot name='{robot_name}'>",
                            f"the file has {len(link_elements):,} links, more than the {MAX_LINKS:,} screwkit reads "
                            "(screwkit.model.urdf_reader.MAX_LINKS).")
        for element in link_elements:
            name = self.required_attribute(element, "<link>", "name")
            if name in links:
                raise self.fail(f"<link name='{name}'>", "the link name is used twice.")
            links[name] = None
        link_set = links.keys()
        joints: dict[str, JointElement] = {}
        for element in root.findall("joint"):
            joint = self.read_joint(element, link_set)
            if joint.name in joints:
                raise self.fail(f"<joint name='{joint.name}'>", "the joint name is used twice.")
            joints[joint.name] = joint
        self.check_tree(robot_name, tuple(links), joints)
        loops = []
        for element in root.findall("loop"):
            loop = self.read_loop(element, link_set)
            if loop.name in joints or any(other.name == loop.name for other in loops):
                raise self.fail(f"<loop name='{loop.name}'>", "the name is already used by another joint or loop.")
            loops.append(loop)
        transmissions = tuple(self.read_transmission(element) for element in root.findall("transmission"))
        reference = {}
        for element in root.findall("reference_configuration"):
            for joint_element in element.findall("joint"):
                name = self.required_attribute(joint_element, "<reference_configuration><joint>", "name")
                tag = f"<reference_configuration><joint name='{name}'>"
                if name not in joints:
                    raise self.fail(tag, "names no tree joint of the robot.")
                reference[name] = self.number(joint_element, tag, "value")
        named_poses = {}
        for element in root.findall("named_pose"):
            name = self.required_attribute(element, "<named_pose>", "name")
            tag = f"<named_pose name='{name}'>"
            if name in named_poses:
                raise self.fail(tag, "the pose name is used twice.")
            named_poses[name] = {key: self.number(element, tag, key) for key in element.keys() if key != "name"}
        task_coordinates = None
        for element in root.findall("task_coordinates"):
            task_coordinates = tuple(self.required_attribute(element, "<task_coordinates>", "names").split())
        output = "frame"
        for element in root.findall("output"):
            output = self.required_attribute(element, "<output>", "type")
            if output not in ("frame", "point"):
                raise self.fail(f"<output type='{output}'>", "expected type 'frame' or 'point'.")
        return UrdfDescription(
            source=self.source,
            text=text,
            robot_name=robot_name,
            links=tuple(links),
            joints=joints,
            loops=tuple(loops),
            transmissions=transmissions,
            reference_configuration=reference,
            named_poses=named_poses,
            length_unit=length_unit,
            task_coordinates=task_coordinates,
            output=output,
        )

    def check_tree(self, robot_name: str, links: tuple[str, ...], joints: dict[str, JointElement]) -> None:
        """One root link, one parent joint per link, no cycle: else name the links and joints."""
        parent_joint: dict[str, str] = {}
        for joint in joints.values():
            if joint.child in parent_joint:
                raise self.fail(f"<link name='{joint.child}'>",
                                f"the link has two parents: joints {parent_joint[joint.child]!r} and {joint.name!r} "
                                "(a tree gives every link one parent; close loops with <loop>).")
            if joint.child == joint.parent:
                raise self.fail(f"<joint name='{joint.name}'>",
                                f"the joint connects the link {joint.child!r} to itself.")
            parent_joint[joint.child] = joint.name
        roots = [link for link in links if link not in parent_joint]
        depth: dict[str, int] = {}  # links known to lead to a root: the number of joints above them
        for start in links:
            path, on_path = [], set()
            link = start
            while link in parent_joint and link not in depth:
                if link in on_path:
                    cycle = path[path.index(link):] + [link]
                    spelled = " -> ".join(f"{a} ({parent_joint[a]})" for a in cycle[:-1]) + f" -> {link}"
                    raise self.fail(f"<joint name='{parent_joint[link]}'>",
                                    f"the tree has a cycle of links (joints): {spelled}; close loops with <loop>.")
                on_path.add(link)
                path.append(link)
                link = joints[parent_joint[link]].parent
            above = depth.get(link, 0)  # 0 at a root
            for visited in reversed(path):
                above += 1
                depth[visited] = above
                if above > MAX_TREE_DEPTH:
                    raise self.fail(f"<link name='{visited}'>",
                                    f"the link is {above} joints below the root link, more than the {MAX_TREE_DEPTH} "
                                    "levels screwkit reads (screwkit.model.urdf_reader.MAX_TREE_DEPTH).")
        if len(roots) != 1:
            spelled = ", ".join(repr(link) for link in roots[:5]) + (" ..." if len(roots) > 5 else "")
            raise self.fail(f"<robot name='{robot_name}'>",
                            f"expected one root link (a link that is no joint's child), found {len(roots)}: "
                            f"{spelled or 'none'}.")

    def required_attribute(self, element: ElementTree.Element, tag: str, attribute: str) -> str:
        value = element.get(attribute)
        if value is None or not value.strip():
            raise self.fail(tag, f"the attribute '{attribute}' is missing.")
        return value.strip()

    def vector(self, element: ElementTree.Element | None, tag: str, attribute: str, default) -> NDArray[np.float64]:
        if element is None or element.get(attribute) is None:
            return np.array(default, dtype=float)
        words = element.get(attribute).split()
        try:
            values = np.array([float(word) for word in words])
        except ValueError:
            values = np.array([])
        if values.shape != (3,) or not np.all(np.isfinite(values)):
            raise self.fail(tag, f"expected three finite numbers in '{attribute}', got {element.get(attribute)!r}.")
        if np.max(np.abs(values)) > LARGEST_COORDINATE:
            raise self.fail(tag, f"'{attribute}' = {element.get(attribute)!r} is absurd for a robot: expected "
                                 f"numbers of magnitude at most {LARGEST_COORDINATE:g}.")
        return values

    def number(self, element: ElementTree.Element, tag: str, attribute: str) -> float:
        raw = self.required_attribute(element, tag, attribute)
        try:
            value = float(raw)
        except ValueError:
            value = float("nan")
        if not np.isfinite(value):
            raise self.fail(tag, f"expected a finite number in '{attribute}', got {raw!r}.")
        return value

    def origin(self, element: ElementTree.Element | None, tag: str) -> Origin:
        origin = None if element is None else element.find("origin")
        return Origin(
            xyz=self.vector(origin, f"{tag}<origin>", "xyz", (0.0, 0.0, 0.0)),
            rpy=self.vector(origin, f"{tag}<origin>", "rpy", (0.0, 0.0, 0.0)),
        )

    def axis(self, element: ElementTree.Element, tag: str, name: str, required: bool,
             meaningful: bool = True) -> NDArray[np.float64] | None:
        """A unit axis; a zero axis is refused where the axis means something (``meaningful``)."""
        axis_element = element.find(name)
        if axis_element is None:
            if required:
                raise self.fail(tag, f"the element <{name} xyz='...'/> is missing.")
            return None
        axis = self.vector(axis_element, f"{tag}<{name}>", "xyz", (1.0, 0.0, 0.0))
        norm = np.linalg.norm(axis)
        if norm < 1e-12:
            if not meaningful:
                return None
            raise self.fail(f"{tag}<{name}>", "the axis is the zero vector.")
        return axis / norm

    def link_reference(self, element: ElementTree.Element, tag: str, child: str,
                       links) -> tuple[str, ElementTree.Element]:
        link_element = element.find(child)
        if link_element is None:
            raise self.fail(tag, f"the element <{child} link='...'> is missing.")
        name = self.required_attribute(link_element, f"{tag}<{child}>", "link")
        if name not in links:
            raise self.fail(tag, f"<{child}> names an unknown link {name!r}.")
        return name, link_element

    def read_joint(self, element: ElementTree.Element, links: set[str]) -> JointElement:
        name = self.required_attribute(element, "<joint>", "name")
        tag = f"<joint name='{name}'>"
        joint_type = self.required_attribute(element, tag, "type")
        if joint_type not in TREE_JOINT_TYPES:
            raise self.fail(tag, f"unknown joint type {joint_type!r}; expected one of {', '.join(TREE_JOINT_TYPES)}.")
        parent, _ = self.link_reference(element, tag, "parent", links)
        child, _ = self.link_reference(element, tag, "child", links)
        axis = self.axis(element, tag, "axis", required=False, meaningful=joint_type in AXIS_JOINT_TYPES)
        limits = (-np.inf, np.inf)
        limit = element.find("limit")
        if joint_type in ("revolute", "prismatic") and limit is not None:
            lower = self.number(limit, f"{tag}<limit>", "lower") if limit.get("lower") is not None else -np.inf
            upper = self.number(limit, f"{tag}<limit>", "upper") if limit.get("upper") is not None else np.inf
            if lower > upper:
                raise self.fail(f"{tag}<limit>", f"the lower limit {lower:g} is above the upper limit {upper:g}.")
            limits = (lower, upper)
        return JointElement(
            name=name,
            type=joint_type,
            parent=parent,
            child=child,
            origin=self.origin(element, tag),
            axis=np.array([1.0, 0.0, 0.0]) if axis is None else axis,
            limits=limits,
        )

    def read_loop(self, element: ElementTree.Element, links: set[str]) -> LoopElement:
        name = self.required_attribute(element, "<loop>", "name")
        tag = f"<loop name='{name}'>"
        loop_type = self.required_attribute(element, tag, "type")
        if loop_type not in LOOP_JOINT_DOFS:
            raise self.fail(
                tag, f"unsupported loop joint type {loop_type!r}; expected one of {', '.join(LOOP_JOINT_DOFS)}."
            )
        predecessor, predecessor_element = self.link_reference(element, tag, "predecessor", links)
        successor, successor_element = self.link_reference(element, tag, "successor", links)
        if predecessor == successor:
            raise self.fail(tag, f"the predecessor and successor are the same link {predecessor!r}.")
        axes: tuple[NDArray[np.float64], ...] = ()
        if loop_type in ("revolute", "continuous", "prismatic", "universal"):
            axes = (self.axis(element, tag, "axis", required=True),)
        if loop_type == "universal":
            second = self.axis(element, tag, "axis2", required=True)
            if abs(float(axes[0] @ second)) > 1.0 - 1e-9:
                raise self.fail(tag, "the universal joint's <axis> and <axis2> are parallel.")
            axes = axes + (second,)
        return LoopElement(
            name=name,
            type=loop_type,
            predecessor=predecessor,
            predecessor_origin=self.origin(predecessor_element, f"{tag}<predecessor>"),
            successor=successor,
            successor_origin=self.origin(successor_element, f"{tag}<successor>"),
            axes=axes,
            chain=element.get("chain", name).strip() or name,
        )

    def read_transmission(self, element: ElementTree.Element) -> TransmissionElement:
        name = element.get("name", "").strip() or "(unnamed)"
        tag = f"<transmission name='{name}'>"
        joints = tuple(self.required_attribute(joint, f"{tag}<joint>", "name") for joint in element.findall("joint"))
        if not joints:
            raise self.fail(tag, "drives no joint (expected <joint name='...'> inside).")
        return TransmissionElement(name=name, joints=joints)
