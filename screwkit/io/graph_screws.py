"""The equivalent chains of a closed-loop graph's legs at a batch of closed configurations.

:mod:`screwkit.io.graph` finds the legs of a closed tree; this module derives, batched over configurations with
numpy (joint frames and twists from :class:`screwkit.io.graph_kinematics.TreeKinematics`), each leg's twist system
with and without its actuator (the platform-twist part of the null space of the leg's closure Jacobian), its
actuated joint's own twist and its ITI and OTI points, and from them the equivalent chains
:func:`screwkit.indices.analysis.analyze` takes (``docs/theory.md``, *Legs with loops inside*).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from itertools import combinations

import numpy as np
from numpy.typing import NDArray

from screwkit.closure.canonical import foot_on_line
from screwkit.common.rotations import cross
from screwkit.common.tolerances import FILE_ROUNDING, IN_LOOP_RATE, MEETING, PARALLEL_FOOT
from screwkit.io.closed_tree import ClosedTree, Closure, ImportError_, path_to
from screwkit.io.compound import TWIST_RANK_TOLERANCE
from screwkit.io.graph_kinematics import TreeKinematics
from screwkit.io.leg_ways import pin_groups, through_closures
from screwkit.screw.chain_screws import ChainScrews

__all__ = ["GraphLeg", "LegScrews", "leg_screws", "equivalent_chains", "dimension_groups", "common_motions",
           "locking_legs", "axis_line", "HINGES"]


@dataclass(frozen=True)
class GraphLeg:
    """One leg of a closed-loop graph: its joints (Pinocchio joint ids, the platform's own joint when the platform
    hangs on the leg: ``spine``), the closures with an end on it, and its actuated joint (none for a passive leg,
    which only constrains the platform); ``others``: for one actuator of a leg of several
    (:func:`~screwkit.io.graph_actuators.split_legs`), the leg's other actuated joints, free in its twist systems,
    and ``of`` that leg's name."""

    name: str
    joints: tuple[int, ...]
    closures: tuple[Closure, ...]
    spine: bool
    actuators: tuple[int, ...]
    others: tuple[int, ...] = ()
    of: str = ""


def _columns(kinematics: TreeKinematics, joints) -> NDArray[np.int64]:
    """Velocity coordinates of ``joints``, in joint order."""
    width = {"revolute": 1, "unbounded": 1, "prismatic": 1, "ball": 3, "free": 6}
    return np.array([kinematics.idx_v[j] + k for j in sorted(set(joints)) for k in range(width[kinematics.kinds[j]])],
                    dtype=np.int64)


def _select(offset: NDArray, kind: str) -> NDArray:
    """(n, r, 6): the rows taking a working twist of a body to the velocity of a closure frame on it (its point's
    velocity for ``3d``, the whole twist about that point for ``6d``)."""
    count = offset.shape[0]
    if kind != "3d":
        return np.broadcast_to(np.eye(6), (count, 6, 6))
    skew = np.zeros((count, 3, 3))
    skew[:, 0, 1], skew[:, 0, 2], skew[:, 1, 2] = -offset[:, 2], offset[:, 1], -offset[:, 0]
    skew[:, 1, 0], skew[:, 2, 0], skew[:, 2, 1] = offset[:, 2], -offset[:, 1], offset[:, 0]
    return np.concatenate([-skew, np.broadcast_to(np.eye(3), (count, 3, 3))], axis=2)


def _twist_spaces(state: _State, joints, leg: GraphLeg, cuts=()) -> tuple[NDArray, NDArray]:
    """Orthonormal rows (n, 6, 6) spanning the platform twists ``joints`` of ``leg`` allow with its closures closed
    (working coordinates; the first ``dims[n]`` rows of configuration n), and ``dims`` (n,).

    Unknowns: the rates of ``joints`` and the platform twist T. Each closure adds the relative velocity of its two
    frames (6 rows for ``6d``, the velocity of its point for ``3d``); a frame whose path passes the platform moves
    with T plus the joints of ``joints`` beyond the platform, unless the leg is the platform's spine (the
    platform's own path is among its joints): then T is tied to the platform body's twist. ``cuts``: connections of
    the leg left out (:func:`_closure_matrix`)."""
    right, free = _null_rows(_closure_matrix(state, joints, leg, cuts))
    null = right[:, :, -6:] * free[:, :, None]
    _, values, rows = np.linalg.svd(null, full_matrices=False)
    return rows, np.sum(values > TWIST_RANK_TOLERANCE, axis=1)


def _null_rows(matrix: NDArray) -> tuple[NDArray, NDArray]:
    """The right singular vectors (n, c, c) of ``matrix`` (n, r, c) and which of them (n, c) span its null space."""
    if matrix.shape[1] == 0:  # no row (every connection of a leg left out): all of it
        return (np.broadcast_to(np.eye(matrix.shape[2]), (matrix.shape[0],) + matrix.shape[2:] * 2),
                np.ones((matrix.shape[0], matrix.shape[2]), dtype=bool))
    _, singular, right = np.linalg.svd(matrix, full_matrices=True)
    largest = np.maximum(singular[:, 0] if singular.shape[1] else np.zeros(matrix.shape[0]), 1.0)
    rank = np.sum(singular > TWIST_RANK_TOLERANCE * largest[:, None], axis=1)
    return right, np.arange(right.shape[1])[None, :] >= rank[:, None]


def drives_rigidly(state: _State, leg: GraphLeg, actuator: int) -> NDArray[np.bool_]:
    """Whether the actuated joint moves with the other joints of its own path in ``leg`` held, the leg's closures
    closed (n,): the joints from the base to it and from it to where the leg meets the platform, the joints of loops
    off that path left free (a parallelogram that doubles a crank follows it, and carries none of its load). It then
    drives the leg as its first joint would, and the power coefficient on its twist is the leg's input (a Delta's or
    Stewart's leg driven from the base). False where it moves inside a loop that closes on the base through its path
    (an excavator's bucket cylinder, pivoted on the arm, pushing an H link pinned to the arm that carries the side
    link): its twist may lie in the leg's twist system (a planar leg's holds every planar twist), but the power
    coefficient on it would pair the actuator's motion with a wrench on links it never pushes."""
    model = state.model
    onto = [(c.joint_a, c.joint_b) if state.platform in path_to(model, c.joint_b) else (c.joint_b, c.joint_a)
            for c in leg.closures]
    ends = [end for end, other in onto if state.platform in path_to(model, other)]  # the leg's ends on the platform
    beyond = [path_to(model, end) for end in ends + ([state.platform] if leg.spine else [])]  # (a spine: its own)
    path = set(path_to(model, actuator)) | {j for way in beyond if actuator in way for j in way[way.index(actuator):]}
    groups = pin_groups(leg.closures)
    loaded = _loaded(state, leg, [("closures", g) for g in groups], actuator) if len(groups) > 1 else None
    idle = {k for g, on in zip(groups, [] if loaded is None else loaded.T) if not on.any() for k in g}
    path |= through_closures(model, leg, actuator, state.platform, idle)  # (whichever way the file's tree runs)
    free = [j for j in leg.joints if j == actuator or j not in path]
    columns = _columns(state.kinematics, free)
    right, null = _null_rows(_closure_matrix(state, free, leg))
    own = np.isin(columns, _columns(state.kinematics, [actuator]))
    return np.linalg.norm(right[:, :, :len(columns)][:, :, own] * null[:, :, None], axis=(1, 2)) > IN_LOOP_RATE


def _closure_matrix(state: _State, joints, leg: GraphLeg, cuts=()) -> NDArray:
    """The rows (n, r, len(columns) + 6) of :func:`_twist_spaces`: the closures' relative velocities over the rates
    of ``joints`` and the platform twist. ``cuts``: connections left out, ``("closures", (k, ...))`` the leg's
    closures k, ..., ``("joint", j)`` joint j made free in all six directions (six columns before the platform's)."""
    model, kinematics = state.model, state.kinematics
    columns = _columns(kinematics, joints)
    count = state.working.shape[0]
    freed = [j for kind, j in cuts if kind == "joint"]
    blocks = []
    for index, closure in enumerate(leg.closures):
        if any(kind == "closures" and index in which for kind, which in cuts):
            continue
        rows_q, rows_t, rows_f = 0.0, 0.0, [0.0] * len(freed)
        for joint, placement, sign in ((closure.joint_a, closure.placement_a, 1.0),
                                       (closure.joint_b, closure.placement_b, -1.0)):
            world = state.transforms[:, joint] @ placement
            select = _select((world[:, :3, 3] - state.centre) / state.scale, closure.kind)
            moves = kinematics.supports(model, joint)[columns]
            rows_q = rows_q + sign * select @ np.swapaxes(state.working[:, columns] * moves[None, :, None], 1, 2)
            if not leg.spine and state.platform in path_to(model, joint):
                rows_t = rows_t + sign * select
            rows_f = [f + sign * select if j in path_to(model, joint) else f for f, j in zip(rows_f, freed)]
        rows_q = np.broadcast_to(rows_q, (count, 6 if closure.kind != "3d" else 3, len(columns)))
        blocks.append(np.concatenate([rows_q] + [np.broadcast_to(f, rows_q.shape[:2] + (6,)) for f in rows_f]
                                     + [np.broadcast_to(rows_t, rows_q.shape[:2] + (6,))], axis=2))
    if leg.spine:
        moves = kinematics.supports(model, state.platform)[columns]
        own = np.swapaxes(state.working[:, columns] * moves[None, :, None], 1, 2)
        carried = [np.broadcast_to(np.eye(6) if j in path_to(model, state.platform) else np.zeros((6, 6)),
                                   (count, 6, 6)) for j in freed]
        blocks.append(np.concatenate([own, *carried, np.broadcast_to(-np.eye(6), (count, 6, 6))], axis=2))
    return np.concatenate(blocks, axis=1) if blocks else np.zeros((count, 0, len(columns) + 6 * len(freed) + 6))


HINGES = ("revolute", "unbounded")


def axis_line(state: _State, joint: int) -> tuple[NDArray, NDArray]:
    """A revolute joint's drawn origin and unit axis (n, 3 each), in the world."""
    transforms = state.transforms[:, joint]
    return transforms[:, :3, 3], transforms[:, :3, :3] @ state.kinematics.axes[joint]


def _joint_point(state: _State, joint: int, among=None) -> NDArray:
    """Where ``joint`` is (n, 3), whatever point of its axis a file draws a revolute at (the same mechanism drawn
    otherwise gives the same point), as :mod:`screwkit.closure.canonical` places a serial chain's: a revolute whose
    axis meets a neighbouring revolute's (its parent's or a child's, not parallel to it, within
    :data:`~screwkit.common.tolerances.MEETING` of the length scale: a universal joint written as two hinges) where
    they meet (the mean, if both meet it); any other revolute at the foot on its axis of the perpendicular from each
    neighbour that is at a point (a ball's centre, where a neighbouring revolute meets its own neighbour: a
    universal joint's centre), or of the common perpendicular with each other neighbouring revolute's axis it
    passes at a clear angle (squared sine above :data:`~screwkit.common.tolerances.PARALLEL_FOOT`; a foot's roll
    hinge 12 mm below its pitch hinge), the mean of both neighbours'; any other joint at its drawn origin (a ball's
    centre; a hinge among parallel ones, whose drawn point lies in the plane of the motion). ``among``: the joints
    that count as neighbours (all, if not given)."""
    meetings, feet = _meetings(state, joint, among)
    if meetings:
        return np.mean(meetings, axis=0)
    return np.mean(feet, axis=0) if feet else state.transforms[:, joint, :3, 3]


def _meetings(state: _State, joint: int, among=None, feet: bool = True) -> tuple[list[NDArray], list[NDArray]]:
    """The points (n, 3 each) where a revolute ``joint``'s axis meets a neighbouring revolute's, and (``feet``) the
    feet on it that :func:`_joint_point` takes where it meets none (only neighbours ``among`` these joints, if
    given); none for any other joint."""
    kinds = state.kinematics.kinds
    if kinds[joint] not in HINGES:
        return [], []
    model = state.model
    neighbours = [j for j in (model.parents[joint], *range(joint + 1, model.njoints))
                  if j != 0 and kinds[j] in (*HINGES, "ball")
                  and (j == model.parents[joint] or model.parents[j] == joint) and (among is None or j in among)]
    point, axis = axis_line(state, joint)
    meetings, lines = [], {}
    for neighbour in (j for j in neighbours if kinds[j] in HINGES):
        other_point, other_axis = axis_line(state, neighbour)
        cosine = np.sum(axis * other_axis, axis=1)
        sine_squared = 1.0 - cosine * cosine
        if not np.all(sine_squared > PARALLEL_FOOT):
            continue
        normal = np.cross(axis, other_axis) / np.sqrt(sine_squared)[:, None]
        if np.all(np.abs(np.sum((point - other_point) * normal, axis=1)) <= MEETING * state.scale):
            meetings.append(foot_on_line(point, axis, other_point, other_axis))
        else:
            lines[neighbour] = foot_on_line(point, axis, other_point, other_axis)
    if meetings or not feet:
        return meetings, []
    found = []
    for neighbour in neighbours:  # (as a serial chain's canonical points: a neighbour at a point first)
        if kinds[neighbour] == "ball":
            found.append(_foot_from(point, axis, state.transforms[:, neighbour, :3, 3]))
            continue
        centres, _ = _meetings(state, neighbour, among, feet=False)
        if centres:  # a universal joint's centre
            found.append(_foot_from(point, axis, np.mean(centres, axis=0)))
        elif neighbour in lines:
            found.append(lines[neighbour])
    return meetings, found


def _attachments(state: _State, leg: GraphLeg, body: int, actuator: int | None = None, own: NDArray | None = None
                 ) -> list[NDArray]:
    """World points (n, 3) where the leg's joints (to its children) and closures meet ``body`` (a hinge closed by
    two points at its joint only: :attr:`~screwkit.io.closed_tree.Closure.axis_point`), each joint where
    :func:`_joint_point` puts it. A weld (``6d``) makes the body at its other end part of ``body``: the leg meets
    ``body`` at the joint that moves that end, not at the weld's frame, which a file may put anywhere (a CAD export
    welds each leg's last link to the platform at the platform's origin). Idle ones (:func:`_loaded`; ``actuator``:
    the leg's actuated joint) are NaN; ``own``: the platform's own joint's point, for the platform's path."""
    model = state.model
    children = [j for j in leg.joints if model.parents[j] == body]
    points, cuts = [_joint_point(state, j, leg.joints) for j in children], [("joint", j) for j in children]
    if own is not None:
        points.append(own)
        cuts.append(("joint", body))
    pins: dict[tuple, list[NDArray]] = {}  # the points of the closures between one pair of bodies
    group = {k: ("closures", g) for g in pin_groups(leg.closures) for k in g}  # (a hinge's both points: one cut)
    for index, closure in enumerate(leg.closures):
        if closure.axis_point:
            continue
        for joint, placement, other in ((closure.joint_a, closure.placement_a, closure.joint_b),
                                        (closure.joint_b, closure.placement_b, closure.joint_a)):
            if joint == body:
                cut = group[index]
                point = (_joint_point(state, other) if closure.kind == "6d" and other != 0 else
                         (state.transforms[:, joint] @ placement)[:, :3, 3])
                pins.setdefault(cut, []).append(point)
    for cut, drawn in pins.items():
        points.append(_pin_on_axis(state, leg, drawn))
        cuts.append(cut)
    if len(points) < 2:
        return points
    loaded = _loaded(state, leg, cuts, actuator)  # (n, k)
    return [np.where(loaded[:, [k]], point, np.nan) for k, point in enumerate(points)]


def _pin_on_axis(state: _State, leg: GraphLeg, drawn: list[NDArray]) -> NDArray:
    """Where closures between two bodies meet them (n, 3): one's point; two or more on a line (a hinge written as two
    connects on its axis) the foot on it from the leg's joints' mean, whatever their spacing or order; else the mean."""
    if len(drawn) == 1:
        return drawn[0]
    first, axis = drawn[0], drawn[1] - drawn[0]
    length = np.linalg.norm(axis, axis=1, keepdims=True)
    unit = axis / np.where(length > 0, length, 1.0)
    off = [np.linalg.norm(np.cross(point - first, unit), axis=1) for point in drawn[2:]]
    if not np.all(length > FILE_ROUNDING * state.scale) or any(np.any(o > FILE_ROUNDING * state.scale) for o in off):
        return np.mean(drawn, axis=0)
    reference = np.mean([state.transforms[:, j, :3, 3] for j in leg.joints], axis=0) if leg.joints else \
        np.mean(drawn, axis=0)
    return _foot_from(first, unit, reference)


def _loaded(state: _State, leg: GraphLeg, cuts: list, actuator: int | None) -> NDArray[np.bool_]:
    """Which of a leg's connections ``cuts`` to one body are kept in the point where the leg meets it (n, k): all but
    those whose removal leaves the leg's twist systems (every joint free; ``actuator`` locked) as they are, unless
    idle only beside another idle one (two bearings of one pin, parallel bars: both kept, whatever the order), if all
    of them out together do too. They add no constraint: a dyad hung between two of the leg's links, which, unloaded,
    carries nothing in its plane; or a support the leg already has (a second carriage on a parallel rail)."""
    systems = [[j for j in leg.joints]] + ([[j for j in leg.joints if j != actuator]] if actuator is not None else [])
    count = state.working.shape[0]
    if count > _SCREENED:  # first at a few configurations of the batch: where no connection is idle at any of them
        # (a Delta's rod pairs, each rod holding the platform's turns), none is taken to be at the others, whose
        # twist systems are not computed again (an idle one shows at every regular configuration)
        sample = _sampled(state, np.unique(np.linspace(0, count - 1, _SCREENED).astype(int)))
        if not _loaded(sample, leg, cuts, actuator).all():
            return _loaded_at_each(state, leg, cuts, systems)
        return np.ones((count, len(cuts)), dtype=bool)
    return _loaded_at_each(state, leg, cuts, systems)


_SCREENED = 4
"""Configurations of a batch at which :func:`_loaded` first looks for an idle connection."""


def _sampled(state: _State, rows: NDArray) -> _State:  # (the configurations ``rows`` of a batch)
    return replace(state, transforms=state.transforms[rows], working=state.working[rows], centre=state.centre[rows],
                   outside=None if state.outside is None else state.outside[rows])


def _spanned_dims(state: _State, rows: NDArray, dims: NDArray) -> NDArray[np.int64]:
    """The dimension (n,) of the part of a twist system (rows (n, 6, 6), the first ``dims[n]`` of configuration n)
    that lies among the twists some leg allows (:attr:`_State.outside`; all of it where that is not set): what it
    frees beyond them only the constraint wrenches every leg holds resist, which no connection carries alone."""
    if state.outside is None:
        return dims
    values = np.linalg.svd(_first(rows, dims) @ state.outside, compute_uv=False)
    return dims - np.sum(values > TWIST_RANK_TOLERANCE, axis=1)


def _first(rows: NDArray, dims: NDArray) -> NDArray:
    """``rows`` (n, r, 6) with all but the first ``dims[n]`` of configuration n zero."""
    return rows * (np.arange(rows.shape[1])[None, :] < np.asarray(dims)[:, None])[:, :, None]


def _outside(screws_allowed: list[tuple[NDArray, NDArray]]) -> NDArray:
    """The projector (n, 6, 6) off the twists some leg allows (every leg's twist system together, working
    coordinates): what it keeps of a twist, only the constraint wrenches common to every leg resist."""
    stacked = np.concatenate([_first(rows, dims) for rows, dims in screws_allowed], axis=1)
    _, values, right = np.linalg.svd(stacked, full_matrices=True)
    basis = _first(right, np.sum(values > TWIST_RANK_TOLERANCE, axis=1))
    return np.eye(6)[None] - np.swapaxes(basis, 1, 2) @ basis


def _loaded_at_each(state: _State, leg: GraphLeg, cuts: list, systems: list) -> NDArray[np.bool_]:
    """:func:`_loaded` at every configuration of the batch."""
    whole = [_spanned_dims(state, *_twist_spaces(state, joints, leg)) for joints in systems]

    def same(cut) -> NDArray[np.bool_]:  # (n,): the leg's twist systems as they are with ``cut`` left out
        kept = np.ones(whole[0].shape, dtype=bool)
        for joints, dims in zip(systems, whole):  # (the locked one only where the free one is the same)
            if kept.any():
                kept &= _spanned_dims(state, *_twist_spaces(state, joints, leg, cut)) == dims
        return kept

    idle = np.stack([same((cut,)) for cut in cuts], axis=1)  # (n, k)
    backed = np.zeros_like(idle)  # idle only beside another idle one (two bearings of one pin, parallel bars)
    for i, j in combinations(range(len(cuts)), 2):
        both = idle[:, i] & idle[:, j]
        if both.any():
            apart = both & ~same((cuts[i], cuts[j]))
            backed[:, i] |= apart
            backed[:, j] |= apart
    drop = idle & ~backed
    for row in {tuple(r) for r in drop if r.any()}:  # (and all of them out together)
        rows = np.all(drop == np.array(row), axis=1)
        drop[rows] &= same(tuple(cut for cut, out in zip(cuts, row) if out))[rows, None]
    drop[drop.all(axis=1)] = False  # (a leg that constrains nothing, whatever it meets the body by: every one)
    return ~drop


def _actuator_point(state: _State, actuator: int, iti_point: NDArray) -> NDArray:
    """Where an actuated joint is (n, 3), whatever point of its line a file draws it at: a hinge that meets a
    neighbouring hinge where they meet (:func:`_joint_point`), else (a hinge on the base, a slide) at the foot, on its
    line, of the perpendicular from its ITI point (the links it moves: the foot from a neighbour that is a point, as
    :mod:`screwkit.closure.canonical` places a serial chain's). It enters the working length of the leg's equivalent
    chain, on which the CTI depends."""
    kinds = state.kinematics.kinds
    meetings, _ = _meetings(state, actuator, feet=False)
    if meetings:  # where it meets a neighbouring hinge
        return np.mean(meetings, axis=0)
    if kinds[actuator] not in HINGES + ("prismatic",):
        return state.transforms[:, actuator, :3, 3]
    return _foot_from(*axis_line(state, actuator), iti_point)


def _pin_point(state: _State, platform: int, others: list[NDArray]) -> NDArray:
    """Where a platform's own joint on the base is (n, 3): a hinge at the foot, on its axis, of the perpendicular from
    the mean of the other legs' points on the platform (``others``), which the geometry decides, not the file's drawn
    point; any other joint (or with no other point) at its drawn origin."""
    origin = state.transforms[:, platform, :3, 3]
    if state.kinematics.kinds[platform] not in HINGES or not others:
        return origin
    return _foot_from(*axis_line(state, platform), np.nanmean(others, axis=0))


def _foot_from(point: NDArray, axis: NDArray, other: NDArray) -> NDArray:
    """The foot (n, 3) on each line (``point``, unit ``axis``) of the perpendicular from ``other``."""
    return point + np.sum((other - point) * axis, axis=1)[:, None] * axis


@dataclass(frozen=True)
class _State:
    """A batch of closed configurations: joint frames (n, njoints, 4, 4), every velocity coordinate's twist in
    working coordinates about the platform joint (n, nv, 6), that centre (n, 3) and the length scale."""

    model: object
    kinematics: TreeKinematics
    platform: int
    transforms: NDArray[np.float64]
    working: NDArray[np.float64]
    centre: NDArray[np.float64]
    scale: float
    outside: NDArray[np.float64] | None = None  # (n, 6, 6): :func:`_outside` of every leg (None: not yet known)

    @classmethod
    def at(cls, tree: ClosedTree, kinematics: TreeKinematics, platform: int, q: NDArray, scale: float) -> _State:
        transforms = kinematics.transforms(q)
        twists = kinematics.twists(transforms)
        centre = transforms[:, platform, :3, 3]
        omega = twists[..., :3]
        working = np.concatenate([omega, (twists[..., 3:] + cross(omega, centre[:, None, :])) / scale], axis=-1)
        return cls(tree.model, kinematics, platform, transforms, working, centre, scale)


@dataclass(frozen=True)
class LegScrews:
    """One leg's equivalent chain at a batch of configurations: the actuated joint's unit twist (n, 6), a basis of
    the twists the leg allows with it locked (n, 6, 6; the first ``locked_dims[n]`` rows), both in working
    coordinates; the actuated joint's point, the ITI and OTI points (n, 3, world) and how far the actuated
    joint's twist lies from the leg's twist system (n,)."""

    own: NDArray[np.float64]
    locked: NDArray[np.float64]
    locked_dims: NDArray[np.int64]
    allowed: NDArray[np.float64]
    allowed_dims: NDArray[np.int64]
    actuator_point: NDArray[np.float64]
    iti_point: NDArray[np.float64]
    oti_point: NDArray[np.float64]
    outside: NDArray[np.float64]
    rigid_input: NDArray[np.bool_] | None = None  # (:func:`drives_rigidly`; None for a passive leg)


def model_name(tree: ClosedTree, joint: int) -> str:
    """The file's name of the model's joint ``joint`` (a ball or universal joint written as hinges: the file's)."""
    return tree.written_joint(tree.model.names[joint])


def leg_screws(tree: ClosedTree, kinematics: TreeKinematics, platform: int, legs, q: NDArray, scale: float):
    """Every leg's :class:`LegScrews` at closed configurations q (n, nq), and the batch's :class:`_State`."""
    state = _State.at(tree, kinematics, platform, np.asarray(q, dtype=float).reshape(-1, kinematics.nq), scale)
    systems = [_twist_spaces(state, leg.joints, leg) for leg in legs]
    state = replace(state, outside=_outside(systems))  # (a connection carrying only common wrenches: out of points)
    out = []
    pinned = [leg.spine and leg.joints == (platform,) for leg in legs]  # the platform's own joint on the base
    on_platform = [_attachments(state, leg, platform, leg.actuators[0] if leg.actuators else None,  # (the own joint:
                                None if not leg.spine or pin else _joint_point(state, platform, leg.joints)  # as a U's,
                                if not leg.actuators else state.transforms[:, platform, :3, 3])  # or as drawn)
                   for leg, pin in zip(legs, pinned)]
    others = [point for points, pin in zip(on_platform, pinned) if not pin for point in points]
    for leg, pin, platform_points, (allowed, allowed_dims) in zip(legs, pinned, on_platform, systems):
        if not leg.actuators:  # a passive leg: its twist system only (the constraint wrenches it exerts)
            oti = platform_points + ([_pin_point(state, platform, others)] if pin else [])
            if not oti:
                raise ImportError_(f"{tree.source}: leg {leg.name!r}: no joint on the platform.")
            point = np.nanmean(oti, axis=0)
            out.append(LegScrews(np.zeros_like(point, shape=point.shape[:1] + (6,)), allowed, allowed_dims, allowed,
                                 allowed_dims, point, point, point, np.zeros(point.shape[0])))
            continue
        actuator = leg.actuators[0]
        locked, locked_dims = _twist_spaces(state, [j for j in leg.joints if j != actuator], leg)
        own = state.working[:, kinematics.idx_v[actuator]]
        own = own / np.linalg.norm(own, axis=1, keepdims=True)
        spanning = _first(allowed, allowed_dims)
        projection = np.einsum("nk,nkj->nj", np.einsum("nj,nkj->nk", own, spanning), spanning)
        iti, oti = _attachments(state, leg, actuator, actuator), list(platform_points)
        if not iti:  # (a slide too: the actuation wrench taken about the platform's joint, drawn anywhere on the
            # slide's line, would turn with where the file draws it)
            raise ImportError_(f"{tree.source}: leg {leg.name!r}: actuated joint {model_name(tree, actuator)!r} moves "
                               "the platform itself, with no link after it: a leg screwkit does not analyse (its "
                               "actuation wrench acts on no link of the leg's own).")
        if not oti:
            raise ImportError_(f"{tree.source}: leg {leg.name!r}: no joint on the platform.")
        iti_point = np.nanmean(iti, axis=0)
        at = _actuator_point(state, actuator, iti_point)
        out.append(LegScrews(own, locked, locked_dims, allowed, allowed_dims, at, iti_point, np.nanmean(oti, axis=0),
                             np.linalg.norm(own - projection, axis=1),
                             drives_rigidly(state, leg, actuator)))
    return out, state


def equivalent_chains(legs, screws: list[LegScrews], state: _State, rows: NDArray, model):
    """The legs' equivalent chains (world coordinates) at the configurations ``rows`` of a batch, which share every
    leg's twist-system dimension: ChainScrews of batch shape (len(rows),), ITI and OTI points (len(rows), legs,
    3)."""
    chains = []
    centre, scale = state.centre[rows][:, None, :], state.scale
    for leg, leg_screw in zip(legs, screws):
        dims = int(leg_screw.locked_dims[rows[0]])
        own = leg_screw.own[rows][:, None, :] if leg.actuators else np.zeros((len(rows), 0, 6))
        working = np.concatenate([own, leg_screw.locked[rows][:, :dims]], axis=1)
        world = np.concatenate([working[..., :3], working[..., 3:] * scale + cross(centre, working[..., :3])],
                               axis=-1)
        points = np.concatenate([leg_screw.actuator_point[rows][:, None][:, :own.shape[1]],
                                 np.repeat(leg_screw.oti_point[rows][:, None, :], dims, axis=1)], axis=1)
        names = tuple(model.names[j] for j in leg.actuators) + tuple(f"{leg.name}_twist_{k + 1}" for k in range(dims))
        chains.append(ChainScrews(world, points, (0,) if leg.actuators else (), leg.name, names))
    actuated = [s for leg, s in zip(legs, screws) if leg.actuators]  # the ITI and OTI points are the actuators'
    iti = np.stack([s.iti_point[rows] for s in actuated], axis=1)
    oti = np.stack([s.oti_point[rows] for s in actuated], axis=1)
    return chains, iti, oti


def dimension_groups(screws: list[LegScrews]) -> list[NDArray[np.int64]]:
    """Configurations of a batch grouped by the dimensions of every leg's locked twist system (one group unless
    some configurations are singular)."""
    signature = np.stack([s.locked_dims for s in screws], axis=1)
    _, inverse = np.unique(signature, axis=0, return_inverse=True)
    return [np.flatnonzero(inverse.reshape(-1) == group) for group in range(int(inverse.max()) + 1)]


def common_motions(screws: list[LegScrews], locked: bool = False, counted: list | None = None) -> NDArray[np.float64]:
    """Orthonormal rows (d, 6) spanning the platform twists every leg allows (working coordinates), at the first
    configuration of a batch; ``locked``: with every actuator locked (the motions no actuator controls);
    ``counted``: a list that gets the singular values counted of the legs' stacked complements."""
    complements = []
    for screw in screws:
        rows = (screw.locked[0][:int(screw.locked_dims[0])] if locked else
                screw.allowed[0][:int(screw.allowed_dims[0])])
        _, values, right = np.linalg.svd(np.vstack([rows, np.zeros((6 - len(rows), 6))]) if len(rows) < 6 else rows)
        complements.append(right[int(np.sum(values > TWIST_RANK_TOLERANCE)):])
    stacked = np.vstack(complements)
    if not len(stacked):
        return np.eye(6)
    _, values, right = np.linalg.svd(np.vstack([stacked, np.zeros((max(6 - len(stacked), 0), 6))]))
    rank = int(np.sum(values > TWIST_RANK_TOLERANCE))
    if counted is not None:
        counted.extend(values[:rank])
    return right[rank:]


def locking_legs(legs, screws: list[LegScrews]) -> str:
    """What holds a platform no twist moves, for the refusal: the legs that allow it none on their own, else those
    any one of which left out would let it move, else every leg's twist-system dimension (at the first
    configuration of a batch)."""
    rigid = [leg.name for leg, screw in zip(legs, screws) if int(screw.allowed_dims[0]) == 0]
    if rigid:
        return f": leg(s) {', '.join(rigid)} allow it no twist on their own"
    freeing = [leg.name for k, leg in enumerate(legs) if len(common_motions(screws[:k] + screws[k + 1:]))]
    if freeing:
        return f": with any one of legs {', '.join(freeing)} left out, the others would let it move"
    return ": the legs allow twist systems of dimension " + ", ".join(
        f"{int(screw.allowed_dims[0])} ({leg.name})" for leg, screw in zip(legs, screws))
