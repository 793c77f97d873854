r"""Link failures: a failed actuator's chain disappears, constraint wrenches included.

The paper's fault indices (Eqs. 12-14) are for free-swinging joint failures (FSJF): a failed
actuator becomes a passive joint and its chain keeps transmitting its constraint wrenches. It
also names link failures (LF): the chain breaks and stops transmitting anything. screwkit's
``fault_type="link"`` computes

.. math:: F^{LF}_{Oj} = \min_{|E| = a - j} LMTI(\mathcal{M} \setminus \mathcal{C}(A \setminus E)),

the worst, over the sets ``E`` of actuators left after ``j`` faults, of the LMTI of the
*reduced mechanism*: the chains of the failed actuators removed, with every actuator they carried.
The reduced mechanism is analysed as a mechanism of its own: its motion space is that of the
remaining chains, so its DOF ``n'`` may exceed ``n`` when a removed chain held a constraint; with
fewer than ``n'`` actuators left the platform is not held and the LMTI is zero. ``F_IOj`` is
``min(F_Oj, ITI)`` as for free-swinging faults, and ``F_Cj`` the CTI of the reduced mechanism.

When every removed chain carried no constraint wrench of its own (6-DOF chains, or constraint
wrenches that every remaining chain duplicates, as the out-of-plane ones of a planar mechanism) and
one actuator, the reduced mechanism's motion space and remaining actuation wrenches are those of the
free-swinging case and the two fault types give the same numbers (the paper, end of Sec. 3).

Only numpy is imported here; the reduced mechanisms are analysed by the ``analyze`` given.
"""

from __future__ import annotations

from itertools import combinations
from typing import Callable, Sequence

import numpy as np
from numpy.typing import NDArray

from screwkit.common import tolerances
from screwkit.screw.chain_screws import ChainScrews
from screwkit.screw.motion import motion_space

__all__ = ["FAULT_TYPES", "link_fault_indices"]

FAULT_TYPES = ("free-swinging", "link")
"""Fault types: free-swinging joint failures (the paper's FSJF, the default) and link failures (LF)."""


def _reduced(chains: list[ChainScrews], removed: frozenset[int], batch_shape, analyze: Callable,
             options: dict) -> tuple[NDArray, NDArray]:
    """LMTI and CTI (NaN where none applies) of the mechanism without the chains ``removed``."""
    remaining = [chain for index, chain in enumerate(chains) if index not in removed]
    zeros = np.zeros(batch_shape)
    if not remaining or not any(chain.actuated for chain in remaining):
        return zeros, zeros
    dof = motion_space(remaining).dof - options.get("idle_count", 0)
    if sum(len(chain.actuated) for chain in remaining) < dof:
        return zeros, zeros  # the platform gained motions the remaining actuators cannot hold
    result = analyze(remaining, faults=(), detail=False, **options["analyze"])
    cti = np.full(batch_shape, np.nan) if result.cti is None else np.asarray(result.cti)
    return np.asarray(result.lmti), cti


def link_fault_indices(chains: Sequence[ChainScrews], actuators: Sequence[tuple[int, int]], faults: Sequence[int],
                       batch_shape: tuple[int, ...], analyze: Callable, options: dict) -> dict:
    """``F_Oj``, the worst faults and ``F_Cj`` under link failures (see the module docstring).

    Parameters
    ----------
    chains : sequence of ChainScrews
        The mechanism's chains, as given to ``analyze``.
    actuators : sequence of (chain, joint)
        Every actuator, in the order of the results.
    faults : sequence of int
        The numbers of faults ``j``.
    batch_shape : tuple of int
    analyze : callable
        :func:`screwkit.indices.analysis.analyze`.
    options : dict
        ``analyze``: keyword arguments for the reduced analyses; ``idle_count``: idle rotations of a
        point output (subtracted from the motion space's dimension).

    Returns
    -------
    dict
        ``f_o``, ``worst`` (indices into ``actuators``, (..., j)), ``f_c`` and ``lmti`` (the LMTI of every set
        left, (..., C(a, j)), in combination order), each a dict by ``j``.
    """
    chains = list(chains)
    a = len(actuators)
    cache: dict[frozenset[int], tuple[NDArray, NDArray]] = {}
    f_o, worst, f_c, lmti_left = {}, {}, {}, {}
    for j in faults:
        sets = list(combinations(range(a), a - j))
        lmti, cti = [], []
        for remaining in sets:
            removed = frozenset(actuators[k][0] for k in range(a) if k not in remaining)
            if removed not in cache:
                cache[removed] = _reduced(chains, removed, batch_shape, analyze, options)
            lmti.append(cache[removed][0])
            cti.append(cache[removed][1])
        lmti, cti = np.stack(lmti, axis=-1), np.stack(cti, axis=-1)
        lmti_left[j] = lmti
        f_o[j] = lmti.min(axis=-1)
        first = np.argmax(lmti <= f_o[j][..., None] + tolerances.WORST_FAULT_TIE, axis=-1)
        failed = np.array([sorted(set(range(a)) - set(e)) for e in sets], dtype=np.int64).reshape(len(sets), j)
        worst[j] = failed[first]
        with np.errstate(invalid="ignore"):
            f_c[j] = np.fmin.reduce(cti, axis=-1)
    return {"f_o": f_o, "worst": worst, "f_c": f_c, "lmti": lmti_left}
