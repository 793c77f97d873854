"""``verify`` on a five-bar written with its output on a leg's distal link, the usual MJCF way.

The first leg's distal link is the platform, and the other legs' ``<connect>`` meet it at the output point. The
first leg is then an R-R chain, and ``verify`` refused it ("The closed forms need RRR or RPR chains"). Its
actuation wrench is the force from its elbow through the output point (the point's rotations idle), as a third
joint there would give. ``verify`` now compares the generic screw path with the textbook pressure angles on such a
file: in metres, and turned in the world and written in millimetres; redundant (three legs) and not (two).
"""

from __future__ import annotations

import re
from dataclasses import replace

import numpy as np
import pytest
from test_io import five_bar_mjcf

from helpers import random_rotation, screwkit_json
from screwkit.closure import solve
from screwkit.io.loader import load
from screwkit.studies.closed_form_poses import planar_points


def listed_last(text: str, body: str) -> str:
    """The MJCF text with ``body`` (a leg's first body, with all it holds) listed after the other legs."""
    start = text.index(f'<body name="{body}"')
    depth, at = 0, start
    for tag in re.finditer(r"<body\b[^>]*?(/?)>|</body>", text[start:]):
        depth += 0 if tag.group(0).endswith("/>") else 1 if tag.group(0).startswith("<body") else -1
        if depth == 0:
            at = start + tag.end()
            break
    leg, rest = text[start:at], text[:start] + text[at:]
    end = rest.index("</body></worldbody>")
    return rest[:end] + leg + rest[end:]


@pytest.mark.parametrize(("legs", "variant"), [(3, "m"), (2, "turned, mm"), (3, "x1e-3, listed otherwise")])
def test_verify_reads_a_five_bar_whose_output_is_on_a_distal_link(tmp_path, legs, variant):
    """In m; turned in the world and written in mm; a thousand times smaller, read in metres, with the leg that
    carries the output listed last."""
    turned = variant.startswith("turned")
    rotation = random_rotation(np.random.default_rng(legs)) if turned else None
    scale = 1000.0 if turned else 1e-3 if variant.startswith("x1e-3") else 1.0
    text = five_bar_mjcf(rotation=rotation, scale=scale, legs=legs)
    path = tmp_path / "five_bar.xml"
    path.write_text(listed_last(text, "proximal_1") if "listed" in variant else text)
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
