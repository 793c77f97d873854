"""Sweeps of one pose coordinate: every series of the paper's Fig. 4, as an xarray Dataset (or plain arrays).

:func:`sweep` varies one task coordinate (the platform angle ``phi`` of a planar mechanism,
or any coordinate of a spatial one) with the others fixed and returns, along the swept
coordinate: the ITI of each actuator and overall; the OTI of every non-redundant
submechanism and the LMTI; for every number of faults j the LMTI of each actuator set left
after j faults, F_Oj and F_IOj.
"""

from __future__ import annotations

from itertools import combinations

import numpy as np
from numpy.typing import ArrayLike

from screwkit.closure.on_the_way import singular_on_the_ways
from screwkit.common.tolerances import SINGULARITY_THRESHOLD
from screwkit.common.units import is_angular
from screwkit.indices.exports import indices_variables
from screwkit.indices.results import set_label
from screwkit.io.graph import GraphMechanism
from screwkit.model import Mechanism, require_mechanism
from screwkit.studies.coordinates import one_pose, pose_text, shown_values
from screwkit.studies.netcdf import PlainDataset
from screwkit.studies.poses import check_graph_analysis, graph_indices_at_poses, indices_at_poses
from screwkit.studies.sizes import check_fits, pose_bytes

__all__ = ["sweep"]


def sweep(mechanism: Mechanism, at: ArrayLike, coordinate: str, values: ArrayLike, *,
          threshold: float = SINGULARITY_THRESHOLD, faults=None, closed_forms: bool = False, limits: bool = True,
          fault_type: str = "free-swinging", as_dataset: bool = True):
    """Every index along one swept task coordinate.

    Parameters
    ----------
    mechanism : Mechanism or GraphMechanism
        A mechanism whose legs have loops inside them (:class:`~screwkit.io.GraphMechanism`) is solved at each
        value by continuation from its configuration (:func:`~screwkit.studies.poses.graph_indices_at_poses`).
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
    limits : bool
        Whether joint limits make a pose unreachable (default).
    as_dataset : bool
        Return an ``xarray.Dataset`` (default) or the same as a :class:`~screwkit.studies.netcdf.PlainDataset` (plain
        arrays: the command writes it, or prints its table, without importing xarray).

    Returns
    -------
    xarray.Dataset or PlainDataset
        Dimension ``coordinate`` (degrees for angles), ``actuator``, ``submechanism`` and for
        each j ``remaining{j}`` (the actuator sets left after j faults). Variables:
        ``iti``, ``iti_actuator``, ``oti_submechanism``, ``lmti``, ``lmti_remaining{j}``,
        ``f_o{j}``, ``f_io{j}``, ``worst_fault{j}``, ``mutual_interference``, ``reachable``
        (those of :meth:`screwkit.indices.results.Indices.to_dataset` along the swept coordinate,
        and the LMTI of every set left after j faults). Attribute ``fixed_pose``: the other coordinates (m, deg).
        For a mechanism with chains closed by damped Newton with a working-mode sign, also ``past_singular``
        (``coordinate``, ``singular_chain``): whether the straight way from the reference pose to each pose passes
        a configuration where the chain's joints are singular (two of its assemblies meet there, and the pose is on
        the one that keeps the reference's sign; :func:`~screwkit.closure.on_the_way.singular_on_the_ways`).
    """

    graph = isinstance(mechanism, GraphMechanism)
    if graph:
        check_graph_analysis(mechanism, closed_forms, fault_type)
    else:
        require_mechanism(mechanism, "sweep")
    if coordinate not in mechanism.task_coordinates:
        raise ValueError(f"Expected `coordinate` in {mechanism.task_coordinates}, got {coordinate!r}.")
    at = one_pose(mechanism, at)
    try:  # (a string such as "0:360" is not numbers; nor are booleans)
        given = np.asarray(values)
        if given.dtype.kind not in "iuf":
            raise TypeError
    except (TypeError, ValueError):
        raise ValueError(f"Expected `values` as numbers (k,) of {coordinate} (m or rad), got {values!r:.60}.") from None
    values = given.astype(float)
    if not np.all(np.isfinite(values)):
        raise ValueError(f"Expected finite `values`, got {values[~np.isfinite(values)][0]}.")
    if values.ndim != 1 or values.size == 0:
        raise ValueError(f"Expected `values` with shape (k,), k >= 1, got {values.shape}.")
    check_fits(values.size, pose_bytes(mechanism, faults), f"the sweep has {values.size:,} values of {coordinate}")
    axis = mechanism.task_coordinates.index(coordinate)
    poses = np.repeat(at[None], values.size, axis=0)
    poses[:, axis] = values
    if graph:
        result = graph_indices_at_poses(mechanism, poses, detail=True, threshold=threshold, faults=faults,
                                        limits=limits)
    else:
        result = indices_at_poses(mechanism, poses, detail=True, threshold=threshold, faults=faults,
                                  closed_forms=closed_forms, limits=limits, fault_type=fault_type)
    angular = is_angular(coordinate)
    shown = shown_values(coordinate, values)  # degrees as written: 30, not 29.999999999999996
    variables, coords, attrs = indices_variables(
        result, (coordinate,), {coordinate: (coordinate, shown, {"units": "deg" if angular else "m"})})
    a = result.actuator_count
    for j in result.faults:
        remaining = list(combinations(range(a), a - j))
        dimension = f"remaining{j}"
        coords[dimension] = (dimension, [set_label(e) for e in remaining])
        if result.oti_submechanisms is not None and fault_type == "free-swinging":
            stacked = np.stack([np.asarray(result.lmti_of(e)) for e in remaining], axis=-1)
            variables[f"lmti_remaining{j}"] = ((coordinate, dimension), stacked,
                                               {"long_name": f"LMTI of each actuator set left after {j} fault(s)"})
    passed = [] if graph else singular_on_the_ways(mechanism, poses)
    if passed:
        coords["singular_chain"] = ("singular_chain", [name for name, _, _ in passed])
        reachable = np.asarray(result.reachable, dtype=bool)[:, None]  # (a pose out of reach is on no assembly)
        variables["past_singular"] = ((coordinate, "singular_chain"),
                                      np.stack([mask for _, mask, _ in passed], axis=1) & reachable,
                                      {"long_name": "the way from the reference pose passes a configuration where "
                                                    "the chain's joints are singular"})
    attrs.update(mechanism=mechanism.name, swept=coordinate, threshold_m=threshold,
                 fixed_pose=pose_text(mechanism.task_coordinates, at, mechanism.length_scale, [coordinate]),
                 method="closed forms" if closed_forms else "generic screw path", fault_type=fault_type)
    plain = PlainDataset(variables, coords, attrs)
    return plain.to_dataset() if as_dataset else plain

