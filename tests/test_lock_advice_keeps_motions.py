"""An advice to hold joints beyond the platform is given only where holding them keeps every platform motion.

A five-bar leg (a published rat robot's, NeRmo's, written small here): the hip motor and the knee carry the foot;
a hinge on the foot carries a link that a servo's horn is pinned to. Asked for a point output at the foot's toe,
the serial reading cannot end the horn's leg on a joint beyond the foot, and advised holding that hinge: held, the
foot keeps one of its two motions, and the leg read "2 actuators, 1 DOF (1 redundant)", another mechanism. Now the
refusal says what holding it would take away and names --output instead; the foot's frame reads the leg as a graph,
2 DOF. MuJoCo's own count of the foot's motions (its body Jacobian on the null space of the connect's rows) is the
reference, in m, mm and a turned world.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest

from helpers import MJCF_WORLDS, mjcf_variant, mujoco_rows, one_line_error, screwkit
from screwkit.io import ImportError_, read_closed_tree
from screwkit.io.graph import graph_mechanism
from screwkit.io.loader import load


def bent_leg(scale: float = 1.0, world=("0 0 0", "1 0 0 0")) -> str:
    """The leg's MJCF text, every length times ``scale``, its base placed by ``world`` (``pos``, ``quat`` texts)."""
    def at(*values) -> str:
        return " ".join(repr(v * scale) for v in values)

    ball = f'<geom type="sphere" size="{0.005 * scale!r}"/>'
    return (f'<mujoco model="bent_leg"><worldbody><body name="base" pos="{world[0]}" quat="{world[1]}">'
            f'<body name="upper"><joint name="hip" type="hinge" axis="0 0 1"/>{ball}'
            f'<body name="foot" pos="{at(0.1, -0.02, 0)}"><joint name="knee" type="hinge" axis="0 0 1"/>{ball}'
            f'<site name="toe" pos="{at(0.08, -0.05, 0)}"/>'
            f'<body name="link" pos="{at(0.03, 0.09, 0)}"><joint name="bend" type="hinge" axis="0 0 1"/>{ball}'
            '</body></body></body>'
            f'<body name="horn" pos="{at(0.06, 0.12, 0)}"><joint name="servo" type="hinge" axis="0 0 1"/>{ball}'
            '</body></body></worldbody><equality>'
            f'<connect name="pin" body1="horn" body2="link" anchor="{at(0.04, -0.01, 0)}"/></equality>'
            '<actuator><motor name="m1" joint="hip"/><motor name="m2" joint="servo"/></actuator></mujoco>')


@pytest.fixture(params=sorted(MJCF_WORLDS))
def leg(request, tmp_path):
    return mjcf_variant(tmp_path, "leg", request.param, bent_leg)


def _foot_motions(path: Path, held: tuple[str, ...]) -> int:
    """MuJoCo's count of the foot's motions at the file's configuration with the joints ``held`` (and the connect)."""
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    rows = mujoco_rows(model, data)
    free = [model.jnt_dofadr[model.joint(k).id] for k in range(model.njnt) if model.joint(k).name not in held]
    _, singular, right = np.linalg.svd(rows[:, free])
    null = right[int(np.sum(singular > 1e-9)):]
    position, rotation = np.zeros((3, model.nv)), np.zeros((3, model.nv))
    mujoco.mj_jacBody(model, data, position, rotation, model.body("foot").id)
    twist = np.vstack([rotation, position / np.abs(data.xpos).max()])[:, free]
    return int(np.sum(np.linalg.svd(twist @ null.T, compute_uv=False) > 1e-9))


def test_holding_the_hinge_would_take_a_motion_away(leg):
    path, unit = leg
    assert (_foot_motions(path, ()), _foot_motions(path, ("bend",))) == (2, 1)
    with pytest.raises(ImportError_, match="held, it would leave the platform 1 of its 2 motions") as refused:
        load(path, length_unit=unit, output="toe", output_type="point")
    assert "--lock" not in str(refused.value)
    graph = graph_mechanism(read_closed_tree(path, output="toe", length_unit=unit))
    assert len(graph.task_axes) == 2
    assert "output frame 'toe' on body 'foot'" in graph.report.lines()[0]  # the site named, not the body's frame


def test_the_command_refuses_the_point_without_advising_the_hold(tmp_path):
    path = tmp_path / "leg.xml"
    path.write_text(bent_leg())
    refused = screwkit("analyze", path, "--output", "toe", "--output-type", "point")
    line = one_line_error(refused, "1 of its 2 motions", "--output")
    assert "--lock" not in line
    read = screwkit("analyze", path, "--output", "toe")
    assert read.returncode == 0 and "2 actuators, 2 DOF (no redundancy)" in read.stdout, read.stderr
