"""The evaluations of a design search: each design's metrics, computed once, kept in a state file.

:class:`Evaluations` evaluates the designs an optimiser asks for, by batch (a generation), in local worker processes
(one per core) or as tasks of a Dask cluster (:func:`screwkit.studies.tasks.run_tasks`). A design is its vector of
free parameters, the integer ones rounded: designs that round to the same one are evaluated once. With a ``state``
file, each batch's metrics are appended to it as they come, and a run with the same study and state replays the
evaluations it finds there (the records of earlier releases, keyed by unrounded integer parameters, included).

A design whose file cannot be written (an arm too short to reach the home pose) or whose home pose does not
assemble cannot be built: :func:`evaluate_candidate` gives it 0 on every region metric, its size, and its ``error``
(the search holds it infeasible). A lost evaluation (a worker process killed, the Dask scheduler lost) ends the
search with one line that says what the state file keeps.

The local worker processes end with the process that started them, however it ends (SIGKILL, the out-of-memory
killer): each asks the kernel for a signal when its parent dies, or (where that cannot be asked) watches its parent.
Each keeps the memory it frees for the next design (:mod:`screwkit.common.memory`).
"""

from __future__ import annotations

import json
import os
import signal
import sys
import threading
import time
from collections.abc import Callable
from concurrent.futures.process import BrokenProcessPool
from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from screwkit.common.memory import keep_freed_memory
from screwkit.studies.design.families import Family
from screwkit.studies.design.objectives import METRICS, Region, region_metrics
from screwkit.studies.files import atomic_text
from screwkit.studies.tasks import ClusterError, Execution, run_tasks

__all__ = ["Evaluations", "evaluate_candidate", "StateError", "EvaluationError"]


class StateError(ValueError):
    """A state file that belongs to another study, or cannot be read."""


class EvaluationError(RuntimeError):
    """A local evaluation process died (killed by a signal, the out-of-memory killer) during a search."""


def evaluate_candidate(family: Family, values: dict, region: Region) -> dict[str, float]:
    """Every metric of one candidate (a task: depends on its arguments alone).

    A candidate whose file cannot be written (an arm too short to reach the home pose) or whose
    home pose does not assemble scores 0 on every region metric, keeps its size and says why
    (``error``): a design that cannot be built, infeasible in a search."""
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


def _start_worker(parent: int) -> None:
    """Initializer of the local evaluation processes: end with ``parent``; keep freed memory for the next design
    (:func:`~screwkit.common.memory.keep_freed_memory`: no page faults on each design's fresh arrays)."""
    _end_with_parent(parent)
    keep_freed_memory()


class Evaluations:
    """A study's evaluations by design (the free-parameter vector, integers rounded, exact bits), appended to the
    state file; called with a batch of vectors (N, d), it returns their metrics."""

    def __init__(self, study, state: str | os.PathLike | None, execution: Execution,
                 notify: Callable[[str], None] | None = None):
        self.study, self.state = study, state
        self.integer = np.array([study.family.parameter(name).integer for name in study.free], dtype=bool)
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

    def designs(self, vectors) -> NDArray[np.float64]:
        """The designs of free-parameter vectors (N, d): the integer parameters rounded (as the study's values)."""
        designs = np.array(vectors, dtype=np.float64, ndmin=2)
        designs[:, self.integer] = np.round(designs[:, self.integer]) + 0.0  # (+ 0.0: no -0.0, a key of its own)
        return designs

    def _key(self, key: str) -> str:
        """A state file's key as the design's key (earlier releases keyed the vector asked, integers unrounded)."""
        try:
            vector = np.frombuffer(bytes.fromhex(key), dtype=np.float64)
        except ValueError:
            return key
        return self.designs(vector)[0].tobytes().hex() if vector.size == self.integer.size else key

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
            self.known.setdefault(self._key(record["key"]), record["metrics"])
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

    def kept(self) -> str:
        """What a search stopped by a lost evaluation leaves: the end of its one line."""
        if self.state is None:
            return "; nothing was kept (--state FILE keeps a search's evaluations as they come, to resume from)."
        designs = f"{self.stored} design{'' if self.stored == 1 else 's'}"
        return (f"; the state file {self.state} keeps {designs}: run the same command again to resume from "
                f"{'it' if self.stored == 1 else 'them'}.")

    def __call__(self, vectors: NDArray) -> list[dict]:
        designs = self.designs(vectors)
        keys = [design.tobytes().hex() for design in designs]
        first = {}
        for i, key in enumerate(keys):
            first.setdefault(key, i)
        new = [key for key in first if key not in self.seen]
        missing = [key for key in new if key not in self.known]
        self.replayed += len(new) - len(missing)
        if missing:
            arguments = [(self.study.family, self.study.values(designs[first[key]]), self.study.region)
                         for key in missing]
            try:
                results = self._run(arguments)
            except BrokenProcessPool:
                raise EvaluationError("An evaluation process died (killed: by a signal, or by the out-of-memory "
                                      "killer when memory ran short)" + self.kept()) from None
            except ClusterError as error:
                if self.state is None:
                    raise
                raise ClusterError(str(error).removesuffix(".").removesuffix("; nothing was written")
                                   + self.kept()) from None
            self.computed += len(missing)
            self.known.update(zip(missing, results))
            if self.state is not None:
                self._append(list(zip(missing, results)))
        for key in new:
            self.seen.add(key)
            self.order.append((designs[first[key]].copy(), self.known[key]))
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
                                            initializer=_start_worker, initargs=(os.getpid(),))
        return list(self.pool.map(evaluate_candidate, *zip(*arguments)))

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
        if self.pool is not None:
            self.pool.shutdown(cancel_futures=True)
