"""The cache of loaded mechanisms (screwkit.io.model_cache): read back only for the same bytes, read the same way by
the same code; equal to the parsed mechanism in everything the indices use; never an error."""

from __future__ import annotations

import os
import pickle
import subprocess
import sys

import numpy as np
import pytest

import screwkit as package
from helpers import screwkit
from screwkit.closure import chain_screws, solve
from screwkit.common import caches
from screwkit.indices.analysis import analyze
from screwkit.io import model_cache
from screwkit.io.loader import bundled_path, load, mechanism_from_description
from screwkit.model.urdf_reader import read_urdf
from screwkit.studies import indices_at_poses

MECHANISMS = ("planar_5rrr", "planar_4rpr", "five_bar_3", "ups_hexapod_8", "rss_hexapod_8", "prs_3_ups", "delta_4",
              "schoenflies_5", "coop_arms")


@pytest.fixture
def cache(tmp_path, monkeypatch):
    """An empty cache folder of this test's own (``SCREWKIT_CACHE_DIR``); the folder is decided again after it."""
    monkeypatch.setenv("SCREWKIT_CACHE_DIR", str(tmp_path / "cache"))
    model_cache._folder.cache_clear()
    yield tmp_path / "cache" / "models"
    model_cache._folder.cache_clear()


def entries(folder):
    return sorted(folder.glob("*.mechanism")) if folder.is_dir() else []


def from_cache(mechanism) -> bool:
    """A mechanism read back from the cache has no Pinocchio tree until something asks for it."""
    return "pinocchio_model" not in vars(mechanism)


def poses_about_home(mechanism, count: int, seed: int = 3):
    rng = np.random.default_rng(seed)
    span = np.array([(0.1 if mechanism.is_planar else 0.02) * mechanism.length_scale if name in ("x", "y", "z")
                     else (0.3 if mechanism.is_planar else 0.05) for name in mechanism.task_coordinates])
    return mechanism.home_pose + rng.uniform(-1, 1, (count, mechanism.n_task)) * span


def assert_same_mechanism(cached, parsed):
    """Every chain's names, actuators, limits, geometry, solver and working mode, the reference assembly, the
    poses and task coordinates; then the chain screws and every index at poses about home, bit for bit."""
    assert cached is not parsed
    for name in ("name", "path", "is_planar", "pose_coordinates", "base_link", "platform_link", "platform_joint",
                 "platform_joint_id", "dof", "length_scale", "length_unit", "task_axes", "task_source",
                 "instantaneous_dof", "assembly_notes", "import_report", "task_coordinates", "actuator_names"):
        assert getattr(cached, name) == getattr(parsed, name), name
    for name in ("rotation_world_base", "translation_world_base", "home_rotation", "home_translation", "home_pose"):
        np.testing.assert_array_equal(getattr(cached, name), getattr(parsed, name), err_msg=name)
    assert (cached.output_point is None) == (parsed.output_point is None)
    assert cached.named_poses.keys() == parsed.named_poses.keys()
    for name, pose in parsed.named_poses.items():
        np.testing.assert_array_equal(cached.named_poses[name], pose)
    assert cached.description.text == parsed.description.text
    assert len(cached.chains) == len(parsed.chains)
    for ours, theirs in zip(cached.chains, parsed.chains):
        for name in ("name", "joint_names", "actuated", "prismatic", "loop_name", "loop_type", "tree_joint_ids",
                     "solver", "solver_reason", "branch", "reference_sign"):
            assert getattr(ours, name) == getattr(theirs, name), (ours.name, name)
        np.testing.assert_array_equal(ours.joint_limits, theirs.joint_limits)
        np.testing.assert_array_equal(ours.reference_values, theirs.reference_values)
        assert type(ours.closed_form) is type(theirs.closed_form)
        for name, value in vars(theirs.geometry).items():
            if isinstance(value, np.ndarray):
                np.testing.assert_array_equal(getattr(ours.geometry, name), value, err_msg=f"{ours.name}.{name}")
            else:
                assert getattr(ours.geometry, name) == value, (ours.name, name)
    poses = poses_about_home(parsed, 12)
    solved = [solve(mechanism, poses) for mechanism in (cached, parsed)]
    np.testing.assert_array_equal(solved[0].reachable, solved[1].reachable)
    assert np.count_nonzero(solved[1].reachable) >= 6
    screws = [chain_screws(mechanism, solution, unreachable="drop") for mechanism, solution in zip((cached, parsed),
                                                                                                   solved)]
    for ours, theirs in zip(*screws):
        np.testing.assert_array_equal(ours.twists, theirs.twists)
        np.testing.assert_array_equal(ours.points, theirs.points)
    ours, theirs = (indices_at_poses(mechanism, poses, detail=True) for mechanism in (cached, parsed))
    for name in ("iti", "lmti", "iti_actuators", "oti_submechanisms", "cti", "instantaneous_dof"):
        if getattr(theirs, name) is not None:
            np.testing.assert_array_equal(getattr(ours, name), getattr(theirs, name), err_msg=name)
    for j in theirs.f_o:
        np.testing.assert_array_equal(ours.f_o[j], theirs.f_o[j])
        np.testing.assert_array_equal(ours.f_io[j], theirs.f_io[j])
        np.testing.assert_array_equal(ours.worst_fault_indices[j], theirs.worst_fault_indices[j])


@pytest.mark.parametrize("name", MECHANISMS)
def test_a_mechanism_read_back_from_the_cache_equals_the_parsed_one(cache, name):
    parsed = mechanism_from_description(read_urdf(bundled_path(name)))
    assert load(name) is not None and len(entries(cache)) == 1  # parsed and kept
    cached = load(name)
    assert from_cache(cached)
    assert_same_mechanism(cached, parsed)
    assert "pinocchio" not in {type(value).__module__.split(".")[0] for value in vars(cached).values()}
    # its Pinocchio tree, built from the description when first asked for, is the parsed one's
    model, theirs = cached.pinocchio_model, parsed.pinocchio_model
    assert (model.nq, model.nv, list(model.names)) == (theirs.nq, theirs.nv, list(theirs.names))
    for ours, placement in zip(model.jointPlacements, theirs.jointPlacements):
        np.testing.assert_array_equal(ours.homogeneous, placement.homogeneous)
    np.testing.assert_array_equal(cached.platform_frame_placement.homogeneous,
                                  parsed.platform_frame_placement.homogeneous)


def test_the_indices_of_chain_screws_from_the_cache_are_those_of_the_parsed_file(cache):
    parsed = mechanism_from_description(read_urdf(bundled_path("planar_5rrr")))
    load("planar_5rrr")
    cached = load("planar_5rrr")
    poses = np.array([cached.named_pose("paper_fig_2a"), cached.home_pose, [0.1, -0.2, 0.7]])
    ours, theirs = (analyze(chain_screws(m, solve(m, poses), unreachable="drop"), detail=True)
                    for m in (cached, parsed))
    np.testing.assert_array_equal(ours.oti_submechanisms, theirs.oti_submechanisms)
    assert round(float(ours.f_o[1][0]), 4) == 0.6793  # the paper's Fig. 2a


def moved_base_joint(text: str, shift: float) -> str:
    """The 5-RRR's first base joint moved along x by ``shift`` (its arms still reach the home pose)."""
    start = text.index("<joint name=\"chain_1_joint_b\"")
    origin = text.index("<origin xyz=\"", start) + len("<origin xyz=\"")
    x, rest = text[origin:].split(" ", 1)
    return text[:origin] + repr(float(x) + shift) + " " + rest


def base_joint_x(mechanism) -> float:
    return float(mechanism.chains[0].geometry.joint_translations[0, 0])


def test_a_changed_file_is_parsed_again(cache, tmp_path):
    text = bundled_path("planar_5rrr").read_text()
    path = tmp_path / "five.urdf"
    path.write_text(text)
    first = load(path)
    assert not from_cache(first) and from_cache(load(path))
    path.write_text(moved_base_joint(text, 0.01))
    changed = load(path)
    assert not from_cache(changed), "the changed file was read from the cache"
    assert base_joint_x(changed) == pytest.approx(base_joint_x(first) + 0.01, abs=1e-12)
    assert base_joint_x(load(path)) == base_joint_x(changed)
    path.write_text(text)  # the first bytes again: their entry is still there
    again = load(path)
    assert from_cache(again) and base_joint_x(again) == base_joint_x(first)
    assert len(entries(cache)) == 2


def test_how_a_file_is_read_is_part_of_the_key(cache, tmp_path):
    path = tmp_path / "five.urdf"
    path.write_text(bundled_path("planar_5rrr").read_text())
    metres = load(path)
    millimetres = load(path, length_unit="mm")
    assert not from_cache(millimetres)
    assert millimetres.length_scale == pytest.approx(metres.length_scale / 1000)
    copy = tmp_path / "copy.urdf"  # the same bytes elsewhere: messages name this file
    copy.write_text(path.read_text())
    assert load(copy).path == str(copy)
    assert from_cache(load(path, length_unit="mm")) and from_cache(load(copy))


def test_another_version_of_screwkit_parses_the_file_again(cache, monkeypatch):
    load("planar_5rrr")
    assert from_cache(load("planar_5rrr"))
    monkeypatch.setattr(package, "__version__", package.__version__ + ".post1")
    caches.package_fingerprint.cache_clear()
    try:
        assert not from_cache(load("planar_5rrr"))
        assert from_cache(load("planar_5rrr")) and len(entries(cache)) == 2
    finally:
        monkeypatch.undo()
        caches.package_fingerprint.cache_clear()
    assert from_cache(load("planar_5rrr"))


def test_edited_sources_parse_the_file_again(cache, monkeypatch):
    load("planar_5rrr")
    fingerprint = caches.package_fingerprint()
    monkeypatch.setattr(model_cache, "package_fingerprint", lambda: fingerprint[::-1])
    assert not from_cache(load("planar_5rrr"))


def test_an_unwritable_cache_folder_parses_silently(tmp_path, monkeypatch, capsys):
    blocker = tmp_path / "a_file"
    blocker.write_text("not a folder")
    monkeypatch.setenv("SCREWKIT_CACHE_DIR", str(blocker / "cache"))  # cannot be created, even by root
    model_cache._folder.cache_clear()
    try:
        mechanism = load("planar_5rrr")
        assert not from_cache(mechanism) and not from_cache(load("planar_5rrr"))
        assert capsys.readouterr() == ("", "")
        assert round(float(indices_at_poses(mechanism, mechanism.named_pose("paper_fig_2a")).f_o[1]), 4) == 0.6793
    finally:
        model_cache._folder.cache_clear()


def test_a_write_that_fails_or_an_entry_that_cannot_be_read_parses_silently(cache, monkeypatch, capsys):
    def full_disk(*args, **kwargs):
        raise OSError(28, "No space left on device")

    with monkeypatch.context() as patched:
        patched.setattr(model_cache.tempfile, "mkstemp", full_disk)
        assert not from_cache(load("planar_5rrr"))
    assert entries(cache) == [] and not any(cache.iterdir())
    load("planar_5rrr")
    (entry,) = entries(cache)
    for damaged in (b"", entry.read_bytes()[:100], pickle.dumps({"format": -1}), b"not a pickle"):
        entry.write_bytes(damaged)
        mechanism = load("planar_5rrr")
        assert not from_cache(mechanism) and mechanism.dof == 3
        assert from_cache(load("planar_5rrr"))  # written again, whole
    assert capsys.readouterr() == ("", "")


def test_a_file_that_cannot_be_read_is_an_error_not_an_entry(cache, tmp_path):
    path = tmp_path / "bad.urdf"
    path.write_text("<robot name='bad'></robot>")
    for _ in range(2):
        with pytest.raises(ValueError, match="bad.urdf"):
            load(path)
    assert entries(cache) == []


def test_the_oldest_entries_go_beyond_the_limit(cache, tmp_path, monkeypatch):
    monkeypatch.setattr(model_cache, "MAX_ENTRIES", 2)
    text = bundled_path("planar_5rrr").read_text()
    for shift in (0.001, 0.002, 0.003):
        path = tmp_path / f"five_{shift}.urdf"
        path.write_text(moved_base_joint(text, shift))
        load(path)
    assert len(entries(cache)) == 2
    assert not from_cache(load(tmp_path / "five_0.001.urdf"))  # the oldest went


def test_a_map_task_reads_its_mechanism_back(cache):
    from screwkit.io.loader import cached_mechanism
    from screwkit.studies.maps import portable

    mechanism = load("planar_5rrr")
    text = portable(mechanism)
    task = cached_mechanism(*text)
    cached_mechanism.cache_clear()
    again = cached_mechanism(*text)
    assert from_cache(again) and not from_cache(task)
    assert_same_mechanism(again, task)


def test_a_command_with_an_unwritable_cache_folder_says_nothing(tmp_path):
    blocker = tmp_path / "a_file"
    blocker.write_text("not a folder")
    result = screwkit("analyze", "planar_5rrr", "--pose", "paper_fig_2a", "--json",
                      env=dict(os.environ, SCREWKIT_CACHE_DIR=str(blocker / "cache")))
    assert result.returncode == 0 and result.stderr == "", result.stderr
    assert '"f_o": {"1": 0.679' in result.stdout


def test_a_command_reads_its_mechanism_back_without_pinocchio(tmp_path):
    """The second run of a command reads the mechanism back: neither Pinocchio nor Dask is imported."""
    environment = dict(os.environ, SCREWKIT_CACHE_DIR=str(tmp_path))
    code = ("import sys; from screwkit.cli import app; app.main(['analyze', 'planar_5rrr', '--json'], "
            "standalone_mode=False); print('pinocchio' in sys.modules, 'dask' in sys.modules, file=sys.stderr)")
    first, second = (subprocess.run([sys.executable, "-W", "error", "-c", code], capture_output=True, text=True,
                                    env=environment, timeout=300) for _ in range(2))
    assert first.stderr.split() == ["True", "False"] and second.stderr.split() == ["False", "False"], second.stderr
    assert first.stdout == second.stdout
