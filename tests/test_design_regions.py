"""The region of ``screwkit design-search``: how its options build it, what they refuse, and the metrics drawn
from it (``family``, ``optimise`` and ``permutations``).

Each metric is checked against a count made here: the fault-tolerant cells of a fresh ``screwkit map`` (or a
region every point of which is fault tolerant, level -1) times the cell the user gave. Each refusal is one
line before any work, the checks and messages of ``screwkit map`` where it has the option.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
import xarray as xr
from click.testing import CliRunner

from helpers import one_line_error, screwkit
from screwkit.cli import app
from screwkit.io.loader import load
from screwkit.studies.design.families import family
from screwkit.studies.design.objectives import default_region, disc_region, grid_region, region_metrics
from screwkit.studies.design.permutations import permutation_search, planar_design

GRID = ("--grid", "x:-0.1:0.1:0.1", "--grid", "y:-0.1:0.1:0.1")
"""A 3 x 3 grid of 0.1 m cells (0.09 m^2)."""


def fault_tolerant_cells(path, level: float) -> int:
    """Points of a written ``screwkit map`` whose f_o1 (worst over the orientation set) is at least ``level``."""
    with xr.open_dataset(path) as data:
        return int(np.sum(np.nan_to_num(data["f_o1"].values, nan=0.0) >= level))


# -- library: the region and its metrics ------------------------------------------------------------------------

def test_a_coordinate_is_on_the_grid_in_the_orientation_set_or_the_layers_at_most_once():
    grid = {"x": (-0.1, 0.1, 0.1), "y": (-0.1, 0.1, 0.1)}
    with pytest.raises(ValueError, match="cannot be both on the grid and in the orientation set"):
        grid_region(grid, {"x": (0, 0.2, 0.1)})
    with pytest.raises(ValueError, match="'x'.*layers|layers.*'x'"):
        grid_region(grid, {"yaw": (-10, 20, 10)}, layers=("x", (0, 0.3, 0.1)))
    with pytest.raises(ValueError, match="'yaw'.*layers|layers.*'yaw'"):
        grid_region(grid, {"yaw": (-10, 20, 10)}, layers=("yaw", (0, 0.3, 0.1)))
    with pytest.raises(ValueError, match="'x'"):  # the family's default grid has x
        default_region(family("ups_hexapod"), layers=("x", (0, 0.3, 0.1)))


def test_a_disc_of_one_point_has_the_cell_of_its_step():
    """radius < step: the home point alone; it counts one cell of step^2, and the largest disc about it that
    holds no point beyond the map reaches the next grid point, one step away."""
    chosen = family("planar_rrr")
    for step in (0.05, 0.07):
        region = disc_region(0.04, step, 90.0, level=0.0)  # every reachable point fault tolerant (F_O1 >= 0)
        assert region.configurations == 4
        metrics = region_metrics(chosen.mechanism(), region, chosen.size())
        assert metrics["area"] == pytest.approx(step**2, rel=1e-12)
        assert metrics["inscribed"] == pytest.approx(step, rel=1e-12)
        assert metrics["cylinder"] == pytest.approx(step, rel=1e-12)


def test_one_layer_is_as_thick_as_its_step():
    """A volume is each layer's area times the layer step, whatever the number of layers; the ball about a point
    of a single layer reaches beyond the map one layer step away."""
    chosen = family("delta")
    region = grid_region({"x": (-0.1, 0.1, 0.1), "y": (-0.1, 0.1, 0.1)}, {}, layers=("z", (-0.75, -0.7, 0.05)),
                         level=0.0)
    assert region.layers[1].size == 1
    metrics = region_metrics(chosen.mechanism(), region, chosen.size())
    assert metrics["area"] == pytest.approx(9 * 0.1**2, rel=1e-12)
    assert metrics["volume"] == pytest.approx(9 * 0.1**2 * 0.05, rel=1e-12)
    assert metrics["inscribed"] == pytest.approx(0.05, rel=1e-12)
    assert metrics["cylinder"] == pytest.approx(0.2, rel=1e-12)  # the 3 x 3 disc: two steps to beyond the map


@pytest.mark.parametrize("disc", [(0.6, 1e-6, 5.0), (0.6, 0.05, 1e-9), (1e3, 1e-4, 1e-7)])
def test_a_region_too_fine_is_refused_from_its_counts(disc):
    """Refused from the counts of the specs, before any array (these would take terabytes)."""
    with pytest.raises(ValueError, match="configurations per design"):
        default_region(family("planar_rrr"), disc=disc)
    with pytest.raises(ValueError, match="configurations per design"):
        default_region(family("ups_hexapod"), grid={"x": (-1, 1, 1e-4), "y": (-1, 1, 1e-4)},
                       over={"yaw": (0, 360, 1e-3)})
    with pytest.raises(ValueError, match="10\\^8"):
        permutation_search(planar_design(load("planar_5rrr")), phi_step_degrees=1e-9)


# -- the command: regions refused in one line ---------------------------------------------------------------------

@pytest.mark.parametrize("arguments, message", [
    (("ups_hexapod", *GRID, "--over", "yaw:-10:20:10", "--layers", "x:0:0.3:0.1"), "'x'"),
    (("ups_hexapod", *GRID, "--over", "yaw:-10:20:10", "--over", "x:0:0.2:0.1"),
     "cannot be both on the grid and in the orientation set"),
    (("ups_hexapod", "--layers", "y:0:0.3:0.1"), "'y'"),  # on the family's default grid
    (("ups_hexapod", *GRID, "--over", "yaw:-10:20:10", "--over", "yaw:0:30:10"), "--over yaw"),
    (("ups_hexapod", "--grid", "x:-0.1:0.1:0.1", "--grid", "x:-0.2:0.2:0.1"), "two different coordinates in --grid"),
    (("delta", "--layers", "z:-0.8:-0.7:0.05", "--layers", "z:-0.9:-0.7:0.05"), "--layers"),
    (("prs_ups", "--grid", "z:0.15:0.25:0.05", "--grid", "roll:-10:10:10", "--objective", "inscribed"),
     "inscribed"),
    (("prs_ups", "--grid", "z:0.15:0.25:0.05", "--grid", "roll:-10:10:10", "--objective", "area",
      "--objective", "cylinder"), "cylinder"),
])
def test_a_region_counting_a_coordinate_twice_or_without_its_metric_is_refused(arguments, message):
    one_line_error(screwkit("design-search", "family", *arguments, "--budget", "0"), message)


@pytest.mark.parametrize("arguments", [
    ("family", "planar_rrr", "--phi-step", "1e-9"),
    ("family", "planar_rrr", "--step", "1e-6"),
    ("optimise", "planar_5rrr", "--step", "1e-6"),
    ("family", "ups_hexapod", "--grid", "x:-1:1:0.00001", "--grid", "y:-1:1:0.00001"),
    ("permutations", "planar_5rrr", "--phi-step", "1e-9"),
])
def test_a_region_too_fine_is_refused_before_any_work(arguments):
    budget = ("--budget", "0") if arguments[0] != "permutations" else ()
    one_line_error(screwkit("design-search", *arguments, *budget), "10^8")


def test_over_and_layers_exclude_their_stop_as_the_map_over_does(tmp_path):
    """--over yaw:-10:15:10 is -10, 0, 10 for screwkit map; the search's area is its fault-tolerant cells x the
    cell."""
    design = screwkit("design-search", "family", "ups_hexapod", "--budget", "0", *GRID, "--over", "yaw:-10:15:10",
                      "--json", "--quiet", "--urdf", tmp_path / "start.urdf")
    assert design.returncode == 0, design.stderr
    found = json.loads(design.stdout)
    mapped = screwkit("map", tmp_path / "start.urdf", *GRID, "--over", "yaw:-10:15:10", "--out", tmp_path / "m.nc",
                      "--quiet")
    assert mapped.returncode == 0, mapped.stderr
    with xr.open_dataset(tmp_path / "m.nc") as data:
        assert data.attrs["orientation_set"].startswith("yaw: 3 values from -10 to 10")
    assert found["start"]["metrics"]["area"] == pytest.approx(fault_tolerant_cells(tmp_path / "m.nc", 0.35) * 0.01,
                                                              rel=1e-9, abs=1e-12)
    # layers z:-0.75:-0.68:0.05: the layers -0.75 and -0.7 (0.05 m thick each), the stop excluded
    design = screwkit("design-search", "family", "delta", "--budget", "0", *GRID, "--layers", "z:-0.75:-0.68:0.05",
                      "--objective", "volume", "--json", "--quiet", "--urdf", tmp_path / "delta.urdf")
    assert design.returncode == 0, design.stderr
    found = json.loads(design.stdout)
    cells = 0
    for k, z in enumerate(("-0.75", "-0.7")):
        mapped = screwkit("map", tmp_path / "delta.urdf", *GRID, "--at", "0", "0", z, "--out", tmp_path / f"d{k}.nc",
                          "--quiet")
        assert mapped.returncode == 0, mapped.stderr
        cells += fault_tolerant_cells(tmp_path / f"d{k}.nc", 0.5)
    assert cells > 0
    assert found["start"]["metrics"]["volume"] == pytest.approx(cells * 0.01 * 0.05, rel=1e-9)
    assert len(found["map_commands"]) == 2


def test_a_disc_of_one_point_from_the_command(tmp_path):
    result = screwkit("design-search", "family", "planar_rrr", "--budget", "0", "--json", "--quiet", "--radius",
                      "0.04", "--step", "0.05", "--level", "0")
    assert result.returncode == 0, result.stderr
    metrics = json.loads(result.stdout)["start"]["metrics"]
    assert metrics["area"] == pytest.approx(0.05**2, rel=1e-12) and metrics["inscribed"] == pytest.approx(0.05)


# -- study files: each value as its option reads it ---------------------------------------------------------------

@pytest.mark.parametrize("line, message", [
    ("budget: abc", "budget: expected an integer >= 0, got 'abc'"),
    ("budget: 6.5", "budget: expected an integer >= 0, got 6.5"),
    ("budget: true", "budget: expected an integer >= 0, got True"),
    ("budget: -1", "budget: expected an integer >= 0, got -1"),
    ("popsize: 0", "popsize: expected an integer >= 2, got 0"),
    ("popsize: 1", "popsize: expected an integer >= 2, got 1"),
    ("seed: 1.5", "seed: expected an integer"),
    ("seed: -1", "seed: expected an integer"),
    ("seed: 4294967296", "seed: expected an integer"),
    ("radius: abc", "radius: expected a number, got 'abc'"),
    ("level: [1]", "level: expected one value, got [1]"),
    ("level: 1.5", "level: expected a number in 0..1, got 1.5"),
    ("legs: two", "legs: expected an integer >= 1, got 'two'"),
    ("family: [planar_rrr]", "family: expected one value, got ['planar_rrr']"),
    ("objectives: [area, size]", "objectives: expected one of"),
    ("layers: ['z:0:1:0.1']", "layers: expected one value"),
    ("index: 5", "index: expected f_o1|f_io1|f_o_mean1|..., got 5"),
    ("index: f_oo1", "index: expected f_o1|f_io1|f_o_mean1|..., got 'f_oo1'"),
])
def test_a_study_value_is_checked_as_its_option(tmp_path, line, message):
    study = tmp_path / "st.yaml"
    key = line.partition(":")[0]
    study.write_text(("" if key == "family" else "family: planar_rrr\n") + line + "\n")
    result = CliRunner().invoke(app, ["design-search", "family", "--study", str(study), "--budget", "0"]
                                if key != "budget" else ["design-search", "family", "--study", str(study)])
    assert result.exit_code == 1 and isinstance(result.exception, SystemExit), result.output
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("Error: ") and message in lines[0], result.output
    assert lines[0].startswith(f"Error: {study}: {key}: "), lines[0]


def test_a_study_value_is_refused_in_one_line_from_the_command(tmp_path):
    study = tmp_path / "st.yaml"
    study.write_text("family: delta\nseed: -3\n")
    one_line_error(screwkit("design-search", "family", "--study", study, "--budget", "0"), f"{study}: seed: ")
    study.write_text("family: delta\nindex: 5\n")  # it was refused after the search started, naming no file
    one_line_error(screwkit("design-search", "family", "--study", study, "--budget", "0"),
                   f"{study}: index: expected f_o1|f_io1|f_o_mean1|..., got 5.")
    one_line_error(screwkit("design-search", "family", "delta", "--index", "5", "--budget", "0"),
                   "Invalid value for '--index': Unknown index '5'")
    study.write_text("family: planar_rrr\nbudget: abc\n")
    one_line_error(screwkit("design-search", "family", "--study", study),
                   f"{study}: budget: expected an integer >= 0, got 'abc'")


def test_a_valid_study_file_still_reads_as_its_options(tmp_path):
    study = tmp_path / "st.yaml"
    study.write_text("family: delta\nbudget: 0\nseed: 4294967295\npopsize: 2\nlevel: '0.5'\n"
                     "grid: ['x:-0.1:0.1:0.1', 'y:-0.1:0.1:0.1']\nlayers: z:-0.75:-0.7:0.05\nobjectives: volume\n")
    result = CliRunner().invoke(app, ["design-search", "family", "--study", str(study), "--json", "--quiet"])
    assert result.exit_code == 0, result.output
    found = json.loads(result.output)
    assert found["seed"] == 4294967295 and found["objectives"] == ["volume"]
    assert "layers z -0.75..-0.75 m (1 values)" in found["region"]


def test_the_design_page_lists_every_study_key():
    from pathlib import Path

    from screwkit.cli.design_options import STUDY_KEYS

    page = (Path(__file__).resolve().parents[1] / "docs" / "design.md").read_text()
    keys = page.split("Keys: ", 1)[1].split("; an", 1)[0]
    assert all(f"`{key}`" in keys for key in STUDY_KEYS), keys
