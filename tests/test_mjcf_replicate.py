"""MuJoCo's ``<replicate>``: copies of a subtree, each named with its index, which screwkit does not expand.

A published wheel-leg scene holds 200 free balls in a ``<replicate>`` beside its legs; the file was refused as "a
free joint inside another body; MuJoCo ... refuses the file", which MuJoCo does not. A block nothing the mechanism
is read by refers to is left out and said; one a closure or an actuator refers into is refused by name, with the
way to write the copies out.
"""

from __future__ import annotations

import mujoco
import pytest
from test_mjcf_base_sites import four_bar

from helpers import one_line_error, screwkit
from screwkit.io.loader import load
from screwkit.studies import indices_at_pose

BALLS = ('<replicate count="4" offset="0.2 0 0"><body name="ball" pos="0 1 0.5"><freejoint/>'
         '<geom type="sphere" size="0.02"/></body></replicate>')


def test_a_block_nothing_refers_to_is_left_out_and_said(tmp_path):
    plain, scene = tmp_path / "plain.xml", tmp_path / "scene.xml"
    plain.write_text(four_bar())
    scene.write_text(four_bar().replace("</worldbody>", BALLS + "</worldbody>"))
    model = mujoco.MjModel.from_xml_path(str(scene))  # MuJoCo reads it: four balls beside the linkage
    assert sum(model.body(k).name.startswith("ball") for k in range(model.nbody)) == 4
    mechanism, reference = load(scene, output="coupler"), load(plain, output="coupler")
    assert any("<replicate> block(s)" in line and "left out" in line for line in mechanism.import_report)
    result, expected = (indices_at_pose(m, m.home_pose) for m in (mechanism, reference))
    assert (float(result.iti), float(result.lmti)) == (float(expected.iti), float(expected.lmti))


def replicated_legs() -> str:
    """The four-bar's crank, coupler and rocker written once in a ``<replicate>`` of two (valid MJCF: MuJoCo names the
    copies' sites D_link0, D_link1 and the connect refers to the file's name)."""
    text = four_bar().replace('<body name="crank">', '<replicate count="2" euler="0 0 180"><body name="crank">')
    return text.replace("</body></body></body></body></worldbody>",
                        "</body></body></body></replicate></body></worldbody>")


def test_a_block_a_closure_or_an_actuator_refers_into_is_refused_by_name(tmp_path):
    path = tmp_path / "legs.xml"
    path.write_text(replicated_legs())
    mujoco.MjModel.from_xml_path(str(path))  # (valid MJCF)
    with pytest.raises(ValueError, match="<replicate count='2'> holds elements <connect site1='D_link'> refers to: "
                                         "screwkit does not expand"):
        load(path, output="coupler")


def test_the_command_reads_the_scene_and_refuses_the_replicated_legs(tmp_path):
    scene, legs = tmp_path / "scene.xml", tmp_path / "legs.xml"
    scene.write_text(four_bar().replace("</worldbody>", BALLS + "</worldbody>"))
    legs.write_text(replicated_legs())
    assert screwkit("analyze", scene, "--output", "coupler").returncode == 0
    one_line_error(screwkit("analyze", legs, "--output", "coupler"), "<replicate count='2'>", "mj_saveLastXML")


def test_a_closure_on_a_copy_named_by_its_number_refers_into_the_block(tmp_path):
    """MuJoCo names the copies ball0, ball1, ...: a connect on ball1 refers into the block, which was left out, and
    the file then refused with Pinocchio's words."""
    path = tmp_path / "copies.xml"
    path.write_text(four_bar().replace("</worldbody>", BALLS + "</worldbody>").replace(
        "</equality>", '<connect name="X" body1="ball1" anchor="0 0 0"/></equality>'))
    mujoco.MjModel.from_xml_path(str(path))  # (valid MJCF: ball1 is a copy)
    with pytest.raises(ValueError, match="<replicate count='4'> holds elements <connect body1='ball1'> refers to"):
        load(path, output="coupler")
