"""Design search over a parametric family: one objective (differential evolution) or several (NSGA-II).

:class:`Study` names a family, the parameters it varies (the others fixed), the region whose metrics are scored
(:mod:`screwkit.studies.design.objectives`), objectives, constraints, a budget and a seed. :func:`run_study`:

* one objective: ``scipy.optimize.differential_evolution`` (the starting design seeds the
  population, integer parameters through ``integrality``, deferred updating so that a generation is
  one batch of independent evaluations);
* several: pymoo's NSGA-II, the Pareto front taken over every evaluation of the run.

Every generation is evaluated as one batch, in local worker processes (one per core) or as tasks of a Dask cluster
(:func:`screwkit.studies.tasks.run_tasks`); a candidate's metrics depend on its parameters alone, so the run is the
same wherever it is evaluated. With a ``state`` file, each
batch's metrics are appended to it as they come; a run started again with the same study and
state replays the evaluations it finds there instead of recomputing them (the optimisers are
seeded, so they ask for the same candidates), which resumes an interrupted run where it stopped.
A batch is appended whole or not at all: a write that fails (disk full, quota) is cut back to the
records before it; a last record cut off by a run killed while writing it is dropped when the
state is read again (and computed again), and an empty state file starts a new search. The evaluations, the state
file and the worker processes are :mod:`screwkit.studies.design.evaluations`.

A design that cannot be built (an arm that cannot reach its platform joint at the home pose) is infeasible: never
the best nor on the front, whatever the objectives (its size is real, its region metrics 0).
"""

from __future__ import annotations

import hashlib
import json
import math
import os
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from screwkit.studies.design.evaluations import EvaluationError, Evaluations, StateError, evaluate_candidate
from screwkit.studies.design.families import Family
from screwkit.studies.design.objectives import MAX_CONFIGURATIONS_PER_DESIGN, MAXIMISED, METRICS, Region
from screwkit.studies.tasks import Execution

__all__ = ["Constraint", "Study", "StudyResult", "run_study", "evaluate_candidate", "pareto_front", "StateError",
           "EvaluationError", "MAX_SEED"]

INFEASIBLE = 1e6
"""Differential evolution's score of an infeasible candidate, plus its constraint violation (every
feasible score is minus a metric, far smaller); a design that cannot be built adds it once more (it comes last)."""

MAX_SEED = 2**32 - 1
"""Largest seed (the optimisers' random generators take 32-bit seeds)."""




@dataclass(frozen=True)
class Constraint:
    """``metric >= bound`` (``at_least``) or ``metric <= bound``."""

    metric: str
    bound: float
    at_least: bool

    @classmethod
    def parse(cls, text: str) -> Constraint:
        for operator in (">=", "<="):
            if operator in text:
                name, _, value = (part.strip() for part in text.partition(operator))
                if name not in METRICS:
                    raise ValueError(f"Unknown metric {name!r} in constraint {text!r}; metrics: {', '.join(METRICS)}.")
                try:
                    bound = float(value)
                except ValueError:
                    raise ValueError(f"Expected a number after {operator} in constraint {text!r}.") from None
                return cls(name, bound, operator == ">=")
        raise ValueError(f"Expected a constraint METRIC>=VALUE or METRIC<=VALUE, got {text!r}.")

    def violation(self, metrics: dict[str, float]) -> float:
        value = metrics[self.metric]
        if not math.isfinite(value):
            return math.inf
        return max(0.0, self.bound - value) if self.at_least else max(0.0, value - self.bound)

    def __str__(self) -> str:
        return f"{self.metric}{'>=' if self.at_least else '<='}{self.bound:g}"


@dataclass(frozen=True)
class Study:
    """A design search: what varies, what is scored, how much it may cost.

    Attributes
    ----------
    family : Family
    region : Region
    objectives : tuple of str
        Metrics of :data:`~screwkit.studies.design.objectives.METRICS`, each optimised in its sense
        (:data:`~screwkit.studies.design.objectives.MAXIMISED`); two or more give a Pareto front.
    free : tuple of str, optional
        Parameters varied (default: the family's ``free``); the others keep ``fixed`` or their default.
    fixed, initial : dict
        Values of parameters that do not vary; starting values of those that do.
    bounds : dict of str to (float, float)
        Narrower bounds of varied parameters.
    constraints : tuple of Constraint
    budget : int
        Designs evaluated besides the start. Differential evolution runs whole generations of
        ``popsize`` x (number of varied parameters) designs, so the budget is rounded down to a
        whole number of them (one at least); NSGA-II stops at the first generation that reaches
        it. 0 evaluates the start only.
    seed : int
        Seed of the optimiser, in 0..:data:`MAX_SEED`: the same study and seed ask for the same designs in the
        same order.
    popsize : int
        Population size per varied parameter.
    """

    family: Family
    region: Region
    objectives: tuple[str, ...] = ("area",)
    free: tuple[str, ...] | None = None
    fixed: dict = field(default_factory=dict)
    initial: dict = field(default_factory=dict)
    bounds: dict = field(default_factory=dict)
    constraints: tuple[Constraint, ...] = ()
    budget: int = 384
    seed: int = 0
    popsize: int = 8

    def __post_init__(self):
        family = self.family
        free = family.free if self.free is None else tuple(self.free)
        object.__setattr__(self, "free", free)
        for name in free:
            family.parameter(name)
        for name in list(self.fixed) + list(self.bounds) + list(self.initial):
            family.parameter(name)
        if set(self.initial) - set(free):
            raise ValueError(f"Starting values given for parameters that do not vary: "
                             f"{', '.join(sorted(set(self.initial) - set(free)))}.")
        if set(free) & set(self.fixed):
            raise ValueError(f"Parameters both varied and fixed: {', '.join(sorted(set(free) & set(self.fixed)))}.")
        family.values({**self.fixed, **self.initial})
        for name, (lower, upper) in self.bounds.items():
            parameter = family.parameter(name)
            parameter.check(lower, "lower bound")
            parameter.check(upper, "upper bound")
            if not lower < upper:
                raise ValueError(f"Expected a lower bound below the upper bound of {name}, got {lower:g}, {upper:g}.")
        if not self.objectives:
            raise ValueError("Expected at least one objective.")
        for name in self.objectives:
            if name not in METRICS:
                raise ValueError(f"Unknown objective {name!r}; metrics: {', '.join(METRICS)}.")
            if name == "volume" and not self.region.layers:
                raise ValueError("The objective volume needs a region with layers.")
        if not free:
            raise ValueError(f"No parameter of family {family.name!r} varies.")
        if self.budget < 0:
            raise ValueError(f"Expected a budget >= 0 evaluations, got {self.budget}.")
        seed = self.seed
        if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or not 0 <= seed <= MAX_SEED:
            raise ValueError(f"Expected a seed in 0..{MAX_SEED} (an integer), got {seed!r}.")
        configurations = self.region.configurations
        if configurations > MAX_CONFIGURATIONS_PER_DESIGN:
            raise ValueError(f"The region has {configurations:,} configurations per design (grid points x "
                             f"orientations x layers), more than {MAX_CONFIGURATIONS_PER_DESIGN:,}: use larger steps.")

    @property
    def generation(self) -> int:
        """Designs per generation of the optimiser: ``popsize`` x the varied parameters (NSGA-II: at least 4)."""
        return self.popsize * len(self.free) if len(self.objectives) == 1 else max(4, self.popsize * len(self.free))

    @property
    def planned_evaluations(self) -> int:
        """The designs the search asks for at most: the start alone for a budget of 0, else the budget in whole
        generations, at least one (differential evolution rounds down, NSGA-II up; fewer if either converges)."""
        whole = self.budget // self.generation if len(self.objectives) == 1 else -(-self.budget // self.generation)
        return 1 if self.budget == 0 else self.generation * max(1, whole)

    @property
    def limits(self) -> NDArray[np.float64]:
        """(d, 2) bounds of the free parameters."""
        return np.array([self.bounds.get(name, (self.family.parameter(name).lower, self.family.parameter(name).upper))
                         for name in self.free], dtype=float)

    @property
    def start(self) -> NDArray[np.float64]:
        """The starting design's free parameters (``initial`` or the defaults, clipped to the bounds)."""
        values = self.family.values({**self.fixed, **self.initial})
        limits = self.limits
        return np.clip([values[name] for name in self.free], limits[:, 0], limits[:, 1])

    def values(self, vector) -> dict[str, float]:
        """Every parameter's value for a vector of the free parameters (integers rounded)."""
        values = self.family.values(self.fixed)
        for name, value in zip(self.free, vector):
            parameter = self.family.parameter(name)
            values[name] = float(round(value)) if parameter.integer else float(value)
        return values

    def fingerprint(self) -> str:
        """What the evaluations of this study depend on (family, fixed values, region, threshold)."""
        region = self.region
        described = [self.family.name, self.family.legs, sorted(self.family.values(self.fixed).items()),
                     list(self.free), region.index, region.level, region.closed_forms, region.threshold,
                     [(n, v.tolist()) for n, v in region.grid], [(n, v.tolist()) for n, v in region.over],
                     None if region.mask is None else region.mask.tolist(),
                     None if not region.layers else (region.layers[0], region.layers[1].tolist())]
        described += [list(region.probabilities)] if region.probabilities is not None else []  # (earlier keys hold)
        if any(values.size < 2 for _, values in region.grid) or (region.layers and region.layers[1].size < 2):
            described += [list(region.steps), region.layer_step]  # a lone value's cell, not seen in its values
        return hashlib.sha256(json.dumps(described).encode()).hexdigest()[:16]


@dataclass
class StudyResult:
    """The outcome of :func:`run_study`.

    Attributes
    ----------
    best : list of dict
        One objective: the best design; several: the Pareto front (feasible, non-dominated, first
        objective best first). Each: ``values`` (every parameter), ``metrics``.
    start : dict
        The starting design (``values``, ``metrics``).
    evaluations : list of dict
        Every design evaluated, once, in the order first asked (``values``, ``metrics``, ``feasible``).
    computed, replayed : int
        Designs computed in this run, and read back from the state file.
    """

    study: Study
    best: list[dict]
    start: dict
    evaluations: list[dict]
    computed: int
    replayed: int


def _score(study: Study, metrics: dict) -> tuple[NDArray, float]:
    """(objectives as minimised values, total constraint violation: :data:`INFEASIBLE` more for a design that cannot
    be built)."""
    objectives = np.array([-metrics[name] if MAXIMISED[name] else metrics[name] for name in study.objectives])
    violation = sum(c.violation(metrics) for c in study.constraints) + (INFEASIBLE if "error" in metrics else 0.0)
    return objectives, float(violation)


def _inside(study: Study) -> NDArray[np.float64]:
    """The start as differential evolution is given it: within the bounds as scipy rescales them to [0, 1] (a start
    on a narrowed bound, 0.6 of 0.6:0.8, lands 1e-16 outside; it moves by that much, a few ulps)."""
    limits, start = study.limits, study.start.copy()
    middle, scale = 0.5 * (limits[:, 0] + limits[:, 1]), 1 / np.fabs(limits[:, 0] - limits[:, 1])  # (as scipy's)
    for i in range(start.size):
        while (start[i] - middle[i]) * scale[i] + 0.5 < 0:
            start[i] = np.nextafter(start[i], np.inf)
        while (start[i] - middle[i]) * scale[i] + 0.5 > 1:
            start[i] = np.nextafter(start[i], -np.inf)
    return start


def pareto_front(scores: NDArray) -> NDArray[np.int64]:
    """Indices of the rows of ``scores`` (N, k; minimised) that no other row dominates, first
    occurrence of equal rows only, ordered by the first column."""
    keep = []
    for i, row in enumerate(scores):
        dominated = np.any(np.all(scores <= row, axis=1) & np.any(scores < row, axis=1))
        duplicate = any(np.array_equal(scores[j], row) for j in keep)
        if not dominated and not duplicate:
            keep.append(i)
    keep = np.array(keep, dtype=np.int64)
    return keep[np.argsort(scores[keep, 0], kind="stable")] if keep.size else keep


def _single(study: Study, evaluate: Callable) -> None:
    from scipy.optimize import differential_evolution

    limits = study.limits
    integrality = np.array([study.family.parameter(name).integer for name in study.free])
    generations = max(0, study.budget // study.generation - 1)  # after the first population

    raised: list[Exception] = []

    def fitness(vectors: NDArray) -> NDArray:  # (d, S) -> (S,)
        scores = []
        try:
            evaluated = evaluate(vectors.T)
        except Exception as error:  # scipy raises a RuntimeError of its own instead: the cause is kept for the caller
            raised.append(error)
            raise
        for metrics in evaluated:
            objectives, violation = _score(study, metrics)
            scores.append(INFEASIBLE + violation if violation > 0 else objectives[0])
        return np.array(scores)

    try:
        differential_evolution(fitness, bounds=limits, x0=_inside(study), maxiter=generations, popsize=study.popsize,
                               seed=study.seed, polish=False, tol=1e-6, integrality=integrality if integrality.any()
                               else None, vectorized=True, updating="deferred")
    except RuntimeError:
        if raised:
            raise raised[0] from None
        raise


def _multiple(study: Study, evaluate: Callable) -> None:
    from pymoo.algorithms.moo.nsga2 import NSGA2
    from pymoo.core.problem import Problem
    from pymoo.optimize import minimize

    limits = study.limits
    size = study.generation

    class Search(Problem):
        def __init__(self):
            super().__init__(n_var=len(study.free), n_obj=len(study.objectives),
                             n_ieq_constr=len(study.constraints) + 1, xl=limits[:, 0], xu=limits[:, 1])

        def _evaluate(self, x, out, *args, **kwargs):
            metrics = evaluate(x)
            out["F"] = np.array([_score(study, m)[0] for m in metrics])
            # pymoo: feasible where every G <= 0; the last: the design can be built
            out["G"] = np.array([[c.violation(m) if c.violation(m) > 0 else -1.0 for c in study.constraints]
                                 + [1.0 if "error" in m else -1.0] for m in metrics])

    rng = np.random.default_rng(study.seed)
    sampling = limits[:, 0] + rng.random((size, len(study.free))) * (limits[:, 1] - limits[:, 0])
    sampling[0] = study.start
    minimize(Search(), NSGA2(pop_size=size, sampling=sampling, eliminate_duplicates=True),
             ("n_eval", max(study.budget, size)), seed=study.seed, verbose=False)


def run_study(study: Study, *, execution: Execution | None = None, state: str | os.PathLike | None = None,
              notify: Callable[[str], None] | None = None) -> StudyResult:
    """Search ``study``; see the module's docstring.

    Parameters
    ----------
    execution : Execution, optional
        The Dask scheduler evaluating the candidates (default: local threads, or local processes),
        a progress bar on stderr (default: when stderr is a terminal), the seconds to wait for the scheduler.
    state : path, optional
        Evaluation log: created, or read back to resume (it must belong to the same study).
    notify : callable, optional
        Called with a line about the state file: an empty one started anew, a cut-off last record dropped.

    Raises
    ------
    StateError, ClusterError, EvaluationError, ValueError
        ClusterError and EvaluationError (a local evaluation process died) say what the state file keeps.
    """
    evaluations = Evaluations(study, state, Execution() if execution is None else execution, notify)
    try:
        start_metrics = evaluations(study.start[None])[0]
        if study.budget > 0:
            (_single if len(study.objectives) == 1 else _multiple)(study, evaluations)
    finally:
        evaluations.close()
    records = []
    for vector, metrics in evaluations.order:
        _, violation = _score(study, metrics)
        records.append({"values": study.values(vector), "metrics": metrics, "feasible": violation == 0})
    feasible = [r for r in records if r["feasible"]]
    if feasible:
        scores = np.array([_score(study, r["metrics"])[0] for r in feasible])
        if len(study.objectives) == 1:
            best = [feasible[int(np.argmin(scores[:, 0]))]]  # first of equal scores: the earliest asked
        else:
            best = [feasible[i] for i in pareto_front(scores)]
    else:
        best = []
    return StudyResult(study, best, {"values": study.values(study.start), "metrics": start_metrics}, records,
                       evaluations.computed, evaluations.replayed)
