"""Sweeps, workspace maps, Dask execution and design search."""

from __future__ import annotations

import json
import os
import signal
import threading
import time

import numpy as np
import pytest
import xarray as xr

from helpers import screwkit
from screwkit.cli.options import parse_range
from screwkit.closure import chain_screws, solve
from screwkit.indices.analysis import analyze
from screwkit.indices.closed_forms import planar_indices
from screwkit.io.loader import load
from screwkit.screw.planar import paper_5rrr, planar_joint_points, rrr_chain_screws
from screwkit.studies.design.permutations import permutation_search, planar_design, rotation_class
from screwkit.studies.files import write_dataset
from screwkit.studies.maps import GridMap, index_map, planar_disc_map
from screwkit.studies.options import AnalysisOptions
from screwkit.studies.sweep import sweep
from screwkit.studies.tasks import Execution

QUIET = Execution(progress=False)
"""Local threads, no progress bar."""


@pytest.fixture(scope="module")
def five():
    return load("planar_5rrr")


def hand_built_minimum(x, y, phi):
    """Minimum over phi of each index at (x, y), from hand-built screws (independent of the URDF path)."""
    poses = np.column_stack([np.full_like(phi, x), np.full_like(phi, y), phi])
    base, elbows, distal, reachable = planar_joint_points(paper_5rrr(), poses)
    if not reachable.all():
        return None
    result = analyze(rrr_chain_screws(base, elbows, distal), detail=False)
    return {"iti": result.iti.min(), "lmti": result.lmti.min(), "f_o1": result.f_o[1].min(),
            "f_io1": result.f_io[1].min()}


def test_parse_range():
    import click

    assert parse_range("0:360:0.1", "--phi").size == 3600
    np.testing.assert_allclose(parse_range("0:1:0.25", "--over"), [0, 0.25, 0.5, 0.75])
    np.testing.assert_allclose(parse_range("-0.2:0.2:0.1", "--grid", include_stop=True), [-0.2, -0.1, 0, 0.1, 0.2])
    np.testing.assert_allclose(parse_range("0:90:45", "--over", angular=True), np.deg2rad([0, 45]))
    with pytest.raises(click.ClickException, match=r"START:STOP:STEP \(three numbers\), got '0:1'"):
        parse_range("0:1", "--phi")
    with pytest.raises(click.ClickException, match="STEP > 0"):
        parse_range("0:1:-1", "--phi")


def test_sweep_at_the_centre_matches_fig_4(five):
    phi = parse_range("0:360:0.1", "--phi", angular=True)
    dataset = sweep(five, [0, 0, 0], "phi", phi)
    assert 0.600 < float(dataset["f_o1"].min()) < 0.601  # Fig. 4(d), 0.6005 at 0.1 deg
    minimum = hand_built_minimum(0.0, 0.0, phi)
    assert float(dataset["f_o1"].min()) == pytest.approx(minimum["f_o1"], abs=1e-12)
    # F_O1 is the minimum over the 4-actuator sets of their LMTIs (Eq. 12), each the max of its OTIs.
    np.testing.assert_allclose(dataset["f_o1"], dataset["lmti_remaining1"].min("remaining1"), atol=0)
    np.testing.assert_allclose(dataset["lmti"], dataset["oti_submechanism"].max("submechanism"), atol=0)
    assert (dataset["lmti_remaining1"].sizes["remaining1"] == 5
            and dataset["oti_submechanism"].sizes["submechanism"] == 10)
    closed = sweep(five, [0, 0, 0], "phi", phi, closed_forms=True)
    np.testing.assert_allclose(dataset["f_o2"], closed["f_o2"], atol=1e-9)


def test_disc_map_values_are_minima_over_the_rotation(five, tmp_path):
    dataset = planar_disc_map(five, 2.0, 0.25, 15.0, execution=QUIET)
    assert set(dataset.coords) >= {"x", "y"}
    assert {"iti", "lmti", "f_o1", "f_io1", "f_o2", "f_io2"} <= set(dataset.data_vars)
    iti = dataset["iti"].values
    assert np.isnan(iti).any() and np.isfinite(iti).any()  # unreachable far out, values inside
    phi = np.deg2rad(np.arange(0, 360, 15.0))
    for x, y in ((0.0, 0.0), (0.25, -0.5), (-0.75, 0.5), (1.75, 0.0)):
        expected = hand_built_minimum(x, y, phi)
        point = dataset.sel(x=x, y=y, method="nearest")
        if expected is None:
            assert np.isnan(float(point["iti"]))
            continue
        for name, value in expected.items():
            assert float(point[name]) == pytest.approx(value, abs=1e-12)
    closed = planar_disc_map(five, 2.0, 0.25, 15.0, analysis=AnalysisOptions(closed_forms=True), execution=QUIET)
    for name in ("iti", "lmti", "f_o1", "f_io1"):
        np.testing.assert_allclose(dataset[name], closed[name], atol=1e-9)
    path = tmp_path / "map.nc"
    write_dataset(dataset, path)
    assert sorted(os.listdir(tmp_path)) == ["map.nc"]  # no temporary left behind
    with xr.open_dataset(path) as reread:
        np.testing.assert_array_equal(reread["f_o1"].values, dataset["f_o1"].values)


def test_map_written_without_xarray_reads_back_as_the_dataset(five, tmp_path):
    """The command line writes the plain GridMap with scipy; xarray reads it back as index_map's dataset."""
    grid = planar_disc_map(five, 0.5, 0.25, 30.0, execution=QUIET, as_dataset=False)
    assert isinstance(grid, GridMap)
    dataset = grid.to_dataset()
    write_dataset(grid, tmp_path / "plain.nc")
    write_dataset(dataset, tmp_path / "xarray.nc")
    assert sorted(os.listdir(tmp_path)) == ["plain.nc", "xarray.nc"]
    with xr.open_dataset(tmp_path / "plain.nc") as plain, xr.open_dataset(tmp_path / "xarray.nc") as written:
        xr.testing.assert_identical(plain, written)
        xr.testing.assert_identical(plain, dataset)
        for key, value in written.attrs.items():  # same attribute types as xarray's own writer
            assert type(plain.attrs[key]) is type(value), key
    assert np.isnan(dataset["f_o1"].values).any() and np.isfinite(dataset["f_o1"].values).any()


def test_map_as_csv_has_one_row_per_grid_point(five, tmp_path):
    import pandas as pd

    grid = planar_disc_map(five, 0.2, 0.1, 30.0, execution=QUIET, as_dataset=False)
    dataset = grid.to_dataset()
    write_dataset(grid, tmp_path / "map.csv")
    table = pd.read_csv(tmp_path / "map.csv")
    assert len(table) == dataset.sizes["x"] * dataset.sizes["y"] == 25
    for _, row in table.iterrows():
        expected = float(dataset["f_o1"].sel(x=row["x"], y=row["y"]))
        assert (np.isnan(row["f_o1"]) and np.isnan(expected)) or row["f_o1"] == pytest.approx(expected, abs=1e-12)
    assert table["f_o1"].isna().sum() == 12 and table["f_o1"].notna().sum() == 13  # 13 grid points on the disc


def test_spatial_map_over_an_orientation_set():
    hexapod = load("ups_hexapod_8")
    grid = {"x": np.array([-0.1, 0.0, 0.1]), "y": np.array([-0.05, 0.05])}
    over = {"yaw": np.deg2rad([0.0, 10.0, 20.0]), "roll": np.deg2rad([-5.0, 5.0])}
    dataset = index_map(hexapod, grid, over, execution=QUIET)
    assert dataset["f_o1"].shape == (2, 3)
    home = np.asarray(hexapod.home_pose, dtype=float)
    poses = np.array([[0.1, -0.05, home[2], roll, 0.0, yaw] for yaw in over["yaw"] for roll in over["roll"]])
    result = analyze(chain_screws(hexapod, solve(hexapod, poses)), detail=False)
    assert float(dataset["f_o1"].sel(x=0.1, y=-0.05)) == pytest.approx(float(result.f_o[1].min()), abs=1e-12)


@pytest.fixture(scope="module")
def cluster():
    distributed = pytest.importorskip("distributed")
    # on loopback, the scheduler's web server on a free port (its default, 8787, may be another test's)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                  dashboard_address="127.0.0.1:0") as cluster:
        with distributed.Client(cluster, set_as_default=False) as client:  # no default client: run_tasks needs none
            yield client


def test_distributed_map_equals_local(five, cluster):
    """The same tasks give bit-identical results on a 2-worker cluster and on local threads."""
    local = planar_disc_map(five, 0.4, 0.1, 10.0, execution=Execution(progress=False, configurations_per_task=2000))
    remote = planar_disc_map(five, 0.4, 0.1, 10.0, execution=Execution(
        scheduler=cluster.scheduler.address, progress=False, configurations_per_task=2000))
    for name in local.data_vars:
        np.testing.assert_array_equal(local[name].values, remote[name].values)


def test_a_worker_lost_mid_run_loses_nothing(five, cluster):
    local = planar_disc_map(five, 0.5, 0.05, 10.0, execution=Execution(progress=False, configurations_per_task=400))
    outcome = {}

    def run():
        outcome["map"] = planar_disc_map(five, 0.5, 0.05, 10.0, execution=Execution(
            scheduler=cluster, progress=False, configurations_per_task=400))

    before = cluster.run(os.getpid)
    thread = threading.Thread(target=run)
    thread.start()
    deadline = time.time() + 60
    while time.time() < deadline and not cluster.run_on_scheduler(
            lambda dask_scheduler: sum(ts.state == "memory" for ts in dask_scheduler.tasks.values())):
        time.sleep(0.05)
    victim = sorted(before)[0]
    os.kill(before[victim], signal.SIGKILL)  # a worker dies while tasks are queued and running
    thread.join(timeout=180)
    assert not thread.is_alive()
    cluster.wait_for_workers(2, timeout=60)
    after = cluster.run(os.getpid)
    assert before[victim] not in after.values()  # the worker really was replaced
    for name in local.data_vars:
        np.testing.assert_array_equal(local[name].values, outcome["map"][name].values)


def test_permutation_search_ranks_the_papers_design_first(five):
    ranked = permutation_search(planar_design(five), phi_step_degrees=5.0, execution=QUIET)
    assert len(ranked) == 240
    best = round(ranked[0].score, 9)
    winners = {(d.permutation, d.working_mode) for d in ranked if round(d.score, 9) == best}
    assert ((0, 3, 1, 4, 2), 1) in winners
    # The winners are the paper's design, its slot rotations and its mirror working mode only.
    assert {rotation_class(p) for p, _ in winners} == {rotation_class((0, 3, 1, 4, 2))}
    assert ranked[0].permutation == (0, 3, 1, 4, 2) and ranked[0].working_mode == 1
    # The score is the minimum of F_O1 over the rotation, recomputed with the closed forms.
    phi = np.deg2rad(np.arange(0, 360, 5.0))
    base, elbows, distal, _ = planar_joint_points(paper_5rrr(), np.column_stack([0 * phi, 0 * phi, phi]))
    assert ranked[0].score == pytest.approx(planar_indices(base, elbows, distal)["f_o"][1].min(), abs=1e-12)


def test_cli_sweep_map_and_design_search(tmp_path):
    result = screwkit("sweep", "planar_5rrr", "--at", "0", "0", "--phi", "0:360:5", "--out", tmp_path / "s.nc",
                      "--figure", tmp_path / "s.png")
    assert result.returncode == 0, result.stderr
    assert "min f_o1" in result.stderr and (tmp_path / "s.png").stat().st_size > 10_000 and result.stdout == ""
    result = screwkit("map", "planar_5rrr", "--radius", "0.2", "--step", "0.1", "--phi-step", "30",
                      "--out", tmp_path / "m.nc", "--quiet")
    assert result.returncode == 0, result.stderr
    assert result.stdout == result.stderr == ""  # --quiet: nothing on the terminal
    with xr.open_dataset(tmp_path / "m.nc") as dataset:
        assert dataset["f_o1"].dims == ("y", "x")
    again = screwkit("map", "planar_5rrr", "--radius", "0.2", "--step", "0.1", "--out", tmp_path / "m.nc")
    assert again.returncode == 1 and "m.nc: the file exists; pass --overwrite to replace it." in again.stderr
    result = screwkit("design-search", "permutations", "planar_5rrr", "--phi-step", "10", "--json", "--quiet")
    assert result.returncode == 0, result.stderr
    designs = json.loads(result.stdout)["designs"]
    assert len(designs) == 240 and set(designs[0]) >= {"permutation", "working_mode", "score"}
    assert designs[0]["permutation"] == [0, 3, 1, 4, 2]


def test_optimised_design_is_no_worse_and_its_urdf_loads(five, tmp_path):
    result = screwkit("design-search", "optimise", "planar_5rrr", "--maxiter", "1", "--popsize", "2",
                      "--step", "0.1", "--phi-step", "15", "--urdf", tmp_path / "best.urdf", "--json")
    assert result.returncode == 0, result.stderr
    summary = json.loads(result.stdout)
    assert summary["files"] == [str(tmp_path / "best.urdf")] and f"wrote {tmp_path / 'best.urdf'}" in result.stderr
    assert summary["free"] == ["platform_radius", "upper", "lower"] and summary["evaluations"] == 12
    best, start = summary["best"][0], summary["start"]
    assert best["metrics"]["area"] >= start["metrics"]["area"]
    optimised = load(tmp_path / "best.urdf")
    assert optimised.dof == 3 and len(optimised.actuators) == 5
    expected = planar_design(optimised)  # read back from the solved assembly of the written file
    np.testing.assert_allclose(expected.upper, best["values"]["upper"], atol=1e-9)
    np.testing.assert_allclose(expected.lower, best["values"]["lower"], atol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(expected.platform, axis=-1), best["values"]["platform_radius"],
                               atol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(expected.base, axis=-1), 1.0, atol=1e-9)


def test_default_task_and_chunk_sizes_balance_the_cores_and_bound_the_memory(five):
    """Tasks: at least 16 per core when the map is large, never under 16,384 nor over 131,072
    configurations. Chunks: the same indices whatever the chunk size, and a bad size named."""
    from screwkit.studies.maps import task_size
    from screwkit.studies.poses import indices_at_poses, poses_per_chunk

    assert task_size(158_760, cores=2) == 16_384  # 10 tasks instead of 2
    assert task_size(605_160, cores=2) == 18_912  # 32 tasks
    assert task_size(10**7, cores=2) == 131_072
    assert task_size(1000, cores=2) == 16_384
    hexapod = load("ups_hexapod_8")
    assert 1024 <= poses_per_chunk(hexapod) < poses_per_chunk(five) <= 262_144
    poses = np.column_stack([np.zeros(50), np.linspace(-0.2, 0.2, 50), np.linspace(0, 3, 50)])
    whole = indices_at_poses(five, poses)
    pieces = indices_at_poses(five, poses, chunk_size=7)
    # equal to rounding: each chunk takes its motion-space basis from its own sample configurations
    np.testing.assert_allclose(whole.f_o[1], pieces.f_o[1], rtol=0, atol=1e-13)
    np.testing.assert_allclose(whole.lmti, pieces.lmti, rtol=0, atol=1e-13)
    with pytest.raises(ValueError, match="chunk_size"):
        indices_at_poses(five, poses, chunk_size=0)


def test_chunks_out_of_reach_before_between_and_among_reachable_ones_give_no_result_there(five):
    """Each batch array is written once per row (unfilled until the chunks write it): poses out of reach in the
    first chunks, in a whole chunk between reachable ones and among reachable poses hold NaN, -1 and False, and
    every other row the indices of the poses computed one at a time."""
    from screwkit.studies.poses import indices_at_poses

    good = np.column_stack([np.zeros(9), np.linspace(-0.15, 0.15, 9), np.linspace(0.0, 2.0, 9)])
    far = np.array([5.0, 5.0, 0.0])
    poses = np.array([far, far, far, far, good[0], far, good[1], good[2], far, far, far, good[3], good[4], good[5],
                      far, good[6], good[7], good[8], far])
    out = np.all(poses == far, axis=-1)
    chunked = indices_at_poses(five, poses, detail=True, chunk_size=3, threads=1)
    assert np.array_equal(np.asarray(chunked.reachable), ~out)
    for j in chunked.faults:
        assert np.all(np.isnan(chunked.f_o[j][out])) and np.all(np.isnan(chunked.remaining_lmti[j][out]))
        assert np.all(chunked.worst_fault_indices[j][out] == -1)
    for name in ("iti", "lmti", "iti_actuators", "oti_submechanisms"):
        assert np.all(np.isnan(getattr(chunked, name)[out])), name
    assert not np.any(np.asarray(chunked.mutual_interference)[out])
    alone = [indices_at_poses(five, pose[None], detail=True) for pose in poses[~out]]
    for name in ("iti", "lmti", "iti_actuators", "oti_submechanisms"):
        np.testing.assert_allclose(getattr(chunked, name)[~out], np.concatenate([getattr(a, name) for a in alone]),
                                   rtol=0, atol=1e-13, err_msg=name)
    for j in chunked.faults:
        np.testing.assert_allclose(chunked.f_o[j][~out], np.concatenate([a.f_o[j] for a in alone]), rtol=0, atol=1e-13)
        assert np.array_equal(chunked.worst_fault_indices[j][~out],
                              np.concatenate([a.worst_fault_indices[j] for a in alone]))
