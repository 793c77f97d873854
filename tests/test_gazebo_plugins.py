"""Loops that Gazebo's plugins close, and the rest of what a Gazebo user writes around a mechanism.

* Gazebo (gz-sim) users close a loop with the DetachableJoint plugin, which makes a fixed joint between
  ``<parent_link>`` and ``<child_link>`` when the simulation starts: a URDF five-bar and 3-R-S-S Delta
  (``tests/data/gallery/published/ros2_closed_loop_ws``, MIT) and an SDFormat five-bar
  (``ros2_closed_loop_demo``, MIT), published so. Read as the weld it is, against the indices that Pinocchio's own
  placement of their joints gives (the five-bar's pressure angles; the Delta's rod lines), in millimetres and in a
  turned world; the SDFormat five-bar against the same model with the plugin written as a fixed joint.
* Their actuators are the joints their joint-controller plugins drive (the Delta's planning chain is no motor).
* A ``<transmission>`` whose joint's hardware interface is passive (``PassiveJointInterface``) drives nothing.
* A world's static models without joints (its ground plane) are left out.

The five-bar's base is turned by ``rpy="0 3.14159 0"``: its plane's normal 2.65e-6 rad from the world's x axis. The
plane's frame, its x taken from the world's as 1 - n_x**2 of nearly equal numbers, came out 4e-11 rad from
perpendicular to the normal, and the file's own home was refused as unreachable (missing by 1.6e-11 m).
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from test_gallery_published import PUBLISHED

from helpers import in_unit, one_line_error, screwkit
from screwkit.common.rotations import rotation_from_rpy, rpy_from_rotation
from screwkit.io import ImportError_, read_mechanism_file
from screwkit.io.loader import load, load_text
from screwkit.studies import indices_at_pose

FIVE_BAR = PUBLISHED / "ros2_closed_loop_ws" / "fivebar_linkage.urdf"
DELTA = PUBLISHED / "ros2_closed_loop_ws" / "3dof_delta.urdf"
SDF_FIVE_BAR = PUBLISHED / "ros2_closed_loop_demo" / "model.sdf"
TURN = ("0.4 -0.3 1.1", "0.3 -0.2 0.5")
"""A world the mechanisms are turned (rpy) and moved (xyz, m) into."""


def pinocchio_placements(path):
    """Pinocchio's reading of a URDF tree at its file's joint values (0, where these files' loops close): each
    joint's origin and unit axis in the world, by name."""
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    pin.forwardKinematics(model, data, pin.neutral(model))

    def line(name):
        joint = model.getJointId(name)
        placement = data.oMi[joint]
        local = {"JointModelRX": (1, 0, 0), "JointModelRY": (0, 1, 0), "JointModelRZ": (0, 0, 1)}.get(
            model.joints[joint].shortname())
        axis = placement.rotation @ (np.array(local, dtype=float) if local is not None
                                     else model.joints[joint].extract().axis)
        return placement.translation.copy(), axis / np.linalg.norm(axis)

    return line


def five_bar_textbook(path) -> dict:
    """The five-bar's pressure angles at its file's configuration: ITI_i = |sin(proximal_i, distal_i)|, the LMTI
    |sin(distal_1, distal_2)| at the closure pin P, in the plane normal to the hinges."""
    line = pinocchio_placements(path)
    normal = line("Chain1_1")[1]

    def sine(u, v):
        u, v = u - (u @ normal) * normal, v - (v @ normal) * normal
        return abs(np.cross(u, v) @ normal) / np.linalg.norm(u) / np.linalg.norm(v)

    (a1, _), (b1, _), (p, _) = (line(name) for name in ("Chain1_1", "Chain1_2", "Chain1_closure"))
    (a2, _), (b2, _) = (line(name) for name in ("Chain2_1", "Chain2_2"))
    return {"Chain1_1": sine(b1 - a1, p - b1), "Chain2_1": sine(b2 - a2, p - b2), "lmti": sine(p - b1, p - b2)}


def delta_textbook(path) -> dict:
    """The Delta's indices from its rod lines (a translating platform): each ball's centre where its three revolutes'
    axes meet (least squares), the rod u_i from the platform's ball to the elbow's, ITI_i = |u_i . t_i| with t_i the
    elbow's velocity direction about the crank, OTI_i = |u_i . (u_j x u_k)| / |u_j x u_k|."""
    line = pinocchio_placements(path)

    def meeting(names):
        lines = [line(name) for name in names]
        projector = [np.eye(3) - np.outer(axis, axis) for _, axis in lines]
        return np.linalg.solve(sum(projector), sum(p @ point for p, (point, _) in zip(projector, lines)))

    rods, found = [], {}
    for leg in (1, 2, 3):
        elbow = meeting([f"Chain{leg}_top_{k}" for k in "ABC"])
        foot = meeting([f"Chain{leg}_cl_{k}" for k in "ABC"])
        crank, axis = line(f"Chain{leg}_1")
        rod = (elbow - foot) / np.linalg.norm(elbow - foot)
        velocity = np.cross(axis, elbow - crank)
        found[f"Chain{leg}_1"] = abs(rod @ velocity) / np.linalg.norm(velocity)
        rods.append(rod)
    for leg in range(3):
        across = np.cross(rods[(leg + 1) % 3], rods[(leg + 2) % 3])
        found[f"oti{leg + 1}"] = abs(rods[leg] @ across) / np.linalg.norm(across)
    return found


def turned(urdf: str, rpy: str, xyz: str) -> str:
    """A URDF whose joints on its root link are placed by a turn (``rpy``) and a shift (``xyz``) of the world
    composed with their own origins: the same mechanism elsewhere in the world."""
    root = ET.fromstring(urdf)
    children = {joint.find("child").get("link") for joint in root.findall("joint")}
    base = next(link.get("name") for link in root.findall("link") if link.get("name") not in children)
    turn, shift = rotation_from_rpy([float(v) for v in rpy.split()]), np.array([float(v) for v in xyz.split()])
    for joint in root.findall("joint"):
        if joint.find("parent").get("link") == base:
            origin = joint.find("origin")
            place = np.array([float(v) for v in origin.get("xyz", "0 0 0").split()])
            own = rotation_from_rpy([float(v) for v in origin.get("rpy", "0 0 0").split()])
            origin.set("xyz", " ".join(repr(float(v)) for v in turn @ place + shift))
            origin.set("rpy", " ".join(repr(float(v)) for v in rpy_from_rotation(turn @ own)))
    return ET.tostring(root, encoding="unicode")


def indices(path, **options) -> dict:
    mechanism = load(path, **options)
    result = indices_at_pose(mechanism, mechanism.home_pose)
    found = {name.split(":")[-1]: float(v) for name, v in zip(mechanism.actuator_names,
                                                                np.ravel(result.iti_actuators))}
    found["lmti"] = float(result.lmti)
    return found


def test_the_published_five_bar_closed_by_a_detachable_joint_opens_as_written_with_pinocchios_pressure_angles():
    """As written (no option), its output the point where the legs meet: the pin Chain1_closure, by which the link
    that the plugin welds onto the right leg's distal link hangs from the left leg's, said in the report; the
    pressure angles measured there; so with that body named (--output Chain1_link_2). The link welded named instead
    (--output Chain1_dummy) has its frame as the output, with the same LMTI; a point asked of it is refused, since a
    weld meets its body at no point (its point was the weld's frame, which moved with the way the weld is written)."""
    mechanism = load(FIVE_BAR)
    assert sorted(name.split(":")[-1] for name in mechanism.actuator_names) == ["Chain1_1", "Chain2_1"]
    notes = " | ".join(read_mechanism_file(FIVE_BAR, output="Chain1_dummy")[1].notes)
    assert "closures Chain2_tip_to_Chain1_dummy: the fixed joints Gazebo's DetachableJoint plugins make" in notes
    assert read_mechanism_file(FIVE_BAR, output="Chain1_dummy")[1].file_format == \
        "URDF + Gazebo joints (DetachableJoint plugins)"
    assert "the joints the file's joint controller plugins drive, Chain1_1, Chain2_1" in notes
    expected = five_bar_textbook(FIVE_BAR)
    for options in ({}, {"output": "Chain1_link_2"}):
        found = indices(FIVE_BAR, **options)
        assert found.keys() == expected.keys()
        for key in expected:
            assert found[key] == pytest.approx(expected[key], abs=1e-9), (options, key)
    report = read_mechanism_file(FIVE_BAR)[1]
    assert "platform inferred: body 'Chain1_link_2', where closure 'Chain2_tip_to_Chain1_dummy' joins the legs " \
           "through joint 'Chain1_closure' (the welded link hangs by it alone)" in " | ".join(report.notes), report
    assert report.output.startswith("the point where the chains meet on body 'Chain1_link_2'"), report.output
    with pytest.raises(ImportError_, match=r"--output-type point needs every closure to meet the platform at one "
                                           r"point; closure 'Chain2_tip_to_Chain1_dummy' welds a leg to it, which "
                                           r"meets it at none \(--output names a body"):
        load(FIVE_BAR, output="Chain1_dummy", output_type="point")
    assert indices(FIVE_BAR, output="Chain1_dummy")["lmti"] == pytest.approx(expected["lmti"], abs=1e-9)


@pytest.mark.parametrize("unit, factor, world, relabel", [("mm", 1e3, None, False), (None, 1.0, TURN, False),
                                                            ("km", 1e-3, TURN, False), (None, 1.0, None, True),
                                                            (None, 1.0, None, "weld")])
def test_the_published_five_bar_reads_the_same_in_another_unit_and_world(tmp_path, unit, factor, world, relabel):
    """In mm and km, turned, with its motors renamed and its joints and links written in reverse order (each ITI
    follows its motor), and with its plugin's weld written the other way round: as written, as with the body welded
    named, Pinocchio's pressure angles of the file as published."""
    expected = five_bar_textbook(FIVE_BAR)
    text = FIVE_BAR.read_text()
    if world is not None:
        text = turned(text, *world)
    if unit is not None:
        text = in_unit(text, unit, factor)
    if relabel == "weld":
        swapped = text.replace("<parent_link>Chain2_tip</parent_link>", "<parent_link>Chain1_dummy</parent_link>") \
            .replace("<child_link>Chain1_dummy</child_link>", "<child_link>Chain2_tip</child_link>")
        assert swapped.count("<parent_link>Chain1_dummy</parent_link>") == 1 and swapped != text
        text = swapped
    elif relabel:
        text = relabelled(text)
    path = tmp_path / "fivebar_linkage.urdf"
    path.write_text(text)
    back = {new: old for old, new in RENAMED.items()}
    for options in ({}, {"output": "Chain1_link_2"}):
        found = indices(path, length_unit=unit, **options)
        found = {back.get(key, key): value for key, value in found.items()}
        assert found.keys() == expected.keys()
        for key in expected:
            assert found[key] == pytest.approx(expected[key], abs=1e-9), (options, key)


RENAMED = {"Chain1_1": "drive_c", "Chain2_1": "drive_a", "Chain3_1": "drive_b"}
"""The Deltas' motors renamed, so that their order by name is another."""


def relabelled(urdf: str) -> str:
    """A Delta URDF with its motors renamed (:data:`RENAMED`, in the joints and the controllers) and its joints and
    links written in reverse order: its legs read in another order."""
    for old, new in RENAMED.items():
        urdf = urdf.replace(f'"{old}"', f'"{new}"').replace(f">{old}<", f">{new}<")
    root = ET.fromstring(urdf)
    elements = [child for child in root if child.tag in ("joint", "link")]
    for child in elements:
        root.remove(child)
    for child in reversed(elements):
        root.append(child)
    return ET.tostring(root, encoding="unicode")


DELTA_VARIANTS = {"as written": (lambda text: text, None), "turned": (lambda text: turned(text, *TURN), None),
                  "mm": (lambda text: in_unit(text, "mm", 1e3), "mm"),
                  "km, turned": (lambda text: in_unit(turned(text, *TURN), "km", 1e-3), "km"),
                  "relabelled": (relabelled, None)}


def delta_indices(path, unit, **options) -> tuple[dict, float]:
    """Each motor's ITI by its name in the file before any renaming, and the LMTI, at the file's home."""
    loaded = load(path, length_unit=unit, **options)
    result = indices_at_pose(loaded, loaded.home_pose)
    back = {new: old for old, new in RENAMED.items()}
    names = [back.get(name.split(":")[-1], name.split(":")[-1]) for name in loaded.actuator_names]
    return dict(zip(names, np.ravel(result.iti_actuators))), float(result.lmti)


@pytest.mark.parametrize("variant", DELTA_VARIANTS)
def test_the_published_delta_closed_by_three_detachable_joints_has_its_rod_lines_indices(tmp_path, variant):
    """Its actuators the three cranks its controllers drive (the prismatic chain a motion planner moves the
    platform with is no motor, and was guessed one); its ITIs and OTIs those of the rod lines, also turned, in mm
    and km, and with its motors renamed and its legs written in another order (each ITI follows its motor)."""
    rewrite, unit = DELTA_VARIANTS[variant]
    path = tmp_path / "3dof_delta.urdf"
    path.write_text(rewrite(DELTA.read_text()))
    expected = delta_textbook(DELTA)
    itis, lmti = delta_indices(path, unit)
    assert sorted(itis) == ["Chain1_1", "Chain2_1", "Chain3_1"]
    for name, value in itis.items():
        assert value == pytest.approx(expected[name], abs=1e-9), name
    assert lmti == pytest.approx(min(expected[f"oti{k}"] for k in (1, 2, 3)), abs=1e-9)


def with_plugin_as_joint(text: str) -> str:
    """The SDFormat five-bar with its DetachableJoint plugin written as the fixed joint it makes."""
    root = ET.fromstring(text)
    model = root.find("model")
    plugin = next(p for p in model.findall("plugin") if "DetachableJoint" in p.get("name", ""))
    model.remove(plugin)
    joint = ET.SubElement(model, "joint", name="loop", type="fixed")
    ET.SubElement(joint, "parent").text = plugin.findtext("parent_link").strip()
    ET.SubElement(joint, "child").text = plugin.findtext("child_link").strip()
    return ET.tostring(root, encoding="unicode")


GROUND = ('<model name="ground_plane"><static>true</static><link name="link"><collision name="c"><geometry><plane>'
          '<normal>0 0 1</normal></plane></geometry></collision></link></model>')


def test_the_published_sdformat_five_bar_reads_as_its_plugin_written_as_a_fixed_joint_and_in_a_world(tmp_path):
    expected = indices(SDF_FIVE_BAR, output="link_4")
    native = tmp_path / "native.sdf"
    native.write_text(with_plugin_as_joint(SDF_FIVE_BAR.read_text()))
    assert indices(native, output="link_4") == pytest.approx(expected, abs=1e-12)
    model = ET.tostring(ET.fromstring(SDF_FIVE_BAR.read_text()).find("model"), encoding="unicode")
    world = tmp_path / "world.sdf"
    world.write_text(f'<sdf version="1.9"><world name="w">{GROUND}{model}</world></sdf>')
    assert indices(world, output="link_4") == pytest.approx(expected, abs=1e-12)
    assert any("models 'ground_plane' of the world left out: scenery (static without joints" in note
               for note in read_mechanism_file(world, output="link_4")[1].notes)
    world.write_text(f'<sdf version="1.9"><world name="w"><include><uri>model://sun</uri></include><include><uri>'
                     'https://fuel.gazebosim.org/1.0/OpenRobotics/models/Ground Plane</uri></include>'
                     f'{model}</world></sdf>')
    assert indices(world, output="link_4") == pytest.approx(expected, abs=1e-12)
    assert any("models 'model://sun', 'https://fuel.gazebosim.org/1.0/OpenRobotics/models/Ground Plane' of the world "
               "left out" in note for note in read_mechanism_file(world, output="link_4")[1].notes)
    other = model.replace("name='closed_loop_demo'", "name='second'").replace('name="closed_loop_demo"',
                                                                               'name="second"')
    world.write_text(f'<sdf version="1.9"><world name="w">{GROUND}{model}{other}</world></sdf>')
    with pytest.raises(ImportError_, match=r": 2 <model> elements \('closed_loop_demo', 'second', besides 1 static "
                                           r"without joints\); screwkit reads one model: write the mechanism's model "
                                           r"alone in a file\.$"):
        load(world, output="link_4")


def test_a_hinge_closure_out_of_the_plane_of_motion_leaves_the_platform_to_be_named(tmp_path):
    """The SDFormat five-bar opens as written at the point where its hinge closure joins the legs, a hinge normal to
    its plane of motion; with one elbow's axis tilted out of that plane the hinge's drawn point is no meeting of the
    legs, and which body is the platform is asked for, as before."""
    assert load(SDF_FIVE_BAR).dof == 2
    text, count = re.subn(r"(<joint name='joint_B' type='revolute'>.*?<xyz>)0 1 0(</xyz>)", r"\g<1>0 1 0.2\g<2>",
                          SDF_FIVE_BAR.read_text(), count=1, flags=re.S)
    assert count == 1
    path = tmp_path / "model.sdf"
    path.write_text(text)
    with pytest.raises(ImportError_, match=r"which body is the platform\? Name its output frame"):
        load(path)
    assert load(path, output="link_2").dof == 1  # (named, it opens: the tilted loop moves in one DoF)


def test_a_detachable_joint_to_another_models_link_closes_no_loop(tmp_path):
    """A gripper's plugin that attaches an object to pick up: no loop of this model."""
    text = SDF_FIVE_BAR.read_text().replace("<child_link>dummy_link</child_link>", "<child_link>box</child_link>")
    path = tmp_path / "model.sdf"
    path.write_text(text)
    with pytest.raises(ImportError_, match="no closure: nothing closes the tree into a parallel mechanism"):
        load(path, output="link_4")


def test_a_transmission_with_a_passive_hardware_interface_drives_nothing(tmp_path):
    """The five-bar with transmissions on its motors (an effort interface) and on a passive joint of each leg (the
    PassiveJointInterface of a closed-loop simulator): two actuators, as the controllers say, and the passive joints
    named in the report."""
    def transmission(joint: str, interface: str) -> str:
        return (f'<transmission name="{joint}_trans"><type>transmission_interface/SimpleTransmission</type>'
                f'<joint name="{joint}"><hardwareInterface>hardware_interface/{interface}</hardwareInterface></joint>'
                f'<actuator name="{joint}_motor"><mechanicalReduction>1</mechanicalReduction></actuator>'
                '</transmission>')

    added = "".join(transmission(joint, interface) for joint, interface in (
        ("Chain1_1", "EffortJointInterface"), ("Chain1_2", "PassiveJointInterface"),
        ("Chain2_1", "PositionJointInterface"), ("Chain2_2", "PassiveJointInterface")))
    path = tmp_path / "fivebar_linkage.urdf"
    path.write_text(FIVE_BAR.read_text().replace("</robot>", added + "</robot>"))
    mechanism = load(path, output="Chain1_dummy")
    assert sorted(name.split(":")[-1] for name in mechanism.actuator_names) == ["Chain1_1", "Chain2_1"]
    assert any(note.startswith("joints Chain1_2, Chain2_2: their <transmission>s' hardware interfaces are passive")
               for note in read_mechanism_file(path, output="Chain1_dummy")[1].notes)
    assert indices(path, output="Chain1_dummy") == pytest.approx(indices(FIVE_BAR, output="Chain1_dummy"), abs=1e-12)


def sdf_five_bar_textbook(text: str, actuators_deg) -> dict:
    """The SDFormat five-bar's pressure angles from its file's geometry (every pose unturned: each joint where its
    child link's pose and the joint's own pose put it, in the file's lengths), with its motors joint_A0 and joint_B0
    (both at the base point O, turning about y) at ``actuators_deg``: the elbows A and B turned about O, the pin C
    where the distal links meet, nearer its place in the file; ITI_i = |sin(OA, AC)|, |sin(OB, BC)|, the LMTI
    |sin(AC, BC)|."""
    model = ET.fromstring(text).find("model")
    links = {link.get("name"): np.array(link.findtext("pose").split(), dtype=float) for link in model.iter("link")}
    joints = {}
    for joint in model.iter("joint"):
        own = joint.findtext("pose")
        if own is not None and joint.findtext("child") in links:
            place = links[joint.findtext("child")] + np.array(own.split(), dtype=float)
            assert not np.any(place[3:]), joint.get("name")  # (no turn anywhere: positions add)
            joints[joint.get("name")] = place[:3]
    origin, (a, b, c) = joints["joint_A0"], (joints[name] for name in ("joint_A", "joint_B", "joint_C"))
    assert np.allclose(joints["joint_B0"], origin)

    def turned(point, degrees):
        s, k = np.sin(np.radians(degrees)), np.cos(np.radians(degrees))
        return origin + np.array([[k, 0, s], [0, 1, 0], [-s, 0, k]]) @ (point - origin)

    first, second = turned(a, actuators_deg[0]), turned(b, actuators_deg[1])
    r1, r2 = np.linalg.norm(c - a), np.linalg.norm(c - b)  # the distal links
    span = second - first
    along = (r1 ** 2 - r2 ** 2 + span @ span) / (2 * np.linalg.norm(span))
    unit = span / np.linalg.norm(span)
    across = np.cross([0.0, 1.0, 0.0], unit)
    pins = [first + along * unit + side * np.sqrt(r1 ** 2 - along ** 2) * across for side in (1, -1)]
    pin = min(pins, key=lambda point: np.linalg.norm(point - c))

    def sine(u, v):
        return abs(np.cross(u, v)[1]) / np.linalg.norm(u) / np.linalg.norm(v)

    return {"joint_A0:joint_A0": sine(first - origin, pin - first),
            "joint_B0:joint_B0": sine(second - origin, pin - second), "lmti": sine(pin - first, pin - second)}


def test_the_command_opens_the_published_files_and_says_what_a_world_holds_too_many_of(tmp_path):
    """Both five-bars as written: the URDF against Pinocchio's pressure angles; the SDFormat one against those of
    its file's geometry at its motors' values (forward kinematics, ``--actuators``), also written in millimetres and
    in kilometres with its elements in reverse order (its legs read in another order)."""
    expected = five_bar_textbook(FIVE_BAR)
    for options in ((), ("--output", "Chain1_link_2")):
        done = screwkit("analyze", FIVE_BAR, *options, "--json")
        assert done.returncode == 0, done.stderr
        printed = json.loads(done.stdout)
        assert [printed["iti"], printed["lmti"]] == pytest.approx([min(expected["Chain1_1"], expected["Chain2_1"]),
                                                                   expected["lmti"]], abs=1e-9), options
    text = SDF_FIVE_BAR.read_text()
    scaled = {"m": SDF_FIVE_BAR}
    for unit, factor in (("mm", 1e3), ("km", 1e-3)):  # (written in that unit, its elements in reverse order)
        root = ET.fromstring(text)
        model = root.find("model")
        for pose in model.iter("pose"):
            values = pose.text.split()
            pose.text = " ".join([*(repr(factor * float(v)) for v in values[:3]), *values[3:]])
        elements = list(model)
        for element in elements:
            model.remove(element)
        model.extend(reversed(elements))
        scaled[unit] = tmp_path / f"model_{unit}.sdf"
        scaled[unit].write_text(ET.tostring(root, encoding="unicode"))
    for actuators in (("0", "0"), ("10", "-15"), ("-25", "5")):
        expected = sdf_five_bar_textbook(text, [float(v) for v in actuators])
        for unit, path in scaled.items():
            done = screwkit("analyze", path, "--actuators", *actuators, "--length-unit", unit, "--json")
            assert done.returncode == 0, done.stderr
            printed = json.loads(done.stdout)
            assert printed["iti_actuators"] == pytest.approx({k: expected[k] for k in printed["iti_actuators"]},
                                                             abs=1e-9), (path, actuators)
            assert printed["lmti"] == pytest.approx(expected["lmti"], abs=1e-9), (path, actuators)
            assert sorted(printed["iti_actuators"]) == ["joint_A0:joint_A0", "joint_B0:joint_B0"]
    model = ET.tostring(ET.fromstring(SDF_FIVE_BAR.read_text()).find("model"), encoding="unicode")
    world = tmp_path / "world.sdf"
    world.write_text(f'<sdf version="1.9"><world name="w">{GROUND}{model}{model.replace("closed_loop_demo", "b")}'
                     '</world></sdf>')
    one_line_error(screwkit("analyze", world, "--output", "link_4"), "2 <model> elements",
                   "write the mechanism's model alone in a file")


def test_a_converted_mechanism_is_named_by_its_whole_file_name(tmp_path):
    """A file named for a variant, ``fivebar_lt_3.1416.urdf``, was called ``fivebar_lt_3``."""
    path = tmp_path / "fivebar_linkage_3.1416.urdf"
    path.write_text(FIVE_BAR.read_text())
    assert load(path, output="Chain1_dummy").name == "fivebar_linkage_3.1416"
    assert load(PUBLISHED / "example_parallel_robots" / "5bar_linkage" / "robot.urdf").name == "robot"  # + robot.yaml


def test_joints_that_apply_joint_force_plugins_drive_are_the_actuators_and_an_end_effector_link_the_output(tmp_path):
    """Gazebo's ApplyJointForce plugins name the joints a user drives by effort: the SDFormat five-bar driven at its
    left motor and its right elbow (not the joints a guess picks, the two leaving the base), named in the report;
    its link ``link_4`` renamed ``endEffector`` is taken as the output, however the name is written."""
    plugins = "".join(f'<plugin filename="libignition-gazebo-apply-joint-force-system.so" '
                      f'name="ignition::gazebo::systems::ApplyJointForce"><joint_name>{joint}</joint_name></plugin>'
                      for joint in ("joint_A0", "joint_B"))
    text = SDF_FIVE_BAR.read_text().replace("</model>", plugins + "</model>")
    path = tmp_path / "model.sdf"
    path.write_text(text)
    mechanism = load(path, output="link_4")
    assert [name.split(":")[-1] for name in mechanism.actuator_names] == ["joint_A0", "joint_B"]
    notes = read_mechanism_file(path, output="link_4")[1].notes
    assert not any("guessed" in note for note in notes), notes
    expected = indices(path, output="link_4")
    for spelled in ("endEffector", "End-Effector", "end_effector"):
        path.write_text(text.replace("'link_4'", f"'{spelled}'").replace(">link_4<", f">{spelled}<"))
        assert indices(path) == pytest.approx(expected, abs=1e-12), spelled


def test_what_the_report_says_of_plugins_and_transmissions(tmp_path):
    """A plugin spawned under another name says so; a joint with an effort and a passive transmission is an actuator,
    not passive; transmissions all passive leave the controllers' joints, said without "no <transmission>"; a
    controller naming no joint of the tree is refused naming the controllers; a plugin whose made-up name a joint
    of the file already has is named apart."""
    notes = read_mechanism_file(SDF_FIVE_BAR, output="link_4")[1].notes
    assert any("its <child_model> 'closed_loop_demo_model' read as this model spawned so" in note for note in notes)

    def transmission(joint: str, interface: str) -> str:
        return (f'<transmission name="{joint}_{interface}"><joint name="{joint}"><hardwareInterface>'
                f'hardware_interface/{interface}</hardwareInterface></joint></transmission>')

    path = tmp_path / "fivebar_linkage.urdf"
    path.write_text(FIVE_BAR.read_text().replace("</robot>", transmission("Chain1_1", "EffortJointInterface")
                                                 + transmission("Chain1_1", "PassiveJointInterface")
                                                 + transmission("Chain2_1", "EffortJointInterface") + "</robot>"))
    notes = read_mechanism_file(path, output="Chain1_dummy")[1].notes
    assert not any("passive" in note for note in notes), notes
    path.write_text(FIVE_BAR.read_text().replace("</robot>", transmission("Chain1_2", "PassiveJointInterface")
                                                 + "</robot>"))
    notes = read_mechanism_file(path, output="Chain1_dummy")[1].notes
    assert any(note.startswith("actuators: the joints the file's joint controller plugins drive, Chain1_1, Chain2_1 "
                               "(no <transmission> drives a joint)") for note in notes), notes
    path.write_text(FIVE_BAR.read_text().replace("<joint_name>Chain1_1</joint_name>",
                                                 "<joint_name>Chain1_9</joint_name>"))
    with pytest.raises(ImportError_, match="its joint controller plugins name joint.s. Chain1_9, not in the tree"):
        load(path, output="Chain1_dummy")
    clash = tmp_path / "model.sdf"
    clash.write_text(SDF_FIVE_BAR.read_text().replace("name='joint_A'", "name='link_2_to_dummy_link'"))
    assert indices(clash, output="link_4") == pytest.approx(indices(SDF_FIVE_BAR, output="link_4"), abs=1e-12)
    notes = read_mechanism_file(clash, output="link_4")[1].notes
    assert any("joints link_2_to_dummy_link_2:" in note for note in notes), notes


def test_a_passive_transmission_drives_nothing_in_screwkits_own_convention_too():
    """The bundled five-bar with a third transmission, its interface PassiveJointInterface, on a distal joint: two
    actuators, as before, where it read three."""
    text = (Path(__file__).resolve().parents[1] / "robots" / "five_bar.urdf").read_text()
    passive = ('<transmission name="chain_1_joint_c_transmission"><type>transmission_interface/SimpleTransmission'
               '</type><joint name="chain_1_joint_c"><hardwareInterface>hardware_interface/PassiveJointInterface'
               '</hardwareInterface></joint></transmission>')
    plain = load_text(text)
    assert load_text(text.replace("</robot>", passive + "</robot>")).actuator_names == plain.actuator_names


def test_a_urdf_that_pinocchio_cannot_read_is_refused_in_one_line_naming_the_element(tmp_path):
    """urdfdom says what is wrong on standard error (four lines), then Pinocchio that the file holds no valid URDF
    model: the one line now carries urdfdom's first complaint (a limit that is no number), and nothing else is
    written. An axis that is no three numbers is named before urdfdom reads the file (the joint and the element)."""
    text = FIVE_BAR.read_text()
    limit = text.index("lower=", text.index('name="Chain1_2"'))
    path = tmp_path / "fivebar_linkage.urdf"
    path.write_text(text[:limit] + 'lower="1zz' + text[limit + len('lower="'):])
    one_line_error(screwkit("analyze", path, "--output", "Chain1_dummy"),
                   "Pinocchio cannot read the tree: joint [Chain1_2]: lower value (1zz-3.14) is not a valid float")
    axis = text.index("<axis", text.index('name="Chain1_2"'))
    path.write_text(text[:axis] + '<axis xyz="1 0zzz 0"/>' + text[text.index("/>", axis) + 2:])
    one_line_error(screwkit("analyze", path, "--output", "Chain1_dummy"),
                   f"{path}: <joint name='Chain1_2'>: <axis xyz='1 0zzz 0'>: expected three finite numbers, each")


def test_a_negative_effort_or_velocity_reads_as_no_limit(tmp_path):
    """Gazebo's and SDFormat's -1 (no limit), which a published PhoneBot URDF writes on its joints: Pinocchio refused
    the file ("Some components of min_effort are greater than max_effort", naming no joint); the indices use neither,
    and the file reads as it does with its own efforts and velocities."""
    import re

    text = FIVE_BAR.read_text()
    assert 'effort="' in text
    path = tmp_path / "fivebar_linkage.urdf"
    path.write_text(re.sub(r'(effort|velocity)="[^"]*"', r'\1="-1"', text))
    expected = indices(FIVE_BAR)
    found = indices(path)
    assert found.keys() == expected.keys()
    for key in expected:
        assert found[key] == pytest.approx(expected[key], abs=1e-12), key


def test_a_xacro_file_given_as_a_urdf_is_refused_naming_xacro(tmp_path):
    """A ROS Delta's package ships its xacro source as ``delta_robot.urdf``: it was refused with Pinocchio's complaint
    about a mass that is an expression (``${mass_base}``), leaving the user to guess; a xacro whose expressions
    happen to parse would be read as another robot. Refused now, naming xacro and how to expand it."""
    text = FIVE_BAR.read_text().replace("<robot", '<robot xmlns:xacro="http://www.ros.org/wiki/xacro"', 1)
    path = tmp_path / "fivebar_linkage.urdf"
    path.write_text(text)  # the namespace alone (xacro's output keeps it): a URDF, read
    assert screwkit("analyze", path, "--output", "Chain1_dummy").returncode == 0
    meshed = text.replace('<link name="world"/>', '<link name="world"><visual><geometry><mesh filename="$(find '
                          'fivebar)/a.stl"/></geometry></visual></link>', 1)  # nor a $(find ...) in a mesh's name
    assert meshed != text
    path.write_text(meshed)
    assert screwkit("analyze", path, "--output", "Chain1_dummy").returncode == 0
    link = text.index("<link")
    path.write_text(text[:link] + '<xacro:property name="mass_base" value="1.0"/>' + text[link:])
    one_line_error(screwkit("analyze", path, "--output", "Chain1_dummy"), "a xacro file (it holds '<xacro:')",
                   "xacro fivebar_linkage.urdf -o robot.urdf")


def test_the_published_four_axis_delta_names_its_wrist_and_opens_with_it_held(tmp_path):
    """LevinTamir's 4-DOF Delta: three R-S-S legs, each ending on a ball written as three hinges on the tool holder
    (the body its planning chain moves), and a wrist, the driven hinge Chain4_1 that turns the tool on the holder,
    with a passive telescopic shaft from the base to the tool. Each rod's closure ends on its own hinge, so no joint
    had two closures and the tool0 frame was taken as the platform: refused as a closed-loop transmission. The three
    balls' closures now meet on the holder, the platform; the wrist, moving inside the shaft's loop, is refused
    naming --lock Chain4_1, which opens it with the rod lines' indices, also turned, in mm and km, and
    relabelled."""
    path = PUBLISHED / "ros2_closed_loop_ws" / "4dof_delta.urdf"
    one_line_error(screwkit("analyze", path), "actuated joint 'Chain4_1' moves inside a loop of leg",
                   "it turns a body on the platform (a wrist after the parallel part): --lock Chain4_1 holds it")
    notes = read_mechanism_file(path, lock=("Chain4_1",))[1].notes
    assert any(note.startswith("platform inferred: body 'tool_holder', where 4 closures meet") for note in notes)
    expected = delta_textbook(path)
    for variant, (rewrite, unit) in DELTA_VARIANTS.items():
        written = tmp_path / variant.replace(" ", "_").replace(",", "") / "4dof_delta.urdf"
        written.parent.mkdir()
        written.write_text(rewrite(path.read_text()))
        itis, lmti = delta_indices(written, unit, lock=("Chain4_1",))
        assert sorted(itis) == ["Chain1_1", "Chain2_1", "Chain3_1"], variant
        for name, value in itis.items():
            assert value == pytest.approx(expected[name], abs=1e-9), (variant, name)
        assert lmti == pytest.approx(min(expected[f"oti{k}"] for k in (1, 2, 3)), abs=1e-9), variant


@pytest.mark.parametrize("name, body, output", [("spherical_eye", "platform", "platform"),
                                                ("spherical_eye_ee", "moving_plate", "ee_link")])
def test_three_hinges_meeting_in_a_spherical_mechanism_are_no_ball_that_moves_its_platform(name, body, output):
    """A 3-RRR spherical mechanism (``tests/data/spherical_eye``, written for this test: every axis through one
    centre, its loops closed by Gazebo fixed joints between the halves of legs 2 and 3): the three hinges of leg 1's
    path and a closed leg's are no ball (driven, or links that carry more than the next hinge), and the body named
    ``platform`` (or the frame ``ee_link``) stays the output, as before balls were counted."""
    report = read_mechanism_file(PUBLISHED.parents[1] / "spherical_eye" / f"{name}.urdf")[1]
    assert (report.platform_body, report.output) == (body, f"frame {output!r} on body {body!r}")


def test_a_urdf_is_read_with_no_standard_error_to_hold():
    """A process whose standard error is closed (a daemon, ``2>&-``) reads a URDF of another tool as before."""
    code = ("import os; os.close(2); from screwkit.io.loader import load; "
            f"print(load({str(FIVE_BAR)!r}, output='Chain1_dummy').dof)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.stdout.strip() == "2", done.stdout
