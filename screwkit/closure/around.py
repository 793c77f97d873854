"""Poses the straight way from the reference assembly does not reach in the working mode: solved from many starts.

The continuation (:func:`screwkit.closure.newton.solve_newton_chain`, and :func:`screwkit.closure.task_space
.complete_poses` for the chains that tie a lower-mobility platform's dependent coordinates) follows the straight way
from the reference pose. Where that way leaves a chain's reach or passes one of its folds, it ends in another
assembly of the chain, or in none, though the pose is reachable in the working mode: a five-bar leg's knee point
on the far side of its hip (published Minitaur and wheel-leg files), which every way around the hip reaches.

A pose left so is solved again from starts spread over a turn of each revolute joint (:data:`TURNS` each, the
slides at their reference values), every start closed by Levenberg-Marquardt at the pose itself, and taken when
the assemblies found that keep every working-mode sign are one (to :data:`SAME_ASSEMBLY`). That is done for planar
chains of at most three joints only (:func:`eligible`): the sign that names such a chain's working mode
(:func:`screwkit.closure.newton.working_sign`: the determinant of its three joint twists, or for two joints to an
output point the elbow) tells its assemblies at a pose apart, which are two at most (a two-joint subproblem's two
solutions on either side of the fold where the sign changes), so the one found is the working mode's. A spatial
chain can have several assemblies with one sign (a six-joint arm's eight, four of each), which no number of starts
proves complete: its poses stay refused, as the continuation leaves them.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
from numpy.typing import NDArray

from screwkit.closure.chain_kinematics import chain_forward_kinematics, wrap_revolute_values
from screwkit.closure.newton import branch_kept, newton_solve_chain
from screwkit.closure.task_space import complete_poses, constraining_chains
from screwkit.common.rotations import wrap_angle

__all__ = ["TURNS", "SAME_ASSEMBLY", "MOST_STARTS", "eligible", "starts", "apart", "one_assembly", "chain_around",
           "completion_around", "newton_chain_around", "complete_around", "searched"]

TURNS = (0.0, 0.5 * math.pi, math.pi, -0.5 * math.pi)
"""Where each revolute joint starts, from its reference value (rad): a quarter turn apart (and each angle task
coordinate, :func:`screwkit.closure.forward_kinematics.forward_from_starts`)."""

SAME_ASSEMBLY = 1e-6
"""Two closed assemblies are one when no joint value (or dependent pose coordinate) differs by more than this (rad,
and length scales)."""

MOST_STARTS = 256
"""Starts a pose may take (chains tied together multiply theirs); beyond it the pose stays as the continuation left
it."""

BLOCK_ROWS = 8192
"""Starts solved at a time (poses times their starts): the search's memory is that of this many configurations,
whatever the batch."""

REACH_SLACK = 1e-6
"""Length scales by which a pose may be beyond a chain of hinges' reach (:func:`_reach_kept`) and still be searched
(the boundary is where the chain is stretched or folded, singular)."""


def eligible(mechanism, indices, branches) -> bool:
    """Whether the chains ``indices`` of a planar mechanism, each of at most three joints, all have a working-mode
    sign (``branches[index]``, +1 or -1), and their starts are at most :data:`MOST_STARTS`."""
    if not mechanism.is_planar or not indices:
        return False
    revolute = 0
    for index in indices:
        geometry = mechanism.chains[index].geometry
        if branches[index] is None or isinstance(branches[index], tuple) or geometry.n_dofs > 3:
            return False
        revolute += sum(not prismatic for prismatic in geometry.dof_prismatic)
    return len(TURNS) ** revolute <= MOST_STARTS


def starts(mechanism, indices) -> list[NDArray[np.float64]]:
    """Per chain of ``indices``, its start values (S, m_i): every combination of :data:`TURNS` on the revolute
    joints of all of them (S = 4 ** revolute joints), from their reference values."""
    geometries = [mechanism.chains[index].geometry for index in indices]
    revolute = [[not prismatic for prismatic in geometry.dof_prismatic] for geometry in geometries]
    turns = np.array(list(itertools.product(TURNS, repeat=sum(map(sum, revolute)))), dtype=float).reshape(
        -1, sum(map(sum, revolute)))
    result, column = [], 0
    for index, mask in zip(indices, revolute):
        values = np.tile(mechanism.chains[index].reference_values, (turns.shape[0], 1))
        values[:, mask] += turns[:, column:column + sum(mask)]
        column += sum(mask)
        result.append(values)
    return result


def apart(difference: NDArray, angular: NDArray, length: float) -> NDArray[np.bool_]:
    """Whether differences (..., k) of joint values or pose coordinates make two assemblies (or poses): one of them
    more than :data:`SAME_ASSEMBLY`, angles (``angular`` (k,)) modulo a turn, lengths in units of ``length``."""
    difference = np.array(difference, dtype=float)
    difference[..., angular] = wrap_angle(difference[..., angular])
    difference[..., ~angular] /= length
    return np.max(np.abs(difference), axis=-1, initial=0.0) > SAME_ASSEMBLY


def one_assembly(values: NDArray, kept: NDArray, angular: NDArray, length: float):
    """Of each pose's closed starts ``values`` (N, S, k) that keep the working mode (``kept``, (N, S)), the one
    assembly: ``(which start (N,), found (N,))``, found where every kept start closed to the same values (:func:`apart`
    from the first kept) and at least one did."""
    first = np.argmax(kept, axis=1)
    chosen = values[np.arange(values.shape[0]), first]
    far = apart(values - chosen[:, None, :], angular, length)
    return first, np.any(kept, axis=1) & ~np.any(kept & far, axis=1)


def _hinges_reach(mechanism, index: int, end: bool):
    """Of chain ``index`` when its joints are all hinges (None otherwise): its first joint's point in the plane, the
    lengths (in the plane) between its joints' points in turn and from the last to the point reached (the last
    joint's own point when ``end``, else the platform frame's origin), and that point's offset in the chain's loop
    frame (``end``) -- all constant as the hinges turn."""
    chain = mechanism.chains[index]
    if any(chain.geometry.dof_prismatic):
        return None
    frames = chain_forward_kinematics(chain.geometry, chain.reference_values)
    points = frames.points[:, :2]
    if end:
        offset = frames.end_rotation.T @ (frames.points[-1] - frames.end_translation)
    else:
        offset = None
        points = np.vstack([points, mechanism.home_translation[:2]])
    return points[0], np.linalg.norm(np.diff(points, axis=0), axis=1), offset


def _reach_kept(mechanism, lengths: NDArray, distance: NDArray) -> NDArray[np.bool_]:
    """Whether a chain of links ``lengths`` in a plane reaches as far as ``distance`` (N,) from its first point: no
    farther than their sum, no nearer than the longest less the others (to :data:`REACH_SLACK` length scales)."""
    if lengths.size == 0:
        return np.ones(distance.shape, dtype=bool)
    slack = REACH_SLACK * mechanism.length_scale
    total = float(np.sum(lengths))
    return (distance <= total + slack) & (distance >= 2.0 * float(np.max(lengths)) - total - slack)


def chain_around(mechanism, index: int, targets, branch, tolerance: float, max_iterations: int):
    """Chain ``index`` closed onto loop ``targets`` (rotations (N, 3, 3), translations (N, 3)) from every start of
    :func:`starts`: ``(values (N, m), found (N,), residual (N,))``, found where one assembly keeps the sign
    ``branch``. A chain of hinges is not solved where the target puts its last joint out of its reach; the starts
    are solved :data:`BLOCK_ROWS` at a time."""
    geometry = mechanism.chains[index].geometry
    count = targets[0].shape[0]
    values = np.full((count, geometry.n_dofs), np.nan)
    found, residual = np.zeros(count, dtype=bool), np.full(count, np.inf)
    hinges = _hinges_reach(mechanism, index, end=True)
    rows = np.arange(count)
    if hinges is not None:
        first, lengths, offset = hinges
        last = targets[1] + targets[0] @ offset
        rows = rows[_reach_kept(mechanism, lengths, np.linalg.norm(last[:, :2] - first, axis=1))]
    (seeds,) = starts(mechanism, (index,))
    block = max(1, BLOCK_ROWS // seeds.shape[0])
    for at in range(0, rows.size, block):
        some = rows[at:at + block]
        values[some], found[some], residual[some] = _chain_from_starts(
            mechanism, index, (targets[0][some], targets[1][some]), seeds, branch, tolerance, max_iterations)
    return values, found, residual


def _chain_from_starts(mechanism, index: int, targets, seeds: NDArray, branch, tolerance: float,
                       max_iterations: int):
    """:func:`chain_around` on one block of poses, every start at once."""
    geometry = mechanism.chains[index].geometry
    count, many = targets[0].shape[0], seeds.shape[0]
    values, converged, residual = newton_solve_chain(
        geometry, np.repeat(targets[0], many, axis=0), np.repeat(targets[1], many, axis=0),
        np.tile(seeds, (count, 1)), tolerance, max_iterations, length=mechanism.length_scale)
    values = wrap_revolute_values(geometry, values)
    kept = (converged & branch_kept(mechanism, index, values, branch)).reshape(count, many)
    values, residual = values.reshape(count, many, -1), residual.reshape(count, many)
    angular = ~np.asarray(geometry.dof_prismatic, dtype=bool)
    first, found = one_assembly(values, kept, angular, mechanism.length_scale)
    rows = np.arange(count)
    return values[rows, first], found, residual[rows, first]


def completion_around(mechanism, chains, task_poses: NDArray, branches):
    """The dependent coordinates and the joint values of the constraining ``chains`` at ``task_poses`` (N, n_task)
    closed together (:func:`screwkit.closure.task_space.complete_poses`) from every start of :func:`starts`, the
    dependent coordinates at the reference's: ``(full poses (N, n_pose), values per chain (N, m_i), found (N,),
    residual (N,))``, found where one assembly keeps every chain's sign in ``branches``. Poses where the platform's
    origin is out of a chain of hinges' reach are not solved; the starts are solved :data:`BLOCK_ROWS` at a time."""
    count = task_poses.shape[0]
    poses = mechanism.full_poses(task_poses, mechanism.home_full_pose[list(mechanism.dependent_indices)])
    values = [np.full((count, mechanism.chains[i].n_joints), np.nan) for i in chains]
    found, residual = np.zeros(count, dtype=bool), np.full(count, np.inf)
    rows = np.arange(count)
    origins = mechanism.transforms_from_poses(poses)[1][:, :2]
    for index in chains:
        hinges = _hinges_reach(mechanism, index, end=False)
        if hinges is not None:
            first, lengths, _ = hinges
            rows = rows[_reach_kept(mechanism, lengths, np.linalg.norm(origins[rows] - first, axis=1))]
    seeds = starts(mechanism, chains)
    block = max(1, BLOCK_ROWS // seeds[0].shape[0])
    for at in range(0, rows.size, block):
        some = rows[at:at + block]
        block_poses, block_values, found[some], residual[some] = _completion_from_starts(
            mechanism, chains, task_poses[some], branches, seeds)
        poses[some] = block_poses
        for chain_values, found_values in zip(values, block_values):
            chain_values[some] = found_values
    return poses, values, found, residual


def _completion_from_starts(mechanism, chains, task_poses: NDArray, branches, seeds):
    """:func:`completion_around` on one block of poses, every start at once."""
    count, many = task_poses.shape[0], seeds[0].shape[0]
    repeated = np.repeat(task_poses, many, axis=0)
    start_poses = mechanism.full_poses(repeated, mechanism.home_full_pose[list(mechanism.dependent_indices)])
    poses, values, converged, residual = complete_poses(mechanism, repeated, start_poses=start_poses,
                                                        start_values=[np.tile(seed, (count, 1)) for seed in seeds])
    kept = converged.copy()
    for index, chain_values in zip(chains, values):
        kept &= branch_kept(mechanism, index, chain_values, branches[index])
    dependent = poses[:, list(mechanism.dependent_indices)]
    stacked = np.concatenate([dependent] + list(values), axis=-1).reshape(count, many, -1)
    angular = np.concatenate([np.asarray(mechanism.pose_angular)[list(mechanism.dependent_indices)]]
                             + [~np.asarray(mechanism.chains[i].geometry.dof_prismatic, dtype=bool) for i in chains])
    first, found = one_assembly(stacked, kept.reshape(count, many), angular, mechanism.length_scale)
    pick = np.arange(count) * many + first
    return poses[pick], [chain_values[pick] for chain_values in values], found, residual[pick]


def _sign(mechanism, index: int, branches):
    """The working-mode sign solve keeps for chain ``index`` (a closed-form chain solved by Newton: its reference
    determinant's)."""
    chain = mechanism.chains[index]
    return branches[index] if chain.closed_form is None else chain.reference_sign


def newton_chain_around(mechanism, index, platform, sign, tolerance, max_iterations, solved):
    """``solved`` (values (N, m), reached (N,), residual (N,): chain ``index`` closed at platform poses ``platform``,
    by continuation or from start values given) with the poses it left unclosed, or closed out of the sign ``sign``,
    taken from :func:`chain_around` where that finds the working mode's one assembly (a planar chain of at most three
    joints)."""
    values, reached, residual = solved
    rows = np.flatnonzero(~reached)
    if rows.size == 0 or not eligible(mechanism, (index,), {index: sign}):
        return solved
    targets = mechanism.loop_targets(index, platform[0][rows], platform[1][rows])
    around, found, around_residual = chain_around(mechanism, index, targets, sign, tolerance, max_iterations)
    values, reached, residual = values.copy(), reached.copy(), residual.copy()
    values[rows[found]], reached[rows[found]], residual[rows[found]] = around[found], True, around_residual[found]
    return values, reached, residual


def searched(mechanism, index: int) -> bool:
    """Whether :func:`solve <screwkit.closure.solve.solve>` solves chain ``index`` from starts where its closure
    fails, with the mechanism's own working modes: alone (:func:`newton_chain_around`), or with the other chains
    that tie the dependent coordinates (:func:`complete_around`)."""
    chains = constraining_chains(mechanism) if mechanism.dependent_indices else ()
    if index in chains:
        return eligible(mechanism, chains, {i: _sign(mechanism, i, [c.branch for c in mechanism.chains])
                                            for i in chains})
    return eligible(mechanism, (index,), {index: _sign(mechanism, index, [c.branch for c in mechanism.chains])})


def complete_around(mechanism, task_poses: NDArray, completion, branches):
    """``completion`` (:func:`screwkit.closure.task_space.complete_poses` at ``task_poses`` from the reference
    assembly) with the poses where it did not close, or closed a constraining chain out of its working mode (a
    planar chain of at most three joints with a sign), taken from :func:`completion_around` where that finds the
    working mode's one assembly."""
    poses, values, completed, residual = completion
    chains = constraining_chains(mechanism)
    signs = {index: _sign(mechanism, index, branches) for index in chains}
    if not eligible(mechanism, chains, signs):
        return completion
    kept = completed.copy()
    for index, chain_values in zip(chains, values):
        kept &= branch_kept(mechanism, index, chain_values, signs[index])
    rows = np.flatnonzero(~kept)
    if rows.size == 0:
        return completion
    around, around_values, found, around_residual = completion_around(mechanism, chains, task_poses[rows], signs)
    poses, values = poses.copy(), [chain_values.copy() for chain_values in values]
    completed, residual = completed.copy(), residual.copy()
    poses[rows[found]], completed[rows[found]], residual[rows[found]] = around[found], True, around_residual[found]
    for chain_values, found_values in zip(values, around_values):
        chain_values[rows[found]] = found_values[found]
    return poses, values, completed, residual
