"""The one result type of screwkit: every index of a mechanism at a batch of configurations.

:class:`Indices` is what :func:`screwkit.indices.analysis.analyze` returns for chain screws and
what :func:`screwkit.studies.indices_at_poses` returns for platform poses; sweeps, maps, the
command line and the viewer are built on it. One configuration is a batch of shape ``()``:
its scalar fields are then plain Python floats. Actuators are named ``chain:joint``
everywhere; worst faults are given by name.

Only numpy is imported here (xarray when :meth:`Indices.to_dataset` is called).
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields, replace
from itertools import combinations
from typing import Any, Iterable, Mapping, Sequence

import numpy as np
from numpy.typing import NDArray

from screwkit.indices.exports import indices_to_dataset, indices_to_dict, set_label, worst_fault_ties
from screwkit.indices.registry import INDICES, applies

__all__ = ["Indices", "set_label", "with_derived", "PER_CONFIGURATION", "PER_CONFIGURATION_DICTS"]

PER_CONFIGURATION = ("iti", "lmti", "mutual_interference", "iti_actuators", "oti_actuators", "oti_submechanisms",
                     "actuation_wrenches", "output_twists", "poses", "reachable", "chain_status", "full_poses",
                     "cti", "cti_submechanisms", "instantaneous_dof", "constraint_singular")
"""Fields of :class:`Indices` with one entry per configuration (leading batch axes)."""
PER_CONFIGURATION_DICTS = ("f_o", "f_io", "worst_fault_indices", "f_c", "remaining_lmti", "joint_values", "derived")
"""Fields of :class:`Indices` that map ``j`` to one entry per configuration."""
REQUIRED = ("iti", "lmti", "f_o", "worst_fault_indices", "mutual_interference")
"""The per-configuration fields :meth:`Indices.from_arrays` cannot do without."""


def _scalar_or_array(value):
    """A 0-d array (or numpy scalar) as a Python float; arrays unchanged."""
    array = np.asarray(value)
    return float(array) if array.ndim == 0 else array


@dataclass(frozen=True, repr=False, eq=False)
class Indices:
    """Every index of the paper at a batch of configurations (leading shape :attr:`batch_shape`).

    Where a pose is unreachable (:attr:`reachable` False) every index is NaN, every worst
    fault is ``""`` and no actuator is flagged as mutual-interference.

    Attributes
    ----------
    actuators : tuple of str
        The set A: every actuator as ``"chain:joint"``, in order.
    dof : int
        Degrees of freedom ``n`` of the platform.
    submechanisms : tuple of tuple of int
        The non-redundant ``n``-subsets ``N_i`` of actuators (Eq. 10), as indices into
        :attr:`actuators`, in combination order.
    iti : float or ndarray (...)
        ITI of the mechanism, the lowest of its actuators (Eq. 7).
    lmti : float or ndarray (...)
        LMTI of the whole actuator set (Eq. 11).
    f_o : dict of int to float or ndarray (...)
        Output fault-tolerance index ``F_Oj`` (Eq. 12) for every computed number of faults ``j``.
    f_io : dict of int to float or ndarray (...)
        Input-output fault-tolerance index ``F_IOj = min(F_Oj, ITI)`` (Eq. 14).
    worst_fault_indices : dict of int to ndarray (..., j) of int
        For each ``j``, the failed actuators of the worst case (the complement of the first
        set ``E_i`` attaining ``F_Oj``), as indices into :attr:`actuators`; -1 where unreachable.
        :attr:`worst_faults` gives them by name.
    mutual_interference : ndarray (..., a) of bool
        Whether each actuator is a mutual-interference actuator: with it free and all the
        others locked, the platform is still fully constrained. If one is not, every
        ``F_Oj`` is zero.
    threshold : float
        The singularity threshold *p* (m) the indices were computed with.
    iti_actuators : ndarray (..., a) or None
        ITI of every actuator (Eq. 6); None unless computed with ``detail``.
    oti_actuators : ndarray (..., S, n) or None
        ``OTI_k`` of each actuator of each submechanism (Eq. 8).
    oti_submechanisms : ndarray (..., S) or None
        OTI of every submechanism (Eq. 9).
    actuation_wrenches : ndarray (..., a, 6) or None
        Unit actuation wrenches ``(f, m)`` in the world frame.
    output_twists : ndarray (..., S, n, 6) or None
        Output twists ``(omega, v)`` of each actuator of each submechanism, world frame: their screw axes, signed so
        that the actuator's wrench does positive work on its twist (the motion when it drives and the others
        hold); their size is that of adjugate columns, not meaningful.
    poses : ndarray (..., n_task) or None
        The platform poses (m, rad), when the indices were computed from poses.
    reachable : ndarray (...) of bool
        Whether every chain closed at each configuration.
    task_coordinates : tuple of str
        Names of the pose coordinates (empty when computed from screws).
    mechanism : str
        The mechanism's name (empty when computed from screws).
    chain_status : ndarray (..., n_chains) of int8 or None
        Why a pose is unreachable, chain by chain: 0 closed, 1 misses its closure, 2 a joint
        outside its position limits (``screwkit.closure.Solution.status``); None from screws.
    full_poses : ndarray (..., n_pose) or None
        The poses in every pose coordinate, dependent (parasitic) ones included.
    pose_coordinates : tuple of str
        Names of the full poses' coordinates.
    cti : float or ndarray (...) or None
        Constraint transmission index (:mod:`screwkit.screw.constraints`): the best non-redundant
        actuator set's; NaN where no constraint wrench applies, None when not computed.
    f_c : dict of int to float or ndarray (...)
        Its fault-tolerant counterpart over ``j`` faults (screwkit's extension).
    cti_submechanisms : ndarray (..., S) or None
        CTI of every non-redundant actuator set.
    constraint_count : int
        Constraint wrenches the CTI releases (0: the CTI does not apply).
    instantaneous_dof : ndarray (...) of int or None
        The platform's DOF at each configuration; above :attr:`dof` at a constraint singularity.
    constraint_singular : ndarray (...) of bool or None
        Whether each configuration is a constraint singularity.
    fault_type : str
        ``"free-swinging"`` (failed actuators become passive joints, the paper's FSJF) or
        ``"link"`` (their chains disappear with their constraint wrenches, the paper's LF).
    remaining_lmti : dict of int to ndarray (..., C(a, j))
        The LMTI of every set left after ``j`` faults (Eq. 12's terms, :meth:`failed_sets` order); with detail.
    joint_values, prismatic_joints : dict of str to float, tuple of str
        Every joint's value (rad, m) by ``chain:joint`` (:func:`~screwkit.studies.indices_at_pose`), and which are m.
    working_mode : dict of str to str
        Per chain, the working mode (branch) its closure follows, in words.
    cti_reason, derived : str, dict of str to float or ndarray (...)
        Why the CTI does not apply; the registered derived indices (:mod:`screwkit.indices.registry`) by column.
    """

    actuators: tuple[str, ...]
    dof: int
    submechanisms: tuple[tuple[int, ...], ...]
    iti: Any
    lmti: Any
    f_o: dict[int, Any]
    f_io: dict[int, Any]
    worst_fault_indices: dict[int, NDArray[np.int64]]
    mutual_interference: NDArray[np.bool_]
    threshold: float
    iti_actuators: NDArray[np.float64] | None = None
    oti_actuators: NDArray[np.float64] | None = None
    oti_submechanisms: NDArray[np.float64] | None = None
    actuation_wrenches: NDArray[np.float64] | None = None
    output_twists: NDArray[np.float64] | None = None
    poses: NDArray[np.float64] | None = None
    reachable: Any = None
    task_coordinates: tuple[str, ...] = ()
    mechanism: str = ""
    chain_status: NDArray[np.int8] | None = None
    full_poses: NDArray[np.float64] | None = None
    pose_coordinates: tuple[str, ...] = ()
    cti: Any = None
    f_c: dict[int, Any] = field(default_factory=dict)
    cti_submechanisms: NDArray[np.float64] | None = None
    constraint_count: int = 0
    instantaneous_dof: Any = None
    constraint_singular: Any = None
    fault_type: str = "free-swinging"
    remaining_lmti: dict[int, NDArray[np.float64]] = field(default_factory=dict)
    joint_values: dict[str, Any] = field(default_factory=dict)
    prismatic_joints: tuple[str, ...] = ()
    working_mode: dict[str, str] = field(default_factory=dict)
    cti_reason: str = ""
    derived: dict[str, Any] = field(default_factory=dict)
    batch_shape: tuple[int, ...] = field(init=False)

    def __post_init__(self):
        _normalise(self)

    @classmethod
    def from_arrays(cls, actuators: Sequence[str], dof: int, arrays: Mapping[str, Any], *, threshold: float,
                    submechanisms: Sequence[Sequence[int]] | None = None, derive: bool = True,
                    **about: Any) -> Indices:
        """The constructor: the per-configuration ``arrays`` by field name (:data:`PER_CONFIGURATION` and
        :data:`PER_CONFIGURATION_DICTS`; ``iti``, ``lmti``, ``f_o``, ``worst_fault_indices`` and
        ``mutual_interference`` are required) and the fields that describe them (``about``: ``mechanism``,
        ``task_coordinates``, ``fault_type``...).

        ``f_io`` is Eq. 14 (``min(F_Oj, ITI)``) unless given; ``submechanisms`` are every ``n``-subset of the
        actuators unless given; every registered derived index is computed unless ``derive`` is False. Every
        array's leading shape is checked against ``iti``'s, and a name that is not a field is refused.
        """
        values = _checked_arrays(arrays, about, {f.name for f in fields(cls) if f.init})
        if submechanisms is None:
            submechanisms = combinations(range(len(actuators)), dof)
        result = cls(actuators=tuple(actuators), dof=int(dof),
                     submechanisms=tuple(tuple(int(i) for i in members) for members in submechanisms),
                     threshold=threshold, **values, **about)
        return with_derived(result) if derive else result

    # -- derived views ------------------------------------------------------------------

    @property
    def actuator_count(self) -> int:
        """Number of actuators ``a``."""
        return len(self.actuators)

    @property
    def faults(self) -> tuple[int, ...]:
        """The numbers of faults ``j`` computed, ascending."""
        return tuple(sorted(self.f_o))

    @property
    def worst_faults(self) -> dict[int, Any]:
        """For each ``j``, the worst-case failed actuators by name.

        A tuple of names for one configuration; for a batch an array of strings (..., j),
        ``""`` where unreachable.
        """
        names = np.asarray(self.actuators + ("",))
        result = {}
        for j, indices in self.worst_fault_indices.items():
            chosen = names[np.where(indices < 0, len(self.actuators), indices)]
            result[j] = tuple(str(name) for name in chosen) if chosen.ndim == 1 and not self.batch_shape else chosen
        return result

    @property
    def not_mutual_interference(self) -> Any:
        """Names of the actuators that are not mutual-interference actuators (one configuration),
        or a mask (..., a) for a batch."""
        if self.batch_shape:
            return ~self.mutual_interference & np.asarray(self.reachable)[..., None]
        if not self.reachable:
            return ()
        return tuple(name for name, ok in zip(self.actuators, self.mutual_interference) if not ok)

    def actuator_index(self, actuator: int | str) -> int:
        """Index into :attr:`actuators` of an actuator given by index, ``chain:joint`` name,
        joint name or chain name (the chain's only actuator)."""
        if isinstance(actuator, (bool, np.bool_)):
            raise TypeError(f"Expected an actuator as an index or a name, got {actuator!r}.")
        if isinstance(actuator, (int, np.integer)):
            if not 0 <= actuator < self.actuator_count:
                raise ValueError(f"Expected an actuator index in 0..{self.actuator_count - 1}, got {actuator}.")
            return int(actuator)
        name = str(actuator)
        if name in self.actuators:
            return self.actuators.index(name)
        by_joint = [i for i, full in enumerate(self.actuators) if full.split(":", 1)[1] == name]
        by_chain = [i for i, full in enumerate(self.actuators) if full.split(":", 1)[0] == name]
        for found in (by_joint, by_chain):
            if len(found) == 1:
                return found[0]
        raise ValueError(f"Unknown actuator {name!r}; the actuators are {', '.join(self.actuators)}.")

    def at(self, index: int | tuple) -> Indices:
        """The indices of one configuration of the batch (its scalar fields become Python floats); with a tuple of
        integer arrays (numpy indexing, one per batch dimension), of those configurations, as a batch."""
        index = _checked_index(index, self.batch_shape)

        def pick(value):
            return None if value is None else np.asarray(value)[index]

        changes = {name: pick(getattr(self, name)) for name in PER_CONFIGURATION}
        changes.update({name: {j: pick(v) for j, v in getattr(self, name).items()} for name in PER_CONFIGURATION_DICTS})
        return replace(self, **changes)

    def lmti_of(self, actuator_set: Sequence[int | str]) -> Any:
        """LMTI of a set of actuators (Eq. 11): the best OTI of its ``n``-subsets.

        ``actuator_set``: actuators by index into :attr:`actuators` or by name. Zero for a set of fewer than ``n``
        actuators: they cannot hold the platform (no submechanism, as the paper's LMTI of a mechanism that is not
        fully constrained). A float for one configuration, an array (...) for a batch.
        """
        _check_actuator_set(actuator_set)
        if self.oti_submechanisms is None:
            raise ValueError("These indices were computed without detail; recompute with detail=True for lmti_of.")
        chosen = sorted({self.actuator_index(actuator) for actuator in actuator_set})
        members = [s for s, sub in enumerate(self.submechanisms) if set(sub) <= set(chosen)]
        if not members:
            return _scalar_or_array(np.where(np.asarray(self.reachable), 0.0, np.nan))
        return _scalar_or_array(self.oti_submechanisms[..., members].max(axis=-1))

    def index(self, name: str) -> Any:
        """The values of a registered index (:mod:`screwkit.indices.registry`): per configuration, or a dict by
        ``j`` for a per-fault index."""
        record = INDICES.get(name)
        if record is None:
            raise ValueError(f"Unknown index {name!r}; the indices are {', '.join(INDICES)}.")
        if record.compute is None:  # the compiled kernels' indices are fields
            return getattr(self, name)
        missing = [column for column in ([record.column(j) for j in self.faults] if record.per_fault else [name])
                   if column not in self.derived]
        if missing:
            raise ValueError(f"These indices have no {name!r}: it was registered after they were computed.")
        if record.per_fault:
            return {j: self.derived[record.column(j)] for j in self.faults}
        return self.derived[name]

    def failed_sets(self, faults: int) -> tuple[tuple[int, ...], ...]:
        """The failed actuators (indices) of each set left after ``faults`` faults (an int in ``1..a``), in the
        combination order of the sets left (that of :attr:`remaining_lmti`)."""
        a = self.actuator_count
        if isinstance(faults, (bool, np.bool_)) or not isinstance(faults, (int, np.integer)) or not 1 <= faults <= a:
            raise ValueError(f"Expected `faults` as an int j in 1..a = 1..{a} (a number of failed actuators), "
                             f"got {faults!r}.")
        return tuple(tuple(sorted(set(range(a)) - set(left))) for left in combinations(range(a), a - int(faults)))

    def worst_fault_ties(self, faults: int) -> tuple[tuple[str, ...], ...]:
        """Every worst case of ``faults`` faults at one configuration, by name (:func:`~screwkit.indices.exports.
        worst_fault_ties`)."""
        return worst_fault_ties(self, faults)

    def __repr__(self) -> str:
        where = f"{self.mechanism}, " if self.mechanism else ""
        if not self.batch_shape:
            f_o = ", ".join(f"F_O{j}={v:.4f}" for j, v in self.f_o.items())
            return (f"Indices({where}{self.actuator_count} actuators, n={self.dof}: ITI={self.iti:.4f}, "
                    f"LMTI={self.lmti:.4f}{', ' + f_o if f_o else ''})")
        return (f"Indices({where}batch {self.batch_shape}, {self.actuator_count} actuators, n={self.dof}, "
                f"faults j={list(self.faults)})")

    # -- exports --------------------------------------------------------------------------

    def to_dict(self) -> dict:
        """A JSON-ready dictionary (what ``screwkit analyze --json`` prints).

        Angles of the pose are in degrees; NaN (unreachable) becomes None. For a batch, every
        per-configuration entry is a nested list in the batch's order.
        """
        return indices_to_dict(self)

    def to_dataset(self, dims: Sequence[str] | None = None, coords: dict | None = None):
        """The indices as an ``xarray.Dataset``.

        Parameters
        ----------
        dims : str or sequence of str, optional
            Names of the batch dimensions (default ``pose`` for a 1-D batch, else
            ``pose_0, pose_1, ...``); one str names the dimension of a 1-D batch.
        coords : dict, optional
            Extra coordinates, as xarray takes them (e.g. the values of a swept coordinate); a name
            the dataset already has (a pose coordinate, ``actuator``, ``submechanism``, an index) is refused.

        Returns
        -------
        xarray.Dataset
            Variables ``reachable``, ``iti``, ``lmti``, ``f_o{j}``, ``f_io{j}``,
            ``worst_fault{j}`` (names), ``mutual_interference``, and with detail
            ``iti_actuator`` and ``oti_submechanism``; the pose coordinates, when known, as
            coordinates along the batch dimensions (m, deg).
        """
        return indices_to_dataset(self, dims, coords)


def _checked_index(index, batch_shape: tuple[int, ...]) -> tuple:
    """:meth:`Indices.at`'s index as a tuple, checked against the batch shape here (not by numpy on a field)."""
    index = index if isinstance(index, tuple) else (index,)
    if len(index) != len(batch_shape):
        raise ValueError(f"Expected an index with {len(batch_shape)} entries for the batch shape {batch_shape}, "
                         f"got {index}.")
    try:
        np.broadcast_to(np.empty((), dtype=bool), batch_shape)[index]
    except (IndexError, TypeError, ValueError) as error:
        raise ValueError(f"Expected `index` within the batch shape {batch_shape} (integers, or integer arrays), "
                         f"got {index if len(index) > 1 else index[0]!r}: {error}.") from None
    return index


def _check_actuator_set(actuator_set) -> None:
    """:meth:`Indices.lmti_of` takes a sequence of actuators: not one actuator, nor a name's characters."""
    if isinstance(actuator_set, (str, bytes)) or not isinstance(actuator_set, Iterable):
        raise TypeError(f"Expected `actuator_set` as a sequence of actuators (indices or names), got "
                        f"{actuator_set!r}; a set of one is [{actuator_set!r}].")


def _normalise(result: Indices) -> None:
    """Scalars of one configuration as Python numbers, names as str, ``reachable`` filled (frozen: set in place)."""
    shape = np.shape(result.iti)
    object.__setattr__(result, "batch_shape", tuple(shape))
    object.__setattr__(result, "actuators", tuple(str(name) for name in result.actuators))
    object.__setattr__(result, "iti", _scalar_or_array(result.iti))
    object.__setattr__(result, "lmti", _scalar_or_array(result.lmti))
    object.__setattr__(result, "f_o", {int(j): _scalar_or_array(v) for j, v in result.f_o.items()})
    object.__setattr__(result, "f_io", {int(j): _scalar_or_array(v) for j, v in result.f_io.items()})
    object.__setattr__(result, "f_c", {int(j): _scalar_or_array(v) for j, v in result.f_c.items()})
    if result.cti is not None:
        object.__setattr__(result, "cti", _scalar_or_array(result.cti))
    if result.instantaneous_dof is not None:
        dofs = np.asarray(result.instantaneous_dof)
        object.__setattr__(result, "instantaneous_dof", int(dofs) if dofs.ndim == 0 else dofs)
    if result.constraint_singular is not None:
        flags = np.asarray(result.constraint_singular, dtype=bool)
        object.__setattr__(result, "constraint_singular", bool(flags) if flags.ndim == 0 else flags)
    reachable = np.ones(shape, dtype=bool) if result.reachable is None else np.asarray(result.reachable, dtype=bool)
    object.__setattr__(result, "reachable", bool(reachable) if reachable.ndim == 0 else reachable)
    object.__setattr__(result, "threshold", float(result.threshold))


def _checked_arrays(arrays: Mapping[str, Any], about: Mapping[str, Any], known: set[str]) -> dict[str, Any]:
    """The arrays of :meth:`Indices.from_arrays`, checked (names, required fields, batch shapes), with F_IOj."""
    per_configuration = set(PER_CONFIGURATION) | set(PER_CONFIGURATION_DICTS)
    unknown = sorted(set(arrays) - per_configuration) + sorted(set(about) - known)
    if unknown:
        raise TypeError(f"Indices.from_arrays: not fields of Indices: {', '.join(unknown)}")
    misplaced = sorted(set(about) & per_configuration)
    if misplaced:
        raise TypeError(f"Indices.from_arrays: per-configuration fields belong in arrays: {', '.join(misplaced)}")
    missing = [name for name in REQUIRED if arrays.get(name) is None]
    if missing:
        raise TypeError(f"Indices.from_arrays: missing {', '.join(missing)}")
    batch = np.shape(arrays["iti"])
    for name, value in arrays.items():
        for key, entry in (value.items() if isinstance(value, dict) else [(None, value)]):
            if entry is not None and np.shape(entry)[:len(batch)] != batch:
                where = name if key is None else f"{name}[{key}]"
                raise ValueError(f"Indices.from_arrays: {where} has shape {np.shape(entry)}, not a batch of "
                                 f"shape {batch} (the shape of iti)")
    values = {name: value for name, value in arrays.items() if value is not None}
    if "f_io" not in values:
        values["f_io"] = {j: np.minimum(f_o, arrays["iti"]) for j, f_o in arrays["f_o"].items()}
    return values


def with_derived(result: Indices) -> Indices:
    """``result`` with every registered derived index computed (the ``compute`` of each record of
    :mod:`screwkit.indices.registry`, which may read the detail arrays: computed with ``detail``)."""
    derived = {}
    for record in INDICES.values():
        if record.compute is None or not applies(record, result):
            continue
        values = record.compute(result)
        if record.per_fault:
            derived.update({record.column(j): _scalar_or_array(values[j]) for j in result.faults})
        else:
            derived[record.name] = _scalar_or_array(values)
    return replace(result, derived=derived)
