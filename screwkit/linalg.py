"""Small dense linear algebra on *batch-last* arrays (shape ``(rows, cols, N)``).

The hot paths of :mod:`screwkit.transmission` keep the batch of configurations on the
last, contiguous axis so that closed-form determinants and adjugates of small matrices
are a handful of element-wise operations over the whole batch. Larger matrices fall back
to numpy's batched LAPACK routines. Only numpy is imported here.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray


def determinant(matrix: NDArray[np.float64]) -> NDArray[np.float64]:
    """Determinant of square matrices of shape (..., n, n, N) -> (..., N)."""
    n = matrix.shape[-2]
    if n == 1:
        return matrix[..., 0, 0, :].copy()
    if n == 2:
        return matrix[..., 0, 0, :] * matrix[..., 1, 1, :] - matrix[..., 0, 1, :] * matrix[..., 1, 0, :]
    if n == 3:
        return np.einsum("...i,...i->...", matrix[..., 0, :, :].swapaxes(-1, -2),
                         _cross_rows(matrix[..., 1, :, :], matrix[..., 2, :, :]).swapaxes(-1, -2))
    return np.linalg.det(np.moveaxis(matrix, -1, -3))


def _cross_rows(first: NDArray, second: NDArray) -> NDArray:
    """Cross product of 3-vectors stored as (..., 3, N)."""
    return np.stack(
        [
            first[..., 1, :] * second[..., 2, :] - first[..., 2, :] * second[..., 1, :],
            first[..., 2, :] * second[..., 0, :] - first[..., 0, :] * second[..., 2, :],
            first[..., 0, :] * second[..., 1, :] - first[..., 1, :] * second[..., 0, :],
        ],
        axis=-2,
    )


def adjugate(matrix: NDArray[np.float64]) -> NDArray[np.float64]:
    r"""Adjugate (transposed cofactor matrix) of square matrices (..., n, n, N).

    :math:`W\,\mathrm{adj}(W) = \det(W) I`, and the adjugate stays well defined (and
    continuous) where :math:`W` is singular: for rank ``n - 1`` it is the rank-one
    product of the null vectors, for lower rank it is zero.
    """
    n = matrix.shape[-2]
    if n == 1:
        return np.ones_like(matrix)
    if n == 2:
        result = np.empty_like(matrix)
        result[..., 0, 0, :] = matrix[..., 1, 1, :]
        result[..., 1, 1, :] = matrix[..., 0, 0, :]
        result[..., 0, 1, :] = -matrix[..., 0, 1, :]
        result[..., 1, 0, :] = -matrix[..., 1, 0, :]
        return result
    if n == 3:
        rows = [matrix[..., i, :, :] for i in range(3)]
        # Column j of adj(W) is the cross product of the two rows other than j.
        columns = [_cross_rows(rows[1], rows[2]), _cross_rows(rows[2], rows[0]), _cross_rows(rows[0], rows[1])]
        return np.stack(columns, axis=-2)
    return np.moveaxis(_adjugate_lapack(np.moveaxis(matrix, -1, -3)), -3, -1)


def _adjugate_lapack(matrix: NDArray[np.float64]) -> NDArray[np.float64]:
    """Adjugate of (..., n, n) matrices: det * inverse where well conditioned, SVD elsewhere."""
    flat = matrix.reshape((-1,) + matrix.shape[-2:])
    n = flat.shape[-1]
    result = np.empty_like(flat)
    row_norms = np.prod(np.linalg.norm(flat, axis=-1), axis=-1)
    det = np.linalg.det(flat)
    with np.errstate(divide="ignore", invalid="ignore"):
        hadamard = np.abs(det) / row_norms
    good = hadamard > 1e-8
    if np.any(good):
        result[good] = det[good, None, None] * np.linalg.inv(flat[good])
    bad = ~good
    if np.any(bad):
        left, singular, right_t = np.linalg.svd(flat[bad])
        # adj(U S V^T) = adj(V^T) adj(S) adj(U) = det(V) V diag(prod_{j != i} s_j) det(U) U^T
        products = np.stack([np.prod(np.delete(singular, i, axis=-1), axis=-1) for i in range(n)], axis=-1)
        signs = np.linalg.det(left) * np.linalg.det(right_t)
        result[bad] = signs[:, None, None] * np.einsum("bij,bi,bki->bjk", right_t, products, left)
    return result.reshape(matrix.shape)


def null_vector(rows: NDArray[np.float64]) -> NDArray[np.float64]:
    r"""Generalised cross product of ``n - 1`` rows of length ``n``: shape (n-1, n, N) -> (n, N).

    The result is orthogonal to every row; its norm is the (n-1)-volume spanned by the
    rows, so it vanishes exactly when the rows are dependent. It is the last column of
    the adjugate of the square matrix whose first rows are ``rows``.
    """
    count, n = rows.shape[-3], rows.shape[-2]
    if count != n - 1:
        raise ValueError(f"Expected n - 1 rows of length n, got {count} rows of length {n}.")
    if n == 2:
        return np.stack([rows[..., 0, 1, :], -rows[..., 0, 0, :]], axis=-2)
    if n == 3:
        return _cross_rows(rows[..., 0, :, :], rows[..., 1, :, :])
    square = np.concatenate([rows, np.zeros_like(rows[..., :1, :, :])], axis=-3)
    return adjugate(square)[..., :, n - 1, :]


def solve_spd(gram: NDArray[np.float64], rhs: NDArray[np.float64]) -> tuple[NDArray, NDArray]:
    """Solve symmetric positive semi-definite systems ``gram x = rhs``, shapes (m, m, N) and (m, k, N).

    Returns ``(solution, regular)``; where the Gram matrix is singular (determinant below
    1e-12 times the product of its diagonal) the solution is zero and ``regular`` is False.
    """
    m = gram.shape[0]
    det = determinant(gram)
    diagonal_product = np.prod(np.stack([gram[i, i] for i in range(m)]), axis=0)
    regular = np.abs(det) > 1e-12 * diagonal_product
    if m <= 3:
        safe = np.where(regular, det, 1.0)
        solution = _matmul(adjugate(gram), rhs) / safe
    else:
        batch_gram = np.moveaxis(gram, -1, 0).copy()
        batch_gram[~regular] = np.eye(m)
        solution = np.moveaxis(np.linalg.solve(batch_gram, np.moveaxis(rhs, -1, 0)), 0, -1)
    return np.where(regular, solution, 0.0), regular


def _matmul(first: NDArray, second: NDArray) -> NDArray:
    """Matrix product of batch-last stacks (..., i, j, N) @ (..., j, k, N)."""
    return np.einsum("...ijn,...jkn->...ikn", first, second)
