"""The small dense algebra inside the compiled kernel, against numpy's determinants."""

from __future__ import annotations

import numpy as np

from screwkit._kernels import _null_vector


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
            _null_vector(np.ascontiguousarray(rows), size, out, work, columns)
            expected = cofactors(rows)
            scale = np.prod(np.linalg.norm(rows, axis=1))
            np.testing.assert_allclose(out, expected, rtol=0, atol=1e-12 * scale)
            np.testing.assert_allclose(rows @ out, 0.0, atol=1e-12 * scale * np.abs(rows).max())
            if case % 4 == 2 and size > 2:
                assert np.all(out == 0.0) or np.abs(out).max() <= 1e-12 * scale
