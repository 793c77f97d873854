"""Right angles written 1.57 (:mod:`screwkit.io.written_angles`): a published knee four-bar opens as written.

Kayra's MJCF knee (``tests/data/gallery/published/kayra``, BSD-3-Clause) writes every right angle as 1.57 rad, so its
crank's hinge is 0.046 deg out of parallel with the coupler's and rocker's, and its rocker's pivot is one
``<connect>`` (a ball). Read exactly, that is no planar mechanism, and the ball pivot was refused. Its author drew a
planar four-bar to two decimals: the axes are now made parallel within what the file's rounded angles can turn them,
and the knee reads the pressure angles MuJoCo's own placement of its joints gives. The angles' rounding is
computed here from the file's numbers independently of the module (counted by hand along the body path), and the
indices are checked against MuJoCo's reading of the same file, in millimetres and in a moved world.
"""

from __future__ import annotations

import json
import math
import xml.etree.ElementTree as ET

import mujoco
import numpy as np
import pytest
from test_gallery_published import PUBLISHED, without_meshes

from helpers import one_line_error, screwkit
from screwkit.common.tolerances import FILE_ROUNDING
from screwkit.io.loader import load
from screwkit.io.written_angles import axis_tolerance, rounded_angle
from screwkit.studies import indices_at_pose

KAYRA = PUBLISHED / "kayra" / "kayraCircle.xml"
OPTIONS = dict(lock=("4R_LinkJoint_0",), output="2R_Link")
"""The knee body floats (a free joint): held where the file puts it; the coupler is the output (its crank as output
is refused, naming --output: ``tests/test_four_bar_output.py``)."""


@pytest.mark.parametrize("text, expected", [
    ("1.57", math.pi / 2 - 1.57), ("-1.57", math.pi / 2 - 1.57), ("0.785", abs(0.785 - math.pi / 4)),
    ("3.14", math.pi - 3.14), ("3.1416", 3.1416 - math.pi), ("1.5708", 1.5708 - math.pi / 2),
    ("4.71", abs(4.71 - 3 * math.pi / 2)), ("0.52", math.pi / 6 - 0.52),
    ("1.5707963267948966", 0.0),  # pi/2 as Python writes it: exact to the double
    ("0", 0.0), ("0.0", 0.0), ("-0.0", 0.0), ("1", 0.0), ("1.6", 0.0), ("0.5", 0.0), ("0.3", 0.0),  # one decimal:
    ("1.56", 0.0), ("1.58", 0.0), ("0.70", 0.0), ("1.57e0", 0.0), ("90", 0.0), ("pi", 0.0)])  # rounds no multiple
def test_an_angle_is_a_rounded_multiple_of_15_degrees_only_within_half_its_last_decimal(text, expected):
    assert rounded_angle(text) == pytest.approx(expected, abs=1e-15)


def test_the_knee_files_rounding_is_summed_along_its_deepest_body_path():
    """4R_Link (0) > 3BR_Link (1.57, -1.57) > 2R_Link (-1.57, 1.57) > 3FU_Link (-1.57): five right angles on one path,
    each pi/2 - 1.57 off; 1R_Link's path has four; the camera's xyaxes and the actuators' ctrlrange are no euler."""
    tolerance, why = axis_tolerance(str(KAYRA))
    assert tolerance == pytest.approx(FILE_ROUNDING + 2 * 5 * (math.pi / 2 - 1.57), rel=1e-12)
    assert why == "1.57 for pi/2"


def test_urdf_and_sdformat_angles_and_degrees(tmp_path):
    """A URDF's rpy summed from the root link along joints (the deeper of two branches), an SDFormat file's poses
    all summed (frames may be relative to any other), MJCF in degrees not at all."""
    urdf = tmp_path / "r.urdf"
    urdf.write_text('<robot name="r"><link name="a"/><link name="b"/><link name="c"/><link name="d"/>'
                    '<joint name="ab" type="revolute"><parent link="a"/><child link="b"/>'
                    '<origin rpy="1.57 0 0.785"/></joint>'
                    '<joint name="bc" type="revolute"><parent link="b"/><child link="c"/><origin rpy="0 3.14 0"/>'
                    '</joint><joint name="ad" type="fixed"><parent link="a"/><child link="d"/>'
                    '<origin rpy="1.5708 0 0"/></joint></robot>')
    path_sum = (math.pi / 2 - 1.57) + abs(0.785 - math.pi / 4) + (math.pi - 3.14)
    assert axis_tolerance(str(urdf)) == (pytest.approx(FILE_ROUNDING + 2 * path_sum, rel=1e-12), "3.14 for pi")
    sdf = tmp_path / "m.sdf"
    sdf.write_text('<sdf version="1.7"><model name="m"><link name="a"><pose>0 0 1 0 0 3.14</pose></link>'
                   '<link name="b"><pose>0.5 0 0 -1.57 0 0</pose></link>'
                   '<link name="c"><pose degrees="true">0 0 0 90.0 0 1.57</pose></link></model></sdf>')
    assert axis_tolerance(str(sdf)) == (pytest.approx(FILE_ROUNDING + 2 * ((math.pi - 3.14) + (math.pi / 2 - 1.57)),
                                                      rel=1e-12), "3.14 for pi")
    mjcf = tmp_path / "degrees.xml"
    mjcf.write_text(KAYRA.read_text().replace('<compiler angle="radian"/>', ""))
    assert axis_tolerance(str(mjcf)) == (FILE_ROUNDING, "")
    assert axis_tolerance(str(tmp_path / "missing.xml")) == (FILE_ROUNDING, "")


def mujoco_pressure_angles(text: str) -> tuple[float, float, float]:
    """MuJoCo's reading of the knee at its file's configuration (the connect closed there): the four-bar's
    pressure angles |sin(AB, BC)| (at the crank) and |sin(BC, DC)| (at the coupler-rocker pin C, the output point),
    A, B, C the crank's, coupler's and rocker's anchors and D the connect's anchor on the knee, projected on the plane
    normal to the hinges' mean axis; and how much the angles change when projected on each hinge's own axis instead
    (what the file's rounding leaves undecided)."""
    model = mujoco.MjModel.from_xml_string(without_meshes(text))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    assert np.linalg.norm(data.efc_pos[:3]) < 1e-12  # closed as written

    def joint(name):
        return mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)

    names = ("3BR_Joint", "2R_Joint", "3FU_Joint")
    a, b, c = (data.xanchor[joint(name)].copy() for name in names)
    knee = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "4R_Link")
    d = data.xpos[knee] + data.xmat[knee].reshape(3, 3) @ model.eq_data[0][:3]
    axes = [data.xaxis[joint(name)].copy() for name in names]

    def angles(axis):
        def sine(u, v):
            u, v = u - (u @ axis) * axis, v - (v @ axis) * axis
            return abs(np.cross(u, v) @ axis) / np.linalg.norm(u) / np.linalg.norm(v)

        return np.array([sine(b - a, c - b), sine(c - b, c - d)])

    mean = np.sum(axes, axis=0)
    central = angles(mean / np.linalg.norm(mean))
    spread = max(float(np.max(np.abs(angles(axis) - central))) for axis in axes)
    return float(central[0]), float(central[1]), spread


def knee_indices(path, **options) -> np.ndarray:
    mechanism = load(path, **OPTIONS, **options)
    result = indices_at_pose(mechanism, mechanism.home_pose)
    return np.array([float(np.ravel(result.iti_actuators)[0]), float(result.lmti)])


def test_the_published_knee_opens_as_written_with_mujocos_pressure_angles(tmp_path):
    """Within what the rounding leaves undecided (the angles projected on each hinge's axis rather than their mean);
    the knee its author drew, every 1.57 written pi/2, to 1e-9 (its axes exactly parallel)."""
    iti, lmti, spread = mujoco_pressure_angles(KAYRA.read_text())
    assert 1e-6 < spread < 1e-3
    np.testing.assert_allclose(knee_indices(KAYRA), [iti, lmti], atol=spread, rtol=0)
    exact = tmp_path / "exact.xml"
    exact.write_text(KAYRA.read_text().replace("1.57", repr(math.pi / 2)))
    assert axis_tolerance(str(exact)) == (FILE_ROUNDING, "")
    iti, lmti, spread = mujoco_pressure_angles(exact.read_text())
    assert spread < 1e-12
    np.testing.assert_allclose(knee_indices(exact), [iti, lmti], atol=1e-9, rtol=0)


def scaled_and_moved(text: str, factor: float, pose: tuple[str, str] | None = None) -> str:
    """The knee's MJCF text with every position (bodies', joints', the connect's anchor) times ``factor``, and the
    knee body at ``pose`` (``pos``, ``euler`` texts) instead of the file's."""
    root = ET.fromstring(text)
    for element in root.iter():
        for attribute in ("pos", "anchor"):
            if element.get(attribute) is not None and element.tag in ("body", "joint", "connect"):
                element.set(attribute, " ".join(repr(factor * float(v)) for v in element.get(attribute).split()))
    if pose is not None:
        knee = next(body for body in root.iter("body") if body.get("name") == "4R_Link")
        knee.set("pos", pose[0])
        knee.set("euler", pose[1])
    return ET.tostring(root, encoding="unicode")


@pytest.mark.parametrize("factor, unit", [(1e3, "mm"), (1e-3, "km")])
def test_the_published_knee_reads_the_same_in_another_unit_and_a_moved_world(tmp_path, factor, unit):
    expected = knee_indices(KAYRA)
    scaled = tmp_path / "knee.xml"
    scaled.write_text(scaled_and_moved(without_meshes(KAYRA.read_text()), factor))
    np.testing.assert_allclose(knee_indices(scaled, length_unit=unit), expected, atol=1e-9, rtol=0)
    moved = tmp_path / "moved.xml"
    moved.write_text(scaled_and_moved(without_meshes(KAYRA.read_text()), 1.0, ("0.3 -0.2 2.1", "0.3 -0.5 0.7")))
    np.testing.assert_allclose(knee_indices(moved), expected, atol=1e-9, rtol=0)


def test_the_command_opens_the_published_knee_and_still_refuses_a_tilt_beyond_its_rounding(tmp_path):
    """As users run it; and with the coupler's last right angle written 1.56 (0.57 deg off: no rounding of pi/2),
    which turns its hinge 0.62 deg out of parallel, more than the 0.37 deg the other rounded angles allow, the ball
    pivot is refused, saying by how much the axes are out of parallel and how much the file's rounding allows."""
    done = screwkit("analyze", KAYRA, "--lock", "4R_LinkJoint_0", "--output", "2R_Link", "--json")
    assert done.returncode == 0, done.stderr
    printed = json.loads(done.stdout)
    np.testing.assert_allclose([printed["iti"], printed["lmti"]], knee_indices(KAYRA), atol=1e-12, rtol=0)
    text = KAYRA.read_text()
    tilted = tmp_path / "tilted.xml"
    assert text.count('euler= "0 -1.57 1.57"') == 1
    tilted.write_text(text.replace('euler= "0 -1.57 1.57"', 'euler= "0 -1.57 1.56"'))
    message = one_line_error(screwkit("analyze", tilted, "--lock", "4R_LinkJoint_0", "--output", "2R_Link"))
    assert message.endswith("in a planar mechanism only (its revolute axes are parallel to within 0.62 deg only, more "
                            "than the file's rounding allows: 0.37 deg, its angles written as 1.57 for pi/2).")
