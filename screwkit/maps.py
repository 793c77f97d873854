"""Workspace maps: at each grid position, the minimum of every index over an orientation set.

:func:`index_map` evaluates a 2-D grid of two task coordinates (the rest fixed) and, at
each grid point, every pose of an orientation set (the product of ranges of other task
coordinates); it keeps the minimum of the ITI, LMTI, F_Oj and F_IOj over the set, like the
paper's Fig. 5. :func:`planar_disc_map` is the paper's case: x, y on a disc, phi over a
full turn.

The grid is cut into tasks run through Dask: the local threaded scheduler by default (no
set-up), or a running ``dask.distributed`` cluster given by its scheduler address. Tasks
are pure functions of their inputs (the URDF text travels with them), so a task lost with a
worker is recomputed elsewhere; results are assembled only when every task is done, and
files are written atomically.
"""

from __future__ import annotations

import functools
import hashlib
import os
import sys
import time
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.analysis import angular_coordinates, indices_at_poses
from screwkit.transmission import DEFAULT_THRESHOLD

__all__ = ["index_map", "planar_disc_map", "GridMap", "write_dataset", "run_tasks"]

CONFIGURATIONS_PER_TASK = 131_072


@dataclass
class GridMap:
    """A computed map as plain numpy arrays, before (or without) xarray.

    :func:`index_map` returns it with ``as_dataset=False``; the command line writes it to
    netCDF directly (:meth:`to_netcdf`), which spares the import of xarray, pandas and
    dask.array (about 1 s of a map command's start-up).

    Attributes
    ----------
    coordinates : dict of str -> (ndarray, str)
        The two grid coordinates, x axis first: values (as shown: degrees for angles) and unit.
    variables : dict of str -> ndarray (len(y), len(x))
    long_names : dict of str -> str
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

    def to_netcdf(self, path) -> None:
        """Write a netCDF-3 file (``scipy.io.netcdf_file``) atomically; ``xarray.open_dataset`` reads it."""
        from scipy.io import netcdf_file

        (x_name, _), (y_name, _) = self.coordinates.items()

        def write(temporary):
            with netcdf_file(temporary, "w", version=2) as handle:
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
                    setattr(handle, key, _netcdf_attribute(value))

        _atomic_write(path, write)


@functools.lru_cache(maxsize=8)
def _mechanism_from_text(digest: str, text: str, source: str):
    from screwkit.mechanism import Mechanism
    from screwkit.urdf import parse_urdf

    return Mechanism(parse_urdf(text, source))


def _portable(mechanism) -> tuple[str, str, str]:
    """What a task needs to rebuild the mechanism anywhere: (digest, URDF text, source name)."""
    text = mechanism.description.text
    text = text if isinstance(text, str) else text.decode()
    return hashlib.sha256(text.encode()).hexdigest(), text, str(mechanism.path)


def map_task(portable, base_poses, over_axes, over_values, threshold, faults, closed_forms, threads=1) -> dict:
    """Minimum of each index over the orientation set at each of the given grid poses.

    Parameters
    ----------
    portable : tuple
        From :func:`_portable`.
    base_poses : ndarray (P, n_task)
        Grid poses (the orientation coordinates are overwritten).
    over_axes : tuple of int
        Task coordinates making up the orientation set.
    over_values : ndarray (K, len(over_axes))
        Every orientation of the set.

    Returns
    -------
    dict of ndarray (P,)
        ``iti``, ``lmti``, ``f_o{j}``, ``f_io{j}`` (NaN where some orientation is
        unreachable) and ``reachable_fraction``.
    """
    mechanism = _mechanism_from_text(*portable)
    orientations = over_values.shape[0]
    poses = np.repeat(base_poses[:, None, :], orientations, axis=1)
    for column, axis in enumerate(over_axes):
        poses[:, :, axis] = over_values[None, :, column]
    result = indices_at_poses(mechanism, poses, threshold=threshold, faults=faults, closed_forms=closed_forms,
                              threads=threads)
    everywhere = result.reachable.all(axis=1)
    out = {"reachable_fraction": result.reachable.mean(axis=1)}
    named = {"iti": result.iti, "lmti": result.lmti}
    for j in result.f_o:
        named[f"f_o{j}"] = result.f_o[j]
        named[f"f_io{j}"] = result.f_io[j]
    for name, values in named.items():
        out[name] = np.where(everywhere, np.min(np.where(result.reachable, values, np.inf), axis=1), np.nan)
    return out


def run_tasks(function, arguments: list[tuple], *, scheduler: str | None = None, progress: bool | None = None,
              label: str = "tasks") -> list:
    """Run ``function(*args)`` for every tuple of ``arguments`` through Dask and return the results in order.

    Parameters
    ----------
    scheduler : str, optional
        Address of a running ``dask.distributed`` scheduler (``tcp://host:8786``) or an
        existing ``distributed.Client``; default: Dask's local threaded scheduler.
    progress : bool, optional
        A progress bar (tqdm, on stderr); default: only when stderr is a terminal.
    """
    if progress is None:
        progress = sys.stderr.isatty()
    from tqdm import tqdm

    bar = tqdm(total=len(arguments), desc=label, disable=not progress, file=sys.stderr, leave=False, delay=2.0)
    try:
        if scheduler is None:
            # Dask's local threaded scheduler on a plain task graph: unlike dask.compute it
            # does not import dask.distributed (0.2-0.3 s of start-up) to look for a client.
            import dask
            from dask.callbacks import Callback
            from dask.threaded import get

            class Counter(Callback):
                def _posttask(self, key, result, dsk, state, worker_id):
                    if str(key).startswith("task-"):
                        bar.update(1)

            tasks = [dask.delayed(function, pure=True)(*args, dask_key_name=f"task-{i}")
                     for i, args in enumerate(arguments)]
            graph = {}
            for task in tasks:
                graph.update(task.__dask_graph__())
            with Counter():
                return list(get(graph, [task.key for task in tasks], num_workers=os.cpu_count() or 1))
        from distributed import Client, as_completed

        client = scheduler if isinstance(scheduler, Client) else Client(scheduler, set_as_default=False)
        try:
            futures = client.map(function, *zip(*arguments), pure=True, retries=3, key=[
                f"screwkit-{hashlib.sha256(repr((function.__name__, i)).encode()).hexdigest()[:12]}-{time.time_ns()}"
                for i in range(len(arguments))])
            for _ in as_completed(futures):
                bar.update(1)
            return client.gather(futures)
        finally:
            if client is not scheduler:
                client.close()
    finally:
        bar.close()


def index_map(mechanism, grid: dict[str, ArrayLike], over: dict[str, ArrayLike], at: ArrayLike | None = None, *,
              mask: NDArray[np.bool_] | None = None, threshold: float = DEFAULT_THRESHOLD, faults=None,
              closed_forms: bool = False, scheduler: str | None = None, progress: bool | None = None,
              configurations_per_task: int = CONFIGURATIONS_PER_TASK, as_dataset: bool = True):
    """Minimum of every index over an orientation set on a 2-D grid of two task coordinates.

    Parameters
    ----------
    mechanism : screwkit.mechanism.Mechanism
    grid : dict of str -> array_like
        Exactly two task coordinates and their values (metres / radians); the first is the
        map's x axis, the second its y axis.
    over : dict of str -> array_like
        The orientation set: task coordinates and their values; the set is their product.
    at : array_like (n_task,), optional
        Values of the other coordinates (default: the home pose).
    mask : ndarray of bool, shape (len(y), len(x)), optional
        Grid points to evaluate (others are NaN).
    threshold, faults, closed_forms :
        As in :func:`screwkit.analysis.indices_at_poses`.
    scheduler : str, optional
        ``dask.distributed`` scheduler address (default: local threads).
    progress : bool, optional
        Progress bar on stderr (default: when stderr is a terminal).
    as_dataset : bool
        Return an ``xarray.Dataset`` (default) or the plain :class:`GridMap`.

    Returns
    -------
    xarray.Dataset or GridMap
        Coordinates named after the two grid coordinates (``x``, ``y`` for planar maps);
        variables ``iti``, ``lmti``, ``f_o{j}``, ``f_io{j}`` (NaN where unreachable for some
        orientation of the set) and ``reachable_fraction``.
    """
    names = mechanism.task_coordinates
    if len(grid) != 2:
        raise ValueError(f"Expected `grid` with exactly two task coordinates, got {list(grid)}.")
    for name in list(grid) + list(over):
        if name not in names:
            raise ValueError(f"Unknown task coordinate {name!r}; mechanism {mechanism.name!r} has {names}.")
    if set(grid) & set(over):
        raise ValueError(f"A coordinate cannot be both on the grid and in the orientation set: {set(grid) & set(over)}.")
    (x_name, x_values), (y_name, y_values) = ((k, np.asarray(v, dtype=float)) for k, v in grid.items())
    at = mechanism.check_poses(mechanism.home_pose if at is None else at)
    over_axes = tuple(names.index(name) for name in over)
    over_values = np.stack([g.ravel() for g in np.meshgrid(*[np.asarray(v, float) for v in over.values()],
                                                           indexing="ij")], axis=-1) if over else np.zeros((1, 0))
    x_grid, y_grid = np.meshgrid(x_values, y_values)
    mask = np.ones(x_grid.shape, dtype=bool) if mask is None else np.asarray(mask, dtype=bool)
    if mask.shape != x_grid.shape:
        raise ValueError(f"Expected `mask` with shape {x_grid.shape} (y, x), got {mask.shape}.")
    positions = np.flatnonzero(mask.ravel())
    base = np.repeat(at[None], positions.size, axis=0)
    base[:, names.index(x_name)] = x_grid.ravel()[positions]
    base[:, names.index(y_name)] = y_grid.ravel()[positions]
    per_task = max(1, configurations_per_task // max(1, over_values.shape[0]))
    portable = _portable(mechanism)
    faults = None if faults is None else tuple(np.atleast_1d(faults).tolist())
    arguments = [(portable, base[start:start + per_task], over_axes, over_values, threshold, faults, closed_forms)
                 for start in range(0, positions.size, per_task)]
    results = run_tasks(map_task, arguments, scheduler=scheduler, progress=progress, label="map")
    variables = {}
    keys = results[0].keys() if results else ("iti", "lmti", "reachable_fraction")
    for key in keys:
        values = np.full(x_grid.size, np.nan)
        if results:
            values[positions] = np.concatenate([r[key] for r in results])
        variables[key] = values.reshape(x_grid.shape)
    angular = angular_coordinates(names)

    def shown(name, values):
        return np.rad2deg(values) if angular[names.index(name)] else values

    def unit(name):
        return "deg" if angular[names.index(name)] else "m"

    grid_map = GridMap(
        coordinates={x_name: (shown(x_name, x_values), unit(x_name)), y_name: (shown(y_name, y_values), unit(y_name))},
        variables=variables,
        long_names={key: f"minimum of {key} over the orientation set" for key in variables if key != "reachable_fraction"},
        attrs=dict(
            mechanism=mechanism.name, threshold_m=threshold,
            method="closed forms" if closed_forms else "generic screw path",
            orientation_set="; ".join(
                f"{name}: {len(np.unique(over_values[:, i]))} values from {shown(name, over_values[:, i].min()):g} "
                f"to {shown(name, over_values[:, i].max()):g} {unit(name)}" for i, name in enumerate(over))
            or "the fixed pose only",
            fixed_pose=", ".join(f"{n}={shown(n, v):g}" for n, v in zip(names, at) if n not in grid and n not in over),
            configurations=int(positions.size * over_values.shape[0])))
    return grid_map.to_dataset() if as_dataset else grid_map


def planar_disc_map(mechanism, radius: float, step: float, phi_step_degrees: float, *, centre=None, **options):
    """The paper's Fig. 5 map: x, y on a disc about ``centre`` (default the home pose), phi over a full turn.

    ``step`` is the grid spacing (m) and ``phi_step_degrees`` the angular step of the
    rotation 0 <= phi < 360 deg. Other options as in :func:`index_map`.
    """
    if not mechanism.is_planar:
        raise ValueError(f"planar_disc_map needs a planar mechanism; {mechanism.name!r} is spatial (use index_map).")
    for name, value in (("radius", radius), ("step", step), ("phi_step_degrees", phi_step_degrees)):
        if not (np.isfinite(value) and value > 0):
            raise ValueError(f"Expected `{name}` > 0, got {value}.")
    home = np.asarray(mechanism.home_pose, dtype=float)
    centre = home[:2] if centre is None else np.asarray(centre, dtype=float)
    count = int(np.floor(radius / step + 1e-9))
    offsets = step * np.arange(-count, count + 1)
    x_values, y_values = centre[0] + offsets, centre[1] + offsets
    x_grid, y_grid = np.meshgrid(offsets, offsets)
    mask = x_grid**2 + y_grid**2 <= radius**2 * (1 + 1e-12)
    phi = np.deg2rad(np.arange(0.0, 360.0 - 1e-9, phi_step_degrees))
    at = home.copy()
    dataset = index_map(mechanism, {"x": x_values, "y": y_values}, {"phi": phi}, at, mask=mask, **options)
    dataset.attrs.update(radius_m=radius, step_m=step, phi_step_deg=phi_step_degrees)
    return dataset


def _wide_table(dataset):
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


def _netcdf_attribute(value):
    """A global attribute in the type xarray's own netCDF-3 writer gives it (floats stay double)."""
    if isinstance(value, (bool, np.bool_)):
        return np.int8(value)
    if isinstance(value, (int, np.integer)):
        return np.int32(value) if abs(int(value)) < 2**31 else np.float64(value)
    if isinstance(value, (float, np.floating)):
        return np.float64(value)
    return value


def _atomic_text(path, text: str) -> None:
    """Write a text file atomically (temporary file in the same folder, then rename)."""

    def write(temporary):
        with open(temporary, "w", encoding="utf-8") as handle:
            handle.write(text)

    _atomic_write(path, write)


def _atomic_write(path, write) -> None:
    """Call ``write(temporary)`` on a temporary file in the same folder, then rename it to ``path``."""
    path = os.fspath(path)
    folder = os.path.dirname(os.path.abspath(path))
    temporary = os.path.join(folder, f".{os.path.basename(path)}.tmp-{os.getpid()}-{time.time_ns()}")
    try:
        write(temporary)
        os.replace(temporary, path)
    finally:
        if os.path.exists(temporary):
            os.remove(temporary)


def write_dataset(dataset, path) -> None:
    """Write a netCDF (``.nc``) or CSV file atomically: a temporary file in the same folder, then rename.

    ``dataset`` is an ``xarray.Dataset`` or a :class:`GridMap` (written to netCDF without xarray).
    """
    path = os.fspath(path)
    if not path.endswith((".nc", ".csv")):
        raise ValueError(f"Expected an output file ending in .nc or .csv, got {path!r}.")
    if isinstance(dataset, GridMap):
        if path.endswith(".nc"):
            dataset.to_netcdf(path)
            return
        dataset = dataset.to_dataset()
    if path.endswith(".csv"):
        _atomic_write(path, lambda temporary: _wide_table(dataset).to_csv(temporary, index=False))
    else:
        _atomic_write(path, lambda temporary: dataset.to_netcdf(temporary, engine="scipy"))
