"""How finely a file of another tool writes its geometry: the step of the last decimal of its lengths and of its angles.

A rounded file's numbers are each within half a step of what its author drew. Where a feature is known only through
such numbers, so is what depends on it: a hinge a file closes by two ball closures a few millimetres apart on its axis
(two MJCF ``<connect>``\\ s) has an axis known to sqrt(3) steps over their spacing, which for points 6 mm apart
written to 6 decimals is 2.9e-4 rad, thirty times the :data:`~screwkit.common.tolerances.FILE_ROUNDING` that joint
axes written as directions are held to (:func:`screwkit.io.graph_rounding.drawn_pairs`); a four-bar's opposite sides
differ by what the rounding of the numbers on their paths adds up to (:func:`screwkit.io.drawn_parallelograms.
written_rounding`). A file written with all the digits of its numbers (a generated one) has steps of 1e-17: it is read
as it is written.

Only the numbers that place joints and closures count (:func:`written_text`): comments, and the positions of geoms,
inertials, lights and cameras (MJCF) and of visuals, collisions and inertials (URDF), which a file may write with
more digits than its kinematics, are left out, and so are numbers below 1e-9 in size (a zero written ``1e-20``, or a
floating-point remainder such as ``6.1e-17``). A hinge closed by two MJCF connects takes the step of the numbers that
place them (:func:`closure_step`) where that is coarser than the file's. A file that writes each number to so many
significant digits (``%g``) rather than to so many decimals is read at the decimals of its smallest numbers, finer
than its larger ones are rounded to: its hinges are then taken as better known than they are, and read as written.
"""

from __future__ import annotations

import re
from pathlib import Path

from screwkit.common.units import metres_per

__all__ = ["written_text", "written_steps", "closure_step"]

_LENGTHS = re.compile(r'(?:<origin[^>]*?\sxyz|\spos|\sfromto|\sanchor)\s*=\s*"([^"]*)"|<pose[^>]*>([^<]*)</pose>')
_ANGLES = re.compile(r'(?:\srpy|\squat|\seuler|\saxisangle|\saxis|<axis[^>]*?\sxyz)\s*=\s*"([^"]*)"'
                     r'|<xyz[^>]*>([^<]*)</xyz>|<pose[^>]*>([^<]*)</pose>')
_NUMBER = re.compile(r"[-+]?(?:\d+\.?(\d*)|\.(\d+))(?:[eE]([-+]?\d+))?")
_LEFT_OUT = re.compile(r"<!--.*?-->|<(visual|collision|inertial)\b[^>]*(?<!/)>.*?</\1\s*>"
                       r"|<(?:geom|inertial|light|camera)\b[^>]*>", re.S)
_TINY = 1e-9
"""Numbers smaller than this in size are zeros written in floating point: their digits say nothing of the rounding."""


def written_text(source: str) -> str | None:
    """The text of the file ``source`` with only the numbers that place joints and closures (the module's docstring);
    None where it cannot be read again (a Gepetto source names its URDF, then its yaml, joined by " + ")."""
    try:
        return _LEFT_OUT.sub(" ", Path(source.split(" + ")[0]).read_text(errors="replace"))
    except OSError:
        return None


def _decimals(numbers: str) -> list[int]:
    """How many decimals each number of ``numbers`` is written with (numbers below :data:`_TINY` left out)."""
    return [len(match.group(1) or match.group(2) or "") - int(match.group(3) or 0)
            for match in _NUMBER.finditer(numbers) if abs(float(match.group(0))) >= _TINY]


def _most_decimals(pattern: re.Pattern, text: str, pose: slice) -> int | None:
    """The most decimals a number of the attributes ``pattern`` finds is written with (its last group a ``<pose>``,
    x y z roll pitch yaw, of whose numbers ``pose`` only count: its lengths or its angles), None if there is none."""
    found = []
    for *attributes, written_pose in pattern.findall(text):
        found += _decimals(" ".join(written_pose.split()[pose]) if written_pose else " ".join(attributes))
    return max(found) if found else None


def written_steps(source: str, length_unit: str | None, text: str | None = None) -> tuple[float | None, float | None]:
    """The step of the last decimal the file ``source`` writes its lengths with (m: times ``length_unit``, the unit
    its lengths are written in, None for metres) and its angles and axis components with (rad, or a unit vector's
    component); None for either it writes none of, or for both where the file cannot be read again. ``text``: its
    :func:`written_text`, when already read."""
    text = written_text(source) if text is None else text
    if text is None:
        return None, None
    lengths, angles = _most_decimals(_LENGTHS, text, slice(0, 3)), _most_decimals(_ANGLES, text, slice(3, 6))
    return (10.0 ** -lengths * metres_per(length_unit or "m") if lengths is not None else None,
            10.0 ** -angles if angles is not None else None)


def _element(text: str, tag: str, name: str) -> str | None:
    found = re.search(rf'<{tag}\b[^>]*\bname\s*=\s*"{re.escape(name)}"[^>]*>', text)
    return found.group(0) if found else None


def _attribute(element: str, name: str) -> str | None:
    found = re.search(rf'\b{name}\s*=\s*"([^"]*)"', element)
    return found.group(1) if found else None


def closure_step(text: str, names, length_unit: str | None) -> float | None:
    """The step (m) of the last decimal of the numbers that place the MJCF ``<connect>``\\ s named ``names`` in
    ``text`` (a :func:`written_text`): their ``anchor``\\ s, or the ``pos`` of the sites they join; None where one
    is not found (unnamed, or not a connect) or writes no number but zeros."""
    found = []
    for name in names:
        element = _element(text, "connect", name)
        if element is None:
            return None
        anchor = _attribute(element, "anchor")
        sites = [_element(text, "site", site) for site in (_attribute(element, "site1"), _attribute(element, "site2"))
                 if site is not None]
        numbers = [anchor] if anchor is not None else [_attribute(site, "pos") or "" for site in sites if site]
        found += [decimals for written in numbers for decimals in _decimals(written)]
    return 10.0 ** -max(found) * metres_per(length_unit or "m") if found else None
