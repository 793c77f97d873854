r"""Constraint wrenches, constraint singularities and the constraint transmission index (CTI).

A chain whose joints do not span every twist transmits **constraint wrenches** to the platform:
the wrenches reciprocal to all its joint twists (a PRS leg: a force through the S centre along
the R axis; a Delta leg: a couple). Liu, Wu and Wang's constraint transmission index measures how
well they hold the platform: lock the actuators, release one constraint wrench, and take the
power coefficient of that wrench on the one twist it leaves free; the CTI is the lowest over the
constraint wrenches. screwkit computes it in its working coordinates (as
:func:`screwkit.indices.analysis.analyze`), so it is independent of the length unit, the scale and the
world frame, and it is **symmetric in the chains**: no decision depends on the order in which they
are listed. The conventions below are screwkit's, stated with their reasons in ``docs/theory.md``
(*Constraint wrenches and the CTI*):

* **Constraints common to every chain** (the out-of-plane wrenches of a planar mechanism, the two
  horizontal couples of every Schoenflies leg, the three forces through the centre of a spherical
  wrist) are kept but never released: no chain holds them alone, releasing one chain's copy frees
  nothing. A mechanism with no other constraint wrench has no CTI ("not applicable": NaN, with
  :attr:`ConstraintPlan.reason`).
* The other constraint wrenches of chain ``i`` (its **own** ones, ``C_i``) may hold more than the
  platform needs (a 4-leg Delta: four couples of rank three). As the LMTI does for redundant
  actuators (Eq. 11), the CTI takes the best of the **non-redundant constraint subsystems**: the
  minimal sets ``L`` of chains whose own constraint wrenches, with the common ones, hold every
  constraint of the mechanism (generic rank; :attr:`ConstraintPlan.subsystems`, all of them, in no
  privileged order).
* For a set ``N`` of ``n`` actuators and a subsystem ``L``, releasing chain ``i`` of ``L`` (its
  ``C_i``) with the actuators of ``N`` locked and the other chains of ``L`` and the common
  constraints kept frees the twists ``F_i`` reciprocal to every other wrench. Each freed twist is
  paired with the constraint wrench of ``C_i`` that resists it along the principal directions of
  the pairing (the singular vectors of ``C_i o F_i``, working coordinates; one pair when the chain
  holds one constraint wrench; a block of repeated singular values, whose vectors any rotation of the block
  gives as well, takes its worst rotation: :mod:`screwkit.screw.principal_pairs`), and

  .. math:: \kappa = \frac{|C \circ T|}{|C \circ T|_{\max}}, \qquad
            CTI_{N,L} = \min_{i \in L,\ \text{pairs}} \kappa, \qquad CTI_N = \max_L CTI_{N,L},

  with the characteristic point of ``C`` the platform joint of its chain projected on its axis (a
  couple gives :math:`|\hat m \cdot \hat\omega|`), and :math:`CTI_{N,L} = 0` when the wrenches of
  ``N``, ``L`` and the common constraints do not span every wrench.
* As the LMTI over actuator sets (Eq. 11): :math:`CTI = \max_N CTI_N`, and its fault-tolerant
  counterpart, screwkit's extension in the spirit of Eq. 12, :math:`F_{Cj} = \min_E \max_{N \subset E}
  CTI_N` over the actuator sets ``E`` left after ``j`` faults.
* The **instantaneous DOF** of a configuration is six minus the rank of all constraint wrenches;
  where it exceeds the mechanism's mobility ``n`` the configuration is a **constraint
  singularity** and its CTI is zero.

Only numpy is imported here.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations

import numpy as np
from numpy.typing import NDArray

from screwkit.common import tolerances
from screwkit.screw.algebra import SWAP, joint_lines
from screwkit.screw.motion import chain_decompositions
from screwkit.screw.principal_pairs import pair_coefficients, released_pairs, worst_in_blocks

__all__ = ["ConstraintPlan", "plan_constraints", "constraint_indices", "chain_constraint_wrenches"]


@dataclass(frozen=True)
class ConstraintPlan:
    """How a mechanism's constraint wrenches are organised (found on sample configurations).

    Attributes
    ----------
    chain_counts : tuple of int
        Constraint wrenches of each chain (6 minus the rank of its joint twists).
    common : int
        Dimension of the constraint wrenches common to every chain.
    own_counts : tuple of int
        Each chain's own (non-common) constraint wrenches.
    rank : int
        Rank of all the chains' own constraint wrenches together (generic): what a subsystem releases.
    subsystems : tuple of tuple of int
        The non-redundant constraint subsystems: every minimal set of chains whose own constraint
        wrenches have rank :attr:`rank`, in combination order of the chains.
    """

    chain_counts: tuple[int, ...]
    common: int
    own_counts: tuple[int, ...] = ()
    rank: int = 0
    subsystems: tuple[tuple[int, ...], ...] = ()

    @property
    def count(self) -> int:
        """Constraint wrenches a subsystem releases: none means the CTI does not apply."""
        return self.rank if self.subsystems else 0

    @property
    def reason(self) -> str:
        """Why the CTI does not apply ("" when it does)."""
        if self.count:
            return ""
        if not any(self.chain_counts):
            return "no chain holds a constraint wrench"
        return (f"every chain holds the same {self.common} constraint wrench{'es' if self.common > 1 else ''} "
                "(none is held by one chain alone)")


def _unit_rows(rows: NDArray) -> NDArray:
    norms = np.linalg.norm(rows, axis=-1, keepdims=True)
    return rows / np.where(norms > 0.0, norms, 1.0)


def chain_constraint_wrenches(twists: NDArray, count: int, decomposition: tuple | None = None) -> NDArray[np.float64]:
    """The ``count`` constraint wrenches (N, count, 6) of a chain's joint twists (N, m, 6): an orthonormal
    basis of the wrenches reciprocal to all of them (working coordinates). ``decomposition``: the chain's
    :func:`screwkit.screw.motion.chain_decompositions` when already computed."""
    if count == 0:
        return np.zeros(twists.shape[:-2] + (0, 6))
    _, right = decomposition if decomposition is not None else chain_decompositions([twists])[0]
    return right[..., 6 - count:, :] @ SWAP  # twists reciprocal to ... -> wrenches: swap the halves


def _rank(rows: NDArray, tolerance: float) -> NDArray[np.int64]:
    if rows.shape[-2] == 0:
        return np.zeros(rows.shape[:-2], dtype=np.int64)
    singular = np.linalg.svd(_unit_rows(rows), compute_uv=False)
    return np.sum(singular > tolerance * np.maximum(singular[..., :1], 1e-300), axis=-1)


def _common_basis(wrenches: list[NDArray], dimension: int) -> NDArray[np.float64]:
    """Orthonormal basis (N, dimension, 6) of the wrenches every chain has (the intersection of their spans)."""
    count = wrenches[0].shape[0]
    total = np.zeros((count, 6, 6))
    for chain in wrenches:
        total += np.eye(6) - np.swapaxes(chain, -1, -2) @ chain
    _, vectors = np.linalg.eigh(total)
    return np.swapaxes(vectors[..., :dimension], -1, -2)


def _without(rows: NDArray, basis: NDArray) -> NDArray:
    """``rows`` (N, k, 6) with their components along the orthonormal ``basis`` (N, c, 6) removed."""
    if basis.shape[-2] == 0:
        return rows
    return rows - (rows @ np.swapaxes(basis, -1, -2)) @ basis


def _orthonormal(rows: NDArray, count: int) -> NDArray:
    """An orthonormal basis (N, count, 6) of the span of ``rows`` (N, k, 6) (its leading directions)."""
    if count == 0:
        return np.zeros(rows.shape[:-2] + (0, 6))
    _, _, right = np.linalg.svd(rows, full_matrices=False)
    return right[..., :count, :]


def _own_wrenches(constraints: list[NDArray], common: int, own_counts: tuple[int, ...]):
    """The common basis (N, common, 6) and each chain's own constraint wrenches (orthonormal, common part removed)."""
    count = constraints[0].shape[0]
    shared = _common_basis(constraints, common) if common else np.zeros((count, 0, 6))
    own = [_orthonormal(_without(chain, shared), c) for chain, c in zip(constraints, own_counts)]
    return shared, own


def _subsystems(own: list[NDArray], rank: int) -> tuple[tuple[int, ...], ...]:
    """Every minimal set of chains whose own wrenches have generic rank ``rank``, in combination order.

    A set is minimal when it has full rank and no proper subset does; as rank only grows with a set, that is a
    full-rank set containing no minimal set found before it (sets are taken by increasing size)."""
    holders = [i for i, rows in enumerate(own) if rows.shape[-2]]
    found: list[tuple[int, ...]] = []
    for size in range(1, len(holders) + 1):
        for subset in combinations(holders, size):
            if sum(own[i].shape[-2] for i in subset) < rank or any(set(f) <= set(subset) for f in found):
                continue
            stacked = np.concatenate([own[i] for i in subset], axis=-2)
            if int(np.max(_rank(stacked, tolerances.RANK_TOLERANCE))) == rank:
                found.append(subset)
    return tuple(found)


def plan_constraints(chain_twists: list[NDArray], mobility: int | None = None) -> ConstraintPlan:
    """The constraint structure of a mechanism from its chains' twists at sample configurations
    (working coordinates). Symmetric in the chains: permuting them permutes the plan.

    Only the samples where every chain has its largest rank are read: a chain singular at one sample (a Delta arm
    stretched at the boundary of the workspace) has a constraint wrench more there, and planned from it every
    configuration of the batch had its constraint subsystems wrong (CTI 0 throughout a sweep that touched the
    boundary). ``mobility``: the platform's DOF (idle rotations of a point output included) where it is known; when
    every sample leaves the platform more (each is a constraint singularity), the wrenches the chains share there are
    not taken for common ones, nor, beyond as many as leave the chains' own able to hold the platform to its mobility,
    wrenches that are only alike."""
    tolerance = tolerances.MOTION_SPACE_TOLERANCE
    ranks = [_rank(twists, tolerance) for twists in chain_twists]
    regular = np.all([rank == np.max(rank) for rank in ranks], axis=0)
    if regular.any():
        chain_twists = [twists[regular] for twists in chain_twists]
    counts = tuple(int(6 - np.max(rank)) for rank in ranks)
    wrenches = [chain_constraint_wrenches(twists, c) for twists, c in zip(chain_twists, counts)]
    if min(counts) > 0:
        total = sum(np.eye(6) - np.swapaxes(w, -1, -2) @ w for w in wrenches)
        eigenvalues = np.linalg.eigvalsh(total)
        common = int(np.min(np.sum(eigenvalues <= tolerances.MOTION_SPACE_EIGENVALUE, axis=-1)))
    else:
        common = 0
    if mobility is not None and common and 6 - np.max(_rank(np.concatenate(wrenches, axis=-2), tolerance)) > mobility:
        # every sample is a constraint singularity, where the chains share wrenches they share nowhere else (a
        # U-P-U platform drawn with its legs' couples all vertical, analysed there alone): no wrench is common
        common = 0
    if mobility is not None and common and len(counts) > 1:
        # the wrenches taken as common (alike to about 1e-4, MOTION_SPACE_EIGENVALUE) and the chains' own must hold
        # the platform to its mobility, common + sum(c - common) >= 6 - mobility: the most alike are kept common, the
        # others are only alike (a U-P-U platform written to 6 decimals, on the line where its legs' couples are
        # parallel to 1e-9; planned with one common couple, no lift was ever singular)
        common = max(0, min(common, (sum(counts) - 6 + mobility) // (len(counts) - 1)))
    own_counts = tuple(max(c - common, 0) for c in counts)
    if not any(own_counts):
        return ConstraintPlan(counts, common, own_counts)
    _, own = _own_wrenches(wrenches, common, own_counts)
    rank = int(np.max(_rank(np.concatenate(own, axis=-2), tolerances.RANK_TOLERANCE)))
    return ConstraintPlan(counts, common, own_counts, rank, _subsystems(own, rank))


def _subsystem_cti(actuation: NDArray, shared: NDArray, own: list[NDArray], members: tuple[int, ...],
                   points: list[NDArray], threshold: NDArray) -> NDArray:
    """:math:`CTI_{N,L}` (N, S) of every actuator set (their unit wrenches ``actuation``, (N, S, n, 6)) and one
    subsystem ``members``: the lowest power coefficient of a released constraint wrench on the twist it frees.
    ``shared`` (N, c0, 6), ``own`` per chain (N, c_i, 6), ``points`` per chain (N, 6: the platform joint's point and its
    :func:`~screwkit.screw.algebra.joint_lines` direction), ``threshold`` (N,)."""
    sets = actuation.shape[1]
    blocks = [np.broadcast_to(own[i][:, None], own[i].shape[:1] + (sets,) + own[i].shape[1:]) for i in members]
    common = np.broadcast_to(shared[:, None], shared.shape[:1] + (sets,) + shared.shape[1:])
    system = np.concatenate([actuation, *blocks, common], axis=-2)  # (N, S, rows, 6)
    values = np.full(system.shape[:2], np.inf)
    if system.shape[-2] == 6:  # the chains' own wrenches are independent: one inverse frees every chain at once
        volume = np.prod(np.linalg.norm(system, axis=-1), axis=-1)
        regular = np.abs(np.linalg.det(system)) > tolerances.RANK_TOLERANCE * volume
        # W Y = I: column r of Y is orthogonal to every row but r, so as a twist (halves swapped) it is reciprocal
        # to every wrench but row r; chain i's columns span the twists freed by releasing its rows.
        inverse = np.linalg.inv(np.where(regular[..., None, None], system, np.eye(6)))
        start = actuation.shape[-2]
        freed_of = []
        for block in blocks:
            columns = SWAP @ inverse[..., start:start + block.shape[-2]]
            freed_of.append(columns if block.shape[-2] == 1 else np.linalg.qr(columns)[0])  # same span, orthonormal
            start += block.shape[-2]
        valid_of = [None] * len(blocks)
    else:  # chains whose own wrenches overlap (each frees fewer twists than it holds wrenches): one null space each
        regular = _rank(system, tolerances.RANK_TOLERANCE) == 6
        freed_of, valid_of = [], []
        for position, block in enumerate(blocks):
            rest = np.concatenate([actuation, *(b for k, b in enumerate(blocks) if k != position), common], axis=-2)
            padding = np.zeros(rest.shape[:2] + (max(0, 6 - rest.shape[-2]), 6))
            _, singular, right = np.linalg.svd(np.concatenate([_unit_rows(rest), padding], axis=-2))
            size = block.shape[-2]
            valid_of.append(singular[..., -size:] <= tolerances.RANK_TOLERANCE * singular[..., :1])
            freed_of.append(SWAP @ np.swapaxes(right[..., -size:, :], -1, -2))
    for index, block, freed, valid in zip(members, blocks, freed_of, valid_of):
        wrenches, twists, singular, exists = released_pairs(block, freed, valid)
        joint, limit = points[index][:, None], threshold[:, None]
        kappa = pair_coefficients(wrenches, twists, joint, limit)
        kappa = worst_in_blocks(kappa, singular, exists, wrenches, twists, joint, limit)
        values = np.minimum(values, np.where(exists, kappa, np.inf).min(axis=-1))
    return np.where(regular & np.isfinite(values), values, 0.0)


def constraint_indices(plan: ConstraintPlan, chain_twists: list[NDArray], chain_points: list[NDArray],
                       wrenches: NDArray, submechanisms: NDArray, dof: int, fault_members: dict,
                       threshold: NDArray, decompositions: list | None = None, stage=None) -> dict[str, NDArray]:
    """CTI of every non-redundant actuator set, the mechanism's CTI, F_Cj, and the instantaneous DOF.

    Parameters
    ----------
    plan : ConstraintPlan
    chain_twists, chain_points : lists of (N, m_i, 6) and (N, m_i, 3)
        Every chain's joint twists and points in working coordinates.
    wrenches : ndarray (N, a, 6)
        Unit actuation wrenches in working coordinates.
    submechanisms : ndarray (S, n)
    dof : int
        The mechanism's mobility ``n``.
    fault_members : dict of int to ndarray (E, M)
        For each ``j``, the submechanisms (rows of ``submechanisms``) in each set left after j faults.
    threshold : ndarray (N,)
        The singularity threshold in working coordinates (*p* / *L*).
    decompositions : list, optional
        :func:`screwkit.screw.motion.chain_decompositions` of ``chain_twists`` when already computed.
    stage : callable, optional
        What computes, from every chain's constraint wrenches (N, K, 6), their platform joints (N, C, 6: point and
        :func:`~screwkit.screw.algebra.joint_lines` direction),
        ``wrenches`` and ``threshold``, the instantaneous DOF (N,) and :math:`CTI_N` of every actuator set (N, S)
        before constraint singularities are zeroed, in place of the numpy code below (the compiled kernel of
        :mod:`screwkit.indices.compiled.constraints`, for large chunks); only asked when the CTI applies.

    Returns
    -------
    dict
        ``cti`` (N,), ``cti_submechanisms`` (N, S), ``f_c{j}`` (N,), ``instantaneous_dof`` (N,)
        and ``constraint_singular`` (N,); where some configuration is a constraint singularity,
        ``held_without`` (number of singular configurations, a): whether the platform stays held
        with each actuator free and every other one locked.
    """
    count = wrenches.shape[0]
    if decompositions is None:
        decompositions = [None] * len(chain_twists)
    constraints = [chain_constraint_wrenches(t, c, d)
                   for t, c, d in zip(chain_twists, plan.chain_counts, decompositions)]
    stacked = np.concatenate(constraints, axis=-2) if constraints else np.zeros((count, 0, 6))
    # each chain's platform joint: its point and the axis along which that point is arbitrary (joint_lines)
    points = [np.concatenate([chain[:, -1], joint_lines(twists, chain, -1)], axis=-1)
              for twists, chain in zip(chain_twists, chain_points)]
    if stage is not None and plan.count:
        instantaneous, per_set = stage(stacked, np.stack(points, axis=1), wrenches, threshold)
    else:
        instantaneous, per_set = 6 - _rank(stacked, tolerances.MOTION_SPACE_TOLERANCE), None
    singular = instantaneous > dof
    result = {"instantaneous_dof": instantaneous, "constraint_singular": singular}
    if singular.any():  # which actuators leave the platform held when free (the kernel assumed n DOF)
        rows = np.flatnonzero(singular)
        held = np.zeros((rows.size, wrenches.shape[-2]), dtype=bool)
        for k in range(wrenches.shape[-2]):
            system = np.concatenate([np.delete(wrenches[rows], k, axis=-2), stacked[rows]], axis=-2)
            held[:, k] = _rank(system, tolerances.RANK_TOLERANCE) == 6
        result["held_without"] = held
    if plan.count == 0:
        nothing = np.full(count, np.nan)
        result.update(cti=nothing, cti_submechanisms=np.full((count, submechanisms.shape[0]), np.nan))
        for j in fault_members:
            result[f"f_c{j}"] = nothing.copy()
        return result
    # the numpy code: every configuration, or those where the compiled stage met a repeated block (NaN)
    rows = slice(None) if per_set is None else np.flatnonzero(np.isnan(per_set).any(axis=-1))
    if per_set is None or rows.size:
        shared, own = _own_wrenches([c[rows] for c in constraints], plan.common, plan.own_counts)
        actuation = wrenches[rows][:, submechanisms]  # (N, S, n, 6): every non-redundant actuator set at once
        found = np.zeros((actuation.shape[0], submechanisms.shape[0]))
        for subsystem in plan.subsystems:
            found = np.maximum(found, _subsystem_cti(actuation, shared, own, subsystem, [p[rows] for p in points],
                                                     threshold[rows]))
        if per_set is None:
            per_set = found
        else:
            per_set[rows] = found
    per_set[singular] = 0.0
    result["cti_submechanisms"] = per_set
    result["cti"] = per_set.max(axis=-1)
    for j, members in fault_members.items():
        result[f"f_c{j}"] = per_set[:, members].max(axis=-1).min(axis=-1)
    return result
