"""How finely a file of another tool writes its geometry: the step of the last decimal of its lengths and of its angles.

A rounded file's numbers are each within half a step of what its author drew. Where a feature is known only through
such numbers, so is what depends on it: a hinge a file closes by two ball closures a few millimetres apart on its axis
(two MJCF ``<connect>``\\ s) has an axis known to the rounding of their points over their spacing, which on a file
written to 6 decimals is 1e-4 rad, ten times the :data:`~screwkit.common.tolerances.FILE_ROUNDING` that joint axes
written as directions are held to (:func:`screwkit.io.graph_rounding.drawn_pairs`); a four-bar's opposite sides differ
by what the rounding of the numbers on their paths adds up to (:func:`screwkit.io.drawn_parallelograms.
written_rounding`). A file written with all the digits of its numbers (a generated one) has steps of 1e-17: it is read
as it is written.
"""

from __future__ import annotations

import re
from pathlib import Path

from screwkit.common.units import metres_per

__all__ = ["written_steps"]

_LENGTHS = re.compile(r'(?:<origin[^>]*?\sxyz|\spos|\sfromto|\sanchor)\s*=\s*"([^"]*)"|<pose[^>]*>([^<]*)</pose>')
_ANGLES = re.compile(r'(?:\srpy|\squat|\seuler|\saxisangle|\saxis|<axis[^>]*?\sxyz)\s*=\s*"([^"]*)"'
                     r'|<xyz[^>]*>([^<]*)</xyz>|<pose[^>]*>([^<]*)</pose>')
_NUMBER = re.compile(r"[-+]?(?:\d+\.?(\d*)|\.(\d+))(?:[eE]([-+]?\d+))?")


def _most_decimals(pattern: re.Pattern, text: str, pose: slice) -> int | None:
    """The most decimals a number of the attributes ``pattern`` finds is written with (its last group a ``<pose>``,
    x y z roll pitch yaw, of whose numbers ``pose`` only count: its lengths or its angles), None if there is none."""
    found = []
    for *attributes, written_pose in pattern.findall(text):
        numbers = written_pose.split()[pose] if written_pose else " ".join(attributes).split()
        found += [len(match[0] or match[1]) - int(match[2] or 0) for match in _NUMBER.findall(" ".join(numbers))]
    return max(found) if found else None


def written_steps(source: str, length_unit: str | None) -> tuple[float | None, float | None]:
    """The step of the last decimal the file ``source`` writes its lengths with (m: times ``length_unit``, the unit
    its lengths are written in, None for metres) and its angles and axis components with (rad, or a unit vector's
    component); None for either it writes none of, or for both where the file cannot be read again (a Gepetto
    source names its URDF, then its yaml, joined by " + ")."""
    try:
        text = Path(source.split(" + ")[0]).read_text(errors="replace")
    except OSError:
        return None, None
    lengths, angles = _most_decimals(_LENGTHS, text, slice(0, 3)), _most_decimals(_ANGLES, text, slice(3, 6))
    unit = metres_per(length_unit) if length_unit not in (None, "m") else 1.0
    return (10.0 ** -lengths * unit if lengths is not None else None,
            10.0 ** -angles if angles is not None else None)
