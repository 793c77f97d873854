"""Planar parallel mechanisms built by hand: n-RRR and n-RPR geometry and their chain screws.

This module gives the math core a way to build chain screws without any file or
Pinocchio: platform poses -> joint points (RRR elbows by circle intersection with a
working mode) -> :class:`~screwkit.screw.chain_screws.ChainScrews` for :func:`screwkit.indices.analysis.analyze`.
It also defines the paper's Table 2 design as a set of *parameters*.
Only numpy is imported here.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.common.validation import as_float_array, check_finite, check_shape
from screwkit.screw.chain_screws import ChainScrews

__all__ = [
    "PlanarDesign",
    "paper_5rrr",
    "platform_points",
    "rrr_elbows",
    "planar_joint_points",
    "rrr_chain_screws",
    "rpr_chain_screws",
]

Z_AXIS = np.array([0.0, 0.0, 1.0])


@dataclass(frozen=True)
class PlanarDesign:
    """Parameters of a planar n-RRR mechanism.

    Attributes
    ----------
    base : ndarray, shape (k, 2)
        Base (actuated) joint points ``b_i`` in the fixed frame F.
    platform : ndarray, shape (k, 2)
        Platform joint points ``d_i`` in the platform frame M.
    upper : ndarray, shape (k,)
        Upper-arm lengths ``a_i`` (b_i to c_i).
    lower : ndarray, shape (k,)
        Lower-arm lengths ``l_i`` (c_i to d_i).
    working_mode : ndarray, shape (k,) of +1/-1
        Side of the line ``b_i -> d_i`` on which elbow ``c_i`` lies: +1 is the side of
        ``u_perp``, the direction ``u = (d_i - b_i)/|d_i - b_i|`` rotated +90 deg about z.
    """

    base: NDArray[np.float64]
    platform: NDArray[np.float64]
    upper: NDArray[np.float64]
    lower: NDArray[np.float64]
    working_mode: NDArray[np.float64]

    def __post_init__(self):
        base = check_finite(check_shape(as_float_array(self.base, "base"), (None, 2), "base", batch=False), "base")
        count = base.shape[0]
        platform = check_finite(check_shape(as_float_array(self.platform, "platform"), (count, 2), "platform",
                                            batch=False), "platform")
        values = {}
        for name in ("upper", "lower", "working_mode"):
            array = np.broadcast_to(as_float_array(getattr(self, name), name), (count,)).astype(float)
            check_finite(array, name)
            values[name] = array
        if np.any(values["upper"] <= 0) or np.any(values["lower"] <= 0):
            raise ValueError(f"Expected positive arm lengths, got upper={values['upper']}, lower={values['lower']}.")
        if not np.all(np.isin(values["working_mode"], (-1.0, 1.0))):
            raise ValueError(f"Expected `working_mode` entries +1 or -1, got {values['working_mode']}.")
        object.__setattr__(self, "base", base)
        object.__setattr__(self, "platform", platform)
        for name, array in values.items():
            object.__setattr__(self, name, array)

    @property
    def chain_count(self) -> int:
        return self.base.shape[0]


def paper_5rrr(working_mode: int = 1) -> PlanarDesign:
    r"""The 5-RRR design of the paper's Table 2.

    :math:`\gamma = 2\pi/5`, :math:`a_i = l_i = 1` m, base radius ``e = 1`` m, platform
    radius ``g = 0.1`` m, :math:`b_i = e[\cos((i-1)\gamma), \sin((i-1)\gamma)]`,
    :math:`{}^M d_i = g[\cos(3(i-1)\gamma), \sin(3(i-1)\gamma)]` (platform slots 0, 3, 1, 4, 2
    for chains 1..5), every elbow on the ``working_mode`` side.
    """
    gamma = 2 * np.pi / 5
    index = np.arange(5)
    base = 1.0 * np.stack([np.cos(index * gamma), np.sin(index * gamma)], axis=-1)
    platform = 0.1 * np.stack([np.cos(3 * index * gamma), np.sin(3 * index * gamma)], axis=-1)
    return PlanarDesign(base, platform, np.ones(5), np.ones(5), np.full(5, float(working_mode)))


def platform_points(poses: ArrayLike, platform: ArrayLike) -> NDArray[np.float64]:
    r"""Platform joint points in F: :math:`d_i = r + R(\phi)\,{}^M d_i` (Eqs. 15-16).

    Parameters
    ----------
    poses : array_like, shape (..., 3)
        Platform poses ``(x, y, phi)``, phi in radians.
    platform : array_like, shape (k, 2)
        Joint points in the platform frame.

    Returns
    -------
    ndarray, shape (..., k, 2)
    """
    poses = check_finite(check_shape(as_float_array(poses, "poses"), (3,), "poses"), "poses")
    platform = check_finite(check_shape(as_float_array(platform, "platform"), (None, 2), "platform"), "platform")
    cos, sin = np.cos(poses[..., 2])[..., None], np.sin(poses[..., 2])[..., None]
    x = poses[..., 0][..., None] + cos * platform[..., 0] - sin * platform[..., 1]
    y = poses[..., 1][..., None] + sin * platform[..., 0] + cos * platform[..., 1]
    return np.stack([x, y], axis=-1)


def rrr_elbows(base: ArrayLike, distal: ArrayLike, upper: ArrayLike, lower: ArrayLike,
               working_mode: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """Elbow points ``c_i``: intersection of the circles (b_i, a_i) and (d_i, l_i).

    Parameters
    ----------
    base, distal : array_like, shape (..., k, 2)
        Points ``b_i`` and ``d_i``.
    upper, lower, working_mode : array_like, shape (k,)
        Arm lengths and elbow side (+1: side of ``u_perp``, see :class:`PlanarDesign`).

    Returns
    -------
    elbows : ndarray, shape (..., k, 2)
        NaN where the circles do not meet.
    reachable : ndarray, shape (..., k) of bool
    """
    base = np.asarray(base, dtype=float)
    distal = np.asarray(distal, dtype=float)
    upper = np.asarray(upper, dtype=float)
    lower = np.asarray(lower, dtype=float)
    chord = distal - base
    length = np.linalg.norm(chord, axis=-1)
    reachable = (length <= upper + lower) & (length >= np.abs(upper - lower)) & (length > 0)
    safe = np.where(reachable, length, 1.0)
    along = (upper**2 - lower**2 + safe**2) / (2 * safe)
    height = np.sqrt(np.maximum(upper**2 - along**2, 0.0))
    unit = chord / safe[..., None]
    perpendicular = np.stack([-unit[..., 1], unit[..., 0]], axis=-1)
    elbows = base + along[..., None] * unit + (np.asarray(working_mode) * height)[..., None] * perpendicular
    return np.where(reachable[..., None], elbows, np.nan), reachable


def planar_joint_points(design: PlanarDesign, poses: ArrayLike):
    """Base, elbow and platform joint points of an n-RRR at platform poses.

    Returns
    -------
    base, elbows, distal : ndarray, shape (..., k, 2)
    reachable : ndarray, shape (...) of bool (every chain assembles)
    """
    distal = platform_points(poses, design.platform)
    base = np.broadcast_to(design.base, distal.shape)
    elbows, reachable = rrr_elbows(base, distal, design.upper, design.lower, design.working_mode)
    return base, elbows, distal, reachable.all(axis=-1)


def _lift(points: NDArray) -> NDArray:
    return np.concatenate([points, np.zeros(points.shape[:-1] + (1,))], axis=-1)


def _revolute_z(points3: NDArray) -> NDArray:
    """Twists of revolute joints about +z through ``points3`` (..., 3): (0, 0, 1, p_y, -p_x, 0)."""
    omega = np.broadcast_to(Z_AXIS, points3.shape)
    return np.concatenate([omega, np.cross(points3, omega)], axis=-1)


def rrr_chain_screws(base: ArrayLike, elbows: ArrayLike, distal: ArrayLike,
                     actuated: tuple[int, ...] = (0,)) -> list[ChainScrews]:
    """Chain screws of planar RRR chains (z-revolutes at ``b_i, c_i, d_i``), one per chain.

    Parameters
    ----------
    base, elbows, distal : array_like, shape (..., k, 2)
    actuated : tuple of int
        Actuated joints of every chain (0: base joint, the paper's case).
    """
    distal = np.asarray(distal, dtype=float)
    points = np.stack([_lift(np.broadcast_to(np.asarray(p, dtype=float), distal.shape))
                       for p in (base, elbows, distal)], axis=-2)  # (..., k, 3 joints, 3)
    twists = _revolute_z(points)
    return [ChainScrews(twists[..., i, :, :], points[..., i, :, :], actuated, name=f"chain_{i + 1}",
                        joint_names=("b", "c", "d"))
            for i in range(points.shape[-3])]


def rpr_chain_screws(base: ArrayLike, distal: ArrayLike, actuated: tuple[int, ...] = (1,)) -> list[ChainScrews]:
    """Chain screws of planar RPR chains: z-revolute at ``b_i``, prismatic along ``b_i -> d_i``, z-revolute at ``d_i``.

    The prismatic joint's point is taken at ``d_i`` (where the sliding link meets the
    platform joint). Default actuator: the prismatic joint.
    """
    base3 = _lift(np.asarray(base, dtype=float))
    distal3 = _lift(np.asarray(distal, dtype=float))
    base3 = np.broadcast_to(base3, distal3.shape)
    direction = distal3 - base3
    length = np.linalg.norm(direction, axis=-1, keepdims=True)
    if np.any(length == 0):
        raise ValueError("Expected distinct base and platform joint points for RPR chains, got a zero-length leg.")
    slide = np.concatenate([np.zeros_like(direction), direction / length], axis=-1)
    twists = np.stack([_revolute_z(base3), slide, _revolute_z(distal3)], axis=-2)
    points = np.stack([base3, distal3, distal3], axis=-2)
    return [ChainScrews(twists[..., i, :, :], points[..., i, :, :], actuated, name=f"leg_{i + 1}",
                        joint_names=("base", "slider", "platform"))
            for i in range(twists.shape[-3])]
