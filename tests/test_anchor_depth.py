"""A closure whose two anchors sit at different depths on one pin: the gap lies along the loop's hinge axes.

A CAD-exported wheel leg writes each connect's two sites a few millimetres apart along the (parallel) pins; MuJoCo
runs it with a constant violation, and screwkit's refusal advised ``--initial`` values, which cannot help: every
joint of the loop turns about an axis along that gap, so no joint values change it. The refusal now says where the
gap lies and what closes it, and the same file with the anchors on one plane reads. A gap along the pins of the
order of a file's rounding (a loop of hinges each written to 6 decimals) is read on one plane, with the pressure
angles MuJoCo's anchors give.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from test_mjcf_base_sites import four_bar

from helpers import MJCF_WORLDS, mjcf_variant, mujoco_closed, one_line_error, screwkit, sine
from screwkit.io.loader import converted_mechanism, load
from screwkit.io.pin_gaps import DEPTH_ROUNDING, ONE_PLANE
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


@pytest.mark.parametrize("variant", sorted(MJCF_WORLDS))
def test_a_gap_along_the_pins_is_named_and_the_anchors_on_one_plane_read(tmp_path, variant):
    path, unit = mjcf_variant(tmp_path, "deep", variant, deep)
    scale = MJCF_WORLDS[variant][0]
    for values in ([0.0, 0.0, 0.0], [0.3, -0.5, 0.2]):  # MuJoCo: the same gap along the pins, whatever the joints
        assert np.linalg.norm(_gap(path, values)) >= DEPTH * scale * (1 - 1e-9)
    assert 'pos="0.0 0.004' in deep() and 'pos="0.0 0.004' not in four_bar()
    with pytest.raises(ValueError, match="its gap lies along the parallel axes of its loop's hinges .*its two "
                                         "anchors drawn at different depths on one pin"):
        load(path, output="coupler", length_unit=unit)
    flat, _ = mjcf_variant(tmp_path, "flat", variant, four_bar)
    assert load(flat, output="coupler", length_unit=unit).dof == 1


def test_the_command_names_the_depth(tmp_path):
    path = tmp_path / "deep.xml"
    path.write_text(deep())
    message = one_line_error(screwkit("analyze", path, "--output", "coupler"), "its gap lies along the parallel axes")
    assert "--initial" not in message


@pytest.mark.parametrize("variant", sorted(MJCF_WORLDS))
def test_anchors_a_file_s_rounding_sets_apart_on_the_pins_read_with_mujoco_s_pressure_angles(tmp_path, variant):
    """MuJoCo reads the file open by at least the depth at any joint values; screwkit reads it on one plane, says so,
    and gives the textbook pressure angles of the four-bar from MuJoCo's anchors of the same file drawn flat, in
    metres, millimetres and a moved world alike. Refused before (a residual of 3.4e-5 of the length scale)."""
    path, unit = mjcf_variant(tmp_path, "rounded", variant, lambda scale, world: deep(scale, world, ROUNDED))
    scale = MJCF_WORLDS[variant][0]
    assert np.linalg.norm(_gap(path, [0.0, 0.0, 0.0])) == pytest.approx(ROUNDED * scale, rel=1e-6)  # the depth alone
    assert np.linalg.norm(_gap(path, [0.3, -0.5, 0.2])) >= ROUNDED * scale * (1 - 1e-9)  # at least, whatever the joints
    assert 1e-5 < ROUNDED / SCALE < DEPTH_ROUNDING
    flat, _ = mjcf_variant(tmp_path, "flat", variant, four_bar)
    model, data, anchor = mujoco_closed(flat)
    a, b, c, d = anchor["jA"], anchor["jB"], anchor["jC"], data.site_xpos[model.site("D_ground").id]
    _, report, mechanism = converted_mechanism(path, output="coupler", length_unit=unit)
    [note] = [note for note in report.notes if note.startswith(ONE_PLANE)]
    assert f"(closure 'D' the most, {ROUNDED * scale:.2g} {unit or 'm'};" in note, note
    result = indices_at_pose(mechanism, mechanism.home_pose)
    assert float(result.iti) == pytest.approx(sine(b - a, c - b), abs=1e-9)
    assert float(result.lmti) == pytest.approx(sine(c - b, c - d), abs=1e-9)


def test_anchors_set_apart_beyond_a_file_s_rounding_are_refused_by_name(tmp_path):
    """Twice ``DEPTH_ROUNDING`` of the length scale along the pins: the refusal that names the depth, as at 4 mm, and
    says how far apart they are beyond what is read as the file's rounding (it read as advice that the loop closes)."""
    path = tmp_path / "beyond.xml"
    path.write_text(deep(depth=2 * DEPTH_ROUNDING * SCALE))
    with pytest.raises(ValueError, match=r"its two anchors drawn at different depths on one pin \(0\.0001[5-9] of "
                                         r"the length scale apart, beyond the 0\.0001 read as the file's rounding\)"):
        load(path, output="coupler")


def test_the_command_says_the_anchors_were_read_on_one_plane(tmp_path):
    path = tmp_path / "rounded.xml"
    path.write_text(deep(depth=ROUNDED))
    run = screwkit("analyze", path, "--output", "coupler")
    assert run.returncode == 0, run.stderr
    assert ONE_PLANE in run.stdout + run.stderr
