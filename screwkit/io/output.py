"""Which frame of a closed tree is the output: the one named, else one called as outputs are, else where the legs meet.

A file of another tool seldom says which body is the platform. :func:`output_frame` takes the frame given (``--output
FRAME``), else the first frame called one of :data:`OUTPUT_NAMES` (or, when that frame hangs by joints of its own off
the body where the most closures meet, that body: a Delta's turning tool), else the body where the most closures meet
(where every leg ends; failing one, where the most closures meet through balls written as three hinges each: a
Delta's rods on the platform), else a frame called so with a ROS ending (``ee_link``, ``tool0``), else the body that
the one ball or pin closure of a two-legged mechanism closes onto (a five-bar's pen: the point where its legs meet is
then its output; a weld onto a closure dummy that hangs by one pin is that pin's closure), else, of the bodies tied
for the most closures, the one on which every actuated leg ends. The notes say which was inferred.
"""

from __future__ import annotations

import numpy as np

from screwkit.common.tolerances import FILE_ROUNDING
from screwkit.io.closed_tree import ClosedTree, ImportError_, ball_of_revolutes, homogeneous, joint_kind, path_to

__all__ = ["output_frame", "platform_body", "OUTPUT_NAMES", "OUTPUT_SUFFIXES"]

OUTPUT_NAMES = ("effector", "end_effector", "eff", "ee", "tool", "tcp", "foot", "platform")
"""Frame names taken as the output when none is given, in this order (however written: ``endEffector``,
``End-Effector``, ``EE``)."""
OUTPUT_SUFFIXES = ("_link", "_frame", "0")
"""Endings of the :data:`OUTPUT_NAMES` also taken, after the body where most closures meet (``ee_link``, ``tool0``)."""


def _spelled(name: str) -> str:
    """A frame's name as :data:`OUTPUT_NAMES` are compared: lower case, without ``_`` or ``-`` (``endEffector``,
    ``end_effector`` and ``End-Effector`` alike)."""
    return name.lower().replace("_", "").replace("-", "")


def output_frame(tree: ClosedTree) -> int:
    model = tree.model
    names = [frame.name for frame in model.frames]
    if tree.output is not None:
        if tree.output not in names:
            raise ImportError_(f"{tree.source}: no frame named {tree.output!r} for the output; frames are "
                               + ", ".join(names[1:]) + ".")
        return names.index(tree.output)
    lowered = [_spelled(name) for name in names]
    counts, ranked, meeting = _meeting(tree, {})
    for candidate in map(_spelled, OUTPUT_NAMES):
        if candidate in lowered:
            index = lowered.index(candidate)
            after = _joints_after(model, meeting, int(model.frames[index].parentJoint)) if meeting else []
            platform = _body_frame(model, meeting) if after and not set(after) & set(counts) else None
            if platform is None:
                return index
            # a tool on a joint of its own after the body where the legs meet (a Delta's turning end effector): the
            # platform is that body, the joints after it are no part of the parallel mechanism
            tree.notes.append(f"platform inferred: body {names[platform]!r}, where {ranked[0][1]} closures meet; frame "
                              f"{names[index]!r} hangs off it by joint(s) {', '.join(model.names[j] for j in after)}, "
                              "after the parallel part (name another output with --output FRAME)")
            return platform
    if meeting is None:  # closures that each end on a ball written as three hinges: where the balls are
        counts, ranked, meeting = _meeting(tree, _ball_carriers(tree))
    if meeting is not None:  # no frame named as an output: the body where the most closures meet
        index = _body_frame(model, meeting)
        if index is not None:
            tree.notes.append(f"platform inferred: body {names[index]!r}, where {ranked[0][1]} closures meet "
                              "(name another with --output FRAME)")
            return index
    for candidate in (_spelled(name + suffix) for suffix in OUTPUT_SUFFIXES for name in OUTPUT_NAMES):
        if candidate in lowered:  # a tool frame named as ROS packages name theirs: ee_link, tool0
            tree.notes.append(f"output frame inferred: {names[lowered.index(candidate)]!r} (name another with "
                              "--output FRAME)")
            return lowered.index(candidate)
    found = _pin_between_legs(tree) if tree.output_type != "frame" else None
    if found is not None:
        # two legs meeting at one ball or pin the file places: its point is the output, the same on either body
        # (their frames are not, nor the point of a loop cut where the file's order puts the cut)
        closure, joint, hinge = found
        index = _body_frame(model, joint)
        if index is not None:
            tree.notes.append(f"platform inferred: body {names[index]!r}, where closure {closure.name!r} joins the "
                              + (f"legs through joint {model.names[hinge]!r} (the welded link hangs by it alone)"
                                 if hinge else "legs") + " (name another with --output FRAME)")
            return index
    every = _where_every_leg_ends(tree)
    index = None if every is None else _body_frame(model, every)
    if index is not None:
        tree.notes.append(f"platform inferred: body {names[index]!r}, where every actuated leg ends (name another with "
                          "--output FRAME)")
        return index
    joined = [names[i] for i in dict.fromkeys(_body_frame(model, joint) for joint, _ in ranked) if i is not None]
    said = f" (the closures join bodies {', '.join(map(repr, joined[:6]))}{', ...' if len(joined) > 6 else ''})"
    raise ImportError_(f"{tree.source}: which body is the platform? Name its output frame (--output FRAME); "
                       f"no frame is called {', '.join(OUTPUT_NAMES)}, and no one body is where most closures meet"
                       + (said if joined else "") + ".")


def _where_every_leg_ends(tree: ClosedTree) -> int | None:
    """Of the bodies tied for the most closures, the joint of the one on which every actuated leg ends, if one: the
    base's branches that carry the motors, each reaching the body by its own path or by a closure from one of its
    links (a Delta whose platform hangs on one leg by a pin, the other legs' connectors pinned to it: each of those
    has as many closures, one from its own leg's parallelogram, and two legs end on it)."""
    model = tree.model
    counts, _, _ = _meeting(tree, {})
    legs = {path_to(model, joint)[0] for joint in tree.motor_joints()}
    if not counts or len(legs) < 2:
        return None
    most = max(counts.values())

    def reaching(joint: int) -> set[int]:
        ends = [other for closure in tree.closures for mine, other in ((closure.joint_a, closure.joint_b),
                                                                        (closure.joint_b, closure.joint_a))
                if mine == joint and other]
        return {path_to(model, end)[0] for end in [joint, *ends]}

    found = [joint for joint, count in counts.items() if count == most and legs <= reaching(joint)]
    return found[0] if len(found) == 1 else None


def _pin_between_legs(tree: ClosedTree):
    """The one ball or pin where the two legs of a mechanism meet, if its closures make that alone: (the closure, the
    joint of the body taken as the platform, the joint that is the pin when the closure is a weld, else 0); else None.

    * One "3d" closure, a ball (with second points on its axis, a pin): the platform is the body more joints from
      the base, whichever end the file writes first (a servo's horn pinned to a thigh that a hip, a knee and an ankle
      carry: the thigh), the second end on a tie (a five-bar's two distal links, whose point reads the same).
    * One weld onto a link that hangs by one revolute or ball joint alone, carrying nothing else, not driven, from a
      body two joints or more from the base (a CAD export's closure dummy, welded by Gazebo's DetachableJoint onto
      the other leg's last link): that link is one body with the one it is welded to, wherever the weld is, so that
      joint is the pin between the legs, and the platform the body it hangs from, on which the pin's point is the
      output as on a pinned closure (on the welded body the output would be that body's frame). A weld between two
      links, neither such, is refused: which body is the platform is for the user to say (a five-bar's two distal
      links welded make a four-bar, whose links both hang from a crank)."""
    model = tree.model
    main = [closure for closure in tree.closures if not closure.axis_point]
    if len(main) != 1 or any(closure.name in tree.cut_by_order for closure in tree.closures):
        return None
    closure = main[0]
    ends = {closure.joint_a, closure.joint_b}
    if 0 in ends or any({other.joint_a, other.joint_b} != ends for other in tree.closures):
        return None
    if closure.kind == "3d":
        if len(tree.closures) > 1 and not _about_the_hinge(tree):
            return None  # (a hinge out of the plane of motion: its drawn point is not where the legs meet)
        return closure, max((closure.joint_b, closure.joint_a), key=lambda joint: len(path_to(model, joint))), 0
    if closure.kind != "6d":
        return None
    motors = tree.motor_joints()
    hanging = [joint for joint in ends if joint not in motors and int(model.parents[joint]) not in ends
               and len(path_to(model, joint)) >= 3 and joint_kind(model, joint)[0] in ("revolute", "spherical")
               and not any(int(model.parents[k]) == joint for k in range(1, model.njoints))]
    if len(hanging) != 1:
        return None
    return closure, int(model.parents[hanging[0]]), hanging[0]


def _about_the_hinge(tree: ClosedTree) -> bool:
    """Whether a mechanism whose closures are one hinge (points on its axis) moves in the plane normal to it: every
    hinge of the file parallel to it and every slide across it (then the hinge's point in that plane is where the
    legs meet, wherever the file draws it along the axis)."""
    import pinocchio as pin  # Pinocchio: imported where a file of another tool is read

    model = tree.model
    data = model.createData()
    pin.forwardKinematics(model, data, tree.q_reference)
    body = tree.closures[0].joint_a  # (both points on one body: the file's joint values may leave the hinge open)
    first, second = ((homogeneous(data.oMi[body]) @ (c.placement_a if c.joint_a == body else c.placement_b))[:3, 3]
                     for c in tree.closures[:2])
    normal = (second - first) / max(float(np.linalg.norm(second - first)), 1e-300)
    for joint in range(1, model.njoints):
        kind, axis = joint_kind(model, joint)
        if kind not in ("revolute", "prismatic"):
            return False
        axis = np.asarray(data.oMi[joint].rotation) @ axis / np.linalg.norm(axis)
        if (kind == "revolute" and np.linalg.norm(np.cross(axis, normal)) > FILE_ROUNDING) or \
                (kind == "prismatic" and abs(float(axis @ normal)) > FILE_ROUNDING):
            return False
    return True


def _meeting(tree: ClosedTree, carriers: dict[int, int]):
    """How many closures end on each joint's body (an end on a joint of ``carriers`` counted on its carrier's), the
    joints ranked by it (ties by their bodies' names, so that a refusal lists them alike whatever order the file lists
    its closures in), and the joint of the one body where the most closures meet (where every leg ends), if one."""
    counts: dict[int, int] = {}
    for closure in tree.closures:
        for joint in {carriers.get(closure.joint_a, closure.joint_a), carriers.get(closure.joint_b, closure.joint_b)} \
                - {0}:
            counts[joint] = counts.get(joint, 0) + 1
    ranked = sorted(counts.items(), key=lambda item: (-item[1], _body_name(tree.model, item[0])))
    meeting = ranked[0][0] if ranked and ranked[0][1] >= 2 and (len(ranked) == 1 or ranked[1][1] < ranked[0][1]) \
        else None
    return counts, ranked, meeting


def _body_name(model, joint: int) -> str:
    """The name of the body ``joint`` carries (the joint's own where it has no body frame)."""
    index = _body_frame(model, joint)
    return model.names[joint] if index is None else model.frames[index].name


def _ball_carriers(tree: ClosedTree) -> dict[int, int]:
    """For each closure's end on the last of three revolute joints in a row that make a ball (their axes through one
    point at the file's joint values: :func:`~screwkit.io.closed_tree.ball_of_revolutes`; the two links between them
    carrying nothing but the next hinge, none of them driven), the joint of the body that carries the ball: the
    closure ends on that body through the ball (a Delta's rods, each on a ball written as three hinges on the
    platform, meet there, not on three bodies). Used only where no body has two closures and no frame is named as
    an output (:data:`OUTPUT_NAMES`): in a spherical mechanism every three hinges' axes meet."""
    import pinocchio as pin  # Pinocchio: imported where a file of another tool is read

    model = tree.model
    data = model.createData()
    pin.forwardKinematics(model, data, tree.q_reference)
    scale = max(max(float(np.linalg.norm(placement.translation)) for placement in data.oMi), 1e-9)
    ends = [end for closure in tree.closures for end in (closure.joint_a, closure.joint_b)]
    children = [[k for k in range(1, model.njoints) if model.parents[k] == joint] for joint in range(model.njoints)]
    motors = tree.motor_joints()
    carriers = {}
    for joint in set(ends) - {0}:
        path = [joint, int(model.parents[joint]), int(model.parents[int(model.parents[joint])])][::-1]
        if 0 in path or motors & set(path) or any(children[j] != [k] or j in ends for j, k in zip(path, path[1:])):
            continue  # a ball's two inner links carry its next hinge alone, and no motor drives a ball
        first = homogeneous(data.oMi[int(model.parents[path[0]])]) @ homogeneous(model.jointPlacements[path[0]])
        if ball_of_revolutes(model, path, [joint_kind(model, j) for j in path], first, scale) is not None:
            carriers[joint] = int(model.parents[path[0]])
    return carriers


def _joints_after(model, ancestor: int, joint: int) -> list[int]:
    """The moving joints from ``ancestor`` (excluded) down to ``joint`` (included) in the tree, root side first; empty
    when ``joint`` is ``ancestor`` or not below it."""
    path = []
    while joint and joint != ancestor:
        path.append(joint)
        joint = int(model.parents[joint])
    return path[::-1] if joint == ancestor and joint else []


HUB_WELDS = 3
"""Welds a body of a welded group needs to be taken for the platform the others are welded around (a Codian Delta's
platform with its six ball brackets); fewer (a flange, an adapter, a plate welded in a row), the body the tree reaches
first is the platform, as the file nests them."""


def _body_frame(model, joint: int) -> int | None:
    """The index of the body frame moved by ``joint``, if it has one: of several (links welded into one body), the
    one the most others are welded to when it holds at least :data:`HUB_WELDS` welds (a Delta's platform, its
    ball-joint brackets welded around it, rather than the bracket the tree happened to reach first), else the first."""
    bodies = [index for index, frame in enumerate(model.frames)
              if frame.parentJoint == joint and str(frame.type) == "BODY"]
    if not bodies:
        return None
    welds = {index: sum(str(frame.type) == "FIXED_JOINT" for frame in model.frames if frame.parentFrame == index)
             + (str(model.frames[model.frames[index].parentFrame].type) == "FIXED_JOINT") for index in bodies}
    hub = max(bodies, key=welds.__getitem__)
    return hub if welds[hub] >= HUB_WELDS else bodies[0]


def platform_body(model, frame: int) -> str:
    """The name of the body that output frame ``frame`` is on: of the links its joint moves (welded together), the one
    :func:`_body_frame` takes; the joint's name if none."""
    joint = int(model.frames[frame].parentJoint)
    index = _body_frame(model, joint)
    return model.names[joint] if index is None else model.frames[index].name
