"""A slider-crank as CAD exporters write it for MuJoCo (FreeCAD-Assembly2MuJoCo's ``crank_and_slider``: the rod a child
of the slider, the crank on the base, the rod-crank pin written as two ``<connect>`` on its axis, every joint driven).

The slider, the output anyone would pick, was refused: the loop closes on the rod, which the file hangs beyond the
slider (the platform), and the refusal advised holding the rod's hinge, which leaves no motion at all (MuJoCo: DOF 0).
The graph reading takes the rod's hinge as a joint of the crank's leg: the indices are the textbook slider-crank's
(ITI = |u . t_B|, the rod's direction against the crank pin's direction of motion; OTI = |u . s|, against the
slide), in millimetres, in a moved world and with the connects written the other way round; as written (the slide
driven too) one line names the option that leaves it out.

With the crank pin as output, its task coordinate x turns back where the pin's circle does; Newton steps on the pose
crossed that turning point and were dropped, so ``--actuators`` refused crank angles 16 degrees short of it (a
published file: 28 degrees of 43.6). A step past where the loops close is now halved from the last closed pose.
"""

from __future__ import annotations

import json
import re

import mujoco
import numpy as np
import pytest

from helpers import mujoco_rows, one_line_error, screwkit
from screwkit.closure.forward_kinematics import forward
from screwkit.io import graph_mechanism, read_closed_tree
from screwkit.io.loader import load

CRANK, ROD, OFFSET = 0.015, 0.05, 0.004  # crank radius r, rod length l, the slide's line offset e from the pivot A
DRAWN = np.radians(-40.0)  # the crank's angle as drawn: its pin's y turns back 50 degrees on
TURN = ("0.3 -0.2 0.5", "0.8660254 0.1336306 0.2672612 0.4008919")  # a moved and turned world (pos, quat)


def closed_form(angle: float) -> dict:
    """The slider-crank with its crank at ``angle`` (from x, about z): the pin B, the slider's pin C, and the
    pressure-angle indices."""
    b = CRANK * np.array([np.cos(angle), np.sin(angle)])
    c = np.array([b[0] + np.sqrt(ROD**2 - (OFFSET - b[1]) ** 2), OFFSET])
    u = (c - b) / ROD
    return {"b": b, "c": c, "iti": abs(u @ np.array([-np.sin(angle), np.cos(angle)])), "oti": abs(u[0])}


RENAMED = {"SliderRod": "zz_carriage", "ConnectingRod": "aa_link", "Crank": "m_arm", "Slider": "q0", "RodHinge": "a9",
           "CrankHinge": "b_drive", "pin_": "loop_"}
"""Other names for every body, joint, actuator and closure (sorted otherwise than the file's own)."""


def cad_slider_crank(scale: float = 1.0, world=None, swapped: bool = False, reordered: bool = False,
                     renamed: bool = False) -> str:
    """The MJCF text, lengths times ``scale``, drawn at the crank angle :data:`DRAWN` (every joint value zero),
    hung in a frame placed by ``world`` (pos, quat), the connects' bodies in the other order if ``swapped``, the
    crank's body written before the slider's if ``reordered``, every name replaced by :data:`RENAMED`'s if
    ``renamed``."""
    def n(*values):
        return " ".join(repr(float(v) * scale) for v in values)

    drawn = closed_form(DRAWN)
    (bx, by), (cx, cy) = drawn["b"], drawn["c"]
    pairs = [("ConnectingRod", "Crank"), ("Crank", "ConnectingRod")][swapped]
    connects = "".join(f'<connect body1="{pairs[0]}" body2="{pairs[1]}" name="pin_{k}" anchor="{n(bx, by, z)}"/>'
                       for k, z in ((1, 0.0), (2, 0.01)))
    slider = f"""
      <body name="SliderRod" pos="0 0 0">
        <joint type="slide" name="Slider" pos="{n(cx, cy, 0)}" axis="1 0 0"/>
        <geom type="box" pos="{n(cx, cy, 0)}" size="{n(0.005, 0.005, 0.005)}"/>
        <body name="ConnectingRod" pos="0 0 0">
          <joint type="hinge" name="RodHinge" pos="{n(cx, cy, 0)}" axis="0 0 1"/>
          <geom type="capsule" fromto="{n(bx, by, 0, cx, cy, 0)}" size="{n(0.002)}"/>
        </body>
      </body>"""
    crank = f"""
      <body name="Crank" pos="0 0 0">
        <joint type="hinge" name="CrankHinge" pos="0 0 0" axis="0 0 1"/>
        <geom type="capsule" fromto="{n(0, 0, 0, bx, by, 0)}" size="{n(0.002)}"/>
      </body>"""
    bodies = crank + slider if reordered else slider + crank
    if world is not None:
        bodies = f'<body name="frame" pos="{n(*map(float, world[0].split()))}" quat="{world[1]}">{bodies}</body>'
    text = f"""<mujoco model="crank_and_slider">
  <worldbody><body name="Base">{bodies}</body></worldbody>
  <equality>{connects}</equality>
  <actuator><position name="Slider" joint="Slider"/><position name="CrankHinge" joint="CrankHinge"/>
    <position name="RodHinge" joint="RodHinge"/></actuator>
</mujoco>
"""
    if renamed:
        longest_first = "|".join(sorted(RENAMED, key=len, reverse=True))
        text = re.sub(f'"({longest_first})', lambda match: '"' + RENAMED[match.group(1)], text)
    return text


def written(tmp_path, name: str = "crank_and_slider.xml", **options):
    path = tmp_path / name
    path.write_text(cad_slider_crank(**options))
    return path


def slider_indices(path, renamed: bool = False, **options):
    names = RENAMED if renamed else {}
    graph = graph_mechanism(read_closed_tree(path, output=names.get("SliderRod", "SliderRod"),
                                             actuate=(names.get("CrankHinge", "CrankHinge"),), **options))
    return graph, graph.indices()


def test_mujoco_reads_the_file_closed_with_one_motion():
    model = mujoco.MjModel.from_xml_string(cad_slider_crank())
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    assert np.max(np.abs(data.efc_pos[:model.neq * 3])) < 1e-15  # the connects hold at every joint zero
    jacobian = mujoco_rows(model, data)
    assert model.nv - np.linalg.matrix_rank(jacobian, tol=1e-9) == 1


def test_the_slider_is_the_output_with_the_textbook_pressure_angles(tmp_path):
    graph, result = slider_indices(written(tmp_path))
    expected = closed_form(DRAWN)
    assert result.dof == 1 and graph.task_coordinates == ("x",)
    np.testing.assert_allclose(np.ravel(result.iti_actuators), [expected["iti"]], atol=1e-9)
    np.testing.assert_allclose(np.ravel(result.oti_actuators), [expected["oti"]], atol=1e-9)
    assert result.lmti == pytest.approx(expected["oti"], abs=1e-9)
    assert 0.5 < expected["iti"] < 0.99 and 0.5 < expected["oti"] < 0.99  # neither trivial nor singular


@pytest.mark.parametrize("variant", ["mm", "moved", "swapped", "reordered", "renamed", "1e-3 as large",
                                     "1e3 as large"])
def test_the_slider_reads_the_same_in_millimetres_in_a_moved_world_and_written_the_other_way(tmp_path, variant):
    """The same mechanism in millimetres, in a moved world, written the other way round, with every name changed;
    and the mechanism a thousand times smaller or larger (read in metres): the same indices."""
    _, reference = slider_indices(written(tmp_path))
    options, reading = {"mm": ({"scale": 1e3}, {"length_unit": "mm"}), "moved": ({"world": TURN}, {}),
                        "swapped": ({"swapped": True}, {}), "reordered": ({"reordered": True}, {}),
                        "renamed": ({"renamed": True}, {"renamed": True}),
                        "1e-3 as large": ({"scale": 1e-3}, {}), "1e3 as large": ({"scale": 1e3}, {})}[variant]
    _, other = slider_indices(written(tmp_path, f"{variant}.xml", **options), **reading)
    for name in ("iti_actuators", "oti_actuators", "lmti", "cti"):
        np.testing.assert_allclose(getattr(other, name), getattr(reference, name), atol=1e-9, err_msg=name)


def test_the_command_line_analyses_the_slider_and_names_the_options_for_the_file_as_written(tmp_path):
    path = written(tmp_path)
    done = screwkit("analyze", path, "--output", "SliderRod", "--actuate", "CrankHinge", "--json")
    assert done.returncode == 0, done.stderr
    report, expected = json.loads(done.stdout), closed_form(DRAWN)
    assert report["iti"] == pytest.approx(expected["iti"], abs=1e-9)
    assert report["lmti"] == pytest.approx(expected["oti"], abs=1e-9)
    one_line_error(screwkit("info", path), "which body is the platform? Name its output frame (--output FRAME)",
                   "the closures join bodies 'ConnectingRod', 'Crank'")
    one_line_error(screwkit("analyze", path, "--output", "SliderRod"), "actuated joint 'Slider' (prismatic) moves "
                   "the platform body on the base directly", "--actuate names the actuators without it (the file's "
                   "others: CrankHinge, RodHinge)")


def test_a_closure_beyond_a_held_joint_that_would_freeze_the_mechanism_is_not_advised(tmp_path):
    """The serial reading's refusal (hold the rod's hinge) stands only where the graph reading refuses too."""
    result = screwkit("info", written(tmp_path), "--output", "SliderRod", "--actuate", "CrankHinge")
    assert result.returncode == 0, result.stderr
    assert "--lock RodHinge" not in result.stdout + result.stderr


@pytest.mark.parametrize("crank", [-25.0, -40.0, -48.0, 100.0, 125.0])
def test_actuator_values_near_where_the_crank_pin_s_task_coordinate_turns_back_are_reached(tmp_path, crank):
    """The task coordinate is y, which the pin moves along faster at the drawing (cos 40 against sin 40 of its
    speed; x was taken before, the first in order). y = r sin(theta) turns back at theta = -90 and 90 degrees, 50
    and 130 degrees from the drawing; Newton on the task coordinate from the drawing stopped about 16 degrees short
    of such a point (x's, 40 degrees away: 25 degrees reached, 28 not, in the published file)."""
    mechanism = load(written(tmp_path), output="Crank", actuate=("CrankHinge",))
    assert mechanism.task_coordinates == ("y",)
    solution = forward(mechanism, [np.radians(crank)], mechanism.home_pose)
    assert bool(np.ravel(solution.reachable)[0])
    np.testing.assert_allclose(np.ravel(solution.poses), closed_form(DRAWN + np.radians(crank))["b"][1:2], atol=1e-9)


def test_the_command_line_takes_the_crank_near_the_turning_point(tmp_path):
    done = screwkit("analyze", written(tmp_path), "--output", "Crank", "--actuate", "CrankHinge", "--actuators", "36",
                    "--json")
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)
    assert report["pose"]["y"] == pytest.approx(closed_form(DRAWN + np.radians(36.0))["b"][1], abs=1e-9)
