"""Whether a study of many poses fits in memory, counted before it computes from the mechanism alone.

A map keeps only its grid's minima (:class:`~screwkit.studies.maps.MapSize`), but a path and a sweep keep every
index at every pose, with the detail they write (the ITI of each actuator, the OTI of each submechanism, the LMTI
left after each set of failures). :func:`pose_bytes` counts what one pose keeps, from the numbers of actuators,
DOF and faults; :func:`check_fits` refuses, in one line naming what was asked, a study whose poses would need more
than :func:`~screwkit.common.memory.available_memory` (at least :data:`PEAK_OVER_RESULT` times that count): before it
computes, rather than failing in an allocation minutes later or being ended by the system without a word.
"""

from __future__ import annotations

from math import comb

import numpy as np

from screwkit.common.memory import available_memory, byte_size

__all__ = ["PEAK_OVER_RESULT", "pose_bytes", "check_fits"]

PEAK_OVER_RESULT = 1.5
"""A lower bound of a study's peak memory over what its result keeps per pose (:func:`pose_bytes`). The growth of
the peak memory per pose over :func:`pose_bytes`, for paths on one thread (numpy's allocations traced), was 1.65,
2.2 (8-leg hexapod), 7.9, 5.4 (5-RRR), 24, 11.5 (4-leg Delta) and 26, 11.3 (3-PRS + UPS) from 10,000 to 30,000
and from 20,000 to 60,000 samples; 2.4, 5.0 and 3.4 for the first three from 200,000 to 400,000 samples (resident
memory), and 2.9 (hexapod) and 4.3 (5-RRR) for sweeps (2026-12-05): the indices' arrays, the series and the dataset
written are copies of each other for a while, and each chunk's work is several times its result. A study refused
needs at least this much; one that passes may still need several times more. Where an allocation then fails,
``screwkit`` says in one line that memory ran out and writes nothing (the system may end the process instead,
where it overcommits memory)."""


def pose_bytes(mechanism, faults=None, joint_coordinates: int = 0) -> int:
    """What one pose of a path or a sweep keeps of ``mechanism`` (a Mechanism or a GraphMechanism): every index
    with its detail for the numbers of ``faults`` (default all, 1..a-n), the pose, and ``joint_coordinates`` joint
    values (bytes)."""
    a, n = len(mechanism.actuator_names), mechanism.dof
    everything = tuple(range(1, a - n + 1))
    try:  # (numbers of faults that are not, or out of range, are refused later, by the index computation)
        faults = everything if faults is None else tuple(max(0, min(int(j), a)) for j in np.atleast_1d(faults))
    except (TypeError, ValueError):
        faults = everything
    sets, failed = comb(a, n), sum(comb(a, j) for j in faults)
    lower = n < (3 if mechanism.is_planar else 6)  # the constraint transmission's arrays besides
    doubles = (sets * (2 if lower else 1) + failed + a + 2 + 2 * len(faults) + sum(faults) + mechanism.n_task + 1
               + (1 + len(faults) if lower else 0) + joint_coordinates)
    return 8 * doubles + a + 2


def check_fits(count: int, per_pose: int, what: str, available_bytes: int | None = None) -> None:
    """A ValueError, in one line, when ``count`` poses of ``per_pose`` bytes each, times :data:`PEAK_OVER_RESULT`
    (at least what they need), need more memory than this process can be given. ``what`` names the study and its
    size as asked ("--samples 1000000: the path has 1,000,000 samples")."""
    available = available_memory() if available_bytes is None else available_bytes
    needed = int(PEAK_OVER_RESULT * count * per_pose)
    if available is not None and needed > available:
        raise ValueError(f"{what}, which need at least {byte_size(needed)}, more than this process can be given "
                         f"({byte_size(available)} available): ask for fewer, or split the study into parts.")
