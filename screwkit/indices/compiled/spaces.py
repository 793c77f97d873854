"""Compiled chain decompositions and motion spaces of lower-mobility mechanisms, configuration by configuration.

:func:`space_kernel` does for a chunk of configurations what :func:`screwkit.screw.motion.chain_decompositions`
and :func:`screwkit.screw.motion.null_spaces` do with numpy (the readable reference, which
``tests/test_space_kernel.py`` holds it to): for each chain, the singular values and right singular vectors of
its joint twists in working coordinates, each scaled to unit norm (:func:`chain_singular_vectors`, one-sided
Jacobi rotations); then the sum over chains of the projectors on the complements of their twist spaces
(:func:`add_complement_projector`) and its eigen-decomposition (:func:`symmetric_eigen`, cyclic Jacobi rotations),
whose eigenvectors of (nearly) zero eigenvalues span the platform's motion space. numpy calls LAPACK once per
6 x 6 matrix (about 10 microseconds each, four or five per configuration); here one configuration takes a few
microseconds.

Both decompositions are backward stable, like LAPACK's: singular values agree with numpy's to rounding; a right
singular vector is unique only up to sign (and within a repeated singular value, up to a rotation), so what the
callers use is a span (the complement of a chain's twists, the motion space), which agrees to rounding. Its own
module, compiled only for mechanisms of fewer than six DoF.
"""

from __future__ import annotations

import numpy as np

from screwkit.common.fastmath import FASTMATH
from screwkit.common.jit import njit

__all__ = ["space_kernel", "JACOBI_TOLERANCE", "JACOBI_SWEEPS", "NULL_COLUMN"]

JACOBI_TOLERANCE = 1e-15
"""A pair of columns (rows) counts as orthogonal when their product is at most this times their norms' product."""
JACOBI_SWEEPS = 60
"""Sweeps of rotations at most (a 6 x 6 matrix converges in 5 to 8)."""
NULL_COLUMN = 1e-15
"""A column of the one-sided rotations whose norm is at most this times the matrix's (Frobenius) is null: rounding
noise, not rotated further (its singular value is far below any rank tolerance)."""

# The one signature: working twists (N, J, 6) in any layout, the rest C-contiguous.
_SIGNATURE = ("void(float64[:, :, :], int64[::1], float64, float64[:, :, ::1], float64[:, :, :, ::1], "
              "float64[:, ::1], float64[:, :, ::1])")


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def unit_columns(twists, index, start, m, columns):
    """columns[:m, k] = component k of the chain's joint twists (joints start .. start + m) scaled to unit norm
    (a zero twist stays zero): the chain's twist matrix, transposed, its columns the six components."""
    for j in range(m):
        total = 0.0
        for k in range(6):
            total += twists[index, start + j, k] * twists[index, start + j, k]
        norm = np.sqrt(total)
        inverse = 1.0 / norm if norm > 0.0 else 1.0
        for k in range(6):
            columns[j, k] = twists[index, start + j, k] * inverse


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
def chain_singular_vectors(columns, m, vectors, norms, order, singular, right):
    """Singular values (descending, ``singular``) and right singular vectors (rows of ``right``) of the m x 6
    matrix ``columns`` (destroyed), by one-sided Jacobi rotations of its six columns (Hestenes): the rotations,
    accumulated in ``vectors``, make the columns orthogonal; their norms are the singular values. As numpy's
    SVD of the rows padded with zero rows to six (more rows than six: the six leading singular values)."""
    for i in range(6):
        for j in range(6):
            vectors[i, j] = 1.0 if i == j else 0.0
    floor = NULL_COLUMN * NULL_COLUMN * m  # of a squared column norm; the m unit rows hold m in all
    for _ in range(JACOBI_SWEEPS):
        for p in range(6):  # the squared column norms, afresh each sweep (updated by the rotations within it)
            total = 0.0
            for k in range(m):
                total += columns[k, p] * columns[k, p]
            norms[p] = total
        rotated = False
        for p in range(5):
            for q in range(p + 1, 6):
                alpha, beta, gamma = norms[p], norms[q], 0.0
                for k in range(m):
                    gamma += columns[k, p] * columns[k, q]
                if abs(gamma) <= JACOBI_TOLERANCE * np.sqrt(alpha * beta) or min(alpha, beta) <= floor:
                    continue  # orthogonal, or a null column (rounding: no direction to keep orthogonal)
                rotated = True
                c, s = rotation_of(alpha, beta, gamma)
                rotate_pair(columns, m, p, q, c, s)
                rotate_pair(vectors, 6, p, q, c, s)
                norms[p] = alpha - s / c * gamma
                norms[q] = beta + s / c * gamma
        if not rotated:
            break
    for p in range(6):
        total = 0.0
        for k in range(m):
            total += columns[k, p] * columns[k, p]
        norms[p] = np.sqrt(total)
    sorted_order(norms, order, True)
    for i in range(6):
        singular[i] = norms[order[i]]
        for k in range(6):
            right[i, k] = vectors[k, order[i]]


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def sorted_order(values, order, descending):
    """order[:6] = the indices of values[:6] sorted (stable insertion sort), descending or ascending."""
    for i in range(6):
        order[i] = i
    for i in range(1, 6):
        j = i
        while j > 0 and ((values[order[j]] > values[order[j - 1]]) if descending
                         else (values[order[j]] < values[order[j - 1]])):
            order[j], order[j - 1] = order[j - 1], order[j]
            j -= 1


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def add_complement_projector(singular, right, tolerance, total):
    """total += R_out^T R_out, R_out the right singular vectors whose singular values are at most ``tolerance``
    times the largest: the projector on the complement of the chain's twist space."""
    for i in range(6):
        if singular[i] <= tolerance * singular[0]:
            for p in range(6):
                for q in range(6):
                    total[p, q] += right[i, p] * right[i, q]


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
                if matrix[p, q] == 0.0:
                    continue
                c, s = rotation_of(matrix[p, p], matrix[q, q], matrix[p, q])
                rotate_pair(matrix, 6, p, q, c, s)
                for k in range(6):  # rows p and q
                    x = matrix[p, k]
                    y = matrix[q, k]
                    matrix[p, k] = c * x - s * y
                    matrix[q, k] = s * x + c * y
                matrix[p, q] = 0.0
                matrix[q, p] = 0.0
                rotate_pair(vectors, 6, p, q, c, s)
    for i in range(6):
        diagonal[i] = matrix[i, i]
    sorted_order(diagonal, order, False)
    for i in range(6):
        values[i] = diagonal[order[i]]
        for k in range(6):
            sorted_vectors[k, i] = vectors[k, order[i]]


@njit(_SIGNATURE, nogil=True, cache=True, error_model="numpy", fastmath=FASTMATH)
def space_kernel(twists, chain_start, tolerance, singular, right, eigenvalues, eigenvectors):
    """Chain decompositions and motion spaces of N configurations.

    Parameters (N configurations, J joints in all, C chains)
    ----------
    twists (N, J, 6) : every chain's joint twists in working coordinates, chains in consecutive joints.
    chain_start (C + 1,) : the first joint of each chain, and J.
    tolerance : MOTION_SPACE_TOLERANCE, the relative rank tolerance of a chain's unit twists.
    singular (C, N, 6), right (C, N, 6, 6) : out, each chain's singular values and right singular vectors (rows),
        as :func:`screwkit.screw.motion.chain_decompositions`.
    eigenvalues (N, 6), eigenvectors (N, 6, 6) : out, of the sum over chains of ``I - P_chain``, as
        ``numpy.linalg.eigh`` of :func:`screwkit.screw.motion.chain_projector_complements`.
    """
    chains = chain_start.shape[0] - 1
    capacity = 6
    for c in range(chains):
        capacity = max(capacity, chain_start[c + 1] - chain_start[c])
    columns = np.empty((capacity, 6))
    vectors = np.empty((6, 6))
    total = np.empty((6, 6))
    norms = np.empty(6)
    order = np.empty(6, dtype=np.int64)
    for index in range(twists.shape[0]):
        for p in range(6):
            for q in range(6):
                total[p, q] = 0.0
        for c in range(chains):
            m = chain_start[c + 1] - chain_start[c]
            unit_columns(twists, index, chain_start[c], m, columns)
            chain_singular_vectors(columns, m, vectors, norms, order, singular[c, index], right[c, index])
            add_complement_projector(singular[c, index], right[c, index], tolerance, total)
        symmetric_eigen(total, vectors, norms, order, eigenvalues[index], eigenvectors[index])
