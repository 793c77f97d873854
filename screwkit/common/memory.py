"""How much memory a study may take (:func:`available_memory`), and freed memory kept for the next design.

A study that would not fit is refused before it computes (a map's result, a path's samples), against what this
process can still be given: the least of the memory the system could free for it (``MemAvailable``, which counts
the page cache it would drop, where ``sysconf``'s free pages alone would refuse a study on a machine that has
written large files), what its container's control group leaves it, and what its address-space limit
(``ulimit -v``) leaves it.

Freed memory is kept for the next design instead of handed back to the system and faulted in again. A design
evaluation allocates its arrays afresh (the joint screws of every configuration of its region, tens of
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
import os
import sys
from pathlib import Path

__all__ = ["available_memory", "byte_size", "keep_freed_memory", "KEPT_BYTES", "OLD_LARGEST"]

_CGROUP = Path("/sys/fs/cgroup")
_SELF_CGROUP = Path("/proc/self/cgroup")
_MEMINFO = Path("/proc/meminfo")


def available_memory() -> int | None:
    """Bytes this process can still be given (module docstring); None where none of the three can be read."""
    found = [_system_available(), _cgroup_available(), _address_space_available()]
    known = [value for value in found if value is not None]
    return max(0, min(known)) if known else None


def _system_available() -> int | None:
    try:
        for line in _MEMINFO.read_text().splitlines():
            if line.startswith("MemAvailable:"):
                return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return int(os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))
    except (ValueError, OSError, AttributeError):
        return None


def _cgroup_available() -> int | None:
    """The limit of this process's control group (its own, from ``/proc/self/cgroup``, else the mount's root: a
    container's) less what it uses, the page cache it could drop (``inactive_file``) not counted, as container
    runtimes count it; v2, then v1. None without a limit."""
    for folder, limit, used, dropped in _cgroup_files():
        try:
            text = (folder / limit).read_text().strip()
            if text == "max" or int(text) >= 1 << 60:  # v1 writes "no limit" as a huge number
                return None
            in_use = int((folder / used).read_text().strip())
        except (OSError, ValueError):
            continue
        try:
            stat = dict(line.split(None, 1) for line in (folder / "memory.stat").read_text().splitlines() if line)
            in_use -= int(stat.get(dropped, 0))
        except (OSError, ValueError):
            pass
        return int(text) - in_use
    return None


def _cgroup_files():
    """``(folder, limit, usage, droppable)`` to look at in turn: v2 (this process's group, then the root), v1."""
    own: dict[str, str] = {}
    try:
        for line in _SELF_CGROUP.read_text().splitlines():
            number, controllers, path = line.split(":", 2)
            if number == "0" and not controllers:
                own["v2"] = path.lstrip("/")
            elif "memory" in controllers.split(","):
                own["v1"] = path.lstrip("/")
    except (OSError, ValueError):
        pass
    for folder in ([_CGROUP / own["v2"]] if own.get("v2") else []) + [_CGROUP]:
        yield folder, "memory.max", "memory.current", "inactive_file"
    for folder in ([_CGROUP / "memory" / own["v1"]] if own.get("v1") else []) + [_CGROUP / "memory"]:
        yield folder, "memory.limit_in_bytes", "memory.usage_in_bytes", "total_inactive_file"


def _address_space_available() -> int | None:
    """The address-space limit (``ulimit -v``) less the process's size now; None without a limit."""
    try:
        import resource  # (POSIX only)

        limit = resource.getrlimit(resource.RLIMIT_AS)[0]
        if limit == resource.RLIM_INFINITY:
            return None
        return limit - int(Path("/proc/self/statm").read_text().split()[0]) * os.sysconf("SC_PAGE_SIZE")
    except (ImportError, OSError, ValueError, IndexError, AttributeError):
        return None


def byte_size(count: int) -> str:
    """``count`` bytes in GiB, MiB, KiB or B (one decimal)."""
    for unit, size in (("GiB", 2**30), ("MiB", 2**20), ("KiB", 2**10)):
        if count >= size:
            return f"{count / size:.1f} {unit}"
    return f"{count} B"


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
