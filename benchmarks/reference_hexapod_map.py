"""A straightforward numpy map of ups_hexapod_8: the yardstick the map command is measured against.

Usage: python benchmarks/reference_hexapod_map.py --step 0.01 --half 0.1 --yaw-step 1 --out ref.npz

Written from the geometry alone, as anyone would (no screwkit kernel): leg lines from the base U
centres to the platform S centres, one 6x6 inverse per six-leg submechanism for all poses at
once, output twists as the columns of the inverse, OTI = |w.t| / (|f| |v + w x p|) with p the S
centre (zero at or below the singularity threshold 1 um), LMTI and F_O1, F_O2 as minima over the
yaw turn at every grid point (x, y at the reference height, roll = pitch = 0). Joint limits are
ignored (compare with ``screwkit map ... --ignore-limits``). Only the anchor points are read from the
bundled file, through screwkit's loader. Prints its wall time and peak memory; with --out, saves
the three maps (y by x) for comparison.
"""

from __future__ import annotations

import argparse
import resource
import time
from itertools import combinations

import numpy as np

from screwkit.closure.chain_kinematics import chain_forward_kinematics
from screwkit.io.loader import load

THRESHOLD = 1e-6


def anchors(mechanism):
    """Base U centres (world) and platform S centres (platform frame) of the eight legs."""
    base, platform = [], []
    for chain in mechanism.chains:
        frames = chain_forward_kinematics(chain.geometry, chain.reference_values)
        base.append(frames.points[0])
        platform.append(chain.geometry.platform_loop_translation)
    return np.array(base), np.array(platform)


def rotation_z(angles):
    c, s = np.cos(angles), np.sin(angles)
    out = np.zeros(angles.shape + (3, 3))
    out[..., 0, 0], out[..., 0, 1], out[..., 1, 0], out[..., 1, 1], out[..., 2, 2] = c, -s, s, c, 1.0
    return out


def indices(base, platform, poses):
    """LMTI, F_O1, F_O2 at poses (N, 4: x, y, z, yaw)."""
    rotation = rotation_z(poses[:, 3])
    points = np.einsum("nij,lj->nli", rotation, platform) + poses[:, None, :3]  # S centres (N, 8, 3)
    direction = points - base
    direction /= np.linalg.norm(direction, axis=-1, keepdims=True)
    wrenches = np.concatenate([direction, np.cross(points, direction)], axis=-1)  # (f, m) about the origin
    legs = base.shape[0]
    subsets = list(combinations(range(legs), 6))
    oti = np.empty((poses.shape[0], len(subsets)))
    for s, subset in enumerate(subsets):
        matrix = wrenches[:, subset]  # rows (f, m)
        singular = np.abs(np.linalg.det(matrix)) < 1e-12
        inverse = np.linalg.inv(np.where(singular[:, None, None], np.eye(6), matrix))  # columns: twists (v, w)
        v, w = np.swapaxes(inverse[:, :3], 1, 2), np.swapaxes(inverse[:, 3:], 1, 2)  # (N, 6 legs, 3)
        arm = np.linalg.norm(v + np.cross(w, points[:, subset]), axis=-1)
        numerator = np.abs(np.einsum("nki,nki->nk", matrix[..., :3], v) + np.einsum("nki,nki->nk", matrix[..., 3:], w))
        value = np.where(arm <= THRESHOLD * np.linalg.norm(w, axis=-1), 0.0, numerator / np.where(arm > 0, arm, 1.0))
        oti[:, s] = np.where(singular, 0.0, np.minimum(value, 1.0).min(axis=1))
    faults = fault_tolerance(oti, subsets, legs)
    return oti.max(axis=1), faults[1], faults[2]


def fault_tolerance(oti, subsets, legs, failures=(1, 2)):
    """F_Oj for each j of ``failures`` (Eq. 12): over the sets of j failed legs, the minimum of the best OTI of the
    submechanisms (``subsets``, columns of ``oti``) the other legs still make."""
    faults = {}
    for j in failures:
        sets = [[s for s, subset in enumerate(subsets) if set(subset) <= set(kept)]
                for kept in combinations(range(legs), legs - j)]
        faults[j] = np.min([oti[:, members].max(axis=1) for members in sets], axis=0)
    return faults


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--step", type=float, default=0.01)
    parser.add_argument("--half", type=float, default=0.1, help="the grid spans -half..half in x and y (m)")
    parser.add_argument("--yaw-step", type=float, default=1.0, help="deg, a full turn, the stop excluded")
    parser.add_argument("--out", default=None)
    args = parser.parse_args()
    start = time.perf_counter()
    mechanism = load("ups_hexapod_8")
    base, platform = anchors(mechanism)
    height = mechanism.home_pose[2]
    axis = np.linspace(-args.half, args.half, int(round(2 * args.half / args.step)) + 1)
    yaws = np.deg2rad(np.arange(0.0, 360.0, args.yaw_step))
    maps = [np.empty((axis.size, axis.size)) for _ in range(3)]
    for row, y in enumerate(axis):  # one row of the grid at a time: every x and yaw at once
        x, yaw = np.meshgrid(axis, yaws, indexing="ij")
        poses = np.column_stack([x.ravel(), np.full(x.size, y), np.full(x.size, height), yaw.ravel()])
        for target, values in zip(maps, indices(base, platform, poses)):
            target[row] = values.reshape(axis.size, yaws.size).min(axis=1)
    elapsed = time.perf_counter() - start
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"{axis.size}x{axis.size} grid, {yaws.size} yaws: {axis.size ** 2 * yaws.size} configurations in "
          f"{elapsed:.2f} s, peak {peak:.0f} MiB")
    if args.out:
        np.savez(args.out, x=axis, y=axis, lmti=maps[0], f_o1=maps[1], f_o2=maps[2])


if __name__ == "__main__":
    main()
