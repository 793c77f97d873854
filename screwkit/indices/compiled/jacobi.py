"""Jacobi rotations shared by the compiled kernels: the one-sided rotations of a singular value decomposition
(Hestenes) and the two-sided cyclic rotations of a symmetric eigen-decomposition.

:func:`singular_vectors` (the chains' twist matrices of :mod:`screwkit.indices.compiled.spaces`, the pairings of
released constraint wrenches of :mod:`screwkit.indices.compiled.constraints`), :func:`symmetric_eigen` (the motion
spaces, the common constraint wrenches) and :func:`screwkit.indices.compiled.algebra.pseudo_inverse` (the Gram
kernel's idle-DoF fallback) take their rotations from here: :func:`rotation_of` (the angle), :func:`rotate_pair`
(two columns) and :func:`rotate_symmetric` (a two-sided rotation of a symmetric matrix with its eigenvectors).
Each is backward stable like LAPACK's decompositions: values agree with numpy's to rounding, vectors up to sign
(and, within a repeated value, up to a rotation).
"""

from __future__ import annotations

import numpy as np

from screwkit.common.fastmath import FASTMATH
from screwkit.common.jit import njit

__all__ = ["JACOBI_TOLERANCE", "JACOBI_SWEEPS", "NULL_COLUMN", "rotation_of", "rotate_pair", "rotate_symmetric",
           "sorted_order", "singular_vectors", "symmetric_eigen", "unit_columns"]

JACOBI_TOLERANCE = 1e-15
"""A pair of columns (rows) counts as orthogonal when their product is at most this times their norms' product."""
JACOBI_SWEEPS = 60
"""Sweeps of rotations at most (a 6 x 6 matrix converges in 5 to 8)."""
NULL_COLUMN = 1e-15
"""A column of the one-sided rotations whose norm is at most this times the matrix's (Frobenius) is null: rounding
noise, not rotated further (its singular value is far below any rank tolerance)."""


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def rotate_pair(matrix, rows, p, q, c, s):
    """Columns p and q of matrix[:rows] rotated: (c a_p - s a_q, s a_p + c a_q)."""
    for k in range(rows):
        x = matrix[k, p]
        y = matrix[k, q]
        matrix[k, p] = c * x - s * y
        matrix[k, q] = s * x + c * y


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def rotation_of(alpha, beta, gamma):
    """(c, s) of the Jacobi rotation that zeroes the product ``gamma`` of two columns of squared norms alpha, beta
    (or the off-diagonal entry of a symmetric 2 x 2 block [[alpha, gamma], [gamma, beta]])."""
    zeta = (beta - alpha) / (2.0 * gamma)
    t = (1.0 if zeta >= 0.0 else -1.0) / (abs(zeta) + np.sqrt(1.0 + zeta * zeta))
    c = 1.0 / np.sqrt(1.0 + t * t)
    return c, c * t


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def rotate_symmetric(matrix, size, vectors, p, q):
    """One two-sided Jacobi rotation of the symmetric matrix[:size, :size] that zeroes its entry (p, q) (nonzero),
    accumulated in the columns of ``vectors``."""
    c, s = rotation_of(matrix[p, p], matrix[q, q], matrix[p, q])
    rotate_pair(matrix, size, p, q, c, s)
    for k in range(size):  # rows p and q
        x = matrix[p, k]
        y = matrix[q, k]
        matrix[p, k] = c * x - s * y
        matrix[q, k] = s * x + c * y
    matrix[p, q] = 0.0
    matrix[q, p] = 0.0
    rotate_pair(vectors, size, p, q, c, s)


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def sorted_order(values, size, order, descending):
    """order[:size] = the indices of values[:size] sorted (stable insertion sort), descending or ascending."""
    for i in range(size):
        order[i] = i
    for i in range(1, size):
        j = i
        while j > 0 and ((values[order[j]] > values[order[j - 1]]) if descending
                         else (values[order[j]] < values[order[j - 1]])):
            order[j], order[j - 1] = order[j - 1], order[j]
            j -= 1


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def unit_columns(twists, index, start, m, columns):
    """columns[:m, k] = component k of the chain's joint twists (joints start .. start + m) scaled to unit norm
    (a zero twist stays zero): the chain's twist matrix, its columns the six components."""
    for j in range(m):
        total = 0.0
        for k in range(6):
            total += twists[index, start + j, k] * twists[index, start + j, k]
        norm = np.sqrt(total)
        inverse = 1.0 / norm if norm > 0.0 else 1.0
        for k in range(6):
            columns[j, k] = twists[index, start + j, k] * inverse


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def column_norms(columns, m, width, norms):
    """norms[:width] = the squared norms of the columns of columns[:m, :width]."""
    for p in range(width):
        total = 0.0
        for k in range(m):
            total += columns[k, p] * columns[k, p]
        norms[p] = total


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def orthogonal_columns(columns, m, width, vectors, norms, floor):
    """Rotate the columns of columns[:m, :width] until orthogonal (one-sided Jacobi), the rotations accumulated
    in vectors[:width, :width]; a column of squared norm at most ``floor`` is null (not rotated)."""
    for i in range(width):
        for j in range(width):
            vectors[i, j] = 1.0 if i == j else 0.0
    for _ in range(JACOBI_SWEEPS):
        column_norms(columns, m, width, norms)  # afresh each sweep (updated by the rotations within it)
        rotated = False
        for p in range(width - 1):
            for q in range(p + 1, width):
                alpha, beta, gamma = norms[p], norms[q], 0.0
                for k in range(m):
                    gamma += columns[k, p] * columns[k, q]
                if abs(gamma) <= JACOBI_TOLERANCE * np.sqrt(alpha * beta) or min(alpha, beta) <= floor:
                    continue  # orthogonal, or a null column (rounding: no direction to keep orthogonal)
                rotated = True
                c, s = rotation_of(alpha, beta, gamma)
                rotate_pair(columns, m, p, q, c, s)
                rotate_pair(vectors, width, p, q, c, s)
                norms[p] = alpha - s / c * gamma
                norms[q] = beta + s / c * gamma
        if not rotated:
            break


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def singular_vectors(columns, m, width, floor, vectors, norms, order, singular, right):
    """Singular values (descending, ``singular[:width]``) and right singular vectors (rows of
    ``right[:width, :width]``) of the m x width matrix ``columns``, by one-sided Jacobi rotations of its columns
    (:func:`orthogonal_columns`; ``floor`` the squared norm of a null column): as numpy's SVD of the rows padded
    with zero rows to ``width`` (more rows than ``width``: the leading singular values). The rotated columns are
    left in ``columns``, in the original order: column ``order[i]`` is ``singular[i]`` times left singular
    vector ``i``."""
    orthogonal_columns(columns, m, width, vectors, norms, floor)
    column_norms(columns, m, width, norms)
    for p in range(width):
        norms[p] = np.sqrt(norms[p])
    sorted_order(norms, width, order, True)
    for i in range(width):
        singular[i] = norms[order[i]]
        for k in range(width):
            right[i, k] = vectors[k, order[i]]


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def symmetric_eigen(matrix, vectors, diagonal, order, values, sorted_vectors):
    """Eigenvalues (ascending, ``values``) and eigenvectors (columns of ``sorted_vectors``) of the symmetric 6 x 6
    ``matrix`` (destroyed), by cyclic Jacobi rotations, as ``numpy.linalg.eigh``."""
    for i in range(6):
        for j in range(6):
            vectors[i, j] = 1.0 if i == j else 0.0
    for _ in range(JACOBI_SWEEPS):
        off, scale = 0.0, 0.0
        for i in range(6):
            scale += matrix[i, i] * matrix[i, i]
            for j in range(i + 1, 6):
                off += matrix[i, j] * matrix[i, j]
        if off <= JACOBI_TOLERANCE * JACOBI_TOLERANCE * scale:
            break
        for p in range(5):
            for q in range(p + 1, 6):
                if matrix[p, q] != 0.0:
                    rotate_symmetric(matrix, 6, vectors, p, q)
    for i in range(6):
        diagonal[i] = matrix[i, i]
    sorted_order(diagonal, 6, order, False)
    for i in range(6):
        values[i] = diagonal[order[i]]
        for k in range(6):
            sorted_vectors[k, i] = vectors[k, order[i]]
