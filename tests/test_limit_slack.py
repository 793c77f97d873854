"""A joint drawn at its stop stays reachable at the poses that put it there to rounding.

A published gripper (an onshape-to-robot export) is drawn with its crank at the lower stop; asked at its home pose
as ``info`` prints it, 7.7e-13 m away, the crank was put 3.8e-11 rad past the stop and the pose refused, and a sweep
from there marked the home row unreachable. Joint values come from closures solved to ``NEWTON_TOLERANCE`` and
from poses given in rounded numbers: a joint within ``LIMIT_SLACK`` (1e-9, times 1 plus the limit's size) of its
limit is at it, in the serial and the graph readings alike; a pose that puts it further past is still refused.

The slider-crank here: crank O-B (driven, range 0 to 1.7 rad, drawn at 0), link B-C, C on a slide along x 0.01 off
the crank's centre; its ITI is |sin(OB, BC)| (the link's force on the crank pin).
"""

from __future__ import annotations

import re

import numpy as np
import pytest

from helpers import MJCF_WORLDS, mjcf_variant, one_line_error, screwkit, screwkit_json, sine
from screwkit.closure.solve import outside_limits, slackened
from screwkit.common.tolerances import LIMIT_SLACK
from screwkit.io.loader import load
from screwkit.studies import indices_at_pose

O, B = np.zeros(3), np.array([0.03, 0.0, 0.0])
C = np.array([0.03 + np.sqrt(0.04**2 - 0.01**2), 0.01, 0.0])


def slider_crank(scale: float = 1.0, world=("0 0 0", "1 0 0 0"), slide_stop: bool = False) -> str:
    """``slide_stop``: the slide drawn at its lower stop (range 0 to 0.05), the crank's range wide."""
    def at(point) -> str:
        return " ".join(repr(float(v) * scale) for v in point)

    ball = f'<geom type="sphere" size="{0.003 * scale!r}"/>'
    return ('<mujoco model="slider_crank"><compiler angle="radian"/><option><flag contact="disable"/></option>'
            f'<worldbody><body name="base" pos="{world[0]}" quat="{world[1]}">'
            f'<body name="crank"><joint name="crank" type="hinge" axis="0 0 1" '
            f'range="{"-3 3" if slide_stop else "0 1.7"}" limited="true"/>{ball}'
            f'<body name="link" pos="{at(B)}"><joint name="bpin" type="hinge" axis="0 0 1"/>{ball}</body></body>'
            f'<body name="slider" pos="{at(C)}"><joint name="slide" type="slide" axis="1 0 0" '
            f'range="{0.0 if slide_stop else -0.05 * scale!r} {0.05 * scale!r}" limited="true"/>{ball}</body></body>'
            '</worldbody>'
            f'<equality><connect name="c0" body1="link" body2="slider" anchor="{at(C - B)}"/>'
            f'<connect name="c1" body1="link" body2="slider" anchor="{at(C - B + [0.0, 0.0, 0.05])}"/></equality>'
            '<actuator><motor name="m" joint="crank"/></actuator></mujoco>')


@pytest.mark.parametrize("variant", sorted(MJCF_WORLDS))
def test_a_pose_at_the_stop_to_rounding_is_reached_and_one_past_it_refused(tmp_path, variant):
    path, unit = mjcf_variant(tmp_path, "slider_crank", variant, slider_crank)
    mechanism = load(path, output="slider", length_unit=unit)
    home = mechanism.home_pose  # (x grows as the crank turns back past its stop at 0)
    expected = sine(B - O, C - B)
    assert float(indices_at_pose(mechanism, home).iti) == pytest.approx(expected, abs=1e-12)
    for step in (1e-12, -1e-12):  # the crank 1.3e-10 rad past its stop one way
        assert float(indices_at_pose(mechanism, home + step).iti) == pytest.approx(expected, abs=1e-9)
    refused = []
    for step in (1e-6, -1e-6):  # (one way the crank turns 1e-4 rad past its stop, whichever the task coordinate)
        try:
            indices_at_pose(mechanism, home + step)
        except ValueError as error:
            refused.append(str(error))
    assert len(refused) == 1 and re.search(r"joint 'crank' at -0\.0001\d* rad is outside its limits \[0, 1\.7\]",
                                           refused[0]), refused


def test_the_command_reads_the_pose_at_the_stop_and_refuses_one_past_it(tmp_path):
    path = tmp_path / "slider_crank.xml"
    path.write_text(slider_crank())
    home = float(load(path, output="slider").home_pose[0])
    found = screwkit_json("analyze", path, "--output", "slider", "--pose", repr(home - 1e-12))
    assert found["iti"] == pytest.approx(sine(B - O, C - B), abs=1e-9)
    one_line_error(screwkit("analyze", path, "--output", "slider", "--pose", repr(home - 1e-6)),
                   "joint 'crank'", "outside its limits")


def test_the_serial_and_the_graph_readings_take_the_same_slack():
    """``outside_limits`` (serial chains) and ``beyond_limits`` (closed-loop graphs) on values about limits of
    several sizes, each end's slack by its own size: within it, at the limit; past it, beyond."""
    from screwkit.io.graph_kinematics import TreeKinematics, beyond_limits

    limits = np.array([[0.0, 1.7], [-3.0, 2.5], [-np.inf, 40.0]])
    lowest, highest = slackened(limits[:, 0], limits[:, 1])
    assert np.allclose(highest - limits[:, 1], LIMIT_SLACK * np.array([2.7, 3.5, 41.0]), rtol=1e-6, atol=0.0)
    assert np.allclose(limits[:2, 0] - lowest[:2], LIMIT_SLACK * np.array([1.0, 4.0]), rtol=1e-6, atol=0.0)
    assert lowest[2] == -np.inf
    far = np.array([[0.0, 1e8]])  # each end by its own size: a stop at 0 keeps 1e-9 whatever the other end
    assert outside_limits(far, (True,), np.array([[-0.5 * LIMIT_SLACK], [-1e-3]])).tolist() == [-1, 0]
    values = np.array([[-0.5 * LIMIT_SLACK, 2.5, 40.0 + 20.0 * LIMIT_SLACK],  # each within its slack
                       [-3.0 * LIMIT_SLACK, 0.0, 0.0],  # the first past it
                       [0.0, 2.5 + 5.0 * LIMIT_SLACK, 0.0],
                       [0.0, 0.0, 40.0 + 42.0 * LIMIT_SLACK]])
    serial = outside_limits(limits, (True, True, True), values)  # (slides: no turn either way)
    assert serial.tolist() == [-1, 0, 1, 2]

    class Kinematics:  # the fields beyond_limits reads of a TreeKinematics
        kinds = ["universe", "prismatic", "prismatic", "prismatic"]
        idx_q = idx_v = [0, 0, 1, 2]
        nv = 3
        lower, upper = limits[:, 0], limits[:, 1]

    assert set(vars(Kinematics)) - {"__module__", "__qualname__", "__doc__", "__dict__", "__weakref__"} <= set(
        TreeKinematics.__dataclass_fields__)
    graph = beyond_limits(Kinematics, values)
    assert [int(np.argmax(row)) if row.any() else -1 for row in graph] == serial.tolist()
    for size in (1e-3, 1e3):  # slides in a mechanism of that length scale, every length times it: the same verdicts

        class Scaled(Kinematics):
            lower, upper = limits[:, 0] * size, limits[:, 1] * size

        assert outside_limits(limits * size, (True, True, True), values * size, size).tolist() == serial.tolist()
        graph = beyond_limits(Scaled, values * size, None, size)
        assert [int(np.argmax(row)) if row.any() else -1 for row in graph] == serial.tolist()


@pytest.mark.parametrize("scale", [1e-3, 1e3])
def test_the_stop_reads_alike_at_any_size(tmp_path, scale):
    """Every length times 1e-3 or 1e3, read in metres, the poses asked scaled with it: the crank's stop (an angle)
    is met and passed at the same poses."""
    path = tmp_path / "slider_crank.xml"
    path.write_text(slider_crank(scale))
    mechanism = load(path, output="slider")
    home = mechanism.home_pose
    for step in (1e-12, -1e-12):
        assert float(indices_at_pose(mechanism, home + step * scale).iti) == pytest.approx(sine(B - O, C - B),
                                                                                            abs=1e-9)
    refused = []
    for step in (1e-6, -1e-6):
        try:
            indices_at_pose(mechanism, home + step * scale)
        except ValueError as error:
            refused.append(str(error))
    assert len(refused) == 1 and "joint 'crank'" in refused[0], refused


@pytest.mark.parametrize("scale", [1e-3, 1.0, 1e3])
def test_a_slides_stop_is_met_in_length_scales_at_any_size(tmp_path, scale):
    """A slide's slack is LIMIT_SLACK times the mechanism's length scale (plus the limit's size), as a hinge's is
    LIMIT_SLACK rad: the same mechanism at a thousandth or a thousand times the size (read in metres) meets and
    passes its slide's stop at the same poses in length scales. (It was 1e-9 m whatever the size: a millimetre-sized
    mechanism's slide let 1e-5 of its size past the stop, a hundred-metre one's refused 1e-10 of it.)"""
    path = tmp_path / "slider_crank.xml"
    path.write_text(slider_crank(scale, slide_stop=True))
    mechanism = load(path, output="slider")
    home, length = mechanism.home_pose, mechanism.length_scale
    for step in (0.5, -0.5):  # inside the range; past the stop by half the slack: at it
        assert float(indices_at_pose(mechanism, home + step * LIMIT_SLACK * length).iti) == pytest.approx(
            sine(B - O, C - B), abs=1e-6)
    with pytest.raises(ValueError, match=r"joint 'slide' at -\S+ m is outside its limits \[0, "):
        indices_at_pose(mechanism, home - 3.0 * LIMIT_SLACK * length)
