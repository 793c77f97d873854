"""Task coordinates as the studies' files and titles show them, and the checks of a map's axes.

Angles are shown in degrees as written (:func:`~screwkit.common.decimals.degrees_as_written`: 30 deg, not
29.999999999999996, so that ``dataset.sel(yaw=30)`` finds it). A fixed pose is shown with its round-off noise
as 0: a pose read through a tilted or moved base frame comes back with coordinates such as roll = -2.4e-15 deg
or x = -1.2e-16 m for 0, which ``%g`` prints as they are.
"""

from __future__ import annotations

from typing import Iterable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.common.decimals import degrees_as_written
from screwkit.common.units import is_angular

__all__ = ["shown_values", "shown_number", "pose_text", "map_axis", "one_pose", "planar_position", "NOISE"]

NOISE = 1e-12
"""A fixed coordinate smaller than this (in degrees for angles; times the mechanism's length scale for lengths)
is shown as 0. Round-off of a pose through a base frame is a few units of 1e-16 of the scale (an ulp of the
coordinates it was computed from: 2.4e-15 deg, 1.2e-16 m on a metre-sized hexapod), a thousandth of this; the
solvers close loops to about 1e-12 of the scale, so no coordinate set or solved is known more finely than this."""


def shown_values(name: str, values: ArrayLike) -> NDArray[np.float64]:
    """A coordinate's values as shown: degrees as written for an angle (values in radians), metres as they are."""
    return degrees_as_written(values) if is_angular(name) else np.asarray(values, dtype=float)


def shown_number(name: str, value: float, length_scale: float) -> float:
    """One coordinate of a pose (m, rad) as shown: in m or deg as written, round-off noise (below :data:`NOISE`)
    and -0 as 0."""
    shown = float(shown_values(name, value))
    if abs(shown) < NOISE * (1.0 if is_angular(name) else float(length_scale)):
        shown = 0.0
    return shown + 0.0


def pose_text(names: Iterable[str], pose: ArrayLike, length_scale: float, leave_out: Iterable[str] = ()) -> str:
    """``x=0.1, y=0, pitch=5``: the coordinates of ``pose`` (m, rad) other than ``leave_out``, in m and deg, each
    the shortest decimal that reads back as the value shown (``z=0.2085665361461421``, not ``%g``'s ``0.208567``,
    so that the pose the file states gives its numbers), round-off noise (below :data:`NOISE`) and -0 shown as 0."""
    left_out = set(leave_out)
    parts = []
    for name, value in zip(names, np.asarray(pose, dtype=float)):
        if name in left_out:
            continue
        text = repr(shown_number(name, value, length_scale))
        parts.append(f"{name}={text.removesuffix('.0')}")
    return ", ".join(parts)


def map_axis(values: ArrayLike, what: str) -> NDArray[np.float64]:
    """A map's axis (``grid``'s or ``over``'s values) as a 1-D array of at least one finite value; else a ValueError
    naming ``what``."""
    array = np.asarray(values, dtype=float)
    if array.ndim != 1 or array.size == 0:
        raise ValueError(f"Expected {what} as a 1-D sequence of at least one value, got shape {array.shape}.")
    if not np.all(np.isfinite(array)):
        raise ValueError(f"Expected finite values in {what}.")
    return array


def one_pose(mechanism, at: ArrayLike, where: str = "`at`") -> NDArray[np.float64]:
    """``at`` checked as one pose (n_task,) of ``mechanism`` (:meth:`~screwkit.model.Mechanism.check_poses`), a
    ValueError naming ``where`` for a batch of poses (a study fixes the other coordinates at one pose)."""
    at = mechanism.check_poses(at, where=where)
    if at.ndim != 1:
        raise ValueError(f"Expected one pose as {where}, shape ({mechanism.n_task},), got {at.shape}.")
    return at


def planar_position(centre, where: str = "`centre`") -> NDArray[np.float64]:
    """``centre`` checked as a position (x, y) in m: two finite numbers, or a ValueError naming ``where``."""
    try:
        given = np.asarray(centre)
    except (TypeError, ValueError):  # ragged
        given = np.full(0, np.nan)
    position = given.astype(float) if given.dtype.kind in "iuf" else np.full(0, np.nan)  # no bool, str, complex
    if position.shape != (2,) or not np.all(np.isfinite(position)):
        raise ValueError(f"Expected {where} as a position (x, y): two finite numbers (m), got {centre!r:.60}.")
    return position
