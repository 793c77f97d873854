r"""Constraint wrenches, constraint singularities and the constraint transmission index (CTI).

A chain whose joints do not span every twist transmits **constraint wrenches** to the platform:
the wrenches reciprocal to all its joint twists (a PRS leg: a force through the S centre along
the R axis; a Delta leg: a couple normal to its parallelogram). Liu, Wu and Wang's constraint
transmission index measures how well they hold the platform: lock the actuators, release one
constraint wrench, and take the power coefficient of that wrench on the one twist it leaves free.
screwkit computes it in its working coordinates (as :func:`screwkit.transmission.analyze`), so it
is independent of the length unit, the scale and the world frame; the conventions below are
screwkit's, stated in ``docs/theory.md`` (*Constraint wrenches and the CTI*):

* **Constraints common to every chain** (the out-of-plane wrenches of a planar mechanism, the two
  horizontal couples of every Schoenflies leg) are kept but never released: no single chain holds
  them. A mechanism with no other constraint wrench has no CTI ("not applicable": NaN).
* The other constraint wrenches are taken chain by chain, in chain order; a chain whose constraint
  wrenches depend on those of earlier chains (a duplicated constraint) is redundant and is not
  released either. ``K`` are the released ones, an orthonormal basis per chain.
* For a non-redundant set ``N`` of ``n`` actuators, the wrench system
  :math:`W = [A_N; C_K; C_0]` (actuation, released and common constraints) is square at a regular
  configuration; releasing :math:`C_j` leaves the twist :math:`T_j` reciprocal to every other row,
  the column ``j`` of :math:`\operatorname{adj} W` (of :math:`W^{-1}`, halves swapped). Then

  .. math:: \kappa_j = \frac{|C_j \circ T_j|}{|C_j \circ T_j|_{\max}}, \qquad
            CTI_N = \min_{j \in K} \kappa_j,

  with the characteristic point of :math:`C_j` the platform joint of its chain projected on its
  axis (a couple gives :math:`|\hat m \cdot \hat\omega|`), and zero when :math:`W` is singular.
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

from screwkit import tolerances
from screwkit.motion import chain_decompositions

__all__ = ["ConstraintPlan", "plan_constraints", "constraint_indices", "chain_constraint_wrenches"]

_SWAP = np.block([[np.zeros((3, 3)), np.eye(3)], [np.eye(3), np.zeros((3, 3))]])


@dataclass(frozen=True)
class ConstraintPlan:
    """How a mechanism's constraint wrenches are organised (found on sample configurations).

    Attributes
    ----------
    chain_counts : tuple of int
        Constraint wrenches of each chain (6 minus the rank of its joint twists).
    common : int
        Dimension of the constraint wrenches common to every chain.
    released : tuple of int
        Chains whose (non-common) constraint wrenches are released one at a time.
    released_counts : tuple of int
        Non-common constraint wrenches of each released chain.
    """

    chain_counts: tuple[int, ...]
    common: int
    released: tuple[int, ...]
    released_counts: tuple[int, ...]

    @property
    def count(self) -> int:
        """Constraint wrenches released: none means the CTI does not apply."""
        return sum(self.released_counts)


def _unit_rows(rows: NDArray) -> NDArray:
    norms = np.linalg.norm(rows, axis=-1, keepdims=True)
    return rows / np.where(norms > 0.0, norms, 1.0)


def chain_constraint_wrenches(twists: NDArray, count: int, decomposition: tuple | None = None) -> NDArray[np.float64]:
    """The ``count`` constraint wrenches (N, count, 6) of a chain's joint twists (N, m, 6): an orthonormal
    basis of the wrenches reciprocal to all of them (working coordinates). ``decomposition``: the chain's
    :func:`screwkit.motion.chain_decompositions` when already computed."""
    if count == 0:
        return np.zeros(twists.shape[:-2] + (0, 6))
    _, right = decomposition if decomposition is not None else chain_decompositions([twists])[0]
    return right[..., 6 - count:, :] @ _SWAP  # twists reciprocal to ... -> wrenches: swap the halves


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


def plan_constraints(chain_twists: list[NDArray]) -> ConstraintPlan:
    """The constraint structure of a mechanism from its chains' twists at sample configurations
    (working coordinates)."""
    tolerance = tolerances.MOTION_SPACE_TOLERANCE
    counts = tuple(int(6 - np.max(_rank(twists, tolerance))) for twists in chain_twists)
    wrenches = [chain_constraint_wrenches(twists, c) for twists, c in zip(chain_twists, counts)]
    if min(counts) > 0:
        total = sum(np.eye(6) - np.swapaxes(w, -1, -2) @ w for w in wrenches)
        eigenvalues = np.linalg.eigvalsh(total)
        common = int(np.min(np.sum(eigenvalues <= tolerances.MOTION_SPACE_EIGENVALUE, axis=-1)))
    else:
        common = 0
    shared = _common_basis(wrenches, common) if common else np.zeros(wrenches[0].shape[:-2] + (0, 6))
    released, released_counts = [], []
    chosen = shared
    for index, chain in enumerate(wrenches):
        own = counts[index] - common
        if own <= 0:
            continue
        candidate = _orthonormal(_without(chain, shared), own)
        stacked = np.concatenate([chosen, candidate], axis=-2)
        if int(np.max(_rank(stacked, tolerances.RANK_TOLERANCE))) == chosen.shape[-2] + own:  # generic rank
            released.append(index)
            released_counts.append(own)
            chosen = stacked
    return ConstraintPlan(counts, common, tuple(released), tuple(released_counts))


def _coefficient(wrench: NDArray, twist: NDArray, point: NDArray, threshold: NDArray) -> NDArray:
    """Power coefficient of unit constraint wrenches on twists (the kernel's definition, working coordinates)."""
    force, moment = wrench[..., :3], wrench[..., 3:]
    omega, velocity = twist[..., :3], twist[..., 3:]
    numerator = np.abs(np.sum(force * velocity, -1) + np.sum(moment * omega, -1))
    force_norm = np.linalg.norm(force, axis=-1)
    moment_norm = np.linalg.norm(moment, axis=-1)
    forceful = force_norm > tolerances.PURE_COUPLE * moment_norm
    safe = np.where(forceful, force_norm, 1.0)
    pitch = np.where(forceful, np.sum(force * moment, -1) / safe**2, 0.0)
    arm_vector = velocity + np.cross(omega, point) + pitch[..., None] * omega
    omega_norm = np.linalg.norm(omega, axis=-1)
    arm = np.where(forceful, np.linalg.norm(arm_vector, axis=-1), omega_norm)
    scale = np.where(forceful, force_norm, moment_norm)
    reference = np.where(forceful, omega_norm, 0.0)
    singular = (arm <= threshold * reference) | (arm * scale <= 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        value = numerator / np.where(singular, 1.0, arm * scale)
    return np.where(singular, 0.0, np.minimum(value, 1.0))


def _project_on_axis(wrench: NDArray, point: NDArray) -> NDArray:
    """The point of a wrench's axis nearest ``point`` (``point`` itself for a couple)."""
    force, moment = wrench[..., :3], wrench[..., 3:]
    norm_sq = np.sum(force * force, -1, keepdims=True)
    safe = np.where(norm_sq > 0, norm_sq, 1.0)
    foot = np.cross(force, moment) / safe
    along = np.sum((point - foot) * force, -1, keepdims=True) / safe
    return np.where(norm_sq > 0, foot + along * force, point)


def constraint_indices(plan: ConstraintPlan, chain_twists: list[NDArray], chain_points: list[NDArray],
                       wrenches: NDArray, submechanisms: NDArray, dof: int, fault_members: dict,
                       threshold: NDArray, decompositions: list | None = None) -> dict[str, NDArray]:
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
        :func:`screwkit.motion.chain_decompositions` of ``chain_twists`` when already computed.

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
    instantaneous = 6 - _rank(stacked, tolerances.MOTION_SPACE_TOLERANCE)
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
    shared = _common_basis(constraints, plan.common) if plan.common else np.zeros((count, 0, 6))
    released, owners = [], []
    for index, own in zip(plan.released, plan.released_counts):
        basis = _orthonormal(_without(constraints[index], shared), own)
        released.append(basis)
        owners += [index] * own
    released = np.concatenate(released, axis=-2)  # (N, c, 6)
    points = np.stack([chain_points[index][:, -1] for index in owners], axis=-2)  # (N, c, 3)
    centres = _project_on_axis(released, points)
    per_set = np.zeros((count, submechanisms.shape[0]))
    for s, members in enumerate(submechanisms):
        system = np.concatenate([wrenches[:, members], released, shared], axis=-2)  # (N, 6, 6) when regular
        if system.shape[-2] != 6:
            continue  # not a square system: the constraints or actuators cannot hold the platform here
        volume = np.prod(np.linalg.norm(system, axis=-1), axis=-1)
        independent = np.abs(np.linalg.det(system)) > tolerances.RANK_TOLERANCE * volume
        # Column r of W^-1 is orthogonal to every row of W but r: releasing row r frees that twist
        # (as (v, omega) in the Euclidean sense; swapped to (omega, v)); its scale cancels in kappa.
        inverse = np.linalg.inv(np.where(independent[:, None, None], system, np.eye(6)))
        values = np.ones(count)
        for k in range(released.shape[-2]):
            twist = inverse[..., len(members) + k] @ _SWAP
            kappa = _coefficient(released[:, k], twist, centres[:, k], threshold)
            values = np.minimum(values, kappa)
        per_set[:, s] = np.where(independent & ~singular, values, 0.0)
    result["cti_submechanisms"] = per_set
    result["cti"] = per_set.max(axis=-1)
    for j, members in fault_members.items():
        result[f"f_c{j}"] = per_set[:, members].max(axis=-1).min(axis=-1)
    return result


def actuator_sets(actuator_count: int, dof: int, faults: tuple[int, ...]) -> dict[int, NDArray[np.int64]]:
    """For each ``j``, the submechanisms (rows of the ``n``-combinations) in each set left after ``j`` faults."""
    position = {sub: s for s, sub in enumerate(combinations(range(actuator_count), dof))}
    return {j: np.array([[position[sub] for sub in combinations(remaining, dof)]
                         for remaining in combinations(range(actuator_count), actuator_count - j)], dtype=np.int64)
            for j in faults}
