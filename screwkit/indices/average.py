"""The average case of Eq. 12: the (probability-weighted) mean over the sets of ``j`` failed actuators.

:math:`F_{Oj}` (Eq. 12) is a worst case: the minimum, over the :math:`\\binom{a}{j}` sets :math:`E` of ``j`` failed
actuators, of the LMTI of the actuators left. The paper notes that an average could replace the minimum and leaves
it aside (end of Sec. 3); screwkit's extension reports it beside the worst case:

.. math::

    \\bar F_{Oj} = \\sum_{|E| = j} w_E \\, {}^{A \\setminus E}LMTI

with equal weights, or per-actuator failure probabilities :math:`p_i` (:func:`failure_weights`). It is one derived
index of the registry (:func:`mean_record`, columns ``f_o_mean1``, ``f_o_mean2``, ...), registered while a study
asks for it (:func:`averaging`): every output that loops over the registry (reports, exports, maps keeping the
worst orientation, sweeps) then carries it. Only numpy and the registry are imported here.
"""

from __future__ import annotations

from contextlib import contextmanager
from functools import lru_cache
from itertools import combinations
from math import prod
from typing import Iterator

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.indices.registry import IndexRecord, shared

__all__ = ["AGGREGATES", "failure_weights", "mean_remaining_lmti", "mean_record", "averaging", "MEAN_NAME",
           "is_mean_column"]

AGGREGATES = ("min", "mean")
"""How the sets of ``j`` failures are combined: the paper's worst case (Eq. 12), or also their (weighted) mean."""
MEAN_NAME = "f_o_mean"
"""The registry name (and column stem) of the mean: ``f_o_mean1``, ``f_o_mean2``, ..."""


def is_mean_column(column: str) -> bool:
    """Whether ``column`` names the average case (``f_o_mean1``, ``f_o_mean2``, ...): the registry knows it only
    while a study has it registered (:func:`averaging`), so that a study choosing it by name asks here first."""
    stem = column.rstrip("0123456789")
    return stem == MEAN_NAME and stem != column


def failure_weights(actuator_count: int, faults: int, probabilities: ArrayLike | None = None
                    ) -> NDArray[np.float64]:
    """The weight of each set of ``faults`` failed actuators (:meth:`Indices.failed_sets` order) in the mean.

    Equal weights without ``probabilities``; with the failure probability :math:`p_i` of each actuator
    (independent failures), the probability that exactly the set ``E`` failed given that ``j`` did:

    .. math::

        w_E = \\frac{\\prod_{i \\in E} p_i \\prod_{i \\notin E} (1 - p_i)}
                   {\\sum_{|E'| = j} \\prod_{i \\in E'} p_i \\prod_{i \\notin E'} (1 - p_i)}
    """
    sets = [tuple(sorted(set(range(actuator_count)) - set(left)))
            for left in combinations(range(actuator_count), actuator_count - faults)]
    if probabilities is None:
        return np.full(len(sets), 1.0 / len(sets))
    p = np.asarray(probabilities, dtype=float)
    if p.shape != (actuator_count,) or not np.all((p >= 0) & (p <= 1)):
        raise ValueError(f"Expected one failure probability in [0, 1] per actuator ({actuator_count}), got "
                         f"{np.asarray(probabilities).tolist()}.")
    weights = np.array([prod(p[i] if i in failed else 1.0 - p[i] for i in range(actuator_count)) for failed in sets])
    if not weights.sum() > 0:
        raise ValueError(f"No set of {faults} failure(s) has a positive probability with failure probabilities "
                         f"{p.tolist()}.")
    return weights / weights.sum()


def mean_remaining_lmti(remaining_lmti: dict, actuator_count: int, probabilities: ArrayLike | None = None
                        ) -> dict[int, NDArray[np.float64]]:
    """:math:`\\bar F_{Oj}` by ``j``: the LMTI left after each set of ``j`` failures (``remaining_lmti[j]``, shape
    (..., C(a, j)), as :attr:`Indices.remaining_lmti`) weighted by :func:`failure_weights`."""
    return {j: np.asarray(values) @ failure_weights(actuator_count, j, probabilities)
            for j, values in remaining_lmti.items()}


@lru_cache(maxsize=32)
def mean_record(probabilities: tuple[float, ...] | None = None) -> IndexRecord:
    """The registry record of :math:`\\bar F_{Oj}` (one object per ``probabilities``, so that registering it twice
    is sharing it, :func:`~screwkit.indices.registry.shared`)."""
    weighted = "probability-weighted " if probabilities is not None else ""
    return IndexRecord(
        MEAN_NAME, "F_Omean", "screwkit's extension of Eq. 12",
        f"output fault-tolerance index, average case: the {weighted}mean LMTI after j faults", per_fault=True,
        compute=lambda result: mean_remaining_lmti(result.remaining_lmti, result.actuator_count, probabilities),
        bounds=(0.0, 1.0))


@contextmanager
def averaging(probabilities: ArrayLike | None = None) -> Iterator[IndexRecord]:
    """:math:`\\bar F_{Oj}` registered for the duration of a ``with`` block (threads of one study share it)."""
    key = None if probabilities is None else tuple(float(p) for p in np.atleast_1d(probabilities))
    with shared(mean_record(key)) as record:
        yield record
