"""The actuators of a closed-loop graph's legs (:mod:`screwkit.io.graph`): revolute or prismatic ones, a leg of several
analysed one actuator at a time (:func:`split_legs`), and, where one of them carries the others, the serial stage a
user can hold with ``--lock`` to analyse the legs on the body it turns; and the graph moved by its actuators
(:func:`follow_actuators`, :func:`between_samples`)."""

from __future__ import annotations

from dataclasses import replace
from itertools import combinations

import numpy as np
from numpy.typing import NDArray

from screwkit.io.closed_tree import ClosedTree, ImportError_, assemble, joint_kind, joint_value, path_to
from screwkit.io.graph_kinematics import STAGE_LENGTH
from screwkit.io.locking import put_joint_value
from screwkit.io.output import platform_body

__all__ = ["check_actuators", "split_legs", "serial_stage", "follow_actuators", "between_samples", "AGREEMENT"]


def follow_actuators(graph, q: NDArray, values: NDArray) -> NDArray[np.float64]:
    """The closed configuration of ``graph`` (a :class:`~screwkit.io.graph.GraphMechanism`) with its actuated joints
    at ``values`` (rad or m, its actuators' order), reached from the closed configuration ``q`` by continuation: the
    actuators moved together in steps of at most :data:`STAGE_LENGTH` (rad, or length scales), the closures assembled
    at each with them held, so the working and assembly modes are followed. A ValueError says at which step the
    loops cannot close (values out of reach, past a singular configuration, or redundant ones that disagree).

    Redundant actuators (more than the DOF) take values that agree only on the mechanism's motions, and values
    interpolated between two that agree do not quite: held all at each step (the assembly takes them to the file's
    rounding), or where those steps do not close, a non-redundant set of them held (each in turn, in the order of
    their names), the others following; then the closed configuration nearest to all of them at ``values`` (values
    rounded as a file or a logger writes them close the loops, held, only to that rounding), refused if an actuator
    is then farther than :data:`AGREEMENT` from its value."""
    ids = _joints(graph)
    if len(ids) <= graph.dof:
        return _steps(graph, q, values, ids)
    names = graph.tree.model.names
    failures = []
    for held in [ids] + [list(c) for c in combinations(sorted(ids, key=lambda joint: names[joint]), graph.dof)]:
        try:
            found = _steps(graph, q, values, held)
        except ValueError as error:
            failures.append(error)
            continue
        try:
            return _agreeing(graph, found, values)
        except ValueError as error:  # (said first: the steps closed, the values did not meet)
            failures.insert(0, error)
    raise failures[0]


def between_samples(graph, first: NDArray, second: NDArray, fraction: float, values: NDArray) -> NDArray[np.float64]:
    """The closed configuration of ``graph`` between two closed configurations of a path (``first``, ``second``) at
    ``fraction`` of the way, its actuators at ``values``: assembled from the configuration interpolated between the
    two (Pinocchio's ``interpolate``) with the actuators put at ``values``, held there. Redundant actuators
    interpolated between two values that agree need not quite agree, and no configuration then holds them all: each
    non-redundant set of them is held in turn, and the configuration is the one the closures assemble from those
    sets' configurations' mean (where the values agree, every set gives the same one). The same whatever the
    actuators' names or order; a ValueError where the loops do not close there."""
    import pinocchio as pin  # (a file of another tool is read with it)

    ids, model = _joints(graph), graph.tree.model
    q = _put(graph, pin.interpolate(model, first, second, float(fraction)), values)
    sets = [ids] if len(ids) <= graph.dof else [list(held) for held in combinations(ids, graph.dof)]
    found = []
    for held in sets:  # (all held, or each non-redundant set)
        try:
            found.append(assemble(replace(graph.tree, q_reference=q, notes=[]), held=held, nearest=False)[0])
        except ImportError_:
            continue
        if np.max(np.abs(_values_at(graph, found[-1]) - values) / _units(graph)) <= MET:  # (every set gives it)
            return found[-1]
    if not found:
        raise ValueError("the loops do not close there")
    mean = found[0]
    for count, other in enumerate(found[1:], start=2):
        mean = np.array(pin.interpolate(model, mean, other, 1.0 / count), dtype=float)
    try:
        return assemble(replace(graph.tree, q_reference=mean, notes=[]), nearest=False)[0]
    except ImportError_:
        raise ValueError("the loops do not close there") from None


def _joints(graph) -> list[int]:
    """The actuated joints of ``graph`` (its actuators' order)."""
    return [leg.actuators[0] for leg in graph.legs if leg.actuators]


def _values_at(graph, q: NDArray) -> NDArray[np.float64]:
    """The actuators' values (rad, m) in configuration ``q``."""
    return np.array([joint_value(graph.tree.model, joint, q) for joint in _joints(graph)])


def _put(graph, q: NDArray, values: NDArray) -> NDArray[np.float64]:
    """A copy of configuration ``q`` with the actuators at ``values``."""
    q = np.array(q, dtype=float)
    for joint, value in zip(_joints(graph), values):
        put_joint_value(graph.tree.model, joint, q, value)
    return q


def _units(graph) -> NDArray[np.float64]:
    """Each actuator's unit of motion: the length scale for a slide, 1 (rad) for a hinge."""
    return np.where(graph.actuator_slides, graph.scale, 1.0)


MET = 1e-12
"""How near (rad, or length scales) every redundant actuator must be to its value, one set held, for
:func:`between_samples` to take that configuration: the values agree."""

AGREEMENT = 1e-5
"""The largest mismatch (rad, or length scales) between redundant actuators' values and the closed configuration
nearest to them that :func:`follow_actuators` accepts, as the serial forward kinematics does
(:func:`screwkit.closure.forward`)."""


def _steps(graph, q: NDArray, values: NDArray, held: list[int]) -> NDArray[np.float64]:
    """:func:`follow_actuators` holding the actuated joints ``held`` at each step."""
    start = _values_at(graph, q)
    count = max(1, int(np.ceil(np.max(np.abs(values - start) / _units(graph)) / STAGE_LENGTH)))
    for step in range(1, count + 1):
        try:
            q, _ = assemble(replace(graph.tree, q_reference=_put(graph, q, start + step / count * (values - start)),
                                    notes=[]), held=held)
        except ImportError_:
            raise ValueError(f"the loops cannot close {step} step(s) of {count} on the way (out of reach, past a "
                             "singular configuration, or redundant actuators whose values disagree)") from None
    return q


def _agreeing(graph, q: NDArray, values: NDArray) -> NDArray[np.float64]:
    """The closed configuration nearest to ``q`` (some redundant actuators at ``values``) with them all put there,
    refused if an actuator is then farther than :data:`AGREEMENT` from its value."""
    try:  # (not held: values rounded as written close the loops only to that rounding, off the motions' rank)
        q, _ = assemble(replace(graph.tree, q_reference=_put(graph, q, values), notes=[]))
    except ImportError_:
        raise ValueError("the loops cannot close at the values given (redundant actuators whose values "
                         "disagree)") from None
    mismatch = np.abs(_values_at(graph, q) - values) / _units(graph)
    if not np.max(mismatch) <= AGREEMENT:
        raise ValueError(f"redundant actuators whose values disagree (or the ones held passed a singular "
                         f"configuration on the way): the closed configuration nearest to them misses one by "
                         f"{np.max(mismatch):.3g} (rad, or length scales)")
    return q


def check_actuators(tree: ClosedTree, legs, platform: int) -> dict[str, str]:
    """Before any screw is derived: revolute or prismatic actuators, a leg of several read one at a time where
    none rides on another joint than actuators (a floating base, a passive joint the loops turn), on the platform or
    after the body its loops end on (refused, naming the joints to hold, and every other leg's that needs one, so
    that one run names them all); ``platform``: the platform body's joint. Returns, for the legs whose actuators are
    in series (a hip's motors one after the other), the advice that holds them, given with the reason if reading
    them one at a time fails (:func:`screwkit.io.graph_checks.check_legs`)."""
    model = tree.model
    if not any(leg.actuators for leg in legs):
        on_legs = {model.names[joint] for leg in legs for joint in leg.joints}
        off = [name for name in dict.fromkeys(tree.motors) if name not in on_legs]
        raise ImportError_(f"{tree.source}: no leg has an actuator (legs {', '.join(leg.name for leg in legs)}): "
                           "--actuate names the driven joints" + (
                               f"; {', '.join(map(repr, off))} {'is' if len(off) == 1 else 'are'} on no leg (a tool "
                               "the platform carries, or a branch off the legs: left out)" if off else "") + ".")
    several, deferred = [leg for leg in legs if len(leg.actuators) > 1], {}
    for leg in several:
        advice, held, series = _leg_advice(tree, leg, platform, alone=len(legs) == 1)
        if not advice:  # (analysed one actuator at a time: split_legs)
            continue
        if series:  # (actuators in series: read one at a time, the advice given if that fails)
            deferred[leg.name] = advice
            continue
        others = [(other, _leg_advice(tree, other, platform, alone=len(legs) == 1)[1]) for other in several
                  if other is not leg]
        if others and all(locks for _, locks in others):
            every = held + [name for _, locks in others for name in locks]
            advice += (f"; legs {', '.join(repr(other.name) for other, _ in others)} likewise, all at once: --lock "
                       + " --lock ".join(dict.fromkeys(every)))
        raise ImportError_(f"{tree.source}: leg {leg.name!r} has loops inside it and {len(leg.actuators)} actuators, "
                           f"which screwkit does not read one at a time here{advice}.")
    for leg in legs:
        for actuator in leg.actuators:
            kind, _ = joint_kind(model, actuator)
            if kind not in ("revolute", "prismatic"):
                raise ImportError_(f"{tree.source}: actuated joint {model.names[actuator]!r} is {kind}: an "
                                   "actuator drives one revolute or prismatic joint.")
    return deferred


def split_legs(tree: ClosedTree, legs) -> list:
    """``legs`` with each leg of several actuators (one :func:`check_actuators` lets through) replaced by one copy
    per actuator: the same joints and closures, that actuator its own and the others in ``others``, free in the
    copy's twist systems. Its actuation wrench is then reciprocal to the platform twists the leg allows with that
    actuator alone locked, as the paper's is for a serial chain of several actuated joints (reciprocal to every other
    joint of the chain), and with some of them locked (the others failed and swinging free) the platform keeps the
    twists none of their wrenches works on, as the leg does: :func:`screwkit.io.graph_checks.check_legs` checks that
    no motion inside the leg, the platform held, moves an actuator. A copy is named after the body its
    actuated joint moves (what a leg of that actuator alone would be named, whatever order the file lists them in),
    ``of`` the leg's name; the legs in order by name."""
    model, split = tree.model, []
    bodies = tree.body_names()
    for leg in legs:
        if len(leg.actuators) < 2:
            split.append(leg)
            continue
        for actuator in leg.actuators:
            split.append(replace(leg, name=bodies.get(actuator, tree.written_joint(model.names[actuator])),
                                 actuators=(actuator,), others=tuple(o for o in leg.actuators if o != actuator),
                                 of=leg.name))
    return sorted(split, key=lambda leg: leg.name)


def _leg_advice(tree: ClosedTree, leg, platform: int, alone: bool) -> tuple[str, list[str], bool]:
    """For a leg with several actuators: what holds the serial stage that carries them (the refusal's end), the
    joints it holds (none: no advice, and the leg is analysed one actuator at a time) and whether that stage is of
    actuators alone (a hip's motors in series: the leg is read one actuator at a time all the same, the advice given
    if that fails). ``alone``: the mechanism has no other leg (a tool turned, or hanging free, after the body where
    the leg's loops end is then no output any other leg holds)."""
    model = tree.model
    riding = [tree.written_joint(model.names[a]) for a in leg.actuators
              if a != platform and platform in path_to(model, a)]
    if riding and len(riding) < len(leg.actuators):  # (a wheel on a wheel leg's end link, where its closure ends)
        one = len(riding) == 1
        return *_and_stage(tree, leg, (
            f"; actuated joint{'' if one else 's'} {', '.join(map(repr, riding))} ride{'s' if one else ''} on the "
            "platform (a wheel or a tool it carries, through which the leg's closure reaches it): --lock "
            f"{' --lock '.join(riding)} holds {'it' if one else 'them'}, or --output names the body "
            f"{'it turns' if one else 'they turn'}", riding)), False
    ends = {end for closure in leg.closures for end in (closure.joint_a, closure.joint_b)}
    tail = [a for a in leg.actuators if a in path_to(model, platform) and not any(a in path_to(model, end)
                                                                                 for end in ends)]
    if tail and alone and len(tail) < len(leg.actuators):  # (a wrist the platform carries, the output on it)
        names = [tree.written_joint(model.names[a]) for a in tail]
        meeting = next((platform_body(model, k) for k, frame in enumerate(model.frames)
                        if int(frame.parentJoint) == model.parents[min(tail)]), None)
        return *_and_stage(tree, leg, (
            f"; actuated joint{'s' if len(names) > 1 else ''} {', '.join(map(repr, names))} turn"
            f"{'' if len(names) > 1 else 's'} the output after the body where the legs' loops end"
            + (f" ({meeting!r})" if meeting else "") + ", as a tool the platform carries: --lock "
            + " --lock ".join(names) + (" hold them" if len(names) > 1 else " holds it")
            + (f", or --output {meeting} takes that body" if meeting else ""), names)), False
    hanging = [j for j in path_to(model, platform) if j in leg.joints and j not in leg.actuators
               and not any(j in path_to(model, end) for end in ends)]
    if hanging and alone and model.parents[min(hanging)] in ends:  # (a tool on a free swivel where the loops end)
        names = [tree.written_joint(model.names[j]) for j in hanging]
        meeting = next((platform_body(model, k) for k, frame in enumerate(model.frames)
                        if int(frame.parentJoint) == model.parents[min(hanging)]), None)
        return *_and_stage(tree, leg, (
            "; the output hangs off the body where the legs' loops end" + (f" ({meeting!r})" if meeting else "")
            + f" by passive joint{'s' if len(names) > 1 else ''} {', '.join(map(repr, names))}, which no actuator "
            "turns: " + (f"--output {meeting} takes that body, or " if meeting else "") + "--lock "
            + " --lock ".join(names) + (" hold them" if len(names) > 1 else " holds it"), names)), False
    advice = _stage_advice(tree, leg)
    if advice[1]:
        return *advice, all(joint in leg.actuators for joint in serial_stage(model, leg))
    return *_transmission_advice(tree, leg, platform), False


def _and_stage(tree: ClosedTree, leg, advice: tuple[str, list[str]]) -> tuple[str, list[str]]:
    """``advice`` (text, joints held) with, where a serial stage also carries the leg's actuators (the whole robot
    on a driven rail), the advice that holds it too: both are needed, and one run names them."""
    text, names = advice
    stage, held = _stage_advice(tree, leg)
    if not held or set(held) & set(names):
        return advice
    return f"{text}; and either way{stage[1:]}", names + held


def _stage_advice(tree: ClosedTree, leg) -> tuple[str, list[str]]:
    """For a leg with several actuators: the serial stage that carries them (a rail, a floating base, a hip's motors
    one after the other), the advice that holds it and its joints; none: ("", [])."""
    model = tree.model
    stage = serial_stage(model, leg)
    if len(stage) > 1 and joint_kind(model, stage[0])[0] != "JointModelFreeFlyer":
        names = list(dict.fromkeys(tree.written_joint(model.names[j]) for j in stage))  # a ball: by its name
        given = [name for name in names if name in tree.actuated]
        return (f"; joints {', '.join(names)} carry every actuator of it in turn (a serial stage before the "
                f"parallel part): --lock {' --lock '.join(names)} analyses the legs on the body they turn"
                + (f" (leave {', '.join(given)} out of --actuate)" if given else "")), names
    if stage:
        name = tree.written_joint(model.names[stage[0]])
        if joint_kind(model, stage[0])[0] == "JointModelFreeFlyer":  # (unnamed in an MJCF file: Pinocchio's)
            return (f"; every actuator rides on the free joint {name!r} (a floating base: a humanoid's pelvis): "
                    f"--lock {name} holds the base where the file puts it, and the legs are analysed on it"), [name]
        carrier = (f"the actuated joint {name!r} carries every other one" if stage[0] in leg.actuators
                   else f"joint {name!r} carries every actuator of it")
        return (f"; {carrier} (a serial stage before the parallel part): --lock {name} analyses the legs on the body "
                "it turns" + (f" (leave {name} out of --actuate)" if name in tree.actuated else "")), [name]
    return "", []


def _transmission_advice(tree: ClosedTree, leg, platform: int) -> tuple[str, list[str]]:
    """For a leg whose actuators no one joint carries: an actuator that drives, through a loop of the leg, a passive
    joint carrying every other actuator (a knee motor turning the shin, and the ankle's motors, through a four-bar),
    with the options that hold both; or nothing. Only where a loop of the leg still reaches the platform from
    beyond that joint: else the other actuators would be left driving the platform in series (a foot motor on an
    ankle that a crank and rod turn: that loop ends on the ankle, not on the foot)."""
    model = tree.model
    for actuator in leg.actuators:
        others = [other for other in leg.actuators if other != actuator]
        carriers = [joint for joint in sorted(leg.joints) if joint not in leg.actuators
                    and joint not in path_to(model, actuator) and all(joint in path_to(model, o) for o in others)
                    and any(platform in path_to(model, end) and joint in path_to(model, other_end)
                            for closure in leg.closures
                            for end, other_end in ((closure.joint_a, closure.joint_b),
                                                   (closure.joint_b, closure.joint_a)))]
        if carriers:
            name, carrier = (tree.written_joint(model.names[j]) for j in (actuator, carriers[0]))
            rest = ", ".join(tree.written_joint(model.names[o]) for o in others)
            return (f"; actuated joint {name!r} drives joint {carrier!r} through a loop, and {carrier!r} carries every "
                    f"other actuator of it ({rest}): --lock {name} --lock {carrier} analyses the legs on the body "
                    f"{carrier!r} turns"), [name, carrier]
    return "", []


def serial_stage(model, leg) -> list[int]:
    """The joints of ``leg`` that carry every actuator still driven, from the base: each actuated one found is held
    and the next sought among the rest, until one actuator is left (a floating base's slides and ball, a hip's motors
    one after the other, then the passive knee joints the ankle's motors ride on)."""
    remaining, stage = set(leg.actuators), []
    for joint in sorted(leg.joints):  # a joint's id is below those of the joints it carries
        others = [actuator for actuator in remaining if actuator != joint]
        if not others:
            break
        if all(joint in path_to(model, actuator) for actuator in others):
            stage.append(joint)
            remaining.discard(joint)
    return stage
