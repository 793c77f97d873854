"""Compiled first stage of :func:`screwkit.indices.analysis.analyze`: working coordinates, actuation wrenches.

For a chunk of configurations, 64 at a time (:data:`screwkit.indices.compiled.algebra.BLOCK`, lane-innermost),
:func:`wrench_kernel` moves every configuration into its working coordinates (see
:mod:`screwkit.indices.compiled.algebra`), flags those whose joint twists leave a constant motion space, and
derives the actuation wrench, in the representative documented in
:func:`screwkit.indices.analysis.analyze`, of every actuator whose chain has n = 3 joint DoFs (the
cross product of its two passive rows in the motion space). For chains of n joint DoFs with
n other than 3 it leaves the passive rows to :mod:`screwkit.indices.compiled.null`, for the other chains
everything to :mod:`screwkit.indices.compiled.gram`; per block, what the later stages need
(:func:`screwkit.indices.compiled.algebra.carry_arrays`). Its own module, so that it compiles apart from the
others (in parallel on a first run, :mod:`screwkit.common.compiling`).

The kernel is a short driver over named stages, run block by block: :func:`gather_block`,
:func:`platform_centroid`, :func:`characteristic_lengths`, :func:`working_coordinates`,
:func:`outside_constant_space` and, per actuator, :func:`actuation_wrench` (:func:`passive_rows_lanes`). numba
inlines them (``inline="always"``), so that the kernel compiles as one function, with the results, bit for bit, of
the loops written out.
"""

from __future__ import annotations

import numpy as np

from screwkit.common.fastmath import FASTMATH
from screwkit.common.jit import njit
from screwkit.indices.compiled.algebra import (
    BLOCK,
    CARRY_SIGNATURE,
    add_swapped_combination,
    cross,
    motion_lanes_of,
    shifted_basis_lanes,
)

__all__ = ["wrench_kernel"]

# The one signature. Joint screws and points come in any memory layout ("A": the loader's
# component-major blocks, hand-built batch-first arrays, slices of either), so a single compiled
# version serves every mechanism and is loaded from numba's disk cache when this module is
# imported; every other argument is C-contiguous (analyze() sees to it).
_SIGNATURE = (
    "void(float64[:, :, :], float64[:, :, :], int64[::1], int64[::1], int64[::1], float64[:, :, ::1], "
    "float64[:, ::1], float64, float64, float64, float64, boolean[::1], "
    + CARRY_SIGNATURE + ")"
)


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def gather_block(all_twists, all_points, first_index, width, local, local_points):
    """The block's joint twists and points, lane-innermost (component-major input is read in runs)."""
    for j in range(local.shape[0]):
        for k in range(6):
            for r in range(width):
                local[j, k, r] = all_twists[first_index + r, j, k]
        for k in range(3):
            for r in range(width):
                local_points[j, k, r] = all_points[first_index + r, j, k]


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def platform_centroid(chain_start, local_points, width, centres):
    """c, the centroid of the platform joints (the last joint of each chain): everything after is expressed about
    it."""
    chains = chain_start.shape[0] - 1
    for k in range(3):
        for r in range(width):
            centres[k, r] = 0.0
    for c in range(chains):
        last = chain_start[c + 1] - 1
        for k in range(3):
            for r in range(width):
                centres[k, r] += local_points[last, k, r]
    for k in range(3):
        for r in range(width):
            centres[k, r] /= chains


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def characteristic_lengths(local_points, centres, threshold, width, sum_sq, lengths, inverse_lengths, thresholds):
    """The characteristic length L (the RMS distance of every joint point from the centroid; 1 when they all sit
    on it), 1 / L and the threshold p / L, lane by lane; the joint points are moved to the centroid on the way."""
    joints = local_points.shape[0]
    for r in range(width):
        sum_sq[r] = 0.0
    for j in range(joints):
        for r in range(width):
            p0 = local_points[j, 0, r] - centres[0, r]
            p1 = local_points[j, 1, r] - centres[1, r]
            p2 = local_points[j, 2, r] - centres[2, r]
            local_points[j, 0, r] = p0
            local_points[j, 1, r] = p1
            local_points[j, 2, r] = p2
            sum_sq[r] += p0 * p0 + p1 * p1 + p2 * p2
    for r in range(width):
        length = np.sqrt(sum_sq[r] / joints)
        if not length > 0.0:  # every joint point at the centroid: no length to scale by
            length = 1.0
        lengths[r] = length
        inverse_lengths[r] = 1.0 / length
        thresholds[r] = threshold / length


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def working_coordinates(local, local_points, centres, inverse_lengths, width):
    """Working coordinates: the joint twists about the centroid, lengths (moments and points) in units of L."""
    for j in range(local.shape[0]):
        for r in range(width):
            x0, x1, x2 = cross(local[j, 0, r], local[j, 1, r], local[j, 2, r],
                                centres[0, r], centres[1, r], centres[2, r])
            inverse = inverse_lengths[r]
            local[j, 3, r] = (local[j, 3, r] + x0) * inverse
            local[j, 4, r] = (local[j, 4, r] + x1) * inverse
            local[j, 5, r] = (local[j, 5, r] + x2) * inverse
            local_points[j, 0, r] *= inverse
            local_points[j, 1, r] *= inverse
            local_points[j, 2, r] *= inverse


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def outside_constant_space(local, complement, outside_sq, first_index, width, lane0, lane1, lane2, outside,
                           outside_out):
    """Whether some joint twist leaves a constant basis: its projection on the complement above
    ``outside_tolerance`` times its norm (compared squared), into ``outside_out``."""
    for r in range(width):
        outside[r] = False
    for j in range(local.shape[0]):
        for r in range(width):
            lane0[r] = 0.0  # |t|^2
            lane1[r] = 0.0  # |projection on the complement|^2
        for k in range(6):
            for r in range(width):
                lane0[r] += local[j, k, r] * local[j, k, r]
        for row in range(complement.shape[0]):
            for r in range(width):
                lane2[r] = 0.0
            for k in range(6):
                for r in range(width):
                    lane2[r] += complement[row, k] * local[j, k, r]
            for r in range(width):
                lane1[r] += lane2[r] * lane2[r]
        for r in range(width):
            outside[r] = outside[r] or lane1[r] > outside_sq * lane0[r]
    for r in range(width):
        outside_out[first_index + r] = outside[r]


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def passive_rows_lanes(start, last, own, local, local_points, shifted_basis, width, passive_rows):
    """The chain's passive joint twists about its platform joint d (the last, working coordinates) in the shifted
    motion basis: the rows of J_passive'^T M', one per joint but the actuated one ``own``."""
    passive = 0
    for j in range(start, last + 1):
        if j == own:
            continue
        for q in range(shifted_basis.shape[0]):
            for r in range(width):
                x0, x1, x2 = cross(local[j, 0, r], local[j, 1, r], local[j, 2, r],
                                    local_points[last, 0, r], local_points[last, 1, r], local_points[last, 2, r])
                passive_rows[passive, q, r] = (
                    local[j, 0, r] * shifted_basis[q, 0, r] + local[j, 1, r] * shifted_basis[q, 1, r]
                    + local[j, 2, r] * shifted_basis[q, 2, r]
                    + (local[j, 3, r] + x0) * shifted_basis[q, 3, r]
                    + (local[j, 4, r] + x1) * shifted_basis[q, 4, r]
                    + (local[j, 5, r] + x2) * shifted_basis[q, 5, r])
        passive += 1


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def actuation_wrench(act, chain_start, actuator_chain, actuator_joint, local, local_points, motion_lanes, width,
                     shifted_basis, passive_rows, combination, force, null_rows, forces):
    """Actuator ``act``'s actuation wrench, in the representative documented in analyze(), into ``forces[act]``:
    for a chain of n = 3 joint DoFs, SWAP M' x with x the cross product of its two passive rows, about the platform
    joint d; for a chain of n joint DoFs (n other than 3), zero here and its passive rows into ``null_rows[act]``
    (:mod:`screwkit.indices.compiled.null` completes it); for other chains (more or fewer joint DoFs than n), zero
    (:mod:`screwkit.indices.compiled.gram`)."""
    n = motion_lanes.shape[0]
    chain = actuator_chain[act]
    start = chain_start[chain]
    m = chain_start[chain + 1] - start
    last = start + m - 1
    for k in range(6):
        for r in range(width):
            force[k, r] = 0.0
    if m == n:
        shifted_basis_lanes(motion_lanes, local_points[last], width, shifted_basis)
        passive_rows_lanes(start, last, start + actuator_joint[act], local, local_points, shifted_basis, width,
                           passive_rows)
        if n == 3:  # the null vector of two rows is their cross product
            for r in range(width):
                combination[0, r], combination[1, r], combination[2, r] = cross(
                    passive_rows[0, 0, r], passive_rows[0, 1, r], passive_rows[0, 2, r],
                    passive_rows[1, 0, r], passive_rows[1, 1, r], passive_rows[1, 2, r])
            add_swapped_combination(combination, shifted_basis, width, force)  # the wrench about d
        else:  # their null vector and the wrench: screwkit.indices.compiled.null, after this one
            for i in range(n - 1):
                for q in range(n):
                    for r in range(width):
                        null_rows[act, i, q, r] = passive_rows[i, q, r]
    for k in range(6):  # for the later stages
        for r in range(width):
            forces[act, k, r] = force[k, r]


@njit(_SIGNATURE, nogil=True, cache=True, error_model="numpy", fastmath=FASTMATH)
def wrench_kernel(all_twists, all_points, chain_start, actuator_chain, actuator_joint, basis, complement,
                  threshold, outside_tolerance, gram_pivot, pseudo_inverse_consistency, outside_out,
                  force_rows, passive_row_rows, threshold_rows, length_rows, centre_rows):
    """Working coordinates and actuation wrenches (before normalisation) of a chunk of configurations.

    Parameters (N configurations, J joints in all, C chains, a actuators, n DOF)
    ----------
    all_twists (N, J, 6), all_points (N, J, 3) : joint screws and points of every chain, world
        frame, in any memory layout (the loader's are component-major): each block of
        configurations is first gathered into a small batch-first buffer.
    chain_start (C + 1,) : joints of chain c are chain_start[c]:chain_start[c+1].
    actuator_chain, actuator_joint (a,) : chain and joint (within the chain) of each actuator.
    basis (1 or N, n, 6) : orthonormal motion-space basis in working coordinates (1: the same
        for all).
    complement (6 - n, 6) : orthonormal complement of a constant basis, used to flag configurations
        whose joint twists leave it (``outside_out``); they are recomputed with their own basis.
    threshold : the singularity threshold p, in the length unit of the screws (compared as p / L).
    outside_tolerance, gram_pivot, pseudo_inverse_consistency : the dimensionless tolerances
        OUTSIDE_CONSTANT_SPACE, GRAM_PIVOT and PSEUDO_INVERSE_CONSISTENCY of
        :mod:`screwkit.common.tolerances`, applied in working coordinates.
    Outputs: outside_out (N,) bool; and, per block, the arrays of
        :func:`screwkit.indices.compiled.algebra.carry_arrays` (at least (N + BLOCK - 1) // BLOCK blocks) for
        :func:`screwkit.indices.compiled.outputs.output_kernel`.
    """
    count, joints, n = all_twists.shape[0], chain_start[chain_start.shape[0] - 1], basis.shape[1]
    # Scratch, allocated once per call. Per-configuration quantities have a last "lane" axis:
    # each block of BLOCK configurations goes through every step lane-innermost, so that the
    # compiler vectorises the steps across configurations.
    local = np.empty((joints, 6, BLOCK))  # joint twists about the centroid
    local_points = np.empty((joints, 3, BLOCK))  # joint points relative to the centroid
    inverse_lengths, outside = np.empty(BLOCK), np.zeros(BLOCK, dtype=np.bool_)
    force = np.empty((6, BLOCK))  # (f, m) of the wrench being built
    motion_lanes, shifted_basis = np.empty((n, 6, BLOCK)), np.empty((n, 6, BLOCK))
    passive_rows, combination = np.empty((6, 6, BLOCK)), np.empty((3, BLOCK))
    lane0, lane1, lane2 = np.empty(BLOCK), np.empty(BLOCK), np.empty(BLOCK)
    for block in range((count + BLOCK - 1) // BLOCK):
        first_index = block * BLOCK
        width = min(count, first_index + BLOCK) - first_index
        centres = centre_rows[block]
        gather_block(all_twists, all_points, first_index, width, local, local_points)
        platform_centroid(chain_start, local_points, width, centres)
        characteristic_lengths(local_points, centres, threshold, width, lane0, length_rows[block], inverse_lengths,
                               threshold_rows[block])
        working_coordinates(local, local_points, centres, inverse_lengths, width)
        motion_lanes_of(basis, first_index, width, motion_lanes)
        if basis.shape[0] == 1 and complement.shape[0] > 0:  # a constant basis must contain every joint twist
            outside_constant_space(local, complement, outside_tolerance * outside_tolerance, first_index, width,
                                   lane0, lane1, lane2, outside, outside_out)
        for act in range(actuator_chain.shape[0]):  # one actuation wrench per actuator
            actuation_wrench(act, chain_start, actuator_chain, actuator_joint, local, local_points, motion_lanes,
                             width, shifted_basis, passive_rows, combination, force, passive_row_rows[block],
                             force_rows[block])
