"""Locating what happens between two samples of a path: minima and level crossings, to a tolerance.

Both searches work on many brackets at once: every round asks ``evaluate(positions, series)`` for the
values of one series at one position per bracket (``series`` says which), so that a whole round is one
batched evaluation of the mechanism, whatever the number of brackets.

* :func:`bracketed_minima`: golden-section search for the minimum of each series inside its bracket
  (a dip that the samples show as a local minimum, which may go lower, to zero at a singularity, between
  them); the bracket shrinks by the golden ratio each round until it is at most ``tolerance`` wide.
* :func:`bisected_crossings`: bisection of each bracket whose ends are on either side of a predicate
  (a value at or above a level, a pose reachable) until it is at most ``tolerance`` wide.

NaN counts as +infinity for the minima (an unreachable position is no minimum of an index) and as
below any level for the crossings (an unreachable position is not controllable).
"""

from __future__ import annotations

import math
from typing import Callable

import numpy as np
from numpy.typing import NDArray

__all__ = ["bracketed_minima", "bisected_crossings", "local_minima", "Evaluate"]

Evaluate = Callable[[NDArray[np.float64], NDArray[np.int64]], NDArray[np.float64]]
"""``evaluate(positions (m,), series (m,)) -> values (m,)``: one batched evaluation."""

GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0
"""The golden-section ratio, 0.618...: the bracket left after each round of :func:`bracketed_minima`."""


def local_minima(values: NDArray[np.float64]) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """Samples (row) of each column (series) of ``values`` (n, K) that are strict local minima on at least one
    side and not above the other neighbour, with a value above zero (a zero is already the lowest): the dips a
    finer sampling could find lower. The first and last samples count when below their one neighbour.
    Returns ``(rows, series)``."""
    values = np.asarray(values, dtype=float)
    finite = np.isfinite(values)
    dip = finite & (values > 0)
    if not finite.all():
        values = np.where(finite, values, np.inf)
    # against each neighbour (+infinity where there is none, at the ends): not above either, below one
    below = np.ones_like(dip)
    if values.shape[0] > 1:
        dip[1:] &= values[1:] <= values[:-1]
        dip[:-1] &= values[:-1] <= values[1:]
        below[1:-1] = (values[1:-1] < values[:-2]) | (values[1:-1] < values[2:])
    dip &= below
    rows, series = np.nonzero(dip)
    return rows.astype(np.int64), series.astype(np.int64)


def bracketed_minima(evaluate: Evaluate, lower: NDArray, upper: NDArray, series: NDArray, tolerance: float
                     ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The minimum of each series inside its bracket ``[lower, upper]``, by golden-section search.

    Returns ``(positions, values)`` of the lowest value evaluated in each bracket (unimodal inside its
    bracket: within ``tolerance`` of the true minimum's position). The ends of the brackets are not
    evaluated (they are samples the caller knows).
    """
    a, b = np.asarray(lower, dtype=float).copy(), np.asarray(upper, dtype=float).copy()
    series = np.asarray(series, dtype=np.int64)
    if a.size == 0:
        return a, a.copy()
    c, d = b - GOLDEN * (b - a), a + GOLDEN * (b - a)
    both = _finite(evaluate(np.concatenate([c, d]), np.concatenate([series, series])))
    fc, fd = both[:a.size], both[a.size:]
    best, best_value = np.where(fc <= fd, c, d), np.minimum(fc, fd)
    while np.max(b - a) > tolerance:
        left = fc <= fd  # the minimum is in [a, d]: drop (d, b]
        b = np.where(left, d, b)
        a = np.where(left, a, c)
        c, d, fc, fd = (np.where(left, b - GOLDEN * (b - a), d), np.where(left, c, a + GOLDEN * (b - a)),
                        np.where(left, np.nan, fd), np.where(left, fc, np.nan))
        new = np.where(left, c, d)
        value = _finite(evaluate(new, series))
        fc, fd = np.where(left, value, fc), np.where(left, fd, value)
        better = value < best_value
        best, best_value = np.where(better, new, best), np.where(better, value, best_value)
    return best, np.where(np.isinf(best_value), np.nan, best_value)


def bisected_crossings(evaluate: Evaluate, lower: NDArray, upper: NDArray, series: NDArray,
                       predicate: Callable[[NDArray, NDArray], NDArray], tolerance: float
                       ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Where ``predicate(values, series)`` changes between the ends of each bracket, by bisection.

    ``predicate`` is True at ``lower`` and False at ``upper`` or the other way round, as the caller found at
    the samples; the returned brackets ``(lower, upper)`` keep that, at most ``tolerance`` wide. The state at
    ``lower`` is taken from one evaluation there.
    """
    low, high = np.asarray(lower, dtype=float).copy(), np.asarray(upper, dtype=float).copy()
    series = np.asarray(series, dtype=np.int64)
    if low.size == 0:
        return low, high
    state = predicate(evaluate(low, series), series)
    while np.max(high - low) > tolerance:
        middle = (low + high) / 2
        same = predicate(evaluate(middle, series), series) == state
        low, high = np.where(same, middle, low), np.where(same, high, middle)
    return low, high


def _finite(values: NDArray) -> NDArray[np.float64]:
    return np.where(np.isnan(values), np.inf, values)
