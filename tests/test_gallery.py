"""Files of other tools, checked against that tool's own reading of them.

Each MJCF file is read by MuJoCo itself (the ``mujoco`` package) and by screwkit. At the file's own configuration
(``qpos0``), at random configurations and after screwkit's assembly, the two agree on every body's placement and
on every closure's residual (what MuJoCo's ``<connect>``/``<weld>`` constrain, computed from MuJoCo's own compiled
equality data), to 1e-9 m. The files are the gallery's faithful rewrites of published ones
(``tests/data/gallery``) and the five-bar of ``tests/test_io.py``; the indices of the Stewart platform written as a
CAD exporter writes it are checked against its leg lines.
"""

from __future__ import annotations

import re
import subprocess
import sys
import xml.etree.ElementTree as ElementTree
from pathlib import Path

import mujoco
import numpy as np
import pinocchio as pin
import pytest
from test_io import five_bar_mjcf

from helpers import leg_line_otis, one_line_error, screwkit
from screwkit.io.closed_tree import assemble
from screwkit.io.loader import load
from screwkit.io.mjcf import read_mjcf
from screwkit.studies import indices_at_pose

GALLERY = Path(__file__).resolve().parent / "data" / "gallery"
TOLERANCE = 1e-9

WELD_OFFSET = """<mujoco model="weld_offset">
  <compiler angle="radian"/>
  <worldbody>
    <body name="base">
      <body name="arm"><joint name="a" type="hinge" axis="0 0 1"/>
        <geom type="capsule" fromto="0 0 0 1 0 0" size="0.02"/>
        <body name="tip" pos="1 0 0"><geom type="sphere" size="0.03"/></body>
      </body>
      <body name="slider" pos="0 1 0"><joint name="s" type="slide" axis="1 0 0"/><geom type="box" size=".05 .05 .05"/>
      </body>
    </body>
  </worldbody>
  <equality><weld name="w" body1="slider" body2="tip" relpose="1 -1 0 1 0 0 0"/></equality>
  <actuator><motor joint="a"/></actuator>
</mujoco>
"""
"""The issue's case: a weld whose body2 has no joint of its own, at an offset from its parent's joint."""


def files(tmp_path: Path) -> dict[str, Path]:
    (tmp_path / "five_bar.xml").write_text(five_bar_mjcf())
    (tmp_path / "weld_offset.xml").write_text(WELD_OFFSET)
    return {"five_bar": tmp_path / "five_bar.xml", "weld_offset": tmp_path / "weld_offset.xml",
            **{path.stem: path for path in sorted(GALLERY.glob("*.xml"))}}


def mujoco_state(path: Path, qpos=None):
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    data.qpos[:] = model.qpos0 if qpos is None else qpos
    mujoco.mj_kinematics(model, data)
    return model, data


def mujoco_residuals(model, data) -> dict[str, np.ndarray]:
    """Every equality's residual as MuJoCo defines it, from MuJoCo's compiled equality data: a connect's two anchor
    points (or sites) apart, a weld's body2 apart from body1 times its relative pose (position and rotation)."""
    out, unnamed = {}, 0
    for k in range(model.neq):
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_EQUALITY, k)
        if name is None:  # named in file order as screwkit names them (connect_1, weld_2, ...)
            unnamed += 1
            name = f"{'connect' if int(model.eq_type[k]) == int(mujoco.mjtEq.mjEQ_CONNECT) else 'weld'}_{unnamed}"
        first, second, values = model.eq_obj1id[k], model.eq_obj2id[k], model.eq_data[k]
        sites = int(model.eq_objtype[k]) == int(mujoco.mjtObj.mjOBJ_SITE)
        if int(model.eq_type[k]) == int(mujoco.mjtEq.mjEQ_CONNECT):
            if sites:
                out[name] = data.site_xpos[first] - data.site_xpos[second]
            else:
                one = data.xpos[first] + data.xmat[first].reshape(3, 3) @ values[0:3]
                two = data.xpos[second] + data.xmat[second].reshape(3, 3) @ values[3:6]
                out[name] = one - two
        elif int(model.eq_type[k]) == int(mujoco.mjtEq.mjEQ_WELD):
            assert not sites, "site-based welds: add them here when a fixture has one"
            rotation_1 = data.xmat[first].reshape(3, 3)
            relative = np.zeros(9)
            mujoco.mju_quat2Mat(relative, values[6:10])
            expected_position = data.xpos[first] + rotation_1 @ values[3:6]
            expected_rotation = rotation_1 @ relative.reshape(3, 3)
            out[name] = np.concatenate([data.xpos[second] - expected_position,
                                        (data.xmat[second].reshape(3, 3) - expected_rotation).ravel()])
    return out


def screwkit_residuals(tree, q) -> dict[str, np.ndarray]:
    model, data = tree.model, tree.model.createData()
    pin.forwardKinematics(model, data, q)
    out = {}
    for closure in tree.closures:
        a = data.oMi[closure.joint_a].homogeneous @ closure.placement_a
        b = data.oMi[closure.joint_b].homogeneous @ closure.placement_b
        out[closure.name] = (a[:3, 3] - b[:3, 3]) if closure.kind == "3d" else \
            np.concatenate([b[:3, 3] - a[:3, 3], (b[:3, :3] - a[:3, :3]).ravel()])
    return out


def pinocchio_q(tree, mj_model, qpos) -> np.ndarray:
    """MuJoCo's qpos as Pinocchio's q, joint by joint by name (hinges and slides only in these files)."""
    q = pin.neutral(tree.model)
    for k in range(mj_model.njnt):
        name = mujoco.mj_id2name(mj_model, mujoco.mjtObj.mjOBJ_JOINT, k)
        assert int(mj_model.jnt_type[k]) in (int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE)), name
        q[tree.model.joints[tree.model.getJointId(name)].idx_q] = qpos[mj_model.jnt_qposadr[k]]
    return q


def mujoco_qpos(tree, mj_model, q) -> np.ndarray:
    qpos = mj_model.qpos0.copy()
    for k in range(mj_model.njnt):
        name = mujoco.mj_id2name(mj_model, mujoco.mjtObj.mjOBJ_JOINT, k)
        qpos[mj_model.jnt_qposadr[k]] = q[tree.model.joints[tree.model.getJointId(name)].idx_q]
    return qpos


def assert_same_bodies(tree, mj_model, mj_data, q):
    model, data = tree.model, tree.model.createData()
    pin.framesForwardKinematics(model, data, q)
    checked = 0
    for k in range(1, mj_model.nbody):
        name = mujoco.mj_id2name(mj_model, mujoco.mjtObj.mjOBJ_BODY, k)
        if name is None or not model.existFrame(name, pin.FrameType.BODY):
            continue
        placement = data.oMf[model.getFrameId(name, pin.FrameType.BODY)]
        np.testing.assert_allclose(placement.translation, mj_data.xpos[k], atol=TOLERANCE, rtol=0, err_msg=name)
        np.testing.assert_allclose(placement.rotation, mj_data.xmat[k].reshape(3, 3), atol=TOLERANCE, rtol=0,
                                   err_msg=name)
        checked += 1
    assert checked == mj_model.nbody - 1 - (1 if name == "screwkit_world" else 0) or checked > 3


@pytest.mark.parametrize("name", ["five_bar", "weld_offset", "stewart_cad"])
def test_bodies_and_closures_are_those_mujoco_computes(name, tmp_path):
    path = files(tmp_path)[name]
    tree = read_mjcf(path)
    mj_model, mj_data = mujoco_state(path)
    rng = np.random.default_rng(len(name))
    configurations = [mj_model.qpos0.copy()]
    for _ in range(3):
        qpos = mj_model.qpos0.copy()
        for k in range(mj_model.njnt):
            hinge = int(mj_model.jnt_type[k]) == int(mujoco.mjtJoint.mjJNT_HINGE)
            qpos[mj_model.jnt_qposadr[k]] += rng.uniform(-0.2, 0.2) * (1.0 if hinge else 0.1)
        configurations.append(qpos)
    for qpos in configurations:
        mj_model, mj_data = mujoco_state(path, qpos)
        q = pinocchio_q(tree, mj_model, qpos)
        assert_same_bodies(tree, mj_model, mj_data, q)
        theirs, ours = mujoco_residuals(mj_model, mj_data), screwkit_residuals(tree, q)
        assert theirs.keys() == ours.keys()
        for closure in theirs:
            np.testing.assert_allclose(ours[closure], theirs[closure], atol=TOLERANCE, rtol=0, err_msg=closure)
    assembled, _ = assemble(tree)  # screwkit's assembly closes every closure as MuJoCo measures it
    mj_model, mj_data = mujoco_state(path, mujoco_qpos(tree, mj_model, assembled))
    assert max(np.max(np.abs(r)) for r in mujoco_residuals(mj_model, mj_data).values()) < TOLERANCE


def test_the_issue_weld_whose_body_has_no_joint_closes_where_mujoco_closes_it(tmp_path):
    """MuJoCo's residual is zero at qpos0; screwkit's was the body's offset from its joint (1 m) before."""
    path = files(tmp_path)["weld_offset"]
    gaps = [float(np.max(np.abs(r))) for r in screwkit_residuals(read_mjcf(path), pin.neutral(read_mjcf(path).model))
            .values()]
    assert max(gaps) < TOLERANCE


def test_a_stewart_platform_written_by_a_cad_exporter_is_a_6_dof_platform_with_its_leg_lines(tmp_path):
    """Welds at the platform body's origin (not at its centre), the platform a child of leg 1 with no joint: the
    platform is a 6-DOF frame output (not a 3-DOF point), non-redundant, and its OTIs are those of its leg lines
    (the output twist of leg k reciprocal to the other five leg forces)."""
    mechanism = load(GALLERY / "stewart_cad.xml")
    assert mechanism.dof == 6 and mechanism.output_point is None and len(mechanism.actuators) == 6
    from screwkit.closure import chain_screws, solve
    from screwkit.studies import indices_at_pose

    pose = mechanism.home_pose + np.array([0.005, -0.004, 0.01, 0.04, -0.03, 0.08])
    result = indices_at_pose(mechanism, pose)
    chains = chain_screws(mechanism, solve(mechanism, pose[None]))
    # each leg's force along the line from its U centre to its top joint's centre
    otis = leg_line_otis([chain.points[0, 0] for chain in chains], [chain.points[0, -1] for chain in chains])
    names = [name.split(":")[0] for name in result.actuators]
    assert names == [chain.name for chain in chains]
    np.testing.assert_allclose(result.oti_actuators[0], otis, atol=TOLERANCE)
    assert 0.1 < result.lmti < 1.0 and result.f_o == {1: 0.0}


def in_a_body(text: str, pos: str, quat: str) -> str:
    """The MJCF ``text`` with every body of its world held in one more body, ``pos`` and ``quat``, which has neither
    an ``<inertial>`` nor a geom."""
    root = ElementTree.fromstring(text)
    world = root.find("worldbody")
    holder = ElementTree.Element("body", name="holder", pos=pos, quat=quat)
    for body in world.findall("body"):
        world.remove(body)
        holder.append(body)
    world.append(holder)
    return ElementTree.tostring(root, encoding="unicode")


@pytest.mark.parametrize(("pos", "quat"), [("0 0 0", "1 0 0 0"), ("0.7 -0.4 1.1", "0.8 0.3 -0.2 0.47")])
def test_the_cad_stewart_platform_held_in_a_body_without_mass_opens_as_mujoco_loads_it(tmp_path, pos, quat):
    """The CAD exporter's Stewart platform writes ``<compiler inertiafromgeom="false">``: each body's inertia from its
    ``<inertial>`` alone. Held in one more body with none (a world frame of the user's, placed or not), MuJoCo loads it
    (the body has no joint); screwkit passed on Pinocchio's refusal ("Cannot get inertia from geom and no inertia was
    found", over five lines of C++). It opens now, with the indices of the file as written at its home, to 1e-12.
    Without the ``<inertial>`` of a body with a joint (nothing welded to it has one), MuJoCo refuses the file, and
    so does screwkit, in one line naming the body."""
    source = (GALLERY / "stewart_cad.xml").read_text()
    assert 'inertiafromgeom="false"' in source
    held = tmp_path / "held.xml"
    held.write_text(in_a_body(source, pos, quat))
    mujoco.MjModel.from_xml_path(str(held))  # (MuJoCo loads it)
    written, moved = load(GALLERY / "stewart_cad.xml"), load(held)
    first, second = indices_at_pose(written, written.home_pose), indices_at_pose(moved, moved.home_pose)
    assert moved.dof == written.dof == 6
    np.testing.assert_allclose(second.iti_actuators, first.iti_actuators, rtol=0, atol=1e-12)
    np.testing.assert_allclose(second.oti_actuators, first.oti_actuators, rtol=0, atol=1e-12)
    assert abs(second.lmti - first.lmti) <= 1e-12
    root = ElementTree.fromstring(held.read_text())
    moving = next(body for body in root.iter("body") if body.get("name") == "cylinder1")
    assert moving.find("joint") is not None and all(child.find("joint") is not None for child in moving.findall("body"))
    moving.remove(moving.find("inertial"))
    massless = tmp_path / "massless.xml"
    massless.write_text(ElementTree.tostring(root, encoding="unicode"))
    with pytest.raises(ValueError, match="mass and inertia of moving bodies"):
        mujoco.MjModel.from_xml_path(str(massless))
    one_line_error(screwkit("analyze", massless), f"{massless}: <body name='cylinder1'>: a moving body without mass")


MASS = '<inertial pos="0 0 0" mass="1" diaginertia="0.01 0.01 0.01"/>'


def weighed_five_bar(compiler: str, body: str | None, child: str = "") -> str:
    """The five-bar of ``tests/test_io.py`` with ``compiler``'s attributes and every body its :data:`MASS` but
    ``body``'s, which holds ``child`` (a body welded to it) beside its geom."""
    text = five_bar_mjcf().replace('<compiler angle="radian"/>', f'<compiler angle="radian" {compiler}/>')
    text = re.sub(r'(<body name="([^"]*)"[^>]*>)', lambda m: m.group(1) + ("" if m.group(2) == body else MASS), text)
    return text if body is None else re.sub(rf'(<body name="{body}"[^>]*>.*?<geom type="sphere" size="0.01"/>)',
                                            lambda m: m.group(1) + child, text, count=1, flags=re.S)


FALSE = 'inertiafromgeom="false"'
WEIGHED = {"every body its mass": (FALSE, None, ""),
           "no mass on a moving body": (FALSE, "distal_1", ""),
           "its mass on a body welded to it": (FALSE, "distal_1", f'<body name="pad">{MASS}</body>'),
           "its mass two bodies down": (FALSE, "distal_1", f'<body name="pad"><body name="pad_2">{MASS}</body></body>'),
           "a welded body of mass 0": (FALSE, "distal_1",
                                       '<body name="pad"><inertial pos="0 0 0" mass="0" diaginertia="1 1 1"/>'
                                       '</body>'),
           "a welded body of inertia 0": (FALSE, "distal_1",
                                          '<body name="pad"><inertial pos="0 0 0" mass="1" diaginertia="0 0 0"/>'
                                          '</body>'),
           "its mass on a moving body below": (FALSE, "distal_1",
                                               f'<body name="pad"><joint name="extra" type="hinge"/>{MASS}</body>'),
           "both bounds": (FALSE + ' boundmass="0.001" boundinertia="0.001"', "distal_1", ""),
           "a bound on the mass only": (FALSE + ' boundmass="0.001"', "distal_1", ""),
           "inertias from geoms": ('inertiafromgeom="auto"', "distal_1", "")}
"""Bodies with and without ``<inertial>`` under each ``inertiafromgeom``: MuJoCo loads some and refuses others."""


@pytest.mark.parametrize("case", WEIGHED)
def test_a_body_without_mass_is_read_where_mujoco_loads_it_and_refused_where_mujoco_refuses_it(tmp_path, case):
    """Pinocchio asks an inertia of every body; under ``inertiafromgeom="false"`` screwkit gives a unit inertia to
    every body without ``<inertial>`` (the kinematics do not depend on it), and refuses, in one line naming the body,
    a body with joints whose mass or inertia, with the bodies welded to it and the compiler's bounds, is zero: as
    MuJoCo's own loading of each file does (an earlier check read a welded body's ``<inertial>`` of mass 0 as mass,
    and refused a file with both bounds, which MuJoCo loads)."""
    path = tmp_path / "five_bar.xml"
    path.write_text(weighed_five_bar(*WEIGHED[case]))
    try:
        mujoco.MjModel.from_xml_path(str(path))
        loads = True
    except ValueError as error:
        assert "mass and inertia of moving bodies" in str(error)
        loads = False
    if loads:
        assert load(path).dof == 2
    else:
        with pytest.raises(ValueError, match=rf"{re.escape(str(path))}: <body name='distal_1'>: a moving body without "
                                             r"mass or inertia .*MuJoCo refuses the file\.$") as refused:
            load(path)
        assert "\n" not in str(refused.value)


def test_the_gallery_files_are_what_the_generator_writes(tmp_path):
    subprocess.run([sys.executable, str(GALLERY / "generate.py"), str(tmp_path)], check=True, capture_output=True)
    for path in GALLERY.glob("*.xml"):
        assert (tmp_path / path.name).read_text() == path.read_text(), path.name
