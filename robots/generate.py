"""Generate the bundled URDF files from their parameters.

Run ``python -m screwkit.robots.generate`` (optionally with an output folder) to rewrite the
``*.urdf`` files next to this module. The files are committed; this script documents and
reproduces them. Geometry of each robot: ``robots/README.md``.

Every file follows ``docs/urdf-convention.md``: the platform hangs from the base by a
``planar`` or ``floating`` joint, each leg is a serial chain of tree joints from the base,
closed onto the platform by a URDF+ ``<loop>`` joint; ``<transmission>`` marks the actuators.
All joint values are zero in the reference assembly unless ``<reference_configuration>`` says
otherwise, and the loops close there exactly.
"""

from __future__ import annotations

import math
import sys
import xml.etree.ElementTree as ElementTree
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from screwkit.kinematics import rotation_from_rpy, rpy_from_rotation

FOLDER = Path(__file__).resolve().parent
Z_AXIS = np.array([0.0, 0.0, 1.0])


# ---------------------------------------------------------------------------------------------
# Writing helpers
# ---------------------------------------------------------------------------------------------


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
                joint, "limit", lower=_number(lower), upper=_number(upper), effort=_number(effort), velocity=_number(velocity)
            )

    def loop(
        self, name, loop_type, chain, predecessor, predecessor_pose, successor, successor_pose, axis=None, second_axis=None
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

    def reference_configuration(self, values: dict[str, float]) -> None:
        element = ElementTree.SubElement(self.robot, "reference_configuration")
        for name, value in values.items():
            ElementTree.SubElement(element, "joint", name=name, value=_number(value))

    def text(self) -> str:
        ElementTree.indent(self.robot, space="  ")
        return '<?xml version="1.0"?>\n' + ElementTree.tostring(self.robot, encoding="unicode") + "\n"


def _frame_rpy(x_axis: NDArray, y_axis: NDArray) -> NDArray:
    """rpy of the frame with the given x and y axes (z = x cross y)."""
    rotation = np.column_stack([x_axis, y_axis, np.cross(x_axis, y_axis)])
    return rpy_from_rotation(rotation)


def _unit(vector: NDArray) -> NDArray:
    return vector / np.linalg.norm(vector)


def _angle(vector: NDArray) -> float:
    return math.atan2(vector[1], vector[0])


# ---------------------------------------------------------------------------------------------
# planar_5rrr: the paper's Table 2
# ---------------------------------------------------------------------------------------------

FIVE_RRR = {"gamma": 2 * math.pi / 5, "base_radius": 1.0, "platform_radius": 0.1, "proximal": 1.0, "distal": 1.0}


def five_rrr_points(parameters: dict = FIVE_RRR) -> tuple[NDArray, NDArray]:
    """Base joints b_i (5, 2) and platform joints d_i in the platform frame (5, 2)."""
    gamma, e, g = parameters["gamma"], parameters["base_radius"], parameters["platform_radius"]
    index = np.arange(5)
    base = e * np.column_stack([np.cos(index * gamma), np.sin(index * gamma)])
    platform = g * np.column_stack([np.cos(3 * index * gamma), np.sin(3 * index * gamma)])
    return base, platform


def elbow(base: NDArray, end: NDArray, proximal: float, distal: float, side: float = 1.0) -> NDArray:
    """Elbow c of an R-R-R leg, on the ``side`` (+1: left, the +u_perp side) of the line base -> end."""
    delta = end - base
    distance = np.linalg.norm(delta)
    along = (proximal**2 - distal**2 + distance**2) / (2 * distance)
    height = side * math.sqrt(proximal**2 - along**2)
    unit = delta / distance
    return base + along * unit + height * np.array([-unit[1], unit[0]])


def planar_rrr_urdf(name: str, base: NDArray, platform: NDArray, proximal, distal, working_mode=1.0,
                    comment: str = "") -> str:
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
        chain = f"chain_{i + 1}"
        b, d, a, l = base[i], platform[i], float(proximal[i]), float(distal[i])
        c = elbow(b, d, a, l, side=float(sides[i]))
        first_angle, second_angle = _angle(c - b), _angle(d - c)
        writer.rod(f"{chain}_link_a", a)
        writer.rod(f"{chain}_link_l", l)
        writer.joint(f"{chain}_joint_b", "continuous", "base_link", f"{chain}_link_a",
                     xyz=(b[0], b[1], 0), rpy=(0, 0, first_angle), axis=(0, 0, 1))  # fmt: skip
        writer.joint(f"{chain}_joint_c", "continuous", f"{chain}_link_a", f"{chain}_link_l",
                     xyz=(a, 0, 0), rpy=(0, 0, second_angle - first_angle), axis=(0, 0, 1))  # fmt: skip
        writer.loop(f"{chain}_joint_d", "revolute", chain,
                    f"{chain}_link_l", ((l, 0, 0), (0, 0, -second_angle)),
                    "platform", ((d[0], d[1], 0), (0, 0, 0)), axis=(0, 0, 1))  # fmt: skip
        writer.transmission(f"{chain}_joint_b")
    return writer.text()


def planar_5rrr() -> str:
    parameters = FIVE_RRR
    base, platform = five_rrr_points(parameters)
    return planar_rrr_urdf(
        "planar_5rrr", base, platform, parameters["proximal"], parameters["distal"], 1.0,
        " Planar 5-RRR of the paper (Table 2): e = 1.0 m, g = 0.1 m, a_i = l_i = 1.0 m, gamma = 2 pi / 5. "
        "Reference assembly: platform at x = y = 0, phi = 0, every elbow c_i on the +u_perp side of b_i -> d_i. "
        "Generated by python -m screwkit.robots.generate ",
    )


# ---------------------------------------------------------------------------------------------
# planar_4rpr: Fig. 1 type
# ---------------------------------------------------------------------------------------------

FOUR_RPR = {
    "base": np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]]),
    "platform": np.array([[-0.2, -0.1], [0.2, -0.1], [0.2, 0.1], [-0.2, 0.1]]),
    "stroke": (0.3, 2.5),  # leg length limits (m)
    "concurrent_y": 0.0,  # the documented three-lines pose has y = 0 and phi = 0.4 rad,
    "concurrent_phi": 0.4,  # x solved for (see four_rpr_concurrent_pose)
    "concurrent_bracket": (-0.4, 0.0),
}


def four_rpr_concurrent_pose(parameters: dict = FOUR_RPR) -> tuple[NDArray, NDArray]:
    """Pose (x, y, phi) where leg lines 1, 2, 3 meet in one point, and that point.

    ``y`` and ``phi`` are fixed (``concurrent_y``, ``concurrent_phi``); ``x`` is the root of the
    distance from line 3 to the intersection of lines 1 and 2, found by bisection.
    """
    base, platform = parameters["base"], parameters["platform"]
    y, phi = parameters["concurrent_y"], parameters["concurrent_phi"]
    rotation = np.array([[math.cos(phi), -math.sin(phi)], [math.sin(phi), math.cos(phi)]])

    def intersection(x: float) -> tuple[float, NDArray]:
        ends = np.array([x, y]) + platform @ rotation.T
        directions = ends - base
        matrix = np.column_stack([directions[0], -directions[1]])
        parameters_12 = np.linalg.solve(matrix, base[1] - base[0])
        point = base[0] + parameters_12[0] * directions[0]
        normal = np.array([-directions[2][1], directions[2][0]]) / np.linalg.norm(directions[2])
        return float((point - base[2]) @ normal), point

    low, high = parameters["concurrent_bracket"]
    if intersection(low)[0] * intersection(high)[0] > 0:
        raise RuntimeError("no three-line concurrency in the bracket")
    for _ in range(200):
        middle = 0.5 * (low + high)
        if intersection(low)[0] * intersection(middle)[0] <= 0:
            high = middle
        else:
            low = middle
    x = 0.5 * (low + high)
    distance, point = intersection(x)
    if abs(distance) > 1e-12:
        raise RuntimeError(f"the bisection found a pole, not a root (distance {distance})")
    return np.array([x, y, phi]), point


def planar_4rpr() -> str:
    parameters = FOUR_RPR
    base, platform = parameters["base"], parameters["platform"]
    lower, upper = parameters["stroke"]
    writer = UrdfWriter(
        "planar_4rpr",
        " Planar 4-RPR (Fig. 1 type): base joints at (+-1, +-1) m, platform joints at (+-0.2, +-0.1) m, "
        "passive R at base and platform, actuated P along each leg. Reference assembly: x = y = phi = 0. "
        "Generated by python -m screwkit.robots.generate ",
    )
    writer.link("base_link", ("box", (2.2, 2.2, 0.01)), xyz=(0, 0, -0.02))
    writer.link("platform", ("box", (0.44, 0.24, 0.02)))
    writer.joint("platform_joint", "planar", "base_link", "platform", axis=(0, 0, 1))
    for i in range(4):
        chain = f"leg_{i + 1}"
        b, d = base[i], platform[i]
        yaw = _angle(d - b)
        length = float(np.linalg.norm(d - b))
        writer.rod(f"{chain}_cylinder", 0.6 * length, radius=0.03)
        writer.rod(f"{chain}_piston", length, radius=0.015)
        writer.joint(f"{chain}_joint_base", "continuous", "base_link", f"{chain}_cylinder",
                     xyz=(b[0], b[1], 0), rpy=(0, 0, yaw), axis=(0, 0, 1))  # fmt: skip
        writer.joint(f"{chain}_joint_slider", "prismatic", f"{chain}_cylinder", f"{chain}_piston",
                     axis=(1, 0, 0), limit=(lower - length, upper - length, 1000.0, 1.0))  # fmt: skip
        writer.loop(f"{chain}_joint_platform", "revolute", chain,
                    f"{chain}_piston", ((length, 0, 0), (0, 0, -yaw)),
                    "platform", ((d[0], d[1], 0), (0, 0, 0)), axis=(0, 0, 1))  # fmt: skip
        writer.transmission(f"{chain}_joint_slider")
    return writer.text()


# ---------------------------------------------------------------------------------------------
# Hexapods with 8 legs
# ---------------------------------------------------------------------------------------------

UPS_HEXAPOD = {
    "legs": 8,
    "base_radius": 1.0,
    "platform_radius": 0.5,
    "height": 1.0,
    "platform_slots": (0, 4, 2, 7, 5, 3, 1, 6),
}
RSS_HEXAPOD = {
    "legs": 8,
    "base_radius": 1.0,
    "crank": 0.4,
    "platform_radius": 0.5,
    "height": 0.9,
    "platform_slots": (1, 0, 3, 5, 2, 7, 4, 6),
}


def hexapod_points(parameters: dict) -> tuple[NDArray, NDArray]:
    """Base points b_i (n, 3) at z = 0 and platform points p_i (n, 3) in the platform frame.

    Base and platform points sit at the n uniform angles ``360 deg * k / n`` of their circles;
    leg i runs from base slot i to platform slot ``platform_slots[i]``. (One leg per uniform
    slot with ``platform_slots[i] = i + const`` would be architecturally singular: the
    rotationally symmetric set of leg lines spans only 3 dimensions.)
    """
    n = parameters["legs"]
    angles = 2 * math.pi * np.arange(n) / n
    base = parameters["base_radius"] * np.column_stack([np.cos(angles), np.sin(angles), np.zeros(n)])
    platform_angles = 2 * math.pi * np.asarray(parameters["platform_slots"]) / n
    platform = parameters["platform_radius"] * np.column_stack(
        [np.cos(platform_angles), np.sin(platform_angles), np.zeros(n)]
    )
    return base, platform


def worst_submechanism(line_points: NDArray, platform_points: NDArray, moment_scale: float) -> tuple[float, float]:
    """Smallest singular value over all 6-leg subsets, and of all legs, of the leg-line matrix.

    Rows are the unit leg lines ``(u, p x u / moment_scale)`` through ``line_points`` and
    ``platform_points`` (n, 3), both in the base frame.
    """
    directions = platform_points - line_points
    directions = directions / np.linalg.norm(directions, axis=-1, keepdims=True)
    lines = np.concatenate([directions, np.cross(platform_points, directions) / moment_scale], -1)
    import itertools

    subsets = np.array(list(itertools.combinations(range(len(lines)), 6)))
    worst = float(np.min(np.linalg.svd(lines[subsets], compute_uv=False)[..., -1]))
    return worst, float(np.linalg.svd(lines, compute_uv=False)[-1])


def best_platform_slots(line_points: NDArray, parameters: dict) -> tuple[tuple[int, ...], float]:
    """Exhaustive search (n! assignments, ~15 s for n = 8) of the leg-to-platform-slot assignment.

    Maximises :func:`worst_submechanism` at the reference pose, the way the paper chose the
    platform-joint permutation of its 5-RRR. This is how ``platform_slots`` were chosen; it is
    not run by :func:`main`.
    """
    import itertools

    best, best_value = None, -1.0
    for slots in itertools.permutations(range(parameters["legs"])):
        _, platform = hexapod_points({**parameters, "platform_slots": slots})
        value = worst_submechanism(line_points, platform + [0, 0, parameters["height"]], parameters["platform_radius"])[0]
        if value > best_value + 1e-12:
            best, best_value = slots, value
    return best, best_value


def _universal_axes(direction: NDArray) -> tuple[NDArray, NDArray]:
    """Two unit axes perpendicular to ``direction`` (the first horizontal)."""
    first = _unit(np.cross(Z_AXIS, direction))
    return first, np.cross(direction, first)


def ups_hexapod_8() -> str:
    parameters = UPS_HEXAPOD
    base, platform = hexapod_points(parameters)
    height = parameters["height"]
    writer = UrdfWriter(
        "ups_hexapod_8",
        " 8-UPS hexapod: base joints at 45 deg steps on a 1.0 m circle (z = 0), platform joints at 45 deg "
        "steps on a 0.5 m circle, leg i to platform slot (0, 4, 2, 7, 5, 3, 1, 6)[i], platform 1.0 m above "
        "the base in the reference assembly; actuated prismatic legs. "
        "Generated by python -m screwkit.robots.generate ",
    )
    writer.link("base_link", ("cylinder", 1.05, 0.01), xyz=(0, 0, -0.02))
    writer.link("platform", ("cylinder", 0.55, 0.02))
    writer.joint("platform_joint", "floating", "base_link", "platform", xyz=(0, 0, height))
    for i in range(parameters["legs"]):
        chain = f"leg_{i + 1}"
        top = platform[i] + np.array([0, 0, height])
        direction = _unit(top - base[i])
        length = float(np.linalg.norm(top - base[i]))
        first_axis, second_axis = _universal_axes(direction)
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
    return writer.text()


def rss_hexapod_8() -> str:
    parameters = RSS_HEXAPOD
    base, platform = hexapod_points(parameters)
    height, crank = parameters["height"], parameters["crank"]
    writer = UrdfWriter(
        "rss_hexapod_8",
        " 8-RSS hexapod (modelled R-U-S: the rod's idle spin is removed): crank pivots at 45 deg steps on a "
        "1.0 m circle (z = 0), horizontal crank axes tangent to it, 0.4 m cranks pointing radially outwards "
        "in the reference assembly, platform joints at 45 deg steps on a 0.5 m circle, leg i to platform slot "
        "(1, 0, 3, 5, 2, 7, 4, 6)[i], platform 0.9 m above the base; actuated cranks. "
        "Generated by python -m screwkit.robots.generate ",
    )
    writer.link("base_link", ("cylinder", 1.45, 0.01), xyz=(0, 0, -0.02))
    writer.link("platform", ("cylinder", 0.55, 0.02))
    writer.joint("platform_joint", "floating", "base_link", "platform", xyz=(0, 0, height))
    for i in range(parameters["legs"]):
        chain = f"leg_{i + 1}"
        angle = _angle(base[i])
        radial = np.array([math.cos(angle), math.sin(angle), 0.0])
        crank_rotation = rotation_from_rpy(np.array([0.0, 0.0, angle]))
        crank_end = base[i] + crank * radial
        top = platform[i] + np.array([0, 0, height])
        direction = _unit(top - crank_end)
        rod_length = float(np.linalg.norm(top - crank_end))
        first_axis, second_axis = _universal_axes(direction)
        rod_rotation = np.column_stack([direction, first_axis, second_axis])
        writer.rod(f"{chain}_crank", crank, radius=0.03)
        writer.link(f"{chain}_cross", ("sphere", 0.03))
        writer.rod(f"{chain}_rod", rod_length)
        writer.joint(f"{chain}_joint_crank", "revolute", "base_link", f"{chain}_crank",
                     xyz=base[i], rpy=(0, 0, angle), axis=(0, 1, 0),
                     limit=(-math.pi, math.pi, 200.0, 3.0))  # fmt: skip
        writer.joint(f"{chain}_joint_u1", "continuous", f"{chain}_crank", f"{chain}_cross",
                     xyz=(crank, 0, 0), rpy=rpy_from_rotation(crank_rotation.T @ rod_rotation), axis=(0, 1, 0))  # fmt: skip
        writer.joint(f"{chain}_joint_u2", "continuous", f"{chain}_cross", f"{chain}_rod", axis=(0, 0, 1))
        writer.loop(f"{chain}_joint_s", "spherical", chain,
                    f"{chain}_rod", ((rod_length, 0, 0), (0, 0, 0)),
                    "platform", (platform[i], rpy_from_rotation(rod_rotation)))  # fmt: skip
        writer.transmission(f"{chain}_joint_crank")
    return writer.text()


# ---------------------------------------------------------------------------------------------
# coop_arms: two UR5 (example-robot-data) rigidly holding one object
# ---------------------------------------------------------------------------------------------

UR5_JOINTS = ("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint")
COOP_ARMS = {
    "reference": (0.0, -1.3, 1.6, -0.3, 1.5707963267948966, 0.0),  # both arms (rad): tool0 z horizontal
    "grasp_offset": 0.1,  # object centre 0.1 m along each tool0 z axis
}


def example_robot_data_ur5() -> Path:
    """The UR5 URDF of the installed example-robot-data (data-only wheel, located by hand)."""
    import sysconfig

    for key in ("purelib", "platlib"):
        candidate = Path(sysconfig.get_paths()[key]) / "cmeel.prefix/share/example-robot-data/robots/ur_description/urdf/ur5_robot.urdf"
        if candidate.is_file():
            return candidate
    raise FileNotFoundError("example-robot-data's ur_description/urdf/ur5_robot.urdf is not installed")


def _ur5_joints() -> list[dict]:
    """Kinematics of the UR5 arm joints and of its tool0 frame, read from example-robot-data."""
    from screwkit.urdf import read_urdf

    description = read_urdf(example_robot_data_ur5())  # the safe pass: no DTD, no entities
    names = UR5_JOINTS + ("wrist_3_link-tool0_fixed_joint",)
    root = ElementTree.fromstring(description.text)
    limits = {
        element.get("name"): element.find("limit") for element in root.findall("joint") if element.find("limit") is not None
    }
    joints = []
    for name in names:
        joint = description.joints[name]
        limit = limits.get(name)
        joints.append(
            {
                "name": name,
                "type": joint.type,
                "parent": joint.parent,
                "child": joint.child,
                "xyz": joint.origin.xyz,
                "rpy": joint.origin.rpy,
                "axis": joint.axis,
                "limit": None
                if limit is None
                else tuple(float(limit.get(key)) for key in ("lower", "upper", "effort", "velocity")),
            }
        )
    return joints


def _ur5_tool_pose(joints: list[dict], values) -> tuple[NDArray, NDArray]:
    """tool0 frame in the arm base frame at joint ``values`` (product of URDF transforms)."""
    from screwkit.kinematics import rotation_about_axis

    rotation, translation = np.eye(3), np.zeros(3)
    for index, joint in enumerate(joints):
        translation = translation + rotation @ joint["xyz"]
        rotation = rotation @ rotation_from_rpy(joint["rpy"])
        if joint["type"] != "fixed":
            rotation = rotation @ rotation_about_axis(joint["axis"], values[index])
    return rotation, translation


def coop_arms() -> str:
    parameters = COOP_ARMS
    joints = _ur5_joints()
    reference = parameters["reference"]
    tool_rotation, tool_translation = _ur5_tool_pose(joints, reference)
    grasp = tool_translation + parameters["grasp_offset"] * tool_rotation[:, 2]
    # Left arm base placed so that the object centre is above the base origin; the right arm is
    # the left one turned by 180 deg about the vertical line through the object centre.
    left_base = np.array([-grasp[0], -grasp[1], 0.0])
    object_position = np.array([0.0, 0.0, grasp[2]])
    turn = rotation_from_rpy(np.array([0.0, 0.0, math.pi]))
    right_base = turn @ left_base
    writer = UrdfWriter(
        "coop_arms",
        " Two UR5 arms (kinematics from example-robot-data 6.0.0 ur5_robot.urdf, primitive geometry) rigidly "
        "holding one object 0.1 m in front of each tool0; the right arm is the left one turned by 180 deg "
        "about the vertical through the object centre. 12 actuators, 6 DOF. "
        "Generated by python -m screwkit.robots.generate ",
    )
    writer.link("base_link", ("box", (1.2, 0.6, 0.01)), xyz=(0, 0, -0.01))
    writer.link("object", ("box", (0.2, 0.05, 0.05)))
    writer.joint("object_joint", "floating", "base_link", "object", xyz=object_position)
    reference_values = {}
    for side, base_position, base_yaw in (("left", left_base, 0.0), ("right", right_base, math.pi)):
        writer.link(f"{side}_base_link", ("cylinder", 0.075, 0.09), xyz=(0, 0, 0.045))
        writer.joint(f"{side}_mount", "fixed", "base_link", f"{side}_base_link", xyz=base_position, rpy=(0, 0, base_yaw))
        for joint in joints:
            child = f"{side}_{joint['child']}"
            writer.link(child, None if joint["type"] == "fixed" else ("sphere", 0.05))
            writer.joint(
                f"{side}_{joint['name']}", joint["type"], f"{side}_{joint['parent']}", child,
                xyz=joint["xyz"], rpy=joint["rpy"], axis=None if joint["type"] == "fixed" else joint["axis"],
                limit=joint["limit"],
            )  # fmt: skip
        for name, value in zip(UR5_JOINTS, reference):
            reference_values[f"{side}_{name}"] = value
            writer.transmission(f"{side}_{name}")
    for side, yaw in (("left", 0.0), ("right", math.pi)):
        side_turn = rotation_from_rpy(np.array([0.0, 0.0, yaw]))
        grasp_rotation = side_turn @ tool_rotation
        # loop frame = tool0 frame moved grasp_offset along its z axis; written in the object frame
        writer.loop(
            f"{side}_grasp", "fixed", f"{side}_arm",
            f"{side}_tool0", ((0, 0, parameters["grasp_offset"]), (0, 0, 0)),
            "object", ((0, 0, 0), rpy_from_rotation(grasp_rotation)),
        )  # fmt: skip
    writer.reference_configuration(reference_values)
    return writer.text()


GENERATORS = {
    "planar_5rrr": planar_5rrr,
    "planar_4rpr": planar_4rpr,
    "ups_hexapod_8": ups_hexapod_8,
    "rss_hexapod_8": rss_hexapod_8,
    "coop_arms": coop_arms,
}
"""Bundled mechanism name -> function returning its URDF text."""


def main(arguments: list[str] | None = None) -> None:
    """Write every bundled URDF into the folder given as argument (default: this package)."""
    arguments = sys.argv[1:] if arguments is None else arguments
    folder = Path(arguments[0]) if arguments else FOLDER
    folder.mkdir(parents=True, exist_ok=True)
    for name, generator in GENERATORS.items():
        path = folder / f"{name}.urdf"
        path.write_text(generator())
        print(f"wrote {path}")


if __name__ == "__main__":
    main()
