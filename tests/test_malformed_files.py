"""Files of other tools that are malformed get one line naming the file and the element, as each tool refuses them,
never a traceback or a crash (found by mutating the bundled and gallery files one element at a time)."""

from __future__ import annotations

import re
from pathlib import Path

import mujoco
import numpy as np
import pytest
from test_io import five_bar_gepetto, five_bar_mjcf

from helpers import one_line_error, screwkit
from screwkit.io.loader import load
from screwkit.studies import indices_at_pose


@pytest.mark.parametrize(("key", "value"), [("closed_loop", "5"), ("type", "6")])
def test_a_robot_yaml_key_that_is_not_a_list_is_named(tmp_path, key, value):
    """A robot.yaml whose ``closed_loop`` or ``type`` is a number: Python's "object of type 'int' has no len()" with
    its traceback before; one line naming the key now."""
    urdf, spec = five_bar_gepetto()
    (tmp_path / "robot.urdf").write_text(urdf)
    changed = re.sub(rf"(?m)^{key}:.*(\n[ -].*)*", f"{key}: {value}", spec)
    assert changed != spec
    (tmp_path / "robot.yaml").write_text(changed)
    one_line_error(screwkit("analyze", tmp_path / "robot.urdf"), f"robot.yaml: {key} must be a list, got {value}.")


@pytest.mark.parametrize("joins", ["a link with two parents", "a cycle"])
def test_joints_that_do_not_form_a_tree_are_named_before_the_parser_crashes(tmp_path, joins):
    """The Gepetto five-bar with one more joint from a rod's end to the other rod (that rod then has two parent
    joints), or a base whose parent is the end of its own chain (every link one parent, none the root): urdfdom's
    parser, called by Pinocchio, ended the process with a segmentation fault (exit status -11). Now one line names
    the link and the joints."""
    urdf, spec = five_bar_gepetto()
    links = re.findall(r'<link name="([^"]+)"', urdf)
    root, last = links[0], links[-1]
    child = links[2] if joins == "a link with two parents" else root
    extra = (f'<joint name="extra" type="revolute"><parent link="{last}"/><child link="{child}"/>'
             '<origin xyz="0 0 0" rpy="0 0 0"/><axis xyz="0 0 1"/>'
             '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>')
    (tmp_path / "robot.urdf").write_text(urdf.replace("</robot>", extra))
    (tmp_path / "robot.yaml").write_text(spec)
    needle = (f"<link name='{child}'> has two parent joints" if joins == "a link with two parents" else
              "back to itself: a URDF's joints form a tree")
    one_line_error(screwkit("analyze", tmp_path / "robot.urdf"), f"{tmp_path / 'robot.urdf'}: ", needle)


def test_a_joint_type_mujoco_does_not_know_is_named_as_mujoco_refuses_it(tmp_path):
    """An MJCF hinge written ``type="banana"``: MuJoCo refuses the file ("invalid keyword"); screwkit passed on
    Pinocchio's message over five lines of C++. Now one line names the joint."""
    path = tmp_path / "five_bar.xml"
    path.write_text(five_bar_mjcf().replace('<joint name="b_2" type="hinge"', '<joint name="b_2" type="banana"', 1))
    assert 'type="banana"' in path.read_text()
    with pytest.raises(ValueError, match="invalid keyword: 'banana'"):
        mujoco.MjModel.from_xml_path(str(path))
    one_line_error(screwkit("analyze", path), f"{path}: <joint name='b_2'>: type='banana' is no joint type of MuJoCo's")


RODS = Path(__file__).resolve().parents[1] / "robots" / "delta_rods_4.xml"
"""The bundled rod-level Delta (MJCF, legs with loops: read as a graph)."""


@pytest.mark.parametrize(("case", "written", "changed", "needle"), [
    ("a motor on no joint", '<motor name="motor_1" joint="motor_1"/>', '<motor name="motor_1" joint="no_such_joint"/>',
     "actuated joint 'no_such_joint' is not a joint of the tree."),
    ("a connect of bodies without its anchor", ' anchor="-0.481810888007 0.0 -0.638637822399"/>', "/>",
     "<connect name='rod_1b_end'>: expected 3 numbers in 'anchor', got none.")])
def test_what_mujoco_refuses_in_a_graph_s_file_is_refused_not_read_otherwise(tmp_path, case, written, changed, needle):
    """The rod-level Delta with its first motor on a joint the file does not have, or its first rod's ``<connect>``
    without its ``anchor``: MuJoCo refuses either file. screwkit read the first with that motor left out (three
    actuators, no word said) and the second with the anchor at the body's origin (1 DOF instead of 3). Now each is
    one line naming it."""
    text = RODS.read_text()
    assert written in text
    path = tmp_path / "rods.xml"
    path.write_text(text.replace(written, changed, 1))
    with pytest.raises(ValueError):
        mujoco.MjModel.from_xml_path(str(path))
    one_line_error(screwkit("analyze", path), f"{path}: ", needle)


@pytest.mark.parametrize(("case", "edit", "needle"), [
    ("a limit upside down", ('<limit effort="1"', '<limit lower="1" upper="-1" effort="1"'),
     "<joint name='mot1'>: <limit lower='1' upper='-1'>: the lower bound is above the upper one."),
    ("an origin of two numbers", ('<origin xyz="-0.1 0.0 0.0"', '<origin xyz="-0.1 0.0"'),
     "<joint name='mot1'>: <origin xyz='-0.1 0.0'>: expected three finite numbers, each"),
    ("an axis not a number", ('<axis xyz="0 0 1"/>', '<axis xyz="0 0 nan"/>'),
     "<axis xyz='0 0 nan'>: expected three finite numbers, each")])
def test_a_urdf_element_urdfdom_would_take_otherwise_or_not_name_is_named(tmp_path, case, edit, needle):
    """The Gepetto five-bar with its first motor's limit upside down (read as no limit before: every pose reachable),
    its origin of two numbers or an axis of NaN (urdfdom's "Parser found 2 elements but 3 expected", naming no
    joint): one line naming the joint and the element."""
    urdf, spec = five_bar_gepetto()
    assert edit[0] in urdf
    (tmp_path / "robot.urdf").write_text(urdf.replace(*edit, 1))
    (tmp_path / "robot.yaml").write_text(spec)
    one_line_error(screwkit("analyze", tmp_path / "robot.urdf"), f"{tmp_path / 'robot.urdf'}: ", needle)


def test_a_joint_mujoco_reads_along_no_axis_and_a_closure_of_a_body_to_itself_are_named(tmp_path):
    """The five-bar with a hinge's axis ``1e308 0 0``: MuJoCo reads its axis as zero (the length overflows once
    squared), and screwkit refused it as "the zero vector" without saying why; with a weld of a body to itself, which
    MuJoCo refuses ("repeated in equality constraint"), screwkit read the file. Each is one line naming the element."""
    path = tmp_path / "five_bar.xml"
    text = five_bar_mjcf().replace('<joint name="b_2" type="hinge" axis="0.0 0.0 1.0"/>',
                                   '<joint name="b_2" type="hinge" axis="1e308 0 0"/>', 1)
    assert 'axis="1e308 0 0"' in text
    path.write_text(text)
    model = mujoco.MjModel.from_xml_path(str(path))
    assert not model.jnt_axis[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, "b_2")].any()
    one_line_error(screwkit("analyze", path), f"{path}: <joint name='b_2'>: the axis is the zero vector "
                                              "(axis='1e308 0 0'; its length overflows once squared")
    path.write_text(five_bar_mjcf().replace("</equality>", '<weld name="self" body1="distal_2" body2="distal_2"/>'
                                            "</equality>"))
    with pytest.raises(ValueError, match="is repeated in equality constraint"):
        mujoco.MjModel.from_xml_path(str(path))
    one_line_error(screwkit("analyze", path), f"{path}: <weld name='self'>: body1 and body2 are both 'distal_2'")


def test_lock_naming_a_fixed_joint_says_so(tmp_path):
    """``--lock`` naming a fixed joint of the file said "no joint of that name"; it says it is a fixed joint."""
    delta = Path(__file__).resolve().parent / "data" / "gallery" / "published" / "ros2_closed_loop_ws"
    delta = delta / "3dof_delta.urdf"
    assert re.search(r'<joint\s+name="Chain1_tip_joint"\s+type="fixed"', delta.read_text())
    one_line_error(screwkit("analyze", delta, "--lock", "Chain1_tip_joint"),
                   "--lock Chain1_tip_joint: a fixed joint already, nothing to hold; joints are ")


def test_what_urdfdom_does_not_read_is_not_refused(tmp_path):
    """The checks read what urdfdom reads: a fixed joint's ``<limit>`` upside down (urdfdom reads the bounds of
    revolute and prismatic joints only) and a link's ``<inertial>`` origin of 2e9 m (screwkit reads no inertia) leave
    the Gepetto five-bar as it is: the same indices at its home."""
    urdf, spec = five_bar_gepetto()
    edited = urdf.replace('<axis xyz="0 0 0"/><joint_properties', '<axis xyz="0 0 0"/><limit lower="1" upper="-1" '
                          'effort="1" velocity="1"/><joint_properties', 1)
    edited = edited.replace("<inertial><mass", '<inertial><origin xyz="0 0 2e9"/><mass', 1)
    assert edited.count("<limit lower=") == 1 and "2e9" in edited
    results = []
    for name, text in (("as_built", urdf), ("edited", edited)):
        (tmp_path / name).mkdir()
        (tmp_path / name / "robot.urdf").write_text(text)
        (tmp_path / name / "robot.yaml").write_text(spec)
        mechanism = load(tmp_path / name / "robot.urdf")
        results.append(indices_at_pose(mechanism, mechanism.home_pose))
    np.testing.assert_array_equal(results[1].iti_actuators, results[0].iti_actuators)
    assert results[1].lmti == results[0].lmti
