"""Bad input to the core gets a ValueError naming the argument, what was expected and what arrived."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from helpers import random_planar_rrr
from screwkit.indices.analysis import analyze
from screwkit.screw.chain_screws import ChainScrews
from screwkit.screw.planar import PlanarDesign, platform_points, rrr_chain_screws


@pytest.fixture
def chains(rng):
    return rrr_chain_screws(*random_planar_rrr(rng, 4, 5))


def test_wrong_twist_shape():
    with pytest.raises(ValueError, match=r"`twists` with shape \(\.\.\., m, 6\), got \(3, 5\)"):
        ChainScrews(np.zeros((3, 5)), np.zeros((3, 3)), (0,))


def test_points_do_not_match_joints():
    with pytest.raises(ValueError, match=r"one point per joint \(3\) of chain 'leg', got shape \(2, 3\)"):
        ChainScrews(np.zeros((3, 6)), np.zeros((2, 3)), (0,), "leg")


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_nan_and_inf(bad):
    twists = np.zeros((3, 6))
    twists[1, 4] = bad
    with pytest.raises(ValueError, match=rf"finite values in `twists`, got {bad} at index \(1, 4\)"):
        ChainScrews(twists, np.zeros((3, 3)), (0,))


def test_actuator_index_outside_its_chain():
    with pytest.raises(ValueError, match=r"actuated joint indices of chain 'leg' in 0\.\.2, got 3"):
        ChainScrews(np.zeros((3, 6)), np.zeros((3, 3)), (3,), "leg")


def test_fewer_actuators_than_dof(chains):
    with pytest.raises(ValueError, match=r"at least n = 3 actuators \(the platform's DOF\), got 2"):
        analyze(chains[:2] + [ChainScrews(c.twists, c.points, ()) for c in chains[2:]])


@pytest.mark.parametrize("faults", [0, 3, -1])
def test_faults_outside_range(chains, faults):
    with pytest.raises(ValueError, match=rf"number of faults `j` in 1\.\.a-n = 1\.\.2, got {faults}"):
        analyze(chains, faults=faults)


def test_mismatched_batches(rng, chains):
    other = rrr_chain_screws(*random_planar_rrr(rng, 3, 1))
    with pytest.raises(ValueError, match=r"share the batch shape \(4,\), chain 'chain_1' has \(3,\)"):
        analyze(chains[:4] + other)


def test_bad_options(chains):
    with pytest.raises(ValueError, match=r"`threshold` >= 0"):
        analyze(chains, threshold=-1.0)
    with pytest.raises(ValueError, match=r"`chunk_size` >= 1, got 0"):
        analyze(chains, chunk_size=0)
    with pytest.raises(ValueError, match=r"`oti_points` with shape \(\.\.\., 5, 3\), got \(2, 3\)"):
        analyze(chains, oti_points=np.zeros((2, 3)))
    with pytest.raises(ValueError, match=r"Expected at least one chain"):
        analyze([])


def test_planar_inputs():
    with pytest.raises(ValueError, match=r"`poses` with shape \(\.\.\., 3\), got \(2,\)"):
        platform_points(np.zeros(2), np.zeros((5, 2)))
    with pytest.raises(ValueError, match=r"`working_mode` entries \+1 or -1"):
        PlanarDesign(np.zeros((2, 2)), np.zeros((2, 2)), 1.0, 1.0, 0.0)
    with pytest.raises(ValueError, match=r"positive arm lengths"):
        PlanarDesign(np.zeros((2, 2)), np.zeros((2, 2)), -1.0, 1.0, 1.0)


def test_lmti_of_checks_its_set(chains):
    result = analyze(chains)
    np.testing.assert_array_equal(result.lmti_of([0, 1]), 0.0)  # fewer than n actuators hold nothing
    with pytest.raises(ValueError, match=r"Expected an actuator index in 0\.\.4, got 9"):
        result.lmti_of([0, 1, 9])


def test_core_imports_numpy_only():
    """The math core pulls in none of the edge dependencies."""
    code = ("import sys; import screwkit.indices.analysis, screwkit.indices.closed_forms, screwkit.screw.planar, "
            "screwkit.screw.algebra; "
            "bad = [m for m in ('pinocchio', 'matplotlib', 'dask', 'meshcat', 'xarray', 'numba', 'yourdfpy', 'sympy', "
            "'scipy') if m in sys.modules]; print(bad); sys.exit(1 if bad else 0)")
    completed = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert completed.returncode == 0, completed.stdout + completed.stderr
