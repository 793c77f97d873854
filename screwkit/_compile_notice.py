"""A line on stderr before a compiled kernel is built for the first time (numba, tens of seconds),
and the index kernels compiled in parallel child processes on a first run.

numba keeps compiled kernels in a cache (an index file ``<module>.<function>-<line>.pyXY.nbi`` in
``__pycache__`` beside the source, in ``NUMBA_CACHE_DIR`` when that is set, else in the user's
cache folder). :func:`announce_compilation` looks for that index before the kernel's module is
imported or first called, without importing numba, and when it is missing says so on stderr, so
that a first run does not look hung. ``screwkit warmup`` compiles every kernel ahead.

The index kernels (:mod:`screwkit._index_kernels`) are the longest to compile. As soon as a
command knows it will compute indices (before Pinocchio is even imported), :func:`compile_ahead`
starts one child process per kernel missing from the cache, each importing the kernel's module
and so compiling it into the cache, and :func:`prepare_kernels` waits for them before the modules
are imported here (they then load from the cache; if a child failed, the import compiles the
kernel in this process). Two cores compile two kernels in about the time of the longer one.
"""

from __future__ import annotations

import os
import subprocess
import sys
import threading
from pathlib import Path

__all__ = ["announce_compilation", "compile_ahead", "prepare_kernels", "kernel_is_cached", "silence", "stage_kernels",
           "KERNELS", "INDEX_KERNELS", "NULL_KERNEL", "GRAM_KERNEL"]

KERNELS = {
    "screwkit._wrench_kernel": ("wrench_kernel", 7),
    "screwkit._output_kernel": ("output_kernel", 14),
    "screwkit._null_kernel": ("null_kernel", 8),
    "screwkit._gram_kernel": ("gram_kernel", 6),
    "screwkit._planar_kernel": ("planar_closed_form_kernel", 2),
    "screwkit.closure._task_kernel": ("close_chains_kernel", 18),
    "screwkit.closure._frames_kernel": ("chain_frames_kernel", 3),
}
"""Each compiled module: its entry function and about how long (s) it takes to compile on a 2-core machine."""

INDEX_KERNELS = ("screwkit._wrench_kernel", "screwkit._output_kernel")
"""The stages of :func:`screwkit.transmission.analyze` every mechanism needs, compiled apart (in parallel on a
first run); the null-vector and Gram stages are compiled only for mechanisms that need them."""

NULL_KERNEL, GRAM_KERNEL = "screwkit._null_kernel", "screwkit._gram_kernel"


def stage_kernels(joint_counts, n: int) -> tuple[str, ...]:
    """The kernels beyond :data:`INDEX_KERNELS` that actuated chains of these joint DoF counts need
    in a motion space of dimension n: the null-vector kernel for a chain of n joint DoFs when n is
    not 3 (for n = 3 the wrench kernel takes a cross product), the Gram kernel for a chain of more
    or fewer joint DoFs than n."""
    counts = {int(count) for count in joint_counts}
    return (NULL_KERNEL,) * (n != 3 and n in counts) + (GRAM_KERNEL,) * bool(counts - {n})


_checked: set[str] = set()
_silent = False
_children: dict[str, subprocess.Popen] = {}
_lock = threading.Lock()


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


def compile_ahead(*modules: str) -> None:
    """Once per process and module: for the kernels numba's cache lacks, one line on stderr and, on a
    machine with more than one core, one child process per kernel that compiles it into the cache
    while this process goes on (:func:`prepare_kernels` waits for them). On one core they compile
    in this process, when first imported."""
    with _lock:
        missing = [module for module in modules if module not in _checked and not kernel_is_cached(module)]
        _checked.update(modules)
        if not missing:
            return
        parallel = (os.cpu_count() or 1) > 1
        if not _silent:
            names = " and ".join(KERNELS[module][0] for module in missing)
            seconds = (max if parallel else sum)(KERNELS[module][1] for module in missing)
            where = f" in {len(missing)} processes" if parallel and len(missing) > 1 else ""
            print(f"screwkit: compiling {names}{where} (first run only, about {seconds} s; `screwkit warmup` "
                  "compiles every kernel ahead)", file=sys.stderr, flush=True)
        if not parallel:
            return  # compiled here, when first imported
        package_parent = str(Path(__file__).resolve().parents[1])
        path = os.pathsep.join(filter(None, [package_parent, os.environ.get("PYTHONPATH")]))
        for module in missing:
            _children[module] = subprocess.Popen(
                [sys.executable, "-c", f"import {module}"], env=dict(os.environ, PYTHONPATH=path),
                stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def prepare_kernels(modules: tuple[str, ...] = INDEX_KERNELS) -> None:
    """Before the index kernels' modules are imported: start compiling those not cached
    (:func:`compile_ahead`) and wait for the child processes compiling them."""
    compile_ahead(*modules)
    for module in modules:
        with _lock:
            child = _children.get(module)
        if child is not None:
            child.wait()  # (thread-safe: every thread needing the kernel waits here)
            with _lock:
                _children.pop(module, None)
