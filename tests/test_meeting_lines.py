"""Axes that a file's rounding leaves missing the point they meet at meet again, and a spherical leg's actuation
wrench is the couple normal to its passive axes.

A spherical 3-RRR manipulator (every joint axis through one centre) exported from CAD comes with its axes missing
the centre by a few tenths of a micrometre. Read exactly, its constraint forces no longer pass through one point, and
the three rotations read as one DOF (or none): ``screwkit.io.rounding.meeting_lines`` makes them meet. The checks
here are independent of the code under test: the mobility and indices of the same manipulator written exactly, the
classical transmission index of a spherical leg (the triple product of its axes), and MuJoCo's own reading of the
file (its bodies' places at the file's joint values).
"""

from __future__ import annotations

import json
from itertools import combinations, permutations
from pathlib import Path

import mujoco
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from helpers import screwkit
from screwkit.closure import solve
from screwkit.io.loader import load
from screwkit.io.rounding import left_as_written, meeting_lines, turned_joint
from screwkit.studies import indices_at_pose, indices_at_poses

CENTRE = np.array([0.0, 0.0, 0.3])
RADIUS, BALL = 0.05, 0.03


def _unit(vector) -> np.ndarray:
    vector = np.asarray(vector, dtype=float)
    return vector / np.linalg.norm(vector)


def spm_axes() -> tuple[list, list, list]:
    """Motor axes u, middle axes v = u x w and platform axes w of a 3-RRR spherical manipulator at its drawn
    configuration (three legs 120 degrees apart, motors 55 degrees off the downward vertical)."""
    beta = np.radians(55.0)
    u = [np.array([np.sin(beta) * np.cos(a), np.sin(beta) * np.sin(a), -np.cos(beta)])
         for a in np.radians([0, 120, 240])]
    w = [np.array([np.sin(0.6) * np.cos(a + 0.3), np.sin(0.6) * np.sin(a + 0.3), np.cos(0.6)])
         for a in np.radians([0, 120, 240])]
    v = [_unit(np.cross(a, b)) for a, b in zip(u, w)]
    return u, v, w


def _xyz(vector) -> str:
    return " ".join(repr(float(x)) for x in vector)


def spm_mjcf(rounding: float = 0.0, seed: int = 0, drawn: float = 0.0, unit: float = 1.0, turn=None) -> str:
    """The manipulator in MJCF, every body unturned (axes in world directions): leg 2 carries the platform on its
    third hinge, legs 1 and 3 end on a ``<connect>`` (a ball) at a point of their platform axis; motors on the three
    base hinges. Each hinge axis passes off the centre by a random ``rounding`` (m, perpendicular to the axis), as a
    CAD export rounds it; ``drawn``: each hinge drawn up to that far (m) along its axis (the same lines). The whole
    mechanism turned by ``turn`` (3 x 3) about the world's origin and written in units of 1 / ``unit`` m (1000: mm),
    with the same rounding (scaled)."""
    rng = np.random.default_rng(seed)
    turn = np.eye(3) if turn is None else np.asarray(turn, dtype=float)
    u, v, w = ([turn @ axis for axis in axes] for axes in spm_axes())
    centre, radius, ball = unit * (turn @ CENTRE), unit * RADIUS, unit * BALL
    rounding, drawn = unit * rounding, unit * drawn

    def line(axis) -> np.ndarray:  # a point of the axis: off the centre by the rounding, along it by the drawing
        off = turn @ rng.normal(size=3)  # turned with the mechanism: the same rounding in any world frame
        off -= (off @ axis) * axis
        return centre + radius * axis + rounding * _unit(off) + drawn * rng.uniform(-1, 1) * axis

    def hinge(name, point, axis, origin) -> str:
        return f'<joint name="{name}" type="hinge" pos="{_xyz(point - origin)}" axis="{_xyz(axis)}"/>'

    bodies = []
    for i in range(3):
        pu, pv = line(u[i]), line(v[i])
        leg = (f'<body name="motor{i + 1}" pos="{_xyz(pu)}">{hinge(f"m{i + 1}", pu, u[i], pu)}'
               f'<geom type="sphere" size="0.005"/>'
               f'<body name="middle{i + 1}" pos="{_xyz(pv - pu)}">{hinge(f"p{i + 1}", pv, v[i], pv)}'
               f'<geom type="sphere" size="0.005"/>')
        if i == 1:
            pw = line(w[i])
            leg += (f'<body name="platform" pos="{_xyz(pw - pv)}">{hinge("q2", pw, w[i], pw)}'
                    f'<geom type="sphere" size="0.01"/><site name="effector" pos="{_xyz(centre - pw)}"/></body>')
        leg += "</body></body>"
        bodies.append(leg)
    connects = [(i, centre + ball * w[i]) for i in (0, 2)]  # each ball's centre on the platform axis w_i
    text = ('<mujoco model="spm"><worldbody>' + "".join(bodies) + "</worldbody><equality>"
            + "".join(f'<connect name="ball{i + 1}" body1="middle{i + 1}" body2="platform" anchor="ANCHOR{i}"/>'
                      for i, _ in connects)
            + '</equality><actuator>' + "".join(f'<motor joint="m{i + 1}"/>' for i in range(3))
            + "</actuator></mujoco>")
    model = mujoco.MjModel.from_xml_string(text.replace("ANCHOR0", "0 0 0").replace("ANCHOR2", "0 0 0"))
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    for i, point in connects:  # the anchor: the ball's centre in the middle body's frame, as MuJoCo places it
        body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, f"middle{i + 1}")
        text = text.replace(f"ANCHOR{i}", _xyz(data.xmat[body].reshape(3, 3).T @ (point - data.xpos[body])))
    return text


def written(tmp_path: Path, text: str, name: str) -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def test_the_synthetic_file_is_the_manipulator_mujoco_reads():
    """MuJoCo's own reading of the exact file: every hinge axis passes through the centre, the balls close at the
    file's joint values, and the platform's site is the centre."""
    model = mujoco.MjModel.from_xml_string(spm_mjcf())
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    for joint in range(model.njnt):
        body = model.jnt_bodyid[joint]
        point = data.xpos[body] + data.xmat[body].reshape(3, 3) @ model.jnt_pos[joint]
        axis = data.xmat[body].reshape(3, 3) @ model.jnt_axis[joint]
        assert np.linalg.norm(np.cross(point - CENTRE, axis)) < 1e-12
    platform = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "platform")
    for k in range(model.neq):
        body = model.eq_obj1id[k]
        ball = data.xpos[body] + data.xmat[body].reshape(3, 3) @ model.eq_data[k][:3]
        own = data.xpos[platform] + data.xmat[platform].reshape(3, 3) @ model.eq_data[k][3:6]
        assert np.linalg.norm(ball - own) < 1e-12
    np.testing.assert_allclose(data.site_xpos[0], CENTRE, atol=1e-12)


def poses_about(mechanism) -> np.ndarray:
    return mechanism.home_pose + np.deg2rad([[0.0, 0.0, 0.0], [8.0, -5.0, 6.0], [-6.0, 4.0, -9.0]])


@pytest.mark.parametrize("rounding, seed", [(1e-7, 0), (2e-7, 1), (3e-7, 2)])
def test_a_manipulator_whose_axes_miss_their_centre_by_rounding_has_three_dof_and_the_exact_ones_indices(
        tmp_path, rounding, seed):
    """Axes off the centre by 0.1-0.3 um (as Rhoban's exported manipulator's, up to 0.34 um on links of 5 cm): three
    rotations, as the exact file, and its indices to the rounding's order; the report says what was moved."""
    exact = load(written(tmp_path, spm_mjcf(), "exact.xml"))
    rounded = load(written(tmp_path, spm_mjcf(rounding, seed), "rounded.xml"))
    assert exact.dof == rounded.dof == 3 and rounded.task_coordinates == exact.task_coordinates
    assert any("written through one point" in note for note in rounded.import_report)
    assert not any("written through one point" in note for note in exact.import_report)
    poses = poses_about(exact)
    first, second = indices_at_poses(exact, poses), indices_at_poses(rounded, poses)
    assert first.reachable.all() and second.reachable.all()
    for name in ("iti", "lmti"):
        np.testing.assert_allclose(getattr(second, name), getattr(first, name), atol=1e-4)


def triple_product(axes: np.ndarray) -> float:
    """The transmission index of a spherical R-R-R leg's first joint: the cosine between its axis and the normal
    to the two passive axes, |u . (v x w)| / |v x w| (the couple the passive joints let through)."""
    normal = np.cross(axes[1], axes[2])
    return float(abs(axes[0] @ normal) / np.linalg.norm(normal))


@pytest.mark.parametrize("drawn", [0.0, 0.02])
def test_the_spherical_leg_transmits_the_couple_normal_to_its_passive_axes_however_its_hinges_are_drawn(
        tmp_path, drawn):
    """Leg 2 (R-R-R, every axis through the centre, the platform on its third hinge): its ITI is the triple product
    of its axes at each pose, with the hinges drawn at the radius or anywhere up to 2 cm along their axes; before,
    the actuation wrench was a force through the last hinge's drawn point (0.82 and 0.72 for 0.99 here)."""
    mechanism = load(written(tmp_path, spm_mjcf(drawn=drawn, seed=3), "spm.xml"))
    leg = next(index for index, chain in enumerate(mechanism.chains) if chain.loop_type == "fixed")
    poses = poses_about(mechanism)
    solution = solve(mechanism, poses)
    result = indices_at_poses(mechanism, poses, detail=True)
    actuator = [index for index, (chain, _) in enumerate(mechanism.actuator_positions()) if chain == leg]
    assert len(actuator) == 1
    expected = [triple_product(solution.joint_axes[leg][pose]) for pose in range(len(poses))]
    np.testing.assert_allclose(result.iti_actuators[:, actuator[0]], expected, atol=1e-9)


def test_lines_meeting_to_rounding_are_moved_onto_one_point_in_any_order():
    """Five lines through a point, each moved off it perpendicular to itself by up to 1e-6 of a unit length: moves
    perpendicular to each line that make all five pass through one point, the same whatever the order of the lines;
    two lines alone, or lines missing by more than the tolerance, are left as written."""
    rng = np.random.default_rng(7)
    units = np.array([_unit(rng.normal(size=3)) for _ in range(5)])
    offsets = rng.normal(size=(5, 3)) * 1e-6
    offsets -= np.sum(offsets * units, axis=1, keepdims=True) * units
    points = np.array([1.0, 2.0, 3.0]) + offsets + rng.uniform(-1, 1, (5, 1)) * units
    moves, largest, left = meeting_lines(points, units, 1.0)
    assert left == []
    np.testing.assert_allclose(np.sum(moves * units, axis=1), 0.0, atol=1e-15)
    moved = points + moves
    projections = np.eye(3)[None] - np.einsum("ki,kj->kij", units, units)
    meet = np.linalg.solve(projections.sum(axis=0), np.einsum("kij,kj->i", projections, moved))
    for point, unit in zip(moved, units):
        assert np.linalg.norm(np.cross(point - meet, unit)) < 1e-13
    assert largest == pytest.approx(np.max(np.linalg.norm(moves, axis=1)))
    assert 0.0 < largest < 1e-5
    for order in list(permutations(range(5)))[::17]:
        again, _, _ = meeting_lines(points[list(order)], units[list(order)], 1.0)
        np.testing.assert_allclose(again, moves[list(order)], atol=1e-15)
    assert not np.any(meeting_lines(points[:2], units[:2], 1.0)[0])
    assert not np.any(meeting_lines(points, units, 1e-3)[0])  # 1e-6 off on a length of 1e-3: not rounding


@pytest.mark.parametrize("rounding", [0.0, 3e-7])
def test_the_axes_written_meet_exactly(tmp_path, rounding):
    """Every hinge axis of the loaded manipulator (the balls' own frame axes aside) passes through one point to
    1e-12 of its length scale, rounded file or exact; the exact one is left as written (no note)."""
    mechanism = load(written(tmp_path, spm_mjcf(rounding, seed=4), "spm.xml"))
    solution = solve(mechanism, poses_about(mechanism))
    for pose in range(3):
        axes, points = [], []
        for chain, chain_axes, chain_points in zip(mechanism.chains, solution.joint_axes, solution.joint_points):
            count = chain.geometry.n_tree_joints  # a ball loop's DoFs are its frame's axes, not hinges
            axes += list(chain_axes[pose][:count])
            points += list(chain_points[pose][:count])
        projections = np.eye(3)[None] - np.einsum("ki,kj->kij", axes, axes)
        centre = np.linalg.lstsq(projections.sum(axis=0), np.einsum("kij,kj->i", projections, points), rcond=None)[0]
        misses = np.linalg.norm(np.einsum("kij,kj->ki", projections, np.array(points) - centre), axis=1)
        assert len(axes) == 7 and misses.max() < 1e-12 * mechanism.length_scale
    moved = any("written through one point" in note for note in mechanism.import_report)
    assert moved == (rounding > 0.0)


def test_analyze_reads_the_rounded_manipulator_as_three_rotations_on_the_command_line(tmp_path):
    """``screwkit analyze`` as a user runs it on the rounded file: three DOF, the motors' ITIs those of the exact
    file to the rounding's order, and the report line that says the axes were moved."""
    exact = load(written(tmp_path, spm_mjcf(), "exact.xml"))
    expected = indices_at_poses(exact, exact.home_pose[None], detail=True)
    path = written(tmp_path, spm_mjcf(3e-7, 5), "spm.xml")
    run = screwkit("analyze", path, "--pose", *(repr(float(x)) for x in exact.home_pose), "--json")
    assert run.returncode == 0, run.stderr
    found = json.loads(run.stdout)
    assert found["dof"] == 3
    np.testing.assert_allclose(list(found["iti_actuators"].values()), expected.iti_actuators[0], atol=1e-4)
    text = screwkit("analyze", path)
    assert text.returncode == 0 and "3 DOF (no redundancy)" in text.stdout
    assert "joint axes that meet to the file's rounding written through one point" in text.stderr


def _through(centre, count, off, rng, spread=1.0):
    """``count`` lines through ``centre`` in random directions, each moved off it by ``off`` perpendicular to
    itself and drawn anywhere up to ``spread`` along itself."""
    units = np.array([_unit(rng.normal(size=3)) for _ in range(count)])
    offsets = rng.normal(size=(count, 3))
    offsets -= np.sum(offsets * units, axis=1, keepdims=True) * units
    offsets *= off / np.linalg.norm(offsets, axis=1, keepdims=True)
    return centre + offsets + rng.uniform(-spread, spread, (count, 1)) * units, units


def test_a_group_one_of_whose_lines_meets_another_elsewhere_is_left_as_written_and_said():
    """A universal joint (two lines meeting exactly at X) whose first axis also passes within the rounding of the
    point where two other lines meet (a coincidence of a symmetric design: Reachy Mini's leg 2 hinge passes 0.48 um
    from leg 1's universal joint): moving that axis onto the point would part the universal joint, so nothing moves
    and the group is returned with the line that meets another elsewhere. The same for a rounded spherical group one
    of whose lines also carries a universal joint elsewhere: left, and said (the report names them)."""
    x, first, second = np.array([0.2, 0.0, 0.0]), np.array([1.0, 0.0, 0.0]), _unit([0.0, 1.0, 0.3])
    crossing = np.array([0.0, 6e-6, 0.0])  # the first axis (y = 0) passes 6e-6 from it
    points = np.array([x, x, crossing, crossing])
    units = np.array([first, second, _unit([0.0, 1.0, 1.0]), _unit([0.3, -1.0, 1.0])])
    moves, largest, left = meeting_lines(points, units, 1.0)
    assert not np.any(moves) and largest == 0.0
    assert len(left) == 1 and sorted(left[0][0].tolist()) == [0, 2, 3] and left[0][1:] == (0, 1)
    rng = np.random.default_rng(9)
    centre = np.array([0.0, 0.0, 0.3])
    points, units = _through(centre, 9, 3e-7, rng, spread=0.05)
    assert np.max(np.linalg.norm(meeting_lines(points, units, 0.05)[0], axis=1)) > 1e-7  # alone: moved
    elsewhere = points[0] + 0.2 * units[0]
    extra = np.array([_unit(np.cross(units[0], [1.0, 0.0, 0.0])), _unit([1.0, 0.3, 0.2])])
    moves, largest, left = meeting_lines(np.vstack([points, [elsewhere, elsewhere]]), np.vstack([units, extra]), 0.05)
    assert not np.any(moves) and [(sorted(lines.tolist()), line) for lines, line, _ in left] == [(list(range(9)), 0)]


def test_many_lines_through_one_point_are_one_group():
    """Sixty lines through one point, rounded: one group, every line moved onto the point."""
    points, units = _through(np.zeros(3), 60, 2e-6, np.random.default_rng(11))
    moves, largest, left = meeting_lines(points, units, 1.0)
    moved = points + moves
    projections = np.eye(3)[None] - np.einsum("ki,kj->kij", units, units)
    meet = np.linalg.solve(projections.sum(axis=0), np.einsum("kij,kj->i", projections, moved))
    assert left == [] and np.max(np.linalg.norm(np.cross(moved - meet, units), axis=1)) < 1e-13


def test_the_otis_are_those_of_the_output_twists_with_the_other_motors_locked(tmp_path):
    """The platform turns about the centre O; each motor transmits a moment about O: leg 2's couple n (normal to
    its passive axes), legs 1 and 3 a force f through their ball centre C, crossing the passive axis and normal to
    OC (the force along OC is a constraint), moment (C - O) x f. Locking two motors leaves the rotation normal to
    their moments; the OTI is the power coefficient on it: |n . w| for the couple, |f . v_C| / |v_C| for a force
    (v_C = w x (C - O)). With the hinges drawn up to 2 cm along their axes."""
    mechanism = load(written(tmp_path, spm_mjcf(drawn=0.02, seed=6), "spm.xml"))
    poses = poses_about(mechanism)
    solution = solve(mechanism, poses)
    for pose in range(len(poses)):
        otis = indices_at_pose(mechanism, poses[pose]).oti_actuators
        assert otis.shape == (1, 3)
        moments, forces = [], []
        for chain, joint in mechanism.actuator_positions():
            axes, points = solution.joint_axes[chain][pose], solution.joint_points[chain][pose]
            if mechanism.chains[chain].loop_type == "fixed":
                moments.append(_unit(np.cross(axes[joint + 1], axes[joint + 2])))
                forces.append(None)
                continue
            radius = points[-1] - CENTRE  # the ball's DoFs sit at its centre
            passive = axes[joint + 1]
            force = _unit(passive - (passive @ _unit(radius)) * _unit(radius))
            moments.append(np.cross(radius, force))
            forces.append((force, radius))
        for k in range(3):
            omega = _unit(np.cross(*[moments[j] for j in range(3) if j != k]))
            if forces[k] is None:
                expected = abs(moments[k] @ omega)
            else:
                velocity = np.cross(omega, forces[k][1])
                expected = abs(forces[k][0] @ velocity) / np.linalg.norm(velocity)
            assert otis[0, k] == pytest.approx(expected, abs=1e-9)


@pytest.mark.parametrize("unit, turned", [(1e3, False), (1e-3, False), (1.0, True), (1e3, True)])
def test_the_rounded_manipulator_in_another_unit_or_world_frame_reads_the_same(tmp_path, unit, turned):
    """The rounded file in millimetres (or kilometres), or turned in the world: the axes met at the same rounding
    relative to its size, three DOF, and the metre file's indices at home; in another unit at poses too."""
    turn = Rotation.from_rotvec([0.4, -1.1, 0.7]).as_matrix() if turned else None
    metres = load(written(tmp_path, spm_mjcf(3e-7, 8), "metres.xml"))
    other = load(written(tmp_path, spm_mjcf(3e-7, 8, unit=unit, turn=turn), "other.xml"))
    assert other.dof == 3 and any("written through one point" in note for note in other.import_report)
    poses = poses_about(metres)[:1] if turned else poses_about(metres)
    first = indices_at_poses(metres, poses, detail=True)
    second = indices_at_poses(other, poses, detail=True)
    for name in ("iti_actuators", "lmti", "cti"):
        np.testing.assert_allclose(getattr(second, name), getattr(first, name), atol=1e-9)


@pytest.mark.parametrize("kind", ["revolute", "prismatic"])
def test_a_turned_axis_keeps_every_frame_where_the_assembly_put_it(kind):
    """An axis made parallel to its neighbours' (``parallel_axes``) turns by up to 1e-5 rad; written with the joint's
    placement unchanged, its frame at the assembly's joint value would turn (a revolute) or shift (a slide) by the
    turn times that value, and open the loops the assembly closed (a spherical manipulator's own home then missed its
    closure by 3.5e-11, beyond Newton's tolerance). The frame at that value is the file's, by scipy's rotations."""
    rng = np.random.default_rng(12)
    placement = np.eye(4)
    placement[:3, :3] = Rotation.from_rotvec(rng.normal(size=3)).as_matrix()
    placement[:3, 3] = rng.normal(size=3)
    axis = _unit(rng.normal(size=3))
    turned = _unit(axis + 3e-6 * rng.normal(size=3))
    value = 0.7

    def motion(direction):
        moved = np.eye(4)
        if kind == "revolute":
            moved[:3, :3] = Rotation.from_rotvec(value * direction).as_matrix()
        else:
            moved[:3, 3] = value * direction
        return moved

    kept, written = turned_joint(placement, kind, axis, turned, value)
    np.testing.assert_array_equal(written, turned)
    np.testing.assert_allclose(kept @ motion(turned), placement @ motion(axis), atol=1e-15)
    assert np.max(np.abs(placement @ motion(turned) - placement @ motion(axis))) > 1e-6  # unturned placement moves it
    again, same = turned_joint(placement, kind, axis, axis, value)  # an axis not turned: the placement as written
    assert again is placement and same is axis
    assert turned_joint(placement, kind, axis, None, value) == (placement, axis)


def _miss(points, units, lines) -> float:
    """The largest distance of ``lines`` from the point nearest to them all (least squares)."""
    projections = np.eye(3)[None] - np.einsum("ki,kj->kij", units[lines], units[lines])
    meet = np.linalg.lstsq(projections.sum(axis=0), np.einsum("kij,kj->i", projections, points[lines]), rcond=None)[0]
    return float(np.max(np.linalg.norm(np.einsum("kij,kj->ki", projections, points[lines] - meet), axis=1)))


def test_any_lines_near_one_point_are_grouped_without_failing_and_lines_far_off_do_not_block():
    """Four to eight lines passing up to 1.3 tolerances from one or two points a few tolerances apart, 4000 times:
    no failure (groups inside groups were one of them), and every moved group meets. A line meeting a group's line
    exactly only far from the mechanism (10 scales away, in one plane by symmetry) is no universal joint there: the
    group is still moved."""
    rng = np.random.default_rng(0)
    for _ in range(4000):
        count = int(rng.integers(4, 9))
        units = np.array([_unit(rng.normal(size=3)) for _ in range(count)])
        offsets = rng.normal(size=(count, 3))
        offsets -= np.sum(offsets * units, axis=1, keepdims=True) * units
        offsets *= rng.uniform(0.0, 1.3e-5, (count, 1)) / np.linalg.norm(offsets, axis=1, keepdims=True)
        centres = np.where(rng.random((count, 1)) < 0.4, rng.normal(size=3) * rng.uniform(0.0, 3e-5), 0.0)
        points = centres + offsets + rng.uniform(-1.0, 1.0, (count, 1)) * units
        moves, largest, left = meeting_lines(points, units, 1.0)
        moved = np.flatnonzero(np.any(moves != 0.0, axis=1))
        for line in moved:  # each moved line meets two other moved lines at one point (its group's)
            assert any(_miss(points + moves, units, [line, one, other]) < 1e-12
                       for one, other in combinations([k for k in moved if k != line], 2))
        assert largest <= 1e-5 and all(len(lines) >= 3 for lines, _, _ in left)
    units = np.array([[1.0, 0.0, 0.0], _unit([0.0, 1.0, 1.0]), _unit([0.0, 1.0, -1.0])])
    points = np.array([[0.0, 2e-7, 0.0], [1e-7, 0.0, 0.0], [-1e-7, 0.0, 0.0]])
    alone = meeting_lines(points, units, 1.0)
    far = meeting_lines(np.vstack([points, [10.0, 0.0, 0.0]]), np.vstack([units, _unit([1.0, 1.0, 0.0])]), 1.0)
    assert alone[1] > 1e-7 and far[1] == alone[1] and far[2] == []


def relabelled(text: str) -> tuple[str, dict[str, str]]:
    """The file with its legs, closures and motors listed in reverse order and every joint renamed; the names'
    map (old -> new)."""
    names = {old: f"joint_{chr(ord('z') - k)}" for k, old in enumerate(["m1", "p1", "m2", "p2", "q2", "m3", "p3"])}
    for old, new in names.items():
        text = text.replace(f'name="{old}"', f'name="{new}"').replace(f'joint="{old}"', f'joint="{new}"')
    head, rest = text.split("<worldbody>")
    world, tail = rest.split("</worldbody>")
    legs = ['<body name="motor' + part for part in world.split('<body name="motor')[1:]]
    equality, actuators = tail.split("<equality>")[1].split("</equality>")[0], tail.split("<actuator>")[1].split(
        "</actuator>")[0]
    reverse = lambda block, tag: "".join(f"<{tag}" + part for part in reversed(block.split(f"<{tag}")[1:]))  # noqa: E731
    return (head + "<worldbody>" + "".join(reversed(legs)) + "</worldbody><equality>" + reverse(equality, "connect")
            + "</equality><actuator>" + reverse(actuators, "motor") + "</actuator></mujoco>"), names


def test_the_rounded_manipulator_relabelled_has_the_same_indices_actuator_by_actuator(tmp_path):
    """Legs, closures and motors listed in reverse and every joint renamed (so the tree, the chains and the
    actuators come in another order): three DOF, the same home, and each motor's ITI, the LMTI and the CTI of the
    file as written; MuJoCo reads both as the same bodies' places."""
    text = spm_mjcf(3e-7, 10)
    other_text, names = relabelled(text)
    for one in (text, other_text):
        model = mujoco.MjModel.from_xml_string(one)
        assert model.neq == 2 and model.nu == 3 and model.njnt == 7
    first = load(written(tmp_path, text, "spm.xml"))
    second = load(written(tmp_path, other_text, "relabelled.xml"))
    assert second.dof == 3 and [a.split(":")[1] for a in second.actuator_names] != [
        names[a.split(":")[1]] for a in first.actuator_names]  # another order indeed
    np.testing.assert_allclose(second.home_pose, first.home_pose, atol=1e-9)
    poses = poses_about(first)
    one, two = indices_at_poses(first, poses, detail=True), indices_at_poses(second, poses, detail=True)
    order = [[a.split(":")[1] for a in second.actuator_names].index(names[a.split(":")[1]])
             for a in first.actuator_names]
    np.testing.assert_allclose(two.iti_actuators[:, order], one.iti_actuators, atol=1e-9)
    for name in ("lmti", "cti"):
        np.testing.assert_allclose(getattr(two, name), getattr(one, name), atol=1e-9)


def test_many_groups_left_as_written_are_counted_not_each_named():
    """Four groups of three lines through a point (to 1e-7), each with a line that another line meets exactly
    elsewhere (a universal joint on it): all four are left as written, and the report names two and counts the
    others (a CAD Stewart platform's base, its hinges all in one plane, made twelve such notes)."""
    rng = np.random.default_rng(3)
    points, units, names = [], [], []
    for group in range(4):
        centre = np.array([1.0 * group, 0.0, 0.0])
        for line in range(3):
            unit = _unit(rng.normal(size=3))
            offset = rng.normal(size=3) * 1e-7
            points.append(centre + offset - (offset @ unit) * unit)
            units.append(unit)
            names.append(f"g{group}_{line}")
        elsewhere = points[-3] + 0.3 * units[-3]  # on the group's first line, away from its centre
        points.append(elsewhere)
        units.append(_unit(np.cross(units[-3], rng.normal(size=3))))
        names.append(f"u{group}")
    _, _, left = meeting_lines(np.array(points), np.array(units), 1.0)
    assert len(left) == 4
    notes = left_as_written(left, names)
    assert len(notes) == 3 and notes[-1].startswith("and 2 more group(s)")
    assert all("left as written" in note and "also meets" in note for note in notes[:2])
    assert left_as_written(left[:2], names) == notes[:2]
