"""The paper's planar closed forms at the closed configurations of a solution: the joint points they take and the
indices they give, beside the generic screw path of :mod:`screwkit.studies.poses` (``--closed-forms``, ``verify``).
"""

from __future__ import annotations

import numpy as np

from screwkit.common.tolerances import SINGULARITY_THRESHOLD
from screwkit.indices.closed_forms import planar_indices, point_indices
from screwkit.indices.results import Indices
from screwkit.model import Mechanism

__all__ = ["planar_points", "closed_form_indices", "MEETING_TOLERANCE"]


MEETING_TOLERANCE = 1e-9
"""Relative to the length scale: how far a leg of a five-bar written with its output on a leg's distal link may meet
the platform from the output point for :func:`planar_points` (the closures put them together to rounding)."""


def planar_points(mechanism: Mechanism, solution):
    """Planar joint points of every chain in the base frame (reachable configurations), for the closed forms.

    Returns ``(base, elbows, distal, prismatic)``: arrays (N, k, 2) of the first, second and
    last joint points of each 3-joint planar chain, and whether the chains are RPR (actuated
    prismatic middle joint) rather than RRR (actuated base joint). With a point output, an R-R chain whose second
    link is the platform (a five-bar written with its output on a leg's distal link) has its last point at the
    output point, where the other legs meet it: the actuation wrench's force runs from its elbow through the point.
    """
    if not mechanism.is_planar:
        raise ValueError(f"The closed forms are planar: mechanism {mechanism.name!r} is spatial.")
    kinds, on_platform = set(), []
    for chain in mechanism.chains:
        prismatic = tuple(chain.prismatic)
        on_platform.append(mechanism.output_point is not None and chain.n_joints == 2 and chain.actuated == (0,)
                           and prismatic == (False, False))
        if on_platform[-1]:
            kinds.add("rrr")
            continue
        if chain.n_joints != 3 or chain.actuated not in ((0,), (1,)):
            driven = ", ".join(repr(chain.joint_names[i]) for i in chain.actuated) or "none"
            raise ValueError(f"The closed forms need RRR or RPR chains with one actuator; chain {chain.name!r} of "
                             f"{mechanism.name!r} has {chain.n_joints} joint(s), actuated: {driven} (the generic "
                             "path reads it: `analyze`, without the closed forms).")
        if prismatic == (False, False, False) and chain.actuated == (0,):
            kinds.add("rrr")
        elif prismatic == (False, True, False) and chain.actuated == (1,):
            kinds.add("rpr")
        else:
            raise ValueError(f"The closed forms need RRR (base actuated) or RPR (prismatic actuated) chains; "
                             f"chain {chain.name!r} is not one.")
    if len(kinds) != 1:
        raise ValueError(f"The closed forms need chains of one kind, got {sorted(kinds)}.")
    mask = np.asarray(solution.reachable).reshape(-1)
    everything = bool(mask.all())
    count = int(mask.size if everything else mask.sum())
    # Joint points in the base frame, reachable configurations only, stored component-major
    # (joint, component, chain, configuration) so that every copy below is contiguous; the
    # returned (N, k, 2) arrays are views of it (the closed-form kernel reads any layout).
    memory = np.empty((3, 2, len(solution.joint_points), count))
    point = mechanism.output_positions(solution.full_poses) if any(on_platform) else None  # (in the base frame)
    for chain, points in enumerate(solution.joint_points):
        if on_platform[chain]:  # (R-R to the platform: the output point last)
            points = np.concatenate([points, point[..., None, :]], axis=-2)
        flat = points.reshape(-1, 3, 3)
        for joint in range(3):
            for component in range(2):
                column = flat[:, joint, component]
                memory[joint, component, chain] = column if everything else column[mask]
    base, elbows, distal = (memory[joint].transpose(2, 1, 0) for joint in range(3))
    if any(on_platform):  # (the output point stands for the R-R legs' last joint: where the other legs meet)
        apart = np.linalg.norm(distal - distal[:, on_platform.index(True)][:, None], axis=-1).max(axis=0)
        if not np.all(apart <= MEETING_TOLERANCE * mechanism.length_scale):
            chain = mechanism.chains[int(np.argmax(apart))].name
            raise ValueError(f"The textbook pressure angles are for legs meeting at the output point; chain {chain!r} "
                             f"of {mechanism.name!r} meets the platform {apart.max():.3g} m from it (the generic "
                             "path reads it: `analyze`, without the closed forms).")
    return base, elbows, distal, kinds == {"rpr"}


def closed_form_indices(mechanism: Mechanism, solution, threshold: float = SINGULARITY_THRESHOLD, faults=None,
                        threads: int | None = None) -> Indices:
    """The paper's planar closed forms at the reachable configurations of a solution (a 1-D batch).

    ITI per chain (Eq. 23; 1 for RPR chains, whose input is along the force), the OTI of every
    3-chain submechanism (Eqs. 34, A4), LMTI, F_Oj, F_IOj, the worst faults and the
    mutual-interference actuators, all from :func:`screwkit.indices.closed_forms.planar_indices`; for R-R-R legs
    meeting at a point output (a five-bar), the textbook pressure angles of
    :func:`screwkit.indices.closed_forms.point_indices`.
    """
    base, elbows, distal, prismatic = planar_points(mechanism, solution)
    if mechanism.output_point is not None:
        if prismatic:
            raise ValueError(f"The point-output closed forms are for R-R-R legs; {mechanism.name!r} has R-P-R legs.")
        closed, dof = point_indices(base, elbows, distal, faults=faults), 2
    elif prismatic:
        closed = planar_indices(base, None, distal, threshold=threshold, faults=faults, threads=threads,
                                directions=distal - base)  # the leg directions, normalised there
        dof = 3
    else:
        closed, dof = planar_indices(base, elbows, distal, threshold=threshold, faults=faults, threads=threads), 3
    return Indices.from_arrays(
        mechanism.actuator_names, dof,
        {"iti": closed["iti"], "lmti": closed["lmti"], "f_o": closed["f_o"], "f_io": closed["f_io"],
         "worst_fault_indices": closed["worst_faults"], "mutual_interference": closed["mutual_interference"],
         "iti_actuators": closed["iti_chains"], "oti_submechanisms": closed["oti_submechanisms"],
         "remaining_lmti": closed["remaining_lmti"]},
        threshold=threshold, submechanisms=closed["submechanisms"], task_coordinates=mechanism.task_coordinates,
        mechanism=mechanism.name)
