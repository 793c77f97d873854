r"""The whole index pipeline in plain numpy, one configuration at a time: the readable reference.

Each step is one function, named after what the paper defines, built on :mod:`screwkit.screw.algebra`; no
numba, no batching tricks. :func:`screwkit.indices.analysis.analyze` (compiled, batched) is tested against
:func:`reference_indices` on every bundled mechanism and on random ones (``tests/test_reference.py``),
so this file is also the shortest complete statement of what screwkit computes:

1. **working coordinates** (:func:`working_frame`): screws about the centroid ``c`` of the platform joints,
   lengths in units of ``L``, the RMS distance of every joint from ``c`` -- so no tolerance depends on the
   unit, the scale or the frame;
2. the **motion space** (:func:`motion_space`): the twists every chain can follow;
3. each actuator's **actuation wrench** (:func:`actuation_wrench`, Sec. 2);
4. its **ITI** (:func:`input_transmission`, Eq. 6) and, for every set ``N`` of ``n`` actuators, the
   **output twists** (:func:`output_twists`) and **OTIs** (:func:`output_transmission`, Eqs. 8-9);
5. the **LMTI**, **F_Oj**, **F_IOj** and mutual-interference actuators (:func:`fault_tolerance`, Eqs. 11-14);
6. the **CTI** and **F_Cj** of constraint wrenches (:func:`constraint_transmission`, ``docs/theory.md``).

Point outputs add the idle rotations about the point to every chain and take output twists modulo them.
Only numpy is imported here.
"""

from __future__ import annotations

from itertools import combinations

import numpy as np
from numpy.typing import NDArray

from screwkit.common.tolerances import (
    MOTION_SPACE_TOLERANCE,
    PSEUDO_INVERSE_CONSISTENCY,
    PURE_COUPLE,
    RANK_TOLERANCE,
    ROUNDED_COUPLE,
    SINGULAR_SPAN,
)
from screwkit.screw.algebra import (
    SWAP,
    joint_lines,
    nearest_on_axis,
    power_coefficient,
    reciprocal_product,
    shift_twist,
)

__all__ = ["working_frame", "motion_space", "actuation_wrench", "joint_after", "input_transmission", "output_twists",
           "output_transmission", "fault_tolerance", "constraint_transmission", "reference_indices"]


def working_frame(twists: list[NDArray], points: list[NDArray]):
    """Every chain's twists (m, 6) and points (m, 3) about the centroid of the platform joints (each chain's last
    joint), lengths in units of ``L``; returns them with the centroid and ``L``."""
    centre = np.mean([p[-1] for p in points], axis=0)
    every = np.concatenate(points) - centre
    length = float(np.sqrt(np.mean(np.sum(every**2, axis=1)))) or 1.0
    moved = [np.concatenate([t[:, :3], (t[:, 3:] + np.cross(t[:, :3], centre)) / length], axis=1) for t in twists]
    return moved, [(p - centre) / length for p in points], centre, length


def _span(rows: NDArray, tolerance: float = MOTION_SPACE_TOLERANCE) -> NDArray:
    """Orthonormal basis (r, 6) of the span of rows, each scaled to unit norm first (relative rank)."""
    unit = rows / np.maximum(np.linalg.norm(rows, axis=1, keepdims=True), 1e-300)
    _, singular, right = np.linalg.svd(unit)
    return right[:int(np.sum(singular > tolerance * singular[0]))]


def motion_space(twists: list[NDArray], dof: int) -> NDArray:
    r"""Orthonormal basis (dof, 6) of :math:`\bigcap_i \mathrm{span}(J_i)`: the eigenvectors of
    :math:`\sum_i (I - P_i)` of smallest eigenvalue (zero on the intersection), found as the right singular vectors
    of least singular value of the stacked :math:`I - P_i` (the same vectors: the sum is the stack's Gram matrix),
    which resolves them to rounding even next to a constraint singularity."""
    stacked = np.concatenate([np.eye(6) - basis.T @ basis for basis in map(_span, twists)])
    return np.linalg.svd(stacked)[2][6 - dof:]


def actuation_wrench(chain: NDArray, points: NDArray, k: int, basis: NDArray | None = None) -> NDArray:
    r"""The actuation wrench of joint ``k`` of a chain (working coordinates), moments about the origin.

    Reciprocal to every other joint of the chain and doing unit work on joint ``k``, the one of least norm in
    :math:`|f|^2 + |m_d|^2` with moments about the platform joint ``d``: :math:`x = J_d^+ e_k` (the chain's
    twists about ``d`` as rows), :math:`w = \Delta x`. Scaled to a unit force (a unit moment for a couple).

    When joint ``k``'s twist depends on the others (an input singularity: a leg stretched or folded), no wrench of
    the chain's twist span does work on it alone; the actuation wrench is then the limit of the one above: of
    least norm about ``d`` in the span of the chain's twists and the motion space ``basis`` (rows), reciprocal to
    every other joint (a force along the stretched leg; it does no work on joint ``k``: ITI 0). Zero without a
    ``basis`` or where that wrench is not unique.
    """
    about_d = shift_twist(chain, points[-1])
    unit = about_d / np.linalg.norm(about_d, axis=1, keepdims=True)
    x = np.linalg.pinv(unit)[:, k]
    if np.max(np.abs(unit @ x - np.eye(len(chain))[k])) > PSEUDO_INVERSE_CONSISTENCY * max(1.0, np.max(np.abs(x))):
        if basis is None:
            return np.zeros(6)
        x = _singular_wrench(unit, k, basis, points[-1])
        if x is None:
            return np.zeros(6)
    force, moment_d = x[3:], x[:3]  # the wrench (f, m_d) is the twist-space vector with its halves swapped
    moment = moment_d + np.cross(points[-1], force)  # about the origin (the centroid)
    if np.linalg.norm(force) <= PURE_COUPLE * np.linalg.norm(moment):
        return np.concatenate([np.zeros(3), moment / np.linalg.norm(moment)])
    return np.concatenate([force, moment]) / np.linalg.norm(force)


def _singular_wrench(unit: NDArray, k: int, basis: NDArray, d: NDArray) -> NDArray | None:
    """:func:`actuation_wrench` at an input singularity, as a twist-space vector about ``d`` (halves swapped)."""
    span = _span(np.concatenate([unit, shift_twist(basis, d)]), SINGULAR_SPAN)
    passive = np.delete(unit, k, axis=0) @ span.T
    _, values, vectors = np.linalg.svd(passive, full_matrices=True)
    rank = np.sum(values > SINGULAR_SPAN * max(values[0], 1e-300)) if values.size else 0
    return vectors[rank] @ span if len(span) - rank == 1 else None


def joint_after(twists: NDArray, joint: int) -> int:
    """The joint whose point is the ITI's for the actuator ``joint`` of a chain (its unit twists (m, 6)): the first
    joint after it that turns. A slide has no point (its twist is a direction), so a force acts on the actuated link
    where it crosses the next joint that has an axis (a Schoenflies leg's slider carriage turns on the revolute
    after it); the last joint when every joint after the actuator slides, the actuator when it is the last."""
    for after in range(joint + 1, len(twists)):
        if np.any(twists[after, :3] != 0.0):
            return after
    return len(twists) - 1


def input_transmission(wrench: NDArray, twist: NDArray, after: NDArray, point: NDArray, threshold: float) -> float:
    """ITI of one actuator (Eq. 6): the power coefficient on its joint's ``twist``, the wrench rotated about the
    joint after the actuator (:func:`joint_after`), drawn at ``point`` with the axis direction ``after``
    (:func:`joint_lines`): on a force, the point of its axis nearest to that joint's axis (where it crosses it),
    wherever along its axis the joint is drawn (:func:`nearest_on_axis`)."""
    return float(power_coefficient(wrench, twist, nearest_on_axis(wrench, point, after), threshold))


def output_twists(wrenches: NDArray, basis: NDArray) -> NDArray | None:
    """The output twist of each of ``n`` actuators (Eq. 8): the motion (in the space ``basis`` (n, 6)) with the
    other ``n - 1`` locked, reciprocal to their wrenches; None when the wrenches are dependent: |det| at most
    :data:`RANK_TOLERANCE` times the product of the wrenches' norms, which bounds it (not of the rows' norms: a
    wrench that does no work on the motion space has a row of rounding noise, independent of itself)."""
    matrix = reciprocal_product(wrenches[:, None, :], basis[None, :, :])  # (n, n): A_k o M_q
    if abs(np.linalg.det(matrix)) <= RANK_TOLERANCE * np.prod(np.linalg.norm(wrenches, axis=1)):
        return None
    return np.array([np.linalg.svd(np.delete(matrix, k, axis=0))[2][-1] @ basis for k in range(len(wrenches))])


def output_transmission(wrench: NDArray, twist: NDArray, platform: NDArray, point: NDArray, threshold: float) -> float:
    """OTI of one actuator of a submechanism (Eq. 8), the wrench rotated about its platform joint (axis direction
    ``platform``, :func:`joint_lines`, drawn at ``point``), the point taken as for the ITI."""
    return float(power_coefficient(wrench, twist, nearest_on_axis(wrench, point, platform), threshold))


def fault_tolerance(oti_sets: dict, actuators: int, dof: int) -> dict:
    """LMTI (Eq. 11) and, for every number of faults ``j``, F_Oj (Eqs. 12-13) from the OTI of each set of ``n``
    actuators (Eq. 9); a set of fewer than ``n`` actuators holds nothing (0)."""
    def lmti(kept):
        kept = set(kept)
        return max((value for members, value in oti_sets.items() if kept.issuperset(members)), default=0.0)

    faults = range(1, max(actuators - dof, 1) + 1)
    return {"lmti": lmti(range(actuators)),
            "f_o": {j: min(lmti(kept) for kept in combinations(range(actuators), actuators - j)) for j in faults}}


def _complement(rows: NDArray) -> NDArray:
    """Orthonormal basis of the vectors orthogonal to every row (rows scaled to unit norm for the rank)."""
    padded = np.concatenate([rows, np.zeros((max(0, 6 - len(rows)), 6))])
    return np.linalg.svd(padded)[2][len(_span(rows, RANK_TOLERANCE)) if len(rows) else 0:]


def constraint_transmission(twists: list[NDArray], points: list[NDArray], wrenches: NDArray, sets: list,
                            dof: int, threshold: float) -> tuple[dict, int]:
    """CTI of each actuator set (``docs/theory.md``) and the instantaneous DOF. A chain's constraint wrenches are
    reciprocal to all its twists; those common to every chain are never released; the CTI of a set is the best,
    over the minimal sets of chains whose own constraint wrenches hold every constraint, of the lowest power
    coefficient of a released wrench on a twist it frees (each chain's wrenches and freed twists paired along the
    principal directions of their pairing). Empty when no chain holds a constraint wrench alone. At a constraint
    singularity (more than ``dof`` instantaneous DOF) the wrenches the chains share are shared there only (every
    U-P-U leg's couple vertical), not common: each chain's own, as
    :func:`screwkit.screw.constraints.plan_constraints` reads them; and only as many are common as leave the chains'
    own able to hold the platform to ``dof``, the most alike (wrenches alike only to about 1e-4 are not)."""
    constraints = [_complement(_span(t)) @ SWAP for t in twists]
    every = np.concatenate(constraints)
    instantaneous = 6 - (len(_span(every)) if len(every) else 0)
    if all(len(c) for c in constraints):
        values, vectors = np.linalg.eigh(sum(np.eye(6) - c.T @ c for c in constraints))
        shared = vectors[:, values <= 1e-8].T  # the intersection: wrenches every chain holds
    else:
        shared = np.zeros((0, 6))
    if instantaneous > dof:  # shared here only (a constraint singularity): none is common to the chains
        shared = np.zeros((0, 6))
    if len(constraints) > 1:  # as many as leave the chains' own able to hold dof: the others only alike
        shared = shared[:max(0, (sum(len(c) for c in constraints) - 6 + dof) // (len(constraints) - 1))]
    own = [np.linalg.svd(c - c @ shared.T @ shared)[2][:len(c) - len(shared)] if len(c) > len(shared)
           else np.zeros((0, 6)) for c in constraints]
    holders = [i for i, o in enumerate(own) if len(o)]
    rank = len(_span(np.concatenate([own[i] for i in holders]), RANK_TOLERANCE)) if holders else 0
    minimal: list = []
    for size in range(1, len(holders) + 1):
        for chosen in combinations(holders, size):
            if not any(set(m) <= set(chosen) for m in minimal) and \
                    len(_span(np.concatenate([own[i] for i in chosen]), RANK_TOLERANCE)) == rank:
                minimal.append(chosen)
    if not rank:
        return {}, instantaneous
    result = {}
    for members in sets:
        best = 0.0
        for chosen in minimal:
            system = np.concatenate([wrenches[list(members)], *(own[i] for i in chosen), shared])
            if instantaneous > dof or len(_span(system, RANK_TOLERANCE)) < 6:
                continue  # the platform is not held: zero
            kappas = []
            for i in chosen:
                rest = np.concatenate([wrenches[list(members)], *(own[c] for c in chosen if c != i), shared])
                freed = _complement(rest) @ SWAP  # the twists reciprocal to every other wrench
                left, singular, right = np.linalg.svd(reciprocal_product(own[i][:, None], freed[None]),
                                                      full_matrices=False)
                for wrench, twist in zip(left.T @ own[i], right @ freed):
                    if np.linalg.norm(wrench[:3]) <= ROUNDED_COUPLE * np.linalg.norm(wrench[3:]):
                        wrench = np.concatenate([np.zeros(3), wrench[3:]])  # the couple a file's rounding made a force
                    centre = nearest_on_axis(wrench, points[i][-1], joint_lines(twists[i], points[i], -1))
                    kappas.append(float(power_coefficient(wrench, twist, centre, threshold)))
            best = max(best, min(kappas))
        result[tuple(members)] = best
    return result, instantaneous


def _with_idle_rotations(work: list[NDArray], at: list[NDArray], idle: NDArray, point: NDArray):
    """Each chain with the idle rotations about the output point it cannot already perform, as passive joints."""
    for c, chain in enumerate(work):
        basis = _span(chain)
        missing = [r for r in idle if np.linalg.norm(r - r @ basis.T @ basis) > 1e-6 * np.linalg.norm(r)]
        work[c] = np.concatenate([chain, *(r[None] for r in missing)])
        at[c] = np.concatenate([at[c], np.repeat(point[None], len(missing), axis=0)])


def reference_indices(twists: list[NDArray], points: list[NDArray], actuated: list[tuple[int, ...]], dof: int,
                      threshold: float = 1e-6, output_point: NDArray | None = None, planar_normal=None) -> dict:
    """Every index of one configuration: the chains' world twists (m_i, 6), points (m_i, 3) and actuated joints,
    the mobility ``dof`` and the threshold *p* (world units); for a point output, the point (and for a planar
    mechanism its plane's normal, the only idle rotation)."""
    work, at, centre, length = working_frame(twists, points)
    idle = np.zeros((0, 6))
    if output_point is not None:  # the rotations about the point are idle: every chain performs them
        axes = np.eye(3) if planar_normal is None else np.asarray(planar_normal, float)[None]
        axes = axes / np.linalg.norm(axes, axis=1, keepdims=True)
        point = (np.asarray(output_point, float) - centre) / length
        idle = np.concatenate([axes, np.cross(point, axes)], axis=1)
        _with_idle_rotations(work, at, idle, point)
        world = [np.concatenate([t[:, :3], t[:, 3:] * length - np.cross(t[:, :3], centre)], axis=1) for t in work]
        work, at, centre, length = working_frame(world, [p * length + centre for p in at])
        idle = np.concatenate([axes, np.cross((np.asarray(output_point, float) - centre) / length, axes)], axis=1)
    space = motion_space(work, dof + len(idle))
    if len(idle):  # output twists modulo the idle rotations
        kept = _span(idle)
        space = np.linalg.svd(space - space @ kept.T @ kept)[2][:dof]
    actuators = [(c, k) for c, ks in enumerate(actuated) for k in ks]
    wrenches = np.array([actuation_wrench(work[c], at[c], k, space) for c, k in actuators])
    p = threshold / length
    after = [joint_after(work[c], k) for c, k in actuators]
    iti = [input_transmission(wrenches[a], work[c][k], joint_lines(work[c], at[c], after[a]), at[c][after[a]], p)
           for a, (c, k) in enumerate(actuators)]
    sets = list(combinations(range(len(actuators)), dof))
    cti, instantaneous = constraint_transmission(work, at, wrenches, sets, dof + len(idle), p)
    instantaneous -= len(idle)
    singular = instantaneous > dof  # a constraint singularity: no n actuators hold the platform
    oti = {}
    for members in sets:
        outputs = None if singular else output_twists(wrenches[list(members)], space)
        oti[members] = [0.0] * dof if outputs is None else \
            [output_transmission(wrenches[a], t, joint_lines(work[c], at[c], -1), at[c][-1], p)
             for a, t in zip(members, outputs) for c in [actuators[a][0]]]
    faults = fault_tolerance({m: min(v) for m, v in oti.items()}, len(actuators), dof)
    if singular:  # held with actuator a free: the other actuators and every constraint wrench span all six
        every = np.concatenate([_complement(_span(t)) @ SWAP for t in work])
        held = [len(_span(np.concatenate([np.delete(wrenches, a, axis=0), every]), RANK_TOLERANCE)) == 6
                for a in range(len(actuators))]
    else:
        held = [any(output_twists(wrenches[list(m)], space) is not None for m in sets if a not in m)
                for a in range(len(actuators))]
    result = {"iti_actuators": np.array(iti), "iti": min(iti), "oti_actuators": oti, **faults,
              "f_io": {j: min(v, min(iti)) for j, v in faults["f_o"].items()}, "mutual_interference": held,
              "instantaneous_dof": instantaneous}
    if cti and not len(idle):  # the CTI is defined for a frame output
        kept_sets = [list(combinations(range(len(actuators)), len(actuators) - j))
                     for j in range(1, max(len(actuators) - dof, 1) + 1)]  # (a = n: F_C1 = 0, as F_O1)
        result["cti"] = max(cti.values())
        result["f_c"] = {j + 1: min(max((v for m, v in cti.items() if set(m) <= set(kept)), default=0.0)
                                    for kept in sets_j) for j, sets_j in enumerate(kept_sets)}
    return result
