"""Spatial mechanisms from hand-built screws: UPS and RSS hexapods with extra legs, a hybrid
with constraint wrenches (3-RPS + UPS), two 6R arms holding one object, and the 4-RPR
with three concurrent legs. Each derived quantity is checked against an independent one."""

from __future__ import annotations

from itertools import combinations

import numpy as np
import pytest

from helpers import moved, random_rotation
from screwkit.indices.analysis import analyze
from screwkit.screw import algebra as screws
from screwkit.screw.chain_screws import ChainScrews
from screwkit.screw.planar import rpr_chain_screws


def revolute(axis, point):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    return np.concatenate([axis, np.cross(point, axis)])


def prismatic(direction):
    direction = np.asarray(direction, float) / np.linalg.norm(direction)
    return np.concatenate([np.zeros(3), direction])


def perpendicular_pair(direction, rng):
    first = np.cross(direction, rng.normal(size=3))
    first /= np.linalg.norm(first)
    return first, np.cross(direction, first)


def ups_leg(base, top, rng, name):
    u = (top - base) / np.linalg.norm(top - base)
    a1, a2 = perpendicular_pair(u, rng)
    twists = [revolute(a1, base), revolute(a2, base), prismatic(u),
              revolute([1, 0, 0], top), revolute([0, 1, 0], top), revolute([0, 0, 1], top)]
    return ChainScrews(np.array(twists), np.array([base, base, top, top, top, top]), (2,), name)


def rss_leg(base, axis, elbow, top, name):
    twists = [revolute(axis, base)] + [revolute(e, elbow) for e in np.eye(3)] + [revolute(e, top) for e in np.eye(3)]
    points = [base] + [elbow] * 3 + [top] * 3
    return ChainScrews(np.array(twists), np.array(points), (0,), name)


def rps_leg(base, axis, top, name):
    u = (top - base) / np.linalg.norm(top - base)
    twists = [revolute(axis, base), prismatic(u)] + [revolute(e, top) for e in np.eye(3)]
    return ChainScrews(np.array(twists), np.array([base, top, top, top, top]), (1,), name)


def line(direction, through):
    direction = direction / np.linalg.norm(direction)
    return np.concatenate([direction, np.cross(through, direction)])


def independent_oti(lines, points, threshold=1e-6):
    """OTI of every leg of every 6-subset from the leg lines: null space by SVD, power coefficient."""
    values = {}
    for sub in combinations(range(len(lines)), 6):
        for position, k in enumerate(sub):
            others = np.array([lines[i] for i in sub if i != k])
            (twist,) = screws.reciprocal_complement(others)
            values[sub, position] = float(screws.power_coefficient(lines[k], twist[0], points[k], threshold))
    return values


def hexapod_points(rng, legs):
    angles = np.sort(rng.uniform(0, 2 * np.pi, legs))
    base = np.column_stack([np.cos(angles), np.sin(angles), np.zeros(legs)]) * 1.0
    top = np.column_stack([np.cos(angles + 0.4), np.sin(angles + 0.4), np.ones(legs)]) * [0.5, 0.5, 0.8]
    return base + rng.normal(scale=0.05, size=base.shape), top + rng.normal(scale=0.05, size=top.shape)


def test_ups_hexapod_with_eight_legs(rng):
    base, top = hexapod_points(rng, 8)
    chains = [ups_leg(b, t, rng, f"leg{i + 1}") for i, (b, t) in enumerate(zip(base, top))]
    result = analyze(chains)
    assert result.dof == 6 and result.actuator_count == 8
    lines = [line(t - b, t) for b, t in zip(base, top)]
    # The actuation wrench is the force along the leg (reciprocal to U and S), unit and signed.
    for k, wrench in enumerate(result.actuation_wrenches):
        np.testing.assert_allclose(wrench, lines[k], atol=1e-9)
    np.testing.assert_allclose(result.iti_actuators, 1.0, atol=1e-12)
    expected = independent_oti(lines, top)
    for (sub, position), value in expected.items():
        s = result.submechanisms.index(sub)
        assert result.oti_actuators[s, position] == pytest.approx(value, abs=1e-9)
    assert set(result.f_o) == {1, 2}


def test_rss_hexapod_with_seven_legs(rng):
    """RSS legs have an idle spin of the S-S rod (7 joint DoFs of rank 6): the pseudo-inverse path."""
    base, top = hexapod_points(rng, 7)
    chains, lines, elbows, inputs = [], [], [], []
    for i, (b, t) in enumerate(zip(base, top)):
        axis = np.array([-b[1], b[0], 0.0])  # tangent to the base circle
        radial = np.cross(axis / np.linalg.norm(axis), [0, 0, 1.0])
        elbow = b + 0.4 * (np.cos(0.7) * radial + np.sin(0.7) * np.array([0, 0, 1.0]))
        chains.append(rss_leg(b, axis, elbow, t, f"leg{i + 1}"))
        lines.append(line(t - elbow, t))
        elbows.append(elbow)
        inputs.append(revolute(axis, b))
    result = analyze(chains)
    assert result.dof == 6
    for k, wrench in enumerate(result.actuation_wrenches):
        assert abs(abs(np.dot(wrench, lines[k])) - np.dot(lines[k], lines[k])) < 1e-9  # same line up to sign
        # ITI: cosine between the rod force and the velocity of the crank end (independent formula).
        velocity = np.cross(inputs[k][:3], elbows[k] - base[k])
        direction = lines[k][:3]
        assert result.iti_actuators[k] == pytest.approx(abs(direction @ velocity) / np.linalg.norm(velocity), abs=1e-9)
    expected = independent_oti(lines, top)
    for (sub, position), value in expected.items():
        assert result.oti_actuators[result.submechanisms.index(sub), position] == pytest.approx(value, abs=1e-9)


def hybrid_chains(rng):
    """3-RPS + 1-UPS: three constraint forces, n = 3, four actuators, motion space varies."""
    base, top = hexapod_points(rng, 4)
    chains = []
    for i in range(3):
        axis = np.array([-base[i, 1], base[i, 0], 0.0]) + rng.normal(scale=0.1, size=3)
        chains.append(rps_leg(base[i], axis, top[i], f"rps{i + 1}"))
    chains.append(ups_leg(base[3], top[3], rng, "ups"))
    return chains


def test_hybrid_with_constraint_wrenches(rng):
    configurations = [hybrid_chains(rng) for _ in range(30)]
    stacked = [ChainScrews(np.stack([c[i].twists for c in configurations]),
                           np.stack([c[i].points for c in configurations]),
                           configurations[0][i].actuated, configurations[0][i].name) for i in range(4)]
    result = analyze(stacked, keep_twists=True)
    assert result.dof == 3 and result.actuator_count == 4
    for index, chains in enumerate(configurations):
        constraints = [screws.reciprocal_complement(c.twists)[0] for c in chains]
        all_constraints = np.vstack(constraints)
        assert all_constraints.shape[0] == 3
        for slot, chain in enumerate(chains):
            wrench = result.actuation_wrenches[index, slot]
            passive = np.delete(chain.twists, chain.actuated[0], axis=0)
            np.testing.assert_allclose(screws.reciprocal_product(wrench, passive), 0, atol=1e-9)
            assert screws.reciprocal_product(wrench, chain.twists[chain.actuated[0]]) > 0
            # Orthogonal to the chain's constraint wrenches, moments about the platform joint point.
            point = chain.points[-1]
            for constraint in constraints[slot]:
                assert abs(np.dot(screws.shift_wrench(wrench, point), screws.shift_wrench(constraint, point))) < 1e-9
        for s, sub in enumerate(result.submechanisms):
            for position, k in enumerate(sub):
                twist = result.output_twists[index, s, position]
                # In the motion space and reciprocal to the other actuators of the submechanism.
                np.testing.assert_allclose(screws.reciprocal_product(all_constraints, twist), 0, atol=1e-9)
                for other in sub:
                    if other != k:
                        assert abs(screws.reciprocal_product(result.actuation_wrenches[index, other], twist)) < 1e-9
                wrench = result.actuation_wrenches[index, k]
                point = screws.project_on_axis(wrench, chains[k].points[-1])
                assert result.oti_actuators[index, s, position] == pytest.approx(
                    float(screws.power_coefficient(wrench, twist, point)), abs=1e-9)
    rotation, translation = random_rotation(rng), rng.normal(size=3) * 10
    again = analyze(moved(stacked, rotation, translation))
    np.testing.assert_allclose(again.oti_actuators, result.oti_actuators, atol=1e-9)
    np.testing.assert_allclose(again.f_o[1], result.f_o[1], atol=1e-9)


def test_two_arms_holding_one_object(rng):
    """Twelve actuators in two 6R chains, six DOF: several actuators per chain, F_Oj for j = 1..6."""
    def arm(offset):
        points = offset + np.cumsum(rng.normal(scale=0.3, size=(6, 3)), axis=0)
        axes = rng.normal(size=(6, 3))
        return ChainScrews(np.array([revolute(a, p) for a, p in zip(axes, points)]), points, range(6))
    chains = [arm(np.zeros(3)), arm(np.array([1.0, 0, 0]))]
    result = analyze(chains)
    assert result.dof == 6 and result.actuator_count == 12
    assert set(result.f_o) == set(range(1, 7))
    actuators = [(c, k) for c, chain in enumerate(chains) for k in chain.actuated]
    assert result.actuators == tuple(f"chain_{c + 1}:joint_{k}" for c, k in actuators)  # unnamed chains and joints
    for k, (c, joint) in enumerate(actuators):
        others = np.delete(chains[c].twists, joint, axis=0)
        np.testing.assert_allclose(screws.reciprocal_product(result.actuation_wrenches[k], others), 0, atol=1e-9)
    assert np.all(np.diff([float(result.f_o[j]) for j in range(1, 7)]) <= 1e-15)  # more faults, no better
    assert float(result.f_o[6]) == pytest.approx(float(result.oti_submechanisms.min()))
    again = analyze(moved(chains, random_rotation(rng), rng.normal(size=3)))
    for j in result.f_o:
        assert float(again.f_o[j]) == pytest.approx(float(result.f_o[j]), abs=1e-9)


def test_4rpr_with_three_concurrent_legs_names_the_non_mutual_interference_actuator(rng):
    """Fig. 1: legs 1-3 meet in one point, so actuator 4 is not a mutual-interference actuator and F_O1 = 0."""
    centre = np.array([0.1, -0.05])
    distal = np.array([[0.3, 0.0], [-0.2, 0.25], [-0.1, -0.3], [0.25, 0.3]])
    base = np.empty_like(distal)
    for i in range(3):
        base[i] = centre + 4.0 * (distal[i] - centre)
    base[3] = np.array([1.5, 1.2])
    result = analyze(rpr_chain_screws(base, distal))
    np.testing.assert_array_equal(result.mutual_interference, [True, True, True, False])
    assert float(result.f_o[1]) < 1e-12
    assert float(result.oti_submechanisms[result.submechanisms.index((0, 1, 2))]) < 1e-12
    assert float(result.lmti) > 0.1
    np.testing.assert_array_equal(result.worst_fault_indices[1], [3])
    assert result.worst_faults[1] == ("leg_4:slider",) and result.not_mutual_interference == ("leg_4:slider",)
    # Move leg 3 off the common point: every actuator is then a mutual-interference actuator.
    base[2] += np.array([0.2, 0.0])
    assert np.all(analyze(rpr_chain_screws(base, distal)).mutual_interference)
