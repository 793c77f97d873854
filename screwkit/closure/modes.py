"""Operation modes that meet at a constraint-singular reference assembly.

A mechanism drawn at a constraint singularity can have several operation modes through its reference assembly:
sets of closed configurations of the same mobility that meet there. A U-P-U leg whose outer hinges are parallel
and whose inner hinges are parallel holds the platform by one couple; drawn with every leg's couple vertical (every
hinge horizontal, as a published Gazebo "Stewart platform" is), the platform of 3 or 6 such legs translates in one
mode and turns in others, and the reference assembly is in all of them. The generic samples near the reference
assembly from which the mobility and the task coordinates are read can fall in any of the modes; task coordinates
read from a mode that a continuation from the reference assembly does not follow drive nothing (every pose off the
reference assembly was unreachable).

:func:`meeting_modes` groups the samples (random ones, and ones offset in the translations alone and in the
rotations alone: :func:`screwkit.closure.assembly.task_space`) by their motion spaces, reads each group's task
coordinates and tries them: small steps of each coordinate from the reference assembly, closed by the continuation
every command uses, must land in that mode. The mode whose coordinates drive the most steps is followed; among
equals the one that turns the platform least (the translational mode of the U-P-U platforms), then the first
coordinates in pose order.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from screwkit.closure.task_space import TASK_RANK_TOLERANCE, complete_poses, infer_task_axes, motion_space_at
from screwkit.model.mechanism import Mechanism

__all__ = ["Mode", "meeting_modes", "describe_modes", "small_steps", "values_at", "MODE_SEPARATION", "PROBE_STEP"]

MODE_SEPARATION = 0.5
"""Two closed samples are of different operation modes when their motion spaces (orthonormal bases in
pose-coordinate rates, lengths in length scales) are further apart than this: the sine of their largest principal
angle. Samples of one mode, within 0.05 rad and length scales of the reference assembly, are a few hundredths
apart (the space turns with the configuration at the rate of the mechanism's curvature, about one per length
scale); the modes of the U-P-U platforms are 0.9 to 1 apart."""

PROBE_STEP = 0.02
"""The steps that try a mode's task coordinates: each coordinate moved by this (rad, or length scales) either way
from the reference assembly."""


@dataclass(frozen=True)
class Mode:
    """One operation mode through the reference assembly, as its samples show it.

    ``space``: an orthonormal basis (n_pose, dof) of one sample's motion space; ``pose`` and ``values`` that
    sample's full pose and joint values (every chain); ``axes`` the task coordinates read there; ``turning`` how
    many independent rotations the mode's motions have; ``driven`` of ``probes`` small steps of ``axes`` closed in
    this mode."""

    space: NDArray
    pose: NDArray
    values: tuple
    axes: tuple[int, ...]
    turning: int
    driven: int = 0
    probes: int = 0


def _apart(first: NDArray, second: NDArray) -> float:
    """The sine of the largest principal angle between two subspaces (orthonormal columns of equal count)."""
    return float(np.linalg.norm(first - second @ (second.T @ first), 2))


def values_at(mechanism: Mechanism, chain_indices, values, sample: int) -> list[NDArray]:
    """Every chain's joint values at closed sample ``sample``: the constraining chains' (``chain_indices``, their
    ``values`` (N, m_i)) there, the reference assembly's for the others (their twists span every motion)."""
    every = [np.asarray(chain.reference_values) for chain in mechanism.chains]
    for index, chain_values in zip(chain_indices, values):
        every[index] = chain_values[sample]
    return every


def meeting_modes(mechanism: Mechanism, chain_indices, poses: NDArray, values, mobility: int) -> list[Mode]:
    """The operation modes the samples ``poses`` (N, n_pose) with the joint values ``values`` of the chains
    ``chain_indices`` show near the reference assembly, each with its task coordinates tried, in the order they are
    followed (see the module's description). Samples with more than ``mobility`` instantaneous DOF are left out.
    Each mode is read at the sample of its group that turns the platform least (a sample that closed near the set
    where the modes meet has rotation rates of the order of its closure's accuracy): how many rotations the mode
    has, its task coordinates and the pose commands start from."""
    subset = replace(mechanism, chains=tuple(mechanism.chains[i] for i in chain_indices))
    dofs, bases = motion_space_at(subset, poses, values)
    angular = np.asarray(mechanism.pose_angular, dtype=bool)
    groups: list[list[int]] = []
    for sample in np.flatnonzero(dofs == mobility):
        space = bases[sample][:, :mobility]
        group = next((g for g in groups if _apart(space, bases[g[0]][:, :mobility]) <= MODE_SEPARATION), None)
        if group is None:
            groups.append([int(sample)])
        else:
            group.append(int(sample))
    modes = []
    for group in groups:
        turning = [np.linalg.svd(bases[s][angular, :mobility], compute_uv=False) for s in group]
        sample = group[int(np.argmin([np.sum(rates) for rates in turning]))]
        every = values_at(mechanism, chain_indices, values, sample)
        axes = infer_task_axes(mechanism, poses[sample], every, mobility)
        count = min(int(np.sum(rates > TASK_RANK_TOLERANCE)) for rates in turning)
        modes.append(_tried(mechanism, subset, Mode(bases[sample][:, :mobility], poses[sample], tuple(every), axes,
                                                   count), mobility))
    return sorted(modes, key=lambda mode: (-mode.driven, mode.turning, mode.axes))


def small_steps(home: NDArray, angular, length_scale: float) -> NDArray:
    """Task poses (2 n, n) a step of :data:`PROBE_STEP` (rad, or length scales) either way along each of the ``n``
    task coordinates from ``home``: what a mode's coordinates must drive."""
    steps = np.where(np.asarray(angular, dtype=bool), PROBE_STEP, PROBE_STEP * length_scale)
    return np.concatenate([home + np.diag(steps), home - np.diag(steps)])


def _tried(mechanism: Mechanism, subset: Mechanism, mode: Mode, mobility: int) -> Mode:
    """``mode`` with the count of the small steps of its task coordinates from the reference assembly that the
    continuation closes in it (its motion space within :data:`MODE_SEPARATION` of the mode's) or on the singular set
    where the modes meet (more than ``mobility`` instantaneous DOF: a U-P-U platform's pure lift)."""
    following = replace(mechanism, dof=mobility, task_axes=mode.axes)
    probes = small_steps(mechanism.home_full_pose[list(mode.axes)], following.angular, mechanism.length_scale)
    poses, values, converged, _ = complete_poses(following, probes)
    driven = 0
    if converged.any():
        dofs, bases = motion_space_at(subset, poses[converged], [v[converged] for v in values])
        driven = sum(int(dof > mobility or _apart(basis[:, :mobility], mode.space) <= MODE_SEPARATION)
                     for dof, basis in zip(dofs, bases))
    return replace(mode, driven=driven, probes=probes.shape[0])


def describe_modes(mechanism: Mechanism, modes: list[Mode]) -> str:
    """A note naming the modes that meet at the reference assembly and the one followed (the first); or, one mode
    found, how far its coordinates drive."""
    def words(mode: Mode) -> str:
        names = ", ".join(mechanism.pose_coordinates[axis] for axis in mode.axes)
        kind = "the platform translates only" if not mode.turning else \
            f"the platform turns ({mode.turning} rotation{'s' if mode.turning > 1 else ''})"
        return (f"{kind} (coordinates {names}: {mode.driven} of {mode.probes} small steps of them close in it or "
                "where the modes meet)")

    first, others = modes[0], modes[1:]
    if not others:  # one mode found, whose coordinates do not drive every step
        return (f"the reference assembly is a constraint singularity where the one mode found near it is the one "
                f"where {words(first)}: poses near it may be unreachable; declare other coordinates "
                "(<task_coordinates> in a screwkit URDF, as screwkit convert writes one) to try them")
    return (f"{len(modes)} meet at the reference assembly, a constraint singularity; followed: the one where "
            f"{words(first)}; not followed: " + "; ".join(f"the one where {words(m)}" for m in others)
            + ". To follow another, declare its coordinates (<task_coordinates> in a screwkit URDF, as screwkit "
              "convert writes one)")
