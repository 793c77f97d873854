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
from screwkit.indices.compiled.jacobi import NULL_COLUMN, singular_vectors, symmetric_eigen, unit_columns

__all__ = ["space_kernel"]

# The one signature: working twists (N, J, 6) in any layout, the rest C-contiguous.
_SIGNATURE = ("void(float64[:, :, :], int64[::1], float64, float64[:, :, ::1], float64[:, :, :, ::1], "
              "float64[:, ::1], float64[:, :, ::1])")


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def chain_singular_vectors(columns, m, vectors, norms, order, singular, right):
    """Singular values (descending, ``singular``) and right singular vectors (rows of ``right``) of the m x 6
    matrix ``columns`` of unit rows (destroyed), by one-sided Jacobi rotations of its six columns
    (:func:`screwkit.indices.compiled.jacobi.singular_vectors`): as numpy's SVD of the rows padded with zero rows
    to six (more rows than six: the six leading singular values)."""
    singular_vectors(columns, m, 6, NULL_COLUMN * NULL_COLUMN * m,  # the m unit rows hold m in all
                     vectors, norms, order, singular, right)


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def add_complement_projector(singular, right, tolerance, total):
    """total += R_out^T R_out, R_out the right singular vectors whose singular values are at most ``tolerance``
    times the largest: the projector on the complement of the chain's twist space."""
    for i in range(6):
        if singular[i] <= tolerance * singular[0]:
            for p in range(6):
                for q in range(6):
                    total[p, q] += right[i, p] * right[i, q]


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
