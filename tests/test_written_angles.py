"""Right angles written 1.57 (:mod:`screwkit.io.written_angles`): a published knee four-bar opens as written.

Kayra's MJCF knee (``tests/data/gallery/published/kayra``, BSD-3-Clause) writes every right angle as 1.57 rad, so its
crank's hinge is 0.046 deg out of parallel with the coupler's and rocker's, and its rocker's pivot is one
``<connect>`` (a ball). Read exactly, that is no planar mechanism, and the ball pivot was refused. Its author drew a
planar four-bar to two decimals: two axes are now made parallel within what the rounded angles between them (on one
body path and not the other) can turn them apart. Here the allowances are counted by hand from the file; the knee's
indices are checked against MuJoCo's own placement of its joints; the same reading holds in other units and in a
moved world written with rounded angles; and rounded angles that cannot turn two axes apart (another branch, the
floating base's world pose) leave a deliberate tilt refused.
"""

from __future__ import annotations

import json
import math
import xml.etree.ElementTree as ET

import mujoco
import numpy as np
import pytest
from test_gallery_published import PUBLISHED, without_meshes
from test_io import HOME
from test_lower_mobility import five_bar_expected
from test_onshape import five_bar_onshape

from helpers import one_line_error, screwkit
from screwkit.common.rotations import rotation_from_rpy, rpy_from_rotation
from screwkit.common.tolerances import FILE_ROUNDING
from screwkit.io import ImportError_
from screwkit.io.loader import load
from screwkit.io.rounding import parallel_axes, plane_normal
from screwkit.io.star_writing import base_frame
from screwkit.io.written_angles import WIDENING_LIMIT, WrittenTurns, rounded_angle, written_turns
from screwkit.studies import indices_at_pose

KAYRA = PUBLISHED / "kayra" / "kayraCircle.xml"
OPTIONS = dict(lock=("4R_LinkJoint_0",), output="2R_Link")
"""The knee body floats (a free joint): held where the file puts it; the coupler is the output (its crank as output
is refused, naming --output: ``tests/test_four_bar_output.py``)."""
OFF = math.pi / 2 - 1.57
"""How far 1.57 is from a right angle."""


@pytest.mark.parametrize("text, expected", [
    ("1.57", OFF), ("-1.57", OFF), ("+1.57", OFF), ("0.785", abs(0.785 - math.pi / 4)),
    (".785", abs(0.785 - math.pi / 4)), ("3.14", math.pi - 3.14), ("3.1416", 3.1416 - math.pi),
    ("1.5708", 1.5708 - math.pi / 2), ("6.28", 2 * math.pi - 6.28),
    ("4.71", abs(4.71 - 3 * math.pi / 2)), ("0.52", math.pi / 6 - 0.52), ("1.5707963", math.pi / 2 - 1.5707963),
    ("1.5707963267948966", 0.0),  # pi/2 as Python writes it: exact to the double
    ("0", 0.0), ("0.0", 0.0), ("-0.00", 0.0), ("1", 0.0), ("1.6", 0.0), ("0.5", 0.0), ("0.3", 0.0),  # one decimal
    ("1.56", 0.0), ("1.58", 0.0), ("1.570", 0.0), ("1.5707", 0.0), ("0.70", 0.0), ("1.57e0", 0.0), ("90", 0.0),
    ("pi", 0.0), ("\u0661.\u0665\u0667", 0.0)])  # 1.570 claims three decimals; 1.5707 is cut, not rounded
def test_an_angle_is_a_rounded_multiple_of_15_degrees_only_within_half_its_last_decimal(text, expected):
    assert rounded_angle(text) == pytest.approx(expected, abs=1e-15)


def test_the_knees_allowances_are_the_rounded_angles_between_two_hinges_counted_by_hand():
    """Bodies 4R_Link (its world pose: no rounded angle) > 3BR_Link (``1.57 0 -1.57``: the crank 3BR_Joint) >
    2R_Link (``0 -1.57 1.57``: the coupler 2R_Joint) > 3FU_Link (``-1.57 0 0``: the rocker 3FU_Joint) and, beside
    it, 1R_Link (``0 0 0.0``: the foot 1R_Joint)."""
    turns = written_turns(str(KAYRA))
    assert turns.example == "1.57 for pi/2"
    expected = {("3BR_Joint", "2R_Joint"): 2, ("3BR_Joint", "3FU_Joint"): 3, ("2R_Joint", "3FU_Joint"): 1,
                ("2R_Joint", "1R_Joint"): 0, ("3FU_Joint", "1R_Joint"): 1, ("3BR_Joint", "3BR_Joint"): 0}
    for (first, second), count in expected.items():
        assert turns.allowance(first, second) == pytest.approx(FILE_ROUNDING + count * OFF, rel=1e-12)
        assert turns.allowance(second, first) == turns.allowance(first, second)
    assert turns.allowance("3BR_Joint", None) == turns.allowance("3BR_Joint", "no such joint") == FILE_ROUNDING
    assert WrittenTurns().allowance("3BR_Joint", "3FU_Joint") == FILE_ROUNDING


def test_urdf_paths_mjcf_in_degrees_sdformat_and_unreadable_files(tmp_path):
    """A URDF joint's path is the joints from the root link to it, its own origin included; the two branches of a
    tree share only what is above them; the widening stops at WIDENING_LIMIT."""
    urdf = tmp_path / "r.urdf"
    urdf.write_text('<robot name="r"><link name="a"/><link name="b"/><link name="c"/><link name="d"/><link name="e"/>'
                    '<joint name="ab" type="revolute"><parent link="a"/><child link="b"/>'
                    '<origin rpy="1.57 0 0.785"/></joint>'
                    '<joint name="bc" type="revolute"><parent link="b"/><child link="c"/><origin rpy="0 3.14 0"/>'
                    '</joint><joint name="ad" type="revolute"><parent link="a"/><child link="d"/>'
                    '<origin rpy="1.5708 0 0"/></joint><joint name="de" type="revolute"><parent link="d"/>'
                    '<child link="e"/><origin rpy="0.79 0.52 1.05"/></joint></robot>')
    turns = written_turns(str(urdf))
    ab, bc, ad = OFF + abs(0.785 - math.pi / 4), math.pi - 3.14, 1.5708 - math.pi / 2
    assert turns.allowance("ab", "bc") == pytest.approx(FILE_ROUNDING + bc, rel=1e-12)
    assert turns.allowance("bc", "ad") == pytest.approx(FILE_ROUNDING + ab + bc + ad, rel=1e-12)
    assert turns.allowance("ad", "de") == FILE_ROUNDING + WIDENING_LIMIT  # 0.79, 0.52, 1.05: 0.63 deg, limited
    assert turns.example == "0.79 for pi/4"
    mjcf = tmp_path / "degrees.xml"  # MuJoCo's default unit: degrees, written whole
    mjcf.write_text(KAYRA.read_text().replace('<compiler angle="radian"/>', ""))
    sdf = tmp_path / "m.sdf"  # poses relative to any frame: not read
    sdf.write_text('<sdf version="1.7"><model name="m"><link name="a"><pose>0 0 1 0 0 3.14</pose></link></model></sdf>')
    for path in (mjcf, sdf, tmp_path / "missing.xml"):
        assert written_turns(str(path)) == WrittenTurns()


def test_a_chain_of_pairs_each_within_its_allowance_is_not_one_group_beyond_it():
    """Directions at 0, 0.4 and 0.8 deg with 0.5 deg allowed: the first and last are 0.8 deg apart, so none is made
    parallel (each pair alone would be); at 0.9 deg allowed, all three are, to their mean direction."""
    angles = np.radians([0.0, 0.4, 0.8])
    axes = np.stack([np.zeros(3), np.sin(angles), np.cos(angles)], axis=1)
    turned, turn = parallel_axes(axes, np.sin(np.radians(0.5)))
    assert turn == 0.0
    np.testing.assert_allclose(turned, axes, atol=1e-15, rtol=0)
    turned, turn = parallel_axes(axes, np.sin(np.radians(0.9)))
    np.testing.assert_allclose(turned, np.tile(axes[1], (3, 1)), atol=1e-15)
    assert turn == pytest.approx(np.sin(np.radians(0.4)), rel=1e-12)


def mujoco_pressure_angles(text: str) -> tuple[np.ndarray, float]:
    """MuJoCo's reading of the knee at its file's configuration (the connect closed there): the four-bar's pressure
    angles |sin(AB, BC)| (at the crank) and |sin(BC, DC)| (at the coupler-rocker pin C, the output point), A, B, C
    the crank's, coupler's and rocker's anchors and D the connect's anchor on the knee, in the plane normal to the
    three hinges' mean axis (the direction they are made parallel to); and how much they change when taken about any
    one hinge's own axis instead (what the file's rounding leaves undecided)."""
    model = mujoco.MjModel.from_xml_string(without_meshes(text))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    assert np.linalg.norm(data.efc_pos[:3]) < 1e-12  # closed as written

    def joint(name):
        return mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)

    names = ("3BR_Joint", "2R_Joint", "3FU_Joint")
    a, b, c = (data.xanchor[joint(name)].copy() for name in names)
    knee = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "4R_Link")
    d = data.xpos[knee] + data.xmat[knee].reshape(3, 3) @ model.eq_data[0][:3]
    axes = [data.xaxis[joint(name)].copy() for name in names]

    def angles(axis):
        def sine(u, v):
            u, v = u - (u @ axis) * axis, v - (v @ axis) * axis
            return abs(np.cross(u, v) @ axis) / np.linalg.norm(u) / np.linalg.norm(v)

        return np.array([sine(b - a, c - b), sine(c - b, c - d)])

    mean = np.sum([axis * np.sign(axis @ axes[0]) for axis in axes], axis=0)
    central = angles(mean / np.linalg.norm(mean))
    return central, max(float(np.max(np.abs(angles(axis) - central))) for axis in axes)


def knee_indices(path, **options) -> np.ndarray:
    mechanism = load(path, **OPTIONS, **options)
    result = indices_at_pose(mechanism, mechanism.home_pose)
    return np.array([float(np.ravel(result.iti_actuators)[0]), float(result.lmti)])


def test_the_published_knee_opens_as_written_with_mujocos_pressure_angles(tmp_path):
    """About the hinges' mean axis to 1e-9 (about any one hinge's axis they differ by up to the spread, 1.1e-4: the
    rounding leaves that undecided); the knee its author drew, every 1.57 written pi/2, exactly (its axes parallel)
    and 8e-4 away (its frames are where pi/2 puts them)."""
    published = knee_indices(KAYRA)
    central, spread = mujoco_pressure_angles(KAYRA.read_text())
    assert 1e-5 < spread < 2e-4
    np.testing.assert_allclose(published, central, atol=1e-9, rtol=0)
    exact = tmp_path / "exact.xml"
    exact.write_text(KAYRA.read_text().replace("1.57", repr(math.pi / 2)))
    assert written_turns(str(exact)) == WrittenTurns()
    central, spread = mujoco_pressure_angles(exact.read_text())
    assert spread < 1e-12
    np.testing.assert_allclose(knee_indices(exact), central, atol=1e-9, rtol=0)
    assert 5e-4 < np.max(np.abs(published - central)) < 2e-3


def rewritten(text: str, factor: float = 1.0, knee: tuple[str, str] | None = None, extra: str = "",
              rocker_axis: str | None = None) -> str:
    """The knee's MJCF text (meshes left out) with every position (bodies', joints', the connect's anchor) times
    ``factor``; the knee body at ``knee`` (``pos``, ``euler`` texts) instead of the file's; ``extra`` (bodies)
    added to the world body; the rocker's hinge along ``rocker_axis``."""
    root = ET.fromstring(without_meshes(text))
    for element in root.iter():
        for attribute in ("pos", "anchor"):
            if element.get(attribute) is not None and element.tag in ("body", "joint", "connect"):
                element.set(attribute, " ".join(repr(factor * float(v)) for v in element.get(attribute).split()))
    bodies = {body.get("name"): body for body in root.iter("body")}
    if knee is not None:
        bodies["4R_Link"].set("pos", knee[0])
        bodies["4R_Link"].set("euler", knee[1])
    if rocker_axis is not None:
        bodies["3FU_Link"].find("joint").set("axis", rocker_axis)
    if extra:
        root.find("worldbody").append(ET.fromstring(extra))
    return ET.tostring(root, encoding="unicode")


@pytest.mark.parametrize("factor, unit", [(1e3, "mm"), (1e-3, "km")])
def test_the_published_knee_reads_the_same_in_another_unit_and_a_world_written_with_rounded_angles(tmp_path, factor,
                                                                                                      unit):
    expected = knee_indices(KAYRA)
    scaled = tmp_path / "knee.xml"
    scaled.write_text(rewritten(KAYRA.read_text(), factor))
    np.testing.assert_allclose(knee_indices(scaled, length_unit=unit), expected, atol=1e-9, rtol=0)
    moved = tmp_path / "moved.xml"  # the floating knee turned by angles that round multiples: the same allowances
    moved.write_text(rewritten(KAYRA.read_text(), factor, ("0.3 -0.2 2.1", "1.57 -0.79 3.14")))
    assert written_turns(str(moved)).allowance("3BR_Joint", "3FU_Joint") == \
        written_turns(str(KAYRA)).allowance("3BR_Joint", "3FU_Joint")
    np.testing.assert_allclose(knee_indices(moved, length_unit=unit), expected, atol=1e-9, rtol=0)


TILT = f"{math.cos(math.radians(0.3))!r} {math.sin(math.radians(0.3))!r} 0"
"""The rocker's hinge (along x in its body) turned 0.3 deg, written to 17 digits: a tilt its author drew, more than
the rounded angles between the crank and the rocker can make (three 1.57: 0.14 deg)."""


@pytest.mark.parametrize("exact, knee, extra", [
    (True, None, ""), (False, None, ""),
    (True, ("0 0 1.8", "1.57 -0.79 3.14"), ""),  # the floating knee's world pose: it turns every hinge together
    (True, None, '<body name="mount" euler="1.57 1.57 1.57"><joint name="spin" axis="1 0 0"/>'  # another branch
                 '<body name="camera" euler="1.57 1.57 1.57"><geom type="sphere" size="0.01"/></body></body>')],
    ids=["exact", "published", "world pose rounded", "another branch rounded"])
def test_a_tilt_its_author_drew_is_refused_whatever_rounded_angles_lie_elsewhere(tmp_path, exact, knee, extra):
    text = KAYRA.read_text().replace("1.57", repr(math.pi / 2)) if exact else KAYRA.read_text()
    path = tmp_path / "tilted.xml"
    path.write_text(rewritten(text, knee=knee, extra=extra, rocker_axis="1 0 0"))
    knee_indices(path)  # (as written, the rocker's hinge untilted: it opens)
    path.write_text(rewritten(text, knee=knee, extra=extra, rocker_axis=TILT))
    with pytest.raises(ImportError_, match=r"in a planar mechanism only \(revolute axes .* out of parallel, more "
                                           r"than the file's rounding allows them"):
        load(path, **OPTIONS)


def test_the_command_opens_the_published_knee_and_refuses_a_tilt_beyond_its_rounding(tmp_path):
    """As users run it, the file as published, and with a comment of dashes that tinyxml2 reads and Python's parser
    does not (its rounding read all the same); with the coupler's last right angle written 1.56 (0.57 deg off: no
    rounding of pi/2), which turns the coupler's hinge 0.62 deg from the crank's, where one 1.57 between them allows
    0.046 deg, the ball pivot is refused, saying by how much and what the file's rounding allows them."""
    done = screwkit("analyze", KAYRA, "--lock", "4R_LinkJoint_0", "--output", "2R_Link", "--json")
    assert done.returncode == 0, done.stderr
    printed = json.loads(done.stdout)
    np.testing.assert_allclose([printed["iti"], printed["lmti"]], knee_indices(KAYRA), atol=1e-12, rtol=0)
    text = KAYRA.read_text()
    dashes = tmp_path / "dashes.xml"
    dashes.write_text("<!-- ---------- a knee -- -->\n" + text)
    done = screwkit("analyze", dashes, "--lock", "4R_LinkJoint_0", "--output", "2R_Link", "--json")
    assert done.returncode == 0, done.stderr
    np.testing.assert_allclose([json.loads(done.stdout)[k] for k in ("iti", "lmti")], knee_indices(KAYRA),
                               atol=1e-12, rtol=0)
    tilted = tmp_path / "tilted.xml"
    assert text.count('euler= "0 -1.57 1.57"') == 1
    tilted.write_text(text.replace('euler= "0 -1.57 1.57"', 'euler= "0 -1.57 1.56"'))
    message = one_line_error(screwkit("analyze", tilted, "--lock", "4R_LinkJoint_0", "--output", "2R_Link"))
    assert message.endswith("in a planar mechanism only (revolute axes '3BR_Joint' and '2R_Joint' are 0.62 deg out "
                            "of parallel, more than the file's rounding allows them: 0.046 deg, its angles written as "
                            "1.57 for pi/2).")


def turned_world(urdf: str, rpy: str) -> str:
    """An onshape URDF with its whole mechanism turned by ``rpy`` (the text of a fixed-axis roll, pitch, yaw) about the
    world's origin: each joint on the base link placed by that turn composed with its own origin."""
    turn = rotation_from_rpy([float(v) for v in rpy.split()])
    root = ET.fromstring(urdf)
    for joint in root.findall("joint"):
        if joint.find("parent").get("link") == "base":
            origin = joint.find("origin")
            xyz = turn @ np.array([float(v) for v in origin.get("xyz").split()])
            own = rotation_from_rpy([float(v) for v in origin.get("rpy").split()])
            origin.set("xyz", " ".join(repr(float(v)) for v in xyz))
            origin.set("rpy", " ".join(repr(float(v)) for v in rpy_from_rotation(turn @ own)))
    return ET.tostring(root, encoding="unicode")


@pytest.mark.parametrize("scale", [1.0, 10.0, 1e3])
@pytest.mark.parametrize("rpy", ["0 1.5708 0", "0 -1.5708 0", "0 3.14159 0", "0 1.5708 1.0"])
def test_a_five_bar_turned_by_a_rounded_right_angle_opens_at_its_home(tmp_path, rpy, scale):
    """The onshape five-bar turned so that its plane's normal is a few microradians from the world's x axis (a right
    angle written 1.5708 or 3.14159), at 1, 10 and 1000 times its size: its home has the textbook pressure angles.
    (Its closures close in closed form; the published five-bar of ``tests/test_gazebo_plugins.py``, whose closure is
    solved by Newton's method, is the one the plane's frame 2.3e-11 rad from orthonormal left unreachable at its
    home.)"""
    path = tmp_path / "robot.urdf"
    path.write_text(turned_world(five_bar_onshape(transform=(scale, 0.0, (0.0, 0.0, 0.0))), rpy))
    mechanism = load(path)
    assert mechanism.task_coordinates == ("x", "y")
    result = indices_at_pose(mechanism, mechanism.home_pose)
    expected = five_bar_expected(HOME)
    legs = [int(name.split(":")[-1].removeprefix("motor")) - 1 for name in mechanism.actuator_names]
    np.testing.assert_allclose(np.ravel(result.iti_actuators), expected["iti_actuators"][legs], atol=1e-9)
    np.testing.assert_allclose([result.lmti, result.f_o[1]], [expected["lmti"], expected["f_o1"]], atol=1e-9)


@pytest.mark.parametrize("tilt", [0.0, 1e-9, 2.65e-6, 9e-7, 1e-3, 0.3])
def test_the_plane_s_frame_is_orthonormal_whatever_its_normal_s_tilt_from_the_world_s_x(tilt):
    for normal in ([np.cos(tilt), 0.0, np.sin(tilt)], [-np.cos(tilt), np.sin(tilt) / 2, np.sin(tilt)]):
        frame = base_frame(np.array(normal), np.array([0.3, -0.2, 0.1]))[:3, :3]
        np.testing.assert_allclose(frame.T @ frame, np.eye(3), atol=1e-15, rtol=0)
        np.testing.assert_allclose(frame[:, 2], np.array(normal) / np.linalg.norm(normal), atol=1e-15, rtol=0)


def test_the_plane_s_normal_is_the_direction_its_axes_are_written_parallel_to():
    """Axes parallel to 1e-10 (more than to the last digit, less than the file's rounding): the normal is the
    direction they are all made parallel to, not the first one's as written, which left the others 1e-10 rad off
    the plane's normal in the legs written in it."""
    rng = np.random.default_rng(5)
    axes = np.array([0.0, 0.0, 1.0]) + rng.normal(0.0, 1e-10, (4, 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    normal = plane_normal(axes, np.zeros((0, 3)))
    turned, turn = parallel_axes(axes)
    assert 1e-11 < turn < 1e-9
    np.testing.assert_allclose(turned, np.tile(normal, (4, 1)), atol=1e-15, rtol=0)


@pytest.mark.parametrize("axis", range(3))
@pytest.mark.parametrize("sense", [1.0, -1.0])
def test_the_plane_s_frame_turns_with_its_normal_continuously_near_every_world_axis(axis, sense):
    """A normal on a world axis gives that axis's two others (x, y about z; x, -z about y; y, z about x, with the
    sense); tilted from it by 1e-12 to 1e-3 rad in any direction, a frame as far from that one as the tilt (the
    plane's x jumped by 90 deg at 1e-6 rad from the world's x)."""
    normal = sense * np.eye(3)[axis]
    square = base_frame(normal, np.zeros(3))[:3, :3]
    others = [k for k in range(3) if k != axis]
    np.testing.assert_allclose(square[:, 0], np.eye(3)[others[0]], atol=0)
    np.testing.assert_allclose(square[:, 2], normal, atol=0)
    rng = np.random.default_rng(axis)
    for tilt in (1e-12, 1e-9, 9e-7, 1.1e-6, 2.65e-6, 1e-3):
        for _ in range(4):
            tilted = normal + tilt * rng.normal(size=3) / np.sqrt(3)
            frame = base_frame(tilted, np.zeros(3))[:3, :3]
            assert np.max(np.abs(frame - square)) < 4 * tilt


def test_a_plane_on_a_diagonal_keeps_its_frame_whatever_its_rounding():
    """A normal at 45 deg between the world's x and z (or x, y and z alike), written with its last digits rounded
    either way: one frame, its nearest axis chosen x before y before z (the least rotation onto the normal turns
    by 90 deg between a normal nearer x and one nearer z, and rounding decided which)."""
    for normal in (np.array([1.0, 0.0, 1.0]), np.array([1.0, 1.0, 1.0]), np.array([0.0, -1.0, 1.0])):
        normal = normal / np.linalg.norm(normal)
        frames = [base_frame(normal + noise, np.zeros(3))[:3, :3]
                  for noise in np.random.default_rng(3).normal(0.0, 1e-12, (8, 3))]
        for frame in frames:
            np.testing.assert_allclose(frame, frames[0], atol=1e-10, rtol=0)


def test_the_published_knee_reads_the_same_relabelled(tmp_path):
    """Its hinges renamed and the coupler's two child bodies written in the other order: the same indices, and the
    allowances follow the names (two right angles between the crank and the coupler, three to the rocker)."""
    text = rewritten(KAYRA.read_text())
    for old, new in (("3BR_Joint", "crank"), ("2R_Joint", "coupler"), ("3FU_Joint", "rocker"), ("1R_Joint", "toe")):
        text = text.replace(f'"{old}"', f'"{new}"')
    root = ET.fromstring(text)
    coupler = next(body for body in root.iter("body") if body.get("name") == "2R_Link")
    children = [child for child in coupler if child.tag == "body"]
    for child in children:
        coupler.remove(child)
    for child in reversed(children):
        coupler.append(child)
    path = tmp_path / "knee.xml"
    path.write_text(ET.tostring(root, encoding="unicode"))
    np.testing.assert_allclose(knee_indices(path), knee_indices(KAYRA), atol=1e-12, rtol=0)
    turns = written_turns(str(path))
    assert turns.allowance("crank", "coupler") == pytest.approx(FILE_ROUNDING + 2 * OFF, rel=1e-12)
    assert turns.allowance("crank", "rocker") == pytest.approx(FILE_ROUNDING + 3 * OFF, rel=1e-12)
