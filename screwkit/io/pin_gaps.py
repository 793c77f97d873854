"""A closure left open along its loop's pins: the two anchors of a closure drawn at different depths on parallel
hinges (a CAD export's), which no joint values close (:func:`screwkit.io.closed_tree.assemble` says so)."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["along_pins"]

PARALLEL = 1e-3
"""Sine (about 0.06 deg) below which the loop's hinge axes, and its gap, count as along one direction."""


def along_pins(model, q: NDArray, first: NDArray, second: NDArray, kinds: list) -> str:
    """What to say of a closure left open at q (its two frames ``first``, ``second``, 4x4 in the world) where its
    gap lies along its loop's hinges, all parallel: ``kinds``, (joint, kind, local axis) of the loop's joints; else
    ''."""
    import pinocchio as pin  # Pinocchio: imported where a file of another tool is read

    data = model.createData()
    pin.forwardKinematics(model, data, q)
    axes = [np.asarray(data.oMi[joint].rotation) @ axis for joint, kind, axis in kinds if kind == "revolute"]
    gap = first[:3, 3] - second[:3, 3]
    if len(axes) < 2 or len(axes) < len(kinds) or not np.linalg.norm(gap) > 0:
        return ""
    across = [np.linalg.norm(np.cross(axes[0], axis)) for axis in axes] + [
        np.linalg.norm(np.cross(axes[0], gap)) / np.linalg.norm(gap)]
    if max(across) > PARALLEL:
        return ""
    hinges = ", ".join(model.names[joint] for joint, _, _ in kinds)
    return (f": its gap lies along the parallel axes of its loop's hinges ({hinges}), its two anchors drawn at "
            "different depths on one pin, which no joint values close: moved along the pin onto one plane (the "
            "connect's anchor or site), the loop closes")
