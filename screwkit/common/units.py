"""Units of task coordinates and lengths, written down once.

In Python every length is in metres and every angle in radians; the command line and the
reports show angles in degrees. A mechanism file may be written in another length unit and
is converted to metres when it is read (:data:`LENGTH_UNITS`).
Only the standard library is imported here.
"""

from __future__ import annotations

import math

ANGULAR_COORDINATES = frozenset({"phi", "roll", "pitch", "yaw"})
"""Task coordinates that are angles (rad in Python, deg at the command line)."""

LENGTH_UNITS = {"m": 1.0, "dm": 0.1, "cm": 0.01, "mm": 0.001, "um": 1e-6, "km": 1000.0, "in": 0.0254, "ft": 0.3048}
"""Length units a mechanism file may be written in, as their length in metres."""


MAX_ANGLE_TURNS = 100
"""Largest angle a pose or a range may hold, either sign, in turns (36,000 deg, 200 pi rad). No joint range
or sweep needs more; at that size a double still holds an angle to 1e-13 rad, whereas at 1e20 deg it cannot
tell one turn from the next, so such an angle is refused rather than analysed as if it meant something."""


def angle_limit(*, degrees: bool) -> float:
    """The largest angle accepted (:data:`MAX_ANGLE_TURNS` turns), in deg or rad.

    >>> angle_limit(degrees=True)
    36000.0
    """
    return MAX_ANGLE_TURNS * (360.0 if degrees else 2 * math.pi)


def angle_beyond_limit(where: str, value: float, *, degrees: bool) -> ValueError:
    """The error of an angle larger than :func:`angle_limit` (``where``: what held it)."""
    unit = "deg" if degrees else "rad"
    return ValueError(f"Expected angles of at most {angle_limit(degrees=degrees):g} {unit} ({MAX_ANGLE_TURNS} turns) "
                      f"either way in {where}, got {value:g} {unit}.")


def is_angular(coordinate: str) -> bool:
    """Whether the task coordinate ``coordinate`` is an angle."""
    return coordinate in ANGULAR_COORDINATES


def unit_of(coordinate: str, *, degrees: bool = True) -> str:
    """The unit a task coordinate is shown in: ``"deg"`` (or ``"rad"``) for angles, ``"m"`` otherwise.

    >>> unit_of("yaw"), unit_of("yaw", degrees=False), unit_of("z")
    ('deg', 'rad', 'm')
    """
    if is_angular(coordinate):
        return "deg" if degrees else "rad"
    return "m"


def spelled_pose(coordinates, pose) -> str:
    """A pose (m, rad) as a report shows it: each task coordinate's name and value, angles in degrees.

    >>> spelled_pose(("x", "y", "phi"), (0.25, -0.5, math.pi / 4))
    'x=0.25, y=-0.5, phi=45 deg'
    """
    return ", ".join(f"{name}={math.degrees(value):.6g} deg" if is_angular(name) else f"{name}={value:.6g}"
                     for name, value in zip(coordinates, pose))


def metres_per(unit: str) -> float:
    """The length of one ``unit`` in metres; a ValueError lists the known units.

    >>> metres_per("mm")
    0.001
    """
    try:
        return LENGTH_UNITS[unit]
    except KeyError:
        raise ValueError(f"Unknown length unit {unit!r}; expected one of {', '.join(LENGTH_UNITS)}.") from None
