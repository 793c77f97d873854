"""A path given in actuator values (``trajectory --actuators``) of a mechanism whose legs have loops inside them.

Such a path was refused ("posed by the output frame only"). It is now followed in joint space: each sample's
configuration from the one before, the actuators moved in small steps and the closures assembled with them held
(``screwkit.io.graph_actuators.follow_actuators``); the trajectory analyses those configurations, and between two
samples moves the actuators linearly along the segment. Posing it by its task coordinates instead would go wrong
past a fold of them: the parallelogram of ``test_idle_dyad`` (a dyad on its rocker, read as a graph) has the
coupler's x as its coordinate, which peaks near 68 deg of crank and comes back, so a pose past the peak closes
from the file's configuration on the near side of it (another crank angle).

Checked against the linkage's geometry (``test_graph_actuators.textbook``: ITI = LMTI = 1 and the CTI
|sin(B'C', C'D)| at crank angle theta), in m, mm and a turned world, listed the other way round; a crank's stop
located where the crank reaches it; the redundant rod-level Delta driven by the arm angles of a pose path back onto
that path, with the textbook pressure angles there; the command as users run it.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from test_graph_actuators import textbook
from test_graph_batch import open_delta
from test_graph_legs import POSES
from test_graph_legs import textbook as delta_textbook
from test_idle_dyad import A, B, linkage

from helpers import MJCF_WORLDS, mjcf_variant, one_line_error, screwkit
from screwkit.io import read_closed_tree
from screwkit.io.closed_tree import joint_value
from screwkit.io.graph import graph_mechanism
from screwkit.studies.actuator_paths import path_from_actuators
from screwkit.studies.options import AnalysisOptions
from screwkit.studies.path_mechanisms import path_mechanism
from screwkit.studies.trajectory import trajectory

CRANK = np.linspace(-40.0, 150.0, 20)
"""Crank angles (deg) from below the file's to well past the peak of the coupler's x."""


def coupler_x(degrees) -> np.ndarray:
    """The x of the coupler's origin B' = A + R(theta)(B - A) (the crank turned about y)."""
    angle = np.radians(degrees)
    return A[0] + np.cos(angle) * (B - A)[0] + np.sin(angle) * (B - A)[2]


def _parallelogram(tmp_path, variant="m", reverse=False, limited=False):
    def text(scale, world):
        written = linkage(scale, world, dyad="rocker", reverse=reverse)
        return written.replace('name="crank" type="hinge" axis="0 1 0"', 'name="crank" type="hinge" axis="0 1 0" '
                               'range="-60 60" limited="true"') if limited else written
    path, unit = mjcf_variant(tmp_path, f"para_{reverse}_{limited}", variant, text)
    return path, graph_mechanism(read_closed_tree(path, output="coupler", length_unit=unit))


@pytest.mark.parametrize("variant", sorted(MJCF_WORLDS))
def test_a_crank_path_past_the_fold_of_its_coordinate_reads_the_parallelogram_at_every_sample(tmp_path, variant):
    _, graph = _parallelogram(tmp_path, variant)
    path = path_from_actuators(graph, np.radians(CRANK)[:, None])
    if variant == "m":  # (the coordinate folds: x rises to its peak and comes back)
        np.testing.assert_allclose(path.poses[:, 0], coupler_x(CRANK), atol=1e-12)
        assert np.argmax(path.poses[:, 0]) not in (0, len(CRANK) - 1)
    result = trajectory(graph, path)
    assert result.summary()["reachable_samples"] == len(CRANK) and not result.events
    np.testing.assert_allclose(np.asarray(result.indices.iti), 1.0, atol=1e-9)
    np.testing.assert_allclose(np.asarray(result.indices.lmti), 1.0, atol=1e-9)
    np.testing.assert_allclose(np.asarray(result.indices.cti), [textbook(d) for d in CRANK], atol=1e-9)


def test_the_same_with_the_linkage_listed_the_other_way_round(tmp_path):
    _, graph = _parallelogram(tmp_path, reverse=True)
    result = trajectory(graph, path_from_actuators(graph, np.radians(CRANK)[:, None]))
    np.testing.assert_allclose(np.asarray(result.indices.cti), [textbook(d) for d in CRANK], atol=1e-9)


def test_a_crank_stop_on_the_path_is_located_where_the_crank_reaches_it(tmp_path):
    """Range +-60 deg, the crank driven from 0 to 90 deg: reachable up to 60 deg, a joint limit after it, located
    to the trajectory's tolerance at 60 deg along the path (its arc length is along the actuator: the crank's
    angle times the length scale)."""
    _, graph = _parallelogram(tmp_path, limited=True)
    degrees = np.linspace(0.0, 90.0, 10)
    result = trajectory(graph, path_from_actuators(graph, np.radians(degrees)[:, None]))
    [event] = result.events
    assert event.kind == "joint limit" and "'crank' at 70 deg, limits [-60, 60] deg" in event.reason
    assert event.start == pytest.approx(np.radians(60.0) * graph.length_scale, abs=result.tolerance)
    assert event.stop == pytest.approx(result.path.length, abs=1e-12)
    assert result.summary()["reachable_samples"] == int(np.sum(degrees <= 60.0))


def test_the_redundant_rod_level_delta_driven_by_its_arms_follows_the_pose_path(tmp_path):
    """Four arms, three DOF: the arm angles of a straight pose path (each pose closed by the pose solver), given
    as the actuators' path, drive the platform back onto those poses (an independent solve: the actuators held,
    not the pose), with the textbook pressure angles there."""
    graph = open_delta(tmp_path)
    steps = np.linspace(-1.0, 1.0, 7)[:, None] * np.array([0.08, 0.05, 0.04])
    poses = graph.task_pose() + steps
    closed, reached = graph.solve(poses)
    assert reached.all()
    motors = [leg.actuators[0] for leg in graph.legs]
    values = np.array([[joint_value(graph.tree.model, joint, q) for joint in motors] for q in closed])
    path = path_from_actuators(graph, values)
    np.testing.assert_allclose(path.poses, poses, atol=1e-9)
    result = trajectory(graph, path)
    for k, step in enumerate(steps):
        expected = delta_textbook(np.add(POSES[0], step))
        np.testing.assert_allclose(result.indices.iti_actuators[k], expected["iti"], atol=1e-9)
        np.testing.assert_allclose(result.indices.lmti[k], expected["lmti"], atol=1e-9)


def test_the_command_follows_a_crank_path_past_the_fold_and_refuses_disagreeing_arms(tmp_path):
    """``trajectory FILE PATH --actuators``: the crank's column in deg, the summary as JSON and the netCDF with the
    textbook CTI at every sample; a Delta's four arms whose values no configuration takes refused in one line
    naming the sample."""
    import xarray as xr

    model, _ = _parallelogram(tmp_path)
    path, out = tmp_path / "crank.csv", tmp_path / "crank.nc"
    path.write_text("crank\n" + "\n".join(repr(float(d)) for d in CRANK) + "\n")
    completed = screwkit("trajectory", model, path, "--actuators", "--output", "coupler", "--json", "--out", out)
    assert completed.returncode == 0, completed.stderr
    summary = json.loads(completed.stdout)
    assert summary["samples"] == summary["reachable_samples"] == len(CRANK) and summary["events"] == []
    with xr.open_dataset(out) as dataset:
        np.testing.assert_allclose(dataset["cti"].values, [textbook(d) for d in CRANK], atol=1e-9)
    arms = tmp_path / "arms.csv"
    arms.write_text("arm_1,arm_2,arm_3,arm_4\n0,0,0,0\n10,0,0,0\n")
    one_line_error(screwkit("trajectory", "delta_rods_4", arms, "--actuators"), "sample 1", "(10, 0, 0, 0",
                   "disagree")


def test_the_redundant_delta_posed_by_its_arms_rounded_as_written_reads_that_pose(tmp_path):
    """``at_actuators`` (``analyze --actuators``) on the four-arm Delta, away from the file's pose: the arm angles
    of a pose, written to 1e-4 deg, agree only to that rounding. Held all four at once at every step, they closed
    no step (a false refusal), and held at those values the loops close only to 1e-7 m, where the graph read 2 DOF.
    The steps now hold three arms, and the configuration is the closed one nearest to all four: 3 DOF, the pose to
    the rounding, the textbook indices there; an arm 1 deg off is refused, saying by how much it misses."""
    graph = open_delta(tmp_path)
    step = np.array([0.08, 0.05, 0.04])
    closed, reached = graph.solve(graph.task_pose() + step[None])
    motors = [leg.actuators[0] for leg in graph.legs]
    values = np.radians(np.round(np.degrees([joint_value(graph.tree.model, j, closed[0]) for j in motors]), 4))
    moved = graph.at_actuators(values)
    assert moved.dof == 3 and moved.task_coordinates == ("x", "y", "z")
    np.testing.assert_allclose(moved.task_pose(), graph.task_pose() + step, atol=1e-5)
    result, expected = moved.indices(), delta_textbook(np.add(POSES[0], moved.task_pose() - graph.task_pose()))
    np.testing.assert_allclose(result.iti_actuators, expected["iti"], atol=1e-9)
    np.testing.assert_allclose(result.lmti, expected["lmti"], atol=1e-9)
    with pytest.raises(ValueError, match="redundant actuators whose values disagree \\(or the ones held passed a "
                                         "singular configuration on the way\\): the closed configuration nearest to "
                                         "them misses one by"):
        graph.at_actuators(values + np.radians([1.0, 0.0, 0.0, 0.0]))


def test_a_segment_whose_two_samples_share_a_pose_is_followed_through(tmp_path):
    """Crank samples symmetric about the peak of the coupler's x (68.2 deg): 58.2 and 78.2 deg put the coupler at one
    x. Between samples placed by the pose's arc length, that segment had no length, nothing inside it was seen, and
    two working-mode changes were reported there; along the crank it has 20 deg, and the parallelogram stays on its
    branch (no event), the CTI the linkage's at every sample."""
    _, graph = _parallelogram(tmp_path)
    degrees = np.array([0.0, 30.0, 58.2, 78.2, 100.0])
    path = path_from_actuators(graph, np.radians(degrees)[:, None])
    assert path.poses[2, 0] == pytest.approx(path.poses[3, 0], abs=1e-5)  # (0.4 um of 20 deg of crank)
    result = trajectory(graph, path)
    assert not result.events, result.events
    np.testing.assert_allclose(np.asarray(result.indices.cti), [textbook(d) for d in degrees], atol=1e-9)
    np.testing.assert_allclose(np.diff(path.arc_length), np.radians(np.diff(degrees)) * graph.length_scale,
                               rtol=1e-12)


def test_a_redundant_path_locates_each_failures_loss_where_the_textbook_crosses_the_level(tmp_path):
    """The four-arm Delta driven by the arm angles of half a loop of poses (7 samples): between samples the
    configuration is the mean of those each non-redundant set of arms gives, closed. At each end of a lost stretch
    found inside the path, the textbook LMTI left after that failure (pressure angles of the geometry, at the pose
    the configuration there has) is the level to the tolerance (1e-5 m of the path, 2e-5 of the LMTI)."""
    graph = open_delta(tmp_path)
    home, turn = graph.task_pose(), np.linspace(0.0, np.pi, 7)
    poses = home + np.stack([0.08 * np.cos(turn) - 0.08, 0.08 * np.sin(turn), 0.03 * np.sin(2 * turn)], axis=1)
    closed, reached = graph.solve(poses)
    assert reached.all()
    motors = [leg.actuators[0] for leg in graph.legs]
    values = np.array([[joint_value(graph.tree.model, joint, q) for joint in motors] for q in closed])

    def left(pose, failed: int) -> float:
        oti = delta_textbook(np.add(POSES[0], pose - home))["oti"]
        return max(value for members, value in oti.items() if failed not in members)

    level = float(np.mean([left(pose, 0) for pose in poses]))
    result = trajectory(graph, path_from_actuators(graph, values), level=level, tolerance=1e-5)
    assert not result.events
    along = path_mechanism(graph, AnalysisOptions(), {}, result.path)
    ends = [(k, at) for k, case in enumerate(result.cases) for stretch in case.lost for at in stretch
            if 0.0 < at < result.path.length]
    assert ends
    for k, at in ends:
        failed = graph.actuators.index(result.cases[k].failed[0])
        pose = np.asarray(along.indices_along(result.path, np.array([at])).full_poses)[0, :3]
        assert left(pose, failed) == pytest.approx(level, abs=2e-5)  # (located to 1e-5 m of the path)


def test_between_samples_the_arms_keep_values_that_agree_and_no_name_moves_the_configuration(tmp_path):
    """Between two samples of ``delta_rods_4``'s mirror-symmetric family (arm_1 = arm_4, arm_2 = arm_3: values that
    agree all along a segment), the configuration has every arm at its interpolated value (a rule holding none moved
    them up to 0.98 deg, and lost stretches 1.4e-2 m); on a segment whose values do not quite agree (a loop of
    poses), the configuration is the same with ``motor_1`` renamed ``motor_9`` (holding the first three by name
    moved a lost stretch by 0.7 mm)."""
    from screwkit.io.graph_actuators import between_samples
    from screwkit.io.loader import bundled_path

    source = bundled_path("delta_rods_4")
    graph = graph_mechanism(read_closed_tree(source))
    model, motors = graph.tree.model, [leg.actuators[0] for leg in graph.legs]
    pair = np.radians([[0.0, 0.0, 0.0, 0.0], [30.0, -15.0, -15.0, 30.0]])
    ends = path_from_actuators(graph, pair)
    for fraction in (0.25, 0.5, 0.75):
        value = pair[0] + fraction * (pair[1] - pair[0])
        q = between_samples(graph, ends.configurations[0], ends.configurations[1], fraction, value)
        np.testing.assert_allclose([joint_value(model, joint, q) for joint in motors], value, atol=1e-9)
    home, turn = graph.task_pose(), np.array([0.0, 0.6])
    poses = home + np.stack([0.15 * np.cos(turn) - 0.15, 0.15 * np.sin(turn), 0.05 * np.sin(2 * turn)], axis=1)
    closed, _ = graph.solve(poses)
    values = np.array([[joint_value(model, joint, q) for joint in motors] for q in closed])
    renamed_file = tmp_path / "renamed.xml"
    renamed_file.write_text(source.read_text().replace('"motor_1"', '"motor_9"'))
    renamed = graph_mechanism(read_closed_tree(renamed_file))
    middle = values.mean(axis=0)
    found = [between_samples(g, closed[0], closed[1], 0.5, middle) for g in (graph, renamed)]
    np.testing.assert_allclose(found[0], found[1], atol=1e-12)


def test_four_arms_turned_together_past_where_three_of_them_fold_reach_the_symmetric_pose():
    """``delta_rods_4`` (symmetric about z, arms at 0 in the file), all four arms to 80 deg: the values agree by
    symmetry, but with three arms held the platform passes where they are at their input singularity (near 79 deg)
    and the fourth came back on its other branch; refused as "disagree". The steps hold all four first now: every
    arm at 80 deg, every rod closed, the platform on the axis (below the lowest point the arms' fold gives, where a
    pose solve from the file's configuration stops at 77.9 deg: a pose there has two arm angles)."""
    from screwkit.io.closed_tree import closure_gaps
    from screwkit.io.loader import bundled_path

    graph = graph_mechanism(read_closed_tree(bundled_path("delta_rods_4")))
    moved = graph.at_actuators(np.radians([80.0] * 4))
    arms = [np.degrees(joint_value(graph.tree.model, leg.actuators[0], moved.q)) for leg in graph.legs]
    np.testing.assert_allclose(arms, 80.0, atol=1e-9)
    assert max(closure_gaps(graph.tree, moved.q).values()) < 1e-12
    np.testing.assert_allclose(moved.task_pose()[:2], 0.0, atol=1e-9)


def test_a_crank_path_moving_by_rounding_only_is_refused(tmp_path):
    """A crank moved by 2e-15 rad: as poses, such a path is refused as one that moves only by rounding; given in
    actuator values it was analysed. Refused the same way now."""
    _, graph = _parallelogram(tmp_path)
    with pytest.raises(ValueError, match="Expected a path that moves: its actuators move by"):
        path_from_actuators(graph, np.array([[0.0], [2e-15]]))


def test_configurations_given_of_the_wrong_shape_are_refused_naming_both(tmp_path):
    from screwkit.studies.poses import graph_indices_at_poses

    _, graph = _parallelogram(tmp_path)
    poses = graph.task_pose()[None].repeat(2, axis=0)
    with pytest.raises(ValueError, match=f"Expected `configurations` of shape \\(2, {graph.kinematics.nq}\\), got "
                                         "\\(2, 3\\)"):
        graph_indices_at_poses(graph, poses, configurations=np.zeros((2, 3)))
