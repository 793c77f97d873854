"""A line on stderr before a compiled kernel is built for the first time (numba, tens of seconds),
and the index kernels compiled in parallel child processes on a first run.

numba keeps compiled kernels in a cache (an index file ``<module>.<function>-<line>.pyXY.nbi`` in
``__pycache__`` beside the source, in ``NUMBA_CACHE_DIR`` when that is set, else in the user's
cache folder). :func:`announce_compilation` looks for that index before the kernel's module is
imported or first called, without importing numba, and when it is missing says so on stderr, so
that a first run does not look hung. ``screwkit warmup`` compiles every kernel ahead.

The index kernels (:mod:`screwkit.indices.compiled.driver`) are the longest to compile. As soon as a
command knows it will compute indices (before Pinocchio is even imported), :func:`compile_ahead`
starts one child process per kernel missing from the cache, each importing the kernel's module
and so compiling it into the cache, and :func:`prepare_kernels` waits for them before the modules
are imported here (they then load from the cache; if a child failed, the import compiles the
kernel in this process). Two cores compile two kernels in about the time of the longer one. No
more children run at once than there are cores: a kernel asked for while every core compiles one
(the hexapod's null-vector kernel, known once the file is loaded) starts when the first of them
ends: three kernels of 5, 6 and 10 s then take about 11 s on two cores, where three processes
sharing them take about 12.5 s and slow the longest (measured on the hexapod's first run: 17.3 s
against 18.9 s, a wall ratio of 0.84).

Where the cache lives is decided once per process by :func:`numba_cache`, before the first kernel is
compiled or looked for: numba's own choice when it can write there (``NUMBA_CACHE_DIR`` when set,
else ``__pycache__`` beside screwkit's sources, else ``$XDG_CACHE_HOME/numba``, ``~/.cache/numba``
by default); when it cannot (a read-only install with no writable home), a folder of this user in
the temporary folder; when not even that, no cache (every run compiles). Each fallback is said in
one line on stderr (the folders are found by :mod:`screwkit.common.caches`, which places screwkit's own caches
the same way). The kernels' modules take ``njit`` from :mod:`screwkit.common.jit`, which asks it.
"""

from __future__ import annotations

import functools
import hashlib
import os
import subprocess
import sys
import threading
import time
from pathlib import Path

from screwkit.common.caches import own_folder, private_temporary_folder, user_cache_home, writable

__all__ = ["announce_compilation", "compile_ahead", "prepare_kernels", "stop_compiling", "kernel_is_cached",
           "silence", "stage_kernels", "numba_cache", "KERNELS", "INDEX_KERNELS", "NULL_KERNEL", "GRAM_KERNEL",
           "SPACE_KERNEL", "CONSTRAINT_KERNEL", "CLOSED_FORM_KERNEL", "KERNEL_SOURCES", "kernel_sources",
           "kernel_sources_digest"]

KERNELS = {
    "screwkit.indices.compiled.wrenches": ("wrench_kernel", 6),
    "screwkit.indices.compiled.outputs": ("output_kernel", 12),
    "screwkit.indices.compiled.null": ("null_kernel", 7),
    "screwkit.indices.compiled.gram": ("gram_kernel", 5),
    "screwkit.indices.compiled.spaces": ("space_kernel", 3),
    "screwkit.indices.compiled.constraints": ("constraint_kernel", 12),
    "screwkit.indices.compiled.planar": ("planar_closed_form_kernel", 2),
    "screwkit.closure.compiled.task": ("close_chains_kernel", 18),
    "screwkit.closure.compiled.frames": ("chain_frames_kernel", 3),
    "screwkit.closure.compiled.closed_form": ("spatial_closed_form_kernel", 6),
}
"""Each compiled module: its entry function and about how long (s) it takes to compile on a 2-core machine."""

INDEX_KERNELS = ("screwkit.indices.compiled.wrenches", "screwkit.indices.compiled.outputs")
"""The stages of :func:`screwkit.indices.analysis.analyze` every mechanism needs, compiled apart (in parallel on a
first run); the null-vector and Gram stages are compiled only for mechanisms that need them."""

NULL_KERNEL, GRAM_KERNEL = "screwkit.indices.compiled.null", "screwkit.indices.compiled.gram"

SPACE_KERNEL = "screwkit.indices.compiled.spaces"
"""The chain decompositions and motion spaces of mechanisms of fewer than six DoF, for chunks of 512
configurations or more."""

CONSTRAINT_KERNEL = "screwkit.indices.compiled.constraints"
"""The instantaneous DOF and CTI of mechanisms whose constraint subsystems are square, for chunks of 512
configurations or more."""

CLOSED_FORM_KERNEL = "screwkit.closure.compiled.closed_form"
"""The spatial closed forms (U-P-S, R-U-S chains) of large batches."""


PACKAGE = Path(__file__).resolve().parents[1]

KERNEL_SOURCES = ("indices/compiled/*.py", "closure/compiled/*.py", "common/fastmath.py", "common/tolerances.py",
                  "common/jit.py")
"""What the kernels are compiled from, relative to the package: every module of the compiled folders, and the modules
outside them whose functions or constants they compile in (``tests/test_kernel_cache.py`` checks that every module
a compiled module imports is here, or is plumbing that only Python runs). Their digest is part of every kernel's
cache stamp (:mod:`screwkit.common.jit`)."""


def kernel_sources(package: Path = PACKAGE) -> list[Path]:
    """The files of :data:`KERNEL_SOURCES` in ``package``, sorted."""
    return sorted({path for pattern in KERNEL_SOURCES for path in package.glob(pattern)})


@functools.cache
def kernel_sources_digest(package: Path = PACKAGE) -> str:
    """SHA-256 of the names and contents of :func:`kernel_sources` (read once per process), hexadecimal."""
    digest = hashlib.sha256()
    for path in kernel_sources(package):
        digest.update(path.relative_to(package).as_posix().encode() + b"\0" + path.read_bytes() + b"\0")
    return digest.hexdigest()


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
_queued: list[str] = []  # kernels waiting for a core (started by _start_what_fits)
_lock = threading.Lock()


def silence() -> None:
    """No notice from now on in this process (a command run with ``--quiet`` or ``--json``)."""
    global _silent
    _silent = True


def _say(message: str) -> None:
    if not _silent:
        print(f"screwkit: {message}", file=sys.stderr, flush=True)


_caching: bool | None = None
_caching_lock = threading.Lock()


def numba_cache() -> bool:
    """Decide, once per process, where numba caches compiled kernels; ``False``: compile without a cache.

    numba's own choice when it can write there: ``NUMBA_CACHE_DIR`` when set, else ``__pycache__``
    beside screwkit's sources, else ``$XDG_CACHE_HOME/numba`` (``~/.cache/numba``). Otherwise
    ``NUMBA_CACHE_DIR`` is set (for this process and the ones it starts) to
    ``screwkit-numba-UID`` in the temporary folder (``TMPDIR``), and if that cannot be written
    either, kernels compile on every run. A line on stderr says which.
    """
    global _caching
    with _caching_lock:
        if _caching is not None:
            return _caching
        package = Path(__file__).resolve().parent
        configured = os.environ.get("NUMBA_CACHE_DIR")
        user = _numba_user_cache()
        if configured:
            tried = [Path(configured)]
            _caching = writable(tried[0])
        else:
            tried = [package / "__pycache__", package / "closure" / "__pycache__"] + ([user] if user else [])
            _caching = all(writable(folder) for folder in tried[:2]) or (user is not None and writable(user))
        if _caching:
            return True
        fallback = private_temporary_folder("numba")
        places = ", ".join(str(folder) for folder in tried)
        if own_folder(fallback):
            os.environ["NUMBA_CACHE_DIR"] = str(fallback)
            config = sys.modules.get("numba.core.config")
            if config is not None:  # numba read the environment when it was imported
                config.CACHE_DIR = str(fallback)
            _caching = True
            _say(f"numba cannot write its cache in {places}; compiled kernels are cached in {fallback} "
                 "(set NUMBA_CACHE_DIR to choose)")
        else:
            _caching = False
            _say(f"numba cannot write its cache in {places} nor {fallback}: kernels are compiled on every run "
                 "(set NUMBA_CACHE_DIR to a writable folder)")
        return _caching


def _first_line(source: Path, function: str) -> int | None:
    """The line numba names the function's cache after: its first decorator (``co_firstlineno``)."""
    lines = source.read_text(encoding="utf-8").splitlines()
    for number, line in enumerate(lines):
        if line.startswith(f"def {function}("):
            while number > 0 and lines[number - 1].startswith("@"):
                number -= 1
            return number + 1
    return None


def _numba_user_cache() -> Path | None:
    """numba's user-wide cache folder (``$XDG_CACHE_HOME/numba``, ``~/.cache/numba``); None without a home."""
    home = user_cache_home()
    return home / "numba" if home is not None else None


def _cache_folders(source: Path) -> list[Path]:
    if os.environ.get("NUMBA_CACHE_DIR"):
        return [Path(os.environ["NUMBA_CACHE_DIR"])]
    user = _numba_user_cache()
    return [source.parent / "__pycache__"] + ([user] if user else [])


def kernel_is_cached(module: str) -> bool:
    """Whether numba's cache holds an index for the module's kernel entry (see :data:`KERNELS`) saved from the
    present sources: the index holds the stamp it was saved with, which names :func:`kernel_sources_digest` as
    text (:mod:`screwkit.common.jit`); an index of older sources is one numba will not use."""
    import importlib.util

    if not numba_cache():
        return False
    function, _ = KERNELS[module]
    spec = importlib.util.find_spec(module)
    if spec is None or spec.origin is None:
        return False
    source = Path(spec.origin)
    line = _first_line(source, function)
    name = f"{source.stem}.{function}-{line}.py{sys.version_info.major}{sys.version_info.minor}.nbi"
    digest = kernel_sources_digest().encode()
    for folder in _cache_folders(source):
        direct = folder / name
        found = [direct] if direct.is_file() else list(folder.rglob(name)) if folder.is_dir() else []
        for index in found:
            try:
                if digest in index.read_bytes():
                    return True
            except OSError:
                continue
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


def _cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # (not on every platform)
        return os.cpu_count() or 1


def _start(module: str) -> None:
    """One child process that imports ``module`` (compiling its kernel into numba's cache); with _lock held."""
    package_parent = str(Path(__file__).resolve().parents[1])
    path = os.pathsep.join(filter(None, [package_parent, os.environ.get("PYTHONPATH")]))
    try:
        _children[module] = subprocess.Popen(
            [sys.executable, "-c", f"import {module}"], env=dict(os.environ, PYTHONPATH=path),
            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    except OSError:  # no child (e.g. no process left): the import compiles the kernel in this process
        pass


def _start_what_fits() -> None:
    """Start queued kernels' children while fewer than the cores are compiling; with _lock held."""
    running = sum(child.poll() is None for child in _children.values())
    while _queued and running < _cores():
        _start(_queued.pop(0))
        running += 1


def _start_queued() -> None:
    """Start each queued kernel's child as soon as a core is free (a daemon thread)."""
    while True:
        time.sleep(0.05)
        with _lock:
            _start_what_fits()
            if not _queued:
                return


def compile_ahead(*modules: str) -> None:
    """Once per process and module: for the kernels numba's cache lacks, one line on stderr and, on a
    machine with more than one core, one child process per kernel that compiles it into the cache
    while this process goes on (:func:`prepare_kernels` waits for them), the longest first and no
    more at once than the cores. On one core they compile in this process, when first imported."""
    with _lock:
        missing = [module for module in modules if module not in _checked and not kernel_is_cached(module)]
        _checked.update(modules)
        if not missing:
            return
        cores = _cores()
        parallel = cores > 1 and numba_cache()  # children compile into the cache, for this process to load
        busy = sum(child.poll() is None for child in _children.values()) + len(_queued)
        if not _silent:
            names = ", ".join(KERNELS[module][0] for module in missing[:-1])
            names = f"{names} and {KERNELS[missing[-1]][0]}" if names else KERNELS[missing[-1]][0]
            seconds = _expected_seconds(missing, cores) if parallel else sum(KERNELS[m][1] for m in missing)
            where = f" in {min(len(missing), cores)} processes" if parallel and len(missing) > 1 else ""
            when = " as cores free up" if parallel and busy else ""
            print(f"screwkit: compiling {names}{where}{when} (first run only, about {seconds} s; `screwkit warmup` "
                  "compiles every kernel ahead)", file=sys.stderr, flush=True)
        if not parallel:
            return  # compiled here, when first imported
        _queued.extend(sorted(missing, key=lambda module: -KERNELS[module][1]))  # the longest first
        _start_what_fits()
        if _queued:
            threading.Thread(target=_start_queued, daemon=True).start()


def _expected_seconds(modules: list[str], cores: int) -> int:
    """About how long ``modules`` take to compile on ``cores`` processes, the longest first, each to
    the process free first."""
    ends = [0] * cores
    for module in sorted(modules, key=lambda module: -KERNELS[module][1]):
        ends[ends.index(min(ends))] += KERNELS[module][1]
    return max(ends)


def prepare_kernels(modules: tuple[str, ...] = INDEX_KERNELS) -> None:
    """Before the index kernels' modules are imported: start compiling those not cached
    (:func:`compile_ahead`) and wait for the child processes compiling them."""
    compile_ahead(*modules)
    for module in modules:
        while True:
            with _lock:
                _start_what_fits()
                if module not in _queued:
                    child = _children.get(module)
                    break
            time.sleep(0.05)  # waiting for a core
        if child is not None:
            child.wait()  # (thread-safe: every thread needing the kernel waits here)
            with _lock:
                _children.pop(module, None)


def stop_compiling() -> None:
    """End the children still compiling and forget the queued kernels: what a command that fails calls as it ends
    (before it needed its kernels), so that no compiler outlives it and competes with the next command for the cores
    (which, finding the kernels still missing from the cache, starts its own). numba writes a cache entry
    whole or not at all, so a child ended mid-way leaves the kernel missing, not broken."""
    with _lock:
        _queued.clear()
        for child in _children.values():
            if child.poll() is None:
                child.kill()
        for child in _children.values():
            child.wait()
        _children.clear()
