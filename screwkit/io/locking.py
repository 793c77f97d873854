"""Locking, driving and starting joints of a closed tree: a serial stage before the parallel part held at the file's
value (``--lock``), the actuated joints named by the user instead of the file (``--actuate``), and joint values the
assembly starts from and holds instead of the file's (``--initial``: a file written at a dead centre or outside a
joint's limits)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from screwkit.common.units import LENGTH_UNITS
from screwkit.io.closed_tree import (
    GUESSED,
    ClosedTree,
    Closure,
    ImportError_,
    assemble,
    closure_rows,
    homogeneous,
    joint_kind,
    joint_value,
    path_to,
)
from screwkit.io.onshape import guessed_motors

__all__ = ["lock_joints", "actuate_joints", "set_initial", "put_joint_value", "joint_names", "drivable_joints",
           "platform_motions", "GUESSED"]


def lock_joints(tree: ClosedTree, names) -> ClosedTree:
    """The tree with the joints ``names`` locked at their values of the file's configuration (Pinocchio's reduced
    model: each locked joint's body merged into its parent's), its closures and actuators carried over.

    For a serial stage before the parallel part -- a turntable under a Stewart head, every leg passing through it
    -- the legs are then analysed on the body the stage turns. A passive joint inside a loop (a knee that a
    four-bar turns) whose value in the file leaves the loops open however the other joints move is held where
    they close with the other locked joints held, and the report says so. Actuators guessed from the branches
    leaving the base (:func:`screwkit.io.onshape.guessed_motors`) are guessed again on the locked tree."""
    import pinocchio as pin  # Pinocchio: imported where a file of another tool is read

    names = joint_names(names, "lock", tree.source)
    if not names:
        return tree
    model = tree.model
    asked, names = names, tuple(dict.fromkeys(hinge for name in names for hinge in _hinges_of(tree, name)))
    for name in names:
        if not model.existJointName(name) or model.getJointId(name) == 0:
            welded = model.existFrame(name, pin.FrameType.FIXED_JOINT)  # (a body may have its joint's name)
            raise ImportError_(f"{tree.source}: --lock {name}: "
                               + ("a fixed joint already, nothing to hold" if welded else "no joint of that name")
                               + "; joints are " + ", ".join(str(n) for n in list(model.names)[1:]) + ".")
    locked = [model.getJointId(name) for name in names]
    held, moved = _values_closing_the_loops(tree, locked)
    data = model.createData()
    pin.forwardKinematics(model, data, held)
    reduced = _reduced_model(model, locked, held)

    def carried(joint: int, placement: NDArray) -> tuple[int, NDArray]:
        while joint in locked:  # the frame rides on the body the locked joint's body is merged into
            placement = homogeneous(data.liMi[joint]) @ placement
            joint = model.parents[joint]
        return (reduced.getJointId(model.names[joint]) if joint else 0), placement

    closures = []
    for closure in tree.closures:
        joint_a, placement_a = carried(closure.joint_a, closure.placement_a)
        joint_b, placement_b = carried(closure.joint_b, closure.placement_b)
        closures.append(Closure(closure.name, joint_a, placement_a, joint_b, placement_b, closure.kind,
                                closure.axis_point))
    kept = [joint for joint in range(1, model.njoints) if joint not in locked]
    q = np.concatenate([tree.q_reference[model.joints[j].idx_q:model.joints[j].idx_q + model.joints[j].nq]
                        for j in kept]) if kept else np.zeros(0)
    given = [name for name in names if name in dict(tree.initial)]
    values = (f"values in the file ({', '.join(given)} at {'its' if len(given) == 1 else 'their'} --initial value"
              f"{'' if len(given) == 1 else 's'})" if given else "values in the file")
    notes = [f"joints {', '.join(asked)} locked at their {values} (--lock): the legs analysed on the body they turn"
             ] + moved
    motors = [motor for motor in tree.motors if motor not in names]
    guessed = [k for k, note in enumerate(tree.notes) if note.startswith(GUESSED)]
    other = [note for k, note in enumerate(tree.notes) if k not in guessed]
    if guessed and len(motors) < len(tree.motors):
        motors = guessed_motors(reduced, closures, tree.split)
        other.append(f"actuators guessed from the branches leaving the base once the locked joints are held: "
                     f"{', '.join(motors)}")
    else:
        other += [tree.notes[k] for k in guessed]
    return replace(tree, model=reduced, closures=closures, motors=motors, q_reference=q, notes=other + notes,
                   locked=tree.locked + names)


def _hinges_of(tree: ClosedTree, name: str) -> list[str]:
    """The model's joints that ``--lock name`` holds: the hinges a reader wrote for the file's ball or universal
    joint ``name``, else ``name``."""
    if tree.model.existJointName(name):
        return [name]
    return [hinge for hinge in tree.split if hinge != name and tree.written_joint(hinge) == name] or [name]


def _reduced_model(model, locked: list[int], held: NDArray):
    """Pinocchio's reduced model, frames that share a name (MuJoCo names a body after its joint, and the model has a
    body frame and a joint frame of that name) told apart while it is built: Pinocchio finds each frame's parent by
    name, and refuses a name that two frames match. Both models keep the names as written."""
    import pinocchio as pin

    seen: dict[str, int] = {}
    for frame in model.frames:
        seen[frame.name] = seen.get(frame.name, 0) + 1
    written = {}
    for index, frame in enumerate(model.frames):
        if seen[frame.name] > 1 and frame.type != pin.FrameType.JOINT:
            written[f"{frame.name}\x00{index}"] = frame.name
            frame.name = f"{frame.name}\x00{index}"
    try:
        reduced = pin.buildReducedModel(model, locked, held)
    finally:
        for frame in model.frames:
            frame.name = written.get(frame.name, frame.name)
    for frame in reduced.frames:
        frame.name = written.get(frame.name, frame.name)
    return reduced


def _values_closing_the_loops(tree: ClosedTree, locked: list[int]) -> tuple[NDArray, list[str]]:
    """The file's configuration, each locked joint at its value in the file when the loops close with every locked
    joint there (the other joints moved); else each locked passive joint inside a loop (a knee that a four-bar
    turns: a file may write it open) at the value where the loops close with the other locked joints held. With
    the notes saying which moved."""
    model, held = tree.model, np.array(tree.q_reference, dtype=float)
    quiet = replace(tree, notes=[])  # (the assembly's own notes are said when it runs again, on the locked tree)
    initial = [joint for joint in tree.initial_joints() if joint not in locked]
    try:
        assemble(quiet, held=locked + initial)
        return held, []  # the file's values close: as written
    except ImportError_ as error:
        refusal = error
    cycles = set()  # the joints of every closure's loop: its two tree paths, less what they share
    for closure in tree.closures:
        cycles |= set(path_to(model, closure.joint_a)) ^ set(path_to(model, closure.joint_b))
    motors = tree.motor_joints()
    inside = [joint for joint in locked if joint in cycles and joint not in motors]
    if not inside:
        raise ImportError_(f"{refusal} (with --lock {', --lock '.join(model.names[j] for j in locked)} held at the "
                           "file's values)") from None
    try:
        closed, _ = assemble(quiet, held=[joint for joint in locked if joint not in inside] + initial)
    except ImportError_ as error:
        raise ImportError_(f"{error} (with --lock {', --lock '.join(model.names[j] for j in locked)}: the passive "
                           f"{', '.join(model.names[j] for j in inside)} free to close the loops, the others held at "
                           "the file's values)") from None
    moved = []
    for joint in inside:
        span = slice(model.joints[joint].idx_q, model.joints[joint].idx_q + model.joints[joint].nq)
        before = joint_value(model, joint, held) if model.joints[joint].nv == 1 else None
        held[span] = closed[span]
        if before is not None and abs(joint_value(model, joint, held) - before) > 1e-9:
            moved.append(f"joint {model.names[joint]} (passive, inside a loop) locked at "
                         f"{joint_value(model, joint, held):.9g}, where the loops close (the file writes {before:.9g})")
    return held, moved


def joint_names(names, option: str, source: str) -> tuple[str, ...]:
    """``names`` (joint names, or one name as a string) as a tuple; a name given twice or not a non-empty string is
    refused naming the file ``source`` and ``--option``."""
    if isinstance(names, str):
        names = (names,)
    elif names is None:
        names = ()
    elif isinstance(names, (bytes, bytearray)) or not hasattr(names, "__iter__"):
        raise ImportError_(f"{source}: --{option}: expected joint names (strings), got {type(names).__name__} "
                           f"{names!r:.60}.")
    names = tuple(names)
    for name in names:
        if not isinstance(name, str) or not name:
            raise ImportError_(f"{source}: --{option}: expected joint names, got {name!r}.")
        if names.count(name) > 1:
            raise ImportError_(f"{source}: --{option} {name}: given twice.")
    return names


def actuate_joints(tree: ClosedTree, names) -> ClosedTree:
    """The tree with the joints ``names`` as its actuators (``--actuate``), instead of those the file marks
    (transmissions, MJCF actuators, ``<screwkit:actuated/>``, controller plugins, ``name_mot``) or that were guessed
    from the branches leaving the base; the mechanism lists its actuators in its legs' order, whatever the order
    given. Each must be a 1-DoF joint (revolute or prismatic) of the tree as read, so not one held by ``--lock``; the
    report says the actuators were given, and which the file had."""
    import pinocchio as pin

    names = joint_names(names, "actuate", tree.source)
    if not names:
        return tree
    model = tree.model
    drivable = drivable_joints(tree)
    for name in names:
        what = None
        if name in tree.locked:
            what = f"the joint is held by --lock {name}"
        elif name in tree.split:
            what = f"{tree.split[name]}, not a 1-DoF joint"
        elif not model.existJointName(name) or model.getJointId(name) == 0:
            welded = model.existFrame(name, pin.FrameType.FIXED_JOINT)  # (a body may have its joint's name)
            closing = any(closure.name in (name, f"{name}_a") for closure in tree.closures)
            what = ("a fixed joint, which cannot drive anything" if welded else "it closes a loop, which screwkit "
                    "cuts there (a joint of the tree can be driven)" if closing else "no joint of that name")
        elif model.joints[model.getJointId(name)].nv != 1:
            joint = model.joints[model.getJointId(name)]
            what = f"a joint of {joint.nv} DoF ({joint.shortname()}), not a 1-DoF joint"
        if what is not None:
            raise ImportError_(f"{tree.source}: --actuate {name}: {what}; the joints that can be driven (revolute or "
                               f"prismatic) are {drivable}.")
    had = [note for note in tree.notes if note.startswith(GUESSED)]
    notes = [note for note in tree.notes if not note.startswith(GUESSED)]
    file = (f"could not be taken ({tree.unactuated.removeprefix(tree.source + ': ')})" if tree.unactuated else
            f"{'were guessed' if had else 'are'}: {', '.join(tree.motors) or 'none'}")
    notes.append(f"actuators as given (--actuate): {', '.join(names)}; the file's {file}")
    return replace(tree, motors=list(names), notes=notes, actuated=names)


def drivable_joints(tree: ClosedTree) -> str:
    """The tree's 1-DoF joints, as the refusals of ``--actuate`` and ``--initial`` list them (not a hinge a reader
    wrote for part of a ball or universal joint)."""
    model = tree.model
    return ", ".join(str(n) for n in list(model.names)[1:]
                     if model.joints[model.getJointId(n)].nv == 1 and str(n) not in tree.split)


def put_joint_value(model, joint: int, q: NDArray, value: float) -> None:
    """``value`` (rad or m) written as 1-DoF ``joint``'s coordinates in ``q``, in place (cos and sin for an unbounded
    hinge): :func:`~screwkit.io.closed_tree.joint_value`'s inverse."""
    start, count = model.joints[joint].idx_q, model.joints[joint].nq
    q[start:start + count] = [np.cos(value), np.sin(value)] if count == 2 else [value]


def set_initial(tree: ClosedTree, values) -> ClosedTree:
    """The tree with the joints of ``values`` (pairs of a joint name and a value: degrees for a revolute joint, metres
    for a prismatic one, as ``--actuators`` takes them) at those values instead of the file's (``--initial``). The
    assembly holds them there and closes the loops with the other joints, so a file written
    at a dead centre (a crank and its rod on one line) or with a joint outside its limits is read at a configuration
    the user chooses, without editing it (:meth:`~screwkit.io.closed_tree.ClosedTree.initial_joints`); ``--lock``
    then holds such a joint at its initial value."""
    pairs = initial_values(values, tree.source)
    if not pairs:
        return tree
    model, q = tree.model, np.array(tree.q_reference, dtype=float)
    startable = drivable_joints(tree)
    said = []
    for name, value in pairs:
        joint = model.getJointId(name) if model.existJointName(name) else 0
        kind = joint_kind(model, joint)[0] if joint else ""
        what = (f"{tree.split[name]}, not a 1-DoF joint" if name in tree.split else
                "no joint of that name" if not joint else
                f"a joint of {model.joints[joint].nv} DoF ({model.joints[joint].shortname()}), not a 1-DoF joint"
                if kind not in ("revolute", "prismatic") else None)
        if what is not None:
            raise ImportError_(f"{tree.source}: --initial {name} {value:g}: {what}; the joints that can be given one "
                               f"(revolute or prismatic) are {startable}.")
        if kind == "revolute":
            put_joint_value(model, joint, q, np.radians(value))
            said.append(f"{name} {value:g} deg")
        else:
            put_joint_value(model, joint, q, value / LENGTH_UNITS[tree.unit])  # (the tree keeps the file's numbers
            said.append(f"{name} {value:g} m")  # when read as written)
    note = (f"joint values given (--initial): {', '.join(said)}, instead of the file's; the loops closed with them "
            "held there")
    return replace(tree, q_reference=q, initial=pairs, notes=[*tree.notes, note])


def initial_values(values, source: str) -> tuple[tuple[str, float], ...]:
    """``values`` (pairs of a joint name and a finite number) as a tuple of pairs; anything else, or a joint given
    twice, refused naming the file ``source`` and ``--initial``."""
    if values is None:
        return ()
    if isinstance(values, dict):
        values = tuple(values.items())
    if isinstance(values, (str, bytes, bytearray)) or not hasattr(values, "__iter__"):
        raise ImportError_(f"{source}: --initial: expected pairs of a joint name and a value, got "
                           f"{type(values).__name__} {values!r:.60}.")
    pairs = []
    for pair in values:
        try:
            name, value = pair
        except (TypeError, ValueError):
            raise ImportError_(f"{source}: --initial: expected pairs of a joint name and a value, got {pair!r:.60}.") \
                from None
        if not isinstance(name, str) or not name:
            raise ImportError_(f"{source}: --initial: expected a joint name, got {name!r:.60}.")
        try:
            number = float(value)
        except (TypeError, ValueError):
            number = float("nan")
        if isinstance(value, bool) or not np.isfinite(number):
            raise ImportError_(f"{source}: --initial {name} {value!r:.40}: expected a finite number (deg for a "
                               "revolute joint, m for a prismatic one).")
        if any(name == other for other, _ in pairs):
            raise ImportError_(f"{source}: --initial {name}: given twice.")
        pairs.append((name, number))
    return tuple(pairs)


def platform_motions(tree: ClosedTree, data, platform: int, held, scale: float) -> int:
    """How many motions the platform's joint keeps with the joints ``held`` locked and every closure kept, at the
    configuration of ``data`` (its forward kinematics computed): the rank of the platform's twist on the null space
    of the closures' velocity rows over the other velocity coordinates (an idle spin, which moves no platform, does
    not count). An advice to hold joints is checked against it before it is given."""
    import pinocchio as pin  # Pinocchio: imported where a file of another tool is read

    model = tree.model
    pin.computeJointJacobians(model, data)
    free = np.ones(model.nv, dtype=bool)
    for joint in held:
        free[model.joints[joint].idx_v:model.joints[joint].idx_v + model.joints[joint].nv] = False
    matrix = closure_rows(model, data, tree.closures, scale)[:, free]
    padded = np.vstack([matrix, np.zeros((max(0, matrix.shape[1] - len(matrix)), matrix.shape[1]))])
    _, singular, right = np.linalg.svd(padded)
    null = right[int(np.sum(singular > 1e-9 * max(float(singular[0]) if singular.size else 0.0, 1.0))):]
    twist = pin.getJointJacobian(model, data, platform, pin.LOCAL_WORLD_ALIGNED)[:, free]
    twist = np.vstack([twist[:3] / scale, twist[3:]])
    if not null.size:
        return 0
    return int(np.sum(np.linalg.svd(twist @ null.T, compute_uv=False) > 1e-9))
