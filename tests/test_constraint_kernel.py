"""The compiled constraint indices (:mod:`screwkit.indices.compiled.constraints`) against their numpy reference
(:func:`screwkit.screw.constraints.constraint_indices` without a ``stage``): on constructed constraint systems of
every shape the kernel takes (one own wrench per chain, several own wrenches per chain, wrenches common to every
chain, forces and couples), at random configurations and at singular and rank-deficient ones, where the CTI must
be zero (never NaN); and the analysis of bundled lower-mobility mechanisms through the kernel (chunks of 512
configurations or more) against the numpy path (smaller chunks)."""

from __future__ import annotations

from itertools import combinations

import numpy as np
import pytest

from helpers import bundled, bundled_chain_screws, random_reachable_poses
from screwkit.indices.sets import submechanisms_left
from screwkit.indices.stages import CONSTRAINTS_COMPILED_FROM, compiled_constraint_stage, constraint_plan_of
from screwkit.screw.constraints import constraint_indices, plan_constraints
from screwkit.studies.poses import indices_at_poses

SWAP = np.block([[np.zeros((3, 3)), np.eye(3)], [np.eye(3), np.zeros((3, 3))]])
COUNT = CONSTRAINTS_COMPILED_FROM + 88
"""Configurations of a constructed system: one chunk, through the kernel."""


def unit(rows):
    return rows / np.linalg.norm(rows, axis=-1, keepdims=True)


def chain_of(wrenches, rng):
    """Joint twists (N, 6 - c, 6) spanning exactly the twists reciprocal to the chain's constraint wrenches
    (N, c, 6), and joint points (N, 6 - c, 3)."""
    count, c = wrenches.shape[:2]
    _, _, right = np.linalg.svd(wrenches @ SWAP)  # twists t with w . SWAP t = 0: the trailing right vectors
    basis = right[:, c:]  # (N, 6 - c, 6)
    twists = rng.standard_normal((count, 6 - c, 6 - c)) @ basis
    return twists, rng.standard_normal((count, 6 - c, 3))


def force_through(rng, count):
    """Unit forces (f, p x f) along random directions through random points: wrenches of pitch zero."""
    force = unit(rng.standard_normal((count, 3)))
    return np.concatenate([force, np.cross(rng.standard_normal((count, 3)), force)], axis=-1)


def couple(rng, count):
    return np.concatenate([np.zeros((count, 3)), unit(rng.standard_normal((count, 3)))], axis=-1)


def constructed(kind, rng):
    """Chains' constraint wrenches (list of (N, c_i, 6)) and the mobility n of a mechanism of each kind."""
    if kind == "forces":  # a 3-PRS + UPS: one constraint force per PRS leg, a six-DoF leg
        return [force_through(rng, COUNT)[:, None] for _ in range(3)] + [np.zeros((COUNT, 0, 6))], 3
    if kind == "couples":  # a 4-leg Delta: one couple per leg (four of rank three: four subsystems)
        return [couple(rng, COUNT)[:, None] for _ in range(4)], 3
    if kind == "mixed":  # forces and couples, one wrench with a pitch
        pitched = unit(force_through(rng, COUNT) + 0.3 * couple(rng, COUNT))
        return [force_through(rng, COUNT)[:, None], couple(rng, COUNT)[:, None], pitched[:, None]], 3
    if kind == "pairs":  # two own wrenches per chain: released pairs from the pairing's singular vectors
        return [np.stack([force_through(rng, COUNT), couple(rng, COUNT)], axis=1),
                np.stack([force_through(rng, COUNT), force_through(rng, COUNT)], axis=1)], 2
    if kind == "common":  # a couple common to every chain and one own force each
        shared = couple(rng, COUNT)
        return [np.stack([shared, force_through(rng, COUNT)], axis=1) for _ in range(3)], 2
    raise ValueError(kind)


def degenerate(wrenches, actuation):
    """Singular and rank-deficient configurations among every fourth one of each kind of degeneracy."""
    holders = [c for c, w in enumerate(wrenches) if w.shape[1]]
    first = holders[0]
    # a constraint singularity: the chains' constraint wrenches in too small a span (the instantaneous DOF exceeds n)
    for chain in holders[1:]:
        wrenches[chain][0::4, -1] = wrenches[first][0::4, -1]
    # an actuation wrench along a constraint wrench: every set holding it is rank deficient (its CTI is zero)
    actuation[1::4, 0] = wrenches[first][1::4, -1]
    # a zero actuation wrench (no volume)
    actuation[2::4, 1] = 0.0
    # an actuation wrench dependent on two others
    actuation[3::4, 2] = unit(actuation[3::4, 0] + actuation[3::4, 1])


def accuracy(plan, wrenches, actuation, submechanisms):
    """What the two paths agree to at each configuration: 1e-12, or rounding times the condition number of its
    worst regular system (random constructed wrenches are at times nearly dependent: 1e5 here and there), each
    system the set's actuation wrenches and an orthonormal basis of its subsystem's constraint wrenches."""
    worst = np.ones(COUNT)
    for subsystem in plan.subsystems:
        _, _, right = np.linalg.svd(np.concatenate([wrenches[c] for c in subsystem], axis=1))
        held = right[:, :6 - submechanisms.shape[1]]
        for actuators in submechanisms:
            condition = np.linalg.cond(np.concatenate([actuation[:, actuators], held], axis=1))
            worst = np.maximum(worst, np.where(condition < 1e10, condition, 1.0))  # (a singular one: zero in both)
    return np.maximum(1e-12, 1e-16 * worst)


def both_paths(wrenches, n, actuation, rng):
    """The numpy reference and the compiled stage's indices of one constructed mechanism."""
    chains = [chain_of(w, rng) if w.shape[1] else (rng.standard_normal((COUNT, 6, 6)),
                                                    rng.standard_normal((COUNT, 6, 3))) for w in wrenches]
    twists, points = [t for t, _ in chains], [p for _, p in chains]
    plan = plan_constraints([t[5::8] for t in twists])  # from sample configurations, as the analysis does
    a = actuation.shape[1]
    submechanisms = np.array(list(combinations(range(a), n)), dtype=np.int64)
    faults = submechanisms_left(a, n, tuple(range(1, a - n + 1)))
    threshold = np.full(COUNT, 1e-3)
    stage = compiled_constraint_stage(plan, submechanisms, COUNT)
    assert stage is not None, plan
    arguments = (plan, twists, points, actuation, submechanisms, n, faults, threshold)
    expected, result = constraint_indices(*arguments), constraint_indices(*arguments, None, stage)
    return plan, expected, result, accuracy(plan, wrenches, actuation, submechanisms)


@pytest.mark.parametrize("kind", ["forces", "couples", "mixed", "pairs", "common"])
@pytest.mark.parametrize("singular", [False, True])
def test_constructed_systems_match_numpy(kind, singular):
    """Every CTI of the kernel equals numpy's to 1e-12 (to rounding at nearly dependent wrenches), the same
    instantaneous DOF, no NaN; where the systems are
    singular or rank deficient, the CTI is the value the docs define: zero."""
    rng = np.random.default_rng(["forces", "couples", "mixed", "pairs", "common"].index(kind) + 10 * singular)
    wrenches, n = constructed(kind, rng)
    actuation = unit(rng.standard_normal((COUNT, n + 1, 6)))
    if singular:
        degenerate(wrenches, actuation)
    plan, expected, result, tolerance = both_paths(wrenches, n, actuation, rng)
    assert plan.common == (kind == "common") and (plan.own_counts == (2, 2)) == (kind == "pairs")
    assert np.array_equal(result["instantaneous_dof"], expected["instantaneous_dof"])
    for key in ("cti", "cti_submechanisms", "f_c1"):
        assert not np.isnan(result[key]).any(), key
        difference = np.abs(result[key] - expected[key])
        assert np.all(difference.reshape(COUNT, -1) <= tolerance[:, None]), (key, difference.max())
    assert np.mean(tolerance == 1e-12) > 0.9  # (the rest: nearly dependent wrenches)
    if singular:
        assert np.all(result["cti"][0::4] == 0.0)  # constraint singularities
        assert np.all(result["constraint_singular"][0::4])
        sets = result["cti_submechanisms"]  # every set holding a dependent or a zero actuation wrench
        for rows, actuator in ((slice(1, None, 4), 0), (slice(2, None, 4), 1)):
            with_it = [s for s, sub in enumerate(combinations(range(n + 1), n)) if actuator in sub]
            assert np.all(sets[rows][:, with_it] == 0.0)
    else:
        assert np.all(result["cti"] > 0.0)


@pytest.mark.parametrize("name", ["prs_3_ups", "delta_4", "schoenflies_5"])
def test_analysis_through_the_constraint_kernel_equals_the_numpy_path(name):
    """Every constraint index of 600 random reachable poses in one chunk (the kernels) and in chunks of 100
    (numpy); schoenflies_5 has no CTI (only common couples) and keeps NaN."""
    mechanism = bundled(name)
    poses = random_reachable_poses(mechanism, np.random.default_rng(5), 600, spread=2.0)
    chains, _ = bundled_chain_screws(name, count=20)
    submechanisms = np.array(list(combinations(range(sum(len(c.actuated) for c in chains)), mechanism.dof)))
    compiled = compiled_constraint_stage(constraint_plan_of(chains, 20), submechanisms, poses.shape[0])
    assert (compiled is None) == (name == "schoenflies_5")  # the kernel runs where the CTI applies
    through_kernel = indices_at_poses(mechanism, poses, detail=True, chunk_size=poses.shape[0], threads=1)
    through_numpy = indices_at_poses(mechanism, poses, detail=True, chunk_size=100, threads=1)
    for key in ("cti", "cti_submechanisms", "lmti", "mutual_interference"):
        expected = getattr(through_numpy, key)
        if expected is not None:
            np.testing.assert_allclose(getattr(through_kernel, key), expected, rtol=0, atol=1e-12, equal_nan=True,
                                       err_msg=key)
    for j in through_numpy.f_c:
        np.testing.assert_allclose(through_kernel.f_c[j], through_numpy.f_c[j], rtol=0, atol=1e-12, equal_nan=True)
    assert np.array_equal(through_kernel.instantaneous_dof, through_numpy.instantaneous_dof)
    assert np.array_equal(through_kernel.constraint_singular, through_numpy.constraint_singular)
    assert np.isnan(through_kernel.cti).all() == (name == "schoenflies_5")


def test_a_wrench_common_to_every_chain_stays_common_when_the_mobility_is_known():
    """Given the mobility, the plan reads the wrenches the chains share as theirs only where every sample is a
    constraint singularity (more instantaneous DOF than the mobility): a couple common to three chains that each
    hold a force of their own is still common (the first form of that rule took any mechanism with wrenches of its
    own for singular, and its plan lost the compiled kernel)."""
    rng = np.random.default_rng(4)
    wrenches, n = constructed("common", rng)
    twists = [chain_of(w, rng)[0] for w in wrenches]
    without, given = plan_constraints([t[5::8] for t in twists]), plan_constraints([t[5::8] for t in twists], n)
    assert (given.common, given.own_counts, given.subsystems) == (without.common, without.own_counts,
                                                                    without.subsystems) == (1, (1, 1, 1), ((0, 1, 2),))


def flattened_four_bar(eps: float):
    """A planar four-bar of two R-R dyads onto a coupler, both base pins actuated, its dyads' force lines eps (rad)
    from collinear: (0, 0)-(1, 0.3 eps) and (3, 0)-(2, eps). The out-of-plane couple and force are common to both
    dyads; their in-plane forces alike to eps."""
    from screwkit.screw.chain_screws import ChainScrews

    def revolute(point):
        return np.concatenate([[0.0, 0.0, 1.0], np.cross(point, [0.0, 0.0, 1.0])])

    dyads = (((0.0, 0.0, 0.0), (1.0, 0.3 * eps, 0.0)), ((3.0, 0.0, 0.0), (2.0, eps, 0.0)))
    return [ChainScrews(np.array([revolute(np.array(a)), revolute(np.array(b))]), np.array([a, b]), (0,),
                        name=f"dyad_{k}") for k, (a, b) in enumerate(dyads)]


@pytest.mark.parametrize("eps", [1e-3, 3e-5, 1e-6])
def test_wrenches_only_alike_are_not_common_and_the_truly_common_ones_stay(eps):
    """Below eps 1e-4 the dyads' in-plane forces are alike to MOTION_SPACE_EIGENVALUE, and the plan took four common
    wrenches and none of the chains' own: no CTI alone (NaN), 5.1e-5 in a batch with a regular pose (eps 3e-5). The
    three out-of-plane wrenches stay common, the in-plane forces are each dyad's own; the CTI vanishes linearly with
    eps (CTI / eps the same at every eps), alone as in a batch, and as the numpy reference computes it."""
    from screwkit.indices.analysis import analyze, constraint_structure
    from screwkit.screw.chain_screws import ChainScrews
    from screwkit.screw.reference import reference_indices

    chains = flattened_four_bar(eps)
    plan, _, _ = constraint_structure(chains, dof=1)
    assert (plan.common, plan.own_counts) == (3, (1, 1))
    alone = analyze(chains, dof=1)
    regular = flattened_four_bar(1e-2)
    both = [ChainScrews(np.stack([r.twists, c.twists]), np.stack([r.points, c.points]), (0,), name=c.name)
            for r, c in zip(regular, chains)]
    batch = analyze(both, dof=1)
    assert float(np.asarray(batch.cti)[1]) == pytest.approx(float(alone.cti), abs=1e-12)
    expected = reference_indices([c.twists for c in chains], [c.points for c in chains], [(0,), (0,)], 1)
    assert float(alone.cti) == pytest.approx(expected["cti"], abs=1e-10)
    assert float(alone.cti) / eps == pytest.approx(float(analyze(flattened_four_bar(1e-3), dof=1).cti) / 1e-3,
                                                   rel=2e-3)
