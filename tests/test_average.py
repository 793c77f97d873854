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


def brute_force_rotation_mean(design, faults, probabilities, phi_step=30.0):
    """The minimum over a full rotation at the centre of the mean over the sets of ``faults`` failed actuators of
    the LMTI of the mechanism made of the chains left alone (a free-swinging planar R-R-R chain constrains nothing,
    so the failed chains are simply left out), each set weighted by its failure pattern's probability."""
    from screwkit.indices.analysis import analyze
    from screwkit.screw.planar import planar_joint_points, rrr_chain_screws

    phi = np.deg2rad(np.arange(0.0, 360.0 - 1e-9, phi_step))
    base, elbows, distal, reachable = planar_joint_points(design, np.column_stack([0 * phi, 0 * phi, phi]))
    assert reachable.all()
    a = design.chain_count
    p = np.full(a, 0.5) if probabilities is None else np.asarray(probabilities)
    total, weight = 0.0, 0.0
    for failed in combinations(range(a), faults):
        kept = [i for i in range(a) if i not in failed]
        chance = np.prod([p[i] if i in failed else 1 - p[i] for i in range(a)])
        total = total + chance * analyze(rrr_chain_screws(base[:, kept], elbows[:, kept], distal[:, kept])).lmti
        weight += chance
    return float(np.min(total / weight))


@pytest.mark.parametrize("probabilities", [None, PROBABILITIES])
def test_the_permutation_search_scores_the_mean(probabilities):
    """design-search permutations with the average case: each design's score is the brute-force minimum over the
    rotation of the mean over the failures, through the closed forms and the generic path alike."""
    from screwkit.studies.design.permutations import planar_design, rotation_score, slot_design

    design = planar_design(bundled("planar_5rrr"))
    for permutation, mode in (((0, 3, 1, 4, 2), 1), ((0, 4, 3, 2, 1), 1), ((2, 0, 1, 4, 3), -1)):
        candidate = slot_design(design, permutation, mode)
        for faults in (1, 2):
            wanted = brute_force_rotation_mean(candidate, faults, probabilities)
            for closed_forms in (False, True):
                got = rotation_score(candidate, phi_step_degrees=30.0, faults=faults, closed_forms=closed_forms,
                                     aggregate="mean", probabilities=probabilities)
                assert got == pytest.approx(wanted, abs=1e-12)
                assert got >= rotation_score(candidate, phi_step_degrees=30.0, faults=faults,
                                             closed_forms=closed_forms) - 1e-12  # the mean is above the worst
    with pytest.raises(ValueError, match="weight the mean"):
        rotation_score(design, probabilities=PROBABILITIES)


def test_a_design_region_of_the_mean_is_the_brute_force_region():
    """A design search's region of f_o_mean<j>: its area and worst value from the mean over the failures at every
    pose of the map (expected_mean, pose by pose), the minimum over the orientations, for the planar family's
    design through the closed forms and the generic path."""
    from screwkit.studies.design.families import family
    from screwkit.studies.design.objectives import disc_region, region_metrics

    chosen = family("planar_rrr", 5)
    mechanism = chosen.mechanism({})
    for closed_forms in (True, False):
        region = disc_region(0.2, 0.1, 120.0, index="f_o_mean1", level=0.75, closed_forms=closed_forms,
                             probabilities=PROBABILITIES)
        metrics = region_metrics(mechanism, region)
        (_, xs), (_, ys) = region.grid
        (_, phis), = region.over
        minima = []
        for row, y in enumerate(ys):
            for column, x in enumerate(xs):
                if region.mask[row, column]:
                    minima.append(min(expected_mean(mechanism, [x, y, phi], 1, PROBABILITIES) for phi in phis))
        minima = np.array(minima)
        assert 0 < np.sum(minima >= 0.75) < minima.size  # the level cuts the disc
        assert metrics["area"] == pytest.approx(np.sum(minima >= 0.75) * 0.1**2, abs=1e-15)
        assert metrics["worst"] == pytest.approx(minima.min(), abs=1e-12)
        assert metrics["mean"] == pytest.approx(minima.mean(), abs=1e-12)
    with pytest.raises(ValueError, match="give the region an index f_o_mean<j>"):
        disc_region(0.2, 0.1, 120.0, probabilities=PROBABILITIES)


def test_the_design_search_commands_offer_the_mean(tmp_path):
    """design-search family and permutations with --index f_o_mean<j> and --probabilities, as subprocesses: the
    family's best design reproduced by a fresh `screwkit map` of its file with the options it prints, the
    permutations' scores by the brute force; bad values refused in one line before any work."""
    from screwkit.studies.design.permutations import planar_design

    probabilities = [str(p) for p in PROBABILITIES]
    region = ["--radius", "0.2", "--step", "0.1", "--phi-step", "120", "--level", "0.75"]
    done = screwkit("design-search", "family", "planar_rrr", "--index", "f_o_mean1", "--probabilities",
                    *probabilities, *region, "--budget", "4", "--json", "--urdf", tmp_path / "best.urdf")
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)
    assert report["region"].startswith("f_o_mean1 >= 0.75")
    (command,) = report["map_commands"]
    assert command.endswith("--aggregate mean --probabilities " + " ".join(repr(p) for p in PROBABILITIES))
    options = command.split()[3:]
    mapped = screwkit("map", tmp_path / "best.urdf", *options, "--out", tmp_path / "best.nc")
    assert mapped.returncode == 0, mapped.stderr
    import xarray as xr

    with xr.open_dataset(tmp_path / "best.nc", engine="scipy") as best_map:
        disc = np.isfinite(best_map["reachable_fraction"].values)  # the disc's points (NaN outside it)
        values = np.nan_to_num(best_map["f_o_mean1"].values[disc], nan=0.0)  # an unreachable point counts 0
    best = report["best"][0]["metrics"]
    assert best["area"] == pytest.approx(np.sum(values >= 0.75) * 0.1**2, abs=1e-15)
    assert best["worst"] == pytest.approx(values.min(), abs=1e-12) and best["mean"] == pytest.approx(values.mean())

    design = planar_design(bundled("planar_5rrr"))
    done = screwkit("design-search", "permutations", "planar_5rrr", "--phi-step", "30", "--index", "f_o_mean2",
                    "--probabilities", *probabilities, "--json")
    assert done.returncode == 0, done.stderr
    ranking = json.loads(done.stdout)
    assert ranking["index"] == "f_o_mean2" and ranking["probabilities"] == list(PROBABILITIES)
    mine = next(row for row in ranking["designs"] if row["permutation"] == [0, 3, 1, 4, 2] and row["working_mode"] == 1)
    assert mine["score"] == pytest.approx(brute_force_rotation_mean(design, 2, PROBABILITIES), abs=1e-12)

    study = tmp_path / "study.yaml"
    study.write_text("family: planar_rrr\nindex: f_o_mean1\nprobabilities: [0.1, 0.2]\nbudget: 4\n")
    for arguments, message in [
        (("family", "planar_rrr", "--index", "f_o_mean1", "--probabilities", "0.1", "0.2", "--budget", "4"),
         "--probabilities: Expected one failure probability in [0, 1] per actuator (5), got [0.1, 0.2]."),
        (("family", "--study", study),
         "--probabilities: Expected one failure probability in [0, 1] per actuator (5), got [0.1, 0.2]."),
        (("family", "planar_rrr", "--probabilities", *probabilities, "--budget", "4"),
         "--probabilities weight the mean over the sets of failed actuators: give --index f_o_mean<j>"),
        (("family", "planar_rrr", "--index", "f_o_mean1", "--probabilities", "a", "--budget", "4"),
         "Expected numbers after --probabilities, got 'a'."),
        (("family", "ups_hexapod", "--index", "f_o_mean3", "--budget", "4"),
         "--index f_o_mean3: the designs have 8 actuators for 6 DoF, so at most 2 may fail (j in 1..2), not 3."),
        (("family", "planar_rrr", "--index", "f_o3", "--budget", "4"),
         "--index f_o3: the designs have 5 actuators for 3 DoF, so at most 2 may fail (j in 1..2), not 3."),
        (("permutations", "planar_5rrr", "--index", "f_o_mean3"),
         "--index f_o_mean3: planar_5rrr has 5 actuators for 3 DoF, so at most 2 may fail (j in 1..2), not 3."),
        (("permutations", "planar_5rrr", "--index", "f_io1"), "Expected --index f_o<j> or f_o_mean<j> (j >= 1)"),
        (("permutations", "planar_5rrr", "--probabilities", *probabilities),
         "--probabilities weight the mean over the sets of failed actuators: give --index f_o_mean<j>"),
        (("permutations", "planar_5rrr", "--index", "f_o_mean1", "--probabilities", "0.1", "2", "0", "0", "0"),
         "--probabilities: Expected one failure probability in [0, 1] per actuator (5)"),
    ]:
        one_line_error(screwkit("design-search", *arguments), message)


def test_a_search_state_belongs_to_its_failure_probabilities():
    """A search's state file is keyed by what its evaluations depend on: other failure probabilities, another
    state; the same ones, or none, the same key as before."""
    from screwkit.studies.design.families import family
    from screwkit.studies.design.objectives import disc_region
    from screwkit.studies.design.optimise import Study

    chosen = family("planar_rrr", 5)

    def key(**region):
        return Study(chosen, disc_region(0.2, 0.1, 120.0, **region), ("area",), budget=4).fingerprint()

    weighted = key(index="f_o_mean1", probabilities=PROBABILITIES)
    assert weighted == key(index="f_o_mean1", probabilities=list(PROBABILITIES))
    assert weighted != key(index="f_o_mean1", probabilities=PROBABILITIES[::-1]) != key(index="f_o_mean1")
    assert key(index="f_o_mean1") != key() == key(index="f_o1")


def test_a_column_of_the_mean_is_named_so_and_nothing_else_is():
    from screwkit.indices.average import is_mean_column

    assert all(is_mean_column(name) for name in ("f_o_mean1", "f_o_mean2", "f_o_mean12"))
    assert not any(is_mean_column(name) for name in ("f_o_mean", "f_o1", "f_io1", "lmti", "xf_o_mean1", "f_o_meanx"))


def test_the_mean_under_link_faults_weights_the_reduced_mechanisms_left(tmp_path):
    """``--fault link --aggregate mean --probabilities`` failed in analyze and sweep whatever was given ("one
    failure probability per actuator (3)" for four, "(4)" for three): the reduced mechanisms were averaged with the
    whole mechanism's probabilities. The 3-PRS + UPS under link faults: losing a PRS leg frees a DOF (LMTI 0),
    losing the UPS leg leaves the 3-PRS, analysed here as a mechanism of its own; the mean weights them by the
    probability of each failure pattern."""
    from screwkit.io.loader import load_text
    from screwkit.robots.generate import PRS_UPS, prs_mechanism

    whole = load_text(prs_mechanism("prs_3_ups_test", PRS_UPS, with_ups=True), "prs_3_ups_test")
    three = load_text(prs_mechanism("prs_3_test", PRS_UPS, with_ups=False), "prs_3_test")
    probabilities = (0.1, 0.2, 0.3, 0.4)
    pose = whole.home_pose + np.array([0.005, np.radians(-10.0), np.radians(20.0)])
    with averaging(probabilities):
        mean = indices_at_pose(whole, pose, fault_type="link").index("f_o_mean")
    chance = [p * np.prod([1 - q for i, q in enumerate(probabilities) if i != k]) for k, p in enumerate(probabilities)]
    left = float(indices_at_pose(three, pose).lmti)
    assert left > 0.5 and mean[1] == pytest.approx(chance[3] / sum(chance) * left, abs=1e-12)
    analysed = screwkit("analyze", "prs_3_ups", "--pose", "0.2 -10 20", "--fault", "link", "--aggregate", "mean",
                        "--probabilities", *map(str, probabilities), "--json")
    assert analysed.returncode == 0, analysed.stderr
    swept = screwkit("sweep", "prs_3_ups", "--sweep", "z:0.19:0.21:0.01", "--fault", "link", "--aggregate", "mean",
                     "--probabilities", *map(str, probabilities))
    assert swept.returncode == 0 and "f_o_mean1" in swept.stdout, swept.stderr
