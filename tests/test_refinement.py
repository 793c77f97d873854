"""The searches between samples of a path (screwkit.studies.refinement) on functions whose minima and crossings
are known in closed form: located to the tolerance from any guess, in one round from the guesses the samples give."""

from __future__ import annotations

import numpy as np
import pytest

from screwkit.studies.refinement import (
    GRID,
    bisected_crossings,
    bracketed_minima,
    kink_vertex,
    linear_crossing,
    parabola_vertex,
)

TOLERANCE = 1e-7


class Counted:
    """``evaluate(positions, series)`` of one function per series, counting the rounds (calls)."""

    def __init__(self, functions):
        self.functions, self.rounds = functions, 0

    def __call__(self, positions, series):
        self.rounds += 1
        values = np.empty(positions.shape)
        for k, function in enumerate(self.functions):
            mine = series == k
            values[mine] = function(positions[mine])
        return values


def _rounds_of_grid(width: float, share: float) -> int:
    return int(np.ceil(np.log(width / TOLERANCE) / np.log(1 / share)))


# minima: a smooth one (a cosine), a kink (the lower of two lines), a V to zero (a singular pose), a flat end
MINIMA = [(lambda x: 1.2 - np.cos(3.0 * (x - 0.4137)), 0.4137),
          (lambda x: np.minimum(0.3 + 2.0 * (x - 0.2719), 0.3 - 0.7 * (x - 0.2719)) * -1 + 1.0, 0.2719),
          (lambda x: np.abs(np.sin(5.0 * (x - 0.3331))), 0.3331)]


@pytest.mark.parametrize("function, true", MINIMA)
def test_minima_are_located_to_the_tolerance_from_any_guess(function, true):
    rng = np.random.default_rng(7)
    lower = true - rng.uniform(0.001, 0.1, 20)
    upper = true + rng.uniform(0.001, 0.1, 20)
    bad_guesses = np.column_stack([rng.uniform(lower, upper), np.full(20, np.nan)])
    for guesses in (None, bad_guesses, np.full((20, 2), np.nan), np.full((20, 2), true)):
        evaluate = Counted([function])
        at, value = bracketed_minima(evaluate, lower, upper, np.zeros(20, dtype=np.int64), TOLERANCE, guesses)
        assert np.all(np.abs(at - true) <= TOLERANCE), (guesses, at - true)
        assert np.allclose(value, function(at))
        widest = float(np.max(upper - lower))
        assert evaluate.rounds <= 1 + _rounds_of_grid(widest, 2 / (GRID + 1))


def test_the_samples_guess_a_smooth_minimum_and_a_kink_in_one_round():
    smooth, kink = MINIMA[0], MINIMA[1]
    x = np.array([0.35, 0.40, 0.45, 0.50])  # samples: the smooth minimum between the 2nd and 3rd
    parabola = parabola_vertex(x[None, 1:], smooth[0](x[None, 1:]))
    assert abs(parabola[0] - smooth[1]) < 1e-4  # a parabola's vertex: the cosine's minimum to O(h^3)
    x = np.array([0.20, 0.25, 0.30, 0.35])
    meeting = kink_vertex(x[None], kink[0](x[None]))
    assert abs(meeting[0] - kink[1]) < 1e-12  # two straight lines meet where they meet
    cases = ((smooth, parabola[0], (0.40, 0.50), 1e-3), (kink, meeting[0], (0.25, 0.30), TOLERANCE))
    for (function, true), guess, (low, high), tolerance in cases:
        evaluate = Counted([function])
        at, _ = bracketed_minima(evaluate, np.array([low]), np.array([high]), np.zeros(1, dtype=np.int64),
                                 tolerance, np.array([[guess, np.nan]]))
        assert evaluate.rounds == 1 and abs(at[0] - true) <= tolerance


def test_the_guesses_of_the_samples_are_exact_on_their_shapes():
    x = np.array([[0.0, 0.3, 1.0]])
    assert parabola_vertex(x, 2.0 * (x - 0.41) ** 2 + 0.5)[0] == pytest.approx(0.41, abs=1e-14)
    assert np.isnan(parabola_vertex(x, -(x - 0.41) ** 2)[0])  # a maximum is no guess of a minimum
    x4 = np.array([[0.0, 0.1, 0.5, 0.6]])
    assert kink_vertex(x4, np.abs(x4 - 0.37))[0] == pytest.approx(0.37, abs=1e-14)
    assert np.isnan(kink_vertex(x4, x4)[0])  # a line that rises throughout has no kink to guess
    assert linear_crossing(np.array([0.0]), np.array([2.0]), np.array([1.0]), np.array([0.0]), 0.25)[0] == 1.5


@pytest.mark.parametrize("use_guess", [False, True])
def test_crossings_are_located_to_the_tolerance_and_keep_the_states_of_their_ends(use_guess):
    rng = np.random.default_rng(11)
    true = rng.uniform(0.2, 0.8, 30)
    slope = rng.choice([-1.0, 1.0], 30) * rng.uniform(0.5, 3.0, 30)
    level = 0.4
    functions = [lambda x, t=t, m=m: level + m * (x - t) + 0.3 * (x - t) ** 2 for t, m in zip(true, slope)]
    lower, upper = true - rng.uniform(0.001, 0.2, 30), true + rng.uniform(0.001, 0.2, 30)
    series = np.arange(30)

    def above(values, _):
        return values >= level

    guess = None
    if use_guess:
        ends = [np.array([f(v) for f, v in zip(functions, side)]) for side in (lower, upper)]
        guess = linear_crossing(lower, upper, ends[0], ends[1], level)
    evaluate = Counted(functions)
    low, high = bisected_crossings(evaluate, lower, upper, series, above, TOLERANCE, guess)
    assert np.all(high - low <= TOLERANCE) and np.all((low <= true) & (true <= high))
    for f, a, b in zip(functions, low, high):
        assert above(f(a), 0) != above(f(b), 0)
    assert evaluate.rounds <= (2 if use_guess else 1) + _rounds_of_grid(float(np.max(upper - lower)), 1 / (GRID + 1))


def test_a_tolerance_finer_than_the_floating_point_spacing_ends_at_that_spacing():
    """Positions near 0.4 are 5.6e-17 apart: a tolerance of 1e-20 cannot be met, and the searches stop (they once
    could go round for ever) with the smallest bracket the positions allow."""
    function, true = MINIMA[2]
    at, _ = bracketed_minima(Counted([function]), np.array([0.3]), np.array([0.4]), np.zeros(1, dtype=np.int64),
                             1e-20, np.array([[np.nan]]))
    assert abs(at[0] - true) <= 4 * np.spacing(true)
    low, high = bisected_crossings(Counted([lambda x: x - true]), np.array([0.3]), np.array([0.4]),
                                   np.zeros(1, dtype=np.int64), lambda v, _: v >= 0, 1e-20)
    assert low[0] <= true <= high[0] and high[0] - low[0] <= 4 * np.spacing(true)
