"""What a scene draws of a mechanism whose legs have loops inside them (:class:`screwkit.io.GraphMechanism`).

Such a mechanism is drawn from its kinematic tree and its closures, not from visual geometry: every body as a rod
from the origin of the joint that carries it to each point where another joint or a closure holds it, and a sphere
at each of those points. The legs are coloured by their index as serial chains are (each leg of a graph has one
actuator), the base and the platform in their own colours, a failed actuator's leg transparent red with a red cross
at its joint. A graph's indices keep neither its actuation wrenches nor its output twists, so no screw is drawn.
No Meshcat and no Pinocchio here.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from screwkit.viewer.markers import ROOT_PATH, Frames, Marker, node_label

__all__ = ["Rod", "graph_rods", "solve_graph_frames", "graph_markers"]


@dataclass(frozen=True)
class Rod:
    """A straight piece of a body: from the origin of joint ``start`` to the origin of joint ``end``, or, with
    ``point``, to that point of joint ``start``'s frame (a closure frame on the body). ``owner``: the leg's index,
    ``"base"`` or ``"platform"``."""

    label: str
    owner: int | str
    start: int
    end: int | None = None
    point: NDArray[np.float64] | None = None


def _owners(graph) -> dict[int, int | str]:
    """The owner of each joint's body: its leg, the platform's joint the platform (also where a leg carries it)."""
    owners: dict[int, int | str] = {0: "base"}
    for index, leg in enumerate(graph.legs):
        owners.update({joint: index for joint in leg.joints})
    owners[graph.platform] = "platform"
    return owners


def graph_rods(graph) -> list[Rod]:
    """The rods of every body: from its joint to each child joint, and to each closure frame on it."""
    names = graph.tree.model.names
    parents = graph.kinematics.parents
    owners = _owners(graph)
    rods = [Rod(f"{node_label(names[parents[joint]])}--{node_label(names[joint])}",
                owners.get(parents[joint], "base"), parents[joint], end=joint) for joint in range(1, len(parents))]
    for closure in graph.tree.closures:
        for side, joint, placement in (("a", closure.joint_a, closure.placement_a),
                                       ("b", closure.joint_b, closure.placement_b)):
            rods.append(Rod(f"{node_label(closure.name)}--{side}", owners.get(joint, "base"), joint,
                            point=np.asarray(placement, dtype=float)[:3, 3]))
    return rods


def solve_graph_frames(graph, poses: NDArray, threshold: float, strict: bool) -> Frames:
    """The closed configurations and indices at ``poses`` (the unreachable ones left out, or with ``strict`` a
    ValueError naming the first), as :func:`screwkit.viewer.markers.solve_frames` gives them for serial legs;
    ``chain_points`` are each leg's joint origins."""
    from screwkit.studies.poses import graph_indices_at_poses  # graphs only

    result, q = graph_indices_at_poses(graph, poses, detail=True, threshold=threshold, configurations=True)
    reachable = np.asarray(result.reachable, dtype=bool).reshape(-1)
    kept = np.flatnonzero(reachable)
    if kept.size < reachable.size:
        if strict:
            raise ValueError(graph.unreachable(poses[int(np.flatnonzero(~reachable)[0])])[1] + ".")
        if not kept.size:
            raise ValueError(f"None of the {poses.shape[0]} poses is reachable for mechanism {graph.name!r}.")
        poses = poses[kept]  # each pose is closed alone as in any batch: the same configurations again
        result, q = graph_indices_at_poses(graph, poses, detail=True, threshold=threshold, configurations=True)
    transforms = graph.kinematics.transforms(q)
    return Frames(poses=np.asarray(poses), configurations=q,
                  chain_points=[transforms[:, list(leg.joints), :3, 3] for leg in graph.legs],
                  centres=graph.frame_pose(q)[:, :3], result=result, kept=kept)


def _rod_ends(rods: list[Rod], transforms: NDArray) -> NDArray[np.float64]:
    """(frames, rods, 2, 3): the two ends of every rod, world frame, from the joints' world placements
    ``transforms`` (frames, joints, 4, 4)."""
    ends = np.empty((transforms.shape[0], len(rods), 2, 3))
    for index, rod in enumerate(rods):
        frame = transforms[:, rod.start]
        ends[:, index, 0] = frame[:, :3, 3]
        ends[:, index, 1] = (transforms[:, rod.end, :3, 3] if rod.point is None
                             else frame[:, :3, :3] @ rod.point + frame[:, :3, 3])
    return ends


def graph_markers(graph, frames: Frames, failed: tuple[int, ...]) -> tuple[tuple[Marker, ...], ...]:
    """Per frame, the rods and joint spheres of every body and a cross at each failed actuator's joint (see the
    module docstring); a rod shorter than 1e-9 length scales (two joints at one point) is left out."""
    rods = graph_rods(graph)
    transforms = graph.kinematics.transforms(frames.configurations)
    ends = _rod_ends(rods, transforms)
    names = graph.tree.model.names
    owners = _owners(graph)
    origins = transforms[:, :, :3, 3]
    shortest = 1e-9 * float(graph.length_scale)

    def marker(path: str, kind: str, start: NDArray, end: NDArray, owner: int | str) -> Marker:
        leg = owner if isinstance(owner, int) else None
        return Marker(path, kind, None, start.copy(), end.copy(), failed=leg is not None and leg in failed,
                      chain=leg, body=None if leg is not None else str(owner))

    every = []
    for frame in range(frames.configurations.shape[0]):
        markers: list[Marker] = []
        for index, rod in enumerate(rods):
            start, end = ends[frame, index]
            if np.linalg.norm(end - start) >= shortest:
                markers.append(marker(f"{ROOT_PATH}/links/{rod.label}", "link", start, end, rod.owner))
            # a sphere where the rod ends: a joint (its own body's colour) or a closure frame (the rod's)
            label, owner = (names[rod.end], owners.get(rod.end, "base")) if rod.point is None else (rod.label,
                                                                                                 rod.owner)
            markers.append(marker(f"{ROOT_PATH}/joints/{node_label(label)}", "joint", end, end, owner))
        for actuator in failed:
            joint = graph.legs[actuator].actuators[0]
            label = node_label(graph.actuators[actuator])
            path = f"{ROOT_PATH}/failed/{actuator}-{label}"
            markers.append(Marker(path, "failed_actuator", actuator, origins[frame, joint].copy(),
                                  origins[frame, joint].copy(), failed=True, chain=actuator))
        every.append(tuple(markers))
    return tuple(every)
