"""Whether a point output's turns about the point are idle indeed: free with every actuator held.

A point output counts the platform's turns about the point as no motion (``docs/theory.md``, *Point outputs*). Where
an actuator drives such a turn (a leg's meeting point on a servo horn's circle, the hip motor turning the thigh about
it), the point's indices and redundancy are the point's alone: two actuators read as one DOF and one redundant. The
turns are tested at the closed configuration the mobility is read at and at closed configurations a small step
either way along each of the platform's motions, so that a configuration singular with the actuators held (the pin
on the line of the two hinges beyond the held hip, which frees the turn to first order) does not hide them.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from screwkit.closure.modes import small_steps
from screwkit.closure.solve import solve
from screwkit.closure.task_space import driven_idle_turns, infer_task_axes
from screwkit.model.mechanism import Mechanism

__all__ = ["DRIVEN_TURNS", "turns_driven"]

DRIVEN_TURNS = "point output: "
"""How the note starts that says an actuator drives the platform's turns about the output point."""
DRIVEN_NOTE = (DRIVEN_TURNS + "an actuator turns the platform about the output point (its turns there are not free "
               "with every actuator held), which a point output counts as no motion: the indices and the redundancy "
               "are the point's alone; a frame output reads the platform's")
"""The note itself (:attr:`~screwkit.model.mechanism.Mechanism.assembly_notes`)."""


def turns_driven(mechanism: Mechanism, at_pose, at_values, dof: int) -> bool:
    """Whether an actuator drives a turn of the platform about its output point (``dof`` platform motions, before
    the point's own count) at ``at_pose`` (joint values ``at_values``, one array per chain) or at the closed
    configurations a step either way along each platform motion from the reference assembly."""
    if driven_idle_turns(mechanism, np.asarray(at_pose, dtype=float), at_values, dof):
        return True
    axes = tuple(int(a) for a in infer_task_axes(mechanism, np.asarray(at_pose, dtype=float), at_values, dof))
    following = replace(mechanism, dof=dof, task_axes=axes if dof < mechanism.n_pose else (), held_axes=())
    home = mechanism.home_full_pose[list(following.task_indices)]
    following = replace(following, named_poses={"home": home})
    solution = solve(following, small_steps(home, following.angular, mechanism.length_scale), limits=False)
    return any(driven_idle_turns(mechanism, solution.full_poses[k], [v[k] for v in solution.joint_values], dof)
               for k in np.flatnonzero(solution.reachable))
