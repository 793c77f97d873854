"""Non-redundant mechanisms (as many actuators as DOF) through every command, as users run them.

The bundled ``five_bar`` (planar, 2 DOF, point output) and ``ups_stewart_6`` (the Gough-Stewart platform)
run through ``analyze``, ``sweep``, ``map``, ``view``, ``verify`` and ``design-search`` in subprocesses.
Their indices are checked against independent computations: the five-bar's textbook pressure angles (its
ITIs the angles between proximal and distal links, its OTI the angle between the distal links) and the
Stewart platform's OTIs from its leg lines (the output twist of leg k reciprocal to the other five leg
forces, by an SVD), and a = n gives F_O1 = F_IO1 = 0 with every actuator a tied worst fault.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from helpers import leg_line_otis, screwkit
from screwkit.closure import chain_screws, solve
from screwkit.io.loader import load
from screwkit.studies import indices_at_pose

TOLERANCE = 1e-9


def test_five_bar_indices_are_the_textbook_pressure_angles():
    mechanism = load("five_bar")
    assert mechanism.dof == 2 and len(mechanism.actuators) == 2 and mechanism.output_point is not None
    for pose in mechanism.named_poses.values():
        result = indices_at_pose(mechanism, pose)
        points = [np.asarray(axes_points)[0] for axes_points in solve(mechanism, pose[None]).joint_points]
        proximal = [p[1] - p[0] for p in points]
        distal = [p[2] - p[1] for p in points]
        sine = [abs(np.cross(a, b)[2]) / (np.linalg.norm(a) * np.linalg.norm(b)) for a, b in zip(proximal, distal)]
        np.testing.assert_allclose(result.iti_actuators, sine, atol=TOLERANCE)
        pressure = abs(np.cross(distal[0], distal[1])[2]) / np.prod([np.linalg.norm(d) for d in distal])
        assert abs(result.lmti - pressure) < TOLERANCE
        assert result.f_o == {1: 0.0} and result.f_io == {1: 0.0}
        assert set(result.worst_fault_ties(1)) == {(name,) for name in mechanism.actuator_names}


def test_stewart_platform_otis_are_the_leg_lines():
    mechanism = load("ups_stewart_6")
    pose = mechanism.home_pose + np.array([0.03, -0.02, 0.05, np.deg2rad(4), np.deg2rad(-3), np.deg2rad(12)])
    result = indices_at_pose(mechanism, pose)
    chains = chain_screws(mechanism, solve(mechanism, pose[None]))
    universal = [chain.points[0, 0] for chain in chains]
    spherical = [chain.points[0, -1] for chain in chains]
    otis = leg_line_otis(universal, spherical)  # velocities of the S centres
    np.testing.assert_allclose(result.oti_actuators[0], otis, atol=TOLERANCE)
    assert abs(result.lmti - min(otis)) < TOLERANCE and 0.2 < result.lmti < 1.0
    assert result.iti == pytest.approx(1.0) and result.f_o == {1: 0.0}
    report = result.to_dict()
    assert report["redundancy"] == 0 and len(report["worst_fault_ties"]["1"]) == 6


@pytest.mark.parametrize("name, sweep, grid, over", [
    ("five_bar", "x:-0.04:0.05:0.02", ("x:-0.04:0.04:0.04", "y:0.3:0.38:0.04"), None),
    ("ups_stewart_6", "yaw:-10:11:5", ("x:-0.1:0.1:0.1", "y:-0.1:0.1:0.1"), "yaw:-10:11:10"),
])
def test_every_command_runs_on_a_non_redundant_mechanism(name, sweep, grid, over, tmp_path):
    analysed = screwkit("analyze", name)
    assert analysed.returncode == 0, analysed.stderr
    assert "no redundancy" in analysed.stdout and "F_O1 = F_IO1 = 0" in analysed.stdout
    assert "worst fault:" not in analysed.stdout  # every actuator is a worst fault: none is singled out
    report = json.loads(screwkit("analyze", name, "--json").stdout)
    assert report["f_o"] == {"1": 0.0} and report["redundancy"] == 0 and report["lmti"] > 0.2

    swept = screwkit("sweep", name, "--sweep", sweep, "--out", tmp_path / "sweep.nc")
    assert swept.returncode == 0, swept.stderr
    import xarray

    with xarray.open_dataset(tmp_path / "sweep.nc") as dataset:
        assert bool(dataset["reachable"].all()) and float(dataset["lmti"].min()) > 0.2
        assert float(np.abs(dataset["f_o1"]).max()) == 0.0
        assert float(np.abs(dataset["lmti_remaining1"]).max()) == 0.0  # one actuator left: nothing held

    arguments = ["map", name, "--grid", grid[0], "--grid", grid[1], "--out", tmp_path / "map.nc", "--quiet"]
    mapped = screwkit(*arguments, *(["--over", over] if over else []))
    assert mapped.returncode == 0, mapped.stderr
    with xarray.open_dataset(tmp_path / "map.nc") as dataset:
        assert float(dataset["lmti"].min()) > 0.2 and float(np.abs(dataset["f_o1"]).max()) == 0.0

    for failed in ((), ("--failed", load(name).actuator_names[0])):
        viewed = screwkit("view", name, *failed, "--html", tmp_path / f"view{len(failed)}.html", "--quiet")
        assert viewed.returncode == 0, viewed.stderr
        assert (tmp_path / f"view{len(failed)}.html").stat().st_size > 10_000


def test_verify_and_design_search_where_they_apply():
    verified = screwkit("verify", "five_bar", "--samples", "300")
    assert verified.returncode == 0, verified.stdout + verified.stderr
    assert "textbook pressure angles" in verified.stdout
    spatial = screwkit("verify", "ups_stewart_6")
    assert spatial.returncode == 1 and spatial.stderr.count("\n") == 1 and "spatial" in spatial.stderr
    refused = screwkit("design-search", "permutations", "five_bar")
    assert refused.returncode == 1 and refused.stderr.count("\n") == 1 and "x, y" in refused.stderr
    for family, legs, region in (("planar_rrr", "3", ["--step", "0.2", "--phi-step", "30"]),
                                 ("ups_hexapod", "6", ["--grid", "x:-0.1:0.1:0.1", "--grid", "y:-0.1:0.1:0.1",
                                                       "--over", "yaw:0:10:10", "--level", "0.1"])):
        searched = screwkit("design-search", "family", family, "--legs", legs, "--budget", "4", "--json", "--quiet",
                            *region)
        assert searched.returncode == 0, searched.stdout + searched.stderr
        report = json.loads(searched.stdout)
        assert report["legs"] == int(legs) and report["region"].startswith("lmti >= ")
