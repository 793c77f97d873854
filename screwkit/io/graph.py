r"""Closed-loop graphs: legs with loops inside them (parallelograms of ball-jointed rods), at the file's configuration.

:mod:`screwkit.io.star` writes a closed tree as legs that are serial chains, each closed onto the platform by one
loop joint. A leg whose forearm is a parallelogram of two ball-jointed rods (every industrial Delta) is not one:
two closures end on the platform through the same actuated path. This module analyses such mechanisms from the
graph itself, following the paper's definitions leg by leg (``docs/theory.md``, *Legs with loops inside*):

* **legs**: the bodies other than the base and the platform, joined by tree joints and closures, fall into
  connected groups; a group joined to both the base and the platform is a **leg**, one joined to the platform only
  is a tool carried by the platform (a gripper: left out, said in the report), one joined to the base only an idle
  branch (left out, said);
* a leg's **twist system** :math:`S_i`: the platform-twist part of the null space of the leg's closure Jacobian
  (:func:`screwkit.io.compound.platform_twists`: the rates of the leg's joints and the platform twist as unknowns,
  one block of rows per closure of the leg); with actuator ``k`` locked, :math:`S_i^k`. Idle motions (a rod
  spinning about its own axis between two ball joints) lie in the null space but move no platform twist: they
  drop out by construction;
* the leg's **actuation wrench**: reciprocal to :math:`S_i^k` and not to :math:`S_i` -- for a serial leg, the
  paper's wrench reciprocal to every passive joint, since :math:`S_i^k` is then their span. It is computed by
  :func:`screwkit.indices.analysis.analyze` from an **equivalent chain**: the actuated joint's own twist followed
  by a basis of :math:`S_i^k`. That chain spans :math:`S_i` when the actuated joint's twist is itself a motion of
  the leg (the actuated joint joins the base to the rest of the leg: every leg of a Delta, of a Stewart platform,
  of any leg driven from the base); a leg whose actuated joint moves inside one of its loops is refused with the
  loop named. The representative modulo the leg's constraint wrenches is screwkit's usual one (least norm in
  working coordinates, moments about the leg's platform point), which for a parallelogram of rods is the force
  along the rods through the line midway between them;
* **characteristic points**: for the ITI, the centroid of the joints by which the rest of the leg hangs on the
  actuated link (the first joint after the actuator for a serial leg; the midpoint of the two rod joints on a
  Delta's arm); for the OTI, the centroid of the leg's joints on the platform (its platform joint; the midpoint of
  the two rod joints on the platform). Each is projected on the wrench axis as for a serial chain.

The rows of an equivalent chain other than the actuator's carry the leg's platform point; with the actuator's
own point they set the working length ``L`` of :func:`~screwkit.indices.analysis.analyze`.

The indices are those of the configuration the file's closures assemble into (:func:`screwkit.io.closed_tree.
assemble`), or of another platform pose (:meth:`GraphMechanism.at_pose`: the same closures plus one that holds the
output frame at the pose, solved from the file's configuration, so the working mode is the nearest one); the
output is the platform frame.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from screwkit.common.rotations import rotation_from_rpy
from screwkit.io.closed_tree import (
    ClosedTree,
    Closure,
    ImportError_,
    ImportReport,
    assemble,
    closure_gaps,
    homogeneous,
    joint_kind,
    joint_value,
    path_to,
)
from screwkit.io.compound import platform_twists
from screwkit.io.star import output_frame
from screwkit.screw.chain_screws import ChainScrews

__all__ = ["GraphLeg", "GraphMechanism", "graph_legs", "graph_mechanism", "IN_LOOP_TOLERANCE"]

IN_LOOP_TOLERANCE = 1e-8
"""Distance (working coordinates, unit twist) of an actuated joint's twist from its leg's twist system above
which the joint moves inside a loop of the leg (its twist is not a motion of the leg)."""


@dataclass(frozen=True)
class GraphLeg:
    """One leg of a closed-loop graph: its joints (Pinocchio joint ids, the platform's own joint when the platform
    hangs on the leg: ``spine``), the closures with an end on it, and its actuated joints."""

    name: str
    joints: tuple[int, ...]
    closures: tuple[Closure, ...]
    spine: bool
    actuators: tuple[int, ...]


@dataclass(frozen=True)
class GraphMechanism:
    """A closed-loop graph assembled at a configuration ``q`` (the file's, or a pose's): its platform (joint id), its
    legs, and the chain screws of its legs' equivalent chains with their ITI and OTI points
    (:func:`graph_mechanism`)."""

    name: str
    tree: ClosedTree
    q: NDArray[np.float64]
    scale: float
    platform: int
    platform_body: str
    legs: tuple[GraphLeg, ...]
    chains: tuple[ChainScrews, ...]
    iti_points: NDArray[np.float64]
    oti_points: NDArray[np.float64]
    report: ImportReport

    def at_pose(self, position, rpy=None) -> GraphMechanism:
        """The mechanism with its output frame at ``position`` (m, world frame) and orientation ``rpy`` (rad; default
        the one it has), closed from this configuration (the nearest working mode). A ValueError names the pose
        when no closed configuration near this one puts the frame there."""
        import pinocchio as pin  # Pinocchio: imported where a file of another tool is read

        model = self.tree.model
        data = model.createData()
        pin.framesForwardKinematics(model, data, self.q)
        frame_id = output_frame(self.tree)
        target = homogeneous(data.oMf[frame_id])
        position = np.asarray(position, dtype=float).reshape(-1)
        if position.shape != (3,) or not np.all(np.isfinite(position)):
            raise ValueError(f"Expected a finite position (x, y, z), got {position.tolist()}.")
        target[:3, 3] = position
        if rpy is not None:
            target[:3, :3] = rotation_from_rpy(np.asarray(rpy, dtype=float))
        frame = model.frames[frame_id]
        holding = Closure("pose", 0, target, int(frame.parentJoint), homogeneous(frame.placement), "6d")
        posed = replace(self.tree, closures=[*self.tree.closures, holding], q_reference=self.q, notes=[])
        try:
            q, _ = assemble(posed)
        except ImportError_:
            raise ValueError(f"{self.tree.source}: no closed configuration near the current one puts the output frame "
                             f"at {np.round(position, 9).tolist()} m"
                             + ("" if rpy is None else f", rpy {np.round(np.degrees(rpy), 9).tolist()} deg")
                             + " (out of reach, or a rotation the legs do not allow).") from None
        if posed.notes:  # closed only to a rounding: the pose is not exactly reachable
            raise ValueError(f"{self.tree.source}: the output frame cannot be put exactly at "
                             f"{np.round(position, 9).tolist()} m: {posed.notes[-1]}.")
        return graph_mechanism(self.tree, q=q, scale=self.scale)

    def indices(self, **options):
        """Every index at this configuration (:func:`screwkit.indices.analysis.analyze`'s options)."""
        from screwkit.indices.analysis import analyze  # the index layer, above io: only when indices are asked

        options.setdefault("detail", True)
        result = analyze(self.chains, iti_points=self.iti_points, oti_points=self.oti_points, **options)
        model = self.tree.model
        values, prismatic = {}, []
        for leg in self.legs:
            for joint in leg.joints:
                kind, _ = joint_kind(model, joint)
                if kind in ("revolute", "prismatic"):
                    name = f"{leg.name}:{model.names[joint]}"
                    values[name] = joint_value(model, joint, self.q)
                    if kind == "prismatic":
                        prismatic.append(name)
        mode = "as the file's closures assemble from its joint values (at another pose: the nearest to it)"
        return replace(result, mechanism=self.name, joint_values=values, prismatic_joints=tuple(prismatic),
                       working_mode={leg.name: mode for leg in self.legs})


def _groups(model, closures: list[Closure], platform: int) -> list[list[int]]:
    """Bodies (joint ids) other than the base and the platform, in connected groups (tree joints and closures)."""
    leader = list(range(model.njoints))

    def find(body: int) -> int:
        while leader[body] != body:
            leader[body] = leader[leader[body]]
            body = leader[body]
        return body

    def join(a: int, b: int) -> None:
        if {a, b} & {0, platform}:
            return
        leader[find(a)] = find(b)

    for body in range(1, model.njoints):
        join(body, model.parents[body])
    for closure in closures:
        join(closure.joint_a, closure.joint_b)
    groups: dict[int, list[int]] = {}
    for body in range(1, model.njoints):
        if body != platform:
            groups.setdefault(find(body), []).append(body)
    return list(groups.values())


def graph_legs(tree: ClosedTree, platform: int, report: ImportReport) -> list[GraphLeg]:
    """The legs of a closed tree whose platform body is joint ``platform`` (tools and idle branches said in
    ``report``)."""
    model = tree.model
    motors = {model.getJointId(name): name for name in tree.motors if model.existJointName(name)}
    body_names = {int(f.parentJoint): f.name for f in reversed(list(model.frames)) if str(f.type) == "BODY"}
    legs, placed = [], set()
    for group in _groups(model, tree.closures, platform):
        members = set(group)
        ends = [c for c in tree.closures if {c.joint_a, c.joint_b} & members]
        touches = {model.parents[b] for b in group} | {j for c in ends for j in (c.joint_a, c.joint_b)}
        spine = model.parents[platform] in members
        to_base, to_platform = 0 in touches, platform in touches or spine
        names = ", ".join(sorted(model.names[b] for b in group))
        actuated = tuple(sorted(j for j in motors if j in members or (spine and j == platform)))
        if not (to_base and to_platform):
            what = "a tool carried by the platform" if to_platform else "a branch of the base"
            report.notes.append(f"joints {names}: {what}, not a leg: left out"
                                + (f" (with its actuators {', '.join(motors[j] for j in actuated)})"
                                   if actuated else ""))
            placed.update(actuated)
            continue
        joints = tuple(sorted(group + ([platform] if spine else [])))
        first = min(group, key=lambda b: (len(path_to(model, b)), b))
        legs.append(GraphLeg(body_names.get(first, model.names[first]), joints, tuple(ends), spine, actuated))
        placed.update(actuated)
    if model.parents[platform] == 0:
        kind, _ = joint_kind(model, platform)
        if model.joints[platform].nv != 6:
            raise ImportError_(f"{tree.source}: the platform body is joined to the base by joint "
                               f"{model.names[platform]!r} ({kind}): a leg without links, which screwkit does not "
                               "analyse; free the platform (a free joint) or join it through a leg.")
    for joint, name in motors.items():
        if joint not in placed:
            raise ImportError_(f"{tree.source}: actuated joint {name!r} is on no leg (a leg joins the base to the "
                               "platform).")
    return sorted(legs, key=lambda leg: leg.name)


def _attachments(tree: ClosedTree, data, leg: GraphLeg, body: int) -> list[NDArray]:
    """World points where the leg's joints (to its children) and closures meet ``body``."""
    model = tree.model
    points = [np.asarray(data.oMi[j].translation) for j in leg.joints if model.parents[j] == body]
    for closure in leg.closures:
        for joint, placement in ((closure.joint_a, closure.placement_a), (closure.joint_b, closure.placement_b)):
            if joint == body:
                points.append((np.asarray(data.oMi[joint].homogeneous) @ placement)[:3, 3])
    return points


def _equivalent_chain(tree: ClosedTree, data, leg: GraphLeg, platform: int, centre: NDArray, scale: float):
    """The leg's equivalent chain (actuated joint's twist, then a basis of the twists the leg allows with the
    actuator locked) in world coordinates, with its ITI and OTI points."""
    import pinocchio as pin  # Pinocchio: imported where a file of another tool is read

    model = tree.model
    if len(leg.actuators) != 1:
        raise ImportError_(f"{tree.source}: leg {leg.name!r} has loops inside it and "
                           f"{len(leg.actuators) or 'no'} actuators: screwkit analyses such a leg with exactly "
                           "one (a leg with loops and several actuators has no per-actuator twist system yet).")
    actuator = leg.actuators[0]
    kind, _ = joint_kind(model, actuator)
    if kind not in ("revolute", "prismatic"):
        raise ImportError_(f"{tree.source}: actuated joint {model.names[actuator]!r} is {kind}: an actuator drives "
                           "one revolute or prismatic joint.")
    closures = list(leg.closures)
    allowed = platform_twists(model, data, list(leg.joints), closures, platform, leg.spine, centre, scale)
    locked = platform_twists(model, data, [j for j in leg.joints if j != actuator], closures, platform, leg.spine,
                             centre, scale)
    jacobian = np.asarray(pin.getJointJacobian(model, data, actuator, pin.ReferenceFrame.WORLD))
    column = jacobian[:, model.joints[actuator].idx_v]
    omega, velocity = column[3:], column[:3]
    own = np.concatenate([omega, (velocity - np.cross(centre, omega)) / scale])
    own = own / np.linalg.norm(own)
    outside = np.linalg.norm(own - own @ allowed.T @ allowed) if len(allowed) else 1.0
    if outside > IN_LOOP_TOLERANCE or len(locked) != len(allowed) - 1:
        raise ImportError_(f"{tree.source}: actuated joint {model.names[actuator]!r} moves inside a loop of leg "
                           f"{leg.name!r} (its twist is not a motion the leg allows: the leg has no serial input); "
                           "analysable when the actuated joint joins the base to the rest of its leg.")
    rows = np.vstack([own, locked])
    world = np.concatenate([rows[:, :3], rows[:, 3:] * scale + np.cross(centre, rows[:, :3])], axis=1)
    iti = _attachments(tree, data, leg, actuator)
    oti = _attachments(tree, data, leg, platform)
    if leg.spine:
        oti.append(np.asarray(data.oMi[platform].translation))
    if not iti or not oti:
        raise ImportError_(f"{tree.source}: leg {leg.name!r}: no joint after its actuator or none on the platform.")
    iti_point, oti_point = np.mean(iti, axis=0), np.mean(oti, axis=0)
    points = np.vstack([np.asarray(data.oMi[actuator].translation)] + [oti_point] * len(locked))
    names = (model.names[actuator],) + tuple(f"{leg.name}_twist_{k + 1}" for k in range(len(locked)))
    return ChainScrews(world, points, (0,), leg.name, names), iti_point, oti_point


def graph_mechanism(tree: ClosedTree, q: NDArray | None = None, scale: float | None = None) -> GraphMechanism:
    """The closed tree assembled at the file's configuration (or at ``q``, a closed configuration, with the length
    scale ``scale``), its legs and their equivalent chains."""
    import pinocchio as pin  # Pinocchio: imported where a file of another tool is read

    model = tree.model
    report = ImportReport(source=tree.source, file_format=tree.file_format)
    if q is None or scale is None:
        q, scale = assemble(tree)
    frame = model.frames[output_frame(tree)]
    report.notes[:0] = tree.notes
    platform = int(frame.parentJoint)
    if platform == 0:
        raise ImportError_(f"{tree.source}: the output frame {frame.name!r} is on the fixed base.")
    bodies = {int(f.parentJoint): f.name for f in reversed(list(model.frames)) if str(f.type) == "BODY"}
    report.platform_body = bodies.get(platform, model.names[platform])
    legs = graph_legs(tree, platform, report)
    if not legs:
        raise ImportError_(f"{tree.source}: no leg joins the base to the platform {report.platform_body!r}.")
    data = model.createData()
    pin.computeJointJacobians(model, data, q)
    pin.forwardKinematics(model, data, q)
    centre = np.asarray(data.oMi[platform].translation)
    chains, iti_points, oti_points = [], [], []
    for leg in legs:
        chain, iti, oti = _equivalent_chain(tree, data, leg, platform, centre, scale)
        chains.append(chain)
        iti_points.append(iti)
        oti_points.append(oti)
    gaps = closure_gaps(tree, tree.q_reference)
    report.gaps_before, report.gaps_after = gaps, closure_gaps(tree, q)
    report.motors = [model.names[leg.actuators[0]] for leg in legs]
    report.chains = [f"{leg.name}: {len(leg.joints)} joints ({', '.join(model.names[j] for j in leg.joints)}), "
                     f"{len(leg.closures)} closure(s), twist system of dimension {len(chain.twists)}"
                     for leg, chain in zip(legs, chains)]
    report.notes.append("legs with loops inside them: analysed as a graph at the file's configuration "
                        "(screwkit.io.graph)")
    report.output = f"the frame of body {report.platform_body!r}"
    return GraphMechanism(Path(tree.source).stem, tree, q, scale, platform, report.platform_body, tuple(legs),
                          tuple(chains), np.array(iti_points), np.array(oti_points), report)

