"""Couplings of joints in files of other tools (MJCF ``<equality><joint>``, URDF ``<mimic>``, SDFormat
``<axis><mimic>``): joint1 moves ``slope`` times as joint2, or is held.

screwkit does not model a coupling. One that only ties the mechanism analysed to a branch that reaches no leg and
follows it (a gripper's two fingers coupled by their drivers, one finger analysed) constrains nothing analysed and
is left out, said in the report; any other is refused naming it. Which is which is decided at the assembled
configuration, to first order: the couplings' rows (``dq1 - slope dq2``; ``dq1`` for a joint held, or a partner
merged away by ``--lock``) are added to the closures' Jacobian, and the coupling is left out only if the motions
the analysed joints can make stay the same (the rank of the null space's rows of their velocity coordinates). So
a partner that cannot follow (a branch the loops make rigid, a joint held, a chain of couplings back into the
mechanism) or a zero slope is refused, as MuJoCo's constraint Jacobian has the analysed joint locked there.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from screwkit.common.xml_text import tolerant_xml
from screwkit.io.closed_tree import ClosedTree, ImportError_, closure_rows, path_to

__all__ = ["check_couplings", "mimicked_joints", "RANK_TOLERANCE"]

RANK_TOLERANCE = 1e-9
"""Singular values below this times the largest count as zero in the closures' Jacobian (lengths in the
mechanism's length scale, angles in radians)."""


def mimicked_joints(urdf_text: bytes, source: str) -> tuple[tuple[str, str, float, str], ...]:
    """A URDF's ``<mimic>`` couplings (Pinocchio's reader takes the joints as independent): ``(joint, the joint it
    mimics, multiplier, where)`` for :attr:`~screwkit.io.closed_tree.ClosedTree.couplings`."""
    import xml.etree.ElementTree as ElementTree

    try:
        root = ElementTree.fromstring(tolerant_xml(urdf_text))
    except ElementTree.ParseError:
        return ()
    found = []
    for joint in root.findall("joint"):
        for mimic in joint.findall("mimic"):
            try:
                slope = float(mimic.get("multiplier", "1"))
            except ValueError:
                raise ImportError_(f"{source}: <joint name='{joint.get('name')}'><mimic multiplier="
                                   f"{mimic.get('multiplier')!r}>: not a number.") from None
            found.append((joint.get("name", ""), mimic.get("joint", ""), slope,
                          f"{source}: <joint name='{joint.get('name')}'><mimic joint='{mimic.get('joint')}'>"))
    return tuple(found)


def check_couplings(tree: ClosedTree, q: NDArray, scale: float, analysed: set[int], platform: int,
                    notes: list[str]) -> None:
    """Refuse a coupling of ``tree`` that constrains the joints ``analysed`` (ids; with the joints between the
    ``platform`` body and each closure through it, the loop joints) at the closed configuration ``q`` (length
    ``scale``), or leave it out saying so in ``notes`` (the module's docstring)."""
    if not tree.couplings:
        return
    model = tree.model
    for closure in tree.closures:
        for joint in (closure.joint_a, closure.joint_b):
            path = path_to(model, joint)
            if platform in path:
                analysed = analysed | set(path[path.index(platform) + 1:])
    couplings, idle = _holding_an_idle_body(tree, platform)
    for _, second, _, where in idle:
        held = "its other joint held (--lock or the file), it" if second else "a joint held at a value, it"
        notes.append(f"{where.split(': ', 1)[-1]}: {held} holds only a body nothing else hangs on (a gear of a stage "
                     "held): left out")
    if not couplings:
        return
    columns = [model.joints[j].idx_v + k for j in sorted(analysed) for k in range(model.joints[j].nv)]
    closures = _closure_rows(tree, q, scale)
    rows = [_coupling_row(model, coupling) for coupling in couplings]
    free = _free_rank(closures, columns)
    together = _free_rank(np.vstack([closures, *rows]), columns)
    if together == free:
        for first, second, _, where in couplings:
            element = where.split(": ", 1)[-1]
            notes.append(f"{element}: ties joint {first!r}" + (f" to {second!r}" if second else "") + ", which "
                         "constrains no motion of the mechanism analysed (the branch it ties follows): left out")
        return
    alone = [k for k, row in enumerate(rows) if _free_rank(np.vstack([closures, row]), columns) < free]
    first, second, _, where = couplings[alone[0] if alone else 0]
    named = "" if alone else " (with the file's other couplings)"
    partner = ("to a value" if not second else f"to joint {second!r}" +
               (", held (--lock)" if second in tree.locked else "" if model.existJointName(second) else
                ", not a joint that moves in the model"))
    stages = [name for name in (first, second) if name and model.existJointName(name)  # carrying every leg
              and all(model.getJointId(name) in path_to(model, end) for end in _ends(tree, platform))]
    hold = (f"--lock {stages[0]} holds the geared stage where the file draws it, or " if stages else "")
    raise ImportError_(f"{where}: a joint coupling ties joint {first!r} {partner}{named}, which holds the mechanism "
                       f"analysed to fewer motions: screwkit does not model it; {hold}remove the element"
                       + (" (or set active='false')" if "<equality>" in where else "")
                       + " to analyse the joints as independent (a joint it drives then passive).")


def _holding_an_idle_body(tree: ClosedTree, platform: int) -> tuple[list, list]:
    """The couplings of ``tree`` split into those to check and those that, their other joint held (merged away by
    ``--lock``, or no joint of the model), hold only a joint whose body, and all that hangs on it, is no end of a
    closure nor the platform: a gear of a stage held, whose own spin is all the coupling stops (before, ToddlerBot's
    hip-yaw gear pair, its driven joint held, was blamed for a waist left free)."""
    model, ends = tree.model, _ends(tree, platform)
    checked, idle = [], []
    for coupling in tree.couplings:
        moving = [model.getJointId(name) for name in coupling[:2] if name and model.existJointName(name)]
        alone = len(moving) == 1 and not any(moving[0] in path_to(model, end) for end in ends)
        (idle if alone else checked).append(coupling)
    return checked, idle


def _ends(tree: ClosedTree, platform: int) -> set[int]:
    """The platform and the joints every closure ends on: what a leg reaches."""
    return {platform} | {joint for closure in tree.closures for joint in (closure.joint_a, closure.joint_b)}


def _coupling_row(model, coupling) -> NDArray[np.float64]:
    """A coupling's row on the velocity coordinates: ``dq1 - slope dq2`` (a term for each joint the model has)."""
    first, second, slope, _ = coupling
    row = np.zeros((1, model.nv))
    for name, factor in ((first, 1.0), (second, -slope)):
        if name and model.existJointName(name):
            joint = model.joints[model.getJointId(name)]
            row[0, joint.idx_v:joint.idx_v + joint.nv] = factor
    return row


def _free_rank(rows: NDArray, columns: list[int]) -> int:
    """The rank of the motions of the velocity coordinates ``columns`` that keep ``rows`` zero."""
    _, values, right = np.linalg.svd(np.vstack([rows, np.zeros((max(rows.shape[1] - len(rows), 0), rows.shape[1]))]))
    rank = int(np.sum(values > RANK_TOLERANCE * max(values[0], 1.0)))
    null = right[rank:][:, columns]
    if not null.size:
        return 0
    found = np.linalg.svd(null, compute_uv=False)
    return int(np.sum(found > RANK_TOLERANCE))


def _closure_rows(tree: ClosedTree, q: NDArray, scale: float) -> NDArray[np.float64]:
    """The closures' Jacobian at ``q`` on the velocity coordinates (:func:`~screwkit.io.closed_tree.closure_rows`)."""
    import pinocchio as pin  # Pinocchio: imported where a file of another tool is read

    data = tree.model.createData()
    pin.computeJointJacobians(tree.model, data, q)
    return closure_rows(tree.model, data, tree.closures, scale)
