"""Helpers shared by several test modules (imported as ``from helpers import ...``)."""

from __future__ import annotations

import functools
import itertools
import subprocess
import sys
import xml.etree.ElementTree as ElementTree

import numpy as np


def screwkit(*arguments, timeout=300, **options) -> subprocess.CompletedProcess:
    """Run the ``screwkit`` command as users do, in a subprocess, with Python warnings turned into errors."""
    return subprocess.run([sys.executable, "-W", "error", "-m", "screwkit.cli", *map(str, arguments)],
                          capture_output=True, text=True, timeout=timeout, **options)


def screwkit_json(*arguments, **options) -> dict:
    """What ``screwkit ARGUMENTS --json`` prints, the command checked to succeed."""
    import json  # (the commands' JSON, for these tests)

    read = screwkit(*arguments, "--json", **options)
    assert read.returncode == 0, read.stderr
    return json.loads(read.stdout)


def one_line_error(result: subprocess.CompletedProcess, *needles: str, after: tuple[str, ...] = ()) -> str:
    """The single ``Error: ...`` line of a failed command, checked to contain every needle.

    It is the last line on stderr; before it there is nothing, or only lines starting with one of ``after``
    (what a command says as it works, ``planar_5rrr: mapping ...``, before a failure mid-run). No traceback,
    no warning, nothing on stdout.
    """
    assert result.returncode == 1, (result.returncode, result.stderr)
    lines = result.stderr.strip().splitlines()
    assert lines and lines[-1].startswith("Error: "), result.stderr
    assert all(line.startswith(after) for line in lines[:-1]), result.stderr
    assert "Traceback" not in result.stderr and "Warning" not in result.stderr
    for needle in needles:
        assert needle in lines[-1], (needle, lines[-1])
    assert result.stdout == ""
    return lines[-1]


def rotation_2d(angle):
    angle = np.asarray(angle, dtype=float)
    return np.stack([np.stack([np.cos(angle), -np.sin(angle)], -1), np.stack([np.sin(angle), np.cos(angle)], -1)], -2)


def unit(angle):
    angle = np.asarray(angle, dtype=float)
    return np.stack([np.cos(angle), np.sin(angle)], axis=-1)


def random_planar_rrr(rng: np.random.Generator, count: int, chains: int = 5):
    """Random RRR configurations: points b, c, d of `chains` chains, shape (count, chains, 2).

    Arm lengths vary in [0.3, 1.5] and directions are uniform, so every geometry occurs.
    """
    distal = rng.uniform(-0.5, 0.5, (count, chains, 2))
    f_angle = rng.uniform(0, 2 * np.pi, (count, chains))
    g_angle = rng.uniform(0, 2 * np.pi, (count, chains))
    lower = rng.uniform(0.3, 1.5, (count, chains, 1))
    upper = rng.uniform(0.3, 1.5, (count, chains, 1))
    elbows = distal - lower * unit(f_angle)
    base = elbows - upper * unit(g_angle)
    return base, elbows, distal


def special_planar_rrr(rng: np.random.Generator, count: int, chains: int = 5):
    """Configurations with exactly/nearly parallel distal links, collinear and concurrent lines,
    and type-one singular chains (f parallel to g). Returns (base, elbows, distal, kind)."""
    base, elbows, distal = random_planar_rrr(rng, count, chains)
    f = distal - elbows
    lengths = np.linalg.norm(f, axis=-1, keepdims=True)
    kind = rng.integers(0, 6, count)
    # 0: chains 0 and 1 exactly parallel distal links (equal f), 1: nearly parallel (1e-7 rad),
    # 2: chains 0 and 1 collinear lines, 3: lines of chains 0, 1, 2 concurrent,
    # 4: chain 0 stretched (f parallel to g: type-one singular), 5: three chains with equal f.
    direction = f[:, 0] / lengths[:, 0]
    for index in range(count):
        k = kind[index]
        if k in (0, 1, 5):
            angle = 0.0 if k != 1 else 1e-7
            rotated = rotation_2d(angle) @ direction[index]
            targets = (1, 2) if k == 5 else (1,)
            for target in targets:
                elbows[index, target] = distal[index, target] - lengths[index, target] * rotated
        elif k == 2:
            offset = rng.uniform(0.2, 0.6)
            distal[index, 1] = distal[index, 0] + offset * direction[index]
            elbows[index, 1] = distal[index, 1] - lengths[index, 1] * direction[index]
        elif k == 3:
            centre = rng.uniform(-0.3, 0.3, 2)
            for target in (0, 1, 2):
                u = distal[index, target] - centre
                u = u / np.linalg.norm(u)
                elbows[index, target] = distal[index, target] - lengths[index, target] * u
        elif k == 4:
            upper = np.linalg.norm(elbows[index, 0] - base[index, 0])
            base[index, 0] = elbows[index, 0] - upper * direction[index]
    base = base.copy()
    # Keep the base joints where the arms put them (upper arm from b to c).
    return base, elbows, distal, kind


def moved(chains, rotation, translation):
    """Chain screws moved by one rigid motion (rotation, translation) of the whole mechanism."""
    from screwkit.screw.algebra import transform_twist
    from screwkit.screw.chain_screws import ChainScrews

    return [ChainScrews(transform_twist(rotation, translation, c.twists), c.points @ rotation.T + translation,
                        c.actuated, c.name, joint_names=c.joint_names) for c in chains]


def random_rotation(rng: np.random.Generator) -> np.ndarray:
    """A uniformly random rotation matrix (QR of a Gaussian matrix, sign-fixed)."""
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q @ np.diag(np.sign(np.diag(r)))
    if np.linalg.det(q) < 0:
        q[:, 0] = -q[:, 0]
    return q


def random_reachable_poses(mechanism, rng: np.random.Generator, count: int, spread: float = 1.0) -> np.ndarray:
    """``count`` reachable platform poses (m, rad) scattered about the mechanism's home pose."""
    from screwkit.closure import solve

    home = np.asarray(mechanism.home_pose, dtype=float)
    scale = mechanism.length_scale
    if mechanism.is_planar:
        spans = {"x": 0.3 * scale, "y": 0.3 * scale, "phi": 1.0}
    else:
        spans = {"x": 0.05 * scale, "y": 0.05 * scale, "z": 0.05 * scale, "roll": 0.08, "pitch": 0.08, "yaw": 0.3}
    span = spread * np.array([spans[name] for name in mechanism.task_coordinates])  # any mobility
    found = []
    while sum(len(f) for f in found) < count:
        poses = home + rng.uniform(-1.0, 1.0, (4 * count, home.size)) * span
        found.append(poses[solve(mechanism, poses).reachable])
    return np.concatenate(found)[:count]


def bundled_chain_screws(name: str, count: int = 200, seed: int = 0):
    """Chain screws (world frame) of a bundled mechanism at ``count`` random reachable poses.

    Returns ``(chains, poses)``: a list of :class:`screwkit.screw.chain_screws.ChainScrews` with batch
    shape (count,), and the poses.
    """
    from screwkit.closure import chain_screws, solve
    from screwkit.io.loader import load

    mechanism = load(name)
    poses = random_reachable_poses(mechanism, np.random.default_rng(seed), count)
    return chain_screws(mechanism, solve(mechanism, poses)), poses


def in_millimetres(text: str, *, declare: bool = False) -> str:
    """A URDF's lengths times 1000: origins, prismatic limits, primitive sizes and the x, y, z of named poses
    (written here, independently of screwkit's reader); with ``declare``, also ``<units length="mm"/>``."""
    return in_unit(text, "mm", 1000.0, declare=declare)


def in_unit(text: str, unit: str, factor: float, *, declare: bool = False) -> str:
    """A URDF's lengths times ``factor`` (:func:`in_millimetres` for any unit); with ``declare``, also
    ``<units length="UNIT"/>``."""
    root = ElementTree.fromstring(text)

    def scale(element, attribute):
        if element is not None and element.get(attribute) is not None:
            element.set(attribute, " ".join(repr(factor * float(v)) for v in element.get(attribute).split()))

    for origin in root.iter("origin"):
        scale(origin, "xyz")
    for joint in root.iter("joint"):
        if joint.get("type") == "prismatic":
            scale(joint.find("limit"), "lower")
            scale(joint.find("limit"), "upper")
    for box in root.iter("box"):
        scale(box, "size")
    for tag in ("cylinder", "sphere"):
        for shape in root.iter(tag):
            scale(shape, "radius")
            scale(shape, "length")
    for pose in root.iter("named_pose"):
        for coordinate in ("x", "y", "z"):
            scale(pose, coordinate)
    if declare:
        ElementTree.SubElement(root, "units", length=unit)
    return ElementTree.tostring(root, encoding="unicode")


def moved_in_the_world(text: str, xyz, rpy) -> str:
    """The whole mechanism placed in a new world frame: ``base_link`` hangs from ``world`` by a fixed joint."""
    return text.replace(
        '<link name="base_link">',
        '<link name="world"/>\n  <joint name="world_to_base" type="fixed">'
        '<parent link="world"/><child link="base_link"/>'
        f'<origin xyz="{" ".join(repr(float(v)) for v in xyz)}" rpy="{" ".join(repr(float(v)) for v in rpy)}"/>'
        '</joint>\n'
        '  <link name="base_link">', 1)


def platform_twist(mechanism, pose_minus, pose_plus, step):
    """World-frame twist (omega, v at the world origin) of the platform between two full poses a step
    either side of a configuration: a central difference."""
    rotation_world_base = mechanism.rotation_world_base
    translation_world_base = mechanism.translation_world_base
    frames = []
    for pose in (pose_minus, pose_plus):
        rotation, translation = mechanism.transforms_from_poses(pose)
        frames.append((rotation_world_base @ rotation, rotation_world_base @ translation + translation_world_base))
    (r0, p0), (r1, p1) = frames
    delta = r1 @ r0.T
    omega = np.array([delta[2, 1] - delta[1, 2], delta[0, 2] - delta[2, 0], delta[1, 0] - delta[0, 1]]) / 2 / (2 * step)
    velocity_point = (p1 - p0) / (2 * step)
    middle = (p0 + p1) / 2
    return np.concatenate([omega, velocity_point - np.cross(omega, middle)])


INDEX_FIELDS = ("iti", "iti_actuators", "oti_actuators", "oti_submechanisms", "lmti", "cti", "cti_submechanisms")
"""Per-configuration index arrays of :class:`screwkit.Indices` compared by :func:`assert_indices_close`."""
FAULT_FIELDS = ("f_o", "f_io", "f_c")
EXACT_FIELDS = ("reachable", "mutual_interference", "instantaneous_dof", "constraint_singular")


def assert_indices_close(reference, other, atol: float = 1e-12, *, fields=INDEX_FIELDS, worst_faults: bool = True,
                         full_poses_atol: float | None = None) -> None:
    """Two :class:`screwkit.Indices` hold the same indices: every index array of ``fields`` that ``reference``
    has (``other`` has it too, or both lack it) to ``atol`` (absolute: the indices are in [0, 1]), every F_Oj,
    F_IOj and F_Cj for the same ``j``, NaN where the other is NaN; the reachability, mutual-interference and
    constraint-singularity flags exactly; the worst faults exactly unless ``worst_faults`` is False (ties
    broken by another order); the full poses to ``full_poses_atol`` when given."""
    for name in fields:
        expected, found = getattr(reference, name), getattr(other, name)
        assert (expected is None) == (found is None), f"{name}: {expected is None=} but {found is None=}"
        if expected is not None:
            np.testing.assert_allclose(found, expected, rtol=0, atol=atol, err_msg=name)
    for name in FAULT_FIELDS:
        expected, found = getattr(reference, name), getattr(other, name)
        assert found.keys() == expected.keys(), (name, found.keys(), expected.keys())
        for j in expected:
            np.testing.assert_allclose(found[j], expected[j], rtol=0, atol=atol, err_msg=f"{name}{j}")
    for name in EXACT_FIELDS:
        expected, found = getattr(reference, name), getattr(other, name)
        if expected is not None:
            np.testing.assert_array_equal(found, expected, err_msg=name)
    if worst_faults:
        assert other.worst_fault_indices.keys() == reference.worst_fault_indices.keys()
        for j, expected in reference.worst_fault_indices.items():
            np.testing.assert_array_equal(other.worst_fault_indices[j], expected, err_msg=f"worst faults, j={j}")
    if full_poses_atol is not None:
        np.testing.assert_allclose(other.full_poses, reference.full_poses, rtol=0, atol=full_poses_atol)


@functools.lru_cache(maxsize=None)
def bundled(name: str):
    """A bundled mechanism, loaded once per test process (mechanisms are not changed by the tests)."""
    from screwkit.io.loader import load

    return load(name)


def couple_cti(couples) -> float:
    """The CTI of legs whose only constraint wrench is a couple m_i, from the couples alone: any three independent
    couples are a non-redundant constraint subsystem; releasing leg i's couple with the other two kept frees the
    rotation along m_j x m_k (whatever actuators are locked, as long as their forces are independent), so
    kappa_i = |m_i . (m_j x m_k)| / |m_j x m_k|, and the CTI is the best subsystem's lowest kappa."""
    from itertools import combinations

    couples = np.asarray(couples, dtype=float)
    couples = couples / np.linalg.norm(couples, axis=1, keepdims=True)
    best = 0.0
    for legs in combinations(range(len(couples)), 3):
        kappas = []
        for i in legs:
            j, k = (other for other in legs if other != i)
            freed = np.cross(couples[j], couples[k])
            kappas.append(abs(couples[i] @ freed) / np.linalg.norm(freed))
        best = max(best, min(kappas))
    return best


def leg_line_otis(starts, ends) -> np.ndarray:
    """The OTIs of six legs whose actuation wrenches are forces along their lines, ``starts[k]`` to ``ends[k]``, on a
    platform free in six DoF: OTI_k = |u_k . v_k| / |v_k|, v_k the velocity at ``ends[k]`` of the platform twist
    reciprocal to the other five forces (numpy alone)."""
    starts, ends = np.asarray(starts, dtype=float), np.asarray(ends, dtype=float)
    directions = (ends - starts) / np.linalg.norm(ends - starts, axis=1, keepdims=True)
    lines = np.concatenate([directions, np.cross(ends, directions)], axis=1)
    otis = []
    for k in range(len(lines)):
        others = np.array([np.concatenate([line[3:], line[:3]]) for j, line in enumerate(lines) if j != k])
        twist = np.linalg.svd(others)[2][-1]  # (omega, v): reciprocal to the five other leg forces
        velocity = twist[3:] + np.cross(twist[:3], ends[k])
        otis.append(abs(directions[k] @ velocity) / np.linalg.norm(velocity))
    return np.array(otis)


def translational_pressure_angles(rods, tangents) -> dict:
    """Indices of a translational parallel robot whose legs transmit forces along unit ``rods`` (n, 3) and whose
    actuators move the rods' upper ends along unit ``tangents`` (n, 3): ITI_i = |u_i . t_i|, OTI of every 3-subset
    (the least over its legs of |u_k . v_k| / |v_k|, v_k = u_i x u_j the translation the other two forces allow), LMTI
    the largest OTI and F_O1 the least, over the failed leg, of the largest OTI without it (numpy alone)."""
    rods, tangents = np.asarray(rods, dtype=float), np.asarray(tangents, dtype=float)
    oti = {}
    for members in itertools.combinations(range(len(rods)), 3):
        values = []
        for k in members:
            j, m = [i for i in members if i != k]
            v = np.cross(rods[j], rods[m])
            values.append(abs(rods[k] @ v) / np.linalg.norm(v))
        oti[members] = min(values)
    legs = range(len(rods))
    f_o1 = min(max(v for members, v in oti.items() if failed not in members) for failed in legs) \
        if len(rods) > 3 else 0.0
    return {"iti": np.abs(np.sum(rods * tangents, axis=1)), "oti": oti, "lmti": max(oti.values()), "f_o1": f_o1}


def assert_same_indices(got, expected, atol: float = 1e-12) -> None:
    """Two :class:`~screwkit.indices.results.Indices` of the same poses (``detail=True``) equal to ``atol``: every
    index array, each F_Oj, and the instantaneous DOF exactly (a compiled path against numpy's, say)."""
    import numpy as np

    for key in ("iti", "lmti", "iti_actuators", "oti_submechanisms", "cti", "cti_submechanisms"):
        if getattr(expected, key) is not None:
            np.testing.assert_allclose(getattr(got, key), getattr(expected, key), rtol=0, atol=atol, equal_nan=True,
                                       err_msg=key)
    for j in expected.f_o:
        np.testing.assert_allclose(got.f_o[j], expected.f_o[j], rtol=0, atol=atol)
    assert np.array_equal(got.instantaneous_dof, expected.instantaneous_dof)


MJCF_WORLDS = {"m": (1.0, None, ("0 0 0", "1 0 0 0")), "mm": (1000.0, "mm", ("0 0 0", "1 0 0 0")),
               "turned": (1.0, None, ("0.3 -0.2 0.5", "0.8 0.3 -0.4 0.2"))}
"""An MJCF file written three ways for invariance tests: ``(scale, --length-unit, (base pos, base quat))``: in
metres, every length times 1000 read in millimetres, and its base moved and turned in the world."""


def mjcf_variant(tmp_path, name: str, variant: str, write) -> tuple:
    """The file ``write(scale, world)`` gives, written as ``variant`` of :data:`MJCF_WORLDS`: (path, length unit)."""
    scale, unit, world = MJCF_WORLDS[variant]
    path = tmp_path / f"{name}_{variant}.xml"
    path.write_text(write(scale, world))
    return path, unit


def sine(u, v) -> float:
    """|sin| of the angle between two vectors: a textbook pressure angle's transmission."""
    return float(np.linalg.norm(np.cross(u, v)) / (np.linalg.norm(u) * np.linalg.norm(v)))


def mujoco_closed(path) -> tuple:
    """MuJoCo's own reading of an MJCF file at its configuration, checked closed as written (its constraints'
    residuals zero): (model, data, each joint's anchor in the world by name)."""
    import mujoco  # (MuJoCo's reading, for the tests of MJCF files)

    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    assert np.abs(data.efc_pos).max() < 1e-12 * (1.0 + np.abs(data.xpos).max())
    return model, data, {model.joint(k).name: data.xanchor[k] for k in range(model.njnt)}


def mujoco_rows(model, data) -> np.ndarray:
    """MuJoCo's constraint Jacobian (nefc, nv), dense: its ``efc_J`` buffer may hold more rows than the constraints
    found (rows MuJoCo leaves out, a connect between two bodies turning on one pin, are not written, and what is left
    there is whatever the memory held)."""
    return data.efc_J[:data.nefc * model.nv].reshape(data.nefc, model.nv)
