"""Bad input to the study API (design helpers, sweeps, maps, paths, trajectories), the closure functions given a
solution of another mechanism, and the readers and figures given the wrong kind of object: a one-line
ValueError/TypeError naming the parameter, never a silently wrong number or a traceback from inside numpy."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import screwkit
from screwkit.closure import actuator_values, chain_screws, closure_residuals, forward, solve, unreachable_reason
from screwkit.screw.planar import paper_5rrr, planar_joint_points
from screwkit.studies.design.permutations import (
    fault_tolerant_area,
    permutation_search,
    planar_design,
    rotation_score,
    slot_design,
)
from screwkit.studies.maps import disc_grid, index_map, planar_disc_map
from screwkit.studies.options import AnalysisOptions
from screwkit.studies.paths import circle_path, line_path, through_path
from screwkit.studies.sweep import sweep
from screwkit.studies.tasks import Execution
from screwkit.studies.trajectory import trajectory

QUIET = Execution(progress=False)


@pytest.fixture(scope="module")
def five():
    return screwkit.load("planar_5rrr")


@pytest.fixture(scope="module")
def hexapod():
    return screwkit.load("ups_hexapod_8")


# -- 1. design helpers ---------------------------------------------------------------------------------------------

@pytest.mark.parametrize("keywords, message", [
    ({"step": -0.1}, r"Expected `step` > 0 \(m\), got -0.1"),
    ({"step": 0.0}, r"Expected `step` > 0 \(m\), got 0.0"),
    ({"step": float("nan")}, r"Expected `step` > 0 \(m\), got nan"),
    ({"radius": -0.2}, r"Expected `radius` > 0 \(m\), got -0.2"),
    ({"radius": float("inf")}, r"Expected `radius` > 0 \(m\), got inf"),
    ({"level": 2.0}, r"Expected `level` in \[0, 1\] \(an index value\), got 2.0"),
    ({"level": float("nan")}, r"Expected `level` in \[0, 1\] \(an index value\), got nan"),
    ({"phi_step_degrees": 0.0}, r"Expected 0 < `phi_step_degrees` <= 360 \(deg\), got 0.0"),
    ({"phi_step_degrees": -30.0}, r"Expected 0 < `phi_step_degrees` <= 360 \(deg\), got -30.0"),
    ({"phi_step_degrees": 400.0}, r"Expected 0 < `phi_step_degrees` <= 360 \(deg\), got 400.0"),
    ({"radius": 1e3, "step": 1e-3}, r"configurations per design"),  # refused from its counts, nothing built
])
def test_fault_tolerant_area_refuses_what_would_give_a_plausible_zero(keywords, message):
    """Before: 0.0 m^2 for a negative step or radius, a level no index reaches or NaN; ZeroDivisionError for a
    zero step; a numpy reduction error for a negative angle step."""
    keywords = {"radius": 0.2, "step": 0.1, "phi_step_degrees": 30.0, **keywords}
    with pytest.raises(ValueError, match=message):
        fault_tolerant_area(paper_5rrr(), **keywords)


@pytest.mark.parametrize("level, error, message", [
    (1.5, ValueError, r"Expected a region level in \[0, 1\] \(a value of f_o1\), got 1.5"),
    (-0.1, ValueError, r"Expected a region level in \[0, 1\] \(a value of f_o1\), got -0.1"),
    (float("nan"), ValueError, r"Expected a region level in \[0, 1\] \(a value of f_o1\), got nan"),
    ("0.4", TypeError, r"Expected region level to be a number, got str '0.4'"),
])
def test_a_design_region_refuses_a_level_no_index_value_can_be(level, error, message):
    """Before: a level above 1 scored every design 0 (no index reaches it) and one below 0 counted every reachable
    point, F_O1 = 0 included, as fault tolerant; the search then ran its whole budget on that. An index registered
    without bounds (tests/test_registry.py's toy margin, which is negative) takes any finite level."""
    from screwkit.studies.design.objectives import disc_region, grid_region

    with pytest.raises(error, match=message):
        disc_region(0.2, 0.1, 60.0, level=level)
    with pytest.raises(error, match=message):
        grid_region({"x": (-0.1, 0.1, 0.1), "y": (-0.1, 0.1, 0.1)}, {"yaw": (0, 30, 10)}, level=level)
    assert disc_region(0.2, 0.1, 60.0, level=1).level == 1 and disc_region(0.2, 0.1, 60.0, level=0).level == 0
    assert disc_region(0.2, 0.1, 60.0, index="iti", level=0.5).level == 0.5


@pytest.mark.parametrize("keywords", [{"level": "0.4"}, {"step": "0.1"}, {"phi_step_degrees": "30"}])
def test_fault_tolerant_area_refuses_numbers_as_text(keywords):
    with pytest.raises(TypeError, match="to be a number, got str"):
        fault_tolerant_area(paper_5rrr(), **{"radius": 0.2, "step": 0.1, "phi_step_degrees": 30.0, **keywords})


def test_fault_tolerant_area_of_valid_input_counts_the_cells_at_or_above_the_level():
    """At each grid point of the disc the minimum of F_O1 over the turn (recomputed here point by point with the
    closed forms), and the area the cells (step^2) where it is >= the level."""
    from screwkit.indices.closed_forms import planar_indices

    design, level = paper_5rrr(), 0.4
    area, grid = fault_tolerant_area(design, radius=0.2, step=0.1, phi_step_degrees=60.0, level=level)
    phi = np.deg2rad(np.arange(0.0, 360.0, 60.0))
    offsets = 0.1 * np.arange(-2, 3)
    expected = np.full((5, 5), np.nan)
    for row, y in enumerate(offsets):
        for column, x in enumerate(offsets):
            if x**2 + y**2 <= 0.2**2 * (1 + 1e-12):
                poses = np.column_stack([np.full(phi.size, x), np.full(phi.size, y), phi])
                base, elbows, distal, reachable = planar_joint_points(design, poses)
                if reachable.all():
                    expected[row, column] = planar_indices(base, elbows, distal, faults=(1,))["f_o"][1].min()
    np.testing.assert_allclose(grid, expected, atol=1e-12)
    assert np.isfinite(expected[2, 2])
    assert area == pytest.approx(np.sum(np.nan_to_num(expected, nan=-1.0) >= level) * 0.1**2, abs=1e-15)
    _, one_angle = fault_tolerant_area(design, radius=0.2, step=0.1, phi_step_degrees=360.0)  # a step of a turn
    assert one_angle.shape == (5, 5)


@pytest.mark.parametrize("phi_step", [0.0, -5.0, float("nan"), 400.0, 360.5])
def test_rotation_score_refuses_a_step_that_is_no_rotation(phi_step):
    """Before: ZeroDivisionError (0), a reduction of an empty array (-5), 'arange: cannot compute length' (nan),
    and the single angle 0 scored as a full rotation (400)."""
    with pytest.raises(ValueError, match=r"Expected 0 < `phi_step_degrees` <= 360 \(deg\)"):
        rotation_score(paper_5rrr(), phi_step_degrees=phi_step)


def test_permutation_search_refuses_a_step_beyond_a_turn():
    with pytest.raises(ValueError, match=r"Expected 0 < `phi_step_degrees` <= 360 \(deg\), got 400.0"):
        permutation_search(paper_5rrr(), phi_step_degrees=400.0)


@pytest.mark.parametrize("centre", [(0.0, 0.0, 5.0), (0.05,), 0.0, ("a", "b"), (np.nan, 0.0), (True, False)])
def test_rotation_score_refuses_a_centre_that_is_not_a_position(centre):
    """Before: a third value ignored, (0.05,) an IndexError."""
    with pytest.raises(ValueError, match=r"Expected `centre` as a position \(x, y\): two finite numbers \(m\)"):
        rotation_score(paper_5rrr(), centre=centre, phi_step_degrees=30.0)


def test_rotation_score_at_a_centre_is_the_minimum_of_f_o1_over_the_turn():
    """Any array-like position; the score is the minimum of F_O1 of the closed forms over the turn at it."""
    from screwkit.indices.closed_forms import planar_indices

    design, centre = paper_5rrr(), np.array([0.05, -0.02])
    phi = np.deg2rad(np.arange(0.0, 360.0, 30.0))
    poses = np.column_stack([np.full(phi.size, centre[0]), np.full(phi.size, centre[1]), phi])
    base, elbows, distal, reachable = planar_joint_points(design, poses)
    assert reachable.all()
    expected = planar_indices(base, elbows, distal, faults=(1,))["f_o"][1].min()
    for given in (centre, list(centre), tuple(centre)):
        assert rotation_score(design, centre=given, phi_step_degrees=30.0, closed_forms=True) == pytest.approx(
            expected, abs=1e-12)


@pytest.mark.parametrize("permutation", [[0, 3.9, 1, 4, 2], [0, 3, 1, 4], [0, 3, 1, 4, 4], "01234",
                                         [0, np.nan, 1, 4, 2]])
def test_slot_design_refuses_what_is_no_permutation(permutation):
    """Before: [0, 3.9, 1, 4, 2] truncated to [0, 3, 1, 4, 2]."""
    with pytest.raises(ValueError, match=r"Expected `permutation` to be a permutation of 0..4"):
        slot_design(paper_5rrr(), permutation)


def test_slot_design_takes_whole_numbers_as_floats_and_puts_each_joint_on_its_slot():
    design = slot_design(paper_5rrr(), [0.0, 3.0, 1.0, 4.0, 2.0], platform_radius=0.1)
    angles = np.array([0, 3, 1, 4, 2]) * 2 * np.pi / 5
    np.testing.assert_allclose(design.platform, 0.1 * np.column_stack([np.cos(angles), np.sin(angles)]), atol=1e-15)


@pytest.mark.parametrize("radius, error, message", [
    (0.0, ValueError, r"Expected `platform_radius` > 0 \(m\), got 0.0"),
    (-0.1, ValueError, r"Expected `platform_radius` > 0 \(m\), got -0.1"),
    (float("nan"), ValueError, r"Expected `platform_radius` > 0 \(m\), got nan"),
    ("0.1", TypeError, r"Expected `platform_radius` to be a number, got str"),
])
def test_slot_design_refuses_a_degenerate_platform(radius, error, message):
    """Before: platform_radius=0 put every platform joint at the centre."""
    with pytest.raises(error, match=message):
        slot_design(paper_5rrr(), [0, 3, 1, 4, 2], platform_radius=radius)


def test_slot_design_refuses_a_working_mode_that_is_no_sign():
    with pytest.raises(ValueError, match=r"Expected `working_mode` \+1 or -1"):
        slot_design(paper_5rrr(), [0, 3, 1, 4, 2], working_mode=2)


def test_planar_design_of_a_name_says_to_load_it():
    """Before: AttributeError 'str' object has no attribute 'is_planar'."""
    with pytest.raises(TypeError, match=r"planar_design expects a Mechanism, got the name 'planar_5rrr': load it"):
        planar_design("planar_5rrr")


# -- 2., 3. the fixed pose and the centre of a study ---------------------------------------------------------------

def test_planar_disc_map_refuses_a_centre_that_is_not_a_position(five):
    """Before: [0, 0, 99] mapped about (0, 0), the 99 ignored; [0.05] an IndexError."""
    for centre in ([0.0, 0.0, 99.0], [0.05], [[0.0, 0.0]], "00"):
        with pytest.raises(ValueError, match=r"Expected `centre` as a position \(x, y\): two finite numbers"):
            planar_disc_map(five, 0.1, 0.05, 90, centre=centre, execution=QUIET)


def test_disc_grid_is_about_its_centre():
    x, y, mask = disc_grid(0.1, 0.05, np.array([0.05, -0.02]))
    np.testing.assert_allclose(x, 0.05 + 0.05 * np.arange(-2, 3), atol=1e-15)
    np.testing.assert_allclose(y, -0.02 + 0.05 * np.arange(-2, 3), atol=1e-15)
    assert mask.sum() == 13  # |i|, |j| <= 2 and i^2 + j^2 <= 4
    with pytest.raises(ValueError, match=r"`centre` as a position"):
        disc_grid(0.1, 0.05, (0.0, 0.0, 1.0))


def test_sweep_refuses_a_batch_as_its_fixed_pose(five):
    """Before: IndexError in sweep.py for at of shape (1, 3)."""
    with pytest.raises(ValueError, match=r"Expected one pose as `at`, shape \(3,\), got \(1, 3\)"):
        sweep(five, np.zeros((1, 3)), "phi", np.deg2rad([0.0, 30.0]))


def test_index_map_refuses_a_batch_as_its_fixed_pose(five):
    """Before: numpy's 'could not broadcast input array from shape (4,) into shape (4,3)'."""
    with pytest.raises(ValueError, match=r"Expected one pose as `at`, shape \(3,\), got \(2, 3\)"):
        index_map(five, {"x": [0, 0.1], "y": [0, 0.1]}, {"phi": [0, 1]}, at=np.zeros((2, 3)), execution=QUIET)


# -- 4. a solution of another mechanism ----------------------------------------------------------------------------

def test_closure_functions_refuse_a_solution_of_another_mechanism(five, hexapod):
    """Before: 'Expected `out` with shape (6, 3), got (6, 6)' from the chain kinematics, bare IndexErrors."""
    solution = solve(five, five.home_pose)
    message = r"Expected a Solution of mechanism 'ups_hexapod_8' \(8 chains .* solved for another mechanism"
    with pytest.raises(ValueError, match=message):
        chain_screws(hexapod, solution)
    with pytest.raises(ValueError, match=message):
        closure_residuals(hexapod, solution)
    with pytest.raises(ValueError, match=message):
        unreachable_reason(hexapod, solution)
    with pytest.raises(ValueError, match=r"Expected `joint_values` of mechanism 'ups_hexapod_8': 8 arrays"):
        actuator_values(hexapod, solution.joint_values)
    with pytest.raises(TypeError, match=r"chain_screws expects a Solution .*, got ndarray"):
        chain_screws(five, five.home_pose)


def test_actuator_values_of_a_solution_are_its_actuated_joint_values(five):
    poses = np.array([[0.0, 0.0, 0.0], [0.05, -0.02, 0.3]])
    solution = solve(five, poses)
    expected = np.stack([solution.joint_values[c][:, five.chains[c].joint_names.index(j)]
                         for c, (_, j) in enumerate(five.actuators)], -1)  # one actuator per chain, in order
    np.testing.assert_array_equal(actuator_values(five, solution.joint_values), expected)
    np.testing.assert_array_equal(actuator_values(five, solution), expected)
    with pytest.raises(ValueError, match=r"of one batch shape"):
        actuator_values(five, [values[:1] if c else values for c, values in enumerate(solution.joint_values)])


def test_unreachable_reason_refuses_an_index_outside_the_batch(five):
    """Before: numpy's 'index 5 is out of bounds for axis 0 with size 2'."""
    batch = solve(five, np.array([[0.0, 0.0, 0.0], [5.0, 0.0, 0.0]]))
    for index in ((5,), (0, 0), (), 1.0, (True,)):
        with pytest.raises(ValueError, match=r"Expected `index` of one pose of the solution's batch \(2,\)"):
            unreachable_reason(five, batch, index)
    alone = unreachable_reason(five, solve(five, np.array([5.0, 0.0, 0.0])))
    assert alone.startswith("chain ")
    assert unreachable_reason(five, batch, (1,)) == alone == unreachable_reason(five, batch, 1)
    assert unreachable_reason(five, batch, (-1,)) == alone


def test_forward_refuses_batches_that_do_not_broadcast(five):
    """Before: numpy's 'shape mismatch: objects cannot be broadcast to a single shape'."""
    poses = np.array([[0.0, 0.0, 0.0], [0.05, -0.02, 0.3], [-0.03, 0.04, -0.2]])
    values = actuator_values(five, solve(five, poses).joint_values)
    with pytest.raises(ValueError, match=r"Expected batches of `actuator_values` \(3,\) and `initial_pose` \(2,\) "
                                         r"that broadcast together"):
        forward(five, values, np.zeros((2, 3)))
    found = forward(five, values, five.home_pose)  # one initial pose for the three: broadcast
    assert found.reachable.all()
    np.testing.assert_allclose(found.poses, poses, atol=1e-9)


# -- 5. messages that say what was wrong ---------------------------------------------------------------------------

@pytest.mark.parametrize("values", ["0:360", [True, False], [[0.0, 1.0], [2.0]]])
def test_sweep_values_that_are_not_numbers(five, values):
    """Before: 'could not convert string to float: '0:360''."""
    with pytest.raises(ValueError, match=r"Expected `values` as numbers \(k,\) of phi \(m or rad\)"):
        sweep(five, [0, 0, 0], "phi", values)
    with pytest.raises(ValueError, match=r"Expected finite `values`, got nan"):
        sweep(five, [0, 0, 0], "phi", [0.0, np.nan])


def test_index_map_says_what_grid_over_and_analysis_are(five):
    """Before: 'NoneType' object is not iterable; 'dict' object has no attribute 'faults'."""
    grid = {"x": [0.0], "y": [0.0, 0.1]}
    with pytest.raises(TypeError, match=r"index_map expects `over` as a dict of task coordinates to values, got None"):
        index_map(five, grid, None, execution=QUIET)
    with pytest.raises(TypeError, match=r"index_map expects `grid` as a dict of task coordinates to values"):
        index_map(five, [("x", [0.0]), ("y", [0.0])], {}, execution=QUIET)
    with pytest.raises(TypeError, match=r"index_map expects `analysis` as a screwkit.studies.options.AnalysisOptions, "
                                        r"got dict: pass AnalysisOptions\(\*\*\{'faults': 1\}\)"):
        index_map(five, grid, {}, analysis={"faults": 1}, execution=QUIET)


def test_trajectory_says_what_level_and_analysis_are(five):
    """Before: a ufunc 'isfinite' error for the level '0.4'; 'dict' object has no attribute 'keywords'; an empty
    dict silently taken as the default options."""
    path = line_path(five, [0, 0, 0], [0.1, 0, 0], 5)
    for level in ("0.4", True, float("nan"), 0.0, 1.5):
        with pytest.raises(ValueError, match=r"Expected `level` in \(0, 1\] \(an LMTI\), got "):
            trajectory(five, path, level=level)
    for analysis in ({"faults": 1}, {}):
        with pytest.raises(TypeError, match=r"trajectory expects `analysis` as a screwkit.studies.options"):
            trajectory(five, path, analysis=analysis)
    assert trajectory(five, path, analysis=AnalysisOptions(faults=1)).indices.faults == (1,)


def test_trajectory_refuses_times_beside_a_path_that_carries_its_own(five):
    """Before: times given with a Path were dropped without a word (the result had no time coordinate)."""
    path = line_path(five, [0, 0, 0], [0.1, 0, 0], 5)
    with pytest.raises(ValueError, match=r"^Expected `times` only with a path given as poses: a Path carries its own "
                                         r"\(screwkit.studies.paths.path_from_poses\(mechanism, poses, times\)\)\.$"):
        trajectory(five, path, times=np.linspace(0.0, 1.0, 5))
    timed = trajectory(five, path.poses, times=np.linspace(0.0, 1.0, 5))
    np.testing.assert_array_equal(timed.plain_dataset().coords["t"][1], np.linspace(0.0, 1.0, 5))


@pytest.mark.parametrize("samples", [2.5, 5.0, "5", True, 1])
def test_paths_refuse_a_sample_count_that_is_no_whole_number(five, samples):
    """Before: numpy's ''float' object cannot be interpreted as an integer'."""
    message = r"Expected `samples`: at least 2 samples on a path, a whole number, got "
    with pytest.raises(ValueError, match=message):
        line_path(five, [0, 0, 0], [0.1, 0, 0], samples)
    with pytest.raises(ValueError, match=message):
        circle_path(five, [0, 0, 0], 0.05, samples)
    with pytest.raises(ValueError, match=message):
        through_path(five, [[0, 0, 0], [0.1, 0, 0]], samples)


def test_line_path_of_a_numpy_count_is_evenly_spaced(five):
    path = line_path(five, [0, 0, 0], [0.1, 0, 0], np.int64(5))
    np.testing.assert_allclose(path.poses[:, 0], [0.0, 0.025, 0.05, 0.075, 0.1], atol=1e-15)


def test_graph_mechanism_of_a_name_says_what_it_takes():
    """Before: 'str' object has no attribute 'model'."""
    from screwkit.io import graph_mechanism
    from screwkit.io.loader import bundled_path

    for given in ("delta_rods_4", bundled_path("delta_rods_4")):
        with pytest.raises(TypeError, match=r"graph_mechanism expects a ClosedTree \(from "
                                            r"screwkit.io.read_closed_tree\), got the name or path .*delta_rods_4"):
            graph_mechanism(given)
    with pytest.raises(TypeError, match=r"graph_mechanism expects a ClosedTree .*, got int"):
        graph_mechanism(3)


def test_load_text_says_it_takes_text():
    """Before: 'cannot convert 'NoneType' object to bytes' (and an int n read as n zero bytes)."""
    from screwkit.io.loader import bundled_path, load_text

    with pytest.raises(TypeError, match=r"load_text expects the text of a URDF \(str or bytes\), got NoneType"):
        load_text(None)
    with pytest.raises(TypeError, match=r"got int"):
        load_text(5)
    path = bundled_path("planar_5rrr")
    with pytest.raises(TypeError, match=r"got PosixPath: a file or a bundled name is opened by screwkit.load"):
        load_text(Path(path))
    text = Path(path).read_text()
    for given in (text, text.encode()):
        assert load_text(given, str(path)).actuator_names == screwkit.load("planar_5rrr").actuator_names


def test_figures_say_what_they_take(five, tmp_path):
    """Before: AttributeErrors ('str' object / 'Indices' object has no attribute 'data_vars')."""
    from screwkit.plots import map_figure, sweep_figure

    with pytest.raises(TypeError, match=r"map_figure expects a map \(the xarray.Dataset or GridMap of "
                                        r"screwkit.studies.maps.index_map\), got str .*open the file first"):
        map_figure(str(tmp_path / "map.nc"))
    with pytest.raises(TypeError, match=r"map_figure expects a map .*got PosixPath"):
        map_figure(tmp_path / "map.nc")
    indices = screwkit.indices_at_poses(five, np.array([[0.0, 0.0, 0.0]]))
    with pytest.raises(TypeError, match=r"sweep_figure expects a sweep \(the xarray.Dataset of "
                                        r"screwkit.studies.sweep.sweep\), got Indices"):
        sweep_figure(indices)
    mapped = planar_disc_map(five, 0.1, 0.1, 180.0, execution=QUIET)
    with pytest.raises(TypeError, match=r"map_figure expects a map .*got str"):
        map_figure(mapped, reference="other.nc")
    assert math.isfinite(float(mapped.lmti.values[1, 1]))
