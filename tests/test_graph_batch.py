"""Closed-loop graphs at many poses at once (:mod:`screwkit.io.graph_kinematics`,
:func:`screwkit.studies.poses.graph_indices_at_poses`).

The batched forward kinematics and joint twists are those Pinocchio computes, for every joint type the module
takes; its integration moves each frame along the twists (finite differences); the batched indices of the
rod-level Delta are those of :meth:`GraphMechanism.at_pose` pose by pose (<= 1e-12) and the textbook pressure
angles over a grid (<= 1e-9); the same in millimetres, in another world frame and with the legs listed in another
order; unreachable poses are NaN, and a Stewart platform opened through the graph moves in all six coordinates.
A position beyond the frame's reach (bounded by its tree path, checked against Pinocchio's forward kinematics and
met by a straight arm) is unreachable without a continuation towards it, with the answer the continuation gives.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from delta_rods import delta_rods_mjcf
from test_gallery import GALLERY
from test_graph_legs import AZIMUTHS, POSES, textbook

from helpers import one_line_error, random_rotation, screwkit
from screwkit.io import graph_kinematics
from screwkit.io.closed_tree import homogeneous
from screwkit.io.graph import graph_mechanism
from screwkit.io.graph_kinematics import TreeKinematics, reach_bound
from screwkit.io.mjcf import read_mjcf
from screwkit.studies.graph_source import cached_graph, graph_source
from screwkit.studies.maps import index_map
from screwkit.studies.poses import graph_indices_at_poses
from screwkit.studies.sweep import sweep

TOLERANCE = 1e-9


def open_delta(tmp_path, centre=POSES[0], azimuths=AZIMUTHS, name="delta.xml", transform=None):
    path = tmp_path / name
    path.write_text(delta_rods_mjcf(centre, azimuths, transform=transform))
    return graph_mechanism(read_mjcf(path))


def random_configurations(model, count: int, rng) -> np.ndarray:
    """Configurations spread over each joint's range (Pinocchio's integration from the neutral one)."""
    import pinocchio as pin

    neutral = pin.neutral(model)
    return np.array([pin.integrate(model, neutral, rng.uniform(-1.5, 1.5, model.nv)) for _ in range(count)])


def sample_models(tmp_path):
    """The rod-level Delta (revolute and ball joints) and Pinocchio's humanoid sample (a free joint and revolutes)
    with one joint made prismatic and one unbounded revolute, read from URDF text."""
    import pinocchio as pin

    delta = open_delta(tmp_path).tree.model
    urdf = """<robot name="mixed"><link name="base"/>
      <link name="a"/><link name="b"/><link name="c"/>
      <joint name="slide" type="prismatic"><parent link="base"/><child link="a"/><origin xyz="0.1 0.2 0.3"
        rpy="0.3 -0.2 0.5"/><axis xyz="0.6 0 0.8"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
      <joint name="spin" type="continuous"><parent link="a"/><child link="b"/><origin xyz="0.4 0 -0.1"
        rpy="0.1 0.2 0.3"/><axis xyz="0 1 0"/></joint>
      <joint name="hinge" type="revolute"><parent link="b"/><child link="c"/><origin xyz="0 0.3 0.2"/>
        <axis xyz="0.48 0.6 0.64"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint></robot>"""
    mixed = pin.buildModelFromXML(urdf, pin.JointModelFreeFlyer())
    return {"delta": delta, "mixed": mixed}


@pytest.mark.parametrize("which", ["delta", "mixed"])
def test_batched_kinematics_are_pinocchio_s(tmp_path, which):
    """Joint placements and WORLD Jacobian columns as Pinocchio computes them, at random configurations."""
    import pinocchio as pin

    model = sample_models(tmp_path)[which]
    kinematics = TreeKinematics.of(model)
    q = random_configurations(model, 5, np.random.default_rng(1))
    transforms = kinematics.transforms(q)
    twists = kinematics.twists(transforms)
    data = model.createData()
    for n in range(len(q)):
        pin.computeJointJacobians(model, data, q[n])
        for joint in range(1, model.njoints):
            np.testing.assert_allclose(transforms[n, joint], data.oMi[joint].homogeneous, atol=1e-12)
        jacobian = np.asarray(pin.getJointJacobian(model, data, model.njoints - 1, pin.ReferenceFrame.WORLD))
        path = np.flatnonzero(np.abs(jacobian).sum(axis=0) > 0)
        np.testing.assert_allclose(twists[n][path][:, :3], jacobian[3:, path].T, atol=1e-12)
        np.testing.assert_allclose(twists[n][path][:, 3:], jacobian[:3, path].T, atol=1e-12)


@pytest.mark.parametrize("which", ["delta", "mixed"])
def test_integration_moves_every_frame_along_its_twists(tmp_path, which):
    """A small step of each velocity coordinate moves every body as the twists say (central differences), so the
    Newton steps of the closure solver and its Jacobian agree; revolute and ball steps are Pinocchio's own."""
    import pinocchio as pin

    model = sample_models(tmp_path)[which]
    kinematics = TreeKinematics.of(model)
    q = random_configurations(model, 1, np.random.default_rng(2))
    twists = kinematics.twists(kinematics.transforms(q))[0]
    step = 1e-6
    for coordinate in range(model.nv):
        move = np.zeros((1, model.nv))
        move[0, coordinate] = step
        ahead = kinematics.transforms(kinematics.integrate(q, move))[0]
        behind = kinematics.transforms(kinematics.integrate(q, -move))[0]
        # the body the coordinate's joint moves (a serial chain's last one, moved by every coordinate)
        joint = model.njoints - 1 if which == "mixed" else int(kinematics.column_joint[coordinate])
        omega, v = twists[coordinate, :3], twists[coordinate, 3:]
        point = kinematics.transforms(q)[0, joint, :3, 3]
        velocity = (ahead[joint, :3, 3] - behind[joint, :3, 3]) / (2 * step)
        np.testing.assert_allclose(velocity, v + np.cross(omega, point), atol=1e-6)
    if which == "delta":  # no free joint: every step is Pinocchio's own integration
        v = np.random.default_rng(3).normal(size=(1, model.nv)) * 0.3
        np.testing.assert_allclose(kinematics.integrate(q, v)[0], pin.integrate(model, q[0], v[0]), atol=1e-12)


def test_batched_indices_are_those_of_each_pose_alone_and_the_textbook_pressure_angles(tmp_path):
    graph = open_delta(tmp_path)
    assert graph.task_coordinates == ("x", "y", "z")
    home = graph.task_pose()
    rng = np.random.default_rng(7)
    moves = rng.uniform(-0.06, 0.06, (40, 3))
    result = graph_indices_at_poses(graph, home + moves, detail=True, chunk_size=16)
    assert result.reachable.all()
    for k in range(0, 40, 5):
        alone = graph.at_pose(home + moves[k]).indices()
        np.testing.assert_allclose(result.iti_actuators[k], alone.iti_actuators, atol=1e-12)
        np.testing.assert_allclose([result.lmti[k], result.f_o[1][k]], [alone.lmti, alone.f_o[1]], atol=1e-12)
        expected = textbook(np.add(POSES[0], moves[k]))
        np.testing.assert_allclose(result.iti_actuators[k], expected["iti"], atol=TOLERANCE)
        np.testing.assert_allclose([result.lmti[k], result.f_o[1][k]], [expected["lmti"], expected["f_o1"]],
                                   atol=TOLERANCE)
    np.testing.assert_allclose(result.full_poses[:, :3], home + moves, atol=1e-12)
    np.testing.assert_allclose(result.full_poses[:, 3:], 0.0, atol=1e-12)  # a Delta's platform does not turn


def test_batched_indices_in_millimetres_in_another_frame_and_with_the_legs_reordered(tmp_path):
    graph = open_delta(tmp_path)
    moves = np.random.default_rng(8).uniform(-0.05, 0.05, (12, 3))
    reference = graph_indices_at_poses(graph, graph.task_pose() + moves)
    rotation = random_rotation(np.random.default_rng(9))
    for scale, turn, shift in ((1e-3, rotation, np.array([0.01, 0.0, -0.02])), (1e3, np.eye(3), np.zeros(3)),
                               (1.0, rotation, np.array([0.3, -1.2, 2.0]))):
        moved = open_delta(tmp_path, transform=(scale, turn, shift), name="moved.xml")
        assert moved.task_coordinates == ("x", "y", "z")
        result = graph_indices_at_poses(moved, moved.task_pose() + scale * moves @ turn.T, threshold=1e-6 * scale)
        np.testing.assert_allclose(result.lmti, reference.lmti, atol=TOLERANCE)
        np.testing.assert_allclose(result.f_o[1], reference.f_o[1], atol=TOLERANCE)
        np.testing.assert_allclose(result.cti, reference.cti, atol=TOLERANCE)
    order = [2, 0, 3, 1]
    relabelled = open_delta(tmp_path, azimuths=AZIMUTHS[order], name="relabelled.xml")
    result = graph_indices_at_poses(relabelled, relabelled.task_pose() + moves)
    for name in ("lmti", "cti"):
        np.testing.assert_allclose(getattr(result, name), getattr(reference, name), atol=TOLERANCE)
    np.testing.assert_allclose(result.f_o[1], reference.f_o[1], atol=TOLERANCE)


def test_a_pose_is_closed_the_same_alone_and_in_any_batch(tmp_path):
    """Each pose takes as many continuation stages as its own move needs (not the batch's longest): a pose solved
    alone and in a batch of poses near and far gives the same configuration, bit for bit."""
    graph = open_delta(tmp_path)
    moves = np.random.default_rng(12).uniform(-0.12, 0.12, (24, 3)) * np.geomspace(0.05, 1.0, 24)[:, None]
    poses = graph.task_pose() + moves
    together, reached = graph.solve(poses)
    assert reached.all()
    for k in (0, 5, 23):
        alone, _ = graph.solve(poses[k:k + 1])
        np.testing.assert_array_equal(alone[0], together[k])
    reordered, _ = graph.solve(poses[::-1])
    np.testing.assert_array_equal(reordered[::-1], together)


def test_unreachable_poses_are_nan_and_bad_poses_are_refused(tmp_path):
    graph = open_delta(tmp_path)
    home = graph.task_pose()
    result = graph_indices_at_poses(graph, np.array([home, home + [0.0, 0.0, -5.0], home + [0.01, 0.0, 0.0]]))
    assert result.reachable.tolist() == [True, False, True]
    assert np.isnan(result.lmti[1]) and np.isfinite(result.lmti[[0, 2]]).all()
    with pytest.raises(ValueError, match=r"Expected `poses` with shape \(\.\.\., 3\) for mechanism 'delta' "
                                         r"\(x, y, z\), got \(2, 6\)"):
        graph_indices_at_poses(graph, np.zeros((2, 6)))
    with pytest.raises(ValueError, match=r"Expected finite values in `poses`, got nan at index \(0, 0\)"):
        graph_indices_at_poses(graph, np.array([[np.nan, 0.0, 0.0]]))
    reach = 1e6 * graph.length_scale  # as a mechanism's poses are checked: positions within a million scales
    with pytest.raises(ValueError, match=r"Expected positions within 1e\+06 length scales .* of the home pose of "
                                         r"mechanism 'delta' in `poses` \(z, sample 1\), got -1e\+300 m"):
        graph_indices_at_poses(graph, np.array([home, home + [0.0, 0.0, -1e300]]))
    assert graph_indices_at_poses(graph, [home + [0.0, 0.0, -0.99 * reach]]).reachable.tolist() == [False]


def test_the_reach_bound_is_never_exceeded_and_a_straight_arm_meets_it(tmp_path):
    """No configuration puts the rod-level Delta's output frame farther from the world origin than the bound
    (Pinocchio's forward kinematics at random configurations, closures aside); a straight arm of two revolute
    joints and a slider at the end of its travel is exactly as far as the bound (the links' lengths plus the
    travel); a slider without limits, or any travel with the limits aside, or a free joint: no bound."""
    import pinocchio as pin

    graph = open_delta(tmp_path)
    model, frame = graph.tree.model, graph.tree.model.frames[graph.frame_id]
    bound = reach_bound(graph.kinematics, int(frame.parentJoint), homogeneous(frame.placement))
    data = model.createData()
    farthest = 0.0
    for q in random_configurations(model, 400, np.random.default_rng(4)):
        pin.framesForwardKinematics(model, data, q)
        farthest = max(farthest, float(np.linalg.norm(data.oMf[graph.frame_id].translation)))
    assert 0.5 * bound < farthest <= bound
    arm = """<robot name="arm"><link name="base"/><link name="a"/><link name="b"/><link name="c"/><link name="tip"/>
      <joint name="shoulder" type="revolute"><parent link="base"/><child link="a"/><origin xyz="0.1 0 0"/>
        <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
      <joint name="elbow" type="continuous"><parent link="a"/><child link="b"/><origin xyz="0.3 0.4 0"/>
        <axis xyz="0 0 1"/></joint>
      <joint name="slide" type="prismatic"><parent link="b"/><child link="c"/><origin xyz="0.2 0 0"/>
        <axis xyz="1 0 0"/><limit lower="-0.1" upper="0.25" effort="1" velocity="1"/></joint>
      <joint name="tool" type="fixed"><parent link="c"/><child link="tip"/><origin xyz="0 0 0.05"/></joint></robot>"""
    for root, expected in ((None, 0.1 + 0.5 + 0.2 + 0.25 + 0.05), (pin.JointModelFreeFlyer(), np.inf)):
        model = pin.buildModelFromXML(arm, root) if root is not None else pin.buildModelFromXML(arm)
        tip = model.getFrameId("tip")
        kinematics = TreeKinematics.of(model)
        joint, placement = int(model.frames[tip].parentJoint), homogeneous(model.frames[tip].placement)
        assert reach_bound(kinematics, joint, placement) == pytest.approx(expected, rel=1e-12)
        assert reach_bound(kinematics, joint, placement, limits=False) == np.inf
    model = pin.buildModelFromXML(arm)
    data, q = model.createData(), pin.neutral(model)
    # straight: the shoulder turns the 0.3 x 0.4 link onto x, the elbow turns back, the slider at its far end
    turn = np.arctan2(0.4, 0.3)
    q[model.idx_qs[model.getJointId("shoulder")]] = -turn
    elbow = model.idx_qs[model.getJointId("elbow")]
    q[elbow:elbow + 2] = np.cos(turn), np.sin(turn)
    q[model.idx_qs[model.getJointId("slide")]] = 0.25
    pin.framesForwardKinematics(model, data, q)
    distance = np.linalg.norm(data.oMf[model.getFrameId("tip")].translation)
    horizontal = 0.1 + 0.5 + 0.2 + 0.25
    assert distance == pytest.approx(np.hypot(horizontal, 0.05), abs=1e-12)  # the tool offset turns no further
    assert distance <= reach_bound(TreeKinematics.of(model), int(model.frames[model.getFrameId("tip")].parentJoint),
                                   homogeneous(model.frames[model.getFrameId("tip")].placement))


def test_a_position_beyond_reach_is_not_followed_and_unreached_as_the_continuation_finds(tmp_path, monkeypatch):
    """A target beyond the bound never enters the continuation (a path in millimetres read as metres took minutes
    there: 2 minutes for 75 m); just beyond it, the continuation followed all the way finds it unreached too."""
    graph = open_delta(tmp_path)
    home = graph.task_pose()
    asked = []
    solve = graph_kinematics._least_squares

    def recorded(residual, kinematics, q, target, iterations, tolerance):
        asked.append(np.abs(target[:, 2]).max())
        return solve(residual, kinematics, q, target, iterations, tolerance)

    monkeypatch.setattr(graph_kinematics, "_least_squares", recorded)
    bound = graph.reach()
    far, near = home + [0.0, 0.0, -75.0], home + [0.0, 0.0, -0.6]
    assert bound < np.linalg.norm(near) < 1.5 * bound
    q, reached = graph.solve(np.array([home, far, near]))
    assert reached.tolist() == [True, False, False] and max(asked) < 1.5 * bound
    np.testing.assert_array_equal(q[1], graph.q)  # left at the start
    monkeypatch.setattr(graph_kinematics, "beyond_reach", lambda *arguments, **options: np.zeros(1, dtype=bool))
    assert graph.solve(near[None])[1].tolist() == [False]  # followed all the way: unreached as well
    assert f"never farther than {bound:.4g} m from the world origin" in graph.unreachable(far)[1]


def test_what_is_beyond_reach_is_the_same_in_millimetres_in_another_frame_and_with_the_legs_reordered(tmp_path):
    """The bound is measured from the world origin, so moving, scaling or relabelling the file changes which poses
    it refuses without a continuation; what is reached does not change: poses near home, just out of reach, far out
    (refused at once) and 10,000 length scales away, the same answers in every copy, and the bound scales with it."""
    graph = open_delta(tmp_path)
    moves = np.array([[0.0, 0.0, 0.0], [0.02, -0.01, 0.03], [0.0, 0.0, -0.6], [0.9, 0.0, 0.0], [0.0, 0.0, -75.0],
                      [4e3, 0.0, 0.0]])
    reference = graph.solve(graph.task_pose() + moves)[1]
    assert reference.tolist() == [True, True, False, False, False, False]
    rotation = random_rotation(np.random.default_rng(13))
    for scale, turn, shift in ((1e-3, rotation, np.array([0.01, 0.0, -0.02])), (1e3, np.eye(3), np.zeros(3)),
                               (1.0, rotation, np.array([0.3, -1.2, 2.0]))):
        moved = open_delta(tmp_path, transform=(scale, turn, shift), name="moved.xml")
        assert moved.solve(moved.task_pose() + scale * moves @ turn.T)[1].tolist() == reference.tolist()
        if not shift.any():
            assert moved.reach() == pytest.approx(scale * graph.reach(), rel=1e-12)
    relabelled = open_delta(tmp_path, azimuths=AZIMUTHS[[2, 0, 3, 1]], name="relabelled.xml")
    assert relabelled.solve(relabelled.task_pose() + moves)[1].tolist() == reference.tolist()


def test_the_command_refuses_a_pose_beyond_reach_in_one_line():
    one_line_error(screwkit("analyze", "delta_rods_4", "--pose", "0 0 -750"), "delta_rods_4",
                   "(x=0, y=0, z=-750): it is never farther than 1.416 m from the world origin")
    one_line_error(screwkit("analyze", "delta_rods_4", "--pose", "0 0 -750 0 0 0"), "delta_rods_4",
                   "[0.0, 0.0, -750.0] m", "out of reach: the output frame is never farther than 1.416 m from the "
                   "world origin")  # the frame's whole pose


def test_a_stewart_platform_through_the_graph_moves_in_six_coordinates():
    """Its task coordinates are the frame's six; a batch of small moves gives the indices of each pose alone (the
    file's joint limits ignored: some of these moves turn a passive joint written with limits 0..2 pi below 0, and
    then neither path reaches them)."""
    graph = graph_mechanism(read_mjcf(GALLERY / "stewart_cad.xml"))
    assert graph.task_coordinates == ("x", "y", "z", "roll", "pitch", "yaw")
    home = graph.task_pose()
    moves = np.random.default_rng(10).uniform(-1.0, 1.0, (6, 6)) * np.array([0.01] * 3 + [0.05] * 3)
    result = graph_indices_at_poses(graph, home + moves, limits=False)
    assert result.reachable.all()
    limited = graph_indices_at_poses(graph, home + moves)
    for k in range(6):
        alone = graph.at_pose(home[:3] + moves[k, :3], home[3:] + moves[k, 3:], limits=False).indices()
        np.testing.assert_allclose([result.lmti[k], result.iti[k]], [alone.lmti, alone.iti], atol=1e-12)
        if not limited.reachable[k]:
            with pytest.raises(ValueError, match="a joint beyond its limits"):
                graph.at_pose(home[:3] + moves[k, :3], home[3:] + moves[k, 3:])
    assert not limited.reachable.all()


def test_a_sweep_of_a_graph_gives_the_textbook_pressure_angles_along_it(tmp_path):
    graph = open_delta(tmp_path)
    home = graph.task_pose()
    heights = np.linspace(home[2] - 0.08, home[2] + 0.08, 9)
    dataset = sweep(graph, home, "z", heights)
    for k, z in enumerate(heights):
        expected = textbook(np.add(POSES[0], [0.0, 0.0, z - home[2]]))
        np.testing.assert_allclose(dataset["lmti"].values[k], expected["lmti"], atol=TOLERANCE)
        np.testing.assert_allclose(dataset["f_o1"].values[k], expected["f_o1"], atol=TOLERANCE)
        np.testing.assert_allclose(dataset["iti_actuator"].values[k], expected["iti"], atol=TOLERANCE)
    with pytest.raises(ValueError, match="no closed forms, no link faults"):
        sweep(graph, home, "z", heights, closed_forms=True)


def test_link_faults_of_a_graph_are_refused_naming_what_it_has_in_the_api_and_on_the_command_line(tmp_path):
    """``analyze FILE --fault link`` said "`iti_points` and `oti_points` apply to free-swinging faults only", options
    the user never gave; ``graph.indices(fault_type="link")`` said the same."""
    graph = open_delta(tmp_path)
    message = "a mechanism whose legs have loops inside them is analysed by the generic screw path with " \
              "free-swinging faults (no closed forms, no link faults)"
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace(")", r"\)")):
        graph.indices(fault_type="link")
    path = tmp_path / "delta.xml"
    path.write_text(delta_rods_mjcf(POSES[0], AZIMUTHS))
    for extra in ((), ("--pose", "0.02 -0.03 -0.45"), ("--json",)):
        refused = screwkit("analyze", path, "--fault", "link", *extra)
        if extra == ("--json",):
            assert refused.returncode == 1 and message in json.loads(refused.stdout)["error"], refused.stdout
        else:
            one_line_error(refused, message)


def test_the_command_line_sweeps_a_rod_level_delta_as_written(tmp_path):
    """``screwkit sweep FILE --sweep z:...`` on the file as written: the textbook indices at every height, in the
    netCDF it writes; a coordinate the platform does not have, and closed forms, refused in one line."""
    import xarray as xr

    path = tmp_path / "delta.xml"
    path.write_text(delta_rods_mjcf(POSES[0], AZIMUTHS))
    home = open_delta(tmp_path).task_pose()
    out = tmp_path / "sweep.nc"
    low, high = float(home[2]) - 0.06, float(home[2]) + 0.06
    completed = screwkit("sweep", path, "--sweep", f"z:{low!r}:{high!r}:0.02", "--out", out)
    assert completed.returncode == 0, completed.stderr
    assert "swept z over 6 values (6 reachable)" in completed.stderr and "Traceback" not in completed.stderr
    with xr.open_dataset(out) as dataset:
        for k, z in enumerate(dataset["z"].values):
            expected = textbook(np.add(POSES[0], [0.0, 0.0, z - home[2]]))
            np.testing.assert_allclose(dataset["lmti"].values[k], expected["lmti"], atol=TOLERANCE)
    one_line_error(screwkit("sweep", path, "--sweep", "yaw:0:10:1"), "Unknown coordinate 'yaw'", "has x, y, z")
    one_line_error(screwkit("sweep", path, "--sweep", "z:-0.5:-0.4:0.05", "--closed-forms"), "no closed forms")


def test_a_map_of_a_graph_is_the_textbook_indices_at_every_grid_point(tmp_path):
    """index_map of the rod-level Delta over x, y at the file's height: each point's indices are the textbook
    pressure angles there (one orientation: a Delta's platform does not turn)."""
    graph = open_delta(tmp_path)
    home = graph.task_pose()
    xs, ys = home[0] + np.array([-0.04, 0.0, 0.05]), home[1] + np.array([-0.03, 0.02])
    dataset = index_map(graph, {"x": xs, "y": ys}, {})
    for row, y in enumerate(ys):
        for column, x in enumerate(xs):
            expected = textbook(np.add(POSES[0], [x - home[0], y - home[1], 0.0]))
            np.testing.assert_allclose(dataset["lmti"].values[row, column], expected["lmti"], atol=TOLERANCE)
            np.testing.assert_allclose(dataset["f_o1"].values[row, column], expected["f_o1"], atol=TOLERANCE)
    assert (dataset["reachable_fraction"].values == 1.0).all()


def test_a_map_task_rebuilds_the_graph_from_its_file_and_refuses_a_changed_file(tmp_path):
    graph = open_delta(tmp_path)
    source = graph_source(graph)
    rebuilt = cached_graph(source)
    np.testing.assert_array_equal(rebuilt.q, graph.q)
    path = tmp_path / "delta.xml"
    path.write_text(path.read_text() + "\n")
    cached_graph.cache_clear()
    with pytest.raises(ValueError, match=r"delta\.xml: the file changed while the map was computed"):
        cached_graph(source)
    path.unlink()
    with pytest.raises(ValueError, match=r"delta\.xml: cannot be read where the map's task runs"):
        cached_graph(source)


def test_info_says_what_was_inferred_of_a_graph(tmp_path):
    """``screwkit info FILE``: the task coordinates inferred from the motion space, the platform, the legs with their
    joints, closures and solver, and the import report; as a subprocess."""
    path = tmp_path / "delta.xml"
    path.write_text(delta_rods_mjcf(POSES[0], AZIMUTHS))
    completed = screwkit("info", path)
    assert completed.returncode == 0, completed.stderr
    text = completed.stdout
    assert "DOF 3; task coordinates: x (m), y (m), z (m) (inferred from the motion space)" in text
    assert "platform 'platform' on 'platform_ball'" in text and "4 actuators: arm_1:motor_1" in text
    assert "arm_2: motor_2 - ball_2a - ball_2b (actuated: motor_2); loop rod_2a_end, rod_2b_end (graph)" in text
    assert "named poses" not in text and "Traceback" not in completed.stderr
