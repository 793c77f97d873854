"""Closing every chain of a mechanism for a batch of platform poses, and the reverse.

:func:`solve` closes all chains for platform poses (a closed form where the chain type has
one, batched damped Newton with continuation otherwise), keeping the working mode and, by
default, the joints' position limits; :func:`solve_one` does one pose and says why it is
unreachable; :func:`forward` finds platform poses from actuator values (forward kinematics of
the closed mechanism) by Newton steps on the pose with the analytic chain Jacobians.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import IntEnum
from functools import cached_property
from typing import Literal, Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.closure.analytic import KernelKind
from screwkit.closure.around import complete_around, newton_chain_around
from screwkit.closure.around import searched as around_searched
from screwkit.closure.chain_kinematics import COMPILED_FROM, chain_forward_kinematics
from screwkit.closure.newton import pose_error, solve_newton_chain
from screwkit.closure.task_space import complete_poses, constraining_chains
from screwkit.closure.threads import for_each_block
from screwkit.common.tolerances import LIMIT_SLACK, NEWTON_TOLERANCE
from screwkit.common.units import spelled_pose
from screwkit.model.mechanism import Mechanism, require_mechanism

__all__ = [
    "Solution",
    "UnreachablePose",
    "ChainStatus",
    "solve",
    "solve_one",
    "actuator_values",
    "closure_residuals",
    "unreachable_reason",
    "run_closed_form",
    "outside_limits",
]

class ChainStatus(IntEnum):
    """Codes of :attr:`Solution.status` (an int8 array): each chain at each pose."""

    REACHABLE = 0  # closed
    MISSES_CLOSURE = 1  # no closure in the working mode
    OUTSIDE_LIMITS = 2  # closed with a joint outside its limits


REACHABLE, MISSES_CLOSURE, OUTSIDE_LIMITS = ChainStatus
"""The codes by their names alone (:class:`ChainStatus`)."""


class UnreachablePose(ValueError):
    """A pose that cannot be reached, with the chain that misses the most named first."""


@dataclass(frozen=True)
class Solution:
    """Closed-chain configurations of a mechanism for a batch of platform poses.

    Attributes
    ----------
    poses : ndarray, shape (..., n_task)
        The poses solved, in task coordinates.
    full_poses : ndarray, shape (..., n_pose)
        The same poses in every pose coordinate, dependent (parasitic) ones included.
    reachable : ndarray of bool, shape (...)
        Every chain closed in the requested working mode with its joints within their limits.
    chain_reachable : ndarray of bool, shape (..., n_chains)
    status : ndarray of int8, shape (..., n_chains)
        Per chain, a :class:`ChainStatus`: 0 closed, 1 misses its closure (no assembly in the working
        mode), 2 closed but a joint is outside its position limits.
    residuals : ndarray, shape (..., n_chains)
        Where the closure failed, by how far the chain misses (m for closed forms, the final
        Newton error norm in m and rad otherwise); else the remaining closure error (0 for
        closed forms).
    limit_joints : ndarray of int, shape (..., n_chains)
        Where ``status`` is ``OUTSIDE_LIMITS`` (2), the index (into the chain's joints) of the first joint outside
        its limits; else -1.
    joint_axes, joint_points : tuple of ndarray, each shape (..., m_i, 3)
        Per chain, joint axes and points in the **base** frame (component-major views for the
        closed forms); meaningful only where the chain closed.
    """

    poses: NDArray[np.float64]
    full_poses: NDArray[np.float64]
    reachable: NDArray[np.bool_]
    chain_reachable: NDArray[np.bool_]
    status: NDArray[np.int8]
    residuals: NDArray[np.float64]
    limit_joints: NDArray[np.int64]
    joint_axes: tuple[NDArray[np.float64], ...]
    joint_points: tuple[NDArray[np.float64], ...]
    value_sources: tuple = field(repr=False)
    """Per chain, the joint values (..., m_i) or a function computing them flat (N, m_i)."""

    @property
    def batch_shape(self) -> tuple[int, ...]:
        """Shape of the batch of poses."""
        return self.poses.shape[:-1]

    @cached_property
    def joint_values(self) -> tuple[NDArray[np.float64], ...]:
        """Per chain, joint values (..., m_i) (rad or m; revolute values wrapped to (-pi, pi],
        spherical loop values as rotation vectors); NaN where the chain misses its closure."""
        values = []
        for source in self.value_sources:
            array = source() if callable(source) else np.asarray(source)
            values.append(array.reshape(self.batch_shape + array.shape[-1:]))
        return tuple(values)


def _check_branches(mechanism: Mechanism, branches) -> tuple:
    if branches is None:
        return tuple(chain.branch for chain in mechanism.chains)
    branches = tuple(branches)
    if len(branches) != len(mechanism.chains):
        raise ValueError(f"Expected one branch per chain ({len(mechanism.chains)}), got {len(branches)}.")
    checked = []
    for chain, branch in zip(mechanism.chains, branches):
        if chain.closed_form is not None:
            signs = tuple(int(sign) for sign in np.atleast_1d(branch))
            if len(signs) != chain.closed_form.n_branches or any(sign not in (1, -1) for sign in signs):
                raise ValueError(f"Expected {chain.closed_form.n_branches} sign(s) of +-1 as branch of chain "
                                 f"{chain.name!r} ({chain.solver}), got {branch!r}.")
            checked.append(signs)
        else:
            if branch is not None and branch not in (1, -1):
                raise ValueError(f"Expected +1, -1 or None as branch of Newton chain {chain.name!r}, got {branch!r}.")
            checked.append(branch)
    return tuple(checked)


def _check_initial(mechanism: Mechanism, initial, batch: tuple[int, ...]):
    if initial is None:
        return None
    if isinstance(initial, Solution):
        initial = initial.joint_values
    initial = tuple(initial)
    if len(initial) != len(mechanism.chains):
        raise ValueError(f"Expected initial joint values for {len(mechanism.chains)} chains, got {len(initial)}.")
    arrays = []
    for chain, values in zip(mechanism.chains, initial):
        values = np.asarray(values, dtype=float)
        try:
            arrays.append(np.broadcast_to(values, batch + (chain.n_joints,)))
        except ValueError:
            raise ValueError(f"Expected initial values of chain {chain.name!r} broadcastable to "
                             f"{batch + (chain.n_joints,)}, got {values.shape}.") from None
    return arrays


class _PoseCache:
    """Quantities of a flat batch of poses shared by every chain (computed once, on demand)."""

    def __init__(self, mechanism: Mechanism, flat_poses: NDArray):
        self.mechanism = mechanism
        self.flat_poses = flat_poses

    @cached_property
    def platform(self):
        return self.mechanism.transforms_from_poses(self.flat_poses)

    @cached_property
    def planar(self):
        flat = self.flat_poses
        angle = np.ascontiguousarray(flat[:, 2])
        cosine, sine = np.empty_like(angle), np.empty_like(angle)

        def trigonometry(block: slice) -> None:
            np.cos(angle[block], out=cosine[block])
            np.sin(angle[block], out=sine[block])

        for_each_block(angle.shape[0], trigonometry)
        return np.ascontiguousarray(flat[:, 0]), np.ascontiguousarray(flat[:, 1]), cosine, sine, angle


def run_closed_form(mechanism: Mechanism, index: int, flat_poses: NDArray, branch, cache: _PoseCache | None = None):
    """The closed-form solver of chain ``index`` on flat poses (N, n_task) in working mode ``branch``."""
    solver = mechanism.chains[index].closed_form
    cache = _PoseCache(mechanism, flat_poses) if cache is None else cache
    if solver.planar:
        return solver.solve(*cache.planar, branch)
    if flat_poses.shape[0] >= COMPILED_FROM and solver.kernel_kind is not KernelKind.NONE:  # the kernel knows it
        return solver.solve_compiled(*cache.platform, branch)
    return solver.solve(*mechanism.loop_targets(index, *cache.platform), branch)


def slackened(lower: NDArray, upper: NDArray, unit: ArrayLike = 1.0) -> tuple[NDArray, NDArray]:
    """Position limits each widened by :data:`~screwkit.common.tolerances.LIMIT_SLACK` times ``unit`` plus its own
    size (``unit``: 1 rad for a hinge, the mechanism's length scale for a slide, so that a copy of the mechanism at
    another scale, or read in another unit, counts the same values within its limits; a stop at 0 keeps that
    whatever the other end: a slide of range 0 to 1e8 m was let 1 mm past it); an infinite limit stays infinite."""
    lower, upper = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
    return lower - LIMIT_SLACK * (unit + np.abs(lower)), upper + LIMIT_SLACK * (unit + np.abs(upper))


def outside_limits(limits: NDArray, prismatic: tuple[bool, ...], values: NDArray, length: float = 1.0
                   ) -> NDArray[np.int64]:
    """Index of the first joint outside its limits for each row of ``values`` (N, m); -1 if none.

    A revolute value counts as within its limits if it, or it plus or minus a full turn, is, to
    :data:`~screwkit.common.tolerances.LIMIT_SLACK` (:func:`slackened`; ``length``: the mechanism's length scale,
    a slide's unit there).
    """
    lowest, highest = slackened(limits[:, 0], limits[:, 1], np.where(np.asarray(prismatic, dtype=bool), length, 1.0))
    # NaN compares false: a chain that did not close is reported as such, not as a limit
    outside = values < lowest
    outside |= values > highest
    rows = np.flatnonzero(outside.any(axis=-1))
    first = np.full(values.shape[:-1], -1, dtype=np.int64)
    if not rows.size:
        return first
    revolute = ~np.asarray(prismatic, dtype=bool)  # the rows with a value outside: revolutes a turn either way
    some, still = values[rows], outside[rows]
    for turn in (2.0 * np.pi, -2.0 * np.pi):
        shifted = some + turn
        still &= ~(revolute & (shifted >= lowest) & (shifted <= highest))
    first[rows] = np.where(still.any(axis=-1), np.argmax(still, axis=-1), -1)
    return first


def _newton_chain(mechanism, index, flat, platform, start, sign, tolerance, max_iterations):
    """Chain ``index`` closed by continuation (:func:`~screwkit.closure.newton.solve_newton_chain`), the poses it
    leaves unclosed solved from many starts where that finds the working mode's one assembly
    (:func:`~screwkit.closure.around.newton_chain_around`)."""
    solved = solve_newton_chain(mechanism, index, flat, platform, start, sign, tolerance, max_iterations)
    return newton_chain_around(mechanism, index, platform, sign, tolerance, max_iterations, solved)


def solve(
    mechanism: Mechanism,
    poses: ArrayLike,
    *,
    branches: Sequence | None = None,
    initial: Solution | Sequence[ArrayLike] | None = None,
    method: Literal["auto", "newton"] = "auto",
    tolerance: float = NEWTON_TOLERANCE,
    max_iterations: int = 40,
    limits: bool = True,
) -> Solution:
    """Close every chain for a batch of platform poses, keeping the working mode.

    Parameters
    ----------
    mechanism : Mechanism
    poses : array_like, shape (..., n_task)
        Platform poses in the task coordinates (m, rad).
    branches : sequence, optional
        Per chain working mode; default each chain's :attr:`~screwkit.model.chain.Chain.branch`
        (the reference assembly). For a closed-form chain a tuple of +-1 signs; for a Newton
        chain the required sign of its twist-matrix determinant (None: no check). Newton
        continuation starts from the reference assembly; where it (or ``initial``) ends out of
        the sign asked, a planar chain of at most three joints is solved from starts over a turn
        of each hinge (:mod:`~screwkit.closure.around`), which reaches any sign's one assembly;
        another chain needs ``initial`` for another sign. With ``method="newton"`` closed-form
        chains keep the reference determinant sign.
    initial : Solution or sequence of array_like, optional
        Start values for Newton chains (per chain, broadcastable to (..., m_i)), e.g. a
        solution at nearby poses. Default: continuation from the reference assembly.
    method : {"auto", "newton"}
        ``"auto"`` uses a closed form for chains that have one; ``"newton"`` forces the
        generic solver everywhere (for checks).
    tolerance : float
        Newton convergence on the closure error norm (rad, and lengths in units of the mechanism's
        length scale: the same for any scaled copy).
    max_iterations : int
        Newton iterations per continuation step.
    limits : bool
        Whether a configuration with a joint outside the position limits of the file counts
        as unreachable (default; ``False``: the purely geometric workspace).

    Returns
    -------
    Solution
        Never raises for an unreachable pose: ``reachable`` is False there and ``status``,
        ``residuals`` and ``limit_joints`` say why (see :func:`solve_one`).
    """
    require_mechanism(mechanism, "solve")
    poses = mechanism.check_poses(poses)
    if method not in ("auto", "newton"):
        raise ValueError(f"Expected `method` 'auto' or 'newton', got {method!r}.")
    branches = _check_branches(mechanism, branches)
    batch = poses.shape[:-1]
    task_flat = poses.reshape(-1, mechanism.n_task)
    count = task_flat.shape[0]
    initial_values = _check_initial(mechanism, initial, batch)
    completed, complete_residual = np.ones(count, dtype=bool), np.zeros(count)
    if mechanism.dependent_indices:  # lower mobility: the dependent coordinates close the constraining chains
        flat, dependent_values, completed, complete_residual = complete_around(
            mechanism, task_flat, complete_poses(mechanism, task_flat), branches)
        initial_values = list(initial_values) if initial_values is not None else [None] * len(mechanism.chains)
        for index, chain_values in zip(constraining_chains(mechanism), dependent_values):
            if initial_values[index] is None:
                initial_values[index] = np.where(completed[:, None], chain_values, np.nan).reshape(
                    batch + (mechanism.chains[index].n_joints,))
    else:
        flat = task_flat
    cache = _PoseCache(mechanism, flat)
    values, axes, points = [], [], []
    chains = len(mechanism.chains)
    status = np.zeros((chains, count), dtype=np.int8)
    residuals = np.empty((chains, count))
    limit_joints = np.full((chains, count), -1, dtype=np.int64)
    for index, chain in enumerate(mechanism.chains):
        geometry = chain.geometry
        if chain.closed_form is not None and method == "auto":
            result = run_closed_form(mechanism, index, flat, branches[index], cache)
            chain_values, chain_reachable, chain_residual = result.values, result.reachable, result.gap
            chain_axes, chain_points = result.axes, result.points
        else:
            start = None if initial_values is None or initial_values[index] is None else \
                np.asarray(initial_values[index]).reshape(count, geometry.n_dofs)
            sign = branches[index] if chain.closed_form is None else chain.reference_sign
            if np.all(completed):
                chain_values, chain_reachable, chain_residual = _newton_chain(
                    mechanism, index, flat, cache.platform, start, sign, tolerance, max_iterations)
            else:  # where the dependent coordinates do not close, the pose is unreachable whatever this chain does
                todo = np.flatnonzero(completed)
                chain_values = np.full((count, geometry.n_dofs), np.nan)
                chain_reachable, chain_residual = np.zeros(count, dtype=bool), np.zeros(count)
                if todo.size:
                    chain_values[todo], chain_reachable[todo], chain_residual[todo] = _newton_chain(
                        mechanism, index, flat[todo], tuple(part[todo] for part in cache.platform),
                        None if start is None else start[todo], sign, tolerance, max_iterations)
            frames = chain_forward_kinematics(geometry, np.nan_to_num(chain_values))
            chain_axes, chain_points = frames.axes, frames.points
        if not np.all(completed):  # no dependent coordinates close the constraining chains
            chain_reachable = chain_reachable & completed
            chain_residual = np.where(completed, chain_residual, np.maximum(chain_residual, complete_residual))
        status[index] = np.where(chain_reachable, REACHABLE, MISSES_CLOSURE)
        if limits and np.any(np.isfinite(chain.joint_limits)):
            flat_values = chain_values() if callable(chain_values) else chain_values
            chain_values = flat_values
            outside = outside_limits(chain.joint_limits, chain.prismatic, flat_values.reshape(count, geometry.n_dofs),
                                     mechanism.length_scale)
            limit_joints[index] = np.where(chain_reachable, outside, -1)
            status[index] = np.where(chain_reachable & (outside >= 0), OUTSIDE_LIMITS, status[index])
        values.append(chain_values if callable(chain_values) else chain_values.reshape(batch + (geometry.n_dofs,)))
        residuals[index] = chain_residual
        axes.append(chain_axes.reshape(batch + chain_axes.shape[-2:]))
        points.append(chain_points.reshape(batch + chain_points.shape[-2:]))
    chain_reachable = status == REACHABLE
    return Solution(
        poses=poses,
        full_poses=flat.reshape(batch + (mechanism.n_pose,)),
        reachable=np.logical_and.reduce(chain_reachable, axis=0).reshape(batch),
        chain_reachable=chain_reachable.T.reshape(batch + (chains,)),
        status=status.T.reshape(batch + (chains,)),
        residuals=residuals.T.reshape(batch + (chains,)),
        limit_joints=limit_joints.T.reshape(batch + (chains,)),
        joint_axes=tuple(axes),
        joint_points=tuple(points),
        value_sources=tuple(values),
    )


BOUNDARY_MISS = 1e-9
"""A closure missed by less than this many length scales is said to miss at the boundary of the reach, to rounding
(a chain stretched or folded exactly: a pose typed on the boundary misses by about 1e-12 of them), not outside it."""


def unreachable_reason(mechanism: Mechanism, solution: Solution, index: tuple = ()) -> str:
    """Why the pose at ``index`` of a solution is unreachable, worst chain first (one line)."""
    check_solution(mechanism, solution, "unreachable_reason")
    batch = solution.batch_shape
    index = tuple(index) if isinstance(index, (tuple, list)) else (index,)
    if len(index) != len(batch) or not all(isinstance(i, (int, np.integer)) and not isinstance(i, bool) and -n <= i < n
                                           for i, n in zip(index, batch)):
        raise ValueError(f"Expected `index` of one pose of the solution's batch {batch} (a tuple of {len(batch)} "
                         f"int), got {index!r}.")
    status = solution.status[index]
    residuals = solution.residuals[index]
    missing = [c for c in np.flatnonzero(status == MISSES_CLOSURE)]
    missing.sort(key=lambda c: -float(residuals[c]) if np.isfinite(residuals[c]) else -np.inf)
    parts = []
    shared = [float(residuals[c]) for c in missing]
    if len(missing) > 1 and mechanism.dependent_indices and np.allclose(shared, shared[0], rtol=1e-9, atol=0.0):
        # the dependent coordinates were solved with every chain together: one residual for all of them
        dependent = ", ".join(mechanism.pose_coordinates[i] for i in mechanism.dependent_indices)
        on_it = shared[0] < BOUNDARY_MISS * mechanism.length_scale
        where = ("on the boundary of the workspace to rounding, where chains stretch or fold: a singular "
                 "configuration, whose indices a pose beside it reads" if on_it else "outside the workspace")
        parts.append(f"no {dependent} closes chains {', '.join(repr(mechanism.chains[c].name) for c in missing)} "
                     f"together (the closure of the dependent coordinates misses by {shared[0]:.6g}, Newton error "
                     f"norm in m and rad: the pose is {where})")
        missing = []
    for c in missing:
        chain = mechanism.chains[c]
        unit = "m" if chain.closed_form is not None else "(Newton error norm, m and rad)"
        if chain.closed_form is not None and residuals[c] < BOUNDARY_MISS * mechanism.length_scale:
            parts.append(f"chain {chain.name!r} closes only to rounding (the pose is on the boundary of its reach, "
                         "or its end on the axis of its base joint, where its joint values are not determined)")
        elif chain.closed_form is None and chain.branch is not None and \
                residuals[c] < 1e3 * NEWTON_TOLERANCE * max(1.0, mechanism.length_scale):  # (closed, but in another)
            searched = ", and no one assembly with it was found from starts over a turn of each of its hinges" \
                if around_searched(mechanism, c) else ""
            parts.append(f"chain {chain.name!r} closes there only in another assembly than its working mode (the "
                         "sign that names it changed on the way from the reference assembly: the way passes where "
                         f"the chain's joints are singular, or leaves its reach{searched})")
        else:
            parts.append(f"chain {chain.name!r} misses closure by {residuals[c]:.6g} {unit}")
    for c in np.flatnonzero(status == OUTSIDE_LIMITS):
        chain = mechanism.chains[c]
        joint = int(solution.limit_joints[index][c])
        value = float(solution.joint_values[c][index][joint])
        lower, upper = chain.joint_limits[joint]
        unit = "m" if chain.prismatic[joint] else "rad"
        bound = lower if value < lower else upper
        parts.append(f"chain {chain.name!r}: joint {chain.joint_names[joint]!r} at {_distinct(value, bound)} {unit} is "
                     f"outside its limits [{lower:.6g}, {upper:.6g}]")
    return "; ".join(parts)


def _distinct(value: float, bound: float) -> str:
    """``value`` to 6 significant digits, or as many more as tell it from ``bound`` (a joint just past its limit)."""
    for digits in range(6, 18):
        if f"{value:.{digits}g}" != f"{bound:.{digits}g}":
            return f"{value:.{digits}g}"
    return repr(float(value))


def solve_one(mechanism: Mechanism, pose: ArrayLike, **options) -> Solution:
    """Solve a single pose (n_task,); raise :class:`UnreachablePose` naming the worst chain if unreachable.

    The message names every chain that fails, the one that misses its closure by the most
    first, and joints outside their limits with their values (``limits=False`` ignores them).
    """
    require_mechanism(mechanism, "solve_one")
    pose = mechanism.check_poses(pose)
    if pose.ndim != 1:
        raise ValueError(f"Expected one pose with shape ({mechanism.n_task},), got {pose.shape}.")
    solution = solve(mechanism, pose, **options)
    if not solution.reachable:
        raise UnreachablePose(f"Pose ({spelled_pose(mechanism.task_coordinates, pose)}) is unreachable for "
                              f"mechanism {mechanism.name!r}: "
                              f"{unreachable_reason(mechanism, solution)}.")
    return solution


def actuator_values(mechanism: Mechanism, joint_values: Sequence[ArrayLike]) -> NDArray[np.float64]:
    """Values (..., a) of all actuators, in :attr:`~Mechanism.actuators` order.

    ``joint_values`` holds one array (..., m_i) per chain, e.g. ``solution.joint_values`` (or the solution).
    """
    require_mechanism(mechanism, "actuator_values")
    if isinstance(joint_values, Solution):
        joint_values = check_solution(mechanism, joint_values, "actuator_values").joint_values
    try:
        joint_values = tuple(np.asarray(values, dtype=float) for values in joint_values)
    except (TypeError, ValueError):
        raise ValueError(f"Expected `joint_values` as one numeric array (..., m_i) per chain of {mechanism.name!r}, "
                         f"got {joint_values!r:.60}.") from None
    given = [values.shape[-1:] for values in joint_values]
    wanted = [(chain.n_joints,) for chain in mechanism.chains]
    if given != wanted or len({values.shape[:-1] for values in joint_values}) > 1:
        raise ValueError(f"Expected `joint_values` of mechanism {mechanism.name!r}: {len(wanted)} arrays (..., m_i) "
                         f"of one batch shape, m_i = {[m for m, in wanted]}, got shapes "
                         f"{[values.shape for values in joint_values]}.")
    return np.stack([np.asarray(joint_values[chain])[..., joint]
                     for chain, joint in mechanism.actuator_positions(None)], -1)


def closure_residuals(mechanism: Mechanism, solution: Solution) -> NDArray[np.float64]:
    """Loop-closure error norm (rad and m) of every chain, recomputed by forward kinematics.

    Returns an array (..., n_chains); NaN where the chain did not close.
    """
    check_solution(mechanism, solution, "closure_residuals")
    rotation, translation = mechanism.transforms_from_poses(solution.full_poses)
    residuals = []
    for index, chain in enumerate(mechanism.chains):
        frames = chain_forward_kinematics(chain.geometry, solution.joint_values[index])
        target_rotation, target_translation = mechanism.loop_targets(index, rotation, translation)
        error = pose_error(target_rotation, target_translation, frames.end_rotation, frames.end_translation)
        residuals.append(np.linalg.norm(error, axis=-1))
    return np.stack(residuals, -1)


def check_solution(mechanism: Mechanism, solution: Solution, function: str) -> Solution:
    """``solution``, checked to be a :class:`Solution` of ``mechanism`` (its chains, their joints and its task
    coordinates), or a one-line error saying what ``function`` got instead."""
    require_mechanism(mechanism, function)
    if not isinstance(solution, Solution):
        raise TypeError(f"{function} expects a Solution (from screwkit.closure.solve or forward), got "
                        f"{type(solution).__name__}.")
    joints = [axes.shape[-2] for axes in solution.joint_axes]
    if joints != [chain.n_joints for chain in mechanism.chains] or solution.poses.shape[-1] != mechanism.n_task:
        raise ValueError(f"Expected a Solution of mechanism {mechanism.name!r} ({len(mechanism.chains)} chains of "
                         f"{[chain.n_joints for chain in mechanism.chains]} joints, {mechanism.n_task} task "
                         f"coordinates) in {function}, got one of {len(joints)} chains of {joints} joints, "
                         f"{solution.poses.shape[-1]} task coordinates: solved for another mechanism.")
    return solution
