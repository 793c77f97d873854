"""MJCF orientations, ``<frame>`` elements, equality couplings and keyframes, read as MuJoCo reads them.

Every placement is checked against MuJoCo's own reading of the same file (the ``mujoco`` package: every body and
site at ``qpos0`` and at a random configuration, to 1e-9), every index against a file screwkit already reads
right that describes the same robot (the five-bar of ``tests/test_io.py``, the gallery's Stewart platform).
"""

from __future__ import annotations

import itertools
import re
from pathlib import Path
from xml.etree import ElementTree

import mujoco
import numpy as np
import pinocchio as pin
import pytest
from test_io import HOME, assert_textbook, five_bar_mjcf, poses_near_home
from test_lower_mobility import five_bar_expected

from helpers import assert_indices_close, mujoco_rows, one_line_error, random_reachable_poses, random_rotation, screwkit
from screwkit.io import ImportError_, read_mechanism_file
from screwkit.io.loader import load
from screwkit.io.mjcf import read_mjcf
from screwkit.studies.poses import indices_at_pose, indices_at_poses

STEWART = Path(__file__).resolve().parent / "data" / "gallery" / "stewart_cad.xml"
TOLERANCE = 1e-9
INERTIA = '<inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>'
CHAIN = """<mujoco model="chain">{compiler}
<default><joint axis="0 1 0"/><site pos="0.01 0.02 0.03" {site_default}/>
 <default class="c2"><joint axis="1 0 0" pos="0 0.1 0"/><site pos="0.2 0 0"/></default></default>
<worldbody>
 <body name="b0" pos="0.1 0.2 0.3" {o0}>""" + INERTIA + """
  <joint name="j0" type="hinge" axis="0 0 1"/><site name="s0"/>
  <body name="b1" pos="0.3 0 0" {o1}>""" + INERTIA + """
   <joint name="j1" type="slide" pos="0.05 0 0"/><site name="s1" {o2}/>
   <body name="b2" pos="0 0.2 0.1" childclass="c2" {o3}>""" + INERTIA + """
     <joint name="j2" type="hinge"/><site name="s2" pos="0.1 0.1 0"/><site name="s3"/>
   </body>
  </body>
 </body>
</worldbody>
<actuator><motor joint="j0"/><motor joint="j1"/><motor joint="j2"/></actuator>
</mujoco>"""
"""A serial chain whose bodies and sites are turned by ``o0``... (class defaults and ``childclass`` too)."""


def chain(compiler="", site_default="", **orientations) -> str:
    values = {key: orientations.get(key, "") for key in ("o0", "o1", "o2", "o3")}
    return CHAIN.format(compiler=compiler, site_default=site_default, **values)


def written(tmp_path: Path, text: str, name: str = "robot.xml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def assert_placed_as_mujoco(path: Path, seed: int = 0) -> int:
    """Every body and site of MuJoCo's reading of ``path`` is where screwkit's tree has it, at ``qpos0`` and at a
    random configuration (hinges, slides, ball and free joints); returns how many were compared."""
    mj_model = mujoco.MjModel.from_xml_path(str(path))
    mj_data = mujoco.MjData(mj_model)
    tree = read_mjcf(path)
    model, data = tree.model, tree.model.createData()
    rng = np.random.default_rng(seed)
    compared = 0
    for qpos in (mj_model.qpos0.copy(), mj_model.qpos0 + rng.uniform(-1.0, 1.0, mj_model.nq)):
        q = pin.neutral(model)
        for k in range(mj_model.njnt):
            kind, start = int(mj_model.jnt_type[k]), int(mj_model.jnt_qposadr[k])
            position = model.joints[model.getJointId(mujoco.mj_id2name(mj_model, mujoco.mjtObj.mjOBJ_JOINT, k))].idx_q
            if kind in (int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE)):
                q[position] = qpos[start]
                continue
            linear = 3 if kind == int(mujoco.mjtJoint.mjJNT_FREE) else 0  # a free joint: position, then quaternion
            turn = slice(start + linear, start + linear + 4)
            quaternion = qpos[turn] / np.linalg.norm(qpos[turn])
            qpos[turn] = quaternion
            q[position:position + linear + 4] = [*qpos[start:start + linear], *quaternion[1:], quaternion[0]]
        mj_data.qpos[:] = qpos
        mujoco.mj_kinematics(mj_model, mj_data)
        pin.framesForwardKinematics(model, data, q)
        kinds = ((mujoco.mjtObj.mjOBJ_BODY, range(1, mj_model.nbody), mj_data.xpos, mj_data.xmat, pin.FrameType.BODY),
                 (mujoco.mjtObj.mjOBJ_SITE, range(mj_model.nsite), mj_data.site_xpos, mj_data.site_xmat,
                  pin.FrameType.OP_FRAME))
        for kind, indices, positions, matrices, frame_type in kinds:
            for k in indices:
                name = mujoco.mj_id2name(mj_model, kind, k)
                if not name:
                    continue  # an unnamed body: Pinocchio names it itself
                assert model.existFrame(name, frame_type), f"{path.name}: {name} is missing"
                placement = data.oMf[model.getFrameId(name, frame_type)]
                np.testing.assert_allclose(placement.translation, positions[k], atol=TOLERANCE, rtol=0,
                                           err_msg=f"{path.name}: {name}")
                np.testing.assert_allclose(placement.rotation, matrices[k].reshape(3, 3), atol=TOLERANCE, rtol=0,
                                           err_msg=f"{path.name}: {name}")
                compared += 1
    return compared


# -- 1. <compiler eulerseq>: fixed (uppercase) and moving (lowercase) axes -------------------------------------


def test_every_euler_sequence_turns_bodies_and_sites_as_mujoco_turns_them(tmp_path):
    """All 216 sequences MuJoCo accepts (x, y, z: moving axes; X, Y, Z: fixed axes; mixed), in degrees and
    radians, on bodies, a site and a class default."""
    for index, letters in enumerate(itertools.product("xyzXYZ", repeat=3)):
        sequence, unit = "".join(letters), ("degree", "radian")[index % 2]
        scale = 180 / np.pi if unit == "degree" else 1.0
        angles = [" ".join(repr(scale * v) for v in row) for row in ((0.3, 0.2, 0.25), (-0.7, 0.4, 1.1),
                                                                      (0.5, -0.9, 0.2), (1.3, 0.1, -0.6))]
        text = chain(compiler=f'<compiler angle="{unit}" eulerseq="{sequence}"/>', site_default=f'euler="{angles[3]}"',
                     o0=f'euler="{angles[0]}"', o1=f'euler="{angles[1]}"', o2=f'euler="{angles[2]}"')
        assert assert_placed_as_mujoco(written(tmp_path, text, f"{sequence}_{unit}.xml")) == 2 * (3 + 4)


def test_several_compiler_elements_are_read_as_one_as_mujoco_does(tmp_path):
    text = chain(compiler='<compiler angle="radian"/><compiler eulerseq="ZYX"/>', o0='euler="0.3 0.2 0.25"',
                 o3='euler="-0.5 1 0.2"')
    assert_placed_as_mujoco(written(tmp_path, text))


def test_a_stewart_platform_turned_in_fixed_axes_has_the_indices_of_the_same_turn_as_a_quaternion(tmp_path):
    """The gallery's Stewart platform, one leg's base turned by ``euler`` under ``eulerseq="XYZ"``, and the same
    turn written as the quaternion MuJoCo computes: one robot for MuJoCo, the same indices for screwkit."""
    original = STEWART.read_text()
    text = original.replace('<compiler angle="radian"', '<compiler angle="radian" eulerseq="XYZ"').replace(
        '<body name="X2bottom" pos="0.128557521937 0.153208888624 0"',
        '<body name="X2bottom" pos="0.128557521937 0.153208888624 0" euler="0.3 0.2 0.25"')
    assert text.count('euler="0.3 0.2 0.25"') == 1
    euler = written(tmp_path, text, "euler.xml")
    mj_model = mujoco.MjModel.from_xml_path(str(euler))
    quat = mj_model.body_quat[mujoco.mj_name2id(mj_model, mujoco.mjtObj.mjOBJ_BODY, "X2bottom")]
    quat_text = " ".join(repr(float(v)) for v in quat)
    quaternion = written(tmp_path, text.replace('euler="0.3 0.2 0.25"', f'quat="{quat_text}"'), "quat.xml")
    assert_placed_as_mujoco(euler)
    first, second = load(quaternion), load(euler)
    assert_indices_close(indices_at_pose(first, first.home_pose), indices_at_pose(second, second.home_pose), 1e-9)


def test_an_euler_sequence_mujoco_refuses_is_refused_naming_the_compiler(tmp_path):
    for sequence in ("xyw", "xy", "xyzx"):
        text = chain(compiler=f'<compiler angle="radian" eulerseq="{sequence}"/>', o0='euler="0.3 0.2 0.25"')
        with pytest.raises(ValueError):
            mujoco.MjModel.from_xml_string(text)
        with pytest.raises(ImportError_, match=f"robot.xml: <compiler eulerseq='{sequence}'>: expected three"):
            read_mjcf(written(tmp_path, text))


# -- 4. axisangle, xyaxes, zaxis: axes of any length, normalised as MuJoCo does ------------------------------


@pytest.mark.parametrize("compiler, orientations", [
    ('<compiler angle="radian"/>', {"o1": 'axisangle="1 1 0 0.7"', "o3": 'axisangle="0 0 2 0.4"'}),
    ("", {"o0": 'axisangle="0 3 4 40"', "o2": 'axisangle="-2 0 0 -75"'}),
    ('<compiler angle="radian"/>', {"o0": 'xyaxes="2 0 0.3 0.5 3 0"', "o2": 'zaxis="0 0 -5"',
                                    "o3": 'zaxis="1e-8 0 -2"', "o1": 'zaxis="0.3 -0.2 2"'}),
    ('<compiler angle="radian"/>', {"o0": 'xyaxes="1 0 0.1 0 -1 0"', "o1": 'xyaxes="-1 0 0 0 1 0.2"',
                                    "o2": 'xyaxes="-1 0.1 0 0 -1 0"', "o3": 'zaxis="0 0 -1"'}),
])
def test_an_axis_of_any_length_turns_as_mujoco_turns_it(tmp_path, compiler, orientations):
    assert_placed_as_mujoco(written(tmp_path, chain(compiler=compiler, **orientations)))


def test_a_five_bar_leg_turned_about_a_long_axis_has_the_indices_of_a_unit_one(tmp_path):
    """Pinocchio alone turns by the axis's length times the angle: the leg was elsewhere (or unreadable)."""
    text = five_bar_mjcf()
    base = re.search(r'<body name="proximal_3" pos="([^"]+)"', text).group(1)
    unit = written(tmp_path, text.replace(f'name="proximal_3" pos="{base}"',
                                          f'name="proximal_3" pos="{base}" axisangle="0 0 1 0.4"'), "unit.xml")
    long = written(tmp_path, text.replace(f'name="proximal_3" pos="{base}"',
                                          f'name="proximal_3" pos="{base}" axisangle="0 0 2.5 0.4"'), "long.xml")
    assert_placed_as_mujoco(long)
    points = poses_near_home()
    first, second = (indices_at_poses(load(path), points, detail=True) for path in (unit, long))
    assert_indices_close(first, second, 1e-9)


@pytest.mark.parametrize("orientation, problem", [
    ('axisangle="0 0 0 0.4"', "axisangle's axis is the zero vector"),
    ('axisangle="0 1e-9 0 0.4"', "axisangle's axis is the zero vector"),
    ('zaxis="0 0 0"', "zaxis is the zero vector"),
    ('xyaxes="1 0 0 2 0 0"', "y axis orthogonal to its x axis is the zero vector"),
    ('quat="0 0 0 0"', "the zero quaternion"),
    ('quat="1 0 0 0" euler="0 0 1"', "quat and euler: one orientation only"),
])
def test_an_orientation_mujoco_refuses_is_refused_naming_the_element(tmp_path, orientation, problem):
    text = five_bar_mjcf().replace('<body name="proximal_3"', f'<body name="proximal_3" {orientation}')
    with pytest.raises(ValueError):
        mujoco.MjModel.from_xml_string(text)
    expected = re.escape("robot.xml: <body name='proximal_3'>: ") + f".*{re.escape(problem)}"
    with pytest.raises(ImportError_, match=expected):
        read_mjcf(written(tmp_path, text))


def test_the_command_refuses_a_zero_axisangle_axis_in_one_line(tmp_path):
    text = five_bar_mjcf().replace('<body name="proximal_3"', '<body name="proximal_3" axisangle="0 0 0 0.4"')
    one_line_error(screwkit("analyze", written(tmp_path, text)), "robot.xml", "<body name='proximal_3'>",
                   "axisangle", "zero vector")


# -- 3. <frame>: children lifted to the frame's parent, the frame's pose composed --------------------------------


FRAMES = """<mujoco model="frames"><compiler angle="degree" eulerseq="zYx"/>
<default><joint axis="0 1 0"/>
 <default class="c"><joint axis="1 0 0" pos="0 0 0.2"/><site pos="0.3 0 0" euler="0 0 45"/></default></default>
<worldbody>
 <frame name="outer" pos="0.1 0 0.2" euler="10 20 30">
 <body name="b0" pos="0.1 0.2 0.3" xyaxes="0 1 0 -1 0 0">""" + INERTIA + """
  <frame pos="0.05 0 0" axisangle="1 1 0 30" childclass="c">
   <site name="s_class"/><site name="s_own" pos="0 0.1 0" quat="0 1 0 0"/>
   <frame pos="0 0 0.1" zaxis="1 0 0"><site name="s_nested" pos="0.1 0 0"/>
    <body name="b1" pos="0.3 0 0">""" + INERTIA + """<joint name="j1" type="hinge"/><site name="s1"/></body>
   </frame>
   <joint name="j0b" type="hinge"/>
  </frame>
  <body name="b2" pos="0 0.2 0.1">""" + INERTIA + """
   <frame euler="0 90 0" pos="0.1 0 0"><joint name="j2" type="hinge" pos="0 0.1 0"/></frame>
   <site name="s2" pos="0.1 0.1 0"/>
  </body>
 </body>
 </frame>
</worldbody>
<actuator><motor joint="j0b"/><motor joint="j1"/><motor joint="j2"/></actuator>
</mujoco>"""
"""Frames in the world, in a body, nested, with a childclass (a site's and a joint's defaults), holding bodies,
sites and joints (one a body, as Pinocchio reads them), turned every way MJCF turns them."""


def test_frames_place_bodies_sites_and_joints_as_mujoco_does(tmp_path):
    path = written(tmp_path, FRAMES)
    assert assert_placed_as_mujoco(path, seed=1) == 2 * (3 + 5)
    assert_placed_as_mujoco(path, seed=2)
    site = re.search(r'<site name="effector" [^>]+/>', five_bar_mjcf()).group(0)
    _, report = read_mechanism_file(written(tmp_path, five_bar_mjcf().replace(site, f"<frame>{site}</frame>"),
                                            "five_bar_frame.xml"))
    assert any("1 <frame> element(s)" in note for note in report.notes), report.notes


OFFSET_SITES = """<mujoco model="offset_sites"><worldbody><site name="ground" pos="0.1 0.2 0.3" quat="0.9 0.1 0.3 0.2"/>
 <body name="arm" pos="0.3 0 0" quat="0.9 0.1 0.3 0.2">""" + INERTIA + """
  <joint name="hinge" type="hinge" axis="0.6 0.8 0" pos="0.06 0.08 0.01"/><site name="on_arm" pos="0.1 0 0"/>
  <body name="hand" pos="0.05 0 0" quat="0.7071068 0 0 0.7071068">""" + INERTIA + """
   <site name="tool" pos="0.1 0.2 0.3" quat="0.9238795 0 0.3826834 0"/>
   <body name="finger" pos="0 0.1 0">""" + INERTIA + """<site name="tip" pos="0.02 0 0"/></body>
   <body pos="0 -0.1 0" euler="0.1 0.2 0.3">""" + INERTIA + """<site name="in_unnamed" pos="0.1 0.2 0.3"/></body>
   <site name="segment" type="capsule" size="0.01" fromto="0 0 0 0.1 0.2 0.3"/>
   <site name="down" type="capsule" size="0.01" fromto="0 0 0.3 0 0 0"/>
  </body>
 </body></worldbody><actuator><motor joint="hinge"/></actuator></mujoco>"""
"""A hinge drawn away from its body's origin, and sites of bodies without a joint of their own under it (one of them
unnamed, two given by ``fromto``), and a site of the world itself."""


def hinges_drawn_elsewhere(text: str, rng, span: float) -> str:
    """The MJCF with every hinge's ``pos`` moved along its own axis (each by its own amount, up to ``span``): the
    same mechanism, as MuJoCo reads it (a hinge is a line; its body and the body's children do not move)."""
    root = ElementTree.fromstring(text)
    for joint in root.iter("joint"):
        if joint.get("type", "hinge") == "hinge" and joint.get("axis"):
            axis = np.array([float(word) for word in joint.get("axis").split()])
            pos = np.array([float(word) for word in joint.get("pos", "0 0 0").split()])
            joint.set("pos", " ".join(repr(float(value)) for value in pos + rng.uniform(-span, span) * axis
                                      / np.linalg.norm(axis)))
    return ElementTree.tostring(root, encoding="unicode")


def test_sites_under_a_hinge_drawn_off_its_bodys_origin_are_placed_as_mujoco_places_them(tmp_path):
    """Pinocchio's parser leaves the hinge's ``pos`` out of the sites of jointless bodies under it (named or not),
    reads no ``fromto`` and makes no frame of a site of the world; screwkit places every named site on its body's
    frame, where MuJoCo has it, at ``qpos0`` and at a random configuration."""
    assert assert_placed_as_mujoco(written(tmp_path, OFFSET_SITES)) == 2 * (3 + 7)


def test_a_site_whose_fromto_has_no_length_is_refused_naming_it_as_mujoco_refuses_it(tmp_path):
    """A site's ``fromto`` gives its orientation only through its segment: one of no length is refused, by MuJoCo
    and in one line by the command, naming the site."""
    text = OFFSET_SITES.replace('fromto="0 0 0 0.1 0.2 0.3"', 'fromto="0.1 0.2 0.3 0.1 0.2 0.3"')
    with pytest.raises(ValueError):
        mujoco.MjModel.from_xml_string(text)
    path = written(tmp_path, text)
    with pytest.raises(ImportError_, match=re.escape("robot.xml: <site name='segment'>: the fromto segment is the "
                                                     "zero vector")):
        read_mjcf(path)
    one_line_error(screwkit("analyze", path), "robot.xml", "<site name='segment'>", "fromto", "zero vector")


def test_a_stewart_platform_whose_hinges_are_drawn_elsewhere_on_their_axes_is_the_same_robot(tmp_path):
    """The CAD Stewart platform with every hinge's ``pos`` moved along its axis (up to 5 cm): its output site
    ``tool`` sits under the last hinge of a leg. Bodies and sites where MuJoCo has them, the same home pose, and the
    indices of the file as written at random poses (before, the output site followed the last hinge's drawn point,
    1.9 cm away here, so every pose named another placement of the platform)."""
    moved = written(tmp_path, hinges_drawn_elsewhere(STEWART.read_text(), np.random.default_rng(1), 0.05),
                    "stewart_moved.xml")
    assert assert_placed_as_mujoco(moved) == assert_placed_as_mujoco(STEWART)
    assert_the_stewart_platform(moved, seed=2, count=20)


def assert_the_stewart_platform(path: Path, seed: int, count: int) -> None:
    """``path`` is the gallery's CAD Stewart platform written otherwise: the same home pose and the same indices at
    ``count`` random reachable poses."""
    mechanism, other = load(STEWART), load(path)
    np.testing.assert_allclose(other.home_pose, mechanism.home_pose, rtol=0, atol=1e-12)
    poses = random_reachable_poses(mechanism, np.random.default_rng(seed), count)
    assert_indices_close(indices_at_poses(mechanism, poses, detail=True), indices_at_poses(other, poses, detail=True),
                         1e-9)


@pytest.mark.parametrize("scale", [1e-3, 1.0, 1e3])
def test_a_five_bar_whose_pins_and_closures_are_drawn_along_the_pins_is_the_planar_five_bar(tmp_path, scale):
    """A leg's distal hinge drawn 0.1 length units along its pin and a closure's anchor lifted 0.05 along it (a CAD
    export places each pin at its own layer), in another unit and world frame: the chains still meet on the pins'
    common line, so the mechanism is the planar five-bar with its output point and the textbook pressure angles
    (before, the closures no longer met at one point, and the platform's idle rotation made the output a frame)."""
    rotation = np.eye(3) if scale == 1.0 else random_rotation(np.random.default_rng(int(scale * 1000) % 97))
    plain = five_bar_mjcf(rotation, scale)
    pin_axis = rotation @ np.array([0.0, 0.0, 1.0])
    lifted = " ".join(repr(float(value)) for value in 0.1 * scale * pin_axis)
    text = plain.replace('<joint name="b_1" type="hinge"', f'<joint name="b_1" type="hinge" pos="{lifted}"')
    anchor = re.search(r'<connect name="loop_2" [^>]*anchor="([^"]+)"', text)
    moved = np.array([float(word) for word in anchor.group(1).split()]) + 0.05 * scale * pin_axis
    text = text.replace(anchor.group(0), anchor.group(0).replace(anchor.group(1), " ".join(map(repr, moved.tolist()))))
    assert text.count(f'pos="{lifted}"') == 1 and text != plain
    mechanism = load(written(tmp_path, text, "lifted.xml"))
    assert mechanism.is_planar and mechanism.task_coordinates == ("x", "y")
    result = indices_at_pose(mechanism, mechanism.home_pose)
    expected = five_bar_expected(HOME)
    np.testing.assert_allclose(result.iti_actuators, expected["iti_actuators"], atol=TOLERANCE)
    np.testing.assert_allclose([result.lmti, result.f_o[1]], [expected["lmti"], expected["f_o1"]], atol=TOLERANCE)
    if scale == 1.0:
        points = poses_near_home()
        assert_textbook(indices_at_poses(mechanism, points, detail=True), points)


def test_a_five_bar_written_with_frames_has_the_indices_of_the_plain_one(tmp_path):
    """The output site and a whole leg inside frames (a shift the frame's children take back): the robot of the
    plain file, its output site found by name."""
    text = five_bar_mjcf()
    site = re.search(r'<site name="effector" pos="([^"]+)"/>', text)
    x, y, z = (float(word) for word in site.group(1).split())
    half = float(np.sqrt(0.5))  # the site turned back by the quarter turn of its frame
    text = text.replace(site.group(0), f'<frame pos="0.01 0 0" euler="0 0 {np.pi / 2!r}"><site name="effector" '
                                       f'pos="{y!r} {-(x - 0.01)!r} {z!r}" quat="{half!r} 0 0 {-half!r}"/></frame>')
    leg = re.search(r'<body name="proximal_3" pos="([^"]+)">', text)
    px, py, pz = (float(word) for word in leg.group(1).split())
    start, end = leg.start(), text.index("</body></body>", leg.start()) + len("</body></body>")
    body = text[start:end].replace(leg.group(0), f'<body name="proximal_3" pos="{px - 0.05} {py} {pz}">')
    text = text[:start] + f'<frame pos="0.05 0 0">{body}</frame>' + text[end:]
    plain, framed = written(tmp_path, five_bar_mjcf(), "plain.xml"), written(tmp_path, text, "framed.xml")
    assert_placed_as_mujoco(framed)
    points = poses_near_home()
    first = indices_at_poses(load(plain, output="effector", output_type="frame"), points, detail=True)
    second = indices_at_poses(load(framed, output="effector", output_type="frame"), points, detail=True)
    assert_indices_close(first, second, 1e-9)


# -- 2. equalities that are not closures: couplings refused, inactive ones left out ----------------------------


COUPLINGS = {
    "joint": ('<joint name="couple" joint1="b_3" joint2="a_3" polycoef="0 1 0 0 0"/>', "",
              "<equality><joint name='couple' joint1='b_3' joint2='a_3'>: a joint coupling"),
    "tendon": ('<tendon tendon1="t"/>', '<tendon><fixed name="t"><joint joint="a_3" coef="1"/>'
               '<joint joint="b_3" coef="1"/></fixed></tendon>', "<equality><tendon tendon1='t'>: a tendon coupling"),
}


@pytest.mark.parametrize("kind", sorted(COUPLINGS))
def test_an_active_coupling_is_refused_naming_the_element(tmp_path, kind):
    """MuJoCo reads a coupling (it changes the mechanism's mobility); screwkit does not model one: refused, not
    left out without a word (a joint coupling once the joints analysed are known: here both are)."""
    element, tendons, message = COUPLINGS[kind]
    text = five_bar_mjcf().replace("</equality>", element + "</equality>" + tendons)
    assert mujoco.MjModel.from_xml_string(text).neq == 3
    with pytest.raises(ImportError_, match=re.escape(f"robot.xml: {message}") + ".*screwkit does not model it"):
        read_mechanism_file(written(tmp_path, text))


def test_the_command_refuses_a_joint_coupling_in_one_line(tmp_path):
    text = five_bar_mjcf().replace("</equality>", COUPLINGS["joint"][0] + "</equality>")
    one_line_error(screwkit("analyze", written(tmp_path, text)), "robot.xml", "<equality><joint name='couple'",
                   "does not model it")


DEFORMABLE = {  # a deformable body beside the five-bar (MuJoCo makes bodies of the first; the second joins two)
    "flexcomp": ('<body name="frame" pos="0 0 0.5"><flexcomp name="strip" type="grid" count="3 1 1" '
                 'spacing="0.02 0.02 0.02" dim="1" radius="0.002"/></body>', ""),
    "flex": ('<body name="a" pos="0 0 0.5"><freejoint/><geom size="0.01"/></body><body name="b" pos="0.1 0 0.5">'
             '<freejoint/><geom size="0.01"/></body>', '<deformable><flex name="strip" dim="1" body="a b" '
             'vertex="0 0 0 0 0 0" element="0 1" radius="0.002"/></deformable>'),
}


@pytest.mark.parametrize("tag", sorted(DEFORMABLE))
def test_a_deformable_body_is_refused_naming_its_element(tmp_path, tag):
    """MuJoCo reads it (and makes bodies of a ``<flexcomp>``); Pinocchio does not, and its refusal named a body the
    file does not write (``rod_0_0_0`` for MuJoCo's own ``model/flex/mechanisms/slidercrank.xml``, whose
    ``<flexcomp name='rod'>`` it is made from, and to which its connects attach): the element is named."""
    bodies, section = DEFORMABLE[tag]
    text = five_bar_mjcf().replace("</worldbody>", bodies + "</worldbody>" + section)
    assert mujoco.MjModel.from_xml_string(text).nflex == 1
    one_line_error(screwkit("info", written(tmp_path, text)), "robot.xml", f"<{tag} name='strip'> is a deformable "
                   "body, which screwkit does not model")


def test_a_distance_equality_mujoco_refuses_is_refused_naming_it(tmp_path):
    text = five_bar_mjcf().replace("</equality>", '<distance geom1="g1" geom2="g2" distance="0.1"/></equality>')
    with pytest.raises(ValueError):
        mujoco.MjModel.from_xml_string(text)
    with pytest.raises(ImportError_, match=re.escape("robot.xml: <equality><distance>: not an equality MuJoCo reads")):
        read_mjcf(written(tmp_path, text))


@pytest.mark.parametrize("kind", sorted(COUPLINGS))
def test_an_inactive_coupling_is_left_out_and_said_with_the_indices_of_the_file_without_it(tmp_path, kind):
    element, tendons, _ = COUPLINGS[kind]
    text = five_bar_mjcf().replace("</equality>", element.replace("/>", ' active="false"/>') + "</equality>" + tendons)
    mj_model = mujoco.MjModel.from_xml_string(text)
    assert list(mj_model.eq_active0) == [True, True, False]
    path = written(tmp_path, text)
    _, report = read_mechanism_file(path)
    assert any("inactive equality coupling(s) left out" in note and f"<{kind}" in note for note in report.notes)
    points = poses_near_home()
    first = indices_at_poses(load(written(tmp_path, five_bar_mjcf(), "plain.xml")), points, detail=True)
    assert_indices_close(first, indices_at_poses(load(path), points, detail=True))


def test_a_closure_made_inactive_by_its_class_is_left_out_as_mujoco_leaves_it_out(tmp_path):
    text = five_bar_mjcf().replace("<worldbody>", '<default><default class="off"><equality active="false"/>'
                                                  '</default></default><worldbody>')
    text = text.replace('<connect name="loop_3"', '<connect name="loop_3" class="off"')
    mj_model = mujoco.MjModel.from_xml_string(text)
    active = [mujoco.mj_id2name(mj_model, mujoco.mjtObj.mjOBJ_EQUALITY, k) for k in range(mj_model.neq)
              if mj_model.eq_active0[k]]
    assert active == ["loop_2"]
    assert [closure.name for closure in read_mjcf(written(tmp_path, text)).closures] == active


# -- 5. keyframes --------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("value", ["nan", "a", "inf"])
def test_a_keyframe_value_that_is_not_a_finite_number_is_refused_naming_the_key(tmp_path, value):
    text = five_bar_mjcf().replace("</mujoco>", f'<keyframe><key name="home" qpos="0 0 0 0 {value} 0"/></keyframe>'
                                                "</mujoco>")
    if value == "a":
        with pytest.raises(ValueError, match="bad format"):
            mujoco.MjModel.from_xml_string(text)
    with pytest.raises(ImportError_, match=re.escape(f"robot.xml: <keyframe><key name='home'> qpos='0 0 0 0 {value} "
                                                     f"0': '{value}' is not a finite number")):
        read_mjcf(written(tmp_path, text))


def test_a_keyframe_of_the_wrong_size_says_so_naming_the_key(tmp_path):
    text = five_bar_mjcf().replace("</mujoco>", '<keyframe><key name="home" qpos="0 0"/></keyframe></mujoco>')
    with pytest.raises(ImportError_, match=re.escape("one number per joint coordinate expected") + ".*'home' 2"):
        read_mjcf(written(tmp_path, text))


def _schema_attributes(tag: str) -> set[str]:
    """The attributes MuJoCo's own XML schema (``mujoco.mj_printSchema``) allows on ``<equality><tag>``: the words
    after ``tag (*)`` on its line and on the continuation lines below it (indented to the attributes' column)."""
    lines = mujoco.mj_printSchema(False, False).splitlines()
    equality = next(k for k, line in enumerate(lines) if line.split()[:1] == ["equality"])
    first = next(k for k in range(equality + 1, len(lines)) if lines[k].split()[:1] == [tag])
    column = len(lines[first]) - len(lines[first].lstrip()) + len(tag) + 4  # "tag (*)" ends before the attributes
    words = lines[first].split()[2:]
    for line in lines[first + 1:]:
        if len(line) - len(line.lstrip()) < column:
            break
        words += line.split()
    return set(words)


@pytest.mark.parametrize("tag", ["connect", "weld"])
def test_the_closure_attributes_screwkit_reads_are_those_of_mujoco_s_schema(tag):
    from screwkit.io.mjcf_text import CLOSURE_ATTRIBUTES

    assert CLOSURE_ATTRIBUTES[tag] == _schema_attributes(tag)


def test_an_attribute_mujoco_refuses_on_a_closure_is_refused_rather_than_ignored(tmp_path):
    """A relpose on a <connect> (only a <weld> has one): MuJoCo refuses the file; screwkit read it, ignoring the
    pose the author may have meant."""
    text = five_bar_mjcf()
    assert text.count("<connect") >= 1
    text = text.replace("<connect", '<connect relpose="0 0 0 1 0 0 0"', 1)
    with pytest.raises(ValueError, match="unrecognized attribute: 'relpose'"):
        mujoco.MjModel.from_xml_string(text)
    path = tmp_path / "five_bar.xml"
    path.write_text(text)
    with pytest.raises(ImportError_, match=r"five_bar\.xml: <equality><connect[^>]*>: relpose='0 0 0 1 0 0 0': not an "
                                           r"attribute of <connect> \(it has active, anchor, body1, body2, class, "
                                           r"name, site1, site2, solimp, solref\): MuJoCo refuses the file\."):
        read_mechanism_file(path)


SINGULAR_FIVE_BAR = """<mujoco model="five_bar"><worldbody>
 <body name="left_1" pos="-0.2 0 0"><joint name="left_motor" type="hinge" axis="0 0 1"/>""" + INERTIA + """
  <body name="left_2" pos="0.3 0 0"><joint name="left_elbow" type="hinge" axis="0 0 1"/>""" + INERTIA + """</body>
 </body>
 <body name="right_1" pos="0.2 0 0"><joint name="right_motor" type="hinge" axis="0 0 1"/>""" + INERTIA + """
  <body name="right_2" pos="-0.3 0 0"><joint name="right_elbow" type="hinge" axis="0 0 1"/>""" + INERTIA + """</body>
 </body>
 <body name="effector" pos="0 0 0"><freejoint/>""" + INERTIA + """</body>
</worldbody>
<equality><connect body1="left_2" body2="effector" anchor="0.3 0 0"/>
 <connect body1="right_2" body2="effector" anchor="-0.3 0 0"/></equality>
<actuator><motor joint="left_motor"/><motor joint="right_motor"/></actuator></mujoco>
"""


def test_a_five_bar_written_with_every_link_on_one_line_is_refused_as_a_singular_configuration(tmp_path):
    """As a published MuJoCo five-bar writes it: every link along x at qpos0, so the loops close with the links on
    one line. Locking a motor there takes no motion away, but it does at closed configurations nearby: the message
    says the file is written at a singularity, not that motors are missing (and suggests no --lock)."""
    path = tmp_path / "five_bar.xml"
    path.write_text(SINGULAR_FIVE_BAR)
    message = one_line_error(screwkit("info", path))
    assert re.search(r"five_bar.xml: locking actuated joint '(left|right)_motor' leaves the platform of leg "
                     r"'(left|right)_1' as free as before at the file's joint values, and takes a motion away at "
                     r"closed configurations near them: the file is written at a singular configuration", message), \
        message
    assert "--lock" not in message


def test_a_tree_with_no_closure_is_refused_as_such_before_any_actuator_is_looked_for(tmp_path):
    """A serial arm with no <equality> and no <actuator> (as Drake's four_bar.sdf is, its loop a force element added
    in code): the refusal says there is no closure, not that there is nothing to actuate (which --actuate answered
    only with the same "no closure" next)."""
    path = tmp_path / "arm.xml"
    path.write_text('<mujoco><worldbody><body name="upper"><joint name="shoulder" type="hinge" axis="0 0 1"/>'
                    '<geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.02"/><body name="lower" pos="0.3 0 0">'
                    '<joint name="elbow" type="hinge" axis="0 0 1"/><geom type="capsule" fromto="0 0 0 0.3 0 0" '
                    'size="0.02"/></body></body></worldbody></mujoco>')
    for options in ((), ("--actuate", "shoulder")):
        line = one_line_error(screwkit("info", path, *options), "arm.xml: no closure: nothing closes the tree")
        assert "actuate" not in line


def two_fingers(coupling: str) -> str:
    """Two four-bar fingers side by side (a gripper; each finger a crank-rocker of Genesis's writing, its crank
    driven), with ``coupling`` written into ``<equality>`` after their closures."""
    from test_singular_on_the_way import crank_rocker

    finger = crank_rocker(1.0, 4.0, 3.0)
    parts = {}
    for side, shift in (("left", "0 0 0"), ("right", "2 0 0")):
        text = finger.replace('name="link_', f'name="{side}_link_').replace('body1="link_', f'body1="{side}_link_')
        text = text.replace('body2="link_', f'body2="{side}_link_').replace('"hinge_', f'"{side}_hinge_')
        text = text.replace('name="kinematic_link1"', f'name="{side}_loop"')
        ground = f'<body name="{side}_link_1" pos="0.0 0.0 0.0"'
        assert ground in text
        text = text.replace(ground, f'<body name="{side}_link_1" pos="{shift}"')
        parts[side] = text
    body = {side: text[text.index("<worldbody>") + 11:text.index("</worldbody>")] for side, text in parts.items()}
    closure = {side: text[text.index("<equality>") + 10:text.index("</equality>")] for side, text in parts.items()}
    return (f'<mujoco><worldbody>{body["left"]}{body["right"]}</worldbody><equality>{closure["left"]}'
            f'{closure["right"]}{coupling}</equality><actuator><motor joint="left_hinge_1"/>'
            '<motor joint="right_hinge_1"/></actuator></mujoco>')


def with_pendulum(coupling: str, pinned: bool) -> str:
    """The crank-rocker with a pendulum hung beside it (a branch that reaches no leg), ``pinned`` to the ground by a
    <connect> (then it cannot move), and ``coupling`` written after the closures."""
    from test_singular_on_the_way import crank_rocker

    text = crank_rocker(1.0, 4.0, 3.0).replace("</worldbody>", '<body name="pendulum" pos="3 0 0"><joint '
                                               'name="swing" axis="1 0 0"/><geom type="capsule" fromto="0 0 0 0 1 0" '
                                               'size="0.05"/></body></worldbody>')
    pin = '<connect name="pin" body1="pendulum" body2="link_1" anchor="0 1 0"/>' if pinned else ""
    return text.replace("</equality>", pin + coupling + "</equality>")


def mujoco_motions(text: str, joints) -> int:
    """MuJoCo's own word: the rank of the motions of ``joints`` its equality constraints allow at qpos0 (the null
    space of its constraint Jacobian, restricted to their velocity coordinates)."""
    model = mujoco.MjModel.from_xml_string(text)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    rows = [i for i in range(data.nefc) if data.efc_type[i] == mujoco.mjtConstraint.mjCNSTR_EQUALITY]
    jacobian = mujoco_rows(model, data)[rows]
    _, values, right = np.linalg.svd(np.vstack([jacobian, np.zeros((model.nv, model.nv))]))
    null = right[int(np.sum(values > 1e-9)):]
    columns = [model.jnt_dofadr[model.joint(name).id] for name in joints]
    return int(np.linalg.matrix_rank(null[:, columns], 1e-9)) if null.size else 0


LEFT = ("left_hinge_1", "left_hinge_2", "left_hinge_3")
COUPLED = {  # (the file, its output body, the joints analysed)
    "to the other finger": (two_fingers('<joint joint1="left_hinge_1" joint2="right_hinge_1"/>'), "left_link_4", LEFT),
    "to a free pendulum": (with_pendulum('<joint joint1="hinge_1" joint2="swing"/>', False), "link_4",
                           ("hinge_1", "hinge_2", "hinge_3")),
    "inside the finger": (two_fingers('<joint joint1="left_hinge_1" joint2="left_hinge_2"/>'), "left_link_4", LEFT),
    "to a value": (two_fingers('<joint joint1="left_hinge_2"/>'), "left_link_4", LEFT),
    "at a zero slope": (two_fingers('<joint joint1="left_hinge_1" joint2="right_hinge_1" polycoef="0 0 1 0 0"/>'),
                        "left_link_4", LEFT),
    "chained back into the finger": (two_fingers('<joint joint1="left_hinge_1" joint2="right_hinge_1"/><joint '
                                                 'joint1="left_hinge_2" joint2="right_hinge_1"/>'), "left_link_4",
                                     LEFT),
    "to a finger held": (two_fingers('<joint joint1="left_hinge_1" joint2="right_hinge_1"/><joint '
                                     'joint1="right_hinge_2"/>'), "left_link_4", LEFT),
    "to a pinned pendulum": (with_pendulum('<joint joint1="hinge_1" joint2="swing"/>', True), "link_4",
                             ("hinge_1", "hinge_2", "hinge_3")),
    "to the loop joint beyond the platform": (two_fingers("").replace(
        "</equality>", '<joint joint1="left_hinge_1" joint2="left_hinge_3"/></equality>'), "left_link_3", LEFT),
}


@pytest.mark.parametrize("case", COUPLED)
def test_a_joint_coupling_is_left_out_only_where_mujoco_keeps_the_motions_analysed(tmp_path, case):
    """A gripper's fingers coupled by ``<equality><joint>`` (as MuJoCo Menagerie's hands are): with one finger
    analysed, a coupling to a branch that follows it constrains nothing there, and the file opens as written,
    saying so, with the indices of the file without it; any other is refused naming the element. Which is which is
    MuJoCo's verdict here: whether its constraint Jacobian, with the coupling, leaves the joints analysed the motions
    they have without it."""
    text, output, joints = COUPLED[case]
    path = tmp_path / "coupled.xml"
    path.write_text(text)
    plain = tmp_path / "plain.xml"
    plain.write_text(re.sub(r"<joint joint1=[^>]*/>", "", text))
    kept = mujoco_motions(text, joints) == mujoco_motions(plain.read_text(), joints)
    assert kept is case.startswith(("to the other finger", "to a free pendulum"))  # (the cases as meant)
    run = screwkit("info", path, "--output", output)
    if not kept:
        one_line_error(run, "coupled.xml: <equality><joint joint1=", "a joint coupling ties joint",
                       "which holds the mechanism analysed to fewer motions", "remove the element (or set "
                       "active='false')")
        return
    assert run.returncode == 0, run.stderr
    assert "which constrains no motion of the mechanism analysed (the branch it ties follows): left out" in run.stdout
    for turn in (0.0, np.radians(20.0)):
        got, want = (indices_at_pose(m, m.home_pose + turn) for m in (load(path, output=output),
                                                                      load(plain, output=output)))
        np.testing.assert_allclose([got.iti, got.lmti], [want.iti, want.lmti], atol=1e-12)


def test_a_coupling_to_a_joint_held_by_lock_is_refused_saying_so(tmp_path):
    path = tmp_path / "gripper.xml"
    path.write_text(COUPLED["to the other finger"][0])
    one_line_error(screwkit("info", path, "--output", "left_link_4", "--lock", "right_hinge_1"),
                   "ties joint 'left_hinge_1' to joint 'right_hinge_1', held (--lock)")


def scaled_and_moved(text: str, factor: float) -> str:
    """An MJCF file's kinematic lengths (``pos``, ``fromto``, ``anchor``; the geoms' radii kept, for MuJoCo's masses)
    times ``factor``, and its bodies hung in a moved and turned frame (written here, apart from screwkit's reading)."""
    def times(match):
        numbers = " ".join(repr(float(word) * factor) for word in match.group(2).split())
        return f'{match.group(1)}="{numbers}"'

    text = re.sub(r'\b(pos|fromto|anchor)="([^"]*)"', times, text)
    start, end = text.index("<worldbody>") + len("<worldbody>"), text.index("</worldbody>")
    return (text[:start] + f'<body name="frame" pos="{0.3 * factor!r} {-0.7 * factor!r} {0.2 * factor!r}" '
            'quat="0.9238795 0.2209424 0.3314136 0.1767767">' + text[start:end] + "</body>" + text[end:])


@pytest.mark.parametrize("factor", [1e-3, 1e3])
@pytest.mark.parametrize("case", ["to the other finger", "at a zero slope", "to the loop joint beyond the platform"])
def test_a_coupling_s_verdict_is_the_same_in_other_units_and_a_moved_world(tmp_path, case, factor):
    """The couplings' check compares ranks on lengths in the mechanism's own scale: the file at 1e-3 and 1e3 of its
    size, hung in a moved and turned frame, gets MuJoCo's verdict on that file and the same one as written."""
    text, output, joints = COUPLED[case]
    moved = scaled_and_moved(text, factor)
    plain = re.sub(r"<joint joint1=[^>]*/>", "", moved)
    kept = mujoco_motions(moved, joints) == mujoco_motions(plain, joints)
    assert kept is (case == "to the other finger")
    path = tmp_path / "coupled.xml"
    path.write_text(moved)
    if kept:
        _, report = read_mechanism_file(path, output=output)
        assert any("constrains no motion of the mechanism analysed" in note for note in report.notes)
    else:
        with pytest.raises(ImportError_, match="which holds the mechanism analysed to fewer motions"):
            read_mechanism_file(path, output=output)


def geared_stage(coupled: bool = True) -> str:
    """The crank-rocker on a turntable (``stage_turn``, about z) that a gear beside it turns (``gear_spin``, coupled
    by ``<equality><joint>`` at a ratio of 2), as a humanoid's hip yaw is geared to its motor."""
    from test_singular_on_the_way import crank_rocker

    text = crank_rocker(1.0, 4.0, 3.0).replace('<geom type="capsule" fromto="0 0 0 0 0 4.0" size="0.05"/>\n      <body '
                                               'name="link_2"', '<joint name="stage_turn" axis="0 0 1"/><geom '
                                               'type="capsule" fromto="0 0 0 0 0 4.0" size="0.05"/>\n      <body '
                                               'name="link_2"', 1)
    assert 'name="stage_turn"' in text
    text = text.replace("</worldbody>", '<body name="gear" pos="2 0 0"><joint name="gear_spin" axis="0 0 1"/><geom '
                                        'type="cylinder" size="0.3 0.05"/></body></worldbody>')
    coupling = '<joint joint1="stage_turn" joint2="gear_spin" polycoef="0 2 0 0 0"/>' if coupled else ""
    return text.replace("</equality>", coupling + "</equality>")


def test_a_coupling_to_a_stage_held_holds_only_its_gear_and_is_left_out(tmp_path):
    """Held by --lock, the stage leaves the coupling nothing to hold but the gear, on which nothing hangs: it is
    left out, saying so, with the indices of the file without it (MuJoCo's word: the stage held by an equality, the
    coupling leaves the four-bar's joints their motions). Free, the stage is named to hold (--lock), not the
    coupling to remove (ToddlerBot's hip-yaw gear pair was blamed for a waist left free)."""
    path, plain = tmp_path / "geared.xml", tmp_path / "plain.xml"
    path.write_text(geared_stage())
    plain.write_text(geared_stage(coupled=False))
    held = '<joint joint1="stage_turn"/></equality>'
    assert mujoco_motions(geared_stage().replace("</equality>", held), ("hinge_1", "hinge_2", "hinge_3")) == \
        mujoco_motions(geared_stage(False).replace("</equality>", held), ("hinge_1", "hinge_2", "hinge_3"))
    run = screwkit("info", path, "--output", "link_4", "--lock", "stage_turn")
    assert run.returncode == 0, run.stderr
    assert "its other joint held (--lock or the file), it holds only a body nothing else hangs on" in run.stdout
    got = load(path, output="link_4", lock=("stage_turn",))
    want = load(plain, output="link_4", lock=("stage_turn",))
    for turn in (0.0, np.radians(20.0)):
        a, b = (indices_at_pose(m, m.home_pose + turn) for m in (got, want))
        np.testing.assert_allclose([a.iti, a.lmti], [b.iti, b.lmti], atol=1e-12)
    free = one_line_error(screwkit("info", path, "--output", "link_4"), "--lock stage_turn")
    assert "remove the element" not in free or "--lock stage_turn holds" in free, free


def bent_crank_rocker() -> str:
    """The crank-rocker whose coupler bends at a hinge ``spring`` halfway along it (an adaptive finger: two DoF, one
    motor)."""
    from test_singular_on_the_way import crank_rocker

    plain = crank_rocker(1.0, 4.0, 3.0)
    link_4 = '<body name="link_4" pos="0.5 0.0 4.0">'
    assert link_4 in plain
    bent = plain.replace(link_4, '<body name="link_3b" pos="0 0 2.0"><joint name="spring" axis="1 0 0"/><geom '
                                 'type="sphere" size="0.1"/><body name="link_4" pos="0.5 0.0 2.0">')
    return bent.replace("</body>\n        </body>", "</body></body>\n        </body>", 1)


def test_a_leg_that_moves_with_its_ends_held_is_refused_not_locked(tmp_path):
    """The bent coupler's four hinges in one plane are dependent at every configuration, as an idle joint's are, and
    the spring was locked as one: the finger read as the rigid crank-rocker, without a word. MuJoCo's constraint
    Jacobian leaves it a motion with the motor held; it is refused naming --lock, and held there it is the
    crank-rocker, its indices the plain file's. An idle spin (two coaxial pins, an S-S rod) is still locked."""
    from test_singular_on_the_way import crank_rocker

    path, reference = tmp_path / "finger.xml", tmp_path / "plain.xml"
    path.write_text(bent_crank_rocker())
    reference.write_text(crank_rocker(1.0, 4.0, 3.0))
    held = bent_crank_rocker().replace("</equality>", '<joint joint1="hinge_1"/></equality>')
    assert mujoco_motions(held, ("hinge_2", "spring", "hinge_3")) == 1
    line = one_line_error(screwkit("info", path, "--output", "link_4"), "moves with its ends held",
                          "turns joints hinge_2, spring, hinge_3 about points it moves", "--lock JOINT")
    assert "\n" not in line
    got, want = load(path, output="link_4", lock=("spring",)), load(reference, output="link_4")
    a, b = (indices_at_pose(m, m.home_pose) for m in (got, want))
    np.testing.assert_allclose([a.iti, a.lmti], [b.iti, b.lmti], atol=1e-12)


def test_an_underactuated_five_bar_s_refusal_names_its_passive_joints_to_hold(tmp_path):
    """The teaching five-bar with its right motor left out: one actuator for two DoF, refused naming --lock and the
    chains' passive joints (a gripper's spring-loaded finger, held at its spring joint, opens so)."""
    source = Path(__file__).parent / "data" / "gallery" / "published" / "lab_robots_iitk" / "5bar.xml"
    text = re.sub(r'\s*<position name="motor_pos_right"[^>]*/>', "", source.read_text())
    path = tmp_path / "5bar.xml"
    path.write_text(text)
    line = one_line_error(screwkit("info", path, "--output", "pen"), "1 actuator(s)", "for an output with 2 DOF",
                          "--lock JOINT", "passive joints:")
    passive = line.split("passive joints:")[1]
    assert "j1_right" in passive and "j1_left" not in passive, line


@pytest.mark.parametrize("left", ['jointinparent="j1_left"', 'joint="j2_left" jointinparent="j1_left"'])
def test_an_actuator_written_jointinparent_drives_the_joint_mujoco_drives(tmp_path, left):
    """``jointinparent`` (the gear of a ball or free joint in its parent's frame; a hinge's the same) drives the
    joint MuJoCo drives, also beside a ``joint`` it overrides: the motors MuJoCo's model names and the indices of the
    file written ``joint``. Before, such an actuator was read as driving no joint and the file refused."""
    source = Path(__file__).parent / "data" / "gallery" / "published" / "lab_robots_iitk" / "5bar.xml"
    text = source.read_text().replace('name="motor_pos_left" joint="j1_left"', f'name="motor_pos_left" {left}')
    path = tmp_path / "5bar.xml"
    path.write_text(text)
    mj = mujoco.MjModel.from_xml_string(re.sub(r'material="[^"]*"', "", re.sub(r"<asset>.*?</asset>", "", text,
                                                                                 flags=re.S)))
    driven = [mujoco.mj_id2name(mj, mujoco.mjtObj.mjOBJ_JOINT, int(k)) for k in mj.actuator_trnid[:, 0]]
    got, want = load(path, output="pen"), load(source, output="pen")
    assert [name.split(":")[0] for name in got.actuator_names] == driven == ["j1_left", "j1_right"]
    a, b = indices_at_pose(got, got.home_pose), indices_at_pose(want, want.home_pose)
    np.testing.assert_allclose([a.iti, a.lmti, *a.iti_actuators], [b.iti, b.lmti, *b.iti_actuators], atol=1e-12)
