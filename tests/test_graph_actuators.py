"""``--actuators`` on a mechanism whose legs have loops inside them: posed by its actuators' values.

The graph reading was posed by its platform only, and ``analyze --actuators`` was refused for it (the refusal's
way round, ``--initial`` on each actuator, assembles from the file's values in one go, which may land on another
assembly). ``GraphMechanism.at_actuators`` moves the actuators from the current configuration in steps, the
closures assembled at each with them held, so the working mode is followed.

The linkage is ``test_idle_dyad``'s parallelogram with a dyad on its rocker (read as a graph): with the crank turned
by theta about y, the coupler translates with B, and the CTI is |sin(B'C', C'D)|, B' = A + R(theta)(B - A) and
C' = B' + (C - B); joint values are the same in any world and unit, so the indices are too.
"""

from __future__ import annotations

import numpy as np
import pytest
from test_idle_dyad import A, B, C, D, linkage

from helpers import MJCF_WORLDS, mjcf_variant, one_line_error, screwkit, screwkit_json, sine
from screwkit.io import read_closed_tree
from screwkit.io.graph import graph_mechanism


def textbook(degrees: float) -> float:
    angle = np.radians(degrees)
    turn = np.array([[np.cos(angle), 0.0, np.sin(angle)], [0.0, 1.0, 0.0], [-np.sin(angle), 0.0, np.cos(angle)]])
    b = A + turn @ (B - A)
    c = b + (C - B)
    return sine(c - b, c - D)


@pytest.mark.parametrize("variant", sorted(MJCF_WORLDS))
@pytest.mark.parametrize("degrees", [20.0, -35.0, 120.0])
def test_the_graph_posed_by_its_crank_reads_the_parallelogram_there(tmp_path, variant, degrees):
    path, unit = mjcf_variant(tmp_path, "dyad", variant, lambda s, w: linkage(s, w, dyad="rocker"))
    graph = graph_mechanism(read_closed_tree(path, output="coupler", length_unit=unit))
    moved = graph.at_actuators([np.radians(degrees)])
    result = moved.indices()
    assert (float(result.iti), float(result.lmti), float(result.cti)) == pytest.approx(
        (1.0, 1.0, textbook(degrees)), abs=1e-9)
    crank = moved.tree.model.getJointId("crank")
    assert moved.q[moved.tree.model.joints[crank].idx_q] == pytest.approx(np.radians(degrees), abs=1e-12)


def test_the_command_takes_actuators_for_a_graph(tmp_path):
    path = tmp_path / "dyad.xml"
    path.write_text(linkage(dyad="rocker"))
    found = screwkit_json("analyze", path, "--output", "coupler", "--actuators", "20")
    assert (found["iti"], found["cti"]) == pytest.approx((1.0, textbook(20.0)), abs=1e-9)
    graph = graph_mechanism(read_closed_tree(path, output="coupler"))
    [(name, value)] = found["pose"].items()
    assert name == graph.task_coordinates[0]
    assert value == pytest.approx(float(graph.at_actuators([np.radians(20.0)]).task_pose()[0]), abs=1e-12)


def test_bad_actuator_values_and_a_joint_past_its_limits_are_refused_in_one_line(tmp_path):
    path = tmp_path / "limited.xml"
    path.write_text(linkage(dyad="rocker").replace('name="crank" type="hinge" axis="0 1 0"',
                                                   'name="crank" type="hinge" axis="0 1 0" range="-60 60" '
                                                   'limited="true"'))
    one_line_error(screwkit("analyze", path, "--output", "coupler", "--actuators", "10", "20"),
                   "Expected --actuators with 1 value (one per actuator: ", "crank", "got 2")
    one_line_error(screwkit("analyze", path, "--output", "coupler", "--actuators", "nan"),
                   "Expected finite values after --actuators, got nan for ", "crank")
    one_line_error(screwkit("analyze", path, "--output", "coupler", "--actuators", "ten"),
                   "Expected numbers after --actuators")
    one_line_error(screwkit("analyze", path, "--output", "coupler", "--actuators", "70"),
                   "beyond their limits", "'crank'", "--ignore-limits")
    found = screwkit_json("analyze", path, "--output", "coupler", "--actuators", "70", "--ignore-limits")
    assert found["cti"] == pytest.approx(textbook(70.0), abs=1e-9)


@pytest.mark.parametrize("scale", [1e-3, 1e3])
def test_actuator_values_drive_the_linkage_alike_at_any_size(tmp_path, scale):
    """Every length times 1e-3 or 1e3, read in metres: the steps are in radians, the indices the same."""
    path = tmp_path / "dyad.xml"
    path.write_text(linkage(scale, dyad="rocker"))
    result = graph_mechanism(read_closed_tree(path, output="coupler")).at_actuators([np.radians(-35.0)]).indices()
    assert (float(result.iti), float(result.cti)) == pytest.approx((1.0, textbook(-35.0)), abs=1e-9)
