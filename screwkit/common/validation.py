"""Input checks that name the argument, what was expected and what arrived."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray


def check_shape(array: NDArray, tail: tuple, name: str, batch: bool = True) -> NDArray:
    """Check that ``array`` ends with the dimensions ``tail`` (``None`` = any size)."""
    ok = array.ndim >= len(tail) if batch else array.ndim == len(tail)
    if ok:
        ok = all(t is None or s == t for s, t in zip(array.shape[array.ndim - len(tail):], tail))
    if not ok:
        spelled = ", ".join("m" if t is None else str(t) for t in tail)
        prefix = "..., " if batch else ""
        raise ValueError(f"Expected `{name}` with shape ({prefix}{spelled}), got {array.shape}.")
    return array


def check_finite(array: NDArray, name: str) -> NDArray:
    """Reject NaN and inf, saying where the first one is."""
    if not np.all(np.isfinite(array)):
        bad = np.argwhere(~np.isfinite(array))[0]
        raise ValueError(
            f"Expected finite values in `{name}`, got {array[tuple(bad)]} at index {tuple(int(i) for i in bad)}."
        )
    return array


def as_float_array(value, name: str) -> NDArray[np.float64]:
    """Convert to a float array, naming the argument if that fails."""
    try:
        return np.asarray(value, dtype=float)
    except (TypeError, ValueError) as error:
        raise ValueError(f"Expected `{name}` to be numeric, got {type(value).__name__}: {error}") from None
