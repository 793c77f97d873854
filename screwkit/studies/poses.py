"""Indices of a mechanism at platform poses: closure -> screws -> indices, in chunks.

This is the layer sweeps, maps, design searches, the command line and the viewer stand on:
:func:`indices_at_poses` solves the closures of a batch of poses, hands the screws of the
reachable ones to :func:`screwkit.indices.analysis.analyze` (or to the paper's planar closed forms)
and returns one :class:`~screwkit.indices.results.Indices` with NaN where a pose is unreachable;
:func:`indices_at_pose` does one pose and says why it is unreachable.
"""

from __future__ import annotations

import os
import threading
from collections import deque
from concurrent.futures import wait
from dataclasses import dataclass, replace
from itertools import islice
from math import comb
from typing import TYPE_CHECKING, Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.closure import chain_screws, solve, solve_one, thread_limit, working_modes
from screwkit.common.chunks import CHUNK_THREAD_PREFIX, chunk_pool
from screwkit.common.tolerances import SINGULARITY_THRESHOLD
from screwkit.indices.analysis import analyze
from screwkit.indices.faults import FAULT_TYPES
from screwkit.indices.results import Indices
from screwkit.indices.stages import checked_chunk_size, checked_faults, checked_threshold
from screwkit.model import Mechanism, require_mechanism
from screwkit.studies.batch_arrays import ARRAYS, DICTS, fill_unreachable, scatter
from screwkit.studies.closed_form_poses import closed_form_indices, planar_points  # noqa: F401 (importable here too)

if TYPE_CHECKING:  # the graph reader is imported when a graph is analysed (it is no part of the other paths)
    from screwkit.io.graph import GraphMechanism

__all__ = ["indices_at_poses", "indices_at_pose", "indices_and_joint_values", "graph_indices_at_poses",
           "check_graph_analysis", "GRAPH_CHUNK", "analyze_solution", "output_points"]


def output_points(mechanism: Mechanism, full_poses: NDArray) -> NDArray[np.float64] | None:
    """The world position (..., 3) of a mechanism's point output at full poses; None for a frame output."""
    in_base = mechanism.output_positions(full_poses)
    if in_base is None:
        return None
    return in_base @ mechanism.rotation_world_base.T + mechanism.translation_world_base


def analyze_solution(mechanism: Mechanism, solution, *, unreachable: str = "raise", **options) -> Indices:
    """:func:`screwkit.indices.analysis.analyze` on the screws of a solution, with the mechanism's output.

    ``unreachable`` as in :func:`screwkit.closure.chain_screws`; other options go to ``analyze``.
    A point output (``<output type="point">``) makes the rotations about the point idle.
    """
    chains = chain_screws(mechanism, solution, unreachable=unreachable)
    points = output_points(mechanism, solution.full_poses)
    if points is not None:
        if unreachable == "drop":
            points = points[np.asarray(solution.reachable)]
        # a planar mechanism's idle rotation is about its plane's normal, the base z axis in the world frame
        normal = mechanism.rotation_world_base[:, 2] if mechanism.is_planar else False
        options.update(output_point=points, planar=normal)
    options.setdefault("dof", mechanism.dof)  # the mobility: a constraint singularity is not another mechanism
    return analyze(chains, **options)


CHUNK_WORK = 1 << 21
"""Configurations times work units closed, screwed and analysed at a time by :func:`indices_at_poses`
(see :func:`poses_per_chunk`). Each chunk costs about 5 ms of Python around the compiled kernels;
its work should dwarf that, and its arrays stay small. Measured: chunks of 262,144 configurations
made the 8-leg hexapod 1.6x and the 5-RRR 1.5x slower per configuration in one process (arrays out
of cache, fresh pages for every chunk); sized by joint count alone, chunks small enough for the
hexapod's memory (5,461 configurations, 322 MiB for its 21 x 21 x 360 map) made the 5-RRR's
10^6-configuration map 1.09x slower, and large enough for the 5-RRR (69,905) took the hexapod's
41 x 41 x 360 map to 642 MiB."""
FULL_MOBILITY_CHUNK_WORK = 1 << 18
""":data:`CHUNK_WORK` of a mechanism free in all six DoF. Its chunks take no samples of the motion
space or the constraint structure (all twists, no constraint wrench: see
:func:`screwkit.screw.motion.motion_space`), which are most of the Python around the kernels of a chunk
(about 7 ms per hexapod chunk). Its chunks can so be eight times smaller at the same speed, for an
eighth of the memory: the 8-leg hexapod's 41 x 41 x 360 map peaked at 262 MiB in chunks of 1,024
configurations, 280-288 MiB in chunks of 2,048 and 379-419 MiB in chunks of 9,709, in 6.5, 6.0-7.0
and 6.2-6.7 s."""
CHUNK_BYTES = 96 << 20
"""At most this much memory per chunk, at about 130 bytes per configuration and joint DoF (closure
results and screws: 34 MB for 5,461 hexapod configurations, traced)."""
BYTES_PER_JOINT = 130
MIN_CHUNK, MAX_CHUNK = 1024, 262_144


def poses_per_chunk(mechanism: Mechanism) -> int:
    """How many poses :func:`indices_at_poses` takes at a time for ``mechanism``.

    :data:`CHUNK_WORK` (:data:`FULL_MOBILITY_CHUNK_WORK` for six DoF) divided by the work of one
    configuration, counted as its joint DoFs (closure and screws) plus n times its C(a, n)
    submechanisms (the index kernel), within :data:`CHUNK_BYTES` of memory: 46,603 poses of the
    5-RRR, 1,213 of the 8-leg hexapods, 36,873 of the 3-PRS-UPS; at least 1,024 and at most 262,144.
    """
    joints = sum(len(chain.joint_names) for chain in mechanism.chains)
    work = joints + mechanism.dof * comb(len(mechanism.actuators), mechanism.dof)
    memory = CHUNK_BYTES // (BYTES_PER_JOINT * max(joints, 1))
    budget = FULL_MOBILITY_CHUNK_WORK if mechanism.dof == 6 else CHUNK_WORK
    return int(np.clip(min(budget // max(work, 1), memory), MIN_CHUNK, MAX_CHUNK))


def indices_at_poses(mechanism: Mechanism, poses: ArrayLike, *, detail: bool = False,
                     threshold: float = SINGULARITY_THRESHOLD, faults=None, chunk_size: int | None = None,
                     progress: Callable[[int], None] | None = None, threads: int | None = None,
                     closed_forms: bool = False, limits: bool = True, fault_type: str = "free-swinging") -> Indices:
    """Solve the closures of ``poses`` and compute every index at the reachable ones.

    Parameters
    ----------
    mechanism : Mechanism
    poses : array_like, shape (..., n_task)
        Task coordinates in metres and radians.
    detail : bool
        Also keep the ITI per actuator and the OTI per submechanism (for :meth:`Indices.lmti_of`).
    threshold : float
        Singularity threshold *p* (m).
    faults : int or sequence of int, optional
        ``j`` values (default all).
    chunk_size : int, optional
        Poses solved and analysed at a time, so that memory stays bounded (default:
        :func:`poses_per_chunk`, from the work and memory of one configuration).
    progress : callable, optional
        Called with the number of poses done after each chunk.
    threads : int, optional
        Threads for the index kernel, and at most as many for closure solving and screws
        (default: all cores).
    closed_forms : bool
        Use the paper's planar closed forms instead of the generic screw path (planar RRR/RPR
        mechanisms only; see :func:`~screwkit.studies.closed_form_poses.planar_points`).
    limits : bool
        Whether poses that put a joint outside its position limits are unreachable (default).
    fault_type : {"free-swinging", "link"}
        What a fault is (see :func:`screwkit.indices.analysis.analyze`). The planar closed forms are for
        free-swinging faults, which give the same numbers as link faults on planar RRR/RPR chains.

    Returns
    -------
    Indices
        Batch shape of ``poses``; NaN (and no worst fault) where unreachable.
    """
    settings = dict(detail=detail, threshold=threshold, faults=faults, chunk_size=chunk_size, progress=progress,
                    threads=threads, closed_forms=closed_forms, limits=limits, fault_type=fault_type)
    return _indices_in_chunks(mechanism, poses, settings, keep_joint_values=False)[0]


def indices_and_joint_values(mechanism: Mechanism, poses: ArrayLike, *, tree_only: bool = False, **settings
                             ) -> tuple[Indices, tuple[NDArray[np.float64], ...]]:
    """:func:`indices_at_poses` (the same keywords), and per chain the joint values (..., m_i) of the closures
    it solved (:attr:`~screwkit.closure.Solution.joint_values`; NaN where the chain does not close), which a
    path needs to see its working mode (:mod:`screwkit.studies.branches`) without solving the closures twice.
    With ``tree_only``, only the values of each chain's tree joints (..., t_i), the first ``t_i``: all that a
    branch change is seen on (half the memory for a leg closed by a spherical joint)."""
    return _indices_in_chunks(mechanism, poses, settings, keep_joint_values="tree" if tree_only else True)


def _indices_in_chunks(mechanism: Mechanism, poses: ArrayLike, settings: dict, keep_joint_values: bool | str):
    """The work of :func:`indices_at_poses`, chunk by chunk, keeping the joint values when asked (``"tree"``: of
    the tree joints only)."""
    unknown = set(settings) - set(_SETTINGS)
    if unknown:
        raise TypeError(f"Unknown keyword(s) of indices_at_poses: {', '.join(sorted(unknown))}.")
    options = {**_SETTINGS, **settings}
    detail, threshold, faults, chunk_size, progress, threads, closed_forms, limits, fault_type = (
        options[name] for name in _SETTINGS)
    require_mechanism(mechanism, "indices_at_poses")
    if fault_type not in FAULT_TYPES:
        raise ValueError(f"Expected `fault_type` in {', '.join(FAULT_TYPES)}, got {fault_type!r}.")
    poses = mechanism.check_poses(poses)
    batch = poses.shape[:-1]
    flat = poses.reshape(-1, mechanism.n_task)
    count = flat.shape[0]
    _check_settings(faults, threshold, progress, chunk_size, len(mechanism.actuator_names), mechanism.dof)
    if chunk_size is None:
        chunk_size = poses_per_chunk(mechanism)
    reachable = np.zeros(count, dtype=bool)
    chain_status = np.zeros((count, len(mechanism.chains)), dtype=np.int8)
    full_poses = np.empty((count, mechanism.n_pose))
    arrays: dict = {}
    meta: Indices | None = None
    kept_joints = [chain.geometry.n_tree_joints if keep_joint_values == "tree" else chain.geometry.n_dofs
                   for chain in mechanism.chains]
    joint_values = [np.empty((count, joints)) for joints in kept_joints] if keep_joint_values else None  # every chunk

    def chunk(part: slice):
        """The closures of one chunk and the indices of its reachable poses (None if it has none)."""
        solution = solve(mechanism, flat[part], limits=limits)
        if not np.any(solution.reachable):
            return solution, None
        if closed_forms:
            return solution, replace(closed_form_indices(mechanism, solution, threshold, faults, threads),
                                     fault_type=fault_type)  # the same numbers for both types on these chains
        return solution, analyze_solution(mechanism, solution, unreachable="drop", detail=detail,
                                          threshold=threshold, faults=faults, threads=threads, fault_type=fault_type)

    parts = [slice(start, min(start + chunk_size, count)) for start in range(0, count, chunk_size)]
    with thread_limit(threads):  # closures and screws on no more threads than the kernel
        for part, (solution, result) in zip(parts, _chunks_in_order(chunk, parts, threads)):
            index = np.flatnonzero(np.asarray(solution.reachable)) + part.start
            reachable[index] = True
            chain_status[part] = solution.status
            full_poses[part] = solution.full_poses
            if joint_values is not None:
                for kept, values, joints in zip(joint_values, solution.joint_values, kept_joints):
                    kept[part] = values[..., :joints]
            if result is not None:
                meta = result
                scatter(arrays, count, index, result)
            if progress is not None:
                progress(part.stop - part.start)

    fill_unreachable(arrays)
    described = _Described(mechanism.actuator_names, mechanism.dof, mechanism.task_coordinates, mechanism.name,
                           mechanism.pose_coordinates)
    result = _batch_indices(arrays, meta, _Gathered(batch, poses, reachable, chain_status, full_poses), described,
                            faults=faults, detail=detail, threshold=threshold)
    if joint_values is None:
        return result, None
    return result, tuple(values.reshape(batch + values.shape[-1:]) for values in joint_values)


CHUNKS_PER_THREAD = 4
"""A batch of at least this many chunks per thread has its chunks computed side by side, a chunk per thread
(:func:`_chunks_in_order`), as a map's tasks are; a smaller one a chunk at a time, each on every thread."""


def _chunks_in_order(chunk: Callable, parts: list[slice], threads: int | None):
    """``chunk(part)`` for every part, yielded in order.

    With ``threads`` (default: every core) above one and at least :data:`CHUNKS_PER_THREAD` chunks per thread,
    the chunks run side by side on the threads kept for the process
    (:func:`~screwkit.common.chunks.chunk_pool`), one more than the threads at a time (their memory bounded),
    each on its thread alone: the closures and screws in one block of threads, and the index kernel's cuts of
    the chunk (:func:`~screwkit.common.chunks.map_chunks`, the same cuts as on several threads) in turn, so that
    every number is the one a chunk at a time gives. The closures and screws then run on every core, not only
    the index kernel, and no thread waits for another between chunks."""
    workers = (os.cpu_count() or 1) if threads is None else int(threads)
    inside = threading.current_thread().name.startswith(CHUNK_THREAD_PREFIX)
    if workers <= 1 or len(parts) < CHUNKS_PER_THREAD * workers or inside:
        yield from (chunk(part) for part in parts)
        return

    def alone(part: slice):
        with thread_limit(1):
            return chunk(part)

    pool = chunk_pool(workers)
    pending = deque()
    waiting = iter(parts)
    try:
        for part in islice(waiting, workers + 1):
            pending.append(pool.submit(alone, part))
        while pending:
            done = pending.popleft().result()
            following = next(waiting, None)
            if following is not None:
                pending.append(pool.submit(alone, following))
            yield done
    finally:  # an error (or a caller that stops early): nothing left running
        for future in pending:
            future.cancel()
        wait(pending)


_SETTINGS = dict(detail=False, threshold=SINGULARITY_THRESHOLD, faults=None, chunk_size=None, progress=None,
                 threads=None, closed_forms=False, limits=True, fault_type="free-swinging")
"""The keywords of :func:`indices_at_poses` and their defaults."""


def _check_settings(faults, threshold, progress, chunk_size, actuators: int, dof: int) -> None:
    """The settings of a batch checked before any work, whatever turns out reachable (as ``analyze`` checks them);
    ``chunk_size`` None is the default."""
    checked_faults(faults, actuators - dof, f"1..a-n = 1..{actuators - dof}")
    checked_threshold(threshold)
    if progress is not None and not callable(progress):
        raise TypeError(f"Expected `progress` as a callable taking the number of poses done, got {progress!r}.")
    if chunk_size is not None:
        checked_chunk_size(chunk_size)




@dataclass(frozen=True)
class _Described:
    """What a batch of indices says of its mechanism."""

    actuator_names: tuple[str, ...]
    dof: int
    task_coordinates: tuple[str, ...]
    mechanism_name: str
    pose_coordinates: tuple[str, ...]


@dataclass(frozen=True)
class _Gathered:
    """A batch's shape, poses, and per flat configuration its reachability, chain status and full pose."""

    batch: tuple[int, ...]
    poses: NDArray
    reachable: NDArray
    chain_status: NDArray
    full_poses: NDArray


def _batch_indices(arrays: dict, meta: Indices | None, gathered: _Gathered, described: _Described, *, faults,
                   detail: bool, threshold: float) -> Indices:
    """One :class:`Indices` of the batch's shape from the arrays :func:`_scatter` filled (``meta`` the last chunk's
    result, None when nothing was reachable)."""
    batch, poses, reachable, chain_status, full_poses = (gathered.batch, gathered.poses, gathered.reachable,
                                                         gathered.chain_status, gathered.full_poses)
    actuator_names, dof, task_coordinates, mechanism_name, pose_coordinates = (
        described.actuator_names, described.dof, described.task_coordinates, described.mechanism_name,
        described.pose_coordinates)

    # no CTI (no constraint wrench held by one chain alone): NaN everywhere, as a view of one NaN
    not_applicable = {} if meta is None else {"cti": np.broadcast_to(np.nan, batch),
                                              "f_c": dict.fromkeys(meta.faults, np.broadcast_to(np.nan, batch))}

    def shaped(key):
        return arrays[key].reshape(batch + arrays[key].shape[1:]) if key in arrays else None

    a = len(actuator_names)
    if meta is None:  # nothing reachable: the structure of the indices from the mechanism alone
        faults_list = checked_faults(faults, a - dof, f"1..a-n = 1..{a - dof}")
        faults_list = tuple(range(1, max(a - dof, 1) + 1)) if faults_list is None else faults_list
        nothing = np.full(batch, np.nan)
        return Indices.from_arrays(
            actuator_names, dof,
            {"iti": nothing, "lmti": nothing.copy(), "f_o": {j: nothing.copy() for j in faults_list},
             "worst_fault_indices": {j: np.full(batch + (j,), -1, dtype=np.int64) for j in faults_list},
             "mutual_interference": np.zeros(batch + (a,), dtype=bool),
             "iti_actuators": np.full(batch + (a,), np.nan) if detail else None, "poses": poses,
             # with detail, what a batch with a reachable pose has: NaN per submechanism and per set left
             "oti_submechanisms": np.full(batch + (comb(a, dof),), np.nan) if detail else None,
             "remaining_lmti": {j: np.full(batch + (comb(a, j),), np.nan) for j in faults_list} if detail else {},
             "reachable": reachable.reshape(batch),
             "chain_status": chain_status.reshape(batch + chain_status.shape[-1:]),
             "full_poses": full_poses.reshape(batch + (full_poses.shape[-1],))},
            threshold=threshold, task_coordinates=task_coordinates, mechanism=mechanism_name,
            pose_coordinates=pose_coordinates, derive=False)
    fields = {name: shaped(name) for name in ARRAYS}
    fields.update({name: {j: shaped((name, j)) for j in getattr(meta, name)} for name in DICTS})
    if not meta.constraint_count:
        fields.update(not_applicable)
    fields.update(poses=poses, reachable=reachable.reshape(batch),
                  chain_status=chain_status.reshape(batch + chain_status.shape[-1:]),
                  full_poses=full_poses.reshape(batch + (full_poses.shape[-1],)))
    return Indices.from_arrays(
        actuator_names, meta.dof, fields, threshold=threshold, submechanisms=meta.submechanisms,
        task_coordinates=task_coordinates, mechanism=mechanism_name,
        pose_coordinates=pose_coordinates, constraint_count=meta.constraint_count,
        fault_type=meta.fault_type, cti_reason=meta.cti_reason, derive=False)


def indices_at_pose(mechanism: Mechanism, pose: ArrayLike, *, threshold: float = SINGULARITY_THRESHOLD,
                    faults=None, limits: bool = True, keep_twists: bool = True,
                    fault_type: str = "free-swinging") -> Indices:
    """Every index at one pose (metres, radians), with every detail (wrenches, output twists).

    Raises
    ------
    screwkit.closure.UnreachablePose
        If the pose is unreachable: the message names the chains, the one that misses its
        closure by the most first, and joints outside their limits.
    """
    require_mechanism(mechanism, "indices_at_pose")
    pose = mechanism.check_poses(pose)
    solution = solve_one(mechanism, pose, limits=limits)
    result = analyze_solution(mechanism, solution, threshold=threshold, faults=faults, keep_twists=keep_twists,
                              fault_type=fault_type)
    values = {f"{chain.name}:{joint}": float(np.asarray(chain_values).reshape(-1)[k])
              for chain, chain_values in zip(mechanism.chains, solution.joint_values)
              for k, joint in enumerate(chain.joint_names)}
    prismatic = tuple(f"{chain.name}:{joint}" for chain in mechanism.chains
                      for joint, slides in zip(chain.joint_names, chain.prismatic) if slides)
    return replace(result, poses=pose, task_coordinates=mechanism.task_coordinates, mechanism=mechanism.name,
                   reachable=True, chain_status=solution.status, full_poses=solution.full_poses,
                   pose_coordinates=mechanism.pose_coordinates, joint_values=values, prismatic_joints=prismatic,
                   working_mode=working_modes(mechanism))


GRAPH_CHUNK = 4096
"""Poses of a closed-loop graph solved and analysed at a time by :func:`graph_indices_at_poses` (its closure
Jacobians take about 10 kB a pose for a rod-level Delta)."""


def check_graph_analysis(graph: GraphMechanism, closed_forms: bool = False, fault_type: str = "free-swinging") -> None:
    """A ValueError when a study asks a closed-loop graph for what it does not have."""
    graph.check_study(closed_forms=closed_forms, fault_type=fault_type)


def graph_indices_at_poses(graph: GraphMechanism, poses: ArrayLike, *, detail: bool = False,
                           threshold: float = SINGULARITY_THRESHOLD, faults=None, limits: bool = True,
                           threads: int | None = None, chunk_size: int = GRAPH_CHUNK,
                           progress: Callable[[int], None] | None = None, configurations: bool | NDArray = False):
    """Every index of a closed-loop graph (:mod:`screwkit.io.graph`) at a batch of task-coordinate poses.

    ``poses`` (..., len(graph.task_axes)) are the output frame's task coordinates (``graph.task_coordinates``; m
    and rad, world frame). Each is closed by continuation from the graph's configuration
    (:meth:`~screwkit.io.GraphMechanism.solve`), its legs' equivalent chains derived batched
    (:func:`screwkit.io.graph.leg_screws`) and analysed as :meth:`~screwkit.io.GraphMechanism.indices` analyses one;
    NaN where a pose is unreachable. ``full_poses`` are the frame's x, y, z, roll, pitch, yaw. With
    ``configurations``, ``(indices, q)``: also the closed configurations (..., nq) solved (NaN where unreachable),
    which a path needs to see its working mode without solving twice; given as an array (..., nq), those
    configurations already known (a path its actuators drive), not solved again (a row of NaN, or with ``limits``
    beyond a joint's limits, unreachable), and returned with the indices.
    """
    from screwkit.io.graph import dimension_groups, equivalent_chains, leg_screws  # graphs only: off other paths
    from screwkit.io.graph_kinematics import beyond_limits  # (the same reason)

    poses = graph.check_poses(poses)
    n_task = graph.n_task
    _check_settings(faults, threshold, progress, chunk_size, len(graph.actuators), n_task)  # (passive legs: none)
    closed = None if isinstance(configurations, bool) else np.asarray(configurations, dtype=float)
    batch = poses.shape[:-1]
    if closed is not None and closed.shape != batch + (graph.kinematics.nq,):
        raise ValueError(f"Expected `configurations` of shape {batch + (graph.kinematics.nq,)}, got {closed.shape}.")
    flat = poses.reshape(-1, n_task)
    count = flat.shape[0]
    reachable = np.zeros(count, dtype=bool)
    full_poses = np.full((count, 6), np.nan)
    arrays: dict = {}
    meta: Indices | None = None
    model = graph.tree.model
    kept = np.full((count, graph.kinematics.nq), np.nan) if configurations is not False else None
    for start in range(0, count, chunk_size):
        part = slice(start, min(start + chunk_size, count))
        if closed is None:
            q, reached = graph.solve(flat[part], limits=limits)
        else:
            q = np.asarray(closed, dtype=float).reshape(-1, graph.kinematics.nq)[part]
            reached = np.isfinite(q).all(axis=1)
            if limits and reached.any():
                reached[reached] = ~beyond_limits(graph.kinematics, q[reached], graph.limited, graph.scale).any(axis=1)
        index = np.flatnonzero(reached)
        reachable[index + start] = True
        if kept is not None:
            kept[index + start] = q[index]
        full_poses[index + start] = graph.frame_pose(q[index])
        if index.size:
            screws, state = leg_screws(graph.tree, graph.kinematics, graph.platform, graph.legs, q[index],
                                       graph.scale)
            for rows in dimension_groups(screws):
                chains, iti, oti = equivalent_chains(graph.legs, screws, state, rows, model)
                result = analyze(chains, iti_points=iti, oti_points=oti, detail=detail, threshold=threshold,
                                 faults=faults, threads=threads, dof=n_task)
                meta = result
                scatter(arrays, count, index[rows] + start, result)
        if progress is not None:
            progress(part.stop - part.start)
    chain_status = np.where(reachable, 0, 1).astype(np.int8)[:, None].repeat(len(graph.legs), axis=1)
    names = graph.actuators
    fill_unreachable(arrays)
    described = _Described(names, n_task, graph.task_coordinates, graph.name, ("x", "y", "z", "roll", "pitch", "yaw"))
    result = _batch_indices(arrays, meta, _Gathered(batch, poses, reachable, chain_status, full_poses), described,
                            faults=faults, detail=detail, threshold=threshold)
    return (result, kept.reshape(batch + kept.shape[-1:])) if kept is not None else result

