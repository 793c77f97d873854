"""Compiled constraint transmission index (CTI) of lower-mobility mechanisms, configuration by configuration.

:func:`constraint_kernel` does for a chunk of configurations what :func:`screwkit.screw.constraints.constraint_indices`
does with numpy (the readable reference, which ``tests/test_constraint_kernel.py`` holds it to) for mechanisms whose
constraint subsystems are *square*: the ``n`` actuation wrenches of a set, the own constraint wrenches of the
chains of a subsystem and the common ones are six wrenches (the numpy branch of one inverse; overlapping own
wrenches keep the numpy path). Per configuration: the rank of all the chains' constraint wrenches (the
instantaneous DOF, one-sided Jacobi rotations, :func:`constraint_rank`); the common constraint wrenches and each
chain's own ones (:func:`own_wrenches`); then, for every actuator set, an orthonormal basis of the complement of
the rows every subsystem keeps (the set's actuation wrenches and the common constraint wrenches; Householder
reflections, :func:`complement`, whose R gives their part of the determinant) and each chain's own wrenches in that
basis (:func:`own_in_complement`); for every subsystem, the square block of its own wrenches there, factored
(:func:`factor`: with the held part, the determinant of the whole system and so its regularity), the twists freed
by releasing each chain (the basis times columns of the block's inverse: the columns of the whole system's inverse,
:func:`freed_twists`), the principal pairs of wrench and freed twist (:func:`released_pairs`) and their power
coefficients (:func:`coefficient`), the lowest of which is :math:`CTI_{N,L}`. numpy takes several LAPACK calls
and a dozen broadcast passes per set and subsystem; here one configuration of a 4-leg Delta (4 sets, 4
subsystems) takes a few microseconds.

Values agree with numpy's to rounding (over the conditioning of the systems): the determinant and the freed
twists come from another but equally stable factorisation than numpy's 6 x 6 LU, the freed twists and the
principal pairs are spans, found here by other means (an orthonormal basis by Gram-Schmidt rather than Householder
QR, Jacobi rather than LAPACK's SVD), and every power coefficient is independent of the basis chosen within them
and of signs.
"""

from __future__ import annotations

import numpy as np

from screwkit.common.fastmath import FASTMATH
from screwkit.common.jit import njit
from screwkit.common.tolerances import ZERO_PITCH
from screwkit.indices.compiled.algebra import crossing_point
from screwkit.indices.compiled.jacobi import NULL_COLUMN, singular_vectors, symmetric_eigen, unit_columns

__all__ = ["constraint_kernel"]

# The one signature: every array C-contiguous.
_SIGNATURE = ("void(float64[:, :, ::1], int64[::1], int64[::1], int64, float64[:, :, ::1], float64[:, :, ::1], "
              "int64[:, ::1], int64[:, ::1], float64[::1], float64, float64, float64, float64, int64[::1], "
              "float64[:, ::1])")


@njit(cache=True, error_model="numpy", fastmath=FASTMATH)
def constraint_rank(constraints, index, count, tolerance, columns, scratch):
    """Rank of the unit constraint wrenches constraints[index, :count]: singular values above ``tolerance`` times
    the largest (``numpy.linalg.svd`` of the unit rows). Six of them or fewer are rotated as the columns of their
    transpose (fewer pairs than the six components'). ``scratch``: vectors (6, 6), norms (6), order (6, int),
    singular (6), right (6, 6)."""
    vectors, norms, order, singular, right = scratch
    unit_columns(constraints, index, 0, count, columns)
    width = min(count, 6)
    rows = 6 if count <= 6 else count
    if count <= 6:
        for j in range(count):  # transposed in place: the lower triangle first, the rest below it
            for k in range(j + 1, 6):
                columns[j, k], columns[k, j] = columns[k, j], columns[j, k]
    singular_vectors(columns, rows, 6 if count > 6 else count, NULL_COLUMN * NULL_COLUMN * count, vectors, norms,
                     order, singular, right)
    rank = 0
    for i in range(width):
        if singular[i] > tolerance * max(singular[0], 1e-300):
            rank += 1
    return rank


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def remove_component(rows, row, units, unit):
    """rows[row] less its component along the unit vector units[unit] (six components)."""
    along = 0.0
    for p in range(6):
        along += rows[row, p] * units[unit, p]
    for p in range(6):
        rows[row, p] -= along * units[unit, p]


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def common_wrenches(constraints, index, wrench_start, common, shared, total, scratch):
    """shared[:common] = an orthonormal basis of the wrenches every chain holds: the eigenvectors of the
    ``common`` smallest eigenvalues of sum_i (I - C_i^T C_i) (as ``_common_basis``)."""
    vectors, diagonal, order, values, eigenvectors = scratch
    chains = wrench_start.shape[0] - 1
    for p in range(6):
        for q in range(6):
            total[p, q] = chains if p == q else 0.0
    for r in range(wrench_start[0], wrench_start[chains]):
        for p in range(6):
            for q in range(6):
                total[p, q] -= constraints[index, r, p] * constraints[index, r, q]
    symmetric_eigen(total, vectors, diagonal, order, values, eigenvectors)
    for k in range(common):
        for p in range(6):
            shared[k, p] = eigenvectors[p, k]


@njit(cache=True, error_model="numpy", fastmath=FASTMATH)
def own_wrenches(constraints, index, wrench_start, own_counts, common, own, shared, columns, total, scratch):
    """own[c, :own_counts[c]] = an orthonormal basis of chain c's constraint wrenches with their components along
    the common ones (``shared[:common]``, :func:`common_wrenches`) removed (as ``_own_wrenches``). Without common
    wrenches, a chain's constraint wrenches are that basis already (rows of right singular vectors)."""
    vectors, norms, order, singular, right = scratch
    if common:
        common_wrenches(constraints, index, wrench_start, common, shared, total, scratch)
    for c in range(own_counts.shape[0]):
        rows = wrench_start[c + 1] - wrench_start[c]
        if own_counts[c] == 0:
            continue
        frobenius = 0.0
        for r in range(rows):
            for p in range(6):
                columns[r, p] = constraints[index, wrench_start[c] + r, p]
            for k in range(common):
                remove_component(columns, r, shared, k)
            for p in range(6):
                frobenius += columns[r, p] * columns[r, p]
        if not common:
            for r in range(rows):
                for p in range(6):
                    own[c, r, p] = columns[r, p]
            continue
        singular_vectors(columns, rows, 6, NULL_COLUMN * NULL_COLUMN * frobenius, vectors, norms, order, singular,
                         right)
        for r in range(own_counts[c]):
            for p in range(6):
                own[c, r, p] = right[r, p]


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def held_rows(wrenches, index, submechanisms, actuators, shared, common, rows):
    """rows[:n + common] = the actuation wrenches of one actuator set (row ``actuators`` of ``submechanisms``) and
    the common constraint wrenches (what every subsystem keeps); returns the product of their norms."""
    n = submechanisms.shape[1]
    for k in range(n):
        for p in range(6):
            rows[k, p] = wrenches[index, submechanisms[actuators, k], p]
    for r in range(common):
        for p in range(6):
            rows[n + r, p] = shared[r, p]
    volume = 1.0
    for r in range(n + common):
        total = 0.0
        for p in range(6):
            total += rows[r, p] * rows[r, p]
        volume *= np.sqrt(total)
    return volume


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def complement(rows, size, reflectors, basis):
    """basis[:, :6 - size] = an orthonormal basis of the vectors orthogonal to rows[:size] (Householder QR of
    their transpose, the reflectors' vectors in ``reflectors``); returns the product of the magnitudes of R's
    diagonal, sqrt(det(rows rows^T)), zero when the rows are dependent."""
    volume = 1.0
    for j in range(size):  # reflector j: from the rows, with the earlier reflectors applied
        for i in range(6):
            reflectors[j, i] = rows[j, i]
        for earlier in range(j):
            along = 0.0
            for i in range(earlier, 6):
                along += reflectors[earlier, i] * reflectors[j, i]
            for i in range(earlier, 6):
                reflectors[j, i] -= 2.0 * along * reflectors[earlier, i]
        norm = 0.0
        for i in range(j, 6):
            norm += reflectors[j, i] * reflectors[j, i]
        norm = np.sqrt(norm)
        if norm == 0.0:
            return 0.0
        volume *= norm
        alpha = -norm if reflectors[j, j] >= 0.0 else norm
        for i in range(j):
            reflectors[j, i] = 0.0
        reflectors[j, j] -= alpha
        scale = np.sqrt(2.0 * norm * (norm + abs(reflectors[j, j] + alpha)))  # |v| (v = x - alpha e_j)
        for i in range(j, 6):
            reflectors[j, i] /= scale
    for k in range(6 - size):  # Q e_(size + k) = H_0 ... H_(size - 1) e_(size + k)
        for i in range(6):
            basis[i, k] = 1.0 if i == size + k else 0.0
        for j in range(size - 1, -1, -1):
            along = 0.0
            for i in range(j, 6):
                along += reflectors[j, i] * basis[i, k]
            for i in range(j, 6):
                basis[i, k] -= 2.0 * along * reflectors[j, i]
    return volume


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def own_in_complement(own, own_counts, basis, size, reduced):
    """reduced[r, :size] = each chain's own wrench r (chains in turn) in the basis of the complement of the held
    rows (:func:`complement`): for a subsystem, the square block of the system the held rows leave."""
    row = 0
    for c in range(own_counts.shape[0]):
        for r in range(own_counts[c]):
            for k in range(size):
                total = 0.0
                for p in range(6):
                    total += own[c, r, p] * basis[p, k]
                reduced[row, k] = total
            row += 1


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def factor(matrix, size, permutation):
    """LU factorisation with partial pivoting of matrix[:size, :size] in place (``P matrix = L U``, the row
    permutation in ``permutation``), as LAPACK's getrf; returns the determinant (zero at a zero pivot)."""
    determinant = 1.0
    for i in range(size):
        permutation[i] = i
    for k in range(size):
        pivot, best = k, abs(matrix[k, k])
        for i in range(k + 1, size):
            if abs(matrix[i, k]) > best:
                pivot, best = i, abs(matrix[i, k])
        if best == 0.0:
            return 0.0
        if pivot != k:
            for j in range(size):
                matrix[k, j], matrix[pivot, j] = matrix[pivot, j], matrix[k, j]
            permutation[k], permutation[pivot] = permutation[pivot], permutation[k]
            determinant = -determinant
        determinant *= matrix[k, k]
        for i in range(k + 1, size):
            matrix[i, k] /= matrix[k, k]
            for j in range(k + 1, size):
                matrix[i, j] -= matrix[i, k] * matrix[k, j]
    return determinant


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def freed_twists(lu, permutation, size, start, count, basis, freed, column):
    """freed[j] (j < count) = the twist reciprocal to every wrench of the system but the chain's own wrench j
    (row start + j of the factored square block ``lu``, size x size): ``basis`` times column start + j of the
    block's inverse, its halves swapped. Orthonormalised (Gram-Schmidt, twice) when the chain holds several
    (the same span, as the numpy path's QR)."""
    for j in range(count):
        for i in range(size):  # L y = P e_(start + j)
            total = 1.0 if permutation[i] == start + j else 0.0
            for k in range(i):
                total -= lu[i, k] * column[k]
            column[i] = total
        for i in range(size - 1, -1, -1):  # U x = y
            total = column[i]
            for k in range(i + 1, size):
                total -= lu[i, k] * column[k]
            column[i] = total / lu[i, i]
        for i in range(6):  # the halves swapped: a twist (omega, v)
            total = 0.0
            for k in range(size):
                total += basis[i, k] * column[k]
            freed[j, i + 3 if i < 3 else i - 3] = total
    if count > 1:
        for j in range(count):
            for _ in range(2):
                for i in range(j):
                    remove_component(freed, j, freed, i)
            norm = 0.0
            for k in range(6):
                norm += freed[j, k] * freed[j, k]
            norm = np.sqrt(norm)
            for k in range(6):
                freed[j, k] = freed[j, k] / norm if norm > 0.0 else 0.0


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def released_pairs(own, chain, size, freed, rank_tolerance, repeated_pairing, pairing, wrenches, twists, exists,
                   scratch):
    """The principal pairs of a chain's own wrenches own[chain, :size] and the twists freed[:size] their release
    frees (as :func:`screwkit.screw.principal_pairs.released_pairs`): wrenches U^T C and twists F V from the
    singular vectors of the pairing ``C o F = U S V^T``; ``exists[i]``: singular value i above ``rank_tolerance``
    times the largest. One wrench and one freed twist are their own pair. Returns whether two pairs that exist have
    singular values within ``repeated_pairing`` times the largest (a repeated block, whose worst rotation the numpy
    code finds: :func:`screwkit.screw.principal_pairs.worst_in_blocks`)."""
    vectors, norms, order, singular, right = scratch
    if size == 1:
        for p in range(6):
            wrenches[0, p] = own[chain, 0, p]
            twists[0, p] = freed[0, p]
        exists[0] = True
        return False
    frobenius = 0.0
    for k in range(size):
        for j in range(size):
            total = 0.0
            for p in range(3):
                total += own[chain, k, p] * freed[j, p + 3] + own[chain, k, p + 3] * freed[j, p]
            pairing[k, j] = total
            frobenius += total * total
    singular_vectors(pairing, size, size, NULL_COLUMN * NULL_COLUMN * frobenius, vectors, norms, order, singular,
                     right)
    for i in range(size):
        exists[i] = singular[i] > rank_tolerance * max(singular[0], 1e-300)
        inverse = 1.0 / singular[i] if singular[i] > 0.0 else 0.0
        for p in range(6):
            wrench, twist = 0.0, 0.0
            for k in range(size):
                wrench += pairing[k, order[i]] * inverse * own[chain, k, p]
                twist += freed[k, p] * right[i, k]
            wrenches[i, p] = wrench
            twists[i, p] = twist
    repeated = False
    for i in range(1, size):
        if exists[i] and singular[i - 1] - singular[i] <= repeated_pairing * singular[0]:
            repeated = True
    return repeated


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def coefficient(wrenches, twists, pair, points, index, chain, threshold, rounded_couple):
    """Power coefficient of the unit constraint wrench ``wrenches[pair]`` on the twist ``twists[pair]`` (as
    :func:`screwkit.screw.principal_pairs.power_coefficients`), its characteristic point the point of the wrench's axis
    nearest to the chain's platform joint ``points[index, chain, :3]`` or, for a force and when the joint has one, its
    axis ``points[index, chain, 3:]`` (:func:`screwkit.screw.algebra.nearest_on_axis`; a couple, or a force at most
    ``rounded_couple`` times its moment: |m . omega| / |m||omega|)."""
    f0, f1, f2 = wrenches[pair, 0], wrenches[pair, 1], wrenches[pair, 2]
    m0, m1, m2 = wrenches[pair, 3], wrenches[pair, 4], wrenches[pair, 5]
    w0, w1, w2 = twists[pair, 0], twists[pair, 1], twists[pair, 2]
    v0, v1, v2 = twists[pair, 3], twists[pair, 4], twists[pair, 5]
    norm_sq = f0 * f0 + f1 * f1 + f2 * f2
    p0, p1, p2 = points[index, chain, 0], points[index, chain, 1], points[index, chain, 2]
    if norm_sq > 0.0:  # the point of the axis nearest the chain's platform joint (its axis, when it has one)
        c0, c1, c2 = (f1 * m2 - f2 * m1) / norm_sq, (f2 * m0 - f0 * m2) / norm_sq, (f0 * m1 - f1 * m0) / norm_sq
        along = ((p0 - c0) * f0 + (p1 - c1) * f1 + (p2 - c2) * f2) / norm_sq
        q0, q1, q2 = c0 + along * f0, c1 + along * f1, c2 + along * f2
        if abs(f0 * m0 + f1 * m1 + f2 * m2) <= ZERO_PITCH * norm_sq:  # a force: where it crosses the joint's axis
            q0, q1, q2 = crossing_point(p0, p1, p2, q0, q1, q2, f0, f1, f2, norm_sq, points[index, chain, 3],
                                        points[index, chain, 4], points[index, chain, 5])
        p0, p1, p2 = q0, q1, q2
    force_norm = np.sqrt(norm_sq)
    moment_norm = np.sqrt(m0 * m0 + m1 * m1 + m2 * m2)
    omega_norm = np.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
    if force_norm > rounded_couple * moment_norm:
        numerator = abs(f0 * v0 + f1 * v1 + f2 * v2 + m0 * w0 + m1 * w1 + m2 * w2)
        pitch = (f0 * m0 + f1 * m1 + f2 * m2) / (force_norm * force_norm)
        a0 = v0 + (w1 * p2 - w2 * p1) + pitch * w0
        a1 = v1 + (w2 * p0 - w0 * p2) + pitch * w1
        a2 = v2 + (w0 * p1 - w1 * p0) + pitch * w2
        arm, scale, reference = np.sqrt(a0 * a0 + a1 * a1 + a2 * a2), force_norm, omega_norm
    else:  # a couple, or the couple a file's rounding made a force far away (ROUNDED_COUPLE): its force left out
        numerator = abs(m0 * w0 + m1 * w1 + m2 * w2)
        arm, scale, reference = omega_norm, moment_norm, 0.0
    if arm <= threshold * reference or arm * scale <= 0.0:
        return 0.0
    return min(numerator / (arm * scale), 1.0)


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def subsystem_cti(index, own_counts, members, subsystem, own, points, threshold, held, work):
    """:math:`CTI_{N,L}` of one configuration, actuator set and subsystem (row ``subsystem`` of ``members``): zero
    when the set's and the subsystem's wrenches do not span every wrench, else the lowest power coefficient of a
    released constraint wrench on the twist it frees (as ``_subsystem_cti``). ``held``: the product of the held
    rows' norms and their sqrt(det(rows rows^T)) (:func:`complement`), the size of the complement, the
    tolerances. -1 where a chain's pairs have a repeated singular value (:func:`released_pairs`)."""
    volume, held_volume, size, rank_tolerance, rounded_couple, repeated_pairing = held
    permutation, basis, reduced, block, freed, column, pairing, wrenches, twists, exists, scratch = work
    row, chain_row = 0, 0
    for c in range(own_counts.shape[0]):  # the square block: the subsystem's own wrenches in the complement
        if members[subsystem, c]:
            for r in range(own_counts[c]):
                norm = 0.0
                for p in range(6):
                    norm += own[c, r, p] * own[c, r, p]
                volume *= np.sqrt(norm)
                for k in range(size):
                    block[row, k] = reduced[chain_row + r, k]
                row += 1
        chain_row += own_counts[c]
    determinant = held_volume * factor(block, size, permutation)  # |det| of the whole system
    if not abs(determinant) > rank_tolerance * volume:
        return 0.0
    value, start = np.inf, 0
    for c in range(own_counts.shape[0]):
        count = own_counts[c]
        if not members[subsystem, c] or count == 0:
            continue
        freed_twists(block, permutation, size, start, count, basis, freed, column)
        if released_pairs(own, c, count, freed, rank_tolerance, repeated_pairing, pairing, wrenches, twists, exists,
                          scratch):
            return -1.0
        for i in range(count):
            if exists[i]:
                value = min(value, coefficient(wrenches, twists, i, points, index, c, threshold[index], rounded_couple))
        start += count
    return value if value < np.inf else 0.0


@njit(_SIGNATURE, nogil=True, cache=True, error_model="numpy", fastmath=FASTMATH)
def constraint_kernel(constraints, wrench_start, own_counts, common, points, wrenches, submechanisms, members,
                      threshold, motion_tolerance, rank_tolerance, rounded_couple, repeated_pairing, instantaneous,
                      per_set):
    """Instantaneous DOF and :math:`CTI_N` of every non-redundant actuator set of N configurations.

    Parameters (N configurations, C chains, K constraint wrenches in all, S sets of n actuators, L subsystems)
    ----------
    constraints (N, K, 6) : every chain's constraint wrenches in working coordinates (orthonormal per chain, as
        :func:`screwkit.screw.constraints.chain_constraint_wrenches`), chains in consecutive rows.
    wrench_start (C + 1,) : the first row of each chain's constraint wrenches, and K.
    own_counts (C,), common : the constraint plan's own wrenches per chain and common wrenches.
    points (N, C, 6) : each chain's platform joint in working coordinates and the direction along which it may be
        drawn anywhere (:func:`screwkit.screw.algebra.joint_lines`; zero for a point).
    wrenches (N, a, 6) : unit actuation wrenches in working coordinates.
    submechanisms (S, n) : the actuator sets; members (L, C) : 1 for the chains of each subsystem.
    threshold (N,) : the singularity threshold in working coordinates (p / L).
    motion_tolerance, rank_tolerance, rounded_couple, repeated_pairing : MOTION_SPACE_TOLERANCE, RANK_TOLERANCE,
        ROUNDED_COUPLE, REPEATED_PAIRING.
    instantaneous (N,), per_set (N, S) : out, six minus the rank of all constraint wrenches, and the best
        :math:`CTI_{N,L}` over the subsystems (before constraint singularities are zeroed); NaN where a chain's
        pairs have a repeated singular value, whose worst rotation the numpy code finds.
    """
    count = wrench_start[wrench_start.shape[0] - 1]
    columns = np.empty((max(count, 6), 6))
    own = np.empty((own_counts.shape[0], 6, 6))
    shared, total, rows, reflectors = np.empty((6, 6)), np.empty((6, 6)), np.empty((6, 6)), np.empty((6, 6))
    scratch = (np.empty((6, 6)), np.empty(6), np.empty(6, dtype=np.int64), np.empty(6), np.empty((6, 6)))
    work = (np.empty(6, dtype=np.int64), np.empty((6, 6)), np.empty((max(np.sum(own_counts), 1), 6)),
            np.empty((6, 6)), np.empty((6, 6)), np.empty(6), np.empty((6, 6)), np.empty((6, 6)), np.empty((6, 6)),
            np.empty(6, dtype=np.bool_), scratch)
    held = submechanisms.shape[1] + common
    for index in range(constraints.shape[0]):
        instantaneous[index] = 6 - constraint_rank(constraints, index, count, motion_tolerance, columns, scratch)
        own_wrenches(constraints, index, wrench_start, own_counts, common, own, shared, columns, total, scratch)
        for s in range(submechanisms.shape[0]):
            volume = held_rows(wrenches, index, submechanisms, s, shared, common, rows)
            held_volume = complement(rows, held, reflectors, work[1])
            own_in_complement(own, own_counts, work[1], 6 - held, work[2])
            best = 0.0
            if held_volume > 0.0:
                for subsystem in range(members.shape[0]):
                    value = subsystem_cti(index, own_counts, members, subsystem, own, points, threshold,
                                          (volume, held_volume, 6 - held, rank_tolerance, rounded_couple,
                                           repeated_pairing), work)
                    best = np.nan if value < 0.0 or np.isnan(best) else max(best, value)
            per_set[index, s] = best
