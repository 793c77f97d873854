"""SDFormat models (``.sdf``): closed loops written natively, as joints between links, read as written.

An SDFormat ``<model>`` is a graph: any link may be joined to any other, so a parallel robot is written with every
one of its joints, loops included (a five-bar's two distal links both jointed to the effector). This module reads
the model's links, joints and ``<frame>`` elements with SDFormat's pose semantics (:mod:`screwkit.io.sdformat_text`:
``relative_to``, ``expressed_in``, ``degrees``, quaternions, the model's pose in the world), then:

* **the base**: the world, when a joint's ``<parent>`` is ``world``; otherwise the canonical link (the model's
  ``canonical_link``, else its first) is fixed in the world, and the report says so;
* **the tree**: a breadth-first spanning tree of the joint graph from the base, the joints taken in file order
  (so loops close where the legs meet, farthest from the base), built as a Pinocchio model at zero joint values
  (SDFormat's reference), grown again with the platform's joints taken last when it would hang from the
  platform links where a loop closes too (the last links of a leg); revolute and continuous joints as revolute
  ones about their axis, prismatic, fixed (the link welded to its parent body), universal and revolute2 as two
  revolute joints ``<name>_axis`` (parent side) and ``<name>_axis2``, ball as three revolute joints ``<name>_x``,
  ``<name>_y``, ``<name>_z`` about its frame's axes through its centre (as ``docs/urdf-convention.md`` writes a
  spherical joint inside a leg: a leg stays a serial chain of 1-DoF joints, so a U-P-S leg carrying the platform
  converts; the three span every rotation unless the middle one turns a quarter turn from the file's configuration);
* **the loops**: every other joint closes a loop, as :mod:`screwkit.io.gazebo` closes ``<gazebo><joint>``
  elements: a ball joint one point both links keep (``3d``), a fixed one the whole frame (``6d``), a revolute or
  continuous one two points on its axis (``<name>_a``, ``<name>_b``; the conversion makes them the hinge through
  them, the first of them where the joint is); a universal one its first revolute joint in the tree and the second
  as such a hinge; a prismatic one the slide in the tree on a body welded (``6d``) to the child. Where the parent
  link is where more loops close than the child (the platform), the universal's second revolute joint and the
  prismatic slide hang from the child instead, so that every loop closes on the platform;
* **the actuated joints**: those with a ``<screwkit:actuated/>`` child (a custom element, its namespace declared on
  ``<sdf>``, e.g. ``xmlns:screwkit="https://screwkit.org/sdformat"``: SDFormat keeps such elements, Gazebo
  ignores them), and those a joint-controller ``<plugin>`` of the model drives (a plugin whose ``filename`` or
  ``name`` says joint and controller, e.g. Gazebo's ``JointPositionController``, by its ``<joint_name>``); with
  neither, guessed as for onshape-to-robot files (:func:`screwkit.io.onshape.guessed_motors`), said in the report.

Types other than these (``screw``, ``gearbox``) are refused by name.
"""

from __future__ import annotations

from collections import Counter
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from screwkit.io.closed_tree import GROUNDED, ClosedTree, Closure, ImportError_, inverse
from screwkit.io.onshape import guessed_motors
from screwkit.io.sdformat_text import (
    MODEL_FRAME,
    WORLD,
    SdfJoint,
    SdfModel,
    attached_link,
    controlled_joints,
    controllers,
    read_model,
    world_poses,
)

__all__ = ["read_sdformat", "SDFORMAT_SUFFIXES", "TYPES", "actuated_joints"]

SDFORMAT_SUFFIXES = (".sdf",)
HINGES = ("revolute", "continuous")
TWO_AXES = ("universal", "revolute2")
TYPES = (*HINGES, "prismatic", "ball", *TWO_AXES, "fixed")


def _local_name(tag: str) -> tuple[str, str]:
    """(namespace, local name) of an ElementTree tag."""
    return (tag[1:].split("}", 1)[0], tag.split("}", 1)[1]) if tag.startswith("{") else ("", tag)


def actuated_joints(sdf: SdfModel) -> list[str]:
    """Joints marked ``<screwkit:actuated/>``, then those of the model's joint-controller plugins (file order)."""
    marked = [joint.get("name", "") for joint in sdf.element.findall("joint")
              if any(_local_name(child.tag)[1] == "actuated" and "screwkit" in _local_name(child.tag)[0]
                     for child in joint)]
    return list(dict.fromkeys(marked + controlled_joints([sdf.element])))


def _spanning_tree(sdf: SdfModel, ends: dict[str, tuple[str, str]], last: str | None = None):
    """(tree joints as (joint, tree parent, tree child) in breadth-first order, loop joints, the base node, and
    (loop joint, tree joint) pairs whose roles the file's order chose among equals). ``last``: a link (the platform)
    whose joints are taken only once no other link is left to take them from (what hangs from it alone, a gripper).

    Links welded by fixed joints are one body: reached together (the fixed joints in the tree), so a chain of welded
    links does not lengthen a leg and move the loop's closing joint into it (onto a fixed joint inside the leg).
    A loop joint from a link at depth d to one at depth d + 1 could as well be in the tree, and the tree joint
    that reached the deeper link (from another link at depth d) close the loop instead: the breadth-first tree is
    tied there and the file's order decides (a parallelogram's two rods reaching its coupler)."""
    base = WORLD if any(WORLD in pair for pair in ends.values()) else sdf.canonical
    visited, queue, tree, loops, used, depth, reached_by, tied = set(), [], [], [], set(), {}, {}, []

    def step(node: str, joint: SdfJoint) -> str | None:
        """The other end of a joint not taken yet from ``node`` (None: taken, or a loop joint now)."""
        parent, child = ends[joint.name]
        if joint.name in used or node not in (parent, child):
            return None
        used.add(joint.name)
        other = child if node == parent else parent
        if other in visited:
            loops.append(joint)
            if joint.kind != "fixed" and depth[other] == depth[node] + 1:
                tied.append((joint.name, reached_by[other]))
            return None
        tree.append((joint, node, other))
        welded = joint.kind == "fixed"  # one body with ``node``: its depth and the joint that reached it
        depth[other], reached_by[other] = depth[node] + (not welded), reached_by.get(node) if welded else joint.name
        return other

    def reach(node: str) -> None:
        """A node and every link welded to it, queued."""
        stack = [node]
        visited.add(node)
        depth.setdefault(node, 0)
        while stack:
            current = stack.pop()
            queue.append(current)
            for joint in sdf.joints:
                other = step(current, joint) if joint.kind == "fixed" else None
                if other is not None:
                    visited.add(other)
                    stack.append(other)

    reach(base)
    deferred: list[str] = []
    while queue or deferred:
        node = queue.pop(0) if queue else deferred.pop(0)
        if node == last and queue:
            deferred.append(node)
            continue
        for joint in sdf.joints:
            other = step(node, joint)
            if other is not None:
                reach(other)
    loose = [link for link in sdf.links if link not in visited]
    if loose:
        fixed = "the world" if base == WORLD else f"the canonical link {base!r}"
        raise ImportError_(f"{sdf.source}: <link name='{loose[0]}'> is joined to nothing on the way to {fixed} (links "
                           f"joined to nothing fixed: {', '.join(loose)}).")
    return tree, loops, base, tied


class _TreeBuilder:
    """A Pinocchio model built joint by joint at zero joint values, each link placed at its SDFormat world pose."""

    def __init__(self, sdf: SdfModel, poses: dict[str, NDArray]):
        import pinocchio as pin  # Pinocchio: imported where a file of another tool is read

        self.pin, self.sdf, self.poses = pin, sdf, poses
        self.model = pin.Model()
        self.model.name = sdf.name
        self.joint_world = {0: np.eye(4)}  # each Pinocchio joint's frame in the world at zero joint values
        self.placed = {WORLD: (0, 0)}  # node -> (Pinocchio joint, frame): where each link is attached
        self.split: dict[str, str] = {}  # a hinge of a ball or universal joint -> that joint (ClosedTree.split)
        self.limits: dict[int, tuple[float, float]] = {}

    def hinges(self, joint: SdfJoint, names) -> None:
        """Record the hinges ``names`` a ball or universal joint is written as (:attr:`ClosedTree.split`)."""
        self.split.update({name: f"one hinge of {joint.kind} joint {joint.name!r}" for name in names})
        self.split[joint.name] = f"a {joint.kind} joint ({len(names)} DoF)"

    def _se3(self, joint: int, world: NDArray):
        matrix = inverse(self.joint_world[joint]) @ world
        return self.pin.SE3(matrix[:3, :3].copy(), matrix[:3, 3].copy())

    def axis_in_joint(self, joint: SdfJoint, number: int) -> NDArray:
        """Axis ``number`` (0: ``<axis>``, 1: ``<axis2>``) of a joint in its own frame."""
        axis = joint.axes[number]
        if not axis.expressed_in or axis.expressed_in == joint.name:
            return axis.xyz
        if axis.expressed_in not in self.poses or axis.expressed_in == WORLD:  # 'world': outside the model's scope
            raise ImportError_(f"{joint.where}: <axis><xyz expressed_in={axis.expressed_in!r}>: not a frame of the "
                               "model.")
        return self.poses[joint.name][:3, :3].T @ self.poses[axis.expressed_in][:3, :3] @ axis.xyz

    def ground(self, link: str) -> None:
        """A link fixed in the world (the canonical link, when no joint reaches the world)."""
        frame = self.model.addBodyFrame(link, 0, self._se3(0, self.poses[link]), 0)
        self.placed[link] = (0, frame)

    def add_joint(self, parent: int, name: str, kind: str, axis: NDArray, world: NDArray,
                  limits: tuple[float, float] | None = None) -> int:
        """A 1-DoF joint (revolute, prismatic) on Pinocchio joint ``parent``, its frame at ``world``."""
        pin = self.pin
        models = {"revolute": pin.JointModelRevoluteUnaligned, "prismatic": pin.JointModelPrismaticUnaligned}
        index = self.model.addJoint(parent, models[kind](np.asarray(axis, dtype=float)), self._se3(parent, world),
                                    name)
        self.joint_world[index] = world
        self.limits[index] = limits if limits is not None else (-np.inf, np.inf)
        return index

    def tree_joint(self, joint: SdfJoint, parent_node: str, child_node: str) -> None:
        """A joint of the spanning tree from ``parent_node`` to ``child_node`` (reversed if those are the SDFormat
        child and parent: the same motion about or along the opposite axis, so its value and limits are the file's)."""
        parent, parent_frame = self.placed[parent_node]
        world = self.poses[joint.name]
        if joint.kind == "fixed":
            frame = self.model.addFrame(self.pin.Frame(joint.name, parent, parent_frame, self._se3(parent, world),
                                                       self.pin.FrameType.FIXED_JOINT))
            self.placed[child_node] = (parent, self.model.addBodyFrame(
                child_node, parent, self._se3(parent, self.poses[child_node]), frame))
            return
        reverse = child_node != attached_link(self.sdf, joint.child)
        steps = [(joint.name, "prismatic" if joint.kind == "prismatic" else "revolute", self.axis_in_joint(joint, 0),
                  joint.axes[0].limits)]
        if joint.kind in TWO_AXES:
            steps = [(f"{joint.name}_axis", "revolute", self.axis_in_joint(joint, 0), joint.axes[0].limits),
                     (f"{joint.name}_axis2", "revolute", self.axis_in_joint(joint, 1), joint.axes[1].limits)]
        elif joint.kind == "ball":  # three hinges through its centre, about its frame's axes (the module docstring)
            steps = [(f"{joint.name}_{axis}", "revolute", np.eye(3)[k], None) for k, axis in enumerate("xyz")]
        if len(steps) > 1:
            self.hinges(joint, [name for name, *_ in steps])
        index = parent
        for name, kind, axis, limits in steps[::-1] if reverse else steps:
            # reversed: the parent's motion seen from the child, about (along) the opposite axis, so that each value
            # and its limits are the file's
            index = self.add_joint(index, name, kind, -axis if reverse else axis, world, limits)
            parent_frame = self.model.addJointFrame(index, parent_frame)
        self.placed[child_node] = (index, self.model.addBodyFrame(
            child_node, index, self._se3(index, self.poses[child_node]), parent_frame))

    def frames(self) -> None:
        """The model's ``<frame>`` elements, on the links they are attached to."""
        for name in self.sdf.frames:
            joint, frame = self.placed[attached_link(self.sdf, name)]
            self.model.addFrame(self.pin.Frame(name, joint, frame, self._se3(joint, self.poses[name]),
                                               self.pin.FrameType.OP_FRAME))

    def finish(self):
        """The model, with its joints' limits (none: unbounded)."""
        lower, upper = self.model.lowerPositionLimit.copy(), self.model.upperPositionLimit.copy()
        for index, (low, high) in self.limits.items():
            lower[self.model.joints[index].idx_q], upper[self.model.joints[index].idx_q] = low, high
        self.model.lowerPositionLimit, self.model.upperPositionLimit = lower, upper
        return self.model


def _loop_closures(builder: _TreeBuilder, joint: SdfJoint, ends: tuple[str, str], scale: float,
                   on_child: bool = False) -> list[Closure]:
    """The closures of a joint outside the spanning tree (the module docstring says which). ``on_child``: a
    universal or prismatic loop joint's tree part hangs from its child link, not its parent (the parent is where
    more loops close, the platform: a body hung from it would put the closure beyond the platform)."""
    world = builder.poses[joint.name]
    (parent, _), (child, _) = builder.placed[ends[0]], builder.placed[ends[1]]
    if joint.kind in TWO_AXES or joint.kind == "prismatic":
        # universal: one hinge in the tree (the first on the parent side, or the second on the child side), the
        # other a hinge closure; prismatic: the slide in the tree, on a body welded to the other link
        tree_axis = 1 if on_child and joint.kind in TWO_AXES else 0
        names = (f"{joint.name}_axis", f"{joint.name}_axis2") if joint.kind in TWO_AXES else (joint.name,)
        kind, limits = ("prismatic" if joint.kind == "prismatic" else "revolute"), joint.axes[tree_axis].limits
        axis = builder.axis_in_joint(joint, tree_axis)
        if on_child:  # the same motion seen from the child, about (along) the opposite axis: the file's value
            child = builder.add_joint(child, names[tree_axis], kind, -axis, world, limits)
        else:
            parent = builder.add_joint(parent, names[tree_axis], kind, axis, world, limits)
        if joint.kind in TWO_AXES:
            builder.hinges(joint, names)
            joint = SdfJoint(names[1 - tree_axis], "revolute", joint.parent, joint.child, joint.pose,
                             joint.relative_to, (joint.axes[1 - tree_axis],), joint.where)
            builder.poses[joint.name] = world

    def closure(name: str, at: NDArray, kind: str, axis_point: bool = False) -> Closure:
        return Closure(name, parent, inverse(builder.joint_world[parent]) @ at, child,
                       inverse(builder.joint_world[child]) @ at, kind, axis_point)

    if joint.kind in ("ball", "fixed", "prismatic"):
        return [closure(joint.name, world, "3d" if joint.kind == "ball" else "6d")]
    second = world.copy()  # a hinge: two points on its axis, made the hinge through them by the conversion
    second[:3, 3] += scale * world[:3, :3] @ builder.axis_in_joint(joint, 0)
    return [closure(f"{joint.name}_a", world, "3d"), closure(f"{joint.name}_b", second, "3d", axis_point=True)]


def _drake_closures(builder: _TreeBuilder, sdf: SdfModel, poses: dict) -> list[Closure]:
    """Drake's ball constraints (``sdf.ball_constraints``): P on link A and Q on link B kept together, each side in its
    joint's frame (a gap the drawing leaves is closed by the assembly, as every closure's)."""
    closures = []
    for number, (link_a, p_ap, link_b, p_bq, where) in enumerate(sdf.ball_constraints, start=1):
        sides = []
        for tag, link, point in (("body_A", link_a, p_ap), ("body_B", link_b, p_bq)):
            if link not in builder.placed or link == WORLD:
                raise ImportError_(f"{where}: <drake:ball_constraint_{tag}> {link!r} is no link of the model.")
            joint, _ = builder.placed[link]
            at = poses[link].copy()
            at[:3, 3] = poses[link][:3, :3] @ point + poses[link][:3, 3]
            sides.append((joint, inverse(builder.joint_world[joint]) @ at))
        (joint_a, on_a), (joint_b, on_b) = sides
        closures.append(Closure(f"ball_constraint_{number}", joint_a, on_a, joint_b, on_b, "3d"))
    return closures


def _hung_from_platform(tree_joints, loops, ends: dict[str, tuple[str, str]]) -> str | None:
    """The platform (the link where most loops close) when the tree hangs from it links where a loop closes too: the
    last links of a leg (a ball joint written as three revolute joints through two massless links), reached through
    the platform before their own leg reached them, which would close that leg's loop inside it; else None."""
    touches = Counter(end for joint in loops for end in ends[joint.name])
    if not touches:
        return None
    platform = max(touches, key=lambda link: touches[link])  # the first of the most touched, in the loops' order
    below, hung = {platform}, set()
    for _, parent, child in tree_joints:
        if parent in below:
            below.add(child)
            hung.add(child)
    return platform if any(end in hung for joint in loops for end in ends[joint.name]) else None


def _output_link(sdf: SdfModel, output: str | None) -> str | None:
    """The link of the output frame named (``--output``: a link, a frame or a joint of the model), which is the
    platform: reached last, so that each leg reaches it at its end and a loop through it is closed there, not at
    the joint the file happens to list last (the same legs, and indices, whatever the order of the joints); None
    when no output is named, or the name is none of the model's (the output's reading refuses it)."""
    if output is None or output not in sdf.poses or output == MODEL_FRAME:
        return None
    link = attached_link(sdf, output)
    return None if link == WORLD else link


def with_chosen_base(path, message: str) -> str:
    """A refusal of an SDFormat file whose model no joint ties to the world and no ``canonical_link`` names a base,
    with the link screwkit fixed (its first: SDFormat's canonical link), which decides every leg, actuator and output
    that follows (a Stewart platform whose platform link is written first is read upside down); ``message``
    unchanged for any other file, or one it cannot read."""
    if Path(path).suffix.lower() not in SDFORMAT_SUFFIXES or "canonical link" in message:
        return message
    try:
        sdf = read_model(Path(path))
        chosen = not sdf.element.get("canonical_link") and not any(WORLD in pair for pair in _ends(sdf).values())
    except (ImportError_, OSError, ValueError):
        return message
    return (f"{message} (The fixed base is the model's first <link> {sdf.canonical!r}, as no joint is to the world: "
            "a joint from the world, or <model canonical_link=...>, names another.)") if chosen else message


def _ends(sdf: SdfModel) -> dict[str, tuple[str, str]]:
    ends = {}
    for joint in sdf.joints:
        if joint.kind not in TYPES:
            raise ImportError_(f"{joint.where}: type {joint.kind!r} is not read (expected one of {', '.join(TYPES)}).")
        if joint.child == WORLD:
            raise ImportError_(f"{joint.where}: <child> is the world; write the world as the <parent>.")
        for tag, end in (("parent", joint.parent), ("child", joint.child)):
            if end != WORLD and end not in sdf.poses:
                raise ImportError_(f"{joint.where}: <{tag}> names {end!r}, not a link, joint or frame of the model.")
        pair = tuple(WORLD if end == WORLD else attached_link(sdf, end) for end in (joint.parent, joint.child))
        if pair[0] == pair[1]:
            raise ImportError_(f"{joint.where}: <parent> and <child> are on the same link {pair[0]!r}.")
        ends[joint.name] = pair
    return ends


def _one_hinge(builder, sdf, poses: dict, name: str, other: str, scale: float) -> bool:
    """Whether two joints tied to one link are one joint: drawn at one point, or revolutes on one line (a coaxial
    wrist drawn stacked along its pin)."""
    gap = poses[name][:3, 3] - poses[other][:3, 3]
    if np.linalg.norm(gap) <= 1e-9 * scale:
        return True
    joints = {joint.name: joint for joint in sdf.joints}
    if any(joints[each].kind not in ("revolute", "continuous") for each in (name, other)):
        return False
    axis, other_axis = (poses[each][:3, :3] @ builder.axis_in_joint(joints[each], 0) for each in (name, other))
    axis, other_axis = axis / np.linalg.norm(axis), other_axis / np.linalg.norm(other_axis)
    return bool(np.linalg.norm(np.cross(axis, other_axis)) <= 1e-9
                and np.linalg.norm(gap - (gap @ axis) * axis) <= 1e-9 * scale)


def _parent_frames_away(sdf: SdfModel, poses: dict, scale: float) -> list[str]:
    """A note naming the joints whose ``<parent>`` is a ``<frame>`` away from the joint, the joint's pose not given
    relative to it: SDFormat places a joint at its child frame (and its ``<pose>``); the parent frame only names the
    link the joint is on, so a file drawn as if the parent frame placed the joint reads otherwise than meant."""
    away = [f"{joint.name!r} ({joint.parent!r} is {distance:.3g} m from it)" for joint in sdf.joints
            if joint.parent in sdf.frames and joint.relative_to != joint.parent
            and (distance := float(np.linalg.norm(poses[joint.parent][:3, 3] - poses[joint.name][:3, 3])))
            > 1e-9 * scale]
    if not away:
        return []
    return [f"joint(s) {', '.join(away)}: each <parent> is a <frame> away from the joint, which SDFormat places at its "
            "child frame and <pose> (the parent frame only names the link the joint is on): read so; if the parent "
            "frame was meant to place the joint, write <pose relative_to='PARENT_FRAME'/> in the joint"]


def read_sdformat(path: Path, *, output: str | None = None, output_type: str | None = None) -> ClosedTree:
    """The closed tree of an SDFormat file's model (its loops closed by native joints; the module docstring)."""
    import pinocchio as pin  # Pinocchio: imported where a file of another tool is read

    sdf = read_model(Path(path))
    poses = world_poses(sdf)
    ends = _ends(sdf)
    tree_joints, loops, base, tied = _spanning_tree(sdf, ends)
    platform = _output_link(sdf, output) or _hung_from_platform(tree_joints, loops, ends)
    if platform is not None:  # every leg ends on the platform, whatever the order of the file's joints
        tree_joints, loops, base, tied = _spanning_tree(sdf, ends, last=platform)
    builder = _TreeBuilder(sdf, poses)
    held = [repr(joint.name) for joint in sdf.joints if joint.held]
    notes = list(sdf.renamed) + ([f"joint(s) {', '.join(held)}: limits lower = upper = 0, they cannot move (Gazebo "
                                  "holds them where the file draws them): read as fixed joints"] if held else [])
    if base != WORLD:
        builder.ground(base)
        notes.append(f"{GROUNDED} {base!r} is the fixed base (Gazebo would let the model float)")
    for joint, parent_node, child_node in tree_joints:
        builder.tree_joint(joint, parent_node, child_node)
    builder.frames()
    origins = np.array([poses[link][:3, 3] for link in sdf.links])
    scale = float(np.max(np.linalg.norm(origins - origins.mean(axis=0), axis=1), initial=0.0)) or 1.0
    notes += _parent_frames_away(sdf, poses, scale)
    touches = Counter(end for joint in loops for end in ends[joint.name])  # the platform: where most loops close
    closing = {joint.name: _loop_closures(builder, joint, ends[joint.name], scale,
                                          touches[ends[joint.name][0]] > touches[ends[joint.name][1]])
               for joint in loops}
    closures = [closure for made in closing.values() for closure in made] + _drake_closures(builder, sdf, poses)
    # where the tree joint the order put in the tree is elsewhere than the loop joint, the cut moves with the order
    # (not along the common axis of two coaxial pins: closed at either, it is the same hinge)
    cut_by_order = tuple(closure.name for name, other in tied for closure in closing[name]
                         if not _one_hinge(builder, sdf, poses, name, other, scale))
    model = builder.finish()
    stated, unactuated = actuated_joints(sdf), ""
    for name in stated:  # a marker on what cannot drive: refused unless --actuate names them (read_closed_tree)
        where = next((joint.where for joint in sdf.joints if joint.name == name), f"{sdf.source}: <plugin>")
        if not unactuated and (not model.existJointName(name) or model.joints[model.getJointId(name)].nv != 1):
            kinds = {joint.name: joint.kind for joint in sdf.joints}
            fixed = ("the world" if base == WORLD else f"the canonical link {base!r}, fixed as the base since no "
                     "joint is to the world (a joint from the world, or <model canonical_link=...>, names the base)")
            unactuated = f"{where}: joint {name!r} is marked actuated but " + (
                "is not a joint of the model" if name not in kinds else
                f"is a {kinds[name]} joint, not a 1-DoF one" if kinds[name] not in (*HINGES, "prismatic") else
                f"closes a loop of the tree grown from {fixed}")
    motors = [] if unactuated else stated or guessed_motors(model, closures, builder.split)
    if not stated:
        silent = bool(controllers([sdf.element]))  # a controller whose joints its own code names
        plugins = "its joint controller plugin names no <joint_name>" if silent else "no joint controller plugin"
        notes.append(f"actuators guessed from the branches leaving the base (no <screwkit:actuated/>, {plugins}): "
                     f"{', '.join(motors)}; --actuate JOINT says otherwise")
    every_joint = np.array([poses[joint.name][:3, 3] for joint in sdf.joints]).reshape(-1, 3)  # (the tree's choice
    # of which to leave out follows the file's order; the size does not)
    return ClosedTree(str(path), model, closures, motors, pin.neutral(model), output, output_type,
                      "SDFormat (joints closing loops)", notes, cut_by_order=cut_by_order, split=builder.split,
                      unactuated=unactuated, couplings=_mimics(sdf), joint_points=every_joint if len(every_joint) else
                      None)


def _mimics(sdf) -> tuple[tuple[str, str, float, str], ...]:
    """The ``<axis><mimic>`` couplings of an SDFormat model (1.11), by the model's joint names (a two-axis joint's
    ``<name>_axis`` and ``<name>_axis2``), for :func:`~screwkit.io.closed_tree.check_couplings`."""
    kinds = {joint.name: joint.kind for joint in sdf.joints}

    def hinge(name: str, axis: str) -> str:
        return f"{name}_{axis}" if kinds.get(name) in TWO_AXES else name

    found = []
    for joint in sdf.element.findall("joint"):
        for axis in ("axis", "axis2"):
            for mimic in joint.findall(f"{axis}/mimic"):
                name, other = joint.get("name", ""), mimic.get("joint", "")
                where = f"{sdf.source}: <joint name='{name}'><{axis}><mimic joint='{other}'>"
                try:
                    slope = float((mimic.findtext("multiplier") or "1").strip())
                except ValueError:
                    raise ImportError_(f"{where}<multiplier>: not a number.") from None
                found.append((hinge(name, axis), hinge(other, mimic.get("axis", "axis")), slope, where))
    return tuple(found)
