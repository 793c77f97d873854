"""A closed tree (MJCF equalities, Gepetto robot.yaml) written in screwkit's convention.

screwkit's convention (``docs/urdf-convention.md``) is a *star*: a platform hanging from the base
by a floating (or planar) joint, and legs, each a serial chain from the base closed onto the
platform by one loop joint. :func:`convert_tree` maps a closed tree
(:class:`~screwkit.io.closed_tree.ClosedTree`) onto it:

1. **Assembly** (:func:`~screwkit.io.closed_tree.assemble`): the closures closed near the file's
   joint values, gaps and working mode reported.
2. **Platform.** The body carrying the output frame (:func:`~screwkit.io.output.output_frame`: named, or a
   frame called effector, eff, ee, tool, tcp, foot or platform, or where the legs meet). Its own tree path from
   the root is one leg, welded to the platform, or, where the platform hangs from it by a ball joint, closed onto
   it by that ball (a leg of the ball alone where it is on the base).
3. **Legs and loop joints.** Every closure onto the platform joins a leg (a tree path from the
   root that shares no joint with another leg) to it; the joints between the platform body and
   the closure frame become the loop joint: none (a ``6d`` weld: ``fixed``; a ``3d`` closure:
   ``spherical``), one revolute or prismatic joint (``revolute``/``prismatic``), two revolute joints whose
   axes meet (``universal``), or three revolute joints through one point or a ball joint (``spherical``). A
   closure on the base itself is a leg of its loop joint alone (a four-bar's rocker pinned to the ground, the
   rocker the platform), or, planar, of its pin and the one joint beyond the platform as the loop joint (the
   coupler the platform). Closures between two legs make **compound legs** (:mod:`screwkit.io.compound`): each
   keeps its actuated leg and writes its passive legs as one equivalent constraint chain, or is refused with the
   reason. Loops that leave a leg's own path, and actuators on branches closed onto other legs (closed-loop
   transmissions), are refused with the closure named.
4. **Idle joints.** A leg whose joint twists are dependent at the assembly (a second pin coaxial
   with the closure pin, the free spin of an S-P-S leg) has passive joints locked at their
   assembled values, from its end backwards, until they are independent: the span of the leg's
   twists, so the platform's motion and every index, is unchanged; the report names them. A leg
   whose twists span less at the assembly than at joint values near it (a crank and its rod on
   one line, a dead centre) is refused, naming ``--initial`` (:mod:`screwkit.io.idle_joints`).
5. **Output.** When every closure onto the platform meets it at one point (in a plane: on one line along the
   normal, wherever along their pins they are drawn) and joins it by every rotation about that point (ball
   joints; pins about the plane's normal in a planar mechanism),
   the platform's rotations about the point are idle and the output is the point (a five-bar's
   distal joint, where pressure angles are measured); otherwise the output frame, whatever points
   the closures reference (welds at the platform body's origin make a 6-DOF platform, not a point).
   A mechanism whose revolute axes are all parallel (and slides perpendicular to them) is written
   planar, its ball closures as pins about the normal.

The result is the text of a URDF in screwkit's convention and an
:class:`~screwkit.io.closed_tree.ImportReport`.
"""


from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from screwkit.common.rotations import rotation_with_z_along
from screwkit.common.tolerances import FILE_ROUNDING
from screwkit.io.closed_tree import (
    GRAPH_HINT,
    ClosedTree,
    Closure,
    ImportError_,
    ImportReport,
    LegWithLoops,
    assemble,
    at_point,
    ball_line,
    ball_of_revolutes,
    closure_gaps,
    closure_turns,
    homogeneous,
    inverse,
    joint_kind,
    joint_value,
    meeting_point,
    path_to,
)
from screwkit.io.compound import compound_groups, compound_legs
from screwkit.io.couplings import check_couplings
from screwkit.io.drawn_parallelograms import drawn_parallelograms
from screwkit.io.graph_rounding import drawn_pairs
from screwkit.io.idle_joints import INDEPENDENCE_TOLERANCE, lock_idle
from screwkit.io.locking import platform_motions
from screwkit.io.output import output_frame, platform_body
from screwkit.io.rounding import drawn_lines, held_limits, turned_joint
from screwkit.io.star_plane import idle_about_the_meeting_point, in_plane, nearly_planar, planar_loops, planar_normal
from screwkit.io.star_writing import (
    UNLIMITED_SLIDE,
    base_frame,
    in_base,
    joint_motion,
    largest_changes,
    origin_of,
    pose_of,
    write_base_pin,
    write_equivalent,
)
from screwkit.io.written_angles import written_turns
from screwkit.model.urdf_writer import UrdfWriter

__all__ = ["convert_tree", "UNLIMITED_SLIDE", "INDEPENDENCE_TOLERANCE"]


# -- the star --------------------------------------------------------------------------------------


@dataclass
class _Leg:
    joints: list[int]
    loop: str  # fixed, revolute, prismatic, universal, spherical
    predecessor: NDArray  # 4x4 in the leg end's joint frame
    successor_world: NDArray  # 4x4 world pose of the platform-side loop frame at the assembly
    axis: NDArray | None
    loop_dofs: list[tuple[str, NDArray, NDArray]]  # world (kind, axis, point) of the loop DoFs at the assembly
    closure: str
    locked: list[int] = field(default_factory=list)
    offsets: dict = field(default_factory=dict)  # world offsets of hinges moved onto a parallelogram's midline
    sources: tuple[Closure, ...] = ()  # the closures onto the platform that make its loop joint (none: the platform
    # body's own path; two ball closures on one hinge's axis, or three or more of a weld)
    base_dofs: list = field(default_factory=list)  # world (kind, axis, point) of a ball closed on the base itself,
    # written as the leg's first joints (a four-bar's rocker pinned to the ground, its joint onto the coupler the loop)
    axis2: NDArray | None = None  # a universal loop's second axis, in the loop frame
    loop_names: tuple[str, ...] = ()  # the model joints its loop DoFs are, where they are joints (the file's rounding)


def _loop_of(tree: ClosedTree, data, closure: Closure, platform: int, scale: float) -> _Leg:
    """The leg and loop joint of a closure (side b made the platform side)."""
    model = tree.model
    a_path, b_path = path_to(model, closure.joint_a), path_to(model, closure.joint_b)
    on_platform_a, on_platform_b = platform in a_path, platform in b_path
    if on_platform_a and not on_platform_b:
        closure = Closure(closure.name, closure.joint_b, closure.placement_b, closure.joint_a, closure.placement_a,
                          closure.kind, closure.axis_point)
        a_path, b_path = b_path, a_path
    elif on_platform_a:
        bodies = [frame.name for frame in model.frames if int(frame.parentJoint) == platform
                  and str(frame.type) == "BODY"]
        named = f"body {bodies[0]!r}" if bodies else f"the body joint {model.names[platform]!r} turns"
        carried = (f"{tree.source}: closure {closure.name!r} has both frames on the platform's side (the platform: "
                   f"{named}, " + ("as --output names it" if tree.output else "taken as the file names none")
                   + "): a loop the platform carries, which joins it to no leg; --output names another platform, a "
                   "body the loops reach from the base.")
        # the graph reading leaves a loop the platform carries out (a foot's toe rods on the shin taken as the
        # platform); where it refuses the file too, its own reason is given
        raise LegWithLoops(carried[:-1] + GRAPH_HINT + ".")
    after = b_path[b_path.index(platform) + 1:]  # joints between the platform body and frame b
    frame_a = homogeneous(data.oMi[closure.joint_a]) @ closure.placement_a
    kinds = [joint_kind(model, joint) for joint in after]
    if closure.kind == "3d":
        if after and not a_path and len(after) == 1 and kinds[0][0] in ("revolute", "prismatic"):
            # a ball on the base itself (a four-bar's rocker pinned to the ground, the coupler the platform): the
            # leg is that ball, then the joint beyond the platform as its loop joint, as a weld's would be
            kind, axis = kinds[0]
            zero = homogeneous(data.oMi[model.parents[after[0]]]) @ homogeneous(model.jointPlacements[after[0]])
            base = [("revolute", np.eye(3)[:, k], frame_a[:3, 3]) for k in range(3)]
            return _Leg([], kind, homogeneous(data.oMi[after[0]]), zero, axis, [(kind, zero[:3, :3] @ axis,
                        zero[:3, 3])], closure.name, sources=(closure,), base_dofs=base,
                        loop_names=(model.names[after[0]],))
        if after:
            _refuse_beyond(tree, after, f"closure {closure.name!r} (3d) ends on joints "
                           f"{', '.join(model.names[j] for j in after)} beyond the platform: not a loop joint "
                           "screwkit supports", data, platform, scale)
        centre = frame_a[:3, 3]
        axes = [("revolute", frame_a[:3, k], centre) for k in range(3)]
        return _Leg(a_path, "spherical", closure.placement_a, frame_a, None, axes, closure.name, sources=(closure,))
    if not after:
        return _Leg(a_path, "fixed", closure.placement_a, frame_a, None, [], closure.name, sources=(closure,))
    # the platform-side loop frame: the first joint beyond the platform at zero motion
    first = after[0]
    zero = homogeneous(data.oMi[model.parents[first]]) @ homogeneous(model.jointPlacements[first])
    predecessor = closure.placement_a @ inverse(closure.placement_b)  # frame b's joint frame, on leg a
    if len(after) == 1 and kinds[0][0] in ("revolute", "prismatic"):
        kind, axis = kinds[0]
        world_axis = zero[:3, :3] @ axis
        return _Leg(a_path, kind, predecessor, zero, axis, [(kind, world_axis, zero[:3, 3])], closure.name,
                    sources=(closure,), loop_names=(model.names[first],))
    ball = ball_of_revolutes(model, after, kinds, zero, scale)
    if ball is not None:  # both loop frames at the ball's centre, wherever the file draws its revolutes
        zero, predecessor = at_point(zero, ball), at_point(predecessor, ball, homogeneous(data.oMi[closure.joint_a]))
        axes = [("revolute", zero[:3, k], ball) for k in range(3)]
        return _Leg(a_path, "spherical", predecessor, zero, None, axes, closure.name, sources=(closure,))
    centre = meeting_point(model, after, kinds, zero, scale) if len(after) == 2 else None
    if centre is not None:  # a universal joint, seen from the leg: its second hinge's turn, then its first's
        second = homogeneous(model.jointPlacements[after[1]])
        predecessor = at_point(predecessor @ inverse(second), centre, homogeneous(data.oMi[closure.joint_a]))
        axes = (second[:3, :3] @ kinds[1][1], kinds[0][1])  # in the loop frames, which both hinges at 0 make one
        world = (np.asarray(data.oMi[after[1]].rotation) @ kinds[1][1], zero[:3, :3] @ kinds[0][1])  # as assembled
        return _Leg(a_path, "universal", predecessor, at_point(zero, centre), axes[0],
                    [("revolute", axis, centre) for axis in world], closure.name, sources=(closure,), axis2=axes[1],
                    loop_names=(model.names[after[1]], model.names[after[0]]))
    _refuse_beyond(tree, after, f"closure {closure.name!r} ends on joints "
                   f"{', '.join(f'{model.names[j]} ({k[0]})' for j, k in zip(after, kinds))} beyond the platform: "
                   "screwkit supports none, one revolute or prismatic joint, two revolute joints whose axes meet "
                   "(a universal joint), or three revolute joints through one point (a spherical joint)",
                   data, platform, scale)


def _spine(model, data, platform: int) -> _Leg:
    """The platform's own path as a leg: the platform its last link, or, where the platform hangs from a link by a
    ball joint, the path to that link with the ball its loop joint, at the ball's centre as a ball closure's is (a
    Gepetto foot on three R-R-R-S legs, the first of which carries it); a ball on the base (a wrist's centre) is a
    leg of its loop joint alone, named after it."""
    path = path_to(model, platform)
    if joint_kind(model, platform)[0] != "spherical":
        return _Leg(path, "fixed", np.eye(4), homogeneous(data.oMi[platform]), None, [], "")
    placement = homogeneous(model.jointPlacements[platform])  # the ball's frame on the link, as it is drawn
    frame, alone = homogeneous(data.oMi[int(model.parents[platform])]) @ placement, len(path) == 1
    return _Leg(path[:-1], "spherical", frame if alone else placement, frame, None, [
        ("revolute", frame[:3, k], frame[:3, 3]) for k in range(3)], model.names[platform] if alone else "")


def _refuse_beyond(tree: ClosedTree, after: list[int], what: str, data, platform: int, scale: float) -> None:
    """Refuse a closure that ends on joints ``after`` between the platform body and it (``what`` says so), with the
    options that hold them (the bodies beyond then move with the platform as one body: two platforms joined by a
    ball, analysed as one) where the platform then keeps every motion (:func:`~screwkit.io.locking.platform_motions`:
    held, a four-bar's coupler and rocker hinges beyond its crank leave a structure, a five-bar leg's knee beyond its
    foot one motion of two), else naming ``--output``; with an
    actuated joint among them, no such advice (held, it would drive nothing: the platform carries the actuator,
    which drives the loop from there) but the graph's reading, which models it."""
    names = list(dict.fromkeys(tree.written_joint(tree.model.names[j]) for j in after))
    motors = [name for name in names if name in tree.motors]
    if motors:
        raise LegWithLoops(f"{tree.source}: {what}, and actuated joint(s) {', '.join(motors)} among them (an actuator "
                           "the platform carries drives the loop)" + GRAPH_HINT + ".")
    them = "it" if len(names) == 1 else "them"
    held = (f"{tree.source}: {what}; --lock {' --lock '.join(names)} holds {them} where the file puts {them}, the "
            "bodies beyond moving with the platform as one body")
    left, whole = (platform_motions(tree, data, platform, held_joints, scale) for held_joints in (after, ()))
    if left < whole:  # held, the loop's joints would take the platform's motions away (a five-bar leg's knee: 2 to 1)
        lost = (f"leave the platform {left} of its {whole} motions" if left else "leave the platform no motion "
                "(a structure)")
        held = (f"{tree.source}: {what}; held, {'it' if len(names) == 1 else 'they'} would {lost}: --output names "
                "another platform, a body the loops reach from the base")
    # the graph reading takes them as joints of the leg the closure ends (a slider-crank's rod hinged on the slider
    # taken as the platform, which held would not move); where it cannot, holding them is the advice
    raise LegWithLoops(held + GRAPH_HINT + ".", held=held + ".")


def _platform_legs(tree: ClosedTree, data, closures: list[Closure], platform: int, scale: float,
                   report: ImportReport) -> list[_Leg]:
    """One leg per closure onto the platform; two ball closures between the same two bodies (a hinge written as two
    ball joints on its axis, as CAD exporters write it for MuJoCo) are one revolute loop about the line through
    them, three or more not on one line one weld."""
    groups: dict[tuple[int, int], list[Closure]] = {}
    for closure in closures:
        groups.setdefault(tuple(sorted((closure.joint_a, closure.joint_b))), []).append(closure)
    legs = []
    for group in groups.values():
        balls = [c for c in group if c.kind == "3d"]
        if len(group) == 1 or len(balls) != len(group):
            legs += [_loop_of(tree, data, closure, platform, scale) for closure in group]
            continue
        first = _loop_of(tree, data, balls[0], platform, scale)
        points = [_loop_of(tree, data, c, platform, scale).successor_world[:3, 3] for c in balls]
        rank, axis, centre = ball_line(points, balls, scale)
        names = ", ".join(repr(c.name) for c in balls)
        if rank == 0:
            legs.append(first)
            continue
        if rank >= 2:
            first.loop, first.loop_dofs, first.axis, first.sources = "fixed", [], None, tuple(balls)
            report.notes.append(f"ball closures {names} join the same two bodies at points not on one line: a weld")
            legs.append(first)
            continue
        frame = np.eye(4)
        frame[:3, :3] = rotation_with_z_along(axis)
        frame[:3, 3] = centre
        leg_end = homogeneous(data.oMi[first.sources[0].joint_a])
        legs.append(_Leg(first.joints, "revolute", inverse(leg_end) @ frame, frame, np.array([0.0, 0.0, 1.0]),
                         [("revolute", axis, centre)], first.closure, sources=tuple(balls)))
        report.notes.append(f"ball closures {names} join the same two bodies on one line: the hinge through them")
    return legs


def _without_carried_loops(tree: ClosedTree, platform: int, report: ImportReport) -> list[Closure]:
    """The closures but the loops the platform carries (both frames beyond the platform: an excavator's arm and
    bucket linkages on its boom taken as the platform), left out and said, as the graph reading leaves out a tool
    the platform carries; all of them where another closure onto the platform ends beyond it through a joint such a
    loop moves (the loop may hold that joint)."""
    model = tree.model

    def beyond(joint: int) -> list[int]:
        path = path_to(model, joint)
        return path[path.index(platform) + 1:] if platform in path else []

    carried = [c for c in tree.closures if platform in path_to(model, c.joint_a) and platform in
               path_to(model, c.joint_b)]
    moved = {j for c in carried for j in beyond(c.joint_a) + beyond(c.joint_b)}
    others = [c for c in tree.closures if c not in carried]
    if not carried or any(set(beyond(c.joint_a) + beyond(c.joint_b)) & moved for c in others):
        return list(tree.closures)
    report.notes.append(f"closure(s) {', '.join(repr(c.name) for c in carried)}: loop(s) the platform carries (both "
                        "frames beyond it), joined to no leg: left out, moving with the platform")
    return others


def convert_tree(tree: ClosedTree) -> tuple[str, ImportReport]:
    """The URDF text of a closed tree in screwkit's convention, and what was done (see the module docstring)."""
    import pinocchio as pin  # Pinocchio: imported where a file of another tool is read

    model = tree.model
    report = ImportReport(source=tree.source, file_format=tree.file_format, unit=tree.unit, values=tree.start_phrase())
    report.gaps_before = closure_gaps(tree, tree.q_reference)
    report.turns_before = closure_turns(tree, tree.q_reference)
    q, scale = assemble(tree, held=tree.initial_joints())
    report.gaps_after = closure_gaps(tree, q)
    tree = drawn_pairs(tree, q)  # (hinges closed by two points a few millimetres apart: along their joints)
    tree = drawn_parallelograms(tree, q, scale)  # (four-bars drawn as parallelograms and written rounded: exact)
    model = tree.model
    changes = largest_changes(model, pin.difference(model, tree.q_reference, q), tree.unit)
    report.notes.append(f"working mode: the closed configuration nearest to {tree.start_phrase()} (the largest "
                        f"joint change {changes})")
    data = model.createData()
    pin.forwardKinematics(model, data, q)
    pin.updateFramePlacements(model, data)
    frame_index = output_frame(tree)
    report.notes[:0] = tree.notes  # what reading, assembling and finding the platform said, before the rest
    frame = model.frames[frame_index]
    platform = int(frame.parentJoint)
    if platform == 0:
        raise ImportError_(f"{tree.source}: the output frame {frame.name!r} is on the fixed base.")
    body = report.platform_body = platform_body(model, frame_index)
    spine = _spine(model, data, platform)
    closures = _without_carried_loops(tree, platform, report)
    onto_platform = [platform in path_to(model, c.joint_a) or platform in path_to(model, c.joint_b)
                     for c in closures]
    couplings = [c for c, onto in zip(closures, onto_platform) if not onto]
    legs = [spine] + _platform_legs(tree, data, [c for c, onto in zip(closures, onto_platform) if onto],
                                    platform, scale, report)
    chain_joints = set(path_to(model, platform))
    if len(legs) == 1 and not any(chain_joints & set(path_to(model, end)) for closure in closures
                                  for end in (closure.joint_a, closure.joint_b)):
        # every loop closes away from the platform's chain (the joints held may have made it so)
        chain = ", ".join(tree.written_joint(model.names[j]) for j in path_to(model, platform))
        raise ImportError_(f"{tree.source}: no loop acts on the platform {body!r}: it hangs on its own chain "
                           f"({chain}) alone, a serial arm, which screwkit does not analyse"
                           + (" (with the joints --lock holds)" if tree.locked else "")
                           + "; name another --output, on a body the loops reach" + (", or hold fewer joints"
                                                                                      if tree.locked else "") + ".")
    owner: dict[int, str] = {}
    for leg in legs:
        if not leg.joints and not leg.base_dofs and leg.loop == "fixed":
            raise ImportError_(f"{tree.source}: closure {leg.closure!r} welds the platform to the fixed base: it "
                               "cannot move.")
        for joint in leg.joints:
            kind, _ = joint_kind(model, joint)
            if kind not in ("revolute", "prismatic"):
                raise LegWithLoops(f"{tree.source}: joint {model.names[joint]!r} ({kind}) inside a leg: not a "
                                   "serial chain of 1-DoF joints" + GRAPH_HINT + ".")
    for leg in legs:
        for joint in leg.joints:
            if joint in owner:
                first = f"closure {owner[joint]!r}" if owner[joint] else "the platform body's own path"
                name = model.names[joint]
                carries_all = tree.motors and all(  # a passive joint every motor rides on: a stage before the legs
                    joint in path_to(model, model.getJointId(motor)) for motor in tree.motors
                    if model.existJointName(motor))
                stage = (f"; {name!r} is actuated: if it is a serial stage before the parallel part, --lock {name} "
                         "analyses the legs on the body it turns" if name in tree.motors and carries_all else
                         "" if name in tree.motors else
                         f"; every actuator rides on {name!r}: if it is a serial stage before the parallel part, "
                         f"--lock {name} analyses the legs on the body it turns" if carries_all else "")
                raise LegWithLoops(f"{tree.source}: closure {leg.closure!r} and {first} share joint {name!r}: a "
                                   "loop inside a leg (a parallelogram of rods, a transmission), which screwkit "
                                   "cannot write as serial legs" + GRAPH_HINT + stage + ".")
            owner[joint] = leg.closure
    motor_ids, idle_motors = {}, []
    joined = {c.name for members, group in compound_groups(model, [leg.joints for leg in legs], couplings) if members
              for c in group}  # closures that reach a leg
    for name in tree.motors:
        if not model.existJointName(name):
            raise ImportError_(f"{tree.source}: {tree.motor_label(name)} is not a joint of the tree.")
        joint = model.getJointId(name)
        if joint not in owner:
            through = [c.name for c in couplings if joint in path_to(model, c.joint_a) + path_to(model, c.joint_b)]
            if name not in tree.actuated and not joined.intersection(through):
                idle_motors.append(name)  # a motor of another limb (a humanoid's other leg): no leg, no platform
                continue
            if through:
                raise LegWithLoops(f"{tree.source}: {tree.motor_label(name)} drives through closure {through[0]!r}, "
                                   "which ends on another leg's link, not on the platform (a closed-loop "
                                   "transmission): screwkit writes compound legs whose actuators lie on a path from "
                                   f"the base to the platform{GRAPH_HINT}.")
            raise ImportError_(f"{tree.source}: {tree.motor_label(name)} is on no leg (a leg is a tree path from the "
                               "base to the platform or to a closure).")
        motor_ids[joint] = name
    if idle_motors:
        report.notes.append(f"actuated joints {', '.join(idle_motors)} on branches that reach no leg: left out (they "
                            "do not move the platform)")
    check_couplings(tree, q, scale, set(owner).union(*(path_to(model, c.joint_a) + path_to(model, c.joint_b)
                                                       for c in couplings if c.name in joined)), platform, report.notes)
    turns = written_turns(tree.source)  # (axes written rounded: 1.57 for pi/2)
    normal = planar_normal(tree, data, legs, turns)
    if normal is not None:
        planar_loops(legs, normal)
    for leg in legs:
        if len(leg.base_dofs) > 1:  # a ball, not a pin: its centre's three rotations and a joint, never checked
            raise ImportError_(f"{tree.source}: closure {leg.closure!r} (3d) joins the fixed base to a body beyond the "
                               "platform: screwkit reads that leg (the pin, then the body's joint onto the platform) "
                               f"in a planar mechanism only{nearly_planar(tree, data, legs, turns)}.")
    onto = legs if legs[0].loop != "fixed" else legs[1:]  # meeting the platform at a loop joint (its own path's ball)
    centres = [leg.successor_world[:3, 3] for leg in onto]  # every closure onto the platform, compound legs' too
    # in a plane, pins about the normal drawn anywhere along their common axis meet (a coaxial wrist drawn stacked)
    meet = all(np.linalg.norm(in_plane(c - centres[0], normal)) < FILE_ROUNDING * scale for c in centres)
    equivalents = compound_legs(tree, q, scale, legs, couplings, set(motor_ids), platform, normal, report)
    for leg in legs:  # (a coupling that reaches the leg's joints makes a loop inside it, which may hold it)
        lock_idle(tree, data, leg, scale, set(motor_ids), q, [c.name for c in couplings if c.name in joined and set(
            leg.joints).intersection(path_to(model, c.joint_a) + path_to(model, c.joint_b))])
    axes, equivalents = drawn_lines(model, data, legs, equivalents, scale, report, turns, normal)
    absorbed = set()
    for closure in tree.closures:
        for joint in (closure.joint_a, closure.joint_b):
            absorbed.update(path_to(model, joint))
    report.dropped = [model.names[j] for j in range(1, model.njoints) if j not in owner and j not in absorbed]
    report.planar = normal is not None
    output_world = homogeneous(data.oMf[frame_index])
    idle = idle_about_the_meeting_point(onto, normal)
    chosen = [leg.closure for leg in legs[1:] if leg.closure in tree.cut_by_order]
    pinned = any(not leg.joints and not leg.base_dofs for leg in legs[1:])  # its loop joint alone, on the base
    # a loop closed on a link that one actuator turns alone from the base: the point there is that link's (a
    # four-bar's coupler closed at the crank's pin read ITI = OTI = 1 at every pose; closed at the rocker's, the
    # linkage's transmission)
    crank = [leg for leg in legs[1:] if not leg.base_dofs and len(leg.joints) == 1 and leg.joints[0] in motor_ids]
    meeting = tree.output_type is None and meet and idle  # (the default, where nothing below rules it out)
    point = tree.output_type == "point" or (meeting and not chosen and not pinned and not crank)
    if meeting and crank and not chosen and not pinned:
        driver = motor_ids[crank[0].joints[0]]
        report.notes.append(f"output the platform's frame, not the point where the legs meet (closure "
                            f"{crank[0].closure!r}): it is on the link actuated joint {driver!r} turns alone from the "
                            "base, whose point it reads, whatever the linkage; --output-type point takes it there")
    if meeting and chosen:  # the meeting point would follow the file's order
        report.notes.append(f"output the platform's frame: the loop closed at {chosen[0]!r} could as well be closed at "
                            "another joint (the file does not say where its legs end), which would move the point "
                            "where the chains meet; --output-type point takes the point there")
    welded = [leg.closure for leg in legs[1:] if leg.loop == "fixed"]  # (its weld's frame is no point of a leg: the
    # file puts it anywhere on the bodies it welds, and which way round it is written moves it)
    if point and (welded or not meet):
        raise ImportError_(f"{tree.source}: --output-type point needs every closure to meet the platform at one "
                           + (f"point; closure {welded[0]!r} welds a leg to it, which meets it at none (--output names "
                              "a body the welded links hang from by a pin or ball)." if welded else
                              "point; they do not."))
    if point:
        offset = float(np.linalg.norm(in_plane(output_world[:3, 3] - centres[0], normal)))  # in the plane of motion
        where = (f"at frame {frame.name!r}" if offset <= FILE_ROUNDING * scale else  # (one point, to the rounding)
                 f"{offset:.4g} {tree.unit} {'in the plane ' if normal is not None else ''}from frame {frame.name!r}")
        report.output = f"the point where the chains meet on body {body!r} (closure {legs[1].closure!r}), {where}"
    else:
        report.output = f"frame {frame.name!r} on body {body!r}"
    platform_world = np.eye(4)
    platform_world[:3, 3] = centres[0] if point else output_world[:3, 3]
    world_base = base_frame(normal, platform_world[:3, 3])
    platform_world[:3, :3] = world_base[:3, :3] if (point or normal is not None) else output_world[:3, :3]
    writer = UrdfWriter(Path(tree.source.split(" + ", 1)[0]).stem or "mechanism",  # (a Gepetto pair: its URDF)
                        f"Converted by screwkit from {tree.source} ({tree.file_format}); " + report.lines()[0])
    base = "base"
    if normal is not None:
        writer.link("world")
        writer.joint("world_to_base", "fixed", "world", base, **origin_of(world_base))
    writer.link(base)
    platform_base = inverse(world_base) @ platform_world
    if normal is not None:
        writer.link("platform")
        writer.joint("platform_joint", "planar", base, "platform", xyz=tuple(platform_base[:3, 3]), axis=(0, 0, 1))
    else:
        writer.link("platform")
        writer.joint("platform_joint", "floating", base, "platform", **origin_of(platform_base))
    reference = {}
    legs.sort(key=lambda leg: leg.joints[0] if leg.joints else 0)
    for leg in legs:
        parent, end = base, base
        synthetic = write_base_pin(writer, leg, world_base, reference)
        if synthetic:
            parent = end = f"{leg.closure}_link"
        for position, joint in enumerate(leg.joints):
            placement = homogeneous(model.jointPlacements[joint])
            if position == 0:
                placement = inverse(world_base) @ placement
            shift = leg.offsets.get(joint, np.zeros(3)) - leg.offsets.get(model.parents[joint], np.zeros(3))
            placement[:3, 3] += np.asarray(data.oMi[model.parents[joint]].rotation).T @ shift
            link = f"{model.names[joint]}_link"
            if joint in leg.locked:
                writer.link(link)
                writer.joint(model.names[joint], "fixed", parent, link, **origin_of(placement @ joint_motion(
                    model, joint, q)))
                report.locked.append(model.names[joint])
            else:
                kind, axis = joint_kind(model, joint)
                value = joint_value(model, joint, q)
                placement, axis = turned_joint(placement, kind, axis, axes.get(joint), value)
                lower, upper = held_limits(model, joint, value, kind, scale, report)
                limit = (lower, upper, 0, 0) if np.isfinite(lower) and np.isfinite(upper) and lower < upper \
                    and model.joints[joint].nq == 1 else None
                joint_type = kind
                if limit is None:  # no limits in the file: a continuous joint, a slide limited only far away
                    joint_type = "continuous" if kind == "revolute" else kind
                    limit = None if kind == "revolute" else (-UNLIMITED_SLIDE, UNLIMITED_SLIDE, 0, 0)
                writer.link(link)
                writer.joint(model.names[joint], joint_type, parent, link, axis=tuple(axis), limit=limit,
                             **origin_of(placement))
                reference[model.names[joint]] = value
            parent, end = link, link
        name = model.names[leg.joints[0]] if leg.joints else leg.closure  # a loop joint alone: named after its closure
        successor = inverse(platform_world) @ leg.successor_world
        predecessor = leg.predecessor if leg.joints else inverse(world_base) @ leg.predecessor  # in the base frame
        if leg.base_dofs:  # in the pin's frame: the base's axes at the ball's centre
            predecessor[:3, 3] -= in_base(world_base, leg.base_dofs[0][2])
        writer.loop(f"{name}_loop", leg.loop, name, end, pose_of(predecessor), "platform", pose_of(successor),
                    axis=None if leg.axis is None else tuple(leg.axis),
                    second_axis=None if leg.axis2 is None else tuple(leg.axis2))
        actuated = [model.names[j] for j in leg.joints if j in motor_ids]
        listed = synthetic + [model.names[j] for j in leg.joints]
        report.chains.append(f"{name}: " + (f"joints {', '.join(listed)}, " if listed else "no joint but its loop, ")
                             + f"loop {leg.loop}"
                             + (f" (closure {leg.closure})" if leg.closure and leg is not spine else
                                " (the platform body's own path)")
                             + (f", actuated {', '.join(actuated)}" if actuated else ""))
    for name, reduction, attachment in equivalents:
        joints = write_equivalent(writer, name, reduction, attachment, world_base, platform_world)
        reference.update(dict.fromkeys(joints, 0.0))
        report.chains.append(f"{name}: joints {', '.join(joints)}, loop fixed (the equivalent constraint chain of a "
                             "compound leg)")
    for name in motor_ids.values():
        writer.transmission(name)
    report.motors = list(motor_ids.values())
    if point:
        writer.output("point")
    if tree.task_coordinates:  # the source's own choice, checked when the written file is loaded
        writer.task_coordinates(tree.task_coordinates)
        report.notes.append(f"task coordinates as the source declares them: {' '.join(tree.task_coordinates)}")
    writer.reference_configuration(reference)
    return writer.text(), report
