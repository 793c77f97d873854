"""Operation modes meeting at a constraint-singular reference assembly (screwkit.closure.modes).

A U-P-U platform drawn as a published Gazebo "Stewart platform" draws its legs (every hinge horizontal, every leg's
couple vertical) is at a constraint singularity where its translational mode meets a mode that turns it. Its task
coordinates must be those of a mode the closure follows from the reference assembly, whatever the scale, the world
frame and the order of the legs; the translational mode's poses are checked against its closed form (each slide
is the change of the distance between its two universal joints, the platform does not turn)."""

from __future__ import annotations

import re

import numpy as np
import pytest
from sdformat_models import rotation_z, upu_legs, upu_sdf

from helpers import in_unit, moved_in_the_world
from screwkit.closure import actuator_values, chain_screws, solve
from screwkit.closure.assembly import MODES_MEET
from screwkit.closure.chain_kinematics import chain_forward_kinematics
from screwkit.common.rotations import rotation_vector_from_rotation
from screwkit.io.loader import bundled_path, load
from screwkit.screw.reference import reference_indices
from screwkit.studies import indices_at_pose, indices_at_poses

VARIANTS = [(3, 1.0, (0.0, (0.0, 0.0, 0.0)), False), (6, 1.0, (0.0, (0.0, 0.0, 0.0)), False),
            (3, 1000.0, (0.0, (0.0, 0.0, 0.0)), False), (3, 1.0, (0.7, (0.3, -0.2, 0.5)), True),
            (6, 1e-3, (-2.1, (-5.0, 40.0, 1.0)), True)]


def upu(tmp_path, legs, scale, world, reverse, name="upu.sdf"):
    path = tmp_path / name
    path.write_text(upu_sdf(legs, scale=scale, world=world, reverse=reverse))
    return path


def joints(legs: int, scale: float, jitter: float = 0.0, decimals: int | None = None):
    """The universal joints' centres of :func:`upu_sdf` in its model frame (feet, heads, legs in order), as written
    to ``decimals``."""
    geometry = upu_legs(legs, scale, jitter=jitter)
    feet, heads = np.array([leg[0] for leg in geometry]), np.array([leg[1] for leg in geometry])
    return (feet, heads) if decimals is None else (np.round(feet, decimals), np.round(heads, decimals))


@pytest.mark.parametrize("legs, scale, world, reverse", VARIANTS)
def test_a_upu_platform_drawn_where_its_modes_meet_translates(tmp_path, legs, scale, world, reverse):
    mechanism = load(upu(tmp_path, legs, scale, world, reverse))
    assert (mechanism.dof, mechanism.instantaneous_dof) == (3, 5)
    assert mechanism.task_coordinates == ("x", "y", "z")
    notes = [note for note in mechanism.assembly_notes if note.startswith(MODES_MEET)]
    assert len(notes) == 1 and "followed: the one where the platform translates only (coordinates x, y, z" in notes[0]
    assert "not followed: the one where the platform turns" in notes[0]
    rng = np.random.default_rng(4)
    moves = rng.uniform(-0.15, 0.15, (6, 3)) * scale  # in the model frame
    yaw, _ = world
    home = mechanism.home_full_pose
    solution = solve(mechanism, home[:3] + moves @ rotation_z(yaw).T)
    assert solution.reachable.all()
    np.testing.assert_allclose(solution.full_poses[:, 3:] - home[3:], 0.0, atol=1e-9)  # it does not turn
    feet, heads = joints(legs, scale)
    lengths = np.linalg.norm(heads[None] + moves[:, None] - feet[None], axis=-1) - 1.9 * scale
    order = [int(name.split("_")[-1]) for name in mechanism.actuator_names]
    np.testing.assert_allclose(actuator_values(mechanism, solution.joint_values), lengths[:, order],
                               atol=1e-9 * scale)


def test_a_3_upu_drawn_at_its_constraint_singularity_opens_with_its_three_slides(tmp_path):
    """Its 3 slides drive its 3 DOF; at the reference assembly it has 5 instantaneous DOF, which once asked for 5
    actuators."""
    mechanism = load(upu(tmp_path, 3, 1.0, (0.0, (0.0, 0.0, 0.0)), False))
    assert len(mechanism.actuator_names) == 3 and mechanism.dof == 3


def test_declared_coordinates_follow_the_mode_they_drive(tmp_path):
    """Declared coordinates that only the turning mode has independent follow it: a roll of 1 degree closes, turns
    the platform and moves it sideways (the mode couples them), every loop closed."""
    from screwkit.closure import closure_residuals
    from screwkit.io import read_mechanism_file
    from screwkit.io.loader import load_text

    text, _ = read_mechanism_file(upu(tmp_path, 3, 1.0, (0.0, (0.0, 0.0, 0.0)), False))  # as screwkit convert writes
    mechanism = load_text(text.replace("</robot>", '<task_coordinates names="x roll pitch" /></robot>'), "upu.urdf")
    assert mechanism.task_coordinates == ("x", "roll", "pitch") and mechanism.task_source == "declared"
    assert mechanism.held_axes == ()  # the turning mode: its dependent coordinates are solved
    notes = [note for note in mechanism.assembly_notes if note.startswith(MODES_MEET)]
    assert "followed: the one where the platform turns" in notes[0]
    solution = solve(mechanism, np.array([0.0, np.radians(1.0), 0.0]))
    assert solution.reachable.all()
    assert abs(solution.full_poses[3] - np.radians(1.0)) < 1e-12 and abs(solution.full_poses[1]) > 1e-3
    assert np.max(np.abs(closure_residuals(mechanism, solution))) < 1e-9


@pytest.mark.parametrize("legs", [3, 6])
def test_the_reference_assembly_analysed_alone_is_the_constraint_singularity_it_is(tmp_path, legs):
    """Analysed alone, the reference assembly's chains share their one couple each, as they do nowhere else: the
    structure read there once made it a regular pose (no CTI, LMTI 0.91 for 6 legs against 0.51 a few cm away).
    It is a constraint singularity (5 instantaneous DOF, no 3 slides hold the platform): LMTI and every F_Oj 0, as
    the numpy reference (which reads the configuration alone) gives, and as the same pose gives in a batch with
    regular poses."""
    from test_reference import compare

    mechanism = load(upu(tmp_path, legs, 1.0, (0.0, (0.0, 0.0, 0.0)), False))
    home = mechanism.home_pose
    alone = compare(mechanism, home[None])
    batch = compare(mechanism, home + np.array([[0.0, 0.0, 0.0], [0.05, 0.03, -0.01], [-0.04, 0.02, 0.03]]))
    for result in (alone.at(0), batch.at(0)):
        assert result.constraint_singular and result.instantaneous_dof == 5
        assert result.lmti == 0.0 and all(value == 0.0 for value in result.f_o.values())
    assert not batch.at(1).constraint_singular and batch.at(1).lmti > 0.1


def test_the_commands_say_which_mode_they_follow_and_analyse_the_singular_home_as_such(tmp_path):
    """As users run it: ``info`` names the modes under the constraint singularity line (and every command says it
    once on stderr); ``analyze`` at home says CONSTRAINT SINGULARITY with LMTI 0; ``sweep`` across x closes every
    pose in the translational mode, LMTI 0 only at the singular home."""
    import json

    import xarray as xr

    from helpers import screwkit

    path = upu(tmp_path, 6, 1.0, (0.0, (0.0, 0.0, 0.0)), False)
    info = screwkit("info", path)
    assert info.returncode == 0, info.stderr
    lines = info.stdout.splitlines()
    singular = next(i for i, line in enumerate(lines) if "the home pose is a constraint singularity" in line)
    assert lines[singular + 1].startswith(f"  {MODES_MEET}2 meet at the reference assembly")
    assert "task coordinates: x (m), y (m), z (m)" in info.stdout
    assert ("  dependent coordinates held at home (the operation mode followed does not turn the platform): roll, "
            "pitch, yaw") in lines and "solved with the closure" not in info.stdout
    described = json.loads(screwkit("info", path, "--json").stdout)
    assert described["held_coordinates"] == ["roll", "pitch", "yaw"]
    assert [line for line in info.stderr.splitlines() if MODES_MEET in line] == [
        f"{path}: {lines[singular + 1].strip()}"]
    analyzed = screwkit("analyze", path, "--json")
    assert analyzed.returncode == 0, analyzed.stderr
    report = json.loads(analyzed.stdout)
    assert report["constraint_singular"] and report["instantaneous_dof"] == 5 and report["lmti"] == 0.0
    assert any(note.startswith(MODES_MEET) for note in report["assembly"])
    out = tmp_path / "sweep.nc"
    swept = screwkit("sweep", path, "--sweep", "x:-0.2:0.2:0.1", "--out", out, "--quiet")
    assert swept.returncode == 0, swept.stderr
    with xr.open_dataset(out) as sweep:
        assert bool(sweep["reachable"].all()) and float(sweep["lmti"].sel(x=0.0)) == 0.0
        assert float(sweep["lmti"].sel(x=0.1)) > 0.1


@pytest.mark.parametrize("draw", [*range(6), 86])  # 86: only the turning mode found by the random samples
def test_the_translational_mode_is_found_whatever_the_random_samples(tmp_path, monkeypatch, draw):
    """The random samples near home fall in the translational mode about one time in ten: with other random draws
    than the shipped ones, some found only the turning mode (draw 86 of the first 120 with random samples alone), and
    the file read x, roll, pitch again with no note. The samples offset in the translations alone find it every time
    (the 120 draws)."""
    import screwkit.closure.assembly as assembly
    import screwkit.io.model_cache as model_cache

    monkeypatch.setattr(model_cache, "_folder", lambda: None)  # built, not read back from the cache
    drawn = assembly._generic_samples
    monkeypatch.setattr(assembly, "_generic_samples", lambda mechanism, count=6, seed=0, **moving: drawn(
        mechanism, count, seed + 1000 * (draw + 1), **moving))
    mechanism = load(upu(tmp_path, 6, 1.0, (0.0, (0.0, 0.0, 0.0)), False))
    assert mechanism.task_coordinates == ("x", "y", "z")
    notes = [note for note in mechanism.assembly_notes if note.startswith(MODES_MEET)]
    assert "followed: the one where the platform translates only" in notes[0]


@pytest.mark.parametrize("legs, scale, world, reverse", [(3, 1.0, (0.0, (0.0, 0.0, 0.0)), False),
                                                    (6, 1.0, (0.0, (0.0, 0.0, 0.0)), False),
                                                    (6, 1000.0, (0.7, (300.0, -200.0, 500.0)), True)])
def test_a_pure_lift_stays_where_the_modes_meet(tmp_path, legs, scale, world, reverse):
    """Every pure lift (x = y = 0) keeps every hinge horizontal and every leg's couple vertical: the constraint
    singularity of home, 5 instantaneous DOF. There the closure is a double root; with legs not quite alike (a
    published file's angles written 2.0945) it stopped a few 1e-6 rad into the turning mode and read 3 DOF, LMTI
    0.55-0.59. The translational mode's orientation is held at home's: the lift is the closed form (each slide the
    change of its leg's length), singular, LMTI and every F_Oj 0."""
    from screwkit.studies import indices_at_poses

    path = tmp_path / "upu.sdf"
    path.write_text(upu_sdf(legs, scale=scale, world=world, reverse=reverse, jitter=1e-3))
    mechanism = load(path)
    assert [mechanism.pose_coordinates[i] for i in mechanism.held_axes] == ["roll", "pitch", "yaw"]
    lifts = np.array([[0.0, 0.0, dz] for dz in (0.05, 0.1, 0.2)]) * scale  # the world's vertical is the model's
    solution = solve(mechanism, mechanism.home_pose + lifts)
    assert solution.reachable.all()
    np.testing.assert_array_equal(solution.full_poses[:, 3:], np.broadcast_to(mechanism.home_full_pose[3:], (3, 3)))
    feet, heads = joints(legs, scale, jitter=1e-3)
    lengths = np.linalg.norm(heads[None] + lifts[:, None] - feet[None], axis=-1) - np.linalg.norm(heads - feet, axis=-1)
    order = [int(name.split("_")[-1]) for name in mechanism.actuator_names]
    np.testing.assert_allclose(actuator_values(mechanism, solution.joint_values), lengths[:, order],
                               atol=1e-9 * scale)
    indices = indices_at_poses(mechanism, mechanism.home_pose + lifts)
    assert np.all(indices.instantaneous_dof == 5) and np.all(indices.constraint_singular)
    assert np.all(indices.lmti == 0.0) and all(np.all(value == 0.0) for value in indices.f_o.values())


def test_a_six_leg_platform_written_to_four_decimals_keeps_its_mobility(tmp_path):
    """Written to 4 decimals, the six legs leave the platform its translations alone (no turning mode): none of the
    random samples near home closed, and the file read DOF 5 (x, y, z, roll, pitch), the instantaneous DOF of home.
    Samples offset in the translations alone close: DOF 3, x, y, z, its poses the closed form of the rounded file."""
    path = tmp_path / "upu.sdf"
    path.write_text(upu_sdf(6, decimals=4))
    mechanism = load(path)
    assert (mechanism.dof, mechanism.task_coordinates) == (3, ("x", "y", "z"))
    moves = np.random.default_rng(2).uniform(-0.15, 0.15, (5, 3))
    solution = solve(mechanism, mechanism.home_pose + moves)
    assert solution.reachable.all()
    np.testing.assert_allclose(solution.full_poses[:, 3:] - mechanism.home_full_pose[3:], 0.0, atol=1e-12)
    feet, heads = joints(6, 1.0, decimals=4)
    lengths = np.linalg.norm(heads[None] + moves[:, None] - feet[None], axis=-1) - np.linalg.norm(heads - feet, axis=-1)
    order = [int(name.split("_")[-1]) for name in mechanism.actuator_names]
    np.testing.assert_allclose(actuator_values(mechanism, solution.joint_values), lengths[:, order], atol=1e-9)


@pytest.mark.parametrize("scale, world, reverse", [(1.0, (0.0, (0.0, 0.0, 0.0)), True),
                                                   (1e-3, (-2.1, (-5.0, 40.0, 1.0)), False)])
def test_the_legs_relabelled_give_the_same_indices_and_the_same_worst_legs(tmp_path, scale, world, reverse):
    """Six U-P-U legs whose names are permuted (leg k called sigma(k): the sorted actuators are other legs), at a
    regular pose off the lift line: every index is that of the file as drawn (scaled, moved, its legs listed in either
    order), and each worst fault set names the same legs, relabelled."""
    sigma = [3, 5, 0, 4, 1, 2]
    drawn = load(upu(tmp_path, 6, 1.0, (0.0, (0.0, 0.0, 0.0)), False, "drawn.sdf"))
    text = re.sub(r"_(\d)(?=[\"<])", lambda match: f"_{sigma[int(match.group(1))]}",
                  upu_sdf(6, scale=scale, world=world, reverse=reverse))
    (tmp_path / "relabelled.sdf").write_text(text)
    relabelled = load(tmp_path / "relabelled.sdf")
    step = np.array([0.05, 0.03, 0.1])
    reference = indices_at_pose(drawn, drawn.home_pose + step)
    found = indices_at_pose(relabelled, relabelled.home_pose + rotation_z(world[0]) @ step * scale)
    for name in ("iti", "lmti", "cti"):
        assert float(getattr(found, name)) == pytest.approx(float(getattr(reference, name)), abs=1e-9), name
    renamed = {f"yb_{k}:slide_{k}": f"yb_{sigma[k]}:slide_{sigma[k]}" for k in range(6)}
    for j in reference.faults:
        assert float(found.f_o[j]) == pytest.approx(float(reference.f_o[j]), abs=1e-9)
        assert float(found.f_io[j]) == pytest.approx(float(reference.f_io[j]), abs=1e-9)
        assert float(found.f_c[j]) == pytest.approx(float(reference.f_c[j]), abs=1e-9)
        expected = {frozenset(renamed[name] for name in tie) for tie in reference.worst_fault_ties(j)}
        assert {frozenset(tie) for tie in found.worst_fault_ties(j)} == expected
        assert frozenset(found.worst_faults[j]) in expected
    np.testing.assert_allclose(sorted(found.iti_actuators), sorted(reference.iti_actuators), atol=1e-9)


@pytest.mark.parametrize("decimals, scale, world, unit, reverse", [
    (4, 1.0, (0.0, (0.0, 0.0, 0.0)), None, False), (5, 1.0, (0.0, (0.0, 0.0, 0.0)), None, False),
    (6, 1.0, (0.0, (0.0, 0.0, 0.0)), None, False), (2, 1000.0, (0.0, (300.0, -200.0, 500.0)), "mm", True),
    (8, 1e-3, (0.0, (0.3e-3, 0.2e-3, -0.1e-3)), "km", True)])
def test_lifts_of_a_rounded_platform_give_each_pose_the_same_indices_in_any_batch(tmp_path, decimals, scale, world,
                                                                               unit, reverse):
    """Written to 4-6 decimals, the lift line of a 3-U-P-U is a constraint singularity only to 1e-9 to 1e-5: its
    legs' couples are that near parallel. The eigenvectors that gave the motion space did not resolve the two
    rotations the legs nearly allow (eigenvalues 1e-16 and below), and the plan read the couples as one common
    wrench wherever every pose of the batch was a lift, then never found a lift singular: the LMTI of one lift was
    0.4942 alone and 0.0635 in a batch of lifts (5 decimals), 0 alone and 0.5036 in a batch (6 decimals). Each lift
    is now the same in any batch, and the numpy reference's, to what so near a singularity resolves (1e-16 over the
    couples' 1e-9: 1e-7)."""
    path = tmp_path / "rounded.sdf"
    path.write_text(upu_sdf(3, scale=scale, world=world, reverse=reverse, decimals=decimals))  # as 5 decimals in m
    mechanism = load(path, length_unit=unit)
    lifts = mechanism.home_pose + np.array([[0.0, 0.0, dz] for dz in (0.01, 0.05, 0.1, 0.2)])
    solution = solve(mechanism, lifts)
    chains = chain_screws(mechanism, solution)
    for row, pose in enumerate(lifts):
        single = indices_at_pose(mechanism, pose)
        expected = reference_indices([c.twists[row] for c in chains], [c.points[row] for c in chains],
                                     [c.actuated for c in chains], mechanism.dof)
        assert float(single.lmti) == pytest.approx(expected["lmti"], abs=1e-6)
        assert float(single.iti) == pytest.approx(expected["iti"], abs=1e-6)
        assert single.instantaneous_dof == expected["instantaneous_dof"]
        regular = mechanism.home_pose + np.array([[0.05, 0.03, 0.1]])
        for batch, at in ((lifts, row), (lifts[::-1], 3 - row), (np.vstack([regular, lifts]), row + 1)):
            result = indices_at_poses(mechanism, batch)
            assert float(result.lmti[at]) == pytest.approx(float(single.lmti), abs=1e-6)
            assert float(result.iti[at]) == pytest.approx(float(single.iti), abs=1e-6)


def one_leg_turned_over(text: str) -> str:
    """The bundled Delta with its first leg's platform universal joint written from the platform (``<predecessor>``
    and ``<successor>`` swapped, the axes kept): that leg's cross turns about the other axes first, another mechanism,
    whose reference assembly is a constraint singularity where two translational modes meet."""
    start = text.index("<loop name=\"leg_1_joint_platform\"")
    end = text.index("</loop>", start)
    loop = text[start:end].replace("predecessor", "@").replace("successor", "predecessor").replace("@", "successor")
    return text[:start] + loop + text[end:]


def test_a_mode_with_its_turns_held_and_a_translation_dependent_closes_its_poses(tmp_path):
    """The operation mode followed has its platform's three angles held at the reference assembly's values and one
    translation dependent (the closure solves it): the closure passed the task coordinates where it reads the held
    and task ones together, and numpy refused to broadcast (4, 2) to (4, 5) from inside the loading. Now the mechanism
    opens (2 DOF, x and z), and poses of the mode close: at each reached pose the angles are the reference's and each
    leg's end frame meets its loop frame on the platform (forward kinematics, not the closure's residual) to 1e-9."""
    path = tmp_path / "delta.urdf"
    path.write_text(one_leg_turned_over(bundled_path("delta_4").read_text()))
    delta = load(path)
    assert (delta.dof, delta.task_coordinates) == (2, ("x", "z"))
    assert [delta.pose_coordinates[axis] for axis in delta.held_axes] == ["roll", "pitch", "yaw"]
    poses = delta.home_pose + np.array([[0.0, 0.0], [0.01, 0.0], [-0.005, 0.01], [0.008, -0.006]])
    solution = solve(delta, poses)
    assert solution.reachable.all()
    np.testing.assert_allclose(solution.full_poses[:, 3:], np.broadcast_to(delta.home_full_pose[3:], (4, 3)),
                               rtol=0, atol=1e-12)
    rotations, translations = delta.transforms_from_poses(solution.full_poses)
    for index, chain in enumerate(delta.chains):
        for k in range(len(poses)):
            frames = chain_forward_kinematics(chain.geometry, solution.joint_values[index][k])
            rotation, translation = delta.loop_targets(index, rotations[k], translations[k])
            assert np.linalg.norm(frames.end_translation - translation) <= 1e-9
            assert np.linalg.norm(rotation_vector_from_rotation(frames.end_rotation.T @ rotation)) <= 1e-9


@pytest.mark.parametrize("variant", ["x 1e-3", "x 1e3", "world", "renamed"])
def test_the_mode_with_held_turns_reads_alike_at_any_size_in_any_world_and_naming(tmp_path, variant):
    """The same mechanism at a thousandth and a thousand times its size (poses scaled with it), hung in a turned and
    moved world (a fixed joint above its base; poses compared in its own frame, at its home plus the same offsets),
    and with its legs named the other way round (leg_1 is leg_4: the leg written from the platform is then the last):
    2 DOF, and at three poses of the mode every leg's ITI, every OTI and the LMTI those of the file in metres to
    1e-9."""
    text = one_leg_turned_over(bundled_path("delta_4").read_text())
    size, legs = 1.0, [0, 1, 2, 3]
    if variant.startswith("x"):
        size = float(variant[2:])
        other = in_unit(text, "m", size)
    elif variant == "world":
        other = moved_in_the_world(text, (0.4, -1.3, 2.1), (0.7, -1.1, 2.3))
    else:
        other, legs = re.sub(r"leg_([1-4])", lambda m: f"leg_{5 - int(m.group(1))}", text), [3, 2, 1, 0]
    (tmp_path / "m.urdf").write_text(text)
    (tmp_path / "other.urdf").write_text(other)
    first, second = load(tmp_path / "m.urdf"), load(tmp_path / "other.urdf")
    assert first.dof == second.dof == 2
    offsets = np.array([[0.01, 0.0], [-0.005, 0.01], [0.008, -0.006]])
    one = indices_at_poses(first, first.home_pose + offsets, detail=True)
    two = indices_at_poses(second, second.home_pose + offsets * size, detail=True, threshold=1e-6 * size)
    assert one.reachable.all() and two.reachable.all()
    np.testing.assert_allclose(two.iti_actuators[:, legs], one.iti_actuators, rtol=0, atol=1e-9)
    np.testing.assert_allclose(np.sort(two.oti_submechanisms, axis=1), np.sort(one.oti_submechanisms, axis=1), rtol=0,
                               atol=1e-9)
    np.testing.assert_allclose(two.lmti, one.lmti, rtol=0, atol=1e-9)
