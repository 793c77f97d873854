"""Compiled second stage of :func:`screwkit.indices.analysis.analyze`: ITIs, output twists, OTIs, LMTI, F_Oj.

For the blocks of configurations :func:`screwkit.indices.compiled.wrenches.wrench_kernel` has prepared
(:func:`screwkit.indices.compiled.algebra.carry_arrays`, working coordinates), :func:`output_kernel` normalises
each actuation wrench, computes its ITI (Eq. 6; the mechanism's, Eq. 7) and the characteristic
point and pitch of its OTI, then builds the output twist of every set of n - 1 locked actuators
(the cofactor vector of their wrench rows: an exterior product of the locked rows, level by
level, each locked set starting from the minors it shares with the set before it; no pivoting,
no division), the OTIs of every non-redundant submechanism (Eqs. 8-9, with the identity
|A_k o T_k| = |det W| of Eq. A3, so that a submechanism's OTI is |det W| over its longest moment
arm), the LMTI of all actuators (Eq. 11), F_Oj for each j (Eqs. 12-13) with the worst fault set,
and the mutual-interference actuators. The kernel is a short driver over named stages, each a few passes
over all the items of one kind in a block: the actuators (:func:`screwkit.indices.compiled.actuators.actuator_stage`),
the locked sets (:func:`locked_stage`), the submechanisms (:func:`submechanism_stage`) and the reductions over
actuator sets (:func:`reduction_stage`). numba inlines every stage
(``inline="always"``), so that the kernel compiles as one function, with the results, bit for bit, of the loops
written out (see :mod:`screwkit.indices.compiled.actuators` on the cost of an inlined call). Its own module, so that
it compiles apart from :mod:`screwkit.indices.compiled.wrenches` (in parallel on a first run,
:mod:`screwkit.common.compiling`).

Loops over the configurations of a block (lanes) write one array each where they are hot: the
compiler vectorises a loop only when it can rule out, with few runtime checks, that what it
writes overlaps what it reads.
"""

from __future__ import annotations

import numpy as np

from screwkit.common.fastmath import FASTMATH
from screwkit.common.jit import njit
from screwkit.indices.compiled.actuators import actuator_scratch, actuator_stage
from screwkit.indices.compiled.algebra import (
    BLOCK,
    CARRY_SIGNATURE,
    arm_square,
    cross,
    motion_lanes_of,
    power_coefficient,
)

__all__ = ["output_kernel"]

# The one signature: joint screws and points in any layout (as the first stage's), the rest C-contiguous.
_SIGNATURE = (
    "void(float64[:, :, :], float64[:, :, :], int64[::1], int64[::1], int64[::1], float64[:, :, ::1], "
    "int64[:, ::1], int64[:, ::1], int64[:, ::1], int64[:, ::1], int64[:, ::1], int64[::1], int64[:, ::1], "
    "int64[::1], float64, float64, float64, float64[:, :, ::1], float64[:, :, ::1], "
    "float64[:, ::1], float64[:, :, ::1], float64[:, ::1], float64[:, ::1], int64[:, ::1], boolean[:, ::1], "
    "float64[:, :, ::1], float64[:, :, :, ::1], "
    + CARRY_SIGNATURE + ")"
)


@njit(cache=True, error_model="numpy", fastmath=FASTMATH)
def output_arm_square(output_twist, locked, point_lanes, pitch_lanes, act, r):
    """The squared moment arm of actuator ``act``'s wrench on locked set ``locked``'s output twist, lane r."""
    return arm_square(output_twist[locked, 0, r], output_twist[locked, 1, r], output_twist[locked, 2, r],
                      output_twist[locked, 3, r], output_twist[locked, 4, r], output_twist[locked, 5, r],
                      point_lanes[act, 0, r], point_lanes[act, 1, r], point_lanes[act, 2, r], pitch_lanes[act, r])


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def identity_basis(basis):
    """Whether the motion basis is the identity (one basis, n = 6): a platform free in all six DoF, M^T y = y."""
    n = basis.shape[1]
    identity = basis.shape[0] == 1 and n == 6
    for q in range(n):
        for k in range(6):
            identity = identity and basis[0, q, k] == (1.0 if q == k else 0.0)
    return identity


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def submechanism_members(submechanisms, a):
    """member[s, act]: whether actuator ``act`` belongs to submechanism s."""
    member = np.zeros((submechanisms.shape[0], a), dtype=np.bool_)
    for s in range(submechanisms.shape[0]):
        for i in range(submechanisms.shape[1]):
            member[s, submechanisms[s, i]] = True
    return member


# --- Per set of n - 1 locked actuators: the output twist reciprocal to their wrenches (a column of adj(W) of
# every submechanism containing the set).

@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def exterior_products(locked_sets, locked_depth, wedge_table, wedge_start, wrench_matrix, n, width, wedge,
                      output):
    """Every locked set's cofactor vector for n >= 4, the exterior product of its rows: level K of ``wedge`` holds
    the K x K minors of the first K rows (one per K-column set, combination order), each from level K - 1 by
    expansion along row K. Lexicographic neighbours share their first rows, so only the levels past the first row
    that changed are recomputed."""
    for locked in range(locked_sets.shape[0]):
        for level in range(max(locked_depth[locked], 1) + 1, n):
            row = locked_sets[locked, level - 1]
            if level == 2:  # level 1's minors: the first row's entries
                for q in range(n):
                    for r in range(width):
                        wedge[1, q, r] = wrench_matrix[locked_sets[locked, 0], q, r]
            # Each minor's WEDGE_TERMS terms (padded with zero signs) summed in one pass over the lanes: one store
            # per minor, a loop the compiler vectorises.
            for target in range(wedge_start[level], wedge_start[level + 1]):
                u0, c0, s0 = wedge_table[target, 1], wedge_table[target, 2], float(wedge_table[target, 3])
                u1, c1, s1 = wedge_table[target, 4], wedge_table[target, 5], float(wedge_table[target, 6])
                u2, c2, s2 = wedge_table[target, 7], wedge_table[target, 8], float(wedge_table[target, 9])
                u3, c3, s3 = wedge_table[target, 10], wedge_table[target, 11], float(wedge_table[target, 12])
                u4, c4, s4 = wedge_table[target, 13], wedge_table[target, 14], float(wedge_table[target, 15])
                minor = wedge_table[target, 0]
                for r in range(width):
                    wedge[level, minor, r] = (s0 * wedge[level - 1, u0, r] * wrench_matrix[row, c0, r]
                                              + s1 * wedge[level - 1, u1, r] * wrench_matrix[row, c1, r]
                                              + s2 * wedge[level - 1, u2, r] * wrench_matrix[row, c2, r]
                                              + s3 * wedge[level - 1, u3, r] * wrench_matrix[row, c3, r]
                                              + s4 * wedge[level - 1, u4, r] * wrench_matrix[row, c4, r])
        for q in range(n):  # output[locked, q]: minor n - 1 - q of the last level, signed
            sign = 1.0 if (n - 1 + q) % 2 == 0 else -1.0
            for r in range(width):
                output[locked, q, r] = sign * wedge[n - 1, n - 1 - q, r]


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def locked_cofactors(locked_sets, locked_depth, wedge_table, wedge_start, wrench_matrix, n, width, wedge, output):
    """output[locked, q] = (-1)^(n-1+q) det(the locked rows of W without column q): the cofactor vector y of every
    locked set, in motion coordinates (no pivoting, no division)."""
    if n > 3:  # the exterior product of the locked rows
        exterior_products(locked_sets, locked_depth, wedge_table, wedge_start, wrench_matrix, n, width, wedge, output)
    for locked in range(locked_sets.shape[0] if n <= 3 else 0):
        if n == 3:  # the cross product of the two locked rows, written out
            i0 = locked_sets[locked, 0]
            i1 = locked_sets[locked, 1]
            for r in range(width):
                output[locked, 0, r], output[locked, 1, r], output[locked, 2, r] = cross(
                    wrench_matrix[i0, 0, r], wrench_matrix[i0, 1, r], wrench_matrix[i0, 2, r],
                    wrench_matrix[i1, 0, r], wrench_matrix[i1, 1, r], wrench_matrix[i1, 2, r])
        elif n == 1:  # no locked row: the one motion
            for r in range(width):
                output[locked, 0, r] = 1.0
        elif n == 2:  # one locked row (x, y): (-y, x)
            i0 = locked_sets[locked, 0]
            for r in range(width):
                output[locked, 0, r] = -wrench_matrix[i0, 1, r]
                output[locked, 1, r] = wrench_matrix[i0, 0, r]


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def locked_output_twists(output, motion_lanes, identity, width, output_twist, omega_squares):
    """The output twist M^T y of every locked set (working coordinates; ``output_twist`` is ``output`` itself when
    the basis is the identity), once per set: every submechanism holding the set uses it; and its |omega|^2."""
    for locked in range(output.shape[0]):
        if not identity:
            for k in range(6):
                for r in range(width):
                    output_twist[locked, k, r] = 0.0
            for q in range(motion_lanes.shape[0]):
                for k in range(6):
                    for r in range(width):
                        output_twist[locked, k, r] += motion_lanes[q, k, r] * output[locked, q, r]
        for r in range(width):
            w0, w1, w2 = output_twist[locked, 0, r], output_twist[locked, 1, r], output_twist[locked, 2, r]
            omega_squares[locked, r] = w0 * w0 + w1 * w1 + w2 * w2


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def locked_stage(locked_sets, locked_depth, wedge_table, wedge_start, wrench_matrix, motion_lanes, identity, width,
                 wedge, output, output_twist, omega_squares):
    """Every locked set's cofactor vector y (motion coordinates, ``output``), output twist M^T y (working
    coordinates) and its |omega|^2."""
    locked_cofactors(locked_sets, locked_depth, wedge_table, wedge_start, wrench_matrix, motion_lanes.shape[0], width,
                     wedge, output)
    locked_output_twists(output, motion_lanes, identity, width, output_twist, omega_squares)


# --- Per non-redundant submechanism: |A_k o T_k| = |det W| for each k (A3), its OTIs (Eqs. 8-9).

@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def submechanism_determinants(submechanisms, locked_of, wrench_matrix, output, row_norms, rank_tolerance, width,
                             determinant, volume, independent):
    """det W of every submechanism s (its first row against its first locked set's cofactors), and whether its wrenches
    are independent: |det W| above ``rank_tolerance`` times the product of its wrenches' norms (``row_norms``:
    :func:`~screwkit.indices.compiled.actuators.wrench_matrix_rows`), which bounds it (the motion basis is
    orthonormal), so that a wrench doing no work on the motion space makes its submechanisms dependent."""
    for s in range(submechanisms.shape[0]):
        n = submechanisms.shape[1]
        first = locked_of[s, 0]
        leader = submechanisms[s, 0]
        for r in range(width):
            volume[r] = 1.0
            determinant[s, r] = 0.0
        for i in range(n):
            act = submechanisms[s, i]
            for r in range(width):
                volume[r] *= row_norms[act, r]
        for q in range(n):
            for r in range(width):
                determinant[s, r] += wrench_matrix[leader, q, r] * output[first, q, r]
        for r in range(width):
            independent[s, r] = abs(determinant[s, r]) > rank_tolerance * volume[r]


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def longest_arm_squares(submechanisms, locked_of, output_twist, omega_squares, point_lanes, pitch_lanes, has_force,
                       thresholds, width, longest_sq):
    """The longest squared moment arm of each submechanism s's wrenches on their output twists, infinite where one is
    at or below its threshold (a zero OTI, as in :func:`~screwkit.indices.compiled.algebra.power_coefficient`)."""
    for s in range(submechanisms.shape[0]):
        for r in range(width):
            longest_sq[s, r] = 0.0
        for position in range(submechanisms.shape[1]):
            act = submechanisms[s, position]
            locked = locked_of[s, position]
            for r in range(width):
                # The OTI's moment arm: the output twist's velocity at the characteristic point plus h omega
                # (v + omega x p + h omega), or |omega| for a couple (both computed, one kept, so that the lanes stay
                # branch-free).
                forceful = has_force[act, r]
                omega_sq = omega_squares[locked, r]
                arm_sq = (output_arm_square(output_twist, locked, point_lanes, pitch_lanes, act, r) if forceful
                          else omega_sq)
                reference_sq = omega_sq if forceful else 0.0
                # one store per lane, so that the compiler vectorises the loop
                zero = arm_sq <= thresholds[r] * thresholds[r] * reference_sq or arm_sq <= 0.0
                longest_sq[s, r] = max(longest_sq[s, r], np.inf if zero else arm_sq)


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def actuator_otis(submechanisms, locked_of, output_twist, omega_squares, point_lanes, pitch_lanes, has_force,
                  thresholds, determinant, independent, first_index, width, oti_out):
    """OTI_k of every actuator k of every submechanism s (Eq. 8, |A_k o T_k| = |det W|) into ``oti_out``."""
    for s in range(submechanisms.shape[0]):
        for position in range(submechanisms.shape[1]):
            act = submechanisms[s, position]
            locked = locked_of[s, position]
            for r in range(width):
                omega = np.sqrt(omega_squares[locked, r])
                arm = (np.sqrt(output_arm_square(output_twist, locked, point_lanes, pitch_lanes, act, r))
                       if has_force[act, r] else omega)
                reference = omega if has_force[act, r] else 0.0
                oti_out[first_index + r, s, position] = (
                    power_coefficient(determinant[s, r], arm, reference, thresholds[r]) if independent[s, r] else 0.0)


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def world_output_twists(submechanisms, locked_of, wrench_matrix, output, output_twist, first_index, width, centres,
                        lengths, twist_out):
    """Submechanism s's output twists back in world units and origin (v_0 = L v' - omega x c) into ``twist_out``,
    each signed so that its actuator's wrench does positive work on it (A_k o T_k = W_k . y > 0: the motion of the
    platform when that actuator drives and the others hold, whatever the sign the motion basis was found with)."""
    for s in range(locked_of.shape[0]):
        for position in range(locked_of.shape[1]):
            locked = locked_of[s, position]
            act = submechanisms[s, position]
            for r in range(width):
                index = first_index + r
                power = 0.0
                for q in range(output.shape[1]):
                    power += wrench_matrix[act, q, r] * output[locked, q, r]
                sign = -1.0 if power < 0.0 else 1.0
                for k in range(6):
                    total = sign * output_twist[locked, k, r]
                    twist_out[index, s, position, k] = total if k < 3 else total * lengths[r]
                x0, x1, x2 = cross(twist_out[index, s, position, 0], twist_out[index, s, position, 1],
                                   twist_out[index, s, position, 2], centres[0, r], centres[1, r], centres[2, r])
                twist_out[index, s, position, 3] -= x0
                twist_out[index, s, position, 4] -= x1
                twist_out[index, s, position, 5] -= x2


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def submechanism_otis(determinant, independent, longest_sq, width, lmti_lanes):
    """The OTI of every submechanism s (Eq. 9), min_k |det W| / arm_k (each at most 1) = |det W| / max_k arm_k: one root
    and one division per submechanism; zero if any arm is at or below its threshold."""
    for s in range(independent.shape[0]):
        for r in range(width):
            value = (abs(determinant[s, r]) / np.sqrt(longest_sq[s, r])
                     if independent[s, r] and longest_sq[s, r] < np.inf else 0.0)
            lmti_lanes[s, r] = 1.0 if value > 1.0 else value


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def submechanism_stage(submechanisms, locked_of, wrench_matrix, output, row_norms, rank_tolerance, output_twist,
                       omega_squares, point_lanes, pitch_lanes, has_force, first_index, width, thresholds, centres,
                       lengths, determinant, volume, longest_sq, independent, lmti_lanes, oti_out, twist_out,
                       oti_sub_out):
    """Every non-redundant submechanism's det W and independence, its OTI (Eq. 9) into the first rows of
    ``lmti_lanes``; when their outputs have rows, its actuators' OTIs (Eq. 8), output twists (world) and OTI."""
    submechanism_determinants(submechanisms, locked_of, wrench_matrix, output, row_norms, rank_tolerance, width,
                              determinant, volume, independent)
    longest_arm_squares(submechanisms, locked_of, output_twist, omega_squares, point_lanes, pitch_lanes, has_force,
                        thresholds, width, longest_sq)
    if oti_out.shape[0] > 0:
        actuator_otis(submechanisms, locked_of, output_twist, omega_squares, point_lanes, pitch_lanes, has_force,
                      thresholds, determinant, independent, first_index, width, oti_out)
    if twist_out.shape[0] > 0:
        world_output_twists(submechanisms, locked_of, wrench_matrix, output, output_twist, first_index, width, centres,
                            lengths, twist_out)
    submechanism_otis(determinant, independent, longest_sq, width, lmti_lanes)
    if oti_sub_out.shape[0] > 0:
        for s in range(submechanisms.shape[0]):
            for r in range(width):
                oti_sub_out[first_index + r, s] = lmti_lanes[s, r]


# --- Reductions over actuator sets.

@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def iti_and_lmti(iti_lanes, lmti_lanes, subs, first_index, width, lowest, highest, summary_out, iti_out):
    """The ITI (Eq. 7, the lowest of the actuators') and the LMTI of all actuators (Eq. 11, the highest OTI of the
    submechanisms) into ``summary_out``; each actuator's ITI into ``iti_out``."""
    for r in range(width):
        lowest[r] = 1.0
        highest[r] = 0.0
    for act in range(iti_lanes.shape[0]):
        for r in range(width):
            lowest[r] = min(lowest[r], iti_lanes[act, r])
    for s in range(subs):
        for r in range(width):
            highest[r] = max(highest[r], lmti_lanes[s, r])
    for r in range(width):
        summary_out[first_index + r, 0] = lowest[r]
        summary_out[first_index + r, 1] = highest[r]
    if iti_out.shape[0] > 0:
        for r in range(width):
            for act in range(iti_lanes.shape[0]):
                iti_out[first_index + r, act] = iti_lanes[act, r]


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def set_lmtis(set_children, subs, width, set_lmti, lmti_lanes):
    """The LMTI of every set the reductions need: row t of ``set_children`` is a set whose LMTI is the max over
    earlier rows of ``lmti_lanes`` (submechanisms' OTIs, or sets one smaller); its value goes to row subs + t."""
    for row in range(set_children.shape[0]):
        for r in range(width):
            set_lmti[r] = -np.inf
        for t in range(set_children.shape[1]):
            child = set_children[row, t]
            if child < 0:
                break
            for r in range(width):
                set_lmti[r] = max(set_lmti[r], lmti_lanes[child, r])
        for r in range(width):
            lmti_lanes[subs + row, r] = set_lmti[r]


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def fault_indices(fault_rows, lmti_lanes, worst_fault_tie, first_index, width, fault_index, tie_limit, first_set,
                  summary_out, worst_out):
    """F_Oj (Eqs. 12-13): the worst, over the sets E left after j faults (rows fault_rows[f] of ``lmti_lanes``),
    of LMTI_E; and the worst set, the first in combination order whose LMTI is within ``worst_fault_tie`` of F_Oj
    (numpy's argmin, robust to rounding between equal LMTIs)."""
    for f in range(fault_rows.shape[0]):
        first_row, last_row = fault_rows[f, 0], fault_rows[f, 1]
        for r in range(width):
            fault_index[r] = np.inf
        for e in range(first_row, last_row):
            for r in range(width):
                fault_index[r] = min(fault_index[r], lmti_lanes[e, r])
        for r in range(width):
            tie_limit[r] = fault_index[r] + worst_fault_tie
            first_set[r] = -1
        for e in range(first_row, last_row):
            for r in range(width):
                if first_set[r] < 0 and lmti_lanes[e, r] <= tie_limit[r]:
                    first_set[r] = e - first_row
        for r in range(width):
            summary_out[first_index + r, 2 + f] = fault_index[r]
            worst_out[first_index + r, f] = max(first_set[r], 0)


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def mutual_interference(member, independent, first_index, width, mutual, mutual_out):
    """Whether each actuator is a mutual-interference actuator: some submechanism without it is non-singular (the
    other actuators alone fully constrain the platform)."""
    for act in range(member.shape[1]):
        for r in range(width):
            mutual[r] = False
        for s in range(member.shape[0]):
            if not member[s, act]:
                for r in range(width):
                    mutual[r] = mutual[r] or independent[s, r]
        for r in range(width):
            mutual_out[first_index + r, act] = mutual[r]


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def reduction_stage(iti_lanes, lmti_lanes, subs, set_children, fault_rows, member, independent, worst_fault_tie,
                    first_index, width, reduction_lanes, first_set, mutual, summary_out, iti_out, worst_out,
                    mutual_out):
    """The ITI and LMTI of all actuators (Eqs. 7, 11), the LMTI of every set the reductions need, F_Oj with the
    worst set (Eqs. 12-13) and the mutual-interference actuators; ``reduction_lanes`` (5, BLOCK) is scratch."""
    iti_and_lmti(iti_lanes, lmti_lanes, subs, first_index, width, reduction_lanes[0], reduction_lanes[1],
                 summary_out, iti_out)
    set_lmtis(set_children, subs, width, reduction_lanes[2], lmti_lanes)
    fault_indices(fault_rows, lmti_lanes, worst_fault_tie, first_index, width, reduction_lanes[3], reduction_lanes[4],
                  first_set, summary_out, worst_out)
    mutual_interference(member, independent, first_index, width, mutual, mutual_out)


@njit(_SIGNATURE, nogil=True, cache=True, error_model="numpy", fastmath=FASTMATH)
def output_kernel(all_twists, all_points, chain_start, actuator_chain, actuator_joint, basis, submechanisms,
                  locked_sets, locked_of, set_children, fault_rows, locked_depth, wedge_table, wedge_start,
                  rank_tolerance, pure_couple, worst_fault_tie, iti_override, oti_override,
                  iti_out, oti_out, oti_sub_out, summary_out, worst_out, mutual_out, wrench_out, twist_out,
                  force_rows, passive_row_rows, threshold_rows, length_rows, centre_rows):
    """ITIs, output twists, OTIs and the reductions over actuator sets of a chunk of configurations.

    Parameters (N configurations, a actuators, n DOF, S submechanisms)
    ----------
    all_twists, all_points, chain_start, actuator_chain, actuator_joint, basis : as for
        :func:`screwkit.indices.compiled.wrenches.wrench_kernel`.
    submechanisms (S, n) : actuator indices of each non-redundant submechanism.
    locked_sets (L, n - 1) : every set of n - 1 actuators (locked while one other drives).
    locked_of (S, n) : for each submechanism and position k, the row of locked_sets holding
        the other n - 1 actuators of the submechanism.
    set_children (R, K), fault_rows (F, 2) : the actuator sets whose LMTI the reductions need
        (see :func:`screwkit.indices.sets.reductions`): row t of ``set_children`` lists rows of
        the OTIs and sets before it (OTIs of submechanisms first, then the sets in order, padded
        with -1) whose maximum is the LMTI of set t; ``fault_rows[f]`` is the range of those rows
        (OTIs included) holding the sets left after the f-th value of j, in combination order.
    locked_depth (L,), wedge_table (T, 1 + 3 WEDGE_TERMS), wedge_start (n + 1,) : for n >= 4, the output twists'
        exterior products (see :func:`screwkit.indices.sets.wedge_tables`): the first position at
        which each locked set differs from the one before, and one row per minor of level K in rows
        wedge_start[K]:wedge_start[K+1] (the minor, then source minor, column and sign of each of its
        WEDGE_TERMS expansion terms, padded with zero signs).
    rank_tolerance, pure_couple, worst_fault_tie : the dimensionless tolerances RANK_TOLERANCE,
        PURE_COUPLE and WORST_FAULT_TIE of :mod:`screwkit.common.tolerances`, in working coordinates.
    iti_override, oti_override (N or 0, a, 3) : characteristic points given by the caller (world).
    Outputs: iti_out (N or 0, a) (Eq. 6), oti_out (N or 0, S, n), oti_sub_out (N or 0, S) (Eq. 9);
        summary_out (N, 2 + F) holding the ITI (Eq. 7), the LMTI of all actuators (Eq. 11) and
        F_Oj for each of the F values of j (Eqs. 12-13); worst_out (N, F) the worst set: the
        first set, in combination order, whose LMTI is at most F_Oj + worst_fault_tie (numpy's
        argmin, made robust to rounding between sets of mathematically equal LMTI);
        mutual_out (N, a) bool, whether each actuator is a mutual-interference actuator (some n
        others have independent wrenches); wrench_out (N or 0, a, 6) (world frame and unit: unit
        force, or unit moment for a pure couple), twist_out (N or 0, S, n, 6) (output twists, world frame
        and unit, scaled as the adjugate columns in working coordinates, so that
        |A'_k o T'_k| = |det W|). The per-block inputs are the earlier stages'
        (:func:`screwkit.indices.compiled.algebra.carry_arrays`; the passive rows are not used here).
    """
    count, a, n = summary_out.shape[0], force_rows.shape[1], basis.shape[1]
    subs, locked_count = submechanisms.shape[0], locked_sets.shape[0]
    # Scratch, allocated once per call, with a last "lane" axis over the configurations of a block.
    motion_lanes, inverse_lengths = np.empty((n, 6, BLOCK)), np.empty(BLOCK)
    joint_lanes, wrench_lanes, point_lanes, pitch_lanes, has_force, iti_lanes, wrench_matrix, row_norms = (
        actuator_scratch(a, n))
    output = np.empty((locked_count, n, BLOCK))  # each locked set's cofactor vector y (motion coordinates)
    wedge = np.zeros((max(n, 1), 20, BLOCK))  # minors of the first K locked rows, at most C(6, 3) = 20 per level
    identity = identity_basis(basis)
    output_twist = output if identity else np.empty((locked_count, 6, BLOCK))  # M^T y (working coordinates)
    omega_squares = np.empty((locked_count, BLOCK))  # |omega|^2 of each output twist
    lmti_lanes = np.empty((subs + set_children.shape[0], BLOCK))  # OTIs of the submechanisms, LMTIs of the sets
    independent = np.empty((subs, BLOCK), dtype=np.bool_)  # whether each submechanism's wrenches are independent
    determinant, volume, longest_sq = np.empty((subs, BLOCK)), np.empty(BLOCK), np.empty((subs, BLOCK))
    reduction_lanes, member = np.empty((5, BLOCK)), submechanism_members(submechanisms, a)
    first_set, mutual = np.empty(BLOCK, dtype=np.int64), np.empty(BLOCK, dtype=np.bool_)
    for block in range((count + BLOCK - 1) // BLOCK):
        first_index = block * BLOCK
        width = min(count, first_index + BLOCK) - first_index
        thresholds, lengths, centres = threshold_rows[block], length_rows[block], centre_rows[block]
        for r in range(width):
            inverse_lengths[r] = 1.0 / lengths[r]
        motion_lanes_of(basis, first_index, width, motion_lanes)
        actuator_stage(all_twists, all_points, chain_start, actuator_chain, actuator_joint, force_rows[block],
                       pure_couple * pure_couple, iti_override, oti_override, motion_lanes, first_index, width,
                       centres, lengths, inverse_lengths, thresholds, joint_lanes, wrench_lanes, point_lanes,
                       pitch_lanes, has_force, iti_lanes, wrench_matrix, row_norms, wrench_out)
        locked_stage(locked_sets, locked_depth, wedge_table, wedge_start, wrench_matrix, motion_lanes, identity, width,
                     wedge, output, output_twist, omega_squares)
        submechanism_stage(submechanisms, locked_of, wrench_matrix, output, row_norms, rank_tolerance, output_twist,
                           omega_squares, point_lanes, pitch_lanes, has_force, first_index, width, thresholds,
                           centres, lengths, determinant, volume, longest_sq, independent, lmti_lanes, oti_out,
                           twist_out, oti_sub_out)
        reduction_stage(iti_lanes, lmti_lanes, subs, set_children, fault_rows, member, independent, worst_fault_tie,
                        first_index, width, reduction_lanes, first_set, mutual, summary_out, iti_out, worst_out,
                        mutual_out)
