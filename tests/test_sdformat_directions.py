"""A joint written either way (parent to child, or child to parent along the opposite axis) is the same joint in
SDFormat: the same value, the child's motion relative to the parent, and the same limits. screwkit's tree may
run through it the other way (from the child), or, for a universal or prismatic joint closing a loop at the
platform, hang its tree part from the child: it used to take the value with its sign changed and show the limits
negated, so ``--actuators`` put the platform elsewhere.

Checked on a planar 3-RRP (tests/sdformat_models.py :func:`rrp_sdf`) against its forward kinematics solved here
with scipy from the geometry alone: the slide values put the platform where the loop equations say, whichever way
each slide is written and in whichever order the legs are, and the values and limits screwkit reports are the
file's.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.optimize import fsolve
from sdformat_models import RRP_CENTRE, rrp_legs, rrp_sdf

from helpers import screwkit
from screwkit.io.loader import load
from screwkit.studies import indices_at_pose

VALUES = (0.02, 0.05, -0.03)


def rotation(angle: float) -> np.ndarray:
    return np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])


def forward(values) -> np.ndarray:
    """x, y (m) and phi (deg) of the platform for the slide values (SDFormat's: the platform's displacement from
    link 2 along u), by scipy from the file's configuration."""
    legs = rrp_legs()

    def equations(unknown):
        x, y, phi, *cranks = unknown
        rows = []
        for (base, slide, elbow, direction), value, crank in zip(legs, values, cranks):
            at_platform = np.array([x, y]) + rotation(phi) @ (slide - RRP_CENTRE)
            at_leg = base + rotation(crank) @ (elbow - base) + rotation(phi) @ (slide - elbow + value * direction)
            rows += list(at_platform - at_leg)
        return rows

    solved = fsolve(equations, np.r_[RRP_CENTRE, 0.0, 0.0, 0.0, 0.0], xtol=1e-14)
    assert np.max(np.abs(equations(solved))) < 1e-12
    return np.array([solved[0], solved[1], np.degrees(solved[2])])


@pytest.mark.parametrize("from_platform, order", [((), (0, 1, 2)), ((1, 2), (0, 1, 2)), ((0, 1, 2), (0, 1, 2)),
                                                  ((0, 1), (2, 1, 0))])
def test_slide_values_put_the_platform_where_the_geometry_does_whichever_way_each_slide_is_written(
        tmp_path, from_platform, order):
    path = tmp_path / "rrp.sdf"
    path.write_text(rrp_sdf(from_platform, order=order))
    result = screwkit("analyze", path, "--output", "effector", "--actuators", " ".join(map(repr, VALUES)), "--json")
    assert result.returncode == 0, result.stderr
    pose = json.loads(result.stdout)["pose"]
    np.testing.assert_allclose([pose["x"], pose["y"], pose["phi"]], forward(VALUES), atol=1e-9)
    mechanism = load(path, output="effector")
    at = indices_at_pose(mechanism, np.array([0.06, 0.03, np.radians(2.0)]))
    values = {name.split(":")[-1]: value for name, value in at.joint_values.items()}
    np.testing.assert_allclose(forward([values[f"p_{k}"] for k in range(3)]), [0.06, 0.03, 2.0], atol=1e-9)


def test_the_limits_shown_are_the_file_s(tmp_path):
    path = tmp_path / "rrp.sdf"
    path.write_text(rrp_sdf((0, 1, 2), limits=(-0.01, 0.2)))
    refused = screwkit("analyze", path, "--output", "effector", "--pose", "0.1 0.0 0")
    assert refused.returncode == 1 and "is outside its limits [-0.01, 0.2]" in refused.stderr, refused.stderr
