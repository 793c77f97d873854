"""Element-by-element reading of a parsed URDF (:class:`ElementReader`), with file-and-element errors.

It checks every element against the convention (names, types, links, numbers, axes) and the tree's
shape (one root link, one parent per link, no cycle), and refuses trees of more than
:data:`MAX_LINKS` links or deeper than :data:`MAX_TREE_DEPTH` joints before Pinocchio sees them.
Documents come here from :func:`screwkit.model.urdf_reader.parse_urdf`, checked for DTDs and in metres.
"""

from __future__ import annotations

import xml.etree.ElementTree as ElementTree

import numpy as np
from numpy.typing import NDArray

from screwkit.common.units import MAX_ANGLE_TURNS, angle_limit, is_angular
from screwkit.model.chain import LOOP_JOINT_DOFS
from screwkit.model.urdf_description import (
    AXIS_JOINT_TYPES,
    TREE_JOINT_TYPES,
    JointElement,
    LoopElement,
    Origin,
    TransmissionElement,
    UrdfDescription,
    file_error,
)

LARGEST_COORDINATE = 1e9
"""The largest magnitude of a number in an ``<origin>`` (in the file's length unit, or rad): a robot a
million kilometres across in metres (or a thousand in millimetres), or an angle of 160 million turns,
is a typo or a corrupted file, and its arithmetic would overflow; it is refused naming the element."""
MAX_LINKS = 10_000
"""Most links a mechanism file may have; Pinocchio's model building grows with the square of
their number (10,000 links: about 1 s; 148,000 links: 8.5 min), so more are refused after parsing."""
MAX_TREE_DEPTH = 200
"""Most joints between the root link and any link; Pinocchio's URDF parser recurses once per
level and crashes the process on a stack overflow at a few hundred levels in a thread with a
small stack (about 230 with 512 KiB, 3,800 with 8 MiB), so deeper trees are refused."""


MIMIC_REFUSED = ("coupled (mimic) joints are not modelled; remove the <mimic> element to analyse the joints as "
                 "independent")
NO_LOOP_EITHER = ("; the file closes no loop either (no <loop>): a closed-loop robot of another tool needs its "
                  "robot.yaml beside it, closing_<name>_1 / closing_<name>_2 frame pairs, <gazebo><joint> or "
                  "<drake:ball_constraint> elements, or an MJCF file (docs/other-formats.md); a parallel robot written "
                  "as a tree with <mimic> joints is not one.")
"""What a ``<mimic>``'s refusal adds when the file has no ``<loop>``: removing the ``<mimic>`` would only meet the
refusal of a tree."""


class ElementReader:
    """Element-by-element reading with file-and-element error messages."""

    def __init__(self, source: str):
        self.source = source

    def fail(self, element: str, problem: str) -> ValueError:
        """A one-line error naming the file, ``element`` and ``problem``."""
        return file_error(self.source, element, problem)

    def read(self, root: ElementTree.Element, text: str, length_unit: str = "m") -> UrdfDescription:
        """Read and check every element of a parsed document (``text`` its text in metres)."""
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
        self.closes = root.find("loop") is not None  # (a <mimic>'s refusal says when the file closes no loop)
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
            named_poses[name] = self.named_pose(element, tag)
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
            read_text=text,
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
        """An attribute's value, stripped; a missing or blank attribute is an error."""
        value = element.get(attribute)
        if value is None or not value.strip():
            raise self.fail(tag, f"the attribute '{attribute}' is missing.")
        return value.strip()

    def vector(self, element: ElementTree.Element | None, tag: str, attribute: str, default) -> NDArray[np.float64]:
        """Three finite numbers of sensible size in an attribute, or ``default`` when it is absent."""
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
        """One finite number in a required attribute."""
        raw = self.required_attribute(element, tag, attribute)
        try:
            value = float(raw)
        except ValueError:
            value = float("nan")
        if not np.isfinite(value):
            raise self.fail(tag, f"expected a finite number in '{attribute}', got {raw!r}.")
        return value

    def origin(self, element: ElementTree.Element | None, tag: str) -> Origin:
        """The ``<origin>`` inside an element (zero translation and angles when absent)."""
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
        """The link named by a child element (``<parent link=...>``, ...) and that element; it must exist."""
        link_element = element.find(child)
        if link_element is None:
            raise self.fail(tag, f"the element <{child} link='...'> is missing.")
        name = self.required_attribute(link_element, f"{tag}<{child}>", "link")
        if name not in links:
            raise self.fail(tag, f"<{child}> names an unknown link {name!r}.")
        return name, link_element

    def read_joint(self, element: ElementTree.Element, links: set[str]) -> JointElement:
        """A tree ``<joint>``: its type, links, origin, axis and limits."""
        name = self.required_attribute(element, "<joint>", "name")
        tag = f"<joint name='{name}'>"
        joint_type = self.required_attribute(element, tag, "type")
        if joint_type not in TREE_JOINT_TYPES:
            raise self.fail(tag, f"unknown joint type {joint_type!r}; expected one of {', '.join(TREE_JOINT_TYPES)}.")
        parent, _ = self.link_reference(element, tag, "parent", links)
        child, _ = self.link_reference(element, tag, "child", links)
        axis = self.axis(element, tag, "axis", required=False, meaningful=joint_type in AXIS_JOINT_TYPES)
        limits, drive_limits = (-np.inf, np.inf), (np.inf, np.inf)
        limit = element.find("limit")
        if limit is not None:
            limits, drive_limits = self.limit(limit, f"{tag}<limit>", joint_type)
        elif joint_type in ("revolute", "prismatic"):
            hint = "; a revolute joint without limits is of type 'continuous'" if joint_type == "revolute" else ""
            raise self.fail(f"{tag}<limit>",
                            "the element is missing: URDF requires <limit effort='...' velocity='...'/> "
                            f"on a {joint_type} joint (lower and upper optional){hint}.")
        mimic = element.find("mimic")
        if mimic is not None:
            mimicked = (mimic.get("joint") or "").strip()
            raise self.fail(f"{tag}<mimic joint='{mimicked}'>" if mimicked else f"{tag}<mimic>",
                            MIMIC_REFUSED + ("." if getattr(self, "closes", True) else NO_LOOP_EITHER))
        return JointElement(
            name=name,
            type=joint_type,
            parent=parent,
            child=child,
            origin=self.origin(element, tag),
            axis=np.array([1.0, 0.0, 0.0]) if axis is None else axis,
            limits=limits,
            drive_limits=drive_limits,
        )

    def limit(self, limit: ElementTree.Element, tag: str,
              joint_type: str) -> tuple[tuple[float, float], tuple[float, float]]:
        """A joint's ``<limit>``: its position limits (unlimited but on revolute and prismatic joints) and its effort
        and velocity. As urdfdom (Pinocchio's URDF parser) on every joint type: effort and velocity are required,
        lower and upper optional, every number finite; as Pinocchio: effort and velocity not negative on the joints
        it gives them to."""
        missing = [attribute for attribute in ("effort", "velocity") if not (limit.get(attribute) or "").strip()]
        if missing:
            spelled = " and ".join(f"'{attribute}'" for attribute in missing)
            raise self.fail(tag, f"the attribute{'s' if len(missing) > 1 else ''} {spelled} "
                                 f"{'are' if len(missing) > 1 else 'is'} missing: URDF requires effort and velocity on "
                                 "every <limit> (lower and upper are optional).")
        effort, velocity = self.number(limit, tag, "effort"), self.number(limit, tag, "velocity")
        lower = self.number(limit, tag, "lower") if limit.get("lower") is not None else -np.inf
        upper = self.number(limit, tag, "upper") if limit.get("upper") is not None else np.inf
        if joint_type in ("revolute", "prismatic", "continuous"):
            for attribute, value in (("effort", effort), ("velocity", velocity)):
                if value < 0:
                    raise self.fail(tag, f"expected a number of at least 0 in '{attribute}', got "
                                         f"{limit.get(attribute).strip()!r} (the largest {attribute} of the joint).")
        if joint_type not in ("revolute", "prismatic"):
            return (-np.inf, np.inf), (effort, velocity)
        if lower > upper:
            raise self.fail(tag, f"the lower limit {lower:g} is above the upper limit {upper:g}.")
        return (lower, upper), (effort, velocity)

    def named_pose(self, element: ElementTree.Element, tag: str) -> dict[str, float]:
        """A ``<named_pose>``'s coordinates: finite numbers, angles within
        :data:`~screwkit.common.units.MAX_ANGLE_TURNS` turns either way (the coordinates themselves are checked
        against the mechanism's when it is loaded)."""
        values = {key: self.number(element, tag, key) for key in element.keys() if key != "name"}
        largest = angle_limit(degrees=False)
        for key, value in values.items():
            if is_angular(key) and abs(value) > largest:
                raise self.fail(tag, f"expected angles of at most {largest:g} rad ({MAX_ANGLE_TURNS} turns) either "
                                     f"way, got {key} = {element.get(key).strip()} rad.")
        return values

    def read_loop(self, element: ElementTree.Element, links: set[str]) -> LoopElement:
        """A ``<loop>``: its type, predecessor and successor links with their origins, and axes."""
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
        """A ``<transmission>`` and the joints it drives (at least one)."""
        name = element.get("name", "").strip() or "(unnamed)"
        tag = f"<transmission name='{name}'>"
        joints = tuple(self.required_attribute(joint, f"{tag}<joint>", "name") for joint in element.findall("joint"))
        if not joints:
            raise self.fail(tag, "drives no joint (expected <joint name='...'> inside).")
        driven = tuple(joint for joint, node in zip(joints, element.findall("joint")) if not passive_joint(node))
        return TransmissionElement(name=name, joints=driven)


def passive_joint(joint: ElementTree.Element) -> bool:
    """Whether a ``<transmission>``'s ``<joint>`` names hardware interfaces, all of them passive ones
    (``PassiveJointInterface``: a closed-loop simulator's joint that the loop moves): it drives nothing."""
    interfaces = [(node.text or "").strip() for node in joint.iter("hardwareInterface")]
    return bool(interfaces) and all("passive" in interface.rsplit("/", 1)[-1].lower() for interface in interfaces)
