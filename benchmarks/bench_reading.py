"""How the time to read a URDF grows with its size: linear (a quadratic reader took 35 minutes for 50 MB).

Usage: python benchmarks/bench_reading.py [--repeat 3]

Reads files of 2,000 and 8,000 extra links (screwkit's safe XML pass, ``read_urdf``), prints the
ratio of their sizes and of their best reading times (about equal when reading is linear, the
square of the size ratio when quadratic), and how long the largest file allowed
(``MAX_LINKS`` links) takes to load, Pinocchio included.
"""

from __future__ import annotations

import argparse
import tempfile
import timeit
from pathlib import Path

from screwkit.io.loader import bundled_path, load
from screwkit.model.urdf_reader import MAX_LINKS, read_urdf


def with_links(count: int) -> str:
    """The bundled 5-RRR with ``count`` fixed links hung from its platform."""
    extra = "".join(f'<link name="e{i}"/><joint name="j{i}" type="fixed"><parent link="platform"/>'
                    f'<child link="e{i}"/></joint>\n' for i in range(count))
    return bundled_path("planar_5rrr").read_text(encoding="utf-8").replace("</robot>", extra + "</robot>")


def best(function, repeat: int) -> float:
    """The best of ``repeat`` wall times of ``function()`` (s)."""
    return min(timeit.repeat(function, number=1, repeat=repeat))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        small, large, largest = (Path(folder) / f"{name}.urdf" for name in ("small", "large", "largest"))
        small.write_text(with_links(2000))
        large.write_text(with_links(8000))
        largest.write_text(with_links(MAX_LINKS - 12))
        size_ratio = large.stat().st_size / small.stat().st_size
        time_ratio = best(lambda: read_urdf(large), args.repeat) / best(lambda: read_urdf(small), args.repeat)
        print(f"size ratio {size_ratio:.2f}, reading time ratio {time_ratio:.2f} (quadratic: {size_ratio ** 2:.1f})")
        print(f"largest file allowed ({MAX_LINKS:,} links) loaded in {best(lambda: load(largest), 1):.2f} s")


if __name__ == "__main__":
    main()
