"""Results as CSV tables, written with numpy alone.

A table has one row per point of the dimensions every variable shares (a map's ``y`` and ``x``, a path's
``sample``, a sweep's swept coordinate): their coordinates first, then each variable over exactly those
dimensions, then the other coordinates over them or over none (a path's ``arc_length``), then one column
``name[label]`` per label of a variable with one more dimension (``iti_actuator[chain_1:joint]``; variables with two
more are left out). It is the table pandas writes from the ``xarray.Dataset`` (``to_dataframe``, ``reset_index``,
``to_csv(index=False)``), byte for byte (``tests/test_tables.py``), for a map (:class:`~screwkit.studies.maps.GridMap`),
a path (:class:`~screwkit.studies.netcdf.PlainDataset`) or any dataset, without importing xarray, pandas and,
through xarray, dask.array: 0.4 s of a map command that prints its result.

Cells as pandas writes them: floats as their shortest repr (NaN empty), booleans ``True``/``False``, a field
quoted where it holds a comma, a quote or a line break (a quote doubled).
"""

from __future__ import annotations

import numpy as np

__all__ = ["wide_csv"]


def wide_csv(dataset) -> str:
    """The CSV text of ``dataset`` (an ``xarray.Dataset``, :class:`~screwkit.studies.netcdf.PlainDataset` or
    :class:`~screwkit.studies.maps.GridMap`): the table of the module docstring.

    Raises
    ------
    ValueError
        The variables share no dimension (or there is none).
    """
    dims, coords, variables = _parts(dataset)
    shared = [d for d in dims if variables and all(d in v_dims for v_dims, _ in variables.values())]
    if not shared:
        sizes = {d: _size(d, coords, variables) for d in dims}
        raise ValueError(f"Cannot write a table: the variables share no dimension ({sizes}).")
    exact = [name for name, (v_dims, _) in variables.items() if set(v_dims) == set(shared)]
    order = list(variables[exact[0]][0]) if exact else shared  # the index's, as the first such variable's
    sizes = [_size(d, coords, variables) for d in order]
    names, cells = [], []
    for d in order:  # the grid of the index, C order
        values = coords[d][1] if d in coords else np.arange(_size(d, coords, variables))
        names.append(d)
        cells.append(_along(((d,), np.asarray(values)), order, sizes))
    others = [name for name, (c_dims, _) in coords.items() if name not in dims and set(c_dims) <= set(shared)]
    for name in exact:
        names.append(name)
        cells.append(_along(variables[name], order))
    for name in others:
        c_dims, values = coords[name]
        names.append(name)
        cells.append(_along((c_dims, values), order, sizes))
    for name, (v_dims, values) in variables.items():
        extra = [d for d in v_dims if d not in shared]
        if len(extra) != 1:
            continue
        labels = coords[extra[0]][1] if extra[0] in coords else np.arange(values.shape[v_dims.index(extra[0])])
        moved = np.moveaxis(values, [v_dims.index(d) for d in order + extra], range(len(order) + 1))
        for k, label in enumerate(np.asarray(labels)):
            names.append(f"{name}[{label.decode() if isinstance(label, bytes) else label}]")
            cells.append(moved[..., k].reshape(-1))
    columns = [_text(column) for column in cells]
    rows = [",".join(_quoted(names))]
    rows.extend(",".join(row) for row in zip(*columns))
    return "\n".join(rows) + "\n"


def _parts(dataset) -> tuple[list[str], dict, dict]:
    """The dimensions (in order of first appearance), coordinates and variables ``{name: (dims, values)}``."""
    if hasattr(dataset, "long_names"):  # a GridMap: coordinates x axis first, variables over (y, x)
        (x_name, (x, _)), (y_name, (y, _)) = dataset.coordinates.items()
        coords = {x_name: ((x_name,), np.asarray(x)), y_name: ((y_name,), np.asarray(y))}
        variables = {name: ((y_name, x_name), np.asarray(values)) for name, values in dataset.variables.items()}
    elif hasattr(dataset, "data_vars"):  # an xarray.Dataset
        coords = {name: (tuple(v.dims), v.values) for name, v in dataset.coords.items()}
        variables = {name: (tuple(v.dims), v.values) for name, v in dataset.data_vars.items()}
    else:  # a PlainDataset: (dims, values[, attrs])
        coords = {name: _entry(name, entry) for name, entry in dataset.coords.items()}
        variables = {name: _entry(name, entry) for name, entry in dataset.variables.items()}
    dims = list(dict.fromkeys(d for v_dims, _ in [*variables.values(), *coords.values()] for d in v_dims))
    return dims, coords, variables


def _entry(name: str, entry: tuple) -> tuple[tuple[str, ...], np.ndarray]:
    dims, values = entry[0], np.asarray(entry[1])
    return ((dims,) if isinstance(dims, str) else tuple(dims)), values


def _size(dim: str, coords: dict, variables: dict) -> int:
    for v_dims, values in [*variables.values(), *coords.values()]:
        if dim in v_dims:
            return values.shape[v_dims.index(dim)]
    raise KeyError(dim)


def _along(entry: tuple, order: list[str], sizes: list[int] | None = None) -> np.ndarray:
    """A variable over some or all of ``order``'s dimensions (one: an index level's coordinate), at every row (C
    order over ``sizes``, which a variable over fewer dimensions than ``order`` needs)."""
    v_dims, values = entry
    moved = np.moveaxis(values, [v_dims.index(d) for d in order if d in v_dims],
                        range(sum(d in v_dims for d in order)))
    if sizes is not None and len(v_dims) < len(order):
        shape = [sizes[k] if d in v_dims else 1 for k, d in enumerate(order)]
        moved = np.broadcast_to(moved.reshape(shape), sizes)
    return moved.reshape(-1)


def _text(values: np.ndarray) -> list[str]:
    """The cells of one column."""
    if values.dtype.kind == "f":
        text = values.astype(str)
        text[np.isnan(values)] = ""
        return text.tolist()
    if values.dtype.kind in "biu":  # (digits, True, False: nothing to quote)
        return values.astype(str).tolist()
    if values.dtype.kind == "S":
        return _quoted([value.decode() for value in values])
    return _quoted(["" if value is None or (isinstance(value, float) and np.isnan(value)) else str(value)
                    for value in values])


def _quoted(text: list[str]) -> list[str]:
    """CSV's minimal quoting: a field with a comma, a quote or a line break in quotes, its quotes doubled."""
    return ['"' + cell.replace('"', '""') + '"' if any(c in cell for c in ',"\r\n') else cell for cell in text]
