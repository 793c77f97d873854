"""The indices do not depend on where along its axis a revolute joint is drawn.

A file may put a revolute joint's origin anywhere on its axis (a CAD export at the middle of a bearing, a Delta's
elbow off its parallelogram's midline): the mechanism is the same. On a force, the characteristic points of the
ITI, the OTI and the CTI are taken where its axis comes nearest to the joint's axis (``docs/theory.md``, "The
characteristic points"). Here revolutes' drawn points are moved along their axes, in the screws (a different amount
in every configuration) and in the files, and every index must stay; and the points are checked against an
independent construction: the common perpendicular of the two lines from a least-squares solve, the power
coefficient from the public algebra.
"""

from __future__ import annotations

from pathlib import Path
from xml.etree import ElementTree

import numpy as np
import pytest
from test_invariance import skew_rsr
from test_lower_mobility import rpy_matrix

from helpers import assert_indices_close, bundled_chain_screws, random_reachable_poses
from screwkit.indices.analysis import analyze
from screwkit.indices.stages import CONSTRAINTS_COMPILED_FROM
from screwkit.io.loader import load
from screwkit.screw import algebra as screws
from screwkit.screw.chain_screws import ChainScrews
from screwkit.studies import indices_at_poses

THRESHOLD = 1e-6
COVERED = ("planar_5rrr", "planar_4rpr", "ups_hexapod_8", "ups_stewart_6", "rss_hexapod_8", "delta_4", "prs_3_ups",
           "schoenflies_5")
"""Bundled mechanisms whose every revolute may be drawn anywhere on its axis in their screws (``schoenflies_5`` since
the ITI's point of an actuator followed by a slide is where the force crosses the next joint that turns, not the
slide's drawn point). The other is the exception ``docs/theory.md`` names: wrenches with a pitch and a force
parallel to the joint after it. The skew 4-RSR below is not covered either: its actuation wrenches are defined modulo
a constraint force whose moment about the platform joint changes with the joint's drawn place, and so does their
representative.
Read from a file, ``coop_arms`` and the skew 4-RSR are covered too: the loader draws every revolute at a canonical
point (``test_canonical_points.py``)."""


def moved_along_axes(chains, chain: int, joint: int, rng, scale: float):
    """The chains with joint ``joint`` of chain ``chain`` drawn elsewhere on its axis, by up to half of ``scale``
    either way, a different amount in each configuration."""
    current = chains[chain]
    axis = current.twists[..., joint, :3]
    shift = rng.uniform(-0.5, 0.5, axis.shape[:-1] + (1,)) * scale
    points = current.points.copy()
    points[..., joint, :] += shift * axis / np.linalg.norm(axis, axis=-1, keepdims=True)
    moved = list(chains)
    moved[chain] = ChainScrews(current.twists, points, current.actuated, current.name, current.joint_names)
    return moved


def revolutes(chains):
    """(chain, joint) of every revolute joint (a twist with a rotation)."""
    return [(c, j) for c, chain in enumerate(chains) for j in range(chain.n_joints)
            if np.all(np.linalg.norm(chain.twists[..., j, :3], axis=-1) > 0.5)]


def size(chains) -> float:
    points = np.concatenate([chain.points.reshape(-1, 3) for chain in chains])
    return float(np.max(np.ptp(points, axis=0)))


@pytest.mark.parametrize("name", COVERED)
def test_every_index_is_the_same_wherever_a_revolute_is_drawn_along_its_axis(name):
    """One joint at a time, so that the joints of a universal or ball joint written as revolutes come apart too
    (each then a line of its own); ITIs, OTIs, LMTI, F_Oj, F_IOj and the CTI to 1e-12."""
    chains = bundled_chain_screws(name, 40)[0]
    rng = np.random.default_rng(sum(map(ord, name)))
    reference = analyze(chains, threshold=THRESHOLD)
    for chain, joint in revolutes(chains):
        moved = analyze(moved_along_axes(chains, chain, joint, rng, size(chains)), threshold=THRESHOLD)
        assert_indices_close(reference, moved, 1e-12)


def test_the_compiled_constraint_kernel_takes_the_same_points():
    """A chunk large enough for the compiled CTI (the Delta's R-U-U legs hold constraint couples)."""
    chains = bundled_chain_screws("delta_4", CONSTRAINTS_COMPILED_FROM + 40)[0]
    rng = np.random.default_rng(4)
    reference = analyze(chains, threshold=THRESHOLD)
    assert np.all(np.isfinite(reference.cti))
    for chain, joint in revolutes(chains)[:5]:
        moved = analyze(moved_along_axes(chains, chain, joint, rng, size(chains)), threshold=THRESHOLD)
        assert_indices_close(reference, moved, 1e-12)


def numbers(text: str) -> np.ndarray:
    return np.array([float(value) for value in text.split()])


def written(values) -> str:
    return " ".join(repr(float(value)) for value in values)


def origins_in(root, link: str):
    """Every ``<origin>`` expressed in ``link``'s frame: its child joints' and the loops' ends on it."""
    for joint in root.iter("joint"):
        parent = joint.find("parent")
        if parent is not None and parent.get("link") == link:
            yield joint.find("origin") if joint.find("origin") is not None else ElementTree.SubElement(joint, "origin")
    for loop in root.iter("loop"):
        for end in ("predecessor", "successor"):
            element = loop.find(end)
            if element is not None and element.get("link") == link:
                yield element.find("origin")


def revolutes_drawn_elsewhere(text: str, rng, span: float) -> str:
    """The URDF with every tree revolute's origin moved along its own axis (by up to ``span`` either way, each its
    own amount) and the origins in its child link's frame moved back, so that every body stays where it was, and
    every revolute loop joint's two ends moved along its axis together: the same mechanism, drawn otherwise (written
    here with ElementTree, not with screwkit's reader)."""
    root = ElementTree.fromstring(text)
    for loop in root.iter("loop"):
        if loop.get("type") != "revolute":
            continue
        axis = numbers(loop.find("axis").get("xyz"))
        shift = rng.uniform(-span, span) * axis / np.linalg.norm(axis)
        for end in ("predecessor", "successor"):  # both frames of the joint, which coincide as drawn
            origin = loop.find(end).find("origin")
            rotation = rpy_matrix(*numbers(origin.get("rpy", "0 0 0")))
            origin.set("xyz", written(numbers(origin.get("xyz", "0 0 0")) + rotation @ shift))
    for joint in root.iter("joint"):
        if joint.get("type") in ("revolute", "continuous"):
            _move_along_axis(root, joint, rng.uniform(-span, span))
    return ElementTree.tostring(root, encoding="unicode")


def revolutes_moved(text: str, distances: dict[str, float]) -> str:
    """The URDF with each named tree revolute's origin moved along its own axis by the given distance (signed along
    the axis as written), the origins in its child link's frame moved back: the same mechanism, drawn otherwise."""
    root = ElementTree.fromstring(text)
    joints = {joint.get("name"): joint for joint in root.findall("joint")}
    for name, distance in distances.items():
        _move_along_axis(root, joints[name], distance)
    return ElementTree.tostring(root, encoding="unicode")


def _move_along_axis(root, joint, distance: float) -> None:
    origin = joint.find("origin") if joint.find("origin") is not None else ElementTree.SubElement(joint, "origin")
    axis = numbers(joint.find("axis").get("xyz") if joint.find("axis") is not None else "1 0 0")  # URDF's default
    shift = distance * axis / np.linalg.norm(axis)
    rotation = rpy_matrix(*numbers(origin.get("rpy", "0 0 0")))
    origin.set("xyz", written(numbers(origin.get("xyz", "0 0 0")) + rotation @ shift))
    for inner in origins_in(root, joint.find("child").get("link")):
        inner.set("xyz", written(numbers(inner.get("xyz", "0 0 0")) - shift))


@pytest.mark.parametrize("name", ("delta_4", "rss_hexapod_8", "prs_3_ups", "ups_hexapod_8", "planar_5rrr",
                                  "schoenflies_5"))
def test_a_file_whose_revolutes_are_drawn_elsewhere_on_their_axes_gives_the_same_indices(name, tmp_path):
    """What a user meets: the bundled URDF with every revolute's origin moved along its axis (up to a tenth of the
    mechanism's size), read and analysed at random reachable poses, gives the indices of the file as bundled."""
    source = Path(__file__).resolve().parents[1] / "robots" / f"{name}.urdf"
    mechanism = load(source)
    rng = np.random.default_rng(sum(map(ord, name)))
    moved = tmp_path / f"{name}.urdf"
    moved.write_text(revolutes_drawn_elsewhere(source.read_text(), rng, 0.1 * mechanism.length_scale))
    assert moved.read_text() != source.read_text()
    poses = random_reachable_poses(mechanism, rng, 30)
    reference = indices_at_poses(mechanism, poses, detail=True)
    other = indices_at_poses(load(moved), poses, detail=True)
    assert_indices_close(reference, other, 1e-9)


def nearest_point(wrench, point, axis):
    """The point of the wrench's axis nearest to the line through ``point`` along ``axis``: least squares on the two
    lines' parameters (a construction of its own, not the package's formula)."""
    force = wrench[:3] / np.linalg.norm(wrench[:3])
    foot = np.cross(wrench[:3], wrench[3:]) / np.dot(wrench[:3], wrench[:3])
    (t, _), *_ = np.linalg.lstsq(np.column_stack([force, -axis]), point - foot, rcond=None)
    return foot + t * force


def test_the_points_are_where_each_force_crosses_its_joint_axis():
    """A 4-RSR with skew axes: the actuation wrenches are forces reciprocal to the S and to the platform's R, so
    they cross the R's axis; the ITI about the S's centre and the OTI about that crossing, from the public power
    coefficient, are the indices (the crossing is one: the lines meet to 1e-9 of the platform's size)."""
    chains = skew_rsr(count=10, seed=2)
    result = analyze(chains, threshold=THRESHOLD, keep_twists=True)
    length = size(chains)
    checked = 0
    for index in range(10):
        for s, members in enumerate(result.submechanisms):
            for position, k in enumerate(members):
                chain = chains[k]
                wrench = result.actuation_wrenches[index, k]
                assert abs(screws.pitch(wrench)) < 1e-9 * length
                axis = chain.twists[index, -1, :3]
                crossing = nearest_point(wrench, chain.points[index, -1], axis)
                offset = crossing - chain.points[index, -1]
                assert np.linalg.norm(np.cross(offset, axis)) < 1e-9 * length  # on the R's axis too
                expected = screws.power_coefficient(wrench, result.output_twists[index, s, position], crossing,
                                                    THRESHOLD)
                assert result.oti_actuators[index, s, position] == pytest.approx(float(expected), abs=1e-9)
                checked += 1
        for k, chain in enumerate(chains):
            wrench = result.actuation_wrenches[index, k]
            centre = screws.project_on_axis(wrench, chain.points[index, 1])  # the S's joints share its centre
            expected = screws.power_coefficient(wrench, chain.twists[index, 0], centre, THRESHOLD)
            assert result.iti_actuators[index, k] == pytest.approx(float(expected), abs=1e-9)
    assert checked


def test_the_drawn_point_is_kept_where_the_line_does_not_decide():
    """A prismatic joint (no axis), a ball's revolutes at one point, an axis parallel to the wrench and a wrench with
    a pitch (whose axis need not meet the joint's): the drawn point projected on the wrench axis."""
    force = np.array([0.0, 0.0, 1.0, 0.3, -0.2, 0.0])  # a force along z through (0.2, 0.3, .) (f x m)
    point = np.array([1.0, 0.3, 0.5])
    projected = screws.project_on_axis(force, point)
    for direction in ([0.0, 0.0, 0.0], [0.0, 0.0, 2.0]):
        np.testing.assert_allclose(screws.nearest_on_axis(force, point, direction), projected, atol=1e-15)
    crossing = screws.nearest_on_axis(force, point, [1.0, 0.0, 1.0])  # the line through point along x + z
    np.testing.assert_allclose(crossing, [0.2, 0.3, -0.3], atol=1e-12)  # (1, 0.3, 0.5) - 0.8 (1, 0, 1)
    screw = force + [0.0, 0.0, 0.0, 0.0, 0.0, 0.05]  # the same axis, pitch 0.05
    np.testing.assert_allclose(screws.nearest_on_axis(screw, point, [1.0, 0.0, 1.0]), projected, atol=1e-15)
    np.testing.assert_allclose(screws.nearest_on_axis(screw, point, [1.0, 0.0, 1.0], length=1e8), crossing,
                               atol=1e-12)  # a pitch of 5e-10 lengths: a force
    twists = np.array([[1.0, 0, 0, 0, 0, 0], [0, 1.0, 0, 0, 0, 0], [0, 0, 1.0, 0, 0, 0]])
    ball = np.zeros((3, 3))
    assert not np.any(screws.joint_lines(twists, ball, 1))
    apart = ball + [[0, 0, 0], [0, 0, 0], [0, 0, 1.0]]
    np.testing.assert_allclose(screws.joint_lines(twists, apart, -1), [0, 0, 1.0])  # on its own line
    prismatic = np.array([[0, 0, 0, 1.0, 0, 0]])
    assert not np.any(screws.joint_lines(prismatic, np.zeros((1, 3)), 0))


@pytest.mark.parametrize("noise", [0.0, 1e-17, 1.6e-11, 9e-11])
def test_a_couple_found_with_rounding_in_its_force_has_no_axis(noise):
    """A constraint couple found by a singular value decomposition carries a force of rounding (1.6e-11 of its
    moment for a U-P-U leg): its "axis" is then |m| / |f| away, and the moment about a point on it mistook the couple
    for a force of huge pitch (the numpy reference's CTI of the U-P-U platform 0.0301 against 0.0084). The drawn
    point is kept, and the power coefficient is the couple's |m . omega| / (|m| |omega|)."""
    rng = np.random.default_rng(3)
    moment = np.array([0.0282, 0.0, 0.9996])
    side = rng.normal(size=3)
    couple = np.concatenate([noise * side / np.linalg.norm(side), moment])  # |f| = noise |m| (|m| about 1)
    point, direction = np.array([0.3, -0.2, 1.1]), np.array([0.0, 1.0, 0.0])
    np.testing.assert_array_equal(screws.nearest_on_axis(couple, point, direction), point)
    twist = np.array([0.2699, -0.9276, 0.0005, 0.2479, 0.0721, -0.0082])
    expected = abs(moment @ twist[:3]) / np.linalg.norm(moment) / np.linalg.norm(twist[:3])
    found = screws.power_coefficient(couple, twist, screws.nearest_on_axis(couple, point, direction), THRESHOLD)
    assert abs(float(found) - expected) < 1e-9
    force = np.concatenate([[0.0, 0.0, 1e-6], moment])  # a force of pitch 1e6 lengths: not a couple, on its axis
    assert np.linalg.norm(screws.nearest_on_axis(force, point, direction) - point) > 1.0
