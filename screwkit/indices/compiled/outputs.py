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
and the mutual-interference actuators. Its own module, so that it compiles apart from
:mod:`screwkit.indices.compiled.wrenches` (in parallel on a first run, :mod:`screwkit.common.compiling`).

Loops over the configurations of a block (lanes) write one array each where they are hot: the
compiler vectorises a loop only when it can rule out, with few runtime checks, that what it
writes overlaps what it reads.
"""

from __future__ import annotations

import numpy as np

from screwkit.common.fastmath import FASTMATH
from screwkit.common.jit import njit
from screwkit.indices.compiled.algebra import (
    BLOCK,
    CARRY_SIGNATURE,
    arm_square,
    cross,
    motion_lanes_of,
    power_coefficient,
    working_point,
    working_twist,
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
    count = summary_out.shape[0]
    a = force_rows.shape[1]
    n = basis.shape[1]
    subs = submechanisms.shape[0]
    blocks = (count + BLOCK - 1) // BLOCK
    wrench_lanes = np.empty((a, 6, BLOCK))
    motion_lanes = np.empty((n, 6, BLOCK))
    joint_lanes = np.empty((12, BLOCK))  # an actuator's joint twist, the point after it and d
    point_lanes = np.empty((a, 3, BLOCK))  # each actuator's OTI characteristic point
    pitch_lanes = np.empty((a, BLOCK))  # and its wrench's pitch (0 for a couple)
    inverse_lengths = np.empty(BLOCK)
    iti_local = np.zeros((a, BLOCK))
    has_force = np.zeros((a, BLOCK), dtype=np.bool_)
    wrench_matrix = np.zeros((a, n, BLOCK))
    row_norms = np.zeros((a, BLOCK))
    pure_couple_sq = pure_couple * pure_couple
    output = np.empty((locked_sets.shape[0], n, BLOCK))
    wedge = np.zeros((max(n, 1), 20, BLOCK))  # minors of the first K locked rows, at most C(6, 3) = 20 per level
    omega_squares = np.empty((locked_sets.shape[0], BLOCK))  # |omega|^2 of each output twist
    oti_local = np.empty((subs + set_children.shape[0], BLOCK))  # OTIs, then the LMTIs of the sets
    independent = np.empty((subs, BLOCK), dtype=np.bool_)
    determinant = np.empty(BLOCK)
    volume = np.empty(BLOCK)
    lane0 = np.empty(BLOCK)
    lane1 = np.empty(BLOCK)
    lane2 = np.empty(BLOCK)
    best = np.empty(BLOCK)
    mutual = np.empty(BLOCK, dtype=np.bool_)
    first_set = np.empty(BLOCK, dtype=np.int64)
    identity = basis.shape[0] == 1 and n == 6  # a platform free in all six DoF: M^T y = y
    for q in range(n):
        for k in range(6):
            identity = identity and basis[0, q, k] == (1.0 if q == k else 0.0)
    # M^T y of each locked set (working coordinates): y itself when the basis is the identity
    output_twist = output if identity else np.empty((locked_sets.shape[0], 6, BLOCK))
    member = np.zeros((subs, a), dtype=np.bool_)
    for s in range(subs):
        for i in range(n):
            member[s, submechanisms[s, i]] = True
    for block in range(blocks):
        first_index = block * BLOCK
        last_index = min(count, first_index + BLOCK)
        width = last_index - first_index
        forces = force_rows[block]
        thresholds = threshold_rows[block]
        lengths = length_rows[block]
        centres = centre_rows[block]
        for r in range(width):
            inverse_lengths[r] = 1.0 / lengths[r]
        motion_lanes_of(basis, first_index, width, motion_lanes)
        for act in range(a):
            # The actuated joint's twist, the point of the joint after it and the platform joint d,
            # in working coordinates (as the first stage computed them).
            start = chain_start[actuator_chain[act]]
            own = start + actuator_joint[act]
            last = chain_start[actuator_chain[act] + 1] - 1
            after = own + 1 if own < last else own
            for r in range(width):
                c0, c1, c2, inverse = centres[0, r], centres[1, r], centres[2, r], inverse_lengths[r]
                (joint_lanes[0, r], joint_lanes[1, r], joint_lanes[2, r], joint_lanes[3, r], joint_lanes[4, r],
                 joint_lanes[5, r]) = working_twist(all_twists, first_index + r, own, c0, c1, c2, inverse)
                joint_lanes[6, r], joint_lanes[7, r], joint_lanes[8, r] = working_point(
                    all_points, first_index + r, after, c0, c1, c2, inverse)
                joint_lanes[9, r], joint_lanes[10, r], joint_lanes[11, r] = working_point(
                    all_points, first_index + r, last, c0, c1, c2, inverse)
            # --- unit wrench about the centroid, its ITI (Eq. 6) and its OTI characteristic point.
            for r in range(width):
                d0, d1, d2 = joint_lanes[9, r], joint_lanes[10, r], joint_lanes[11, r]
                f0, f1, f2 = forces[act, 0, r], forces[act, 1, r], forces[act, 2, r]
                x0, x1, x2 = cross(d0, d1, d2, f0, f1, f2)  # m_c = m_d + d x f
                m0 = forces[act, 3, r] + x0
                m1 = forces[act, 4, r] + x1
                m2 = forces[act, 5, r] + x2
                force_sq = f0 * f0 + f1 * f1 + f2 * f2
                moment_sq = m0 * m0 + m1 * m1 + m2 * m2
                # A pure couple: |f| <= PURE_COUPLE |m_c| / L (working coordinates, moment about c).
                forceful = force_sq > pure_couple_sq * moment_sq and force_sq > 0.0
                scale = np.sqrt(force_sq) if forceful else np.sqrt(moment_sq)
                work_done = (f0 * joint_lanes[3, r] + f1 * joint_lanes[4, r] + f2 * joint_lanes[5, r]
                             + m0 * joint_lanes[0, r] + m1 * joint_lanes[1, r] + m2 * joint_lanes[2, r])
                factor = ((-1.0 if work_done < 0.0 else 1.0) / scale) if scale > 0.0 else 0.0
                f0 *= factor
                f1 *= factor
                f2 *= factor
                m0 *= factor
                m1 *= factor
                m2 *= factor
                wrench_lanes[act, 0, r] = f0
                wrench_lanes[act, 1, r] = f1
                wrench_lanes[act, 2, r] = f2
                wrench_lanes[act, 3, r] = m0
                wrench_lanes[act, 4, r] = m1
                wrench_lanes[act, 5, r] = m2
                forceful = forceful and scale > 0.0
                has_force[act, r] = forceful
                pitch = f0 * m0 + f1 * m1 + f2 * m2 if forceful else 0.0
                pitch_lanes[act, r] = pitch
                # Characteristic points: projections on the wrench axis (unit force).
                axis0, axis1, axis2 = cross(f0, f1, f2, m0, m1, m2)
                if iti_override.shape[0] > 0:
                    p0 = (iti_override[first_index + r, act, 0] - centres[0, r]) * inverse_lengths[r]
                    p1 = (iti_override[first_index + r, act, 1] - centres[1, r]) * inverse_lengths[r]
                    p2 = (iti_override[first_index + r, act, 2] - centres[2, r]) * inverse_lengths[r]
                else:
                    p0, p1, p2 = joint_lanes[6, r], joint_lanes[7, r], joint_lanes[8, r]
                    if forceful:
                        along = (p0 - axis0) * f0 + (p1 - axis1) * f1 + (p2 - axis2) * f2
                        p0 = axis0 + along * f0
                        p1 = axis1 + along * f1
                        p2 = axis2 + along * f2
                # ITI (Eq. 6): power coefficient on the actuated joint's own twist.
                w0, w1, w2 = joint_lanes[0, r], joint_lanes[1, r], joint_lanes[2, r]
                omega = np.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
                arm = np.sqrt(arm_square(w0, w1, w2, joint_lanes[3, r], joint_lanes[4, r], joint_lanes[5, r],
                                         p0, p1, p2, pitch)) if forceful else omega
                reference = omega if forceful else 0.0
                iti_local[act, r] = power_coefficient(work_done * factor, arm, reference, thresholds[r])
                if oti_override.shape[0] > 0:
                    p0 = (oti_override[first_index + r, act, 0] - centres[0, r]) * inverse_lengths[r]
                    p1 = (oti_override[first_index + r, act, 1] - centres[1, r]) * inverse_lengths[r]
                    p2 = (oti_override[first_index + r, act, 2] - centres[2, r]) * inverse_lengths[r]
                else:
                    p0, p1, p2 = d0, d1, d2
                    if forceful:
                        along = (p0 - axis0) * f0 + (p1 - axis1) * f1 + (p2 - axis2) * f2
                        p0 = axis0 + along * f0
                        p1 = axis1 + along * f1
                        p2 = axis2 + along * f2
                point_lanes[act, 0, r] = p0
                point_lanes[act, 1, r] = p1
                point_lanes[act, 2, r] = p2
            # The row of the wrench matrix in motion coordinates, A_k o M_q.
            for r in range(width):
                row_norms[act, r] = 0.0
            for q in range(n):
                for r in range(width):
                    value = (wrench_lanes[act, 0, r] * motion_lanes[q, 3, r]
                             + wrench_lanes[act, 1, r] * motion_lanes[q, 4, r]
                             + wrench_lanes[act, 2, r] * motion_lanes[q, 5, r]
                             + wrench_lanes[act, 3, r] * motion_lanes[q, 0, r]
                             + wrench_lanes[act, 4, r] * motion_lanes[q, 1, r]
                             + wrench_lanes[act, 5, r] * motion_lanes[q, 2, r])
                    wrench_matrix[act, q, r] = value
                    row_norms[act, r] += value * value
            for r in range(width):
                row_norms[act, r] = np.sqrt(row_norms[act, r])
            if wrench_out.shape[0] > 0:  # back to world units and origin: m_0 = L m' + c x f
                for r in range(width):
                    f0, f1, f2 = wrench_lanes[act, 0, r], wrench_lanes[act, 1, r], wrench_lanes[act, 2, r]
                    x0, x1, x2 = cross(centres[0, r], centres[1, r], centres[2, r], f0, f1, f2)
                    length = lengths[r]
                    unit = 1.0 if has_force[act, r] else inverse_lengths[r]  # a couple: unit moment in world units
                    wrench_out[first_index + r, act, 0] = f0 * unit
                    wrench_out[first_index + r, act, 1] = f1 * unit
                    wrench_out[first_index + r, act, 2] = f2 * unit
                    wrench_out[first_index + r, act, 3] = (wrench_lanes[act, 3, r] * length + x0) * unit
                    wrench_out[first_index + r, act, 4] = (wrench_lanes[act, 4, r] * length + x1) * unit
                    wrench_out[first_index + r, act, 5] = (wrench_lanes[act, 5, r] * length + x2) * unit
        # --- output twists: for each set of n - 1 locked actuators, the twist reciprocal to
        # their wrenches (a column of adj(W) of every submechanism containing the set).
        for locked in range(locked_sets.shape[0]):
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
            else:
                # The cofactor vector as the exterior product of the locked rows: level K holds the
                # K x K minors of the first K rows (one per K-column set, combination order), each
                # from level K - 1 by expansion along row K; lexicographic neighbours share their
                # first rows, so only the levels past the first changed row are recomputed.
                for level in range(max(locked_depth[locked], 1) + 1, n):
                    row = locked_sets[locked, level - 1]
                    if level == 2:  # level 1's minors: the first row's entries
                        for q in range(n):
                            for r in range(width):
                                wedge[1, q, r] = wrench_matrix[locked_sets[locked, 0], q, r]
                    # Each minor's WEDGE_TERMS terms (padded with zero signs) summed in one pass over
                    # the lanes: one store per minor, a loop the compiler vectorises.
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
                # out[q] = (-1)^(n-1+q) det(rows without column q): minor n - 1 - q of the last level
                for q in range(n):
                    sign = 1.0 if (n - 1 + q) % 2 == 0 else -1.0
                    for r in range(width):
                        output[locked, q, r] = sign * wedge[n - 1, n - 1 - q, r]
            # The output twist M^T y, once per locked set: every submechanism holding the set uses it.
            if not identity:
                for k in range(6):
                    for r in range(width):
                        output_twist[locked, k, r] = 0.0
                for q in range(n):
                    for k in range(6):
                        for r in range(width):
                            output_twist[locked, k, r] += motion_lanes[q, k, r] * output[locked, q, r]
            for r in range(width):
                w0, w1, w2 = output_twist[locked, 0, r], output_twist[locked, 1, r], output_twist[locked, 2, r]
                omega_squares[locked, r] = w0 * w0 + w1 * w1 + w2 * w2
        # --- every non-redundant submechanism once: |A_k o T_k| = |det W| for each k (A3).
        for s in range(subs):
            first = locked_of[s, 0]
            leader = submechanisms[s, 0]
            for r in range(width):
                volume[r] = 1.0
                determinant[r] = 0.0
                best[r] = 0.0  # the longest moment arm, squared
            for i in range(n):
                act = submechanisms[s, i]
                for r in range(width):
                    volume[r] *= row_norms[act, r]
            for q in range(n):
                for r in range(width):
                    determinant[r] += wrench_matrix[leader, q, r] * output[first, q, r]
            for r in range(width):
                independent[s, r] = abs(determinant[r]) > rank_tolerance * volume[r]
            for position in range(n):
                act = submechanisms[s, position]
                locked = locked_of[s, position]
                for r in range(width):
                    # The OTI's moment arm: the output twist's velocity at the characteristic point
                    # plus h omega (v + omega x p + h omega), or |omega| for a couple (both computed,
                    # one kept, so that the lanes stay branch-free).
                    forceful = has_force[act, r]
                    omega_sq = omega_squares[locked, r]
                    arm_sq = (output_arm_square(output_twist, locked, point_lanes, pitch_lanes, act, r) if forceful
                              else omega_sq)
                    reference_sq = omega_sq if forceful else 0.0
                    # power_coefficient's zero (the arm at or below p |omega|, or zero) as an infinite
                    # arm; one store per lane, so that the compiler vectorises the loop
                    zero = arm_sq <= thresholds[r] * thresholds[r] * reference_sq or arm_sq <= 0.0
                    best[r] = max(best[r], np.inf if zero else arm_sq)
                if oti_out.shape[0] > 0:
                    for r in range(width):
                        omega = np.sqrt(omega_squares[locked, r])
                        arm = (np.sqrt(output_arm_square(output_twist, locked, point_lanes, pitch_lanes, act, r))
                               if has_force[act, r] else omega)
                        reference = omega if has_force[act, r] else 0.0
                        oti_out[first_index + r, s, position] = (
                            power_coefficient(determinant[r], arm, reference, thresholds[r])
                            if independent[s, r] else 0.0)
                if twist_out.shape[0] > 0:
                    for r in range(width):
                        index = first_index + r
                        for k in range(6):
                            total = output_twist[locked, k, r]
                            twist_out[index, s, position, k] = total if k < 3 else total * lengths[r]
                        # back to world units and origin: v_0 = L v' - omega x c
                        x0, x1, x2 = cross(twist_out[index, s, position, 0], twist_out[index, s, position, 1],
                                            twist_out[index, s, position, 2], centres[0, r], centres[1, r],
                                            centres[2, r])
                        twist_out[index, s, position, 3] -= x0
                        twist_out[index, s, position, 4] -= x1
                        twist_out[index, s, position, 5] -= x2
            # The OTI (Eq. 9), min_k |det W| / arm_k (each at most 1) = |det W| / max_k arm_k: one
            # root and one division per submechanism; zero if any arm is at or below its threshold.
            for r in range(width):
                value = abs(determinant[r]) / np.sqrt(best[r]) if independent[s, r] and best[r] < np.inf else 0.0
                best[r] = 1.0 if value > 1.0 else value
                oti_local[s, r] = best[r]
            if oti_sub_out.shape[0] > 0:
                for r in range(width):
                    oti_sub_out[first_index + r, s] = best[r]
        # --- ITI (Eq. 7) and LMTI of all actuators (Eq. 11).
        for r in range(width):
            lane0[r] = 1.0
            lane1[r] = 0.0
        for act in range(a):
            for r in range(width):
                lane0[r] = min(lane0[r], iti_local[act, r])
        for s in range(subs):
            for r in range(width):
                lane1[r] = max(lane1[r], oti_local[s, r])
        for r in range(width):
            summary_out[first_index + r, 0] = lane0[r]
            summary_out[first_index + r, 1] = lane1[r]
        if iti_out.shape[0] > 0:
            for r in range(width):
                for act in range(a):
                    iti_out[first_index + r, act] = iti_local[act, r]
        # --- F_Oj: the worst, over the sets E left after j faults, of LMTI_E = max OTI_N, N in E.
        # The worst set reported is the first, in combination order, whose LMTI is within
        # worst_fault_tie of F_Oj: numpy's argmin, robust to rounding between equal LMTIs.
        # Each row of set_children is a set whose LMTI is the max over earlier rows (submechanisms'
        # OTIs, or sets one smaller); its value goes after the OTIs.
        for row in range(set_children.shape[0]):
            for r in range(width):
                lane2[r] = -np.inf
            for t in range(set_children.shape[1]):
                child = set_children[row, t]
                if child < 0:
                    break
                for r in range(width):
                    lane2[r] = max(lane2[r], oti_local[child, r])
            for r in range(width):
                oti_local[subs + row, r] = lane2[r]
        for f in range(fault_rows.shape[0]):
            first_row, last_row = fault_rows[f, 0], fault_rows[f, 1]
            for r in range(width):
                best[r] = np.inf
            for e in range(first_row, last_row):
                for r in range(width):
                    best[r] = min(best[r], oti_local[e, r])
            for r in range(width):
                lane2[r] = best[r] + worst_fault_tie
                first_set[r] = -1
            for e in range(first_row, last_row):
                for r in range(width):
                    if first_set[r] < 0 and oti_local[e, r] <= lane2[r]:
                        first_set[r] = e - first_row
            for r in range(width):
                summary_out[first_index + r, 2 + f] = best[r]
                worst_out[first_index + r, f] = max(first_set[r], 0)
        # --- mutual interference: the other actuators alone fully constrain the platform.
        for act in range(a):
            for r in range(width):
                mutual[r] = False
            for s in range(subs):
                if not member[s, act]:
                    for r in range(width):
                        mutual[r] = mutual[r] or independent[s, r]
            for r in range(width):
                mutual_out[first_index + r, act] = mutual[r]
