r"""Transmission and fault-tolerance indices derived generically from chain screws.

Given, for every chain of a parallel mechanism, its joint twists in the world frame at a
batch of configurations (a :class:`~screwkit.chains.ChainScrews`), :func:`analyze`
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

Everything is batched: the configurations are processed in chunks with the batch on the
last (contiguous) axis, and small determinants/adjugates are closed-form element-wise
expressions (:mod:`screwkit.linalg`). Only numpy is imported here.
"""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from itertools import combinations
from math import comb
from typing import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit._validation import as_float_array, check_finite
from screwkit.chains import ChainScrews
from screwkit.linalg import adjugate, determinant, null_vector, solve_spd

__all__ = ["TransmissionResult", "MotionSpace", "analyze", "motion_space", "fault_sets"]

DEFAULT_THRESHOLD = 1e-6
"""The paper's singularity threshold *p* on the moment arm: 1 um (in metres)."""


# ----------------------------------------------------------------------------------------
# Motion space
# ----------------------------------------------------------------------------------------
@dataclass(frozen=True)
class MotionSpace:
    """The platform's motion space found on sample configurations.

    Attributes
    ----------
    dof : int
        Degrees of freedom ``n`` of the platform.
    constant_basis : ndarray, shape (n, 6) or None
        Orthonormal basis (rows, world coordinates) of the motion space when it was the
        same at every sample (planar mechanisms, 6-DoF legs); ``None`` otherwise.
    """

    dof: int
    constant_basis: NDArray[np.float64] | None

    @property
    def complement(self) -> NDArray[np.float64]:
        """Orthonormal rows spanning the Euclidean complement of :attr:`constant_basis`."""
        if self.constant_basis is None:
            raise ValueError("The motion space is not constant; it has no fixed complement.")
        _, _, right = np.linalg.svd(self.constant_basis)
        return np.ascontiguousarray(right[self.dof:])


def _chain_projector_complements(twists: NDArray[np.float64], tolerance: float) -> NDArray[np.float64]:
    """Sum over chains of ``I - P_chain`` for twists given as a list of (K, m, 6) arrays."""
    total = np.zeros((twists[0].shape[0], 6, 6))
    for chain_twists in twists:
        left, singular, _ = np.linalg.svd(np.swapaxes(chain_twists, -1, -2), full_matrices=False)
        rank_mask = singular > tolerance * np.maximum(singular[..., :1], 1.0)
        basis = left * rank_mask[..., None, :]
        total += np.eye(6) - basis @ np.swapaxes(basis, -1, -2)
    return total


def _null_spaces(chain_twists: list[NDArray[np.float64]], dof: int | None, tolerance: float):
    """Per-configuration motion spaces: eigen-decomposition of sum_i (I - P_i)."""
    values, vectors = np.linalg.eigh(_chain_projector_complements(chain_twists, tolerance))
    dims = np.sum(values <= 1e-8, axis=-1)
    count = int(dims.max()) if dof is None else dof
    return dims, np.swapaxes(vectors[..., :count], -1, -2)


def _centred(twists: list[NDArray], points: list[NDArray]):
    """Express batch-first twists (N, m, 6) and points (N, m, 3) about the centroid of the platform joints.

    Every Euclidean norm and tolerance downstream is then invariant to a rigid motion of
    the whole mechanism and to the choice of the world frame.
    """
    centre = np.mean([chain_points[:, -1] for chain_points in points], axis=0)  # (N, 3)
    moved = [np.concatenate([t[..., :3], t[..., 3:] + np.cross(t[..., :3], centre[:, None])], axis=-1) for t in twists]
    return moved, [p - centre[:, None] for p in points], centre


def motion_space(chains: Sequence[ChainScrews], dof: int | None = None, samples: int = 9,
                 tolerance: float = 1e-9) -> MotionSpace:
    r"""Find the platform's DOF and, if it is constant, its motion space.

    The motion space is the intersection of the chains' twist spaces,
    :math:`\mathcal{M} = \bigcap_i \mathrm{span}(J_i)`, i.e. the null space of
    :math:`\sum_i (I - P_i)` with :math:`P_i` the orthogonal projector on the span of chain
    ``i``'s joint twists. It is evaluated on ``samples`` configurations spread over the
    batch; the DOF is the largest dimension found (a singular sample can only lose
    mobility). Not a hot path: a few SVDs.

    Parameters
    ----------
    chains : sequence of ChainScrews
    dof : int, optional
        Impose the DOF instead of deriving it.
    samples : int
        Number of configurations to sample.
    tolerance : float
        Relative rank tolerance of the chains' twist systems.

    Returns
    -------
    MotionSpace
    """
    flat = [chain.twists.reshape((-1,) + chain.twists.shape[-2:]) for chain in chains]
    flat_points = [chain.points.reshape((-1,) + chain.points.shape[-2:]) for chain in chains]
    count = flat[0].shape[0]
    index = np.unique(np.linspace(0, count - 1, min(count, samples)).round().astype(int))
    centred, _, _ = _centred([twists[index] for twists in flat], [points[index] for points in flat_points])
    dims, bases = _null_spaces(centred, dof, tolerance)
    found = int(dims.max()) if dof is None else dof
    if found == 0:
        raise ValueError("The platform has no mobility: the chains' twist spaces intersect only in zero.")
    if dof is not None and (not isinstance(dof, (int, np.integer)) or not 1 <= dof <= 6):
        raise ValueError(f"Expected `dof` in 1..6, got {dof!r}.")
    generic = np.flatnonzero(dims == found)
    if generic.size == 0:
        return MotionSpace(found, None)
    candidate = np.ascontiguousarray(bases[generic[0]])
    for sample in generic[1:]:
        residual = bases[sample] - bases[sample] @ candidate.T @ candidate
        if np.abs(residual).max() > 1e-8:
            return MotionSpace(found, None)
    return MotionSpace(found, candidate)


# ----------------------------------------------------------------------------------------
# Results
# ----------------------------------------------------------------------------------------
def fault_sets(actuator_count: int, dof: int, faults: int) -> tuple[tuple[int, ...], ...]:
    """The remaining-actuator sets ``E_i`` (Eq. 13) for ``faults`` failed actuators, in combination order."""
    return tuple(combinations(range(actuator_count), actuator_count - faults))


@dataclass
class TransmissionResult:
    """Indices of a mechanism over a batch of configurations (leading shape ``batch_shape``).

    Attributes
    ----------
    actuators : tuple of (int, int)
        ``(chain index, joint index)`` of every actuator, in order; the set A.
    actuator_names : tuple of str
    dof : int
        Degrees of freedom ``n``.
    submechanisms : tuple of tuple of int
        The non-redundant ``n``-subsets ``N_i`` of actuators (Eq. 10).
    iti : ndarray (...)
        Overall ITI (Eq. 7).
    lmti : ndarray (...)
        LMTI of the whole actuator set (Eq. 11).
    f_o, f_io : dict of int -> ndarray (...)
        ``F_Oj`` (Eq. 12) and ``F_IOj`` (Eq. 14) for every computed ``j``.
    worst_faults : dict of int -> ndarray (..., j)
        For each ``j``, the failed actuators of the worst case (the minimising ``E_i``'s complement).
    mutual_interference : ndarray (..., a) of bool
        Whether each actuator is a mutual-interference actuator (with all the others
        locked, the platform is fully constrained). If one is not, every ``F_Oj`` is zero.
    iti_actuators : ndarray (..., a) or None
        ITI of every actuator (Eq. 6).
    oti_actuators : ndarray (..., S, n) or None
        ``OTI_k`` of each actuator of each submechanism (Eq. 8).
    oti_submechanisms : ndarray (..., S) or None
        OTI of every submechanism (Eq. 9).
    actuation_wrenches : ndarray (..., a, 6) or None
        Unit actuation wrenches (f, m), world frame.
    output_twists : ndarray (..., S, n, 6) or None
        Output twists (omega, v) of each actuator of each submechanism, scaled so that
        ``A_k o T_k = det(W_N)`` (the adjugate columns).
    """

    actuators: tuple[tuple[int, int], ...]
    actuator_names: tuple[str, ...]
    dof: int
    submechanisms: tuple[tuple[int, ...], ...]
    iti: NDArray[np.float64]
    lmti: NDArray[np.float64]
    f_o: dict[int, NDArray[np.float64]]
    f_io: dict[int, NDArray[np.float64]]
    worst_faults: dict[int, NDArray[np.int64]]
    mutual_interference: NDArray[np.bool_]
    iti_actuators: NDArray[np.float64] | None = None
    oti_actuators: NDArray[np.float64] | None = None
    oti_submechanisms: NDArray[np.float64] | None = None
    actuation_wrenches: NDArray[np.float64] | None = None
    output_twists: NDArray[np.float64] | None = None
    threshold: float = DEFAULT_THRESHOLD
    batch_shape: tuple[int, ...] = field(default=())

    @property
    def actuator_count(self) -> int:
        """Number of actuators ``a``."""
        return len(self.actuators)

    def lmti_of(self, actuator_set: Sequence[int]) -> NDArray[np.float64]:
        """LMTI of a set of actuators (Eq. 11): the best OTI of its ``n``-subsets.

        Parameters
        ----------
        actuator_set : sequence of int
            Indices into :attr:`actuators`, at least ``n`` of them.

        Returns
        -------
        ndarray (...)
        """
        if self.oti_submechanisms is None:
            raise ValueError("This result was computed with detail=False; recompute with detail=True.")
        chosen = sorted(set(int(i) for i in actuator_set))
        if any(not 0 <= i < self.actuator_count for i in chosen):
            raise ValueError(f"Expected actuator indices in 0..{self.actuator_count - 1}, got {list(actuator_set)}.")
        if len(chosen) < self.dof:
            raise ValueError(f"Expected at least n = {self.dof} actuators in `actuator_set`, got {len(chosen)}.")
        members = [s for s, sub in enumerate(self.submechanisms) if set(sub) <= set(chosen)]
        return self.oti_submechanisms[..., members].max(axis=-1)

    def not_mutual_interference(self) -> NDArray[np.bool_]:
        """Mask (..., a) of actuators that are *not* mutual-interference actuators."""
        return ~self.mutual_interference


# ----------------------------------------------------------------------------------------
# Analysis
# ----------------------------------------------------------------------------------------
def _swap(screws: NDArray) -> NDArray:
    """Swap the two halves of batch-last screws (..., 6, N): twist -> wrench coordinates."""
    return np.concatenate([screws[..., 3:, :], screws[..., :3, :]], axis=-2)


def _cross(first: NDArray, second: NDArray) -> NDArray:
    """Cross product of batch-last 3-vectors (..., 3, N), broadcasting."""
    return np.stack(
        [
            first[..., 1, :] * second[..., 2, :] - first[..., 2, :] * second[..., 1, :],
            first[..., 2, :] * second[..., 0, :] - first[..., 0, :] * second[..., 2, :],
            first[..., 0, :] * second[..., 1, :] - first[..., 1, :] * second[..., 0, :],
        ],
        axis=-2,
    )


def _shift(twists: NDArray, point: NDArray) -> NDArray:
    """Twists (..., 6, N) expressed about ``point`` (3, N): (omega, v + omega x p)."""
    omega = twists[..., :3, :]
    velocity = twists[..., 3:, :] + _cross(omega, point)
    return np.concatenate([np.broadcast_to(omega, velocity.shape), velocity], axis=-2)


def _dot(first: NDArray, second: NDArray) -> NDArray:
    return np.einsum("...in,...in->...n", first, second)


def _project_on_axis(wrench: NDArray, force_sq: NDArray, point: NDArray) -> NDArray:
    """Projection of ``point`` on the axis of ``wrench`` (6, N); the point itself for a couple."""
    force, moment = wrench[..., :3, :], wrench[..., 3:, :]
    safe = np.where(force_sq > 0, force_sq, 1.0)[..., None, :]
    foot = _cross(force, moment) / safe
    along = _dot(point - foot, force)[..., None, :] / safe
    return np.where(force_sq[..., None, :] > 0, foot + along * force, point)


@dataclass
class _Plan:
    """Everything about a mechanism that does not depend on the configuration."""

    chain_sizes: tuple[int, ...]
    actuated: tuple[tuple[int, ...], ...]
    actuators: tuple[tuple[int, int], ...]
    dof: int
    space: MotionSpace
    submechanisms: NDArray[np.int64]
    faults: tuple[int, ...]
    fault_members: dict[int, NDArray[np.int64]]
    fault_sets: dict[int, NDArray[np.int64]]
    complement_members: list[NDArray[np.int64]]
    threshold: float
    rank_tolerance: float
    group_keys: tuple[tuple[int, tuple[int, ...]], ...]
    group_members: tuple[tuple[int, ...], ...]
    group_slots: tuple[NDArray[np.int64], ...]
    complement: NDArray[np.float64] | None
    appearances: tuple[tuple[NDArray[np.int64], NDArray[np.int64]], ...]


def _make_plan(chains, dof, faults, threshold, rank_tolerance) -> _Plan:
    space = motion_space(chains, dof)
    n = space.dof
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
            if not 1 <= j <= a - n:
                raise ValueError(f"Expected the number of faults `j` in 1..a-n = 1..{a - n}, got {j}.")
    submechanisms = list(combinations(range(a), n))
    position = {sub: s for s, sub in enumerate(submechanisms)}
    fault_members, fault_set_arrays = {}, {}
    for j in fault_list:
        sets = fault_sets(a, n, j)
        fault_set_arrays[j] = np.array(sets, dtype=np.int64)
        fault_members[j] = np.array([[position[sub] for sub in combinations(remaining, n)] for remaining in sets])
    complement = [np.array([s for s, sub in enumerate(submechanisms) if k not in sub], dtype=np.int64)
                  for k in range(a)]
    if not threshold >= 0:
        raise ValueError(f"Expected `threshold` >= 0 (a length), got {threshold}.")
    if not rank_tolerance > 0:
        raise ValueError(f"Expected `rank_tolerance` > 0, got {rank_tolerance}.")
    # Chains of equal structure are processed together.
    keys, members = [], []
    for index, chain in enumerate(chains):
        key = (chain.n_joints, chain.actuated)
        if key not in keys:
            keys.append(key)
            members.append([])
        members[keys.index(key)].append(index)
    slot_of = {actuator: slot for slot, actuator in enumerate(actuators)}
    slots = tuple(np.array([slot_of[(c, k)] for c in group for k in key[1]], dtype=np.int64)
                  for key, group in zip(keys, members))
    return _Plan(tuple(c.n_joints for c in chains), tuple(c.actuated for c in chains), actuators, n, space,
                 np.array(submechanisms, dtype=np.int64), fault_list, fault_members, fault_set_arrays,
                 complement, float(threshold), float(rank_tolerance), tuple(keys),
                 tuple(tuple(g) for g in members), slots,
                 space.complement if space.constant_basis is not None else None,
                 tuple((np.array([s for s, sub in enumerate(submechanisms) if k in sub], dtype=np.int64),
                        np.array([sub.index(k) for sub in submechanisms if k in sub], dtype=np.int64))
                       for k in range(a)))


def _motion_basis(plan: _Plan, groups: list[tuple]) -> NDArray:
    """Motion-space basis (n, 6, N) for a chunk; constant where the joint twists allow it."""
    count = groups[0][1].shape[-1]
    n = plan.dof
    basis = plan.space.constant_basis
    if basis is not None:
        # Every joint twist must lie in the constant space: its part along the orthogonal
        # complement (6 - n rows) must vanish relative to its size.
        inside = np.ones(count, dtype=bool)
        if plan.complement.shape[0]:
            for _, twists, _ in groups:
                outside_part = np.einsum("rc,kmcn->kmrn", plan.complement, twists)
                leak = np.einsum("kmrn,kmrn->kmn", outside_part, outside_part)
                size = np.einsum("kmcn,kmcn->kmn", twists, twists)
                inside &= np.all(leak <= 1e-18 * np.maximum(size, 1.0), axis=(0, 1))
        result = np.broadcast_to(basis[:, :, None], (n, 6, count))
        if inside.all():
            return result
        result = result.copy()
        outside = ~inside
    else:
        result = np.empty((n, 6, count))
        outside = np.ones(count, dtype=bool)
    batch_twists = [np.moveaxis(chain[..., outside], -1, 0)
                    for _, twists, _ in groups for chain in twists]
    _, bases = _null_spaces(batch_twists, n, 1e-9)
    result[..., outside] = np.moveaxis(bases, 0, -1)
    return result


def _minimum_norm_wrenches(shifted: NDArray, actuated: tuple[int, ...]) -> NDArray:
    """Actuation wrenches (k, 6, N) of one chain with more joints than the platform's DOF.

    ``shifted`` holds the chain's twists about its platform joint point (m, 6, N). Where
    the joint twists are dependent (an idle DoF such as the spin of an S-S rod) the
    pseudo-inverse gives the minimum-norm solution; it is kept only if it is reciprocal to
    every passive joint (otherwise the actuator cannot transmit: the wrench is zero).
    """
    m, count = shifted.shape[0], shifted.shape[-1]
    gram = np.einsum("icn,jcn->ijn", shifted, shifted)
    unit = np.zeros((m, len(actuated), 1))
    unit[list(actuated), range(len(actuated)), 0] = 1.0
    solution, regular = solve_spd(gram, np.broadcast_to(unit, (m, len(actuated), count)))
    if not regular.all():
        singular = ~regular
        pseudo = np.linalg.pinv(np.moveaxis(gram[..., singular], -1, 0), hermitian=True)  # (K, m, m)
        fallback = np.moveaxis(pseudo[:, :, list(actuated)], 0, -1)  # (m, k, K)
        twists = shifted[..., singular]
        conditions = np.einsum("icn,jkn,jcn->ikn", twists, fallback, twists)  # J'^T J' y (= e_k if consistent)
        consistent = np.all(np.abs(conditions - unit) <= 1e-9 * np.maximum(1.0, np.abs(fallback).max(axis=(0, 1))),
                            axis=(0, 1))
        solution[..., singular] = np.where(consistent, fallback, 0.0)
    return _swap(np.einsum("jkn,jcn->kcn", solution, shifted))


def _actuation_wrenches(plan: _Plan, groups: list[tuple], basis: NDArray):
    """Unit actuation wrenches (a, 6, N), their input twists and characteristic points.

    ``groups`` holds ``(actuated, twists (c, m, 6, N), points (c, m, 3, N))`` for chains of
    equal structure, so that every operation runs on all chains of a group at once.
    """
    n = plan.dof
    count = basis.shape[-1]
    a = len(plan.actuators)
    wrenches = np.empty((a, 6, count))
    inputs = np.empty((a, 6, count))
    iti_points = np.empty((a, 3, count))
    oti_points = np.empty((a, 3, count))
    for (actuated, twists, points), slots in zip(groups, plan.group_slots):
        if not actuated:
            continue
        m = twists.shape[1]
        platform_point = points[:, -1]  # (c, 3, N)
        shifted = _shift(twists, platform_point[:, None])  # (c, m, 6, N)
        if m == n:
            # The chain spans the motion space: its constraint wrenches are the mechanism's,
            # and the representative is SWAP @ M' x with x spanning null(J_passive'^T M').
            shifted_basis = _shift(basis[None], platform_point[:, None])  # (c, n, 6, N)
            gram = np.einsum("kjcn,kqcn->kjqn", shifted, shifted_basis)  # (c, m, n, N)
            group_wrenches = []
            for k in actuated:
                coefficients = null_vector(np.delete(gram, k, axis=1))  # (c, n, N)
                group_wrenches.append(np.einsum("kqn,kqcn->kcn", coefficients, shifted_basis))
            group_wrenches = _swap(np.stack(group_wrenches, axis=1))  # (c, actuated, 6, N)
        else:
            # Minimum-norm solution of the reciprocity conditions J'^T SWAP w = e_k:
            # w = SWAP J' (J'^T J')^-1 e_k, orthogonal to the chain's constraint wrenches.
            group_wrenches = np.stack([_minimum_norm_wrenches(chain_shifted, actuated)
                                       for chain_shifted in shifted])
        # Back to moments about the world origin: m_0 = m_d + d x f.
        force = group_wrenches[:, :, :3]
        moment = group_wrenches[:, :, 3:] + _cross(platform_point[:, None], force)
        after = [min(k + 1, m - 1) for k in actuated]
        wrenches[slots, :3] = force.reshape((-1, 3, count))
        wrenches[slots, 3:] = moment.reshape((-1, 3, count))
        inputs[slots] = twists[:, list(actuated)].reshape((-1, 6, count))
        iti_points[slots] = points[:, after].reshape((-1, 3, count))
        oti_points[slots] = np.broadcast_to(platform_point[:, None], (len(twists), len(actuated), 3, count)
                                            ).reshape((-1, 3, count))
    force_sq = _dot(wrenches[:, :3], wrenches[:, :3])
    moment_sq = _dot(wrenches[:, 3:], wrenches[:, 3:])
    has_force = force_sq > 1e-20 * moment_sq
    scale = np.sqrt(np.where(has_force, force_sq, moment_sq))
    has_force &= scale > 0
    sign = np.sign(_dot(wrenches[:, :3], inputs[:, 3:]) + _dot(wrenches[:, 3:], inputs[:, :3]))
    wrenches *= (np.where(sign < 0, -1.0, 1.0) / np.where(scale > 0, scale, np.inf))[:, None]
    unit_force = has_force.astype(float)
    iti_points = _project_on_axis(wrenches, unit_force, iti_points)
    oti_points = _project_on_axis(wrenches, unit_force, oti_points)
    return wrenches, inputs, has_force, iti_points, oti_points


def _arm_operator(wrenches, has_force, points, basis):
    """Per actuator the 3 x n map y -> v_p + h omega (y -> omega for a couple) for twists M^T y."""
    omega = basis[:, :3]  # (n, 3, N)
    velocity = basis[:, 3:]
    force, moment = wrenches[:, :3], wrenches[:, 3:]
    pitch = _dot(force, moment)  # unit force -> pitch = f . m
    # (a, n, 3, N): v + omega x p + h omega for every basis twist.
    arm = (velocity[None] + _cross(omega[None], points[:, None]) + pitch[:, None, None] * omega[None])
    return np.where(has_force[:, None, None], arm, omega[None])


def _power_coefficients(numerator, arm, reference, threshold):
    """|A o T| / |A o T|_max with the zero cases: arm <= threshold * |omega| (incl. 0/0)."""
    singular = arm <= threshold * reference
    with np.errstate(divide="ignore", invalid="ignore"):
        value = np.abs(numerator) / np.where(singular, 1.0, arm)
    return np.where(singular, 0.0, np.minimum(value, 1.0))


def _analyze_chunk(plan: _Plan, groups, centre, iti_override, oti_override, detail, keep_twists):
    """All indices for one chunk; screws and points are given about ``centre`` (3, N), world axes."""
    basis = _motion_basis(plan, groups)
    wrenches, inputs, has_force, iti_points, oti_points = _actuation_wrenches(plan, groups, basis)
    if iti_override is not None:
        iti_points = iti_override
    if oti_override is not None:
        oti_points = oti_override
    # ITI per actuator (Eq. 6) and overall (Eq. 7).
    input_numerator = _dot(wrenches[:, :3], inputs[:, 3:]) + _dot(wrenches[:, 3:], inputs[:, :3])
    input_omega = inputs[:, :3]
    pitch = _dot(wrenches[:, :3], wrenches[:, 3:])
    input_arm_vector = inputs[:, 3:] + _cross(input_omega, iti_points) + pitch[:, None] * input_omega
    input_arm = np.where(has_force, np.sqrt(_dot(input_arm_vector, input_arm_vector)),
                         np.sqrt(_dot(input_omega, input_omega)))
    input_reference = np.where(has_force, np.sqrt(_dot(input_omega, input_omega)), 0.0)
    iti_actuators = _power_coefficients(input_numerator, input_arm, input_reference, plan.threshold)
    # Wrench matrix in motion coordinates: Q[k, q] = A_k o M_q.
    wrench_matrix = np.einsum("acn,qcn->aqn", wrenches[:, :3], basis[:, 3:]) + np.einsum(
        "acn,qcn->aqn", wrenches[:, 3:], basis[:, :3])
    row_norms = np.sqrt(np.einsum("aqn,aqn->an", wrench_matrix, wrench_matrix))
    arm = _arm_operator(wrenches, has_force, oti_points, basis)
    # Every non-redundant submechanism once (Eq. 10): W = Q[N], output twists = adj(W) columns.
    subs = plan.submechanisms
    matrices = wrench_matrix[subs]  # (S, n rows, n, N)
    det = determinant(matrices)
    adj = adjugate(matrices)  # adj[s, q, p]: coordinate q of the output twist of position p
    volume = np.prod(row_norms[subs], axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        independent = np.abs(det) > plan.rank_tolerance * volume
    arm_length = np.empty(adj.shape[:1] + adj.shape[2:])  # (S, n, N)
    for k, (sub_index, position) in enumerate(plan.appearances):
        vectors = np.einsum("qcn,tqn->tcn", arm[k], adj[sub_index, :, position])
        arm_length[sub_index, position] = np.sqrt(np.einsum("tcn,tcn->tn", vectors, vectors))
    # |omega| of every output twist; a pure-couple wrench has no moment arm to compare.
    omega_vectors = np.einsum("qcn,sqpn->spcn", basis[:, :3], adj)
    omega_length = np.sqrt(np.einsum("spcn,spcn->spn", omega_vectors, omega_vectors))
    omega_length = np.where(has_force[subs], omega_length, 0.0)
    oti_actuators = _power_coefficients(det[:, None], arm_length, omega_length, plan.threshold)
    oti_actuators = np.where(independent[:, None], oti_actuators, 0.0)
    oti_sub = oti_actuators.min(axis=1)  # Eq. 9
    # Mutual-interference actuators: the others alone fully constrain the platform.
    a = len(plan.actuators)
    mutual = np.stack([independent[members].any(axis=0) if members.size else np.zeros(det.shape[-1], bool)
                       for members in plan.complement_members])
    out = {
        "iti": iti_actuators.min(axis=0),
        "lmti": oti_sub.max(axis=0),
        "mutual_interference": mutual,
    }
    for j in plan.faults:
        lmti_sets = oti_sub[plan.fault_members[j]].max(axis=1)  # (E, N), Eq. 11 on each E_i
        worst = lmti_sets.argmin(axis=0)
        out[f"f_o{j}"] = lmti_sets.min(axis=0)
        remaining = plan.fault_sets[j][worst]  # (N, a-j)
        failed = np.ones((remaining.shape[0], a), dtype=bool)
        np.put_along_axis(failed, remaining, False, axis=1)
        out[f"worst{j}"] = np.nonzero(failed)[1].reshape(-1, j).T
    if detail:
        # Back to the world origin: m_0 = m_c + c x f and v_0 = v_c - omega x c.
        world_wrenches = wrenches.copy()
        world_wrenches[:, 3:] += _cross(centre, wrenches[:, :3])
        out.update(iti_actuators=iti_actuators, oti_actuators=oti_actuators, oti_submechanisms=oti_sub,
                   actuation_wrenches=world_wrenches)
        if keep_twists:
            twists = np.einsum("sqpn,qcn->spcn", adj, basis)
            twists[:, :, 3:] -= _cross(twists[:, :, :3], centre)
            out["output_twists"] = twists
    return out


def _batch_last(array: NDArray, count: int) -> NDArray:
    """(..., m, k) batch-first -> (m, k, N)."""
    return np.moveaxis(array.reshape((count,) + array.shape[-2:]), 0, -1)


def analyze(
    chains: Sequence[ChainScrews],
    *,
    dof: int | None = None,
    faults: int | Sequence[int] | None = None,
    threshold: float = DEFAULT_THRESHOLD,
    rank_tolerance: float = 1e-9,
    iti_points: ArrayLike | None = None,
    oti_points: ArrayLike | None = None,
    detail: bool = True,
    keep_twists: bool = False,
    chunk_size: int = 4096,
    threads: int | None = None,
) -> TransmissionResult:
    r"""Every index of the paper for a batch of configurations, derived from chain screws.

    **Actuation wrench** (Sec. 2): the wrench of chain ``i`` reciprocal to every other
    joint of the chain; it is defined modulo the chain's constraint wrenches. screwkit's
    representative is the one *orthogonal to the constraint wrenches with moments taken
    about the chain's platform-joint point* ``d`` — the minimum-norm solution of the
    reciprocity conditions

    .. math:: w = \Delta J'_i (J_i'^T J'_i)^{-1} e_k

    (:math:`J'_i` the chain's twists about ``d``, :math:`\Delta` the swap of the halves).
    For a planar RRR/RPR chain it is the paper's force along the distal link through
    :math:`d_i` (Eq. 21); it is invariant to a rigid motion of the whole mechanism and to
    the world frame. For a chain with exactly ``n`` joints (which then spans the motion
    space ``M``) the same wrench is computed as :math:`\Delta M' x`,
    :math:`x \in \mathrm{null}(J'^T_{\text{passive}} M')`, which stays defined where the
    chain itself is singular (ITI = 0). Wrenches are scaled to a unit force (a unit
    moment for a pure couple) and signed so that they do positive work on their own joint.

    **Characteristic points**: for the ITI the point of the first joint after the actuator,
    for the OTI the chain's platform-joint point, each projected on the wrench axis
    (overridable with ``iti_points`` / ``oti_points``, used as given).

    **Output twists** (Eq. 8): for a submechanism ``N`` with wrench matrix
    :math:`W_N = [A_k \circ M_q]` in motion coordinates, the output twists are the
    columns of :math:`\mathrm{adj}(W_N)` mapped by ``M``; then
    :math:`A_k \circ T_k = \det W_N` for every ``k`` (general form of Eq. A3), and

    .. math:: OTI_k = \frac{|\det W_N|}{\| v_k + \omega_k \times p_k + h_k \omega_k \|}

    with the zero cases of the paper: ``OTI_k = 0`` when the moment arm is at or below
    ``threshold`` (the paper's *p*), and every ``OTI_k`` of ``N`` is zero when its wrenches
    are dependent (:math:`|\det W_N|` at or below ``rank_tolerance`` times the product of
    its row norms).

    Then ``OTI_N = min_k OTI_k`` (Eq. 9), ``LMTI_E = max_{N subset E} OTI_N`` (Eq. 11),
    ``F_Oj = min_{|E| = a - j} LMTI_E`` (Eqs. 12-13; for ``j = a - n`` this is the minimum
    OTI), ``F_IOj = min(F_Oj, ITI)`` (Eq. 14).

    Parameters
    ----------
    chains : sequence of ChainScrews
        All chains, with the same batch shape.
    dof : int, optional
        Impose the platform's DOF ``n`` (derived from the screws by default).
    faults : int or sequence of int, optional
        Which ``j`` to compute ``F_Oj``/``F_IOj`` for; default ``1..a-n``.
    threshold : float
        Singularity threshold on the moment arm, in the length unit of the screws (1e-6).
    rank_tolerance : float
        Relative tolerance for dependent actuation wrenches.
    iti_points, oti_points : array_like, shape (..., a, 3), optional
        Characteristic points overriding the defaults.
    detail : bool
        Keep per-actuator and per-submechanism arrays (needed by :meth:`TransmissionResult.lmti_of`).
    keep_twists : bool
        Also keep the output twists (memory: ``S * n * 6`` floats per configuration).
    chunk_size : int
        Configurations per chunk (bounds memory).
    threads : int, optional
        Threads working on chunks concurrently (default: the number of CPUs, at most 4).

    Returns
    -------
    TransmissionResult
    """
    chains = list(chains)
    if not chains:
        raise ValueError("Expected at least one chain in `chains`, got none.")
    for chain in chains:
        if not isinstance(chain, ChainScrews):
            raise ValueError(f"Expected `chains` to hold ChainScrews, got {type(chain).__name__}.")
    batch_shape = chains[0].batch_shape
    for chain in chains[1:]:
        if chain.batch_shape != batch_shape:
            raise ValueError(
                f"Expected every chain to share the batch shape {batch_shape}, chain {chain.name!r} has {chain.batch_shape}."
            )
    if not isinstance(chunk_size, (int, np.integer)) or chunk_size < 1:
        raise ValueError(f"Expected `chunk_size` >= 1, got {chunk_size!r}.")
    if threads is None:
        threads = min(os.cpu_count() or 1, 4)
    if not isinstance(threads, (int, np.integer)) or threads < 1:
        raise ValueError(f"Expected `threads` >= 1, got {threads!r}.")
    plan = _make_plan(chains, dof, faults, threshold, rank_tolerance)
    a = len(plan.actuators)
    count = int(np.prod(batch_shape, dtype=np.int64))
    overrides = {}
    for name, value in (("iti_points", iti_points), ("oti_points", oti_points)):
        if value is not None:
            array = check_finite(as_float_array(value, name), name)
            try:
                array = np.broadcast_to(array, batch_shape + (a, 3))
            except ValueError:
                raise ValueError(f"Expected `{name}` with shape (..., {a}, 3), got {array.shape}.") from None
            overrides[name] = _batch_last(array, count)
    twists = [chain.twists.reshape((count,) + chain.twists.shape[-2:]) for chain in chains]
    points = [chain.points.reshape((count,) + chain.points.shape[-2:]) for chain in chains]

    def run(start: int) -> dict:
        part = slice(start, min(start + chunk_size, count))
        chunk_twists, chunk_points, centre = _centred([t[part] for t in twists], [p[part] for p in points])
        # (c, m, 6, N) contiguous stacks of the chains of each group, batch last.
        groups = [(key[1],
                   np.ascontiguousarray(np.stack([chunk_twists[c] for c in members]).transpose(0, 2, 3, 1)),
                   np.ascontiguousarray(np.stack([chunk_points[c] for c in members]).transpose(0, 2, 3, 1)))
                  for key, members in zip(plan.group_keys, plan.group_members)]
        centre = np.ascontiguousarray(centre.T)
        return _analyze_chunk(
            plan, groups, centre,
            overrides["iti_points"][..., part] - centre if "iti_points" in overrides else None,
            overrides["oti_points"][..., part] - centre if "oti_points" in overrides else None,
            detail, keep_twists)

    starts = range(0, count, chunk_size)
    if threads > 1 and len(starts) > 1:
        # numpy releases the GIL inside its kernels: chunks overlap on several cores.
        with ThreadPoolExecutor(max_workers=threads) as pool:
            pieces = list(pool.map(run, starts))
    else:
        pieces = [run(start) for start in starts]
    merged = {key: np.concatenate([piece[key] for piece in pieces], axis=-1) for key in pieces[0]}

    def batch_first(array: NDArray) -> NDArray:
        return np.moveaxis(array, -1, 0).reshape(batch_shape + array.shape[:-1])

    names = tuple(f"{chains[c].name or f'chain{c + 1}'}:{k}" for c, k in plan.actuators)
    return TransmissionResult(
        actuators=plan.actuators,
        actuator_names=names,
        dof=plan.dof,
        submechanisms=tuple(tuple(int(i) for i in sub) for sub in plan.submechanisms),
        iti=batch_first(merged["iti"]),
        lmti=batch_first(merged["lmti"]),
        f_o={j: batch_first(merged[f"f_o{j}"]) for j in plan.faults},
        f_io={j: np.minimum(batch_first(merged[f"f_o{j}"]), batch_first(merged["iti"])) for j in plan.faults},
        worst_faults={j: batch_first(merged[f"worst{j}"]) for j in plan.faults},
        mutual_interference=batch_first(merged["mutual_interference"]),
        iti_actuators=batch_first(merged["iti_actuators"]) if detail else None,
        oti_actuators=batch_first(merged["oti_actuators"]) if detail else None,
        oti_submechanisms=batch_first(merged["oti_submechanisms"]) if detail else None,
        actuation_wrenches=batch_first(merged["actuation_wrenches"]) if detail else None,
        output_twists=batch_first(merged["output_twists"]) if detail and keep_twists else None,
        threshold=plan.threshold,
        batch_shape=batch_shape,
    )
