"""Files exported with their numbers rounded read as the mechanism drawn: a planar mechanism whose hinge axes are
parallel only to the file's rounding is planar, a hinge coaxial with the revolute loop that closes it only to that
rounding is idle, a joint at its stop beyond it by the rounding is read; and where the rounding decides the DOF
count, every command says so.

The checks are against independent computations: the five-bar's textbook pressure angles (Eqs. 30-34 of the paper,
``test_lower_mobility.five_bar_expected``) and Gepetto's published five-bar read from its file as published (its
numbers to 16 digits), against the same file with every number written to 6 decimals.
"""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import mujoco
import numpy as np
import pinocchio as pin
import pytest
from scipy.spatial.transform import Rotation
from test_assembly_nearest import spherical_manipulator_onshape
from test_gallery import mujoco_residuals
from test_io import poses_near_home
from test_lower_mobility import five_bar_expected
from test_onshape import MOVED, assert_moved_textbook, five_bar_onshape

from helpers import screwkit
from screwkit.cli import options
from screwkit.closure import solve
from screwkit.closure.assembly import DOF_AT_ROUNDING, DOF_MARGIN
from screwkit.common.tolerances import FILE_ROUNDING
from screwkit.io import LegWithLoops, read_closed_tree, read_mechanism_file
from screwkit.io.graph import graph_mechanism
from screwkit.io.loader import bundled_names, load
from screwkit.io.rounding import FULL_TURNS
from screwkit.studies.poses import indices_at_pose, indices_at_poses

GEPETTO_FIVE_BAR = (Path(__file__).resolve().parent / "data" / "gallery" / "published" / "example_parallel_robots"
                    / "5bar_linkage")


def tilted(text: str, rounding: float, seed: int) -> str:
    """An onshape-to-robot URDF with every joint origin's roll and pitch (written 0) set to about ``rounding`` rad
    at random: each hinge axis off the plane's normal by that much, as a CAD export's are."""
    rng = np.random.default_rng(seed)
    return re.sub(r'rpy="0 -0 ', lambda _: f'rpy="{rng.normal(0, rounding)!r} {rng.normal(0, rounding)!r} ', text)


def test_a_five_bar_whose_axes_are_parallel_to_the_rounding_is_planar_with_the_textbook_indices(tmp_path):
    """The three-legged onshape five-bar with its hinges tilted by about 3e-7 rad: read planar (before, as a spatial
    mechanism with other task coordinates), its task coordinates x and y, and at poses near its home the textbook
    pressure angles of the exact five-bar to the rounding's order."""
    path = tmp_path / "robot.urdf"
    path.write_text(tilted(five_bar_onshape(), 3e-7, 0))
    assert 'rpy="0 -0 ' not in path.read_text()
    converted, report = read_mechanism_file(path)
    assert report.planar, report.lines()
    assert any("written parallel" in note for note in report.notes)
    mechanism = load(path)
    assert mechanism.task_coordinates == ("x", "y")
    points = poses_near_home()
    result = indices_at_poses(mechanism, points, detail=True)
    legs = [int(name.split(":")[-1].removeprefix("motor")) - 1 for name in mechanism.actuator_names]
    for k, point in enumerate(points):
        expected = five_bar_expected(point)
        np.testing.assert_allclose(result.iti_actuators[k], expected["iti_actuators"][legs], atol=1e-5)
        np.testing.assert_allclose([result.lmti[k], result.f_o[1][k]], [expected["lmti"], expected["f_o1"]],
                                   atol=1e-5)


def rounded_copy(folder: Path, source: Path, decimals: int) -> Path:
    """``source``'s folder copied into ``folder`` with every decimal number of ``source`` written to ``decimals``
    decimals (the file's companions, such as Gepetto's robot.yaml, as they are)."""
    target = folder / source.parent.name
    shutil.copytree(source.parent, target)
    text = re.sub(r"(?<![\w.#])-?\d+\.\d+(?:[eE][-+]?\d+)?", lambda m: repr(round(float(m.group(0)), decimals)),
                  source.read_text())
    assert text != source.read_text()
    (target / source.name).write_text(text)
    return target / source.name


def test_gepetto_s_five_bar_written_to_six_decimals_reads_as_published(tmp_path):
    """Gepetto's five-bar (its end rod closed by a weld on a hinge coaxial with it) with every number written to
    6 decimals: its axes parallel to 3e-7 rad and the welded hinge coaxial only that far. It reads as the published
    file does: planar, the point where its chains meet, x and y, the coaxial hinge locked as idle, its home within
    1e-6 m and its indices there within 1e-6 (before: read as a spatial mechanism in y and roll whose home its own
    closure could not reach, refused by `screwkit analyze`)."""
    published = load(GEPETTO_FIVE_BAR / "robot.urdf")
    path = rounded_copy(tmp_path, GEPETTO_FIVE_BAR / "robot.urdf", 6)
    rounded = load(path)
    assert rounded.task_coordinates == published.task_coordinates == ("x", "y")
    assert rounded.output_point is not None and published.output_point is not None
    assert any("idle joints locked" in note and "closedloop1_A" in note for note in rounded.import_report)
    np.testing.assert_allclose(rounded.home_pose, published.home_pose, atol=1e-6)
    first, second = indices_at_pose(published, published.home_pose), indices_at_pose(rounded, rounded.home_pose)
    np.testing.assert_allclose(second.iti_actuators, first.iti_actuators, atol=1e-6)
    assert abs(second.lmti - first.lmti) < 1e-6
    run = screwkit("analyze", path)
    assert run.returncode == 0, run.stderr
    assert "2 DOF" in run.stdout and "at x = " in run.stdout


def test_a_full_turn_or_a_stop_missed_by_the_rounding_is_read(tmp_path):
    """The CAD Stewart platform's rod joints are limited to [0, 6.283185] (a full turn to 3e-7 rad) and sit at 0;
    written to 7 decimals, its assembly puts one 3e-9 rad below 0. That was refused as outside its limits. Now the
    full turns read as continuous joints, and the file reads as the exact one does (home within 1e-7, LMTI within
    1e-6). With the rods limited to [0, 3] instead, the limit that the assembly misses by 3e-9 is moved out to the
    joint's value, and the report says which and to where."""
    source = Path(__file__).resolve().parent / "data" / "gallery" / "stewart_cad.xml"
    exact = load(source)
    assert any(FULL_TURNS in note and "r_rod6" in note for note in exact.import_report)
    path = rounded_copy(tmp_path, source, 7)
    rounded = load(path)
    assert rounded.dof == exact.dof == 6
    np.testing.assert_allclose(rounded.home_pose, exact.home_pose, atol=1e-7)
    assert abs(indices_at_pose(rounded, rounded.home_pose).lmti - indices_at_pose(exact, exact.home_pose).lmti) < 1e-6
    half = path.with_name("half_turn.xml")
    half.write_text(path.read_text().replace('range="0 6.283185"', 'range="0 3.0"'))
    stopped = load(half)
    assert any("limits moved out to" in note for note in stopped.import_report), stopped.import_report
    assert not any(FULL_TURNS in note for note in stopped.import_report)
    np.testing.assert_allclose(stopped.home_pose, rounded.home_pose, atol=1e-12)

GALLERY = Path(__file__).resolve().parent / "data"
ROUNDED_FILES = ["gallery/published/example_parallel_robots/5bar_linkage/robot.urdf",
                 "gallery/published/example_parallel_robots/robot_delta/robot.urdf",
                 "gallery/published/example_parallel_robots/wl16_like/robot.urdf", "gallery/stewart_cad.xml"]
"""The gallery's files of other tools with numbers of more than 7 decimals (the SDFormat five-bar has none)."""


@pytest.mark.parametrize("name", ROUNDED_FILES)
def test_every_published_file_written_to_seven_decimals_reads_as_published(tmp_path, name):
    """A property of reading: the gallery's files of other tools with every number written to 7 decimals (a
    rounding of 1e-7 m, 2e-6 of the smallest one's size) have the published files' DOF, task coordinates and output,
    a home within 1e-6 of their length scale and ITIs and LMTI there within 1e-5. Before this stop, three of the
    four were refused (a home its closure could not reach, a compound leg read as not reducible, a limit)."""
    source = GALLERY / name
    published, rounded = load(source), load(rounded_copy(tmp_path, source, 7))
    assert (rounded.dof, rounded.task_coordinates) == (published.dof, published.task_coordinates)
    assert (rounded.output_point is None) == (published.output_point is None)
    np.testing.assert_allclose(rounded.home_pose, published.home_pose, atol=1e-6 * published.length_scale)
    first, second = indices_at_pose(published, published.home_pose), indices_at_pose(rounded, rounded.home_pose)
    np.testing.assert_allclose(second.iti_actuators, first.iti_actuators, atol=1e-5)
    assert abs(second.lmti - first.lmti) < 1e-5


def test_a_dof_count_that_turns_on_the_file_s_rounding_is_said(tmp_path):
    """The manipulator's axes off its centre by 3e-7 m at random (up to 1.3e-5 of its size, beyond the rounding that
    reading idealises): its constraints are independent only to 1e-5, so it reads 2 DOF where the same manipulator
    written exactly (checked here) has 3. ``screwkit analyze`` says so in one line and in its JSON; the manipulator
    within the rounding, and every bundled mechanism, has no such note. The graph derivation, which reads the file
    as written, reads 1 DOF of the manipulator within the rounding, and says so; of the exact one, 3 and nothing."""
    paths = {}
    for label, rounding, seed in (("exact", 0.0, 2), ("within", 1e-7, 0), ("beyond", 3e-7, 2)):
        paths[label] = tmp_path / label / "robot.urdf"
        paths[label].parent.mkdir()
        paths[label].write_text(spherical_manipulator_onshape(rounding, seed))
    assert load(paths["exact"]).dof == load(paths["within"]).dof == 3
    beyond = load(paths["beyond"])
    assert beyond.dof == 2
    [note] = [note for note in beyond.assembly_notes if note.startswith(DOF_AT_ROUNDING)]
    assert "2 DOF" in note and "may have up to 3 DOF" in note
    value = float(re.search(r"only to ([0-9.e+-]+) \(relative\)", note).group(1))
    assert FILE_ROUNDING / 10 < value < DOF_MARGIN
    run = screwkit("analyze", paths["beyond"])
    assert run.returncode == 0 and f"{paths['beyond']}: {DOF_AT_ROUNDING}2 DOF" in run.stderr, run.stderr
    as_json = screwkit("analyze", paths["beyond"], "--json")
    assert as_json.returncode == 0 and json.loads(as_json.stdout)["assembly"] == [note]
    within = screwkit("analyze", paths["within"])
    assert within.returncode == 0 and DOF_AT_ROUNDING not in within.stderr
    for name in bundled_names():  # read in metres and as if written in mm (a slide's twist is 1 / the length scale)
        for unit in ("m", "mm"):
            notes = load(name, length_unit=unit).assembly_notes
            assert not [note for note in notes if note.startswith(DOF_AT_ROUNDING)], (name, unit)
    # the graph derivation reads a file as written (no axes made to meet): its count is said alike
    exact, rounded = (graph_mechanism(read_closed_tree(paths[label])) for label in ("exact", "within"))
    assert exact.dof == 3 and not [note for note in exact.report.notes if note.startswith(DOF_AT_ROUNDING)]
    [note] = [note for note in rounded.report.notes if note.startswith(DOF_AT_ROUNDING)]
    assert rounded.dof == 1 and "may have up to 3 DOF" in note, note


def test_every_command_says_a_graph_s_dof_count_that_turns_on_the_rounding(tmp_path, monkeypatch, capsys):
    """The commands' loader prints a graph mechanism's note as it prints a serial one's (before, only ``info`` and
    ``analyze --json``'s import report carried it). The manipulator within the rounding is routed to the graph
    derivation here (its serial reading, patched, says its legs have loops), which reads it as written."""
    path = tmp_path / "robot.urdf"
    path.write_text(spherical_manipulator_onshape(1e-7, 0))

    def legs_with_loops(*args, **kwargs):
        raise LegWithLoops(f"{path}: routed to the graph derivation by the test")

    monkeypatch.setattr(options, "load", legs_with_loops)
    graph = options.load_mechanism(str(path), None, graphs=True, indices=False)
    assert graph.dof == 1
    printed = capsys.readouterr().err
    assert f"{path}: {DOF_AT_ROUNDING}1 DOF" in printed and "may have up to 3 DOF" in printed, printed



def relabelled_urdf(text: str) -> str:
    """The URDF with its links and joints listed in reverse order (so Pinocchio's tree, the chains and the actuators
    come in another order) and its motors renamed."""
    lines = text.splitlines()
    head, body, tail = lines[:2], lines[2:-1], lines[-1:]  # <robot>, the base link; </robot>
    return re.sub(r"\bmotor(\d)\b", r"drive_\1", "\n".join(head + body[::-1] + tail)) + "\n"


def test_the_dof_note_is_the_same_in_any_unit_world_or_order(tmp_path):
    """The manipulator beyond the rounding, written with its lengths x 1e-3 and x 1e3, turned and moved in the world,
    or with its legs listed in reverse and its motors renamed: the same 2 DOF and the same note, word for word (its
    singular value is of unit twists and orthonormal complements, which no unit, frame or order changes)."""
    turned = pin.SE3(pin.rpy.rpyToMatrix(0.7, -1.1, 2.3), np.array([0.4, -1.3, 2.1]))
    texts = {"as written": spherical_manipulator_onshape(3e-7, 2),
             "x 1e-3": spherical_manipulator_onshape(3e-7, 2, unit=1e-3),
             "x 1e3": spherical_manipulator_onshape(3e-7, 2, unit=1e3),
             "turned": spherical_manipulator_onshape(3e-7, 2, world=turned)}
    texts["reversed"] = relabelled_urdf(texts["as written"])
    assert 'name="drive_1"' in texts["reversed"] and 'name="motor1"' not in texts["reversed"]
    notes = {}
    for label, text in texts.items():
        path = tmp_path / label.replace(" ", "_") / "robot.urdf"
        path.parent.mkdir()
        path.write_text(text)
        mechanism = load(path)
        assert mechanism.dof == 2, label
        notes[label] = [note for note in mechanism.assembly_notes if note.startswith(DOF_AT_ROUNDING)]
    assert [a.split(":")[1] for a in load(tmp_path / "reversed" / "robot.urdf").actuator_names] != ["motor1",
                                                                                                "motor2", "motor3"]
    for label, found in notes.items():
        assert found == notes["as written"] and len(found) == 1, (label, found)


@pytest.mark.parametrize("transform", MOVED)
def test_the_rounded_five_bar_in_another_unit_and_frame_with_its_legs_reordered_reads_planar(tmp_path, transform):
    """The onshape five-bar with its hinges tilted by 3e-7 rad, scaled by 1e-3 and 1e3, turned and shifted in the
    world, its legs written in reverse and its motors renamed: planar, and at poses near its home the textbook
    pressure angles, each following its own leg, and the worst single fault the leg the textbook names (to 1e-8). In
    millimetres its plane is 110 of its sizes above the world's origin: the plane's frame, turned about that origin to
    the rounded normal, moved the textbook's points by 1e-5 of its size, and the ITIs by 1.7e-5."""
    names = {0: "drive_c", 1: "drive_a", 2: "drive_b"}
    path = tmp_path / "robot.urdf"
    path.write_text(tilted(five_bar_onshape(transform=transform, order=(2, 1, 0), motor=names.get), 3e-7, 1))
    assert read_mechanism_file(path)[1].planar
    mechanism = load(path)
    assert sorted(name.split(":")[-1] for name in mechanism.actuator_names) == ["drive_a", "drive_b", "drive_c"]
    assert_moved_textbook(mechanism, transform, {name: leg for leg, name in names.items()}.get, tolerance=1e-8)


@pytest.mark.parametrize("decimals", [None, 7, 6])
def test_the_rounded_cad_stewart_platform_is_where_mujoco_puts_it(tmp_path, decimals):
    """The CAD Stewart platform as published and written to 7 and 6 decimals, checked against MuJoCo's own reading
    of each file: at the joint values screwkit solves for three poses about its home (its home among them), MuJoCo
    measures every weld closed and puts the platform's ``tool`` site at the pose, position and roll-pitch-yaw: to
    1e-9 as published, to the rounding (1e-7, 1e-6 m and of a rotation matrix's entries; the file's size is 0.23 m)
    written rounded. MuJoCo reads the rounded geometry as written; screwkit the exact mechanism the rounding hides
    (measured: welds open by 2e-8 and 2.8e-7, the site 2.4e-8 and 1.3e-7 away, away from the home)."""
    source = GALLERY / "gallery" / "stewart_cad.xml"
    path = source if decimals is None else rounded_copy(tmp_path, source, decimals)
    tolerance = 1e-9 if decimals is None else 10.0**-decimals
    mechanism = load(path)
    assert mechanism.task_coordinates == ("x", "y", "z", "roll", "pitch", "yaw")
    poses = mechanism.home_pose + np.array([[0.0] * 6, [0.01, -0.02, 0.015, 0.05, -0.04, 0.1],
                                            [-0.02, 0.01, -0.01, -0.06, 0.03, -0.08]])
    solution = solve(mechanism, poses)
    assert solution.reachable.all()
    model = mujoco.MjModel.from_xml_path(str(path))
    site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "tool")
    for k, pose in enumerate(poses):
        data = mujoco.MjData(model)
        for chain, values in zip(mechanism.chains, solution.joint_values):
            for name, value in zip(chain.joint_names, values[k]):
                joint = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)
                data.qpos[model.jnt_qposadr[joint]] = value
        mujoco.mj_kinematics(model, data)
        for weld, gap in mujoco_residuals(model, data).items():
            assert np.max(np.abs(gap)) < tolerance, (k, weld, gap)
        np.testing.assert_allclose(data.site_xpos[site], pose[:3], atol=tolerance)
        np.testing.assert_allclose(data.site_xmat[site].reshape(3, 3),
                                   Rotation.from_euler("xyz", pose[3:]).as_matrix(), atol=tolerance)


def mjcf_scaled(text: str, factor: float) -> str:
    """An MJCF's lengths times ``factor``: body, geom and site positions, capsules' ends, welds' relative positions and
    slides' ranges (all the CAD Stewart platform has)."""
    def times(values) -> str:
        return " ".join(repr(factor * float(v)) for v in values)

    text = re.sub(r'\b(pos|fromto)="([^"]*)"', lambda m: f'{m.group(1)}="{times(m.group(2).split())}"', text)
    text = re.sub(r'relpose="(\S+) (\S+) (\S+) ', lambda m: f'relpose="{times(m.groups())} ', text)
    return re.sub(r'(type="slide" axis="[^"]*" )range="([^"]*)"', lambda m: f'{m.group(1)}range="'
                  f'{times(m.group(2).split())}"', text)


@pytest.mark.parametrize("factor", [1.0, 1e3, 1e-3])
def test_a_slide_stop_missed_by_the_rounding_is_held_in_any_unit(tmp_path, factor):
    """The CAD Stewart platform with one slider's lower stop written 1e-6 m (3e-6 of its length scale) above where
    it sits: the stop is moved out to the slider's value and the report names it, in metres and with every length x
    1e3 and x 1e-3, and the indices are the unedited file's. A stop 1e-4 m above (3e-4 of the length scale, beyond
    the rounding) is refused in one line naming the file, the joint and its limits."""
    text = mjcf_scaled((GALLERY / "gallery" / "stewart_cad.xml").read_text(), factor)
    stops = {}
    for offset in (1e-6, 1e-4):
        stops[offset] = tmp_path / f"stop_{offset:g}.xml"
        stops[offset].write_text(re.sub(r'(<joint name="s3" type="slide" axis="[^"]*" )range="[^"]*"',
                                        lambda m, low=offset * factor: f'{m.group(1)}range="{low!r} {0.1 * factor!r}"',
                                        text))
    (tmp_path / "as_written.xml").write_text(text)
    written, held = load(tmp_path / "as_written.xml"), load(stops[1e-6])
    assert [note for note in held.import_report if "moved out to" in note and "'s3'" in note], held.import_report
    assert not [note for note in written.import_report if "moved out to" in note]
    first, second = indices_at_pose(written, written.home_pose), indices_at_pose(held, held.home_pose)
    np.testing.assert_allclose(second.iti_actuators, first.iti_actuators, atol=1e-12)
    with pytest.raises(ValueError) as refused:
        load(stops[1e-4])
    message = str(refused.value)
    assert "\n" not in message and stops[1e-4].name in message and "'s3'" in message and "outside its limits" in message
