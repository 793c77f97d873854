"""What a closed-form chain solver returns: a :class:`ClosedFormResult`, or a :class:`Rejection` saying why
a chain is not of its type."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
from numpy.typing import NDArray


@dataclass(frozen=True)
class ClosedFormResult:
    """Result of a closed-form chain solver for a flat batch of N platform poses.

    Attributes
    ----------
    values : ndarray, shape (N, m), or a function returning it
        Joint values, NaN where unreachable. The planar closed forms return a function: the
        joint values follow from the joint points by a few ``arctan2`` and are only computed
        when asked for (screws need the points only).
    reachable : ndarray of bool, shape (N,)
    gap : ndarray, shape (N,)
        0 where reachable, otherwise by how much the target is out of reach (m).
    axes, points : ndarray, shape (N, m, 3)
        Joint axes and points in the base frame (possibly component-major views).
    """

    values: NDArray[np.float64] | Callable[[], NDArray[np.float64]]
    reachable: NDArray[np.bool_]
    gap: NDArray[np.float64]
    axes: NDArray[np.float64]
    points: NDArray[np.float64]


@dataclass(frozen=True)
class Rejection:
    """Why a chain is not of a closed-form type (falsy, so ``if solver:`` reads naturally)."""

    kind: str
    reason: str

    def __bool__(self) -> bool:
        return False
