"""Screw algebra on plain arrays, batched on leading axes.

Conventions (written down once, used everywhere in screwkit):

* a **twist** is ``(omega, v)``: angular velocity, then the velocity of the point at
  the origin of the frame the twist is expressed in;
* a **wrench** is ``(f, m)``: force, then the moment about the origin;
* every function takes arrays of shape ``(..., 6)`` (or ``(..., 3)`` for points) and
  returns arrays with the same leading batch shape: one screw in, a scalar out;
  ``(N, 6)`` in, ``(N,)`` out.

Only numpy is imported here.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.common.tolerances import AXIS_PARALLEL, PURE_COUPLE, SAME_POINT, SINGULARITY_THRESHOLD, ZERO_PITCH
from screwkit.common.validation import as_float_array, check_finite, check_shape

__all__ = [
    "SWAP",
    "reciprocal_product",
    "pitch",
    "axis_point",
    "project_on_axis",
    "nearest_on_axis",
    "joint_lines",
    "shift_twist",
    "shift_wrench",
    "adjoint",
    "transform_twist",
    "transform_wrench",
    "reciprocal_complement",
    "max_reciprocal_product",
    "power_coefficient",
]

#: The 6x6 swap of the two 3-vector halves: ``s1 o s2 = s1 @ SWAP @ s2``.
SWAP: NDArray[np.float64] = np.block([[np.zeros((3, 3)), np.eye(3)], [np.eye(3), np.zeros((3, 3))]])


def _screws(value: ArrayLike, name: str) -> NDArray[np.float64]:
    return check_finite(check_shape(as_float_array(value, name), (6,), name), name)


def _points(value: ArrayLike, name: str) -> NDArray[np.float64]:
    return check_finite(check_shape(as_float_array(value, name), (3,), name), name)


def reciprocal_product(screw_1: ArrayLike, screw_2: ArrayLike) -> NDArray[np.float64]:
    r"""Reciprocal product of two screws (Eq. 1).

    .. math:: \$_1 \circ \$_2 = \mathbf{s}_1 \cdot \mathbf{s}_{O2} + \mathbf{s}_{O1} \cdot \mathbf{s}_2

    For a wrench and a twist it is the instantaneous power of the wrench on the twist.

    Parameters
    ----------
    screw_1, screw_2 : array_like, shape (..., 6)
        Screws ordered (direction part, moment part); batch shapes broadcast.

    Returns
    -------
    ndarray, shape (...)

    Examples
    --------
    A force along the x axis and a rotation about z through (-2, 0, 0), whose axes meet: no work.

    >>> float(reciprocal_product([1, 0, 0, 0, 0, 0], [0, 0, 1, 0, 2, 0]))
    0.0
    >>> float(reciprocal_product([1, 0, 0, 0, 0, 0], [0, 0, 1, 2, 0, 0]))
    2.0
    """
    first = _screws(screw_1, "screw_1")
    second = _screws(screw_2, "screw_2")
    return np.einsum("...i,...i->...", first[..., :3], second[..., 3:]) + np.einsum(
        "...i,...i->...", first[..., 3:], second[..., :3]
    )


def pitch(screw: ArrayLike) -> NDArray[np.float64]:
    r"""Pitch :math:`h = \mathbf{s} \cdot \mathbf{s}_O / |\mathbf{s}|^2`; ``inf`` for a pure moment/translation.

    Parameters
    ----------
    screw : array_like, shape (..., 6)

    Returns
    -------
    ndarray, shape (...)
    """
    screw = _screws(screw, "screw")
    direction_sq = np.einsum("...i,...i->...", screw[..., :3], screw[..., :3])
    dot = np.einsum("...i,...i->...", screw[..., :3], screw[..., 3:])
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(direction_sq > 0, dot / np.where(direction_sq > 0, direction_sq, 1.0), np.inf)


def axis_point(screw: ArrayLike) -> NDArray[np.float64]:
    r"""Point of the screw axis closest to the origin, :math:`\mathbf{s} \times \mathbf{s}_O / |\mathbf{s}|^2`.

    For a screw of infinite pitch (no axis) the origin is returned.

    Parameters
    ----------
    screw : array_like, shape (..., 6)

    Returns
    -------
    ndarray, shape (..., 3)
    """
    screw = _screws(screw, "screw")
    direction = screw[..., :3]
    direction_sq = np.einsum("...i,...i->...", direction, direction)[..., None]
    safe = np.where(direction_sq > 0, direction_sq, 1.0)
    return np.where(direction_sq > 0, np.cross(direction, screw[..., 3:]) / safe, 0.0)


def project_on_axis(screw: ArrayLike, point: ArrayLike) -> NDArray[np.float64]:
    """Orthogonal projection of ``point`` onto the axis of ``screw`` (the point itself if it has no axis).

    Parameters
    ----------
    screw : array_like, shape (..., 6)
    point : array_like, shape (..., 3)

    Returns
    -------
    ndarray, shape (..., 3)
    """
    screw = _screws(screw, "screw")
    point = _points(point, "point")
    direction = screw[..., :3]
    norm_sq = np.einsum("...i,...i->...", direction, direction)[..., None]
    safe = np.where(norm_sq > 0, norm_sq, 1.0)
    foot = np.cross(direction, screw[..., 3:]) / safe
    along = np.einsum("...i,...i->...", point - foot, direction)[..., None] / safe
    return np.where(norm_sq > 0, foot + along * direction, point)


def nearest_on_axis(screw: ArrayLike, point: ArrayLike, direction: ArrayLike, length: float = 1.0
                    ) -> NDArray[np.float64]:
    """A joint's characteristic point on a force, independent of where along its axis the joint is drawn: the point
    of the axis of ``screw`` nearest to the line through ``point`` along ``direction``.

    For a revolute joint (``direction`` its axis) and a force reciprocal to it, the point where the force's line
    crosses the joint's axis. The projection of ``point`` (:func:`project_on_axis`) when the screw is not a force
    (its pitch above :data:`~screwkit.common.tolerances.ZERO_PITCH` times ``length``, or no axis), the lines are
    parallel (squared sine at or below :data:`~screwkit.common.tolerances.AXIS_PARALLEL`) or ``direction`` is zero
    (a prismatic joint: its point is the one drawn). ``point`` itself for a pure couple (``|f| length`` at most
    :data:`~screwkit.common.tolerances.PURE_COUPLE` times its moment about ``point``, the test of
    :func:`power_coefficient`).

    Parameters
    ----------
    screw : array_like, shape (..., 6)
    point, direction : array_like, shape (..., 3)
    length : float
        The characteristic length the pitch is measured against (1 in working coordinates).

    Returns
    -------
    ndarray, shape (..., 3)
    """
    screw = _screws(screw, "screw")
    point = _points(point, "point")
    direction = _points(direction, "direction")
    projected = project_on_axis(screw, point)
    force = screw[..., :3]
    force_sq = np.einsum("...i,...i->...", force, force)[..., None]
    direction_sq = np.einsum("...i,...i->...", direction, direction)[..., None]
    unit_force = force / np.sqrt(np.where(force_sq > 0, force_sq, 1.0))
    unit = direction / np.sqrt(np.where(direction_sq > 0, direction_sq, 1.0))
    cosine = np.einsum("...i,...i->...", unit_force, unit)[..., None]
    sine_sq = 1.0 - cosine * cosine
    crossing = np.where(sine_sq > AXIS_PARALLEL, sine_sq, 1.0)
    # projected + t f is nearest to point + s u: t = (f.u)(u.(projected - point)) / (1 - (f.u)^2)
    along = cosine * np.einsum("...i,...i->...", unit, projected - point)[..., None] / crossing
    dot = np.einsum("...i,...i->...", force, screw[..., 3:])[..., None]
    force_like = np.abs(dot) <= ZERO_PITCH * length * force_sq
    use = (force_sq > 0) & force_like & (direction_sq > 0) & (sine_sq > AXIS_PARALLEL)
    # a pure couple (as power_coefficient tests it, about ``point``) has no axis: the rounding left in its force
    # would put one about |m| / |f| away (1e11 lengths for a constraint couple found by a singular value
    # decomposition), and the moment about that point mistake the couple for a force of huge pitch
    moment = screw[..., 3:] - np.cross(point, force)
    couple = force_sq * length**2 <= PURE_COUPLE**2 * np.einsum("...i,...i->...", moment, moment)[..., None]
    return np.where(couple, point, np.where(use, projected + along * unit_force, projected))


def joint_lines(twists: ArrayLike, points: ArrayLike, joint: int) -> NDArray[np.float64]:
    """The direction along which joint ``joint`` of a chain may be drawn anywhere: its axis, for
    :func:`nearest_on_axis`; zero for a prismatic joint and for a joint drawn at the same point as a neighbour in
    the chain with another axis (a universal or ball joint written as revolutes, whose point is that point).

    Parameters
    ----------
    twists : array_like, shape (..., m, 6)
    points : array_like, shape (..., m, 3)
        The chain's joint twists and points in working coordinates (the same point: at most
        :data:`~screwkit.common.tolerances.SAME_POINT` apart; another axis: squared sine above
        :data:`~screwkit.common.tolerances.AXIS_PARALLEL`).
    joint : int

    Returns
    -------
    ndarray, shape (..., 3)
    """
    twists, points = np.asarray(twists, dtype=float), np.asarray(points, dtype=float)
    count = twists.shape[-2]
    joint = joint % count
    axis = twists[..., joint, :3]
    point = np.ones(axis.shape[:-1], dtype=bool)
    for other in (joint - 1, joint + 1):
        if 0 <= other < count:
            neighbour = twists[..., other, :3]
            gap = np.linalg.norm(points[..., other, :] - points[..., joint, :], axis=-1)
            sine_sq = np.sum(np.cross(axis, neighbour) ** 2, axis=-1)
            crossing = sine_sq > AXIS_PARALLEL * np.sum(axis * axis, -1) * np.sum(neighbour * neighbour, -1)
            point &= ~((gap <= SAME_POINT) & crossing)
    return np.where(point[..., None], axis, 0.0)


def _shift(screw: NDArray, point: NDArray) -> NDArray[np.float64]:
    """(s, s_O + s x p): the moment part of a screw taken about ``point``."""
    direction = screw[..., :3]
    return np.concatenate([np.broadcast_to(direction, np.broadcast_shapes(direction.shape, point.shape)),
                           screw[..., 3:] + np.cross(direction, point)], axis=-1)


def shift_twist(twist: ArrayLike, point: ArrayLike) -> NDArray[np.float64]:
    r"""Express a twist about ``point``: :math:`(\omega, v + \omega \times p)` (the velocity of ``point``)."""
    return _shift(_screws(twist, "twist"), _points(point, "point"))


def shift_wrench(wrench: ArrayLike, point: ArrayLike) -> NDArray[np.float64]:
    r"""Express a wrench about ``point``: :math:`(f, m - p \times f)` (the moment about ``point``)."""
    return _shift(_screws(wrench, "wrench"), _points(point, "point"))


def adjoint(rotation: ArrayLike, translation: ArrayLike) -> NDArray[np.float64]:
    r"""Adjoint of the rigid transform :math:`(R, p)` acting on twists ordered (omega, v).

    .. math:: \mathrm{Ad} = \begin{bmatrix} R & 0 \\ [p]_\times R & R \end{bmatrix}

    Wrenches ordered (f, m) transform with the same matrix (a force moves like an
    angular velocity and a moment like a linear velocity).

    Parameters
    ----------
    rotation : array_like, shape (..., 3, 3)
    translation : array_like, shape (..., 3)

    Returns
    -------
    ndarray, shape (..., 6, 6)
    """
    rotation = check_finite(check_shape(as_float_array(rotation, "rotation"), (3, 3), "rotation"), "rotation")
    translation = _points(translation, "translation")
    batch = np.broadcast_shapes(rotation.shape[:-2], translation.shape[:-1])
    rotation = np.broadcast_to(rotation, batch + (3, 3))
    translation = np.broadcast_to(translation, batch + (3,))
    skew = np.zeros(batch + (3, 3))
    skew[..., 0, 1], skew[..., 0, 2] = -translation[..., 2], translation[..., 1]
    skew[..., 1, 0], skew[..., 1, 2] = translation[..., 2], -translation[..., 0]
    skew[..., 2, 0], skew[..., 2, 1] = -translation[..., 1], translation[..., 0]
    result = np.zeros(batch + (6, 6))
    result[..., :3, :3] = rotation
    result[..., 3:, 3:] = rotation
    result[..., 3:, :3] = skew @ rotation
    return result


def transform_twist(rotation: ArrayLike, translation: ArrayLike, twist: ArrayLike) -> NDArray[np.float64]:
    """Apply the rigid transform ``(rotation, translation)`` to twists, shape (..., 6)."""
    return np.einsum("...ij,...j->...i", adjoint(rotation, translation), _screws(twist, "twist"))


def transform_wrench(rotation: ArrayLike, translation: ArrayLike, wrench: ArrayLike) -> NDArray[np.float64]:
    """Apply the rigid transform ``(rotation, translation)`` to wrenches ordered (f, m), shape (..., 6)."""
    return np.einsum("...ij,...j->...i", adjoint(rotation, translation), _screws(wrench, "wrench"))


def reciprocal_complement(screws: ArrayLike, tolerance: float = 1e-9) -> list[NDArray[np.float64]]:
    r"""Basis of the screws reciprocal to every screw of a system (rank revealing).

    The reciprocal complement of the system spanned by the rows of ``screws`` is the null
    space of ``screws @ SWAP``. It is computed by an SVD; singular values at or below
    ``tolerance * max(1, largest singular value)`` count as zero. Its dimension is
    ``6 - rank``.

    Not for hot paths: the indices use closed-form complements (see
    :mod:`screwkit.indices.analysis`).

    Parameters
    ----------
    screws : array_like, shape (..., k, 6)
        The ``k`` screws spanning the system.
    tolerance : float
        Relative rank tolerance.

    Returns
    -------
    list of ndarray
        For each configuration of the flattened batch, an array of shape (6 - rank, 6)
        of orthonormal (in the Euclidean sense of the given coordinates) reciprocal screws.
    """
    screws = check_finite(check_shape(as_float_array(screws, "screws"), (None, 6), "screws"), "screws")
    if not tolerance > 0:
        raise ValueError(f"Expected `tolerance` > 0, got {tolerance}.")
    flat = screws.reshape((-1,) + screws.shape[-2:])
    _, singular, right = np.linalg.svd(flat @ SWAP, full_matrices=True)
    result = []
    for values, vectors in zip(singular, right):
        rank = int(np.sum(values > tolerance * max(1.0, values[0] if values.size else 1.0)))
        result.append(vectors[rank:].copy())
    return result


def _length(length) -> float:
    if not (isinstance(length, (int, float, np.floating, np.integer)) and np.isfinite(length) and length > 0):
        raise ValueError(f"Expected `length` > 0 (a length in the unit of the screws), got {length!r}.")
    return float(length)


def max_reciprocal_product(wrench: ArrayLike, twist: ArrayLike, point: ArrayLike, *,
                           length: float = 1.0) -> NDArray[np.float64]:
    r"""Local maximum of :math:`|A \circ T|` over all rotations of the wrench about ``point`` (Eq. 5).

    For a wrench of force :math:`f`, pitch :math:`h` applied at its characteristic point
    :math:`p`, and a twist :math:`(\omega, v)`:

    .. math:: |A \circ T|_{\max} = |f| \, \| v + \omega \times p + h\,\omega \|

    which for unit screws equals :math:`\sqrt{(h_1 + h_2)^2 + \rho_{\max}^2}`. A twist
    at infinity (:math:`\omega = 0`) needs no special case. A pure moment (infinite
    pitch wrench) gives :math:`|m|\,|\omega|`; the wrench counts as one when
    :math:`|f|\,\ell \le` ``PURE_COUPLE`` :math:`|m_p|` (see :func:`power_coefficient`).

    Parameters
    ----------
    wrench, twist : array_like, shape (..., 6)
    point : array_like, shape (..., 3)
    length : float
        Characteristic length :math:`\ell` of the pure-couple test, in the unit of the screws.

    Returns
    -------
    ndarray, shape (...)
    """
    wrench = _screws(wrench, "wrench")
    twist = _screws(twist, "twist")
    point = _points(point, "point")
    arm, _, scale = _moment_arm(wrench, twist, point, _length(length))
    return arm * scale


def _moment_arm(wrench, twist, point, length):
    """Return ``(|v_p + h omega|, |omega|, |f|)``; for a pure couple ``(|omega|, 0, |m|)``.

    The wrench is a pure couple when ``|f| * length <= PURE_COUPLE * |m_p|``, ``m_p`` its moment
    about ``point``: the test of the compiled kernel (which takes the moment about the centroid
    of the platform joints and ``length = L``), dimensionless and frame free.
    """
    force, moment = wrench[..., :3], wrench[..., 3:]
    omega, velocity = twist[..., :3], twist[..., 3:]
    force_sq = np.einsum("...i,...i->...", force, force)
    moment_about_point = moment - np.cross(point, force)
    moment_sq = np.einsum("...i,...i->...", moment_about_point, moment_about_point)
    has_force = (force_sq * length**2 > PURE_COUPLE**2 * moment_sq) & (force_sq > 0)
    safe = np.where(has_force, force_sq, 1.0)
    wrench_pitch = np.where(has_force, np.einsum("...i,...i->...", force, moment) / safe, 0.0)
    arm_vector = velocity + np.cross(omega, point) + wrench_pitch[..., None] * omega
    omega_norm = np.linalg.norm(omega, axis=-1)
    arm = np.where(has_force, np.linalg.norm(arm_vector, axis=-1), omega_norm)
    reference = np.where(has_force, omega_norm, 0.0)
    scale = np.where(has_force, np.sqrt(force_sq), np.linalg.norm(moment, axis=-1))
    return arm, reference, scale


def power_coefficient(
    wrench: ArrayLike, twist: ArrayLike, point: ArrayLike, threshold: float = SINGULARITY_THRESHOLD, *,
    length: float = 1.0,
) -> NDArray[np.float64]:
    r"""Power coefficient of a wrench on a twist with the local maximum of the moment arm (Eqs. 4-5).

    .. math:: PC = \frac{|A \circ T|}{|A \circ T|_{\max}}

    with :math:`|A \circ T|_{\max}` from :func:`max_reciprocal_product`. Scale free in
    both screws. By definition (the paper, Sec. 4) the coefficient is **zero** when the
    local moment arm :math:`\| v + \omega \times p + h \omega \| / |\omega|` is at or
    below ``threshold`` (the singularity threshold *p*, default 1 um), which also
    covers a zero twist or a zero wrench.

    The wrench is a **pure couple** (infinite pitch) when

    .. math:: |f|\,\ell \le \varepsilon\,|m_p|

    with :math:`m_p` its moment about ``point``, :math:`\ell` = ``length`` and
    :math:`\varepsilon` = :data:`screwkit.common.tolerances.PURE_COUPLE`: the test
    :func:`screwkit.indices.analysis.analyze` applies with the characteristic length ``L`` of the
    configuration (moment about the centroid of the platform joints, which differs from
    :math:`m_p` by :math:`|f|` times a distance of order ``L``, immaterial at this tolerance).
    ``threshold`` and ``length`` are the only lengths: with both scaled with the screws, the
    result does not depend on the length unit or the scale, and it never depends on the frame.

    Parameters
    ----------
    wrench : array_like, shape (..., 6)
        Wrench (f, m).
    twist : array_like, shape (..., 6)
        Twist (omega, v).
    point : array_like, shape (..., 3)
        Characteristic point of the wrench (where it is rotated).
    threshold : float
        Singularity threshold on the moment arm, in length units (>= 0).
    length : float
        Characteristic length of the mechanism (> 0, same unit), for the pure-couple test;
        default 1, e.g. 1 m for screws in metres.

    Returns
    -------
    ndarray, shape (...), values in [0, 1]
    """
    wrench = _screws(wrench, "wrench")
    twist = _screws(twist, "twist")
    point = _points(point, "point")
    if not threshold >= 0:
        raise ValueError(f"Expected `threshold` >= 0, got {threshold}.")
    arm, omega_norm, scale = _moment_arm(wrench, twist, point, _length(length))
    numerator = np.abs(
        np.einsum("...i,...i->...", wrench[..., :3], twist[..., 3:])
        + np.einsum("...i,...i->...", wrench[..., 3:], twist[..., :3])
    )
    denominator = arm * scale
    singular = (arm <= threshold * omega_norm) | (denominator <= 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        value = numerator / np.where(singular, 1.0, denominator)
    return np.where(singular, 0.0, np.minimum(value, 1.0))
