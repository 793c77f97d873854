"""The plane the legs of a star move in (:mod:`screwkit.io.star`): the common normal of their revolute axes, to the
file's rounding, and what a planar mechanism changes in its legs (ball loops become pins about the normal) and in its
output (the point where the closures meet, in the plane).

The rounding is the file's: :data:`~screwkit.common.tolerances.FILE_ROUNDING` between every two axes, widened between
the axes of two joints that the file's angles written by hand turn apart (:mod:`screwkit.io.written_angles`).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from screwkit.common.tolerances import FILE_ROUNDING
from screwkit.io.closed_tree import ClosedTree, joint_kind
from screwkit.io.rounding import plane_normal
from screwkit.io.written_angles import WrittenTurns

__all__ = ["planar_normal", "joint_axes", "nearly_planar", "planar_loops", "idle_about_the_meeting_point", "in_plane"]


def planar_normal(tree: ClosedTree, data, legs: list, turns: WrittenTurns) -> NDArray | None:
    """The common direction of every revolute axis when slides are perpendicular to it, to the file's rounding
    (``turns``: :func:`~screwkit.io.rounding.plane_normal`), else None. Ball loops (a ``connect``) do not count: in
    a mechanism whose other joints all move in one plane, only their rotation about the plane's normal moves
    (:func:`planar_loops` writes them so)."""
    axes = joint_axes(tree, data, legs)
    revolutes = [(axis, name) for kind, axis, name in axes if kind == "revolute"]
    prismatics = [(axis, name) for kind, axis, name in axes if kind == "prismatic"]
    names = [name for _, name in revolutes]
    slides = [max((turns.allowance(name, other) for other in names), default=FILE_ROUNDING) for _, name in prismatics]
    return plane_normal([axis for axis, _ in revolutes], [axis for axis, _ in prismatics], turns.allowances(names),
                        np.array(slides))


def joint_axes(tree: ClosedTree, data, legs: list) -> list[tuple[str, NDArray, str | None]]:
    """Every leg joint's kind, world axis and name, its loop joint's but a ball's (no name)."""
    axes = []
    for leg in legs:
        for joint in leg.joints:
            kind, axis = joint_kind(tree.model, joint)
            axes.append((kind, np.asarray(data.oMi[joint].rotation) @ axis, tree.model.names[joint]))
        if leg.loop != "spherical":
            names = leg.loop_names if len(leg.loop_names) == len(leg.loop_dofs) else (None,) * len(leg.loop_dofs)
            axes += [(kind, axis, name) for (kind, axis, _), name in zip(leg.loop_dofs, names)]
    return axes


def nearly_planar(tree: ClosedTree, data, legs: list, turns: WrittenTurns) -> str:
    """Where a mechanism is not planar only because two revolute axes are out of parallel by less than a degree,
    more than the file's rounding allows them (``turns``), what says so: the two furthest beyond it."""
    revolutes = [(axis, name) for kind, axis, name in joint_axes(tree, data, legs) if kind == "revolute"]
    names = [name for _, name in revolutes]
    beyond = turns.furthest_beyond(np.reshape([axis for axis, _ in revolutes], (-1, 3)), names)
    if beyond is None or beyond[2] >= np.radians(1.0):
        return ""
    which = " and ".join(repr(tree.written_joint(names[k])) if names[k] else "a loop's" for k in beyond[:2])
    return (f" (revolute axes {which} are {np.degrees(beyond[2]):.2g} deg out of parallel, more than the file's "
            f"rounding allows them: {np.degrees(beyond[3]):.2g} deg"
            f"{f', its angles written as {turns.example}' if turns.example else ''})")


def planar_loops(legs: list, normal: NDArray) -> None:
    """In a planar mechanism, every ball loop becomes the revolute joint about the plane's normal through its
    centre: its two other rotations would turn legs out of the plane, which their joints forbid."""
    for leg in legs:
        if leg.base_dofs:
            leg.base_dofs = [("revolute", normal, leg.base_dofs[0][2])]
        if leg.loop == "spherical":
            centre = leg.successor_world[:3, 3]
            leg.loop = "revolute"
            leg.axis = leg.successor_world[:3, :3].T @ normal  # in the loop frame
            leg.loop_dofs = [("revolute", normal, centre)]


def idle_about_the_meeting_point(legs: list, normal: NDArray | None) -> bool:
    """Whether every leg of ``legs`` (those meeting the platform at a loop joint) joins it by every rotation about the
    point where they meet (a ball, or in a plane a pin about the normal): the platform's rotations about that point
    are then idle, and the output is the point. A weld or a pin in another direction makes them the actuators' to
    control."""
    for leg in legs:
        if leg.loop == "spherical" and normal is None:
            continue
        if leg.loop == "revolute" and normal is not None and \
                abs(abs(float(leg.loop_dofs[0][1] @ normal)) - 1.0) < 1e-9:
            continue
        return False
    return True


def in_plane(vector: NDArray, normal: NDArray | None) -> NDArray:
    """``vector`` without its component along the plane's ``normal`` (all of it in space: no normal)."""
    return vector if normal is None else vector - (vector @ normal) * normal
