"""The generic screw derivation equals the paper's planar closed forms (Eqs. 23, 30-38, A2, A4-A6)."""

from __future__ import annotations

from itertools import combinations

import numpy as np
import pytest

from helpers import random_planar_rrr, special_planar_rrr
from screwkit.indices import closed_forms as cf
from screwkit.indices.analysis import analyze
from screwkit.screw.planar import rpr_chain_screws, rrr_chain_screws

TOLERANCE = 1e-9


def generic(base, elbows, distal, **options):
    return analyze(rrr_chain_screws(base, elbows, distal), **options)


@pytest.mark.parametrize("chains", [3, 4, 5, 6])
def test_random_configurations_match_closed_forms(rng, chains):
    count = 10_000 if chains == 5 else 2_000
    base, elbows, distal = random_planar_rrr(rng, count, chains)
    result = generic(base, elbows, distal)
    closed = cf.planar_indices(base, elbows, distal)
    assert result.dof == 3
    np.testing.assert_allclose(result.iti_actuators, closed["iti_chains"], rtol=0, atol=TOLERANCE)
    np.testing.assert_allclose(result.iti, closed["iti"], rtol=0, atol=TOLERANCE)
    assert result.submechanisms == closed["submechanisms"]
    np.testing.assert_allclose(result.oti_submechanisms, closed["oti_submechanisms"], rtol=0, atol=TOLERANCE)
    np.testing.assert_allclose(result.lmti, closed["lmti"], rtol=0, atol=TOLERANCE)
    assert set(result.f_o) == set(closed["f_o"]) == set(range(1, max(chains - 2, 2)))  # a = n: F_O1 = 0
    for j in result.f_o:
        np.testing.assert_allclose(result.f_o[j], closed["f_o"][j], rtol=0, atol=TOLERANCE)
        np.testing.assert_allclose(result.f_io[j], closed["f_io"][j], rtol=0, atol=TOLERANCE)


def test_per_chain_oti_matches_ic_a2_and_a4(rng):
    """OTI_k of every chain of every submechanism: Eqs. 30-33 (IC), A2 and A4 all agree with the generic one."""
    base, elbows, distal = random_planar_rrr(rng, 10_000, 5)
    result = generic(base, elbows, distal)
    f = cf.distal_directions(elbows, distal)
    for s, (k, l, m) in enumerate(result.submechanisms):
        for position, (own, first, second) in enumerate(((k, l, m), (l, k, m), (m, k, l))):
            args = (f[:, own], distal[:, own], f[:, first], distal[:, first], f[:, second], distal[:, second])
            expected_a4 = cf.oti_chain_a4(*args)
            np.testing.assert_allclose(result.oti_actuators[:, s, position], expected_a4, rtol=0, atol=TOLERANCE)
            np.testing.assert_allclose(cf.oti_chain_ic(*args), expected_a4, rtol=0, atol=TOLERANCE)
            np.testing.assert_allclose(cf.oti_chain_a2(*args), expected_a4, rtol=0, atol=TOLERANCE)


def test_special_configurations_match_closed_forms(rng):
    """Parallel, nearly parallel, collinear, concurrent and type-one singular configurations."""
    base, elbows, distal, kind = special_planar_rrr(rng, 6_000, 5)
    result = generic(base, elbows, distal)
    closed = cf.planar_indices(base, elbows, distal)
    np.testing.assert_allclose(result.iti_actuators, closed["iti_chains"], rtol=0, atol=TOLERANCE)
    np.testing.assert_allclose(result.oti_submechanisms, closed["oti_submechanisms"], rtol=0, atol=TOLERANCE)
    for j in result.f_o:
        np.testing.assert_allclose(result.f_o[j], closed["f_o"][j], rtol=0, atol=TOLERANCE)
    # The singular cases give the zeros the paper defines.
    stretched = kind == 4
    assert np.all(result.iti_actuators[stretched, 0] < 1e-12)
    collinear = kind == 2
    triples_with_0_and_1 = [s for s, sub in enumerate(result.submechanisms) if {0, 1} <= set(sub)]
    assert np.all(result.oti_submechanisms[np.ix_(collinear, triples_with_0_and_1)] == 0.0)
    concurrent = kind == 3
    first_triple = result.submechanisms.index((0, 1, 2))
    assert np.all(result.oti_submechanisms[concurrent, first_triple] < 1e-9)


def test_parallel_links_match_a5_and_a6(rng):
    """With f_l parallel to f_m the generic OTI_k equals Eq. (A5), and (A6) when f_m = f_l."""
    count = 3_000
    base, elbows, distal = random_planar_rrr(rng, count, 3)
    f = cf.distal_directions(elbows, distal)
    sign = np.where(rng.random(count) < 0.5, 1.0, -1.0)[:, None]
    f_m = sign * f[:, 1]
    elbows[:, 2] = distal[:, 2] - 0.8 * f_m
    f = cf.distal_directions(elbows, distal)
    result = generic(base, elbows, distal)
    args = (f[:, 0], distal[:, 0], f[:, 1], distal[:, 1], f[:, 2], distal[:, 2])
    np.testing.assert_allclose(result.oti_actuators[:, 0, 0], cf.oti_chain_a5(*args), rtol=0, atol=TOLERANCE)
    np.testing.assert_allclose(cf.oti_chain_a4(*args), cf.oti_chain_a5(*args), rtol=0, atol=TOLERANCE)
    # (A6) reads OTI_k = |f_l f_k| when f_m = f_l (same orientation); it is also what an
    # infinite-pitch output twist gives. A pure translation needs no special case.
    same = sign[:, 0] > 0
    np.testing.assert_allclose(result.oti_actuators[same, 0, 0], cf.oti_chain_a6(f[same, 0], f[same, 1]),
                               rtol=0, atol=TOLERANCE)


def test_nearly_parallel_links_are_continuous(rng):
    """Approaching parallel links, the generic OTI tends to the A5 value (no blow-up at the IC at infinity)."""
    base, elbows, distal = random_planar_rrr(rng, 200, 3)
    f = cf.distal_directions(elbows, distal)
    parallel = elbows.copy()
    parallel[:, 2] = distal[:, 2] - 0.8 * f[:, 1]
    f_parallel = cf.distal_directions(parallel, distal)
    limit = cf.oti_chain_a5(f_parallel[:, 0], distal[:, 0], f_parallel[:, 1], distal[:, 1],
                            f_parallel[:, 2], distal[:, 2])
    errors = []
    for angle in (1e-4, 1e-6, 1e-8):
        tilted = parallel.copy()
        c, s = np.cos(angle), np.sin(angle)
        direction = f[:, 1] @ np.array([[c, s], [-s, c]])
        tilted[:, 2] = distal[:, 2] - 0.8 * direction
        value = generic(base, tilted, distal).oti_actuators[:, 0, 0]
        assert np.all(np.isfinite(value))
        errors.append(np.abs(value - limit))
    # The deviation shrinks linearly with the angle, configuration by configuration.
    assert np.all(errors[1] <= 1.5e-2 * errors[0] + 1e-12)
    assert np.all(errors[2] <= 1.5e-2 * errors[1] + 1e-12)
    assert errors[2].max() < 1e-5


def test_rpr_mechanism_matches_closed_forms(rng):
    """Prismatic actuators: ITI is 1 and the OTIs are the same closed forms along the legs."""
    count = 3_000
    base = rng.uniform(-1, 1, (count, 4, 2))
    distal = rng.uniform(-0.3, 0.3, (count, 4, 2))
    result = analyze(rpr_chain_screws(base, distal))
    directions = cf.distal_directions(base, distal)
    closed = cf.planar_indices(base, None, distal, directions=directions)
    np.testing.assert_allclose(result.iti_actuators, 1.0, atol=TOLERANCE)
    np.testing.assert_allclose(result.oti_submechanisms, closed["oti_submechanisms"], rtol=0, atol=TOLERANCE)
    np.testing.assert_allclose(result.f_o[1], closed["f_o"][1], rtol=0, atol=TOLERANCE)


def test_numerator_is_shared_by_the_submechanism(rng):
    """Eq. (A3): |A_k o O_k| |f_l f_m| is the same for the three chains (O_k a unit-rotation twist)."""
    base, elbows, distal = random_planar_rrr(rng, 2_000, 3)
    result = analyze(rrr_chain_screws(base, elbows, distal), keep_twists=True)
    f = cf.distal_directions(elbows, distal)
    wrenches = result.actuation_wrenches
    twists = result.output_twists[:, 0]  # (N, 3 positions, 6)
    values = []
    for own, (l, m) in zip(range(3), ((1, 2), (0, 2), (0, 1))):
        twist = twists[:, own] / twists[:, own, 2:3]  # unit rotation about +z
        product = np.einsum("ni,ni->n", wrenches[:, own, :3], twist[:, 3:]) + np.einsum(
            "ni,ni->n", wrenches[:, own, 3:], twist[:, :3])
        values.append(np.abs(product * cf.det2(f[:, l], f[:, m])))
    np.testing.assert_allclose(values[0], values[1], rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(values[0], values[2], rtol=1e-9, atol=1e-12)


def test_threshold_zeroes_short_moment_arms(rng):
    """OTI_k = 0 when rho_kmax < p (the paper's threshold), in both paths."""
    base, elbows, distal = random_planar_rrr(rng, 4_000, 3)
    for threshold in (1e-6, 0.03, 0.3):
        result = generic(base, elbows, distal, threshold=threshold)
        closed = cf.planar_indices(base, elbows, distal, threshold=threshold)
        np.testing.assert_allclose(result.oti_submechanisms, closed["oti_submechanisms"], rtol=0, atol=TOLERANCE)
    f = cf.distal_directions(elbows, distal)
    rho = np.linalg.norm(distal[:, 0] - cf.instantaneous_centre(f[:, 1], distal[:, 1], f[:, 2], distal[:, 2]), axis=-1)
    short = rho < 0.3
    assert short.any() and (~short).any()
    result = generic(base, elbows, distal, threshold=0.3)
    assert np.all(result.oti_actuators[short, 0, 0] == 0.0)
    assert np.all(result.oti_actuators[~short, 0, 0] > 0.0)


def test_fault_sets_follow_eq_12(rng):
    """F_Oj recomputed by brute force from the per-submechanism OTIs (Eqs. 11-13)."""
    base, elbows, distal = random_planar_rrr(rng, 500, 6)
    result = generic(base, elbows, distal)
    a, n = 6, 3
    for j in range(1, a - n + 1):
        lmtis = [result.lmti_of(remaining) for remaining in combinations(range(a), a - j)]
        np.testing.assert_array_equal(result.f_o[j], np.min(lmtis, axis=0))
        worst = result.worst_fault_indices[j]
        for index in range(0, 500, 97):
            remaining = sorted(set(range(a)) - set(worst[index]))
            assert result.lmti_of(remaining)[index] == result.f_o[j][index]
    np.testing.assert_array_equal(result.f_o[a - n], result.oti_submechanisms.min(axis=-1))
