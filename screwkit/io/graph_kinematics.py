r"""A closed-loop graph at many configurations at once: forward kinematics, joint twists and closure solving.

:mod:`screwkit.io.graph` analyses a closed tree (a Pinocchio model and its closures) at one configuration through
Pinocchio. Sweeps and maps need it at thousands of platform poses, each closed by Newton's method: this module
does the same computations batched over configurations with numpy, from the model's joint placements, types and
axes read once (:class:`TreeKinematics`), so that no Python loop runs per configuration.

* **Joints**: revolute (bounded, or unbounded with ``(cos, sin)`` as Pinocchio stores it), prismatic, ball
  (``JointModelSpherical``: a unit quaternion ``(x, y, z, w)``, angular velocity in the joint frame) and free
  (``JointModelFreeFlyer``: position and quaternion, velocity in the joint frame, linear part first) -- what URDF,
  MJCF and onshape-to-robot files give. Any other joint type is refused by name.
* **Forward kinematics** ``oMi = oMi[parent] placement M_j(q_j)`` as Pinocchio composes it; the world twist of
  each velocity coordinate ``(omega, v)``, ``v`` the velocity of the point at the world origin (Pinocchio's
  ``WORLD`` Jacobian, halves swapped).
* **Closure solving** (:func:`solve_poses`): Levenberg-Marquardt on the joint velocities, residuals the closures'
  gaps (origins in units of the length scale, and for ``6d`` closures the rotation vector between the frames)
  and the output frame's task coordinates (position in units of the length scale, roll-pitch-yaw angles), the
  damped least-change step ``-J^T (J J^T + lambda I)^{-1} r``. A pose is reached by continuation from the
  configuration given (the file's): its task coordinates move in equal stages along the straight line to the
  target, each stage closed before the next, so the working mode is the one reached by moving the platform
  straight from the file's configuration -- the same rule for one pose (:meth:`GraphMechanism.at_pose`) and for a
  batch. A pose whose closures cannot be closed, or that puts a joint beyond its limits, is unreachable.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from screwkit.closure.solve import slackened
from screwkit.common.rotations import cross
from screwkit.io.closed_tree import ASSEMBLY_TOLERANCE, ClosedTree, Closure, ImportError_, joint_kind, path_to

__all__ = ["TreeKinematics", "solve_poses", "beyond_limits", "joints_beyond_limits", "reach_bound", "rpy_of",
           "rpy_rates_inverse", "STAGE_LENGTH",
           "MAX_ITERATIONS", "STAGE_TOLERANCE", "FINAL_TOLERANCE"]

STAGE_LENGTH = 0.05
"""Largest move of a continuation stage: task coordinates in units of the length scale, and radians."""
MAX_ITERATIONS = 60
"""Levenberg-Marquardt iterations of the last stage (the stages before take a quarter of them)."""
STAGE_TOLERANCE = 1e-4
"""Residual to which a continuation stage before the last closes its poses: near enough to stay in the working
mode's basin for the next stage (each moves the platform by :data:`STAGE_LENGTH` at most), without the last
Newton steps of a tight closure."""
FINAL_TOLERANCE = 1e-14
"""Residual to which the last stage closes a pose (Newton's last steps are cheap and take the configuration to
rounding); a pose counts as reached below
:data:`~screwkit.io.closed_tree.ASSEMBLY_TOLERANCE` times ten, or the residual the file's own configuration
keeps."""
GIMBAL_LOCK = 1e-4
"""A pose whose roll or yaw is a task coordinate is not reached where the cosine of the output frame's pitch is
below this (within 0.006 deg of +-90 deg): there roll and yaw are one angle, and Newton meets any value of either
(a foot held in roll met 120 and 170 deg at one configuration, 1.7e-6 and 8e-7 from the lock)."""


def _rotation(axis: NDArray, angle: NDArray) -> NDArray:
    """Rotations (n, 3, 3) about a unit axis (3,) by angles (n,) (Rodrigues)."""
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    s, c = np.sin(angle)[:, None, None], np.cos(angle)[:, None, None]
    return np.eye(3) + s * k + (1.0 - c) * (k @ k)


def _quaternion_matrix(quaternion: NDArray, out: NDArray | None = None) -> NDArray:
    """Rotations (n, 3, 3) of unit quaternions (n, 4) in Pinocchio's order (x, y, z, w), into ``out`` if given (a
    view: written entry by entry, without stacking)."""
    x, y, z, w = np.moveaxis(quaternion / np.linalg.norm(quaternion, axis=-1, keepdims=True), -1, 0)
    out = np.empty(quaternion.shape[:-1] + (3, 3)) if out is None else out
    out[..., 0, 0], out[..., 0, 1], out[..., 0, 2] = 1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)
    out[..., 1, 0], out[..., 1, 1], out[..., 1, 2] = 2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)
    out[..., 2, 0], out[..., 2, 1], out[..., 2, 2] = 2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)
    return out


def _quaternion_step(quaternion: NDArray, omega: NDArray) -> NDArray:
    """q * exp(omega / 2) for quaternions (n, 4) (x, y, z, w) and rotation vectors (n, 3) in the body frame."""
    angle = np.linalg.norm(omega, axis=-1)
    half = angle / 2
    factor = np.where(angle > 1e-12, np.sin(half) / np.where(angle > 1e-12, angle, 1.0), 0.5)
    dx, dy, dz = np.moveaxis(omega * factor[:, None], -1, 0)
    dw = np.cos(half)
    x, y, z, w = np.moveaxis(quaternion, -1, 0)
    out = np.stack([w * dx + x * dw + y * dz - z * dy, w * dy - x * dz + y * dw + z * dx,
                    w * dz + x * dy - y * dx + z * dw, w * dw - x * dx - y * dy - z * dz], -1)
    return out / np.linalg.norm(out, axis=-1, keepdims=True)


def rpy_of(rotation: NDArray) -> NDArray:
    """Roll, pitch, yaw (..., 3) of rotations (..., 3, 3), R = Rz(yaw) Ry(pitch) Rx(roll)."""
    return np.stack([np.arctan2(rotation[..., 2, 1], rotation[..., 2, 2]),
                     np.arcsin(np.clip(-rotation[..., 2, 0], -1.0, 1.0)),
                     np.arctan2(rotation[..., 1, 0], rotation[..., 0, 0])], -1)


def rpy_rates_inverse(rpy: NDArray) -> NDArray:
    """(n, 3, 3): roll, pitch, yaw rates from the world angular velocity (singular at pitch = +-90 deg)."""
    pitch, yaw = rpy[:, 1], rpy[:, 2]
    cp = np.cos(pitch)
    cp = np.where(np.abs(cp) < 1e-12, 1e-12, cp)
    cy, sy, tp = np.cos(yaw), np.sin(yaw), np.tan(pitch)
    zero = np.zeros_like(yaw)
    return np.stack([np.stack([cy / cp, sy / cp, zero], -1),
                     np.stack([-sy, cy, zero], -1),
                     np.stack([cy * tp, sy * tp, np.ones_like(yaw)], -1)], -2)


@dataclass(frozen=True)
class TreeKinematics:
    """What batched kinematics need of a Pinocchio model: per joint its parent, placement in the parent (4x4),
    kind (``revolute``, ``unbounded``, ``prismatic``, ``ball``, ``free``), unit axis and indices into q and v."""

    parents: tuple[int, ...]
    placements: NDArray[np.float64]
    kinds: tuple[str, ...]
    axes: NDArray[np.float64]
    idx_q: tuple[int, ...]
    idx_v: tuple[int, ...]
    nq: int
    nv: int
    column_joint: NDArray[np.int64]  # the joint of each velocity coordinate
    lower: NDArray[np.float64]  # position limits of 1-DoF joints per velocity coordinate (-inf/+inf: none)
    upper: NDArray[np.float64]

    @classmethod
    def of(cls, model, source: str = "") -> TreeKinematics:
        placements, kinds, axes = [np.eye(4)], ["root"], [np.zeros(3)]
        column_joint = []
        lower, upper = np.full(model.nv, -np.inf), np.full(model.nv, np.inf)
        for joint in range(1, model.njoints):
            placement = model.jointPlacements[joint]
            matrix = np.eye(4)
            matrix[:3, :3], matrix[:3, 3] = np.asarray(placement.rotation), np.asarray(placement.translation)
            placements.append(matrix)
            kind, axis = joint_kind(model, joint)
            joint_model = model.joints[joint]
            if kind == "revolute" and joint_model.nq == 2:
                kind = "unbounded"
            elif kind == "spherical":
                kind = "ball"
            elif kind == "JointModelFreeFlyer":
                kind = "free"
            elif kind not in ("revolute", "prismatic"):
                raise ImportError_(f"{source}: joint {model.names[joint]!r} is a {kind}: screwkit solves graphs of "
                                   "revolute, prismatic, ball and free joints.")
            kinds.append(kind)
            axes.append(np.zeros(3) if axis is None else np.asarray(axis, dtype=float))
            column_joint += [joint] * joint_model.nv
            if kind in ("revolute", "prismatic"):
                q_index, v_index = joint_model.idx_q, joint_model.idx_v
                low, high = float(model.lowerPositionLimit[q_index]), float(model.upperPositionLimit[q_index])
                if low < high:  # Pinocchio's defaults are huge: finite only where the file sets them
                    lower[v_index], upper[v_index] = low, high
        return cls(tuple(int(p) for p in model.parents), np.array(placements), tuple(kinds), np.array(axes),
                   tuple(int(model.joints[j].idx_q) if j else 0 for j in range(model.njoints)),
                   tuple(int(model.joints[j].idx_v) if j else 0 for j in range(model.njoints)),
                   int(model.nq), int(model.nv), np.array(column_joint, dtype=np.int64), lower, upper)

    def transforms(self, q: NDArray) -> NDArray[np.float64]:
        """World placements (n, njoints, 4, 4) of every joint frame at configurations q (n, nq)."""
        count = q.shape[0]
        out = np.empty((count, len(self.parents), 4, 4))
        out[:, 0] = np.eye(4)
        for joint in range(1, len(self.parents)):
            local = np.broadcast_to(self.placements[joint], (count, 4, 4)).copy()
            kind, start, axis = self.kinds[joint], self.idx_q[joint], self.axes[joint]
            motion = np.zeros((count, 4, 4))
            motion[:, 3, 3] = 1.0
            if kind == "revolute":
                motion[:, :3, :3] = _rotation(axis, q[:, start])
            elif kind == "unbounded":
                motion[:, :3, :3] = _rotation(axis, np.arctan2(q[:, start + 1], q[:, start]))
            elif kind == "prismatic":
                motion[:, :3, :3] = np.eye(3)
                motion[:, :3, 3] = q[:, start, None] * axis
            elif kind == "ball":
                _quaternion_matrix(q[:, start:start + 4], out=motion[:, :3, :3])
            else:  # free
                _quaternion_matrix(q[:, start + 3:start + 7], out=motion[:, :3, :3])
                motion[:, :3, 3] = q[:, start:start + 3]
            out[:, joint] = out[:, self.parents[joint]] @ local @ motion
        return out

    def twists(self, transforms: NDArray) -> NDArray[np.float64]:
        """World twists (n, nv, 6) ``(omega, v at the world origin)`` of every velocity coordinate."""
        count = transforms.shape[0]
        out = np.zeros((count, self.nv, 6))
        for joint in range(1, len(self.parents)):
            rotation, origin = transforms[:, joint, :3, :3], transforms[:, joint, :3, 3]
            start, kind = self.idx_v[joint], self.kinds[joint]
            if kind in ("revolute", "unbounded"):
                omega = rotation @ self.axes[joint]
                out[:, start, :3], out[:, start, 3:] = omega, cross(origin, omega)
            elif kind == "prismatic":
                out[:, start, 3:] = rotation @ self.axes[joint]
            else:
                turn = start + (3 if kind == "free" else 0)
                for k in range(3):
                    omega = rotation[:, :, k]
                    out[:, turn + k, :3], out[:, turn + k, 3:] = omega, cross(origin, omega)
                    if kind == "free":
                        out[:, start + k, 3:] = omega
        return out

    def integrate(self, q: NDArray, step: NDArray) -> NDArray[np.float64]:
        """q moved by velocity coordinates ``step`` (n, nv) over unit time, as Pinocchio integrates each joint."""
        out = q.copy()
        for joint in range(1, len(self.parents)):
            start, velocity, kind = self.idx_q[joint], self.idx_v[joint], self.kinds[joint]
            if kind in ("revolute", "prismatic"):
                out[:, start] += step[:, velocity]
            elif kind == "unbounded":
                angle = np.arctan2(q[:, start + 1], q[:, start]) + step[:, velocity]
                out[:, start], out[:, start + 1] = np.cos(angle), np.sin(angle)
            elif kind == "ball":
                out[:, start:start + 4] = _quaternion_step(q[:, start:start + 4], step[:, velocity:velocity + 3])
            else:  # free: the position moves by the body-frame velocity turned into the world, to first order
                rotation = _quaternion_matrix(q[:, start + 3:start + 7])
                out[:, start:start + 3] += np.einsum("nij,nj->ni", rotation, step[:, velocity:velocity + 3])
                out[:, start + 3:start + 7] = _quaternion_step(q[:, start + 3:start + 7],
                                                               step[:, velocity + 3:velocity + 6])
        return out

    def supports(self, model, joint: int) -> NDArray[np.bool_]:
        """(nv,) which velocity coordinates move ``joint``'s body (those of the joints on its path from the root)."""
        on_path = set(path_to(model, joint))
        return np.array([int(j) in on_path for j in self.column_joint], dtype=bool)


def _rotation_vector(rotation: NDArray) -> NDArray:
    """Rotation vectors (n, 3) of rotations (n, 3, 3) of less than half a turn (log map)."""
    cosine = np.clip((np.trace(rotation, axis1=-2, axis2=-1) - 1.0) / 2.0, -1.0, 1.0)
    angle = np.arccos(cosine)
    sine = np.sin(angle)
    factor = np.where(sine > 1e-9, angle / (2 * np.where(sine > 1e-9, sine, 1.0)), 0.5)
    return factor[:, None] * np.stack([rotation[:, 2, 1] - rotation[:, 1, 2], rotation[:, 0, 2] - rotation[:, 2, 0],
                                       rotation[:, 1, 0] - rotation[:, 0, 1]], -1)


@dataclass(frozen=True)
class _Residual:
    """Closure residuals and their Jacobian, batched (lengths in units of the length scale)."""

    model: object
    kinematics: TreeKinematics
    closures: tuple[Closure, ...]
    frame_joint: int
    frame_placement: NDArray[np.float64]
    task_axes: tuple[int, ...]  # among x, y, z, roll, pitch, yaw of the output frame
    scale: float
    unit: NDArray[np.float64]  # velocity-coordinate units: the length scale for a translation, 1 for a rotation
    paths: dict = field(default_factory=dict)  # joint -> the velocity coordinates that move its body (a cache)

    def columns(self, joint: int) -> NDArray[np.int64]:
        """Velocity coordinates that move ``joint``'s body (none for the base)."""
        return self._path(joint)[0]

    def runs(self, joint: int) -> tuple[tuple[slice, slice], ...]:
        """The columns of :meth:`columns` as runs of consecutive coordinates: ``(in the Jacobian, in the columns)``,
        so that the Jacobian is written through views, not through a fancy index (the same numbers, faster)."""
        return self._path(joint)[1]

    def _path(self, joint: int):
        if joint not in self.paths:
            columns = np.flatnonzero(self.kinematics.supports(self.model, joint)) if joint else np.zeros(
                0, dtype=np.int64)
            cuts = [0, *(np.flatnonzero(np.diff(columns) != 1) + 1).tolist(), columns.size] if columns.size else []
            runs = tuple((slice(int(columns[a]), int(columns[b - 1]) + 1), slice(a, b)) for a, b in zip(cuts, cuts[1:]))
            self.paths[joint] = (columns, runs)
        return self.paths[joint]

    def frame(self, transforms: NDArray) -> NDArray:
        return transforms[:, self.frame_joint] @ self.frame_placement

    def __call__(self, q: NDArray, target: NDArray, jacobian: bool = True):
        count = q.shape[0]
        transforms = self.kinematics.transforms(q)
        rows: list[NDArray] = []
        height = sum(6 if closure.kind == "6d" else 3 for closure in self.closures) + len(self.task_axes)
        matrix = np.zeros((count, height, self.kinematics.nv)) if jacobian else None
        if jacobian:  # every twist in the units of the unknowns (a translation's per length scale)
            twists = self.kinematics.twists(transforms) * self.unit[None, :, None]
            twists[..., 3:] /= self.scale  # velocities in units of the length scale
        top = 0
        for closure in self.closures:
            a = transforms[:, closure.joint_a] @ closure.placement_a
            b = transforms[:, closure.joint_b] @ closure.placement_b
            rows.append((b[:, :3, 3] - a[:, :3, 3]) / self.scale)
            if closure.kind == "6d":
                rows.append(np.einsum("nij,nj->ni", a[:, :3, :3],
                                      _rotation_vector(np.swapaxes(a[:, :3, :3], 1, 2) @ b[:, :3, :3])))
            if jacobian:
                for joint, point, sign in ((closure.joint_b, b[:, :3, 3], 1.0), (closure.joint_a, a[:, :3, 3], -1.0)):
                    columns = self.columns(joint)
                    if not columns.size:
                        continue
                    omega, v = twists[:, columns, :3], twists[:, columns, 3:]
                    at_point = sign * np.swapaxes(v + cross(omega, point[:, None, :] / self.scale), 1, 2)
                    turning = sign * np.swapaxes(omega, 1, 2) if closure.kind == "6d" else None
                    for into, part in self.runs(joint):
                        matrix[:, top:top + 3, into] += at_point[:, :, part]
                        if turning is not None:
                            matrix[:, top + 3:top + 6, into] += turning[:, :, part]
            top += 6 if closure.kind == "6d" else 3
        if self.task_axes:
            frame = self.frame(transforms)
            pose = np.concatenate([frame[:, :3, 3] / self.scale, rpy_of(frame[:, :3, :3])], axis=1)
            gap = pose - np.concatenate([target[:, :3] / self.scale, target[:, 3:]], axis=1)
            gap[:, 3:] = (gap[:, 3:] + np.pi) % (2 * np.pi) - np.pi
            rows.append(gap[:, list(self.task_axes)])
            if jacobian:
                columns = self.columns(self.frame_joint)
                omega, v = twists[:, columns, :3], twists[:, columns, 3:]
                rates = np.concatenate([np.swapaxes(v + cross(omega, frame[:, None, :3, 3] / self.scale), 1, 2),
                                        rpy_rates_inverse(pose[:, 3:]) @ np.swapaxes(omega, 1, 2)], axis=1)
                rates = rates[:, list(self.task_axes)]
                for into, part in self.runs(self.frame_joint):
                    matrix[:, top:, into] = rates[:, :, part]
        return np.concatenate(rows, axis=1), matrix


def _least_squares(residual: _Residual, kinematics: TreeKinematics, q: NDArray, target: NDArray, iterations: int,
                   tolerance: float):
    """Damped Gauss-Newton (Levenberg-Marquardt) from q towards the closures and target; (q, residual norm)."""
    count = q.shape[0]
    damping = np.full(count, 1e-6)
    error, jacobian = residual(q, target)
    norm = np.linalg.norm(error, axis=1)
    for _ in range(iterations):
        active = (norm >= tolerance) & (damping < 1e8)
        if not active.any():
            break
        rows = np.flatnonzero(active)
        j, e = jacobian[rows], error[rows]
        gram = j @ np.swapaxes(j, 1, 2)
        gram += (damping[rows] + norm[rows] ** 2)[:, None, None] * np.eye(gram.shape[-1])
        step = -np.einsum("nji,nj->ni", j, np.linalg.solve(gram, e[:, :, None])[:, :, 0])
        largest = np.max(np.abs(step), axis=1)
        step *= np.minimum(1.0, 0.5 / np.maximum(largest, 1e-300))[:, None]
        candidate = kinematics.integrate(q[rows], step * residual.unit)
        new_error, new_jacobian = residual(candidate, target[rows])
        new_norm = np.linalg.norm(new_error, axis=1)
        better = new_norm < norm[rows]
        accepted = rows[better]
        q[accepted], error[accepted], jacobian[accepted] = candidate[better], new_error[better], new_jacobian[better]
        norm[accepted] = new_norm[better]
        damping[accepted] = np.maximum(damping[accepted] / 10, 1e-12)
        damping[rows[~better]] *= 10
    return q, norm


def reach_bound(kinematics: TreeKinematics, joint: int, placement: NDArray, *, limits: bool = True) -> float:
    """An upper bound (m) on the distance from the world origin of a frame (``placement`` 4x4 in ``joint``) over every
    configuration of the tree, its closures aside: the lengths of the joint placements on its path from the root, and
    of its own, add up (a revolute or ball joint turns about its origin and moves nothing there), plus each prismatic
    joint's largest travel within its limits (``limits`` False: any travel). Infinite when a free joint, or a
    prismatic joint without limits, is on the path."""
    total = float(np.linalg.norm(placement[:3, 3]))
    while joint > 0:
        total += float(np.linalg.norm(kinematics.placements[joint][:3, 3]))
        kind = kinematics.kinds[joint]
        if kind == "free":
            return np.inf
        if kind == "prismatic":
            travel = (kinematics.lower[kinematics.idx_v[joint]], kinematics.upper[kinematics.idx_v[joint]])
            if not limits or not np.all(np.isfinite(travel)):
                return np.inf
            total += float(np.max(np.abs(travel)))
        joint = kinematics.parents[joint]
    return total


def beyond_reach(kinematics: TreeKinematics, joint: int, placement: NDArray, targets: NDArray,
                 task_axes: tuple[int, ...], spare: float, *, limits: bool = True) -> NDArray[np.bool_]:
    """Which ``targets`` (n, 6) hold a position the frame can never reach: farther from the world origin, in the held
    position coordinates, than :func:`reach_bound` plus ``spare`` (m: the residual a reached pose may keep)."""
    held = [axis for axis in task_axes if axis < 3]
    bound = reach_bound(kinematics, joint, placement, limits=limits)
    if not held or not np.isfinite(bound):
        return np.zeros(targets.shape[0], dtype=bool)
    distance = np.linalg.norm(targets[:, held], axis=1)
    return distance > bound * (1.0 + 1e-9) + spare


def solve_poses(tree: ClosedTree, q_start: NDArray, scale: float, frame_id: int, targets: NDArray,
                task_axes: tuple[int, ...], *, limits: bool = True, kinematics: TreeKinematics | None = None,
                limited: NDArray | None = None):
    """Closed configurations (n, nq) putting the output frame's task coordinates at ``targets`` (n, 6: x, y, z in m
    and roll, pitch, yaw in rad, world frame; only ``task_axes`` of them are held), by continuation from the closed
    configuration ``q_start``; and which of them are reached (closures closed, joints within their limits: those of
    the velocity coordinates ``limited``, a mask (nv,), when given; a graph's, its legs')."""
    model = tree.model
    kinematics = TreeKinematics.of(model, tree.source) if kinematics is None else kinematics
    frame = model.frames[frame_id]
    placement = np.eye(4)
    placement[:3, :3], placement[:3, 3] = np.asarray(frame.placement.rotation), np.asarray(frame.placement.translation)
    translating = np.array([kinematics.kinds[j] == "prismatic" for j in kinematics.column_joint], dtype=bool)
    free_linear = np.zeros(kinematics.nv, dtype=bool)
    for joint, kind in enumerate(kinematics.kinds):
        if kind == "free":
            free_linear[kinematics.idx_v[joint]:kinematics.idx_v[joint] + 3] = True
    unit = np.where(translating | free_linear, scale, 1.0)
    residual = _Residual(model, kinematics, tuple(tree.closures), int(frame.parentJoint), placement,
                         tuple(task_axes), scale, unit)
    targets = np.asarray(targets, dtype=float).reshape(-1, 6)
    count = targets.shape[0]
    start = np.asarray(q_start, dtype=float)[None]
    start_frame = residual.frame(kinematics.transforms(start))[0]
    origin = np.concatenate([start_frame[:3, 3], rpy_of(start_frame[:3, :3])])
    move = targets - origin
    move[:, 3:] = (move[:, 3:] + np.pi) % (2 * np.pi) - np.pi
    held = list(task_axes)
    span = np.abs(move[:, held]) / np.where(np.arange(6)[held] < 3, scale, 1.0) if held else np.zeros((count, 0))
    # each pose its own stages, as many as its own move needs: the same steps alone as in any batch
    stages = np.maximum(np.ceil(np.max(span, axis=1, initial=0.0) / STAGE_LENGTH), 1).astype(np.int64)
    q = np.repeat(start, count, axis=0)
    norm = np.zeros(count)
    floor = float(np.linalg.norm(residual(start, np.concatenate([origin])[None], jacobian=False)[0]))
    reach_tolerance = max(ASSEMBLY_TOLERANCE * 10, 2 * floor)  # a pose is reached below this residual
    # a position no configuration reaches (a path in millimetres read as metres: thousands of stages, minutes) is
    # not followed at all: it stays at the start, unreached (its position's gap alone, in length scales, is more
    # than a reached pose's whole residual)
    beyond = beyond_reach(kinematics, int(frame.parentJoint), placement, targets, tuple(task_axes),
                          reach_tolerance * scale, limits=limits)
    stages[beyond], norm[beyond] = 0, np.inf
    for stage in range(1, int(np.max(stages, initial=1)) + 1):
        for rows, iterations, tolerance in ((np.flatnonzero(stages > stage), MAX_ITERATIONS // 4, STAGE_TOLERANCE),
                                            (np.flatnonzero(stages == stage), MAX_ITERATIONS, FINAL_TOLERANCE)):
            if rows.size:
                q[rows], norm[rows] = _least_squares(residual, kinematics, q[rows],
                                                     origin + move[rows] * (stage / stages[rows])[:, None],
                                                     iterations, tolerance)
    reached = norm < reach_tolerance
    if 3 in task_axes or 5 in task_axes:  # roll and yaw at a gimbal lock: one angle, either value "reached" there
        pitch = rpy_of(residual.frame(kinematics.transforms(q))[:, :3, :3])[:, 1]
        reached &= np.abs(np.cos(pitch)) > GIMBAL_LOCK
    if limits:
        reached &= ~np.any(beyond_limits(kinematics, q, limited, scale), axis=1)
    return q, reached


def beyond_limits(kinematics: TreeKinematics, q: NDArray, limited: NDArray | None = None, length: float = 1.0
                  ) -> NDArray[np.bool_]:
    """(n, nv): which 1-DoF joints (by velocity coordinate; only those of the mask ``limited`` when given) of
    configurations ``q`` (n, nq) are beyond their position limits (by more than
    :func:`screwkit.closure.solve.slackened`, as the serial reading counts it; ``length``: the length scale, a
    slide's unit there)."""
    values, unit = np.zeros((q.shape[0], kinematics.nv)), np.ones(kinematics.nv)
    for joint, kind in enumerate(kinematics.kinds):
        if kind in ("revolute", "prismatic"):
            values[:, kinematics.idx_v[joint]] = q[:, kinematics.idx_q[joint]]
            unit[kinematics.idx_v[joint]] = length if kind == "prismatic" else 1.0
    lowest, highest = slackened(kinematics.lower, kinematics.upper, unit)
    beyond = (values < lowest) | (values > highest)
    return beyond if limited is None else beyond & np.asarray(limited, dtype=bool)


def joints_beyond_limits(model, kinematics: TreeKinematics, q: NDArray, limited: NDArray | None = None,
                         length: float = 1.0) -> list[str]:
    """The joints of one configuration ``q`` (nq,) beyond their limits (those of ``limited``; :func:`beyond_limits`
    with the length scale ``length``), each said with its value and limits (deg for a revolute joint, m for a
    prismatic one), for a message."""
    said = []
    for column in np.flatnonzero(beyond_limits(kinematics, q[None], limited, length)[0]):
        joint = int(kinematics.column_joint[column])
        value, low, high = float(q[kinematics.idx_q[joint]]), kinematics.lower[column], kinematics.upper[column]
        if kinematics.kinds[joint] == "revolute":
            value, low, high = np.degrees([value, low, high])
            said.append(f"{model.names[joint]!r} at {value:.6g} deg, limits [{low:.6g}, {high:.6g}] deg")
        else:
            said.append(f"{model.names[joint]!r} at {value:.6g} m, limits [{low:.6g}, {high:.6g}] m")
    return said
