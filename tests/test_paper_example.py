"""The paper's 5-RRR (Table 2) from hand-built screws: Fig. 2(a) numbers and Fig. 4's minimum."""

from __future__ import annotations

import numpy as np
import pytest

from screwkit.indices import closed_forms as cf
from screwkit.indices.analysis import analyze
from screwkit.screw.planar import paper_5rrr, planar_joint_points, rrr_chain_screws


def indices_at(poses, working_mode=1, **options):
    base, elbows, distal, reachable = planar_joint_points(paper_5rrr(working_mode), poses)
    assert np.all(reachable)
    return analyze(rrr_chain_screws(base, elbows, distal), **options), (base, elbows, distal)


@pytest.mark.parametrize("working_mode, phi", [(1, 45.0), (-1, 315.0)])
def test_fig_2a_numbers(working_mode, phi):
    """Stated in Sec. 4: ITI = 0.6973, 5LMTI_12345 = 0.9814, F_O1 = F_IO1 = 0.6793 (mirror mode at 315 deg)."""
    result, _ = indices_at(np.array([-0.2, 0.0, np.deg2rad(phi)]), working_mode)
    assert round(float(result.iti), 4) == 0.6973
    assert round(float(result.lmti), 4) == 0.9814
    assert round(float(result.f_o[1]), 4) == 0.6793
    assert round(float(result.f_io[1]), 4) == 0.6793
    # "The value of ITI equals the ITI value of chain three" (the lowest); the mirror
    # image swaps the roles of chains 3 and 4.
    assert int(np.argmin(result.iti_actuators)) == (2 if working_mode == 1 else 3)
    assert np.all(result.mutual_interference)


def test_working_mode_puts_every_elbow_on_the_positive_side():
    _, (base, elbows, distal) = indices_at(np.array([-0.2, 0.0, np.deg2rad(45.0)]))
    u = distal - base
    side = u[..., 0] * (elbows - base)[..., 1] - u[..., 1] * (elbows - base)[..., 0]
    assert np.all(side > 0)


def test_fig_4_minimum_of_f_o1_over_a_rotation():
    """Fig. 4(d): at x = y = 0, F_O1 stays above ~0.60 over a full turn (0.6005 at 0.1 deg steps)."""
    phi = np.deg2rad(np.arange(0.0, 360.0, 0.1))
    poses = np.column_stack([np.zeros_like(phi), np.zeros_like(phi), phi])
    result, (base, elbows, distal) = indices_at(poses)
    minimum = result.f_o[1].min()
    assert 0.600 < minimum < 0.601
    closed = cf.planar_indices(base, elbows, distal)
    assert abs(closed["f_o"][1].min() - minimum) < 1e-12
    # F_IO1 = F_O1 there because the ITI stays above F_O1 (Sec. 4).
    assert np.all(result.iti >= result.f_o[1])
    np.testing.assert_array_equal(result.f_io[1], result.f_o[1])
    # Fig. 4(b): each submechanism's OTI has (at least) two zeros over the turn.
    for s in range(10):
        oti = result.oti_submechanisms[:, s]
        assert oti.min() < 0.02
