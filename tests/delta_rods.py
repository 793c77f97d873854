"""A Delta robot whose forearms are parallelograms of ball-jointed rods, written as an MJCF file (test helper).

Leg ``i`` at azimuth ``phi_i``: the motor's hinge at ``B_i`` (radius ``BASE`` in the base plane) about the
tangent ``a_i``; the arm (length ``ARM``) ends at the elbow ``E_i``; two rods of length ``ROD`` from
``E_i -+ SPACING/2 a_i`` to ``P_i -+ SPACING/2 a_i``, ``P_i`` the platform's attachment (radius ``PLATFORM``
about the platform centre ``p``). The platform hangs in the tree from leg 1's first rod by a ball joint, as
onshape-to-robot writes it; every other rod end is closed onto the platform by a ``<connect>``.
"""

from __future__ import annotations

import numpy as np

BASE, PLATFORM, ARM, ROD, SPACING = 0.20, 0.05, 0.25, 0.55, 0.06


def text(vector) -> str:
    return " ".join(repr(float(v)) for v in vector)


class _Scaled:
    """``text`` of positions multiplied by a scale."""

    def __init__(self, scale: float):
        self.scale = scale

    def __call__(self, vector) -> str:
        return text(self.scale * np.asarray(vector, dtype=float))


def delta_geometry(centre, azimuths):
    """Base joints, motor axes, elbows and platform attachments (each (legs, 3)) with the platform at
    ``centre``: each motor angle the one whose elbow lies outside (the usual working mode)."""
    centre = np.asarray(centre, dtype=float)
    radial = np.stack([np.cos(azimuths), np.sin(azimuths), np.zeros_like(azimuths)], axis=-1)
    axes = np.stack([-np.sin(azimuths), np.cos(azimuths), np.zeros_like(azimuths)], axis=-1)
    base = BASE * radial
    attach = centre + PLATFORM * radial
    elbows = []
    for b, r, p in zip(base, radial, attach):
        # elbow E = b + ARM (cos t r - sin t z); |E - p| = ROD: A cos t + C sin t = D
        d = p - b
        a_, c_ = 2 * ARM * (d @ r), -2 * ARM * d[2]
        dd = (d @ d + ARM**2 - ROD**2)
        angle = np.arctan2(c_, a_) - np.arccos(np.clip(dd / np.hypot(a_, c_), -1.0, 1.0))
        elbows.append(b + ARM * (np.cos(angle) * r - np.sin(angle) * np.array([0.0, 0.0, 1.0])))
    elbows = np.array(elbows)
    assert np.allclose(np.linalg.norm(elbows - attach, axis=1), ROD), "pose out of reach"
    return base, axes, elbows, attach


def quaternion(rotation) -> np.ndarray:
    """(w, x, y, z) of a rotation matrix (MuJoCo's order)."""
    w = np.sqrt(max(1.0 + np.trace(rotation), 1e-300)) / 2
    if w > 1e-3:
        return np.array([w, *(np.array([rotation[2, 1] - rotation[1, 2], rotation[0, 2] - rotation[2, 0],
                                         rotation[1, 0] - rotation[0, 1]]) / (4 * w))])
    k = int(np.argmax(np.diag(rotation)))
    i, j = (k + 1) % 3, (k + 2) % 3
    v = np.zeros(3)
    v[k] = np.sqrt(1.0 + rotation[k, k] - rotation[i, i] - rotation[j, j]) / 2
    v[i] = (rotation[i, k] + rotation[k, i]) / (4 * v[k])
    v[j] = (rotation[j, k] + rotation[k, j]) / (4 * v[k])
    return np.array([(rotation[j, i] - rotation[i, j]) / (4 * v[k]), *v])


def delta_rods_mjcf(centre=(0.02, -0.03, -0.45), azimuths=None, transform=None, platform_spacing=SPACING) -> str:
    """The MJCF text (metres, radians), closed at ``qpos0``; ``transform`` = (scale, rotation, translation) writes
    the same robot scaled and placed elsewhere in the world (its base body rotated and moved);
    ``platform_spacing``: the rods' spacing at the platform (``SPACING`` at the arms; another makes each pair a
    trapezoid, not a parallelogram)."""
    scale, rotation, translation = (1.0, np.eye(3), np.zeros(3)) if transform is None else transform
    azimuths = np.radians([90.0, 180.0, 270.0, 0.0]) if azimuths is None else np.asarray(azimuths, dtype=float)
    base, axes, elbows, attach = delta_geometry(centre, azimuths)
    at = _Scaled(scale)
    legs, connects = [], []
    half = SPACING / 2
    for i, (b, a, e, p) in enumerate(zip(base, axes, elbows, attach), start=1):
        rods = []
        for side, sign in (("a", -1.0), ("b", 1.0)):
            start, end = e + sign * half * a, p + sign * platform_spacing / 2 * a
            hang = ""
            if i == 1 and side == "a":  # the platform hangs from this rod's far end
                hang = (f'<body name="platform" pos="{at(end - start)}"><joint name="platform_ball" type="ball"/>'
                        f'<geom type="sphere" size="0.01"/><site name="centre" pos="{at(centre - end)}"/></body>')
            else:
                connects.append(f'<connect name="rod_{i}{side}_end" body1="rod_{i}{side}" body2="platform" '
                                f'anchor="{at(end - start)}"/>')
            rods.append(f'<body name="rod_{i}{side}" pos="{at(start - b)}"><joint name="ball_{i}{side}" '
                        f'type="ball"/><geom type="capsule" fromto="0 0 0 {at(end - start)}" size="0.004"/>'
                        f'{hang}</body>')
        legs.append(f'<body name="arm_{i}" pos="{at(b)}"><joint name="motor_{i}" type="hinge" axis="{text(a)}"/>'
                    f'<geom type="capsule" fromto="0 0 0 {at(e - b)}" size="0.01"/>{"".join(rods)}</body>')
    motors = "".join(f'<motor name="m_{i}" joint="motor_{i}"/>' for i in range(1, len(base) + 1))
    placed = f'pos="{text(translation)}" quat="{text(quaternion(rotation))}"'
    return (f'<mujoco model="delta_rods"><compiler angle="radian"/><worldbody><body name="base" {placed}>'
            + "".join(legs) + "</body></worldbody><equality>" + "".join(connects) + "</equality><actuator>"
            + motors + "</actuator></mujoco>")
