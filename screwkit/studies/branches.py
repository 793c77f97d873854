"""Changes of working mode along a path: a chain whose joint values jump between two samples.

The closures keep each chain's working mode pose by pose (a closed form its branch sign; damped Newton the
reference assembly's, by continuation from it, and the sign of its joint-twist determinant): see
:func:`screwkit.closure.working_modes`. Pose by pose is not path by path. A branch defined by a sign can fold
over itself: on the paper's 5-RRR (equal arms), when a platform joint passes over its base joint, "the elbow on
the left of the line from the base joint to the platform joint" changes sides with the line, and the closed form
puts the elbow back on the left: a jump of half a turn of the actuated joint, between two samples of a smooth
motion of the platform. Newton from the reference assembly can land on another assembly at one pose than at the
next, and so can the continuation that closes a leg with loops inside it from its file's configuration (each
pose reached along its own straight line). Indices computed on both sides are each right for their assembly;
the motion between them is not one a robot can make without leaving the path. :func:`branch_changes` finds
such jumps and locates them:

1. **Screen** (every pair of consecutive samples, every chain, batched). The step of the values of the joints a
   chain's working mode is seen on (:class:`ChainJoints`: a serial chain's tree joints, which with the platform
   pose fix its configuration; a leg with loops inside it, its revolute and prismatic joints), revolute steps
   wrapped to (-pi, pi], slides divided by the length scale, against the step the neighbouring segments
   predict, their rates times this segment's arc length. A segment is suspect where the step misses that
   prediction by more than the prediction itself (plus :data:`STEP_FLOOR`): a jump of the size of the joints'
   own motion over a sample step is seen.
2. **Bisection** (all suspects at once, one closure solve per round). The suspect segment is split (at its
   golden section, :data:`SPLIT`), keeping the part with the larger joint step, until it is at most
   ``tolerance`` long. A smooth motion's step shrinks with the bracket, however fast the joints turn near a
   singularity; a jump does not. A change of working mode is reported where the last bracket still holds at
   least :data:`JUMP_SHARE` of the first step; a point between the samples where the chain does not close at all
   is reported as a closure the path cannot follow.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np
from numpy.typing import NDArray

from screwkit.common.rotations import wrap_angle
from screwkit.model import Mechanism

__all__ = ["BranchChange", "ChainJoints", "branch_changes", "chain_joints", "describe", "joint_steps",
           "suspect_segments", "STEP_FLOOR", "JUMP_SHARE"]

STEP_FLOOR = 1e-9
"""Joint steps (rad, or length scales for a slide) below which nothing is suspected."""
SPLIT = (3.0 - 5.0 ** 0.5) / 2
"""Where a bracket is split (a share of its length from its start): the golden section rather than the middle,
so that a path symmetric about a singular pose (where a closed form's branch is undefined) does not put a split
point exactly on it."""
JUMP_SHARE = 0.25
"""The share of a suspect segment's joint step that its last bracket (``tolerance`` long) must still hold for the
step to be a jump (a smooth motion keeps about ``tolerance / segment`` of it)."""


@dataclass(frozen=True)
class ChainJoints:
    """What a chain's working mode is seen on along a path: its name, the joints whose values a branch change makes
    jump (a serial chain's tree joints, which with the platform pose fix its configuration; a leg with loops
    inside it, its revolute and prismatic joints) and which of them slide."""

    name: str
    joints: tuple[str, ...]
    prismatic: tuple[bool, ...]


def chain_joints(mechanism: Mechanism) -> tuple[ChainJoints, ...]:
    """The :class:`ChainJoints` of a mechanism's chains: each chain's tree joints."""
    return tuple(ChainJoints(chain.name, tuple(chain.joint_names[:chain.geometry.n_tree_joints]),
                             tuple(bool(p) for p in chain.geometry.dof_prismatic[:chain.geometry.n_tree_joints]))
                 for chain in mechanism.chains)


@dataclass(frozen=True)
class BranchChange:
    """A chain's joint values jumping between two samples (``kind="branch"``), or a chain that cannot close at a
    point between them (``kind="closure"``): the chain, the segment's samples, the last bracket of arc length
    (m) and, for a jump, the joint that jumps the most with its values on both sides (rad or m)."""

    kind: str
    chain: int
    samples: tuple[int, int]
    start: float
    stop: float
    joint: int = -1
    before: float = np.nan
    after: float = np.nan


def _scaled(chains: Sequence[ChainJoints], length_scale: float, joint_values) -> list[NDArray[np.float64]]:
    """Per chain, its joint values (N, t_i), slides in length scales."""
    return [np.asarray(values, dtype=float) / np.where(np.asarray(chain.prismatic, dtype=bool), length_scale, 1.0)
            for chain, values in zip(chains, joint_values)]


def joint_steps(chain: ChainJoints, before: NDArray, after: NDArray) -> NDArray[np.float64]:
    """The steps (..., t) of a chain's joint values from ``before`` to ``after`` (as from :func:`_scaled`): revolute
    steps wrapped to (-pi, pi], slides in length scales."""
    revolute = ~np.asarray(chain.prismatic, dtype=bool)
    steps = after - before
    steps[..., revolute] = wrap_angle(steps[..., revolute])
    return steps


def suspect_segments(steps: NDArray, lengths: NDArray) -> NDArray[np.bool_]:
    """Segments (n - 1,) whose joint steps (n - 1, t) miss the prediction of their neighbours' rates times their
    arc length ``lengths`` (n - 1,) by more than that prediction (plus :data:`STEP_FLOOR`); NaN steps (a sample
    where the chain does not close) are not suspected, nor used as neighbours."""
    with np.errstate(invalid="ignore", divide="ignore"):
        rates = np.where(lengths[:, None] > 0, steps / lengths[:, None], np.nan)
    # the same sums and maxima as over the stacked neighbours, taken column by column (a chain has few joints)
    finite = np.ones(rates.shape[0], dtype=bool)
    for column in rates.T:
        finite &= np.isfinite(column)
    previous, following = np.zeros_like(rates), np.zeros_like(rates)
    previous[1:] = np.where(finite[:-1, None], rates[:-1], 0.0)
    following[:-1] = np.where(finite[1:, None], rates[1:], 0.0)
    count = np.zeros(rates.shape[0], dtype=np.int64)
    count[1:] += finite[:-1]
    count[:-1] += finite[1:]
    predicted = (previous + following) / np.maximum(count, 1)[:, None] * lengths[:, None]
    miss = _row_max(np.abs(steps - predicted))
    return np.isfinite(miss) & (miss > _row_max(np.abs(predicted)) + STEP_FLOOR)


def _bridged(chain: ChainJoints, values: NDArray, arc_length: NDArray) -> list[int]:
    """The samples where the chain alone does not close between two where it does (a pose exactly where its joint
    values are not determined: its end on its base joint's axis, the middle of a branch change), whose step
    across, from the sample before to the one after, is suspect against the segments either side."""
    finite = np.all(np.isfinite(values), axis=-1)
    lone = np.flatnonzero(~finite[1:-1] & finite[:-2] & finite[2:]) + 1
    bridged = []
    for i in lone:
        around = np.array([k for k in (i - 2, i - 1, i + 1, i + 2) if 0 <= k < len(finite)])
        steps = joint_steps(chain, values[around[:-1]], values[around[1:]])
        across = int(np.flatnonzero(around == i - 1)[0])  # the segment from i - 1 to i + 1
        if suspect_segments(steps, np.diff(arc_length[around]))[across]:
            bridged.append(int(i))
    return bridged


def _row_max(values: NDArray) -> NDArray[np.float64]:
    """The maximum of each row (NaN if any is NaN), a column at a time."""
    if values.shape[-1] == 0:
        return np.max(values, axis=-1)
    largest = values[:, 0].copy()
    for column in values.T[1:]:
        np.maximum(largest, column, out=largest)
    return largest


def branch_changes(chains: Sequence[ChainJoints], length_scale: float, arc_length: NDArray, joint_values,
                   solve_at: Callable, tolerance: float) -> list[BranchChange]:
    """Every jump of a chain's joint values between consecutive samples, located to ``tolerance`` (m of arc length).

    Parameters
    ----------
    arc_length : ndarray (n,)
        The samples' arc lengths.
    chains : sequence of ChainJoints
        The joints each chain's working mode is seen on (:func:`chain_joints`).
    length_scale : float
        The mechanism's length scale (m), the unit of a slide's step.
    joint_values : sequence of ndarray (n, t_i)
        Per chain, the values of those joints at the samples (NaN where it does not close).
    solve_at : callable
        ``solve_at(arc_lengths)`` -> per chain the values (k, t_i) of those joints at those arc lengths.
    """
    tree = _scaled(chains, length_scale, joint_values)
    lengths = np.diff(arc_length)
    brackets = []  # (chain, first sample, last sample)
    for chain, values in enumerate(tree):
        if values.shape[-1] == 0:
            continue
        steps = joint_steps(chains[chain], values[:-1], values[1:])
        brackets += [(chain, int(i), int(i) + 1) for i in np.flatnonzero(suspect_segments(steps, lengths))]
        brackets += [(chain, i - 1, i + 1) for i in _bridged(chains[chain], values, arc_length)]
    if not brackets:
        return []
    of = np.array([c for c, _, _ in brackets])
    segments = np.array([(i, k) for _, i, k in brackets])
    low, high = arc_length[segments[:, 0]].astype(float), arc_length[segments[:, 1]].astype(float)
    left = [tree[c][i] for c, i, _ in brackets]
    right = [tree[c][k] for c, _, k in brackets]
    first = np.array([np.max(np.abs(joint_steps(chains[c], a, b))) for c, a, b in zip(of, left, right)])
    found: list[BranchChange] = []
    jumps: list[int] = []
    active = np.arange(len(brackets))
    while active.size:
        middle = low[active] + SPLIT * (high[active] - low[active])
        at_middle = _scaled(chains, length_scale, solve_at(middle))
        keep = []
        for row, k in enumerate(active):
            c = of[k]
            value = at_middle[c][row]
            if not np.all(np.isfinite(value)):
                found.append(BranchChange("closure", int(c), (int(segments[k, 0]), int(segments[k, 1])),
                                          float(middle[row]), float(middle[row])))
                continue
            before = np.max(np.abs(joint_steps(chains[c], left[k], value)))
            after = np.max(np.abs(joint_steps(chains[c], value, right[k])))
            if before >= after:
                high[k], right[k] = middle[row], value
            else:
                low[k], left[k] = middle[row], value
            largest = max(before, after)
            if largest < JUMP_SHARE * first[k] / 4 or largest < STEP_FLOOR:
                continue  # shrinking with the bracket: a smooth motion
            if high[k] - low[k] > tolerance:
                keep.append(k)
            elif largest >= JUMP_SHARE * first[k]:
                jumps.append(k)
        active = np.array(keep, dtype=np.int64)
    found += _jumps(chains, length_scale, [(int(of[k]), tuple(int(i) for i in segments[k]), low[k], high[k])
                                           for k in jumps], solve_at, tolerance, arc_length[-1])
    return sorted(found, key=lambda change: (change.start, change.chain))


def _jumps(chains: Sequence[ChainJoints], length_scale: float, located: list, solve_at: Callable, tolerance: float,
           length: float) -> list[BranchChange]:
    """The :class:`BranchChange` of each located jump ``(chain, samples, low, high)``: the joint that jumps the
    most, with its values (rad or m) one ``tolerance`` either side of the bracket (at its ends the pose may be
    the singular one, where the branch is undefined); one batched solve."""
    if not located:
        return []
    ends = np.array([[low - tolerance, high + tolerance] for _, _, low, high in located]).clip(0.0, length)
    values = _scaled(chains, length_scale, solve_at(ends.reshape(-1)))
    changes = []
    for row, (chain, samples, low, high) in enumerate(located):
        left, right = values[chain][2 * row], values[chain][2 * row + 1]
        joint = int(np.argmax(np.abs(joint_steps(chains[chain], left, right))))
        scale = length_scale if chains[chain].prismatic[joint] else 1.0
        changes.append(BranchChange("branch", chain, samples, float(low), float(high), joint,
                                    float(left[joint] * scale), float(right[joint] * scale)))
    return changes


def describe(chains: Sequence[ChainJoints], change: BranchChange) -> str:
    """One line: which chain changes working mode (or cannot close) and how."""
    chain = chains[change.chain]
    if change.kind == "closure":
        return (f"chain {chain.name!r} cannot close at {change.start:.6g} m, between samples {change.samples[0]} "
                f"and {change.samples[1]} where it closes: the path leaves its working mode's workspace there")
    slides = chain.prismatic[change.joint]
    shown = (lambda v: f"{v:.6g} m") if slides else (lambda v: f"{np.rad2deg(v):.6g} deg")
    return (f"chain {chain.name!r} changes working mode: joint {chain.joints[change.joint]!r} jumps from "
            f"{shown(change.before)} to {shown(change.after)} at {(change.start + change.stop) / 2:.6g} m (located to "
            f"{change.stop - change.start:.2g} m, between samples {change.samples[0]} and {change.samples[1]}): "
            f"its closure on one side is not the continuation of the other side's")
