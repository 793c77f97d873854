"""Compiled forward kinematics of chains: rotations as tuples of numbers, one configuration at a time.

:func:`leg_frames` is the forward kinematics of
:func:`screwkit.closure.chain_kinematics.chain_forward_kinematics` written out for one chain and
one configuration. :func:`chain_frames_kernel` runs it over a batch, for large batches, where the
numpy version's array operations per joint cost about five times more; the compiled closure
(:mod:`screwkit.closure.compiled.task`) runs it inside its iteration. Geometry comes packed as in
:func:`screwkit.closure.chain_kinematics.packed_chains`: tree joints of the chains stacked with
offsets, loop joints coded 0 fixed, 1 revolute, 2 prismatic, 3 universal, 4 spherical.
"""

from __future__ import annotations

import math

from screwkit.common.jit import njit

# Rotations are 9-tuples (row-major) and vectors 3-tuples: values, not arrays, so that the
# forward kinematics allocates nothing and creates no array views.

@njit(cache=True, nogil=True, error_model="numpy")
def mul(a, b):
    """a @ b."""
    return (a[0] * b[0] + a[1] * b[3] + a[2] * b[6], a[0] * b[1] + a[1] * b[4] + a[2] * b[7],
            a[0] * b[2] + a[1] * b[5] + a[2] * b[8],
            a[3] * b[0] + a[4] * b[3] + a[5] * b[6], a[3] * b[1] + a[4] * b[4] + a[5] * b[7],
            a[3] * b[2] + a[4] * b[5] + a[5] * b[8],
            a[6] * b[0] + a[7] * b[3] + a[8] * b[6], a[6] * b[1] + a[7] * b[4] + a[8] * b[7],
            a[6] * b[2] + a[7] * b[5] + a[8] * b[8])


@njit(cache=True, nogil=True, error_model="numpy")
def mul_transposed(a, b):
    """a @ b^T."""
    return (a[0] * b[0] + a[1] * b[1] + a[2] * b[2], a[0] * b[3] + a[1] * b[4] + a[2] * b[5],
            a[0] * b[6] + a[1] * b[7] + a[2] * b[8],
            a[3] * b[0] + a[4] * b[1] + a[5] * b[2], a[3] * b[3] + a[4] * b[4] + a[5] * b[5],
            a[3] * b[6] + a[4] * b[7] + a[5] * b[8],
            a[6] * b[0] + a[7] * b[1] + a[8] * b[2], a[6] * b[3] + a[7] * b[4] + a[8] * b[5],
            a[6] * b[6] + a[7] * b[7] + a[8] * b[8])


@njit(cache=True, nogil=True, error_model="numpy")
def apply(a, x, y, z):
    """a @ (x, y, z)."""
    return (a[0] * x + a[1] * y + a[2] * z, a[3] * x + a[4] * y + a[5] * z, a[6] * x + a[7] * y + a[8] * z)


@njit(cache=True, nogil=True, error_model="numpy")
def skew_terms(x, y, z, a, b):
    """I + a [v] + b [v]^2 for v = (x, y, z)."""
    return (1.0 - b * (y * y + z * z), -a * z + b * x * y, a * y + b * x * z,
            a * z + b * x * y, 1.0 - b * (x * x + z * z), -a * x + b * y * z,
            -a * y + b * x * z, a * x + b * y * z, 1.0 - b * (x * x + y * y))


@njit(cache=True, nogil=True, error_model="numpy")
def rotation_about(x, y, z, angle):
    """Rot(unit axis (x, y, z), angle) (Rodrigues)."""
    return skew_terms(x, y, z, math.sin(angle), 1.0 - math.cos(angle))


@njit(cache=True, nogil=True, error_model="numpy")
def exp_map(x, y, z):
    """Exponential map of a rotation vector (as :func:`screwkit.common.rotations.rotation_from_rotation_vector`)."""
    angle = math.sqrt(x * x + y * y + z * z)
    if angle < 1e-6:
        return skew_terms(x, y, z, 1.0 - angle * angle / 6.0, 0.5 - angle * angle / 24.0)
    return skew_terms(x, y, z, math.sin(angle) / angle, (1.0 - math.cos(angle)) / (angle * angle))


@njit(cache=True, nogil=True, error_model="numpy")
def log_map(r):
    """Logarithm map, angle in [0, pi] (as :func:`screwkit.common.rotations.rotation_vector_from_rotation`)."""
    cosine = min(1.0, max(-1.0, (r[0] + r[4] + r[8] - 1.0) / 2.0))
    v0, v1, v2 = r[7] - r[5], r[2] - r[6], r[3] - r[1]
    angle = math.atan2(0.5 * math.sqrt(v0 * v0 + v1 * v1 + v2 * v2), cosine)
    if angle <= math.pi - 1e-3:
        scale = 0.5 + angle * angle / 12.0 if angle < 1e-4 else angle / (2.0 * math.sin(angle))
        return scale * v0, scale * v1, scale * v2
    # near pi: the axis from the column of the symmetric part with the largest diagonal
    column = 0
    if r[4] > r[0] and r[4] >= r[8]:
        column = 1
    elif r[8] > r[0] and r[8] > r[4]:
        column = 2
    diagonal = (r[4 * column] - cosine) / (1.0 - cosine)
    norm = math.sqrt(max(diagonal, 1e-300)) * (1.0 - cosine)
    a0 = (0.5 * (r[column] + r[3 * column]) - (cosine if column == 0 else 0.0)) / norm
    a1 = (0.5 * (r[3 + column] + r[3 * column + 1]) - (cosine if column == 1 else 0.0)) / norm
    a2 = (0.5 * (r[6 + column] + r[3 * column + 2]) - (cosine if column == 2 else 0.0)) / norm
    sign = -angle if a0 * v0 + a1 * v1 + a2 * v2 < 0.0 else angle
    return sign * a0, sign * a1, sign * a2


@njit(cache=True, nogil=True, error_model="numpy")
def matrix_at(array, index):
    """array[index] (3, 3) as a 9-tuple."""
    return (array[index, 0, 0], array[index, 0, 1], array[index, 0, 2], array[index, 1, 0], array[index, 1, 1],
            array[index, 1, 2], array[index, 2, 0], array[index, 2, 1], array[index, 2, 2])



@njit(cache=True, nogil=True, error_model="numpy")
def leg_frames(c, values, tree_start, dof_start, joint_rot, joint_trans, joint_axis, joint_prism, leg_rot, leg_trans,
               loop_code, loop_axes, axes, points):
    """Forward kinematics of packed chain ``c`` at joint values ``values`` (all chains' DoFs, packed).

    Writes each joint DoF's axis and point (base frame) into rows ``dof_start[c]...`` of ``axes``
    and ``points``; returns the leg-side loop frame and the platform-side loop frame reached
    through the chain (rotation 9-tuples, translation 3-tuples).
    """
    rotation = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)
    t0 = t1 = t2 = 0.0
    dof = dof_start[c]
    for j in range(tree_start[c], tree_start[c + 1]):
        d0, d1, d2 = apply(rotation, joint_trans[j, 0], joint_trans[j, 1], joint_trans[j, 2])
        t0, t1, t2 = t0 + d0, t1 + d1, t2 + d2
        rotation = mul(rotation, matrix_at(joint_rot, j))
        a0, a1, a2 = apply(rotation, joint_axis[j, 0], joint_axis[j, 1], joint_axis[j, 2])
        axes[dof, 0], axes[dof, 1], axes[dof, 2] = a0, a1, a2
        q = values[dof]
        if joint_prism[j]:
            t0, t1, t2 = t0 + a0 * q, t1 + a1 * q, t2 + a2 * q
        else:
            rotation = mul(rotation, rotation_about(joint_axis[j, 0], joint_axis[j, 1], joint_axis[j, 2], q))
        points[dof, 0], points[dof, 1], points[dof, 2] = t0, t1, t2
        dof += 1
    d0, d1, d2 = apply(rotation, leg_trans[c, 0], leg_trans[c, 1], leg_trans[c, 2])
    t0, t1, t2 = t0 + d0, t1 + d1, t2 + d2
    rotation = mul(rotation, matrix_at(leg_rot, c))
    leg_rotation, leg_translation = rotation, (t0, t1, t2)
    code = loop_code[c]
    if code == 1 or code == 3:  # revolute; universal (two axes at one point)
        for k in range(1 if code == 1 else 2):
            a0, a1, a2 = apply(rotation, loop_axes[c, k, 0], loop_axes[c, k, 1], loop_axes[c, k, 2])
            axes[dof, 0], axes[dof, 1], axes[dof, 2] = a0, a1, a2
            points[dof, 0], points[dof, 1], points[dof, 2] = t0, t1, t2
            rotation = mul(rotation, rotation_about(loop_axes[c, k, 0], loop_axes[c, k, 1], loop_axes[c, k, 2],
                                                    values[dof]))
            dof += 1
    elif code == 2:  # prismatic: the point moves with the slider
        a0, a1, a2 = apply(rotation, loop_axes[c, 0, 0], loop_axes[c, 0, 1], loop_axes[c, 0, 2])
        axes[dof, 0], axes[dof, 1], axes[dof, 2] = a0, a1, a2
        q = values[dof]
        t0, t1, t2 = t0 + a0 * q, t1 + a1 * q, t2 + a2 * q
        points[dof, 0], points[dof, 1], points[dof, 2] = t0, t1, t2
        dof += 1
    elif code == 4:  # spherical: leg-side frame axes, rotation vector composed on the right
        for k in range(3):
            axes[dof + k, 0], axes[dof + k, 1], axes[dof + k, 2] = rotation[k], rotation[3 + k], rotation[6 + k]
            points[dof + k, 0], points[dof + k, 1], points[dof + k, 2] = t0, t1, t2
        rotation = mul(rotation, exp_map(values[dof], values[dof + 1], values[dof + 2]))
    return leg_rotation, leg_translation, rotation, (t0, t1, t2)


# Compiled on its first call (not when the module is imported for its helpers by the closure
# kernel); every caller passes C-contiguous writeable arrays of one set of types, so one compiled
# version serves every chain and loads from numba's disk cache.
@njit(cache=True, nogil=True, error_model="numpy")
def chain_frames_kernel(values, tree_start, dof_start, joint_rot, joint_trans, joint_axis, joint_prism, leg_rot,
                        leg_trans, loop_code, loop_axes, axes, points, leg_rotation, leg_translation, end_rotation,
                        end_translation):
    """:func:`leg_frames` of one packed chain (``loop_code.size == 1``) for every row of ``values`` (N, m).

    Outputs: ``axes``, ``points`` (N, m, 3); the leg-side loop frame ``leg_rotation`` (N, 3, 3),
    ``leg_translation`` (N, 3); the platform-side loop frame reached ``end_rotation``,
    ``end_translation``.
    """
    for n in range(values.shape[0]):
        leg_r, leg_t, end_r, end_t = leg_frames(0, values[n], tree_start, dof_start, joint_rot, joint_trans,
                                                joint_axis, joint_prism, leg_rot, leg_trans, loop_code, loop_axes,
                                                axes[n], points[n])
        for i in range(3):
            leg_translation[n, i] = leg_t[i]
            end_translation[n, i] = end_t[i]
            for k in range(3):
                leg_rotation[n, i, k] = leg_r[3 * i + k]
                end_rotation[n, i, k] = end_r[3 * i + k]
