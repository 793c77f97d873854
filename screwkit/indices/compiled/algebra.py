"""Compiled kernels of :func:`screwkit.indices.analysis.analyze`: shared helpers and the block layout.

The indices of a chunk of configurations come from numba functions in their own modules, so that
a first run compiles them at once in several processes (:mod:`screwkit.common.compiling`) and a
mechanism compiles only those it needs: :func:`screwkit.indices.compiled.wrenches.wrench_kernel` moves the
configurations into working coordinates and derives the actuation wrenches of chains with n joint
DoFs; :func:`screwkit.indices.compiled.gram.gram_kernel` those of the other chains (a Gram solve), for
mechanisms that have such chains; :func:`screwkit.indices.compiled.outputs.output_kernel` the ITIs, the
output twists and OTIs of every non-redundant submechanism, then the LMTI, F_Oj and the
mutual-interference actuators, exactly as documented in :func:`screwkit.indices.analysis.analyze`
(:func:`screwkit.indices.compiled.driver.run_kernels` runs them in turn). They take the configurations 64
at a time (:data:`BLOCK`): every per-configuration quantity has a last "lane" axis over the 64
configurations and every step loops over the lanes innermost, so that the compiler vectorises
the algebra across configurations. What the first hands to the others is
kept per block (arrays ``(blocks, ..., BLOCK)``, see :func:`carry_arrays`).

Screws are ordered (omega, v) for twists and (f, m) for wrenches. Inside the kernels every
configuration is in its own *working coordinates*: about the centroid ``c`` of the platform
joints, with lengths in units of ``L``, the RMS distance of all the configuration's joint points
from ``c`` (a twist (omega, v) becomes (omega, v_c / L), a point p becomes (p - c) / L, a wrench
(f, m) becomes (f, m_c / L)). Every tolerance is then compared with dimensionless numbers, so
that no decision depends on the length unit, the scale of the mechanism or the world frame; the
singularity threshold *p*, a length, is compared as p / L. ``c`` and ``L`` are computed per
configuration, exactly as :func:`screwkit.screw.motion.working_coordinates` does for the
motion-space bases it passes in; outputs go back to world units and frame. The tolerances come
in as arguments (named in :mod:`screwkit.common.tolerances`); those of the characteristic points
(``AXIS_PARALLEL``, ``ZERO_PITCH``, ``SAME_POINT``) are read as constants of that module, which the kernels' cache
stamp covers (:mod:`screwkit.common.jit`).
"""

from __future__ import annotations

import numpy as np

from screwkit.common.fastmath import FASTMATH
from screwkit.common.jit import njit
from screwkit.common.tolerances import AXIS_PARALLEL
from screwkit.indices.compiled.jacobi import rotate_symmetric

__all__ = ["BLOCK", "KERNEL_BATCH", "CARRY_SIGNATURE", "LEADING_PIVOT_RATIO", "PSEUDO_INVERSE_RCOND",
           "add_swapped_combination", "carry_arrays", "cross", "crossing_point", "motion_lanes_of", "null_vector",
           "null_vectors_lanes", "pseudo_inverse", "power_coefficient", "shifted_basis_lanes", "solve", "working_point",
           "working_twist"]

BLOCK = 64  # configurations gathered batch-first at a time
KERNEL_BATCH = 32 * BLOCK
"""Configurations the two kernels take at a time from a chunk: the first stage's per-block results
for them (:func:`carry_arrays`, about 2 kB per configuration of an 8-leg hexapod) stay in cache."""


@njit(cache=True, error_model="numpy", fastmath=FASTMATH)
def cross(a0, a1, a2, b0, b1, b2):
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


@njit(cache=True, error_model="numpy", fastmath=FASTMATH)
def crossing_point(p0, p1, p2, q0, q1, q2, f0, f1, f2, force_sq, u0, u1, u2):
    """The point of a force's axis nearest to the line through p along u (as
    :func:`screwkit.screw.algebra.nearest_on_axis`): q, p's projection on the axis of the force f (|f|^2
    ``force_sq``), moved along f; q itself when u is zero or parallel to f."""
    direction_sq = u0 * u0 + u1 * u1 + u2 * u2
    if direction_sq > 0.0:
        dot = f0 * u0 + f1 * u1 + f2 * u2
        sine_sq = 1.0 - dot * dot / (force_sq * direction_sq)
        if sine_sq > AXIS_PARALLEL:
            shift = dot * (u0 * (q0 - p0) + u1 * (q1 - p1) + u2 * (q2 - p2)) / (force_sq * direction_sq * sine_sq)
            return q0 + shift * f0, q1 + shift * f1, q2 + shift * f2
    return q0, q1, q2


@njit(cache=True, error_model="numpy", fastmath=FASTMATH)
def arm_square(w0, w1, w2, v0, v1, v2, p0, p1, p2, pitch):
    """|v + omega x p + h omega|^2: the squared moment arm of a wrench of pitch h through p on the
    twist (omega, v) (|A o T|_max of Eq. 5 for a unit force)."""
    x0, x1, x2 = cross(w0, w1, w2, p0, p1, p2)
    a0 = v0 + x0 + pitch * w0
    a1 = v1 + x1 + pitch * w1
    a2 = v2 + x2 + pitch * w2
    return a0 * a0 + a1 * a1 + a2 * a2


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def null_vector(rows, size, out, work, columns):
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
        out[0], out[1], out[2] = cross(rows[0, 0], rows[0, 1], rows[0, 2], rows[1, 0], rows[1, 1], rows[1, 2])
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
conditioned block) get their null vector from :func:`null_vector`'s full pivoting instead."""


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def eliminate_lanes(work, size, width, pivot, determinant, scratch, smallest, largest):
    """Gaussian elimination with partial pivoting of the leading (size-1) x (size-1) block of ``work``, every lane
    at once, the last column carried along: pivot choices and row swaps as per-lane blends. ``determinant``
    receives the block's determinant, ``smallest`` and ``largest`` its smallest and largest pivot magnitudes."""
    m = size - 1
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


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def back_substitute_lanes(work, size, width, out, determinant, scratch):
    """out[:size, r] = determinant[r] (y, 1), U y = -u by back substitution (U the eliminated leading block of
    ``work``, u its last column), every lane at once."""
    m = size - 1
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


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def redo_poorly_conditioned(rows, size, width, out, smallest, largest, scalar_rows, scalar_work, scalar_columns,
                            scalar_out):
    """Lanes whose leading block is poorly conditioned (smallest pivot not above :data:`LEADING_PIVOT_RATIO` of the
    largest, or zero) get ``out[:, r]`` from :func:`null_vector`'s full pivoting, one by one."""
    m = size - 1
    for r in range(width):
        if not smallest[r] > LEADING_PIVOT_RATIO * largest[r]:  # poorly conditioned (or zero) block
            for i in range(m):
                for j in range(size):
                    scalar_rows[i, j] = rows[i, j, r]
            null_vector(scalar_rows, size, scalar_out, scalar_work, scalar_columns)
            for q in range(size):
                out[q, r] = scalar_out[q]


@njit(cache=True, error_model="numpy", fastmath=FASTMATH)
def null_vectors_lanes(rows, size, width, out, work, pivot, determinant, scratch, smallest, largest,
                        scalar_rows, scalar_work, scalar_columns, scalar_out):
    """out[:size, r] = generalised cross product of the rows rows[:size-1, :size, r], every lane r at once.

    The vector of :func:`null_vector` (``out[q] = (-1)^(size-1+q) det(rows without column q)``),
    computed lane-innermost so that the compiler vectorises it across configurations: Gaussian
    elimination with partial pivoting of the leading (size-1) x (size-1) block, the last column
    carried along (pivot choices and row swaps as per-lane blends, :func:`eliminate_lanes`); then ``out`` is
    ``det(leading block)`` times the null vector whose last entry is 1, by back substitution
    (:func:`back_substitute_lanes`). Lanes whose leading block is poorly conditioned (smallest pivot below
    :data:`LEADING_PIVOT_RATIO` of the largest) are redone one by one with :func:`null_vector`
    (:func:`redo_poorly_conditioned`). ``work`` (size-1, size, BLOCK), ``pivot``, ``determinant``, ``scratch``,
    ``smallest``, ``largest`` (BLOCK) and the ``scalar_*`` arrays are scratch.
    """
    for i in range(size - 1):
        for j in range(size):
            for r in range(width):
                work[i, j, r] = rows[i, j, r]
    eliminate_lanes(work, size, width, pivot, determinant, scratch, smallest, largest)
    back_substitute_lanes(work, size, width, out, determinant, scratch)
    redo_poorly_conditioned(rows, size, width, out, smallest, largest, scalar_rows, scalar_work, scalar_columns,
                            scalar_out)


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def solve(matrix, size, rhs, out, work, pivot_tolerance):
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


PSEUDO_INVERSE_RCOND = 1e-15
"""Eigenvalues at or below this fraction of the largest count as zero in :func:`pseudo_inverse`
(numpy's ``pinv`` default)."""


@njit(cache=True, error_model="numpy", fastmath=FASTMATH)
def pseudo_inverse(matrix, size, out, vectors, values):
    """out[:size, :size] = the Moore-Penrose pseudo-inverse of the symmetric matrix[:size, :size].

    Cyclic Jacobi rotations (:func:`screwkit.indices.compiled.jacobi.rotate_symmetric`) diagonalise a copy
    (``matrix = V diag(values) V^T``); eigenvalues at or below :data:`PSEUDO_INVERSE_RCOND` times the largest in
    magnitude count as zero, as in ``numpy.linalg.pinv`` (for a symmetric matrix its singular values are the
    eigenvalues' magnitudes). Written out rather than ``np.linalg.pinv``, whose compiled LAPACK wrapper alone
    took about 3 s of the kernel's first compilation. ``vectors`` (at least size x size) and
    ``values`` (size) are scratch; returns ``out``.
    """
    for i in range(size):
        for j in range(size):
            out[i, j] = matrix[i, j]
            vectors[i, j] = 1.0 if i == j else 0.0
    for _ in range(100):
        off = 0.0
        diagonal = 0.0
        for i in range(size):
            diagonal += out[i, i] * out[i, i]
            for j in range(i + 1, size):
                off += out[i, j] * out[i, j]
        if off <= 1e-36 * diagonal or off == 0.0:
            break
        for p in range(size - 1):
            for q in range(p + 1, size):
                if out[p, q] != 0.0:
                    rotate_symmetric(out, size, vectors, p, q)
    largest = 0.0
    for i in range(size):
        values[i] = out[i, i]
        largest = max(largest, abs(values[i]))
    cutoff = PSEUDO_INVERSE_RCOND * largest
    for i in range(size):
        values[i] = 1.0 / values[i] if abs(values[i]) > cutoff else 0.0
    for i in range(size):
        for j in range(size):
            total = 0.0
            for k in range(size):
                total += vectors[i, k] * values[k] * vectors[j, k]
            out[i, j] = total
    return out


@njit(cache=True, error_model="numpy", fastmath=FASTMATH)
def working_twist(all_twists, index, joint, c0, c1, c2, inverse):
    """Joint ``joint``'s twist of configuration ``index`` in working coordinates: (omega, (v + omega x c) / L)."""
    w0, w1, w2 = all_twists[index, joint, 0], all_twists[index, joint, 1], all_twists[index, joint, 2]
    x0, x1, x2 = cross(w0, w1, w2, c0, c1, c2)
    return (w0, w1, w2, (all_twists[index, joint, 3] + x0) * inverse, (all_twists[index, joint, 4] + x1) * inverse,
            (all_twists[index, joint, 5] + x2) * inverse)


@njit(cache=True, error_model="numpy", fastmath=FASTMATH)
def working_point(all_points, index, joint, c0, c1, c2, inverse):
    """Joint ``joint``'s point of configuration ``index`` in working coordinates: (p - c) / L."""
    return ((all_points[index, joint, 0] - c0) * inverse, (all_points[index, joint, 1] - c1) * inverse,
            (all_points[index, joint, 2] - c2) * inverse)


@njit(cache=True, error_model="numpy", fastmath=FASTMATH)
def motion_lanes_of(basis, first_index, width, out):
    """out[q, k, r] = the motion basis of configuration first_index + r (one basis for all when ``basis`` has one)."""
    for q in range(basis.shape[1]):
        for k in range(6):
            if basis.shape[0] == 1:
                for r in range(width):
                    out[q, k, r] = basis[0, q, k]
            else:
                for r in range(width):
                    out[q, k, r] = basis[first_index + r, q, k]


@njit(cache=True, error_model="numpy", fastmath=FASTMATH)
def shifted_basis_lanes(motion_lanes, point, width, out):
    """out[q, :, r] = the motion basis twist q of lane r taken about point[:, r]: (omega, v + omega x point)."""
    for q in range(motion_lanes.shape[0]):
        for r in range(width):
            x0, x1, x2 = cross(motion_lanes[q, 0, r], motion_lanes[q, 1, r], motion_lanes[q, 2, r],
                               point[0, r], point[1, r], point[2, r])
            out[q, 0, r] = motion_lanes[q, 0, r]
            out[q, 1, r] = motion_lanes[q, 1, r]
            out[q, 2, r] = motion_lanes[q, 2, r]
            out[q, 3, r] = motion_lanes[q, 3, r] + x0
            out[q, 4, r] = motion_lanes[q, 4, r] + x1
            out[q, 5, r] = motion_lanes[q, 5, r] + x2


@njit(cache=True, error_model="numpy", fastmath=FASTMATH)
def add_swapped_combination(combination, shifted_basis, width, force):
    """force[:, r] += SWAP of sum_q combination[q, r] shifted_basis[q, :, r]: the wrench (f, m) reciprocal
    to the combined twists (omega, v), about the point the basis was shifted to."""
    for q in range(shifted_basis.shape[0]):
        for r in range(width):
            y = combination[q, r]
            force[0, r] += y * shifted_basis[q, 3, r]
            force[1, r] += y * shifted_basis[q, 4, r]
            force[2, r] += y * shifted_basis[q, 5, r]
            force[3, r] += y * shifted_basis[q, 0, r]
            force[4, r] += y * shifted_basis[q, 1, r]
            force[5, r] += y * shifted_basis[q, 2, r]


@njit(cache=True, error_model="numpy", fastmath=FASTMATH)
def power_coefficient(numerator, arm, reference, threshold):
    """|A o T| / |A o T|_max, zero when the moment arm is at or below threshold * |omega|.

    Homogeneous: ``arm``, ``numerator`` and ``threshold`` are in working coordinates (lengths in
    units of L), ``threshold`` being p / L.
    """
    if arm <= threshold * reference or arm <= 0.0:
        return 0.0
    value = abs(numerator) / arm
    return 1.0 if value > 1.0 else value


def carry_arrays(blocks: int, a: int, n: int) -> tuple[np.ndarray, ...]:
    """What :func:`~screwkit.indices.compiled.wrenches.wrench_kernel` hands to the later stages, per block of
    :data:`BLOCK` configurations, in working coordinates: each actuator's wrench before
    normalisation, about its platform joint d (blocks, a, 6, BLOCK); its chain's n - 1 passive rows
    against the motion basis about d (blocks, a, n - 1, n, BLOCK; for :mod:`screwkit.indices.compiled.null`,
    written only when n is not 3); the thresholds p / L, the lengths L (blocks, BLOCK) and the
    centroids c (blocks, 3, BLOCK). The later stages recompute what else they need of the joints
    (:func:`working_twist`, :func:`working_point`) rather than read it back."""
    return (np.empty((blocks, a, 6, BLOCK)), np.empty((blocks, a, max(n - 1, 1), n, BLOCK)),
            np.empty((blocks, BLOCK)), np.empty((blocks, BLOCK)), np.empty((blocks, 3, BLOCK)))


CARRY_SIGNATURE = ("float64[:, :, :, ::1], float64[:, :, :, :, ::1], float64[:, ::1], float64[:, ::1], "
                   "float64[:, :, ::1]")
"""numba types of :func:`carry_arrays`, in its order (part of every stage's one signature)."""

