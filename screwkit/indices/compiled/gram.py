"""Compiled actuation wrenches of chains whose joint DoFs are not n (a Gram solve; idle DoFs).

:func:`gram_kernel` runs after :func:`screwkit.indices.compiled.wrenches.wrench_kernel` on the same
configurations, and only for mechanisms that have such a chain (an S-S rod with its idle spin,
a chain of a lower-mobility mechanism with more joints than the platform's DOF): for each of
their actuators, the minimum-norm wrench ``SWAP J' (J'^T J')^-1 e_k`` over the chain's joint
twists ``J'`` about its platform joint, in the working coordinates the first kernel chose
(:mod:`screwkit.indices.compiled.algebra`), with a pseudo-inverse, kept if consistent, when the joint twists are
dependent. Its own module, so that a mechanism without such chains never compiles it.

The kernel is a short driver over named stages, each a pass over the lanes of a block for one actuator:
its chain's unit joint twists about its platform joint (:func:`chain_unit_twist_lanes`), their Gram matrices
(:func:`gram_matrix_lanes`) and the minimum-norm wrenches (:func:`minimum_norm_wrenches`, with
:func:`consistent_pseudo_solution` for dependent joint twists). numba inlines them (``inline="always"``): the
kernel compiles as one function, with the results, bit for bit, of the loops written out in it.
"""

from __future__ import annotations

import numpy as np

from screwkit.common.fastmath import FASTMATH
from screwkit.common.jit import njit
from screwkit.indices.compiled.algebra import BLOCK, cross, pseudo_inverse, solve, working_point, working_twist

__all__ = ["gram_kernel"]

# The one signature: joint screws and points in any layout (as the first kernel's), the rest C-contiguous.
_SIGNATURE = (
    "void(float64[:, :, :], float64[:, :, :], int64[::1], int64[::1], int64[::1], int64, float64, float64, "
    "boolean[::1], float64[:, :, :, ::1], float64[:, ::1], float64[:, :, ::1], float64[:, :, ::1], float64)"
)


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def gram_scratch(capacity):
    """The scratch of one actuator, allocated once per call (chains of at most ``capacity`` joint DoFs): its
    chain's joint twists (capacity, 6, BLOCK) and platform joint d (3, BLOCK) in working coordinates, 1 / L
    (BLOCK), the unit twists about d (capacity, 6, BLOCK), their Gram matrices (capacity, capacity, BLOCK), then
    one lane's Gram matrix, elimination work, eigenvectors, eigenvalues, right-hand side and solution, and a lane
    of sums."""
    return (np.empty((capacity, 6, BLOCK)), np.empty((3, BLOCK)), np.empty(BLOCK), np.empty((capacity, 6, BLOCK)),
            np.empty((capacity, capacity, BLOCK)), np.empty((capacity, capacity)), np.empty((capacity, capacity)),
            np.empty((capacity, capacity)), np.empty(capacity), np.zeros(capacity), np.empty(capacity),
            np.empty(BLOCK))


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def chain_unit_twist_lanes(all_twists, all_points, first_index, width, start, m, centres, inverse_lengths, local,
                           platform, shifted_lanes):
    """The m joint twists of the chain starting at joint ``start`` about the centroid, and its platform joint d
    (its last joint's point), lengths in units of L (as the first kernel computes them); then ``shifted_lanes``,
    those twists about d each scaled to unit norm (a column scaling: the same wrench, and the Gram pivot test
    compares dimensionless numbers), lane by lane."""
    for j in range(m):
        for r in range(width):
            c0, c1, c2, inverse = centres[0, r], centres[1, r], centres[2, r], inverse_lengths[r]
            (local[j, 0, r], local[j, 1, r], local[j, 2, r], local[j, 3, r], local[j, 4, r],
             local[j, 5, r]) = working_twist(all_twists, first_index + r, start + j, c0, c1, c2, inverse)
    for r in range(width):
        platform[0, r], platform[1, r], platform[2, r] = working_point(
            all_points, first_index + r, start + m - 1, centres[0, r], centres[1, r], centres[2, r],
            inverse_lengths[r])
    for j in range(m):
        for r in range(width):
            w0, w1, w2 = local[j, 0, r], local[j, 1, r], local[j, 2, r]
            x0, x1, x2 = cross(w0, w1, w2, platform[0, r], platform[1, r],
                               platform[2, r])
            u0 = local[j, 3, r] + x0
            u1 = local[j, 4, r] + x1
            u2 = local[j, 5, r] + x2
            norm = np.sqrt(w0 * w0 + w1 * w1 + w2 * w2 + u0 * u0 + u1 * u1 + u2 * u2)
            inverse = 1.0 / norm if norm > 0.0 else 0.0
            shifted_lanes[j, 0, r] = w0 * inverse
            shifted_lanes[j, 1, r] = w1 * inverse
            shifted_lanes[j, 2, r] = w2 * inverse
            shifted_lanes[j, 3, r] = u0 * inverse
            shifted_lanes[j, 4, r] = u1 * inverse
            shifted_lanes[j, 5, r] = u2 * inverse


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def gram_matrix_lanes(shifted_lanes, m, width, lane0, gram_lanes):
    """gram_lanes[:m, :m, r] = J'^T J' of lane r, J' the m unit twists ``shifted_lanes[:m, :, r]``."""
    for i in range(m):
        for j in range(i + 1):
            for r in range(width):
                lane0[r] = 0.0
            for k in range(6):
                for r in range(width):
                    lane0[r] += shifted_lanes[i, k, r] * shifted_lanes[j, k, r]
            for r in range(width):
                gram_lanes[i, j, r] = lane0[r]
                gram_lanes[j, i, r] = lane0[r]


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def consistent_pseudo_solution(gram, m, column, rhs, solution, work, eigenvectors, eigenvalues,
                               pseudo_inverse_consistency):
    """``solution`` = column ``column`` of the pseudo-inverse of the singular gram[:m, :m] (dependent joint
    twists: an idle DoF), kept if consistent (gram solution = rhs within ``pseudo_inverse_consistency`` of its
    largest entry, at least 1), else zero."""
    pseudo = pseudo_inverse(gram, m, work, eigenvectors, eigenvalues)
    worst = 0.0
    for i in range(m):
        solution[i] = pseudo[i, column]
    for i in range(m):
        total = 0.0
        for j in range(m):
            total += gram[i, j] * solution[j]
        worst = max(worst, abs(total - rhs[i]))
    largest = 1.0
    for i in range(m):
        largest = max(largest, abs(solution[i]))
    if worst > pseudo_inverse_consistency * largest:
        for i in range(m):
            solution[i] = 0.0


@njit(cache=True, error_model="numpy")
def _remainder(vector, basis, count) -> float:
    """``vector`` less its components along basis[:count] (orthonormal rows; twice, for rounding), in place;
    returns the norm of what is left."""
    size = vector.shape[0]
    for _ in range(2):
        for q in range(count):
            along = 0.0
            for p in range(size):
                along += vector[p] * basis[q, p]
            for p in range(size):
                vector[p] -= along * basis[q, p]
    return np.sqrt(np.sum(vector * vector))


@njit(cache=True, error_model="numpy")
def singular_wrench(shifted_lanes, m, column, basis, row, r, platform, tolerance, twist):
    """At an input singularity of the chain (joint ``column``'s twist depends on the others: a leg stretched or
    folded), twist[:] = the twist-space vector (about d, halves to be swapped) of its actuation wrench, the limit
    of the minimum-norm one: in the span of the chain's unit twists and the motion space basis[row] (about d),
    reciprocal to every other joint (:func:`screwkit.screw.reference.actuation_wrench`). Returns whether it is
    unique (else ``twist`` is not written). Rare: not inlined."""
    vector, span = np.empty(6), np.empty((6, 6))
    size = 0
    for i in range(m + basis.shape[1]):  # an orthonormal basis of the span
        if i < m:
            for p in range(6):
                vector[p] = shifted_lanes[i, p, r]
        else:
            w0, w1, w2 = basis[row, i - m, 0], basis[row, i - m, 1], basis[row, i - m, 2]
            x0, x1, x2 = cross(w0, w1, w2, platform[0, r], platform[1, r], platform[2, r])
            vector[0], vector[1], vector[2] = w0, w1, w2
            vector[3] = basis[row, i - m, 3] + x0
            vector[4] = basis[row, i - m, 4] + x1
            vector[5] = basis[row, i - m, 5] + x2
            vector /= max(np.sqrt(np.sum(vector * vector)), 1e-300)
        norm = _remainder(vector, span, size)
        if norm > tolerance and size < 6:
            span[size] = vector / norm
            size += 1
    coordinates, taken = np.empty(size), np.empty((size, size))
    kept = 0
    for j in range(m):  # the other joints' coordinates in the span, orthonormalised
        if j == column:
            continue
        for q in range(size):
            coordinates[q] = np.sum(shifted_lanes[j, :, r] * span[q])
        norm = _remainder(coordinates, taken, kept)
        if norm > tolerance and kept < size:
            taken[kept] = coordinates / norm
            kept += 1
    if size - kept != 1:
        return False
    best, null, candidate = 0.0, np.zeros(size), np.empty(size)
    for e in range(size):  # the one direction of the span the other joints leave: the largest remainder
        candidate[:] = 0.0
        candidate[e] = 1.0
        norm = _remainder(candidate, taken, kept)
        if norm > best:
            best, null = norm, candidate / norm
    for p in range(6):
        twist[p] = np.sum(null * span[:size, p])
    return True


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def minimum_norm_wrenches(gram_lanes, shifted_lanes, m, column, first_index, width, outside, gram_pivot,
                          pseudo_inverse_consistency, gram, work, eigenvectors, eigenvalues, rhs, solution, force,
                          basis, platform, span_tolerance):
    """force[:, r] += SWAP J' (J'^T J')^-1 e_column, the minimum-norm wrench about d (J' the unit twists
    ``shifted_lanes``, J'^T J' ``gram_lanes``), configuration by configuration, or at an input singularity
    (no consistent solution) :func:`singular_wrench`'s; the configurations flagged ``outside`` are left alone
    (recomputed with their own motion space)."""
    limit = np.empty(6)
    for r in range(width):
        if outside[first_index + r]:
            continue  # recomputed with its own motion space
        for i in range(m):
            for j in range(m):
                gram[i, j] = gram_lanes[i, j, r]
            rhs[i] = 0.0
        rhs[column] = 1.0
        regular = solve(gram, m, rhs, solution, work, gram_pivot)
        if not regular:
            consistent_pseudo_solution(gram, m, column, rhs, solution, work, eigenvectors, eigenvalues,
                                       pseudo_inverse_consistency)
            zero = True
            for j in range(m):
                zero = zero and solution[j] == 0.0
            row = 0 if basis.shape[0] == 1 else first_index + r
            if zero and singular_wrench(shifted_lanes, m, column, basis, row, r, platform, span_tolerance,
                                        limit):
                force[0, r] += limit[3]
                force[1, r] += limit[4]
                force[2, r] += limit[5]
                force[3, r] += limit[0]
                force[4, r] += limit[1]
                force[5, r] += limit[2]
                continue
        for j in range(m):  # the wrench about d: SWAP of the combination
            y = solution[j]
            force[0, r] += y * shifted_lanes[j, 3, r]
            force[1, r] += y * shifted_lanes[j, 4, r]
            force[2, r] += y * shifted_lanes[j, 5, r]
            force[3, r] += y * shifted_lanes[j, 0, r]
            force[4, r] += y * shifted_lanes[j, 1, r]
            force[5, r] += y * shifted_lanes[j, 2, r]


@njit(_SIGNATURE, nogil=True, cache=True, error_model="numpy", fastmath=FASTMATH)
def gram_kernel(all_twists, all_points, chain_start, actuator_chain, actuator_joint, n, gram_pivot,
                pseudo_inverse_consistency, outside, force_rows, length_rows, centre_rows, basis,
                span_tolerance):
    """Add the actuation wrench of every actuator whose chain has other than n joint DoFs to ``force_rows``.

    Parameters (N configurations, J joints in all, C chains, a actuators)
    ----------
    all_twists (N, J, 6), all_points (N, J, 3), chain_start (C + 1,), actuator_chain,
        actuator_joint (a,) : as for :func:`screwkit.indices.compiled.wrenches.wrench_kernel`.
    n : the DOF of the motion space.
    gram_pivot, pseudo_inverse_consistency : the dimensionless tolerances GRAM_PIVOT and
        PSEUDO_INVERSE_CONSISTENCY of :mod:`screwkit.common.tolerances`.
    outside (N,) : the configurations the first kernel flagged (recomputed with their own motion
        space; left alone here).
    force_rows, length_rows, centre_rows : the first kernel's per-block wrenches (zero for these
        actuators), lengths L and centroids c (:func:`screwkit.indices.compiled.algebra.carry_arrays`).
    basis (1 or N, n, 6), span_tolerance : the motion space (working coordinates, as the first kernel's) and
        SINGULAR_SPAN, for the wrench at an input singularity (:func:`singular_wrench`).

    Per block and actuator of such a chain: :func:`chain_unit_twist_lanes`, :func:`gram_matrix_lanes`,
    :func:`minimum_norm_wrenches`.
    """
    count = all_twists.shape[0]
    capacity = 1
    for c in range(chain_start.shape[0] - 1):
        capacity = max(capacity, chain_start[c + 1] - chain_start[c])
    (local, platform, inverse_lengths, shifted_lanes, gram_lanes, gram, work, eigenvectors, eigenvalues, rhs,
     solution, lane0) = gram_scratch(capacity)
    for block in range((count + BLOCK - 1) // BLOCK):
        first_index = block * BLOCK
        width = min(count, first_index + BLOCK) - first_index
        centres = centre_rows[block]
        for r in range(width):
            inverse_lengths[r] = 1.0 / length_rows[block, r]
        for act in range(actuator_chain.shape[0]):
            start = chain_start[actuator_chain[act]]
            m = chain_start[actuator_chain[act] + 1] - start
            if m == n:
                continue  # the first kernel's
            chain_unit_twist_lanes(all_twists, all_points, first_index, width, start, m, centres, inverse_lengths,
                                   local, platform, shifted_lanes)
            gram_matrix_lanes(shifted_lanes, m, width, lane0, gram_lanes)
            minimum_norm_wrenches(gram_lanes, shifted_lanes, m, actuator_joint[act], first_index, width, outside,
                                  gram_pivot, pseudo_inverse_consistency, gram, work, eigenvectors, eigenvalues, rhs,
                                  solution, force_rows[block, act], basis, platform, span_tolerance)
