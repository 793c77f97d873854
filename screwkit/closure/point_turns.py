"""Whether a point output's turns about the point are idle indeed: free with every actuator held.

A point output counts the platform's turns about the point as no motion (``docs/theory.md``, *Point outputs*). Where
an actuator drives such a turn (a leg's meeting point on a servo horn's circle, the hip motor turning the thigh
about it), the indices are those of another mechanism: a published rat robot's leg read its two actuators as one DOF
and one redundant, F_O1 0.2435, where the hip alone cannot hold the point with the servo failed. Such an output is
refused (:func:`check_turns`). The turns are tested at the closed configuration the mobility is read at and at
closed configurations a small step either way along each of the platform's motions, so that a configuration singular
with the actuators held (the pin on the line of the two hinges beyond the held hip, which frees the turn to first
order) does not hide them.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from screwkit.closure.modes import small_steps
from screwkit.closure.solve import solve
from screwkit.closure.task_space import driven_idle_turns, infer_task_axes, still_motions
from screwkit.model.mechanism import Mechanism

__all__ = ["DrivenIdleTurns", "check_turns", "turns_driven"]


class DrivenIdleTurns(ValueError):
    """A point output whose turns about the point an actuator drives (:func:`check_turns`): a file of another tool
    whose output type was left to screwkit is read with a frame instead (:func:`screwkit.io.loader.load`)."""


DRIVEN = ("an actuator turns the platform about the output point (its turns there are not free with every actuator "
          "held), which a point output counts as no motion: its indices would be those of another mechanism (the "
          "actuator driving the turn read as redundant); ")
"""The refusal's reason; its advice depends on the file (:func:`check_turns`)."""


def check_turns(mechanism: Mechanism, at_pose, at_values, dof: int) -> None:
    """:class:`DrivenIdleTurns` naming the file's element and what to write instead, when :func:`turns_driven`."""
    if not turns_driven(mechanism, at_pose, at_values, dof):
        return
    advice = ("take a frame for the output (--output-type frame, or --output naming another body's frame)"
              if mechanism.description.converted_from else "write the output as a frame (no <output type='point'/>)")
    raise DrivenIdleTurns(str(mechanism.description.fail("<output type='point'>", DRIVEN + advice)))


def turns_driven(mechanism: Mechanism, at_pose, at_values, dof: int) -> bool:
    """Whether an actuator drives a turn of the platform about its output point (``dof`` platform motions, before
    the point's own count) at ``at_pose`` (joint values ``at_values``, one array per chain) or at the closed
    configurations a step either way along each platform motion from the reference assembly."""
    at_pose = np.asarray(at_pose, dtype=float)
    still = still_motions(mechanism, at_pose, at_values, dof)
    if still is not None and not still.shape[1]:  # no motion keeps the point still at a regular configuration, nor
        return False  # generically (their number only grows where the translations' rank drops): no turn to drive
    if driven_idle_turns(mechanism, at_pose, at_values, dof):
        return True
    axes = tuple(int(a) for a in infer_task_axes(mechanism, at_pose, at_values, dof))
    following = replace(mechanism, dof=dof, task_axes=axes if dof < mechanism.n_pose else (), held_axes=())
    home = mechanism.home_full_pose[list(following.task_indices)]
    following = replace(following, named_poses={"home": home})
    solution = solve(following, small_steps(home, following.angular, mechanism.length_scale), limits=False)
    return any(driven_idle_turns(mechanism, solution.full_poses[k], [v[k] for v in solution.joint_values], dof)
               for k in np.flatnonzero(solution.reachable))
