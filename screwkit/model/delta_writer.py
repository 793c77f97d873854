"""Writing Delta robots with any number of legs in screwkit's URDF convention.

Used by the bundled ``delta_4`` (``python -m screwkit.robots.generate``) and by the design family
``delta`` of :mod:`screwkit.studies.design.families`. Each parallelogram forearm is modelled by Tsai's
translational R-U-U leg (see :func:`delta_urdf` and ``robots/README.md``).
"""

from __future__ import annotations

import math

import numpy as np

from screwkit.common.rotations import rpy_from_rotation
from screwkit.model.urdf_document import UrdfDocument
from screwkit.model.urdf_writer import UrdfWriter

__all__ = ["delta_leg", "delta_document", "delta_urdf"]

Z_AXIS = np.array([0.0, 0.0, 1.0])


def delta_leg(parameters: dict, position, angle: float) -> dict:
    """One Delta leg, elbow out, for the platform centre at ``position``: actuated axis point A and
    unit axis a (tangent to the base circle), elbow B, platform rod end D, arm angle theta below the
    horizontal (rad), unit arm vector r and rod direction u.

    ``parameters``: ``base_radius`` (actuated axes from the centre), ``platform_radius`` (rod ends
    from the platform centre), ``arm``, ``rod`` (m). Raises ValueError when the leg cannot reach."""
    radius, arm, rod = parameters["base_radius"], parameters["arm"], parameters["rod"]
    radial = np.array([math.cos(angle), math.sin(angle), 0.0])
    axis = np.array([-math.sin(angle), math.cos(angle), 0.0])
    a_point = radius * radial
    d_point = np.asarray(position, dtype=float) + parameters["platform_radius"] * radial
    delta = d_point - a_point
    # |delta - arm (cos t radial - sin t z)| = rod  <=>  k cos t - m sin t = c
    k, m = 2 * arm * (delta @ radial), 2 * arm * delta[2]
    c = delta @ delta + arm**2 - rod**2
    if not abs(c) <= math.hypot(k, m):
        raise ValueError(f"A Delta leg at {math.degrees(angle):g} deg cannot reach the platform at "
                         f"{np.round(position, 6).tolist()} m (arm {arm:g} m, rod {rod:g} m).")
    theta = math.atan2(-m, k) - math.acos(c / math.hypot(k, m))  # the elbow-out solution
    r = math.cos(theta) * radial - math.sin(theta) * Z_AXIS
    b_point = a_point + arm * r
    return {"A": a_point, "a": axis, "B": b_point, "D": d_point, "theta": theta, "r": r, "u": (d_point - b_point) / rod}


def delta_urdf(name: str, parameters: dict, comment: str = "") -> str:
    """The URDF text of :func:`delta_document`."""
    return delta_document(name, parameters, comment).text()


def delta_document(name: str, parameters: dict, comment: str = "") -> UrdfDocument:
    """A Delta robot (3 DOF: x, y, z) with a leg at each of ``parameters["leg_angles_deg"]``.

    Leg i: actuated revolute ``leg_i_joint_arm`` about a_i (horizontal, tangent to the base circle)
    at A_i, upper arm to the elbow B_i, then Tsai's R-U-U equivalent of the parallelogram forearm:
    a universal joint at B_i (``leg_i_joint_elbow_a`` about a_i, ``leg_i_joint_elbow_w`` about
    w_i = a_i x u_i / |a_i x u_i|, normal to the parallelogram's plane), the rod B_i -> D_i, and a
    universal loop joint at D_i on the platform (``leg_i_joint_platform``: w_i, then a_i). The
    platform sits at ``parameters["home"]`` in the reference assembly; ``named_poses`` (name ->
    (x, y, z)) are written as ``<named_pose>`` elements.
    """
    arm, rod = parameters["arm"], parameters["rod"]
    home = np.asarray(parameters["home"], dtype=float)
    writer = UrdfWriter(name, comment)
    writer.link("base_link", ("cylinder", parameters["base_radius"] + 0.05, 0.01), xyz=(0, 0, 0.02))
    writer.link("platform", ("cylinder", parameters["platform_radius"] + 0.02, 0.01))
    writer.joint("platform_joint", "floating", "base_link", "platform", xyz=home)
    for i, degrees in enumerate(parameters["leg_angles_deg"]):
        chain = f"leg_{i + 1}"
        leg = delta_leg(parameters, home, math.radians(degrees))
        a, r, u = leg["a"], leg["r"], leg["u"]
        w = np.cross(a, u)
        w = w / np.linalg.norm(w)
        arm_frame = np.column_stack([r, a, np.cross(r, a)])  # x along the arm, y along the actuated axis
        rod_frame = np.column_stack([u, w, np.cross(u, w)])  # x along the rod, y along w
        writer.rod(f"{chain}_arm", arm, radius=0.02)
        writer.link(f"{chain}_cross", ("sphere", 0.02))
        writer.rod(f"{chain}_rod", rod, radius=0.01)
        writer.joint(f"{chain}_joint_arm", "revolute", "base_link", f"{chain}_arm", xyz=leg["A"],
                     rpy=rpy_from_rotation(arm_frame), axis=(0, 1, 0), limit=(-1.5, 1.5, 100.0, 5.0))  # fmt: skip
        writer.joint(f"{chain}_joint_elbow_a", "continuous", f"{chain}_arm", f"{chain}_cross", xyz=(arm, 0, 0),
                     rpy=rpy_from_rotation(arm_frame.T @ rod_frame), axis=rod_frame.T @ a)  # fmt: skip
        writer.joint(f"{chain}_joint_elbow_w", "continuous", f"{chain}_cross", f"{chain}_rod", axis=(0, 1, 0))
        writer.loop(f"{chain}_joint_platform", "universal", chain, f"{chain}_rod", ((rod, 0, 0), (0, 0, 0)),
                    "platform", (leg["D"] - home, rpy_from_rotation(rod_frame)),
                    axis=(0, 1, 0), second_axis=rod_frame.T @ a)  # fmt: skip
        writer.transmission(f"{chain}_joint_arm")
    for pose_name, (x, y, z) in parameters.get("named_poses", {}).items():
        writer.named_pose(pose_name, {"x": x, "y": y, "z": z})
    return writer.document()
