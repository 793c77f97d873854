"""The compiled forward kinematics and closure of the constraining chains, against independent numpy computations."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from screwkit.closure.chain_kinematics import chain_forward_kinematics
from screwkit.closure.compiled import frames as frames
from screwkit.closure.compiled import task as kernel
from screwkit.closure.newton import pose_error
from screwkit.closure.task_space import complete_poses, constraining_chains, pose_rates
from screwkit.closure.threads import thread_limit
from screwkit.common.rotations import rotation_from_rotation_vector, rotation_vector_from_rotation
from screwkit.io.loader import load

LOWER_MOBILITY = ("prs_3_ups", "delta_4", "schoenflies_5")


def random_rotation_vectors(rng, count):
    axes = rng.normal(size=(count, 3))
    axes /= np.linalg.norm(axes, axis=-1, keepdims=True)
    angles = np.concatenate([rng.uniform(0.0, np.pi, count - 6), [0.0, 1e-9, 1e-5, np.pi - 1e-4, np.pi - 1e-7, np.pi]])
    return axes * angles[:, None]


def test_compiled_exp_and_log_equal_the_numpy_maps_small_angles_and_near_pi_included():
    rng = np.random.default_rng(3)
    for vector in random_rotation_vectors(rng, 60):
        rotation = np.array(frames.exp_map(*vector)).reshape(3, 3)
        np.testing.assert_allclose(rotation, rotation_from_rotation_vector(vector), atol=1e-14)
        logged = np.array(frames.log_map(tuple(rotation.ravel())))
        expected = rotation_vector_from_rotation(rotation)
        # at exactly pi the vector and its opposite are the same rotation
        assert np.allclose(logged, expected, atol=1e-9) or np.allclose(logged, -expected, atol=1e-9)
        np.testing.assert_allclose(np.array(frames.exp_map(*logged)).reshape(3, 3), rotation, atol=1e-12)


FRAMES = ("axes", "points", "leg_rotation", "leg_translation", "end_rotation", "end_translation")
BUNDLED = ("planar_5rrr", "planar_4rpr", "five_bar_3", "ups_hexapod_8", "rss_hexapod_8", "prs_3_ups", "delta_4",
           "schoenflies_5", "coop_arms")


def loop_variants(geometry):
    """The chain closed by every loop joint type in turn (axes: the platform frame's, unit)."""
    axes = {"fixed": np.zeros((0, 3)), "revolute": np.array([[0.0, 0.6, 0.8]]),
            "prismatic": np.array([[0.0, 0.6, 0.8]]), "universal": np.array([[1.0, 0.0, 0.0], [0.0, 0.6, 0.8]]),
            "spherical": np.eye(3)}
    return [replace(geometry, loop_type=kind, loop_axes=value) for kind, value in axes.items()]


@pytest.mark.parametrize("name", BUNDLED)
def test_compiled_forward_kinematics_equals_numpy_for_every_chain_and_loop_type(name):
    """Random joint values, batch of any shape, read-only input: the kernel gives numpy's frames."""
    rng = np.random.default_rng(11)
    for chain in load(name).chains:
        for geometry in loop_variants(chain.geometry):
            values = rng.uniform(-3.0, 3.0, (4, 150, geometry.n_dofs))
            values.flags.writeable = False
            numpy_frames = chain_forward_kinematics(geometry, values, compiled=False)
            compiled = chain_forward_kinematics(geometry, values, compiled=True)
            for field in FRAMES:
                expected = getattr(numpy_frames, field)
                assert getattr(compiled, field).shape == expected.shape, (chain.name, geometry.loop_type, field)
                np.testing.assert_allclose(getattr(compiled, field), expected, rtol=0, atol=1e-13,
                                           err_msg=f"{chain.name} {geometry.loop_type} {field}")
    assert len(frames.chain_frames_kernel.signatures) == 1


def test_large_batches_go_through_the_compiled_forward_kinematics(monkeypatch):
    """The default path by batch size: numpy below COMPILED_FROM, the kernel from it on."""
    from screwkit.closure import chain_kinematics

    geometry = load("ups_hexapod_8").chains[0].geometry
    calls = []
    original = chain_kinematics._compiled_frames
    monkeypatch.setattr(chain_kinematics, "_compiled_frames", lambda *a: calls.append(a) or original(*a))
    chain_forward_kinematics(geometry, np.zeros((chain_kinematics.COMPILED_FROM - 1, geometry.n_dofs)))
    assert not calls
    chain_forward_kinematics(geometry, np.zeros((chain_kinematics.COMPILED_FROM, geometry.n_dofs)))
    assert len(calls) == 1


@pytest.mark.parametrize("name", ["prs_3_ups", "planar_5rrr"])
def test_compiled_platform_frame_and_pose_rates_equal_the_mechanism_model(name):
    mechanism = load(name)
    rng = np.random.default_rng(4)
    poses = mechanism.home_full_pose + rng.uniform(-0.4, 0.4, (20, mechanism.n_pose))
    rotation, translation = mechanism.transforms_from_poses(poses)
    free = np.arange(mechanism.n_pose, dtype=np.int64)
    for pose, expected_rotation, expected_translation, expected_rates in zip(
            poses, rotation, translation, pose_rates(mechanism, poses)):
        got_rotation, got_translation = kernel._platform(pose, mechanism.is_planar, mechanism.home_translation[2])
        np.testing.assert_allclose(np.array(got_rotation).reshape(3, 3), expected_rotation, atol=1e-15)
        np.testing.assert_allclose(got_translation, expected_translation, atol=1e-15)
        rates = np.empty((6, mechanism.n_pose))
        kernel._pose_rates(pose, mechanism.is_planar, free, rates)
        np.testing.assert_allclose(rates, expected_rates, atol=1e-15)


def task_samples(mechanism, count, seed):
    """Task poses around the reference assembly (0.3 rad, 0.15 length scales)."""
    rng = np.random.default_rng(seed)
    home = mechanism.task_poses(mechanism.home_full_pose)
    spread = np.where(mechanism.angular, 0.3, 0.15 * mechanism.length_scale)
    return home + rng.uniform(-1.0, 1.0, (count, mechanism.n_task)) * spread


@pytest.mark.parametrize("name", LOWER_MOBILITY)
def test_completed_poses_close_every_constraining_chain_in_numpy_forward_kinematics(name):
    mechanism = load(name)
    tasks = task_samples(mechanism, 200, 5)
    full, values, converged, residual = complete_poses(mechanism, tasks)
    assert converged.mean() > 0.5, f"{name}: {converged.mean():.2f} of the samples closed"
    np.testing.assert_allclose(mechanism.task_poses(full[converged]), tasks[converged], atol=1e-12)
    rotation, translation = mechanism.transforms_from_poses(full[converged])
    for index, chain_values in zip(constraining_chains(mechanism), values):
        frames = chain_forward_kinematics(mechanism.chains[index].geometry, chain_values[converged])
        target_rotation, target_translation = mechanism.loop_targets(index, rotation, translation)
        error = pose_error(target_rotation, target_translation, frames.end_rotation, frames.end_translation)
        assert np.linalg.norm(error, axis=-1).max() < 1e-10
    assert np.all(residual[converged] < 1e-11) and np.all(residual[~converged] >= 1e-11)


@pytest.mark.parametrize("name", LOWER_MOBILITY)
def test_each_pose_is_completed_as_if_alone_whatever_the_batch_and_the_threads(name):
    mechanism = load(name)
    tasks = task_samples(mechanism, 40, 6)
    full, values, converged, _ = complete_poses(mechanism, tasks)
    with thread_limit(1):
        one_thread = complete_poses(mechanism, tasks[::-1])
    np.testing.assert_array_equal(one_thread[0][::-1], full)
    for pose_index in (0, 17, 39):
        alone = complete_poses(mechanism, tasks[pose_index:pose_index + 1])
        assert alone[2][0] == converged[pose_index]
        np.testing.assert_array_equal(alone[0][0], full[pose_index])
        for chain_values, alone_values in zip(values, alone[1]):
            np.testing.assert_array_equal(alone_values[0], chain_values[pose_index])


def test_every_caller_uses_one_compiled_signature_of_the_kernel():
    """Each new argument type (a read-only array, another dtype) would compile the kernel again (about 15 s)."""
    for name in LOWER_MOBILITY:
        mechanism = load(name)
        complete_poses(mechanism, task_samples(mechanism, 1, 7))
        complete_poses(mechanism, task_samples(mechanism, 5, 8))
    assert len(kernel.close_chains_kernel.signatures) == 1
