"""Identities: rigid motions in 3-D, batching, world frame choice."""

from __future__ import annotations

import numpy as np
import pytest

from helpers import moved, random_planar_rrr, random_rotation
from screwkit.indices.analysis import analyze
from screwkit.screw.algebra import transform_twist
from screwkit.screw.chain_screws import ChainScrews
from screwkit.screw.planar import rrr_chain_screws


def compare(first, second, tolerance=1e-9):
    np.testing.assert_allclose(first.iti_actuators, second.iti_actuators, atol=tolerance)
    np.testing.assert_allclose(first.oti_actuators, second.oti_actuators, atol=tolerance)
    np.testing.assert_allclose(first.lmti, second.lmti, atol=tolerance)
    for j in first.f_o:
        np.testing.assert_allclose(first.f_o[j], second.f_o[j], atol=tolerance)
        np.testing.assert_allclose(first.f_io[j], second.f_io[j], atol=tolerance)
    np.testing.assert_array_equal(first.mutual_interference, second.mutual_interference)


def test_indices_invariant_under_rigid_motion_in_space(rng):
    base, elbows, distal = random_planar_rrr(rng, 2_000, 5)
    chains = rrr_chain_screws(base, elbows, distal)
    reference = analyze(chains, keep_twists=True)
    for _ in range(5):
        rotation = random_rotation(rng)
        translation = rng.uniform(-50, 50, 3)
        result = analyze(moved(chains, rotation, translation), keep_twists=True)
        assert result.dof == 3
        compare(reference, result)
        # Wrenches move with the same adjoint (as (f, m)).
        np.testing.assert_allclose(result.actuation_wrenches,
                                   transform_twist(rotation, translation, reference.actuation_wrenches), atol=1e-9)


def test_batched_equals_loop_over_single_configurations(rng):
    base, elbows, distal = random_planar_rrr(rng, 40, 5)
    batched = analyze(rrr_chain_screws(base, elbows, distal), chunk_size=7)
    for index in range(40):
        single = analyze(rrr_chain_screws(base[index], elbows[index], distal[index]))
        assert isinstance(single.iti, float) and single.batch_shape == ()  # one configuration: plain floats
        assert single.iti == pytest.approx(batched.iti[index], abs=1e-12)
        assert single.lmti == pytest.approx(batched.lmti[index], abs=1e-12)
        np.testing.assert_allclose(single.oti_submechanisms, batched.oti_submechanisms[index], atol=1e-12)
        for j in single.f_o:
            assert single.f_o[j] == pytest.approx(batched.f_o[j][index], abs=1e-12)


def test_batch_shape_is_kept(rng):
    base, elbows, distal = random_planar_rrr(rng, 24, 4)
    shaped = [a.reshape(2, 3, 4, 4, 2) for a in (base, elbows, distal)]
    result = analyze(rrr_chain_screws(*shaped))
    assert result.iti.shape == (2, 3, 4)
    assert result.oti_submechanisms.shape == (2, 3, 4, 4)
    assert result.worst_faults[1].shape == (2, 3, 4, 1)
    flat = analyze(rrr_chain_screws(base, elbows, distal))
    np.testing.assert_allclose(result.lmti.reshape(-1), flat.lmti, atol=1e-15)


def test_threads_and_chunks_do_not_change_results(rng):
    base, elbows, distal = random_planar_rrr(rng, 3_000, 5)
    chains = rrr_chain_screws(base, elbows, distal)
    one = analyze(chains, threads=1, chunk_size=3_000)
    many = analyze(chains, threads=2, chunk_size=256)
    np.testing.assert_array_equal(one.f_o[1], many.f_o[1])
    np.testing.assert_array_equal(one.iti, many.iti)


def test_tiled_and_separate_chain_memory_give_the_same_result(rng):
    """Chains built as blocks of one array are read in place; separate copies are concatenated."""
    base, elbows, distal = random_planar_rrr(rng, 500, 5)
    tiled = rrr_chain_screws(base, elbows, distal)
    separate = [ChainScrews(c.twists.copy(), c.points.copy(), c.actuated, c.name) for c in tiled]
    first, second = analyze(tiled), analyze(separate)
    np.testing.assert_array_equal(first.oti_actuators, second.oti_actuators)
    np.testing.assert_array_equal(first.iti_actuators, second.iti_actuators)
    reordered = analyze(tiled[::-1])  # blocks out of order: not tiled, concatenated
    np.testing.assert_allclose(reordered.f_o[1], first.f_o[1], atol=1e-12)


def test_characteristic_points_given_on_the_wrench_axis_change_nothing():
    """For an RRR chain the elbow c and the platform joint d lie on the actuation wrench's axis (the
    distal link), so passing them as the ITI and OTI points must reproduce the default projections;
    points off the axis must change the indices."""
    rng = np.random.default_rng(11)
    base, elbows, distal = random_planar_rrr(rng, 3000)
    chains = rrr_chain_screws(base, elbows, distal)
    on_axis = analyze(chains, iti_points=np.pad(elbows, ((0, 0), (0, 0), (0, 1))),
                      oti_points=np.pad(distal, ((0, 0), (0, 0), (0, 1))))
    compare(analyze(chains), on_axis)
    for detail in (False, True):  # the override path with and without per-actuator outputs
        plain = analyze(chains, detail=detail, oti_points=np.pad(distal, ((0, 0), (0, 0), (0, 1))))
        np.testing.assert_allclose(plain.f_o[1], on_axis.f_o[1], atol=1e-9)
    off_axis = analyze(chains, oti_points=np.pad(distal + 0.3, ((0, 0), (0, 0), (0, 1))))
    assert np.abs(off_axis.oti_actuators - on_axis.oti_actuators).max() > 1e-3
