"""A spatial Delta whose forearms are parallelograms of hinges, written in SDFormat the way Gazebo writes one.

Each leg: a motor at B about a (the base's tangent), the arm to the elbow E, a cross-piece turning about a at E,
two parallel rods hinged to it about n = a x u (u the rods' direction) at E +- W a and to a lower cross-piece at
P +- W a, which turns about a at P on the platform. The rods' pair keeps the lower cross-piece parallel to the
upper one, so the platform only translates (three DOF). As the published model writes it (SDFormat 1.6, poses in
the model frame with roll-pitch-yaw, every link turned so that its x axis is the leg's a and its y axis n): the
joints of the tree have their axes in the model frame; the loop joints (the second rod's lower hinge, and the
platform hinges of every leg but ``platform_leg``, written from the platform) in their own frame, so that their
axes come through the rounded roll-pitch-yaw. ``digits`` writes every number rounded to that many decimals.

The indices are the textbook pressure angles of a Delta (as in ``tests/test_graph_legs.py``): ITI = |u . t|, t
the elbow's velocity direction, OTI_k = |u_k . v_k|, v_k the translation reciprocal to the other legs' rod forces.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from helpers import translational_pressure_angles

BASE, ARM, PLATFORM, HALF_WIDTH = 0.09, 0.2, 0.04, 0.025
AZIMUTHS = np.radians([-90.0, 30.0, 150.0, 60.0])


def geometry(centre, arm_angles, azimuths=AZIMUTHS) -> dict[str, np.ndarray]:
    """Motor points B, axes a, elbows E, platform hinges P, rods' directions u (one row per leg)."""
    radial = np.column_stack([np.cos(azimuths), np.sin(azimuths), np.zeros(len(azimuths))])
    axes = np.column_stack([-np.sin(azimuths), np.cos(azimuths), np.zeros(len(azimuths))])
    down = np.array([0.0, 0.0, -1.0])
    angles = np.radians(np.asarray(arm_angles, dtype=float))[:, None]
    base = BASE * radial
    elbows = base + ARM * (np.cos(angles) * radial + np.sin(angles) * down)
    attach = np.asarray(centre, dtype=float) + PLATFORM * radial
    rods = (attach - elbows) / np.linalg.norm(attach - elbows, axis=1, keepdims=True)
    return {"base": base, "axes": axes, "elbows": elbows, "attach": attach, "rods": rods}


def textbook(points: dict) -> dict:
    """ITI per leg, OTI of every 3-subset, LMTI and F_O1 (pressure angles of the geometry's rods)."""
    arms = points["elbows"] - points["base"]
    tangents = np.cross(points["axes"], arms) / np.linalg.norm(arms, axis=1, keepdims=True)
    return translational_pressure_angles(points["rods"], tangents)


def hinged_delta_sdf(centre=(0.01, -0.02, -0.42), arm_angles=(35.0, 28.0, 40.0, 32.0), azimuths=AZIMUTHS,
                     platform_leg: int = 0, digits: int | None = None, transform=None, half_width: float = HALF_WIDTH,
                     widen: float = 0.0, elbow_shift: float = 0.0, unit: float = 1.0, platform_name: str = "platform",
                     wrists_onto_platform: bool = False) -> str:
    """The SDFormat text (see the module docstring); ``transform`` (rotation, translation) moves the whole robot.

    The first rod of each leg is at +``half_width`` along a (a negative value mirrors the rods: the tree then runs
    through the other one); ``widen`` moves the second rod's lower hinge that much further out along a, so that
    the rods make a trapezoid, not a parallelogram; ``elbow_shift`` draws each elbow hinge that far along its own
    axis (the same mechanism); ``unit``: every length written times it (1000: the file in millimetres).
    ``platform_name`` names the platform's link; with ``wrists_onto_platform`` every leg's wrist is written from its
    lower cross-piece to the platform (the reader's tree takes one, the others close loops onto the platform).
    """
    points = geometry(centre, arm_angles, azimuths)
    rotation, shift = (np.eye(3), np.zeros(3)) if transform is None else transform

    def number(value: float) -> str:
        if digits is None:
            return repr(float(value))
        text = f"{value:.{digits}f}".rstrip("0").rstrip(".")
        return "0" if text in ("-0", "") else text

    def numbers(values) -> str:
        return " ".join(number(v) for v in values)

    frames: dict[str, np.ndarray] = {"base": np.eye(4)}
    links, joints = [], []

    def link(name: str, point, turn) -> None:
        frame = np.eye(4)
        frame[:3, :3] = rotation @ turn
        frame[:3, 3] = rotation @ point + shift
        frames[name] = frame
        rpy = Rotation.from_matrix(frame[:3, :3]).as_euler("xyz")
        links.append(f"<link name='{name}'><pose frame=''>{numbers(unit * frame[:3, 3])} {numbers(rpy)}</pose>"
                     "<inertial><mass>0.1</mass></inertial></link>")

    def joint(name: str, parent: str, child: str, point, axis, in_model: bool) -> None:
        frame = frames[child]
        local_point = frame[:3, :3].T @ (rotation @ point + shift - frame[:3, 3])
        world_axis = rotation @ axis
        written = world_axis if in_model else frame[:3, :3].T @ world_axis
        joints.append(f"<joint name='{name}' type='revolute'><parent>{parent}</parent><child>{child}</child>"
                      f"<pose frame=''>{numbers(unit * local_point)} 0 0 0</pose><axis><xyz>{numbers(written)}</xyz>"
                      f"<use_parent_model_frame>{1 if in_model else 0}</use_parent_model_frame>"
                      "<limit><lower>-3</lower><upper>3</upper></limit></axis></joint>")

    link("base", np.zeros(3), np.eye(3))
    link("platform", np.asarray(centre, dtype=float), np.eye(3))
    for k in range(len(azimuths)):
        a, u = points["axes"][k], points["rods"][k]
        n = np.cross(a, u) / np.linalg.norm(np.cross(a, u))
        turn = np.column_stack([a, n, np.cross(a, n)])
        b, e, p = points["base"][k], points["elbows"][k], points["attach"][k]
        leg = k + 1
        link(f"arm_{leg}", b, turn)
        link(f"cross_{leg}", e, turn)
        link(f"rod_{leg}a", e + half_width * a, turn)
        link(f"rod_{leg}b", e - half_width * a, turn)
        link(f"lower_{leg}", p, turn)
        joint(f"motor_{leg}", "base", f"arm_{leg}", b, a, True)
        joint(f"elbow_{leg}", f"arm_{leg}", f"cross_{leg}", e + elbow_shift * a, a, True)
        joint(f"top_{leg}a", f"cross_{leg}", f"rod_{leg}a", e + half_width * a, n, True)
        joint(f"top_{leg}b", f"cross_{leg}", f"rod_{leg}b", e - half_width * a, n, True)
        joint(f"bottom_{leg}a", f"rod_{leg}a", f"lower_{leg}", p + half_width * a, n, True)
        joint(f"bottom_{leg}b", f"rod_{leg}b", f"lower_{leg}", p - (half_width + widen) * a, n, False)
        if k == platform_leg or wrists_onto_platform:
            joint(f"wrist_{leg}", f"lower_{leg}", "platform", p, a, True)
        else:
            joint(f"wrist_{leg}", "platform", f"lower_{leg}", p, a, False)
    fixed = "<joint name='anchor' type='fixed'><parent>world</parent><child>base</child></joint>"
    text = ("<?xml version='1.0'?>\n<sdf version='1.6'><model name='hinged_delta'>" + "".join(links) + fixed
            + "".join(joints) + "</model></sdf>\n")
    return text.replace("'platform'", f"'{platform_name}'").replace(">platform<", f">{platform_name}<")
