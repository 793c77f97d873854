"""The chain records of a mechanism model: what a chain is, independent of any configuration.

A chain is a serial chain of 1-DoF tree joints (revolute or prismatic) from the base to the
*leg-side loop frame*, followed by the DoFs of its loop joint, which ends at the
*platform-side loop frame* (URDF+ ``<loop>``, see ``docs/urdf-convention.md``). Its constant
geometry (:class:`ChainGeometry`) is expressed in the **base frame**, the frame of the link the
platform joint hangs from.

Loop joints:

========== ===== =====================================================================
type       DoFs  motion of the platform-side frame relative to the leg-side frame
========== ===== =====================================================================
fixed      0     none
revolute   1     rotation ``q`` about ``axis``
continuous 1     same as revolute
prismatic  1     translation ``q`` along ``axis``
universal  2     rotation ``q1`` about ``axis`` then ``q2`` about ``axis2``
spherical  3     rotation ``exp([r])`` with ``r`` the rotation vector (3 values); its
                 three twists are rotations about the leg-side frame's x, y and z axes
========== ===== =====================================================================
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["LOOP_JOINT_DOFS", "ChainGeometry", "Chain"]

LOOP_JOINT_DOFS = {"fixed": 0, "revolute": 1, "continuous": 1, "prismatic": 1, "universal": 2, "spherical": 3}
"""Number of DoFs a loop joint of each supported type adds to its chain."""


@dataclass(frozen=True)
class ChainGeometry:
    """Constant geometry of one chain, in the base frame, read from the mechanism model.

    Parameters
    ----------
    name : str
        Chain name.
    joint_rotations, joint_translations : ndarray, shapes (k, 3, 3) and (k, 3)
        Placement of each tree joint frame relative to the previous joint frame (the first
        relative to the base frame), at zero joint value.
    joint_axes : ndarray, shape (k, 3)
        Unit axis of each tree joint in its own frame.
    joint_prismatic : tuple of bool
        Whether each tree joint is prismatic (else revolute).
    leg_loop_rotation, leg_loop_translation : ndarray, shapes (3, 3) and (3,)
        Leg-side loop frame relative to the last tree joint frame (the base frame if k = 0).
    loop_type : str
        One of :data:`LOOP_JOINT_DOFS`.
    loop_axes : ndarray, shape (n, 3)
        Unit axes of the loop joint in the leg-side loop frame (1 for revolute/prismatic,
        2 for universal, none otherwise).
    platform_loop_rotation, platform_loop_translation : ndarray, shapes (3, 3) and (3,)
        Platform-side loop frame relative to the platform frame.
    """

    name: str
    joint_rotations: NDArray[np.float64]
    joint_translations: NDArray[np.float64]
    joint_axes: NDArray[np.float64]
    joint_prismatic: tuple[bool, ...]
    leg_loop_rotation: NDArray[np.float64]
    leg_loop_translation: NDArray[np.float64]
    loop_type: str
    loop_axes: NDArray[np.float64]
    platform_loop_rotation: NDArray[np.float64]
    platform_loop_translation: NDArray[np.float64]
    dof_prismatic: tuple[bool, ...] = field(init=False)

    def __post_init__(self):
        loop_prismatic = (self.loop_type == "prismatic",) * LOOP_JOINT_DOFS[self.loop_type]
        object.__setattr__(self, "dof_prismatic", tuple(self.joint_prismatic) + loop_prismatic)

    @property
    def n_tree_joints(self) -> int:
        """Number of tree joints k."""
        return len(self.joint_prismatic)

    @property
    def n_dofs(self) -> int:
        """Number of joint DoFs m of the chain (tree joints plus loop-joint DoFs)."""
        return len(self.dof_prismatic)



@dataclass(frozen=True)
class Chain:
    """One chain of a mechanism: its joints, actuators, geometry and how it is closed.

    Attributes
    ----------
    name : str
        Chain name (the loop's ``chain`` attribute, else the loop name).
    joint_names : tuple of str
        One name per DoF, base to platform. A loop joint with several DoFs contributes
        ``loop[1]``, ``loop[2]`` (universal) or ``loop[x]``, ``loop[y]``, ``loop[z]`` (spherical).
    actuated : tuple of int
        Indices into :attr:`joint_names` of the actuated DoFs.
    prismatic : tuple of bool
        Whether each DoF is prismatic.
    loop_name, loop_type : str
        The closing ``<loop>``.
    geometry : ChainGeometry
        Constant geometry in the base frame.
    tree_joint_ids : tuple of int
        Pinocchio joint ids of the chain's tree joints, base to platform.
    joint_limits : ndarray, shape (m, 2)
        Lower and upper position limit of every DoF (rad or m; -inf/inf where unlimited).
    reference_values : ndarray, shape (m,)
        Joint values of the reference assembly (revolute values wrapped to (-pi, pi]).
    solver : str
        How the chain is closed: ``"planar_rrr"``, ``"planar_rpr"``, ``"ups"``, ``"rus"``
        (closed forms) or ``"newton"``.
    solver_reason : str
        Why: the closed form that matched, or why none did.
    branch : tuple of int or int or None
        The working mode of the reference assembly: the +-1 signs of a closed-form chain, the
        sign of the chain's twist-matrix determinant for a Newton chain (None if it is not
        square or is singular there).
    closed_form : object or None
        The closed-form solver instance (:mod:`screwkit.closure.analytic`), if any.
    reference_sign : int or None
        Sign of the chain's twist-matrix determinant at the reference assembly (the working
        mode Newton keeps when it solves a closed-form chain for a check); None if not square.
    """

    name: str
    joint_names: tuple[str, ...]
    actuated: tuple[int, ...]
    prismatic: tuple[bool, ...]
    loop_name: str
    loop_type: str
    geometry: ChainGeometry
    tree_joint_ids: tuple[int, ...]
    joint_limits: NDArray[np.float64] = field(repr=False, default=None)
    reference_values: NDArray[np.float64] = field(repr=False, default=None)
    solver: str = "newton"
    solver_reason: str = ""
    branch: Any = None
    closed_form: Any = field(repr=False, default=None)
    reference_sign: Any = None

    @property
    def n_joints(self) -> int:
        """Number of DoFs m of the chain."""
        return len(self.joint_names)
