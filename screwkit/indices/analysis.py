r"""Transmission and fault-tolerance indices derived generically from chain screws.

Given, for every chain of a parallel mechanism, its joint twists in the world frame at a
batch of configurations (a :class:`~screwkit.screw.chain_screws.ChainScrews`), :func:`analyze`
derives

* the platform's **motion space** and its DOF ``n`` (the twists every chain can follow
  with all its joints free; a planar mechanism in 3-D space gets ``n = 3`` by itself);
* the **actuation wrench** of every actuator: reciprocal to the other joints of its chain,
  with the chain's constraint wrenches removed (see :func:`analyze` for the representative);
* the **ITI** of every actuator and overall (Eqs. 6-7);
* the **output twists** and **OTI** of every non-redundant ``n``-subset of actuators
  (Eqs. 8-9), computed once per configuration and shared by every LMTI;
* the **LMTI** of any actuator set (Eq. 11), the **output fault-tolerance indices**
  ``F_Oj`` for ``j = 1..a-n`` (Eqs. 12-13) and the **input-output** ones ``F_IOj`` (Eq. 14);
* which actuators are **mutual-interference actuators**.

Everything is batched: validation and planning (motion space, submechanisms, fault sets)
are numpy; the per-configuration screw algebra and the reductions over actuator sets run
in one compiled kernel (:mod:`screwkit.indices.compiled.algebra`, numba, vectorised across configurations,
no allocation per configuration) over chunks of configurations, the chunks side by side on
several cores. numba is imported only when :func:`analyze` first runs.

**Working coordinates.** The indices are dimensionless and frame invariant, and so is every
decision taken on the way: each configuration is expressed about the centroid ``c`` of its
platform joints with lengths in units of its characteristic length ``L`` (the RMS distance of
all its joint points from ``c``), and every tolerance (:mod:`screwkit.common.tolerances`) compares
numbers of those coordinates. The one length is the singularity threshold *p*, compared as
``p / L``. Results come back in world units and frame.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.common import tolerances
from screwkit.common.chunks import map_chunks
from screwkit.common.compiling import prepare_kernels
from screwkit.common.validation import as_float_array, check_finite
from screwkit.indices.faults import FAULT_TYPES, link_fault_indices
from screwkit.indices.results import Indices
from screwkit.indices.sets import fault_sets, remaining_lmti, set_plan, submechanisms_left
from screwkit.screw.chain_screws import ChainScrews
from screwkit.screw.constraints import ConstraintPlan, constraint_indices, plan_constraints
from screwkit.screw.motion import (
    MotionSpace,
    chain_decompositions,
    motion_space,
    null_spaces,
    sampled_working_coordinates,
    working_coordinates,
)
from screwkit.screw.outputs import idle_rotations, quotient_bases, with_idle_joints

__all__ = ["MotionSpace", "analyze", "motion_space", "fault_sets"]

DEFAULT_THRESHOLD = tolerances.SINGULARITY_THRESHOLD
"""The paper's singularity threshold *p* on the moment arm: 1 um (in metres)."""


# ----------------------------------------------------------------------------------------
# ----------------------------------------------------------------------------------------
# Analysis
# ----------------------------------------------------------------------------------------
@dataclass
class _Plan:
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


def _make_plan(chains, dof, faults, threshold, rank_tolerance, idle_count: int = 0) -> _Plan:
    if not threshold >= 0:
        raise ValueError(f"Expected `threshold` >= 0 (a length), got {threshold}.")
    if not rank_tolerance > 0:
        raise ValueError(f"Expected `rank_tolerance` > 0, got {rank_tolerance}.")
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
    if faults is None:
        fault_list = tuple(range(1, a - n + 1))
    else:
        fault_list = tuple(sorted(set(int(j) for j in np.atleast_1d(faults))))
        for j in fault_list:
            if not 1 <= j <= max(a - n, 1):
                raise ValueError(f"Expected the number of faults `j` in 1..a-n = 1..{a - n}, got {j}.")
        if a == n:  # no redundancy: F_O1 = 0 (see analyze), no set of n actuators is left to reduce
            fault_list = ()
    complement = space.complement if space.constant_basis is not None else np.empty((0, 6))
    return _Plan(
        actuators=actuators, dof=n, space=space, complement=complement,
        chain_start=np.cumsum([0] + [c.n_joints for c in chains]).astype(np.int64),
        actuator_chain=np.array([c for c, _ in actuators], dtype=np.int64),
        actuator_joint=np.array([k for _, k in actuators], dtype=np.int64),
        faults=fault_list, **set_plan(a, n, fault_list),
        threshold=float(threshold), rank_tolerance=float(rank_tolerance),
        idle_count=idle_count)



def _run_kernel(plan: _Plan, twists, points, basis, complement, iti_override, oti_override, detail, keep_twists):
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


class _ChunkSpaces:
    """A chunk's chains in working coordinates and their decompositions, computed once when first asked
    (shared by the motion spaces and the constraint indices)."""

    def __init__(self, plan: _Plan, twists, points):
        self.plan, self.twists, self.points = plan, twists, points

    @cached_property
    def working(self):
        starts = self.plan.chain_start
        chain_twists = [self.twists[:, starts[c]:starts[c + 1]] for c in range(len(starts) - 1)]
        chain_points = [self.points[:, starts[c]:starts[c + 1]] for c in range(len(starts) - 1)]
        return working_coordinates(chain_twists, chain_points)

    @cached_property
    def decompositions(self):
        return chain_decompositions(self.working[0])


def _analyze_chunk(plan: _Plan, twists, points, iti_override, oti_override, detail, keep_twists, idle=None,
                   spaces: _ChunkSpaces | None = None) -> dict:
    """All indices for one chunk of configurations (arrays (N, J, 6) and (N, J, 3) over all joints);
    ``spaces`` the chunk's working coordinates when they are needed for every configuration anyway."""
    if plan.space.constant_basis is not None:
        basis = plan.space.constant_basis[None]
        out = _run_kernel(plan, twists, points, basis, plan.complement, iti_override, oti_override,
                          detail, keep_twists)
        redo = np.flatnonzero(out["outside"])
    else:
        out, redo = None, np.arange(twists.shape[0])
    if redo.size:
        # Configurations whose joint twists leave the constant space: their own motion space, in
        # the working coordinates the kernel uses (same centroid and characteristic length).
        if spaces is not None or redo.size == twists.shape[0]:
            spaces = spaces or _ChunkSpaces(plan, twists, points)
            working, _, centre, length = spaces.working
            working = [chain[redo] for chain in working]
            centre, length = centre[redo], length[redo]
            decompositions = [(singular[redo], right[redo]) for singular, right in spaces.decompositions]
        else:
            working, _, centre, length = _ChunkSpaces(plan, twists[redo], points[redo]).working
            decompositions = None
        _, bases = null_spaces(working, plan.dof + plan.idle_count, tolerances.MOTION_SPACE_TOLERANCE,
                               decompositions)
        if plan.idle_count:
            bases = quotient_bases(bases, idle[redo], centre, length, plan.dof)
        again = _run_kernel(plan, twists[redo], points[redo], np.ascontiguousarray(bases), np.empty((0, 6)),
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


def _joints_of_all_chains(arrays: list[NDArray]):
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


def _constraint_plan(chains: list[ChainScrews], count: int) -> ConstraintPlan:
    """The constraint structure of the chains, found on up to 9 configurations spread over the batch."""
    if not count:
        return ConstraintPlan(tuple(0 for _ in chains), 0)
    _, working, _, _, _ = sampled_working_coordinates(chains)
    return plan_constraints(working)


def _constraint_chunk(plan: _Plan, constraint_plan: ConstraintPlan, spaces: _ChunkSpaces, wrenches,
                      fault_members) -> dict:
    """The CTI of a chunk (see :mod:`screwkit.screw.constraints`), in the kernel's working coordinates."""
    working, working_points, centre, length = spaces.working
    moments = wrenches[..., 3:] + np.cross(wrenches[..., :3], centre[:, None, :])  # about the centroid
    working_wrenches = np.concatenate([wrenches[..., :3], moments / length[:, None, None]], axis=-1)
    norms = np.linalg.norm(working_wrenches, axis=-1, keepdims=True)
    working_wrenches = working_wrenches / np.where(norms > 0.0, norms, 1.0)
    # With a point output the idle rotations are joints of the chains: the platform's instantaneous DOF
    # counts them, and the CTI (defined for a frame output, every wrench acting on the platform) does not apply.
    result = constraint_indices(constraint_plan, working, working_points, working_wrenches, plan.submechanisms,
                                plan.dof + plan.idle_count, fault_members, plan.threshold / length,
                                spaces.decompositions)
    if plan.idle_count:
        result["instantaneous_dof"] = result["instantaneous_dof"] - plan.idle_count
        for key in result:
            if key == "cti" or key == "cti_submechanisms" or key.startswith("f_c"):
                result[key] = np.full(result[key].shape, np.nan)
    return result


def _at_constraint_singularities(plan: _Plan, result: dict, held: NDArray) -> None:
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


def analyze(
    chains: Sequence[ChainScrews],
    *,
    dof: int | None = None,
    faults: int | Sequence[int] | None = None,
    threshold: float = DEFAULT_THRESHOLD,
    rank_tolerance: float = tolerances.RANK_TOLERANCE,
    iti_points: ArrayLike | None = None,
    oti_points: ArrayLike | None = None,
    detail: bool = True,
    keep_twists: bool = False,
    chunk_size: int = 65536,
    threads: int | None = None,
    output_point: ArrayLike | None = None,
    planar: bool | ArrayLike = False,
    fault_type: str = "free-swinging",
) -> Indices:
    r"""Every index of the paper for a batch of configurations, derived from chain screws.

    **Working coordinates.** Each configuration is expressed about the centroid ``c`` of its
    platform joints (the last joint of every chain) with lengths in units of its characteristic
    length

    .. math:: L = \sqrt{\tfrac{1}{J} \textstyle\sum_j \lVert p_j - c \rVert^2}

    over all its ``J`` joint points: a twist :math:`(\omega, v)` becomes
    :math:`(\omega, v_c / L)`, a wrench :math:`(f, m)` becomes :math:`(f, m_c / L)`, a point
    :math:`(p - c) / L`. These coordinates are the same for a mechanism and for any scaled or
    rigidly moved copy of it, so every tolerance below compares dimensionless numbers and no
    decision depends on the length unit, the scale or the world frame; the singularity
    threshold *p*, a length, is compared as :math:`p / L`. ``c`` and ``L`` belong to each
    configuration: a batch gives what a loop over single configurations gives.

    **Actuation wrench** (Sec. 2): the wrench of chain ``i`` reciprocal to every other
    joint of the chain; it is defined modulo the chain's constraint wrenches. screwkit's
    representative is the one *orthogonal to the constraint wrenches in working coordinates,
    with moments taken about the chain's platform-joint point* ``d`` — the minimum-norm
    solution of the reciprocity conditions

    .. math:: w = \Delta J'_i (J_i'^T J'_i)^{-1} e_k

    (:math:`J'_i` the chain's twists about ``d`` in working coordinates, :math:`\Delta` the
    swap of the halves), i.e. orthogonal in the metric :math:`|f|^2 + |m_d|^2 / L^2`. It is
    covariant with the scale and invariant to a rigid motion of the whole mechanism and to the
    world frame. Where a constraint wrench passes through ``d`` (planar RRR/RPR, RPS, PRS
    chains) the metric does not matter; for a planar RRR/RPR chain it is the paper's force
    along the distal link through :math:`d_i` (Eq. 21). For a chain with exactly ``n`` joints
    (which then spans the motion space ``M``) the same wrench is computed as
    :math:`\Delta M' x`, :math:`x \in \mathrm{null}(J'^T_{\text{passive}} M')`, which stays
    defined where the chain itself is singular (ITI = 0). Wrenches are scaled to a unit force
    (a unit moment for a pure couple: :math:`|f| \le` ``PURE_COUPLE`` :math:`|m_c| / L`) and
    signed so that they do positive work on their own joint.

    **Characteristic points**: for the ITI the point of the first joint after the actuator,
    for the OTI the chain's platform-joint point, each projected on the wrench axis
    (overridable with ``iti_points`` / ``oti_points``, used as given).

    **Output twists** (Eq. 8): for a submechanism ``N`` with wrench matrix
    :math:`W_N = [A_k \circ M_q]` in motion coordinates (``M`` an orthonormal basis of the
    motion space in working coordinates), the output twists are the columns of
    :math:`\mathrm{adj}(W_N)` mapped by ``M``. Column ``k`` depends only on the other
    ``n - 1`` (locked) actuators, so it is computed once per locked set and shared by every
    submechanism containing it (for ``n >= 4`` as the exterior product of the locked wrenches,
    whose minors lexicographically neighbouring locked sets share); :math:`|A_k \circ T_k| = |\det W_N|` for every ``k``
    (general form of Eq. A3), and

    .. math:: OTI_k = \frac{|\det W_N|}{\| v_k + \omega_k \times p_k + h_k \omega_k \|}

    with the zero cases of the paper: ``OTI_k = 0`` when the moment arm is at or below
    ``threshold`` (the paper's *p*), and every ``OTI_k`` of ``N`` is zero when its wrenches
    are dependent (:math:`|\det W_N|` at or below ``rank_tolerance`` times the product of
    its row norms, in working coordinates). An actuator is a mutual-interference actuator
    when some ``n`` of the other actuators have independent wrenches.

    Then ``OTI_N = min_k OTI_k`` (Eq. 9), ``LMTI_E = max_{N subset E} OTI_N`` (Eq. 11),
    ``F_Oj = min_{|E| = a - j} LMTI_E`` (Eqs. 12-13; for ``j = a - n`` this is the minimum
    OTI), ``F_IOj = min(F_Oj, ITI)`` (Eq. 14). The **worst fault** reported with ``F_Oj`` is
    the complement of the first set ``E``, in combination order, whose LMTI is at most
    ``F_Oj + WORST_FAULT_TIE`` (``1e-12``): numpy's argmin, except that sets whose LMTIs are
    mathematically equal and differ by rounding count as equal, so the choice does not change
    with the unit or the frame.

    The dimensionless tolerances are named in :mod:`screwkit.common.tolerances` (``RANK_TOLERANCE``,
    ``PURE_COUPLE``, ``MOTION_SPACE_TOLERANCE``, ``MOTION_SPACE_EIGENVALUE``,
    ``CONSTANT_BASIS_TOLERANCE``, ``OUTSIDE_CONSTANT_SPACE``, ``GRAM_PIVOT``,
    ``PSEUDO_INVERSE_CONSISTENCY``, ``WORST_FAULT_TIE``).

    Parameters
    ----------
    chains : sequence of ChainScrews
        All chains, with the same batch shape.
    dof : int, optional
        Impose the platform's DOF ``n`` (derived from the screws by default).
    faults : int or sequence of int, optional
        Which ``j`` to compute ``F_Oj``/``F_IOj`` for; default ``1..a-n``.
    threshold : float
        Singularity threshold *p* on the moment arm, in the length unit of the screws
        (default 1e-6: 1 um in metres). The only input with a unit: scale it with the
        mechanism.
    rank_tolerance : float
        Relative tolerance for dependent actuation wrenches (dimensionless).
    iti_points, oti_points : array_like, shape (..., a, 3), optional
        Characteristic points overriding the defaults (world frame).
    detail : bool
        Keep per-actuator and per-submechanism arrays (needed by :meth:`Indices.lmti_of`).
    keep_twists : bool
        Also keep the output twists (memory: ``S * n * 6`` floats per configuration).
    chunk_size : int
        Configurations per chunk (bounds memory).
    threads : int, optional
        Threads running chunks side by side (default: the number of CPUs).
    output_point : array_like, shape (..., 3), optional
        A point output (world frame): the rotations of the platform about it are idle
        (:mod:`screwkit.screw.outputs`) and the indices are those of the point's motion: ``n`` is the
        DOF of the point, actuation wrenches are forces through it.
    planar : bool or array_like (3,)
        With ``output_point``: the mechanism is planar, its only idle rotation is about the plane's
        normal: z when True, else the normal given (world frame).
    fault_type : {"free-swinging", "link"}
        What a fault is: a failed actuator becomes a passive joint (the paper's FSJF, default),
        or its chain disappears with its constraint wrenches (LF, :mod:`screwkit.indices.faults`).
        Changes ``F_Oj``, ``F_IOj``, the worst faults and ``F_Cj``.

    Returns
    -------
    Indices
        Actuators named ``chain:joint`` from the chains' names and joint names. Actuation
        wrenches and output twists are in the world frame and the unit of the screws.
    """
    chains = list(chains)
    if not chains:
        raise ValueError("Expected at least one chain in `chains`, got none.")
    if fault_type not in FAULT_TYPES:
        raise ValueError(f"Expected `fault_type` in {', '.join(FAULT_TYPES)}, got {fault_type!r}.")
    if fault_type == "link" and (iti_points is not None or oti_points is not None):
        raise ValueError("`iti_points` and `oti_points` apply to free-swinging faults only, not fault_type='link'.")
    given_chains = chains
    for chain in chains:
        if not isinstance(chain, ChainScrews):
            raise ValueError(f"Expected `chains` to hold ChainScrews, got {type(chain).__name__}.")
    batch_shape = chains[0].batch_shape
    for chain in chains[1:]:
        if chain.batch_shape != batch_shape:
            raise ValueError(
                f"Expected every chain to share the batch shape {batch_shape}, "
                f"chain {chain.name!r} has {chain.batch_shape}."
            )
    if not isinstance(chunk_size, (int, np.integer)) or chunk_size < 1:
        raise ValueError(f"Expected `chunk_size` >= 1, got {chunk_size!r}.")
    if threads is not None and (not isinstance(threads, (int, np.integer)) or threads < 1):
        raise ValueError(f"Expected `threads` >= 1, got {threads!r}.")
    count = int(np.prod(batch_shape, dtype=np.int64))
    idle = None
    if output_point is not None:
        point = check_finite(as_float_array(output_point, "output_point"), "output_point")
        try:
            point = np.broadcast_to(point, batch_shape + (3,)).reshape(count, 3)
        except ValueError:
            raise ValueError(f"Expected `output_point` with shape (..., 3), got {point.shape}.") from None
        idle, idle_points = idle_rotations(point, planar)
        index, _, _, centre, length = sampled_working_coordinates(chains)
        chains = with_idle_joints(chains, idle, idle_points, centre, length, index)
    plan = _make_plan(chains, dof, faults, threshold, rank_tolerance, 0 if idle is None else idle.shape[-2])
    a = len(plan.actuators)
    overrides = {}
    for name, value in (("iti_points", iti_points), ("oti_points", oti_points)):
        if value is not None:
            array = check_finite(as_float_array(value, name), name)
            try:
                array = np.broadcast_to(array, batch_shape + (a, 3))
            except ValueError:
                raise ValueError(f"Expected `{name}` with shape (..., {a}, 3), got {array.shape}.") from None
            # writable for the kernel
            overrides[name] = np.array(array.reshape(count, a, 3), dtype=np.float64, order="C")
    twists = _joints_of_all_chains([chain.twists.reshape((count,) + chain.twists.shape[-2:]) for chain in chains])
    points = _joints_of_all_chains([chain.points.reshape((count,) + chain.points.shape[-2:]) for chain in chains])

    # a platform free in all six DoF: every chain's twists span all twists, so no chain holds a constraint wrench
    constraint_plan = (_constraint_plan(chains, count) if plan.space.dof < 6
                       else ConstraintPlan(tuple(0 for _ in chains), 0))
    fault_members = submechanisms_left(a, plan.dof, plan.faults) if constraint_plan.count else {}

    def run(part: slice) -> dict:
        chunk_twists, chunk_points = twists(part), points(part)
        spaces = _ChunkSpaces(plan, chunk_twists, chunk_points) if constraint_plan.count else None
        result = _analyze_chunk(
            plan, chunk_twists, chunk_points,
            overrides["iti_points"][part] if "iti_points" in overrides else None,
            overrides["oti_points"][part] if "oti_points" in overrides else None,
            detail or constraint_plan.count > 0, keep_twists, None if idle is None else idle[part], spaces)
        if constraint_plan.count:
            result.update(_constraint_chunk(plan, constraint_plan, spaces, result["actuation_wrenches"],
                                            fault_members))
            if "held_without" in result:
                _at_constraint_singularities(plan, result, result.pop("held_without"))
            if not detail:
                for key in ("iti_actuators", "oti_actuators", "oti_submechanisms", "actuation_wrenches",
                            "cti_submechanisms", *(f"remaining{j}" for j in plan.faults)):
                    result.pop(key, None)
        return result

    pieces = map_chunks(run, count, chunk_size, threads)
    merged = {key: np.concatenate([piece[key] for piece in pieces], axis=0) for key in pieces[0]}

    def batch_first(array: NDArray) -> NDArray:
        return array.reshape(batch_shape + array.shape[1:])

    names = tuple(f"{chains[c].name or f'chain_{c + 1}'}:{chains[c].joint_names[k]}" for c, k in plan.actuators)
    f_o = {j: batch_first(merged[f"f_o{j}"]) for j in plan.faults}
    worst = {j: batch_first(merged[f"worst{j}"]) for j in plan.faults}
    not_applicable = np.broadcast_to(np.nan, batch_shape)  # no constraint wrench held by one chain alone: no CTI
    f_c = ({j: batch_first(merged[f"f_c{j}"]) for j in plan.faults} if constraint_plan.count
           else dict.fromkeys(plan.faults, not_applicable))
    remaining = {j: batch_first(merged[f"remaining{j}"]) for j in plan.faults} if detail else {}
    if a == plan.dof:  # no redundancy (a = n): one failed actuator leaves the platform
        # uncontrolled, so no set of n working actuators remains: F_O1 = F_IO1 = 0 (every fault ties; the first named)
        f_o = {1: np.zeros(batch_shape)}
        worst = {1: np.zeros(batch_shape + (1,), dtype=np.int64)}
        f_c = {1: np.zeros(batch_shape) if constraint_plan.count else not_applicable}
        remaining = {1: np.zeros(batch_shape + (a,))} if detail else {}
    if fault_type == "link" and plan.faults:
        options = {"analyze": dict(threshold=threshold, rank_tolerance=rank_tolerance, chunk_size=chunk_size,
                                   threads=threads, output_point=output_point, planar=planar),
                   "idle_count": 0 if idle is None else idle.shape[-2]}
        link = link_fault_indices(given_chains, plan.actuators, plan.faults, batch_shape, analyze, options)
        f_o, worst = link["f_o"], link["worst"]
        remaining = link["lmti"] if detail else {}
        f_c = link["f_c"] if constraint_plan.count else f_c
    return Indices(
        actuators=names,
        dof=plan.dof,
        submechanisms=tuple(tuple(int(i) for i in sub) for sub in plan.submechanisms),
        iti=batch_first(merged["iti"]),
        lmti=batch_first(merged["lmti"]),
        f_o=f_o,
        f_io={j: np.minimum(f_o[j], batch_first(merged["iti"])) for j in f_o},
        worst_fault_indices=worst,
        mutual_interference=batch_first(merged["mutual_interference"]),
        threshold=plan.threshold,
        iti_actuators=batch_first(merged["iti_actuators"]) if detail else None,
        oti_actuators=batch_first(merged["oti_actuators"]) if detail else None,
        oti_submechanisms=batch_first(merged["oti_submechanisms"]) if detail else None,
        actuation_wrenches=batch_first(merged["actuation_wrenches"]) if detail else None,
        output_twists=batch_first(merged["output_twists"]) if detail and keep_twists else None,
        cti=batch_first(merged["cti"]) if constraint_plan.count else not_applicable,
        f_c=f_c,
        cti_submechanisms=batch_first(merged["cti_submechanisms"]) if constraint_plan.count and detail else None,
        constraint_count=constraint_plan.count if idle is None else 0,
        cti_reason=(constraint_plan.reason if idle is None
                    else "the output is a point: the CTI is defined for a frame output, whose every wrench acts on it"),
        instantaneous_dof=batch_first(merged["instantaneous_dof"]) if constraint_plan.count else None,
        constraint_singular=batch_first(merged["constraint_singular"]) if constraint_plan.count else None,
        fault_type=fault_type,
        remaining_lmti=remaining,
    )
