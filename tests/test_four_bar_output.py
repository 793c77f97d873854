"""A four-bar written as a hand-made MJCF knee is (a published humanoid leg's): the crank on the base, the coupler and
the rocker hung beyond it, the rocker's end ``<connect>``-ed back to the base.

Taken as the platform, the crank has the loop close beyond it, on the coupler's and rocker's hinges. The refusal used
to advise holding both: a four-bar with two of its hinges held is a structure (MuJoCo: no motion left), and the next
run said DOF 0. An advice to hold joints is now checked first (the platform must keep a motion); here the refusal
names ``--output`` instead, and the coupler taken as the platform opens with the textbook four-bar's indices.
"""

from __future__ import annotations

import json

import mujoco
import numpy as np
import pytest

from helpers import mujoco_rows, one_line_error, screwkit
from screwkit.io import ImportError_
from screwkit.io.loader import load
from screwkit.studies import indices_at_pose

A, B, C, D = (np.array(p) for p in ([0.0, 0.0, 0.0], [0.05, 0.08, 0.0], [0.20, 0.10, 0.0], [0.16, -0.02, 0.0]))
"""The crank's pivot A on the base, the crank-coupler pin B, the coupler-rocker pin C, the rocker's pivot D on the base
(every axis along z)."""


def four_bar_mjcf(single: bool = False, tilt: float = 0.0, scale: float = 1.0, world=("0 0 0", "1 0 0 0")) -> str:
    """The knee's MJCF text: every body's frame at its first joint's pin but the coupler's, at C (its output point);
    ``single``: the rocker's pivot one ``<connect>`` (a ball, as the published knee writes it), not two on its axis;
    ``tilt``: the crank's axis turned that far (rad) about x; ``scale`` multiplies every length, ``world`` (``pos``,
    ``quat`` texts) places the base."""
    def text(point, factor=scale) -> str:
        return " ".join(repr(float(v) * factor) for v in point)

    sphere = f'<geom type="sphere" size="{0.005 * scale!r}"/>'
    axis = text([0.0, -np.sin(tilt), np.cos(tilt)], 1.0)
    return (f'<mujoco model="knee"><worldbody><body name="base" pos="{world[0]}" quat="{world[1]}">{sphere}'
            f'<body name="crank"><joint name="crank" type="hinge" axis="{axis}" pos="{text(A)}"/>{sphere}'
            f'<body name="coupler" pos="{text(C)}"><joint name="coupler" type="hinge" axis="0 0 1" '
            f'pos="{text(B - C)}"/>{sphere}'
            f'<body name="rocker"><joint name="rocker" type="hinge" axis="0 0 1"/>{sphere}'
            '</body></body></body></body></worldbody><equality>'
            f'<connect name="pivot" body1="rocker" body2="base" anchor="{text(D - C)}"/>'
            + ("" if single else
               f'<connect name="pivot_z" body1="rocker" body2="base" anchor="{text(D - C + [0.0, 0.0, 0.01])}"/>')
            + '</equality><actuator><motor name="m" joint="crank"/></actuator></mujoco>')


def mobility(model, free) -> int:
    """MuJoCo's own count: the velocities ``free`` (the others held) that keep the connects closed."""
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    jacobian = mujoco_rows(model, data)[:, free]
    return len(free) - int(np.linalg.matrix_rank(jacobian, tol=1e-9))


@pytest.fixture
def knee(tmp_path):
    path = tmp_path / "knee.xml"
    path.write_text(four_bar_mjcf())
    return path


def test_mujoco_reads_one_motion_and_none_with_the_coupler_and_rocker_held(knee):
    model = mujoco.MjModel.from_xml_string(four_bar_mjcf())
    assert model.nv == 3 and mobility(model, [0, 1, 2]) == 1 and mobility(model, [0]) == 0


def test_the_crank_as_platform_is_refused_naming_the_output_not_a_hold_that_leaves_a_structure(knee):
    with pytest.raises(ImportError_) as refused:
        load(knee, output="crank")
    assert "--lock" not in str(refused.value.held) and "would leave the platform no motion (a structure): --output " \
        "names another platform" in str(refused.value.held)
    message = one_line_error(screwkit("analyze", knee, "--output", "crank"))
    assert message.endswith("beyond the platform: not a loop joint screwkit supports; held, they would leave the "
                            "platform no motion (a structure): --output names another platform, a body the loops "
                            "reach from the base.")


def sine(u, v) -> float:
    return abs(float(u[0] * v[1] - u[1] * v[0])) / np.linalg.norm(u) / np.linalg.norm(v)


def test_the_coupler_as_platform_has_the_textbook_four_bar_indices(knee):
    """With the coupler as the platform (its output point the pin C), the crank drives C through the coupler BC and
    the rocker makes C move normal to DC: ITI = |sin(AB, BC)|, OTI = |sin(BC, DC)| (the five-bar's pressure angles,
    ``docs/theory.md``, *Point outputs*), as the published knee's check found them."""
    mechanism = load(knee, output="coupler")
    result = indices_at_pose(mechanism, mechanism.home_pose)
    assert mechanism.dof == 1
    np.testing.assert_allclose(np.ravel(result.iti_actuators), [sine(B - A, C - B)], atol=1e-9)
    np.testing.assert_allclose(result.lmti, sine(C - B, C - D), atol=1e-9)
    assert 0.2 < sine(B - A, C - B) < 0.95 and 0.2 < sine(C - B, C - D) < 0.95


def test_a_ball_pivot_in_a_knee_whose_axis_is_tilted_is_refused_saying_so(tmp_path):
    """The published knee writes its rocker's pivot as one ball, and its crank's axis is 0.046 deg out of parallel
    with the others (a right angle written 1.57). Here the tilt is written in the axis's direction to 17 digits,
    which no rounding explains: the mechanism is not planar, and such a ball pivot is read in a planar mechanism
    only. The refusal gives the angle and what the file's rounding allows (the published knee itself, whose
    rounded angles allow it, opens: ``tests/test_written_angles.py``). Written exactly, the same knee opens with the
    four-bar's pressure angles."""
    (tmp_path / "tilted.xml").write_text(four_bar_mjcf(single=True, tilt=np.pi / 2 - 1.57))
    message = one_line_error(screwkit("analyze", tmp_path / "tilted.xml", "--output", "coupler"))
    assert message.endswith("in a planar mechanism only (revolute axes 'crank' and 'coupler' are 0.046 deg out of "
                            "parallel, more than the file's rounding allows them: 0.00057 deg).")
    (tmp_path / "exact.xml").write_text(four_bar_mjcf(single=True))
    mechanism = load(tmp_path / "exact.xml", output="coupler")
    result = indices_at_pose(mechanism, mechanism.home_pose)
    np.testing.assert_allclose([float(np.ravel(result.iti_actuators)[0]), result.lmti],
                               [sine(B - A, C - B), sine(C - B, C - D)], atol=1e-9)


@pytest.mark.parametrize("scale", [1e-3, 1e3])
def test_the_knee_reads_the_same_in_other_scales_and_a_moved_world(tmp_path, scale):
    """The refusal of the crank as platform, and the coupler's indices, in a knee a thousand times smaller or larger
    (read in metres) and placed elsewhere in the world."""
    world = (f"{0.4 * scale!r} {-0.3 * scale!r} {1.1 * scale!r}", "0.8 0.3 -0.4 0.33")
    path = tmp_path / "knee.xml"
    path.write_text(four_bar_mjcf(scale=scale, world=world))
    with pytest.raises(ImportError_) as refused:
        load(path, output="crank")
    assert "would leave the platform no motion (a structure): --output names another platform" in str(
        refused.value.held)
    mechanism = load(path, output="coupler")
    result = indices_at_pose(mechanism, mechanism.home_pose)
    np.testing.assert_allclose([float(np.ravel(result.iti_actuators)[0]), result.lmti],
                               [sine(B - A, C - B), sine(C - B, C - D)], atol=1e-9)



def _carrying_a_loop(scale: float = 1.0, world=("0 0 0", "1 0 0 0")) -> str:
    """The knee with a loop of its own on the coupler: two links hung from it, closed by a ``<connect>`` (a tool, as
    a biped's ankle rods ride on the shin taken as the platform)."""
    def at(*values) -> str:
        return " ".join(repr(v * scale) for v in values)

    ball = f'<geom type="sphere" size="{0.002 * scale!r}"/>'
    tool = (f'<body name="tool_a" pos="{at(0.01, 0, 0)}"><joint name="ta" type="hinge" axis="0 0 1"/>{ball}'
            f'<body name="tool_a2" pos="{at(0.02, 0, 0)}"><joint name="ta2" type="hinge" axis="0 0 1"/>{ball}'
            f'</body></body><body name="tool_b" pos="{at(0.01, 0.02, 0)}"><joint name="tb" type="hinge" '
            f'axis="0 0 1"/>{ball}</body>')
    text = four_bar_mjcf(scale=scale, world=world)
    start = text.index('<joint name="coupler"')
    end = text.index("/>", start) + 2
    closure = f'<connect name="tool" body1="tool_b" body2="tool_a2" anchor="{at(0.01, -0.02, 0)}"/>'
    return (text[:end] + tool + text[end:]).replace("</equality>", closure + "</equality>")


@pytest.mark.parametrize("variant", ["m", "mm", "turned"])
def test_a_loop_the_platform_carries_is_left_out(tmp_path, variant):
    """A loop riding on the platform was refused ("a loop the platform carries"), whatever was held, so that a
    biped's knee with its ankle rods on the shin, or an excavator's boom carrying its arm and bucket linkages, could
    not be read. It is left out and said, and the knee reads as the knee alone: the textbook four-bar's pressure
    angles at the pin C where the legs meet, ITI = |sin(AB, BC)| and OTI = |sin(BC, DC)|."""
    scale, unit, world = {"m": (1.0, None, ("0 0 0", "1 0 0 0")), "mm": (1000.0, "mm", ("0 0 0", "1 0 0 0")),
                          "turned": (1.0, None, ("0.4 -0.3 1.1", "0.8 0.3 -0.4 0.33"))}[variant]
    path = tmp_path / "carrying.xml"
    path.write_text(_carrying_a_loop(scale, world))
    model = mujoco.MjModel.from_xml_path(str(path))
    assert mobility(model, list(range(model.nv))) == 2  # the knee's motion and the tool's own
    run = screwkit("analyze", path, "--output", "coupler", "--json", *(["--length-unit", unit] if unit else []))
    assert run.returncode == 0, run.stderr
    assert "closure(s) 'tool': loop(s) the platform carries (both frames beyond it), joined to no leg: left out" \
        in run.stdout
    result = json.loads(run.stdout)
    assert (result["iti"], result["lmti"]) == pytest.approx((sine(B - A, C - B), sine(C - B, C - D)), abs=1e-9)
