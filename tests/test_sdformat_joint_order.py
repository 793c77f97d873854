"""An SDFormat mechanism reads the same whatever the order its joints and links are written in.

SDFormat writes a loop as joints among links: which joint closes the loop is screwkit's choice (the spanning tree
it grows from the base). The choice followed the file's order: a four-bar whose rocker is the output, its joints
written in reverse, was cut at the crank's coupler pin instead of the rocker's, read as a leg with a loop inside
(a graph) instead of serial legs, with another task coordinate and another CTI (gazebosim/sdformat's
``test/sdf/four_bar.sdf``: 0.98974 in the file's order, 0.98624 in reverse, at the same configuration). With
``--output`` naming the platform, the platform is reached last, so each leg ends on it whatever the order.

The indices are checked against the four-bar's closed forms (the coupler's pressure angles on the crank and on the
rocker), at three drawn configurations, for every order of the four joints, with the links reversed, in mm, and
in a turned and shifted world. The same four-bar, turned so that its rocker's pin moves mostly along y, takes y
for its one task coordinate (the fastest), and reaches the whole stroke.
"""

from __future__ import annotations

from itertools import permutations

import numpy as np
import pytest

from screwkit.io.loader import load
from screwkit.studies import indices_at_pose

A, D = np.array([0.0, 0.0]), np.array([0.3, 0.0])
CRANK, COUPLER, ROCKER = 0.1, 0.25, 0.2


def _points(theta: float) -> tuple[np.ndarray, np.ndarray]:
    """B (crank-coupler pin) and C (coupler-rocker pin, the upper assembly) at crank angle ``theta``."""
    b = A + CRANK * np.array([np.cos(theta), np.sin(theta)])
    gap = D - b
    distance = np.linalg.norm(gap)
    along = (COUPLER ** 2 - ROCKER ** 2 + distance ** 2) / (2 * distance)
    height = np.sqrt(COUPLER ** 2 - along ** 2)
    c = b + along * gap / distance + height * np.array([-gap[1], gap[0]]) / distance
    return b, c


def _sine(u: np.ndarray, v: np.ndarray) -> float:
    return abs(u[0] * v[1] - u[1] * v[0]) / (np.linalg.norm(u) * np.linalg.norm(v))


def four_bar_sdf(theta: float, order=(0, 1, 2, 3), links_reversed: bool = False, scale: float = 1.0,
                 world=(0.0, (0.0, 0.0, 0.0))) -> str:
    """The four-bar drawn at crank angle ``theta``: joints ``crank_pin`` (A), ``coupler_pin`` (B), ``rocker_pin``
    (C), ``rocker_pivot`` (D) written in ``order``; the model turned by ``world[0]`` rad about z and shifted."""
    b, c = _points(theta)
    places = {"ground": A, "crank": A, "coupler": b, "rocker": D}
    links = "".join(f'<link name="{name}"><pose>{scale * x} {scale * y} 0 0 0 0</pose></link>'
                    for name, (x, y) in (reversed(places.items()) if links_reversed else places.items()))
    joints = [("crank_pin", "ground", "crank", A), ("coupler_pin", "crank", "coupler", b),
              ("rocker_pin", "coupler", "rocker", c), ("rocker_pivot", "ground", "rocker", D)]
    written = ""
    for k in order:
        name, parent, child, at = joints[k]
        local = (at - places[child]) * scale
        written += (f'<joint name="{name}" type="revolute"><parent>{parent}</parent><child>{child}</child>'
                    f'<pose>{local[0]} {local[1]} 0 0 0 0</pose><axis><xyz>0 0 1</xyz></axis></joint>')
    turn, shift = world
    return (f'<sdf version="1.7"><model name="four_bar"><pose>{" ".join(map(str, shift))} 0 0 {turn}</pose>'
            f'<joint name="to_world" type="fixed"><parent>world</parent><child>ground</child></joint>'
            f"{links}{written}</model></sdf>")


def _read(tmp_path, text: str, name: str, **options):
    path = tmp_path / f"{name}.sdf"
    path.write_text(text)
    mechanism = load(path, output="rocker", actuate=("crank_pin",), **options)
    return mechanism, indices_at_pose(mechanism, mechanism.home_pose)


@pytest.mark.parametrize("theta", [np.deg2rad(60.0), np.deg2rad(100.0), np.deg2rad(25.0)])
def test_every_joint_order_reads_the_four_bar_of_the_closed_forms(tmp_path, theta):
    b, c = _points(theta)
    iti = _sine(b - A, c - b)  # the coupler's force on the crank's pin B
    oti = _sine(c - b, c - D)  # that force against the rocker's pin C's motion
    readings = set()
    for number, order in enumerate(permutations(range(4))):
        mechanism, result = _read(tmp_path, four_bar_sdf(theta, order, links_reversed=number % 2 == 1), f"o{number}")
        assert float(result.iti) == pytest.approx(iti, abs=1e-10), order
        assert float(result.lmti) == pytest.approx(oti, abs=1e-10), order
        readings.add((mechanism.task_coordinates,
                      frozenset(line for line in mechanism.import_report if line.lstrip().startswith("chain "))))
        _, framed = _read(tmp_path, four_bar_sdf(theta, order), f"f{number}", output_type="frame")
        assert float(framed.iti) == pytest.approx(iti, abs=1e-10)
        if number == 0:
            cti = float(framed.cti)
        assert float(framed.cti) == pytest.approx(cti, abs=1e-12), order
    assert len(readings) == 1, readings  # the same legs and task coordinates (listed in the file's order)


@pytest.mark.parametrize("order", [(0, 1, 2, 3), (3, 2, 1, 0), (2, 0, 3, 1)])
def test_the_reading_is_the_same_in_mm_and_in_a_turned_world(tmp_path, order):
    theta = np.deg2rad(70.0)
    _, plain = _read(tmp_path, four_bar_sdf(theta, order), "plain", output_type="frame")
    _, mm = _read(tmp_path, four_bar_sdf(theta, order, scale=1000.0), "mm", output_type="frame", length_unit="mm")
    _, turned = _read(tmp_path, four_bar_sdf(theta, order, world=(0.7, (0.4, -1.2, 2.0))), "turned",
                      output_type="frame")
    for other in (mm, turned):
        for field in ("iti", "lmti", "cti"):
            assert float(getattr(other, field)) == pytest.approx(float(getattr(plain, field)), abs=1e-12), field


def test_the_command_reads_both_orders_alike(tmp_path):
    """``screwkit analyze FILE --output rocker``, the four-bar written in file order and in reverse."""
    import json

    from helpers import screwkit

    readings = []
    for name, order in (("forward", (0, 1, 2, 3)), ("reverse", (3, 2, 1, 0))):
        (tmp_path / f"{name}.sdf").write_text(four_bar_sdf(np.deg2rad(60.0), order))
        done = screwkit("analyze", tmp_path / f"{name}.sdf", "--output", "rocker", "--actuate", "crank_pin",
                        "--output-type", "frame", "--json")
        assert done.returncode == 0, done.stderr
        readings.append(json.loads(done.stdout))
    forward, reverse = readings
    assert forward["pose"] == reverse["pose"] and forward["dependent"] == reverse["dependent"]
    for key in ("iti", "lmti", "cti"):
        assert reverse[key] == pytest.approx(forward[key], abs=1e-12), key


@pytest.mark.parametrize("turn, scale", [(np.deg2rad(40.0), 1.0), (np.deg2rad(-140.0), 1.0),
                                         (np.deg2rad(40.0), 1e3), (np.deg2rad(40.0), 1e-3)])
def test_one_motion_takes_the_coordinate_it_runs_along_fastest(tmp_path, turn, scale):
    """The rocker's pin as the output, the four-bar turned so that the pin moves mostly along y, 9 deg from the
    place where its x turns back: x, first in order and moving at 0.16 of the speed, was taken, and crank angles
    past that place could not be asked. y is taken now, and every crank angle of the stroke is reached, with the
    closed forms' indices."""
    from screwkit.closure.forward_kinematics import forward

    theta = np.deg2rad(180.0)
    path = tmp_path / "turned.sdf"
    path.write_text(four_bar_sdf(theta, scale=scale, world=(turn, (0.0, 0.0, 0.0))))
    unit = {1e3: "mm", 1e-3: "km"}.get(scale)  # (the file written in that unit, read in metres)
    mechanism = load(path, output="rocker", actuate=("crank_pin",), output_type="point", length_unit=unit)
    assert mechanism.task_coordinates == ("y",)
    for change in (-10.0, -25.0, -40.0, -60.0, -80.0):
        solution = forward(mechanism, [np.deg2rad(change)], mechanism.home_pose)
        assert bool(np.ravel(solution.reachable)[0]), change
        b, c = _points(theta + np.deg2rad(change))
        result = indices_at_pose(mechanism, np.ravel(solution.poses))
        assert float(result.iti) == pytest.approx(_sine(b - A, c - b), abs=1e-9), change
        assert float(result.lmti) == pytest.approx(_sine(c - b, c - D), abs=1e-9), change
