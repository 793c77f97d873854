"""What a scene draws of a mechanism whose legs have loops inside them (:class:`screwkit.io.GraphMechanism`).

Such a mechanism is drawn from its kinematic tree and its closures, not from visual geometry: every body of a leg as
a rod from the origin of the joint that carries it to each point where another joint or a closure holds it, and a
sphere at each of those points. The base and the platform are plates: each is drawn as the outline of the points
where the legs hold it (the joints it carries and the closure frames on it, with the platform's own joint): their
convex hull in their mean plane, and a spoke from their centre to each point inside it; not as spokes from the
body's frame, whose origin a CAD export may put far from the mechanism. The legs are coloured by their index as
serial chains are (each leg of a graph has one actuator), the base and the platform in their own colours, a failed
actuator's leg transparent red with a red cross at its joint. A graph's indices keep neither its actuation wrenches
nor its output twists, so no screw is drawn. No Meshcat and no Pinocchio here.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from screwkit.io.closed_tree import path_to
from screwkit.viewer.markers import ROOT_PATH, Frames, Marker, node_label

__all__ = ["Rod", "graph_rods", "solve_graph_frames", "graph_markers"]


@dataclass(frozen=True)
class Rod:
    """A straight piece of a body: from the origin of joint ``start`` (or, with ``start_point``, that point of its
    frame) to the origin of joint ``end``, or, with ``point``, to that point of joint ``start``'s frame (a closure
    frame on the body). ``owner``: the leg's index, ``"base"`` or ``"platform"``. ``sphere``: whether a sphere marks
    its end (a piece of an outline has none: its ends are marked as the joints and closure frames they are)."""

    label: str
    owner: int | str
    start: int
    end: int | None = None
    point: NDArray[np.float64] | None = None
    start_point: NDArray[np.float64] | None = None
    sphere: bool = True


def _owners(graph) -> dict[int, int | str]:
    """The owner of each joint's body: its leg, the platform's joint the platform (also where a leg carries it). Of a
    leg of several actuators read one at a time (copies of it, ``of`` its name), the copy whose actuator the body
    rides on (a five-bar leg's two sides), else the first."""
    owners: dict[int, int | str] = {0: "base"}
    for index, leg in enumerate(graph.legs):
        for joint in leg.joints:  # (a copy has one actuator; a passive leg, never a copy, none)
            if joint not in owners or not leg.of or leg.actuators[0] in path_to(graph.tree.model, joint):
                owners[joint] = index
    owners[graph.platform] = "platform"
    return owners


def graph_rods(graph) -> list[Rod]:
    """The rods of every body of a leg (from its joint to each child joint and to each closure frame on it), and
    the outlines of the base and the platform (:func:`_outline`)."""
    names = graph.tree.model.names
    kinematics = graph.kinematics
    parents = kinematics.parents
    owners = _owners(graph)
    plates = (0, graph.platform)
    rods = [Rod(f"{node_label(names[parents[joint]])}--{node_label(names[joint])}",
                owners.get(parents[joint], "base"), parents[joint], end=joint)
            for joint in range(1, len(parents)) if parents[joint] not in plates]
    vertices: dict[int, list[NDArray]] = {plate: [] for plate in plates}
    if kinematics.kinds[graph.platform] != "free":  # the joint carrying the platform holds it there
        vertices[graph.platform].append(np.zeros(3))
    for joint in range(1, len(parents)):
        plate = parents[joint]
        if plate not in plates or kinematics.kinds[joint] == "free":  # (a floating body is held nowhere)
            continue
        held = kinematics.placements[joint][:3, 3]
        vertices[plate].append(held)
        # from where the plate holds the joint to the joint's origin: nothing for a revolute or ball joint, the
        # travel for a prismatic one; its sphere marks the joint
        rods.append(Rod(f"{node_label(names[plate])}--{node_label(names[joint])}", owners.get(plate, "base"), plate,
                        end=joint, start_point=held))
    for closure in graph.tree.closures:
        for side, joint, placement in (("a", closure.joint_a, closure.placement_a),
                                       ("b", closure.joint_b, closure.placement_b)):
            at = np.asarray(placement, dtype=float)[:3, 3]
            on_plate = joint in plates  # a point of the outline: its sphere alone (a rod of no length)
            if on_plate:
                vertices[joint].append(at)
            rods.append(Rod(f"{node_label(closure.name)}--{side}", owners.get(joint, "base"), joint, point=at,
                            start_point=at if on_plate else None))
    for plate in plates:
        rods += _outline(plate, owners[plate], vertices[plate], graph.length_scale)
    return rods


def _outline(plate: int, owner: str, points: list[NDArray], length: float) -> list[Rod]:
    """The outline of a plate through ``points`` (its frame): their convex hull in their mean plane, with a spoke
    from their centre to each point inside it (such as the platform's joint), a polyline along them when they lie
    on a line, nothing for fewer than two distinct points."""
    unique: list[NDArray] = []
    for point in points:
        if all(np.linalg.norm(point - other) > 1e-9 * length for other in unique):
            unique.append(np.asarray(point, dtype=float))
    if len(unique) < 2:
        return []
    stacked = np.array(unique)
    centre = stacked.mean(axis=0)
    _, singular, directions = np.linalg.svd(stacked - centre)
    flat = (stacked - centre) @ directions[:2].T
    if len(unique) > 2 and singular[1] > 1e-6 * singular[0]:
        from scipy.spatial import ConvexHull  # the viewer's drawing of a graph only

        order = ConvexHull(flat).vertices  # counter-clockwise in the mean plane
        pieces = [(stacked[a], stacked[b]) for a, b in zip(order, np.roll(order, -1))]
        pieces += [(centre, stacked[i]) for i in np.setdiff1d(np.arange(len(unique)), order)]
    else:
        order = np.argsort(flat[:, 0], kind="stable")
        pieces = [(stacked[a], stacked[b]) for a, b in zip(order[:-1], order[1:])]
    return [Rod(f"{owner}--outline_{index}", owner, plate, point=end, start_point=start, sphere=False)
            for index, (start, end) in enumerate(pieces)]


def solve_graph_frames(graph, poses: NDArray, threshold: float, strict: bool, limits: bool = True) -> Frames:
    """The closed configurations and indices at ``poses`` (the unreachable ones left out, or with ``strict`` a
    ValueError naming the first), as :func:`screwkit.viewer.markers.solve_frames` gives them for serial legs;
    ``chain_points`` are each leg's joint origins."""
    from screwkit.studies.poses import graph_indices_at_poses  # graphs only

    result, q = graph_indices_at_poses(graph, poses, detail=True, threshold=threshold, configurations=True,
                                       limits=limits)
    reachable = np.asarray(result.reachable, dtype=bool).reshape(-1)
    kept = np.flatnonzero(reachable)
    if kept.size < reachable.size:
        if strict:
            raise ValueError(graph.unreachable(poses[int(np.flatnonzero(~reachable)[0])], limits=limits)[1] + ".")
        if not kept.size:
            raise ValueError(f"None of the {poses.shape[0]} poses is reachable for mechanism {graph.name!r}.")
        # each pose is closed and analysed alone (as in any batch): the reachable ones' rows are what a batch of
        # them alone would give, so they are taken, not solved again
        poses, result, q = poses[kept], result.at((kept,)), q[kept]
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
        ends[:, index, 0] = (frame[:, :3, 3] if rod.start_point is None
                             else frame[:, :3, :3] @ rod.start_point + frame[:, :3, 3])
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

    failed_legs = {graph.actuator_legs[actuator] for actuator in failed}  # (a passive leg has no actuator)

    def marker(path: str, kind: str, start: NDArray, end: NDArray, owner: int | str) -> Marker:
        leg = owner if isinstance(owner, int) else None
        return Marker(path, kind, None, start.copy(), end.copy(), failed=leg is not None and leg in failed_legs,
                      chain=leg, body=None if leg is not None else str(owner))

    every = []
    for frame in range(frames.configurations.shape[0]):
        markers: list[Marker] = []
        for index, rod in enumerate(rods):
            start, end = ends[frame, index]
            if np.linalg.norm(end - start) >= shortest:
                markers.append(marker(f"{ROOT_PATH}/links/{rod.label}", "link", start, end, rod.owner))
            if not rod.sphere:
                continue
            # a sphere where the rod ends: a joint (its own body's colour) or a closure frame (the rod's)
            label, owner = (names[rod.end], owners.get(rod.end, "base")) if rod.point is None else (rod.label,
                                                                                                 rod.owner)
            markers.append(marker(f"{ROOT_PATH}/joints/{node_label(label)}", "joint", end, end, owner))
        for actuator in failed:
            leg = graph.actuator_legs[actuator]
            joint = graph.legs[leg].actuators[0]
            label = node_label(graph.actuators[actuator])
            path = f"{ROOT_PATH}/failed/{actuator}-{label}"
            markers.append(Marker(path, "failed_actuator", actuator, origins[frame, joint].copy(),
                                  origins[frame, joint].copy(), failed=True, chain=leg))
        every.append(tuple(markers))
    return tuple(every)
