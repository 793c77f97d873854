"""Which motions of a leg with its ends held are idle spins (locked) and which move its links (refused).

A leg's joints are dependent at every configuration both when it has an idle spin (two coaxial pins, an S-S rod
about its own line, two slides along one line) and when its links can move with its ends held (four hinges in one
plane: a finger bent at a spring joint). Only the first may be locked; the second is a motion of the mechanism no
actuator drives. The verdict is the geometry's: the same wherever the leg is in the world, in any unit, wherever a
hinge is drawn on its axis. (A first version took the joints' twists about the world's origin, and read the spin of
Reachy Mini's rods as a motion once the robot was put 5 m away.)
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from screwkit.io.idle_joints import _moving_self_motion
from screwkit.io.loader import load
from screwkit.studies import indices_at_pose


def _ball(centre, turn=None, drawn=(0.0, 0.0, 0.0)):
    """A ball joint written as three hinges at ``centre`` (each drawn ``drawn[i]`` along its own axis)."""
    turn = np.eye(3) if turn is None else turn
    return [("revolute", turn[:, i], np.asarray(centre, float) + drawn[i] * turn[:, i]) for i in range(3)]


def _turn(seed: int) -> np.ndarray:
    q, _ = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    return q


A, B = np.zeros(3), np.array([0.3, 0.1, 0.5])
LEGS = {  # (triples, idle?)
    "S-S rod": (_ball(A) + _ball(B), True),
    "S-S rod, hinges drawn apart on their axes": (_ball(A, drawn=(0.2, -0.4, 0.1)) + _ball(B, _turn(1), (0.3, 0, -0.2)),
                                                 True),
    "S-P-S, the slide along the rod": (_ball(A) + [("prismatic", B / np.linalg.norm(B), A)] + _ball(B), True),
    "S-P-S, the slide 5 deg off the rod": (_ball(A) + [("prismatic", np.array([np.sin(0.087), 0.0, np.cos(0.087)]),
                                                         A)] + _ball(np.array([0.0, 0.0, 0.5])), True),
    "two coaxial pins": ([("revolute", np.array([0.0, 0.0, 1.0]), A), ("revolute", np.array([0.0, 0.0, 1.0]),
                                                                           np.array([0.0, 0.0, 0.3])),
                          ("revolute", np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.2, 0.3]))], True),
    "two slides along one line": ([("prismatic", np.array([1.0, 0.0, 0.0]), A),
                                   ("prismatic", np.array([1.0, 0.0, 0.0]), B),
                                   ("revolute", np.array([0.0, 0.0, 1.0]), B)], True),
    "four hinges in a plane": ([("revolute", np.array([0.0, 0.0, 1.0]), np.array(p, float))
                                for p in ((0, 0, 0), (0.1, 0.2, 0), (0.4, 0.25, 0), (0.5, 0, 0))], False),
    "a spatial 7R": ([("revolute", _turn(10 + k)[:, 0], np.random.default_rng(k).normal(size=3) * 0.3)
                      for k in range(7)], False),
}


@pytest.mark.parametrize("leg", LEGS)
@pytest.mark.parametrize("scale, shift", [(1.0, 0.0), (1e-3, 0.0), (1e3, 0.0), (1.0, 300.0), (1e-3, 1e3)])
def test_an_idle_spin_is_told_from_a_motion_of_links_anywhere_and_in_any_unit(leg, scale, shift):
    triples, idle = LEGS[leg]
    turn = _turn(7)
    placed = [(kind, turn @ axis, turn @ (point * scale) + shift * scale * np.array([1.0, -2.0, 0.5]))
              for kind, axis, point in triples]
    moving = _moving_self_motion(placed, 0.5 * scale)
    assert (not moving) is idle, (leg, moving)


def test_reachy_mini_s_rods_spin_idly_wherever_the_robot_stands(tmp_path):
    """The published URDF hung 5 m away on a fixed joint reads the indices it reads where it is drawn."""
    source = Path(__file__).parent / "data" / "gallery" / "published" / "reachy_mini"
    text = (source / "robot.urdf").read_text()
    root = '<link name="body_foot_3dprint">'
    assert root in text
    for item in source.iterdir():
        if item.name != "robot.urdf":
            (tmp_path / item.name).symlink_to(item)
    (tmp_path / "robot.urdf").write_text(text.replace(root, '<link name="anchor"/><joint name="anchor_fix" '
                                                            'type="fixed"><parent link="anchor"/><child '
                                                            'link="body_foot_3dprint"/><origin xyz="5 5 5"/></joint>'
                                                      + root, 1))
    here, there = (load(path, lock=("yaw_body",)) for path in (source / "robot.urdf", tmp_path / "robot.urdf"))
    a, b = (indices_at_pose(m, m.home_pose) for m in (here, there))
    np.testing.assert_allclose(np.asarray(b.iti_actuators), np.asarray(a.iti_actuators), atol=1e-9)
    assert float(b.lmti) == pytest.approx(float(a.lmti), abs=1e-9)
