"""Paths of the platform: samples of task coordinates, their arc length, points between samples, path files.

A path is a sequence of poses (task coordinates, m and rad) joined by straight segments *in task
coordinates*: between two samples every coordinate varies linearly, angles included (no wrapping:
350 deg to 10 deg turns back through 180 deg; write 370 deg to turn forward). Its length is
measured in the same coordinates, angles weighted by the mechanism's length scale ``L``
(:attr:`screwkit.model.Mechanism.length_scale`, m), as closure solving weighs them:

.. math::

    s_{i+1} - s_i = \\sqrt{\\lVert \\Delta \\mathbf{p} \\rVert^2 + L^2 \\lVert \\Delta \\boldsymbol{\\theta} \\rVert^2}

so the arc length is in metres, a pure rotation has a length, and a mechanism scaled by ``k`` has
every arc length scaled by ``k``. :meth:`Path.at` gives the pose at any arc length on that
piecewise-linear path, which is where the refinement of :mod:`screwkit.studies.trajectory` evaluates.

:func:`line_path`, :func:`circle_path` and :func:`through_path` (piecewise linear through given poses)
generate paths; :func:`read_path` reads a CSV or netCDF file (angles in degrees and lengths in metres unless a
netCDF variable's ``units`` says otherwise) and says in one line what is wrong with it (:func:`read_columns`, which
also reads the actuator values of :mod:`~screwkit.studies.actuator_paths`). :func:`checked_tolerance` is the range of
refinement tolerances a path can honour.
"""

from __future__ import annotations

import csv
import io
import math
import os
import warnings
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.common.units import LENGTH_UNITS, angle_beyond_limit, angle_limit, is_angular
from screwkit.model import Mechanism
from screwkit.studies.files import open_netcdf

__all__ = ["Path", "path_from_poses", "line_path", "circle_path", "through_path", "read_path", "read_columns",
           "PathFileError", "TIME_COLUMN", "checked_times", "checked_tolerance", "ANGLE_UNITS", "TIME_UNITS",
           "weighted_arc_length", "ARC_LENGTH_NAMES", "ARC_LENGTH_WAYS"]

ARC_LENGTH_WAYS = {False: "in task coordinates", True: "along the actuators"}
"""How the arc length is measured (by :attr:`Path.along_actuators`), as a trajectory's summary says it (its
``arc_length``)."""
ARC_LENGTH_NAMES = {False: "arc length", True: f"arc length {ARC_LENGTH_WAYS[True]}"}
"""The ``long_name`` of a path file's ``arc_length`` and its figure's axis (a figure drawn again from the file reads
it)."""

TIME_COLUMN = "t"
"""The optional column (CSV) or variable (netCDF) of a path file holding the time of each sample (s)."""

ANGLE_UNITS = {"deg": math.pi / 180, "degree": math.pi / 180, "degrees": math.pi / 180,
               "rad": 1.0, "radian": 1.0, "radians": 1.0}
"""The ``units`` a netCDF path variable of an angle may have (any case), as radians per unit; none is deg."""

TIME_UNITS = {"s": 1.0, "sec": 1.0, "second": 1.0, "seconds": 1.0}
"""The ``units`` the :data:`TIME_COLUMN` variable of a netCDF path may have; none is s."""

ROUNDING_ULPS = 64
"""Units in the last place of a path's size (its poses', or the mechanism's length scale if larger) within which
its length counts as zero (rounding, as of a circle of two samples), and of its arc length below which no
refinement tolerance can be honoured."""


class PathFileError(ValueError):
    """A path file that cannot be used: the message is one line naming the file and what is wrong."""


@dataclass(frozen=True)
class Path:
    """A sampled path of a mechanism's platform.

    Attributes
    ----------
    poses : ndarray (n, n_task)
        The samples, task coordinates in m and rad.
    arc_length : ndarray (n,)
        Arc length at each sample from the first (m; angles weighted by ``length_scale``), non-decreasing; of a
        path driven by the actuators (:mod:`~screwkit.studies.actuator_paths`), along the actuators' values.
    length_scale : float
        The weight of angles in the arc length (m per rad): the mechanism's length scale.
    times : ndarray (n,) or None
        The time of each sample (s), increasing, when the path has them.
    actuators : ndarray (n, a) or None
        Of a path driven by the mechanism's actuators (:func:`~screwkit.studies.actuator_paths.path_from_actuators`):
        their values (rad, m) at each sample, along which the arc length is measured.
    configurations : ndarray (n, nq) or None
        Of a mechanism whose legs have loops inside them so driven: the closed configuration the actuators reach at
        each sample, from which the path is analysed (between samples, the actuators move linearly along each
        segment).
    """

    poses: NDArray[np.float64]
    arc_length: NDArray[np.float64]
    length_scale: float
    times: NDArray[np.float64] | None = None
    actuators: NDArray[np.float64] | None = None
    configurations: NDArray[np.float64] | None = None

    @property
    def length(self) -> float:
        """The path's length (m)."""
        return float(self.arc_length[-1])

    @property
    def along_actuators(self) -> bool:
        """Whether the arc length is along the actuators (a path driven by them), not in task coordinates."""
        return self.actuators is not None

    @property
    def samples(self) -> int:
        return int(self.poses.shape[0])

    def at(self, arc_length: ArrayLike) -> NDArray[np.float64]:
        """The poses (..., n_task) at arc lengths (...) on the piecewise-linear path (clipped to its ends)."""
        segment, fraction = self.located(arc_length)
        first, second = self.poses[segment], self.poses[segment + 1]
        return first + fraction[..., None] * (second - first)

    def located(self, arc_length: ArrayLike) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
        """The segment (the sample it starts at) and the fraction of it (0 on a segment of no length) of each arc
        length (...), clipped to the path's ends."""
        wanted = np.clip(np.asarray(arc_length, dtype=float), 0.0, self.length)
        segment = np.clip(np.searchsorted(self.arc_length, wanted, side="right") - 1, 0, self.samples - 2)
        start, stop = self.arc_length[segment], self.arc_length[segment + 1]
        span = stop - start
        return segment, np.where(span > 0, (wanted - start) / np.where(span > 0, span, 1.0), 0.0)

    def time_at(self, arc_length: ArrayLike) -> NDArray[np.float64] | None:
        """The times at arc lengths, linear along each segment; None for a path without times."""
        if self.times is None:
            return None
        return np.interp(arc_length, self.arc_length, self.times)


def path_from_poses(mechanism: Mechanism, poses: ArrayLike, times: ArrayLike | None = None,
                    where: str = "`poses`") -> Path:
    """A :class:`Path` through ``poses`` (n, n_task; m, rad), checked: at least two samples, finite and within the
    mechanism's reach of angles and positions (:meth:`~screwkit.model.Mechanism.check_poses`, naming ``where`` they
    came from), a length above the rounding of the poses and of the length scale (:data:`ROUNDING_ULPS`),
    ``times`` (n,) increasing when given."""
    poses = mechanism.check_poses(poses, where=where)
    if poses.ndim != 2 or poses.shape[0] < 2:
        raise ValueError(f"Expected a path of at least 2 poses with shape (n, {mechanism.n_task}), got "
                         f"{poses.shape}.")
    arc_length, size = weighted_arc_length(poses, mechanism.angular, mechanism.length_scale)  # (finite: in reach)
    if not arc_length[-1] > 0:
        raise ValueError("Expected a path that moves: every pose of the path is the same.")
    if arc_length[-1] <= ROUNDING_ULPS * np.spacing(size):
        raise ValueError(f"Expected a path that moves: every pose of the path is the same to rounding (a length of "
                         f"{arc_length[-1]:.3g} m, at a size of {size:.3g} m: its poses' or the mechanism's length "
                         "scale).")
    return Path(poses, arc_length, float(mechanism.length_scale), checked_times(times, poses.shape[0]))


def weighted_arc_length(samples: NDArray, angular: NDArray, length_scale: float) -> tuple[NDArray, float]:
    """The arc length (n,) through ``samples`` (n, k), angles (``angular``) weighted by ``length_scale``, and the
    size its rounding is taken at (the largest weighted sample, at least the length scale)."""
    weights = np.where(angular, length_scale, 1.0)
    steps = np.linalg.norm(np.diff(samples, axis=0) * weights, axis=1)
    return (np.concatenate([[0.0], np.cumsum(steps)]),
            max(float(np.max(np.abs(samples * weights))), float(length_scale)))


def checked_tolerance(path: Path, tolerance: float, name: str = "`tolerance`") -> float:
    """``tolerance`` (m of arc length) as a float, if the refinement along ``path`` can honour it: at least
    :data:`ROUNDING_ULPS` units in the last place of its arc length (rounded up to 3 digits), below its length;
    else a ValueError naming ``name`` and that range."""
    low = ROUNDING_ULPS * float(np.spacing(path.length))
    digit = 10.0 ** (math.floor(math.log10(low)) - 2)
    low = math.ceil(low / digit) * digit  # as the message shows it
    try:
        tolerance = float(tolerance)
    except (TypeError, ValueError):
        raise ValueError(f"Expected {name} to be a number (m of arc length), got {tolerance!r}.") from None
    if not (np.isfinite(tolerance) and low <= tolerance < path.length):
        raise ValueError(f"Expected {name} from {low:.3g} m (the rounding of the arc length) to below the path's "
                         f"length, {path.length:.6g} m, got {tolerance:g}.")
    return tolerance


def checked_times(times: ArrayLike | None, count: int) -> NDArray[np.float64] | None:
    """``times`` (s) as floats, one per pose of ``count``, finite and increasing; None for None."""
    if times is None:
        return None
    times = np.asarray(times, dtype=float)
    if times.shape != (count,):
        raise ValueError(f"Expected one time per pose ({count}), got shape {times.shape}.")
    if not np.all(np.isfinite(times)) or np.any(np.diff(times) <= 0):
        raise ValueError("Expected finite, increasing times along the path.")
    return times


def _check_samples(samples: int) -> None:
    """A ValueError for ``samples`` that is not a whole number >= 2 (a float, a string, a bool: not a count)."""
    if isinstance(samples, (bool, np.bool_)) or not isinstance(samples, (int, np.integer)) or samples < 2:
        raise ValueError(f"Expected `samples`: at least 2 samples on a path, a whole number, got {samples!r}.")


def line_path(mechanism: Mechanism, start: ArrayLike, stop: ArrayLike, samples: int) -> Path:
    """``samples`` poses evenly spaced on the straight segment from ``start`` to ``stop`` (task coordinates, m
    and rad), both included."""
    _check_samples(samples)
    start, stop = mechanism.check_poses(start), mechanism.check_poses(stop)
    fractions = np.linspace(0.0, 1.0, samples)[:, None]
    return path_from_poses(mechanism, start + fractions * (stop - start))


def circle_path(mechanism: Mechanism, centre: ArrayLike, radius: float, samples: int) -> Path:
    """``samples`` poses on the circle of ``radius`` (m) about ``centre`` (task coordinates) in the x-y plane of
    the task coordinates, the other coordinates fixed at the centre's; a full turn from ``+x``, counter-clockwise,
    the first pose repeated at the end."""
    _check_samples(samples)
    names = mechanism.task_coordinates
    if "x" not in names or "y" not in names:
        raise ValueError(f"A circle lies in the x-y plane; {mechanism.name!r} has task coordinates "
                         f"{', '.join(names)}.")
    if not (math.isfinite(radius) and radius > 0):
        raise ValueError(f"Expected a circle radius > 0 (m), got {radius:g}.")
    centre = mechanism.check_poses(centre)
    angle = np.linspace(0.0, 2 * np.pi, samples)
    poses = np.repeat(centre[None], samples, axis=0)
    poses[:, names.index("x")] += radius * np.cos(angle)
    poses[:, names.index("y")] += radius * np.sin(angle)
    return path_from_poses(mechanism, poses)


def through_path(mechanism: Mechanism, poses: ArrayLike, samples: int) -> Path:
    """The piecewise-linear path through ``poses`` (k >= 2, (k, n_task); m, rad), straight in task coordinates
    between consecutive poses: ``samples`` points evenly spaced in arc length over the whole path, and every pose
    given (its corners are samples)."""
    _check_samples(samples)
    corners = path_from_poses(mechanism, poses)
    return path_from_poses(mechanism, corners.at(np.union1d(np.linspace(0.0, corners.length, samples),
                                                            corners.arc_length)))


def read_path(mechanism: Mechanism, path: str | os.PathLike) -> Path:
    """A path from a CSV or netCDF file: a column (variable) per task coordinate of ``mechanism`` (m, and deg
    for angles; a netCDF variable in the ``units`` it names) and an optional :data:`TIME_COLUMN` (s).

    Other columns are ignored (so the output of ``screwkit trajectory --out`` reads back as a path).

    Raises
    ------
    PathFileError
        One line naming the file: what :func:`read_columns` refuses, a pose beyond the mechanism's reach, a path
        that does not move, times not increasing.
    """
    name = os.fspath(path)
    wanted = mechanism.task_coordinates
    poses, times = read_columns(name, wanted, [is_angular(c) for c in wanted],
                                f"a path of {mechanism.name!r} has columns {', '.join(wanted)} (m, deg)")
    try:
        return path_from_poses(mechanism, poses, times, where="the file")
    except ValueError as error:
        raise PathFileError(f"{name}: {error}") from None


def read_columns(name: str, wanted, angular, expected: str) -> tuple[NDArray[np.float64], NDArray | None]:
    """The columns ``wanted`` of a CSV or netCDF path file (n, k), angles (``angular``) read in deg and lengths
    in m (a netCDF variable in its ``units``: :data:`ANGLE_UNITS`, :data:`~screwkit.common.units.LENGTH_UNITS`) and
    returned in rad and m, and the :data:`TIME_COLUMN` (s) if there is one. ``expected`` says what a path has (for
    the message on a missing column).

    Raises
    ------
    PathFileError
        One line naming the file: missing, a folder, an unknown suffix, unreadable, a column missing or named
        twice, variables of different lengths, units unknown, a value that is not a finite number, an angle beyond
        :func:`~screwkit.common.units.angle_limit`, fewer than two samples.
    """
    if os.path.isdir(name):
        raise PathFileError(f"{name}: is a folder, not a path file (.csv or .nc).")
    if not os.path.isfile(name):
        raise PathFileError(f"{name}: no such file.")
    suffix = os.path.splitext(name)[1].lower()
    if suffix not in (".csv", ".nc"):
        raise PathFileError(f"{name}: a path file must end in .csv or .nc, got {suffix or 'no suffix'!r}.")
    columns = _read_netcdf(name, wanted) if suffix == ".nc" else _read_csv(name, (*wanted, TIME_COLUMN))
    missing = [column for column in wanted if column not in columns]
    if missing:
        raise PathFileError(f"{name}: no column {', '.join(repr(m) for m in missing)}; {expected} and optionally "
                            f"{TIME_COLUMN!r} (s), got {', '.join(columns) or 'none'}.")
    used = [column for column in (*wanted, TIME_COLUMN) if column in columns]
    lengths = {column: columns[column][0].size for column in used}
    if len(set(lengths.values())) > 1:
        raise PathFileError(f"{name}: variables of different lengths ("
                            + ", ".join(f"{column!r} {size}" for column, size in lengths.items())
                            + " samples); a path has one value of each per sample.")
    factors = [_unit_factor(name, column, columns[column][1], bool(a)) for column, a in zip(wanted, angular)]
    for column in used:
        if columns[column][2]:
            raise PathFileError(f"{name}: {columns[column][2]}")
    values = np.column_stack([columns[c][0] for c in wanted]) * factors
    if values.shape[0] < 2:
        raise PathFileError(f"{name}: {values.shape[0]} sample(s); a path needs at least 2.")
    for k, (column, a) in enumerate(zip(wanted, angular)):
        beyond = np.flatnonzero(np.abs(values[:, k]) > angle_limit(degrees=False)) if a else ()
        if len(beyond):
            degrees = factors[k] != 1.0
            error = angle_beyond_limit(f"{'variable' if suffix == '.nc' else 'column'} {column!r} (sample "
                                       f"{beyond[0]})", values[beyond[0], k] / factors[k], degrees=degrees)
            raise PathFileError(f"{name}: {error}")
    if TIME_COLUMN not in columns:
        return values, None
    return values, columns[TIME_COLUMN][0] * _unit_factor(name, TIME_COLUMN, columns[TIME_COLUMN][1], None)


_METRES = {"meter": 1.0, "meters": 1.0, "metre": 1.0, "metres": 1.0}


def _unit_factor(name: str, column: str, unit: str, angular: bool | None) -> float:
    """What a value of a netCDF variable with ``units`` ``unit`` is in rad (``angular``), m, or s (``angular``
    None, the time); none is deg, m or s. A PathFileError naming the variable for units of something else."""
    spelled = unit.strip()
    if angular is None:
        factor, expected = (TIME_UNITS.get(spelled.lower()) if spelled else 1.0), "s (a time)"
    elif angular:
        factor = ANGLE_UNITS.get(spelled.lower()) if spelled else math.pi / 180
        expected = "deg or rad (an angle; or degrees, radians)"
    else:
        factor = {**LENGTH_UNITS, **_METRES}.get(spelled) if spelled else 1.0
        expected = f"a length unit ({', '.join(LENGTH_UNITS)})"
    if factor is None:
        raise PathFileError(f"{name}: variable {column!r} has units {unit!r}; expected {expected}, or no units.")
    return factor


def _read_csv(name: str, wanted) -> dict[str, tuple[NDArray[np.float64] | None, str, str]]:
    """The columns ``wanted`` of a CSV file (the others by name only): their numbers, no unit, and what is wrong
    with their first value that is not a finite number ("" if none). A file of plain numbers is read by numpy's
    parser; anything else (quotes, a cell missing or not a number) cell by cell, to say where.

    A file of plain numbers with ``\n`` line ends is read straight from the file by both parsers
    (:func:`_read_plain_csv`: the same characters, so the same numbers, without two copies of its text in memory:
    0.1 s for a path of 100,000 samples); any other file, or one that does not read so, as a whole text
    (:func:`_read_csv_text`)."""
    plain = _read_plain_csv(name, wanted)
    return plain if plain is not None else _read_csv_text(name, wanted)


def _read_plain_csv(name: str, wanted) -> dict[str, tuple[NDArray[np.float64], str, str]] | None:
    """:func:`_read_csv_text` for a file that it reads with numpy's parser, without its text in memory; None for
    any other file (a ``\r``, a header that is not on the first non-blank line, cells that are not all finite
    numbers, a file that is not UTF-8 or not CSV: :func:`_read_csv_text` says what is wrong)."""
    try:
        with open(name, "rb") as raw:
            if b"\r" in raw.read():
                return None
        with open(name, newline="", encoding="utf-8-sig") as handle:  # a byte-order mark (Excel) skipped
            header, skipped = None, 0
            for row in csv.reader(handle):
                skipped += 1
                if any(cell.strip() for cell in row):
                    header = [cell.strip() for cell in row]
                    break
            if header is None or _doubled(header, wanted):
                return None
            positions = {column: position for position, column in enumerate(header) if column in wanted}
            handle.seek(0)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                table = np.loadtxt(handle, delimiter=",", skiprows=skipped, dtype=float, comments=None,
                                   usecols=list(positions.values()) or None, ndmin=2)
    except (OSError, UnicodeDecodeError, csv.Error, ValueError):
        return None
    if table.shape[1] != len(positions) or not np.all(np.isfinite(table)):
        return None
    columns: dict[str, tuple[NDArray[np.float64] | None, str, str]] = dict.fromkeys(header, (None, "", ""))
    columns.update({column: (table[:, k], "", "") for k, column in enumerate(positions)})
    return columns


def _read_csv_text(name: str, wanted) -> dict[str, tuple[NDArray[np.float64] | None, str, str]]:
    """:func:`_read_csv` on the file's whole text, cell by cell where numpy's parser cannot read it."""
    try:
        with open(name, newline="", encoding="utf-8-sig") as handle:  # a byte-order mark (Excel) skipped
            text = handle.read()
        rows = csv.reader(io.StringIO(text))
        header, skipped = None, 0
        for row in rows:
            skipped += 1
            if any(cell.strip() for cell in row):
                header = [cell.strip() for cell in row]
                break
    except (OSError, UnicodeDecodeError, csv.Error) as error:
        raise PathFileError(f"{name}: cannot be read as a CSV file ({error}).") from None
    if header is None:
        raise PathFileError(f"{name}: is empty; expected a header row of column names and a row per sample.")
    doubled = _doubled(header, wanted)
    if doubled:
        where = [str(position + 1) for position, column in enumerate(header) if column == doubled]
        raise PathFileError(f"{name}: column {doubled!r} is in the header {len(where)} times (columns "
                            f"{', '.join(where)}); give each column once.")
    positions = {column: position for position, column in enumerate(header) if column in wanted}
    columns: dict[str, tuple[NDArray[np.float64] | None, str, str]] = dict.fromkeys(header, (None, "", ""))
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # an empty table warns; it is refused below as one sample too few
            table = np.loadtxt(io.StringIO(text), delimiter=",", skiprows=skipped, dtype=float, comments=None,
                               usecols=list(positions.values()) or None, ndmin=2)
        if table.shape[1] == len(positions) and np.all(np.isfinite(table)):
            columns.update({column: (table[:, k], "", "") for k, column in enumerate(positions)})
            return columns
    except ValueError:
        pass
    return _read_csv_cells(name, text, positions, columns)


def _doubled(header: list[str], wanted) -> str | None:
    """The first column of ``wanted`` that ``header`` names more than once, or None."""
    return next((column for column in header if column in wanted and header.count(column) > 1), None)


def _read_csv_cells(name: str, text: str, positions: dict[str, int], columns: dict) -> dict:
    """:func:`_read_csv` cell by cell: the first value of each column that is not a finite number, and where."""
    try:
        rows = [row for row in csv.reader(io.StringIO(text)) if any(cell.strip() for cell in row)]
    except csv.Error as error:
        raise PathFileError(f"{name}: cannot be read as a CSV file ({error}).") from None
    for column, position in positions.items():
        values, problem = np.empty(len(rows) - 1), ""
        for line, row in enumerate(rows[1:], start=2):
            text = row[position].strip() if position < len(row) else ""
            try:
                values[line - 2] = float(text)
            except ValueError:
                values[line - 2] = np.nan
            if not problem and not math.isfinite(values[line - 2]):
                problem = f"line {line}, column {column!r}: expected a finite number, got {text!r}."
        columns[column] = (values, "", problem)
    return columns


def _read_netcdf(name: str, wanted) -> dict[str, tuple[NDArray[np.float64], str, str]]:
    """Every one-dimensional numeric variable (and coordinate) of a netCDF file, with its ``units`` and what is
    wrong with its first value that is not a finite number ("" if none).

    A netCDF-3 file whose variables need no decoding but their fill values, and that has the columns ``wanted``, is
    read by scipy's reader alone (:func:`_read_plain_netcdf`: the same numbers, without importing xarray, pandas and
    dask.array, a quarter of a second); any other file through xarray, which decodes it and says what is wrong."""
    plain = _read_plain_netcdf(name, wanted)
    if plain is not None:
        return plain
    dataset = open_netcdf(name, PathFileError)
    return {str(key): _netcdf_column(str(key), variable.values, str(variable.attrs.get("units", "")))
            for key, variable in {**dataset.coords, **dataset.data_vars}.items()
            if variable.ndim == 1 and np.issubdtype(variable.dtype, np.number)}


_DECODED = ("scale_factor", "add_offset", "calendar", "dtype", "_Unsigned", "_Encoding", "compress", "flag_values")
"""Attributes by which xarray decodes a variable into other values or another type: a file with any of them is
read through xarray."""


def _read_plain_netcdf(name: str, wanted) -> dict[str, tuple[NDArray[np.float64], str, str]] | None:
    """:func:`_read_netcdf` by ``scipy.io.netcdf_file``, with xarray's decoding of the fill values (``_FillValue``
    and ``missing_value`` read as NaN) and nothing else; None for a file it would decode otherwise (an attribute
    of :data:`_DECODED`, times in units "... since ..."), one that lacks a column ``wanted``, or one scipy's reader
    does not read (netCDF-4, not netCDF: xarray's reading says what is wrong)."""
    from screwkit.studies.netcdf import netcdf_file  # scipy's netCDF module alone: only where a file is read

    columns = {}
    try:
        with netcdf_file()(name, "r", mmap=False) as handle:
            for key, variable in handle.variables.items():
                attributes = {str(k): v.decode("utf-8") if isinstance(v, bytes) else v
                              for k, v in variable._attributes.items()}
                if (len(variable.dimensions) != 1 or not np.issubdtype(variable.data.dtype, np.number)
                        or attributes.get("dtype") == "bool"):
                    continue  # not a column: strings (characters along a second dimension), booleans
                units = attributes.get("units", "")
                if set(attributes) & set(_DECODED) or not isinstance(units, str) or " since " in units:
                    return None
                values = np.array(variable.data, dtype=float)  # a copy, its fill values masked in place
                for fill in (attributes.get("_FillValue"), attributes.get("missing_value")):
                    if fill is not None:
                        values[np.isin(values, np.asarray(fill, dtype=float))] = np.nan
                columns[str(key)] = _netcdf_column(str(key), values, units)
    except Exception:  # whatever scipy's reader makes of a file it does not read: xarray's reading says it
        return None
    return columns if all(column in columns for column in wanted) else None


def _netcdf_column(key: str, values, units: str) -> tuple[NDArray[np.float64], str, str]:
    """A netCDF variable's values as floats, its units and what is wrong with its first value that is not a finite
    number ("" if none)."""
    values = np.asarray(values, dtype=float)
    bad = np.flatnonzero(~np.isfinite(values))
    problem = (f"variable {key!r}, sample {int(bad[0])}: expected a finite number, got {values[bad[0]]}."
               if bad.size else "")
    return values, units, problem
