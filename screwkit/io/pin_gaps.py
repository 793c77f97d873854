"""A closure left open along its loop's pins: the two anchors of a closure drawn at different depths on parallel
hinges, which no joint values close (:func:`screwkit.io.closed_tree.assemble` reads them on one plane).

A file's rounding sets such anchors apart (each hinge of a loop drawn with its numbers rounded to 6 decimals is up to
half a micrometre off its plane, and a loop adds its hinges' offsets: 1.3e-6 m on a five-bar of 10 cm links, beyond
the :data:`~screwkit.common.tolerances.FILE_ROUNDING` by which a closure may stay open in any direction), and so does
a CAD export, which puts a pin's two mate frames on the two links it joins, millimetres apart along it (a wheel leg's
connects). Either way the anchors are read on one plane (:func:`on_one_plane`): every joint of the loop turns about an
axis along the gap, so no joint values change it, and moving an anchor along the pins moves no hinge's line: the
loop moves as the pin the two frames mark. MuJoCo runs such a file with the gap held open (its ``connect`` pulls
along the pin at every step). The report says how far apart the anchors were; beyond :data:`PIN_DEPTH` of the
length scale the file is refused, naming the depth.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from screwkit.common.tolerances import FILE_ROUNDING
from screwkit.io.tree_joints import joint_frames, joint_kind, path_to

__all__ = ["along_pins", "pin_axis", "depths_drawn_apart", "on_one_plane", "loop_kinds", "ONE_PLANE", "PIN_DEPTH"]

PIN_DEPTH = 0.1
"""Relative to the mechanism's length scale: the largest gap along a loop's parallel pins read as one pin through the
two links it joins (a CAD export's two mate frames, 0.9 to 1.8 % of the length scale on published wheel legs).
Further apart the file is refused, naming the depth: where along a pin a ball closure stands moves the points a
spatial reading takes (by about 1e-4 of the CTI at 4 mm on a 15 cm linkage, by a third at twice its size)."""
CLOSED = 1e-10
"""Relative: a closure whose frames are at most this apart (the assembly's own tolerance) is left where it is."""
ONE_PLANE = "closure frames drawn at different depths on their loops' pins read on one plane"
"""How the note of :func:`on_one_plane` begins."""

PARALLEL = 1e-3
"""Sine (about 0.06 deg) below which the loop's hinge axes, and its gap, count as along one direction."""


def along_pins(model, q: NDArray, first: NDArray, second: NDArray, kinds: list, scale: float, moved: bool = False
               ) -> str:
    """What to say of a closure left open at q (its two frames ``first``, ``second``, 4x4 in the world) where its
    gap lies along its loop's hinges, all parallel: ``kinds``, (joint, kind, local axis) of the loop's joints;
    ``scale``, the mechanism's length scale (:func:`pin_axis`); ``moved``, whether the closures were read on one
    plane already (:func:`on_one_plane`); else ''."""
    if pin_axis(model, q, first, second, kinds, scale) is None:
        return ""
    hinges = ", ".join(model.names[joint] for joint, _, _ in kinds)
    depth = float(np.linalg.norm(first[:3, 3] - second[:3, 3])) / scale
    said = (f": its gap lies along the parallel axes of its loop's hinges ({hinges}), its two anchors drawn at "
            f"different depths on one pin ({depth:.2g} of the length scale apart")
    if moved:
        return said + "), which no joint values close, and read on one plane the loop still did not close"
    return (said + f", more than the {PIN_DEPTH:g} read as the two layers of one pin), which no joint values close: "
            "moved along the pin onto one plane (the closure's frame: an MJCF connect's anchor or site, a robot.yaml "
            "or SDFormat closing frame), the loop closes")


def pin_axis(model, q: NDArray, first: NDArray, second: NDArray, kinds: list, scale: float) -> NDArray | None:
    """The world axis (unit) of the loop's hinges at q when they are all parallel, its slides (if any) across them and
    the closure's gap along them (:data:`PARALLEL`; or across them by at most
    :data:`~screwkit.common.tolerances.FILE_ROUNDING` of the length ``scale``, what the assembly leaves open in any
    direction: an R-P-R/R-P-R written to 6 decimals was left 2.9e-9 m across its pins, 5e-3 of its gap of 5.9e-7 m
    along them), else None (as :func:`along_pins`)."""
    world = joint_frames(model, q)
    axes = [world[joint][:3, :3] @ axis for joint, kind, axis in kinds if kind == "revolute"]
    slides = [world[joint][:3, :3] @ axis for joint, kind, axis in kinds if kind == "prismatic"]
    gap = first[:3, 3] - second[:3, 3]
    if len(axes) < 2 or len(axes) + len(slides) < len(kinds) or not np.linalg.norm(gap) > 0:
        return None
    off = np.linalg.norm(np.cross(axes[0], gap))
    across = [np.linalg.norm(np.cross(axes[0], axis)) for axis in axes] + [
        off / np.linalg.norm(gap) if off > FILE_ROUNDING * scale else 0.0] + [
        abs(float(axes[0] @ slide)) / np.linalg.norm(slide) for slide in slides]  # (slides across the pins)
    return None if max(across) > PARALLEL else axes[0] / np.linalg.norm(axes[0])


def depths_drawn_apart(model, q: NDArray, frames: list, loops: list[list], scale: float) -> list[NDArray] | None:
    """The world offsets along the pins that put each closure's second frame on its first's plane at q, where
    every closure left open at q is open along its loop's pins only (:func:`pin_axis`), by at most :data:`PIN_DEPTH`
    times ``scale`` (a zero offset for a closure that closes, or that stays open by a file's rounding in another
    direction: :data:`~screwkit.common.tolerances.FILE_ROUNDING` of ``scale``, which the assembly accepts); else None.
    ``frames``: each closure's two world frames at q; ``loops``: each closure's loop, as the ``kinds`` of
    :func:`along_pins`; ``scale``: the mechanism's length scale."""
    offsets = []
    for (first, second), kinds in zip(frames, loops):
        gap = first[:3, 3] - second[:3, 3]
        axis = pin_axis(model, q, first, second, kinds, scale) if np.linalg.norm(gap) > CLOSED * scale else None
        if axis is None and not np.linalg.norm(gap) > FILE_ROUNDING * scale:
            offsets.append(np.zeros(3))
            continue
        if axis is None or np.linalg.norm(gap) > PIN_DEPTH * scale:
            return None
        offsets.append(axis * float(axis @ gap))  # (the joints close what lies across the pins)
    return offsets


def loop_kinds(model, closure) -> list[tuple]:
    """The joints of ``closure``'s loop (those on one of its two frames' paths from the root only), as the ``kinds``
    of :func:`along_pins`: (joint, kind, local axis)."""
    return [(j, *joint_kind(model, j)) for j in sorted(set(path_to(model, closure.joint_a))
                                                      ^ set(path_to(model, closure.joint_b)))]


def on_one_plane(tree, q: NDArray, scale: float, found: list) -> bool:
    """Whether the closures of ``tree`` (a :class:`~screwkit.io.closed_tree.ClosedTree`) left open at q were open
    along their loops' pins only (:func:`depths_drawn_apart`): each one's two frames are then moved along the pins
    onto the plane midway between them (the same whichever end the file names first), in ``tree`` (once: a tree
    whose note says so is not moved again; its closures and notes are new lists), and a note says how far apart they
    were. ``found``: each closure with its two world frames at q (:func:`~screwkit.io.closed_tree.closure_frames`)."""
    if any(note.startswith(ONE_PLANE) for note in tree.notes):
        return False
    offsets = depths_drawn_apart(tree.model, q, [(first, second) for _, first, second in found],
                                 [loop_kinds(tree.model, closure) for closure in tree.closures], scale)
    if offsets is None:
        return False
    closures = []
    for (closure, first, second), offset in zip(found, offsets):  # both frames onto the plane midway between them
        placements = [np.array(placement, dtype=float) for placement in (closure.placement_a, closure.placement_b)]
        for placement, frame, sign in zip(placements, (first, second), (-0.5, 0.5)):
            placement[:3, 3] += placement[:3, :3] @ frame[:3, :3].T @ (sign * offset)  # (in the joint's frame)
        closures.append(replace(closure, placement_a=placements[0], placement_b=placements[1]))
    most = int(np.argmax([np.linalg.norm(offset) for offset in offsets]))
    # new lists, not the old ones changed: a tree copied to be assembled from elsewhere shares them with its original
    tree.closures = closures
    depth = float(np.linalg.norm(offsets[most]))
    tree.notes = [*tree.notes, f"{ONE_PLANE} (closure {closures[most].name!r} the most, {depth:.2g} {tree.unit}, "
                               f"{depth / scale:.2g} of the length scale: no joint values close a gap along the pins)"]
    return True
