"""A hinge a CAD export tilts by its quaternion's floating-point noise, in a planar linkage whose other hinges are
written exactly parallel.

An excavator's bucket linkage (published without a licence; its structure is written anew here) places its cylinder
on a body turned by ``quat="0.679624 1.9812e-07 0.733561 1.9812e-07"``: the two tiny components, noise of the export,
tilt the cylinder's hinge 5.6e-7 rad off the four others, written ``0 1 0``. The axes within the file's rounding were
made parallel to their mean, 1.1e-7 rad off the four: the two rockers drawn one behind the other (0.34 m apart along
the hinges) then stood 3.7e-8 m apart across them, no longer on one line, and the linkage read rigid. The common
direction is now the one more than half of a group is written along exactly (``screwkit.io.rounding.parallel_axes``):
the linkage reads as the same file written without the noise, in metres, millimetres and a moved world.
"""

from __future__ import annotations

import numpy as np
import pytest

from helpers import MJCF_WORLDS, mjcf_variant
from screwkit.io.loader import converted_mechanism
from screwkit.io.rounding import parallel_axes
from screwkit.studies.poses import indices_at_pose

NOISY = "0.68 1.9812e-07 0.7334 1.9812e-07"
"""The cylinder body's orientation, with the export's noise."""


def bucket(scale: float = 1.0, world=("0 0 0", "1 0 0 0"), quat: str = NOISY) -> str:
    """A bucket on an actuated hinge, its link pinned to a passive cylinder (hinge, slide, ball) and to two rockers
    (hinge, ball) one behind the other, every hinge along y; lengths times ``scale``, the whole in a body at
    ``world``."""
    def at(*values) -> str:
        return " ".join(repr(v * scale) for v in values)

    return (f'<mujoco model="bucket"><option><flag contact="disable"/></option><worldbody>'
            f'<body name="stick" pos="{world[0]}" quat="{world[1]}"><geom size="{0.02 * scale!r}"/>'
            f'<body name="cyl" pos="{at(0.4, 0, 0.77)}" quat="{quat}"><joint name="jCyl" axis="0 -1 0"/>'
            f'<geom size="{0.02 * scale!r}"/><body name="rod" pos="{at(0, 0, 1.07)}">'
            f'<joint name="jRod" type="slide" axis="0 0 -1"/><geom size="{0.02 * scale!r}"/>'
            f'<site name="rod_end" pos="{at(0, 0, 1.46)}"/></body></body>'
            + "".join(f'<body name="rocker_{side}" pos="{at(2.46, y, 0.17)}" quat="0.9115 0 0.4113 0">'
                      f'<joint name="j_{side}" axis="0 1 0"/><geom size="{0.02 * scale!r}"/>'
                      f'<site name="{side}" pos="{at(0, 0, 0.62)}"/></body>' for side, y in (("l", 0.17), ("r", -0.17)))
            + f'<body name="bucket" pos="{at(2.91, 0, 0.15)}" quat="0.7413 0 0.6712 0"><joint name="jBucket" '
            f'axis="0 1 0"/><geom size="{0.02 * scale!r}"/><body name="link" pos="{at(-0.104, 0, 0.591)}" '
            f'quat="0.9647 0 0.2635 0"><joint name="jLink" axis="0 -1 0"/><geom size="{0.02 * scale!r}"/>'
            + "".join(f'<site name="link_{side}" pos="{at(0, y, -0.63)}"/>'
                      for side, y in (("l", 0.17), ("m", 0.0), ("r", -0.17)))
            + '</body></body></body></worldbody><equality><connect site1="r" site2="link_r"/>'
            '<connect site1="l" site2="link_l"/><connect site1="rod_end" site2="link_m"/></equality>'
            '<actuator><position joint="jBucket"/></actuator></mujoco>')


@pytest.mark.parametrize("variant", sorted(MJCF_WORLDS))
def test_a_hinge_tilted_by_a_quaternion_s_noise_reads_as_the_linkage_written_without_it(tmp_path, variant):
    noisy, unit = mjcf_variant(tmp_path, "noisy", variant, bucket)
    exact, _ = mjcf_variant(tmp_path, "exact", variant, lambda scale, world: bucket(scale, world, "0.68 0 0.7334 0"))
    (_, report, got), (_, _, want) = (converted_mechanism(path, length_unit=unit) for path in (noisy, exact))
    assert got.dof == want.dof == 1
    a, b = indices_at_pose(got, got.home_pose), indices_at_pose(want, want.home_pose)
    np.testing.assert_allclose([a.iti, a.lmti, a.cti], [b.iti, b.lmti, b.cti], atol=1e-9)
    assert any("written parallel (the largest turn 5.6e-07 rad, of joint 'jCyl')" in note for note in report.notes)


def test_the_common_direction_is_the_exact_majority_s_else_the_mean():
    tilted = np.array([1e-6, 1.0, 0.0])
    turned, turn = parallel_axes(np.array([[0.0, 1.0, 0.0]] * 3 + [tilted]))
    np.testing.assert_array_equal(turned, [[0.0, 1.0, 0.0]] * 4)  # three of four exact: theirs
    assert turn == pytest.approx(1e-6, rel=1e-6)
    turned, _ = parallel_axes(np.array([[0.0, 1.0, 0.0], [0.0, 1.0, 0.0], tilted, -tilted]))
    np.testing.assert_allclose(turned[0], [5e-7, 1.0, 0.0], atol=1e-12)  # half: the mean (senses kept)
    np.testing.assert_allclose(turned[3], -turned[0], atol=0)
