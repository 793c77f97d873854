"""A dataset as plain numpy arrays, written to netCDF-3 as xarray writes it, without importing xarray.

xarray, pandas and dask.array take about a second to import, and xarray's netCDF writer another second on a
100,000-sample path: a command that only writes a file needs neither. :class:`PlainDataset` holds what an
``xarray.Dataset`` would (variables and coordinates as ``(dims, values[, attrs])``, global attributes);
:meth:`PlainDataset.write_netcdf` writes it with ``scipy.io.netcdf_file`` in xarray's own encoding of netCDF-3,
so that ``xarray.open_dataset`` reads back exactly what :meth:`PlainDataset.to_dataset` would have written:

* floats as themselves with ``_FillValue`` NaN;
* booleans as bytes with the attribute ``dtype: bool``;
* 64-bit integers as 32-bit ones (netCDF-3 has no other), refused if they do not fit;
* strings encoded in UTF-8 as characters along one more dimension ``string{N}`` (``N`` the longest, in
  bytes), with the attribute ``_Encoding: utf-8``;
* every coordinate that is not a dimension named in the ``coordinates`` attribute of each variable that
  spans its dimensions (the others in the global ``coordinates``).
"""

from __future__ import annotations

import functools
import importlib.util
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from screwkit.studies.files import atomic_write, output_suffix

__all__ = ["PlainDataset", "netcdf_attribute", "netcdf_file"]


@functools.cache
def netcdf_file() -> type:
    """``scipy.io.netcdf_file``, without importing ``scipy.io``.

    ``scipy.io`` imports its MATLAB reader and, through it, ``scipy.sparse`` and scipy's array-API layer: 0.12 s of
    every command that writes a netCDF file, for a module (``scipy/io/_netcdf.py``) that needs only numpy and the
    standard library. That module is loaded alone from scipy's folder; ``scipy.io``'s own class where it is not
    there or does not load alone (a later scipy that gives it imports of its own package)."""
    found = importlib.util.find_spec("scipy")
    folders = list(found.submodule_search_locations or []) if found is not None else []
    source = Path(folders[0], "io", "_netcdf.py") if folders else None
    if source is not None and source.is_file():
        try:
            alone = importlib.util.spec_from_file_location("screwkit.studies._scipy_netcdf", source)
            module = importlib.util.module_from_spec(alone)
            alone.loader.exec_module(module)
            return module.netcdf_file
        except (ImportError, AttributeError, SyntaxError):
            pass
    from scipy.io import netcdf_file as scipy_netcdf_file

    return scipy_netcdf_file


@dataclass
class PlainDataset:
    """What an ``xarray.Dataset`` holds, as plain arrays.

    Attributes
    ----------
    variables, coords : dict of str to tuple
        ``(dims, values)`` or ``(dims, values, attrs)``, as ``xarray.Variable`` takes them.
    attrs : dict
        Global attributes (str, numbers).
    """

    variables: dict[str, tuple]
    coords: dict[str, tuple]
    attrs: dict[str, Any] = field(default_factory=dict)

    def to_dataset(self):
        """The ``xarray.Dataset``."""
        import xarray as xr

        dataset = xr.Dataset({k: xr.Variable(*v) for k, v in self.variables.items()}, coords=self.coords)
        dataset.attrs.update(self.attrs)
        return dataset

    def write_netcdf(self, path) -> None:
        """Write a netCDF-3 file (``scipy.io.netcdf_file``) atomically, in xarray's encoding (module docstring).

        Raises
        ------
        ValueError
            A variable of a type netCDF-3 cannot hold, or integers beyond 32 bits.
        """
        output_suffix(path, (".nc",))
        everything = {name: _variable(name, entry) for name, entry in {**self.coords, **self.variables}.items()}
        sizes = {}
        for name, (dims, values, _) in everything.items():
            for dim, size in zip(dims, values.shape):
                if sizes.setdefault(dim, size) != size:
                    raise ValueError(f"Variable {name!r}: dimension {dim!r} of size {size}, elsewhere {sizes[dim]}.")
        placed = _coordinates(self.coords, self.variables)

        def write(temporary):
            with _netcdf_writer()(temporary, "w", version=2) as handle:
                for dim, size in sizes.items():
                    handle.createDimension(dim, size)
                for name, (dims, values, attrs) in everything.items():
                    variable = handle.createVariable(name, values.dtype.char if values.dtype.char != "S" else "c", dims)
                    if getattr(handle, "streams", False):
                        handle._screwkit_sources[name] = values  # written when the file closes, a block at a time
                    else:
                        variable[:] = values
                    for key, value in attrs.items():
                        setattr(variable, key, netcdf_attribute(value))
                    if name in placed:
                        variable.coordinates = placed[name]
                for key, value in self.attrs.items():
                    if key in handle.__dict__:
                        raise ValueError(f"Cannot write a global attribute named {key!r} to netCDF.")
                    setattr(handle, key, netcdf_attribute(value))
                if placed.get(None):
                    handle.coordinates = placed[None]

        atomic_write(path, write)


STREAM_BLOCK = 1 << 16
"""Values converted to big-endian and written at a time by the writer of :meth:`PlainDataset.write_netcdf`."""
_WRITER = None


def _netcdf_writer():
    """:func:`netcdf_file`, writing each variable's values from the array given, in blocks of
    :data:`STREAM_BLOCK` converted to the file's big-endian order, instead of from a big-endian copy of the whole
    array made when it is given and copied again to bytes when written (a path's 76 MB file took three times its
    size in memory): the same bytes. scipy's own writer (``streams`` False) where its writing of a variable's data
    is not the one this replaces."""
    global _WRITER
    if _WRITER is None:
        _WRITER = streaming(netcdf_file())
    return _WRITER


def streaming(base: type) -> type:
    """``base`` (a ``netcdf_file`` class) writing each variable's values in blocks (:func:`_netcdf_writer`);
    ``base`` itself if it has not the methods this replaces."""
    needed = ("_write_var_data", "_pack_begin", "_write_var_padding")
    if not all(hasattr(base, name) for name in needed):
        return base

    class StreamingNetCDF(base):
        streams = True

        def __init__(self, *args, **kwargs):
            self._screwkit_sources = {}  # before scipy sets up its attributes: not one of the file
            super().__init__(*args, **kwargs)

        def _write_var_data(self, name):
            variable, source = self.variables[name], self._screwkit_sources.get(name)
            if source is None or variable.isrec:
                return super()._write_var_data(name)
            begin = self.fp.tell()  # where the data starts, in the header (as scipy writes it)
            self.fp.seek(variable._begin)
            self._pack_begin(begin)
            self.fp.seek(begin)
            flat = np.ascontiguousarray(source).reshape(-1)
            for start in range(0, flat.size, STREAM_BLOCK):
                self.fp.write(flat[start:start + STREAM_BLOCK].astype(variable.data.dtype).tobytes())
            self._write_var_padding(variable, variable._vsize - flat.size * variable.data.itemsize)

    return StreamingNetCDF


def netcdf_attribute(value):
    """An attribute in the type xarray's own netCDF-3 writer gives it (floats stay double, booleans are bytes)."""
    if isinstance(value, (bool, np.bool_)):
        return np.int8(value)
    if isinstance(value, (int, np.integer)):
        return np.int32(value) if abs(int(value)) < 2**31 else np.float64(value)
    if isinstance(value, (float, np.floating)):
        return np.float64(value)
    return value


def _variable(name: str, entry: tuple) -> tuple[tuple[str, ...], np.ndarray, dict]:
    """``(dims, values, attrs)`` of one variable in netCDF-3's types, with the attributes xarray adds."""
    dims, values, attrs = (tuple(entry) + ({},))[:3]
    dims = (dims,) if isinstance(dims, str) else tuple(dims)
    values = np.asarray(values)
    attrs = dict(attrs or {})
    if values.ndim != len(dims):
        raise ValueError(f"Variable {name!r}: {len(dims)} dimension(s) {dims} for values of shape {values.shape}.")
    kind = values.dtype.kind
    if kind == "b":
        return dims, values.astype(np.int8), {**attrs, "dtype": "bool"}
    if kind == "f":
        return dims, values, {**attrs, "_FillValue": values.dtype.type(np.nan)}
    if kind == "i":
        if values.size and (values.min() < -2**31 or values.max() >= 2**31):
            raise ValueError(f"Variable {name!r}: integers beyond 32 bits cannot be written to netCDF-3.")
        return dims, values.astype(np.int32) if values.dtype.itemsize > 4 else values, attrs
    if kind in "UO":
        encoded = _utf8(values if kind == "U" else values.astype(str))
        width = max(encoded.dtype.itemsize, 1)
        characters = encoded.astype(f"S{width}").reshape(values.shape + (1,)).view("S1")
        return dims + (f"string{width}",), characters, {**attrs, "_Encoding": "utf-8"}
    raise ValueError(f"Variable {name!r}: values of type {values.dtype} cannot be written to netCDF-3.")


def _utf8(values: np.ndarray) -> np.ndarray:
    """Strings encoded in UTF-8, as bytes as long as the longest (as ``np.char.encode`` gives them): ASCII by
    narrowing numpy's code points (four bytes each) to one byte each, anything else one distinct string at a time."""
    width = values.dtype.itemsize // 4
    if width == 0 or values.size == 0:
        return np.zeros(values.shape, dtype="S1")
    codes = np.ascontiguousarray(values).view(np.uint32).reshape(values.shape + (width,))
    if int(codes.max()) >= 128:
        unique, inverse = np.unique(values, return_inverse=True)
        return np.array([text.encode("utf-8") for text in unique], dtype=bytes)[inverse].reshape(values.shape)
    used = np.flatnonzero(codes.reshape(-1, width).any(axis=0))
    longest = int(used[-1]) + 1 if used.size else 1  # trailing zeros are numpy's padding, not characters
    return np.ascontiguousarray(codes[..., :longest]).astype(np.uint8).view(f"S{longest}").reshape(values.shape)


def _coordinates(coords: dict[str, tuple], variables: dict[str, tuple]) -> dict[str | None, str]:
    """xarray's ``coordinates`` attributes: per variable, the non-dimension coordinates over some of its dimensions
    (sorted); under None, those no variable names."""
    def dims_of(entry):
        return {entry[0]} if isinstance(entry[0], str) else set(entry[0])

    auxiliary = {name: dims_of(entry) for name, entry in coords.items() if dims_of(entry) != {name}}
    placed, used = {}, set()
    for name, entry in variables.items():
        mine = sorted(c for c, c_dims in auxiliary.items() if c_dims <= dims_of(entry) and name not in dims_of(entry))
        if mine:
            placed[name] = " ".join(mine)
            used.update(mine)
    leftover = sorted(set(auxiliary) - used)
    if leftover:
        placed[None] = " ".join(leftover)
    return placed
