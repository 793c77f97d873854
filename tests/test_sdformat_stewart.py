"""Stewart platforms written in SDFormat as published Gazebo models write them (tests/sdformat_models.py
:func:`ups_sdf`): the spherical joint at the platform a pitch hinge plus a ``revolute2`` joint written from the
platform to the leg, SDFormat 1.4's axes in the model frame.

Each is the bundled 8-UPS hexapod (``robots/ups_hexapod_8.urdf``): the same joint centres and leg lines, so the
same indices, computed by that file's own serial chains. Three readings were wrong:

* a ``revolute2`` loop joint written from the platform hung its first hinge from the platform, so the loop closed
  beyond it, and the file was refused;
* a hinge loop joint is two points on its axis, the second ``scale`` away along it; the leg's point (the OTI's
  characteristic point) was their middle, so the LMTI was 0.7148 for 0.8738, and which leg carried the platform in
  the spanning tree (the file's order) changed the OTIs;
* SDFormat 1.4 writes every axis in the model frame (libsdformat's ``1_4.convert`` adds
  ``<use_parent_model_frame>true``): they were read in the joint frame.
"""

from __future__ import annotations

import numpy as np
import pytest
from sdformat_models import ups_sdf

from helpers import screwkit
from screwkit.io import ImportError_, read_closed_tree
from screwkit.io.loader import load
from screwkit.studies import indices_at_pose

TOLERANCE = 1e-9


@pytest.fixture(scope="module")
def bundled():
    mechanism = load("ups_hexapod_8")
    return indices_at_pose(mechanism, mechanism.home_pose)


def write(tmp_path, text: str, name: str = "stewart.sdf"):
    path = tmp_path / name
    path.write_text(text)
    return path


@pytest.mark.parametrize("version", ["1.9", "1.4"])
@pytest.mark.parametrize("from_platform", [True, False])
@pytest.mark.parametrize("reverse", [False, True])
def test_a_gazebo_stewart_platform_has_the_indices_of_the_same_legs_written_as_serial_chains(
        tmp_path, bundled, version, from_platform, reverse):
    mechanism = load(write(tmp_path, ups_sdf(version, from_platform, reverse)))
    assert mechanism.dof == 6 and len(mechanism.actuators) == 8
    found = indices_at_pose(mechanism, mechanism.home_pose)
    assert found.lmti == pytest.approx(bundled.lmti, abs=TOLERANCE)
    for j in bundled.faults:
        assert found.f_o[j] == pytest.approx(bundled.f_o[j], abs=TOLERANCE)
    np.testing.assert_allclose(sorted(found.iti_actuators), sorted(bundled.iti_actuators), atol=TOLERANCE)
    names = [name.split(":")[-1] for name in mechanism.actuator_names]
    by_leg = dict(zip(names, found.oti_actuators))
    reference = load("ups_hexapod_8")
    expected = dict(zip([name.split(":")[-1].replace("_joint_", "_") for name in reference.actuator_names],
                        bundled.oti_actuators))
    for name, value in by_leg.items():  # each leg's OTI follows the leg, whatever the file's order
        assert value == pytest.approx(expected[name], abs=TOLERANCE), name


def test_sdformat_1_4_axes_are_read_in_the_model_frame(tmp_path):
    """Every joint of the 1.4 file (axes in the model frame) turns about the same world axis as in the 1.9 file
    (axes in the joint frames, which are turned along each leg)."""
    import pinocchio as pin

    trees = [read_closed_tree(write(tmp_path, ups_sdf(version), f"{version}.sdf")) for version in ("1.9", "1.4")]
    axes = []
    for tree in trees:
        data = tree.model.createData()
        pin.forwardKinematics(tree.model, data, tree.q_reference)
        axes.append({str(name): np.asarray(data.oMi[k].rotation) @ np.asarray(tree.model.joints[k].extract().axis)
                     for k, name in enumerate(tree.model.names) if k and tree.model.joints[k].nv == 1})
    # per leg its base hinges, slide and pitch hinge, and one hinge of its revolute2 in the tree (both for the leg
    # that carries the platform)
    assert axes[0].keys() == axes[1].keys() and len(axes[0]) == 8 * 5 + 1
    for name, axis in axes[0].items():
        np.testing.assert_allclose(axes[1][name], axis, atol=1e-12, err_msg=name)
    pitch = np.array([axes[0][f"leg_{k}_pitch"] for k in range(1, 9)])  # written "0 1 0" in each leg's frame
    assert np.all(np.linalg.norm(pitch - [0.0, 1.0, 0.0], axis=1) > 0.1)  # so the two frames differ for each


def test_a_joint_named_as_a_link_is_renamed_before_sdformat_1_7_and_refused_from_it(tmp_path):
    """SDFormat before 1.7 let a joint share a link's name (Gazebo's own demo_joint_types does), and libsdformat
    renames such a joint ``<name>_joint`` with a warning; 1.7 puts links, joints and frames in one namespace. Each leg's
    pitch joint named as the link it carries: as 1.6, the file opens, the report says which joints were renamed, and
    the indices are those of the file as written apart; as 1.9, it is refused naming the clash."""
    plain = load(write(tmp_path, ups_sdf("1.6"), "plain.sdf"))
    text = ups_sdf("1.6")
    legs = sorted({name.split('"')[1][:-len("_pitch")] for name in text.split("<joint name=")[1:]
                   if name.split('"')[1].endswith("_pitch")})
    for leg in legs:
        text = text.replace(f'<joint name="{leg}_pitch"', f'<joint name="{leg}_top"')
    clashing = write(tmp_path, text, "clashing.sdf")
    renamed = load(clashing)
    notes = read_closed_tree(clashing).notes
    assert f"joint '{legs[0]}_top' named '{legs[0]}_top_joint': a link of this SDFormat 1.6 file has its name" in \
        " ".join(notes)
    assert sum("named" in note and "_top_joint" in note for note in notes) == len(legs) == 8
    np.testing.assert_allclose(indices_at_pose(renamed, renamed.home_pose).lmti,
                               indices_at_pose(plain, plain.home_pose).lmti, atol=1e-12)
    info = screwkit("info", clashing)
    assert info.returncode == 0 and f"joint '{legs[0]}_top' named '{legs[0]}_top_joint'" in info.stdout, info.stderr
    newer = write(tmp_path, text.replace('<sdf version="1.6"', '<sdf version="1.9"'), "newer.sdf")
    with pytest.raises(ImportError_, match=r"the name '.*_top' is already <link name='.*_top'> \(links, joints and "
                                           r"frames share one namespace\)"):
        read_closed_tree(newer)


def test_an_axis_mimic_is_read_as_a_coupling_and_refused_between_legs(tmp_path):
    """SDFormat 1.11's <axis><mimic> couples a joint to another; read as independent joints the mechanism would
    have a mobility the file does not give it: one slide mimicking another leg's is refused naming the element."""
    text = ups_sdf()
    sliders = [part.split('"')[1] for part in text.split("<joint name=")[1:] if part.split('"')[1].endswith("_slider")]
    start = text.index(f'<joint name="{sliders[0]}"')
    end = text.index("</axis>", start)
    text = text[:end] + f'<mimic joint="{sliders[1]}" axis="axis"/>' + text[end:]
    with pytest.raises(ImportError_, match=rf"<joint name='{sliders[0]}'><axis><mimic joint='{sliders[1]}'>: a joint "
                                           rf"coupling ties joint '{sliders[0]}' to joint '{sliders[1]}', which holds "
                                           r"the mechanism analysed to fewer motions"):
        load(write(tmp_path, text))


def test_renamed_joints_follow_libsdformat_s_order(tmp_path):
    """libsdformat (Model.cc, before 1.7) renames in file order against the links and the joints already named: a
    pitch joint named as its link becomes ``<link>_joint``, and a later joint written with that very name becomes
    ``<link>_joint_joint`` (not the other way round); the indices are the file's as written apart."""
    text = ups_sdf("1.6")
    leg = next(part.split('"')[1][:-len("_pitch")] for part in text.split("<joint name=")[1:]
               if part.split('"')[1].endswith("_pitch"))
    assert text.index(f'<joint name="{leg}_pitch"') < text.index(f'<joint name="{leg}_s"')
    text = text.replace(f'<joint name="{leg}_pitch"', f'<joint name="{leg}_top"')
    text = text.replace(f'<joint name="{leg}_s"', f'<joint name="{leg}_top_joint"')
    path = write(tmp_path, text)
    notes = " ".join(read_closed_tree(path).notes)
    assert f"joint '{leg}_top' named '{leg}_top_joint': a link of this SDFormat 1.6 file" in notes
    assert f"joint '{leg}_top_joint' named '{leg}_top_joint_joint': a joint before it" in notes
    plain = load(write(tmp_path, ups_sdf("1.6"), "plain.sdf"))
    np.testing.assert_allclose(indices_at_pose(load(path), plain.home_pose).lmti,
                               indices_at_pose(plain, plain.home_pose).lmti, atol=1e-12)
