"""MJCF class defaults, several default sections, sites given by ``fromto``, bodies with several joints, free bodies
and nested includes, read as MuJoCo reads them.

Every placement is checked against MuJoCo's own reading of the same file (``assert_placed_as_mujoco``: every body and
site at ``qpos0`` and at a random configuration), every index against the same robot written plainly (the five-bar's
closed-form pressure angles, the gallery's Stewart platform), every refusal against MuJoCo's refusal of the file.
"""

from __future__ import annotations

import re
from xml.etree import ElementTree

import mujoco
import numpy as np
import pytest
from test_io import HOME, five_bar_mjcf
from test_lower_mobility import five_bar_expected
from test_mjcf_reading import INERTIA, STEWART, assert_placed_as_mujoco, assert_the_stewart_platform, written

from helpers import one_line_error, random_rotation, screwkit
from screwkit.io import ImportError_, read_mechanism_file
from screwkit.io.loader import load
from screwkit.io.mjcf import read_mjcf
from screwkit.studies.poses import indices_at_pose

SECTIONS = """<mujoco model="sections"><compiler angle="radian"/>
<default><site euler="0 0 1" pos="0 0 1"/><joint pos="0 0.02 0"/><default class="a"><site pos="0.1 0 0"/></default>
</default>
<default><site pos="0 0.1 0"/><joint axis="0.6 0 0.8"/><default class="b"><joint pos="0.03 0 0"/></default></default>
<worldbody><body name="b0" pos="0.1 0 0">""" + INERTIA + """<joint name="j0"/><site name="s0"/>
 <body name="b1" pos="0.3 0 0" childclass="b">""" + INERTIA + """<joint name="j1"/><site name="sa" class="a"/>
  <site name="sb"/></body></body></worldbody><actuator><motor joint="j0"/><motor joint="j1"/></actuator></mujoco>"""
"""Two top-level default sections, each with attributes of the top class (one of them in both) and a class."""


def test_several_default_sections_are_one_top_class_as_mujoco_reads_them(tmp_path):
    """MuJoCo reads every top-level ``<default>`` as the top class, a later section's attributes winning, and a
    class inherits the top class as it stands when its section is read; screwkit read only the first section's
    (Pinocchio's reading): bodies and sites off by up to the length of the chain."""
    assert assert_placed_as_mujoco(written(tmp_path, SECTIONS)) == 2 * (2 + 3)


def test_a_five_bar_whose_hinge_axes_come_from_a_second_default_section_has_the_textbook_angles(tmp_path):
    """The five-bar turned in space, its hinges given no axis and the pins' axis given in a second default section
    (as a file that includes a defaults file has it): the textbook pressure angles near home (before, every hinge
    turned about z: an ITI of 0.961 for 0.9998)."""
    rotation = random_rotation(np.random.default_rng(5))
    text = five_bar_mjcf(rotation)
    axis = re.search(r' axis="([^"]+)"', text).group(1)
    text = text.replace(f' axis="{axis}"', "").replace(
        '<compiler angle="radian"/>', f'<compiler angle="radian"/><default><joint damping="0.1"/></default>'
                                      f'<default><joint axis="{axis}"/></default>')
    assert "axis" not in text.split("</default>")[-1]
    path = written(tmp_path, text, "sections.xml")
    assert_placed_as_mujoco(path)
    mechanism = load(path)
    result = indices_at_pose(mechanism, mechanism.home_pose)
    expected = five_bar_expected(HOME)
    np.testing.assert_allclose(result.iti_actuators, expected["iti_actuators"], atol=1e-9)
    np.testing.assert_allclose([result.lmti, result.f_o[1]], [expected["lmti"], expected["f_o1"]], atol=1e-9)


FROMTO = """<mujoco model="fromto"><compiler angle="radian"/>
<default><default class="rod"><site type="capsule" size="0.01" fromto="0.1 0.2 0.3 0.3 0 0.1"/></default></default>
<worldbody><body name="b0" pos="0.1 0 0" quat="0.9 0.1 0.3 0.2">""" + INERTIA + """<joint name="j0" axis="0 0 1"/>
 <site name="by_class" class="rod"/><site name="own_turn_ignored" class="rod" quat="0 1 0 0"/>
 <frame pos="0.05 0.1 0" euler="0.3 0.2 0.1"><site name="in_frame" class="rod"/>
  <site name="own_in_frame" type="box" size="0.01 0.01 0.01" fromto="0 0 0 0 0.2 0.1"/></frame>
 <body name="b1" pos="0.3 0 0" childclass="rod">""" + INERTIA + """<joint name="j1" axis="0 1 0"/>
  <site name="by_child"/></body></body></worldbody>
<actuator><motor joint="j0"/><motor joint="j1"/></actuator></mujoco>"""
"""Sites placed by a ``fromto`` from a class (by ``class`` and by ``childclass``), one with an orientation of its own
that the segment overrides, and two inside a turned frame."""


def test_sites_given_by_a_fromto_of_their_class_or_in_a_frame_are_placed_as_mujoco_places_them(tmp_path):
    """Before, a class's ``fromto`` was not read (the site sat at its body's origin) and a site with a ``fromto``
    inside a ``<frame>`` was refused by Pinocchio ('both pos and fromto')."""
    assert assert_placed_as_mujoco(written(tmp_path, FROMTO)) == 2 * (2 + 5)


def test_a_stewart_platform_whose_output_site_comes_from_a_class_fromto_is_the_same_robot(tmp_path):
    """The CAD Stewart platform's output site ``tool`` given by a class's ``fromto``: a short segment along the
    platform's z, centred where the file has the site, which turns the site by nothing (MuJoCo turns a site's z to
    point from the segment's end to its start). The same home pose and indices as the file (before, ``tool`` sat
    0.118 m away, at the platform body's origin)."""
    site = re.search(r'<site name="tool" pos="([^"]+)"/>', STEWART.read_text())
    x, y, z = (float(word) for word in site.group(1).split())
    segment = f"{x!r} {y!r} {z + 0.01!r} {x!r} {y!r} {z - 0.01!r}"
    text = STEWART.read_text().replace(site.group(0), '<site name="tool" class="tip"/>').replace(
        '<default class="spin">', f'<default class="tip"><site type="capsule" size="0.005" fromto="{segment}"/>'
                                  '</default><default class="spin">')
    path = written(tmp_path, text, "stewart_class_fromto.xml")
    assert assert_placed_as_mujoco(path) == assert_placed_as_mujoco(STEWART)
    assert_the_stewart_platform(path, seed=3, count=12)


def merged_joints(text: str) -> str:
    """The MJCF with every body of one joint and no site whose only child body has one joint and sits at its origin
    unturned merged into that child (which keeps its name and takes the body's place and joint, first): a universal
    joint written as two hinges in one body, a cylindrical joint as a slide and a hinge. The same robot for MuJoCo."""
    root = ElementTree.fromstring(text)
    parents = {child: parent for parent in root.iter() for child in parent}
    for body in list(root.iter("body")):
        children = body.findall("body")
        joints = body.findall("joint")
        if len(children) != 1 or len(joints) != 1 or body.findall("site") or body not in parents:
            continue
        inner = children[0]
        if len(inner.findall("joint")) != 1 or inner.get("quat") or inner.get("pos", "0 0 0") != "0 0 0":
            continue
        inner.insert(0, joints[0])
        inner.set("pos", body.get("pos", "0 0 0"))
        parent = parents[body]
        parent.insert(list(parent).index(body), inner)
        parent.remove(body)
        parents[inner] = parent
    return ElementTree.tostring(root, encoding="unicode")


def test_a_stewart_platform_written_with_several_joints_per_body_is_the_same_robot(tmp_path):
    """The CAD Stewart platform with each universal joint written as two hinges in one body and each piston as a
    slide and a hinge in one (MuJoCo turns a body by its joints in order, each in the frame the joints before it
    turned). Pinocchio makes one composite joint of each, which moved the bodies elsewhere at any configuration but
    the file's; screwkit writes them as nested bodies: the bodies where MuJoCo has them, the same indices."""
    text = merged_joints(STEWART.read_text())
    assert len(re.findall(r"<body ", text)) == 38 - 18
    path = written(tmp_path, text, "stewart_merged.xml")
    assert assert_placed_as_mujoco(path) == 2 * (20 + 1)  # 20 bodies (and the world), the output site
    assert_the_stewart_platform(path, seed=4, count=12)
    _, report = read_mechanism_file(path)
    assert any("bodies with several joints (cylinder1, piston1, UJ1," in note for note in report.notes), report.notes


JOINTS = """<mujoco model="joints"><compiler angle="radian"/><worldbody>
 <body name="arm" pos="0.1 0.2 0.3" quat="0.9 0.1 0.3 0.2">""" + INERTIA + """
  <joint name="h" axis="0.6 0.8 0" pos="0.05 0 0"/><joint name="s" type="slide" axis="0 0 1" pos="0 0.1 0"/>
  <joint name="b" type="ball" pos="0.02 0.03 0"/><site name="on_arm" pos="0.1 0 0"/>
  <body name="hand" pos="0.2 0 0">""" + INERTIA + """<joint name="h2" axis="1 0 0"/><site name="tip" pos="0 0.1 0"/>
  </body></body>
 <body name="free" pos="0.4 0.5 0.6" euler="0 0.4 1.2">""" + INERTIA + """<freejoint name="f"/>
  <site name="on_free" pos="0.1 0 0"/></body></worldbody>
<actuator><motor joint="h"/><motor joint="h2"/></actuator></mujoco>"""
"""A body turned by a hinge, a slide and a ball joint, each about its own point, and a free body turned and moved."""


def test_bodies_with_several_joints_and_a_turned_free_body_are_placed_as_mujoco_places_them(tmp_path):
    """Before, the three joints of ``arm`` were one composite joint (bodies off at any other configuration) and the
    free body sat (I - R) p away from where MuJoCo has it."""
    assert assert_placed_as_mujoco(written(tmp_path, JOINTS)) == 2 * (3 + 3)


def test_nested_includes_are_found_from_the_main_files_folder_as_mujoco_finds_them(tmp_path):
    """A file included by an included file is looked for in the main file's folder (MuJoCo's rule), not beside the
    file that includes it; a decoy beside that one is not read."""
    (tmp_path / "sub").mkdir()
    written(tmp_path, f'<mujoco><body name="tip" pos="0.1 0 0">{INERTIA}<site name="found"/></body></mujoco>',
            "tip.xml")
    written(tmp_path / "sub", f'<mujoco><body name="tip" pos="0 0.3 0">{INERTIA}<site name="decoy"/></body>'
            "</mujoco>", "tip.xml")
    written(tmp_path / "sub", f'<mujoco><body name="leg" pos="0.2 0 0">{INERTIA}<joint name="j1"/>'
            '<include file="tip.xml"/></body></mujoco>', "leg.xml")
    main = written(tmp_path, f'<mujoco><worldbody><body name="base">{INERTIA}<joint name="j0"/>'
                   '<include file="sub/leg.xml"/></body></worldbody><actuator><motor joint="j0"/></actuator></mujoco>',
                   "main.xml")
    assert assert_placed_as_mujoco(main) == 2 * (3 + 1)
    assert read_mjcf(main).model.existFrame("found")


@pytest.mark.parametrize("old, new, problem", [
    ('<joint name="j1"/><site name="sa" class="a"/>', '<joint name="j1" class="main"/><site name="sa" class="main"/>',
     None),
    ('<default><site euler', '<default class="main"><site euler', None),
])
def test_the_top_class_named_main_is_read_as_mujoco_reads_it(tmp_path, old, new, problem):
    """MuJoCo names the top class ``main``; a file may name it on an element or on the top ``<default>``
    (Pinocchio refused both: 'unordered_map::at')."""
    assert old in SECTIONS
    assert assert_placed_as_mujoco(written(tmp_path, SECTIONS.replace(old, new, 1))) == 2 * (2 + 3)


CLASSES_AND_BODIES = """<mujoco model="classes"><compiler angle="degree"/>
<default><default class="early"><site size="0.01"/></default></default>
<default><joint pos="0 0.03 0" axis="1 0 0"/><site pos="0 0.2 0"/>
 <default class="k"><joint type="slide" axis="0 1 0" pos="0.01 0 0" ref="10"/></default></default>
<worldbody>
 <body name="arm" pos="0.1 0.2 0.3" childclass="k">""" + INERTIA + """<joint name="h" class="main" axis="0 0 1"/>
  <joint name="early" class="early"/><site name="on_arm" class="early"/><site name="own" class="main"/>
  <body name="hand" pos="0.2 0 0">""" + INERTIA + """<joint name="slide"/><site name="tip" pos="0 0.1 0"/>
   <body pos="0.1 0.1 0" quat="0.9 0.1 0.3 0.2">""" + INERTIA + """<joint name="u1" class="main" pos="0.05 0 0"/>
    <joint name="u2" class="main" axis="0 1 0"/><site name="in_unnamed" pos="0.1 0 0"/>
    <body name="last" pos="0.2 0 0">""" + INERTIA + """<joint name="end" class="main"/><site name="end_tip"/></body>
   </body></body></body>
 <body name="free" pos="0.4 0.5 0.6" euler="0 20 70">""" + INERTIA + """<joint name="f" type="free" pos="0.1 0.2 0.3"/>
  <site name="on_free" pos="0.1 0 0"/></body>
</worldbody><actuator><motor joint="h"/><motor joint="slide"/></actuator></mujoco>"""
"""A joint and a site of the top class in a body whose ``childclass`` is a slide with a ``ref`` (in degrees: a
slide's ``ref`` is a length), a class read before a later section changed the top class, an unnamed body with two
hinges inside another, and a free joint with a ``pos`` on a turned body."""


def test_classes_unnamed_bodies_and_a_free_joint_s_pos_are_read_as_mujoco_reads_them(tmp_path):
    """Each of these was read otherwise (the second read of this change): Pinocchio took the body's childclass for a
    joint of ``class="main"`` (a slide for a hinge), a class of an earlier section took the later section's top
    class (MuJoCo copies the top class as it stands when it reads a class), Pinocchio dropped an unnamed body
    inside another with its joints and sites, offset a free body by its joint's ``pos``, and a slide's ``ref`` from a
    class was converted from degrees as an angle. Every body and site where MuJoCo has it, and the reference
    configuration MuJoCo's ``qpos0``."""
    path = written(tmp_path, CLASSES_AND_BODIES)
    assert assert_placed_as_mujoco(path) == 2 * (4 + 6)  # the named bodies and every site
    mj_model, tree = mujoco.MjModel.from_xml_path(str(path)), read_mjcf(path)
    # the unnamed body named after its first joint, a name a reader finds in the file (messages name bodies)
    assert "u1_body" in [frame.name for frame in tree.model.frames]
    for name in ("h", "early", "slide", "u1", "u2", "end"):
        joint = mujoco.mj_name2id(mj_model, mujoco.mjtObj.mjOBJ_JOINT, name)
        position = tree.model.joints[tree.model.getJointId(name)].idx_q
        assert tree.q_reference[position] == pytest.approx(mj_model.qpos0[mj_model.jnt_qposadr[joint]], abs=1e-12)


LIMITS = """<mujoco model="limits"><compiler angle="degree"/>
<default><joint axis="0 1 0" limited="true" range="-30 30"/><default class="early"><joint damping="1"/></default>
 <default class="hg"><joint ref="20" springref="10"/><default class="bl"><joint type="ball" range="0 45"/></default>
 </default></default>
<default><default class="late"><joint damping="2"/></default><joint axis="1 0 0"/>
 <default class="sl"><joint type="slide" axis="0 0 1" range="-0.1 0.2"/></default></default>
<worldbody><body name="b1">""" + INERTIA + """<joint name="early" class="early"/>
 <body name="b2" pos="0.3 0 0">""" + INERTIA + """<joint name="late" class="late"/>
  <body name="b3" pos="0.3 0 0" childclass="hg">""" + INERTIA + """<joint name="hinge_ref" ref="10"/>
   <body name="b4" pos="0.2 0 0">""" + INERTIA + """<joint name="ball" class="bl"/>
    <body name="b5" pos="0.2 0 0">""" + INERTIA + """<joint name="slide" class="sl" ref="0.05"/>
     <site name="tip" pos="0.1 0.1 0"/></body></body></body></body></body></worldbody>
<keyframe><key name="home" qpos="0.1 0.2 0.3 1 0 0 0 0.06"/></keyframe>
<actuator><motor joint="early"/><motor joint="slide"/></actuator></mujoco>"""
"""A later default section whose class comes before its own joint defaults (the class takes them: MuJoCo reads a
section's element defaults first), a ball joint of a class under one with a ``ref``, limits from classes in degrees
on joints with a ``ref`` of their own."""


def test_limits_refs_and_a_later_section_s_classes_are_read_as_mujoco_reads_them(tmp_path):
    """The third read of this change: a later section's class took the top class as it stood before the section's
    own joint defaults (bodies 0.84 m off), Pinocchio shifts a joint's limits by its ``ref`` (a hinge MuJoCo limits
    to [0.4, 0.6] and starts at 0.5 was refused as outside [-0.1, 0.1]), and refused a ball joint whose class
    inherits a ``ref``. Every body and site where MuJoCo has it, and every hinge's and slide's limits MuJoCo's."""
    path = written(tmp_path, LIMITS)
    assert assert_placed_as_mujoco(path) == 2 * (5 + 1)
    mj_model, model = mujoco.MjModel.from_xml_path(str(path)), read_mjcf(path).model
    for joint in range(mj_model.njnt):
        if int(mj_model.jnt_type[joint]) in (int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE)):
            name = mujoco.mj_id2name(mj_model, mujoco.mjtObj.mjOBJ_JOINT, joint)
            index = model.joints[model.getJointId(name)].idx_q
            np.testing.assert_allclose([model.lowerPositionLimit[index], model.upperPositionLimit[index]],
                                       mj_model.jnt_range[joint], rtol=0, atol=1e-12, err_msg=name)


REFUSED = {
    "a pos and a class fromto": ('<site name="by_class" class="rod"/>',
                                 '<site name="by_class" class="rod" pos="0 0 1"/>',
                                 "<site name='by_class'>: both pos and fromto"),
    "a fromto on a sphere": ('type="capsule" size="0.01" fromto', 'size="0.01" fromto',
                             "<site name='by_class'>: a fromto on a site of type 'sphere'"),
    "a fromto of five numbers": ('fromto="0 0 0 0 0.2 0.1"', 'fromto="0 0 0 0 0.2"',
                                 "<site name='own_in_frame'> fromto='0 0 0 0 0.2': expected 6 finite number(s)"),
    "a renamed top class": ("<default><default class=", '<default class="top"><default class=',
                            "top-level <default class='top'>: the top class is 'main'"),
    "a class name twice": ('<default class="rod">', '<default class="rod"/><default class="rod">',
                           "<default class='rod'>: a class name given twice"),
    "two sites in one class": ('<site type="capsule"', '<site group="1"/><site type="capsule"',
                               "<default class='rod'> holds more than one <site>"),
    "a free joint inside a body": ('<joint name="j1" axis="0 1 0"/>', '<freejoint name="j1"/>',
                                   "<body name='b1'>: a free joint inside another body"),
    "a mocap body inside a body": ('<body name="b1" pos="0.3 0 0"', '<body name="b1" mocap="true" pos="0.3 0 0"',
                                   "<body name='b1'>: a mocap body inside another body"),
    "an unknown class": ('<site name="by_class" class="rod"/>', '<site name="by_class" class="rods"/>',
                         "<site name='by_class'>: class='rods' names no default class"),
    "an unknown childclass": ('childclass="rod"', 'childclass="nope"',
                              "<body name='b1'>: childclass='nope' names no default class"),
    "a ball then a hinge in one body": ('<joint name="j1" axis="0 1 0"/>',
                                        '<joint name="b" type="ball"/><joint name="j1" axis="0 1 0"/>',
                                        "<body name='b1'>: a ball joint followed by a rotation in one body"),
    "a free joint and a hinge in one body": ('<body name="b0" pos="0.1 0 0" quat="0.9 0.1 0.3 0.2">' + INERTIA
                                             + '<joint name="j0" axis="0 0 1"/>',
                                             '<body name="b0" pos="0.1 0 0" quat="0.9 0.1 0.3 0.2">' + INERTIA
                                             + '<freejoint/><joint name="j0" axis="0 0 1"/>',
                                             "<body name='b0'>: a free joint and other joints in one body"),
    "global coordinates": ('<compiler angle="radian"/>', '<compiler angle="radian" coordinate="global"/>',
                           "<compiler coordinate='global'>: global coordinates are no longer read by MuJoCo"),
}


@pytest.mark.parametrize("case", list(REFUSED))
def test_what_mujoco_refuses_is_refused_naming_the_element(tmp_path, case):
    """Each of these files MuJoCo refuses; screwkit did not (it read a NaN placement, another site, a body placed in
    the world's frame as if in its parent's, or raised from deep in numpy): it now refuses them, naming the element,
    in one line from the command."""
    old, new, message = REFUSED[case]
    assert old in FROMTO
    text = FROMTO.replace(old, new, 1)
    with pytest.raises(ValueError):
        mujoco.MjModel.from_xml_string(text)
    path = written(tmp_path, text)
    with pytest.raises(ImportError_, match=re.escape(message)):
        read_mjcf(path)
    if case in ("a fromto of five numbers", "a free joint inside a body"):
        one_line_error(screwkit("analyze", path), "robot.xml", message.split(":")[0])


def test_a_fromto_with_a_nan_is_refused_in_one_line(tmp_path):
    """MuJoCo only warns of a NaN in a file, and places the site nowhere (NaN); screwkit read a closure's site there
    and printed indices beside a NaN gap. It refuses it, naming the site."""
    path = written(tmp_path, FROMTO.replace('fromto="0 0 0 0 0.2 0.1"', 'fromto="0 0 0 0 nan 0.1"'))
    one_line_error(screwkit("analyze", path), "robot.xml", "<site name='own_in_frame'> fromto='0 0 0 0 nan 0.1'",
                   "expected 6 finite number(s)")
