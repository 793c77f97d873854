"""The Meshcat viewer: a loopback-only server, what the scene contains, and the offline HTML
rendered by headless Chromium.

The scene contents are read back from the exported HTML itself (the msgpack drawing commands
it inlines), so these tests check what a reader of the file gets.
"""

from __future__ import annotations

import base64
import contextlib
import html
import json
import os
import re
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pytest

from helpers import one_line_error, screwkit
from screwkit.closure import chain_screws, solve, solve_one
from screwkit.closure.solve import actuator_values
from screwkit.common.tolerances import SINGULARITY_THRESHOLD
from screwkit.io.loader import load
from screwkit.studies import indices_at_pose
from screwkit.studies.paths import line_path, path_from_poses
from screwkit.viewer import (
    FAILED_COLOR,
    animate_sweep,
    colors_from_values,
    export_html,
    resolve_actuators,
    show,
    start_viewer,
)
from screwkit.viewer.markers import ROOT_PATH

CHROMIUM = Path("/usr/bin/chromium")
CHROMIUM_FLAGS = (
    "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
    "--disable-background-networking", "--disable-component-update", "--disable-sync",
    # WebGL on the CPU: SwiftShader through ANGLE (the automatic fallback is deprecated).
    "--use-gl=angle", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
    "--hide-scrollbars", "--mute-audio",
    # Proof that the page needs no network: no host name resolves.
    "--host-resolver-rules=MAP * ~NOTFOUND",
    "--window-size=1024,768",
)
PLANAR_POSE = np.array([0.05, -0.03, np.deg2rad(12.0)])
SPATIAL_POSE = np.array([0.02, -0.01, 1.0, np.deg2rad(3.0), 0.0, np.deg2rad(5.0)])


# ----------------------------------------------------------------------------------------
# Helpers
# ----------------------------------------------------------------------------------------
def scene_commands(html: str) -> list[dict]:
    """The Meshcat commands inlined in an exported page, decoded."""
    import umsgpack

    blobs = re.findall(r'data:application/octet-binary;base64,([A-Za-z0-9+/=]*)"', html)
    return [umsgpack.unpackb(base64.b64decode(blob)) for blob in blobs]


def scene_tree(html: str) -> dict[str, dict]:
    """Per Meshcat path: its object, transform (4x4) and properties, as the page sets them."""
    tree: dict[str, dict] = {}
    for command in scene_commands(html):
        node = tree.setdefault(command.get("path", ""), {"properties": {}})
        if command["type"] == "set_object":
            node["object"] = command["object"]
        elif command["type"] == "set_transform":
            node["transform"] = np.array(command["matrix"], dtype=float).reshape(4, 4).T
        elif command["type"] == "set_property":
            node["properties"][command["property"]] = command["value"]
        elif command["type"] == "set_animation":
            node["animation"] = command
    return tree


def full_path(path: str) -> str:
    return f"/meshcat/{path}"


def distance_to_line(points, point_on_line, direction) -> np.ndarray:
    direction = np.asarray(direction, dtype=float) / np.linalg.norm(direction)
    offset = np.asarray(points, dtype=float) - point_on_line
    return np.linalg.norm(offset - np.outer(offset @ direction, direction), axis=-1)


def _parent_pid(pid: int) -> int | None:
    try:
        with open(f"/proc/{pid}/stat") as handle:
            return int(handle.read().rsplit(")", 1)[1].split()[1])
    except (OSError, ValueError, IndexError):
        return None


def listening_sockets(pid: int) -> list[tuple[str, int]]:
    """(address, port) of every TCP socket of a process in the LISTEN state (Linux /proc)."""
    inodes = set()
    for descriptor in os.listdir(f"/proc/{pid}/fd"):
        try:
            target = os.readlink(f"/proc/{pid}/fd/{descriptor}")
        except OSError:
            continue
        match = re.fullmatch(r"socket:\[(\d+)\]", target)
        if match:
            inodes.add(match.group(1))
    found = []
    for table, family in (("tcp", socket.AF_INET), ("tcp6", socket.AF_INET6)):
        lines = Path(f"/proc/{pid}/net/{table}").read_text().splitlines()[1:]
        for line in lines:
            fields = line.split()
            local, state, inode = fields[1], fields[3], fields[9]
            if state != "0A" or inode not in inodes:  # 0A: LISTEN
                continue
            address_hex, port_hex = local.split(":")
            raw = bytes.fromhex(address_hex)
            raw = b"".join(raw[i:i + 4][::-1] for i in range(0, len(raw), 4))  # host-order words
            found.append((socket.inet_ntop(family, raw), int(port_hex, 16)))
    return found


def stop_viewer(viewer) -> None:
    viewer.window.zmq_socket.close(linger=0)
    viewer.window.screwkit_server.stop()


@pytest.fixture(scope="module")
def viewer():
    """One server (127.0.0.1) shared by the scene tests; show() replaces the scene each time."""
    started = start_viewer()
    yield started
    stop_viewer(started)


@pytest.fixture(scope="module")
def planar():
    return load("planar_5rrr")


@pytest.fixture(scope="module")
def hexapod():
    return load("ups_hexapod_8")


# ----------------------------------------------------------------------------------------
# Import, server
# ----------------------------------------------------------------------------------------
def test_import_stays_light():
    code = ("import sys, screwkit.viewer; heavy = [m for m in ('meshcat', 'pinocchio', 'zmq', 'tornado') "
            "if m in sys.modules]; print(heavy); sys.exit(1 if heavy else 0)")
    completed = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60,
                               check=False)
    assert completed.returncode == 0, f"importing screwkit.viewer imported {completed.stdout.strip()}"


def test_scene_server_listens_on_loopback_only_and_stops(planar, viewer):
    with show(planar, PLANAR_POSE) as scene:  # starts its own server
        server = scene.server
        assert server is not None and server.running and scene.viewer.window.server_proc is server.process
        assert scene.url == server.web_url and server.web_url.startswith("http://127.0.0.1:"), server.web_url
        assert server.zmq_url.startswith("tcp://127.0.0.1:"), server.zmq_url
        web_port = int(re.search(r":(\d+)/", server.web_url).group(1))
        zmq_port = int(server.zmq_url.rsplit(":", 1)[1])
        sockets = listening_sockets(server.process.pid)
        assert {port for _, port in sockets} == {web_port, zmq_port}, sockets
        assert all(address == "127.0.0.1" for address, _ in sockets), f"not loopback only: {sockets}"
    assert server.process.returncode is not None and not server.running
    for port in (web_port, zmq_port):  # the ports are free again
        with socket.socket() as probe:
            assert probe.connect_ex(("127.0.0.1", port)) != 0
    server.stop()  # idempotent
    with pytest.raises(ValueError, match="stopped"):
        export_html(scene, Path(tempfile.gettempdir()) / "never-written.html")
    borrowed = show(planar, PLANAR_POSE, viewer=viewer)  # a given viewer: its server is not ours to stop
    assert borrowed.server is None
    borrowed.close()
    assert viewer.window.screwkit_server.running


# ----------------------------------------------------------------------------------------
# Scene contents
# ----------------------------------------------------------------------------------------
def test_resolve_actuators_by_index_and_names(planar):
    assert resolve_actuators(planar, None) == ()
    for spelling in (1, "1", "chain_2:chain_2_joint_b", "chain_2_joint_b", "chain_2", [1, "chain_2"]):
        assert resolve_actuators(planar, spelling) == (1,)
    with pytest.raises(ValueError, match="Unknown actuator 'nope'.*chain_1:chain_1_joint_b"):
        resolve_actuators(planar, "nope")
    with pytest.raises(ValueError, match=r"0\.\.4.*got 7"):
        resolve_actuators(planar, 7)


def test_chains_coloured_by_iti_and_failed_chain_distinct(planar, viewer):
    healthy = scene_tree(show(planar, PLANAR_POSE, viewer=viewer).static_html())
    scene = show(planar, PLANAR_POSE, failed=["chain_2:chain_2_joint_b"], viewer=viewer)
    tree = scene_tree(scene.static_html())
    result = indices_at_pose(planar, PLANAR_POSE)
    visuals = full_path(f"{ROOT_PATH}/mechanism/visuals")
    for index, chain in enumerate(planar.chains):
        paths = [path for path in tree if path.startswith(f"{visuals}/{chain.name}_")]
        assert len(paths) == 2, paths  # two links per RRR chain
        for path in paths:
            drawn = np.array(tree[path]["properties"]["color"])
            before = np.array(healthy[path]["properties"]["color"])
            np.testing.assert_allclose(before, colors_from_values(result.iti_actuators[index]), atol=1e-12)
            if index == 1:
                np.testing.assert_allclose(drawn, FAILED_COLOR)
                assert drawn[3] < 1 and np.max(np.abs(drawn - before)) > 0.3
            else:
                np.testing.assert_allclose(drawn, before, atol=1e-12)
    cross = full_path(f"{ROOT_PATH}/failed/1-chain_2-chain_2_joint_b")
    assert cross in tree and f"{cross}/bar_0" in tree and f"{cross}/bar_1" in tree
    base_joint = chain_screws(planar, solve_one(planar, PLANAR_POSE))[1].points[0]
    np.testing.assert_allclose(tree[cross]["transform"][:3, 3], base_joint, atol=1e-12)
    failed_line = tree[full_path(f"{ROOT_PATH}/actuation_wrenches/1-chain_2-chain_2_joint_b/line")]["object"]
    assert failed_line["materials"][0]["transparent"] and failed_line["materials"][0]["opacity"] < 1
    assert full_path(f"{ROOT_PATH}/failed/0-chain_1-chain_1_joint_b") not in tree
    # The best submechanism avoids the failed actuator and is the best of those that do.
    working = [s for s, sub in enumerate(result.submechanisms) if 1 not in sub]
    best = max(working, key=lambda s: result.oti_submechanisms[s])
    assert scene.best_submechanisms[0] == tuple(result.submechanisms[best])
    assert np.isnan(scene.chain_values[0, 1]) and not np.isnan(scene.chain_values[0, 0])


def test_wrench_lines_lie_on_the_actuation_wrench_axes(planar, viewer):
    scene = show(planar, PLANAR_POSE, viewer=viewer)
    tree = scene_tree(scene.static_html())
    result = indices_at_pose(planar, PLANAR_POSE)
    points = [screws.points for screws in chain_screws(planar, solve_one(planar, PLANAR_POSE))]
    for actuator, (chain, joint) in enumerate(planar.actuators):
        path = full_path(f"{ROOT_PATH}/actuation_wrenches/{actuator}-{chain}-{joint}")
        matrix = tree[path]["transform"]
        direction, centre = matrix[:3, 1], matrix[:3, 3]
        force, moment = result.actuation_wrenches[actuator, :3], result.actuation_wrenches[actuator, 3:]
        np.testing.assert_allclose(direction, force / np.linalg.norm(force), atol=1e-12)
        on_axis = np.cross(force, moment) / (force @ force)
        assert distance_to_line(centre[None], on_axis, force)[0] < 1e-12
        # The planar RRR actuation wrench is a force along the distal link: through c and d.
        assert np.all(distance_to_line(points[actuator][1:], centre, direction) < 1e-9)
        # Centred on the characteristic point: the platform-joint point d projected on the axis.
        np.testing.assert_allclose(centre, points[actuator][2], atol=1e-9)
        line = tree[f"{path}/line"]["object"]["geometries"][0]
        assert line["type"] == "CylinderGeometry" and line["height"] == pytest.approx(2 * planar.length_scale)
        assert line["radiusTop"] < 0.02 * planar.length_scale


def test_instantaneous_centres_of_the_best_submechanism(planar, viewer):
    scene = show(planar, PLANAR_POSE, viewer=viewer)
    tree = scene_tree(scene.static_html())
    result = indices_at_pose(planar, PLANAR_POSE)
    best = int(np.argmax(result.oti_submechanisms))
    submechanism = result.submechanisms[best]
    assert scene.best_submechanisms[0] == tuple(submechanism)
    wrenches = result.actuation_wrenches
    for slot, twist in enumerate(result.output_twists[best]):
        omega, velocity = twist[:3], twist[3:]
        expected = np.cross(omega, velocity) / (omega @ omega)
        centre = tree[full_path(f"{ROOT_PATH}/output_twists/{slot}/centre")]["transform"][:3, 3]
        np.testing.assert_allclose(centre[:2], expected[:2], atol=1e-9)
        assert centre[2] == pytest.approx(0.0, abs=1e-12)  # the platform plane
        # Identity: with actuator k driven and the others of the set locked, the platform
        # turns about the point where the locked actuators' wrench lines meet.
        for other in submechanism:
            if other == submechanism[slot]:
                continue
            force, moment = wrenches[other, :3], wrenches[other, 3:]
            assert distance_to_line(centre[None], np.cross(force, moment) / (force @ force), force)[0] < 1e-9
        axis = tree[full_path(f"{ROOT_PATH}/output_twists/{slot}/axis")]["transform"]
        np.testing.assert_allclose(np.abs(axis[:3, 1]), [0, 0, 1], atol=1e-12)  # vertical through the centre
        np.testing.assert_allclose(axis[:2, 3], centre[:2], atol=1e-9)
    assert len(scene.markers_of_kind("instantaneous_centre")) == 3


def test_spatial_twist_axes_and_platform_pose(hexapod, viewer):
    scene = show(hexapod, SPATIAL_POSE, failed=[3], viewer=viewer)
    tree = scene_tree(scene.static_html())
    result = scene.result
    best = scene.best_submechanisms[0]
    assert 3 not in best and len(best) == 6
    s = result.submechanisms.index(best)
    for slot, twist in enumerate(result.output_twists[s]):
        omega, velocity = twist[:3], twist[3:]
        matrix = tree[full_path(f"{ROOT_PATH}/output_twists/{slot}/axis")]["transform"]
        np.testing.assert_allclose(np.cross(matrix[:3, 1], omega / np.linalg.norm(omega)), 0, atol=1e-9)
        assert distance_to_line(matrix[None, :3, 3], np.cross(omega, velocity) / (omega @ omega), omega)[0] < 1e-9
    assert not scene.markers_of_kind("instantaneous_centre")
    platform = tree[full_path(f"{ROOT_PATH}/mechanism/visuals/platform_0")]["transform"]
    np.testing.assert_allclose(platform[:3, 3], SPATIAL_POSE[:3], atol=1e-12)
    legs = [path for path in tree if "/visuals/leg_4_" in path and "properties" in tree[path]
            and "color" in tree[path]["properties"]]
    assert legs and all(np.allclose(tree[path]["properties"]["color"], FAILED_COLOR) for path in legs)


def test_links_without_visuals_are_drawn_as_rods(planar, viewer, tmp_path):
    text = Path(planar.path).read_text()
    bare = re.sub(r'(<link name="chain_[^"]*">)\s*<visual>.*?</visual>', r"\1", text, flags=re.DOTALL)
    assert bare.count("<visual>") == 2  # base and platform keep theirs
    path = tmp_path / "bare_5rrr.urdf"
    path.write_text(bare)
    mechanism = load(path)
    scene = show(mechanism, PLANAR_POSE, viewer=viewer)
    links = scene.markers_of_kind("link")
    assert len(links) == 2 * len(mechanism.chains)
    tree = scene_tree(scene.static_html())
    points = [screws.points for screws in chain_screws(mechanism, solve_one(mechanism, PLANAR_POSE))]
    for marker in links:
        position = int(marker.path.rsplit("/", 1)[1])
        np.testing.assert_allclose(marker.start, points[marker.chain][position], atol=1e-12)
        np.testing.assert_allclose(marker.end, points[marker.chain][position + 1], atol=1e-12)
        matrix = tree[full_path(marker.path)]["transform"]
        np.testing.assert_allclose(matrix[:3, 1], marker.end - marker.start, atol=1e-12)  # y scaled to the length
        np.testing.assert_allclose(matrix[:3, 3], 0.5 * (marker.start + marker.end), atol=1e-12)
    assert scene.markers_of_kind("joint")


def test_chains_coloured_by_best_submechanism_oti(planar, viewer):
    scene = show(planar, PLANAR_POSE, failed=[4], color_by="oti", viewer=viewer)
    result = indices_at_pose(planar, PLANAR_POSE)
    for chain in range(4):
        expected = max(result.oti_submechanisms[s] for s, sub in enumerate(result.submechanisms)
                       if chain in sub and 4 not in sub)
        assert scene.chain_values[0, chain] == pytest.approx(expected, abs=1e-12)
    assert np.isnan(scene.chain_values[0, 4])
    np.testing.assert_allclose(scene.chain_colors[:4], colors_from_values(scene.chain_values[0, :4]))
    np.testing.assert_allclose(scene.chain_colors[4], FAILED_COLOR)
    with pytest.raises(ValueError, match="color_by"):
        show(planar, PLANAR_POSE, color_by="lmti", viewer=viewer)


def test_twists_at_infinity_are_drawn_as_translation_arrows(planar):
    from screwkit.viewer.markers import twist_markers

    centre = np.array([0.1, 0.2, 0.0])
    for omega in ([0.0, 0.0, 0.0], [0.0, 0.0, 1e-14]):  # a translation, and a centre 1e13 m away
        twist = np.concatenate([omega, [3.0, 4.0, 0.0]])
        (marker,) = twist_markers(planar, 0, 2, twist, centre, planar.length_scale)
        assert marker.kind == "translation" and marker.actuator == 2
        np.testing.assert_allclose(marker.start, centre)
        np.testing.assert_allclose(marker.direction, [0.6, 0.8, 0.0], atol=1e-9)
    twist = np.concatenate([[0.0, 0.0, 2.0], np.cross([0.3, -0.1, 0.0], [0.0, 0.0, 2.0])])  # about (0.3, -0.1)
    kinds = {m.kind: m for m in twist_markers(planar, 0, 2, twist, centre, planar.length_scale)}
    np.testing.assert_allclose(kinds["instantaneous_centre"].start, [0.3, -0.1, 0.0], atol=1e-12)


def test_unreachable_pose_is_reported_before_any_server_starts(planar):
    with pytest.raises(ValueError, match="unreachable.*chain"):
        show(planar, [3.0, 0.0, 0.0])


def test_animate_sweep_keyframes_follow_the_poses(planar, viewer):
    angles = np.deg2rad([-20.0, -10.0, 0.0, 10.0, 20.0])
    poses = np.column_stack([np.full(6, 0.05), np.full(6, -0.03), np.append(angles, 0.0)])
    poses[-1, 0] = 3.0  # unreachable: skipped
    scene = animate_sweep(planar, poses, viewer=viewer, frame_rate=5)
    np.testing.assert_allclose(scene.poses, poses[:-1])
    commands = [c for c in scene_commands(scene.static_html()) if c["type"] == "set_animation"]
    assert len(commands) == 1
    clips = {item["path"]: item["clip"] for item in commands[0]["animations"]}
    platform = clips[full_path(f"{ROOT_PATH}/mechanism/visuals/platform_0")]
    assert platform["fps"] == 5
    positions = {track["name"]: track for track in platform["tracks"]}[".position"]["keys"]
    assert [key["time"] for key in positions] == [0, 1, 2, 3, 4]
    np.testing.assert_allclose([key["value"][:2] for key in positions], poses[:-1, :2], atol=1e-12)
    wrench = f"{ROOT_PATH}/actuation_wrenches/0-chain_1-chain_1_joint_b"
    tracks = {track["name"]: track["keys"] for track in clips[full_path(wrench)]["tracks"]}
    for frame in (0, 4):  # each keyframe is the still scene of that pose
        still = {marker.path: marker for marker in show(planar, poses[frame], viewer=viewer).markers}[wrench]
        np.testing.assert_allclose(tracks[".position"][frame]["value"], 0.5 * (still.start + still.end), atol=1e-12)
        assert tracks[".visible"][frame]["value"] is True
    after = [c for c in scene_commands(show(planar, PLANAR_POSE, viewer=viewer).static_html())
             if c["type"] == "set_animation"]
    assert all(not command["animations"] for command in after)  # the still scene cleared it


def test_path_animation_colours_each_chain_by_its_index_frame_by_frame(planar, viewer):
    """Along a path, the material colour of every drawn part of a working chain is a keyframe track equal, frame by
    frame, to the colour of that chain in the still scene of the pose; a failed chain stays red, untracked."""
    path = line_path(planar, [-0.3, -0.2, np.deg2rad(-45.0)], [0.3, 0.2, np.deg2rad(45.0)], 7)
    scene = animate_sweep(planar, path, failed=["chain_3"], viewer=viewer, frame_rate=4)
    np.testing.assert_allclose(scene.poses, path.poses)
    commands = scene_commands(scene.static_html())
    animated = [i for i, c in enumerate(commands) if c["type"] == "set_animation" and c["animations"]]
    assert len(animated) == 1
    # after the drawing: a page binds the colour tracks to the objects drawn, not to placeholders they replace
    assert animated[0] > max(i for i, c in enumerate(commands) if c["type"] == "set_object")
    clips = {item["path"]: item["clip"] for item in commands[animated[0]]["animations"]}
    coloured = {path_: {t["name"]: t for t in clip["tracks"]}[".material.color"] for path_, clip in clips.items()
                if any(t["name"] == ".material.color" for t in clip["tracks"])}
    visuals = full_path(f"{ROOT_PATH}/mechanism/visuals")
    for chain in ("chain_1", "chain_2", "chain_4", "chain_5"):
        assert f"{visuals}/{chain}_link_a_0/<object>" in coloured and f"{visuals}/{chain}_link_l_0/<object>" in coloured
    assert not [p for p in coloured if "chain_3" in p or "platform" in p or "base" in p], sorted(coloured)
    keys = coloured[f"{visuals}/chain_4_link_a_0/<object>"]["keys"]
    assert coloured[f"{visuals}/chain_4_link_a_0/<object>"]["type"] == "color"
    assert [key["time"] for key in keys] == list(range(7))
    np.testing.assert_allclose([key["value"] for key in keys], colors_from_values(scene.chain_values[:, 3])[:, :3])
    assert np.ptp(scene.chain_values[:, 3]) > 0.3  # the index does change along this path
    for frame in (0, 5):  # each keyframe's colour is the still scene's at that pose
        still = show(planar, path.poses[frame], failed=["chain_3"], viewer=viewer)
        np.testing.assert_allclose(keys[frame]["value"], still.chain_colors[3][:3], atol=1e-12)
        np.testing.assert_allclose(still.chain_colors[2], FAILED_COLOR)


def test_a_path_with_times_plays_at_its_own_times(planar, viewer):
    """Keyframe k of a timed path is at its time less the first (Meshcat: key time / fps seconds), whatever the frame
    rate; an unreachable sample is skipped with its time."""
    poses = np.array([[-0.1, 0.0, 0.0], [0.0, 0.05, 0.17], [0.1, 0.0, 0.35], [3.0, 0.0, 0.0], [0.12, 0.01, 0.3]])
    times = np.array([1.0, 1.5, 3.0, 3.5, 5.0])
    kept = [0, 1, 2, 4]
    for rate in (4.0, 25.0):
        scene = animate_sweep(planar, path_from_poses(planar, poses, times), viewer=viewer, frame_rate=rate)
        np.testing.assert_allclose(scene.times, times[kept])
        np.testing.assert_allclose(scene.poses, poses[kept])
        animation = [c["animations"] for c in scene_commands(scene.static_html())
                     if c["type"] == "set_animation" and c["animations"]][-1]
        platform = full_path(f"{ROOT_PATH}/mechanism/visuals/platform_0")
        clip = {item["path"]: item["clip"] for item in animation}[platform]
        keys = {track["name"]: track for track in clip["tracks"]}[".position"]["keys"]
        np.testing.assert_allclose([key["time"] / clip["fps"] for key in keys], times[kept] - times[0], atol=1e-12)
        np.testing.assert_allclose([key["value"][:2] for key in keys], poses[kept, :2], atol=1e-12)
    untimed = animate_sweep(planar, poses[kept], viewer=viewer, frame_rate=4.0)  # without times: one per 1/4 s
    assert untimed.times is None
    with pytest.raises(ValueError, match="increasing"):
        animate_sweep(planar, poses[kept], viewer=viewer, times=[0.0, 1.0, 1.0, 2.0])


def test_a_long_timed_path_is_animated_at_frames_even_in_time(planar, tmp_path, monkeypatch):
    """More samples than MAX_FRAMES with a time column: frames evenly spaced in time, each the path's pose then
    (the platform speeds up: x = 0.01 t^2, so arc length and time are not proportional)."""
    import screwkit.cli.view as view_command

    times = np.arange(12.0)
    table = tmp_path / "timed.csv"
    table.write_text("t,x,y,phi\n" + "".join(f"{t},{0.01 * t * t - 0.5},0,0\n" for t in times))
    monkeypatch.setattr(view_command, "MAX_FRAMES", 5)
    motion = view_command._motion(None, 10.0, str(table), None, None, None, 100)
    poses, at = view_command._animated_poses(planar, motion, planar.home_pose, quiet=True)
    np.testing.assert_allclose(at, np.linspace(0.0, 11.0, 5))
    np.testing.assert_allclose(poses[:, 0], np.interp(at, times, 0.01 * times**2 - 0.5), atol=1e-12)


# ----------------------------------------------------------------------------------------
# Legs with loops inside them: rods between the joints of the closed tree
# ----------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def graph():
    from screwkit.io import graph_mechanism, read_closed_tree
    from screwkit.io.loader import bundled_path

    return graph_mechanism(read_closed_tree(bundled_path("delta_rods_4")))


def pinocchio_points(graph, q):
    """Pinocchio's own forward kinematics of the closed tree at q: each joint's origin, and each closure's two frame
    origins (the independent reading the drawing is checked against)."""
    import pinocchio

    model = graph.tree.model
    data = model.createData()
    pinocchio.forwardKinematics(model, data, q)
    pinocchio.updateFramePlacements(model, data)
    origins = np.array([np.asarray(data.oMi[j].translation) for j in range(model.njoints)])
    ends = {closure.name: [np.asarray((data.oMi[joint] * pinocchio.SE3(placement)).translation)
                           for joint, placement in ((closure.joint_a, closure.placement_a),
                                                    (closure.joint_b, closure.placement_b))]
            for closure in graph.tree.closures}
    return origins, ends, np.asarray(data.oMf[graph.frame_id].translation)


def _hull(flat) -> list[int]:
    """The vertices of the convex hull of planar points, counter-clockwise (Andrew's monotone chain: an independent
    reading of what the drawing takes from qhull)."""
    order = sorted(range(len(flat)), key=lambda i: (flat[i][0], flat[i][1]))

    def turn(o, a, b):
        return (flat[a][0] - flat[o][0]) * (flat[b][1] - flat[o][1]) - (flat[a][1] - flat[o][1]) * (flat[b][0]
                                                                                                     - flat[o][0])

    lower, upper = [], []
    for i in order:
        while len(lower) >= 2 and turn(lower[-2], lower[-1], i) <= 1e-15:
            lower.pop()
        lower.append(i)
    for i in reversed(order):
        while len(upper) >= 2 and turn(upper[-2], upper[-1], i) <= 1e-15:
            upper.pop()
        upper.append(i)
    return lower[:-1] + upper[:-1]


def test_a_graph_is_drawn_as_rods_between_its_joints(graph, viewer):
    """The rod-level Delta: every body of a leg a rod from its joint to each child joint and each closure frame on
    it, the base and the platform each the outline of the points where the legs hold it, at Pinocchio's forward
    kinematics of the closed configuration; the legs in their ITI's colour, the failed leg red with a cross at its
    motor; the base and the platform in their own colours; no screw (a graph keeps none)."""
    from screwkit.viewer.markers import node_label

    pose = graph.home_pose + np.array([0.04, -0.03, 0.02])
    scene = show(graph, pose, failed=["arm_2"], viewer=viewer)
    assert scene.visualizer is None and scene.failed == (1,)
    q, reached = graph.solve(pose[None])
    origins, ends, output = pinocchio_points(graph, q[0])
    np.testing.assert_allclose(output, pose, atol=1e-9)  # the drawn configuration is at the pose asked
    names, parents = graph.tree.model.names, graph.tree.model.parents
    links = {marker.path: marker for marker in scene.markers_of_kind("link")}
    plates = {0: "base", graph.platform: "platform"}
    held = {plate: [] if plate == 0 else [origins[plate]] for plate in plates}  # where the legs hold each plate
    drawn = 0
    for joint in range(1, len(parents)):
        if parents[joint] in plates:
            held[parents[joint]].append(origins[joint])  # revolute and ball joints: their origins do not move
            continue
        path = f"{ROOT_PATH}/links/{node_label(names[parents[joint]])}--{node_label(names[joint])}"
        start, end = origins[parents[joint]], origins[joint]
        if np.linalg.norm(end - start) < 1e-9:
            assert path not in links
            continue
        drawn += 1
        np.testing.assert_allclose(links[path].start, start, atol=1e-12)
        np.testing.assert_allclose(links[path].end, end, atol=1e-12)
    for closure in graph.tree.closures:
        a, b = ends[closure.name]
        assert np.linalg.norm(a - b) < 1e-8  # closed: the two ends of each rod's far joint meet
        np.testing.assert_allclose(links[f"{ROOT_PATH}/links/{node_label(closure.name)}--a"].end, a, atol=1e-12)
        held[closure.joint_b].append(b)  # the rods' far ends: on the platform
    for plate, body in plates.items():
        points = np.array(held[plate])
        pieces = [m for m in links.values() if m.body == body and "--outline_" in m.path]
        # independently: the convex hull of the held points in their mean plane, the others spokes from the centre
        centre = points.mean(axis=0)
        plane = np.linalg.svd(points - centre)[2][:2]
        flat = (points - centre) @ plane.T
        on_hull = _hull(flat)
        inside = [i for i in range(len(points)) if i not in on_hull]
        assert len(pieces) == len(on_hull) + len(inside)
        edges = [(m.start, m.end) for m in pieces]
        for a, b in zip(on_hull, on_hull[1:] + on_hull[:1]):  # the hull's edges, in one sense or the other
            assert sum(np.allclose(start, points[a], atol=1e-12) and np.allclose(end, points[b], atol=1e-12)
                       or np.allclose(start, points[b], atol=1e-12) and np.allclose(end, points[a], atol=1e-12)
                       for start, end in edges) == 1
        for i in inside:
            assert any(np.allclose(start, centre, atol=1e-12) and np.allclose(end, points[i], atol=1e-12)
                       for start, end in edges)
        assert len(on_hull) >= 3
    assert drawn >= 4 and not any(m.path.endswith(("universe--motor_1", "--b")) for m in links.values())
    tree = scene_tree(scene.static_html())
    for marker in list(links.values())[:5]:
        matrix = tree[full_path(marker.path)]["transform"]
        np.testing.assert_allclose(matrix[:3, 1], marker.end - marker.start, atol=1e-12)  # y scaled to the length
        np.testing.assert_allclose(matrix[:3, 3], 0.5 * (marker.start + marker.end), atol=1e-12)
    legs = {index: [m for m in links.values() if m.chain == index] for index in range(4)}
    assert all(legs.values()) and all(m.failed for m in legs[1]) and not any(m.failed for m in legs[0])
    bodies = {m.body for m in links.values() if m.chain is None}
    assert "platform" in bodies and bodies <= {"platform", "base"}
    expected = graph.at_pose(pose).indices().iti_actuators  # the indices of the mechanism moved to the pose alone
    np.testing.assert_allclose(scene.chain_values[0, [0, 2, 3]], expected[[0, 2, 3]], atol=1e-9)
    assert np.isnan(scene.chain_values[0, 1])
    np.testing.assert_allclose(scene.chain_colors[1], FAILED_COLOR)
    cross = scene.markers_of_kind("failed_actuator")
    motor = list(names).index("motor_2")
    assert len(cross) == 1 and np.allclose(cross[0].start, origins[motor], atol=1e-12)
    assert not scene.markers_of_kind("actuation_wrench") and not scene.markers_of_kind("twist_axis")
    assert resolve_actuators(graph, ["arm_2:motor_2"]) == resolve_actuators(graph, "motor_2") == (1,)
    with pytest.raises(ValueError, match="no closed configuration"):
        show(graph, graph.home_pose + np.array([0.0, 0.0, 5.0]), viewer=viewer)


def test_a_graph_path_animation_follows_its_closed_configurations(graph, viewer):
    """Keyframes of a rod follow Pinocchio's forward kinematics pose by pose, and each leg's colour track is the
    colour of its index at each pose."""
    poses = graph.home_pose + np.linspace([0.0, 0.0, 0.0], [0.08, 0.05, 0.03], 6)
    scene = animate_sweep(graph, poses, failed=[3], viewer=viewer, frame_rate=5)
    np.testing.assert_allclose(scene.poses, poses)
    commands = [c for c in scene_commands(scene.static_html()) if c["type"] == "set_animation" and c["animations"]]
    assert len(commands) == 1
    clips = {item["path"]: item["clip"] for item in commands[0]["animations"]}
    rod = f"{ROOT_PATH}/links/motor_1--ball_1b"
    tracks = {track["name"]: track["keys"] for track in clips[full_path(rod)]["tracks"]}
    q, _ = graph.solve(poses)
    names = list(graph.tree.model.names)
    for frame in range(len(poses)):
        origins, _, output = pinocchio_points(graph, q[frame])
        np.testing.assert_allclose(output, poses[frame], atol=1e-9)
        middle_point = 0.5 * (origins[names.index("motor_1")] + origins[names.index("ball_1b")])
        np.testing.assert_allclose(tracks[".position"][frame]["value"], middle_point, atol=1e-12)
    colour = {t["name"]: t for t in clips[full_path(f"{rod}/<object>")]["tracks"]}[".material.color"]["keys"]
    np.testing.assert_allclose([key["value"] for key in colour], colors_from_values(scene.chain_values[:, 0])[:, :3])
    for frame in (0, 5):
        expected = graph.at_pose(poses[frame]).indices().iti_actuators[0]
        assert scene.chain_values[frame, 0] == pytest.approx(expected, abs=1e-9)
    failed_leg = {full_path(m.path) for m in scene.frame_markers[0] if m.chain == 3 and m.kind == "link"}
    assert failed_leg and all(m.failed for m in scene.frame_markers[0] if m.chain == 3)
    assert not [p for p in failed_leg if f"{p}/<object>" in clips]  # the failed leg: red, its colour untracked
    assert all(f"{full_path(m.path)}/<object>" in clips for m in scene.frame_markers[0] if m.chain == 0)


def test_a_graph_s_unreachable_poses_are_left_out_as_if_never_asked(graph):
    """The frames of a batch with unreachable poses are the reachable ones' rows of it: every index and
    configuration equal to a batch of the reachable poses alone, analysed afresh."""
    from screwkit.studies.poses import graph_indices_at_poses
    from screwkit.viewer.graph_drawing import solve_graph_frames

    poses = graph.home_pose + np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 5.0], [0.05, 0.02, 0.01], [3.0, 0.0, 0.0],
                                        [0.02, -0.04, 0.03]])
    frames = solve_graph_frames(graph, poses, SINGULARITY_THRESHOLD, strict=False)
    np.testing.assert_array_equal(frames.kept, [0, 2, 4])
    alone, q = graph_indices_at_poses(graph, poses[[0, 2, 4]], detail=True, configurations=True)
    np.testing.assert_array_equal(frames.poses, poses[[0, 2, 4]])
    np.testing.assert_array_equal(frames.configurations, q)
    assert frames.result.batch_shape == (3,) and bool(np.all(frames.result.reachable))
    for name in ("iti", "lmti", "iti_actuators", "oti_submechanisms", "cti"):
        np.testing.assert_array_equal(getattr(frames.result, name), getattr(alone, name), err_msg=name)
    for j in alone.faults:
        for name in ("f_o", "f_io", "remaining_lmti"):
            np.testing.assert_array_equal(getattr(frames.result, name)[j], getattr(alone, name)[j], err_msg=name)


def test_export_html_is_atomic_and_offline(planar, viewer, tmp_path):
    scene = show(planar, PLANAR_POSE, viewer=viewer)
    target = tmp_path / "scene.html"
    target.write_text("old")
    assert export_html(scene, target) == target
    html = target.read_text()
    assert "MeshCat.Viewer" in html and "set_object" not in html[:100]
    assert not re.search(r"<script[^>]*\ssrc=|<link[^>]*\shref=", html), "the page loads external files"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scene.html"]  # no temporary left
    assert oct(target.stat().st_mode & 0o777) != oct(0o600)
    with pytest.raises(ValueError, match="does not exist"):
        export_html(scene, tmp_path / "missing" / "scene.html")
    with pytest.raises(ValueError, match="Expected a Scene"):
        export_html(object(), tmp_path / "x.html")


# ----------------------------------------------------------------------------------------
# Command line
# ----------------------------------------------------------------------------------------
def test_cli_view_writes_html_and_animations(tmp_path):
    still = tmp_path / "still.html"
    outcome = screwkit("view", "planar_5rrr", "--pose", "0.05", "-0.03", "12", "--failed", "1", "--html", still)
    assert outcome.returncode == 0, outcome.stderr
    assert "chain_2" in outcome.stdout and "failed: chain_2:chain_2_joint_b" in outcome.stdout
    assert f"wrote {still}" in outcome.stderr
    tree = scene_tree(still.read_text())
    np.testing.assert_allclose(tree[full_path(f"{ROOT_PATH}/mechanism/visuals/platform_0")]["transform"][:3, 3],
                               [0.05, -0.03, 0.0], atol=1e-12)
    sweep = tmp_path / "sweep.html"
    outcome = screwkit("view", "planar_5rrr", "--sweep-phi", "-10:10:5", "--html", sweep)
    assert outcome.returncode == 0, outcome.stderr
    animation = [c for c in scene_commands(sweep.read_text()) if c["type"] == "set_animation"]
    keys = animation[0]["animations"][0]["clip"]["tracks"][0]["keys"]
    assert len(keys) == 4  # -10, -5, 0, 5 (stop exclusive)
    other = tmp_path / "other.html"
    for arguments, message in (
        (["planar_5rrr", "--failed", "chain_9", "--html", other], "Unknown actuator 'chain_9'"),
        (["ups_hexapod_8", "--sweep-phi", "0:10:5", "--html", other], "planar"),
        (["planar_5rrr", "--pose", "0", "0", "--html", other], "Expected --pose with 3 values"),
        (["planar_5rrr", "--html", still], "still.html: the file exists; pass --overwrite to replace it."),
    ):
        outcome = screwkit("view", *arguments)
        assert outcome.returncode == 1 and message in outcome.stderr, outcome.stderr
        assert len(outcome.stderr.strip().splitlines()) == 1


def test_cli_view_animates_a_path_and_refuses_a_bad_path_file(tmp_path):
    page = tmp_path / "path.html"
    outcome = screwkit("view", "planar_5rrr", "--line", "-0.3", "-0.2", "-45", "0.3", "0.2", "45", "--samples", "5",
                       "--failed", "chain_3", "--color-by", "oti", "--html", page)
    assert outcome.returncode == 0, outcome.stderr
    assert "first of 5 frames" in outcome.stdout and "failed: chain_3:chain_3_joint_b" in outcome.stdout
    animation = [c for c in scene_commands(page.read_text()) if c["type"] == "set_animation"][0]["animations"]
    clips = {item["path"]: item["clip"] for item in animation}
    platform = {t["name"]: t for t in clips[full_path(f"{ROOT_PATH}/mechanism/visuals/platform_0")]["tracks"]}
    np.testing.assert_allclose([key["value"][:2] for key in platform[".position"]["keys"]],
                               np.linspace([-0.3, -0.2], [0.3, 0.2], 5), atol=1e-12)
    assert any(t["name"] == ".material.color" for clip in clips.values() for t in clip["tracks"])
    table = tmp_path / "path.csv"
    table.write_text("x,y,phi\n-0.1,0,0\n0,0.05,10\n0.1,0,20\n")
    outcome = screwkit("view", "planar_5rrr", "--path", table, "--html", tmp_path / "file.html")
    assert outcome.returncode == 0, outcome.stderr
    assert "first of 3 frames" in outcome.stdout
    timed = tmp_path / "timed.csv"  # a time column: played at its times
    timed.write_text("t,x,y,phi\n2,-0.1,0,0\n2.5,0,0.05,10\n4,0.1,0,20\n")
    outcome = screwkit("view", "planar_5rrr", "--path", timed, "--html", tmp_path / "timed.html")
    assert outcome.returncode == 0, outcome.stderr
    assert "Animated at the path's own times: 2 s." in outcome.stderr
    animation = [c for c in scene_commands((tmp_path / "timed.html").read_text())
                 if c["type"] == "set_animation" and c["animations"]][-1]["animations"]
    clip = {item["path"]: item["clip"] for item in animation}[full_path(f"{ROOT_PATH}/mechanism/visuals/platform_0")]
    keys = {t["name"]: t for t in clip["tracks"]}[".position"]["keys"]
    np.testing.assert_allclose([key["time"] / clip["fps"] for key in keys], [0.0, 0.5, 2.0], atol=1e-12)
    five = load("planar_5rrr")  # the line's actuator values (inverse kinematics), animated through their poses
    poses = five.poses_from_degrees(np.linspace([-0.3, -0.2, -45], [0.3, 0.2, 45], 5))
    values = np.rad2deg(actuator_values(five, solve(five, poses).joint_values))
    driven = tmp_path / "driven.csv"
    np.savetxt(driven, values, delimiter=",", header=",".join(f"chain_{i}" for i in range(1, 6)), comments="")
    outcome = screwkit("view", "planar_5rrr", "--path", driven, "--actuators", "--html", tmp_path / "driven.html")
    assert outcome.returncode == 0, outcome.stderr
    animation = [c for c in scene_commands((tmp_path / "driven.html").read_text())
                 if c["type"] == "set_animation" and c["animations"]][-1]["animations"]
    clip = {item["path"]: item["clip"] for item in animation}[full_path(f"{ROOT_PATH}/mechanism/visuals/platform_0")]
    keys = {t["name"]: t for t in clip["tracks"]}[".position"]["keys"]
    np.testing.assert_allclose([key["value"][:2] for key in keys], poses[:, :2], atol=1e-9)
    bad = tmp_path / "bad.csv"
    bad.write_text("x,y\n0,0\n0.1,0\n")
    for arguments, needles in (
        (["--path", bad], ("bad.csv", "no column 'phi'")),
        (["--path", tmp_path / "missing.csv"], ("missing.csv: no such file",)),
        (["--path", table, "--sweep-phi", "0:10:5"], ("at most one of", "--sweep-phi, --path")),
        (["--actuators"], ("--actuators says that --path holds actuator values, and there is no --path",)),
        (["--line", "0", "0", "0", "0.1", "0", "0", "--actuators"], ("give --path a file, not --line",)),
    ):
        one_line_error(screwkit("view", "planar_5rrr", *arguments, "--html", tmp_path / "never.html"), *needles)
    assert not (tmp_path / "never.html").exists()


def test_cli_view_draws_and_animates_a_graph(tmp_path):
    """`screwkit view` on the rod-level Delta (legs with loops inside them), still and along a path, as a user runs
    it; each leg's value in the legend is its actuator's ITI as `screwkit analyze` reports it."""
    still = tmp_path / "still.html"
    outcome = screwkit("view", "delta_rods_4", "--failed", "arm_2", "--html", still)
    assert outcome.returncode == 0, outcome.stderr
    analysed = json.loads(screwkit("analyze", "delta_rods_4", "--json").stdout)
    legend = dict(line.split()[:2] for line in outcome.stdout.splitlines()[1:5])
    iti = analysed["iti_actuators"]
    for leg in ("arm_1", "arm_3", "arm_4"):
        assert float(legend[leg]) == pytest.approx(iti[f"{leg}:motor_{leg[-1]}"], abs=6e-5)
    assert "failed: arm_2:motor_2" in outcome.stdout and "no screw drawn" in outcome.stdout
    assert any(path.startswith(full_path(f"{ROOT_PATH}/links/")) for path in scene_tree(still.read_text()))
    moving = tmp_path / "moving.html"
    outcome = screwkit("view", "delta_rods_4", "--through", "0 0 -0.75", "0.1 0 -0.72", "0 0.1 -0.75", "--samples",
                       "12", "--html", moving)
    assert outcome.returncode == 0, outcome.stderr
    animation = [c for c in scene_commands(moving.read_text()) if c["type"] == "set_animation" and c["animations"]]
    keys = animation[0]["animations"][0]["clip"]["tracks"][0]["keys"]
    assert len(keys) == 13  # 12 samples evenly spaced in arc length, plus the pose in the middle
    one_line_error(screwkit("view", "delta_rods_4", "--pose", "0", "0", "5", "--html", tmp_path / "far.html"),
                   "no closed configuration", "z=5")
    driven = tmp_path / "arms.csv"  # actuator values: poses closed again past a fold may close elsewhere
    driven.write_text("arm_1,arm_2,arm_3,arm_4\n0,0,0,0\n5,5,5,5\n")
    one_line_error(screwkit("view", "delta_rods_4", "--path", driven, "--actuators", "--html", tmp_path / "a.html"),
                   "--actuators animates the poses the actuators drive", "the legs of 'delta_rods_4' have loops",
                   "`screwkit trajectory --actuators` follows such a path in joint space")
    assert not (tmp_path / "a.html").exists()


SIGNAL_AFTER_THE_LINE = """
import signal
import screwkit.cli.view as view
said = view.echo_error
def echo(message):  # a SIGTERM delivered the moment the line is written, before the next statement runs
    said(message)
    if message.startswith("Serving at"):
        raise view.Stopped(signal.SIGTERM)
view.echo_error = echo
import sys
from screwkit.cli import main
sys.argv = ["screwkit", "view", "planar_5rrr"]
main()
"""


def test_a_signal_the_moment_the_serving_line_is_written_stops_a_served_view():
    """Whoever stops the view once it reads the 'Serving at' line (a script, the test below) may signal it before
    the command's next statement: the view is already served, so it says 'Stopped.' and exits 0 (the command took
    such a signal for one before the view was ready, and exited 1, under load in CI)."""
    done = subprocess.run([sys.executable, "-c", SIGNAL_AFTER_THE_LINE], capture_output=True, text=True, timeout=300)
    assert "Serving at http://127.0.0.1:" in done.stderr, done.stderr
    assert done.returncode == 0 and "Stopped." in done.stderr, done.stderr


@pytest.mark.parametrize("stop", ["SIGINT", "SIGTERM"])
def test_cli_view_serves_on_loopback_until_interrupted(stop):
    """``screwkit view`` serves on 127.0.0.1 until Ctrl+C (SIGINT) or SIGTERM (a `kill`), then stops the server
    (no Meshcat server left without its parent) and exits 0. The command starts with SIGINT's default action, as
    from a terminal, whatever the test runner inherited (a shell's background job ignores SIGINT, and so would
    every process it starts)."""
    import signal

    process = subprocess.Popen([sys.executable, "-m", "screwkit.cli", "view", "planar_5rrr", "--failed", "chain_3"],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               env={**os.environ, "PYTHONFAULTHANDLER": "1"},  # SIGABRT: every thread's stack
                               preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    servers: list[int] = []
    try:
        port = None
        deadline = time.monotonic() + 120
        while port is None and time.monotonic() < deadline:
            line = process.stderr.readline()
            if not line:
                break
            match = re.search(r"Serving at http://127\.0\.0\.1:(\d+)/static/", line)
            port = int(match.group(1)) if match else None
        assert port is not None, "no 'Serving at' line on stderr"
        with socket.socket() as probe:
            assert probe.connect_ex(("127.0.0.1", port)) == 0, "the server is not listening on 127.0.0.1"
        servers = [int(entry) for entry in os.listdir("/proc") if entry.isdigit()
                   and _parent_pid(int(entry)) == process.pid]  # the Meshcat server is a child process
        sockets = [item for child in servers for item in listening_sockets(child)]
        assert ("127.0.0.1", port) in sockets and all(address == "127.0.0.1" for address, _ in sockets), sockets
        process.send_signal(getattr(signal, stop))
        try:
            stdout, stderr = process.communicate(timeout=60)
        except subprocess.TimeoutExpired:  # where it hangs, for the report
            process.send_signal(signal.SIGABRT)
            stdout, stderr = process.communicate(timeout=30)
            pytest.fail(f"still running 60 s after {stop}; its threads at SIGABRT:\n{stderr[-6000:]}")
    finally:
        if process.poll() is None:
            process.kill()
        deadline = time.monotonic() + 10
        while any(Path(f"/proc/{pid}").exists() for pid in servers) and time.monotonic() < deadline:
            time.sleep(0.1)  # (an orphan would be reparented, and reaped only once it ends)
        orphans = [pid for pid in servers if Path(f"/proc/{pid}").exists()]
        for pid in orphans:  # none left behind by this test, whatever failed
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)
    assert process.returncode == 0 and "Stopped." in stderr, stderr
    assert "chain_3" in stdout and "failed: chain_3:chain_3_joint_b" in stdout
    with socket.socket() as probe:  # stopped on Ctrl+C
        assert probe.connect_ex(("127.0.0.1", port)) != 0
    assert not orphans, "the Meshcat server outlived the command"


# ----------------------------------------------------------------------------------------
# Headless Chromium renders the offline page
# ----------------------------------------------------------------------------------------
def chromium_or_skip() -> Path:
    """/usr/bin/chromium, or a skip that says why (the tests never change the host: .ci/run installs it)."""
    if CHROMIUM.exists():
        return CHROMIUM
    pytest.skip(f"{CHROMIUM} is missing: headless Chromium renders the exported HTML; install the Debian packages "
                "chromium and chromium-driver (.ci/run does) to run this test.")


def render(pages: dict[str, Path], folder: Path, dump_dom: tuple[str, ...] = ()) -> dict[str, tuple]:
    """Screenshots (768, 1024, 3) of HTML files, rendered side by side by headless Chromium.

    Returns per page ``(image, dom)``: ``dom`` is the page's DOM after its scripts ran for the
    pages named in ``dump_dom`` (``--dump-dom``), else None.
    """
    from PIL import Image

    chromium = chromium_or_skip()
    rendered = {}
    with contextlib.ExitStack() as stack:
        running = {}
        for name, page in pages.items():
            profile = stack.enter_context(tempfile.TemporaryDirectory(prefix="chromium-profile-",
                                                                      ignore_cleanup_errors=True))
            log = stack.enter_context(open(folder / f"{name}.log", "wb"))
            dom = stack.enter_context(open(folder / f"{name}.dom.html", "wb"))
            screenshot = folder / f"{name}.png"
            command = [str(chromium), *CHROMIUM_FLAGS, f"--user-data-dir={profile}", f"--screenshot={screenshot}",
                       *(["--dump-dom"] if name in dump_dom else []), page.resolve().as_uri()]
            process = subprocess.Popen(command, stdout=dom, stderr=log, stdin=subprocess.DEVNULL)
            stack.callback(end_process, process)  # runs before its files close and its profile goes
            running[name] = (process, screenshot)
        for name, (process, screenshot) in running.items():
            try:
                process.wait(timeout=120)
            except subprocess.TimeoutExpired:
                pytest.fail(f"Chromium did not finish rendering {pages[name]} within 120 s.")
            assert screenshot.exists(), (f"Chromium wrote no screenshot of {pages[name]} (exit code "
                                         f"{process.returncode}); see {folder / (name + '.log')}")
            image = np.asarray(Image.open(screenshot).convert("RGB")).astype(int)
            rendered[name] = (image, (folder / f"{name}.dom.html").read_text() if name in dump_dom else None)
    return rendered


def end_process(process: subprocess.Popen) -> None:
    if process.poll() is None:
        process.kill()
        process.wait()


def middle(image: np.ndarray) -> np.ndarray:
    height, width, _ = image.shape
    return image[height // 5: 4 * height // 5, width // 5: 4 * width // 5]


def coloured_fraction(image: np.ndarray) -> float:
    """Share of clearly coloured pixels (channel spread > 60 of 255) in the middle region.

    The background and the ground grid are grey; chains (viridis), wrench lines (orange) and
    twist axes (magenta) are not.
    """
    region = middle(image)
    return float(np.mean(region.max(axis=-1) - region.min(axis=-1) > 60))


def shows_a_mechanism(image: np.ndarray) -> bool:
    region = middle(image)
    coarse = region // 32
    colours = len(np.unique(coarse[..., 0] * 64 + coarse[..., 1] * 8 + coarse[..., 2]))  # distinct coarse colours
    return coloured_fraction(image) > 0.02 and colours > 60


SYNCHRONOUS_FETCH = """<script>
// Test only: run the page's drawing commands (data: URLs) at once instead of in promises,
// so that the probe below sees the whole scene.
window.fetch = function (url) {
  const bytes = Uint8Array.from(atob(url.split(",")[1]), (c) => c.charCodeAt(0));
  const now = (value) => ({ then: (next) => now(next(value)) });
  return now({ arrayBuffer: () => bytes.buffer });
};
</script>
"""


def with_animation_probe(html: str, seconds: float, paths: dict[str, list[str]]) -> str:
    """The page, paused at ``seconds`` of its animation, writing the state of ``paths`` to its title."""
    start = html.rindex("<script", 0, html.index("var viewer = new MeshCat.Viewer"))
    html = html[:start] + SYNCHRONOUS_FETCH + html[start:]
    probe = f"""<script>
viewer.animator.pause();
viewer.animator.seek({seconds});
const probed = {{}};
for (const [name, path] of Object.entries({json.dumps(paths)})) {{
  const node = viewer.scene_tree.find(path).object;
  probed[name] = {{position: node.position.toArray(), quaternion: node.quaternion.toArray(),
                  visible: node.visible, colour: node.material ? node.material.color.toArray() : null}};
}}
document.title = "PROBE" + JSON.stringify(probed) + "PROBE";
</script>
"""
    end = html.rindex("</body>")
    return html[:end] + probe + html[end:]


SWEEP_FRAME = 6  # probed keyframe of the animation (phi = 10 deg)
PATH_FRAME = 7  # probed keyframe of the path animation


@pytest.fixture(scope="module")
def screenshots(planar, hexapod, graph, viewer, tmp_path_factory):
    folder = tmp_path_factory.mktemp("screenshots")
    export_html(show(planar, PLANAR_POSE, failed=[1], viewer=viewer), folder / "planar_5rrr.html")
    export_html(show(hexapod, SPATIAL_POSE, failed=[3], viewer=viewer), folder / "ups_hexapod_8.html")
    export_html(show(graph, graph.home_pose + np.array([0.04, -0.03, 0.02]), failed=[1], viewer=viewer),
                folder / "delta_rods_4.html")
    poses = np.column_stack([np.full(9, 0.05), np.full(9, -0.03), np.deg2rad(np.arange(-20.0, 21.0, 5.0))])
    sweep = animate_sweep(planar, poses, failed=[2], viewer=viewer, frame_rate=10)
    paths = {"platform": ["meshcat", ROOT_PATH, "mechanism", "visuals", "platform_0"],
             "wrench": ["meshcat", ROOT_PATH, "actuation_wrenches", "0-chain_1-chain_1_joint_b"],
             "centre": ["meshcat", ROOT_PATH, "output_twists", "0", "centre"]}
    (folder / "planar_5rrr_sweep.html").write_text(
        with_animation_probe(sweep.static_html(), SWEEP_FRAME / 10, paths))
    path = line_path(planar, [-0.3, -0.2, np.deg2rad(-45.0)], [0.3, 0.2, np.deg2rad(45.0)], 9)
    along = animate_sweep(planar, path, failed=["chain_3"], viewer=viewer, frame_rate=10)
    visuals = ["meshcat", ROOT_PATH, "mechanism", "visuals"]
    (folder / "planar_5rrr_path.html").write_text(with_animation_probe(along.static_html(), PATH_FRAME / 10, {
        "platform": visuals + ["platform_0"], "chain_4": visuals + ["chain_4_link_a_0", "<object>"],
        "chain_3": visuals + ["chain_3_link_a_0", "<object>"]}))
    viewer[ROOT_PATH].delete()  # the same viewer (background, grid, last camera) without the mechanism
    show(planar, PLANAR_POSE, viewer=viewer)  # also clears the animation
    viewer[ROOT_PATH].delete()
    export_html(viewer, folder / "blank.html")
    pages = {name: folder / f"{name}.html"
             for name in ("planar_5rrr", "ups_hexapod_8", "delta_rods_4", "blank", "planar_5rrr_sweep",
                          "planar_5rrr_path")}
    return (render(pages, folder, dump_dom=("planar_5rrr_sweep", "planar_5rrr_path")), folder,
            {"sweep": sweep, "path": along})


@pytest.mark.browser
def test_blank_page_fails_the_check(screenshots):
    rendered, folder, _ = screenshots
    blank = rendered["blank"][0]
    assert blank.shape == (768, 1024, 3)
    assert not shows_a_mechanism(blank), f"the check passes on an empty scene ({folder / 'blank.png'})"
    assert coloured_fraction(blank) < 0.01
    assert np.ptp(middle(blank)) > 20  # the viewer did render: a background gradient and grid, not a white page


@pytest.mark.browser
@pytest.mark.parametrize("name", ["planar_5rrr", "ups_hexapod_8", "delta_rods_4", "planar_5rrr_sweep",
                                  "planar_5rrr_path"])
def test_offline_page_renders_the_mechanism(screenshots, name):
    rendered, folder, _ = screenshots
    image, blank = rendered[name][0], rendered["blank"][0]
    assert shows_a_mechanism(image), (f"{folder / (name + '.png')}: only {coloured_fraction(image):.2%} "
                                      "coloured pixels in the middle")
    changed = np.mean(np.max(np.abs(middle(image) - middle(blank)), axis=-1) > 40)
    assert changed > 0.05, f"{folder / (name + '.png')} differs from the empty scene in {changed:.2%} of the middle"


@pytest.mark.browser
def test_browser_plays_the_sweep_animation(screenshots):
    rendered, folder, scenes = screenshots
    sweep = scenes["sweep"]
    dom = rendered["planar_5rrr_sweep"][1]
    match = re.search(r"PROBE(.*?)PROBE", dom)
    assert match, f"the probe did not run in the page; see {folder / 'planar_5rrr_sweep.dom.html'}"
    probed = json.loads(html.unescape(match.group(1)))
    pose = sweep.poses[SWEEP_FRAME]
    np.testing.assert_allclose(probed["platform"]["position"][:2], pose[:2], atol=1e-6)
    x, y, z, w = probed["platform"]["quaternion"]  # three.js order
    assert 2 * np.arctan2(z, w) == pytest.approx(pose[2], abs=1e-6) and abs(x) + abs(y) < 1e-6
    markers = {marker.path: marker for marker in sweep.frame_markers[SWEEP_FRAME]}
    wrench = markers[f"{ROOT_PATH}/actuation_wrenches/0-chain_1-chain_1_joint_b"]
    np.testing.assert_allclose(probed["wrench"]["position"], 0.5 * (wrench.start + wrench.end), atol=1e-6)
    centre = markers[f"{ROOT_PATH}/output_twists/0/centre"]
    np.testing.assert_allclose(probed["centre"]["position"], centre.start, atol=1e-6)
    assert probed["wrench"]["visible"] and probed["centre"]["visible"]


@pytest.mark.browser
def test_browser_plays_the_path_animation_with_the_chain_colours(screenshots):
    rendered, folder, scenes = screenshots
    along = scenes["path"]
    match = re.search(r"PROBE(.*?)PROBE", rendered["planar_5rrr_path"][1])
    assert match, f"the probe did not run in the page; see {folder / 'planar_5rrr_path.dom.html'}"
    probed = json.loads(html.unescape(match.group(1)))
    np.testing.assert_allclose(probed["platform"]["position"][:2], along.poses[PATH_FRAME][:2], atol=1e-6)
    np.testing.assert_allclose(probed["chain_4"]["colour"], colors_from_values(along.chain_values[PATH_FRAME, 3])[:3],
                               atol=1e-6)  # the colour of its index at that pose, not of the first frame
    assert np.abs(along.chain_values[PATH_FRAME, 3] - along.chain_values[0, 3]) > 0.2
    np.testing.assert_allclose(probed["chain_3"]["colour"], FAILED_COLOR[:3], atol=1e-6)  # the failed chain: red


def test_a_plate_outline_is_its_hull_with_spokes_to_the_points_inside():
    """A plate held at the corners of a tilted square, at a point inside it and at a repeated corner: the four
    edges of the square and one spoke from the centre of the five distinct points; points on a line: a polyline
    along them; one point: nothing."""
    from screwkit.viewer.graph_drawing import _outline

    tilt = np.array([[1.0, 0.0, 0.0], [0.0, np.cos(0.4), -np.sin(0.4)], [0.0, np.sin(0.4), np.cos(0.4)]])
    corners = [tilt @ np.array(c) + [0.3, -0.2, 0.5] for c in ([1, 1, 0], [-1, 1, 0], [-1, -1, 0], [1, -1, 0])]
    inner = tilt @ np.array([0.2, 0.1, 0.0]) + [0.3, -0.2, 0.5]
    rods = _outline(0, "base", [corners[2], inner, corners[0], corners[3], corners[1], corners[0].copy()], 1.0)
    assert all(rod.owner == "base" and rod.start == 0 and not rod.sphere for rod in rods)
    pieces = {(tuple(np.round(rod.start_point, 12)), tuple(np.round(rod.point, 12))) for rod in rods}
    centre = np.mean(corners + [inner], axis=0)
    square = {frozenset({tuple(np.round(corners[k], 12)), tuple(np.round(corners[(k + 1) % 4], 12))})
              for k in range(4)}
    assert len(rods) == 5 and {frozenset(p) for p in pieces} - {frozenset({tuple(np.round(centre, 12)),
                                                                           tuple(np.round(inner, 12))})} == square
    line = [np.array([x, 2 * x, 0.0]) for x in (0.3, -0.1, 0.7, 0.1)]
    along = _outline(5, "platform", line, 1.0)
    assert sorted(tuple(sorted((rod.start_point[0], rod.point[0]))) for rod in along) == [(-0.1, 0.1), (0.1, 0.3),
                                                                                          (0.3, 0.7)]
    assert _outline(0, "base", [corners[0], corners[0] + 1e-12], 1.0) == []
