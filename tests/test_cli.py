"""The command line as users run it (a subprocess each): the paper's numbers, outputs, errors, conventions."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from helpers import one_line_error, screwkit
from screwkit.closure import chain_screws, solve
from screwkit.indices.analysis import analyze
from screwkit.io.loader import load
from screwkit.screw.planar import paper_5rrr, planar_joint_points, rrr_chain_screws


def test_analyze_reproduces_the_paper_through_the_urdf():
    result = screwkit("analyze", "planar_5rrr", "--pose", "-0.2", "0", "45")
    assert result.returncode == 0, result.stderr
    assert "ITI  (Eq. 7)                        0.6973" in result.stdout
    assert "LMTI (Eq. 11, all actuators)        0.9814" in result.stdout
    assert "F_O1 (Eq. 12) 0.6793   F_IO1 (Eq. 14) 0.6793" in result.stdout
    assert result.stderr == ""


def test_analyze_json_and_named_poses():
    by_name = screwkit("analyze", "planar_5rrr", "--pose", "paper_fig_2a", "--json")
    by_values = screwkit("analyze", "planar_5rrr", "--pose", "-0.2", "0", "45", "--json")
    assert by_name.returncode == by_values.returncode == 0, by_name.stderr + by_values.stderr
    report = json.loads(by_name.stdout)
    assert report == json.loads(by_values.stdout)
    assert report["pose"] == {"x": -0.2, "y": 0.0, "phi": 45.0}
    assert round(report["iti"], 4) == 0.6973 and round(report["lmti"], 4) == 0.9814
    assert set(report["f_o"]) == set(report["f_io"]) == {"1", "2"}
    assert round(report["f_o"]["1"], 4) == round(report["f_io"]["1"], 4) == 0.6793
    assert report["worst_faults"]["1"] == ["chain_2:chain_2_joint_b"]
    assert report["actuators"][0] == "chain_1:chain_1_joint_b" and report["not_mutual_interference"] == []
    four = json.loads(screwkit("analyze", "planar_4rpr", "--pose", "three_lines_concurrent", "--json").stdout)
    assert four["not_mutual_interference"] == ["leg_4:leg_4_joint_slider"] and four["f_o"]["1"] < 1e-9


def test_info_lists_task_coordinates_solvers_and_named_poses():
    result = screwkit("info", "planar_4rpr", "--json")
    assert result.returncode == 0, result.stderr
    info = json.loads(result.stdout)
    assert info["dof"] == 3
    assert info["task_coordinates"] == [{"name": "x", "unit": "m"}, {"name": "y", "unit": "m"},
                                        {"name": "phi", "unit": "deg"}]
    assert {chain["solver"] for chain in info["chains"]} == {"planar_rpr"}
    assert info["named_poses"]["three_lines_concurrent"]["phi"] == pytest.approx(np.rad2deg(0.4))
    text = screwkit("info", "coop_arms")
    assert text.returncode == 0 and "solver newton: damped Newton: not ups (" in text.stdout


def test_urdf_path_equals_hand_built_screws(rng):
    mechanism = load("planar_5rrr")
    poses = np.column_stack([rng.uniform(-0.4, 0.4, 3000), rng.uniform(-0.4, 0.4, 3000),
                             rng.uniform(-np.pi, np.pi, 3000)])
    solution = solve(mechanism, poses)
    ok = np.asarray(solution.reachable)
    assert ok.mean() > 0.5
    from_urdf = analyze(chain_screws(mechanism, solution, unreachable="drop"))
    base, elbows, distal, reachable = planar_joint_points(paper_5rrr(), poses[ok])
    assert reachable.all()
    by_hand = analyze(rrr_chain_screws(base, elbows, distal))
    np.testing.assert_allclose(from_urdf.iti_actuators, by_hand.iti_actuators, atol=1e-9)
    np.testing.assert_allclose(from_urdf.oti_submechanisms, by_hand.oti_submechanisms, atol=1e-9)
    for j in by_hand.f_o:
        np.testing.assert_allclose(from_urdf.f_o[j], by_hand.f_o[j], atol=1e-9)
        np.testing.assert_array_equal(from_urdf.worst_fault_indices[j], by_hand.worst_fault_indices[j])


def placed_copy(tmp_path, rpy, xyz):
    """The bundled 5-RRR hung below a new world link by a fixed joint with the given origin."""
    text = load("planar_5rrr").description.text
    head, tail = text.split("<link name=\"base_link\">", 1)
    extra = (f'<link name="world" />\n  <joint name="world_to_base" type="fixed">\n    <parent link="world" />\n'
             f'    <child link="base_link" />\n'
             f'    <origin xyz="{xyz[0]} {xyz[1]} {xyz[2]}" rpy="{rpy[0]} {rpy[1]} {rpy[2]}" />\n'
             f'  </joint>\n  ')
    path = tmp_path / "tilted_5rrr.urdf"
    path.write_text(head + extra + "<link name=\"base_link\">" + tail)
    return path


def test_mechanism_placed_and_tilted_in_space_gives_the_same_indices(tmp_path, rng):
    reference = load("planar_5rrr")
    moved = load(placed_copy(tmp_path, (0.4, -0.7, 1.1), (3.0, -2.0, 5.0)))
    poses = np.column_stack([rng.uniform(-0.3, 0.3, 500), rng.uniform(-0.3, 0.3, 500), rng.uniform(-np.pi, np.pi, 500)])
    first = analyze(chain_screws(reference, solve(reference, poses), unreachable="drop"))
    second_screws = chain_screws(moved, solve(moved, poses), unreachable="drop")
    assert np.abs(second_screws[0].twists[..., 2]).max() < 0.99  # the joint axes really are tilted
    second = analyze(second_screws)
    np.testing.assert_allclose(first.iti_actuators, second.iti_actuators, atol=1e-9)
    np.testing.assert_allclose(first.oti_submechanisms, second.oti_submechanisms, atol=1e-9)
    np.testing.assert_allclose(first.f_o[1], second.f_o[1], atol=1e-9)
    result = screwkit("analyze", tmp_path / "tilted_5rrr.urdf", "--pose", "-0.2", "0", "45", "--json")
    assert round(json.loads(result.stdout)["f_o"]["1"], 4) == 0.6793


@pytest.mark.parametrize("arguments, message", [
    (("analyze", "planar_9rrr"), "Unknown bundled mechanism 'planar_9rrr'; bundled are: coop_arms, delta_4"),
    (("analyze", "planar_5rrr", "--pose", "0", "0"),
     "Expected --pose with 3 values (x (m), y (m), phi (deg)) or a named pose (home, paper_fig_2a)"),
    (("analyze", "planar_5rrr", "--pose", "0", "nan", "0"), "Expected finite values in --pose, got nan for y."),
    (("analyze", "planar_5rrr", "--actuators", "1e20", "0", "0", "0", "0"),  # was the pose of 0 deg, 1e20 rounded
     "Expected angles of at most 36000 deg (100 turns) either way in --actuators (chain_1:chain_1_joint_b), got "
     "1e+20 deg."),
    (("analyze", "planar_5rrr", "--actuators", "0", "0", "-1e300", "0", "0"),
     "either way in --actuators (chain_3:chain_3_joint_b), got -1e+300 deg."),
    (("analyze", "planar_5rrr", "--actuators", "inf", "0", "0", "0", "0"),
     "Expected finite values after --actuators, got inf for chain_1:chain_1_joint_b."),
    (("analyze", "planar_5rrr", "--actuators", "0", "nan", "0", "0", "0"),
     "Expected finite values after --actuators, got nan for chain_2:chain_2_joint_b."),
    (("analyze", "planar_5rrr", "--pose", "0", "x", "0"), "Expected numbers or a named pose after --pose, got '0 x 0'"),
    (("analyze", "planar_5rrr", "--pose", "paper_fig_9"), "Unknown pose 'paper_fig_9' of mechanism 'planar_5rrr'"),
    (("analyze", "planar_5rrr", "--pose", "5", "0", "0"),  # the chain that misses the most first
     "is unreachable for mechanism 'planar_5rrr': chain 'chain_3' misses closure by 3.86066 m; chain 'chain_4'"),
    (("sweep", "planar_5rrr", "--phi", "0:360"), "Expected --phi as START:STOP:STEP"),
    (("map", "planar_5rrr", "--radius", "0.3"), "A planar map takes --radius and --step"),
    (("map", "planar_5rrr", "--radius", "0.1"), "A planar map takes --radius and --step (and --phi-step): --step is "
                                                "missing."),
    (("map", "planar_5rrr", "--step", "0.1"), "(and --phi-step): --radius is missing."),
    (("map", "planar_5rrr", "--radius", "0.3", "--step", "0.1", "--phi-step", "400"), "Expected 0 < --phi-step <= 360"),
])
def test_bad_input_is_one_line(arguments, message):
    result = screwkit(*arguments)
    assert result.returncode == 1
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("Error: "), result.stderr
    assert message in lines[0], lines[0]
    assert result.stdout == ""


def test_a_chain_folded_onto_its_base_joint_is_one_line_without_a_warning():
    """The 5-RRR's first chain has equal links: with its end on its base joint's axis its joint values are not
    determined. The pose is computed from the model (its end where its base joint is); the command says why in one
    line, with no RuntimeWarning of the arithmetic before it."""
    from screwkit.closure.chain_kinematics import chain_forward_kinematics
    from screwkit.io.loader import load

    mechanism = load("planar_5rrr")
    chain = mechanism.chains[0]
    frames = chain_forward_kinematics(chain.geometry, chain.reference_values)
    lengths = np.linalg.norm(np.diff(frames.points[:3], axis=0), axis=1)
    assert lengths[0] == pytest.approx(lengths[1], rel=1e-12)  # folded, the end can sit on the base joint
    home = mechanism.home_full_pose
    assert home[2] == 0.0
    x, y = np.round(frames.points[0][:2] - (frames.points[2][:2] - home[:2]), 12)  # the end on the base joint
    result = screwkit("analyze", "planar_5rrr", "--pose", repr(float(x)), repr(float(y)), "0")
    one_line_error(result, "chain 'chain_1' closes only to rounding", "where its joint values are not determined")


def test_with_json_errors_are_json_on_stdout():
    result = screwkit("analyze", "planar_5rrr", "--pose", "5", "0", "0", "--json")
    assert result.returncode == 1 and result.stderr == ""
    assert "is unreachable" in json.loads(result.stdout)["error"]
    missing = screwkit("info", "no/such/file.urdf", "--json")
    assert missing.returncode == 1 and json.loads(missing.stdout) == {
        "error": "no/such/file.urdf: no such file (bundled mechanisms are: coop_arms, delta_4, five_bar, five_bar_3, "
                 "planar_4rpr, planar_5rrr, prs_3_ups, rss_hexapod_8, schoenflies_5, ups_hexapod_8, ups_stewart_6)."}


def test_verify_compares_with_the_closed_forms():
    result = screwkit("verify", "planar_5rrr", "--samples", "500", "--json")
    assert result.returncode == 0, result.stderr
    report = json.loads(result.stdout)
    assert report["poses"] == 500 and report["largest_deviation"] < 1e-9
    assert set(report["differing_poses"].values()) == {0}  # worst faults and mutual interference agree too
    assert screwkit("verify", "planar_4rpr", "--samples", "300").returncode == 0


def test_verify_refuses_a_spatial_mechanism_before_compiling_anything(tmp_path):
    """It started compiling three kernels (about 18 s on a first run, and said so in two lines) before refusing."""
    import os

    cache = tmp_path / "empty_cache"
    refused = screwkit("verify", "ups_hexapod_8", env=dict(os.environ, NUMBA_CACHE_DIR=str(cache)))
    one_line_error(refused, "verify compares with the planar closed forms; 'ups_hexapod_8' is spatial.")
    assert not cache.exists() or not any(cache.rglob("*.nbi"))


def test_list_names_the_bundled_robots():
    result = screwkit("list")
    assert result.stdout.split() == ["coop_arms", "delta_4", "five_bar", "five_bar_3", "planar_4rpr", "planar_5rrr",
                                     "prs_3_ups", "rss_hexapod_8", "schoenflies_5", "ups_hexapod_8", "ups_stewart_6",
                                     "delta_rods_4", "(legs", "with", "loops", "inside", "them:", "analyze,", "info,",
                                     "sweep,", "map,", "trajectory,", "view)"]


def test_python_dash_m_screwkit_is_the_command():
    """``python -m screwkit`` runs the command line, as ``python -m screwkit.cli`` and the ``screwkit`` script do."""
    package = subprocess.run([sys.executable, "-W", "error", "-m", "screwkit", "list"], capture_output=True,
                             text=True, timeout=120)
    assert package.returncode == 0, package.stderr
    assert package.stdout == screwkit("list").stdout and "planar_5rrr" in package.stdout
    wrong = subprocess.run([sys.executable, "-m", "screwkit", "analyze", "no_such_robot"], capture_output=True,
                           text=True, timeout=120)
    assert wrong.returncode == 1 and "Unknown bundled mechanism 'no_such_robot'" in wrong.stderr


def test_console_entry_point_exits_with_the_status_and_complete_output(tmp_path):
    """main() ends the process without the interpreter's teardown: nothing may be lost."""
    import xarray as xr

    analysed = screwkit("analyze", "planar_5rrr", "--pose", "-0.2", "0", "45", "--json")
    assert analysed.returncode == 0, analysed.stderr
    assert json.loads(analysed.stdout)["f_o"]["1"] == pytest.approx(0.6793, abs=5e-5)  # the whole JSON arrived
    wrong = screwkit("analyze", "no_such_robot")
    assert wrong.returncode == 1 and "Unknown bundled mechanism 'no_such_robot'" in wrong.stderr
    path = tmp_path / "map.nc"
    mapped = screwkit("map", "planar_5rrr", "--radius", "0.1", "--step", "0.05", "--phi-step", "60", "--out", path)
    assert mapped.returncode == 0, mapped.stderr
    assert f"wrote {path}" in mapped.stderr and mapped.stdout == ""
    with xr.open_dataset(path) as dataset:
        assert np.isfinite(dataset["f_o1"].values).sum() == 13  # the disc of radius 0.1 m at 0.05 m steps


def test_data_go_to_stdout_and_summaries_to_stderr():
    swept = screwkit("sweep", "planar_5rrr", "--phi", "0:360:30")
    assert swept.returncode == 0, swept.stderr
    header, *rows = swept.stdout.strip().splitlines()
    assert header.startswith("phi,") and len(rows) == 12  # the data, as CSV
    assert "min f_o1" in swept.stderr
    quiet = screwkit("sweep", "planar_5rrr", "--phi", "0:360:30", "--quiet")
    assert quiet.stdout == swept.stdout and quiet.stderr == ""


def test_a_first_run_says_it_is_compiling_within_a_second_and_warmup_reports_the_kernels(tmp_path):
    """With an empty numba cache the first line on stderr says a kernel is being compiled, before the file is
    loaded (the process is stopped there: compiling takes tens of seconds); with the cache, warmup finds every
    kernel cached."""
    import os
    import signal

    def stop(process):  # the command and the children compiling its kernels (each command finds the cache empty)
        os.killpg(process.pid, signal.SIGKILL)
        return process.communicate()

    environment = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "empty_cache"))
    process = subprocess.Popen([sys.executable, "-m", "screwkit.cli", "analyze", "planar_5rrr"], env=environment,
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        first = process.stderr.readline()
    finally:
        stop(process)
    assert first.startswith("screwkit: compiling wrench_kernel and output_kernel in 2 processes (first run only, "
                            "about"), first
    quiet_commands = (["analyze", "planar_5rrr", "--json"],
                      ["map", "planar_5rrr", "--radius", "0.05", "--step", "0.05", "--phi-step", "90", "--out",
                       str(tmp_path / "m.nc"), "--quiet"])
    for command in quiet_commands:  # stderr stays empty: no notice either
        option = command[-1]
        process = subprocess.Popen([sys.executable, "-m", "screwkit.cli", *command], env=environment,
                                   stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
        try:
            _, stderr = process.communicate(timeout=8.0)
        except subprocess.TimeoutExpired:  # still compiling: what it wrote so far
            _, stderr = stop(process)
        assert stderr == "", (option, stderr)
    kernels = ["planar_closed_form_kernel", "close_chains_kernel", "chain_frames_kernel", "wrench_kernel",
               "output_kernel", "null_kernel", "spatial_closed_form_kernel", "gram_kernel", "space_kernel",
               "constraint_kernel"]
    for _ in range(2):  # the first run compiles what no earlier test has; the second finds everything cached
        warm = screwkit("warmup", timeout=600)
        assert warm.returncode == 0, warm.stderr
        lines = warm.stderr.splitlines()
        assert lines[-1] == "screwkit kernels ready"
        notices = [line for line in lines if line.startswith("screwkit: compiling ")]
        reports = [line for line in lines[:-1] if not line.startswith("screwkit: compiling ")]
        assert [line.split()[0] for line in reports] == kernels, lines
        compiled = [line.split()[0] for line in reports if " compiled, ready after " in line]
        announced = [name.rstrip(",") for line in notices for name in line.split("(")[0].split()[2:]
                     if name.rstrip(",").endswith("_kernel")]
        assert sorted(announced) == sorted(compiled), lines  # every compilation was announced, once
        assert all(" cached, ready after " in line or " compiled, ready after " in line for line in reports), lines
    assert not compiled, lines


def test_sweep_at_x_y_of_a_planar_point_output_without_phi():
    """``sweep five_bar --at "0 0.35"`` (the help's "x y for a planar mechanism", the whole pose of this one) died
    in a traceback reading a phi the five-bar does not have."""
    swept = screwkit("sweep", "five_bar", "--at", "0 0.35", "--sweep", "x:-0.05:0.1:0.05")
    assert swept.returncode == 0 and "Traceback" not in swept.stderr, swept.stderr
    rows = swept.stdout.splitlines()
    rows = rows[next(k for k, row in enumerate(rows) if row.startswith("x,reachable,")) + 1:]
    assert [float(row.split(",")[0]) for row in rows] == [-0.05, 0.0, 0.05], swept.stdout
    assert all(row.split(",")[1] == "True" for row in rows), swept.stdout


def test_a_small_mechanism_s_slides_are_printed_to_their_digits(tmp_path):
    """The plain report printed a slide's value to 6 decimals: the 8-UPS hexapod written a million times smaller (its
    legs a micrometre long) read ``s1 = 0.000000 m`` for each actuator; they now read to 6 significant digits, the
    values of the JSON."""
    from helpers import in_unit
    from screwkit.io.loader import bundled_path

    path = tmp_path / "tiny.urdf"
    path.write_text(in_unit(bundled_path("ups_hexapod_8").read_text(), "m", 1e-6))
    at_home = screwkit("analyze", path)
    assert at_home.returncode == 0, at_home.stderr
    assert "leg_1:leg_1_joint_slider = 0 m," in at_home.stdout  # round-off at home: 0, not 1e-22
    pose = ["--pose", "1e-08 -2e-08 1.02e-06 3 -2 5"]
    printed = screwkit("analyze", path, *pose)
    assert printed.returncode == 0, printed.stderr
    line = next(line for line in printed.stdout.splitlines() if line.startswith("  actuators: "))
    shown = {name: float(value.removesuffix(" m")) for name, value in
             (part.split(" = ") for part in line.removeprefix("  actuators: ").split(", "))}
    configuration = json.loads(screwkit("analyze", path, *pose, "--json").stdout)["configuration"]
    expected = {name: entry["value"] for name, entry in configuration.items() if entry["actuated"]}
    assert len(shown) == 8 and shown.keys() == expected.keys()
    assert all(abs(value) > 0 for value in shown.values())
    np.testing.assert_allclose(list(shown.values()), list(expected.values()), rtol=1e-5)
