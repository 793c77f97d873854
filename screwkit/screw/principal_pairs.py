r"""The principal pairs of a released chain's constraint wrenches and the twists their release frees, and their power
coefficients: the CTI's inner step (:mod:`screwkit.screw.constraints`), as numpy code over batches.

Releasing chain ``i``'s own constraint wrenches ``C`` (orthonormal rows, working coordinates) frees the twists ``F``
(orthonormal columns). Their pairing ``C o F = U S V^T`` gives the pairs: wrench ``u_k^T C`` with twist ``F v_k``,
each wrench reciprocal to every freed twist but its own, and :math:`\kappa` of each pair is its power coefficient.

**Repeated singular values.** Where ``S`` repeats a value ``s`` (a pin holding a foot: 1, 1, 1, 1, 0.32), the
singular vectors of the block are any rotation ``U_b R``, ``V_b R`` of each other, and every rotation pairs the
wrenches as well (``(U_b R)^T (C o F) (V_b R) = s I``): with unit ``a``, the wrench ``a^T U_b^T C`` is reciprocal to
every freed twist but ``F V_b a``, and its power on it is ``s``. The pairs' :math:`\kappa`, taken at points, change
with ``R``, and numpy's pick follows the rounding of its input, so the CTI would move with a change of drawing or of
unit. The block instead takes its **worst rotation**: the lowest :math:`\kappa` of ``(a^T U_b^T C, F V_b a)`` over
every unit ``a`` (any unit ``a`` is the first column of some ``R``), the worst case the paper's indices take
everywhere; it is no higher than any pick's. Each rotated wrench is taken at the chain's joint point projected on its
axis, not where it crosses the joint's line (:func:`~screwkit.screw.algebra.nearest_on_axis`, as a pair of its own
is): a rotation that turns a force almost along a pin makes it cross the pin's axis arbitrarily far away, where the
crossing moves fast and :math:`\kappa` vanishes, and the search would find that edge (an excavator boom read as a
graph: 1.0e-6). Found by a fixed set of directions on the half sphere (``a`` and ``-a``
are the same pair) and compass searches from the lowest of them, apart from each other (:data:`_STARTS`; steps along
and against turned axes, doubled after a move and halved after none, down to :data:`_STEP_FLOOR`): equal to scipy's
minimisation from many starts to 1e-12 on every block a published file makes (two and four pairs), to 4e-4 on
synthetic blocks of five, which only an accident of numbers makes (the point on a wrench's axis jumps as its pitch
leaves zero, and the search can stop at that edge). At the tolerance's edge it is a convention:
values a little further apart pair by their singular vectors, whose values the worst rotation need not be the limit
of (a synthetic block of 1, 1, 1 - 1.01e-6 read 0.02 higher than of 1, 1, 1 - 0.99e-6).
"""

from __future__ import annotations

import math
from functools import cache

import numpy as np
from numpy.typing import NDArray

from screwkit.common import tolerances
from screwkit.screw.algebra import SWAP, nearest_on_axis

_STEP_FLOOR = 1e-9
"""Smallest step of the compass search on the unit sphere of a repeated block (radians, about): near its minimum
:math:`\\kappa` is quadratic in the step, so it is found to about its square."""

_SEARCH_STEPS = 400
"""At most this many steps of the compass search (each moves and doubles the step, up to the samples' spacing, or
halves it)."""

_STARTS = 8
"""Compass searches from this many of the lowest sampled directions, apart from each other (blocks of up to four
pairs, as a mechanism's geometry makes them: a pin holding a foot repeats four)."""

_MORE_STARTS = 32
"""The same for a block of five or six pairs, which only an accident of numbers makes (eight starts missed the
lowest of a synthetic five-block by up to 0.024)."""

_APART = 3
"""Sampled directions closer than this many spacings to a chosen start are in its valley."""

_BATCH = 1 << 21
"""About this many sampled pairs at once (memory)."""


def released_pairs(own: NDArray, freed: NDArray, valid: NDArray | None = None):
    """Principal pairs of a chain's own constraint wrenches (..., c, 6) and the twists (..., 6, d) their release
    frees: wrenches ``U^T C`` and twists ``F V`` from the singular vectors of the pairing ``C o F = U S V^T``
    (orthonormal ``F``), so that each wrench is reciprocal to every freed twist but its own.
    ``valid`` (..., d): which columns of ``freed`` are freed twists (the others are ignored). Returns wrenches
    (..., d, 6), twists (..., d, 6), the singular values (..., d) and a mask (..., d) of the pairs that exist. One
    wrench and one freed twist are their own pair."""
    if own.shape[-2] == 1 and freed.shape[-1] == 1:
        exists = np.ones(own.shape[:-2] + (1,), dtype=bool) if valid is None else valid
        return own, np.swapaxes(freed, -1, -2), exists.astype(float), exists
    if valid is not None:
        freed = freed * valid[..., None, :]
    pairing = own @ SWAP @ freed  # (..., c, d): C_k o F_l
    left, singular, right = np.linalg.svd(pairing, full_matrices=False)  # d <= c where the system is regular
    wrenches = np.swapaxes(left, -1, -2) @ own  # (..., d, 6)
    twists = np.swapaxes(freed @ np.swapaxes(right, -1, -2), -1, -2)  # (..., d, 6)
    exists = singular > tolerances.RANK_TOLERANCE * np.maximum(singular[..., :1], 1e-300)
    return wrenches, twists, singular, exists


def power_coefficients(wrench: NDArray, twist: NDArray, point: NDArray, threshold: NDArray) -> NDArray:
    """Power coefficient of unit constraint wrenches on twists (the kernel's definition, working coordinates), the
    characteristic point ``point`` on each wrench's axis."""
    force, moment = wrench[..., :3], wrench[..., 3:]
    omega, velocity = twist[..., :3], twist[..., 3:]
    force_norm = np.linalg.norm(force, axis=-1)
    moment_norm = np.linalg.norm(moment, axis=-1)
    forceful = force_norm > tolerances.ROUNDED_COUPLE * moment_norm  # (else a couple: its force, if any, left out)
    numerator = np.abs(np.where(forceful, np.sum(force * velocity, -1), 0.0) + np.sum(moment * omega, -1))
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


def pair_coefficients(wrenches: NDArray, twists: NDArray, joint: NDArray, threshold: NDArray) -> NDArray:
    """:math:`\\kappa` of pairs (..., d, 6) released from one chain whose platform joint is ``joint`` (..., 6: its
    point and :func:`~screwkit.screw.algebra.joint_lines` direction): each wrench's characteristic point the point
    of its axis nearest the joint (:func:`~screwkit.screw.algebra.nearest_on_axis`). ``threshold`` (...)."""
    centres = nearest_on_axis(wrenches, joint[..., None, :3], joint[..., None, 3:])
    return power_coefficients(wrenches, twists, centres, threshold[..., None])


@cache
def _directions(size: int) -> tuple[NDArray, float]:
    """Fixed unit directions over half the unit sphere of R^size (``a`` and ``-a`` are the same pair), the coordinate
    axes (the pick's own pairs) first, and their spacing (radians, about)."""
    if size == 2:
        angles = np.arange(360) * np.pi / 360
        return np.stack([np.cos(angles), np.sin(angles)], axis=-1), np.pi / 360
    count = 1024 << (size - 2)
    samples = np.random.default_rng(size).normal(size=(count, size))
    samples /= np.linalg.norm(samples, axis=-1, keepdims=True)
    half_area = np.pi ** (size / 2) / math.gamma(size / 2)  # half the area of the unit sphere of R^size
    return np.concatenate([np.eye(size), samples]), (half_area / count) ** (1 / (size - 1))


@cache
def _turns(size: int) -> list[NDArray]:
    """Fixed sets of steps (2 size, size) of the compass search: along and against the axes of turned frames of
    R^size, the first the coordinate axes."""
    rng = np.random.default_rng(size)
    frames = [np.eye(size)] + [np.linalg.qr(rng.normal(size=(size, size)))[0] for _ in range(31)]
    return [np.concatenate([frame, -frame]) for frame in frames]


def _starts(directions: NDArray, values: NDArray, spacing: float, count: int) -> NDArray:
    """The ``count`` lowest of ``values`` (M, D) at directions (D, k), each at least :data:`_APART` spacings from those
    taken before (so mostly in other valleys, where the sphere has them), as indices (M, count)."""
    rows = np.arange(values.shape[0])
    left = values.copy()
    picks = []
    for _ in range(count):
        pick = left.argmin(axis=-1)
        picks.append(pick)
        near = np.abs(directions[pick] @ directions.T) > np.cos(_APART * spacing)  # (M, D)
        left = np.where(near, np.inf, left)
        left[rows, pick] = np.inf
    return np.stack(picks, axis=-1)


def worst_rotation(wrenches: NDArray, twists: NDArray, joint: NDArray, threshold: NDArray) -> NDArray:
    """The lowest :math:`\\kappa` of the pairs ``(a W, a T)`` over unit ``a`` of one repeated block of M chains'
    pairs: wrenches and twists (M, k, 6), ``joint`` (M, 6), ``threshold`` (M,). Returns (M,).

    Sampled on fixed directions, then compass searches (steps along and against the axes of turned frames of R^k,
    renormalised; doubled after a move, halved where none is lower) from :data:`_STARTS` of the lowest samples, apart
    from each other, at once: the sphere has several valleys (five on Gepetto's ``robot_marcheur_3`` foot pin, whose
    lowest a search from the lowest sample alone missed)."""
    count, size = wrenches.shape[:2]
    directions, spacing = _directions(size)
    chunk = max(1, _BATCH // directions.shape[0])
    if count > chunk:  # bounded memory: a few million pairs at once
        return np.concatenate([worst_rotation(wrenches[i:i + chunk], twists[i:i + chunk], joint[i:i + chunk],
                                              threshold[i:i + chunk]) for i in range(0, count, chunk)])

    def kappa(a, rows):  # directions (L, D, k) of the blocks ``rows`` (L,) -> (L, D)
        return pair_coefficients(a @ wrenches[rows], a @ twists[rows], joint[rows], threshold[rows])

    values = kappa(np.broadcast_to(directions, (count,) + directions.shape), np.arange(count))
    starts = _starts(directions, values, spacing, _STARTS if size <= 4 else _MORE_STARTS)
    # one search per start, flat: its block, direction, value and step; those whose step is below the floor stop
    owner = np.repeat(np.arange(count), starts.shape[1])
    best = directions[starts.reshape(-1)]
    value = np.take_along_axis(values, starts, axis=-1).reshape(-1)
    step = np.full(value.shape, spacing)
    turns = _turns(size)
    for iteration in range(_SEARCH_STEPS):
        live = np.flatnonzero(step >= _STEP_FLOOR)
        if live.size == 0:
            break
        moves = turns[iteration % len(turns)]  # along and against axes turned anew each step (past kinks)
        candidates = best[live, None, :] + step[live, None, None] * moves  # (L, 2k, k)
        candidates /= np.linalg.norm(candidates, axis=-1, keepdims=True)
        trial = kappa(candidates, owner[live])
        pick = trial.argmin(axis=-1)
        lower = trial[np.arange(live.size), pick]
        better = lower < value[live]
        best[live[better]] = candidates[np.flatnonzero(better), pick[better]]
        value[live[better]] = lower[better]
        step[live] = np.where(better, np.minimum(2.0 * step[live], spacing), step[live] / 2)  # longer after a move
    return value.reshape(count, -1).min(axis=-1)


def worst_in_blocks(kappa: NDArray, singular: NDArray, exists: NDArray, wrenches: NDArray, twists: NDArray,
                    joint: NDArray, threshold: NDArray) -> NDArray:
    """``kappa`` (..., d) of pairs released from one chain with each block of repeated singular values (equal within
    :data:`~screwkit.common.tolerances.REPEATED_PAIRING` of the largest) given its worst rotation
    (:func:`worst_rotation`). ``singular``, ``exists`` (..., d); ``wrenches``, ``twists`` (..., d, 6); ``joint``
    (..., 6); ``threshold`` (...)."""
    size = singular.shape[-1]
    if size < 2:
        return kappa
    gap = tolerances.REPEATED_PAIRING * singular[..., :1]
    alike = (singular[..., :-1] - singular[..., 1:] <= gap) & exists[..., 1:]
    if not alike.any():
        return kappa
    kappa = kappa.copy()
    joint = np.broadcast_to(joint, kappa.shape[:-1] + (6,))
    threshold = np.broadcast_to(threshold, kappa.shape[:-1])
    edge = np.zeros(kappa.shape[:-1] + (1,), dtype=bool)
    bounded = np.concatenate([edge, alike, edge], axis=-1)  # bounded[k + 1]: pairs k and k + 1 are alike
    for start in range(size - 1):
        for stop in range(start + 2, size + 1):  # the maximal block of pairs start .. stop - 1
            block = bounded[..., start + 1:stop].all(axis=-1) & ~bounded[..., start] & ~bounded[..., stop]
            if not block.any():
                continue
            point = joint[block] * np.array([1.0, 1.0, 1.0, 0.0, 0.0, 0.0])  # (the joint's point, not its line)
            kappa[block, start:stop] = worst_rotation(wrenches[block][:, start:stop], twists[block][:, start:stop],
                                                      point, threshold[block])[:, None]
    return kappa
