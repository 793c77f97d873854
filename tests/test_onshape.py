"""URDFs as onshape-to-robot exports them: loops closed by ``closing_<name>_1`` / ``_2`` frame pairs, no robot.yaml.

The files are written here the way the exporter writes them (a dummy link per closing frame on a fixed joint
``closing_<name>_<k>_frame``, the two frames of a pair turned against each other as CAD mate connectors are,
revolute joints with ``<limit effort velocity/>`` and no bounds, an ``effector`` frame link, inertias), and
checked against the textbook pressure angles of the five-bar (independent closed forms).
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from test_io import HOME, assert_textbook, assert_three_leg_five_bar, poses_near_home, text
from test_lower_mobility import DISTAL, FIVE_BAR_BASE, PROXIMAL, five_bar_elbows, five_bar_expected

from helpers import screwkit
from screwkit.io import ImportError_, read_closed_tree, read_mechanism_file
from screwkit.io.loader import load
from screwkit.studies.poses import indices_at_poses

TOLERANCE = 1e-9
INERTIAL = ('<inertial><origin xyz="0 0 0" rpy="0 0 0"/><mass value="1e-9"/>'
            '<inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial>')


def onshape_urdf(links: list[tuple[str, str, str, tuple, float, tuple]], frames: list[tuple[str, str, tuple, tuple]]):
    """A URDF as onshape-to-robot writes it: ``links`` (name, joint, kind, xyz, yaw, parent), ``frames``
    (name, parent link, xyz, rpy) as dummy links on fixed joints ``<name>_frame``."""
    out = ['<robot name="onshape">', f'<link name="base">{INERTIAL}</link>']
    for name, joint, kind, xyz, yaw, parent in links:
        limit = ('<limit effort="1" velocity="20"/>' if kind == "revolute"
                 else '<limit effort="1" velocity="20" lower="-1" upper="1"/>')
        axis = "0 0 1" if kind == "revolute" else "1 0 0"
        out.append(f'<link name="{name}">{INERTIAL}</link>')
        out.append(f'<joint name="{joint}" type="{kind}"><origin xyz="{text(xyz)}" rpy="0 -0 {yaw!r}"/>'
                   f'<parent link="{parent}"/><child link="{name}"/><axis xyz="{axis}"/>'
                   f'{limit}<joint_properties friction="0.0"/></joint>')
    for name, parent, xyz, rpy in frames:
        out.append(f'<link name="{name}">{INERTIAL}</link>')
        out.append(f'<joint name="{name}_frame" type="fixed"><origin xyz="{text(xyz)}" rpy="{text(rpy)}"/>'
                   f'<parent link="{parent}"/><child link="{name}"/><axis xyz="0 0 0"/></joint>')
    return "\n".join(out + ["</robot>"]) + "\n"


MOVED = [(1e-3, 0.7, (0.2, -0.1, 0.05)), (1e3, -2.1, (-40.0, 25.0, 3.0))]
"""(scale, turn about the normal, shift) of the five-bar's world: millimetres-like and kilometres-like copies."""


def five_bar_links(legs: int, names, transform=(1.0, 0.0, (0.0, 0.0, 0.0)), order=None) -> list:
    """The five-bar's legs as ``onshape_urdf`` links: leg i's proximal link ``names[0](i)`` on motor ``names[1](i)``
    at its base, its distal link ``names[2](i)`` on the passive joint ``names[3](i)``; the world scaled, turned about
    the normal and shifted by ``transform``; the legs written in ``order`` (default 0, 1, ...)."""
    scale, turn, shift = transform
    rotation = np.array([[np.cos(turn), -np.sin(turn)], [np.sin(turn), np.cos(turn)]])
    elbows = five_bar_elbows(HOME)
    links = []
    for i in (range(legs) if order is None else order):
        base, elbow = FIVE_BAR_BASE[i], elbows[i]
        first = float(np.arctan2(*(elbow - base)[::-1]))
        second = float(np.arctan2(*(HOME - elbow)[::-1]))
        at = scale * rotation @ base + np.array(shift[:2])
        links.append((names[0](i), names[1](i), "revolute", (*at, shift[2]), first + turn, "base"))
        links.append((names[2](i), names[3](i), "revolute", (scale * PROXIMAL, 0.0, 0.0), second - first,
                      names[0](i)))
    return links


def moved_points(points, transform):
    """Points of the five-bar's plane in the world of ``transform`` (as :func:`five_bar_links` moves it)."""
    scale, turn, shift = transform
    rotation = np.array([[np.cos(turn), -np.sin(turn)], [np.sin(turn), np.cos(turn)]])
    return scale * np.asarray(points) @ rotation.T + np.array(shift[:2])


def five_bar_onshape(legs: int = 3, transform=(1.0, 0.0, (0.0, 0.0, 0.0)), order=None, motor=None) -> str:
    """The five-bar of tests/test_io.py: legs 2.. close on leg 1's distal link by ``closing_loop<i>`` pairs; moved
    by ``transform``, its legs written in ``order``, its motors named ``motor(i)`` (default motor<i+1>)."""
    motor = motor or (lambda i: f"motor{i + 1}")
    names = (lambda i: f"branch1_{i + 1}", motor, lambda i: f"branch2_{i + 1}", lambda i: f"passive{i + 1}")
    links, frames = five_bar_links(legs, names, transform, order), []
    distal = (transform[0] * DISTAL, 0.0, 0.0)
    for i in range(1, legs):
        frames.append((f"closing_loop{i + 1}_1", f"branch2_{i + 1}", distal, (0.0, 0.0, 0.0)))
        frames.append((f"closing_loop{i + 1}_2", "branch2_1", distal, (np.pi, 0.0, np.pi / 2)))
    frames.append(("effector", "branch2_1", distal, (np.pi, 0.0, 0.0)))
    return onshape_urdf(links, frames)


def assert_moved_textbook(mechanism, transform, motor_leg, tolerance=TOLERANCE):
    """The textbook pressure angles at points near HOME, the mechanism moved by ``transform``: the ITI of each
    actuator follows its leg (``motor_leg``: the leg of a motor's joint name), the LMTI and F_O1 agree, and the worst
    single fault is the leg the textbook names."""
    points = poses_near_home()
    result = indices_at_poses(mechanism, moved_points(points, transform), detail=True)
    legs = [motor_leg(name.split(":")[-1]) for name in mechanism.actuator_names]
    for k, point in enumerate(points):
        expected = five_bar_expected(point)
        np.testing.assert_allclose(result.iti_actuators[k], expected["iti_actuators"][legs], atol=tolerance)
        np.testing.assert_allclose([result.lmti[k], result.f_o[1][k]], [expected["lmti"], expected["f_o1"]],
                                   atol=tolerance)
        kept = [(0, 1), (0, 2), (1, 2)][int(np.argmin(expected["oti_submechanisms"]))]
        failed = {0, 1, 2}.difference(kept).pop()
        assert [legs[a] for a in np.atleast_1d(result.worst_fault_indices[1][k])] == [failed]


def test_an_onshape_five_bar_opens_as_written_with_the_textbook_pressure_angles(tmp_path):
    path = tmp_path / "robot.urdf"
    path.write_text(five_bar_onshape())
    converted, report = read_mechanism_file(path)
    assert report.file_format == "onshape-to-robot URDF (closing_ frame pairs)" and report.planar
    assert report.motors == ["motor1", "motor2", "motor3"]
    lines = "\n".join(report.lines())
    assert "closing_ pairs read as ball joints (a URDF does not say the mate's type): closing_loop2, closing_loop3" \
        in lines
    assert "actuators guessed from the branches leaving the base" in lines and "name_mot" in lines
    assert_three_leg_five_bar(path)


@pytest.mark.parametrize("transform", MOVED)
def test_an_onshape_five_bar_in_another_unit_and_frame_with_its_legs_reordered_and_renamed(tmp_path, transform):
    """Scaled by 1e-3 and 1e3, turned and shifted in the world, legs written in reverse and motors renamed: the same
    pressure angles, each following its own leg."""
    path = tmp_path / "robot.urdf"
    names = {0: "drive_c", 1: "drive_a", 2: "drive_b"}
    path.write_text(five_bar_onshape(transform=transform, order=(2, 1, 0), motor=names.get))
    mechanism = load(path)
    assert sorted(name.split(":")[-1] for name in mechanism.actuator_names) == ["drive_a", "drive_b", "drive_c"]
    assert_moved_textbook(mechanism, transform, {name: leg for leg, name in names.items()}.get)


def test_a_non_redundant_onshape_five_bar_has_the_textbook_indices_and_no_fault_tolerance(tmp_path):
    path = tmp_path / "robot.urdf"
    path.write_text(five_bar_onshape(legs=2))
    mechanism = load(path)
    assert mechanism.is_planar and mechanism.dof == 2 and len(mechanism.actuators) == 2
    points = poses_near_home()
    assert_textbook(indices_at_poses(mechanism, points, detail=True), points, legs=(0, 1))


def test_a_leg_with_one_prismatic_joint_is_guessed_driven_by_it(tmp_path):
    """A planar 3-RPR written by the exporter: each leg R (base) - P - R, the platform hanging from leg 1."""
    base = [(-0.4, 0.0), (0.4, 0.0), (0.0, 0.6)]
    attach = [(-0.1, -0.05), (0.1, -0.05), (0.0, 0.1)]  # on the platform, its frame at (0, 0.25)
    centre = np.array([0.0, 0.25])
    links, frames = [], []
    for i, (b, a) in enumerate(zip(base, attach)):
        target = centre + np.array(a)
        direction = target - np.array(b)
        yaw = float(np.arctan2(direction[1], direction[0]))
        links.append((f"leg{i + 1}", f"pivot{i + 1}", "revolute", (*b, 0.0), yaw, "base"))
        links.append((f"rod{i + 1}", f"slide{i + 1}", "prismatic", (0.0, 0.0, 0.0), 0.0, f"leg{i + 1}"))
        length = float(np.linalg.norm(direction))
        if i == 0:
            links.append(("platform", "wrist1", "revolute", (length, 0.0, 0.0), -yaw, "rod1"))
        else:
            frames.append((f"closing_wrist{i + 1}_1", f"rod{i + 1}", (length, 0.0, 0.0), (0.0, 0.0, 0.0)))
            frames.append((f"closing_wrist{i + 1}_2", "platform", (a[0] - attach[0][0], a[1] - attach[0][1], 0.0),
                           (0.0, 0.0, 0.3)))
    path = tmp_path / "rpr.urdf"
    path.write_text(onshape_urdf(links, frames))
    tree = read_closed_tree(path)
    assert tree.motors == ["slide1", "slide2", "slide3"]
    mechanism = load(path)
    assert mechanism.dof == 3 and mechanism.is_planar
    assert [name.split(":")[-1] for name in mechanism.actuator_names] == ["slide1", "slide2", "slide3"]


def test_a_closing_frame_without_its_other_half_is_refused_by_name(tmp_path):
    text_ = five_bar_onshape().replace("closing_loop3_2", "closing_loop3_b")
    path = tmp_path / "robot.urdf"
    path.write_text(text_)
    with pytest.raises(ImportError_, match=r"closing frame\(s\) closing_loop3_1 without their other half"):
        read_mechanism_file(path)


@pytest.mark.cli
def test_analyze_opens_an_onshape_export_on_the_command_line(tmp_path):
    path = tmp_path / "robot.urdf"
    path.write_text(five_bar_onshape())
    result = screwkit("analyze", path, "--json")
    assert result.returncode == 0, result.stderr
    report = json.loads(result.stdout)
    expected = five_bar_expected(HOME)
    assert report["lmti"] == pytest.approx(expected["lmti"], abs=TOLERANCE)
    assert any("actuators guessed" in line for line in report["converted"])


def test_the_task_coordinates_a_source_urdf_declares_are_kept(tmp_path):
    """<task_coordinates> in the exported URDF (screwkit's element) reaches the converted file: honoured when the
    motion allows it, refused by the element's name when it does not (a point output has no orientation)."""
    path = tmp_path / "robot.urdf"
    path.write_text(five_bar_onshape().replace("</robot>", '<task_coordinates names="y x"/></robot>'))
    converted, report = read_mechanism_file(path)
    assert '<task_coordinates names="y x"' in converted
    assert "task coordinates as the source declares them: y x" in report.notes
    mechanism = load(path)
    assert mechanism.task_coordinates == ("x", "y") and mechanism.task_source == "declared"
    path.write_text(five_bar_onshape().replace("</robot>", '<task_coordinates names="x phi"/></robot>'))
    with pytest.raises(ValueError, match="<task_coordinates>"):
        load(path)


def test_the_actuators_a_transmission_names_are_the_actuators(tmp_path):
    """A URDF's <transmission> elements say which joints are driven: the elbows here, not the base joints the reader
    would guess (it guessed them although the file said otherwise); a transmission naming no 1-DoF joint of the
    tree is refused naming it."""
    elbows = "".join(f'<transmission name="t{i}"><type>transmission_interface/SimpleTransmission</type>'
                     f'<joint name="passive{i}"><hardwareInterface>hardware_interface/EffortJointInterface'
                     f'</hardwareInterface></joint><actuator name="m{i}"/></transmission>' for i in (1, 2, 3))
    path = tmp_path / "robot.urdf"
    path.write_text(five_bar_onshape().replace("</robot>", elbows + "</robot>"))
    converted, report = read_mechanism_file(path)
    assert report.motors == ["passive1", "passive2", "passive3"]
    assert "actuators guessed" not in "\n".join(report.lines())
    mechanism = load(path)
    assert sorted(name.split(":")[-1] for name in mechanism.actuator_names) == ["passive1", "passive2", "passive3"]
    (tmp_path / "plain.urdf").write_text(five_bar_onshape())
    base_driven = load(tmp_path / "plain.urdf")
    elbow, base = (indices_at_poses(m, HOME, detail=True) for m in (mechanism, base_driven))
    assert not np.allclose(elbow.iti_actuators, base.iti_actuators)  # another set of actuators, other numbers
    path.write_text(five_bar_onshape().replace("</robot>", elbows.replace("passive3", "nowhere") + "</robot>"))
    with pytest.raises(ImportError_, match=r"<transmission> names joint\(s\) nowhere, not 1-DoF joints of the tree"):
        read_mechanism_file(path)
