"""Nothing computed is lost, nothing hangs, every environment runs: faults of the machine and slips of the user.

Each case runs the ``screwkit`` command in a subprocess as users meet it: an output name in upper case, a full
disk (a 64 KiB tmpfs), a folder made read-only mid-run, a read-only install with no writable home (a private
mount namespace whose root is remounted read-only), a design search killed however it is killed, a state file
cut off mid-record or empty, saved results drawn again, and small input mistakes. What needs root (mounting a
tmpfs, ``unshare``) skips, saying why, where the machine does not allow it. Subprocess time limits only guard
against a hang; nothing here measures how long anything takes.
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from helpers import one_line_error, screwkit
from screwkit.io.loader import load
from screwkit.studies import indices_at_pose, indices_at_poses
from screwkit.studies.maps import disc_size

SMALL_DISC = ("--radius", "0.3", "--step", "0.1", "--phi-step", "30")
"""A planar family's region of 29 points x 12 angles: a design in a fraction of a second."""
SEARCH = ("design-search", "family", "planar_rrr", *SMALL_DISC, "--popsize", "4")
"""A search of the planar family: 12 designs per generation (3 varied parameters x 4)."""
SMALL_MAP = ("map", "planar_5rrr", "--radius", "0.1", "--step", "0.05", "--phi-step", "90")
"""13 grid points x 4 orientations."""
LARGE_MAP = ("map", "planar_5rrr", "--radius", "0.6", "--step", "0.01", "--phi-step", "30")
"""135,468 configurations: a netCDF file of about 0.8 MB."""
MAPPING = ("planar_5rrr: ",)
"""The lines a map says as it works (its size before it starts, its time when done)."""


def run(arguments, **options) -> subprocess.Popen:
    """The command started in a subprocess (``-W error``), its output piped."""
    return subprocess.Popen([sys.executable, "-W", "error", "-m", "screwkit.cli", *map(str, arguments)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **options)


# -- outputs: one rule for names, writes that fail in one line ------------------------------------


def test_upper_case_suffixes_are_written_as_the_check_accepted_them(tmp_path):
    """M.NC passed the check, then the writer (case-sensitive) threw the finished map away with a traceback."""
    mapped = screwkit(*SMALL_MAP, "--out", tmp_path / "M.NC", "--figure", tmp_path / "M.PNG")
    assert mapped.returncode == 0, mapped.stderr
    with xr.open_dataset(tmp_path / "M.NC", engine="scipy") as dataset:
        assert int(np.isfinite(dataset["f_o1"].values).sum()) == 13
    assert (tmp_path / "M.PNG").read_bytes().startswith(b"\x89PNG")
    swept = screwkit("sweep", "planar_5rrr", "--phi", "0:360:90", "--out", tmp_path / "s.CSV")
    assert swept.returncode == 0, swept.stderr
    assert (tmp_path / "s.CSV").read_text().splitlines()[0].startswith("phi,")
    searched = screwkit(*SEARCH, "--budget", "0", "--table", tmp_path / "T.CSV", "--urdf", tmp_path / "B.URDF",
                        "--json", "--quiet")
    assert searched.returncode == 0, searched.stderr
    assert (tmp_path / "T.CSV").read_text().splitlines()[0].startswith("evaluation,base_radius,")
    assert load(tmp_path / "B.URDF").name.startswith("planar_rrr")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["B.URDF", "M.NC", "M.PNG", "T.CSV", "s.CSV"]


@pytest.fixture
def small_disk(tmp_path):
    """A 64 KiB tmpfs: a disk that fills. Unmounted after the test."""
    folder = tmp_path / "disk"
    folder.mkdir()
    if os.geteuid() != 0:
        pytest.skip("mounting a small tmpfs (a disk that fills) needs root")
    mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", str(folder)], capture_output=True,
                             text=True)
    if mounted.returncode:
        pytest.skip(f"cannot mount a tmpfs on this machine: {mounted.stderr.strip()}")
    try:
        yield folder
    finally:
        subprocess.run(["umount", "-l", str(folder)], capture_output=True)


def fill(folder: Path, leave: int = 0) -> Path:
    """Fill the disk of ``folder`` up to ``leave`` bytes."""
    stats = os.statvfs(folder)
    filler = folder / "filler"
    with open(filler, "wb") as handle:
        try:
            handle.write(b"\0" * max(0, stats.f_bavail * stats.f_frsize - leave))
            handle.flush()
        except OSError:  # full already
            pass
    return filler


def test_a_full_disk_is_one_line_and_leaves_no_partial_file(small_disk):
    """Disk full gave a multi-line OSError traceback, and --json printed nothing."""
    out = small_disk / "map.nc"
    one_line_error(screwkit(*LARGE_MAP, "--out", out), f"Cannot write {out}: No space left on device",
                   "no partial file was left", after=MAPPING)
    assert os.listdir(small_disk) == []  # neither the file nor a temporary one
    fill(small_disk)
    table = small_disk / "table.nc"
    searched = screwkit(*SEARCH, "--budget", "0", "--table", table, "--json", "--quiet")
    assert searched.returncode == 1 and searched.stderr == "", searched.stderr
    error = json.loads(searched.stdout)["error"]
    assert error.startswith(f"Cannot write {table}: No space left on device") and "\n" not in error
    assert os.listdir(small_disk) == ["filler"]
    with open(small_disk / "stdout.csv", "w") as stdout:  # data on stdout, redirected to the full disk
        swept = subprocess.run([sys.executable, "-W", "error", "-m", "screwkit.cli", "sweep", "planar_5rrr", "--phi",
                                "0:360:30", "--quiet"], stdout=stdout, stderr=subprocess.PIPE, text=True, timeout=300)
    assert swept.returncode == 1 and swept.stderr == "Error: Cannot write to stdout: No space left on device.\n"


def test_a_folder_made_read_only_mid_run_is_one_line_and_leaves_no_partial_file(small_disk):
    """The output folder passes the check, then loses its permission while the map computes: the command is
    stopped once it has said its size (before its work), the folder remounted read-only, and the command let go."""
    out = small_disk / "map.nc"
    command = run(["map", "planar_5rrr", "--radius", "0.5", "--step", "0.01", "--phi-step", "2", "--out", out])
    try:
        first = command.stderr.readline()
        command.send_signal(signal.SIGSTOP)
        assert first.startswith(MAPPING[0]), first
        remounted = subprocess.run(["mount", "-o", "remount,ro", str(small_disk)], capture_output=True, text=True)
        command.send_signal(signal.SIGCONT)
        assert remounted.returncode == 0, remounted.stderr
        stdout, stderr = command.communicate(timeout=300)
    finally:
        if command.poll() is None:
            command.kill()
    result = subprocess.CompletedProcess(command.args, command.returncode, stdout, first + stderr)
    one_line_error(result, f"Cannot write {out}: Read-only file system", "no partial file was left", after=MAPPING)
    assert os.listdir(small_disk) == []


def test_a_state_on_a_full_disk_keeps_whole_records_and_resumes(small_disk):
    """A batch that does not fit is not appended at all (it used to leave a record cut off, after which the next
    record was appended to the broken line and never stored); freed, the same command resumes from the state."""
    arguments = (*SEARCH, "--budget", "48", "--json", "--quiet")
    state = small_disk / "state.jsonl"
    filler = fill(small_disk, leave=8192)  # the header and one or two generations
    failed = screwkit(*arguments, "--state", state)
    assert failed.returncode == 1 and failed.stderr == "", failed.stderr
    error = json.loads(failed.stdout)["error"]
    assert error.startswith(f"Cannot append to the design-search state {state}: No space left on device; it keeps "
                            "the ") and "a run with it resumes from them" in error
    content = state.read_text()
    assert content.endswith("\n")
    records = [json.loads(line) for line in content.splitlines()[1:]]
    assert f"keeps the {len(records)} evaluations" in error and len(records) >= 12  # the start and a generation
    filler.unlink()
    resumed = json.loads(screwkit(*arguments, "--state", state).stdout)
    fresh = json.loads(screwkit(*arguments).stdout)
    assert resumed["replayed"] == len(records) and resumed["best"] == fresh["best"]
    assert [json.loads(line) for line in state.read_text().splitlines()[1:]][:len(records)] == records


# -- the design search's state file ---------------------------------------------------------------


def test_a_state_cut_off_mid_record_resumes_and_stores_the_next_records_whole(tmp_path):
    """A run killed while writing leaves its last record cut off: it is dropped (and computed again), and what
    follows is stored on lines of its own."""
    state = tmp_path / "state.jsonl"
    first = screwkit(*SEARCH, "--budget", "12", "--json", "--quiet", "--state", state)
    assert first.returncode == 0, first.stderr
    content = state.read_bytes()
    last = content.splitlines(keepends=True)[-1]
    state.write_bytes(content[:-len(last) // 2])  # half of the last record
    stored = len(content.splitlines()) - 2
    resumed = screwkit(*SEARCH, "--budget", "24", "--json", "--state", state)
    assert resumed.returncode == 0, resumed.stderr
    assert f"dropped the cut-off last record of {state}" in resumed.stderr
    summary = json.loads(resumed.stdout)
    assert summary["replayed"] == stored
    lines = state.read_text().splitlines()
    assert len(lines) - 1 == summary["replayed"] + summary["computed"]  # every record whole, each on its line
    assert all(set(json.loads(line)) == {"key", "metrics"} for line in lines[1:])
    fresh = json.loads(screwkit(*SEARCH, "--budget", "24", "--json", "--quiet").stdout)
    assert summary["best"] == fresh["best"] and summary["evaluations"] == fresh["evaluations"]
    # A line on which an earlier version appended a record to a cut-off one gives that record back.
    header, *records = state.read_text().splitlines()
    glued = records[-2][:40] + records[-1]
    state.write_text("\n".join([header, *records[:-2], glued]) + "\n")
    again = json.loads(screwkit(*SEARCH, "--budget", "24", "--json", "--quiet", "--state", state).stdout)
    assert again["replayed"] == summary["evaluations"] - 1 and again["best"] == fresh["best"]


def test_an_empty_state_file_starts_a_new_search_and_says_so(tmp_path):
    """A 0-byte state gave 'list index out of range'."""
    state = tmp_path / "state.jsonl"
    state.touch()
    result = screwkit(*SEARCH, "--budget", "0", "--state", state)
    assert result.returncode == 0, result.stderr
    assert f"the design-search state {state} is empty (0 bytes): a new search starts in it" in result.stderr
    header, record = state.read_text().splitlines()
    assert json.loads(header)["screwkit_design_state"] == 1 and set(json.loads(record)) == {"key", "metrics"}


def test_the_state_and_the_table_cannot_be_the_same_file(tmp_path, monkeypatch):
    """--state t.csv --table t.csv was accepted, and the table replaced the state."""
    state = tmp_path / "t.csv"
    state.write_text("an earlier search's state\n")
    monkeypatch.chdir(tmp_path)
    for table in (state, "t.csv", "./t.csv"):
        one_line_error(screwkit(*SEARCH, "--state", state, "--table", table, "--overwrite"),
                       f"--table {table} and --state {state} name the same file")
    assert state.read_text() == "an earlier search's state\n"


# -- processes end with their parent ----------------------------------------------------------------


def children_of(pid: int) -> dict[int, str]:
    """Every living descendant of ``pid``: its command line."""
    parents, commands = {}, {}
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            status = (entry / "stat").read_text()
            commands[int(entry.name)] = (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode()
        except OSError:
            continue
        fields = status[status.rindex(")") + 2:].split()
        if fields[0] != "Z":  # a zombie has ended
            parents[int(entry.name)] = int(fields[1])
    found, frontier = {}, [pid]
    while frontier:
        parent = frontier.pop()
        for child, its_parent in parents.items():
            if its_parent == parent and child not in found:
                found[child] = commands[child]
                frontier.append(child)
    return found


def alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return state[state.rindex(")") + 2] != "Z"


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads the process table from /proc (Linux)")
@pytest.mark.parametrize("stop", [signal.SIGKILL, signal.SIGTERM], ids=["SIGKILL", "SIGTERM"])
def test_a_killed_design_search_leaves_no_process_behind(stop, tmp_path):
    """Its two evaluation processes and a resource tracker (about 0.5 GB) outlived a killed search. The
    deadlines are hang guards: the processes end within a second."""
    with open(tmp_path / "stderr.txt", "w") as errors:
        command = subprocess.Popen([sys.executable, "-W", "error", "-m", "screwkit.cli", *SEARCH, "--budget", "2000",
                                    "--json", "--quiet"], stdout=subprocess.DEVNULL, stderr=errors,
                                   start_new_session=True)
    try:
        deadline, workers = time.monotonic() + 120, {}
        while time.monotonic() < deadline:
            assert command.poll() is None, (tmp_path / "stderr.txt").read_text()
            workers = {pid: line for pid, line in children_of(command.pid).items()
                       if "multiprocessing.spawn" in line or "resource_tracker" in line}
            if sum("multiprocessing.spawn" in line for line in workers.values()) >= 2:
                break
            time.sleep(0.05)
        assert any("resource_tracker" in line for line in workers.values()), workers
        os.kill(command.pid, stop)  # the main process alone, as the out-of-memory killer or `kill PID` do
        command.wait(timeout=60)
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline and any(alive(pid) for pid in workers):
            time.sleep(0.05)
        survivors = {pid: line for pid, line in workers.items() if alive(pid)}
        assert not survivors, survivors
    finally:
        try:
            os.killpg(command.pid, signal.SIGKILL)  # whatever is left of its group
        except ProcessLookupError:
            pass


# -- figures --------------------------------------------------------------------------------------


def test_figure_options_are_checked_before_the_work(tmp_path):
    """--vmin 1 --vmax 0 computed the map, wrote the data, then ended in a traceback. The check comes before the
    mechanism is even loaded: a missing file is not reached."""
    for mechanism in ("planar_5rrr", tmp_path / "missing.urdf"):
        one_line_error(screwkit("map", mechanism, "--radius", "0.6", "--step", "0.005", "--out", tmp_path / "m.nc",
                                "--figure", tmp_path / "m.png", "--vmin", "1", "--vmax", "0"),
                       "Expected finite --vmin < --vmax", "got --vmin 1 --vmax 0")
    one_line_error(screwkit(*SMALL_MAP, "--vmin", "2"), "got --vmin 2 --vmax 1 (default)")
    one_line_error(screwkit(*SEARCH, "--figure", tmp_path / "f.png", "--vmin", "0.5", "--vmax", "0.5"),
                   "Expected finite --vmin < --vmax")
    assert os.listdir(tmp_path) == []


def test_plot_draws_a_saved_map_or_sweep_again_as_it_was_drawn(tmp_path):
    mapped = screwkit(*SMALL_MAP, "--out", tmp_path / "m.nc", "--figure", tmp_path / "m.png", "--vmin", "0.2",
                      "--quiet")
    swept = screwkit("sweep", "planar_5rrr", "--phi", "0:360:30", "--out", tmp_path / "s.nc", "--figure",
                     tmp_path / "s.png", "--quiet")
    assert mapped.returncode == 0 and swept.returncode == 0, mapped.stderr + swept.stderr
    drawn = screwkit("plot", tmp_path / "m.nc", "--figure", tmp_path / "again.PNG", "--vmin", "0.2")
    assert drawn.returncode == 0, drawn.stderr
    assert drawn.stderr == f"wrote {tmp_path / 'again.PNG'}: the map of planar_5rrr\n"
    assert (tmp_path / "again.PNG").read_bytes() == (tmp_path / "m.png").read_bytes()
    assert screwkit("plot", tmp_path / "s.nc", "--figure", tmp_path / "again.svg", "--quiet").returncode == 0
    assert screwkit("plot", tmp_path / "s.nc", "--figure", tmp_path / "s2.png", "--quiet").returncode == 0
    assert (tmp_path / "s2.png").read_bytes() == (tmp_path / "s.png").read_bytes()
    assert (tmp_path / "again.svg").read_text().startswith("<?xml")
    (tmp_path / "fake.nc").write_bytes(b"not a netCDF file")
    for arguments, message in [
        ((tmp_path / "missing.nc", "--figure", tmp_path / "x.png"), "missing.nc: no such file"),
        ((tmp_path, "--figure", tmp_path / "x.png"), "is a folder; expected the netCDF file (.nc)"),
        ((tmp_path / "m.png", "--figure", tmp_path / "x.png"), "expected the netCDF file (.nc) of a map or a sweep"),
        ((tmp_path / "fake.nc", "--figure", tmp_path / "x.png"),
         "fake.nc: cannot be read as a netCDF file (it is not a valid NetCDF 3 file)."),  # not "(Error: .../fake.nc"
        ((tmp_path / "s.nc", "--figure", tmp_path / "x.png", "--vmin", "0"), "holds a sweep"),
        ((tmp_path / "m.nc", "--figure", tmp_path / "x.png", "--vmin", "1", "--vmax", "0"), "--vmin < --vmax"),
        ((tmp_path / "m.nc", "--figure", tmp_path / "m.png"), "the file exists; pass --overwrite"),
        ((tmp_path / "m.nc", "--figure", tmp_path / "x.jpg"), "must end in .png, .pdf, .svg"),
    ]:
        one_line_error(screwkit("plot", *arguments), message)
    # named as given, relative: scipy names it absolutely ("(/tmp/.../it is not a valid ..." before)
    one_line_error(screwkit("plot", "fake.nc", "--figure", "x.png", cwd=tmp_path),
                   "Error: fake.nc: cannot be read as a netCDF file (it is not a valid NetCDF 3 file).")
    assert not (tmp_path / "x.png").exists()


KILLED_WHILE_SAVING = """
import os, signal, sys
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
from screwkit.plots import save_figure

figure = plt.figure()
def killed_while_saving(temporary, **options):
    with open(temporary, "wb") as handle:
        handle.write(b"\\x89PNG half a figure")
    os.kill(os.getpid(), signal.SIGKILL)
figure.savefig = killed_while_saving
save_figure(figure, sys.argv[1])
"""


def test_the_temporary_figure_of_a_run_killed_while_saving_is_removed_and_named(tmp_path):
    """The figure's temporary file did not follow the data files' naming, so it was never found."""
    figure = tmp_path / "map.png"
    killed = subprocess.run([sys.executable, "-c", KILLED_WHILE_SAVING, str(figure)], capture_output=True)
    assert killed.returncode == -signal.SIGKILL
    (leftover,) = tmp_path.iterdir()
    assert leftover.name.startswith(".map.png.tmp-")
    dead = int(leftover.name.split("-")[1])
    older = tmp_path / f".map.tmp-{dead}.png"  # what earlier versions left
    older.write_bytes(b"half a figure")
    result = screwkit(*SMALL_MAP, "--figure", figure)
    assert result.returncode == 0, result.stderr
    (line,) = [line for line in result.stderr.splitlines() if line.startswith("removed ")]
    removed, said = line[len("removed "):].split(": ", 1)
    assert sorted(removed.split(", ")) == sorted([str(leftover), str(older)])
    assert said == f"temporary file(s) left by an earlier run killed while writing {figure}"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["map.png"]


# -- a read-only install with no writable home --------------------------------------------------


def read_only_world(tmp_path: Path, *, writable_temporary: bool):
    """Runs commands where the whole file system is read-only (the root remounted read-only in a private mount
    namespace: the install, the home, /tmp), except ``out`` and, if ``writable_temporary``, the temporary
    folder (TMPDIR) screwkit falls back on. Returns a function running one command there."""
    if os.geteuid() != 0 or shutil.which("unshare") is None:
        pytest.skip("a read-only install is made with `unshare -m` and read-only mounts, which need root")
    trial = subprocess.run(["unshare", "-m", "--propagation", "private", "mount", "-o", "remount,bind,ro", "/"],
                           capture_output=True, text=True)
    if trial.returncode:
        pytest.skip(f"cannot remount the root read-only in a private mount namespace here: {trial.stderr.strip()}")
    folders = {name: tmp_path / name for name in ("home", "tmp", "out")}
    for folder in folders.values():
        folder.mkdir()
    writable = [folders["out"]] + ([folders["tmp"]] if writable_temporary else [])
    script = "".join(f'mount --bind "{folder}" "{folder}" && ' for folder in writable)
    script += 'mount -o remount,bind,ro / && cd "$WORK" && exec "$@"'
    environment = {key: value for key, value in os.environ.items() if key not in ("XDG_CACHE_HOME", "NUMBA_CACHE_DIR")}
    environment.update(HOME=str(folders["home"]), TMPDIR=str(folders["tmp"]),
                       WORK=str(folders["out"] if writable_temporary else folders["home"]))

    def run_there(*arguments) -> subprocess.CompletedProcess:
        return subprocess.run(["unshare", "-m", "--propagation", "private", "sh", "-c", script, "sh", sys.executable,
                               "-W", "error", "-m", "screwkit.cli", *map(str, arguments)],
                              capture_output=True, text=True, env=environment, timeout=900)

    return run_there, folders


def seed_numba_cache(cache: Path, *, leave_out: str) -> None:
    """Copies the kernels numba has already cached beside screwkit's sources (as earlier tests left them) to
    where numba looks for them under ``NUMBA_CACHE_DIR=cache``, but not those of the function ``leave_out``
    (``module.function``): warmup then compiles that one and writes it there, without compiling every other
    kernel again (a minute on two cores). A kernel not yet cached is compiled there too."""
    from numba.core.caching import _CacheLocator

    cache.mkdir(mode=0o700)
    for cached in Path(__file__).resolve().parents[1].joinpath("screwkit").rglob("__pycache__/*.nb[ic]"):
        if cached.name.startswith(f"{leave_out}-"):
            continue
        target = cache / _CacheLocator.get_suitable_cache_subpath(str(cached.parent.parent / "source.py"))
        target.mkdir(parents=True, exist_ok=True)
        shutil.copy2(cached, target / cached.name)


@pytest.mark.slow
def test_a_read_only_install_with_no_writable_home_computes_caching_in_the_temporary_folder(tmp_path):
    """numba could cache nowhere ('cannot cache function ... no locator available'): every computing command and
    warmup died in a traceback, --json printed nothing. Now the kernels are cached in TMPDIR, said in one line."""
    run_there, folders = read_only_world(tmp_path, writable_temporary=True)
    cache = folders["tmp"] / f"screwkit-numba-{os.getuid()}"
    left_out = "frames.chain_frames_kernel"  # the forward kinematics (about 2 s) is compiled and cached there
    seed_numba_cache(cache, leave_out=left_out)
    notice = f"screwkit: numba cannot write its cache in {Path(__file__).resolve().parents[1] / 'screwkit'}"
    warm = run_there("warmup")
    assert warm.returncode == 0, warm.stderr
    lines = warm.stderr.splitlines()
    assert lines[0].startswith(notice) and f"compiled kernels are cached in {cache} (set NUMBA_CACHE_DIR" in lines[0]
    assert lines[-1] == "screwkit kernels ready" and "Traceback" not in warm.stderr
    assert any(line.split()[0] == "chain_frames_kernel" and " compiled, ready after " in line for line in lines), lines
    assert any(cache.rglob(f"{left_out}-*.nbi")) and any(cache.rglob(f"{left_out}-*.nbc"))
    analysed = run_there("analyze", "planar_5rrr", "--pose", "paper_fig_2a", "--json")
    assert analysed.returncode == 0 and analysed.stderr == "", analysed.stderr
    assert round(json.loads(analysed.stdout)["f_o"]["1"], 4) == 0.6793
    mapped = run_there(*SMALL_MAP, "--closed-forms", "--out", folders["out"] / "m.nc")
    assert mapped.returncode == 0, mapped.stderr
    assert mapped.stderr.splitlines()[0].startswith(notice)  # said in one line, and nothing compiled again
    assert "compiling" not in mapped.stderr and (folders["out"] / "m.nc").is_file()
    assert any(cache.rglob("*.nbi")) and not any((folders["home"]).iterdir())
    # the loaded mechanisms are kept in the temporary folder too (a private folder), and read back silently
    models = folders["tmp"] / f"screwkit-models-{os.getuid()}"
    assert any(models.glob("*.mechanism")) and models.stat().st_mode & 0o777 == 0o700
    again = run_there("analyze", "planar_5rrr", "--pose", "paper_fig_2a", "--json")
    assert again.returncode == 0 and again.stderr == "" and again.stdout == analysed.stdout, again.stderr


def test_a_read_only_install_with_nowhere_to_cache_compiles_without_a_cache(tmp_path):
    """The root, the home and every temporary folder read-only: kernels are compiled in the process, said once."""
    run_there, folders = read_only_world(tmp_path, writable_temporary=False)
    swept = run_there("sweep", "planar_5rrr", "--phi", "0:360:90", "--closed-forms")
    assert swept.returncode == 0, swept.stderr
    first = swept.stderr.splitlines()[0]
    assert first.startswith("screwkit: numba cannot write its cache in ") and first.endswith(
        ": kernels are compiled on every run (set NUMBA_CACHE_DIR to a writable folder)"), first
    assert "Traceback" not in swept.stderr and swept.stderr.count("numba cannot write") == 1
    assert len(swept.stdout.splitlines()) == 5 and swept.stdout.startswith("phi,")


# -- input slips ----------------------------------------------------------------------------------


def test_a_grid_step_that_does_not_divide_its_range_is_refused(tmp_path):
    """--grid x:-0.2:0.2:0.03 silently stopped at 0.19, not at the 0.2 the help promises."""
    refused = screwkit("map", "planar_5rrr", "--grid", "x:-0.2:0.2:0.03", "--grid", "y:-0.05:0.05:0.05",
                       "--over", "phi:0:360:90")
    one_line_error(refused, "--grid x:-0.2:0.2:0.03 with a STEP that divides STOP - START", "13.33 steps",
                   "a stop of 0.19", "a step of 0.0307692")
    out = tmp_path / "grid.nc"
    kept = screwkit("map", "planar_5rrr", "--grid", "x:-0.2:0.2:0.025", "--grid", "y:-0.05:0.05:0.05",
                    "--over", "phi:0:360:90", "--out", out, "--quiet")
    assert kept.returncode == 0, kept.stderr
    with xr.open_dataset(out, engine="scipy") as dataset:
        assert dataset["x"].size == 17 and dataset["x"].values[-1] == pytest.approx(0.2, abs=1e-12)


@pytest.mark.parametrize("arguments, needle", [
    (("analyze", "planar_5rrr", "--pose", "0", "0", "1e308"), "in --pose (phi), got 1e+308 deg"),
    (("analyze", "ups_hexapod_8", "--pose", "0", "0", "1", "0", "0", "-1e20"), "in --pose (yaw), got -1e+20 deg"),
    (("sweep", "planar_5rrr", "--phi", "0:1e20:1e19"), "in --phi, got 1e+20 deg"),
    (("map", "ups_hexapod_8", "--grid", "x:-0.02:0.02:0.02", "--grid", "y:-0.02:0.02:0.02", "--over",
      "yaw:0:1e20:1e19"), "in --over yaw:0:1e20:1e19, got 1e+20 deg"),
])
def test_angles_beyond_a_hundred_turns_are_refused(arguments, needle):
    """Angles of 1e308 or 1e20 deg were analysed as if they meant something (a double cannot tell one turn of
    1e20 deg from the next)."""
    one_line_error(screwkit(*arguments), "Expected angles of at most 36000 deg (100 turns) either way", needle,
                   after=("screwkit: compiling ",))


@pytest.mark.parametrize("arguments, needle", [
    (("analyze", "planar_5rrr", "--pose", "1e300", "0", "0"), "in --pose (x), got 1e+300 m"),
    (("analyze", "planar_4rpr", "--pose", "0", "1e160", "0"), "in --pose (y), got 1e+160 m"),
    (("analyze", "ups_hexapod_8", "--pose", "0", "0", "-1e300", "0", "0", "0"), "in --pose (z), got -1e+300 m"),
    (("sweep", "planar_5rrr", "--at", "1e300 0 0", "--phi", "0:90:45"), "in --at (x), got 1e+300 m"),
])
def test_positions_beyond_a_million_length_scales_are_refused(arguments, needle):
    """Such poses overflowed the closures' squares: the 4-RPR's slider was "at -1.20416 m" at y = 1e160 m, the
    hexapod's legs missed their closures "by nan m", with numpy's overflow warnings on stderr."""
    one_line_error(screwkit(*arguments), "Expected positions within 1e+06 length scales", needle,
                   after=("screwkit: compiling ",))


def test_the_position_bound_follows_the_mechanism_not_its_unit_or_world_frame(tmp_path):
    """A million length scales from the home pose: the same poses refused and analysed for the file in metres, in
    millimetres and moved far in the world frame; a pose within the bound is unreachable, not refused."""
    from helpers import in_millimetres, moved_in_the_world
    from screwkit.io.loader import bundled_path

    metres = load("planar_5rrr")
    reach = 1e6 * metres.length_scale
    text = bundled_path("planar_5rrr").read_text()
    (tmp_path / "mm.urdf").write_text(in_millimetres(text, declare=True))
    (tmp_path / "moved.urdf").write_text(moved_in_the_world(text, [3e3, -2e3, 0.0], [0.0, 0.0, 0.7]))
    files = [load(tmp_path / "mm.urdf"), load(tmp_path / "moved.urdf")]
    for mechanism in [metres, *files]:
        assert mechanism.length_scale == pytest.approx(metres.length_scale, rel=1e-12)
        home = mechanism.home_pose
        with pytest.raises(ValueError, match=r"Expected positions within 1e\+06 length scales"):
            indices_at_poses(mechanism, [home + [1.01 * reach, 0.0, 0.0]])
        assert not indices_at_poses(mechanism, [home + [0.99 * reach, 0.0, 0.0]]).reachable[0]
        assert indices_at_poses(mechanism, [home]).reachable[0]


def test_an_angle_of_a_hundred_turns_is_the_angle_itself():
    at_bound = screwkit("analyze", "planar_5rrr", "--pose", "0.1", "0", "36000", "--json")
    at_zero = screwkit("analyze", "planar_5rrr", "--pose", "0.1", "0", "0", "--json")
    assert at_bound.returncode == 0 and at_zero.returncode == 0, at_bound.stderr
    bound, zero = json.loads(at_bound.stdout), json.loads(at_zero.stdout)
    assert bound["iti"] == pytest.approx(zero["iti"], abs=1e-9) and bound["f_o"] == pytest.approx(zero["f_o"])


def test_a_folder_given_as_the_mechanism_is_named_a_folder(tmp_path, monkeypatch):
    """It was reported as 'no such file'."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "robots").mkdir()
    for given in (tmp_path / "robots", "robots", "robots/"):
        one_line_error(screwkit("info", given), f"{given}: is a folder; expected a mechanism file")
    one_line_error(screwkit("convert", "robots", "out.urdf"), "File 'robots' is a directory")


def test_the_python_api_refuses_complex_and_boolean_poses_and_names_what_arrived_instead_of_a_mechanism():
    five = load("planar_5rrr")
    with pytest.raises(ValueError, match=r"expected real numbers \(m, rad\), got complex values"):
        indices_at_pose(five, [0.1 + 0.5j, 0.0, 0.0])
    with pytest.raises(ValueError, match=r"expected real numbers \(m, rad\), got boolean values"):
        indices_at_poses(five, np.array([[True, False, True]]))
    with pytest.raises(ValueError, match=r"Expected angles of at most 628.319 rad \(100 turns\)"):
        indices_at_pose(five, [0.0, 0.0, 1e20])
    with pytest.raises(TypeError, match=r"Expected the name of a bundled mechanism .* or a file path, got NoneType"):
        load(None)
    with pytest.raises(TypeError, match=r"indices_at_pose expects a Mechanism, got the name 'planar_5rrr': load it "
                                        r"first, mechanism = screwkit.io.loader.load\('planar_5rrr'\)"):
        indices_at_pose("planar_5rrr", [0.0, 0.0, 0.0])
    with pytest.raises(TypeError, match=r"indices_at_poses expects a Mechanism \(from screwkit.io.loader.load\), got "
                                        r"NoneType"):
        indices_at_poses(None, [[0.0, 0.0, 0.0]])


def test_a_map_states_its_size_before_it_starts_when_stderr_is_not_a_terminal():
    """It was said only at the end (in a progress bar when stderr is a terminal)."""
    command = run(["map", "planar_5rrr", "--radius", "0.6", "--step", "0.005", "--phi-step", "1"])
    try:
        first = command.stderr.readline()
        still_working = command.poll() is None
    finally:
        command.kill()
        command.communicate()
    size = disc_size(load("planar_5rrr"), 0.6, 0.005, 1.0)
    assert first == f"planar_5rrr: mapping {size.configurations:,} configurations ({size.grid_points:,} grid points " \
                    f"x 360 orientations)\n"
    assert still_working


def test_range_values_are_the_decimals_written():
    """START + k STEP in doubles drifts from the decimal written (-0.2 + 3 x 0.1 = 0.10000000000000003): the values
    are the doubles nearest START + k STEP computed in decimals, as Python reads those decimals typed."""
    from decimal import Decimal

    from screwkit.cli.options import parse_range

    for text, include in (("-0.2:0.2:0.1", True), ("0:1:0.1", True), ("0.05:0.6:0.05", False),
                          ("-1.3:2.6:0.013", False), ("1e-3:5e-2:1e-3", False), ("100000:100010:2.5", True)):
        values = parse_range(text, "--grid", include_stop=include)
        start, _, step = (Decimal(part) for part in text.split(":"))
        assert values.tolist() == [float(start + k * step) for k in range(len(values))], text
    degrees = parse_range("0:360:0.36", "--over", angular=True)
    assert np.array_equal(degrees, np.deg2rad([float(Decimal("0.36") * k) for k in range(1000)]))


def test_a_swept_coordinate_reads_back_as_written_and_is_the_pose_typed():
    """The CSV's x column is -0.2, -0.1, 0.0, 0.1 (not 0.10000000000000003), and its row at 0.1 is `analyze --pose`
    at 0.1."""
    swept = screwkit("sweep", "planar_5rrr", "--sweep", "x:-0.2:0.2:0.1")
    assert swept.returncode == 0, swept.stderr
    lines = swept.stdout.splitlines()
    header = lines[0].split(",")
    assert [line.split(",")[0] for line in lines[1:]] == ["-0.2", "-0.1", "0.0", "0.1"]
    row = dict(zip(header, lines[-1].split(",")))
    alone = screwkit("analyze", "planar_5rrr", "--pose", f"0.1 {row['y']} {row['phi']}", "--json")
    assert alone.returncode == 0, alone.stderr
    report = json.loads(alone.stdout)
    assert float(row["lmti"]) == pytest.approx(report["lmti"], abs=1e-12)
    assert float(row["iti"]) == pytest.approx(report["iti"], abs=1e-12)


RIGID_URDF = """<robot name="rigid">
  <link name="base"/><link name="link1"/><link name="link2"/><link name="link3"/><link name="end_a"/>
  <link name="end_b"/><link name="effector"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="link1"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="link1"/><child link="link2"/><origin xyz="1 0 0"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="end_a_frame" type="fixed"><parent link="link2"/><child link="end_a"/><origin xyz="1 0 0"/></joint>
  <joint name="effector_frame" type="fixed"><parent link="link2"/><child link="effector"/><origin xyz="0.5 0 0"/>
  </joint>
  <joint name="j3" type="revolute"><parent link="base"/><child link="link3"/><origin xyz="2 0.5 0"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="end_b_frame" type="fixed"><parent link="link3"/><child link="end_b"/><origin xyz="0 -0.5 0"/></joint>
</robot>
"""
"""Two revolutes in a row from the base welded (a Gepetto 6d closure) to a third revolute's link: three planar
joints and three planar constraints, a rigid triangle."""


def test_a_file_whose_closures_leave_the_platform_no_motion_is_refused_as_rigid(tmp_path):
    """The frame-output file's platform cannot move at all: one line that says so (it said that an output point
    could not move, "every platform motion is a rotation about it", of a file with no point output)."""
    (tmp_path / "robot.urdf").write_text(RIGID_URDF)
    (tmp_path / "robot.yaml").write_text("closed_loop: [['end_a', 'end_b']]\ntype: ['6d']\nname_mot: ['j1']\n")
    message = one_line_error(screwkit("analyze", tmp_path / "robot.urdf"), "robot.urdf",
                             "the platform cannot move", "(DOF 0)")
    assert "output point" not in message
