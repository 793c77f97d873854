"""The bundled rod-level Delta ``delta_rods_4``: ``delta_4``'s geometry with each forearm a parallelogram of two
ball-jointed rods, as industrial Deltas are built, opened as a closed-loop graph.

Checked against the bundled R-U-U model ``delta_4``, an independent model (serial legs, closed by another solver)
of the same platform positions: the indices that need only the rod forces and a translating platform (ITI per
actuator, OTI of every submechanism, LMTI, F_O1, F_IO1) are the same at every pose (<= 1e-9); the constraint
indices are not. The rod-level CTI is the one of the parallelogram's constraint couples a_i x u_i (a the motor
axis, u the rods' direction, read from delta_4's solved joints), computed here from them with numpy; delta_4's is
that of its R-U-U couples a_i x w_i (tests/test_constraints.py). MuJoCo reads the file as screwkit does.
"""

from __future__ import annotations

import numpy as np
import pytest
from test_gallery import assert_same_bodies, mujoco_residuals, mujoco_state

from helpers import couple_cti, screwkit
from screwkit.closure import chain_screws, solve
from screwkit.io import graph_mechanism, read_closed_tree
from screwkit.io.loader import bundled_path, load
from screwkit.studies.poses import graph_indices_at_poses, indices_at_poses

TOLERANCE = 1e-9


def poses(mechanism) -> np.ndarray:
    """delta_4's named poses and random ones about its home."""
    named = np.array(list(mechanism.named_poses.values()))
    spread = np.random.default_rng(11).uniform(-1.0, 1.0, (12, 3)) * np.array([0.15, 0.15, 0.15])
    return np.vstack([named, mechanism.home_pose + spread])


@pytest.fixture(scope="module")
def models():
    return load("delta_4"), graph_mechanism(read_closed_tree(bundled_path("delta_rods_4")))


def test_mujoco_reads_the_bundled_rod_level_delta_as_screwkit_does(models):
    path = bundled_path("delta_rods_4")
    mj_model, mj_data = mujoco_state(path)
    tree = models[1].tree
    assert_same_bodies(tree, mj_model, mj_data, tree.q_reference)
    assert max(np.max(np.abs(r)) for r in mujoco_residuals(mj_model, mj_data).values()) < TOLERANCE
    np.testing.assert_allclose(models[1].task_pose(), models[0].home_pose, atol=1e-12)  # the platform's centre


def test_the_rod_level_delta_has_delta_4_s_actuation_indices_and_the_parallelogram_s_cti(models):
    mechanism, graph = models
    targets = poses(mechanism)
    serial = indices_at_poses(mechanism, targets, detail=True)
    rods = graph_indices_at_poses(graph, targets, detail=True)
    assert serial.reachable.all() and rods.reachable.all()
    for name in ("iti_actuators", "oti_submechanisms", "lmti", "iti"):
        np.testing.assert_allclose(getattr(rods, name), getattr(serial, name), atol=TOLERANCE, err_msg=name)
    np.testing.assert_allclose(rods.f_o[1], serial.f_o[1], atol=TOLERANCE)
    np.testing.assert_allclose(rods.f_io[1], serial.f_io[1], atol=TOLERANCE)
    chains = chain_screws(mechanism, solve(mechanism, targets))
    for n in range(len(targets)):
        axes = np.array([chain.twists[n, 0, :3] for chain in chains])
        rods_direction = np.array([chain.points[n, -1] - chain.points[n, 1] for chain in chains])
        expected = couple_cti(np.cross(axes, rods_direction))
        assert abs(rods.cti[n] - expected) < TOLERANCE, n
    assert np.min(np.abs(rods.cti - serial.cti)) > 0.05  # what the R-U-U model changed: the constraint couples


def test_the_command_line_analyses_the_bundled_rod_level_delta_by_name():
    completed = screwkit("analyze", "delta_rods_4", "--json")
    assert completed.returncode == 0, completed.stderr
    serial = screwkit("analyze", "delta_4", "--json")
    import json

    rods_report, serial_report = json.loads(completed.stdout), json.loads(serial.stdout)
    assert rods_report["lmti"] == pytest.approx(serial_report["lmti"], abs=TOLERANCE)
    assert rods_report["cti"] > serial_report["cti"] + 0.1
    info = screwkit("info", "delta_rods_4")
    assert info.returncode == 0 and "task coordinates: x (m), y (m), z (m)" in info.stdout
