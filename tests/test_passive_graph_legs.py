"""A passive leg in a closed-loop graph: the two-rod parallel ankle of MuJoCo humanoids (Digit's, Cassie-like).

The foot hangs from the shank on a passive universal joint; two cranks drive it through rods written as MuJoCo writes
them, a ``ball`` at the crank and a ``<connect>`` on the foot (``tests/rod_ankle.py``). Each rod then spins idly about
its own line, so the star reading (serial legs of 1-DoF joints) does not take it and the graph does
(:mod:`screwkit.io.graph`); but the graph took a leg with no actuator for "loops inside it and no actuators: exactly
one" and refused the file. The universal-joint leg is a passive leg: it constrains the foot (four constraint
wrenches), and is analysed as the star analyses a passive chain.

Checked against:

* the same ankle with each rod's ball written as two hinges (no idle spin), which the star reading takes: every
  actuator's ITI, the LMTI, the OTIs and F_O1 equal at the home pose and at poses about it;
* the rod lines, from Pinocchio's own forward kinematics of the configurations the graph solves: the actuation
  wrench of a crank-rod leg is the force along its rod, ITI_k = |f_k . v_C| / |v_C| at the crank's end, and OTI_k =
  |f_k . v_F| / |v_F| at the rod's foot anchor, v from the foot rotation about the ankle centre reciprocal to the
  other rod's force;
* the file in km and mm and in a moved world (the same indices), MuJoCo's own reading of it (the connects closed as
  drawn, the foot where Pinocchio puts it), and the command line.
"""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pinocchio as pin
import pytest
from rod_ankle import FOOT, rod_ankle_mjcf

from helpers import assert_indices_close, one_line_error, screwkit
from screwkit.io import graph_mechanism, read_closed_tree
from screwkit.io.loader import load
from screwkit.studies import indices_at_pose, indices_at_poses
from screwkit.studies.poses import graph_indices_at_poses

TOLERANCE = 1e-9
POSES = np.radians([[0.0, 0.0], [6.0, -4.0], [-8.0, 5.0], [3.0, 10.0], [-5.0, -9.0]])  # roll, pitch of the foot
OFFSET = (0.0, 0.002, -0.012)
"""The roll hinge's axis 12 mm below the pitch hinge's and 2 mm aside (a humanoid's ankle: the axes do not meet)."""
TOE_AXIS = np.array([0.3, 0.5, 0.81]) / np.linalg.norm([0.3, 0.5, 0.81])
TOE = np.array([0.01, 0.03, -0.03])  # the toe hinge's axis passes here, skew to the roll hinge's (x, through O)


def write(tmp_path, rods="ball", name="ankle.xml", **options):
    path = tmp_path / name
    path.write_text(rod_ankle_mjcf(rods, **options))
    return path


def graph_of(path):
    return graph_mechanism(read_closed_tree(path, output="foot"))


def test_the_universal_joint_leg_is_a_passive_leg_of_the_graph(tmp_path):
    graph = graph_of(write(tmp_path))
    assert [leg.name for leg in graph.legs] == ["crank_1", "crank_2", "cross"]
    assert [len(leg.actuators) for leg in graph.legs] == [1, 1, 0]
    assert graph.actuators == ("crank_1:motor_1", "crank_2:motor_2")
    assert graph.task_coordinates == ("roll", "pitch")
    assert [len(chain.twists) for chain in graph.chains] == [6, 6, 2]  # crank + the rod's 5; the foot's 2 rotations
    assert graph.report.motors == ["motor_1", "motor_2"]
    assert "leg(s) cross: no actuator, passive: each constrains the platform only" in graph.report.notes


def test_rods_on_balls_read_as_a_graph_equal_rods_on_two_hinges_read_as_serial_legs(tmp_path):
    graph = graph_of(write(tmp_path))
    serial = load(write(tmp_path, "hinges", "hinges.xml"), output="foot")
    assert serial.task_coordinates == graph.task_coordinates
    poses = serial.home_pose + POSES
    ours = graph_indices_at_poses(graph, graph.home_pose + POSES, detail=True)
    theirs = indices_at_poses(serial, poses, detail=True)
    assert np.all(ours.reachable) and np.all(theirs.reachable)
    for field in ("iti_actuators", "iti", "lmti", "oti_submechanisms"):
        np.testing.assert_allclose(getattr(ours, field), getattr(theirs, field), atol=TOLERANCE, err_msg=field)
    np.testing.assert_allclose(graph.indices().oti_actuators, serial_home_otis(serial), atol=TOLERANCE)
    np.testing.assert_array_equal(ours.f_o[1], 0.0)  # two actuators for two DoF: none may fail
    np.testing.assert_array_equal(theirs.f_o[1], 0.0)


def serial_home_otis(serial):
    from screwkit.studies import indices_at_pose

    return indices_at_pose(serial, serial.home_pose).oti_actuators


def _rod_line_indices(model, q):
    """ITI per actuator and OTI per actuator from the rod lines, Pinocchio's forward kinematics at q."""
    data = model.createData()
    pin.forwardKinematics(model, data, q)

    def origin(name):
        return data.oMi[model.getJointId(name)].translation.copy()

    def axis(name, local):
        return data.oMi[model.getJointId(name)].rotation @ np.array(local, dtype=float)

    centre = origin("roll")  # the universal joint's centre
    rotations = np.stack([axis("pitch", (0, 1, 0)), axis("roll", (1, 0, 0))])  # the foot's motion space
    foot = data.oMi[model.getJointId("roll")]
    anchors = [foot.act(np.asarray(point)) for point in FOOT]
    forces, itis = [], []
    for k, anchor in zip((1, 2), anchors):
        crank_end = origin(f"rod_{k}")
        force = (anchor - crank_end) / np.linalg.norm(anchor - crank_end)
        velocity = np.cross(axis(f"motor_{k}", (1, 0, 0)), crank_end - origin(f"motor_{k}"))
        forces.append(force)
        itis.append(abs(force @ velocity) / np.linalg.norm(velocity))
    otis = []
    for k in range(2):
        other = 1 - k
        # omega = rotations^T c, with f_other . (omega x (F_other - O)) = 0
        row = np.array([forces[other] @ np.cross(r, anchors[other] - centre) for r in rotations])
        omega = np.array([row[1], -row[0]]) @ rotations
        velocity = np.cross(omega, anchors[k] - centre)
        otis.append(abs(forces[k] @ velocity) / np.linalg.norm(velocity))
    return np.array(itis), np.array(otis)


def test_the_graph_s_indices_are_the_rod_lines(tmp_path):
    graph = graph_of(write(tmp_path))
    result, q = graph_indices_at_poses(graph, graph.home_pose + POSES, detail=True, configurations=True)
    for index in range(len(POSES)):
        itis, otis = _rod_line_indices(graph.tree.model, q[index])
        np.testing.assert_allclose(result.iti_actuators[index], itis, atol=TOLERANCE)
        if index == 0:  # the home pose: each actuator's OTI (a batch keeps the submechanisms' only)
            np.testing.assert_allclose(graph.indices().oti_actuators[0], otis, atol=TOLERANCE)
        assert result.lmti[index] == pytest.approx(otis.min(), abs=TOLERANCE)
        assert result.iti[index] == pytest.approx(itis.min(), abs=TOLERANCE)


@pytest.mark.parametrize("shape", ["as drawn", "roll hinge below", "toe hinge"])
@pytest.mark.parametrize("scale", [1e-3, 1e3])
def test_the_file_in_other_units_and_a_moved_world_gives_the_same_indices(tmp_path, scale, shape):
    """Also with the roll hinge below the pitch hinge (drawn 5 cm along its axis) and with a toe hinge after the
    universal joint, whose points the geometry decides."""
    options = {"as drawn": {}, "roll hinge below": {"roll_offset": OFFSET, "roll_drawn": 0.05},
               "toe hinge": {"cranks": 3, "toe": (TOE, TOE_AXIS)}}[shape]
    reference = graph_of(write(tmp_path, **options))
    turned = (f"{0.7 * scale!r} {-1.2 * scale!r} {2.5 * scale!r}", "0.8 0.3 -0.4 0.33")
    moved = graph_of(write(tmp_path, name="moved.xml", scale=scale, world=turned, **options))
    ours, theirs = reference.indices(), moved.indices()
    for field in ("iti_actuators", "iti", "lmti", "oti_actuators", "oti_submechanisms", "cti"):
        np.testing.assert_allclose(getattr(theirs, field), getattr(ours, field), atol=TOLERANCE, err_msg=field)
    assert moved.scale == pytest.approx(reference.scale * scale, rel=1e-12)


def test_mujoco_reads_the_file_closed_and_its_foot_where_pinocchio_has_it(tmp_path):
    mujoco = pytest.importorskip("mujoco")
    path = write(tmp_path)
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    assert model.neq == 2 and np.abs(data.efc_pos[:6]).max() < 1e-12  # both connects closed as drawn
    graph = graph_of(path)
    frames = graph.kinematics.transforms(graph.q[None])[0]
    foot = frames[graph.tree.model.getJointId("roll")]
    np.testing.assert_allclose(data.xpos[model.body("foot").id], foot[:3, 3], atol=1e-12)
    np.testing.assert_allclose(data.xmat[model.body("foot").id].reshape(3, 3), foot[:3, :3], atol=1e-12)


def test_the_command_analyses_the_ankle_and_refuses_a_graph_with_no_actuator(tmp_path):
    path = write(tmp_path)
    done = screwkit("analyze", path, "--output", "foot", "--json")
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)
    assert report["actuators"] == ["crank_1:motor_1", "crank_2:motor_2"]
    assert report["lmti"] == pytest.approx(graph_of(path).indices().lmti, abs=1e-12)
    bare = tmp_path / "bare.xml"
    bare.write_text(path.read_text().replace('<motor name="m1" joint="motor_1"/><motor name="m2" joint="motor_2"/>',
                                             ""))
    one_line_error(screwkit("analyze", bare, "--output", "foot"), "bare.xml: ", "nothing is actuated")
    tree = read_closed_tree(path, output="foot")
    with pytest.raises(ValueError, match=r"ankle\.xml: no leg has an actuator \(legs crank_1, crank_2, cross\): "
                                         r"--actuate names the driven joints\."):
        graph_mechanism(replace(tree, motors=[]))


def test_the_command_poses_the_ankle_by_its_task_coordinates(tmp_path):
    """``--pose roll pitch`` (the task coordinates ``info`` lists) closes the ankle there, the sole's position (a
    dependent coordinate) wherever the foot's turn puts it. ``--pose`` took the output frame's x y z [roll pitch yaw]
    only, and held the frame's position or its whole pose: a mechanism whose output frame moves along with its task
    coordinates (this sole; a Delta whose platform frame turns as it moves) reached no pose but the file's."""
    path = write(tmp_path)
    graph = graph_mechanism(read_closed_tree(path, output="sole"))
    assert graph.task_coordinates == ("roll", "pitch")
    target = graph.home_pose + np.radians([6.0, -4.0])
    done = screwkit("analyze", path, "--output", "sole", "--pose", " ".join(repr(float(v)) for v in np.degrees(target)),
                    "--json")
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)
    expected = graph_indices_at_poses(graph, target[None], detail=True)
    assert report["lmti"] == pytest.approx(float(expected.lmti[0]), abs=1e-12)
    assert report["iti"] == pytest.approx(float(expected.iti[0]), abs=1e-12)
    assert report["pose"] == pytest.approx(dict(zip(("roll", "pitch"), np.degrees(target))), abs=1e-9)
    moved = graph.solve(target[None])[0][0]
    sole = graph.frame_pose(moved)[:3]
    assert np.linalg.norm(sole - graph.frame_pose()[:3]) > 1e-3  # the sole moved: its position is no task coordinate
    one_line_error(screwkit("analyze", path, "--output", "sole", "--pose", "1 2 3 4"), "ankle.xml: ",
                   "--pose takes its task coordinates roll pitch (m, deg), or the output frame's x y z")
    home = dict(zip(("roll", "pitch"), np.degrees(graph.home_pose)))  # the foot drawn level: 0 and 0
    assert home == pytest.approx({"roll": 0.0, "pitch": 0.0}, abs=1e-9)
    one_line_error(screwkit("analyze", path, "--output", "sole", "--pose", "90 80"), "ankle.xml: no closed "
                   "configuration reached from the file's by continuation puts the output frame at (roll=90 deg, "
                   "pitch=80 deg); the file's configuration has it at (roll=0 deg, pitch=0 deg).")
    text = screwkit("analyze", path, "--output", "sole")  # the text names where the file's configuration is too
    assert text.returncode == 0, text.stderr
    assert text.stdout.splitlines()[0] == "ankle: 2 actuators, 2 DOF (no redundancy), at the file's configuration " \
                                          "(roll = 0, pitch = 0)"


def test_a_floating_ankle_names_its_free_joint_and_locked_there_is_the_fixed_one(tmp_path):
    """A humanoid's file floats its pelvis on an unnamed free joint: the whole robot is then one leg from the world
    with every actuator on it, refused with nothing to say how on (the free joint's name, Pinocchio's, appeared
    only after a wrong --lock). The refusal names it; locked, the ankle is the fixed one."""
    path = write(tmp_path, name="floating.xml", floating=True)
    refused = screwkit("info", path, "--output", "foot")
    message = one_line_error(refused, "floating.xml: leg 'shank' has loops inside it and 2 actuators",
                             "every actuator rides on the free joint")
    name = message.split("--lock ")[1].split()[0]
    held = graph_mechanism(read_closed_tree(path, output="foot", lock=(name,)))
    fixed = graph_of(write(tmp_path))
    for field in ("iti_actuators", "iti", "lmti", "oti_actuators", "cti"):
        np.testing.assert_allclose(getattr(held.indices(), field), getattr(fixed.indices(), field), atol=1e-12,
                                   err_msg=field)


def test_the_viewer_marks_the_failed_actuator_s_leg_not_the_passive_one(tmp_path):
    """The viewer took an actuator's index for its leg's: with the passive leg sorted first ('a_cross'), failing
    crank_1's motor drew the passive leg as failed and the crank as sound."""
    from screwkit.viewer.graph_drawing import graph_markers, solve_graph_frames

    path = tmp_path / "ankle.xml"
    path.write_text(rod_ankle_mjcf().replace('name="cross"', 'name="a_cross"'))
    graph = graph_of(path)
    assert [leg.name for leg in graph.legs] == ["a_cross", "crank_1", "crank_2"] and graph.actuator_legs == (1, 2)
    frames = solve_graph_frames(graph, graph.home_pose[None], 1e-6, True)
    for actuator, leg in ((0, 1), (1, 2)):
        marked = {(marker.chain, marker.kind) for marker in graph_markers(graph, frames, (actuator,))[0]
                  if marker.failed}
        assert {chain for chain, _ in marked} == {leg} and (leg, "failed_actuator") in marked, marked


def test_a_batch_checks_its_faults_against_the_actuators_not_the_legs(tmp_path):
    graph = graph_of(write(tmp_path))  # 2 actuators, 2 DoF, 3 legs
    with pytest.raises(ValueError, match=r"1\.\.a-n = 1\.\.0"):
        graph_indices_at_poses(graph, graph.home_pose[None], faults=[2])  # (F_O1 = 0 is allowed: j <= max(a-n, 1))


def test_with_a_redundant_crank_the_fault_indices_of_both_readings_agree(tmp_path):
    """Three cranks for two DoF (one redundant): with the passive leg among the chains, F_O1, F_IO1, the worst single
    fault and the CTI after a fault (F_C1) of the graph equal those of the serial reading at five poses."""
    graph = graph_of(write(tmp_path, cranks=3))
    serial = load(write(tmp_path, "hinges", "hinges.xml", cranks=3), output="foot")
    assert graph.dof == 2 and len(graph.actuators) == 3
    ours = graph_indices_at_poses(graph, graph.home_pose + POSES, detail=True)
    theirs = indices_at_poses(serial, serial.home_pose + POSES, detail=True)
    for field in ("iti_actuators", "lmti", "oti_submechanisms"):
        np.testing.assert_allclose(getattr(ours, field), getattr(theirs, field), atol=TOLERANCE, err_msg=field)
    np.testing.assert_allclose(ours.f_o[1], theirs.f_o[1], atol=TOLERANCE)
    np.testing.assert_allclose(ours.f_io[1], theirs.f_io[1], atol=TOLERANCE)
    assert np.all(ours.f_o[1] > 0.05)  # a fault is survivable here: the comparison is not of zeros
    np.testing.assert_array_equal(ours.worst_fault_indices[1], theirs.worst_fault_indices[1])


def test_a_closure_beyond_the_platform_on_a_ball_is_refused_naming_the_lock_that_holds_it(tmp_path):
    """Two platforms joined by a ball (a published nine-motor robot has one on each side of a central sphere): the
    second rod closed onto a toe that turns on a ball in the foot. The refusal names ``--lock`` on that ball; held
    where the file draws it, the toe moves with the foot, and the ankle's indices are those of the rod closed on the
    foot itself at the same point."""
    plain = tmp_path / "plain.xml"
    plain.write_text(rod_ankle_mjcf("hinges"))
    toed = tmp_path / "toe.xml"
    toed.write_text(rod_ankle_mjcf("hinges").replace(
        '<site name="sole"', '<body name="toe"><joint name="toe_ball" type="ball"/><geom type="sphere" size="0.01"/>'
        '</body><site name="sole"').replace('body1="foot" body2="rod_2"', 'body1="toe" body2="rod_2"'))
    refused = screwkit("info", toed, "--output", "foot")
    one_line_error(refused, "closure 'closure_2' (3d) ends on joints toe_ball beyond the platform",
                   "--lock toe_ball holds it where the file puts it, the bodies beyond moving with the platform")
    held = load(toed, output="foot", lock=("toe_ball",))
    expected = load(plain, output="foot")
    for pose in (expected.home_pose, expected.home_pose + np.radians([4.0, -3.0])):
        assert_indices_close(indices_at_pose(expected, pose), indices_at_pose(held, pose), atol=1e-12)



@pytest.mark.parametrize("drawn", [0.05, -0.03, 0.2])
def test_a_roll_hinge_below_the_pitch_hinge_gives_the_same_indices_wherever_drawn_along_its_axis(tmp_path, drawn):
    """The foot's roll hinge, whose axis passes the pitch hinge's without meeting it, is where their common
    perpendicular meets it, as a serial chain's canonical point: drawn 3 to 20 cm along its axis (MuJoCo: the same
    bodies at every configuration), the ankle has the same ITI, OTIs, LMTI and CTI at the file's configuration and at
    poses about it. Before, the hinge's drawn point was the passive leg's point on the foot, and the CTI of a
    published humanoid's ankle read 0.9332, 0.8923 or 0.8859 as its roll hinge was drawn 0, 5 or -3 cm along it.
    The ITI, OTIs and LMTI are those of the rods on two hinges, read as serial legs."""
    reference = graph_of(write(tmp_path, roll_offset=OFFSET))
    other = graph_of(write(tmp_path, name="drawn.xml", roll_offset=OFFSET, roll_drawn=drawn))
    ours = graph_indices_at_poses(reference, reference.home_pose + POSES, detail=True)
    theirs = graph_indices_at_poses(other, other.home_pose + POSES, detail=True)
    assert np.all(ours.reachable) and np.all(theirs.reachable)
    assert np.all(ours.cti > 0.1) and np.ptp(ours.cti) > 0.01  # neither vanishing nor constant over the poses
    for field in ("iti_actuators", "lmti", "oti_submechanisms", "cti"):
        np.testing.assert_allclose(getattr(theirs, field), getattr(ours, field), atol=TOLERANCE, err_msg=field)
    serial = load(write(tmp_path, "hinges", "hinges.xml", roll_offset=OFFSET, roll_drawn=drawn), output="foot")
    on_hinges = indices_at_poses(serial, serial.home_pose + POSES, detail=True)
    for field in ("iti_actuators", "lmti", "oti_submechanisms"):
        np.testing.assert_allclose(getattr(on_hinges, field), getattr(ours, field), atol=TOLERANCE, err_msg=field)


def test_mujoco_reads_the_roll_hinge_drawn_along_its_axis_as_the_same_mechanism(tmp_path):
    import mujoco

    sites = []
    for drawn in (0.0, 0.2):
        model = mujoco.MjModel.from_xml_string(rod_ankle_mjcf(roll_offset=OFFSET, roll_drawn=drawn))
        data = mujoco.MjData(model)
        placed = []
        for angles in np.radians([[0.0, 0.0], [7.0, -4.0], [-5.0, 9.0]]):
            data.qpos[:] = 0.0
            for joint, angle in (("roll", angles[0]), ("pitch", angles[1])):
                data.qpos[model.jnt_qposadr[model.joint(joint).id]] = angle
            mujoco.mj_kinematics(model, data)
            placed.append(data.site("sole").xpos.copy())
        sites.append(placed)
    np.testing.assert_allclose(sites[0], sites[1], atol=1e-15)
    assert not np.allclose(sites[0][0], sites[0][1])  # (the foot turns)




@pytest.mark.parametrize("drawn", [0.0, 0.1, -0.07])
def test_a_hinge_after_a_universal_joint_is_at_the_foot_of_the_perpendicular_from_its_centre(tmp_path, drawn):
    """The foot on a third hinge after the pitch-roll universal joint (three cranks): the passive leg's point on the
    foot is the toe hinge's, at the foot on its axis of the perpendicular from the universal joint's centre O, as the
    serial canonical points place it (:func:`screwkit.closure.canonical.offsets_along_axes` on the leg's three
    lines), not the foot of its common perpendicular with the roll hinge's axis (3.2 mm away here); drawn elsewhere
    along its axis, the same point and the same indices."""
    from screwkit.closure.canonical import offsets_along_axes

    reference = graph_of(write(tmp_path, cranks=3, toe=(TOE, TOE_AXIS)))
    other = graph_of(write(tmp_path, name="drawn.xml", cranks=3, toe=(TOE + drawn * TOE_AXIS, TOE_AXIS)))
    lines = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], TOE_AXIS]), np.array([np.zeros(3), np.zeros(3), TOE])
    canonical = TOE + offsets_along_axes((False, False, False), *lines)[2] * TOE_AXIS
    expected = TOE - (TOE @ TOE_AXIS) * TOE_AXIS  # the foot from O = (0, 0, 0)
    np.testing.assert_allclose(canonical, expected, atol=1e-12)
    for graph in (reference, other):
        assert [leg.name for leg in graph.legs][-1] == "cross" and graph.dof == 3
        np.testing.assert_allclose(graph.chains[-1].points, np.broadcast_to(expected, (3, 3)), atol=1e-12)
    ours, theirs = reference.indices(), other.indices()
    for field in ("iti_actuators", "oti_actuators", "lmti", "cti"):
        np.testing.assert_allclose(getattr(theirs, field), getattr(ours, field), atol=TOLERANCE, err_msg=field)
