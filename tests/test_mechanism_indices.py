"""Indices of the bundled URDF mechanisms against independent computations.

* spatial output twists against finite differences of the closure: lock all actuators of a
  submechanism but one, move it slightly, re-solve the forward kinematics, compare the
  platform's twist direction;
* OTIs of UPS and RSS legs against the leg lines (null space by SVD, power coefficient);
* the 4-RPR at its concurrent pose, the cooperative arms.
"""

from __future__ import annotations

import numpy as np
import pytest

from helpers import platform_twist
from screwkit.closure import actuator_values, chain_screws, forward, solve
from screwkit.indices.analysis import analyze
from screwkit.io.loader import load
from screwkit.screw import algebra as screws
from screwkit.studies import indices_at_pose


@pytest.mark.parametrize("name", ["ups_hexapod_8", "rss_hexapod_8"])
def test_output_twists_match_finite_differences_of_the_closure(name):
    mechanism = load(name)
    pose = np.asarray(mechanism.home_pose, dtype=float) + np.array([0.02, -0.03, 0.05, 0.05, -0.04, 0.1])
    result = indices_at_pose(mechanism, pose)
    solution = solve(mechanism, pose)
    at_pose = actuator_values(mechanism, solution.joint_values)
    step = 1e-6
    for s in (0, 7, 27):
        sub = list(result.submechanisms[s])
        # One batched forward-kinematics call: each actuator of the submechanism moved by -step and +step.
        values = np.repeat(at_pose[sub][None], 2 * len(sub), axis=0)
        for position in range(len(sub)):
            values[2 * position, position] -= step
            values[2 * position + 1, position] += step
        moved = forward(mechanism, values, pose, actuators=sub)
        assert np.all(moved.reachable)
        for position in range(len(sub)):
            twist = platform_twist(mechanism, moved.poses[2 * position], moved.poses[2 * position + 1], step)
            expected = result.output_twists[s, position]
            # signed: the output twist is the platform's motion when its actuator moves forward (its wrench does
            # positive work on it), whichever sign the motion basis came with
            cosine = (twist @ expected) / np.linalg.norm(twist) / np.linalg.norm(expected)
            assert cosine > 1 - 1e-6, (s, position, cosine)


@pytest.mark.parametrize("threshold", [None, 0.5])
@pytest.mark.parametrize("name, rod_start", [("ups_hexapod_8", 0), ("rss_hexapod_8", 1)])
def test_leg_otis_match_an_independent_formula(name, rod_start, threshold):
    """The actuation wrench of a UPS (RSS) leg is the force along the leg (rod); OTIs from those lines.

    Each actuator's OTI (Eq. 8), each submechanism's (Eq. 9: the kernel takes |det W| over the
    longest moment arm, a path apart from the per-actuator values) and the LMTI (Eq. 11), at the
    paper's threshold and at one large enough (0.5 m) to zero about half the OTIs."""
    mechanism = load(name)
    rng = np.random.default_rng(3)
    poses = np.asarray(mechanism.home_pose, dtype=float) + rng.uniform(-0.05, 0.05, (20, 6))
    solution = solve(mechanism, poses)
    assert np.all(solution.reachable)
    chains = chain_screws(mechanism, solution)
    options = {} if threshold is None else {"threshold": threshold}
    result = analyze(chains, **options)
    zeroed = 0
    for index in range(0, 20, 5):
        lines, tops = [], []
        for chain in chains:
            points = chain.points[index]
            start, top = points[rod_start], points[-1]
            direction = (top - start) / np.linalg.norm(top - start)
            lines.append(np.concatenate([direction, np.cross(top, direction)]))
            tops.append(top)
        submechanism_otis = []
        for s, sub in enumerate(result.submechanisms):
            values = []
            for position, k in enumerate(sub):
                others = np.array([lines[i] for i in sub if i != k])
                (twist,) = screws.reciprocal_complement(others)
                values.append(float(screws.power_coefficient(lines[k], twist[0], tops[k], **options)))
                assert result.oti_actuators[index, s, position] == pytest.approx(values[-1], abs=1e-9)
            submechanism_otis.append(min(values))
            assert result.oti_submechanisms[index, s] == pytest.approx(min(values), abs=1e-9)
            zeroed += min(values) == 0.0
        assert result.lmti[index] == pytest.approx(max(submechanism_otis), abs=1e-9)
    assert (zeroed > 0) == (threshold is not None)  # the large threshold zeroes some submechanisms, not all
    assert zeroed < 4 * len(result.submechanisms)


def test_4rpr_concurrent_pose_names_the_non_mutual_interference_actuator():
    mechanism = load("planar_4rpr")
    result = indices_at_pose(mechanism, mechanism.named_pose("three_lines_concurrent"))
    np.testing.assert_array_equal(result.mutual_interference, [True, True, True, False])
    assert result.f_o[1] < 1e-9
    assert result.worst_faults[1] == ("leg_4:leg_4_joint_slider",)
    assert result.not_mutual_interference == ("leg_4:leg_4_joint_slider",)
    at_home = indices_at_pose(mechanism, mechanism.home_pose)
    assert np.all(at_home.mutual_interference) and float(at_home.f_o[1]) > 0.1


def test_cooperative_arms_are_finite_and_frame_invariant():
    mechanism = load("coop_arms")
    rng = np.random.default_rng(5)
    poses = np.asarray(mechanism.home_pose, dtype=float) + rng.uniform(-0.03, 0.03, (4, 6))
    solution = solve(mechanism, poses)
    assert np.all(solution.reachable)
    world = analyze(chain_screws(mechanism, solution))
    base = analyze(chain_screws(mechanism, solution, frame="base"))
    assert world.dof == 6 and world.actuator_count == 12 and set(world.f_o) == set(range(1, 7))
    assert np.all(np.isfinite(world.iti)) and np.all(np.isfinite(world.f_o[6]))
    assert np.all(world.lmti > 0)
    for j in world.f_o:
        np.testing.assert_allclose(world.f_o[j], base.f_o[j], atol=1e-9)
    np.testing.assert_allclose(world.iti_actuators, base.iti_actuators, atol=1e-9)
