"""A leg that drives its platform by two rods pulling against each other is refused, not read as a perfect couple.

ToddlerBot's knee (its published MJCF, MIT) turns the calf by a motor plate and two rods, a parallelogram doubled on
the far side of the crank: the rods stay parallel to the line of the two axes, one pushes while the other pulls,
and what the leg exerts on the calf is a pure couple. Read as a leg with loops inside it, its actuation wrench is
that couple, whose power coefficient is 1 on any rotation: ITI = LMTI = CTI = 1.0000 at every pose, also 0.85 deg
from the dead centre where both rods line up with the crank and the leg locks (each rod's pressure angle 0.0148
there). Such a leg is now refused in one line naming the rods' joints and how to read one force path; with one
rod's weld left out (``active="false"``), the leg is a serial one and reads that rod's pressure angle, |sin| of
the angle between the crank and the rod, which the test computes from the drawing.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from helpers import one_line_error, screwkit
from screwkit.io import graph_mechanism, read_closed_tree
from screwkit.io.loader import load
from screwkit.studies import indices_at_pose

GAP, CRANK = 0.04, 0.015  # motor axis to knee axis; crank radius on both


def knee_mjcf(angle: float, rods: int = 2, scale: float = 1.0, world=((0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0)),
              order=(0, 1)) -> str:
    """The knee drawn with the crank at ``angle`` (rad) from the line of the axes; ``rods`` welds active; the whole
    turned (``world``: a position and a quaternion of the thigh) and its rods written in ``order``."""
    crank = CRANK * np.array([np.cos(angle), np.sin(angle), 0.0]) * scale
    gap = GAP * scale

    def place(vector):
        return " ".join(repr(float(v)) for v in vector)

    plate_rods = {k: f'<body name="rod{k + 1}" pos="{place(sign * crank)}"><joint name="rod{k + 1}_pin" '
                     f'axis="0 0 1"/><geom type="capsule" fromto="0 0 0 {gap} 0 0" size="{0.002 * scale}"/></body>'
                  for k, sign in ((0, 1.0), (1, -1.0))}
    bearings = {k: f'<body name="bearing{k + 1}" pos="{place(sign * crank)}"><joint name="bearing{k + 1}_pin" '
                   f'axis="0 0 1"/><geom type="sphere" size="{0.003 * scale}"/></body>'
                for k, sign in ((0, 1.0), (1, -1.0))}
    inactive = ' active="false"'
    welds = "".join(f'<weld body1="rod{k + 1}" body2="bearing{k + 1}"{"" if k < rods else inactive}/>' for k in order)
    position, quaternion = world
    return f"""<mujoco model="knee">
  <worldbody>
    <body name="thigh" pos="{place(np.array(position) * scale)}" quat="{place(quaternion)}">
      <geom type="box" size="{0.01 * scale} {0.01 * scale} {0.01 * scale}"/>
      <body name="plate" pos="0 0 0"><joint name="motor" axis="0 0 1"/>
        <geom type="cylinder" size="{0.02 * scale} {0.002 * scale}"/>{"".join(plate_rods[k] for k in order)}</body>
      <body name="calf" pos="{gap} 0 0"><joint name="knee" axis="0 0 1"/>
        <geom type="capsule" fromto="0 0 0 0 {-0.1 * scale} 0" size="{0.005 * scale}"/>
        {"".join(bearings[k] for k in order)}
        <site name="foot" pos="0 {-0.1 * scale} 0"/></body>
    </body>
  </worldbody>
  <equality>{welds}</equality>
  <actuator><motor joint="motor"/></actuator>
</mujoco>"""


@pytest.mark.parametrize("variant", ["plain", "mm", "turned", "reordered"])
def test_two_rods_pulling_against_each_other_are_refused_naming_them(tmp_path, variant):
    options = {"mm": dict(scale=1000.0), "turned": dict(world=((0.3, -0.2, 0.5), (0.8, 0.3, -0.4, 0.2))),
               "reordered": dict(order=(1, 0))}.get(variant, {})
    path = tmp_path / "knee.xml"
    path.write_text(knee_mjcf(np.deg2rad(50.0), **options))
    tree = read_closed_tree(path, output="calf", length_unit="mm" if variant == "mm" else None)
    with pytest.raises(ValueError) as error:  # read as a graph: the leg has loops inside it
        graph_mechanism(tree)
    message = str(error.value)
    assert "drives the platform by a pure couple" in message and "'rod1_pin'" in message and "'rod2_pin'" in message
    assert "active='false'" in message and "\n" not in message


@pytest.mark.parametrize("degrees", [50.0, 100.0, 12.0, 2.0])
def test_one_rod_reads_its_pressure_angle(tmp_path, degrees):
    expected = abs(np.sin(np.deg2rad(degrees)))  # the rod stays parallel to the axes' line: |sin| crank to rod
    readings = []
    for name, options, unit in (("plain", {}, None), ("mm", dict(scale=1000.0), "mm"),
                                ("turned", dict(world=((0.3, -0.2, 0.5), (0.8, 0.3, -0.4, 0.2))), None)):
        path = tmp_path / f"{name}.xml"
        path.write_text(knee_mjcf(np.deg2rad(degrees), rods=1, **options))
        mechanism = load(path, output="calf", length_unit=unit)
        result = indices_at_pose(mechanism, mechanism.home_pose)
        readings.append((float(result.iti), float(result.lmti)))
    for iti, lmti in readings:
        assert iti == pytest.approx(expected, abs=1e-9) and lmti == pytest.approx(expected, abs=1e-9)
    model = mujoco.MjModel.from_xml_path(str(tmp_path / "turned.xml"))  # MuJoCo's own reading of the drawing
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    motor, pin, bearing, knee = (data.xanchor[model.joint(name).id] for name in ("motor", "rod1_pin", "bearing1_pin",
                                                                                 "knee"))
    crank, rod = pin - motor, bearing - pin
    assert np.linalg.norm(np.cross(crank, rod)) / (np.linalg.norm(crank) * np.linalg.norm(rod)) == pytest.approx(
        readings[2][0], abs=1e-9)
    assert np.linalg.norm(np.cross(bearing - knee, rod)) / (np.linalg.norm(bearing - knee) * np.linalg.norm(rod)) \
        == pytest.approx(readings[2][1], abs=1e-9)


def test_the_command_refuses_the_two_rods_in_one_line(tmp_path):
    path = tmp_path / "knee.xml"
    path.write_text(knee_mjcf(np.deg2rad(50.0)))
    one_line_error(screwkit("analyze", path, "--output", "calf"), "pure couple", "'rod1_pin', 'rod2_pin'",
                   "that rod's pressure angles")
