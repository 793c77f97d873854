"""numba's ``njit`` for screwkit's compiled kernels, caching where :func:`screwkit.common.compiling.numba_cache`
decides (without a cache when no folder can be written)."""

from __future__ import annotations

from numba import njit as numba_njit

from screwkit.common.compiling import numba_cache

__all__ = ["njit"]


def njit(*args, **options):
    """``numba.njit``; ``cache=True`` caches where :func:`~screwkit.common.compiling.numba_cache` decides."""
    if options.get("cache") and not numba_cache():
        options["cache"] = False
    return numba_njit(*args, **options)
