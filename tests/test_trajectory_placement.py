"""A path driven by the actuators has one arc length wherever the file places the mechanism.

The task coordinates are taken in the file's world frame: a one-DoF linkage turned in the world takes its plane's
y for its coordinate where it took x, and a spherical manipulator's roll, pitch and yaw rates change with its turn.
Measured in task coordinates, the same actuator values gave another arc length (7 to 49 % on six published files),
so other positions of every event and stretch and another meaning of ``--tolerance``. Measured along the actuators
(angles times the length scale, m for slides) it is the same in a turned and moved world, in millimetres and with
the legs listed in another order, and scales with the mechanism.
"""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr
from scipy.spatial.transform import Rotation
from test_four_bar_output import four_bar_mjcf
from test_meeting_lines import spm_mjcf
from test_relabelling import listed_otherwise

from helpers import bundled, in_millimetres, moved_in_the_world, screwkit_json
from screwkit.closure import solve
from screwkit.closure.solve import actuator_values
from screwkit.io.loader import bundled_path, load, load_text
from screwkit.studies.actuator_paths import actuator_columns, path_from_actuators
from screwkit.studies.paths import line_path
from screwkit.studies.trajectory import trajectory

CRANK = np.linspace(-0.4, 0.6, 21)[:, None]
"""The knee's crank, driven from -0.4 to 0.6 rad of its file's angle (its only actuator)."""


KNEE_WORLDS = {"m": (1.0, None, ("0 0 0", "1 0 0 0")), "mm": (1000.0, "mm", ("0 0 0", "1 0 0 0")),
               "turned": (1.0, None, ("0.4 -0.3 1.1", "0.8 0.3 -0.4 0.33"))}
"""The knee in metres, in millimetres, and moved and turned so that its plane's y is its coordinate."""


def test_a_one_dof_linkage_turned_in_the_world_has_the_same_arc_length_and_events(tmp_path):
    """The knee's coupler point: x its task coordinate as written, y in the turned world (its plane's projection of
    the world's axes; measured along it, the same crank turn was 0.065 m of arc against 0.078 m). Its arc length is
    the crank's turn times the length scale, in m, in mm and turned, and the minimum of its ITI is at the same arc
    length in all three (to the refinement's tolerance)."""
    variants = {}
    for variant, (scale, unit, world) in KNEE_WORLDS.items():
        (tmp_path / f"{variant}.xml").write_text(four_bar_mjcf(scale=scale, world=world))
        variants[variant] = load(tmp_path / f"{variant}.xml", length_unit=unit, output="coupler")
    assert variants["m"].task_coordinates == ("x",) and variants["turned"].task_coordinates == ("y",)
    reference = None
    for variant, mechanism in variants.items():
        path = path_from_actuators(mechanism, CRANK)
        np.testing.assert_allclose(path.arc_length, mechanism.length_scale * (CRANK[:, 0] - CRANK[0, 0]),
                                   rtol=1e-13, atol=0)
        result = trajectory(mechanism, path)
        if reference is None:
            reference = path, result
            continue
        np.testing.assert_allclose(path.arc_length, reference[0].arc_length, rtol=1e-12, atol=0, err_msg=variant)
        for name, margin in reference[1].margins.items():
            assert result.margins[name].value == pytest.approx(margin.value, abs=1e-9), (variant, name)
            assert result.margins[name].arc_length == pytest.approx(margin.arc_length,
                                                                    abs=2 * reference[1].tolerance), (variant, name)
    turned = variants["turned"]
    wrapped = CRANK.copy()  # a log written in [-180, 180) deg: the crank's step the short way round, as driven
    wrapped[10:] -= 2.0 * np.pi
    again = path_from_actuators(turned, wrapped)
    np.testing.assert_allclose(again.poses, path_from_actuators(turned, CRANK).poses, atol=1e-12)
    np.testing.assert_allclose(again.arc_length, reference[0].arc_length, rtol=1e-12)
    np.savetxt(tmp_path / "crank.csv", np.rad2deg(CRANK), header=actuator_columns(turned)[0][0], comments="")
    summary = screwkit_json("trajectory", tmp_path / "turned.xml", tmp_path / "crank.csv", "--actuators", "--output",
                            "coupler", "--quiet", "--out", tmp_path / "crank.nc")
    assert summary["length_m"] == pytest.approx(reference[0].length, rel=1e-12)
    assert summary["arc_length"] == "along the actuators"
    with xr.open_dataset(tmp_path / "crank.nc", engine="scipy") as written:  # the file says which arc length
        assert written["arc_length"].attrs["long_name"] == "arc length along the actuators"


def test_a_spherical_manipulator_turned_in_the_world_has_the_same_arc_length(tmp_path):
    """Its three motors swung about their file's angles: roll, pitch and yaw rates of the platform in a world
    turned about three axes are other rates, the motors' the same; the turned file written in millimetres
    likewise. The indices at every sample and their minima's positions are the same."""
    turn = Rotation.from_euler("xyz", [0.7, -0.4, 1.1]).as_matrix()
    phase = np.linspace(0.0, 2.0 * np.pi, 17)[:, None]
    values = 0.12 * np.sin(phase + np.array([0.0, 2.1, 4.2]))
    mechanisms = []
    for unit in (1.0, 1000.0):
        (tmp_path / f"spm_{unit:g}.xml").write_text(spm_mjcf(unit=unit, turn=turn))
        mechanisms.append(load(tmp_path / f"spm_{unit:g}.xml", length_unit="mm" if unit > 1 else None,
                               output="platform"))
    (tmp_path / "spm_plain.xml").write_text(spm_mjcf())
    plain = load(tmp_path / "spm_plain.xml", output="platform")
    assert plain.task_coordinates == ("roll", "pitch", "yaw")
    expected_path = path_from_actuators(plain, values)
    steps = plain.length_scale * np.linalg.norm(np.diff(values, axis=0), axis=1)
    np.testing.assert_allclose(expected_path.arc_length[1:], np.cumsum(steps), rtol=1e-13)
    expected = trajectory(plain, expected_path)
    for mechanism in mechanisms:
        path = path_from_actuators(mechanism, values)
        np.testing.assert_allclose(path.arc_length, expected_path.arc_length, rtol=1e-12, atol=0)
        result = trajectory(mechanism, path)
        np.testing.assert_allclose(result.indices.lmti, expected.indices.lmti, atol=1e-9)
        for name, margin in expected.margins.items():
            assert result.margins[name].arc_length == pytest.approx(margin.arc_length, abs=2 * expected.tolerance)


def test_a_redundant_hexapod_loses_control_on_the_same_stretches_however_placed_written_or_listed():
    """The 8-UPS hexapod's leg lengths along a line through its workspace (inverse kinematics), driven in a moved
    world, in millimetres and with its legs listed in another order and renamed (the values given by name):
    every failure loses control on the same stretches of the same arc length."""
    hexapod = bundled("ups_hexapod_8")
    home = hexapod.home_pose
    posed = line_path(hexapod, home + [-0.03, 0.02, -0.01, 0.05, -0.08, 0.3],
                      home + [0.04, -0.03, 0.02, -0.06, 0.09, -0.35], 25)
    values = actuator_values(hexapod, solve(hexapod, posed.poses).joint_values)
    expected = trajectory(hexapod, path_from_actuators(hexapod, values), level=0.55)
    assert sum(case.lost.size for case in expected.cases) >= 4  # some failures lose control on the way
    text = bundled_path("ups_hexapod_8").read_text()
    listed, renamed = listed_otherwise(text, np.random.default_rng(7), rename=True)
    variants = {"moved": (load_text(moved_in_the_world(text, (0.4, -1.3, 0.7), (0.3, -0.5, 2.0)), "moved.urdf"), {}),
                "mm": (load_text(in_millimetres(text, declare=True), "mm.urdf"), {}),
                "listed": (load_text(listed, "listed.urdf"), renamed)}
    for variant, (mechanism, names) in variants.items():
        original = [f"{names.get(chain, chain)}:{joint}" for chain, joint in mechanism.actuators]
        assert variant != "listed" or original != list(hexapod.actuator_names)
        columns = [hexapod.actuator_names.index(name) for name in original]
        result = trajectory(mechanism, path_from_actuators(mechanism, values[:, columns]), level=0.55)
        np.testing.assert_allclose(result.path.arc_length, expected.path.arc_length, rtol=1e-12, atol=0,
                                   err_msg=variant)
        cases = {frozenset(f"{names.get(c, c)}:{j}" for c, _, j in (a.partition(":") for a in case.failed)): case
                 for case in result.cases}
        for case in expected.cases:
            np.testing.assert_allclose(cases[frozenset(case.failed)].lost, case.lost, rtol=0,
                                       atol=2 * expected.tolerance, err_msg=f"{variant} {case.failed}")


@pytest.mark.parametrize("scale", [1e-3, 1e3])
def test_the_arc_length_of_a_linkage_scaled_scales_with_it(tmp_path, scale):
    """The knee a thousand times smaller or larger, read in metres: every arc length, and the ITI minimum's place
    on it, times the scale; the indices the same."""
    results = {}
    for factor in (1.0, scale):
        (tmp_path / f"knee_{factor:g}.xml").write_text(four_bar_mjcf(scale=factor))
        mechanism = load(tmp_path / f"knee_{factor:g}.xml", output="coupler")
        result = trajectory(mechanism, path_from_actuators(mechanism, CRANK))
        results[factor] = result
    small, big = results[1.0], results[scale]
    np.testing.assert_allclose(big.path.arc_length, scale * small.path.arc_length, rtol=1e-12, atol=0)
    np.testing.assert_allclose(big.indices.iti, small.indices.iti, atol=1e-9)
    assert big.margins["iti"].arc_length == pytest.approx(scale * small.margins["iti"].arc_length,
                                                          abs=2 * big.tolerance)
