"""The small dense algebra inside the compiled kernel, against numpy's determinants."""

from __future__ import annotations

import numpy as np
import pytest

from screwkit.indices.compiled.algebra import BLOCK, LEADING_PIVOT_RATIO, null_vector, null_vectors_lanes


def cofactors(rows):
    """(-1)^(m+q) det(rows without column q), from numpy.linalg.det (the definition)."""
    m, size = rows.shape
    return np.array([(-1) ** (m + q) * np.linalg.det(np.delete(rows, q, axis=1)) for q in range(size)])


def test_null_vector_is_the_cofactor_vector():
    rng = np.random.default_rng(7)
    work, columns = np.empty((6, 6)), np.empty(6, dtype=np.int64)
    for size in (2, 3, 4, 5, 6):
        for case in range(60):
            rows = rng.standard_normal((size - 1, size))
            if case % 4 == 1:
                rows[:, 0] = 0.0  # the leading block is singular: needs a column pivot
            elif case % 4 == 2 and size > 2:
                rows[-1] = 2.0 * rows[0]  # dependent rows: every cofactor is zero
            elif case % 4 == 3:
                rows *= 10.0 ** rng.integers(-6, 6)  # scale
            out = np.full(size, np.nan)
            null_vector(np.ascontiguousarray(rows), size, out, work, columns)
            expected = cofactors(rows)
            scale = np.prod(np.linalg.norm(rows, axis=1))
            np.testing.assert_allclose(out, expected, rtol=0, atol=1e-12 * scale)
            np.testing.assert_allclose(rows @ out, 0.0, atol=1e-12 * scale * np.abs(rows).max())
            if case % 4 == 2 and size > 2:
                assert np.all(out == 0.0) or np.abs(out).max() <= 1e-12 * scale


def test_null_vectors_of_every_lane_are_the_cofactor_vectors():
    """The lane-innermost version: the same cofactor vectors for a block of configurations mixing generic
    rows, a singular leading block (redone by full pivoting), dependent rows, poor scaling and lanes
    left unused (width below the block)."""
    rng = np.random.default_rng(8)
    for size in (4, 5, 6):
        m = size - 1
        rows = rng.standard_normal((m, size, BLOCK))
        rows[:, 0, 1::5] = 0.0  # singular leading blocks
        rows[-1, :, 2::5] = 2.0 * rows[0, :, 2::5]  # dependent rows
        rows[:, :, 3::5] *= 1e5
        rows[:, m - 1, 4::5] = 1e-9 * rows[:, 0, 4::5]  # a nearly singular leading block
        width = BLOCK - 3
        out = np.full((size, BLOCK), np.nan)
        scratch = [np.empty(BLOCK) for _ in range(5)]
        null_vectors_lanes(rows, size, width, out, np.empty((m, size, BLOCK)), *scratch, np.empty((6, 6)),
                            np.empty((6, 6)), np.empty(6, dtype=np.int64), np.empty(6))
        assert np.isnan(out[:, width:]).all()  # lanes beyond the width are left alone
        for r in range(width):
            expected = cofactors(rows[:, :, r])
            scale = np.prod(np.linalg.norm(rows[:, :, r], axis=1))
            np.testing.assert_allclose(out[:, r], expected, rtol=0, atol=1e-12 * scale, err_msg=f"lane {r}")
    assert 0.0 < LEADING_PIVOT_RATIO < 1.0


def test_solve_matches_numpy_and_takes_its_pivot_tolerance():
    """solve on Gram matrices of unit columns (as the kernel builds them): numpy's solution when
    regular, False when a pivot is at or below the tolerance it is given (GRAM_PIVOT)."""
    from screwkit.common.tolerances import GRAM_PIVOT
    from screwkit.indices.compiled.algebra import solve

    rng = np.random.default_rng(8)
    out, work = np.empty(8), np.empty((8, 8))
    for size in range(1, 8):
        columns = rng.standard_normal((6, size))  # seven columns in six dimensions: singular
        columns /= np.linalg.norm(columns, axis=0)
        gram = np.ascontiguousarray(columns.T @ columns)
        rhs = rng.standard_normal(size)
        regular = solve(gram, size, rhs, out, work, GRAM_PIVOT)
        assert regular == (size <= 6)
        if regular:
            np.testing.assert_allclose(out[:size], np.linalg.solve(gram, rhs), rtol=1e-9, atol=1e-9)
    # Two columns 1e-5 apart: the last pivot is about 1e-10 of the diagonal.
    first = rng.standard_normal(6)
    first /= np.linalg.norm(first)
    second = first + 1e-5 * rng.standard_normal(6)
    second /= np.linalg.norm(second)
    gram = np.ascontiguousarray(np.array([first, second]) @ np.array([first, second]).T)
    assert solve(gram, 2, np.array([1.0, 0.0]), out, work, 1e-12)
    assert not solve(gram, 2, np.array([1.0, 0.0]), out, work, 1e-8)


@pytest.mark.parametrize("n", [4, 5, 6])
def test_exterior_product_tables_give_every_minor_and_the_cofactor_vector(n):
    """The output twists' expansion terms (level by level, as the kernel runs them) against numpy's determinants."""
    from itertools import combinations

    from screwkit.indices.sets import WEDGE_TERMS, wedge_tables

    tables = wedge_tables(n)
    table, start = tables["wedge_table"], tables["wedge_start"]
    rows = np.random.default_rng(n).normal(size=(n - 1, n))
    minors = {1: rows[0].copy()}
    for level in range(2, n):
        sets = list(combinations(range(n), level))
        entries = table[start[level]:start[level + 1]]
        assert entries.shape == (len(sets), 1 + 3 * WEDGE_TERMS)
        values = np.zeros(len(sets))
        for target, *terms in entries:  # as the kernel sums them: every minor's padded terms in one pass
            for source, column, sign in np.reshape(terms, (WEDGE_TERMS, 3)):
                values[target] += sign * minors[level - 1][source] * rows[level - 1, column]
        assert np.count_nonzero(entries[:, 3::3]) == len(sets) * level  # `level` real terms per minor
        minors[level] = values
        for index, columns in enumerate(combinations(range(n), level)):
            assert np.isclose(values[index], np.linalg.det(rows[:level][:, columns]), rtol=1e-12, atol=1e-12)
    cofactor = np.array([(-1) ** (n - 1 + q) * minors[n - 1][n - 1 - q] for q in range(n)])
    expected = np.empty(n)
    null_vector(rows, n, expected, np.empty((n, n)), np.empty(n, dtype=np.int64))
    np.testing.assert_allclose(cofactor, expected, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(rows @ cofactor, 0.0, atol=1e-12)


@pytest.mark.parametrize("size, rank", [(1, 0), (1, 1), (3, 2), (6, 6), (7, 6), (9, 5)])
def test_pseudo_inverse_matches_numpy_on_symmetric_matrices_of_any_rank(size, rank):
    """The written-out Jacobi pseudo-inverse of the wrench kernel's idle-DoF fallback equals
    numpy's SVD-based pinv on Gram matrices of unit twists (positive semi-definite, rank deficient)."""
    from screwkit.indices.compiled.algebra import pseudo_inverse

    rng = np.random.default_rng(size * 10 + rank)
    for _ in range(20):
        factors = rng.standard_normal((size, rank))
        factors /= np.maximum(np.linalg.norm(factors, axis=1, keepdims=True), 1e-300)
        gram = factors @ factors.T if rank else np.zeros((size, size))
        capacity = size + 2  # scratch larger than the matrix, as in the kernel
        matrix = np.full((capacity, capacity), np.nan)
        matrix[:size, :size] = gram
        out = np.full((capacity, capacity), np.nan)
        result = pseudo_inverse(matrix, size, out, np.empty((capacity, capacity)), np.empty(capacity))
        expected = np.linalg.pinv(gram)
        assert result is out
        np.testing.assert_allclose(out[:size, :size], expected, rtol=0, atol=1e-12 * max(1.0, np.abs(expected).max()))
