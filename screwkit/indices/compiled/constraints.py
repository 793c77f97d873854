"""Compiled constraint transmission index (CTI) of lower-mobility mechanisms, configuration by configuration.

:func:`constraint_kernel` does for a chunk of configurations what :func:`screwkit.screw.constraints.constraint_indices`
does with numpy (the readable reference, which ``tests/test_constraint_kernel.py`` holds it to) for mechanisms whose
constraint subsystems are *square*: the ``n`` actuation wrenches of a set, the own constraint wrenches of the
chains of a subsystem and the common ones are six wrenches (the numpy branch of one inverse; overlapping own
wrenches keep the numpy path). Per configuration: the rank of all the chains' constraint wrenches (the
instantaneous DOF, one-sided Jacobi rotations, :func:`constraint_rank`); the common constraint wrenches and each
chain's own ones (:func:`own_wrenches`); then, for every actuator set and subsystem, the six wrenches' LU
factorisation (:func:`factor`: determinant, regularity), the twists freed by releasing each chain (columns of the
inverse, :func:`freed_twists`), the principal pairs of wrench and freed twist (:func:`released_pairs`) and their
power coefficients (:func:`coefficient`), the lowest of which is :math:`CTI_{N,L}`. numpy takes several LAPACK
calls and a dozen broadcast passes per set and subsystem; here one configuration of a 4-leg Delta (16 systems)
takes a few microseconds.

Values agree with numpy's to rounding: the freed twists and the principal pairs are spans, found here by other
but equally stable means (an orthonormal basis by Gram-Schmidt rather than Householder QR, Jacobi rather than
LAPACK's SVD), and every power coefficient is independent of the basis chosen within them and of signs.
"""

from __future__ import annotations

import numpy as np

from screwkit.common.fastmath import FASTMATH
from screwkit.common.jit import njit
from screwkit.indices.compiled.jacobi import NULL_COLUMN, singular_vectors, symmetric_eigen, unit_columns

__all__ = ["constraint_kernel"]

# The one signature: every array C-contiguous.
_SIGNATURE = ("void(float64[:, :, ::1], int64[::1], int64[::1], int64, float64[:, :, ::1], float64[:, :, ::1], "
              "int64[:, ::1], int64[:, ::1], float64[::1], float64, float64, float64, int64[::1], float64[:, ::1])")


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def constraint_rank(constraints, index, count, tolerance, columns, scratch):
    """Rank of the unit constraint wrenches constraints[index, :count]: singular values above ``tolerance`` times
    the largest (``numpy.linalg.svd`` of the unit rows). ``scratch``: vectors (6, 6), norms (6), order (6, int),
    singular (6), right (6, 6)."""
    vectors, norms, order, singular, right = scratch
    unit_columns(constraints, index, 0, count, columns)
    singular_vectors(columns, count, 6, NULL_COLUMN * NULL_COLUMN * count, vectors, norms, order, singular, right)
    rank = 0
    for i in range(6):
        if singular[i] > tolerance * max(singular[0], 1e-300):
            rank += 1
    return rank


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


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
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
                along = 0.0
                for p in range(6):
                    along += columns[r, p] * shared[k, p]
                for p in range(6):
                    columns[r, p] -= along * shared[k, p]
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
def system_rows(wrenches, index, actuators, own, own_counts, members, shared, common, system):
    """system[:6] = the actuation wrenches of one actuator set, the own constraint wrenches of the chains of one
    subsystem (in chain order) and the common ones; returns the product of the rows' norms (the volume)."""
    row = 0
    for k in range(actuators.shape[0]):
        for p in range(6):
            system[row, p] = wrenches[index, actuators[k], p]
        row += 1
    for c in range(own_counts.shape[0]):
        if members[c]:
            for r in range(own_counts[c]):
                for p in range(6):
                    system[row, p] = own[c, r, p]
                row += 1
    for r in range(common):
        for p in range(6):
            system[row, p] = shared[r, p]
        row += 1
    volume = 1.0
    for r in range(6):
        total = 0.0
        for p in range(6):
            total += system[r, p] * system[r, p]
        volume *= np.sqrt(total)
    return volume


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def factor(system, permutation):
    """LU factorisation with partial pivoting of the 6 x 6 ``system`` in place (``P system = L U``, the row
    permutation in ``permutation``), as LAPACK's getrf; returns the determinant (zero at a zero pivot)."""
    determinant = 1.0
    for i in range(6):
        permutation[i] = i
    for k in range(6):
        pivot, best = k, abs(system[k, k])
        for i in range(k + 1, 6):
            if abs(system[i, k]) > best:
                pivot, best = i, abs(system[i, k])
        if best == 0.0:
            return 0.0
        if pivot != k:
            for j in range(6):
                system[k, j], system[pivot, j] = system[pivot, j], system[k, j]
            permutation[k], permutation[pivot] = permutation[pivot], permutation[k]
            determinant = -determinant
        determinant *= system[k, k]
        for i in range(k + 1, 6):
            system[i, k] /= system[k, k]
            for j in range(k + 1, 6):
                system[i, j] -= system[i, k] * system[k, j]
    return determinant


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def freed_twists(lu, permutation, start, size, freed, column):
    """freed[:, j] (j < size) = column start + j of the inverse of the factored system, its halves swapped: the
    twist reciprocal to every row but row start + j (chain's wrench j). Orthonormalised (Gram-Schmidt, twice)
    when the chain holds several (the same span, as the numpy path's QR)."""
    for j in range(size):
        for i in range(6):  # L y = P e_(start + j)
            total = 1.0 if permutation[i] == start + j else 0.0
            for k in range(i):
                total -= lu[i, k] * column[k]
            column[i] = total
        for i in range(5, -1, -1):  # U x = y
            total = column[i]
            for k in range(i + 1, 6):
                total -= lu[i, k] * column[k]
            column[i] = total / lu[i, i]
        for i in range(3):
            freed[i, j] = column[i + 3]
            freed[i + 3, j] = column[i]
    if size > 1:
        for j in range(size):
            for _ in range(2):
                for i in range(j):
                    along = 0.0
                    for k in range(6):
                        along += freed[k, i] * freed[k, j]
                    for k in range(6):
                        freed[k, j] -= along * freed[k, i]
            norm = 0.0
            for k in range(6):
                norm += freed[k, j] * freed[k, j]
            norm = np.sqrt(norm)
            for k in range(6):
                freed[k, j] = freed[k, j] / norm if norm > 0.0 else 0.0


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def released_pairs(own, size, freed, rank_tolerance, pairing, wrenches, twists, exists, scratch):
    """The principal pairs of a chain's own wrenches own[:size] and the twists freed[:, :size] their release frees
    (as ``_released_pairs``): wrenches U^T C and twists F V from the singular vectors of the pairing
    ``C o F = U S V^T``; ``exists[i]``: singular value i above ``rank_tolerance`` times the largest. One wrench
    and one freed twist are their own pair."""
    vectors, norms, order, singular, right = scratch
    if size == 1:
        for p in range(6):
            wrenches[0, p] = own[0, p]
            twists[0, p] = freed[p, 0]
        exists[0] = True
        return
    frobenius = 0.0
    for k in range(size):
        for j in range(size):
            total = 0.0
            for p in range(3):
                total += own[k, p] * freed[p + 3, j] + own[k, p + 3] * freed[p, j]
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
                wrench += pairing[k, order[i]] * inverse * own[k, p]
                twist += freed[p, k] * right[i, k]
            wrenches[i, p] = wrench
            twists[i, p] = twist


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def coefficient(wrench, twist, point, threshold, pure_couple):
    """Power coefficient of the unit constraint wrench on the twist (as ``_coefficient``), its characteristic
    point ``point`` projected on the wrench's axis (as ``_project_on_axis``; a couple: |m . omega| / |m||omega|)."""
    f0, f1, f2, m0, m1, m2 = wrench[0], wrench[1], wrench[2], wrench[3], wrench[4], wrench[5]
    w0, w1, w2, v0, v1, v2 = twist[0], twist[1], twist[2], twist[3], twist[4], twist[5]
    numerator = abs(f0 * v0 + f1 * v1 + f2 * v2 + m0 * w0 + m1 * w1 + m2 * w2)
    norm_sq = f0 * f0 + f1 * f1 + f2 * f2
    p0, p1, p2 = point[0], point[1], point[2]
    if norm_sq > 0.0:  # the point of the axis nearest the chain's platform joint
        c0, c1, c2 = (f1 * m2 - f2 * m1) / norm_sq, (f2 * m0 - f0 * m2) / norm_sq, (f0 * m1 - f1 * m0) / norm_sq
        along = ((p0 - c0) * f0 + (p1 - c1) * f1 + (p2 - c2) * f2) / norm_sq
        p0, p1, p2 = c0 + along * f0, c1 + along * f1, c2 + along * f2
    force_norm = np.sqrt(norm_sq)
    moment_norm = np.sqrt(m0 * m0 + m1 * m1 + m2 * m2)
    omega_norm = np.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
    if force_norm > pure_couple * moment_norm:
        pitch = (f0 * m0 + f1 * m1 + f2 * m2) / (force_norm * force_norm)
        a0 = v0 + (w1 * p2 - w2 * p1) + pitch * w0
        a1 = v1 + (w2 * p0 - w0 * p2) + pitch * w1
        a2 = v2 + (w0 * p1 - w1 * p0) + pitch * w2
        arm, scale, reference = np.sqrt(a0 * a0 + a1 * a1 + a2 * a2), force_norm, omega_norm
    else:
        arm, scale, reference = omega_norm, moment_norm, 0.0
    if arm <= threshold * reference or arm * scale <= 0.0:
        return 0.0
    return min(numerator / (arm * scale), 1.0)


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def subsystem_cti(index, system, own_counts, members, own, points, threshold, tolerances, work):
    """:math:`CTI_{N,L}` of one configuration, actuator set and subsystem, its six wrenches in ``system`` (of
    product of norms ``volume``): zero when they do not span every wrench, else the lowest power coefficient of a
    released constraint wrench on the twist it frees (as ``_subsystem_cti``)."""
    volume, rank_tolerance, pure_couple, start = tolerances
    permutation, freed, column, pairing, wrenches, twists, exists, scratch = work
    determinant = factor(system, permutation)
    if not abs(determinant) > rank_tolerance * volume:
        return 0.0
    value = np.inf
    for c in range(own_counts.shape[0]):
        size = own_counts[c]
        if not members[c] or size == 0:
            continue
        freed_twists(system, permutation, start, size, freed, column)
        released_pairs(own[c], size, freed, rank_tolerance, pairing, wrenches, twists, exists, scratch)
        for i in range(size):
            if exists[i]:
                value = min(value, coefficient(wrenches[i], twists[i], points[index, c], threshold[index],
                                               pure_couple))
        start += size
    return value if value < np.inf else 0.0


@njit(_SIGNATURE, nogil=True, cache=True, error_model="numpy", fastmath=FASTMATH)
def constraint_kernel(constraints, wrench_start, own_counts, common, points, wrenches, submechanisms, members,
                      threshold, motion_tolerance, rank_tolerance, pure_couple, instantaneous, per_set):
    """Instantaneous DOF and :math:`CTI_N` of every non-redundant actuator set of N configurations.

    Parameters (N configurations, C chains, K constraint wrenches in all, S sets of n actuators, L subsystems)
    ----------
    constraints (N, K, 6) : every chain's constraint wrenches in working coordinates (orthonormal per chain, as
        :func:`screwkit.screw.constraints.chain_constraint_wrenches`), chains in consecutive rows.
    wrench_start (C + 1,) : the first row of each chain's constraint wrenches, and K.
    own_counts (C,), common : the constraint plan's own wrenches per chain and common wrenches.
    points (N, C, 3) : each chain's platform joint in working coordinates.
    wrenches (N, a, 6) : unit actuation wrenches in working coordinates.
    submechanisms (S, n) : the actuator sets; members (L, C) : 1 for the chains of each subsystem.
    threshold (N,) : the singularity threshold in working coordinates (p / L).
    motion_tolerance, rank_tolerance, pure_couple : MOTION_SPACE_TOLERANCE, RANK_TOLERANCE, PURE_COUPLE.
    instantaneous (N,), per_set (N, S) : out, six minus the rank of all constraint wrenches, and the best
        :math:`CTI_{N,L}` over the subsystems (before constraint singularities are zeroed).
    """
    count = wrench_start[wrench_start.shape[0] - 1]
    columns = np.empty((max(count, 6), 6))
    own = np.empty((own_counts.shape[0], 6, 6))
    shared, total, system = np.empty((6, 6)), np.empty((6, 6)), np.empty((6, 6))
    scratch = (np.empty((6, 6)), np.empty(6), np.empty(6, dtype=np.int64), np.empty(6), np.empty((6, 6)))
    work = (np.empty(6, dtype=np.int64), np.empty((6, 6)), np.empty(6), np.empty((6, 6)), np.empty((6, 6)),
            np.empty((6, 6)), np.empty(6, dtype=np.bool_), scratch)
    n = submechanisms.shape[1]
    for index in range(constraints.shape[0]):
        instantaneous[index] = 6 - constraint_rank(constraints, index, count, motion_tolerance, columns, scratch)
        own_wrenches(constraints, index, wrench_start, own_counts, common, own, shared, columns, total, scratch)
        for s in range(submechanisms.shape[0]):
            best = 0.0
            for subsystem in range(members.shape[0]):
                volume = system_rows(wrenches, index, submechanisms[s], own, own_counts, members[subsystem], shared,
                                     common, system)
                best = max(best, subsystem_cti(index, system, own_counts, members[subsystem], own, points, threshold,
                                               (volume, rank_tolerance, pure_couple, n), work))
            per_set[index, s] = best
