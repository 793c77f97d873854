"""Fixes of the map, sweep and cluster paths: options refused in one line rather than hung on, crashed on or
ignored; coordinates written as typed; Ctrl+C while a scheduler's handshake is awaited.

Command-line paths run as users run them, in a subprocess (``helpers.screwkit``); the network is loopback only,
and every listener and process a test starts is ended by it.
"""

from __future__ import annotations

import json
import math
import os
import signal
import socket
import subprocess
import sys
import textwrap
import threading
import time
import xml.etree.ElementTree as ElementTree
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import xarray as xr

from helpers import one_line_error, screwkit
from screwkit.io.loader import bundled_path, load
from screwkit.studies import maps as maps_module
from screwkit.studies.maps import TASKS_PER_CORE, disc_grid, disc_size, index_map, task_size
from screwkit.studies.sweep import sweep
from screwkit.studies.tasks import ClusterError, connect

ROOT = Path(__file__).resolve().parents[1]
SMALL = ("map", "planar_5rrr", "--radius", "0.2", "--step", "0.1", "--phi-step", "60")
GRID = ("map", "ups_hexapod_8", "--grid", "x:-0.1:0.1:0.1", "--grid", "y:-0.1:0.1:0.1")


def free_port() -> int:
    """A loopback port nothing listens on (bound, then released)."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


# -- 1. --connect-timeout: NaN, infinity and absurd values ---------------------------------------------------------

@pytest.mark.parametrize("seconds", ["nan", "inf", "1e10", "1e12", "-inf"])
def test_a_connect_timeout_that_is_not_a_number_of_seconds_is_refused_at_once(tmp_path, seconds):
    """NaN hung for good (a deadline never reached); inf, 1e10 and 1e12 ended in ``OverflowError: timestamp out of
    range``. Nothing listens at the address: the refusal comes before any connection (the time limit guards the
    hang)."""
    address = f"tcp://127.0.0.1:{free_port()}"
    start = time.monotonic()
    result = screwkit(*SMALL, "--connect-timeout", seconds, "--scheduler", address, "--out", tmp_path / "ct.nc",
                      timeout=60)
    one_line_error(result, "--connect-timeout", "at most 86,400 (a day)")
    assert time.monotonic() - start < 30
    assert os.listdir(tmp_path) == []


def test_design_search_refuses_a_nan_connect_timeout_in_its_json():
    address = f"tcp://127.0.0.1:{free_port()}"
    result = screwkit("design-search", "permutations", "planar_5rrr", "--phi-step", "60", "--connect-timeout", "nan",
                      "--scheduler", address, "--json", timeout=60)
    assert result.returncode == 1 and result.stderr == ""
    assert "--connect-timeout" in json.loads(result.stdout)["error"]


def test_connect_refuses_a_timeout_that_is_not_a_number_of_seconds():
    """The API: a ValueError naming ``connect_timeout``, before any connection (a subprocess: NaN hung for good)."""
    code = textwrap.dedent(f"""
        import math
        from screwkit.studies.tasks import Execution, connect, run_tasks
        for seconds in (math.nan, math.inf, 1e10, 1e12, 0.0, -1.0, 86400.5):
            try:
                connect("tcp://127.0.0.1:{free_port()}", seconds)
            except ValueError as error:
                assert "`connect_timeout`" in str(error), error
            else:
                raise AssertionError(seconds)
        try:
            run_tasks(abs, [(1,)], Execution(scheduler="tcp://127.0.0.1:{free_port()}", connect_timeout=math.nan))
        except ValueError as error:
            assert "`connect_timeout`" in str(error), error
        else:
            raise AssertionError("run_tasks")
        print("refused")
    """)
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert result.returncode == 0 and result.stdout == "refused\n", result.stderr


# -- 2. a repeated --over -----------------------------------------------------------------------------------------

def test_a_coordinate_given_twice_in_over_is_refused():
    """The last of two --over yaw:... was kept silently (a dict); a repeated --grid was refused already."""
    result = screwkit(*GRID, "--over", "yaw:0:360:90", "--over", "yaw:0:360:180")
    one_line_error(result, "--over", "yaw 2 times", "yaw:0:360:90 yaw:0:360:180")


# -- 3. the fixed pose of a sweep and of a map --------------------------------------------------------------------

def parsed(fixed_pose: str) -> dict[str, str]:
    return dict(part.strip().split("=") for part in fixed_pose.split(","))


def test_a_sweep_states_its_fixed_pose_in_degrees_without_the_swept_coordinate(tmp_path):
    """``fixed_pose: x=-0.2, y=0, phi=0.785398``: phi in radians, and the swept coordinate, whose fixed value means
    nothing. Now as typed with --at (m, deg), without phi."""
    out = tmp_path / "s.nc"
    assert screwkit("sweep", "planar_5rrr", "--at", "-0.2", "0", "45", "--phi", "0:360:30", "--out", out,
                    "--quiet").returncode == 0
    with xr.open_dataset(out) as swept:
        assert parsed(swept.attrs["fixed_pose"]) == {"x": "-0.2", "y": "0"}
    five = load("planar_5rrr")  # a swept x: phi stays, in degrees
    dataset = sweep(five, [0.0, 0.05, np.deg2rad(45.0)], "x", [0.0, 0.01])
    assert parsed(dataset.attrs["fixed_pose"]) == {"y": "0.05", "phi": "45"}


def tilted_hexapod(folder: Path) -> Path:
    """The hexapod under a world frame moved and tilted (roll, pitch, yaw): its home pose, read through the base
    frame, comes back with round-off of 1e-15 in coordinates that are 0."""
    tree = ElementTree.parse(bundled_path("ups_hexapod_8"))
    root = tree.getroot()
    joint = ElementTree.Element("joint", name="world_to_base", type="fixed")
    ElementTree.SubElement(joint, "parent", link="world")
    ElementTree.SubElement(joint, "child", link="base_link")
    ElementTree.SubElement(joint, "origin", xyz="3 -2 0.5", rpy="0.3 -0.2 0.7")
    root.insert(0, joint)
    root.insert(0, ElementTree.Element("link", name="world"))
    path = folder / "tilted.urdf"
    tree.write(path)
    return path


def test_round_off_of_a_pose_is_not_shown_in_the_fixed_pose(tmp_path):
    """roll=-2.3943e-15 and x=-1.16805e-16 showed in a map's and a sweep's fixed_pose; now 0, and the other values
    are the mechanism's home pose (m, deg), every digit."""
    path = tilted_hexapod(tmp_path)
    mechanism = load(str(path))
    home = dict(zip(mechanism.task_coordinates, mechanism.home_pose))
    assert any(0 < abs(value) < 1e-12 for value in home.values()), home  # the noise is there to be hidden
    swept, mapped = tmp_path / "s.nc", tmp_path / "m.nc"
    assert screwkit("sweep", path, "--sweep", "yaw:0:360:180", "--out", swept, "--quiet").returncode == 0
    assert screwkit("map", path, "--grid", "x:-0.05:0.05:0.05", "--grid", "y:-0.05:0.05:0.05", "--over",
                    "yaw:0:360:180", "--out", mapped, "--quiet").returncode == 0
    for out, left_out in ((swept, {"yaw"}), (mapped, {"x", "y", "yaw"})):
        with xr.open_dataset(out) as data:
            shown = parsed(data.attrs["fixed_pose"])
        assert set(shown) == set(home) - left_out
        for name, text in shown.items():
            assert "e-" not in text and text != "-0", data.attrs["fixed_pose"]
            value = np.rad2deg(home[name]) if name in ("roll", "pitch", "yaw") else home[name]
            expected = 0.0 if abs(value) < 1e-12 * mechanism.length_scale else value
            assert float(text) == pytest.approx(expected, rel=1e-15, abs=1e-12), (name, text, value)


def test_the_fixed_pose_a_map_states_gives_the_map_s_numbers():
    """``fixed_pose: z=0.208567`` (%g) for the 3-PRS + UPS's home height 0.2085665361461421: analysed at the pose the
    file states, F_O1 came out 0.78326837694604 for the map's 0.7832677046392849. Now the shortest decimal of each
    value: the stated pose is the map's, to the last bit."""
    from screwkit.studies import indices_at_pose
    from screwkit.studies.maps import index_map

    mechanism = load("prs_3_ups")
    roll, pitch = np.radians([-5.0, 0.0, 5.0]), np.radians([0.0, 5.0])
    mapped = index_map(mechanism, {"roll": roll, "pitch": pitch}, {})
    stated = parsed(mapped.attrs["fixed_pose"])
    assert set(stated) == {"z"} and float(stated["z"]) == mechanism.home_pose[0]
    for i, j in ((0, 0), (2, 1), (1, 1)):
        at = indices_at_pose(mechanism, [float(stated["z"]), roll[i], pitch[j]])
        assert float(mapped["f_o1"].isel(roll=i, pitch=j)) == pytest.approx(float(at.f_o[1]), abs=1e-12)
        assert float(mapped["lmti"].isel(roll=i, pitch=j)) == pytest.approx(float(at.lmti), abs=1e-12)


def test_round_off_of_a_pose_is_not_shown_by_info(tmp_path):
    """`info --json` of the same tilted hexapod gave its home pose as roll = 1.06e-15 deg, x = -1.13e-18 m: now 0,
    the other coordinates the home pose (m, deg)."""
    path = tilted_hexapod(tmp_path)
    mechanism = load(str(path))
    described = screwkit("info", path, "--json")
    assert described.returncode == 0, described.stderr
    home = json.loads(described.stdout)["named_poses"]["home"]
    for name, value in zip(mechanism.task_coordinates, mechanism.home_pose):
        value = np.rad2deg(value) if name in ("roll", "pitch", "yaw") else value
        expected = 0.0 if abs(value) < 1e-12 * mechanism.length_scale else value
        assert home[name] == pytest.approx(expected, rel=1e-12, abs=0.0), (name, home[name])


# -- 4. Ctrl+C while a handshake is awaited -----------------------------------------------------------------------

def test_ctrl_c_aborts_at_once_while_a_silent_listener_is_awaited(tmp_path):
    """Something accepts TCP connections and never answers: the handshake ran in a ThreadPoolExecutor's block,
    whose exit waited for its thread up to --connect-timeout (60 s here) after Ctrl+C. Now ``Aborted.`` at once."""
    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen(8)
    held: list[socket.socket] = []

    def accept():
        while True:
            try:
                held.append(server.accept()[0])
            except OSError:  # closed: the test is done
                return

    listener = threading.Thread(target=accept, daemon=True)
    listener.start()
    out = tmp_path / "m.nc"
    command = subprocess.Popen([sys.executable, "-W", "error", "-m", "screwkit.cli", *SMALL, "--out", str(out),
                                "--scheduler", f"tcp://127.0.0.1:{server.getsockname()[1]}", "--connect-timeout",
                                "60"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 30
        while len(held) < 2 and time.monotonic() < deadline:  # the reach (opened, closed), then the handshake's
            assert command.poll() is None, command.communicate()
            time.sleep(0.02)
        assert len(held) >= 2, "the command never opened its handshake's connection"
        time.sleep(0.3)  # in the wait for the handshake
        command.send_signal(signal.SIGINT)
        interrupted = time.monotonic()
        stdout, stderr = command.communicate(timeout=15)
        assert time.monotonic() - interrupted < 5
    finally:
        if command.poll() is None:
            command.kill()
            command.communicate()
        server.close()
        for connection in held:
            connection.close()
        listener.join(timeout=5)
    assert command.returncode == 1, stderr
    assert stderr.strip().splitlines()[-1] == "Aborted." and "Traceback" not in stderr, stderr
    assert stdout == "" and os.listdir(tmp_path) == []


# -- 5. options that were accepted and ignored --------------------------------------------------------------------

def test_options_a_map_would_ignore_are_refused_in_one_line():
    one_line_error(screwkit("map", "planar_5rrr", "--radius", "0.1", "--step", "0.1", "--phi-step", "90", "--at",
                            "0.3", "0.3", "30"), "--at", "planar map")
    one_line_error(screwkit("map", "planar_5rrr", "--grid", "x:-0.1:0.1:0.1", "--grid", "y:-0.1:0.1:0.1",
                            "--phi-step", "5"), "--phi-step", "--over phi:0:360:5")
    one_line_error(screwkit(*SMALL, "--vmin", "0.2"), "--vmin and --vmax", "--figure")
    one_line_error(screwkit(*SMALL, "--vmax", "0.9"), "--vmin and --vmax", "--figure")
    one_line_error(screwkit(*SMALL, "--connect-timeout", "5"), "--connect-timeout", "--scheduler")


# -- 6. the documentation of the task size ------------------------------------------------------------------------

def test_the_documented_task_size_is_the_code_s():
    """cluster.md and --task-size's help said 4 tasks per core, the code 16; the table's task count was 9 where the
    code makes 49 (two cores, the command's own machine)."""
    text = (ROOT / "docs" / "cluster.md").read_text()
    assert f"{TASKS_PER_CORE} tasks per core of the machine" in text and "4 tasks per core of" not in text
    help_text = " ".join(screwkit("map", "--help").stdout.split())
    assert f"{TASKS_PER_CORE} tasks per core" in help_text
    five = load("planar_5rrr")
    for radius, step, phi_step in ((0.6, 0.02, 1.0), (0.5, 0.005, 2.0)):
        size = disc_size(five, radius, step, phi_step)
        per_point = max(1, task_size(size.configurations, cores=2) // size.orientations)
        tasks = len(maps_module._blocks(disc_grid(radius, step)[2], per_point))
        assert f"({size.configurations:,} configurations; {tasks} tasks now" in text or \
            f"({size.configurations:,} configurations, {tasks} tasks)" in text, (radius, tasks)


# -- minor ------------------------------------------------------------------------------------------------------

def test_angular_coordinates_are_written_as_typed(tmp_path):
    """yaw = 29.999999999999996 after radians and back: ``sel(yaw=30)`` raised KeyError. netCDF and CSV, map and
    sweep."""
    mapped, table, swept = tmp_path / "m.nc", tmp_path / "m.csv", tmp_path / "s.csv"
    grid = ("map", "ups_hexapod_8", "--grid", "roll:-10:10:10", "--grid", "yaw:0:60:30", "--over", "z:0.95:1.05:0.1",
            "--quiet")
    assert screwkit(*grid, "--out", mapped).returncode == 0
    assert screwkit(*grid, "--out", table).returncode == 0
    assert screwkit("sweep", "ups_hexapod_8", "--sweep", "yaw:0:90:30", "--out", swept, "--quiet").returncode == 0
    with xr.open_dataset(mapped) as data:
        assert data["yaw"].values.tolist() == [0.0, 30.0, 60.0]
        assert data["roll"].values.tolist() == [-10.0, 0.0, 10.0]
        assert data.sel(yaw=30, roll=-10)["iti"].size == 1
        assert np.array_equal(np.deg2rad(data["yaw"].values), np.deg2rad([0.0, 30.0, 60.0]))
    assert sorted(set(pd.read_csv(table)["yaw"])) == [0.0, 30.0, 60.0]
    assert pd.read_csv(swept)["yaw"].tolist() == [0.0, 30.0, 60.0]
    dataset = sweep(load("ups_hexapod_8"), load("ups_hexapod_8").home_pose, "yaw", np.deg2rad([0.0, 30.0]))
    assert dataset.sel(yaw=30)["iti"].size == 1


def test_a_tiny_phi_step_is_refused_with_its_true_number_of_orientations():
    """--phi-step 1e-9 stated 10^12 orientations (a placeholder); a full turn in steps of 1e-9 deg is 3.6e11."""
    result = screwkit("map", "planar_5rrr", "--radius", "0.1", "--step", "0.1", "--phi-step", "1e-9")
    one_line_error(result, f"x {math.ceil(360 / 1e-9):,} orientations")


@pytest.mark.parametrize("threshold", ["inf", "nan", "-inf"])
def test_a_threshold_that_is_not_finite_is_refused(threshold):
    """--threshold inf gave every index 0."""
    one_line_error(screwkit(*SMALL, "--threshold", threshold), "--threshold", "finite")


def test_one_orientation_is_said_in_the_singular():
    result = screwkit("map", "planar_5rrr", "--grid", "x:-0.1:0.1:0.1", "--grid", "y:-0.1:0.1:0.1")
    assert result.returncode == 0, result.stderr
    assert "(9 grid points x 1 orientation)" in result.stderr.splitlines()[0], result.stderr


def test_warmup_does_not_point_at_itself():
    """Every kernel taken as missing from numba's cache (no child compiles it: each is loaded from the cache as it
    is): the notices said "`screwkit warmup` compiles every kernel ahead" while warmup was running."""
    code = textwrap.dedent("""
        import screwkit.common.compiling as compiling
        compiling.kernel_is_cached = lambda module: False
        compiling._start = lambda module: None
        from screwkit.cli import app
        app.main(["warmup"], standalone_mode=False)
    """)
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=240)
    assert result.returncode == 0, result.stderr
    assert "`screwkit warmup`" not in result.stderr, result.stderr
    assert result.stderr.startswith("screwkit warmup: compiling "), result.stderr
    assert result.stderr.rstrip().endswith("screwkit kernels ready")


def test_analyze_json_of_a_converted_file_keeps_stderr_quiet():
    """The 14 lines of "(converted from ...)" went to stderr with --json too; they are the JSON's ``converted``."""
    result = screwkit("analyze", ROOT / "tests" / "data" / "gallery" / "stewart_cad.xml", "--json")
    assert result.returncode == 0 and result.stderr == "", result.stderr
    report = json.loads(result.stdout)
    assert report["converted"] and report["converted"][0].startswith(str(ROOT / "tests" / "data" / "gallery"))


def test_index_map_refuses_axes_that_are_not_one_dimensional_and_non_empty():
    """An empty orientation set gave "zero-size array" and RuntimeWarnings, a 2-D one was flattened silently, a 2-D
    grid axis an IndexError, an empty one an empty map."""
    five = load("planar_5rrr")
    grid = {"x": [0.0, 0.1], "y": [0.0, 0.1]}
    cases = [(grid, {"phi": []}, "`over['phi']`"), (grid, {"phi": [[0.0, 1.0], [2.0, 3.0]]}, "`over['phi']`"),
             ({"x": [[0.0, 0.1]], "y": [0.0]}, {}, "`grid['x']`"), ({"x": [0.0], "y": []}, {}, "`grid['y']`")]
    for grid_axes, over, named in cases:
        with pytest.raises(ValueError, match=named.replace("[", r"\[").replace("]", r"\]")):
            index_map(five, grid_axes, over)


@pytest.mark.parametrize("address, found", [("inproc://foo", "inproc:// is not supported"),
                                            ("ucx://127.0.0.1:8786", "ucx:// is not supported"),
                                            ("tcp://127.0.0.1:99999", "port 99999")])
def test_scheduler_addresses_screwkit_cannot_use_are_refused_at_once(address, found):
    """inproc:// ended in "not enough values to unpack", ucx:// in "Can't instantiate abstract class", port 99999
    waited the whole timeout (30 s here)."""
    start = time.monotonic()
    result = screwkit(*SMALL, "--scheduler", address, "--connect-timeout", "30", timeout=120)
    one_line_error(result, "--scheduler", found, "tcp://HOST:PORT or tls://HOST:PORT")
    assert time.monotonic() - start < 20
    with pytest.raises(ClusterError, match="tcp://HOST:PORT"):
        connect(address, 30)
