"""Workspace maps: at each grid position, the minimum of every index over an orientation set.

:func:`index_map` evaluates a 2-D grid of two task coordinates (the rest fixed) and, at
each grid point, every pose of an orientation set (the product of ranges of other task
coordinates); it keeps the minimum of the ITI, LMTI, F_Oj and F_IOj over the set, like the
paper's Fig. 5. :func:`planar_disc_map` is the paper's case: x, y on a disc, phi over a
full turn.

The grid is cut into rectangular blocks of about :data:`CONFIGURATIONS_PER_TASK`
configurations, run as tasks (:func:`screwkit.studies.tasks.run_tasks`): on local threads by default, or on a
running ``dask.distributed`` cluster. A task receives only
its block's coordinates and mask and returns only the block's minima, so memory beyond the
output grid does not grow with the number of configurations; :func:`map_size` states the size
of a map before anything is allocated. Tasks are pure functions of their inputs (the URDF text
travels with them), so a task lost with a worker is recomputed elsewhere.
"""

from __future__ import annotations

import hashlib
import math
import os
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.common.memory import available_memory, byte_size
from screwkit.common.units import unit_of
from screwkit.indices.registry import index_columns
from screwkit.io.graph import GraphMechanism
from screwkit.io.loader import cached_mechanism
from screwkit.model import Mechanism, require_mechanism
from screwkit.studies.coordinates import map_axis, one_pose, planar_position, pose_text, shown_values
from screwkit.studies.files import atomic_write
from screwkit.studies.graph_source import GraphSource, cached_graph, graph_source
from screwkit.studies.netcdf import netcdf_attribute, netcdf_file
from screwkit.studies.options import AnalysisOptions, checked_analysis
from screwkit.studies.poses import check_graph_analysis, graph_indices_at_poses, indices_at_poses
from screwkit.studies.tasks import Execution, run_tasks

__all__ = ["index_map", "planar_disc_map", "disc_grid", "disc_point_count", "range_values", "range_count", "GridMap",
           "MapSize", "map_size", "disc_size", "map_task", "map_block", "MapBlock", "orientation_set"]

CONFIGURATIONS_PER_TASK = 131_072
"""Configurations (grid points times orientations) per task, at most (see :func:`task_size`)."""
TASKS_PER_CORE = 16
"""A map of local threads is cut into at least this many tasks per core when it is large enough
(two tasks of 131,072 and 27,688 configurations kept one of two cores idle most of the time). Each
running task holds its configurations' poses and indices until it reduces them: 16 tasks per core
rather than 4 took the hexapod's 41 x 41 x 360 map from 312 to 286 MiB at its peak."""
MIN_CONFIGURATIONS_PER_TASK = 16_384
"""Smaller tasks than this cost more scheduling than they balance."""
MAX_CONFIGURATIONS = 2_000_000_000
"""Maps with more configurations are refused unless the caller says to proceed (``--yes``)."""


@dataclass(frozen=True)
class MapSize:
    """The size of a map, known before it is computed.

    Attributes
    ----------
    grid_points : int
        Grid points evaluated (inside the mask).
    orientations : int
        Poses of the orientation set at every grid point.
    variables : int
        Variables of the output grid.
    grid_shape : tuple of int
        (len(y), len(x)).
    """

    grid_points: int
    orientations: int
    variables: int
    grid_shape: tuple[int, int]

    @property
    def configurations(self) -> int:
        """Poses evaluated: grid points times orientations."""
        return self.grid_points * self.orientations

    @property
    def memory_bytes(self) -> int:
        """Memory of the result: every variable on the whole grid, plus the mask and coordinates."""
        cells = self.grid_shape[0] * self.grid_shape[1]
        return int(cells * (8 * self.variables + 1) + 8 * sum(self.grid_shape))

    @property
    def description(self) -> str:
        """``N configurations (P grid points x K orientations)``."""
        return (f"{_count(self.configurations, 'configuration')} ({_count(self.grid_points, 'grid point')} x "
                f"{_count(self.orientations, 'orientation')})")

    def check(self, *, max_configurations: int = MAX_CONFIGURATIONS, proceed: bool = False,
              available_bytes: int | None = None) -> None:
        """Refuse, with one line, a map that would not fit in memory or is larger than stated without ``proceed``."""
        available = available_memory() if available_bytes is None else available_bytes
        summary = self.description
        if available is not None and self.memory_bytes > 0.8 * available:
            raise ValueError(f"The map has {summary}; its result alone needs {byte_size(self.memory_bytes)}, more than "
                             f"this machine can give ({byte_size(available)} available): use a coarser grid.")
        if self.configurations > max_configurations and not proceed:
            raise ValueError(f"The map has {summary}, more than {max_configurations:,}; it would run for a long time "
                             f"and its result needs {byte_size(self.memory_bytes)}: use a coarser grid, or pass --yes "
                             "to proceed.")


def _count(count: int, noun: str) -> str:
    return f"{count:,} {noun}{'' if count == 1 else 's'}"


@dataclass
class GridMap:
    """A computed map as plain numpy arrays, before (or without) xarray.

    :func:`index_map` returns it with ``as_dataset=False``; the command line writes it to
    netCDF directly (:meth:`write_netcdf`), which spares the import of xarray, pandas and
    dask.array (about 1 s of a map command's start-up).

    Attributes
    ----------
    coordinates : dict of str to (ndarray, str)
        The two grid coordinates, x axis first: values (as shown: degrees for angles) and unit.
    variables : dict of str to ndarray (len(y), len(x))
        The minimum of each index over the orientation set (NaN outside the mask or where some
        orientation is unreachable), and ``reachable_fraction``.
    long_names : dict of str to str
        A description of each variable.
    attrs : dict
        Global attributes (mechanism, method, orientation set, ...).
    """

    coordinates: dict[str, tuple[NDArray[np.float64], str]]
    variables: dict[str, NDArray[np.float64]]
    long_names: dict[str, str]
    attrs: dict = field(default_factory=dict)

    def to_dataset(self):
        """The same map as an ``xarray.Dataset`` (what :func:`index_map` returns by default)."""
        import xarray as xr

        (x_name, _), (y_name, _) = self.coordinates.items()
        dataset = xr.Dataset(
            {key: ((y_name, x_name), values) for key, values in self.variables.items()},
            coords={name: (name, values, {"units": unit}) for name, (values, unit) in self.coordinates.items()})
        for key, long_name in self.long_names.items():
            dataset[key].attrs["long_name"] = long_name
        dataset.attrs.update(self.attrs)
        return dataset

    def write_netcdf(self, path) -> None:
        """Write a netCDF-3 file (``scipy.io.netcdf_file``) atomically; ``xarray.open_dataset`` reads it."""
        (x_name, _), (y_name, _) = self.coordinates.items()

        def write(temporary):
            with netcdf_file()(temporary, "w", version=2) as handle:
                for name, (values, unit) in self.coordinates.items():
                    handle.createDimension(name, values.size)
                    variable = handle.createVariable(name, "d", (name,))
                    variable[:] = values
                    variable.units = unit
                for key, values in self.variables.items():
                    variable = handle.createVariable(key, "d", (y_name, x_name))
                    variable[:] = values
                    if key in self.long_names:
                        variable.long_name = self.long_names[key]
                for key, value in self.attrs.items():
                    if key in handle.__dict__:
                        raise ValueError(f"Cannot write a global attribute named {key!r} to netCDF.")
                    setattr(handle, key, netcdf_attribute(value))

        atomic_write(path, write)


def portable(mechanism: Mechanism | GraphMechanism):
    """What a task needs to rebuild the mechanism anywhere: (digest, URDF text in metres, source name); a
    :class:`GraphSource` for a closed-loop graph."""
    if isinstance(mechanism, GraphMechanism):
        return graph_source(mechanism)
    text = mechanism.description.text
    text = text if isinstance(text, str) else text.decode()
    return hashlib.sha256(text.encode()).hexdigest(), text, str(mechanism.path)


@dataclass(frozen=True, eq=False)
class MapBlock:
    """One task of a map: a rectangular block of the grid and the orientation set at each of its points.

    Attributes
    ----------
    at : ndarray (n_task,)
        The fixed coordinates.
    x_axis, y_axis : int
        Task coordinates of the grid's x and y.
    x_values, y_values : ndarray
        The block's grid values (m, rad).
    mask : ndarray of bool, shape (len(y_values), len(x_values))
        Grid points of the block to evaluate.
    over_axes : tuple of int
        Task coordinates making up the orientation set.
    over_values : ndarray (K, len(over_axes))
        Every orientation of the set.
    """

    at: NDArray[np.float64]
    x_axis: int
    x_values: NDArray[np.float64]
    y_axis: int
    y_values: NDArray[np.float64]
    mask: NDArray[np.bool_]
    over_axes: tuple[int, ...]
    over_values: NDArray[np.float64]

    def poses(self) -> NDArray[np.float64]:
        """Every pose of the block (P, K, n_task): the P masked points in row-major order, K orientations each."""
        rows, columns = np.nonzero(self.mask)
        base = np.repeat(np.asarray(self.at, dtype=float)[None], rows.size, axis=0)
        base[:, self.x_axis] = self.x_values[columns]
        base[:, self.y_axis] = self.y_values[rows]
        poses = np.repeat(base[:, None, :], self.over_values.shape[0], axis=1)
        for column, axis in enumerate(self.over_axes):
            poses[:, :, axis] = self.over_values[None, :, column]
        return poses


def map_task(mechanism_text: tuple[str, str, str], block: MapBlock, analysis: AnalysisOptions,
             threads: int = 1) -> dict:
    """Minimum of each index over the orientation set at the grid points of one block.

    Parameters
    ----------
    mechanism_text : tuple
        From :func:`portable`.
    block : MapBlock
        The block's grid points and orientation set.
    analysis : AnalysisOptions
        What is computed at every pose.
    threads : int
        Threads of the index kernel.

    Returns
    -------
    dict of ndarray (P,)
        For the P masked points of the block in row-major order: ``iti``, ``lmti``,
        ``f_o{j}``, ``f_io{j}`` (NaN where some orientation is unreachable) and
        ``reachable_fraction``.
    """
    if isinstance(mechanism_text, GraphSource):
        return map_block(cached_graph(mechanism_text), block, analysis, threads)
    # read as it was loaded: limits ignored at loading (--ignore-limits) are ignored where the task runs too
    return map_block(cached_mechanism(*mechanism_text, limits=analysis.limits), block, analysis, threads)


def map_block(mechanism: Mechanism | GraphMechanism, block: MapBlock, analysis: AnalysisOptions,
              threads: int = 1) -> dict:
    """:func:`map_task` on a loaded mechanism (in the calling process)."""
    with analysis.indices():  # the average case too, if asked, wherever the task runs
        if isinstance(mechanism, GraphMechanism):
            check_graph_analysis(mechanism, analysis.closed_forms, analysis.fault_type)
            result = graph_indices_at_poses(mechanism, block.poses(), threads=threads, threshold=analysis.threshold,
                                            faults=analysis.faults, limits=analysis.limits)
        else:
            result = indices_at_poses(mechanism, block.poses(), threads=threads, **analysis.keywords())
        columns = index_columns(result)
    everywhere = result.reachable.all(axis=1)
    out = {"reachable_fraction": result.reachable.mean(axis=1)}
    for name, values in columns.items():  # every registered index: the worst orientation (its `reduce`)
        out[name] = np.where(everywhere, np.min(np.where(result.reachable, values, np.inf), axis=1), np.nan)
    return out


def _blocks(mask: NDArray[np.bool_], per_task: int) -> list[tuple[slice, slice]]:
    """Rectangular blocks of the grid (row slice, column slice) with about ``per_task`` masked points each."""
    counts = mask.sum(axis=1)
    blocks, start, total = [], 0, 0
    for row, count in enumerate(counts):
        if count > per_task:  # one long row: split its columns
            if row > start:
                blocks.append((slice(start, row), slice(None)))
            columns = np.flatnonzero(mask[row])
            for first in range(0, columns.size, per_task):
                chosen = columns[first:first + per_task]
                blocks.append((slice(row, row + 1), slice(int(chosen[0]), int(chosen[-1]) + 1)))
            start, total = row + 1, 0
            continue
        if total + count > per_task and row > start:
            blocks.append((slice(start, row), slice(None)))
            start, total = row, 0
        total += count
    if start < mask.shape[0]:
        blocks.append((slice(start, mask.shape[0]), slice(None)))
    return [block for block in blocks if mask[block].any()]


def orientation_set(over: dict[str, ArrayLike]) -> NDArray[np.float64]:
    """Every orientation of the product set ``over`` (coordinate -> values) as rows (K, len(over));
    one empty row when ``over`` is empty."""
    if not over:
        return np.zeros((1, 0))
    return np.stack([g.ravel() for g in np.meshgrid(*[np.asarray(v, float) for v in over.values()], indexing="ij")],
                    axis=-1)


def task_size(configurations: int, cores: int | None = None) -> int:
    """Default configurations per task of a map of ``configurations``: at most
    :data:`CONFIGURATIONS_PER_TASK`, at least :data:`MIN_CONFIGURATIONS_PER_TASK`, and small
    enough for :data:`TASKS_PER_CORE` tasks per core of this machine (``cores``, default all)."""
    cores = max(1, cores or os.cpu_count() or 1)
    balanced = -(-int(configurations) // (TASKS_PER_CORE * cores))
    return int(min(CONFIGURATIONS_PER_TASK, max(MIN_CONFIGURATIONS_PER_TASK, balanced)))


def map_size(mechanism: Mechanism, grid: dict[str, ArrayLike], over: dict[str, ArrayLike],
             mask: NDArray[np.bool_] | None = None, faults=None) -> MapSize:
    """How many grid points, orientations and configurations a map has, and the memory of its result."""
    (_, x_values), (_, y_values) = ((k, np.asarray(v)) for k, v in grid.items())
    shape = (y_values.size, x_values.size)
    points = int(np.count_nonzero(mask)) if mask is not None else shape[0] * shape[1]
    orientations = int(np.prod([np.asarray(v).size for v in over.values()], dtype=np.int64)) if over else 1
    a = len(mechanism.actuators)
    j_count = (a - mechanism.dof) if faults is None else len(np.atleast_1d(faults))
    return MapSize(points, orientations, 3 + 2 * max(j_count, 0), shape)


def index_map(mechanism: Mechanism, grid: dict[str, ArrayLike], over: dict[str, ArrayLike],
              at: ArrayLike | None = None, *, mask: NDArray[np.bool_] | None = None,
              analysis: AnalysisOptions | None = None, execution: Execution | None = None,
              as_dataset: bool = True, proceed: bool = False, max_configurations: int = MAX_CONFIGURATIONS):
    """Minimum of every index over an orientation set on a 2-D grid of two task coordinates.

    Parameters
    ----------
    mechanism : Mechanism or GraphMechanism
        A mechanism whose legs have loops inside them is solved at each pose by continuation from its file's
        configuration (:func:`~screwkit.studies.poses.graph_indices_at_poses`).
    grid : dict of str to array_like
        Exactly two task coordinates and their values (metres / radians); the first is the
        map's x axis, the second its y axis.
    over : dict of str to array_like
        The orientation set: task coordinates and their values; the set is their product.
    at : array_like (n_task,), optional
        Values of the other coordinates (default: the home pose).
    mask : ndarray of bool, shape (len(y), len(x)), optional
        Grid points to evaluate (others are NaN).
    analysis : AnalysisOptions, optional
        What is computed at every pose: threshold, faults, fault type, closed forms, joint limits
        (as in :func:`screwkit.studies.indices_at_poses`; default :class:`AnalysisOptions()`).
    execution : Execution, optional
        The ``dask.distributed`` scheduler (default: local threads), the progress bar on stderr
        (default: when stderr is a terminal), the seconds to wait for the scheduler, and the grid
        points times orientations per task (default: :func:`task_size` of the map).
    as_dataset : bool
        Return an ``xarray.Dataset`` (default) or the plain :class:`GridMap`.
    proceed, max_configurations :
        Maps with more configurations are refused unless ``proceed`` (see :meth:`MapSize.check`).

    Returns
    -------
    xarray.Dataset or GridMap
        Coordinates named after the two grid coordinates (``x``, ``y`` for planar maps);
        variables ``iti``, ``lmti``, ``f_o{j}``, ``f_io{j}`` (NaN where unreachable for some
        orientation of the set) and ``reachable_fraction``.
    """
    analysis = checked_analysis(analysis, "index_map")
    if isinstance(mechanism, GraphMechanism):
        check_graph_analysis(mechanism, analysis.closed_forms, analysis.fault_type)
    else:
        require_mechanism(mechanism, "index_map")
    names = mechanism.task_coordinates
    for name, given in (("grid", grid), ("over", over)):
        if not isinstance(given, dict):
            raise TypeError(f"index_map expects `{name}` as a dict of task coordinates to values, got {given!r:.60}.")
    if len(grid) != 2:
        raise ValueError(f"Expected `grid` with exactly two task coordinates, got {list(grid)}.")
    for name in list(grid) + list(over):
        if name not in names:
            raise ValueError(f"Unknown task coordinate {name!r}; mechanism {mechanism.name!r} has {names}.")
    if set(grid) & set(over):
        raise ValueError("A coordinate cannot be both on the grid and in the orientation set: "
                         f"{set(grid) & set(over)}.")
    grid = {name: map_axis(values, f"`grid[{name!r}]`") for name, values in grid.items()}
    over = {name: map_axis(values, f"`over[{name!r}]`") for name, values in over.items()}
    (x_name, x_values), (y_name, y_values) = grid.items()
    shape = (y_values.size, x_values.size)
    if mask is not None:
        mask = np.asarray(mask, dtype=bool)
        if mask.shape != shape:
            raise ValueError(f"Expected `mask` with shape {shape} (y, x), got {mask.shape}.")
    execution = Execution() if execution is None else execution
    size = map_size(mechanism, grid, over, mask, analysis.faults)
    size.check(max_configurations=max_configurations, proceed=proceed)
    mask = np.ones(shape, dtype=bool) if mask is None else mask
    at = one_pose(mechanism, mechanism.home_pose if at is None else at)
    over_axes = tuple(names.index(name) for name in over)
    over_values = orientation_set(over)
    configurations_per_task = execution.configurations_per_task
    if configurations_per_task is None:
        configurations_per_task = task_size(size.configurations)
    per_task = max(1, configurations_per_task // max(1, over_values.shape[0]))
    text = portable(mechanism)
    blocks = _blocks(mask, per_task)
    arguments = [(text, MapBlock(at, names.index(x_name), x_values[columns], names.index(y_name), y_values[rows],
                                 mask[rows, columns], over_axes, over_values), analysis)
                 for rows, columns in blocks]
    results = run_tasks(map_task, arguments, execution, label="map")
    keys = results[0].keys() if results else ("iti", "lmti", "reachable_fraction")
    variables = {key: np.full(shape, np.nan) for key in keys}
    for (rows, columns), result in zip(blocks, results):
        block_mask = mask[rows, columns]
        for key in keys:
            view = variables[key][rows, columns]
            view[block_mask] = result[key]
    shown = shown_values
    grid_map = GridMap(
        coordinates={x_name: (shown(x_name, x_values), unit_of(x_name)),
                     y_name: (shown(y_name, y_values), unit_of(y_name))},
        variables=variables,
        long_names={key: f"minimum of {key} over the orientation set"
                    for key in variables if key != "reachable_fraction"},
        attrs=dict(
            mechanism=mechanism.name, threshold_m=analysis.threshold,
            method="closed forms" if analysis.closed_forms else "generic screw path",
            orientation_set="; ".join(
                f"{name}: {len(np.unique(over_values[:, i]))} values from {shown(name, over_values[:, i].min()):g} "
                f"to {shown(name, over_values[:, i].max()):g} {unit_of(name)}" for i, name in enumerate(over))
            or "the fixed pose only",
            fixed_pose=pose_text(names, at, mechanism.length_scale, leave_out=[*grid, *over]),
            joint_limits="respected" if analysis.limits else "ignored", fault_type=analysis.fault_type,
            configurations=int(size.configurations)))
    return grid_map.to_dataset() if as_dataset else grid_map


def range_values(start: float, stop: float, step: float, *, include_stop: bool = False) -> NDArray[np.float64]:
    """START, START + STEP, ... up to STOP: the ranges of ``screwkit map --grid`` (``include_stop``)
    and ``--over`` (stop excluded).

    With ``include_stop`` the step must divide STOP - START (to a millionth of a step), so that the
    stop is on the grid; a step that does not is refused rather than the stop silently dropped (a grid's
    points are evenly spaced: region areas are counts of points times the cell).
    """
    if not (np.isfinite(start) and np.isfinite(stop) and np.isfinite(step)) or not step > 0 or not stop > start:
        raise ValueError("finite numbers, STEP > 0 and STOP > START")
    span = (stop - start) / step
    count = range_count(start, stop, step, include_stop=include_stop)
    if count > 10**8:
        raise ValueError(f"at most 10^8 values ({count:,} asked; use a larger step)")
    if include_stop and abs(span - round(span)) > 1e-6:
        whole = max(1, math.floor(span))
        raise ValueError(f"a STEP that divides STOP - START, since the stop is included ({stop - start:g} / {step:g} "
                         f"= {span:.4g} steps; e.g. a stop of {start + whole * step:g}, or a step of "
                         f"{(stop - start) / whole:.6g} or {(stop - start) / (whole + 1):.6g})")
    return start + step * np.arange(count)


def range_count(start: float, stop: float, step: float, *, include_stop: bool = False) -> int:
    """How many values :func:`range_values` gives for a checked START, STOP and STEP, without listing them."""
    span = (stop - start) / step
    return int(np.floor(span + 1e-6)) + 1 if include_stop else int(np.ceil(span - 1e-6))


def disc_point_count(radius: float, step: float) -> int:
    """Grid points of :func:`disc_grid`'s disc for a checked radius and step, counted row by row without the grid
    (beyond 10^7 rows, the disc's area in cells: close enough for a refusal)."""
    count = int(math.floor(radius / step + 1e-9))
    if count >= 10**7:
        return int(math.pi * (radius / step) ** 2)
    offsets = step * np.arange(-count, count + 1, dtype=float)
    half = np.sqrt(np.maximum(radius**2 * (1 + 1e-12) - offsets**2, 0.0))
    return int(np.sum(2 * np.floor(half / step + 1e-9) + 1))


def disc_grid(radius: float, step: float, centre=(0.0, 0.0)) -> tuple[NDArray, NDArray, NDArray[np.bool_]]:
    """x and y values of a square grid of spacing ``step`` about ``centre``, and the mask of the disc of ``radius``."""
    for name, value in (("radius", radius), ("step", step)):
        if not (np.isfinite(value) and value > 0):
            raise ValueError(f"Expected `{name}` > 0, got {value}.")
    count = int(math.floor(radius / step + 1e-9))
    offsets = step * np.arange(-count, count + 1)
    mask = offsets[None, :] ** 2 + offsets[:, None] ** 2 <= radius**2 * (1 + 1e-12)
    centre = planar_position(centre)
    return centre[0] + offsets, centre[1] + offsets, mask


def disc_size(mechanism: Mechanism, radius: float, step: float, phi_step_degrees: float) -> MapSize:
    """The size of :func:`planar_disc_map`'s map, computed without allocating its grid."""
    for name, value in (("radius", radius), ("step", step), ("phi_step_degrees", phi_step_degrees)):
        if not (np.isfinite(value) and value > 0):
            raise ValueError(f"Expected `{name}` > 0, got {value}.")
    count = int(math.floor(radius / step + 1e-9))
    points = disc_point_count(radius, step)
    orientations = (len(np.arange(0.0, 360.0 - 1e-9, phi_step_degrees)) if phi_step_degrees >= 1e-6 else
                    int(math.ceil(360.0 / phi_step_degrees - 1e-9)))  # (counted, not listed: 3.6e11 for 1e-9)
    if "phi" not in mechanism.task_coordinates:  # a planar point output: no rotation to map over
        orientations = 1
    a = len(mechanism.actuators)
    return MapSize(points, orientations, 3 + 2 * max(a - mechanism.dof, 0), (2 * count + 1, 2 * count + 1))


def planar_disc_map(mechanism: Mechanism, radius: float, step: float, phi_step_degrees: float, *, centre=None,
                    proceed: bool = False, **keywords):
    """The paper's Fig. 5 map: x, y on a disc about ``centre`` (default the home pose), phi over a full turn.

    ``step`` is the grid spacing (m) and ``phi_step_degrees`` the angular step of the
    rotation 0 <= phi < 360 deg. A planar point output (task coordinates x, y: its rotation is idle)
    is mapped at its positions alone and ``phi_step_degrees`` is not used. Other keywords
    (``analysis``, ``execution``, ``as_dataset``, ``max_configurations``) as in :func:`index_map`.
    """
    require_mechanism(mechanism, "planar_disc_map")
    if not mechanism.is_planar:
        raise ValueError(f"planar_disc_map needs a planar mechanism; {mechanism.name!r} is spatial (use index_map).")
    if phi_step_degrees > 360:
        raise ValueError(f"Expected a phi step of at most 360 deg, got {phi_step_degrees:g}.")
    disc_size(mechanism, radius, step, phi_step_degrees).check(
        proceed=proceed, max_configurations=keywords.get("max_configurations", MAX_CONFIGURATIONS))
    home = mechanism.home_pose
    x_values, y_values, mask = disc_grid(radius, step, home[:2] if centre is None else centre)
    rotating = "phi" in mechanism.task_coordinates
    over = {"phi": np.deg2rad(np.arange(0.0, 360.0 - 1e-9, phi_step_degrees))} if rotating else {}
    result = index_map(mechanism, {"x": x_values, "y": y_values}, over, home, mask=mask, proceed=proceed,
                       **keywords)
    result.attrs.update(radius_m=radius, step_m=step)
    if rotating:
        result.attrs.update(phi_step_deg=phi_step_degrees)
    return result
