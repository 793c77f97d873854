"""Writing results to files: one rule for every output, checked before any work, written atomically.

:func:`output_suffix` is the rule for an output's name: its suffix, compared without regard to case
(``M.NC`` is a netCDF file), decides what is written; the check before the work and the writer
after it both ask it. :func:`check_output` is called before a computation starts: it refuses an
unsupported suffix, a missing or read-only folder, and an existing file unless ``overwrite``; it
also removes the temporary files that an earlier run killed mid-write left behind (and says which).
:func:`check_distinct` refuses two options naming the same file. :func:`atomic_write` then writes
through a temporary file in the same folder, flushed to disk and renamed into place, so a reader
never sees a half-written file; a write that fails (disk full, quota, permission lost mid-run) is
one :class:`WriteError` line and leaves neither a partial file nor a temporary one.
"""

from __future__ import annotations

import glob
import os
import re
import time
from typing import Callable

from screwkit.studies.tables import wide_csv

__all__ = ["check_output", "check_distinct", "output_suffix", "write_dataset", "read_result", "open_netcdf",
           "atomic_write", "atomic_text", "save_figure", "WriteError", "DATA_SUFFIXES", "FIGURE_SUFFIXES", "FORMATS"]

DATA_SUFFIXES = (".nc", ".csv")
"""Data files screwkit writes: netCDF (``.nc``) or CSV, in any case."""
FIGURE_SUFFIXES = (".png", ".pdf", ".svg")
"""Figure files screwkit writes, in any case."""
FORMATS = tuple(suffix[1:] for suffix in FIGURE_SUFFIXES)
"""File types :func:`save_figure` writes."""
_TEMPORARY = re.compile(r"^\.(?P<name>.+)\.tmp-(?P<pid>\d+)(-\d+|\.\w+)$")
"""``.NAME.tmp-PID-NANOSECONDS`` (:func:`atomic_write`), or ``.ROOT.tmp-PID.SUFFIX``, the figures' temporary files
of screwkit 0.1 before every output shared one rule."""


class WriteError(OSError):
    """An output could not be written (disk full, quota, permission lost): the message is one line naming the
    file, and nothing of it was left behind."""


def output_suffix(path: str | os.PathLike, suffixes: tuple[str, ...], what: str = "output") -> str:
    """The suffix of ``path`` among ``suffixes``, in lower case, compared without regard to case.

    Raises
    ------
    ValueError
        ``path`` ends in none of them (the message names the path and the suffixes allowed).
    """
    path = os.fspath(path)
    for suffix in suffixes:
        if path.lower().endswith(suffix.lower()):
            return suffix.lower()
    found = os.path.splitext(path)[1]
    raise ValueError(f"{path}: the {what} file must end in {', '.join(suffixes)} (any case), got "
                     f"{repr(found) if found else 'no suffix'}.")


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
    name = os.path.basename(path)
    root, suffix = os.path.splitext(name)
    found = []
    for pattern in (f".{glob.escape(name)}.tmp-*", f".{glob.escape(root)}.tmp-*{glob.escape(suffix)}"):
        for candidate in glob.glob(os.path.join(glob.escape(folder), pattern)):
            match = _TEMPORARY.match(os.path.basename(candidate))
            if match and not _alive(int(match.group("pid"))) and candidate not in found:
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
    output_suffix(path, suffixes, what)
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


def _same_file(first: str, second: str) -> bool:
    if os.path.realpath(first) == os.path.realpath(second):
        return True
    try:
        return os.path.samefile(first, second)  # hard links, or names a case-insensitive folder takes as one
    except OSError:
        return False


def check_distinct(paths: dict[str, str | os.PathLike | None]) -> None:
    """Refuse two options that name the same file (``--state t.csv --table t.csv``): one would destroy the other.

    Raises
    ------
    ValueError
        One line naming both options and the file.
    """
    named = [(option, os.fspath(path)) for option, path in paths.items() if path is not None]
    for index, (option, path) in enumerate(named):
        for other, other_path in named[index + 1:]:
            if _same_file(path, other_path):
                raise ValueError(f"{option} {path} and {other} {other_path} name the same file: give each its own.")


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


def _remove_quietly(path: str) -> None:
    try:
        os.remove(path)
    except OSError:  # gone already, or the folder became read-only: a later run removes it (stale_temporaries)
        pass


def atomic_write(path: str | os.PathLike, write: Callable[[str], None]) -> None:
    """Call ``write(temporary)`` on a temporary file in the same folder, flush it to disk, rename it to ``path``.

    Raises
    ------
    WriteError
        The file could not be written (disk full, quota, the folder made read-only mid-run, ...):
        one line naming ``path``; the temporary file is removed and an existing ``path`` is untouched.
    """
    path = os.fspath(path)
    temporary = _temporary_name(path)
    try:
        write(temporary)
        descriptor = os.open(temporary, os.O_RDONLY)
        try:
            os.fsync(descriptor)  # on disk before it takes the name: a crash leaves the old file or the new one
        finally:
            os.close(descriptor)
        os.replace(temporary, path)
    except OSError as error:
        reason = error.strerror or (str(error).splitlines()[0] if str(error) else type(error).__name__)
        raise WriteError(f"Cannot write {path}: {reason}; no partial file was left"
                         f"{' and the earlier file is unchanged' if os.path.exists(path) else ''}.") from None
    finally:
        if os.path.exists(temporary):
            _remove_quietly(temporary)


def atomic_text(path: str | os.PathLike, text: str) -> None:
    """Write a text file atomically (temporary file in the same folder, then rename)."""

    def write(temporary):
        with open(temporary, "w", encoding="utf-8") as handle:
            handle.write(text)

    atomic_write(path, write)


def write_dataset(dataset, path) -> None:
    """Write a netCDF (``.nc``) or CSV file (the suffix in any case) atomically (:func:`atomic_write`).

    ``dataset`` is an ``xarray.Dataset``, a :class:`~screwkit.studies.maps.GridMap` or a
    :class:`~screwkit.studies.netcdf.PlainDataset` (both written without xarray). A CSV file is its wide table
    (:func:`screwkit.studies.tables.wide_csv`).
    """
    path = os.fspath(path)
    kind = output_suffix(path, DATA_SUFFIXES)
    if kind == ".csv":
        atomic_text(path, wide_csv(dataset))
    elif hasattr(dataset, "write_netcdf"):
        dataset.write_netcdf(path)
    else:
        atomic_write(path, lambda temporary: dataset.to_netcdf(temporary, engine="scipy"))


def open_netcdf(path: str, error: type[Exception] = ValueError):
    """The xarray Dataset of a netCDF file, loaded and closed; ``error`` with one line naming the file when it
    cannot be read as one."""
    import xarray as xr  # only where a netCDF file is read back

    try:
        with xr.open_dataset(path, engine="scipy") as dataset:
            return dataset.load()
    except MemoryError:
        raise
    except Exception as failure:  # whatever the netCDF reader makes of a file that is not one
        reason = str(failure).splitlines()[0] if str(failure) else type(failure).__name__
        reason = reason.removeprefix("Error: ")
        for named in (os.path.abspath(path), str(path)):  # scipy's words name it again, absolutely or as given
            if reason.startswith(f"{named} "):
                reason = "it " + reason[len(named) + 1:]
                break
        raise error(f"{path}: cannot be read as a netCDF file ({reason}).") from None


def read_result(path) -> tuple[str, object]:
    """A map, a sweep or a trajectory read back from the netCDF file :func:`write_dataset` wrote:
    ``("map" | "sweep" | "trajectory", dataset)``.

    A map's indices lie over two grid coordinates, a sweep's along one; a trajectory's along ``sample``, with the
    ``arc_length`` coordinate and the JSON ``summary`` attribute (``screwkit trajectory --out``).

    Raises
    ------
    ValueError
        One line naming the file: missing, a folder, not a netCDF file, or not a map or sweep of screwkit.
    """
    path = os.fspath(path)
    if os.path.isdir(path):
        raise ValueError(f"{path}: is a folder; expected the netCDF file (.nc) of a map or a sweep.")
    if not os.path.isfile(path):
        raise ValueError(f"{path}: no such file.")
    if not path.lower().endswith(".nc"):
        raise ValueError(f"{path}: expected the netCDF file (.nc) of a map or a sweep (screwkit map/sweep --out "
                         "FILE.nc).")
    dataset = open_netcdf(path)
    dimensions = dataset["iti"].ndim if "iti" in dataset.data_vars else 0
    if dimensions == 1 and dataset["iti"].dims == ("sample",) and "arc_length" in dataset.coords \
            and "summary" in dataset.attrs:  # indices along a path: screwkit trajectory --out FILE.nc
        return "trajectory", dataset
    if dimensions == 1 and dataset["iti"].dims == ("sample",):  # samples of a path, not a swept coordinate
        raise ValueError(f"{path}: holds indices along a path (over 'sample') without the arc length and summary "
                         "that `screwkit trajectory --out` writes; draw its figure with `screwkit trajectory ... "
                         "--figure FILE`.")
    if "lmti" not in dataset.data_vars or dimensions not in (1, 2):
        raise ValueError(f"{path}: not a map or a sweep of screwkit (expected 'iti' and 'lmti' over one or two "
                         f"coordinates, got variables {', '.join(sorted(map(str, dataset.data_vars))) or 'none'}).")
    return ("map" if dimensions == 2 else "sweep"), dataset


def save_figure(figure, path, *, dpi: float = 130) -> None:
    """Save a figure as PNG, PDF or SVG, atomically (:func:`atomic_write`).

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
        If the suffix is not one of :data:`FIGURE_SUFFIXES` (the message names the path).
    WriteError
        If the file cannot be written.
    """
    kind = output_suffix(path, FIGURE_SUFFIXES, "figure")[1:]
    atomic_write(path, lambda temporary: figure.savefig(temporary, format=kind, dpi=dpi, bbox_inches="tight",
                                                        pad_inches=0.05))
