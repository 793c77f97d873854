"""Writing results to files: netCDF or CSV, atomically, with the output checked before any work.

:func:`check_output` is called before a computation starts: it refuses an unsupported suffix,
a missing or read-only folder, and an existing file unless ``overwrite``; it also removes the
temporary files that an earlier run killed mid-write left behind (and says which).
:func:`write_dataset` then writes through a temporary file in the same folder, renamed into
place, so a reader never sees a half-written file.
"""

from __future__ import annotations

import glob
import os
import re
import time
from typing import Callable

__all__ = ["check_output", "write_dataset", "atomic_write", "atomic_text", "save_figure", "DATA_SUFFIXES",
           "FIGURE_SUFFIXES", "FORMATS"]

DATA_SUFFIXES = (".nc", ".csv")
"""Data files screwkit writes: netCDF (``.nc``) or CSV."""
FIGURE_SUFFIXES = (".png", ".pdf", ".svg")
"""Figure files screwkit writes."""
FORMATS = ("png", "pdf", "svg")
"""File types :func:`save_figure` writes."""
_TEMPORARY = re.compile(r"^\.(?P<name>.+)\.tmp-(?P<pid>\d+)-\d+$")


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def stale_temporaries(path: str | os.PathLike) -> list[str]:
    """Temporary files of earlier writes of ``path`` whose process is gone (killed mid-write)."""
    path = os.fspath(path)
    folder = os.path.dirname(os.path.abspath(path))
    found = []
    for candidate in glob.glob(os.path.join(glob.escape(folder), f".{glob.escape(os.path.basename(path))}.tmp-*")):
        match = _TEMPORARY.match(os.path.basename(candidate))
        if match and not _alive(int(match.group("pid"))):
            found.append(candidate)
    return found


def check_output(path: str | os.PathLike, suffixes: tuple[str, ...], *, overwrite: bool = False,
                 what: str = "output") -> list[str]:
    """Check, before any computation, that ``path`` can be written; return stale temporary files removed.

    Raises
    ------
    ValueError
        One line naming the path and the problem: an unsupported suffix, a missing folder, a
        folder that cannot be written, a path that is a folder, or an existing file without
        ``overwrite`` (or a read-only one).
    """
    path = os.fspath(path)
    if not path.lower().endswith(suffixes):
        raise ValueError(f"{path}: the {what} file must end in {', '.join(suffixes)}.")
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        raise ValueError(f"{path}: the folder {folder} does not exist.")
    if os.path.isdir(path):
        raise ValueError(f"{path}: is a folder, not a file.")
    if os.path.exists(path):
        if not overwrite:
            raise ValueError(f"{path}: the file exists; pass --overwrite to replace it.")
        # No write bit for anyone also counts for root, whom os.access lets write anything.
        if not os.stat(path).st_mode & 0o222 or not os.access(path, os.W_OK):
            raise ValueError(f"{path}: the file exists and is read-only.")
    _check_folder_writable(path, folder)
    removed = []
    for stale in stale_temporaries(path):
        try:
            os.remove(stale)
            removed.append(stale)
        except OSError:
            pass
    return removed


def _temporary_name(path: str) -> str:
    """A temporary file beside ``path``: ``.NAME.tmp-PID-NANOSECONDS`` (see :func:`stale_temporaries`)."""
    return os.path.join(os.path.dirname(os.path.abspath(path)),
                        f".{os.path.basename(path)}.tmp-{os.getpid()}-{time.time_ns()}")


def _check_folder_writable(path: str, folder: str) -> None:
    """Create and remove a temporary file as a write would: the one sure test (os.access also says yes for
    an immutable folder or one like /proc, which holds no new files)."""
    probe = _temporary_name(path)
    try:
        os.close(os.open(probe, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600))
    except OSError as error:
        raise ValueError(f"{path}: cannot write in the folder {folder} ({error.strerror or error}).") from None
    os.remove(probe)


def atomic_write(path: str | os.PathLike, write: Callable[[str], None]) -> None:
    """Call ``write(temporary)`` on a temporary file in the same folder, then rename it to ``path``."""
    path = os.fspath(path)
    temporary = _temporary_name(path)
    try:
        write(temporary)
        os.replace(temporary, path)
    finally:
        if os.path.exists(temporary):
            os.remove(temporary)


def atomic_text(path: str | os.PathLike, text: str) -> None:
    """Write a text file atomically (temporary file in the same folder, then rename)."""

    def write(temporary):
        with open(temporary, "w", encoding="utf-8") as handle:
            handle.write(text)

    atomic_write(path, write)


def wide_table(dataset):
    """A dataset as one row per point of the dimensions every variable shares, one column per series.

    Variables over exactly those dimensions are columns (a sweep's ``phi``; a map's ``y`` and
    ``x``); a variable with one more dimension (e.g. the ITI per actuator) gives one column per
    label, ``iti_actuator[chain_1:joint]``.
    """
    import pandas as pd

    shared = [d for d in dataset.dims if all(d in dataset[v].dims for v in dataset.data_vars)]
    if not shared:
        raise ValueError(f"Cannot write a table: the variables share no dimension ({dict(dataset.sizes)}).")
    frame = dataset[[v for v in dataset.data_vars if set(dataset[v].dims) == set(shared)]].to_dataframe()
    frame = frame.reset_index()
    columns = {}
    for name in dataset.data_vars:
        extra = [d for d in dataset[name].dims if d not in shared]
        if len(extra) == 1:
            for label in dataset[extra[0]].values:
                columns[f"{name}[{label}]"] = dataset[name].sel({extra[0]: label}).transpose(*shared).values.ravel()
    return pd.concat([frame, pd.DataFrame(columns)], axis=1)


def write_dataset(dataset, path) -> None:
    """Write a netCDF (``.nc``) or CSV file atomically: a temporary file in the same folder, then rename.

    ``dataset`` is an ``xarray.Dataset`` or a :class:`~screwkit.studies.maps.GridMap` (written
    to netCDF without xarray).
    """
    path = os.fspath(path)
    if not path.endswith(DATA_SUFFIXES):
        raise ValueError(f"{path}: the output file must end in {', '.join(DATA_SUFFIXES)}.")
    if hasattr(dataset, "write_netcdf"):
        if path.endswith(".nc"):
            dataset.write_netcdf(path)
            return
        dataset = dataset.to_dataset()
    if path.endswith(".csv"):
        atomic_write(path, lambda temporary: wide_table(dataset).to_csv(temporary, index=False))
    else:
        atomic_write(path, lambda temporary: dataset.to_netcdf(temporary, engine="scipy"))


def save_figure(figure, path, *, dpi: float = 130) -> None:
    """Save a figure as PNG, PDF or SVG, atomically (a temporary file in the same folder, then rename).

    The bounding box is tight (``bbox_inches="tight"``), so nothing drawn outside the
    figure's nominal area (a long title, a legend, a colour-bar label) is cut off.

    Parameters
    ----------
    figure : matplotlib.figure.Figure
        The figure to save.
    path : str or os.PathLike
        Output file; its suffix (``.png``, ``.pdf`` or ``.svg``, any case) picks the format.
    dpi : float
        Resolution of PNG files and of rasterised map panels in PDF and SVG files.

    Raises
    ------
    ValueError
        If the suffix is not one of :data:`FORMATS` (the message names the path).
    """
    path = os.fspath(path)
    root, extension = os.path.splitext(path)
    kind = extension[1:].lower()
    if kind not in FORMATS:
        found = repr(extension) if extension else "no suffix"
        raise ValueError(f"Cannot save a figure to {path!r}: expected a file ending in "
                         f"{', '.join('.' + f for f in FORMATS[:-1])} or .{FORMATS[-1]}, got {found}.")
    folder = os.path.dirname(os.path.abspath(path))
    temporary = os.path.join(folder, f".{os.path.basename(root)}.tmp-{os.getpid()}.{kind}")
    try:
        figure.savefig(temporary, format=kind, dpi=dpi, bbox_inches="tight", pad_inches=0.05)
        os.replace(temporary, path)
    finally:
        if os.path.exists(temporary):
            os.remove(temporary)
