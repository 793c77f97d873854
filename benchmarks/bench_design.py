"""Evaluations per second of ``screwkit design-search family`` for each bundled family, whole processes.

Usage: python benchmarks/bench_design.py [--budget 192] [--runs 3]

For each family, the command runs with ``--budget 0`` (start-up, the start's evaluation, the
worker processes) and with ``--budget N`` on the family's default region, in turn, ``--runs``
times; the rate is the designs evaluated beyond the start divided by the difference of the
median wall times. The figures of docs/performance.md come from this script.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import time

FAMILIES = ("planar_rrr", "ups_hexapod", "rss_hexapod", "delta", "prs_ups")


def run(family: str, budget: int) -> tuple[float, int]:
    start = time.perf_counter()
    command = [sys.executable, "-m", "screwkit.cli", "design-search", "family", family, "--budget", str(budget),
               "--json", "--quiet"]
    completed = subprocess.run(command, capture_output=True, text=True, check=True)
    return time.perf_counter() - start, json.loads(completed.stdout)["evaluations"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--budget", type=int, default=192)
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--families", nargs="+", default=FAMILIES, choices=FAMILIES)
    arguments = parser.parse_args()
    print(f"{'family':12s} {'budget 0 (s)':>13s} {'budget N (s)':>13s} {'designs':>8s} {'designs/s':>10s}")
    for family in arguments.families:
        run(family, 0)  # warm the compile cache and the file cache
        empty, full, count = [], [], 0
        for _ in range(arguments.runs):
            empty.append(run(family, 0)[0])
            seconds, count = run(family, arguments.budget)
            full.append(seconds)
        base, total = statistics.median(empty), statistics.median(full)
        print(f"{family:12s} {base:13.2f} {total:13.2f} {count:8d} {(count - 1) / (total - base):10.1f}"
              f"   (wall ranges {min(empty):.2f}-{max(empty):.2f} and {min(full):.2f}-{max(full):.2f} s)")


if __name__ == "__main__":
    main()
