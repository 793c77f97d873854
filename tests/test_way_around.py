"""Poses the straight way from the reference leaves in another assembly, solved from many starts (closure.around).

The textbook checks of the poses it reaches are in ``test_point_leg_mode.py`` (a diamond five-bar all the way round
its hip, its motors turned together, a sweep on the command line). Here: the rule that takes an assembly (one, to
``SAME_ASSEMBLY``, among the starts that keep the working-mode sign), which chains it applies to, and that poses out
of the leg's reach are still refused, saying which chain misses.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from test_point_leg_mode import CALF, THIGH, diamond

from helpers import one_line_error, screwkit
from screwkit.closure.around import MOST_STARTS, SAME_ASSEMBLY, TURNS, eligible, one_assembly, starts
from screwkit.io.loader import load
from screwkit.studies import indices_at_pose


def test_one_assembly_is_taken_only_where_every_kept_start_agrees():
    angular = np.array([True, False])  # a hinge and a slide
    length = 1e-3  # (a millimetre-sized mechanism: a slide's 1e-7 m is 1e-4 length scales)
    values = np.zeros((4, 3, 2))
    kept = np.ones((4, 3), dtype=bool)
    values[0, 1, 0] = 2 * math.pi + 0.1 * SAME_ASSEMBLY  # the same hinge angle a turn away: one assembly
    values[1, 2, 1] = 1e-7  # the slide apart by 1e-4 length scales: two assemblies
    values[2, 2, 0] = 1.0  # two assemblies; but the one apart did not keep the sign:
    kept[2, 2] = False
    kept[3] = False  # none kept
    first, found = one_assembly(values, kept, angular, length)
    assert found.tolist() == [True, False, True, False]
    assert first[:3].tolist() == [0, 0, 0]
    kept[0, 0] = False  # the first kept start is the one taken
    assert one_assembly(values, kept, angular, length)[0][0] == 1


def test_starts_cover_a_turn_of_each_hinge_from_the_reference(tmp_path):
    path = tmp_path / "diamond.xml"
    path.write_text(diamond())
    mechanism = load(path)
    branches = [chain.branch for chain in mechanism.chains]
    assert eligible(mechanism, (0,), branches) and eligible(mechanism, (1,), branches)
    assert len(TURNS) ** 5 > MOST_STARTS and not eligible(mechanism, (0, 1), branches)  # both chains tied together
    for index, chain in enumerate(mechanism.chains):
        (values,) = starts(mechanism, (index,))
        assert values.shape == (len(TURNS) ** chain.n_joints, chain.n_joints)
        offsets = np.unique(np.round(values - chain.reference_values, 12), axis=0)
        assert len(offsets) == values.shape[0]  # every combination once
        assert set(np.round(offsets.ravel(), 12)) == set(np.round(TURNS, 12))
    assert not eligible(mechanism, (0,), [None, None])  # no sign: nothing tells its assemblies apart


def test_spatial_and_longer_chains_are_left_to_the_continuation():
    """A six-joint arm has several assemblies with one sign: no start proves the one found is the working mode's."""
    arms = load("coop_arms")
    assert all(chain.branch is not None for chain in arms.chains)
    assert not eligible(arms, (0,), [chain.branch for chain in arms.chains])


@pytest.mark.parametrize("distance", [0.05, 0.35])
def test_poses_out_of_the_legs_reach_are_still_refused(tmp_path, distance):
    """Inside the hole about the hip (nearer than the calf less the thigh) and beyond the stretched leg."""
    assert not CALF - THIGH < distance < CALF + THIGH
    path = tmp_path / "diamond.xml"
    path.write_text(diamond())
    mechanism = load(path)
    hip = mechanism.home_pose - np.array([0.0, CALF * np.sin(np.radians(60.0))])  # (the task y points down)
    pose = hip + distance * np.array([np.sin(1.0), np.cos(1.0)])
    with pytest.raises(ValueError, match="outside the workspace"):
        indices_at_pose(mechanism, pose)
    one_line_error(screwkit("analyze", path, "--pose", *(repr(float(v)) for v in pose)), "unreachable",
                   "outside the workspace")


def test_the_folded_leg_is_refused_saying_the_starts_found_no_assembly_with_its_sign(tmp_path):
    """At the fold (calf back along its thigh, the knee point the calf less the thigh from the hip) the two
    assemblies meet and the sign that names the working mode is zero: no start keeps it."""
    path = tmp_path / "diamond.xml"
    path.write_text(diamond())
    mechanism = load(path)
    hip = mechanism.home_pose - np.array([0.0, CALF * np.sin(np.radians(60.0))])
    pose = hip + (CALF - THIGH) * np.array([np.sin(1.0), np.cos(1.0)])
    with pytest.raises(ValueError, match="no one assembly with it was found from starts over a turn of each"):
        indices_at_pose(mechanism, pose)
