"""Small chunks through the compiled space and constraint kernels (``screwkit.indices.stages.compiled_chunks``):
what a design search's regions (81 to 1,183 configurations a design) take, instead of numpy's per-call cost. The
indices are numpy's to 1e-12 (numpy, the reference, outside the block), and the kernels do run inside it."""

from __future__ import annotations

import numpy as np
import pytest

import screwkit.indices.compiled.constraints as constraint_module
import screwkit.indices.compiled.spaces as space_module
from helpers import assert_same_indices, bundled
from screwkit.closure import solve
from screwkit.indices.stages import SPACES_COMPILED_FROM, compiled_chunks
from screwkit.studies.design.families import family
from screwkit.studies.design.objectives import default_region, region_maps
from screwkit.studies.poses import indices_at_poses


@pytest.fixture
def kernel_calls(monkeypatch):
    """How many times each compiled kernel runs (each wrapped, then called through)."""
    calls = {"space": 0, "constraint": 0}
    for key, module, name in (("space", space_module, "space_kernel"),
                              ("constraint", constraint_module, "constraint_kernel")):
        kernel = getattr(module, name)

        def counted(*arguments, _kernel=kernel, _key=key):
            calls[_key] += 1
            return _kernel(*arguments)

        monkeypatch.setattr(module, name, counted)
    return calls


def near_home(name: str, count: int):
    mechanism = bundled(name)
    rng = np.random.default_rng(5)
    span = np.array([0.05 * mechanism.length_scale if coordinate in ("x", "y", "z") else 0.1
                     for coordinate in mechanism.task_coordinates])
    poses = mechanism.home_pose + rng.uniform(-1.0, 1.0, (4 * count, mechanism.n_task)) * span
    return mechanism, poses[solve(mechanism, poses).reachable][:count]


@pytest.mark.parametrize("name", ["prs_3_ups", "delta_4"])
def test_a_small_chunk_in_the_block_takes_the_kernels_and_gives_numpy_s_indices(name, kernel_calls):
    mechanism, poses = near_home(name, 120)
    assert poses.shape[0] < SPACES_COMPILED_FROM
    through_numpy = indices_at_poses(mechanism, poses, detail=True, threads=1)
    assert kernel_calls == {"space": 0, "constraint": 0}
    with compiled_chunks():
        through_kernels = indices_at_poses(mechanism, poses, detail=True, threads=1)
    assert kernel_calls["space"] >= 1 and kernel_calls["constraint"] >= 1
    assert_same_indices(through_kernels, through_numpy)


def test_the_block_ends_even_when_its_work_fails(kernel_calls):
    mechanism, poses = near_home("prs_3_ups", 40)
    with pytest.raises(RuntimeError), compiled_chunks(), compiled_chunks():
        raise RuntimeError("a study that fails inside the block")
    indices_at_poses(mechanism, poses, threads=1)
    assert kernel_calls == {"space": 0, "constraint": 0}


def test_a_design_region_is_mapped_through_the_kernels_with_numpy_s_values(kernel_calls, monkeypatch):
    """A Delta design's region (289 configurations): its maps through the kernels (region_maps opens the block)
    equal those the map machinery computes without it, chunk by chunk in numpy."""
    import contextlib

    import screwkit.studies.design.objectives as objectives

    delta = family("delta")
    region = default_region(delta)
    mechanism = delta.mechanism({})
    maps = region_maps(mechanism, region)
    assert kernel_calls["space"] >= 1
    monkeypatch.setattr(objectives, "compiled_chunks", contextlib.nullcontext)  # the numpy reference
    reference = region_maps(mechanism, region)
    assert maps.keys() == reference.keys()
    for key in reference:
        np.testing.assert_allclose(maps[key], reference[key], rtol=0, atol=1e-12, equal_nan=True, err_msg=key)
