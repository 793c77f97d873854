"""The average case of Eq. 12 (screwkit's extension): F_Oj's mean over the sets of j failed actuators, equal or
weighted by per-actuator failure probabilities, in every study that offers the worst case (analyze, sweeps, maps,
trajectories), each checked against an independent numpy computation over the failure patterns."""

from __future__ import annotations

import json
import threading
from itertools import combinations, product

import numpy as np
import pytest

from helpers import bundled, one_line_error, screwkit
from screwkit.indices.average import averaging, failure_weights, mean_record
from screwkit.indices.registry import INDICES, registered
from screwkit.studies import indices_at_pose, indices_at_poses
from screwkit.studies.maps import MapBlock, map_block
from screwkit.studies.options import AnalysisOptions
from screwkit.studies.paths import line_path
from screwkit.studies.sweep import sweep
from screwkit.studies.trajectory import trajectory

PROBABILITIES = (0.1, 0.2, 0.05, 0.3, 0.5)


def expected_mean(mechanism, pose, faults, probabilities=None):
    """The mean over every set E of ``faults`` failed actuators of the LMTI of the actuators left, each set weighted
    by the probability of exactly that failure pattern among all 2^a patterns (independent failures), normalised
    over the patterns with ``faults`` failures; the LMTI of each set left from ``Indices.lmti_of``."""
    detailed = indices_at_poses(mechanism, np.asarray(pose)[None], detail=True).at(0)
    a = len(mechanism.actuators)
    p = np.full(a, 0.5) if probabilities is None else np.asarray(probabilities)
    total, weight = 0.0, 0.0
    for pattern in product((False, True), repeat=a):
        if sum(pattern) != faults:
            continue
        chance = np.prod(np.where(pattern, p, 1 - p))  # p = 1/2 everywhere: every pattern alike, the plain mean
        kept = tuple(i for i in range(a) if not pattern[i])
        total += chance * float(detailed.lmti_of(kept))
        weight += chance
    return total / weight


@pytest.mark.parametrize("probabilities", [None, PROBABILITIES])
def test_analyze_gives_the_mean_over_the_failures(probabilities):
    five = bundled("planar_5rrr")
    pose = five.named_pose("paper_fig_2a")
    assert "f_o_mean" not in INDICES  # nothing registered outside a study that asks
    with averaging(probabilities):
        result = indices_at_pose(five, pose)
        mean = result.index("f_o_mean")
    for j in (1, 2):
        assert mean[j] == pytest.approx(expected_mean(five, pose, j, probabilities), abs=1e-14)
        assert mean[j] >= result.f_o[j] and result.derived[f"f_o_mean{j}"] == mean[j]
    assert "f_o_mean" not in INDICES


def test_sweeps_and_maps_give_the_mean_and_its_worst_orientation():
    five = bundled("planar_5rrr")
    phis = np.deg2rad([0.0, 30.0, 60.0])
    with averaging(PROBABILITIES):
        swept = sweep(five, five.home_pose, "phi", phis)
    for k, phi in enumerate(phis):
        for j in (1, 2):
            assert swept[f"f_o_mean{j}"].values[k] == pytest.approx(
                expected_mean(five, [0.0, 0.0, phi], j, PROBABILITIES), abs=1e-14)
    block = MapBlock(five.home_pose, 0, np.array([0.0, 0.1]), 1, np.array([0.0]), np.ones((1, 2), dtype=bool), (2,),
                     phis[:, None])
    mapped = map_block(five, block, AnalysisOptions(aggregate="mean"))
    for x, got in zip((0.0, 0.1), mapped["f_o_mean2"]):
        assert got == pytest.approx(min(expected_mean(five, [x, 0.0, phi], 2) for phi in phis), abs=1e-14)
    assert "f_o_mean2" not in map_block(five, block, AnalysisOptions())  # the worst case alone unless asked


def test_the_trajectory_mean_is_the_same_index():
    five = bundled("planar_5rrr")
    path = line_path(five, [-0.3, -0.2, -0.5], [0.3, 0.2, 0.5], 5)
    result = trajectory(five, path, aggregate="mean", probabilities=PROBABILITIES)
    for i in (0, 2, 4):
        for j in (1, 2):
            assert result.mean[j][i] == pytest.approx(expected_mean(five, path.poses[i], j, PROBABILITIES), abs=1e-14)


def test_the_mean_is_registered_once_for_threads_and_refused_beside_another():
    """Tasks of a map in threads each register the mean: shared, gone after the last; another record under the
    same name is refused, as any second registration is."""
    five = bundled("planar_5rrr")
    errors = []

    def task():
        try:
            with averaging():
                indices_at_poses(five, five.home_pose[None])
                assert INDICES["f_o_mean"] is mean_record(None)
        except Exception as error:  # reported below
            errors.append(error)

    threads = [threading.Thread(target=task) for _ in range(6)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert not errors and "f_o_mean" not in INDICES
    with registered(mean_record((0.5,) * 5)), pytest.raises(ValueError, match="registered already"):
        with averaging():
            pass
    assert "f_o_mean" not in INDICES
    with pytest.raises(ValueError, match="one failure probability in \\[0, 1\\] per actuator \\(5\\)"):
        failure_weights(5, 1, (0.1, 2.0, 0, 0, 0))
    assert len(failure_weights(5, 2)) == len(list(combinations(range(5), 2)))


def test_the_commands_offer_the_mean(tmp_path):
    five = bundled("planar_5rrr")
    pose = five.named_pose("paper_fig_2a")
    probabilities = [str(p) for p in PROBABILITIES]
    done = screwkit("analyze", "planar_5rrr", "--pose", "paper_fig_2a", "--aggregate", "mean", "--probabilities",
                    *probabilities, "--json")
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)
    for j in (1, 2):
        assert report["f_o_mean"][str(j)] == pytest.approx(expected_mean(five, pose, j, PROBABILITIES), abs=1e-12)
    assert "f_o_mean" not in json.loads(screwkit("analyze", "planar_5rrr", "--json").stdout)

    done = screwkit("sweep", "planar_5rrr", "--phi", "0:60:30", "--aggregate", "mean", "--out", tmp_path / "s.csv")
    assert done.returncode == 0, done.stderr
    import pandas as pd

    table = pd.read_csv(tmp_path / "s.csv")
    for phi, got in zip(table["phi"], table["f_o_mean1"]):
        assert got == pytest.approx(expected_mean(five, [0.0, 0.0, np.deg2rad(phi)], 1), abs=1e-12)

    done = screwkit("map", "planar_5rrr", "--radius", "0.1", "--step", "0.1", "--phi-step", "120", "--aggregate",
                    "mean", "--probabilities", *probabilities, "--out", tmp_path / "m.nc")
    assert done.returncode == 0, done.stderr
    import xarray as xr

    with xr.open_dataset(tmp_path / "m.nc", engine="scipy") as mapped:
        got = float(mapped["f_o_mean2"].sel(x=0.0, y=0.0))
    wanted = min(expected_mean(five, [0.0, 0.0, np.deg2rad(phi)], 2, PROBABILITIES) for phi in (0.0, 120.0, 240.0))
    assert got == pytest.approx(wanted, abs=1e-12)

    one_line_error(screwkit("analyze", "planar_5rrr", "--probabilities", "0.1"),
                   "--probabilities weight the mean: give --aggregate mean with them.")
    one_line_error(screwkit("map", "planar_5rrr", "--radius", "0.1", "--step", "0.1", "--phi-step", "120",
                            "--aggregate", "mean", "--probabilities", "0.1", "0.2"),
                   "--probabilities: Expected one failure probability in [0, 1] per actuator (5), got [0.1, 0.2].")
    one_line_error(screwkit("sweep", "planar_5rrr", "--phi", "0:60:30", "--aggregate", "mean", "--probabilities",
                            "a", "b"), "Expected numbers after --probabilities, got 'a b'.")
