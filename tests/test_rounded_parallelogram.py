"""A Delta's parallelograms of ball-jointed rods written rounded off parallel keep their CTI.

Two rods a file writes with 6 decimals are parallel only to its rounding: their lines meet 1e5 to 1e6 working lengths
away, and the leg's constraint wrench is a force through that point instead of the parallelogram's couple. Scored as
a force there (the point of its axis nearest to the leg's platform joint, a million lengths away), its power
coefficient did not tend to the couple's: the rod-level Delta's CTI read 0.99757 for its parallelograms' 0.93132 with
its platform's rods drawn 1e-10 m closer together, and a published CAD Delta (RemcoKuijpers' Codian, 6 decimals) read
0.99704 for 0.99588 and changed by 3.4e-5 with its legs listed the other way round. A constraint wrench whose force
is at most ``ROUNDED_COUPLE`` (1e-3) times its moment about the centroid is scored as its couple, in the compiled
kernel, its numpy counterpart and the reference. Checked against the CTI of the couples a_i x u_i computed here from
the drawing (``helpers.couple_cti``).
"""

from __future__ import annotations

import re

import numpy as np
import pytest
from delta_rods import ROD, SPACING, delta_rods_mjcf
from test_compiled_chunks import kernel_calls  # noqa: F401 (a fixture)
from test_graph_legs import POSES, textbook

from helpers import couple_cti, random_rotation
from screwkit.common.tolerances import ROUNDED_COUPLE
from screwkit.indices.stages import compiled_chunks
from screwkit.io.graph import graph_mechanism
from screwkit.io.graph_checks import FAR_FORCE, FAR_FORCE_NOTE
from screwkit.io.mjcf import read_mjcf

AZIMUTHS = np.radians([90.0, 210.0, 330.0])


def _cti(tmp_path, off: float, azimuths=AZIMUTHS, transform=None, compiled: bool = False) -> float:
    path = tmp_path / "delta.xml"
    path.write_text(delta_rods_mjcf(POSES[0], azimuths, transform=transform, platform_spacing=SPACING - off))
    graph = graph_mechanism(read_mjcf(path))
    if compiled:
        with compiled_chunks():
            return float(np.asarray(graph.indices().cti).ravel()[0])
    return float(np.asarray(graph.indices().cti).ravel()[0])


def _couples_cti(azimuths=AZIMUTHS) -> float:
    drawn = textbook(POSES[0], azimuths)
    return couple_cti(np.cross(drawn["axes"], drawn["rods"]))


@pytest.mark.parametrize("compiled", [False, True], ids=["numpy", "kernel"])
@pytest.mark.parametrize("off", [0.0, 1e-10, 1e-7, 3e-6])
def test_rods_rounded_off_parallel_keep_the_parallelograms_cti(tmp_path, off, compiled, kernel_calls):  # noqa: F811
    """Within the geometry's own change (the rods turn by ``off`` / ROD): 1e-9 relative at 1e-7 m."""
    assert _cti(tmp_path, off, compiled=compiled) == pytest.approx(_couples_cti(), abs=1e-12 + off / ROD)
    assert (kernel_calls["constraint"] > 0) == compiled


@pytest.mark.parametrize("variant", ["mm", "turned", "reversed"])
def test_the_same_in_millimetres_in_a_turned_world_and_listed_back(tmp_path, variant):
    transforms = {"mm": (1000.0, np.eye(3), np.zeros(3)),
                  "turned": (1.0, random_rotation(np.random.default_rng(7)), np.array([0.4, -1.1, 2.3]))}
    azimuths = AZIMUTHS[::-1] if variant == "reversed" else AZIMUTHS
    other = _cti(tmp_path, 3e-6, azimuths, transforms.get(variant))
    assert other == pytest.approx(_cti(tmp_path, 3e-6), abs=1e-9)


def _far_note(tmp_path, off: float, azimuths=AZIMUTHS, transform=None) -> list[str]:
    path = tmp_path / "delta.xml"
    path.write_text(delta_rods_mjcf(POSES[0], azimuths, transform=transform, platform_spacing=SPACING - off))
    return [note for note in graph_mechanism(read_mjcf(path)).reading_notes() if note.startswith(FAR_FORCE_NOTE)]


@pytest.mark.parametrize("variant", ["m", "mm", "turned", "reversed"])
def test_rods_nearly_parallel_beyond_the_rounding_are_said_to_make_the_cti_unsettled(tmp_path, variant):
    """Rods 1 mm closer at the platform (of 60 mm): each leg's constraint force passes 30 to 300 working lengths away,
    scored as a force there (the step of theory.md's *Not settled either*): every command names the three legs, in
    any unit, world frame and order; rods parallel, or a file's rounding off it, are not named."""
    transforms = {"mm": (1000.0, np.eye(3), np.zeros(3)),
                  "turned": (1.0, random_rotation(np.random.default_rng(7)), np.array([0.4, -1.1, 2.3]))}
    azimuths = AZIMUTHS[::-1] if variant == "reversed" else AZIMUTHS
    (said,) = _far_note(tmp_path, 1e-3, azimuths, transforms.get(variant))
    distances = [float(value) for value in re.findall(r"arm_\d \(([\d.e+]+) working lengths away\)", said)]
    assert len(distances) == 3 and all(1.0 / FAR_FORCE < d < 1.0 / ROUNDED_COUPLE for d in distances), said
    assert _far_note(tmp_path, 0.0, azimuths, transforms.get(variant)) == []
    assert _far_note(tmp_path, 3e-6, azimuths, transforms.get(variant)) == []
