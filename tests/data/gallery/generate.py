"""Write the gallery's files: faithful rewrites of published closed-loop robot descriptions.

Each file reproduces the way a kind of published file is written (the exporter's conventions, its quirks),
with geometry of our own, so that it can be shipped with the tests (the published ones carry no licence that
allows it, or carry meshes). ``python tests/data/gallery/generate.py`` writes them next to this script;
``tests/test_gallery.py`` checks that the committed files are what it writes.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

FOLDER = Path(__file__).resolve().parent


def _text(values) -> str:
    return " ".join(f"{float(v):.12g}" for v in values)


INERTIAL = '<inertial pos="0 0 0" mass="0.05" diaginertia="1e-4 1e-4 1e-4"/>'


def _unit(vector):
    vector = np.asarray(vector, dtype=float)
    return vector / np.linalg.norm(vector)


def stewart_points(base_radius=0.2, platform_radius=0.12, spread_deg=20.0, height=0.3):
    """Base and platform joint points of a Gough-Stewart platform, joints in pairs (the bundled ups_stewart_6
    layout): base pairs around 30, 150, 270 deg, platform pairs around 90, 210, 330 deg."""
    k = np.arange(6)
    base_angles = np.deg2rad(60.0 * k + np.where(k % 2 == 0, 0.5, -0.5) * spread_deg)
    top_angles = np.deg2rad(60.0 * k - np.where(k % 2 == 0, 0.5, -0.5) * spread_deg)
    base = np.column_stack([base_radius * np.cos(base_angles), base_radius * np.sin(base_angles), np.zeros(6)])
    top = np.column_stack([platform_radius * np.cos(top_angles), platform_radius * np.sin(top_angles),
                           np.full(6, height)])
    return base, top


def stewart_cad() -> str:
    """A Stewart platform as a CAD exporter (and a hand edit) writes it in MJCF, after raincut/stewart_mujoco:
    U-P-R-U legs of six bodies each, every body at identity orientation; the platform body TOP is the child of
    leg 1's last body with no joint of its own (its frame at leg 1's top joint, not at the platform centre);
    legs 2-6 welded to it by body (``<weld body1="UJk" body2="TOP" relpose=...>``); position actuators on the
    sliders; a ground plane and a light beside the robot; joint defaults through a class."""
    base, top = stewart_points()
    lines = ['<mujoco model="stewart_cad">',
             '  <compiler angle="radian" autolimits="true" inertiafromgeom="false"/>',
             '  <default><joint limited="true" damping="0.01" armature="0.01"/>'
             '<default class="spin"><joint range="0 6.283185"/></default></default>',
             "  <worldbody>",
             '    <light directional="true" pos="0 0 5" dir="0 0 -1"/>',
             '    <geom name="floor" type="plane" size="1 1 0.1"/>',
             f'    <body name="base" pos="0 0 0">{INERTIAL}',
             '      <geom type="cylinder" size="0.22 0.01"/>']
    welds = []
    for k in range(6):
        leg = top[k] - base[k]
        axis = _unit(leg)
        first = _unit(np.cross([0.0, 0.0, 1.0], axis))
        second = np.cross(axis, first)
        indent = "      "
        lines.append(f'{indent}<body name="X{k + 1}bottom" pos="{_text(base[k])}">{INERTIAL}')
        lines.append(f'{indent}  <joint name="r_xb{k + 1}" type="hinge" axis="{_text(first)}" range="-0.8 0.8"/>')
        lines.append(f'{indent}  <geom type="sphere" size="0.01"/>')
        lines.append(f'{indent}  <body name="cylinder{k + 1}" pos="0 0 0">{INERTIAL}')
        lines.append(f'{indent}    <joint name="r_xb_rod{k + 1}" type="hinge" axis="{_text(second)}" '
                     'range="-0.8 0.8"/>')
        lines.append(f'{indent}    <geom type="capsule" fromto="0 0 0 {_text(0.5 * leg)}" size="0.008"/>')
        lines.append(f'{indent}    <body name="rod{k + 1}" pos="0 0 0">{INERTIAL}')
        lines.append(f'{indent}      <joint name="s{k + 1}" type="slide" axis="{_text(axis)}" range="-0.1 0.1"/>')
        lines.append(f'{indent}      <body name="piston{k + 1}" pos="0 0 0">{INERTIAL}')
        lines.append(f'{indent}        <joint name="r_rod{k + 1}" type="hinge" axis="{_text(axis)}" class="spin"/>')
        lines.append(f'{indent}        <geom type="capsule" fromto="{_text(0.5 * leg)} {_text(leg)}" size="0.006"/>')
        lines.append(f'{indent}        <body name="X{k + 1}top" pos="{_text(leg)}">{INERTIAL}')
        lines.append(f'{indent}          <joint name="r_rod_xt{k + 1}" type="hinge" axis="{_text(first)}" '
                     'range="-0.8 0.8"/>')
        lines.append(f'{indent}          <body name="UJ{k + 1}" pos="0 0 0">{INERTIAL}')
        lines.append(f'{indent}            <joint name="r_xt{k + 1}" type="hinge" axis="{_text(second)}" '
                     'range="-0.8 0.8"/>')
        lines.append(f'{indent}            <geom type="sphere" size="0.01"/>')
        if k == 0:  # the platform: a child of leg 1's last body, no joint, its frame at that body's origin
            lines.append(f'{indent}            <body name="TOP" pos="0 0 0">{INERTIAL}')
            lines.append(f'{indent}              <geom type="cylinder" pos="{_text(-top[0] + [0, 0, top[0][2]])}" '
                         'size="0.13 0.01"/>')
            lines.append(f'{indent}              <site name="tool" pos="{_text([0, 0, top[0][2]] - top[0])}"/>')
            lines.append(f'{indent}            </body>')
        else:
            welds.append(f'    <weld name="rigid{k + 1}" body1="UJ{k + 1}" body2="TOP" '
                         f'relpose="{_text(top[0] - top[k])} 1 0 0 0"/>')
        lines += [f"{indent}          </body>", f"{indent}        </body>", f"{indent}      </body>",
                  f"{indent}    </body>", f"{indent}  </body>", f"{indent}</body>"]
    lines += ["    </body>", "  </worldbody>", "  <equality>", *welds, "  </equality>", "  <actuator>"]
    lines += [f'    <position name="act{k + 1}" joint="s{k + 1}" kp="10000"/>' for k in range(6)]
    lines += ["  </actuator>", "</mujoco>", ""]
    return "\n".join(lines)


FILES = {"stewart_cad.xml": stewart_cad}


def main(arguments: list[str]) -> None:
    folder = Path(arguments[0]) if arguments else FOLDER
    for name, writer in FILES.items():
        (folder / name).write_text(writer())
        print(f"wrote {folder / name}")


if __name__ == "__main__":
    main(sys.argv[1:])
