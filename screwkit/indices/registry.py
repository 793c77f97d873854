"""Every index screwkit reports, one record each: what it is, where it is defined, how studies use it.

Whatever lists indices loops over :data:`INDICES`: the JSON and xarray exports of
:class:`~screwkit.indices.results.Indices`, the columns of maps and how a map keeps the worst of an
orientation set, sweep summaries, the region metrics of the design search and the command line.
**Adding an index** is one :class:`IndexRecord` (:func:`register`) and its computation: ``compute``, a
function of a result computed with ``detail`` (its per-actuator, per-submechanism and per-set arrays).

Each index has one value per configuration, or, with ``per_fault``, one per number of faults ``j``
(columns ``f_o1``, ``f_o2``, ...). Only the standard library is imported here.
"""

from __future__ import annotations

import threading
from contextlib import contextmanager
from dataclasses import dataclass, replace
from typing import Any, Callable, Iterator

__all__ = ["IndexRecord", "INDICES", "register", "unregister", "registered", "shared", "index_columns",
           "column_record",
           "column_label", "is_column", "applies"]


@dataclass(frozen=True)
class IndexRecord:
    """One index.

    Attributes
    ----------
    name : str
        Key in reports, and the stem of its columns (``f_o`` gives ``f_o1``, ``f_o2``, ... with ``per_fault``).
    label : str
        How it is written: ``ITI``, ``F_O`` (then ``F_O1``, ...).
    equation : str
        Where it is defined (``Eq. 12`` of the paper, or ``screwkit``'s extension).
    description : str
        One line on what it measures (the ``long_name`` of its variables).
    per_fault : bool
        One value per number of faults ``j`` (a dict by ``j`` in results and reports).
    constraints : bool
        Defined only where chains hold constraint wrenches of their own (elsewhere NaN, "not applicable").
    reduce : str
        How a map keeps the orientation set of a point: ``"min"``, the worst orientation (the paper's Fig. 5).
    compute : callable or None
        For an index derived from the others: ``compute(result)`` gives its values (a dict by ``j`` with
        ``per_fault``) from a result computed with detail. None for the indices the compiled kernels give.
    bounds : (float, float) or None
        The range of its values, where it has one (the paper's indices and screwkit's extensions: [0, 1]); a
        design region's level outside it is refused.
    """

    name: str
    label: str
    equation: str
    description: str
    per_fault: bool = False
    constraints: bool = False
    reduce: str = "min"
    compute: Callable[[Any], Any] | None = None
    bounds: tuple[float, float] | None = None

    def column(self, faults: int | None = None) -> str:
        """The column name: the name, followed by ``j`` for a per-fault index."""
        return f"{self.name}{faults}" if self.per_fault else self.name

    def long_name(self, faults: int | None = None) -> str:
        """``F_O1 (Eq. 12)``: the label (with ``j``) and where it is defined."""
        return f"{self.label}{faults if self.per_fault else ''} ({self.equation})"


INDICES: dict[str, IndexRecord] = {}
"""Every index, by name, in the order reports list them."""


def register(record: IndexRecord) -> IndexRecord:
    """Add an index (its name must be new); studies, exports and the command line then include it."""
    if record.name in INDICES:
        raise ValueError(f"An index named {record.name!r} is registered already.")
    if record.reduce != "min":
        raise ValueError(f"Expected `reduce` 'min' (a map keeps the worst orientation), got {record.reduce!r}.")
    INDICES[record.name] = record
    return record


def unregister(name: str) -> None:
    """Remove an index added with :func:`register`."""
    if name not in INDICES or INDICES[name].compute is None:
        raise ValueError(f"{name!r} is not an index added with register().")
    del INDICES[name]


@contextmanager
def registered(record: IndexRecord) -> Iterator[IndexRecord]:
    """An index registered for the duration of a ``with`` block."""
    register(record)
    try:
        yield record
    finally:
        unregister(record.name)


_SHARED: dict[str, int] = {}
_SHARED_LOCK = threading.Lock()


@contextmanager
def shared(record: IndexRecord) -> Iterator[IndexRecord]:
    """:func:`registered`, for a record that tasks running at once (threads of one study) each register: the first
    registers it, the last to leave unregisters it; another record of the same name is refused as by
    :func:`register`."""
    with _SHARED_LOCK:
        if INDICES.get(record.name) is record and record.name in _SHARED:
            _SHARED[record.name] += 1
        else:
            register(record)
            _SHARED[record.name] = 1
    try:
        yield record
    finally:
        with _SHARED_LOCK:
            _SHARED[record.name] -= 1
            if not _SHARED[record.name]:
                del _SHARED[record.name]
                unregister(record.name)


def applies(record: IndexRecord, result) -> bool:
    """Whether ``result`` has values of ``record`` (a constraint index needs constraint wrenches)."""
    return not record.constraints or bool(result.constraint_count)


def index_columns(result) -> dict[str, Any]:
    """Every column of every registered index that applies to ``result``: name -> values (batch shape)."""
    out = {}
    for record in INDICES.values():
        if not applies(record, result):
            continue
        try:
            values = result.index(record.name)
        except ValueError:  # a derived index registered after the result was computed
            continue
        if record.per_fault:
            out.update({record.column(j): value for j, value in values.items()})
        else:
            out[record.name] = values
    return out


def column_record(column: str) -> tuple[IndexRecord, int | None]:
    """The record and number of faults of a column name (``f_io2`` -> F_IO, 2); ValueError if none."""
    if column in INDICES and not INDICES[column].per_fault:
        return INDICES[column], None
    stem = column.rstrip("0123456789")
    if stem != column and stem in INDICES and INDICES[stem].per_fault and not column[len(stem)] == "0":
        return INDICES[stem], int(column[len(stem):])
    known = ", ".join(record.column("<j>") if record.per_fault else record.name for record in INDICES.values())
    raise ValueError(f"Unknown index {column!r}; the indices are {known}.")


def is_column(name: str) -> bool:
    """Whether ``name`` is the column of a registered index (``iti``, ``f_o2``, ...)."""
    try:
        column_record(name)
    except ValueError:
        return False
    return True


def column_label(column: str) -> str:
    """``F_IO2 (Eq. 14)`` for ``f_io2``."""
    record, faults = column_record(column)
    return record.long_name(faults)


for _record in (
    IndexRecord("iti", "ITI", "Eq. 7", "input transmission index: the lowest ITI of the actuators (Eq. 6)"),
    IndexRecord("lmti", "LMTI", "Eq. 11", "local minimized transmission index: the best OTI of the non-redundant "
                                        "submechanisms (Eqs. 8-10)"),
    IndexRecord("f_o", "F_O", "Eq. 12", "output fault-tolerance index: the worst LMTI after j faults",
                per_fault=True),
    IndexRecord("f_io", "F_IO", "Eq. 14", "input-output fault-tolerance index: min(F_Oj, ITI)", per_fault=True),
    IndexRecord("cti", "CTI", "constraint transmission, docs/theory.md",
                "constraint transmission index: the best non-redundant constraint subsystem's lowest power "
                "coefficient of a released constraint wrench", constraints=True),
    IndexRecord("f_c", "F_C", "screwkit's extension of Eq. 12", "the worst CTI after j faults", per_fault=True,
                constraints=True),
):
    register(replace(_record, bounds=(0.0, 1.0)))
del _record
