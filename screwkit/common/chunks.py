"""Running a function over chunks of a batch, the chunks side by side on several threads."""

from __future__ import annotations

import numbers
import os
import threading
from concurrent.futures import ThreadPoolExecutor
from typing import Callable, TypeVar

Result = TypeVar("Result")

CHUNK_THREAD_PREFIX = "screwkit-chunks"
"""The name of the threads of :func:`chunk_pool` (a call made on one of them runs its chunks in turn)."""
_POOLS: dict[tuple[int, int], ThreadPoolExecutor] = {}
_POOLS_LOCK = threading.Lock()


def chunk_pool(threads: int) -> ThreadPoolExecutor:
    """The pool of ``threads`` threads kept for the process (one per size, made when first asked, in each
    process: a forked child makes its own), so that a batch cut into many calls of :func:`map_chunks` (a
    path of 100 chunks, the rounds of its refinement) does not start and stop its threads for each call."""
    key = (os.getpid(), threads)
    with _POOLS_LOCK:
        pool = _POOLS.get(key)
        if pool is None:
            pool = _POOLS[key] = ThreadPoolExecutor(max_workers=threads, thread_name_prefix=CHUNK_THREAD_PREFIX)
        return pool


def map_chunks(function: Callable[[slice], Result], count: int, chunk_size: int,
               threads: int | None = None) -> list[Result]:
    """``function(part)`` for consecutive slices ``part`` covering ``range(count)``, in order.

    Chunks are at most ``chunk_size`` long and, with several threads, small enough that every
    thread gets one. The compiled kernels release the GIL, so the threads run in parallel, on threads kept
    across calls (:func:`chunk_pool`); a call made from one of those threads runs its chunks in turn
    (the same chunks), so that a pool never waits on itself.
    """
    threads = (os.cpu_count() or 1) if threads is None else threads
    if not isinstance(threads, numbers.Integral) or threads < 1:
        raise ValueError(f"Expected `threads` >= 1, got {threads!r}.")
    chunk_size = max(1, min(chunk_size, -(-count // threads)))
    parts = [slice(start, min(start + chunk_size, count)) for start in range(0, count, chunk_size)]
    if threads > 1 and len(parts) > 1 and not threading.current_thread().name.startswith(CHUNK_THREAD_PREFIX):
        return list(chunk_pool(int(threads)).map(function, parts))
    return [function(part) for part in parts]
