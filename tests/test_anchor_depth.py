"""A closure whose two anchors sit at different depths on one pin: the gap lies along the loop's hinge axes.

A CAD-exported wheel leg writes each connect's two sites a few millimetres apart along the (parallel) pins; MuJoCo
runs it with a constant violation, and screwkit's refusal advised ``--initial`` values, which cannot help: every
joint of the loop turns about an axis along that gap, so no joint values change it. The refusal now says where the
gap lies and what closes it, and the same file with the anchors on one plane reads.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from test_mjcf_base_sites import four_bar

from helpers import MJCF_WORLDS, mjcf_variant, one_line_error, screwkit
from screwkit.io.loader import load

DEPTH = 0.004
"""How far along the pins (y) the rocker's site is drawn from the ground's, in the file's length unit per metre."""


def deep(scale: float = 1.0, world=("0 0 0", "1 0 0 0"), depth: float = DEPTH) -> str:
    return four_bar(scale, world).replace(f'<site name="D_link" pos="{0.0 * scale!r} {0.0 * scale!r}',
                                          f'<site name="D_link" pos="{0.0 * scale!r} {depth * scale!r}')


def _gap(path, values) -> np.ndarray:
    """MuJoCo's connect residual (world) at the joint values ``values``."""
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    data.qpos[:] = values
    mujoco.mj_forward(model, data)
    rows = [k for k in range(data.nefc) if data.efc_type[k] == mujoco.mjtConstraint.mjCNSTR_EQUALITY]
    return data.efc_pos[rows]


@pytest.mark.parametrize("variant", sorted(MJCF_WORLDS))
def test_a_gap_along_the_pins_is_named_and_the_anchors_on_one_plane_read(tmp_path, variant):
    path, unit = mjcf_variant(tmp_path, "deep", variant, deep)
    scale = MJCF_WORLDS[variant][0]
    for values in ([0.0, 0.0, 0.0], [0.3, -0.5, 0.2]):  # MuJoCo: the same gap along the pins, whatever the joints
        assert np.linalg.norm(_gap(path, values)) >= DEPTH * scale * (1 - 1e-9)
    assert 'pos="0.0 0.004' in deep() and 'pos="0.0 0.004' not in four_bar()
    with pytest.raises(ValueError, match="its gap lies along the parallel axes of its loop's hinges .*its two "
                                         "anchors drawn at different depths on one pin"):
        load(path, output="coupler", length_unit=unit)
    flat, _ = mjcf_variant(tmp_path, "flat", variant, four_bar)
    assert load(flat, output="coupler", length_unit=unit).dof == 1


def test_the_command_names_the_depth(tmp_path):
    path = tmp_path / "deep.xml"
    path.write_text(deep())
    message = one_line_error(screwkit("analyze", path, "--output", "coupler"), "its gap lies along the parallel axes")
    assert "--initial" not in message
