"""Cached kernels load without refreshing numba's whole target (``screwkit.common.jit.install_lean_loads``).

A command that finds its kernels cached must not import numba's lowering registries (nor ``scipy.linalg``, which
they import), and must give the same numbers, bit for bit, as numba's own loading (``SCREWKIT_LEAN_KERNEL_LOADS=0``):
for the index kernels of a planar, a spatial, two lower-mobility and a point-output mechanism, and for the kernels of
batches of 512 poses or more (closures, frames, constraint and chain-decomposition kernels), in a map. A kernel
compiled after lean loads still compiles (numba's compiler refreshes the target itself), with arrays, linear algebra
and a dictionary.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest

from helpers import screwkit

pytestmark = pytest.mark.cli

LEAN_OFF = {**os.environ, "SCREWKIT_LEAN_KERNEL_LOADS": "0"}

PROBE = """
import json, sys
from screwkit.cli import app
try:
    app(["analyze", "planar_5rrr", "--json"], standalone_mode=False)
finally:
    named = ("numba.np", "scipy", "screwkit.indices.compiled.")
    print(json.dumps(sorted(m for m in sys.modules if m.startswith(named))))
"""


def _probe(environment=None) -> tuple[dict, list[str]]:
    result = subprocess.run([sys.executable, "-W", "error", "-c", PROBE], capture_output=True, text=True, timeout=300,
                            env=environment)
    assert result.returncode == 0, result.stderr
    report, modules = result.stdout.strip().splitlines()[-2:]
    return json.loads(report), json.loads(modules)


def test_a_command_with_its_kernels_cached_loads_none_of_numbas_registries():
    _probe()  # compiles and caches the kernels if this machine has not yet
    report, modules = _probe()
    assert "screwkit.indices.compiled.outputs" in modules  # the kernels were loaded
    assert not [m for m in modules if m.startswith(("scipy.linalg", "numba.np.arraymath", "numba.np.linalg"))], modules
    full_report, full_modules = _probe(LEAN_OFF)
    assert "numba.np.arraymath" in full_modules and "scipy.linalg" in full_modules  # numba's own load imports them
    assert report == full_report


@pytest.mark.parametrize("name", ["planar_5rrr", "ups_hexapod_8", "delta_4", "five_bar_3", "prs_3_ups"])
def test_lean_and_full_loads_report_the_same(name):
    lean = screwkit("analyze", name, "--json")
    full = screwkit("analyze", name, "--json", env=LEAN_OFF)
    assert lean.returncode == 0 and full.returncode == 0, (lean.stderr, full.stderr)
    assert json.loads(lean.stdout) == json.loads(full.stdout)  # every number, bit for bit (JSON keeps 17 digits)


def test_lean_and_full_loads_map_the_same(tmp_path):
    """A Delta map of 726 configurations (a chunk above 512: compiled closures, frames, constraint and chain
    decomposition kernels) and a hexapod map of 2,400 (its spatial closed forms)."""
    import xarray as xr

    maps = {"delta_4": ["--grid", "x:-0.1:0.1:0.02", "--grid", "y:-0.1:0.1:0.02", "--over", "z:-0.8:-0.7:0.02",
                        "--at", "0", "0", "-0.75"],
            "ups_hexapod_8": ["--grid", "x:-0.02:0.02:0.01", "--grid", "y:-0.02:0.02:0.01", "--over", "yaw:0:360:4"]}
    for name, axes in maps.items():
        files = []
        for label, environment in (("lean", None), ("full", LEAN_OFF)):
            out = tmp_path / f"{name}_{label}.nc"
            result = screwkit("map", name, *axes, "--quiet", "--out", out, env=environment)
            assert result.returncode == 0, result.stderr
            files.append(out)
        with xr.open_dataset(files[0]) as lean, xr.open_dataset(files[1]) as full:
            assert set(lean.data_vars) == set(full.data_vars) and lean.data_vars
            for variable in lean.data_vars:
                np.testing.assert_array_equal(lean[variable].values, full[variable].values, err_msg=variable)


COMPILE_AFTER = """
import numpy as np
import numba
from screwkit.common.jit import install_lean_loads
from screwkit.indices.compiled.driver import run_kernels  # the index kernels, loaded lean from the cache
assert install_lean_loads()

@numba.njit
def fresh(matrix):
    counts = {0: 0, 1: 0}
    for value in matrix.ravel():
        counts[int(value > 0)] += 1
    return np.linalg.svd(matrix)[1], counts[1]

matrix = np.arange(12.0).reshape(4, 3) - 4.0
singular, positive = fresh(matrix)
print(float(np.max(np.abs(singular - np.linalg.svd(matrix)[1]))), positive)
"""


def test_a_kernel_compiles_and_runs_after_lean_loads():
    for _ in range(2):  # the second run finds the index kernels cached whatever this machine had before
        result = subprocess.run([sys.executable, "-W", "error", "-c", COMPILE_AFTER], capture_output=True, text=True,
                                timeout=600)
        assert result.returncode == 0, result.stderr
    difference, positive = result.stdout.split()
    assert float(difference) < 1e-12 and int(positive) == 7


def test_another_target_is_loaded_by_numbas_own_loading():
    """A context that is not numba's CPU target (CUDA's, in a process that uses both) is refreshed and loaded as
    numba does it."""
    import contextlib

    from numba.core import caching
    from numba.core.cpu import CPUContext

    from screwkit.common.jit import install_lean_loads

    assert install_lean_loads()
    calls = []

    class Target:  # not a CPUContext
        def refresh(self):
            calls.append("refresh")

    class Cache:
        def _guard_against_spurious_io_errors(self):
            return contextlib.nullcontext()

        def _load_overload(self, sig, target_context):
            calls.append("load")
            return "loaded"

    assert not isinstance(Target(), CPUContext)
    assert caching.Cache.load_overload(Cache(), None, Target()) == "loaded" and calls == ["refresh", "load"]


def test_the_numba_versions_installed_are_those_lean_loads_know():
    """pyproject.toml's bounds on numba are the versions install_lean_loads was written for, and this numba is one."""
    import re
    import tomllib
    from pathlib import Path

    import numba

    from screwkit.common.jit import LEAN_NUMBA

    project = tomllib.loads((Path(__file__).resolve().parents[1] / "pyproject.toml").read_text(encoding="utf-8"))
    numba_requirement = next(r for r in project["project"]["dependencies"] if r.startswith("numba"))
    bounds = re.fullmatch(r"numba>=(\d+)\.(\d+),<(\d+)\.(\d+)", numba_requirement)
    assert bounds, numba_requirement
    low, high = (tuple(int(g) for g in bounds.groups()[i:i + 2]) for i in (0, 2))
    assert (low, high) == LEAN_NUMBA
    assert low <= tuple(int(part) for part in numba.__version__.split(".")[:2]) < high
