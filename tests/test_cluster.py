"""The cluster path as users run it: a real ``dask scheduler`` and ``dask worker`` processes on loopback.

The scheduler and the workers are started with the ``dask`` command line, each in its own
process group (so that one can be killed with SIGKILL, nanny and worker together, as when a
machine is lost), and always ended when the tests are done. The ``screwkit`` command runs in a
subprocess against them; a separate client only watches the scheduler's task states to kill
things mid-run. Nothing here uses a default distributed client.
"""

from __future__ import annotations

import contextlib
import http.server
import json
import os
import signal
import socket
import socketserver
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from helpers import one_line_error, screwkit

distributed = pytest.importorskip("distributed")

DASK = str(Path(sys.executable).with_name("dask"))
MAP = ("map", "planar_5rrr", "--radius", "0.5", "--step", "0.01", "--phi-step", "2", "--task-size", "4000")
"""1.4 million configurations in over 300 tasks: a few seconds on two single-threaded workers."""
SEARCH = ("design-search", "permutations", "planar_5rrr", "--phi-step", "10", "--json", "--quiet")


def free_port() -> int:
    """A loopback port nothing listens on (bound, then released)."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


class Cluster:
    """``dask scheduler`` and ``dask worker`` processes on 127.0.0.1, each in its own process group."""

    def __init__(self, folder: Path, workers: int, scheduler_environment: dict | None = None,
                 port: int | None = None):
        self.folder = folder
        self.port = free_port() if port is None else port
        self.address = f"tcp://127.0.0.1:{self.port}"
        self.logs = []
        self.scheduler = self.start("scheduler", ["scheduler", "--host", "127.0.0.1", "--port", str(self.port),
                                                  "--no-dashboard"], scheduler_environment)
        self.workers = [self.start(f"worker-{i}", ["worker", self.address, "--nworkers", "1", "--nthreads", "1",
                                                   "--no-dashboard"]) for i in range(workers)]
        self.client = None
        try:
            self.client = distributed.Client(self.address, timeout=30, set_as_default=False)
            self.client.wait_for_workers(workers, timeout=60)
        except BaseException:
            self.stop()
            raise

    def start(self, name: str, arguments: list[str], environment: dict | None = None) -> subprocess.Popen:
        log = open(self.folder / f"{name}.log", "w")
        self.logs.append(log)
        return subprocess.Popen([DASK, *arguments], cwd=self.folder, stdin=subprocess.DEVNULL,
                                stdout=log, stderr=subprocess.STDOUT, start_new_session=True,
                                env=None if environment is None else {**os.environ, **environment})

    def kill(self, process: subprocess.Popen) -> None:
        """SIGKILL to the process's whole group (a worker's nanny and the worker it spawned)."""
        try:
            os.killpg(process.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        process.wait(timeout=30)

    def finished_tasks(self, prefix: str = "screwkit-map_task-") -> tuple[int, int]:
        """(tasks in memory, all tasks) of screwkit's tasks on the scheduler."""

        def count(dask_scheduler, prefix=prefix):
            states = [task.state for key, task in dask_scheduler.tasks.items() if str(key).startswith(prefix)]
            return sum(state == "memory" for state in states), len(states)

        return tuple(self.client.run_on_scheduler(count))

    def wait_until_some_finished(self, command: subprocess.Popen, count: int = 5, timeout: float = 60) -> tuple:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            assert command.poll() is None, "the command ended before anything could be killed"
            done, total = self.finished_tasks()
            if done >= count:
                return done, total
            time.sleep(0.02)
        raise AssertionError(f"no {count} tasks finished within {timeout} s")

    def close_client(self) -> None:
        if self.client is not None:
            self.client.close(timeout=10)
            self.client = None

    def stop(self) -> None:
        try:
            self.close_client()
        finally:
            for process in [*self.workers, self.scheduler]:
                self.kill(process)
            for log in self.logs:
                log.close()


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    running = Cluster(tmp_path_factory.mktemp("cluster"), workers=2)
    try:
        yield running
    finally:
        running.stop()


@pytest.fixture(scope="module")
def local_map(tmp_path_factory) -> Path:
    """The map computed on local threads, the reference."""
    out = tmp_path_factory.mktemp("local") / "local.nc"
    result = screwkit(*MAP, "--out", out)
    assert result.returncode == 0, result.stderr
    return out


def assert_same_file(expected: Path, actual: Path) -> None:
    """Every variable, coordinate and attribute equal, and the files equal byte for byte."""
    with xr.open_dataset(expected) as one, xr.open_dataset(actual) as other:
        assert set(one.variables) == set(other.variables) and one.attrs == other.attrs
        for name in one.variables:
            np.testing.assert_array_equal(one[name].values, other[name].values, err_msg=name)
            assert one[name].attrs == other[name].attrs, name
    assert expected.read_bytes() == actual.read_bytes()


def one_line(result: subprocess.CompletedProcess | tuple, *needles: str) -> str:
    """The one-line error of a command (:func:`helpers.one_line_error`), after at most the map's size line."""
    if not hasattr(result, "stderr"):
        code, stdout, stderr = result
        result = subprocess.CompletedProcess([], code, stdout, stderr)
    return one_line_error(result, *needles, after=("planar_5rrr: mapping ",))


def test_map_on_the_cluster_equals_the_local_map(cluster, local_map, tmp_path):
    out = tmp_path / "remote.nc"
    result = screwkit(*MAP, "--scheduler", cluster.address, "--out", out)
    assert result.returncode == 0, result.stderr
    assert "Warning" not in result.stderr and "Traceback" not in result.stderr, result.stderr
    assert_same_file(local_map, out)
    assert sorted(os.listdir(tmp_path)) == ["remote.nc"]


def test_a_map_of_a_closed_loop_graph_on_the_cluster_equals_the_local_map(cluster, tmp_path):
    """A rod-level Delta (legs with loops inside them): the workers read the file at its path and solve each pose
    from the file's configuration, as the local threads do."""
    sys.path.insert(0, str(Path(__file__).parent))
    from delta_rods import delta_rods_mjcf

    path = tmp_path / "delta.xml"
    path.write_text(delta_rods_mjcf((0.02, -0.03, -0.45), np.radians([90.0, 180.0, 270.0, 0.0])))
    arguments = ("map", path, "--grid", "x:-0.03:0.13:0.02", "--grid", "y:-0.1:0.1:0.02", "--at", "0 0 -0.45",
                 "--task-size", "20")
    local, remote = tmp_path / "local.nc", tmp_path / "remote.nc"
    assert screwkit(*arguments, "--out", local).returncode == 0
    result = screwkit(*arguments, "--scheduler", cluster.address, "--out", remote)
    assert result.returncode == 0, result.stderr
    assert "Traceback" not in result.stderr, result.stderr
    assert_same_file(local, remote)


def test_design_search_on_the_cluster_equals_the_local_search(cluster):
    local = screwkit(*SEARCH)
    remote = screwkit(*SEARCH, "--scheduler", cluster.address)
    assert local.returncode == 0 and remote.returncode == 0, remote.stderr
    assert json.loads(remote.stdout) == json.loads(local.stdout)
    assert len(json.loads(remote.stdout)["designs"]) == 240


def test_a_worker_killed_mid_run_loses_nothing(cluster, local_map, tmp_path):
    out = tmp_path / "remote.nc"
    with open(tmp_path / "stderr.txt", "w+") as errors:
        command = subprocess.Popen([sys.executable, "-W", "error", "-m", "screwkit.cli", *MAP,
                                    "--scheduler", cluster.address, "--out", str(out)],
                                   stdout=subprocess.DEVNULL, stderr=errors)
        try:
            done, total = cluster.wait_until_some_finished(command, count=100)
            victim = cluster.workers[0]
            cluster.kill(victim)  # the nanny and its worker: a lost machine, not a restarted worker
            assert command.poll() is None, "the kill came after the run"
            assert 100 <= done < total and total > 300, (done, total)
            assert command.wait(timeout=120) == 0
        finally:
            if command.poll() is None:
                command.kill()
        errors.seek(0)
        stderr = errors.read()
    assert "Warning" not in stderr and "Traceback" not in stderr, stderr
    assert len(cluster.client.scheduler_info()["workers"]) == len(cluster.workers) - 1  # really gone
    assert_same_file(local_map, out)


def test_an_unreachable_scheduler_fails_with_one_line_naming_the_address_and_the_timeout(tmp_path):
    """Nothing listens: the command tries for --connect-timeout seconds, then exits with one line that says so
    (the time limit of the subprocesses only guards against a hang)."""
    address = f"tcp://127.0.0.1:{free_port()}"
    out = tmp_path / "remote.nc"
    one_line(screwkit(*MAP, "--scheduler", address, "--out", out, timeout=120),
             f"Cannot reach the Dask scheduler at {address} within 3 s", "Connection refused")
    one_line(screwkit(*MAP, "--scheduler", address, "--out", out, "--connect-timeout", "0.5", timeout=120),
             "within 0.5 s")
    one_line(screwkit(*SEARCH[:-2], "--scheduler", address, "--connect-timeout", "1.5", timeout=120),
             f"Cannot reach the Dask scheduler at {address} within 1.5 s")
    # An address that is no address, and the same with --json.
    one_line(screwkit(*MAP, "--scheduler", "nowhere", "--out", out), "Dask scheduler address 'nowhere'")
    result = screwkit(*SEARCH[:-1], "--scheduler", address, "--connect-timeout", "0.5", timeout=120)
    assert result.returncode == 1 and result.stderr == ""
    assert "Cannot reach the Dask scheduler" in json.loads(result.stdout)["error"]
    assert os.listdir(tmp_path) == []


def test_a_scheduler_started_within_the_connect_timeout_is_waited_for(tmp_path_factory, tmp_path):
    """--connect-timeout is how long the command keeps trying: a scheduler started after the command is found."""
    port = free_port()
    out = tmp_path / "late.nc"
    command = subprocess.Popen([sys.executable, "-W", "error", "-m", "screwkit.cli", "map", "planar_5rrr", "--radius",
                                "0.1", "--step", "0.05", "--phi-step", "90", "--out", str(out), "--scheduler",
                                f"tcp://127.0.0.1:{port}", "--connect-timeout", "120"],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        late = Cluster(tmp_path_factory.mktemp("late"), workers=1, port=port)
        try:
            stdout, stderr = command.communicate(timeout=300)
        finally:
            late.stop()
    finally:
        if command.poll() is None:
            command.kill()
    assert command.returncode == 0, stderr
    assert out.read_bytes().startswith(b"CDF")


class _Replying(socketserver.BaseRequestHandler):
    """Answers every connection at once as a web server answers a request it cannot parse, then waits."""

    def handle(self):
        try:
            self.request.sendall(b"HTTP/1.0 400 Bad Request\r\nContent-Length: 0\r\n\r\n")
            while self.request.recv(4096):
                pass
        except ConnectionError:  # the client hung up
            pass


class _Quiet(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *arguments):
        pass


@contextlib.contextmanager
def listener(kind: str):
    """A server on loopback that is not a Dask scheduler: ``http`` (a web server, waiting for a request line
    as on a dashboard's port) or ``reply`` (one that answers at once, something else than Dask's frames)."""
    server_class = http.server.ThreadingHTTPServer if kind == "http" else socketserver.ThreadingTCPServer
    server = server_class(("127.0.0.1", 0), _Quiet if kind == "http" else _Replying)
    server.daemon_threads = True
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"tcp://127.0.0.1:{server.server_address[1]}"
    finally:
        server.shutdown()
        server.server_close()


@pytest.mark.parametrize("kind, found", [("http", "no Dask handshake within 1 s"),
                                         ("reply", "its answer is not Dask's handshake")])
def test_an_address_that_answers_but_is_not_dask_fails_within_the_timeout_with_one_line(tmp_path, kind, found):
    """A web server on the port (the dashboard's, given by mistake) hung the command for good; one that answered
    at once ended in a traceback of an allocation of 3 EiB. The subprocesses' time limit is a hang guard."""
    out = tmp_path / "remote.nc"
    with listener(kind) as address:
        mapped = screwkit(*MAP, "--scheduler", address, "--connect-timeout", "1", "--out", out, timeout=120)
        searched = screwkit(*SEARCH[:-1], "--scheduler", address, "--connect-timeout", "1", timeout=120)
    one_line(mapped, f"The address {address} answers but is not a Dask scheduler", found)
    assert searched.returncode == 1 and searched.stderr == ""
    error = json.loads(searched.stdout)["error"]
    assert error.startswith(f"The address {address} answers but is not a Dask scheduler") and found in error
    assert os.listdir(tmp_path) == []


def test_a_tls_address_without_tls_settings_is_refused_with_one_line(tmp_path):
    address = f"tls://127.0.0.1:{free_port()}"
    one_line(screwkit(*MAP, "--scheduler", address, "--out", tmp_path / "remote.nc"),
             f"Cannot connect to the Dask scheduler at {address}: a tls:// address needs TLS settings")
    assert os.listdir(tmp_path) == []


def test_a_scheduler_lost_mid_run_gives_one_line_and_no_file(tmp_path_factory, tmp_path):
    lost = Cluster(tmp_path_factory.mktemp("lost"), workers=1)
    out = tmp_path / "remote.nc"
    try:
        command = subprocess.Popen([sys.executable, "-W", "error", "-m", "screwkit.cli", *MAP,
                                    "--scheduler", lost.address, "--out", str(out)],
                                   stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        try:
            done, total = lost.wait_until_some_finished(command)
            lost.close_client()
            lost.kill(lost.scheduler)
            assert command.poll() is None, "the kill came after the run"
            stdout, stderr = command.communicate(timeout=60)  # a hang guard: it ends at once
        finally:
            if command.poll() is None:
                command.kill()
    finally:
        lost.stop()
    assert 5 <= done < total, (done, total)
    one_line((command.returncode, stdout, stderr), f"Lost the Dask scheduler at {lost.address} mid-run",
             "nothing was written")
    assert os.listdir(tmp_path) == []  # no output, no temporary file


def test_a_task_given_up_by_the_scheduler_gives_one_line_and_no_file(tmp_path_factory, tmp_path):
    """With allowed-failures 0 the scheduler gives a task up as soon as a worker dies running it (KilledWorker)."""
    fragile = Cluster(tmp_path_factory.mktemp("fragile"), workers=2,
                      scheduler_environment={"DASK_DISTRIBUTED__SCHEDULER__ALLOWED_FAILURES": "0"})
    out = tmp_path / "remote.nc"
    try:
        command = subprocess.Popen([sys.executable, "-W", "error", "-m", "screwkit.cli", *MAP,
                                    "--scheduler", fragile.address, "--out", str(out)],
                                   stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        try:
            done, total = fragile.wait_until_some_finished(command)
            fragile.kill(fragile.workers[0])  # busy with a task: there are hundreds queued
            assert command.poll() is None, "the kill came after the run"
            stdout, stderr = command.communicate(timeout=60)
        finally:
            if command.poll() is None:
                command.kill()
    finally:
        fragile.stop()
    one_line((command.returncode, stdout, stderr), f"Dask workers of the scheduler at {fragile.address} died while "
             "running a task (KilledWorker:", "nothing was written")
    assert os.listdir(tmp_path) == []


FAMILY_SEARCH = ("design-search", "family", "ups_hexapod", "--grid", "x:-0.1:0.1:0.05", "--grid", "y:-0.1:0.1:0.05",
                 "--over", "yaw:-20:40:20", "--free", "platform_radius", "--free", "height", "--objective", "mean",
                 "--budget", "64", "--popsize", "4", "--index", "f_o_mean1", "--probabilities", "0.1", "0.05", "0.2",
                 "0.1", "0.1", "0.3", "0.1", "0.05", "--json", "--quiet")
"""A family search of up to 65 hexapod designs in 9 batches (the start, then 8 populations of 8; the mean index
varies continuously, so the search does not stop early on a converged population), on the average case weighted by
failure probabilities (registered in each worker that evaluates a design)."""


def test_a_family_search_on_two_workers_equals_the_local_search_and_survives_a_killed_worker(tmp_path_factory,
                                                                                             tmp_path):
    local = screwkit(*FAMILY_SEARCH, "--urdf", tmp_path / "local.urdf")
    assert local.returncode == 0, local.stderr
    own = Cluster(tmp_path_factory.mktemp("search"), workers=2)
    try:
        command = subprocess.Popen([sys.executable, "-W", "error", "-m", "screwkit.cli", *FAMILY_SEARCH,
                                    "--urdf", str(tmp_path / "remote.urdf"), "--scheduler", own.address],
                                   stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        try:
            deadline, seen = time.monotonic() + 120, set()
            while len(seen) < 17:  # the start and more than a population: each batch's tasks are forgotten after it
                assert command.poll() is None, "the search ended before a worker could be killed"
                assert time.monotonic() < deadline, "no 17 designs sent within 120 s"
                seen.update(own.client.run_on_scheduler(
                    lambda dask_scheduler: [str(k) for k in dask_scheduler.tasks
                                            if str(k).startswith("screwkit-evaluate_candidate-")]))
                time.sleep(0.01)
            own.kill(own.workers[0])  # the nanny and its worker: a lost machine
            assert command.poll() is None, "the kill came after the run"
            stdout, stderr = command.communicate(timeout=300)
        finally:
            if command.poll() is None:
                command.kill()
        assert len(own.client.scheduler_info()["workers"]) == 1  # really gone
    finally:
        own.stop()
    assert command.returncode == 0, stderr
    assert "Warning" not in stderr and "Traceback" not in stderr, stderr
    remote, expected = json.loads(stdout), json.loads(local.stdout)
    assert remote["evaluations"] == expected["evaluations"] > 48  # designs asked twice (at a bound) count once
    assert remote["best"] == expected["best"] and remote["start"] == expected["start"]
    assert (tmp_path / "remote.urdf").read_text() == (tmp_path / "local.urdf").read_text()
