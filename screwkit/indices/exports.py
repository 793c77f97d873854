"""Exports of :class:`screwkit.indices.results.Indices`: the JSON-ready dictionary and the xarray dataset.

Only numpy is imported here (xarray when a dataset is made).
"""

from __future__ import annotations

import math
from typing import Any, Sequence

import numpy as np

from screwkit.common.tolerances import WORST_FAULT_TIE
from screwkit.common.units import is_angular
from screwkit.indices.registry import INDICES, applies

__all__ = ["indices_to_dict", "indices_to_dataset", "indices_variables", "json_number", "set_label", "tied",
           "worst_fault_ties"]


def json_number(value: float) -> float | None:
    """A float for JSON: NaN (an unreachable pose) becomes None (null); -0.0 becomes 0.0."""
    value = float(value)
    return None if math.isnan(value) else value + 0.0


def set_label(actuators: Sequence[int]) -> str:
    """A set of 0-based actuator indices as the paper writes it, counting from 1.

    >>> set_label((0, 1, 2))
    '1-2-3'
    """
    return "-".join(str(i + 1) for i in actuators)


def worst_fault_ties(indices, faults: int) -> tuple[tuple[str, ...], ...]:
    """Every worst case of ``faults`` faults at one configuration, by name: the failed actuators of each set
    whose LMTI is within :data:`~screwkit.common.tolerances.WORST_FAULT_TIE` of ``F_Oj`` (the reported
    ``worst_faults`` first). Only the reported one without ``detail``; none where unreachable."""
    if indices.batch_shape:
        raise ValueError("worst_fault_ties is for one configuration; take .at(index) of a batch first.")
    if isinstance(faults, (bool, np.bool_)) or not isinstance(faults, (int, np.integer)) \
            or faults not in indices.worst_faults:
        raise ValueError(f"Expected `faults` as one of the numbers of faults j computed, "
                         f"{', '.join(map(str, indices.faults)) or 'none'}, got {faults!r}.")
    if not indices.reachable:
        return ()
    first = tuple(indices.worst_faults[faults])
    if faults not in indices.remaining_lmti:
        return (first,)
    values = np.asarray(indices.remaining_lmti[faults])
    tied_sets = [tuple(indices.actuators[k] for k in failed)
                 for failed, value in zip(indices.failed_sets(faults), values)
                 if value <= indices.f_o[faults] + WORST_FAULT_TIE]
    return (first,) + tuple(names for names in tied_sets if names != first)


def tied(values, best: float, highest: bool = False) -> list[int]:
    """Positions of ``values`` within :data:`~screwkit.common.tolerances.WORST_FAULT_TIE` of ``best`` (the lowest, or
    the highest): values that are mathematically equal differ by rounding only, and count as ties."""
    values = np.asarray(values, dtype=float)
    close = values >= best - WORST_FAULT_TIE if highest else values <= best + WORST_FAULT_TIE
    return [int(i) for i in np.flatnonzero(close)]


def _submechanism_detail(indices, allowed: set[int]) -> dict:
    """The best submechanism among those inside ``allowed`` (actuator indices), its OTI per actuator and the
    actuators that limit it (ties included), and the other submechanisms tied with it (one configuration)."""
    names = indices.actuators
    members = [s for s, sub in enumerate(indices.submechanisms) if set(sub) <= allowed]
    if not members:
        return {"submechanism": [], "tied_submechanisms": [], "oti_actuators": {}, "limiting": []}
    otis = np.asarray(indices.oti_submechanisms)[members]
    best = tied(otis, float(otis.max()), highest=True)
    chosen = members[best[0]]
    sub = indices.submechanisms[chosen]
    per_actuator = np.asarray(indices.oti_actuators)[chosen]
    return {"submechanism": [names[k] for k in sub],
            "tied_submechanisms": [[names[k] for k in indices.submechanisms[members[b]]] for b in best[1:]],
            "oti_actuators": {names[k]: json_number(v) for k, v in zip(sub, per_actuator)},
            "limiting": [names[sub[i]] for i in tied(per_actuator, float(per_actuator.min()))]}


def _one_configuration(indices) -> dict:
    """What a report of one reachable configuration adds to the indices: ties, the submechanisms that give the
    LMTI and each F_Oj with their limiting actuators, the configuration and the working mode."""
    report: dict[str, Any] = {"redundancy": indices.actuator_count - indices.dof}
    names = indices.actuators
    if indices.iti_actuators is not None:
        report["iti_lowest"] = [names[i] for i in tied(indices.iti_actuators, indices.iti)]
    if indices.oti_submechanisms is not None and indices.oti_actuators is not None:
        report["lmti_detail"] = _submechanism_detail(indices, set(range(indices.actuator_count)))
        faults = {}
        for j in indices.faults:
            ties = indices.worst_fault_ties(j)
            left = set(range(indices.actuator_count)) - {indices.actuator_index(name) for name in ties[0]}
            detail = {"worst": [list(names_) for names_ in ties], "left": [names[k] for k in sorted(left)]}
            if indices.fault_type == "free-swinging":  # the LMTI of the set left is that of its submechanisms
                detail.update(_submechanism_detail(indices, left))
            faults[str(j)] = detail
        report["fault_detail"] = faults
    if indices.joint_values:
        report["configuration"] = {
            name: {"value": json_number(value if name in indices.prismatic_joints else np.rad2deg(value)),
                   "unit": "m" if name in indices.prismatic_joints else "deg",
                   "actuated": name in names}
            for name, value in indices.joint_values.items()}
    if indices.working_mode:
        report["working_mode"] = dict(indices.working_mode)
    return report


def _values(indices, record):
    """The values of a registered index, or None for a derived index registered after they were computed."""
    try:
        return indices.index(record.name)
    except ValueError:
        return None


def indices_to_dict(indices) -> dict:
    """What :meth:`screwkit.indices.results.Indices.to_dict` returns."""

    def number(values):
        array = np.asarray(values, dtype=float)
        if array.ndim == 0:
            return json_number(array)
        return [number(v) for v in array]

    report: dict[str, Any] = {}
    if indices.mechanism:
        report["mechanism"] = indices.mechanism
    if indices.poses is not None and indices.task_coordinates:
        shown = np.array(indices.poses, dtype=float, copy=True)
        for axis, name in enumerate(indices.task_coordinates):
            if is_angular(name):
                shown[..., axis] = np.rad2deg(shown[..., axis])
        report["pose"] = ({name: number(shown[..., axis]) for axis, name in enumerate(indices.task_coordinates)})
    if indices.full_poses is not None and indices.pose_coordinates:
        dependent = [name for name in indices.pose_coordinates if name not in indices.task_coordinates]
        if dependent:  # the parasitic coordinates the closure gave
            full = np.array(indices.full_poses, dtype=float, copy=True)
            for axis, name in enumerate(indices.pose_coordinates):
                if is_angular(name):
                    full[..., axis] = np.rad2deg(full[..., axis])
            report["dependent"] = {name: number(full[..., indices.pose_coordinates.index(name)]) for name in dependent}
    report["reachable"] = indices.reachable if not indices.batch_shape else np.asarray(indices.reachable).tolist()
    report["dof"] = indices.dof
    report["actuators"] = list(indices.actuators)
    for record in INDICES.values():  # every index, one record each
        if not applies(record, indices):
            if not record.per_fault:
                report[record.name] = "not applicable"
            continue
        values = _values(indices, record)
        if values is not None:
            report[record.name] = ({str(j): number(v) for j, v in values.items()} if record.per_fault
                                   else number(values))
    if not indices.constraint_count:
        report["cti_reason"] = indices.cti_reason or "no constraint wrench is held by one chain alone"
    if indices.iti_actuators is not None:
        report["iti_actuators"] = {name: number(indices.iti_actuators[..., i])
                                   for i, name in enumerate(indices.actuators)}
    worst = indices.worst_faults
    report["worst_faults"] = {str(j): (list(v) if not indices.batch_shape else np.asarray(v).tolist())
                              for j, v in worst.items()}
    report["fault_type"] = indices.fault_type
    if not indices.batch_shape:
        report["worst_fault_ties"] = {str(j): [list(names) for names in indices.worst_fault_ties(j)]
                                      for j in indices.faults}
    if indices.instantaneous_dof is not None:
        report["instantaneous_dof"] = (int(indices.instantaneous_dof) if not indices.batch_shape
                                       else np.asarray(indices.instantaneous_dof).tolist())
        report["constraint_singular"] = (bool(indices.constraint_singular) if not indices.batch_shape
                                         else np.asarray(indices.constraint_singular).tolist())
    if indices.batch_shape:
        report["not_mutual_interference"] = np.asarray(indices.not_mutual_interference).tolist()
    else:
        report["not_mutual_interference"] = list(indices.not_mutual_interference)
    report["threshold_m"] = indices.threshold
    if not indices.batch_shape and indices.reachable:
        report.update(_one_configuration(indices))
    return report


def indices_to_dataset(indices, dims: Sequence[str] | None = None, coords: dict | None = None):
    """What :meth:`screwkit.indices.results.Indices.to_dataset` returns: :func:`indices_variables` in xarray."""
    import xarray as xr

    variables, all_coords, attrs = indices_variables(indices, dims, coords)
    dataset = xr.Dataset({k: xr.Variable(*v) for k, v in variables.items()}, coords=all_coords)
    dataset.attrs.update(attrs)
    return dataset


def indices_variables(indices, dims: Sequence[str] | None = None,
                      coords: dict | None = None) -> tuple[dict[str, tuple], dict[str, tuple], dict[str, Any]]:
    """The content of :func:`indices_to_dataset` as plain numpy arrays, without xarray: the variables and the
    coordinates, each ``(dims, values[, attrs])`` as ``xarray.Variable`` takes them, and the global attributes."""
    batch = indices.batch_shape
    if dims is None:
        dims = ("pose",) if len(batch) == 1 else tuple(f"pose_{i}" for i in range(len(batch)))
    dims = (dims,) if isinstance(dims, str) else tuple(dims)  # one name: the dimension of a 1-D batch
    if len(dims) != len(batch) or not all(isinstance(name, str) for name in dims):
        raise ValueError(f"Expected {len(batch)} names (str) in `dims` for the batch shape {batch}, got {dims}.")
    variables = {"reachable": (dims, np.asarray(indices.reachable))}
    for record in INDICES.values():  # every index, one record each
        values = _values(indices, record) if applies(record, indices) else None
        if values is None:
            continue
        for j, value in (values.items() if record.per_fault else [(None, values)]):
            variables[record.column(j)] = (dims, np.asarray(value), {"long_name": record.long_name(j),
                                                                     "description": record.description})
    variables["mutual_interference"] = (dims + ("actuator",), indices.mutual_interference,
                                        {"long_name": "mutual-interference actuator"})
    if indices.iti_actuators is not None:
        variables["iti_actuator"] = (dims + ("actuator",), indices.iti_actuators,
                                     {"long_name": "ITI per actuator (Eq. 6)"})
    if indices.oti_submechanisms is not None:
        variables["oti_submechanism"] = (dims + ("submechanism",), indices.oti_submechanisms,
                                         {"long_name": "OTI of each non-redundant submechanism (Eq. 9)"})
    worst = indices.worst_faults
    for j in indices.faults:
        variables[f"worst_fault{j}"] = (dims + (f"fault{j}",), np.asarray(worst[j], dtype=str),
                                        {"long_name": f"failed actuators of the worst case of {j} fault(s)"})
    if indices.instantaneous_dof is not None:
        variables["instantaneous_dof"] = (dims, np.asarray(indices.instantaneous_dof))
        variables["constraint_singular"] = (dims, np.asarray(indices.constraint_singular))
    all_coords = {"actuator": ("actuator", list(indices.actuators)),
                  "submechanism": ("submechanism", [set_label(s) for s in indices.submechanisms])}
    if indices.poses is not None and indices.task_coordinates:
        for axis, name in enumerate(indices.task_coordinates):
            values = np.asarray(indices.poses)[..., axis]
            values = np.rad2deg(values) if is_angular(name) else values
            if name not in dims:
                all_coords[name] = (dims, values, {"units": "deg" if is_angular(name) else "m"})
    taken = sorted(set(coords or {}) & (set(all_coords) | set(variables)))
    if taken:  # it would replace a pose coordinate, the actuators, the submechanisms or an index, silently
        raise ValueError(f"Expected `coords` named unlike the dataset's own coordinates and variables, got "
                         f"{', '.join(map(repr, taken))} (taken: {', '.join(sorted(all_coords))}).")
    all_coords.update(coords or {})
    attrs: dict[str, Any] = dict(threshold_m=indices.threshold, dof=indices.dof, fault_type=indices.fault_type)
    if indices.mechanism:
        attrs["mechanism"] = indices.mechanism
    return variables, all_coords, attrs
