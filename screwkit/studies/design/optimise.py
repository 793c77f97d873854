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
state is read again (and computed again), and an empty state file starts a new search.

The local worker processes end with the process that started them, however it ends (SIGKILL, the out-of-memory
killer): each asks the kernel for a signal when its parent dies, or (where that cannot be asked) watches its parent.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import signal
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import NDArray

from screwkit.studies.design.families import Family
from screwkit.studies.design.objectives import MAXIMISED, METRICS, Region, region_metrics
from screwkit.studies.files import atomic_text
from screwkit.studies.tasks import Execution, run_tasks

__all__ = ["Constraint", "Study", "StudyResult", "run_study", "evaluate_candidate", "pareto_front", "StateError"]

INFEASIBLE = 1e6
"""Differential evolution's score of an infeasible candidate, plus its constraint violation (every
feasible score is minus a metric, far smaller)."""


MAX_CONFIGURATIONS_PER_DESIGN = 10**8
"""Largest region a design is mapped on (about an hour of one core per design on the spatial path)."""


class StateError(ValueError):
    """A state file that belongs to another study, or cannot be read."""


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
        Seed of the optimiser: the same study and seed ask for the same designs in the same order.
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
        return hashlib.sha256(json.dumps(described).encode()).hexdigest()[:16]


def evaluate_candidate(family: Family, values: dict, region: Region) -> dict[str, float]:
    """Every metric of one candidate (a task: depends on its arguments alone).

    A candidate whose file cannot be written (an arm too short to reach the home pose) or whose
    home pose does not assemble scores 0 on every region metric."""
    try:
        mechanism = family.mechanism(values)
    except ValueError as error:
        return {**{name: 0.0 for name in METRICS}, **family.size(values), "error": str(error)}
    return region_metrics(mechanism, region, family.size(values))


def _end_with_parent(parent: int) -> None:
    """Initializer of the local evaluation processes: end when ``parent`` ends, however it ends.

    Linux sends the process SIGKILL when its parent dies (``prctl(PR_SET_PDEATHSIG)``); elsewhere a
    thread checks every half second that the parent is still there. Either way no evaluation process
    (nor the resource tracker they keep alive) outlives a search that was killed."""
    asked = False
    if sys.platform.startswith("linux"):
        import ctypes

        try:
            libc = ctypes.CDLL(None, use_errno=True)
            asked = libc.prctl(1, int(signal.SIGKILL), 0, 0, 0) == 0  # 1: PR_SET_PDEATHSIG
        except (OSError, AttributeError):
            pass
    if not asked:
        def watch() -> None:
            while os.getppid() == parent:
                time.sleep(0.5)
            os._exit(1)

        threading.Thread(target=watch, daemon=True).start()
    if os.getppid() != parent:  # the parent died before the request was made
        os._exit(1)


class _Evaluations:
    """The study's evaluations by free-parameter vector (exact bits), appended to the state file."""

    def __init__(self, study: Study, state: str | os.PathLike | None, execution: Execution,
                 notify: Callable[[str], None] | None = None):
        self.study, self.state = study, state
        self.execution = replace(execution, progress=False)  # the search's own bar counts the designs
        self.notify = notify or (lambda message: None)
        self.known: dict[str, dict] = {}
        self.order: list[tuple[NDArray, dict]] = []  # every design asked, once, in the order asked
        self.seen: set[str] = set()
        self.replayed = 0
        self.computed = 0
        self.stored = 0  # records in the state file
        if state is not None and os.path.exists(state) and os.path.getsize(state) > 0:
            self._read(state)
        elif state is not None:
            if os.path.exists(state):
                self.notify(f"the design-search state {state} is empty (0 bytes): a new search starts in it")
            header = json.dumps({"screwkit_design_state": 1, "study": study.fingerprint(),
                                 "family": study.family.name, "free": list(study.free)})
            try:
                atomic_text(state, header + "\n")
            except OSError as error:
                raise StateError(f"Cannot write the design-search state {state}: "
                                 f"{error.strerror or error}.") from None
        self.bar, self.pool = None, None
        if sys.stderr.isatty() if execution.progress is None else execution.progress:
            from tqdm import tqdm

            self.bar = tqdm(total=study.budget, desc="designs", unit="design", leave=False)

    def _read(self, state) -> None:
        try:
            with open(state, "rb") as file:
                content = file.read()
            complete, _, cut = content.rpartition(b"\n")  # the bytes after the last newline: a cut-off record
            lines = complete.decode("utf-8").split("\n")
            header = json.loads(lines[0])
            records = [self._record(line, number) for number, line in enumerate(lines[1:], start=2)]
        except (OSError, ValueError) as error:
            raise StateError(f"Cannot read the design-search state {state}: {error}") from None
        if not isinstance(header, dict) or "screwkit_design_state" not in header:
            raise StateError(f"{state} is not a design-search state (its first line is not the header of one); "
                             "give a new --state file.")
        if header.get("study") != self.study.fingerprint():
            raise StateError(f"The state {state} belongs to another study (family {header.get('family')!r}, "
                             f"free {header.get('free')}); give a new --state file or the same study options.")
        if cut:
            try:
                os.truncate(state, len(content) - len(cut))  # the next batch starts on a line of its own
            except OSError as error:
                raise StateError(f"Cannot drop the cut-off last record of the design-search state {state}: "
                                 f"{error.strerror or error}.") from None
            self.notify(f"dropped the cut-off last record of {state} (a run stopped while writing it); "
                        "it is computed again")
        for record in records:
            self.known[record["key"]] = record["metrics"]
        self.stored = len(records)

    @staticmethod
    def _record(line: str, number: int) -> dict:
        """One record; from a line where an earlier version of screwkit appended a record to a cut-off one,
        the record it ends with."""
        try:
            return json.loads(line)
        except ValueError:
            start = line.rfind('{"key"')
            if start <= 0:
                raise ValueError(f"line {number} is not a record") from None
            return json.loads(line[start:])

    def _append(self, records: list[tuple[str, dict]]) -> None:
        """Append a batch of records whole, or (disk full, quota) not at all."""
        data = "".join(json.dumps({"key": key, "metrics": metrics}) + "\n" for key, metrics in records).encode()
        try:
            descriptor = os.open(self.state, os.O_WRONLY | os.O_APPEND)
        except OSError as error:
            raise StateError(f"Cannot append to the design-search state {self.state}: "
                             f"{error.strerror or error}.") from None
        try:
            size = os.fstat(descriptor).st_size
            try:
                written = 0
                while written < len(data):
                    written += os.write(descriptor, data[written:])
                os.fsync(descriptor)
            except OSError as error:
                os.ftruncate(descriptor, size)
                raise StateError(f"Cannot append to the design-search state {self.state}: "
                                 f"{error.strerror or error}; it keeps the {self.stored} evaluations stored before, "
                                 "and a run with it resumes from them.") from None
        finally:
            os.close(descriptor)
        self.stored += len(records)

    def __call__(self, vectors: NDArray) -> list[dict]:
        keys = [np.asarray(v, dtype=np.float64).tobytes().hex() for v in vectors]
        first = {}
        for i, key in enumerate(keys):
            first.setdefault(key, i)
        new = [key for key in first if key not in self.seen]
        missing = [key for key in new if key not in self.known]
        self.replayed += len(new) - len(missing)
        self.computed += len(missing)
        if missing:
            arguments = [(self.study.family, self.study.values(vectors[first[key]]), self.study.region)
                         for key in missing]
            results = self._run(arguments)
            self.known.update(zip(missing, results))
            if self.state is not None:
                self._append(list(zip(missing, results)))
        for key in new:
            self.seen.add(key)
            self.order.append((np.array(vectors[first[key]], dtype=float), self.known[key]))
        if self.bar is not None:
            self.bar.update(len(new))
        return [self.known[key] for key in keys]

    def _run(self, arguments: list[tuple]) -> list[dict]:
        """Evaluate on the cluster, or locally in worker processes: a candidate's evaluation is mostly
        Python (writing, parsing and assembling its file), which threads would run one at a time.
        A family whose functions a new process cannot import (written in a notebook or a script
        run as ``__main__``) is evaluated on local threads."""
        family = self.study.family
        importable = all(f.__module__ != "__main__" and "<locals>" not in f.__qualname__
                         for f in (family.writer, family.measures))  # what a spawned process can import
        if self.execution.scheduler is not None or len(arguments) < 2 or (os.cpu_count() or 1) < 2 or not importable:
            return run_tasks(evaluate_candidate, arguments, self.execution)
        if self.pool is None:
            import multiprocessing
            from concurrent.futures import ProcessPoolExecutor

            # spawn: a forked copy of a process that already runs threads (numba, Dask) can deadlock
            self.pool = ProcessPoolExecutor(os.cpu_count(), mp_context=multiprocessing.get_context("spawn"),
                                            initializer=_end_with_parent, initargs=(os.getpid(),))
        return list(self.pool.map(evaluate_candidate, *zip(*arguments)))

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
        if self.pool is not None:
            self.pool.shutdown(cancel_futures=True)


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
    """(objectives as minimised values, total constraint violation)."""
    objectives = np.array([-metrics[name] if MAXIMISED[name] else metrics[name] for name in study.objectives])
    violation = sum(c.violation(metrics) for c in study.constraints)
    return objectives, float(violation)


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
        differential_evolution(fitness, bounds=limits, x0=study.start, maxiter=generations, popsize=study.popsize,
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
            super().__init__(n_var=len(study.free), n_obj=len(study.objectives), n_ieq_constr=len(study.constraints),
                             xl=limits[:, 0], xu=limits[:, 1])

        def _evaluate(self, x, out, *args, **kwargs):
            metrics = evaluate(x)
            out["F"] = np.array([_score(study, m)[0] for m in metrics])
            if study.constraints:  # pymoo: feasible where every G <= 0
                out["G"] = np.array([[c.violation(m) if c.violation(m) > 0 else -1.0 for c in study.constraints]
                                     for m in metrics])

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
    StateError, ClusterError, ValueError
    """
    evaluations = _Evaluations(study, state, Execution() if execution is None else execution, notify)
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
