"""Forward kinematics of the closed mechanism: platform poses from actuator values (Newton steps on the pose)."""

from __future__ import annotations

from typing import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.closure.chain_kinematics import chain_forward_kinematics, chain_jacobian
from screwkit.closure.solve import MISSES_CLOSURE, Solution, solve
from screwkit.closure.task_space import motion_space_at, pose_rates
from screwkit.common.rotations import wrap_angle
from screwkit.model.mechanism import Mechanism, require_mechanism

__all__ = ["forward"]

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
        rates = pose_rates(mechanism, full) @ _task_to_pose_rates(mechanism, full, previous)  # (N, 6, n_task)
        rotation, translation = mechanism.transforms_from_poses(full)
        jacobian = np.empty((rows.size, len(selected), mechanism.n_task))
        for row, (chain_index, joint) in enumerate(selected):
            chain = mechanism.chains[chain_index]
            frames = chain_forward_kinematics(chain.geometry, previous[chain_index])
            _, end = mechanism.loop_targets(chain_index, rotation, translation)
            # velocity of the loop frame's origin: v_end = v_origin + omega x (end - origin)
            arm = end - translation
            loop_rates = rates.copy()
            loop_rates[:, 3:] += np.swapaxes(np.cross(np.swapaxes(rates[:, :3], 1, 2), arm[:, None, :]), 1, 2)
            joint_rates = np.linalg.pinv(chain_jacobian(chain.geometry, frames)) @ loop_rates
            jacobian[:, row] = joint_rates[:, joint]
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

