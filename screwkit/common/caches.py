"""Where screwkit keeps what it computes once for later runs: numba's compiled kernels and loaded mechanisms.

Both go to a folder this user can write, found the same way: the user's cache folder
(``$XDG_CACHE_HOME``, else ``~/.cache``) when it can be written; else, on a read-only install with no
writable home, a folder of this user alone in the temporary folder (``TMPDIR``), ``screwkit-NAME-UID``;
else nowhere. :func:`screwkit.common.compiling.numba_cache` places numba's cache with these helpers, and
:func:`cache_folder` gives screwkit's own caches a folder (``SCREWKIT_CACHE_DIR`` when set).

:func:`package_fingerprint` names the code that wrote a cached entry: screwkit's version and its
sources, so that an entry written by other code is never read back.
"""

from __future__ import annotations

import functools
import hashlib
import os
import sys
import tempfile
from pathlib import Path

__all__ = ["user_cache_home", "writable", "own_folder", "private_temporary_folder", "cache_folder",
           "package_fingerprint"]


def user_cache_home() -> Path | None:
    """The user's cache folder (``$XDG_CACHE_HOME``, ``~/.cache``); None without a home."""
    try:
        return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    except RuntimeError:  # no HOME and no entry in the password database
        return None


def writable(folder: Path) -> bool:
    """Whether files can be made in ``folder`` (created if missing), as numba tests its cache folders."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
        tempfile.TemporaryFile(dir=folder).close()
    except OSError:
        return False
    return True


def own_folder(folder: Path) -> bool:
    """Whether ``folder`` (created if missing) is writable by this user alone: in a shared temporary folder,
    what is found there is loaded (numba's kernels, pickled mechanisms), so nobody else may put it there."""
    try:
        folder.mkdir(mode=0o700, exist_ok=True)
        status = folder.stat()
    except OSError:
        return False
    return status.st_uid == os.getuid() and not status.st_mode & 0o022 and writable(folder)


def private_temporary_folder(name: str) -> Path:
    """``screwkit-NAME-UID`` in the temporary folder (``TMPDIR``), not created here."""
    try:
        temporary = tempfile.gettempdir()
    except OSError:  # no usable temporary folder at all
        temporary = os.environ.get("TMPDIR") or "/tmp"
    return Path(temporary) / f"screwkit-{name}-{os.getuid()}"


def cache_folder(name: str) -> Path | None:
    """A writable folder for screwkit's cache ``name``, or None when there is none (then nothing is cached).

    ``$SCREWKIT_CACHE_DIR/NAME`` when that variable is set, else ``screwkit/NAME`` in the user's cache folder
    (``~/.cache/screwkit/NAME``), else :func:`private_temporary_folder`; None if the chosen folder cannot be
    written (``SCREWKIT_CACHE_DIR`` set to a read-only folder turns the cache off).
    """
    configured = os.environ.get("SCREWKIT_CACHE_DIR")
    if configured:
        folder = Path(configured) / name
        return folder if writable(folder) else None
    home = user_cache_home()
    if home is not None and writable(home / "screwkit" / name):
        return home / "screwkit" / name
    fallback = private_temporary_folder(name)
    return fallback if own_folder(fallback) else None


@functools.cache
def package_fingerprint() -> str:
    """screwkit's version and the name, size and modification time of each of its sources, hashed: changes with
    any edit of the code (an editable install) as well as with the version (an installed one)."""
    package = Path(__file__).resolve().parents[1]
    sources = []
    for folder, folders, files in os.walk(package):
        folders[:] = [name for name in folders if name != "__pycache__"]
        for name in files:
            if name.endswith(".py"):
                status = os.stat(os.path.join(folder, name))
                sources.append(f"{os.path.relpath(os.path.join(folder, name), package)}:{status.st_size}:"
                               f"{status.st_mtime_ns}")
    version = sys.modules["screwkit"].__version__  # (the package is imported before any of its modules)
    return hashlib.sha256("\n".join([version, *sorted(sources)]).encode()).hexdigest()
