"""A point output of a linkage that cannot move says why, as a frame output does.

A published hand's four-bar fingers draw a rocker's axis a few hundredths of a degree off its loop's: MuJoCo's
constraint Jacobian leaves such a finger no motion. Read with a point output (the point where its legs meet), the
refusal said "every platform motion is a rotation about it", which hid the cause; the platform itself cannot move,
and the refusal now says so as a frame output's does, naming the chains that lock it and the axis out of line.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from helpers import MJCF_WORLDS, mjcf_variant, mujoco_rows, one_line_error, screwkit
from screwkit.io.loader import load
from screwkit.studies import indices_at_pose


def finger(scale: float = 1.0, world=("0 0 0", "1 0 0 0"), rocker_axis: str = "0 1 0") -> str:
    """A crank A-B driving a coupler (the platform) whose tip C a rocker from D holds, the rocker's pin a connect at
    C; every hinge along y but the rocker's, ``rocker_axis``."""
    def at(*values) -> str:
        return " ".join(repr(v * scale) for v in values)

    ball = f'<geom type="sphere" size="{0.01 * scale!r}"/>'
    return ('<mujoco model="finger"><option><flag contact="disable"/></option><worldbody>'
            f'<body name="base" pos="{world[0]}" quat="{world[1]}">{ball}'
            f'<body name="crank"><joint name="jA" type="hinge" axis="0 1 0"/>{ball}'
            f'<body name="coupler" pos="{at(0, 0, 0.1)}"><joint name="jB" type="hinge" axis="0 1 0"/>{ball}'
            '</body></body>'
            f'<body name="rocker" pos="{at(0.3, 0, 0.02)}"><joint name="jD" type="hinge" axis="{rocker_axis}"/>{ball}'
            '</body></body></worldbody><equality>'
            f'<connect name="C" body1="rocker" body2="coupler" anchor="{at(0, 0, 0.18)}"/></equality>'
            '<actuator><motor name="m" joint="jA"/></actuator></mujoco>')


def _mobility(path) -> int:
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    return model.nv - int(np.linalg.matrix_rank(mujoco_rows(model, data), tol=1e-9))


@pytest.mark.parametrize("variant", sorted(MJCF_WORLDS))
def test_a_finger_with_its_rocker_out_of_line_is_refused_naming_the_chains(tmp_path, variant):
    path, unit = mjcf_variant(tmp_path, "tilted", variant, lambda s, w: finger(s, w, rocker_axis="0.002 1 0"))
    assert _mobility(path) == 0  # MuJoCo: no motion (0.11 deg out of line)
    with pytest.raises(ValueError, match="the platform cannot move: its chains leave it no motion .* any one chain "
                                         "left out, the others would let it move \\(chains jA .*, jD .*joint axis "
                                         "slightly out of line"):
        load(path, length_unit=unit)
    straight, _ = mjcf_variant(tmp_path, "straight", variant, finger)
    assert _mobility(straight) == 1
    mechanism = load(straight, length_unit=unit)  # (the point C, as before)
    a, b, c = np.array([0.0, 0, 0]), np.array([0.0, 0, 0.1]), np.array([0.3, 0, 0.2])
    expected = np.linalg.norm(np.cross(b - a, c - b)) / (np.linalg.norm(b - a) * np.linalg.norm(c - b))
    assert float(indices_at_pose(mechanism, mechanism.home_pose).iti) == pytest.approx(expected, abs=1e-9)


def test_the_command_names_the_chains(tmp_path):
    path = tmp_path / "tilted.xml"
    path.write_text(finger(rocker_axis="0.002 1 0"))
    one_line_error(screwkit("analyze", path), "the platform cannot move", "any one chain left out")
