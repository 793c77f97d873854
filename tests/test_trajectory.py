"""Fault tolerance along a path: the indices at the samples are analyze's, the stretches each failure leaves below
the level agree with a dense sampling, a singular pose between two samples is located to the tolerance, and a
scaled mechanism gives the same stretches scaled; the path files and the command line."""

from __future__ import annotations

import json
from itertools import product

import numpy as np
import pytest

from helpers import assert_indices_close, bundled, in_unit, moved_in_the_world, one_line_error, screwkit
from screwkit.closure import actuator_values, solve
from screwkit.common.rotations import wrap_angle
from screwkit.common.tolerances import SINGULARITY_THRESHOLD
from screwkit.io.loader import bundled_path, load_text
from screwkit.studies import indices_at_pose, indices_at_poses
from screwkit.studies.actuator_paths import path_from_actuators, read_actuator_path
from screwkit.studies.branches import chain_joints, joint_steps, suspect_segments
from screwkit.studies.options import AnalysisOptions
from screwkit.studies.paths import (
    PathFileError,
    checked_tolerance,
    circle_path,
    line_path,
    path_from_poses,
    read_path,
    through_path,
)
from screwkit.studies.trajectory import failure_weights, trajectory

FIG_4 = np.array([0.0, 0.0, 0.0])
"""The centre of the paper's Fig. 4 (x = y = 0; phi swept there)."""
START, STOP = np.array([-0.3, -0.2, np.deg2rad(-45.0)]), np.array([0.3, 0.2, np.deg2rad(45.0)])
"""A straight path of the 5-RRR through the Fig. 4 pose, at its middle."""
LEVEL = 0.6


@pytest.fixture(scope="module")
def five_path():
    five = bundled("planar_5rrr")
    return five, trajectory(five, line_path(five, START, STOP, 41), level=LEVEL)


def test_the_indices_at_every_sample_are_those_of_analyze(five_path):
    five, result = five_path
    poses = result.path.poses
    np.testing.assert_allclose(poses[20], FIG_4, atol=1e-15)  # the Fig. 4 pose is a sample
    for i in range(poses.shape[0]):
        alone = indices_at_pose(five, poses[i])
        assert_indices_close(alone, result.indices.at(i), atol=1e-12,
                             fields=("iti", "iti_actuators", "oti_submechanisms", "lmti"))
        for j in (1, 2):
            np.testing.assert_allclose(result.indices.remaining_lmti[j][i], alone.remaining_lmti[j], atol=1e-12)
    assert result.margins["iti"].value == pytest.approx(np.min(result.indices.iti), abs=0)
    assert result.margins["f_o1"].value <= np.min(result.indices.f_o[1])


def _dense_lost(values: np.ndarray, s: np.ndarray, level: float) -> np.ndarray:
    """Stretches [start, stop] where ``values`` < level on a dense sampling, ends at the midpoints of a change."""
    below = ~(np.nan_to_num(values, nan=-1.0) >= level)
    change = np.flatnonzero(below[1:] != below[:-1])
    edges = np.concatenate([[s[0]], (s[change] + s[change + 1]) / 2, [s[-1]]])
    runs = np.column_stack([edges[:-1], edges[1:]])
    state = below[np.concatenate([[0], change + 1])]
    return runs[state]


def test_the_lost_stretches_agree_with_a_dense_sampling(five_path):
    """1,000,000 samples of the same path (the issue's brute force), batched: every stretch each failure leaves
    below the level, and every singular point, within the refinement's tolerance plus the dense step."""
    five, result = five_path
    dense_s = np.linspace(0.0, result.path.length, 1_000_001)
    dense = indices_at_poses(five, result.path.at(dense_s), detail=True)
    step = dense_s[1]
    lost_somewhere = 0
    for case in result.cases:
        failed = tuple(result.indices.actuators.index(name) for name in case.failed)
        column = result.indices.failed_sets(case.faults).index(failed)
        values = dense.remaining_lmti[case.faults][:, column]
        expected = _dense_lost(values, dense_s, LEVEL)
        assert case.lost.shape == expected.shape, (case.label, case.lost, expected)
        np.testing.assert_allclose(case.lost, expected, rtol=0, atol=result.tolerance + step, err_msg=case.label)
        lost_somewhere += len(case.lost) > 0
        assert case.minimum <= np.nanmin(values) + 1e-9
        assert abs(case.at - dense_s[np.nanargmin(values)]) <= result.tolerance + step or case.minimum < 1e-5
        for zero in case.singular_at:  # a singular point: the dense sampling is near zero there
            near = np.abs(dense_s - zero) <= result.tolerance + step
            assert np.nanmin(values[near]) < 1e-4, (case.label, zero)
        covered = np.concatenate([case.lost, case.controllable])
        assert np.sum(covered[:, 1] - covered[:, 0]) == pytest.approx(result.path.length, abs=1e-12)
    assert lost_somewhere >= 5  # the path is a test of something: failures lose control along it
    assert sum(bool(c.singular_at) for c in result.cases) >= 3


def test_a_singular_pose_between_two_samples_is_located_to_the_tolerance():
    """The 4-RPR at phi = 0, platform at (0, -0.9): the platform joints of legs 1 and 2 at y = -1, their lines
    the base edge y = -1, collinear, so the sets {1, 2, 3} and {1, 2, 4} left after a failure of leg 4 or 3 are
    singular there (Sec. 2: collinear lines give OTI = 0). A path from y = -0.5 to -0.95 in 7 samples has it
    between its samples 5 and 6 (y = -0.875 and -0.95), at arc length 0.4."""
    rpr = bundled("planar_4rpr")
    path = np.column_stack([np.zeros(7), np.linspace(-0.5, -0.95, 7), np.zeros(7)])
    assert not np.any(np.isclose(path[:, 1], -0.9))
    result = trajectory(rpr, path, tolerance=1e-7)
    singular = {case.failed: case.singular_at for case in result.cases}
    for leg in ("leg_3", "leg_4"):
        (found,) = singular[(f"{leg}:{leg}_joint_slider",)]
        assert abs(found - 0.4) <= 1e-7, found
        assert result.case(f"{leg}:{leg}_joint_slider").minimum < 1e-6
    for leg in ("leg_1", "leg_2"):
        assert singular[(f"{leg}:{leg}_joint_slider",)] == ()
    assert set(result.worst[1]) == {("leg_3:leg_3_joint_slider",), ("leg_4:leg_4_joint_slider",)}
    assert result.margins["f_o1"].sample is None and result.margins["f_o1"].value < 1e-6
    # the samples alone would have missed it: none is near zero
    assert np.min(result.indices.f_o[1]) > 0.02
    coarse = trajectory(rpr, path, tolerance=1e-3)  # the tolerance is what it says, not finer by chance
    assert abs(coarse.case("leg_3:leg_3_joint_slider").singular_at[0] - 0.4) <= 1e-3


CROSSING = np.sqrt(2) * 0.08
"""Arc length where the diagonal paths of :func:`_over_the_base_joint` put a platform joint on its base joint."""


def _over_the_base_joint(mechanism, platform_at_crossing, offset=0.0, samples=4):
    """A diagonal path (along x = y) whose platform passes through ``platform_at_crossing`` (x, y) at arc length
    :data:`CROSSING` (or ``offset`` m beside it, perpendicular), no sample on it."""
    side = offset / np.sqrt(2)
    centre = np.array([platform_at_crossing[0] + side, platform_at_crossing[1] - side, 0.0])
    return line_path(mechanism, centre - [0.08, 0.08, 0.0], centre + [0.08, 0.08, 0.0], samples)


@pytest.mark.parametrize("name, platform, chain, joint, limits", [
    ("planar_5rrr", (0.9, 0.0), "chain_1", "chain_1_joint_b", True),
    ("planar_4rpr", (-0.8, -0.9), "leg_1", "leg_1_joint_base", False)])
def test_a_branch_change_between_two_samples_is_reported_where_it_happens(name, platform, chain, joint, limits):
    """Closed form: at platform (0.9, 0, 0) the 5-RRR's platform joint d_1 = (1, 0) is on its base joint b_1 (equal
    arms: the chain folded). Along a line through it, the line from b_1 to d_1 turns by half a turn, and the elbow
    the closed form keeps "on the left" of that line jumps to the other side: the actuated joint jumps by 180 deg,
    which no smooth motion does. The 4-RPR's leg 1 likewise at platform (-0.8, -0.9, 0): its slider through zero
    length, the base joint turning by half a turn. 4 samples, none near; the change located to the tolerance."""
    mechanism = bundled(name)
    result = trajectory(mechanism, _over_the_base_joint(mechanism, platform), tolerance=1e-7,
                        analysis=AnalysisOptions(limits=limits))
    assert result.indices.reachable.all()
    (event,) = result.events
    assert event.kind == "branch" and event.samples == (1, 2)
    assert event.start - 1e-12 <= CROSSING <= event.stop + 1e-12 and event.stop - event.start <= 1e-7
    assert f"chain {chain!r} changes working mode: joint {joint!r} jumps" in event.reason
    number = [c.name for c in mechanism.chains].index(chain)
    position = mechanism.chains[number].joint_names.index(joint)
    before, after = solve(mechanism, result.path.at([event.start - 1e-6, event.stop + 1e-6]),
                          limits=limits).joint_values[number][:, position]
    jump = np.rad2deg(abs(wrap_angle(after - before)))
    assert jump == pytest.approx(180.0, abs=0.01)


@pytest.mark.parametrize("moved", [False, True])
def test_a_branch_change_at_a_sample_is_reported_as_between_samples(moved):
    """The 5-RRR from x = 0.6 to 1.0 m: its chain 1 changes working mode at x = 0.9 (platform joint on base joint),
    at 0.3 m. With 10 samples that is between two samples; with 9 it is a sample, where the closed form's joint
    values are not determined (the chain closes only to rounding there, or closes, as rounding has it in another
    world frame). The change is reported either way, located to the tolerance between the samples either side;
    it used to be dropped when the sample between did not close (the screen skips a step to a sample that does
    not close), so that the answer depended on the sampling and on the world frame."""
    text = bundled_path("planar_5rrr").read_text()
    if moved:
        text = moved_in_the_world(text, (0.3, -0.2, 0.5), (0.4, -0.3, 1.1))
    five = load_text(text, "planar_5rrr.urdf")
    start, stop = np.array([0.6, 0.0, 0.0]), np.array([1.0, 0.0, 0.0])
    for samples, between in ((10, (6, 7)), (9, (5, 7))):
        result = trajectory(five, line_path(five, start, stop, samples))
        (change,) = [event for event in result.events if event.kind == "branch"]
        assert "chain 'chain_1' changes working mode: joint 'chain_1_joint_b' jumps" in change.reason
        assert change.start - 2 * result.tolerance <= 0.3 <= change.stop + 2 * result.tolerance
        assert change.samples in (between, (6, 7))  # the sample on it closed (by rounding) or not
        assert all(event.stop - event.start <= result.tolerance for event in result.events)


def test_a_fast_but_smooth_turn_near_the_base_joint_is_no_branch_change(five_path):
    """The same 5-RRR path 0.03 m beside b_1: between samples 1 and 2 the actuated joint turns by most of half a
    turn (the screen suspects the segment), but smoothly: the bisection sees the step shrink, and nothing is
    reported; nor on the path through the Fig. 4 pose."""
    five = bundled("planar_5rrr")
    path = _over_the_base_joint(five, (0.9, 0.0), offset=0.03)
    values = solve(five, path.poses).joint_values[0][:, :2]
    steps = joint_steps(chain_joints(five)[0], values[:-1], values[1:])
    assert suspect_segments(steps, np.diff(path.arc_length)).tolist() == [False, True, False]
    assert abs(np.rad2deg(steps[1, 0])) > 90
    assert trajectory(five, path).events == ()
    assert five_path[1].events == ()
    assert set(five_path[1].working_modes) == {f"chain_{i}" for i in range(1, 6)}


@pytest.mark.parametrize("factor", [1000.0, 1e-3])
def test_a_scaled_mechanism_has_the_same_stretches_scaled(factor):
    """The 5-RRR with every length times 1000 (its file in mm read as m) or times 1e-3, with the path and the
    threshold scaled: the same stretches, singular points and margins, arc lengths times the factor (the
    default tolerance scales with it)."""
    five = bundled("planar_5rrr")
    large = load_text(in_unit(bundled_path("planar_5rrr").read_text(), "m", factor), "planar_5rrr_scaled.urdf")
    scale = np.array([factor, factor, 1.0])
    small = trajectory(five, line_path(five, START, STOP, 41), level=LEVEL)
    big = trajectory(large, line_path(large, START * scale, STOP * scale, 41), level=LEVEL,
                     analysis=AnalysisOptions(threshold=factor * SINGULARITY_THRESHOLD))
    assert big.tolerance == pytest.approx(factor * small.tolerance, rel=1e-12)
    assert big.path.length == pytest.approx(factor * small.path.length, rel=1e-12)
    for one, other in zip(small.cases, big.cases):
        assert one.failed == other.failed
        np.testing.assert_allclose(other.lost, factor * one.lost, rtol=0, atol=big.tolerance)
        np.testing.assert_allclose(other.singular_at, factor * np.array(one.singular_at), rtol=0,
                                   atol=big.tolerance)
    assert big.worst == small.worst
    for name, margin in small.margins.items():
        assert big.margins[name].value == pytest.approx(margin.value, abs=1e-9), name


def test_the_stretches_are_the_same_in_another_world_frame_and_with_the_legs_listed_otherwise(five_path):
    """The 5-RRR placed in another world frame (its task coordinates stay the base's), and its file with the
    chains listed in another order and renamed: every failure, found by the names of the failed actuators, loses
    control on the same stretches, singular at the same points; the same worst failures and margins."""
    from test_relabelling import listed_otherwise

    five, reference = five_path
    text = bundled_path("planar_5rrr").read_text()
    moved = load_text(moved_in_the_world(text, (0.4, -1.3, 0.7), (0.3, -0.5, 2.0)), "planar_5rrr_moved.urdf")
    listed, renamed = listed_otherwise(text, np.random.default_rng(4), rename=True)
    relabelled = load_text(listed, "planar_5rrr_listed_otherwise.urdf")
    assert relabelled.actuator_names != five.actuator_names

    def by_failed(result, names=None):
        names = names or {}

        def original(actuator):
            chain, _, joint = actuator.partition(":")
            return f"{names.get(chain, chain)}:{joint}"

        cases = {frozenset(map(original, case.failed)): case for case in result.cases}
        worst = {j: {frozenset(map(original, ties)) for ties in sets} for j, sets in result.worst.items()}
        return cases, worst

    expected, expected_worst = by_failed(reference)
    for mechanism, names in ((moved, None), (relabelled, renamed)):
        assert not mechanism.base_is_world or mechanism is relabelled
        result = trajectory(mechanism, line_path(mechanism, START, STOP, 41), level=LEVEL)
        cases, worst = by_failed(result, names)
        assert cases.keys() == expected.keys() and worst == expected_worst
        for failed, case in cases.items():
            np.testing.assert_allclose(case.lost, expected[failed].lost, rtol=0, atol=2 * reference.tolerance)
            np.testing.assert_allclose(case.singular_at, expected[failed].singular_at, rtol=0,
                                       atol=2 * reference.tolerance)
            assert case.minimum == pytest.approx(expected[failed].minimum, abs=1e-9)
        for name, margin in reference.margins.items():
            assert result.margins[name].value == pytest.approx(margin.value, abs=1e-9), name
            at = result.margins[name].arc_length
            assert at == pytest.approx(margin.arc_length, abs=2 * reference.tolerance), name


@pytest.mark.parametrize("name", ["planar_4rpr", "ups_hexapod_8"])
def test_a_margin_tied_along_the_path_is_at_its_first_sample_in_any_unit_and_world_frame(name):
    """An ITI of 1 all along (rounding apart) had its margin at sample 6 of the 4-RPR's path, at sample 0 with the
    file in another world frame (26 and 5 for the hexapod): where rounding fell. Now at the first sample of the
    ties, in metres, in millimetres and moved."""
    text = bundled_path(name).read_text()
    files = (bundled(name), load_text(in_unit(text, "mm", 1000.0, declare=True), f"{name}_mm.urdf"),
             load_text(moved_in_the_world(text, (1.0, 2.0, 0.0), (0.0, 0.0, 0.5)), f"{name}_moved.urdf"))
    margins = []
    for mechanism in files:
        start, stop = mechanism.home_pose.copy(), mechanism.home_pose.copy()
        start[:2] -= [0.2, 0.1] if mechanism.is_planar else [0.0, 0.0]
        stop[0] += 0.2 if mechanism.is_planar else 0.1
        stop[-1] += 0.3 if mechanism.is_planar else 0.5
        margins.append(trajectory(mechanism, line_path(mechanism, start, stop, 41)).margins)
    for column, margin in margins[0].items():
        for other in margins[1:]:
            assert other[column].value == pytest.approx(margin.value, abs=1e-9), column
            assert other[column].sample == margin.sample, column
    assert margins[0]["iti"].sample == 0 and margins[0]["iti"].value == pytest.approx(1.0, abs=1e-12)


def test_the_average_case_is_the_weighted_mean_over_the_failures(five_path):
    """F_Oj mean: the mean of the LMTI left over the sets of j failures; weighted by the probability of exactly
    that set failing given j failures, counted here over all 2^5 failure patterns."""
    five, _ = five_path
    path = line_path(five, START, STOP, 9)
    plain = trajectory(five, path, aggregate="mean")
    for j in (1, 2):
        np.testing.assert_allclose(plain.mean[j], plain.indices.remaining_lmti[j].mean(axis=1), atol=1e-15)
        assert np.all(plain.mean[j] >= plain.indices.f_o[j])
        assert plain.margins[f"f_o_mean{j}"].value == pytest.approx(np.min(plain.mean[j]), abs=0)
    p = np.array([0.1, 0.2, 0.05, 0.3, 0.5])
    weighted = trajectory(five, path, aggregate="mean", probabilities=p)
    for j in (1, 2):
        sets = plain.indices.failed_sets(j)
        chances = np.zeros(len(sets))
        for pattern in product((False, True), repeat=5):
            failed = tuple(i for i in range(5) if pattern[i])
            if len(failed) == j:
                chances[sets.index(failed)] += np.prod(np.where(pattern, p, 1 - p))
        np.testing.assert_allclose(failure_weights(5, j, p), chances / chances.sum(), rtol=1e-12)
        np.testing.assert_allclose(weighted.mean[j], plain.indices.remaining_lmti[j] @ (chances / chances.sum()),
                                   atol=1e-12)
    assert not np.allclose(weighted.mean[1], plain.mean[1])
    assert trajectory(five, path).mean == {}  # the worst case alone unless asked
    with pytest.raises(ValueError, match="failure probability in \\[0, 1\\] per actuator \\(5\\)"):
        failure_weights(5, 1, [0.1, 0.2])


def test_a_path_leaving_the_workspace_reports_where():
    """The 5-RRR's platform pushed along +y out of reach: one closure event, its start located to the tolerance
    (the last reachable arc length on a dense sampling), the chains that cannot close named; control is lost there
    for every failure."""
    five = bundled("planar_5rrr")
    path = path_from_poses(five, np.column_stack([np.zeros(16), np.linspace(0.0, 1.5, 16), np.zeros(16)]))
    result = trajectory(five, path)
    (event,) = result.events
    assert event.kind == "closure" and "misses closure" in event.reason and event.stop == pytest.approx(1.5)
    dense_s = np.linspace(0.0, 1.5, 300_001)
    reachable = indices_at_poses(five, path.at(dense_s)).reachable
    edge = dense_s[np.flatnonzero(~reachable)[0]]
    assert abs(event.start - edge) <= result.tolerance + dense_s[1]
    for case in result.cases:
        assert case.lost[-1, 1] == pytest.approx(1.5) and case.lost[-1, 0] <= event.start + result.tolerance


def test_a_path_entering_the_workspace_or_out_of_it_throughout_reports_where():
    """The same path run backwards (from out of reach into the workspace) has its closure event where the forward
    one has it, mirrored; a path out of reach throughout is one event over its whole length, with why. Both were
    reported as nothing: the stretches were taken from the reach series' values, whose NaN counts as true."""
    five = bundled("planar_5rrr")
    forward = path_from_poses(five, np.column_stack([np.zeros(16), np.linspace(0.0, 1.5, 16), np.zeros(16)]))
    backward = path_from_poses(five, forward.poses[::-1])
    (ahead,), (back,) = trajectory(five, forward).events, trajectory(five, backward).events
    assert back.kind == "closure" and "misses closure" in back.reason and back.start == 0.0
    assert back.stop == pytest.approx(1.5 - ahead.start, abs=2 * forward_tolerance(five))
    assert back.samples[0] == 0 and back.samples[1] == 15 - ahead.samples[0]
    away = path_from_poses(five, np.column_stack([np.linspace(100.0, 200.0, 5), np.zeros(5), np.zeros(5)]))
    result = trajectory(five, away)
    (event,) = result.events
    assert (event.start, event.stop, event.samples) == (0.0, pytest.approx(100.0), (0, 4))
    assert "is unreachable for mechanism 'planar_5rrr'" in event.reason and "(x=100, y=0" in event.reason
    for case in result.cases:
        assert case.lost.tolist() == [[0.0, pytest.approx(100.0)]] and case.first_loss == 0.0


@pytest.mark.parametrize("name, poses", [
    ("planar_5rrr", [(0.95, 0.0, 0.0), (1.2, 0.0, 0.0)]),  # out of reach from 0.148 m: a leg cannot close
    ("planar_4rpr", [(0.0, 0.0, 0.0), (-0.6, -0.7, 0.0), (0.0, 0.05, 0.0)]),  # a slider beyond its limit
])
def test_the_edge_of_an_unreachable_stretch_is_no_singular_point(name, poses):
    """Several failures' LMTI left is lowest where the path leaves the workspace (or a joint's limits), well above
    zero there (a dense sampling): none of them is singular there, and the worst failure is the one with the lowest
    minimum on the dense sampling. The side of such a minimum out of reach used to count as an infinite rise,
    which made every failure with its minimum at an edge 'singular' and the worst of the path."""
    mechanism = bundled(name)
    path = through_path(mechanism, np.array([(x, y, np.deg2rad(phi)) for x, y, phi in poses]), 21)
    result = trajectory(mechanism, path)
    edges = [edge for event in result.events for edge in (event.start, event.stop)]
    assert edges and all(event.kind in ("closure", "joint limit") for event in result.events)
    dense_s = np.linspace(0.0, path.length, 20_001)
    dense = indices_at_poses(mechanism, path.at(dense_s), detail=True)
    lowest, at_an_edge = {}, 0
    for case in result.cases:
        failed = tuple(result.indices.actuators.index(n) for n in case.failed)
        values = dense.remaining_lmti[case.faults][:, result.indices.failed_sets(case.faults).index(failed)]
        if np.nanmin(values) > 0.05:
            assert not case.singular_at, (case.label, case.singular_at, np.nanmin(values))
        at_an_edge += min(abs(case.at - edge) for edge in edges) <= 2 * result.tolerance
        if case.faults == 1:
            lowest[case.failed] = np.nanmin(values)
    assert at_an_edge >= 2
    assert result.worst[1] == (min(lowest, key=lowest.get),)


def test_a_stretch_out_of_reach_between_two_reachable_samples_found_by_the_searches_is_reported():
    """The 4-RPR on a straight path whose four samples are all reachable, while leg 1's slider passes its lower limit
    between the second and the third (0.245 m to 0.354 m, a dense sampling says). The minimum searches between those
    samples evaluate poses there; such a pose out of reach used to be dropped, leaving no event and every failure
    controllable across the stretch. It is now reported with the samples either side, its edges located to the
    tolerance, and it is lost for every failure, as on a path of 61 samples."""
    rpr = bundled("planar_4rpr")
    start, stop = np.array([-0.3793, -0.9035, 0.0]), np.array([-0.8035, -0.4793, 0.0])
    coarse = trajectory(rpr, line_path(rpr, start, stop, 4))
    assert np.asarray(coarse.indices.reachable).all()
    dense_s = np.linspace(0.0, coarse.path.length, 200_001)
    out = np.flatnonzero(~indices_at_poses(rpr, coarse.path.at(dense_s)).reachable)
    assert out.size and np.all(np.diff(out) == 1)  # one stretch
    (event,) = coarse.events
    assert event.kind == "joint limit" and "leg_1_joint_slider" in event.reason and event.samples == (1, 2)
    step = dense_s[1]
    assert abs(event.start - dense_s[out[0]]) <= coarse.tolerance + step
    assert abs(event.stop - dense_s[out[-1]]) <= coarse.tolerance + step
    fine = trajectory(rpr, line_path(rpr, start, stop, 61))
    (expected,) = fine.events
    assert (event.start, event.stop) == (pytest.approx(expected.start, abs=2 * coarse.tolerance),
                                         pytest.approx(expected.stop, abs=2 * coarse.tolerance))
    for case in coarse.cases:
        lost = case.lost
        assert np.any((lost[:, 0] <= event.start + coarse.tolerance) & (lost[:, 1] >= event.stop - coarse.tolerance))


def forward_tolerance(mechanism) -> float:
    """The default tolerance of a path's crossings for ``mechanism`` (m of arc length)."""
    from screwkit.studies.trajectory import RELATIVE_TOLERANCE

    return RELATIVE_TOLERANCE * mechanism.length_scale


def test_a_hexapod_path_runs_and_agrees_with_its_samples():
    hexapod = bundled("ups_hexapod_8")
    home = hexapod.home_pose
    stop = home + np.array([0.05, -0.03, 0.02, np.deg2rad(5.0), np.deg2rad(-3.0), np.deg2rad(20.0)])
    result = trajectory(hexapod, line_path(hexapod, home, stop, 40), aggregate="mean")
    assert len(result.cases) == 8 + 28 and set(result.worst) == {1, 2}
    direct = indices_at_poses(hexapod, result.path.poses)
    for j in (1, 2):
        np.testing.assert_allclose(result.indices.f_o[j], direct.f_o[j], rtol=0, atol=1e-12)
    for case in result.cases:
        covered = np.concatenate([case.lost, case.controllable])
        assert np.sum(covered[:, 1] - covered[:, 0]) == pytest.approx(result.path.length, abs=1e-12)
    dataset = result.to_dataset()
    assert dataset["lmti_left2"].shape == (40, 28) and "f_o_mean2" in dataset
    assert json.loads(dataset.attrs["summary"])["worst"] == {str(j): [list(t) for t in ties]
                                                              for j, ties in result.worst.items()}


def _netcdf_layout(path) -> dict:
    """Everything a netCDF-3 file holds, as scipy reads it: dimensions, global attributes, per variable its
    dimensions, type, attributes and values."""
    from scipy.io import netcdf_file

    with netcdf_file(path, "r", mmap=False) as handle:
        def attributes(owner):
            return {key: repr(value) for key, value in owner._attributes.items()}

        return {"dimensions": dict(handle.dimensions), "attributes": attributes(handle),
                "variables": {name: (variable.dimensions, variable.typecode(), attributes(variable),
                                     np.array(variable.data).tobytes()) for name, variable in handle.variables.items()}}


@pytest.mark.parametrize("name", ["planar_5rrr", "delta_4"])
def test_the_netcdf_written_without_xarray_is_the_file_xarray_writes(tmp_path, name):
    """``plain_dataset().write_netcdf`` (what --out writes, without importing xarray) gives, byte for byte in every
    variable and attribute, the file ``to_dataset().to_netcdf`` writes; xarray reads back the same dataset. A path
    with times, leaving the workspace (NaN indices, empty worst-fault names), with the mean (f_o_mean{j}); the
    Delta adds the CTI, integer and boolean variables."""
    import xarray as xr

    mechanism = bundled(name)
    start = mechanism.home_pose
    stop = start + (np.array([0.0, 1.5, 0.0]) if name == "planar_5rrr" else np.array([0.0, 0.0, -1.0]))
    poses = np.linspace(start, stop, 12)
    result = trajectory(mechanism, path_from_poses(mechanism, poses, np.linspace(0.0, 2.0, 12)), aggregate="mean")
    assert not np.all(result.indices.reachable) and np.any(result.indices.reachable)
    result.to_dataset().to_netcdf(tmp_path / "xarray.nc", engine="scipy")
    result.plain_dataset().write_netcdf(tmp_path / "plain.nc")
    assert _netcdf_layout(tmp_path / "plain.nc") == _netcdf_layout(tmp_path / "xarray.nc")
    with xr.open_dataset(tmp_path / "xarray.nc", engine="scipy") as expected, \
            xr.open_dataset(tmp_path / "plain.nc", engine="scipy") as found:
        xr.testing.assert_identical(found.load(), expected.load())
        assert {k: v.dtype for k, v in found.variables.items()} == {k: v.dtype for k, v in expected.variables.items()}
    xr.testing.assert_identical(result.plain_dataset().to_dataset(), result.to_dataset())


def test_the_command_writes_its_netcdf_without_importing_xarray(tmp_path):
    """The data written by --out .nc is the Python result's, and xarray, pandas and dask are never imported."""
    import subprocess
    import sys

    import xarray as xr

    five = bundled("planar_5rrr")
    done = subprocess.run([sys.executable, "-X", "importtime", "-m", "screwkit.cli", "trajectory", "planar_5rrr",
                           "--line", "-0.3", "-0.2", "-45", "0.3", "0.2", "45", "--samples", "9", "--quiet",
                           "--out", tmp_path / "t.nc"], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    imported = {line.rsplit("|", 1)[-1].strip() for line in done.stderr.splitlines() if line.startswith("import time")}
    assert not imported & {"xarray", "pandas", "dask", "dask.array"}, sorted(imported & {"xarray", "pandas", "dask"})
    result = trajectory(five, line_path(five, START, STOP, 9))
    result.to_dataset().to_netcdf(tmp_path / "expected.nc", engine="scipy")
    with xr.open_dataset(tmp_path / "expected.nc", engine="scipy") as expected, \
            xr.open_dataset(tmp_path / "t.nc", engine="scipy") as found:
        xr.testing.assert_allclose(found.load().drop_attrs(), expected.load().drop_attrs(), rtol=0, atol=1e-12)
        assert json.loads(found.attrs["summary"])["worst"] == json.loads(expected.attrs["summary"])["worst"]


def test_generated_paths():
    five = bundled("planar_5rrr")
    circle = circle_path(five, [0.1, 0.0, 0.3], 0.2, 9)
    np.testing.assert_allclose(circle.poses[0], circle.poses[-1], atol=1e-15)
    np.testing.assert_allclose(np.hypot(circle.poses[:, 0] - 0.1, circle.poses[:, 1]), 0.2, atol=1e-15)
    assert circle.length == pytest.approx(8 * 2 * 0.2 * np.sin(np.pi / 8), rel=1e-12)  # the inscribed octagon
    turn = line_path(five, [0, 0, 0], [0, 0, 1.0], 3)  # a pure rotation has a length: L per radian
    assert turn.length == pytest.approx(five.length_scale, rel=1e-12)
    with pytest.raises(ValueError, match="x-y plane; 'prs_3_ups' has task coordinates z, roll, pitch"):
        circle_path(bundled("prs_3_ups"), bundled("prs_3_ups").home_pose, 0.1, 10)
    with pytest.raises(ValueError, match="every pose of the path is the same"):
        path_from_poses(five, np.zeros((3, 3)))


def test_a_path_of_rounding_or_overflowing_length_is_refused():
    """A circle of two samples is a 'path' of 2.4e-17 m (sin 2 pi rounded); ends 1e308 m apart, an infinite arc
    length: both were run (the second with overflow warnings, 'UNREACHABLE from inf m to inf m')."""
    five = bundled("planar_5rrr")
    with pytest.raises(ValueError, match=r"every pose of the path is the same to rounding \(a length of 2.45e-17 m"):
        circle_path(five, five.home_pose, 0.1, 2)
    with np.errstate(all="raise"):  # refused without a warning of the arithmetic, as beyond the mechanism's reach
        for start, stop in (([0, 0, 0], [1e308, 0, 0]), ([-1e308, 0, 0], [1e308, 0, 0])):
            with pytest.raises(ValueError, match=r"Expected positions within 1e\+06 length scales \(1.09614e\+06 m\) "
                                                 r"of the home pose of mechanism 'planar_5rrr' in `poses` \(x\)"):
                line_path(five, start, stop, 201)
    assert line_path(five, [0.1, 0, 0], [0.1 + 1e-12, 0, 0], 2).length == pytest.approx(1e-12, rel=1e-3)


def test_the_tolerance_is_one_the_refinement_can_honour():
    """1e-15 m on a 1.87 m path is below the rounding of its arc length (a singular point was lost), 10 m above the
    path's length (false singular points); a path shorter than the default tolerance gets a thousandth of it."""
    five = bundled("planar_5rrr")
    path = line_path(five, START, STOP, 3)
    for tolerance, shown in ((1e-15, "1e-15"), (path.length, f"{path.length:g}"), (10.0, "10"), (np.nan, "nan")):
        with pytest.raises(ValueError, match=rf"Expected `tolerance` from 1.43e-14 m \(the rounding of the arc "
                                             rf"length\) to below the path's length, 1.86672 m, got {shown}.$"):
            trajectory(five, path, tolerance=tolerance)
    assert checked_tolerance(path, 1.43e-14) == 1.43e-14
    short = trajectory(five, line_path(five, [0, 0, 0], [1e-7, 0, 0], 3))
    assert short.tolerance == pytest.approx(1e-10, rel=1e-12)


BAD_FILES = {
    "missing.csv": (None, "missing.csv: no such file."),
    "columns.csv": ("x,y,theta\n0,0,0\n0.1,0,0\n", "no column 'phi'; a path of 'planar_5rrr' has columns x, y, phi"),
    "nan.csv": ("t,x,y,phi\n0,0,0,0\n1,0.1,nan,0\n", "line 3, column 'y': expected a finite number, got 'nan'."),
    "one.csv": ("x,y,phi\n0,0,0\n", "1 sample(s); a path needs at least 2."),
    "times.csv": ("t,x,y,phi\n0,0,0,0\n0,0.1,0,0\n", "Expected finite, increasing times along the path."),
    "path.txt": ("x,y,phi\n0,0,0\n", "a path file must end in .csv or .nc, got '.txt'."),
    "doubled.csv": ("x,y,phi,x\n-0.1,0,0,5\n0.1,0.05,10,6\n",
                    "column 'x' is in the header 2 times (columns 1, 4); give each column once."),
    "turns.csv": ("x,y,phi\n0,0,0\n0,0,40000\n",
                  "Expected angles of at most 36000 deg (100 turns) either way in column 'phi' (sample 1), got "
                  "40000 deg."),
    "still.csv": ("x,y,phi\n0.1,0,0\n0.10000000000000002,0,0\n", "every pose of the path is the same to rounding"),
    "huge.csv": ("x,y,phi\n0,0,0\n1e200,0,0\n", "Expected positions within 1e+06 length scales (1.09614e+06 m) of the "
                 "home pose of mechanism 'planar_5rrr' in the file (x, sample 1), got 1e+200 m."),
    "lengths.nc": ({"x": ("a", [0.0, 0.1, 0.2]), "y": ("b", [0.0, 0.01, 0.02, 0.03]), "phi": ("a", [0.0, 1.0, 2.0])},
                   "variables of different lengths ('x' 3, 'y' 4, 'phi' 3 samples); a path has one value of each"),
    "units.nc": ({"x": ("s", [0.0, 0.1]), "y": ("s", [0.0, 0.0], {"units": "furlong"}), "phi": ("s", [0.0, 1.0])},
                 "variable 'y' has units 'furlong'; expected a length unit (m, dm, cm, mm, um, km, in, ft), or no"),
    "grad.nc": ({"x": ("s", [0.0, 0.1]), "y": ("s", [0.0, 0.0]), "phi": ("s", [0.0, 1.0], {"units": "grad"})},
                "variable 'phi' has units 'grad'; expected deg or rad (an angle; or degrees, radians), or no units."),
}


def _write_path_file(folder, name: str, contents) -> None:
    """A path file of BAD_FILES: the text of a CSV file, or the variables of a netCDF file."""
    if isinstance(contents, dict):
        import xarray as xr

        xr.Dataset(contents).to_netcdf(folder / name, engine="scipy")
    elif contents is not None:
        (folder / name).write_text(contents)


@pytest.mark.parametrize("name", BAD_FILES)
def test_a_bad_path_file_is_one_line_naming_it(tmp_path, name):
    text, message = BAD_FILES[name]
    _write_path_file(tmp_path, name, text)
    with pytest.raises(PathFileError) as error:
        read_path(bundled("planar_5rrr"), tmp_path / name)
    assert str(error.value).startswith(str(tmp_path / name)) and message in str(error.value)
    assert "\n" not in str(error.value)


def test_a_path_file_reads_in_degrees_with_times(tmp_path):
    five = bundled("planar_5rrr")
    (tmp_path / "p.csv").write_text("t,x,y,phi,comment\n0,0,0,0,a\n2,0.1,0,90,b\n")
    path = read_path(five, tmp_path / "p.csv")
    np.testing.assert_allclose(path.poses, [[0, 0, 0], [0.1, 0, np.pi / 2]])
    np.testing.assert_allclose(path.times, [0, 2])
    np.testing.assert_allclose(path.time_at([path.length / 2]), [1.0])


def test_a_path_file_in_the_units_it_names_or_with_a_byte_order_mark_is_the_plain_csv(tmp_path):
    """A netCDF variable in radians was read as degrees, one in mm as metres; an Excel CSV's byte-order mark made
    its first column unknown."""
    import xarray as xr

    five = bundled("planar_5rrr")
    (tmp_path / "plain.csv").write_text("t,x,y,phi\n0,-0.1,0,0\n2,0.1,0.05,10\n")
    expected = read_path(five, tmp_path / "plain.csv")
    (tmp_path / "bom.csv").write_bytes(b"\xef\xbb\xbf" + (tmp_path / "plain.csv").read_bytes())
    for x, y, phi, t in ((("m", [-0.1, 0.1]), ("metres", [0.0, 0.05]), ("radians", [0.0, np.deg2rad(10)]), "s"),
                         (("mm", [-100.0, 100.0]), ("cm", [0.0, 5.0]), ("Degrees", [0.0, 10.0]), "seconds"),
                         (("", [-0.1, 0.1]), ("", [0.0, 0.05]), ("rad", [0.0, np.deg2rad(10)]), "")):
        variables = {name: ("s", values, {"units": unit} if unit else {}) for name, (unit, values) in
                     zip(("x", "y", "phi"), (x, y, phi))}
        xr.Dataset(variables, coords={"t": ("s", [0.0, 2.0], {"units": t} if t else {})}).to_netcdf(
            tmp_path / f"{x[0] or 'none'}.nc", engine="scipy")
        read = read_path(five, tmp_path / f"{x[0] or 'none'}.nc")
        np.testing.assert_allclose(read.poses, expected.poses, rtol=1e-15, atol=1e-17)
        np.testing.assert_array_equal(read.times, expected.times)
    np.testing.assert_array_equal(read_path(five, tmp_path / "bom.csv").poses, expected.poses)
    for name in ("mm.nc", "bom.csv"):
        done = screwkit("trajectory", "planar_5rrr", tmp_path / name, "--json", "--level", "0.99")
        assert done.returncode == 0, done.stderr
        assert json.loads(done.stdout)["length_m"] == pytest.approx(expected.length, rel=1e-12)


@pytest.mark.parametrize("name", ["missing.csv", "columns.csv", "nan.csv", "one.csv", "doubled.csv", "turns.csv",
                                  "still.csv", "huge.csv", "lengths.nc", "units.nc", "grad.nc"])
def test_the_command_refuses_a_bad_path_file_in_one_line(tmp_path, name):
    text, message = BAD_FILES[name]
    _write_path_file(tmp_path, name, text)
    one_line_error(screwkit("trajectory", "planar_5rrr", tmp_path / name, "--out", tmp_path / "out.nc"),
                   str(tmp_path / name), message)
    assert not (tmp_path / "out.nc").exists()
    if name == "lengths.nc":  # with --json, the same line as JSON on stdout
        done = screwkit("trajectory", "planar_5rrr", tmp_path / name, "--json")
        assert done.returncode == 1 and "Traceback" not in done.stderr, done.stderr
        assert message in json.loads(done.stdout)["error"]


LINE = ("--line", "-0.3", "-0.2", "-45", "0.3", "0.2", "45", "--samples", "41")


@pytest.mark.parametrize("arguments, message", [
    (("--circle", "home", "0.1", "--samples", "2"),
     "every pose of the path is the same to rounding (a length of 2.45e-17"),
    (("--line", "0", "0", "0", "1e308", "0", "0"), "home pose of mechanism 'planar_5rrr' in --line's second pose (x), "
                                                   "got 1e+308 m."),
    (("--line", "0", "0", "0", "nan", "0", "0"), "Expected finite values in --line's second pose, got nan for x."),
    (("--through", "0", "0", "0", "0.1", "0", "0", "0.1", "inf", "0"),
     "Expected finite values in --through's pose 3, got inf for y."),
    (("--circle", "0", "0", "nan", "0.1"), "Expected finite values in --circle's centre, got nan for phi."),
    (("--circle", "0", "0", "0"), "Expected --circle with the centre's 3 task coordinates (x (m), y (m), phi (deg)) "
                                  "then the radius (m), 4 numbers, got 3 (no radius): 0 0 0."),
    (("--circle", "home", "nan"), "Expected --circle's radius > 0 (m), got nan."),
    ((*LINE, "--tolerance", "1e-15"), "Expected --tolerance from 1.43e-14 m (the rounding of the arc length) to below "
                                      "the path's length, 1.86672 m, got 1e-15."),
    ((*LINE, "--tolerance", "10"), "to below the path's length, 1.86672 m, got 10."),
])
def test_the_command_refuses_a_path_or_tolerance_it_cannot_use_in_one_line(arguments, message):
    one_line_error(screwkit("trajectory", "planar_5rrr", *arguments), message)


def test_the_command_writes_the_path_its_summary_and_figure(tmp_path):
    """--line through the Fig. 4 pose: the JSON summary is the Python result's; the CSV written reads back as the
    same path (its x, y, phi columns in m and deg) and gives the same result; the netCDF holds the summary."""
    five = bundled("planar_5rrr")
    arguments = ("--line", "-0.3", "-0.2", "-45", "0.3", "0.2", "45", "--samples", "41", "--level", str(LEVEL))
    done = screwkit("trajectory", "planar_5rrr", *arguments, "--json", "--out", tmp_path / "t.csv",
                    "--figure", tmp_path / "t.png")
    assert done.returncode == 0 and done.stderr == "", done.stderr
    summary = json.loads(done.stdout)
    expected = trajectory(five, line_path(five, START, STOP, 41), level=LEVEL).summary()
    assert summary["worst"] == expected["worst"]
    for found, wanted in zip(summary["faults"], expected["faults"]):
        np.testing.assert_allclose(np.reshape(found["lost_m"], (-1, 2)), np.reshape(wanted["lost_m"], (-1, 2)),
                                   atol=1e-9)
    assert (tmp_path / "t.png").stat().st_size > 10_000
    again = screwkit("trajectory", "planar_5rrr", tmp_path / "t.csv", "--level", str(LEVEL), "--json",
                     "--out", tmp_path / "t.nc")
    assert again.returncode == 0, again.stderr
    reread = json.loads(again.stdout)
    assert reread["worst"] == summary["worst"] and reread["samples"] == 41
    import xarray as xr

    with xr.open_dataset(tmp_path / "t.nc", engine="scipy") as dataset:
        assert json.loads(dataset.attrs["summary"])["worst"] == summary["worst"]
        assert dataset["lmti_left1"].shape == (41, 5)
    one_line_error(screwkit("trajectory", "planar_5rrr", *arguments, "--out", tmp_path / "t.nc"),
                   "t.nc: the file exists")
    one_line_error(screwkit("trajectory", "planar_5rrr"), "Expected exactly one of PATH")


def test_a_path_through_poses_is_straight_between_them_with_each_pose_a_sample():
    five = bundled("planar_5rrr")
    corners = np.array([[-0.2, 0.0, 0.0], [0.0, 0.2, np.deg2rad(30.0)], [0.25, 0.0, 0.0]])
    path = through_path(five, corners, 20)
    for corner in corners:  # every pose given is a sample
        assert np.min(np.linalg.norm(path.poses - corner, axis=1)) < 1e-15
    weights = np.array([1.0, 1.0, five.length_scale])
    lengths = np.linalg.norm(np.diff(corners, axis=0) * weights, axis=1)
    assert path.length == pytest.approx(lengths.sum(), rel=1e-12)
    steps = np.diff(path.arc_length)
    assert steps.max() <= path.length / 19 + 1e-12 and path.samples in (20, 21, 22)
    middle = path.arc_length < lengths[0]  # on the first segment: on the straight line between the first two poses
    fraction = path.arc_length[middle] / lengths[0]
    np.testing.assert_allclose(path.poses[middle], corners[0] + fraction[:, None] * (corners[1] - corners[0]),
                               atol=1e-14)
    with pytest.raises(ValueError, match="at least 2 samples"):
        through_path(five, corners, 1)


def _actuator_file(tmp_path, five, path, times=True):
    """The actuator values of the 5-RRR along ``path`` (deg), as the CSV a user would give, with times."""
    values = np.rad2deg(actuator_values(five, solve(five, path.poses).joint_values))
    columns = [f"chain_{i}" for i in range(1, 6)]
    rows = np.column_stack([np.linspace(0.0, 4.0, path.samples), values]) if times else values
    np.savetxt(tmp_path / "q.csv", rows, delimiter=",", header=",".join((["t"] if times else []) + columns),
               comments="")
    return tmp_path / "q.csv", values


def test_a_path_in_actuator_values_is_the_path_of_the_poses_they_drive(tmp_path):
    """The actuator values of the path through the Fig. 4 pose (inverse kinematics) give back its poses by forward
    kinematics (continuation from the reference assembly) to 1e-9, and so the same trajectory; values that
    disagree with each other are refused naming the sample."""
    five = bundled("planar_5rrr")
    path = line_path(five, START, STOP, 41)
    file, values = _actuator_file(tmp_path, five, path)
    driven = read_actuator_path(five, file)
    np.testing.assert_allclose(driven.poses, path.poses, rtol=0, atol=1e-9)
    np.testing.assert_allclose(driven.times, np.linspace(0.0, 4.0, 41))
    back = path_from_actuators(five, np.deg2rad(values))
    np.testing.assert_allclose(back.poses, path.poses, rtol=0, atol=1e-9)
    values[7, 2] += 1.0  # chain 3 one degree off at sample 7: no pose gives all five
    with pytest.raises(ValueError, match="^sample 7: no pose near the previous sample's gives the actuator values "
                                         ".*: they disagree with each other"):
        path_from_actuators(five, np.deg2rad(values))
    untimed = "\n".join(line.split(",", 1)[1] for line in file.read_text().splitlines())  # chain_1 first
    (tmp_path / "bom.csv").write_text("\ufeff" + untimed, encoding="utf-8")  # Excel's byte-order mark, skipped
    np.testing.assert_array_equal(read_actuator_path(five, tmp_path / "bom.csv").poses, driven.poses)


def test_actuator_values_of_more_than_a_hundred_turns_are_refused(tmp_path):
    """1e20 deg was taken for the angle it rounds to (a double cannot tell one turn of it from the next)."""
    five = bundled("planar_5rrr")
    values = np.zeros((3, 5))
    values[1, 2] = 1e20
    with pytest.raises(ValueError, match=r"at most 628.319 rad \(100 turns\) either way in actuator values "
                                         r"\(chain_3:chain_3_joint_b, sample 1\), got 1e\+20 rad.$"):
        path_from_actuators(five, values)
    np.savetxt(tmp_path / "far.csv", values, delimiter=",", header="chain_1,chain_2,chain_3,chain_4,chain_5",
               comments="")
    message = ("Expected angles of at most 36000 deg (100 turns) either way in column 'chain_3' (sample 1), got "
               "1e+20 deg.")
    with pytest.raises(PathFileError, match=r"far.csv: Expected angles"):
        read_actuator_path(five, tmp_path / "far.csv")
    one_line_error(screwkit("trajectory", "planar_5rrr", tmp_path / "far.csv", "--actuators"),
                   f"{tmp_path / 'far.csv'}: {message}")


def test_the_command_takes_a_path_through_poses_or_in_actuator_values(tmp_path):
    five = bundled("planar_5rrr")
    through = screwkit("trajectory", "planar_5rrr", "--through", "-0.2", "0", "0", "0", "0.2", "30", "0.25", "0", "0",
                       "--samples", "21", "--json")
    assert through.returncode == 0, through.stderr
    expected = trajectory(five, through_path(five, [[-0.2, 0, 0], [0, 0.2, np.deg2rad(30)], [0.25, 0, 0]], 21))
    summary = json.loads(through.stdout)
    assert summary["samples"] == expected.path.samples and summary["worst"] == expected.summary()["worst"]
    assert summary["length_m"] == pytest.approx(expected.path.length, rel=1e-12)

    file, values = _actuator_file(tmp_path, five, line_path(five, START, STOP, 41))
    driven = screwkit("trajectory", "planar_5rrr", file, "--actuators", "--level", str(LEVEL), "--json")
    assert driven.returncode == 0, driven.stderr
    summary = json.loads(driven.stdout)
    posed = line_path(five, START, STOP, 41)
    expected = trajectory(five, posed, level=LEVEL).summary()
    assert summary["worst"] == expected["worst"] and summary["duration_s"] == 4.0
    driven_path = read_actuator_path(five, file)  # its arc length along the actuators: compared at the poses there
    weights = np.array([1.0, 1.0, five.length_scale])
    assert sum(np.size(case["lost_m"]) for case in expected["faults"]) >= 4
    for found, wanted in zip(summary["faults"], expected["faults"]):  # each located to the tolerance, 1e-6 L
        assert np.size(found["lost_m"]) == np.size(wanted["lost_m"])
        np.testing.assert_allclose(driven_path.at(np.ravel(found["lost_m"])) * weights,
                                   posed.at(np.ravel(wanted["lost_m"])) * weights, atol=2e-6 * five.length_scale)

    values[7, 2] += 1.0
    np.savetxt(tmp_path / "bad.csv", values, delimiter=",", header="chain_1,chain_2,chain_3,chain_4,chain_5",
               comments="")
    one_line_error(screwkit("trajectory", "planar_5rrr", tmp_path / "bad.csv", "--actuators"),
                   f"{tmp_path / 'bad.csv'}: sample 7: no pose near the previous sample's gives the actuator values")
    (tmp_path / "poses.csv").write_text("x,y,phi\n0,0,0\n0.1,0,0\n")
    one_line_error(screwkit("trajectory", "planar_5rrr", tmp_path / "poses.csv", "--actuators"),
                   "no column 'chain_1:chain_1_joint_b'", "has columns chain_1, chain_2, chain_3, chain_4, chain_5")
    one_line_error(screwkit("trajectory", "planar_5rrr", "--line", "0", "0", "0", "0.1", "0", "0", "--actuators"),
                   "--actuators says that PATH holds actuator values")
    one_line_error(screwkit("trajectory", "planar_5rrr", "--through", "0", "0", "0"),
                   "Expected --through with at least 2 poses")
    one_line_error(screwkit("trajectory", "planar_5rrr", "--through", "0", "0", "0", "0.1", "0"),
                   "Expected --through with at least 2 poses (named poses, or 3 numbers each", "got 0 0 0 0.1 0.")


def test_a_failure_that_leaves_fewer_actuators_than_dof_is_said_once_not_sample_by_sample(tmp_path):
    """A non-redundant five-bar (2 actuators, 2 DOF): after either failure the one actuator left holds nothing at
    any pose (F_O1 = 0 by definition, as analyze says). The summary says so in one line per failure instead of
    listing every sample as a singular point (a 100,000-sample path printed 100,000 numbers a failure); the JSON
    keeps the samples and says how many actuators are left."""
    five = bundled("five_bar")
    result = trajectory(five, circle_path(five, five.home_pose, 0.05, 9))
    summary = result.summary()
    assert summary["dof"] == 2 and [case["actuators_left"] for case in summary["faults"]] == [1, 1]
    assert all(len(case["singular_at_m"]) == 9 and case["minimum"] == 0.0 for case in summary["faults"])
    done = screwkit("trajectory", "five_bar", "--circle", "home", "0.05", "--samples", "9",
                    "--out", tmp_path / "t.csv")
    assert done.returncode == 0, done.stderr
    failures = [line for line in done.stderr.splitlines() if line.startswith("  fail ")]
    assert len(failures) == 2 and all(
        "uncontrolled all along (the 1 actuator left cannot hold the 2 DOF, so F_O1 = 0)" in line for line in failures)
    assert "singular at" not in done.stderr
    redundant = trajectory(bundled("planar_5rrr"), line_path(bundled("planar_5rrr"), START, STOP, 5)).summary()
    assert redundant["dof"] == 3 and {case["actuators_left"] for case in redundant["faults"]} == {4, 3}  # j = 1, 2


def test_a_path_of_a_non_redundant_mechanism_is_not_said_to_disagree():
    """Two motors of a five-bar turned apart until no pose of the mode followed gives their values: the refusal said
    they "disagree with each other", which two values for two DOF cannot; it names the mode left instead."""
    from screwkit.closure import solve

    five = bundled("five_bar")
    solution = solve(five, five.home_pose[None])
    start = np.array([solution.joint_values[c][0][j] for c, j in five.actuator_positions(None)])
    values = start + np.linspace(0.0, 1.0, 11)[:, None] * np.radians([120.0, -120.0])
    with pytest.raises(ValueError, match="they leave the working and assembly modes followed there") as refused:
        path_from_actuators(five, values)
    assert "disagree" not in str(refused.value)
