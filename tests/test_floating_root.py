"""An export that writes ``<freejoint>`` on its root body: the refusal names the floating base, not a loop.

onshape-to-robot writes every MJCF export's root with a free joint. A gripper driven by a crank through a closed
loop was refused as "moves inside a loop of leg 'base' ... the leg has no serial input", with the right option
(``--lock`` the free joint) but the wrong cause: nothing moves inside a loop; the actuator rides on a body that
floats. The slider-crank of ``test_limit_slack`` with its base floating: the refusal names the free joint, and the
option it gives reads the crank's |sin(OB, BC)|.
"""

from __future__ import annotations

import pytest
from test_limit_slack import B, C, O, slider_crank

from helpers import one_line_error, screwkit, screwkit_json, sine
from screwkit.io import ImportError_, read_closed_tree
from screwkit.io.graph import graph_mechanism


def floating(tmp_path):
    path = tmp_path / "floating.xml"
    path.write_text(slider_crank().replace('quat="1 0 0 0">', 'quat="1 0 0 0"><freejoint name="float"/>', 1))
    return path


def test_the_graph_reading_names_the_free_joint_the_actuator_rides_on(tmp_path):
    with pytest.raises(ImportError_, match=r"actuated joint 'crank' rides on the free joint 'float' \(a floating base"
                                           r", as an export writes <freejoint> on its root\): --lock float holds the "
                                           "base where the file puts it"):
        graph_mechanism(read_closed_tree(floating(tmp_path), output="slider"))


def test_the_command_gives_the_option_that_reads_it(tmp_path):
    path = floating(tmp_path)
    one_line_error(screwkit("analyze", path, "--output", "slider"), "rides on the free joint 'float'", "--lock float")
    found = screwkit_json("analyze", path, "--output", "slider", "--lock", "float")
    assert found["iti"] == pytest.approx(sine(B - O, C - B), abs=1e-12)
