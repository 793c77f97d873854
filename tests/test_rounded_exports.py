"""Files exported with their numbers rounded read as the mechanism drawn: a planar mechanism whose hinge axes are
parallel only to the file's rounding is planar, and a hinge coaxial with the revolute loop that closes it only to
that rounding is idle.

The checks are against independent computations: the five-bar's textbook pressure angles (Eqs. 30-34 of the paper,
``test_lower_mobility.five_bar_expected``) and Gepetto's published five-bar read from its file as published (its
numbers to 16 digits), against the same file with every number written to 6 decimals.
"""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from test_io import poses_near_home
from test_lower_mobility import five_bar_expected
from test_onshape import five_bar_onshape

from helpers import screwkit
from screwkit.io import read_mechanism_file
from screwkit.io.loader import load
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


def test_a_joint_at_its_stop_beyond_it_by_the_rounding_is_read(tmp_path):
    """The CAD Stewart platform's rod joints are limited to [0, 2 pi] and sit at 0. Written to 7 decimals (its
    upper limit 6.2831853, its assembly putting one rod joint 3e-9 rad below 0) it was refused as outside its
    limits; it reads as the exact file does (home within 1e-7, LMTI within 1e-6), and the report says which limits
    moved and to where."""
    source = Path(__file__).resolve().parent / "data" / "gallery" / "stewart_cad.xml"
    exact = load(source)
    path = rounded_copy(tmp_path, source, 7)
    rounded = load(path)
    assert rounded.dof == exact.dof == 6
    np.testing.assert_allclose(rounded.home_pose, exact.home_pose, atol=1e-7)
    assert abs(indices_at_pose(rounded, rounded.home_pose).lmti - indices_at_pose(exact, exact.home_pose).lmti) < 1e-6
    assert any("limits moved out to" in note for note in rounded.import_report), rounded.import_report


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
