"""The integer codes the compiled kernels read are enums at the Python level: each member means what the kernel
does with its value (the kernels compare plain integers, so the agreement is checked by what they compute)."""

from __future__ import annotations

import numpy as np
import pytest
from test_kinematics import random_loops_mechanism

from screwkit.closure import solve
from screwkit.closure.analytic import KernelKind
from screwkit.closure.chain_kinematics import COMPILED_FROM, LOOP_CODES, LoopCode, chain_forward_kinematics
from screwkit.closure.solve import MISSES_CLOSURE, OUTSIDE_LIMITS, REACHABLE, ChainStatus
from screwkit.io.loader import load
from screwkit.model.chain import LOOP_JOINT_DOFS


def test_every_loop_joint_type_has_a_code_and_the_packed_geometry_holds_plain_integers():
    assert set(LOOP_CODES) == set(LOOP_JOINT_DOFS)
    assert set(LOOP_CODES.values()) == set(LoopCode)
    assert [int(code) for code in LoopCode] == [0, 1, 2, 3, 4]
    mechanism = random_loops_mechanism()
    packed = mechanism.chains[0].closed_form.packed if mechanism.chains[0].closed_form else None
    from screwkit.closure.chain_kinematics import packed_chains

    packed = packed_chains([chain.geometry for chain in mechanism.chains])
    assert packed["loop_code"].dtype == np.int64
    assert packed["loop_code"].tolist() == [int(LOOP_CODES[chain.loop_type]) for chain in mechanism.chains]


def test_the_compiled_forward_kinematics_reads_every_loop_code_as_its_joint_type():
    """A chain closed by each loop joint type, through the compiled kernel (a large batch) and numpy (one row)."""
    mechanism = random_loops_mechanism()
    assert {LOOP_CODES[chain.loop_type] for chain in mechanism.chains} == set(LoopCode) - {LoopCode.FIXED} | (
        {LoopCode.FIXED} if any(chain.loop_type == "fixed" for chain in mechanism.chains) else set())
    rng = np.random.default_rng(3)
    for chain in mechanism.chains:
        geometry = chain.geometry
        values = chain.reference_values + rng.normal(scale=0.2, size=(COMPILED_FROM, chain.n_joints))
        compiled = chain_forward_kinematics(geometry, values)
        for row in (0, COMPILED_FROM // 2, COMPILED_FROM - 1):
            single = chain_forward_kinematics(geometry, values[row:row + 1])
            np.testing.assert_allclose(compiled.axes[row], single.axes[0], rtol=0, atol=1e-12)
            np.testing.assert_allclose(compiled.points[row], single.points[0], rtol=0, atol=1e-12)


@pytest.mark.parametrize("name, kind", [("ups_hexapod_8", KernelKind.UPS), ("rss_hexapod_8", KernelKind.RUS)])
def test_the_compiled_closed_form_reads_the_kernel_kind_as_its_chain_type(name, kind):
    mechanism = load(name)
    solver = mechanism.chains[0].closed_form
    assert solver.kernel_kind is kind and KernelKind.NONE < kind
    rng = np.random.default_rng(5)
    poses = mechanism.home_pose + rng.normal(scale=[0.02, 0.02, 0.02, 0.05, 0.05, 0.1], size=(600, 6))
    from screwkit.closure.solve import _PoseCache

    cache = _PoseCache(mechanism, poses)
    compiled = solver.solve_compiled(*cache.platform, (1.0, 1.0))
    reference = solver.solve(*mechanism.loop_targets(0, *cache.platform), (1.0, 1.0))
    assert compiled.reachable.any()
    np.testing.assert_array_equal(compiled.reachable, reference.reachable)
    np.testing.assert_allclose(compiled.points, reference.points, rtol=0, atol=1e-12)


def test_chain_status_codes():
    assert (REACHABLE, MISSES_CLOSURE, OUTSIDE_LIMITS) == tuple(ChainStatus) == (0, 1, 2)
    mechanism = load("planar_5rrr")
    solution = solve(mechanism, np.array([mechanism.home_pose, [5.0, 0.0, 0.0]]))
    assert solution.status.dtype == np.int8
    assert np.all(solution.status[0] == ChainStatus.REACHABLE)
    assert np.all(solution.status[1] == ChainStatus.MISSES_CLOSURE)
