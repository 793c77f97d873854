"""Which compiled kernels a study of a mechanism will use beyond the index kernels, so that a command of many poses
compiles them ahead (:func:`~screwkit.common.compiling.compile_ahead`) while it loads and solves, and no other."""

from __future__ import annotations

import numpy as np

from screwkit.closure import chain_screws, solve
from screwkit.common.compiling import CONSTRAINT_KERNEL, SPACE_KERNEL, stage_kernels
from screwkit.indices.analysis import constraint_structure
from screwkit.indices.stages import square_subsystems
from screwkit.model import Mechanism
from screwkit.studies.poses import output_points

__all__ = ["constraint_kernels", "mechanism_kernels"]


def mechanism_kernels(mechanism: Mechanism, *, batches: bool = True) -> tuple[str, ...]:
    """The kernels beyond the index kernels that this mechanism's indices need: those of its actuated chains'
    joint counts (:func:`~screwkit.common.compiling.stage_kernels`) and, for ``batches`` of many poses,
    :func:`constraint_kernels`."""
    return (stage_kernels([chain.geometry.n_dofs for chain in mechanism.chains if chain.actuated], mechanism.dof)
            + (constraint_kernels(mechanism) if batches else ()))


def constraint_kernels(mechanism: Mechanism) -> tuple[str, ...]:
    """The kernels that large chunks of this mechanism's configurations use beyond the index kernels, for
    :func:`~screwkit.common.compiling.compile_ahead`: the space kernel when the motion space changes with the
    configuration (a point output's idle rotations included, as
    :func:`~screwkit.studies.poses.analyze_solution` adds them) or some chain holds constraint wrenches of its own,
    and the constraint kernel when, moreover, the constraint subsystems are square
    (:func:`~screwkit.indices.stages.square_subsystems`). Found at the home pose and 8 poses about it (seeded);
    both when fewer than two of them assemble or the structure cannot be found (a kernel not compiled ahead is
    compiled when first used)."""
    try:
        return _constraint_kernels(mechanism)
    except Exception:  # a hint for compiling ahead, never an error: the command reports what is wrong itself
        return SPACE_KERNEL, CONSTRAINT_KERNEL


def _constraint_kernels(mechanism: Mechanism) -> tuple[str, ...]:
    span = np.where(mechanism.angular, 0.02, 0.01 * mechanism.length_scale)
    poses = mechanism.home_pose + np.random.default_rng(0).uniform(-1.0, 1.0, (9, mechanism.n_task)) * span
    poses[0] = mechanism.home_pose
    solution = solve(mechanism, poses)
    if np.count_nonzero(solution.reachable) < 2:
        return SPACE_KERNEL, CONSTRAINT_KERNEL
    options = {}
    points = output_points(mechanism, solution.full_poses)
    if points is not None:  # as analyze_solution
        options = dict(output_point=points[np.asarray(solution.reachable)],
                       planar=mechanism.rotation_world_base[:, 2] if mechanism.is_planar else False)
    plan, n, constant = constraint_structure(chain_screws(mechanism, solution, unreachable="drop"), dof=mechanism.dof,
                                             **options)
    if constant and not plan.count:
        return ()
    return (SPACE_KERNEL, CONSTRAINT_KERNEL) if plan.count and square_subsystems(plan, n) else (SPACE_KERNEL,)
