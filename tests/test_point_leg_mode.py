"""A five-bar leg that is the output body's own path keeps its working mode.

A diamond five-bar (a Minitaur-style leg: two thighs on one hip axis, two calves meeting at the knee, the knee point
of the first calf the output) is read as two chains: the first thigh and calf (two hinges, the calf the platform's
own body: no loop joint) and the second (closed onto the first calf at the knee). The first has two joints for the
plane's three task-space rows, so no joint-twist determinant names its working mode, and poses past a fold of the
straight way from the reference were solved with its elbow flipped: a published Minitaur leg read LMTI 0 (the two
calves on one line) where its working mode gives 0.79. The sign of the chain's map to the output point (its elbow)
now names the mode (``closure.newton.working_sign``): each pose reads the reference mode's textbook values, or is
refused saying that the chain closes there only in another assembly.

Textbook, from the knee positions of the reference mode (each thigh's elbow on the side it has in the file): ITI of
leg i = |sin(OB_i, B_iP)|, and with two actuators for two coordinates the LMTI = |sin(B_1P, B_2P)| (each calf's
force against the knee's motion with the other thigh locked).
"""

from __future__ import annotations

import numpy as np
import pytest

from helpers import mjcf_variant, screwkit, sine
from screwkit.closure.forward_kinematics import forward
from screwkit.io.loader import load
from screwkit.studies import indices_at_pose

THIGH, CALF, HIP = 0.1, 0.2, 0.35
"""The thighs' and calves' lengths and the hip's height (m)."""


def diamond(scale: float = 1.0, world=("0 0 0", "1 0 0 0"), names=("thigh1_j", "thigh2_j"), reverse=False) -> str:
    """The leg's MJCF text (angles in degrees, MuJoCo's default), every length times ``scale``; ``names``: the two
    motors' joints; ``reverse``: the second thigh's branch listed first."""
    def length(value: float) -> str:
        return repr(value * scale)

    first = (f'<body name="thigh1"><joint name="{names[0]}" type="hinge" axis="0 1 0"/>'
             f'<body name="calf_long" pos="{length(THIGH)} {length(0.01)} 0" euler="0 120 0">'
             '<joint name="knee1" type="hinge" axis="0 1 0"/></body></body>')
    second = (f'<body name="thigh2" euler="0 180 0" pos="0 {length(0.03)} 0"><joint name="{names[1]}" type="hinge" '
              f'axis="0 1 0"/><body name="calf_short" euler="0 -120 0" pos="{length(THIGH)} {length(-0.01)} 0">'
              '<joint name="knee2" type="hinge" axis="0 1 0"/></body></body>')
    return ('<mujoco model="diamond"><option><flag contact="disable"/></option><worldbody>'
            f'<body name="base" pos="{world[0]}" quat="{world[1]}"><body name="hip" pos="0 0 {length(HIP)}">'
            + (second + first if reverse else first + second) + '</body></body></worldbody>'
            f'<equality><connect name="knee" body1="calf_short" body2="calf_long" anchor="{length(CALF)} 0 0"/>'
            f'</equality><actuator><motor name="m1" joint="{names[0]}"/><motor name="m2" joint="{names[1]}"/>'
            '</actuator></mujoco>')


WRITINGS = {"m": (1.0, None, {}), "mm": (1000.0, "mm", {}), "x1e-3": (1e-3, None, {}), "x1e3": (1e3, None, {}),
            "relabelled": (1.0, None, {"names": ("rear_j", "front_j"), "reverse": True})}
"""The leg written five ways: ``(every length times, --length-unit, diamond's other options)``: in metres, in
millimetres read as such, scaled by 1e-3 and 1e3 (read in metres: poses scale with it), and with its branches listed
the other way round and its motors renamed."""


def _knees(point: np.ndarray) -> list[np.ndarray]:
    """The two knees (in the leg's plane, hip at the origin, x forward and y up) for the knee point ``point`` in the
    reference mode: thigh 1's elbow on the left of the way from the hip to the point, thigh 2's on the right (as
    drawn: the thighs along +x and -x, the point below the hip)."""
    distance = float(np.linalg.norm(point))
    along = (THIGH ** 2 - CALF ** 2 + distance ** 2) / (2 * distance)
    across = np.sqrt(THIGH ** 2 - along ** 2)
    unit = point / distance
    normal = np.array([-unit[1], unit[0]])
    return [along * unit + across * normal, along * unit - across * normal]


def textbook(point) -> tuple[float, float, float]:
    point = np.asarray(point, dtype=float)
    first, second = _knees(point)
    flat = [np.append(v, 0.0) for v in (first, second, point)]
    return (sine(flat[0], flat[2] - flat[0]), sine(flat[1], flat[2] - flat[1]),
            sine(flat[2] - flat[0], flat[2] - flat[1]))


def test_the_reference_mode_is_the_drawing():
    first, second = _knees(np.array([0.0, -CALF * np.sin(np.radians(60.0))]))
    assert first == pytest.approx([THIGH, 0.0], abs=1e-12) and second == pytest.approx([-THIGH, 0.0], abs=1e-12)


def _around_the_hip(mechanism, factor: float):
    """Knee points on four circles about the hip inside the leg's reach, every 30 deg (the offset from the hip,
    x forward and up) with the task pose of each (``factor``: the file's lengths in metres)."""
    hip = mechanism.home_pose - factor * np.array([0.0, CALF * np.sin(np.radians(60.0))])  # (the task y points down)
    for radius in (0.12, 0.17, 0.22, 0.27):
        for angle in np.radians(np.arange(-180, 180, 30)):
            offset = radius * np.array([np.sin(angle), -np.cos(angle)])
            yield offset, hip + factor * np.array([offset[0], -offset[1]])


@pytest.mark.parametrize("writing", sorted(WRITINGS))  # (a turned world takes other in-plane axes: the next tests)
def test_every_pose_in_reach_reads_the_reference_mode(tmp_path, writing):
    """All the way round the hip: the straight way from the reference to a knee point beyond the hip leaves the
    leg's reach (or folds a chain), and the pose is solved from many starts (``closure.around``). Poses past the hip
    were refused before (12 of the 48 of this grid on a published Minitaur leg)."""
    scale, unit, options = WRITINGS[writing]
    path = tmp_path / f"diamond_{writing}.xml"
    path.write_text(diamond(scale, **options))
    mechanism = load(path, length_unit=unit)
    factor = 1.0 if unit else scale  # (poses in metres: the file's lengths unless read in millimetres)
    motors = [f"{name}:{name}" for name in options.get("names", ("thigh1_j", "thigh2_j"))]
    assert mechanism.task_coordinates == ("x", "y")
    for offset, pose in _around_the_hip(mechanism, factor):
        result = indices_at_pose(mechanism, pose)
        iti_1, iti_2, lmti = textbook(offset)
        found = dict(zip(result.actuators, result.iti_actuators))
        assert (found[motors[0]], found[motors[1]], float(result.lmti)) == pytest.approx(
            (iti_1, iti_2, lmti), abs=1e-9), offset


HOME = (0.0, -CALF * np.sin(np.radians(60.0)))
"""The reference knee point from the hip (x forward, y up)."""


@pytest.mark.parametrize("writing", sorted(WRITINGS) + ["turned"])
def test_motors_turned_together_turn_the_reference_assembly(tmp_path, writing):
    """Both motors turned by one angle turn the whole leg about the hip (the thighs' frames turn alike): the
    reference assembly turned, whose indices are the reference's whatever the world frame. At 135 and 180 deg the
    way from the reference pose to the turned one passes the hip, out of the leg's reach, and was refused."""
    if writing == "turned":
        path, unit = mjcf_variant(tmp_path, "diamond", "turned", diamond)
        scale, names = 1.0, ("thigh1_j", "thigh2_j")
    else:
        scale, unit, options = WRITINGS[writing]
        path = tmp_path / f"diamond_{writing}.xml"
        path.write_text(diamond(scale, **options))
        names = options.get("names", ("thigh1_j", "thigh2_j"))
    mechanism = load(path, length_unit=unit)
    order = [mechanism.actuator_names.index(f"{name}:{name}") for name in names]
    expected = textbook(np.array(HOME))
    reached = []
    for angle in (-180.0, -135.0, -90.0, 45.0, 135.0):
        values = np.full(2, np.radians(angle))[order]
        solution = forward(mechanism, values, mechanism.home_pose)
        assert bool(np.asarray(solution.reachable).reshape(-1)[0]), angle
        pose = np.asarray(solution.poses).reshape(-1)
        result = indices_at_pose(mechanism, pose)
        found = dict(zip(result.actuators, result.iti_actuators))
        assert (found[f"{names[0]}:{names[0]}"], found[f"{names[1]}:{names[1]}"], float(result.lmti)) == \
            pytest.approx(expected, abs=1e-9), angle
        reached.append(pose)
    # the knee turned about the hip: half a turn puts it as far beyond the hip as it was before it
    factor = 1.0 if unit else scale
    assert np.linalg.norm(reached[0] - mechanism.home_pose) == pytest.approx(2 * factor * CALF * np.sin(np.radians(
        60.0)), rel=1e-9)


def test_a_turned_world_reads_the_drawing_and_keeps_both_elbows(tmp_path):
    """In a turned world the task frame's in-plane axes are others (so the sweep above, posed in them, is not run
    there): the file's own pose reads the textbook, and each chain keeps the working-mode sign it has in metres in
    the world as drawn."""
    path, unit = mjcf_variant(tmp_path, "diamond", "turned", diamond)
    mechanism = load(path, length_unit=unit)
    home = float(indices_at_pose(mechanism, mechanism.home_pose).lmti)
    assert home == pytest.approx(textbook(np.array([0.0, -CALF * np.sin(np.radians(60.0))]))[2], abs=1e-9)
    drawn = load(mjcf_variant(tmp_path, "diamond", "m", diamond)[0])
    assert [chain.branch for chain in mechanism.chains] == [chain.branch for chain in drawn.chains]
    assert None not in [chain.branch for chain in drawn.chains]


def test_a_sweep_past_the_hip_reads_the_reference_mode_on_the_command_line(tmp_path):
    """The knee point swept from below the hip to above it, beside it (a published Minitaur leg's sweep was refused
    at 6 of 11 poses, after reading LMTI 0 at 5): every row the textbook's."""
    path = tmp_path / "diamond.xml"
    path.write_text(diamond())
    mechanism = load(path)
    hip = float(mechanism.home_pose[1] - CALF * np.sin(np.radians(60.0)))  # (the task y points down)
    process = screwkit("sweep", path, "--sweep", f"y:{hip - 0.25!r}:{hip + 0.26!r}:0.05", "--at", "0.12", "0",
                       "--quiet")
    assert process.returncode == 0, process.stderr
    lines = process.stdout.strip().splitlines()
    header = lines[0].split(",")
    rows = [dict(zip(header, line.split(","))) for line in lines[1:]]
    assert len(rows) == 11
    for row in rows:
        up = hip - float(row["y"])
        assert row["reachable"] == "True", row
        assert float(row["lmti"]) == pytest.approx(textbook(np.array([0.12, up]))[2], abs=1e-9), up
