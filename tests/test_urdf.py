"""The safe XML pass and the URDF convention (screwkit.model.urdf_reader)."""

from __future__ import annotations

import numpy as np
import pytest

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
