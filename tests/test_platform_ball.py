"""A platform that hangs from one of its legs by a ball joint, the other legs closed onto it by ``<connect>``s.

A hand-written MJCF Stewart platform often nests the platform body in its first leg, on a ``<joint type="ball">``,
and closes the other five legs onto it: six U-P-S legs here (a universal joint on the base as two hinges, the
actuated slide, a ball under the platform). The first leg's ball is its loop joint, as the other legs' balls are
theirs: it was read as a joint inside a leg, so that ``screwkit.load`` and ``screwkit convert`` refused the file
("joint 'ball_0' (spherical) inside a leg"), and the commands read it as legs with loops inside them. Checked
against the leg-line indices of MuJoCo's own placement of the joints (ITI = 1: the force along the leg and the
slide's motion along it; OTI_k at leg k's ball, of the platform twist reciprocal to the other five leg forces), as
written, in millimetres, in a moved world, and with the platform nested in another leg; against the graph reading
of the same file; and through ``screwkit convert``. Three such legs meeting at the ball the platform hangs on read
that point as the output; a wrist turning on a ball on the base reads its rotations.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from helpers import leg_line_otis, screwkit
from screwkit.common.rotations import rotation_from_rpy
from screwkit.io import graph_mechanism, read_closed_tree
from screwkit.io.loader import load
from screwkit.studies import indices_at_pose

BASE = [0.5 * np.array([np.cos(a), np.sin(a), 0.0]) for a in np.radians([-12, 12, 108, 132, 228, 252])]
TOP = [np.array([0.03, -0.02, 0.62]) + 0.3 * np.array([np.cos(a), np.sin(a), 0.0])
       for a in np.radians([-50, 55, 70, 175, 190, 295])]


INERTIAL = '<inertial pos="0 0 0" mass="0.01" diaginertia="1e-5 1e-5 1e-5"/>'


def _quaternion(rotation: np.ndarray) -> np.ndarray:
    found = np.zeros(4)
    mujoco.mju_mat2Quat(found, np.ascontiguousarray(rotation).ravel())
    return found


def stewart_mjcf(carrier: int = 0, scale: float = 1.0, world=None, base=BASE, top=TOP) -> str:
    """U-P-S legs from ``base`` to ``top`` (six by default), the platform nested in leg ``carrier`` on a ball joint;
    lengths times ``scale``; the base placed in the world by ``world`` (rpy, xyz), if given."""
    def text(vector):
        return " ".join(repr(float(v)) for v in vector)

    legs, connects = [], []
    for k, (b, p) in enumerate(zip(base, top)):
        axis = (p - b) / np.linalg.norm(p - b)
        side = np.cross([0.0, 0.0, 1.0], axis)
        side /= np.linalg.norm(side)
        frame = np.column_stack([side, np.cross(axis, side), axis])  # the leg's frame: z along the leg
        length = float(np.linalg.norm(p - b))
        end = f'<body name="end_{k}" pos="0 0 {scale * length!r}">{INERTIAL}'
        if k == carrier:  # the platform on this leg's ball, its frame the world's
            end += (f'<body name="platform" quat="{text(_quaternion(frame.T))}"><joint name="ball_{k}" type="ball"/>'
                    '<inertial pos="0 0 0" mass="0.1" diaginertia="1e-4 1e-4 1e-4"/></body>')
        else:
            connects.append(f'<connect name="loop_{k}" body1="end_{k}" body2="platform" anchor="0 0 0"/>')
        legs.append(f'<body name="cup_{k}" pos="{text(scale * b)}" quat="{text(_quaternion(frame))}">'
                    f'<joint name="u1_{k}" type="hinge" axis="1 0 0"/>{INERTIAL}'
                    f'<body name="cylinder_{k}"><joint name="u2_{k}" type="hinge" axis="0 1 0"/>{INERTIAL}'
                    f'<body name="rod_{k}"><joint name="slide_{k}" type="slide" axis="0 0 1"/>{INERTIAL}'
                    f'{end}</body></body></body></body>')
    turn = None if world is None else _quaternion(rotation_from_rpy(world[0]))
    placed = "" if world is None else f' pos="{text(world[1])}" quat="{text(turn)}"'
    actuators = "".join(f'<position joint="slide_{k}"/>' for k in range(len(base)))
    return (f'<mujoco model="stewart"><worldbody><body name="base"{placed}>{"".join(legs)}</body></worldbody>'
            f'<equality>{"".join(connects)}</equality><actuator>{actuators}</actuator></mujoco>')


def mujoco_leg_lines(text: str, scale: float, legs: int = 6):
    """Each leg's universal-joint centre and ball centre as MuJoCo places them (in the file's lengths over
    ``scale``), in the order of the legs."""
    model = mujoco.MjModel.from_xml_string(text)
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    starts = [data.xanchor[model.joint(f"u1_{k}").id] / scale for k in range(legs)]
    ends = [data.xpos[model.body(f"end_{k}").id] / scale for k in range(legs)]
    return np.array(starts), np.array(ends)


SCALES = {None: 1.0, "mm": 1e3, "km": 1e-3}
"""The factor of the file's lengths for each --length-unit the tests read it in."""
WORLD = ((0.4, -0.3, 1.1), (0.3, -0.2, 0.5))
"""A world the mechanisms are turned (rpy, rad) and moved (xyz, m) into."""


@pytest.mark.parametrize("carrier, unit, world", [(0, None, None), (3, None, None), (0, "mm", None),
                                                  (2, None, WORLD), (1, "km", WORLD)])
def test_a_platform_on_a_legs_ball_reads_the_leg_line_indices(tmp_path, carrier, unit, world):
    scale = SCALES[unit]
    text = stewart_mjcf(carrier, scale, world)
    path = tmp_path / "stewart.xml"
    path.write_text(text)
    mechanism = load(path, length_unit=unit)
    result = indices_at_pose(mechanism, mechanism.home_pose)
    names = [name.split(":")[-1] for name in mechanism.actuator_names]
    assert sorted(names) == [f"slide_{k}" for k in range(6)] and result.dof == 6
    starts, ends = mujoco_leg_lines(text, scale)
    order = [int(name.split("_")[-1]) for name in names]
    expected = leg_line_otis(starts[order], ends[order])
    np.testing.assert_allclose(np.ravel(result.iti_actuators), np.ones(6), atol=1e-9)
    np.testing.assert_allclose(result.oti_actuators[0], expected, atol=1e-9)
    assert 0.05 < min(expected) < max(expected) < 0.99  # neither singular nor trivially 1
    assert any("loop spherical (the platform body's own path)" in line for line in mechanism.import_report), \
        mechanism.import_report
    graph = graph_mechanism(read_closed_tree(path, length_unit=unit)).indices()  # the graph reading of the file
    np.testing.assert_allclose(graph.lmti, result.lmti, atol=1e-9)


def test_convert_writes_the_platform_on_a_legs_ball_in_the_convention(tmp_path):
    """``screwkit convert``, run as users do: the file it writes reads the leg-line indices of the source."""
    source, written = tmp_path / "stewart.xml", tmp_path / "stewart.urdf"
    source.write_text(stewart_mjcf(1))
    done = screwkit("convert", source, written)
    assert done.returncode == 0, done.stderr
    mechanism = load(written)
    result = indices_at_pose(mechanism, mechanism.home_pose)
    starts, ends = mujoco_leg_lines(source.read_text(), 1.0)
    order = [int(name.split(":")[-1].split("_")[-1]) for name in mechanism.actuator_names]
    np.testing.assert_allclose(result.oti_actuators[0], leg_line_otis(starts[order], ends[order]), atol=1e-9)


@pytest.mark.parametrize("carrier, unit, world", [(0, None, None), (2, None, WORLD), (1, "mm", None),
                                                  (0, "km", WORLD)])
def test_three_legs_meeting_where_the_platform_hangs_on_a_ball_read_that_point(tmp_path, carrier, unit, world):
    """Three U-P-S legs whose balls meet at one point, the platform on one of them: the output is that point (x, y,
    z; the platform's turns about it idle), OTI_k = |u_k . (u_i x u_j)| / |u_i x u_j| of the legs' unit lines as
    MuJoCo places them (the graph reading refused it: the platform's frame turns with every actuator locked)."""
    meeting = np.array([0.05, -0.03, 0.6])
    path = tmp_path / "tripod.xml"
    path.write_text(stewart_mjcf(carrier, SCALES[unit], world, base=BASE[::2], top=[meeting] * 3))
    mechanism = load(path, length_unit=unit)
    result = indices_at_pose(mechanism, mechanism.home_pose)
    assert mechanism.task_coordinates == ("x", "y", "z") and result.dof == 3
    starts, ends = mujoco_leg_lines(path.read_text(), SCALES[unit], legs=3)
    order = [int(name.split(":")[-1].split("_")[-1]) for name in mechanism.actuator_names]
    lines = [(ends[k] - starts[k]) / np.linalg.norm(ends[k] - starts[k]) for k in order]
    across = [np.cross(lines[k - 2], lines[k - 1]) for k in range(3)]  # the motion the other two forces allow
    expected = [abs(lines[k] @ across[k]) / np.linalg.norm(across[k]) for k in range(3)]
    np.testing.assert_allclose(np.ravel(result.iti_actuators), np.ones(3), atol=1e-9)
    np.testing.assert_allclose(result.oti_actuators[0], expected, atol=1e-9)
    assert any("output the point where the chains meet on body 'platform'" in line for line in mechanism.import_report)


def test_a_wrist_on_a_central_ball_reads_the_rotations_the_legs_control(tmp_path):
    """Three U-P-S legs onto a platform that turns on a ball on the base (a spherical wrist): the ball is a leg of its
    loop joint alone (read as a joint inside a leg before; the graph reading gives the same numbers). Output the
    platform's rotations (roll, pitch, yaw) about the centre C; OTI_k of the force along leg k through its ball P_k
    and the rotation omega_k about C that the other two forces allow (omega_k . ((P_j - C) x u_j) = 0 for both):
    |u_k . (omega_k x (P_k - C))| / |omega_k x (P_k - C)|, the legs' lines as MuJoCo places them; also in mm and km."""
    centre = np.array([0.03, -0.02, 0.62])
    top = [centre + 0.3 * np.array([np.cos(a), np.sin(a), 0.0]) for a in np.radians([10, 130, 250])]
    for unit, scale in SCALES.items():
        text = stewart_mjcf(-1, scale, base=BASE[::2], top=top).replace(
            "</body></worldbody>", f'<body name="platform" pos="{" ".join(repr(float(v)) for v in scale * centre)}">'
            '<joint name="centre" type="ball"/><inertial pos="0 0 0" mass="0.1" diaginertia="1e-4 1e-4 1e-4"/></body>'
            "</body></worldbody>")
        path = tmp_path / f"wrist_{unit}.xml"
        path.write_text(text)
        mechanism = load(path, length_unit=unit)
        result = indices_at_pose(mechanism, mechanism.home_pose)
        assert mechanism.task_coordinates == ("roll", "pitch", "yaw") and result.dof == 3
        starts, ends = mujoco_leg_lines(text, scale, legs=3)
        order = [int(name.split(":")[-1].split("_")[-1]) for name in mechanism.actuator_names]
        lines = [(ends[k] - starts[k]) / np.linalg.norm(ends[k] - starts[k]) for k in order]
        arms = [ends[k] - centre for k in order]
        moments = [np.cross(arm, line) for arm, line in zip(arms, lines)]
        expected = []
        for k in range(3):
            omega = np.cross(moments[k - 2], moments[k - 1])
            velocity = np.cross(omega, arms[k])
            expected.append(abs(lines[k] @ velocity) / np.linalg.norm(velocity))
        np.testing.assert_allclose(np.ravel(result.iti_actuators), np.ones(3), atol=1e-9)
        np.testing.assert_allclose(result.oti_actuators[0], expected, atol=1e-9)
        assert 0.05 < min(expected) < max(expected) < 0.99
        assert any("chain centre: no joint but its loop, loop spherical (the platform body's own path)" in line
                   for line in mechanism.import_report), mechanism.import_report
        graph = graph_mechanism(read_closed_tree(path, length_unit=unit)).indices()
        np.testing.assert_allclose(graph.lmti, result.lmti, atol=1e-9)
