"""CSV tables written with numpy alone (:mod:`screwkit.studies.tables`) are the bytes pandas writes from the same
dataset: maps, sweeps and paths as the studies give them, graph mechanisms' too, and a dataset with every kind of
cell (NaN, booleans, integers, labels with commas and quotes, a coordinate over the shared dimension, a dimension
with no coordinate, a variable with two more dimensions)."""

from __future__ import annotations

import io
import json
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest
import xarray as xr

from helpers import bundled, screwkit
from screwkit.io import graph_mechanism, read_closed_tree
from screwkit.io.loader import bundled_path
from screwkit.studies.maps import index_map
from screwkit.studies.netcdf import PlainDataset
from screwkit.studies.paths import line_path
from screwkit.studies.sweep import sweep
from screwkit.studies.tables import wide_csv
from screwkit.studies.tasks import Execution
from screwkit.studies.trajectory import trajectory

QUIET = Execution(progress=False)


def pandas_table(dataset: xr.Dataset) -> str:
    """The reference: one row per point of the dimensions every variable shares, as xarray's ``to_dataframe`` and
    pandas' ``to_csv`` make it, and a column per label of a variable with one more dimension."""
    shared = [d for d in dataset.dims if all(d in dataset[v].dims for v in dataset.data_vars)]
    frame = dataset[[v for v in dataset.data_vars if set(dataset[v].dims) == set(shared)]].to_dataframe()
    order = list(frame.index.names)
    columns = {}
    for name in dataset.data_vars:
        extra = [d for d in dataset[name].dims if d not in shared]
        if len(extra) == 1:
            for label in dataset[extra[0]].values:
                columns[f"{name}[{label}]"] = dataset[name].sel({extra[0]: label}).transpose(*order).values.ravel()
    return pd.concat([frame.reset_index(), pd.DataFrame(columns)], axis=1).to_csv(index=False)


def test_a_map_s_table_is_the_one_pandas_writes():
    five = bundled("planar_5rrr")
    grid = {"x": np.linspace(-1.2, 1.2, 5), "y": np.linspace(-0.2, 0.2, 4)}  # (the ends out of reach)
    mapped = index_map(five, grid, {"phi": np.radians([0.0, 40.0])}, execution=QUIET, as_dataset=False)
    assert np.isnan(mapped.variables["iti"]).any() and not np.isnan(mapped.variables["iti"]).all()
    text = wide_csv(mapped)
    assert text == pandas_table(mapped.to_dataset()) == wide_csv(mapped.to_dataset())
    assert text.splitlines()[0].startswith("y,x,") and len(text.splitlines()) == 1 + 5 * 4


def test_a_graph_mechanism_s_map_table_is_the_one_pandas_writes():
    delta = graph_mechanism(read_closed_tree(bundled_path("delta_rods_4")))
    home = delta.home_pose
    grid = {"x": home[0] + np.array([-0.01, 0.0, 0.01]), "y": home[1] + np.array([0.0, 0.01])}
    mapped = index_map(delta, grid, {}, execution=QUIET, as_dataset=False)
    assert wide_csv(mapped) == pandas_table(mapped.to_dataset())


def test_a_sweep_s_table_with_its_per_actuator_and_per_set_columns_is_the_one_pandas_writes():
    five = bundled("planar_5rrr")
    swept = sweep(five, five.home_pose, "phi", np.radians(np.arange(-40.0, 41.0, 20.0)))
    text = wide_csv(swept)
    assert text == pandas_table(swept)
    header = text.splitlines()[0]
    assert "iti_actuator[" in header and "lmti_remaining1[" in header


@pytest.mark.parametrize("options", [{}, {"aggregate": "mean"}, {"times": np.linspace(0.0, 2.0, 7)}])
def test_a_path_s_table_is_the_one_pandas_writes(options):
    five = bundled("planar_5rrr")
    poses = line_path(five, [-0.3, -0.2, -0.5], [0.3, 0.2, 0.5], 7).poses
    result = trajectory(five, poses, **options)
    plain = result.plain_dataset()
    text = wide_csv(plain)
    assert text == pandas_table(plain.to_dataset()) == wide_csv(result.to_dataset())
    assert "arc_length" in text.splitlines()[0] and ("t" in text.splitlines()[0].split(",")) == ("times" in options)


def test_every_kind_of_cell_is_written_as_pandas_writes_it():
    rng = np.random.default_rng(3)
    values = rng.normal(size=(4, 3)) * 10.0 ** rng.integers(-12, 12, size=(4, 3))
    values[1, 2] = np.nan
    values[2, 0] = -0.0
    plain = PlainDataset(
        variables={"value": (("row", "column"), values),
                   "flag": (("column", "row"), rng.normal(size=(3, 4)) > 0),
                   "count": ("row", np.arange(4, dtype=np.int64) * 7 - 5),
                   "name": ("row", np.array(["plain", 'with "quotes"', "a, comma", "line\nbreak"], dtype=object)),
                   "cube": (("row", "column", "other"), np.zeros((4, 3, 2))),
                   "unlabelled": (("row", "free"), rng.normal(size=(4, 2)))},
        coords={"row": ("row", np.array([0.5, 1.0, 1.5, 2.0])),
                "column": ("column", np.array(["a", "b,c", 'd"e'], dtype=object)),
                "weight": ("row", np.array([1.0, np.nan, 3.0, 4.0])), "scale": ((), 2.5),
                "origin": ((), "x, y")})
    text = wide_csv(plain)
    assert text == pandas_table(plain.to_dataset())
    assert '"value[b,c]"' in text.splitlines()[0] and "cube" not in text  # (two more dimensions: left out)
    assert ',2.5,"x, y",' in text.splitlines()[1]  # (the scalar coordinates, in every row)


def test_variables_that_share_no_dimension_are_refused_in_one_line():
    plain = PlainDataset(variables={"a": ("one", np.zeros(2)), "b": ("two", np.zeros(3))}, coords={})
    with pytest.raises(ValueError, match=r"^Cannot write a table: the variables share no dimension "
                                         r"\(\{'one': 2, 'two': 3\}\)\.$"):
        wide_csv(plain)


def test_the_commands_print_and_write_the_table_pandas_writes_from_their_netcdf_file(tmp_path):
    """``map`` and ``trajectory`` print their table (no output file) and write it (``--out X.csv``): the table pandas
    writes from the netCDF file the same command writes, read back by xarray (the columns in the order of the
    dataset, which the file's variables need not keep)."""
    commands = {"map": ["map", "planar_5rrr", "--radius", "0.3", "--step", "0.1", "--phi-step", "30", "--quiet"],
                "trajectory": ["trajectory", "planar_5rrr", "--line", "-0.2 -0.1 -20", "0.2 0.1 20", "--samples", "9",
                               "--quiet"]}
    for name, arguments in commands.items():
        printed = screwkit(*arguments)
        assert printed.returncode == 0, printed.stderr
        for suffix in ("nc", "csv"):
            written = screwkit(*arguments, "--out", tmp_path / f"{name}.{suffix}")
            assert written.returncode == 0 and written.stdout == "", written.stderr
        with xr.open_dataset(tmp_path / f"{name}.nc", engine="scipy") as dataset:
            expected = pandas_table(dataset.load())
        assert printed.stdout == (tmp_path / f"{name}.csv").read_text(), name
        table, reference = (pd.read_csv(io.StringIO(text), keep_default_na=False, dtype=str)
                            for text in (printed.stdout, expected))
        assert sorted(table.columns) == sorted(reference.columns) and len(table) == len(reference) >= 9, name
        pd.testing.assert_frame_equal(table, reference[table.columns])  # every cell's text


LEAN = """
import json, sys
from screwkit.cli import app
try:
    app(sys.argv[1:], standalone_mode=False)
finally:
    print(json.dumps(sorted(m for m in ("xarray", "pandas", "dask") if m in sys.modules)), file=sys.stderr)
"""


@pytest.mark.parametrize("arguments", [
    ["map", "planar_5rrr", "--radius", "0.1", "--step", "0.1", "--phi-step", "90", "--quiet"],
    ["sweep", "planar_5rrr", "--at", "-0.2 0", "--phi", "0:360:30", "--quiet"],
    ["trajectory", "planar_5rrr", "--line", "-0.2 -0.1 -20", "0.2 0.1 20", "--samples", "5", "--quiet"]])
@pytest.mark.parametrize("out", [None, "csv", "nc"])
def test_the_studies_print_and_write_without_importing_xarray_pandas_or_dask(tmp_path, arguments, out):
    """What pandas needs xarray and xarray imports dask.array for (0.5 s of a command that prints its table)."""
    given = arguments + ([] if out is None else ["--out", str(tmp_path / f"result.{out}")])
    result = subprocess.run([sys.executable, "-W", "error", "-c", LEAN, *given], capture_output=True, text=True,
                            timeout=300)
    assert result.returncode == 0, result.stderr
    assert json.loads(result.stderr.strip().splitlines()[-1]) == []
    assert (result.stdout.count("\n") > 3) == (out is None)


def test_the_sweep_command_s_file_reads_back_as_the_dataset_the_api_returns(tmp_path):
    five = bundled("planar_5rrr")
    swept = sweep(five, [-0.2, 0.0, 0.0], "phi", np.radians(np.arange(0.0, 360.0, 30.0)))
    written = screwkit("sweep", "planar_5rrr", "--at", "-0.2 0", "--phi", "0:360:30", "--quiet", "--out",
                       tmp_path / "sweep.nc")
    assert written.returncode == 0, written.stderr
    with xr.open_dataset(tmp_path / "sweep.nc", engine="scipy") as dataset:
        xr.testing.assert_identical(dataset.load(), swept)
