"""The bundled robots, loading by name or path, and what a bad file produces."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

from helpers import bundled, screwkit
from screwkit.closure import chain_screws, solve, solve_one
from screwkit.closure.chain_kinematics import chain_forward_kinematics
from screwkit.io.loader import bundled_names, bundled_path, load
from screwkit.model.pinocchio_bridge import configuration_vector
from screwkit.screw.chain_screws import ChainScrews

BUNDLED = ("coop_arms", "delta_4", "five_bar", "five_bar_3", "planar_4rpr", "planar_5rrr", "prs_3_ups",
           "rss_hexapod_8", "schoenflies_5", "ups_hexapod_8", "ups_stewart_6")


mechanism = bundled  # one load per test process


def bundled_text(name: str) -> str:
    return bundled_path(name).read_text()


def write(tmp_path: Path, text: str, name: str = "changed.urdf") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def test_bundled_names_and_unknown_names():
    assert bundled_names() == BUNDLED
    with pytest.raises(ValueError, match=r"Unknown bundled mechanism 'planar_6rrr'; bundled are: coop_arms, delta_4"):
        load("planar_6rrr")
    with pytest.raises(ValueError, match=r"missing\.urdf: no such file \(bundled mechanisms are: coop_arms"):
        load("somewhere/missing.urdf")


def test_loading_by_path_equals_loading_by_name(tmp_path):
    by_path = load(write(tmp_path, bundled_text("planar_5rrr")))
    by_name = mechanism("planar_5rrr")
    assert by_path.actuators == by_name.actuators
    for first, second in zip(by_path.chains, by_name.chains):
        assert (first.name, first.joint_names, first.solver, first.branch) == (second.name, second.joint_names,
                                                                              second.solver, second.branch)
        np.testing.assert_array_equal(first.reference_values, second.reference_values)
    np.testing.assert_array_equal(by_path.home_pose, by_name.home_pose)
    assert by_path.named_poses.keys() == by_name.named_poses.keys()


def test_generator_reproduces_the_committed_files(tmp_path):
    from screwkit.robots.generate import main

    main([str(tmp_path)])
    number = re.compile(r"-?\d+(?:\.\d+)?(?:e-?\d+)?")
    for name in BUNDLED:
        written, committed = (tmp_path / f"{name}.urdf").read_text(), bundled_text(name)
        # The same text but for the last bits of computed numbers (libm and BLAS round differently by machine).
        assert number.sub("#", written) == number.sub("#", committed), name
        np.testing.assert_allclose([float(x) for x in number.findall(written)],
                                   [float(x) for x in number.findall(committed)], rtol=1e-13, atol=1e-15, err_msg=name)
    from screwkit.io.loader import bundled_graph_names, bundled_path

    assert bundled_graph_names() == ("delta_rods_4",)
    for name in bundled_graph_names():
        written, committed = (tmp_path / f"{name}.xml").read_text(), bundled_path(name).read_text()
        assert number.sub("#", written) == number.sub("#", committed), name
        np.testing.assert_allclose([float(x) for x in number.findall(written)],
                                   [float(x) for x in number.findall(committed)], rtol=1e-13, atol=1e-15, err_msg=name)


# -- planar 5-RRR: the paper's Table 2 -----------------------------------------------------


def test_five_rrr_follows_table_2():
    five = mechanism("planar_5rrr")
    assert five.is_planar and five.dof == 3 and five.task_coordinates == ("x", "y", "phi")
    np.testing.assert_array_equal(five.home_pose, [0.0, 0.0, 0.0])
    assert [chain.name for chain in five.chains] == [f"chain_{i}" for i in range(1, 6)]
    assert five.actuators == tuple((f"chain_{i}", f"chain_{i}_joint_b") for i in range(1, 6))
    assert all(chain.actuated == (0,) and chain.solver == "planar_rrr" for chain in five.chains)
    gamma = 2 * math.pi / 5
    for pose in ([0.0, 0.0, 0.0], [0.1, -0.05, 0.3]):
        solution = solve_one(five, pose)
        screws = chain_screws(five, solution)
        phi = pose[2]
        rotation = np.array([[math.cos(phi), -math.sin(phi)], [math.sin(phi), math.cos(phi)]])
        for i, screws_i in enumerate(screws):
            assert isinstance(screws_i, ChainScrews) and screws_i.actuated == (0,)
            b, c, d = screws_i.points[:, :2]
            np.testing.assert_allclose(b, [math.cos(i * gamma), math.sin(i * gamma)], atol=1e-15)
            platform_joint = 0.1 * np.array([math.cos(3 * i * gamma), math.sin(3 * i * gamma)])
            np.testing.assert_allclose(d, np.asarray(pose[:2]) + rotation @ platform_joint, atol=1e-14)
            assert abs(np.linalg.norm(c - b) - 1.0) < 1e-14 and abs(np.linalg.norm(d - c) - 1.0) < 1e-14
            u = (d - b) / np.linalg.norm(d - b)
            assert (c - b) @ np.array([-u[1], u[0]]) > 0.0  # elbow on the +u_perp side
            np.testing.assert_allclose(screws_i.twists[:, :3], np.tile([0, 0, 1.0], (3, 1)), atol=0)


def test_five_rrr_named_poses_are_reachable():
    five = mechanism("planar_5rrr")
    assert set(five.named_poses) == {"home", "paper_fig_2a"}
    np.testing.assert_allclose(five.named_pose("paper_fig_2a"), [-0.2, 0.0, math.pi / 4], atol=0)
    for pose in five.named_poses.values():
        assert solve_one(five, pose).reachable


# -- planar 4-RPR --------------------------------------------------------------------------


def _line_distance(point, start, end):
    direction = (end - start) / np.linalg.norm(end - start)
    offset = point - start
    return abs(offset[0] * direction[1] - offset[1] * direction[0])


def test_four_rpr_has_a_pose_where_three_leg_lines_meet():
    four = mechanism("planar_4rpr")
    assert four.dof == 3 and len(four.actuators) == 4
    assert all(chain.actuated == (1,) and chain.prismatic == (False, True, False) for chain in four.chains)
    assert all(chain.solver == "planar_rpr" for chain in four.chains)
    solution = solve_one(four, four.named_pose("three_lines_concurrent"))
    legs = [(points[0, :2], points[2, :2]) for points in solution.joint_points]
    (b1, d1), (b2, d2) = legs[0], legs[1]
    matrix = np.column_stack([d1 - b1, b2 - d2])
    point = b1 + np.linalg.solve(matrix, b2 - b1)[0] * (d1 - b1)
    assert _line_distance(point, *legs[2]) < 1e-12
    assert _line_distance(point, *legs[3]) > 0.2
    at_home = solve_one(four, four.home_pose)
    home_legs = [(points[0, :2], points[2, :2]) for points in at_home.joint_points]
    matrix = np.column_stack([home_legs[0][1] - home_legs[0][0], home_legs[1][0] - home_legs[1][1]])
    along = np.linalg.solve(matrix, home_legs[1][0] - home_legs[0][0])[0]
    home_point = home_legs[0][0] + along * (home_legs[0][1] - home_legs[0][0])
    assert _line_distance(home_point, *home_legs[2]) > 0.05


def test_four_rpr_slider_twists_are_along_the_legs():
    four = mechanism("planar_4rpr")
    solution = solve(four, four.home_pose + [[0.1, -0.2, 0.3]])
    for screws, points in zip(chain_screws(four, solution), solution.joint_points):
        leg = points[0, 2] - points[0, 0]
        np.testing.assert_allclose(screws.twists[0, 1, :3], 0.0)
        np.testing.assert_allclose(screws.twists[0, 1, 3:], leg / np.linalg.norm(leg), atol=1e-14)


# -- hexapods ------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("name", "kind", "actuated", "line_start", "worst"),
    [("ups_hexapod_8", "ups", (2,), 0, 0.0702), ("rss_hexapod_8", "rus", (0,), 1, 0.0466)],
)
def test_hexapods_have_eight_legs_and_no_singular_six_leg_submechanism_at_home(name, kind, actuated, line_start, worst):
    hexapod = mechanism(name)
    assert hexapod.dof == 6 and len(hexapod.chains) == 8 and len(hexapod.actuators) == 8
    assert all(chain.solver == kind and chain.actuated == actuated and chain.n_joints == 6 for chain in hexapod.chains)
    solution = solve_one(hexapod, hexapod.home_pose)
    starts = np.array([points[line_start] for points in solution.joint_points])
    ends = np.array([points[-1] for points in solution.joint_points])
    directions = (ends - starts) / np.linalg.norm(ends - starts, axis=-1, keepdims=True)
    lines = np.concatenate([directions, np.cross(ends, directions) / 0.5], -1)
    import itertools

    smallest = min(np.linalg.svd(lines[list(subset)], compute_uv=False)[-1]
                   for subset in itertools.combinations(range(8), 6))
    assert abs(smallest - worst) < 1e-3


# -- cooperative arms ----------------------------------------------------------------------


def test_cooperative_arms_are_two_example_robot_data_ur5():
    import pinocchio

    from screwkit.robots.generate import UR5_JOINTS, example_robot_data_ur5

    arms = mechanism("coop_arms")
    assert arms.dof == 6 and len(arms.actuators) == 12 and not arms.is_planar
    assert [chain.name for chain in arms.chains] == ["left_arm", "right_arm"]
    for side, chain in zip(("left", "right"), arms.chains):
        assert chain.joint_names == tuple(f"{side}_{name}" for name in UR5_JOINTS) and chain.actuated == tuple(range(6))
        assert chain.loop_type == "fixed"
    ur5 = pinocchio.buildModelFromUrdf(str(example_robot_data_ur5()))
    ur5_data = ur5.createData()
    data = arms.pinocchio_model.createData()
    rng = np.random.default_rng(20)
    for _ in range(5):
        values = rng.uniform(-np.pi, np.pi, 6)
        configuration = configuration_vector(arms, [values, values])
        pinocchio.framesForwardKinematics(arms.pinocchio_model, data, configuration)
        pinocchio.framesForwardKinematics(ur5, ur5_data, values)
        for side in ("left", "right"):
            base = data.oMf[arms.pinocchio_model.getFrameId(f"{side}_base_link")]
            tool = data.oMf[arms.pinocchio_model.getFrameId(f"{side}_tool0")]
            expected = ur5_data.oMf[ur5.getFrameId("base_link")].inverse() * ur5_data.oMf[ur5.getFrameId("tool0")]
            np.testing.assert_allclose((base.inverse() * tool).homogeneous, expected.homogeneous, atol=1e-12)


# -- frame invariance: a planar mechanism moved and tilted in 3-D --------------------------


def test_tilted_planar_mechanism_gives_the_same_relative_geometry(tmp_path):
    from scipy.spatial.transform import Rotation

    xyz, rpy = np.array([0.3, -0.2, 0.5]), np.array([0.4, -0.3, 0.7])
    text = bundled_text("planar_5rrr").replace(
        '<link name="base_link">',
        '<link name="world"/>\n  <joint name="world_to_base" type="fixed">'
        '<parent link="world"/><child link="base_link"/>'
        f'<origin xyz="{xyz[0]} {xyz[1]} {xyz[2]}" rpy="{rpy[0]} {rpy[1]} {rpy[2]}"/></joint>\n'
        '  <link name="base_link">',
        1,
    )
    tilted = load(write(tmp_path, text))
    flat = mechanism("planar_5rrr")
    assert tilted.dof == flat.dof and tilted.is_planar
    assert [(c.name, c.joint_names, c.solver, c.branch) for c in tilted.chains] == \
        [(c.name, c.joint_names, c.solver, c.branch) for c in flat.chains]
    np.testing.assert_allclose(tilted.home_pose, flat.home_pose, atol=1e-14)
    rotation = Rotation.from_euler("xyz", rpy).as_matrix()
    np.testing.assert_allclose(tilted.rotation_world_base, rotation, atol=1e-14)
    poses = flat.home_pose + np.random.default_rng(21).uniform(-0.3, 0.3, (40, 3))
    for method in ("auto", "newton"):
        tilted_solution, flat_solution = solve(tilted, poses, method=method), solve(flat, poses, method=method)
        np.testing.assert_array_equal(tilted_solution.reachable, flat_solution.reachable)
        for first, second in zip(tilted_solution.joint_values, flat_solution.joint_values):
            np.testing.assert_allclose(first, second, atol=1e-10)
    tilted_solution, flat_solution = solve(tilted, poses), solve(flat, poses)
    for in_base, flat_screws, in_world in zip(
        chain_screws(tilted, tilted_solution, frame="base"),
        chain_screws(flat, flat_solution),
        chain_screws(tilted, tilted_solution),
    ):
        np.testing.assert_allclose(in_base.twists, flat_screws.twists, atol=1e-13)
        np.testing.assert_allclose(in_world.points, flat_screws.points @ rotation.T + xyz, atol=1e-13)
        omega = flat_screws.twists[..., :3] @ rotation.T
        np.testing.assert_allclose(in_world.twists[..., :3], omega, atol=1e-13)
        expected_moment = flat_screws.twists[..., 3:] @ rotation.T + np.cross(xyz, omega)
        np.testing.assert_allclose(in_world.twists[..., 3:], expected_moment, atol=1e-13)


# -- bad files -----------------------------------------------------------------------------


def _replace(text: str, pattern: str, replacement: str, count: int = 1) -> str:
    changed, done = re.subn(pattern, replacement, text, count=count, flags=re.S)
    assert done, pattern
    return changed


@pytest.mark.parametrize(
    ("name", "change", "message"),
    [
        (
            "planar_5rrr",
            lambda text: _replace(text, r'(<successor link="platform">\s*<origin xyz=")0\.1 ', r"\g<1>5.1 "),
            r"<loop name='chain_1_joint_d'>: does not close at the reference configuration: the loop frames are 5 m "
            r"and 0 rad apart .*, and moving the chain's joints leaves them 2\.1 \(m and rad\) apart",
        ),
        ("planar_5rrr", lambda text: re.sub(r"<transmission.*?</transmission>", "", text, flags=re.S), "no actuators"),
        (
            "planar_5rrr",
            lambda text: _replace(text, r'<successor link="platform">', '<successor link="chain_2_link_a">'),
            r"<loop name='chain_1_joint_d'>: chain has no path to the platform: neither 'chain_1_link_l' nor "
            r"'chain_2_link_a' is the platform link 'platform'",
        ),
        (
            "planar_5rrr",
            lambda text: _replace(text, r'<predecessor link="chain_1_link_l">', '<predecessor link="chain_1_elbow">'),
            r"<loop name='chain_1_joint_d'>: <predecessor> names an unknown link 'chain_1_elbow'",
        ),
        ("planar_5rrr", lambda text: text.replace("</robot>", "</robo>"), "malformed XML: mismatched tag"),
        ("planar_5rrr", lambda text: _replace(text, 'type="planar"', 'type="fixed"'),
         "exactly one floating or planar joint"),
        (
            "planar_5rrr",
            lambda text: _replace(text, '<joint name="chain_1_joint_b">', '<joint name="chain_9_joint_b">'),
            r"<transmission name='chain_1_joint_b_transmission'>: names an unknown joint 'chain_9_joint_b'",
        ),
        (
            "planar_5rrr",
            lambda text: _replace(text, '<joint name="chain_1_joint_b">', '<joint name="platform_joint">'),
            "drives joint 'platform_joint', which is in no chain from the base to the platform",
        ),
        (
            "planar_5rrr",
            lambda text: _replace(text, r'<predecessor link="chain_2_link_l">', '<predecessor link="chain_1_link_l">'),
            "its chain shares the joint 'chain_1_joint_b' with the chain of loop 'chain_1_joint_d'",
        ),
        (
            "planar_5rrr",
            lambda text: _replace(text, r'(name="chain_2_joint_c".*?<axis xyz=")0 0 1"', r'\g<1>0 1 0"', count=1),
            "joint 'chain_2_joint_c' of this chain is not a planar joint",
        ),
        (
            "coop_arms",
            lambda text: _replace(text, '<joint name="left_elbow_joint" value', '<joint name="left_elbow" value'),
            r"<reference_configuration><joint name='left_elbow'>: names no tree joint",
        ),
    ],
)
def test_bad_files_raise_one_line_errors_naming_file_element_and_problem(tmp_path, name, change, message):
    path = write(tmp_path, change(bundled_text(name)), "bad.urdf")
    with pytest.raises(ValueError) as error:
        load(path)
    text = str(error.value)
    assert text.startswith(f"{path}: "), text
    assert re.search(message, text), text
    assert "\n" not in text


def test_a_loop_left_open_by_the_file_is_closed_at_loading_and_said(tmp_path):
    """A loop the file's joint values leave open (0.1 m here) is closed by moving its chain's joints, the platform
    where the file puts it; the indices are those of the closed file, and convert writes the closure back."""
    text = _replace(bundled_text("planar_5rrr"), r'(<successor link="platform">\s*<origin xyz=")0\.1 ', r"\g<1>0.2 ")
    opened = load(write(tmp_path, text, "open.urdf"))
    assert len(opened.assembly_notes) == 1 and opened.assembly_notes[0].startswith(
        "loop 'chain_1_joint_d' was 0.1 m and 0 rad open at the file's joint values: closed by moving the joints of "
        "chain 'chain_1' (most: ")
    frames = chain_forward_kinematics(opened.chains[0].geometry, opened.chains[0].reference_values)
    target_rotation, target_translation = opened.loop_targets(0, opened.home_rotation, opened.home_translation)
    np.testing.assert_allclose(frames.end_translation, target_translation, atol=1e-10)
    np.testing.assert_allclose(frames.end_rotation, target_rotation, atol=1e-10)
    assert mechanism("planar_5rrr").assembly_notes == ()
    out = tmp_path / "closed.urdf"
    result = screwkit("convert", tmp_path / "open.urdf", out)
    assert result.returncode == 0, result.stderr
    assert "closed by moving the joints of chain 'chain_1'" in result.stderr
    closed = load(out)
    assert closed.assembly_notes == ()  # the reference configuration written back closes the loop
    for first, second in zip(opened.chains, closed.chains):
        np.testing.assert_allclose(second.reference_values, first.reference_values, atol=1e-12)


def test_every_command_says_in_one_line_that_a_file_was_opened_closed(tmp_path):
    """A typo in a link length leaves a loop open: each command analyses the closed mechanism and says so in one
    line on stderr (which loop, how far, which joint moved most), not silently; --quiet silences it."""
    text = _replace(bundled_text("planar_5rrr"), r'(<child link="chain_1_link_l" />\s*<origin xyz=")1 ', r"\g<1>1.05 ")
    path = write(tmp_path, text, "typo.urdf")
    commands = [("info",), ("analyze",), ("analyze", "--json"),
                ("sweep", "--phi", "0:30:10", "--out", tmp_path / "s.nc"),
                ("map", "--radius", "0.05", "--step", "0.05", "--phi-step", "30", "--out", tmp_path / "m.nc"),
                ("view", "--html", tmp_path / "v.html"), ("verify", "--samples", "20")]
    for command, *options in commands:
        result = screwkit(command, path, *options)
        assert result.returncode == 0, result.stderr
        said = [line for line in result.stderr.splitlines() if "were closed at loading" in line]
        assert len(said) == 1 and "loop 'chain_1_joint_d' was 0.05 m and 0 rad open" in said[0], result.stderr
        assert "(most: 'chain_1_joint_d' by " in said[0]
    quiet = screwkit("sweep", path, "--phi", "0:30:10", "--out", tmp_path / "q.nc", "--quiet")
    assert quiet.returncode == 0 and quiet.stderr == ""


def test_an_absurd_number_in_a_file_is_one_line_naming_the_element(tmp_path):
    text = bundled_text("planar_5rrr").replace('<origin xyz="1 0 0" rpy="0 0 -2.037561665842193" />',
                                               '<origin xyz="1e308 0 0" rpy="0 0 -2.037561665842193" />', 1)
    result = screwkit("analyze", write(tmp_path, text, "absurd.urdf"))
    assert result.returncode == 1 and result.stderr.count("\n") == 1
    assert "<joint name='chain_1_joint_b'><origin>: 'xyz' = '1e308 0 0' is absurd for a robot" in result.stderr


def test_the_chain_attribute_names_the_chain_and_defaults_to_the_loop_name(tmp_path):
    text = bundled_text("planar_5rrr").replace(' chain="chain_1"', "")
    renamed = load(write(tmp_path, text))
    assert renamed.chains[0].name == "chain_1_joint_d" and renamed.chains[1].name == "chain_2"
    assert renamed.actuators[0] == ("chain_1_joint_d", "chain_1_joint_b")


def test_a_loop_written_from_the_platform_side_is_the_same_chain(tmp_path):
    """Swapping predecessor and successor of a loop changes nothing: values are measured leg to platform."""
    text = bundled_text("planar_5rrr")
    match = re.search(r'<loop name="chain_2_joint_d".*?</loop>', text, flags=re.S)
    loop = match.group(0)
    predecessor = re.search(r"<predecessor .*?</predecessor>", loop, flags=re.S).group(0)
    successor = re.search(r"<successor .*?</successor>", loop, flags=re.S).group(0)
    swapped = loop.replace(predecessor, "@P@").replace(successor, predecessor.replace("predecessor", "successor"))
    swapped = swapped.replace("@P@", successor.replace("successor", "predecessor"))
    reversed_mechanism = load(write(tmp_path, text.replace(loop, swapped)))
    five = mechanism("planar_5rrr")
    poses = five.home_pose + np.random.default_rng(22).uniform(-0.3, 0.3, (20, 3))
    first, second = solve(five, poses), solve(reversed_mechanism, poses)
    for one, other in zip(chain_screws(five, first), chain_screws(reversed_mechanism, second)):
        np.testing.assert_allclose(one.twists, other.twists, atol=1e-14)
    np.testing.assert_allclose(first.joint_values[1], second.joint_values[1], atol=1e-12)


def test_a_file_written_to_six_decimals_keeps_its_closed_forms(tmp_path):
    """Closure tolerance and closed-form recognition agree (both 1e-6): rounding the file to 6 decimals
    changes the geometry by about 1e-7, which both accept, so every chain keeps its closed form."""
    for name in ("planar_5rrr", "ups_hexapod_8", "rss_hexapod_8"):
        text = re.sub(r"-?\d+\.\d{7,}", lambda match: f"{float(match.group()):.6f}", bundled_text(name))
        assert text != bundled_text(name)
        rounded, exact = load(write(tmp_path, text, f"{name}_6.urdf")), mechanism(name)
        assert [chain.solver for chain in rounded.chains] == [chain.solver for chain in exact.chains]
        assert all(chain.solver != "newton" for chain in rounded.chains)
        poses = exact.home_pose + np.random.default_rng(3).uniform(-1, 1, (50, exact.n_task)) * (
            [0.2, 0.2, 0.5] if exact.is_planar else [0.03, 0.03, 0.03, 0.05, 0.05, 0.1])
        first, second = solve(exact, poses), solve(rounded, poses)
        assert first.reachable.all() and second.reachable.all()
        from screwkit.indices.analysis import analyze

        one, two = analyze(chain_screws(exact, first)), analyze(chain_screws(rounded, second))
        np.testing.assert_allclose(two.iti_actuators, one.iti_actuators, atol=1e-5)
        np.testing.assert_allclose(two.oti_submechanisms, one.oti_submechanisms, atol=1e-4)
