"""Closed-loop robots written by other tools (MJCF, URDF + Gepetto robot.yaml), against independent values.

The files are written here: the five-bar with a third leg of ``robots/five_bar_3.urdf`` (bases
A_i, proximal 0.2 m, distal 0.3 m, the three distal links meeting at the output point), in MJCF
(``<connect>`` closures) and as a Gepetto-style URDF tree (a ``6d`` weld between two coaxial
closure pins, a ``3d`` closure, fixed joints with zero axes, and joint origins that leave the loops
open at q = 0). Their indices are compared with the textbook pressure angles of the five-bar
(``five_bar_expected`` of the lower-mobility tests), computed from the geometry alone.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
from test_lower_mobility import DISTAL, FIVE_BAR_BASE, PROXIMAL, five_bar_elbows, five_bar_expected

from helpers import assert_indices_close, one_line_error, random_rotation, screwkit
from screwkit.io import ImportError_, LegWithLoops, read_gepetto, read_mechanism_file
from screwkit.io.closed_tree import assemble, joint_kind
from screwkit.io.loader import bundled_path, load
from screwkit.studies.poses import indices_at_pose, indices_at_poses

HOME = np.array([0.0, 0.35])
TOLERANCE = 1e-9


def text(values) -> str:
    return " ".join(repr(float(v)) for v in values)


def five_bar_mjcf(rotation=None, scale=1.0, legs=3, name_equalities=True, actuators=True) -> str:
    """The five-bar in MJCF, its points moved by ``rotation`` and scaled; closed at q = 0."""
    rotation = np.eye(3) if rotation is None else rotation
    elbows = five_bar_elbows(HOME)

    def at(point2):
        return rotation @ (scale * np.array([point2[0], point2[1], 0.0]))

    axis = text(rotation @ np.array([0.0, 0.0, 1.0]))
    bodies, equalities, motors = [], [], []
    for i in range(legs):
        base, elbow = FIVE_BAR_BASE[i], elbows[i]
        site = f'<site name="effector" pos="{text(at(HOME - elbow))}"/>' if i == 0 else ""
        bodies.append(
            f'<body name="proximal_{i + 1}" pos="{text(at(base))}">'
            f'<joint name="a_{i + 1}" type="hinge" axis="{axis}"/><geom type="sphere" size="0.01"/>'
            f'<body name="distal_{i + 1}" pos="{text(at(elbow - base))}">'
            f'<joint name="b_{i + 1}" type="hinge" axis="{axis}"/><geom type="sphere" size="0.01"/>{site}'
            '</body></body>')
        if i:
            label = f' name="loop_{i + 1}"' if name_equalities else ""
            equalities.append(f'<connect{label} body1="distal_{i + 1}" body2="distal_1" '
                              f'anchor="{text(at(HOME - elbow))}"/>')
        motors.append(f'<motor name="m_{i + 1}" joint="a_{i + 1}"/>')
    return ('<mujoco model="five_bar_mjcf"><compiler angle="radian"/><worldbody><body name="base">'
            + "".join(bodies) + "</body></worldbody><equality>" + "".join(equalities) + "</equality>"
            + ("<actuator>" + "".join(motors) + "</actuator>" if actuators else "") + "</mujoco>")


def five_bar_gepetto(legs=3, opening=0.3) -> tuple[str, str]:
    """The five-bar as a Gepetto-style URDF tree and robot.yaml.

    Leg 1 carries the output (frame ``effector``); leg 2 ends in an extra pin ``closure_2b`` on
    leg 1's distal link, welded (6d) to the pin ``closure_2a`` at the end of leg 2 (two coaxial
    pins: one idle DoF); leg 3 meets leg 1 by a 3d closure. Every proximal joint origin is turned
    by ``opening`` (rad), so q = 0 leaves the loops open. Fixed joints carry zero axes.
    """
    elbows = five_bar_elbows(HOME)
    links, joints = ['<link name="built"/>'], []

    def joint(name, kind, parent, child, xyz=(0, 0, 0), yaw=0.0):
        axis = "0 0 0" if kind == "fixed" else "0 0 1"
        limit = '<limit effort="1" velocity="1"/>' if kind == "revolute" else ""  # no lower/upper: as exported
        links.append(f'<link name="{child}"><inertial><mass value="0"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" '
                     'iyz="0" izz="0"/></inertial></link>')
        joints.append(f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
                      f'<origin xyz="{text(xyz)}" rpy="0 0 {float(yaw)!r}"/><axis xyz="{axis}"/>{limit}'
                      '<joint_properties friction="0.0"/></joint>')

    for i in range(legs):
        base, elbow = FIVE_BAR_BASE[i], elbows[i]
        first = np.arctan2(*(elbow - base)[::-1])
        second = np.arctan2(*(HOME - elbow)[::-1])
        joint(f"mot{i + 1}", "revolute", "built", f"proximal_{i + 1}", (*base, 0.0), first + opening)
        joint(f"free{i + 1}", "revolute", f"proximal_{i + 1}", f"distal_{i + 1}", (PROXIMAL, 0.0, 0.0),
              second - first)
    joint("effector_frame", "fixed", "distal_1", "effector", (DISTAL, 0.0, 0.0))
    joint("closure_2b", "revolute", "distal_1", "pin_2b", (DISTAL, 0.0, 0.0))
    joint("closure_2a", "revolute", "distal_2", "pin_2a", (DISTAL, 0.0, 0.0))
    pairs, kinds = [["closure_2a", "closure_2b"]], ["6d"]
    if legs > 2:
        joint("closedloop3_A_frame", "fixed", "distal_3", "closedloop3_A", (DISTAL, 0.0, 0.0))
        joint("closedloop3_B_frame", "fixed", "distal_1", "closedloop3_B", (DISTAL, 0.0, 0.0))
        pairs.append(["closedloop3_B", "closedloop3_A"])
        kinds.append("3D")
    urdf = '<?xml version="1.0"?>\n<robot name="five_bar_gepetto">' + "".join(links) + "".join(joints) + "</robot>"
    yaml = (f"closed_loop: {json.dumps(pairs)}\ntype: {json.dumps(kinds)}\n"
            f"name_mot: {json.dumps([f'mot{i + 1}' for i in range(legs)])}\n")
    return urdf, yaml


def poses_near_home(count=8, seed=3):
    return HOME + np.random.default_rng(seed).uniform(-0.05, 0.05, (count, 2))


def assert_textbook(result, points, legs=(0, 1, 2)):
    """The five-bar's pressure angles at every point; with two legs (non-redundant) F_O1 = F_IO1 = 0."""
    for k, point in enumerate(points):
        expected = five_bar_expected(point, legs=legs)
        np.testing.assert_allclose(result.iti_actuators[k], expected["iti_actuators"], atol=TOLERANCE)
        np.testing.assert_allclose(result.lmti[k], expected["lmti"], atol=TOLERANCE)
        if len(legs) > 2:
            np.testing.assert_allclose(result.f_o[1][k], expected["f_o1"], atol=TOLERANCE)
    if len(legs) == 2:
        assert result.f_o.keys() == {1} and np.all(result.f_o[1] == 0.0) and np.all(result.f_io[1] == 0.0)


def assert_three_leg_five_bar(path):
    """The file at ``path`` loads as the three-legged five-bar (2 DoF, 3 actuators) with the textbook pressure angles
    at points near its home."""
    from screwkit.io.loader import load

    mechanism = load(path)
    assert mechanism.dof == 2 and len(mechanism.actuators) == 3
    points = poses_near_home()
    assert_textbook(indices_at_poses(mechanism, points, detail=True), points)


def test_an_mjcf_five_bar_has_the_textbook_pressure_angles(tmp_path):
    path = tmp_path / "five_bar.xml"
    path.write_text(five_bar_mjcf())
    mechanism = load(path)
    assert mechanism.dof == 2 and mechanism.output_point is not None
    assert mechanism.actuator_names == ("a_1:a_1", "a_2:a_2", "a_3:a_3")  # chains named after their first joint
    np.testing.assert_allclose(mechanism.home_pose, HOME, atol=1e-12)  # the world x, y of the meeting point
    points = poses_near_home()
    assert_textbook(indices_at_poses(mechanism, points, detail=True), points)


def test_a_point_output_names_the_closure_where_the_legs_meet_not_the_file_s_first(tmp_path):
    """A published gripper lists the other finger's loop first: the point output of one finger was said to be where
    that loop closes (its name only: the point was right). Here a rigid pair of rods on the base, closed by a
    connect listed first, beside a two-legged five-bar: the output names the five-bar's closure, and the indices are
    the five-bar's alone."""
    idle = ''.join(f'<body name="idle_{side}" pos="{x} -0.5 0"><joint name="idle_{side}" type="hinge" axis="0 0 1"/>'
                   '<geom type="sphere" size="0.01"/></body>' for side, x in (("a", -0.5), ("b", -0.2)))
    text = five_bar_mjcf(legs=2).replace('<body name="base">', '<body name="base">' + idle).replace(
        "<equality>", '<equality><connect name="idle" body1="idle_a" body2="idle_b" anchor="0.15 0.2 0"/>')
    (tmp_path / "with_idle.xml").write_text(text)
    (tmp_path / "plain.xml").write_text(five_bar_mjcf(legs=2))
    _, report = read_mechanism_file(tmp_path / "with_idle.xml")
    assert report.output.startswith("the point where the chains meet on body 'distal_1' (closure 'loop_2')")
    assert "closure 'idle' closes branches that reach no leg: left out (it does not move the platform)" in report.notes
    plain, found = load(tmp_path / "plain.xml"), load(tmp_path / "with_idle.xml")
    points = poses_near_home()
    assert_indices_close(indices_at_poses(found, points, detail=True), indices_at_poses(plain, points, detail=True))


def test_info_says_in_which_frame_a_planar_mechanism_s_coordinates_are(tmp_path):
    """A published five-bar moving in a vertical plane reads x = 0, y = -0.25 for an effector at world (0.02, 0,
    0.25): x and y are in the plane of motion, which nothing said. ``info`` now gives the base frame in the world
    (also in its JSON): the home pose mapped through it is the effector where the file draws it."""
    rotation = random_rotation(np.random.default_rng(3))
    path = tmp_path / "turned.xml"
    path.write_text(five_bar_mjcf(rotation, 2.0))
    described = screwkit("info", path)
    assert described.returncode == 0, described.stderr
    assert "task frame: base 'base', origin (" in described.stdout
    assert "(the plane of motion is its x-y plane)" in described.stdout
    report = json.loads(screwkit("info", path, "--json").stdout)
    placed = report["platform"]["base_in_world"]
    home = report["named_poses"]["home"]
    world = np.array(placed["origin_m"]) + np.array(placed["axes"]).T @ np.array([home["x"], home["y"], 0.0])
    np.testing.assert_allclose(world, rotation @ (2.0 * np.array([*HOME, 0.0])), atol=1e-9)


@pytest.mark.parametrize("scale", [1e-3, 1.0, 1e3])
def test_an_mjcf_file_gives_the_same_indices_in_any_unit_and_world_frame(tmp_path, scale):
    rotation = random_rotation(np.random.default_rng(int(scale * 1000) % 97))
    path = tmp_path / "moved.xml"
    path.write_text(five_bar_mjcf(rotation, scale))
    mechanism = load(path)
    result = indices_at_pose(mechanism, mechanism.home_pose)
    expected = five_bar_expected(HOME)
    np.testing.assert_allclose(result.iti_actuators, expected["iti_actuators"], atol=TOLERANCE)
    np.testing.assert_allclose([result.lmti, result.f_o[1]], [expected["lmti"], expected["f_o1"]], atol=TOLERANCE)


def test_a_gepetto_style_urdf_and_yaml_with_open_loops_is_assembled(tmp_path):
    urdf, yaml = five_bar_gepetto()
    (tmp_path / "robot.urdf").write_text(urdf)
    (tmp_path / "robot.yaml").write_text(yaml)
    converted, report = read_mechanism_file(tmp_path / "robot.urdf")
    assert all(gap > 0.01 for gap in report.gaps_before.values()), report.gaps_before  # q = 0 is open
    assert all(gap < 1e-9 for gap in report.gaps_after.values()), report.gaps_after
    assert report.locked == ["closure_2a"]  # coaxial with the welded pin closure_2b: the idle DoF
    assert report.planar is True  # every axis along z: planar, the 3d closure written as a pin about z
    assert report.output.startswith("the point where the chains meet on body 'distal_1'")
    assert report.output.endswith("at frame 'effector'")  # (the point and the frame one, to the rounding)
    mechanism = load(tmp_path / "robot.urdf")
    assert mechanism.dof == 2 and mechanism.actuator_names[0].endswith("mot1")
    points = poses_near_home()
    assert_textbook(indices_at_poses(mechanism, points, detail=True), points)


def test_a_gepetto_joint_with_a_zero_axis_is_refused_naming_the_file(tmp_path):
    """Pinocchio reads a URDF revolute joint about the zero vector: refused naming the file and the joint (numpy
    warnings and "SVD did not converge" before)."""
    urdf, yaml = five_bar_gepetto()
    (tmp_path / "robot.urdf").write_text(re.sub(r'(<joint name="free2".*?<axis xyz=")0 0 1', r"\g<1>0 0 0", urdf,
                                                count=1))
    (tmp_path / "robot.yaml").write_text(yaml)
    with pytest.raises(ValueError) as refused:
        read_mechanism_file(tmp_path / "robot.urdf")
    assert str(refused.value) == (f"{tmp_path / 'robot.urdf'} + robot.yaml: <joint name='free2'>: the axis is the "
                                  "zero vector.")


def test_a_planar_gepetto_five_bar_is_written_planar_and_non_redundant_gives_zero_fault_tolerance(tmp_path):
    urdf, yaml = five_bar_gepetto(legs=2)
    (tmp_path / "robot.urdf").write_text(urdf)
    (tmp_path / "robot.yaml").write_text(yaml)
    mechanism = load(tmp_path / "robot.urdf")
    assert mechanism.is_planar and mechanism.dof == 2 and len(mechanism.actuators) == 2
    points = poses_near_home()
    assert_textbook(indices_at_poses(mechanism, points, detail=True), points, legs=(0, 1))


@pytest.mark.parametrize("change, message", [
    (lambda t: t.replace("<actuator>", "<actuator>").replace('<motor name="m_1" joint="a_1"/>', "")
     .replace('<motor name="m_2" joint="a_2"/>', "").replace('<motor name="m_3" joint="a_3"/>', ""),
     "drives a joint"),
    (lambda t: t.replace("<worldbody>", '<include file="missing.xml"/><worldbody>'), "missing.xml: cannot be read"),
])
def test_an_mjcf_file_that_cannot_be_read_says_why(tmp_path, change, message):
    path = tmp_path / "bad.xml"
    path.write_text(change(five_bar_mjcf()))
    with pytest.raises(ValueError, match=message):
        load(path)


@pytest.mark.parametrize("old, new, element", [
    ('<site name="effector" pos="', '<site name="effector" pos="np.float64(0.1) ', "<site name='effector'> pos="),
    ('anchor="', 'anchor="0.1 ', "<connect name='loop_2'> anchor="),
    ('axis="0.0 0.0 1.0"', 'axis="0.0 1.0"', "<joint name='a_1'> axis="),
])
def test_a_number_mujoco_cannot_read_is_refused_naming_the_element(tmp_path, old, new, element):
    """Numbers MuJoCo refuses (a word that is not a number, too many or too few) are refused too, naming the
    element and the attribute, not read as the numbers that parse."""
    import mujoco

    text_ = five_bar_mjcf().replace(old, new, 1)
    with pytest.raises(ValueError, match="XML Error"):
        mujoco.MjModel.from_xml_string(text_)
    path = tmp_path / "bad.xml"
    path.write_text(text_)
    with pytest.raises(ValueError, match=f"bad.xml: {re.escape(element)}.*expected \\d finite number"):
        load(path)


A_1 = '<joint name="a_1" type="hinge" axis="0.0 0.0 1.0"/>'
FLAT = '<compiler angle="radian"/><default><default class="flat"><joint axis="0 0 0"/></default></default>'


@pytest.mark.parametrize("old, new, element, problem", [
    ('name="b_2"', 'name="b_1"', "<joint name='b_1'>", "the joint name is used twice."),
    ('name="distal_2"', 'name="distal_1"', "<body name='distal_1'>", "the body name is used twice."),
    ('name="base"', 'name="world"', "<body name='world'>",
     "the body name is used twice (MuJoCo's world body is named 'world')."),
    ('<site name="effector"', '<site name="effector"/><site name="effector"', "<site name='effector'>",
     "the site name is used twice."),
    ('name="loop_3"', 'name="loop_2"', "<connect name='loop_2'>", "the equality name is used twice."),
    ('name="m_2"', 'name="m_1"', "<motor name='m_1'>", "the actuator name is used twice."),
    (A_1, '<joint name="a_1" type="hinge" axis="0 0 0"/>', "<joint name='a_1'>",
     "the axis is the zero vector (axis='0 0 0')."),
    (A_1, '<joint name="a_1" type="slide" axis="0 1e-8 0"/>', "<joint name='a_1'>",
     "the axis is the zero vector (axis='0 1e-8 0'; MuJoCo refuses lengths up to 1e-07)."),
    (A_1, '<joint name="a_1" type="hinge" class="flat"/>', "<joint name='a_1'>",
     "the axis is the zero vector (axis='0 0 0')."),
    (A_1, '<joint name="a_1" type="hinge" axis="0 0 1" range="0.1 -0.1" limited="true"/>', "<joint name='a_1'>",
     "range='0.1 -0.1' on a limited joint: the lower limit must be below the upper."),
    ('<compiler angle="radian"/>', '<compiler angle="radian"/><default><joint limited="true"/></default>',
     "<joint name='a_1'>", "range='0 0' on a limited joint: the lower limit must be below the upper."),
    ('<compiler angle="radian"/>', '<compiler angle="radian" autolimits="false"/><default><joint range="-1 1"/>'
     '</default>', "<joint name='a_1'>", "range='-1 1' without limited='true' or 'false', under <compiler "
     "autolimits='false'>: limited or not?"),
    (A_1, '<joint name="a_1" type="ball" range="0.5 1"/>', "<joint name='a_1'>",
     "range='0.5 1' on a limited ball joint: the first number must be 0 (the second is the largest angle)."),
])
def test_a_joint_name_or_range_mujoco_refuses_is_refused_naming_the_element(tmp_path, old, new, element, problem):
    """Names repeated in one of MuJoCo's namespaces (Pinocchio would merge two joints into one: wrong indices), a
    zero axis (a hinge about nothing), a limited joint's range that is no interval: MuJoCo refuses the file, so
    does screwkit, in one line naming the element."""
    import mujoco

    text_ = five_bar_mjcf().replace(old, new, 1).replace('<compiler angle="radian"/>',
                                                        FLAT if "flat" in new else '<compiler angle="radian"/>')
    with pytest.raises(ValueError):
        mujoco.MjModel.from_xml_string(text_)
    path = tmp_path / "bad.xml"
    path.write_text(text_)
    with pytest.raises(ValueError) as refused:
        load(path)
    assert str(refused.value) == f"{path}: {element}: {problem}"


def test_a_range_mujoco_does_not_apply_is_not_read_as_limits(tmp_path):
    """``limited="false"`` (and, with autolimits, a range that is no interval) leaves a joint free in MuJoCo;
    Pinocchio would read the range as limits (here the reference assembly outside them: refused)."""
    import mujoco

    for attributes in ('range="0.001 1" limited="false"', 'range="1 0.001"'):
        path = tmp_path / "free.xml"
        path.write_text(five_bar_mjcf().replace(A_1, f'<joint name="a_1" type="hinge" axis="0 0 1" {attributes}/>'))
        assert not mujoco.MjModel.from_xml_path(str(path)).jnt_limited.any()
        converted, report = read_mechanism_file(path)
        assert any("range not applied" in note and "a_1" in note for note in report.notes), report.notes
        assert re.search(r'<joint name="a_1" type="continuous"', converted), converted
        points = poses_near_home()
        assert_textbook(indices_at_poses(load(path), points, detail=True), points)


@pytest.mark.parametrize("old, new, element, problem", [
    ('name="r_xb_rod1"', 'name="r_xb1"', "<joint name='r_xb1'>", "the joint name is used twice."),
    ('axis="0.576369848528 -0.817188960833 0"', 'axis="0 0 0"', "<joint name='r_xb1'>", "the axis is the zero "
     "vector"),
    ('axis="-0.250022039445 -0.176342525304 0.952046371539" range="-0.1 0.1"', 'axis="0 0 0" range="-0.1 0.1"',
     "<joint name='s1'>", "the axis is the zero vector"),
    ('range="-0.1 0.1"', 'range="0.1 -0.1"', "<joint name='s1'>", "range='0.1 -0.1' on a limited joint"),
])
def test_the_command_refuses_a_cad_export_mujoco_refuses_in_one_line(tmp_path, old, new, element, problem):
    """The published Stewart platform's CAD export with one joint renamed to another's name (screwkit read it with
    one joint dropped: LMTI 0.4035 instead of 0.4233), a zero axis (numpy warnings, then "SVD did not converge"),
    an inverted range on a limited slide (the limit ignored)."""
    import mujoco

    source = (Path(__file__).resolve().parent / "data" / "gallery" / "stewart_cad.xml").read_text()
    assert old in source
    path = tmp_path / "stewart_cad.xml"
    path.write_text(source.replace(old, new, 1))
    with pytest.raises(ValueError):
        mujoco.MjModel.from_xml_path(str(path))
    one_line_error(screwkit("analyze", path), f"{path}: {element}: {problem}")


def test_two_actuators_on_one_joint_are_one_actuated_joint_as_mujoco_has_them(tmp_path):
    """A servo written as a position and a velocity actuator on one slide: MuJoCo has two actuators and one joint
    they drive; screwkit reads one actuated joint, says so in the report, and gives the file's indices."""
    import mujoco

    source = (Path(__file__).resolve().parent / "data" / "gallery" / "stewart_cad.xml").read_text()
    plain, doubled = tmp_path / "plain.xml", tmp_path / "doubled.xml"
    plain.write_text(source)
    doubled.write_text(source.replace('<position name="act1" joint="s1" kp="10000"/>',
                                      '<position name="act1" joint="s1" kp="10000"/><velocity name="act1_v" '
                                      'joint="s1" kv="100"/>', 1))
    model = mujoco.MjModel.from_xml_path(str(doubled))
    assert model.nu == 7 and len(set(model.actuator_trnid[:, 0])) == 6
    _, report = read_mechanism_file(doubled)
    assert any("joint 's1' is driven by more than one <actuator>" in note for note in report.notes), report
    mechanism = load(doubled)
    assert len(mechanism.actuator_names) == 6
    home = load(plain).home_pose
    assert_indices_close(indices_at_pose(load(plain), home), indices_at_pose(mechanism, home), TOLERANCE)


def test_the_platform_is_the_body_where_most_closures_meet_and_a_tie_is_asked_for(tmp_path):
    """No frame named as an output: the body where most closures meet is the platform, said in the report. With one
    ball or pin closure (a two-legged five-bar), the body it closes onto, its output the point where the legs meet:
    the indices of the file whose effector is named there, with the closure written either way round (a published
    teaching five-bar and another needed --output for this). One weld between two legs, one pin onto the world, or the
    two-legged five-bar asked for a frame output (whose body's?) is refused with the option that names the platform."""
    plain, renamed = tmp_path / "plain.xml", tmp_path / "renamed.xml"
    plain.write_text(five_bar_mjcf())
    renamed.write_text(five_bar_mjcf().replace('name="effector"', 'name="marker"'))
    _, report = read_mechanism_file(renamed)
    assert any("platform inferred: body 'distal_1', where 2 closures meet" in note for note in report.notes), report
    expected, got = (indices_at_pose(load(path), np.array(HOME)) for path in (plain, renamed))
    assert_indices_close(expected, got, TOLERANCE)
    named, tie, swapped, welded = (tmp_path / f"{name}.xml" for name in ("named", "tie", "swapped", "welded"))
    named.write_text(five_bar_mjcf(legs=2))
    tie.write_text(five_bar_mjcf(legs=2).replace('name="effector"', 'name="marker"'))
    _, report = read_mechanism_file(tie)
    assert any("platform inferred: body 'distal_1', where closure 'loop_2' joins the legs" in note
               for note in report.notes), report
    anchor = " ".join(repr(float(v)) for v in (*(np.asarray(HOME) - five_bar_elbows(HOME)[0]), 0.0))
    swapped.write_text(re.sub(r'<connect name="loop_2" body1="distal_2" body2="distal_1" anchor="[^"]*"/>',
                              f'<connect name="loop_2" body1="distal_1" body2="distal_2" anchor="{anchor}"/>',
                              tie.read_text()))
    assert swapped.read_text() != tie.read_text()
    expected = indices_at_pose(load(named), np.array(HOME))
    for path in (tie, swapped):
        assert_indices_close(expected, indices_at_pose(load(path), np.array(HOME)), TOLERANCE)
    welded.write_text(re.sub(r' anchor="[^"]*"', "", tie.read_text().replace("<connect ", "<weld ")))
    grounded = tmp_path / "grounded.xml"  # the closure onto the world: one leg, no meeting of two
    grounded.write_text(tie.read_text().replace(' body2="distal_1"', ""))
    for path, options in ((welded, {}), (grounded, {}), (tie, {"output_type": "frame"})):  # (a frame: whose?)
        with pytest.raises(ValueError, match="which body is the platform.*--output FRAME"):
            load(path, **options)


def test_unnamed_closures_several_world_bodies_and_degrees_open_as_mujoco_reads_them(tmp_path):
    """What Pinocchio's parser alone could not read: unnamed connects (it merges them), a second body under
    <worldbody> (it reads the first only), angles in degrees (MuJoCo's default) and an <include>. The file opens
    with the indices of the plain one."""
    plain = tmp_path / "plain.xml"
    plain.write_text(five_bar_mjcf())
    text = five_bar_mjcf(name_equalities=False).replace('<compiler angle="radian"/>', "")
    text = text.replace("</body></worldbody>", '</body><body name="camera_rig" pos="1 1 1"><geom type="sphere" '
                        'size="0.01"/></body></worldbody>')
    text = text.replace('<joint name="a_1" type="hinge"', '<joint name="a_1" type="hinge" range="-170 170"')
    (tmp_path / "actuators.xml").write_text("<mujoco>" + text[text.index("<actuator>"):text.index("</mujoco>")]
                                            + "</mujoco>")
    text = text[:text.index("<actuator>")] + '<include file="actuators.xml"/></mujoco>'
    written = tmp_path / "written.xml"
    written.write_text(text)
    _, report = read_mechanism_file(written)
    assert "2 unnamed closure(s) named in file order: connect_1, connect_2" in report.notes, report.notes
    assert any("2 bodies under <worldbody>" in note for note in report.notes)
    assert any("angles in degrees" in note for note in report.notes)
    first, second = load(plain), load(written)
    assert [c.joint_names for c in first.chains] == [c.joint_names for c in second.chains]
    np.testing.assert_allclose(second.chains[0].joint_limits[0], np.deg2rad([-170.0, 170.0]), atol=1e-12)
    poses = poses_near_home()
    a, b = (indices_at_poses(m, poses, detail=True) for m in (first, second))
    np.testing.assert_allclose(b.iti_actuators, a.iti_actuators, atol=1e-12)
    np.testing.assert_allclose(b.lmti, a.lmti, atol=1e-12)


def test_an_actuator_on_a_leg_closed_onto_another_leg_is_refused_by_name(tmp_path):
    """Leg 3 closed onto leg 2's pin instead of the platform: its motor drives through a closed-loop transmission."""
    urdf, yaml = five_bar_gepetto()
    yaml = yaml.replace('["closedloop3_B", "closedloop3_A"]', '["closedloop3_A", "closure_2a"]')
    (tmp_path / "robot.urdf").write_text(urdf)
    (tmp_path / "robot.yaml").write_text(yaml)
    with pytest.raises(ImportError_, match="actuated joint 'mot3' drives through closure 'closedloop3_A-closure_2a', "
                                           "which ends on another leg's link, not on the platform"):
        read_mechanism_file(tmp_path / "robot.urdf")


def test_convert_on_the_command_line_round_trips(tmp_path):
    source = tmp_path / "five_bar.xml"
    source.write_text(five_bar_mjcf())
    out = tmp_path / "converted.urdf"
    result = screwkit("convert", source, out, "--json")
    assert result.returncode == 0, result.stderr
    summary = json.loads(result.stdout)
    assert summary["dof"] == 2 and summary["task_coordinates"] == ["x", "y"] and out.is_file()
    original = json.loads(screwkit("analyze", source, "--json").stdout)
    converted = json.loads(screwkit("analyze", out, "--json").stdout)
    for key in ("iti", "lmti", "f_o", "iti_actuators"):
        assert original[key] == converted[key], key
    assert original["converted"][0].startswith(f"{source}: MJCF, platform body 'distal_1', output the point where "
                                                "the chains meet") and "converted" not in converted
    info = json.loads(screwkit("info", source, "--json").stdout)
    assert info["import_report"] == original["converted"] and info["dof"] == 2
    assert converted["iti"] == pytest.approx(five_bar_expected(HOME)["iti"], abs=TOLERANCE)
    again = screwkit("convert", source, out)
    assert again.returncode == 1 and "exists" in again.stderr and again.stderr.count("\n") == 1
    missing = screwkit("convert", tmp_path / "none.xml", tmp_path / "x.urdf")
    assert missing.returncode == 1 and "no such file" in missing.stderr and missing.stderr.count("\n") == 1


def mjcf_of_tree(tree, q, output: str) -> str:
    """The same closed tree written in MJCF, its bodies placed at the configuration q (closed there, so that
    MJCF's closures, taken at q0, are the tree's); a site at the output frame."""
    import pinocchio as pin

    model = tree.model
    data = model.createData()
    pin.forwardKinematics(model, data, q)
    frames = {int(f.parentJoint): f.name for f in reversed(list(model.frames)) if str(f.type) == "BODY"}
    output_frame = model.frames[model.getFrameId(output)]

    def placement(matrix):
        quaternion = pin.Quaternion(matrix[:3, :3]).coeffs()  # x, y, z, w
        return (f'pos="{text(matrix[:3, 3])}" '
                f'quat="{text([quaternion[3], quaternion[0], quaternion[1], quaternion[2]])}"')

    def body(joint):
        kind, axis = joint_kind(model, joint)
        local = np.eye(4)
        local[:3, :3] = model.jointPlacements[joint].rotation
        local[:3, 3] = model.jointPlacements[joint].translation
        children = "".join(body(child) for child in range(1, model.njoints) if model.parents[child] == joint)
        site = ""
        if int(output_frame.parentJoint) == joint:
            site_placement = np.eye(4)
            site_placement[:3, :3] = output_frame.placement.rotation
            site_placement[:3, 3] = output_frame.placement.translation
            site = f'<site name="{output}" {placement(site_placement)}/>'
        # the body frame is the joint frame at q: MJCF's q0 is the assembly, the joint keeps its axis
        motion = np.eye(4)
        value = q[model.joints[joint].idx_q]
        if kind == "revolute":
            motion[:3, :3] = pin.exp3(axis * value)
        else:
            motion[:3, 3] = axis * value
        return (f'<body name="{frames[joint]}" {placement(local @ motion)}>'
                f'<joint name="{model.names[joint]}" type="{"hinge" if kind == "revolute" else "slide"}" '
                f'axis="{text(axis)}"/><geom type="sphere" size="0.005"/>{site}{children}</body>')

    roots = "".join(body(joint) for joint in range(1, model.njoints) if model.parents[joint] == 0)
    equalities = []
    for index, closure in enumerate(tree.closures):
        # in the joint frames after the motion: the tree's closure frames, here at the assembly q
        anchor = closure.placement_a[:3, 3]
        name = f"closure_{index}"
        if closure.kind == "3d":
            equalities.append(f'<connect name="{name}" body1="{frames[closure.joint_a]}" '
                              f'body2="{frames[closure.joint_b]}" anchor="{text(anchor)}"/>')
        else:
            equalities.append(f'<weld name="{name}" body1="{frames[closure.joint_a]}" '
                              f'body2="{frames[closure.joint_b]}"/>')
    motors = "".join(f'<motor name="motor_{name}" joint="{name}"/>' for name in tree.motors)
    return ('<mujoco model="from_tree"><compiler angle="radian"/><worldbody><body name="base">' + roots
            + "</body></worldbody><equality>" + "".join(equalities) + f"</equality><actuator>{motors}</actuator>"
            "</mujoco>")


def test_the_same_mechanism_in_mjcf_and_in_urdf_and_yaml_gives_identical_indices(tmp_path):
    """Both formats of one five-bar (a 6d weld of two coaxial pins, a 3d closure) convert to the same indices."""
    urdf, yaml = five_bar_gepetto(opening=0.0)
    (tmp_path / "robot.urdf").write_text(urdf)
    (tmp_path / "robot.yaml").write_text(yaml)
    tree = read_gepetto(tmp_path / "robot.urdf", tmp_path / "robot.yaml")
    q, _ = assemble(tree)
    (tmp_path / "same.xml").write_text(mjcf_of_tree(tree, q, "effector"))
    from_yaml, from_mjcf = load(tmp_path / "robot.urdf"), load(tmp_path / "same.xml")
    _, report = read_mechanism_file(tmp_path / "same.xml")
    assert report.locked == ["closure_2a"] and from_mjcf.dof == from_yaml.dof == 2
    points = poses_near_home()
    first, second = (indices_at_poses(m, points, detail=True) for m in (from_yaml, from_mjcf))
    for key in ("iti_actuators", "oti_submechanisms", "lmti"):
        np.testing.assert_allclose(getattr(second, key), getattr(first, key), rtol=0, atol=TOLERANCE, err_msg=key)
    np.testing.assert_allclose(second.f_o[1], first.f_o[1], rtol=0, atol=TOLERANCE)
    assert_textbook(second, points)


def test_a_tree_without_loops_or_yaml_says_what_is_missing(tmp_path):
    urdf, _ = five_bar_gepetto()
    (tmp_path / "robot.urdf").write_text(urdf)  # no robot.yaml beside it
    with pytest.raises(ValueError, match="a tree with no <loop>: a closed-loop robot of another tool needs its "
                                         "robot.yaml beside it, closing_<name>_1 / closing_<name>_2 frame pairs as "
                                         "onshape-to-robot writes them, <gazebo><joint> or <drake:ball_constraint> "
                                         "elements, or an MJCF file"):
        load(tmp_path / "robot.urdf")


def test_a_ball_joint_inside_a_leg_is_refused_by_name(tmp_path):
    text = five_bar_mjcf().replace('<joint name="b_2" type="hinge" axis="0.0 0.0 1.0"/>',
                                   '<joint name="b_2" type="ball"/>')
    assert 'name="b_2" type="ball"' in text
    path = tmp_path / "ball.xml"
    path.write_text(text)
    with pytest.raises(LegWithLoops, match=r"joint 'b_2' \(spherical\) inside a leg: not a serial chain of 1-DoF "
                       r"joints; `screwkit analyze`, `info`, `sweep`, `map`, `trajectory` and `view`"
                       r".*analyse it as a graph"):
        read_mechanism_file(path)


def test_a_urdf_named_xml_and_output_options_on_a_screwkit_file_are_refused_in_one_line(tmp_path):
    urdf, _ = five_bar_gepetto()
    (tmp_path / "tree.xml").write_text(urdf)
    with pytest.raises(ValueError, match=r"the root element is <robot>, not <mujoco> \(a URDF: give it the suffix"):
        load(tmp_path / "tree.xml")
    own = tmp_path / "five.urdf"
    own.write_text(bundled_path("five_bar_3").read_text())
    result = screwkit("convert", own, tmp_path / "out.urdf", "--output", "effector")
    assert result.returncode == 1 and "apply to files of other tools (MJCF, SDFormat" in result.stderr
    assert result.stderr.count("\n") == 1


def _hinges_as_ball_pairs(text_: str, half_length: float, slip: float = 0.0) -> str:
    """Each connect written as a CAD exporter writes a hinge for MuJoCo: two ball joints on its axis (here z),
    ``half_length`` either side of the anchor; the second one's anchor moved by ``slip`` along x (rounding)."""
    def doubled(match):
        name, bodies, x, y, z = match.group(1), match.group(2), *map(float, match.group(3).split())
        return (f'<connect name="{name}a" {bodies} anchor="{x!r} {y!r} {z - half_length!r}"/>'
                f'<connect name="{name}b" {bodies} anchor="{x + slip!r} {y!r} {z + half_length!r}"/>')
    return re.sub(r'<connect name="(\w+)" (body1="\w+" body2="\w+") anchor="([^"]+)"/>', doubled, text_)


@pytest.mark.parametrize("scale", [1.0, 1000.0])
def test_a_hinge_written_as_two_ball_closures_on_its_axis_is_one_revolute_loop(tmp_path, scale):
    """Two connects between the same two bodies are the hinge through them (not two legs sharing joints): the
    five-bar opens with the indices of the one-connect file, in metres and in millimetres."""
    plain, doubled = tmp_path / "plain.xml", tmp_path / "doubled.xml"
    plain.write_text(five_bar_mjcf(scale=scale))
    doubled.write_text(_hinges_as_ball_pairs(five_bar_mjcf(scale=scale), 0.05 * scale))
    _, report = read_mechanism_file(doubled)
    assert sum("on one line: the hinge through them" in note for note in report.notes) == 2, report.notes
    expected, got = (indices_at_poses(load(path), poses_near_home() * scale, detail=True) for path in (plain, doubled))
    assert_indices_close(expected, got, TOLERANCE)


def _hinges_as_site_pairs(half_length: float, slip: float) -> str:
    """The five-bar with each closure a hinge written as onshape-to-robot writes it: two connects between sites,
    one site on each body, on the hinge axis ``half_length`` either side of the meeting point; the sites of the
    second connect on the platform side moved by ``slip`` along x (a CAD exporter's rounding)."""
    text_, elbows = five_bar_mjcf(), five_bar_elbows(HOME)
    connects = []
    for i in range(3):
        x, y = (float(v) for v in HOME - elbows[i])
        sites = "".join(f'<site name="s{i + 1}{end}" pos="{x + (slip if i == 0 and end == "b" else 0.0)!r} '
                        f'{y!r} {sign * half_length!r}"/>' for end, sign in (("a", -1), ("b", 1)))
        opening = rf'(<body name="distal_{i + 1}" pos="[^"]+">)'
        text_ = re.sub(opening, lambda m, sites=sites: m.group(1) + sites, text_)
        if i:
            connects += [f'<connect site1="s{i + 1}{end}" site2="s1{end}"/>' for end in "ab"]
    return re.sub(r"<equality>.*</equality>", "<equality>" + "".join(connects) + "</equality>", text_)


def test_closures_that_disagree_by_a_rounding_close_as_well_as_they_can_and_say_by_how_much(tmp_path):
    """A CAD file's redundant closures written with rounded numbers: the two ball joints of one hinge a tenth of a
    micrometre apart on one body from where they are on the other. The file opens, the report says how far the
    closures stay open, and the indices move by about as much; a millimetre off is a file that does not close,
    refused with the closure and the gap."""
    plain, exact, rounded, wrong = (tmp_path / f"{name}.xml" for name in ("plain", "exact", "rounded", "wrong"))
    plain.write_text(five_bar_mjcf())
    exact.write_text(_hinges_as_site_pairs(0.05, slip=0.0))
    rounded.write_text(_hinges_as_site_pairs(0.05, slip=1e-7))
    _, report = read_mechanism_file(exact)
    assert not any("at best" in note for note in report.notes), report.notes
    _, report = read_mechanism_file(rounded)
    assert any("at best" in note and "disagree" in note for note in report.notes), report.notes
    expected = indices_at_pose(load(plain), np.array(HOME))
    for path, tolerance in ((exact, TOLERANCE), (rounded, 1e-5)):
        got = indices_at_pose(load(path), np.array(HOME))
        np.testing.assert_allclose(got.iti_actuators, expected.iti_actuators, atol=tolerance)
        assert abs(got.lmti - expected.lmti) < tolerance
    wrong.write_text(_hinges_as_site_pairs(0.05, slip=1e-3))
    with pytest.raises(ValueError, match=r"cannot be closed.*closure 'connect_\d' still misses by .* after assembly "
                       r"\(every closure's gap after assembly: connect_\d .*\): if the file draws the robot far from "
                       r"an assembly, --initial JOINT VALUE gives joints values nearer one\.$"):
        load(wrong)


def test_a_reference_assembly_outside_a_joint_limit_is_refused_by_name_or_read_with_limits_off(tmp_path):
    """A CAD export whose range misses the assembled value by a rounding: refused naming the source, the joint and
    the way out; read with ``limits=False`` (the command line's --ignore-limits), the note says what was ignored."""
    path = tmp_path / "limited.xml"
    path.write_text(five_bar_mjcf().replace('<joint name="a_1" type="hinge"', '<joint name="a_1" type="hinge" '
                                                                           'range="0.001 1"'))
    with pytest.raises(ValueError, match=re.escape(f"{path}: <joint name='a_1'>: the reference assembly puts the "
                                                   "joint at 0, outside its limits [0.001, 1] (--ignore-limits")):
        load(path)
    mechanism = load(path, limits=False)
    assert mechanism.assembly_notes == ("limits ignored: joint 'a_1': the reference assembly puts the joint at 0, "
                                        "outside its limits [0.001, 1]",)
    points = poses_near_home()
    assert_textbook(indices_at_poses(mechanism, points, detail=True, limits=False), points)


def test_ignore_limits_reads_a_reference_assembly_outside_its_limits_on_every_command(tmp_path):
    """analyze, info and convert: refused in one line naming the joint without --ignore-limits; with it the file
    is read (by map's tasks too), stderr says what was ignored, and convert writes a file that reads the same with
    --ignore-limits."""
    path = tmp_path / "limited.xml"
    path.write_text(five_bar_mjcf().replace('<joint name="a_1" type="hinge"', '<joint name="a_1" type="hinge" '
                                                                           'range="0.001 1"'))
    for command in (("analyze", path), ("info", path), ("convert", path, tmp_path / "refused.urdf")):
        result = screwkit(*command)
        assert result.returncode == 1 and result.stderr.count("\n") == 1, result.stderr
        assert "<joint name='a_1'>: the reference assembly puts the joint at 0, outside its limits" in result.stderr
        assert "--ignore-limits" in result.stderr
    assert not (tmp_path / "refused.urdf").exists()
    analysed = screwkit("analyze", path, "--ignore-limits", "--json")
    assert analysed.returncode == 0, analysed.stderr
    assert "limits ignored: joint 'a_1'" in analysed.stderr
    both = tmp_path / "both.xml"  # two joints outside one range: said once, naming both
    both.write_text(path.read_text().replace('<joint name="a_2" type="hinge"', '<joint name="a_2" type="hinge" '
                                                                              'range="0.001 1"'))
    twice = screwkit("info", both, "--ignore-limits")
    assert twice.returncode == 0 and twice.stderr.count("limits ignored") == 1, twice.stderr
    assert "limits ignored: joints 'a_1', 'a_2': the reference assembly puts each at 0, outside its limits [0.001, " \
           "1]" in twice.stderr
    assert json.loads(analysed.stdout)["lmti"] == pytest.approx(five_bar_expected(HOME)["lmti"], abs=TOLERANCE)
    assert screwkit("info", path, "--ignore-limits", "--json").returncode == 0
    mapped = screwkit("map", path, "--ignore-limits", "--grid", "x:-0.02:0.02:0.01", "--grid", "y:0.33:0.37:0.01",
                      "--quiet", "--out", tmp_path / "map.nc")  # the tasks read the file as it was loaded
    assert mapped.returncode == 0 and (tmp_path / "map.nc").is_file(), mapped.stderr
    out = tmp_path / "converted.urdf"
    converted = screwkit("convert", path, out, "--ignore-limits", "--json")
    assert converted.returncode == 0, converted.stderr
    assert any(note.startswith("limits ignored: joint") for note in json.loads(converted.stdout)["notes"])
    again = json.loads(screwkit("analyze", out, "--ignore-limits", "--json").stdout)
    assert again["lmti"] == pytest.approx(json.loads(analysed.stdout)["lmti"], abs=1e-12)


@pytest.mark.parametrize("name", ["ee_link", "tool0", "Effector_Frame"])
def test_a_tool_frame_named_as_ros_packages_name_theirs_is_the_output(tmp_path, name):
    """A two-legged five-bar whose effector site is called ee_link, tool0 or Effector_Frame (a published Delta's tool
    frame is ee_link, and `--output ee_link` was needed): it is the output, said in the report, with the indices of
    the file whose site is called effector."""
    named, renamed = tmp_path / "named.xml", tmp_path / "renamed.xml"
    named.write_text(five_bar_mjcf(legs=2))
    renamed.write_text(five_bar_mjcf(legs=2).replace('name="effector"', f'name="{name}"'))
    _, report = read_mechanism_file(renamed)
    assert any(f"output frame inferred: {name!r}" in note for note in report.notes), report.notes
    assert_indices_close(indices_at_pose(load(named), np.array(HOME)), indices_at_pose(load(renamed), np.array(HOME)),
                         TOLERANCE)


def test_the_output_frame_a_message_asks_for_is_an_option_of_every_command(tmp_path):
    """Two legs welded to each other with no output frame named: the one-line error asks for --output FRAME; a
    two-leg five-bar (one pin closure: its point is taken) takes it in analyze, info and sweep (the marker site
    names distal_1: the textbook five-bar)."""
    tie, welded = tmp_path / "tie.xml", tmp_path / "welded.xml"
    tie.write_text(five_bar_mjcf(legs=2).replace('name="effector"', 'name="marker"'))
    welded.write_text(re.sub(r' anchor="[^"]*"', "", tie.read_text().replace("<connect ", "<weld ")))
    refused = screwkit("analyze", welded)
    assert refused.returncode == 1 and refused.stderr.count("\n") == 1 and "--output FRAME" in refused.stderr
    analysed = screwkit("analyze", tie, "--output", "marker", "--json")
    assert analysed.returncode == 0, analysed.stderr
    report = json.loads(analysed.stdout)
    expected = five_bar_expected(HOME, legs=(0, 1))
    assert report["lmti"] == pytest.approx(expected["lmti"], abs=TOLERANCE)
    info = screwkit("info", tie, "--output", "marker", "--output-type", "point", "--json")
    assert info.returncode == 0 and json.loads(info.stdout)["dof"] == 2, info.stderr
    swept = screwkit("sweep", tie, "--output", "marker", "--sweep", "x:-0.01:0.01:0.01", "--quiet")
    assert swept.returncode == 0, swept.stderr
    own = screwkit("analyze", "five_bar_3", "--output", "effector")
    assert own.returncode == 1 and "apply to files of other tools" in own.stderr and own.stderr.count("\n") == 1
