"""The safe XML pass and the URDF convention (screwkit.model.urdf_reader)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from helpers import one_line_error, screwkit
from screwkit.io.loader import bundled_names, bundled_path
from screwkit.model.urdf_reader import parse_urdf, read_urdf

MINIMAL = """<?xml version="1.0"?>
<robot name="toy">
  <link name="base_link"/>
  <link name="platform"/>
  <link name="arm"/>
  <joint name="platform_joint" type="planar">
    <parent link="base_link"/><child link="platform"/><axis xyz="0 0 1"/>
  </joint>
  <joint name="arm_joint" type="continuous">
    <parent link="base_link"/><child link="arm"/>
    <origin xyz="1 0 0" rpy="0 0 1.5707963267948966"/><axis xyz="0 0 2"/>
  </joint>
  {loops}
  <transmission name="arm_transmission">
    <type>transmission_interface/SimpleTransmission</type>
    <joint name="arm_joint"><hardwareInterface>hardware_interface/EffortJointInterface</hardwareInterface></joint>
    <actuator name="arm_motor"><mechanicalReduction>1</mechanicalReduction></actuator>
  </transmission>
</robot>
"""

LOOP = """<loop name="arm_tip" type="{type}">
    <predecessor link="{predecessor}"><origin xyz="0.5 0 0" rpy="0 0 0.25"/></predecessor>
    <successor link="platform"><origin xyz="0.1 0.2 0"/></successor>
    {axes}
  </loop>"""


def toy(loop_type="revolute", predecessor="arm", axes='<axis xyz="0 0 1"/>') -> str:
    return MINIMAL.format(loops=LOOP.format(type=loop_type, predecessor=predecessor, axes=axes))


BILLION_LAUGHS = """<?xml version="1.0"?>
<!DOCTYPE robot [
  <!ENTITY lol "lol">
  <!ENTITY lol1 "&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;">
  <!ENTITY lol2 "&lol1;&lol1;&lol1;&lol1;&lol1;&lol1;&lol1;&lol1;&lol1;&lol1;">
  <!ENTITY lol3 "&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;">
  <!ENTITY lol4 "&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;">
  <!ENTITY lol5 "&lol4;&lol4;&lol4;&lol4;&lol4;&lol4;&lol4;&lol4;&lol4;&lol4;">
  <!ENTITY lol6 "&lol5;&lol5;&lol5;&lol5;&lol5;&lol5;&lol5;&lol5;&lol5;&lol5;">
  <!ENTITY lol7 "&lol6;&lol6;&lol6;&lol6;&lol6;&lol6;&lol6;&lol6;&lol6;&lol6;">
  <!ENTITY lol8 "&lol7;&lol7;&lol7;&lol7;&lol7;&lol7;&lol7;&lol7;&lol7;&lol7;">
  <!ENTITY lol9 "&lol8;&lol8;&lol8;&lol8;&lol8;&lol8;&lol8;&lol8;&lol8;&lol8;">
]>
<robot name="&lol9;"><link name="base_link"/></robot>
"""

EXTERNAL_ENTITY = """<?xml version="1.0"?>
<!DOCTYPE robot [<!ENTITY secret SYSTEM "file:///etc/passwd">]>
<robot name="x"><link name="&secret;"/></robot>
"""


def test_reads_loops_transmissions_and_origins():
    description = parse_urdf(toy(), "toy.urdf")
    (loop,) = description.loops
    assert (loop.name, loop.type, loop.predecessor, loop.successor, loop.chain) == (
        "arm_tip", "revolute", "arm", "platform", "arm_tip",
    )  # fmt: skip
    np.testing.assert_allclose(loop.predecessor_origin.xyz, [0.5, 0, 0])
    np.testing.assert_allclose(loop.predecessor_origin.rpy, [0, 0, 0.25])
    np.testing.assert_allclose(loop.successor_origin.xyz, [0.1, 0.2, 0])
    np.testing.assert_allclose(loop.axes[0], [0, 0, 1])
    assert description.transmissions[0].joints == ("arm_joint",)
    joint = description.joints["arm_joint"]
    np.testing.assert_allclose(joint.axis, [0, 0, 1])  # normalised
    np.testing.assert_allclose(joint.origin.rotation @ [1, 0, 0], [0, 1, 0], atol=1e-15)


@pytest.mark.parametrize(
    ("loop_type", "axes", "n_axes"),
    [
        ("revolute", '<axis xyz="0 0 1"/>', 1),
        ("continuous", '<axis xyz="0 0 1"/>', 1),
        ("prismatic", '<axis xyz="1 0 0"/>', 1),
        ("universal", '<axis xyz="1 0 0"/><axis2 xyz="0 1 0"/>', 2),
        ("spherical", "", 0),
        ("fixed", "", 0),
    ],
)
def test_supported_loop_types(loop_type, axes, n_axes):
    (loop,) = parse_urdf(toy(loop_type, axes=axes)).loops
    assert loop.type == loop_type and len(loop.axes) == n_axes


@pytest.mark.parametrize(
    ("document", "expected"),
    [
        ("<robot name='x'><link name='a'></robot>", "malformed XML"),
        (toy(predecessor="elbow"), "<loop name='arm_tip'>: <predecessor> names an unknown link 'elbow'"),
        (toy("ball"), "unsupported loop joint type 'ball'"),
        (toy("universal"), "<axis2 xyz='...'/> is missing"),
        (toy("revolute", axes=""), "<axis xyz='...'/> is missing"),
        (toy(axes='<axis xyz="0 0 0"/>'), "the axis is the zero vector"),
        (toy(axes='<axis xyz="0 zero 1"/>'), "expected three finite numbers in 'xyz'"),
        (
            MINIMAL.format(loops="").replace('<joint name="arm_joint"><hardware', "<joint><hardware"),
            "<transmission name='arm_transmission'><joint>: the attribute 'name' is missing",
        ),
        (
            MINIMAL.format(loops="").replace('<joint name="arm_joint" type', "<joint type"),
            "<joint>: the attribute 'name'",
        ),
        (MINIMAL.format(loops="").replace('type="continuous"', 'type="ball"'), "unknown joint type 'ball'"),
        (MINIMAL.format(loops="").replace("<link name=\"arm\"/>", "<link name=\"platform\"/>"), "used twice"),
        ("<robot name='x'><link name='a'/><transmission name='t'/></robot>", "drives no joint"),
        ("<sdf version='1.6'/>", "expected the root element <robot>"),
    ],
)
def test_bad_documents_raise_one_line_errors_naming_file_and_element(document, expected):
    with pytest.raises(ValueError) as error:
        parse_urdf(document, "bad.urdf")
    message = str(error.value)
    assert message.startswith("bad.urdf: ") and expected in message
    assert "\n" not in message


@pytest.mark.parametrize("document", [BILLION_LAUGHS, EXTERNAL_ENTITY, BILLION_LAUGHS.replace("DOCTYPE", "doctype")])
def test_entity_declarations_are_refused_without_expansion(document):
    """Refused at the declaration itself (an expanded bomb takes gigabytes and minutes)."""
    with pytest.raises(ValueError, match=r"bomb\.urdf: <!DOCTYPE> at line 2: document type and entity declarations"):
        parse_urdf(document.encode(), "bomb.urdf")


def test_entity_bomb_file_is_refused_before_pinocchio_sees_it(tmp_path):
    path = tmp_path / "bomb.urdf"
    path.write_text(BILLION_LAUGHS)
    from screwkit.io.loader import load

    with pytest.raises(ValueError, match="document type and entity declarations are refused"):
        load(path)


def test_bare_entity_declaration_is_refused():
    with pytest.raises(ValueError, match="<!ENTITY> at line 1"):
        parse_urdf('<!ENTITY x "y"><robot name="r"/>')


def test_missing_file_is_a_value_error(tmp_path):
    with pytest.raises(ValueError, match="cannot read the file"):
        read_urdf(tmp_path / "nothing.urdf")


@pytest.mark.parametrize("name", bundled_names())
def test_bundled_files_load_in_pinocchio_and_yourdfpy(name):
    import pinocchio
    import yourdfpy

    path = bundled_path(name)
    description = read_urdf(path)
    model = pinocchio.buildModelFromUrdf(str(path))
    tree_joints = {joint.name for joint in description.joints.values() if joint.type != "fixed"}
    assert set(model.names[1:]) == tree_joints
    robot = yourdfpy.URDF.load(str(path), load_meshes=False, build_scene_graph=True)
    assert set(robot.joint_map) == set(description.joints)
    assert set(robot.link_map) == set(description.links)
    assert description.loops and description.transmissions


NO_LOOP = MINIMAL.format(loops="")


def with_arm(joint_type="continuous", inside="", extra="") -> str:
    """The toy robot with its arm joint of ``joint_type``, ``inside`` added to the joint, ``extra`` to the robot."""
    document = NO_LOOP.replace('name="arm_joint" type="continuous"', f'name="arm_joint" type="{joint_type}"')
    document = document.replace('<axis xyz="0 0 2"/>', f'<axis xyz="0 0 2"/>{inside}')
    return document.replace("</robot>", f"{extra}</robot>")


ARM_LIMIT = "<joint name='arm_joint'><limit>"


@pytest.mark.parametrize(
    ("document", "element", "problem"),
    [
        (with_arm("revolute"), ARM_LIMIT, "the element is missing: URDF requires <limit effort='...' velocity='...'/> "
                                          "on a revolute joint"),
        (with_arm("prismatic"), ARM_LIMIT, "the element is missing: URDF requires <limit effort='...' velocity='...'/> "
                                           "on a prismatic joint"),
        (with_arm("revolute", '<limit lower="-3" upper="3"/>'), ARM_LIMIT,
         "the attributes 'effort' and 'velocity' are missing"),
        (with_arm("revolute", '<limit lower="-3" upper="3" velocity="1"/>'), ARM_LIMIT,
         "the attribute 'effort' is missing"),
        (with_arm("prismatic", '<limit lower="-3" upper="3" effort="1"/>'), ARM_LIMIT,
         "the attribute 'velocity' is missing"),
        (with_arm("continuous", '<limit effort="1"/>'), ARM_LIMIT, "the attribute 'velocity' is missing"),
        (with_arm("revolute", '<limit effort="nan" velocity="1"/>'), ARM_LIMIT,
         "expected a finite number in 'effort', got 'nan'"),
        (with_arm("revolute", '<limit effort="1" velocity="-2"/>'), ARM_LIMIT,
         "expected a number of at least 0 in 'velocity', got '-2'"),
        (with_arm("continuous", '<limit effort="1" velocity="1" lower="low"/>'), ARM_LIMIT,
         "expected a finite number in 'lower', got 'low'"),
        (with_arm("revolute", '<limit effort="1" velocity="1"/><mimic joint="platform_joint" multiplier="2"/>'),
         "<joint name='arm_joint'><mimic joint='platform_joint'>", "coupled (mimic) joints are not modelled"),
        (with_arm(extra='<named_pose name="p" x="0" y="0" phi="1e6"/>'), "<named_pose name='p'>",
         "expected angles of at most 628.319 rad (100 turns) either way, got phi = 1e6"),
        (with_arm(extra='<named_pose name="q" x="0" y="0" phi="-629"/>'), "<named_pose name='q'>",
         "expected angles of at most 628.319 rad (100 turns) either way, got phi = -629"),
    ],
)
def test_limits_mimic_repeated_units_and_huge_named_angles_are_refused_naming_the_element(document, element, problem):
    with pytest.raises(ValueError) as error:
        parse_urdf(document, "bad.urdf")
    message = str(error.value)
    assert message.startswith(f"bad.urdf: {element}: {problem}"), message
    assert "\n" not in message


def test_repeated_units_must_agree():
    """A repeated <units> that says the same is harmless; one that disagrees is refused (not the last one winning)."""
    assert parse_urdf(with_arm(extra='<units length="mm"/><units length="mm"/>'), "mm.urdf").length_unit == "mm"
    for extra, element, before in (('<units length="mm"/><units length="m"/>', "<units length='m'>", "mm"),
                                   ('<units length="m"/><units length="in"/>', "<units length='in'>", "m")):
        with pytest.raises(ValueError) as error:
            parse_urdf(with_arm(extra=extra), "units.urdf")
        message = str(error.value)
        assert message == (f"units.urdf: {element}: a second <units> element disagrees with <units length='{before}'> "
                           "before it; keep one."), message
        with pytest.raises(ValueError, match="disagrees"):  # even when the caller gives the unit
            parse_urdf(with_arm(extra=extra), "units.urdf", length_unit="mm")


LIMITS = ("", "<limit/>", '<limit effort="1"/>', '<limit velocity="1"/>', '<limit effort="1" velocity="1"/>',
          '<limit lower="-1" upper="1" effort="1" velocity="1"/>', '<limit upper="1" effort="0" velocity="0"/>',
          '<limit effort="x" velocity="1"/>', '<limit effort="1" velocity="inf"/>',
          '<limit effort="1e400" velocity="1"/>', '<limit effort="-1" velocity="1"/>',
          '<limit effort="1" velocity="-1"/>', '<limit effort="1" velocity="1" lower="a"/>',
          '<limit effort="1" velocity="1" upper="nan"/>')
"""<limit> elements urdfdom and Pinocchio read or refuse (effort and velocity required, lower and upper optional)."""


@pytest.mark.parametrize("joint_type", ["revolute", "prismatic", "continuous", "fixed"])
def test_joint_limits_are_refused_exactly_when_pinocchio_refuses_them(joint_type):
    """The XML pass refuses what urdfdom and Pinocchio refuse (before they print to stderr), and nothing more."""
    import pinocchio

    for limit in LIMITS:
        document = with_arm(joint_type, limit)
        try:
            pinocchio.buildModelFromXML(document)
            pinocchio_refuses = False
        except Exception:
            pinocchio_refuses = True
        try:
            parse_urdf(document, "limits.urdf")
            screwkit_refuses = False
        except ValueError as error:
            screwkit_refuses = True
            assert str(error).startswith("limits.urdf: <joint name='arm_joint'><limit>: "), str(error)
        assert screwkit_refuses == pinocchio_refuses, (joint_type, limit)


def test_revolute_joint_without_limit_is_refused_before_urdfdom_prints_anything(tmp_path):
    from helpers import one_line_error, screwkit

    text = bundled_path("planar_5rrr").read_text()
    joint = '<joint name="chain_1_joint_c" type="continuous">'
    assert joint in text
    path = tmp_path / "revolute_nolimit.urdf"
    path.write_text(text.replace(joint, joint.replace("continuous", "revolute")))
    expected = f"{path}: <joint name='chain_1_joint_c'><limit>: the element is missing: URDF requires <limit "
    line = one_line_error(screwkit("analyze", path), expected)
    assert "joint.cpp" not in line and "Pinocchio" not in line
    result = screwkit("analyze", path, "--json")  # the error as JSON on stdout, nothing on stderr
    assert (result.returncode, result.stderr) == (1, "")
    assert json.loads(result.stdout)["error"].startswith(expected)


def test_a_tree_with_mimic_joints_and_no_loop_is_told_what_a_closed_loop_file_needs(tmp_path):
    """A Delta written as a tree whose arms mimic one another (published as such) was told to remove the <mimic>,
    then refused as a tree: the first refusal now says the file closes no loop either; a file with loops is told
    only of the <mimic>."""
    path = tmp_path / "tree.urdf"
    path.write_text('<robot name="delta"><link name="base"/><link name="arm_1"/><link name="arm_2"/>'
                    '<joint name="j1" type="revolute"><parent link="base"/><child link="arm_1"/><axis xyz="0 0 1"/>'
                    '<limit effort="1" velocity="1"/></joint><joint name="j2" type="revolute"><parent link="base"/>'
                    '<child link="arm_2"/><axis xyz="0 0 1"/><limit effort="1" velocity="1"/><mimic joint="j1"/>'
                    '</joint></robot>')
    with pytest.raises(ValueError) as error:
        read_urdf(path)
    message = str(error.value)
    assert "coupled (mimic) joints are not modelled" in message and "the file closes no loop either" in message
    assert "\n" not in message
    one_line_error(screwkit("info", path), "tree.urdf", "<mimic joint='j1'>", "the file closes no loop either")
