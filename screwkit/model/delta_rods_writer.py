"""Writing Delta robots whose forearms are parallelograms of ball-jointed rods, as MJCF (a closed-loop graph).

Used by the bundled ``delta_rods_4`` (``python -m screwkit.robots.generate``), the rod-level twin of ``delta_4``:
the same base, arms, rods and platform, with each forearm the two rods of an industrial Delta's parallelogram
(``spacing`` apart along the motor axis, a ball joint at each end) instead of Tsai's R-U-U leg. screwkit opens it
as a graph (:mod:`screwkit.io.graph`). The platform hangs in the tree from leg 1's first rod by a ball joint, as
CAD exporters write it; every other rod end is closed onto the platform by a ``<connect>``.
"""

from __future__ import annotations

import math

import numpy as np

from screwkit.model.delta_writer import delta_leg

__all__ = ["delta_rods_mjcf"]


def _text(vector) -> str:
    return " ".join(repr(round(float(v), 12) + 0.0) for v in vector)


def delta_rods_mjcf(name: str, parameters: dict, spacing: float, comment: str = "") -> str:
    """MJCF text (metres, radians) of a Delta with a rod-pair forearm at each of ``parameters["leg_angles_deg"]``
    (the parameters of :func:`screwkit.model.delta_writer.delta_document`), closed at ``qpos0`` with the platform
    at ``parameters["home"]``: each leg's arm, elbow-out, then rods from ``B -+ spacing/2 a`` to
    ``D -+ spacing/2 a``."""
    home = np.asarray(parameters["home"], dtype=float)
    half = spacing / 2
    legs, connects = [], []
    for i, degrees in enumerate(parameters["leg_angles_deg"], start=1):
        leg = delta_leg(parameters, home, math.radians(degrees))
        a_point, axis, elbow, end = leg["A"], leg["a"], leg["B"], leg["D"]
        rods = []
        for side, sign in (("a", -1.0), ("b", 1.0)):
            start, finish = elbow + sign * half * axis, end + sign * half * axis
            hang = ""
            if i == 1 and side == "a":  # the platform hangs from this rod's far end
                hang = (f'<body name="platform" pos="{_text(home - start)}">'  # its frame at the centre
                        f'<joint name="platform_ball" type="ball" pos="{_text(finish - home)}"/>'
                        f'<geom type="cylinder" size="0.07 0.005"/></body>')
            else:
                connects.append(f'<connect name="rod_{i}{side}_end" body1="rod_{i}{side}" body2="platform" '
                                f'anchor="{_text(finish - start)}"/>')
            rods.append(f'<body name="rod_{i}{side}" pos="{_text(start - a_point)}">'
                        f'<joint name="ball_{i}{side}" type="ball"/>'
                        f'<geom type="capsule" fromto="0 0 0 {_text(finish - start)}" size="0.006"/>{hang}</body>')
        legs.append(f'<body name="arm_{i}" pos="{_text(a_point)}">'
                    f'<joint name="motor_{i}" type="hinge" axis="{_text(axis)}" range="-1.5 1.5"/>'
                    f'<geom type="capsule" fromto="0 0 0 {_text(elbow - a_point)}" size="0.015"/>'
                    + "".join(rods) + "</body>")
    motors = "".join(f'<motor name="motor_{i}" joint="motor_{i}"/>'
                     for i in range(1, len(parameters["leg_angles_deg"]) + 1))
    return (f"<!--{comment}-->\n" if comment else "") + (
        f'<mujoco model="{name}">\n  <compiler angle="radian" autolimits="true"/>\n'
        '  <option gravity="0 0 0"><flag contact="disable"/></option>\n  <worldbody>\n    <body name="base">\n      '
        + "\n      ".join(legs) + "\n    </body>\n  </worldbody>\n  <equality>\n    "
        + "\n    ".join(connects) + "\n  </equality>\n  <actuator>" + motors + "</actuator>\n</mujoco>\n")
