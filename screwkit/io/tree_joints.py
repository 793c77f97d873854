"""The joints of a Pinocchio tree as the readers of closed trees see them: kinds and axes, values, paths from the root,
placements as matrices; and :class:`ImportError_`, what a reader raises for a file it cannot write in screwkit's
convention. Kept below :mod:`screwkit.io.closed_tree`, which re-exports them, so that its helpers
(:mod:`screwkit.io.pin_gaps`) can use them without importing it."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["ImportError_", "homogeneous", "inverse", "joint_frames", "joint_kind", "joint_value", "path_to"]


class ImportError_(ValueError):
    """A file of another tool that cannot be written in screwkit's convention (the message says why); ``reason``:
    its cause in one clause, for a refusal that quotes it (a leg's stage refused because one of its actuators cannot
    be read), else empty."""

    def __init__(self, message: str, reason: str = "") -> None:
        super().__init__(message)
        self.reason = reason


def homogeneous(placement) -> NDArray[np.float64]:
    """A Pinocchio placement (SE3) as a 4x4 matrix (a new array)."""
    return np.array(placement.homogeneous, dtype=float)


def joint_frames(model, q: NDArray) -> list[NDArray]:
    """Every joint's frame (4x4, world) of the Pinocchio ``model`` at its configuration ``q``."""
    import pinocchio as pin  # Pinocchio: imported where a file of another tool is read

    data = model.createData()
    pin.forwardKinematics(model, data, np.asarray(q, dtype=float))
    return [homogeneous(data.oMi[joint]) for joint in range(model.njoints)]


def inverse(matrix: NDArray) -> NDArray:
    """The inverse of a 4x4 rigid transform."""
    out = np.eye(4)
    out[:3, :3] = matrix[:3, :3].T
    out[:3, 3] = -matrix[:3, :3].T @ matrix[:3, 3]
    return out


def joint_kind(model, joint: int) -> tuple[str, NDArray | None]:
    """("revolute" | "prismatic" | "spherical" | other shortname, unit axis in the joint frame or None)."""
    joint_model = model.joints[joint]
    name = joint_model.shortname()
    for prefix, kind in (("JointModelRevoluteUnbounded", "revolute"), ("JointModelRevolute", "revolute"),
                         ("JointModelPrismatic", "prismatic")):
        if name.startswith(prefix):
            if name == "JointModelRevoluteUnboundedUnaligned":  # (Pinocchio 4.1's bindings give it no axis: its
                joint_data = joint_model.createData()  # motion subspace's rotation is the axis)
                joint_model.calc(joint_data, np.array([1.0, 0.0]))
                axis = np.asarray(joint_data.S, dtype=float).reshape(6, -1)[3:, 0]
            else:
                axis = np.asarray(joint_model.extract().axis, dtype=float)
            if not np.linalg.norm(axis) > 0.0:  # refused where the source is known (assemble); a net here
                raise ImportError_(f"<joint name='{model.names[joint]}'>: the axis is the zero vector.")
            return kind, axis / np.linalg.norm(axis)
    for prefix, kind in (("JointModelRUB", "revolute"), ("JointModelR", "revolute"), ("JointModelP", "prismatic")):
        if name.startswith(prefix) and name[-1] in "XYZ" and len(name) == len(prefix) + 1:
            return kind, np.eye(3)["XYZ".index(name[-1])]
    if name == "JointModelSpherical":
        return "spherical", None
    return name, None


def joint_value(model, joint: int, q: NDArray) -> float:
    """The value (rad or m) of a 1-DoF joint in configuration q (an unbounded revolute's angle from cos, sin)."""
    joint_model = model.joints[joint]
    values = q[joint_model.idx_q:joint_model.idx_q + joint_model.nq]
    return float(np.arctan2(values[1], values[0])) if joint_model.nq == 2 else float(values[0])


def path_to(model, joint: int) -> list[int]:
    """Joints from the root to ``joint`` (included), root side first."""
    path = []
    while joint != 0:
        path.append(joint)
        joint = model.parents[joint]
    return path[::-1]
