"""Compiled kernel of :func:`screwkit.transmission.analyze`.

One numba function takes a chunk of configurations, 64 at a time, and for each derives the
actuation wrenches, the ITIs, and the output twists and OTIs of every non-redundant
submechanism, then the LMTI, F_Oj and the mutual-interference actuators, exactly as
documented in :func:`screwkit.transmission.analyze`. Every per-configuration quantity has a
last "lane" axis over the 64 configurations and every step loops over the lanes innermost,
so that the compiler vectorises the algebra across configurations. The output twists (cofactor
vectors of n - 1 locked wrenches) are exterior products of the locked rows, level by level, each
locked set starting from the minors it shares with the set before it (no pivoting, no division);
the actuation wrenches' null vectors are eliminated lane-innermost, pivot choices and row swaps as
per-lane blends (:func:`_null_vectors_lanes`); only the lanes whose leading block is poorly
conditioned, and the Gram solves of chains with more joint DoFs than n, run lane by lane. The
small dense algebra (null vectors, Gram solves over one chain's joints) is written out here, and
scratch is allocated once per call (the pseudo-inverse fallback for idle DoFs excepted).

Screws are ordered (omega, v) for twists and (f, m) for wrenches. Inside the kernel every
configuration is in its own *working coordinates*: about the centroid ``c`` of the platform
joints, with lengths in units of ``L``, the RMS distance of all the configuration's joint points
from ``c`` (a twist (omega, v) becomes (omega, v_c / L), a point p becomes (p - c) / L, a wrench
(f, m) becomes (f, m_c / L)). Every tolerance is then compared with dimensionless numbers, so
that no decision depends on the length unit, the scale of the mechanism or the world frame; the
singularity threshold *p*, a length, is compared as p / L. ``c`` and ``L`` are computed per
configuration, exactly as :func:`screwkit.motion.working_coordinates` does for the
motion-space bases it passes in; outputs go back to world units and frame. The tolerances come
in as arguments (named in :mod:`screwkit.tolerances`): numba's disk cache would not notice a
changed constant of another module.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from screwkit._fastmath import FASTMATH

BLOCK = 64  # configurations gathered batch-first at a time

# The one signature of transmission_kernel. Joint screws and points come in any memory layout
# ("A": the loader's component-major blocks, hand-built batch-first arrays, slices of either),
# so a single compiled version serves every mechanism and is loaded from numba's disk cache
# when this module is imported; every other argument is C-contiguous (analyze() sees to it).
_SIGNATURE = (
    "void(float64[:, :, :], float64[:, :, :], int64[::1], int64[::1], int64[::1], float64[:, :, ::1], "
    "float64[:, ::1], int64[:, ::1], int64[:, ::1], int64[:, ::1], int64[:, ::1], int64[:, ::1], "
    "int64[::1], int64[:, ::1], int64[::1], float64, float64, "
    "float64, float64, float64, float64, float64, "
    "float64[:, :, ::1], float64[:, :, ::1], float64[:, ::1], float64[:, :, ::1], float64[:, ::1], float64[:, ::1], "
    "int64[:, ::1], boolean[:, ::1], float64[:, :, ::1], float64[:, :, :, ::1], boolean[::1])"
)


@njit(cache=True, error_model="numpy", fastmath=FASTMATH)
def _cross(a0, a1, a2, b0, b1, b2):
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def _null_vector(rows, size, out, work, columns):
    """out[:size] = generalised cross product of the size - 1 rows rows[:size-1, :size].

    ``out[q] = (-1)^(size-1+q) det(rows without column q)``: orthogonal to every row, zero
    exactly when the rows are dependent; for the rows of ``W`` other than row ``k`` it is
    (up to sign) column ``k`` of ``adj(W)``. Computed with one Gaussian elimination with full
    pivoting, ``rows Q = P L U``: the cofactor vector of the upper-trapezoidal ``U`` is
    ``prod(diag U)`` times its null vector with last entry 1, and permutations only change its
    sign and order. ``work`` (float, at least (size - 1, size)) and ``columns`` (int, size) are
    scratch.
    """
    if size == 1:
        out[0] = 1.0
        return
    if size == 3:
        out[0], out[1], out[2] = _cross(rows[0, 0], rows[0, 1], rows[0, 2], rows[1, 0], rows[1, 1], rows[1, 2])
        return
    m = size - 1
    for i in range(m):
        for j in range(size):
            work[i, j] = rows[i, j]
    for j in range(size):
        columns[j] = j
    sign = 1.0
    for col in range(m):
        best = 0.0
        pivot_row = col
        pivot_column = col
        for i in range(col, m):
            for j in range(col, size):
                if abs(work[i, j]) > best:
                    best = abs(work[i, j])
                    pivot_row = i
                    pivot_column = j
        if best == 0.0:  # rank below size - 1: every cofactor vanishes
            for j in range(size):
                out[j] = 0.0
            return
        if pivot_row != col:
            for j in range(size):
                tmp = work[col, j]
                work[col, j] = work[pivot_row, j]
                work[pivot_row, j] = tmp
            sign = -sign
        if pivot_column != col:
            for i in range(m):
                tmp = work[i, col]
                work[i, col] = work[i, pivot_column]
                work[i, pivot_column] = tmp
            swap = columns[col]
            columns[col] = columns[pivot_column]
            columns[pivot_column] = swap
            sign = -sign
        for i in range(col + 1, m):
            factor = work[i, col] / work[col, col]
            for j in range(col + 1, size):
                work[i, j] -= factor * work[col, j]
    # Null vector of U with last entry 1 (back substitution), scaled by prod(diag U) and the sign.
    scale = sign
    for i in range(m):
        scale *= work[i, i]
    out[columns[m]] = scale
    for i in range(m - 1, -1, -1):
        total = work[i, m] * out[columns[m]]
        for j in range(i + 1, m):
            total += work[i, j] * out[columns[j]]
        out[columns[i]] = -total / work[i, i]
    return


LEADING_PIVOT_RATIO = 1e-2
"""Lanes whose leading block's smallest pivot is below this fraction of its largest (a poorly
conditioned block) get their null vector from :func:`_null_vector`'s full pivoting instead."""


@njit(cache=True, error_model="numpy", fastmath=FASTMATH)
def _null_vectors_lanes(rows, size, width, out, work, pivot, determinant, scratch, smallest, largest,
                        scalar_rows, scalar_work, scalar_columns, scalar_out):
    """out[:size, r] = generalised cross product of the rows rows[:size-1, :size, r], every lane r at once.

    The vector of :func:`_null_vector` (``out[q] = (-1)^(size-1+q) det(rows without column q)``),
    computed lane-innermost so that the compiler vectorises it across configurations: Gaussian
    elimination with partial pivoting of the leading (size-1) x (size-1) block, the last column
    carried along (pivot choices and row swaps as per-lane blends); then ``out`` is
    ``det(leading block)`` times the null vector whose last entry is 1, by back substitution.
    Lanes whose leading block is poorly conditioned (smallest pivot below
    :data:`LEADING_PIVOT_RATIO` of the largest) are redone one by one with :func:`_null_vector`.
    ``work`` (size-1, size, BLOCK), ``pivot``, ``determinant``, ``scratch``, ``smallest``,
    ``largest`` (BLOCK) and the ``scalar_*`` arrays are scratch.
    """
    m = size - 1
    for i in range(m):
        for j in range(size):
            for r in range(width):
                work[i, j, r] = rows[i, j, r]
    for r in range(width):
        determinant[r] = 1.0
        smallest[r] = np.inf
        largest[r] = 0.0
    for k in range(m):
        for r in range(width):
            pivot[r] = float(k)
            scratch[r] = abs(work[k, k, r])
        for i in range(k + 1, m):
            row = float(i)
            for r in range(width):
                value = abs(work[i, k, r])
                better = value > scratch[r]
                scratch[r] = value if better else scratch[r]
                pivot[r] = row if better else pivot[r]
        for i in range(k + 1, m):
            row = float(i)
            for r in range(width):
                scratch[r] = 1.0 if pivot[r] == row else 0.0
                determinant[r] *= 1.0 - 2.0 * scratch[r]
            for j in range(k, size):
                for r in range(width):  # exact blends (a weight of 0 or 1), which vectorise unlike branches
                    upper = work[k, j, r]
                    lower = work[i, j, r]
                    work[k, j, r] = lower * scratch[r] + upper * (1.0 - scratch[r])
                    work[i, j, r] = upper * scratch[r] + lower * (1.0 - scratch[r])
        for r in range(width):
            value = work[k, k, r]
            determinant[r] *= value
            magnitude = abs(value)
            smallest[r] = min(smallest[r], magnitude)
            largest[r] = max(largest[r], magnitude)
            scratch[r] = 1.0 / value if value != 0.0 else 0.0
        for i in range(k + 1, m):
            for r in range(width):
                pivot[r] = work[i, k, r] * scratch[r]  # reused: the row's multiplier
            for j in range(k + 1, size):
                for r in range(width):
                    work[i, j, r] -= pivot[r] * work[k, j, r]
    # back substitution: U y = -u (u the last column), out = det * (y, 1)
    for r in range(width):
        out[m, r] = 1.0
    for i in range(m - 1, -1, -1):
        for r in range(width):
            scratch[r] = -work[i, m, r]
        for j in range(i + 1, m):
            for r in range(width):
                scratch[r] -= work[i, j, r] * out[j, r]
        for r in range(width):
            value = work[i, i, r]
            out[i, r] = scratch[r] / value if value != 0.0 else 0.0
    for q in range(size):
        for r in range(width):
            out[q, r] *= determinant[r]
    for r in range(width):
        if not smallest[r] > LEADING_PIVOT_RATIO * largest[r]:  # poorly conditioned (or zero) block
            for i in range(m):
                for j in range(size):
                    scalar_rows[i, j] = rows[i, j, r]
            _null_vector(scalar_rows, size, scalar_out, scalar_work, scalar_columns)
            for q in range(size):
                out[q, r] = scalar_out[q]


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def _solve(matrix, size, rhs, out, work, pivot_tolerance):
    """Solve matrix[:size,:size] out = rhs by Gaussian elimination with partial pivoting.

    Returns False if singular: a pivot at or below ``pivot_tolerance`` times the largest diagonal
    entry (the matrix is a Gram matrix, positive semi-definite). ``work`` is scratch.
    """
    scale = 0.0
    for i in range(size):
        scale = max(scale, abs(matrix[i, i]))
        for j in range(size):
            work[i, j] = matrix[i, j]
        out[i] = rhs[i]
    limit = pivot_tolerance * scale
    for col in range(size):
        pivot = col
        best = abs(work[col, col])
        for row in range(col + 1, size):
            if abs(work[row, col]) > best:
                best = abs(work[row, col])
                pivot = row
        if best <= limit or best == 0.0:
            return False
        if pivot != col:
            for j in range(size):
                tmp = work[col, j]
                work[col, j] = work[pivot, j]
                work[pivot, j] = tmp
            tmp = out[col]
            out[col] = out[pivot]
            out[pivot] = tmp
        for row in range(col + 1, size):
            factor = work[row, col] / work[col, col]
            for j in range(col + 1, size):
                work[row, j] -= factor * work[col, j]
            out[row] -= factor * out[col]
    for row in range(size - 1, -1, -1):
        total = out[row]
        for j in range(row + 1, size):
            total -= work[row, j] * out[j]
        out[row] = total / work[row, row]
    return True


@njit(cache=True, error_model="numpy", fastmath=FASTMATH)
def _power_coefficient(numerator, arm, reference, threshold):
    """|A o T| / |A o T|_max, zero when the moment arm is at or below threshold * |omega|.

    Homogeneous: ``arm``, ``numerator`` and ``threshold`` are in working coordinates (lengths in
    units of L), ``threshold`` being p / L.
    """
    if arm <= threshold * reference or arm <= 0.0:
        return 0.0
    value = abs(numerator) / arm
    return 1.0 if value > 1.0 else value


@njit(_SIGNATURE, nogil=True, cache=True, error_model="numpy", fastmath=FASTMATH)
def transmission_kernel(all_twists, all_points, chain_start, actuator_chain, actuator_joint, basis, complement,
                        submechanisms, locked_sets, locked_of, set_children, fault_rows, locked_depth,
                        wedge_table, wedge_start, threshold, rank_tolerance,
                        pure_couple, outside_tolerance, gram_pivot, pseudo_inverse_consistency, worst_fault_tie,
                        iti_override, oti_override, iti_out, oti_out, oti_sub_out, summary_out, worst_out, mutual_out,
                        wrench_out, twist_out, outside_out):
    """Indices of a chunk of configurations.

    Parameters (N configurations, J joints in all, C chains, a actuators, n DOF, S submechanisms)
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
    submechanisms (S, n) : actuator indices of each non-redundant submechanism.
    locked_sets (L, n - 1) : every set of n - 1 actuators (locked while one other drives).
    locked_of (S, n) : for each submechanism and position k, the row of locked_sets holding
        the other n - 1 actuators of the submechanism.
    locked_depth (L,), wedge_table (T, 5), wedge_start (n + 1,) : for n >= 4, the output twists'
        exterior products (see :func:`screwkit.transmission._wedge_tables`): the first position at
        which each locked set differs from the one before, and the expansion terms (target minor,
        source minor, column, sign, first term of its target) of level K in rows
        wedge_start[K]:wedge_start[K+1].
    set_children (R, K), fault_rows (F, 2) : the actuator sets whose LMTI the reductions need
        (see :func:`screwkit.transmission._reductions`): row t of ``set_children`` lists rows of
        the OTIs and sets before it (OTIs of submechanisms first, then the sets in order, padded
        with -1) whose maximum is the LMTI of set t; ``fault_rows[f]`` is the range of those rows
        (OTIs included) holding the sets left after the f-th value of j, in combination order.
    threshold : the singularity threshold p, in the length unit of the screws (compared as p / L).
    rank_tolerance, pure_couple, outside_tolerance, gram_pivot, pseudo_inverse_consistency,
        worst_fault_tie : the dimensionless tolerances RANK_TOLERANCE, PURE_COUPLE,
        OUTSIDE_CONSTANT_SPACE, GRAM_PIVOT, PSEUDO_INVERSE_CONSISTENCY and WORST_FAULT_TIE of
        :mod:`screwkit.tolerances`, applied in working coordinates.
    iti_override, oti_override (N or 0, a, 3) : characteristic points given by the caller (world).
    Outputs: iti_out (N or 0, a), oti_out (N or 0, S, n), oti_sub_out (N or 0, S) (Eq. 9);
        summary_out (N, 2 + F) holding the ITI (Eq. 7), the LMTI of all actuators (Eq. 11) and
        F_Oj for each of the F values of j (Eqs. 12-13); worst_out (N, F) the worst set: the
        first set, in combination order, whose LMTI is at most F_Oj + worst_fault_tie (numpy's
        argmin, made robust to rounding between sets of mathematically equal LMTI);
        mutual_out (N, a) bool, whether each actuator is a mutual-interference actuator (some n
        others have independent wrenches); wrench_out (N or 0, a, 6) (world frame and unit:
        unit force, or unit moment for a pure couple), twist_out (N or 0, S, n, 6) (output
        twists, world frame and unit, scaled as the adjugate columns in working coordinates,
        so that |A'_k o T'_k| = |det W|), outside_out (N,) bool.
    """
    count = all_twists.shape[0]
    chains = chain_start.shape[0] - 1
    joints = chain_start[chains]
    a = actuator_chain.shape[0]
    n = basis.shape[1]
    subs = submechanisms.shape[0]
    constant = basis.shape[0] == 1
    blocks = (count + BLOCK - 1) // BLOCK
    # Scratch for the solves: a chain may have more joint DoFs than 6 (e.g. an S-S rod with
    # its idle spin), and numba does not check bounds.
    capacity = 6
    for c in range(chains):
        if chain_start[c + 1] - chain_start[c] > capacity:
            capacity = chain_start[c + 1] - chain_start[c]
    # Scratch, allocated once per call. Per-configuration quantities have a last "lane" axis:
    # each block of BLOCK configurations goes through every step lane-innermost, so that the
    # compiler vectorises the steps across configurations; the few steps with a data-dependent
    # algebra (null vectors of n > 3, Gram solves of chains with more joints than n) run per lane.
    local = np.empty((joints, 6, BLOCK))  # joint twists about the centroid
    local_points = np.empty((joints, 3, BLOCK))  # joint points relative to the centroid
    centres = np.empty((3, BLOCK))
    lengths = np.empty(BLOCK)  # the characteristic length L of each configuration
    inverse_lengths = np.empty(BLOCK)
    thresholds = np.empty(BLOCK)  # p / L
    motion_lanes = np.empty((n, 6, BLOCK))
    outside = np.zeros(BLOCK, dtype=np.bool_)
    shifted_basis = np.empty((n, 6, BLOCK))
    passive_rows = np.empty((6, 6, BLOCK))
    combination = np.empty((capacity, BLOCK))
    force = np.empty((6, BLOCK))  # (f, m) of the wrench being built
    wrench_lanes = np.empty((a, 6, BLOCK))
    point_lanes = np.empty((3, BLOCK))  # the OTI characteristic point of the actuator
    pitch_lanes = np.empty(BLOCK)
    shifted_lanes = np.empty((capacity, 6, BLOCK))  # a chain's unit twists about d
    gram_lanes = np.empty((capacity, capacity, BLOCK))
    rows = np.empty((6, 6))
    gram = np.empty((capacity, capacity))
    work = np.empty((capacity, capacity))
    columns = np.empty(6, dtype=np.int64)
    rhs = np.zeros(capacity)
    solution = np.empty(capacity)
    has_force = np.zeros((a, BLOCK), dtype=np.bool_)
    arms = np.zeros((a, n, 3, BLOCK))
    iti_local = np.zeros((a, BLOCK))
    wrench_matrix = np.zeros((a, n, BLOCK))
    row_norms = np.zeros((a, BLOCK))
    output = np.empty((locked_sets.shape[0], n, BLOCK))
    wedge = np.zeros((max(n, 1), 20, BLOCK))  # minors of the first K locked rows, at most C(6, 3) = 20 per level
    locked_rows = np.empty((max(n - 1, 1), n, BLOCK))
    elimination = np.empty((max(n - 1, 1), n, BLOCK))
    lane_a = np.empty(BLOCK)
    lane_b = np.empty(BLOCK)
    lane_c = np.empty(BLOCK)
    lane_d = np.empty(BLOCK)
    lane_e = np.empty(BLOCK)
    scalar_out = np.empty(6)
    output_omega = np.empty((locked_sets.shape[0], BLOCK))
    oti_local = np.empty((subs + set_children.shape[0], BLOCK))  # OTIs, then the LMTIs of the sets
    independent = np.empty((subs, BLOCK), dtype=np.bool_)
    values = np.empty((n, BLOCK))
    determinant = np.empty(BLOCK)
    volume = np.empty(BLOCK)
    lane0 = np.empty(BLOCK)
    lane1 = np.empty(BLOCK)
    lane2 = np.empty(BLOCK)
    best = np.empty(BLOCK)
    mutual = np.empty(BLOCK, dtype=np.bool_)
    first_set = np.empty(BLOCK, dtype=np.int64)
    pure_couple_sq = pure_couple * pure_couple
    outside_sq = outside_tolerance * outside_tolerance
    member = np.zeros((subs, a), dtype=np.bool_)
    for s in range(subs):
        for i in range(n):
            member[s, submechanisms[s, i]] = True
    for block in range(blocks):
        first_index = block * BLOCK
        last_index = min(count, first_index + BLOCK)
        width = last_index - first_index
        # ---------------- first stage: centroid frame, actuation wrenches, ITIs, moment arms.
        for j in range(joints):  # gather the block lane-innermost (component-major input is read in runs)
            for k in range(6):
                for r in range(width):
                    local[j, k, r] = all_twists[first_index + r, j, k]
            for k in range(3):
                for r in range(width):
                    local_points[j, k, r] = all_points[first_index + r, j, k]
        # --- centroid of the platform joints; everything below is expressed about it.
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
        # --- the characteristic length L: RMS distance of every joint point from the centroid.
        for r in range(width):
            lane0[r] = 0.0
        for j in range(joints):
            for r in range(width):
                p0 = local_points[j, 0, r] - centres[0, r]
                p1 = local_points[j, 1, r] - centres[1, r]
                p2 = local_points[j, 2, r] - centres[2, r]
                local_points[j, 0, r] = p0
                local_points[j, 1, r] = p1
                local_points[j, 2, r] = p2
                lane0[r] += p0 * p0 + p1 * p1 + p2 * p2
        for r in range(width):
            length = np.sqrt(lane0[r] / joints)
            if not length > 0.0:  # every joint point at the centroid: no length to scale by
                length = 1.0
            lengths[r] = length
            inverse_lengths[r] = 1.0 / length
            thresholds[r] = threshold / length
        # --- working coordinates: twists about the centroid, lengths in units of L.
        for j in range(joints):
            for r in range(width):
                x0, x1, x2 = _cross(local[j, 0, r], local[j, 1, r], local[j, 2, r],
                                    centres[0, r], centres[1, r], centres[2, r])
                inverse = inverse_lengths[r]
                local[j, 3, r] = (local[j, 3, r] + x0) * inverse
                local[j, 4, r] = (local[j, 4, r] + x1) * inverse
                local[j, 5, r] = (local[j, 5, r] + x2) * inverse
                local_points[j, 0, r] *= inverse
                local_points[j, 1, r] *= inverse
                local_points[j, 2, r] *= inverse
        for q in range(n):
            for k in range(6):
                if constant:
                    for r in range(width):
                        motion_lanes[q, k, r] = basis[0, q, k]
                else:
                    for r in range(width):
                        motion_lanes[q, k, r] = basis[first_index + r, q, k]
        # --- a constant basis must contain every joint twist.
        for r in range(width):
            outside[r] = False
        if constant and complement.shape[0] > 0:
            for j in range(joints):
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
        # --- actuation wrenches (one per actuator), in the representative documented in analyze().
        for act in range(a):
            chain = actuator_chain[act]
            start = chain_start[chain]
            m = chain_start[chain + 1] - start
            own = start + actuator_joint[act]
            last = start + m - 1
            after = own + 1 if own < last else own
            for k in range(6):
                for r in range(width):
                    force[k, r] = 0.0
            if m == n:
                # SWAP M' x with x spanning null(J_passive'^T M'), all about the platform joint d
                # (working coordinates).
                for q in range(n):
                    for r in range(width):
                        x0, x1, x2 = _cross(motion_lanes[q, 0, r], motion_lanes[q, 1, r], motion_lanes[q, 2, r],
                                            local_points[last, 0, r], local_points[last, 1, r],
                                            local_points[last, 2, r])
                        shifted_basis[q, 0, r] = motion_lanes[q, 0, r]
                        shifted_basis[q, 1, r] = motion_lanes[q, 1, r]
                        shifted_basis[q, 2, r] = motion_lanes[q, 2, r]
                        shifted_basis[q, 3, r] = motion_lanes[q, 3, r] + x0
                        shifted_basis[q, 4, r] = motion_lanes[q, 4, r] + x1
                        shifted_basis[q, 5, r] = motion_lanes[q, 5, r] + x2
                passive = 0
                for j in range(start, last + 1):
                    if j == own:
                        continue
                    for q in range(n):
                        for r in range(width):
                            x0, x1, x2 = _cross(local[j, 0, r], local[j, 1, r], local[j, 2, r],
                                                local_points[last, 0, r], local_points[last, 1, r],
                                                local_points[last, 2, r])
                            passive_rows[passive, q, r] = (
                                local[j, 0, r] * shifted_basis[q, 0, r] + local[j, 1, r] * shifted_basis[q, 1, r]
                                + local[j, 2, r] * shifted_basis[q, 2, r]
                                + (local[j, 3, r] + x0) * shifted_basis[q, 3, r]
                                + (local[j, 4, r] + x1) * shifted_basis[q, 4, r]
                                + (local[j, 5, r] + x2) * shifted_basis[q, 5, r])
                    passive += 1
                if n == 3:  # the null vector of two rows is their cross product
                    for r in range(width):
                        combination[0, r], combination[1, r], combination[2, r] = _cross(
                            passive_rows[0, 0, r], passive_rows[0, 1, r], passive_rows[0, 2, r],
                            passive_rows[1, 0, r], passive_rows[1, 1, r], passive_rows[1, 2, r])
                else:
                    for i in range(n - 1):
                        for q in range(n):
                            for r in range(width):
                                locked_rows[i, q, r] = passive_rows[i, q, r]
                    _null_vectors_lanes(locked_rows, n, width, combination, elimination, lane_a, lane_b, lane_c,
                                        lane_d, lane_e, rows, work, columns, scalar_out)
                # The wrench about d: SWAP of the combination of the shifted basis.
                for q in range(n):
                    for r in range(width):
                        y = combination[q, r]
                        force[0, r] += y * shifted_basis[q, 3, r]
                        force[1, r] += y * shifted_basis[q, 4, r]
                        force[2, r] += y * shifted_basis[q, 5, r]
                        force[3, r] += y * shifted_basis[q, 0, r]
                        force[4, r] += y * shifted_basis[q, 1, r]
                        force[5, r] += y * shifted_basis[q, 2, r]
            else:
                # Minimum-norm solution SWAP J' (J'^T J')^-1 e_k, J' the chain's twists about d in
                # working coordinates, each scaled to unit norm (a column scaling: the same wrench,
                # and the Gram pivot test compares dimensionless numbers). J' and its Gram matrix
                # across the lanes, then the solve configuration by configuration.
                for j in range(m):
                    for r in range(width):
                        w0, w1, w2 = local[start + j, 0, r], local[start + j, 1, r], local[start + j, 2, r]
                        x0, x1, x2 = _cross(w0, w1, w2, local_points[last, 0, r], local_points[last, 1, r],
                                            local_points[last, 2, r])
                        u0 = local[start + j, 3, r] + x0
                        u1 = local[start + j, 4, r] + x1
                        u2 = local[start + j, 5, r] + x2
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
                    if outside[r]:
                        continue  # recomputed with its own motion space
                    for i in range(m):
                        for j in range(m):
                            gram[i, j] = gram_lanes[i, j, r]
                        rhs[i] = 0.0
                    rhs[own - start] = 1.0
                    regular = _solve(gram, m, rhs, solution, work, gram_pivot)
                    if not regular:
                        # Dependent joint twists (an idle DoF): pseudo-inverse, kept if consistent.
                        pseudo = np.linalg.pinv(gram[:m, :m].copy())
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
            # --- unit wrench about the centroid, its ITI (Eq. 6) and its OTI characteristic point.
            for r in range(width):
                d0, d1, d2 = local_points[last, 0, r], local_points[last, 1, r], local_points[last, 2, r]
                f0, f1, f2 = force[0, r], force[1, r], force[2, r]
                x0, x1, x2 = _cross(d0, d1, d2, f0, f1, f2)  # m_c = m_d + d x f
                m0 = force[3, r] + x0
                m1 = force[4, r] + x1
                m2 = force[5, r] + x2
                force_sq = f0 * f0 + f1 * f1 + f2 * f2
                moment_sq = m0 * m0 + m1 * m1 + m2 * m2
                # A pure couple: |f| <= PURE_COUPLE |m_c| / L (working coordinates, moment about c).
                forceful = force_sq > pure_couple_sq * moment_sq and force_sq > 0.0
                scale = np.sqrt(force_sq) if forceful else np.sqrt(moment_sq)
                work_done = (f0 * local[own, 3, r] + f1 * local[own, 4, r] + f2 * local[own, 5, r]
                             + m0 * local[own, 0, r] + m1 * local[own, 1, r] + m2 * local[own, 2, r])
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
                pitch_lanes[r] = pitch
                # Characteristic points: projections on the wrench axis (unit force).
                axis0, axis1, axis2 = _cross(f0, f1, f2, m0, m1, m2)
                if iti_override.shape[0] > 0:
                    p0 = (iti_override[first_index + r, act, 0] - centres[0, r]) * inverse_lengths[r]
                    p1 = (iti_override[first_index + r, act, 1] - centres[1, r]) * inverse_lengths[r]
                    p2 = (iti_override[first_index + r, act, 2] - centres[2, r]) * inverse_lengths[r]
                else:
                    p0, p1, p2 = local_points[after, 0, r], local_points[after, 1, r], local_points[after, 2, r]
                    if forceful:
                        along = (p0 - axis0) * f0 + (p1 - axis1) * f1 + (p2 - axis2) * f2
                        p0 = axis0 + along * f0
                        p1 = axis1 + along * f1
                        p2 = axis2 + along * f2
                # ITI (Eq. 6): power coefficient on the actuated joint's own twist.
                w0, w1, w2 = local[own, 0, r], local[own, 1, r], local[own, 2, r]
                x0, x1, x2 = _cross(w0, w1, w2, p0, p1, p2)
                omega = np.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
                v0 = local[own, 3, r] + x0 + pitch * w0
                v1 = local[own, 4, r] + x1 + pitch * w1
                v2 = local[own, 5, r] + x2 + pitch * w2
                arm = np.sqrt(v0 * v0 + v1 * v1 + v2 * v2) if forceful else omega
                reference = omega if forceful else 0.0
                iti_local[act, r] = _power_coefficient(work_done * factor, arm, reference, thresholds[r])
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
                point_lanes[0, r] = p0
                point_lanes[1, r] = p1
                point_lanes[2, r] = p2
            # Moment-arm operator of the OTI for twists M^T y: v + omega x p + h omega (omega for a couple),
            # and the row of the wrench matrix in motion coordinates, A_k o M_q.
            for r in range(width):
                row_norms[act, r] = 0.0
            for q in range(n):
                for r in range(width):
                    w0, w1, w2 = motion_lanes[q, 0, r], motion_lanes[q, 1, r], motion_lanes[q, 2, r]
                    x0, x1, x2 = _cross(w0, w1, w2, point_lanes[0, r], point_lanes[1, r], point_lanes[2, r])
                    pitch = pitch_lanes[r]
                    forceful = has_force[act, r]
                    arms[act, q, 0, r] = motion_lanes[q, 3, r] + x0 + pitch * w0 if forceful else w0
                    arms[act, q, 1, r] = motion_lanes[q, 4, r] + x1 + pitch * w1 if forceful else w1
                    arms[act, q, 2, r] = motion_lanes[q, 5, r] + x2 + pitch * w2 if forceful else w2
                    value = (wrench_lanes[act, 0, r] * motion_lanes[q, 3, r]
                             + wrench_lanes[act, 1, r] * motion_lanes[q, 4, r]
                             + wrench_lanes[act, 2, r] * motion_lanes[q, 5, r]
                             + wrench_lanes[act, 3, r] * w0 + wrench_lanes[act, 4, r] * w1
                             + wrench_lanes[act, 5, r] * w2)
                    wrench_matrix[act, q, r] = value
                    row_norms[act, r] += value * value
            for r in range(width):
                row_norms[act, r] = np.sqrt(row_norms[act, r])
            if wrench_out.shape[0] > 0:  # back to world units and origin: m_0 = L m' + c x f
                for r in range(width):
                    f0, f1, f2 = wrench_lanes[act, 0, r], wrench_lanes[act, 1, r], wrench_lanes[act, 2, r]
                    x0, x1, x2 = _cross(centres[0, r], centres[1, r], centres[2, r], f0, f1, f2)
                    length = lengths[r]
                    unit = 1.0 if has_force[act, r] else inverse_lengths[r]  # a couple: unit moment in world units
                    wrench_out[first_index + r, act, 0] = f0 * unit
                    wrench_out[first_index + r, act, 1] = f1 * unit
                    wrench_out[first_index + r, act, 2] = f2 * unit
                    wrench_out[first_index + r, act, 3] = (wrench_lanes[act, 3, r] * length + x0) * unit
                    wrench_out[first_index + r, act, 4] = (wrench_lanes[act, 4, r] * length + x1) * unit
                    wrench_out[first_index + r, act, 5] = (wrench_lanes[act, 5, r] * length + x2) * unit
        # ---------------- second stage: output twists, OTIs and the reductions over actuator sets.
        # --- output twists: for each set of n - 1 locked actuators, the twist reciprocal to
        # their wrenches (a column of adj(W) of every submechanism containing the set).
        for locked in range(locked_sets.shape[0]):
            if n == 3:  # the cross product of the two locked rows, written out
                i0 = locked_sets[locked, 0]
                i1 = locked_sets[locked, 1]
                for r in range(width):
                    output[locked, 0, r], output[locked, 1, r], output[locked, 2, r] = _cross(
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
                    first_row = locked_sets[locked, 0]
                    for term in range(wedge_start[level], wedge_start[level + 1]):
                        target = wedge_table[term, 0]
                        source = wedge_table[term, 1]
                        column = wedge_table[term, 2]
                        sign = float(wedge_table[term, 3])
                        if wedge_table[term, 4] == 1:
                            for r in range(width):
                                wedge[level, target, r] = 0.0
                        if level == 2:
                            for r in range(width):
                                wedge[2, target, r] += sign * wrench_matrix[first_row, source, r] * wrench_matrix[
                                    row, column, r]
                        else:
                            for r in range(width):
                                wedge[level, target, r] += sign * wedge[level - 1, source, r] * wrench_matrix[
                                    row, column, r]
                # out[q] = (-1)^(n-1+q) det(rows without column q): minor n - 1 - q of the last level
                for q in range(n):
                    sign = 1.0 if (n - 1 + q) % 2 == 0 else -1.0
                    for r in range(width):
                        output[locked, q, r] = sign * wedge[n - 1, n - 1 - q, r]
            for r in range(width):
                lane0[r] = 0.0
                lane1[r] = 0.0
                lane2[r] = 0.0
            for q in range(n):
                for r in range(width):
                    y = output[locked, q, r]
                    lane0[r] += motion_lanes[q, 0, r] * y
                    lane1[r] += motion_lanes[q, 1, r] * y
                    lane2[r] += motion_lanes[q, 2, r] * y
            for r in range(width):
                output_omega[locked, r] = np.sqrt(lane0[r] * lane0[r] + lane1[r] * lane1[r] + lane2[r] * lane2[r])
        # --- every non-redundant submechanism once: |A_k o T_k| = |det W| for each k (A3).
        for s in range(subs):
            first = locked_of[s, 0]
            leader = submechanisms[s, 0]
            for r in range(width):
                volume[r] = 1.0
                determinant[r] = 0.0
                best[r] = 1.0  # the submechanism's OTI (Eq. 9), a minimum
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
                    lane0[r] = 0.0
                    lane1[r] = 0.0
                    lane2[r] = 0.0
                for q in range(n):
                    for r in range(width):
                        y = output[locked, q, r]
                        lane0[r] += arms[act, q, 0, r] * y
                        lane1[r] += arms[act, q, 1, r] * y
                        lane2[r] += arms[act, q, 2, r] * y
                for r in range(width):
                    arm = np.sqrt(lane0[r] * lane0[r] + lane1[r] * lane1[r] + lane2[r] * lane2[r])
                    reference = output_omega[locked, r] if has_force[act, r] else 0.0
                    value = (_power_coefficient(determinant[r], arm, reference, thresholds[r])
                             if independent[s, r] else 0.0)
                    values[position, r] = value
                    best[r] = min(best[r], value)
                if oti_out.shape[0] > 0:
                    for r in range(width):
                        oti_out[first_index + r, s, position] = values[position, r]
                if twist_out.shape[0] > 0:
                    for r in range(width):
                        index = first_index + r
                        for k in range(6):
                            total = 0.0
                            for q in range(n):
                                total += output[locked, q, r] * motion_lanes[q, k, r]
                            twist_out[index, s, position, k] = total if k < 3 else total * lengths[r]
                        # back to world units and origin: v_0 = L v' - omega x c
                        x0, x1, x2 = _cross(twist_out[index, s, position, 0], twist_out[index, s, position, 1],
                                            twist_out[index, s, position, 2], centres[0, r], centres[1, r],
                                            centres[2, r])
                        twist_out[index, s, position, 3] -= x0
                        twist_out[index, s, position, 4] -= x1
                        twist_out[index, s, position, 5] -= x2
            for r in range(width):
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
