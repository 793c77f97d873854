"""Issue 28's targets in one run: each benchmark side by side on this machine, then one table of target and measure.

Usage: python benchmarks/bench_targets.py [--repeat 3] [--budget 192] [--against REV] [--quick]

Runs, one after the other and each as its own process (their output shown as they go):

* ``bench_planar_map.py``: the paper's Fig. 5 map command against the numpy script (wall time, ratio, peak memory);
* ``bench_hexapod_map.py``: the 8-leg hexapod map command against its numpy script (ratio, peak memory);
* ``bench_lower_mobility.py``: lower-mobility mechanisms' cost per configuration against the hexapod's;
* ``bench_design.py --against``: designs per second of every family against the code the issue was measured on
  (``--against``, a revision of this repository, default the issue's 5a11a80, checked out in a temporary folder
  with ``git worktree``; its kernels compile on its first run).

Then prints each of the issue's "Done when" lines with its target, the measure and whether it is met. ``--quick``
runs each benchmark once and the design searches with a budget of 48 (a check that the runner works, not a
measure). The first-run compile times and the values' identity to earlier code are measured elsewhere
(``docs/performance.md``; ``tests/``).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
ISSUE_REVISION = "5a11a80"


def measured(script: str, arguments: list[str], folder: Path) -> dict:
    """Run one benchmark with ``--json``; its measures (an error names the benchmark)."""
    target = folder / f"{Path(script).stem}.json"
    command = [sys.executable, str(HERE / script), *arguments, "--json", str(target)]
    print(f"\n$ {' '.join(command[1:])}", flush=True)
    if subprocess.run(command).returncode or not target.is_file():
        raise SystemExit(f"{script} failed: its measures are missing")
    return json.loads(target.read_text())


def checkout(revision: str, folder: Path) -> Path | None:
    """A worktree of ``revision`` of this repository in ``folder``, or None (said) when there is none."""
    path = folder / f"screwkit-{revision}"
    done = subprocess.run(["git", "-C", str(HERE.parent), "worktree", "add", "--detach", "-f", str(path), revision],
                          capture_output=True, text=True)
    if done.returncode:
        print(f"no checkout of {revision}: {done.stderr.strip()}; the designs' line is not measured", flush=True)
        return None
    return path


def verdict(value: float, limit: float, larger: bool = False) -> str:
    return "met" if (value >= limit if larger else value <= limit) else "not met"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="pairs (runs) of each side-by-side benchmark")
    parser.add_argument("--budget", type=int, default=192, help="designs of each search")
    parser.add_argument("--against", default=ISSUE_REVISION, help="the revision designs are compared with")
    parser.add_argument("--quick", action="store_true", help="one run of each, small searches: a check, no measure")
    arguments = parser.parse_args()
    repeat, budget = (1, 48) if arguments.quick else (arguments.repeat, arguments.budget)
    rows = []
    with tempfile.TemporaryDirectory(prefix="screwkit-targets-") as temporary:
        folder = Path(temporary)
        planar = measured("bench_planar_map.py", ["--repeat", str(repeat)], folder)
        hexapod = measured("bench_hexapod_map.py", ["--repeat", str(repeat)], folder)
        lower = measured("bench_lower_mobility.py", ["--repeat", str(repeat)], folder)
        other = checkout(arguments.against, folder)
        try:
            designs = (measured("bench_design.py", ["--runs", str(repeat), "--budget", str(budget), "--against",
                                                    str(other)], folder) if other else None)
        finally:
            if other:
                subprocess.run(["git", "-C", str(HERE.parent), "worktree", "remove", "--force", str(other)],
                               capture_output=True)
    for name, values in lower.items():
        if name != "ups_hexapod_8":
            rows.append((f"lower mobility per configuration, {name} / hexapod", "<= 1.3",
                         f"{values['ratio']:.2f} ({values['microseconds']:.1f} us)", verdict(values["ratio"], 1.3)))
    if designs is None:
        rows.append(("designs per second against the issue's code", ">= 2", "not measured", "-"))
    for family, values in (designs or {}).items():
        rows.append((f"designs per second, {family}, against {arguments.against}", ">= 2",
                     f"{values['ratio']:.2f} ({values['this']:.1f} against {values['other']:.1f})",
                     verdict(values["ratio"], 2.0, larger=True)))
    rows += [
        ("Fig. 5 map command, wall", "<= 0.8 s", f"{planar['command_wall_s']:.2f} s",
         verdict(planar["command_wall_s"], 0.8)),
        ("Fig. 5 map command / numpy script, wall", "<= 0.35", f"{planar['ratio_wall']:.3f}",
         verdict(planar["ratio_wall"], 0.35)),
        ("hexapod map command / numpy script, wall", "<= 0.2", f"{hexapod['ratio_wall']:.3f}",
         verdict(hexapod["ratio_wall"], 0.2)),
        ("Fig. 5 map peak memory / script's", "<= 1.5", f"{planar['memory_ratio']:.2f}",
         verdict(planar["memory_ratio"], 1.5)),
        ("hexapod map peak memory / script's", "<= 1.5", f"{hexapod['memory_ratio']:.2f}",
         verdict(hexapod["memory_ratio"], 1.5)),
        ("largest difference command - script, Fig. 5 / hexapod", "<= 1e-12",
         f"{planar['difference']:.1e} / {hexapod['difference']:.1e}",
         verdict(max(planar["difference"], hexapod["difference"]), 1e-12)),
    ]
    print(f"\nissue 28's targets, measured in this run{' (--quick: not a measure)' if arguments.quick else ''}:")
    width = max(len(row[0]) for row in rows)
    for line, target, value, met in rows:
        print(f"  {line:{width}s}  {target:>9s}  {value:>28s}  {met}")


if __name__ == "__main__":
    main()
