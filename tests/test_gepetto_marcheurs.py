"""Walking robots' legs and a two-legged effector from Gepetto's example-parallel-robots
(``tests/data/gallery/published``, BSD-3-Clause; files since removed from that repository's tree), the legs with
their hip and knee held (``--lock``).

* ``robot_marcheur_3``: the foot turns on a pin at the end of the shin, driven by a crank on the shin and a rod with
  a ball at each end. The platform hangs on the base (the shin) by that one pin: a passive leg of one joint, which
  was refused as "a leg without links". Its ITI and OTI are the rod line's, on Gepetto's own reading of the file
  (``tests/gepetto_loader.py``) closed by scipy: the rod carries one force, along the line through its two balls;
  ITI = |f . v| / |v| at the crank's ball, v its velocity when the crank turns, OTI = |f . v| / |v| at the foot's
  ball, v its velocity when the foot turns on its pin.
* ``robot_marcheur_2``: an ankle ball driven by a crank and rod, a foot motor on it. Holding the crank's motor and
  the ankle (which a refusal once advised) leaves the foot on its motor alone: a traceback (``IndexError`` in
  the conversion); now one line, and the advice is no longer given.
* ``robot_ludo`` with its effector's pin held: a slide that carries the effector itself, refused in one line.
"""

from __future__ import annotations

import numpy as np
import pytest
import yaml
from gepetto_loader import gepetto_model
from rod_lines import closed_by_scipy, joint_line
from test_axis_points import revolutes_moved
from test_gallery_published import GEPETTO
from test_gepetto_joint_types import variants

from helpers import one_line_error, screwkit
from screwkit.io import graph_mechanism, read_closed_tree

ANKLE = GEPETTO / "robot_marcheur_3" / "robot.urdf"
ANKLE_LOCKS = ("mot_hanche1", "mot_hanche2", "mot_cuisse", "mot_genoux", "libre_genoux")
CRANK, CRANK_BALL, FOOT_PIN, FOOT_BALL = "mot_cheville", "to_rotule_free_molet", "libre_cheville", "to_rotule_free_pied"
BALL_ANKLE = GEPETTO / "robot_marcheur_2" / "robot.urdf"
BALL_ANKLE_LOCKS = ("mot_hanche1_droite", "mot_hanche2_droit", "mot_hanche3_droite", "mot_genoux_droite")


def ankle(path, **options):
    """screwkit's indices of robot_marcheur_3's ankle at the file's configuration, the crank's value and the value
    the knee is held at (where its loop closes)."""
    graph = graph_mechanism(read_closed_tree(path, output="foot_2", lock=ANKLE_LOCKS, **options))
    result = graph.indices()
    crank = next(value for name, value in result.joint_values.items() if name.endswith(f":{CRANK}"))
    note = next(note for note in graph.report.notes
                if note.startswith("joint libre_genoux (passive, inside a loop) locked"))
    return result, crank, float(note.split(" locked at ")[1].split(",")[0])


def test_a_foot_on_its_ankle_pin_driven_by_a_rod_has_the_rod_line_indices():
    result, crank, knee = ankle(ANKLE)
    assert result.dof == 1 and [name.split(":")[-1] for name in result.actuators] == [CRANK]
    model = gepetto_model(ANKLE, ANKLE.parent / "robot.yaml")
    spec = yaml.safe_load((ANKLE.parent / "robot.yaml").read_text())
    pairs = [(model.getFrameId(a), model.getFrameId(b)) for a, b in spec["closed_loop"]]
    held = {name: 0.0 for name in ANKLE_LOCKS[:4]} | {"libre_genoux": knee, CRANK: crank}
    data, _ = closed_by_scipy(model, pairs, held)
    crank_origin, crank_axis = joint_line(model, data, CRANK)
    pin_origin, pin_axis = joint_line(model, data, FOOT_PIN)
    at_crank, at_foot = (joint_line(model, data, ball)[0] for ball in (CRANK_BALL, FOOT_BALL))
    force = (at_foot - at_crank) / np.linalg.norm(at_foot - at_crank)
    crank_velocity = np.cross(crank_axis, at_crank - crank_origin)
    foot_velocity = np.cross(pin_axis, at_foot - pin_origin)
    iti = abs(force @ crank_velocity) / np.linalg.norm(crank_velocity)
    oti = abs(force @ foot_velocity) / np.linalg.norm(foot_velocity)
    np.testing.assert_allclose(np.ravel(result.iti_actuators), [iti], atol=1e-9)
    np.testing.assert_allclose(np.ravel(result.oti_actuators), [oti], atol=1e-9)
    assert result.lmti == pytest.approx(oti, abs=1e-9) and 0.2 < oti < 0.99 and 0.2 < iti < 0.99


def test_the_rod_driven_foot_is_the_same_in_millimetres_in_a_moved_world_and_listed_back(tmp_path):
    result, crank, knee = ankle(ANKLE)
    for name, path, options in variants(ANKLE, tmp_path):
        other, other_crank, other_knee = ankle(path, **options)
        np.testing.assert_allclose(np.ravel(other.iti_actuators), np.ravel(result.iti_actuators), atol=1e-9)
        np.testing.assert_allclose(np.ravel(other.oti_actuators), np.ravel(result.oti_actuators), atol=1e-9)
        np.testing.assert_allclose(other.cti, result.cti, atol=1e-9, err_msg=name)
        assert (other_crank, other_knee) == pytest.approx((crank, knee), abs=1e-8), name


def test_the_command_line_analyses_the_rod_driven_foot(tmp_path):
    result = screwkit("analyze", ANKLE, "--output", "foot_2", *[f"--lock={name}" for name in ANKLE_LOCKS])
    assert result.returncode == 0, result.stderr
    assert "1 actuator, 1 DOF" in result.stdout and "servo_gauche:mot_cheville" in result.stdout, result.stdout


def test_a_foot_left_on_its_motor_alone_is_refused_in_one_line_and_not_advised(tmp_path):
    """The refusal one step before no longer advises holding the crank's motor and the ankle (the loop they leave
    ends on the ankle, not on the foot); held all the same, one line names the chain the foot hangs on."""
    before = screwkit("analyze", BALL_ANKLE, "--output", "pied", *[f"--lock={name}" for name in BALL_ANKLE_LOCKS])
    message = one_line_error(before, "leg 'moteur_cheville' has loops inside it and 2 actuators")
    assert "--lock mot_cheville_droite" not in message, message
    held = BALL_ANKLE_LOCKS + ("mot_cheville_droite", "libre_to_rotule_cheville_droite")
    for command in ("analyze", "info"):
        result = screwkit(command, BALL_ANKLE, "--output", "pied", *[f"--lock={name}" for name in held])
        one_line_error(result, "no loop acts on the platform 'pied'", "(mot_pied_droit)", "serial arm", "--output",
                       "hold fewer joints")


LUDO = GEPETTO / "robot_ludo" / "robot.urdf"


def test_a_slide_that_carries_the_platform_itself_is_refused_in_one_line():
    """robot_ludo with the effector's pin held: its R-P leg's slide carries the effector with no link after it. Taken
    about the effector's joint, which a file may draw anywhere on the slide's line, its actuation wrench turned with
    that point (ITI 0.9964 to 0.9987, OTI 0.45 to 0.90 as it was drawn 0.3 m either way): refused, naming the slide;
    with the base's pivot held instead, the R-P-R leg opens."""
    message = one_line_error(screwkit("info", LUDO, "--output", "effecteur", "--lock", "pivot2"), "leg 'part_2_3'",
                             "actuated joint 'motor1' moves the platform itself, with no link after it")
    assert "Traceback" not in message
    assert screwkit("info", LUDO, "--output", "effecteur", "--lock", "pivot").returncode == 0


@pytest.mark.parametrize("joint, distance", [("libre_cheville", 0.1), ("libre_cheville", 0.06),
                                             ("libre_cheville", -0.5), (CRANK, -0.2), (CRANK, 0.06)])
def test_the_foot_pin_or_crank_drawn_elsewhere_along_its_axis_changes_no_index(tmp_path, joint, distance):
    """The foot's pin drawn 0.1 m or -0.5 m along its axis: the ITI, OTI, LMTI and CTI do not change (its drawn point
    was the passive leg's, and moved the CTI from 0.9987 to 0.9960 or 0.8914; the pin is now at the foot of the
    perpendicular from the rod's ball, the crank at the foot from its ball). This leg's pairing of constraint wrenches
    and freed motions repeats a singular value (1, 1, 1, 1, 0.32): the CTI takes the repeated block's worst rotation,
    which no drawing moves (before, numpy's pick within the block moved it from 0.9990 to 0.9968 with the pin drawn
    6 cm along its axis; ``test_repeated_pairs.py``)."""
    result, crank, knee = ankle(ANKLE)
    (tmp_path / "robot.urdf").write_text(revolutes_moved(ANKLE.read_text(), {joint: distance}))
    (tmp_path / "robot.yaml").write_text((ANKLE.parent / "robot.yaml").read_text())
    other, other_crank, other_knee = ankle(tmp_path / "robot.urdf")
    for name in ("iti_actuators", "oti_actuators", "lmti", "cti"):
        np.testing.assert_allclose(getattr(other, name), getattr(result, name), atol=1e-9, err_msg=name)
    assert (other_crank, other_knee) == pytest.approx((crank, knee), abs=1e-8)
