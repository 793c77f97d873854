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
    "model_from_description",
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


_AXIS_MODELS = {  # joint type -> (name prefix of the joint models about x, y, z, the unaligned model's name)
    "revolute": ("JointModelR", "JointModelRevoluteUnaligned"),
    "continuous": ("JointModelRUB", "JointModelRevoluteUnboundedUnaligned"),
    "prismatic": ("JointModelP", "JointModelPrismaticUnaligned"),
}


def _joint_model(pinocchio, joint):
    """The Pinocchio joint model its URDF parser makes of a tree joint (an axis equal to x, y or z: the
    specialised model; else the unaligned one)."""
    if joint.type == "floating":
        return pinocchio.JointModelFreeFlyer()
    if joint.type == "planar":
        return pinocchio.JointModelPlanar()
    prefix, unaligned = _AXIS_MODELS[joint.type]
    for letter, unit in zip("XYZ", np.eye(3)):
        if np.array_equal(joint.axis, unit):
            return getattr(pinocchio, prefix + letter)()
    return getattr(pinocchio, unaligned)(np.asarray(joint.axis, dtype=float))


def _placement(pinocchio, origin):
    """A URDF ``<origin>`` as Pinocchio's parser makes it: the rpy angles through urdfdom's unit quaternion."""
    roll, pitch, yaw = (0.5 * float(angle) for angle in origin.rpy)
    sr, cr, sp, cp, sy, cy = np.sin(roll), np.cos(roll), np.sin(pitch), np.cos(pitch), np.sin(yaw), np.cos(yaw)
    x = sr * cp * cy - cr * sp * sy
    y = cr * sp * cy + sr * cp * sy
    z = cr * cp * sy - sr * sp * cy
    w = cr * cp * cy + sr * sp * sy
    norm = np.sqrt(x * x + y * y + z * z + w * w)
    quaternion = pinocchio.Quaternion(w / norm, x / norm, y / norm, z / norm)
    return pinocchio.SE3(quaternion.matrix(), np.asarray(origin.xyz, dtype=float))


def _parser_limits(joint, nq: int, nv: int) -> tuple[NDArray, NDArray, NDArray, NDArray]:
    """Effort, velocity, lower and upper configuration limits of a joint as Pinocchio's URDF parser sets them:
    the file's for revolute and prismatic joints; +-1.01 on unit-complex and quaternion parts, else unbounded."""
    if joint.type in ("revolute", "prismatic", "continuous"):
        effort, velocity = (np.array([value], dtype=float) for value in joint.drive_limits)
    else:
        effort, velocity = np.full(nv, np.inf), np.full(nv, np.inf)
    if joint.type in ("revolute", "prismatic"):
        return effort, velocity, np.array([joint.limits[0]], dtype=float), np.array([joint.limits[1]], dtype=float)
    unbounded = {"continuous": 0, "planar": 2, "floating": 3}[joint.type]  # coordinates before the unit parts
    lower, upper = np.full(nq, -1.01), np.full(nq, 1.01)
    lower[:unbounded], upper[:unbounded] = -np.inf, np.inf
    return effort, velocity, lower, upper


def model_from_description(description):
    """The Pinocchio model :func:`build_model` makes of the description's text, built without the text.

    For descriptions a writer built (:meth:`screwkit.model.urdf_document.UrdfDocument.description`): tree
    joints revolute, continuous, prismatic, floating or planar, links without inertia. As Pinocchio's URDF
    parser (through urdfdom) does: the root link is a body frame of the universe, the tree is walked depth
    first with the child joints of a link in the order of their names, each joint followed by its frame
    and its child link's body frame; joint limits as the parser sets them.
    """
    import pinocchio

    children: dict[str, list] = {}
    for joint in description.joints.values():
        if joint.type not in ("revolute", "continuous", "prismatic", "floating", "planar"):
            raise description.fail(f"<joint name='{joint.name}'>",
                                   f"a {joint.type} joint: the model is built from the text for it.")
        children.setdefault(joint.parent, []).append(joint)
    child_links = {joint.child for joint in description.joints.values()}
    root = next(link for link in description.links if link not in child_links)
    model = pinocchio.Model()
    model.name = description.robot_name
    model.addFrame(pinocchio.Frame(root, 0, 0, pinocchio.SE3.Identity(), pinocchio.FrameType.BODY))

    def add_subtree(link: str) -> None:
        parent_frame_id = model.getFrameId(link, pinocchio.FrameType.BODY)
        parent_frame = model.frames[parent_frame_id]
        for joint in sorted(children.get(link, ()), key=lambda joint: joint.name):
            joint_model = _joint_model(pinocchio, joint)
            placement = parent_frame.placement * _placement(pinocchio, joint.origin)
            joint_id = model.addJoint(parent_frame.parentJoint, joint_model, placement, joint.name,
                                      *_parser_limits(joint, joint_model.nq, joint_model.nv))
            joint_frame = model.addJointFrame(joint_id, parent_frame_id)
            model.appendBodyToJoint(joint_id, pinocchio.Inertia.Zero(), pinocchio.SE3.Identity())
            model.addBodyFrame(joint.child, joint_id, pinocchio.SE3.Identity(), joint_frame)
            add_subtree(joint.child)

    add_subtree(root)
    return model


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
