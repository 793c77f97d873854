"""The compiled stages of :func:`screwkit.indices.analysis.analyze` on a chunk of configurations.

Importing this module loads :mod:`screwkit.indices.compiled.wrenches` and :mod:`screwkit.indices.compiled.outputs`
(numba: from its cache, or compiled; :func:`screwkit.common.compiling.prepare_kernels` compiles
them in parallel first); :mod:`screwkit.indices.compiled.null` and :mod:`screwkit.indices.compiled.gram` are
loaded (and compiled) only for a mechanism that needs them
(:func:`screwkit.common.compiling.stage_kernels`).
"""

from __future__ import annotations

import threading

import numpy as np

from screwkit.common import tolerances
from screwkit.common.compiling import GRAM_KERNEL, NULL_KERNEL, prepare_kernels, stage_kernels
from screwkit.indices.compiled.algebra import BLOCK, KERNEL_BATCH, carry_arrays
from screwkit.indices.compiled.outputs import output_kernel
from screwkit.indices.compiled.wrenches import wrench_kernel

__all__ = ["run_kernels"]

_carry = threading.local()  # each thread's carry arrays, kept between calls (no fresh pages per chunk)


def _carry_arrays(blocks: int, a: int, n: int) -> tuple[np.ndarray, ...]:
    """This thread's :func:`~screwkit.indices.compiled.algebra.carry_arrays` for ``blocks`` blocks of a and n,
    reused."""
    kept = getattr(_carry, "arrays", None)
    if kept is None or kept[0].shape[:2] != (blocks, a) or kept[1].shape[3] != n:
        kept = _carry.arrays = carry_arrays(blocks, a, n)
    return kept


def run_kernels(plan, twists, points, basis, complement, iti_override, oti_override, out: dict) -> None:
    """The kernels on a chunk, ``KERNEL_BATCH`` configurations at a time, into the arrays of ``out``.

    ``plan`` is the chunk's :class:`screwkit.indices.stages.Plan` (actuators, submechanisms, locked
    sets, reductions, threshold); arrays as :func:`screwkit.indices.stages.run_kernel` prepares them,
    ``iti_override`` and ``oti_override`` (N, a, 3) or None. The first stage hands the later ones
    its per-block results (:func:`~screwkit.indices.compiled.algebra.carry_arrays`) for one batch at a time (kept
    in cache), rather than for the whole chunk.
    """
    count = twists.shape[0]
    a, n = len(plan.actuators), plan.submechanisms.shape[1]
    empty = np.empty((0, a, 3))
    iti_override, oti_override = (empty if point is None else point for point in (iti_override, oti_override))
    carry = _carry_arrays(KERNEL_BATCH // BLOCK, a, n)
    stages = stage_kernels(np.diff(plan.chain_start)[plan.actuator_chain], n)
    prepare_kernels(stages)
    null_kernel = gram_kernel = None
    if NULL_KERNEL in stages:
        from screwkit.indices.compiled.null import null_kernel  # numba: compiled only for mechanisms that need it
    if GRAM_KERNEL in stages:
        from screwkit.indices.compiled.gram import gram_kernel  # idem
    for start in range(0, count, KERNEL_BATCH):
        part = slice(start, min(count, start + KERNEL_BATCH))
        own = {key: value[part] if len(value) else value for key, value in out.items()}
        basis_part = basis if len(basis) == 1 else basis[part]
        wrench_kernel(twists[part], points[part], plan.chain_start, plan.actuator_chain, plan.actuator_joint,
                      basis_part, complement, plan.threshold,
                      tolerances.OUTSIDE_CONSTANT_SPACE, tolerances.GRAM_PIVOT, tolerances.PSEUDO_INVERSE_CONSISTENCY,
                      own["outside"], *carry)
        if null_kernel is not None:
            null_kernel(points[part], plan.chain_start, plan.actuator_chain, basis_part, part.stop - part.start, *carry)
        if gram_kernel is not None:
            gram_kernel(twists[part], points[part], plan.chain_start, plan.actuator_chain, plan.actuator_joint, n,
                        tolerances.GRAM_PIVOT, tolerances.PSEUDO_INVERSE_CONSISTENCY, own["outside"], carry[0],
                        carry[3], carry[4], basis_part, tolerances.SINGULAR_SPAN)
        output_kernel(twists[part], points[part], plan.chain_start, plan.actuator_chain, plan.actuator_joint,
                      basis_part, plan.submechanisms, plan.locked_sets, plan.locked_of, plan.set_children,
                      plan.fault_rows, plan.locked_depth, plan.wedge_table, plan.wedge_start, plan.rank_tolerance,
                      tolerances.PURE_COUPLE, tolerances.WORST_FAULT_TIE,
                      iti_override[part] if len(iti_override) else empty,
                      oti_override[part] if len(oti_override) else empty, own["iti_actuators"],
                      own["oti_actuators"], own["oti_submechanisms"], own["summary"], own["worst"],
                      own["mutual_interference"], own["actuation_wrenches"], own["output_twists"], *carry)
