"""`screwkit plot` of a trajectory's netCDF file, the trajectory figure's time axis, and the index values `plot`
accepts."""

from __future__ import annotations

import re

import numpy as np
import pytest

from helpers import one_line_error, screwkit
from screwkit.io.loader import load
from screwkit.plots.trajectory import time_ticks, trajectory_figure
from screwkit.studies.paths import path_from_poses
from screwkit.studies.trajectory import trajectory


def _png(path) -> np.ndarray:
    from PIL import Image

    with Image.open(path) as image:
        return np.asarray(image.convert("RGBA"))


@pytest.mark.parametrize("source", [
    ["--line", "-0.3", "-0.2", "-45", "0.3", "0.2", "45", "--samples", "21"],
    ["--line", "0", "0", "0", "1.2", "0", "0", "--samples", "13", "--aggregate", "mean"],  # unreachable stretch
    ["TIMED"],
])
def test_plot_of_a_trajectory_file_is_the_trajectory_figure(source, tmp_path):
    """`plot path.nc` draws, pixel for pixel, the figure `trajectory --figure` drew from the same run (it used to
    take the file for a sweep over sample numbers drawn as metres); --vmin is refused."""
    if source == ["TIMED"]:
        table = tmp_path / "timed.csv"
        table.write_text("t,x,y,phi\n0.23,-0.2,0,0\n0.33,-0.15,0,5\n0.93,-0.05,0,15\n1.73,0,0,20\n3.43,0.2,0,40\n")
        source = [table]
    data, drawn, again = tmp_path / "path.nc", tmp_path / "drawn.png", tmp_path / "again.png"
    outcome = screwkit("trajectory", "planar_5rrr", *source, "--level", "0.6", "--out", data, "--figure", drawn)
    assert outcome.returncode == 0, outcome.stderr
    outcome = screwkit("plot", data, "--figure", again)
    assert outcome.returncode == 0, outcome.stderr
    assert "the trajectory of planar_5rrr" in outcome.stderr
    np.testing.assert_array_equal(_png(again), _png(drawn))
    one_line_error(screwkit("plot", data, "--figure", tmp_path / "x.png", "--vmin", "0.2"), "holds a trajectory")


def test_a_file_over_samples_without_the_trajectory_summary_is_refused(tmp_path):
    import xarray as xr

    data = tmp_path / "path.nc"
    outcome = screwkit("trajectory", "planar_5rrr", "--line", "-0.3", "-0.2", "-45", "0.3", "0.2", "45", "--samples",
                       "5", "--out", data)
    assert outcome.returncode == 0, outcome.stderr
    with xr.open_dataset(data, engine="scipy") as dataset:
        bare = dataset.load()
    del bare.attrs["summary"]
    bare.to_netcdf(tmp_path / "bare.nc", engine="scipy")
    one_line_error(screwkit("plot", tmp_path / "bare.nc", "--figure", tmp_path / "x.png"),
                   "bare.nc", "along a path", "screwkit trajectory ... --figure")
    assert not (tmp_path / "x.png").exists()


def _top_ticks(figure):
    """Positions (m of arc length) and labels of the time axis over panel (a)."""
    top = [axis for axis in figure.axes[0].child_axes if axis.get_xlabel() == "t (s)"]
    assert len(top) == 1
    figure.canvas.draw()
    positions = np.asarray(top[0].get_xticks(), dtype=float)
    labels = [label.get_text() for label in top[0].get_xticklabels()]
    lo, hi = figure.axes[0].get_xlim()
    shown = (positions >= lo) & (positions <= hi)
    return positions[shown], [label for label, keep in zip(labels, shown) if keep]


def _trajectory_result(times, poses_deg):
    planar = load("planar_5rrr")
    poses = np.array(poses_deg, dtype=float)
    poses[:, 2] = np.deg2rad(poses[:, 2])
    return trajectory(planar, path_from_poses(planar, poses, np.array(times, dtype=float)), level=0.6)


def test_time_ticks_are_at_times_the_path_reaches_where_it_reaches_them():
    """Times 0.23 .. 3.43 s, uneven: every tick label is a time within them, at the arc length where the path's own
    times put it (linear between samples); no label at 0 or 3.5 (it used to clamp them onto the ends)."""
    times = [0.23, 0.33, 0.53, 0.93, 1.73, 1.83, 1.93, 3.23, 3.43]
    result = _trajectory_result(times, [[-0.2 + 0.05 * k, 0.0, 5.0 * k] for k in range(9)])
    positions, labels = _top_ticks(trajectory_figure(result))
    assert len(labels) >= 3
    s, t = result.path.arc_length, result.path.times
    for position, label in zip(positions, labels):
        value = float(label)
        assert t[0] <= value <= t[-1], label
        np.testing.assert_allclose(position, np.interp(value, t, s), atol=1e-12)
        np.testing.assert_allclose(np.interp(position, s, t), value, atol=1e-9)  # and back: the path's time there
    assert len(set(np.round(positions, 9))) == len(positions)


def test_a_dwell_gets_one_tick_labelled_with_its_span():
    """The platform stays put from 1 s to 2 s: one tick there, labelled 1–2 (arrival–departure), at the dwell's arc
    length; no tick for a time inside the dwell; the others at the path's own arc length for their time."""
    result = _trajectory_result([0, 1, 2, 3], [[-0.1, 0, 0], [0, 0, 10], [0, 0, 10], [0.1, 0, 20]])
    positions, labels = _top_ticks(trajectory_figure(result))
    s, t = result.path.arc_length, result.path.times
    assert labels.count("1–2") == 1
    np.testing.assert_allclose(positions[labels.index("1–2")], s[1], atol=1e-12)
    for position, label in zip(positions, labels):
        if label == "1–2":
            continue
        value = float(label)
        assert 0 <= value <= 3 and not 1 <= value <= 2, label
        np.testing.assert_allclose(position, np.interp(value, t, s), atol=1e-12)
    assert np.all(np.diff(positions) > 0)  # no two labels on top of each other
    positions, labels = time_ticks(s, t)
    assert all(re.fullmatch(r"[\d.]+(–[\d.]+)?", label) for label in labels)


def test_plot_refuses_index_values_outside_0_1(tmp_path):
    import xarray as xr

    data = tmp_path / "sweep.nc"
    outcome = screwkit("sweep", "planar_5rrr", "--phi", "0:40:10", "--out", data)
    assert outcome.returncode == 0, outcome.stderr
    with xr.open_dataset(data, engine="scipy") as dataset:
        good = dataset.load()
    for name, value in (("iti", np.inf), ("f_o1", 7.0), ("lmti", -0.5)):
        bad = good.copy(deep=True)
        bad[name].values[1] = value
        bad.to_netcdf(tmp_path / "bad.nc", engine="scipy")
        one_line_error(screwkit("plot", tmp_path / "bad.nc", "--figure", tmp_path / "x.png", "--overwrite"),
                       "bad.nc", f"'{name}'", "outside [0, 1]")
    unreachable = good.copy(deep=True)
    unreachable["iti"].values[1] = np.nan  # NaN: unreachable, drawn
    unreachable.to_netcdf(tmp_path / "nan.nc", engine="scipy")
    assert screwkit("plot", tmp_path / "nan.nc", "--figure", tmp_path / "nan.png").returncode == 0


def test_a_reachable_sample_between_two_out_of_reach_is_drawn():
    """The 5-RRR along x from 0 to 1.2 m in 13 samples reaches 1.0 m between two samples out of reach (0.9, 1.1 m):
    a line alone drew nothing there; now every index of panel (a) has a dot at that sample, at its value."""
    from screwkit.io.loader import load
    from screwkit.plots.trajectory import trajectory_figure
    from screwkit.studies.paths import line_path
    from screwkit.studies.trajectory import trajectory

    five = load("planar_5rrr")
    result = trajectory(five, line_path(five, [0.0, 0.0, 0.0], [1.2, 0.0, 0.0], 13))
    reachable = np.asarray(result.indices.reachable)
    assert reachable[[8, 10]].all() and not reachable[[9, 11, 12]].any()
    figure = trajectory_figure(result)
    dots = [line for line in figure.axes[0].lines if line.get_marker() == "."]
    at = result.path.arc_length[10]
    drawn = {round(float(y), 12) for line in dots for x, y in zip(line.get_xdata(), line.get_ydata()) if x == at}
    expected = [result.indices.iti[10], result.indices.lmti[10], *(result.indices.f_o[j][10] for j in (1, 2)),
                *(result.indices.f_io[j][10] for j in (1, 2))]
    assert {round(float(v), 12) for v in expected} <= drawn
    assert all(x == at for line in dots for x in line.get_xdata())  # no dot where a line is drawn
