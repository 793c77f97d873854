"""Constraint wrenches, the CTI, constraint singularities and link failures.

The CTI is checked against an independent computation from the explicit geometry of PRS legs
(constraint force through the S centre along the R axis, actuation force along the link through
the S centre, the freed twist as the null space of the other wrenches by an SVD, the power
coefficient as the cosine between the released force and the velocity of its S centre), on a
symmetric 4-PRS at tilted poses. Its home pose, where four constraint forces span only three
wrenches, is a constraint singularity. Link failures agree with free-swinging ones where the
paper says they must (chains without constraint wrenches of their own) and differ where a chain
holds one. Invariance to the length unit and the world frame is checked on the CTI too.
"""

from __future__ import annotations

import re
from itertools import combinations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from helpers import assert_indices_close, couple_cti, in_unit, moved, random_rotation, screwkit
from screwkit.closure import chain_screws, solve
from screwkit.closure.task_space import choose_task_axes
from screwkit.indices.analysis import analyze
from screwkit.io.loader import bundled_path, load_text
from screwkit.robots.generate import PRS_UPS, prs_mechanism
from screwkit.screw.chain_screws import ChainScrews
from screwkit.studies.poses import analyze_solution, indices_at_poses

TOLERANCE = 1e-9


@pytest.fixture(scope="module")
def prs_4(tmp_path_factory):
    """A symmetric 4-PRS (rails at 0, 90, 180, 270 deg): mobility 2 (z and a tilt), 4 actuators."""
    parameters = dict(PRS_UPS, prs_angles_deg=(0.0, 90.0, 180.0, 270.0))
    text = prs_mechanism("prs_4_symmetric", parameters, with_ups=False)
    path = tmp_path_factory.mktemp("prs") / "prs_4_symmetric.urdf"
    path.write_text(text)
    return load_text(text, str(path)), path


@pytest.fixture(scope="module")
def prs_3_ups():
    return load_text(prs_mechanism("prs_3_ups_test", PRS_UPS, with_ups=True), "prs_3_ups_test")


def _coefficient(force, point, twist):
    """|f . v_P| / (|f| |v_P|) for a pure force through ``point`` and a twist (omega, v about the origin)."""
    velocity = twist[3:] + np.cross(twist[:3], point)
    return abs(force @ velocity) / (np.linalg.norm(force) * np.linalg.norm(velocity))


def prs_cti(twists, points, dof):
    """The CTI of PRS legs from their explicit geometry (joint twists (m, 6) and points (m, 3) of each leg,
    P, R, then the S joint's three): max over n-subsets of min over the released constraint forces."""
    centres = [p[-1] for p in points]  # S centre
    r_axes = [t[1, :3] for t in twists]
    links = [centre - p[1] for p, centre in zip(points, centres)]  # R point -> S centre

    def line(direction, point):  # a unit force (f, m) through a point
        direction = direction / np.linalg.norm(direction)
        return np.concatenate([direction, np.cross(point, direction)])

    constraints = np.array([line(r, c) for r, c in zip(r_axes, centres)])
    actuation = np.array([line(u, c) for u, c in zip(links, centres)])
    best = 0.0
    for subset in combinations(range(len(twists)), dof):
        system = np.vstack([actuation[list(subset)], constraints])
        if np.linalg.matrix_rank(system, tol=1e-9) < 6:
            continue
        kappas = []
        for j in range(len(twists)):
            others = np.delete(system, dof + j, axis=0)
            _, _, right = np.linalg.svd(others)
            null = right[-1]  # Euclidean null vector x: others @ x = 0, x = (v, omega) of a twist
            twist = np.concatenate([null[3:], null[:3]])
            kappas.append(_coefficient(constraints[j, :3], centres[j], twist))
        best = max(best, min(kappas))
    return best


def test_4_prs_home_is_a_constraint_singularity(prs_4):
    mechanism, path = prs_4
    assert mechanism.dof == 2
    result = indices_at_poses(mechanism, mechanism.home_pose[None])
    assert result.instantaneous_dof[0] == 3 and result.constraint_singular[0]
    assert result.dof == 2
    assert result.cti[0] == 0.0 and result.lmti[0] == 0.0 and all(v[0] == 0.0 for v in result.f_o.values())
    assert result.iti[0] > 0.9  # the input transmission is not what failed
    completed = screwkit("analyze", path)
    assert completed.returncode == 0, completed.stderr
    assert "CONSTRAINT SINGULARITY: 3 instantaneous DOF at this pose, mobility 2" in completed.stdout


def test_the_4_prs_constraint_singularity_has_no_fault_index_under_link_failures_either(prs_4):
    """Under link failures the home pose gave F_O1 0.948 and F_C1 0.8845 beside LMTI 0 and CTI 0 (the 3-PRS a
    removed leg leaves holds its platform there): the intact mechanism does not hold its platform, so every fault
    index is zero and the worst faults the first sets, as under free-swinging failures; a tilted pose in the same
    batch keeps its own values."""
    mechanism, _ = prs_4
    poses = mechanism.home_pose + np.array([[0.0, 0.0], [0.0, np.deg2rad(5.0)]])
    swinging = indices_at_poses(mechanism, poses, detail=True)
    link = indices_at_poses(mechanism, poses, fault_type="link", detail=True)
    assert list(link.constraint_singular) == [True, False]
    for j in link.faults:
        assert link.f_o[j][0] == 0.0 and link.f_c[j][0] == 0.0 and np.all(link.remaining_lmti[j][0] == 0.0)
        assert list(link.worst_fault_indices[j][0]) == list(swinging.worst_fault_indices[j][0])
    alone = indices_at_poses(mechanism, poses[1:], fault_type="link")
    for j in link.faults:
        assert link.f_o[j][1] == alone.f_o[j][0] and link.f_c[j][1] == alone.f_c[j][0]
    assert link.f_o[1][1] > 0.9  # a 3-PRS left: held (two faults leave two actuators for its three DOF)


@pytest.mark.parametrize("tilt_degrees", [3.0, 8.0, -12.0])
def test_4_prs_cti_matches_the_explicit_geometry(prs_4, tilt_degrees):
    mechanism, _ = prs_4
    pose = mechanism.home_pose + np.array([0.01, np.deg2rad(tilt_degrees)])
    solution = solve(mechanism, pose[None])
    assert solution.reachable.all()
    result = analyze_solution(mechanism, solution, detail=True)
    assert not result.constraint_singular[0] and result.instantaneous_dof[0] == 2
    chains = chain_screws(mechanism, solution)
    expected = prs_cti([c.twists[0] for c in chains], [c.points[0] for c in chains], 2)
    assert 0.0 < expected < 1.0
    assert abs(result.cti[0] - expected) < TOLERANCE


def test_cti_is_not_applicable_without_own_constraint_wrenches():
    from screwkit.io.loader import load

    for name in ("planar_5rrr", "ups_hexapod_8"):
        mechanism = load(name)
        result = indices_at_poses(mechanism, mechanism.home_pose[None])
        assert np.isnan(result.cti).all() and result.constraint_count == 0
        assert all(np.isnan(values).all() for values in result.f_c.values())
        assert result.at(0).to_dict()["cti"] == "not applicable"


def test_cti_is_invariant_to_unit_and_frame(prs_3_ups):
    rng = np.random.default_rng(3)
    mechanism = prs_3_ups
    poses = mechanism.home_pose + rng.uniform(-1, 1, (40, 3)) * np.array([0.01, 0.2, 0.2])
    solution = solve(mechanism, poses)
    chains = chain_screws(mechanism, solution, unreachable="drop")
    reference = analyze(chains, dof=3)
    assert reference.constraint_count == 3 and np.all(reference.cti > 0.9)
    for scale in (1e-3, 1e3):
        rotation = random_rotation(rng)
        changed = moved(chains, rotation, rng.normal(size=3))
        scaled = [ChainScrews(c.twists * np.r_[np.ones(3), np.full(3, scale)], c.points * scale, c.actuated,
                              c.name, joint_names=c.joint_names) for c in changed]
        other = analyze(scaled, dof=3, threshold=1e-6 * scale)
        np.testing.assert_allclose(other.cti, reference.cti, atol=TOLERANCE, rtol=0)
        for j in reference.faults:
            np.testing.assert_allclose(other.f_c[j], reference.f_c[j], atol=TOLERANCE, rtol=0)


@pytest.mark.parametrize("name", ["planar_5rrr", "planar_4rpr", "ups_hexapod_8"])
def test_link_and_free_swinging_faults_agree_without_own_constraints(name):
    from screwkit.io.loader import load

    mechanism = load(name)
    rng = np.random.default_rng(7)
    poses = mechanism.home_pose + rng.uniform(-1, 1, (30, mechanism.n_task)) * 0.02
    free = indices_at_poses(mechanism, poses)
    link = indices_at_poses(mechanism, poses, fault_type="link")
    assert link.fault_type == "link" and free.fault_type == "free-swinging"
    both = free.reachable & link.reachable
    assert both.sum() > 20
    for j in free.faults:
        np.testing.assert_allclose(link.f_o[j][both], free.f_o[j][both], atol=1e-12, rtol=0)
        np.testing.assert_allclose(link.f_io[j][both], free.f_io[j][both], atol=1e-12, rtol=0)


def test_link_failure_of_a_constraining_leg_frees_the_platform(prs_3_ups):
    """3-PRS + UPS: losing a PRS leg takes its constraint force away; the platform gains a DOF that the
    three actuators left cannot hold (F_O1 = 0), while a free-swinging PRS joint keeps the force."""
    mechanism = prs_3_ups
    poses = mechanism.home_pose + np.array([[0.0, 0.05, 0.02], [0.01, -0.1, 0.08]])
    free = indices_at_poses(mechanism, poses, detail=True)
    link = indices_at_poses(mechanism, poses, fault_type="link")
    assert np.all(free.f_o[1] > 0.5)
    np.testing.assert_array_equal(link.f_o[1], 0.0)
    prs = [name for name in mechanism.actuator_names if name.startswith("prs")]
    assert len(prs) == 3 and all(name in prs for row in link.worst_faults[1] for name in row)
    # the UPS leg holds no constraint: the 3-PRS without it transmits as the free-swinging set of its actuators
    chains = chain_screws(mechanism, solve(mechanism, poses))
    alone = analyze([c for c in chains if c.name.startswith("prs")], dof=3)
    np.testing.assert_allclose(alone.lmti, free.lmti_of(prs), atol=TOLERANCE, rtol=0)


def test_cli_fault_option_reports_the_type():
    import json

    completed = screwkit("analyze", "planar_5rrr", "--pose", "paper_fig_2a", "--fault", "link", "--json")
    assert completed.returncode == 0, completed.stderr
    report = json.loads(completed.stdout)
    assert report["fault_type"] == "link" and report["cti"] == "not applicable"
    wrong = screwkit("analyze", "planar_5rrr", "--fault", "gearbox")
    assert wrong.returncode != 0 and "--fault" in wrong.stderr


def delta_cti(twists):
    """The CTI of R-U-U Delta legs from their explicit geometry: each leg's constraint couple m_i = a_i x w_i
    (a the arm axis, w the universal joints' middle axis), then :func:`helpers.couple_cti`."""
    return couple_cti([np.cross(t[0, :3], t[2, :3]) for t in twists])


@pytest.mark.parametrize("pose_name", ["home", "raised", "off_centre"])
def test_delta_cti_matches_the_explicit_geometry(pose_name):
    from screwkit.io.loader import load

    mechanism = load("delta_4")
    solution = solve(mechanism, mechanism.named_pose(pose_name)[None])
    result = analyze_solution(mechanism, solution)
    chains = chain_screws(mechanism, solution)
    expected = delta_cti([c.twists[0] for c in chains])
    assert result.constraint_count == 3 and 0.0 < expected <= 1.0
    assert abs(result.cti[0] - expected) < TOLERANCE
    # the couples' kappas do not depend on which actuators are locked: every regular set has the same CTI_N
    np.testing.assert_allclose(result.cti_submechanisms[0], expected, atol=TOLERANCE, rtol=0)


def test_a_3_prs_reports_3_dof_and_its_parasitic_motion():
    """The non-redundant 3-PRS: z, roll, pitch drive it; at a pitch theta about the axis through leg 1 the
    platform centre shifts by R2 (1 - cos theta) / 2 along that axis (closed form), with no torsion."""
    mechanism = load_text(prs_mechanism("prs_3", PRS_UPS, with_ups=False), "prs_3")
    assert mechanism.dof == 3 and mechanism.task_coordinates == ("z", "roll", "pitch")
    theta = np.deg2rad(np.array([5.0, 15.0, 25.0]))
    poses = np.column_stack([np.full(3, mechanism.home_pose[0]), np.zeros(3), theta])
    result = indices_at_poses(mechanism, poses)
    assert result.reachable.all() and result.dof == 3 and not result.constraint_singular.any()
    full = dict(zip(mechanism.pose_coordinates, np.moveaxis(result.full_poses, -1, 0)))
    shift = PRS_UPS["platform_radius"] * (1 - np.cos(theta)) / 2
    np.testing.assert_allclose(np.abs(full["y"]), shift, atol=1e-10, rtol=0)
    np.testing.assert_allclose(full["x"], 0.0, atol=1e-10)
    np.testing.assert_allclose(full["yaw"], 0.0, atol=1e-10)
    assert result.faults == (1,) and np.all(result.f_o[1] == 0.0)  # 3 actuators for 3 DOF: one fault, no control


def test_link_faults_are_invariant_to_unit_and_frame(prs_4):
    """Link failures of the 4-PRS: a lost leg leaves a 3-PRS of mobility 3 held by its three actuators, a
    reduced mechanism of its own; its F_O1 and worst faults do not depend on the unit or the world frame."""
    mechanism, _ = prs_4
    rng = np.random.default_rng(5)
    poses = mechanism.home_pose + np.column_stack([rng.uniform(-0.01, 0.01, 20),
                                                   np.deg2rad(rng.choice([-1, 1], 20) * rng.uniform(3, 15, 20))])
    chains = chain_screws(mechanism, solve(mechanism, poses), unreachable="drop")
    reference = analyze(chains, dof=2, fault_type="link")
    assert np.all(reference.f_o[1] > 0.5)
    for scale in (1e-3, 1e3):
        changed = moved(chains, random_rotation(rng), rng.normal(size=3))
        scaled = [ChainScrews(c.twists * np.r_[np.ones(3), np.full(3, scale)], c.points * scale, c.actuated,
                              c.name, joint_names=c.joint_names) for c in changed]
        other = analyze(scaled, dof=2, fault_type="link", threshold=1e-6 * scale)
        for j in reference.faults:
            np.testing.assert_allclose(other.f_o[j], reference.f_o[j], atol=TOLERANCE, rtol=0)
            np.testing.assert_array_equal(other.worst_fault_indices[j], reference.worst_fault_indices[j])


def test_cli_pose_from_actuator_values(tmp_path):
    """`analyze --actuators` finds the pose whose actuator values are given (closure solved here by screwkit's
    inverse kinematics, read back through the command) and refuses values redundant actuators cannot share."""
    import json

    from screwkit.closure import actuator_values, solve_one
    from screwkit.io.loader import load

    mechanism = load("prs_3_ups")
    pose = mechanism.named_pose("pitch_10") + np.array([0.005, np.deg2rad(3.0), 0.0])
    values = actuator_values(mechanism, solve_one(mechanism, pose).joint_values).reshape(-1)
    completed = screwkit("analyze", "prs_3_ups", "--actuators", *[repr(float(v)) for v in values], "--json")
    assert completed.returncode == 0, completed.stderr
    report = json.loads(completed.stdout)
    shown = [report["pose"]["z"], np.deg2rad(report["pose"]["roll"]), np.deg2rad(report["pose"]["pitch"])]
    np.testing.assert_allclose(shown, pose, atol=1e-9)
    inconsistent = values + np.array([0.0, 0.0, 0.0, 0.02])  # the UPS leg 2 cm longer than the PRS legs allow
    refused = screwkit("analyze", "prs_3_ups", "--actuators", *[repr(float(v)) for v in inconsistent])
    assert refused.returncode == 1 and refused.stderr.strip().splitlines() == [
        "Error: No closed pose of 'prs_3_ups' has these actuator values near the start pose (redundant actuators "
        "must agree with one another, and the pose may lie on another assembly, past a singular configuration from "
        "the start, or out of reach; give another start with --pose, or for a file of another tool --initial on each "
        "actuator)."]
    # a mechanism without redundancy is not told its actuators must agree (it has none to spare)
    far = screwkit("analyze", "five_bar", "--actuators", "0", "180")  # no closed pose near the start
    assert far.returncode == 1 and "No closed pose of 'five_bar'" in far.stderr, far.stderr
    assert "redundant" not in far.stderr and "out of reach" in far.stderr, far.stderr


def test_cli_sweep_and_map_say_their_fault_type(tmp_path):
    import xarray as xr

    sweep_file, map_file = tmp_path / "sweep.nc", tmp_path / "map.nc"
    completed = screwkit("sweep", "prs_3_ups", "--sweep", "pitch:-10:11:10", "--fault", "link", "--out", sweep_file,
                         "--quiet")
    assert completed.returncode == 0, completed.stderr
    completed = screwkit("map", "prs_3_ups", "--grid", "roll:-5:5:5", "--grid", "pitch:-5:5:5", "--fault", "link",
                         "--out", map_file, "--quiet")
    assert completed.returncode == 0, completed.stderr
    with xr.open_dataset(sweep_file) as sweep, xr.open_dataset(map_file) as grid:
        assert sweep.attrs["fault_type"] == "link" and grid.attrs["fault_type"] == "link"
        np.testing.assert_array_equal(sweep["f_o1"].values, 0.0)  # a lost PRS leg frees the platform
        np.testing.assert_array_equal(grid["f_o1"].values, 0.0)
        assert np.all(sweep["cti"].values > 0.9)


def spherical_wrist_urdf(radius: float = 0.1, frame_offset=(0.0, 0.0, 0.0), declared: bool = True) -> str:
    """A spherical 3-RRR wrist (the agile eye at home): three R-R-R legs whose nine joint axes all pass through the
    centre O (the platform frame's origin, or O + ``frame_offset``), leg i's base, middle and platform axes along
    e_i, e_(i+1), e_(i+2); task coordinates roll, pitch, yaw (declared unless not ``declared``)."""
    from screwkit.model.urdf_writer import UrdfWriter

    centre = np.array([0.0, 0.0, 0.3])
    writer = UrdfWriter("spherical_wrist", " spherical 3-RRR wrist, every joint axis through the centre ")
    writer.link("base_link", ("box", (0.1, 0.1, 0.01)))
    writer.link("platform", ("sphere", 0.02))
    offset = np.asarray(frame_offset, dtype=float)
    writer.joint("platform_joint", "floating", "base_link", "platform", xyz=centre + offset)
    for i in range(3):
        axes = [np.eye(3)[(i + k) % 3] for k in range(3)]
        points = [radius * a for a in axes]  # a point on each axis, relative to O
        chain = f"leg_{i + 1}"
        writer.link(f"{chain}_proximal", ("sphere", 0.01))
        writer.link(f"{chain}_distal", ("sphere", 0.01))
        writer.joint(f"{chain}_joint_base", "continuous", "base_link", f"{chain}_proximal", xyz=centre + points[0],
                     axis=axes[0])
        writer.joint(f"{chain}_joint_middle", "continuous", f"{chain}_proximal", f"{chain}_distal",
                     xyz=points[1] - points[0], axis=axes[1])
        writer.loop(f"{chain}_joint_platform", "revolute", chain, f"{chain}_distal", (points[2] - points[1], (0, 0, 0)),
                    "platform", (points[2] - offset, (0, 0, 0)), axis=axes[2])
        writer.transmission(f"{chain}_joint_base")
    if declared:
        writer.task_coordinates(("roll", "pitch", "yaw"))
    return writer.text()


@pytest.mark.parametrize("frame_offset", [(0.0, 0.0, 0.0), (0.03, -0.02, 0.05)])
def test_a_spherical_wrist_is_given_three_rotations_whatever_point_its_frame_is_at(frame_offset):
    """No <task_coordinates>: the motion space has no twist without rotation, so the task coordinates are the
    three rotations, not the translations of a frame origin off the centre; the indices equal the declared ones."""
    inferred = load_text(spherical_wrist_urdf(frame_offset=frame_offset, declared=False), "wrist.urdf")
    declared = load_text(spherical_wrist_urdf(frame_offset=frame_offset), "wrist.urdf")
    assert inferred.task_coordinates == ("roll", "pitch", "yaw") and inferred.task_source == "inferred"
    poses = declared.home_pose + np.deg2rad([[0.0, 0.0, 0.0], [10.0, -5.0, 15.0]])
    assert_indices_close(indices_at_poses(declared, poses), indices_at_poses(inferred, poses), 1e-12)


def three_leg_delta_with_a_turned_universal(turn: float) -> str:
    """The bundled Delta (robots/delta_4.urdf) with its fourth leg left out and leg 1's platform universal joint's
    second axis turned by ``turn`` rad: that leg no longer keeps the platform's orientation, which turns a little as
    it moves (no motion of the platform is a pure translation)."""
    text = bundled_path("delta_4").read_text(encoding="utf-8")
    text = re.sub(r'\s*<(link|joint|loop|transmission) name="leg_4[^"]*"(?:(?!</\1>).)*</\1>', "", text, flags=re.S)
    text = re.sub(r"\s*<named_pose [^>]*/>", "", text)
    turned = f'<axis2 xyz="{float(np.sin(turn))!r} 0 {float(np.cos(turn))!r}" />'
    return text.replace('<axis2 xyz="0 0 1.0000000000000002" />', turned, 1)


@pytest.mark.parametrize("unit", [1.0, 1e-3])
def test_a_delta_that_turns_a_little_as_it_moves_is_driven_in_x_y_z(unit):
    """Three legs of the bundled Delta, one universal joint's axis turned 0.15 rad: the platform turns as it moves
    (a pose 2 cm off its home in x turns it by more than 1e-3 rad), but every motion moves it more than it turns it
    (x, y, z tell its motions apart by 0.975 in length scales): its task coordinates are x, y, z, in metres and in
    millimetres. The rule took x, y, then a rotation (the motion space has two pure translations)."""
    text = three_leg_delta_with_a_turned_universal(0.15)
    mechanism = load_text(text if unit == 1.0 else in_unit(text, "mm", 1.0 / unit), "delta_3.urdf")
    assert mechanism.task_coordinates == ("x", "y", "z") and mechanism.task_source == "inferred"
    solution = solve(mechanism, mechanism.home_pose + np.array([[0.02 / unit, 0.0, 0.0]]))
    assert solution.reachable.all()
    angles = np.asarray(mechanism.pose_angular, dtype=bool)
    assert np.max(np.abs(solution.full_poses[0][angles] - mechanism.home_full_pose[angles])) > 1e-3


@pytest.mark.parametrize("turn", [0.0, 90.0, 33.0])
def test_the_translations_taken_are_the_same_motions_in_a_turned_world(turn):
    """A two-DOF motion space, a vertical translation and a motion mostly along one horizontal direction turning a
    little about the vertical, its world turned about the vertical: the task coordinates are the pair of translations
    that tells the motions apart best (x, z; y, z; or the better of them), not the first independent in x, y, z order,
    which took x, 0.01 independent, when the horizontal motion was along y, and then fell back to z and yaw."""
    rotation = Rotation.from_euler("z", turn, degrees=True).as_matrix()
    lift, swing = np.array([0, 0, 1.0, 0, 0, 0]), np.array([0.9, 0.01, 0.0, 0.0, 0.0, 0.43])
    motions = [np.concatenate([rotation @ motion[:3], rotation @ motion[3:]]) for motion in (lift, swing)]
    space, _ = np.linalg.qr(np.column_stack(motions))
    axes = choose_task_axes(space, np.array([False] * 3 + [True] * 3), 2)
    horizontal = rotation @ np.array([0.9, 0.01, 0.0])
    assert axes == (int(np.argmax(np.abs(horizontal[:2]))), 2)


def test_a_spherical_wrist_has_no_cti_and_says_why(tmp_path):
    """Every leg of a spherical wrist holds the same three constraint forces through its centre: no leg
    holds a constraint alone, so the CTI does not apply (rather than reading 0 at every pose)."""
    path = tmp_path / "spherical_wrist.urdf"
    path.write_text(spherical_wrist_urdf())
    mechanism = load_text(path.read_text(), str(path))
    assert mechanism.dof == 3 and mechanism.task_coordinates == ("roll", "pitch", "yaw")
    poses = mechanism.home_pose + np.deg2rad([[0.0, 0.0, 0.0], [10.0, -5.0, 15.0], [-20.0, 10.0, -25.0]])
    result = indices_at_poses(mechanism, poses, detail=True)
    assert result.reachable.all() and np.all(result.lmti > 0.0)
    assert np.isnan(result.cti).all() and result.constraint_count == 0
    assert result.cti_reason == "every chain holds the same 3 constraint wrenches (none is held by one chain alone)"
    completed = screwkit("analyze", path)
    assert completed.returncode == 0, completed.stderr
    assert "CTI  not applicable: every chain holds the same 3 constraint wrenches" in completed.stdout


def test_a_stretched_delta_in_the_batch_leaves_the_cti_of_the_other_poses_as_they_are_alone():
    """The constraint structure was planned from every sampled configuration, the Delta at the boundary of its
    workspace (every arm stretched, a constraint wrench more per chain) included: added to a batch, it set the CTI
    of every other pose to 0 (a sweep from the boundary printed cti 0 on every row). Now the plan reads the samples
    where every chain has its largest rank; each pose keeps the CTI it has alone, and the CTI agrees with the
    couple formula of docs/theory.md on the poses alone."""
    from screwkit.io.loader import load

    delta = load("delta_4")
    home = delta.home_pose
    poses = np.array([home, home + [0.0, 0.0, -0.2], home + [0.0, 0.0, -0.39017542510292885]])
    alone = [float(indices_at_poses(delta, pose[None], limits=False).cti[0]) for pose in poses[:2]]
    for pose, value in zip(poses[:2], alone):
        twists = [chain.twists[0] for chain in chain_screws(delta, solve(delta, pose[None], limits=False))]
        assert value == pytest.approx(delta_cti(twists), abs=1e-9)
    batch = indices_at_poses(delta, poses, limits=False)
    assert 0.4 < min(alone) and batch.cti[:2] == pytest.approx(alone, abs=1e-12)
    assert batch.lmti[2] == 0.0  # every arm stretched: singular
