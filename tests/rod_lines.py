"""The indices of a two-rod parallel ankle from its rod lines (test helper), computed from a Pinocchio model's joint
frames alone, independently of screwkit.

Each rod, with a ball or universal joint at each end, carries one force, along the line through its two joint
centres: ITI = |f . v| / |v| with v the velocity of the crank's end when its motor turns, and OTI = |f . v| / |v|
with v the velocity of the rod's foot end under the foot twist reciprocal to the other rod's force in the foot's
motion space (the twists of its two hinges). The configuration is found by scipy's least squares on the loops of
the file (:func:`closed_by_scipy`).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
from scipy.optimize import least_squares


def closed_by_scipy(model, pairs, held: dict[str, float]):
    """``model`` with every loop (frame ``pairs``) closed by scipy's least squares over the velocity coordinates of
    the joints not ``held`` (those at the given values), from the neutral configuration."""
    data = model.createData()
    start = pin.neutral(model)
    for name, value in held.items():
        start[model.joints[model.getJointId(name)].idx_q] = value
    held_v = {model.joints[model.getJointId(name)].idx_v for name in held}
    free = [index for index in range(model.nv) if index not in held_v]

    def configuration(x):
        step = np.zeros(model.nv)
        step[free] = x
        return pin.integrate(model, start, step)

    def residuals(x):
        pin.framesForwardKinematics(model, data, configuration(x))
        return np.concatenate([pin.log6(data.oMf[a].inverse() * data.oMf[b]).vector for a, b in pairs])

    solved = least_squares(residuals, np.zeros(len(free)), xtol=1e-15, ftol=1e-15, gtol=1e-15)
    assert np.abs(residuals(solved.x)).max() < 1e-10  # every loop closed
    q = configuration(solved.x)
    pin.forwardKinematics(model, data, q)
    return data, q


AXES = {"JointModelRX": 0, "JointModelRY": 1, "JointModelRZ": 2}


def joint_line(model, data, name: str) -> tuple[np.ndarray, np.ndarray | None]:
    """A joint's origin and, for a revolute, its unit axis, in the world, at the configuration of ``data``."""
    joint = model.getJointId(name)
    shortname = model.joints[joint].shortname()
    if shortname in AXES:
        axis = data.oMi[joint].rotation[:, AXES[shortname]]
    elif shortname.startswith("JointModelRevolute"):
        axis = data.oMi[joint].rotation @ np.asarray(model.joints[joint].extract().axis)
    else:
        axis = None
    return data.oMi[joint].translation.copy(), None if axis is None else np.array(axis)


def joint_centre(model, data, joint) -> np.ndarray:
    """A joint's origin (a name), or the point where two revolute joints' lines meet (a pair of names: a universal
    joint drawn anywhere along its hinges' lines), in the world."""
    if isinstance(joint, str):
        return joint_line(model, data, joint)[0]
    (p, u), (q, w) = (joint_line(model, data, name) for name in joint)
    s, t = np.linalg.solve(np.array([[u @ u, -u @ w], [u @ w, -w @ w]]), np.array([(q - p) @ u, (q - p) @ w]))
    return (p + s * u + q + t * w) / 2


def two_rod_indices(model, data, rods: dict, hinges: tuple[str, str]) -> tuple[np.ndarray, np.ndarray]:
    """The ITI and OTI of each motor (sorted by name) of ``rods``, each motor's (crank-end joint, foot-end joint;
    either a pair of hinges, see :func:`joint_centre`), the foot's two ``hinges`` named, at the configuration of
    ``data`` (its joint placements computed)."""
    forces, itis = {}, []
    for motor in sorted(rods):
        crank, end = (joint_centre(model, data, joint) for joint in rods[motor])
        force = (end - crank) / np.linalg.norm(end - crank)
        origin, axis = joint_line(model, data, motor)
        velocity = np.cross(axis, crank - origin)
        itis.append(abs(force @ velocity) / np.linalg.norm(velocity))
        forces[motor] = (force, crank, end)
    lines = [joint_line(model, data, name) for name in hinges]
    space = np.array([np.concatenate([axis, np.cross(point, axis)]) for point, axis in lines]).T  # (omega, v at 0)

    def power(force, at, twist):
        return force @ (twist[3:] + np.cross(twist[:3], at))

    otis = []
    for motor in sorted(rods):
        force, _, end = forces[motor]
        other, other_at, _ = next(value for key, value in forces.items() if key != motor)
        twist = space @ np.array([-power(other, other_at, space[:, 1]), power(other, other_at, space[:, 0])])
        velocity = twist[3:] + np.cross(twist[:3], end)
        otis.append(abs(force @ velocity) / np.linalg.norm(velocity))
    return np.array(itis), np.array(otis)
