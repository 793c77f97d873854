"""SDFormat models (``.sdf``) whose loops are native joints, opened as written (tests/sdformat_models.py writes them).

No SDFormat library installs from pip on this platform (``sdformat14-py-bindings`` installs but its extension needs
``libsdformat14.so.14`` and ``libgz-math7.so.7``, which it does not ship; ``sdformat-mjcf`` imports ``sdformat13``,
which pip does not have), so the poses screwkit reads are checked against poses computed from the geometry by hand
(the five-bar) and against MuJoCo's reading of the same Delta written in MJCF (tests/delta_rods.py). The indices are
the textbook pressure angles: the five-bar's (tests/test_lower_mobility.py) leg by leg, in another unit and world
frame, legs reversed and motors renamed; the rod-level Delta's (tests/test_graph_legs.py), through the graph path.
"""

from __future__ import annotations

import json
import re

import numpy as np
import pytest
from delta_rods import SPACING, delta_geometry, delta_rods_mjcf
from sdformat_models import delta_sdf, five_bar_sdf, five_bar_world_poses, hexapod_sdf, rss_sdf
from test_graph_legs import POSES, assert_delta_textbook, textbook
from test_io import HOME, assert_textbook, poses_near_home
from test_lower_mobility import five_bar_expected
from test_onshape import MOVED, assert_moved_textbook

from helpers import one_line_error, random_rotation, screwkit
from screwkit.io import ImportError_, LegWithLoops, graph_mechanism, is_foreign, read_closed_tree, read_mechanism_file
from screwkit.io.closed_tree import closure_gaps
from screwkit.io.loader import load
from screwkit.io.sdformat_text import read_model, world_poses
from screwkit.studies.poses import indices_at_poses

TOLERANCE = 1e-9


def write(tmp_path, text: str, name: str = "robot.sdf"):
    path = tmp_path / name
    path.write_text(text)
    return path


def frame_poses(tree) -> dict[str, np.ndarray]:
    """Every frame of screwkit's Pinocchio model in the world at the file's configuration (4x4)."""
    import pinocchio as pin

    data = tree.model.createData()
    pin.framesForwardKinematics(tree.model, data, tree.q_reference)
    return {frame.name: data.oMf[k].homogeneous for k, frame in enumerate(tree.model.frames)}


@pytest.mark.parametrize("marker", ["screwkit", "plugin", ""])
def test_a_five_bar_written_in_sdformat_opens_as_written_with_the_textbook_pressure_angles(tmp_path, marker):
    path = write(tmp_path, five_bar_sdf(marker=marker))
    assert is_foreign(path)
    converted, report = read_mechanism_file(path)
    assert report.file_format == "SDFormat (joints closing loops)" and report.planar
    assert report.motors == ["mot1", "mot2", "mot3"]
    assert sum("the hinge through them" in note for note in report.notes) == 2, report.notes
    assert any("actuators guessed" in note for note in report.notes) is (marker == "")
    mechanism = load(path)
    assert mechanism.is_planar and mechanism.dof == 2 and len(mechanism.actuators) == 3
    points = poses_near_home()
    assert_textbook(indices_at_poses(mechanism, points, detail=True), points)


@pytest.mark.parametrize("transform", MOVED)
def test_an_sdformat_five_bar_in_another_unit_and_frame_with_its_legs_reversed_and_motors_renamed(tmp_path, transform):
    """Scaled by 1e-3 and 1e3, turned and shifted in the world by the model's pose (in degrees), legs written in
    reverse and motors renamed: the same pressure angles, each following its own leg."""
    names = {0: "drive_c", 1: "drive_a", 2: "drive_b"}
    path = write(tmp_path, five_bar_sdf(transform, order=(2, 1, 0), motor=names.get))
    mechanism = load(path)
    assert mechanism.is_planar
    assert sorted(name.split(":")[-1] for name in mechanism.actuator_names) == ["drive_a", "drive_b", "drive_c"]
    assert_moved_textbook(mechanism, transform, {name: leg for leg, name in names.items()}.get)


@pytest.mark.parametrize("transform", [(1.0, 0.0, (0.0, 0.0, 0.0)), *MOVED])
def test_the_five_bar_s_links_and_joints_are_where_the_geometry_puts_them(tmp_path, transform):
    """Links, by the geometry computed by hand (not through the file's chain of relative_to poses); joints where
    SDFormat puts them (the child link's frame, turned as the file says); each loop joint's two sides coincide."""
    path = write(tmp_path, five_bar_sdf(transform, order=(2, 1, 0)))
    tree = read_closed_tree(path)
    read = frame_poses(tree)
    expected = five_bar_world_poses(transform)
    resolved = world_poses(read_model(path))
    for name, pose in expected.items():
        np.testing.assert_allclose(read[name], pose, atol=TOLERANCE * transform[0], rtol=0, err_msg=name)
        np.testing.assert_allclose(resolved[name], pose, atol=TOLERANCE * transform[0], rtol=0, err_msg=name)
    for i in range(3):  # motors at the proximal links' origins (their own frames); loop joints at the effector's
        np.testing.assert_allclose(read[f"mot{i + 1}"], expected[f"proximal_{i + 1}"], atol=TOLERANCE * transform[0])
        np.testing.assert_allclose(resolved[f"loop_{i + 1}"][:3, 3], expected["effector"][:3, 3],
                                   atol=TOLERANCE * transform[0])
    import pinocchio as pin

    data = tree.model.createData()
    pin.forwardKinematics(tree.model, data, tree.q_reference)
    for closure in tree.closures:
        a = data.oMi[closure.joint_a].homogeneous @ closure.placement_a
        b = data.oMi[closure.joint_b].homogeneous @ closure.placement_b
        np.testing.assert_allclose(a, b, atol=TOLERANCE * transform[0], err_msg=closure.name)


@pytest.mark.parametrize("placed", [False, True])
def test_the_delta_s_links_are_where_mujoco_puts_the_same_delta_written_in_mjcf(tmp_path, placed):
    """The rod-level Delta written in both formats, its base turned and moved (or not): every link of the SDFormat
    file where MuJoCo puts the body of that name, and the frame ``centre`` where the MJCF's site is."""
    import mujoco

    transform = (1.0, random_rotation(np.random.default_rng(6)), np.array([0.3, -0.2, 0.5])) if placed else None
    tree = read_closed_tree(write(tmp_path, delta_sdf(transform=transform)))
    (tmp_path / "delta.xml").write_text(delta_rods_mjcf(transform=transform))
    mj_model = mujoco.MjModel.from_xml_path(str(tmp_path / "delta.xml"))
    mj_data = mujoco.MjData(mj_model)
    mujoco.mj_kinematics(mj_model, mj_data)
    read = frame_poses(tree)
    names = [mujoco.mj_id2name(mj_model, mujoco.mjtObj.mjOBJ_BODY, k) for k in range(1, mj_model.nbody)]
    assert len(names) == 14 and set(names) <= set(read)
    for k, name in enumerate(names, start=1):
        np.testing.assert_allclose(read[name][:3, 3], mj_data.xpos[k], atol=TOLERANCE, rtol=0, err_msg=name)
        np.testing.assert_allclose(read[name][:3, :3], mj_data.xmat[k].reshape(3, 3), atol=TOLERANCE, err_msg=name)
    site = mujoco.mj_name2id(mj_model, mujoco.mjtObj.mjOBJ_SITE, "centre")
    np.testing.assert_allclose(read["centre"][:3, 3], mj_data.site_xpos[site], atol=TOLERANCE, rtol=0)


@pytest.mark.parametrize("centre", POSES)
def test_a_rod_level_delta_in_sdformat_has_the_textbook_pressure_angles_through_the_graph(tmp_path, centre):
    path = write(tmp_path, delta_sdf(centre))
    with pytest.raises(LegWithLoops, match=r"inside a leg"):
        read_mechanism_file(path)
    tree = read_closed_tree(path)
    assert tree.motors == ["motor_1", "motor_2", "motor_3", "motor_4"]
    assert [closure.kind for closure in tree.closures] == ["3d"] * 7  # eight ball joints on the platform, one in
    result = graph_mechanism(tree).indices()  # the tree
    expected = textbook(centre)
    assert result.dof == 3
    assert_delta_textbook(result, expected)


def balls_as_three_hinges(text: str, names, reverse: bool = False) -> str:
    """The SDFormat text with each ball joint of ``names`` written as three revolute joints about perpendicular axes
    through its centre, joined by two links of no mass (as files converted from URDF write a ball); ``reverse``:
    every joint listed in the opposite order. The same mechanism."""
    for name in names:
        joint = re.search(rf'<joint name="{name}" type="ball"><parent>(\w+)</parent><child>(\w+)</child>(<pose[^>]*>'
                          r'[^<]*</pose>)</joint>', text)
        parent, child, pose = joint.groups()
        pose = pose if "relative_to" in pose else pose.replace("<pose>", f'<pose relative_to="{child}">')
        links = f'<link name="{name}_l1">{pose}</link><link name="{name}_l2">{pose}</link>'
        hinges = (f'<joint name="{name}_r1" type="revolute"><parent>{parent}</parent><child>{name}_l1</child>'
                  '<axis><xyz>1 0 0</xyz></axis></joint>'
                  f'<joint name="{name}_r2" type="revolute"><parent>{name}_l1</parent><child>{name}_l2</child>'
                  '<axis><xyz>0 1 0</xyz></axis></joint>'
                  f'<joint name="{name}_r3" type="revolute"><parent>{name}_l2</parent><child>{child}</child>'
                  f'<pose relative_to="{name}_l2">0 0 0 0 0 0</pose><axis><xyz>0 0 1</xyz></axis></joint>')
        text = text.replace(joint.group(0), hinges).replace("<link ", links + "<link ", 1)
    if reverse:
        joints = re.findall(r"<joint .*?</joint>", text)
        for joint in joints:
            text = text.replace(joint, "", 1)
        text = text.replace("<plugin", "".join(reversed(joints)) + "<plugin", 1)
    return text


@pytest.mark.parametrize("names, reverse", [(["end_1b"], False), (["end_1a"], True), (["end_1a", "end_2b"], False),
                                            (["end_1a", "end_2b"], True), (["end_4b"], False)])
def test_a_delta_whose_platform_balls_are_written_as_three_hinges_opens_in_any_order(tmp_path, names, reverse):
    """A platform ball joint of the rod-level Delta written as three revolute joints through two massless links:
    the spanning tree reached those links through the platform before their own rod (depending on the order the
    file lists its joints and on the rod), and the loop closed inside the leg, beyond the platform, which every
    command refused. The platform's joints are now taken last: the textbook pressure angles, whatever the order."""
    centre = POSES[0]
    text = balls_as_three_hinges(delta_sdf(centre), names, reverse)
    assert text.count('type="ball"') == 16 - len(names)
    path = write(tmp_path, text)
    with pytest.raises(LegWithLoops, match=r"inside a leg"):  # the commands then analyse it as a graph
        read_mechanism_file(path)
    result = graph_mechanism(read_closed_tree(path)).indices()
    assert result.dof == 3
    assert_delta_textbook(result, textbook(centre))
    if names == ["end_1b"]:  # and the command, as users run it
        command = screwkit("analyze", path, "--json")
        assert command.returncode == 0, command.stderr
        assert json.loads(command.stdout)["lmti"] == pytest.approx(float(result.lmti), abs=1e-12)


def test_the_length_scale_is_the_same_whatever_order_the_file_lists_its_joints_in(tmp_path):
    """SDFormat does not say which joints close the loops: the reader's spanning tree leaves out those its order
    meets last, and the length scale (the spread of the tree's joints) followed the order: 0.41326 m as written,
    0.41345 m with the joints listed the other way, and with it every tolerance (a path's ``tolerance_m``). It is now
    the spread of every joint of the file, once each: the same in either order and in the file written in mm,
    turned and moved in the world (read in its unit); a thousandth of it for a Delta a thousand times smaller."""
    as_written = write(tmp_path, delta_sdf(), "delta.sdf")
    reversed_ = write(tmp_path, balls_as_three_hinges(delta_sdf(), [], reverse=True), "reversed.sdf")
    turn = (1e3, random_rotation(np.random.default_rng(11)), np.array([300.0, -200.0, 500.0]))
    in_mm = write(tmp_path, balls_as_three_hinges(delta_sdf(transform=turn), [], reverse=True), "mm.sdf")
    smaller = write(tmp_path, balls_as_three_hinges(delta_sdf(transform=(1e-3, np.eye(3), np.zeros(3))), [],
                                                    reverse=True), "smaller.sdf")
    trees = {"as written": read_closed_tree(as_written), "reversed": read_closed_tree(reversed_),
             "mm": read_closed_tree(in_mm, length_unit="mm"), "x1e-3": read_closed_tree(smaller)}
    assert [c.name for c in trees["as written"].closures] != [c.name for c in trees["reversed"].closures]  # cut
    scales = {name: graph_mechanism(tree).length_scale for name, tree in trees.items()}  # (elsewhere)
    assert scales["reversed"] == pytest.approx(scales["as written"], rel=1e-12)
    assert scales["mm"] == pytest.approx(scales["as written"], rel=1e-12)
    assert scales["x1e-3"] == pytest.approx(1e-3 * scales["as written"], rel=1e-12)  # (a smaller Delta, in metres)
    base, axes, elbows, attach = delta_geometry((0.02, -0.03, -0.45), np.radians([90.0, 180.0, 270.0, 0.0]))
    drawn = np.array([np.zeros(3), *base] + [point + sign * SPACING / 2 * axis for points in (elbows, attach)
                                             for point, axis in zip(points, axes) for sign in (-1.0, 1.0)])
    # (the file's 17 joints where the generator puts them: the anchor, the motors, the rods' balls at both ends)
    assert scales["as written"] == pytest.approx(np.sqrt(np.mean(np.sum((drawn - drawn.mean(axis=0)) ** 2, axis=1))),
                                                 rel=1e-12)
    line = ["--line", "0.02", "-0.03", "-0.45", "0.03", "-0.02", "-0.44", "--samples", "5", "--json"]
    runs = [screwkit("trajectory", path, *line) for path in (as_written, reversed_)]
    assert all(run.returncode == 0 for run in runs), [run.stderr for run in runs]
    one, other = (json.loads(run.stdout) for run in runs)
    assert other["length_scale_m"] == pytest.approx(one["length_scale_m"], rel=1e-12)
    assert other["tolerance_m"] == pytest.approx(one["tolerance_m"], rel=1e-12)


def test_motors_marked_in_the_file_and_the_marker_on_a_joint_that_cannot_drive(tmp_path):
    tree = read_closed_tree(write(tmp_path, delta_sdf(plugin=False)))
    assert tree.motors == ["motor_1", "motor_2", "motor_3", "motor_4"] and tree.notes == []
    text = delta_sdf(plugin=False).replace('type="ball"><parent>arm_2</parent>',
                                           'type="ball"><screwkit:actuated/><parent>arm_2</parent>', 1)
    with pytest.raises(ImportError_, match=r"robot.sdf: <joint name='ball_2a'>: joint 'ball_2a' is marked actuated "
                                           r"but is a ball joint"):
        read_closed_tree(write(tmp_path, text))


def effector_first(text: str) -> str:
    """The five-bar without its joint to the world and with the effector listed first: the effector is then the
    canonical link, fixed as the base, and a motor closes a loop of the tree grown from it."""
    effector = re.search(r'<link name="effector">.*?</link>', text).group(0)
    text = text.replace('<joint name="anchor" type="fixed"><parent>world</parent><child>base</child></joint>', "")
    return text.replace(effector, "").replace('<link name="base"/>', effector + '<link name="base"/>')


BAD = [
    (lambda t: t.replace('name="loop_2" type="revolute"', 'name="loop_2" type="screw"'),
     r"<joint name='loop_2'>: type 'screw' is not read \(expected one of revolute, continuous"),
    (lambda t: t.replace("<link name=\"base\"/>", '<link name="base"/><model name="gripper"><link name="g"/></model>'),
     r"<model name='five_bar'><model name='gripper'>: nested models are not read"),
    (lambda t: t.replace("<model ", "<include><uri>model://arm</uri></include><model "),
     r"<include> of 'model://arm': included models are not read"),
    (lambda t: t.replace('relative_to="proximal_2"', 'relative_to="proximal_9"'),
     r"<link name='distal_2'>: its pose is relative_to 'proximal_9', not a frame of the model"),
    (lambda t: t.replace('<link name="base"/>', '<link name="base"><pose relative_to="anchor"/></link>'),
     r"<joint name='anchor'>: its pose's relative_to goes round a cycle \(base -> anchor -> base\)"),
    (lambda t: t.replace("</model></sdf>", '</model><model name="other"><link name="x"/></model></sdf>'),
     r"2 <model> elements \('five_bar', 'other'\); screwkit reads one model"),
    (lambda t: t.replace("<parent>proximal_3</parent>", "<parent>elsewhere</parent>"),
     r"<joint name='free3'>: <parent> names 'elsewhere', not a link, joint or frame of the model"),
    (lambda t: t.replace('<link name="effector"><pose rotation_format="quat_xyzw">',
                         '<link name="effector"><pose rotation_format="quat_xyzw">1 '),
     r"<link name='effector'>: <pose> must hold 7 finite numbers"),
    (lambda t: t.replace('<link name="base"/>', '<link name="base"><pose>0 0  1.12 0 0</pose></link>')
     .replace('<link name="effector"><pose rotation_format="quat_xyzw">',
              '<link name="effector"><pose rotation_format="quat_xyzw">1 '),  # (both named in one run)
     r"<link name='base'>: <pose> must hold 6 finite numbers, got '0 0  1.12 0 0'; <link name='effector'>: <pose> "
     r"must hold 7 finite numbers, got '1 .*'\.$"),
    (lambda t: t.replace("<parent>world</parent><child>base</child>", "<parent>world</parent><child>base</child>")
     .replace("<child>proximal_1</child>", "<child>base</child>"),
     r"<joint name='mot1'>: <parent> and <child> are on the same link 'base'"),
    (lambda t: t.replace('<pose relative_to="proximal_2">', '<pose relative_to="world">'),  # not in a model's scope
     r"<link name='distal_2'>: its pose is relative_to 'world', a frame outside the model's scope"),
    (lambda t: t.replace('expressed_in="__model__"', 'expressed_in="world"'),
     r"<joint name='loop_2'>: <axis><xyz expressed_in='world'>: not a frame of the model"),
    (effector_first,
     r"<joint name='mot2'>: joint 'mot2' is marked actuated but closes a loop of the tree grown from the canonical "
     r"link 'effector'"),
]


@pytest.mark.parametrize(("edit", "message"), BAD)
def test_constructs_this_reading_does_not_follow_are_refused_naming_the_file_and_element(tmp_path, edit, message):
    path = write(tmp_path, edit(five_bar_sdf()))
    with pytest.raises(ImportError_, match=r"robot.sdf: " + message) as error:
        read_closed_tree(path)
    assert "\n" not in str(error.value)


@pytest.mark.cli
def test_analyze_and_info_open_sdformat_files_on_the_command_line(tmp_path):
    five_bar = write(tmp_path, five_bar_sdf(), "five_bar.sdf")
    analysed = screwkit("analyze", five_bar, "--json")
    assert analysed.returncode == 0, analysed.stderr
    assert json.loads(analysed.stdout)["lmti"] == pytest.approx(five_bar_expected(HOME)["lmti"], abs=TOLERANCE)
    info = screwkit("info", five_bar)
    assert info.returncode == 0, info.stderr
    assert "SDFormat (joints closing loops)" in info.stdout and "planar" in info.stdout
    bad = write(tmp_path, five_bar_sdf().replace('<link name="base"/>', '<link name="base"><pose>0 0 1</pose></link>')
                .replace('<link name="effector"><pose rotation_format="quat_xyzw">',
                         '<link name="effector"><pose rotation_format="quat_xyzw">1 '), "bad.sdf")
    one_line_error(screwkit("analyze", bad), "<link name='base'>: <pose> must hold 6 finite numbers, got '0 0 1'; "
                   "<link name='effector'>: <pose> must hold 7 finite numbers")  # (every one, in one run)
    delta = write(tmp_path, delta_sdf(), "delta.sdf")
    expected = textbook(POSES[0])
    analysed = screwkit("analyze", delta)
    assert analysed.returncode == 0, analysed.stderr
    assert f"LMTI (Eq. 11, all actuators)        {expected['lmti']:.4f}" in analysed.stdout
    info = screwkit("info", delta)
    assert info.returncode == 0, info.stderr
    assert "SDFormat (joints closing loops)" in info.stdout and "legs with loops inside them" in info.stdout
    write(tmp_path, five_bar_sdf().replace('type="continuous"', 'type="gearbox"', 1), "bad.sdf")
    one_line_error(screwkit("analyze", tmp_path / "bad.sdf"), "bad.sdf: <joint name='free1'>: type 'gearbox' is not "
                   "read")


@pytest.mark.cli
def test_a_model_joined_to_no_world_says_its_fixed_base_on_the_first_line(tmp_path):
    """Gazebo lets a model with no joint to the world float; screwkit fixes its canonical link and says so where the
    guessed actuators are said, not only among the import report's lines (the same indices as anchored)."""
    anchored = screwkit("analyze", write(tmp_path, five_bar_sdf(), "anchored.sdf"), "--json")
    floating = write(tmp_path, five_bar_sdf().replace(
        '<joint name="anchor" type="fixed"><parent>world</parent><child>base</child></joint>', ""), "floating.sdf")
    assert floating.read_text() != five_bar_sdf()
    text = screwkit("analyze", floating)
    assert text.returncode == 0, text.stderr
    assert text.stdout.splitlines()[0].endswith("; no joint to the world: the canonical link 'base' is the fixed base "
                                                "(Gazebo would let the model float)")
    report, before = json.loads(screwkit("analyze", floating, "--json").stdout), json.loads(anchored.stdout)
    assert report["base_guessed"].startswith("no joint to the world") and before["base_guessed"] is None
    assert report["lmti"] == pytest.approx(before["lmti"], abs=1e-12)


def test_map_verify_and_sweep_of_a_serial_leg_sdformat_file_and_a_graph_sweep(tmp_path):
    """The commands of serial legs on a five-bar written as SDFormat (map against indices_at_poses at its grid
    points, verify's closed forms), and a sweep of the rod-level Delta written as SDFormat (a graph)."""
    import xarray as xr

    five_bar = write(tmp_path, five_bar_sdf(), "five_bar.sdf")
    mechanism = load(five_bar)
    out = tmp_path / "map.nc"
    mapped = screwkit("map", five_bar, "--radius", "0.04", "--step", "0.02", "--out", out)
    assert mapped.returncode == 0, mapped.stderr
    with xr.open_dataset(out) as dataset:
        xs, ys = np.meshgrid(dataset["x"].values, dataset["y"].values)
        inside = np.isfinite(dataset["lmti"].values)
        expected = indices_at_poses(mechanism, np.stack([xs[inside], ys[inside]], axis=-1))
        np.testing.assert_allclose(dataset["lmti"].values[inside], expected.lmti, atol=1e-12)
    verified = screwkit("verify", five_bar, "--samples", "200")
    assert verified.returncode == 0 and "largest deviation" in verified.stdout, verified.stderr
    delta = write(tmp_path, delta_sdf(), "delta.sdf")
    swept = screwkit("sweep", delta, "--sweep", f"z:{POSES[0][2] - 0.02!r}:{POSES[0][2] + 0.02!r}:0.02")
    assert swept.returncode == 0 and "swept z over 2 values (2 reachable)" in swept.stderr, swept.stderr


STACKED_PINS = {"wrist_1": 0.1, "elbow_2": -0.05, "wrist_3": 0.07, "motor_3": 0.2}
"""Joints of tests/data/sdformat/five_bar.sdf drawn elsewhere along their pins (z, metres)."""


@pytest.mark.parametrize("stacked", (False, True))
def test_the_five_bar_of_docs_other_formats_opens_with_its_pressure_angles(tmp_path, stacked):
    """tests/data/sdformat/five_bar.sdf, written by hand (link frames at the joints, unturned): ITI_i the sine of
    the angle between leg i's proximal and distal links, the OTI of a pair the sine between their distal links.
    Also with joints drawn elsewhere along their pins (a coaxial wrist drawn stacked, as a CAD export places each
    pin at its own layer): the same planar five-bar with its output point (before, the wrists no longer met at one
    point, and the platform's idle rotation made the output a frame with every LMTI zero)."""
    from pathlib import Path

    from screwkit.studies import indices_at_pose

    path = Path(__file__).parent / "data" / "sdformat" / "five_bar.sdf"
    if stacked:
        text = path.read_text()
        for joint, height in STACKED_PINS.items():
            opening = re.search(rf'<joint name="{joint}" type="revolute">.*?</child>', text).group(0)
            text = text.replace(opening, f"{opening}<pose>0 0 {height} 0 0 0</pose>")
        path = tmp_path / "five_bar_stacked.sdf"
        path.write_text(text)

    bases = np.array([[-0.1, 0.0], [0.1, 0.0], [0.2, 0.65]])
    elbows = np.array([[-0.25, 0.15], [0.25, 0.15], [0.35, 0.4]])
    point = np.array([0.0, 0.35])

    def sine(u, v):
        return abs(u[0] * v[1] - u[1] * v[0]) / np.linalg.norm(u) / np.linalg.norm(v)

    mechanism = load(path)
    assert mechanism.is_planar and mechanism.dof == 2 and mechanism.task_coordinates == ("x", "y")
    result = indices_at_pose(mechanism, mechanism.home_pose)
    distal = point - elbows
    np.testing.assert_allclose(result.iti_actuators, [sine(e - b, d) for b, e, d in zip(bases, elbows, distal)],
                               atol=TOLERANCE)
    pairs = {(0, 1): sine(distal[0], distal[1]), (0, 2): sine(distal[0], distal[2]), (1, 2): sine(distal[1], distal[2])}
    np.testing.assert_allclose(result.lmti, max(pairs.values()), atol=TOLERANCE)
    np.testing.assert_allclose(result.f_o[1], min(pairs[(1, 2)], pairs[(0, 2)], pairs[(0, 1)]), atol=TOLERANCE)


@pytest.mark.parametrize(("kind", "tree_joint", "closures"), [
    ("prismatic", "loop_3", ["loop_3"]), ("universal", "loop_3_axis", ["loop_3_axis2_a", "loop_3_axis2_b"])])
def test_a_universal_or_prismatic_joint_closing_a_loop_keeps_its_first_motion_in_the_tree(tmp_path, kind, tree_joint,
                                                                                          closures):
    """A prismatic loop joint: its slide in the tree on a body welded to the child; a universal one: its first axis
    in the tree, its second a hinge. Both close at the file's configuration (structure only: no textbook here)."""
    text = five_bar_sdf().replace('name="loop_3" type="revolute"', f'name="loop_3" type="{kind}"')
    text = text.replace('<axis><xyz>0 0 -1</xyz></axis></joint>', '<axis><xyz>0 0 -1</xyz></axis><axis2><xyz>1 0 0'
                        '</xyz></axis2></joint>')
    tree = read_closed_tree(write(tmp_path, text))
    assert tree.model.existJointName(tree_joint)
    assert [c.name for c in tree.closures if c.name.startswith("loop_3")] == closures
    assert max(closure_gaps(tree, tree.q_reference).values()) < TOLERANCE
    parent = tree.model.names[tree.model.parents[tree.model.getJointId(tree_joint)]]
    assert parent == "free3"


@pytest.mark.parametrize("transform", [(1.0, 0.0, (0.0, 0.0, 0.0)), *MOVED])
def test_a_five_bar_on_a_turntable_with_the_table_locked_is_the_five_bar_in_any_unit_frame_and_leg_order(
        tmp_path, transform):
    """Every leg stands on a ``stage`` that a passive, tilted ``table`` joint turns: the whole robot is one leg
    until ``--lock table`` holds it. Locked, it is the five-bar: the textbook pressure angles, each following its
    own leg, whatever the unit (1e-3, 1e3), the world frame, the order the legs are written in and the motors'
    names. The graph path, which analyses the platform's frame, refuses it in one line: the effector turns freely on
    the pin where the legs meet, so no actuator controls its frame (its indices would be zero everywhere)."""
    names = {0: "drive_c", 1: "drive_a", 2: "drive_b"}
    path = write(tmp_path, five_bar_sdf(transform, order=(2, 1, 0), motor=names.get, stage=True))
    with pytest.raises(LegWithLoops, match="every actuator rides on 'table'.*--lock table analyses"):
        load(path)
    with pytest.raises(ImportError_, match="joint 'table' carries every actuator.*--lock table analyses"):
        graph_mechanism(read_closed_tree(path))
    mechanism = load(path, lock=("table",))
    assert mechanism.is_planar and mechanism.dof == 2
    assert_moved_textbook(mechanism, transform, {name: leg for leg, name in names.items()}.get)
    with pytest.raises(ImportError_, match="the platform 'effector' moves with every actuator locked"):
        graph_mechanism(read_closed_tree(path, lock=("table",)))  # the effector turns freely on its pin: no frame


def test_a_platform_no_actuator_holds_is_refused_naming_the_actuators_and_whether_they_were_guessed(tmp_path):
    """A published SDFormat robot whose motors the file does not mark (Cassie's cassie_v2.sdf) was refused as "moves
    with every actuator locked" without saying which joints were taken as actuators: here the turntable alone, the
    one branch leaving the base."""
    guessed = write(tmp_path, five_bar_sdf(marker="", stage=True), "guessed.sdf")
    with pytest.raises(ImportError_, match=r"or motors the file does not name; actuators table, guessed from the "
                                           r"branches leaving the base\)"):
        graph_mechanism(read_closed_tree(guessed))
    marked = write(tmp_path, five_bar_sdf(stage=True), "marked.sdf")
    with pytest.raises(ImportError_, match=r"actuators mot1, mot2, mot3\): its frame is no output"):
        graph_mechanism(read_closed_tree(marked, lock=("table",)))


def test_analyze_of_an_sdformat_five_bar_on_a_turntable_names_lock_and_locked_gives_the_pressure_angles(tmp_path):
    """The command line, as a subprocess, on the millimetre copy: without ``--lock`` one line naming the option;
    with it the textbook LMTI and F_O1 at the file's pose."""
    path = write(tmp_path, five_bar_sdf(MOVED[0], stage=True))
    one_line_error(screwkit("analyze", path), "--lock table analyses the legs on the body it turns")
    completed = screwkit("analyze", path, "--lock", "table", "--json")
    assert completed.returncode == 0, completed.stderr
    report, expected = json.loads(completed.stdout), five_bar_expected(HOME)
    assert report["lmti"] == pytest.approx(expected["lmti"], abs=TOLERANCE)
    assert report["f_o"]["1"] == pytest.approx(expected["f_o1"], abs=TOLERANCE)


@pytest.mark.parametrize(("platform_joint", "base_offset"), [
    ("universal", (0.0, 0.0, 0.0)), ("universal", (3.0, 0.0, 0.0)), ("revolute", (0.0, -2.0, 0.5))])
def test_a_hexapod_whose_loops_close_by_hinges_has_the_indices_of_its_legs_wherever_its_base_frame_is_drawn(
        tmp_path, platform_joint, base_offset):
    """An S-P-U hexapod's loops close at the platform by universal (or two revolute) joints, each made a hinge of two
    points on its axis. The leg's OTI point is the joint, not the middle of those two points, whose distance is
    the model's size: it was, and the LMTI was 0.66 (0.43 with the base link's frame drawn 3 m away) for the
    0.8738 of the same legs as U-P-S (the bundled file, read through its own serial chains)."""
    from screwkit.studies import indices_at_pose

    bundled = load("ups_hexapod_8")
    reference = indices_at_pose(bundled, bundled.home_pose)
    found = graph_mechanism(read_closed_tree(write(tmp_path, hexapod_sdf(platform_joint, base_offset)))).indices()
    assert found.lmti == pytest.approx(reference.lmti, abs=1e-9)
    for j in reference.faults:
        assert found.f_o[j] == pytest.approx(reference.f_o[j], abs=1e-9)
    np.testing.assert_allclose(sorted(found.iti_actuators), sorted(reference.iti_actuators), atol=1e-9)


CRANK, SPAN = 0.3, 0.2
"""The parallelogram four-bar: cranks of CRANK m from pins SPAN m apart on the ground, hanging down at zero."""


def parallelogram_sdf(crank_first: str) -> str:
    """Cranks ``AB`` and ``DC`` hanging from A = (0, 0) and D = (SPAN, 0), the coupler ``BC`` (its frame at B)
    pinned to both; every joint native, ``crank_first`` ("A" or "D") the crank whose joints the file lists first
    (which decides where a breadth-first tree closes the loop: at C or at B)."""
    links = ('<link name="crank_AB"/><link name="crank_DC"><pose>0.2 0 0 0 0 0</pose></link>'
             '<link name="coupler"><pose>0 -0.3 0 0 0 0</pose></link>')
    axis = "<axis><xyz>0 0 1</xyz></axis>"
    crank_a = (f'<joint name="A" type="revolute"><parent>world</parent><child>crank_AB</child>{axis}</joint>'
               f'<joint name="B" type="revolute"><pose relative_to="coupler">0 0 0 0 0 0</pose><parent>crank_AB'
               f'</parent><child>coupler</child>{axis}</joint>')
    crank_d = (f'<joint name="D" type="revolute"><parent>world</parent><child>crank_DC</child>{axis}</joint>'
               f'<joint name="C" type="revolute"><pose relative_to="coupler">0.2 0 0 0 0 0</pose><parent>crank_DC'
               f'</parent><child>coupler</child>{axis}</joint>')
    joints = crank_a + crank_d if crank_first == "A" else crank_d + crank_a
    return f'<sdf version="1.7"><model name="parallelogram">{links}{joints}</model></sdf>'


def test_a_parallelogram_whose_loop_the_file_does_not_cut_has_the_same_indices_whichever_crank_is_listed_first(
        tmp_path):
    """SDFormat does not say where a loop is cut; the breadth-first tree cut the parallelogram at the coupler's
    second pin in file order, and the output point was that pin: listing the other crank first moved the output
    from C to B (the same 19.47 deg configuration at x = 0.3 or 0.1) and swapped the cranks' ITIs (0.9428 and 1).
    Now the output is the coupler's frame, whichever crank comes first, and its indices are the closed forms: the
    coupler translates on the circle x = CRANK sin t, and the constraint keeping it from turning, a force along a
    crank, has power coefficient cos t with the twist freed by releasing that crank (the coupler turning about the
    other crank's pin, its velocity at the pin across the horizontal coupler)."""
    angles = np.radians([12.0, 19.47122063449069, -30.0])
    results = {}
    for first in ("A", "D"):
        path = write(tmp_path, parallelogram_sdf(first), f"parallelogram_{first}.sdf")
        for t in angles:
            x = repr(float(CRANK * np.sin(t)))
            analysed = screwkit("analyze", path, "--output", "coupler", "--pose", x, "--json")
            assert analysed.returncode == 0, analysed.stderr
            results[first, t] = json.loads(analysed.stdout)
            assert results[first, t]["cti"] == pytest.approx(np.cos(t), abs=TOLERANCE)
            assert results[first, t]["f_c"]["1"] == pytest.approx(np.cos(t), abs=TOLERANCE)
        shown = screwkit("info", path, "--output", "coupler")
        assert shown.returncode == 0, shown.stderr
        cut = {"A": "C", "D": "B"}[first]
        assert f"output the platform's frame: the loop closed at '{cut}_a' could as well be closed at another joint" \
               in shown.stdout and "output frame 'coupler' on body 'coupler'" in shown.stdout
        point = screwkit("info", path, "--output", "coupler", "--output-type", "point")  # asked for: the pin cut
        assert point.returncode == 0 and f"the point where the chains meet on body 'coupler' (closure '{cut}_a')" \
            in point.stdout, point.stderr
    for t in angles:
        one, other = results["A", t], results["D", t]
        assert one["pose"] == pytest.approx(other["pose"], abs=1e-12)
        for key in ("iti", "lmti", "cti"):
            assert one[key] == pytest.approx(other[key], abs=TOLERANCE), key
        assert one["f_o"]["1"] == pytest.approx(other["f_o"]["1"], abs=TOLERANCE)


@pytest.mark.parametrize("degrees", [5.0, 12.0, 15.0, 30.0])
def test_the_parallelogram_s_actuator_values_give_the_pose_the_geometry_gives(tmp_path, degrees):
    """--actuators 15 15 was refused ("no closed pose ... near the start pose") between about 11 and 17 deg: the
    forward kinematics asked the closure for 1e-13 where the coupler's completed pose holds to about 2e-13."""
    path = write(tmp_path, parallelogram_sdf("A"), "parallelogram.sdf")
    analysed = screwkit("analyze", path, "--output", "coupler", "--actuators", f"{degrees!r} {degrees!r}", "--json")
    assert analysed.returncode == 0, analysed.stderr
    # to what the forward kinematics asks of the actuator values (1e-11 rad) through the crank: x = CRANK sin(t)
    assert json.loads(analysed.stdout)["pose"]["x"] == pytest.approx(CRANK * np.sin(np.radians(degrees)),
                                                                    abs=CRANK * 1e-11)


@pytest.mark.parametrize("tilt, scale, reverse", [(0.0, 1.0, False), (4e-5, 1.0, False), (3e-4, 1.0, False),
                                                  (4e-5, 1e-3, True), (3e-4, 1e3, True)])
def test_an_rss_stewart_platform_locks_each_rod_s_spin_however_its_frames_are_turned(tmp_path, tilt, scale, reverse):
    """The bundled 8-RSS hexapod in SDFormat with ball joints at both ends of its rods, each rod's frame along it to
    ``tilt`` (a file's rounding; 0 exactly), in m, mm-like and km-like sizes, its legs listed either way: the hinge
    locked as each rod's idle spin is its lower ball's x (the one along the rod; in the leg the platform hangs from, one
    of its six ball hinges), its legs' joints are independent (no DOF note), and the indices at its home and at a pose
    off it are ``rss_hexapod_8``'s (1e-9). The first hinge from the leg's end whose removal kept the rank at the
    rounding used to be locked: the leg kept its spin and a hinge 4e-5 from it, and five of the eight chains read "DOF
    decided at the file's rounding"."""
    path = tmp_path / "rss.sdf"
    path.write_text(rss_sdf(tilt, seed=1, scale=scale, reverse=reverse))
    mechanism, bundled = load(path), load("rss_hexapod_8")
    assert mechanism.dof == 6 and not mechanism.assembly_notes
    locked = [note for note in mechanism.import_report if "idle joints locked" in note]
    carrier = 7 if reverse else 0  # the platform hangs from the first leg written: its path holds both its balls
    names = re.findall(r"\w+_\d_[xyz]", locked[0]) if len(locked) == 1 else []
    assert len(names) == 8 and {f"elbow_{k}_x" for k in range(8) if k != carrier} <= set(names), locked
    poses = bundled.home_pose + np.array([[0.0] * 6, [0.02, -0.03, 0.01, 0.05, -0.03, 0.04]])
    expected = indices_at_poses(bundled, poses, detail=True)
    names = [f"motor_{name.split(':')[0].removeprefix('leg_')}" for name in bundled.actuator_names]
    order = [[name.split(":")[-1] for name in mechanism.actuator_names].index(f"motor_{int(n.split('_')[1]) - 1}")
             for n in names]
    found = indices_at_poses(mechanism, poses * np.where(mechanism.angular, 1.0, scale), detail=True)
    np.testing.assert_allclose(found.iti_actuators[:, order], expected.iti_actuators, atol=1e-9)
    np.testing.assert_allclose(found.lmti, expected.lmti, atol=1e-9)
