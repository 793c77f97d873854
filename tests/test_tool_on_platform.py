"""An output taken on a tool the platform carries: the refusal names the joint to hold and the body to take.

The rod-level Delta with a wrist on its platform (a hinge, driven, carrying a tool body), as a published
onshape-to-robot Delta carries its gripper. With the tool as the output, the wrist is one more actuator on the leg
the platform hangs on, and a leg with loops inside it and several actuators is refused: the refusal now says the
wrist turns the output after the body where the legs' loops end, and that ``--lock wrist`` holds it or
``--output platform`` takes that body. Held, the tool reads the platform's indices (it moves with it); in m, mm
and a turned world.
"""

from __future__ import annotations

import numpy as np
import pytest
from delta_rods import delta_rods_mjcf
from test_graph_legs import POSES

from helpers import random_rotation
from screwkit.io import ImportError_, read_closed_tree
from screwkit.io.graph import graph_mechanism

TRANSFORMS = {"m": None, "mm": (1000.0, np.eye(3), np.zeros(3)),
              "turned": (1.0, random_rotation(np.random.default_rng(8)), np.array([0.3, -1.2, 2.0]))}


def _with_wrist(tmp_path, transform) -> str:
    scale = 1.0 if transform is None else transform[0]
    text = delta_rods_mjcf(POSES[0], transform=transform)
    site = text.index("/>", text.index('<site name="centre"')) + 2
    wrist = (f'<body name="tool" pos="0 0 {-0.05 * scale!r}"><joint name="wrist" type="hinge" axis="0 0 1"/>'
             '<geom type="sphere" size="0.01"/></body>')
    text = text[:site] + wrist + text[site:]
    text = text.replace("</actuator>", '<motor name="m_wrist" joint="wrist"/></actuator>')
    path = tmp_path / "delta_wrist.xml"
    path.write_text(text)
    return path


@pytest.mark.parametrize("variant", sorted(TRANSFORMS))
def test_a_tool_as_the_output_is_refused_naming_the_wrist_and_the_platform(tmp_path, variant):
    path = _with_wrist(tmp_path, TRANSFORMS[variant])
    with pytest.raises(ImportError_, match="actuated joint 'wrist' turns the output after the body where the legs' "
                                           "loops end \\('platform'\\), as a tool the platform carries: --lock wrist "
                                           "holds it, or --output platform takes that body"):
        graph_mechanism(read_closed_tree(path, output="tool"))
    held = graph_mechanism(read_closed_tree(path, output="tool", lock=("wrist",))).indices()
    platform = graph_mechanism(read_closed_tree(path, output="platform")).indices()
    np.testing.assert_allclose(held.iti_actuators, platform.iti_actuators, atol=1e-9)
    np.testing.assert_allclose([held.lmti, held.f_o[1]], [platform.lmti, platform.f_o[1]], atol=1e-9)
