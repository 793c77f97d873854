"""Compound legs: legs of a closed tree joined to each other by closures that do not touch the platform.

Gepetto's ``robot_delta`` is the example: its second motor drives a rod whose distal link is also
pinned to a passive rod, the two forming parallelograms that keep the effector from rotating. No
serial chain runs from the base to the platform on links of its own, so screwkit's convention
(legs, each a serial chain closed onto the platform) cannot write the leg as it is.

**What a compound leg contributes.** The paper's indices need, per leg, the twists the leg lets
the platform make (its *twist system*, whose reciprocal wrenches are the leg's constraint
wrenches) and, per actuator, an actuation wrench: reciprocal to every platform twist the leg
allows with that actuator locked. For a compound leg with one actuator:

* the **twist system** S_g is the platform-twist part of the null space of the leg's closure
  Jacobian (:func:`platform_twists`: every joint rate of the leg and the platform twist as
  unknowns, one block of rows per closure of the leg, in the working coordinates of
  :func:`screwkit.indices.analysis.analyze`);
* the **actuated path**, the tree path from the base through the actuator to the platform, is a
  serial chain, and every motion of the leg moves it: the platform twist of any leg motion is a
  combination of the path's joint twists, with the actuator's rate when the actuator moves and
  without it when it is locked. So the path's actuation wrench (reciprocal to its passive joints)
  is reciprocal to every twist of the leg with the actuator locked: it is an actuation wrench of
  the leg, and the ITI is the path's (the actuator's own screw, the next joint's point);
* the leg's remaining constraint is carried by an **equivalent constraint chain** replacing its
  passive legs: slides spanning every translation (the plane's two for a planar mechanism) and
  revolutes along R_g, the rotations S_g allows. It is exact when S_path ∩ (translations ⊕ R_g)
  = S_g (the leg constrains only rotations beyond what its actuated path does) and R_g is the
  same at every closed configuration: then the platform's orientation stays in one family, and
  the platform's motion space and every chain's constraint wrenches are those of the leg. This
  holds for planar parallelogram legs (R_g = 0: the effector translates); a spatial Delta forearm
  with ball joints does not meet it (the rotations it allows turn with the forearm), nor does a
  four-bar that is not a parallelogram. :func:`equivalent_constraint` checks both conditions at
  several closed configurations and raises :class:`NotReducible` with the reason when they
  fail, or when R_g has two dimensions (rotations about two fixed axes do not make one family
  of orientations).

The passive legs' own reach (link lengths limiting the workspace) is not carried over; a link
fault (``fault_type="link"``) of the actuated path leaves the equivalent chain in place.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from screwkit.common.rotations import skew_matrix
from screwkit.common.tolerances import FILE_ROUNDING
from screwkit.io.closed_tree import (
    GRAPH_HINT,
    ClosedTree,
    Closure,
    ImportError_,
    ImportReport,
    LegWithLoops,
    assemble,
    ball_line,
    homogeneous,
    joint_kind,
    path_to,
)

__all__ = ["NotReducible", "compound_groups", "platform_twists", "Reduction", "equivalent_constraint", "closed_samples",
           "compound_legs",
           "TWIST_RANK_TOLERANCE", "SUBSPACE_TOLERANCE",
           "CONSTANT_TOLERANCE"]

TWIST_RANK_TOLERANCE = 1e-9
"""Singular values of a closure Jacobian (working coordinates), relative to the largest, counted as zero where
closures are solved at the configurations of a study (:mod:`screwkit.io.graph`)."""

SUBSPACE_TOLERANCE = 10 * FILE_ROUNDING
"""Singular values (of unit twists in working coordinates) below which two twist spaces count as sharing a
direction, a leg as allowing no rotation about one, or a null-space direction as not moving the platform. What a
leg allows has parts of order one. A twist system read through a closure Jacobian whose rounding (at most
:data:`~screwkit.common.tolerances.FILE_ROUNDING`) was taken as zero is off by that over the smallest singular value
kept, 0.1 or more in a leg away from its singularities (0.18-0.27 on the published spatial Delta, whose rounding,
3.5e-7, moves its twist systems by about 2e-6); closures solved to 1e-10 leave about 1e-8. A four-bar whose
opposite sides differ by more than this (relative) is not a parallelogram."""

CONSTANT_TOLERANCE = SUBSPACE_TOLERANCE
"""Largest change of the projector on R_g between closed configurations for R_g to count as constant: a rotation
that turns with a forearm changes it by about the 0.2 rad the samples move; rounding, as much as it moves a twist
system (above)."""


class NotReducible(ValueError):
    """A compound leg screwkit cannot write as serial chains (the message says why)."""


def compound_groups(model, legs: list[list[int]], couplings: list) -> list[tuple[list[int], list]]:
    """The legs joined by ``couplings`` (closures between two legs): per group, the leg indices and its couplings.

    A closure frame on a branch that belongs to no leg (a rod closed only onto other legs) joins
    the legs its branch's other closures reach: branches are keyed by their first joint.
    """
    owner = {joint: index for index, joints in enumerate(legs) for joint in joints}
    parent: dict = {}

    def find(key):
        parent.setdefault(key, key)
        while parent[key] != key:
            parent[key] = parent[parent[key]]
            key = parent[key]
        return key

    keys = []
    for closure in couplings:
        sides = []
        for joint in (closure.joint_a, closure.joint_b):
            path = path_to(model, joint)
            held = [owner[j] for j in path if j in owner]
            sides.append(("leg", held[0]) if held else ("branch", path[0] if path else 0))
        parent[find(sides[1])] = find(sides[0])
        keys.append(sides[0])
    groups: dict = {}
    for closure, key in zip(couplings, keys):
        groups.setdefault(find(key), ([], []))[1].append(closure)
    for index in range(len(legs)):
        root = find(("leg", index))
        if root in groups:
            groups[root][0].append(index)
    return [group for group in groups.values()]


def platform_twists(model, data, joints: list[int], closures: list, platform: int, spine: bool, centre: NDArray,
                    scale: float) -> tuple[NDArray[np.float64], float]:
    """Orthonormal rows (k, 6) spanning the platform twists a set of joints allows with its closures closed, and the
    largest singular value of the closure Jacobian (relative) taken as the file's rounding (0.0 when none).

    Twists in working coordinates ``(omega, v_centre / scale)``. Unknowns: the rates of ``joints``
    and the platform twist T. Each closure adds the relative velocity of its two frames (6 rows for
    ``6d``, the velocity of its point for ``3d``); a frame whose path passes the platform moves with
    T plus the joints of ``joints`` beyond the platform, unless ``spine`` (the platform's own path
    is among ``joints``): then T is tied to the platform body's twist. Needs
    ``pinocchio.computeJointJacobians`` at the configuration. Singular values at or below
    :data:`~screwkit.common.tolerances.FILE_ROUNDING` times the largest (at least 1) count as zero: an
    overconstrained loop whose axes or lengths are rounded (a parallelogram of hinges) moves as drawn.
    """
    import pinocchio as pin  # Pinocchio: imported where a file of another tool is read

    columns = [model.joints[j].idx_v + k for j in sorted(set(joints)) for k in range(model.joints[j].nv)]

    def working(joint: int) -> NDArray:
        jacobian = np.asarray(pin.getJointJacobian(model, data, joint, pin.ReferenceFrame.WORLD))
        angular = jacobian[3:]
        return np.vstack([angular, (jacobian[:3] - skew_matrix(centre) @ angular) / scale])

    blocks = []
    for closure in closures:
        rows_q, rows_t = 0.0, 0.0
        for joint, placement, sign in ((closure.joint_a, closure.placement_a, 1.0),
                                       (closure.joint_b, closure.placement_b, -1.0)):
            world = np.asarray(data.oMi[joint].homogeneous) @ placement
            offset = (world[:3, 3] - centre) / scale
            select = np.hstack([-skew_matrix(offset), np.eye(3)]) if closure.kind == "3d" else np.eye(6)
            rows_q = rows_q + sign * select @ working(joint)[:, columns]
            if not spine and platform in path_to(model, joint):
                rows_t = rows_t + sign * select
        blocks.append(np.hstack([rows_q, np.broadcast_to(rows_t, (rows_q.shape[0], 6))]))
    if spine:
        blocks.append(np.hstack([working(platform)[:, columns], -np.eye(6)]))
    matrix = np.vstack(blocks) if blocks else np.zeros((0, len(columns) + 6))
    _, singular, right = np.linalg.svd(matrix, full_matrices=True)
    largest = max(float(singular[0]) if singular.size else 0.0, 1.0)
    rank = int(np.sum(singular > FILE_ROUNDING * largest))
    rounding = singular[rank:][singular[rank:] > TWIST_RANK_TOLERANCE * largest]
    twists = right[rank:, -6:]  # the T part of the null space
    left, values, rows = np.linalg.svd(twists, full_matrices=False)
    return rows[:int(np.sum(values > SUBSPACE_TOLERANCE))], float(rounding.max() / largest) if rounding.size else 0.0


def _dimension(rows: NDArray) -> int:
    if rows.shape[0] == 0:
        return 0
    singular = np.linalg.svd(rows, compute_uv=False)
    return int(np.sum(singular > SUBSPACE_TOLERANCE * max(float(singular[0]), 1.0)))


@dataclass(frozen=True)
class Reduction:
    """A compound leg written as its actuated path plus an equivalent constraint chain.

    ``translations`` (t, 3) and ``rotations`` (r, 3): world unit directions of the chain's slides
    and revolutes (no chain is needed when the leg constrains nothing beyond its actuated path:
    ``needed`` False); ``dimension``: of the leg's twist system; ``samples``: closed
    configurations at which the equivalence was checked.
    """

    translations: NDArray[np.float64]
    rotations: NDArray[np.float64]
    needed: bool
    dimension: int
    samples: int


def equivalent_constraint(twist_systems: list[NDArray], path_systems: list[NDArray],
                          normal: NDArray | None) -> Reduction:
    """The equivalent constraint chain of a compound leg, checked at closed configurations.

    ``twist_systems``: the leg's twist system at each configuration (:func:`platform_twists`);
    ``path_systems``: its actuated path's (all twists when the leg has no actuator); ``normal``:
    a planar mechanism's plane normal (world), else None. Raises :class:`NotReducible`.
    """
    translations = np.eye(3) if normal is None else np.linalg.svd(np.outer(normal, normal))[0][:, 1:].T
    projectors, dimensions = [], set()
    for leg, path in zip(twist_systems, path_systems):
        dimensions.add(leg.shape[0])
        angular = leg[:, :3]
        values, rows = np.linalg.svd(angular, full_matrices=False)[1:]
        rotations = rows[:int(np.sum(values > SUBSPACE_TOLERANCE))]
        slides = np.hstack([np.zeros((translations.shape[0], 3)), translations])
        equivalent = np.vstack([slides, np.hstack([rotations, np.zeros((rotations.shape[0], 3))])])
        if _dimension(np.vstack([equivalent, leg])) != equivalent.shape[0]:
            raise NotReducible("its twists leave the plane of motion")
        meet = path.shape[0] + equivalent.shape[0] - _dimension(np.vstack([path, equivalent]))
        if meet != leg.shape[0]:
            raise NotReducible(f"its constraint is not one of rotations about fixed directions: the actuated path "
                               f"and the leg's translations and rotations share {meet} twists, the leg has "
                               f"{leg.shape[0]}")
        projectors.append(rotations.T @ rotations)
    change = max(float(np.max(np.abs(p - projectors[0]))) for p in projectors)
    if len(dimensions) != 1 or change > CONSTANT_TOLERANCE:
        raise NotReducible(f"the rotations it allows change between closed configurations (by {change:.2g}): "
                           "no serial chain of constant geometry is equivalent")
    rank = int(round(np.trace(projectors[0])))
    free = 1 if normal is not None else 3
    if normal is None and rank == 2:
        raise NotReducible("it allows rotations about two fixed directions, which do not form one family of "
                           "orientations")
    axes = np.linalg.eigh(projectors[0])[1][:, ::-1][:, :rank].T
    return Reduction(translations, axes, rank < free, twist_systems[0].shape[0], len(twist_systems))


def closed_samples(tree: ClosedTree, q: NDArray, scale: float, count: int = 4) -> list[NDArray]:
    """Closed configurations near q (random joint offsets of up to 0.2 rad, or 0.2 length scales, closed again)."""
    import pinocchio as pin  # Pinocchio: imported where a file of another tool is read

    model = tree.model
    unit = np.ones(model.nv)
    for joint in range(1, model.njoints):
        if joint_kind(model, joint)[0] == "prismatic":
            unit[model.joints[joint].idx_v] = scale
    rng = np.random.default_rng(0)
    samples: list[NDArray] = []
    for _ in range(3 * count):
        start = pin.integrate(model, q, rng.uniform(-0.2, 0.2, model.nv) * unit)
        try:
            samples.append(assemble(replace(tree, q_reference=start), nearest=False)[0])
        except ImportError_:
            continue
        if len(samples) == count:
            break
    return samples


def _hinges(model, data, joints: list[int], closures: list[Closure],
            scale: float) -> list[tuple[frozenset, NDArray, NDArray]]:
    """The hinges among ``joints`` and ``closures`` at the configuration in ``data``: (the two bodies it joins, by the
    joint each hangs from; a point of its axis; its unit axis), world. A hinge closure is ball closures between the
    same two bodies on one line (:func:`~screwkit.io.closed_tree.ball_line`, as the serial legs read them)."""
    hinges = []
    for joint in joints:
        kind, axis = joint_kind(model, joint)
        if kind == "revolute":
            hinges.append((frozenset({model.parents[joint], joint}), np.asarray(data.oMi[joint].translation),
                           np.asarray(data.oMi[joint].rotation) @ axis))
    pairs: dict[frozenset, list[Closure]] = {}  # ball closures by the two bodies they join
    for closure in closures:
        if closure.kind == "3d":
            pairs.setdefault(frozenset({closure.joint_a, closure.joint_b}), []).append(closure)
    for bodies, balls in pairs.items():
        if len(bodies) == 2:
            rank, axis, point = ball_line([(homogeneous(data.oMi[c.joint_a]) @ c.placement_a)[:3, 3]
                                           for c in balls], balls, scale)
            if rank == 1:
                hinges.append((bodies, point, axis))
    return hinges


def parallelogram_midlines(model, data, joints: list[int], closures: list[Closure], path: list[int],
                           motors: set[int], scale: float) -> dict[int, NDArray]:
    """World offsets that move the actuated path's rods that are one side of a parallelogram of hinges onto its
    midline: {joint id: offset} for both hinges of each such rod.

    A rod of the path is the body between two consecutive passive hinges j1 (from body X) and j2 (to body Y); it is
    one side of a parallelogram when hinges of the leg join X to another body R' and R' to Y, parallel to j1 and j2,
    offset from them by one vector D (perpendicular to the axes; to :data:`SUBSPACE_TOLERANCE` of the length scale,
    beyond what :func:`equivalent_constraint` accepts as a parallelogram). The leg then transmits the force along
    the parallelogram's midline, not along the rod the spanning tree happens to run through: the path's actuation
    wrench (orthogonal to the path's own constraint wrenches, :mod:`docs/theory`) would follow the rod, and change
    with the file's choice of tree. Each of j1 and j2 moved halfway to its twin (a virtual rod, the platform's motion
    unchanged) gives the leg's.
    """
    hinges = _hinges(model, data, joints, closures, scale)
    offsets: dict[int, NDArray] = {}
    for j1, j2 in zip(path, path[1:]):
        if model.parents[j2] != j1 or model.parents[j1] == 0 or {j1, j2} & motors:
            continue
        if joint_kind(model, j1)[0] != "revolute" or joint_kind(model, j2)[0] != "revolute":
            continue
        first, second = ((np.asarray(data.oMi[j].translation), np.asarray(data.oMi[j].rotation) @ joint_kind(
            model, j)[1]) for j in (j1, j2))
        x, y = model.parents[j1], j2
        for bodies_1, point_1, axis_1 in hinges:
            if x not in bodies_1 or j1 in bodies_1 or np.linalg.norm(np.cross(axis_1, first[1])) > FILE_ROUNDING:
                continue
            other = next(iter(bodies_1 - {x}))
            offset = point_1 - first[0]
            offset = offset - (offset @ first[1]) * first[1]
            for bodies_2, point_2, axis_2 in hinges:
                gap = point_2 - second[0]
                gap = gap - (gap @ second[1]) * second[1]
                if (bodies_2 == frozenset({other, y}) and np.linalg.norm(np.cross(axis_2, second[1])) <= FILE_ROUNDING
                        and np.linalg.norm(gap - offset) <= SUBSPACE_TOLERANCE * scale
                        and np.linalg.norm(offset) > SUBSPACE_TOLERANCE * scale):
                    offsets[j1], offsets[j2] = offset / 2, gap / 2
    return offsets


def compound_legs(tree: ClosedTree, q: NDArray, scale: float, legs: list, couplings: list[Closure],
                   motors: set[int], platform: int, normal: NDArray | None,
                   report: ImportReport) -> list[tuple[str, Reduction, NDArray]]:
    """Legs joined by closures that do not touch the platform (:mod:`screwkit.io.compound`): each group keeps its
    actuated leg; its passive legs leave ``legs`` and become one equivalent constraint chain, returned as
    (chain name, reduction, world attachment point) where one is needed."""
    import pinocchio as pin  # Pinocchio: imported where a file of another tool is read

    if not couplings:
        return []
    model = tree.model
    states = []
    for sample in [q] + closed_samples(tree, q, scale):
        state = model.createData()
        pin.computeJointJacobians(model, state, sample)
        states.append(state)
    spine_joints = set(legs[0].joints)

    def joints_of(closures: list[Closure], members: list[int], spine: bool) -> list[int]:
        joints = {j for c in closures for side in (c.joint_a, c.joint_b) for j in path_to(model, side)}
        joints |= {j for index in members for j in legs[index].joints}
        return sorted(joints if spine else joints - spine_joints)

    equivalents, removed = [], set()
    for members, group_couplings in compound_groups(model, [leg.joints for leg in legs], couplings):
        label = f"the compound leg joined by closure {', '.join(repr(c.name) for c in group_couplings)}"
        if not members:  # loops among branches that reach no leg: they cannot move the platform
            report.notes.append(f"closure {', '.join(repr(c.name) for c in group_couplings)} closes branches that "
                                "reach no leg: left out (it does not move the platform)")
            continue
        actuated = [index for index in members if motors & set(legs[index].joints)]
        if len(actuated) > 1:
            driven = [model.names[j] for i in actuated for j in legs[i].joints if j in motors]
            raise ImportError_(f"{tree.source}: {label} has {len(actuated)} actuated legs "
                               f"({', '.join(model.names[legs[i].joints[0]] for i in actuated)}), the legs from "
                               f"those joints, with actuated joints {', '.join(driven)}: screwkit writes a compound "
                               "leg with one actuator; --lock holds the others where the file puts them, or --actuate "
                               "names the actuated joints to read.")
        closures = list(group_couplings) + [closure for i in members for closure in legs[i].sources]
        spine = 0 in members
        joints = joints_of(closures, members, spine)
        if actuated:
            kept = legs[actuated[0]]
            path_closures = list(kept.sources)
            path_joints = joints_of(path_closures, actuated, actuated[0] == 0)
            if normal is None:
                kept.offsets = parallelogram_midlines(model, states[0], joints_of(closures, members, True), closures,
                                                      kept.joints, motors, scale)
                if kept.offsets.get(kept.joints[-1]) is not None:  # the loop frame stays where it is
                    kept.predecessor = kept.predecessor.copy()
                    kept.predecessor[:3, 3] -= np.asarray(states[0].oMi[kept.joints[-1]].rotation).T @ kept.offsets[
                        kept.joints[-1]]
        systems, paths, rounding = [], [], 0.0
        for state in states:
            centre = np.asarray(state.oMi[platform].translation)
            system, absorbed = platform_twists(model, state, joints, closures, platform, spine, centre, scale)
            systems.append(system)
            paths.append(platform_twists(model, state, path_joints, path_closures, platform, actuated[0] == 0, centre,
                                         scale)[0] if actuated else np.eye(6))
            rounding = max(rounding, absorbed)
        try:
            reduction = equivalent_constraint(systems, paths, normal)
        except NotReducible as error:  # the graph reading may model it (a crank doubled by a parallelogram off its
            # path, its distal link hinged on the crank); where it refuses too, its reason is the mechanism's, where
            # this one is the serial writer's (a planar leg closed by balls "leaves the plane of motion")
            raise LegWithLoops(f"{tree.source}: {label} cannot be written as serial chains: {error}" + GRAPH_HINT
                               + ".") from None
        passive = [index for index in members if index not in actuated]
        removed.update(passive)
        first = legs[passive[0]] if passive else legs[members[0]]
        name = f"{model.names[first.joints[0]]}_equivalent"
        replaced = ", ".join(model.names[legs[i].joints[0]] for i in passive)
        allowed = ("no rotation" if not len(reduction.rotations) else
                   "rotations about " + ", ".join(str(np.round(r, 6).tolist()) for r in reduction.rotations))
        report.notes.append(
            f"{label}: twist system of dimension {reduction.dimension} ({allowed} beyond translations), the same at "
            f"{reduction.samples} closed configurations; actuated path "
            f"{model.names[legs[actuated[0]].joints[0]] if actuated else 'none'} kept, "
            + (f"passive {'legs ' + replaced if passive else 'branches'} written as the equivalent constraint chain "
               f"{name}" if reduction.needed else
               f"nothing written for its passive {'legs ' + replaced + ' and ' if passive else ''}branches: they "
               "constrain nothing the actuated path does not"))
        if rounding:
            report.notes.append(f"{label}: its loops move only to within the file's rounding (a singular value of "
                                f"{rounding:.2g} of its closure Jacobian, relative, taken as zero): read as drawn")
        if reduction.needed:
            equivalents.append((name, reduction, first.successor_world[:3, 3].copy()))
    legs[:] = [leg for index, leg in enumerate(legs) if index not in removed]
    return equivalents
