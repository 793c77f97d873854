"""A closed-loop graph's joint axes that agree to the file's rounding, written parallel before it is analysed.

The serial reading (:mod:`screwkit.io.star`) reads a file's rounding as what its author drew
(:func:`screwkit.io.rounding.parallel_axes`); the graph reading read the file as written, and a published parallelogram
whose hand-written closing hinges (``-1 0 0``) miss the exported ones (``-1 -0 -3e-06``) by 3 microradians read as
rigid: a four-bar of hinges not quite parallel is a spatial 4R loop, which does not move. :func:`drawn_tree` gives
each group of directions within :data:`~screwkit.common.tolerances.FILE_ROUNDING` of each other (or further, where the
file writes rounded angles between them: :mod:`screwkit.io.written_angles`) one direction, as the serial reading
does, among the tree's 1-DoF joints and the hinges the file closes by two points on an axis (two
``3d`` closures between the same two joints: SDFormat's and Gazebo's revolute loop joints, two MJCF connects). A
tree joint is turned with :func:`screwkit.io.rounding.turned_joint` (its frame, and every frame after it, stays where
the assembly put it); a closed hinge's two points are turned, on both bodies, about the point where the file draws
the joint (SDFormat, Gazebo) or about their middle (two connects, whichever is listed first). A file whose axes
are parallel, or apart by more than the rounding, is returned as it is.

Unlike the serial reading, lines meant to meet at one point are left as written (:func:`screwkit.io.rounding.
meeting_lines` moves a joint's line, which in a graph moves every frame its body carries), and so are hinges closed
by three or more connects.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from screwkit.common.tolerances import FILE_ROUNDING
from screwkit.io.closed_tree import ClosedTree, joint_kind, joint_value
from screwkit.io.leg_ways import pin_groups
from screwkit.io.rounding import EXACT, parallel_axes, turned_joint
from screwkit.io.tree_joints import joint_frames
from screwkit.io.written_angles import written_turns
from screwkit.io.written_decimals import closure_step, written_steps, written_text

__all__ = ["drawn_tree", "drawn_pairs", "closed_hinges", "PAIR_TURN"]

PAIR_TURN = 1e-3
"""Radians: the largest turn :func:`drawn_pairs` gives a hinge closed by two ball closures (beyond, the file's
rounding over their spacing says too little of its axis to write it along another: it is read as written)."""


def closed_hinges(tree: ClosedTree) -> list[tuple[int, int]]:
    """The pairs of closures (indices, in file order) that close a hinge: the only two ``3d`` closures between the
    same two joints."""
    return [(pair[0], pair[1]) for pair in pin_groups(tree.closures, "3d") if len(pair) == 2]


def drawn_tree(tree: ClosedTree, q: NDArray) -> ClosedTree:
    """``tree`` with its nearly parallel axes made parallel at the closed configuration ``q`` (the module's
    docstring), its notes saying the largest turn; ``tree`` itself when no axis turns."""
    import pinocchio as pin  # Pinocchio: imported where a file of another tool is read

    tree = drawn_pairs(tree, q)
    model = tree.model
    world = joint_frames(model, q)
    owners, directions = [], []
    for joint in range(1, model.njoints):
        kind, axis = joint_kind(model, joint)
        if axis is not None:
            owners.append(joint)
            directions.append(world[joint][:3, :3] @ axis)
    for pair in closed_hinges(tree):
        first, second = (tree.closures[k] for k in pair)
        ends = _points(world, first, second, first.joint_a)
        if np.linalg.norm(ends[1] - ends[0]) > 0.0:  # (two connects at one point make no hinge: left as written)
            owners.append(pair)
            directions.append(ends[1] - ends[0])
    if len(directions) < 2:
        return tree
    units = np.array(directions) / np.linalg.norm(directions, axis=1, keepdims=True)
    turns = written_turns(tree.source)  # (axes written rounded, 1.57 for pi/2: as the serial reading allows them)
    # (a closed hinge's points are written in its first body's frame: their line turns as that body's joint does)
    names = [model.names[owner] if not isinstance(owner, tuple) else
             model.names[tree.closures[owner[0]].joint_a] if tree.closures[owner[0]].joint_a else None
             for owner in owners]
    turned, turn = parallel_axes(units, turns.allowances(names))
    if not turn:
        return tree
    moved = model.copy()
    closures = list(tree.closures)
    amounts = np.linalg.norm(np.cross(turned, units), axis=1)
    for owner, direction, amount in zip(owners, turned, amounts):
        if not amount:
            continue
        if isinstance(owner, tuple):
            closures[owner[0]], closures[owner[1]] = _turned_hinge(world, *(tree.closures[k] for k in owner),
                                                                   direction)
            continue
        kind, axis = joint_kind(model, owner)
        local = world[owner][:3, :3].T @ direction
        placement, local = turned_joint(np.asarray(model.jointPlacements[owner].homogeneous), kind, axis, local,
                                        joint_value(model, owner, q))
        moved.joints[owner] = _joint_model(model.joints[owner], kind, local)
        moved.jointPlacements[owner] = pin.SE3(placement)
    most = owners[int(np.argmax(amounts))]
    named = (f"joint {model.names[most]!r}" if not isinstance(most, tuple)
             else f"the hinge closed by {tree.closures[most[0]].name!r} and {tree.closures[most[1]].name!r}")
    rounded = f"; the file writes angles rounded, {turns.example}" if turn > FILE_ROUNDING and turns.example else ""
    note = (f"joint axes that agree to the file's rounding written parallel (the largest turn {turn:.2g} rad, of "
            f"{named}{rounded})")
    return replace(tree, model=moved, closures=closures, notes=[*tree.notes, note])


def drawn_pairs(tree: ClosedTree, q: NDArray) -> ClosedTree:
    """``tree`` with each hinge it closes by two ball closures (no point of it marked as where the file draws the
    joint) whose axis the file's rounding knows less well than :data:`~screwkit.common.tolerances.FILE_ROUNDING`
    written along the revolute joints (and better-known closed hinges) parallel to it within what it knows, at the
    closed configuration ``q``; ``tree`` itself when none turns.

    The two points are written in one body's frame, each coordinate to half the step of the last length decimal of
    the file, or of the numbers that place them where that is coarser (:mod:`screwkit.io.written_decimals`): the line
    through them is known to sqrt(3) steps over their spacing (2.9e-4 rad for two MJCF connects 6 mm apart written to
    6 decimals, where a joint's axis written as a direction is held to 1e-5). Read as written, such a hinge in a
    parallelogram made the four-bar a spatial 4R loop, which does not move: a rounded Delta read 1 DOF instead of 2.
    A hinge is turned (about the middle of its points, on both bodies, so that the configuration stays closed) when
    the directions within its allowance (that bound plus the file's rounding, at most :data:`PAIR_TURN`) agree with
    each other to the file's rounding: onto their mean (signed; whichever the file lists first). Where none is that
    near, or they disagree, it is left as written."""
    text = written_text(tree.source)
    file_step = written_steps(tree.source, tree.length_unit, text)[0] if text is not None else None
    if file_step is None or not tree.closures:
        return tree
    model = tree.model
    world = joint_frames(model, q)
    known, unsure = [], []  # directions known to the file's rounding; (pair, unit, bound) of the others
    for joint in range(1, model.njoints):
        kind, axis = joint_kind(model, joint)
        if kind == "revolute":
            known.append(world[joint][:3, :3] @ axis)
    for pair in closed_hinges(tree):
        first, second = (tree.closures[k] for k in pair)
        ends = _points(world, first, second, first.joint_a)
        spacing = float(np.linalg.norm(ends[1] - ends[0]))
        if spacing == 0.0:
            continue
        own = closure_step(text, (first.name, second.name), tree.length_unit)
        bound = np.sqrt(3.0) * max(file_step, own or 0.0) / spacing
        if bound <= FILE_ROUNDING or first.axis_point or second.axis_point:
            known.append((ends[1] - ends[0]) / spacing)
        elif bound + FILE_ROUNDING <= PAIR_TURN:
            unsure.append((pair, (ends[1] - ends[0]) / spacing, bound))
    if not known or not unsure:
        return tree
    known = np.array(known) / np.linalg.norm(known, axis=1, keepdims=True)
    closures, turns = list(tree.closures), {}
    for pair, unit, bound in unsure:
        near = known[np.linalg.norm(np.cross(known, unit), axis=1) <= bound + FILE_ROUNDING]
        if not len(near) or np.max(np.linalg.norm(np.cross(near[:, None], near[None]), axis=-1)) > FILE_ROUNDING:
            continue
        direction = np.sum(near * np.sign(near @ near[0])[:, None], axis=0)
        direction /= np.linalg.norm(direction)
        turn = float(np.linalg.norm(np.cross(direction, unit)))
        if turn > EXACT:
            closures[pair[0]], closures[pair[1]] = _turned_hinge(world, *(tree.closures[k] for k in pair), direction)
            turns[tuple(sorted(repr(tree.closures[k].name) for k in pair))] = (turn, bound)
    if not turns:
        return tree
    largest = max(turn for turn, _ in turns.values())  # (named: the first by name of those within 1 % of it, the
    most = min(names for names, (turn, _) in turns.items() if turn >= 0.99 * largest)  # same in any unit or world)
    note = (f"hinges closed by two ball closures whose axis the file's rounding knows only over their points' "
            f"spacing written along the hinges parallel to them ({len(turns)} hinge{'s' * (len(turns) > 1)}; the "
            f"largest turn {largest:.2g} rad, of the hinge closed by {most[0]} and {most[1]}, whose axis is known "
            f"to {turns[most][1]:.2g} rad)")
    return replace(tree, closures=closures, notes=[*tree.notes, note])


def _points(world: list, first, second, joint: int) -> tuple[NDArray, NDArray]:
    """The world points (at the assembly) of a closed hinge's closures ``first`` and ``second`` on the body of
    ``joint`` (either end of either closure: a file may write the two with their bodies in either order)."""
    return tuple((world[joint] @ (c.placement_a if c.joint_a == joint else c.placement_b))[:3, 3]
                 for c in (first, second))


def _turned_hinge(world: list, first, second, direction: NDArray) -> tuple:
    """The closures of a closed hinge with the line through their points along ``direction``, on both bodies: turned
    about the point the file draws the joint at (SDFormat's and Gazebo's first point; the other is marked
    :attr:`~screwkit.io.closed_tree.Closure.axis_point`), else about the middle of the two (two connects: whichever
    the file lists first, the same hinge)."""
    about = 0.0 if second.axis_point and not first.axis_point else 1.0 if first.axis_point else 0.5
    placed = {id(first): {}, id(second): {}}
    for joint in (first.joint_a, first.joint_b):
        start, end = _points(world, first, second, joint)
        span = np.linalg.norm(end - start) * np.copysign(1.0, float(np.dot(end - start, direction))) * direction
        centre = start + about * (end - start)
        inverse = np.linalg.inv(world[joint])
        for closure, point in ((first, centre - about * span), (second, centre + (1.0 - about) * span)):
            placed[id(closure)][joint] = inverse[:3, :3] @ point + inverse[:3, 3]
    turned = []
    for closure in (first, second):
        a, b = np.array(closure.placement_a, dtype=float), np.array(closure.placement_b, dtype=float)
        a[:3, 3], b[:3, 3] = placed[id(closure)][closure.joint_a], placed[id(closure)][closure.joint_b]
        turned.append(replace(closure, placement_a=a, placement_b=b))
    return tuple(turned)


def _joint_model(joint_model, kind: str, axis: NDArray):
    """A joint model like ``joint_model`` (its indices, bounded or not) about or along the unit ``axis``."""
    import pinocchio as pin

    axis = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    if kind == "prismatic":
        made = pin.JointModelPrismaticUnaligned(axis)
    elif joint_model.nq == 2:  # an unbounded hinge: Pinocchio's bindings take its axis only through a file
        text = ('<robot name="r"><link name="a"/><link name="b"/><joint name="j" type="continuous"><parent link="a"/>'
                f'<child link="b"/><axis xyz="{" ".join(repr(float(a)) for a in axis)}"/></joint></robot>')
        made = pin.buildModelFromXML(text).joints[1].extract()
    else:
        made = pin.JointModelRevoluteUnaligned(axis)
    made.setIndexes(joint_model.id, joint_model.idx_q, joint_model.idx_v)
    return made
