"""One record per index: adding one is a registry record and its computation, and everything follows.

A toy index (the LMTI's margin over the ITI) and a per-fault one (the mean LMTI over the sets left after j faults,
the average case the paper mentions at the end of Sec. 3) are registered; their values then come back from
the analysis, the poses, the JSON and xarray exports, maps (the worst orientation), sweeps, the design
search's regions and the text report, each checked against an independent computation from the other results.
"""

from __future__ import annotations

import numpy as np
import pytest

from screwkit.cli.analyze import print_report
from screwkit.indices.registry import INDICES, IndexRecord, column_label, index_columns, registered, unregister
from screwkit.io.loader import load
from screwkit.studies import indices_at_pose, indices_at_poses
from screwkit.studies.design.objectives import disc_region, region_metrics
from screwkit.studies.maps import MapBlock, map_block
from screwkit.studies.options import AnalysisOptions
from screwkit.studies.sweep import sweep

TOY = IndexRecord("toy_margin", "TOY", "a test's toy", "LMTI minus ITI", compute=lambda r: r.lmti - r.iti)
MEAN = IndexRecord("f_o_mean", "F_Omean", "average case of Eq. 12", "mean LMTI over the sets left after j faults",
                   per_fault=True, compute=lambda r: {j: np.mean(r.remaining_lmti[j], axis=-1) for j in r.faults})


@pytest.fixture
def toys():
    with registered(TOY), registered(MEAN):
        yield
    assert "toy_margin" not in INDICES and "f_o_mean" not in INDICES


def test_a_registered_index_reaches_every_output(toys):
    mechanism = load("planar_5rrr")
    poses = mechanism.home_pose + np.array([[0.0, 0.0, 0.0], [0.1, -0.05, 0.4], [-0.2, 0.0, np.pi / 4]])
    result = indices_at_poses(mechanism, poses)  # no detail asked: the derived indices still have theirs
    np.testing.assert_allclose(result.index("toy_margin"), result.lmti - result.iti, rtol=0, atol=0)
    detailed = indices_at_poses(mechanism, poses, detail=True)
    for j in (1, 2):
        expected = [np.mean([detailed.at(i).lmti_of(kept) for kept in _kept(5, j)]) for i in range(3)]
        np.testing.assert_allclose(result.index("f_o_mean")[j], expected, rtol=0, atol=1e-15)
    assert result.oti_submechanisms is None  # the detail computed for them is not kept

    report = indices_at_pose(mechanism, poses[2]).to_dict()
    assert report["toy_margin"] == pytest.approx(report["lmti"] - report["iti"], abs=1e-15)
    assert set(report["f_o_mean"]) == {"1", "2"} and report["f_o_mean"]["1"] >= report["f_o"]["1"]
    dataset = result.to_dataset()
    assert dataset["f_o_mean2"].attrs["long_name"] == "F_Omean2 (average case of Eq. 12)"
    assert column_label("toy_margin") == "TOY (a test's toy)"

    over = np.deg2rad(np.arange(0.0, 360.0, 30.0))[:, None]
    block = map_block(mechanism, MapBlock(mechanism.home_pose, 0, np.array([0.0, 0.1]), 1, np.array([0.0]),
                                          np.ones((1, 2), dtype=bool), (2,), over), AnalysisOptions(threshold=1e-6))
    for x, got in zip((0.0, 0.1), block["toy_margin"]):
        around = indices_at_poses(mechanism, np.column_stack([np.full(12, x), np.zeros(12), over[:, 0]]))
        assert got == pytest.approx(np.min(around.lmti - around.iti), abs=1e-15)
    assert set(index_columns(result)) >= {"toy_margin", "f_o_mean1", "f_o_mean2", "iti", "f_io2"}

    swept = sweep(mechanism, mechanism.home_pose, "phi", np.deg2rad([0.0, 45.0]))
    np.testing.assert_allclose(swept["toy_margin"].values, swept["lmti"].values - swept["iti"].values, atol=1e-15)
    metrics = region_metrics(mechanism, disc_region(0.1, 0.1, 90.0, index="toy_margin", level=-1.0))
    assert metrics["area"] > 0.0


def test_the_text_report_prints_a_registered_index(toys, capsys):
    mechanism = load("planar_5rrr")
    print_report(indices_at_pose(mechanism, mechanism.named_pose("paper_fig_2a")).to_dict())
    printed = capsys.readouterr().out
    assert "TOY (a test's toy) " in printed and "F_Omean2 (average case of Eq. 12) " in printed


def test_the_registry_refuses_what_it_cannot_hold():
    with pytest.raises(ValueError, match="registered already"):
        with registered(IndexRecord("iti", "X", "-", "-", compute=lambda r: r.iti)):
            pass
    with pytest.raises(ValueError, match="not an index added with register"):
        unregister("lmti")
    with pytest.raises(ValueError, match=r"Unknown index 'f_q1'; the indices are iti, lmti, f_o<j>"):
        column_label("f_q1")


def _kept(count: int, faults: int):
    from itertools import combinations

    return list(combinations(range(count), count - faults))


def test_indices_from_arrays_fills_eq_14_and_refuses_what_is_not_a_field():
    """The constructor: F_IOj = min(F_Oj, ITI) (Eq. 14) and every n-subset when not given; a misspelt field, a
    per-configuration field given as a keyword, a missing index or a batch of another shape is refused by name."""
    from screwkit.indices.results import Indices

    iti, f_o = np.array([0.2, 0.9, 0.5]), np.array([0.4, 0.3, np.nan])
    arrays = {"iti": iti, "lmti": np.array([0.8, 0.7, 0.6]), "f_o": {1: f_o},
              "worst_fault_indices": {1: np.zeros((3, 1), dtype=np.int64)},
              "mutual_interference": np.zeros((3, 3), dtype=bool)}
    result = Indices.from_arrays(("a:1", "b:1", "c:1"), 2, arrays, threshold=1e-3)
    np.testing.assert_array_equal(result.f_io[1], [0.2, 0.3, np.nan])
    assert result.submechanisms == ((0, 1), (0, 2), (1, 2)) and result.batch_shape == (3,)
    with pytest.raises(TypeError, match="not fields of Indices: lmit"):
        Indices.from_arrays(("a:1", "b:1", "c:1"), 2, {**arrays, "lmit": arrays["lmti"]}, threshold=1e-3)
    with pytest.raises(TypeError, match="belong in arrays: cti"):
        Indices.from_arrays(("a:1", "b:1", "c:1"), 2, arrays, threshold=1e-3, cti=iti)
    with pytest.raises(TypeError, match="missing lmti"):
        Indices.from_arrays(("a:1", "b:1", "c:1"), 2, {k: v for k, v in arrays.items() if k != "lmti"},
                            threshold=1e-3)
    with pytest.raises(ValueError, match=r"f_o\[1\] has shape \(2,\), not a batch of shape \(3,\)"):
        Indices.from_arrays(("a:1", "b:1", "c:1"), 2, {**arrays, "f_o": {1: f_o[:2]}}, threshold=1e-3)


def test_assert_indices_close_fails_on_any_index_that_differs():
    """The shared comparison of the tests can fail: an F_O1, an ITI, a worst fault or a flag off is found."""
    from dataclasses import replace

    from helpers import assert_indices_close

    result = indices_at_pose(load("planar_5rrr"), load("planar_5rrr").home_pose)
    assert_indices_close(result, result)
    for change in ({"f_o": {1: result.f_o[1] + 1e-9}}, {"iti_actuators": result.iti_actuators + 1e-9},
                   {"worst_fault_indices": {1: (result.worst_fault_indices[1] + 1) % 4}},
                   {"mutual_interference": ~np.asarray(result.mutual_interference)},
                   {"oti_submechanisms": None}):
        with pytest.raises(AssertionError):
            assert_indices_close(result, replace(result, **change))
