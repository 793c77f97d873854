"""Compiled actuation wrenches of chains with n joint DoFs, n other than 3 (null vectors).

:func:`null_kernel` runs after :func:`screwkit.indices.compiled.wrenches.wrench_kernel` on the same
configurations, and only for mechanisms that have such a chain (the hexapods, the Schoenflies
robot, ``coop_arms``; not the planar mechanisms): for each of their actuators, the generalised
cross product ``x`` of the n - 1 passive rows the first kernel left (the chain's passive joint
twists against the motion basis ``M'`` shifted to the platform joint d), and the wrench
``SWAP M' x`` about d, in working coordinates (:mod:`screwkit.indices.compiled.algebra`). Its own module, so that
a planar mechanism never compiles the lane-innermost elimination
(:func:`screwkit.indices.compiled.algebra.null_vectors_lanes`).
"""

from __future__ import annotations

import numpy as np

from screwkit.common.fastmath import FASTMATH
from screwkit.common.jit import njit
from screwkit.indices.compiled.algebra import (
    BLOCK,
    CARRY_SIGNATURE,
    add_swapped_combination,
    motion_lanes_of,
    null_vectors_lanes,
    shifted_basis_lanes,
    working_point,
)

__all__ = ["null_kernel"]

# The one signature: joint points in any layout (as the first stage's), the rest C-contiguous.
_SIGNATURE = "void(float64[:, :, :], int64[::1], int64[::1], float64[:, :, ::1], int64, " + CARRY_SIGNATURE + ")"


@njit(_SIGNATURE, nogil=True, cache=True, error_model="numpy", fastmath=FASTMATH)
def null_kernel(all_points, chain_start, actuator_chain, basis, count, force_rows, passive_row_rows, threshold_rows,
                length_rows, centre_rows):
    """Add the actuation wrench of every actuator whose chain has n joint DoFs (n not 3) to ``force_rows``.

    Parameters (N = ``count`` configurations, C chains, a actuators)
    ----------
    all_points, chain_start, actuator_chain, basis : as for
        :func:`screwkit.indices.compiled.wrenches.wrench_kernel`.
    force_rows, passive_row_rows, length_rows, centre_rows : the first kernel's per-block wrenches
        (zero for these actuators), passive rows, lengths L and centroids c
        (:func:`screwkit.indices.compiled.algebra.carry_arrays`); the thresholds are not used.
    """
    a = actuator_chain.shape[0]
    n = basis.shape[1]
    blocks = (count + BLOCK - 1) // BLOCK
    motion_lanes = np.empty((n, 6, BLOCK))
    platform = np.empty((3, BLOCK))  # the platform joint d in working coordinates
    shifted_basis = np.empty((n, 6, BLOCK))
    combination = np.empty((n, BLOCK))
    locked_rows = np.empty((max(n - 1, 1), n, BLOCK))
    elimination = np.empty((max(n - 1, 1), n, BLOCK))
    lane_a = np.empty(BLOCK)
    lane_b = np.empty(BLOCK)
    lane_c = np.empty(BLOCK)
    lane_d = np.empty(BLOCK)
    lane_e = np.empty(BLOCK)
    rows = np.empty((6, 6))
    work = np.empty((6, 6))
    columns = np.empty(6, dtype=np.int64)
    scalar_out = np.empty(6)
    for block in range(blocks):
        first_index = block * BLOCK
        width = min(count, first_index + BLOCK) - first_index
        forces = force_rows[block]
        null_rows = passive_row_rows[block]
        lengths = length_rows[block]
        centres = centre_rows[block]
        motion_lanes_of(basis, first_index, width, motion_lanes)
        for act in range(a):
            chain = actuator_chain[act]
            if chain_start[chain + 1] - chain_start[chain] != n:
                continue  # the Gram kernel's
            for r in range(width):
                platform[0, r], platform[1, r], platform[2, r] = working_point(
                    all_points, first_index + r, chain_start[chain + 1] - 1, centres[0, r], centres[1, r],
                    centres[2, r], 1.0 / lengths[r])
            # The motion basis about d (as the first kernel shifted it).
            shifted_basis_lanes(motion_lanes, platform, width, shifted_basis)
            for i in range(n - 1):
                for q in range(n):
                    for r in range(width):
                        locked_rows[i, q, r] = null_rows[act, i, q, r]
            null_vectors_lanes(locked_rows, n, width, combination, elimination, lane_a, lane_b, lane_c, lane_d,
                               lane_e, rows, work, columns, scalar_out)
            add_swapped_combination(combination, shifted_basis, width, forces[act])  # the wrench about d
