"""The indices do not depend on the length unit, the scale of the mechanism or the world frame.

Every bundled mechanism and four built here (a skew 4-RSR whose chains' constraint wrenches
miss the platform joint, a 3-PRS of lower mobility, also with six actuators, a 6-UPS with a
platform 0.05 times the size of its base, a planar mechanism whose fourth chain is balanced by a
pure couple) is analysed at its own scale and then with every length multiplied by 1e-3 ... 1e3
and under random rigid changes of the world frame, the singularity threshold *p* scaled with it.
Scaled and moved results are compared with the unscaled ones (never with printed numbers): the
indices to 1e-9, the worst faults and the mutual-interference flags exactly. The two failures of
the issue (a hexapod in millimetres, the representative of a skew chain) come first.

The hand-built configurations are closed: the 4-RSR by solving its loop equations at random
actuator inputs, the 3-PRS by solving for its parasitic motions at random heights and tilts (a
batched Newton, numpy), the UPS hexapod at random platform poses (any pose closes a UPS leg), the
planar mechanism from random joint points (any points close planar chains of some dimensions).
"""

from __future__ import annotations

import functools
from xml.etree import ElementTree

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from helpers import assert_indices_close, bundled_chain_screws, in_unit, random_rotation
from screwkit.indices.analysis import analyze
from screwkit.io.loader import bundled_path, load
from screwkit.screw import algebra as screws
from screwkit.screw.chain_screws import ChainScrews
from screwkit.screw.planar import rrr_chain_screws
from screwkit.studies.paths import path_from_poses

SCALES = (1e-3, 1e-2, 1.0, 1e2, 1e3)
THRESHOLD = 1e-6  # p at scale 1 (m); p = THRESHOLD * scale
TOLERANCE = 1e-9
COUNT = 200


# ----------------------------------------------------------------------------------------
# Hand-built mechanisms
# ----------------------------------------------------------------------------------------
def unit(vector):
    vector = np.asarray(vector, dtype=float)
    return vector / np.linalg.norm(vector, axis=-1, keepdims=True)


def revolute(axis, point):
    axis = unit(axis)
    return np.concatenate([axis, np.cross(point, axis)])


def prismatic(direction):
    return np.concatenate([np.zeros(3), unit(direction)])


def rotate(rotation_vectors, vectors):
    """Rodrigues: ``vectors`` (..., 3) rotated by the rotation vectors (..., 3) (batched, numpy)."""
    angle = np.linalg.norm(rotation_vectors, axis=-1, keepdims=True)
    axis = rotation_vectors / np.where(angle > 0, angle, 1.0)
    return (vectors * np.cos(angle) + np.cross(axis, vectors) * np.sin(angle)
            + axis * np.sum(axis * vectors, axis=-1, keepdims=True) * (1 - np.cos(angle)))


def solve_closures(residual, guess, reference, inputs, steps=4):
    """Batched Newton on ``residual(x (N, k), inputs (N, i)) -> (N, k)``, continued from the
    solution ``guess`` at the inputs ``reference`` to ``inputs`` in ``steps`` steps
    (central-difference Jacobians); returns the inputs and solutions that closed on that branch."""
    x = np.tile(guess, (len(inputs), 1))

    def newton(target, iterations):
        nonlocal x
        for _ in range(iterations):
            value = residual(x, target)
            jacobian = np.empty(value.shape + (x.shape[1],))
            for k in range(x.shape[1]):
                delta = np.zeros(x.shape[1])
                delta[k] = 1e-7
                jacobian[..., k] = (residual(x + delta, target) - residual(x - delta, target)) / 2e-7
            usable = np.all(np.isfinite(jacobian), axis=(1, 2)) & np.all(np.isfinite(value), axis=1)
            update = np.zeros_like(x)
            update[usable] = (np.linalg.pinv(jacobian[usable]) @ value[usable, :, None])[..., 0]
            x = x - update

    for fraction in np.linspace(0.0, 1.0, steps + 1)[1:]:
        newton(reference + fraction * (inputs - reference), 4)
    newton(inputs, 6)
    with np.errstate(invalid="ignore"):
        closed = np.all(np.abs(residual(x, inputs)) < 1e-12, axis=1) & np.all(np.abs(x - guess) < 1.5, axis=1)
    return inputs[closed], x[closed]


class SkewRSR:
    """A 2-DOF 4-RSR: base and platform revolute axes skew, so the constraint force of each chain
    (through the S centre, meeting both revolute axes) misses the platform joint point ``d``.
    Closed configurations from the actuator angles of legs 0 and 1 (loop equations solved)."""

    def __init__(self, rng):
        angles = np.arange(4) * np.pi / 2 + rng.uniform(-0.25, 0.25, 4)
        radial = np.column_stack([np.cos(angles), np.sin(angles), np.zeros(4)])
        tangent = np.column_stack([-np.sin(angles), np.cos(angles), np.zeros(4)])
        up = np.array([0.0, 0.0, 1.0])
        self.base = radial * rng.uniform(0.9, 1.1, (4, 1))
        self.base_axis = unit(tangent + 0.4 * up + 0.3 * radial + rng.normal(scale=0.1, size=(4, 3)))
        crank = up - 0.4 * radial + rng.normal(scale=0.1, size=(4, 3))
        self.crank = 0.5 * unit(crank - np.sum(crank * self.base_axis, axis=1, keepdims=True) * self.base_axis)
        self.height = np.array([0.0, 0.0, 1.0])
        shifted = angles + 0.35
        self.platform_point = np.column_stack([0.4 * np.cos(shifted), 0.4 * np.sin(shifted), np.zeros(4)])
        self.link = self.base + self.crank - self.platform_point - self.height  # c - d, platform frame
        self.platform_axis = unit(np.cross(self.link, rng.normal(size=(4, 3))))  # skew to the base axes

    def elbows(self, cranks):
        return self.base + rotate(self.base_axis * cranks[..., None], self.crank)

    def platform(self, x):
        """Platform joint points and axes, world frame, for unknowns x (N, 12)."""
        rotation = x[:, None, 3:6]
        return (x[:, None, :3] + self.height + rotate(rotation, self.platform_point),
                rotate(rotation, np.broadcast_to(self.platform_axis, (len(x), 4, 3))))

    def residual(self, x, inputs):
        cranks = np.concatenate([inputs, x[:, 6:8]], axis=1)
        links = rotate(self.platform_axis * x[:, 8:12, None], self.link)
        from_platform = x[:, None, :3] + self.height + rotate(x[:, None, 3:6], self.platform_point + links)
        return (self.elbows(cranks) - from_platform).reshape(len(x), 12)

    def chains(self, rng, count=COUNT):
        inputs, x = solve_closures(self.residual, np.zeros(12), np.zeros(2), rng.uniform(-0.2, 0.2, (3 * count, 2)))
        inputs, x = inputs[:count], x[:count]
        assert len(x) == count
        elbows = self.elbows(np.concatenate([inputs, x[:, 6:8]], axis=1))
        points, axes = self.platform(x)
        chains = []
        for i in range(4):
            twists = [np.broadcast_to(revolute(self.base_axis[i], self.base[i]), (count, 6))]
            twists += [np.concatenate([np.broadcast_to(e, (count, 3)), np.cross(elbows[:, i], e)], axis=1)
                       for e in np.eye(3)]
            twists.append(np.concatenate([axes[:, i], np.cross(points[:, i], axes[:, i])], axis=1))
            joint_points = [np.broadcast_to(self.base[i], (count, 3))] + [elbows[:, i]] * 3 + [points[:, i]]
            chains.append(ChainScrews(np.stack(twists, axis=1), np.stack(joint_points, axis=1), (0,), f"rsr_{i}"))
        return chains


class PRS3:
    """A 3-PRS (3 DOF, one constraint force per chain through its S centre): vertical rails,
    revolute axes tangent to the base circle, legs of unit length. Closed configurations at
    random heights and tilts of the platform: the parasitic motions (x, y, yaw) solved so that
    every S centre lies in the plane of its rail, then the sliders placed. ``actuated`` selects
    the actuated joints of every chain (the sliders by default; ``(0, 1)`` also actuates the
    revolutes: six actuators)."""

    def __init__(self, rng, actuated=(0,)):
        angles = np.arange(3) * 2 * np.pi / 3 + rng.uniform(-0.15, 0.15, 3)
        self.radial = np.column_stack([np.cos(angles), np.sin(angles), np.zeros(3)])
        self.tangent = np.column_stack([-np.sin(angles), np.cos(angles), np.zeros(3)])
        self.platform_point = 0.4 * np.column_stack([np.cos(angles + 0.1), np.sin(angles + 0.1), np.zeros(3)])
        self.actuated = tuple(actuated)

    def platform_points(self, parasitic, free):
        """S centres for x, y, yaw (``parasitic``) and height, roll, pitch (``free``), (N, 3, 3)."""
        rotation = np.stack([free[:, 1], free[:, 2], parasitic[:, 2]], axis=1)[:, None]
        centre = np.stack([parasitic[:, 0], parasitic[:, 1], free[:, 0]], axis=1)[:, None]
        return centre + rotate(rotation, self.platform_point)

    def residual(self, parasitic, free):
        return np.sum(self.platform_points(parasitic, free) * self.tangent, axis=-1)  # off the rail planes

    def chains(self, rng, count=COUNT):
        free = np.column_stack([1.8 + rng.uniform(-0.15, 0.15, 2 * count), rng.uniform(-0.2, 0.2, (2 * count, 2))])
        free, parasitic = solve_closures(self.residual, np.zeros(3), np.array([1.8, 0.0, 0.0]), free)
        free, parasitic = free[:count], parasitic[:count]
        assert len(free) == count
        points = self.platform_points(parasitic, free)
        across = np.sum(points * self.radial, axis=-1) - 1.0  # radial offset of d from its rail
        sliders = self.radial + (points[..., 2] - np.sqrt(1.0 - across**2))[..., None] * [0.0, 0.0, 1.0]
        chains = []
        for i in range(3):
            twists = [np.broadcast_to(prismatic([0.0, 0.0, 1.0]), (count, 6)),
                      np.concatenate([np.broadcast_to(self.tangent[i], (count, 3)),
                                      np.cross(sliders[:, i], self.tangent[i])], axis=1)]
            twists += [np.concatenate([np.broadcast_to(e, (count, 3)), np.cross(points[:, i], e)], axis=1)
                       for e in np.eye(3)]
            joint_points = [sliders[:, i]] * 2 + [points[:, i]] * 3
            chains.append(ChainScrews(np.stack(twists, axis=1), np.stack(joint_points, axis=1), self.actuated,
                                      f"prs_{i}"))
        return chains


def planar_with_a_couple(rng, count=COUNT):
    """Three planar RRR chains and an R-P-P chain whose actuated base revolute is balanced by a pure
    couple (its two prismatic joints take every in-plane force): the pure-couple path. Any joint
    points close a planar chain of some dimensions, so random points are closed configurations."""
    base = rng.uniform(-1.0, 1.0, (count, 4, 2))
    elbows = base + 0.6 * unit(rng.normal(size=(count, 4, 2)))
    distal = 0.2 * unit(rng.normal(size=(count, 4, 2)))
    chains = rrr_chain_screws(base[:, :3], elbows[:, :3], distal[:, :3])
    lift = np.zeros((count, 1))
    b, d = np.concatenate([base[:, 3], lift], axis=1), np.concatenate([distal[:, 3], lift], axis=1)
    slide = np.concatenate([unit(rng.normal(size=(count, 2))), lift], axis=1)
    across = np.cross([0.0, 0.0, 1.0], slide)
    z = np.broadcast_to([0.0, 0.0, 1.0], (count, 3))
    twists = np.stack([np.concatenate([z, np.cross(b, z)], axis=1), np.concatenate([0 * z, slide], axis=1),
                       np.concatenate([0 * z, across], axis=1)], axis=1)
    chains.append(ChainScrews(twists, np.stack([b, d, d], axis=1), (0,), "rpp"))
    return chains


def small_platform_ups(rng, count=COUNT):
    """A 6-UPS hexapod whose platform radius is 0.05 times its base radius, at random poses."""
    paired = np.repeat(np.arange(3) * 2 * np.pi / 3, 2) + np.tile([-0.2, 0.2], 3)
    base = np.column_stack([np.cos(paired), np.sin(paired), np.zeros(6)])
    top_angles = np.repeat(np.arange(3) * 2 * np.pi / 3 + np.pi / 3, 2) + np.tile([-0.3, 0.3], 3)
    top = 0.05 * np.column_stack([np.cos(top_angles), np.sin(top_angles), np.zeros(6)])
    centres = rng.uniform([-0.1, -0.1, 0.9], [0.1, 0.1, 1.1], (count, 1, 3))
    points = centres + rotate(rng.uniform(-0.2, 0.2, (count, 1, 3)), top)  # (count, 6, 3)
    along = unit(points - base)
    first = unit(np.cross(along, [0.0, 0.0, 1.0]))
    second = np.cross(along, first)
    chains = []
    for i in range(6):
        b = np.broadcast_to(base[i], (count, 3))
        twists = [np.concatenate([axis, np.cross(b, axis)], axis=1) for axis in (first[:, i], second[:, i])]
        twists.append(np.concatenate([np.zeros((count, 3)), along[:, i]], axis=1))
        twists += [np.concatenate([np.broadcast_to(e, (count, 3)), np.cross(points[:, i], e)], axis=1)
                   for e in np.eye(3)]
        joint_points = [b, b] + [points[:, i]] * 4
        chains.append(ChainScrews(np.stack(twists, axis=1), np.stack(joint_points, axis=1), (2,), f"ups_{i}"))
    return chains


# ----------------------------------------------------------------------------------------
# Changes of unit, scale and frame
# ----------------------------------------------------------------------------------------
def scaled(chains, scale):
    """Every length multiplied by ``scale`` (a change of unit): points and the moment half of
    revolute twists scale, prismatic twists (0, a) keep their unit direction. ``scale`` may be
    an array over the batch."""
    result = []
    for chain in chains:
        factor = np.asarray(scale, dtype=float).reshape(np.shape(scale) + (1, 1))
        revolute_joint = np.linalg.norm(chain.twists[..., :3], axis=-1, keepdims=True) > 0
        moments = np.where(revolute_joint, chain.twists[..., 3:] * factor, chain.twists[..., 3:])
        twists = np.concatenate([chain.twists[..., :3], moments], axis=-1)
        result.append(ChainScrews(twists, chain.points * factor, chain.actuated, chain.name, chain.joint_names))
    return result


def moved(chains, rotation, translation):
    """The world frame changed: every screw and point moved by the rigid transform (rotation,
    translation), one for all or one per configuration (shapes (..., 3, 3) and (..., 3))."""
    rotation = np.asarray(rotation)[..., None, :, :]  # over the joints
    translation = np.asarray(translation)[..., None, :]
    return [ChainScrews(screws.transform_twist(rotation, translation, chain.twists),
                        np.einsum("...ij,...j->...i", rotation, chain.points) + translation,
                        chain.actuated, chain.name, chain.joint_names) for chain in chains]


def assert_same_indices(reference, other):
    """Every index to TOLERANCE, the worst faults and the mutual-interference flags exactly."""
    assert_indices_close(reference, other, TOLERANCE, fields=("iti_actuators", "iti", "oti_submechanisms", "lmti"))


def assert_wrenches_follow(reference, other, scale, rotation=None, translation=None):
    """Actuation wrenches come back in world units and frame: a unit force (f, m) becomes
    Ad (f, scale m); a unit couple (0, m) stays the unit couple (0, R m)."""
    rotation = np.eye(3) if rotation is None else rotation
    translation = np.zeros(3) if translation is None else translation
    wrenches = reference.actuation_wrenches
    couple = np.linalg.norm(wrenches[..., :3], axis=-1) <= 1e-8 * np.linalg.norm(wrenches[..., 3:], axis=-1)
    expected = screws.transform_wrench(rotation, translation, wrenches * [1.0, 1.0, 1.0, scale, scale, scale])
    size = np.linalg.norm(expected, axis=-1, keepdims=True)
    found = other.actuation_wrenches
    assert np.all(np.abs(found - expected)[~couple] <= 1e-9 * size[~couple])
    moments = np.einsum("ij,...j->...i", rotation, wrenches[..., 3:])
    np.testing.assert_allclose(found[couple][:, 3:], moments[couple], rtol=0, atol=1e-9)
    assert np.all(np.linalg.norm(found[couple][:, :3], axis=-1) <= 1e-9 / scale)


# Every bundled mechanism but five_bar_3, whose indices are those of a point output
# (analyze(..., output_point=...)): these chain screws do not carry the output point.
MECHANISMS = ("planar_5rrr", "planar_4rpr", "ups_hexapod_8", "rss_hexapod_8", "coop_arms", "delta_4", "prs_3_ups",
              "schoenflies_5",
              "skew_4rsr", "prs_3", "prs_3_six_actuators", "ups_small_platform", "planar_with_a_couple")


def skew_rsr(count=COUNT, seed=0):
    """Closed configurations of one 4-RSR design (a well-conditioned one, whose actuator range of
    +-0.2 rad closes everywhere)."""
    return SkewRSR(np.random.default_rng(3)).chains(np.random.default_rng(seed), count)


@functools.lru_cache(maxsize=None)
def build(name):
    """Chain screws of a mechanism at COUNT closed configurations (cached: ChainScrews are immutable)."""
    rng = np.random.default_rng(sum(map(ord, name)))
    if name == "skew_4rsr":
        return skew_rsr()
    if name == "prs_3":
        return PRS3(rng).chains(rng)
    if name == "prs_3_six_actuators":
        return PRS3(rng, actuated=(0, 1)).chains(rng)
    if name == "ups_small_platform":
        return small_platform_ups(rng)
    if name == "planar_with_a_couple":
        return planar_with_a_couple(rng)
    chains, _ = bundled_chain_screws(name, COUNT)
    return chains


@pytest.fixture(scope="module", params=MECHANISMS)
def mechanism(request):
    chains = build(request.param)
    return request.param, chains, analyze(chains, threshold=THRESHOLD)


# ----------------------------------------------------------------------------------------
# The two failures
# ----------------------------------------------------------------------------------------
def bundled_at_home(name):
    """Chain screws of a bundled mechanism at its home pose (batch of one)."""
    from screwkit.closure import chain_screws, solve
    from screwkit.io.loader import load

    mechanism = load(name)
    return chain_screws(mechanism, solve(mechanism, mechanism.home_pose[None]))


def test_hexapod_in_millimetres_keeps_its_indices_at_home():
    """The issue: ups_hexapod_8 with every length times 0.001 gave LMTI = F_O1 = F_O2 = 0 at home and
    flagged no actuator as mutual-interference (the dependency test mixed force and moment units)."""
    chains = bundled_at_home("ups_hexapod_8")
    metres = analyze(chains, threshold=THRESHOLD)
    assert np.all(metres.mutual_interference) and metres.lmti > 0.5 and metres.f_o[2] > 0.1
    for scale in (1e-3, 1e3):
        other = analyze(scaled(chains, scale), threshold=THRESHOLD * scale)
        assert_same_indices(metres, other)


def test_skew_rsr_representative_is_scale_covariant():
    """The issue: a chain whose constraint wrench misses the platform joint had a minimum-norm
    actuation wrench that mixed force and moment units (leg 0's ITI changed from m to mm to km).
    The representative is now orthogonal to the constraint wrench in working coordinates."""
    chains = skew_rsr(count=20, seed=4)
    metres = analyze(chains, threshold=THRESHOLD)
    for scale in (1e3, 1e-3):  # millimetres, kilometres
        other = analyze(scaled(chains, scale), threshold=THRESHOLD * scale)
        np.testing.assert_allclose(other.iti_actuators[:, 0], metres.iti_actuators[:, 0], rtol=0, atol=TOLERANCE)
        np.testing.assert_allclose(other.lmti, metres.lmti, rtol=0, atol=TOLERANCE)
        assert_wrenches_follow(metres, other, scale)
    points = np.concatenate([chain.points for chain in chains], axis=1)
    centre = np.mean([chain.points[:, -1] for chain in chains], axis=0)
    length = np.sqrt(np.mean(np.sum((points - centre[:, None]) ** 2, axis=-1), axis=1))
    for index in range(20):
        twists = chains[0].twists[index]
        (constraint,) = screws.reciprocal_complement(twists)[0]  # the chain's constraint wrench
        wrench = metres.actuation_wrenches[index, 0]
        d = chains[0].points[index, -1]
        np.testing.assert_allclose(screws.reciprocal_product(wrench, twists[1:]), 0.0, atol=1e-9)
        # The constraint wrench misses d (else every metric gives the same representative) ...
        about_d = screws.shift_wrench(constraint, d)
        assert np.linalg.norm(about_d[3:]) > 1e-3 * np.linalg.norm(about_d[:3]) * length[index]
        # ... and the actuation wrench is orthogonal to it in the metric |f|^2 + |m_d|^2 / L^2.
        weight = np.array([1.0] * 3 + [length[index] ** -2] * 3)
        wrench_d = screws.shift_wrench(wrench, d)
        assert abs(np.sum(weight * wrench_d * about_d)) < 1e-9 * np.sqrt(np.sum(weight * about_d**2))


# ----------------------------------------------------------------------------------------
# Properties on every mechanism
# ----------------------------------------------------------------------------------------
def test_indices_do_not_depend_on_unit_scale_or_frame(mechanism):
    name, chains, reference = mechanism
    rng = np.random.default_rng(sum(map(ord, name)) + 1)
    for scale in SCALES:
        if scale != 1.0:
            other = analyze(scaled(chains, scale), threshold=THRESHOLD * scale)
            assert_same_indices(reference, other)
        rotation, translation = random_rotation(rng), rng.uniform(-3.0, 3.0, 3) * scale
        other = analyze(moved(scaled(chains, scale), rotation, translation), threshold=THRESHOLD * scale)
        assert_same_indices(reference, other)
        assert_wrenches_follow(reference, other, scale, rotation, translation)


@pytest.mark.parametrize("name, move", [("planar_5rrr", False), ("skew_4rsr", True)])
def test_each_configuration_has_its_own_working_coordinates(name, move):
    """A batch whose configurations are scaled (and moved) differently gives the unscaled indices:
    the centroid and the characteristic length belong to each configuration. No threshold here,
    as *p* is one length for the whole batch."""
    chains = build(name)
    rng = np.random.default_rng(8)
    scales = 10.0 ** rng.uniform(-3, 3, COUNT)
    reference = analyze(chains, threshold=0.0)
    other = scaled(chains, scales)
    if move:
        rotations = np.array([random_rotation(rng) for _ in range(COUNT)])
        other = moved(other, rotations, rng.uniform(-3, 3, (COUNT, 3)) * scales[:, None])
    assert_same_indices(reference, analyze(other, threshold=0.0, chunk_size=37))


def test_output_twists_and_oti_in_world_units():
    """Output twists come back in world units: the public power coefficient of a world wrench on a
    world twist, about the point of the wrench's axis nearest to the platform joint's axis, with the threshold and
    the characteristic length in the same unit, gives the OTI."""
    chains = skew_rsr(count=10, seed=5)
    for scale in (1e-3, 1.0, 1e3):
        current = scaled(chains, scale)
        result = analyze(current, threshold=THRESHOLD * scale, keep_twists=True)
        points = np.concatenate([chain.points for chain in current], axis=1)
        centre = np.mean([chain.points[:, -1] for chain in current], axis=0)
        length = np.sqrt(np.mean(np.sum((points - centre[:, None]) ** 2, axis=-1), axis=1))
        for index in range(10):
            for s, sub in enumerate(result.submechanisms):
                for position, k in enumerate(sub):
                    wrench = result.actuation_wrenches[index, k]
                    line = screws.joint_lines(current[k].twists[index], current[k].points[index], -1)
                    point = screws.nearest_on_axis(wrench, current[k].points[index, -1], line, length[index])
                    value = screws.power_coefficient(wrench, result.output_twists[index, s, position], point,
                                                     THRESHOLD * scale, length=length[index])
                    assert result.oti_actuators[index, s, position] == pytest.approx(float(value), abs=1e-9)


def test_power_coefficient_is_free_of_unit_and_frame_with_its_lengths(rng):
    """power_coefficient(A, T, p, threshold, length): scaling every length (moments, velocities, the
    point, the threshold and the characteristic length) and moving the frame change nothing, also
    for wrenches on either side of the pure-couple test."""
    count = 400
    wrench = rng.normal(size=(count, 6))
    twist = rng.normal(size=(count, 6))
    point = rng.normal(size=(count, 3))
    near_couple = np.arange(count) % 4 == 0
    wrench[near_couple, :3] *= 10.0 ** rng.uniform(-13, -8, (near_couple.sum(), 1))  # |f| ~ 1e-10 |m|
    reference = screws.power_coefficient(wrench, twist, point, 1e-3, length=1.0)
    for scale in SCALES:
        rotation, translation = random_rotation(rng), rng.uniform(-3, 3, 3) * scale
        lengths = np.array([1.0, 1.0, 1.0, scale, scale, scale])
        value = screws.power_coefficient(screws.transform_wrench(rotation, translation, wrench * lengths),
                                         screws.transform_twist(rotation, translation, twist * lengths),
                                         point @ rotation.T * scale + translation, 1e-3 * scale, length=scale)
        np.testing.assert_allclose(value, reference, rtol=0, atol=1e-9)


@pytest.mark.parametrize("name, faults", [("prs_3_six_actuators", None), ("coop_arms", None), ("coop_arms", 1),
                                          ("coop_arms", (2, 5))])
def test_worst_fault_is_the_first_set_within_the_tie_margin(name, faults):
    """F_Oj is the minimum LMTI over the sets left after j faults; the worst fault reported is the
    complement of the first set (combination order) whose LMTI is within WORST_FAULT_TIE of it,
    recomputed here from the OTIs of the submechanisms. Two actuators of one PRS chain give sets
    of mathematically equal LMTI, so ties occur and are resolved by the rule, not by rounding.
    coop_arms (a = 12, n = 6) reduces every j, and j = 2 and 5, through the lattice of sets, j = 1
    alone through the table of submechanisms: both are checked."""
    from itertools import combinations

    from screwkit.common.tolerances import WORST_FAULT_TIE
    from screwkit.indices.sets import reductions

    result = analyze(build(name), threshold=THRESHOLD, faults=faults)
    a = result.actuator_count
    if name == "coop_arms":
        children, _ = reductions(a, result.dof, list(combinations(range(a), result.dof)), tuple(result.f_o))
        assert (children.shape[1] <= a) == (faults != 1)  # lattice rows list at most a sets
    ties = 0
    for j in result.f_o:
        sets = list(combinations(range(a), a - j))
        lmti = np.stack([result.oti_submechanisms[:, [s for s, sub in enumerate(result.submechanisms)
                                                      if set(sub) <= set(kept)]].max(axis=1) for kept in sets], axis=1)
        np.testing.assert_array_equal(result.f_o[j], lmti.min(axis=1))
        within = lmti <= lmti.min(axis=1, keepdims=True) + WORST_FAULT_TIE
        first = np.argmax(within, axis=1)
        expected = np.array([sorted(set(range(a)) - set(sets[e])) for e in first]).reshape(-1, j)
        np.testing.assert_array_equal(result.worst_fault_indices[j], expected)
        ties += int(np.sum(np.sum(within & (lmti != lmti.min(axis=1, keepdims=True)), axis=1) > 0))
    if name == "prs_3_six_actuators":
        assert ties > 0  # sets equal up to rounding occur, and the rule decides


@pytest.mark.parametrize("name", ["prs_3_ups", "delta_4"])
@pytest.mark.parametrize("scale", [1e-3, 1e3])
def test_closure_and_forward_kinematics_of_a_scaled_copy(tmp_path, name, scale):
    """The same mechanism written with every length times ``scale``: its closure (Newton chains, dependent
    coordinates) reaches the same configurations away from home, forward kinematics finds the same poses
    from the same actuator values, and the indices are the same (closures in rad and length scales)."""
    from xml.etree import ElementTree

    from helpers import random_reachable_poses
    from screwkit.closure import actuator_values, forward, solve
    from screwkit.io.loader import bundled_path, load
    from screwkit.model.urdf_reader import scale_lengths
    from screwkit.studies.poses import indices_at_poses

    root = ElementTree.parse(bundled_path(name)).getroot()
    scale_lengths(root, scale)
    path = tmp_path / f"{name}.urdf"
    path.write_text(ElementTree.tostring(root, encoding="unicode"))
    metres, copy = load(bundled_path(name)), load(path)
    poses = random_reachable_poses(metres, np.random.default_rng(4), 6)
    factor = np.where(np.array([axis in ("x", "y", "z") for axis in metres.task_coordinates]), scale, 1.0)
    first, second = solve(metres, poses), solve(copy, poses * factor)
    assert second.reachable.all()
    a, b = indices_at_poses(metres, poses, detail=True), indices_at_poses(copy, poses * factor, detail=True)
    for key in ("iti_actuators", "oti_submechanisms", "lmti"):
        np.testing.assert_allclose(getattr(b, key), getattr(a, key), atol=1e-9, err_msg=key)
    prismatic = np.array([copy.chains[c].prismatic[j] for c, j in copy.actuator_positions(None)])
    targets = actuator_values(metres, first.joint_values) * np.where(prismatic, scale, 1.0)
    found = forward(copy, targets, np.broadcast_to(copy.home_pose, poses.shape))
    in_metres = forward(metres, targets / np.where(prismatic, scale, 1.0), np.broadcast_to(metres.home_pose,
                                                                                          poses.shape))
    np.testing.assert_array_equal(found.reachable, in_metres.reachable)  # what forward reaches from home
    assert found.reachable.sum() >= 4
    np.testing.assert_allclose(found.poses[found.reachable] / factor, poses[found.reachable], atol=1e-9)


def test_a_stretched_leg_is_reached_in_every_unit_and_world_frame(tmp_path):
    """At the boundary of a leg's reach the R-R-R closed form decided "reachable" by the sign of a square height
    that rounding sets: five_bar_3 at (-0.2, 0.35) was unreachable in metres and in millimetres and reachable moved
    in its world, (0.3, 0.3) the other way round, and maps of it differed at 2-4 of 441 points. The leg is
    stretched there (its elbow on the line from its base joint to the platform joint: ITI 0, an input singularity);
    now reached in every unit and frame, with the same indices, which are the paper's closed forms (Eqs. 21-23:
    the stretched leg's actuation wrench is the force along it; the generic path had it zero there, and so its
    OTIs: F_O1 0 where the closed forms give 0.5843)."""
    from helpers import in_millimetres, in_unit, moved_in_the_world
    from screwkit.io.loader import bundled_path, load
    from screwkit.studies import indices_at_poses

    text = bundled_path("five_bar_3").read_text()
    files = {"m": (text, 1.0), "mm": (in_millimetres(text, declare=True), 1.0),
             "moved": (moved_in_the_world(text, (0.3, -0.2, 0.5), (0.4, -0.3, 0.7)), 1.0),
             "in plane": (moved_in_the_world(text, (0.25, -0.15, 0.0), (0.0, 0.0, 1.1)), 1.0),
             "x1e-3": (in_unit(text, "m", 1e-3), 1e-3), "x1e3": (in_unit(text, "m", 1e3), 1e3)}
    poses = np.array([[-0.2, 0.35], [0.3, 0.3], [0.30000000000000004, 0.3], [-0.2, 0.4], [0.2, 0.4]])
    results = {}
    for name, (written, scale) in files.items():  # a scaled copy: its poses scaled with it
        path = tmp_path / f"five_bar_3_{name.replace(' ', '_')}.urdf"
        path.write_text(written)
        results[name] = indices_at_poses(load(path), poses * scale, detail=True)
    reference = results["m"]
    stretched = np.isclose(reference.iti_actuators, 0.0, atol=1e-12)
    assert reference.reachable.all() and stretched.any(axis=-1).all()  # at each pose a stretched leg: ITI 0
    closed = indices_at_poses(load(tmp_path / "five_bar_3_m.urdf"), poses, closed_forms=True)
    np.testing.assert_allclose(reference.lmti, closed.lmti, atol=1e-12)
    np.testing.assert_allclose(reference.f_o[1], closed.f_o[1], atol=1e-12)
    assert closed.f_o[1][0] == pytest.approx(0.5843193180388375, abs=1e-12)
    for name, result in results.items():
        assert result.reachable.all(), name
        np.testing.assert_allclose(result.lmti, reference.lmti, atol=1e-12, err_msg=name)
        np.testing.assert_allclose(result.f_o[1], reference.f_o[1], atol=1e-12, err_msg=name)
        np.testing.assert_allclose(result.iti_actuators, reference.iti_actuators, atol=1e-7, err_msg=name)


def drawn_elsewhere(text: str, rotation: np.ndarray, shift: np.ndarray) -> str:
    """A URDF with every joint hanging from ``base_link`` (its chains' first joints and the platform's) turned by
    ``rotation`` and moved by ``shift`` in the base link's frame: the same mechanism drawn elsewhere in its base frame,
    as CAD files draw theirs; its chains renamed so that they are listed the other way round, its elements written in
    reverse order."""
    root = ElementTree.fromstring(text)
    for joint in root.iter("joint"):
        parent, origin = joint.find("parent"), joint.find("origin")
        if parent is None or parent.get("link") != "base_link":
            continue
        xyz = rotation @ np.array(origin.get("xyz", "0 0 0").split(), float) + shift
        turned = rotation @ Rotation.from_euler("xyz", np.array(origin.get("rpy", "0 0 0").split(), float)).as_matrix()
        origin.set("xyz", " ".join(repr(float(v)) for v in xyz))
        origin.set("rpy", " ".join(repr(float(v)) for v in Rotation.from_matrix(turned).as_euler("xyz")))
    loops = [loop for loop in root.iter("loop")]
    for rank, loop in enumerate(sorted(loops, key=lambda loop: loop.get("chain"), reverse=True)):
        loop.set("chain", f"leg_{rank}")
    root[:] = list(root)[::-1]
    return ElementTree.tostring(root, encoding="unicode")


@pytest.mark.parametrize("name", ["prs_3_ups", "coop_arms", "schoenflies_5", "five_bar_3", "ups_hexapod_8"])
def test_the_length_scale_is_the_mechanism_s_own_size(tmp_path, name):
    """The length scale (what closures measure their gaps and tolerances in, and what weighs angles against lengths
    along a path) follows the mechanism's unit only: drawn 2 m from its base link's origin and turned there (about the
    vertical unless it moves in six DOF), its chains listed the other way round, it is the same to 1e-12, and a path
    turning the platform has the same arc length; lengths x 1e3 make it x 1e3. It was the largest distance from the
    base link's origin: 0.26 m for the 3-PRS + UPS drawn about it, 2.19 m drawn 2 m away."""
    text = bundled_path(name).read_text(encoding="utf-8")
    mechanism = load(bundled_path(name))
    turn = np.array([0.4, -0.7, 0.3]) if mechanism.dof == 6 else np.array([0.0, 0.0, 0.3])  # keeping its coordinates
    rotation = Rotation.from_rotvec(turn).as_matrix()
    copies = {"drawn elsewhere": (drawn_elsewhere(text, rotation, np.array([0.9, -1.7, 0.4])), 1.0),
              "x 1e3": (in_unit(text, "mm", 1e3), 1e3)}
    for label, (copy, factor) in copies.items():
        path = tmp_path / f"{label.replace(' ', '_')}.urdf"
        path.write_text(copy, encoding="utf-8")
        other = load(path)
        assert other.length_scale == pytest.approx(factor * mechanism.length_scale, rel=1e-12), label
        if factor == 1.0:
            assert [c.joint_names[0] for c in other.chains] == [c.joint_names[0] for c in mechanism.chains][::-1]
        angles = np.flatnonzero(other.angular)
        if factor == 1.0 and angles.size:
            for loaded in (mechanism, other):
                turned = np.array([loaded.home_pose, loaded.home_pose])
                turned[1, angles[0]] += 0.2
                assert path_from_poses(loaded, turned).length == pytest.approx(0.2 * mechanism.length_scale, rel=1e-12)
