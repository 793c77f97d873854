"""What a closed-loop graph's legs must be at the file's configuration for :mod:`screwkit.io.graph` to analyse
them, each refused in one line naming the leg, its joints and what to do: an actuated joint that drives its leg
from the base (not inside one of its loops, not at a dead centre of the leg), a platform no motion of which is left
to no actuator, and an actuation that is not a couple carried as forces (``docs/theory.md``, *Legs with loops
inside*)."""

from __future__ import annotations

import numpy as np

from screwkit.common.tolerances import FILE_ROUNDING, RANK_TOLERANCE, ROUNDED_COUPLE
from screwkit.io.closed_tree import ClosedTree, ImportError_, joint_kind, path_to
from screwkit.io.graph_screws import HINGES, GraphLeg, LegScrews, axis_line, common_motions, model_name
from screwkit.screw.chain_screws import ChainScrews
from screwkit.screw.constraints import chain_constraint_wrenches
from screwkit.screw.motion import chain_decompositions
from screwkit.screw.reference import actuation_wrench, working_frame

__all__ = ["check_legs", "check_output", "refuse_couples_of_forces", "couples_of_forces", "IN_LOOP_TOLERANCE",
           "COUPLE_LIKE", "length_dependent_legs", "LENGTH_DEPENDENT", "LENGTH_CHANGE", "far_force_legs", "FAR_FORCE",
           "FAR_FORCE_NOTE", "reading_cautions", "CAUTIONS", "stage_refusal"]

IN_LOOP_TOLERANCE = 1e-8
"""Distance (working coordinates, unit twist) of an actuated joint's twist from its leg's twist system above
which the joint moves inside a loop of the leg (its twist is not a motion of the leg)."""


def check_legs(tree: ClosedTree, legs, screws: list[LegScrews], nearby, platform: int,
               deferred: dict[str, str] | None = None) -> None:
    """At the file's configuration: each actuated joint's twist is a motion of its leg, and locking it takes one
    motion away (else the actuator moves inside a loop of the leg, or the file's joint values are a singular
    configuration of the leg: ``nearby()`` gives the legs' screws at closed configurations near it, or none).
    ``deferred``: by leg name, the advice that holds a leg's actuators in series
    (:func:`~screwkit.io.graph_actuators.check_actuators`), given with the reason where one of them fails."""
    for index, (leg, screw) in enumerate(zip(legs, screws)):  # one actuator each, or none (check_actuators)
        if not leg.actuators:
            continue
        try:
            _check_leg(tree, leg, index, screw, nearby, platform)
        except ImportError_ as error:
            if leg.of not in (deferred or {}):
                raise
            raise stage_refusal(tree, legs, {leg.of: deferred[leg.of]}, error, leg.name) from None


def stage_refusal(tree: ClosedTree, legs, deferred: dict[str, str], error: ImportError_, copy: str = ""
                  ) -> ImportError_:
    """The refusal of a leg of actuators in series read one at a time (``deferred``: its advice by its name, the
    first one's taken) where ``error`` (its ``reason``, else its whole message; ``copy``: the copy of the leg it
    names, left out of the reason) says why that failed: the advice that holds the stage."""
    name, advice = next(iter(deferred.items()))
    count = sum(1 for leg in legs if leg.of == name)
    reason = error.reason or str(error).removeprefix(f"{tree.source}: ").removesuffix(".")
    reason = reason.replace(f" of leg {copy!r}", "")
    return ImportError_(f"{tree.source}: leg {name!r} has loops inside it and {count} actuators, which screwkit does "
                        f"not read one at a time here ({reason}){advice}.")


def _check_leg(tree: ClosedTree, leg: GraphLeg, index: int, screw: LegScrews, nearby, platform: int) -> None:
    """:func:`check_legs` of one leg with an actuator."""
    model = tree.model
    actuator = leg.actuators[0]
    name = model.names[actuator]
    if leg.others:
        _check_independent(tree, leg, index, screw, nearby)
    carries = all(actuator in path_to(model, j) for j in leg.joints if j != actuator)
    if screw.outside[0] <= IN_LOOP_TOLERANCE and screw.locked_dims[0] == screw.allowed_dims[0] and carries:
        _refuse_a_singular_file(tree, name, leg, index, nearby)
        raise ImportError_(f"{tree.source}: locking actuated joint {name!r} leaves the platform of leg "
                           f"{leg.name!r} as free as before: the joints it carries move the platform on their own "
                           "(motors the file does not name, or a leg with no input); if it is a serial stage "
                           f"before the parallel part, --lock {name} analyses the legs on the body it turns.",
                           reason=f"locking actuated joint {name!r} leaves the platform as free as before")
    outside = screw.outside[0] > IN_LOOP_TOLERANCE or screw.locked_dims[0] != screw.allowed_dims[0] - 1
    below = [model.names[j] for j in path_to(model, actuator)[:-1]  # carrying it (not the platform's pin)
             if j in leg.joints and j != platform]
    if screw.rigid_input is not None and not screw.rigid_input[0] and not (outside and below):
        # (where joints of the leg carry it, holding them is the way out named below)
        raise ImportError_(f"{tree.source}: actuated joint {name!r} moves inside a loop of leg {leg.name!r} (with "
                           "the other joints of its path to the platform held it cannot move: a loop through that "
                           "path closes on the base and shares the load the leg carries, so the power coefficient "
                           "on its own twist is not the leg's input); analysable when the actuated joint joins the "
                           "base to the rest of its leg: the link it drives taken as the output (--output) reads "
                           "its own transmission.", reason=f"actuated joint {name!r} moves inside a loop")
    floating = [j for j in path_to(model, actuator)[:1] if j in leg.joints and j != platform
                and joint_kind(model, j)[0] == "JointModelFreeFlyer"]
    if outside and floating:  # (not a loop: the leg's own base floats, as an export's <freejoint> on its root)
        free = model.names[floating[0]]
        raise ImportError_(f"{tree.source}: actuated joint {name!r} rides on the free joint {free!r} (a floating "
                           "base, as an export writes <freejoint> on its root): --lock "
                           f"{' --lock '.join(below)} holds the base where the file puts it, and the legs are "
                           "analysed on it.", reason=f"actuated joint {name!r} rides on the free joint {free!r}")
    if outside:
        one = len(below) == 1
        hint = (f"; {', '.join(below)} carr{'ies' if one else 'y'} it within the leg: --lock "
                f"{' --lock '.join(below)} holds {'it' if one else 'them'} where the loops close" if below else
                f"; it turns a body on the platform (a wrist after the parallel part): --lock {name} holds it, "
                "and the legs are analysed on the platform" if model.parents[actuator] == platform else "")
        raise ImportError_(f"{tree.source}: actuated joint {name!r} moves inside a loop of leg {leg.name!r} (its "
                           "twist is not a motion the leg allows: the leg has no serial input); analysable when "
                           f"the actuated joint joins the base to the rest of its leg{hint}.",
                           reason=f"actuated joint {name!r} moves inside a loop")


def _check_independent(tree: ClosedTree, leg: GraphLeg, index: int, screw: LegScrews, nearby) -> None:
    """One actuator of a leg of several (:func:`~screwkit.io.graph_actuators.split_legs`): locking it alone takes a
    motion of the platform away. Then no motion inside the leg with the platform held moves it, its rate is one linear
    function of the platform twist (its actuation wrench), and any set of the leg's actuators locked leaves the
    platform the twists none of their wrenches works on, as the copies read it. Else the leg's other actuators undo
    its motion (kinematic redundancy inside the leg), refused, or the file is written at a singular configuration of
    the leg (``nearby()``)."""
    if screw.locked_dims[0] < screw.allowed_dims[0]:
        return
    _refuse_a_singular_file(tree, tree.model.names[leg.actuators[0]], leg, index, nearby)
    name = tree.written_joint(tree.model.names[leg.actuators[0]])
    others = ", ".join(sorted(tree.written_joint(tree.model.names[j]) for j in leg.others))
    raise ImportError_(f"{tree.source}: locking actuated joint {name!r} leaves the platform as free as before: a "
                       "motion inside its leg moves it with the platform held (kinematic redundancy; the leg's other "
                       f"actuated joints: {others}), so it has no actuation wrench; --lock {name} holds it.",
                       reason=f"locking actuated joint {name!r} leaves the platform as free as before")


def _refuse_a_singular_file(tree: ClosedTree, name: str, leg: GraphLeg, index: int, nearby) -> None:
    """Where locking actuated joint ``name`` leaves leg ``index``'s platform as free as before at the file's joint
    values: refused as a file written at a singular configuration of the leg if it takes a motion away at closed
    configurations near them (``nearby()``); nothing otherwise (the caller says why else)."""
    around = nearby()
    if around and np.any(around[index].locked_dims < around[index].allowed_dims):
        raise ImportError_(f"{tree.source}: locking actuated joint {name!r} leaves the platform of leg {leg.name!r} "
                           "as free as before at the file's joint values, and takes a motion away at closed "
                           "configurations near them: the file is written at a singular configuration of the leg "
                           "(its links on one line, stretched or folded); give joint values away from it: --initial "
                           "JOINT VALUE (an actuated joint away from its dead centre, held there while the loops "
                           "close), or a keyframe named 'home' (MJCF).",
                           reason=f"locking actuated joint {name!r} leaves the platform as free as before at the "
                           "file's joint values, and takes a motion away at closed configurations near them")


def check_output(tree: ClosedTree, screws: list[LegScrews], body: str, legs: list[GraphLeg],
                 deferred: dict[str, str] | None = None) -> None:
    """The platform's frame is the output of a graph: refused when a point is asked for, or when the platform still
    moves with every actuator locked (an effector turning freely on the pin where the legs meet: its frame is no
    output any actuator controls, and its indices would be zero everywhere); ``deferred``: as :func:`check_legs`'s,
    the stage named instead."""
    if tree.output_type == "point":
        raise ImportError_(f"{tree.source}: --output-type point: legs with loops inside them are analysed for the "
                           f"frame of their platform {body!r} only.")
    try:
        _check_idle(tree, screws, body, legs)
    except ImportError_ as error:
        if deferred:
            raise stage_refusal(tree, legs, deferred, error) from None
        raise


def _check_idle(tree: ClosedTree, screws: list[LegScrews], body: str, legs: list[GraphLeg]) -> None:
    """:func:`check_output`'s refusal of a platform that moves with every actuator locked."""
    idle = common_motions(screws, locked=True)
    if len(idle):
        guessed = next((note.split(":")[0].split(" (")[0].removeprefix("actuators ") for note in tree.notes
                        if note.startswith("actuators guessed")), "")
        passive = dict.fromkeys(tree.written_joint(tree.model.names[j]) for leg in legs for j in leg.joints
                                if tree.model.names[j] not in tree.motors and tree.model.joints[j].nv < 6)
        raise ImportError_(f"{tree.source}: the platform {body!r} moves with every actuator locked ({len(idle)} "
                           "motion(s) no actuator controls, e.g. an effector turning freely on the pin where the legs "
                           f"meet, a spring joint, or motors the file does not name; actuators {', '.join(tree.motors)}"
                           f"{f', {guessed}' if guessed else ''}): its frame is no output of this mechanism; --lock "
                           "holds a passive joint that moves it"
                           + (f" (the legs' passive joints: {', '.join(passive)})" if passive else "")
                           + ", --actuate names a joint that drives it.",
                           reason=f"the platform {body!r} moves with every actuator locked")


def refuse_couples_of_forces(tree: ClosedTree, legs, chains: list[ChainScrews], state) -> None:
    """An ImportError_ naming the first leg :func:`couples_of_forces` finds, its actuated joint and the joints that
    carry the couple's forces, and how to read each force path; nothing if there is none."""
    for leg, carriers in couples_of_forces(legs, chains, state)[:1]:
        names = ", ".join(repr(model_name(tree, j)) for j in carriers)
        raise ImportError_(f"{tree.source}: leg {leg.name!r}: actuated joint {model_name(tree, leg.actuators[0])!r} "
                           f"drives the platform by a pure couple, which the leg carries onto the link it turns only "
                           f"as forces through {names} (rods pulling against each other): the index of a couple is 1 "
                           "at every pose, blind to those forces' pressure angles and to the dead centre where they "
                           "line up, so screwkit does not analyse this leg as a graph; read with one force path (the "
                           "other rods' closures left out, in MJCF <weld ... active='false'/>), the leg's ITI and OTI "
                           "are that rod's pressure angles.")


COUPLE_LIKE = 1e3
"""An actuation wrench whose line passes farther than this many working lengths from the mechanism's centroid acts
as a couple: its power coefficient on any rotation is 1 to within a millionth (:func:`couples_of_forces`)."""


def couples_of_forces(legs, chains: list[ChainScrews], state) -> list[tuple[GraphLeg, tuple[int, ...]]]:
    """The actuated legs whose actuation wrench (its representative, as the index layer takes it) is a couple that
    the leg carries onto its actuated link only as forces at two or more points, and those joints: balls, hinges
    along the couple, ball closures (two rods pulling against each other, a parallelogram doubled on the far side of
    its crank). The power coefficient of a couple is 1 whatever those forces' pressure angles, even beside the dead
    centre where they line up and the leg locks; such a leg is refused (``docs/theory.md``)."""
    kinds, model = state.kinematics.kinds, state.model
    work, at, _, _ = working_frame([chain.twists for chain in chains], [chain.points for chain in chains])
    found = []
    for leg, twists, points in zip(legs, work, at):
        if not leg.actuators:
            continue
        wrench = actuation_wrench(twists, points, 0)
        force, moment = np.linalg.norm(wrench[:3]), np.linalg.norm(wrench[3:])
        if not moment or moment < COUPLE_LIKE * force:
            continue
        axis = wrench[3:] / moment  # (moments about the centroid: of a near couple, its direction)
        actuator = leg.actuators[0]
        carriers = [j for j in leg.joints if model.parents[j] == actuator]
        carriers += [other for closure in leg.closures
                     for end, other in ((closure.joint_a, closure.joint_b), (closure.joint_b, closure.joint_a))
                     if end == actuator and closure.kind == "3d"]
        welded = [closure for closure in leg.closures if actuator in (closure.joint_a, closure.joint_b)
                  and closure.kind != "3d"]
        forces_only = all(kinds[j] == "ball" or (kinds[j] in HINGES and float(np.linalg.norm(np.cross(
            axis_line(state, j)[1][0], axis))) <= 10 * FILE_ROUNDING) for j in carriers if j in leg.joints)
        if len(carriers) >= 2 and forces_only and not welded:
            found.append((leg, tuple(carriers)))
    return found



LENGTH_DEPENDENT = "working length in the ITI: "
"""The start of the note naming legs whose actuation wrench's representative changes with the working length."""


def length_dependent_legs(legs, chains: list[ChainScrews]) -> list[tuple[str, float]]:
    """The actuated legs whose actuation wrench (defined up to the leg's constraint wrenches) has a representative,
    the least-norm one in working coordinates with moments about the leg's point on the platform
    (:func:`screwkit.screw.reference.actuation_wrench`), that changes with the working length ``L``: where a
    constraint wrench of the leg neither passes through that point nor is a couple (two rods that are not
    parallel: their lines meet, and so does the constraint force). Its ITI and OTI then do too. The representative
    is compared at the working length and at a thousandth of it (the chain in units of ``L``/1000): each such leg's
    name, and the angle (deg, in working coordinates) between the two."""
    work, at, _, _ = working_frame([chain.twists for chain in chains], [chain.points for chain in chains])
    found = []
    for leg, twists, points in zip(legs, work, at):
        if not leg.actuators or len(twists) < 2:
            continue
        at_length = actuation_wrench(twists, points, 0)
        shorter = actuation_wrench(np.concatenate([twists[:, :3], twists[:, 3:] * 1e3], axis=1), points * 1e3, 0)
        near_zero = np.concatenate([shorter[:3], shorter[3:] * 1e-3])  # (moments back in units of L)
        if not np.any(at_length) or not np.any(near_zero):  # (an input singularity: none does work on it alone)
            continue
        cosine = abs(at_length @ near_zero) / (np.linalg.norm(at_length) * np.linalg.norm(near_zero))
        turn = float(np.degrees(np.arccos(min(cosine, 1.0))))
        if turn > LENGTH_CHANGE:
            found.append((leg.name, turn))
    return found


LENGTH_CHANGE = 0.05
"""How far (deg, between unit wrenches in working coordinates) the representative may turn between the working
length and a thousandth of it before :func:`length_dependent_legs` names the leg: rods a file's rounding
(:data:`~screwkit.common.tolerances.FILE_ROUNDING`, 1e-5 rad) from parallel turn it by 1e-4 to 3e-4 deg, and their ITI
by a few millionths; a published Delta's rods 1.4 deg from parallel, by 0.3 to 1.3 deg, and their ITI by up to 0.05."""


FAR_FORCE = 0.1
"""A leg's one constraint wrench whose force is at most this times its moment about the centroid, and more than
:data:`~screwkit.common.tolerances.ROUNDED_COUPLE` times (its line 10 to 1000 working lengths from the mechanism), is
named by :func:`far_force_legs`: the CTI of such a force is not settled (``docs/theory.md``, *Not settled either*)."""

FAR_FORCE_NOTE = "CTI of a far constraint force: "
"""The start of the note naming the legs :func:`far_force_legs` finds."""


def far_force_legs(legs, chains: list[ChainScrews]) -> list[tuple[str, float]]:
    """The legs holding one constraint wrench that is a force far from the mechanism (two rods nearly parallel, or
    written so to a rounding beyond the file's usual one), each with how far its line passes (working lengths): the
    CTI scores it as a force there, where the paper's rule does not tend to the couple's (a desktop rod Delta written
    to 4 decimals read 3e-2 to 6.5e-2 above its parallelograms' CTI). Legs holding several constraint wrenches are
    not examined."""
    work, _, _, _ = working_frame([chain.twists for chain in chains], [chain.points for chain in chains])
    found = []
    for leg, twists, decomposition in zip(legs, work, chain_decompositions(work)):
        values = decomposition[0]
        if int(np.sum(values > RANK_TOLERANCE * values[0])) != 5:
            continue
        wrench = chain_constraint_wrenches(twists, 1, decomposition)[0]
        ratio = float(np.linalg.norm(wrench[:3]) / max(np.linalg.norm(wrench[3:]), 1e-300))
        if ROUNDED_COUPLE < ratio <= FAR_FORCE:
            found.append((leg.name, 1.0 / ratio))
    return found


CAUTIONS = (LENGTH_DEPENDENT, FAR_FORCE_NOTE)
"""The starts of the notes :func:`reading_cautions` makes, which every command says."""


def reading_cautions(legs, chains: list[ChainScrews]) -> list[str]:
    """The notes on what the indices of these legs depend on beyond the mechanism (:func:`length_dependent_legs`,
    :func:`far_force_legs`), for every command to say."""
    notes = []
    varying = length_dependent_legs(legs, chains)
    if varying:
        turns = ", ".join(f"{name} (its representative turns {turn:.2g} deg)" for name, turn in varying)
        notes.append(f"{LENGTH_DEPENDENT}leg(s) {turns}: a constraint wrench of the leg neither passes through its "
                     "point on the platform nor is a couple (rods not parallel), so the representative of its "
                     "actuation wrench, and its ITI and OTI, change with the working length (docs/theory.md, The "
                     "representative and the working length)")
    far = far_force_legs(legs, chains)
    if far:
        lines = ", ".join(f"{name} ({distance:.3g} working lengths away)" for name, distance in far)
        notes.append(f"{FAR_FORCE_NOTE}leg(s) {lines}: the leg's constraint wrench is a force whose line passes far "
                     "from the mechanism (rods nearly parallel, or a parallelogram written rounded beyond 1e-5 of its "
                     "size), and the CTI scored at that far point does not tend to a parallelogram's couple "
                     "(docs/theory.md, Not settled either)")
    return notes
