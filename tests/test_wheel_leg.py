"""A wheel leg: a five-bar whose distal link carries the wheel, its closure pin at the wheel's centre.

Published wheel-leg MJCF files (a five-bar wheel leg of a wheeled biped) close the five-bar at the wheel's centre,
on the wheel body itself, which the driven wheel joint turns on the distal link. With that distal link as the output
the wheel joint is in a leg with the other knee's motor: the refusal "has loops inside it and 2 actuators" named
neither the wheel joint nor the way out. It now names ``--lock wheel_joint``, with which the legs read the
five-bar's textbook input transmission: ITI = |sin(AB, BC)| and |sin(ED, DC)| from MuJoCo's placement of the pins,
in m, mm and a moved, turned world.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from helpers import MJCF_WORLDS, mjcf_variant, mujoco_closed, one_line_error, screwkit, sine
from screwkit.io import ImportError_, read_closed_tree
from screwkit.io.graph import graph_mechanism
from screwkit.io.loader import load
from screwkit.studies import indices_at_pose

A, B, C = np.array([0.0, 0.0, 0.0]), np.array([-0.08, 0.0, -0.18]), np.array([0.03, 0.0, -0.35])
E, D = np.array([0.06, 0.0, 0.0]), np.array([0.15, 0.0, -0.17])
"""The hips A and E, the knees B and D, the wheel's centre C (the plane y = 0, every axis along y)."""


def wheel_leg(scale: float = 1.0, world=("0 0 0", "1 0 0 0")) -> str:
    def at(point) -> str:
        return " ".join(repr(float(v) * scale) for v in point)

    ball = f'<geom type="sphere" size="{0.005 * scale!r}"/>'
    hinge = '<joint name="{}" type="hinge" axis="0 1 0"/>' + ball
    return ('<mujoco model="wheel_leg"><option><flag contact="disable"/></option><worldbody>'
            f'<body name="base" pos="{world[0]}" quat="{world[1]}">'
            f'<body name="link_AB" pos="{at(A)}">{hinge.format("q1")}'
            f'<body name="link_BC" pos="{at(B - A)}">{hinge.format("q2")}'
            f'<body name="wheel" pos="{at(C - B)}">{hinge.format("wheel_joint")}</body></body></body>'
            f'<body name="link_ED" pos="{at(E)}">{hinge.format("q4")}'
            f'<body name="link_DC" pos="{at(D - E)}">{hinge.format("q3")}<site name="C_right" pos="{at(C - D)}"/>'
            '</body></body></body></worldbody>'
            '<equality><connect name="five_link_closure" body1="wheel" body2="link_DC" anchor="0 0 0"/></equality>'
            '<actuator><motor joint="q1"/><motor joint="q4"/><motor joint="wheel_joint"/></actuator></mujoco>')



@pytest.mark.parametrize("variant", sorted(MJCF_WORLDS))
def test_the_distal_link_names_the_wheel_joint_and_reads_with_it_held(tmp_path, variant):
    path, unit = mjcf_variant(tmp_path, "wheel_leg", variant, wheel_leg)
    _, _, anchor = mujoco_closed(path)
    with pytest.raises(ImportError_, match="actuated joint 'wheel_joint' rides on the platform .*--lock wheel_joint"):
        graph_mechanism(read_closed_tree(path, output="link_BC", length_unit=unit))  # (the command's reading)
    mechanism = load(path, output="link_BC", lock=("wheel_joint",), length_unit=unit)
    result = indices_at_pose(mechanism, mechanism.home_pose)
    itis = dict(zip(mechanism.actuator_names, np.ravel(result.iti_actuators)))
    a, b, c, e, d = (anchor[name] for name in ("q1", "q2", "wheel_joint", "q4", "q3"))
    assert itis["q1:q1"] == pytest.approx(sine(b - a, c - b), abs=1e-9)
    assert itis["q4:q4"] == pytest.approx(sine(d - e, c - d), abs=1e-9)
    assert sine(B - A, C - B) != pytest.approx(sine(D - E, C - D), abs=1e-3)  # (the legs told apart)


def test_the_command_names_the_wheel_joint(tmp_path):
    path = tmp_path / "wheel_leg.xml"
    path.write_text(wheel_leg())
    one_line_error(screwkit("analyze", path, "--output", "link_BC"), "actuated joint 'wheel_joint' rides on the "
                   "platform", "--lock wheel_joint holds it")
    read = screwkit("analyze", path, "--output", "link_BC", "--lock", "wheel_joint", "--json")
    assert read.returncode == 0, read.stderr
    assert json.loads(read.stdout)["iti_actuators"]["q1:q1"] == pytest.approx(sine(B - A, C - B), abs=1e-9)
