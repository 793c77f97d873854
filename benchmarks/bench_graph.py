"""What a closed-loop graph costs per pose, beside the serial-leg model of the same robot.

Usage: python benchmarks/bench_graph.py [--poses 4096] [--repeat 3]

The bundled rod-level Delta ``delta_rods_4`` (four arms, each forearm a parallelogram of two ball-jointed rods,
opened as a graph: :func:`screwkit.studies.poses.graph_indices_at_poses`) and the bundled ``delta_4`` (the same
geometry with R-U-U legs, serial chains: :func:`screwkit.studies.poses.indices_at_poses`), at the same ``--poses``
random poses within 0.15 m of home, in one process, one after the other, best of ``--repeat``: microseconds per
pose, and for the graph the part spent closing the poses (:meth:`GraphMechanism.solve`).
"""

from __future__ import annotations

import argparse
import timeit

import numpy as np

from screwkit.io import graph_mechanism, read_closed_tree
from screwkit.io.loader import bundled_path, load
from screwkit.studies.poses import graph_indices_at_poses, indices_at_poses


def best(function, repeat: int) -> float:
    """The best of ``repeat`` wall times of ``function()`` (s)."""
    return min(timeit.repeat(function, number=1, repeat=repeat))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--poses", type=int, default=4096)
    parser.add_argument("--repeat", type=int, default=3)
    arguments = parser.parse_args()
    serial = load("delta_4")
    graph = graph_mechanism(read_closed_tree(bundled_path("delta_rods_4")))
    poses = serial.home_pose + np.random.default_rng(0).uniform(-0.15, 0.15, (arguments.poses, 3))
    indices_at_poses(serial, poses[:64])  # compiled kernels loaded before timing
    graph_indices_at_poses(graph, poses[:64])
    count = arguments.poses
    timings = {
        "delta_4 (serial R-U-U legs)": best(lambda: indices_at_poses(serial, poses), arguments.repeat),
        "delta_rods_4 (graph)": best(lambda: graph_indices_at_poses(graph, poses), arguments.repeat),
        "  of which closing the poses": best(lambda: graph.solve(poses), arguments.repeat),
    }
    for name, seconds in timings.items():
        print(f"{name:32s} {1e6 * seconds / count:9.1f} us per pose")
    ratio = timings["delta_rods_4 (graph)"] / timings["delta_4 (serial R-U-U legs)"]
    print(f"graph / serial: {ratio:.1f}")


if __name__ == "__main__":
    main()
