"""Whether the way from the reference assembly to a pose passes a singular configuration of a chain.

A chain closed by damped Newton keeps the reference assembly's working mode by the sign of its joint-twist
determinant (:func:`~screwkit.closure.newton.determinant_sign`), reaching each pose by continuation along the
straight way from the reference pose. Where that way passes a configuration at which the chain's joints are
singular (its twists dependent: two assemblies of the chain meet there), the same sign beyond it is the other
assembly of the chain, not the one a motion through that configuration may continue into. A square four-bar
(every link as long) is the plain case: at the crank's 90 deg its end lies on the rocker's pivot, the
parallelogram and the folded assembly meet, and beyond it the reference's sign is the folded one, where the crank
stays at 90 deg while the rocker turns (published: Genesis's ``four_bar_linkage.xml``).

:func:`singular_on_the_ways` samples the ways to a batch of poses (a sweep's, or ``analyze --pose``'s one, through
:func:`singular_on_the_way`), :func:`singular_along` takes a path's samples (a ``"singular"`` event of ``screwkit
trajectory``); both find where the chain's normalised determinant dips, and refine the dips (golden-section search
on the way's parameter, or the path's arc length, every dip of a batch at once) to tell a configuration where the
joints are singular (the determinant below :data:`SINGULAR`) from one merely near it.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from screwkit.closure.chain_kinematics import chain_forward_kinematics, twists_from_axes_and_points
from screwkit.closure.newton import task_rows
from screwkit.closure.solve import solve
from screwkit.model import Mechanism

__all__ = ["singular_on_the_way", "singular_on_the_ways", "singular_along", "SAMPLES", "SINGULAR", "OTHER_ASSEMBLY"]

SAMPLES = 129
"""Poses sampled on the way from the reference pose (both ends included)."""

SINGULAR = 1e-4
"""A chain's normalised joint-twist determinant (moments about the centre of its joints' points, in length scales;
each twist made unit: the same whatever the world frame and the unit) below which its joints count as singular: a
dip refined to below it is a configuration where two of its assemblies meet."""

OTHER_ASSEMBLY = "not necessarily the assembly a motion through it continues into"
"""How every message of a pose past such a configuration ends: what the working-mode sign kept there does not say."""

_DIP = 0.2
"""A sampled dip (a local minimum inside the way) refined only if it is below this."""


WAYS_PER_BATCH = 1024
"""Ways sampled and solved at a time by :func:`singular_on_the_ways` (their samples' memory bounded)."""


def sign_kept_chains(mechanism: Mechanism) -> list[int]:
    """The chains closed by damped Newton with a working-mode sign and as many joints as task rows: those whose
    assembly past a singular configuration of their joints is the other one (their determinant is square)."""
    return [k for k, chain in enumerate(mechanism.chains) if chain.closed_form is None and chain.branch is not None
            and chain.geometry.n_dofs == len(task_rows(mechanism.is_planar))]


def singular_on_the_way(mechanism: Mechanism, pose: NDArray) -> list[tuple[str, NDArray[np.float64]]]:
    """Per chain closed by damped Newton with a working-mode sign, the first singular configuration of its joints
    on the straight way in task coordinates from the reference pose to ``pose`` (m and rad), as ``(chain name, the
    pose there)``; none for a chain whose way has none, or whose way leaves its reach (a sample where it does not
    close: the pose's assembly is then the one its working-mode sign names, solved from starts,
    :mod:`~screwkit.closure.around`, which no configuration on the way tells)."""
    found = singular_on_the_ways(mechanism, np.asarray(pose, dtype=float)[None])
    return [(name, where[0]) for name, passed, where in found if passed[0]]


def singular_on_the_ways(mechanism: Mechanism, poses: NDArray) -> list[tuple[str, NDArray, NDArray]]:
    """:func:`singular_on_the_way` for a batch of poses (n, n_task): per chain it applies to, ``(chain name, whether
    the way to each pose passes a singular configuration of its joints (n,), the first such pose on each way
    (n, n_task; NaN where none))``. The ways are sampled (:data:`SAMPLES` poses each, solved in batches of
    :data:`WAYS_PER_BATCH` ways) and their dips refined together."""
    poses = np.asarray(poses, dtype=float).reshape(-1, mechanism.n_task)
    chains = sign_kept_chains(mechanism)
    start = np.asarray(mechanism.home_pose, dtype=float)
    passed = {k: np.zeros(len(poses), dtype=bool) for k in chains}
    where = {k: np.full(poses.shape, np.nan) for k in chains}
    direction = _one_line(poses - start) if chains else None
    if direction is not None:  # every way a stretch of one line (a sweep from the reference pose): sampled once
        along = (poses - start) @ direction
        line = np.linspace(min(along.min(), 0.0), max(along.max(), 0.0), SAMPLES)
        samples = start + line[:, None] * direction
        values = solve(mechanism, samples, limits=False).joint_values
        found = singular_along(mechanism, samples, line, lambda t: start + np.asarray(t)[..., None] * direction,
                               values=values)
        names = [mechanism.chains[k].name for k in chains]
        for name, t, _ in sorted(found, key=lambda item: abs(item[1]), reverse=True):  # the nearest written last
            k = chains[names.index(name)]
            beyond = (np.sign(along) == np.sign(t)) & (np.abs(along) >= abs(t)) & (t != 0.0)
            beyond &= ~_leaves_reach(line, np.all(np.isfinite(values[k]), axis=-1), along)
            passed[k] |= beyond
            where[k][beyond] = start + t * direction
        return [(mechanism.chains[k].name, passed[k], where[k]) for k in chains]
    way = np.linspace(0.0, 1.0, SAMPLES)
    for first in range(0, len(poses) if chains else 0, WAYS_PER_BATCH):
        rows = np.arange(first, min(first + WAYS_PER_BATCH, len(poses)))
        rows = rows[np.any(poses[rows] != start, axis=1)]  # (the reference pose's own way has no length)
        if not rows.size:
            continue
        sampled = start + way[None, :, None] * (poses[rows] - start)[:, None, :]
        solved = solve(mechanism, sampled.reshape(-1, mechanism.n_task), limits=False).joint_values
        for k in chains:
            determinants = _normalised(mechanism, k, np.asarray(solved[k], dtype=float)).reshape(len(rows), SAMPLES)
            inside = np.all(np.isfinite(determinants), axis=1)  # ways that leave the chain's reach are not noted
            candidates = [(row, i) for row, line in zip(rows[inside], determinants[inside]) for i in _dips(line)]
            if not candidates:
                continue
            owner = np.array([row for row, _ in candidates])
            lows = np.array([way[max(i - 1, 0)] for _, i in candidates])
            highs = np.array([way[min(i + 1, SAMPLES - 1)] for _, i in candidates])
            at, values = _refined(mechanism, k, lambda t, r=owner: start + t[:, None] * (poses[r] - start), lows, highs)
            for row, t in sorted(zip(owner[values < SINGULAR], at[values < SINGULAR]), key=lambda pair: pair[1],
                                 reverse=True):  # the first on each way written last
                passed[k][row], where[k][row] = True, start + t * (poses[row] - start)
    return [(mechanism.chains[k].name, passed[k], where[k]) for k in chains]


def _leaves_reach(line: NDArray, closed: NDArray, along: NDArray) -> NDArray[np.bool_]:
    """Of the poses at ``along`` on a line sampled at ``line`` (the chain ``closed`` at each sample), those whose way
    from the reference (``along`` 0) passes a sample where the chain does not close: their assembly is not the one
    the way continues into but the one the working-mode sign names (solved from starts,
    :mod:`~screwkit.closure.around`), so no configuration on the way says anything of it."""
    open_at = line[~closed][None, :]
    along = np.asarray(along, dtype=float)[:, None]
    return np.any((open_at * np.sign(along) > 0) & (np.abs(open_at) <= np.abs(along)), axis=1)


def singular_along(mechanism: Mechanism, poses: NDArray, at: NDArray, pose_at, *,
                   values=None) -> list[tuple[str, float, int]]:
    """Per chain closed by damped Newton with a working-mode sign, the singular configurations of its joints along
    the samples ``poses`` (n, n_task) at parameters ``at`` (n,, increasing), ``pose_at(t)`` giving the poses at the
    parameters ``t`` (k,) between them (k, n_task): ``(chain name, the parameter there, the sample nearest before
    it)``, refined between the samples either side of each dip of its normalised determinant (and in the first and
    last intervals). ``values``: per chain its joint values at the samples, where already solved (a chain's are used
    when they are all its joints)."""
    found, solved = [], None
    last = len(at) - 1
    for k in sign_kept_chains(mechanism):
        given = None if values is None else np.asarray(values[k], dtype=float)
        if given is None or given.shape[-1] != mechanism.chains[k].geometry.n_dofs:
            if solved is None:  # every chain's closure at the samples, solved once for all the chains looked at
                solved = solve(mechanism, poses, limits=False).joint_values
            given = np.asarray(solved[k], dtype=float)
        dips = _dips(_normalised(mechanism, k, given))
        if not dips:
            continue
        lows = np.array([at[max(i - 1, 0)] for i in dips])
        highs = np.array([at[min(i + 1, last)] for i in dips])
        where, value = _refined(mechanism, k, pose_at, lows, highs)
        for t in where[value < SINGULAR]:  # (in the dips' order: along the path)
            found.append((mechanism.chains[k].name, float(t), int(np.searchsorted(at, t, side="right")) - 1))
    return found


def _one_line(offsets: NDArray) -> NDArray | None:
    """The unit direction of the line through the reference pose that every pose lies on (their ``offsets`` from
    it, (n, n_task), to 1e-12 of the farthest), or None."""
    lengths = np.linalg.norm(offsets, axis=1)
    if len(offsets) < 2 or not lengths.max() > 0.0:
        return None
    direction = offsets[np.argmax(lengths)] / lengths.max()
    across = offsets - (offsets @ direction)[:, None] * direction
    return direction if np.linalg.norm(across, axis=1).max() <= 1e-12 * lengths.max() else None


def _dips(determinants: NDArray) -> list[int]:
    """The samples (in order) where a normalised determinant along a way or path dips below :data:`_DIP`: inside,
    no higher than either neighbour; at an end, lower than its neighbour. A neighbour where the chain does not close
    is left out of the comparison when the chain closes again beyond it (damped Newton may fail right beside a
    singular configuration it passes: the refinement looks between them); where it never closes again on that side
    (the edge of the workspace, where a chain stretched out is singular too), the sample is no dip."""
    finite = np.isfinite(determinants)
    last = len(determinants) - 1
    closes_before = np.cumsum(finite) - finite > 0  # some sample before closes
    closes_after = np.cumsum(finite[::-1])[::-1] - finite > 0  # some sample after closes
    dips = []
    for i in np.flatnonzero(finite & (np.where(finite, determinants, np.inf) < _DIP)):
        neighbours = [j for j in (i - 1, i + 1) if 0 <= j <= last]
        if any(not finite[j] and not (closes_before[j] if j < i else closes_after[j]) for j in neighbours):
            continue
        closing = [j for j in neighbours if finite[j]]
        if i in (0, last) and last > 0:
            keep = all(determinants[i] < determinants[j] for j in closing)
        else:
            keep = all(determinants[i] <= determinants[j] for j in closing)
        if keep:
            dips.append(int(i))
    return dips


def _determinants(mechanism: Mechanism, k: int, poses: NDArray) -> NDArray[np.float64]:
    """Chain ``k``'s normalised |joint-twist determinant| at ``poses`` (NaN where it does not close)."""
    solution = solve(mechanism, poses, limits=False)
    return _normalised(mechanism, k, np.asarray(solution.joint_values[k], dtype=float))


def _normalised(mechanism: Mechanism, k: int, values: NDArray) -> NDArray[np.float64]:
    """Chain ``k``'s normalised |joint-twist determinant| at its joint values (..., m; NaN where not closed)."""
    geometry = mechanism.chains[k].geometry
    closed = np.all(np.isfinite(values), axis=-1)
    frames = chain_forward_kinematics(geometry, np.nan_to_num(values))
    points = frames.points - np.mean(frames.points, axis=-2, keepdims=True)  # moments about the chain's own centre
    twists = twists_from_axes_and_points(frames.axes, points, geometry.dof_prismatic)
    twists = np.concatenate([twists[..., :3], twists[..., 3:] / mechanism.length_scale], axis=-1)
    twists = twists[..., task_rows(mechanism.is_planar)]
    twists = twists / np.maximum(np.linalg.norm(twists, axis=-1, keepdims=True), 1e-300)
    return np.where(closed, np.abs(np.linalg.det(twists)), np.nan)


def _refined(mechanism: Mechanism, k: int, poses_at, lows: NDArray, highs: NDArray,
             iterations: int = 20) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The least normalised determinant of chain ``k`` between each pair of parameters ``lows`` and ``highs`` (k,),
    found by golden section, every interval at once (``poses_at(t)``: the poses (k, n_task) at parameters t (k,)):
    the parameters and the values."""
    ratio = (math.sqrt(5.0) - 1.0) / 2.0

    def value(t: NDArray) -> NDArray:
        found = _determinants(mechanism, k, np.asarray(poses_at(t), dtype=float))
        return np.where(np.isfinite(found), found, np.inf)

    a, b = np.asarray(lows, dtype=float).copy(), np.asarray(highs, dtype=float).copy()
    c, d = b - ratio * (b - a), a + ratio * (b - a)
    fc, fd = value(c), value(d)
    for _ in range(iterations):
        left = fc <= fd  # the least lies in [a, d] (d's place taken by c), else in [c, b] (c's by d)
        a, b = np.where(left, a, c), np.where(left, d, b)
        kept, f_kept = np.where(left, c, d), np.where(left, fc, fd)
        probe = np.where(left, b - ratio * (b - a), a + ratio * (b - a))
        f_probe = value(probe)
        c, fc = np.where(left, probe, kept), np.where(left, f_probe, f_kept)
        d, fd = np.where(left, kept, probe), np.where(left, f_kept, f_probe)
    return np.where(fc <= fd, c, d), np.where(fc <= fd, fc, fd)
