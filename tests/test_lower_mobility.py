"""The bundled mechanisms of lower mobility or with a point output, against independent computations.

* ``prs_3_ups``: a 3-PRS (3 DOF: z, roll, pitch) made redundant by an actuated UPS leg. The
  closure (parasitic x, y, yaw and the slider positions) is solved here by Newton on the PRS leg
  equations, the screws are written from the explicit geometry, and ITI, OTI, LMTI, F_O1, F_IO1,
  CTI and F_C1 are the pressure-angle cosines of the research notes (sections 0 and 1), computed
  with numpy. The parasitic motion has a closed form for a pure roll or pitch, and the 3-PRS
  submechanism reproduces the notes' table.
* ``five_bar_3``: a planar five-bar with a third actuated leg on its output point (2 DOF, point
  output). The textbook pressure angles: ITI_i = |sin| of the angle between the proximal and
  distal links, OTI of a pair = |sin| of the angle between their distal links; its legs 1 and 2
  (and the standard two-leg five-bar made from them) reproduce the notes' five-bar table.

Every expected value is computed in this file from the geometry; screwkit's numbers are never
compared with numbers it printed once. The command line (analyze, sweep, map, info) runs as a
subprocess. All four new bundled mechanisms (also ``delta_4`` and ``schoenflies_5``, whose
independent checks are in ``tests/test_delta_schoenflies.py``) report their task coordinates in
``screwkit info --json`` and give the same indices from a file in millimetres and with the whole
mechanism moved in the world.
"""

from __future__ import annotations

import json
import math
import re
from itertools import combinations

import numpy as np
import pytest

from helpers import (
    assert_indices_close,
    bundled,
    in_millimetres,
    moved,
    moved_in_the_world,
    random_rotation,
    screwkit,
)
from screwkit.closure import solve_one
from screwkit.io.loader import bundled_path, load, load_text
from screwkit.studies.poses import indices_at_poses

TOLERANCE = 1e-9
Z = np.array([0.0, 0.0, 1.0])


mechanism = bundled  # one load per test process


# ---------------------------------------------------------------------------------------------
# Screw algebra (numpy, independent of screwkit): twists (omega, v), wrenches (f, m), v and m
# about the world origin; the reciprocal product f.v + m.omega.
# ---------------------------------------------------------------------------------------------


def unit(vector):
    vector = np.asarray(vector, dtype=float)
    return vector / np.linalg.norm(vector, axis=-1, keepdims=True)


def force(direction, point):
    """The unit force along ``direction`` through ``point``: (f, point x f)."""
    f = unit(direction)
    return np.concatenate([f, np.cross(point, f)])


def couple(direction):
    return np.concatenate([np.zeros(3), unit(direction)])


def free_twist(wrenches):
    """The one twist reciprocal to five independent wrenches (the null space of the reciprocal product)."""
    rows = np.array([np.concatenate([w[3:], w[:3]]) for w in wrenches])  # (m, f) . (omega, v)
    _, singular, right = np.linalg.svd(rows)
    assert singular[-1] > 1e-6 * singular[0]  # a regular configuration: exactly one free twist
    return right[-1]


def pressure_cosine(wrench, twist, point):
    """Power coefficient with the local maximum at ``point`` (research notes section 0): for a force,
    |f.v_P| / (|f| |v_P|) with v_P the velocity of the point of application; for a couple |m.omega| / (|m| |omega|)."""
    f, m = wrench[:3], wrench[3:]
    omega, v = twist[:3], twist[3:]
    if np.linalg.norm(f) > 1e-12:
        velocity = v + np.cross(omega, point)
        return abs(f @ velocity) / (np.linalg.norm(f) * np.linalg.norm(velocity))
    return abs(m @ omega) / (np.linalg.norm(m) * np.linalg.norm(omega))


def rpy_matrix(roll, pitch, yaw):
    """R = Rz(yaw) Ry(pitch) Rx(roll)."""
    cr, sr, cp, sp = math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    return np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                     [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                     [-sp, cp * sr, cp * cr]])


def redundant_indices(actuation, constraints, actuation_points, constraint_points, dof):
    """OTI and CTI of every non-redundant actuator set (combination order), LMTI, F_O1, CTI, F_C1.

    OTI of a set N: for each k in N, lock the other actuators of N, keep every constraint wrench:
    the free twist is reciprocal to them; the pressure cosine of A_k on it at its point; the minimum
    over k. CTI of N: lock the actuators of N, release one constraint wrench C_j: the free twist is
    reciprocal to A_N and the other constraints; the pressure cosine of C_j; the minimum over j.
    The mechanism's LMTI and CTI are the maxima over the sets, F_O1 and F_C1 the minima over the
    sets left after one fault of their maxima (a - 1 = n actuators left: one set each).
    """
    count = len(actuation)
    sets = list(combinations(range(count), dof))
    oti, cti = [], []
    for members in sets:
        values = []
        for k in members:
            locked = [actuation[j] for j in members if j != k] + list(constraints)
            values.append(pressure_cosine(actuation[k], free_twist(locked), actuation_points[k]))
        oti.append(min(values))
        values = []
        for j in range(len(constraints)):
            locked = [actuation[k] for k in members] + [c for i, c in enumerate(constraints) if i != j]
            values.append(pressure_cosine(constraints[j], free_twist(locked), constraint_points[j]))
        cti.append(min(values) if values else math.nan)
    oti, cti = np.array(oti), np.array(cti)
    left = [[s for s, members in enumerate(sets) if set(members) <= set(kept)]
            for kept in combinations(range(count), count - 1)]
    return {"oti_submechanisms": oti, "lmti": oti.max(), "f_o1": min(oti[m].max() for m in left),
            "cti_submechanisms": cti, "cti": cti.max(), "f_c1": min(cti[m].max() for m in left)}


# ---------------------------------------------------------------------------------------------
# prs_3_ups: explicit geometry, closure and indices
# ---------------------------------------------------------------------------------------------

R1, R2, LINK = 0.2, 0.13, 0.22  # base radius of the rails, platform radius of the S centres, link length (m)
PRS_ANGLES = np.deg2rad([90.0, 210.0, 330.0])
UPS_ANGLE, UPS_BASE = math.radians(270.0), 0.26
HEIGHT = math.sqrt(LINK**2 - (R1 - R2) ** 2)  # platform height of the reference assembly


def radial(angle):
    return np.array([math.cos(angle), math.sin(angle), 0.0])


def tangent(angle):
    return np.array([-math.sin(angle), math.cos(angle), 0.0])


def prs_residual(unknowns, z, roll, pitch):
    """PRS leg equations for (x, y, yaw, s_1, s_2, s_3): each S centre in the plane of its rail and R axis
    normal, at the link length from the carriage b_i + s_i z."""
    x, y, yaw = unknowns[:3]
    rotation, centre = rpy_matrix(roll, pitch, yaw), np.array([x, y, z])
    residual = []
    for i, angle in enumerate(PRS_ANGLES):
        point = centre + rotation @ (R2 * radial(angle))
        carriage = R1 * radial(angle) + unknowns[3 + i] * Z
        residual += [point @ tangent(angle), (point - carriage) @ (point - carriage) - LINK**2]
    return np.array(residual)


def prs_closure(z, roll, pitch):
    """Newton (central-difference Jacobian) with continuation from the reference assembly (all zero)."""
    unknowns = np.zeros(6)
    for fraction in np.linspace(0.0, 1.0, 6)[1:]:
        target = (HEIGHT + fraction * (z - HEIGHT), fraction * roll, fraction * pitch)
        for _ in range(30):
            value = prs_residual(unknowns, *target)
            if np.max(np.abs(value)) < 1e-15:
                break
            jacobian = np.empty((6, 6))
            for k in range(6):
                step = np.zeros(6)
                step[k] = 1e-7
                forward, backward = prs_residual(unknowns + step, *target), prs_residual(unknowns - step, *target)
                jacobian[:, k] = (forward - backward) / 2e-7
            unknowns = unknowns - np.linalg.solve(jacobian, value)
    assert np.max(np.abs(prs_residual(unknowns, z, roll, pitch))) < 1e-14
    return unknowns


def prs_ups_expected(pose):
    """Every index of prs_3_ups at a task pose (z, roll, pitch), and the parasitic (x, y, yaw)."""
    z, roll, pitch = pose
    unknowns = prs_closure(z, roll, pitch)
    x, y, yaw = unknowns[:3]
    rotation, centre = rpy_matrix(roll, pitch, yaw), np.array([x, y, z])
    actuation, constraints, points, iti = [], [], [], []
    for i, angle in enumerate(PRS_ANGLES):
        point = centre + rotation @ (R2 * radial(angle))  # the S centre
        carriage = R1 * radial(angle) + unknowns[3 + i] * Z  # on the R axis
        link = unit(point - carriage)
        actuation.append(force(link, point))  # actuation wrench: along the link through the S centre
        constraints.append(force(tangent(angle), point))  # constraint: through the S centre along the R axis
        points.append(point)
        iti.append(abs(link @ Z))  # input twist: the slider's translation along z
    ups_point = centre + rotation @ (R2 * radial(UPS_ANGLE))
    actuation.append(force(ups_point - UPS_BASE * radial(UPS_ANGLE), ups_point))  # along the UPS leg
    points.append(ups_point)
    iti.append(1.0)  # the slider moves along its own force
    result = redundant_indices(actuation, constraints, points, points[:3], 3)
    result.update(iti_actuators=np.array(iti), iti=min(iti), parasitic=np.array([x, y, yaw]))
    result["f_io1"] = min(result["f_o1"], result["iti"])
    return result


def tilt_torsion(tilt, azimuth):
    """roll, pitch (and yaw) of the Tilt-and-Torsion orientation Rz(azimuth) Ry(tilt) Rz(-azimuth) (zero torsion)."""
    c, s = math.cos(azimuth), math.sin(azimuth)
    spin = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    rotation = spin @ rpy_matrix(0.0, tilt, 0.0) @ spin.T
    return (math.atan2(rotation[2, 1], rotation[2, 2]), -math.asin(rotation[2, 0]),
            math.atan2(rotation[1, 0], rotation[0, 0]))


def prs_poses():
    """The named poses and random tilted, raised and lowered poses (z, roll, pitch)."""
    rng = np.random.default_rng(11)
    random = np.column_stack([HEIGHT + rng.uniform(-0.03, 0.03, 8), rng.uniform(-0.35, 0.35, (8, 2))])
    named = np.array(list(mechanism("prs_3_ups").named_poses.values()))
    return np.concatenate([named, random])


def test_prs_3_ups_geometry_and_task_coordinates():
    from screwkit.robots.generate import PRS_UPS

    assert (PRS_UPS["base_radius"], PRS_UPS["platform_radius"], PRS_UPS["link"]) == (R1, R2, LINK)
    prs = mechanism("prs_3_ups")
    assert prs.dof == 3 and prs.task_coordinates == ("z", "roll", "pitch") and prs.task_source == "declared"
    assert prs.actuator_names == ("prs_1:prs_1_joint_p", "prs_2:prs_2_joint_p", "prs_3:prs_3_joint_p",
                                  "ups:ups_joint_slider")
    np.testing.assert_allclose(prs.home_pose, [HEIGHT, 0.0, 0.0], atol=1e-15)
    solution = solve_one(prs, prs.named_pose("pitch_30"))
    unknowns = prs_closure(*prs.named_pose("pitch_30"))
    for i, points in enumerate(solution.joint_points[:3]):  # carriage (P and R at one point), S centre
        np.testing.assert_allclose(points[0], R1 * radial(PRS_ANGLES[i]) + unknowns[3 + i] * Z, atol=1e-10)
        np.testing.assert_allclose(np.linalg.norm(points[-1] - points[1]), LINK, atol=1e-10)


def test_prs_3_ups_indices_equal_the_independent_pressure_angles():
    prs = mechanism("prs_3_ups")
    poses = prs_poses()
    result = indices_at_poses(prs, poses, detail=True)
    assert result.reachable.all() and result.submechanisms == tuple(combinations(range(4), 3))
    assert result.constraint_count == 3 and not result.constraint_singular.any()
    np.testing.assert_array_equal(result.instantaneous_dof, 3)
    for index, pose in enumerate(poses):
        expected = prs_ups_expected(pose)
        np.testing.assert_allclose(result.full_poses[index, [0, 1, 5]], expected["parasitic"], rtol=0, atol=1e-10)
        np.testing.assert_allclose(result.iti_actuators[index], expected["iti_actuators"], rtol=0, atol=TOLERANCE)
        np.testing.assert_allclose(result.oti_submechanisms[index], expected["oti_submechanisms"], rtol=0,
                                   atol=TOLERANCE)
        np.testing.assert_allclose(result.cti_submechanisms[index], expected["cti_submechanisms"], rtol=0,
                                   atol=TOLERANCE)
        for key, value in (("iti", result.iti), ("lmti", result.lmti), ("f_o1", result.f_o[1]),
                           ("f_io1", result.f_io[1]), ("cti", result.cti), ("f_c1", result.f_c[1])):
            assert value[index] == pytest.approx(expected[key], abs=TOLERANCE), (key, pose)


@pytest.mark.parametrize("angle_deg", [10.0, 20.0, 30.0])
def test_prs_parasitic_motion_has_the_closed_form(angle_deg):
    """A pure pitch theta moves the platform by y = R2 (1 - cos theta) / 2, a pure roll by -R2 (1 - cos theta) / 2;
    x and yaw stay zero (legs at 90, 210, 330 deg)."""
    theta = math.radians(angle_deg)
    shift = R2 * (1 - math.cos(theta)) / 2
    prs = mechanism("prs_3_ups")
    result = indices_at_poses(prs, [[HEIGHT, 0.0, theta], [HEIGHT, theta, 0.0], [HEIGHT - 0.02, 0.0, -theta]])
    expected = np.array([[0.0, shift, 0.0], [0.0, -shift, 0.0], [0.0, shift, 0.0]])
    np.testing.assert_allclose(result.full_poses[:, [0, 1, 5]], expected, rtol=0, atol=1e-10)
    for pose, parasitic in zip(result.poses, expected):
        np.testing.assert_allclose(prs_closure(*pose)[:3], parasitic, rtol=0, atol=1e-14)


# The research notes' table (3-PRS, R1 = 200 mm, R2 = 130 mm, L = 220 mm): tilt, azimuth (deg) ->
# ITI, OTI, CTI, parasitic x, y (mm). The 3-PRS is the submechanism of the three sliders.
NOTES_TABLE = [
    ((0.0, 0.0), (0.9480, 0.9480, 1.0000, 0.0, 0.0)),
    ((10.0, 0.0), (0.9450, 0.8846, 0.9998, 0.0, 0.987)),
    ((20.0, 0.0), (0.9353, 0.7860, 0.9989, 0.0, 3.92)),
    ((30.0, 0.0), (0.9177, 0.6482, 0.9964, 0.0, 8.71)),
    ((30.0, 30.0), (0.8995, 0.8196, 0.9999, 7.54, 4.35)),
]


def test_prs_3_ups_reproduces_the_notes_table():
    prs = mechanism("prs_3_ups")
    poses = []
    for (tilt, azimuth), _ in NOTES_TABLE:
        roll, pitch, _ = tilt_torsion(math.radians(tilt), math.radians(azimuth))
        poses.append([HEIGHT, roll, pitch])
    result = indices_at_poses(prs, poses, detail=True)
    for index, ((tilt, azimuth), (iti, oti, cti, x_mm, y_mm)) in enumerate(NOTES_TABLE):
        expected = prs_ups_expected(poses[index])
        for value in (result.iti[index], expected["iti"]):
            assert round(float(value), 4) == iti
        for value in (result.oti_submechanisms[index, 0], expected["oti_submechanisms"][0]):
            assert round(float(value), 4) == oti
        for value in (result.cti_submechanisms[index, 0], expected["cti_submechanisms"][0]):
            assert round(float(value), 4) == cti
        decimals = 3 if y_mm < 1 else 2
        for x, y in (result.full_poses[index, :2], expected["parasitic"][:2]):
            assert (round(1000 * x, decimals) + 0.0, round(1000 * y, decimals)) == (x_mm, y_mm)
        # zero torsion: the solved yaw is the T&T orientation's
        assert result.full_poses[index, 5] == pytest.approx(tilt_torsion(math.radians(tilt), math.radians(azimuth))[2],
                                                            abs=1e-9)
    assert result.iti[0] == pytest.approx(math.sqrt(1 - ((R1 - R2) / LINK) ** 2), abs=1e-12)
    named = prs.named_pose("tilt_30_azimuth_30")
    np.testing.assert_allclose(named, poses[-1], atol=1e-15)


# ---------------------------------------------------------------------------------------------
# five_bar_3: textbook pressure angles from explicit geometry
# ---------------------------------------------------------------------------------------------

FIVE_BAR_BASE = np.array([[-0.1, 0.0], [0.1, 0.0], [0.2, 0.65]])
PROXIMAL, DISTAL = 0.2, 0.3
ELBOW_SIDES = (1.0, -1.0, -1.0)  # the elbow on the left (+1) or right (-1) of the line A_i -> P


def cross_2d(first, second):
    return first[..., 0] * second[..., 1] - first[..., 1] * second[..., 0]


def five_bar_elbows(point):
    """Elbows B_i at the output point P (circle intersection on the working-mode side)."""
    elbows = []
    for base, side in zip(FIVE_BAR_BASE, ELBOW_SIDES):
        delta = point - base
        distance = np.linalg.norm(delta)
        along = (PROXIMAL**2 - DISTAL**2 + distance**2) / (2 * distance)
        across = math.sqrt(PROXIMAL**2 - along**2)
        direction = delta / distance
        elbows.append(base + along * direction + side * across * np.array([-direction[1], direction[0]]))
    return np.array(elbows)


def five_bar_expected(point, legs=(0, 1, 2)):
    """ITI_i = |sin(proximal, distal)|, OTI of a pair = |sin(distal_i, distal_k)|, LMTI, F_O1."""
    point = np.asarray(point, dtype=float)
    elbows = five_bar_elbows(point)[list(legs)]
    bases = FIVE_BAR_BASE[list(legs)]
    iti = np.abs(cross_2d(elbows - bases, point - elbows)) / (PROXIMAL * DISTAL)
    pairs = list(combinations(range(len(legs)), 2))
    oti = np.array([abs(cross_2d(point - elbows[i], point - elbows[k])) / DISTAL**2 for i, k in pairs])
    left = [[s for s, pair in enumerate(pairs) if set(pair) <= set(kept)]
            for kept in combinations(range(len(legs)), len(legs) - 1)]
    f_o1 = min(oti[m].max() for m in left) if len(legs) > 2 else 0.0
    return {"elbows": elbows, "iti_actuators": iti, "iti": iti.min(), "oti_submechanisms": oti, "lmti": oti.max(),
            "f_o1": f_o1, "f_io1": min(f_o1, iti.min())}


def five_bar_poses():
    rng = np.random.default_rng(12)
    named = np.array(list(mechanism("five_bar_3").named_poses.values()))
    return np.concatenate([named, np.array([0.0, 0.35]) + rng.uniform(-0.06, 0.06, (10, 2))])


def test_five_bar_3_is_a_point_output_with_two_task_coordinates():
    five = mechanism("five_bar_3")
    assert five.is_planar and five.dof == 2 and five.task_coordinates == ("x", "y")
    np.testing.assert_array_equal(five.output_point, [0.0, 0.0, 0.0])
    np.testing.assert_allclose(five.home_pose, [0.0, 0.35], atol=1e-15)
    assert all(chain.actuated == (0,) and chain.n_joints == 3 for chain in five.chains)
    for pose in five_bar_poses()[:6]:
        solution = solve_one(five, pose)
        expected = five_bar_elbows(pose)
        for i, points in enumerate(solution.joint_points):  # A_i, B_i, P: the working mode of the file
            np.testing.assert_allclose(points[:, :2], [FIVE_BAR_BASE[i], expected[i], pose], atol=1e-12)


def test_five_bar_3_indices_are_the_textbook_pressure_angles():
    five = mechanism("five_bar_3")
    poses = five_bar_poses()
    result = indices_at_poses(five, poses, detail=True)
    assert result.reachable.all() and result.dof == 2 and result.submechanisms == ((0, 1), (0, 2), (1, 2))
    assert result.constraint_count == 0 and np.isnan(result.cti).all()  # no CTI: "not applicable"
    assert result.f_c.keys() == {1} and np.isnan(result.f_c[1]).all()
    for index, pose in enumerate(poses):
        expected = five_bar_expected(pose)
        np.testing.assert_allclose(result.iti_actuators[index], expected["iti_actuators"], rtol=0, atol=TOLERANCE)
        np.testing.assert_allclose(result.oti_submechanisms[index], expected["oti_submechanisms"], rtol=0,
                                   atol=TOLERANCE)
        for key, value in (("iti", result.iti), ("lmti", result.lmti), ("f_o1", result.f_o[1]),
                           ("f_io1", result.f_io[1])):
            assert value[index] == pytest.approx(expected[key], abs=TOLERANCE), (key, pose)


NOTES_FIVE_BAR = {(0.0, 0.35): (0.9998, 0.9998, 0.9889), (0.0, 0.25): (0.8777, 0.8777, 0.8193),
                  (0.1, 0.30): (1.0000, 0.9428, 0.9597)}
"""The research notes' five-bar (section 5; A = (-+0.1, 0), 0.2 / 0.3, elbows out): P -> ITI_1, ITI_2, OTI."""


def test_the_first_two_legs_are_the_notes_five_bar():
    """Legs 1 and 2 of five_bar_3 are the notes' standard five-bar: their ITIs and the OTI of the
    submechanism {1, 2} are its values (the formula here, and the notes' table to 4 decimals)."""
    five = mechanism("five_bar_3")
    result = indices_at_poses(five, list(NOTES_FIVE_BAR), detail=True)
    for index, (pose, (first, second, oti)) in enumerate(NOTES_FIVE_BAR.items()):
        expected = five_bar_expected(pose, legs=(0, 1))
        np.testing.assert_allclose(result.iti_actuators[index, :2], expected["iti_actuators"], rtol=0, atol=TOLERANCE)
        assert result.oti_submechanisms[index, 0] == pytest.approx(expected["lmti"], abs=TOLERANCE)
        assert tuple(np.round(expected["iti_actuators"], 4)) == (first, second)
        assert round(float(result.oti_submechanisms[index, 0]), 4) == round(float(expected["lmti"]), 4) == oti


def two_leg_five_bar_text() -> str:
    """five_bar_3 without its third leg: the standard five-bar, 2 actuators for 2 DOF."""
    text = bundled_path("five_bar_3").read_text()
    for pattern in (r'\s*<loop name="chain_3_joint_d".*?</loop>',
                    r'\s*<transmission name="chain_3_joint_b_transmission">.*?</transmission>',
                    r'\s*<joint name="chain_3_joint_[bc]".*?</joint>', r'\s*<link name="chain_3_link_[al]".*?</link>'):
        text, done = re.subn(pattern, "", text, flags=re.S)
        assert done
    return text


def test_a_standard_two_leg_five_bar_loads():
    """A point output with exactly n actuators (research/lower_mobility_bugs.md, 1: the actuator count was
    checked against the DOF before the idle rotation was removed)."""
    two = load_text(two_leg_five_bar_text(), "five_bar_2.urdf")
    assert len(two.chains) == 2 and two.dof == 2
    rng = np.random.default_rng(13)
    poses = np.concatenate([np.array(list(NOTES_FIVE_BAR)), np.array([0.0, 0.3]) + rng.uniform(-0.1, 0.1, (10, 2))])
    result = indices_at_poses(two, poses, detail=True)
    assert result.reachable.all() and result.submechanisms == ((0, 1),)
    for index, pose in enumerate(poses):
        expected = five_bar_expected(pose, legs=(0, 1))
        np.testing.assert_allclose(result.iti_actuators[index], expected["iti_actuators"], rtol=0, atol=TOLERANCE)
        assert result.lmti[index] == pytest.approx(expected["lmti"], abs=TOLERANCE)


# ---------------------------------------------------------------------------------------------
# The command line (subprocesses), against the independent values above
# ---------------------------------------------------------------------------------------------

NEW_MECHANISMS = {
    # name: (task coordinates with units, dependent coordinates, output)
    "prs_3_ups": ([("z", "m"), ("roll", "deg"), ("pitch", "deg")], ["x", "y", "yaw"], "frame"),
    "five_bar_3": ([("x", "m"), ("y", "m")], ["phi"], "point"),
    "delta_4": ([("x", "m"), ("y", "m"), ("z", "m")], ["roll", "pitch", "yaw"], "frame"),
    "schoenflies_5": ([("x", "m"), ("y", "m"), ("z", "m"), ("yaw", "deg")], ["roll", "pitch"], "frame"),
}


@pytest.mark.parametrize("name", NEW_MECHANISMS)
def test_info_reports_the_task_coordinates(name):
    result = screwkit("info", name, "--json")
    assert result.returncode == 0, result.stderr
    described = json.loads(result.stdout)
    task, dependent, output = NEW_MECHANISMS[name]
    assert [(c["name"], c["unit"]) for c in described["task_coordinates"]] == task
    assert [c["name"] for c in described["dependent_coordinates"]] == dependent
    assert described["dof"] == len(task) and described["output"] == output
    loaded = mechanism(name)
    assert described["named_poses"].keys() == loaded.named_poses.keys()
    for pose_name, values in described["named_poses"].items():  # angles in degrees on the command line
        expected = [math.degrees(v) if unit == "deg" else v for v, (_, unit) in zip(loaded.named_pose(pose_name), task)]
        assert list(values.values()) == pytest.approx(expected, abs=1e-12)


def test_analyze_on_the_command_line_gives_the_independent_values():
    result = screwkit("analyze", "prs_3_ups", "--pose", "pitch_10", "--json")
    assert result.returncode == 0, result.stderr
    report = json.loads(result.stdout)
    expected = prs_ups_expected([HEIGHT, 0.0, math.radians(10.0)])
    assert report["pose"] == pytest.approx({"z": HEIGHT, "roll": 0.0, "pitch": 10.0}, abs=1e-12)
    x, y, yaw = expected["parasitic"]
    assert report["dependent"] == pytest.approx({"x": x, "y": y, "yaw": math.degrees(yaw)}, abs=1e-10)
    assert list(report["iti_actuators"].values()) == pytest.approx(list(expected["iti_actuators"]), abs=TOLERANCE)
    for key in ("iti", "lmti", "cti"):
        assert report[key] == pytest.approx(expected[key], abs=TOLERANCE), key
    for key in ("f_o", "f_io", "f_c"):
        assert report[key] == pytest.approx({"1": expected[f"{key}1"]}, abs=TOLERANCE), key
    assert report["instantaneous_dof"] == 3 and report["constraint_singular"] is False
    five = json.loads(screwkit("analyze", "five_bar_3", "--pose", "notes_row_3", "--json").stdout)
    expected = five_bar_expected([0.1, 0.3])
    assert five["cti"] == "not applicable" and five["dof"] == 2
    assert list(five["iti_actuators"].values()) == pytest.approx(list(expected["iti_actuators"]), abs=TOLERANCE)
    for key in ("lmti",):
        assert five[key] == pytest.approx(expected[key], abs=TOLERANCE)
    assert five["f_o"] == pytest.approx({"1": expected["f_o1"]}, abs=TOLERANCE)


def read_csv(path):
    import csv

    with open(path, newline="") as handle:
        return list(csv.DictReader(handle))


def test_sweep_on_the_command_line_gives_the_independent_values(tmp_path):
    out = tmp_path / "sweep.csv"
    result = screwkit("sweep", "prs_3_ups", "--sweep", "pitch:-20:31:10", "--out", out, "--quiet")
    assert result.returncode == 0, result.stderr
    rows = read_csv(out)
    assert [float(row["pitch"]) for row in rows] == pytest.approx([-20.0, -10.0, 0.0, 10.0, 20.0, 30.0], abs=1e-12)
    for row in rows:
        expected = prs_ups_expected([HEIGHT, 0.0, math.radians(float(row["pitch"]))])
        for key in ("iti", "lmti", "f_o1", "f_io1", "cti", "f_c1"):
            assert float(row[key]) == pytest.approx(expected[key], abs=TOLERANCE), (key, row["pitch"])


def test_map_on_the_command_line_gives_the_textbook_values(tmp_path):
    out = tmp_path / "map.csv"
    result = screwkit("map", "five_bar_3", "--grid", "x:-0.05:0.05:0.05", "--grid", "y:0.3:0.4:0.05", "--out", out,
                      "--quiet")
    assert result.returncode == 0, result.stderr
    rows = read_csv(out)
    assert len(rows) == 9
    for row in rows:
        expected = five_bar_expected([float(row["x"]), float(row["y"])])
        assert float(row["reachable_fraction"]) == 1.0
        for key in ("iti", "lmti", "f_o1", "f_io1"):
            assert float(row[key]) == pytest.approx(expected[key], abs=TOLERANCE), (key, row["x"], row["y"])


def test_planar_disc_map_of_a_point_output(tmp_path):
    """The planar disc form maps x, y about home, with no phi turn for a point output
    (research/lower_mobility_bugs.md, 2: it asked for the task coordinate phi)."""
    out = tmp_path / "disc.csv"
    result = screwkit("map", "five_bar_3", "--radius", "0.05", "--step", "0.05", "--out", out, "--quiet")
    assert result.returncode == 0, result.stderr
    inside = 0
    for row in read_csv(out):
        x, y = float(row["x"]), float(row["y"])
        if math.hypot(x, y - 0.35) > 0.05 + 1e-9:
            assert row["iti"] == ""  # outside the disc
            continue
        inside += 1
        expected = five_bar_expected([x, y])
        for key in ("iti", "lmti", "f_o1"):
            assert float(row[key]) == pytest.approx(expected[key], abs=TOLERANCE), (key, x, y)
    assert inside == 5


# ---------------------------------------------------------------------------------------------
# The same indices in millimetres and with the whole mechanism moved in the world
# ---------------------------------------------------------------------------------------------


def assert_same_indices(reference, other):
    fields = ("iti", "iti_actuators", "oti_submechanisms", "lmti", "cti", "cti_submechanisms")
    assert_indices_close(reference, other, TOLERANCE, fields=fields, full_poses_atol=1e-9)


@pytest.mark.parametrize("name", NEW_MECHANISMS)
def test_indices_do_not_depend_on_the_unit_or_the_world_frame(tmp_path, name):
    reference_mechanism = mechanism(name)
    rng = np.random.default_rng(sum(map(ord, name)))
    named = np.array(list(reference_mechanism.named_poses.values()))
    scale = np.where(reference_mechanism.angular, 0.1, 0.02)
    poses = np.concatenate([named, reference_mechanism.home_pose + rng.uniform(-1, 1, (6, named.shape[1])) * scale])
    reference = indices_at_poses(reference_mechanism, poses, detail=True)
    assert reference.reachable.all()
    text = bundled_path(name).read_text()
    millimetres = tmp_path / f"{name}_mm.urdf"
    millimetres.write_text(in_millimetres(text, declare=True))
    in_mm = load(millimetres)
    assert in_mm.length_unit == "mm" and in_mm.task_coordinates == reference_mechanism.task_coordinates
    np.testing.assert_allclose(np.array(list(in_mm.named_poses.values())), named, rtol=0, atol=1e-12)
    assert_same_indices(reference, indices_at_poses(in_mm, poses, detail=True))
    xyz, rpy = rng.uniform(-2, 2, 3), rng.uniform(-np.pi, np.pi, 3)
    for source, length in ((text, 1.0), (in_millimetres(text, declare=True), 1000.0)):
        moved = tmp_path / f"{name}_moved.urdf"
        moved.write_text(moved_in_the_world(source, xyz * length, rpy))
        placed = load(moved)
        assert not placed.base_is_world
        assert_same_indices(reference, indices_at_poses(placed, poses, detail=True))


def test_a_planar_point_output_turns_about_its_own_plane_normal_in_any_world_frame(tmp_path, monkeypatch):
    """The idle rotation of a planar point output is about the plane's normal, not the world z axis: with
    world z it would be one more shared twist, and which motion-space basis is kept would be arbitrary."""
    from screwkit.indices import analysis as transmission

    reference_mechanism = mechanism("five_bar_3")
    poses = np.array(list(reference_mechanism.named_poses.values()))
    reference = indices_at_poses(reference_mechanism, poses, detail=True)
    rng = np.random.default_rng(11)
    text = bundled_path("five_bar_3").read_text()
    appended = []

    def recording(chains, *arguments):
        result = original(chains, *arguments)
        appended.append([b.twists.shape[-2] - a.twists.shape[-2] for a, b in zip(chains, result)])
        return result

    original = transmission.with_idle_joints
    monkeypatch.setattr(transmission, "with_idle_joints", recording)
    for trial in range(4):
        moved = tmp_path / f"moved_{trial}.urdf"
        moved.write_text(moved_in_the_world(text, rng.uniform(-1, 1, 3), rng.uniform(-np.pi, np.pi, 3)))
        assert_same_indices(reference, indices_at_poses(load(moved), poses, detail=True))
    # each chain ends in a revolute joint about the point's normal: no idle joint is appended
    assert appended and all(count == 0 for counts in appended for count in counts), appended


def test_idle_rotations_about_a_given_normal():
    from screwkit.screw.outputs import idle_rotations

    twists, points = idle_rotations(np.array([[1.0, 2.0, 3.0]]), np.array([0.0, 0.0, 2.0]))
    np.testing.assert_allclose(twists, [[[0, 0, 1, 2, -1, 0]]])
    np.testing.assert_allclose(points, [[[1, 2, 3]]])
    with pytest.raises(ValueError, match="plane normal"):
        idle_rotations(np.zeros((1, 3)), np.zeros(3))


def test_poses_whose_dependent_coordinates_do_not_close_are_unreachable_without_solving_the_chains():
    """A Delta batch mixing reachable poses with poses far outside the workspace: the second are
    unreachable with the closure error of the dependent coordinates for every chain (the chains
    are not tracked there: the pose is unreachable whatever they do), the first have the values
    and reachability they have alone."""
    from screwkit.closure import solve
    from screwkit.closure.task_space import complete_poses

    delta = mechanism("delta_4")
    home = delta.home_pose
    poses = np.array([home, home + [0.05, -0.03, 0.02], [0.9, 0.9, -0.1], home + [-0.04, 0.02, -0.03],
                      [-1.5, 0.2, 0.4]])
    _, _, completed, completion_residual = complete_poses(delta, poses)
    assert completed.tolist() == [True, True, False, True, False]
    batch = solve(delta, poses)
    assert batch.reachable.tolist() == [True, True, False, True, False]
    for row in np.flatnonzero(~completed):
        np.testing.assert_array_equal(batch.residuals[row], np.full(len(delta.chains), completion_residual[row]))
        assert all(np.all(np.isnan(values[row])) for values in batch.joint_values)
    for row in np.flatnonzero(completed):
        alone = solve(delta, poses[row:row + 1])
        assert alone.reachable[0]
        for values, single in zip(batch.joint_values, alone.joint_values):
            np.testing.assert_allclose(values[row], single[0], rtol=0, atol=1e-12)


def test_a_mechanism_of_one_dof_has_the_indices_of_its_closed_form():
    """Mobility one: a platform on a passive slide along x, driven by three planar R-P-R legs at angles t_k. Each
    leg's actuation wrench is a force along it, the output twist a translation along x: OTI_k = |cos t_k|, ITI_k = 1,
    LMTI = max_k |cos t_k|, F_O1 = the least of the two largest, F_O2 = the smallest (Eqs. 6-12). It raised
    "cannot reshape array of size 0" (the empty set of n - 1 = 0 locked actuators)."""
    from screwkit.indices.analysis import analyze
    from screwkit.screw.chain_screws import ChainScrews
    from screwkit.screw.planar import rpr_chain_screws

    rng = np.random.default_rng(11)
    angles = rng.uniform(0.0, np.pi, (5, 3))
    platform = rng.uniform(-0.2, 0.2, (5, 1, 2)) * np.ones((1, 3, 1))
    legs = rpr_chain_screws(platform - 0.8 * np.stack([np.cos(angles), np.sin(angles)], axis=-1), platform)
    slide = ChainScrews(np.tile([0.0, 0.0, 0.0, 1.0, 0.0, 0.0], (5, 1, 1)),
                        np.concatenate([platform[:, :1], np.zeros((5, 1, 1))], axis=-1), (), name="guide",
                        joint_names=("slide",))
    result = analyze([*legs, slide])
    cosines = np.sort(np.abs(np.cos(angles)), axis=-1)
    assert result.dof == 1
    np.testing.assert_allclose(result.iti_actuators, 1.0, atol=1e-12)
    np.testing.assert_allclose(result.lmti, cosines[:, 2], atol=1e-12)
    np.testing.assert_allclose(result.f_o[1], cosines[:, 1], atol=1e-12)
    np.testing.assert_allclose(result.f_o[2], cosines[:, 0], atol=1e-12)


ONE_DOF_MJCF = (
    '<mujoco model="welded_five_bar"><compiler angle="radian"/><worldbody><body name="base">'
    '<body name="proximal_1" pos="-0.1 0 0"><joint name="a_1" type="hinge" axis="0 0 1"/><geom type="sphere" '
    'size="0.01"/><body name="distal_1" pos="-0.1273240921790808 0.15423545490830878 0"><joint name="b_1" '
    'type="hinge" axis="0 0 1"/><geom type="sphere" size="0.01"/><site name="effector" '
    'pos="0.2273240921790808 0.1957645450916912 0"/></body></body>'
    '<body name="proximal_2" pos="0.1 0 0"><joint name="a_2" type="hinge" axis="0 0 1"/><geom type="sphere" '
    'size="0.01"/><body name="distal_2" pos="0.1273240921790808 0.15423545490830878 0"><joint name="b_2" '
    'type="hinge" axis="0 0 1"/><geom type="sphere" size="0.01"/></body></body>'
    '<body name="proximal_3" pos="0.2 0.65 0"><joint name="a_3" type="hinge" axis="0 0 1"/><geom type="sphere" '
    'size="0.01"/><body name="distal_3" pos="-0.2 0 0"><joint name="b_3" type="hinge" axis="0 0 1"/><geom '
    'type="sphere" size="0.01"/></body></body></body></worldbody><equality><weld name="loop_2" body1="distal_2" '
    'body2="distal_1"/><connect name="loop_3" body1="distal_3" body2="distal_1" anchor="0 -0.3 0"/></equality>'
    '<actuator><motor name="m_1" joint="a_1"/><motor name="m_2" joint="a_2"/><motor name="m_3" joint="a_3"/>'
    '</actuator></mujoco>')


def test_a_file_of_one_dof_is_analysed_and_swept_on_the_command_line(tmp_path):
    """A five-bar whose first two legs are welded where the third meets them: one DOF, three actuators. `analyze`
    and `sweep` said "cannot reshape array of size 0 into shape (0)"; now the indices, each LMTI the largest of
    its actuators' min(ITI, OTI) (Eq. 11 over submechanisms of one actuator)."""
    path = tmp_path / "welded.xml"
    path.write_text(ONE_DOF_MJCF)
    analysed = screwkit("analyze", path, "--json")
    assert analysed.returncode == 0, analysed.stderr
    report = json.loads(analysed.stdout)
    assert report["dof"] == 1 and set(report["f_o"]) == {"1", "2"}
    iti = np.array(list(report["iti_actuators"].values()))
    assert 0 < report["lmti"] <= 1 and report["lmti"] <= iti.max() + 1e-12
    described = json.loads(screwkit("info", path, "--json").stdout)  # its frame moves more than it turns (in
    assert [coordinate["name"] for coordinate in described["task_coordinates"]] == ["x"]  # length scales): x
    swept = screwkit("sweep", path, "--sweep", "x:-0.1:0.15:0.05")
    assert swept.returncode == 0, swept.stderr
    assert len(swept.stdout.splitlines()) == 6


def _ups_leg(base, top, name):
    """A U-P-S leg's screws from ``base`` to ``top``: universal at the base (two hinges across the leg), the slide
    along it (actuated), a ball at the top (three hinges): its actuation wrench is a force along the leg."""
    from screwkit.screw.chain_screws import ChainScrews

    along = (top - base) / np.linalg.norm(top - base)
    across = np.cross(along, [1.0, 0.0, 0.0] if abs(along[0]) < 0.9 else [0.0, 1.0, 0.0])
    across /= np.linalg.norm(across)
    axes = [across, np.cross(along, across), None, *np.eye(3)]
    points = [base, base, top, top, top, top]
    twists = [np.concatenate([np.zeros(3), along]) if axis is None else np.concatenate([axis, np.cross(p, axis)])
              for axis, p in zip(axes, points)]
    return ChainScrews(np.array(twists), np.array(points), (2,), name=name,
                       joint_names=("u1", "u2", "slide", "s1", "s2", "s3"))


@pytest.mark.parametrize("seed", range(6))
def test_an_actuator_whose_force_does_no_work_on_the_platform_s_motion_leaves_the_others_free(seed):
    """A platform on a passive slide along x (mobility one), three U-P-S legs, the first two across x: their
    forces do no work on the slide, so locking them leaves it free, and the third is no mutual-interference
    actuator (Sec. 3), F_O1 = F_O2 = 0 exactly; LMTI = the third leg's |cos| with x (0.8). Rows of rounding noise
    measured against their own norms made their submechanisms count as independent: the third leg was flagged in
    most placements and F_O1 came out 1e-17. The plain-numpy reference gives the same."""
    from screwkit.indices.analysis import analyze
    from screwkit.screw.chain_screws import ChainScrews
    from screwkit.screw.reference import reference_indices

    rng = np.random.default_rng(seed)
    directions = np.array([[0.0, 1.0, 0.3], [0.0, 0.8, 0.6], [0.8, 0.0, 0.6]])
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    tops = rng.uniform(-0.2, 0.2, (3, 3))
    legs = [_ups_leg(top - 0.9 * u, top, f"leg_{k}") for k, (u, top) in enumerate(zip(directions, tops))]
    slide = ChainScrews(np.array([[0.0, 0.0, 0.0, 1.0, 0.0, 0.0]]), np.zeros((1, 3)), (), name="guide",
                        joint_names=("slide",))
    result = analyze([*legs, slide], threads=1)
    assert result.dof == 1
    assert list(result.mutual_interference) == [True, True, False]
    assert result.lmti == pytest.approx(0.8, abs=1e-12)
    assert result.f_o[1] == 0.0 and result.f_o[2] == 0.0
    chains = [*legs, slide]
    reference = reference_indices([c.twists for c in chains], [c.points for c in chains],
                                  [c.actuated for c in chains], 1)
    assert list(reference["mutual_interference"]) == [True, True, False]
    assert reference["lmti"] == pytest.approx(0.8, abs=1e-12) and reference["f_o"][1] == 0.0
    # the same in another world frame, at lengths x 1e-3 and x 1e3, and with the legs listed in reverse
    rotation, translation = random_rotation(rng), rng.uniform(-2.0, 2.0, 3)
    for variant, flags in ((moved(chains, rotation, translation), [True, True, False]),
                           (_scaled(chains, 1e-3), [True, True, False]), (_scaled(chains, 1e3), [True, True, False]),
                           ([*legs[::-1], slide], [False, True, True])):
        other = analyze(variant, threads=1)
        assert list(other.mutual_interference) == flags
        assert other.lmti == pytest.approx(0.8, abs=1e-12) and other.f_o[1] == 0.0 and other.f_o[2] == 0.0


def _scaled(chains, factor: float):
    """Chain screws of the mechanism with every length times ``factor`` (points, and the moments of revolute twists;
    a slide's unit direction stays)."""
    from screwkit.screw.chain_screws import ChainScrews

    scaled = []
    for c in chains:
        twists = np.array(c.twists, dtype=float)
        revolute = np.linalg.norm(twists[..., :3], axis=-1) > 0
        twists[revolute, 3:] *= factor
        scaled.append(ChainScrews(twists, np.asarray(c.points) * factor, c.actuated, c.name,
                                  joint_names=c.joint_names))
    return scaled
