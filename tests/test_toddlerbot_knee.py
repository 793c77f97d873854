"""ToddlerBot's published knee (``tests/data/gallery/excerpts/toddlerbot_knee``, MIT): refusals followed to the end.

The calf is turned by a motor plate and two rods on opposite sides of the crank (a parallelogram doubled). Read as a
leg with loops inside it, the knee gave ITI = LMTI = CTI = 1.0000 at every pose (the rods' forces make a pure
couple); the path there told the user to remove the hip's gear coupling. Now:

* each refusal names the serial stage to hold (the waist, then the hip), and the last one the knee's rods pulling
  against each other, refused;
* with one rod's weld left out (``active="false"``), the knee is a serial leg and reads that rod's pressure angles,
  computed here from MuJoCo's own anchors with the weld closed by Newton on MuJoCo's residuals, at the ``home``
  keyframe's motor value and at two others.
"""

from __future__ import annotations

import re
from pathlib import Path

import mujoco
import numpy as np
import pytest

from helpers import mujoco_rows, one_line_error, screwkit
from screwkit.closure import actuator_values, solve
from screwkit.closure.forward_kinematics import forward
from screwkit.io.loader import load
from screwkit.studies import indices_at_pose

KNEE = Path(__file__).parent / "data" / "gallery" / "excerpts" / "toddlerbot_knee" / "toddlerbot_fixed.xml"
HELD = ("waist_yaw", "waist_roll", "left_hip_pitch", "left_hip_roll", "left_hip_yaw_driven")


def test_the_advice_ends_at_the_knee_s_rods_pulling_against_each_other():
    advised: list[str] = []
    lines = []
    for _ in range(4):
        run = screwkit("info", KNEE, "--output", "left_calf_link", *advised)
        line = one_line_error(run, "toddlerbot_fixed.xml")
        lines.append(line)
        found = re.findall(r"--lock (\w+)", line)
        if not found:
            break
        advised += [word for joint in found for word in ("--lock", joint)]
    assert "remove the element" not in " ".join(lines[:-1]), lines
    assert set(advised[1::2]) == set(HELD), advised
    assert "drives the platform by a pure couple" in lines[-1]
    assert "'left_knee_front_rev_1', 'left_knee_back_rev_1'" in lines[-1]


def _one_rod(tmp_path) -> Path:
    text = KNEE.read_text()
    weld = '<weld body1="knee_rod_2" body2="bearing_683_4"'
    assert text.count(weld) == 1
    path = tmp_path / "one_rod.xml"
    path.write_text(text.replace(weld, weld + ' active="false"'))
    return path


def _mujoco_pressure_angles(path: Path, motor: float) -> tuple[float, float]:
    """The front rod's pressure angles on the plate (ITI) and on the calf (OTI), with MuJoCo's anchors: the home
    keyframe, the knee motor at ``motor`` (rad), the front rod's weld closed by Newton over the knee and the rod's
    pins, in the plane normal to the motor's axis."""
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    joint = {name: model.joint(name).id for name in ("left_knee_act", "left_knee", "left_knee_front_rev_1",
                                                       "left_knee_front_rev_2")}
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    data.qpos[model.jnt_qposadr[joint["left_knee_act"]]] = motor
    free = [joint[name] for name in ("left_knee", "left_knee_front_rev_1", "left_knee_front_rev_2")]
    weld = next(k for k in range(model.neq) if model.eq_type[k] == mujoco.mjtEq.mjEQ_WELD
                and model.body(model.eq_obj1id[k]).name == "knee_rod")
    for _ in range(100):
        mujoco.mj_forward(model, data)
        rows = [k for k in range(data.nefc) if data.efc_type[k] == mujoco.mjtConstraint.mjCNSTR_EQUALITY
                and data.efc_id[k] == weld]
        residual = data.efc_pos[rows]
        if np.linalg.norm(residual) < 1e-14:
            break
        jacobian = mujoco_rows(model, data)[rows][:, [model.jnt_dofadr[j] for j in free]]
        step = np.linalg.lstsq(jacobian, -residual, rcond=None)[0]
        for j, change in zip(free, step):
            data.qpos[model.jnt_qposadr[j]] += change
    assert np.linalg.norm(residual) < 1e-12
    normal = data.xaxis[joint["left_knee_act"]]

    def sine(u, v):
        u, v = u - (u @ normal) * normal, v - (v @ normal) * normal
        return abs(float(np.cross(u, v) @ normal)) / (np.linalg.norm(u) * np.linalg.norm(v))

    motor_at, knee = data.xanchor[joint["left_knee_act"]], data.xanchor[joint["left_knee"]]
    pin, bearing = data.xanchor[joint["left_knee_front_rev_1"]], data.xanchor[joint["left_knee_front_rev_2"]]
    return sine(pin - motor_at, bearing - pin), sine(bearing - pin, bearing - knee)


@pytest.mark.parametrize("change", [0.0, np.radians(-15.0), np.radians(20.0)])
def test_one_rod_reads_its_pressure_angles_where_mujoco_places_it(tmp_path, change):
    path = _one_rod(tmp_path)
    mechanism = load(path, output="left_calf_link", lock=HELD)
    home = float(np.ravel(actuator_values(mechanism, solve(mechanism, mechanism.home_pose)))[0])
    solution = forward(mechanism, [home + change], mechanism.home_pose)
    assert bool(np.ravel(solution.reachable)[0])
    result = indices_at_pose(mechanism, np.ravel(solution.poses))
    iti, oti = _mujoco_pressure_angles(path, home + change)
    assert float(result.iti) == pytest.approx(iti, abs=1e-9)
    assert float(result.lmti) == pytest.approx(oti, abs=1e-9)
