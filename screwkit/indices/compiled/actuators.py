"""Per-actuator stages of :func:`screwkit.indices.compiled.outputs.output_kernel`, on a block of configurations.

Each stage is one pass over every actuator, lane by lane (one lane per configuration of the block, working
coordinates): its joint's twist and points (:func:`actuator_joint_lanes`); its actuation wrench scaled to a unit
force (a unit moment for a pure couple) and signed to do positive work on its own joint, its ITI (Eq. 6) and the
characteristic point of its OTI (:func:`unit_wrench_lanes`); its row of the wrench matrix in motion coordinates
(:func:`wrench_matrix_rows`) and, when asked for, the wrench back in world units (:func:`world_wrenches`).
:func:`actuator_stage` runs them in turn.

These functions have no signature of their own: numba inlines them (``inline="always"``) into
:func:`~screwkit.indices.compiled.outputs.output_kernel`, which compiles as one function, with the results, bit for
bit, of the loops written out in it. Stages are passes over all the items of a block rather than functions called
per item: each inlined call costs reference counts on its array arguments, once per block this way. A change to
this module alone compiles the kernels anew (their cache stamp covers every kernel source: :mod:`screwkit.common.jit`).
"""

from __future__ import annotations

import numpy as np

from screwkit.common.fastmath import FASTMATH
from screwkit.common.jit import njit
from screwkit.common.tolerances import AXIS_PARALLEL, SAME_POINT, ZERO_PITCH
from screwkit.indices.compiled.algebra import (
    BLOCK,
    arm_square,
    cross,
    crossing_point,
    power_coefficient,
    working_point,
    working_twist,
)

__all__ = ["actuator_scratch", "actuator_stage"]


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def actuator_scratch(a, n):
    """The per-actuator lanes the later stages read, allocated once per call: each actuator's joint twist, points and
    the axes along which those points are arbitrary (a, 18, BLOCK), unit wrench (a, 6, BLOCK), OTI characteristic
    point (a, 3, BLOCK), pitch (0 for a couple), whether it has a force (else a couple), ITI, row of W in motion
    coordinates (a, n, BLOCK) and that row's norm."""
    return (np.empty((a, 18, BLOCK)), np.empty((a, 6, BLOCK)), np.empty((a, 3, BLOCK)), np.empty((a, BLOCK)),
            np.zeros((a, BLOCK), dtype=np.bool_), np.zeros((a, BLOCK)), np.zeros((a, n, BLOCK)),
            np.zeros((a, BLOCK)))


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def joint_line(all_twists, all_points, index, joint, first, last, inverse):
    """Joint ``joint``'s axis direction (as :func:`screwkit.screw.reference.joint_line`): zero for a prismatic joint
    and for one drawn at the same point as a neighbour (``first`` to ``last``, its chain) with another axis."""
    w0, w1, w2 = all_twists[index, joint, 0], all_twists[index, joint, 1], all_twists[index, joint, 2]
    for other in (joint - 1, joint + 1):
        if other < first or other > last:
            continue
        g0 = (all_points[index, other, 0] - all_points[index, joint, 0]) * inverse
        g1 = (all_points[index, other, 1] - all_points[index, joint, 1]) * inverse
        g2 = (all_points[index, other, 2] - all_points[index, joint, 2]) * inverse
        if g0 * g0 + g1 * g1 + g2 * g2 <= SAME_POINT * SAME_POINT:
            u0, u1, u2 = all_twists[index, other, 0], all_twists[index, other, 1], all_twists[index, other, 2]
            x0, x1, x2 = cross(w0, w1, w2, u0, u1, u2)
            if x0 * x0 + x1 * x1 + x2 * x2 > AXIS_PARALLEL * (w0 * w0 + w1 * w1 + w2 * w2) * (u0 * u0 + u1 * u1
                                                                                                + u2 * u2):
                return 0.0, 0.0, 0.0
    return w0, w1, w2


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def actuator_joint_lanes(all_twists, all_points, chain_start, actuator_chain, actuator_joint, first_index, width,
                         centres, inverse_lengths, joint_lanes):
    """Each actuator's joint twist (rows 0-5 of ``joint_lanes[act]``), the point of the joint after it (6-8: the
    first that turns, as :func:`screwkit.screw.reference.joint_after` takes it) and its chain's platform joint d
    (9-11), lane by lane, in working coordinates (as the first stage computed them), and the axes of those two joints
    along which their points are arbitrary (12-14, 15-17: :func:`joint_line`)."""
    if width == 0:
        return
    for act in range(actuator_chain.shape[0]):
        start = chain_start[actuator_chain[act]]
        own = start + actuator_joint[act]
        last = chain_start[actuator_chain[act] + 1] - 1
        after = own  # a slide has no point: the next joint that turns (a slide's twist turns in no configuration)
        for joint in range(own + 1, last + 1):
            after = joint
            if (all_twists[first_index, joint, 0] != 0.0 or all_twists[first_index, joint, 1] != 0.0
                    or all_twists[first_index, joint, 2] != 0.0):
                break
        for r in range(width):
            c0, c1, c2, inverse = centres[0, r], centres[1, r], centres[2, r], inverse_lengths[r]
            (joint_lanes[act, 0, r], joint_lanes[act, 1, r], joint_lanes[act, 2, r], joint_lanes[act, 3, r],
             joint_lanes[act, 4, r], joint_lanes[act, 5, r]) = working_twist(all_twists, first_index + r, own, c0, c1,
                                                                             c2, inverse)
            joint_lanes[act, 6, r], joint_lanes[act, 7, r], joint_lanes[act, 8, r] = working_point(
                all_points, first_index + r, after, c0, c1, c2, inverse)
            joint_lanes[act, 9, r], joint_lanes[act, 10, r], joint_lanes[act, 11, r] = working_point(
                all_points, first_index + r, last, c0, c1, c2, inverse)
            joint_lanes[act, 12, r], joint_lanes[act, 13, r], joint_lanes[act, 14, r] = joint_line(
                all_twists, all_points, first_index + r, after, start, last, inverse)
            joint_lanes[act, 15, r], joint_lanes[act, 16, r], joint_lanes[act, 17, r] = joint_line(
                all_twists, all_points, first_index + r, last, start, last, inverse)


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def on_wrench_axis(joint_lanes, act, r, row, f0, f1, f2, axis0, axis1, axis2, pitch, forceful):
    """The characteristic point of the joint whose point and axis are ``joint_lanes[act, row:row + 3, r]`` and
    ``[row + 6:row + 9]`` on the axis of a unit-force wrench (through ``axis``, f x m; ``pitch`` in working
    coordinates), as :func:`screwkit.screw.algebra.nearest_on_axis`: for a force, the point of its axis nearest to
    the joint's axis; the point's projection for a pitch, a parallel or a zero axis; p itself for a couple."""
    p0, p1, p2 = joint_lanes[act, row, r], joint_lanes[act, row + 1, r], joint_lanes[act, row + 2, r]
    if not forceful:
        return p0, p1, p2
    q0, q1, q2 = projected(p0, p1, p2, f0, f1, f2, axis0, axis1, axis2)
    if abs(pitch) > ZERO_PITCH:
        return q0, q1, q2
    return crossing_point(p0, p1, p2, q0, q1, q2, f0, f1, f2, 1.0, joint_lanes[act, row + 6, r],
                          joint_lanes[act, row + 7, r], joint_lanes[act, row + 8, r])


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def given_point(override, index, act, centres, r, inverse, f0, f1, f2, axis0, axis1, axis2, forceful):
    """A characteristic point the caller gave (world frame and unit), in working coordinates, projected on the axis
    of the unit-force wrench (through ``axis``): the paper rotates a wrench about a point *on* it (Sec. 2, Eq. 5), and
    a point beside it (the hinge of a universal joint whose other hinge is the actuator, on the actuator's own axis)
    measured a velocity the wrench never meets. A couple keeps the point."""
    p0 = (override[index, act, 0] - centres[0, r]) * inverse
    p1 = (override[index, act, 1] - centres[1, r]) * inverse
    p2 = (override[index, act, 2] - centres[2, r]) * inverse
    if not forceful:
        return p0, p1, p2
    return projected(p0, p1, p2, f0, f1, f2, axis0, axis1, axis2)


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def projected(p0, p1, p2, f0, f1, f2, axis0, axis1, axis2):
    """The point p projected on the axis of a unit force f through the point ``axis``."""
    along = (p0 - axis0) * f0 + (p1 - axis1) * f1 + (p2 - axis2) * f2
    return axis0 + along * f0, axis1 + along * f1, axis2 + along * f2


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def unit_wrench_lanes(forces, joint_lanes, pure_couple_sq, iti_override, oti_override, first_index, width,
                      centres, inverse_lengths, thresholds, wrench_lanes, has_force, pitch_lanes, point_lanes,
                      iti_lanes):
    """Each actuator's unit wrench about the centroid, its ITI (Eq. 6) and its OTI
    characteristic point, lane by lane.

    The characteristic points are the caller's (``iti_override``, ``oti_override``) projected on the wrench axis
    (:func:`given_point`), else the joint after the actuated one (ITI) and the platform joint d (OTI), each where the
    wrench axis comes nearest to the joint's axis (:func:`on_wrench_axis`).
    """
    for act in range(forces.shape[0]):
        for r in range(width):
            d0, d1, d2 = joint_lanes[act, 9, r], joint_lanes[act, 10, r], joint_lanes[act, 11, r]
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
            work_done = (f0 * joint_lanes[act, 3, r] + f1 * joint_lanes[act, 4, r] + f2 * joint_lanes[act, 5, r]
                         + m0 * joint_lanes[act, 0, r] + m1 * joint_lanes[act, 1, r] + m2 * joint_lanes[act, 2, r])
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
            # Characteristic points on the wrench axis (unit force).
            axis0, axis1, axis2 = cross(f0, f1, f2, m0, m1, m2)
            if iti_override.shape[0] > 0:
                p0, p1, p2 = given_point(iti_override, first_index + r, act, centres, r, inverse_lengths[r], f0, f1, f2,
                                         axis0, axis1, axis2, forceful)
            else:
                p0, p1, p2 = on_wrench_axis(joint_lanes, act, r, 6, f0, f1, f2, axis0, axis1, axis2, pitch, forceful)
            # ITI (Eq. 6): power coefficient on the actuated joint's own twist.
            w0, w1, w2 = joint_lanes[act, 0, r], joint_lanes[act, 1, r], joint_lanes[act, 2, r]
            omega = np.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
            arm = np.sqrt(arm_square(w0, w1, w2, joint_lanes[act, 3, r], joint_lanes[act, 4, r], joint_lanes[act, 5, r],
                                     p0, p1, p2, pitch)) if forceful else omega
            reference = omega if forceful else 0.0
            iti_lanes[act, r] = power_coefficient(work_done * factor, arm, reference, thresholds[r])
            if oti_override.shape[0] > 0:
                p0, p1, p2 = given_point(oti_override, first_index + r, act, centres, r, inverse_lengths[r], f0, f1, f2,
                                         axis0, axis1, axis2, forceful)
            else:
                p0, p1, p2 = on_wrench_axis(joint_lanes, act, r, 9, f0, f1, f2, axis0, axis1, axis2, pitch, forceful)
            point_lanes[act, 0, r] = p0
            point_lanes[act, 1, r] = p1
            point_lanes[act, 2, r] = p2


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def wrench_matrix_rows(wrench_lanes, motion_lanes, width, wrench_matrix, row_norms):
    """Each actuator's row of the wrench matrix in motion coordinates, A_k o M_q, and the norm of its wrench A_k
    (working coordinates), lane by lane: the scale a submechanism's determinant is measured against
    (:func:`~screwkit.indices.compiled.outputs.submechanism_determinants`). Not the row's own norm: a wrench that
    does no work on the motion space has a row of rounding noise, which measured against itself would count as
    independent."""
    for act in range(wrench_lanes.shape[0]):
        for r in range(width):
            row_norms[act, r] = 0.0
        for c in range(6):
            for r in range(width):
                row_norms[act, r] += wrench_lanes[act, c, r] * wrench_lanes[act, c, r]
        for q in range(motion_lanes.shape[0]):
            for r in range(width):
                value = (wrench_lanes[act, 0, r] * motion_lanes[q, 3, r]
                         + wrench_lanes[act, 1, r] * motion_lanes[q, 4, r]
                         + wrench_lanes[act, 2, r] * motion_lanes[q, 5, r]
                         + wrench_lanes[act, 3, r] * motion_lanes[q, 0, r]
                         + wrench_lanes[act, 4, r] * motion_lanes[q, 1, r]
                         + wrench_lanes[act, 5, r] * motion_lanes[q, 2, r])
                wrench_matrix[act, q, r] = value
        for r in range(width):
            row_norms[act, r] = np.sqrt(row_norms[act, r])


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def world_wrenches(wrench_lanes, has_force, first_index, width, centres, lengths, inverse_lengths, wrench_out):
    """Each actuator's unit wrench back in world units and origin (m_0 = L m' + c x f) into ``wrench_out``: a
    unit force, or a unit moment in world units for a couple."""
    for act in range(wrench_lanes.shape[0]):
        for r in range(width):
            f0, f1, f2 = wrench_lanes[act, 0, r], wrench_lanes[act, 1, r], wrench_lanes[act, 2, r]
            x0, x1, x2 = cross(centres[0, r], centres[1, r], centres[2, r], f0, f1, f2)
            length = lengths[r]
            unit = 1.0 if has_force[act, r] else inverse_lengths[r]
            wrench_out[first_index + r, act, 0] = f0 * unit
            wrench_out[first_index + r, act, 1] = f1 * unit
            wrench_out[first_index + r, act, 2] = f2 * unit
            wrench_out[first_index + r, act, 3] = (wrench_lanes[act, 3, r] * length + x0) * unit
            wrench_out[first_index + r, act, 4] = (wrench_lanes[act, 4, r] * length + x1) * unit
            wrench_out[first_index + r, act, 5] = (wrench_lanes[act, 5, r] * length + x2) * unit


@njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")
def actuator_stage(all_twists, all_points, chain_start, actuator_chain, actuator_joint, forces, pure_couple_sq,
                   iti_override, oti_override, motion_lanes, first_index, width, centres, lengths, inverse_lengths,
                   thresholds, joint_lanes, wrench_lanes, point_lanes, pitch_lanes, has_force, iti_lanes,
                   wrench_matrix, row_norms, wrench_out):
    """Every actuator's unit wrench, ITI (Eq. 6), OTI characteristic point and row of W (into the lanes of
    :func:`actuator_scratch`); its world wrench into ``wrench_out`` when that has rows."""
    actuator_joint_lanes(all_twists, all_points, chain_start, actuator_chain, actuator_joint, first_index, width,
                         centres, inverse_lengths, joint_lanes)
    unit_wrench_lanes(forces, joint_lanes, pure_couple_sq, iti_override, oti_override, first_index, width, centres,
                      inverse_lengths, thresholds, wrench_lanes, has_force, pitch_lanes, point_lanes, iti_lanes)
    wrench_matrix_rows(wrench_lanes, motion_lanes, width, wrench_matrix, row_norms)
    if wrench_out.shape[0] > 0:
        world_wrenches(wrench_lanes, has_force, first_index, width, centres, lengths, inverse_lengths, wrench_out)
