r"""Canonical points of revolute joints: a chain's geometry made independent of where along its axis a file
draws each revolute joint.

A revolute joint is a line; a file draws its frame at some point of that line, and any other point draws the same
mechanism. The indices read joint points in three places: the working length ``L`` and centroid (every joint
point), the characteristic points of the ITI and OTI (for a force, the point of its axis nearest to the joint's
axis, which does not depend on the drawn point; for a wrench with a pitch and the other exceptions of
:func:`screwkit.screw.algebra.nearest_on_axis`, the drawn point projected), and the representative of an actuation
wrench defined modulo constraint wrenches (least norm about the chain's platform joint). So that none of them
depends on how the file is written, :func:`canonical_geometry` moves each revolute joint, once when the chain is
read, to a point of its axis that the geometry alone decides, as Denavit and Hartenberg place their frames:

* each joint of a chain is a **slide** (prismatic: no point), a **point** or a **line** (any other revolute). The
  points are the revolutes of a universal or ball joint, where their axes meet a neighbour's (at most
  :data:`~screwkit.common.tolerances.MEETING` times the chain's size apart, a size its lines decide:
  :func:`chain_extent`; drawn apart, at an angle whose squared sine is above
  :data:`~screwkit.common.tolerances.PARALLEL_FOOT` too). The meetings are taken in order of how many of the chain's
  axes pass through them, then of how clear their angle is; one is kept unless either axis has already kept one of a
  higher rank at another point, and an axis that keeps two (a tie) takes their mean (:func:`_points`); a universal
  or spherical loop joint's DoFs sit at its centre before any of this;
* a line takes the foot, on its axis, of the common perpendicular with each neighbour in the chain (the joint
  before it and the one after it) that is a line whose axis is not nearly parallel to its own (squared sine above
  :data:`~screwkit.common.tolerances.PARALLEL_FOOT`), and the foot of the perpendicular from each neighbour that is a
  point; the midpoint of the two feet when both neighbours give one (so that the rule reads a chain the same way
  from either end);
* a line whose line neighbours are all (nearly) parallel to it, as in a run of parallel axes, takes the foot of the
  perpendicular from the points its neighbours took, passed along the run;
* a line that nothing decides (a planar chain: every axis parallel and no point) keeps its drawn point, as does every
  slide;
* a chain whose every axis passes through one point (a spherical wrist's leg) keeps its drawn points but for its
  last joint (the platform joint), which goes to that point: all its canonical points would be that point, and a
  spherical mechanism's working length would vanish with them; the platform joint is the point its actuation wrench
  is taken about, and there the representative is the couple normal to the passive axes (a force through the
  centre, which any drawn point would add, does no work on the chain's joints or on the platform's rotations about
  it, but lowers the ITI's power coefficient).

The points depend on the lines alone (and, for nearly parallel axes, on whether a file draws them together), so a
chain drawn at its canonical points is its own canonical drawing.

Two consecutive joints of a chain are fixed in the link between them, so every foot is a constant of the design,
the same at every configuration: the points are found once, at zero joint values, and the chain's constant
placements rewritten so that each moved joint's frame sits there (its child placements compensated). The chain
moves exactly as before, every joint value is unchanged, and the Pinocchio tree (drawn by the viewer) is not
touched. A slide between two joints breaks the link they would share, so it decides nothing.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from screwkit.closure.chain_kinematics import chain_forward_kinematics
from screwkit.common.tolerances import AXIS_PARALLEL, MEETING, MEETING_TIE, PARALLEL_FOOT
from screwkit.model.chain import LOOP_JOINT_DOFS, ChainGeometry

__all__ = ["joint_lines_at_zero", "chain_extent", "canonical_offsets", "offsets_along_axes", "canonical_geometry",
           "foot_on_line"]


CLEAR_FEET = 0.25
"""Squared sine (30 degrees): two axes whose common perpendicular's feet measure a chain's size; at a shallower angle
the feet lie far along the axes (more than twice their distance apart), outside the chain."""


def joint_lines_at_zero(geometry: ChainGeometry) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Unit axis and drawn point of every DoF of a chain at zero joint values, base frame: shapes (m, 3), (m, 3)."""
    frames = chain_forward_kinematics(geometry, np.zeros(geometry.n_dofs), compiled=False)
    axes = frames.axes.reshape(-1, 3)
    return axes / np.linalg.norm(axes, axis=1, keepdims=True), frames.points.reshape(-1, 3)


def _line_gap(point: NDArray, axis: NDArray, other_point: NDArray, other_axis: NDArray) -> float:
    """Distance between two lines (unit axes that are not parallel)."""
    normal = np.cross(axis, other_axis)
    return abs((other_point - point) @ normal) / np.linalg.norm(normal)


def foot_on_line(point: NDArray, axis: NDArray, other_point: NDArray, other_axis: NDArray) -> NDArray:
    """The foot on the line (``point``, ``axis``) of its common perpendicular with the line (``other_point``,
    ``other_axis``), unit axes that are not parallel; pairs of lines (..., 3) at once."""
    gap = point - other_point
    cosine = np.sum(axis * other_axis, axis=-1)
    along = (cosine * np.sum(other_axis * gap, axis=-1) - np.sum(axis * gap, axis=-1)) / (1.0 - cosine * cosine)
    return point + along[..., None] * axis


def _foot_of(point: NDArray, axis: NDArray, other: NDArray) -> NDArray:
    """The foot on the line (``point``, ``axis``) of the perpendicular from ``other``."""
    return point + ((other - point) @ axis) * axis


def _points(prismatic: tuple[bool, ...], axes: NDArray, points: NDArray, extent: float, declared: int = 0
            ) -> list[NDArray | None]:
    """The point of each revolute DoF that is part of a joint at a point (None for the others): a universal or
    ball joint, whose revolutes' axes meet (not parallel, at most :data:`MEETING` times the chain's ``extent``
    apart; drawn apart, at a clear angle too: squared sine above :data:`PARALLEL_FOOT`).

    An axis may meet both its neighbours', at two points (a UR wrist's second axis, or a universal joint's first
    axis and a crank's, met far away at a shallow angle). The meetings are then taken in order of how many of the
    chain's axes pass through them, then of how clear their angle is (squared sine); a meeting is kept when each of
    its two joints has kept none yet, or one at the same point (a ball's pairs, at whatever angles), or one of the
    same rank (the same number of axes, squared sines within :data:`MEETING_TIE`): a ball's centre before anything
    else, a universal joint's right angle before a shallow crossing, and an axis met by both neighbours at equal
    rank takes the mean of the two points, which the feet of the common perpendiculars give too when the axes pass
    near each other instead. Nothing of this depends on where the file draws the joints. The last ``declared`` DoFs
    (a universal or spherical loop joint) are a joint at a point by declaration, at their drawn centre, before any
    meeting: their axes are only the axes of the loop's frame, whose meetings with a neighbour's mean nothing."""
    extent = max(extent, np.finfo(float).tiny)
    reach = MEETING * extent
    revolutes = [joint for joint, slide in enumerate(prismatic[:len(prismatic) - declared]) if not slide]
    found = []  # (axes through the meeting, squared sine, joint, its neighbour, meeting point)
    for joint, other in zip(revolutes, revolutes[1:]):
        sine2 = float(np.sum(np.cross(axes[joint], axes[other]) ** 2))
        if other != joint + 1 or sine2 <= AXIS_PARALLEL:
            continue
        together = np.linalg.norm(points[other] - points[joint]) <= reach
        # axes drawn apart meet only at a clear angle: nearly parallel lines in one plane would meet far away
        if not (together or sine2 > PARALLEL_FOOT) or _line_gap(points[joint], axes[joint], points[other],
                                                                 axes[other]) > reach:
            continue
        meeting = 0.5 * (foot_on_line(points[joint], axes[joint], points[other], axes[other])
                         + foot_on_line(points[other], axes[other], points[joint], axes[joint]))
        through = sum(np.linalg.norm(np.cross(meeting - points[line], axes[line])) <= reach for line in revolutes)
        found.append((through, sine2, joint, other, meeting))
    found.sort(key=lambda meeting: (-meeting[0], -meeting[1]))
    meets: list[list[NDArray]] = [[] for _ in prismatic]
    best: list[tuple[float, float]] = [(np.inf, np.inf)] * len(prismatic)  # rank of each joint's first meeting
    for joint in range(len(prismatic) - declared, len(prismatic)):
        meets[joint].append(points[joint])

    def may_keep(joint: int, through: int, sine2: float, meeting: NDArray) -> bool:
        """Whether ``joint`` keeps a meeting: its first, one at the point it already holds (a ball's pairs, at
        whatever angles), or one of the same rank as its first (a tie: the mean)."""
        return (not meets[joint] or all(np.linalg.norm(meeting - held) <= reach for held in meets[joint])
                or (through == best[joint][0] and best[joint][1] - sine2 <= MEETING_TIE))

    for through, sine2, joint, other, meeting in found:
        if may_keep(joint, through, sine2, meeting) and may_keep(other, through, sine2, meeting):
            for member in (joint, other):
                best[member] = best[member] if meets[member] else (through, sine2)
                meets[member].append(meeting)
    return [_foot_of(points[joint], axes[joint], np.mean(joint_meets, axis=0)) if joint_meets else None
            for joint, joint_meets in enumerate(meets)]


def canonical_offsets(geometry: ChainGeometry) -> NDArray[np.float64]:
    """How far along its axis (base-frame units, signed along the joint's axis) each DoF of a chain moves to its
    canonical point (see the module docstring); zero for slides and undecided lines. Shape (m,)."""
    declared = LOOP_JOINT_DOFS[geometry.loop_type] if geometry.loop_type in ("universal", "spherical") else 0
    return offsets_along_axes(geometry.dof_prismatic, *joint_lines_at_zero(geometry), declared=declared)


def _diameter(points) -> float:
    """The largest distance between two of ``points`` (0 for fewer than two): the same in any world frame, unlike
    the extent of their bounding box along the world's axes."""
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    return float(np.max(np.linalg.norm(points[:, None] - points[None], axis=-1))) if len(points) > 1 else 0.0


def chain_extent(prismatic: tuple[bool, ...], axes: NDArray, points: NDArray, declared: int = 0) -> float:
    """The size of a chain that its lines alone decide, the scale of :data:`MEETING`: the largest distance between
    the feet of the common perpendiculars of every two revolute axes at a clear angle (squared sine above
    :data:`CLEAR_FEET`) and the centre of a loop joint at a point (the last ``declared`` DoFs), or the largest
    distance between two revolute axes when that is larger. Where the file draws a joint along its axis, and the
    world frame, change none of it; a chain whose every axis passes through one point has none (a spherical chain),
    and is measured as drawn (the largest distance between its drawn points), as is a chain whose lines are all
    that close to one point at that scale."""
    count = len(prismatic)
    revolutes = [joint for joint, slide in enumerate(prismatic[:count - declared]) if not slide]
    anchors = [points[joint] for joint in range(count - declared, count)]
    gaps = [0.0]
    for index, joint in enumerate(revolutes):
        for other in revolutes[index + 1:]:
            sine2 = float(np.sum(np.cross(axes[joint], axes[other]) ** 2))
            if sine2 <= AXIS_PARALLEL:  # parallel: the distance between the lines
                gaps.append(float(np.linalg.norm(np.cross(points[other] - points[joint], axes[joint]))))
                continue
            gaps.append(_line_gap(points[joint], axes[joint], points[other], axes[other]))
            if sine2 > CLEAR_FEET:
                anchors += [foot_on_line(points[joint], axes[joint], points[other], axes[other]),
                            foot_on_line(points[other], axes[other], points[joint], axes[joint])]
    spread, drawn = _diameter(anchors), _diameter(points)
    lines = max(spread, max(gaps))
    return lines if lines > MEETING * drawn else drawn


def offsets_along_axes(prismatic: tuple[bool, ...], axes: NDArray, points: NDArray, declared: int = 0
                       ) -> NDArray[np.float64]:
    """:func:`canonical_offsets` of a chain's joints given as lines: which are slides, unit axes (m, 3) and drawn
    points (m, 3), consecutive in the chain, the last ``declared`` of them the DoFs of a loop joint at a point (a
    universal or spherical loop joint, whose axes are only its frame's). Shape (m,)."""
    count = len(prismatic)
    extent = chain_extent(prismatic, axes, points, declared)
    canonical = _points(prismatic, axes, points, extent, declared)
    is_point = [found is not None for found in canonical]
    lines = [joint for joint in range(count) if not prismatic[joint] and not is_point[joint]]
    for joint in lines:
        feet = []
        for other in (joint - 1, joint + 1):
            if not 0 <= other < count or prismatic[other]:
                continue
            if is_point[other]:
                feet.append(_foot_of(points[joint], axes[joint], canonical[other]))
            elif np.sum(np.cross(axes[joint], axes[other]) ** 2) > PARALLEL_FOOT:
                feet.append(foot_on_line(points[joint], axes[joint], points[other], axes[other]))
        if feet:
            canonical[joint] = np.mean(feet, axis=0)
    for _ in range(count):  # along runs of parallel axes, from the joints already decided
        passed = {}
        for joint in lines:
            sources = [canonical[other] for other in (joint - 1, joint + 1)
                       if canonical[joint] is None and other in lines and canonical[other] is not None]
            if sources:
                passed[joint] = np.mean([_foot_of(points[joint], axes[joint], source) for source in sources], axis=0)
        if not passed:
            break
        for joint, point in passed.items():
            canonical[joint] = point
    placed = [point for point in canonical if point is not None]
    if len(placed) == count and count > 1 and _diameter(placed) <= MEETING * extent:
        # a spherical chain, every axis through one point: drawn as the file draws it but for its platform joint,
        # which goes to the point (where its actuation wrench's representative is the couple)
        offsets = np.zeros(count)
        offsets[-1] = float((np.mean(placed, axis=0) - points[-1]) @ axes[-1])
        return offsets
    return np.array([0.0 if point is None else float((point - points[joint]) @ axes[joint])
                     for joint, point in enumerate(canonical)])


def canonical_geometry(geometry: ChainGeometry) -> ChainGeometry:
    """The chain's geometry with every revolute joint's frame moved along its axis to its canonical point
    (:func:`canonical_offsets`), the placements after it compensated: the same chain, drawn canonically."""
    offsets = canonical_offsets(geometry)
    if not np.any(offsets):
        return geometry
    tree = geometry.n_tree_joints
    translations = np.array(geometry.joint_translations, dtype=float)
    leg_translation = np.array(geometry.leg_loop_translation, dtype=float)
    platform_translation = np.array(geometry.platform_loop_translation, dtype=float)
    for joint in range(tree):
        shift = offsets[joint] * geometry.joint_axes[joint]  # in the joint's own frame, fixed by its motion
        translations[joint] += geometry.joint_rotations[joint] @ shift
        if joint + 1 < tree:
            translations[joint + 1] -= shift
        else:
            leg_translation -= shift
    if geometry.loop_type in ("revolute", "continuous") and offsets[tree:].size:
        shift = offsets[tree] * geometry.loop_axes[0]
        leg_translation += geometry.leg_loop_rotation @ shift
        platform_translation += geometry.platform_loop_rotation @ shift
    return replace(geometry, joint_translations=translations, leg_loop_translation=leg_translation,
                   platform_loop_translation=platform_translation)
