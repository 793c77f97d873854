"""An output taken on a tool the platform carries: the refusal names the joint to hold and the body to take.

The rod-level Delta with a wrist on its platform (a hinge, driven, carrying a tool body), as a published
onshape-to-robot Delta carries its gripper. With the tool as the output, the wrist is one more actuator on the leg
the platform hangs on, and a leg with loops inside it and several actuators is refused: the refusal now says the
wrist turns the output after the body where the legs' loops end, and that ``--lock wrist`` holds it or
``--output platform`` takes that body. Held, the tool reads the platform's indices (it moves with it); in m, mm
and a turned world. With it, three more refusals a tester met on published files: a driven joint on the tool alone
(said to be on no leg), a Delta's motor no longer offered as a serial stage to hold, and the closed forms' refusal
naming the mechanism and its driven joints.
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


def _with_wrist(tmp_path, transform, driven: bool = True) -> str:
    scale = 1.0 if transform is None else transform[0]
    text = delta_rods_mjcf(POSES[0], transform=transform)
    site = text.index("/>", text.index('<site name="centre"')) + 2
    wrist = (f'<body name="tool" pos="0 0 {-0.05 * scale!r}"><joint name="wrist" type="hinge" axis="0 0 1"/>'
             '<geom type="sphere" size="0.01"/></body>')
    text = text[:site] + wrist + text[site:]
    if driven:
        text = text.replace("</actuator>", '<motor name="m_wrist" joint="wrist"/></actuator>')
    path = tmp_path / "delta_wrist.xml"
    path.write_text(text)
    return path


def _refused_then_read_held(path, refusal: str) -> None:
    """The tool as the output is refused with ``refusal``; held (``--lock wrist``) it reads the platform's indices."""
    with pytest.raises(ImportError_, match=refusal):
        graph_mechanism(read_closed_tree(path, output="tool"))
    held = graph_mechanism(read_closed_tree(path, output="tool", lock=("wrist",))).indices()
    platform = graph_mechanism(read_closed_tree(path, output="platform")).indices()
    np.testing.assert_allclose(held.iti_actuators, platform.iti_actuators, atol=1e-9)
    np.testing.assert_allclose([held.lmti, held.f_o[1]], [platform.lmti, platform.f_o[1]], atol=1e-9)


@pytest.mark.parametrize("variant", sorted(TRANSFORMS))
def test_a_tool_as_the_output_is_refused_naming_the_wrist_and_the_platform(tmp_path, variant):
    _refused_then_read_held(_with_wrist(tmp_path, TRANSFORMS[variant]),
                            r"actuated joint 'wrist' turns the output after the body where the legs' loops end "
                            r"\('platform'\), as a tool the platform carries: --lock wrist holds it, or --output "
                            "platform takes that body")


@pytest.mark.parametrize("variant", sorted(TRANSFORMS))
def test_a_tool_on_a_free_swivel_as_the_output_is_refused_naming_the_swivel_and_the_platform(tmp_path, variant):
    """The wrist not driven (a published Codian Delta's tool on its passive ``ee_joint``): the refusal named only the
    leg's three actuators, with no advice; it now says the output hangs off the platform by the passive joint, and
    both ways out read the platform's indices."""
    _refused_then_read_held(_with_wrist(tmp_path, TRANSFORMS[variant], driven=False),
                            r"the output hangs off the body where the legs' loops end \('platform'\) by passive "
                            "joint 'wrist', which no actuator turns: --output platform takes that body, or --lock "
                            "wrist holds it")


def test_a_swivel_delta_on_a_driven_rail_is_refused_naming_both_joints_to_hold_in_one_run(tmp_path):
    """The same Delta carried by a driven rail: the refusal named the swivel only, and held, the next run named the
    rail. It now names both ways out and the rail each needs; either reads the platform's indices on a fixed
    base."""
    text = _with_wrist(tmp_path, None, driven=False).read_text()
    fixed = graph_mechanism(read_closed_tree(tmp_path / "delta_wrist.xml", output="platform")).indices()
    rail = (text.replace('<body name="base" ', '<body name="carriage"><joint name="rail" type="slide" axis="1 0 0"/>'
                         '<geom size="0.01"/><body name="base" ', 1)
            .replace("</body></worldbody>", "</body></body></worldbody>")
            .replace("</actuator>", '<motor name="m_rail" joint="rail"/></actuator>'))
    path = tmp_path / "delta_rail.xml"
    path.write_text(rail)
    with pytest.raises(ImportError_, match=r"by passive joint 'wrist', which no actuator turns: --output platform "
                                           r"takes that body, or --lock wrist holds it; and either way the actuated "
                                           r"joint 'rail' carries every other one \(a serial stage before the "
                                           r"parallel part\): --lock rail analyses the legs on the body it turns.$"):
        graph_mechanism(read_closed_tree(path, output="tool"))
    for output, lock in (("tool", ("wrist", "rail")), ("platform", ("rail",))):
        read = graph_mechanism(read_closed_tree(path, output=output, lock=lock)).indices()
        np.testing.assert_allclose(read.iti_actuators, fixed.iti_actuators, atol=1e-9)
        np.testing.assert_allclose([read.lmti, read.f_o[1]], [fixed.lmti, fixed.f_o[1]], atol=1e-9)


def test_a_driven_joint_on_the_tool_alone_is_said_to_be_on_no_leg(tmp_path):
    """``--actuate wrist`` alone: no leg has an actuator, and the refusal now says the joint named is on none."""
    path = _with_wrist(tmp_path, None)
    with pytest.raises(ImportError_, match="no leg has an actuator .*--actuate names the driven joints; 'wrist' is "
                                           "on no leg \\(a tool the platform carries"):
        graph_mechanism(read_closed_tree(path, output="platform", actuate=("wrist",)))


def test_a_delta_motor_shared_by_two_rods_is_not_offered_as_a_serial_stage(tmp_path):
    """The serial reading's refusal of a rod Delta (two rods on each arm share its motor) went on "'motor_1' is
    actuated: if it is a serial stage before the parallel part, --lock motor_1 ...": a Delta's motor carries no other
    motor, and holding it leaves the platform one motion short. It names the graph reading only now."""
    from sdformat_models import delta_sdf

    from screwkit.io import LegWithLoops, read_mechanism_file

    path = tmp_path / "delta.sdf"
    path.write_text(delta_sdf())
    with pytest.raises(LegWithLoops) as refused:
        read_mechanism_file(path)
    assert "share joint 'motor_1'" in str(refused.value) and "--lock" not in str(refused.value)


def test_the_closed_forms_refusal_names_the_mechanism_and_the_driven_joints(tmp_path):
    """``verify`` (the planar closed forms) on the parallelogram read as serial legs: the refusal printed a Python
    tuple, ``actuated (0,)``, and no mechanism; it names both and the way round."""
    from test_idle_dyad import linkage

    from screwkit.io.loader import load
    from screwkit.studies.poses import indices_at_poses

    path = tmp_path / "parallelogram.xml"
    path.write_text(linkage(dyad=None))
    mechanism = load(path, output="coupler", output_type="frame")
    with pytest.raises(ValueError, match="chain 'crank' of 'parallelogram' has 2 joint\\(s\\), actuated: 'crank' "
                                         "\\(the generic path reads it: `analyze`, without the closed forms\\)"):
        indices_at_poses(mechanism, mechanism.home_pose[None], closed_forms=True)
