"""The bundled delta_4 (3 translational DOF, 4 legs) and schoenflies_5 (x, y, z, yaw; 5 legs) against
independent computations.

* ``delta_4``: every platform pose is closed here by the Delta's own inverse kinematics (a quadratic
  in tan(theta / 2), numpy); ITI, OTI of every 3-leg set, LMTI, F_O1 and F_IO1 are the research
  notes' pressure-angle closed forms (section 4): ITI_i = |det[a_i, r_i, u_i]|, OTI_i =
  |det[u_1, u_2, u_3]| / |u_j x u_k|. The legs are Tsai's R-U-U equivalent of the parallelogram
  forearm; their twists are compared with the parallelogram leg's {omega . (a x u) = 0}: the same
  translations, rotation about a and actuation force, a different constraint couple (and the
  parallelogram's couple would need a rank-4 serial leg).
* ``schoenflies_5``: the task coordinates inferred are x, y, z, yaw, each leg spans the Schoenflies
  motions, roll and pitch stay zero; the output twists of every 4-leg set against central finite
  differences of the closure (three actuators locked, the fourth moved by +-1e-6 with
  ``screwkit.closure.forward``); ITI and OTI from the leg-plane forces (numpy); OTI above 0.2 about
  home.
* ``prs_3_ups``: the general form of its parasitic motion (zero torsion, a closed-form shift).
* ``screwkit info``, ``analyze``, ``sweep`` and ``map`` as subprocesses on delta_4 and schoenflies_5.
"""

from __future__ import annotations

import json
import math
from itertools import combinations

import numpy as np
import pytest

from helpers import bundled, platform_twist, screwkit
from screwkit.closure import actuator_values, chain_screws, forward, solve
from screwkit.studies import indices_at_pose, indices_at_poses
from screwkit.studies.poses import analyze_solution

TOLERANCE = 1e-9
Z = np.array([0.0, 0.0, 1.0])


mechanism = bundled  # one load per test process


def unit(vector):
    vector = np.asarray(vector, dtype=float)
    return vector / np.linalg.norm(vector, axis=-1, keepdims=True)


def twist_rank(twists, tolerance=1e-10):
    singular = np.linalg.svd(np.asarray(twists), compute_uv=False)
    return int(np.sum(singular > tolerance * singular[0]))


def in_span(vectors, basis, tolerance=1e-9):
    """Whether every row of ``vectors`` lies in the row space of ``basis``."""
    q, _ = np.linalg.qr(np.asarray(basis).T)
    vectors = np.atleast_2d(vectors)
    return bool(np.all(np.linalg.norm(vectors - (vectors @ q) @ q.T, axis=-1) < tolerance))


# ---------------------------------------------------------------------------------------------
# delta_4: the Delta's inverse kinematics and the notes' closed forms
# ---------------------------------------------------------------------------------------------

BASE_RADIUS, PLATFORM_RADIUS, ARM, ROD = 0.2, 0.05, 0.35, 0.8  # the notes' illustrative Delta (m)
LEG_ANGLES = np.deg2rad([0.0, 90.0, 180.0, 270.0])


def delta_legs(position):
    """Per leg: actuated axis a, its point A, unit arm r, elbow B, rod end D, rod direction u.

    |D - A - ARM (cos t e - sin t z)| = ROD with t = 2 atan(s): a quadratic in s; the elbow-out root
    is the one with the elbow farther out (the larger cos t).
    """
    legs = []
    for angle in LEG_ANGLES:
        e = np.array([math.cos(angle), math.sin(angle), 0.0])
        a = np.array([-math.sin(angle), math.cos(angle), 0.0])
        point_a = BASE_RADIUS * e
        point_d = np.asarray(position, dtype=float) + PLATFORM_RADIUS * e
        delta = point_d - point_a
        # |delta|^2 + ARM^2 - ROD^2 - 2 ARM (delta.e cos t - delta_z sin t) = 0, cos t = (1 - s^2)/(1 + s^2),
        # sin t = 2 s / (1 + s^2)
        k = delta @ delta + ARM**2 - ROD**2
        p, q = 2 * ARM * (delta @ e), -2 * ARM * delta[2]
        roots = np.roots([k + p, -2 * q, k - p])  # (k + p) s^2 - 2 q s + (k - p) = 0
        roots = roots[np.abs(roots.imag) < 1e-12].real
        assert roots.size == 2, position
        theta = max(2 * np.arctan(roots), key=math.cos)
        r = math.cos(theta) * e - math.sin(theta) * Z
        point_b = point_a + ARM * r
        legs.append({"a": a, "A": point_a, "r": r, "B": point_b, "D": point_d, "u": (point_d - point_b) / ROD,
                     "theta": theta})
    return legs


def delta_expected(position):
    """ITI per leg, OTI per 3-leg set (combination order), LMTI, F_O1, F_IO1 (research notes, section 4)."""
    legs = delta_legs(position)
    iti = np.array([abs(np.linalg.det(np.array([leg["a"], leg["r"], leg["u"]]))) for leg in legs])
    u = np.array([leg["u"] for leg in legs])
    sets = list(combinations(range(4), 3))
    oti = []
    for members in sets:
        determinant = abs(np.linalg.det(u[list(members)]))
        oti.append(min(determinant / np.linalg.norm(np.cross(*u[[j for j in members if j != i]])) for i in members))
    oti = np.array(oti)
    # F_O1: the sets left after one fault are the 3-leg sets, each one submechanism.
    return {"iti_actuators": iti, "iti": iti.min(), "oti_submechanisms": oti, "lmti": oti.max(), "f_o1": oti.min(),
            "f_io1": min(oti.min(), iti.min())}


def delta_poses(count=120, seed=21):
    rng = np.random.default_rng(seed)
    random = np.column_stack([rng.uniform(-0.2, 0.2, (count, 2)), rng.uniform(-0.9, -0.6, count)])
    return np.concatenate([np.array(list(mechanism("delta_4").named_poses.values())), random])


def test_delta_4_is_a_translational_delta_with_four_legs():
    from screwkit.robots.generate import DELTA_4

    assert (DELTA_4["base_radius"], DELTA_4["platform_radius"], DELTA_4["arm"], DELTA_4["rod"]) == (
        BASE_RADIUS, PLATFORM_RADIUS, ARM, ROD)
    delta = mechanism("delta_4")
    assert delta.dof == delta.instantaneous_dof == 3 and not delta.is_planar
    assert delta.task_coordinates == ("x", "y", "z") and delta.task_source == "inferred"
    assert delta.actuator_names == tuple(f"leg_{i}:leg_{i}_joint_arm" for i in range(1, 5))
    assert all(chain.n_joints == 5 and chain.actuated == (0,) and chain.loop_type == "universal"
               for chain in delta.chains)
    np.testing.assert_allclose(delta.home_pose, [0.0, 0.0, -0.75], atol=1e-15)
    assert set(delta.named_poses) == {"home", "raised", "lowered", "off_centre"}


def test_delta_4_closes_as_the_delta_and_only_translates():
    """At random task poses the solved platform keeps its orientation (roll, pitch, yaw zero) and every
    leg's joints sit where the Delta's inverse kinematics puts them: A, the elbow B (arm angle), D."""
    delta = mechanism("delta_4")
    poses = delta_poses()
    solution = solve(delta, poses)
    assert solution.reachable.all()
    np.testing.assert_allclose(solution.full_poses[:, 3:], 0.0, atol=1e-10)
    np.testing.assert_allclose(solution.full_poses[:, :3], poses, atol=0)
    for index in range(0, len(poses), 7):
        for leg, points in zip(delta_legs(poses[index]), solution.joint_points):
            np.testing.assert_allclose(points[index, 0], leg["A"], atol=1e-12)
            np.testing.assert_allclose(points[index, 1], leg["B"], atol=1e-9)
            np.testing.assert_allclose(points[index, -1], leg["D"], atol=1e-9)


def test_delta_4_indices_are_the_pressure_angle_closed_forms():
    delta = mechanism("delta_4")
    poses = delta_poses()
    result = indices_at_poses(delta, poses, detail=True)
    assert result.reachable.all() and result.dof == 3 and result.submechanisms == tuple(combinations(range(4), 3))
    for index, pose in enumerate(poses):
        expected = delta_expected(pose)
        np.testing.assert_allclose(result.iti_actuators[index], expected["iti_actuators"], rtol=0, atol=TOLERANCE)
        np.testing.assert_allclose(result.oti_submechanisms[index], expected["oti_submechanisms"], rtol=0,
                                   atol=TOLERANCE)
        for key, value in (("iti", result.iti), ("lmti", result.lmti), ("f_o1", result.f_o[1]),
                           ("f_io1", result.f_io[1])):
            assert value[index] == pytest.approx(expected[key], abs=TOLERANCE), (key, pose)


NOTES_DELTA_CENTRE = {-0.55: (-13.6, 0.624), -0.75: (18.6, 0.948), -0.95: (46.2, 0.957)}
"""The research notes' Delta table at x = y = 0: z (m) -> arm angle below the horizontal (deg), ITI."""


def test_delta_4_reproduces_the_notes_table_at_the_centre():
    """At x = y = 0 each leg's ITI is |cos(theta - gamma)| (theta the arm angle below the horizontal,
    gamma the rod angle from the vertical) and matches the notes' table; the 3-leg sets all have one OTI."""
    delta = mechanism("delta_4")
    heights = list(NOTES_DELTA_CENTRE)
    result = indices_at_poses(delta, [[0.0, 0.0, z] for z in heights], detail=True)
    for index, z in enumerate(heights):
        angle_deg, iti = NOTES_DELTA_CENTRE[z]
        leg = delta_legs([0.0, 0.0, z])[0]
        gamma = math.acos(-leg["u"][2])
        assert round(math.degrees(leg["theta"]), 1) == angle_deg
        np.testing.assert_allclose(result.iti_actuators[index], abs(math.cos(leg["theta"] - gamma)), rtol=0,
                                   atol=TOLERANCE)
        assert round(float(result.iti[index]), 3) == iti
        np.testing.assert_allclose(result.oti_submechanisms[index], result.oti_submechanisms[index, 0], atol=1e-12)


def test_delta_leg_twists_against_the_parallelogram_leg():
    """Each R-U-U leg's twists span 5 dimensions, reciprocal to one couple along a x w (w = a x u / |a x u|),
    i.e. along the component of u normal to a. The parallelogram leg's twists are {omega . (a x u) = 0}:
    the two share all translations and the rotation about a (a 4-system), and their constraint couples are
    orthogonal. Both transmit the force along the rod through D, which is the actuation wrench found.
    The R-U-U with w in the plane of a and u (the parallelogram's couple) would be singular: rank 4."""
    delta = mechanism("delta_4")
    poses = delta_poses(count=6, seed=22)
    solution = solve(delta, poses)
    result = analyze_solution(delta, solution, detail=True)
    for k, chain in enumerate(chain_screws(delta, solution)):
        for index in range(len(poses)):
            twists, points = chain.twists[index], chain.points[index]
            a, u = twists[0, :3], unit(points[-1] - points[1])
            point_a, point_b, point_d = points[0], points[1], points[-1]
            assert twist_rank(twists) == 5
            # the reciprocal wrench (f, m): f.v + m.omega = 0 for every twist
            wrench = np.linalg.svd(np.concatenate([twists[:, 3:], twists[:, :3]], axis=1))[2][-1]
            assert np.linalg.norm(wrench[:3]) < 1e-10
            normal_component = unit(u - (u @ a) * a)
            assert abs(abs(unit(wrench[3:]) @ normal_component) - 1) < 1e-10  # the couple along a x w
            parallelogram_couple = unit(np.cross(a, u))
            assert abs(wrench[3:] @ parallelogram_couple) < 1e-10
            # the parallelogram leg: {(omega, v): omega . (a x u) = 0}
            parallelogram = np.array([[*a, 0, 0, 0], [*u, 0, 0, 0], [0, 0, 0, 1, 0, 0], [0, 0, 0, 0, 1, 0],
                                      [0, 0, 0, 0, 0, 1]], dtype=float)
            shared = np.array([[0, 0, 0, 1, 0, 0], [0, 0, 0, 0, 1, 0], [0, 0, 0, 0, 0, 1],
                               [*a, *np.cross(point_a, a)]], dtype=float)
            assert in_span(shared, twists) and in_span(shared, parallelogram)
            assert twist_rank(np.concatenate([twists, parallelogram])) == 6
            # the actuation wrench: the unit force along the rod through D (moment about D zero)
            found = result.actuation_wrenches[index, k]
            np.testing.assert_allclose(abs(unit(found[:3]) @ u), 1.0, atol=1e-10)
            np.testing.assert_allclose(found[3:] - np.cross(point_d, found[:3]), 0.0, atol=1e-10)
            # w in the plane of a and u: no translation along a, rank 4
            w = normal_component
            in_plane = [[*axis, *np.cross(point, axis)] for axis, point in
                        ((a, point_a), (a, point_b), (w, point_b), (w, point_d), (a, point_d))]
            singular = np.linalg.svd(np.array(in_plane), compute_uv=False)
            assert singular[-1] < 1e-12 * singular[0] and singular[-2] > 1e-3 * singular[0]


# ---------------------------------------------------------------------------------------------
# schoenflies_5
# ---------------------------------------------------------------------------------------------

SCHOENFLIES = np.array([[0, 0, 0, 1, 0, 0], [0, 0, 0, 0, 1, 0], [0, 0, 0, 0, 0, 1], [0, 0, 1, 0, 0, 0]], dtype=float)
"""The Schoenflies motions: translations and the rotation about z (through the origin)."""


SCHOENFLIES_SPAN = np.array([0.04, 0.04, 0.03, math.radians(15.0)])
"""Random poses about home: +-4 cm in x and y, +-3 cm in z, +-15 deg in yaw."""


def schoenflies_poses(count, seed):
    rng = np.random.default_rng(seed)
    return mechanism("schoenflies_5").home_pose + rng.uniform(-1.0, 1.0, (count, 4)) * SCHOENFLIES_SPAN


def test_schoenflies_5_infers_x_y_z_yaw_and_only_makes_schoenflies_motions():
    sch = mechanism("schoenflies_5")
    assert sch.task_coordinates == ("x", "y", "z", "yaw") and sch.task_source == "inferred"
    assert sch.dof == sch.instantaneous_dof == 4 and len(sch.actuators) == 5
    assert all(chain.n_joints == 4 and chain.actuated == (0,) for chain in sch.chains)
    poses = schoenflies_poses(30, seed=31)
    solution = solve(sch, poses)
    assert solution.reachable.all()
    np.testing.assert_allclose(solution.full_poses[:, 3:5], 0.0, atol=1e-10)  # no roll, no pitch
    np.testing.assert_allclose(solution.full_poses[:, [0, 1, 2, 5]], poses, atol=0)
    for chain in chain_screws(sch, solution):
        for twists in chain.twists[::5]:
            assert twist_rank(twists) == 4 and in_span(twists, SCHOENFLIES) and in_span(SCHOENFLIES, twists)


def schoenflies_expected(solution, index):
    """ITI per leg and OTI per 4-leg set from the leg geometry (numpy): the actuation force of leg i lies in
    the vertical plane through C and D (it meets both vertical axes), normal to q, through D (any height: it is
    defined modulo the leg's constraint couples); the ITI is its pressure cosine on the rotation about z at A at the
    point where it crosses C's axis (the slider's carriage turns on C: a slide has no point), the OTI its pressure
    cosine at D on the Schoenflies twist left when the other three legs of the set are locked."""
    forces, platform, iti = [], [], []
    for points, axes in zip(solution.joint_points, solution.joint_axes):
        point_a, _, point_c, point_d = points[index]
        q = unit(axes[index, 1])
        f = unit(np.cross(np.cross(point_d - point_c, Z), q))  # in the vertical plane through C and D, normal to q
        across = f - (f @ Z) * Z  # the force line's horizontal run: it reaches C's vertical axis at
        on_line = point_d + (((point_c - point_d) @ across) / (across @ across)) * f
        velocity = np.cross(Z, on_line - point_a)
        iti.append(abs(f @ velocity) / np.linalg.norm(velocity))
        forces.append(f)
        platform.append(point_d)
    forces, platform = np.array(forces), np.array(platform)
    rows = np.concatenate([forces, np.cross(platform, forces)[:, 2:]], axis=1)  # on (v at the origin, omega_z)
    oti = []
    for members in combinations(range(5), 4):
        values = []
        for k in members:
            free = np.linalg.svd(rows[[j for j in members if j != k]])[2][-1]
            velocity = free[:3] + free[3] * np.cross(Z, platform[k])
            values.append(abs(forces[k] @ velocity) / np.linalg.norm(velocity))
        oti.append(min(values))
    return np.array(iti), np.array(oti)


def test_schoenflies_5_indices_from_the_leg_plane_forces():
    sch = mechanism("schoenflies_5")
    poses = np.concatenate([np.array(list(sch.named_poses.values())), schoenflies_poses(60, seed=32)])
    solution = solve(sch, poses)
    result = indices_at_poses(sch, poses, detail=True)
    assert result.reachable.all() and result.submechanisms == tuple(combinations(range(5), 4))
    for index in range(len(poses)):
        iti, oti = schoenflies_expected(solution, index)
        np.testing.assert_allclose(result.iti_actuators[index], iti, rtol=0, atol=TOLERANCE)
        np.testing.assert_allclose(result.oti_submechanisms[index], oti, rtol=0, atol=TOLERANCE)
        assert result.f_o[1][index] == pytest.approx(oti.min(), abs=TOLERANCE)  # one 4-leg set per fault
        assert result.lmti[index] == pytest.approx(oti.max(), abs=TOLERANCE)
    # well conditioned: at home the five legs' ITIs are equal (the robot's symmetry) and high, and every 4-leg set
    # has OTI > 0.2 about home. (sin 55 deg = 0.819 at the slider's drawn point; 0.742 where the force crosses C.)
    np.testing.assert_allclose(result.iti_actuators[0], result.iti_actuators[0, 0], atol=1e-12)
    assert result.iti_actuators[0, 0] > 0.7
    assert result.f_o[1][0] > 0.69 and np.min(result.f_o[1]) > 0.2


@pytest.mark.parametrize("pose_name", ["home", "shifted_turned"])
def test_schoenflies_5_output_twists_match_finite_differences_of_the_closure(pose_name):
    """Lock three actuators of a 4-leg set, move the fourth by +-1e-6 rad with the forward kinematics of the
    closure: the platform's twist is the output twist of that actuator in that set (its direction)."""
    sch = mechanism("schoenflies_5")
    assert sch.base_is_world  # base frame = world frame: the output twists compare directly
    pose = sch.named_pose(pose_name)
    result = indices_at_pose(sch, pose)
    at_pose = actuator_values(sch, solve(sch, pose).joint_values)
    step = 1e-6
    for s, members in enumerate(result.submechanisms):
        sub = list(members)
        values = np.repeat(at_pose[sub][None], 2 * len(sub), axis=0)
        for position in range(len(sub)):
            values[2 * position, position] -= step
            values[2 * position + 1, position] += step
        moved = forward(sch, values, pose, actuators=sub)
        assert np.all(moved.reachable)
        np.testing.assert_allclose(moved.full_poses[:, 3:5], 0.0, atol=1e-12)
        for position in range(len(sub)):
            twist = platform_twist(sch, moved.full_poses[2 * position], moved.full_poses[2 * position + 1], step)
            expected = result.output_twists[s, position]  # signed: the motion with its actuator moving forward
            cosine = (twist @ expected) / np.linalg.norm(twist) / np.linalg.norm(expected)
            assert cosine > 1 - 1e-6, (s, position, cosine)


# ---------------------------------------------------------------------------------------------
# prs_3_ups: the parasitic motion in general (tests/test_lower_mobility.py has the rest)
# ---------------------------------------------------------------------------------------------


def test_prs_3_ups_parasitic_motion_is_torsion_free_with_the_tilt_and_torsion_closed_form():
    """Legs at 90, 210, 330 deg: every solved orientation is a pure tilt, R = Rz(phi) Ry(theta) Rz(-phi)
    (Tilt-and-Torsion angles with zero torsion; theta the tilt, phi the azimuth of the platform normal),
    and the platform centre shifts by R2 (1 - cos theta) / 2 along (sin 2 phi, cos 2 phi).
    Derivation: the S centre of leg i stays in the vertical plane of its rail and R axis normal,
    (p + R2 R s_i) . t_i = 0, and t_i . R s_i = (1 - cos theta) sin(2 alpha_i - 2 phi) / 2, so
    p . t_i = -R2 (1 - cos theta) sin(2 alpha_i - 2 phi) / 2, solved for every leg by the shift above
    because 3 alpha_i = 270 deg (mod 360) for the three legs. A pure pitch theta (phi = 0) gives
    y = R2 (1 - cos theta) / 2, a pure roll (phi = -90 deg) y = -R2 (1 - cos theta) / 2."""
    from screwkit.common.rotations import rotation_from_rpy

    prs = mechanism("prs_3_ups")
    assert prs.dof == 3 and prs.task_coordinates == ("z", "roll", "pitch")
    rng = np.random.default_rng(41)
    poses = np.column_stack([prs.home_pose[0] + rng.uniform(-0.03, 0.03, 40), rng.uniform(-0.4, 0.4, (40, 2))])
    solution = solve(prs, poses)
    assert solution.reachable.all()
    full = solution.full_poses
    for pose, rotation in zip(full, rotation_from_rpy(full[:, 3:])):
        normal = rotation[:, 2]
        theta, phi = math.acos(normal[2]), math.atan2(normal[1], normal[0])
        turn, tilt = rotation_from_rpy(np.array([0.0, 0.0, phi])), rotation_from_rpy(np.array([0.0, theta, 0.0]))
        np.testing.assert_allclose(rotation, turn @ tilt @ turn.T, atol=1e-12)
        shift = 0.13 * (1 - math.cos(theta)) / 2
        np.testing.assert_allclose(pose[:2], shift * np.array([math.sin(2 * phi), math.cos(2 * phi)]), atol=1e-12)


# ---------------------------------------------------------------------------------------------
# The command line, as users run it
# ---------------------------------------------------------------------------------------------

CLI_CASES = {
    "delta_4": {"coordinates": ["x", "y", "z"], "pose": ["0.1", "-0.05", "-0.8"], "sweep": "z:-0.9:-0.6:0.1",
                "map": ["--grid", "x:-0.1:0.1:0.1", "--grid", "y:-0.1:0.1:0.1", "--over", "z:-0.8:-0.7:0.05"]},
    "schoenflies_5": {"coordinates": ["x", "y", "z", "yaw"], "pose": ["0.02", "0.01", "0.21", "10"],
                      "sweep": "yaw:-20:20:10",
                      "map": ["--grid", "x:-0.04:0.04:0.04", "--grid", "y:-0.04:0.04:0.04", "--over", "yaw:-15:15:15",
                              "--at", "home"]},
}


@pytest.mark.parametrize("name", CLI_CASES)
def test_the_command_line_runs_on_the_mechanism(name, tmp_path):
    case = CLI_CASES[name]
    info = screwkit("info", name, "--json")
    assert info.returncode == 0, info.stderr
    assert [c["name"] for c in json.loads(info.stdout)["task_coordinates"]] == case["coordinates"]
    analysed = screwkit("analyze", name, "--pose", *case["pose"], "--json")
    assert analysed.returncode == 0, analysed.stderr
    report = json.loads(analysed.stdout)
    assert list(report["pose"]) == case["coordinates"] and report["dof"] == len(case["coordinates"])
    angular = np.array([c == "yaw" for c in case["coordinates"]])
    pose = np.where(angular, np.deg2rad(np.array(case["pose"], dtype=float)), np.array(case["pose"], dtype=float))
    expected = indices_at_pose(mechanism(name), pose)
    assert report["f_o"]["1"] == pytest.approx(float(expected.f_o[1]), abs=1e-12)
    assert report["iti"] == pytest.approx(float(expected.iti), abs=1e-12)
    swept = screwkit("sweep", name, "--sweep", case["sweep"], "--out", tmp_path / "sweep.csv")
    assert swept.returncode == 0, swept.stderr
    header, *rows = (tmp_path / "sweep.csv").read_text().strip().splitlines()
    assert header.startswith(case["sweep"].split(":")[0] + ",") and len(rows) == 3 + (name == "schoenflies_5")
    mapped = screwkit("map", name, *case["map"], "--out", tmp_path / "map.csv")
    assert mapped.returncode == 0, mapped.stderr
    header, *rows = (tmp_path / "map.csv").read_text().strip().splitlines()
    assert header.startswith("y,x,") and len(rows) == 9
    assert all(float(row.split(",")[header.split(",").index("f_o1")]) > 0.2 for row in rows)
