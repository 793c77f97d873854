"""A four-bar whose coupler is the output, its loop closed at either of the coupler's pins.

robosuite's Robotiq-85 finger closes its four-bar at the crank's pin B, xArm's gripper at the rocker's pin C. With
the coupler as the platform the default output was the point where the legs meet, the closure's pin: at C the
linkage's transmission (ITI = |sin(BC, AB)|, OTI = |sin(BC, DC)|), at B a point of the crank itself, which the
actuator turns alone: ITI = OTI = 1 at every pose (the published finger read 1.0000 where its transmission falls
to 0.39). Closed at the crank's pin, the coupler's frame is read instead, and said; the frame reads the same
whichever pin closes the loop. Checked against MuJoCo's placement of the pins in m, mm and a moved, turned world.
"""

from __future__ import annotations

import numpy as np
import pytest

from helpers import MJCF_WORLDS, mjcf_variant, mujoco_closed, screwkit_json, sine
from screwkit.io.loader import load
from screwkit.studies import indices_at_pose

A, B = np.array([0.0, 0.0, 0.0]), np.array([0.04, 0.0, 0.08])
C, D = np.array([0.16, 0.0, 0.1]), np.array([0.15, 0.0, -0.02])
"""The crank's pivot A and pin B, the rocker's pin C and pivot D (the plane y = 0, every hinge along y)."""


def four_bar(scale: float = 1.0, world=("0 0 0", "1 0 0 0"), cut: str = "C") -> str:
    """The linkage's MJCF text, its loop closed by a connect at the pin ``cut`` ("B" or "C")."""
    def at(point) -> str:
        return " ".join(repr(float(v) * scale) for v in point)

    ball = f'<geom type="sphere" size="{0.004 * scale!r}"/>'
    hinge = '<joint name="{}" type="hinge" axis="0 1 0"/>' + ball
    if cut == "C":
        crank = (f'<body name="crank" pos="{at(A)}">{hinge.format("crank")}'
                 f'<body name="coupler" pos="{at(B - A)}">{hinge.format("bpin")}</body></body>')
        rocker = f'<body name="rocker" pos="{at(D)}">{hinge.format("rocker")}</body>'
        closure = f'<connect name="pin" body1="rocker" body2="coupler" anchor="{at(C - D)}"/>'
    else:
        crank = f'<body name="crank" pos="{at(A)}">{hinge.format("crank")}</body>'
        rocker = (f'<body name="rocker" pos="{at(D)}">{hinge.format("rocker")}'
                  f'<body name="coupler" pos="{at(C - D)}">{hinge.format("cpin")}</body></body>')
        closure = f'<connect name="pin" body1="crank" body2="coupler" anchor="{at(B - A)}"/>'
    return ('<mujoco model="four_bar"><option><flag contact="disable"/></option><worldbody>'
            f'<body name="base" pos="{world[0]}" quat="{world[1]}">{crank}{rocker}</body></worldbody>'
            f'<equality>{closure}</equality><actuator><motor name="m" joint="crank"/></actuator></mujoco>')


def _indices(path, unit, **options):
    mechanism = load(path, output="coupler", length_unit=unit, **options)
    result = indices_at_pose(mechanism, mechanism.home_pose)
    cti = np.ravel(result.cti)
    return mechanism, (float(result.iti), float(result.lmti), float(cti[0]) if cti.size else None)


@pytest.mark.parametrize("variant", sorted(MJCF_WORLDS))
def test_closed_at_the_rocker_the_point_reads_the_linkage_and_at_the_crank_the_frame_is_read(tmp_path, variant):
    at_c, unit = mjcf_variant(tmp_path, "cut_c", variant, lambda s, w: four_bar(s, w, "C"))
    at_b, _ = mjcf_variant(tmp_path, "cut_b", variant, lambda s, w: four_bar(s, w, "B"))
    _, _, anchor = mujoco_closed(at_c)
    a, b, d = anchor["crank"], anchor["bpin"], anchor["rocker"]
    _, _, other = mujoco_closed(at_b)
    c = other["cpin"]
    assert np.linalg.norm(other["crank"] - a) < 1e-12 and np.linalg.norm(other["rocker"] - d) < 1e-12
    mechanism, (iti, lmti, _) = _indices(at_c, unit)
    assert mechanism.output_point is not None
    assert (iti, lmti) == pytest.approx((sine(c - b, b - a), sine(c - b, c - d)), abs=1e-9)
    mechanism, frame = _indices(at_b, unit)
    assert mechanism.output_point is None
    assert any("not the point where the legs meet (closure 'pin'): it is on the link actuated joint 'crank'" in line
               for line in mechanism.import_report)
    _, expected = _indices(at_c, unit, output_type="frame")
    assert frame == pytest.approx(expected, abs=1e-9)  # the frame: the same whichever pin closes the loop
    _, (iti, lmti, _) = _indices(at_b, unit, output_type="point")  # the crank's own point, asked for
    assert (iti, lmti) == pytest.approx((1.0, 1.0), abs=1e-9)
    assert sine(c - b, b - a) < 0.99  # (the linkage's transmission told apart from 1)


def test_the_command_says_it_reads_the_frame(tmp_path):
    path = tmp_path / "cut_b.xml"
    path.write_text(four_bar(cut="B"))
    result = screwkit_json("analyze", path, "--output", "coupler")
    assert any("not the point where the legs meet" in line for line in result["converted"])
    assert (result["iti"], result["lmti"]) == pytest.approx((1.0, 1.0), abs=1e-9)
