"""A file in screwkit's own convention written rounded reads as the mechanism drawn (``screwkit.io.drawn_loops``).

The bundled Delta (Tsai's R-U-U legs) with every number written to 6 decimals read 2 DOF and refused its own home
pose; to 5 decimals its first loop did not close; the 3-PRS + UPS and the Schoenflies mechanism were refused at both.
The checks are against the Delta's pressure-angle closed forms (``test_delta_schoenflies.delta_expected``), against
each bundled file as generated (16 digits), and between the rounded Delta in metres, in millimetres, in a turned
world and with its legs named the other way round.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
from test_delta_schoenflies import delta_expected, delta_poses

from helpers import in_unit, moved_in_the_world, one_line_error, screwkit
from screwkit.closure.assembly import DRAWN_AT_ROUNDING
from screwkit.io.loader import bundled_names, bundled_path, load
from screwkit.studies import indices_at_pose, indices_at_poses

NUMBER = re.compile(r"(?<![\w.#])-?\d+\.\d+(?:[eE][-+]?\d+)?")


def rounded(text: str, decimals: int) -> str:
    """``text`` with every decimal number written to ``decimals`` decimals (names, such as ``leg_1``, untouched)."""
    return NUMBER.sub(lambda m: repr(round(float(m.group(0)), decimals)), text)


def written(folder: Path, name: str, text: str) -> Path:
    path = folder / f"{name}.urdf"
    path.write_text(text)
    return path


def drawn_note(mechanism) -> str:
    [note] = [note for note in mechanism.assembly_notes if note.startswith(DRAWN_AT_ROUNDING)]
    return note


@pytest.mark.parametrize(("decimals", "tolerance"), [(6, 1e-6), (5, 1e-5)])
def test_the_delta_written_rounded_has_the_pressure_angle_closed_forms(tmp_path, decimals, tolerance):
    """At the named poses and 20 random ones, the ITI of each leg, the OTI of each 3-leg set and F_O1 are the closed
    forms' for the exact Delta to the rounding's order (measured 1.7e-7 at 6 decimals, 1.8e-6 at 5)."""
    delta = load(written(tmp_path, "delta", rounded(bundled_path("delta_4").read_text(), decimals)))
    assert delta.dof == 3 and delta.task_coordinates == ("x", "y", "z")
    note = drawn_note(delta)
    assert "written parallel" in note and "'leg_1_joint_platform'" in note, note
    poses = delta_poses(20, seed=5)
    result = indices_at_poses(delta, poses, detail=True)
    assert result.reachable.all()
    for index, pose in enumerate(poses):
        expected = delta_expected(pose)
        np.testing.assert_allclose(result.iti_actuators[index], expected["iti_actuators"], rtol=0, atol=tolerance)
        np.testing.assert_allclose(result.oti_submechanisms[index], expected["oti_submechanisms"], rtol=0,
                                   atol=tolerance)
        assert abs(result.f_o[1][index] - expected["f_o1"]) <= tolerance


@pytest.mark.parametrize("decimals", [6, 5])
@pytest.mark.parametrize("name", bundled_names())
def test_every_bundled_file_written_rounded_reads_as_generated(tmp_path, name, decimals):
    """Each bundled file with its numbers written to 6 or 5 decimals: the DOF, task coordinates and actuators of the
    file as generated, its home within the rounding, and its indices there within 3e-5 (the 8-RSS hexapod at 5
    decimals, 2.2e-5, is the furthest)."""
    exact = load(name)
    copy = load(written(tmp_path, name, rounded(bundled_path(name).read_text(), decimals)))
    assert (copy.dof, copy.task_coordinates, copy.actuator_names) == (exact.dof, exact.task_coordinates,
                                                                      exact.actuator_names)
    np.testing.assert_allclose(copy.home_pose, exact.home_pose, rtol=0, atol=10.0 ** -decimals * 5)
    first, second = indices_at_pose(exact, exact.home_pose), indices_at_pose(copy, copy.home_pose)
    np.testing.assert_allclose(second.iti_actuators, first.iti_actuators, rtol=0, atol=3e-5)
    np.testing.assert_allclose([second.lmti, second.f_o[1]], [first.lmti, first.f_o[1]], rtol=0, atol=3e-5)


def renamed_legs(text: str) -> str:
    """The Delta's legs named the other way round: leg_1 is leg_4, leg_2 is leg_3 (chains and actuators ordered by
    name come in the other order)."""
    return re.sub(r"leg_([1-4])", lambda m: f"leg_{5 - int(m.group(1))}", text)


def test_the_rounded_delta_reads_alike_in_millimetres_in_a_turned_world_and_with_its_legs_renamed(tmp_path):
    """The Delta to 6 decimals in metres; the same file in millimetres; hung in a world turned and
    moved (a fixed joint above its base); its legs named the other way round: the same note, word for word (the
    renamed one names its loops in the other order), and at five poses the same indices per leg to 1e-9."""
    text = rounded(bundled_path("delta_4").read_text(), 6)
    files = {"m": text, "mm": in_unit(text, "mm", 1000.0, declare=True),
             "world": moved_in_the_world(text, (0.4, -1.3, 2.1), (0.7, -1.1, 2.3)), "renamed": renamed_legs(text)}
    mechanisms = {label: load(written(tmp_path, label, source)) for label, source in files.items()}
    notes = {label: drawn_note(mechanism) for label, mechanism in mechanisms.items()}
    assert notes["mm"] == notes["world"] == notes["m"]
    turn = re.search(r"largest turn ([0-9.e-]+) rad", notes["m"]).group(1)
    assert f"largest turn {turn} rad" in notes["renamed"]
    poses = delta_poses(4, seed=9)
    reference = indices_at_poses(mechanisms["m"], poses, detail=True)
    order = {"renamed": [3, 2, 1, 0]}
    for label, mechanism in mechanisms.items():
        result = indices_at_poses(mechanism, poses, detail=True)
        legs = order.get(label, [0, 1, 2, 3])
        np.testing.assert_allclose(result.iti_actuators[:, legs], reference.iti_actuators, rtol=0, atol=1e-9,
                                   err_msg=label)
        np.testing.assert_allclose(result.f_o[1], reference.f_o[1], rtol=0, atol=1e-9, err_msg=label)
        np.testing.assert_allclose(result.lmti, reference.lmti, rtol=0, atol=1e-9, err_msg=label)


def test_the_commands_say_what_the_rounding_changed_and_refuse_a_loop_beyond_it_in_one_line(tmp_path):
    """``screwkit analyze`` of the Delta to 6 decimals: exit 0, its note on stderr and in the JSON's assembly notes.
    To 4 decimals its loops miss by 1.3e-5 rad, beyond the rounding read as drawn: one line naming the loop and
    saying so."""
    path = written(tmp_path, "delta6", rounded(bundled_path("delta_4").read_text(), 6))
    run = screwkit("analyze", path, "--json")
    assert run.returncode == 0, run.stderr
    assert f"{path}: {DRAWN_AT_ROUNDING}" in run.stderr
    assembly = json.loads(run.stdout)["assembly"]
    assert [note for note in assembly if note.startswith(DRAWN_AT_ROUNDING)] == [drawn_note(load(path))]
    beyond = written(tmp_path, "delta4", rounded(bundled_path("delta_4").read_text(), 4))
    message = one_line_error(screwkit("analyze", beyond))
    assert re.search(r"<loop name='leg_\d_joint_platform'>: does not close at the reference configuration", message)
    assert "more than the file's rounding read as drawn" in message, message
