"""Screw description of a mechanism's chains at a batch of configurations.

This is the hand-over point between the mechanism side (URDF, Pinocchio, closure
solving) and the math core: everything the indices need is the world-frame joint
twists of every chain, the points of its joints and which joints are actuated.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.common.validation import check_finite, check_shape


@dataclass(frozen=True)
class ChainScrews:
    """Joint screws of one serial chain from the base to the platform.

    Parameters
    ----------
    twists : array_like, shape (..., m, 6)
        Unit joint twists in the world frame, ordered base to platform, each as
        ``(omega, v)`` with ``v`` the velocity of the point at the world origin.
        Revolute joints have ``|omega| = 1``; prismatic joints ``omega = 0, |v| = 1``.
        A spherical or universal joint contributes one twist per rotational DoF.
    points : array_like, shape (..., m, 3)
        A point of each joint in the world frame (the joint origin; for a revolute
        joint it lies on the axis). The last one is the chain's *platform joint point*.
    actuated : tuple of int
        Indices (0-based, into the m joints) of the actuated joints of this chain.
    name : str
        The chain's name (actuators are reported as ``name:joint``).
    joint_names : sequence of str, optional
        One name per joint DoF (default ``joint_0``, ``joint_1``, ...).
    """

    twists: NDArray[np.float64]
    points: NDArray[np.float64]
    actuated: tuple[int, ...]
    name: str = ""
    joint_names: tuple[str, ...] = ()
    batch_shape: tuple[int, ...] = field(init=False)

    def __init__(self, twists: ArrayLike, points: ArrayLike, actuated, name: str = "",
                 joint_names: tuple[str, ...] | None = None):
        twists = check_finite(check_shape(np.asarray(twists, dtype=float), (None, 6), "twists", batch=True), "twists")
        points = check_finite(check_shape(np.asarray(points, dtype=float), (None, 3), "points", batch=True), "points")
        m = twists.shape[-2]
        if points.shape[-2] != m:
            raise ValueError(
                f"Expected `points` with one point per joint ({m}) of chain {name!r}, "
                f"got shape {points.shape}."
            )
        if twists.shape[:-2] != points.shape[:-2]:
            raise ValueError(
                f"Expected `twists` and `points` of chain {name!r} to share their batch shape, "
                f"got {twists.shape[:-2]} and {points.shape[:-2]}."
            )
        actuated_tuple = tuple(int(i) for i in np.atleast_1d(np.asarray(actuated)))
        for index in actuated_tuple:
            if not 0 <= index < m:
                raise ValueError(
                    f"Expected actuated joint indices of chain {name!r} in 0..{m - 1}, got {index}."
                )
        if len(set(actuated_tuple)) != len(actuated_tuple):
            raise ValueError(f"Actuated joint indices of chain {name!r} repeat: {actuated_tuple}.")
        object.__setattr__(self, "twists", twists)
        object.__setattr__(self, "points", points)
        object.__setattr__(self, "actuated", actuated_tuple)
        if joint_names is None:
            joint_names = tuple(f"joint_{k}" for k in range(m))
        joint_names = tuple(str(joint) for joint in joint_names)
        if len(joint_names) != m:
            raise ValueError(f"Expected one joint name per joint ({m}) of chain {name!r}, got {len(joint_names)}.")
        object.__setattr__(self, "name", name)
        object.__setattr__(self, "joint_names", joint_names)
        object.__setattr__(self, "batch_shape", twists.shape[:-2])

    @property
    def n_joints(self) -> int:
        """Number of joint DoFs m of the chain."""
        return self.twists.shape[-2]
