"""numba's ``njit`` for screwkit's compiled kernels, caching where :func:`screwkit.common.compiling.numba_cache`
decides (without a cache when no folder can be written), and never serving machine code older than its sources.

numba keeps a cached kernel while the stamp of the kernel's own source file is unchanged. A kernel here inlines
stages and helpers from other modules (:mod:`screwkit.indices.compiled.jacobi`, ``algebra``, ``actuators``, the
frames of :mod:`screwkit.closure.compiled`, the tolerances it reads as constants), so a change to one of those alone
would leave numba serving the machine code compiled from the old one: in an editable install updated by ``git
pull``, silently the old numbers. The cache locators installed here (numba's own, the same folders) add to that
stamp the digest of every source a kernel is compiled from
(:func:`~screwkit.common.compiling.kernel_sources_digest`), so any change to any of them compiles every kernel anew;
:func:`~screwkit.common.compiling.kernel_is_cached` reads the same digest in the index, so the first run after such a
change says it compiles, as a first run does.

Loading a cached kernel, numba first refreshes its whole CPU target: it imports every lowering registry it has
(arrays, linear algebra, random generators, typed containers, cffi's parser and, through the BLAS check,
``scipy.linalg``), about half a second of CPU, more than the rest of ``screwkit analyze``. Machine code read back
from the cache needs none of that: only the runtime's symbols (numba's NRT, for the arrays a kernel allocates)
and the hash secrets (for hashing) that the refresh also registers. :func:`install_lean_loads` makes a cache load
register just those; a kernel that must be compiled still refreshes the target first, as numba's compiler always
does. Set ``SCREWKIT_LEAN_KERNEL_LOADS=0`` for numba's own loading.
"""

from __future__ import annotations

import functools
import os
from pathlib import Path

from numba import njit as numba_njit

from screwkit.common.compiling import kernel_sources, kernel_sources_digest, numba_cache

__all__ = ["njit", "install_locators", "install_lean_loads"]

LEAN_NUMBA = ((0, 60), (0, 69))
"""The numba versions (from, before) whose cache loading :func:`install_lean_loads` knows (run on 0.68.1; the code
it replaces, ``Cache.load_overload``, and the runtime set-up it keeps read the same in 0.60.0): pyproject.toml's
bounds."""


@functools.cache
def _kernel_source_set() -> frozenset[Path]:
    return frozenset(kernel_sources())


def _is_kernel_source(py_file: str) -> bool:
    try:
        return Path(py_file).resolve() in _kernel_source_set()
    except OSError:
        return False


def _stamped(locator: type) -> type:
    """numba's cache ``locator`` for screwkit's kernels, its source stamp extended by the sources' digest."""

    class SourcesStamped(locator):
        screwkit_sources = True

        @classmethod
        def from_function(cls, py_func, py_file):
            return super().from_function(py_func, py_file) if _is_kernel_source(py_file) else None

        def get_source_stamp(self):
            return super().get_source_stamp(), kernel_sources_digest()

    SourcesStamped.__name__ = SourcesStamped.__qualname__ = f"SourcesStamped{locator.__name__}"
    return SourcesStamped


def install_locators() -> bool:
    """Put the stamped locators before numba's own (once); False if this numba has not the expected classes, in
    which case numba's own stamp (the kernel's file alone) applies."""
    from numba.core import caching

    implementation = getattr(caching, "CacheImpl", None)
    names = ("UserProvidedCacheLocator", "InTreeCacheLocator", "UserWideCacheLocator")
    bases = [getattr(caching, name, None) for name in names]
    classes = getattr(implementation, "_locator_classes", None)
    if classes is None or None in bases:
        return False
    if not any(getattr(locator, "screwkit_sources", False) for locator in classes):
        implementation._locator_classes = [*map(_stamped, bases), *classes]
    return True


def install_lean_loads() -> bool:
    """Make numba's cache loads register the runtime's symbols instead of refreshing the whole target (once);
    False, and numba's own loads, where ``SCREWKIT_LEAN_KERNEL_LOADS`` is ``0`` or for a numba version or layout
    this was not written for."""
    import numba
    from numba.core import caching

    if os.environ.get("SCREWKIT_LEAN_KERNEL_LOADS", "1") == "0":
        return False
    version = tuple(int(part) for part in numba.__version__.split(".")[:2] if part.isdigit())
    cache = getattr(caching, "Cache", None)
    if not LEAN_NUMBA[0] <= version < LEAN_NUMBA[1] or cache is None or not all(
            hasattr(cache, name) for name in ("load_overload", "_load_overload", "_guard_against_spurious_io_errors")):
        return False
    if getattr(cache.load_overload, "screwkit_lean", False):
        return True

    numbas_own = cache.load_overload

    def load_overload(self, sig, target_context):
        from numba.core.cpu import CPUContext
        from numba.core.runtime import nrt
        from numba.cpython import hashing  # noqa: F401  (registers the hash secrets' symbols)

        if not isinstance(target_context, CPUContext):  # another target (CUDA) in the same process: numba's own
            return numbas_own(self, sig, target_context)
        # numba's extension entry points are not initialised here (50 ms of scanning installed packages): screwkit's
        # kernels use no extension, and numba initialises them before any call it must compile
        nrt.rtsys.initialize(target_context)
        with self._guard_against_spurious_io_errors():
            return self._load_overload(sig, target_context)

    load_overload.screwkit_lean = True
    cache.load_overload = load_overload
    return True


install_locators()
install_lean_loads()


def njit(*args, **options):
    """``numba.njit``; ``cache=True`` caches where :func:`~screwkit.common.compiling.numba_cache` decides."""
    if options.get("cache") and not numba_cache():
        options["cache"] = False
    return numba_njit(*args, **options)
