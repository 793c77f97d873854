"""Locking joints of a closed tree: a serial stage before the parallel part held at the file's value."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from screwkit.io.closed_tree import ClosedTree, Closure, ImportError_, homogeneous
from screwkit.io.onshape import guessed_motors

__all__ = ["lock_joints"]


def lock_joints(tree: ClosedTree, names) -> ClosedTree:
    """The tree with the joints ``names`` locked at their values of the file's configuration (Pinocchio's reduced
    model: each locked joint's body merged into its parent's), its closures and actuators carried over.

    For a serial stage before the parallel part -- a turntable under a Stewart head, every leg passing through it
    -- the legs are then analysed on the body the stage turns. Actuators guessed from the branches leaving the
    base (:func:`screwkit.io.onshape.guessed_motors`) are guessed again on the locked tree."""
    import pinocchio as pin  # Pinocchio: imported where a file of another tool is read

    names = tuple(names or ())
    if not names:
        return tree
    model = tree.model
    for name in names:
        if not model.existJointName(name) or model.getJointId(name) == 0:
            raise ImportError_(f"{tree.source}: --lock {name}: no joint of that name; joints are "
                               + ", ".join(str(n) for n in list(model.names)[1:]) + ".")
    locked = [model.getJointId(name) for name in names]
    data = model.createData()
    pin.forwardKinematics(model, data, tree.q_reference)
    reduced = pin.buildReducedModel(model, locked, tree.q_reference)

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
    notes = [f"joints {', '.join(names)} locked at their values in the file (--lock): the legs analysed on the body "
             "they turn"]
    motors = [motor for motor in tree.motors if motor not in names]
    guessed = [k for k, note in enumerate(tree.notes) if note.startswith("actuators guessed")]
    other = [note for k, note in enumerate(tree.notes) if k not in guessed]
    if guessed and len(motors) < len(tree.motors):
        motors = guessed_motors(reduced, closures)
        other.append(f"actuators guessed from the branches leaving the base once the locked joints are held: "
                     f"{', '.join(motors)}")
    else:
        other += [tree.notes[k] for k in guessed]
    return replace(tree, model=reduced, closures=closures, motors=motors, q_reference=q, notes=other + notes,
                   locked=tree.locked + names)
