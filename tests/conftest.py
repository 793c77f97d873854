"""Shared, seeded generators of planar configurations for the tests."""

from __future__ import annotations

import numpy as np
import pytest


def rotation_2d(angle):
    angle = np.asarray(angle, dtype=float)
    return np.stack([np.stack([np.cos(angle), -np.sin(angle)], -1), np.stack([np.sin(angle), np.cos(angle)], -1)], -2)


def unit(angle):
    angle = np.asarray(angle, dtype=float)
    return np.stack([np.cos(angle), np.sin(angle)], axis=-1)


def random_planar_rrr(rng: np.random.Generator, count: int, chains: int = 5):
    """Random RRR configurations: points b, c, d of `chains` chains, shape (count, chains, 2).

    Arm lengths vary in [0.3, 1.5] and directions are uniform, so every geometry occurs.
    """
    distal = rng.uniform(-0.5, 0.5, (count, chains, 2))
    f_angle = rng.uniform(0, 2 * np.pi, (count, chains))
    g_angle = rng.uniform(0, 2 * np.pi, (count, chains))
    lower = rng.uniform(0.3, 1.5, (count, chains, 1))
    upper = rng.uniform(0.3, 1.5, (count, chains, 1))
    elbows = distal - lower * unit(f_angle)
    base = elbows - upper * unit(g_angle)
    return base, elbows, distal


def special_planar_rrr(rng: np.random.Generator, count: int, chains: int = 5):
    """Configurations with exactly/nearly parallel distal links, collinear and concurrent lines,
    and type-one singular chains (f parallel to g). Returns (base, elbows, distal, kind)."""
    base, elbows, distal = random_planar_rrr(rng, count, chains)
    f = distal - elbows
    lengths = np.linalg.norm(f, axis=-1, keepdims=True)
    kind = rng.integers(0, 6, count)
    # 0: chains 0 and 1 exactly parallel distal links (equal f), 1: nearly parallel (1e-7 rad),
    # 2: chains 0 and 1 collinear lines, 3: lines of chains 0, 1, 2 concurrent,
    # 4: chain 0 stretched (f parallel to g: type-one singular), 5: three chains with equal f.
    direction = f[:, 0] / lengths[:, 0]
    for index in range(count):
        k = kind[index]
        if k in (0, 1, 5):
            angle = 0.0 if k != 1 else 1e-7
            rotated = rotation_2d(angle) @ direction[index]
            targets = (1, 2) if k == 5 else (1,)
            for target in targets:
                elbows[index, target] = distal[index, target] - lengths[index, target] * rotated
        elif k == 2:
            offset = rng.uniform(0.2, 0.6)
            distal[index, 1] = distal[index, 0] + offset * direction[index]
            elbows[index, 1] = distal[index, 1] - lengths[index, 1] * direction[index]
        elif k == 3:
            centre = rng.uniform(-0.3, 0.3, 2)
            for target in (0, 1, 2):
                u = distal[index, target] - centre
                u = u / np.linalg.norm(u)
                elbows[index, target] = distal[index, target] - lengths[index, target] * u
        elif k == 4:
            upper = np.linalg.norm(elbows[index, 0] - base[index, 0])
            base[index, 0] = elbows[index, 0] - upper * direction[index]
    base = base.copy()
    # Keep the base joints where the arms put them (upper arm from b to c).
    return base, elbows, distal, kind


@pytest.fixture
def rng():
    return np.random.default_rng(20261121)
