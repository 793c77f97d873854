"""The compiled spatial closed forms (U-P-S, R-U-S chains) against the numpy ones they replace on large batches."""

from __future__ import annotations

import numpy as np
import pytest

from helpers import in_millimetres, in_unit, moved_in_the_world
from screwkit.closure import chain_screws, solve
from screwkit.closure.chain_kinematics import COMPILED_FROM, chain_forward_kinematics
from screwkit.closure.solve import _PoseCache
from screwkit.common.rotations import rotation_from_rotation_vector
from screwkit.io.loader import bundled_path, load

BRANCHES = [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)]


def spread_poses(mechanism, count, seed):
    """Poses about home, far enough that some are out of reach and some spherical joints turn near pi."""
    rng = np.random.default_rng(seed)
    return mechanism.home_pose[None] + rng.normal(scale=[0.08, 0.08, 0.08, 0.3, 0.3, 1.5], size=(count, 6))


@pytest.mark.parametrize("name, kind", [("ups_hexapod_8", "ups"), ("rss_hexapod_8", "rus")])
def test_compiled_closed_forms_equal_the_numpy_ones_in_every_working_mode(name, kind):
    mechanism = load(name)
    poses = spread_poses(mechanism, 3000, 1)
    cache = _PoseCache(mechanism, poses)
    for index, chain in enumerate(mechanism.chains):
        solver = chain.closed_form
        assert solver.kind == kind
        for branch in BRANCHES:
            numpy_result = solver.solve(*mechanism.loop_targets(index, *cache.platform), branch)
            compiled = solver.solve_compiled(*cache.platform, branch)
            reachable = numpy_result.reachable
            np.testing.assert_array_equal(compiled.reachable, reachable)
            np.testing.assert_allclose(compiled.gap, numpy_result.gap, rtol=0, atol=1e-12)
            np.testing.assert_allclose(compiled.axes, numpy_result.axes, rtol=0, atol=1e-12)
            np.testing.assert_allclose(compiled.points, numpy_result.points, rtol=0, atol=1e-12)
            assert np.all(np.isnan(compiled.values[~reachable]))
            np.testing.assert_allclose(compiled.values[reachable, :3], numpy_result.values[reachable, :3], rtol=0,
                                       atol=1e-12)
            # the spherical joint's rotation vector, read from the skew part over sin(angle): rounding grows
            # like 1 / sin(angle) towards pi (1e-12 at angle pi - 1e-3, where the symmetric part takes over)
            np.testing.assert_allclose(rotation_from_rotation_vector(compiled.values[reachable, 3:]),
                                       rotation_from_rotation_vector(numpy_result.values[reachable, 3:]),
                                       rtol=0, atol=1e-11)
    assert 0.0 < np.mean(reachable) < 1.0 or name == "ups_hexapod_8"  # the RSS poses leave its workspace


@pytest.mark.parametrize("name", ["ups_hexapod_8", "rss_hexapod_8"])
def test_solve_gives_the_same_solution_on_a_large_batch_as_pose_by_small_batch(name):
    """solve() takes the compiled closed forms from COMPILED_FROM poses on, numpy below."""
    mechanism = load(name)
    poses = spread_poses(mechanism, COMPILED_FROM + 40, 2)
    large = solve(mechanism, poses)
    small = [solve(mechanism, part) for part in np.array_split(poses, 8)]
    np.testing.assert_array_equal(large.status, np.concatenate([part.status for part in small]))
    for index in range(len(mechanism.chains)):
        np.testing.assert_allclose(large.joint_axes[index],
                                   np.concatenate([part.joint_axes[index] for part in small]), rtol=0, atol=1e-12)
        np.testing.assert_allclose(large.joint_points[index],
                                   np.concatenate([part.joint_points[index] for part in small]), rtol=0, atol=1e-12)


@pytest.mark.parametrize("name", ["ups_hexapod_8", "rss_hexapod_8"])
@pytest.mark.parametrize("unreachable", ["drop", "reference"])
def test_compiled_joint_screws_are_the_unit_twists_of_the_joint_axes_and_points(name, unreachable):
    """(a, p x a) for revolute joints and (0, a) for sliders, as numpy gives them on small batches."""
    mechanism = load(name)
    poses = mechanism.home_pose + 0.1 * (spread_poses(mechanism, 2 * COMPILED_FROM, 3) - mechanism.home_pose)
    poses[::8, 2] += 2.0  # out of reach (its joints' limits, or the RSS legs' length)
    solution = solve(mechanism, poses)
    reachable = np.asarray(solution.reachable)
    assert COMPILED_FROM <= reachable.sum() < reachable.size  # the compiled path, with unreachable poses to handle
    screws = chain_screws(mechanism, solution, unreachable=unreachable)
    for index, (chain, screw) in enumerate(zip(mechanism.chains, screws)):
        axes, points = solution.joint_axes[index].copy(), solution.joint_points[index].copy()
        if unreachable == "drop":
            axes, points = axes[reachable], points[reachable]
        else:  # the reference assembly's screws where the chains do not close
            frames = chain_forward_kinematics(chain.geometry, chain.reference_values)
            axes[~reachable], points[~reachable] = frames.axes, frames.points
        prismatic = np.asarray(chain.prismatic)[:, None]
        expected = np.concatenate([np.where(prismatic, 0.0, axes),
                                   np.where(prismatic, axes, np.cross(points, axes))], axis=-1)
        np.testing.assert_allclose(screw.twists, expected, rtol=0, atol=1e-15)
        np.testing.assert_array_equal(screw.points, points)


@pytest.mark.parametrize("name", ["ups_hexapod_8", "rss_hexapod_8"])
def test_compiled_closure_keeps_the_indices_in_other_units_scales_and_world_frames(tmp_path, name):
    """The same indices, on batches that take the compiled closed forms and screws, from the file in metres,
    in millimetres, moved in the world, and with the mechanism itself scaled by 1e-3 and 1e3 (its poses'
    translations and the singularity threshold scaled alike)."""
    from screwkit.io.loader import bundled_path
    from screwkit.studies.poses import indices_at_poses

    mechanism = load(name)
    rng = np.random.default_rng(7)
    poses = mechanism.home_pose + rng.uniform(-1, 1, (COMPILED_FROM + 88, 6)) * [0.01, 0.01, 0.01, 0.05, 0.05, 0.2]
    reference = indices_at_poses(mechanism, poses, detail=True)
    assert reference.reachable.sum() >= COMPILED_FROM
    text = bundled_path(name).read_text()
    xyz, rpy = rng.uniform(-2, 2, 3), rng.uniform(-np.pi, np.pi, 3)
    files = {"mm": (in_millimetres(text, declare=True), 1.0), "moved": (moved_in_the_world(text, xyz, rpy), 1.0),
             "moved_mm": (moved_in_the_world(in_millimetres(text, declare=True), 1000 * xyz, rpy), 1.0),
             "x1e-3": (in_unit(text, "m", 1e-3), 1e-3), "x1e3": (in_unit(text, "m", 1e3), 1e3)}
    for label, (source, scale) in files.items():
        path = tmp_path / f"{name}_{label}.urdf"
        path.write_text(source)
        scaled_poses = poses * np.where(np.arange(6) < 3, scale, 1.0)
        other = indices_at_poses(load(path), scaled_poses, detail=True, threshold=reference.threshold * scale)
        np.testing.assert_array_equal(other.reachable, reference.reachable, err_msg=label)
        for key in ("iti", "iti_actuators", "oti_submechanisms", "lmti"):
            np.testing.assert_allclose(getattr(other, key), getattr(reference, key), rtol=0, atol=1e-9,
                                       err_msg=f"{label} {key}")
        for j, value in reference.f_o.items():
            np.testing.assert_allclose(other.f_o[j], value, rtol=0, atol=1e-9, err_msg=f"{label} f_o{j}")


def rod_stretched_height(mechanism) -> float:
    """The platform height above the RSS hexapod's home pose where its first rod is stretched (its end as far from
    the crank circle as the rod is long), found by bisection in 50-digit arithmetic on the crank-rod geometry of the
    file (crank point, axis and arm, rod length): the boundary of the leg's reach as a vertical rise meets it."""
    import mpmath

    mpmath.mp.dps = 50
    chain, home = mechanism.chains[0].closed_form, mechanism.home_pose

    def attachment(z):
        pose = home.copy()
        pose[2] = z
        return mechanism.loop_targets(0, *mechanism.transforms_from_poses(pose[None]))[1][0]

    start, along_z = attachment(home[2]), attachment(home[2] + 1.0) - attachment(home[2])
    c, n, v = (mpmath.matrix([float(x) for x in a]) for a in (chain.crank_point, chain.crank_axis, chain.crank_vector))
    length = mpmath.mpf(float(chain.rod_length))

    def dot(a, b):
        return sum(a[i] * b[i] for i in range(3))

    def excess(s):  # |constant| - amplitude of the crank angle's equation: > 0 out of reach
        o = mpmath.matrix([float(x) for x in start]) + s * mpmath.matrix([float(x) for x in along_z]) - c
        perpendicular = v - dot(v, n) * n
        binormal = mpmath.matrix([n[1] * perpendicular[2] - n[2] * perpendicular[1],
                                  n[2] * perpendicular[0] - n[0] * perpendicular[2],
                                  n[0] * perpendicular[1] - n[1] * perpendicular[0]])
        constant = (dot(o, o) + dot(v, v) - length**2) / 2 - dot(o, dot(v, n) * n)
        return abs(constant) - mpmath.sqrt(dot(o, perpendicular) ** 2 + dot(o, binormal) ** 2)

    low, high = mpmath.mpf(0), mpmath.mpf(1)
    assert excess(low) < 0 < excess(high)
    for _ in range(200):
        middle = (low + high) / 2
        low, high = (low, middle) if excess(middle) > 0 else (middle, high)
    return float(home[2] + low)


def test_a_stretched_rod_is_reached_in_every_unit_and_world_frame_by_numpy_and_the_kernel(tmp_path):
    """At the boundary of an R-U-S leg's reach the closed forms decided "reachable" by the sign of a difference that
    rounding sets: of nine heights one ulp apart about the stretched rod, the first two were out of reach and the
    next seven within. Now each is reached (the rod stretched: the ITI of its crank 0), by numpy and by the kernel,
    in metres, millimetres and another world frame; a height 1e-9 of the scale beyond stays out of reach."""
    mechanism = load("rss_hexapod_8")
    z = [rod_stretched_height(mechanism) - 4 * np.spacing(1.6)]
    for _ in range(16):
        z.append(np.nextafter(z[-1], 2.0))
    beyond = z[-1] + 1e-9 * mechanism.length_scale
    written = bundled_path("rss_hexapod_8").read_text()
    variants = {"m": written, "mm": in_millimetres(written, declare=True),
                "moved": moved_in_the_world(written, (0.4, -0.3, 0.2), (0.3, -0.2, 0.6))}
    for name, text in variants.items():
        path = tmp_path / f"rss_{name}.urdf"
        path.write_text(text)
        variant = load(path)
        poses = np.repeat(variant.home_pose[None], len(z) + 1, 0)
        poses[:, 2] = variant.home_pose[2] - mechanism.home_pose[2] + np.array([*z, beyond])
        small = solve(variant, poses)  # numpy below COMPILED_FROM poses
        large = solve(variant, np.tile(poses, (COMPILED_FROM // len(poses) + 1, 1)))  # the kernel
        for solution in (small, large):
            reached = np.asarray(solution.reachable).reshape(-1, len(poses))
            assert reached[:, :-1].all(), (name, reached)
            assert not reached[:, -1].any(), name
