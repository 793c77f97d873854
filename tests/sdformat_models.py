"""Parallel robots written in SDFormat as their users write them: every joint native, loops included (test helper).

* :func:`five_bar_sdf`: the five-bar of tests/test_io.py (geometry from tests/test_lower_mobility.py), each distal
  link jointed to the ``effector`` by a revolute joint; the world scaled, turned and shifted through the model's
  ``<pose>`` (in degrees), links placed relative to one another, the effector's pose a quaternion, axes written in
  the joint frame or in ``__model__``, motors marked ``<screwkit:actuated/>`` or driven by controller plugins;
* :func:`delta_sdf`: the rod-level Delta of tests/delta_rods.py, its link frames where that file's MJCF bodies
  are (so MuJoCo's reading of the MJCF is a reference for this file's link poses), rods placed relative to their
  arms and the platform's joints written in the platform or in the rods' frames.
"""

from __future__ import annotations

import numpy as np
from delta_rods import SPACING, delta_geometry, quaternion
from test_io import HOME, text
from test_lower_mobility import FIVE_BAR_BASE, PROXIMAL, five_bar_elbows

from screwkit.common.rotations import rotation_from_rpy

NAMESPACE = 'xmlns:screwkit="https://screwkit.org/sdformat"'
EFFECTOR_RPY = (np.pi, 0.0, 0.3)
"""The effector link's frame in the model frame: upside down (its z against the plane's normal), turned."""


def rotation_z(angle: float) -> np.ndarray:
    return rotation_from_rpy(np.array([0.0, 0.0, angle]))


def quaternion_text(rotation) -> str:
    """``qx qy qz qw`` of a rotation matrix (SDFormat's quat_xyzw order)."""
    w, x, y, z = quaternion(rotation)
    return text((x, y, z, w))


def five_bar_sdf(transform=(1.0, 0.0, (0.0, 0.0, 0.0)), order=None, motor=None, legs=3, marker="screwkit",
                 stage: bool = False) -> str:
    """The five-bar at HOME: ``transform`` (scale, turn about the normal, shift) in the model's pose, legs written in
    ``order``, motors named ``motor(i)``; ``marker``: "screwkit" (``<screwkit:actuated/>``), "plugin"
    (JointPositionController plugins) or "" (none: guessed). ``stage``: the legs stand on a ``stage`` link that a
    passive revolute joint ``table`` (its axis tilted, through a point off the origin) joins to the base: every leg
    passes through it, a serial stage before the parallel part (``--lock table`` holds it)."""
    scale, turn, shift = transform
    motor = motor or (lambda i: f"mot{i + 1}")
    elbows = five_bar_elbows(HOME)
    links, joints = ['<link name="base"/>'], ['<joint name="anchor" type="fixed"><parent>world</parent>'
                                              '<child>base</child></joint>']
    ground = "stage" if stage else "base"
    if stage:
        links.append('<link name="stage"/>')
        joints.append(f'<joint name="table" type="revolute"><parent>base</parent><child>stage</child><pose>'
                      f'{text((0.3 * scale, -0.2 * scale, 0.1 * scale))} 0 0 0</pose><axis><xyz>0.3 -0.2 1</xyz>'
                      '<limit><lower>-3</lower><upper>3</upper></limit></axis></joint>')
    actuated = "<screwkit:actuated/>" if marker == "screwkit" else ""
    for i in (range(legs) if order is None else order):
        base, elbow = FIVE_BAR_BASE[i], elbows[i]
        first = float(np.arctan2(*(elbow - base)[::-1]))
        second = float(np.arctan2(*(HOME - elbow)[::-1]))
        links.append(f'<link name="proximal_{i + 1}"><pose>{text((*(scale * base), 0.0))} 0 0 {first!r}</pose></link>')
        links.append(f'<link name="distal_{i + 1}"><pose relative_to="proximal_{i + 1}">{scale * PROXIMAL!r} 0 0 0 0 '
                     f'{second - first!r}</pose></link>')
        joints.append(f'<joint name="{motor(i)}" type="revolute"><parent>{ground}</parent>'
                      f'<child>proximal_{i + 1}</child><axis><xyz>0 0 1</xyz><limit><lower>-3</lower><upper>3</upper>'
                      f'</limit></axis>{actuated}</joint>')
        joints.append(f'<joint name="free{i + 1}" type="continuous"><parent>proximal_{i + 1}</parent>'
                      f'<child>distal_{i + 1}</child><axis><xyz>0 0 1</xyz></axis></joint>')
        axis = ('<xyz expressed_in="__model__">0 0 1</xyz>' if i % 2 else '<xyz>0 0 -1</xyz>')
        joints.append(f'<joint name="loop_{i + 1}" type="revolute"><parent>distal_{i + 1}</parent><child>effector'
                      f'</child><pose>0 0 0 0 0 {0.2 * i!r}</pose><axis>{axis}</axis></joint>')
    effector = rotation_from_rpy(np.array(EFFECTOR_RPY))
    links.append(f'<link name="effector"><pose rotation_format="quat_xyzw">{text((*(scale * HOME), 0.0))} '
                 f'{quaternion_text(effector)}</pose></link>')
    plugins = "".join(f'<plugin filename="gz-sim-joint-position-controller-system" name="gz::sim::systems::'
                      f'JointPositionController"><joint_name>{motor(i)}</joint_name></plugin>'
                      for i in range(legs)) if marker == "plugin" else ""
    pose = f'<pose degrees="true">{text(shift)} 0 0 {float(np.degrees(turn))!r}</pose>'
    return (f'<?xml version="1.0"?>\n<sdf version="1.9" {NAMESPACE}><model name="five_bar">{pose}'
            + "".join(links + joints) + plugins + "</model></sdf>\n")


def five_bar_world_poses(transform=(1.0, 0.0, (0.0, 0.0, 0.0)), legs=3) -> dict[str, np.ndarray]:
    """Each link's pose in the world, computed from the geometry (not from the file's pose chain)."""
    scale, turn, shift = transform
    elbows = five_bar_elbows(HOME)

    def pose(point, rotation):
        matrix = np.eye(4)
        matrix[:3, :3] = rotation_z(turn) @ rotation
        matrix[:3, 3] = np.array(shift) + rotation_z(turn) @ np.array([*(scale * np.asarray(point)), 0.0])
        return matrix

    out = {"base": pose((0.0, 0.0), np.eye(3)), "effector": pose(HOME, rotation_from_rpy(np.array(EFFECTOR_RPY)))}
    for i in range(legs):
        base, elbow = FIVE_BAR_BASE[i], elbows[i]
        out[f"proximal_{i + 1}"] = pose(base, rotation_z(float(np.arctan2(*(elbow - base)[::-1]))))
        out[f"distal_{i + 1}"] = pose(elbow, rotation_z(float(np.arctan2(*(HOME - elbow)[::-1]))))
    return out


def delta_sdf(centre=(0.02, -0.03, -0.45), azimuths=None, transform=None, plugin=True) -> str:
    """The rod-level Delta (tests/delta_rods.py) in SDFormat, at ``centre``; ``transform`` = (scale, rotation,
    translation) places its base link in the world, as :func:`delta_rods.delta_rods_mjcf` places its base body.
    Link frames: the base's rotation everywhere (as the MJCF bodies); arms at the motors, rods at the elbow end of
    each rod, the platform at rod 1a's far end (the MJCF's platform body)."""
    scale, rotation, translation = (1.0, np.eye(3), np.zeros(3)) if transform is None else transform
    azimuths = np.radians([90.0, 180.0, 270.0, 0.0]) if azimuths is None else np.asarray(azimuths, dtype=float)
    base, axes, elbows, attach = delta_geometry(centre, azimuths)
    half = SPACING / 2
    platform_at = attach[0] - half * axes[0]

    def at(vector):
        return text(scale * np.asarray(vector, dtype=float))

    links = [f'<link name="base"><pose rotation_format="quat_xyzw">{text(translation)} {quaternion_text(rotation)}'
             '</pose></link>']
    joints = ['<joint name="anchor" type="fixed"><parent>world</parent><child>base</child></joint>']
    ends = []
    for i, (b, a, e, p) in enumerate(zip(base, axes, elbows, attach), start=1):
        links.append(f'<link name="arm_{i}"><pose relative_to="base">{at(b)} 0 0 0</pose></link>')
        marker = "" if plugin else "<screwkit:actuated/>"
        joints.append(f'<joint name="motor_{i}" type="revolute"><parent>base</parent><child>arm_{i}</child>'
                      f'<axis><xyz expressed_in="base">{text(a)}</xyz></axis>{marker}</joint>')
        for side, sign in (("a", -1.0), ("b", 1.0)):
            start, end = e + sign * half * a, p + sign * half * a
            links.append(f'<link name="rod_{i}{side}"><pose relative_to="arm_{i}">{at(start - b)} 0 0 0</pose>'
                         '</link>')
            joints.append(f'<joint name="ball_{i}{side}" type="ball"><parent>arm_{i}</parent><child>rod_{i}{side}'
                          '</child></joint>')
            where = (f'<pose relative_to="rod_{i}{side}">{at(end - start)} 0 0 0</pose>' if side == "b"
                     else f'<pose>{at(end - platform_at)} 0 0 0</pose>')
            ends.append(f'<joint name="end_{i}{side}" type="ball"><parent>rod_{i}{side}</parent><child>platform'
                        f'</child>{where}</joint>')
    links.append(f'<link name="platform"><pose relative_to="rod_1a">{at(platform_at - elbows[0] + half * axes[0])} '
                 '0 0 0</pose></link>')
    links.append(f'<frame name="centre" attached_to="platform"><pose>{at(np.asarray(centre) - platform_at)} 0 0 0'
                 '</pose></frame>')
    plugins = "".join(f'<plugin filename="gz-sim-joint-position-controller-system" name="gz::sim::systems::'
                      f'JointPositionController"><joint_name>motor_{i}</joint_name></plugin>'
                      for i in range(1, len(base) + 1)) if plugin else ""
    return (f'<?xml version="1.0"?>\n<sdf version="1.9" {NAMESPACE}><model name="delta_rods">'
            + "".join(links + joints + ends) + plugins + "</model></sdf>\n")


def hexapod_legs() -> tuple[str, list[tuple[str, str, tuple[str, str, str], str]]]:
    """The bundled 8-leg U-P-S hexapod's geometry as robots/ups_hexapod_8.urdf writes it: the platform joint's pose
    (``"x y z r p y"``) and per leg, in leg order, its name, its base joint's pose, the axes of its universal joint
    and slide (``xyz`` texts) and the slide's length to the spherical joint (the loop's offset along the slide)."""
    from xml.etree import ElementTree

    from screwkit.io.loader import bundled_path

    root = ElementTree.parse(bundled_path("ups_hexapod_8")).getroot()
    joints = {joint.get("name"): joint for joint in root.findall("joint")}
    loops = {loop.get("name"): loop for loop in root.findall("loop")}
    names = sorted({name.split("_joint")[0] for name in joints if name.startswith("leg_")},
                   key=lambda name: int(name.split("_")[1]))

    def pose(element) -> str:
        origin = element.find("origin")
        return f'{origin.get("xyz")} {origin.get("rpy")}'

    legs = [(leg, pose(joints[f"{leg}_joint_u1"]),
             tuple(joints[f"{leg}_joint_{part}"].find("axis").get("xyz") for part in ("u1", "u2", "slider")),
             loops[f"{leg}_joint_s"].find("predecessor/origin").get("xyz").split()[0]) for leg in names]
    return pose(joints["platform_joint"]), legs


def hexapod_sdf(platform_joint: str = "universal", base_offset=(0.0, 0.0, 0.0)) -> str:
    """The bundled 8-leg U-P-S hexapod (robots/ups_hexapod_8.urdf: its joint centres, read from that file) written in
    SDFormat with its legs turned over, S-P-U: a ball joint at the base, the actuated slide, and at the platform a
    ``universal`` (or ``revolute`` pair: ``platform_joint="revolute"``) joint closing the loop, at the centre of the
    URDF's spherical joint. The base link's frame is drawn at ``base_offset`` (m; no joint moves with it). Such a
    leg transmits the force along its slide as the U-P-S leg does: the same indices."""
    platform, legs = hexapod_legs()
    lines = [f'<?xml version="1.0"?>\n<sdf version="1.9" {NAMESPACE}>\n<model name="spu_hexapod">',
             f'<link name="base"><pose>{text(base_offset)} 0 0 0</pose></link>',
             '<joint name="anchor" type="fixed"><parent>world</parent><child>base</child></joint>',
             f'<link name="platform"><pose>{platform}</pose></link>']
    for leg, base_pose, _, length in legs:
        lines.append(f'<link name="{leg}_cyl"><pose>{base_pose}</pose></link>'
                     f'<link name="{leg}_pis"><pose>{base_pose}</pose></link>')
        lines.append(f'<joint name="{leg}_s" type="ball"><parent>base</parent><child>{leg}_cyl</child>'
                     f'<pose relative_to="{leg}_cyl"/></joint>')
        lines.append(f'<joint name="{leg}_slider" type="prismatic"><parent>{leg}_cyl</parent><child>{leg}_pis</child>'
                     '<axis><xyz>1 0 0</xyz></axis><screwkit:actuated/></joint>')
        at = f'<pose relative_to="{leg}_pis">{length} 0 0 0 0 0</pose>'
        if platform_joint == "universal":
            lines.append(f'<joint name="{leg}_u" type="universal"><parent>{leg}_pis</parent><child>platform</child>'
                         f'{at}<axis><xyz>0 1 0</xyz></axis><axis2><xyz>0 0 1</xyz></axis2></joint>')
        else:  # the universal joint as two revolute joints about crossing axes, through a cross link
            lines.append(f'<link name="{leg}_cross"><pose relative_to="{leg}_pis">{length} 0 0 0 0 0</pose></link>'
                         f'<joint name="{leg}_u1" type="revolute"><parent>{leg}_pis</parent><child>{leg}_cross</child>'
                         '<axis><xyz>0 1 0</xyz></axis></joint>'
                         f'<joint name="{leg}_u2" type="revolute"><parent>{leg}_cross</parent><child>platform</child>'
                         f'{at}<axis><xyz>0 0 1</xyz></axis></joint>')
    lines.append("</model>\n</sdf>")
    return "\n".join(lines)


def ups_sdf(version: str = "1.9", from_platform: bool = True, reverse: bool = False, scale: float = 1.0,
            limits: float | None = None) -> str:
    """The bundled 8-leg U-P-S hexapod written as published Gazebo Stewart platforms write theirs: per leg a
    universal joint at the base as two revolute joints (through a yoke link), the actuated slide, and the spherical
    joint at the platform as a pitch hinge on the piston plus a ``revolute2`` joint, written from the platform to the
    leg (``from_platform``; else from the leg to the platform), every leg closing its loop there but the first. Each
    link's frame is at its joint's centre, turned along its leg. ``version`` "1.9": axes in the joint frames; "1.4":
    no ``relative_to``, every axis in the model frame (SDFormat 1.4, whose axes libsdformat reads in the model frame).
    ``reverse``: the legs written in reverse order. The joint centres and leg lines are the bundled file's, so the
    indices are those of ``ups_hexapod_8``. ``scale``: every length times it (a file in millimetres: 1000);
    ``limits``: each slide's limits +-``limits`` (m, times ``scale`` too)."""
    from screwkit.common.rotations import rotation_from_rpy

    platform, legs = hexapod_legs()
    platform = " ".join([*(repr(float(v) * scale) for v in platform.split()[:3]), *platform.split()[3:]])
    lines = [f'<?xml version="1.0"?>\n<sdf version="{version}" {NAMESPACE}>\n<model name="ups_stewart">',
             '<link name="base"/>', '<joint name="anchor" type="fixed"><parent>world</parent><child>base</child>'
             '</joint>', f'<link name="platform"><pose>{platform}</pose></link>']
    for leg, base_pose, (first, second, slide), length in (legs[::-1] if reverse else legs):
        values = np.array(base_pose.split(), dtype=float)
        values[:3] *= scale
        base_pose = text(values)
        turn = rotation_from_rpy(values[3:])
        top = values[:3] + turn @ np.array([scale * float(length), 0.0, 0.0])

        def axis(local: str, tag: str = "axis", turn=turn, bounds: str = "") -> str:
            vector = np.array(local.split(), dtype=float)
            return f"<{tag}><xyz>{text(turn @ vector if version == '1.4' else vector)}</xyz>{bounds}</{tag}>"

        at = f"{text(top)} {text(values[3:])}"
        bounds = "" if limits is None else (f"<limit><lower>{-limits * scale!r}</lower><upper>{limits * scale!r}"
                                            "</upper></limit>")
        lines.append(f'<link name="{leg}_yoke"><pose>{base_pose}</pose></link><link name="{leg}_cyl"><pose>'
                     f'{base_pose}</pose></link><link name="{leg}_pis"><pose>{at}</pose></link><link name="{leg}_top">'
                     f'<pose>{at}</pose></link>')
        lines.append(f'<joint name="{leg}_b1" type="revolute"><parent>base</parent><child>{leg}_yoke</child>'
                     f'{axis(first)}</joint><joint name="{leg}_b2" type="revolute"><parent>{leg}_yoke</parent><child>'
                     f'{leg}_cyl</child>{axis(second)}</joint><joint name="{leg}_slider" type="prismatic"><parent>'
                     f'{leg}_cyl</parent><child>{leg}_pis</child>{axis(slide, bounds=bounds)}<screwkit:actuated/>'
                     '</joint>'
                     f'<joint name="{leg}_pitch" type="revolute"><parent>{leg}_pis</parent><child>{leg}_top</child>'
                     f'{axis("0 1 0")}</joint>')
        ends = ("platform", f"{leg}_top") if from_platform else (f"{leg}_top", "platform")
        pose = "" if from_platform else f"<pose>{text(top - np.array(platform.split()[:3], dtype=float))} 0 0 0</pose>"
        if not from_platform and version != "1.4":
            pose = f'<pose relative_to="{leg}_top"/>'
        lines.append(f'<joint name="{leg}_s" type="revolute2"><parent>{ends[0]}</parent><child>{ends[1]}</child>'
                     f'{pose}{axis("0 0 1")}{axis("1 0 0", "axis2")}</joint>')
    lines.append("</model>\n</sdf>")
    return "\n".join(lines)


RRP_CENTRE = np.array([0.05, 0.02])
"""The 3-RRP's platform point (m) in the file's configuration."""


def rrp_legs() -> list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]]:
    """Per leg of :func:`rrp_sdf` (planar, m): its base pin B, its slide's point A on the platform, its elbow E and
    the slide's direction u (from E to A), in the file's configuration."""
    legs = []
    for k in range(3):
        turn = np.radians(90 + 120 * k)
        base = np.array([np.cos(turn), np.sin(turn)])
        slide = RRP_CENTRE + 0.3 * np.array([np.cos(turn + 0.7), np.sin(turn + 0.7)])
        elbow = base + 0.45 * np.array([np.cos(turn + 2.6), np.sin(turn + 2.6)])
        legs.append((base, slide, elbow, (slide - elbow) / np.linalg.norm(slide - elbow)))
    return legs


def rrp_sdf(from_platform=(), limits=None, order=(0, 1, 2)) -> str:
    """A planar 3-RRP (per leg: base -R- link 1 -R- link 2 -P, actuated, onto the platform), every axis in
    ``__model__``. The legs in ``from_platform`` write their slide from the platform to link 2, along the opposite
    axis: the same joint, the same value (SDFormat's value is the child's displacement along the axis) and limits
    (``limits``: (lower, upper) m). ``order``: the order the legs are written in."""
    lines = [f'<?xml version="1.0"?>\n<sdf version="1.9" {NAMESPACE}><model name="rrp">', '<link name="base"/>',
             '<joint name="anchor" type="fixed"><parent>world</parent><child>base</child></joint>',
             f'<link name="platform"><pose>{text((*RRP_CENTRE, 0.0))} 0 0 0</pose></link>',
             '<frame name="effector" attached_to="platform"/>']
    bounds = "" if limits is None else f"<limit><lower>{limits[0]!r}</lower><upper>{limits[1]!r}</upper></limit>"
    legs = rrp_legs()
    for k in order:
        base, slide, elbow, direction = legs[k]
        lines.append(f'<link name="l1_{k}"><pose>{text((*base, 0.0))} 0 0 0</pose></link><link name="l2_{k}"><pose>'
                     f'{text((*elbow, 0.0))} 0 0 0</pose></link>'
                     f'<joint name="r1_{k}" type="revolute"><parent>base</parent><child>l1_{k}</child><axis><xyz>0 0 1'
                     f'</xyz></axis></joint><joint name="r2_{k}" type="revolute"><parent>l1_{k}</parent><child>l2_{k}'
                     '</child><axis><xyz>0 0 1</xyz></axis></joint>')
        ends, sign = (("platform", f"l2_{k}"), -1.0) if k in from_platform else ((f"l2_{k}", "platform"), 1.0)
        lines.append(f'<joint name="p_{k}" type="prismatic"><parent>{ends[0]}</parent><child>{ends[1]}</child>'
                     f'<pose relative_to="__model__">{text((*slide, 0.0))} 0 0 0</pose><axis><xyz expressed_in='
                     f'"__model__">{text((*(sign * direction), 0.0))}</xyz>{bounds}</axis><screwkit:actuated/></joint>')
    lines.append("</model></sdf>")
    return "\n".join(lines)


def rss_sdf(tilt: float = 0.0, seed: int = 0, scale: float = 1.0, reverse: bool = False) -> str:
    """The bundled 8-RSS hexapod (robots/rss_hexapod_8.urdf: its crank pivots and axes, crank ends and platform ball
    centres at the reference assembly, read from that file) written in SDFormat as a published Gazebo Stewart platform
    writes its RSS legs: an actuated crank, then a ball joint at the crank's end and one at the platform, each rod's
    link frame at its lower ball with its x axis along the rod, off it by ``tilt`` rad (a file's rounding; ``seed``
    picks the direction). Balls read as three hinges about their frames' axes, the lower one's x hinge is the rod's
    idle spin (to ``tilt``). The link frames change no joint centre or axis: the indices are those of
    ``rss_hexapod_8``. ``scale``: every length times it; ``reverse``: the legs written in reverse order."""
    from scipy.spatial.transform import Rotation

    from screwkit.closure.chain_kinematics import chain_forward_kinematics
    from screwkit.io.loader import load

    bundled, rng = load("rss_hexapod_8"), np.random.default_rng(seed)
    platform = scale * np.asarray(bundled.home_translation, dtype=float)
    lines = [f'<?xml version="1.0"?>\n<sdf version="1.9" {NAMESPACE}>\n<model name="rss_stewart">',
             '<link name="base"/>', '<joint name="anchor" type="fixed"><parent>world</parent><child>base</child>'
             '</joint>', f'<link name="platform"><pose>{text(platform)} 0 0 0</pose></link>']
    legs = list(enumerate(bundled.chains))
    for k, chain in legs[::-1] if reverse else legs:
        geometry = chain.geometry
        tree = [bundled.description.reference_configuration.get(name, 0.0)
                for name in chain.joint_names[: geometry.n_tree_joints]]
        frames = chain_forward_kinematics(geometry, np.concatenate([tree, np.zeros(geometry.n_dofs - len(tree))]))
        pivot, elbow, ball = (scale * frames.points[k] for k in (0, 1, -1))
        axis = frames.axes[0]
        along = (ball - elbow) / np.linalg.norm(ball - elbow)
        side = np.cross(along, rng.normal(size=3))
        along = Rotation.from_rotvec(tilt * side / np.linalg.norm(side)).apply(along)
        second = np.cross(along, axis) / np.linalg.norm(np.cross(along, axis))
        turn = Rotation.from_matrix(np.column_stack([along, second, np.cross(along, second)])).as_euler("xyz")
        lines.append(f'<link name="crank_{k}"><pose>{text(pivot)} 0 0 0</pose></link>'
                     f'<link name="rod_{k}"><pose>{text(elbow)} {text(turn)}</pose></link>')
        lines.append(f'<joint name="motor_{k}" type="revolute"><parent>base</parent><child>crank_{k}</child>'
                     f'<axis><xyz>{text(axis)}</xyz></axis><screwkit:actuated/></joint>')
        lines.append(f'<joint name="elbow_{k}" type="ball"><parent>crank_{k}</parent><child>rod_{k}</child></joint>')
        lines.append(f'<joint name="top_{k}" type="ball"><parent>rod_{k}</parent><child>platform</child>'
                     f'<pose relative_to="__model__">{text(ball)} 0 0 0</pose></joint>')
    lines.append("</model>\n</sdf>")
    return "\n".join(lines)


def upu_legs(legs: int, scale: float = 1.0, tilt: float = 0.35, jitter: float = 0.0):
    """Per leg of :func:`upu_sdf` (model frame, m): its universal joints' centres on the base (foot) and on the
    platform (head), its radial axis y and its tangential axis x, as the file is drawn."""
    moved = jitter * np.random.default_rng(5).normal(size=(legs, 2))
    geometry = []
    for k in range(legs):
        turn = rotation_z(2.0 * np.pi * k / legs + (0.3 if k % 2 else 0.0) * (legs > 3) + moved[k, 0])
        radial, tangential = turn @ np.array([0.0, 1.0, 0.0]), turn @ np.array([1.0, 0.0, 0.0])
        foot = 0.8 * scale * (1.0 + moved[k, 1]) * radial
        head = foot + 1.9 * scale * (np.cos(tilt) * np.array([0.0, 0.0, 1.0]) - np.sin(tilt) * radial)
        geometry.append((foot, head, radial, tangential))
    return geometry


def upu_sdf(legs: int = 3, scale: float = 1.0, world=(0.0, (0.0, 0.0, 0.0)), reverse: bool = False,
            tilt: float = 0.35, decimals: int | None = None, jitter: float = 0.0) -> str:
    """A translational U-P-U parallel mechanism written as a published Gazebo "Stewart platform" writes its legs (each
    universal joint two hinges, every joint native): per leg at azimuth psi, a hinge on the base about the radial axis
    y, one about the tangential axis x, the actuated slide along the leg (tilted by ``tilt`` rad about x toward the
    centre), then a hinge about x and one about y onto the platform. Each leg's outer hinges are parallel and so are
    its inner ones, so the leg holds the platform by one couple, about x cross y: the platform translates (Tsai's
    3-UPU, here with ``legs`` legs). In the file's configuration every x and y is horizontal and every leg's couple is
    vertical: a constraint singularity where the translational operation mode meets others that turn the platform.
    ``scale``: every length times it; ``world``: (yaw in rad, shift in m) of the whole mechanism in the world, through
    the model's ``<pose>``; ``reverse``: the legs written in reverse order; ``decimals``: the joints' points and axes
    written to so many decimals (as a published file writes them: its legs no longer quite alike); ``jitter``: each
    leg's azimuth and radius moved by about so much (rad, relative), its hinges still horizontal (the legs not quite
    alike, every one still a translational U-P-U vertical at home, as in a file whose angles are written 2.0945)."""
    length = 1.9 * scale
    rounded = (lambda values: values) if decimals is None else (lambda values: np.round(values, decimals))
    yaw, shift = world
    lines = [f'<?xml version="1.0"?>\n<sdf version="1.9" {NAMESPACE}><model name="upu">',
             f'<pose>{text(shift)} 0 0 {yaw!r}</pose>', '<link name="base"/>',
             '<joint name="anchor" type="fixed"><parent>world</parent><child>base</child></joint>',
             f'<link name="platform"><pose>0 0 {float(length * np.cos(tilt))!r} 0 0 0</pose></link>']
    order = range(legs - 1, -1, -1) if reverse else range(legs)
    geometry = upu_legs(legs, scale, tilt, jitter)
    for k in order:
        foot, head, radial, tangential = geometry[k]
        direction = (head - foot) / length
        joints = [("yb", "base", f"ub_{k}", foot, radial, "revolute"),
                  ("xb", f"ub_{k}", f"cyl_{k}", foot, tangential, "revolute"),
                  ("slide", f"cyl_{k}", f"rod_{k}", foot, direction, "prismatic"),
                  ("xp", f"rod_{k}", f"up_{k}", head, tangential, "revolute"),
                  ("yp", f"up_{k}", "platform", head, radial, "revolute")]
        joints = [(name, parent, child, rounded(point), rounded(axis), kind)
                  for name, parent, child, point, axis, kind in joints]
        for name, link in ((f"ub_{k}", foot), (f"cyl_{k}", foot), (f"rod_{k}", head), (f"up_{k}", head)):
            lines.append(f'<link name="{name}"><pose>{text(rounded(link))} 0 0 0</pose></link>')
        for name, parent, child, point, axis, kind in joints:
            marked = "<screwkit:actuated/>" if kind == "prismatic" else ""
            bounds = f"<limit><lower>{-0.4 * scale!r}</lower><upper>{0.4 * scale!r}</upper></limit>" \
                if kind == "prismatic" else ""
            lines.append(f'<joint name="{name}_{k}" type="{kind}"><parent>{parent}</parent><child>{child}</child>'
                         f'<pose relative_to="__model__">{text(point)} 0 0 0</pose><axis><xyz expressed_in='
                         f'"__model__">{text(axis)}</xyz>{bounds}</axis>{marked}</joint>')
    lines.append("</model></sdf>")
    return "\n".join(lines)
