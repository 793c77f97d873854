"""The numpy yardsticks of benchmarks/ against the commands they measure: independent computations of the same maps.

``benchmarks/reference_planar_map.py`` maps ``planar_5rrr`` from the geometry alone (closed-form elbows, a 3x3
inverse per submechanism, no screwkit kernel), so its maps equal to ``screwkit map``'s are a check of the command
itself: of the disc's grid and the orientations it takes, of the generic screw path and the paper's closed forms,
of the singularity threshold and of the minimum over phi with NaN where some orientation is unreachable.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from helpers import screwkit

BENCHMARKS = Path(__file__).resolve().parents[1] / "benchmarks"


@pytest.mark.parametrize("options, threshold", [((), 1e-6), (("--closed-forms",), 0.03)],
                         ids=["generic-1um", "closed-forms-3cm"])
def test_planar_reference_map_equals_the_map_command(tmp_path, options, threshold):
    """A disc of 1.2 m (beyond the workspace: 184 of its 441 grid points are unreachable at some phi) at 0.1 m and
    10 deg steps; at the paper's other threshold, 3 cm, F_O2 is zero at most grid points."""
    area = ["--radius", "1.2", "--step", "0.1", "--phi-step", "10"]
    result = screwkit("map", "planar_5rrr", *area, "--threshold", threshold, *options, "--quiet",
                      "--out", tmp_path / "map.nc")
    assert result.returncode == 0, result.stderr
    script = subprocess.run([sys.executable, "-W", "error", str(BENCHMARKS / "reference_planar_map.py"), *area,
                             "--threshold", str(threshold), "--out", str(tmp_path / "reference.npz")],
                            capture_output=True, text=True, timeout=300)
    assert script.returncode == 0, script.stderr
    reference = np.load(tmp_path / "reference.npz")
    with xr.open_dataset(tmp_path / "map.nc") as mapped:
        assert set(mapped.data_vars) == set(reference.files) - {"x", "y"}
        np.testing.assert_array_equal(mapped["x"].values, reference["x"])
        np.testing.assert_array_equal(mapped["y"].values, reference["y"])
        for name in mapped.data_vars:
            ours, theirs = mapped[name].values, reference[name]
            np.testing.assert_array_equal(np.isnan(ours), np.isnan(theirs), err_msg=name)
            np.testing.assert_array_equal(ours == 0, theirs == 0, err_msg=name)
            np.testing.assert_allclose(ours, theirs, rtol=0, atol=1e-12, err_msg=name)
        unreachable = np.isnan(mapped["iti"].values) & np.isfinite(mapped["reachable_fraction"].values)
        assert unreachable.sum() > 100  # the NaN pattern is tested on a part of the disc, not only outside it
        if threshold > 1e-3:
            assert (mapped["f_o2"].values == 0).sum() > 100  # and the zero pattern at singularities
