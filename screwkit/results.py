"""The one result type of screwkit: every index of a mechanism at a batch of configurations.

:class:`Indices` is what :func:`screwkit.transmission.analyze` returns for chain screws and
what :func:`screwkit.studies.indices_at_poses` returns for platform poses; sweeps, maps, the
command line and the viewer are built on it. One configuration is a batch of shape ``()``:
its scalar fields are then plain Python floats. Actuators are named ``chain:joint``
everywhere; worst faults are given by name.

Only numpy is imported here (xarray when :meth:`Indices.to_dataset` is called).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np
from numpy.typing import NDArray

from screwkit.units import is_angular

__all__ = ["Indices", "set_label"]


def _scalar_or_array(value):
    """A 0-d array (or numpy scalar) as a Python float; arrays unchanged."""
    array = np.asarray(value)
    return float(array) if array.ndim == 0 else array


def _json_number(value: float) -> float | None:
    """A float for JSON: NaN (an unreachable pose) becomes None (null); -0.0 becomes 0.0."""
    value = float(value)
    return None if math.isnan(value) else value + 0.0


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
        Output twists ``(omega, v)`` of each actuator of each submechanism, world frame
        (only their screw axes are meaningful: they are scaled as adjugate columns).
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
    batch_shape: tuple[int, ...] = field(init=False)

    def __post_init__(self):
        shape = np.shape(self.iti)
        object.__setattr__(self, "batch_shape", tuple(shape))
        object.__setattr__(self, "actuators", tuple(str(name) for name in self.actuators))
        object.__setattr__(self, "iti", _scalar_or_array(self.iti))
        object.__setattr__(self, "lmti", _scalar_or_array(self.lmti))
        object.__setattr__(self, "f_o", {int(j): _scalar_or_array(v) for j, v in self.f_o.items()})
        object.__setattr__(self, "f_io", {int(j): _scalar_or_array(v) for j, v in self.f_io.items()})
        reachable = np.ones(shape, dtype=bool) if self.reachable is None else np.asarray(self.reachable, dtype=bool)
        object.__setattr__(self, "reachable", bool(reachable) if reachable.ndim == 0 else reachable)
        object.__setattr__(self, "threshold", float(self.threshold))

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

    def at(self, index: int | tuple[int, ...]) -> Indices:
        """The indices of one configuration of the batch (its scalar fields become Python floats)."""
        index = index if isinstance(index, tuple) else (index,)
        if len(index) != len(self.batch_shape):
            raise ValueError(f"Expected an index with {len(self.batch_shape)} entries for the batch shape "
                             f"{self.batch_shape}, got {index}.")

        def pick(value):
            return None if value is None else np.asarray(value)[index]

        return Indices(
            actuators=self.actuators, dof=self.dof, submechanisms=self.submechanisms, iti=pick(self.iti),
            lmti=pick(self.lmti), f_o={j: pick(v) for j, v in self.f_o.items()},
            f_io={j: pick(v) for j, v in self.f_io.items()},
            worst_fault_indices={j: pick(v) for j, v in self.worst_fault_indices.items()},
            mutual_interference=pick(self.mutual_interference), threshold=self.threshold,
            iti_actuators=pick(self.iti_actuators), oti_actuators=pick(self.oti_actuators),
            oti_submechanisms=pick(self.oti_submechanisms), actuation_wrenches=pick(self.actuation_wrenches),
            output_twists=pick(self.output_twists), poses=pick(self.poses), reachable=pick(self.reachable),
            task_coordinates=self.task_coordinates, mechanism=self.mechanism, chain_status=pick(self.chain_status),
            full_poses=pick(self.full_poses), pose_coordinates=self.pose_coordinates)

    def lmti_of(self, actuator_set: Sequence[int | str]) -> Any:
        """LMTI of a set of actuators (Eq. 11): the best OTI of its ``n``-subsets.

        Parameters
        ----------
        actuator_set : sequence of int or str
            Actuators by index into :attr:`actuators` or by name, at least ``n`` of them.

        Returns
        -------
        float or ndarray (...)
        """
        if self.oti_submechanisms is None:
            raise ValueError("These indices were computed without detail; recompute with detail=True for lmti_of.")
        chosen = sorted({self.actuator_index(actuator) for actuator in actuator_set})
        if len(chosen) < self.dof:
            raise ValueError(f"Expected at least n = {self.dof} actuators in `actuator_set`, got {len(chosen)}.")
        members = [s for s, sub in enumerate(self.submechanisms) if set(sub) <= set(chosen)]
        return _scalar_or_array(self.oti_submechanisms[..., members].max(axis=-1))

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

        def number(values):
            array = np.asarray(values, dtype=float)
            if array.ndim == 0:
                return _json_number(array)
            return [number(v) for v in array]

        report: dict[str, Any] = {}
        if self.mechanism:
            report["mechanism"] = self.mechanism
        if self.poses is not None and self.task_coordinates:
            shown = np.array(self.poses, dtype=float, copy=True)
            for axis, name in enumerate(self.task_coordinates):
                if is_angular(name):
                    shown[..., axis] = np.rad2deg(shown[..., axis])
            report["pose"] = ({name: number(shown[..., axis]) for axis, name in enumerate(self.task_coordinates)})
        if self.full_poses is not None and self.pose_coordinates:
            dependent = [name for name in self.pose_coordinates if name not in self.task_coordinates]
            if dependent:  # the parasitic coordinates the closure gave
                full = np.array(self.full_poses, dtype=float, copy=True)
                for axis, name in enumerate(self.pose_coordinates):
                    if is_angular(name):
                        full[..., axis] = np.rad2deg(full[..., axis])
                report["dependent"] = {name: number(full[..., self.pose_coordinates.index(name)]) for name in dependent}
        report["reachable"] = self.reachable if not self.batch_shape else np.asarray(self.reachable).tolist()
        report["dof"] = self.dof
        report["actuators"] = list(self.actuators)
        report["iti"] = number(self.iti)
        if self.iti_actuators is not None:
            report["iti_actuators"] = {name: number(self.iti_actuators[..., i]) for i, name in enumerate(self.actuators)}
        report["lmti"] = number(self.lmti)
        report["f_o"] = {str(j): number(v) for j, v in self.f_o.items()}
        report["f_io"] = {str(j): number(v) for j, v in self.f_io.items()}
        worst = self.worst_faults
        report["worst_faults"] = {str(j): (list(v) if not self.batch_shape else np.asarray(v).tolist())
                                  for j, v in worst.items()}
        if self.batch_shape:
            report["not_mutual_interference"] = np.asarray(self.not_mutual_interference).tolist()
        else:
            report["not_mutual_interference"] = list(self.not_mutual_interference)
        report["threshold_m"] = self.threshold
        return report

    def to_dataset(self, dims: Sequence[str] | None = None, coords: dict | None = None):
        """The indices as an ``xarray.Dataset``.

        Parameters
        ----------
        dims : sequence of str, optional
            Names of the batch dimensions (default ``pose`` for a 1-D batch, else
            ``pose_0, pose_1, ...``).
        coords : dict, optional
            Extra coordinates, as xarray takes them (e.g. the values of a swept coordinate).

        Returns
        -------
        xarray.Dataset
            Variables ``reachable``, ``iti``, ``lmti``, ``f_o{j}``, ``f_io{j}``,
            ``worst_fault{j}`` (names), ``mutual_interference``, and with detail
            ``iti_actuator`` and ``oti_submechanism``; the pose coordinates, when known, as
            coordinates along the batch dimensions (m, deg).
        """
        import xarray as xr

        batch = self.batch_shape
        if dims is None:
            dims = ("pose",) if len(batch) == 1 else tuple(f"pose_{i}" for i in range(len(batch)))
        dims = tuple(dims)
        if len(dims) != len(batch):
            raise ValueError(f"Expected {len(batch)} names in `dims` for the batch shape {batch}, got {dims}.")
        variables = {
            "reachable": (dims, np.asarray(self.reachable)),
            "iti": (dims, np.asarray(self.iti), {"long_name": "ITI (Eq. 7)"}),
            "lmti": (dims, np.asarray(self.lmti), {"long_name": "LMTI of all actuators (Eq. 11)"}),
            "mutual_interference": (dims + ("actuator",), self.mutual_interference,
                                    {"long_name": "mutual-interference actuator"}),
        }
        if self.iti_actuators is not None:
            variables["iti_actuator"] = (dims + ("actuator",), self.iti_actuators,
                                         {"long_name": "ITI per actuator (Eq. 6)"})
        if self.oti_submechanisms is not None:
            variables["oti_submechanism"] = (dims + ("submechanism",), self.oti_submechanisms,
                                             {"long_name": "OTI of each non-redundant submechanism (Eq. 9)"})
        worst = self.worst_faults
        for j in self.faults:
            variables[f"f_o{j}"] = (dims, np.asarray(self.f_o[j]), {"long_name": f"F_O{j} (Eq. 12)"})
            variables[f"f_io{j}"] = (dims, np.asarray(self.f_io[j]), {"long_name": f"F_IO{j} (Eq. 14)"})
            variables[f"worst_fault{j}"] = (dims + (f"fault{j}",), np.asarray(worst[j], dtype=str),
                                            {"long_name": f"failed actuators of the worst case of {j} fault(s)"})
        all_coords = {"actuator": ("actuator", list(self.actuators)),
                      "submechanism": ("submechanism", [set_label(s) for s in self.submechanisms])}
        if self.poses is not None and self.task_coordinates:
            for axis, name in enumerate(self.task_coordinates):
                values = np.asarray(self.poses)[..., axis]
                values = np.rad2deg(values) if is_angular(name) else values
                if name not in dims:
                    all_coords[name] = (dims, values, {"units": "deg" if is_angular(name) else "m"})
        all_coords.update(coords or {})
        dataset = xr.Dataset({k: xr.Variable(*v) for k, v in variables.items()}, coords=all_coords)
        dataset.attrs.update(threshold_m=self.threshold, dof=self.dof)
        if self.mechanism:
            dataset.attrs["mechanism"] = self.mechanism
        return dataset


def set_label(actuators: Sequence[int]) -> str:
    """A set of 0-based actuator indices as the paper writes it, counting from 1.

    >>> set_label((0, 1, 2))
    '1-2-3'
    """
    return "-".join(str(i + 1) for i in actuators)
