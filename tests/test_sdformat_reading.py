"""What the SDFormat reader refuses and how it reads what it accepts: includes anywhere, poses (a zero quaternion,
``degrees``), joint limits as SDFormat and Gazebo take them, unnamed elements, and the spanning tree (a ball joint
carrying the platform, fixed links in a leg), checked against the spec's meaning and the bundled robots.

SDFormat's spec (sdformat.org/spec, sdf/1.9): ``<pose degrees>`` is a bool (libsdformat takes true, false, 1, 0 and
refuses anything else, and degrees on a quaternion); ``<link name>``, ``<joint name>``, ``<frame name>`` are
required; an axis's ``<lower>``/``<upper>``: "Omit if joint is continuous" (a continuous joint has no limits; Gazebo's
physics engines apply limits to revolute and prismatic joints only). Gazebo holds a joint whose lower and upper
limits are equal at that value: the reader refuses it, saying so (write it fixed), and refuses an inverted range.
"""

from __future__ import annotations

import json
import xml.etree.ElementTree as ElementTree

import numpy as np
import pinocchio as pin
import pytest
from sdformat_models import NAMESPACE, PROXIMAL, five_bar_elbows, five_bar_sdf, hexapod_legs
from test_io import HOME

from helpers import one_line_error, screwkit
from screwkit.common.rotations import rotation_from_rpy
from screwkit.io import ImportError_, graph_mechanism, read_closed_tree, read_mechanism_file
from screwkit.io.loader import bundled_path, load, load_text
from screwkit.io.sdformat_text import read_model, world_poses
from screwkit.studies import indices_at_pose

TOLERANCE = 1e-9


def write(tmp_path, text: str, name: str = "robot.sdf"):
    path = tmp_path / name
    path.write_text(text)
    return path


def refused(tmp_path, text: str, *needles: str) -> str:
    """The one-line refusal of reading ``text``: naming the file and every needle, no 'None' for a name."""
    with pytest.raises(ImportError_) as error:
        read_closed_tree(write(tmp_path, text))
    message = str(error.value)
    assert "\n" not in message and message.startswith(str(tmp_path / "robot.sdf") + ": "), message
    assert "name='None'" not in message, message
    for needle in needles:
        assert needle in message, (needle, message)
    return message


def same_indices(found, reference) -> None:
    assert found.dof == reference.dof
    assert found.lmti == pytest.approx(reference.lmti, abs=TOLERANCE)
    for j in reference.faults:
        assert found.f_o[j] == pytest.approx(reference.f_o[j], abs=TOLERANCE)
    np.testing.assert_allclose(sorted(found.iti_actuators), sorted(reference.iti_actuators), atol=TOLERANCE)


def at_home(mechanism):
    return indices_at_pose(mechanism, mechanism.home_pose)


# -- <include> --------------------------------------------------------------------------------------------------------

INCLUDE = "<include><uri>model://foo</uri></include>"


@pytest.mark.parametrize(("edit", "scope"), [
    (lambda t: t.replace('<link name="base"/>', '<link name="base"/>' + INCLUDE), "<model name='five_bar'>"),
    (lambda t: t.replace('<link name="base"/>', '<link name="base"/><model name="arm">' + INCLUDE + "</model>"),
     "<model name='arm'>"),
    (lambda t: t.replace("<model ", INCLUDE + "<model "), "<sdf>"),
])
def test_an_include_is_refused_wherever_it_is_naming_the_file_and_where_it_is(tmp_path, edit, scope):
    """The module says included models are refused: one inside the model was read as if it were not there."""
    refused(tmp_path, edit(five_bar_sdf()), "<include> of 'model://foo': included models are not read", scope)


# -- poses ------------------------------------------------------------------------------------------------------------

def with_pose(link: str, words: str) -> str:
    """The five-bar with ``link``'s <pose> text replaced by ``words`` (its attributes kept)."""
    text = five_bar_sdf()
    start = text.index(">", text.index("<pose", text.index(f'<link name="{link}">'))) + 1
    return text[:start] + words + text[text.index("</pose>", start):]


@pytest.mark.parametrize("quaternion", ["0 0 0 0", "0 0 0 0.0", "1e-300 0 0 0"])
def test_a_zero_quaternion_is_refused_in_one_line_naming_the_link(tmp_path, quaternion):
    """It was divided by its zero norm: a RuntimeWarning, then 'SVD did not converge'."""
    refused(tmp_path, with_pose("effector", f"0.1 0.2 0 {quaternion}"), "<link name='effector'>", "quaternion",
            "zero")


@pytest.mark.parametrize("value", ["nan", "inf", "-inf"])
def test_a_pose_value_that_is_not_finite_is_refused(tmp_path, value):
    refused(tmp_path, with_pose("proximal_1", f"{value} 0 0 0 0 0"), "<link name='proximal_1'>", "finite")
    refused(tmp_path, with_pose("effector", f"0 0 0 0 0 {value} 1"), "<link name='effector'>", "finite")


@pytest.mark.parametrize(("flag", "in_degrees"), [("true", True), ("TRUE", True), ("1", True), ("false", False),
                                                  ("0", False), (" True ", True)])
def test_degrees_is_an_sdformat_bool(tmp_path, flag, in_degrees):
    """``degrees`` takes true/false/1/0 (any case): the pose is the one written in radians."""
    angles = np.array([10.0, -20.0, 35.0])
    written = angles if in_degrees else np.radians(angles)
    text = (f'<sdf version="1.9"><model name="m"><link name="a"><pose degrees="{flag}">0.1 0.2 0.3 '
            + " ".join(repr(float(v)) for v in written) + '</pose></link></model></sdf>')
    pose = world_poses(read_model(write(tmp_path, text)))["a"]
    np.testing.assert_allclose(pose[:3, :3], rotation_from_rpy(np.radians(angles)), atol=1e-12)
    np.testing.assert_allclose(pose[:3, 3], [0.1, 0.2, 0.3], atol=1e-12)


@pytest.mark.parametrize(("edit", "needles"), [
    (lambda t: t.replace('<pose degrees="true">', '<pose degrees="yes">'), ("<pose degrees='yes'>", "true or false")),
    (lambda t: t.replace('<pose rotation_format="quat_xyzw">', '<pose rotation_format="quat_xyzw" degrees="true">'),
     ("<link name='effector'>", "quaternion")),
    (lambda t: t.replace("<limit><lower>-3</lower>", '<limit degrees="true"><lower>-3</lower>', 1),
     ("<joint name='mot1'>", "degrees", "radians")),
    (lambda t: t.replace("<limit><lower>-3</lower>", '<limit><lower degrees="true">-3</lower>', 1),
     ("<joint name='mot1'>", "degrees", "radians")),
])
def test_degrees_that_sdformat_does_not_define_are_refused(tmp_path, edit, needles):
    """``degrees="yes"`` was read as radians; SDFormat refuses it (not a bool), and degrees on a quaternion; on a
    joint's limits SDFormat has no degrees at all (radians), so a file relying on it is refused, not misread."""
    text = edit(five_bar_sdf())
    assert text != five_bar_sdf()
    refused(tmp_path, text, *needles)


def _parent_frame(offset: float, scale: float, relative: bool = False) -> str:
    """The five-bar at ``scale`` with joint free1's <parent> a <frame> on proximal_1 drawn ``offset`` (in units of the
    five-bar) along it beyond the elbow, where free1 is; ``relative``: free1's pose given relative to that frame."""
    frame = (f'<frame name="pin1" attached_to="proximal_1"><pose relative_to="proximal_1">'
             f'{scale * (PROXIMAL + offset)!r} 0 0 0 0 0</pose></frame>')
    old = '<joint name="free1" type="continuous"><parent>proximal_1</parent>'
    new = '<joint name="free1" type="continuous"><parent>pin1</parent>' + (
        '<pose relative_to="pin1">0 0 0 0 0 0</pose>' if relative else "")
    text_ = five_bar_sdf((scale, 0.3, (0.4 * scale, -0.2 * scale, 0.1 * scale)))
    assert old in text_
    return text_.replace(old, new).replace('<link name="base"/>', '<link name="base"/>' + frame)


@pytest.mark.parametrize("scale", [1e-3, 1.0, 1e3])
def test_a_parent_frame_away_from_its_joint_is_said_with_its_distance(tmp_path, scale):
    """SDFormat places a joint at its child frame and <pose>; a <parent> <frame> only names the link. A file drawn as
    if the parent frame placed the joint (Drake's 'aspirational' four-bar) was read without a word: a note names the
    joint, the frame and how far apart they are, at any scale; none when the frame is at the joint, or when the
    joint's pose is given relative to it."""
    away = read_closed_tree(write(tmp_path, _parent_frame(0.05, scale), "away.sdf"))
    said = [note for note in away.notes if "'free1'" in note]
    assert len(said) == 1 and "'pin1'" in said[0] and "relative_to" in said[0], away.notes
    distance = float(said[0].split("'pin1' is ")[1].split(" m")[0])
    assert distance == pytest.approx(0.05 * scale, rel=1e-3)
    for text_ in (_parent_frame(0.0, scale), _parent_frame(0.05, scale, relative=True)):
        tree = read_closed_tree(write(tmp_path, text_, "at.sdf"))
        assert not any("<parent> is a <frame>" in note for note in tree.notes), tree.notes
    # the joint is where SDFormat puts it: at the elbow (the child), not at the frame
    model, data = away.model, away.model.createData()
    pin.forwardKinematics(model, data, away.q_reference)
    elbow = five_bar_elbows(HOME)[0]
    at = data.oMi[model.getJointId("free1")].translation
    turn = np.array([[np.cos(0.3), -np.sin(0.3)], [np.sin(0.3), np.cos(0.3)]])
    expected = np.array([*(scale * turn @ elbow + scale * np.array([0.4, -0.2])), 0.1 * scale])
    np.testing.assert_allclose(at, expected, atol=1e-9 * scale)


def test_info_says_which_joint_s_parent_frame_is_away(tmp_path):
    result = screwkit("info", write(tmp_path, _parent_frame(0.05, 1.0), "away.sdf"))
    assert result.returncode == 0, result.stderr
    assert "'free1' ('pin1' is 0.05 m from it)" in result.stdout, result.stdout


# -- joint limits -----------------------------------------------------------------------------------------------------

def limited(kind: str, lower: str, upper: str) -> str:
    """The five-bar with its first elbow (continuous in five_bar_sdf) of type ``kind`` limited to [lower, upper]."""
    old = ('<joint name="free1" type="continuous"><parent>proximal_1</parent><child>distal_1</child><axis><xyz>0 0 1'
           '</xyz></axis>')
    text = five_bar_sdf()
    assert old in text
    return text.replace(old, old.replace('type="continuous"', f'type="{kind}"').replace(
        "</xyz></axis>", f"</xyz><limit><lower>{lower}</lower><upper>{upper}</upper></limit></axis>"))


def test_a_continuous_joint_s_limits_are_ignored_as_sdformat_says(tmp_path):
    """A continuous joint limited to [0.5, 1] (the file's configuration, 0, outside): read as the same joint
    without limits, as SDFormat says; a revolute joint with those limits keeps them (and is refused there)."""
    plain = load(write(tmp_path, five_bar_sdf(), "plain.sdf"))
    with_limits = load(write(tmp_path, limited("continuous", "0.5", "1"), "limits.sdf"))
    same_indices(at_home(with_limits), at_home(plain))
    tree = read_closed_tree(tmp_path / "limits.sdf")
    index = tree.model.joints[tree.model.getJointId("free1")].idx_q
    assert tree.model.lowerPositionLimit[index] == -np.inf and tree.model.upperPositionLimit[index] == np.inf
    with pytest.raises(ValueError, match=r"outside its limits \[0.5, 1\]"):
        load(write(tmp_path, limited("revolute", "0.5", "1"), "revolute.sdf"))


@pytest.mark.parametrize("kind", ["revolute", "prismatic"])
def test_an_inverted_limit_is_refused_naming_the_joint(tmp_path, kind):
    """lower > upper was read as no limit at all."""
    refused(tmp_path, limited(kind, "1", "-1"), "<joint name='free1'>", "lower 1 > upper -1")


def test_equal_limits_at_zero_are_the_fixed_joint_gazebo_holds(tmp_path):
    """lower = upper = 0: Gazebo holds the joint where the file draws it, so it is the fixed joint (a published
    Codian Delta holds the platform's six ball mounts so, and was refused): read as the file with that joint written
    fixed, the same DOF, coordinates and indices, and a note names it. Equal limits elsewhere than 0 hold it away
    from where the file draws it: still refused, naming the joint (lower = upper was once read as no limit)."""
    old = ('<joint name="free1" type="continuous"><parent>proximal_1</parent><child>distal_1</child><axis><xyz>0 0 1'
           '</xyz></axis>')
    fixed = load(write(tmp_path, five_bar_sdf().replace(old, '<joint name="free1" type="fixed"><parent>proximal_1'
                                                             '</parent><child>distal_1</child>'), "fixed.sdf"))
    held = load(write(tmp_path, limited("revolute", "0", "0"), "held.sdf"))
    assert (held.dof, held.task_coordinates) == (fixed.dof, fixed.task_coordinates) == (1, ("x",))
    same_indices(at_home(held), at_home(fixed))
    assert any("'free1'" in line and "lower = upper = 0" in line and "fixed" in line for line in held.import_report)
    refused(tmp_path, limited("revolute", "0.3", "0.3"), "<joint name='free1'>", "lower = upper = 0.3",
            "cannot move", "fixed")


def test_a_continuous_joint_with_inverted_limits_is_read_as_sdformat_reads_it_without(tmp_path):
    tree = read_closed_tree(write(tmp_path, limited("continuous", "1", "-1")))
    assert "free1" in list(tree.model.names)


# -- names ------------------------------------------------------------------------------------------------------------

@pytest.mark.parametrize(("edit", "needles"), [
    (lambda t: t.replace('<link name="proximal_2">', "<link>"), ("<model name='five_bar'>", "4th <link> has no name")),
    (lambda t: t.replace('<joint name="free2"', "<joint"), ("<model name='five_bar'>", "6th <joint> has no name")),
    (lambda t: t.replace('<link name="effector">', '<frame><pose/></frame><link name="effector">'),
     ("<model name='five_bar'>", "1st <frame> has no name")),
    (lambda t: t.replace('<model name="five_bar">', "<model>"), ("<model> has no name",)),
])
def test_an_unnamed_element_is_refused_by_its_position(tmp_path, edit, needles):
    """SDFormat requires names; an unnamed link was reported as <link name='None'>."""
    text = edit(five_bar_sdf())
    assert text != five_bar_sdf()
    refused(tmp_path, text, *needles)


# -- a ball joint carrying the platform: U-P-S legs ------------------------------------------------------------------

def ups_hexapod_sdf(reversed_ball: bool = False) -> str:
    """The bundled U-P-S hexapod (robots/ups_hexapod_8.urdf) in SDFormat: per leg a universal joint at the base, the
    actuated slide, a ball joint at the platform (``reversed_ball``: written platform to piston)."""
    platform, legs = hexapod_legs()
    lines = [f'<?xml version="1.0"?>\n<sdf version="1.9" {NAMESPACE}>\n<model name="ups">',
             '<link name="base"/><joint name="anchor" type="fixed"><parent>world</parent><child>base</child></joint>',
             f'<link name="platform"><pose>{platform}</pose></link>']
    for leg, base_pose, axes, length in legs:
        ends = ("platform", f"{leg}_pis") if reversed_ball else (f"{leg}_pis", "platform")
        lines.append(f'<link name="{leg}_cyl"><pose>{base_pose}</pose></link>'
                     f'<link name="{leg}_pis"><pose relative_to="{leg}_cyl"/></link>'
                     f'<joint name="{leg}_u" type="universal"><parent>base</parent><child>{leg}_cyl</child>'
                     f'<axis><xyz>{axes[0]}</xyz></axis><axis2><xyz>{axes[1]}</xyz></axis2></joint>'
                     f'<joint name="{leg}_slider" type="prismatic"><parent>{leg}_cyl</parent><child>{leg}_pis</child>'
                     f'<axis><xyz>{axes[2]}</xyz></axis><screwkit:actuated/></joint>'
                     f'<joint name="{leg}_s" type="ball"><parent>{ends[0]}</parent><child>{ends[1]}</child>'
                     f'<pose relative_to="{leg}_pis">{length} 0 0 0 0 0</pose></joint>')
    lines.append("</model>\n</sdf>")
    return "\n".join(lines)


@pytest.mark.parametrize("reversed_ball", [False, True])
def test_a_ups_hexapod_converts_with_the_bundled_hexapod_s_indices(tmp_path, reversed_ball):
    """The leg carrying the platform in the tree has its ball joint in it (as three hinges through its centre, as
    docs/urdf-convention.md writes a spherical joint inside a leg): convert refused it as a ball joint inside a leg."""
    path = write(tmp_path, ups_hexapod_sdf(reversed_ball))
    text, report = read_mechanism_file(path)
    assert report.platform_body == "platform"
    reference = at_home(load("ups_hexapod_8"))
    same_indices(at_home(load_text(text, str(path))), reference)
    same_indices(at_home(load(path)), reference)


@pytest.mark.cli
def test_convert_writes_a_ups_hexapod_whose_analysis_is_the_bundled_one(tmp_path):
    source = write(tmp_path, ups_hexapod_sdf(), "hex.sdf")
    converted = screwkit("convert", source, tmp_path / "hex.urdf")
    assert converted.returncode == 0, converted.stderr
    reports = [json.loads(screwkit("analyze", path, "--json").stdout)
               for path in (tmp_path / "hex.urdf", source, "ups_hexapod_8")]
    for report in reports[:2]:
        assert report["lmti"] == pytest.approx(reports[2]["lmti"], abs=TOLERANCE)
        assert report["f_o"] == pytest.approx(reports[2]["f_o"], abs=TOLERANCE)


# -- fixed links inside a leg -----------------------------------------------------------------------------------------

def rpr_sdf(welded: int) -> str:
    """The bundled planar 4-RPR (robots/planar_4rpr.urdf) in SDFormat; legs 2 to 4 written with ``welded`` links
    fixed one to the next between the base pivot and the slide, and their platform pivot written from the platform."""
    root = ElementTree.parse(bundled_path("planar_4rpr")).getroot()
    joints = {joint.get("name"): joint for joint in root.findall("joint")}
    loops = {loop.get("name"): loop for loop in root.findall("loop")}
    legs = sorted({name.split("_joint")[0] for name in joints if name.startswith("leg_")})
    lines = [f'<?xml version="1.0"?><sdf version="1.9" {NAMESPACE}><model name="rpr">',
             '<link name="base"/><joint name="anchor" type="fixed"><parent>world</parent><child>base</child></joint>',
             '<link name="platform"/>']
    for k, leg in enumerate(legs):
        origin = joints[f"{leg}_joint_base"].find("origin")
        yaw = float(origin.get("rpy").split()[2])
        length = float(loops[f"{leg}_joint_platform"].find("predecessor/origin").get("xyz").split()[0])
        start = np.array([float(word) for word in origin.get("xyz").split()])
        top = start + length * np.array([np.cos(yaw), np.sin(yaw), 0.0])
        lines.append(f'<link name="{leg}_cyl"><pose>{origin.get("xyz")} 0 0 {yaw!r}</pose></link>'
                     f'<link name="{leg}_pis"><pose>{float(top[0])!r} {float(top[1])!r} 0 0 0 {yaw!r}</pose></link>'
                     f'<joint name="{leg}_base" type="revolute"><parent>base</parent><child>{leg}_cyl</child>'
                     '<axis><xyz>0 0 1</xyz></axis></joint>')
        previous = f"{leg}_cyl"
        for i in range(welded if k else 0):
            lines.append(f'<link name="{leg}_f{i}"><pose relative_to="{leg}_cyl"/></link><joint name="{leg}_fx{i}" '
                         f'type="fixed"><parent>{previous}</parent><child>{leg}_f{i}</child></joint>')
            previous = f"{leg}_f{i}"
        top_joint = (f'<joint name="{leg}_top" type="revolute"><parent>platform</parent><child>{leg}_pis</child>'
                     if k else f'<joint name="{leg}_top" type="revolute"><parent>{leg}_pis</parent><child>platform'
                     '</child>')
        lines.append(f'<joint name="{leg}_slider" type="prismatic"><parent>{previous}</parent><child>{leg}_pis'
                     f'</child><pose relative_to="{leg}_cyl"/><axis><xyz>1 0 0</xyz></axis><screwkit:actuated/>'
                     f'</joint>{top_joint}<pose relative_to="{leg}_pis"/><axis><xyz>0 0 1</xyz></axis></joint>')
    lines.append("</model></sdf>")
    return "\n".join(lines)


@pytest.mark.parametrize("welded", [0, 3, 4, 7])
def test_fixed_links_inside_a_leg_do_not_move_the_loop_into_it(tmp_path, welded):
    """Four or more welded links made the platform side reach the piston first, and the loop closed on a fixed joint
    inside the leg, refused; welded links are one body in the spanning tree: the bundled 4-RPR's indices."""
    path = write(tmp_path, rpr_sdf(welded))
    read_mechanism_file(path)
    same_indices(at_home(load(path)), at_home(load("planar_4rpr")))


@pytest.mark.cli
@pytest.mark.parametrize(("text", "needles"), [
    (five_bar_sdf().replace('<link name="base"/>', '<link name="base"/>' + INCLUDE), ("<include> of 'model://foo'",)),
    (with_pose("effector", "0 0 0 0 0 0 0"), ("<link name='effector'>", "zero")),
    (limited("revolute", "1", "-1"), ("<joint name='free1'>", "lower 1 > upper -1")),
    (five_bar_sdf().replace('<link name="proximal_2">', "<link>"), ("4th <link> has no name",)),
])
def test_the_command_line_refuses_in_one_line_with_no_warning(tmp_path, text, needles):
    path = write(tmp_path, text)
    one_line_error(screwkit("analyze", path), str(path), *needles)


def test_a_tool_turning_on_its_own_joint_after_the_platform_leaves_the_platform_where_the_legs_meet(tmp_path):
    """A published Codian Delta hangs its tool 'ee' off the platform by a revolute of its own: 'ee' was taken as the
    platform, and the legs, which meet on the body before it, were refused as a closed-loop transmission. The
    platform is the body where the closures meet, said in a note, and the Delta reads as without the tool (the
    indices of the rod-level Delta, as a subprocess)."""
    from sdformat_models import delta_sdf

    tool = ('<link name="ee"><pose relative_to="platform">0 0 -0.04 0 0 0</pose></link><joint name="tool_spin" '
            'type="revolute"><parent>platform</parent><child>ee</child><axis><xyz>0 0 1</xyz></axis></joint>')
    plain = write(tmp_path, delta_sdf(), "plain.sdf")
    turning = write(tmp_path, delta_sdf().replace("</model>", tool + "</model>"), "turning.sdf")
    reports = []
    for path in (plain, turning):
        analysed = screwkit("analyze", path, "--json")
        assert analysed.returncode == 0, analysed.stderr
        reports.append(json.loads(analysed.stdout))
    assert reports[1]["iti"] == pytest.approx(reports[0]["iti"], abs=1e-9)
    assert reports[1]["lmti"] == pytest.approx(reports[0]["lmti"], abs=1e-9)
    described = screwkit("info", turning)
    assert described.returncode == 0, described.stderr
    assert "frame 'ee' hangs off it by joint(s) tool_spin, after the parallel part" in described.stdout


def bracketed_delta(tmp_path, reverse: bool = False, transform=None) -> tuple[str, str]:
    """The rod-level Delta with its platform called 'carrier' (no output name), plain and with each rod's far ball
    on a bracket welded to the carrier 1 cm below the ball (a Codian Delta's brackets), ``reverse``: the brackets
    and their welds written in reverse order. The spanning tree reaches a bracket before the carrier."""
    from sdformat_models import delta_sdf

    plain = delta_sdf(transform=transform).replace("platform", "carrier")
    root = ElementTree.fromstring(plain.split("\n", 1)[1])
    model = root.find("model")
    ends = [joint for joint in model.findall("joint") if joint.get("name").startswith("end_")]
    poses = world_poses(read_model(write(tmp_path, plain, "plain.sdf")))
    carrier = poses["carrier"]
    added = []
    for joint in ends:
        name = joint.get("name").replace("end_", "bracket_")
        ball = poses[joint.get("name")][:3, 3]
        below = np.linalg.solve(carrier[:3, :3], ball - carrier[:3, 3]) - np.array([0.0, 0.0, 0.01])
        joint.find("child").text = name
        pose = joint.find("pose")
        pose.text = " ".join(repr(float(v)) for v in np.linalg.solve(carrier[:3, :3], ball - carrier[:3, 3])) \
            + " 0 0 0"
        pose.set("relative_to", "carrier")
        added.append((ElementTree.fromstring(f'<link name="{name}"><pose relative_to="carrier">'
                                             f'{" ".join(repr(float(v)) for v in below)} 0 0 0</pose></link>'),
                      ElementTree.fromstring(f'<joint name="weld_{name}" type="fixed"><parent>carrier</parent>'
                                             f'<child>{name}</child></joint>')))
    for link, weld in (added[::-1] if reverse else added):
        model.insert(1, link)
        model.append(weld)
    return plain, '<?xml version="1.0"?>\n' + ElementTree.tostring(root, encoding="unicode")


def output_position(graph) -> np.ndarray:
    """Where a graph mechanism's output frame is at its configuration (Pinocchio's forward kinematics)."""
    import pinocchio as pin

    data = graph.tree.model.createData()
    pin.framesForwardKinematics(graph.tree.model, data, graph.q)
    return data.oMf[graph.frame_id].translation


@pytest.mark.parametrize("reverse, transform", [
    (False, None), (True, None), (True, (1e-3, rotation_from_rpy((0.3, -0.5, 1.1)), np.array([0.4, -0.1, 2.0]))),
    (False, (1e3, rotation_from_rpy((-1.2, 0.2, 0.7)), np.array([-30.0, 5.0, 100.0])))])
def test_a_platform_of_welded_links_is_named_and_placed_after_the_one_they_are_welded_to(tmp_path, reverse,
                                                                                      transform):
    """A published Codian Delta welds a bracket per ball around its platform: the platform was named after the
    bracket the tree reached first ('A12'), and its pose was that bracket's origin. It is the body the others are
    welded to, whatever order the file lists the brackets in: its name, its origin as the file's text places it, and
    the indices of the same Delta without brackets."""
    plain, bracketed = bracketed_delta(tmp_path, reverse, transform)
    reference = graph_mechanism(read_closed_tree(tmp_path / "plain.sdf"))
    found = graph_mechanism(read_closed_tree(write(tmp_path, bracketed, "bracketed.sdf")))
    assert found.platform_body == reference.platform_body == "carrier"
    assert "platform inferred: body 'carrier'" in " ".join(found.report.notes)
    carrier = world_poses(read_model(tmp_path / "plain.sdf"))["carrier"][:3, 3]
    np.testing.assert_allclose(output_position(found), carrier, atol=1e-12)
    np.testing.assert_allclose(output_position(reference), carrier, atol=1e-12)
    same_indices(found.indices(), reference.indices())


@pytest.mark.parametrize("reverse", [False, True])
def test_links_welded_in_a_row_below_the_platform_leave_it_the_platform(tmp_path, reverse):
    """A flange and its plate welded in a row below the carrier (the carrier holding one weld, the flange two): no
    hub, the carrier stays the platform, as the file nests them (a rule counting welds alone took the flange, its
    origin 3 cm lower the output)."""
    from sdformat_models import delta_sdf

    plain = delta_sdf().replace("platform", "carrier")
    links = ['<link name="adapter"><pose relative_to="carrier">0 0 -0.03 0 0 0</pose></link>',
             '<link name="plate"><pose relative_to="carrier">0 0 -0.08 0 0 0</pose></link>']
    joints = ['<joint name="weld_adapter" type="fixed"><parent>carrier</parent><child>adapter</child></joint>',
              '<joint name="weld_plate" type="fixed"><parent>adapter</parent><child>plate</child></joint>']
    order = (lambda items: items[::-1]) if reverse else (lambda items: items)
    path = write(tmp_path, plain.replace("</model>", "".join(order(links) + order(joints)) + "</model>"), "row.sdf")
    found = graph_mechanism(read_closed_tree(path))
    assert found.platform_body == "carrier"
    carrier = world_poses(read_model(write(tmp_path, plain, "plain.sdf")))["carrier"][:3, 3]
    np.testing.assert_allclose(output_position(found), carrier, atol=1e-12)


def test_the_commands_name_and_place_a_welded_platform_after_its_hub(tmp_path):
    """The same, as users run it: ``info`` names the carrier, ``analyze`` gives its origin as the pose."""
    _, bracketed = bracketed_delta(tmp_path)
    path = write(tmp_path, bracketed, "bracketed.sdf")
    described = screwkit("info", path)
    assert described.returncode == 0, described.stderr
    assert "platform 'carrier'" in described.stdout
    analysed = screwkit("analyze", path, "--json")
    assert analysed.returncode == 0, analysed.stderr
    pose = json.loads(analysed.stdout)["pose"]
    carrier = world_poses(read_model(tmp_path / "plain.sdf"))["carrier"][:3, 3]
    np.testing.assert_allclose([pose[axis] for axis in "xyz"], carrier, atol=1e-9)
