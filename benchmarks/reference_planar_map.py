"""A straightforward numpy map of planar_5rrr: the yardstick the paper's Fig. 5 map command is measured against.

Usage: python benchmarks/reference_planar_map.py --radius 0.6 --step 0.02 --phi-step 1 --out ref.npz

Written from the geometry alone, as anyone would from the paper (no screwkit kernel): the grid points of the
disc of the given radius about the home position (spacing ``step`` in x and y, the points with x^2 + y^2 <=
radius^2), phi over a full turn (0 <= phi < 360 deg, the stop excluded). At every pose each R-R-R chain is
closed in closed form (the elbow c_i at the intersection of the circles about b_i and d_i, on the side of the
line b_i -> d_i it has in the file's reference assembly; a pose is unreachable when a chain cannot close), the
actuation wrench is the force along the distal link f_i = (d_i - c_i) / l_i through the platform joint d_i (a
planar wrench f_x, f_y, m_z), ITI = min_i |det [g_i f_i]| (Eqs. 6-7, 23), and for each of the ten 3-chain
submechanisms one batched 3x3 inverse of its wrench matrix, output twists as its columns (by cofactors: the
adjugate over the determinant, as the paper's Eq. A3 has one determinant per submechanism;
``--numpy-inverse``: np.linalg.inv, about twice the time), zero where the determinant is below 1e-12, OTI_k =
|A_k o O_k| / |v + w z x d_k| (zero at or below the singularity threshold p = 1 um, the command's default
``--threshold``, Eqs. 26-33), the submechanism's OTI the minimum over its chains; LMTI, F_O1 and F_O2 (Eqs.
11-13) and F_IOj = min(F_Oj, ITI) (Eq. 14). Each map holds the minimum over phi at every grid point, NaN where
some orientation is unreachable (and outside the disc). The joints of the bundled file are continuous (no
limits). Only the anchor points, the link lengths and each chain's working mode are read from the bundled
file, through screwkit's loader. Prints its wall time and peak memory; with --out, saves the maps (y by x) for
comparison.
"""

from __future__ import annotations

import argparse
import math
import resource
import time
from itertools import combinations

import numpy as np
from reference_hexapod_map import fault_tolerance  # Eq. 12, the same minima

from screwkit.closure.chain_kinematics import chain_forward_kinematics
from screwkit.io.loader import load

THRESHOLD = 1e-6
NAMES = ("iti", "lmti", "f_o1", "f_o2", "f_io1", "f_io2", "reachable_fraction")


def cross(a, b):
    """z component of the cross product of planar vectors (..., 2)."""
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def cross3(a, b):
    """Cross product of vectors (..., 3), component by component (numpy's np.cross is slow on small axes)."""
    return np.stack([a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1], a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2],
                     a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]], axis=-1)


def perpendicular(a):
    """z x a for planar vectors (..., 2)."""
    return np.stack([-a[..., 1], a[..., 0]], axis=-1)


def anchors(mechanism):
    """Base joints b_i (world), platform joints d_i (platform frame), link lengths a_i, l_i and elbow sides
    (+1: c_i on the left of b_i -> d_i) of the five chains, from the reference assembly."""
    base, platform, proximal, distal, side = [], [], [], [], []
    for chain in mechanism.chains:
        b, c, d = chain_forward_kinematics(chain.geometry, chain.reference_values).points[:3, :2]
        base.append(b)
        platform.append(chain.geometry.platform_loop_translation[:2])
        proximal.append(np.linalg.norm(c - b))
        distal.append(np.linalg.norm(d - c))
        side.append(np.sign(cross(d - b, c - b)))
    return np.array(base), np.array(platform), np.array(proximal), np.array(distal), np.array(side)


def indices(base, platform, proximal, distal, side, poses, threshold=THRESHOLD, numpy_inverse=False):
    """ITI, LMTI, F_O1, F_O2, F_IO1, F_IO2 and reachability at poses (N, 3: x, y, phi)."""
    cosine, sine = np.cos(poses[:, 2:]), np.sin(poses[:, 2:])
    points = poses[:, None, :2] + np.stack([cosine * platform[:, 0] - sine * platform[:, 1],
                                            sine * platform[:, 0] + cosine * platform[:, 1]], axis=-1)  # d_i (N, 5, 2)
    delta = points - base
    distance = np.linalg.norm(delta, axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):  # unreachable poses are dropped below
        along = (proximal**2 - distal**2 + distance**2) / (2 * distance)
        height_squared = proximal**2 - along**2
        reachable = np.all((height_squared >= 0) & (distance > 0), axis=1)
        u = delta / distance[..., None]
        height = side * np.sqrt(np.maximum(height_squared, 0))  # signed: the reference assembly's side
        elbow = base + along[..., None] * u + height[..., None] * perpendicular(u)
        f = (points - elbow) / distal[:, None]
        g = (elbow - base) / proximal[:, None]
    iti = np.abs(cross(g, f)).min(axis=1)
    wrenches = np.concatenate([f, cross(points, f)[..., None]], axis=-1)  # (f_x, f_y, m_z) about the origin
    wrenches[~reachable] = np.eye(3)[[0, 1, 2, 0, 1]]  # placeholders, dropped with their poses
    chains = base.shape[0]
    subsets = list(combinations(range(chains), 3))
    oti = np.empty((poses.shape[0], len(subsets)))
    for s, subset in enumerate(subsets):
        matrix = wrenches[:, subset]  # rows (f_x, f_y, m_z)
        if numpy_inverse:
            singular = np.abs(np.linalg.det(matrix)) < 1e-12
            inverse = np.linalg.inv(np.where(singular[:, None, None], np.eye(3), matrix))  # columns: twists
            twists = np.swapaxes(inverse, 1, 2)  # (N, 3 chains, 3): (v_x, v_y, w)
        else:  # the same inverse by cofactors: its columns are the cross products of the other two rows over det
            first, second, third = matrix[:, 0], matrix[:, 1], matrix[:, 2]
            adjugate = np.stack([cross3(second, third), cross3(third, first), cross3(first, second)], axis=1)
            determinant = np.einsum("ni,ni->n", first, adjugate[:, 0])
            singular = np.abs(determinant) < 1e-12
            twists = adjugate / np.where(singular, 1.0, determinant)[:, None, None]  # (N, 3 chains, 3)
        v, w = twists[..., :2], twists[..., 2]
        arm = np.linalg.norm(v + w[..., None] * perpendicular(points[:, subset]), axis=-1)  # |v + w z x d_k|
        numerator = np.abs(np.einsum("nki,nki->nk", matrix, twists))
        value = np.where(arm <= threshold * np.abs(w), 0.0, numerator / np.where(arm > 0, arm, 1.0))
        oti[:, s] = np.where(singular, 0.0, np.minimum(value, 1.0).min(axis=1))
    lmti = oti.max(axis=1)
    faults = fault_tolerance(oti, subsets, chains)
    return (iti, lmti, faults[1], faults[2], np.minimum(faults[1], iti), np.minimum(faults[2], iti)), reachable


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--radius", type=float, default=0.6)
    parser.add_argument("--step", type=float, default=0.02)
    parser.add_argument("--phi-step", type=float, default=1.0, help="deg, a full turn, the stop excluded")
    parser.add_argument("--threshold", type=float, default=THRESHOLD, help="singularity threshold p on the moment "
                        "arm (m); the command's --threshold")
    parser.add_argument("--numpy-inverse", action="store_true",
                        help="each submechanism's inverse by np.linalg.inv (LAPACK, one call per matrix) rather "
                             "than by cofactors")
    parser.add_argument("--out", default=None)
    args = parser.parse_args()
    start = time.perf_counter()
    mechanism = load("planar_5rrr")
    anchored = anchors(mechanism)
    centre = mechanism.home_pose[:2]
    count = math.floor(args.radius / args.step + 1e-9)
    offsets = args.step * np.arange(-count, count + 1)
    x_values, y_values = centre[0] + offsets, centre[1] + offsets
    inside = offsets[None, :] ** 2 + offsets[:, None] ** 2 <= args.radius**2 * (1 + 1e-12)  # the disc, to rounding
    phis = np.deg2rad(np.arange(0.0, 360.0 - 1e-9, args.phi_step))
    maps = {name: np.full(inside.shape, np.nan) for name in NAMES}
    for row, y in enumerate(y_values):  # one row of the grid at a time: its points in the disc and every phi at once
        columns = np.flatnonzero(inside[row])
        x, phi = np.meshgrid(x_values[columns], phis, indexing="ij")
        poses = np.column_stack([x.ravel(), np.full(x.size, y), phi.ravel()])
        values, reachable = indices(*anchored, poses, args.threshold, args.numpy_inverse)
        reachable = reachable.reshape(columns.size, phis.size)
        everywhere = reachable.all(axis=1)
        for name, value in zip(NAMES, values):
            maps[name][row, columns] = np.where(everywhere, value.reshape(reachable.shape).min(axis=1), np.nan)
        maps["reachable_fraction"][row, columns] = reachable.mean(axis=1)
    elapsed = time.perf_counter() - start
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    points = int(inside.sum())
    print(f"{points} grid points, {phis.size} orientations: {points * phis.size} configurations in {elapsed:.2f} s, "
          f"peak {peak:.0f} MiB")
    if args.out:
        np.savez(args.out, x=x_values, y=y_values, **maps)


if __name__ == "__main__":
    main()
