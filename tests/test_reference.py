"""The compiled, batched pipeline equals the plain-numpy reference (:mod:`screwkit.screw.reference`).

Every bundled mechanism (frame and point outputs, lower mobility with constraint wrenches, redundant and not)
and a random design of every family, at random reachable poses: the ITI of every actuator, the OTI of every
actuator of every submechanism, the LMTI, every F_Oj and F_IOj, the mutual-interference actuators, the
instantaneous DOF, the CTI and every F_Cj, to 1e-10.
"""

from __future__ import annotations

import numpy as np
import pytest
from test_relabelling import random_designs

from helpers import random_reachable_poses
from screwkit.closure import chain_screws, solve
from screwkit.io.loader import bundled_names, load
from screwkit.screw.reference import reference_indices
from screwkit.studies.poses import analyze_solution, indices_at_poses, output_points

TOLERANCE = 1e-10
COUNT = 6


@pytest.fixture(scope="module")
def designs():
    return random_designs()


def compare(mechanism, poses):
    solution = solve(mechanism, poses)
    result = analyze_solution(mechanism, solution, detail=True)
    chains = chain_screws(mechanism, solution)
    points = output_points(mechanism, solution.full_poses)
    normal = mechanism.rotation_world_base[:, 2] if mechanism.is_planar else None
    for i in range(poses.shape[0]):
        expected = reference_indices([c.twists[i] for c in chains], [c.points[i] for c in chains],
                                     [c.actuated for c in chains], mechanism.dof,
                                     output_point=None if points is None else points[i], planar_normal=normal)
        got = result.at(i)
        np.testing.assert_allclose(got.iti_actuators, expected["iti_actuators"], atol=TOLERANCE, rtol=0)
        for s, members in enumerate(got.submechanisms):
            np.testing.assert_allclose(got.oti_actuators[s], expected["oti_actuators"][members], atol=TOLERANCE,
                                       rtol=0, err_msg=f"OTIs of submechanism {members}")
        for key in ("iti", "lmti"):
            assert abs(getattr(got, key) - expected[key]) <= TOLERANCE, key
        assert got.f_o.keys() == expected["f_o"].keys()
        for j in got.f_o:
            assert abs(got.f_o[j] - expected["f_o"][j]) <= TOLERANCE and abs(got.f_io[j] - expected["f_io"][j]) \
                <= TOLERANCE, j
        assert list(got.mutual_interference) == expected["mutual_interference"]
        if got.instantaneous_dof is not None:
            assert got.instantaneous_dof == expected["instantaneous_dof"]
        if got.constraint_count:
            assert abs(got.cti - expected["cti"]) <= TOLERANCE
            for j in got.f_c:
                assert abs(got.f_c[j] - expected["f_c"][j]) <= TOLERANCE
        else:
            assert "cti" not in expected
    return result


@pytest.mark.parametrize("name", bundled_names())
def test_the_compiled_pipeline_equals_the_reference_on_every_bundled_mechanism(name):
    mechanism = load(name)
    count = 2 if name == "coop_arms" else COUNT  # (its 924 submechanisms: the reference takes 1.4 s a pose)
    poses = random_reachable_poses(mechanism, np.random.default_rng(len(name)), count, spread=0.5)
    compare(mechanism, np.concatenate([mechanism.home_pose[None], poses]))


@pytest.mark.parametrize("name, poses", [("five_bar", [[0.4, 0.0], [0.4 - 1e-12, 0.0]]),
                                         ("five_bar_3", [[0.3, 0.3], [-0.2, 0.35], [0.2, 0.4]])])
def test_at_a_stretched_leg_both_pipelines_give_the_paper_s_closed_forms(name, poses):
    """At an input singularity (a leg stretched: its actuated joint's twist in the span of the others) the
    minimum-norm wrench has no solution, and both pipelines made it zero, and with it every OTI of the sets holding
    that actuator: five_bar at (0.4, 0) had LMTI 0 where the closed forms (Eqs. 21-23, the force along the distal
    link) give 0.6285, and 0.6285 1e-12 inside. Now the wrench is the limit (in the span of the chain's twists and
    the motion space, reciprocal to the other joints): the compiled kernel and the numpy reference agree with each
    other and with the closed forms, and the value is continuous."""
    mechanism = load(name)
    poses = np.array(poses)
    result = compare(mechanism, poses)
    closed = indices_at_poses(mechanism, poses, closed_forms=True)
    np.testing.assert_allclose(result.lmti, closed.lmti, atol=1e-9)
    np.testing.assert_allclose(result.f_o[1], closed.f_o[1], atol=1e-9)
    assert np.all(result.lmti > 0.4) and np.all(np.min(result.iti_actuators, axis=-1) < 1e-5)  # sqrt(1e-12) inside


@pytest.mark.parametrize("index", range(8))
def test_the_compiled_pipeline_equals_the_reference_on_random_designs(designs, index):
    mechanism = designs[index]
    compare(mechanism, random_reachable_poses(mechanism, np.random.default_rng(index), COUNT, spread=0.5))


def test_the_reference_sees_a_constraint_singularity():
    """The symmetric 4-PRS at home: four constraint forces of rank three, 3 instantaneous DOF for mobility 2."""
    from screwkit.io.loader import load_text
    from screwkit.robots.generate import PRS_UPS, prs_mechanism

    mechanism = load_text(prs_mechanism("prs_4", dict(PRS_UPS, prs_angles_deg=(0.0, 90.0, 180.0, 270.0)),
                                        with_ups=False), "prs_4")
    result = compare(mechanism, mechanism.home_pose[None] + np.array([[0.0, 0.0], [0.01, 0.05]]))
    assert result.constraint_singular[0] and not result.constraint_singular[1]
