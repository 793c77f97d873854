"""Right angles written 1.57: how far a file's rounded angles can turn two of its joint axes apart.

A hand-written file gives a right angle as ``1.57`` (an MJCF ``euler`` in radians, a URDF ``rpy``), and a four-bar
drawn with it has one hinge 8e-4 rad (0.046 deg) out of parallel with the others: read exactly, a loop that cannot
move, or a mechanism no longer planar. Its author drew parallel hinges, and wrote every angle to two decimals.

An angle written with at least two decimals that lies within half a unit of its last decimal of a nonzero multiple
of 15 deg (``1.57`` and ``-1.57`` of pi/2, ``0.785`` of pi/4, ``3.1416`` of pi) is that multiple rounded, off by the
difference (:func:`rounded_angle`); angles that round no such multiple (``0``, ``0.5``, ``1.56``, a value in
degrees) count for nothing. Each joint's axis is turned by the rotations of the frames on its path from the root
(MJCF: the ``<body>`` and ``<frame>`` elements it is nested in; URDF: the origins of the joints from the root link
to it, its own included), and a rotation moves every direction beyond it by at most its own angle. Two axes turn
apart only by the rotations on one path and not the other, those below the frame they share (a rotation above both,
as the world pose of a floating base, turns them together): their **allowance** is
:data:`~screwkit.common.tolerances.FILE_ROUNDING` plus the sum of those rotations' rounding, at most
:data:`WIDENING_LIMIT` (:meth:`WrittenTurns.allowance`). Axes within their allowance of parallel are the author's
parallel axes (:func:`screwkit.io.rounding.parallel_axes`), as those within ``FILE_ROUNDING`` are in a file written
to 6 decimals. Geoms, sites, cameras and lights turn no joint, and count for nothing.

What is not read (the allowance is then ``FILE_ROUNDING``, as for an exact file: such a file is read as before):
``quat``, ``xyaxes``, ``zaxis`` and axis vectors written rounded, ``<default>`` orientations, ``<include>``\\ d files,
MuJoCo's ``<replicate>``, angles in degrees, joints the file leaves unnamed, and SDFormat files (whose poses may be
relative to any frame).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from fractions import Fraction
from xml.etree import ElementTree

import numpy as np
from numpy.typing import NDArray

from screwkit.common.tolerances import FILE_ROUNDING
from screwkit.common.xml_text import tolerant_xml

__all__ = ["ANGLE_STEP", "WIDENING_LIMIT", "WrittenTurns", "rounded_angle", "written_turns"]

ANGLE_STEP = math.pi / 12
"""The angles a file's author writes rounded: nonzero multiples of 15 deg."""

WIDENING_LIMIT = math.radians(0.5)
"""The most an allowance is widened beyond ``FILE_ROUNDING`` (rad): a tilt of more than half a degree is the
author's, however many rounded angles lie between the axes (seven bodies deep, two right angles written 1.57 each,
already sum to 0.64 deg; two-decimal roundings of pi/4 and pi/6, 0.79 and 0.52, are off by 4.6e-3 and 3.6e-3)."""

_DECIMALS = re.compile(r"[+-]?[0-9]*\.([0-9]{2,})")


def rounded_angle(text: str) -> float:
    """How far the angle written ``text`` (rad) is from the nonzero multiple of pi/12 it rounds to its written
    decimals (``1.57``: pi/2 - 1.57 = 7.96e-4), or 0 if it rounds none (``0``, ``0.5``, ``1``, ``1.56``, an
    exponent)."""
    match = _DECIMALS.fullmatch(text.strip())
    if match is None:
        return 0.0
    value = float(text)
    step = round(value / ANGLE_STEP)
    off = abs(value - step * ANGLE_STEP)
    return off if step and off <= 0.5 * 10.0 ** -len(match.group(1)) else 0.0


@dataclass(frozen=True)
class WrittenTurns:
    """Per named joint of a file, the rounded rotations on its path from the root (``{frame: rounding, rad}``, the
    frames by their order in the file), and an angle of the file that says why (``"1.57 for pi/2"``; "" if none)."""

    paths: dict[str, dict[int, float]] = field(default_factory=dict)
    example: str = ""
    loops: dict[str, tuple[tuple[str | None, str | None], float]] = field(default_factory=dict)
    """Per ``<loop>`` of a file in screwkit's convention: the joints into its two links, and the rounding of the
    rotations of its two frames' origins."""
    lineage: dict[str, tuple[str, ...]] = field(default_factory=dict)
    """Per joint of a URDF, the joints from the root to it, its own included."""

    def to_platform(self, joint: str, loop: str) -> float:
        """The rounding of the rotations between the axis of ``joint`` and the platform along its chain, closed onto
        it by ``loop``: the origins of the joints after it up to the loop's link on its chain (whichever of its
        predecessor and successor that is), and the loop's frames. An axis fixed in the platform (its loop fixed,
        every hinge after it parallel to it) is turned by them alone: two such axes of two chains (two arms' last
        wrist hinges, both grasping the object on one line) are parallel whatever the configuration, to these
        roundings."""
        ends, own = self.loops.get(loop, ((None, None), 0.0))
        end = next((end for end in ends if joint in self.lineage.get(end, ())), None)
        path, before = self.paths.get(end, {}), self.paths.get(joint, {})
        return sum(off for frame, off in path.items() if frame not in before) + own

    def around(self, loop: str) -> float:
        """The rounding of the rotations around ``loop``'s cycle: the origins on the way from the frame its two links
        share to each of them (those on one way and not the other) and the loop's own frames. Its chain's joints close
        it onto the platform's frame only to this, and the directions of its axes, which the closure sets, are known
        only to this."""
        ends, own = self.loops.get(loop, ((None, None), 0.0))
        return _apart(*(self.paths.get(end, {}) for end in ends)) + own

    def allowance(self, first: str | None, second: str | None) -> float:
        """How far apart (rad, the norm of their cross product) the axes of joints ``first`` and ``second`` may be
        and still be the parallel axes the author drew (module docstring); ``FILE_ROUNDING`` for a joint not read
        (None: an axis that is no joint's)."""
        if first not in self.paths or second not in self.paths:
            return FILE_ROUNDING
        return FILE_ROUNDING + min(_apart(self.paths[first], self.paths[second]), WIDENING_LIMIT)

    def furthest_beyond(self, axes: NDArray, names) -> tuple[int, int, float, float] | None:
        """Of the directions ``axes`` (n, 3) of joints ``names``, the two furthest out of parallel beyond their
        allowance (up to sense), their angle and their allowance as an angle (rad); None if every two are within."""
        units = axes / np.linalg.norm(axes, axis=1, keepdims=True)
        angles = np.arcsin(np.clip(np.linalg.norm(np.cross(units[:, None], units[None]), axis=-1), 0.0, 1.0))
        allowed = np.arcsin(np.clip(self.allowances(names), 0.0, 1.0))
        first, second = np.unravel_index(int(np.argmax(angles - allowed)), angles.shape) if len(units) else (0, 0)
        if not len(units) or angles[first, second] <= allowed[first, second]:
            return None
        return int(first), int(second), float(angles[first, second]), float(allowed[first, second])

    def allowances(self, names) -> NDArray[np.float64]:
        """The allowances (n, n) of every two of the axes of joints ``names`` (None: an axis that is no joint's)."""
        names = list(names)
        return np.array([[self.allowance(a, b) for b in names] for a in names]).reshape(len(names), len(names))


def _apart(one: dict[int, float], other: dict[int, float]) -> float:
    """The rounding of the rotations on one of two paths from the root and not the other (``{frame: rounding}``):
    those below the frame they share, which turn the two ends apart."""
    return sum(off for frame, off in one.items() if frame not in other) + \
        sum(off for frame, off in other.items() if frame not in one)


def written_turns(source: str, text: str | None = None) -> WrittenTurns:
    """The :class:`WrittenTurns` of the file ``source`` (an MJCF or URDF file; none for any other, or one that
    cannot be read again), or of its ``text`` when given (the text being read, not the file again), parsed as the
    readers of other tools parse it (:func:`~screwkit.common.xml_text.tolerant_xml`)."""
    try:
        if text is None:
            with open(source, "rb") as handle:
                text = handle.read()
        root = ElementTree.fromstring(tolerant_xml(text))
    except (OSError, ElementTree.ParseError, ValueError):
        return WrittenTurns()
    found: list[tuple[float, str]] = []  # every rounded angle on a joint's path, in the file's order
    paths, lineage, loops = ({}, {}, {}) if root.tag not in ("mujoco", "robot") else \
        (_mjcf_paths(root, found), {}, {}) if root.tag == "mujoco" else _urdf_paths(root, found)
    if not any(paths.values()) and not any(off for _, off in loops.values()):  # (a joint whose path has none is
        return WrittenTurns()                                      # kept: its axis turns apart from a rounded one's)
    largest = max(off for off, _ in found)
    example = next(text for off, text in found if off == largest)
    return WrittenTurns(paths, f"{example} for {_multiple(example)}", loops, lineage)


def _multiple(text: str) -> str:
    """The multiple of pi that the angle written ``text`` rounds: ``pi/2``, ``-pi``, ``3pi/4``."""
    multiple = Fraction(round(float(text) / ANGLE_STEP), 12)
    numerator = "" if abs(multiple.numerator) == 1 else str(abs(multiple.numerator))
    return ("-" if multiple < 0 else "") + f"{numerator}pi" + (f"/{multiple.denominator}"
                                                               if multiple.denominator != 1 else "")


def _rounding(words: list[str], found: list[tuple[float, str]]) -> float:
    """The sum of :func:`rounded_angle` over ``words``, each that rounds a multiple added to ``found``."""
    total = 0.0
    for word in words:
        off = rounded_angle(word)
        if off:
            total += off
            found.append((off, word))
    return total


def _mjcf_paths(root: ElementTree.Element, found: list) -> dict[str, dict[int, float]]:
    """Each named joint's rounded ``euler`` and ``axisangle`` rotations of the ``<body>`` and ``<frame>`` elements
    it is nested in (none when the file's angles are in degrees, MuJoCo's default)."""
    compilers = [c for c in root.iter("compiler") if c.get("angle")]
    if not compilers or compilers[-1].get("angle", "").strip().lower() != "radian":
        return {}
    paths: dict[str, dict[int, float]] = {}
    order = 0

    def visit(element: ElementTree.Element, path: dict[int, float]) -> None:
        nonlocal order
        for child in element:
            order += 1
            if child.tag in ("joint", "freejoint") and child.get("name"):
                paths[child.get("name")] = path
            elif child.tag in ("body", "frame"):
                words = (child.get("euler") or "").split() + (child.get("axisangle") or "").split()[3:4]
                off = _rounding(words, found)
                visit(child, {**path, order: off} if off else path)

    for world in root.findall("worldbody"):
        visit(world, {})
    return paths


def _urdf_paths(root: ElementTree.Element, found: list) -> tuple[dict, dict, dict]:
    """Each joint's rounded ``rpy`` rotations of the joints' origins from the root link to it, its own included; its
    lineage (the joints from the root to it); and each ``<loop>``'s joints into its two links with the rounding of
    its two frames' ``rpy``."""
    joints = {}
    for order, joint in enumerate(root.findall("joint")):
        parent, child, origin = joint.find("parent"), joint.find("child"), joint.find("origin")
        if parent is None or child is None or not joint.get("name"):
            continue
        off = _rounding((origin.get("rpy") or "").split() if origin is not None else [], found)
        joints[joint.get("name")] = (parent.get("link", ""), child.get("link", ""), order, off)
    into = {child: name for name, (_, child, _, _) in joints.items()}  # each link's joint from its parent
    paths: dict[str, dict[int, float]] = {}
    lineage: dict[str, tuple[str, ...]] = {}
    for name in joints:
        path, line, current, seen = {}, [], name, set()
        while current is not None and current not in seen:  # (a file whose joints form a cycle: each joint once)
            seen.add(current)
            line.append(current)
            parent, _, order, off = joints[current]
            if off:
                path[order] = off
            current = into.get(parent)
        paths[name], lineage[name] = path, tuple(reversed(line))
    loops = {}
    for loop in root.findall("loop"):
        ends = [loop.find(tag) for tag in ("predecessor", "successor")]
        if loop.get("name") and None not in ends:
            words = [word for origin in loop.iter("origin") for word in (origin.get("rpy") or "").split()]
            loops[loop.get("name")] = (tuple(into.get(end.get("link", "")) for end in ends), _rounding(words, found))
    return paths, lineage, loops
