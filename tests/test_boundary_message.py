"""A pose on the boundary of the workspace to rounding is refused saying so, not as one outside it.

The parallelogram of ``test_idle_dyad`` (no dyad: serial legs), its coupler's frame the output and x its task
coordinate: x is largest, |AB|, with the crank along x and every pin on one line, a singular configuration. A pose
typed a few ulps beyond it is refused (the Newton steps on y and phi miss by 1e-11 of the length scale), and the
refusal said "the pose is outside the workspace"; it now says that the pose is on the boundary to rounding, where
chains stretch or fold. A pose 1e-6 or 1e-4 of its size beyond still reads as outside. In metres, and with every
length times 1e-3 and 1e3.
"""

from __future__ import annotations

import numpy as np
import pytest
from test_idle_dyad import A, B, linkage

from screwkit.closure import UnreachablePose, solve_one
from screwkit.io.loader import load


@pytest.mark.parametrize("scale", [1.0, 1e-3, 1e3])
def test_a_pose_beyond_the_boundary_by_rounding_is_said_to_be_on_it(tmp_path, scale):
    path = tmp_path / "parallelogram.xml"
    path.write_text(linkage(scale, dyad=None))
    mechanism = load(path, output="coupler", output_type="frame")
    assert mechanism.task_coordinates == ("x",) and mechanism.dof == 1
    reach = float(np.linalg.norm(B - A)) * scale
    with pytest.raises(UnreachablePose, match="the pose is on the boundary of the workspace to rounding, where "
                                              "chains stretch or fold"):
        solve_one(mechanism, [reach + 1e-10 * scale])
    for beyond in (1e-6, 1e-4):  # (the same words at every size: a millimetre linkage read "on the boundary" 1e-6
        with pytest.raises(UnreachablePose, match="the pose is outside the workspace"):  # of its size beyond it)
            solve_one(mechanism, [reach + beyond * scale])
