"""A spatial Delta whose forearms are parallelograms of hinges, in SDFormat as Gazebo writes it (tests/hinged_delta.py).

Published models of this robot are written to 6 decimals. Three readings were wrong:

* the rounding (hinge axes 1e-7 to 1e-5 rad apart where they are drawn parallel) made every parallelogram rigid, and
  the file was refused ("the actuated path and the leg's translations and rotations share 4 twists, the leg has
  3"); read with the rounding taken as zero, the legs' hinges to the platform (written through rounded
  roll-pitch-yaw) were not parallel to their motor axes, and the Delta had one DOF;
* a leg joined to the platform by a hinge (two ball closures) counted only one of them in its twist system: the
  leg seemed to allow every rotation, and its parallelogram's constraint was left out;
* a leg's actuation wrench followed the rod the spanning tree runs through, not the parallelogram's midline: the
  ITI was up to 8e-4 off the pressure angle, and changed sign of error with the other rod; and the ITI's point was
  the elbow hinge's origin as drawn, not where its axis meets the wrench (3e-3 off at some poses of the published
  file, whose rods are not centred on the elbow's origin).

Every index is checked against the textbook pressure angles of the geometry (tests/hinged_delta.py), computed with
numpy from the points alone.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from hinged_delta import AZIMUTHS, geometry, hinged_delta_sdf, textbook
from test_gallery import assert_same_bodies, mujoco_residuals, mujoco_state
from test_io import mjcf_of_tree

from helpers import one_line_error, random_rotation, screwkit
from screwkit.closure.assembly import DOF_AT_ROUNDING
from screwkit.io import ImportError_, read_closed_tree, read_mechanism_file
from screwkit.io.closed_tree import assemble
from screwkit.io.graph import graph_mechanism
from screwkit.io.loader import load
from screwkit.io.rounding import parallel_axes
from screwkit.studies import indices_at_pose

TOLERANCE = 1e-9
ROUNDED = 1e-5  # a file written to 6 decimals, against the geometry it rounds
POSES = [((0.01, -0.02, -0.42), (35.0, 28.0, 40.0, 32.0)), ((-0.05, 0.03, -0.38), (22.0, 41.0, 30.0, 18.0))]
MOVED = (random_rotation(np.random.default_rng(11)), np.array([0.3, -0.2, 0.7]))


def indices(tmp_path, **options):
    path = tmp_path / "hinged_delta.sdf"
    path.write_text(hinged_delta_sdf(**options))
    mechanism = load(path)
    return mechanism, indices_at_pose(mechanism, mechanism.home_pose)


def assert_textbook(mechanism, result, expected: dict, tolerance: float) -> None:
    assert mechanism.dof == 3 and len(mechanism.actuators) == 4, (mechanism.dof, mechanism.actuators)
    np.testing.assert_allclose(result.iti_actuators, expected["iti"], atol=tolerance)
    found = dict(zip(result.submechanisms, result.oti_submechanisms))
    for members, value in expected["oti"].items():
        np.testing.assert_allclose(found[members], value, atol=tolerance, err_msg=str(members))
    np.testing.assert_allclose([result.lmti, result.f_o[1]], [expected["lmti"], expected["f_o1"]], atol=tolerance)


@pytest.mark.parametrize("pose", POSES)
@pytest.mark.parametrize(("platform_leg", "half_width", "transform", "elbow_shift"), [
    (0, 0.025, None, 0.0), (2, 0.025, None, 0.0), (0, -0.025, None, 0.0), (3, -0.025, MOVED, 0.0),
    (1, 0.025, None, 0.01), (2, -0.025, MOVED, -0.02)])
def test_a_hinged_delta_has_the_textbook_pressure_angles_whichever_rod_and_leg_the_tree_runs_through(
        tmp_path, pose, platform_leg, half_width, transform, elbow_shift):
    """Also with each elbow hinge drawn 1 or 2 cm along its own axis: the ITI's point is where the leg's force
    crosses the hinge's axis, wherever the hinge is drawn on it (the projection of the drawn point was off the
    pressure angle)."""
    centre, arms = pose
    mechanism, result = indices(tmp_path, centre=centre, arm_angles=arms, platform_leg=platform_leg,
                                half_width=half_width, transform=transform, elbow_shift=elbow_shift)
    assert_textbook(mechanism, result, textbook(geometry(centre, arms)), TOLERANCE)
    notes = mechanism.import_report
    legs = [note for note in notes if "twist system of dimension 4 (rotations about" in note]
    assert len(legs) == 4, notes  # each leg: the translations and the rotation about its motor axis
    assert not [note for note in notes if "rounding" in note], notes  # an exact file is read as written


@pytest.mark.parametrize(("order", "unit", "transform"), [((0, 1, 2), None, None), ((2, 0, 1), None, MOVED),
                                                         ((1, 2, 0), "mm", None), ((2, 0, 1), "km", MOVED)])
def test_three_legs_whose_wrists_all_close_onto_the_platform_open_as_written(tmp_path, order, unit, transform):
    """A three-legged hinged Delta whose every wrist is written from its leg onto a platform named ``low_base`` (as a
    published SDFormat Delta writes it): the reader's tree takes one wrist, the others close onto the platform, and
    each of those legs' lower cross-pieces meets as many closures as the platform (one from its parallelogram). It
    asked which body is the platform; the one where every actuated leg ends is taken, said in the report, with the
    textbook pressure angles, the legs listed in any order, also in millimetres and kilometres and moved in the
    world."""
    azimuths, arms = AZIMUTHS[:3][list(order)], np.array([35.0, 28.0, 40.0])[list(order)]
    path = tmp_path / "hinged_delta.sdf"
    path.write_text(hinged_delta_sdf(arm_angles=arms, azimuths=azimuths, platform_name="low_base",
                                     wrists_onto_platform=True, unit={None: 1.0, "mm": 1e3, "km": 1e-3}[unit],
                                     transform=transform))
    mechanism = load(path, length_unit=unit)
    result = indices_at_pose(mechanism, mechanism.home_pose)
    expected = textbook(geometry((0.01, -0.02, -0.42), arms, azimuths))
    assert mechanism.dof == 3 and len(mechanism.actuators) == 3
    np.testing.assert_allclose(np.ravel(result.iti_actuators), expected["iti"], atol=TOLERANCE)
    np.testing.assert_allclose(result.lmti, expected["lmti"], atol=TOLERANCE)
    assert "platform inferred: body 'low_base', where every actuated leg ends" in " | ".join(mechanism.import_report)


@pytest.mark.parametrize(("unit", "name"), [(1000.0, "mm"), (1e-3, "km")])
def test_the_same_delta_in_another_length_unit_has_the_same_indices(tmp_path, unit, name):
    """Every length times 1000 (millimetres) or 1e-3 (kilometres), read with ``length_unit``: the metre file's
    indices, each leg's with its leg."""
    centre, arms = POSES[1]
    _, metres = indices(tmp_path, centre=centre, arm_angles=arms, platform_leg=2)
    path = tmp_path / f"hinged_delta_{name}.sdf"
    path.write_text(hinged_delta_sdf(centre=centre, arm_angles=arms, platform_leg=2, unit=unit))
    mechanism = load(path, length_unit=name)
    result = indices_at_pose(mechanism, mechanism.home_pose)
    assert_textbook(mechanism, result, textbook(geometry(centre, arms)), TOLERANCE)
    np.testing.assert_allclose(result.iti_actuators, metres.iti_actuators, atol=TOLERANCE)
    np.testing.assert_allclose(result.oti_submechanisms, metres.oti_submechanisms, atol=TOLERANCE)


def test_legs_listed_in_another_order_carry_their_indices_and_the_worst_fault_with_them(tmp_path):
    """The legs written in the order 3, 1, 4, 2 (so motor_k names another leg): each leg's ITI, every OTI and the
    worst single fault follow the leg, and the LMTI and F_O1 do not change."""
    centre, arms = POSES[0]
    order = [2, 0, 3, 1]
    _, first = indices(tmp_path, centre=centre, arm_angles=arms)
    _, second = indices(tmp_path, centre=centre, arm_angles=[arms[k] for k in order],
                        azimuths=AZIMUTHS[order])
    np.testing.assert_allclose(second.iti_actuators, np.asarray(first.iti_actuators)[order], atol=TOLERANCE)
    found = dict(zip(second.submechanisms, second.oti_submechanisms))
    for members, value in zip(first.submechanisms, first.oti_submechanisms):
        renamed = tuple(sorted(order.index(k) for k in members))
        np.testing.assert_allclose(found[renamed], value, atol=TOLERANCE, err_msg=str(members))
    np.testing.assert_allclose([second.lmti, second.f_o[1]], [first.lmti, first.f_o[1]], atol=TOLERANCE)
    worst = [int(name.split(":")[0].split("_")[1]) - 1 for name in first.worst_faults[1]]
    assert second.worst_faults[1] == tuple(f"motor_{order.index(k) + 1}:motor_{order.index(k) + 1}" for k in worst)


@pytest.mark.parametrize(("platform_leg", "half_width", "transform"), [(0, 0.025, None), (2, -0.025, MOVED)])
def test_the_same_delta_written_to_six_decimals_opens_with_three_dof_and_the_indices_of_what_it_rounds(
        tmp_path, platform_leg, half_width, transform):
    centre, arms = POSES[0]
    mechanism, result = indices(tmp_path, centre=centre, arm_angles=arms, platform_leg=platform_leg,
                                half_width=half_width, transform=transform, digits=6)
    assert_textbook(mechanism, result, textbook(geometry(centre, arms)), ROUNDED)
    notes = mechanism.import_report
    assert any("its loops move only to within the file's rounding" in note for note in notes), notes
    assert any("joint axes that agree to the file's rounding written parallel" in note for note in notes), notes


@pytest.mark.parametrize("digits", [None, 6])
def test_a_parallelogram_off_by_micrometres_gives_the_same_indices_whichever_rod_the_tree_runs_through(
        tmp_path, digits):
    """The second rod's lower hinge 4 um further out: read as the parallelogram it nearly is, on the midline
    between the two rods whichever the tree runs through (the rod's own line gave an ITI 8e-4 off, for a 0.5 um
    change)."""
    centre, arms = POSES[1]
    found = [indices(tmp_path, centre=centre, arm_angles=arms, half_width=side, widen=4e-6, digits=digits)[1]
             for side in (0.025, -0.025)]
    np.testing.assert_allclose(found[0].iti_actuators, found[1].iti_actuators, atol=TOLERANCE if digits is None
                               else ROUNDED)
    np.testing.assert_allclose(found[0].iti_actuators, textbook(geometry(centre, arms))["iti"], atol=ROUNDED)


@pytest.mark.parametrize("platform_leg", [0, 2])
def test_the_same_delta_in_mjcf_as_mujoco_reads_it_has_the_textbook_pressure_angles(tmp_path, platform_leg):
    """The tree written in MJCF (every loop hinge two ``<connect>``s on its axis, as CAD exporters write them for
    MuJoCo): MuJoCo reads it closed with every body where screwkit puts it, and the indices are the textbook's."""
    source = tmp_path / "hinged_delta.sdf"
    source.write_text(hinged_delta_sdf(platform_leg=platform_leg))
    tree = read_closed_tree(source)
    q, _ = assemble(tree)
    path = tmp_path / "hinged_delta.xml"
    path.write_text(mjcf_of_tree(tree, q, "platform"))
    mj_model, mj_data = mujoco_state(path)
    assert max(np.max(np.abs(r)) for r in mujoco_residuals(mj_model, mj_data).values()) < TOLERANCE
    mjcf = read_closed_tree(path)
    assert_same_bodies(mjcf, mj_model, mj_data, mjcf.q_reference)
    mechanism = load(path)
    assert_textbook(mechanism, indices_at_pose(mechanism, mechanism.home_pose), textbook(geometry(*POSES[0])),
                    TOLERANCE)


def test_a_trapezoid_is_not_read_as_a_parallelogram_and_is_refused_by_name(tmp_path):
    """The second rod's lower hinge 1 mm further out (4 % of the cross-piece): a four-bar whose coupler turns, far
    beyond rounding."""
    path = tmp_path / "trapezoid.sdf"
    path.write_text(hinged_delta_sdf(widen=1e-3, digits=6))
    with pytest.raises(ImportError_, match=r"trapezoid.sdf: the compound leg joined by closure 'bottom_1b_a', "
                                           r"'bottom_1b_b' cannot be written as serial chains"):
        read_mechanism_file(path)


def test_the_graph_reading_agrees_on_the_exact_file_and_says_the_rounded_one_s_count_turns_on_the_rounding(tmp_path):
    """The graph derivation (the leg's wrench system from its closure Jacobian, not the serial path and equivalent
    chain) gives the same textbook values. Of the rounded file it makes the hinge axes parallel (as the serial
    reading does), but leaves its hinges' positions as written: three of the legs allow the horizontal translations
    only to 1.4e-6 to 2.7e-6, and the count of 1 DOF is said to turn on the rounding (the serial reading,
    which the command takes first, reads 3: the next test)."""
    path = tmp_path / "exact.sdf"
    path.write_text(hinged_delta_sdf(platform_leg=1, half_width=-0.025))
    graph = graph_mechanism(read_closed_tree(path))
    assert_textbook(graph, graph.indices(), textbook(geometry(*POSES[0])), TOLERANCE)
    assert all(line.endswith("twist system of dimension 4") for line in graph.report.chains)
    assert not [note for note in graph.report.notes if "rounding" in note], graph.report.notes
    path = tmp_path / "rounded.sdf"
    path.write_text(hinged_delta_sdf(digits=6))
    rounded = graph_mechanism(read_closed_tree(path))
    assert all(line.endswith("twist system of dimension 4") for line in rounded.report.chains)  # (3 before)
    [turned] = [note for note in rounded.report.notes if note.startswith("joint axes that agree to the file's")]
    [count] = [note for note in rounded.report.notes if note.startswith(DOF_AT_ROUNDING)]
    assert rounded.dof == 1 and "may have up to 3 DOF" in count, count


def test_analyze_opens_the_rounded_file_on_the_command_line(tmp_path):
    path = tmp_path / "delta.sdf"
    path.write_text(hinged_delta_sdf(digits=6, platform_leg=1))
    run = screwkit("analyze", path, "--json")
    assert run.returncode == 0, run.stderr
    found = json.loads(run.stdout)
    expected = textbook(geometry(*POSES[0]))
    assert found["dof"] == 3
    np.testing.assert_allclose(list(found["iti_actuators"].values()), expected["iti"], atol=ROUNDED)
    np.testing.assert_allclose([found["lmti"], found["f_o"]["1"]], [expected["lmti"], expected["f_o1"]], atol=ROUNDED)


def test_parallel_axes_makes_nearly_parallel_directions_parallel_in_any_order_keeping_each_sense():
    rng = np.random.default_rng(4)
    axis = np.array([0.6, -0.48, 0.64])
    tilt = np.cross(axis, [0.0, 0.0, 1.0])
    near = [axis, -axis + 3e-6 * tilt, axis - 2e-6 * tilt, 2.0 * axis + 1e-6 * np.cross(axis, tilt)]
    far = [axis + 0.01 * tilt, np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, -1.0])]
    directions = np.array(near + far)
    turned, turn = parallel_axes(directions)
    units = directions / np.linalg.norm(directions, axis=1, keepdims=True)
    common = turned[0]
    assert np.max(np.linalg.norm(np.cross(turned[:4], common), axis=1)) < 1e-15
    assert np.all(np.sum(turned[:4] * units[:4], axis=1) > 0.999)  # each keeps its own sense
    np.testing.assert_array_equal(turned[4:], units[4:])  # too far apart, or already exactly (anti)parallel
    moved = np.arcsin(np.minimum(np.linalg.norm(np.cross(units[:4], common), axis=1), 1.0))
    assert turn == pytest.approx(np.max(moved), rel=1e-6) and 1e-6 < turn < 1e-5
    order = rng.permutation(len(directions))
    again, turn_again = parallel_axes(directions[order])
    np.testing.assert_allclose(again, turned[order], atol=1e-15)
    assert turn_again == pytest.approx(turn, rel=1e-9)


ANCHOR = "<joint name='anchor' type='fixed'><parent>world</parent><child>base</child></joint>"


def floating(platform_first: bool = False, canonical: str | None = None) -> str:
    """The hinged Delta with no joint to the world (Gazebo would let it float), its platform's <link> written before
    the base's if ``platform_first``, the base named by ``<model canonical_link=...>`` if ``canonical``."""
    text = hinged_delta_sdf().replace(ANCHOR, "")
    starts = [text.index(f"<link name='{name}'>") for name in ("base", "platform")]
    base, platform = (text[start:text.index("</link>", start) + len("</link>")] for start in starts)
    if platform_first:
        text = text.replace(base + platform, platform + base)
    if canonical:
        text = text.replace("<model name='hinged_delta'>", f"<model name='hinged_delta' canonical_link='{canonical}'>")
    return text


def test_a_model_with_no_joint_to_the_world_says_which_link_it_fixed_when_refused(tmp_path):
    """No joint to the world, and the platform's <link> first: SDFormat's canonical link, which screwkit fixes, is the
    platform, and the mechanism read is another one (here its output is on the fixed base). The refusal names the
    link fixed and what names another; with ``<model canonical_link='base'>`` the file reads as the anchored one."""
    anchored = indices(tmp_path)[1]
    (tmp_path / "first.sdf").write_text(floating(platform_first=True))
    message = one_line_error(screwkit("analyze", tmp_path / "first.sdf"))
    assert message.endswith("(The fixed base is the model's first <link> 'platform', as no joint is to the world: a "
                            "joint from the world, or <model canonical_link=...>, names another.)"), message
    for name, text in (("named.sdf", floating(platform_first=True, canonical="base")), ("floating.sdf", floating())):
        (tmp_path / name).write_text(text)
        mechanism = load(tmp_path / name)
        result = indices_at_pose(mechanism, mechanism.home_pose)
        for field in ("iti_actuators", "oti_submechanisms", "lmti"):
            np.testing.assert_allclose(getattr(result, field), getattr(anchored, field), atol=TOLERANCE,
                                       err_msg=f"{name} {field}")


def test_the_chosen_base_is_said_only_where_screwkit_chose_it(tmp_path):
    from screwkit.io.sdformat import with_chosen_base

    cases = {"first.sdf": floating(platform_first=True), "named.sdf": floating(platform_first=True, canonical="base"),
             "anchored.sdf": hinged_delta_sdf()}
    for name, text in cases.items():
        (tmp_path / name).write_text(text)
    assert with_chosen_base(tmp_path / "first.sdf", "refused.").startswith("refused. (The fixed base is the model's "
                                                                          "first <link> 'platform'")
    for name in ("named.sdf", "anchored.sdf"):
        assert with_chosen_base(tmp_path / name, "refused.") == "refused."
    assert with_chosen_base(tmp_path / "first.sdf", "loose: on the way to the canonical link 'platform'.") == \
        "loose: on the way to the canonical link 'platform'."  # (said already)
    assert with_chosen_base(tmp_path / "missing.sdf", "refused.") == "refused."  # (unreadable: as it was)
