"""URDFs whose loops are closed by Drake's ball constraints (``<drake:ball_constraint>``, :mod:`screwkit.io.drake`).

The five-bar of tests/test_io.py written as a Drake user writes it: the tree of its legs in URDF, each further leg's
distal link tied to the effector by a ball constraint (P at the distal link's far end, in its frame; Q the effector's
origin). Such files were read as trees with no loop and refused; the closures, and Drake's other elements, were not
mentioned. Checked against the textbook pressure angles (as the same five-bar closed by Gazebo joints), in other units,
frames and leg orders; Drake's implicit ``world``, an undeclared ``drake:`` prefix and ``--`` in a comment (which
Drake and every tinyxml2 reader take) read; a closure Drake has and screwkit does not read refused by name.
"""

from __future__ import annotations

import pytest
from test_io import assert_textbook, assert_three_leg_five_bar, poses_near_home, text
from test_lower_mobility import DISTAL
from test_onshape import MOVED, assert_moved_textbook, five_bar_links, onshape_urdf

from helpers import one_line_error, screwkit
from screwkit.io import ImportError_, read_closed_tree, read_mechanism_file
from screwkit.io.loader import load
from screwkit.studies.poses import indices_at_poses

DECLARED = ' xmlns:drake="http://drake.mit.edu"'


def five_bar_drake(legs: int = 3, transform=(1.0, 0.0, (0.0, 0.0, 0.0)), order=None, motor=None, declare=True,
                   transmissions=True) -> str:
    """The five-bar's tree (onshape_urdf links, the effector on distal_1 at the output point) and one ball constraint
    per further leg: P at distal_i's far end (its x axis points there as drawn), Q the effector's origin."""
    motor = motor or (lambda i: f"mot{i + 1}")
    names = (lambda i: f"proximal_{i + 1}", motor, lambda i: f"distal_{i + 1}", lambda i: f"free{i + 1}")
    links = five_bar_links(legs, names, transform, order)
    urdf = onshape_urdf(links, [("effector", "distal_1", (transform[0] * DISTAL, 0.0, 0.0), (0.0, 0.0, 0.0))])
    far = (transform[0] * DISTAL, 0.0, 0.0)
    constraints = "".join(
        f'<drake:ball_constraint><drake:ball_constraint_body_A name="distal_{i + 1}"/>'
        f'<drake:ball_constraint_body_B name="effector"/><drake:ball_constraint_p_AP value="{text(far)}"/>'
        '<drake:ball_constraint_p_BQ value="0 0 0"/></drake:ball_constraint>' for i in range(1, legs))
    if transmissions:
        constraints += "".join(f'<transmission name="t{i + 1}"><type>SimpleTransmission</type>'
                               f'<joint name="{motor(i)}"/></transmission>' for i in range(legs))
    urdf = urdf.replace("</robot>", constraints + "</robot>")
    return urdf.replace("<robot ", "<robot" + DECLARED + " ", 1) if declare else urdf


def test_a_five_bar_closed_by_drake_ball_constraints_has_the_textbook_pressure_angles(tmp_path):
    path = tmp_path / "robot.urdf"
    path.write_text(five_bar_drake())
    converted, report = read_mechanism_file(path)
    assert report.file_format == "URDF + Drake ball constraints (<drake:ball_constraint>)" and report.planar
    assert report.motors == ["mot1", "mot2", "mot3"]
    assert all(gap < 1e-12 for gap in report.gaps_before.values())  # the drawing closes the loops
    assert_three_leg_five_bar(path)


@pytest.mark.parametrize("transform", MOVED)
def test_a_drake_five_bar_in_another_unit_and_frame_with_its_legs_reordered_and_renamed(tmp_path, transform):
    path = tmp_path / "robot.urdf"
    names = {0: "drive_c", 1: "drive_a", 2: "drive_b"}
    path.write_text(five_bar_drake(transform=transform, order=(2, 1, 0), motor=names.get))
    assert_moved_textbook(load(path), transform, {name: leg for leg, name in names.items()}.get)


def test_drake_s_implicit_world_an_undeclared_prefix_and_a_drawing_in_a_comment_are_read(tmp_path):
    """Drake leaves ``world`` implicit; a file may use the ``drake:`` prefix without declaring it and draw the
    mechanism in a comment with ``--`` (a published Drake four-bar does both): Drake reads such files, and so do
    tinyxml2 (Gazebo, MuJoCo) and Pinocchio; Python's XML parser refused them as not well-formed."""
    text_ = five_bar_drake(declare=False, transmissions=False)
    assert "<link name=\"world\"" not in text_ and "xmlns:drake" not in text_
    root = text_.index(">", text_.index("<robot")) + 1
    text_ = text_[:root] + "<!-- A *----* B, the loop -- closed at B --->" + text_[root:]
    first = text_.index("<joint ")
    fixed = '<joint name="to_world" type="fixed"><parent link="world"/><child link="base"/></joint>'
    text_ = text_[:first] + fixed + text_[first:]
    path = tmp_path / "robot.urdf"
    path.write_text(text_)
    tree = read_closed_tree(path)
    assert [closure.name for closure in tree.closures] == ["ball_constraint_1", "ball_constraint_2"]
    assert any("actuators guessed" in note for note in tree.notes)
    points = poses_near_home()
    assert_textbook(indices_at_poses(load(path), points, detail=True), points)


def test_a_closure_drake_has_and_screwkit_does_not_read_is_refused_by_name(tmp_path):
    path = tmp_path / "robot.urdf"
    weld = ('<drake:weld_constraint><drake:weld_constraint_body_A name="distal_2"/>'
            '<drake:weld_constraint_body_B name="effector"/></drake:weld_constraint>')
    path.write_text(five_bar_drake().replace("</robot>", weld + "</robot>"))
    with pytest.raises(ImportError_, match=r"robot\.urdf: <drake:weld_constraint>, Drake's own, joins bodies in a "
                                           r"way screwkit does not read \(it reads <drake:ball_constraint>\)"):
        read_closed_tree(path)
    path.write_text(five_bar_drake().replace('name="effector"/><drake:ball', 'name="nowhere"/><drake:ball', 1))
    with pytest.raises(ImportError_, match=r"<drake:ball_constraint> 1: <drake:ball_constraint_body_B "
                                           r"name='nowhere'>: no link of that name"):
        read_closed_tree(path)
    path.write_text(five_bar_drake().replace('value="0 0 0"', 'value="0 0"', 1))
    with pytest.raises(ImportError_, match=r"<drake:ball_constraint_p_BQ value='0 0'>: expected three finite numbers"):
        read_closed_tree(path)


def test_the_command_analyses_a_drake_five_bar(tmp_path):
    path = tmp_path / "robot.urdf"
    path.write_text(five_bar_drake())
    done = screwkit("analyze", path)
    assert done.returncode == 0, done.stderr
    assert "3 actuators, 2 DOF (1 redundant)" in done.stdout
    assert "URDF + Drake ball constraints" in done.stderr
    weld = '<drake:linear_bushing_rpy><drake:bushing_frameA name="x"/></drake:linear_bushing_rpy>'
    path.write_text(five_bar_drake().replace("</robot>", weld + "</robot>"))
    one_line_error(screwkit("analyze", path), "robot.urdf: <drake:linear_bushing_rpy>, Drake's own, joins bodies")


def sdformat_five_bar_drake(transform=(1.0, 0.0, (0.0, 0.0, 0.0))) -> str:
    """The SDFormat five-bar (tests/sdformat_models.py) with the loops of legs 2 and 3 written as Drake's ball
    constraints onto the effector (P at the distal link's far end, Q the effector's origin) instead of revolute
    joints."""
    import re

    from sdformat_models import five_bar_sdf

    text_ = five_bar_sdf(transform=transform, marker="")
    for leg in (2, 3):
        text_, count = re.subn(rf'<joint name="loop_{leg}" type="revolute">.*?</joint>', "", text_)
        assert count == 1
    balls = "".join(
        f"<drake:ball_constraint><drake:ball_constraint_body_A>distal_{leg}</drake:ball_constraint_body_A>"
        f"<drake:ball_constraint_p_AP>{text((transform[0] * DISTAL, 0.0, 0.0))}</drake:ball_constraint_p_AP>"
        "<drake:ball_constraint_body_B>effector</drake:ball_constraint_body_B>"
        "<drake:ball_constraint_p_BQ>0 0 0</drake:ball_constraint_p_BQ></drake:ball_constraint>" for leg in (2, 3))
    return text_.replace("</model>", balls + "</model>", 1)


@pytest.mark.parametrize("transform", MOVED)
def test_an_sdformat_drake_five_bar_in_another_unit_and_frame(tmp_path, transform):
    path = tmp_path / "robot.sdf"
    path.write_text(sdformat_five_bar_drake(transform))
    assert_moved_textbook(load(path), transform, {f"mot{leg + 1}": leg for leg in range(3)}.get)


def test_an_sdformat_five_bar_closed_by_drake_ball_constraints_has_the_textbook_pressure_angles(tmp_path):
    """The SDFormat five-bar with its legs 2 and 3 closed onto the effector by Drake's ball constraints (the links'
    names and P, Q as the elements' text) instead of revolute joints: the textbook pressure angles. Before, they
    were left out (the model a tree, refused); a bushing is refused naming it."""
    path = tmp_path / "robot.sdf"
    written = sdformat_five_bar_drake()
    path.write_text(written)
    tree = read_closed_tree(path)
    assert [closure.name for closure in tree.closures if closure.name.startswith("ball")] == ["ball_constraint_1",
                                                                                           "ball_constraint_2"]
    assert_three_leg_five_bar(path)
    bushing = ('<drake:linear_bushing_rpy><drake:bushing_frameA>distal_2</drake:bushing_frameA>'
               '</drake:linear_bushing_rpy>')
    path.write_text(written.replace("</model>", bushing + "</model>", 1))
    with pytest.raises(ImportError_, match=r"robot\.sdf: <model name='\w+'>: <drake:linear_bushing_rpy>, Drake's own, "
                                           r"joins links in a way screwkit does not read"):
        read_closed_tree(path)
    path.write_text(written.replace("<drake:ball_constraint_body_A>distal_3", "<drake:ball_constraint_body_A>nowhere"))
    with pytest.raises(ImportError_, match=r"<drake:ball_constraint> 2: <drake:ball_constraint_body_A> 'nowhere' is no "
                                           r"link of the model"):
        read_closed_tree(path)


def test_a_drake_joint_is_refused_naming_it(tmp_path):
    """A joint of Drake's own (``drake:joint``, e.g. planar) is skipped by Pinocchio: its child link read as a free
    body, the refusal said so; it is refused as what it is."""
    path = tmp_path / "robot.urdf"
    joint = ('<drake:joint name="slide" type="planar"><drake:parent link="effector"/><drake:child link="extra"/>'
             '</drake:joint><link name="extra"/>')
    path.write_text(five_bar_drake().replace("</robot>", joint + "</robot>"))
    with pytest.raises(ImportError_, match=r"robot\.urdf: <drake:joint>, Drake's own, joins bodies"):
        read_closed_tree(path)


def test_a_link_drake_leaves_free_is_refused_naming_it(tmp_path):
    """A link no joint holds is a free body to Drake (the published Strandbeest's crossbar); Pinocchio's URDF reader
    refused the file with lines of its own. It is refused in one line naming the roots."""
    path = tmp_path / "robot.urdf"
    path.write_text(five_bar_drake().replace("</robot>", '<link name="crossbar"/></robot>'))
    with pytest.raises(ImportError_, match=r"robot\.urdf: links 'base', 'crossbar' are no joint's child: Drake makes "
                                           r"each but the first a free body"):
        read_closed_tree(path)
