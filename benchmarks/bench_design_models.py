"""Designs per second of building a family's mechanism model: through the URDF text and directly, side by side.

Usage: python benchmarks/bench_design_models.py [--designs 20] [--rounds 5]

For each bundled family, ``--designs`` candidates are drawn (seeded) uniformly within the bounds of
the free parameters, keeping those that assemble. Each round builds every candidate's model both ways,
in turn: **via text** writes the URDF and loads it (``load_text(family.urdf(values))``, the path of the
previous releases) and **direct** builds it from the writer's document without a text
(``family.mechanism(values)``). The rate is the designs divided by the shortest time of the rounds (the
machine is shared: the shortest is the least disturbed). The
two models are the same (``tests/test_design_direct.py``); the map a search then evaluates on each
design is not part of this (see ``bench_design.py`` for whole searches).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from screwkit.io.loader import load_text
from screwkit.studies.design.families import FAMILIES, family


def candidates(name: str, count: int, seed: int = 0) -> tuple[object, list[dict[str, float]]]:
    """The family and ``count`` candidates of it that assemble, drawn within the free parameters' bounds."""
    chosen, rng = family(name), np.random.default_rng(seed)
    designs = []
    while len(designs) < count:
        values = {}
        for parameter in (chosen.parameter(free) for free in chosen.free):
            value = rng.uniform(parameter.lower, parameter.upper)
            values[parameter.name] = float(round(value)) if parameter.integer else float(value)
        try:
            chosen.mechanism(values)
        except ValueError:  # an arm too short for the home pose: not a candidate of the comparison
            continue
        designs.append(values)
    return chosen, designs


def seconds(build, designs) -> float:
    start = time.perf_counter()
    for values in designs:
        build(values)
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--designs", type=int, default=20)
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--families", nargs="+", default=list(FAMILIES), choices=list(FAMILIES))
    arguments = parser.parse_args()
    print(f"{'family':12s} {'legs':>4s} {'via text (designs/s)':>21s} {'direct (designs/s)':>19s} {'ratio':>6s}")
    for name in arguments.families:
        chosen, designs = candidates(name, arguments.designs)
        paths = {"text": lambda values, chosen=chosen: load_text(chosen.urdf(values)), "direct": chosen.mechanism}
        times: dict[str, list[float]] = {path: [] for path in paths}
        for _ in range(arguments.rounds):
            for path, build in paths.items():
                times[path].append(seconds(build, designs))
        text, direct = (len(designs) / min(times[path]) for path in paths)
        print(f"{name:12s} {chosen.legs:4d} {text:21.1f} {direct:19.1f} {direct / text:6.2f}")


if __name__ == "__main__":
    main()
