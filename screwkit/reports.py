"""Exports of :class:`screwkit.results.Indices`: the JSON-ready dictionary and the xarray dataset.

Only numpy is imported here (xarray when a dataset is made).
"""

from __future__ import annotations

import math
from typing import Any, Sequence

import numpy as np

from screwkit.units import is_angular

__all__ = ["indices_to_dict", "indices_to_dataset", "json_number", "set_label"]


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


def indices_to_dict(indices) -> dict:
    """What :meth:`screwkit.results.Indices.to_dict` returns."""

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
    report["iti"] = number(indices.iti)
    if indices.iti_actuators is not None:
        report["iti_actuators"] = {name: number(indices.iti_actuators[..., i])
                                   for i, name in enumerate(indices.actuators)}
    report["lmti"] = number(indices.lmti)
    report["f_o"] = {str(j): number(v) for j, v in indices.f_o.items()}
    report["f_io"] = {str(j): number(v) for j, v in indices.f_io.items()}
    worst = indices.worst_faults
    report["worst_faults"] = {str(j): (list(v) if not indices.batch_shape else np.asarray(v).tolist())
                              for j, v in worst.items()}
    report["fault_type"] = indices.fault_type
    if indices.cti is None or not indices.constraint_count:
        report["cti"] = "not applicable"  # no constraint wrench held by one chain alone
    else:
        report["cti"] = number(indices.cti)
        report["f_c"] = {str(j): number(v) for j, v in indices.f_c.items()}
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
    return report


def indices_to_dataset(indices, dims: Sequence[str] | None = None, coords: dict | None = None):
    """What :meth:`screwkit.results.Indices.to_dataset` returns."""
    import xarray as xr

    batch = indices.batch_shape
    if dims is None:
        dims = ("pose",) if len(batch) == 1 else tuple(f"pose_{i}" for i in range(len(batch)))
    dims = tuple(dims)
    if len(dims) != len(batch):
        raise ValueError(f"Expected {len(batch)} names in `dims` for the batch shape {batch}, got {dims}.")
    variables = {
        "reachable": (dims, np.asarray(indices.reachable)),
        "iti": (dims, np.asarray(indices.iti), {"long_name": "ITI (Eq. 7)"}),
        "lmti": (dims, np.asarray(indices.lmti), {"long_name": "LMTI of all actuators (Eq. 11)"}),
        "mutual_interference": (dims + ("actuator",), indices.mutual_interference,
                                {"long_name": "mutual-interference actuator"}),
    }
    if indices.iti_actuators is not None:
        variables["iti_actuator"] = (dims + ("actuator",), indices.iti_actuators,
                                     {"long_name": "ITI per actuator (Eq. 6)"})
    if indices.oti_submechanisms is not None:
        variables["oti_submechanism"] = (dims + ("submechanism",), indices.oti_submechanisms,
                                         {"long_name": "OTI of each non-redundant submechanism (Eq. 9)"})
    worst = indices.worst_faults
    for j in indices.faults:
        variables[f"f_o{j}"] = (dims, np.asarray(indices.f_o[j]), {"long_name": f"F_O{j} (Eq. 12)"})
        variables[f"f_io{j}"] = (dims, np.asarray(indices.f_io[j]), {"long_name": f"F_IO{j} (Eq. 14)"})
        variables[f"worst_fault{j}"] = (dims + (f"fault{j}",), np.asarray(worst[j], dtype=str),
                                        {"long_name": f"failed actuators of the worst case of {j} fault(s)"})
    if indices.cti is not None and indices.constraint_count:
        variables["cti"] = (dims, np.asarray(indices.cti), {"long_name": "constraint transmission index"})
        for j, value in indices.f_c.items():
            variables[f"f_c{j}"] = (dims, np.asarray(value), {"long_name": f"F_C{j} (worst CTI after {j} faults)"})
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
    all_coords.update(coords or {})
    dataset = xr.Dataset({k: xr.Variable(*v) for k, v in variables.items()}, coords=all_coords)
    dataset.attrs.update(threshold_m=indices.threshold, dof=indices.dof, fault_type=indices.fault_type)
    if indices.mechanism:
        dataset.attrs["mechanism"] = indices.mechanism
    return dataset
