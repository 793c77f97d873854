"""The actuator sets of the paper's indices: submechanisms (Eq. 10), the sets left after ``j`` faults (Eq. 13),
and how the compiled kernel reduces the submechanisms' OTIs to the LMTIs of Eq. 12 (with the exterior-product
tables of its output twists). Everything here depends on ``a``, ``n`` and the values of ``j`` only; it is
computed once per mechanism (cached), never per configuration.

Only numpy is imported here.
"""

from __future__ import annotations

import functools
from itertools import combinations
from math import comb

import numpy as np
from numpy.typing import NDArray

__all__ = ["fault_sets", "set_plan", "WEDGE_TERMS", "wedge_tables", "reductions", "remaining_lmti",
           "submechanisms_left"]


def fault_sets(actuator_count: int, dof: int, faults: int) -> tuple[tuple[int, ...], ...]:
    """The remaining-actuator sets ``E_i`` (Eq. 13) for ``faults`` failed actuators, in combination order."""
    return tuple(combinations(range(actuator_count), actuator_count - faults))


@functools.lru_cache(maxsize=32)
def set_plan(a: int, n: int, fault_list: tuple[int, ...]) -> dict:
    """What a plan takes from a, n and the values of j alone (submechanisms, locked sets, fault reductions,
    failed sets), cached: 17 ms for a = 12 and every j, once per process, not per chunk; shared, only read."""
    submechanisms = list(combinations(range(a), n))
    locked = list(combinations(range(a), n - 1))
    locked_index = {subset: index for index, subset in enumerate(locked)}
    set_children, fault_rows = reductions(a, n, submechanisms, fault_list)
    return dict(
        submechanisms=np.array(submechanisms, dtype=np.int64).reshape(len(submechanisms), n),
        locked_sets=np.array(locked, dtype=np.int64).reshape(len(locked), n - 1),  # n = 1: one empty set
        locked_of=np.array([[locked_index[tuple(i for i in sub if i != k)] for k in sub] for sub in submechanisms],
                           dtype=np.int64).reshape(len(submechanisms), n),
        failed_sets={j: np.array([sorted(set(range(a)) - set(e)) for e in fault_sets(a, n, j)],
                                 dtype=np.int64).reshape(-1, j) for j in fault_list},
        set_children=set_children, fault_rows=fault_rows,
        locked_depth=np.array([0] + [next(k for k in range(n - 1) if before[k] != after[k])
                                     for before, after in zip(locked, locked[1:])], dtype=np.int64),
        **wedge_tables(n))


WEDGE_TERMS = 5
"""Expansion terms per minor in :func:`wedge_tables`: at most n - 1 = 5 (twists have six coordinates)."""


def wedge_tables(n: int) -> dict:
    """Expansion terms of the exterior products that give the output twists for n >= 4.

    The minor of rows ``r_1..r_K`` on columns ``S = {s_0 < ... < s_(K-1)}`` expands along its last
    row: ``sum_t (-1)^(K-1-t) m_(S - s_t) r_K[s_t]``, ``m`` the minors of the first ``K - 1`` rows
    (level 1: the first row). Row ``i`` of ``wedge_table`` is one minor: the index of ``S`` among the
    K-column sets, then for each term the index of ``S - s_t`` among the (K-1)-column sets, ``s_t``
    and the sign, padded to ``WEDGE_TERMS`` terms with zero signs, so that the kernel sums every
    minor in one fixed pass; level K's minors are rows ``wedge_start[K]:wedge_start[K+1]`` (none
    below K = 2). At level n - 1 the minors are the cofactor vector's entries: no pivoting and no
    division, each locked set's vector from its predecessor's minors (Sum_K C(n, K) K
    multiply-adds per new row).
    """
    table, start = [], [0, 0, 0]
    for size in range(2, max(n, 2)):
        previous = {columns: index for index, columns in enumerate(combinations(range(n), size - 1))}
        for target, columns in enumerate(combinations(range(n), size)):
            terms = [(previous[columns[:t] + columns[t + 1:]], column, (-1) ** (size - 1 - t))
                     for t, column in enumerate(columns)]
            terms += [(0, 0, 0)] * (WEDGE_TERMS - len(terms))
            table.append((target,) + tuple(value for term in terms for value in term))
        start.append(len(table))
    start += [len(table)] * (n + 1 - len(start))
    return dict(wedge_table=np.array(table, dtype=np.int64).reshape(-1, 1 + 3 * WEDGE_TERMS),
                wedge_start=np.array(start[:n + 1], dtype=np.int64))


def reductions(a: int, n: int, submechanisms: list[tuple[int, ...]], fault_list: tuple[int, ...]):
    """The sets whose LMTIs give F_Oj, each as the maximum of earlier rows, whichever way costs fewer reads.

    The kernel's rows are the submechanisms' OTIs (``S = C(a, n)`` of them), then one row per set
    ``E`` of ``set_children``, the maximum over the rows it lists. *Table*: each set left after
    ``j`` faults lists the C(a - j, n) submechanisms it contains (Sum_j C(a, j) C(a - j, n) reads).
    *Lattice*: ``LMTI_E = max_{e in E} LMTI_{E - e}`` for ``|E| > n`` (every submechanism of ``E``
    misses some ``e``), so every set of size n + 1, n + 2, ... lists its ``|E|`` subsets one
    smaller (Sum_k k C(a, k) reads), far fewer when ``a - n`` is large (``coop_arms``, every j:
    14,785 against 58,212). Both are exact (maxima and minima of the same numbers).

    Returns ``set_children`` (R, K), the rows listed by each set (padded with -1), and ``fault_rows``
    (F, 2), for the f-th ``j`` the range of rows (OTIs included) holding the sets left after ``j``
    faults, in combination order.
    """
    if not fault_list:
        return np.zeros((0, 0), dtype=np.int64), np.zeros((0, 2), dtype=np.int64)
    largest = a - min(fault_list)
    table_cost = sum(comb(a, j) * comb(a - j, n) for j in fault_list)
    lattice_cost = sum(k * comb(a, k) for k in range(n + 1, largest + 1)) + sum(comb(a, j) for j in fault_list)
    index = {sub: row for row, sub in enumerate(submechanisms)}
    children, start = [], {}
    if lattice_cost < table_cost:
        start[n] = 0
        for size in range(n + 1, largest + 1):
            start[size] = len(index)
            for members in combinations(range(a), size):
                children.append([index[members[:k] + members[k + 1:]] for k in range(size)])
                index[members] = len(index)
        rows = [(start[a - j], start[a - j] + comb(a, a - j)) for j in fault_list]
    else:
        rows = []
        for j in fault_list:
            first = len(submechanisms) + len(children)
            children += [[index[sub] for sub in combinations(remaining, n)] for remaining in fault_sets(a, n, j)]
            rows.append((first, len(submechanisms) + len(children)))
    width = max((len(kids) for kids in children), default=0)
    set_children = np.full((len(children), width), -1, dtype=np.int64)
    for row, kids in enumerate(children):
        set_children[row, :len(kids)] = kids
    return set_children, np.array(rows, dtype=np.int64).reshape(-1, 2)


def remaining_lmti(plan, oti_submechanisms: NDArray) -> dict[int, NDArray]:
    """The LMTI (Eq. 11) of every actuator set left after ``j`` faults, (N, C(a, j)) for each ``j`` of the plan, in
    combination order of the sets left: the terms of Eq. 12, reduced from the submechanisms' OTIs (N, S) by the
    same rows as the kernel's (each set the maximum of the rows it lists, :func:`reductions`)."""
    rows = [oti_submechanisms[:, s] for s in range(oti_submechanisms.shape[-1])]
    for children in plan.set_children:
        rows.append(np.max([rows[child] for child in children if child >= 0], axis=0))
    stacked = np.stack(rows, axis=-1) if rows else np.zeros((oti_submechanisms.shape[0], 0))
    return {j: stacked[:, first:last] for j, (first, last) in zip(plan.faults, plan.fault_rows)}


def submechanisms_left(actuator_count: int, dof: int, faults: tuple[int, ...]) -> dict[int, NDArray[np.int64]]:
    """For each ``j``, the submechanisms (rows of the ``n``-combinations) in each set left after ``j`` faults."""
    position = {sub: s for s, sub in enumerate(combinations(range(actuator_count), dof))}
    return {j: np.array([[position[sub] for sub in combinations(remaining, dof)]
                         for remaining in combinations(range(actuator_count), actuator_count - j)], dtype=np.int64)
            for j in faults}
