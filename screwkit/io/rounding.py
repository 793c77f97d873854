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
(then they are made parallel, and its indices move by about that much, 1e-7).

Where a hinge is drawn along its axis is not the mechanism either; the indices take no account of it (the
characteristic points lie where the wrench's axis comes nearest to the joint's axis:
:func:`screwkit.screw.algebra.nearest_on_axis`), so nothing here moves a hinge.

This runs once, where a file of another tool is converted (:mod:`screwkit.io.star`).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from screwkit.common.tolerances import FILE_ROUNDING
from screwkit.io.closed_tree import joint_kind

__all__ = ["parallel_axes", "drawn_axes", "EXACT"]

EXACT = 1e-12
"""Directions whose cross product is at most this already agree: a group of them is left as written."""


def parallel_axes(axes: NDArray, tolerance: float = FILE_ROUNDING) -> tuple[NDArray[np.float64], float]:
    """Unit directions (n, 3) with each group of nearly parallel ones made parallel, and the largest turn (rad).

    Two directions are in one group when the norm of their cross product is at most ``tolerance`` (linked
    pairwise: a chain of such pairs is one group).
    """
    axes = np.asarray(axes, dtype=float).reshape(-1, 3)
    units = axes / np.linalg.norm(axes, axis=1, keepdims=True)
    count = units.shape[0]
    parent = list(range(count))

    def find(index: int) -> int:
        while parent[index] != index:
            parent[index] = parent[parent[index]]
            index = parent[index]
        return index

    crosses = np.linalg.norm(np.cross(units[:, None, :], units[None, :, :]), axis=-1)
    for first, second in zip(*np.nonzero(np.triu(crosses <= tolerance, k=1))):
        parent[find(int(first))] = find(int(second))
    result, turn = units.copy(), 0.0
    groups: dict[int, list[int]] = {}
    for index in range(count):
        groups.setdefault(find(index), []).append(index)
    for members in groups.values():
        if len(members) < 2 or float(np.max(crosses[np.ix_(members, members)])) <= EXACT:
            continue
        senses = np.sign(units[members] @ units[members[0]])  # whichever member comes first, each keeps its sense
        direction = np.sum(units[members] * senses[:, None], axis=0)
        direction /= np.linalg.norm(direction)
        result[members] = senses[:, None] * direction
        turn = max(turn, float(np.max(np.linalg.norm(np.cross(units[members], direction), axis=1))))
    return result, turn


def drawn_axes(model, data, legs: list, equivalents: list, report) -> tuple[dict[int, NDArray], list]:
    """The legs' joint axes, loop axes and equivalent chains' rotations with :func:`parallel_axes` applied.

    ``legs``: :mod:`screwkit.io.star`'s legs at the assembly held in ``data``; their loop axes are set in place.
    Returns each 1-DoF joint's axis in its own frame (by joint id) and the equivalent chains with their rotations
    turned; the import ``report`` notes the largest turn.
    """
    owners, directions = [], []
    for leg in legs:
        for joint in leg.joints:
            if joint not in leg.locked:
                owners.append(("joint", joint))
                directions.append(np.asarray(data.oMi[joint].rotation) @ joint_kind(model, joint)[1])
        if leg.loop in ("revolute", "prismatic"):
            owners.append(("loop", leg))
            directions.append(leg.loop_dofs[0][1])
    for index, (_, reduction, _) in enumerate(equivalents):
        owners += [("turn", (index, row)) for row in range(len(reduction.rotations))]
        directions += list(reduction.rotations)
    if not directions:
        return {}, equivalents
    turned, turn = parallel_axes(np.array(directions))
    if turn:
        report.notes.append(f"joint axes that agree to the file's rounding written parallel (the largest turn "
                            f"{turn:.2g} rad)")
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
    return local, equivalents
