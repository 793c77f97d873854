"""Evaluations per second of ``screwkit design-search family`` for each bundled family, whole processes.

Usage: python benchmarks/bench_design.py [--budget 192] [--runs 3] [--against /path/to/other/checkout] [--json FILE]

For each family, the command runs with ``--budget 0`` (start-up, the start's evaluation, the
worker processes) and with ``--budget N`` on the family's default region, in turn, ``--runs``
times; the rate is the designs evaluated beyond the start divided by the difference of the
median wall times. With ``--against``, the same runs of another checkout (its folder put first on
``PYTHONPATH``) alternate with these, run by run, and the ratio of the two rates is printed: issue
28's "designs per second >= 2 x" is measured so, side by side in one run. The figures of
docs/performance.md come from this script.
"""

from __future__ import annotations

import argparse
import functools
import json
import os
import pathlib
import statistics
import subprocess
import sys
import time

THIS = str(pathlib.Path(__file__).resolve().parents[1])  # this checkout
FAMILIES = ("planar_rrr", "ups_hexapod", "rss_hexapod", "delta", "prs_ups")


def _environment(code: str | None) -> dict[str, str]:
    environment = dict(os.environ)
    if code is not None:
        environment["PYTHONPATH"] = os.pathsep.join(filter(None, [code, environment.get("PYTHONPATH")]))
    return environment


@functools.cache
def _search_words(code: str | None) -> tuple[str, ...]:
    """``design-search family`` of this checkout; ``design-search`` alone for a checkout older than the
    ``family`` subcommand (issue 28's baseline, 5a11a80)."""
    probe = subprocess.run([sys.executable, "-m", "screwkit.cli", "design-search", "--help"],
                           capture_output=True, text=True, check=True, env=_environment(code), cwd=code or THIS)
    return ("design-search", "family") if "COMMAND [ARGS]" in probe.stdout else ("design-search",)


def run(family: str, budget: int, code: str | None = None) -> tuple[float, int]:
    """Wall seconds and evaluations of one search; ``code``: another checkout's folder, put first on the path
    and made the working folder (``python -m`` puts the working folder before the path)."""
    command = [sys.executable, "-m", "screwkit.cli", *_search_words(code), family, "--budget", str(budget),
               "--json", "--quiet"]
    start = time.perf_counter()
    completed = subprocess.run(command, capture_output=True, text=True, check=True, env=_environment(code),
                               cwd=code or THIS)
    return time.perf_counter() - start, json.loads(completed.stdout)["evaluations"]


def rate(runs: list[tuple[float, float]], count: int) -> tuple[float, str]:
    """Designs per second from (budget 0, budget N) wall times, and the line that shows them."""
    empty, full = [r[0] for r in runs], [r[1] for r in runs]
    base, total = statistics.median(empty), statistics.median(full)
    per_second = (count - 1) / (total - base)
    return per_second, (f"{base:13.2f} {total:13.2f} {count:8d} {per_second:10.1f}"
                        f"   (wall ranges {min(empty):.2f}-{max(empty):.2f} and {min(full):.2f}-{max(full):.2f} s)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--budget", type=int, default=192)
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--families", nargs="+", default=FAMILIES, choices=FAMILIES)
    parser.add_argument("--against", help="another checkout's folder, run alternately with this one")
    parser.add_argument("--json", type=pathlib.Path, help="also write the rates (and their ratios) to this file")
    arguments = parser.parse_args()
    found = {}
    codes = {"this": None} if arguments.against is None else {"this": None, "other": arguments.against}
    print(f"{'family':12s} {'code':5s} {'budget 0 (s)':>13s} {'budget N (s)':>13s} {'designs':>8s} {'designs/s':>10s}")
    for family in arguments.families:
        for code in codes.values():
            run(family, 0, code)  # warm the compile cache and the file cache
        runs: dict[str, list[tuple[float, float]]] = {name: [] for name in codes}
        counts = {}
        for _ in range(arguments.runs):
            for name, code in codes.items():  # alternately, so that a slow moment of the machine hits both
                empty = run(family, 0, code)[0]
                seconds, counts[name] = run(family, arguments.budget, code)
                runs[name].append((empty, seconds))
        rates = {}
        for name in codes:
            rates[name], line = rate(runs[name], counts[name])
            print(f"{family:12s} {name:5s} {line}")
        if len(codes) == 2:
            print(f"{family:12s} this / other: {rates['this'] / rates['other']:.2f}", flush=True)
        found[family] = {**rates, **({"ratio": rates["this"] / rates["other"]} if len(codes) == 2 else {})}
    if arguments.json:
        arguments.json.write_text(json.dumps(found))


if __name__ == "__main__":
    main()
