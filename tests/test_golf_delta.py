"""A published MuJoCo Delta (D-sorganization/Golf_Modeling_Suite, MIT; ``tests/data/gallery/published/
golf_modeling_suite``): three motor arms, each carrying two rods on hinges parallel to its motor, the rods pinned to
a free platform by ``<connect>``s, the rods of an arm kept parallel by ``<equality><joint>``.

Its hinges leave the platform one motion, along z. Each leg is then a planar crank and rod in its own vertical
plane: ITI = |sin| of the angle between arm and rod, OTI = the rod's cosine with z. The plane's constants (motor
pivot, arm and rod lengths) are read here from MuJoCo's own placement of the joints and connects, and the leg closed
by two circles; screwkit analyses the file as a graph (its rods are loops inside the legs).

At z = pivot - arm - rod every arm and its rods are on one line: the workspace's boundary, where ITI falls to 0.
Posed there exactly, the platform has no motion left; the refusal said "at the file's configuration" and blamed the
file's rounding, where the file opens and is not rounded. It now names the pose asked.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import mujoco
import numpy as np
import pytest

from helpers import one_line_error, screwkit, screwkit_json
from screwkit.io import ImportError_, read_closed_tree
from screwkit.io.graph import graph_mechanism

DELTA = Path(__file__).parent / "data" / "gallery" / "published" / "golf_modeling_suite" / "delta_robot.xml"
START = [("joint1", 30.0), ("joint2", 30.0), ("joint3", 30.0)]
"""The file draws every arm and rod straight down (a dead centre, refused); the refusal advises --initial."""


def _plane() -> tuple[float, float, float, float]:
    """Arm 1's vertical plane as MuJoCo places it at qpos0: the motor pivot's radius and height, the arm's and the
    rod's lengths (in the plane normal to the hinges' common axis)."""
    model = mujoco.MjModel.from_xml_path(str(DELTA))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    joint = {model.joint(k).name: k for k in range(model.njnt)}
    pivot, elbow = data.xanchor[joint["joint1"]], data.xanchor[joint["elbow1a"]]
    axis = data.xaxis[joint["joint1"]]
    connect = next(k for k in range(model.neq) if model.eq_type[k] == mujoco.mjtEq.mjEQ_CONNECT)
    body = model.eq_obj1id[connect]
    end = data.xpos[body] + data.xmat[body].reshape(3, 3) @ model.eq_data[connect][:3]

    def in_plane(v):
        return float(np.linalg.norm(v - np.dot(v, axis) * axis))

    return float(np.hypot(*pivot[:2])), float(pivot[2]), in_plane(elbow - pivot), in_plane(end - elbow)


def _closed_form(z: float) -> tuple[float, float]:
    """ITI and OTI of a leg with the platform's joint line at height ``z`` (the elbow on the arm's side inward, as
    the legs assemble from 30 deg)."""
    radius, height, arm, rod = _plane()
    pivot, joint = np.array([radius, height]), np.array([radius, z])
    apart = np.linalg.norm(joint - pivot)
    along = (arm ** 2 + apart ** 2 - rod ** 2) / (2 * apart)
    across = np.sqrt(max(arm ** 2 - along ** 2, 0.0))
    middle = pivot + along * (joint - pivot) / apart
    normal = np.array([-(joint - pivot)[1], (joint - pivot)[0]]) / apart
    elbow = min((middle + across * normal, middle - across * normal), key=lambda e: e[0])
    u, v = (elbow - pivot) / arm, (joint - elbow) / rod
    return abs(u[0] * v[1] - u[1] * v[0]), abs(v[1])


def _scaled(tmp_path: Path, factor: float) -> Path:
    """The file with every length times ``factor``."""
    def times(match):
        return f'{match.group(1)}="{" ".join(repr(float(x) * factor) for x in match.group(2).split())}"'

    text = re.sub(r'\b(pos|anchor|fromto|size)="([^"]*)"', times, DELTA.read_text())
    path = tmp_path / "delta_mm.xml"
    path.write_text(text)
    return path


def _turned(tmp_path: Path) -> Path:
    """The file with its world body's contents in a ``<frame>`` moved by :data:`SHIFT` and turned by :data:`TURN`
    (a ``<body>`` would hold the platform's free joint, which MuJoCo refuses there)."""
    text = DELTA.read_text()
    start, end = text.index("<worldbody>") + len("<worldbody>"), text.index("</worldbody>")
    quat = " ".join(repr(v) for v in TURN)
    path = tmp_path / "delta_turned.xml"
    path.write_text(f'{text[:start]}<frame pos="{" ".join(map(repr, SHIFT))}" quat="{quat}">{text[start:end]}'
                    f"</frame>{text[end:]}")
    return path


SHIFT, TURN = (0.3, -0.7, 1.9), (0.8, 0.3, -0.4, 0.33)


def _rotation(quat) -> np.ndarray:
    w, x, y, z = np.asarray(quat) / np.linalg.norm(quat)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


@pytest.mark.parametrize("variant", ["m", "mm", "turned"])
def test_indices_are_the_legs_pressure_angles_where_mujoco_places_them(tmp_path, variant):
    path, unit_option = {"m": (DELTA, None), "mm": (_scaled(tmp_path, 1000.0), "mm"),
                         "turned": (_turned(tmp_path), None)}[variant]
    graph = graph_mechanism(read_closed_tree(path, initial=START, length_unit=unit_option))
    place = (lambda p: _rotation(TURN) @ p + np.array(SHIFT)) if variant == "turned" else (lambda p: p)
    assert len(graph.task_axes) == 1
    for z in (-1.2, -2.06, -2.5, -2.9, -2.99):
        result = graph.at_pose(place(np.array([0.0, 0.0, z]))).indices()
        iti, oti = _closed_form(z)
        assert float(result.iti) == pytest.approx(iti, abs=1e-9)
        assert float(result.lmti) == pytest.approx(oti, abs=1e-9)


def test_the_boundary_is_refused_as_the_pose_asked_not_the_file():
    radius, height, arm, rod = _plane()
    graph = graph_mechanism(read_closed_tree(DELTA, initial=START))
    boundary = height - arm - rod
    beside = graph.at_pose([0.0, 0.0, boundary + 1e-6]).indices()
    assert float(beside.iti) == pytest.approx(_closed_form(boundary + 1e-6)[0], abs=1e-9)
    assert float(beside.iti) < 2e-3
    with pytest.raises(ImportError_, match="cannot move at the pose asked") as refused:
        graph.at_pose([0.0, 0.0, boundary])
    assert "file's" not in str(refused.value)


def test_the_command_names_the_pose_asked_at_the_boundary():
    initial = [word for name, value in START for word in ("--initial", name, str(value))]
    opened = screwkit("analyze", DELTA, *initial, "--pose", "-2.5")
    assert opened.returncode == 0, opened.stderr
    assert f"ITI  (Eq. 7)                        {_closed_form(-2.5)[0]:.4f}" in opened.stdout
    radius, height, arm, rod = _plane()
    refused = screwkit("analyze", DELTA, *initial, "--pose", repr(height - arm - rod))
    line = one_line_error(refused, "cannot move at the pose asked", "arm1")
    assert "file's" not in line


def test_actuator_values_are_given_by_actuators_or_by_initial():
    """A graph posed by its motors: ``--actuators`` moves them there from the assembly, ``--initial`` assembles the
    file with them there; every arm turned by 40 deg puts the platform at z = 2 - 2 cos 40 - sqrt(9 - (2 sin 40)^2)
    (the arm 2 and rod 3 of MuJoCo's placement, the platform's joints on the motors' circle), and the indices are the
    closed form's there, both ways."""
    started = [word for name, value in START for word in ("--initial", name, str(value))]
    radius, height, arm, rod = _plane()
    turn = np.radians(40.0)
    z = height - arm * np.cos(turn) - np.sqrt(rod ** 2 - (arm * np.sin(turn)) ** 2)
    driven = screwkit_json("analyze", DELTA, *started, "--actuators", "40", "40", "40")
    assert driven["pose"]["z"] == pytest.approx(z, abs=1e-9)
    assert (driven["iti"], driven["lmti"]) == pytest.approx(_closed_form(z), abs=1e-9)
    initial = [word for name, _ in START for word in ("--initial", name, "40")]
    read = screwkit("analyze", DELTA, *initial, "--json")
    assert read.returncode == 0, read.stderr
    result = json.loads(read.stdout)
    assert result["pose"]["z"] == pytest.approx(z, abs=1e-9)
    assert (result["iti"], result["lmti"]) == pytest.approx(_closed_form(z), abs=1e-9)
