"""Published robot descriptions, opened as their authors wrote them (``tests/data/gallery/published``, origins and
licences in its ``SOURCES.md``).

* Gepetto's example-parallel-robots (BSD-3-Clause), URDF + robot.yaml: the five-bar ``5bar_linkage``, the planar
  Delta ``robot_delta`` (revolute parallelograms) and the 6-SPS leg ``wl16_like``. Their indices are checked against
  numbers computed here with Pinocchio's forward kinematics and numpy alone, at the configuration the file's
  closures assemble into (closed to 1e-12 as Pinocchio measures it, the motor values those screwkit analyses): the
  textbook pressure angles of the five-bar and of the Delta (ITI = |u . t|, OTI_i = |u_i . (n x u_j)|, u the distal
  link's direction, t the elbow's velocity direction, n the plane's normal), and the leg-line OTIs of the
  Stewart-like leg (the output twist of leg k reciprocal to the other five leg forces, measured at leg k's foot
  joint).
* Pollen Robotics' Reachy Mini (Apache-2.0), an onshape-to-robot export of a 6-RSS Stewart head as MJCF and as a
  URDF with closing_ frames, and Agility Robotics' Cassie from MuJoCo Menagerie (MIT), a biped whose legs hold
  closed-loop transmissions: MuJoCo's reading (meshes left out, which MuJoCo needs and kinematics does not) and
  screwkit's agree on every body and every closure at the file's configuration, at random ones and after screwkit's
  assembly; neither is analysed yet, and the tests hold the one-line reasons screwkit gives.
"""

from __future__ import annotations

import json
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import mujoco
import numpy as np
import pinocchio as pin
import pytest
from test_axis_points import revolutes_drawn_elsewhere, revolutes_moved
from test_gallery import GALLERY, assert_same_bodies, mujoco_residuals, screwkit_residuals

from helpers import in_unit, leg_line_otis, one_line_error, screwkit
from screwkit.io import ImportError_, read_closed_tree
from screwkit.io.closed_tree import assemble
from screwkit.io.graph import graph_mechanism
from screwkit.io.loader import load
from screwkit.io.mjcf import read_mjcf
from screwkit.studies import indices_at_pose

PUBLISHED = GALLERY / "published"
DOCS = Path(__file__).resolve().parents[1] / "docs" / "other-formats.md"
GEPETTO = PUBLISHED / "example_parallel_robots"
TOLERANCE = 1e-9


# --- Gepetto's robots: indices from the geometry ---------------------------------------------------------------

def assembled(path: Path):
    """The tree of a URDF + robot.yaml closed by screwkit's assembly, checked closed with Pinocchio alone, and its
    joint placements."""
    tree = read_closed_tree(path)
    q, _ = assemble(tree)
    gaps = screwkit_residuals(tree, q)
    assert max(float(np.max(np.abs(gap))) for gap in gaps.values()) < 1e-12
    data = tree.model.createData()
    pin.forwardKinematics(tree.model, data, q)
    return tree, q, data


def joint_point(tree, data, name: str) -> np.ndarray:
    return data.oMi[tree.model.getJointId(name)].translation.copy()


def joint_axis(tree, data, name: str) -> np.ndarray:
    """The world axis of a revolute joint about (or prismatic joint along) its own z (every joint of these files)."""
    joint = tree.model.getJointId(name)
    assert tree.model.joints[joint].shortname().endswith("Z"), name
    return data.oMi[joint].rotation[:, 2].copy()


def path_to_root(model, joint: int) -> list[int]:
    """The joints from ``joint`` up to the base, ``joint`` first."""
    out = [joint]
    while model.parents[out[-1]] > 0:
        out.append(int(model.parents[out[-1]]))
    return out


def unit(vector) -> np.ndarray:
    return np.asarray(vector) / np.linalg.norm(vector)


def planar_pressure_angles(motors, elbows, ends, normal) -> dict:
    """ITI and OTI of a two-motor planar mechanism whose legs transmit a force along their distal links (elbow to
    end) to a platform that only translates in the plane (a point, or a body kept parallel): the textbook
    pressure angles, numpy alone. The links of a CAD model sit in layers along the axes: the angles are those of
    the links projected on the plane of motion (a force along the unprojected link differs from the projected one
    by a force along the normal, which the legs' parallel axes resist)."""
    def in_plane(vector):
        return unit(vector - (vector @ normal) * normal)

    rods = [in_plane(end - elbow) for elbow, end in zip(elbows, ends)]
    tangents = [in_plane(np.cross(normal, elbow - motor)) for motor, elbow in zip(motors, elbows)]
    iti = [abs(rod @ tangent) for rod, tangent in zip(rods, tangents)]
    oti = [abs(rods[0] @ unit(np.cross(normal, rods[1]))), abs(rods[1] @ unit(np.cross(normal, rods[0])))]
    return {"iti": np.array(iti), "oti": np.array(oti), "lmti": min(oti)}


def gallery_docs() -> str:
    """The Gallery section of docs/other-formats.md, whose quoted outputs the tests hold."""
    text = DOCS.read_text(encoding="utf-8")
    return text[text.index("## Gallery"):]


def assert_documented(result, path: Path) -> None:
    """The LMTI that the Gallery section quotes for ``path`` is the one computed."""
    section = gallery_docs()
    block = section[section.index(f"screwkit analyze {path.relative_to(DOCS.parents[1])}"):]
    assert f"LMTI (Eq. 11, all actuators)        {result.lmti:.4f}" in block.split("```bash")[0]


def assert_refusal_documented(error: pytest.ExceptionInfo) -> None:
    """The refusal's message (after the file's name) is quoted in the Gallery section as screwkit prints it."""
    assert str(error.value).split(": ", 1)[1] in gallery_docs()


def screwkit_at_home(path: Path, tree, q):
    """screwkit's indices at the file's home pose, after checking that its motors sit where the assembly put them."""
    mechanism = load(path)
    result = indices_at_pose(mechanism, mechanism.home_pose)
    motors = [name.split(":")[-1] for name in result.actuators]
    values = {name.split(":")[-1]: value for name, value in result.joint_values.items()}
    for motor in motors:
        np.testing.assert_allclose(values[motor], q[tree.model.joints[tree.model.getJointId(motor)].idx_q],
                                   atol=1e-9, err_msg=motor)
    return result, motors


def assert_pressure_angles(result, expected: dict, path: Path) -> None:
    """Each actuator's ITI, the OTIs of the whole mechanism and the LMTI are the textbook pressure angles'
    (``expected``: :func:`planar_pressure_angles`), at a pose where they say something, and the docs quote them."""
    np.testing.assert_allclose(result.iti_actuators, expected["iti"], atol=TOLERANCE)
    np.testing.assert_allclose(result.oti_actuators[0], expected["oti"], atol=TOLERANCE)
    np.testing.assert_allclose(result.lmti, expected["lmti"], atol=TOLERANCE)
    assert 0.1 < expected["lmti"] < 0.99  # a pose where the angles say something
    assert_documented(result, path)


def test_gepetto_five_bar_gives_the_textbook_pressure_angles():
    """5bar_linkage: leg 1 mot1-free1 ends on the pin closedloop1_A, leg 2 mot2-free2 on closedloop1_B (the 6d
    closure holds the two pins coaxial): the output is the pin's point."""
    path = GEPETTO / "5bar_linkage" / "robot.urdf"
    tree, q, data = assembled(path)
    point = joint_point(tree, data, "closedloop1_A")
    np.testing.assert_allclose(joint_point(tree, data, "closedloop1_B"), point, atol=1e-12)
    expected = planar_pressure_angles([joint_point(tree, data, m) for m in ("mot1", "mot2")],
                                      [joint_point(tree, data, e) for e in ("free1", "free2")], [point, point],
                                      joint_axis(tree, data, "mot1"))
    result, motors = screwkit_at_home(path, tree, q)
    assert motors == ["mot1", "mot2"] and result.dof == 2
    assert_pressure_angles(result, expected, path)


def test_gepetto_planar_delta_with_revolute_parallelograms_gives_the_textbook_pressure_angles():
    """robot_delta: rod 1 (mot1_rod1, free1_rod1, free2_rod1) carries the effector; rod 2 (mot1_rod2, free1_rod2)
    is pinned to it at closedloop2_A/B; the passive rod 3 closes two parallelograms that keep the effector from
    turning, so each leg transmits the force along its distal link and the effector translates."""
    path = GEPETTO / "robot_delta" / "robot.urdf"
    tree, q, data = assembled(path)
    ends = [joint_point(tree, data, "free2_rod1"), joint_point(tree, data, "closedloop2_A")]
    expected = planar_pressure_angles([joint_point(tree, data, m) for m in ("mot1_rod1", "mot1_rod2")],
                                      [joint_point(tree, data, e) for e in ("free1_rod1", "free1_rod2")], ends,
                                      joint_axis(tree, data, "mot1_rod1"))
    result, motors = screwkit_at_home(path, tree, q)
    assert motors == ["mot1_rod1", "mot1_rod2"] and result.dof == 2
    assert_pressure_angles(result, expected, path)


def test_gepetto_sps_leg_gives_the_leg_line_otis():
    """wl16_like: six S-P-S legs (three hip revolutes through one point, a prismatic motor, a ball at the foot);
    the actuation wrench of a leg is the force along its line, hip centre to foot ball centre, so ITI = 1 and OTI_k
    is |line_k . v_k| / |v_k|, v_k the velocity at leg k's foot ball centre of the foot twist reciprocal to the
    other five leg forces (the closure frames sit on the leg lines but not at the balls' centres)."""
    path = GEPETTO / "wl16_like" / "robot.urdf"
    tree, q, data = assembled(path)
    model = tree.model
    pin.framesForwardKinematics(model, data, q)
    feet = {}
    for closure in tree.closures:  # each closure joins a motor leg's end to a ball of the foot: the ball's centre
        sides = [path_to_root(model, closure.joint_a), path_to_root(model, closure.joint_b)]
        ball = [j for side in sides for j in side if model.names[j].startswith("foot_part_axis_")]
        leg = next(side for side in sides if not set(side) & set(ball))  # the foot side runs through leg 6 too
        motor = [model.names[j] for j in leg if model.names[j].startswith("motor_")]
        assert len(motor) == 1 and len(ball) == 3, closure.name
        feet[motor[0]] = data.oMi[ball[-1]].translation.copy()  # the ball's first revolute (three through a point)
    feet["motor_6"] = joint_point(tree, data, "part_4_foot_part_rev0")  # leg 6 carries the foot on its own ball
    result, motors = screwkit_at_home(path, tree, q)
    assert sorted(feet) == sorted(motors) and result.dof == 6
    hips = []
    for motor in motors:
        hip_joint = model.parents[model.parents[model.parents[model.getJointId(motor)]]]
        hips.append(data.oMi[hip_joint].translation.copy())
        direction = unit(feet[motor] - hips[-1])
        np.testing.assert_allclose(abs(direction @ joint_axis(tree, data, motor)), 1.0, atol=1e-9)  # along the slide
    otis = leg_line_otis(hips, [feet[motor] for motor in motors])
    np.testing.assert_allclose(result.iti_actuators, np.ones(6), atol=TOLERANCE)
    np.testing.assert_allclose(result.oti_actuators[0], otis, atol=TOLERANCE)
    np.testing.assert_allclose(result.lmti, min(otis), atol=TOLERANCE)
    assert_documented(result, path)


# --- MJCF exports: MuJoCo's geometry, and what screwkit says of them -------------------------------------------

REACHY = PUBLISHED / "reachy_mini" / "reachy_mini.xml"
IITK = PUBLISHED / "lab_robots_iitk" / "5bar.xml"
CASSIE = PUBLISHED / "agility_cassie" / "cassie.xml"


def without_meshes(text: str) -> str:
    """The MJCF text without what MuJoCo would load from disk (mesh, texture and material assets, mesh geoms,
    ``meshdir``): bodies, joints, inertials, sites and equalities untouched. For MuJoCo only: screwkit reads the
    file as written."""
    root = ET.fromstring(text)
    for parent in root.iter():
        for child in list(parent):
            if (parent.tag == "asset" and child.tag in ("mesh", "texture", "material")) or \
                    (child.tag == "geom" and (child.get("type") == "mesh" or child.get("mesh"))):
                parent.remove(child)
        if parent.tag == "geom":
            parent.attrib.pop("material", None)
        if parent.tag == "compiler":
            parent.attrib.pop("meshdir", None)
            parent.attrib.pop("texturedir", None)
    return ET.tostring(root, encoding="unicode")


def mujoco_model(path: Path) -> mujoco.MjModel:
    return mujoco.MjModel.from_xml_string(without_meshes(path.read_text()))


def mujoco_data(model: mujoco.MjModel, qpos) -> mujoco.MjData:
    data = mujoco.MjData(model)
    data.qpos[:] = qpos
    mujoco.mj_kinematics(model, data)
    return data


def pinocchio_q(tree, mj_model, qpos) -> np.ndarray:
    """MuJoCo's qpos as Pinocchio's q, joint by joint: free joints (x y z, quaternion w x y z in MuJoCo, x y z w in
    Pinocchio), balls (w x y z / x y z w), hinges and slides."""
    model = tree.model
    q = pin.neutral(model)
    for k in range(mj_model.njnt):
        kind, start = int(mj_model.jnt_type[k]), int(mj_model.jnt_qposadr[k])
        name = mujoco.mj_id2name(mj_model, mujoco.mjtObj.mjOBJ_JOINT, k)
        if kind == int(mujoco.mjtJoint.mjJNT_FREE):
            body = mujoco.mj_id2name(mj_model, mujoco.mjtObj.mjOBJ_BODY, int(mj_model.jnt_bodyid[k]))
            joint = model.joints[model.getJointId(name or f"{body}_free")]
            q[joint.idx_q:joint.idx_q + 7] = np.r_[qpos[start:start + 3], qpos[start + 4:start + 7], qpos[start + 3]]
        elif kind == int(mujoco.mjtJoint.mjJNT_BALL):
            joint = model.joints[model.getJointId(name)]
            q[joint.idx_q:joint.idx_q + 4] = np.r_[qpos[start + 1:start + 4], qpos[start]]
        else:
            q[model.joints[model.getJointId(name)].idx_q] = qpos[start]
    return q


def mujoco_qpos(tree, mj_model, q) -> np.ndarray:
    """The inverse of :func:`pinocchio_q`."""
    model, qpos = tree.model, mj_model.qpos0.copy()
    for k in range(mj_model.njnt):
        kind, start = int(mj_model.jnt_type[k]), int(mj_model.jnt_qposadr[k])
        name = mujoco.mj_id2name(mj_model, mujoco.mjtObj.mjOBJ_JOINT, k)
        if kind == int(mujoco.mjtJoint.mjJNT_FREE):
            body = mujoco.mj_id2name(mj_model, mujoco.mjtObj.mjOBJ_BODY, int(mj_model.jnt_bodyid[k]))
            at = model.joints[model.getJointId(name or f"{body}_free")].idx_q
            qpos[start:start + 7] = np.r_[q[at:at + 3], q[at + 6], q[at + 3:at + 6]]
        elif kind == int(mujoco.mjtJoint.mjJNT_BALL):
            at = model.joints[model.getJointId(name)].idx_q
            qpos[start:start + 4] = np.r_[q[at + 3], q[at:at + 3]]
        else:
            qpos[start] = q[model.joints[model.getJointId(name)].idx_q]
    return qpos


@pytest.mark.parametrize("path", [REACHY, CASSIE, IITK], ids=["reachy_mini", "agility_cassie", "lab_robots_iitk"])
def test_mujoco_reads_the_published_mjcf_exports_as_screwkit_does(path):
    """Reachy Mini: sites closed by unnamed <connect>s, ball joints, quaternions to six digits; Cassie: no <compiler
    angle> (degrees), eulerseq zyx, xyaxes frames, hinge refs, a free joint, ball joints, a home keyframe; the IITK
    five-bar: a pen hinged on one distal link and <connect>ed to the other, position actuators."""
    tree = read_mjcf(path)
    mj_model = mujoco_model(path)
    assert mj_model.nq == tree.model.nq
    rng = np.random.default_rng(27)
    keyframe = mj_model.key_qpos[0].copy() if mj_model.nkey else mj_model.qpos0.copy()
    np.testing.assert_allclose(pinocchio_q(tree, mj_model, keyframe), tree.q_reference, atol=1e-12)
    configurations = [mj_model.qpos0.copy(), keyframe]
    for _ in range(3):
        qpos = keyframe.copy()
        mujoco.mj_integratePos(mj_model, qpos, rng.uniform(-0.2, 0.2, mj_model.nv), 1.0)
        configurations.append(qpos)
    for qpos in configurations:
        mj_data = mujoco_data(mj_model, qpos)
        q = pinocchio_q(tree, mj_model, qpos)
        assert_same_bodies(tree, mj_model, mj_data, q)
        theirs, ours = mujoco_residuals(mj_model, mj_data), screwkit_residuals(tree, q)
        assert theirs.keys() == ours.keys() and len(ours) == mj_model.neq
        for closure in theirs:
            np.testing.assert_allclose(ours[closure], theirs[closure], atol=TOLERANCE, rtol=0, err_msg=closure)
    closed, _ = assemble(tree)
    residuals = mujoco_residuals(mj_model, mujoco_data(mj_model, mujoco_qpos(tree, mj_model, closed)))
    assert max(float(np.max(np.abs(r))) for r in residuals.values()) < TOLERANCE


def test_reachy_mini_is_refused_for_the_body_yaw_joint_under_its_stewart_platform():
    """The head is a 6-RSS Stewart platform on a body turned by the yaw_body motor: every leg runs through
    yaw_body, so the tree has one leg from the base (with loops and 7 motors) instead of six. Read one motor at a
    time, yaw_body has no actuation wrench: the six horns turn the head back as it turns the body (kinematic
    redundancy)."""
    with pytest.raises(ImportError_, match=r"leg 'body_down_3dprint' has loops inside it and 7 actuators, which "
                                           r"screwkit does not read one at a time here \(locking actuated joint "
                                           r"'yaw_body' leaves the platform as free as before\); the actuated joint "
                                           r"'yaw_body' carries every other one .*--lock yaw_body analyses") as error:
        graph_mechanism(read_closed_tree(REACHY))
    assert_refusal_documented(error)
    with pytest.raises(ImportError_, match=r"locking actuated joint 'yaw_body' leaves the platform of leg "
                                           r"'body_down_3dprint' as free as before") as error:
        graph_mechanism(read_closed_tree(REACHY.with_name("robot.urdf")))
    assert_refusal_documented(error)
    urdf = load(REACHY.with_name("robot.urdf"), lock=("yaw_body",))  # serial R-S-S legs, motors guessed again
    graph = graph_mechanism(read_closed_tree(REACHY, lock=("yaw_body",)))
    assert sorted(a.split(":")[1] for a in urdf.actuator_names) == [f"stewart_{k}" for k in range(1, 7)]
    # two exports of one CAD model, their numbers printed to other digits: the same LMTI and ITIs to 1e-6 (leg 2's
    # hinge passes 0.48 um from leg 1's universal joint; moved onto it, it parted its own, and its ITI moved 9.5e-6)
    np.testing.assert_allclose(indices_at_pose(urdf, urdf.home_pose).lmti, graph.indices().lmti, atol=1e-6)
    np.testing.assert_allclose(indices_at_pose(urdf, urdf.home_pose).iti_actuators,
                               graph.indices().iti_actuators, atol=1e-6)
    # each leg's idle spin locked on the hinge along its rod, passive_k_x (leg 2's lock fell on passive_2_z before,
    # and passive_2_x, kept, passed within the rounding of passive_1_y and passive_1_z): one group left as written
    assert any("idle joints locked" in note and "passive_1_x, passive_2_x, passive_3_x" in note
               for note in urdf.import_report)
    assert any("passive_6_x, passive_7_y, passive_7_z pass within the file's rounding of one point and are left as "
               "written" in note for note in urdf.import_report)


def test_cassie_needs_its_output_named_and_is_refused_for_its_transmissions():
    """A biped: no frame screwkit recognises as the platform; with a foot named, the whole robot (free joint, both
    legs, ten motors) is one leg with loops inside it."""
    with pytest.raises(ImportError_, match=r"which body is the platform\?") as error:
        graph_mechanism(read_closed_tree(CASSIE))
    assert_refusal_documented(error)
    with pytest.raises(ImportError_, match=r"leg 'cassie-pelvis' has loops inside it and 10 actuators, which "
                                           r"screwkit does not read one at a time here; every actuator rides on "
                                           r"the free joint 'cassie-pelvis_free'") as error:
        graph_mechanism(read_closed_tree(CASSIE, output="left-foot"))
    assert_refusal_documented(error)


CASSIE_LEFT_LEG = ("cassie-pelvis_free", "left-hip-roll", "left-hip-yaw", "left-hip-pitch", "left-knee", "left-shin",
                   "left-tarsus")
"""The joints Cassie's refusals name one after the other, down to the left ankle."""


def test_cassie_with_its_left_leg_held_drives_its_foot_directly_the_other_leg_s_motors_left_out():
    """Held down to the ankle, the left foot is on its own hinge, which the file's foot motor drives (Menagerie puts
    the motor on the foot joint, the plantar rod a passive chain that spans every planar motion): a direct drive,
    whose actuation wrench is the couple about the hinge and whose output twist is that hinge's rotation, so ITI =
    OTI = 1. The other leg's five motors reach no leg and are left out, said (they refused it as a closed-loop
    transmission)."""
    with pytest.raises(ImportError_) as error:  # the base held, the refusal names the rest at once, in turn
        graph_mechanism(read_closed_tree(CASSIE, output="left-foot", lock=CASSIE_LEFT_LEG[:1]))
    assert str(error.value).endswith(f"joints {', '.join(CASSIE_LEFT_LEG[1:])} carry every actuator of it in turn (a "
                                     "serial stage before the parallel part): --lock "
                                     f"{' --lock '.join(CASSIE_LEFT_LEG[1:])} analyses the legs on the body they turn.")
    mechanism = load(CASSIE, output="left-foot", output_type="frame", lock=CASSIE_LEFT_LEG)
    report = "\n".join(mechanism.import_report)
    assert ("actuated joints right-hip-roll, right-hip-yaw, right-hip-pitch, right-knee, right-foot on branches that "
            "reach no leg: left out (they do not move the platform)") in report
    assert mechanism.actuator_names == ("left-foot:left-foot",) and mechanism.dof == 1
    result = indices_at_pose(mechanism, mechanism.home_pose)
    assert result.iti == pytest.approx(1.0, abs=1e-12) and result.lmti == pytest.approx(1.0, abs=1e-12)


def test_reachy_mini_with_its_yaw_stage_locked_gives_the_leg_line_indices_of_its_stewart_head(tmp_path):
    """``--lock yaw_body`` holds the turntable every leg stands on: six R-S-S legs remain (a crank motor, a rod
    ball-jointed at both ends; leg 6 carries the head on its rod's far ball). Each leg's actuation wrench is the
    force along its rod, crank ball centre B to head ball centre D, so ITI_k = |u_k . t_k| (t_k the direction of
    B's velocity about the crank axis) and OTI_k = |u_k . v_k| / |v_k|, v_k the velocity at D_k of the head twist
    reciprocal to the other five rod forces: Pinocchio's forward kinematics and numpy, at the configuration the
    file's loops assemble into."""
    graph = graph_mechanism(read_closed_tree(REACHY, lock=("yaw_body",)))
    model = graph.tree.model
    assert not model.existJointName("yaw_body") and len(graph.legs) == 6 and graph.dof == 6
    data = model.createData()
    pin.forwardKinematics(model, data, graph.q)
    itis, starts, ends = [], [], []
    for leg in graph.legs:
        motor, ball = leg.joints[0], leg.joints[1]
        assert model.names[motor].startswith("stewart_") and model.joints[ball].shortname() == "JointModelSpherical"
        if leg.closures:
            closure = leg.closures[0]
            joint, placement = ((closure.joint_a, closure.placement_a) if closure.joint_a != graph.platform
                                else (closure.joint_b, closure.placement_b))
            end = (data.oMi[joint].homogeneous @ placement)[:3, 3]
        else:  # the leg the head hangs from: its rod's far ball
            end = data.oMi[leg.joints[2]].translation.copy()
        crank, axis = data.oMi[motor].translation, data.oMi[motor].rotation[:, 2]
        start = data.oMi[ball].translation
        rod = unit(end - start)
        itis.append(abs(rod @ unit(np.cross(axis, start - crank))))
        starts.append(start.copy())
        ends.append(end)
    otis = leg_line_otis(starts, ends)
    result = graph.indices()
    np.testing.assert_allclose(result.iti_actuators, itis, atol=TOLERANCE)
    np.testing.assert_allclose(result.oti_actuators[0], otis, atol=TOLERANCE)
    np.testing.assert_allclose(result.lmti, min(otis), atol=TOLERANCE)
    assert 0.1 < min(otis) < 0.99 and 0.1 < min(itis) < 0.99
    completed = screwkit("analyze", REACHY, "--lock", "yaw_body", "--json")
    assert completed.returncode == 0, completed.stderr
    assert json.loads(completed.stdout)["lmti"] == pytest.approx(result.lmti, abs=1e-12)
    one_line_error(screwkit("analyze", REACHY, "--lock", "no_such_joint"), "--lock no_such_joint: no joint of that")
    one_line_error(screwkit("analyze", REACHY), "--lock yaw_body analyses the legs on the body it turns")


@pytest.mark.parametrize("seed", [1, 2])
def test_reachy_mini_s_urdf_drawn_otherwise_along_its_axes_gives_the_same_indices(tmp_path, seed):
    """onshape-to-robot's URDF of Reachy Mini with every revolute but the head's own frame's drawn elsewhere on its
    axis (up to 5 cm): its balls
    are three revolutes each, whose axes the CAD export rounds so that they miss each other by about 1e-7 m. Their
    canonical points, each on its own axis, are then that far apart; they are still one joint at a point, as the
    canonical points read them, so the ITI of the leg the head hangs from (whose rod force lies along its ball's
    first axis) is the file's to the export's rounding (before: 0.90 and 0.99 for 0.858 with these two drawings, the
    rod force's crossing with that axis read from two lines 3e-6 rad apart)."""
    source = REACHY.with_name("robot.urdf")
    rng, joints = np.random.default_rng(seed), ET.fromstring(source.read_text()).findall("joint")
    distances = {joint.get("name"): rng.uniform(-0.05, 0.05) for joint in joints  # not the head's own frame
                 if joint.get("type") in ("revolute", "continuous") and joint.find("child").get("link") != "xl_330"}
    moved = tmp_path / "robot.urdf"
    moved.write_text(revolutes_moved(source.read_text(), distances))
    original, other = load(source, lock=("yaw_body",)), load(moved, lock=("yaw_body",))
    np.testing.assert_allclose(other.home_pose, original.home_pose, rtol=0, atol=1e-8)
    here, there = indices_at_pose(original, original.home_pose), indices_at_pose(other, original.home_pose)
    np.testing.assert_allclose(there.iti_actuators, here.iti_actuators, rtol=0, atol=1e-5)
    np.testing.assert_allclose(there.oti_actuators, here.oti_actuators, rtol=0, atol=1e-5)
    np.testing.assert_allclose(there.lmti, here.lmti, rtol=0, atol=1e-5)


def test_a_map_of_reachy_mini_with_its_yaw_stage_locked_rebuilds_the_locked_graph_in_its_tasks(tmp_path):
    """``map --lock``: the map's tasks rebuild the graph from the file with the same joints locked; each grid
    point's indices are those of graph_indices_at_poses at that pose (the head's orientation as in the file)."""
    import xarray as xr

    from screwkit.studies.poses import graph_indices_at_poses

    graph = graph_mechanism(read_closed_tree(REACHY, lock=("yaw_body",)))
    home = graph.task_pose()
    out = tmp_path / "map.nc"
    xs = [float(home[0]) - 0.004, float(home[0]) + 0.004]
    completed = screwkit("map", REACHY, "--lock", "yaw_body", "--grid", f"x:{xs[0]!r}:{xs[1]!r}:0.004", "--grid",
                         f"y:{float(home[1])!r}:{float(home[1]) + 0.004!r}:0.004", "--out", out, "--quiet")
    assert completed.returncode == 0, completed.stderr
    with xr.open_dataset(out) as dataset:
        x, y = np.meshgrid(dataset["x"].values, dataset["y"].values)
        poses = np.repeat(home[None], x.size, axis=0)
        poses[:, 0], poses[:, 1] = x.ravel(), y.ravel()
        expected = graph_indices_at_poses(graph, poses)
        np.testing.assert_allclose(dataset["lmti"].values.ravel(), expected.lmti, atol=1e-12)


def test_convert_writes_reachy_mini_s_urdf_with_its_yaw_stage_locked(tmp_path):
    """``convert --lock``: the onshape-to-robot URDF with ``yaw_body`` held is six serial R-S-S legs in screwkit's
    convention; the written file loads with the six horn motors and the indices of the file it came from."""
    source = REACHY.with_name("robot.urdf")
    out = tmp_path / "reachy_locked.urdf"
    completed = screwkit("convert", source, out, "--lock", "yaw_body", "--quiet")
    assert completed.returncode == 0, completed.stderr
    written, read = load(out), load(source, lock=("yaw_body",))
    assert sorted(a.split(":")[1] for a in written.actuator_names) == [f"stewart_{k}" for k in range(1, 7)]
    np.testing.assert_allclose(indices_at_pose(written, written.home_pose).lmti,
                               indices_at_pose(read, read.home_pose).lmti, atol=1e-12)
    one_line_error(screwkit("convert", source, tmp_path / "other.urdf"), "--lock yaw_body")


@pytest.mark.parametrize("name, xyz, rpy", [("robot_delta", (0.7, -1.3, 0.0), (0.0, 0.0, 0.9)),
                                            ("wl16_like", (2.0, 0.5, -3.0), (0.4, -0.3, 1.1))])
def test_a_file_whose_joint_values_do_not_close_assembles_the_same_in_another_world_frame(tmp_path, name, xyz, rpy):
    """Both files' joint values leave their closures open (by up to 3 cm and 0.37 m): the assembly moves them to the
    closed configuration nearest to them. The length scale its gaps are measured in is the mechanism's size (the
    joints' spread about their centroid), not their distance from the world's origin, which it once included: moved
    to another world frame, the file assembled elsewhere on the mechanism and its indices changed in the third
    decimal."""
    source = GEPETTO / name / "robot.urdf"
    text = source.read_text(encoding="utf-8")
    root = ET.fromstring(text)
    children = {joint.find("child").get("link") for joint in root.iter("joint")}
    (base,) = [link.get("name") for link in root.iter("link") if link.get("name") not in children]
    placement = f'<origin xyz="{" ".join(map(repr, xyz))}" rpy="{" ".join(map(repr, rpy))}"/>'
    moved = text.replace(f'<link name="{base}">', '<link name="new_world"/><joint name="new_world_to_base" '
                         f'type="fixed"><parent link="new_world"/><child link="{base}"/>{placement}</joint>'
                         f'<link name="{base}">', 1)
    assert moved != text
    folder = tmp_path / name
    folder.mkdir()
    (folder / "robot.urdf").write_text(moved, encoding="utf-8")
    (folder / "robot.yaml").write_text((source.parent / "robot.yaml").read_text(encoding="utf-8"), encoding="utf-8")
    scales = [assemble(read_closed_tree(path))[1] for path in (source, folder / "robot.urdf")]
    assert scales[1] == pytest.approx(scales[0], rel=1e-12)
    here, there = (indices_at_pose(m := load(path), m.home_pose) for path in (source, folder / "robot.urdf"))
    np.testing.assert_allclose(there.iti_actuators, here.iti_actuators, atol=1e-9)
    np.testing.assert_allclose([there.lmti, there.iti], [here.lmti, here.iti], atol=1e-9)


def wl16_written(folder: Path, text: str) -> Path:
    """``text`` as a copy of Gepetto's ``wl16_like`` (its robot.yaml beside it) in ``folder``."""
    folder.mkdir()
    (folder / "robot.urdf").write_text(text)
    (folder / "robot.yaml").write_text((GEPETTO / "wl16_like" / "robot.yaml").read_text())
    return folder / "robot.urdf"


@pytest.mark.parametrize("factor", [1.0, 1e-3, 1e3])
def test_the_6_sps_leg_with_its_ball_revolutes_drawn_apart_on_their_axes_is_the_same_robot(tmp_path, factor):
    """Gepetto's ``wl16_like`` with every revolute drawn elsewhere on its axis (up to 5 cm), the balls' three
    revolutes among them, in metres, millimetres and kilometres: the ball that ends each leg beyond the platform is
    still one point, where its three axes meet (it was refused: 'three revolute joints through one point' was read
    from where the file draws them), and at the file's pose the indices are the file's, the ITI the slider's 1 (a rod
    force through both ball centres)."""
    source = GEPETTO / "wl16_like" / "robot.urdf"
    redrawn = revolutes_drawn_elsewhere(source.read_text(), np.random.default_rng(4), 0.05)
    other = load(wl16_written(tmp_path / "wl16_like", in_unit(redrawn, "m", factor)))
    original = load(source)
    pose = original.home_pose * np.array([factor] * 3 + [1.0] * 3)
    here, there = indices_at_pose(original, original.home_pose), indices_at_pose(other, pose)
    np.testing.assert_allclose(there.iti_actuators, here.iti_actuators, rtol=0, atol=1e-9)
    np.testing.assert_allclose(there.iti_actuators, 1.0, rtol=0, atol=1e-9)
    np.testing.assert_allclose([there.lmti, there.f_o[1]], [here.lmti, here.f_o[1]], rtol=0, atol=1e-9)


def test_the_6_sps_leg_drawn_apart_on_its_axes_in_another_world_frame_is_the_same_robot(tmp_path):
    """The same redrawn ``wl16_like`` hung in another world frame: its balls beyond the platform are found at the
    same points of the robot, and its indices at its home pose are the unmoved redrawn file's at its own."""
    source = GEPETTO / "wl16_like" / "robot.urdf"
    redrawn = revolutes_drawn_elsewhere(source.read_text(), np.random.default_rng(4), 0.05)
    base = "base_link" if '<link name="base_link">' in redrawn else ET.fromstring(redrawn).find("link").get("name")
    placement = '<origin xyz="2.0 0.5 -3.0" rpy="0.4 -0.3 1.1"/>'
    moved = redrawn.replace(f'<link name="{base}">', '<link name="new_world"/><joint name="new_world_to_base" '
                            f'type="fixed"><parent link="new_world"/><child link="{base}"/>{placement}</joint>'
                            f'<link name="{base}">', 1)
    assert moved != redrawn
    unmoved, other = (load(wl16_written(tmp_path / name, text)) for name, text in (("a", redrawn), ("b", moved)))
    here, there = indices_at_pose(unmoved, unmoved.home_pose), indices_at_pose(other, other.home_pose)
    np.testing.assert_allclose(there.iti_actuators, here.iti_actuators, rtol=0, atol=1e-9)
    np.testing.assert_allclose([there.lmti, there.f_o[1]], [here.lmti, here.f_o[1]], rtol=0, atol=1e-9)


@pytest.mark.parametrize("axes", [("0 0 1", "0 1 0", "0 0 1"), ("1 0 0", "0 1 0", "1 1 0.1")],
                         ids=["z-y-z at its singular pose", "nearly in one plane"])
def test_a_leg_ending_on_any_three_revolutes_that_meet_is_a_ball(tmp_path, axes):
    """``wl16_like`` with one foot ball's revolutes turned to other axes through the same point: a Z-Y-Z one drawn
    at its singular pose (the first and third axes parallel) and one whose axes are nearly in one plane. Both are a
    ball beyond the platform (every rotation about the point, as the file's), so the indices are the file's (a
    determinant test refused both)."""
    source = GEPETTO / "wl16_like" / "robot.urdf"
    text = source.read_text()
    for k, axis in enumerate(axes):
        text = re.sub(rf'(<joint name="foot_part_axis_1_4_rev{k}" type="revolute">.*?<axis xyz=")[^"]*(")',
                      rf"\g<1>{axis}\2", text, count=1, flags=re.S)
    assert text.count(f'<axis xyz="{axes[2]}"') >= 1 and text != source.read_text()
    folder = tmp_path / "wl16_like"
    folder.mkdir()
    (folder / "robot.urdf").write_text(text)
    (folder / "robot.yaml").write_text((source.parent / "robot.yaml").read_text())
    original, other = load(source), load(folder / "robot.urdf")
    here, there = indices_at_pose(original, original.home_pose), indices_at_pose(other, original.home_pose)
    np.testing.assert_allclose(there.iti_actuators, here.iti_actuators, rtol=0, atol=1e-9)
    np.testing.assert_allclose([there.lmti, there.f_o[1]], [here.lmti, here.f_o[1]], rtol=0, atol=1e-9)


def five_bar_pressure_angles(bases, elbows, point) -> tuple[np.ndarray, float]:
    """A planar five-bar's textbook indices at its point ``point``: each actuator's ITI, the sine of the angle its
    proximal link makes with its distal link, and (two actuators, no redundancy) the LMTI, the sine of the angle between
    the two distal links (each leg's force is along its distal link; the point moves across the other one's)."""
    def sine(first, second):
        return abs(first[0] * second[1] - first[1] * second[0]) / np.linalg.norm(first) / np.linalg.norm(second)

    itis = np.array([sine(elbow - base, point - elbow) for base, elbow in zip(bases, elbows)])
    return itis, sine(point - elbows[0], point - elbows[1])


def test_the_lab_robots_five_bar_has_the_textbook_pressure_angles_as_mujoco_places_it():
    """The IITK teaching five-bar (MIT; 0.2 m links, motors 67 mm apart) opens as written, its pen (where its one
    <connect> joins the legs) the platform as when named as the output, and `analyze` gives the textbook values from
    MuJoCo's own placement of its bodies at the file's configuration (the elbows 0.0335 m off the motors' line: ITI
    0.1675), and at two other pen positions from the elbows found as circle intersections here (the file's working mode:
    each elbow on its own side)."""
    model = mujoco_model(IITK)
    data = mujoco_data(model, model.qpos0.copy())
    body = {name: mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name) for name in
            ("l1_left", "l1_right", "l2_left", "l2_right")}
    bases = [data.xpos[body[name]][:2] for name in ("l1_left", "l1_right")]
    elbows = [data.xpos[body[name]][:2] for name in ("l2_left", "l2_right")]
    pen = data.site_xpos[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "site_pen")][:2]
    run, inferred = screwkit("analyze", IITK, "--output", "site_pen", "--json"), screwkit("analyze", IITK, "--json")
    assert run.returncode == 0 and inferred.returncode == 0, run.stderr + inferred.stderr
    found = json.loads(run.stdout)
    assert json.loads(inferred.stdout)["iti_actuators"] == pytest.approx(found["iti_actuators"], abs=1e-12)
    itis, lmti = five_bar_pressure_angles(bases, elbows, pen)
    np.testing.assert_allclose(list(found["iti_actuators"].values()), itis, atol=TOLERANCE)
    assert found["lmti"] == pytest.approx(lmti, abs=TOLERANCE) and found["dof"] == 2
    np.testing.assert_allclose([found["pose"]["x"], found["pose"]["y"]], pen, atol=TOLERANCE)
    proximal, distal = 0.2, float(np.linalg.norm(pen - elbows[0]))
    for point in (np.array([0.33, 0.02]), np.array([0.3, -0.05])):
        run = screwkit("analyze", IITK, "--output", "site_pen", "--json", "--pose", *(repr(float(v)) for v in point))
        assert run.returncode == 0, run.stderr
        found, elbows = json.loads(run.stdout), []
        for base, side in zip(bases, (1.0, -1.0)):  # the elbow on the motors' own side of the base-to-pen line
            reach = point - base
            length = float(np.linalg.norm(reach))
            along = (proximal**2 - distal**2 + length**2) / (2.0 * length)
            normal = np.array([-reach[1], reach[0]]) / length
            elbows.append(base + along * reach / length + side * np.sqrt(proximal**2 - along**2) * normal)
        itis, lmti = five_bar_pressure_angles(bases, elbows, point)
        np.testing.assert_allclose(list(found["iti_actuators"].values()), itis, atol=TOLERANCE)
        assert found["lmti"] == pytest.approx(lmti, abs=TOLERANCE)


def test_gepetto_five_bar_says_beside_its_pose_that_the_pose_is_the_pins():
    """Its output frame ``effector`` is 0.0675 m from the pin where the legs meet, which is the output point: the
    pose printed is the pin's. That used to be said only in the conversion's report, after the indices; it is now
    said beside the pose, with the distance as Pinocchio places the two frames."""
    path = GEPETTO / "5bar_linkage" / "robot.urdf"
    tree, _, data = assembled(path)
    pin.updateFramePlacements(tree.model, data)
    effector = data.oMf[tree.model.getFrameId("effector")].translation
    offset, normal = effector - joint_point(tree, data, "closedloop1_A"), joint_axis(tree, data, "mot1")
    apart = np.linalg.norm(offset - (offset @ normal) * normal)  # in the plane of motion
    run = screwkit("analyze", path)
    assert run.returncode == 0, run.stderr
    line = run.stdout.splitlines()[1]
    assert line.startswith("  output: the point where the chains meet on body 'end_rod'")
    assert f"{apart:.4g} m in the plane from frame 'effector'" in line
