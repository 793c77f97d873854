"""The command line and the URDF path end to end: the paper's numbers, frames, bad input."""

from __future__ import annotations

import json

import numpy as np
import pytest
from click.testing import CliRunner

from screwkit.cli import app
from screwkit.mechanism import load
from screwkit.planar import paper_5rrr, planar_joint_points, rrr_chain_screws
from screwkit.transmission import analyze


def run(*arguments):
    result = CliRunner().invoke(app, list(arguments), catch_exceptions=False)
    return result


def test_analyze_reproduces_the_paper_through_the_urdf():
    result = run("analyze", "planar_5rrr", "--pose", "-0.2", "0", "45")
    assert result.exit_code == 0, result.output
    assert "ITI  (Eq. 7)                        0.6973" in result.output
    assert "LMTI (Eq. 11, all actuators)        0.9814" in result.output
    assert "F_O1 (Eq. 12) 0.6793   F_IO1 (Eq. 14) 0.6793" in result.output


def test_analyze_json():
    result = run("analyze", "planar_5rrr", "--pose", "-0.2", "0", "45", "--json")
    assert result.exit_code == 0, result.output
    report = json.loads(result.output)
    assert round(report["iti"], 4) == 0.6973
    assert round(report["lmti"], 4) == 0.9814
    assert set(report["f_o"]) == set(report["f_io"]) == {"1", "2"}
    assert round(report["f_o"]["1"], 4) == round(report["f_io"]["1"], 4) == 0.6793
    assert report["not_mutual_interference"] == []


def test_urdf_path_equals_hand_built_screws(rng):
    mechanism = load("planar_5rrr")
    poses = np.column_stack([rng.uniform(-0.4, 0.4, 3000), rng.uniform(-0.4, 0.4, 3000), rng.uniform(-np.pi, np.pi, 3000)])
    solution = mechanism.solve(poses)
    ok = np.asarray(solution.reachable)
    assert ok.mean() > 0.5
    from_urdf = analyze(mechanism.chain_screws(solution, unreachable="drop"))
    base, elbows, distal, reachable = planar_joint_points(paper_5rrr(), poses[ok])
    assert reachable.all()
    by_hand = analyze(rrr_chain_screws(base, elbows, distal))
    np.testing.assert_allclose(from_urdf.iti_actuators, by_hand.iti_actuators, atol=1e-9)
    np.testing.assert_allclose(from_urdf.oti_submechanisms, by_hand.oti_submechanisms, atol=1e-9)
    for j in by_hand.f_o:
        np.testing.assert_allclose(from_urdf.f_o[j], by_hand.f_o[j], atol=1e-9)


def placed_copy(tmp_path, rpy, xyz):
    """The bundled 5-RRR hung below a new world link by a fixed joint with the given origin."""
    text = load("planar_5rrr").description.text
    text = text if isinstance(text, str) else text.decode()
    head, tail = text.split("<link name=\"base_link\">", 1)
    extra = (f'<link name="world" />\n  <joint name="world_to_base" type="fixed">\n    <parent link="world" />\n'
             f'    <child link="base_link" />\n    <origin xyz="{xyz[0]} {xyz[1]} {xyz[2]}" rpy="{rpy[0]} {rpy[1]} {rpy[2]}" />\n'
             f'  </joint>\n  ')
    path = tmp_path / "tilted_5rrr.urdf"
    path.write_text(head + extra + "<link name=\"base_link\">" + tail)
    return path


def test_mechanism_placed_and_tilted_in_space_gives_the_same_indices(tmp_path, rng):
    reference = load("planar_5rrr")
    moved = load(placed_copy(tmp_path, (0.4, -0.7, 1.1), (3.0, -2.0, 5.0)))
    poses = np.column_stack([rng.uniform(-0.3, 0.3, 500), rng.uniform(-0.3, 0.3, 500), rng.uniform(-np.pi, np.pi, 500)])
    first = analyze(reference.chain_screws(reference.solve(poses), unreachable="drop"))
    second_screws = moved.chain_screws(moved.solve(poses), unreachable="drop")
    assert np.abs(second_screws[0].twists[..., 2]).max() < 0.99  # the joint axes really are tilted
    second = analyze(second_screws)
    np.testing.assert_allclose(first.iti_actuators, second.iti_actuators, atol=1e-9)
    np.testing.assert_allclose(first.oti_submechanisms, second.oti_submechanisms, atol=1e-9)
    np.testing.assert_allclose(first.f_o[1], second.f_o[1], atol=1e-9)
    result = run("analyze", str(tmp_path / "tilted_5rrr.urdf"), "--pose", "-0.2", "0", "45", "--json")
    assert round(json.loads(result.output)["f_o"]["1"], 4) == 0.6793


@pytest.mark.parametrize("arguments, message", [
    (("analyze", "planar_9rrr"), "Unknown bundled mechanism 'planar_9rrr'; bundled are: coop_arms, planar_4rpr"),
    (("analyze", "planar_5rrr", "--pose", "0", "0"), "Expected --pose with 3 values (x, y, phi) for mechanism 'planar_5rrr', got 2"),
    (("analyze", "planar_5rrr", "--pose", "0", "nan", "0"), "Expected finite values in `poses`, got nan"),
    (("analyze", "planar_5rrr", "--pose", "0", "x", "0"), "Expected numbers after --pose, got 0 x 0"),
    (("analyze", "planar_5rrr", "--pose", "5", "0", "0"), "is unreachable for mechanism 'planar_5rrr': chain 'chain_1' misses closure by"),
    (("sweep", "planar_5rrr", "--phi", "0:360"), "Expected `--phi` as START:STOP:STEP"),
    (("map", "planar_5rrr", "--radius", "0.3"), "A planar map takes --radius and --step"),
])
def test_bad_input_is_one_line(arguments, message):
    result = run(*arguments)
    assert result.exit_code == 1
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("Error: "), result.output
    assert message in lines[0], lines[0]


def test_verify_compares_with_the_closed_forms():
    result = run("verify", "planar_5rrr", "--samples", "500")
    assert result.exit_code == 0, result.output
    deviation = float(result.output.strip().splitlines()[-1].split()[-1])
    assert deviation < 1e-9
    assert run("verify", "planar_4rpr", "--samples", "300").exit_code == 0


def test_list_names_the_bundled_robots():
    result = run("list")
    assert result.output.split() == ["coop_arms", "planar_4rpr", "planar_5rrr", "rss_hexapod_8", "ups_hexapod_8"]


def test_console_entry_point_exits_with_the_status_and_complete_output(tmp_path):
    """main() ends the process without the interpreter's teardown: nothing may be lost."""
    import subprocess
    import sys

    import xarray as xr

    def command(*arguments):
        return subprocess.run([sys.executable, "-m", "screwkit.cli", *arguments], capture_output=True, text=True,
                              timeout=300)

    listed = command("list")
    assert listed.returncode == 0 and "planar_5rrr" in listed.stdout and "ups_hexapod_8" in listed.stdout
    analysed = command("analyze", "planar_5rrr", "--pose", "-0.2", "0", "45", "--json")
    assert analysed.returncode == 0, analysed.stderr
    assert json.loads(analysed.stdout)["f_o"]["1"] == pytest.approx(0.6793, abs=5e-5)  # the whole JSON arrived
    wrong = command("analyze", "no_such_robot")
    assert wrong.returncode == 1 and "Unknown bundled mechanism 'no_such_robot'" in wrong.stderr
    path = tmp_path / "map.nc"
    mapped = command("map", "planar_5rrr", "--radius", "0.1", "--step", "0.05", "--phi-step", "60", "--out", str(path))
    assert mapped.returncode == 0, mapped.stderr
    assert f"wrote {path}" in mapped.stderr
    with xr.open_dataset(path) as dataset:
        assert np.isfinite(dataset["f_o1"].values).sum() == 13  # the disc of radius 0.1 m at 0.05 m steps
