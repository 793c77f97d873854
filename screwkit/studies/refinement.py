"""Locating what happens between two samples of a path: minima and level crossings, to a tolerance.

Both searches work on many brackets at once: every round asks ``evaluate(positions, series)`` for the
values of one series at one or more positions per bracket (``series`` says which), so that a whole round is
one batched evaluation of the mechanism, whatever the number of brackets. Each starts from a guess that the
samples give (a round costs what its Python costs, whatever its size, so the rounds are what to save):

* :func:`bracketed_minima`: the minimum of each series inside its bracket (a dip that the samples show as a
  local minimum, which may go lower, to zero at a singularity, between them). The vertex of the parabola
  through three samples (:func:`parabola_vertex`) and the meeting point of the lines through the samples
  either side (:func:`kink_vertex`) are checked against their neighbours :data:`SIDE` tolerance away; where
  neither is the lowest (a V-shaped dip to a singular pose, a series that is neither smooth nor a kink there),
  the search goes on, :data:`GRID` points a round, in the part of the bracket that holds the minimum, until it
  is at most ``tolerance`` wide.
* :func:`bisected_crossings`: where a predicate changes (a value at or above a level, a pose reachable)
  between the ends of each bracket. The crossing of the straight line through the two samples
  (:func:`linear_crossing`) is checked with the points :data:`SIDE` tolerance either side; where the predicate
  does not change between them, the search goes on, :data:`GRID` points a round, in the part that holds the
  change.

NaN counts as +infinity for the minima (an unreachable position is no minimum of an index) and as
below any level for the crossings (an unreachable position is not controllable).
"""

from __future__ import annotations

from typing import Callable

import numpy as np
from numpy.typing import NDArray

__all__ = ["bracketed_minima", "bisected_crossings", "local_minima", "parabola_vertex", "kink_vertex",
           "linear_crossing", "Evaluate", "GRID", "SIDE"]

Evaluate = Callable[[NDArray[np.float64], NDArray[np.int64]], NDArray[np.float64]]
"""``evaluate(positions (m,), series (m,)) -> values (m,)``: one batched evaluation."""

GRID = 16
"""Points evenly spaced inside each bracket that a round evaluates where no guess located it: a round shrinks a
minimum's bracket to ``2 / (GRID + 1)`` of its width, a crossing's to ``1 / (GRID + 1)`` (a bracket 50 tolerances
wide located in two rounds instead of eight of golden section or six of bisection). The rounds, not the points,
are what a refinement costs on a batched evaluation."""
_GRID_SHARES = np.arange(1, GRID + 1) / (GRID + 1)
SIDE = 0.45
"""How far either side of a guess its neighbours are evaluated, in tolerances: the bracket between them, 0.9
tolerance, is within the tolerance whatever the rounding of the positions."""


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


def bracketed_minima(evaluate: Evaluate, lower: NDArray, upper: NDArray, series: NDArray, tolerance: float,
                     guesses: NDArray | None = None) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The minimum of each series inside its bracket ``[lower, upper]``.

    Returns ``(positions, values)`` of the lowest value evaluated in each bracket (unimodal inside its
    bracket: within ``tolerance`` of the true minimum's position). The ends of the brackets are not
    evaluated (they are samples the caller knows).

    Every round evaluates points inside each bracket left and cuts it to the neighbours of its lowest point
    (unimodal: the minimum lies between them). The first round takes ``guesses`` (positions (m, g) where the
    minimum of each bracket may be, NaN for none: the middle) with the points :data:`SIDE` tolerance either
    side of each: a guess that is the lowest of the three locates its minimum at once. A smooth minimum guessed
    by the parabola through three samples (:func:`parabola_vertex`), or a kink (two smooth series meeting, as in
    a minimum over submechanisms) by the lines through the samples either side (:func:`kink_vertex`), is located
    in that one round; a wrong guess costs that round and still cuts its bracket. Each later round evaluates
    :data:`GRID` points evenly spaced inside each bracket left, which shrinks it to ``2 / (GRID + 1)`` of its width.
    """
    a, b = np.asarray(lower, dtype=float).copy(), np.asarray(upper, dtype=float).copy()
    series = np.asarray(series, dtype=np.int64)
    best, best_value = (a + b) / 2, np.full(a.size, np.inf)
    if a.size == 0:
        return a, a.copy()
    todo = np.arange(a.size)
    if guesses is not None:
        guesses = np.asarray(guesses, dtype=float).reshape(a.size, -1)
        centre = np.where(np.isfinite(guesses), guesses, ((a + b) / 2)[:, None])
        points = np.concatenate([centre - SIDE * tolerance, centre, centre + SIDE * tolerance], axis=1)
    while todo.size:
        grid = guesses is None  # (a round of guesses may leave its bracket as it was: the grid rounds go on)
        if grid:
            points = a[todo, None] + (b - a)[todo, None] * _GRID_SHARES
        points = np.sort(np.clip(points, a[todo, None], b[todo, None]), axis=1)
        guesses = None
        found = _finite(evaluate(points.reshape(-1), np.repeat(series[todo], points.shape[1]))).reshape(points.shape)
        rows, lowest = np.arange(todo.size), np.argmin(found, axis=1)
        at, value = points[rows, lowest], found[rows, lowest]
        better = value < best_value[todo]
        best[todo[better]], best_value[todo[better]] = at[better], value[better]
        # the nearest distinct points either side of the lowest (a guess may repeat another, or a bracket's end)
        width = b[todo] - a[todo] if grid else np.full(todo.size, np.inf)
        a[todo] = np.maximum(a[todo], np.max(np.where(points < at[:, None], points, -np.inf), axis=1))
        b[todo] = np.minimum(b[todo], np.min(np.where(points > at[:, None], points, np.inf), axis=1))
        todo = todo[_still_open(b[todo] - a[todo], width, tolerance)]
    return best, np.where(np.isinf(best_value), np.nan, best_value)


def bisected_crossings(evaluate: Evaluate, lower: NDArray, upper: NDArray, series: NDArray,
                       predicate: Callable[[NDArray, NDArray], NDArray], tolerance: float,
                       guess: NDArray | None = None) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Where ``predicate(values, series)`` changes between the ends of each bracket.

    ``predicate`` is True at ``lower`` and False at ``upper`` or the other way round, as the caller found at
    the samples; the returned brackets ``(lower, upper)`` keep that, at most ``tolerance`` wide. The state at
    ``lower`` is taken from one evaluation there.

    Every round evaluates points inside each bracket left and cuts it to the first two consecutive points
    (the bracket's ends included) between which the state changes. The first round, with the state at ``lower``,
    takes the points :data:`SIDE` tolerance either side of ``guess`` (a position per bracket, NaN for none: the
    middle): a crossing guessed by interpolating the samples' values (:func:`linear_crossing`) is located in that
    one round. Each later round evaluates :data:`GRID` points evenly spaced inside each bracket left (without a
    guess, the first does too), which shrinks it to ``1 / (GRID + 1)`` of its width.
    """
    low, high = np.asarray(lower, dtype=float).copy(), np.asarray(upper, dtype=float).copy()
    series = np.asarray(series, dtype=np.int64)
    if low.size == 0:
        return low, high
    if guess is None:
        points = low[:, None] + (high - low)[:, None] * _GRID_SHARES
    else:
        guess = np.asarray(guess, dtype=float)
        middle = np.where(np.isfinite(guess), guess, (low + high) / 2)[:, None]
        points = np.concatenate([middle - SIDE * tolerance, middle + SIDE * tolerance], axis=1)
    points = np.clip(points, low[:, None], high[:, None])
    found = predicate(evaluate(np.concatenate([low, points.reshape(-1)]),
                               np.concatenate([series, np.repeat(series, points.shape[1])])),
                      np.concatenate([series, np.repeat(series, points.shape[1])]))
    state = found[:low.size]
    todo = np.arange(low.size)
    grid = guess is None  # (a round of guesses may leave its bracket as it was: the grid rounds go on)
    while True:
        changed = found[-points.size:].reshape(points.shape) != state[todo, None]
        rows = np.arange(todo.size)
        first = np.where(changed.any(axis=1), np.argmax(changed, axis=1), points.shape[1])  # the first point changed
        ends = np.concatenate([low[todo, None], points, high[todo, None]], axis=1)
        width = high[todo] - low[todo] if grid else np.full(todo.size, np.inf)
        grid = True
        low[todo], high[todo] = ends[rows, first], ends[rows, first + 1]
        todo = todo[_still_open(high[todo] - low[todo], width, tolerance)]
        if not todo.size:
            return low, high
        points = low[todo, None] + (high - low)[todo, None] * _GRID_SHARES
        repeated = np.repeat(series[todo], points.shape[1])
        found = predicate(evaluate(points.reshape(-1), repeated), repeated)


def parabola_vertex(x: NDArray, f: NDArray) -> NDArray[np.float64]:
    """The position of the vertex of the parabola through three points per row (``x``, ``f``: (..., 3), ``x``
    increasing), the guess of a smooth minimum between them; NaN where the three are not finite or not convex."""
    (x0, x1, x2), (f0, f1, f2) = np.moveaxis(np.asarray(x, dtype=float), -1, 0), np.moveaxis(
        np.asarray(f, dtype=float), -1, 0)
    with np.errstate(invalid="ignore", divide="ignore"):
        left, right = (f1 - f0) / (x1 - x0), (f2 - f1) / (x2 - x1)  # the slopes either side
        curvature = (right - left) / (x2 - x0)  # half the second derivative
        vertex = (x0 + x1) / 2 - left / (2 * curvature)  # where the derivative, linear, vanishes
    return np.where(np.isfinite(vertex) & (curvature > 0), vertex, np.nan)


def kink_vertex(x: NDArray, f: NDArray) -> NDArray[np.float64]:
    """Where the line through the first two points meets the line through the last two (``x``, ``f``: (..., 4),
    ``x`` increasing): the guess of a V-shaped minimum (a kink) between the middle two points, which the lines
    either side extend to; NaN where the lines do not fall then rise, or meet outside the middle two points."""
    (x0, x1, x2, x3), (f0, f1, f2, f3) = np.moveaxis(np.asarray(x, dtype=float), -1, 0), np.moveaxis(
        np.asarray(f, dtype=float), -1, 0)
    with np.errstate(invalid="ignore", divide="ignore"):
        left, right = (f1 - f0) / (x1 - x0), (f3 - f2) / (x3 - x2)
        vertex = (f2 - f1 + left * x1 - right * x2) / (left - right)
    good = np.isfinite(vertex) & (left < 0) & (right > 0) & (vertex >= x1) & (vertex <= x2)
    return np.where(good, vertex, np.nan)


def linear_crossing(x0: NDArray, x1: NDArray, f0: NDArray, f1: NDArray, level: float) -> NDArray[np.float64]:
    """Where the straight line through ``(x0, f0)`` and ``(x1, f1)`` meets ``level``: the guess of a crossing
    between two samples; NaN where either value is not finite or they are equal."""
    with np.errstate(invalid="ignore", divide="ignore"):
        at = x0 + (level - f0) / (f1 - f0) * (x1 - x0)
    return np.where(np.isfinite(at), at, np.nan)


def _still_open(width: NDArray, before: NDArray, tolerance: float) -> NDArray[np.bool_]:
    """Brackets to search on: wider than the tolerance, and narrowed by the last round (a tolerance finer than the
    spacing of floating-point numbers at the positions cannot be met: the bracket stops at that spacing)."""
    return (width > tolerance) & (width < before)


def _finite(values: NDArray) -> NDArray[np.float64]:
    return np.where(np.isnan(values), np.inf, values)
