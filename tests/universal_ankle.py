"""A two-rod ankle in Gepetto's format whose rods end on the foot in universal joints (test helper).

The foot hangs from the base (the shank) on two hinges, ``ankle_y`` then ``ankle_x``, at the origin. Each of two
motors turns a crank; the crank's end carries a ball (three revolutes ``sph{i}``, ``sph{i}_b``, ``sph{i}_c`` through
one point) and the rod, whose lower end is closed (``6d``) onto the last body of a universal joint written in the
foot's tree: ``uA{i}`` on the foot, then ``uB{i}``. The universal can be drawn off its centre along each hinge's line
(``off1``, ``off2``), its second hinge's frame turned (``turn2``, roll-pitch-yaw), and its closing frame placed so that
the loop closes with the hinges at ``angles`` (rad); with ``rod_aligned`` the second hinge is drawn along the rod
and the first across it, so that the universal is a Hooke joint only at the first hinge's 90 deg.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import yaml


def _turn(axis, angle: float) -> np.ndarray:
    return pin.exp3(np.asarray(axis, dtype=float) / np.linalg.norm(axis) * angle)


def _pose(rotation=None, point=None) -> np.ndarray:
    pose = np.eye(4)
    if rotation is not None:
        pose[:3, :3] = rotation
    if point is not None:
        pose[:3, 3] = point
    return pose


def _origin(pose: np.ndarray) -> str:
    rpy = pin.rpy.matrixToRpy(pose[:3, :3])
    return f'<origin xyz="{_numbers(pose[:3, 3])}" rpy="{_numbers(rpy)}"/>'


def _numbers(values) -> str:
    return " ".join(repr(float(value)) for value in values)


def _link(name: str) -> str:
    return (f'<link name="{name}"><inertial><mass value="0.1"/><inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" '
            'iyz="0" izz="1e-4"/></inertial></link>')


def _joint(name: str, kind: str, parent: str, child: str, pose: np.ndarray, axis=None) -> str:
    written = "" if axis is None else f'<axis xyz="{_numbers(axis)}"/>'
    limit = '<limit lower="-3.14" upper="3.14" effort="1" velocity="1"/>' if kind == "revolute" else ""
    return (f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>{_origin(pose)}'
            f'{written}{limit}</joint>')


def universal_ankle(folder: Path, *, off1: float = 0.0, off2: float = 0.0, turn2=(0.0, 0.0, 0.0),
                    angles=(0.0, 0.0), rod_aligned: bool = False) -> Path:
    """Write the ankle's robot.urdf and robot.yaml into ``folder``; the URDF's path."""
    folder.mkdir(parents=True, exist_ok=True)
    parts = ['<?xml version="1.0"?>', '<robot name="ankle">'] + [_link(name) for name in ("base", "ay", "foot")]
    parts.append(_joint("ankle_y", "revolute", "base", "ay", _pose(), (0.0, 1.0, 0.0)))
    parts.append(_joint("ankle_x", "revolute", "ay", "foot", _pose(), (1.0, 0.0, 0.0)))
    crank_turn = _turn((0.1, 1.0, 0.0), 0.2)
    for i, side in ((1, 1.0), (2, -1.0)):
        motor = np.array([0.0, 0.04 * side, 0.25])
        crank_end = motor + np.array([-0.05, 0.0, 0.012])
        centre = np.array([-0.06, 0.05 * side, 0.0])  # the universal's centre on the foot
        parts += [_link(name) for name in (f"crank{i}", f"s1_{i}", f"s2_{i}", f"rod{i}", f"rodend{i}", f"ua{i}",
                                           f"ub{i}", f"uend{i}")]
        parts.append(_joint(f"motor{i}", "revolute", "base", f"crank{i}", _pose(crank_turn, motor), (0.1, 1.0, 0.0)))
        parts.append(_joint(f"sph{i}", "revolute", f"crank{i}", f"s1_{i}",
                            _pose(point=crank_turn.T @ (crank_end - motor)), (1.0, 0.0, 0.0)))
        parts.append(_joint(f"sph{i}_b", "revolute", f"s1_{i}", f"s2_{i}", _pose(), (0.0, 1.0, 0.0)))
        parts.append(_joint(f"sph{i}_c", "revolute", f"s2_{i}", f"rod{i}", _pose(), (0.0, 0.0, 1.0)))
        rod = _pose(crank_turn, crank_end)
        rod_end = _pose(_turn((0.3, -0.2, 1.0), 0.4), centre)  # the closure's frame on the rod, turned
        parts.append(_joint(f"rodend{i}_fix", "fixed", f"rod{i}", f"rodend{i}", np.linalg.inv(rod) @ rod_end))
        first = _turn((0.0, 0.0, 1.0), 0.3 * side) @ np.array([1.0, 0.0, 0.0])
        second = np.array([0.0, 1.0, 0.0]) - first[1] * first
        second /= np.linalg.norm(second)
        if rod_aligned:
            second = (centre - crank_end) / np.linalg.norm(centre - crank_end)
            first = np.cross(second, (0.0, 1.0, 0.0))
            first /= np.linalg.norm(first)
        frame1 = _turn((0.2, 0.5, -0.4), 0.7)  # the first hinge's frame turned
        hinge1 = _pose(frame1, centre + off1 * first)
        parts.append(_joint(f"uA{i}", "revolute", "foot", f"ua{i}", hinge1, frame1.T @ first))
        frame2 = frame1 @ pin.rpy.rpyToMatrix(*turn2)
        placement2 = np.linalg.inv(hinge1) @ _pose(frame2, centre + off2 * second)
        parts.append(_joint(f"uB{i}", "revolute", f"ua{i}", f"ub{i}", placement2, frame2.T @ second))
        assembled = hinge1 @ _pose(_turn(frame1.T @ first, angles[0])) @ placement2 @ _pose(
            _turn(frame2.T @ second, angles[1]))
        parts.append(_joint(f"uend{i}_fix", "fixed", f"ub{i}", f"uend{i}", np.linalg.inv(assembled) @ rod_end))
    parts.append("</robot>")
    (folder / "robot.urdf").write_text("\n".join(parts))
    spec = {"closed_loop": [["rodend1", "uend1"], ["rodend2", "uend2"]], "type": ["6d", "6d"],
            "name_mot": ["motor1", "motor2"]}
    (folder / "robot.yaml").write_text(yaml.safe_dump(spec))
    return folder / "robot.urdf"
