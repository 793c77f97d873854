"""A two-rod parallel ankle written as an MJCF file (test helper), the way MuJoCo humanoids write theirs.

The foot hangs from the shank (the fixed base) on a passive universal joint at the ankle centre ``O`` (the origin):
pitch about y, then roll about x. Two motors on the shank turn cranks about x at ``MOTORS[k]``; each crank (length
``CRANK``, pointing along -y at zero) carries a rod, on a ``ball`` joint at the crank's end ``C_k`` (``rods="ball"``)
or on two hinges through it (``rods="hinges"``: the rod's idle spin about its own line left out), whose far end is
``<connect>``-ed to the foot at ``FOOT[k]``. The rods' lengths are what the drawing gives them (MuJoCo's connect
holds the anchors together as drawn).
"""

from __future__ import annotations

import numpy as np

MOTORS = np.array([[0.0, 0.045, 0.30], [0.0, -0.045, 0.22], [0.05, 0.0, 0.26]])
CRANK = 0.05
FOOT = np.array([[-0.03, 0.04, -0.02], [-0.03, -0.04, -0.02], [0.04, 0.01, -0.025]])
SOLE = np.array([0.02, -0.01, -0.06])
"""A site on the foot's sole, away from the ankle centre (an output frame whose position follows the foot's turns)."""


def text(vector, scale: float = 1.0) -> str:
    return " ".join(repr(float(v) * scale) for v in vector)


def crank_ends() -> np.ndarray:
    """The cranks' ends ``C_k`` as drawn (every joint at zero)."""
    return MOTORS + np.array([0.0, -CRANK, 0.0])


def rod_ankle_mjcf(rods: str = "ball", scale: float = 1.0, world=None, floating: bool = False, cranks: int = 2,
                   roll_offset=(0.0, 0.0, 0.0), roll_drawn: float = 0.0, toe=None) -> str:
    """The ankle's MJCF text; ``scale`` multiplies every length (a file in other units), ``world`` (``pos``,
    ``quat`` texts) puts the shank in another place of the world; ``floating``: the shank on an unnamed free joint
    (a humanoid's leg, its pelvis floating); ``cranks`` 3: a third crank and rod (one redundant actuator);
    ``roll_offset``: the roll hinge's axis passes there instead of through ``O`` (a humanoid's roll hinge 12 mm below
    its pitch hinge: the two axes do not meet), drawn ``roll_drawn`` along its own axis from that point (the same
    mechanism); ``toe`` (a point and an axis): the foot on a third hinge there, after the roll hinge (three DoF,
    for three cranks)."""
    def rod(k: int) -> str:
        joint = (f'<joint name="rod_{k}" type="ball"/>' if rods == "ball" else
                 f'<joint name="rod_{k}_u1" type="hinge" axis="1 0 0"/><joint name="rod_{k}_u2" type="hinge" '
                 'axis="0 0 1"/>')
        return (f'<body name="crank_{k}" pos="{text(MOTORS[k - 1], scale)}"><joint name="motor_{k}" type="hinge" '
                f'axis="1 0 0"/><geom type="sphere" size="{0.01 * scale!r}"/>'
                f'<body name="rod_{k}" pos="{text([0.0, -CRANK, 0.0], scale)}">{joint}'
                f'<geom type="sphere" size="{0.01 * scale!r}"/></body></body>')

    pos, quat = world if world is not None else ("0 0 0", "1 0 0 0")
    offset = np.asarray(roll_offset, dtype=float)  # the foot's frame there: its anchors and site given in it
    connects = "".join(f'<connect name="closure_{k}" body1="foot" body2="rod_{k}" '
                       f'anchor="{text(FOOT[k - 1] - offset, scale)}"/>' for k in range(1, cranks + 1))
    motors = "".join(f'<motor name="m{k}" joint="motor_{k}"/>' for k in range(1, cranks + 1))
    return (f'<mujoco model="rod_ankle"><compiler angle="radian"/><worldbody><body name="shank" pos="{pos}" '
            f'quat="{quat}">{"<freejoint/>" if floating else ""}<geom type="sphere" size="{0.01 * scale!r}"/>'
            f'{"".join(rod(k) for k in range(1, cranks + 1))}'
            '<body name="cross"><joint name="pitch" type="hinge" axis="0 1 0"/>'
            f'<geom type="sphere" size="{0.01 * scale!r}"/><body name="{"heel" if toe else "foot"}" '
            f'pos="{text(offset, scale)}">'
            f'<joint name="roll" type="hinge" axis="1 0 0" pos="{text([roll_drawn, 0.0, 0.0], scale)}"/>'
            + (f'<geom type="sphere" size="{0.01 * scale!r}"/><body name="foot"><joint name="toe" type="hinge" '
               f'pos="{text(toe[0], scale)}" axis="{text(toe[1])}"/>' if toe else "")
            + f'<geom type="box" size="{text([0.05, 0.03, 0.01], scale)}"/>'
            f'<site name="sole" pos="{text(SOLE - offset, scale)}"/>{"</body>" if toe else ""}</body></body></body>'
            f'</worldbody><equality>{connects}</equality><actuator>{motors}</actuator></mujoco>')
