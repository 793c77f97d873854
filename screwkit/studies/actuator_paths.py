"""Paths given as actuator values: the platform poses they drive, by forward kinematics along the path.

:func:`path_from_actuators` turns a sequence of actuator values (one value per actuator and sample) into a
:class:`~screwkit.studies.paths.Path` of platform poses with :func:`screwkit.closure.forward` (Newton steps on the
pose, every actuator held at its value: for a redundantly actuated mechanism the values must agree with each
other, as those of one pose do). The forward kinematics has several solutions (assembly modes); the one followed
is the one reached from ``start`` (default: the reference assembly's pose), by continuation along the path:

0. the first sample from ``start``, or where that finds no pose, from starts about the reference pose, the one pose
   in the reference's working and assembly modes (:func:`~screwkit.closure.forward_kinematics.forward_from_starts`);
1. a coarse pass, sample after sample: at most :data:`COARSE_SEGMENTS` + 1 samples evenly spread along the path,
   each solved from the pose of the one before;
2. then, round after round, the sample halfway between two solved samples, from the pose of the first of them:
   every round one batched call, about log2(n / :data:`COARSE_SEGMENTS`) rounds in all.

A mechanism whose legs have loops inside them (:class:`~screwkit.io.GraphMechanism`) is followed in joint space
from its configuration, sample after sample (:func:`~screwkit.io.graph_actuators.follow_actuators`: the actuators
in small steps, the closures assembled at each with them held), one assembly of its closures per step; the path
keeps the configurations reached, which the trajectory analyses (its task coordinates may fold where the actuators do
not: a crank past the top of its circle moves its coupler's x back).

:func:`read_actuator_path` reads the values from a CSV or netCDF file (a column per actuator, named as
:attr:`~screwkit.model.Mechanism.actuator_names` names them or by its chain's name when the chain has one actuator;
deg for revolute and m for prismatic actuators; optionally ``t``, s) and says in one line what is wrong.

The arc length of a path so driven is along the actuators (their values' steps, angles times the length scale),
for serial legs and loops alike: the same wherever the file places the mechanism in the world, where the task
coordinates (taken in the world's frame, a one-DoF linkage's x or y as its plane lies) and their roll, pitch and
yaw rates are not. For serial legs a revolute actuator's step is taken the short way round, as the forward
kinematics takes it (a log written in [-180, 180) deg); legs with loops inside them are moved through every value
in between, and their steps are measured so.
"""

from __future__ import annotations

import os
from dataclasses import replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.closure import forward
from screwkit.closure.forward_kinematics import forward_from_starts
from screwkit.common.units import angle_beyond_limit, angle_limit
from screwkit.io.graph import GraphMechanism
from screwkit.io.graph_actuators import follow_actuators
from screwkit.model import Mechanism
from screwkit.studies.netcdf import netcdf_file
from screwkit.studies.paths import (
    ROUNDING_ULPS,
    Path,
    PathFileError,
    checked_times,
    path_from_poses,
    read_columns,
    weighted_arc_length,
)

__all__ = ["path_from_actuators", "read_actuator_path", "actuator_columns", "COARSE_SEGMENTS"]

COARSE_SEGMENTS = 64
"""Segments of the coarse pass of the continuation, solved one after the other."""



def actuator_columns(mechanism: Mechanism | GraphMechanism) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """The column of each actuator in a path file (``chain:joint``) and its short alias (the chain's name, when
    the chain has one actuator; else the full name again)."""
    names = mechanism.actuator_names
    chains = [name.split(":")[0] for name in names]
    aliases = tuple(chain if chains.count(chain) == 1 else name for chain, name in zip(chains, names))
    return names, aliases


def path_from_actuators(mechanism: Mechanism | GraphMechanism, values: ArrayLike, times: ArrayLike | None = None,
                        *, start: ArrayLike | None = None) -> Path:
    """The path of the platform driven by actuator ``values`` (n, a) (rad, m; :attr:`Mechanism.actuators` order).

    A mechanism whose legs have loops inside them (:class:`~screwkit.io.GraphMechanism`) is followed from its file's
    configuration, sample after sample (``start`` is for the others).

    Raises
    ------
    ValueError
        A sample whose values no pose near its neighbour's gives (values that disagree with each other, or
        outside the workspace of the assembly mode followed): the first such sample, by number.
    """
    values = _checked(mechanism, values)
    if isinstance(mechanism, GraphMechanism):
        if start is not None:
            raise ValueError("Expected no `start` for a mechanism whose legs have loops inside them: its path is "
                             "followed from its configuration (GraphMechanism.at_pose moves it first).")
        return _graph_path(mechanism, values, times)
    n = values.shape[0]
    poses = np.full((n, mechanism.n_task), np.nan)
    start = mechanism.home_pose if start is None else mechanism.check_poses(start)
    coarse = np.unique(np.linspace(0, n - 1, min(n, COARSE_SEGMENTS + 1)).round().astype(np.int64))
    first, found = forward_from_starts(mechanism, values[0], start)  # the path's first pose, from starts if need be
    if not bool(first.reachable):
        if found:
            raise ValueError(f"sample 0: {found}; give a start near the one meant.")
        raise _not_reached(mechanism, values[0], 0)
    previous = poses[0] = np.asarray(first.poses).reshape(-1)
    for i in coarse[1:]:  # one after the other
        poses[i] = _reached(mechanism, values[i:i + 1], previous[None], np.array([i]))[0]
        previous = poses[i]
    solved = coarse
    while solved.size < n:  # halfway between solved samples, from the first of them, batched
        gaps = np.flatnonzero(np.diff(solved) > 1)
        middle = (solved[gaps] + solved[gaps + 1]) // 2
        poses[middle] = _reached(mechanism, values[middle], poses[solved[gaps]], middle)
        solved = np.sort(np.concatenate([solved, middle]))
    posed = path_from_poses(mechanism, poses, times)  # (checked as a path of poses is)
    # (a revolute actuator's step the short way, as the forward kinematics takes it: a log written in [-180, 180))
    unwrapped, angular = values.copy(), _angular(mechanism)
    unwrapped[:, angular] = np.unwrap(values[:, angular], axis=0)
    return replace(posed, arc_length=_along_actuators(mechanism, unwrapped), actuators=values)


def _checked(mechanism: Mechanism | GraphMechanism, values: ArrayLike) -> NDArray[np.float64]:
    """``values`` (n >= 2, a), finite, each angle within what a double tells one turn from the next."""
    values = np.asarray(values, dtype=float)
    count = len(mechanism.actuators)
    if values.ndim != 2 or values.shape[1] != count or values.shape[0] < 2:
        raise ValueError(f"Expected actuator values with shape (n >= 2, {count}), got {values.shape}.")
    if not np.all(np.isfinite(values)):
        raise ValueError(f"Expected finite actuator values, got {values[~np.isfinite(values)][0]} at sample "
                         f"{int(np.flatnonzero(~np.all(np.isfinite(values), axis=1))[0])}.")
    beyond = np.argwhere(_angular(mechanism) & (np.abs(values) > angle_limit(degrees=False)))
    if beyond.size:  # 1e20 rad cannot tell one turn from the next
        sample, k = (int(i) for i in beyond[0])
        raise angle_beyond_limit(f"actuator values ({mechanism.actuator_names[k]}, sample {sample})",
                                 float(values[sample, k]), degrees=False)
    return values


def _graph_path(graph: GraphMechanism, values: NDArray, times: ArrayLike | None) -> Path:
    """The path of a graph's output frame driven by actuator ``values`` (n, a): each sample's closed configuration
    from the one before (the first from the file's) by :func:`~screwkit.io.graph_actuators.follow_actuators`, one
    sample after the other (each step one assembly of the closures), kept with the path; its arc length is along the
    actuators (angles times the length scale), as the task coordinates may fold or stand still where they move."""
    q, closed = graph.q, np.empty((values.shape[0], graph.kinematics.nq))
    for sample, row in enumerate(values):
        try:
            q = closed[sample] = follow_actuators(graph, q, row)
        except ValueError as error:
            raise _not_reached(graph, row, sample, f"from the {'previous sample' if sample else 'file'}'s "
                                                   f"configuration, {error}") from None
    return Path(graph.frame_pose(closed)[:, list(graph.task_axes)], _along_actuators(graph, values),
                float(graph.length_scale), checked_times(times, values.shape[0]), values, closed)


def _along_actuators(mechanism: Mechanism | GraphMechanism, values: NDArray) -> NDArray[np.float64]:
    """The arc length (n,) of a path driven by actuator ``values`` (n, a): along the actuators, angles times the
    length scale, m for slides. No placement of the mechanism in the world changes it (its task coordinates and
    their angles do), and it moves where they fold or stand still."""
    arc_length, size = weighted_arc_length(values, _angular(mechanism), mechanism.length_scale)
    if not arc_length[-1] > ROUNDING_ULPS * np.spacing(size):
        raise ValueError(f"Expected a path that moves: its actuators move by {arc_length[-1]:.3g} (angles times the "
                         f"length scale) in all, their values' rounding at a size of {size:.3g}.")
    return arc_length


def _reached(mechanism: Mechanism, values: NDArray, initial: NDArray, samples: NDArray) -> NDArray[np.float64]:
    """The poses where the actuators take ``values`` (k, a), from ``initial`` poses; ValueError naming the first
    sample not reached."""
    solution = forward(mechanism, values, initial)
    missed = np.flatnonzero(~np.asarray(solution.reachable))
    if missed.size:
        raise _not_reached(mechanism, values[missed[0]], int(samples[missed[0]]))
    return solution.poses


def _not_reached(mechanism: Mechanism | GraphMechanism, values: NDArray, sample: int, why: str | None = None
                 ) -> ValueError:
    """The refusal of ``sample``, whose actuator ``values`` (a,) no pose near the previous sample's gives."""
    shown = ", ".join(f"{v:.6g}" for v in np.where(_angular(mechanism), np.rad2deg(values), values))
    if why is not None:
        return ValueError(f"sample {sample}: no closed configuration puts the actuators at ({shown}; deg, m): {why}.")
    why = ("they disagree with each other, or leave the workspace of the assembly followed" if
           len(mechanism.actuators) > mechanism.dof else "they leave the working and assembly modes followed there "
           "(a chain stretched or folded on the way, past which only another mode meets them, or out of reach): a "
           "path in poses, or `analyze --actuators` from a start in the other mode (--pose; --initial for a file of "
           "another tool), reads it")
    return ValueError(f"sample {sample}: no pose near the previous sample's gives the actuator values ({shown}; deg, "
                      f"m): {why}.")


def _angular(mechanism: Mechanism | GraphMechanism) -> NDArray[np.bool_]:
    if isinstance(mechanism, GraphMechanism):
        return ~np.asarray(mechanism.actuator_slides, dtype=bool)
    return np.array([not mechanism.chains[c].prismatic[j] for c, j in mechanism.actuator_positions(None)])


def read_actuator_path(mechanism: Mechanism | GraphMechanism, path: str | os.PathLike, *,
                       start: ArrayLike | None = None) -> Path:
    """The platform path driven by the actuator values of a CSV or netCDF file (:func:`path_from_actuators`).

    Raises
    ------
    PathFileError
        One line naming the file: what :func:`~screwkit.studies.paths.read_columns` refuses, times not increasing,
        or a sample whose values no pose gives.
    """
    name = os.fspath(path)
    names, aliases = actuator_columns(mechanism)
    header = _header(name)
    wanted = [alias if name_ not in header and alias in header else name_ for name_, alias in zip(names, aliases)]
    listed = ", ".join(alias for alias in aliases)
    values, times = read_columns(name, wanted, _angular(mechanism),
                                 f"a path of {mechanism.name!r} in actuator values has columns {listed} (deg for a "
                                 "revolute actuator, m for a prismatic one; or chain:joint)")
    try:
        return path_from_actuators(mechanism, values, times, start=start)
    except ValueError as error:
        raise PathFileError(f"{name}: {error}") from None


def _header(name: str) -> set[str]:
    """The column names of a CSV file's first line, or the variables of a netCDF file (nothing for a file that
    cannot be read: :func:`~screwkit.studies.paths.read_columns` says why)."""
    try:
        if name.lower().endswith(".nc"):
            with netcdf_file()(name, "r", mmap=False) as handle:
                return set(handle.variables)
        with open(name, encoding="utf-8-sig") as handle:
            return {cell.strip() for cell in handle.readline().split(",")}
    except MemoryError:
        raise
    except Exception:  # whatever a file that is not one raises: read_columns says what is wrong with it
        return set()
