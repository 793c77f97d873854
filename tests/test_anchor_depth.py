"""A closure whose two anchors sit at different depths on one pin: the gap lies along the loop's hinge axes.

A CAD-exported wheel leg writes each connect's two sites a few millimetres apart along the (parallel) pins; MuJoCo
runs it with a constant violation, and screwkit's refusal advised ``--initial`` values, which cannot help: every
joint of the loop turns about an axis along that gap, so no joint values change it. Such anchors, whether a file's
rounding or a CAD's two layers of one pin set them apart, are read on one plane, with the pressure angles MuJoCo's
anchors give the same file drawn flat, and the report says how far they were moved; a loop left open across its pins
beside them is named in the refusal, not the one along them.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from test_mjcf_base_sites import four_bar

from helpers import MJCF_WORLDS, mjcf_variant, mujoco_closed, screwkit, sine
from screwkit.io.loader import converted_mechanism, load
from screwkit.io.pin_gaps import ONE_PLANE
from screwkit.studies.poses import indices_at_pose

DEPTH = 0.004
"""How far along the pins (y) the rocker's site is drawn from the ground's, in the file's length unit per metre."""
SCALE = 0.149
"""The four-bar's length scale (m): the root-mean-square distance of its three hinges from their centroid."""
ROUNDED = 5e-6
"""A depth its rounding could give a file (m per metre of the file's unit): 3.4e-5 of the length scale, beyond the
1e-5 by which a closure may stay open in any direction, within ``DEPTH_ROUNDING``."""


def deep(scale: float = 1.0, world=("0 0 0", "1 0 0 0"), depth: float = DEPTH) -> str:
    return four_bar(scale, world).replace(f'<site name="D_link" pos="{0.0 * scale!r} {0.0 * scale!r}',
                                          f'<site name="D_link" pos="{0.0 * scale!r} {depth * scale!r}')


def _gap(path, values) -> np.ndarray:
    """MuJoCo's connect residual (world) at the joint values ``values``."""
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    data.qpos[:] = values
    mujoco.mj_forward(model, data)
    rows = [k for k in range(data.nefc) if data.efc_type[k] == mujoco.mjtConstraint.mjCNSTR_EQUALITY]
    return data.efc_pos[rows]


@pytest.mark.parametrize("depth", [ROUNDED, DEPTH])
@pytest.mark.parametrize("variant", sorted(MJCF_WORLDS))
def test_anchors_apart_on_the_pins_read_with_mujoco_s_pressure_angles(tmp_path, variant, depth):
    """MuJoCo reads the file open by at least the depth at any joint values; screwkit reads it on one plane, says so,
    and gives the textbook pressure angles of the four-bar from MuJoCo's anchors of the same file drawn flat, in
    metres, millimetres and a moved world alike: at a depth a file's rounding gives (refused before, a residual of
    3.4e-5 of the length scale) and at a CAD's 4 mm (refused before, naming the depth)."""
    path, unit = mjcf_variant(tmp_path, "deep", variant, lambda scale, world: deep(scale, world, depth))
    scale = MJCF_WORLDS[variant][0]
    assert np.linalg.norm(_gap(path, [0.0, 0.0, 0.0])) == pytest.approx(depth * scale, rel=1e-6)  # the depth alone
    assert np.linalg.norm(_gap(path, [0.3, -0.5, 0.2])) >= depth * scale * (1 - 1e-9)  # at least, whatever the joints
    assert 1e-5 < ROUNDED / SCALE < 1e-4 < DEPTH / SCALE  # (beyond what the assembly leaves open: a rounding, a CAD)
    flat, _ = mjcf_variant(tmp_path, "flat", variant, four_bar)
    model, data, anchor = mujoco_closed(flat)
    a, b, c, d = anchor["jA"], anchor["jB"], anchor["jC"], data.site_xpos[model.site("D_ground").id]
    _, report, mechanism = converted_mechanism(path, output="coupler", length_unit=unit)
    [note] = [note for note in report.notes if note.startswith(ONE_PLANE)]
    assert f"(closure 'D' the most, {depth * scale:.2g} {unit or 'm'}, " in note, note
    result = indices_at_pose(mechanism, mechanism.home_pose)
    assert float(result.iti) == pytest.approx(sine(b - a, c - b), abs=1e-9)
    assert float(result.lmti) == pytest.approx(sine(c - b, c - d), abs=1e-9)


def test_a_loop_open_across_its_pins_is_named_not_the_one_open_along_them(tmp_path):
    """Beside the four-bar's closure open 2 m along its pins, a dyad hung on the base whose ground site is out of its
    reach: no depth closes that one, and the refusal names it (with --initial advice), not the wider gap along the
    pins, which alone would be read on one plane (it named that one, saying a move along the pin closes it)."""
    dyad = ('<body name="dyad_a" pos="-0.2 0 0"><joint name="jE" type="hinge" axis="0 1 0"/><geom size="0.01"/>'
            '<body name="dyad_b" pos="0 0 -0.02"><joint name="jF" type="hinge" axis="0 1 0"/><geom size="0.01"/>'
            '<site name="E_link" pos="0 0 -0.02"/></body></body>')
    text = deep(depth=2.0).replace('</body></body></body></body></worldbody>',
                                   f'</body></body></body>{dyad}</body></worldbody>')
    text = text.replace('<site name="D_ground"', '<site name="E_ground" pos="-0.2 0 -0.6"/><site name="D_ground"')
    text = text.replace('</equality>', '<connect name="E" site1="E_link" site2="E_ground"/></equality>')
    path = tmp_path / "two.xml"
    path.write_text(text)
    model = mujoco.MjModel.from_xml_path(str(path))
    assert model.neq == 2 and model.njnt == 5
    with pytest.raises(ValueError, match=r"closure 'E' still misses by .*--initial JOINT VALUE") as caught:
        load(path, output="coupler")
    assert "along the parallel axes" not in str(caught.value)


def test_the_command_says_how_far_the_anchors_were_moved_onto_one_plane(tmp_path):
    path = tmp_path / "deep.xml"
    path.write_text(deep())
    run = screwkit("analyze", path, "--output", "coupler")
    assert run.returncode == 0, run.stderr
    assert ONE_PLANE in run.stdout + run.stderr
    assert f"(closure 'D' the most, {DEPTH:.2g} m, " in run.stdout + run.stderr


@pytest.mark.parametrize("swapped", [False, True])
def test_the_closure_is_read_midway_between_its_anchors_whichever_end_is_named_first(tmp_path, swapped):
    """Both frames move half the depth along the pins, so the closure's point (which a spatial leg's characteristic
    points take) is the same with ``site1`` and ``site2`` the other way round: before, the second moved onto the
    first, 4 mm along the pin from where the other order put it."""
    from screwkit.io import read_closed_tree
    from screwkit.io.closed_tree import assemble, closure_frames

    text = deep()
    if swapped:
        text = text.replace('site1="D_link" site2="D_ground"', 'site1="D_ground" site2="D_link"')
    path = tmp_path / "deep.xml"
    path.write_text(text)
    tree = read_closed_tree(path, output="coupler")
    ((_, first, second),) = closure_frames(tree, assemble(tree)[0])
    np.testing.assert_allclose(first[:3, 3], [0.3, DEPTH / 2, 0.02], atol=1e-12)
    np.testing.assert_allclose(second[:3, 3], first[:3, 3], atol=1e-12)


def test_anchors_further_apart_than_one_pin_s_layers_are_refused_naming_the_depth(tmp_path):
    """Beyond ``PIN_DEPTH`` of the length scale (here 0.31 of it) the anchors are no pin's two layers: where along the
    pin the ball would stand moves a spatial reading's points, so the refusal names the depth and what closes it."""
    path = tmp_path / "far.xml"
    path.write_text(deep(depth=0.05))
    with pytest.raises(ValueError, match=r"its two anchors drawn at different depths on one pin \(0\.31 of the length "
                                         r"scale apart, more than the 0\.1 read as the two layers of one pin\), which "
                                         r"no joint values close: moved along the pin onto one plane"):
        load(path, output="coupler")


def _with_strut(text: str, stretch: float) -> str:
    """``text`` (a four-bar of :func:`deep`) with a ball-jointed strut on the base whose ground site is ``stretch``
    times as far as its reach (a rounding's gap beyond 1)."""
    strut = ('<body name="strut" pos="-0.2 0 0"><joint name="sball" type="ball"/><geom size="0.01"/>'
             '<site name="S_link" pos="0 0.1 -0.2"/></body>')
    text = text.replace('</body></body></body></body></worldbody>', f'</body></body></body>{strut}</body></worldbody>')
    text = text.replace('<site name="D_ground"', f'<site name="S_ground" pos="-0.2 {0.1 * stretch!r} '
                                                 f'{-0.2 * stretch!r}"/><site name="D_ground"')
    return text.replace('</equality>', '<connect name="S" site1="S_link" site2="S_ground"/></equality>')


def test_a_rounding_s_gap_elsewhere_leaves_the_anchors_read_on_one_plane(tmp_path):
    """Beside the 4 mm pin, a ball-jointed strut whose ground site is 2e-7 m beyond its reach (a rounding, accepted
    alone): the anchors are still read on one plane, with the four-bar's indices drawn flat (the strut's gap kept
    the move from being made, and the refusal said the loop had been read on one plane)."""
    path, flat = tmp_path / "strut.xml", tmp_path / "flat.xml"
    path.write_text(_with_strut(deep(), 1 + 2e-7 / float(np.hypot(0.1, 0.2))))
    flat.write_text(_with_strut(deep(depth=0.0), 1.0))
    _, report, mechanism = converted_mechanism(path, output="coupler")
    assert any(note.startswith(ONE_PLANE) for note in report.notes), report.notes
    reference = load(flat, output="coupler")
    got, want = (indices_at_pose(m, m.home_pose) for m in (mechanism, reference))
    np.testing.assert_allclose([got.iti, got.lmti], [want.iti, want.lmti], atol=1e-9)
