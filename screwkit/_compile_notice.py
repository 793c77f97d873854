"""A line on stderr before a compiled kernel is built for the first time (numba, tens of seconds).

numba keeps compiled kernels in a cache (an index file ``<module>.<function>-<line>.pyXY.nbi`` in
``__pycache__`` beside the source, in ``NUMBA_CACHE_DIR`` when that is set, else in the user's
cache folder). :func:`announce_compilation` looks for that index before the kernel's module is
imported or first called, without importing numba, and when it is missing says so on stderr, so
that a first run does not look hung. ``screwkit warmup`` compiles every kernel ahead.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

__all__ = ["announce_compilation", "kernel_is_cached", "silence", "KERNELS"]

KERNELS = {
    "screwkit._kernels": ("transmission_kernel", 40),
    "screwkit._planar_kernel": ("planar_closed_form_kernel", 2),
    "screwkit.closure._task_kernel": ("close_chains_kernel", 18),
    "screwkit.closure._frames_kernel": ("chain_frames_kernel", 3),
}
"""Each compiled module: its entry function and about how long (s) it takes to compile on a 2-core machine."""

_checked: set[str] = set()
_silent = False


def silence() -> None:
    """No notice from now on in this process (a command run with ``--quiet`` or ``--json``)."""
    global _silent
    _silent = True


def _first_line(source: Path, function: str) -> int | None:
    """The line numba names the function's cache after: its first decorator (``co_firstlineno``)."""
    lines = source.read_text(encoding="utf-8").splitlines()
    for number, line in enumerate(lines):
        if line.startswith(f"def {function}("):
            while number > 0 and lines[number - 1].startswith("@"):
                number -= 1
            return number + 1
    return None


def _cache_folders(source: Path) -> list[Path]:
    if os.environ.get("NUMBA_CACHE_DIR"):
        return [Path(os.environ["NUMBA_CACHE_DIR"])]
    home = Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache"))
    return [source.parent / "__pycache__", home / "numba"]


def kernel_is_cached(module: str) -> bool:
    """Whether numba's cache holds an index for the module's kernel entry (see :data:`KERNELS`)."""
    import importlib.util

    function, _ = KERNELS[module]
    spec = importlib.util.find_spec(module)
    if spec is None or spec.origin is None:
        return False
    source = Path(spec.origin)
    line = _first_line(source, function)
    name = f"{source.stem}.{function}-{line}.py{sys.version_info.major}{sys.version_info.minor}.nbi"
    for folder in _cache_folders(source):
        if (folder / name).is_file() or (folder.is_dir() and any(folder.rglob(name))):
            return True
    return False


def announce_compilation(module: str) -> None:
    """Once per process and module: a line on stderr when the module's kernel is about to be compiled."""
    if _silent or module in _checked:  # (an imported module may still compile on first call)
        return
    _checked.add(module)
    if not kernel_is_cached(module):
        function, seconds = KERNELS[module]
        print(f"screwkit: compiling {function} (first run only, about {seconds} s; `screwkit warmup` compiles "
              "every kernel ahead)", file=sys.stderr, flush=True)
