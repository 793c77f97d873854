"""``screwkit warmup``: compile every kernel ahead (for a CI image, a cluster's workers, a first session)."""

from __future__ import annotations

import time

import click

from screwkit.common.compiling import (
    CLOSED_FORM_KERNEL,
    CONSTRAINT_KERNEL,
    GRAM_KERNEL,
    INDEX_KERNELS,
    KERNELS,
    NULL_KERNEL,
    SPACE_KERNEL,
    compile_ahead,
    kernel_is_cached,
    silence,
)

__all__ = ["warmup"]


@click.command()
def warmup() -> None:
    """Compile the index kernels, the planar and spatial closed forms, the lower-mobility closure and the batched
    forward kinematics into numba's cache, saying for each whether it was cached and when it was ready (later runs
    load them in under a second). The index kernels and the spatial closed forms compile in child processes, two
    at a time on two cores, while the others compile in this one."""
    import numpy as np

    from screwkit.closure import solve  # numba: when run, not for --help
    from screwkit.closure.chain_kinematics import COMPILED_FROM, chain_forward_kinematics  # idem
    from screwkit.io.loader import load  # Pinocchio: loaded when the command runs, not for --help
    from screwkit.studies.poses import indices_at_pose, indices_at_poses  # idem

    start = time.perf_counter()
    cached = {module: kernel_is_cached(module) for module in KERNELS}
    missing = [KERNELS[module][0] for module in KERNELS if not cached[module]]
    if missing:  # said here, for the notices of the kernels compiled below would point at this very command
        click.echo(f"screwkit warmup: compiling {len(missing)} of {len(KERNELS)} kernels, not in numba's cache yet "
                   f"({', '.join(missing)}; first run only, a minute or two)", err=True)
    silence()
    compile_ahead(*INDEX_KERNELS, NULL_KERNEL, GRAM_KERNEL, SPACE_KERNEL, CONSTRAINT_KERNEL, CLOSED_FORM_KERNEL)
    five, hexapod = load("planar_5rrr"), load("ups_hexapod_8")
    steps = {  # the kernels compiled here first, while the child processes compile the index kernels
        ("screwkit.indices.compiled.planar",): lambda: indices_at_poses(five, five.home_pose[None], closed_forms=True),
        # (a mechanism read back from the cache of loaded mechanisms is not assembled again: solve a pose)
        ("screwkit.closure.compiled.task",): lambda: solve(prs := load("prs_3_ups"), prs.home_pose[None]),
        ("screwkit.closure.compiled.frames",): lambda: chain_forward_kinematics(
            five.chains[0].geometry, np.zeros((COMPILED_FROM, five.chains[0].geometry.n_dofs))),
        INDEX_KERNELS: lambda: indices_at_pose(five, five.home_pose),
        (NULL_KERNEL,): lambda: indices_at_pose(hexapod, hexapod.home_pose),
        (CLOSED_FORM_KERNEL,): lambda: solve(hexapod, np.repeat(hexapod.home_pose[None], COMPILED_FROM, axis=0)),
        (GRAM_KERNEL,): lambda: indices_at_pose(three := load("five_bar_3"), three.home_pose),
        (SPACE_KERNEL, CONSTRAINT_KERNEL): lambda: indices_at_poses(
            prs := load("prs_3_ups"), np.repeat(prs.home_pose[None], COMPILED_FROM, axis=0), threads=1),
    }
    for modules, step in steps.items():
        step()
        for module in modules:
            click.echo(f"{KERNELS[module][0]:28s} {'cached' if cached[module] else 'compiled'}, ready after "
                       f"{time.perf_counter() - start:.1f} s", err=True)
    click.echo("screwkit kernels ready", err=True)
