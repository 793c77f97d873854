"""Sweeps of one pose coordinate: every series of the paper's Fig. 4, as an xarray Dataset.

:func:`sweep` varies one task coordinate (the platform angle ``phi`` of a planar mechanism,
or any coordinate of a spatial one) with the others fixed and returns, along the swept
coordinate: the ITI of each actuator and overall; the OTI of every non-redundant
submechanism and the LMTI; for every number of faults j the LMTI of each actuator set left
after j faults, F_Oj and F_IOj.
"""

from __future__ import annotations

from itertools import combinations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.analysis import angular_coordinates, indices_at_poses
from screwkit.transmission import DEFAULT_THRESHOLD

__all__ = ["parse_range", "sweep", "set_label"]


def parse_range(text: str, name: str = "range") -> NDArray[np.float64]:
    """``"START:STOP:STEP"`` -> the values START, START+STEP, ... below STOP.

    The stop is exclusive (``0:360:1`` gives 360 angles) up to a rounding tolerance of a
    millionth of a step.
    """
    parts = str(text).split(":")
    try:
        start, stop, step = (float(p) for p in parts)
    except ValueError:
        raise ValueError(f"Expected `{name}` as START:STOP:STEP (three numbers), got {text!r}.") from None
    if not step > 0 or not stop > start:
        raise ValueError(f"Expected `{name}` with STEP > 0 and STOP > START, got {text!r}.")
    count = int(np.ceil((stop - start) / step - 1e-6))
    return start + step * np.arange(count)


def set_label(actuators) -> str:
    """A set of 0-based actuator indices as the paper writes it: ``(0, 1, 2)`` -> ``"123"``."""
    return "-".join(str(i + 1) for i in actuators)


def sweep(mechanism, at: ArrayLike, coordinate: str, values: ArrayLike, *,
          threshold: float = DEFAULT_THRESHOLD, faults=None, closed_forms: bool = False):
    """Every index along one swept task coordinate.

    Parameters
    ----------
    mechanism : screwkit.mechanism.Mechanism
    at : array_like, shape (n_task,)
        The fixed pose (metres, radians); its ``coordinate`` entry is replaced by ``values``.
    coordinate : str
        One of ``mechanism.task_coordinates``.
    values : array_like, shape (k,)
        Values of the swept coordinate (metres or radians).
    threshold : float
        Singularity threshold *p* (m).
    faults : int or sequence of int, optional
        Numbers of faults j (default all).
    closed_forms : bool
        Use the planar closed forms instead of the generic screw path.

    Returns
    -------
    xarray.Dataset
        Dimension ``coordinate`` (degrees for angles), ``actuator``, ``submechanism`` and for
        each j ``remaining{j}`` (the actuator sets left after j faults). Variables:
        ``iti``, ``iti_actuator``, ``oti_submechanism``, ``lmti``, ``lmti_remaining{j}``,
        ``f_o{j}``, ``f_io{j}``, ``reachable``.
    """
    import xarray as xr

    if coordinate not in mechanism.task_coordinates:
        raise ValueError(f"Expected `coordinate` in {mechanism.task_coordinates}, got {coordinate!r}.")
    at = mechanism.check_poses(at)
    values = np.asarray(values, dtype=float)
    if values.ndim != 1 or values.size == 0:
        raise ValueError(f"Expected `values` with shape (k,), k >= 1, got {values.shape}.")
    axis = mechanism.task_coordinates.index(coordinate)
    poses = np.repeat(at[None], values.size, axis=0)
    poses[:, axis] = values
    result = indices_at_poses(mechanism, poses, detail=True, threshold=threshold, faults=faults,
                              closed_forms=closed_forms)
    angular = bool(angular_coordinates(mechanism.task_coordinates)[axis])
    shown = np.rad2deg(values) if angular else values
    a = len(result.actuator_names)
    subs = [set_label(s) for s in result.submechanisms]
    data = {
        "reachable": ((coordinate,), result.reachable),
        "iti": ((coordinate,), result.iti, {"long_name": "ITI (Eq. 7)"}),
        "iti_actuator": ((coordinate, "actuator"), result.iti_actuators, {"long_name": "ITI per actuator (Eq. 6)"}),
        "lmti": ((coordinate,), result.lmti, {"long_name": "LMTI of all actuators (Eq. 11)"}),
    }
    coords = {coordinate: (coordinate, shown, {"units": "deg" if angular else "m"}),
              "actuator": ("actuator", list(result.actuator_names))}
    if result.oti_submechanisms is not None:
        data["oti_submechanism"] = ((coordinate, "submechanism"), result.oti_submechanisms,
                                    {"long_name": "OTI of each non-redundant submechanism (Eq. 9)"})
        coords["submechanism"] = ("submechanism", subs)
    for j in result.f_o:
        remaining = list(combinations(range(a), a - j))
        dimension = f"remaining{j}"
        coords[dimension] = (dimension, [set_label(e) for e in remaining])
        if result.oti_submechanisms is not None:
            stacked = np.stack([result.lmti_of(e) for e in remaining], axis=-1)
            data[f"lmti_remaining{j}"] = ((coordinate, dimension), stacked,
                                          {"long_name": f"LMTI of each actuator set left after {j} fault(s)"})
        data[f"f_o{j}"] = ((coordinate,), result.f_o[j], {"long_name": f"F_O{j} (Eq. 12)"})
        data[f"f_io{j}"] = ((coordinate,), result.f_io[j], {"long_name": f"F_IO{j} (Eq. 14)"})
    dataset = xr.Dataset({k: xr.Variable(*v) for k, v in data.items()}, coords=coords)
    dataset.attrs.update(mechanism=mechanism.name, swept=coordinate, threshold_m=threshold,
                         fixed_pose=", ".join(f"{n}={v:g}" for n, v in zip(mechanism.task_coordinates, at)),
                         method="closed forms" if closed_forms else "generic screw path")
    return dataset
