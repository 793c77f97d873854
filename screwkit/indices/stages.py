"""The stages of :func:`screwkit.indices.analysis.analyze`: the plan of a mechanism (what does not depend on the
configuration), and one chunk of configurations through the compiled kernels, the motion spaces that leave a
constant one, the constraint indices and the constraint singularities.

Only numpy is imported here (numba when the kernels first run).
"""

from __future__ import annotations

import threading
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import NDArray

from screwkit.common import tolerances
from screwkit.common.compiling import CONSTRAINT_KERNEL, SPACE_KERNEL, prepare_kernels
from screwkit.indices.sets import remaining_lmti, set_plan
from screwkit.screw.chain_screws import ChainScrews
from screwkit.screw.constraints import ConstraintPlan, constraint_indices, plan_constraints
from screwkit.screw.motion import (
    MotionSpace,
    chain_decompositions,
    motion_bases,
    motion_space,
    null_spaces,
    sampled_working_coordinates,
    working_coordinates,
)
from screwkit.screw.outputs import quotient_bases

__all__ = ["Plan", "make_plan", "run_kernel", "ChunkSpaces", "analyze_chunk", "joints_of_all_chains",
           "constraint_plan_of", "constraint_chunk", "at_constraint_singularities", "CONSTRAINTS_COMPILED_FROM",
           "compiled_chunks", "square_subsystems", "compiled_constraint_stage", "checked_faults", "checked_threshold",
           "checked_rank_tolerance", "checked_chunk_size"]


@dataclass
class Plan:
    """Everything about a mechanism that does not depend on the configuration."""

    actuators: tuple[tuple[int, int], ...]
    dof: int
    space: MotionSpace
    complement: NDArray[np.float64]
    chain_start: NDArray[np.int64]
    actuator_chain: NDArray[np.int64]
    actuator_joint: NDArray[np.int64]
    submechanisms: NDArray[np.int64]
    locked_sets: NDArray[np.int64]
    locked_of: NDArray[np.int64]
    faults: tuple[int, ...]
    failed_sets: dict[int, NDArray[np.int64]]
    set_children: NDArray[np.int64]
    fault_rows: NDArray[np.int64]
    locked_depth: NDArray[np.int64]
    wedge_table: NDArray[np.int64]
    wedge_start: NDArray[np.int64]
    threshold: float
    rank_tolerance: float
    idle_count: int = 0


def checked_threshold(threshold, name: str = "threshold") -> float:
    """The singularity threshold *p* as a float: a real number, finite and >= 0 (a length), else a one-line error."""
    if isinstance(threshold, (str, bytes, bool, np.bool_)) or np.ndim(threshold) != 0 \
            or np.asarray(threshold).dtype.kind not in "iuf":
        raise TypeError(f"Expected `{name}` as a number >= 0 (a length), got {threshold!r}.")
    value = float(threshold)
    if not 0.0 <= value < np.inf:
        raise ValueError(f"Expected `{name}` >= 0 and finite (a length), got {threshold!r}.")
    return value


def checked_rank_tolerance(rank_tolerance) -> None:
    """A ValueError unless ``rank_tolerance`` is a number > 0."""
    if isinstance(rank_tolerance, (str, bytes, bool)) or not rank_tolerance > 0:
        raise ValueError(f"Expected `rank_tolerance` > 0, got {rank_tolerance!r}.")


def checked_chunk_size(chunk_size) -> None:
    """A ValueError unless ``chunk_size`` is a whole number >= 1 (a bool is not one)."""
    if not isinstance(chunk_size, (int, np.integer)) or isinstance(chunk_size, bool) or chunk_size < 1:
        raise ValueError(f"Expected `chunk_size` >= 1, got {chunk_size!r}.")


def checked_faults(faults, most: int, span: str = "") -> tuple[int, ...] | None:
    """The numbers of faults ``j`` that ``faults`` asks for (None: all; an int; a sequence of ints), distinct and
    ascending, each in ``1..max(most, 1)`` (``span`` how that range is written in the message, ``1..{most}`` by
    default). Bools, floats, strings and other non-integers are refused (a TypeError), not truncated."""
    if faults is None:
        return None
    if isinstance(faults, Iterable) and not isinstance(faults, (str, bytes)):
        values = tuple(faults.reshape(-1) if isinstance(faults, np.ndarray) else faults)
    else:
        values = (faults,)
    for j in values:
        if isinstance(j, (bool, np.bool_)) or not isinstance(j, (int, np.integer)):
            raise TypeError(f"Expected `faults` as an int or a sequence of ints (numbers of faults j), got {faults!r}.")
    for j in values:
        if not 1 <= j <= max(most, 1):
            raise ValueError(f"Expected the number of faults `j` in {span or f'1..{most}'}, got {j}.")
    return tuple(sorted({int(j) for j in values}))


def make_plan(chains, dof, faults, threshold, rank_tolerance, idle_count: int = 0) -> Plan:
    threshold = checked_threshold(threshold)
    checked_rank_tolerance(rank_tolerance)
    space = motion_space(chains, None if dof is None else dof + idle_count)
    n = space.dof - idle_count
    if idle_count:  # a point output: the motion space modulo the idle rotations, configuration by configuration
        if n < 1:
            raise ValueError("The output point has no mobility: every platform motion is an idle rotation about it.")
        space = MotionSpace(space.dof, None)
    actuators = tuple((c, k) for c, chain in enumerate(chains) for k in chain.actuated)
    a = len(actuators)
    if a < n:
        raise ValueError(f"Expected at least n = {n} actuators (the platform's DOF), got {a}.")
    for chain in chains:
        if chain.n_joints < n:
            raise ValueError(
                f"Chain {chain.name!r} has {chain.n_joints} joint DoFs, fewer than the platform's DOF n = {n}: "
                "it cannot follow the platform."
            )
    fault_list = checked_faults(faults, a - n, f"1..a-n = 1..{a - n}")
    if fault_list is None:
        fault_list = tuple(range(1, a - n + 1))
    elif a == n:  # no redundancy: F_O1 = 0 (see analyze), no set of n actuators is left to reduce
        fault_list = ()
    complement = space.complement if space.constant_basis is not None else np.empty((0, 6))
    return Plan(
        actuators=actuators, dof=n, space=space, complement=complement,
        chain_start=np.cumsum([0] + [c.n_joints for c in chains]).astype(np.int64),
        actuator_chain=np.array([c for c, _ in actuators], dtype=np.int64),
        actuator_joint=np.array([k for _, k in actuators], dtype=np.int64),
        faults=fault_list, **set_plan(a, n, fault_list),
        threshold=float(threshold), rank_tolerance=float(rank_tolerance),
        idle_count=idle_count)



def run_kernel(plan: Plan, twists, points, basis, complement, iti_override, oti_override, detail, keep_twists):
    """The compiled kernels on one chunk; ``basis`` in working coordinates (see :func:`working_coordinates`)."""
    prepare_kernels()
    from screwkit.indices.compiled.driver import run_kernels  # numba: loaded when indices first run

    count = twists.shape[0]
    kept = count if detail else 0
    a, (subs, n) = len(plan.actuators), plan.submechanisms.shape
    out = {
        "iti_actuators": np.zeros((kept, a)),
        "oti_actuators": np.zeros((kept, subs, n)),
        "oti_submechanisms": np.zeros((kept, subs)),
        "summary": np.zeros((count, 2 + len(plan.faults))),
        "worst": np.zeros((count, len(plan.faults)), dtype=np.int64),
        "mutual_interference": np.zeros((count, a), dtype=bool),
        "actuation_wrenches": np.zeros((kept, a, 6)),
        "output_twists": np.zeros((count if keep_twists else 0, subs, n, 6)),
        "outside": np.zeros(count, dtype=bool),
    }
    # The kernels' one signature: screws in any layout, the rest C-contiguous; all writable float64.
    twists, points = (array if array.flags.writeable else array.copy() for array in (twists, points))
    basis, complement = (array if array.flags.writeable and array.flags.c_contiguous else np.array(array, order="C")
                         for array in (basis, complement))
    run_kernels(plan, twists, points, basis, complement, iti_override, oti_override, out)
    return out


SPACES_COMPILED_FROM = 512
"""Chunks of at least this many configurations take their chain decompositions and motion spaces from the
compiled :func:`screwkit.indices.compiled.spaces.space_kernel`; smaller ones from numpy
(:func:`screwkit.screw.motion.chain_decompositions`, :func:`screwkit.screw.motion.null_spaces`), which needs
no compiling (:func:`compiled_chunks`: every chunk)."""

_COMPILED_EVERYWHERE = [0]  # the compiled_chunks blocks open in this process
_COMPILED_LOCK = threading.Lock()


@contextmanager
def compiled_chunks() -> Iterator[None]:
    """A block in which chunks of any size take the compiled space and constraint kernels, not only those of
    :data:`SPACES_COMPILED_FROM` (:data:`CONSTRAINTS_COMPILED_FROM`) configurations or more: for a study that
    evaluates many small batches (a design search's regions, 81 to 1,183 configurations a design), which pays
    the kernels' compiling once and numpy's per-call cost at every batch. The same indices to rounding (the
    kernels' tests: 1e-12). Process-wide while open: the threads of one study share it."""
    with _COMPILED_LOCK:
        _COMPILED_EVERYWHERE[0] += 1
    try:
        yield
    finally:
        with _COMPILED_LOCK:
            _COMPILED_EVERYWHERE[0] -= 1


def _compiled_from(smallest: int) -> int:
    """The least chunk the compiled kernels serve: ``smallest``, or 1 in a :func:`compiled_chunks` block."""
    return 1 if _COMPILED_EVERYWHERE[0] else smallest


class ChunkSpaces:
    """A chunk's chains in working coordinates and their decompositions, computed once when first asked
    (shared by the motion spaces and the constraint indices)."""

    def __init__(self, plan: Plan, twists, points):
        self.plan, self.twists, self.points = plan, twists, points

    @cached_property
    def working(self):
        starts = self.plan.chain_start
        chain_twists = [self.twists[:, starts[c]:starts[c + 1]] for c in range(len(starts) - 1)]
        chain_points = [self.points[:, starts[c]:starts[c + 1]] for c in range(len(starts) - 1)]
        return working_coordinates(chain_twists, chain_points)

    @cached_property
    def compiled(self):
        """The space kernel's singular values (C, N, 6), right singular vectors (C, N, 6, 6), eigenvalues (N, 6)
        and eigenvectors (N, 6, 6) for a chunk of :data:`SPACES_COMPILED_FROM` configurations or more; else None."""
        count, chains = self.twists.shape[0], len(self.plan.chain_start) - 1
        if count < _compiled_from(SPACES_COMPILED_FROM):
            return None
        prepare_kernels((SPACE_KERNEL,))
        from screwkit.indices.compiled.spaces import space_kernel  # numba: compiled for lower mobility only

        out = (np.empty((chains, count, 6)), np.empty((chains, count, 6, 6)), np.empty((count, 6)),
               np.empty((count, 6, 6)))
        space_kernel(np.concatenate(self.working[0], axis=1), self.plan.chain_start,
                     tolerances.MOTION_SPACE_TOLERANCE, *out)
        return out

    @cached_property
    def decompositions(self):
        if self.compiled is None:
            return chain_decompositions(self.working[0])
        singular, right = self.compiled[:2]
        return [(singular[c], right[c]) for c in range(singular.shape[0])]

    def null_spaces(self, dof: int):
        """:func:`screwkit.screw.motion.null_spaces` of every configuration of the chunk."""
        if self.compiled is None:
            return null_spaces(self.working[0], dof, tolerances.MOTION_SPACE_TOLERANCE, self.decompositions)
        return motion_bases(self.compiled[2], self.compiled[3], dof)


def analyze_chunk(plan: Plan, twists, points, iti_override, oti_override, detail, keep_twists, idle=None,
                   spaces: ChunkSpaces | None = None) -> dict:
    """All indices for one chunk of configurations (arrays (N, J, 6) and (N, J, 3) over all joints);
    ``spaces`` the chunk's working coordinates when they are needed for every configuration anyway."""
    if plan.space.constant_basis is not None:
        basis = plan.space.constant_basis[None]
        out = run_kernel(plan, twists, points, basis, plan.complement, iti_override, oti_override,
                          detail, keep_twists)
        redo = np.flatnonzero(out["outside"])
    else:
        out, redo = None, np.arange(twists.shape[0])
    if redo.size:
        # Configurations whose joint twists leave the constant space: their own motion space, in
        # the working coordinates the kernel uses (same centroid and characteristic length).
        every = redo.size == twists.shape[0]
        if every:  # every configuration: no copies
            redo = slice(None)
            spaces = spaces or ChunkSpaces(plan, twists, points)
            _, _, centre, length = spaces.working
            _, bases = spaces.null_spaces(plan.dof + plan.idle_count)
        else:
            if spaces is not None:
                working, _, centre, length = spaces.working
                working = [chain[redo] for chain in working]
                centre, length = centre[redo], length[redo]
                decompositions = [(singular[redo], right[redo]) for singular, right in spaces.decompositions]
            else:
                working, _, centre, length = ChunkSpaces(plan, twists[redo], points[redo]).working
                decompositions = None
            _, bases = null_spaces(working, plan.dof + plan.idle_count, tolerances.MOTION_SPACE_TOLERANCE,
                                   decompositions)
        if plan.idle_count:
            bases = quotient_bases(bases, idle[redo], centre, length, plan.dof)
        again = run_kernel(plan, twists[redo], points[redo], np.ascontiguousarray(bases), np.empty((0, 6)),
                            None if iti_override is None else iti_override[redo],
                            None if oti_override is None else oti_override[redo], detail, keep_twists)
        if out is None:
            out = again
        else:
            for key, value in again.items():
                if out[key].shape[0]:
                    out[key][redo] = value
    summary = out["summary"]
    result = {
        "iti": summary[:, 0],  # Eq. 7
        "lmti": summary[:, 1],  # Eq. 11 on the whole set
        "mutual_interference": out["mutual_interference"],
    }
    for column, j in enumerate(plan.faults):
        result[f"f_o{j}"] = summary[:, 2 + column]  # Eqs. 12-13
        result[f"worst{j}"] = plan.failed_sets[j][out["worst"][:, column]]  # (N, j): the complement of the worst E_i
    if detail:
        result.update(iti_actuators=out["iti_actuators"], oti_actuators=out["oti_actuators"],
                      oti_submechanisms=out["oti_submechanisms"], actuation_wrenches=out["actuation_wrenches"])
        result.update({f"remaining{j}": lmti for j, lmti in remaining_lmti(plan, out["oti_submechanisms"]).items()})
        if keep_twists:
            result["output_twists"] = out["output_twists"]
    return result


def joints_of_all_chains(arrays: list[NDArray]):
    """A function giving, for a slice of the batch, the (n, J, k) array of every chain's joints.

    When the chains are consecutive blocks along the joint axis of one array, whatever its
    memory layout (the loader's screws are component-major, hand-built ones batch-first), the
    slice is a view of that array and the kernel reads it in place; otherwise the chains'
    slices are concatenated.
    """
    first = arrays[0]
    width = sum(a.shape[1] for a in arrays)
    strides = first.strides
    address = first.__array_interface__["data"][0]
    tiled = first.shape[0] > 0 and first.dtype == np.float64
    for array in arrays:
        tiled &= array.strides == strides and array.dtype == first.dtype
        tiled &= array.__array_interface__["data"][0] == address
        address += array.shape[1] * strides[1]
    if tiled:
        # Writable exactly when the chains' memory is (the kernel only reads it).
        whole = np.lib.stride_tricks.as_strided(first, (first.shape[0], width, first.shape[2]), strides)
        if all(np.shares_memory(whole, array) for array in arrays):
            return lambda part: whole[part]
    return lambda part: np.concatenate([a[part] for a in arrays], axis=1)


def constraint_plan_of(chains: list[ChainScrews], count: int, mobility: int | None = None) -> ConstraintPlan:
    """The constraint structure of the chains, found on up to 9 configurations spread over the batch (``mobility``:
    :func:`~screwkit.screw.constraints.plan_constraints`)."""
    if not count:
        return ConstraintPlan(tuple(0 for _ in chains), 0)
    _, working, _, _, _ = sampled_working_coordinates(chains)
    return plan_constraints(working, mobility)


def constraint_chunk(plan: Plan, constraint_plan: ConstraintPlan, spaces: ChunkSpaces, wrenches,
                      fault_members) -> dict:
    """The CTI of a chunk (see :mod:`screwkit.screw.constraints`), in the kernel's working coordinates."""
    working, working_points, centre, length = spaces.working
    moments = wrenches[..., 3:] + np.cross(wrenches[..., :3], centre[:, None, :])  # about the centroid
    working_wrenches = np.concatenate([wrenches[..., :3], moments / length[:, None, None]], axis=-1)
    norms = np.linalg.norm(working_wrenches, axis=-1, keepdims=True)
    working_wrenches = working_wrenches / np.where(norms > 0.0, norms, 1.0)
    # With a point output the idle rotations are joints of the chains: the platform's instantaneous DOF
    # counts them, and the CTI (defined for a frame output, every wrench acting on the platform) does not apply.
    stage = compiled_constraint_stage(constraint_plan, plan.submechanisms, length.shape[0])
    result = constraint_indices(constraint_plan, working, working_points, working_wrenches, plan.submechanisms,
                                plan.dof + plan.idle_count, fault_members, plan.threshold / length,
                                spaces.decompositions, stage)
    if plan.idle_count:
        result["instantaneous_dof"] = result["instantaneous_dof"] - plan.idle_count
        for key in result:
            if key == "cti" or key == "cti_submechanisms" or key.startswith("f_c"):
                result[key] = np.full(result[key].shape, np.nan)
    return result


CONSTRAINTS_COMPILED_FROM = 512
"""Chunks of at least this many configurations take their instantaneous DOF and CTI from the compiled
:func:`screwkit.indices.compiled.constraints.constraint_kernel` when every constraint subsystem is square (see
:func:`compiled_constraint_stage`); smaller ones, and other mechanisms, from numpy
(:func:`screwkit.screw.constraints.constraint_indices`), which needs no compiling."""


def subsystem_members(constraint_plan: ConstraintPlan) -> NDArray[np.int64]:
    """(subsystems, chains): 1 where a chain's own constraint wrenches belong to a subsystem."""
    members = np.zeros((len(constraint_plan.subsystems), len(constraint_plan.own_counts)), dtype=np.int64)
    for row, subsystem in enumerate(constraint_plan.subsystems):
        members[row, list(subsystem)] = 1
    return members


def square_subsystems(constraint_plan: ConstraintPlan, n: int) -> bool:
    """Whether ``n`` actuation wrenches, each subsystem's own constraint wrenches and the common ones are six
    wrenches for every subsystem: what the compiled constraint kernel serves."""
    members = subsystem_members(constraint_plan)
    own_counts = np.array(constraint_plan.own_counts, dtype=np.int64)
    return bool(members.size) and bool(np.all(n + constraint_plan.common + members @ own_counts == 6))


def compiled_constraint_stage(constraint_plan: ConstraintPlan, submechanisms: NDArray, count: int):
    """The ``stage`` of :func:`screwkit.screw.constraints.constraint_indices` that runs the compiled constraint
    kernel, for a chunk of ``count`` >= :data:`CONSTRAINTS_COMPILED_FROM` configurations of a mechanism whose
    actuator sets with each subsystem's own constraint wrenches and the common ones are six wrenches (the numpy
    code's branch of one inverse per system); else None (the numpy code)."""
    n = submechanisms.shape[1]
    own_counts = np.array(constraint_plan.own_counts, dtype=np.int64)
    members = subsystem_members(constraint_plan)
    if (count < _compiled_from(CONSTRAINTS_COMPILED_FROM) or not constraint_plan.count
            or not square_subsystems(constraint_plan, n)):
        return None
    wrench_start = np.cumsum((0,) + constraint_plan.chain_counts).astype(np.int64)
    sets = np.ascontiguousarray(submechanisms, dtype=np.int64)

    def stage(constraints, points, wrenches, threshold):
        prepare_kernels((CONSTRAINT_KERNEL,))
        from screwkit.indices.compiled.constraints import constraint_kernel  # numba: compiled for the CTI only

        instantaneous, per_set = np.empty(constraints.shape[0], dtype=np.int64), np.empty((constraints.shape[0],
                                                                                           sets.shape[0]))
        constraint_kernel(np.ascontiguousarray(constraints), wrench_start, own_counts, constraint_plan.common,
                          np.ascontiguousarray(points), np.ascontiguousarray(wrenches), sets, members,
                          np.ascontiguousarray(threshold, dtype=np.float64), tolerances.MOTION_SPACE_TOLERANCE,
                          tolerances.RANK_TOLERANCE, tolerances.ROUNDED_COUPLE, tolerances.REPEATED_PAIRING,
                          instantaneous, per_set)
        return instantaneous, per_set

    return stage


def at_constraint_singularities(plan: Plan, result: dict, held: NDArray) -> None:
    """Where the platform has more instantaneous DOF than its mobility ``n``, no ``n`` actuators hold it:
    every OTI, LMTI and F_Oj is zero (the worst fault the first set, as for ties), and an actuator is a
    mutual-interference one when the others with every constraint wrench still hold the platform."""
    rows = np.flatnonzero(result["constraint_singular"])
    result["lmti"][rows] = 0.0
    for j in plan.faults:
        result[f"f_o{j}"][rows] = 0.0
        result[f"worst{j}"][rows] = plan.failed_sets[j][0]
    for key in ("oti_actuators", "oti_submechanisms", *(f"remaining{j}" for j in plan.faults)):
        if key in result:
            result[key][rows] = 0.0
    result["mutual_interference"][rows] = held
