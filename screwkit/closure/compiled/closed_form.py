"""Compiled spatial closed forms: U-P-S and R-U-S chains, one configuration at a time.

:func:`spatial_closed_form_kernel` is :meth:`screwkit.closure.analytic.SpatialClosedForm.solve`
written out for one configuration: the chain's loop target from the platform frame, the tree-joint
values of :class:`~screwkit.closure.analytic.LegVectorChain` (``ups``) or
:class:`~screwkit.closure.analytic.CrankRodChain` (``rus``) by the same Paden-Kahan subproblems,
the forward kinematics of :func:`screwkit.closure.compiled.frames.leg_frames` and the spherical
joint's rotation vector. The numpy version stays the reference (small batches, tests); this one
serves batches of :data:`screwkit.closure.chain_kinematics.COMPILED_FROM` configurations or more,
where the numpy version's array operations per chain cost several times more than the arithmetic.
:func:`joint_screws_kernel` then writes the joint screws of such batches into the component-major
block that the index kernels read (:func:`screwkit.closure.configuration_screws.chain_screws`).
"""

from __future__ import annotations

import math

import numpy as np

from screwkit.closure.compiled.frames import apply, leg_frames, log_map, matrix_at, mul, rotation_about
from screwkit.common.jit import njit
from screwkit.common.tolerances import BOUNDARY_ROUNDING

__all__ = ["spatial_closed_form_kernel", "joint_screws_kernel"]


@njit(cache=True, nogil=True, error_model="numpy")
def _dot(a0, a1, a2, b0, b1, b2):
    return a0 * b0 + a1 * b1 + a2 * b2


@njit(cache=True, nogil=True, error_model="numpy")
def _align(x, y, z, u0, u1, u2, v0, v1, v2):
    """Angle about unit axis (x, y, z) turning u towards v (Paden-Kahan 1, as ``rotation_angle_to_align``)."""
    du = _dot(u0, u1, u2, x, y, z)
    dv = _dot(v0, v1, v2, x, y, z)
    p0, p1, p2 = u0 - du * x, u1 - du * y, u2 - du * z
    q0, q1, q2 = v0 - dv * x, v1 - dv * y, v2 - dv * z
    c0, c1, c2 = y * p2 - z * p1, z * p0 - x * p2, x * p1 - y * p0
    return math.atan2(_dot(c0, c1, c2, q0, q1, q2), _dot(p0, p1, p2, q0, q1, q2))


@njit(cache=True, nogil=True, error_model="numpy")
def _pointing(parameters, first, second, s0, s1, s2, g0, g1, g2, branch):
    """Rot(first axis, q1) Rot(second axis, q2) s = g (Paden-Kahan 2, as ``two_axis_pointing``); axes at
    ``parameters[first:first + 3]`` and ``parameters[second:second + 3]``. Returns q1, q2 and the gap."""
    f0, f1, f2 = parameters[first], parameters[first + 1], parameters[first + 2]
    e0, e1, e2 = parameters[second], parameters[second + 1], parameters[second + 2]
    x0, x1, x2 = f1 * e2 - f2 * e1, f2 * e0 - f0 * e2, f0 * e1 - f1 * e0
    cosine = _dot(f0, f1, f2, e0, e1, e2)
    denominator = cosine * cosine - 1.0
    second_start = _dot(e0, e1, e2, s0, s1, s2)
    first_goal = _dot(f0, f1, f2, g0, g1, g2)
    alpha = (cosine * second_start - first_goal) / denominator
    beta = (cosine * first_goal - second_start) / denominator
    gamma_squared = ((_dot(s0, s1, s2, s0, s1, s2) - alpha * alpha - beta * beta - 2.0 * alpha * beta * cosine)
                     / _dot(x0, x1, x2, x0, x1, x2))
    gap = gamma_squared if gamma_squared < -1e-12 else 0.0
    gamma = branch * math.sqrt(max(gamma_squared, 0.0))
    i0 = alpha * f0 + beta * e0 + gamma * x0
    i1 = alpha * f1 + beta * e1 + gamma * x1
    i2 = alpha * f2 + beta * e2 + gamma * x2
    return (_align(f0, f1, f2, i0, i1, i2, g0, g1, g2), _align(e0, e1, e2, s0, s1, s2, i0, i1, i2), gap)


@njit(cache=True, nogil=True, error_model="numpy")
def _wrap(angle):
    """Angle in (-pi, pi] (as ``wrap_angle``)."""
    wrapped = angle - (2.0 * math.pi) * np.rint(angle * (0.5 / math.pi))
    return wrapped + 2.0 * math.pi if wrapped <= -math.pi else wrapped


@njit(cache=True, nogil=True, error_model="numpy")
def _leg_vector(parameters, t0, t1, t2, universal_sign, slider_sign, values):
    """U-P-S tree values (``LegVectorChain._tree_values``) into values[:3]; returns the gap."""
    l0, l1, l2 = t0 - parameters[0], t1 - parameters[1], t2 - parameters[2]
    distance = math.sqrt(_dot(l0, l1, l2, l0, l1, l2))
    inverse = slider_sign / (distance if distance > 0.0 else 1.0)
    first, second, gap = _pointing(parameters, 3, 6, parameters[9], parameters[10], parameters[11],
                                   l0 * inverse, l1 * inverse, l2 * inverse, universal_sign)
    values[0], values[1], values[2] = first, second, slider_sign * distance - parameters[12]
    return -gap * distance if distance > 0.0 else math.inf


@njit(cache=True, nogil=True, error_model="numpy")
def _crank_rod(parameters, t0, t1, t2, crank_sign, universal_sign, values):
    """R-U-S tree values (``CrankRodChain._tree_values``) into values[:3]; returns the gap."""
    a0, a1, a2 = parameters[3], parameters[4], parameters[5]
    v0, v1, v2 = parameters[6], parameters[7], parameters[8]
    along = _dot(v0, v1, v2, a0, a1, a2)
    w0, w1, w2 = along * a0, along * a1, along * a2
    p0, p1, p2 = v0 - w0, v1 - w1, v2 - w2
    b0, b1, b2 = a1 * p2 - a2 * p1, a2 * p0 - a0 * p2, a0 * p1 - a1 * p0
    o0, o1, o2 = t0 - parameters[0], t1 - parameters[1], t2 - parameters[2]
    cosine_coefficient = _dot(o0, o1, o2, p0, p1, p2)
    sine_coefficient = _dot(o0, o1, o2, b0, b1, b2)
    rod_length = parameters[18]
    constant = (0.5 * (_dot(o0, o1, o2, o0, o1, o2) + _dot(v0, v1, v2, v0, v1, v2) - rod_length * rod_length)
                - _dot(o0, o1, o2, w0, w1, w2))
    amplitude = math.hypot(cosine_coefficient, sine_coefficient)
    excess = abs(constant) - amplitude  # within rounding of the rod's reach: reached (as CrankRodChain)
    if excess <= BOUNDARY_ROUNDING * max(abs(constant), amplitude):
        excess = 0.0
    gap = excess / math.sqrt(_dot(p0, p1, p2, p0, p1, p2))
    ratio = constant / (amplitude if amplitude > 0.0 else 1.0)
    crank = (math.atan2(sine_coefficient, cosine_coefficient)
             + crank_sign * math.acos(min(1.0, max(-1.0, ratio))))
    turn = rotation_about(a0, a1, a2, crank)
    c0, c1, c2 = apply(turn, v0, v1, v2)
    d0, d1, d2 = t0 - parameters[0] - c0, t1 - parameters[1] - c1, t2 - parameters[2] - c2
    r0 = turn[0] * d0 + turn[3] * d1 + turn[6] * d2  # crank rotation transposed
    r1 = turn[1] * d0 + turn[4] * d1 + turn[7] * d2
    r2 = turn[2] * d0 + turn[5] * d1 + turn[8] * d2
    inverse = 1.0 / max(math.sqrt(_dot(r0, r1, r2, r0, r1, r2)), 1e-300)
    first, second, pointing_gap = _pointing(parameters, 9, 12, parameters[15], parameters[16], parameters[17],
                                            r0 * inverse, r1 * inverse, r2 * inverse, universal_sign)
    values[0], values[1], values[2] = _wrap(crank), first, second
    return gap if gap > 0.0 else -pointing_gap * rod_length


_SIGNATURE = ("void(int64, float64[::1], float64[::1], float64[:, :, ::1], float64[:, ::1], float64[:, ::1], "
              "float64[::1], int64[::1], int64[::1], float64[:, :, ::1], float64[:, ::1], float64[:, ::1], "
              "boolean[::1], float64[:, :, ::1], float64[:, ::1], int64[::1], float64[:, :, ::1], float64[:, ::1], "
              "float64[:, :, ::1], float64[:, :, ::1], float64[::1])")


@njit(_SIGNATURE, cache=True, nogil=True, error_model="numpy")
def spatial_closed_form_kernel(kind, parameters, branch, platform_rotation, platform_translation, loop_rotation,
                               loop_translation, tree_start, dof_start, joint_rot, joint_trans, joint_axis,
                               joint_prism, leg_rot, leg_trans, loop_code, loop_axes, values, axes, points, gap):
    """Joint values, axes, points and gap of one U-P-S or R-U-S chain closed by a spherical joint.

    Parameters (N configurations, m = 6 joint DoFs)
    ----------
    kind : 0 for a U-P-S chain, 1 for an R-U-S chain (the solver's ``kernel_kind``).
    parameters : the solver's attributes named by its ``kernel_parameters``, in order, flattened.
    branch (2,) : the working mode, as the solvers take it.
    platform_rotation (N, 3, 3), platform_translation (N, 3) : platform frames in the base frame.
    loop_rotation (3, 3), loop_translation (3,) : the platform-side loop frame in the platform frame.
    tree_start ... loop_axes : the chain packed by :func:`screwkit.closure.chain_kinematics.packed_chains`.
    Outputs: values (N, m), NaN where unreachable; axes, points (N, m, 3); gap (N,), 0 where reachable.
    """
    loop = (loop_rotation[0, 0], loop_rotation[0, 1], loop_rotation[0, 2], loop_rotation[1, 0], loop_rotation[1, 1],
            loop_rotation[1, 2], loop_rotation[2, 0], loop_rotation[2, 1], loop_rotation[2, 2])
    for index in range(values.shape[0]):
        rotation = matrix_at(platform_rotation, index)
        u0, u1, u2 = apply(rotation, loop_translation[0], loop_translation[1], loop_translation[2])
        t0 = platform_translation[index, 0] + u0
        t1 = platform_translation[index, 1] + u1
        t2 = platform_translation[index, 2] + u2
        row = values[index]
        if kind == 0:
            missed = _leg_vector(parameters, t0, t1, t2, branch[0], branch[1], row)
        else:
            missed = _crank_rod(parameters, t0, t1, t2, branch[0], branch[1], row)
        for k in range(3, row.shape[0]):
            row[k] = 0.0  # the spherical joint's axes do not depend on its values
        leg_rotation, _, _, _ = leg_frames(0, row, tree_start, dof_start, joint_rot, joint_trans, joint_axis,
                                           joint_prism, leg_rot, leg_trans, loop_code, loop_axes, axes[index],
                                           points[index])
        target = mul(rotation, loop)
        relative = (  # leg rotation transposed times the target
            leg_rotation[0] * target[0] + leg_rotation[3] * target[3] + leg_rotation[6] * target[6],
            leg_rotation[0] * target[1] + leg_rotation[3] * target[4] + leg_rotation[6] * target[7],
            leg_rotation[0] * target[2] + leg_rotation[3] * target[5] + leg_rotation[6] * target[8],
            leg_rotation[1] * target[0] + leg_rotation[4] * target[3] + leg_rotation[7] * target[6],
            leg_rotation[1] * target[1] + leg_rotation[4] * target[4] + leg_rotation[7] * target[7],
            leg_rotation[1] * target[2] + leg_rotation[4] * target[5] + leg_rotation[7] * target[8],
            leg_rotation[2] * target[0] + leg_rotation[5] * target[3] + leg_rotation[8] * target[6],
            leg_rotation[2] * target[1] + leg_rotation[5] * target[4] + leg_rotation[8] * target[7],
            leg_rotation[2] * target[2] + leg_rotation[5] * target[5] + leg_rotation[8] * target[8])
        row[3], row[4], row[5] = log_map(relative)
        gap[index] = missed
        if missed != 0.0:
            for k in range(row.shape[0]):
                row[k] = np.nan


_SCREWS_SIGNATURE = "void(float64[:, :, ::1], float64[:, :, ::1], boolean[::1], float64[:, :, :], float64[:, :, :])"


@njit(_SCREWS_SIGNATURE, cache=True, nogil=True, error_model="numpy")
def joint_screws_kernel(axes, points, prismatic, twists, twist_points):
    """Unit joint twists of one chain, as :func:`screwkit.closure.chain_kinematics.twists_from_axes_and_points`.

    axes, points (N, m, 3); prismatic (m,). Outputs, component-major: twists (6, m, N), ``(a, p x a)`` for a
    revolute joint and ``(0, a)`` for a prismatic one; twist_points (3, m, N), the points.
    """
    for joint in range(axes.shape[1]):
        slider = prismatic[joint]
        for index in range(axes.shape[0]):
            a0, a1, a2 = axes[index, joint, 0], axes[index, joint, 1], axes[index, joint, 2]
            p0, p1, p2 = points[index, joint, 0], points[index, joint, 1], points[index, joint, 2]
            twist_points[0, joint, index], twist_points[1, joint, index], twist_points[2, joint, index] = p0, p1, p2
            if slider:
                twists[0, joint, index] = twists[1, joint, index] = twists[2, joint, index] = 0.0
                twists[3, joint, index], twists[4, joint, index], twists[5, joint, index] = a0, a1, a2
            else:
                twists[0, joint, index], twists[1, joint, index], twists[2, joint, index] = a0, a1, a2
                twists[3, joint, index] = a2 * p1 - a1 * p2
                twists[4, joint, index] = a0 * p2 - a2 * p0
                twists[5, joint, index] = a1 * p0 - a0 * p1
