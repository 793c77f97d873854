"""Loaded mechanisms kept on disk, so that reading a file read before takes neither Pinocchio nor the closure set-up.

Loading a file parses it, builds its Pinocchio tree (importing Pinocchio: about 0.1 s), reads its chains and
assembles it (solving its reference assembly, choosing each chain's closed form and working mode, finding its
mobility and task coordinates). :func:`load_cached` does that once: it keeps the mechanism's
:meth:`~screwkit.model.Mechanism.stored_state` (pickled, 20-50 kB) under a key made of

* the SHA-256 of the file's bytes (a changed file is another key),
* how it was read (the source name the messages use, the length unit, limits, the size limit),
* the code that read it (:func:`screwkit.common.caches.package_fingerprint`: screwkit's version and its
  sources), Python's and numpy's versions,

and reads it back on the next load of the same bytes the same way, in a few milliseconds; its Pinocchio tree
is built again only if something asks for it (the viewer). The folder is
:func:`screwkit.common.caches.cache_folder` ``("models")``: ``~/.cache/screwkit/models``, a private folder
in the temporary folder on a read-only install with no writable home, ``$SCREWKIT_CACHE_DIR/models`` when that
is set. Nothing here is ever an error: a folder that cannot be written, an entry that cannot be read (cut short,
written by another version of a library) or one that cannot be written (a full disk), and the file is simply
parsed as without a cache. At most :data:`MAX_ENTRIES` entries are kept, the least recently used removed first.
"""

from __future__ import annotations

import functools
import hashlib
import os
import pickle
import sys
import tempfile
from pathlib import Path
from typing import Callable

import numpy as np

from screwkit.common.caches import cache_folder, package_fingerprint
from screwkit.model.mechanism import Mechanism

__all__ = ["load_cached", "entry_path", "MAX_ENTRIES", "FORMAT"]

FORMAT = 1
"""The layout of an entry: a pickled dict ``{"format": FORMAT, "state": Mechanism.stored_state()}``."""

MAX_ENTRIES = 256
"""Entries kept in the folder (about 10 MB); when a new one is written beyond that, the least recently used go."""

_SUFFIX = ".mechanism"


@functools.cache
def _folder() -> Path | None:
    """The cache's folder, decided once per process (None: no cache)."""
    return cache_folder("models")


def entry_path(content: bytes, reading: tuple) -> Path | None:
    """Where the mechanism of ``content`` read as ``reading`` is kept (None: nowhere, no cache)."""
    folder = _folder()
    if folder is None:
        return None
    key = repr((FORMAT, package_fingerprint(), sys.version_info[:2], np.__version__,
                hashlib.sha256(content).hexdigest(), reading))
    return folder / (hashlib.sha256(key.encode()).hexdigest() + _SUFFIX)


def _read(path: Path) -> Mechanism | None:
    try:
        with open(path, "rb") as stream:
            entry = pickle.load(stream)
        if entry.get("format") != FORMAT:
            return None
        mechanism = Mechanism.from_stored_state(entry["state"])
    except Exception:  # missing, cut short, or written by other versions of the libraries: parse the file again
        return None
    try:
        os.utime(path)  # used: the last to be removed
    except OSError:
        pass
    return mechanism


def _write(path: Path, mechanism: Mechanism) -> None:
    """The entry, written whole or not at all (a temporary file renamed); then the least recently used entries
    beyond :data:`MAX_ENTRIES` removed."""
    try:
        data = pickle.dumps({"format": FORMAT, "state": mechanism.stored_state()}, protocol=pickle.HIGHEST_PROTOCOL)
    except Exception:  # something of a mechanism built in a notebook that cannot be pickled: not kept
        return
    temporary = None
    try:
        descriptor, temporary = tempfile.mkstemp(dir=path.parent, prefix=".", suffix=".tmp")
        with os.fdopen(descriptor, "wb") as stream:
            stream.write(data)
        os.replace(temporary, path)
        temporary = None
        entries = sorted(path.parent.glob("*" + _SUFFIX), key=_age)
        for old in entries[:max(0, len(entries) - MAX_ENTRIES)]:
            old.unlink(missing_ok=True)
    except OSError:  # a full disk, a folder made read-only meanwhile: not kept
        pass
    finally:
        if temporary is not None:
            Path(temporary).unlink(missing_ok=True)


def _age(path: Path) -> float:
    try:
        return path.stat().st_mtime
    except OSError:  # removed meanwhile by another process
        return 0.0


def load_cached(content: bytes | None, reading: tuple, build: Callable[[], Mechanism]) -> Mechanism:
    """The mechanism ``build()`` returns for a file of bytes ``content`` read as ``reading`` (a tuple of what
    else decides the result: source name, options), from the cache when it holds it, else built and kept.

    ``content`` None (a file not read, e.g. too large): built, not kept. Errors of ``build`` are raised as they
    are, and nothing is kept.
    """
    path = entry_path(content, reading) if content is not None else None
    if path is None:
        return build()
    mechanism = _read(path)
    if mechanism is not None:
        return mechanism
    mechanism = build()
    _write(path, mechanism)
    return mechanism
