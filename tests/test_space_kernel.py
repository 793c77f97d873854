"""The compiled chain decompositions and motion spaces (:mod:`screwkit.indices.compiled.spaces`) against their
numpy reference (:func:`screwkit.screw.motion.chain_decompositions`, :func:`screwkit.screw.motion.null_spaces`),
on random chains and on degenerate ones: a chain at a serial singularity (dependent joint twists), a zero joint
twist, chains that share a constraint (a constraint singularity of the whole) and badly scaled twists; and the
analysis of a bundled lower-mobility mechanism through the kernel (chunks of 512 configurations or more) against
the numpy path (smaller chunks)."""

from __future__ import annotations

import numpy as np
import pytest

from helpers import assert_same_indices, bundled
from screwkit.closure import solve
from screwkit.common import tolerances
from screwkit.indices.compiled.spaces import space_kernel
from screwkit.indices.stages import SPACES_COMPILED_FROM
from screwkit.screw.motion import chain_decompositions, chain_projector_complements, null_spaces
from screwkit.studies.poses import indices_at_poses

TOLERANCE = tolerances.MOTION_SPACE_TOLERANCE


def compiled(chains):
    """The kernel on a list of (N, m_i, 6) twist arrays: singular values, right vectors, eigenvalues, vectors."""
    count = chains[0].shape[0]
    start = np.cumsum([0] + [chain.shape[1] for chain in chains]).astype(np.int64)
    out = (np.empty((len(chains), count, 6)), np.empty((len(chains), count, 6, 6)), np.empty((count, 6)),
           np.empty((count, 6, 6)))
    space_kernel(np.concatenate(chains, axis=1), start, TOLERANCE, *out)
    return out


def projector(rows):
    return np.swapaxes(rows, -1, -2) @ rows


def degenerate_chains(rng, count):
    """Random chains of 3 to 7 joints, with every kind of degenerate configuration among them."""
    sizes = (5, 5, 6, 3, 7, 4)
    chains = [rng.standard_normal((count, m, 6)) for m in sizes]
    chains[0][1::4, 4] = 2.0 * chains[0][1::4, 0] - chains[0][1::4, 2]  # a serial singularity: dependent twists
    chains[1][2::4, 3] = 0.0  # a zero joint twist
    chains[3][3::4] = chains[3][3::4] * np.array([1e-7, 1e-7, 1e-7, 1.0, 1.0, 1.0])  # badly scaled twists
    # a constraint shared by two chains (their twists in one 5-D space: the complement of a common wrench)
    common = rng.standard_normal((count, 6))
    common /= np.linalg.norm(common, axis=-1, keepdims=True)
    for chain in (0, 1):
        rows = chains[chain][::4]
        chains[chain][::4] = rows - (rows @ common[::4, :, None]) * common[::4, None, :]
    return chains


@pytest.mark.parametrize("seed", [0, 1])
def test_decompositions_match_numpy(seed):
    """Singular values to rounding, the same rank at every configuration, and the complement of each chain's
    twists (the trailing right singular vectors, what the motion space and the constraint wrenches use) spanning
    the same space, including at the degenerate configurations."""
    rng = np.random.default_rng(seed)
    chains = degenerate_chains(rng, 400)
    singular, right, _, _ = compiled(chains)
    for c, (expected_singular, expected_right) in enumerate(chain_decompositions(chains)):
        np.testing.assert_allclose(singular[c], expected_singular, rtol=0, atol=1e-13, err_msg=f"chain {c}")
        np.testing.assert_allclose(right[c] @ np.swapaxes(right[c], -1, -2), np.broadcast_to(np.eye(6), right[c].shape),
                                   atol=1e-13)
        rank = np.sum(expected_singular > TOLERANCE * expected_singular[:, :1], axis=-1)
        assert np.array_equal(rank, np.sum(singular[c] > TOLERANCE * singular[c][:, :1], axis=-1))
        for nullity in np.unique(6 - rank):
            rows = np.flatnonzero(6 - rank == nullity)
            if nullity:
                np.testing.assert_allclose(projector(right[c][rows, 6 - nullity:]),
                                           projector(expected_right[rows, 6 - nullity:]), atol=1e-12,
                                           err_msg=f"chain {c}, nullity {nullity}")


def test_motion_spaces_match_numpy():
    """The eigenvalues of sum_i (I - P_i) to rounding, and the motion spaces (the eigenvectors of eigenvalues at
    most MOTION_SPACE_EIGENVALUE) the same spaces of the same dimension, on chains of a 3-DoF platform."""
    rng = np.random.default_rng(4)
    count, dof = 300, 3
    motion = np.linalg.qr(rng.standard_normal((count, 6, dof)))[0]  # (N, 6, 3): each configuration's motion space
    chains = []
    for m in (5, 5, 4, 6):
        extra = rng.standard_normal((count, m - dof, 6))
        chains.append(np.concatenate([np.swapaxes(motion @ rng.standard_normal((count, dof, dof)), -1, -2), extra],
                                     axis=1))
    chains[3][:] = rng.standard_normal(chains[3].shape)  # a six-DoF chain: no constraint
    chains[0][::5, 4] = chains[0][::5, 3]  # a serial singularity of one chain
    _, _, values, vectors = compiled(chains)
    decompositions = chain_decompositions(chains)
    expected_values, _ = np.linalg.eigh(chain_projector_complements(chains, TOLERANCE, decompositions))
    # known to rounding over the conditioning: of each chain's complement, its smallest nonzero singular value
    # (0.002 at worst here); of the motion space, the smallest nonzero eigenvalue
    smallest = np.min([np.where(s > TOLERANCE * s[:, :1], s, np.inf).min(axis=-1) for s, _ in decompositions], axis=0)
    accuracy = 1e-14 / np.minimum(smallest, expected_values[:, dof])[:, None]
    assert np.all(np.abs(values - expected_values) <= accuracy)
    dims, bases = null_spaces(chains, None, TOLERANCE)
    assert np.all(dims == np.sum(values <= tolerances.MOTION_SPACE_EIGENVALUE, axis=-1))
    assert np.all(np.abs(projector(np.swapaxes(vectors[..., :dof], -1, -2)) - projector(bases))
                  <= accuracy[:, :, None])
    np.testing.assert_allclose(projector(bases), projector(np.swapaxes(motion, -1, -2)), atol=1e-12)


@pytest.mark.parametrize("name", ["prs_3_ups", "delta_4", "schoenflies_5"])
def test_analysis_through_the_kernel_equals_the_numpy_path(name):
    """Every index of 600 random reachable poses in one chunk (the kernel) and in chunks of 100 (numpy)."""
    mechanism = bundled(name)
    rng = np.random.default_rng(3)
    span = np.array([0.05 * mechanism.length_scale if coordinate in ("x", "y", "z") else 0.1
                     for coordinate in mechanism.task_coordinates])
    poses = mechanism.home_pose + rng.uniform(-1.0, 1.0, (2400, mechanism.n_task)) * span
    poses = poses[solve(mechanism, poses).reachable][:600]
    assert poses.shape[0] >= SPACES_COMPILED_FROM
    through_kernel = indices_at_poses(mechanism, poses, detail=True, chunk_size=poses.shape[0], threads=1)
    through_numpy = indices_at_poses(mechanism, poses, detail=True, chunk_size=100, threads=1)
    assert_same_indices(through_kernel, through_numpy)
