"""What was made faster for a long path (issue 29) gives the numbers and bytes it gave before.

Each faster way is checked against the plain definition it replaced, bit for bit: chunks side by side against
a chunk at a time, the local minima and the branch screening against their stacked forms, a CSV read straight
from the file against its whole text, a netCDF path read by scipy's reader against xarray's reading, the streamed
netCDF writer against scipy's own.
"""

from __future__ import annotations

import numpy as np
import pytest

from helpers import bundled
from screwkit.studies import netcdf, poses
from screwkit.studies.branches import STEP_FLOOR, suspect_segments
from screwkit.studies.netcdf import PlainDataset
from screwkit.studies.paths import (
    PathFileError,
    _read_csv_text,
    _read_netcdf,
    _read_plain_csv,
    _read_plain_netcdf,
    read_path,
)
from screwkit.studies.refinement import local_minima


def _stacked_local_minima(values):
    finite = np.where(np.isfinite(values), values, np.inf)
    before = np.vstack([np.full((1, values.shape[1]), np.inf), finite[:-1]])
    after = np.vstack([finite[1:], np.full((1, values.shape[1]), np.inf)])
    dip = (finite <= before) & (finite <= after) & ((finite < before) | (finite < after))
    dip &= np.isfinite(finite) & (finite > 0)
    return np.nonzero(dip)


def _stacked_suspects(steps, lengths):
    with np.errstate(invalid="ignore", divide="ignore"):
        rates = np.where(lengths[:, None] > 0, steps / lengths[:, None], np.nan)
    previous = np.concatenate([np.full((1, steps.shape[1]), np.nan), rates[:-1]])
    following = np.concatenate([rates[1:], np.full((1, steps.shape[1]), np.nan)])
    neighbours = np.stack([previous, following])
    known = np.all(np.isfinite(neighbours), axis=-1)
    mean_rate = np.where(known[..., None], neighbours, 0.0).sum(axis=0) / np.maximum(known.sum(axis=0), 1)[:, None]
    predicted = mean_rate * lengths[:, None]
    miss = np.max(np.abs(steps - predicted), axis=-1)
    return np.isfinite(miss) & (miss > np.max(np.abs(predicted), axis=-1) + STEP_FLOOR)


def test_local_minima_and_branch_screening_are_their_stacked_definitions():
    rng = np.random.default_rng(7)
    for _ in range(2000):
        values = rng.choice([0.0, -1.0, 0.25, 0.5, 1.0, 2.0, np.nan, np.inf, -np.inf], size=rng.integers(1, 8, 2))
        found = local_minima(values)
        for got, wanted in zip(found, _stacked_local_minima(values)):
            np.testing.assert_array_equal(got, wanted)
        steps = rng.choice([0.0, -0.0, 1e-10, 0.1, -0.3, 1.0, np.nan, 5.0], size=rng.integers(1, 8, 2))
        lengths = rng.choice([0.0, 1e-9, 0.1, 1.0], size=steps.shape[0])
        np.testing.assert_array_equal(suspect_segments(steps, lengths), _stacked_suspects(steps, lengths))


@pytest.mark.parametrize("name, count, chunk", [("ups_hexapod_8", 9000, 1024), ("delta_4", 5000, 600)])
def test_chunks_side_by_side_give_the_numbers_of_a_chunk_at_a_time(monkeypatch, name, count, chunk):
    """Many chunks on two threads, each alone on its thread, against the same chunks one at a time (the index
    kernel's cuts the same: below 512 configurations for the Delta, where its motion spaces take numpy)."""
    mechanism = bundled(name)
    rng = np.random.default_rng(3)
    home = np.asarray(mechanism.home_pose, dtype=float)
    spread = np.where(mechanism.angular, np.deg2rad(5.0), 0.03)
    batch = home + rng.uniform(-1, 1, (count, home.size)) * spread
    side_by_side, joints = poses.indices_and_joint_values(mechanism, batch, detail=True, chunk_size=chunk, threads=2)
    monkeypatch.setattr(poses, "CHUNKS_PER_THREAD", 10**9)
    in_turn, joints_in_turn = poses.indices_and_joint_values(mechanism, batch, detail=True, chunk_size=chunk,
                                                             threads=2)
    assert np.count_nonzero(in_turn.reachable) > count // 2
    for field in ("iti", "lmti", "iti_actuators", "oti_submechanisms", "reachable", "chain_status", "full_poses"):
        assert np.asarray(getattr(side_by_side, field)).tobytes() == np.asarray(getattr(in_turn, field)).tobytes()
    for j in in_turn.faults:
        assert side_by_side.f_o[j].tobytes() == in_turn.f_o[j].tobytes()
        assert side_by_side.remaining_lmti[j].tobytes() == in_turn.remaining_lmti[j].tobytes()
    for a, b in zip(joints, joints_in_turn):
        assert a.tobytes() == b.tobytes()
    _, tree = poses.indices_and_joint_values(mechanism, batch[:chunk], tree_only=True)
    _, full = poses.indices_and_joint_values(mechanism, batch[:chunk])
    for values, chain, every in zip(tree, mechanism.chains, full):
        assert values.shape == (chunk, chain.geometry.n_tree_joints)
        assert values.tobytes() == np.ascontiguousarray(every[:, :chain.geometry.n_tree_joints]).tobytes()


def test_a_plain_csv_read_from_the_file_is_read_as_from_its_text(tmp_path):
    hexapod = bundled("ups_hexapod_8")
    rng = np.random.default_rng(5)
    rows = np.asarray(hexapod.home_pose) + rng.normal(0, 0.01, (300, 6))
    rows[:, 3:] = np.rad2deg(rows[:, 3:])
    file = tmp_path / "path.csv"
    np.savetxt(file, np.column_stack([np.arange(300.0), rows, rng.random(300)]), delimiter=",",
               header="t,x,y,z,roll,pitch,yaw,other", comments="\n")  # a blank line before the header
    wanted = (*hexapod.task_coordinates, "t")
    plain, text = _read_plain_csv(str(file), wanted), _read_csv_text(str(file), wanted)
    assert plain is not None and plain.keys() == text.keys()
    for column in plain:
        assert plain[column][1:] == text[column][1:]
        assert (plain[column][0] is None) == (text[column][0] is None)
        if plain[column][0] is not None:
            assert plain[column][0].tobytes() == text[column][0].tobytes()
    np.testing.assert_array_equal(read_path(hexapod, file).poses[:, :3], rows[:, :3])
    file.write_bytes(file.read_bytes().replace(b"\n", b"\r\n"))  # another line end: read as a whole text
    assert _read_plain_csv(str(file), wanted) is None
    np.testing.assert_array_equal(read_path(hexapod, file).poses[:, :3], rows[:, :3])


def test_the_streamed_netcdf_writer_writes_scipys_bytes(tmp_path, monkeypatch):
    rng = np.random.default_rng(9)
    n = netcdf.STREAM_BLOCK + 123  # more than one block
    dataset = PlainDataset(
        {"value": ("sample", rng.random(n), {"units": "m"}), "table": (("sample", "k"), rng.random((n, 3))),
         "flag": ("sample", rng.random(n) > 0.5), "count": ("sample", rng.integers(-5, 5, n)),
         "name": ("k", np.array(["a", "bb", "ccc"]))},
        {"sample": ("sample", np.arange(n, dtype=float)), "k": ("k", np.arange(3))}, {"title": "x", "level": 0.4})
    dataset.write_netcdf(tmp_path / "streamed.nc")
    from scipy.io import netcdf_file

    monkeypatch.setattr(netcdf, "_WRITER", netcdf_file)
    dataset.write_netcdf(tmp_path / "scipy.nc")
    assert (tmp_path / "streamed.nc").read_bytes() == (tmp_path / "scipy.nc").read_bytes()
    monkeypatch.setattr(netcdf, "_WRITER", netcdf.streaming(netcdf_file))  # scipy.io's class, streamed
    dataset.write_netcdf(tmp_path / "scipy_streamed.nc")
    assert (tmp_path / "streamed.nc").read_bytes() == (tmp_path / "scipy_streamed.nc").read_bytes()
    assert netcdf.netcdf_file() is not netcdf_file  # (the class loaded alone was the one compared)


WRITE_ALONE = """
import sys
import numpy as np
from screwkit.studies.netcdf import PlainDataset
PlainDataset({"value": ("sample", np.arange(3.0))}, {}).write_netcdf(sys.argv[1])
print("scipy.io" in sys.modules)
"""


def test_writing_netcdf_does_not_import_scipy_io(tmp_path):
    """scipy's netCDF module is loaded alone (0.12 s less a command); the file reads back through scipy.io."""
    import subprocess
    import sys

    from scipy.io import netcdf_file

    result = subprocess.run([sys.executable, "-W", "error", "-c", WRITE_ALONE, str(tmp_path / "a.nc")],
                            capture_output=True, text=True, timeout=120)
    assert result.returncode == 0 and result.stdout.split() == ["False"], result.stderr
    with netcdf_file(tmp_path / "a.nc", "r", mmap=False) as handle:
        np.testing.assert_array_equal(handle.variables["value"][:], np.arange(3.0))


@pytest.mark.parametrize("texts", [
    ["leg_1:slider", "", "leg_12:leg_12_joint", "x"],  # ASCII, the empty string of an unreachable pose
    ["jambe_é:rotule", "a", "", "腿"],  # not ASCII: one distinct string at a time
    [""], ["", ""],
])
def test_strings_are_encoded_as_numpy_encodes_them(texts):
    rng = np.random.default_rng(3)
    values = np.array(texts)[rng.integers(0, len(texts), (50, 3))]
    expected = np.char.encode(values, "utf-8")
    encoded = netcdf._utf8(values)
    assert encoded.dtype == expected.dtype and encoded.shape == values.shape
    np.testing.assert_array_equal(encoded, expected)


def test_rows_no_chunk_wrote_hold_nan_minus_one_and_false():
    """The batch arrays filled chunk by chunk: a chunk of unreachable poses only, chunks with some and chunks with
    none give every pose the indices it has alone, NaN (-1, False) where unreachable."""
    five = bundled("planar_5rrr")
    rng = np.random.default_rng(2)
    home = np.asarray(five.home_pose, dtype=float)
    near = home + rng.uniform(-1, 1, (30, 3)) * np.array([0.05, 0.05, 0.3])
    far = near + np.array([5.0, 0.0, 0.0])  # five metres off: no leg reaches
    batch = np.concatenate([far[:7], near[:7], np.where((np.arange(16) % 3 == 0)[:, None], far[7:23], near[7:23])])
    result = poses.indices_at_poses(five, batch, detail=True, chunk_size=7)
    reachable = np.asarray(result.reachable)
    assert not reachable[:7].any() and reachable[7:14].all() and 0 < reachable[14:].sum() < 16
    alone = [poses.indices_at_poses(five, pose[None], detail=True) for pose in batch[reachable]]
    for field in ("iti", "lmti", "iti_actuators", "oti_submechanisms", "mutual_interference"):
        values = np.asarray(getattr(result, field))
        expected = np.stack([np.asarray(getattr(one, field))[0] for one in alone])
        np.testing.assert_allclose(values[reachable], expected, rtol=0, atol=1e-13)
        blank = values[~reachable]
        assert np.all(~blank) if blank.dtype == bool else np.all(np.isnan(blank))
    for j in result.faults:
        np.testing.assert_allclose(result.f_o[j][reachable], [one.f_o[j][0] for one in alone], rtol=0, atol=1e-13)
        assert np.all(np.isnan(result.f_o[j][~reachable])) and np.all(np.isnan(result.remaining_lmti[j][~reachable]))
        assert np.all(result.worst_fault_indices[j][~reachable] == -1)
        assert np.all(result.worst_fault_indices[j][reachable] >= 0)


def _xarray_columns(path):
    """Every one-dimensional numeric variable of a netCDF file as xarray decodes it, its units and values."""
    import xarray as xr

    with xr.open_dataset(path, engine="scipy") as dataset:
        return {str(key): (np.asarray(variable.values, dtype=float), str(variable.attrs.get("units", "")))
                for key, variable in {**dataset.coords, **dataset.data_vars}.items()
                if variable.ndim == 1 and np.issubdtype(variable.dtype, np.number)}


def _netcdf_paths(folder):
    """netCDF path files as xarray writes them: (file, whether scipy's reader alone reads it)."""
    import xarray as xr

    rng = np.random.default_rng(5)
    x, y, phi = rng.normal(size=(3, 40)) * [[0.1], [0.1], [30.0]]
    y[7] = np.nan
    plain = {"x": ("s", x, {"units": "m"}), "y": ("s", y), "phi": ("s", phi, {"units": "deg"})}
    files = {
        "plain.nc": (xr.Dataset(plain, coords={"t": ("s", np.arange(40.0), {"units": "s"})}), {}, True),
        # a fill value other than NaN, and a missing value: both read as NaN
        "fill.nc": (xr.Dataset(plain), {"y": {"_FillValue": -999.0}, "x": {"_FillValue": 1e30}}, True),
        "missing_value.nc": (xr.Dataset(plain), {"y": {"missing_value": -5.0, "_FillValue": -5.0}}, True),
        "integers.nc": (xr.Dataset({**plain, "x": ("s", np.arange(40, dtype=np.int32))}), {}, True),
        # strings, booleans and a two-dimensional variable beside the columns: not columns
        "others.nc": (xr.Dataset({**plain, "name": ("s", np.array(["a", "bc"] * 20)),
                                  "ok": ("s", np.arange(40) % 2 == 0), "grid": (("s", "k"), np.ones((40, 2)))}),
                      {}, True),
        # packed values and times since a date: decoded by xarray, so read through it
        "packed.nc": (xr.Dataset(plain), {"x": {"dtype": "int16", "scale_factor": 1e-4, "add_offset": 0.0,
                                                 "_FillValue": -32768}}, False),
        "dated.nc": (xr.Dataset(plain, coords={"t": ("s", np.arange(40.0), {"units": "seconds since 2000-01-01"})}),
                     {}, False),
    }
    made = []
    for name, (dataset, encoding, alone) in files.items():
        dataset.to_netcdf(folder / name, engine="scipy", encoding=encoding)
        made.append((folder / name, alone))
    return made


def test_a_netcdf_path_is_read_as_xarray_reads_it(tmp_path):
    """scipy's reader alone gives every column xarray gives (values, NaN where a fill value is written, units);
    a file xarray decodes further (packed values, dates) is left to xarray, which reads it as before."""
    for path, alone in _netcdf_paths(tmp_path):
        assert (_read_plain_netcdf(str(path), ("x", "y", "phi")) is not None) == alone, path.name
        expected = _xarray_columns(path)
        found = _read_netcdf(str(path), ("x", "y", "phi"))
        assert set(found) == set(expected), path.name
        for key, (values, units) in expected.items():
            np.testing.assert_array_equal(found[key][0], values, err_msg=f"{path.name}: {key}")
            assert found[key][1] == units
            assert ("sample 7" in found[key][2]) == (key == "y" or (key == "x" and path.name == "fill.nc"
                                                                        and np.isnan(values).any()))
    assert _read_plain_netcdf(str(tmp_path / "plain.nc"), ("x", "y", "theta")) is None  # a column missing
    (tmp_path / "empty.nc").write_bytes(b"")  # nothing scipy reads: xarray's reading says what is wrong
    assert _read_plain_netcdf(str(tmp_path / "empty.nc"), ("x",)) is None
    with pytest.raises(PathFileError, match=r"empty.nc: cannot be read as a netCDF file \(") as error:
        _read_netcdf(str(tmp_path / "empty.nc"), ("x",))
    assert "\n" not in str(error.value)


READ_ALONE = """
import sys
from screwkit.io.loader import load
from screwkit.studies.paths import read_path
path = read_path(load("planar_5rrr"), sys.argv[1])
print(path.poses.shape[0], "xarray" in sys.modules, "pandas" in sys.modules)
"""


def test_a_netcdf_path_is_read_without_importing_xarray(tmp_path):
    """Reading a netCDF path imported xarray, pandas and dask.array: a quarter of a second of the command."""
    import subprocess
    import sys

    import xarray as xr

    five = bundled("planar_5rrr")
    home = np.asarray(five.home_pose, dtype=float)
    poses_ = home + np.linspace(0.0, 1.0, 5)[:, None] * np.array([0.02, 0.01, np.deg2rad(5.0)])
    xr.Dataset({"x": ("s", poses_[:, 0]), "y": ("s", poses_[:, 1]),
                "phi": ("s", poses_[:, 2], {"units": "rad"})}).to_netcdf(tmp_path / "p.nc", engine="scipy")
    result = subprocess.run([sys.executable, "-c", READ_ALONE, str(tmp_path / "p.nc")], capture_output=True,
                            text=True, timeout=120)
    assert result.returncode == 0 and result.stdout.split() == ["5", "False", "False"], result.stderr
    np.testing.assert_array_equal(read_path(five, tmp_path / "p.nc").poses, poses_)
