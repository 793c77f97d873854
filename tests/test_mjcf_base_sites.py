"""A closure's anchor on a site of the fixed base body, the base written with no joint and no ``pos``.

MJCF files of wheel legs and linkages often write their ground pivots as sites of a jointless base body at the
world's origin (``<body name="base"><site name="D_ground" .../>``). Pinocchio's parser makes that body a frame and
leaves its sites out, and the closure was refused: "no site named 'D_ground'" (a base with a ``pos`` was read, its
sites kept). The site is now placed on the body's frame, and the four-bar reads the textbook pressure angles of
MuJoCo's own placement of its joints and sites, in m, mm and a moved, turned world.
"""

from __future__ import annotations

import subprocess
import sys

import mujoco
import numpy as np
import pytest

from helpers import MJCF_WORLDS, mjcf_variant, mujoco_closed, sine
from screwkit.io.loader import load
from screwkit.studies import indices_at_pose


def four_bar(scale: float = 1.0, world=("0 0 0", "1 0 0 0")) -> str:
    """A crank A-B, coupler B-C and rocker C-D (pins along y), D a site of the base body; the base written bare
    where ``world`` is the identity."""
    def at(*values) -> str:
        return " ".join(repr(v * scale) for v in values)

    placed = "" if world == ("0 0 0", "1 0 0 0") else f' pos="{world[0]}" quat="{world[1]}"'
    ball = f'<geom type="sphere" size="{0.01 * scale!r}"/>'
    return ('<mujoco model="fourbar"><option><flag contact="disable"/></option>'
            f'<worldbody><body name="base"{placed}>{ball}'
            f'<site name="D_ground" pos="{at(0.3, 0, 0.02)}"/>'
            f'<body name="crank"><joint name="jA" type="hinge" axis="0 1 0"/>{ball}'
            f'<body name="coupler" pos="{at(0, 0, 0.1)}"><joint name="jB" type="hinge" axis="0 1 0"/>{ball}'
            f'<body name="rocker" pos="{at(0.3, 0, 0.1)}"><joint name="jC" type="hinge" axis="0 1 0"/>{ball}'
            f'<site name="D_link" pos="{at(0, 0, -0.18)}"/></body></body></body></body></worldbody>'
            '<equality><connect name="D" site1="D_link" site2="D_ground"/></equality>'
            '<actuator><motor name="m" joint="jA"/></actuator></mujoco>')



@pytest.mark.parametrize("variant", sorted(MJCF_WORLDS))
def test_a_ground_site_of_a_bare_base_body_closes_the_loop(tmp_path, variant):
    path, unit = mjcf_variant(tmp_path, "fourbar", variant, four_bar)
    model, data, anchor = mujoco_closed(path)  # closed as written
    a, b, c, d = anchor["jA"], anchor["jB"], anchor["jC"], data.site_xpos[model.site("D_ground").id]
    mechanism = load(path, output="coupler", length_unit=unit)
    result = indices_at_pose(mechanism, mechanism.home_pose)
    assert float(result.iti) == pytest.approx(sine(b - a, c - b), abs=1e-9)  # the crank drives the coupler at B
    assert float(result.lmti) == pytest.approx(sine(c - b, c - d), abs=1e-9)  # the rocker holds it at C


@pytest.mark.parametrize("connect", ['body1="rocker" body2="world" anchor="0.0 0.0 -0.18"',
                                     'body1="rocker" anchor="0.0 0.0 -0.18"',
                                     'body1="world" body2="rocker" anchor="0.3 0.0 0.02"'])
def test_a_connect_to_the_world_body_named_or_left_out_reads_the_same(tmp_path, connect):
    """``body2="world"`` (or ``body1``) is MuJoCo's world body, as ``body2`` left out: it was refused with Pinocchio's
    words ("Model does not have any body named world")."""
    path = tmp_path / "world.xml"
    path.write_text(four_bar().replace('<connect name="D" site1="D_link" site2="D_ground"/>',
                                       f'<connect name="D" {connect}/>'))
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    assert np.abs(data.efc_pos).max() < 1e-12
    anchor = {model.joint(k).name: data.xanchor[k] for k in range(model.njnt)}
    a, b, c = anchor["jA"], anchor["jB"], anchor["jC"]
    d = c + data.xmat[model.body("rocker").id].reshape(3, 3) @ np.array([0.0, 0.0, -0.18])
    mechanism = load(path, output="coupler")
    result = indices_at_pose(mechanism, mechanism.home_pose)
    assert (float(result.iti), float(result.lmti)) == pytest.approx((sine(b - a, c - b), sine(c - b, c - d)),
                                                                    abs=1e-9)


def test_connects_on_sites_read_over_and_over_do_not_crash_the_process(tmp_path):
    """Pinocchio 4.1's parser of ``<connect site1=... site2=...>`` faults now and then (a segmentation fault within
    a few hundred readings of this file, in a test run and in a user's sweep of files); screwkit places closures
    itself, and the text Pinocchio reads no longer holds the ``<equality>`` section. Read 400 times in a process of
    its own, which a fault would end with a signal."""
    path = tmp_path / "fourbar.xml"
    path.write_text(four_bar())
    code = ("import sys\nfrom screwkit.io import read_closed_tree\n"
            "for _ in range(400):\n    read_closed_tree(sys.argv[1], output='coupler')\n")
    run = subprocess.run([sys.executable, "-c", code, str(path)], capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, (run.returncode, run.stderr[-2000:])


def test_convert_reads_a_file_in_millimetres_and_writes_its_unit(tmp_path):
    """``convert --length-unit mm``: the four-bar written in millimetres is converted with its unit said in a
    ``<units>`` element, and the file written reads the textbook pressure angles of the four-bar in metres (the
    option was refused by convert alone, and without it the mechanism is written a thousand times too large)."""
    import json

    from helpers import screwkit

    source, written = tmp_path / "fourbar_mm.xml", tmp_path / "fourbar.urdf"
    source.write_text(four_bar(1000.0))
    converted = screwkit("convert", source, written, "--output", "coupler", "--length-unit", "mm", "--json")
    assert converted.returncode == 0, converted.stderr
    assert '<units length="mm"/>' in written.read_text()
    analysed = screwkit("analyze", written, "--json")
    assert analysed.returncode == 0, analysed.stderr
    result = json.loads(analysed.stdout)
    metres, _ = mjcf_variant(tmp_path, "metres", "m", four_bar)
    model, data, anchor = mujoco_closed(metres)
    a, b, c, d = anchor["jA"], anchor["jB"], anchor["jC"], data.site_xpos[model.site("D_ground").id]
    in_metres = json.loads(screwkit("analyze", metres, "--output", "coupler", "--json").stdout)
    assert result["pose"] == pytest.approx(in_metres["pose"], rel=1e-9)  # (a pose in m, not mm)
    assert result["iti"] == pytest.approx(sine(b - a, c - b), abs=1e-9)
    assert result["lmti"] == pytest.approx(sine(c - b, c - d), abs=1e-9)
