r"""Closed-loop graphs: legs with loops inside them (parallelograms of ball-jointed rods), at the file's configuration.

:mod:`screwkit.io.star` writes a closed tree as legs that are serial chains, each closed onto the platform by one
loop joint. A leg whose forearm is a parallelogram of two ball-jointed rods (every industrial Delta) is not one:
two closures end on the platform through the same actuated path. This module analyses such mechanisms from the
graph itself, following the paper's definitions leg by leg (``docs/theory.md``, *Legs with loops inside*):

* **legs**: the bodies other than the base and the platform, joined by tree joints and closures, fall into
  connected groups; a group joined to both the base and the platform is a **leg**, one joined to the platform only
  a tool it carries (a gripper), one joined to the base only an idle branch (both left out, said in the report);
* a leg's **twist system** :math:`S_i`: the platform-twist part of the null space of the leg's closure Jacobian
  (:func:`screwkit.io.compound.platform_twists`: the rates of the leg's joints and the platform twist as unknowns,
  one block of rows per closure of the leg); with actuator ``k`` locked, :math:`S_i^k`. Idle motions (a rod
  spinning about its own axis between two ball joints) lie in the null space but move no platform twist;
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
from functools import cached_property
from os import PathLike
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from screwkit.closure.assembly import DOF_AT_ROUNDING, DOF_MARGIN, LIMITS_IGNORED, rounded_dof_note
from screwkit.closure.task_space import choose_task_axes
from screwkit.common.rotations import cross
from screwkit.common.units import is_angular, spelled_pose
from screwkit.io.closed_tree import (
    ClosedTree,
    Closure,
    ImportError_,
    ImportReport,
    assemble,
    closure_gaps,
    closure_turns,
    homogeneous,
    joint_kind,
    joint_value,
    path_to,
)
from screwkit.io.compound import closed_samples
from screwkit.io.couplings import check_couplings
from screwkit.io.graph_actuators import check_actuators, follow_actuators, split_legs
from screwkit.io.graph_checks import (
    CAUTIONS,
    IN_LOOP_TOLERANCE,
    check_legs,
    check_output,
    reading_cautions,
    refuse_couples_of_forces,
)
from screwkit.io.graph_kinematics import (
    GIMBAL_LOCK,
    TreeKinematics,
    beyond_reach,
    joints_beyond_limits,
    reach_bound,
    rpy_of,
    rpy_rates_inverse,
    solve_poses,
)
from screwkit.io.graph_rounding import drawn_tree
from screwkit.io.graph_screws import (
    GraphLeg,
    LegScrews,
    common_motions,
    dimension_groups,
    equivalent_chains,
    leg_screws,
    locking_legs,
)
from screwkit.io.output import output_frame, platform_body
from screwkit.model.mechanism import SPATIAL_TASK_COORDINATES, checked_task_poses
from screwkit.screw.chain_screws import ChainScrews

__all__ = ["GraphLeg", "GraphMechanism", "LegScrews", "graph_legs", "graph_mechanism", "leg_screws",
           "equivalent_chains", "dimension_groups", "IN_LOOP_TOLERANCE"]

@dataclass(frozen=True)
class GraphMechanism:
    """A closed-loop graph assembled at a configuration ``q`` (the file's, or a pose's): its platform (joint id), its
    legs, and the chain screws of its legs' equivalent chains with their ITI and OTI points
    (:func:`graph_mechanism`); the output frame and its task coordinates (indices into x, y, z, roll, pitch, yaw of
    the frame in the world)."""

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
    kinematics: TreeKinematics
    frame_id: int
    task_axes: tuple[int, ...]

    @property
    def task_coordinates(self) -> tuple[str, ...]:
        """Names of the task coordinates (``x y z`` for a Delta, ``roll pitch yaw`` for a spherical wrist)."""
        return tuple(SPATIAL_TASK_COORDINATES[axis] for axis in self.task_axes)

    @property
    def n_task(self) -> int:
        return len(self.task_axes)

    @property
    def angular(self) -> NDArray[np.bool_]:
        """Which task coordinates are angles."""
        return np.array([is_angular(name) for name in self.task_coordinates], dtype=bool)

    @property
    def length_scale(self) -> float:
        """The mechanism's length scale (m): what its closures measure lengths in, and what weighs angles against
        lengths along a path."""
        return float(self.scale)

    @property
    def dof(self) -> int:
        """The platform's mobility (its task coordinates' count)."""
        return len(self.task_axes)

    @property
    def actuators(self) -> tuple[str, ...]:
        """``leg:joint`` of every actuator, as the indices name them."""
        return tuple(f"{leg.name}:{self.tree.model.names[leg.actuators[0]]}" for leg in self.legs if leg.actuators)

    @property
    def actuator_names(self) -> tuple[str, ...]:
        return self.actuators

    @property
    def actuator_slides(self) -> tuple[bool, ...]:
        """Which actuated joints (:attr:`actuators` order) slide (their values in m; the others turn, in rad)."""
        return tuple(joint_kind(self.tree.model, leg.actuators[0])[0] == "prismatic" for leg in self.legs
                     if leg.actuators)

    @property
    def actuator_legs(self) -> tuple[int, ...]:
        """The leg (index into :attr:`legs`) of each actuator: passive legs have none."""
        return tuple(index for index, leg in enumerate(self.legs) if leg.actuators)

    @property
    def is_planar(self) -> bool:
        return False

    @property
    def named_poses(self) -> dict:
        return {}

    @property
    def home_pose(self) -> NDArray[np.float64]:
        """The task coordinates of this configuration (the file's, for a graph as read)."""
        return self.task_pose()

    def named_pose(self, name: str) -> NDArray[np.float64]:
        raise ValueError(f"Unknown pose {name!r} of mechanism {self.name!r}: a closed-loop graph has no named poses.")

    def check_poses(self, poses, *, degrees: bool = False, where: str = "`poses`") -> NDArray[np.float64]:
        """Poses as a float array (..., n_task), checked as a mechanism's are
        (:func:`~screwkit.model.mechanism.checked_task_poses`)."""
        return checked_task_poses(self, poses, degrees=degrees, where=where)

    def poses_from_degrees(self, values, where: str = "`poses`") -> NDArray[np.float64]:
        """Task coordinates with angles in degrees -> radians (checked; ``where``: what held them)."""
        poses = self.check_poses(values, degrees=True, where=where).copy()
        angular = self.angular
        poses[..., angular] = np.deg2rad(poses[..., angular])
        return poses

    def frame_pose(self, q: NDArray | None = None) -> NDArray[np.float64]:
        """x, y, z (m) and roll, pitch, yaw (rad) of the output frame in the world at configurations q (..., nq;
        default this one's)."""
        q = self.q if q is None else np.asarray(q, dtype=float)
        frame = self.tree.model.frames[self.frame_id]
        transforms = self.kinematics.transforms(q.reshape(-1, self.kinematics.nq))[:, int(frame.parentJoint)]
        world = transforms @ homogeneous(frame.placement)
        pose = np.concatenate([world[:, :3, 3], rpy_of(world[:, :3, :3])], axis=1)
        return pose.reshape(q.shape[:-1] + (6,))

    def task_pose(self) -> NDArray[np.float64]:
        """The task coordinates of this configuration."""
        return self.frame_pose()[list(self.task_axes)]

    def solve(self, poses, *, limits: bool = True) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
        """Closed configurations (n, nq) with the task coordinates at ``poses`` (n, len(task_axes); m, rad, world),
        each reached by continuation from this configuration (:func:`screwkit.io.graph_kinematics.solve_poses`),
        and which are reached."""
        poses = self.check_poses(poses).reshape(-1, self.n_task)
        targets = np.repeat(self.frame_pose()[None], poses.shape[0], axis=0)
        targets[:, list(self.task_axes)] = poses
        return solve_poses(self.tree, self.q, self.scale, self.frame_id, targets, self.task_axes, limits=limits,
                           kinematics=self.kinematics, limited=self.limited)

    def reading_notes(self, *, limits: bool = True) -> list[str]:
        """What a command says of this reading, as of a serial mechanism's: a DOF found at the file's rounding, and
        the legs' joints the configuration puts beyond their limits (a file drawn with a joint outside its range, as
        MuJoCo's qpos0 often is): refused (a ValueError), or said with ``limits`` False (``--ignore-limits``)."""
        beyond = joints_beyond_limits(self.tree.model, self.kinematics, self.q, self.limited, self.scale)
        plural = len(beyond) > 1
        if beyond and limits:
            raise ValueError(f"{self.tree.source}: the configuration puts {'joints' if plural else 'a joint'} of "
                             f"its legs beyond {'their' if plural else 'its'} limits: {'; '.join(beyond)} "
                             "(--ignore-limits reads it all the same; --initial JOINT VALUE on such a joint, or on "
                             "the one driving it, starts the assembly inside them).")
        return ([note for note in self.report.notes if note.startswith((DOF_AT_ROUNDING, *CAUTIONS))]
                + ([f"{LIMITS_IGNORED}{'; '.join(beyond)}"] if beyond else []))

    @cached_property
    def limited(self) -> NDArray[np.bool_]:
        """(nv,) the velocity coordinates of the legs' joints: those whose limits a pose keeps (a branch that
        reaches no leg, a biped's other leg, does not move with the platform and is not checked)."""
        joints = {joint for leg in self.legs for joint in leg.joints}
        return np.array([int(joint) in joints for joint in self.kinematics.column_joint], dtype=bool)

    def reach(self, *, limits: bool = True) -> float:
        """The farthest the output frame can be from the world origin (m), an upper bound
        (:func:`screwkit.io.graph_kinematics.reach_bound`); infinite through a free joint or a slider without limits."""
        frame = self.tree.model.frames[self.frame_id]
        return reach_bound(self.kinematics, int(frame.parentJoint), homogeneous(frame.placement), limits=limits)

    def _beyond_reach(self, target: NDArray, task_axes: tuple[int, ...], limits: bool) -> bool:
        """Whether the frame pose ``target`` (6,) holds, in ``task_axes``, a position beyond :meth:`reach`
        (:func:`screwkit.io.graph_kinematics.beyond_reach`, nothing spared): for the reason a refusal gives."""
        frame = self.tree.model.frames[self.frame_id]
        return bool(beyond_reach(self.kinematics, int(frame.parentJoint), homogeneous(frame.placement), target[None],
                                 task_axes, 0.0, limits=limits)[0])

    def unreachable(self, pose, *, limits: bool = True) -> tuple[str, str]:
        """``(kind, reason)`` of task coordinates ``pose`` (m, rad) that :meth:`solve` does not reach: ``"joint
        limit"`` when the continuation reaches them once the joint limits are left aside, else ``"closure"``."""
        names = spelled_pose(self.task_coordinates, pose)
        target = self.frame_pose()
        target[list(self.task_axes)] = pose
        if self._beyond_reach(target, self.task_axes, limits=False):
            return "closure", (f"{self.tree.source}: no closed configuration puts the output frame at ({names}): it "
                               f"is never farther than {self.reach(limits=False):.4g} m from the world origin")
        free_q, free_reached = self.solve(np.asarray(pose, dtype=float)[None], limits=False)
        if {3, 5} & set(self.task_axes) and abs(np.cos(self.frame_pose(free_q[0])[4])) <= GIMBAL_LOCK:
            return "closure", (f"{self.tree.source}: the output frame is met at ({names}) only at a gimbal lock (its "
                               "pitch at +-90 deg, where roll and yaw are one angle and any value of either reads as "
                               "met): not a pose this frame's angles tell")
        if limits and free_reached[0]:
            beyond = joints_beyond_limits(self.tree.model, self.kinematics, free_q[0], self.limited, self.scale)
            plural = len(beyond) > 1
            return "joint limit", (f"{self.tree.source}: at ({names}) the configuration reached from the file's by "
                                   f"continuation puts {'joints' if plural else 'a joint'} beyond "
                                   f"{'their' if plural else 'its'} limits: {'; '.join(beyond)}")
        return "closure", (f"{self.tree.source}: no closed configuration reached from the file's by continuation "
                           f"puts the output frame at ({names}); the file's configuration has it at "
                           f"({spelled_pose(self.task_coordinates, self.task_pose() + 0.0)})")  # (no -0)

    def at_pose(self, position, rpy=None, *, limits: bool = True) -> GraphMechanism:
        """The mechanism with its output frame at ``position`` (m, world frame) and orientation ``rpy`` (rad; default:
        its task coordinates' angles as they are, any other angle where the closures put it), reached by continuation
        from this configuration (the working mode followed). A ValueError names the pose when the frame cannot be
        put there (out of reach, a rotation the legs do not allow, or a joint beyond its limits)."""
        position = np.asarray(position, dtype=float).reshape(-1)
        if position.shape != (3,) or not np.all(np.isfinite(position)):
            raise ValueError(f"Expected a finite position (x, y, z), got {position.tolist()}.")
        target = self.frame_pose()
        target[:3] = position
        if rpy is not None:
            target[3:] = np.asarray(rpy, dtype=float)
        held = tuple(range(6)) if rpy is not None else tuple(sorted({0, 1, 2} | set(self.task_axes)))
        q, reached = solve_poses(self.tree, self.q, self.scale, self.frame_id, target[None], held,
                                 limits=limits, kinematics=self.kinematics, limited=self.limited)
        if not reached[0]:
            why = (f"out of reach: the output frame is never farther than {self.reach(limits=limits):.4g} m from the "
                   "world origin" if self._beyond_reach(target, held, limits)
                   else "out of reach, a rotation the legs do not allow, or a joint beyond its limits")
            raise ValueError(f"{self.tree.source}: no closed configuration reached from the current one puts the "
                             f"output frame at {np.round(position, 9).tolist()} m"
                             + ("" if rpy is None else f", rpy {np.round(np.degrees(rpy), 9).tolist()} deg")
                             + f" ({why}).")
        return graph_mechanism(self.tree, q=q[0], scale=self.scale)

    def at_actuators(self, values, *, limits: bool = True) -> GraphMechanism:
        """The mechanism with its actuated joints at ``values`` (rad or m, :attr:`actuators` order), reached from this
        configuration by continuation (:func:`~screwkit.io.graph_actuators.follow_actuators`: small steps of the
        actuators, the closures assembled at each with them held, so the working mode is followed). A ValueError names
        the step whose loops cannot close (values out of reach, past a singular configuration, or redundant ones that
        disagree) or the joints a configuration puts beyond their limits."""
        values = np.asarray(values, dtype=float).reshape(-1)
        if values.shape != (len(self.actuators),) or not np.all(np.isfinite(values)):
            raise ValueError(f"Expected {len(self.actuators)} finite actuator values ({', '.join(self.actuators)}), "
                             f"got {values.tolist()}.")
        try:
            q = follow_actuators(self, self.q, values)
        except ValueError as error:
            raise ValueError(f"{self.tree.source}: no closed configuration reached from the current one puts the "
                             f"actuators at the values given: {error}.") from None
        model = self.tree.model
        beyond = joints_beyond_limits(model, self.kinematics, q, self.limited, self.scale)
        if beyond and limits:
            raise ValueError(f"{self.tree.source}: the actuator values put joints of its legs beyond their limits: "
                             f"{'; '.join(beyond)} (--ignore-limits reads it all the same).")
        return graph_mechanism(self.tree, q=q, scale=self.scale)

    def check_study(self, *, closed_forms: bool = False, fault_type: str = "free-swinging") -> None:
        """A ValueError when a study asks these legs for what they do not have: closed forms, link faults."""
        if closed_forms or fault_type != "free-swinging":
            raise ValueError(f"{self.name}: a mechanism whose legs have loops inside them is analysed by the generic "
                             "screw path with free-swinging faults (no closed forms, no link faults).")

    def indices(self, **options):
        """Every index at this configuration (:func:`screwkit.indices.analysis.analyze`'s options)."""
        from screwkit.indices.analysis import analyze  # the index layer, above io: only when indices are asked

        self.check_study(fault_type=options.get("fault_type", "free-swinging"))
        options.setdefault("detail", True)
        options.setdefault("dof", len(self.task_axes))
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
    motors = {model.getJointId(name): name for name in tree.motors}  # (each a joint: read_closed_tree)
    body_names = tree.body_names()
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
        first = min(group, key=lambda b: (b not in body_names, len(path_to(model, b)), b))  # a body, if any
        legs.append(GraphLeg(body_names.get(first, tree.written_joint(model.names[first])), joints, tuple(ends), spine,
                             actuated))
        placed.update(actuated)
    direct = tuple(c for c in tree.closures if {c.joint_a, c.joint_b} == {0, platform})
    if direct:  # the platform pinned to the base by closures alone (an H link's pivot on the arm): a passive leg
        # of no joint, whose twist system the closures leave (a ball's turns about its point; two on an axis, a hinge)
        legs.append(GraphLeg(direct[0].name, (), direct, False, ()))
    if model.parents[platform] == 0 and model.joints[platform].nv != 6:
        kind, _ = joint_kind(model, platform)
        name = tree.written_joint(model.names[platform])
        if platform in motors:
            others = ", ".join(motor for joint, motor in motors.items() if joint != platform)
            verb = "moves" if kind == "prismatic" else "turns"
            raise ImportError_(f"{tree.source}: actuated joint {name!r} ({kind}) {verb} the platform body on the base "
                               "directly, with no link between: a leg screwkit does not analyse (the actuation wrench "
                               "acts on no link of its own)" + (f"; --actuate names the actuators without it (the "
                                                                f"file's others: {others})." if others else "."))
        # a pin (or slide, ball...) holding the platform on the base: a passive leg of that one joint, whose twist
        # system is the joint's (a foot on its ankle pin, turned by a crank and rod)
        legs.append(GraphLeg(name, (platform,), (), True, ()))
    for joint, name in motors.items():
        if joint not in placed:
            raise ImportError_(f"{tree.source}: actuated joint {name!r} is on no leg (a leg joins the base to the "
                               "platform).")
    return sorted(legs, key=lambda leg: leg.name)


def _task_axes(tree: ClosedTree, state, frame_id: int, motion: NDArray) -> tuple[int, ...]:
    """The output frame's task coordinates among x, y, z, roll, pitch, yaw: the file's declared ones, else chosen
    from the motion space (:func:`screwkit.closure.task_space.choose_task_axes`)."""
    frame = state.transforms[0, tree.model.frames[frame_id].parentJoint] @ homogeneous(
        tree.model.frames[frame_id].placement)
    offset = (frame[:3, 3] - state.centre[0]) / state.scale
    omega = motion[:, :3]
    rates = np.concatenate([motion[:, 3:] + cross(omega, offset),
                            (rpy_rates_inverse(rpy_of(frame[None, :3, :3]))[0] @ omega.T).T], axis=1).T
    if tree.task_coordinates:
        unknown = [name for name in tree.task_coordinates if name not in SPATIAL_TASK_COORDINATES]
        axes = tuple(sorted(SPATIAL_TASK_COORDINATES.index(n) for n in tree.task_coordinates if n not in unknown))
        singular = np.linalg.svd(rates[list(axes)], compute_uv=False) if axes else np.zeros(0)
        if unknown or len(axes) != len(motion) or (singular.size and singular[-1] <= 1e-6):
            raise ImportError_(f"{tree.source}: <task_coordinates> {' '.join(tree.task_coordinates)}: expected "
                               f"{len(motion)} independent coordinates of the platform's motion among "
                               f"{' '.join(SPATIAL_TASK_COORDINATES)}.")
        return axes
    return choose_task_axes(rates, np.array([False] * 3 + [True] * 3), len(motion))


def graph_mechanism(tree: ClosedTree, q: NDArray | None = None, scale: float | None = None) -> GraphMechanism:
    """The closed tree assembled at the file's configuration (or at ``q``, a closed configuration, with the length
    scale ``scale``), its legs and their equivalent chains."""
    if not isinstance(tree, ClosedTree):
        got = (f"the name or path {str(tree)!r}: read it first, graph_mechanism(read_closed_tree(path)), a bundled "
               "name's path from screwkit.io.loader.bundled_path(name)" if isinstance(tree, (str, PathLike))
               else f"{type(tree).__name__}")
        raise TypeError(f"graph_mechanism expects a ClosedTree (from screwkit.io.read_closed_tree), got {got}.")
    report = ImportReport(source=tree.source, file_format=tree.file_format, values=tree.start_phrase())
    at_file = q is None or scale is None
    if at_file:
        q, scale = assemble(tree, held=tree.initial_joints())
        drawn = drawn_tree(tree, q)  # (axes parallel to the file's rounding: parallel, then assembled again)
        if drawn is not tree:
            tree = drawn
            q, scale = assemble(tree, held=tree.initial_joints())
    model = tree.model
    frame_id = output_frame(tree)
    frame = model.frames[frame_id]
    report.notes[:0] = tree.notes
    platform = int(frame.parentJoint)
    if platform == 0:
        raise ImportError_(f"{tree.source}: the output frame {frame.name!r} is on the fixed base.")
    report.platform_body = platform_body(model, frame_id)
    legs = graph_legs(tree, platform, report)
    if not legs:
        raise ImportError_(f"{tree.source}: no leg joins the base to the platform {report.platform_body!r}.")
    deferred = check_actuators(tree, legs, platform)  # (first: a serial stage left free is what to hold)
    several = [leg for leg in legs if len(leg.actuators) > 1]
    if several:  # (the copies named, not the leg: its name is its first body in the file's order)
        legs = split_legs(tree, legs)
        for leg in several:
            copies = ", ".join(f"{copy.name} ({tree.written_joint(model.names[copy.actuators[0]])})"
                               for copy in legs if copy.of == leg.name)
            report.notes.append(f"chains {copies}: one leg with loops inside it and {len(leg.actuators)} actuators, "
                                "analysed one actuator at a time (the others free), an equivalent chain each")
    check_couplings(tree, q, scale, {joint for leg in legs for joint in leg.joints}, platform, report.notes)
    kinematics = TreeKinematics.of(model, tree.source)
    screws, state = leg_screws(tree, kinematics, platform, legs, q, scale)
    if at_file:
        def nearby():  # closed configurations near the file's, only when a leg's check needs them
            samples = closed_samples(tree, q, scale, count=3)
            return leg_screws(tree, kinematics, platform, legs, np.array(samples), scale)[0] if samples else []

        check_legs(tree, legs, screws, nearby, platform, deferred)
        check_output(tree, screws, report.platform_body, legs, deferred)
    chains, iti_points, oti_points = equivalent_chains(legs, screws, state, np.array([0]), model)
    chains = [ChainScrews(c.twists[0], c.points[0], c.actuated, c.name, c.joint_names) for c in chains]
    counted = []
    motion = common_motions(screws, counted=counted)
    counted = np.array(counted)
    small = counted[counted <= DOF_MARGIN]
    if small.size:  # as closure.assembly.mobility_notes says it of serial legs
        report.notes.append(rounded_dof_note(len(motion), small, "legs"))
    task_axes = _task_axes(tree, state, frame_id, motion)
    if not task_axes and not at_file:  # the file's configuration moved: a pose asked on a singularity
        raise ImportError_(f"{tree.source}: the platform {report.platform_body!r} cannot move at the pose asked: its "
                           f"legs allow no twist in common there{locking_legs(legs, screws)} (a singular pose, such as "
                           "legs stretched or folded at the workspace's boundary: a pose beside it reads the indices)")
    if not task_axes:
        raise ImportError_(f"{tree.source}: the platform {report.platform_body!r} cannot move: analysed as a graph, "
                           f"its legs allow no twist in common at the file's configuration{locking_legs(legs, screws)} "
                           "(a loop inside a leg that the file's numbers make rigid reads so: hinges drawn parallel "
                           "but written further apart than the file's rounding, 1e-5 rad, or lines drawn through one "
                           "point that miss it: the graph makes parallel only axes within the rounding).")
    if at_file:
        refuse_couples_of_forces(tree, legs, chains, state)
        report.notes += reading_cautions(legs, chains)
    gaps = closure_gaps(tree, tree.q_reference)
    report.gaps_before, report.gaps_after = gaps, closure_gaps(tree, q)
    report.turns_before = closure_turns(tree, tree.q_reference)
    report.motors = [model.names[leg.actuators[0]] for leg in legs if leg.actuators]
    report.chains = [f"{leg.name}: {len(leg.joints)} joints ({', '.join(model.names[j] for j in leg.joints)}), "
                     f"{len(leg.closures)} closure(s), twist system of dimension {len(chain.twists)}"
                     for leg, chain in zip(legs, chains)]
    report.notes.append("legs with loops inside them: analysed as a graph (screwkit.io.graph)")
    passive = [leg.name for leg in legs if not leg.actuators]
    if passive:  # said: a leg whose motor the file leaves out reads so too
        report.notes.append(f"leg(s) {', '.join(passive)}: no actuator, passive: each constrains the platform only")
    report.output = (f"the frame of body {report.platform_body!r}" if frame.name == report.platform_body
                     else f"frame {frame.name!r} on body {report.platform_body!r}")  # (a site on it, named)
    report.task_coordinates = " ".join(SPATIAL_TASK_COORDINATES[a] for a in task_axes)
    return GraphMechanism(Path(tree.source).stem, tree, q, scale, platform, report.platform_body, tuple(legs),
                          tuple(chains), iti_points[0], oti_points[0], report, kinematics, frame_id, task_axes)
