"""A path or a sweep that cannot fit in memory is refused in one line before anything is computed, against what this
process can be given (the system's available memory, its control group's limit, its address-space limit), and
memory that runs out anyway is one line, not a traceback.

The size counted (:func:`screwkit.studies.sizes.pose_bytes`) is held to what numpy really allocates: the growth
of the traced peak per sample is at least :data:`~screwkit.studies.sizes.PEAK_OVER_RESULT` times it, so a study
refused could not have run.
"""

from __future__ import annotations

import json
import os
import resource
import subprocess
import sys
import tracemalloc

import numpy as np
import pytest

from helpers import one_line_error, screwkit
from screwkit.common import memory
from screwkit.common.memory import byte_size
from screwkit.io.loader import load
from screwkit.studies.options import AnalysisOptions
from screwkit.studies.path_mechanisms import check_path_size, path_mechanism
from screwkit.studies.sizes import PEAK_OVER_RESULT, check_fits, pose_bytes
from screwkit.studies.sweep import sweep
from screwkit.studies.trajectory import trajectory

GIB = 2**30


def circle(mechanism, samples: int) -> np.ndarray:
    angle = np.linspace(0.0, 2 * np.pi, samples)
    poses = np.tile(mechanism.home_pose, (samples, 1))
    poses[:, 0] += 0.02 * mechanism.length_scale * np.cos(angle)
    poses[:, 1] += 0.02 * mechanism.length_scale * np.sin(angle)
    return poses


@pytest.mark.parametrize("name", ["ups_hexapod_8", "planar_5rrr", "delta_4", "prs_3_ups"])
def test_a_path_s_traced_peak_grows_by_at_least_the_bound_counted_per_sample(name):
    mechanism = load(name)
    trajectory(mechanism, circle(mechanism, 300), threads=1)  # kernels loaded, caches filled: outside the trace
    peaks = []
    for samples in (10_000, 30_000):
        tracemalloc.start()
        try:
            result = trajectory(mechanism, circle(mechanism, samples), threads=1)
            result.plain_dataset()  # what --out writes, built while the result is alive
            peaks.append(tracemalloc.get_traced_memory()[1])
        finally:
            tracemalloc.stop()
        del result
    along = path_mechanism(mechanism, AnalysisOptions(), {})
    counted = pose_bytes(mechanism, None, along.joint_coordinates)
    kept = 8 * (len(mechanism.actuator_names) + mechanism.n_task)  # the ITI of each actuator and the pose, at least
    assert counted > kept
    assert (peaks[1] - peaks[0]) / 20_000 >= PEAK_OVER_RESULT * counted


def test_pose_bytes_counts_the_detail_of_every_set_of_failures():
    hexapod, planar = load("ups_hexapod_8"), load("planar_5rrr")
    # hexapod: 28 submechanisms, 8 + 28 sets left after 1 and 2 failures, 8 ITIs, the scalars, the pose, 24 joints
    assert pose_bytes(hexapod, None, 24) == 8 * (28 + 36 + 8 + 2 + 4 + 3 + 6 + 1 + 24) + 8 + 2
    assert pose_bytes(hexapod, 1) < pose_bytes(hexapod, None) == pose_bytes(hexapod, (1, 2))
    assert pose_bytes(planar, "not faults") == pose_bytes(planar)  # refused later, by the index computation
    assert pose_bytes(planar, ()) == pose_bytes(planar) - 8 * (5 + 10 + 2 * 2 + 1 + 2)  # no failure asked


def test_check_fits_refuses_in_one_line_what_the_memory_given_cannot_hold():
    check_fits(1000, 1000, "the path has 1,000 samples", available_bytes=int(PEAK_OVER_RESULT * 10**6))
    with pytest.raises(ValueError) as raised:
        check_fits(1001, 1000, "the path has 1,001 samples", available_bytes=int(PEAK_OVER_RESULT * 10**6))
    needed, available = byte_size(int(PEAK_OVER_RESULT * 1001 * 1000)), byte_size(int(PEAK_OVER_RESULT * 10**6))
    assert str(raised.value) == (f"the path has 1,001 samples, which need at least {needed}, more than this process "
                                 f"can be given ({available} available): ask for fewer, or split the study into parts.")
    along = path_mechanism(load("planar_5rrr"), AnalysisOptions(), {})
    with pytest.raises(ValueError, match=r"^path.csv: the path has 2,000,000 samples, which need at least "):
        check_path_size(along, 2_000_000, "path.csv: the path", available_bytes=GIB)
    check_path_size(along, 200_000, "path.csv: the path", available_bytes=GIB)


def test_the_api_refuses_a_path_and_a_sweep_too_large_before_computing(monkeypatch):
    mechanism = load("planar_5rrr")
    monkeypatch.setattr(memory, "_system_available", lambda: 10 * 2**20)
    with pytest.raises(ValueError, match=r"^the path has 100,000 samples, which need at least .* \(10.0 MiB "):
        trajectory(mechanism, circle(mechanism, 100_000))
    with pytest.raises(ValueError, match=r"^the sweep has 100,000 values of phi, which need at least "):
        sweep(mechanism, mechanism.home_pose, "phi", np.linspace(-1.0, 1.0, 100_000))
    trajectory(mechanism, circle(mechanism, 2_000))  # within them


def test_available_memory_is_the_least_of_the_system_s_the_control_group_s_and_the_address_space_s(
        tmp_path, monkeypatch):
    meminfo = tmp_path / "meminfo"
    meminfo.write_text("MemTotal:       24683784 kB\nMemFree:         1000000 kB\nMemAvailable:   20000000 kB\n")
    monkeypatch.setattr(memory, "_MEMINFO", meminfo)
    monkeypatch.setattr(memory, "_CGROUP", tmp_path / "no cgroup")
    monkeypatch.setattr(memory, "_address_space_available", lambda: None)
    assert memory.available_memory() == 20000000 * 1024  # what the system could free, page cache included
    root = tmp_path / "cgroup"
    group = root / "user.slice" / "job.scope"  # this process's own group, below the mount's root
    group.mkdir(parents=True)
    own = tmp_path / "self_cgroup"
    own.write_text("0::/user.slice/job.scope\n")
    monkeypatch.setattr(memory, "_SELF_CGROUP", own)
    (group / "memory.max").write_text("max\n")
    (group / "memory.current").write_text("123\n")
    (root / "memory.max").write_text(f"{GIB}\n")  # (a limit elsewhere than this process's group: not read)
    (root / "memory.current").write_text("0\n")
    monkeypatch.setattr(memory, "_CGROUP", root)
    assert memory.available_memory() == 20000000 * 1024
    (group / "memory.max").write_text(f"{4 * GIB}\n")
    (group / "memory.current").write_text(f"{GIB}\n")
    assert memory.available_memory() == 3 * GIB
    (group / "memory.stat").write_text(f"anon {GIB // 2}\nactive_file 7\ninactive_file {GIB // 2}\n")
    assert memory.available_memory() == 3 * GIB + GIB // 2  # the page cache it could drop: not in use
    monkeypatch.setattr(memory, "_address_space_available", lambda: GIB)
    assert memory.available_memory() == GIB
    own.write_text("12:memory:/job\n3:cpu:/job\n")  # control groups v1
    (root / "memory.max").unlink()
    (root / "memory" / "job").mkdir(parents=True)
    (root / "memory" / "job" / "memory.limit_in_bytes").write_text(f"{2**63 - 4096}\n")
    (root / "memory" / "job" / "memory.usage_in_bytes").write_text(f"{GIB}\n")
    monkeypatch.setattr(memory, "_address_space_available", lambda: None)
    assert memory.available_memory() == 20000000 * 1024
    (root / "memory" / "job" / "memory.limit_in_bytes").write_text(f"{2 * GIB}\n")
    (root / "memory" / "job" / "memory.stat").write_text(f"cache 5\ntotal_inactive_file {GIB // 4}\n")
    assert memory.available_memory() == GIB + GIB // 4


def test_an_address_space_limit_is_what_this_process_can_still_be_given():
    limit = 3 * GIB
    code = ("from screwkit.common.memory import available_memory; import resource, os;"
            "size = int(open('/proc/self/statm').read().split()[0]) * os.sysconf('SC_PAGE_SIZE');"
            f"print(available_memory(), {limit} - size)")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60, env=ONE_THREAD,
                         preexec_fn=lambda: resource.setrlimit(resource.RLIMIT_AS, (limit, limit)))
    assert run.returncode == 0, run.stderr
    available, left = map(int, run.stdout.split())
    assert 0 < available <= left and left - available < 64 * 2**20  # less what the process has mapped since


ONE_THREAD = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1",
              "NUMBA_NUM_THREADS": "2"}
"""A child under an address-space limit: a BLAS's buffers per core would take it on a machine of many cores."""


def _limited(gibibytes: float):
    size = int(gibibytes * GIB)
    return lambda: resource.setrlimit(resource.RLIMIT_AS, (size, size))


def test_the_command_refuses_a_path_too_large_for_the_memory_in_one_line_before_computing(tmp_path):
    out = tmp_path / "t.nc"
    run = screwkit("trajectory", "ups_hexapod_8", "--line", "0", "0", "1", "0", "0", "0", "0.05", "0", "1", "0", "0",
                   "20", "--samples", "1000000000", "--quiet", "--out", out)
    one_line_error(run, "--samples 1000000000: the path has 1,000,000,000 samples, which need at least ",
                   "more than this process can be given", "split the study into parts")
    assert not out.exists() and "compiling" not in run.stderr
    run = screwkit("trajectory", "ups_hexapod_8", "--circle", "home", "0.01", "--samples", "1000000000", "--json")
    assert run.returncode == 1 and "1,000,000,000 samples" in json.loads(run.stdout)["error"]
    run = screwkit("sweep", "ups_hexapod_8", "--sweep", "yaw:0:360:0.00012", "--quiet", "--out", tmp_path / "s.nc",
                   preexec_fn=_limited(1.2), env=ONE_THREAD)  # 4.3 GiB at least, against what 1.2 GiB leaves
    one_line_error(run, "the sweep has 3,000,000 values of yaw, which need at least ")


def test_a_path_file_too_large_for_an_address_space_limit_is_refused_naming_the_file(tmp_path):
    angle = np.linspace(0.0, 2 * np.pi, 1_000_000)
    rows = np.column_stack([0.02 * np.cos(angle), 0.02 * np.sin(angle), np.ones_like(angle),
                            np.zeros_like(angle), np.zeros_like(angle), 10 * np.sin(angle)])
    rows[:, 2] = load("ups_hexapod_8").home_pose[2]
    path = tmp_path / "path.csv"
    np.savetxt(path, rows, delimiter=",", header="x,y,z,roll,pitch,yaw", comments="")
    out = tmp_path / "t.nc"
    run = screwkit("trajectory", "ups_hexapod_8", path, "--quiet", "--out", out, preexec_fn=_limited(1.2),
                   env=ONE_THREAD)
    one_line_error(run, f"{path}: the path has 1,000,000 samples, which need at least ", "available)")
    assert not out.exists()


INJECTED = """
import sys
import numpy as np
import screwkit.cli.{module} as command
from screwkit.cli import main

def exhausted(*args, **kwargs):  # the study's arrays beyond what the system gives: numpy's own MemoryError
    return np.empty(2**50)

command.{name} = exhausted
sys.argv = ["screwkit", *sys.argv[1:]]
main()
"""


@pytest.mark.parametrize(("module", "name", "arguments"), [
    ("sweep", "run_sweep", ["sweep", "planar_5rrr", "--phi", "0:10:1"]),
    ("trajectory", "run_trajectory", ["trajectory", "planar_5rrr", "--circle", "home", "0.01", "--samples", "10"]),
])
def test_memory_that_runs_out_anyway_is_one_line_and_no_file(tmp_path, module, name, arguments):
    """An allocation that fails inside the command (injected: 8 PiB), after the size checks let it start."""
    out = tmp_path / "out.nc"
    run = subprocess.run([sys.executable, "-W", "error", "-c", INJECTED.format(module=module, name=name), *arguments,
                          "--quiet", "--out", str(out)], capture_output=True, text=True, timeout=120)
    one_line_error(run, "Ran out of memory: Unable to allocate 8.00 PiB", "ask for a smaller study")
    assert not list(tmp_path.iterdir())
    if module == "sweep":  # (no --json)
        return
    run = subprocess.run([sys.executable, "-W", "error", "-c", INJECTED.format(module=module, name=name), *arguments,
                          "--json"], capture_output=True, text=True, timeout=120)
    assert run.returncode == 1 and json.loads(run.stdout)["error"].startswith("Ran out of memory: Unable to allocate")
