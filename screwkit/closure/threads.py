"""Thread policy of closure solving and screw building.

numpy releases the GIL inside its loops, so cache-sized blocks of a large batch run side by
side on several threads (:func:`for_each_block`). A caller that already runs one task per core
(a map's tasks, the index kernel given ``threads``) bounds them with
:func:`thread_limit`, so that thread pools are not nested on the same cores.
"""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Callable, Iterator

__all__ = ["thread_limit", "block_threads", "for_each_block", "BLOCK"]

BLOCK = 1 << 15
"""Configurations per block in the closed-form solvers and screw building."""
_WORKERS = max(1, min(4, os.cpu_count() or 1))  # threads for blocks (numpy releases the GIL)
_THREAD_LIMIT: ContextVar[int] = ContextVar("screwkit_thread_limit", default=_WORKERS)


@contextmanager
def thread_limit(threads: int | None) -> Iterator[None]:
    """Within the block, closure solving and screw building use at most ``threads`` threads.

    For callers that already run one task per core (a map's tasks): nested thread
    pools would only compete for the same cores. ``None`` leaves the default (all cores, up
    to 4). The limit is per thread (a context variable).
    """
    if threads is None:
        yield
        return
    token = _THREAD_LIMIT.set(max(1, int(threads)))
    try:
        yield
    finally:
        _THREAD_LIMIT.reset(token)


def block_threads() -> int:
    """Threads the closure and screw computations may use here (see :func:`thread_limit`)."""
    return min(_WORKERS, _THREAD_LIMIT.get())


def for_each_block(count: int, work: Callable[[slice], None], block: int = BLOCK) -> None:
    """Call ``work(block)`` for consecutive slices of ``range(count)`` (``block`` long), in threads when large.

    numpy (and a numba function compiled ``nogil``) releases the GIL inside its loops, so blocks
    that fit in cache run in parallel on all cores; ``work`` must only write to its own slice of
    the outputs.
    """
    blocks = [slice(start, min(start + block, count)) for start in range(0, count, block)]
    workers = block_threads()
    if workers > 1 and len(blocks) > 1:
        with ThreadPoolExecutor(workers) as pool:
            for _ in pool.map(work, blocks):
                pass
    else:
        for block in blocks:
            work(block)

