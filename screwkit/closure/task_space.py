"""Task coordinates of any mobility: the independent pose coordinates and the dependent ones.

A mechanism of lower mobility (a 3-PRS: z, roll, pitch; a Delta: x, y, z) is driven through
its **task coordinates**; its other pose coordinates are *dependent* (parasitic) and follow
from the closure of the chains that constrain the platform. :func:`complete_poses` finds them:
batched Levenberg-Marquardt on the dependent coordinates and the joint values of the
constraining chains together, with continuation from the reference assembly.
:func:`infer_task_axes` chooses the task coordinates from the platform's motion space, and
:func:`motion_space_at` gives that space (and so the instantaneous DOF) at closed configurations.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations

import numpy as np
from numpy.typing import NDArray

from screwkit.closure.chain_kinematics import (
    chain_forward_kinematics,
    packed_chains,
    twists_from_axes_and_points,
    wrap_revolute_values,
)
from screwkit.closure.threads import for_each_block
from screwkit.common.compiling import announce_compilation
from screwkit.common.tolerances import MOTION_SPACE_TOLERANCE, NEWTON_TOLERANCE
from screwkit.model.mechanism import Mechanism

__all__ = [
    "pose_rates",
    "constraining_chains",
    "complete_poses",
    "close_constraining_chains",
    "packed_geometry",
    "motion_space_at",
    "infer_task_axes",
    "choose_task_axes",
    "still_motions",
    "driven_idle_turns",
]

TRANSLATIONAL = np.sqrt(0.5)
"""The platform's motions are translational when translation coordinates tell them apart by at least this (the
smallest singular value of their rates on an orthonormal basis of the motion space, lengths in length scales): each
motion then moves the frame's origin by more length scales than it turns the platform, and the task coordinates
are translations (:func:`choose_task_axes`)."""
TASK_RANK_TOLERANCE = 1e-6
"""A pose coordinate is independent of those chosen before it when the rates of the chosen ones
on an orthonormal basis of the motion space (lengths in units of the length scale) keep a
smallest singular value above this."""
TASK_CHOICE_FRACTION = 0.1
"""A pose coordinate is taken in its order only when its rates tell the motions apart (the smallest singular value
above) at least this fraction as well as the best coordinate of its kind not yet taken (:func:`choose_task_axes`)."""
ONE_MOTION_FRACTION = 1.0 - 1e-9
""":data:`TASK_CHOICE_FRACTION` of a mechanism of one DoF: its coordinate is the one of its kind the motion runs
along fastest (the first in order among equals), not the first that moves: a coordinate that moves a tenth as fast
as another turns back within a few degrees of the stroke (a gripper's fingertip moving along the world's y, x taken
for moving at a third of y's rate, reached its largest x 12 deg into a 46 deg stroke, and the poses past it could
not be asked; the same file turned in the world read them). The fastest moves at least 1/sqrt(3) of the speed (1/sqrt(2)
in a plane of two axes), so along a circle its extremum is at least 35 deg (45 deg) away, in any world frame."""


def pose_rates(mechanism: Mechanism, full_poses: NDArray) -> NDArray[np.float64]:
    """d(platform frame)/d(pose coordinates): (N, 6, n_pose), rows (angular velocity, velocity of
    the platform frame's origin), base frame."""
    count = full_poses.shape[0]
    rates = np.zeros((count, 6, mechanism.n_pose))
    if mechanism.is_planar:
        rates[:, 2, 2] = 1.0
        rates[:, 3, 0] = rates[:, 4, 1] = 1.0
        return rates
    pitch, yaw = full_poses[:, 4], full_poses[:, 5]
    zero, one = np.zeros(count), np.ones(count)
    # R = Rz(yaw) Ry(pitch) Rx(roll): omega = z yaw' + Rz(yaw) y pitch' + Rz(yaw) Ry(pitch) x roll'
    rates[:, :3, 3] = np.stack([np.cos(yaw) * np.cos(pitch), np.sin(yaw) * np.cos(pitch), -np.sin(pitch)], -1)
    rates[:, :3, 4] = np.stack([-np.sin(yaw), np.cos(yaw), zero], -1)
    rates[:, :3, 5] = np.stack([zero, zero, one], -1)
    rates[:, 3:, :3] = np.eye(3)
    return rates


def _chain_rank(mechanism: Mechanism, index: int, values: NDArray | None = None):
    """The dimension of the twists chain ``index``'s joints span at joint ``values`` (its reference ones by
    default: an int; a batch (k, joints): an array (k,))."""
    chain = mechanism.chains[index]
    frames = chain_forward_kinematics(chain.geometry, chain.reference_values if values is None else values)
    twists = twists_from_axes_and_points(frames.axes, frames.points, chain.prismatic)
    twists = twists / np.maximum(np.linalg.norm(twists, axis=-1, keepdims=True), 1e-300)
    rows = [2, 3, 4] if mechanism.is_planar else list(range(6))
    if twists.shape[-2] == 0:
        return 0 if values is None or np.ndim(values) == 1 else np.zeros(len(values), dtype=int)
    singular = np.linalg.svd(twists[..., rows], compute_uv=False)
    ranks = np.sum(singular > MOTION_SPACE_TOLERANCE * np.maximum(singular[..., :1], 1e-300), axis=-1)
    return int(ranks) if np.ndim(ranks) == 0 else ranks


def chain_ranks(mechanism: Mechanism) -> list[int]:
    """The dimension of the twists each chain's joints span at the reference assembly."""
    return [_chain_rank(mechanism, index) for index in range(len(mechanism.chains))]


def singular_chains(mechanism: Mechanism, ranks: list[int] | None = None, samples: int = 4) -> list[str]:
    """The chains whose joints span fewer twists at the reference assembly (``ranks``, :func:`chain_ranks`) than at
    joint values near it (every joint moved by up to 0.05 rad or 0.05 length scales; ``samples`` random ones, seeded,
    one batch): stretched or folded, as a crank and its rod on one line."""
    rng, found = np.random.default_rng(0), []
    ranks = chain_ranks(mechanism) if ranks is None else ranks
    for index, chain in enumerate(mechanism.chains):
        if ranks[index] == min(chain.n_joints, 3 if mechanism.is_planar else 6):
            continue  # as many as the chain can span: no more near it (most chains, at one batch of FK)
        step = np.where(np.asarray(chain.geometry.dof_prismatic, dtype=bool), 0.05 * mechanism.length_scale, 0.05)
        values = chain.reference_values + np.vstack([np.zeros(chain.n_joints),
                                                     rng.uniform(-1.0, 1.0, (samples, chain.n_joints)) * step])
        batch = _chain_rank(mechanism, index, values)
        if np.max(batch[1:]) > batch[0]:
            found.append(chain.name)
    return found


def constraining_chains(mechanism: Mechanism, ranks: list[int] | None = None) -> tuple[int, ...]:
    """Chains whose joints do not span every platform motion: those whose closure ties the dependent coordinates
    (``ranks``: :func:`chain_ranks`, computed when not given)."""
    ranks = chain_ranks(mechanism) if ranks is None else ranks
    return tuple(index for index, rank in enumerate(ranks) if rank < mechanism.n_pose)


def packed_geometry(mechanism: Mechanism, chains: tuple[int, ...]) -> dict:
    """The geometry of ``chains`` packed for the compiled closure (:func:`packed_chains`, and the planar plane)."""
    announce_compilation("screwkit.closure.compiled.task")
    geometries = [mechanism.chains[index].geometry for index in chains]
    return dict(packed_chains(geometries), planar=mechanism.is_planar,
                planar_z=float(mechanism.home_translation[2]),
                dof_prism=np.array([p for g in geometries for p in g.dof_prismatic], dtype=np.bool_),
                plat_rot=np.array([g.platform_loop_rotation for g in geometries], dtype=float).reshape(-1, 3, 3),
                plat_trans=np.array([g.platform_loop_translation for g in geometries], dtype=float).reshape(-1, 3))


BLOCK = 2048
"""Configurations per thread block of the compiled closure."""


@dataclass(frozen=True)
class ClosureSteps:
    """How the compiled closure iterates: Levenberg-Marquardt to ``tolerance`` in at most ``iterations``
    at the last step of a continuation, to ``step_tolerance`` in ``step_iterations`` at the steps before
    it, each step of the unknowns at most ``max_step`` (rad and length scales)."""

    tolerance: float
    iterations: int
    step_tolerance: float
    step_iterations: int
    max_step: float


def _run_closure(mechanism, chains, full_poses, values, free_axes, targets, steps, settings: ClosureSteps):
    """The compiled closure (:mod:`screwkit.closure.compiled.task`) over a batch, in thread blocks.

    The kernel runs on the mechanism scaled to a unit length scale (every length, pose
    coordinate, target and slide value divided by it), so that its damping, step limit and
    tolerances mean the same for a mechanism and any scaled copy; the residual is in rad and
    length scales.
    """
    tolerance, iterations, max_step = settings.tolerance, settings.iterations, settings.max_step
    step_tolerance, step_iterations = settings.step_tolerance, settings.step_iterations
    announce_compilation("screwkit.closure.compiled.task")
    from screwkit.closure.compiled.task import close_chains_kernel  # numba: loaded when a closure first runs

    poses = np.array(full_poses, dtype=float, order="C", copy=True)
    count = poses.shape[0]
    sizes = [mechanism.chains[index].n_joints for index in chains]
    flat = np.zeros((count, sum(sizes)))
    column = 0
    for chain_values, size in zip(values, sizes):
        flat[:, column:column + size] = chain_values
        column += size
    free = np.asarray(free_axes, dtype=np.int64)
    task = np.array([axis for axis in range(mechanism.n_pose) if axis not in free_axes], dtype=np.int64)
    # writable copies: one compiled signature of the kernel whatever the caller passed
    targets = np.array(np.broadcast_to(targets, (count, task.size)), dtype=float, order="C")
    steps = np.array(np.broadcast_to(steps, (count,)), dtype=np.int64, order="C")
    geometry = packed_geometry(mechanism, chains)
    length = mechanism.length_scale
    for key in ("joint_trans", "leg_trans", "plat_trans"):
        geometry[key] = geometry[key] / length
    geometry["planar_z"] = geometry["planar_z"] / length
    lengths = ~np.asarray(mechanism.pose_angular)
    poses[:, lengths] /= length
    targets[:, lengths[task]] /= length
    flat[:, geometry["dof_prism"]] /= length
    residual = np.empty(count)

    def work(block: slice) -> None:
        close_chains_kernel(poses[block], flat[block], targets[block], steps[block], task, free,
                            geometry["planar"], geometry["planar_z"], geometry["tree_start"], geometry["dof_start"],
                            geometry["joint_rot"], geometry["joint_trans"], geometry["joint_axis"],
                            geometry["joint_prism"], geometry["dof_prism"], geometry["leg_rot"], geometry["leg_trans"],
                            geometry["loop_code"], geometry["loop_axes"], geometry["plat_rot"], geometry["plat_trans"],
                            tolerance, iterations, step_tolerance, step_iterations, max_step, residual[block])

    for_each_block(count, work, block=BLOCK)
    poses[:, lengths] *= length
    flat[:, geometry["dof_prism"]] *= length
    split = np.cumsum([0] + sizes)
    return poses, [flat[:, split[i]:split[i + 1]] for i in range(len(sizes))], residual < tolerance, residual


def close_constraining_chains(mechanism, chains, full_poses, values, free_axes, tolerance, iterations, max_step):
    """Close the constraining chains by moving the free pose coordinates and their joints together.

    Levenberg-Marquardt as :func:`screwkit.closure.newton.newton_solve_chain`, on the unknowns
    (free pose coordinates, joint values of every constraining chain) with lengths in units of
    the length scale: the step solves ``(J^T J + (mu + |e|^2) I) dx = -J^T e`` for the closure
    errors ``e`` of every constraining chain, is limited to ``max_step`` and kept only if it
    lowers ``|e|``. Compiled (:mod:`screwkit.closure.compiled.task`), one configuration at a time.

    Returns
    -------
    full_poses : ndarray (N, n_pose)
    values : list of ndarray (N, m_i)
    converged : ndarray (N,) of bool
    residual : ndarray (N,)
    """
    full_poses = np.asarray(full_poses, dtype=float)
    task = [axis for axis in range(mechanism.n_pose) if axis not in free_axes]
    return _run_closure(mechanism, chains, full_poses, values, tuple(free_axes), full_poses[:, task], 1,
                        ClosureSteps(tolerance, iterations, tolerance, iterations, max_step))


def complete_poses(mechanism: Mechanism, task_poses: NDArray, *, start_poses: NDArray | None = None,
                   start_values=None, tolerance: float = NEWTON_TOLERANCE, iterations: int = 40):
    """Full poses (N, n_pose) of task poses (N, n_task): the dependent coordinates that close the chains.

    Continuation from the reference assembly along straight paths in task coordinates (for each
    pose, steps of at most 0.1 rad and 0.1 length scales), each step closed by
    Levenberg-Marquardt on the dependent coordinates and the joint values of the
    :func:`constraining_chains` together (:func:`close_constraining_chains`; intermediate steps to
    1e-8 in at most 12 iterations).

    Returns
    -------
    full_poses : ndarray (N, n_pose)
    values : list of ndarray (N, m_i)
        Joint values of the constraining chains (in :func:`constraining_chains` order).
    converged : ndarray (N,) of bool
    residual : ndarray (N,)
        The closure error norm left (rad and length scales), times the length scale: metres for
        a position error.
    """
    task_poses = np.asarray(task_poses, dtype=float)
    count = task_poses.shape[0]
    chains = constraining_chains(mechanism)
    free = tuple(i for i in mechanism.dependent_indices if i not in mechanism.held_axes)
    if start_poses is None:
        start_poses = np.broadcast_to(mechanism.home_full_pose, (count, mechanism.n_pose))
        start_values = [np.broadcast_to(mechanism.chains[i].reference_values, (count, mechanism.chains[i].n_joints))
                        for i in chains]
    if mechanism.held_axes:  # held at the reference assembly's values, wherever the continuation starts
        start_poses = np.array(start_poses, dtype=float)
        start_poses[:, list(mechanism.held_axes)] = mechanism.home_full_pose[list(mechanism.held_axes)]
    if not chains or not free:
        return mechanism.full_poses(task_poses, np.asarray(start_poses)[:, list(mechanism.dependent_indices)]), [], \
            np.ones(count, dtype=bool), np.zeros(count)
    start_task = mechanism.task_poses(start_poses)
    distance = np.abs(task_poses - start_task) / np.where(mechanism.angular, 1.0, mechanism.length_scale)
    largest = np.nan_to_num(np.max(distance, axis=-1, initial=0.0), nan=0.0, posinf=6.4)
    steps = np.clip(np.ceil(largest / 0.1), 1, 64).astype(np.int64)
    targets = task_poses if not mechanism.held_axes else \
        mechanism.full_poses(task_poses)[:, [axis for axis in range(mechanism.n_pose) if axis not in free]]
    poses, values, converged, residual = _run_closure(mechanism, chains, start_poses, start_values, free, targets,
                                                      steps, ClosureSteps(tolerance, iterations, 1e-8, 12, 0.5))
    values = [wrap_revolute_values(mechanism.chains[i].geometry, v) for i, v in zip(chains, values)]
    return poses, values, converged, residual * mechanism.length_scale


def motion_space_at(mechanism: Mechanism, full_poses: NDArray, joint_values, *, locked: bool = False
                    ) -> tuple[NDArray, NDArray]:
    """The platform's motion space at closed configurations, in pose-coordinate rates.

    Parameters
    ----------
    full_poses : ndarray (N, n_pose)
    joint_values : sequence of ndarray (N, m_i), one per chain
    locked : bool
        With every actuator held: the motions the passive joints alone allow.

    Returns
    -------
    dof : ndarray (N,) of int
        Instantaneous DOF: dimension of the intersection of the chains' twist spaces.
    rates : ndarray (N, n_pose, n_pose)
        Orthonormal basis (columns, first ``dof`` of them) of the pose-coordinate rates the
        platform can follow (lengths in units of the length scale).
    """
    count = full_poses.shape[0]
    rotation, translation = mechanism.transforms_from_poses(full_poses)
    rows = [2, 3, 4] if mechanism.is_planar else list(range(6))
    total = np.zeros((count, len(rows), len(rows)))
    for chain, values in zip(mechanism.chains, joint_values):
        frames = chain_forward_kinematics(chain.geometry, values)
        twists = twists_from_axes_and_points(frames.axes, frames.points - translation[:, None, :], chain.prismatic)
        twists = np.concatenate([twists[..., :3], twists[..., 3:] / mechanism.length_scale], axis=-1)[..., rows]
        twists = twists / np.maximum(np.linalg.norm(twists, axis=-1, keepdims=True), 1e-300)
        if locked:
            twists = np.delete(twists, list(chain.actuated), axis=-2)
        if not twists.shape[-2]:  # a chain of actuators alone, held: it holds the platform
            total += np.eye(len(rows))
            continue
        left, singular, _ = np.linalg.svd(np.swapaxes(twists, -1, -2), full_matrices=False)
        mask = singular > MOTION_SPACE_TOLERANCE * np.maximum(singular[..., :1], 1e-300)
        basis = left * mask[..., None, :]
        total += np.eye(len(rows)) - basis @ np.swapaxes(basis, -1, -2)
    eigenvalues, eigenvectors = np.linalg.eigh(total)
    dof = np.sum(eigenvalues <= 1e-8, axis=-1)
    # twists (omega, v / length) about the platform origin -> pose-coordinate rates (lengths / length)
    rates = pose_rates(mechanism, full_poses)
    rates = np.concatenate([rates[:, :3], rates[:, 3:] / mechanism.length_scale], axis=1)[:, rows]
    rates = rates * np.where(mechanism.pose_angular, 1.0, mechanism.length_scale)  # per length-scaled coordinate
    coordinates = np.linalg.pinv(rates) @ eigenvectors
    basis, _ = np.linalg.qr(coordinates)
    return dof, basis


def still_motions(mechanism: Mechanism, full_pose: NDArray, joint_values, dof: int) -> NDArray | None:
    """The platform's motions (columns of pose-coordinate rates) that keep a point output still, at the closed
    configuration ``full_pose`` (``joint_values`` one array per chain) where the platform has ``dof`` motions; None
    where it has another number there (a singular configuration: nothing to tell)."""
    dofs, basis = motion_space_at(mechanism, full_pose[None], [np.asarray(v)[None] for v in joint_values])
    if int(dofs[0]) != dof:
        return None
    space = basis[0][:, :dof]
    _, singular, rows = np.linalg.svd(space[~mechanism.pose_angular], full_matrices=True)
    return space @ rows[int(np.sum(singular > TASK_RANK_TOLERANCE)):].T


def driven_idle_turns(mechanism: Mechanism, full_pose: NDArray, joint_values, dof: int) -> bool:
    """Whether a point output's idle turns are driven: the platform's motions (``dof`` of them at the closed
    configuration ``full_pose``) that keep the point still (:func:`still_motions`), which a point output counts as
    none, are not all allowed with every actuator held (an actuator drives one: a leg's output point on a crank, the
    other motor turning the leg's links about it: a published rat robot's five-bar leg read 2 actuators as 1 DOF, 1
    redundant, F_O1 0.2435, where it has 2 DOF and no redundancy)."""
    still = still_motions(mechanism, full_pose, joint_values, dof)
    if still is None or not still.shape[1]:
        return False
    held, free = motion_space_at(mechanism, full_pose[None], [np.asarray(v)[None] for v in joint_values], locked=True)
    allowed = free[0][:, :int(held[0])]
    return bool(np.linalg.norm(still - allowed @ (allowed.T @ still)) > TASK_RANK_TOLERANCE ** 0.5)


def infer_task_axes(mechanism: Mechanism, full_pose: NDArray, joint_values, dof: int,
                    candidates=None) -> tuple[int, ...]:
    """``dof`` pose coordinates whose rates are independent on the motion space, following that space.

    The platform's translations without rotation come first: as many translation coordinates as the motion
    space has twists with no rotation (three for a Delta, none for a spherical wrist whatever point its frame
    is at), chosen in order among those independent on that subspace; then the rotation coordinates
    independent on the whole space, in order (a hexapod's roll, pitch, yaw, a spherical wrist's three rotations
    rather than the translations of its frame's origin off the centre), then any others. Translations alone when they
    tell every motion apart by :data:`TRANSLATIONAL` (each motion moves the frame more than it turns it: a Delta
    whose rod pairs are trapezoids, its platform turning a little as it moves). ``joint_values``
    holds one (m_i,) array per chain at the closed configuration ``full_pose``; ``candidates`` restricts the
    coordinates tried (the translations of a point output), in order, with no such split.
    """
    dofs, basis = motion_space_at(mechanism, full_pose[None], [np.asarray(v)[None] for v in joint_values])
    space = basis[0][:, :int(dofs[0])]
    return choose_task_axes(space, np.asarray(mechanism.pose_angular, dtype=bool), dof, candidates)


def choose_task_axes(space: NDArray, angular: NDArray, dof: int, candidates=None) -> tuple[int, ...]:
    """The rule of :func:`infer_task_axes` on ``space`` (n_pose, d): the pose-coordinate rates of a basis of the
    motion space (lengths in units of the length scale), ``angular`` which coordinates are angles."""
    chosen = _task_axes_in_order(space, angular, dof, candidates)
    every = candidates is None or len(list(candidates)) == space.shape[0]  # (not a point output's translations)
    if every and 0 < dof <= int(np.sum(~angular)) and any(angular[axis] for axis in chosen):
        # motions that move the frame more than they turn it are told apart by translations, the set of them that
        # does so best (in any world frame): a Delta whose rod pairs are not quite parallelograms turns 0.19 rad per
        # length scale, and its roll, pitch, yaw told its motions apart by 0.0015 against x, y, z's 0.98
        sets = combinations(np.flatnonzero(~angular), dof)
        separation, best = max(((_separation(space, axes), axes) for axes in sets), key=lambda pair: pair[0])
        # (whether they do is read on every translation coordinate at once, which no turn of the world changes: a
        # parallelogram's coupler translating along a slant of a turned world moves each of x, y, z 0.6 length
        # scales a unit, and took the pitch it turns 1e-4 rad with the file's rounding)
        if _separation(space, np.flatnonzero(~angular)) >= TRANSLATIONAL and separation > TASK_RANK_TOLERANCE:
            return tuple(int(axis) for axis in best)
    return chosen


def _telling(space: NDArray, chosen: list[int], axis: int, pool: list[int], fraction: float = TASK_CHOICE_FRACTION
             ) -> bool:
    """Whether the coordinate ``axis`` joins ``chosen``: independent of them (above :data:`TASK_RANK_TOLERANCE`)
    and within :data:`TASK_CHOICE_FRACTION` of the best coordinate of its kind left in ``pool``. The rule takes
    coordinates in order, but not one that barely moves: a foot turning about the world's y axis to within 4e-6 rad,
    drawn at a pitch of 77 deg, moves its roll 1.6e-5 as fast as its pitch; taken for the task coordinate, roll
    would have asked turns of the foot 60,000 times as large, and reached its values only at the gimbal lock."""
    separation = _separation(space, chosen + [axis])
    if separation <= TASK_RANK_TOLERANCE:
        return False
    return separation >= fraction * max(_separation(space, chosen + [other]) for other in pool)


def _separation(space: NDArray, axes) -> float:
    """How well the coordinates ``axes`` tell the motions of ``space`` apart: their rates' smallest singular value."""
    return float(np.linalg.svd(space[list(axes)], compute_uv=False)[-1])


def _task_axes_in_order(space: NDArray, angular: NDArray, dof: int, candidates=None) -> tuple[int, ...]:
    order = list(range(space.shape[0])) if candidates is None else list(candidates)
    chosen: list[int] = []
    fraction = ONE_MOTION_FRACTION if dof == 1 else TASK_CHOICE_FRACTION
    if len(order) == space.shape[0] and space.shape[1]:
        _, singular, rows = np.linalg.svd(space[angular], full_matrices=True)
        turning = int(np.sum(singular > TASK_RANK_TOLERANCE))
        translations = space @ rows[turning:].T  # the motions that turn the platform by nothing
        for axis in (axis for axis in order if not angular[axis]):
            if len(chosen) == translations.shape[1]:
                break
            if _telling(translations, chosen, axis, [a for a in order if not angular[a] and a not in chosen], fraction):
                chosen.append(axis)
        order = [axis for axis in order if angular[axis]] + [axis for axis in order if not angular[axis]]
    for axis in order:
        if len(chosen) == dof:
            break
        if axis not in chosen and _telling(space, chosen, axis, [a for a in order if a not in chosen
                                                                  and angular[a] == angular[axis]], fraction):
            chosen.append(axis)
    for axis in order:  # one passed over for a better one that a later choice then made worse: independence alone
        if len(chosen) == dof:
            break
        if axis not in chosen and _separation(space, chosen + [axis]) > TASK_RANK_TOLERANCE:
            chosen.append(axis)
    return tuple(sorted(chosen))
