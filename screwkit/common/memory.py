"""Freed memory kept for the next design instead of handed back to the system and faulted in again.

A design evaluation allocates its arrays afresh (the joint screws of every configuration of its region, tens of
megabytes for a planar disc) and frees them when it returns. glibc's allocator serves blocks above its mmap
threshold (128 KiB, rising to at most 32 MiB as blocks are freed) by ``mmap``, hands them back on ``free``, and
trims the heap's free top above its trim threshold: the next design touches new pages, and the kernel zeroes each
one (a minor page fault). On this toolkit's planar family that was about 6,000 page faults and a third of each
design's time (45 ms against 27 ms, ``docs/performance.md``). :func:`keep_freed_memory` raises both thresholds
(``mallopt``), so a process that evaluates one design after another reuses the pages it already has.

It changes how the whole process allocates, so the library never calls it on import: the ``design-search``
command calls it, and so do its evaluation processes. The resident memory a process keeps is then its peak, which
it has reached anyway. Elsewhere than glibc (macOS, Windows, musl) it does nothing and says so.
"""

from __future__ import annotations

import ctypes
import sys

__all__ = ["keep_freed_memory", "KEPT_BYTES", "OLD_LARGEST"]

KEPT_BYTES = 1 << 30
"""Blocks up to this size come from the heap, and up to this much free memory is kept at its top (1 GiB: above the
arrays of a design evaluation, tens of megabytes)."""

OLD_LARGEST = 32 << 20
"""The largest mmap threshold every glibc takes (64 bits)."""
_M_TRIM_THRESHOLD = -1  # glibc's malloc.h
_M_MMAP_THRESHOLD = -3


def keep_freed_memory(kept: int = KEPT_BYTES) -> bool:
    """Make glibc keep freed blocks of up to ``kept`` bytes for reuse; True where it did (glibc), else False."""
    if not sys.platform.startswith("linux"):
        return False
    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):  # a C library without mallopt
        return False
    mallopt.argtypes, mallopt.restype = (ctypes.c_int, ctypes.c_int), ctypes.c_int
    # a glibc may refuse an mmap threshold above 32 MiB (half its largest heap on 64 bits): then 32 MiB
    mapped = bool(mallopt(_M_MMAP_THRESHOLD, kept)) or bool(mallopt(_M_MMAP_THRESHOLD, min(kept, OLD_LARGEST)))
    return bool(mallopt(_M_TRIM_THRESHOLD, kept)) and mapped
