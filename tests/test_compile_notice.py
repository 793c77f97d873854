"""The first-run compilation of the index kernels in child processes: at most as many at once as cores."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

import screwkit.common.compiling as notice

WRENCH, OUTPUT = notice.INDEX_KERNELS


@pytest.fixture
def stand_in_children(monkeypatch):
    """Children that sleep instead of compiling (seconds per module), on two cores, nothing cached;
    returns, for each child in the order started, which of the children before it had ended then."""
    seconds = {WRENCH: 0.6, OUTPUT: 4.0, notice.NULL_KERNEL: 0.6, notice.GRAM_KERNEL: 0.3}
    started: dict[str, dict[str, bool]] = {}

    def start(module):
        started[module] = {other: child.poll() is not None for other, child in notice._children.items()}
        sleep = f"import time; time.sleep({seconds[module]})"
        notice._children[module] = subprocess.Popen([sys.executable, "-c", sleep])

    monkeypatch.setattr(notice, "_start", start)
    monkeypatch.setattr(notice, "_cores", lambda: 2)
    monkeypatch.setattr(notice, "kernel_is_cached", lambda module: False)
    monkeypatch.setattr(notice, "_checked", set())
    monkeypatch.setattr(notice, "_children", {})
    monkeypatch.setattr(notice, "_queued", [])
    monkeypatch.setattr(notice, "_silent", False)
    return started


def test_a_kernel_asked_for_while_the_cores_compile_starts_when_one_is_free(stand_in_children, capsys):
    notice.compile_ahead(WRENCH, OUTPUT)
    first = capsys.readouterr().err
    assert first.startswith("screwkit: compiling wrench_kernel and output_kernel in 2 processes (first run only")
    assert set(stand_in_children) == {WRENCH, OUTPUT}  # both at once, on the two cores

    notice.compile_ahead(notice.NULL_KERNEL)  # both cores busy: queued
    second = capsys.readouterr().err
    assert second.startswith("screwkit: compiling null_kernel as cores free up"), second
    assert notice.NULL_KERNEL not in stand_in_children

    notice.prepare_kernels((notice.NULL_KERNEL,))  # waits for the queued kernel to start, then to end
    assert stand_in_children[notice.NULL_KERNEL] == {WRENCH: True, OUTPUT: False}  # once the wrench kernel's ended
    assert notice._children[WRENCH].poll() is not None
    assert notice._children[OUTPUT].poll() is None  # and not after the output kernel's (still compiling)
    notice.prepare_kernels(notice.INDEX_KERNELS)
    assert not notice._children and not notice._queued


def test_several_kernels_start_longest_first_and_the_notice_states_the_makespan(stand_in_children, capsys):
    notice.compile_ahead(WRENCH, OUTPUT, notice.NULL_KERNEL, notice.GRAM_KERNEL)
    line = capsys.readouterr().err
    # output 12 s on one core; null 7 + wrench 6 on the other, then gram 5 after the output kernel: 17 s
    assert notice._expected_seconds([WRENCH, OUTPUT, notice.NULL_KERNEL, notice.GRAM_KERNEL], 2) == 17
    assert line.startswith("screwkit: compiling wrench_kernel, output_kernel, null_kernel and gram_kernel in 2 "
                           "processes (first run only, about 17 s"), line
    assert list(stand_in_children) == [OUTPUT, notice.NULL_KERNEL]  # the two longest first
    notice.prepare_kernels((WRENCH, OUTPUT, notice.NULL_KERNEL, notice.GRAM_KERNEL))
    assert list(stand_in_children) == [OUTPUT, notice.NULL_KERNEL, WRENCH, notice.GRAM_KERNEL]
    assert not notice._children and not notice._queued


def test_one_pose_does_not_compile_the_kernels_of_large_chunks_ahead(monkeypatch):
    """``analyze`` (one pose) starts the index kernels ahead but not the lower-mobility kernels of chunks of
    ``SPACES_COMPILED_FROM`` poses or more, which one pose never reaches (23 s of CPU on a first run); a command
    of many poses starts those its mechanism uses (both, for the Delta)."""
    import json

    from click.testing import CliRunner

    import screwkit.cli.options as options
    from screwkit.cli import app

    asked: list[str] = []
    monkeypatch.setattr(options, "compile_ahead", lambda *modules: asked.extend(modules))
    done = CliRunner().invoke(app, ["analyze", "delta_4", "--json"])
    assert done.exit_code == 0, done.output
    assert json.loads(done.output)["dof"] == 3
    assert set(notice.INDEX_KERNELS) <= set(asked)
    assert notice.SPACE_KERNEL not in asked and notice.CONSTRAINT_KERNEL not in asked
    asked.clear()
    options.load_mechanism("delta_4")  # what map, sweep and trajectory ask
    assert {notice.SPACE_KERNEL, notice.CONSTRAINT_KERNEL} <= set(asked)


@pytest.mark.parametrize("name", ["delta_4", "prs_3_ups", "schoenflies_5", "ups_hexapod_8", "coop_arms", "five_bar",
                                  "planar_5rrr", "five_bar_3"])
def test_the_kernels_compiled_ahead_are_those_a_large_batch_uses(name, monkeypatch):
    """``constraint_kernels`` (what a command of many poses compiles ahead beside the index kernels) names exactly
    the lower-mobility kernels that a chunk of SPACES_COMPILED_FROM poses about the home pose asks for: none for
    the Schoenflies robot, whose chains hold only common constraint wrenches."""
    import screwkit.indices.stages as stages
    from screwkit.io.loader import load
    from screwkit.studies import indices_at_poses
    from screwkit.studies.kernels import constraint_kernels

    mechanism = load(name)
    asked: list[str] = []
    prepare = stages.prepare_kernels
    monkeypatch.setattr(stages, "prepare_kernels", lambda modules=(): (asked.extend(modules), prepare(modules)))
    count = max(stages.SPACES_COMPILED_FROM, stages.CONSTRAINTS_COMPILED_FROM)
    span = np.array([0.01 * mechanism.length_scale if c in ("x", "y", "z") else 0.02
                     for c in mechanism.task_coordinates])
    poses = mechanism.home_pose + np.random.default_rng(3).uniform(-1.0, 1.0, (count, mechanism.n_task)) * span
    result = indices_at_poses(mechanism, poses, threads=1)
    assert np.mean(result.reachable) > 0.9
    lower = {notice.SPACE_KERNEL, notice.CONSTRAINT_KERNEL}
    assert set(constraint_kernels(mechanism)) == set(asked) & lower
    if name == "schoenflies_5":  # the case that compiled both for nothing
        assert not set(asked) & lower


def test_stopping_ends_the_children_and_the_queue(stand_in_children):
    """What a command does as it ends: the children compiling are killed, and no queued kernel starts after."""
    notice.compile_ahead(WRENCH, OUTPUT, notice.NULL_KERNEL, notice.GRAM_KERNEL)  # two run, two wait for a core
    children = list(notice._children.values())
    assert len(children) == 2 and notice._queued
    notice.stop_compiling()
    assert all(child.poll() is not None for child in children)
    assert not notice._queued and not notice._children
    time.sleep(0.3)  # the thread that starts queued kernels as cores free up has nothing left to start
    assert not notice._children


def _compilers_of(cache: str) -> list[int]:
    """The processes whose environment names ``cache`` as numba's cache (a command's compiling children)."""
    found = []
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                environment = open(f"/proc/{entry}/environ", "rb").read()
            except OSError:
                continue
            if f"NUMBA_CACHE_DIR={cache}".encode() in environment.split(b"\0"):
                found.append(int(entry))
    return found


@pytest.mark.skipif(not sys.platform.startswith("linux") or notice._cores() < 2,
                    reason="children compile only on two cores or more; found through /proc")
def test_a_command_that_fails_leaves_no_compiler_running(tmp_path):
    """A first run (nothing cached) whose file is refused after the kernels started compiling: the command ends with
    its one line, and so do the compilers it started (they kept compiling 25 s after it, and two failed commands in a
    row had four compilers share two cores)."""
    cache = str(tmp_path / "numba")
    (tmp_path / "robot.urdf").write_text("<robot name='r'><link name='a'/><joint name='j' type='revolute'>")
    environment = dict(os.environ, NUMBA_CACHE_DIR=cache, SCREWKIT_CACHE_DIR=str(tmp_path / "own"))
    try:
        done = subprocess.run([sys.executable, "-m", "screwkit.cli", "analyze", str(tmp_path / "robot.urdf")],
                              capture_output=True, text=True, env=environment, timeout=120)
        assert done.returncode == 1 and "compiling" in done.stderr and "in 2 processes" in done.stderr, done.stderr
        assert done.stderr.strip().splitlines()[-1].startswith("Error: "), done.stderr
        assert _compilers_of(cache) == []
    finally:
        for pid in _compilers_of(cache):
            os.kill(pid, signal.SIGKILL)
