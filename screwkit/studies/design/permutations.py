"""Design search for planar n-RRR mechanisms: the paper's permutation selection and beyond.

* :func:`planar_design` reads the parameters of a planar n-RRR from a loaded mechanism;
* :func:`permutation_search` redoes the paper's selection (Sec. 4): every assignment of
  the platform joint slots to the chains (n! of them) in both working modes, scored by the
  minimum of F_O1 over a full rotation at the workspace centre, ranked;
* :func:`family_values` places a planar n-RRR in the family ``planar_rrr``, whose design search
  (the paper's future work) is :mod:`screwkit.studies.design.optimise`.

Evaluations run as tasks (:func:`screwkit.studies.tasks.run_tasks`: local threads, or a Dask cluster).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from itertools import permutations

import numpy as np
from numpy.typing import NDArray

from screwkit.closure import solve
from screwkit.common.tolerances import SINGULARITY_THRESHOLD
from screwkit.indices.analysis import analyze
from screwkit.indices.average import AGGREGATES, failure_weights, mean_remaining_lmti
from screwkit.indices.closed_forms import planar_indices
from screwkit.model import Mechanism, require_mechanism
from screwkit.screw.planar import PlanarDesign, planar_joint_points, rrr_chain_screws
from screwkit.studies.closed_form_poses import planar_points
from screwkit.studies.coordinates import planar_position
from screwkit.studies.design.families import permutation_rank
from screwkit.studies.design.objectives import check_disc, check_turn_count, real_number
from screwkit.studies.tasks import Execution, run_tasks

__all__ = ["planar_design", "slot_design", "slots_of", "rotation_score", "permutation_search", "rotation_class",
           "DesignScore", "fault_tolerant_area", "family_values"]


def planar_design(mechanism: Mechanism) -> PlanarDesign:
    """The :class:`~screwkit.screw.planar.PlanarDesign` of a planar n-RRR mechanism at its home pose.

    Base and platform joint points, arm lengths and working mode are read from the solved
    reference assembly (base frame), so any planar RRR URDF can be searched.
    """
    require_mechanism(mechanism, "planar_design")
    if not mechanism.is_planar:
        raise ValueError(f"Design search needs a planar n-RRR; {mechanism.name!r} is spatial.")
    if mechanism.task_coordinates != ("x", "y", "phi"):
        raise ValueError(f"Design search needs a planar n-RRR whose platform turns (x, y, phi); {mechanism.name!r} "
                         f"has the task coordinates {', '.join(mechanism.task_coordinates)}.")
    home = mechanism.home_pose
    solution = solve(mechanism, home[None])
    base, elbows, distal, prismatic = planar_points(mechanism, solution)
    if prismatic:
        raise ValueError(f"Design search needs RRR chains; {mechanism.name!r} has RPR chains.")
    base, elbows, distal = base[0], elbows[0], distal[0]
    cos, sin = np.cos(home[2]), np.sin(home[2])
    local = (distal - home[:2]) @ np.array([[cos, -sin], [sin, cos]])  # R(phi)^T (d - r)
    chord = distal - base
    side = np.sign(chord[:, 0] * (elbows - base)[:, 1] - chord[:, 1] * (elbows - base)[:, 0])
    return PlanarDesign(base, local, np.linalg.norm(elbows - base, axis=-1), np.linalg.norm(distal - elbows, axis=-1),
                        np.where(side == 0, 1.0, side))


def slots_of(design: PlanarDesign) -> NDArray[np.int64]:
    """The slot of each chain's platform joint: slot s sits at angle s 2 pi / n in the platform frame."""
    n = design.chain_count
    angles = np.arctan2(design.platform[:, 1], design.platform[:, 0])
    return np.round(angles / (2 * np.pi / n)).astype(int) % n


def slot_design(design: PlanarDesign, permutation, working_mode: int | None = None,
                platform_radius: float | None = None) -> PlanarDesign:
    """A design whose chain i has its platform joint at slot ``permutation[i]`` (angle slot 2 pi / n).

    The platform radius is the mean radius of ``design`` unless given; the working mode is
    kept unless given (+1 or -1 for every chain).
    """
    n = design.chain_count
    try:  # whole numbers only: 3.9 is no slot (not slot 3)
        given = np.asarray(permutation, dtype=float)
    except (TypeError, ValueError):
        given = np.full(1, np.nan)
    if given.shape != (n,) or not np.all(given == np.round(given)) or sorted(given.tolist()) != list(range(n)):
        raise ValueError(f"Expected `permutation` to be a permutation of 0..{n - 1}, got {permutation!r:.80}.")
    permutation = given.astype(int)
    if working_mode is not None and working_mode not in (1, -1):
        raise ValueError(f"Expected `working_mode` +1 or -1 (or None: kept), got {working_mode!r}.")
    if platform_radius is None:
        radius = float(np.mean(np.linalg.norm(design.platform, axis=-1)))
    else:
        radius = real_number(platform_radius, "`platform_radius`")
        if not (np.isfinite(radius) and radius > 0):
            raise ValueError(f"Expected `platform_radius` > 0 (m), got {platform_radius!r}.")
    angles = permutation * 2 * np.pi / n
    platform = radius * np.column_stack([np.cos(angles), np.sin(angles)])
    mode = design.working_mode if working_mode is None else np.full(n, float(working_mode))
    return replace(design, platform=platform, working_mode=mode)


def rotation_score(design: PlanarDesign, centre=(0.0, 0.0), phi_step_degrees: float = 1.0, *,
                   faults: int = 1, threshold: float = SINGULARITY_THRESHOLD, closed_forms: bool = False,
                   aggregate: str = "min", probabilities=None) -> float:
    """Minimum of F_Oj over a full platform rotation at ``centre`` (NaN if some angle is unreachable).

    ``aggregate="mean"``: of the average case instead, the (``probabilities``-weighted) mean over the sets of ``j``
    failed actuators of the LMTI left (:mod:`screwkit.indices.average`, screwkit's extension of Eq. 12)."""
    if aggregate not in AGGREGATES:
        raise ValueError(f"Expected `aggregate` in {', '.join(AGGREGATES)}, got {aggregate!r}.")
    if probabilities is not None and aggregate != "mean":
        raise ValueError("Failure probabilities weight the mean: give them with aggregate='mean'.")
    check_turn_count(phi_step_degrees)
    x, y = planar_position(centre)
    phi = np.deg2rad(np.arange(0.0, 360.0 - 1e-9, phi_step_degrees))
    poses = np.column_stack([np.full_like(phi, x), np.full_like(phi, y), phi])
    base, elbows, distal, reachable = planar_joint_points(design, poses)
    if not np.all(reachable):
        return float("nan")
    mean = aggregate == "mean"
    if closed_forms:
        found = planar_indices(base, elbows, distal, threshold=threshold, faults=(faults,), threads=1)
        worst, left = found["f_o"][faults], found["remaining_lmti"][faults]
    else:
        found = analyze(rrr_chain_screws(base, elbows, distal), threshold=threshold, faults=faults, detail=mean,
                        threads=1)
        worst, left = found.f_o[faults], found.remaining_lmti.get(faults)
    values = mean_remaining_lmti({faults: left}, design.chain_count, probabilities)[faults] if mean else worst
    return float(values.min())


@dataclass(frozen=True)
class DesignScore:
    """One candidate of :func:`permutation_search`."""

    permutation: tuple[int, ...]
    working_mode: int
    score: float


def _score_task(design, permutation, mode, phi_step, faults, threshold, closed_forms, aggregate="min",
                probabilities=None):
    return rotation_score(slot_design(design, permutation, mode), phi_step_degrees=phi_step, faults=faults,
                          threshold=threshold, closed_forms=closed_forms, aggregate=aggregate,
                          probabilities=probabilities)


def permutation_search(design: PlanarDesign, *, phi_step_degrees: float = 1.0, faults: int = 1,
                       threshold: float = SINGULARITY_THRESHOLD, closed_forms: bool = False,
                       execution: Execution | None = None, aggregate: str = "min",
                       probabilities=None) -> list[DesignScore]:
    """Every slot permutation in both working modes, ranked by the minimum of F_Oj over a full rotation (of its
    mean over the sets of failed actuators with ``aggregate="mean"``: :func:`rotation_score`).

    As the paper's Sec. 4: base and platform joints on regular polygons, identical arms,
    the n! assignments of platform slots to chains, each scored at the workspace centre
    (the origin of the base frame). Designs that differ by a rotation of the slots
    (``permutation + k mod n``) are the same mechanism rotated and get the same score.
    ``execution``: where the designs are scored (default: local threads, a progress bar when
    stderr is a terminal).

    Returns
    -------
    list of DesignScore
        Best first (NaN scores, i.e. not fully rotatable, last).
    """
    check_turn_count(phi_step_degrees)  # counted before any angle is listed
    n = design.chain_count
    candidates = [(p, mode) for mode in (1, -1) for p in permutations(range(n))]
    if probabilities is not None:  # (checked once, not in every task)
        failure_weights(n, faults, probabilities)
        probabilities = tuple(float(p) for p in probabilities)
    arguments = [(design, p, mode, phi_step_degrees, faults, threshold, closed_forms, aggregate, probabilities)
                 for p, mode in candidates]
    scores = run_tasks(_score_task, arguments, execution, label="designs")
    ranked = [DesignScore(tuple(int(i) for i in p), mode, float(s)) for (p, mode), s in zip(candidates, scores)]
    # Scores equal to 1e-9 are ties (rotated or mirrored copies differ only by rounding);
    # ties are listed working mode +1 first, then by permutation.
    return sorted(ranked, key=lambda d: (np.isnan(d.score), -round(np.nan_to_num(d.score), 9), d.working_mode < 0,
                                         d.permutation))


def rotation_class(permutation) -> tuple[int, ...]:
    """The smallest of the n slot rotations ``permutation + k mod n``: one label per rotated design."""
    n = len(permutation)
    return min(tuple((p + k) % n for p in permutation) for k in range(n))


def fault_tolerant_area(design: PlanarDesign, *, level: float = 0.4, radius: float = 0.6, step: float = 0.05,
                        phi_step_degrees: float = 5.0, faults: int = 1, threshold: float = SINGULARITY_THRESHOLD):
    """Area (m^2) of the positions of a disc where the minimum of F_Oj over a full rotation is >= ``level``.

    Evaluated with the planar closed forms on a grid of spacing ``step`` (each point counts
    ``step^2``); a position where some angle is unreachable does not count.

    Returns
    -------
    area : float
    grid : ndarray (k, k)
        Minimum over the rotation at every grid point (NaN outside the disc or unreachable).
    """
    check_disc(radius, step, phi_step_degrees)
    if not 0 <= real_number(level, "`level`") <= 1:  # (NaN too) the indices are in [0, 1]
        raise ValueError(f"Expected `level` in [0, 1] (an index value), got {level!r}.")
    count = int(np.floor(radius / step + 1e-9))
    offsets = step * np.arange(-count, count + 1)
    x, y = np.meshgrid(offsets, offsets)
    inside = x**2 + y**2 <= radius**2 * (1 + 1e-12)
    phi = np.deg2rad(np.arange(0.0, 360.0 - 1e-9, phi_step_degrees))
    positions = np.column_stack([x[inside], y[inside]])
    poses = np.concatenate([np.repeat(positions, phi.size, axis=0), np.tile(phi, positions.shape[0])[:, None]], axis=1)
    base, elbows, distal, reachable = planar_joint_points(design, poses)
    values = np.full(poses.shape[0], np.nan)
    if reachable.any():
        values[reachable] = planar_indices(base[reachable], elbows[reachable], distal[reachable], threshold=threshold,
                                           faults=(faults,), threads=1)["f_o"][faults]
    values = values.reshape(positions.shape[0], phi.size)
    minimum = np.where(np.all(np.isfinite(values), axis=1), np.min(values, axis=1), np.nan)
    grid = np.full(x.shape, np.nan)
    grid[inside] = minimum
    return float(np.sum(minimum >= level) * step**2), grid


def family_values(design: PlanarDesign) -> tuple[int, dict[str, float]]:
    """(legs, values) of ``design`` in the family ``planar_rrr`` (:mod:`screwkit.studies.design.families`).

    Raises ValueError naming the first chain that does not fit the family (base joints on a circle
    at the angles 2 pi i / n, platform joints on a circle at slot angles, identical arms, one
    working mode), in the order of their base joints' angles whatever the order the file lists them in."""
    n = design.chain_count
    turn = np.round(np.arctan2(design.base[:, 1], design.base[:, 0]) / (2 * np.pi / n)).astype(int) % n
    order = np.argsort(turn, kind="stable")  # the family's chain i has its base joint at the angle 2 pi i / n
    design = PlanarDesign(design.base[order], design.platform[order], design.upper[order], design.lower[order],
                          design.working_mode[order])
    radius = float(np.mean(np.linalg.norm(design.base, axis=-1)))
    angles = 2 * np.pi * np.arange(n) / n
    expected = radius * np.column_stack([np.cos(angles), np.sin(angles)])
    platform_radius = float(np.mean(np.linalg.norm(design.platform, axis=-1)))
    slots = slots_of(design)
    slot_points = platform_radius * np.column_stack([np.cos(slots * 2 * np.pi / n), np.sin(slots * 2 * np.pi / n)])
    for i in range(n):
        for what, actual, wanted in (("base joint", design.base[i], expected[i]),
                                     ("platform joint", design.platform[i], slot_points[i]),
                                     ("proximal arm", design.upper[i], design.upper[0]),
                                     ("distal arm", design.lower[i], design.lower[0]),
                                     ("working mode", design.working_mode[i], design.working_mode[0])):
            if not np.allclose(actual, wanted, rtol=0, atol=1e-9 * max(1.0, radius)):
                raise ValueError(f"The design is not a member of the family planar_rrr: chain {i + 1}'s {what} "
                                 f"is {np.round(actual, 6).tolist()}, the family's would be "
                                 f"{np.round(wanted, 6).tolist()}.")
    if sorted(slots.tolist()) != list(range(n)):
        raise ValueError(f"The design is not a member of the family planar_rrr: platform slots {slots.tolist()} "
                         "are not a permutation.")
    return n, {"base_radius": radius, "platform_radius": platform_radius, "upper": float(design.upper[0]),
               "lower": float(design.lower[0]), "slots": float(permutation_rank(slots.tolist())),
               "mirrored": float(design.working_mode[0] < 0)}
