"""The batch arrays of :mod:`screwkit.studies.poses`: each chunk's per-configuration results copied into arrays for
the whole batch, every row written once (no fill before the chunks write: a map's or a path's arrays are large).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from screwkit.indices.results import Indices

__all__ = ["ARRAYS", "DICTS", "scatter", "fill_unreachable"]

ARRAYS = ("iti", "lmti", "mutual_interference", "iti_actuators", "oti_submechanisms", "cti", "cti_submechanisms",
          "instantaneous_dof", "constraint_singular")
DICTS = ("f_o", "f_io", "worst_fault_indices", "f_c", "remaining_lmti", "derived")


def _unreachable_value(dtype):
    """What a batch array holds where there is no result: NaN, -1 or False."""
    return False if dtype.kind == "b" else -1 if dtype.kind in "iu" else np.nan


def scatter(arrays: dict, count: int, index: NDArray, result: Indices) -> None:
    """Copy one chunk's per-configuration results (batch-first) into the batch arrays at ``index`` (sorted, without
    repeats: a slice when it is a run, as when every pose of the chunk is reachable, a copy without indexing).

    Each row is written once: an array is made unfilled by the first chunk that has its result, with the rows of
    the chunks before it filled with "no result" (:func:`_unreachable_value`; none when it is the first chunk with
    reachable poses), and a chunk without a result the array has fills its rows so; :func:`fill_unreachable`
    fills the rows out of reach at the end."""
    if index.size and int(index[-1]) - int(index[0]) + 1 == index.size:
        index = slice(int(index[0]), int(index[-1]) + 1)
    applicable = ARRAYS if result.constraint_count else tuple(n for n in ARRAYS if not n.startswith("cti"))
    pieces = {name: getattr(result, name) for name in applicable}
    pieces.update({(name, j): value for name in DICTS for j, value in getattr(result, name).items()
                   if result.constraint_count or name != "f_c"})
    done = arrays.setdefault(_DONE, np.zeros(count, dtype=bool))  # the rows of the chunks scattered so far
    for key, value in pieces.items():
        if value is None:
            continue
        if key not in arrays:
            value = np.asarray(value)
            arrays[key] = np.empty((count,) + value.shape[1:], dtype=value.dtype)
            arrays[key][done] = _unreachable_value(value.dtype)
        arrays[key][index] = value
    for key, array in arrays.items():
        if key is not _DONE and (pieces.get(key) is None):
            array[index] = _unreachable_value(array.dtype)
    done[index] = True


_DONE = "rows scattered"
"""The key of :func:`scatter`'s record of the rows it has written (taken out by :func:`fill_unreachable`)."""


def fill_unreachable(arrays: dict) -> None:
    """The rows of the batch arrays that no chunk wrote (the poses out of reach): NaN, -1 or False."""
    done = arrays.pop(_DONE, None)
    if done is None or done.all():
        return
    missing = np.flatnonzero(~done)
    for array in arrays.values():
        array[missing] = _unreachable_value(array.dtype)
