"""Running a function over chunks of a batch, the chunks side by side on several threads."""

from __future__ import annotations

import numbers
import os
from concurrent.futures import ThreadPoolExecutor
from typing import Callable, TypeVar

Result = TypeVar("Result")


def map_chunks(function: Callable[[slice], Result], count: int, chunk_size: int,
               threads: int | None = None) -> list[Result]:
    """``function(part)`` for consecutive slices ``part`` covering ``range(count)``, in order.

    Chunks are at most ``chunk_size`` long and, with several threads, small enough that every
    thread gets one. The compiled kernels release the GIL, so the threads run in parallel.
    """
    threads = (os.cpu_count() or 1) if threads is None else threads
    if not isinstance(threads, numbers.Integral) or threads < 1:
        raise ValueError(f"Expected `threads` >= 1, got {threads!r}.")
    chunk_size = max(1, min(chunk_size, -(-count // threads)))
    parts = [slice(start, min(start + chunk_size, count)) for start in range(0, count, chunk_size)]
    if threads > 1 and len(parts) > 1:
        with ThreadPoolExecutor(max_workers=threads) as pool:
            return list(pool.map(function, parts))
    return [function(part) for part in parts]
