"""Forward kinematics of the closed mechanism: platform poses from actuator values (Newton steps on the pose)."""

from __future__ import annotations

from itertools import product
from typing import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.closure.around import TURNS, apart
from screwkit.closure.chain_kinematics import chain_forward_kinematics, chain_jacobian
from screwkit.closure.solve import MISSES_CLOSURE, Solution, solve
from screwkit.closure.task_space import motion_space_at, pose_rates
from screwkit.common.rotations import wrap_angle
from screwkit.model.mechanism import Mechanism, require_mechanism

__all__ = ["forward", "forward_from_starts"]

_SHORTENED_STEPS = 12
"""Newton steps on the pose that end where the loops do not close are halved, at most this many times each."""


def _task_to_pose_rates(mechanism: Mechanism, full_poses: NDArray, joint_values) -> NDArray[np.float64]:
    """d(pose coordinates)/d(task coordinates) (N, n_pose, n_task) on the closure: the identity at full
    mobility, else the dependent rates that keep the platform in its motion space."""
    count = full_poses.shape[0]
    if not mechanism.dependent_indices:
        return np.broadcast_to(np.eye(mechanism.n_pose), (count, mechanism.n_pose, mechanism.n_pose))
    _, basis = motion_space_at(mechanism, full_poses, joint_values)
    space = basis[..., :mechanism.dof]  # pose-coordinate rates, lengths in units of the length scale
    scale = np.where(mechanism.pose_angular, 1.0, mechanism.length_scale)
    space = space * scale[:, None]  # back to metres
    task = space[:, list(mechanism.task_indices)]  # (N, n_task, dof)
    return space @ np.linalg.pinv(task)


def _actuator_rates(mechanism: Mechanism, selected, full_poses: NDArray, joint_values) -> NDArray[np.float64]:
    """d(actuators ``selected``)/d(task coordinates) (N, k, n_task) at closed configurations (full poses (N, n_pose)
    and each chain's joint values (N, m_i)), from each chain's analytic Jacobian."""
    rates = pose_rates(mechanism, full_poses) @ _task_to_pose_rates(mechanism, full_poses, joint_values)
    rotation, translation = mechanism.transforms_from_poses(full_poses)
    jacobian = np.empty((full_poses.shape[0], len(selected), mechanism.n_task))
    for row, (chain_index, joint) in enumerate(selected):
        chain = mechanism.chains[chain_index]
        frames = chain_forward_kinematics(chain.geometry, joint_values[chain_index])
        _, end = mechanism.loop_targets(chain_index, rotation, translation)
        # velocity of the loop frame's origin: v_end = v_origin + omega x (end - origin)
        arm = end - translation
        loop_rates = rates.copy()
        loop_rates[:, 3:] += np.swapaxes(np.cross(np.swapaxes(rates[:, :3], 1, 2), arm[:, None, :]), 1, 2)
        joint_rates = np.linalg.pinv(chain_jacobian(chain.geometry, frames)) @ loop_rates
        jacobian[:, row] = joint_rates[:, joint]
    return jacobian


def forward(
    mechanism: Mechanism,
    actuator_values: ArrayLike,
    initial_pose: ArrayLike,
    *,
    actuators: Sequence[int | str | tuple[str, str]] | None = None,
    tolerance: float = 1e-11,
    agreement: float = 1e-5,
    max_iterations: int = 30,
    limits: bool = False,
) -> Solution:
    """Platform poses for given actuator values (forward kinematics of the closed mechanism).

    Only the listed ``actuators`` are held at ``actuator_values``; all others move freely
    (they act as passive joints). With as many listed actuators as DOF this is the forward
    kinematics of a non-redundant submechanism. Newton steps on the pose: the rates of the
    listed actuators per task-coordinate rate come from each chain's analytic Jacobian
    (:func:`~screwkit.closure.chain_kinematics.chain_jacobian`), ``dq = J^+ dT``, at the
    current closed configuration; the working mode is the one reachable from ``initial_pose``.

    Parameters
    ----------
    actuator_values : array_like, shape (..., k)
        Values of the listed actuators (rad or m).
    initial_pose : array_like, shape (..., n_task)
        Start pose.
    actuators : sequence, optional
        Indices into :attr:`~Mechanism.actuators`, ``chain:joint`` names or ``(chain, joint)``
        pairs, distinct and at least as many as the DOF (fewer leave the pose undetermined); default all.
    tolerance : float
        Convergence on the largest actuator mismatch (rad, or length scales for a slide).
    agreement : float
        The largest mismatch accepted where Newton steps no longer halve it (same units): the values of a
        redundantly actuated mechanism rounded as a file or a logger writes them (1e-7 deg at nine digits) cannot
        all be met at once, and the closure itself is exact to about 1e-11 only; the pose found is then the
        least-squares fit of the values. Values that disagree by more are refused (not reachable).
    limits : bool
        Whether joint limits make a pose unreachable (default: no, as in the pure geometry).

    Returns
    -------
    Solution
        At the poses found; ``reachable`` is False where Newton did not converge.
    """
    require_mechanism(mechanism, "forward")
    selected = mechanism.actuator_positions(actuators)
    if len(set(selected)) != len(selected) or len(selected) < mechanism.dof:
        held = [f"{mechanism.chains[c].name}:{mechanism.chains[c].joint_names[k]}" for c, k in selected]
        raise ValueError(f"Expected at least {mechanism.dof} distinct actuators held (the DOF of {mechanism.name!r}; "
                         f"fewer leave the pose undetermined), got {', '.join(held) or 'none'}.")
    targets = np.asarray(actuator_values, dtype=float)
    if targets.shape[-1:] != (len(selected),):
        raise ValueError(f"Expected `actuator_values` with shape (..., {len(selected)}), got {targets.shape}.")
    poses = mechanism.check_poses(initial_pose, where="`initial_pose`")
    try:
        batch = np.broadcast_shapes(targets.shape[:-1], poses.shape[:-1])
    except ValueError:
        raise ValueError(f"Expected batches of `actuator_values` {targets.shape[:-1]} and `initial_pose` "
                         f"{poses.shape[:-1]} that broadcast together (equal, or one of them a single one).") from None
    targets = np.broadcast_to(targets, batch + (len(selected),)).reshape(-1, len(selected))
    poses = np.array(np.broadcast_to(poses, batch + (mechanism.n_task,)).reshape(-1, mechanism.n_task))
    angular = np.array([not mechanism.chains[chain].prismatic[joint] for chain, joint in selected])
    count = poses.shape[0]
    converged = np.zeros(count, dtype=bool)
    active = np.arange(count)
    last = np.full(count, np.inf)  # each pose's mismatch at the step before
    scales = np.where(angular, 1.0, mechanism.length_scale)
    closed, step = poses.copy(), np.zeros_like(poses)  # each pose's last closed pose, and the step taken from it
    shortened = np.zeros(count, dtype=int)
    known = None  # each chain's joint values (count, m_i) at each pose's last closed pose
    for _ in range(max_iterations + _SHORTENED_STEPS):
        if active.size == 0:
            break
        solution = solve(mechanism, poses[active], initial=None if known is None else [k[active] for k in known],
                         limits=False)
        values = np.stack([solution.joint_values[chain][..., joint] for chain, joint in selected], -1)
        error = values - targets[active]
        error[:, angular] = wrap_angle(error[:, angular])
        shut = np.all(np.isfinite(error), axis=-1)
        if known is None:
            known = [np.zeros((count,) + chain_values.shape[1:]) for chain_values in solution.joint_values]
        for chain_known, chain_values in zip(known, solution.joint_values):
            chain_known[active[shut]] = chain_values[shut]
        closed[active[shut]] = poses[active[shut]]
        # a step past where the loops close (past the turning point of a task coordinate: a crank pin's x on its
        # circle) is halved from the last closed pose, at most _SHORTENED_STEPS times
        back = active[~shut & np.any(step[active] != 0.0, axis=-1) & (shortened[active] < _SHORTENED_STEPS)]
        step[back] /= 2.0
        poses[back] = closed[back] + step[back]
        shortened[back] += 1
        mismatch = np.max(np.abs(error) / scales, axis=-1)
        done = shut & (mismatch < tolerance)
        done |= shut & (mismatch < agreement) & (mismatch > 0.5 * last[active])  # as close as Newton gets
        last[active[shut]] = mismatch[shut]
        converged[active[done]] = True
        stepping = shut & ~done
        rows, error = active[stepping], error[stepping]
        active = np.sort(np.concatenate([rows, back]))
        if rows.size == 0:
            continue
        full = solution.full_poses[stepping]
        previous = [chain_values[stepping] for chain_values in solution.joint_values]
        jacobian = _actuator_rates(mechanism, selected, full, previous)
        update = -(np.linalg.pinv(jacobian) @ error[..., None])[..., 0]
        # steps of at most 0.2 rad and 0.2 length scales (task coordinates mix angles and lengths)
        largest = np.max(np.abs(update) / np.where(mechanism.angular, 1.0, mechanism.length_scale), axis=-1)
        update *= np.minimum(1.0, 0.2 / np.maximum(largest, 1e-300))[:, None]
        usable = np.all(np.isfinite(update), axis=-1)
        step[rows[usable]] = update[usable]
        poses[rows[usable]] += update[usable]
    solution = solve(mechanism, poses.reshape(batch + (mechanism.n_task,)), limits=limits)
    converged = converged.reshape(batch)
    return Solution(
        poses=solution.poses,
        full_poses=solution.full_poses,
        reachable=solution.reachable & converged,
        chain_reachable=solution.chain_reachable & converged[..., None],
        status=np.where(converged[..., None], solution.status,
                        np.maximum(solution.status, MISSES_CLOSURE)).astype(np.int8),
        residuals=solution.residuals,
        limit_joints=solution.limit_joints,
        joint_axes=solution.joint_axes,
        joint_points=solution.joint_points,
        value_sources=solution.joint_values,
    )


SPREAD = (-2.0, -1.0, 0.0, 1.0, 2.0)
"""Where :func:`forward_from_starts` starts, about the reference pose: these many length scales along each length
coordinate, and :data:`screwkit.closure.around.TURNS` along each angle."""

MOST_TASK_COORDINATES = 3
"""Task spaces of more coordinates are not searched (their starts would be thousands)."""


def forward_from_starts(mechanism: Mechanism, actuator_values: ArrayLike, start: ArrayLike, *,
                        limits: bool = False) -> tuple[Solution, str]:
    """:func:`forward` at one set of actuator values (k,) from ``start`` (n_task,); where that finds no pose (the way
    from the start passes a fold, or where the working mode cannot follow), from starts spread about the reference
    pose (:data:`SPREAD`, :data:`TURNS`; those in the working mode), for a mechanism of at most
    :data:`MOST_TASK_COORDINATES` task coordinates. A pose so found is taken when it is the only one
    (:func:`screwkit.closure.around.apart`) with the reference assembly's assembly mode: the sign of the determinant
    of the actuators' rates in the task coordinates, when there are as many actuators as task coordinates (a
    redundantly actuated mechanism's values, which over-determine the pose, must give one pose). Returns the solution
    (batch ()) and, when it is not the plain :func:`forward`'s, why: what was found from the starts (the solution then
    still unreachable where none, or several, were)."""
    values = np.asarray(actuator_values, dtype=float).reshape(-1)
    first = forward(mechanism, values, start, limits=limits)
    if bool(first.reachable) or mechanism.n_task > MOST_TASK_COORDINATES:
        return first, ""
    spread = [TURNS if angle else tuple(mechanism.length_scale * np.array(SPREAD)) for angle in mechanism.angular]
    grid = mechanism.home_pose + np.array(list(product(*spread)), dtype=float).reshape(-1, mechanism.n_task)
    starts = grid[np.asarray(solve(mechanism, grid, limits=False).reachable)]
    if starts.shape[0] == 0:
        return first, ""
    found = forward(mechanism, values, starts, limits=False)
    poses = np.asarray(found.poses)[found.reachable]
    joint_values = [np.asarray(chain_values)[found.reachable] for chain_values in found.joint_values]
    if len(mechanism.actuator_names) == mechanism.n_task and poses.shape[0]:
        selected = mechanism.actuator_positions()
        home = solve(mechanism, mechanism.home_pose[None], limits=False)
        reference = np.sign(np.linalg.det(_actuator_rates(mechanism, selected, np.asarray(home.full_poses),
                                                          list(home.joint_values))))
        signs = np.sign(np.linalg.det(_actuator_rates(mechanism, selected, np.asarray(found.full_poses)[
            found.reachable], joint_values)))
        poses = poses[signs == reference[0]]
    distinct = _distinct_poses(mechanism, poses)
    if len(distinct) != 1:
        said = ("several poses with these actuator values keep the reference assembly's working and assembly modes"
                if len(distinct) > 1 else "")
        return first, said
    return forward(mechanism, values, distinct[0], limits=limits), "found from starts spread about the reference pose"


def _distinct_poses(mechanism: Mechanism, poses: NDArray) -> list[NDArray]:
    """The poses (K, n_task) that are :func:`~screwkit.closure.around.apart`, the first of each group."""
    kept: list[NDArray] = []
    for pose in poses:
        if not kept or np.all(apart(pose - np.array(kept), mechanism.angular, mechanism.length_scale)):
            kept.append(pose)
    return kept
