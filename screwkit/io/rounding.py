"""A file's rounding read as what its author drew: joint axes that agree to the file's rounding are one direction.

CAD exporters and Gazebo write 6 decimals. The hinges of a parallelogram, or a Delta leg's motor axis and the hinge
that joins it to the platform, drawn parallel, come out up to about 1e-5 rad apart when one axis is written in the
model frame and another through a rounded roll-pitch-yaw. Read exactly, the file is another mechanism: the motions
that parallel axes give are lost (the published spatial Delta with hinged parallelograms, whose legs' hinge axes
differ by 4e-6 rad, reads with one DOF instead of three). :func:`parallel_axes` gives each group of directions
within :data:`~screwkit.common.tolerances.FILE_ROUNDING` of each other (up to sign, linked pairwise) one direction:
the normalised sum of its members turned to one sense, which does not depend on the order in which they are listed,
and keeps each joint's own sense. Directions that already agree to 1e-12 are left as they are; an exact file is
written unchanged unless two of its axes happen to lie within 1e-5 rad of each other at the file's configuration
(then they are made parallel, and its indices move by about that much, 1e-7). A turned joint's placement turns
with it (:func:`turned_joint`), so that at the assembly every frame stays where it was and the loops stay closed.

Joint axes drawn through one point come out of the same rounding missing it by a few tenths of a micrometre (the
nine axes of a spherical manipulator exported from CAD miss its centre by up to 3.4e-7 m on links of 5 cm). Read
exactly, that file too is another mechanism: the constraint forces that pass through the centre no longer do, and the
three rotations about it read as one DOF, or none. :func:`meeting_lines` moves each group of three or more axis lines
that pass within :data:`~screwkit.common.tolerances.FILE_ROUNDING` of the length scale of one point onto the point
nearest to them all (least squares, which does not depend on their order), each line moved perpendicular to itself.
Pairs of lines are left as written (two lines always pass at some least distance; making it zero constrains no
motion), and so are groups whose lines all meet to 1e-12 of the scale already, and groups one of whose lines meets
another line exactly elsewhere (a universal joint on it) or belongs to a second group, which moving it would part:
the report names those (Reachy Mini's symmetric head has two, by coincidence of its design).

Where a hinge is drawn along its axis is not the mechanism either; the indices take no account of it (the
characteristic points lie where the wrench's axis comes nearest to the joint's axis:
:func:`screwkit.screw.algebra.nearest_on_axis`), so nothing here moves a hinge along its axis.

This runs once, where a file of another tool is converted (:mod:`screwkit.io.star`).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from screwkit.closure.canonical import foot_on_line
from screwkit.common.rotations import rotation_about_axis
from screwkit.common.tolerances import FILE_ROUNDING, PARALLEL_FOOT
from screwkit.io.closed_tree import joint_kind, nearest_to_lines

__all__ = ["parallel_axes", "plane_normal", "meeting_lines", "left_as_written", "drawn_lines", "turned_joint",
           "held_limits", "EXACT"]

EXACT = 1e-12
"""Directions whose cross product is at most this already agree, lines that pass within this of the length scale
of their meeting point already meet: a group of them is left as written."""

PLANE_AXIS = 1e-3
"""Sine: in a planar mechanism (every revolute parallel to its normal to the file's rounding, or to that of the angles
it writes), a hinge at most this far from the normal is written along it, and a slide at most this far from its plane
in it (:func:`drawn_lines`)."""


def parallel_axes(axes: NDArray, tolerance: float | NDArray = FILE_ROUNDING, links: NDArray | None = None
                  ) -> tuple[NDArray[np.float64], float]:
    """Unit directions (n, 3) with each group of nearly parallel ones made parallel, and the largest turn (rad).

    Two directions are in one group when the norm of their cross product is at most ``tolerance`` (a number, or
    one per pair, (n, n): :meth:`screwkit.io.written_angles.WrittenTurns.allowances`), linked pairwise (only the
    pairs ``links``, (n, n) booleans, when given): a chain of such pairs is one group, unless two of its members are
    further apart than their own tolerance (directions at 0, 0.4 and 0.8 deg with 0.5 deg allowed): then its members
    are grouped at :data:`FILE_ROUNDING` only.
    """
    axes = np.asarray(axes, dtype=float).reshape(-1, 3)
    units = axes / np.linalg.norm(axes, axis=1, keepdims=True)
    count = units.shape[0]
    allowed = np.broadcast_to(np.asarray(tolerance, dtype=float), (count, count))
    links = np.ones((count, count), dtype=bool) if links is None else links
    crosses = np.linalg.norm(np.cross(units[:, None, :], units[None, :, :]), axis=-1)
    groups = []
    for members in _linked((crosses <= allowed) & links):
        block = np.ix_(members, members)
        if np.all(crosses[block] <= allowed[block]):
            groups.append(members)
        else:
            groups += [[members[k] for k in inner] for inner in _linked((crosses[block] <= FILE_ROUNDING)
                                                                        & links[block])]
    result, turn = units.copy(), 0.0
    for members in groups:
        if len(members) < 2 or float(np.max(crosses[np.ix_(members, members)])) <= EXACT:
            continue
        senses = np.sign(units[members] @ units[members[0]])  # whichever member comes first, each keeps its sense
        block = np.ix_(members, members)
        direction = _common_direction(units[members] * senses[:, None], crosses[block],
                                      bool(np.max(allowed[block]) <= FILE_ROUNDING))
        result[members] = senses[:, None] * direction
        turn = max(turn, float(np.max(np.linalg.norm(np.cross(units[members], direction), axis=1))))
    return result, turn


def _common_direction(units: NDArray, crosses: NDArray, as_written: bool) -> NDArray[np.float64]:
    """The direction a group of nearly parallel ``units`` (m, 3, of one sense; ``crosses`` their pairs' cross
    products' norms) is written along: where they are held to the file's rounding alone (``as_written``: no angle
    written rounded by hand lies between them), that of more than half of them where those are written exactly
    parallel (a file's axes written ``0 1 0`` beside one a CAD export's quaternion tilts by 5.6e-7 rad,
    ``1.9812e-07``: their mean leaned 1.1e-7 rad off them, which moved points 0.17 m along it 3.7e-8 across, and two
    rockers drawn one behind the other no longer held one line); else their mean (axes turned by the same angles
    written ``1.57`` agree exactly with each other, and are all off the drawn direction by those angles' rounding)."""
    agreeing = crosses <= EXACT  # (each member agrees with itself)
    best = int(np.argmax(np.sum(agreeing, axis=1)))
    majority = agreeing[best] if as_written and 2 * np.sum(agreeing[best]) > len(units) else np.ones(len(units), bool)
    direction = np.sum(units[majority], axis=0)  # (their sum: the same whichever of them is listed first)
    return direction / np.linalg.norm(direction)


def _linked(links: NDArray[np.bool_]) -> list[list[int]]:
    """The groups (each in increasing order) that the pairs ``links`` (n, n) link, a chain of pairs being one."""
    count = links.shape[0]
    parent = list(range(count))

    def find(index: int) -> int:
        while parent[index] != index:
            parent[index] = parent[parent[index]]
            index = parent[index]
        return index

    for first, second in zip(*np.nonzero(np.triu(links, k=1))):
        parent[find(int(first))] = find(int(second))
    groups: dict[int, list[int]] = {}
    for index in range(count):
        groups.setdefault(find(index), []).append(index)
    return list(groups.values())


def plane_normal(revolutes, prismatics, tolerance: float | NDArray = FILE_ROUNDING,
                 slides: float | NDArray = FILE_ROUNDING) -> NDArray[np.float64] | None:
    """The normal of the plane a mechanism moves in: the common direction of its ``revolutes`` axes when its
    ``prismatics`` are perpendicular to it, else None. Parallel to :data:`EXACT`, the first revolute's direction as
    written; else (from 1e-12 on, the axes :func:`drawn_lines` makes parallel to their common direction, which the
    normal must then be), all parallel to the file's rounding (one group of :func:`parallel_axes` within
    ``tolerance``, a number or one per pair of revolutes, and each slide perpendicular to it within ``slides``, a
    number or one per slide: :class:`screwkit.io.written_angles.WrittenTurns`), the direction they are written along.
    A CAD export's five-bar, its axes parallel to 3e-7 rad, read as a spatial mechanism otherwise: other task
    coordinates, and a home it could not reach."""
    if not len(revolutes):
        return None
    revolutes, prismatics = np.reshape(revolutes, (-1, 3)), np.reshape(prismatics, (-1, 3))

    def normal_of(axes, slides: float) -> NDArray | None:  # the first axis, if every one is parallel to it
        parallel = np.all(np.linalg.norm(np.cross(axes, axes[0]), axis=1) <= EXACT)
        return axes[0] if parallel and np.all(np.abs(prismatics @ axes[0]) <= slides) else None

    exact = normal_of(revolutes, 1e-9)
    return exact if exact is not None else normal_of(parallel_axes(revolutes, tolerance)[0],
                                                     np.asarray(slides) * np.linalg.norm(prismatics, axis=1))


def meeting_lines(points: NDArray, units: NDArray, scale: float, tolerance: float = FILE_ROUNDING
                  ) -> tuple[NDArray[np.float64], float, list[tuple[NDArray, int, int]]]:
    """Moves (n, 3), each perpendicular to its line, that make every group of three or more lines passing within
    ``tolerance`` times ``scale`` of one point pass through it; the largest move; and the groups left as written.

    Lines: a point (n, 3) and a unit direction (n, 3) each. A group's point is where two of its lines come nearest
    (no two nearly parallel: squared sine above :data:`~screwkit.common.tolerances.PARALLEL_FOOT`), with every line
    that passes that near; two such points that share two lines are one (two lines meet once), and the group meets at
    the point nearest to all its lines, which each must pass within the tolerance of. A group whose lines all pass
    within :data:`EXACT` of the scale of that point is left as it is. So is a group one of whose lines meets another
    line exactly (to :data:`EXACT`) at a point of the mechanism (within three scales of the lines' drawn points'
    centroid) other than the group's (a universal joint on it), or belongs to another group: moving it would part that
    meeting; such groups are returned as (the group's lines, that line, the other line).
    """
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    units = np.asarray(units, dtype=float).reshape(-1, 3)
    count, reach = points.shape[0], tolerance * scale
    moves = np.zeros((count, 3))
    if count < 3:
        return moves, 0.0, []
    projections = np.eye(3)[None] - units[:, :, None] * units[:, None, :]
    first, second = np.triu_indices(count, 1)
    clear = np.sum(np.cross(units[first], units[second]) ** 2, axis=1) > PARALLEL_FOOT
    first, second = first[clear], second[clear]
    nearest_first = foot_on_line(points[first], units[first], points[second], units[second])
    nearest_second = foot_on_line(points[second], units[second], points[first], units[first])
    gaps = np.linalg.norm(nearest_first - nearest_second, axis=1)
    meetings = (nearest_first + nearest_second) / 2
    near = gaps <= reach
    middle = points.mean(axis=0)
    exact = (gaps <= EXACT * scale) & (np.linalg.norm(meetings - middle, axis=1) <= 3.0 * scale)  # on the mechanism
    joined = [(int(one), int(other), meeting) for one, other, meeting in
              zip(first[exact], second[exact], meetings[exact])]  # lines that meet exactly: a universal joint
    through = np.linalg.norm(np.einsum("kij,ckj->cki", projections, points[None] - meetings[near][:, None]),
                             axis=-1) <= reach  # (candidate, line)
    groups = [row for row in np.unique(through[np.sum(through, axis=1) >= 3], axis=0)]  # many through one: one row
    merged = True
    while merged:  # points that share two lines are one (two lines meet once), also through a third point
        merged = False
        for one in range(len(groups)):
            for other in range(one + 1, len(groups)):
                if np.sum(groups[one] & groups[other]) >= 2:
                    groups[one] = groups[one] | groups.pop(other)
                    merged = True
                    break
            if merged:
                break
    largest, left = 0.0, []
    for members in groups:
        lines = np.flatnonzero(members)
        centre, offsets = nearest_to_lines(projections[lines], points[lines])
        distances = np.linalg.norm(offsets, axis=1)
        if np.max(distances) > reach or np.max(distances) <= EXACT * scale:
            continue
        elsewhere = [(one, other) if members[one] else (other, one) for one, other, meeting in joined
                     if members[one] != members[other] and np.linalg.norm(meeting - centre) > 2.0 * reach]
        elsewhere += [(int(line), int(np.flatnonzero(another & ~members)[0])) for another in groups
                      if another is not members for line in np.flatnonzero(another & members)]  # two groups
        if elsewhere:
            left.append((lines, *elsewhere[0]))
            continue
        moves[lines] = -offsets
        largest = max(largest, float(np.max(distances)))
    return moves, largest, left


def drawn_lines(model, data, legs: list, equivalents: list, scale: float, report, turns=None, normal=None
                ) -> tuple[dict[int, NDArray], list]:
    """The legs' joint axes, loop axes and equivalent chains' rotations with :func:`parallel_axes` applied, and the
    legs' revolute lines (joints and revolute loops) with :func:`meeting_lines` applied.

    ``legs``: :mod:`screwkit.io.star`'s legs at the assembly held in ``data``; their loop axes, loop frames and
    joint offsets are set in place (a leg's loop frame stays where it is when its last joint moves). Returns each
    1-DoF joint's axis in its own frame (by joint id) and the equivalent chains with their rotations turned; the
    import ``report`` notes the largest turn and move. ``scale``: the mechanism's length scale; ``turns``: the
    file's rounded angles (:class:`screwkit.io.written_angles.WrittenTurns`: how far apart two joints' axes drawn
    parallel may be written), none for :data:`FILE_ROUNDING` between every two axes; ``normal``: a planar mechanism's
    plane normal (:func:`plane_normal`), along which every hinge parallel to it is then written, not along the mean of
    its group (the legs that are written, whose mean it need not be: a leg whose hinges leaned 3e-9 rad off the plane
    reached no pose of it but its reference, by more than Newton's tolerance), and in whose plane every slide nearly
    in it is written (two slides 4e-7 rad off it did the same).
    """
    owners, directions, slides = [], [], []
    for leg in legs:
        for joint in leg.joints:
            if joint not in leg.locked:
                owners.append(("joint", joint))
                kind, axis = joint_kind(model, joint)
                directions.append(np.asarray(data.oMi[joint].rotation) @ axis)
                slides.append(kind == "prismatic")
        if leg.loop in ("revolute", "prismatic"):
            owners.append(("loop", leg))
            directions.append(leg.loop_dofs[0][1])
            slides.append(leg.loop == "prismatic")
    for index, (_, reduction, _) in enumerate(equivalents):
        owners += [("turn", (index, row)) for row in range(len(reduction.rotations))]
        directions += list(reduction.rotations)
        slides += [False] * len(reduction.rotations)
    if not directions:
        return {}, equivalents
    names = [model.names[owner] if kind == "joint" else owner.loop_names[0] if kind == "loop" and owner.loop_names
             else None for kind, owner in owners]
    allowed = turns.allowances(names) if turns is not None else FILE_ROUNDING
    turned, turn = parallel_axes(np.array(directions), allowed)
    units = np.array(directions) / np.linalg.norm(directions, axis=1, keepdims=True)
    if normal is not None:  # hinges along the normal, slides in the plane (an exact file's as written)
        off = np.linalg.norm(np.cross(turned, normal), axis=1)
        along = (off <= PLANE_AXIS) & (off > EXACT) & ~np.array(slides)
        turned[along] = np.sign(turned[along] @ normal)[:, None] * normal
        out = turned @ normal
        across = (np.abs(out) <= PLANE_AXIS) & (np.abs(out) > EXACT) & np.array(slides)
        turned[across] -= out[across, None] * normal
        turned[across] /= np.linalg.norm(turned[across], axis=1, keepdims=True)
        turn = float(np.max(np.linalg.norm(np.cross(turned, units), axis=1), initial=0.0))
        turn = turn if turn > EXACT else 0.0
    if turn:
        most = names[int(np.argmax(np.linalg.norm(np.cross(turned, units), axis=1)))]
        report.notes.append(f"joint axes that agree to the file's rounding written parallel (the largest turn "
                            f"{turn:.2g} rad{f', of joint {most!r}' if most else ''}"
                            + (f"; the file writes angles rounded, {turns.example}" if turn > FILE_ROUNDING and
                               turns is not None and turns.example else "") + ")")
    local: dict[int, NDArray] = {}
    rotations = [np.array(reduction.rotations, dtype=float) for _, reduction, _ in equivalents]
    for (kind, owner), direction in zip(owners, turned):
        if kind == "joint":
            local[owner] = np.asarray(data.oMi[owner].rotation).T @ direction
        elif kind == "loop":
            owner.axis = owner.successor_world[:3, :3].T @ direction
            owner.loop_dofs = [(owner.loop_dofs[0][0], direction, owner.loop_dofs[0][2])]
        else:
            rotations[owner[0]][owner[1]] = direction
    equivalents = [(name, replace(reduction, rotations=rotation), point)
                   for (name, reduction, point), rotation in zip(equivalents, rotations)]
    _meet(model, data, legs, local, scale, report)
    return local, equivalents


def left_as_written(left: list, names: list[str], shown: int = 2) -> list[str]:
    """The import report's notes on the groups of lines :func:`meeting_lines` leaves as written (its ``left``; the
    lines' ``names``): the first ``shown`` named, the others counted (a Stewart base's hinges, all in one plane, meet
    by threes: a CAD export's made twelve such notes)."""
    notes = [f"joint axes {', '.join(names[k] for k in lines)} pass within the file's rounding of one point and are "
             f"left as written: {names[line]} also meets {names[other]} elsewhere"
             for lines, line, other in left[:shown]]
    if len(left) > shown:
        notes.append(f"and {len(left) - shown} more group(s) of joint axes within the file's rounding of one point "
                     "left as written, each with an axis that also meets another elsewhere")
    return notes


def _meet(model, data, legs: list, local: dict[int, NDArray], scale: float, report) -> None:
    """:func:`meeting_lines` on the legs' revolute joints (axes ``local``, in their own frames) and revolute loops:
    a joint's move is added to its leg's offsets, a loop's moves its two frames."""
    owners, points, units = [], [], []
    for leg in legs:
        for joint in leg.joints:
            if joint not in leg.locked and joint_kind(model, joint)[0] == "revolute":
                rotation = np.asarray(data.oMi[joint].rotation)
                owners.append((leg, joint))
                points.append(np.asarray(data.oMi[joint].translation) + leg.offsets.get(joint, np.zeros(3)))
                units.append(rotation @ local[joint] / np.linalg.norm(local[joint]))
        if leg.loop == "revolute":
            owners.append((leg, None))
            points.append(leg.loop_dofs[0][2])
            units.append(leg.loop_dofs[0][1] / np.linalg.norm(leg.loop_dofs[0][1]))
    moves, largest, left = meeting_lines(np.array(points).reshape(-1, 3), np.array(units).reshape(-1, 3), scale)
    names = [model.names[joint] if joint is not None else f"{leg.closure} (loop)" for leg, joint in owners]
    report.notes.extend(left_as_written(left, names))
    if not largest:
        return
    report.notes.append(f"joint axes that meet to the file's rounding written through one point (the largest move "
                        f"{largest:.2g} {report.unit})")
    for (leg, joint), move in zip(owners, moves):
        if not np.any(move):
            continue
        end = np.asarray(data.oMi[leg.joints[-1] if leg.joints else 0].rotation)  # where the loop frame is written
        leg.predecessor = leg.predecessor.copy()
        if joint is None:  # the loop's line: both its frames move with it
            leg.successor_world = leg.successor_world.copy()
            leg.successor_world[:3, 3] += move
            leg.predecessor[:3, 3] += end.T @ move
            leg.loop_dofs = [(leg.loop_dofs[0][0], leg.loop_dofs[0][1], leg.loop_dofs[0][2] + move)]
            continue
        leg.offsets = dict(leg.offsets)
        leg.offsets[joint] = leg.offsets.get(joint, np.zeros(3)) + move
        if joint == leg.joints[-1]:  # the loop frame stays where it is
            leg.predecessor[:3, 3] -= end.T @ move


def turned_joint(placement: NDArray, kind: str, axis: NDArray, turned: NDArray | None, value: float
                 ) -> tuple[NDArray[np.float64], NDArray]:
    """A joint's placement (4x4, in its parent's frame) and axis (its own frame) written with the axis ``turned``
    by :func:`drawn_lines` (None: as the file has it), its placement turned with it so that at the joint's
    ``value`` at the assembly its frame, and every frame after it, stays where it is (a turned axis alone moves
    them by the turn times the joint's value, which opens the loops the assembly closed): the rotation
    ``R(a, value) R(a', -value)`` after the placement's for a revolute, the offset ``(a - a') value`` for a slide."""
    if turned is None:
        return placement, axis
    written = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    direction = np.asarray(turned, dtype=float) / np.linalg.norm(turned)
    if np.linalg.norm(np.cross(written, direction)) <= EXACT:  # not turned (its own frame's axis, read back)
        return placement, turned
    kept = np.array(placement, dtype=float)
    if kind == "revolute":
        kept[:3, :3] = kept[:3, :3] @ rotation_about_axis(written, value) @ rotation_about_axis(direction, -value)
    else:
        kept[:3, 3] += kept[:3, :3] @ ((written - direction) * value)
    return kept, turned


FULL_TURNS = "revolutes whose limits span a full turn to the file's rounding, read as continuous joints: "
"""How the import report's note on :func:`held_limits`' full turns starts (the joints' names follow)."""


def held_limits(model, joint: int, value: float, kind: str, scale: float, report) -> tuple[float, float]:
    """The limits of a 1-DoF ``joint`` as written, or moved out to its assembled ``value`` where that value misses
    them by at most the file's rounding (:data:`FILE_ROUNDING` rad, or times the length ``scale`` for a slide), said
    in the import ``report``; a revolute whose limits span a full turn to the rounding ([0, 6.283185], [-3.14159,
    3.14159]) unlimited (-inf, inf): a continuous joint. A CAD export writes a joint drawn at its stop 1e-9 to 3e-7
    beyond it: read as written, the file's own configuration was refused as outside its limits."""
    index = model.joints[joint].idx_q
    lower, upper = float(model.lowerPositionLimit[index]), float(model.upperPositionLimit[index])
    if kind == "revolute" and upper - lower >= 2.0 * np.pi - FILE_ROUNDING and np.isfinite(upper - lower):
        named = [k for k, note in enumerate(report.notes) if note.startswith(FULL_TURNS)]
        if named:
            report.notes[named[0]] += f", {model.names[joint]}"
        else:
            report.notes.append(f"{FULL_TURNS}{model.names[joint]}")
        return -np.inf, np.inf  # (a sliver of 3e-7 rad left out of [0, 6.283185] reads as a limit otherwise)
    reach = FILE_ROUNDING * (scale if kind == "prismatic" else 1.0)
    moved = lower - reach <= value < lower or upper < value <= upper + reach
    if moved and np.isfinite(lower) and np.isfinite(upper) and lower < upper:  # (no range: a continuous joint)
        lower, upper = min(lower, value), max(upper, value)
        report.notes.append(f"joint {model.names[joint]!r}: its limits moved out to {value:.6g}, where the assembly "
                            "puts it, beyond them by less than the file's rounding")
    return lower, upper
