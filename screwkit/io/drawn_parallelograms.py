"""Four-bars of hinges a file draws as parallelograms and writes rounded, read as parallelograms.

A parallelogram of hinges keeps its coupler from turning. Written with its numbers rounded, its opposite sides differ
by the rounding: the four-bar is then another linkage, whose coupler turns a little as it moves. Gepetto's
``robot_delta`` written to 6 decimals turned its effector by 4e-4 to 1.6e-3 rad per unit twist, from one configuration
to the next; a compound leg (:mod:`screwkit.io.compound`) read that as a rotation the leg allows, which changes between
configurations, and the file was refused.

:func:`drawn_parallelograms` finds, at a closed configuration of a tree (:mod:`screwkit.io.closed_tree`), every
**four-bar of hinge lines**: four bodies joined in a cycle by four distinct lines of hinges, all parallel to
:data:`~screwkit.common.tolerances.FILE_ROUNDING`. A line is every hinge on it: a revolute joint of the tree, a
hinge the file closes by two ball closures on its axis (drawn through their middle), and the coaxial hinges of bodies
a ``6d`` closure welds (Gepetto's closing pins); a line is drawn through the mean of its hinges. A four-bar whose
opposite sides, as vectors across the axes, differ by at most :data:`SIDES_ROUNDING` of the length scale, and by at
most what the rounding of the numbers its file is written with can give (:func:`written_rounding`: none in a file
written with all their digits), and by more than :data:`UNSEEN` of the length scale, was drawn as a parallelogram. The
lines of all such four-bars are moved across their axes the least (the minimum-norm solution of every four-bar's
condition together, so that no choice of a side or of a file's order enters), on every body they join, for their
opposite sides to be equal. Every other feature of every body (its other joints, its frames, its closure frames)
stays where it is at the configuration, so the configuration stays closed; a note says the largest move.
"""

from __future__ import annotations

from dataclasses import replace
from itertools import permutations

import numpy as np
from numpy.typing import NDArray

from screwkit.common.tolerances import FILE_ROUNDING
from screwkit.io.closed_tree import ClosedTree, closure_gaps, homogeneous, joint_kind
from screwkit.io.graph_rounding import closed_hinges
from screwkit.io.tree_joints import joint_frames
from screwkit.io.written_decimals import written_steps

__all__ = ["drawn_parallelograms", "written_rounding", "SIDES_ROUNDING", "UNSEEN", "PARALLELOGRAMS_DRAWN",
           "DEFECT_STEPS"]

SIDES_ROUNDING = 10 * FILE_ROUNDING
"""Relative to the length scale: the largest difference of a four-bar's opposite sides (as vectors) read as a
parallelogram written rounded (its four hinges each drawn to :data:`~screwkit.common.tolerances.FILE_ROUNDING`)."""

UNSEEN = 1e-12
"""Relative to the length scale: four-bars whose opposite sides differ by at most this are left as they are (an exact
file reads as before, bit for bit)."""

PARALLELOGRAMS_DRAWN = "four-bars of hinges drawn as parallelograms and written rounded read as parallelograms"
"""How the note of :func:`drawn_parallelograms` begins."""

_SIDE = 1e-2
"""Relative to its longest side: a four-bar with a side shorter than this is not taken for a parallelogram (two of
its lines nearly one)."""

DEFECT_STEPS = 20
"""How many of the file's last written decimals (each coordinate rounded by half of one: lengths in the file's unit,
angles and axis components times the length scale) a four-bar's defect may add up to and still be the file's rounding:
the numbers on its four hinges' paths."""


def written_rounding(tree: ClosedTree, scale: float) -> float:
    """The largest defect (m) that the rounding of the numbers the file writes its geometry with can give a four-bar:
    :data:`DEFECT_STEPS` times half the step of the last decimal its lengths are written with (times its length unit)
    plus half that of its angles and axes (times ``scale``): :func:`screwkit.io.written_decimals.written_steps`. A
    file written with all the digits of its numbers (a generated one) leaves no defect to its rounding: a four-bar it
    draws a little off a parallelogram is one. Infinite where the file cannot be read again (its numbers unknown)."""
    lengths, angles = written_steps(tree.source, tree.length_unit)
    if lengths is None and angles is None:
        return np.inf
    return DEFECT_STEPS * 0.5 * ((lengths if lengths is not None else 0.0) + (angles * scale if angles is not None
                                                                               else 0.0))


def drawn_parallelograms(tree: ClosedTree, q: NDArray, scale: float) -> ClosedTree:
    """``tree`` with its four-bars of hinges drawn as parallelograms made exact at the closed configuration ``q``
    (the module's docstring), its notes saying so; ``tree`` itself when none is moved."""
    world = joint_frames(tree.model, q)
    lines, members = _lines(tree, world, scale)
    limit = min(SIDES_ROUNDING * scale, written_rounding(tree, scale))
    found = _four_bars(lines, members, limit)
    if not any(np.linalg.norm(defect) > UNSEEN * scale for _, _, defect in found):
        return tree
    moves = _least_moves(found, len(lines))
    moved_model, closures = _moved(tree, world, lines, moves)
    moved = replace(tree, model=moved_model, closures=closures)
    gaps, before = closure_gaps(moved, q), closure_gaps(tree, q)
    after_lines, after_members = _lines(moved, joint_frames(moved.model, q), scale)
    left = [np.linalg.norm(defect) for _, _, defect in _four_bars(after_lines, after_members, SIDES_ROUNDING * scale)]
    if any(gaps[name] > before[name] + UNSEEN * scale for name in gaps) or max(left, default=0.0) > UNSEEN * scale:
        return tree  # (not made exact as drawn: read as written)
    sizes = np.array([np.linalg.norm(move) for move in moves])
    named = min(line["name"] for line, size in zip(lines, sizes) if size >= sizes.max() * (1 - 1e-9))  # (ties by name)
    note = (f"{PARALLELOGRAMS_DRAWN} ({len(found)} four-bar{'s' * (len(found) > 1)}; the largest move "
            f"{sizes.max():.2g} {tree.unit} across the axes, of {named}; four-bars whose opposite sides "
            f"differ by at most {limit / scale:.2g} of the length scale, the file's rounding, taken as parallelograms)")
    return replace(moved, notes=[*tree.notes, note])


def _bodies(tree: ClosedTree) -> list[int]:
    """Each joint's body (the link it moves; 0 the base) as the representative of the bodies ``6d`` closures weld to
    it."""
    parent = list(range(tree.model.njoints))

    def find(body: int) -> int:
        while parent[body] != body:
            parent[body] = parent[parent[body]]
            body = parent[body]
        return body

    for closure in tree.closures:
        if closure.kind == "6d":
            a, b = find(closure.joint_a), find(closure.joint_b)
            parent[max(a, b)] = min(a, b)
    return [find(body) for body in range(tree.model.njoints)]


def _lines(tree: ClosedTree, world: list, scale: float) -> tuple[list[dict], list[set]]:
    """The lines of hinges at the configuration of ``world`` (each joint's 4x4 frame): per line, its ``point`` and unit
    ``axis`` (of its first hinge), its ``joints`` (revolutes) and ``pairs`` (two ball closures on its axis), a
    ``name`` for the note; and per line the bodies it joins."""
    model = tree.model
    body = _bodies(tree)
    hinges = []  # (point, axis, joint or None, pair or None, the two bodies)
    for joint in range(1, model.njoints):
        kind, axis = joint_kind(model, joint)
        if kind == "revolute":
            hinges.append((world[joint][:3, 3], world[joint][:3, :3] @ axis, joint, None,
                           {body[model.parents[joint]], body[joint]}))
    for pair in closed_hinges(tree):
        first, second = (tree.closures[k] for k in pair)
        ends = [(world[c.joint_a] @ c.placement_a)[:3, 3] for c in (first, second)]
        if np.linalg.norm(ends[1] - ends[0]) > 0.0:  # (its middle: the same whichever the file lists first)
            hinges.append(((ends[0] + ends[1]) / 2, (ends[1] - ends[0]) / np.linalg.norm(ends[1] - ends[0]), None,
                           pair, {body[first.joint_a], body[first.joint_b]}))
    lines: list[dict] = []
    members: list[set] = []
    for point, axis, joint, pair, joined in hinges:
        index = next((k for k, line in enumerate(lines) if _on_line(point, axis, line, scale)), len(lines))
        if index == len(lines):
            lines.append({"point": point, "axis": axis, "joints": [], "pairs": [], "hinges": []})
            members.append(set())
        lines[index]["joints" if joint is not None else "pairs"].append(joint if joint is not None else pair)
        named = sorted(repr(tree.closures[k].name) for k in pair) if joint is None else None
        lines[index]["hinges"].append(repr(model.names[joint]) if joint is not None else
                                      f"the hinge closed by {named[0]} and {named[1]}")
        lines[index].setdefault("points", []).append((point, axis))
        members[index].update(joined)
    for line in lines:  # (named by all its hinges in the order of their names, drawn through their mean: the same
        line["name"] = "the line of " + ", ".join(sorted(line["hinges"]))  # in a file that lists them otherwise)
        axes = np.array([axis * np.sign(axis @ line["axis"]) for _, axis in line["points"]])
        line["axis"] = np.sum(axes, axis=0) / np.linalg.norm(np.sum(axes, axis=0))
        line["point"] = np.mean([point for point, _ in line["points"]], axis=0)
    return lines, members


def _on_line(point: NDArray, axis: NDArray, line: dict, scale: float) -> bool:
    """Whether a hinge (its point and unit axis) lies on ``line``: parallel to
    :data:`~screwkit.common.tolerances.FILE_ROUNDING`, and across the axis within :data:`SIDES_ROUNDING` of
    ``scale``."""
    across = point - line["point"]
    across = across - (across @ line["axis"]) * line["axis"]
    return bool(np.linalg.norm(np.cross(axis, line["axis"])) <= FILE_ROUNDING
                and np.linalg.norm(across) <= SIDES_ROUNDING * scale)


def _four_bars(lines: list[dict], members: list[set], limit: float) -> list[tuple[tuple, NDArray, NDArray]]:
    """Every four-bar of parallel lines drawn as a parallelogram: (its four lines in cyclic order, the projector
    across their axes, its defect: the sum of two opposite sides, across the axes), at most ``limit`` (m); each
    once. A four-bar is lines l0, l1, l2, l3 and distinct bodies b1 on l0
    and l1, b2 on l1 and l2, b3 on l2 and l3, b0 on l3 and l0."""
    through: dict[int, set] = {}
    for index, bodies in enumerate(members):
        for body in bodies:
            through.setdefault(body, set()).add(index)
    found, seen = [], set()
    for l0, bodies in enumerate(members):
        for b0, b1 in permutations(bodies, 2):
            for l1 in through[b1] - {l0}:
                for b2 in members[l1] - {b0, b1}:
                    for l2 in through[b2] - {l0, l1}:
                        for b3 in members[l2] - {b0, b1, b2}:
                            for l3 in (through[b3] & through[b0]) - {l0, l1, l2}:
                                cycle = (l0, l1, l2, l3)
                                turns = [cycle[k:] + cycle[:k] for k in range(4)]
                                key = min(turns + [tuple(reversed(turn)) for turn in turns])
                                if key not in seen:
                                    seen.add(key)
                                    kept = _parallelogram(cycle, lines, limit)
                                    if kept is not None:
                                        found.append(kept)
    return found


def _parallelogram(cycle: tuple, lines: list[dict], limit: float) -> tuple[tuple, NDArray, NDArray] | None:
    axes = [lines[k]["axis"] * np.sign(lines[k]["axis"] @ lines[cycle[0]]["axis"]) for k in cycle]
    if max(np.linalg.norm(np.cross(axes[0], axis)) for axis in axes) > FILE_ROUNDING:
        return None
    axis = np.mean(axes, axis=0)
    axis /= np.linalg.norm(axis)
    across = np.eye(3) - np.outer(axis, axis)
    points = [across @ lines[k]["point"] for k in cycle]
    sides = [points[(k + 1) % 4] - points[k] for k in range(4)]
    if min(np.linalg.norm(side) for side in sides) < _SIDE * max(np.linalg.norm(side) for side in sides):
        return None
    defect = sides[0] + sides[2]
    return (cycle, across, defect) if np.linalg.norm(defect) <= limit else None


def _least_moves(found: list, count: int) -> list[NDArray]:
    """The world moves of the ``count`` lines, least in norm, that make every four-bar of ``found`` a parallelogram:
    for lines (l0, l1, l2, l3) in cyclic order, across the axes, (m1 - m0) + (m3 - m2) = -defect."""
    rows, right = [], []
    for cycle, across, defect in found:
        block = np.zeros((3, 3 * count))
        for line, sign in zip(cycle, (-1.0, 1.0, -1.0, 1.0)):
            block[:, 3 * line:3 * line + 3] += sign * across
        rows.append(block)
        right.append(-defect)
    solution = np.linalg.lstsq(np.vstack(rows), np.concatenate(right), rcond=None)[0]
    return list(solution.reshape(count, 3))


def _moved(tree: ClosedTree, world: list, lines: list[dict], moves: list[NDArray]):
    """The model and closures with each line moved by its world move on every body it joins, every other feature of
    every body kept where it is at the configuration of ``world``."""
    import pinocchio as pin  # Pinocchio: imported where a file of another tool is read

    model = tree.model.copy()
    shift = np.zeros((model.njoints, 3))  # how far each joint's origin moves (its body's frame with it)
    for line, move in zip(lines, moves):
        for joint in line["joints"]:
            shift[joint] = move
    for joint in range(1, model.njoints):
        parent = model.parents[joint]
        change = world[parent][:3, :3].T @ (shift[joint] - shift[parent])
        if np.any(change):
            placement = homogeneous(model.jointPlacements[joint])
            placement[:3, 3] += change
            model.jointPlacements[joint] = pin.SE3(placement)
    for index in range(len(model.frames)):
        frame = model.frames[index]
        if frame.type != pin.FrameType.JOINT and np.any(shift[frame.parentJoint]):
            placement = homogeneous(frame.placement)
            placement[:3, 3] -= world[frame.parentJoint][:3, :3].T @ shift[frame.parentJoint]
            frame.placement = pin.SE3(placement)
            model.frames[index] = frame
    on_line = {k: move for line, move in zip(lines, moves) for pair in line["pairs"] for k in pair}
    closures = []
    for index, closure in enumerate(tree.closures):
        point = on_line.get(index, np.zeros(3))
        a, b = np.array(closure.placement_a, dtype=float), np.array(closure.placement_b, dtype=float)
        a[:3, 3] += world[closure.joint_a][:3, :3].T @ (point - shift[closure.joint_a])
        b[:3, 3] += world[closure.joint_b][:3, :3].T @ (point - shift[closure.joint_b])
        closures.append(replace(closure, placement_a=a, placement_b=b))
    return model, closures
