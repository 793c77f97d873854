r"""The paper's closed-form planar results, implemented independently of the generic path.

Everything here works with planar vectors (shape ``(..., 2)``) of a planar n-RRR (or
n-RPR) mechanism whose actuation wrenches are forces along the distal links:

* ``f_i = (d_i - c_i)/l_i`` (Eq. 18) and ``g_i = (c_i - b_i)/a_i`` (Eq. 19);
* the ITI of a chain, :math:`|\det[g_i\ f_i]|` (Eq. 23);
* the instantaneous centre of chain ``k``'s output twist (Eq. 30) and its OTI through it
  (Eqs. 31-33), or equivalently Eq. (A2) and its IC-free form (A4), with the parallel
  special cases (A5) and (A6);
* the OTI of a 3-chain submechanism (Eq. 34) and the ITI, LMTI and output fault tolerance
  of the whole mechanism (Eqs. 35-38 and, for any number of faults, Eq. 12).

Notation: :math:`|x\ y| = \det[x\ y] = x_1 y_2 - x_2 y_1`. Only numpy is imported here.
"""

from __future__ import annotations

from itertools import combinations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.common.chunks import map_chunks
from screwkit.common.compiling import announce_compilation
from screwkit.common.tolerances import RANK_TOLERANCE, SINGULARITY_THRESHOLD, WORST_FAULT_TIE
from screwkit.common.validation import as_float_array, check_finite
from screwkit.indices.stages import checked_chunk_size, checked_faults, checked_rank_tolerance, checked_threshold

__all__ = [
    "det2",
    "distal_directions",
    "iti_rrr",
    "instantaneous_centre",
    "oti_chain_ic",
    "oti_chain_a2",
    "oti_chain_a4",
    "oti_chain_a5",
    "oti_chain_a6",
    "oti_triple",
    "planar_indices",
    "point_indices",
]


def det2(first: ArrayLike, second: ArrayLike) -> NDArray[np.float64]:
    r""":math:`|x\ y| = x_1 y_2 - x_2 y_1` for planar vectors (..., 2)."""
    first = np.asarray(first, dtype=float)
    second = np.asarray(second, dtype=float)
    return first[..., 0] * second[..., 1] - first[..., 1] * second[..., 0]


def distal_directions(elbows: ArrayLike, distal: ArrayLike) -> NDArray[np.float64]:
    """Unit vectors ``f_i = (d_i - c_i)/|d_i - c_i|`` (Eq. 18), shape (..., 2)."""
    vector = np.asarray(distal, dtype=float) - np.asarray(elbows, dtype=float)
    return vector / np.linalg.norm(vector, axis=-1, keepdims=True)


def iti_rrr(base: ArrayLike, elbows: ArrayLike, distal: ArrayLike) -> NDArray[np.float64]:
    r"""ITI of RRR chains, :math:`ITI_i = \sin\beta_i = |\det[g_i\ f_i]|` (Eq. 23)."""
    upper = np.asarray(elbows, dtype=float) - np.asarray(base, dtype=float)
    upper = upper / np.linalg.norm(upper, axis=-1, keepdims=True)
    return np.abs(det2(upper, distal_directions(elbows, distal)))


def instantaneous_centre(f_l, d_l, f_m, d_m) -> NDArray[np.float64]:
    r"""Instantaneous centre of chain ``k``'s output twist (Eq. 30).

    .. math:: r_{IC,k} = \frac{1}{|f_l\ f_m|} [f_m\ \ -f_l]
              \begin{bmatrix} |f_l\ d_l| \\ |f_m\ d_m| \end{bmatrix}

    ``inf``/``nan`` where the lines of chains ``l`` and ``m`` are parallel.
    """
    f_l, d_l, f_m, d_m = (np.asarray(v, dtype=float) for v in (f_l, d_l, f_m, d_m))
    with np.errstate(divide="ignore", invalid="ignore"):
        return (f_m * det2(f_l, d_l)[..., None] - f_l * det2(f_m, d_m)[..., None]) / det2(f_l, f_m)[..., None]


def oti_chain_ic(f_k, d_k, f_l, d_l, f_m, d_m, threshold: float = SINGULARITY_THRESHOLD) -> NDArray[np.float64]:
    r"""OTI of chain ``k`` through the instantaneous centre (Eqs. 30-33).

    :math:`OTI_k = \sin\alpha_k = |\det[\rho_{k\max}/\rho_{k\max}\ \ f_k]|` with
    :math:`\rho_{k\max} = d_k - r_{IC,k}`; zero when :math:`\rho_{k\max}` is below
    ``threshold``. Only valid where ``f_l`` and ``f_m`` are not parallel (use A4 there).
    """
    centre = instantaneous_centre(f_l, d_l, f_m, d_m)
    arm = np.asarray(d_k, dtype=float) - centre
    length = np.linalg.norm(arm, axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        value = np.abs(det2(arm, f_k)) / length
    return np.where(length < threshold, 0.0, value)


def _numerator(f_k, d_k, f_l, d_l, f_m, d_m):
    """|f_k d_k||f_l f_m| + |f_l d_l||f_m f_k| + |f_m d_m||f_k f_l| (A2), the same for every k."""
    return (det2(f_k, d_k) * det2(f_l, f_m) + det2(f_l, d_l) * det2(f_m, f_k)
            + det2(f_m, d_m) * det2(f_k, f_l))


def oti_chain_a2(f_k, d_k, f_l, d_l, f_m, d_m, threshold: float = SINGULARITY_THRESHOLD) -> NDArray[np.float64]:
    r"""OTI of chain ``k`` by Eq. (A2): the A3-shared numerator over :math:`|f_l\ f_m|\,\rho_{k\max}`."""
    centre = instantaneous_centre(f_l, d_l, f_m, d_m)
    arm = np.linalg.norm(np.asarray(d_k, dtype=float) - centre, axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        value = np.abs(_numerator(f_k, d_k, f_l, d_l, f_m, d_m)) / (np.abs(det2(f_l, f_m)) * arm)
    return np.where(arm < threshold, 0.0, value)


def oti_chain_a4(f_k, d_k, f_l, d_l, f_m, d_m, threshold: float = SINGULARITY_THRESHOLD) -> NDArray[np.float64]:
    r"""OTI of chain ``k`` by Eq. (A4), free of the IC and valid for parallel ``f_l, f_m``.

    .. math:: OTI_k = \frac{\left| |f_k\,d_k||f_l\,f_m| + |f_l\,d_l||f_m\,f_k| + |f_m\,d_m||f_k\,f_l| \right|}
              {\left\| |f_l\,f_m|\, d_k - [f_m\ -f_l]\begin{bmatrix}|f_l\,d_l|\\|f_m\,d_m|\end{bmatrix}\right\|}

    The denominator is :math:`|f_l\,f_m|\,\rho_{k\max}`; the value is zero when
    :math:`\rho_{k\max} < p`, i.e. when the denominator is below ``threshold`` times
    :math:`|f_l\ f_m|` (which includes the collinear case 0/0).

    The extracted text of (A4) shows :math:`|f_l\ d_k|` in the second numerator term; the
    cyclic form of (A2), used here, is the correct one (the symbolic tests prove it equals
    the generic derivation; the literal reading does not).
    """
    f_k, d_k, f_l, d_l, f_m, d_m = (np.asarray(v, dtype=float) for v in (f_k, d_k, f_l, d_l, f_m, d_m))
    cross_lm = det2(f_l, f_m)
    vector = cross_lm[..., None] * d_k - (f_m * det2(f_l, d_l)[..., None] - f_l * det2(f_m, d_m)[..., None])
    denominator = np.linalg.norm(vector, axis=-1)
    singular = denominator <= threshold * np.abs(cross_lm)
    with np.errstate(divide="ignore", invalid="ignore"):
        value = np.abs(_numerator(f_k, d_k, f_l, d_l, f_m, d_m)) / np.where(singular, 1.0, denominator)
    return np.where(singular, 0.0, np.minimum(value, 1.0))


def oti_chain_a5(f_k, d_k, f_l, d_l, f_m, d_m) -> NDArray[np.float64]:
    r"""OTI of chain ``k`` when ``f_l`` and ``f_m`` are parallel (Eq. A5).

    .. math:: OTI_k = \frac{\left||f_l\,d_l||f_m\,f_k| + |f_m\,d_m||f_k\,f_l|\right|}
              {\left\|[f_m\ -f_l]\begin{bmatrix}|f_l\,d_l|\\|f_m\,d_m|\end{bmatrix}\right\|}

    (the extraction garbled the denominator; this is A4 with :math:`|f_l\,f_m| = 0`).
    Zero (0/0) when the two lines are collinear.
    """
    f_k, d_k, f_l, d_l, f_m, d_m = (np.asarray(v, dtype=float) for v in (f_k, d_k, f_l, d_l, f_m, d_m))
    numerator = det2(f_l, d_l) * det2(f_m, f_k) + det2(f_m, d_m) * det2(f_k, f_l)
    denominator = np.linalg.norm(f_m * det2(f_l, d_l)[..., None] - f_l * det2(f_m, d_m)[..., None], axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(denominator > 0, np.abs(numerator) / np.where(denominator > 0, denominator, 1.0), 0.0)


def oti_chain_a6(f_k, f_l) -> NDArray[np.float64]:
    r"""OTI of chain ``k`` when ``f_m = f_l`` (parallel, not collinear): :math:`|\det[f_l\ f_k]|` (Eq. A6)."""
    return np.abs(det2(f_l, f_k))


def oti_triple(f, d, threshold: float = SINGULARITY_THRESHOLD) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    r"""OTI of each chain of a 3-chain submechanism and their minimum (Eqs. 25, 34).

    Parameters
    ----------
    f, d : array_like, shape (..., 3, 2)
        Distal-link directions and platform joint points of chains ``k, l, m``.

    Returns
    -------
    per_chain : ndarray, shape (..., 3)
    submechanism : ndarray, shape (...)
    """
    f = np.asarray(f, dtype=float)
    d = np.asarray(d, dtype=float)
    per_chain = np.stack([
        oti_chain_a4(f[..., k, :], d[..., k, :], f[..., l, :], d[..., l, :], f[..., m, :], d[..., m, :], threshold)
        for k, l, m in ((0, 1, 2), (1, 2, 0), (2, 0, 1))
    ], axis=-1)
    return per_chain, per_chain.min(axis=-1)


def _planar_chunk(base, elbows, distal, directions, threshold, triples, fault_members, rank_tolerance, without):
    """Closed-form indices of one chunk (batch-first (n, k, 2) arrays) through the compiled kernel."""
    announce_compilation("screwkit.indices.compiled.planar")
    from screwkit.indices.compiled.planar import planar_closed_form_kernel  # numba: when first run

    count, chains = distal.shape[:2]
    iti_chains = np.empty((count, chains))
    oti_subs = np.empty((count, len(triples)))
    independent = np.empty((count, len(triples)), dtype=bool)
    empty = np.empty((0, chains, 2))
    planar_closed_form_kernel(empty if base is None else base, empty if elbows is None else elbows, distal,
                              empty if directions is None else directions, np.array(triples, dtype=np.int64),
                              float(threshold), float(rank_tolerance), iti_chains, oti_subs, independent)
    iti = iti_chains.min(axis=1)
    f_o, worst, remaining = {}, {}, {}
    for j, members in fault_members.items():
        remaining[j] = oti_subs[:, members].max(axis=2)  # Eq. 38 for every set left after j faults
        f_o[j] = remaining[j].min(axis=1)  # Eq. 37
        worst[j] = np.argmax(remaining[j] <= f_o[j][:, None] + WORST_FAULT_TIE, axis=1)  # the first worst set
    mutual = np.stack([independent[:, subs].any(axis=1) for subs in without], axis=1)
    return iti_chains, iti, oti_subs, f_o, worst, mutual, remaining


def _planar_inputs(base, elbows, distal, directions):
    """:func:`planar_indices`' points and directions checked (finite, shapes (..., k, 2) like ``distal``'s, unit
    directions from nonzero ones): ``(distal, batch shape, k, base, elbows, directions)``, the unused ones None."""
    distal = check_finite(as_float_array(distal, "distal"), "distal")
    if distal.ndim < 2 or distal.shape[-1] != 2 or distal.shape[-2] < 3:
        raise ValueError(f"Expected `distal` with shape (..., k, 2), k >= 3, got {distal.shape}.")

    def like_distal(value, name):
        array = check_finite(as_float_array(value, name), name)
        try:
            return np.broadcast_to(array, distal.shape)
        except ValueError:
            raise ValueError(f"Expected `{name}` with the shape of `distal`, {distal.shape}, got {array.shape}.") \
                from None

    if directions is not None:
        directions = like_distal(directions, "directions")
        length = np.linalg.norm(directions, axis=-1, keepdims=True)
        if not np.all(length > 0):
            where = tuple(int(i) for i in np.argwhere(length[..., 0] == 0)[0])
            raise ValueError(f"Expected nonzero leg `directions`, got a zero vector at index {where}.")
        return distal, distal.shape[:-2], distal.shape[-2], None, None, directions / length
    if elbows is None:
        raise ValueError("Expected `elbows` or `directions`, got neither.")
    if base is None:
        raise ValueError("Expected `base` with `elbows` (RRR chains), got None.")
    return distal, distal.shape[:-2], distal.shape[-2], like_distal(base, "base"), like_distal(elbows, "elbows"), None


def planar_indices(base: ArrayLike, elbows: ArrayLike | None, distal: ArrayLike,
                   threshold: float = SINGULARITY_THRESHOLD, faults: int | tuple[int, ...] | None = None,
                   directions: ArrayLike | None = None,
                   chunk_size: int = 65536, threads: int | None = None, rank_tolerance: float = RANK_TOLERANCE) -> dict:
    r"""ITI, LMTI, F_Oj and F_IOj of a planar mechanism from its closed forms (Eqs. 35-38, 12, 14).

    Every 3-subset of the ``k`` chains is a non-redundant submechanism; its OTI is Eq. (34)
    with the chain OTIs of Eq. (A4). :math:`ITI = \min_i |\det[g_i\ f_i]|` (Eq. 35),
    :math:`LMTI = \max OTI_{N_i}` (Eq. 36), :math:`F_{Oj} = \min_{E} LMTI_E` over the
    ``(k - j)``-subsets (Eqs. 37-38 for ``j = 1``), :math:`F_{IOj} = \min(F_{Oj}, ITI)`.

    Parameters
    ----------
    base, elbows, distal : array_like, shape (..., k, 2)
        Points ``b_i, c_i, d_i`` (finite; ``base`` and ``elbows`` broadcast to the shape of ``distal``).
        ``elbows`` may be None for RPR chains: then ``directions`` (the leg directions) must be given
        and the ITI is 1 (prismatic input along its own force). An empty batch gives empty arrays.
    threshold : float
        Singularity threshold *p* on :math:`\rho_{k\max}` (finite, >= 0).
    faults : int or tuple of int, optional
        Which ``j`` (default ``1..k-3``).
    directions : array_like, shape (..., k, 2), optional
        The distal-link directions ``f_i`` (computed from ``elbows`` if omitted), normalised here: only
        their direction counts (a zero vector is refused). ``base`` and ``elbows`` are then not used.
    chunk_size : int
        Configurations per chunk (bounds memory).
    threads : int, optional
        Threads working on chunks side by side (default: the number of CPUs); the compiled
        kernel (:func:`screwkit.indices.compiled.planar.planar_closed_form_kernel`) releases the GIL.

    rank_tolerance : float
        Relative tolerance of dependent wrenches (see the kernel).

    Returns
    -------
    dict
        ``iti_chains`` (..., k), ``iti``, ``oti_submechanisms`` (..., C(k,3)), ``lmti``,
        ``f_o`` and ``f_io`` (dicts over j), ``worst_faults`` (dict over j of (..., j) failed
        chains of the first worst set, within :data:`screwkit.common.tolerances.WORST_FAULT_TIE`),
        ``mutual_interference``
        (..., k) (some 3 of the other chains have independent wrenches), ``submechanisms``
        (tuple of triples), ``remaining_lmti`` (dict over j of (..., C(k, j)): the LMTI of every set left after j
        faults, Eq. 38, in combination order).
    """
    distal, batch, count, base, elbows, directions = _planar_inputs(base, elbows, distal, directions)
    threshold = checked_threshold(threshold)
    checked_rank_tolerance(rank_tolerance)
    checked_chunk_size(chunk_size)
    faults = checked_faults(faults, count - 3)
    faults = tuple(range(1, count - 2)) if faults is None else faults
    if count == 3:
        faults = ()  # no redundancy: F_O1 = 0 below
    triples = tuple(combinations(range(count), 3))
    index = {triple: s for s, triple in enumerate(triples)}
    fault_members = {j: np.array([[index[t] for t in combinations(remaining, 3)]
                                  for remaining in combinations(range(count), count - j)]) for j in faults}
    failed_sets = {j: np.array([sorted(set(range(count)) - set(remaining))
                                for remaining in combinations(range(count), count - j)], dtype=np.int64).reshape(-1, j)
                   for j in faults}
    without = [np.array([s for s, triple in enumerate(triples) if k not in triple], dtype=np.int64)
               for k in range(count)]
    total = int(np.prod(batch, dtype=np.int64))
    def flat(array):
        return None if array is None else array.reshape(total, count, 2)

    sources = [flat(base), flat(elbows), flat(distal), flat(directions)] if directions is None else \
        [None, None, flat(distal), flat(directions)]

    def run(part):  # views where possible: the kernel reads any memory layout (but writable arrays)
        chunk = [None if a is None else a[part] if a.flags.writeable else np.ascontiguousarray(a[part])
                 for a in sources]
        return _planar_chunk(*chunk, threshold, triples, fault_members, rank_tolerance, without)

    # an empty batch: one empty piece (no chunk), so that every array has its shape (0, ...)
    pieces = map_chunks(run, total, chunk_size, threads) or [(
        np.empty((0, count)), np.empty(0), np.empty((0, len(triples))), {j: np.empty(0) for j in faults},
        {j: np.empty(0, dtype=np.int64) for j in faults}, np.empty((0, count), dtype=bool),
        {j: np.empty((0, len(members))) for j, members in fault_members.items()})]

    def gather(arrays):  # chunk pieces (n, ...) -> (..., ...)
        joined = np.concatenate(arrays, axis=0)
        return joined.reshape(batch + joined.shape[1:])

    iti_chains = gather([p[0] for p in pieces])
    iti = gather([p[1] for p in pieces])
    oti_subs = gather([p[2] for p in pieces])
    f_o = {j: gather([p[3][j] for p in pieces]) for j in faults}
    worst = {j: failed_sets[j][gather([p[4][j] for p in pieces])] for j in faults}
    remaining = {j: gather([p[6][j] for p in pieces]) for j in faults}
    if count == 3 and not faults:  # no redundancy: one failed actuator leaves the platform uncontrolled
        f_o, worst, faults = {1: np.zeros(batch)}, {1: np.zeros(batch + (1,), dtype=np.int64)}, (1,)
        remaining = {1: np.zeros(batch + (count,))}
    return {"iti_chains": iti_chains, "iti": iti, "oti_submechanisms": oti_subs, "lmti": oti_subs.max(axis=-1),
            "f_o": f_o, "f_io": {j: np.minimum(f_o[j], iti) for j in faults}, "worst_faults": worst,
            "mutual_interference": gather([p[5] for p in pieces]), "submechanisms": triples,
            "remaining_lmti": remaining}


def point_indices(base: ArrayLike, elbows: ArrayLike, distal: ArrayLike, faults: tuple[int, ...] | None = None,
                  rank_tolerance: float = RANK_TOLERANCE) -> dict:
    r"""The textbook pressure angles of planar R-R-R legs meeting at one output point (a five-bar and its
    redundant variants): 2 DOF, the point's rotations idle.

    The actuation wrench of leg ``i`` is the force along its distal link ``f_i`` through the point (Eq. 21),
    its input twist the base joint's rotation, so :math:`ITI_i = |\det[g_i\ f_i]|` (Eq. 23). With leg ``l``
    locked, the point moves perpendicular to ``f_l``: the output twist of leg ``k`` in the pair ``(k, l)`` is that
    translation and :math:`OTI_k = |\det[f_k\ f_l]|`, the same for both legs (the pressure angle between the
    distal links); zero when the two are parallel (within ``rank_tolerance``). Then LMTI, F_Oj, F_IOj as
    Eqs. 11-14 over pairs. Numpy only, vectorised over configurations (..., k, 2).

    Returns
    -------
    dict
        ``iti_chains`` (..., k), ``iti``, ``oti_submechanisms`` (..., C(k, 2)), ``lmti``, ``f_o``, ``f_io`` and
        ``remaining_lmti`` (dicts over j), ``worst_faults`` (dict over j of (..., j), the first worst set),
        ``mutual_interference`` (..., k), ``submechanisms`` (pairs).
    """
    base, elbows, distal = (np.asarray(value, dtype=float) for value in (base, elbows, distal))
    count = distal.shape[-2]
    upper = elbows - base
    upper = upper / np.linalg.norm(upper, axis=-1, keepdims=True)
    forces = distal_directions(elbows, distal)
    iti_chains = np.abs(det2(upper, forces))
    pairs = tuple(combinations(range(count), 2))
    oti = np.stack([np.abs(det2(forces[..., k, :], forces[..., l, :])) for k, l in pairs], axis=-1)
    oti = np.where(oti > rank_tolerance, oti, 0.0)
    faults = checked_faults(faults, count - 2)
    faults = tuple(range(1, count - 1)) if faults is None else faults
    if count == 2:
        faults = ()  # no redundancy: F_O1 = 0 below
    f_o, worst, remaining = {}, {}, {}
    for j in faults:
        left = list(combinations(range(count), count - j))
        remaining[j] = np.stack([oti[..., [p for p, pair in enumerate(pairs) if set(pair) <= set(e)]].max(axis=-1)
                                 for e in left], axis=-1)
        f_o[j] = remaining[j].min(axis=-1)
        first = np.argmax(remaining[j] <= f_o[j][..., None] + WORST_FAULT_TIE, axis=-1)
        failed = np.array([sorted(set(range(count)) - set(e)) for e in left], dtype=np.int64).reshape(-1, j)
        worst[j] = failed[first]
    if count == 2 and not faults:  # no redundancy: one failed actuator leaves the point uncontrolled
        faults = (1,)
        f_o, worst = {1: np.zeros(oti.shape[:-1])}, {1: np.zeros(oti.shape[:-1] + (1,), dtype=np.int64)}
        remaining = {1: np.zeros(oti.shape[:-1] + (2,))}
    mutual = np.stack([(oti[..., [p for p, pair in enumerate(pairs) if k not in pair]] > 0).any(axis=-1)
                       if count > 2 else np.zeros(oti.shape[:-1], dtype=bool) for k in range(count)], axis=-1)
    iti = iti_chains.min(axis=-1)
    return {"iti_chains": iti_chains, "iti": iti, "oti_submechanisms": oti, "lmti": oti.max(axis=-1), "f_o": f_o,
            "f_io": {j: np.minimum(f_o[j], iti) for j in faults}, "worst_faults": worst, "remaining_lmti": remaining,
            "mutual_interference": mutual, "submechanisms": pairs}
