"""Bad or unusual input to the index API (closed forms, indices at poses, the result type and its exports): a one-line
ValueError/TypeError naming the parameter, never a silently wrong number or a traceback from numpy; and results
whose structure does not depend on what part of a batch is reachable."""

from __future__ import annotations

import re
from itertools import combinations
from math import comb

import numpy as np
import pytest

import screwkit
import screwkit.studies.poses as poses_module
from helpers import random_planar_rrr
from screwkit.indices.closed_forms import oti_triple, planar_indices, point_indices
from screwkit.screw.planar import paper_5rrr, planar_joint_points
from screwkit.studies.sweep import sweep

FAR, HOME = np.array([[5.0, 0.0, 0.0]]), np.array([[0.0, 0.0, 0.0]])


@pytest.fixture(scope="module")
def five_rrr():
    return screwkit.load("planar_5rrr")


@pytest.fixture(scope="module")
def fig_2a():
    """The 5-RRR's joint points at the paper's Fig. 2a pose and the unit distal directions."""
    base, elbows, distal, ok = planar_joint_points(paper_5rrr(), np.array([-0.2, 0.0, np.pi / 4]))
    assert ok
    directions = (distal - elbows) / np.linalg.norm(distal - elbows, axis=-1, keepdims=True)
    return base, elbows, distal, directions


def brute_force_f_o(directions, distal, j):
    """F_Oj by Eqs. 12 and 34 over the numpy chain OTIs (oti_triple), one configuration: no kernel involved."""
    count = distal.shape[0]
    oti = {t: float(oti_triple(directions[list(t)], distal[list(t)])[1]) for t in combinations(range(count), 3)}
    return min(max(oti[t] for t in combinations(left, 3)) for left in combinations(range(count), count - j))


# -- 1. planar_indices(directions=...) normalises ----------------------------------------------------------------

@pytest.mark.parametrize("scale", [2.0, 0.5, 3.7])
def test_planar_indices_normalises_the_directions(fig_2a, scale):
    base, elbows, distal, directions = fig_2a
    unit = planar_indices(base, None, distal, directions=directions)
    scaled = planar_indices(base, None, distal, directions=scale * directions)
    for j in (1, 2):
        assert scaled["f_o"][j] == pytest.approx(brute_force_f_o(directions, distal, j), abs=1e-12)
        if scale in (2.0, 0.5):  # exact in floating point: the very same numbers
            assert scaled["f_o"][j] == unit["f_o"][j]
    np.testing.assert_allclose(scaled["oti_submechanisms"], unit["oti_submechanisms"], rtol=0, atol=1e-14)


def test_planar_indices_refuses_a_zero_direction(fig_2a):
    base, _, distal, directions = fig_2a
    directions = directions.copy()
    directions[2] = 0.0
    with pytest.raises(ValueError, match=r"nonzero leg `directions`, got a zero vector at index \(2,\)"):
        planar_indices(base, None, distal, directions=directions)


# -- 2. planar_indices checks its inputs ---------------------------------------------------------------------------

@pytest.mark.parametrize("name", ["base", "elbows", "distal", "directions"])
def test_planar_indices_refuses_nan_points(fig_2a, name):
    base, elbows, distal, directions = (array.copy() for array in fig_2a)
    given = {"base": base, "elbows": elbows, "distal": distal, "directions": directions}
    given[name][1, 0] = np.nan
    with pytest.raises(ValueError, match=rf"finite values in `{name}`, got nan at index \(1, 0\)"):
        if name == "directions":
            planar_indices(base, None, distal, directions=directions)
        else:
            planar_indices(base, elbows, distal)


@pytest.mark.parametrize("threshold, error", [(-1.0, ValueError), (np.nan, ValueError), (np.inf, ValueError),
                                              ("1e-6", TypeError), (None, TypeError), (True, TypeError)])
def test_planar_indices_refuses_a_bad_threshold(fig_2a, threshold, error):
    base, elbows, distal, _ = fig_2a
    with pytest.raises(error, match="`threshold`"):
        planar_indices(base, elbows, distal, threshold=threshold)


def test_planar_indices_names_mismatched_shapes(fig_2a):
    base, elbows, distal, _ = fig_2a
    with pytest.raises(ValueError, match=r"`elbows` with the shape of `distal`, \(5, 2\), got \(4, 2\)"):
        planar_indices(base, elbows[:4], distal)
    with pytest.raises(ValueError, match=r"`base` with the shape of `distal`, \(5, 2\), got \(3, 5, 2\)"):
        planar_indices(np.zeros((3, 5, 2)), elbows, distal)


def test_planar_indices_of_an_empty_batch_are_empty(rng):
    full = planar_indices(*random_planar_rrr(rng, 2, 5))
    empty = planar_indices(np.zeros((0, 5, 2)), np.zeros((0, 5, 2)), np.zeros((0, 5, 2)))
    for key in ("iti_chains", "iti", "oti_submechanisms", "lmti", "mutual_interference"):
        assert empty[key].shape == (0,) + full[key].shape[1:], key
        assert empty[key].dtype == full[key].dtype, key
    for key in ("f_o", "f_io", "worst_faults", "remaining_lmti"):
        assert set(empty[key]) == set(full[key]) == {1, 2}, key
        for j in (1, 2):
            assert empty[key][j].shape == (0,) + full[key][j].shape[1:], (key, j)
    assert empty["remaining_lmti"][2].shape == (0, comb(5, 2))


def test_planar_and_point_indices_take_an_int_for_faults(rng):
    points = random_planar_rrr(rng, 3, 5)
    one, both = planar_indices(*points, faults=1), planar_indices(*points)
    assert set(one["f_o"]) == {1}
    np.testing.assert_array_equal(one["f_o"][1], both["f_o"][1])
    assert set(point_indices(*points, faults=2)["f_o"]) == {2}


@pytest.mark.parametrize("faults", [1.5, "1", True, (1, 2.0)])
def test_planar_indices_refuse_non_integer_faults(fig_2a, faults):
    with pytest.raises(TypeError, match=r"Expected `faults` as an int or a sequence of ints"):
        planar_indices(*fig_2a[:3], faults=faults)


# -- 3. faults: not truncated, checked whatever is reachable -------------------------------------------------------

@pytest.mark.parametrize("faults", [1.5, 2.9, "1", True, np.float64(1.0)])
def test_non_integer_faults_are_refused_not_truncated(five_rrr, faults):
    pose = five_rrr.named_pose("paper_fig_2a")
    with pytest.raises(TypeError, match=r"Expected `faults` as an int or a sequence of ints"):
        screwkit.indices_at_pose(five_rrr, pose, faults=faults)
    for poses in (FAR, HOME):
        with pytest.raises(TypeError, match=r"Expected `faults` as an int or a sequence of ints"):
            screwkit.indices_at_poses(five_rrr, poses, faults=faults)


@pytest.mark.parametrize("faults", [0, 7, -3, (1, 3)])
@pytest.mark.parametrize("closed_forms", [False, True])
def test_faults_are_checked_when_nothing_is_reachable(five_rrr, faults, closed_forms):
    bad = list(np.atleast_1d(faults))[-1]
    message = rf"Expected the number of faults `j` in 1\.\.a-n = 1\.\.2, got {bad}\."
    for poses in (FAR, HOME, np.zeros((0, 3))):
        with pytest.raises(ValueError, match=message):
            screwkit.indices_at_poses(five_rrr, poses, faults=faults, closed_forms=closed_forms)


def test_integer_faults_keep_working(five_rrr):
    pose = five_rrr.named_pose("paper_fig_2a")
    every = screwkit.indices_at_pose(five_rrr, pose)
    for faults, keys in ((2, [2]), (np.int64(1), [1]), ([2, 1, 2], [1, 2]), (np.array([1]), [1])):
        result = screwkit.indices_at_pose(five_rrr, pose, faults=faults)
        assert list(result.f_o) == keys
        assert all(result.f_o[j] == every.f_o[j] for j in keys)
    assert list(screwkit.indices_at_poses(five_rrr, FAR, faults=2).f_o) == [2]


# -- 4. detail is kept when nothing is reachable -------------------------------------------------------------------

@pytest.mark.parametrize("poses", [FAR, np.repeat(FAR, 3, axis=0), np.zeros((0, 3))], ids=["one", "three", "empty"])
def test_detail_when_nothing_is_reachable(five_rrr, poses):
    mixed = screwkit.indices_at_poses(five_rrr, np.concatenate([FAR, HOME]), detail=True)
    result = screwkit.indices_at_poses(five_rrr, poses, detail=True)
    count = poses.shape[0]
    assert result.oti_submechanisms.shape == (count,) + mixed.oti_submechanisms.shape[1:] == (count, comb(5, 3))
    assert np.isnan(result.oti_submechanisms).all()
    assert set(result.remaining_lmti) == set(mixed.remaining_lmti) == {1, 2}
    for j, lmti in result.remaining_lmti.items():
        assert lmti.shape == (count,) + mixed.remaining_lmti[j].shape[1:] == (count, comb(5, j))
        assert np.isnan(lmti).all()
    assert np.isnan(result.lmti_of([0, 1, 2])).all() and np.shape(result.lmti_of([0, 1, 2])) == (count,)
    assert np.isnan(mixed.lmti_of([0, 1, 2])[0])
    dataset = result.to_dataset()
    assert {"oti_submechanism", "iti_actuator"} <= set(dataset.data_vars)
    assert dataset["oti_submechanism"].dims == mixed.to_dataset()["oti_submechanism"].dims
    without = screwkit.indices_at_poses(five_rrr, poses)
    assert without.oti_submechanisms is None and without.remaining_lmti == {}


def test_a_sweep_out_of_reach_has_the_variables_of_one_within_reach(five_rrr):
    within = sweep(five_rrr, [0, 0, 0], "x", [0.0, 5.0])
    beyond = sweep(five_rrr, [5, 0, 0], "x", [5.0, 5.1])
    assert {"oti_submechanism", "lmti_remaining1", "lmti_remaining2"} <= set(within.data_vars)
    assert set(beyond.data_vars) == set(within.data_vars)
    assert np.isnan(beyond["lmti_remaining1"].values).all()


# -- 5. to_dataset: coordinates that collide, one name for dims ----------------------------------------------------

@pytest.fixture(scope="module")
def batch(five_rrr):
    return screwkit.indices_at_poses(five_rrr, np.array([[-0.2, 0.0, 0.0], [0.0, 0.0, 0.0], [0.2, 0.0, 0.0]]))


@pytest.mark.parametrize("name", ["x", "phi", "actuator", "lmti", "f_o1"])
def test_to_dataset_refuses_a_coordinate_that_replaces_its_own(batch, name):
    with pytest.raises(ValueError, match=rf"`coords` named unlike the dataset's own .*got '{name}'"):
        batch.to_dataset(coords={name: [1.0, 2.0, 3.0]})


def test_to_dataset_keeps_the_poses_and_takes_new_coordinates(batch):
    dataset = batch.to_dataset(coords={"run": ("pose", [10, 20, 30])})
    np.testing.assert_array_equal(dataset["x"].values, [-0.2, 0.0, 0.2])
    assert dataset["x"].dims == ("pose",)
    np.testing.assert_array_equal(dataset["run"].values, [10, 20, 30])


def test_to_dataset_takes_one_string_for_dims(batch):
    import xarray as xr

    xr.testing.assert_identical(batch.to_dataset(dims="pose"), batch.to_dataset(dims=("pose",)))
    assert batch.to_dataset(dims="sample")["lmti"].dims == ("sample",)
    with pytest.raises(ValueError, match=r"Expected 1 names \(str\) in `dims` for the batch shape \(3,\), "
                                         r"got \('a', 'b'\)"):
        batch.to_dataset(dims=("a", "b"))


# -- 6. one-line messages naming the parameter ---------------------------------------------------------------------

@pytest.fixture(scope="module")
def one(five_rrr):
    return screwkit.indices_at_pose(five_rrr, five_rrr.named_pose("paper_fig_2a"))


def one_line(error) -> str:
    text = str(error.value)
    assert "\n" not in text
    return text


def test_lmti_of_wants_a_sequence(one):
    for given in (3, "chain_1"):
        with pytest.raises(TypeError, match=r"`actuator_set` as a sequence of actuators") as error:
            one.lmti_of(given)
        assert repr(given) in one_line(error)
    assert one.lmti_of(["chain_1", 1, "chain_3"]) == one.lmti_of([0, 1, 2]) == one.oti_submechanisms[0]
    with pytest.raises(TypeError, match=r"an actuator as an index or a name, got True"):
        one.lmti_of([True, 2, 3])


def test_worst_fault_ties_and_failed_sets_name_faults(one):
    for j in (3, 0, 1.0, "1"):
        with pytest.raises(ValueError, match=rf"`faults` as one of the numbers of faults j computed, 1, 2, "
                                             rf"got {j!r}"):
            one.worst_fault_ties(j)
    for j in (9, 6, 0, -1, 1.5, True):
        with pytest.raises(ValueError, match=rf"`faults` as an int j in 1\.\.a = 1\.\.5 .*got {j!r}") as error:
            one.failed_sets(j)
        one_line(error)
    assert one.failed_sets(5) == ((0, 1, 2, 3, 4),)
    assert one.failed_sets(1) == tuple((k,) for k in reversed(range(5)))


def test_at_names_index(batch):
    for index in (5, -4, 1.0, "0"):
        with pytest.raises(ValueError, match=rf"`index` within the batch shape \(3,\) .*got {index!r}") as error:
            batch.at(index)
        one_line(error)
    assert batch.at(-1).lmti == batch.lmti[2]
    np.testing.assert_array_equal(batch.at((np.array([0, 2]),)).lmti, batch.lmti[[0, 2]])


@pytest.mark.parametrize("threshold", ["1e-6", None, [1e-6]])
def test_threshold_of_the_wrong_type(five_rrr, threshold):
    pose = five_rrr.named_pose("paper_fig_2a")
    message = r"`threshold` as a number >= 0 \(a length\), got " + re.escape(repr(threshold))
    with pytest.raises(TypeError, match=message):
        screwkit.indices_at_pose(five_rrr, pose, threshold=threshold)
    for poses in (FAR, HOME):
        with pytest.raises(TypeError, match=r"`threshold` as a number >= 0"):
            screwkit.indices_at_poses(five_rrr, poses, threshold=threshold)


def test_progress_is_checked_before_any_work(five_rrr, monkeypatch):
    def no_work(*arguments, **options):
        raise AssertionError("closures solved before the settings were checked")

    monkeypatch.setattr(poses_module, "solve", no_work)
    with pytest.raises(TypeError, match=r"`progress` as a callable .*got 3\."):
        screwkit.indices_at_poses(five_rrr, HOME, progress=3)
    with pytest.raises(ValueError, match=r"`threshold` >= 0 and finite \(a length\), got -1\.0"):
        screwkit.indices_at_poses(five_rrr, HOME, threshold=-1.0)


def test_graph_batches_check_their_settings_and_keep_detail():
    from screwkit.io import graph_mechanism, read_closed_tree
    from screwkit.io.loader import bundled_path
    from screwkit.studies.poses import graph_indices_at_poses

    graph = graph_mechanism(read_closed_tree(bundled_path("delta_rods_4")))
    within, beyond = [0.04, -0.03, -0.73], [5.0, -0.03, -0.73]
    for options, error, message in ((dict(chunk_size=0), ValueError, r"`chunk_size` >= 1, got 0"),
                                    (dict(faults=5), ValueError, r"`j` in 1\.\.a-n = 1\.\.1, got 5"),
                                    (dict(faults=1.0), TypeError, r"`faults` as an int or a sequence of ints"),
                                    (dict(progress=3), TypeError, r"`progress` as a callable")):
        for poses in ([beyond], [within]):
            with pytest.raises(error, match=message):
                graph_indices_at_poses(graph, poses, **options)
    mixed = graph_indices_at_poses(graph, [beyond, within], detail=True)
    alone = graph_indices_at_poses(graph, [beyond], detail=True)
    assert alone.oti_submechanisms.shape == (1,) + mixed.oti_submechanisms.shape[1:]
    assert {j: v.shape[1:] for j, v in alone.remaining_lmti.items()} == \
        {j: v.shape[1:] for j, v in mixed.remaining_lmti.items()}
    assert np.isnan(alone.oti_submechanisms).all() and np.isnan(mixed.oti_submechanisms[0]).all()


@pytest.mark.parametrize("given", ["mechanism", "name", "one chain"])
def test_analyze_names_what_it_takes_when_given_a_mechanism_a_name_or_one_chain(given):
    """``screwkit.analyze(mechanism)`` said "'Mechanism' object is not iterable"."""
    import screwkit
    from screwkit.closure import chain_screws, solve

    mechanism = screwkit.load("planar_5rrr")
    chains = chain_screws(mechanism, solve(mechanism, mechanism.home_pose[None]))
    argument = {"mechanism": mechanism, "name": "planar_5rrr", "one chain": chains[0]}[given]
    with pytest.raises(TypeError, match=r"Expected `chains` as a sequence of ChainScrews \(screwkit.closure"):
        screwkit.analyze(argument)
