"""Revolute joints read at canonical points: no index depends on where along its axis a file draws a revolute.

On a force the ITI's and OTI's points do not depend on the drawn point (``test_axis_points.py``). Three other
readings of joint points did: the working length and centroid, the characteristic points of wrenches with a pitch
(a serial arm's), and the representative of an actuation wrench defined modulo a constraint force (least norm about
the platform joint). The loader now moves each revolute to a point its geometry decides
(:mod:`screwkit.closure.canonical`). Checked here against constructions of the tests' own: the feet of common
perpendiculars from least squares, the chain's motion against Pinocchio's, and files rewritten with ElementTree.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from xml.etree import ElementTree

import numpy as np
import pytest
from test_axis_points import revolutes_drawn_elsewhere, revolutes_moved
from test_constraints import spherical_wrist_urdf
from test_invariance import SkewRSR

from helpers import assert_indices_close, in_unit, moved_in_the_world, random_reachable_poses, random_rotation
from screwkit.closure import solve
from screwkit.closure.canonical import (
    canonical_geometry,
    canonical_offsets,
    chain_extent,
    joint_lines_at_zero,
    offsets_along_axes,
)
from screwkit.closure.chain_kinematics import chain_forward_kinematics
from screwkit.io.loader import bundled_names, load, load_text
from screwkit.studies import indices_at_poses

ROBOTS = Path(__file__).resolve().parents[1] / "robots"


def xyz(vector) -> str:
    return " ".join(repr(float(value)) for value in vector)


def skew_rsr_urdf(design: SkewRSR) -> str:
    """A URDF of the skew 4-RSR of ``test_invariance`` (written here, not by screwkit): each leg a base revolute on
    its skew axis, a ball written as three revolutes at the elbow, and the platform revolute as the chain's loop;
    the legs' constraint forces miss the platform joints, so the representative of each actuation wrench depends on
    the platform joint's point."""
    links = ["base_link", "platform"]
    parts = ['<joint name="platform_joint" type="floating"><parent link="base_link"/><child link="platform"/>'
             f'<origin xyz="{xyz(design.height)}"/></joint>']
    for leg in range(4):
        names = [f"leg_{leg}_{part}" for part in ("crank", "ball_1", "ball_2", "rod")]
        links += names
        parts.append(f'<joint name="leg_{leg}_base" type="revolute"><parent link="base_link"/>'
                     f'<child link="{names[0]}"/><origin xyz="{xyz(design.base[leg])}"/>'
                     f'<axis xyz="{xyz(design.base_axis[leg])}"/>'
                     '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>')
        for step, axis in enumerate(np.eye(3)):
            origin = design.crank[leg] if step == 0 else np.zeros(3)
            parts.append(f'<joint name="leg_{leg}_ball_{step}" type="continuous"><parent link="{names[step]}"/>'
                         f'<child link="{names[step + 1]}"/><origin xyz="{xyz(origin)}"/>'
                         f'<axis xyz="{xyz(axis)}"/></joint>')
        parts.append(f'<loop name="leg_{leg}_hinge" type="revolute" chain="leg_{leg}">'
                     f'<predecessor link="{names[3]}"><origin xyz="{xyz(-design.link[leg])}"/></predecessor>'
                     f'<successor link="platform"><origin xyz="{xyz(design.platform_point[leg])}"/></successor>'
                     f'<axis xyz="{xyz(design.platform_axis[leg])}"/></loop>')
        parts.append(f'<transmission name="leg_{leg}_drive"><type>transmission_interface/SimpleTransmission</type>'
                     f'<joint name="leg_{leg}_base"><hardwareInterface>hardware_interface/EffortJointInterface'
                     f'</hardwareInterface></joint><actuator name="leg_{leg}_motor"/></transmission>')
    body = "".join(f'<link name="{link}"></link>' for link in links) + "".join(parts)
    return f'<?xml version="1.0"?><robot name="skew_4rsr">{body}</robot>'


@pytest.fixture(scope="module")
def skew_file(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("skew") / "skew_4rsr.urdf"
    path.write_text(skew_rsr_urdf(SkewRSR(np.random.default_rng(3))))
    return path


def foot_of_perpendicular(point, axis, other):
    """The point of the line (``point``, ``axis``) nearest to ``other``, by least squares."""
    along = np.linalg.lstsq(axis[:, None], other - point, rcond=None)[0][0]
    return point + along * axis


def meeting_point(point, axis, other_point, other_axis):
    """The point where two lines meet, by least squares on ``point + s axis = other_point + t other_axis``."""
    (along, _), *_ = np.linalg.lstsq(np.column_stack([axis, -other_axis]), other_point - point, rcond=None)
    return point + along * axis


@pytest.mark.parametrize("name", ("skew_4rsr", "coop_arms", "delta_4", "rss_hexapod_8"))
def test_a_file_whose_revolutes_are_drawn_elsewhere_gives_the_same_indices(name, skew_file, tmp_path):
    """Every revolute's origin moved along its axis in the file (each by its own amount, up to a tenth of the
    mechanism's size, a ball's three revolutes apart), read and analysed at random reachable poses: every index of
    the file as written, the representative-dependent LMTI and F_Oj of the skew 4-RSR and the pitched wrenches of the
    cooperating arms included."""
    source = skew_file if name == "skew_4rsr" else ROBOTS / f"{name}.urdf"
    mechanism = load(source)
    rng = np.random.default_rng(sum(map(ord, name)))
    poses = random_reachable_poses(mechanism, rng, 30)
    reference = indices_at_poses(mechanism, poses, detail=True)
    for attempt in range(2):
        moved = tmp_path / f"{name}_{attempt}.urdf"
        moved.write_text(revolutes_drawn_elsewhere(source.read_text(), rng, 0.1 * mechanism.length_scale))
        assert_indices_close(reference, indices_at_poses(load(moved), poses, detail=True), 1e-9)


@pytest.mark.parametrize("redrawn", (False, True))
def test_the_skew_legs_revolutes_sit_at_the_feet_from_the_ball(skew_file, tmp_path, redrawn):
    """Each leg's base and platform revolutes: the foot of the perpendicular from the ball's centre (its three
    revolutes meet there), as the design draws them and with every revolute drawn elsewhere on its axis."""
    if redrawn:
        moved = tmp_path / "redrawn.urdf"
        moved.write_text(revolutes_drawn_elsewhere(skew_file.read_text(), np.random.default_rng(2), 0.3))
        skew_file = moved
    mechanism = load(skew_file)
    design = SkewRSR(np.random.default_rng(3))
    for leg, chain in enumerate(mechanism.chains):
        axes, points = joint_lines_at_zero(chain.geometry)
        elbow = design.base[leg] + design.crank[leg]
        np.testing.assert_allclose(points[1:4], np.broadcast_to(elbow, (3, 3)), atol=1e-12)
        np.testing.assert_allclose(points[0], foot_of_perpendicular(design.base[leg], design.base_axis[leg], elbow),
                                   atol=1e-12)
        platform = design.height + design.platform_point[leg]
        np.testing.assert_allclose(points[4], foot_of_perpendicular(platform, design.platform_axis[leg], elbow),
                                   atol=1e-12)


def test_the_cooperating_arms_revolutes_sit_where_their_axes_meet_or_pass_nearest():
    """The UR5 arms of ``coop_arms``: shoulder pan and lift meet (both there), consecutive wrist axes meet (wrist 2
    between its two meeting points), and the elbow, parallel to both its neighbours, at the mean of the feet of the
    perpendiculars from the shoulder's and the first wrist's meeting points."""
    for chain in load("coop_arms").chains:
        axes, points = joint_lines_at_zero(chain.geometry)
        pan, lift, elbow, wrist_1, wrist_2, wrist_3 = range(6)
        shoulder = meeting_point(points[pan], axes[pan], points[lift], axes[lift])
        first = meeting_point(points[wrist_1], axes[wrist_1], points[wrist_2], axes[wrist_2])
        second = meeting_point(points[wrist_2], axes[wrist_2], points[wrist_3], axes[wrist_3])
        for joint, expected in ((pan, shoulder), (lift, shoulder), (wrist_1, first),
                                (wrist_2, 0.5 * (first + second)), (wrist_3, second)):
            np.testing.assert_allclose(points[joint], expected, atol=1e-12)
        between = [foot_of_perpendicular(points[elbow], axes[elbow], meeting) for meeting in (shoulder, first)]
        np.testing.assert_allclose(points[elbow], np.mean(between, axis=0), atol=1e-12)
        assert np.linalg.norm(between[0] - between[1]) > 0.05  # the mean is a choice, and is tested as one


WRIST_MEETINGS = {"first": {"wrist_1_joint": 0.093}, "second": {"wrist_2_joint": 0.09465},
                  "both": {"wrist_1_joint": 0.093, "wrist_2_joint": 0.09465}}


@pytest.mark.parametrize("moved", WRIST_MEETINGS)
def test_an_arm_whose_wrist_frames_sit_where_the_next_axis_meets_reads_as_bundled(moved, tmp_path):
    """Denavit and Hartenberg draw a frame where its axis meets the next one. The UR5 arms of ``coop_arms`` with the
    first wrist joint drawn where its axis meets the second's (0.093 m along it, the offset the file gives the
    second), the second where its axis meets the third's (0.09465 m), or both: the same points and indices as the
    file as bundled. The second wrist axis meets both its neighbours', at two points: a tie, whose mean it takes
    however the file draws it (before the meetings were ranked, an OTI moved by up to 0.17)."""
    distances = {f"{side}_{joint}": distance for side in ("left", "right")
                 for joint, distance in WRIST_MEETINGS[moved].items()}
    text = (ROBOTS / "coop_arms.urdf").read_text()
    redrawn = tmp_path / "coop_arms_dh.urdf"
    redrawn.write_text(revolutes_moved(text, distances))
    mechanism, other = load("coop_arms"), load(redrawn)
    for chain, other_chain in zip(mechanism.chains, other.chains):
        np.testing.assert_allclose(joint_lines_at_zero(other_chain.geometry)[1], joint_lines_at_zero(chain.geometry)[1],
                                   rtol=0, atol=1e-12)
    poses = random_reachable_poses(mechanism, np.random.default_rng(11), 30)
    assert_indices_close(indices_at_poses(mechanism, poses, detail=True), indices_at_poses(other, poses, detail=True),
                         1e-9)


def test_a_universal_joint_drawn_apart_keeps_its_centre_and_the_crank_its_foot(tmp_path):
    """``rss_hexapod_8`` with each leg's first universal-joint revolute drawn 5 cm along its axis away from the
    second: its axis still meets the second's at the joint's centre at a right angle, and the crank's far away (1.18
    m) at a shallow one. The right angle ranks first, so the universal joint's revolutes stay at its centre, the
    crank at the foot of the perpendicular from it, and the length scale is the bundled one (1.55 instead of 1.40
    before the meetings were ranked)."""
    distances = {f"leg_{leg}_joint_u1": 0.05 * (-1) ** leg for leg in range(1, 9)}
    redrawn = tmp_path / "rss_u_apart.urdf"
    redrawn.write_text(revolutes_moved((ROBOTS / "rss_hexapod_8.urdf").read_text(), distances))
    mechanism, other = load("rss_hexapod_8"), load(redrawn)
    assert other.length_scale == pytest.approx(mechanism.length_scale, rel=1e-12)
    for chain, other_chain in zip(mechanism.chains, other.chains):
        axes, points = joint_lines_at_zero(other_chain.geometry)
        np.testing.assert_allclose(points, joint_lines_at_zero(chain.geometry)[1], rtol=0, atol=1e-12)
        crank, first, second = range(3)
        centre = meeting_point(points[first], axes[first], points[second], axes[second])
        np.testing.assert_allclose(points[[first, second]], [centre, centre], atol=1e-12)
        np.testing.assert_allclose(points[crank], foot_of_perpendicular(points[crank], axes[crank], centre),
                                   atol=1e-12)


def canonical_however_drawn(axes, on_axes, seed: int, declared: int = 0) -> np.ndarray:
    """The canonical points of a chain of revolutes (unit ``axes``, one point of each axis ``on_axes``), found from six
    drawings (the given points, then each moved along its axis by up to 2 either way), which must all agree; the last
    ``declared`` are a loop joint's DoFs, drawn at their centre."""
    rng, found = np.random.default_rng(seed), []
    for draw in range(6):
        points = on_axes + (rng.uniform(-2.0, 2.0, len(axes)) if draw else np.zeros(len(axes)))[:, None] * axes
        if declared:
            points[-declared:] = on_axes[-declared:]
        offsets = offsets_along_axes((False,) * len(axes), axes, points, declared=declared)
        found.append(points + offsets[:, None] * axes)
    for other in found[1:]:
        np.testing.assert_allclose(other, found[0], atol=1e-12)
    return found[0]


def unit_rows(rows) -> np.ndarray:
    rows = np.asarray(rows, dtype=float)
    return rows / np.linalg.norm(rows, axis=1, keepdims=True)


def test_meetings_are_ranked_by_the_axes_through_them_then_by_their_angle():
    """A chain crank - universal - ball, drawn anywhere along its axes: the crank's axis meets the universal joint's
    first axis 5 m away at a shallow angle (squared sine 1/26), and the universal joint's second axis meets the
    ball's first frame axis at a right angle, at neither centre. However it is drawn, the ball's revolutes sit at its
    centre (three axes pass there), the universal joint's at its own (a right angle beats the shallow crossing and
    ties with the one the ball took), the crank at the foot of the perpendicular from that centre."""
    universal, ball = np.zeros(3), np.array([1.0, 0.0, 1.0])
    crank_axis = np.array([0.0, 1.0, 5.0]) / np.sqrt(26.0)  # through (0, 0, -5) on the universal joint's first axis
    axes = np.array([crank_axis, [0, 0, 1], [1, 0, 0], [0, 0, 1], [1, 0, 0], [0, 1, 0]], dtype=float)
    on_axes = np.array([[0.0, 1.0, 0.0], universal, universal, ball, ball, ball])
    expected = np.array([foot_of_perpendicular(on_axes[0], crank_axis, universal), universal, universal, ball, ball,
                         ball])
    np.testing.assert_allclose(canonical_however_drawn(axes, on_axes, seed=4), expected, atol=1e-12)


def test_a_ball_whose_axes_meet_at_unequal_angles_stays_one_point():
    """A universal joint, then a ball written as three revolutes whose pairs meet at different angles (squared sines
    0.5 and 0.8), the universal joint's second axis meeting the ball's first elsewhere at a right angle: the ball's
    pairs are one joint at one point whatever their angles, so its revolutes sit at its centre and the universal
    joint's at its own."""
    universal, ball = np.zeros(3), np.array([1.0, 0.0, 1.0])
    axes = unit_rows([[0, 0, 1], [1, 0, 0], [0, 0, 1], [1, 0, 1], [np.sqrt(0.2), np.sqrt(0.8), 0]])
    found = canonical_however_drawn(axes, np.array([universal, universal, ball, ball, ball]), seed=8)
    np.testing.assert_allclose(found, [universal, universal, ball, ball, ball], atol=1e-12)


def test_a_meeting_more_axes_pass_through_comes_before_a_clearer_one():
    """A ball whose second and third axes meet at a shallow angle (squared sine 0.05), the third meeting the next
    revolute's elsewhere at a right angle: three axes pass through the ball's centre, two through the other meeting,
    so the third revolute stays in the ball and the next one takes the foot of the perpendicular from its centre."""
    ball = np.zeros(3)
    third = np.array([np.sqrt(0.05), 0.0, np.sqrt(0.95)])
    after_point = 0.7 * third  # on the third axis, where the next revolute's axis crosses it
    after_axis = np.cross(third, [0.0, 1.0, 0.0])
    axes = unit_rows([[1, 0, 0], [0, 0, 1], third, after_axis])
    on_axes = np.array([ball, ball, ball, after_point + 0.4 * after_axis / np.linalg.norm(after_axis)])
    found = canonical_however_drawn(axes, on_axes, seed=9)
    np.testing.assert_allclose(found[:3], [ball, ball, ball], atol=1e-12)
    np.testing.assert_allclose(found[3], foot_of_perpendicular(on_axes[3], axes[3], ball), atol=1e-12)


@pytest.mark.parametrize("unrelated", (1.0, 0.9999))
def test_an_axis_met_by_both_neighbours_at_nearly_equal_angles_takes_the_mean(unrelated):
    """A wrist axis (z) meeting the axis before it at squared sine 0.99994 and the one after at 0.99987, within the
    tie of 1e-4 (as axes written to a few decimals give): the mean of its two meeting points, whatever the angle of
    an unrelated pair earlier in the chain (squared sine 1 or 0.9999)."""
    first, second, base = np.array([0.0, 0.0, 0.2]), np.array([0.0, 0.0, 0.5]), np.array([0.5, 0.0, -1.0])
    axes = np.array([[np.sqrt(unrelated), np.sqrt(1.0 - unrelated), 0.0],  # meets the next one at base
                     [0.0, 1.0, 0.0],  # through base, skew to the next one
                     [np.sqrt(0.99994), 0.0, np.sqrt(1.0 - 0.99994)],  # meets the wrist axis at first
                     [0.0, 0.0, 1.0],  # the wrist axis
                     [0.0, np.sqrt(0.99987), np.sqrt(1.0 - 0.99987)]])  # meets the wrist axis at second
    found = canonical_however_drawn(axes, np.array([base, base, first, first, second]), seed=10)
    np.testing.assert_allclose(found[3], 0.5 * (first + second), atol=1e-12)
    np.testing.assert_allclose(found[[0, 1, 2, 4]], [base, base, first, second], atol=1e-12)


def test_a_loop_balls_frame_axes_meet_nothing():
    """An R-U-S leg whose spherical loop joint's first frame axis lies along the rod, through the universal joint's
    centre (as ``rss_hexapod_8`` draws it): that axis meets the universal joint's second at a right angle, at a
    point three axes pass through, as many as through the ball's centre. A loop joint's axes are only its frame's,
    so its DoFs sit at its centre before any meeting is ranked, and the universal joint's revolutes at theirs."""
    universal, ball = np.zeros(3), np.array([0.0, 0.6, 0.8])
    rod = ball / np.linalg.norm(ball)
    axes = np.array([[0.0, 0.6, 0.8 + 0.5], [0, 0, 1], [1, 0, 0], rod, [1, 0, 0], np.cross(rod, [1, 0, 0])])
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    on_axes = np.array([[0.3, 0.0, 0.0], universal, universal, ball, ball, ball])
    expected = np.array([foot_of_perpendicular(on_axes[0], axes[0], universal), universal, universal, ball, ball,
                         ball])
    np.testing.assert_allclose(canonical_however_drawn(axes, on_axes, seed=6, declared=3), expected, atol=1e-12)


@pytest.mark.parametrize("scale", (1e-3, 1.0, 1e3))
@pytest.mark.parametrize("gap, meets", ((2e-5, False), (5e-6, True)))
def test_whether_two_axes_meet_does_not_depend_on_where_another_joint_is_drawn(gap, meets, scale):
    """Three revolutes at right angles: the first two axes pass ``gap`` apart (of a chain 1 long), the last two meet.
    Two axes meet within 1e-5 of the chain's size; that size is the lines' own, so drawing the first joint far along
    its axis (up to 100 chain lengths) decides nothing: 2e-5 apart they do not meet and the middle revolute sits where
    it meets the last, 5e-6 apart they meet and it takes the mean of its two meetings; in any unit."""
    axes = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    on_axes = scale * np.array([[0.0, 0.0, 0.0], [0.0, gap, 0.0], [1.0, gap, 0.0]])
    middle = scale * np.array([0.5 if meets else 1.0, gap, 0.0])
    for along in (0.0, 3.0, -10.0, 100.0):
        for moved in (0, 2):
            points = on_axes.copy()
            points[moved] += scale * along * axes[moved]
            found = points + offsets_along_axes((False,) * 3, axes, points)[:, None] * axes
            np.testing.assert_allclose(found, [on_axes[0], middle, on_axes[2]], atol=1e-12 * scale,
                                       err_msg=f"joint {moved} drawn {along} along its axis")


def test_a_chains_extent_is_its_lines_own():
    """:func:`chain_extent` of random chains (revolutes at random angles, some parallel, a slide, a ball's pairs) is
    the same however each revolute is drawn along its axis and in any world frame (a bounding box along the world's
    axes was not), and scales with the chain; two axes at a shallow angle
    do not stretch it to where their common perpendicular's feet lie; a chain whose axes all pass through one point
    has no extent of its lines and is measured as drawn."""
    rng = np.random.default_rng(17)
    for _ in range(200):
        count = int(rng.integers(2, 8))
        axes = unit_rows(rng.normal(size=(count, 3)))
        if count > 3:
            axes[2] = axes[1]  # a parallel pair
        on_axes = rng.normal(size=(count, 3))
        prismatic = (False, False) + tuple(bool(flag) for flag in rng.random(count - 2) < 0.2)  # two revolutes or more
        extent = chain_extent(prismatic, axes, on_axes)
        redrawn = on_axes + rng.uniform(-50.0, 50.0, count)[:, None] * axes * ~np.array(prismatic)[:, None]
        assert chain_extent(prismatic, axes, redrawn) == pytest.approx(extent, rel=1e-9)
        for factor in (1e-3, 1e3):
            assert chain_extent(prismatic, axes, factor * on_axes) == pytest.approx(factor * extent, rel=1e-12)
        turn, shift = random_rotation(rng), rng.uniform(-5.0, 5.0, 3)  # another world frame
        assert chain_extent(prismatic, axes @ turn.T, on_axes @ turn.T + shift) == pytest.approx(extent, rel=1e-9)
    shallow = np.radians(6.3)  # axes 0 and 2 at a shallow angle, 1.4 apart: their feet lie 9 along the axes
    axes = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [np.sin(shallow), 0.0, np.cos(shallow)]])
    # the feet of the clear pairs: the origin (axes 0 and 1) and (1, 1e-5, 0), (1, 1, 0) (axes 1 and 2): sqrt(2)
    assert chain_extent((False,) * 3, axes, np.array([[0.0, 0, 0], [0, 1e-5, 0], [1, 1, 0]])) == pytest.approx(
        np.sqrt(2.0))
    axes = unit_rows(rng.normal(size=(4, 3)))
    drawn = 0.1 * axes  # every axis through the origin, each drawn at 0.1 along it
    largest = max(np.linalg.norm(a - b) for a in drawn for b in drawn)  # the drawn points' diameter
    assert chain_extent((False,) * 4, axes, drawn) == pytest.approx(largest, rel=1e-12)


def every_chain(skew_path):
    for name in bundled_names():
        yield from ((name, chain) for chain in load(name).chains)
    yield from (("skew_4rsr", chain) for chain in load(skew_path).chains)


def test_a_canonical_chain_is_its_own_canonical_drawing(skew_file):
    """Read again, a chain drawn at its canonical points stays there (the points depend on the lines alone)."""
    for name, chain in every_chain(skew_file):
        np.testing.assert_allclose(canonical_offsets(chain.geometry), 0.0, atol=1e-12, err_msg=name)


def test_the_canonical_chain_moves_as_the_drawn_one(skew_file):
    """The rewritten placements: at random joint values, the same axes and loop frames, and each joint's point
    moved along its own axis by a constant (the forward kinematics of the chain as drawn, by :func:`_drawn`)."""
    rng = np.random.default_rng(8)
    for name, chain in every_chain(skew_file):
        drawn = _drawn(chain.geometry, rng)
        canonical = canonical_geometry(drawn)
        offsets = canonical_offsets(drawn)
        values = rng.uniform(-np.pi, np.pi, (50, chain.n_joints))
        before = chain_forward_kinematics(drawn, values, compiled=False)
        after = chain_forward_kinematics(canonical, values, compiled=False)
        for field in ("axes", "leg_rotation", "end_rotation", "end_translation"):
            np.testing.assert_allclose(getattr(after, field), getattr(before, field), atol=1e-12, err_msg=name)
        np.testing.assert_allclose(after.points, before.points + offsets[:, None] * before.axes, atol=1e-12,
                                   err_msg=name)
        loop_point = before.leg_translation + offsets[-1] * before.axes[..., -1, :] * (chain.loop_type == "revolute")
        np.testing.assert_allclose(after.leg_translation, loop_point, atol=1e-12, err_msg=name)


def _drawn(geometry, rng):
    """The chain with every tree revolute drawn elsewhere on its axis (placements after it compensated, by hand)."""
    translations = np.array(geometry.joint_translations, dtype=float)
    leg = np.array(geometry.leg_loop_translation, dtype=float)
    for joint in range(geometry.n_tree_joints):
        if geometry.joint_prismatic[joint]:
            continue
        shift = rng.uniform(-0.2, 0.2) * geometry.joint_axes[joint]
        translations[joint] += geometry.joint_rotations[joint] @ shift
        if joint + 1 < geometry.n_tree_joints:
            translations[joint + 1] -= shift
        else:
            leg -= shift
    return replace(geometry, joint_translations=translations, leg_loop_translation=leg)


@pytest.mark.parametrize("radius", [0.1, 0.37])
def test_a_spherical_chain_keeps_its_drawn_points_but_its_platform_joint_which_goes_to_the_centre(radius):
    """Every axis of a spherical wrist's leg passes through its centre, where the rule would put every joint (and the
    working length to zero): its legs keep the points the file draws, on each axis at the wrist's radius, but for the
    platform joint, at the centre: there the actuation wrench is the couple normal to the two passive axes, so the
    agile eye's ITI is the triple product of its axes, |u . (v x w)| / |v x w|, at every pose and every radius."""
    mechanism = load_text(spherical_wrist_urdf(radius=radius), "wrist.urdf")
    centre = np.array([0.0, 0.0, 0.3])
    for chain in mechanism.chains:
        axes, points = joint_lines_at_zero(chain.geometry)
        np.testing.assert_allclose(points[:-1], centre + radius * axes[:-1], atol=1e-12)
        np.testing.assert_allclose(points[-1], centre, atol=1e-12)
        np.testing.assert_allclose(canonical_offsets(chain.geometry)[:-1], 0.0, atol=0.0)
    poses = mechanism.home_pose + np.deg2rad([[0.0, 0.0, 0.0], [10.0, -5.0, 15.0], [-20.0, 10.0, -25.0]])
    result, solution = indices_at_poses(mechanism, poses, detail=True), solve(mechanism, poses)
    for (chain, joint), iti in zip(mechanism.actuator_positions(), result.iti_actuators.T):
        axes = solution.joint_axes[chain]
        normal = np.cross(axes[:, joint + 1], axes[:, joint + 2])
        expected = np.abs(np.sum(axes[:, joint] * normal, axis=1)) / np.linalg.norm(normal, axis=1)
        np.testing.assert_allclose(iti, expected, atol=1e-12)
    np.testing.assert_allclose(result.iti_actuators[0], 1.0, atol=1e-12)  # home: each motor along its couple


def test_nearly_parallel_axes_in_one_plane_do_not_meet_far_away(tmp_path):
    """The UR5 elbows tilted by 2e-6 rad in the plane of their parallel neighbours: the lines meet some 1e5 m away,
    which is no joint of the arm; the points stay on the arm and every pose of the untilted file still closes."""
    root = ElementTree.fromstring((ROBOTS / "coop_arms.urdf").read_text())
    for joint in root.iter("joint"):
        if joint.get("name").endswith("elbow_joint") and joint.get("type"):  # not a transmission's <joint>
            assert joint.find("axis").get("xyz").split() == ["0", "1", "0"]
            joint.find("axis").set("xyz", f"0 {float(np.cos(2e-6))!r} {float(np.sin(2e-6))!r}")
    tilted = tmp_path / "tilted.urdf"
    tilted.write_text(ElementTree.tostring(root, encoding="unicode"))
    mechanism, other = load("coop_arms"), load(tilted)
    reach = max(np.linalg.norm(joint_lines_at_zero(chain.geometry)[1], axis=1).max() for chain in other.chains)
    assert reach < 1.5 * mechanism.length_scale
    poses = random_reachable_poses(mechanism, np.random.default_rng(5), 20)
    assert indices_at_poses(other, poses).reachable.all()


@pytest.mark.parametrize("name", ("skew_4rsr", "coop_arms"))
@pytest.mark.parametrize("change", ("x1e-3", "x1e3", "world"))
def test_a_redrawn_file_scaled_or_moved_in_the_world_gives_the_same_indices(name, change, skew_file, tmp_path):
    """The file with its revolutes drawn elsewhere on their axes, then its lengths times 1e-3 or 1e3 (poses scaled
    with them) or the whole mechanism in another world frame: the indices of the file as written."""
    source = skew_file if name == "skew_4rsr" else ROBOTS / f"{name}.urdf"
    mechanism = load(source)
    rng = np.random.default_rng(sum(map(ord, name + change)))
    poses = random_reachable_poses(mechanism, rng, 20)
    factor = {"x1e-3": 1e-3, "x1e3": 1e3, "world": 1.0}[change]
    text = source.read_text()
    if change == "world":
        text = moved_in_the_world(text, rng.uniform(-2.0, 2.0, 3), rng.uniform(-np.pi, np.pi, 3))
        assert "world_to_base" in text
    text = revolutes_drawn_elsewhere(text, rng, 0.2 * mechanism.length_scale)
    if change != "world":
        text = in_unit(text, "m", factor)
    changed = tmp_path / f"{name}_{change}.urdf"
    changed.write_text(text)
    other = load(changed)
    scaled = poses * np.where(mechanism.angular, 1.0, factor)
    assert_indices_close(indices_at_poses(mechanism, poses, detail=True), indices_at_poses(other, scaled, detail=True),
                         1e-9)
