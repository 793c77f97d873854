"""Point outputs: a platform whose output is a point, its rotations about that point idle.

When the output of a mechanism is a point (a five-bar's end effector, a tool point), the
rotations of the platform about that point do not matter and no actuator controls them: every
chain ends in joints about the point, so those rotations are *idle* degrees of freedom. The
indices of a point output are those of the quotient: the motion space modulo the idle
rotations, actuation wrenches reciprocal to them (forces through the point), output twists taken
in a complement of them. :func:`idle_rotations` gives the idle twists of a point;
:func:`with_idle_joints` adds them to the chains that lack them; :func:`quotient_bases` removes
them from motion-space bases. Only numpy is imported here.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.common.tolerances import MOTION_SPACE_TOLERANCE
from screwkit.screw.chain_screws import ChainScrews

__all__ = ["idle_rotations", "with_idle_joints", "quotient_bases"]


def idle_rotations(points: ArrayLike, planar) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Unit rotations about a point (..., 3): about the plane's normal only for a planar mechanism, else
    about x, y, z.

    ``planar`` is False (spatial), True (the plane's normal is z) or the plane's normal (3,), in the
    frame of the points: a planar mechanism placed in a tilted world frame turns about its own normal.

    Returns
    -------
    twists : ndarray (..., r, 6)
    points : ndarray (..., r, 3)
    """
    points = np.asarray(points, dtype=float)
    if isinstance(planar, (bool, np.bool_)):
        axes = np.array([[0.0, 0.0, 1.0]]) if planar else np.eye(3)
    else:
        normal = np.asarray(planar, dtype=float).reshape(-1)
        length = float(np.linalg.norm(normal)) if normal.shape == (3,) and np.all(np.isfinite(normal)) else 0.0
        if length == 0.0:
            raise ValueError(f"Expected `planar` True, False or a plane normal of 3 finite numbers, not all 0; "
                             f"got {planar!r}.")
        axes = (normal / length)[None]
    axes = np.broadcast_to(axes, points.shape[:-1] + axes.shape)
    where = np.broadcast_to(points[..., None, :], axes.shape)
    return np.concatenate([axes, np.cross(where, axes)], axis=-1), np.array(where)


def _working(twists: NDArray, centre: NDArray, length: NDArray) -> NDArray:
    """Twists (N, k, 6) about ``centre`` (N, 3) with lengths in units of ``length`` (N,)."""
    moved = twists[..., 3:] + np.cross(twists[..., :3], centre[:, None, :])
    return np.concatenate([twists[..., :3], moved / length[:, None, None]], axis=-1)


def with_idle_joints(chains: list[ChainScrews], idle_twists: NDArray, idle_points: NDArray,
                     centre: NDArray, length: NDArray, samples: NDArray) -> list[ChainScrews]:
    """Every chain with the idle rotations it cannot already perform appended as passive joints.

    Whether a chain already performs an idle twist is decided on the ``samples`` configurations,
    in working coordinates (``centre``, ``length`` of those samples). Chains ending in joints
    about the point (the usual case) get nothing; the others get the missing rotations, so that
    their actuation wrenches are reciprocal to every idle twist (forces through the point).
    """
    result = []
    idle_working = _working(idle_twists[samples], centre, length)
    for chain in chains:
        flat = chain.twists.reshape((-1,) + chain.twists.shape[-2:])[samples]
        chain_working = _working(flat, centre, length)
        norms = np.linalg.norm(chain_working, axis=-1, keepdims=True)
        columns = chain_working / np.where(norms > 0, norms, 1.0)
        left, singular, _ = np.linalg.svd(np.swapaxes(columns, -1, -2), full_matrices=False)
        basis = left * (singular > MOTION_SPACE_TOLERANCE * singular[..., :1])[..., None, :]
        projected = idle_working - np.einsum("nij,nkj,nlk->nli", basis, basis, idle_working)
        outside = np.linalg.norm(projected, axis=-1) > 1e-6 * np.linalg.norm(idle_working, axis=-1)
        missing = np.flatnonzero(outside.any(axis=0))
        if missing.size == 0:
            result.append(chain)
            continue
        shape = chain.batch_shape
        extra_twists = idle_twists[:, missing].reshape(shape + (missing.size, 6))
        extra_points = idle_points[:, missing].reshape(shape + (missing.size, 3))
        names = chain.joint_names + tuple(f"idle[{k}]" for k in missing)
        result.append(ChainScrews(np.concatenate([chain.twists, extra_twists], axis=-2),
                                  np.concatenate([chain.points, extra_points], axis=-2), chain.actuated,
                                  chain.name, joint_names=names))
    return result


def quotient_bases(bases: NDArray, idle_twists: NDArray, centre: NDArray, length: NDArray, dof: int) -> NDArray:
    """Orthonormal bases (N, dof, 6) of motion spaces (N, dof + r, 6) modulo idle twists (N, r, 6) (world frame).

    Both in working coordinates: the idle twists are moved there with ``centre`` and ``length``;
    the result is the part of each motion space orthogonal to its idle twists.
    """
    idle = _working(idle_twists, centre, length)
    q, _ = np.linalg.qr(np.swapaxes(idle, -1, -2))  # (N, 6, r) orthonormal columns
    projected = bases - (bases @ q) @ np.swapaxes(q, -1, -2)
    _, _, right = np.linalg.svd(projected, full_matrices=False)
    return np.ascontiguousarray(right[:, :dof])
