"""Numbers as they are written in decimals: ranges typed on the command line, angles read back in degrees.

A range START:STOP:STEP computed in doubles drifts from the decimals written (-0.2 + 3 x 0.1 is
0.10000000000000003), and an angle typed in degrees comes back from radians off by an ulp (30 deg is
29.999999999999996 after ``np.rad2deg(np.deg2rad(30))``). A user reads such a coordinate back from a file, or
selects it (``dataset.sel(yaw=30)``), as written. Only numpy and the standard library are imported here.
"""

from __future__ import annotations

from decimal import Decimal, InvalidOperation

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["decimal_range", "degrees_as_written"]

MAX_PLACES = 15
"""Most decimal places of a range's START and STEP taken as written (beyond, the doubles' values stand)."""


def decimal_range(start: str, step: str, count: int) -> NDArray[np.float64] | None:
    """START + k STEP (k < ``count``) as the doubles nearest the decimal numbers written, when START and STEP are
    decimals of at most :data:`MAX_PLACES` places: ``-0.2`` and ``0.1`` give 0.1 at k = 3. Whole multiples of the
    last place, then one correctly rounded division. None when they are not such decimals (or too large for whole
    numbers in a double).

    >>> decimal_range("-0.2", "0.1", 4).tolist()
    [-0.2, -0.1, 0.0, 0.1]
    """
    try:
        first, increment = Decimal(start.strip()), Decimal(step.strip())
    except InvalidOperation:
        return None
    if not (first.is_finite() and increment.is_finite()):
        return None
    places = max(0, -first.as_tuple().exponent, -increment.as_tuple().exponent)
    if places > MAX_PLACES:
        return None
    unit = 10 ** places
    whole_start, whole_step = int(first * unit), int(increment * unit)
    if abs(whole_start) + abs(whole_step) * count >= 2**53:  # beyond exact integers in a double
        return None
    return (whole_start + whole_step * np.arange(count, dtype=np.int64)).astype(float) / unit


def degrees_as_written(radians: ArrayLike) -> NDArray[np.float64]:
    """Angles in degrees, each the decimal of fewest places (up to 17) whose ``np.deg2rad`` is the angle given, else
    ``np.rad2deg`` of it: an angle typed as 30 deg (and so computed at ``np.deg2rad(30)``) reads back as 30.0, not
    29.999999999999996, and is exactly the angle computed.

    >>> degrees_as_written(np.deg2rad([30.0, 0.36, 59.99])).tolist(), float(degrees_as_written(np.deg2rad(30.0)))
    ([30.0, 0.36, 59.99], 30.0)
    """
    given = np.asarray(radians, dtype=float)
    radians = given.ravel()
    degrees = np.rad2deg(radians)
    pending = np.isfinite(degrees)
    for places in range(18):
        if not pending.any():
            break
        unit = 10.0 ** places
        candidates = np.round(degrees[pending] * unit) / unit
        back = np.flatnonzero(pending)[np.deg2rad(candidates) == radians[pending]]
        degrees[back] = candidates[np.deg2rad(candidates) == radians[pending]]
        pending[back] = False
    return degrees.reshape(given.shape)
