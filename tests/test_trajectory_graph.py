"""Fault tolerance along a path of a mechanism whose legs have loops inside them: the rod-level Delta, every leg a
motor, an arm and two rods on ball joints (two closures a leg), opened as written.

Checked against the textbook pressure angles of its geometry (test_graph_legs.textbook), not against screwkit:
every index at every sample, and the stretches where each failure leaves the platform uncontrollable against a
dense evaluation of the textbook LMTI left; the same stretches in millimetres, in another world frame and with the
legs listed in another order; leaving the workspace located to the tolerance; the command as users run it.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from test_graph_batch import open_delta
from test_graph_legs import AZIMUTHS, POSES, textbook

from helpers import one_line_error, random_rotation, screwkit
from screwkit.studies.poses import graph_indices_at_poses
from screwkit.studies.trajectory import trajectory

DIRECTION = np.array([0.10, 0.06, 0.05])
"""Half the path, from the file's pose: a straight line through it, well inside the workspace."""
SAMPLES = 25


def _path(graph, scale=1.0, turn=None):
    home = graph.task_pose()
    steps = np.linspace(-1.0, 1.0, SAMPLES)[:, None] * DIRECTION
    return home + scale * steps @ (np.eye(3) if turn is None else turn).T, steps


def _left_after(moves: np.ndarray) -> np.ndarray:
    """The textbook LMTI left after each single failure, (n, 4) (the largest OTI of a 3-subset without it)."""
    rows = []
    for move in moves:
        oti = textbook(np.add(POSES[0], move))["oti"]
        rows.append([max(v for members, v in oti.items() if failed not in members) for failed in range(4)])
    return np.array(rows)


def _dense_lost(values: np.ndarray, s: np.ndarray, level: float) -> list[tuple[float, float]]:
    """Stretches of ``s`` where ``values`` < ``level``, their ends at the middle of the dense step that changes."""
    lost = values < level
    edges = np.flatnonzero(lost[1:] != lost[:-1])
    cuts = [float(s[0])] + [float((s[i] + s[i + 1]) / 2) for i in edges] + [float(s[-1])]
    runs = list(zip(cuts[:-1], cuts[1:]))
    return [run for k, run in enumerate(runs) if (k % 2 == 0) == bool(lost[0])]


@pytest.fixture(scope="module")
def delta(tmp_path_factory):
    graph = open_delta(tmp_path_factory.mktemp("delta"))
    poses, steps = _path(graph)
    dense = np.linspace(-1.0, 1.0, 4001)[:, None] * DIRECTION
    left = _left_after(dense)
    level = float((left[:, 0].min() + left[:, 0].max()) / 2)  # leg 1's failure crosses it: a stretch to find
    return graph, poses, steps, level, dense, left


def test_every_index_along_the_path_is_the_textbook_s_and_the_lost_stretches_a_dense_sampling_s(delta):
    graph, poses, steps, level, dense, left = delta
    result = trajectory(graph, poses, level=level)
    assert result.indices.reachable.all() and not result.events
    for k, move in enumerate(steps):
        expected = textbook(np.add(POSES[0], move))
        np.testing.assert_allclose(result.indices.iti_actuators[k], expected["iti"], atol=1e-9)
        np.testing.assert_allclose([result.indices.lmti[k], result.indices.f_o[1][k]],
                                   [expected["lmti"], expected["f_o1"]], atol=1e-9)
    for k in (0, SAMPLES // 2, SAMPLES - 1):  # and each sample alone, as `analyze` closes it
        alone = graph.at_pose(poses[k]).indices()
        np.testing.assert_allclose([result.indices.lmti[k], result.indices.f_o[1][k]], [alone.lmti, alone.f_o[1]],
                                   atol=1e-12)
    s_dense = np.linspace(0.0, result.path.length, len(dense))
    step = s_dense[1] - s_dense[0]
    names = result.indices.actuators
    found_some = 0
    for leg in range(4):
        case = result.case(names[leg])
        expected = _dense_lost(left[:, leg], s_dense, level)
        assert len(case.lost) == len(expected), (names[leg], case.lost, expected)
        for (start, stop), (dense_start, dense_stop) in zip(case.lost, expected):
            assert abs(start - dense_start) <= result.tolerance + step
            assert abs(stop - dense_stop) <= result.tolerance + step
        found_some += len(expected)
        assert case.minimum == pytest.approx(left[:, leg].min(), abs=1e-6)
    assert found_some >= 1  # the path is a test of something
    assert set(result.working_modes) == {"arm_1", "arm_2", "arm_3", "arm_4"}


def test_the_stretches_are_the_same_scaled_in_another_frame_and_with_the_legs_reordered(delta, tmp_path):
    graph, poses, _, level, _, _ = delta
    reference = trajectory(graph, poses, level=level)
    turn = random_rotation(np.random.default_rng(21))

    def lost_by_failed_leg(result, scale, order=(0, 1, 2, 3)):
        names = result.indices.actuators
        return {order[leg]: result.case(names[leg]).lost / scale for leg in range(4)}

    expected = lost_by_failed_leg(reference, 1.0)
    near = np.array([0.01, 0.0, -0.02])
    for scale, rotation, shift in ((1e3, turn, near), (1e-3, turn, near), (1.0, turn, np.array([0.3, -1.2, 2.0]))):
        moved = open_delta(tmp_path, transform=(scale, rotation, shift), name="moved.xml")
        moved_poses, _ = _path(moved, scale, rotation)
        result = trajectory(moved, moved_poses, level=level)
        assert result.tolerance == pytest.approx(scale * reference.tolerance)
        for leg, lost in lost_by_failed_leg(result, scale).items():
            np.testing.assert_allclose(lost, expected[leg], atol=2 * reference.tolerance)
    order = [2, 0, 3, 1]
    relabelled = open_delta(tmp_path, azimuths=AZIMUTHS[order], name="relabelled.xml")
    result = trajectory(relabelled, _path(relabelled)[0], level=level)
    for leg, lost in lost_by_failed_leg(result, 1.0, order).items():
        np.testing.assert_allclose(lost, expected[leg], atol=2 * reference.tolerance)


def test_the_configurations_kept_put_the_frame_at_each_pose_and_are_nan_out_of_reach(delta):
    graph = delta[0]
    poses = graph.task_pose() + np.array([[0.0, 0.0, 0.0], [0.03, -0.02, 0.01], [0.0, 0.0, 0.6]])
    indices, q = graph_indices_at_poses(graph, poses, configurations=True)
    assert indices.reachable.tolist() == [True, True, False] and np.isnan(q[2]).all()
    np.testing.assert_allclose(graph.frame_pose(q[:2])[:, :3], poses[:2], atol=1e-12)
    np.testing.assert_allclose(indices.lmti, graph_indices_at_poses(graph, poses).lmti, atol=0, equal_nan=True)


def test_leaving_the_workspace_is_located_to_the_tolerance(delta):
    graph = delta[0]
    home = graph.task_pose()
    poses = home + np.linspace(0.0, 1.0, 11)[:, None] * np.array([0.0, 0.0, 0.6])  # straight up, out of reach
    result = trajectory(graph, poses)
    (event,) = result.events
    assert event.kind == "closure" and "no closed configuration" in event.reason
    s = result.path.arc_length
    assert s[event.samples[0] - 1] < event.start <= s[event.samples[0]]
    before, after = result.path.at(np.array([event.start - result.tolerance, event.start + result.tolerance]))
    _, reached = graph.solve(np.array([before, after]))
    assert reached[0] and not reached[1]


def test_the_command_follows_a_path_of_the_rod_level_delta_as_written(tmp_path):
    """``screwkit trajectory delta_rods_4 --line ...`` (the bundled MJCF file, its legs closed by rods on ball
    joints): exit 0, the summary as JSON and the netCDF with every sample; --closed-forms refused in one line
    (--actuators: test_graph_actuator_path)."""
    import xarray as xr

    out = tmp_path / "path.nc"
    completed = screwkit("trajectory", "delta_rods_4", "--line", "-0.04", "0", "-0.78", "0.04", "0.03", "-0.72",
                         "--samples", "9", "--json", "--out", out)
    assert completed.returncode == 0, completed.stderr
    summary = json.loads(completed.stdout)
    assert summary["samples"] == 9 and summary["reachable_samples"] == 9 and summary["events"] == []
    assert set(summary["working_modes"]) == {"arm_1", "arm_2", "arm_3", "arm_4"}
    assert len(summary["faults"]) == 4 and summary["worst"]["1"]
    with xr.open_dataset(out) as dataset:
        assert dataset.sizes["sample"] == 9 and np.all(np.isfinite(dataset["f_o1"].values))
    one_line_error(screwkit("trajectory", "delta_rods_4", "--line", "0", "0", "-0.75", "0", "0", "-0.7",
                            "--closed-forms"), "no closed forms")


def test_the_bundled_rod_level_delta_loses_control_where_its_r_u_u_model_does():
    """``delta_rods_4`` (a graph, closed by continuation) and ``delta_4`` (serial R-U-U legs, closed forms) have
    the same ITI, LMTI and F_O1 at every pose: along a pick-and-place cycle, each failure's lost stretches agree to
    the two tolerances and its minimum to 1e-9, although every number comes from another model and solver."""
    from screwkit.io import graph_mechanism, read_closed_tree
    from screwkit.io.loader import bundled_path, load
    from screwkit.studies.paths import through_path

    delta = load("delta_4")
    corners = np.array([[0.2, 0.1, -0.65], [0.2, 0.1, -0.85], [0.2, 0.1, -0.65],
                        [-0.2, -0.15, -0.65], [-0.2, -0.15, -0.85], [-0.2, -0.15, -0.65]])
    cycle = through_path(delta, corners, 41)
    serial = trajectory(delta, cycle, level=0.5)
    rods = trajectory(graph_mechanism(read_closed_tree(bundled_path("delta_rods_4"))), cycle.poses, level=0.5)
    assert not rods.events and sum(len(case.lost) for case in serial.cases) >= 4
    for a, b in zip(serial.cases, rods.cases):
        assert a.failed[0].split(":")[0][-1] == b.failed[0].split(":")[0][-1]  # leg_k and arm_k
        assert a.lost.shape == b.lost.shape
        np.testing.assert_allclose(b.lost, a.lost, atol=serial.tolerance + rods.tolerance)
        assert abs(a.minimum - b.minimum) < 1e-9
