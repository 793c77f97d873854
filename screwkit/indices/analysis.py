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

from dataclasses import replace
from typing import Iterable, Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.common import tolerances
from screwkit.common.chunks import map_chunks
from screwkit.common.validation import as_float_array, check_finite
from screwkit.indices.faults import FAULT_TYPES, link_fault_indices
from screwkit.indices.registry import INDICES
from screwkit.indices.results import Indices
from screwkit.indices.sets import fault_sets, submechanisms_left
from screwkit.indices.stages import (
    ChunkSpaces,
    analyze_chunk,
    at_constraint_singularities,
    checked_chunk_size,
    constraint_chunk,
    constraint_plan_of,
    joints_of_all_chains,
    make_plan,
)
from screwkit.screw.chain_screws import ChainScrews
from screwkit.screw.constraints import ConstraintPlan
from screwkit.screw.motion import (
    MotionSpace,
    motion_space,
    sampled_working_coordinates,
)
from screwkit.screw.outputs import idle_rotations, with_idle_joints

__all__ = ["MotionSpace", "analyze", "motion_space", "fault_sets", "constraint_structure"]

DEFAULT_THRESHOLD = tolerances.SINGULARITY_THRESHOLD
"""The paper's singularity threshold *p* on the moment arm: 1 um (in metres)."""


def _structure(chains: list[ChainScrews], batch_shape: tuple[int, ...], count: int, dof, faults, threshold,
               rank_tolerance, output_point, planar):
    """The chains :func:`analyze` works on (with the idle rotations of a point output as passive joints), the idle
    rotations (None for a frame output), its :class:`~screwkit.indices.stages.Plan` and the constraint plan."""
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
    plan = make_plan(chains, dof, faults, threshold, rank_tolerance, 0 if idle is None else idle.shape[-2])
    # a platform free in all six DoF: every chain's twists span all twists, so no chain holds a constraint wrench
    constraint_plan = (constraint_plan_of(chains, count, plan.space.dof) if plan.space.dof < 6
                       else ConstraintPlan(tuple(0 for _ in chains), 0))
    return chains, idle, plan, constraint_plan


def constraint_structure(chains: Sequence[ChainScrews], *, dof: int | None = None,
                         output_point: ArrayLike | None = None, planar: bool | ArrayLike = False):
    """What :func:`analyze` finds of these chains' structure (taking its arguments): the constraint plan (``count``
    0: no chain holds a constraint wrench of its own), the number ``n`` of actuators of a submechanism, and whether
    the motion space is the same at every configuration of the batch (else each configuration takes its own)."""
    chains = list(chains)
    batch_shape = chains[0].batch_shape
    count = int(np.prod(batch_shape, dtype=np.int64))
    _, _, plan, constraint_plan = _structure(chains, batch_shape, count, dof, None, DEFAULT_THRESHOLD,
                                             tolerances.RANK_TOLERANCE, output_point, planar)
    return constraint_plan, plan.dof, plan.space.constant_basis is not None


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
    configuration: a batch gives what a loop over single configurations gives, to rounding (the chunks and the
    other configurations of a batch can change the last digits, about 1e-15).

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

    **Characteristic points**: for the ITI the first joint after the actuator, for the OTI the
    chain's platform joint. On a force, where its axis comes nearest to the joint's axis
    (:func:`~screwkit.screw.algebra.nearest_on_axis`: where it crosses a revolute, wherever along
    its axis the joint is drawn); the joint's point projected on the wrench axis for a wrench with
    a pitch, a prismatic joint, a universal or ball joint written as revolutes
    (:func:`~screwkit.screw.algebra.joint_lines`) and an axis parallel to the force's (overridable
    with ``iti_points`` / ``oti_points``, projected on the wrench axis: the paper rotates a wrench about a point on
    it). The chains' points are taken as given; the
    loader draws every revolute of a file at a point its geometry decides
    (:mod:`screwkit.closure.canonical`), so that ``L``, the representative and these points do not
    depend on where along its axis the file draws it.

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
        Characteristic points overriding the defaults (world frame), each projected on its actuator's wrench axis
        (the point of the axis nearest to it; a pure couple keeps it).
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
    if isinstance(chains, (ChainScrews, str)) or not isinstance(chains, Iterable):  # a Mechanism, one chain, a name
        raise TypeError(f"Expected `chains` as a sequence of ChainScrews (screwkit.closure.chain_screws of a solved "
                        f"mechanism; indices of a Mechanism at poses: screwkit.indices_at_poses), got "
                        f"{type(chains).__name__}.")
    chains = list(chains)
    if not chains:
        raise ValueError("Expected at least one chain in `chains`, got none.")
    if fault_type not in FAULT_TYPES:
        raise ValueError(f"Expected `fault_type` in {', '.join(FAULT_TYPES)}, got {fault_type!r}.")
    if fault_type == "link" and (iti_points is not None or oti_points is not None):
        raise ValueError("`iti_points` and `oti_points` apply to free-swinging faults only, not fault_type='link'.")
    given_chains = chains
    # indices derived from the per-configuration detail (registry records with a `compute`) need that detail
    derived = any(record.compute is not None for record in INDICES.values())
    requested_detail, detail = detail, detail or derived
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
    checked_chunk_size(chunk_size)
    if threads is not None and (not isinstance(threads, (int, np.integer)) or threads < 1):
        raise ValueError(f"Expected `threads` >= 1, got {threads!r}.")
    count = int(np.prod(batch_shape, dtype=np.int64))
    chains, idle, plan, constraint_plan = _structure(chains, batch_shape, count, dof, faults, threshold,
                                                     rank_tolerance, output_point, planar)
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
    twists = joints_of_all_chains([chain.twists.reshape((count,) + chain.twists.shape[-2:]) for chain in chains])
    points = joints_of_all_chains([chain.points.reshape((count,) + chain.points.shape[-2:]) for chain in chains])

    fault_members = submechanisms_left(a, plan.dof, plan.faults) if constraint_plan.count else {}

    def run(part: slice) -> dict:
        chunk_twists, chunk_points = twists(part), points(part)
        spaces = ChunkSpaces(plan, chunk_twists, chunk_points) if constraint_plan.count else None
        result = analyze_chunk(
            plan, chunk_twists, chunk_points,
            overrides["iti_points"][part] if "iti_points" in overrides else None,
            overrides["oti_points"][part] if "oti_points" in overrides else None,
            detail or constraint_plan.count > 0, keep_twists, None if idle is None else idle[part], spaces)
        if constraint_plan.count:
            result.update(constraint_chunk(plan, constraint_plan, spaces, result["actuation_wrenches"],
                                            fault_members))
            if "held_without" in result:
                at_constraint_singularities(plan, result, result.pop("held_without"))
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
    if a == plan.dof and not (faults is not None and np.size(faults) == 0):  # no redundancy (a = n), and fault
        # indices not declined (faults=()): one failed actuator leaves the platform uncontrolled, so no set of n
        # working actuators remains: F_O1 = F_IO1 = 0 (every fault ties; the first named)
        f_o = {1: np.zeros(batch_shape)}
        worst = {1: np.zeros(batch_shape + (1,), dtype=np.int64)}
        f_c = {1: np.zeros(batch_shape) if constraint_plan.count else not_applicable}
        remaining = {1: np.zeros(batch_shape + (a,))} if detail else {}
    if fault_type == "link" and plan.faults:
        options = {"analyze": dict(threshold=threshold, rank_tolerance=rank_tolerance, chunk_size=chunk_size,
                                   threads=threads, output_point=output_point, planar=planar),
                   "idle_count": 0 if idle is None else idle.shape[-2]}
        link = link_fault_indices(given_chains, plan.actuators, plan.faults, batch_shape, analyze, options)
        if constraint_plan.count:  # a constraint singularity of the intact mechanism: no fault index (as for FSJF)
            singular = batch_first(merged["constraint_singular"]).astype(bool)
            for j in plan.faults:
                for name in ("f_o", "f_c", "lmti"):
                    link[name][j] = np.where(singular[..., None] if name == "lmti" else singular, 0.0,
                                             link[name][j])
                link["worst"][j] = np.where(singular[..., None], plan.failed_sets[j][0], link["worst"][j])
        f_o, worst = link["f_o"], link["worst"]
        remaining = link["lmti"] if detail else {}
        f_c = link["f_c"] if constraint_plan.count else f_c
    arrays = {"iti": batch_first(merged["iti"]), "lmti": batch_first(merged["lmti"]), "f_o": f_o,
              "worst_fault_indices": worst, "mutual_interference": batch_first(merged["mutual_interference"]),
              "f_c": f_c, "remaining_lmti": remaining,
              "cti": batch_first(merged["cti"]) if constraint_plan.count else not_applicable}
    if detail:
        arrays.update({name: batch_first(merged[name]) for name in
                       ("iti_actuators", "oti_actuators", "oti_submechanisms", "actuation_wrenches")})
        if keep_twists:
            arrays["output_twists"] = batch_first(merged["output_twists"])
    if constraint_plan.count:
        arrays.update({name: batch_first(merged[name]) for name in ("instantaneous_dof", "constraint_singular")})
        if detail:
            arrays["cti_submechanisms"] = batch_first(merged["cti_submechanisms"])
    result = Indices.from_arrays(
        names, plan.dof, arrays, threshold=plan.threshold, submechanisms=plan.submechanisms, derive=derived,
        constraint_count=constraint_plan.count if idle is None else 0, fault_type=fault_type,
        cti_reason=(constraint_plan.reason if idle is None
                    else "the output is a point: the CTI is defined for a frame output, whose every wrench acts on it"))
    if not derived or requested_detail:
        return result
    return replace(result, iti_actuators=None, oti_actuators=None, oti_submechanisms=None, actuation_wrenches=None,
                   output_twists=None, cti_submechanisms=None, remaining_lmti={})
