"""Idle joints of a leg, and legs stretched or folded at the assembly (:mod:`screwkit.io.star`, step 4).

A leg whose joint twists are dependent at the assembly has an idle joint (a second pin coaxial with the closure's,
the spin of an S-S rod), which :func:`lock_idle` locks, or it is stretched or folded there (a crank and its rod on
one line: a dead centre), which :func:`check_not_stretched` refuses: the twists of an idle joint stay as dependent at
joint values near the assembly, those of a dead centre do not.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from screwkit.common.tolerances import FILE_ROUNDING
from screwkit.io.closed_tree import GRAPH_HINT, ClosedTree, ImportError_, LegWithLoops, homogeneous, joint_kind
from screwkit.model.urdf_description import initial_remedy

__all__ = ["INDEPENDENCE_TOLERANCE", "joint_twists", "independent", "lock_idle", "check_not_stretched"]

INDEPENDENCE_TOLERANCE = 1e-9
"""Smallest singular value of a leg's unit joint twists (working coordinates), relative to the
largest, for them to count as independent (as :data:`screwkit.common.tolerances.MOTION_SPACE_TOLERANCE`)."""


def joint_twists(axis_kinds: list[tuple[str, NDArray, NDArray]], centre: NDArray, scale: float,
                 unit: bool = True) -> NDArray:
    """Unit joint twists (omega, v / scale) about ``centre`` of (kind, world axis, world point) triples (``unit``
    False: not scaled to unit norm, so that a combination's coefficients are the joints' rates, rad/s and length
    scales/s)."""
    rows = []
    for kind, axis, point in axis_kinds:
        row = np.concatenate([np.zeros(3), axis]) if kind == "prismatic" else \
            np.concatenate([axis, np.cross(point - centre, axis) / scale])
        rows.append(row / np.linalg.norm(row) if unit else row)
    return np.array(rows).reshape(-1, 6)


def independent(rows: NDArray, tolerance: float = INDEPENDENCE_TOLERANCE) -> bool:
    """Whether twist rows are independent: at most six, the smallest singular value above ``tolerance`` times the
    largest."""
    if rows.shape[0] == 0:
        return True
    singular = np.linalg.svd(rows, compute_uv=False)
    return rows.shape[0] <= 6 and singular[-1] > tolerance * singular[0]


def lock_idle(tree: ClosedTree, data, leg, scale: float, motors: set[int], q: NDArray, loops: list[str] = ()
              ) -> None:
    """Lock passive joints while the leg's joint twists are dependent to the file's rounding, each time the one whose
    removal leaves the others most independent (ties: from the leg's end backwards). A hinge coaxial with the revolute
    loop that closes it to 3e-7 rad, kept, gave the leg a fourth joint in its plane and its home no closure; the first
    hinge whose removal kept the rank left an S-S rod its spin beside a ball's hinge 4e-5 rad from it. Twists that
    are dependent at the assembly only (:func:`check_not_stretched`) are refused, not locked. ``loops``: closures
    between the leg's links and elsewhere (not the platform), which may hold a motion its joints alone have: the leg
    then has a loop inside it, for :mod:`screwkit.io.graph` (an H link pinned to an excavator's arm, on the bucket's
    path)."""
    model = tree.model

    def triples(kept, at=data, carry=None):
        carry = np.eye(4) if carry is None else carry  # the loop's DoFs moved with the leg's end
        joints = [(kind, np.asarray(at.oMi[joint].rotation) @ axis, np.asarray(at.oMi[joint].translation))
                  for joint in kept for kind, axis in [joint_kind(model, joint)]]
        return joints + [(kind, carry[:3, :3] @ axis, carry[:3, :3] @ point + carry[:3, 3])
                         for kind, axis, point in leg.loop_dofs]

    def rows(kept, at=data, carry=None):
        carry = np.eye(4) if carry is None else carry
        return joint_twists(triples(kept, at, carry), carry[:3, :3] @ leg.successor_world[:3, 3] + carry[:3, 3], scale)

    kept = list(leg.joints)
    if not independent(rows(kept), FILE_ROUNDING):
        check_not_stretched(tree, leg, q, scale, lambda at, carry: rows(kept, at, carry))
        moving = _moving_self_motion(triples(kept), scale)
        passive = [model.names[joint] for k, joint in enumerate(kept) if k in moving and joint not in motors]
        which = f"the leg closed by {leg.closure!r}" if leg.closure else "the platform body's own path"
        if passive and loops:
            raise LegWithLoops(f"{tree.source}: {which} ({', '.join(model.names[joint] for joint in kept)}) has more "
                               f"motions than its ends hold, and closure(s) {', '.join(map(repr, loops))} join its "
                               "links to others: a loop inside a leg, which screwkit cannot write as serial legs"
                               + GRAPH_HINT + ".")
        if passive:
            raise ImportError_(f"{tree.source}: {which} moves with its ends held: its joints "
                               f"{', '.join(model.names[joint] for joint in kept)} make a motion of their own that "
                               f"turns joints {', '.join(passive)} about points it moves (no idle spin): a motion no "
                               "actuator drives (a spring joint, as an adaptive finger's), so the mechanism has more "
                               "motions than its actuators; --lock JOINT holds one of them, --actuate names another "
                               "actuator.")
    while not independent(current := rows(kept), FILE_ROUNDING):
        rank, best = np.linalg.matrix_rank(current, tol=FILE_ROUNDING), (0.0, None)
        for joint in reversed([j for j in kept if j not in motors]):  # the one leaving the others most independent
            trial = np.linalg.svd(rows([j for j in kept if j != joint]), compute_uv=False)
            margin = trial[rank - 1] / trial[0] if trial.size >= rank else 0.0
            if margin > FILE_ROUNDING and margin > best[0] * (1.0 + 1e-6):
                best = (margin, joint)
        if best[1] is None:
            break
        kept.remove(best[1])
        leg.locked.append(best[1])
    if not independent(rows(kept)):
        raise ImportError_(f"{tree.source}: the leg closed by {leg.closure!r} keeps dependent joints after locking "
                           "its idle passive joints (its actuated joints are dependent at the assembly).")


def _moving_self_motion(triples, scale: float) -> set[int]:
    """The items of a leg's (kind, world axis, world point) ``triples`` (base to end) that take part in a self-motion
    of the leg (joint rates that move its end by nothing) which moves its links, not an idle spin: in an idle spin
    (two coaxial pins, an S-S rod about its own line, a ball's hinges about their centre, two slides along one line)
    each link that moves turns about a line that meets its hinges' axes, or slides along its joints' axes, so the
    leg keeps its shape; a planar chain of four hinges (an adaptive finger's spring joint) moves its links otherwise.
    Empty when every self-motion is idle. A hinge's drawn point may be anywhere on its axis: only the axes count;
    points are taken about the leg's own centroid, in length scales, so the verdict is the same wherever the file
    puts the leg and in any unit."""
    tolerance = 10 * FILE_ROUNDING
    centre = np.mean([point for _, _, point in triples], axis=0)
    local = [(kind, axis, (point - centre) / scale) for kind, axis, point in triples]
    twists = joint_twists(triples, centre, scale, unit=False)
    _, singular, right = np.linalg.svd(twists.T)  # (rates in rad/s, a slide's in length scales/s)
    rank = int(np.sum(singular > FILE_ROUNDING * singular[0])) if singular.size else 0
    moving = set()
    for rates in right[rank:]:
        body = np.cumsum(rates[:, None] * twists, axis=0)  # the twist of the link after each item
        for k in range(len(local) - 1):
            if not _keeps_shape(body[k], local[k], local[k + 1], tolerance):
                moving |= {j for j, rate in enumerate(rates) if abs(rate) > tolerance * np.max(np.abs(rates))}
                break
    return moving


def _keeps_shape(twist: NDArray, joint, other, tolerance: float) -> bool:
    """Whether a link with ``twist`` (omega, the velocity of the origin; lengths in length scales) between two joints
    (kind, axis, point) stays still, turns about a line that meets its hinges' axes (a slide lets any turn of both
    its sides), or slides along every one of its joints' axes."""
    omega, velocity = twist[:3], twist[3:]
    spin = float(np.linalg.norm(omega))
    if spin <= tolerance:
        speed = float(np.linalg.norm(velocity))
        return speed <= tolerance or all(float(np.linalg.norm(np.cross(velocity / speed, axis))) <= tolerance
                                         for _, axis, _ in (joint, other))
    direction = omega / spin
    if abs(float(direction @ velocity)) / spin > tolerance:  # a screw motion, not a turn
        return False
    through = np.cross(omega, velocity) / spin**2  # a point of the turning line
    for kind, axis, point in (joint, other):
        if kind == "prismatic":
            continue
        normal = np.cross(direction, axis)
        offset = point - through
        apart = (abs(float(offset @ normal)) / float(np.linalg.norm(normal)) if np.linalg.norm(normal) > tolerance
                 else float(np.linalg.norm(np.cross(offset, axis))))  # parallel: the same line, or not
        if apart > tolerance:
            return False
    return True


def check_not_stretched(tree: ClosedTree, leg, q: NDArray, scale: float, rows, samples: int = 4) -> None:
    """Refuse a leg whose joint twists (``rows(data, carry)``: at the joint frames of ``data``, its loop's DoFs carried
    by ``carry`` with the leg's end) span less at the assembly than at each of ``samples`` joint values near it (every
    joint of the leg moved by up to 0.05 rad or 0.05 length scales, seeded): the leg is stretched or folded there, as
    a crank and its rod on one line -- a dead centre, where an idle joint (a pin coaxial with another, an S-S rod's
    spin) keeps the rank it has, with a dead centre or without. Locking a joint there would analyse another
    mechanism, and the working mode is not decided there."""
    import pinocchio as pin  # Pinocchio: imported where a file of another tool is read

    model, rng = tree.model, np.random.default_rng(0)
    end = leg.joints[-1] if leg.joints else 0
    data, moved = model.createData(), model.createData()
    pin.forwardKinematics(model, data, q)
    at = _rank(rows(data, np.eye(4)))
    for _ in range(samples):
        v = np.zeros(model.nv)
        for joint in leg.joints:
            kind = joint_kind(model, joint)[0]
            start, width = model.joints[joint].idx_v, model.joints[joint].nv
            v[start:start + width] = rng.uniform(-1.0, 1.0, width) * (0.05 * scale if kind == "prismatic" else 0.05)
        pin.forwardKinematics(model, moved, pin.integrate(model, q, v))
        carry = homogeneous(moved.oMi[end]) @ np.linalg.inv(homogeneous(data.oMi[end]))
        if _rank(rows(moved, carry)) <= at:
            return  # as dependent away from the assembly: idle joints, locked by the caller
    names = ", ".join(model.names[joint] for joint in leg.joints)
    which = f"the leg closed by {leg.closure!r}" if leg.closure else "the platform body's own path"
    raise ImportError_(f"{tree.source}: {which} (joints {names}) is stretched or folded at the assembly: its joints' "
                       "twists span less there than at joint values near it (a dead centre, such as a crank and its "
                       "rod on one line), where the platform's motion and the working mode are not decided; "
                       f"{_remedy(tree, leg)}.")


def _remedy(tree: ClosedTree, leg) -> str:
    """What to do about a leg stretched at the assembly: ``--initial``, or, when values were given and the
    assembly they start still is so, values for more of its joints (another assembly of the same joints)."""
    given = {name for name, _ in tree.initial}
    if not given:
        return initial_remedy(tree.file_format)
    others = [tree.model.names[joint] for joint in leg.joints if tree.model.names[joint] not in given]
    told = " ".join(f"--initial {name} {value:g}" for name, value in tree.initial)
    return (f"the values given ({told}) assemble it so: give values to more of its joints"
            + (f" ({', '.join(others)})" if others else "") + " to start from another assembly")


def _rank(rows: NDArray) -> int:
    """The rank of twist rows, to the file's rounding (relative to the largest singular value)."""
    singular = np.linalg.svd(rows, compute_uv=False) if rows.size else np.zeros(0)
    return int(np.sum(singular > FILE_ROUNDING * singular[0])) if singular.size else 0
