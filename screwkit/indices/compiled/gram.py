"""Compiled actuation wrenches of chains whose joint DoFs are not n (a Gram solve; idle DoFs).

:func:`gram_kernel` runs after :func:`screwkit.indices.compiled.wrenches.wrench_kernel` on the same
configurations, and only for mechanisms that have such a chain (an S-S rod with its idle spin,
a chain of a lower-mobility mechanism with more joints than the platform's DOF): for each of
their actuators, the minimum-norm wrench ``SWAP J' (J'^T J')^-1 e_k`` over the chain's joint
twists ``J'`` about its platform joint, in the working coordinates the first kernel chose
(:mod:`screwkit.indices.compiled.algebra`), with a pseudo-inverse, kept if consistent, when the joint twists are
dependent. Its own module, so that a mechanism without such chains never compiles it.
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
    "boolean[::1], float64[:, :, :, ::1], float64[:, ::1], float64[:, :, ::1])"
)


@njit(_SIGNATURE, nogil=True, cache=True, error_model="numpy", fastmath=FASTMATH)
def gram_kernel(all_twists, all_points, chain_start, actuator_chain, actuator_joint, n, gram_pivot,
                pseudo_inverse_consistency, outside, force_rows, length_rows, centre_rows):
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
    """
    count = all_twists.shape[0]
    chains = chain_start.shape[0] - 1
    a = actuator_chain.shape[0]
    blocks = (count + BLOCK - 1) // BLOCK
    capacity = 1
    for c in range(chains):
        capacity = max(capacity, chain_start[c + 1] - chain_start[c])
    local = np.empty((capacity, 6, BLOCK))  # the chain's joint twists in working coordinates
    platform = np.empty((3, BLOCK))  # its platform joint d in working coordinates
    inverse_lengths = np.empty(BLOCK)
    shifted_lanes = np.empty((capacity, 6, BLOCK))  # a chain's unit twists about d
    gram_lanes = np.empty((capacity, capacity, BLOCK))
    gram = np.empty((capacity, capacity))
    work = np.empty((capacity, capacity))
    eigenvectors = np.empty((capacity, capacity))
    eigenvalues = np.empty(capacity)
    rhs = np.zeros(capacity)
    solution = np.empty(capacity)
    lane0 = np.empty(BLOCK)
    for block in range(blocks):
        first_index = block * BLOCK
        width = min(count, first_index + BLOCK) - first_index
        forces = force_rows[block]
        lengths = length_rows[block]
        centres = centre_rows[block]
        for r in range(width):
            inverse_lengths[r] = 1.0 / lengths[r]
        for act in range(a):
            chain = actuator_chain[act]
            start = chain_start[chain]
            m = chain_start[chain + 1] - start
            if m == n:
                continue  # the first kernel's
            own = start + actuator_joint[act]
            last = start + m - 1
            force = forces[act]
            # --- the chain's twists about the centroid and its platform joint, lengths in units of
            # L (as the first kernel computes them).
            for j in range(m):
                for r in range(width):
                    c0, c1, c2, inverse = centres[0, r], centres[1, r], centres[2, r], inverse_lengths[r]
                    (local[j, 0, r], local[j, 1, r], local[j, 2, r], local[j, 3, r], local[j, 4, r],
                     local[j, 5, r]) = working_twist(all_twists, first_index + r, start + j, c0, c1, c2, inverse)
            for r in range(width):
                platform[0, r], platform[1, r], platform[2, r] = working_point(
                    all_points, first_index + r, last, centres[0, r], centres[1, r], centres[2, r], inverse_lengths[r])
            # Minimum-norm solution SWAP J' (J'^T J')^-1 e_k, J' the chain's twists about d in
            # working coordinates, each scaled to unit norm (a column scaling: the same wrench,
            # and the Gram pivot test compares dimensionless numbers). J' and its Gram matrix
            # across the lanes, then the solve configuration by configuration.
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
            for r in range(width):
                if outside[first_index + r]:
                    continue  # recomputed with its own motion space
                for i in range(m):
                    for j in range(m):
                        gram[i, j] = gram_lanes[i, j, r]
                    rhs[i] = 0.0
                rhs[own - start] = 1.0
                regular = solve(gram, m, rhs, solution, work, gram_pivot)
                if not regular:
                    # Dependent joint twists (an idle DoF): pseudo-inverse, kept if consistent.
                    pseudo = pseudo_inverse(gram, m, work, eigenvectors, eigenvalues)
                    worst = 0.0
                    for i in range(m):
                        solution[i] = pseudo[i, own - start]
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
                for j in range(m):  # the wrench about d: SWAP of the combination
                    y = solution[j]
                    force[0, r] += y * shifted_lanes[j, 3, r]
                    force[1, r] += y * shifted_lanes[j, 4, r]
                    force[2, r] += y * shifted_lanes[j, 5, r]
                    force[3, r] += y * shifted_lanes[j, 0, r]
                    force[4, r] += y * shifted_lanes[j, 1, r]
                    force[5, r] += y * shifted_lanes[j, 2, r]
