"""What a path needs of a mechanism, for serial legs and for legs with loops inside them alike.

:func:`~screwkit.studies.trajectory.trajectory` asks a mechanism for five things: every index at a batch of poses
(with the joint values a branch change is seen on, at the samples), the same indices alone (each round of the
refinement), those joint values alone (the branch search), why a pose is unreachable, and the working mode its
closures keep. :class:`SerialPath` answers for a :class:`~screwkit.model.Mechanism` (closures chain by chain:
closed forms, damped Newton), :class:`GraphPath` for a :class:`~screwkit.io.GraphMechanism` (every closure of the
graph solved at once, each pose by continuation from the file's configuration,
:meth:`~screwkit.io.GraphMechanism.solve`), and :class:`ActuatedGraphPath` for one along a path its actuators drive
(each configuration followed from the sample before in joint space). The trajectory asks at arc lengths of the path
(``indices_along``, ``joint_values_along``, ``unreachable_along``): the first two at the poses there.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from screwkit.closure import UnreachablePose, solve, solve_one, working_modes
from screwkit.closure.on_the_way import singular_along
from screwkit.closure.solve import ChainStatus
from screwkit.common.units import spelled_pose
from screwkit.indices.results import Indices
from screwkit.io.graph import GraphMechanism
from screwkit.io.graph_actuators import between_samples
from screwkit.io.graph_kinematics import beyond_limits, joints_beyond_limits
from screwkit.model import Mechanism
from screwkit.studies.branches import ChainJoints, chain_joints
from screwkit.studies.options import AnalysisOptions
from screwkit.studies.paths import Path
from screwkit.studies.poses import (
    check_graph_analysis,
    graph_indices_at_poses,
    indices_and_joint_values,
    indices_at_poses,
)
from screwkit.studies.sizes import check_fits, pose_bytes

__all__ = ["SerialPath", "GraphPath", "ActuatedGraphPath", "path_mechanism", "check_path_size"]


class _Along:
    """What the trajectory asks at arc lengths of a path: by default at the poses there."""

    def indices_along(self, path: Path, positions: NDArray) -> Indices:
        return self.indices(path.at(positions))

    def joint_values_along(self, path: Path, positions: NDArray) -> list[NDArray[np.float64]]:
        return self.joint_values(path.at(positions))

    def unreachable_along(self, path: Path, position: float, status: NDArray) -> tuple[str, str]:
        return self.unreachable(path.at(np.array([position]))[0], status)


@dataclass(frozen=True)
class SerialPath(_Along):
    """A mechanism of serial legs along a path: its closures keep each chain's working mode pose by pose."""

    mechanism: Mechanism
    analysis: AnalysisOptions
    keywords: dict

    @property
    def chains(self) -> tuple[ChainJoints, ...]:
        return chain_joints(self.mechanism)

    @property
    def joint_coordinates(self) -> int:
        """The joint values kept per sample (each chain's tree joints)."""
        return sum(chain.geometry.n_tree_joints for chain in self.mechanism.chains)

    def samples(self, poses: NDArray) -> tuple[Indices, tuple[NDArray[np.float64], ...]]:
        """Every index (with detail) at ``poses``, and per chain its tree joints' values."""
        return indices_and_joint_values(self.mechanism, poses, tree_only=True, **self.keywords)

    def singular(self, path, joint_values) -> list[tuple[str, float, int]]:
        """Where a chain's joints are singular along ``path`` (:func:`~screwkit.closure.on_the_way.singular_along`:
        chain, arc length, the sample before), from its tree joints' values at the samples where they are all."""
        return singular_along(self.mechanism, path.poses, path.arc_length, lambda s: path.at(np.asarray(s)),
                              values=joint_values)

    def indices(self, poses: NDArray) -> Indices:
        return indices_at_poses(self.mechanism, poses, **self.keywords)

    def joint_values(self, poses: NDArray) -> list[NDArray[np.float64]]:
        """Per chain, its tree joints' values at ``poses`` (NaN where it does not close)."""
        values = solve(self.mechanism, poses, limits=self.analysis.limits).joint_values
        return [v[..., :len(chain.joints)] for v, chain in zip(values, self.chains)]

    def unreachable(self, pose: NDArray, status: NDArray) -> tuple[str, str]:
        """``(kind, reason)`` of an unreachable pose: ``"closure"`` or ``"joint limit"``, and the closure's words."""
        kind = "closure" if np.any(status == ChainStatus.MISSES_CLOSURE) else "joint limit"
        try:
            solve_one(self.mechanism, pose, limits=self.analysis.limits)
            return kind, "unreachable"
        except UnreachablePose as error:
            return kind, str(error)

    def working_modes(self) -> dict[str, str]:
        return working_modes(self.mechanism)


@dataclass(frozen=True)
class GraphPath(_Along):
    """A mechanism whose legs have loops inside them along a path: every pose closed by continuation from the
    file's configuration, so the working mode is the one that continuation reaches; a branch change between two
    samples is seen on the legs' revolute and prismatic joints (their ball joints turn with them)."""

    graph: GraphMechanism
    analysis: AnalysisOptions
    keywords: dict

    @property
    def chains(self) -> tuple[ChainJoints, ...]:
        model = self.graph.tree.model
        kinds = self.graph.kinematics.kinds
        return tuple(ChainJoints(leg.name, tuple(model.names[j] for j in self._joints(leg)),
                                 tuple(kinds[j] == "prismatic" for j in self._joints(leg))) for leg in self.graph.legs)

    @property
    def joint_coordinates(self) -> int:
        """The joint values kept per sample (the tree's configuration and each leg's joints)."""
        return self.graph.tree.model.nq + sum(len(self._joints(leg)) for leg in self.graph.legs)

    def _joints(self, leg) -> tuple[int, ...]:
        kinds = self.graph.kinematics.kinds
        return tuple(j for j in leg.joints if kinds[j] in ("revolute", "unbounded", "prismatic"))

    def _values(self, q: NDArray) -> list[NDArray[np.float64]]:
        """Per leg, its revolute and prismatic joints' values (rad, m) in configurations ``q`` (..., nq)."""
        kinematics = self.graph.kinematics
        values = []
        for leg in self.graph.legs:
            columns = []
            for joint in self._joints(leg):
                at = kinematics.idx_q[joint]
                columns.append(np.arctan2(q[..., at + 1], q[..., at]) if kinematics.kinds[joint] == "unbounded"
                               else q[..., at])
            values.append(np.stack(columns, axis=-1) if columns else np.zeros(q.shape[:-1] + (0,)))
        return values

    def samples(self, poses: NDArray) -> tuple[Indices, list[NDArray[np.float64]]]:
        indices, q = graph_indices_at_poses(self.graph, poses, configurations=True, **self.keywords)
        return indices, self._values(q)

    def singular(self, path, joint_values) -> list:
        """None looked for: the graph is closed whole, by continuation (no working-mode sign kept)."""
        return []

    def indices(self, poses: NDArray) -> Indices:
        return graph_indices_at_poses(self.graph, poses, **self.keywords)

    def joint_values(self, poses: NDArray) -> list[NDArray[np.float64]]:
        q, reached = self.graph.solve(poses, limits=self.analysis.limits)
        return self._values(np.where(reached[:, None], q, np.nan))

    def unreachable(self, pose: NDArray, status: NDArray) -> tuple[str, str]:
        """:meth:`~screwkit.io.GraphMechanism.unreachable` (``status`` is not needed: the graph is closed whole)."""
        return self.graph.unreachable(pose, limits=self.analysis.limits)

    def working_modes(self) -> dict[str, str]:
        mode = ("the one reached from the file's configuration by moving the platform straight to each pose "
                "(continuation)")
        return {leg.name: mode for leg in self.graph.legs}


@dataclass(frozen=True)
class ActuatedGraphPath(GraphPath):
    """A mechanism whose legs have loops inside them along a path its actuators drive (a :class:`Path` with
    ``configurations``, :func:`~screwkit.studies.actuator_paths.path_from_actuators`, its arc length along the
    actuators): the samples at the closed configurations the actuators reached; between two samples the actuators
    move linearly along the segment, the configuration there the one assembled from the two samples' configurations
    interpolated (:func:`~screwkit.io.graph_actuators.between_samples`), so the task coordinates may fold or stand
    still where the actuators do not."""

    path: Path | None = None
    found: dict = field(default_factory=dict, compare=False, repr=False)  # (configurations at arc lengths asked)

    def samples(self, poses: NDArray) -> tuple[Indices, list[NDArray[np.float64]]]:
        indices, q = graph_indices_at_poses(self.graph, poses, configurations=self.path.configurations,
                                            **self.keywords)
        return indices, self._values(q)

    def _closed(self, positions: NDArray) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The task poses (k, n_task) and closed configurations (k, nq; NaN where the closures cannot follow the
        actuators) at arc lengths ``positions`` (k,), each found once."""
        path, graph = self.path, self.graph
        wanted = np.clip(np.asarray(positions, dtype=float).reshape(-1), 0.0, path.length)
        segment, fraction = path.located(wanted)
        values = path.actuators[segment] + fraction[:, None] * (path.actuators[segment + 1] - path.actuators[segment])
        q = np.full((wanted.size, graph.kinematics.nq), np.nan)
        for row, (at, start, part, value) in enumerate(zip(wanted, segment, fraction, values)):
            if float(at) not in self.found:
                try:
                    self.found[float(at)] = between_samples(graph, path.configurations[start],
                                                            path.configurations[start + 1], part, value)
                except ValueError:
                    self.found[float(at)] = q[row].copy()
            q[row] = self.found[float(at)]
        poses = path.at(wanted)
        closed = np.isfinite(q).all(axis=1)
        poses[closed] = graph.frame_pose(q[closed])[:, list(graph.task_axes)]
        return poses, q

    def indices_along(self, path: Path, positions: NDArray) -> Indices:
        poses, q = self._closed(positions)
        return graph_indices_at_poses(self.graph, poses, configurations=q, **self.keywords)[0]

    def joint_values_along(self, path: Path, positions: NDArray) -> list[NDArray[np.float64]]:
        _, q = self._closed(positions)
        if self.analysis.limits:
            closed = np.isfinite(q).all(axis=1)
            q[closed] = np.where(beyond_limits(self.graph.kinematics, q[closed], self.graph.limited,
                                               self.graph.scale).any(axis=1)[:, None], np.nan, q[closed])
        return self._values(q)

    def unreachable_along(self, path: Path, position: float, status: NDArray) -> tuple[str, str]:
        """``"joint limit"`` where the actuators' configuration puts joints beyond their limits, else
        ``"closure"`` (the closures cannot follow the actuators there from the sample before)."""
        pose, q = self._closed(np.array([position]))
        graph = self.graph
        names = spelled_pose(graph.task_coordinates, pose[0])
        if np.isfinite(q[0]).all():
            beyond = joints_beyond_limits(graph.tree.model, graph.kinematics, q[0], graph.limited, graph.scale)
            return "joint limit", (f"{graph.tree.source}: at ({names}) the configuration the actuators reach puts "
                                   f"joints beyond their limits: {'; '.join(beyond)}")
        return "closure", (f"{graph.tree.source}: the closures do not close with the actuators between the samples "
                           f"either side, at arc length {position:.6g} m (out of reach, or past a singular "
                           "configuration)")

    def working_modes(self) -> dict[str, str]:
        mode = ("the one the actuators reach from the file's configuration, sample after sample (continuation in "
                "joint space)")
        return {leg.name: mode for leg in self.graph.legs}


def path_mechanism(mechanism: Any, analysis: AnalysisOptions, keywords: dict, path: Path | None = None
                   ) -> SerialPath | GraphPath:
    """The :class:`SerialPath` or :class:`GraphPath` of ``mechanism``, with the index keywords of ``analysis``
    (``keywords``: detail, threads, ...); for a graph along a ``path`` its actuators drive, an
    :class:`ActuatedGraphPath`; a ValueError when a graph is asked for what it does not have (closed forms, link
    faults)."""
    if isinstance(mechanism, GraphMechanism):
        check_graph_analysis(mechanism, analysis.closed_forms, analysis.fault_type)
        graph_keywords = {k: v for k, v in keywords.items() if k not in ("closed_forms", "fault_type")}
        if path is not None and path.configurations is not None:
            return ActuatedGraphPath(mechanism, analysis, graph_keywords, path)
        return GraphPath(mechanism, analysis, graph_keywords)
    return SerialPath(mechanism, analysis, keywords)


def check_path_size(along: SerialPath | GraphPath, samples: int, where: str = "the path",
                    available_bytes: int | None = None) -> None:
    """A ValueError, in one line, for a path whose samples would not fit in memory
    (:func:`~screwkit.studies.sizes.check_fits`), before anything is computed."""
    mechanism = along.graph if isinstance(along, GraphPath) else along.mechanism
    check_fits(samples, pose_bytes(mechanism, along.analysis.faults, along.joint_coordinates),
               f"{where} has {samples:,} samples", available_bytes)
