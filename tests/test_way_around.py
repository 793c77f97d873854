"""Poses the straight way from the reference leaves in another assembly, solved from many starts (closure.around).

The textbook checks of the poses it reaches are in ``test_point_leg_mode.py`` (a diamond five-bar all the way round
its hip, its motors turned together, a sweep on the command line). Here: the rule that takes an assembly (one, to
``SAME_ASSEMBLY``, among the starts that keep the working-mode sign), which chains it applies to, and that poses out
of the leg's reach are still refused, saying which chain misses; and the same for actuator values
(``forward_from_starts``, ``analyze --actuators``) on a five-bar whose hips are apart (a PhoneBot leg's layout), where
the way from the start pose passes the fold between the hips: checked against the textbook's forward kinematics in
the drawing's working mode (each elbow) and assembly mode (the foot on the drawing's side of the line of the knees).
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from test_point_leg_mode import CALF, THIGH, diamond

from helpers import MJCF_WORLDS, mjcf_variant, one_line_error, screwkit, screwkit_json
from screwkit.closure.around import MOST_STARTS, SAME_ASSEMBLY, TURNS, eligible, one_assembly, starts
from screwkit.closure.forward_kinematics import forward, forward_from_starts
from screwkit.io.loader import load
from screwkit.studies import indices_at_pose


def test_one_assembly_is_taken_only_where_every_kept_start_agrees():
    angular = np.array([True, False])  # a hinge and a slide
    length = 1e-3  # (a millimetre-sized mechanism: a slide's 1e-7 m is 1e-4 length scales)
    values = np.zeros((4, 3, 2))
    kept = np.ones((4, 3), dtype=bool)
    values[0, 1, 0] = 2 * math.pi + 0.1 * SAME_ASSEMBLY  # the same hinge angle a turn away: one assembly
    values[1, 2, 1] = 1e-7  # the slide apart by 1e-4 length scales: two assemblies
    values[2, 2, 0] = 1.0  # two assemblies; but the one apart did not keep the sign:
    kept[2, 2] = False
    kept[3] = False  # none kept
    first, found = one_assembly(values, kept, angular, length)
    assert found.tolist() == [True, False, True, False]
    assert first[:3].tolist() == [0, 0, 0]
    kept[0, 0] = False  # the first kept start is the one taken
    assert one_assembly(values, kept, angular, length)[0][0] == 1


def test_starts_cover_a_turn_of_each_hinge_from_the_reference(tmp_path):
    path = tmp_path / "diamond.xml"
    path.write_text(diamond())
    mechanism = load(path)
    branches = [chain.branch for chain in mechanism.chains]
    assert eligible(mechanism, (0,), branches) and eligible(mechanism, (1,), branches)
    assert len(TURNS) ** 5 > MOST_STARTS and not eligible(mechanism, (0, 1), branches)  # both chains tied together
    for index, chain in enumerate(mechanism.chains):
        (values,) = starts(mechanism, (index,))
        assert values.shape == (len(TURNS) ** chain.n_joints, chain.n_joints)
        offsets = np.unique(np.round(values - chain.reference_values, 12), axis=0)
        assert len(offsets) == values.shape[0]  # every combination once
        assert set(np.round(offsets.ravel(), 12)) == set(np.round(TURNS, 12))
    assert not eligible(mechanism, (0,), [None, None])  # no sign: nothing tells its assemblies apart


def test_a_slide_counts_and_a_spatial_chain_is_left_to_the_continuation():
    """A planar R-P-R leg (a slide between its hinges) is searched, its slide at its reference value in every start;
    a six-joint arm has several assemblies with one sign: no start proves the one found is the working mode's."""
    rpr = load("planar_4rpr")
    signs = [chain.reference_sign for chain in rpr.chains]
    assert rpr.chains[0].prismatic == (False, True, False) and eligible(rpr, (0,), signs)
    (values,) = starts(rpr, (0,))
    assert values.shape == (16, 3) and np.all(values[:, 1] == rpr.chains[0].reference_values[1])
    arms = load("coop_arms")
    assert all(chain.branch is not None for chain in arms.chains)
    assert not eligible(arms, (0,), [chain.branch for chain in arms.chains])


@pytest.mark.parametrize("turn", [120.0, 150.0, 180.0])
def test_every_working_mode_asked_is_reached_beyond_the_hip_and_start_values_do_not_hide_it(tmp_path, turn):
    """``solve(branches=...)``: each of the four elbow combinations at knee points beyond the hip, where the
    continuation from the reference ends in the reference's signs, against the textbook's knees on the sides asked;
    and start values (``initial``) that end out of the working mode no longer refuse a pose the search reaches."""
    from test_point_leg_mode import _knees

    from screwkit.closure.chain_kinematics import chain_forward_kinematics
    from screwkit.closure.newton import working_sign
    from screwkit.closure.solve import solve

    path = tmp_path / "diamond.xml"
    path.write_text(diamond())
    mechanism = load(path)
    hip = mechanism.home_pose - np.array([0.0, CALF * np.sin(np.radians(60.0))])
    offset = 0.2 * np.array([np.sin(np.radians(turn)), -np.cos(np.radians(turn))])  # x forward, y up
    pose = hip + np.array([offset[0], -offset[1]])
    reference = [chain.branch for chain in mechanism.chains]
    for flips in ((1, 1), (-1, 1), (1, -1), (-1, -1)):
        asked = tuple(b * f for b, f in zip(reference, flips))
        solution = solve(mechanism, pose[None], branches=asked)
        assert bool(solution.reachable[0]), (turn, flips)
        for k, chain in enumerate(mechanism.chains):
            frames = chain_forward_kinematics(chain.geometry, np.asarray(solution.joint_values[k])[0])
            assert working_sign(mechanism, k, frames) == asked[k]
        first, second = _knees(offset)
        if flips[0] < 0:
            first = 2 * (first @ offset) / (offset @ offset) * offset - first  # mirrored across the hip-to-foot line
        if flips[1] < 0:
            second = 2 * (second @ offset) / (offset @ offset) * offset - second
        knees = [np.asarray(solution.joint_points[k])[0][1, :2] for k in range(2)]  # each knee in the base frame's
        assert np.linalg.norm(knees[0] - knees[1]) == pytest.approx(np.linalg.norm(first - second), abs=1e-9)  # plane
    home = solve(mechanism, mechanism.home_pose[None])
    alone = solve(mechanism, pose[None])
    started = solve(mechanism, pose[None], initial=home)
    assert bool(started.reachable[0]) and bool(alone.reachable[0])
    for with_start, without in zip(started.joint_values, alone.joint_values):
        assert np.asarray(with_start) == pytest.approx(np.asarray(without), abs=1e-9)


@pytest.mark.parametrize("distance", [0.05, 0.35])
def test_poses_out_of_the_legs_reach_are_still_refused(tmp_path, distance):
    """Inside the hole about the hip (nearer than the calf less the thigh) and beyond the stretched leg."""
    assert not CALF - THIGH < distance < CALF + THIGH
    path = tmp_path / "diamond.xml"
    path.write_text(diamond())
    mechanism = load(path)
    hip = mechanism.home_pose - np.array([0.0, CALF * np.sin(np.radians(60.0))])  # (the task y points down)
    pose = hip + distance * np.array([np.sin(1.0), np.cos(1.0)])
    with pytest.raises(ValueError, match="outside the workspace"):
        indices_at_pose(mechanism, pose)
    one_line_error(screwkit("analyze", path, "--pose", *(repr(float(v)) for v in pose)), "unreachable",
                   "outside the workspace")


def test_the_folded_leg_is_refused_saying_the_starts_found_no_assembly_with_its_sign(tmp_path):
    """At the fold (calf back along its thigh, the knee point the calf less the thigh from the hip) the two
    assemblies meet and the sign that names the working mode is zero: no start keeps it."""
    path = tmp_path / "diamond.xml"
    path.write_text(diamond())
    mechanism = load(path)
    hip = mechanism.home_pose - np.array([0.0, CALF * np.sin(np.radians(60.0))])
    pose = hip + (CALF - THIGH) * np.array([np.sin(1.0), np.cos(1.0)])
    with pytest.raises(ValueError, match="no one assembly with it was found from starts over a turn of each"):
        indices_at_pose(mechanism, pose)


HIP, LEG, SHIN, FOOT = 0.05, 0.15, 0.3, np.array([0.0, -0.35])
"""The spread five-bar: hips at x = -+HIP, thighs LEG, calves SHIN long, the foot drawn at FOOT below the hips (x, z
in the leg's plane)."""


def _cross(a, b) -> float:
    return float(a[0] * b[1] - a[1] * b[0])


def _drawn_knee(hip: np.ndarray, side: float) -> np.ndarray:
    """The knee of the thigh from ``hip`` to the calf ending at the foot, on the outer ``side`` (-1 left, +1 right)."""
    way = FOOT - hip
    distance = float(np.linalg.norm(way))
    along = (LEG ** 2 - SHIN ** 2 + distance ** 2) / (2 * distance)
    unit, across = way / distance, np.sqrt(LEG ** 2 - along ** 2)
    normal = np.array([-unit[1], unit[0]])
    return max((hip + along * unit + across * normal, hip + along * unit - across * normal), key=lambda k: side * k[0])


HIPS = (np.array([-HIP, 0.0]), np.array([HIP, 0.0]))
KNEES = (_drawn_knee(HIPS[0], -1.0), _drawn_knee(HIPS[1], 1.0))


def spread_five_bar(scale: float = 1.0, world=("0 0 0", "1 0 0 0"), names=("motor1", "motor2"),
                    reverse: bool = False) -> str:
    """The MJCF text (degrees, MuJoCo's default), every length times ``scale``, the base at ``world``; ``names``:
    the two motors' joints; ``reverse``: the legs, the connect's bodies and the motors listed the other way round."""
    def turn(way) -> float:  # about y, taking x to ``way`` (x, z)
        return float(np.degrees(np.arctan2(-way[1], way[0])))

    legs, motors = [], []
    for i, (hip, knee, name) in enumerate(zip(HIPS, KNEES, names), start=1):
        thigh = turn(knee - hip)
        legs.append(f'<body name="thigh{i}" pos="{float(hip[0]) * scale!r} 0 {float(hip[1]) * scale!r}" '
                    f'euler="0 {thigh!r} 0"><joint name="{name}" type="hinge" axis="0 1 0"/>'
                    f'<body name="calf{i}" pos="{LEG * scale!r} 0 0" euler="0 {turn(FOOT - knee) - thigh!r} 0">'
                    f'<joint name="knee{i}" type="hinge" axis="0 1 0"/></body></body>')
        motors.append(f'<motor name="m{i}" joint="{name}"/>')
    ends = ("calf1", "calf2") if reverse else ("calf2", "calf1")
    order = slice(None, None, -1 if reverse else 1)
    return ('<mujoco model="spread"><option><flag contact="disable"/></option><worldbody>'
            f'<body name="base" pos="{world[0]}" quat="{world[1]}">{"".join(legs[order])}</body></worldbody>'
            f'<equality><connect name="foot" body1="{ends[0]}" body2="{ends[1]}" anchor="{SHIN * scale!r} 0 0"/>'
            f'</equality><actuator>{"".join(motors[order])}</actuator></mujoco>')


def spread_textbook(first: float, second: float):
    """The foot (x, z), each thigh's ITI |sin(HK, KP)| and the LMTI |sin(K1P, K2P)| at motor angles (deg) in the
    drawing's working and assembly modes; None where those modes have no assembly."""
    knees = []
    for hip, knee, angle in zip(HIPS, KNEES, (first, second)):
        way = np.arctan2(-(knee - hip)[1], (knee - hip)[0]) + np.radians(angle)
        knees.append(hip + LEG * np.array([np.cos(way), -np.sin(way)]))
    between = knees[1] - knees[0]
    distance = float(np.linalg.norm(between))
    if not 0.0 < distance < 2 * SHIN:
        return None
    unit, height = between / distance, np.sqrt(SHIN ** 2 - (distance / 2) ** 2)
    middle, normal = knees[0] + distance / 2 * unit, np.array([-unit[1], unit[0]])
    drawn = np.sign(_cross(KNEES[1] - KNEES[0], FOOT - KNEES[0]))
    foot = next(p for p in (middle + height * normal, middle - height * normal)
                if np.sign(_cross(between, p - knees[0])) == drawn)
    if any(np.sign(_cross(k - h, foot - k)) != np.sign(_cross(k0 - h, FOOT - k0))
           for h, k0, k in zip(HIPS, KNEES, knees)):
        return None
    flat = [np.append(v, 0.0) for v in (knees[0] - HIPS[0], foot - knees[0], knees[1] - HIPS[1], foot - knees[1])]
    from helpers import sine

    return foot, (sine(flat[0], flat[1]), sine(flat[2], flat[3])), sine(flat[1], flat[3])


MOTORS = [(180, 180), (-165, 165), (-135, 135), (-90, 90), (165, 165), (-150, 150),  # the way from the start folds
          (-90, -90), (45, -45), (120, 120), (0, 0),  # the way from the start reaches them
          (120, -120), (-60, 60)]  # no assembly in the drawing's modes
"""Motor angles (deg): where the way from the drawing's pose passes the fold between the hips (refused before),
where it does not, and where the drawing's modes have no assembly."""


SPREAD_WRITINGS = {"x1e-3": (1e-3, {}), "x1e3": (1e3, {}),
                   "relabelled": (1.0, {"names": ("right_motor", "left_motor"), "reverse": True})}
"""The spread five-bar written beyond :data:`~helpers.MJCF_WORLDS`: every length times 1e-3 and 1e3 read in metres,
and its legs, connect and motors listed the other way round with the motors renamed."""


@pytest.mark.parametrize("variant", sorted(MJCF_WORLDS) + sorted(SPREAD_WRITINGS))
def test_actuator_values_past_the_fold_between_the_hips_read_the_drawings_modes(tmp_path, variant):
    names = ("motor1", "motor2")
    if variant in SPREAD_WRITINGS:
        scale, options = SPREAD_WRITINGS[variant]
        path, unit = tmp_path / f"spread_{variant}.xml", None
        path.write_text(spread_five_bar(scale, **options))
        names = options.get("names", names)
    else:
        path, unit = mjcf_variant(tmp_path, "spread", variant, spread_five_bar)
    mechanism = load(path, length_unit=unit)
    motors_named = [f"{name}:{name}" for name in names]
    order = [mechanism.actuator_names.index(name) for name in motors_named]
    folded = 0
    motors = MOTORS if variant == "m" else [MOTORS[i] for i in (0, 2, 6, 10)]  # (two past the fold, as written)
    for first, second in motors:
        values = np.radians(np.array([first, second], dtype=float))[order]
        solution, found = forward_from_starts(mechanism, values, mechanism.home_pose)
        expected = spread_textbook(first, second)
        if expected is None:
            assert not bool(solution.reachable) and found == "", (first, second)
            continue
        assert bool(solution.reachable), (first, second)
        folded += not bool(forward(mechanism, values, mechanism.home_pose).reachable)
        result = indices_at_pose(mechanism, np.asarray(solution.poses).reshape(-1))
        got = dict(zip(result.actuators, result.iti_actuators))
        assert (got[motors_named[0]], got[motors_named[1]], float(result.lmti)) == pytest.approx(
            (*expected[1], expected[2]), abs=1e-9), (first, second)
        if variant not in ("mm", "turned"):  # the task frame is the file's (x along x, y down), lengths as written
            factor = SPREAD_WRITINGS.get(variant, (1.0,))[0]
            assert np.asarray(solution.poses).reshape(-1) == pytest.approx(
                [factor * expected[0][0], -factor * expected[0][1]], abs=1e-9 * factor)
    assert folded == (6 if variant == "m" else 2)  # (the way from the start pose reaches none of the first six)


def test_the_command_reads_actuator_values_past_the_fold_and_refuses_those_no_assembly_reaches(tmp_path):
    path = tmp_path / "spread.xml"
    path.write_text(spread_five_bar())
    report = screwkit_json("analyze", path, "--actuators", "-135", "135")
    expected = spread_textbook(-135, 135)
    assert (report["iti_actuators"]["motor1:motor1"], report["iti_actuators"]["motor2:motor2"], report["lmti"]) == \
        pytest.approx((*expected[1], expected[2]), abs=1e-9)
    assert [report["pose"]["x"], report["pose"]["y"]] == pytest.approx([expected[0][0], -expected[0][1]], abs=1e-5)
    one_line_error(screwkit("analyze", path, "--actuators", "120", "-120"), "No closed pose of 'spread' has these "
                   "actuator values")


def test_no_singular_configuration_is_said_of_a_way_that_leaves_the_reach(tmp_path):
    """The knee point swept beside the hip (x = 0.12, y from 0.25 below the hip to 0.26 above): every straight way
    from the reference to these poses crosses the hole about the hip, where the legs cannot close, so the pose's
    assembly is the working-mode sign's, found from starts, and no configuration on the way tells anything of it
    (one way, grazing the hole, was said to pass a singular configuration, with advice to assemble "the other");
    a way that stays in reach still says it (the file's own square four-bar check is tests/test_singular_on_the_way)."""
    from screwkit.closure.on_the_way import singular_on_the_ways

    path = tmp_path / "diamond.xml"
    path.write_text(diamond())
    mechanism = load(path)
    hip = mechanism.home_pose - np.array([0.0, CALF * np.sin(np.radians(60.0))])
    poses = np.array([hip + np.array([0.12, -up]) for up in np.arange(-0.25, 0.26, 0.05)])  # (each way sampled)
    assert not any(passed.any() for _, passed, _ in singular_on_the_ways(mechanism, poses))
    assert not any(passed.any() for _, passed, _ in singular_on_the_ways(mechanism, poses[[5]]))  # (grazing)
    through = np.array([hip + np.array([0.0, -up]) for up in (0.12, 0.2, 0.27)])  # straight up through the hip
    assert not any(passed.any() for _, passed, _ in singular_on_the_ways(mechanism, through))  # (one line, once)


def test_poses_found_from_several_starts_are_told_apart_to_a_micro_length_scale():
    from screwkit.closure.around import SAME_ASSEMBLY
    from screwkit.closure.forward_kinematics import _distinct_poses

    five = load("planar_5rrr")  # (x, y in m, phi in rad)
    length = five.length_scale
    poses = np.array([[0.1, 0.2, np.pi - 1e-9], [0.1, 0.2, -np.pi + 1e-9],  # a turn apart: one pose
                      [0.1 + 0.5 * SAME_ASSEMBLY * length, 0.2, np.pi],  # within SAME_ASSEMBLY length scales: the same
                      [0.1 + 2.0 * SAME_ASSEMBLY * length, 0.2, np.pi]])  # beyond: another
    kept = _distinct_poses(five, poses)
    assert len(kept) == 2 and np.array_equal(kept[0], poses[0]) and np.array_equal(kept[1], poses[3])


def test_a_path_in_motor_values_that_starts_past_the_fold_reads_the_drawings_modes(tmp_path):
    """``trajectory --actuators``: a path whose first values the way from the reference pose does not reach (the
    foot above the hips) starts at the pose the starts find (it was refused at sample 0), and every sample reads the
    textbook's forward kinematics in the drawing's modes."""
    from screwkit.studies import indices_at_poses
    from screwkit.studies.actuator_paths import path_from_actuators

    path = tmp_path / "spread.xml"
    path.write_text(spread_five_bar())
    mechanism = load(path)
    order = [mechanism.actuator_names.index(name) for name in ("motor1:motor1", "motor2:motor2")]
    angles = np.linspace(135.0, 105.0, 11)
    motors = np.column_stack([-angles, angles])
    assert not bool(forward(mechanism, np.radians(motors[0])[order], mechanism.home_pose).reachable)
    driven = path_from_actuators(mechanism, np.radians(motors)[:, order])
    result = indices_at_poses(mechanism, driven.poses)
    for k, (first, second) in enumerate(motors):
        expected = spread_textbook(first, second)
        assert np.asarray(driven.poses)[k] == pytest.approx([expected[0][0], -expected[0][1]], abs=1e-9)
        assert float(np.asarray(result.lmti)[k]) == pytest.approx(expected[2], abs=1e-9)
    table = tmp_path / "motors.csv"
    np.savetxt(table, motors, delimiter=",", header="motor1:motor1,motor2:motor2", comments="")
    done = screwkit("trajectory", path, table, "--actuators", "--json")
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout)["reachable_samples"] == 11
