"""Screw algebra: reciprocal product, pitch, axis, adjoint, complement, power coefficient."""

from __future__ import annotations

import numpy as np
import pytest

from helpers import random_rotation
from screwkit.screw import algebra as screws


def random_screws(rng, count):
    return rng.normal(size=(count, 6))


def test_reciprocal_product_is_invariant_under_the_adjoint(rng):
    first, second = random_screws(rng, 500), random_screws(rng, 500)
    rotations = np.stack([random_rotation(rng) for _ in range(500)])
    translations = rng.uniform(-10, 10, (500, 3))
    moved_first = screws.transform_twist(rotations, translations, first)
    moved_second = screws.transform_wrench(rotations, translations, second)
    np.testing.assert_allclose(screws.reciprocal_product(moved_first, moved_second),
                               screws.reciprocal_product(first, second), atol=1e-9)


def test_reciprocal_product_equals_eq_2(rng):
    """(h1 + h2) cos(v) - rho sin(v) for unit screws with finite pitch, with signed common-normal geometry."""
    for _ in range(200):
        axis_1, axis_2 = rng.normal(size=3), rng.normal(size=3)
        axis_1 /= np.linalg.norm(axis_1)
        axis_2 /= np.linalg.norm(axis_2)
        point_1, point_2 = rng.normal(size=3), rng.normal(size=3)
        pitch_1, pitch_2 = rng.normal(size=2)
        s1 = np.concatenate([axis_1, np.cross(point_1, axis_1) + pitch_1 * axis_1])
        s2 = np.concatenate([axis_2, np.cross(point_2, axis_2) + pitch_2 * axis_2])
        normal = np.cross(axis_1, axis_2)
        sin_v = np.linalg.norm(normal)
        normal /= sin_v
        rho = np.dot(point_2 - point_1, normal)  # signed length of the common perpendicular
        expected = (pitch_1 + pitch_2) * np.dot(axis_1, axis_2) - rho * sin_v
        assert screws.reciprocal_product(s1, s2) == pytest.approx(expected, abs=1e-10)


def test_pitch_and_axis(rng):
    axis = rng.normal(size=(50, 3))
    axis /= np.linalg.norm(axis, axis=-1, keepdims=True)
    point = rng.normal(size=(50, 3))
    pitch = rng.normal(size=50)
    screw = np.concatenate([axis, np.cross(point, axis) + pitch[:, None] * axis], axis=-1)
    np.testing.assert_allclose(screws.pitch(3.0 * screw), pitch, atol=1e-12)
    foot = screws.axis_point(screw)
    # The foot lies on the axis (point + t axis) and is orthogonal to it.
    np.testing.assert_allclose(np.cross(foot - point, axis), 0, atol=1e-12)
    np.testing.assert_allclose(np.einsum("ni,ni->n", foot, axis), 0, atol=1e-12)
    assert screws.pitch([0, 0, 0, 1, 0, 0]) == np.inf
    projected = screws.project_on_axis(screw, point + 2.0 * axis + 0.0)
    np.testing.assert_allclose(projected, point + 2.0 * axis, atol=1e-12)


def test_reciprocal_complement_dimension_and_reciprocity(rng):
    for rank in range(1, 6):
        system = rng.normal(size=(rank, 6))
        system = np.vstack([system, system[:1] * 2.0])  # one dependent screw
        (complement,) = screws.reciprocal_complement(system)
        assert complement.shape == (6 - rank, 6)
        np.testing.assert_allclose(complement @ screws.SWAP @ system.T, 0, atol=1e-10)


def _brute_force_max(wrench, twist, point, samples=200_000, rng=None):
    """Maximise |A' o T| over wrenches A' of the same pitch through `point`, by sampling directions."""
    directions = rng.normal(size=(samples, 3))
    directions /= np.linalg.norm(directions, axis=-1, keepdims=True)
    force = wrench[:3]
    h = np.dot(force, wrench[3:]) / np.dot(force, force)
    rotated = np.concatenate([directions, np.cross(point, directions) + h * directions], axis=-1)
    return np.abs(screws.reciprocal_product(rotated, twist)).max() * np.linalg.norm(force)


def test_max_reciprocal_product_is_the_maximum_over_rotations(rng):
    """Eq. (5): |A o T|_max is the maximum of |A' o T| over all rotations of A about p."""
    for _ in range(5):
        wrench = rng.normal(size=6)
        twist = rng.normal(size=6)
        point = rng.normal(size=3)
        expected = _brute_force_max(wrench, twist, point, rng=rng)
        value = screws.max_reciprocal_product(wrench, twist, point)
        assert expected <= value * (1 + 1e-12)
        assert value == pytest.approx(expected, rel=2e-3)


def test_max_reciprocal_product_equals_eq_5_for_unit_screws(rng):
    """sqrt((h1 + h2)^2 + rho_max^2), rho_max the distance from p to the twist axis."""
    axis = np.array([0.0, 0.0, 1.0])
    centre = np.array([0.3, -0.2, 0.0])
    pitch_twist, pitch_wrench = 0.7, -0.25
    twist = np.concatenate([axis, np.cross(centre, axis) + pitch_twist * axis])
    point = np.array([1.3, 0.8, 0.4])
    force = np.array([0.0, 1.0, 0.0])
    wrench = np.concatenate([force, np.cross(point, force) + pitch_wrench * force])
    rho = np.linalg.norm((point - centre)[:2])
    assert screws.max_reciprocal_product(wrench, twist, point) == pytest.approx(
        np.sqrt((pitch_twist + pitch_wrench) ** 2 + rho**2))


def test_power_coefficient_special_cases():
    force_x_at_origin = np.array([1.0, 0, 0, 0, 0, 0])
    # A pure translation (twist at infinity) needs no special case: the cosine of the angle.
    translation = np.array([0, 0, 0, np.cos(0.3), np.sin(0.3), 0])
    assert screws.power_coefficient(force_x_at_origin, translation, [0, 0, 0]) == pytest.approx(np.cos(0.3))
    # Intersecting zero-pitch screws: zero.
    rotation_about_z = np.array([0, 0, 1.0, 0, 0, 0])
    assert screws.power_coefficient(force_x_at_origin, rotation_about_z, [0, 0, 0]) == 0.0
    # A short moment arm (below the threshold) gives zero; above it the ratio.
    near = np.concatenate([[0, 0, 1.0], np.cross([0, 5e-7, 0], [0, 0, 1.0])])
    assert screws.power_coefficient(force_x_at_origin, near, [0, 0, 0]) == 0.0
    assert screws.power_coefficient(force_x_at_origin, near, [0, 0, 0], threshold=1e-7) == pytest.approx(1.0)
    # A pure couple on a rotation: cosine between the moment and the axis.
    couple = np.array([0, 0, 0, 0, 0, 2.0])
    tilted = np.array([0, np.sin(0.2), np.cos(0.2), 0, 0, 0])
    assert screws.power_coefficient(couple, tilted, [0, 0, 0]) == pytest.approx(np.cos(0.2))
    # Zero twist: zero, not NaN.
    assert screws.power_coefficient(force_x_at_origin, np.zeros(6), [0, 0, 0]) == 0.0


def test_power_coefficient_is_frame_invariant_and_scale_free(rng):
    wrench, twist, point = rng.normal(size=(100, 6)), rng.normal(size=(100, 6)), rng.normal(size=(100, 3))
    value = screws.power_coefficient(wrench, twist, point)
    assert np.all((value >= 0) & (value <= 1))
    rotation, translation = random_rotation(rng), rng.normal(size=3)
    moved = screws.power_coefficient(screws.transform_wrench(rotation, translation, 3 * wrench),
                                     screws.transform_twist(rotation, translation, 0.5 * twist),
                                     point @ rotation.T + translation)
    np.testing.assert_allclose(moved, value, atol=1e-12)


@pytest.mark.parametrize("call, message", [
    (lambda: screws.reciprocal_product(np.zeros((3, 5)), np.zeros(6)),
     r"`screw_1` with shape \(\.\.\., 6\), got \(3, 5\)"),
    (lambda: screws.reciprocal_product(np.zeros(6), [0, 0, np.nan, 0, 0, 0]), r"finite values in `screw_2`, got nan"),
    (lambda: screws.power_coefficient(np.zeros(6), np.zeros(6), np.zeros(2)), r"`point` with shape \(\.\.\., 3\)"),
    (lambda: screws.power_coefficient(np.zeros(6), np.zeros(6), np.zeros(3), threshold=-1), r"`threshold` >= 0"),
    (lambda: screws.adjoint(np.eye(2), np.zeros(3)), r"`rotation` with shape \(\.\.\., 3, 3\)"),
    (lambda: screws.pitch("abc"), r"`screw` to be numeric"),
])
def test_bad_input_names_the_argument(call, message):
    with pytest.raises(ValueError, match=message):
        call()
