"""Fault tolerance along a path: will a planned motion stay controllable if actuators fail on the way?

:func:`trajectory` computes every index at the samples of a :class:`~screwkit.studies.paths.Path` in one
batched call of :func:`~screwkit.studies.poses.indices_at_poses` (the closures keep the working mode of the
reference assembly at every sample, as ``analyze`` does), then, for every set ``E`` of ``j`` failed actuators
(``j`` up to the redundancy ``a - n``), follows the LMTI of the actuators left, :math:`{}^{A \\setminus E}LMTI`,
whose minimum over the sets is :math:`F_{Oj}` (Eq. 12):

* the **stretches** of arc length where it is at least ``level`` (the remaining actuators keep the platform
  controllable with that transmission) and those where it is not, the **first point** where control is lost,
  its **minimum** along the path and where, and the **worst failure** of the path (the lowest minimum; ties
  within :data:`~screwkit.common.tolerances.WORST_FAULT_TIE` all named);
* between samples, nothing is taken on trust: a dip that the samples show as a local minimum is searched for
  its true minimum (a singular pose between two samples is found at zero), and every change of side of
  ``level`` is searched for, until located to ``tolerance`` in arc length (:mod:`~screwkit.studies.refinement`:
  each from the guess the samples give, a parabola's vertex, a kink's, a straight line's crossing, then a grid
  of points a round); every round evaluates all its brackets in one batched call;
* the **margin** of each index (its minimum over the samples and where; F_Oj's also over the refined minima);
* the **events** of the path: where it leaves the reachable set, because a chain cannot close in its working
  mode or because a joint crosses its limit, located by bisection and explained chain by chain; where a
  chain changes working mode between two samples (its joint values jump, :mod:`~screwkit.studies.branches`),
  located to the tolerance, never silently jumped; and where a chain's joints are singular, two of its
  assemblies meeting, past which its working-mode sign is kept (:mod:`~screwkit.closure.on_the_way`).

With ``aggregate="mean"`` the average case is reported beside the worst case: the mean of the LMTI left over
the sets of ``j`` failures, or their probability-weighted mean (screwkit's extension of Eq. 12, which the
paper mentions and leaves aside; :mod:`screwkit.indices.average`, the same for ``analyze``, sweeps and maps).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.closure.on_the_way import OTHER_ASSEMBLY
from screwkit.common.tolerances import WORST_FAULT_TIE
from screwkit.indices.average import AGGREGATES, failure_weights, mean_remaining_lmti
from screwkit.indices.exports import indices_variables, set_label
from screwkit.indices.registry import index_columns
from screwkit.indices.results import Indices
from screwkit.io.graph import GraphMechanism
from screwkit.model import Mechanism, require_mechanism
from screwkit.studies.branches import branch_changes, describe
from screwkit.studies.netcdf import PlainDataset
from screwkit.studies.options import AnalysisOptions, checked_analysis
from screwkit.studies.path_mechanisms import GraphPath, SerialPath, check_path_size, path_mechanism
from screwkit.studies.paths import ARC_LENGTH_NAMES, ARC_LENGTH_WAYS, Path, checked_tolerance, path_from_poses
from screwkit.studies.refinement import (
    bisected_crossings,
    bracketed_minima,
    kink_vertex,
    linear_crossing,
    local_minima,
    parabola_vertex,
)

__all__ = ["trajectory", "TrajectoryResult", "FaultCase", "Margin", "PathEvent", "failure_weights", "singular_dips",
           "remaining_lmti",
           "AGGREGATES", "RELATIVE_TOLERANCE"]

RELATIVE_TOLERANCE = 1e-6
"""Default refinement tolerance, in units of the mechanism's length scale (so a scaled mechanism has its
tolerance scaled with it)."""

_HIDDEN_ROUNDS = 4
"""Rounds of locating stretches out of reach that lie between two reachable samples (each round's searches may
find another); each further round is taken only when the one before found one."""


@dataclass(frozen=True)
class FaultCase:
    """One set of failed actuators along the path.

    Attributes
    ----------
    faults : int
        ``j``, the number of failed actuators.
    failed : tuple of str
        The failed actuators by name.
    controllable, lost : ndarray (k, 2)
        Stretches ``[start, stop]`` of arc length (m) where the LMTI of the actuators left is at least the
        level, and where it is not (below it, or the pose unreachable); together they cover the path.
    first_loss : float or None
        Arc length (m) where control is first lost; None if never.
    minimum, at : float
        The lowest LMTI left along the path (over the samples and the refined dips; NaN if no pose is
        reachable) and its arc length.
    singular_at : tuple of float
        Arc lengths (m) where the LMTI left vanishes: a sample where it is zero, or a dip refined to zero
        (:func:`singular_dips`), located to the tolerance.
    """

    faults: int
    failed: tuple[str, ...]
    controllable: NDArray[np.float64]
    lost: NDArray[np.float64]
    first_loss: float | None
    minimum: float
    at: float
    singular_at: tuple[float, ...] = ()

    @property
    def label(self) -> str:
        return "+".join(self.failed)


@dataclass(frozen=True)
class Margin:
    """The minimum of one index along the path, its arc length (m) and sample (None: a refined minimum between
    samples)."""

    value: float
    arc_length: float
    sample: int | None


SINGULAR_REASON = ("chain {chain}'s joints are singular here: two of its assemblies meet, and past it the path keeps "
                   f"its working-mode sign, {OTHER_ASSEMBLY}")
"""What a ``"singular"`` event says (:func:`~screwkit.closure.on_the_way.singular_along`)."""


@dataclass(frozen=True)
class PathEvent:
    """Where the path cannot be followed in the working mode: ``kind`` is ``"closure"`` (a chain cannot close),
    ``"joint limit"``, ``"branch"`` (a chain's joint values jump: it changes working mode) or ``"singular"`` (a
    chain's joints are singular, :data:`SINGULAR_REASON`); ``start``/``stop``
    the stretch of arc length (m, located to the tolerance), ``samples`` its first and last sample (for a branch
    change, or a stretch out of reach between two samples, the samples either side), ``reason`` the chains and
    joints concerned."""

    kind: str
    start: float
    stop: float
    samples: tuple[int, int]
    reason: str


@dataclass(frozen=True, eq=False)
class TrajectoryResult:
    """Everything :func:`trajectory` finds along a path.

    Attributes
    ----------
    mechanism : str
    path : Path
    indices : Indices
        Every index at the samples (with detail: per actuator, per submechanism, per set left).
    level, tolerance : float
        The level of controllability and the refinement tolerance (m of arc length).
    cases : tuple of FaultCase
        Every set of failed actuators, ``j`` ascending, in :meth:`Indices.failed_sets` order.
    worst : dict of int to tuple of tuple of str
        For each ``j``, the failures worst for this path (the lowest minimum; ties all named).
    margins : dict of str to Margin
        Per index column (``iti``, ``f_o1``, ..., ``f_o_mean1`` with the mean), its minimum along the path.
    events : tuple of PathEvent
        In order of arc length.
    working_modes : dict of str to str
        Per chain, the working mode its closures keep (:func:`screwkit.closure.working_modes`).
    aggregate : str
        ``"min"`` or ``"mean"`` (:data:`AGGREGATES`).
    mean : dict of int to ndarray (n,)
        With ``aggregate="mean"``: the (weighted) mean over the sets of ``j`` failures of the LMTI left.
    weights : dict of int to ndarray (C(a, j),)
        The weight of each set of ``j`` failures in the mean (:func:`failure_weights`).
    evaluations : int
        Poses evaluated by the refinement, beyond the samples.
    """

    mechanism: str
    path: Path
    indices: Indices
    level: float
    tolerance: float
    cases: tuple[FaultCase, ...]
    worst: dict[int, tuple[tuple[str, ...], ...]]
    margins: dict[str, Margin]
    events: tuple[PathEvent, ...]
    working_modes: dict[str, str] = field(default_factory=dict)
    aggregate: str = "min"
    mean: dict[int, NDArray[np.float64]] = field(default_factory=dict)
    weights: dict[int, NDArray[np.float64]] = field(default_factory=dict)
    evaluations: int = 0

    def case(self, *failed: str) -> FaultCase:
        """The :class:`FaultCase` of the failed actuators named (``chain:joint``)."""
        wanted = tuple(sorted(failed))
        for case in self.cases:
            if tuple(sorted(case.failed)) == wanted:
                return case
        raise ValueError(f"No fault case {'+'.join(failed)}; the actuators are {', '.join(self.indices.actuators)}.")

    def summary(self) -> dict:
        """A JSON-ready summary: the path, the margins, every fault case, the worst failures, the events."""
        def number(value):
            return None if value is None or not np.isfinite(value) else float(value)

        path = self.path
        return {
            "mechanism": self.mechanism, "samples": path.samples, "length_m": path.length,
            "length_scale_m": path.length_scale, "arc_length": ARC_LENGTH_WAYS[path.along_actuators],
            "level": self.level, "tolerance_m": self.tolerance,
            "aggregate": self.aggregate,
            "duration_s": None if path.times is None else float(path.times[-1] - path.times[0]),
            "reachable_samples": int(np.count_nonzero(self.indices.reachable)), "dof": int(self.indices.dof),
            "margins": {name: {"value": number(m.value), "arc_length_m": number(m.arc_length), "sample": m.sample}
                        for name, m in self.margins.items()},
            "faults": [{"j": c.faults, "failed": list(c.failed),
                        "actuators_left": len(self.indices.actuators) - c.faults, "minimum": number(c.minimum),
                        "at_m": number(c.at), "first_loss_m": number(c.first_loss),
                        "singular_at_m": list(c.singular_at),
                        "lost_m": c.lost.tolist(), "controllable_m": c.controllable.tolist()} for c in self.cases],
            "worst": {str(j): [list(t) for t in ties] for j, ties in self.worst.items()},
            "working_modes": self.working_modes,
            "events": [{"kind": e.kind, "start_m": e.start, "stop_m": e.stop, "samples": list(e.samples),
                        "reason": e.reason} for e in self.events],
            "refinement_evaluations": self.evaluations,
        }

    def to_dataset(self):
        """The indices along the path as an ``xarray.Dataset`` over ``sample`` (coordinates ``arc_length`` in m,
        ``t`` in s when given, the task coordinates in m and deg): every index, ``lmti_left{j}`` over ``failed{j}``
        (the LMTI of the actuators left after each set of ``j`` failures), ``f_o_mean{j}`` with the mean; the
        summary (:meth:`summary`) as the JSON attribute ``summary``. :meth:`plain_dataset` without xarray."""
        return self.plain_dataset().to_dataset()

    def plain_dataset(self) -> PlainDataset:
        """What :meth:`to_dataset` holds, as plain arrays: ``--out`` writes it to netCDF without importing xarray
        (:meth:`PlainDataset.write_netcdf`), and ``xarray.open_dataset`` reads back the same dataset."""
        coords = {"arc_length": ("sample", self.path.arc_length, {"units": "m", "long_name": ARC_LENGTH_NAMES[
            self.path.along_actuators]})}
        if self.path.times is not None:
            coords["t"] = ("sample", self.path.times, {"units": "s"})
        variables, coords, attrs = indices_variables(self.indices, ("sample",), coords)
        for j in self.indices.faults:
            dimension = f"failed{j}"
            coords[dimension] = (dimension, [set_label(failed) for failed in self.indices.failed_sets(j)])
            variables[f"lmti_left{j}"] = (("sample", dimension), remaining_lmti(self.indices, j),
                                          {"long_name": f"LMTI of the actuators left after each set of {j} "
                                                        f"failure(s) (F_O{j} is their minimum, Eq. 12)"})
            if j in self.mean:
                variables[f"f_o_mean{j}"] = ("sample", self.mean[j],
                                             {"long_name": f"F_O{j} mean (screwkit's extension of Eq. 12)"})
        attrs.update(mechanism=self.mechanism, level=self.level, tolerance_m=self.tolerance,
                     length_m=self.path.length, aggregate=self.aggregate, summary=json.dumps(self.summary()))
        return PlainDataset(variables, coords, attrs)


def trajectory(mechanism: Mechanism | GraphMechanism, path: Path | ArrayLike, *, times: ArrayLike | None = None,
               level: float = 0.4, tolerance: float | None = None, aggregate: str = "min",
               probabilities: ArrayLike | None = None, analysis: AnalysisOptions | None = None,
               threads: int | None = None) -> TrajectoryResult:
    """Every index along a path, and what each actuator failure leaves controllable, refined between samples.

    Parameters
    ----------
    mechanism : Mechanism or GraphMechanism
        A mechanism whose legs have loops inside them (:class:`~screwkit.io.GraphMechanism`) has each sample closed
        by continuation from its file's configuration (:mod:`screwkit.studies.path_mechanisms`).
    path : Path or array_like (n, n_task)
        The samples (task coordinates, m and rad; :mod:`screwkit.studies.paths`), at least two.
    times : array_like (n,), optional
        The time of each sample (s), for a path given as poses.
    level : float
        The LMTI the actuators left must keep for the platform to count as controllable (default 0.4).
    tolerance : float, optional
        How closely (m of arc length) crossings of the level and minima between samples are located
        (default :data:`RELATIVE_TOLERANCE` times the mechanism's length scale).
    aggregate : {"min", "mean"}
        ``"mean"`` also reports the (weighted) mean over the sets of ``j`` failures (``f_o_mean{j}``).
    probabilities : array_like (a,), optional
        Failure probability of each actuator, weighting the mean (:func:`failure_weights`).
    analysis : AnalysisOptions, optional
        Threshold, numbers of faults, fault type, closed forms, joint limits.
    threads : int, optional
        Threads of the index kernel.
    """
    if not isinstance(mechanism, GraphMechanism):
        require_mechanism(mechanism, "trajectory")
    if isinstance(path, Path) and times is not None:  # (a Path's own times would be silently replaced, or not)
        raise ValueError("Expected `times` only with a path given as poses: a Path carries its own "
                         "(screwkit.studies.paths.path_from_poses(mechanism, poses, times)).")
    path = path if isinstance(path, Path) else path_from_poses(mechanism, path, times)
    analysis = checked_analysis(analysis, "trajectory")
    if aggregate not in AGGREGATES:
        raise ValueError(f"Expected `aggregate` in {', '.join(AGGREGATES)}, got {aggregate!r}.")
    if isinstance(level, (bool, np.bool_)) or not isinstance(level, (int, float, np.integer, np.floating)) \
            or not 0 < level <= 1:  # (NaN too)
        raise ValueError(f"Expected `level` in (0, 1] (an LMTI), got {type(level).__name__} {level!r}.")
    if tolerance is None:  # the default; at most a thousandth of a path shorter than a thousandth of the scale
        tolerance = RELATIVE_TOLERANCE * min(mechanism.length_scale, 1e3 * path.length)
    tolerance = checked_tolerance(path, tolerance)  # from a few ulps of the arc length to below the path's length

    along = path_mechanism(mechanism, analysis, dict(analysis.keywords(), detail=True, threads=threads), path)
    check_path_size(along, path.samples)  # before anything is computed
    samples, joint_values = along.samples(path.poses)
    faults = samples.faults
    failed_sets = [(j, failed) for j in faults for failed in samples.failed_sets(j)]
    evaluations = [0]

    def table(result: Indices) -> NDArray[np.float64]:
        """Per pose, the LMTI left after every set of failures, then 1 (reachable) or NaN: the series (n, K + 1),
        a view of an array holding each series in a row (so that each is contiguous)."""
        columns = [remaining_lmti(result, j) for j in faults]
        rows = np.empty((sum(c.shape[1] for c in columns) + 1, len(result.reachable)))
        at = 0
        for c in columns:
            rows[at:at + c.shape[1]] = c.T
            at += c.shape[1]
        rows[at] = np.where(np.asarray(result.reachable), 1.0, np.nan)
        return rows.T

    probed = []  # every pose evaluated between samples: (positions, their series (m, K + 1))

    def evaluate(positions: NDArray, series: NDArray) -> NDArray[np.float64]:
        evaluations[0] += positions.size
        found = table(along.indices_along(path, positions))
        probed.append((positions, found))
        return found[np.arange(positions.size), series]

    # the series at the samples, as views of the indices' own arrays (a column each; no copy of them all)
    blocks = [remaining_lmti(samples, j) for j in faults]
    columns = [block[:, c] for block in blocks for c in range(block.shape[1])]
    columns.append(np.where(np.asarray(samples.reachable), 1.0, np.nan))
    reach_series = len(columns) - 1

    def above(found: NDArray, series: NDArray) -> NDArray[np.bool_]:
        return np.where(series == reach_series, np.isfinite(found), np.nan_to_num(found, nan=-np.inf) >= level)

    s = path.arc_length
    rows, series = _local_minima_of_blocks(blocks)
    around = np.clip(rows[:, None] + np.arange(-2, 3), 0, len(s) - 1)  # two samples either side
    inside = (around[:, 0] == rows - 2) & (around[:, -1] == rows + 2)
    values = np.array([columns[k][r] for k, r in zip(series, around)]).reshape(around.shape)
    with np.errstate(invalid="ignore"):
        guesses = np.where(inside[:, None], np.stack([parabola_vertex(s[around[:, 1:4]], values[:, 1:4]),
                                                      kink_vertex(s[around[:, [0, 1, 3, 4]]],
                                                                  values[:, [0, 1, 3, 4]])], axis=1), np.nan)
    at_end = (rows == 0) | (rows == len(s) - 1)  # a dip at an end of the path: there, or near it
    guesses[at_end, 0] = s[rows[at_end]]
    before, after = np.maximum(rows - 1, 0), np.minimum(rows + 1, len(s) - 1)
    minima_at, minima = bracketed_minima(evaluate, s[before], s[after], series, tolerance, guesses)
    singular = singular_dips(evaluate, path, minima_at, minima, series, tolerance)
    points = _series_points(s, columns, rows, series, minima_at, minima)
    reachable_samples, kept = np.asarray(samples.reachable, dtype=bool), 0
    # again while the searches find a pose out of reach between two reachable samples, at most _HIDDEN_ROUNDS times
    # (what the last round finds is left out: the points used below are those its crossings were located on)
    for round_ in range(_HIDDEN_ROUNDS):
        states = [np.isfinite(v) if k == reach_series else np.nan_to_num(v, nan=-np.inf) >= level
                  for k, (_, v) in enumerate(points)]  # above(v, k) for one series at a time
        brackets = [(k, i) for k, state in enumerate(states) for i in np.flatnonzero(state[1:] != state[:-1])]
        where = np.array([k for k, _ in brackets], dtype=np.int64)
        ends = np.array([(points[k][0][i], points[k][0][i + 1], points[k][1][i], points[k][1][i + 1])
                         for k, i in brackets]).reshape(-1, 4).T
        guess = np.where(where == reach_series, np.nan, linear_crossing(*ends, level))
        low, high = bisected_crossings(evaluate, ends[0], ends[1], where, above, tolerance, guess)
        crossing = {(k, i): (lo + hi) / 2 for (k, i), lo, hi in zip(brackets, low, high)}
        hidden = _hidden_gaps(s, reachable_samples, probed[kept:])
        kept = len(probed)
        if hidden is None or round_ == _HIDDEN_ROUNDS - 1:
            break
        points = [_merged(at, v, hidden[0], hidden[1][:, k]) for k, (at, v) in enumerate(points)]

    cases = []
    for k, (j, failed) in enumerate(failed_sets):
        at, v = points[k]
        controllable, lost = _stretches(at, states[k], {i: crossing[(kk, i)] for kk, i in brackets if kk == k})
        finite = np.isfinite(v)
        lowest = int(np.argmin(np.where(finite, v, np.inf)))
        zeros = np.concatenate([s[columns[k] == 0], minima_at[(series == k) & singular]])
        cases.append(FaultCase(j, tuple(samples.actuators[i] for i in failed), controllable, lost,
                               float(lost[0, 0]) if len(lost) else None,
                               float(v[lowest]) if finite.any() else np.nan, float(at[lowest]),
                               tuple(float(z) for z in np.sort(zeros))))
    reach_at = points[reach_series][0]  # its state, not its values (NaN where unreachable: NaN is true)
    _, unreachable = _stretches(reach_at, states[reach_series], {i: crossing[(kk, i)] for kk, i in brackets
                                                                 if kk == reach_series})
    chains = along.chains
    changes = branch_changes(chains, mechanism.length_scale, s, joint_values,
                             lambda at: along.joint_values_along(path, at), tolerance)
    events = _events(along, path, samples, unreachable) + tuple(
        PathEvent(c.kind, c.start, c.stop, c.samples, describe(chains, c)) for c in changes) + tuple(
        PathEvent("singular", at, at, (i, min(i + 1, len(s) - 1)), SINGULAR_REASON.format(chain=name))
        for name, at, i in along.singular(path, joint_values))
    weights = {j: failure_weights(samples.actuator_count, j, probabilities) for j in faults}
    mean = mean_remaining_lmti(samples.remaining_lmti, samples.actuator_count, probabilities) \
        if aggregate == "mean" else {}
    return TrajectoryResult(
        mechanism=mechanism.name, path=path, indices=samples, level=float(level), tolerance=tolerance,
        cases=tuple(cases), worst=_worst(cases, faults), margins=_margins(samples, s, cases, mean),
        events=tuple(sorted(events, key=lambda e: (e.start, e.kind))), working_modes=along.working_modes(),
        aggregate=aggregate, mean=mean,
        weights=weights if aggregate == "mean" else {}, evaluations=evaluations[0])


def remaining_lmti(result: Indices, faults: int) -> NDArray[np.float64]:
    """The LMTI left after each set of ``faults`` failures, (..., C(a, j)): NaN throughout a batch without a
    reachable pose (which carries none)."""
    found = (result.remaining_lmti or {}).get(faults)
    if found is not None:
        return np.asarray(found)
    return np.full(tuple(result.batch_shape) + (len(result.failed_sets(faults)),), np.nan)


def singular_dips(evaluate, path: Path, minima_at: NDArray, minima: NDArray, series: NDArray,
                  tolerance: float) -> NDArray[np.bool_]:
    """Which refined minima are zeros of their series: the value found is at most its rise one ``tolerance``
    either side (a V-shaped dip whose two sides, extended, meet within the tolerance at zero), whereas a smooth
    minimum above zero rises only by the square of the tolerance there. One batched evaluation.

    A side out of reach (the edge of an unreachable or joint-limit stretch) tells nothing of the dip: the rise is
    the other side's alone, and a minimum with neither side reachable is no zero."""
    if minima_at.size == 0:
        return np.zeros(0, dtype=bool)
    sides = np.clip(np.concatenate([minima_at - tolerance, minima_at + tolerance]), 0.0, path.length)
    found = evaluate(sides, np.concatenate([series, series]))
    with np.errstate(invalid="ignore"):
        rise = np.fmax(found[:minima.size], found[minima.size:]) - minima  # NaN only where both sides are
        return np.isfinite(minima) & (minima <= rise)


def _hidden_gaps(s: NDArray, reachable: NDArray, probed: list) -> tuple[NDArray, NDArray] | None:
    """The poses the searches evaluated between two reachable samples that have one out of reach among them
    (with every other pose evaluated between the same two samples, so that each edge lies between two of them):
    ``(positions, series (m, K + 1))``, or None. Such a stretch out of reach is shorter than the samples' spacing;
    once one of its poses is known, its edges are located as any other."""
    if not probed:
        return None
    at = np.concatenate([positions for positions, _ in probed])
    values = np.concatenate([found for _, found in probed])
    after = np.searchsorted(s, at, side="right")  # the sample after each pose
    between = (after > 0) & (after < len(s)) & (at > s[np.maximum(after - 1, 0)])
    between &= reachable[np.maximum(after - 1, 0)] & reachable[np.minimum(after, len(s) - 1)]
    gaps = np.unique(after[between & np.isnan(values[:, -1])])
    chosen = between & np.isin(after, gaps)
    return (at[chosen], values[chosen]) if gaps.size else None


def _merged(at: NDArray, v: NDArray, more_at: NDArray, more: NDArray) -> tuple[NDArray, NDArray]:
    """A series' points (``at`` in order, values ``v``) with more points inserted in order, each after the points
    already at its arc length."""
    order = np.argsort(more_at, kind="stable")
    where = np.searchsorted(at, more_at[order], side="right")
    return np.insert(at, where, more_at[order]), np.insert(v, where, more[order])


def _local_minima_of_blocks(blocks: list[NDArray]) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """:func:`~screwkit.studies.refinement.local_minima` of the blocks (n, C_j) side by side, in its order (by row,
    then series), without putting them side by side."""
    found = [local_minima(block) for block in blocks]
    offsets = np.cumsum([0] + [block.shape[1] for block in blocks])
    rows = np.concatenate([np.zeros(0, dtype=np.int64)] + [r for r, _ in found])
    series = np.concatenate([np.zeros(0, dtype=np.int64)] + [c + o for (_, c), o in zip(found, offsets)])
    order = np.lexsort((series, rows))
    return rows[order], series[order]


def _series_points(s, columns, rows, series, minima_at, minima):
    """Per series (``columns``, its values at the samples): the sample positions and values, with the refined
    minima inserted in order."""
    points = []
    for k in range(len(columns)):
        mine = series == k
        if not mine.any():
            points.append((s, columns[k]))
            continue
        points.append(_merged(s, columns[k], minima_at[mine], minima[mine]))
    return points


def _stretches(at: NDArray, state: NDArray, crossings: dict[int, float]) -> tuple[NDArray, NDArray]:
    """The stretches ``(true, false)`` of a predicate known at ``at``, changing at ``crossings[i]`` between
    points ``i`` and ``i + 1``: arrays (k, 2) of [start, stop]."""
    edges = [float(at[0])] + [crossings[i] for i in sorted(crossings)] + [float(at[-1])]
    first = bool(state[0])
    runs = np.array([edges[:-1], edges[1:]]).T.reshape(-1, 2)
    kinds = np.array([(first if r % 2 == 0 else not first) for r in range(len(runs))], dtype=bool)
    return runs[kinds], runs[~kinds]


def _worst(cases: list[FaultCase], faults) -> dict[int, tuple[tuple[str, ...], ...]]:
    """For each ``j``: every failure that meets a singularity on the path (tied at zero), else the lowest minimum
    and its ties within :data:`WORST_FAULT_TIE`."""
    worst = {}
    for j in faults:
        mine = [c for c in cases if c.faults == j and np.isfinite(c.minimum)]
        singular = [c.failed for c in mine if c.singular_at]
        if singular or not mine:
            worst[j] = tuple(singular)
            continue
        lowest = min(c.minimum for c in mine)
        worst[j] = tuple(c.failed for c in mine if c.minimum <= lowest + WORST_FAULT_TIE)
    return worst


def _margins(samples: Indices, s: NDArray, cases: list[FaultCase], mean: dict) -> dict[str, Margin]:
    """The minimum of every index column along the path, at its first sample within :data:`WORST_FAULT_TIE` of it
    (values equal but for rounding, such as an ITI of 1 all along, would otherwise put it where rounding falls,
    which moves with the file's unit and world frame); F_Oj's over the refined minima too."""
    columns = dict(index_columns(samples))
    columns.update({f"f_o_mean{j}": values for j, values in mean.items()})
    margins = {}
    for name, values in columns.items():
        values = np.asarray(values, dtype=float)
        if not np.any(np.isfinite(values)):
            continue  # not applicable (a CTI without constraint wrenches) or nothing reachable
        lowest = float(np.nanmin(values))
        index = int(np.flatnonzero(values <= lowest + WORST_FAULT_TIE)[0])
        margins[name] = Margin(lowest, float(s[index]), index)
    for j in samples.faults:
        refined = [c for c in cases if c.faults == j and np.isfinite(c.minimum)]
        if refined and f"f_o{j}" in margins:
            lowest = min(refined, key=lambda c: c.minimum)
            if lowest.minimum < margins[f"f_o{j}"].value:
                margins[f"f_o{j}"] = Margin(lowest.minimum, lowest.at, None)
    return margins


def _events(along: SerialPath | GraphPath, path: Path, samples: Indices, unreachable: NDArray
            ) -> tuple[PathEvent, ...]:
    """A :class:`PathEvent` per stretch where the path is unreachable, with why at its first sample."""
    events = []
    s = path.arc_length
    status = np.asarray(samples.chain_status)
    for start, stop in unreachable:
        inside = np.flatnonzero((s >= start) & (s <= stop) & ~np.asarray(samples.reachable))
        if inside.size:
            first, last = int(inside[0]), int(inside[-1])
            kind, reason = along.unreachable_along(path, float(s[first]), status[first])
        else:  # between two samples (found by the searches): the samples either side, why at its middle
            last, middle = int(np.searchsorted(s, (start + stop) / 2)), np.array([(start + stop) / 2])
            first = last - 1
            status_there = np.asarray(along.indices_along(path, middle).chain_status)[0]
            kind, reason = along.unreachable_along(path, float(middle[0]), status_there)
        events.append(PathEvent(kind, float(start), float(stop), (first, last), reason))
    return tuple(events)
