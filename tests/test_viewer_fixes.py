"""``screwkit view``: no Meshcat server outlives the command, however it ends; what the viewer draws of a planar
mechanism placed elsewhere in its world frame; what it says of unreachable samples; its refusals.

Servers are found by process id (children of the command whose command line is the Meshcat bridge) and port, on
127.0.0.1 only; every test kills whatever it started.
"""

from __future__ import annotations

import contextlib
import math
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from test_viewer import _parent_pid, listening_sockets, scene_commands

from helpers import one_line_error, screwkit

# A `screwkit view` whose drawing pauses (after its Meshcat server started) until it is signalled: the stage
# "still drawing" held open for as long as a test needs, without timing guesses.
SLOW_DRAWING = r"""
import sys, time
import screwkit.viewer.scene as scene
original = scene.frame_view
def slow(*arguments, **options):
    sys.stderr.write("DRAWING\n")
    sys.stderr.flush()
    time.sleep(120)
    return original(*arguments, **options)
scene.frame_view = slow
from screwkit.cli import main
sys.argv = ["screwkit", *sys.argv[1:]]
main()
"""


def _alive(pid: int) -> bool:
    """Whether a process exists and is not a zombie (an orphan's zombie waits for init to reap it)."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (OSError, IndexError):
        return False
    return state not in ("Z", "X")


def _servers_of(pid: int) -> list[int]:
    """The Meshcat bridge processes whose parent is ``pid``."""
    found = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit() or _parent_pid(int(entry)) != pid:
            continue
        with contextlib.suppress(OSError):
            if b"ZMQWebSocketBridge" in Path(f"/proc/{entry}/cmdline").read_bytes():
                found.append(int(entry))
    return found


def _wait_for_line(process: subprocess.Popen, pattern: str, timeout: float = 180) -> str:
    deadline = time.monotonic() + timeout
    seen = []
    while time.monotonic() < deadline:
        line = process.stderr.readline()
        if not line:
            break
        seen.append(line)
        if re.search(pattern, line):
            return line
    pytest.fail(f"no line matching {pattern!r} on stderr: {''.join(seen)[-2000:]}")


@pytest.mark.parametrize(("stage", "stop"), [
    ("drawing", "SIGTERM"), ("drawing", "SIGHUP"), ("drawing", "SIGINT"), ("drawing", "SIGKILL"),
    ("serving", "SIGHUP"), ("serving", "SIGKILL"),
])
def test_no_meshcat_server_outlives_the_view_command(stage, stop, tmp_path):
    """SIGTERM, SIGHUP (terminal closed) or Ctrl+C while the scene is still being drawn (its server already
    started), SIGHUP while serving: the command stops its server and says so; SIGKILL of the command, at either
    stage: the server's watchdog ends it. In every case the server process is gone (by its pid)."""
    page = tmp_path / "never.html"
    arguments = ["view", "planar_5rrr", "--sweep-phi", "-10:10:5"] + (["--html", page] if stage == "drawing" else [])
    command = [sys.executable, "-c", SLOW_DRAWING, *map(str, arguments)] if stage == "drawing" \
        else [sys.executable, "-m", "screwkit.cli", *map(str, arguments)]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               stdin=subprocess.DEVNULL,
                               preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    servers: list[int] = []
    try:
        line = _wait_for_line(process, "DRAWING" if stage == "drawing" else r"Serving at http://127\.0\.0\.1:\d+/")
        servers = _servers_of(process.pid)
        assert len(servers) == 1, servers
        ports = [port for address, port in listening_sockets(servers[0])]
        assert ports and all(address == "127.0.0.1" for address, _ in listening_sockets(servers[0]))
        if stage == "serving":
            assert int(re.search(r":(\d+)/", line).group(1)) in ports
        process.send_signal(getattr(signal, stop))
        stdout, stderr = process.communicate(timeout=60)
        deadline = time.monotonic() + 15
        while _alive(servers[0]) and time.monotonic() < deadline:
            time.sleep(0.1)
        assert not _alive(servers[0]), f"the Meshcat server {servers[0]} outlived `screwkit view` ({stop})"
    finally:
        if process.poll() is None:
            process.kill()
            process.communicate(timeout=30)
        for pid in servers:
            if _alive(pid):
                with contextlib.suppress(ProcessLookupError):
                    os.kill(pid, signal.SIGKILL)
    if stop == "SIGKILL":
        assert process.returncode == -signal.SIGKILL
    elif stage == "serving":
        assert process.returncode == 0 and stderr.strip().endswith("Stopped."), stderr
    else:
        result = subprocess.CompletedProcess(command, process.returncode, stdout, stderr)
        one_line_error(result, f"Stopped by {stop} before the view was ready; no HTML written.")
        assert not page.exists()


# ----------------------------------------------------------------------------------------
# A planar mechanism placed elsewhere in its world frame
# ----------------------------------------------------------------------------------------
def _placed(tmp_path, name: str, xyz: str, rpy: str) -> Path:
    """planar_5rrr under a fixed `world` joint (docs/urdf-convention.md allows it)."""
    from screwkit.io.loader import bundled_path

    source = Path(bundled_path("planar_5rrr")).read_text()
    at = source.index('  <link name="base_link">')
    world = (f'  <link name="world" />\n  <joint name="world_to_base" type="fixed">\n    <parent link="world" />\n'
             f'    <child link="base_link" />\n    <origin xyz="{xyz}" rpy="{rpy}" />\n  </joint>\n')
    target = tmp_path / name
    target.write_text(source[:at] + world + source[at:])
    return target


def _camera_direction(scene) -> np.ndarray:
    """The camera's position relative to the orbit target, in the world frame, as the page sets it."""
    from test_viewer import scene_tree

    position = scene_tree(scene.static_html())["/Cameras/default/rotated/<object>"]["properties"]["position"]
    x, y_up, minus_y = position  # the viewer's y-up frame: (x, z, -y) of the world
    return np.array([x, -minus_y, y_up]) / np.linalg.norm(position)


@pytest.mark.parametrize(("xyz", "rpy"), [("3 -2 1.5", "0.3 -0.4 1.1"), ("0 0 2", "0 0 0")])
def test_a_planar_mechanism_elsewhere_in_its_world_is_drawn_moved_rigidly(xyz, rpy, tmp_path):
    """Tilted and moved, or raised 2 m: the instantaneous centres lie on the platform's plane, and every marker, the
    camera's target (minus the display offset) and its direction are the plain file's, moved by the world joint's
    transform (the centres used to be put on the world plane z = const, the target 2 m off)."""
    from screwkit.io.loader import load
    from screwkit.viewer import show, start_viewer

    plain = load("planar_5rrr")
    placed = load(_placed(tmp_path, "placed.urdf", xyz, rpy))
    rotation, translation = np.asarray(placed.rotation_world_base), np.asarray(placed.translation_world_base)
    assert not np.allclose(translation, 0.0)
    pose = np.array([-0.2, 0.0, np.radians(45.0)])
    viewer = start_viewer()
    try:
        drawn = {}
        for key, mechanism in (("plain", plain), ("placed", placed)):
            scene = show(mechanism, pose, viewer=viewer)
            drawn[key] = ({m.path: (m.kind, m.start, m.end) for m in scene.markers}, -scene.display_offset,
                          _camera_direction(scene))
    finally:
        viewer.window.zmq_socket.close(linger=0)
        viewer.window.screwkit_server.stop()
    markers, target, camera = drawn["placed"]
    plain_markers, plain_target, plain_camera = drawn["plain"]
    assert set(markers) == set(plain_markers)
    kinds = {kind for kind, _, _ in markers.values()}
    assert {"instantaneous_centre", "twist_axis", "actuation_wrench"} <= kinds
    normal, platform = rotation[:, 2], rotation @ np.array([pose[0], pose[1], 0.0]) + translation
    for path, (kind, start, end) in markers.items():
        _, plain_start, plain_end = plain_markers[path]
        moved = [rotation @ plain_start + translation, rotation @ plain_end + translation]
        if kind == "twist_axis" and np.linalg.norm(start - moved[1]) < np.linalg.norm(start - moved[0]):
            moved.reverse()  # the same axis; the sense of an output twist is the index code's choice, not drawn here
        np.testing.assert_allclose(start, moved[0], atol=1e-9, err_msg=path)
        np.testing.assert_allclose(end, moved[1], atol=1e-9, err_msg=path)
        if kind == "instantaneous_centre":
            assert abs(np.dot(start - platform, normal)) < 1e-9
    np.testing.assert_allclose(target, rotation @ plain_target + translation, atol=1e-9)
    np.testing.assert_allclose(camera, rotation @ plain_camera, atol=1e-6)


# ----------------------------------------------------------------------------------------
# Refusals and what an animation says of unreachable samples
# ----------------------------------------------------------------------------------------
def test_view_refuses_a_sweep_of_phi_without_phi_and_non_finite_options(tmp_path):
    page = tmp_path / "never.html"
    swept = screwkit("sweep", "five_bar", "--phi", "0:90:10")
    one_line_error(swept, "'five_bar' has x, y")
    one_line_error(screwkit("view", "five_bar", "--sweep-phi", "0:90:10", "--html", page), "--sweep-phi",
                   "'five_bar' has x, y")
    for value in ("inf", "nan", "-inf"):
        one_line_error(screwkit("view", "planar_5rrr", "--sweep-phi", "0:10:5", "--frame-rate", value, "--html", page),
                       "--frame-rate")
    one_line_error(screwkit("view", "planar_5rrr", "--threshold", "-1", "--html", page), "--threshold")
    assert not page.exists()


@pytest.mark.parametrize("arguments, needle", [
    (("--samples", "5"), "--samples is the number of samples of a --line, --circle or --through path"),
    (("--frame-rate", "5"), "--frame-rate is the pace of an animation (--sweep-phi or a path)"),
    (("--open",), "--open opens the served viewer, and --html writes a file instead of serving"),
    (("--pose", "0.1 0 0", "--line", "0 0 0 0.1 0 0"), "--pose is the pose of one view"),
])
def test_view_refuses_options_it_would_ignore(tmp_path, arguments, needle):
    """Each was accepted and ignored without a word; the same options where they mean something still draw."""
    page = tmp_path / "never.html"
    one_line_error(screwkit("view", "planar_5rrr", *arguments, "--html", page), needle)
    assert not page.exists()


def test_view_takes_those_options_where_they_mean_something(tmp_path):
    page = tmp_path / "drawn.html"
    for arguments in (("--line", "0 0 0 0.1 0 0", "--samples", "5", "--frame-rate", "5"),
                      ("--sweep-phi", "0:90:45", "--frame-rate", "5", "--pose", "0.1 0 0")):
        drawn = screwkit("view", "planar_5rrr", *arguments, "--html", page, "--overwrite")
        assert drawn.returncode == 0 and page.is_file(), drawn.stderr


def _platform_keys(page: Path):
    from screwkit.viewer.markers import ROOT_PATH

    animation = [c for c in scene_commands(page.read_text()) if c["type"] == "set_animation" and c["animations"]]
    clips = {item["path"]: item["clip"] for item in animation[-1]["animations"]}
    clip = clips[f"/meshcat/{ROOT_PATH}/mechanism/visuals/platform_0"]
    keys = {t["name"]: t for t in clip["tracks"]}[".position"]["keys"]
    return np.array([key["time"] / clip["fps"] for key in keys]), np.array([key["value"][:2] for key in keys])


def test_view_names_the_unreachable_samples_it_skips_and_keeps_their_time(tmp_path):
    """The unreachable samples of the path (as the closure finds them, pose by pose) are named on stderr in one
    line; the keyframes of the others stay at their own times, from the path's first time even when its first
    sample is unreachable."""
    from screwkit.closure import solve
    from screwkit.io.loader import load

    planar = load("planar_5rrr")
    page = tmp_path / "line.html"
    outcome = screwkit("view", "planar_5rrr", "--line", "0", "0", "0", "1.2", "0", "0", "--samples", "13",
                       "--frame-rate", "4", "--html", page)
    assert outcome.returncode == 0, outcome.stderr
    poses = np.column_stack([np.linspace(0.0, 1.2, 13), np.zeros(13), np.zeros(13)])
    reachable = np.asarray(solve(planar, poses).reachable)
    assert 0 < np.count_nonzero(~reachable) < 13
    line = [text for text in outcome.stderr.splitlines() if "UNREACHABLE" in text]
    assert len(line) == 1, outcome.stderr
    named = set()
    for first, _, last in re.findall(r"(\d+)(-(\d+))?(?=[,( ])", line[0].split("skipped:")[1].split("(")[0]):
        named.update(range(int(first), int(last or first) + 1))
    assert named == set(np.flatnonzero(~reachable).tolist()), line[0]
    times, where = _platform_keys(page)
    np.testing.assert_allclose(times, np.flatnonzero(reachable) / 4.0, atol=1e-12)
    np.testing.assert_allclose(where, poses[reachable, :2], atol=1e-12)

    timed = tmp_path / "timed.csv"  # its first sample is out of reach
    timed.write_text("t,x,y,phi\n2,1.5,0,0\n2.5,0,0,10\n3,0.1,0,10\n4,2,0,20\n4.5,0.1,0,0\n")
    page = tmp_path / "timed.html"
    outcome = screwkit("view", "planar_5rrr", "--path", timed, "--html", page)
    assert outcome.returncode == 0, outcome.stderr
    line = [text for text in outcome.stderr.splitlines() if "UNREACHABLE" in text]
    assert len(line) == 1 and "0 (t 2 s), 3 (t 4 s)" in line[0] and "waits at sample 1" in line[0], outcome.stderr
    times, _ = _platform_keys(page)
    np.testing.assert_allclose(times, np.array([2.5, 3.0, 4.5]) - 2.0, atol=1e-12)  # from the path's first time
    assert math.isclose(float(re.search(r"own times: ([\d.]+) s", outcome.stderr).group(1)), 2.5)


def test_a_sweep_of_phi_is_capped_as_paths_are(tmp_path, monkeypatch):
    import screwkit.cli.view as view_command
    from screwkit.io.loader import load

    planar = load("planar_5rrr")
    monkeypatch.setattr(view_command, "MAX_FRAMES", 5)
    motion = view_command._motion("0:90:1", 10.0, None, None, None, None, 100)
    poses, times = view_command._animated_poses(planar, motion, planar.home_pose, quiet=True)
    assert times is None
    np.testing.assert_allclose(np.degrees(poses[:, 2]), np.linspace(0.0, 89.0, 5), atol=1e-9)
