"""The closed configuration nearest to a file's values: the slide along the closed set that ends an assembly.

:func:`screwkit.io.closed_tree.assemble` closes a tree's closures by damped steps from the file's joint values; where
they stop depends on how the residuals are weighed, so on where the file draws its joints and frames.
:func:`nearest_closed` then moves along the closed configurations (or, for closures that close only to the file's
rounding, along their floor) to the one nearest to the file's values, which the mechanism decides.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

__all__ = ["FLOOR_MOVE", "nearest_closed", "independent_blocks"]

FLOOR_MOVE = 0.1
"""Joint change (rad, or length scales) beyond which closing a residual of the file's rounding is not what the
rounding means. On closures that close only to that rounding, a direction of their Jacobian whose singular value is
below the residual over this moves along the floor: closing the residual along it would turn the joints by more than
this (a ball's radial gap on a sphere that every axis meets), and the assembly does not creep along it. Rhoban's
exported spherical manipulator has two such directions, at 1.2e-6 and 5.5e-6 against a residual of 8.5e-6 (moves of
1.5 rad and more); a 1 mm four-bar beside one of 0.5 m, or one 0.01 rad from its flat singular configuration, has
its weakest closing direction at about 1e-3 (a move of 1e-4 rad for a residual of 1e-7), which is closed."""


def nearest_closed(residuals, derivatives, v: NDArray, error: NDArray, directions: NDArray,
                   on_floor: bool = False, blocks=None) -> tuple[NDArray, NDArray]:
    """From a closed ``v`` (its residuals ``error``; ``derivatives(v)`` their Jacobian along ``directions``), the closed
    configuration nearest to the reference one (v = 0; angles in rad, lengths in the slides' unit of
    :func:`~screwkit.io.closed_tree.assemble`, along ``directions`` only): the point of the linearised closed set
    nearest to 0 (the pseudo-inverse of the closures' Jacobian, whose null space is where the closures stay closed,
    whatever the residuals' weights), closed again on that Jacobian, taken while it comes nearer (halved when it does
    not close again or come nearer). At the end ``v`` is normal to the closed set (no change that keeps them closed
    comes nearer): the least change of the joints, which the mechanism decides, not its drawing. ``on_floor``: closures
    that close only to the file's rounding. The directions that only move along their floor (singular values below the
    residual over :data:`FLOOR_MOVE`) are then free, and closed means that what the other directions can close of the
    residual (its part in their range) is closed, judged on each candidate's own Jacobian: the point nearest to the
    reference where every closure is as closed as it can be (the same for residuals weighed otherwise, to the order of
    the floor times the change of weights). ``blocks`` (:func:`independent_blocks`): the residuals' rows and the
    directions of loops that share no joint; on a floor each is cut by its own residual, so that a loop beside another,
    however open that one is to the rounding, is closed or slid as it is alone."""
    if not on_floor or blocks is None or len(blocks) < 2:
        blocks = [(np.arange(error.size), np.arange(len(directions)))]
    cuts = [float(np.linalg.norm(error[rows])) / FLOOR_MOVE for rows, _ in blocks]

    def inverse(jacobian) -> NDArray:
        """The closures' pseudo-inverse: singular values at most 1e-7 of the largest dropped, on a floor also those
        below each block's cut."""
        if not on_floor:
            return np.linalg.pinv(jacobian, rcond=1e-7)
        if len(blocks) == 1:
            return _cut_inverse(jacobian, cuts[0])
        result = np.zeros(jacobian.shape[::-1])
        for (rows, columns), cut in zip(blocks, cuts):
            result[np.ix_(columns, rows)] = _cut_inverse(jacobian[np.ix_(rows, columns)], cut)
        return result

    def closable(jacobian, inverse_, residual) -> float:
        """What of ``residual`` the steps close: all of it, or on a floor its part in the Jacobian's range."""
        return float(np.linalg.norm(jacobian @ (inverse_ @ residual) if on_floor else residual))

    def chords(candidate, closed, jacobian, inverse_, bound: float, steps: int = 8) -> tuple[NDArray, NDArray]:
        """``candidate`` closed again by up to ``steps`` chord steps along ``jacobian``, until ``bound`` is met."""
        for _ in range(steps):
            if closable(jacobian, inverse_, closed) <= bound:
                break
            candidate = candidate - (inverse_ @ closed) @ directions
            closed = residuals(candidate)
        return candidate, closed

    for _ in range(10):  # closed first to round-off (the damped steps stop at ASSEMBLY_TOLERANCE), so that a nearer
        if not on_floor and np.linalg.norm(error) <= 1e-14:  # point is not one that is merely less closed; a file
            break  # closed as written is left as written, to the bit (a rounded one's reading can turn on last bits)
        jacobian = derivatives(v)
        inverse_ = inverse(jacobian)
        if closable(jacobian, inverse_, error) <= 1e-14:
            break
        candidate = v - (inverse_ @ error) @ directions
        candidate, closed = chords(candidate, residuals(candidate), jacobian, inverse_, 1e-14,
                                   8 if on_floor else 0)  # a weak direction's full step can bend a stiff loop open
        if not closable(jacobian, inverse_, closed) < closable(jacobian, inverse_, error):
            break
        v, error = candidate, closed
    jacobian = derivatives(v) if on_floor else None
    floor = max(2.0 * (closable(jacobian, inverse(jacobian), error) if on_floor
                       else float(np.linalg.norm(error))), 1e-14)

    def close_again(candidate, closed, jacobian, inverse_) -> tuple[NDArray, NDArray, bool]:
        """``candidate`` closed again by chord steps on the Jacobian it was found with, then on a floor judged (and
        closed) on its own Jacobian (the range that closes turns with the configuration); and whether it is closed."""
        candidate, closed = chords(candidate, closed, jacobian, inverse_, floor)
        if not on_floor:
            return candidate, closed, closable(jacobian, inverse_, closed) <= floor
        for _ in range(4):
            own = derivatives(candidate)
            own_inverse = inverse(own)
            if closable(own, own_inverse, closed) <= floor:
                return candidate, closed, True
            candidate = candidate - (own_inverse @ closed) @ directions
            closed = residuals(candidate)
        return candidate, closed, False

    for _ in range(100):
        x = directions @ v
        jacobian = derivatives(v)
        inverse_ = inverse(jacobian)
        step = inverse_ @ (jacobian @ x - error) - x
        if np.linalg.norm(step) <= 1e-10 * max(1.0, float(np.linalg.norm(x))):
            break
        for fraction in 0.5 ** np.arange(8):
            trial = v + (fraction * step) @ directions
            candidate, closed, closes = close_again(trial, residuals(trial), jacobian, inverse_)
            nearer = np.linalg.norm(directions @ candidate) <= np.linalg.norm(x) * (1.0 + 1e-12)  # to round-off
            if closes and nearer:
                break
        else:
            break
        v, error = candidate, closed
    return v, error


def _cut_inverse(jacobian: NDArray, cut: float) -> NDArray:
    """``jacobian``'s pseudo-inverse without its singular values at most 1e-7 of the largest or below ``cut``."""
    if not jacobian.size:
        return np.zeros(jacobian.shape[::-1])
    left, singular, right = np.linalg.svd(jacobian, full_matrices=False)
    keep = singular > max(cut, 1e-7 * singular[0])
    return (right[keep].T / singular[keep]) @ left[:, keep].T


def independent_blocks(rows: Sequence[int], joints: Sequence[set], columns: dict) -> list[tuple[NDArray, NDArray]]:
    """The closures grouped into loops that share no joint: each group's residual rows and directions.

    ``rows``: each closure's count of residual rows, in the residuals' order; ``joints``: each closure's joints (the
    ones whose motion moves one of its frames and not the other); ``columns``: each joint's directions (indices),
    absent for a held joint."""
    group = list(range(len(rows)))

    def root(k: int) -> int:
        while group[k] != k:
            k = group[k]
        return k

    for a in range(len(rows)):
        for b in range(a):
            if joints[a] & joints[b]:
                group[root(a)] = root(b)
    starts = np.concatenate([[0], np.cumsum(rows)]).astype(int)
    blocks = []
    for leader in sorted({root(k) for k in range(len(rows))}):
        members = [k for k in range(len(rows)) if root(k) == leader]
        block_rows = np.concatenate([np.arange(starts[k], starts[k + 1]) for k in members])
        block_columns = sorted({c for k in members for joint in joints[k] for c in columns.get(joint, ())})
        blocks.append((block_rows, np.array(block_columns, dtype=int)))
    return blocks
