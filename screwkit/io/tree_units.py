"""A closed tree read in the length unit its file is written in, brought to metres (``--length-unit``).

MJCF, SDFormat and URDF say their lengths are metres; a file written in millimetres all the same (a CAD export)
is read in its own numbers, so its poses, its singularity threshold and everything shown in metres would be a
thousand times off. :func:`in_metres` scales such a tree: every joint placement and frame placement, each
closure's two placements, and the values and limits of the joints that move along a length (prismatic joints,
the translations of planar, translation and free-flyer joints). Angles are unchanged, and so are the indices
(they are dimensionless): only what is measured in metres changes.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from screwkit.common.units import metres_per
from screwkit.io.closed_tree import LENGTH_COORDINATES, ClosedTree, Closure, ImportError_

__all__ = ["in_metres", "LENGTH_COORDINATES"]
_ANGULAR = ("JointModelR", "JointModelSpherical", "JointModelUniversal")


def in_metres(tree: ClosedTree, unit: str | None) -> ClosedTree:
    """``tree`` with its lengths, written in ``unit`` (``"mm"``, ...; None or ``"m"``: as it is), in metres."""
    if unit in (None, "m"):
        return tree
    factor = metres_per(unit)
    model = tree.model.copy()
    q = np.array(tree.q_reference, dtype=float)
    for joint in range(1, model.njoints):
        placement = model.jointPlacements[joint]
        model.jointPlacements[joint] = type(placement)(placement.rotation, placement.translation * factor)
        kind = model.joints[joint].shortname()
        lengths = LENGTH_COORDINATES.get(kind, 0)
        if not lengths and not kind.startswith(_ANGULAR):
            raise ImportError_(f"{tree.source}: --length-unit {unit}: joint {model.names[joint]!r} is a {kind}, "
                               "whose lengths are not known to screwkit.")
        start = model.joints[joint].idx_q
        q[start:start + lengths] *= factor
        for bounds in (model.lowerPositionLimit, model.upperPositionLimit):
            bounds[start:start + lengths] *= factor  # (infinite bounds stay so)
    for index in range(len(model.frames)):
        frame = model.frames[index]
        frame.placement = type(frame.placement)(frame.placement.rotation, frame.placement.translation * factor)
        model.frames[index] = frame

    def scaled(matrix):
        matrix = np.array(matrix, dtype=float)
        matrix[:3, 3] *= factor
        return matrix

    closures = [Closure(c.name, c.joint_a, scaled(c.placement_a), c.joint_b, scaled(c.placement_b), c.kind,
                        c.axis_point) for c in tree.closures]
    return replace(tree, model=model, closures=closures, q_reference=q, length_unit=unit,
                   joint_points=None if tree.joint_points is None else tree.joint_points * factor,
                   notes=[*tree.notes, f"lengths read in {unit} (--length-unit) and used in m"])
