"""Indices of a loaded mechanism at platform poses: closure -> screws -> indices, in chunks.

This is the layer the command line, the sweeps and the maps stand on:
:func:`indices_at_poses` solves the closures of a batch of poses, hands the screws of the
reachable ones to :func:`screwkit.transmission.analyze`, and returns plain arrays with NaN
where a pose is unreachable.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.kinematics import thread_limit
from screwkit.transmission import DEFAULT_THRESHOLD, TransmissionResult, analyze

__all__ = ["PoseIndices", "indices_at_poses", "analyze_pose", "poses_from_degrees", "angular_coordinates"]


def angular_coordinates(task_coordinates: tuple[str, ...]) -> NDArray[np.bool_]:
    """Which task coordinates are angles (phi, roll, pitch, yaw)."""
    return np.array([name in ("phi", "roll", "pitch", "yaw") for name in task_coordinates])


def poses_from_degrees(mechanism, values: ArrayLike) -> NDArray[np.float64]:
    """Task coordinates with angles in degrees -> radians (validated against the mechanism)."""
    poses = mechanism.check_poses(values).copy()
    poses[..., angular_coordinates(mechanism.task_coordinates)] = np.deg2rad(
        poses[..., angular_coordinates(mechanism.task_coordinates)])
    return poses


@dataclass
class PoseIndices:
    """Indices over a batch of poses (leading shape of ``poses``), NaN where unreachable.

    Attributes
    ----------
    poses : ndarray (..., n_task)
    reachable : ndarray (...) of bool
    iti, lmti : ndarray (...)
    f_o, f_io : dict of int -> ndarray (...)
    iti_actuators : ndarray (..., a) or None
    oti_submechanisms : ndarray (..., S) or None
    actuator_names : tuple of str
    submechanisms : tuple of tuple of int
    dof : int
    """

    poses: NDArray[np.float64]
    reachable: NDArray[np.bool_]
    iti: NDArray[np.float64]
    lmti: NDArray[np.float64]
    f_o: dict[int, NDArray[np.float64]]
    f_io: dict[int, NDArray[np.float64]]
    actuator_names: tuple[str, ...]
    submechanisms: tuple[tuple[int, ...], ...]
    dof: int
    iti_actuators: NDArray[np.float64] | None = None
    oti_submechanisms: NDArray[np.float64] | None = None
    extra: dict = field(default_factory=dict)

    def lmti_of(self, actuator_set) -> NDArray[np.float64]:
        """LMTI of a set of actuators (Eq. 11), from the stored submechanism OTIs."""
        if self.oti_submechanisms is None:
            raise ValueError("Computed with detail=False; pass detail=True for per-set LMTIs.")
        chosen = set(int(i) for i in actuator_set)
        members = [s for s, sub in enumerate(self.submechanisms) if set(sub) <= chosen]
        if not members:
            raise ValueError(f"Expected at least n = {self.dof} actuators in `actuator_set`, got {sorted(chosen)}.")
        return self.oti_submechanisms[..., members].max(axis=-1)


def _actuator_names(mechanism) -> tuple[str, ...]:
    return tuple(f"{chain}:{joint}" for chain, joint in mechanism.actuators)


def indices_at_poses(mechanism, poses: ArrayLike, *, detail: bool = False, threshold: float = DEFAULT_THRESHOLD,
                     faults=None, chunk_size: int = 262_144, progress=None, threads: int | None = None,
                     closed_forms: bool = False) -> PoseIndices:
    """Solve the closures of ``poses`` and compute the indices of the reachable ones.

    Parameters
    ----------
    mechanism : screwkit.mechanism.Mechanism
    poses : array_like, shape (..., n_task)
        Task coordinates in metres and radians.
    detail : bool
        Also keep ITI per actuator and OTI per submechanism.
    threshold : float
        Singularity threshold *p* (m).
    faults : int or sequence of int, optional
        ``j`` values (default all).
    chunk_size : int
        Poses solved and analysed at a time (memory stays bounded).
    progress : callable, optional
        Called with the number of poses done after each chunk.
    threads : int, optional
        Threads for the index kernel, and at most as many for closure solving and screws
        (default: all cores).
    closed_forms : bool
        Use the paper's planar closed forms instead of the generic screw path (planar RRR/RPR
        mechanisms only; see :func:`planar_points`).

    Returns
    -------
    PoseIndices
    """
    poses = mechanism.check_poses(poses)
    batch = poses.shape[:-1]
    flat = poses.reshape(-1, mechanism.n_task)
    count = flat.shape[0]
    reachable = np.zeros(count, dtype=bool)
    iti = np.full(count, np.nan)
    lmti = np.full(count, np.nan)
    f_o: dict[int, NDArray] = {}
    f_io: dict[int, NDArray] = {}
    iti_actuators = oti_subs = None
    meta = None
    with thread_limit(threads):  # closures and screws on no more threads than the kernel
        for start in range(0, count, chunk_size):
            part = slice(start, min(start + chunk_size, count))
            solution = mechanism.solve(flat[part])
            ok = np.asarray(solution.reachable)
            index = np.flatnonzero(ok) + start
            reachable[index] = True
            if index.size:
                if closed_forms:
                    result = _closed_form_result(mechanism, solution, threshold, faults, threads)
                else:
                    chains = mechanism.chain_screws(solution, unreachable="drop")
                    result = analyze(chains, detail=detail, threshold=threshold, faults=faults, threads=threads)
                if meta is None:
                    meta = result
                    f_o = {j: np.full(count, np.nan) for j in result.f_o}
                    f_io = {j: np.full(count, np.nan) for j in result.f_o}
                    if detail and result.iti_actuators is not None:
                        iti_actuators = np.full((count, result.iti_actuators.shape[-1]), np.nan)
                        oti_subs = np.full((count, result.oti_submechanisms.shape[-1]), np.nan)
                iti[index] = result.iti
                lmti[index] = result.lmti
                for j in f_o:
                    f_o[j][index] = result.f_o[j]
                    f_io[j][index] = result.f_io[j]
                if iti_actuators is not None:
                    iti_actuators[index] = result.iti_actuators
                    oti_subs[index] = result.oti_submechanisms
            if progress is not None:
                progress(part.stop - part.start)

    def shaped(array):
        return None if array is None else array.reshape(batch + array.shape[1:])

    if meta is None:
        names, subs, dof = _actuator_names(mechanism), (), mechanism.dof
    else:
        names, subs, dof = _actuator_names(mechanism), meta.submechanisms, meta.dof
    return PoseIndices(poses=poses, reachable=reachable.reshape(batch), iti=shaped(iti), lmti=shaped(lmti),
                       f_o={j: shaped(v) for j, v in f_o.items()}, f_io={j: shaped(v) for j, v in f_io.items()},
                       actuator_names=names, submechanisms=subs, dof=dof,
                       iti_actuators=shaped(iti_actuators), oti_submechanisms=shaped(oti_subs))


def planar_points(mechanism, solution):
    """Planar joint points of every chain in the base frame (reachable configurations), for the closed forms.

    Returns ``(base, elbows, distal, prismatic)``: arrays (N, k, 2) of the first, second and
    last joint points of each 3-joint planar chain, and whether the chains are RPR (actuated
    prismatic middle joint) rather than RRR (actuated base joint).
    """
    if not mechanism.is_planar:
        raise ValueError(f"The closed forms are planar: mechanism {mechanism.name!r} is spatial.")
    kinds = set()
    for chain in mechanism.chains:
        prismatic = tuple(chain.prismatic)
        if chain.n_joints != 3 or chain.actuated not in ((0,), (1,)):
            raise ValueError(f"The closed forms need RRR or RPR chains with one actuator; chain {chain.name!r} "
                             f"has {chain.n_joints} joints, actuated {chain.actuated}.")
        if prismatic == (False, False, False) and chain.actuated == (0,):
            kinds.add("rrr")
        elif prismatic == (False, True, False) and chain.actuated == (1,):
            kinds.add("rpr")
        else:
            raise ValueError(f"The closed forms need RRR (base actuated) or RPR (prismatic actuated) chains; "
                             f"chain {chain.name!r} is not one.")
    if len(kinds) != 1:
        raise ValueError(f"The closed forms need chains of one kind, got {sorted(kinds)}.")
    mask = np.asarray(solution.reachable).reshape(-1)
    everything = bool(mask.all())
    count = int(mask.size if everything else mask.sum())
    # Joint points in the base frame, reachable configurations only, stored component-major
    # (joint, component, chain, configuration) so that every copy below is contiguous; the
    # returned (N, k, 2) arrays are views of it (the closed-form kernel reads any layout).
    memory = np.empty((3, 2, len(solution.joint_points), count))
    for chain, points in enumerate(solution.joint_points):
        flat = points.reshape(-1, 3, 3)
        for joint in range(3):
            for component in range(2):
                column = flat[:, joint, component]
                memory[joint, component, chain] = column if everything else column[mask]
    base, elbows, distal = (memory[joint].transpose(2, 1, 0) for joint in range(3))
    return base, elbows, distal, kinds == {"rpr"}


def _closed_form_result(mechanism, solution, threshold, faults, threads):
    from screwkit.closed_forms import planar_indices

    base, elbows, distal, prismatic = planar_points(mechanism, solution)
    if prismatic:
        direction = distal - base
        closed = planar_indices(base, None, distal, threshold=threshold, faults=faults, threads=threads,
                                directions=direction / np.linalg.norm(direction, axis=-1, keepdims=True))
    else:
        closed = planar_indices(base, elbows, distal, threshold=threshold, faults=faults, threads=threads)
    return TransmissionResult(
        actuators=tuple((c, 0) for c in range(distal.shape[-2])), actuator_names=_actuator_names(mechanism),
        dof=3, submechanisms=closed["submechanisms"], iti=closed["iti"], lmti=closed["lmti"], f_o=closed["f_o"],
        f_io=closed["f_io"], worst_faults={}, mutual_interference=np.ones(distal.shape[:-1], bool),
        iti_actuators=closed["iti_chains"], oti_submechanisms=closed["oti_submechanisms"])


def analyze_pose(mechanism, pose: ArrayLike, *, threshold: float = DEFAULT_THRESHOLD) -> TransmissionResult:
    """Every index at one pose (metres, radians); an unreachable pose raises a ValueError naming the chain."""
    solution = mechanism.solve_one(pose)
    return analyze(mechanism.chain_screws(solution), threshold=threshold, keep_twists=True)
