"""A URDF joint drawn elsewhere along its own axis (test helper): the same mechanism written otherwise.

:func:`shifted_along_axis` moves a joint's ``<origin>`` by a distance along the joint's axis and moves every joint on
its child link back by the same vector in the child's frame, so that every link stays where it was, every joint turns
about the same line, and every joint value means the same: an index must not change. Only for a joint that stays a
hinge or a slide: one a Gepetto robot.yaml makes a ball or a universal joint (``joint_type``) turns about its origin,
and moved it is another mechanism.
"""

from __future__ import annotations

import re

import numpy as np

from screwkit.common.rotations import rotation_from_rpy

_JOINT = re.compile(r'<joint name="([^"]+)" type="(\w+)">(.*?)</joint>', re.S)


def _attribute(body: str, tag: str, name: str) -> str | None:
    match = re.search(rf'<{tag} [^>]*{name}="([^"]*)"', body)
    return match.group(1) if match else None


def shifted_along_axis(text: str, joint: str, distance: float) -> str:
    """The URDF ``text`` with ``joint`` drawn ``distance`` further along its axis (its child's joints moved back)."""
    blocks = {match.group(1): match for match in _JOINT.finditer(text)}
    target = blocks[joint].group(3)
    axis = np.array([float(v) for v in (_attribute(target, "axis", "xyz") or "1 0 0").split()])
    axis = axis / np.linalg.norm(axis)
    child = _attribute(target, "child", "link")
    edits = []

    def moved(match, change) -> None:
        origin = re.search(r'<origin xyz="([^"]*)" rpy="([^"]*)"', match.group(3))
        xyz = np.array([float(v) for v in origin.group(1).split()])
        rotation = rotation_from_rpy(np.array([float(v) for v in origin.group(2).split()]))
        start, end = match.start(3) + origin.start(1), match.start(3) + origin.end(1)
        edits.append((start, end, " ".join(repr(float(v)) for v in change(xyz, rotation))))

    moved(blocks[joint], lambda xyz, rotation: xyz + distance * rotation @ axis)
    for match in blocks.values():
        if _attribute(match.group(3), "parent", "link") == child:
            moved(match, lambda xyz, rotation: xyz - distance * axis)
    for start, end, value in sorted(edits, reverse=True):
        text = text[:start] + value + text[end:]
    return text
