"""Right angles written 1.57: how far a file's rounded angles can turn its joint axes.

A hand-written file gives a right angle as ``1.57`` (MJCF ``euler`` in radians, a URDF ``rpy``, an SDFormat
``<pose>``), and a four-bar drawn with it has one hinge 8e-4 rad (0.046 deg) out of parallel with the others: read
exactly, a loop that cannot move, or a mechanism no longer planar. Its author drew parallel hinges, and wrote every
angle to two decimals. :func:`axis_tolerance` reads how far the file's angles are from the angles they round: an
angle written with at least two decimals that lies within half a unit of its last decimal of a nonzero multiple of
15 deg (``1.57`` and ``-1.57`` of pi/2, ``0.785`` of pi/4, ``3.1416`` of pi) is that multiple rounded, off by the
difference. Summed along a body's path from the root (each turn moves every direction beyond it by at most its own
angle), the largest such sum bounds how far the rounding turned any one frame of the file; twice it, how far it
moved two axes apart. Axes within that of parallel are the author's parallel axes
(:func:`screwkit.io.rounding.parallel_axes`), as those within :data:`~screwkit.common.tolerances.FILE_ROUNDING` of
it are in a file written to 6 decimals. Angles that round no such multiple (0, 0.5, 1, a value in degrees) turn
nothing the author did not draw, and count for nothing.

The paths are the file's own: MJCF bodies nested in ``<worldbody>`` (angles in radians only, ``<compiler
angle="radian">``: MuJoCo's degrees are written whole), URDF joints from parent link to child link; an SDFormat
file's poses, which may be relative to any frame, all summed (a bound as well, looser).
"""

from __future__ import annotations

import math
import re
from fractions import Fraction
from xml.etree import ElementTree

from screwkit.common.tolerances import FILE_ROUNDING

__all__ = ["ANGLE_STEP", "rounded_angle", "axis_tolerance"]

ANGLE_STEP = math.pi / 12
"""The angles a file's author writes rounded: nonzero multiples of 15 deg."""

_DECIMALS = re.compile(r"[+-]?\d*\.(\d{2,})")


def rounded_angle(text: str) -> float:
    """How far the angle written ``text`` (rad) is from the nonzero multiple of pi/12 it rounds to its written
    decimals (``1.57``: pi/2 - 1.57 = 7.96e-4), or 0 if it rounds none (``0``, ``0.5``, ``1``, ``0.3``, an
    exponent)."""
    match = _DECIMALS.fullmatch(text.strip())
    if match is None:
        return 0.0
    value = float(text)
    step = round(value / ANGLE_STEP)
    off = abs(value - step * ANGLE_STEP)
    return off if step and off <= 0.5 * 10.0 ** -len(match.group(1)) else 0.0


def axis_tolerance(source: str) -> tuple[float, str]:
    """How far apart two joint axes of the file ``source`` may be and still be the parallel axes its author drew
    (rad, compared with the norm of their cross product): :data:`FILE_ROUNDING` plus twice the largest sum of
    rounded angles along one path (module docstring); and, when that sum is not zero, an angle of the file that
    says why (``"1.57 for pi/2"``). :data:`FILE_ROUNDING` and "" for a file that cannot be read again."""
    try:
        root = ElementTree.parse(source).getroot()
    except (OSError, ElementTree.ParseError):
        return FILE_ROUNDING, ""
    angles: list[str] = []
    if root.tag == "mujoco":
        largest = _mjcf_path_sum(root, angles)
    elif root.tag == "robot":
        largest = _urdf_path_sum(root, angles)
    elif root.tag == "sdf":
        poses = [pose for pose in root.iter("pose") if pose.get("degrees", "false").strip().lower() != "true"]
        largest = sum(_angles(" ".join((pose.text or "").split()[3:6]), angles) for pose in poses)
    else:
        largest = 0.0
    if not largest:
        return FILE_ROUNDING, ""
    example = max(angles, key=rounded_angle)
    multiple = Fraction(round(float(example) / ANGLE_STEP), 12)
    sign = "-" if multiple < 0 else ""
    numerator = "" if abs(multiple.numerator) == 1 else str(abs(multiple.numerator))
    name = f"{sign}{numerator}pi" + (f"/{multiple.denominator}" if multiple.denominator != 1 else "")
    return FILE_ROUNDING + 2.0 * largest, f"{example} for {name}"


def _angles(text: str | None, found: list[str]) -> float:
    """The sum of :func:`rounded_angle` over the numbers of ``text``, those that round one added to ``found``."""
    total = 0.0
    for word in (text or "").split():
        off = rounded_angle(word)
        if off:
            total += off
            found.append(word)
    return total


def _mjcf_path_sum(root: ElementTree.Element, found: list[str]) -> float:
    """The largest sum of rounded ``euler`` and ``axisangle`` angles along a path of nested elements of the
    ``<worldbody>`` (none when the file's angles are in degrees)."""
    compilers = [c for c in root.iter("compiler") if c.get("angle")]
    if not compilers or compilers[-1].get("angle", "").strip().lower() != "radian":
        return 0.0
    largest = 0.0
    pending = [(element, 0.0) for element in root.findall("worldbody")]
    while pending:
        element, above = pending.pop()
        axisangle = (element.get("axisangle") or "").split()
        here = above + _angles(element.get("euler"), found) + _angles(" ".join(axisangle[3:4]), found)
        largest = max(largest, here)
        pending += [(child, here) for child in element]
    return largest


def _urdf_path_sum(root: ElementTree.Element, found: list[str]) -> float:
    """The largest sum of rounded ``rpy`` angles of the joints' origins along a path from a root link."""
    parent_of: dict[str, tuple[str, float]] = {}
    for joint in root.findall("joint"):
        parent, child, origin = joint.find("parent"), joint.find("child"), joint.find("origin")
        if parent is None or child is None:
            continue
        turn = _angles(origin.get("rpy") if origin is not None else None, found)
        parent_of[child.get("link", "")] = (parent.get("link", ""), turn)
    largest = 0.0
    for link in parent_of:
        total, seen, current = 0.0, set(), link
        while current in parent_of and current not in seen:  # (a file whose joints form a cycle: each link once)
            seen.add(current)
            current, turn = parent_of[current]
            total += turn
        largest = max(largest, total)
    return largest
