"""The platform's motion space, and the working coordinates every index is computed in.

:func:`working_coordinates` expresses a configuration about the centroid of its platform joints
with lengths in units of its characteristic length (the RMS distance of its joint points from
that centroid): every tolerance of the core then compares dimensionless numbers, independent of
the length unit, the scale and the world frame. :func:`motion_space` finds the platform's DOF and,
when it is the same everywhere, one basis of its motion space. Only numpy is imported here.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np
from numpy.typing import NDArray

from screwkit.common import tolerances
from screwkit.screw.chain_screws import ChainScrews

__all__ = ["MotionSpace", "motion_space", "null_spaces", "motion_bases", "chain_decompositions",
           "chain_projector_complements", "working_coordinates", "sampled_working_coordinates"]


@dataclass(frozen=True)
class MotionSpace:
    """The platform's motion space found on sample configurations.

    Attributes
    ----------
    dof : int
        Degrees of freedom ``n`` of the platform.
    constant_basis : ndarray, shape (n, 6) or None
        Orthonormal basis (rows) of the motion space when it was the same at every sample
        (planar mechanisms, 6-DoF legs); ``None`` otherwise. In the working coordinates of each
        configuration (twists about the centroid of the platform joints, ``(omega, v / L)``,
        see :func:`analyze`): a constant space is the same space in those coordinates at
        every configuration.
    """

    dof: int
    constant_basis: NDArray[np.float64] | None

    @property
    def complement(self) -> NDArray[np.float64]:
        """Orthonormal rows spanning the Euclidean complement of :attr:`constant_basis`."""
        if self.constant_basis is None:
            raise ValueError("The motion space is not constant; it has no fixed complement.")
        _, _, right = np.linalg.svd(self.constant_basis)
        return np.ascontiguousarray(right[self.dof:])


def chain_decompositions(twists: list[NDArray[np.float64]]) -> list[tuple[NDArray, NDArray]]:
    """Per chain, the singular values (K, 6) and right singular vectors (K, 6, 6) of its joint twists.

    The twists (K, m, 6) of each chain, in working coordinates, are scaled to unit norm (a
    scaling of the rows: the same span, so that relative rank decisions compare dimensionless
    singular values whatever the joint types) and padded with zero rows to six: the last rows of
    the right singular vectors then span the twists' Euclidean complement whatever ``m``. One
    decomposition serves the motion space (:func:`chain_projector_complements`) and the chain's
    constraint wrenches (:func:`screwkit.screw.constraints.chain_constraint_wrenches`).
    """
    decompositions = []
    for chain_twists in twists:
        norms = np.linalg.norm(chain_twists, axis=-1, keepdims=True)
        rows = chain_twists / np.where(norms > 0.0, norms, 1.0)
        padding = max(0, 6 - rows.shape[-2])
        if padding:
            rows = np.concatenate([rows, np.zeros(rows.shape[:-2] + (padding, 6))], axis=-2)
        _, singular, right = np.linalg.svd(rows)
        decompositions.append((singular[..., :6], right))
    return decompositions


def chain_projector_complements(twists: list[NDArray[np.float64]], tolerance: float,
                                decompositions: list | None = None) -> NDArray[np.float64]:
    """Sum over chains of ``I - P_chain`` for twists given as a list of (K, m, 6) arrays.

    ``I - P_chain`` projects on the Euclidean complement of the span of the chain's twists: the
    right singular vectors of :func:`chain_decompositions` whose singular values are at most
    ``tolerance`` times the largest (passed in as ``decompositions`` when already computed).
    """
    if decompositions is None:
        decompositions = chain_decompositions(twists)
    total = np.zeros((decompositions[0][0].shape[0], 6, 6))
    for singular, right in decompositions:
        rows = _complement_rows(singular, right, tolerance)
        total += np.swapaxes(rows, -1, -2) @ rows
    return total


def _complement_rows(singular: NDArray, right: NDArray, tolerance: float) -> NDArray:
    """A chain's right singular vectors (K, 6, 6) spanning its twists' Euclidean complement, the others zeroed: those
    whose singular values are at most ``tolerance`` times the largest."""
    return right * (singular <= tolerance * singular[..., :1])[..., :, None]


def null_spaces(chain_twists: list[NDArray[np.float64]], dof: int | None, tolerance: float,
                decompositions: list | None = None):
    """Per-configuration motion spaces: eigen-decomposition of sum_i (I - P_i) (working coordinates)."""
    if decompositions is None:
        decompositions = chain_decompositions(chain_twists)
    values, vectors = np.linalg.eigh(chain_projector_complements(chain_twists, tolerance, decompositions))
    return motion_bases(values, vectors, dof, decompositions, tolerance)


def motion_bases(values: NDArray, vectors: NDArray, dof: int | None, decompositions: list | None = None,
                 tolerance: float = tolerances.MOTION_SPACE_TOLERANCE):
    """Per-configuration motion spaces from the eigenvalues (K, 6), ascending, and eigenvectors (K, 6, 6) of
    sum_i (I - P_i): their dimensions (eigenvalues at most ``MOTION_SPACE_EIGENVALUE``) and bases (K, n, 6), n
    ``dof`` or else the largest dimension.

    Where the eigenvalue after the ``n`` smallest is at most :data:`~screwkit.common.tolerances.
    EIGENVALUE_RESOLUTION`, the eigenvectors mix the motion space with the twists the chains nearly allow (a pose
    near a constraint singularity: three U-P-U legs' couples 1e-8 from parallel); those configurations take the
    ``n`` least singular directions of the chains' stacked complements (``decompositions``, from
    :func:`chain_decompositions`, ``tolerance`` as :func:`chain_projector_complements` takes it) instead: the same
    space where the eigenvectors resolve it."""
    dims = np.sum(values <= tolerances.MOTION_SPACE_EIGENVALUE, axis=-1)
    count = int(dims.max()) if dof is None else dof
    bases = np.swapaxes(vectors[..., :count], -1, -2)
    if decompositions is None or count >= 6:
        return dims, bases
    unresolved = np.flatnonzero(values[:, count] <= tolerances.EIGENVALUE_RESOLUTION)
    if unresolved.size:
        rows = np.concatenate([_complement_rows(singular[unresolved], right[unresolved], tolerance)
                               for singular, right in decompositions], axis=-2)
        bases = np.array(bases)
        bases[unresolved] = np.linalg.svd(rows)[2][:, 6 - count:]
    return dims, bases


def working_coordinates(twists: list[NDArray], points: list[NDArray]):
    """Batch-first twists (N, m, 6) and points (N, m, 3) of every chain in working coordinates.

    About the centroid ``c`` of the platform joints (the last joint of every chain) with lengths
    in units of ``L``, the RMS distance of every joint point from ``c``: a twist becomes
    ``(omega, (v + omega x c) / L)`` and a point ``(p - c) / L``. Every Euclidean norm and
    tolerance downstream is then invariant to the length unit, the scale of the mechanism and
    the world frame. The compiled kernel computes ``c`` and ``L`` by the same formulas
    (a configuration whose joint points all coincide gets ``L = 1``).

    Returns
    -------
    twists, points : lists of arrays as given, in working coordinates
    centre : ndarray (N, 3)
    length : ndarray (N,)
    """
    centre = np.mean([chain_points[:, -1] for chain_points in points], axis=0)  # (N, 3)
    relative = [chain_points - centre[:, None] for chain_points in points]
    joints = sum(chain_points.shape[1] for chain_points in points)
    length = np.sqrt(sum(np.einsum("nmk,nmk->n", r, r) for r in relative) / joints)
    length = np.where(length > 0.0, length, 1.0)
    scale = 1.0 / length[:, None, None]
    moved = [np.concatenate([t[..., :3], (t[..., 3:] + np.cross(t[..., :3], centre[:, None])) * scale], axis=-1)
             for t in twists]
    return moved, [r * scale for r in relative], centre, length


def sampled_working_coordinates(chains: Sequence[ChainScrews], samples: int = 9):
    """:func:`working_coordinates` of up to ``samples`` configurations spread evenly over the chains' batch.

    Returns
    -------
    index : ndarray of int
        The sampled configurations (flat indices into the batch).
    twists, points, centre, length :
        As :func:`working_coordinates` returns them, for those configurations.
    """
    flat = [chain.twists.reshape((-1,) + chain.twists.shape[-2:]) for chain in chains]
    flat_points = [chain.points.reshape((-1,) + chain.points.shape[-2:]) for chain in chains]
    count = flat[0].shape[0]
    index = np.unique(np.linspace(0, count - 1, min(count, samples)).round().astype(int)) if count else np.arange(0)
    return (index,) + working_coordinates([twists[index] for twists in flat], [points[index] for points in flat_points])


def motion_space(chains: Sequence[ChainScrews], dof: int | None = None, samples: int = 9,
                 tolerance: float = tolerances.MOTION_SPACE_TOLERANCE) -> MotionSpace:
    r"""Find the platform's DOF and, if it is constant, its motion space.

    The motion space is the intersection of the chains' twist spaces,
    :math:`\mathcal{M} = \bigcap_i \mathrm{span}(J_i)`, i.e. the null space of
    :math:`\sum_i (I - P_i)` with :math:`P_i` the orthogonal projector on the span of chain
    ``i``'s joint twists. It is evaluated on ``samples`` configurations spread over the
    batch; the DOF is the largest dimension found (a singular sample can only lose
    mobility). Every sample is in its working coordinates (about the centroid of its platform
    joints, lengths in units of its characteristic length, as in :func:`analyze`), so that the
    rank decisions do not depend on the length unit, the scale or the world frame. Not a hot
    path: a few SVDs.

    Parameters
    ----------
    chains : sequence of ChainScrews
    dof : int, optional
        Impose the DOF instead of deriving it.
    samples : int
        Number of configurations to sample.
    tolerance : float
        Relative rank tolerance of the chains' twist systems (each twist scaled to unit norm).

    Returns
    -------
    MotionSpace
    """
    if dof is not None and (not isinstance(dof, (int, np.integer)) or not 1 <= dof <= 6):
        raise ValueError(f"Expected `dof` in 1..6, got {dof!r}.")
    if dof == 6:  # every twist: the same space in any coordinates, nothing to sample
        return MotionSpace(6, np.eye(6))
    _, working, _, _, _ = sampled_working_coordinates(chains, samples)
    dims, bases = null_spaces(working, dof, tolerance)
    found = int(dims.max()) if dof is None else dof
    if found == 0:
        raise ValueError("The platform has no mobility: the chains' twist spaces intersect only in zero.")
    generic = np.flatnonzero(dims == found)
    if generic.size == 0:
        return MotionSpace(found, None)
    candidate = np.ascontiguousarray(bases[generic[0]])
    for sample in generic[1:]:
        residual = bases[sample] - bases[sample] @ candidate.T @ candidate
        if np.abs(residual).max() > tolerances.CONSTANT_BASIS_TOLERANCE:
            return MotionSpace(found, None)
    return MotionSpace(found, candidate)

