"""Parametric families, region metrics and design searches (``screwkit design-search family FAMILY``).

Each family's writer is checked against an independent construction (the bundled files, the
planar closed forms, leg lines written from the geometry); each metric against a brute force;
each search path as users run it: the command in a subprocess, its best design re-mapped by a
fresh ``screwkit map`` of the URDF it wrote, an interrupted run resumed from its state file.
"""

from __future__ import annotations

import json
import math
import os
import re
import signal
import subprocess
import sys
import time
from dataclasses import replace
from itertools import combinations, permutations

import numpy as np
import pytest
import xarray as xr

from helpers import one_line_error, screwkit
from screwkit.io.loader import bundled_path, load
from screwkit.screw.planar import PlanarDesign
from screwkit.studies import indices_at_poses
from screwkit.studies.design.families import FAMILIES, family, permutation_of_rank, permutation_rank
from screwkit.studies.design.objectives import (
    default_region,
    disc_region,
    grid_region,
    inscribed_radius,
    region_metrics,
)
from screwkit.studies.design.optimise import Constraint, StateError, Study, pareto_front, run_study
from screwkit.studies.design.permutations import family_values, fault_tolerant_area, planar_design
from screwkit.studies.tasks import Execution

QUIET = Execution(progress=False)
"""Local threads, no progress bar."""

SMALL_DISC = ("--radius", "0.3", "--step", "0.1", "--phi-step", "30")
"""A planar region of 29 points x 12 angles: a search of 24 designs in a few seconds."""
SMALL_GRID = ("--grid", "x:-0.1:0.1:0.1", "--grid", "y:-0.1:0.1:0.1", "--over", "yaw:-20:40:20")


def without_comments(text: str) -> str:
    return re.sub(r"<!--.*?-->", "", text, flags=re.S)


NUMBER = re.compile(r"-?\d+\.?\d*(?:e[-+]?\d+)?")


def assert_same_file(text: str, expected: str) -> None:
    """The same text, numbers equal to 1e-12 (the last digit of a trigonometric value written with repr can
    differ between numpy releases)."""
    assert NUMBER.sub("#", text) == NUMBER.sub("#", expected)
    np.testing.assert_allclose([float(v) for v in NUMBER.findall(text)],
                               [float(v) for v in NUMBER.findall(expected)], rtol=1e-12, atol=1e-15)


def test_permutation_ranks_follow_the_lexicographic_order():
    for count in (4, 5):
        for rank, permutation in enumerate(permutations(range(count))):
            assert permutation_of_rank(count, rank) == permutation
            assert permutation_rank(permutation) == rank


@pytest.mark.parametrize("name, bundled", [("ups_hexapod", "ups_hexapod_8"), ("rss_hexapod", "rss_hexapod_8"),
                                           ("delta", "delta_4"), ("prs_ups", "prs_3_ups")])
def test_spatial_families_at_their_defaults_are_the_bundled_mechanisms(name, bundled):
    """The same file but for comments and the bundled file's named poses."""
    text = family(name).urdf(name=bundled)
    expected = re.sub(r"\n *<named_pose [^>]*/>", "", without_comments(bundled_path(bundled).read_text()))
    assert_same_file(without_comments(text), expected)


def test_the_planar_family_at_its_defaults_is_table_2():
    """Same indices as the bundled planar_5rrr (written by generate.py's own code) at random poses."""
    candidate, bundled = family("planar_rrr", 5).mechanism(), load("planar_5rrr")
    rng = np.random.default_rng(3)
    poses = np.column_stack([rng.uniform(-0.3, 0.3, (50, 2)), rng.uniform(-np.pi, np.pi, 50)])
    one, other = indices_at_poses(candidate, poses), indices_at_poses(bundled, poses)
    np.testing.assert_array_equal(one.reachable, other.reachable)
    for j in (1, 2):
        np.testing.assert_allclose(one.f_o[j], other.f_o[j], atol=1e-12, equal_nan=True)
    legs, values = family_values(planar_design(bundled))
    assert legs == 5 and values == pytest.approx(family("planar_rrr").defaults(), abs=1e-12)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_design_is_a_member_of_its_family_whatever_the_order_of_its_legs(seed):
    """The bundled 5-RRR with its legs listed in another order (a file whose chains are named otherwise) is the same
    member of the family, with the same values: it was refused as "not a member" (chain 1's base joint elsewhere)."""
    design = planar_design(load("planar_5rrr"))
    order = np.random.default_rng(seed).permutation(design.chain_count)
    while np.array_equal(order, np.arange(design.chain_count)):
        order = np.roll(order, 1)
    shuffled = PlanarDesign(design.base[order], design.platform[order], design.upper[order], design.lower[order],
                            design.working_mode[order])
    legs, values = family_values(shuffled)
    assert legs == 5 and values == pytest.approx(family_values(design)[1], abs=1e-12)


def ups_f_o1(base, platform, poses):
    """F_O1 of a UPS hexapod at (x, y, z, yaw) poses, from the leg lines alone: every 6-leg
    submechanism's output twists are the columns of its inverse wrench matrix."""
    c, s = np.cos(poses[:, 3]), np.sin(poses[:, 3])
    rotation = np.zeros((len(poses), 3, 3))
    rotation[:, 0, 0], rotation[:, 0, 1], rotation[:, 1, 0], rotation[:, 1, 1], rotation[:, 2, 2] = c, -s, s, c, 1
    points = np.einsum("nij,lj->nli", rotation, platform) + poses[:, None, :3]
    direction = (points - base) / np.linalg.norm(points - base, axis=-1, keepdims=True)
    wrenches = np.concatenate([direction, np.cross(points, direction)], -1)
    legs = len(base)
    lmti = {}
    for subset in combinations(range(legs), 6):
        twists = np.linalg.inv(wrenches[:, subset])
        oti = []
        for k, leg in enumerate(subset):
            v, w = twists[:, :3, k], twists[:, 3:, k]
            power = np.abs(np.einsum("ni,ni->n", wrenches[:, leg, :3], v)
                           + np.einsum("ni,ni->n", wrenches[:, leg, 3:], w))
            speed = np.linalg.norm(v + np.cross(w, points[:, leg]), axis=-1)
            oti.append(power / speed)
        lmti[subset] = np.min(oti, axis=0)
    return np.min([np.max([lmti[s] for s in lmti if set(s) <= set(range(legs)) - {e}], axis=0)
                   for e in range(legs)], axis=0)


def test_a_spread_and_permuted_ups_hexapod_has_the_indices_of_its_leg_lines():
    chosen = family("ups_hexapod", 7)
    values = {"platform_radius": 0.42, "height": 0.9, "base_spread": 20.0, "platform_spread": 11.0, "slots": 1234}
    mechanism = chosen.mechanism(values)
    slots = permutation_of_rank(7, 1234)

    def angles(k, spread):
        return 2 * math.pi * np.asarray(k) / 7 + np.where(np.asarray(k) % 2 == 0, 0.5, -0.5) * math.radians(spread)

    base = np.column_stack([np.cos(angles(range(7), 20)), np.sin(angles(range(7), 20)), np.zeros(7)])
    platform = 0.42 * np.column_stack([np.cos(angles(slots, 11)), np.sin(angles(slots, 11)), np.zeros(7)])
    rng = np.random.default_rng(5)
    poses = np.column_stack([rng.uniform(-0.1, 0.1, (20, 2)), 0.9 + rng.uniform(-0.05, 0.05, 20),
                             rng.uniform(-0.3, 0.3, 20)])
    full = np.zeros((20, 6))
    full[:, [0, 1, 2, 5]] = poses
    result = indices_at_poses(mechanism, full, faults=1, limits=False)
    assert result.reachable.all()
    np.testing.assert_allclose(result.f_o[1], ups_f_o1(base, platform, poses), atol=1e-10)
    assert chosen.size(values)["footprint"] == 1.0


def test_the_planar_family_area_equals_the_closed_form_area_of_its_design():
    """The family writes a URDF that is loaded and mapped; fault_tolerant_area computes from the
    design's points with the closed forms: the same area for random candidates."""
    chosen = family("planar_rrr", 5)
    region = disc_region(0.4, 0.1, 30.0)
    rng = np.random.default_rng(2)
    for _ in range(3):
        values = {"platform_radius": rng.uniform(0.05, 0.3), "upper": rng.uniform(0.7, 1.2),
                  "lower": rng.uniform(0.7, 1.2), "slots": int(rng.integers(0, 120)), "mirrored": 1}
        metrics = region_metrics(chosen.mechanism(values), region, chosen.size(values))
        slots = np.array(permutation_of_rank(5, values["slots"]))
        angles = 2 * np.pi * np.arange(5) / 5
        design = PlanarDesign(np.column_stack([np.cos(angles), np.sin(angles)]),
                              values["platform_radius"] * np.column_stack([np.cos(slots * 2 * np.pi / 5),
                                                                           np.sin(slots * 2 * np.pi / 5)]),
                              np.full(5, values["upper"]), np.full(5, values["lower"]), np.full(5, -1.0))
        area, _ = fault_tolerant_area(design, radius=0.4, step=0.1, phi_step_degrees=30.0)
        assert metrics["area"] == pytest.approx(area, abs=1e-12)


def test_region_metrics_equal_a_brute_force_over_the_poses():
    chosen = family("ups_hexapod", 8)
    region = grid_region({"x": (-0.2, 0.2, 0.1), "y": (-0.1, 0.1, 0.1)}, {"yaw": (-30, 30, 15)},
                         layers=("z", (0.9, 1.1, 0.1)), level=0.42)
    mechanism = chosen.mechanism()
    metrics = region_metrics(mechanism, region, chosen.size())
    x, y, yaw, z = np.arange(-0.2, 0.21, 0.1), np.arange(-0.1, 0.11, 0.1), np.radians([-30, -15, 0, 15]), [0.9, 1.0]
    inside, values, iti = 0, [], []
    for zz in z:
        for yy in y:
            for xx in x:
                poses = np.array([[xx, yy, zz, 0, 0, angle] for angle in yaw])
                result = indices_at_poses(mechanism, poses)
                worst = result.f_o[1].min() if result.reachable.all() else 0.0
                values.append(worst)
                iti.append(result.iti.min() if result.reachable.all() else 0.0)
                inside += worst >= 0.42
    assert metrics["area"] == pytest.approx(inside * 0.01, abs=1e-12)
    assert metrics["volume"] == pytest.approx(inside * 0.001, abs=1e-12)
    assert metrics["worst"] == pytest.approx(min(values), abs=1e-12)
    assert metrics["mean"] == pytest.approx(np.mean(values), abs=1e-12)
    assert metrics["iti_floor"] == pytest.approx(min(iti), abs=1e-12)
    tolerant = (np.array(values) >= 0.42).reshape(2, 3, 5)  # (z, y, x)
    assert metrics["inscribed"] == pytest.approx(inscribed_radius(tolerant, [0.1, 0.1, 0.1]), abs=1e-12)
    assert metrics["cylinder"] == pytest.approx(inscribed_radius(tolerant.all(axis=0), [0.1, 0.1]), abs=1e-12)
    assert 0 < inside < len(values)  # the level cuts the region: the test can fail both ways


def test_the_inscribed_radius_is_the_largest_clearance_to_an_outside_point():
    rng = np.random.default_rng(4)
    for _ in range(20):
        inside = rng.random((7, 9)) < 0.8
        padded = np.pad(inside, 1)
        points = np.argwhere(padded) * [0.2, 0.1]
        outside = np.argwhere(~padded) * [0.2, 0.1]
        expected = max((np.min(np.linalg.norm(outside - p, axis=-1)) for p in points), default=0.0)
        assert inscribed_radius(inside, [0.2, 0.1]) == pytest.approx(expected, abs=1e-12)


def test_the_pareto_front_is_every_non_dominated_score_once():
    rng = np.random.default_rng(6)
    scores = np.round(rng.random((60, 2)), 1)
    front = pareto_front(scores)
    for i, row in enumerate(scores):
        dominated = any(np.all(other <= row) and np.any(other < row) for other in scores)
        first = not any(np.array_equal(scores[j], row) for j in range(i))
        assert (i in front) == (not dominated and first)
    assert list(scores[front, 0]) == sorted(scores[front, 0])


@pytest.mark.parametrize("change, message", [
    (dict(objectives=("volume",)), "needs a region with layers"),
    (dict(objectives=("speed",)), "Unknown objective 'speed'"),
    (dict(free=("radius",)), "Unknown parameter 'radius' of family 'planar_rrr'"),
    (dict(fixed={"base_radius": 3.0}), "Expected base_radius in [0.5, 2] m, got 3"),
    (dict(fixed={"upper": 1.0}), "both varied and fixed: upper"),
    (dict(bounds={"upper": (1.2, 0.9)}), "lower bound below the upper bound of upper"),
])
def test_a_bad_study_is_named_before_anything_is_computed(change, message):
    with pytest.raises(ValueError, match=re.escape(message)):
        Study(family("planar_rrr"), disc_region(0.3, 0.1, 30.0), **change)
    with pytest.raises(ValueError, match="METRIC>=VALUE"):
        Constraint.parse("area=3")


def comparable(records):
    """Records with NaN metrics (volume without layers) as None, so that equal records compare equal."""
    return json.loads(json.dumps(records).replace("NaN", "null"))


def test_a_resumed_search_equals_an_uninterrupted_one(tmp_path):
    study = Study(family("planar_rrr"), disc_region(0.3, 0.1, 30.0), budget=24, popsize=4)
    state = tmp_path / "state.jsonl"
    short = run_study(replace(study, budget=12), state=state, execution=QUIET)
    assert short.computed == 12 and short.replayed == 0
    resumed = run_study(study, state=state, execution=QUIET)
    fresh = run_study(study, execution=QUIET)
    assert resumed.replayed == 12 and resumed.computed == 12
    assert comparable(resumed.best) == comparable(fresh.best)
    assert comparable(resumed.evaluations) == comparable(fresh.evaluations)
    other = replace(study, region=disc_region(0.3, 0.1, 15.0))
    with pytest.raises(StateError, match="belongs to another study"):
        run_study(other, state=state, execution=QUIET)


def test_every_family_evaluates_its_default_region():
    for name in FAMILIES:
        chosen = family(name)
        metrics = region_metrics(chosen.mechanism(), default_region(chosen), chosen.size())
        assert metrics["area"] > 0, name  # the default region holds fault-tolerant points of the default design


# -- the command --------------------------------------------------------------------------------


def remapped_area(tmp_path, urdf, map_command: str, index: str, level: float, cell: float) -> float:
    assert map_command.startswith(f"screwkit map {urdf} ")  # the command names the file written
    options = map_command.split(" ", 3)[3].split()
    out = tmp_path / "remap.nc"
    result = screwkit("map", urdf, *options, "--out", out, "--quiet", "--overwrite")
    assert result.returncode == 0, result.stderr
    with xr.open_dataset(out) as dataset:
        return float(np.sum(np.nan_to_num(dataset[index].values) >= level) * cell)


@pytest.mark.parametrize("arguments, cell", [
    (("planar_rrr", *SMALL_DISC), 0.01),
    (("ups_hexapod", *SMALL_GRID, "--level", "0.33", "--free", "platform_radius", "--free", "height"), 0.01),
    (("prs_ups", "--grid", "roll:-20:20:10", "--grid", "pitch:-20:20:10", "--level", "0.7"), math.radians(10) ** 2),
])
def test_the_best_design_remapped_by_a_fresh_map_has_the_reported_area(tmp_path, arguments, cell):
    urdf = tmp_path / "best.urdf"
    result = screwkit("design-search", "family", *arguments, "--budget", "16", "--popsize", "4", "--urdf", urdf,
                      "--table", tmp_path / "all.csv", "--figure", tmp_path / "maps.png", "--json")
    assert result.returncode == 0, result.stderr
    summary = json.loads(result.stdout)
    best = summary["best"][0]
    level = float(arguments[arguments.index("--level") + 1]) if "--level" in arguments else 0.4
    assert best["metrics"]["area"] >= summary["start"]["metrics"]["area"]
    area = remapped_area(tmp_path, urdf, summary["map_commands"][0], "f_o1", level, cell)
    assert abs(area - best["metrics"]["area"]) <= 1e-9
    table = np.genfromtxt(tmp_path / "all.csv", delimiter=",", names=True)
    assert len(table) == summary["evaluations"] and table["best"].sum() == 1
    assert np.max(table["area"]) == pytest.approx(best["metrics"]["area"], abs=1e-12)
    assert (tmp_path / "maps.png").stat().st_size > 10_000


def test_a_pareto_search_writes_its_front(tmp_path):
    result = screwkit("design-search", "family", "ups_hexapod", *SMALL_GRID, "--level", "0.33", "--objective", "worst",
                      "--objective", "footprint", "--free", "base_radius", "--free", "platform_radius",
                      "--constraint", "lmti_floor>=0.5", "--budget", "16", "--popsize", "4",
                      "--front-figure", tmp_path / "front.png", "--table", tmp_path / "front.nc", "--json")
    assert result.returncode == 0, result.stderr
    summary = json.loads(result.stdout)
    front = summary["best"]
    assert len(front) >= 2 and all(r["metrics"]["lmti_floor"] >= 0.5 for r in front)
    worst = [r["metrics"]["worst"] for r in front]
    footprints = [r["metrics"]["footprint"] for r in front]
    assert worst == sorted(worst, reverse=True) and footprints == sorted(footprints, reverse=True)
    with xr.open_dataset(tmp_path / "front.nc") as table:
        assert int(table["best"].sum()) == len(front) and table.attrs["objectives"] == "worst, footprint"
        feasible = table.where(table["feasible"] == 1, drop=True)
        for w, f in zip(feasible["worst"].values, feasible["footprint"].values):  # no feasible design beats the front
            for r in front:
                better = (w >= r["metrics"]["worst"] and f <= r["metrics"]["footprint"]
                          and (w > r["metrics"]["worst"] or f < r["metrics"]["footprint"]))
                assert not better, (w, f, r["metrics"])
    assert (tmp_path / "front.png").stat().st_size > 10_000


def test_optimise_searches_the_planar_family_from_the_file(tmp_path):
    base = ("--budget", "12", "--popsize", "4", *SMALL_DISC, "--json", "--quiet")
    from_file = screwkit("design-search", "optimise", "planar_5rrr", *base)
    from_family = screwkit("design-search", "family", "planar_rrr", *base)
    assert from_file.returncode == 0 and from_family.returncode == 0, from_file.stderr + from_family.stderr
    assert json.loads(from_file.stdout)["best"] == json.loads(from_family.stdout)["best"]


def test_an_interrupted_search_resumes_from_its_state(tmp_path):
    arguments = ("design-search", "family", "planar_rrr", *SMALL_DISC, "--budget", "48", "--popsize", "4", "--json",
                 "--quiet")
    state = tmp_path / "state.jsonl"
    command = subprocess.Popen([sys.executable, "-m", "screwkit.cli", *arguments, "--state", str(state)],
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and (not state.exists() or len(state.read_text().splitlines()) < 13):
            assert command.poll() is None, "the search ended before it could be interrupted"
            time.sleep(0.02)
        os.killpg(command.pid, signal.SIGKILL)
        command.wait(timeout=30)
    finally:
        if command.poll() is None:
            command.kill()
    written = len(state.read_text().splitlines()) - 1
    assert 12 <= written < 48
    resumed = screwkit(*arguments, "--state", state)
    fresh = screwkit(*arguments)
    assert resumed.returncode == 0 and fresh.returncode == 0, resumed.stderr
    resumed, fresh = json.loads(resumed.stdout), json.loads(fresh.stdout)
    assert resumed["replayed"] == written and resumed["computed"] == 48 - written
    assert resumed["best"] == fresh["best"]


@pytest.mark.parametrize("arguments, message", [
    (("family", "planar_rrr", "--set", "upper=3"), "--set upper=3: Expected upper in [0.5, 1.5] m, got 3"),
    (("family", "planar_rrr", "--objective", "volume"), "The objective volume needs a region with layers."),
    (("family", "ups_hexapod", "--grid", "x:-0.1:0.1:0.1", "--grid", "q:0:1:1"), "Unknown coordinate 'q' in --grid"),
    (("family", "ups_hexapod", "--radius", "0.2"), "--radius, --step and --phi-step map a planar family's disc"),
    (("family", "planar_rrr", "--front-figure", "{tmp}/f.png"), "--front-figure needs two or more --objective."),
    (("family", "planar_rrr", "--legs", "2"), "Family planar_rrr needs at least 3 legs (3 DOF), got 2."),
    (("family", "planar_rrr", "--maxiter", "2"), "Give --budget or --maxiter, not both."),
    (("family", "fivebar"), "Expected a family (planar_rrr, ups_hexapod, rss_hexapod, delta, prs_ups), got 'fivebar'"),
    (("family", "planar_5rrr"), "design-search optimise MECHANISM"),
    (("optimise", "ups_hexapod_8"), "Design search needs a planar n-RRR; 'ups_hexapod_8' is spatial."),
    (("optimise", "five_bar_3"), "'five_bar_3' has the task coordinates x, y."),
    (("optimise", "planar_rrr"), "planar_rrr is a family: design-search family planar_rrr searches it"),
    (("permutations", "planar_5rrr", "--objective", "area"), "--objective"),
    (("optimise", "planar_5rrr", "--legs", "3"), "--legs"),
    (("family", "planar_rrr", "--state", "{tmp}/other.jsonl"), "belongs to another study"),
    (("family", "planar_rrr", "--state", "{tmp}/missing/state.jsonl"), "Cannot write the design-search state"),
    (("family", "ups_hexapod", "--grid", "x:-1:1:0.0001", "--grid", "y:-1:1:0.001"), "configurations per design"),
    (("planar_5rrr", "--permutations", "--optimise"), "Expected one of --permutations or --optimise, not both"),
])
def test_bad_search_options_give_one_line(tmp_path, arguments, message):
    other = tmp_path / "other.jsonl"
    other.write_text(json.dumps({"screwkit_design_state": 1, "study": "0" * 16, "family": "ups_hexapod",
                                 "free": ["height"]}) + "\n")
    result = screwkit("design-search", *(str(a).format(tmp=tmp_path) for a in arguments), "--budget", "4")
    assert result.returncode == 1, result.stderr
    lines = result.stderr.strip().splitlines()
    assert lines[-1].startswith("Error: ") and message in lines[-1], result.stderr
    assert "Traceback" not in result.stderr


def test_the_flat_form_of_earlier_releases_still_runs_with_a_note(tmp_path):
    """``design-search MECHANISM --permutations`` (``--optimise``, or a FAMILY alone) is its subcommand for one
    release: the same output, and a one-line note on stderr unless --quiet."""
    for old, new in ((("planar_5rrr", "--permutations", "--phi-step", "90"),
                      ("permutations", "planar_5rrr", "--phi-step", "90")),
                     (("planar_rrr", *SMALL_DISC, "--budget", "0"),
                      ("family", "planar_rrr", *SMALL_DISC, "--budget", "0")),
                     (("planar_5rrr", *SMALL_DISC, "--optimise", "--budget", "0"),
                      ("optimise", "planar_5rrr", *SMALL_DISC, "--budget", "0"))):
        flat, current = screwkit("design-search", *old, "--json"), screwkit("design-search", *new, "--json")
        assert flat.returncode == current.returncode == 0, flat.stderr + current.stderr
        assert flat.stdout == current.stdout
        note = f"Deprecated: `design-search {'FAMILY' if new[0] == 'family' else 'MECHANISM'}"
        assert flat.stderr.startswith(note) and f"is now `design-search {new[0]} " in flat.stderr, flat.stderr
        assert "Deprecated" not in current.stderr
        if new[0] == "permutations":  # (--quiet leaves the note out: the same switch for every flat form)
            quiet = screwkit("design-search", *old, "--json", "--quiet")
            assert quiet.returncode == 0 and quiet.stderr == "" and quiet.stdout == current.stdout
    study = tmp_path / "study.yaml"
    study.write_text("family: planar_rrr\nradius: 0.3\nstep: 0.1\nphi_step: 30\nbudget: 0\n")
    flat = screwkit("design-search", "--study", study, "--json", "--quiet")
    assert flat.returncode == 0 and json.loads(flat.stdout)["evaluations"] == 1, flat.stderr
    printed = screwkit("design-search", "--study", study, "--quiet")  # one evaluation, said in the singular
    assert printed.returncode == 0 and "legs), 1 evaluation (1 computed, 0 from the state file)" in printed.stdout


def test_the_design_page_names_every_family_parameter_and_metric():
    from pathlib import Path

    from screwkit.studies.design.objectives import METRICS

    page = (Path(__file__).resolve().parents[1] / "docs" / "design.md").read_text()
    for name in FAMILIES:
        assert f"`{name}`" in page, name
        for parameter in family(name).parameters:
            assert f"`{parameter.name}`" in page, (name, parameter.name)
    for metric in METRICS:
        assert f"| `{metric}` |" in page, metric


def test_a_study_file_is_the_same_search_as_its_options(tmp_path):
    study = tmp_path / "study.yaml"
    study.write_text("family: planar_rrr\nobjectives: [area]\nset: {mirrored: 1}\nstart: {upper: 0.9}\n"
                     "bounds: {lower: [0.8, 1.2]}\nradius: 0.3\nstep: 0.1\nphi_step: 30\nbudget: 12\npopsize: 4\n")
    from_file = screwkit("design-search", "family", "--study", study, "--json", "--quiet")
    from_options = screwkit("design-search", "family", "planar_rrr", "--objective", "area", "--set", "mirrored=1",
                            "--start", "upper=0.9", "--bounds", "lower=0.8:1.2", *SMALL_DISC, "--budget", "12",
                            "--popsize", "4", "--json", "--quiet")
    assert from_file.returncode == 0 and from_options.returncode == 0, from_file.stderr + from_options.stderr
    assert json.loads(from_file.stdout) == json.loads(from_options.stdout)
    overridden = json.loads(screwkit("design-search", "family", "--study", study, "--budget", "0", "--json").stdout)
    assert overridden["evaluations"] == 1 and overridden["start"]["values"]["upper"] == 0.9
    study.write_text("family: planar_rrr\ncolour: blue\n")
    bad = screwkit("design-search", "family", "--study", study)
    assert bad.returncode == 1 and "Error: Unknown key 'colour' in the study file" in bad.stderr


def delta_rods(angles, base_radius, platform_radius, arm, rod, position):
    """Unit rod directions of Delta legs, elbow out, from the legs' inverse kinematics (a quadratic in
    tan(t / 2) per leg, the root with the elbow farther out)."""
    rods = []
    for angle in angles:
        e = np.array([math.cos(angle), math.sin(angle), 0.0])
        delta = np.asarray(position) + platform_radius * e - base_radius * e
        k = delta @ delta + arm**2 - rod**2
        p, q = 2 * arm * (delta @ e), -2 * arm * delta[2]
        roots = np.roots([k + p, -2 * q, k - p])
        theta = max(2 * np.arctan(roots[np.abs(roots.imag) < 1e-12].real), key=math.cos)
        elbow = base_radius * e + arm * (math.cos(theta) * e - math.sin(theta) * np.array([0.0, 0.0, 1.0]))
        rods.append((np.asarray(position) + platform_radius * e - elbow) / rod)
    return np.array(rods)


def test_a_five_legged_delta_of_the_family_has_the_pressure_angle_f_o1():
    """F_O1 of a translating platform driven by rod forces: OTI_k of a 3-leg set is
    |u_k . (u_j x u_l)| / |u_j x u_l|; a set of four legs keeps its best 3-leg set; the worst fault."""
    values = {"base_radius": 0.25, "platform_radius": 0.07, "arm": 0.4, "rod": 0.9, "depth": 0.8, "spread": 20.0}
    mechanism = family("delta", 5).mechanism(values)
    angles = 2 * np.pi * np.arange(5) / 5 + np.where(np.arange(5) % 2 == 0, 0.5, -0.5) * math.radians(20)
    rng = np.random.default_rng(8)
    poses = np.column_stack([rng.uniform(-0.2, 0.2, (15, 2)), rng.uniform(-0.9, -0.7, 15)])
    result = indices_at_poses(mechanism, poses, faults=1)
    assert result.reachable.all()
    for index, pose in enumerate(poses):
        u = delta_rods(angles, 0.25, 0.07, 0.4, 0.9, pose)

        def oti(members, u=u):
            return min(abs(np.linalg.det(u[list(members)])) / np.linalg.norm(np.cross(*u[[j for j in members
                                                                                         if j != k]]))
                       for k in members)

        expected = min(max(oti(s) for s in combinations([i for i in range(5) if i != e], 3)) for e in range(5))
        assert result.f_o[1][index] == pytest.approx(expected, abs=1e-10)
    assert family("delta").size(values) == {"footprint": 0.65, "link_length": 0.9}


def test_a_grid_of_a_length_and_an_angle_has_no_distances():
    chosen = family("ups_hexapod")
    region = grid_region({"x": (-0.1, 0.1, 0.1), "roll": (-10, 10, 10)}, {}, level=0.3)
    metrics = region_metrics(chosen.mechanism(), region, chosen.size())
    assert region.unit("area") == "m rad" and region.unit("inscribed") == "mixed"
    assert math.isnan(metrics["inscribed"]) and math.isnan(metrics["cylinder"])
    poses = np.array([[x, 0, 1, roll, 0, 0] for roll in np.radians([-10, 0, 10]) for x in (-0.1, 0, 0.1)])
    tolerant = np.nan_to_num(indices_at_poses(chosen.mechanism(), poses).f_o[1]) >= 0.3
    assert metrics["area"] == pytest.approx(tolerant.sum() * 0.1 * math.radians(10), abs=1e-12)
    angular = grid_region({"roll": (-10, 10, 10), "pitch": (-10, 10, 10)}, {})
    assert angular.unit("area") == "rad^2" and angular.unit("inscribed") == "rad"


def scaled_hexapod_metrics(scale: float, quarter_turns: int) -> dict:
    """Metrics of an 8-UPS with spread slots, every length times ``scale`` and the mechanism turned by
    ``quarter_turns`` x 90 deg about the vertical (the square map turns onto itself), on the region
    scaled with it: x, y in +-0.2, three layers of z about the home height, yaw in +-30 deg."""
    from screwkit.io.loader import load_text
    from screwkit.model.hexapod_writer import hexapod_points, ups_hexapod_urdf

    base, platform = hexapod_points(8, 1.0, 0.45, (0, 4, 2, 7, 5, 3, 1, 6), base_spread=0.3, platform_spread=0.2)
    turn = np.linalg.matrix_power(np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]), quarter_turns)
    mechanism = load_text(ups_hexapod_urdf("scaled", scale * base @ turn.T, scale * platform @ turn.T, scale * 1.0))
    region = grid_region({"x": (-0.2 * scale, 0.2 * scale, 0.1 * scale), "y": (-0.2 * scale, 0.2 * scale, 0.1 * scale)},
                         {"yaw": (-30, 40, 10)}, layers=("z", (0.9 * scale, 1.2 * scale, 0.1 * scale)), level=0.34)
    return region_metrics(mechanism, region)


@pytest.mark.parametrize("scale, quarter_turns", [(1e-3, 0), (1e3, 0), (1.0, 1), (1e-3, 3)])
def test_region_metrics_follow_the_scale_and_not_the_frame(scale, quarter_turns):
    """Lengths x s: areas x s^2, the volume x s^3, radii x s, index values unchanged; a turn of the
    mechanism about the vertical (a change of world frame that maps the square map onto itself)
    changes nothing."""
    reference, scaled = scaled_hexapod_metrics(1.0, 0), scaled_hexapod_metrics(scale, quarter_turns)
    assert 0 < reference["area"] < 75 * 0.01  # the level cuts the region: the test can fail both ways
    assert reference["inscribed"] > 0 and reference["cylinder"] > 0
    for name, power in (("area", 2), ("volume", 3), ("inscribed", 1), ("cylinder", 1), ("worst", 0), ("mean", 0),
                        ("iti_floor", 0), ("lmti_floor", 0)):
        assert scaled[name] == pytest.approx(reference[name] * scale**power, rel=1e-9, abs=0), name


def test_a_volume_search_gives_one_map_command_per_layer(tmp_path):
    urdf = tmp_path / "best.urdf"
    result = screwkit("design-search", "family", "delta", "--grid", "x:-0.2:0.2:0.1", "--grid", "y:-0.2:0.2:0.1",
                      "--layers", "z:-0.9:-0.6:0.1", "--objective", "volume", "--budget", "6", "--popsize", "2",
                      "--urdf", urdf, "--figure", tmp_path / "maps.png", "--json", "--quiet")
    assert result.returncode == 0, result.stderr
    summary = json.loads(result.stdout)
    assert len(summary["map_commands"]) == 3 and all("--at" in command for command in summary["map_commands"])
    areas = [remapped_area(tmp_path, urdf, command, "f_o1", 0.5, 0.01) for command in summary["map_commands"]]
    assert sum(areas) * 0.1 == pytest.approx(summary["best"][0]["metrics"]["volume"], abs=1e-9)
    assert summary["best"][0]["metrics"]["volume"] >= summary["start"]["metrics"]["volume"] > 0


@pytest.mark.parametrize("objectives, budget", [(("area",), 0), (("area",), 4), (("area",), 50),
                                                (("area", "footprint"), 30)])
def test_a_search_announces_the_evaluations_it_makes(objectives, budget):
    """The designs a search plans (its budget in the optimiser's whole generations: differential evolution rounds
    down, NSGA-II up, at least one; the start alone for a budget of 0) are the designs it evaluates here, where
    neither optimiser meets a design twice nor converges before the budget."""
    planar = family("planar_rrr", 5)
    study = Study(planar, disc_region(0.2, 0.1, 90.0), objectives, budget=budget, seed=3)
    assert study.generation == 24
    result = run_study(study, execution=QUIET)
    assert len(result.evaluations) == study.planned_evaluations
    assert study.planned_evaluations == {0: 1, 4: 24, 50: 48, 30: 48}[budget]


# -- designs that cannot be built, seeds, integer parameters, evaluations lost --------------------------------

UNREACHABLE = {"base_radius": 2.0}
"""planar_rrr on a base of radius 2 m: arms of 0.5 m cannot reach the platform at the home pose."""


def test_a_design_that_cannot_be_built_is_never_the_best():
    """It keeps its real size (footprint, link_length: the smallest of the family) and its error, but it is
    infeasible: no objective picks it, the size ones included."""
    chosen = family("planar_rrr")
    for objectives in (("link_length",), ("footprint",), ("area", "link_length")):
        study = Study(chosen, disc_region(0.3, 0.1, 30.0), objectives, fixed=UNREACHABLE,
                      initial={"upper": 0.5, "lower": 0.5}, budget=12, popsize=2)
        result = run_study(study, execution=QUIET)
        failed = [r for r in result.evaluations if "error" in r["metrics"]]
        assert failed and "cannot reach its platform joint" in failed[0]["metrics"]["error"]
        assert not any(r["feasible"] for r in failed)
        assert result.best and all("error" not in r["metrics"] for r in result.best)
        assert all(r["feasible"] for r in result.evaluations if "error" not in r["metrics"])


def test_a_search_keeps_its_designs_that_cannot_be_built_out_of_its_files(tmp_path):
    common = ("design-search", "family", "planar_rrr", "--set", "base_radius=2", "--start", "upper=0.5", "--start",
              "lower=0.5", *SMALL_DISC)
    urdf, table, figure = tmp_path / "best.urdf", tmp_path / "all.csv", tmp_path / "maps.png"
    result = screwkit(*common, "--objective", "link_length", "--budget", "6", "--popsize", "2", "--urdf", urdf,
                      "--table", table, "--figure", figure, "--json")
    assert result.returncode == 0, result.stderr
    summary = json.loads(result.stdout)
    assert "cannot reach its platform joint" in summary["start"]["metrics"]["error"]
    assert "error" not in summary["best"][0]["metrics"]
    assert load(str(urdf)).name and figure.stat().st_size > 10_000
    rows = np.genfromtxt(table, delimiter=",", names=True)
    assert rows["feasible"][0] == 0 and rows["best"][0] == 0 and rows["feasible"].sum() >= 1
    state = tmp_path / "state.jsonl"
    none = screwkit(*common, "--budget", "0", "--state", state, "--urdf", tmp_path / "none.urdf", "--table",
                    tmp_path / "none.csv", "--figure", tmp_path / "none.png")
    line = one_line_error(none, "No design evaluated can be built", "leg 1 cannot reach its platform joint",
                          after=("planar_rrr (5 legs): ",))
    assert "the state file" not in line or str(state) in line
    assert sorted(os.listdir(tmp_path)) == sorted(["best.urdf", "all.csv", "maps.png", "state.jsonl"])
    assert len(state.read_text().splitlines()) == 2  # the header and the start's record, kept


def test_a_start_on_the_edge_of_narrowed_bounds_is_searched():
    """The start (upper = 1 m clipped to 0.8) sits on a bound that differential evolution's rescaling would move
    just outside its unit interval."""
    study = Study(family("planar_rrr"), disc_region(0.3, 0.1, 30.0), bounds={"upper": (0.6, 0.8)}, budget=6,
                  popsize=2)
    result = run_study(study, execution=QUIET)
    assert result.start["values"]["upper"] == 0.8 and len(result.evaluations) > 1
    assert all(0.6 <= r["values"]["upper"] <= 0.8 for r in result.evaluations)


def test_a_seed_out_of_range_is_refused_before_any_work(tmp_path):
    for seed in ("-1", str(2**32)):
        one_line_error(screwkit("design-search", "family", "planar_rrr", *SMALL_DISC, "--budget", "6", "--popsize",
                                "2", "--seed", seed, "--state", tmp_path / "state.jsonl"), "seed", seed)
        assert not (tmp_path / "state.jsonl").exists()
    study = tmp_path / "study.yaml"
    for seed in ("-1", str(2**32), "0.5", "abc"):
        study.write_text(f"family: planar_rrr\nradius: 0.3\nstep: 0.1\nphi_step: 30\nbudget: 6\npopsize: 2\n"
                         f"seed: {seed}\n")
        one_line_error(screwkit("design-search", "family", "--study", study), "seed", seed)
    assert screwkit("design-search", "family", "planar_rrr", *SMALL_DISC, "--budget", "0", "--seed",
                    str(2**32 - 1)).returncode == 0
    with pytest.raises(ValueError, match="seed"):
        Study(family("planar_rrr"), disc_region(0.3, 0.1, 30.0), seed=-1)


def test_a_design_of_integer_parameters_is_evaluated_once(tmp_path):
    """NSGA-II varies the integer parameters continuously: the designs it asks that round to the same one are one
    evaluation, and a state file of earlier releases (keyed by the unrounded values) resumes."""
    study = Study(family("planar_rrr"), disc_region(0.3, 0.1, 30.0), ("area", "link_length"),
                  free=("mirrored", "upper"), budget=24, popsize=4)
    state = tmp_path / "state.jsonl"
    result = run_study(study, state=state, execution=QUIET)
    designs = [(r["values"]["mirrored"], r["values"]["upper"]) for r in result.evaluations]
    assert len(set(designs)) == len(designs) == result.computed
    lines = state.read_text().splitlines()
    assert len(lines) == 1 + result.computed
    older = [lines[0]]  # the keys an earlier release wrote: the vector as asked, mirrored unrounded
    for line in lines[1:]:
        record = json.loads(line)
        vector = np.frombuffer(bytes.fromhex(record["key"]), dtype=np.float64).copy()
        vector[0] += 0.25 if vector[0] < 1 else -0.25
        older.append(json.dumps({"key": vector.tobytes().hex(), "metrics": record["metrics"]}))
    state.write_text("\n".join(older) + "\n")
    resumed = run_study(study, state=state, execution=QUIET)
    assert resumed.computed == 0 and resumed.replayed == result.computed
    assert comparable(resumed.evaluations) == comparable(result.evaluations)


def test_nothing_varied_by_default_that_is_fixed(tmp_path):
    """--set of every parameter the family varies by default: the others vary (none was asked to vary)."""
    result = screwkit("design-search", "family", "planar_rrr", "--set", "platform_radius=0.1", "--set", "upper=1",
                      "--set", "lower=1", *SMALL_DISC, "--budget", "0", "--json")
    assert result.returncode == 0, result.stderr
    summary = json.loads(result.stdout)
    assert summary["free"] == ["base_radius", "slots", "mirrored"]
    assert summary["start"]["values"]["upper"] == 1.0 and summary["start"]["values"]["platform_radius"] == 0.1


def test_a_scheduler_lost_mid_search_says_what_the_state_keeps(tmp_path, monkeypatch):
    """The state file holds every generation evaluated before the scheduler was lost: the line says so."""
    from screwkit.studies.design import evaluations
    from screwkit.studies.tasks import ClusterError

    calls = []

    def lost_after_the_start(function, arguments, execution=None, **options):
        calls.append(len(arguments))
        if len(calls) > 1:
            raise ClusterError("Lost the Dask scheduler at tcp://127.0.0.1:1 mid-run (CancelledError); "
                               "nothing was written.")
        return [function(*a) for a in arguments]

    monkeypatch.setattr(evaluations, "run_tasks", lost_after_the_start)
    study = Study(family("planar_rrr"), disc_region(0.3, 0.1, 30.0), budget=12, popsize=4)
    remote = Execution(scheduler="tcp://127.0.0.1:1", progress=False)
    state = tmp_path / "state.jsonl"
    with pytest.raises(ClusterError) as raised:
        run_study(study, state=state, execution=remote)
    message = str(raised.value)
    assert message.startswith("Lost the Dask scheduler at tcp://127.0.0.1:1 mid-run (CancelledError)")
    assert "nothing was written" not in message and f"the state file {state} keeps 1 design" in message
    calls.clear()
    with pytest.raises(ClusterError, match="nothing was written"):  # without a state file, it is true
        run_study(study, execution=remote)
    assert run_study(replace(study, budget=0), state=state, execution=QUIET).replayed == 1


def test_an_evaluation_process_killed_gives_one_line_and_the_state_resumes(tmp_path):
    """kill -9 of a local evaluation process (as the out-of-memory killer does): one line, exit status 1, and the
    state file keeps the designs evaluated before, which a run with it replays."""
    import psutil  # (a dependency of dask.distributed)
    arguments = ("design-search", "family", "planar_rrr", "--step", "0.03", "--phi-step", "2", "--budget", "120",
                 "--popsize", "4", "--state", str(tmp_path / "state.jsonl"))
    state = tmp_path / "state.jsonl"
    command = subprocess.Popen([sys.executable, "-W", "error", "-m", "screwkit.cli", *arguments],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        deadline, victim = time.monotonic() + 240, None
        while victim is None and time.monotonic() < deadline:
            assert command.poll() is None, "the search ended before a process could be killed"
            if state.exists() and len(state.read_text().splitlines()) >= 2:
                workers = [p for p in psutil.Process(command.pid).children(recursive=True)
                           if "spawn_main" in " ".join(p.cmdline())]
                victim = workers[0] if workers else None
            time.sleep(0.05)
        assert victim is not None, "no evaluation process started"
        victim.send_signal(signal.SIGKILL)
        stdout, stderr = command.communicate(timeout=120)
    finally:
        if command.poll() is None:
            os.killpg(command.pid, signal.SIGKILL)
            command.wait(timeout=30)
    kept = len(state.read_text().splitlines()) - 1
    assert kept >= 1
    line = one_line_error(subprocess.CompletedProcess(command.args, command.returncode, stdout, stderr),
                          "An evaluation process died", f"the state file {state} keeps {kept} design",
                          after=("planar_rrr (5 legs): ",))
    assert "resume" in line
    resumed = screwkit(*arguments[:7], "--budget", "0", "--state", state, "--json")
    assert resumed.returncode == 0, resumed.stderr
    assert json.loads(resumed.stdout)["replayed"] == 1 and json.loads(resumed.stdout)["computed"] == 0
