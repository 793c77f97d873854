"""A leg whose constraint wrench misses its platform point: the ITI depends on the working length, and it is said.

The actuation wrench is defined up to the leg's constraint wrenches; screwkit's representative is the least-norm one
in working coordinates with moments about the leg's point on the platform, and its power coefficients (the ITI, the
OTI) depend on the representative. A Delta leg of two parallel rods holds a couple, and the representative, the
force along the rods through the midline, is the same at any working length. Rods that converge (a published
onshape export's, 1.4 deg from parallel) hold a force through the point where their lines meet, and the
representative turns with the working length (``docs/theory.md``, *The representative and the working length*):
the reading says so on every command, naming the legs.
"""

from __future__ import annotations

import re

import numpy as np
import pytest
from delta_rods import SPACING, delta_rods_mjcf
from test_graph_legs import POSES

from helpers import random_rotation, screwkit
from screwkit.io.graph import graph_mechanism
from screwkit.io.graph_checks import LENGTH_DEPENDENT
from screwkit.io.mjcf import read_mjcf

AZIMUTHS = np.radians([90.0, 210.0, 330.0])
TRANSFORMS = {"m": None, "mm": (1000.0, np.eye(3), np.zeros(3)),
              "turned": (1.0, random_rotation(np.random.default_rng(4)), np.array([0.3, -1.2, 2.0]))}


def _notes(tmp_path, spacing, transform):
    path = tmp_path / "delta.xml"
    path.write_text(delta_rods_mjcf(POSES[0], AZIMUTHS, transform=transform, platform_spacing=spacing))
    graph = graph_mechanism(read_mjcf(path))
    return [note for note in graph.reading_notes() if note.startswith(LENGTH_DEPENDENT)], graph


@pytest.mark.parametrize("variant", sorted(TRANSFORMS))
def test_converging_rods_are_said_to_make_the_iti_depend_on_the_working_length(tmp_path, variant):
    said, graph = _notes(tmp_path, 0.05, TRANSFORMS[variant])
    assert len(said) == 1 and all(f"{leg.name}" in said[0] for leg in graph.legs), said
    assert "rods not parallel" in said[0]
    turns = [float(turn) for turn in re.findall(r"representative turns (\d[^ ]*) deg", said[0])]
    assert len(turns) == 3 and all(turn > 0.05 for turn in turns), said


@pytest.mark.parametrize("variant", sorted(TRANSFORMS))
@pytest.mark.parametrize("off", [0.0, 1e-5])
def test_parallel_rods_say_nothing_of_it_nor_rods_off_parallel_by_a_files_rounding(tmp_path, variant, off):
    """Rods 1.8e-5 rad from parallel (their platform ends 1e-5 m closer: a file written to 0.01 mm) turn the
    representative by about 1e-4 deg, and were named: within the rounding, not a convergence of the rods."""
    said, _ = _notes(tmp_path, SPACING - off, TRANSFORMS[variant])
    assert said == []


def test_the_command_says_it_on_stderr(tmp_path):
    path = tmp_path / "trapezoids.xml"
    path.write_text(delta_rods_mjcf(POSES[0], AZIMUTHS, platform_spacing=0.05))
    completed = screwkit("analyze", path, "--json")
    assert completed.returncode == 0, completed.stderr
    assert f"{LENGTH_DEPENDENT}leg(s)" in completed.stderr


def test_each_leg_keeps_its_turn_with_the_legs_listed_in_another_order(tmp_path):
    """The trapezoid Delta written with its legs in reverse order (arm_1 is then the leg at the last azimuth): each
    leg, found by its azimuth, is named with the same turn of its representative (1e-9 deg)."""
    from screwkit.io.graph_checks import length_dependent_legs

    turns = []
    for azimuths in (AZIMUTHS, AZIMUTHS[::-1]):
        path = tmp_path / "delta.xml"
        path.write_text(delta_rods_mjcf(POSES[0], azimuths, platform_spacing=0.05))
        graph = graph_mechanism(read_mjcf(path))
        found = dict(length_dependent_legs(graph.legs, graph.chains))
        assert set(found) == {leg.name for leg in graph.legs}
        turns.append([found[f"arm_{k + 1}"] for k in range(len(azimuths))])
    np.testing.assert_allclose(turns[0], turns[1][::-1], atol=1e-9)
