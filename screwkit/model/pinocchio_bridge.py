"""Everything screwkit asks of Pinocchio, in one place.

Pinocchio builds the kinematic tree of a mechanism file; screwkit reads joint placements and
joint subspaces from it once, when a mechanism is loaded, and writes Pinocchio configuration
vectors for the viewer and for checks. Pinocchio orders ``Motion`` and ``Force`` as
``(linear, angular)``; screwkit's screws are ``(omega, v)`` and ``(f, m)``:
:func:`twist_from_pinocchio_motion` is the only place where the order is converted.

Pinocchio is imported inside the functions, so that importing this module stays light.
"""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.common.rotations import quaternion_from_rotation

__all__ = [
    "twist_from_pinocchio_motion",
    "build_model",
    "body_frame",
    "joint_axis_local",
    "configuration_vector",
]


def twist_from_pinocchio_motion(motion: ArrayLike) -> NDArray[np.float64]:
    """Reorder Pinocchio motion vectors ``(linear, angular)`` (..., 6) to screwkit twists ``(omega, v)``.

    This is the only place where Pinocchio's ordering is converted. For a Jacobian matrix
    (6, n), pass its transpose.
    """
    motion = np.asarray(motion, dtype=float)
    if motion.shape[-1:] != (6,):
        raise ValueError(f"Expected Pinocchio motion vectors with shape (..., 6), got {motion.shape}.")
    return np.concatenate([motion[..., 3:], motion[..., :3]], axis=-1)


def build_model(text: str, fail):
    """The Pinocchio model of a URDF text; ``fail(problem)`` builds the error raised when it cannot."""
    import pinocchio

    try:
        return pinocchio.buildModelFromXML(text)
    except Exception as error:  # Pinocchio raises plain RuntimeErrors
        message = str(error).strip().splitlines()[0] if str(error).strip() else type(error).__name__
        raise fail(f"Pinocchio cannot build the model: {message}") from None


def body_frame(model, link: str):
    """The Pinocchio frame of a link (a BODY frame)."""
    import pinocchio

    return model.frames[model.getFrameId(link, pinocchio.BODY)]


def joint_axis_local(model, data, joint_id: int) -> tuple[NDArray[np.float64], bool]:
    """Unit axis of a 1-DoF joint in its own frame and whether it is prismatic.

    Read from the joint's motion subspace (``pinocchio.computeJointJacobians`` must have run
    on ``data``).
    """
    import pinocchio

    joint = model.joints[joint_id]
    subspace = twist_from_pinocchio_motion(
        np.array(pinocchio.getJointJacobian(model, data, joint_id, pinocchio.LOCAL))[:, joint.idx_v].T
    )
    if np.linalg.norm(subspace[:3]) > 0.5:
        return subspace[:3] / np.linalg.norm(subspace[:3]), False
    return subspace[3:] / np.linalg.norm(subspace[3:]), True


def neutral_with_jacobians(model):
    """``(data, q0)``: Pinocchio data with the joint Jacobians computed at the neutral configuration."""
    import pinocchio

    data = model.createData()
    neutral = pinocchio.neutral(model)
    pinocchio.computeJointJacobians(model, data, neutral)
    return data, neutral


def _set_joint(configuration: NDArray, joint, value: NDArray) -> None:
    if joint.nq == 2:  # continuous joint stored as (cos, sin)
        configuration[..., joint.idx_q] = np.cos(value)
        configuration[..., joint.idx_q + 1] = np.sin(value)
    else:
        configuration[..., joint.idx_q] = value


def configuration_vector(mechanism, joint_values: Sequence[ArrayLike],
                         poses: ArrayLike | None = None) -> NDArray[np.float64]:
    """Pinocchio configuration vectors q (..., nq) of a mechanism's tree.

    Parameters
    ----------
    mechanism : screwkit.model.Mechanism
    joint_values : sequence of array_like
        Per chain, values (..., m_i) (e.g. ``solution.joint_values``); the tree joints take
        them (loop-joint values are not part of the tree).
    poses : array_like, shape (..., n_pose), optional
        Full platform poses for the platform joint (e.g. ``solution.full_poses``); default the
        reference assembly.
        Joints outside every chain keep their reference values.
    """
    import pinocchio

    model = mechanism.pinocchio_model
    joint_values = [np.asarray(values, dtype=float) for values in joint_values]
    poses = mechanism.home_full_pose if poses is None else np.asarray(poses, dtype=float)
    if poses.shape[-1:] != (mechanism.n_pose,):
        raise ValueError(f"Expected full poses with shape (..., {mechanism.n_pose}), got {poses.shape}.")
    batch = np.broadcast_shapes(poses.shape[:-1], *(values.shape[:-1] for values in joint_values))
    reference = pinocchio.neutral(model)
    for name, value in mechanism.description.reference_configuration.items():
        _set_joint(reference, model.joints[model.getJointId(name)], np.asarray(value))
    configuration = np.array(np.broadcast_to(reference, batch + (model.nq,)))
    for index, chain in enumerate(mechanism.chains):
        for position, joint_id in enumerate(chain.tree_joint_ids):
            _set_joint(configuration, model.joints[joint_id], joint_values[index][..., position])
    rotation, translation = mechanism.transforms_from_poses(np.broadcast_to(poses, batch + (mechanism.n_pose,)))
    world_rotation = mechanism.rotation_world_base @ rotation
    world_translation = mechanism.translation_world_base + translation @ mechanism.rotation_world_base.T
    frame_inverse = mechanism.platform_frame_placement.inverse()
    joint_rotation = world_rotation @ np.array(frame_inverse.rotation)
    joint_translation = world_translation + world_rotation @ np.array(frame_inverse.translation)
    placement = model.jointPlacements[mechanism.platform_joint_id]
    local_rotation = np.array(placement.rotation).T @ joint_rotation
    local_translation = (joint_translation - np.array(placement.translation)) @ np.array(placement.rotation)
    start = model.joints[mechanism.platform_joint_id].idx_q
    if mechanism.is_planar:
        angle = np.arctan2(local_rotation[..., 1, 0], local_rotation[..., 0, 0])
        configuration[..., start : start + 4] = np.stack(
            [local_translation[..., 0], local_translation[..., 1], np.cos(angle), np.sin(angle)], -1
        )
    else:
        configuration[..., start : start + 3] = local_translation
        configuration[..., start + 3 : start + 7] = quaternion_from_rotation(local_rotation)
    return configuration


def placement_arrays(placement: Any) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``(rotation, translation)`` arrays of a ``pinocchio.SE3``."""
    return np.array(placement.rotation), np.array(placement.translation)
