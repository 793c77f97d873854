"""Whether the way from the reference assembly to a pose passes a singular configuration of a chain.

A chain closed by damped Newton keeps the reference assembly's working mode by the sign of its joint-twist
determinant (:func:`~screwkit.closure.newton.determinant_sign`), reaching each pose by continuation along the
straight way from the reference pose. Where that way passes a configuration at which the chain's joints are
singular (its twists dependent: two assemblies of the chain meet there), the same sign beyond it is the other
assembly of the chain, not the one a motion through that configuration may continue into. A square four-bar
(every link as long) is the plain case: at the crank's 90 deg its end lies on the rocker's pivot, the
parallelogram and the folded assembly meet, and beyond it the reference's sign is the folded one, where the crank
stays at 90 deg while the rocker turns (published: Genesis's ``four_bar_linkage.xml``).

:func:`singular_on_the_way` samples the way (for ``analyze --pose``), :func:`singular_along` takes a path's
samples (a ``"singular"`` event of ``screwkit trajectory``); both find where the chain's normalised determinant
dips, and refine the dip (golden-section search on the way's parameter, or the path's arc length) to tell a
configuration where the joints are singular (the determinant below :data:`SINGULAR`) from one merely near it.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from screwkit.closure.chain_kinematics import chain_forward_kinematics, twists_from_axes_and_points
from screwkit.closure.newton import task_rows
from screwkit.closure.solve import solve
from screwkit.model import Mechanism

__all__ = ["singular_on_the_way", "singular_along", "SAMPLES", "SINGULAR"]

SAMPLES = 129
"""Poses sampled on the way from the reference pose (both ends included)."""

SINGULAR = 1e-4
"""A chain's normalised joint-twist determinant (moments about the centre of its joints' points, in length scales;
each twist made unit: the same whatever the world frame and the unit) below which its joints count as singular: a
dip refined to below it is a configuration where two of its assemblies meet."""

_DIP = 0.2
"""A sampled dip (a local minimum inside the way) refined only if it is below this."""


def singular_on_the_way(mechanism: Mechanism, pose: NDArray) -> list[tuple[str, NDArray[np.float64]]]:
    """Per chain closed by damped Newton with a working-mode sign, the first singular configuration of its joints
    on the straight way in task coordinates from the reference pose to ``pose`` (m and rad), as ``(chain name, the
    pose there)``; none for a chain whose way has none. Dips between samples where the chain does not close are
    looked at as well."""
    start, pose = np.asarray(mechanism.home_pose, dtype=float), np.asarray(pose, dtype=float)
    if np.array_equal(start, pose):
        return []
    way = np.linspace(0.0, 1.0, SAMPLES)
    found = singular_along(mechanism, start + way[:, None] * (pose - start), way,
                           lambda t: start + t * (pose - start), first_only=True)
    return [(name, start + at * (pose - start)) for name, at, _ in found]


def singular_along(mechanism: Mechanism, poses: NDArray, at: NDArray, pose_at, *, values=None,
                   first_only: bool = False) -> list[tuple[str, float, int]]:
    """Per chain closed by damped Newton with a working-mode sign, the singular configurations of its joints along
    the samples ``poses`` (n, n_task) at parameters ``at`` (n,, increasing), ``pose_at(t)`` giving the pose at any
    parameter between them: ``(chain name, the parameter there, the sample nearest before it)``, refined between
    the samples either side of each dip of its normalised determinant (and in the first and last intervals).
    ``values``: per chain its joint values at the samples, where already solved (a chain's are used when they are
    all its joints); ``first_only``: the first per chain."""
    chains = [k for k, chain in enumerate(mechanism.chains) if chain.closed_form is None and chain.branch is not None
              and chain.geometry.n_dofs == len(task_rows(mechanism.is_planar))]
    found, solved = [], None
    last = len(at) - 1
    for k in chains:
        given = None if values is None else np.asarray(values[k], dtype=float)
        if given is None or given.shape[-1] != mechanism.chains[k].geometry.n_dofs:
            if solved is None:  # every chain's closure at the samples, solved once for all the chains looked at
                solved = solve(mechanism, poses, limits=False).joint_values
            given = np.asarray(solved[k], dtype=float)
        determinants = _normalised(mechanism, k, given)
        finite = np.isfinite(determinants)
        dips = [i for i in range(1, last) if finite[i - 1:i + 2].all() and determinants[i] < _DIP
                and determinants[i] <= determinants[i - 1] and determinants[i] <= determinants[i + 1]]
        ends = [(0, 1), (last, last - 1)] if last >= 1 else []
        dips += [i for i, j in ends if finite[i] and finite[j] and determinants[i] < min(determinants[j], _DIP)]
        for i in sorted(dips):  # (samples where the chain does not close break the way: the dips between them count)
            where, value = _refined(mechanism, k, pose_at, at[max(i - 1, 0)], at[min(i + 1, last)])
            if value < SINGULAR:
                found.append((mechanism.chains[k].name, where, int(np.searchsorted(at, where, side="right")) - 1))
                if first_only:
                    break
    return found


def _determinants(mechanism: Mechanism, k: int, poses: NDArray) -> NDArray[np.float64]:
    """Chain ``k``'s normalised |joint-twist determinant| at ``poses`` (NaN where it does not close)."""
    solution = solve(mechanism, poses, limits=False)
    return _normalised(mechanism, k, np.asarray(solution.joint_values[k], dtype=float))


def _normalised(mechanism: Mechanism, k: int, values: NDArray) -> NDArray[np.float64]:
    """Chain ``k``'s normalised |joint-twist determinant| at its joint values (..., m; NaN where not closed)."""
    geometry = mechanism.chains[k].geometry
    closed = np.all(np.isfinite(values), axis=-1)
    frames = chain_forward_kinematics(geometry, np.nan_to_num(values))
    points = frames.points - np.mean(frames.points, axis=-2, keepdims=True)  # moments about the chain's own centre
    twists = twists_from_axes_and_points(frames.axes, points, geometry.dof_prismatic)
    twists = np.concatenate([twists[..., :3], twists[..., 3:] / mechanism.length_scale], axis=-1)
    twists = twists[..., task_rows(mechanism.is_planar)]
    twists = twists / np.maximum(np.linalg.norm(twists, axis=-1, keepdims=True), 1e-300)
    return np.where(closed, np.abs(np.linalg.det(twists)), np.nan)


def _refined(mechanism: Mechanism, k: int, pose_at, low: float, high: float,
             iterations: int = 20) -> tuple[float, float]:
    """The least normalised determinant of chain ``k`` between the parameters ``low`` and ``high`` (golden
    section): the parameter and the value."""
    ratio = (math.sqrt(5.0) - 1.0) / 2.0

    def value(t: float) -> float:
        found = _determinants(mechanism, k, np.asarray(pose_at(t), dtype=float)[None])[0]
        return float(found) if np.isfinite(found) else np.inf

    a, b = low, high
    c, d = b - ratio * (b - a), a + ratio * (b - a)
    fc, fd = value(c), value(d)
    for _ in range(iterations):
        if fc <= fd:
            b, d, fd = d, c, fc
            c = b - ratio * (b - a)
            fc = value(c)
        else:
            a, c, fc = c, d, fd
            d = a + ratio * (b - a)
            fd = value(d)
    return (c, fc) if fc <= fd else (d, fd)
