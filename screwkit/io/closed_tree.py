"""A kinematic tree closed by frame pairs (MJCF equalities, Gepetto robot.yaml), and its assembly.

Other tools describe a closed-loop mechanism as a **tree** (a Pinocchio model built from a URDF
or an MJCF file) plus **closures**: pairs of frames that must coincide in position (``3d``: a ball
joint) or entirely (``6d``: a weld). This module holds that description (:class:`ClosedTree`,
:class:`Closure`), what an import reports (:class:`ImportReport`) and the **assembly**
(:func:`assemble`): the closures are solved from the file's reference joint values (Levenberg-Marquardt on every
joint, then along the closed configurations to the one nearest to the file's values, which the mechanism decides,
not its drawing); the gaps closed and the largest joint change are reported, and a closure that cannot close is
named with its gap. :func:`screwkit.io.star.convert_tree` writes a closed
tree in screwkit's convention.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from screwkit.common.tolerances import FILE_ROUNDING, MEETING, PARALLEL_FOOT
from screwkit.common.xml_text import tolerant_xml
from screwkit.io.nearest import independent_blocks, nearest_closed
from screwkit.io.pin_gaps import ONE_PLANE, along_pins, loop_kinds, on_one_plane, pin_axis
from screwkit.io.tree_joints import ImportError_, homogeneous, inverse, joint_kind, joint_value, path_to

GUESSED = "actuators guessed"
"""How a reader's note on guessed actuators begins."""

__all__ = ["Closure", "ClosedTree", "declared_task_coordinates", "ImportReport", "ImportError_", "LegWithLoops",
           "GRAPH_HINT", "ASSEMBLY_TOLERANCE", "homogeneous", "inverse", "joint_kind", "joint_value", "path_to",
           "closure_gaps", "assemble", "ball_line", "ball_of_revolutes", "meeting_point", "at_point",
           "LENGTH_COORDINATES", "nearest_to_lines", "closure_motions", "closure_rows"]

ASSEMBLY_TOLERANCE = 1e-10
"""Closure residual (lengths in units of the mechanism's length scale, rad) below which a closure is closed."""
LENGTH_COORDINATES = {"JointModelPX": 1, "JointModelPY": 1, "JointModelPZ": 1, "JointModelPrismaticUnaligned": 1,
                      "JointModelTranslation": 3, "JointModelPlanar": 2, "JointModelFreeFlyer": 3}
"""Pinocchio joint models whose first configuration coordinates (and velocity coordinates) are lengths, and how
many."""
LEVI_CIVITA = np.zeros((3, 3, 3))
LEVI_CIVITA[[0, 1, 2], [1, 2, 0], [2, 0, 1]], LEVI_CIVITA[[0, 1, 2], [2, 0, 1], [1, 2, 0]] = 1.0, -1.0
INCONSISTENCY_TOLERANCE = FILE_ROUNDING
"""Residual (the same units) that a file's closures may keep when no configuration closes them all exactly:
redundant closures written with rounded numbers (a hinge written as two ball joints on its axis, by a CAD
exporter) disagree by that much. The assembly then closes them as well as they close, and says by how much."""
TURN_SAID = 1e-3
"""A weld's angle (rad) at the start that the report says beside its gap: 0.06 deg, above the rounding of a
file's angles (``1.5708`` for pi / 2 is 4e-6 rad off)."""


class LegWithLoops(ImportError_):
    """A leg with loops inside it (a parallelogram of ball-jointed rods, a ball joint inside a leg): not a serial
    chain, so not written in screwkit's convention; :mod:`screwkit.io.graph` analyses it at the file's
    configuration. ``held``: the serial reading's own advice, where it has one (a closure that ends on passive
    joints beyond the platform, taken with them held), which stands if the graph reading refuses the file too."""

    def __init__(self, message: str, held: str | None = None):
        super().__init__(message)
        self.held = held

    def refusal(self, graph_error: ValueError) -> ValueError:
        """What to raise when the graph reading refuses the file too: the serial reading's advice, where it gave one
        (a toe on a ball beyond the foot: hold it), else the graph's reason."""
        return ImportError_(self.held) if self.held else graph_error


GRAPH_HINT = ("; `screwkit analyze`, `info`, `sweep`, `map`, `trajectory` and `view` (or "
              "screwkit.io.graph_mechanism) analyse it as a graph; `convert` and the commands of serial legs do not")
"""What a :class:`LegWithLoops` message adds."""


GROUNDED = "no joint to the world: the canonical link"
"""How a reader's note on a model that joins no link to the world begins (its canonical link taken as the fixed base,
where Gazebo would let the model float): said on the first line of a report."""


@dataclass(frozen=True)
class Closure:
    """Two frames of the tree that must coincide: ``kind`` "3d" (origins) or "6d" (frames)."""

    name: str
    joint_a: int
    placement_a: NDArray[np.float64]  # 4x4, in joint_a's frame
    joint_b: int
    placement_b: NDArray[np.float64]
    kind: str
    axis_point: bool = False
    """A second point on a hinge's axis (a hinge closed by two "3d" closures, the first at the joint): it makes the
    hinge, but is not where the leg meets the body (:func:`screwkit.io.graph_screws` leaves it out of a leg's ITI
    and OTI points, which would otherwise move with the arbitrary distance between the two points)."""


@dataclass
class ClosedTree:
    """A Pinocchio model, its closures, its motors and the reference joint values of the file."""

    source: str
    model: object
    closures: list[Closure]
    motors: list[str]
    q_reference: NDArray[np.float64]
    output: str | None = None
    output_type: str | None = None  # "point", "frame" or None (decided as the module says)
    file_format: str = ""
    notes: list[str] = field(default_factory=list)  # what reading the file changed (said in the report)
    task_coordinates: tuple[str, ...] | None = None  # a URDF source's <task_coordinates names="...">, kept
    locked: tuple[str, ...] = ()  # joints held at their values in the file (screwkit.io.locking)
    actuated: tuple[str, ...] = ()  # the actuators as the user named them (--actuate), not the file (idem)
    initial: tuple[tuple[str, float], ...] = ()  # joint values given instead of the file's (--initial; idem)
    unactuated: str = ""  # why the file's own actuators cannot be taken: refused unless --actuate names them
    length_unit: str | None = None  # the unit the file was written in, its lengths now in m (screwkit.io.tree_units)
    unit: str = "m"  # the unit of its lengths, for messages: the file's own when it is converted as written
    couplings: tuple[tuple[str, str | None, float, str], ...] = ()
    """A file's couplings of two joints, ``(joint1, joint2, slope, where)``: joint1 moves ``slope`` times as joint2
    (``joint2`` None: joint1 held), each with where it is written; left out only where they constrain nothing
    analysed (:func:`screwkit.io.couplings.check_couplings`)."""
    split: dict[str, str] = field(default_factory=dict)
    """A file's joint of several DoF written as hinges (SDFormat's ball and universal joints), and each hinge: what
    it is, for messages (none is an actuator)."""

    def initial_joints(self) -> list[int]:
        """The ids of the joints ``--initial`` gave values to that the model still has (a locked one is merged away):
        the assembly holds them (:func:`screwkit.io.locking.set_initial`)."""
        return [self.model.getJointId(name) for name, _ in self.initial if self.model.existJointName(name)]

    def start_phrase(self) -> str:
        """Where the assembly starts, for messages: the file's joint values, or those ``--initial`` gave."""
        return ("the joint values given (--initial) and the file's for the others" if self.initial else
                "the file's joint values")

    def written_joint(self, name: str) -> str:
        """The file's joint that the model's joint ``name`` stands for: a ball or universal joint a reader wrote as
        hinges (:attr:`split`), else ``name`` itself."""
        match = re.fullmatch(r"one hinge of \w+ joint (['\"])(.*)\1", self.split.get(name, ""))
        return match.group(2) if match else name

    def body_names(self) -> dict[int, str]:
        """Each joint's body, by the name of its first BODY frame (the body a joint moves, as a leg is named)."""
        return {int(f.parentJoint): f.name for f in reversed(list(self.model.frames)) if str(f.type) == "BODY"}

    def motor_joints(self) -> set[int]:
        """The model's joints of the actuated joints (those of :attr:`motors` the model has)."""
        return {self.model.getJointId(name) for name in self.motors if self.model.existJointName(name)}

    def motor_label(self, name: str) -> str:
        """How a message names the actuated joint ``name``: by the option that named it, as guessed (the file marks
        none), else as the file's."""
        if name in self.actuated:
            return f"--actuate {name}"
        if any(note.startswith(GUESSED) for note in self.notes):
            return (f"guessed actuator {name!r} (the file marks none; --actuate JOINT names the joints that are "
                    "driven)")
        return f"actuated joint {name!r}"
    cut_by_order: tuple[str, ...] = ()
    """Closures of loops the file could as well have closed at another joint, where the reader chose by the file's
    order (SDFormat's breadth-first tree tied): no point output is taken at them unless asked."""
    joint_points: NDArray[np.float64] | None = None
    """Where each joint of the file is (k, 3, world, m), once each, at the file's joint values, where the reader
    chooses the spanning tree (SDFormat): the length scale's points (:func:`_file_length_scale`), the same whatever
    joints the tree leaves out and in whatever order the file lists them. None: the model's joints."""


def declared_task_coordinates(urdf_text: bytes) -> tuple[str, ...] | None:
    """The names of a URDF's ``<task_coordinates names="...">`` (screwkit's element), if it has one."""
    import xml.etree.ElementTree as ElementTree

    try:
        root = ElementTree.fromstring(tolerant_xml(urdf_text))
    except ElementTree.ParseError:
        return None
    names = [element.get("names", "").split() for element in root.findall("task_coordinates")]
    return tuple(names[-1]) if names and names[-1] else None


@dataclass
class ImportReport:
    """What an import did: for ``screwkit convert`` and ``screwkit info``."""

    source: str
    file_format: str
    platform_body: str = ""
    output: str = ""
    planar: bool = False
    chains: list[str] = field(default_factory=list)
    locked: list[str] = field(default_factory=list)
    dropped: list[str] = field(default_factory=list)
    gaps_before: dict = field(default_factory=dict)
    gaps_after: dict = field(default_factory=dict)
    turns_before: dict = field(default_factory=dict)  # a weld's angle at the start, where it is open in rotation
    motors: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    task_coordinates: str = ""
    unit: str = "m"  # of the lengths it gives (the file's own, for a file converted as written and scaled after)
    values: str = "the file's joint values"  # where the assembly started (ClosedTree.start_phrase)

    def lines(self) -> list[str]:
        """The report as lines of text."""
        platform = f", platform body {self.platform_body!r}" if self.platform_body else ""
        planar = ", planar" if self.planar else ""
        out = [f"{self.source}: {self.file_format}{platform}, output {self.output}{planar}"]
        for name in self.gaps_before:
            turn = self.turns_before.get(name, 0.0)
            turned = f" and {np.degrees(turn):.3g} deg" if turn > TURN_SAID else ""
            out.append(f"  closure {name}: gap {self.gaps_before[name]:.3g} {self.unit}{turned} at {self.values}, "
                       f"{self.gaps_after[name]:.1e} after assembly")
        out += [f"  chain {line}" for line in self.chains]
        out.append(f"  actuators: {', '.join(self.motors)}")
        if self.task_coordinates:
            out.append(f"  task coordinates: {self.task_coordinates}")
        if self.locked:
            out.append(f"  idle joints locked at their assembled values: {', '.join(self.locked)}")
        if self.dropped:
            out.append(f"  joints outside every chain, left out: {', '.join(self.dropped)}")
        out += [f"  {note}" for note in self.notes]
        return out


# -- the tree ------------------------------------------------------------------------------------


def _length_scale(model, data) -> float:
    """The root-mean-square distance of the joints from their centroid: the mechanism's own size, the same in any
    world frame (the universe joint, at the world's origin, is not one of them); what the closures' gaps and their
    tolerances are measured in."""
    return _spread(np.array([np.asarray(data.oMi[j].translation) for j in range(1, model.njoints)]).reshape(-1, 3))


def _file_length_scale(tree: ClosedTree, data) -> float:
    """:func:`_length_scale` of the tree's model at the configuration in ``data``, or, where the reader chose the
    spanning tree, of every joint of the file (:attr:`ClosedTree.joint_points`): the joints a tree leaves out
    depend on the order the file lists them in, and a reading in another order must have the same size."""
    return _length_scale(tree.model, data) if tree.joint_points is None else _spread(tree.joint_points)


def _spread(points: NDArray) -> float:
    """The root-mean-square distance of ``points`` (k, 3) from their centroid; 1 where it is zero."""
    spread = np.sqrt(np.mean(np.sum((points - points.mean(axis=0)) ** 2, axis=-1)))
    return float(spread) if spread > 0.0 else 1.0


def nearest_to_lines(projections: NDArray, points: NDArray) -> tuple[NDArray, NDArray]:
    """The point nearest to lines in the least-squares sense, each line given by its projection off itself
    (``projections`` (k, 3, 3): I - u u^T, or I for a point) and a point of it (``points`` (k, 3)); and each line's
    offset from it, perpendicular to the line (k, 3). Solved from the points' centroid: lines rounded off parallel (a
    planar mechanism's) leave the point undecided along them, and it stays near the mechanism."""
    middle = points.mean(axis=0)
    offsets = np.einsum("kij,kj->ki", projections, points - middle)
    centre = middle + np.linalg.lstsq(projections.sum(axis=0), offsets.sum(axis=0), rcond=1e-6)[0]
    return centre, np.einsum("kij,kj->ki", projections, points - centre)


def _lines_scale(model, data, closures=(), kinds=None) -> float:
    """The length that weighs a slide against an angle in the nearest closed configuration, at the configuration in
    ``data``: the root-mean-square distance of the revolute axis lines and ball centres (spherical joints, ``3d``
    closures) from the point nearest to them all (least squares), which neither where the file draws a joint along
    its axis, nor its link frames, nor the world frame change; the joints' spread (:func:`_length_scale`) when that
    is zero (every line through one point) or there are none. ``kinds``: each joint's :func:`joint_kind`, if known."""
    kinds = kinds or {joint: joint_kind(model, joint) for joint in range(1, model.njoints)}
    lines = [(joint, axis if kind == "revolute" else np.zeros(3)) for joint, (kind, axis) in kinds.items()
             if kind in ("revolute", "spherical")]
    directions = np.array([np.asarray(data.oMi[joint].rotation) @ axis for joint, axis in lines]).reshape(-1, 3)
    projections = list(np.eye(3) - directions[:, :, None] * directions[:, None, :])  # each line's projection off
    points = [np.array(data.oMi[joint].translation, dtype=float) for joint, _ in lines]  # itself, a point of it
    for closure in closures:
        if closure.kind == "3d":  # the ball's centre: midway between its two frames (apart where the file is open)
            projections.append(np.eye(3))
            first, second = _frames(model, data, closure)
            points.append((first[:3, 3] + second[:3, 3]) / 2)
    if points:
        projections, points = np.array(projections), np.array(points)
        centre, distances = nearest_to_lines(projections, points)
        spread = float(np.sqrt(np.mean(np.sum(distances**2, axis=-1))))
        if spread > MEETING * float(np.max(np.linalg.norm(points - centre, axis=1))):  # else lines that meet to
            # rounding: a spherical mechanism
            return spread
    return _length_scale(model, data)


def at_point(frame: NDArray, point: NDArray, parent: NDArray | None = None) -> NDArray[np.float64]:
    """A 4x4 frame (in ``parent``'s, the world's when None) moved, unturned, so that its origin is the world
    ``point``."""
    world = frame if parent is None else parent @ frame
    moved = np.eye(4)
    moved[:3, 3] = world[:3, :3].T @ (np.asarray(point, dtype=float) - world[:3, 3])
    return frame @ moved


def ball_of_revolutes(model, joints: list[int], kinds: list[tuple], first: NDArray, scale: float) -> NDArray | None:
    r"""The centre of a ball joint ending a leg beyond the platform, or None: one spherical joint, or three revolute
    ``joints`` in a row (their :func:`joint_kind`\ s ``kinds``; ``first`` the first one's frame, 4x4, world, at zero
    motion) whose axis lines pass within :data:`MEETING` of the length ``scale`` of one point, wherever along them
    the file draws each joint, no two in a row nearly parallel (squared sine above :data:`PARALLEL_FOOT`; the first
    and the third may be, a Z-Y-Z wrist drawn at its singular pose); the centre is the point nearest to the three
    lines."""
    if len(joints) == 1 and kinds[0][0] == "spherical":
        return np.asarray(first, dtype=float)[:3, 3]
    return meeting_point(model, joints, kinds, first, scale) if len(joints) == 3 else None


def meeting_point(model, joints: list[int], kinds: list[tuple], first: NDArray, scale: float) -> NDArray | None:
    r"""The point where the axis lines of revolute ``joints`` in a row meet (two: a universal joint; three: a ball),
    or None: their lines, each at zero motion of the ones before (``first`` the first one's frame, 4x4, world; the
    ``kinds`` from :func:`joint_kind`), pass within :data:`MEETING` of the length ``scale`` of one point, wherever
    along them the file draws each joint, no two in a row nearly parallel (squared sine above
    :data:`PARALLEL_FOOT`); the point is the one nearest to the lines."""
    if len(joints) < 2 or any(kind[0] != "revolute" for kind in kinds):
        return None
    frames = [np.asarray(first, dtype=float)]
    for joint in joints[1:]:  # each at zero motion of the ones before
        frames.append(frames[-1] @ homogeneous(model.jointPlacements[joint]))
    units = np.array([frame[:3, :3] @ kind[1] / np.linalg.norm(kind[1]) for frame, kind in zip(frames, kinds)])
    points = np.array([frame[:3, 3] for frame in frames])
    if any(np.sum(np.cross(units[k], units[k + 1]) ** 2) <= PARALLEL_FOOT for k in range(len(joints) - 1)):
        return None  # two in a row on (nearly) one direction turn about one axis: no ball
    centre, offsets = nearest_to_lines(np.eye(3)[None] - units[:, :, None] * units[:, None, :], points)
    return centre if np.all(np.linalg.norm(offsets, axis=1) <= MEETING * scale) else None


def ball_line(points, closures: list[Closure], scale: float) -> tuple[int, NDArray | None, NDArray]:
    """Ball closures joining the same two bodies, at world ``points`` (one per closure): the rank of their spread
    (0 one point, 1 a hinge through them, 2 or more a weld; to 1e-9 of the length ``scale``), the unit direction of
    the largest spread (None for one point), and the hinge's point: the mean of the points not marked
    :attr:`Closure.axis_point` (a point only on the hinge's line is not where it is), else of all."""
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    spread = points - points[0]
    rank = int(np.linalg.matrix_rank(spread, tol=1e-9 * scale)) if len(points) > 1 else 0
    axis = None
    if rank:
        axis = spread[np.argmax(np.linalg.norm(spread, axis=1))]
        axis = axis / np.linalg.norm(axis)
    joint_points = [point for point, closure in zip(points, closures) if not closure.axis_point]
    return rank, axis, np.mean(joint_points or points, axis=0)


def _frames(model, data, closure: Closure) -> tuple[NDArray, NDArray]:
    return (homogeneous(data.oMi[closure.joint_a]) @ closure.placement_a,
            homogeneous(data.oMi[closure.joint_b]) @ closure.placement_b)


def closure_motions(model, data, closure: Closure) -> list[tuple[NDArray, NDArray, NDArray]]:
    """Per side of a closure (a, then b), at the configuration of ``data`` (its joint Jacobians computed): the rows
    (3, nv) of its frame origin's velocity and of its angular velocity on the velocity coordinates, both in world
    axes, and the frame (4x4, world)."""
    import pinocchio as pin  # Pinocchio: imported where a file of another tool is read

    motions = []
    for joint, frame in zip((closure.joint_a, closure.joint_b), _frames(model, data, closure)):
        jacobian = pin.getJointJacobian(model, data, joint, pin.LOCAL_WORLD_ALIGNED)
        (o0, o1, o2), (w0, w1, w2) = frame[:3, 3] - data.oMi[joint].translation, jacobian[3:]
        moved = np.array([o1 * w2 - o2 * w1, o2 * w0 - o0 * w2, o0 * w1 - o1 * w0])  # (np.cross's, by components)
        motions.append((jacobian[:3] - moved, jacobian[3:], frame))
    return motions


def closure_rows(model, data, closures, scale: float) -> NDArray[np.float64]:
    """The closures' velocity rows (k, nv) at the configuration of ``data`` (its joint Jacobians computed): per
    closure the relative velocity of its two frames' origins (in length scales ``scale``) and, for ``6d``, of their
    rotations (the angular velocities' difference)."""
    rows = [np.zeros((0, model.nv))]
    for closure in closures:
        (moves_a, turns_a, _), (moves_b, turns_b, _) = closure_motions(model, data, closure)
        rows += [(moves_b - moves_a) / scale] + ([turns_b - turns_a] if closure.kind == "6d" else [])
    return np.vstack(rows)


def closure_gaps(tree: ClosedTree, q: NDArray) -> dict[str, float]:
    """Distance (m) between the two frame origins of every closure at q."""
    return {c.name: float(np.linalg.norm(a[:3, 3] - b[:3, 3])) for c, a, b in closure_frames(tree, q)}


def closure_turns(tree: ClosedTree, q: NDArray) -> dict[str, float]:
    """The angle (rad) between the two frames of every ``6d`` closure at q: a weld can be open in rotation alone."""
    import pinocchio as pin  # Pinocchio: imported where a file of another tool is read

    return {c.name: float(np.linalg.norm(pin.log3(a[:3, :3].T @ b[:3, :3]))) for c, a, b in closure_frames(tree, q)
            if c.kind == "6d"}


def closure_frames(tree: ClosedTree, q: NDArray) -> list[tuple[Closure, NDArray, NDArray]]:
    """Every closure with its two frames (4x4, world) at q."""
    import pinocchio as pin  # Pinocchio: imported where a file of another tool is read

    data = tree.model.createData()
    pin.forwardKinematics(tree.model, data, q)
    return [(closure, *_frames(tree.model, data, closure)) for closure in tree.closures]


def assemble(tree: ClosedTree, held=(), nearest: bool = True) -> tuple[NDArray, float]:
    """The closed configuration nearest to the file's reference one, and the length scale.

    Levenberg-Marquardt on the joint velocities integrated from the reference configuration (any joint type, lengths in
    units of :func:`_lines_scale`; the joints ``held``, by id, keep their values), residuals the closures' origin gaps
    in units of the length scale and, for ``6d`` closures, the difference of their rotation matrices (smooth where a
    rotation vector jumps, at half a turn); the Jacobian from Pinocchio's joint Jacobians. Once the residual is within
    the file's rounding (:data:`INCONSISTENCY_TOLERANCE`), 20 more steps at most: closures that close take two or three,
    and rounded redundant ones (a parallelogram of hinges written to 6 decimals) only creep along their floor. Then,
    when ``nearest`` and the closures close, the configuration is slid along the closed ones to the nearest
    (:func:`~screwkit.io.nearest.nearest_closed`): the damped steps reach *a* closed configuration, which depends on how
    the residuals are weighed and so on where the file draws its joints and frames; the nearest one does not. Closures
    that close only to the file's rounding (their largest residual within it) are slid the same way along their floor
    (:data:`~screwkit.io.nearest.FLOOR_MOVE`): the damped steps creep along it (Rhoban's exported spherical manipulator,
    its balls rounded off their sphere: 0.02 rad in 20 steps for 2 % of the residual), and where they stop depended on
    the drawing; the floor's point nearest to the file's values does not. Directions that close the floor's gap only by
    turning the joints far are left alone (a pseudo-inverse of all of them went far from the file's values or left the
    floor). A file whose floor there is beyond the rounding is refused: the damped steps had crept 0.16 rad from its
    values to bring it under (drawings 0.03 rad apart).
    """
    import pinocchio as pin  # Pinocchio: imported where a file of another tool is read

    model = tree.model
    data = model.createData()
    pin.forwardKinematics(model, data, tree.q_reference)
    lengths, kinds = np.zeros(model.nv, dtype=bool), {}  # the velocity coordinates that are lengths (slides, ...)
    for joint in range(1, model.njoints):
        try:
            kinds[joint] = joint_kind(model, joint)
        except ImportError_ as error:  # a zero axis (a Gepetto URDF read by Pinocchio): the file named
            raise ImportError_(f"{tree.source}: {error}") from None
        start = model.joints[joint].idx_v
        lengths[start:start + (1 if kinds[joint][0] == "prismatic" else
                               LENGTH_COORDINATES.get(model.joints[joint].shortname(), 0))] = True
    scale = _file_length_scale(tree, data)
    unit = np.where(lengths, _lines_scale(model, data, tree.closures, kinds), 1.0)  # slides weighed against angles

    def configuration(v):
        return pin.integrate(model, tree.q_reference, v * unit)

    def residuals(v):
        pin.forwardKinematics(model, data, configuration(v))
        rows = []
        for closure in tree.closures:
            a, b = _frames(model, data, closure)
            rows.append((b[:3, 3] - a[:3, 3]) / scale)
            if closure.kind == "6d":  # smooth everywhere (a rotation vector jumps at half a turn)
                rows.append((b[:3, :3] - a[:3, :3]).ravel())
        return np.concatenate(rows)

    def derivatives(v):  # the residuals' Jacobian along the free directions, from Pinocchio's joint Jacobians
        pin.computeJointJacobians(model, data, configuration(v))
        rows = []
        for closure in tree.closures:
            (moves_a, turns_a, frame_a), (moves_b, turns_b, frame_b) = closure_motions(model, data, closure)
            rows.append((moves_b - moves_a) / scale)
            if closure.kind == "6d":  # the rotation matrices' rates: w x each column
                rows.append((np.einsum("ijl,jk,lc->ick", LEVI_CIVITA, turns_b, frame_b[:3, :3])
                             - np.einsum("ijl,jk,lc->ick", LEVI_CIVITA, turns_a, frame_a[:3, :3])).reshape(9, -1))
        chain = pin.dIntegrate(model, tree.q_reference, v * unit, pin.ARG1) * unit
        return np.vstack(rows) @ chain @ directions.T

    if not tree.closures:
        raise ImportError_(f"{tree.source}: no closure: nothing closes the tree into a parallel mechanism.")
    free = np.ones(model.nv, dtype=bool)
    for joint in held:
        free[model.joints[joint].idx_v:model.joints[joint].idx_v + model.joints[joint].nv] = False
    directions = np.eye(model.nv)[free]
    v = np.zeros(model.nv)
    error = residuals(v)
    damping, within = 1e-6, 0
    for _ in range(500):
        norm = float(np.linalg.norm(error))
        within += norm < INCONSISTENCY_TOLERANCE  # closures that close need 2-3 steps from there; rounded ones creep
        if norm < ASSEMBLY_TOLERANCE or damping > 1e8 or within > 20:
            break
        jacobian = derivatives(v)
        normal = jacobian.T @ jacobian + (damping + norm**2) * np.eye(len(directions))
        change = -np.linalg.solve(normal, jacobian.T @ error) @ directions
        change *= min(1.0, 0.5 / max(float(np.max(np.abs(change))), 1e-300))
        candidate = residuals(v + change)
        if np.linalg.norm(candidate) < norm:
            v, error, damping = v + change, candidate, max(damping * 0.1, 1e-12)
        else:
            damping *= 10.0
    if nearest and np.linalg.norm(error) < ASSEMBLY_TOLERANCE:
        v, error = nearest_closed(residuals, derivatives, v, error, directions)
    elif nearest and np.max(np.abs(error)) < INCONSISTENCY_TOLERANCE:  # on a floor: along it only, back from the creep
        direction = np.cumsum(free) - 1  # each free velocity coordinate's direction
        columns = {joint: [direction[k] for k in range(model.joints[joint].idx_v, model.joints[joint].idx_v
                                                       + model.joints[joint].nv) if free[k]]
                   for joint in range(1, model.njoints)}
        loops = [set(model.supports[c.joint_a]) ^ set(model.supports[c.joint_b]) for c in tree.closures]
        blocks = independent_blocks([12 if c.kind == "6d" else 3 for c in tree.closures], loops, columns)
        v, error = nearest_closed(residuals, derivatives, v, error, directions, on_floor=True, blocks=blocks)
    q = configuration(v)
    if np.max(np.abs(error)) >= ASSEMBLY_TOLERANCE:
        gaps = closure_gaps(tree, q)
        worst = max(gaps, key=gaps.get)
        if np.max(np.abs(error)) < INCONSISTENCY_TOLERANCE:
            tree.notes.append(f"the closures close to {gaps[worst]:.3g} {tree.unit} at best (closure {worst!r}): the "
                              "file's numbers disagree by that much (redundant closures written rounded)")
            return q, scale
        found = closure_frames(tree, q)
        if on_one_plane(tree, q, scale, found):  # anchors drawn at different depths on their pins: again
            return assemble(tree, held, nearest)
        where = (f"with {', '.join(f'--initial {name} {value:g}' for name, value in tree.initial)} held (the file's "
                 "values for the other joints)" if tree.initial else "near the file's joint values")
        across = [closure.name for closure, first, second in found if gaps[closure.name] > FILE_ROUNDING * scale
                  and pin_axis(model, q, first, second, loop_kinds(model, closure), scale) is None]
        worst = max(across, key=gaps.get, default=worst)  # (one open across its pins kept the others from one plane)
        closure, first, second = next(item for item in found if item[0].name == worst)
        moved = any(note.startswith(ONE_PLANE) for note in tree.notes)
        advice = along_pins(model, q, first, second, loop_kinds(model, closure), scale, moved) or (
            "" if tree.initial else ": if the file draws the robot far from an assembly, --initial JOINT VALUE gives "
            "joints values nearer one")
        raise ImportError_(f"{tree.source}: the loops cannot be closed {where}: closure "
                           f"{worst!r} still misses by {gaps[worst]:.3g} {tree.unit} after assembly (every closure's "
                           "gap after assembly: " + ", ".join(f"{k} {v:.3g} {tree.unit}" for k, v in gaps.items())
                           + f"){advice}.")
    return q, scale


