"""The ways through a closed-loop leg from its actuated joint to the platform, over its joints and its closures.

:func:`screwkit.io.graph_screws.drives_rigidly` holds the joints of the actuated joint's own path and asks whether
it still moves. A leg's path to the platform is its tree path, but a file's spanning tree may reach the platform by
another branch: a crank that drives a four-bar grounded on the base, whose rocker carries the rod to the platform
(a walking robot's ankle), lies on no tree path to the platform, and the rocker's hinge, which carries the crank's
load, was left free as if it were a loop beside the path. :func:`through_closures` gives the joints of every
shortest way from the actuated joint's body to the platform's, crossing closures as well as joints.
"""

from __future__ import annotations

from collections import deque

__all__ = ["through_closures", "pin_groups"]


def through_closures(model, leg, actuator: int, platform: int, idle=frozenset()) -> set[int]:
    """The joints of ``leg`` (a :class:`~screwkit.io.graph_screws.GraphLeg`) on the shortest ways from the body of
    joint ``actuator`` to the body of joint ``platform`` (Pinocchio ids: a joint's id is its body's), each step a
    joint of the leg or one of its closures, never through the base (0) nor the actuated joint itself, nor the
    closures ``idle`` (by index: load-free ones, as a dyad of two links between the crank and the platform, which
    would be the shortest way and carries nothing). Every shortest way counts, so that no order of the file picks one;
    empty when none reaches the platform."""
    steps: dict[int, list[tuple[int, int | None]]] = {}  # body: (next body, the joint between them, None: a closure)
    for joint in leg.joints:
        if joint != actuator:
            steps.setdefault(joint, []).append((model.parents[joint], joint))
            steps.setdefault(model.parents[joint], []).append((joint, joint))
    for index, closure in enumerate(leg.closures):
        if index in idle:
            continue
        steps.setdefault(closure.joint_a, []).append((closure.joint_b, None))
        steps.setdefault(closure.joint_b, []).append((closure.joint_a, None))
    ahead, back = _distances(steps, actuator), _distances(steps, platform)
    if platform not in ahead:
        return set()
    return {joint for body, distance in ahead.items() if body != 0 for other, joint in steps.get(body, [])
            if joint is not None and other in back and distance + 1 + back[other] == ahead[platform]}


def _distances(steps: dict, start: int) -> dict[int, int]:
    """Breadth-first: the number of steps from ``start`` to each body reached, not going on from the base."""
    found, queue = {start: 0}, deque([start])
    while queue:
        body = queue.popleft()
        if body == 0:
            continue
        for other, _ in steps.get(body, []):
            if other not in found:
                found[other] = found[body] + 1
                queue.append(other)
    return found


def pin_groups(closures, kind: str | None = None) -> list[tuple[int, ...]]:
    """The indices of ``closures`` (of that ``kind`` only, when given) grouped by the two bodies they join, in file
    order: one connection each (a hinge written as two points on its axis is one group of two)."""
    groups: dict[frozenset, list[int]] = {}
    for index, closure in enumerate(closures):
        if kind is None or closure.kind == kind:
            groups.setdefault(frozenset((closure.joint_a, closure.joint_b)), []).append(index)
    return [tuple(group) for group in groups.values()]
