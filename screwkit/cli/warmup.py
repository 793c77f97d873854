"""``screwkit warmup``: compile every kernel ahead (for a CI image, a cluster's workers, a first session)."""

from __future__ import annotations

import time

import click

from screwkit._compile_notice import INDEX_KERNELS, KERNELS, kernel_is_cached

__all__ = ["warmup"]


@click.command()
def warmup() -> None:
    """Compile the index kernel, the planar closed forms, the lower-mobility closure and the batched forward
    kinematics into numba's cache, saying for each whether it was cached and how long it took (later runs load
    them in under a second)."""
    import numpy as np

    from screwkit.closure.chain_kinematics import COMPILED_FROM, chain_forward_kinematics  # idem
    from screwkit.loader import load  # Pinocchio: loaded when the command runs, not for --help
    from screwkit.studies.poses import indices_at_pose, indices_at_poses  # idem

    five = load("planar_5rrr")
    steps = {  # the two index kernels compile together, in two processes
        INDEX_KERNELS: lambda: indices_at_pose(five, five.home_pose),
        ("screwkit._null_kernel",): lambda: indices_at_pose(hexapod := load("ups_hexapod_8"), hexapod.home_pose),
        ("screwkit._gram_kernel",): lambda: indices_at_pose(three := load("five_bar_3"), three.home_pose),
        ("screwkit._planar_kernel",): lambda: indices_at_poses(five, five.home_pose[None], closed_forms=True),
        ("screwkit.closure._task_kernel",): lambda: load("prs_3_ups"),
        ("screwkit.closure._frames_kernel",): lambda: chain_forward_kinematics(
            five.chains[0].geometry, np.zeros((COMPILED_FROM, five.chains[0].geometry.n_dofs))),
    }
    for modules, step in steps.items():
        cached = [kernel_is_cached(module) for module in modules]
        start = time.perf_counter()
        step()
        for module, was_cached in zip(modules, cached):
            click.echo(f"{KERNELS[module][0]:28s} {'cached' if was_cached else 'compiled'} in "
                       f"{time.perf_counter() - start:.1f} s", err=True)
    click.echo("screwkit kernels ready", err=True)
