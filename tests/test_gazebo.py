"""URDFs whose loops are closed by Gazebo joints (``<gazebo><joint>``, SDFormat joints inside a URDF).

The five-bar of tests/test_io.py written as a Gazebo user writes it: the tree of its legs in URDF, each further
leg's distal link joined to leg 1's by a revolute SDFormat joint (pose in the child link's frame, axis in the
joint's), with and without ``<transmission>`` elements; checked against the textbook pressure angles.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from test_io import HOME, assert_textbook, assert_three_leg_five_bar, poses_near_home, text
from test_lower_mobility import DISTAL, five_bar_expected
from test_onshape import MOVED, assert_moved_textbook, five_bar_links, onshape_urdf

from helpers import one_line_error, screwkit
from screwkit.common.rotations import rotation_from_rpy
from screwkit.io import ImportError_, read_closed_tree, read_mechanism_file
from screwkit.io.loader import load
from screwkit.studies.poses import indices_at_poses

EFFECTOR_RPY = (np.pi, 0.0, 0.3)


def five_bar_gazebo(legs: int = 3, kind: str = "revolute", transmissions: bool = True, pose_rpy=(0.0, 0.0, 0.4),
                    transform=(1.0, 0.0, (0.0, 0.0, 0.0)), order=None, motor=None, model_axis: str = ""):
    """The five-bar's tree and one Gazebo joint per further leg, its child the ``effector`` link (on distal_1 at the
    output point, turned upside down and about its normal): the pose is the joint frame in that link, turned by
    ``pose_rpy``, and the axis is written in the joint frame so that it is the plane's normal. Read in the parent
    link's frame instead (distal_i, whose origin is its elbow), the loops would not close where they do. Moved by
    ``transform``, legs written in ``order``, motors named ``motor(i)``, as :func:`test_onshape.five_bar_links`.
    ``model_axis``: the axis written as the normal in the model's frame instead, by ``<use_parent_model_frame>``
    ("element") or ``expressed_in="__model__"`` ("attribute")."""
    motor = motor or (lambda i: f"mot{i + 1}")
    names = (lambda i: f"proximal_{i + 1}", motor, lambda i: f"distal_{i + 1}", lambda i: f"free{i + 1}")
    links = five_bar_links(legs, names, transform, order)
    urdf = onshape_urdf(links, [("effector", "distal_1", (transform[0] * DISTAL, 0.0, 0.0), EFFECTOR_RPY)])
    joint_in_distal = rotation_from_rpy(np.array(EFFECTOR_RPY)) @ rotation_from_rpy(np.array(pose_rpy))
    axis = joint_in_distal.T @ np.array([0.0, 0.0, 1.0])  # distal_1's z is the plane's normal
    written = {"": f"<xyz>{text(axis)}</xyz>", "attribute": '<xyz expressed_in="__model__">0 0 1</xyz>',
               "element": "<xyz>0 0 1</xyz><use_parent_model_frame>1</use_parent_model_frame>"}[model_axis]
    joints = "".join(
        f'<joint name="loop_{i + 1}" type="{kind}"><parent>distal_{i + 1}</parent><child>effector</child>'
        f'<pose>0 0 0 {text(pose_rpy)}</pose><axis>{written}</axis></joint>'
        for i in range(1, legs))
    extra = f"<gazebo>{joints}</gazebo>"
    if transmissions:
        extra += "".join(f'<transmission name="t{i + 1}"><type>transmission_interface/SimpleTransmission</type>'
                         f'<joint name="{motor(i)}"/></transmission>' for i in range(legs))
    return urdf.replace("</robot>", extra + "</robot>")


@pytest.mark.parametrize("transmissions", [True, False])
def test_a_five_bar_closed_by_gazebo_joints_has_the_textbook_pressure_angles(tmp_path, transmissions):
    path = tmp_path / "robot.urdf"
    path.write_text(five_bar_gazebo(transmissions=transmissions))
    converted, report = read_mechanism_file(path)
    assert report.file_format == "URDF + Gazebo joints (<gazebo><joint>)" and report.planar
    assert report.motors == ["mot1", "mot2", "mot3"]
    assert any("the hinge through them" in note for note in report.notes), report.notes
    guessed = any("actuators guessed" in note for note in report.notes)
    assert guessed is not transmissions
    assert_three_leg_five_bar(path)


@pytest.mark.parametrize("transform", MOVED)
def test_a_gazebo_five_bar_in_another_unit_and_frame_with_its_legs_reordered_and_renamed(tmp_path, transform):
    """Scaled by 1e-3 and 1e3, turned and shifted in the world, legs written in reverse and motors renamed: the same
    pressure angles, each following its own leg (the hinge's second point is placed at the file's own scale)."""
    path = tmp_path / "robot.urdf"
    names = {0: "drive_c", 1: "drive_a", 2: "drive_b"}
    path.write_text(five_bar_gazebo(transform=transform, order=(2, 1, 0), motor=names.get))
    assert_moved_textbook(load(path), transform, {name: leg for leg, name in names.items()}.get)


def test_ball_gazebo_joints_close_the_five_bar_too(tmp_path):
    path = tmp_path / "robot.urdf"
    path.write_text(five_bar_gazebo(kind="ball"))
    mechanism = load(path)
    points = poses_near_home()
    assert_textbook(indices_at_poses(mechanism, points, detail=True), points)


def test_a_gazebo_joint_of_a_type_that_cannot_close_a_loop_or_naming_no_link_is_refused_by_name(tmp_path):
    path = tmp_path / "robot.urdf"
    path.write_text(five_bar_gazebo(kind="screw"))
    with pytest.raises(ImportError_, match=r"<gazebo><joint name='loop_2'>: type 'screw' cannot close a loop here"):
        read_closed_tree(path)
    path.write_text(five_bar_gazebo().replace("<parent>distal_3</parent>", "<parent>distal_9</parent>"))
    with pytest.raises(ImportError_, match=r"<gazebo><joint name='loop_3'>: <parent> names 'distal_9', not a link"):
        read_closed_tree(path)


def test_convert_and_analyze_open_a_gazebo_closed_urdf_on_the_command_line(tmp_path):
    """The commands users run: convert writes the mechanism in screwkit's convention, analyze of the source and of
    the written file give the textbook LMTI, and a bad Gazebo joint is one line."""
    path = tmp_path / "robot.urdf"
    path.write_text(five_bar_gazebo())
    written = tmp_path / "converted.urdf"
    converted = screwkit("convert", path, written, "--json")
    assert converted.returncode == 0, converted.stderr
    assert json.loads(converted.stdout)["format"] == "URDF + Gazebo joints (<gazebo><joint>)"
    expected = five_bar_expected(HOME)["lmti"]
    for source in (path, written):
        analysed = screwkit("analyze", source, "--json")
        assert analysed.returncode == 0, analysed.stderr
        assert json.loads(analysed.stdout)["lmti"] == pytest.approx(expected, abs=1e-9)
    path.write_text(five_bar_gazebo(kind="screw"))
    one_line_error(screwkit("analyze", path), "<gazebo><joint name='loop_2'>: type 'screw' cannot close a loop")


def test_a_pose_or_axis_written_in_another_frame_is_refused_rather_than_misread(tmp_path):
    path = tmp_path / "robot.urdf"
    path.write_text(five_bar_gazebo().replace("<pose>", '<pose relative_to="distal_2">', 1))
    with pytest.raises(ImportError_, match=r"loop_2'>: a pose relative_to or an axis expressed_in another frame"):
        read_closed_tree(path)
    path.write_text(five_bar_gazebo().replace("<xyz>", '<xyz expressed_in="distal_2">', 1))
    with pytest.raises(ImportError_, match=r"loop_2'>: a pose relative_to or an axis expressed_in another frame"):
        read_closed_tree(path)
    path.write_text(five_bar_gazebo().replace("<pose>", '<pose relative_to="effector">', 1))
    read_closed_tree(path)  # the child link named explicitly: the default


@pytest.mark.parametrize("written", ["element", "attribute"])
@pytest.mark.parametrize("transform", MOVED)
def test_an_axis_written_in_the_model_frame_is_read_there(tmp_path, transform, written):
    """The plane's normal written as the model's z (``<use_parent_model_frame>``, SDFormat 1.5 and 1.6, or
    ``expressed_in="__model__"``), each joint frame tilted off the plane: the textbook pressure angles, scaled and
    turned in the world. The element was dropped without a word (the axis read in the tilted joint frame: the loops
    rigid), the attribute refused; the report says where Gazebo's conversion to SDFormat 1.7 reads the element
    otherwise. The legs written in reverse and the motors renamed, as above."""
    path = tmp_path / "robot.urdf"
    names = {0: "drive_c", 1: "drive_a", 2: "drive_b"}
    path.write_text(five_bar_gazebo(transform=transform, pose_rpy=(0.3, -0.2, 0.4), model_axis=written,
                                    order=(2, 1, 0), motor=names.get))
    assert_moved_textbook(load(path), transform, {name: leg for leg, name in names.items()}.get)
    _, report = read_mechanism_file(path)
    said = [note for note in report.notes if "as <use_parent_model_frame> asks" in note]
    assert len(said) == (2 if written == "element" else 0), report.notes
