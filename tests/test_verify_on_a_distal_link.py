"""``verify`` on a five-bar written with its output on a leg's distal link, the usual MJCF way.

The first leg's distal link is the platform, and the other legs' ``<connect>`` meet it at the output point. The
first leg is then an R-R chain, and ``verify`` refused it ("The closed forms need RRR or RPR chains"). Its
actuation wrench is the force from its elbow through the output point (the point's rotations idle), as a third
joint there would give. ``verify`` now compares the generic screw path with the textbook pressure angles on such a
file: in metres, and turned in the world and written in millimetres; redundant (three legs) and not (two).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from test_io import five_bar_mjcf

from helpers import random_rotation, screwkit_json
from screwkit.closure import solve
from screwkit.io.loader import load
from screwkit.studies.closed_form_poses import planar_points


@pytest.mark.parametrize(("legs", "turned"), [(3, False), (2, True)])
def test_verify_reads_a_five_bar_whose_output_is_on_a_distal_link(tmp_path, legs, turned):
    rotation = random_rotation(np.random.default_rng(legs)) if turned else None
    path = tmp_path / "five_bar.xml"
    path.write_text(five_bar_mjcf(rotation=rotation, scale=1000.0 if turned else 1.0, legs=legs))
    unit = ["--length-unit", "mm"] if turned else []
    report = screwkit_json("verify", path, "--output", "distal_1", *unit, "--samples", "200")
    assert report["poses"] == 200 and report["largest_deviation"] < 1e-9, report
    assert set(report["deviations"]) >= {"ITI per actuator", "OTI per submechanism", "LMTI", "F_O1", "F_IO1"}
    assert not any(report["differing_poses"].values()), report


def test_the_closed_forms_refuse_an_output_point_where_the_legs_do_not_meet(tmp_path):
    """The output point stands for the R-R leg's last joint only where the other legs meet the platform: moved off
    it (a mechanism built in Python), the closed forms are refused naming the leg and the distance."""
    path = tmp_path / "five_bar.xml"
    path.write_text(five_bar_mjcf(legs=3))
    mechanism = load(path, output="distal_1")
    solution = solve(mechanism, mechanism.home_pose[None])
    planar_points(mechanism, solution)  # as read: the legs meet at the output point
    moved = replace(mechanism, output_point=mechanism.output_point + [0.01, 0.0, 0.0])
    with pytest.raises(ValueError, match=r"The textbook pressure angles are for legs meeting at the output point; "
                                         r"chain '.*' of '.*' meets the platform 0.01 m from it"):
        planar_points(moved, solve(moved, moved.home_pose[None]))
