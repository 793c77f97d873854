"""A leg with a loop inside it and several actuators, analysed one actuator at a time.

The mechanism: a planar platform (hinges along y, the plane y = 0) held by a five-bar leg, whose two motors m1 and
m2 on the base drive distal links that meet at the platform's pin P, and by two R-R-R legs closed onto the platform
at Q and R (motors m3, m4): four actuators for three motions. The five-bar's loop closes at P (the second distal
link onto the first), so the leg has a loop inside it and two actuators. Each actuator's wrench is then reciprocal
to the platform twists the leg allows with that actuator alone locked (the paper's definition for a chain of several
actuated joints): the five-bar reads as its two sides would as legs of their own, each closed onto the platform at
P. The checks:

* against the same mechanism written as those two legs (the second distal link closed onto the platform, not onto
  the first), which screwkit reads leg by leg: every index, actuation wrench and worst fault the same to 1e-12;
* against the textbook pressure angles from MuJoCo's own placement of the pins: ITI = |sin(OE, EP)| of each side;
* in metres, in millimetres and in a moved, turned world; every length times 1e-3 and 1e3; with the file's
  bodies, closures and motors listed in reverse order, with motors renamed each as another (the indices and worst
  faults follow the joints), and with the platform hung on another leg (a different tree of the same mechanism);
* with the first elbow driven too (three actuators in the leg, redundant inside it): against the two legs, the first
  a serial chain of two actuators;
* refused, naming the actuator, where a motion inside the leg moves it with the platform held (a six-bar side);
* through ``screwkit analyze --json``, ``analyze --actuators`` and ``trajectory`` as subprocesses;
* spatial: a 6-3 Stewart platform of R-S-S legs whose rods meet two by two at the platform's balls, each pair
  written as one leg of two motors: every ITI and OTI from the rods' lines.
"""

from __future__ import annotations

import json
import pickle
from types import SimpleNamespace

import numpy as np
import pytest

from helpers import MJCF_WORLDS, leg_line_otis, mjcf_variant, mujoco_closed, screwkit, sine
from screwkit.io import ImportError_, read_closed_tree
from screwkit.io.graph import graph_mechanism
from screwkit.io.graph_checks import stage_refusal
from screwkit.io.loader import load
from screwkit.studies import indices_at_pose

POINTS = {"O1": (-0.20, 0.0), "E1": (-0.25, -0.18), "F1": (-0.17, -0.30), "P": (-0.05, -0.35),
          "O2": (0.05, 0.0), "E2": (0.15, -0.17),
          "O3": (0.35, -0.05), "E3": (0.30, -0.25), "Q": (0.08, -0.36),
          "O4": (-0.30, -0.60), "E4": (-0.10, -0.62), "R": (0.02, -0.45)}
"""The motors O, elbows E, the platform's pins P, Q, R (x, z; the plane y = 0); F1 an extra elbow of a six-bar side."""


def point(name: str) -> np.ndarray:
    x, z = POINTS[name]
    return np.array([x, 0.0, z])


def five_bar_leg(scale: float = 1.0, world=("0 0 0", "1 0 0 0"), *, closed_on: str = "dist1", spine: str = "dist1",
                 reverse: bool = False, driven_elbow: bool = False, six_bar: bool = False) -> str:
    """The MJCF file. ``closed_on``: the body the second distal link is closed onto at P (``dist1``: the five-bar
    leg; ``platform``: its two sides as two legs); ``spine``: the body the platform hangs on (``dist1`` or
    ``dist3``); ``reverse``: bodies, closures and motors listed the other way round; ``driven_elbow``: a motor on the
    first elbow too; ``six_bar``: the first side with one more hinge (at F1)."""
    def at(v) -> str:
        return " ".join(repr(float(c) * scale) for c in v)

    ball = f'<geom type="sphere" size="{0.005 * scale!r}"/>'
    hinge = '<joint name="{}" type="hinge" axis="0 1 0"/>' + ball
    last = {"dist1": "F1" if six_bar else "E1", "dist3": "E3"}[spine]
    origin = {"dist1": point("P"), "dist3": point("Q")}[spine]
    platform = (f'<body name="platform" pos="{at(origin - point(last))}">{hinge.format("pin")}'
                + "".join(f'<site name="{p}_pin" pos="{at(point(p) - origin)}"/>' for p in "PQR") + "</body>")

    def leg(k: int) -> str:
        joints = [f"O{k}", f"E{k}"] + (["F1"] if six_bar and k == 1 else [])
        text, before = "", np.zeros(3)
        for depth, joint in enumerate(joints):
            body = f"dist{k}" if depth == len(joints) - 1 else ("prox", "mid")[depth] + str(k)
            text += (f'<body name="{body}" pos="{at(point(joint) - before)}">'
                     + hinge.format(f"m{k}" if depth == 0 else f"{'ef'[depth - 1]}{k}"))
            before = point(joint)
        return text + (platform if spine == f"dist{k}" else "") + "</body>" * len(joints)

    def anchor(body: str, joint: str, pin: str) -> str:
        return f'anchor="{at(point(pin) - point(joint))}" body1="{body}"'

    legs = [leg(k) for k in (1, 2, 3, 4)]
    closures = [f'<connect name="c_P" {anchor("dist2", "E2", "P")} body2="{closed_on}"/>']
    if spine != "dist1":
        closures.append(f'<connect name="c_P1" {anchor("dist1", "F1" if six_bar else "E1", "P")} body2="platform"/>')
    if spine != "dist3":
        closures.append(f'<connect name="c_Q" {anchor("dist3", "E3", "Q")} body2="platform"/>')
    closures.append(f'<connect name="c_R" {anchor("dist4", "E4", "R")} body2="platform"/>')
    motors = [f'<motor joint="m{k}"/>' for k in (1, 2, 3, 4)] + (['<motor joint="e1"/>'] if driven_elbow else [])
    if reverse:
        legs, closures, motors = legs[::-1], closures[::-1], motors[::-1]
    return ('<mujoco model="five_bar_leg"><option><flag contact="disable"/></option><worldbody>'
            f'<body name="base" pos="{world[0]}" quat="{world[1]}">' + "".join(legs) + "</body></worldbody>"
            "<equality>" + "".join(closures) + "</equality><actuator>" + "".join(motors) + "</actuator></mujoco>")


def read(path, unit=None):
    """The graph reading of a file, its platform the output, and its indices at the file's configuration."""
    graph = graph_mechanism(read_closed_tree(path, output="platform", length_unit=unit))
    return graph, graph.indices()


def by_joint(graph, values) -> dict[str, float]:
    """Per-actuator values keyed by the actuated joint (chain names differ between two readings)."""
    return {name.split(":")[1]: float(v) for name, v in zip(graph.actuators, np.ravel(values))}


def assert_same(first, second, tolerance: float = 1e-12, cti: bool = True, wrenches: bool = True) -> None:
    """Two readings (mechanism, indices) of one mechanism, their actuators matched by joint: every index, actuation
    wrench (up to its sign) and worst fault the same (the CTI and F_Cj unless ``cti`` is False: the serial reading
    takes a planar mechanism's pins for hinges, where the graph keeps MJCF's balls and their couples; the wrenches
    unless ``wrenches`` is False: a moment scales with the mechanism's size)."""
    (graph_a, a), (graph_b, b) = first, second
    joints_a, joints_b = ([name.split(":")[1] for name in g.actuator_names] for g in (graph_a, graph_b))
    assert sorted(joints_a) == sorted(joints_b)
    order = [joints_b.index(joint) for joint in joints_a]  # b's actuators in a's order
    np.testing.assert_allclose(a.iti_actuators, b.iti_actuators[order], atol=tolerance)
    for index, members in enumerate(a.submechanisms):  # (each actuator's OTI in each submechanism)
        theirs = tuple(sorted(order[k] for k in members))
        row = b.submechanisms.index(theirs)
        np.testing.assert_allclose(a.oti_actuators[index], b.oti_actuators[row][[theirs.index(order[k])
                                                                                 for k in members]], atol=tolerance)
        assert float(a.oti_submechanisms[index]) == pytest.approx(float(b.oti_submechanisms[row]), abs=tolerance)
    for name in ("iti", "lmti") + (("cti",) if cti else ()):
        np.testing.assert_allclose(float(getattr(a, name)), float(getattr(b, name)), atol=tolerance, err_msg=name)
    for name in ("f_o", "f_io") + (("f_c",) if cti else ()):
        assert getattr(a, name).keys() == getattr(b, name).keys()
        for j in getattr(a, name):
            np.testing.assert_allclose(float(getattr(a, name)[j]), float(getattr(b, name)[j]), atol=tolerance,
                                       err_msg=f"{name}{j}")
    for j in a.remaining_lmti:  # (each set of j failed, by the joints failed)
        theirs = [b.failed_sets(j).index(tuple(sorted(order[k] for k in failed))) for failed in a.failed_sets(j)]
        np.testing.assert_allclose(a.remaining_lmti[j], b.remaining_lmti[j][theirs], atol=tolerance)
        worst_a = sorted(joints_a[k] for k in np.ravel(a.worst_fault_indices[j]))
        assert worst_a == sorted(joints_b[k] for k in np.ravel(b.worst_fault_indices[j]))
    if wrenches:
        signs = np.sign(np.sum(a.actuation_wrenches * b.actuation_wrenches[order], axis=1))[:, None]
        np.testing.assert_allclose(a.actuation_wrenches, b.actuation_wrenches[order] * signs, atol=tolerance)


@pytest.mark.parametrize("variant", sorted(MJCF_WORLDS))
def test_a_five_bar_leg_reads_as_its_two_sides_and_the_textbook_pressure_angles(tmp_path, variant):
    leg, unit = mjcf_variant(tmp_path, "leg", variant, five_bar_leg)
    sides, _ = mjcf_variant(tmp_path, "sides", variant, lambda *a: five_bar_leg(*a, closed_on="platform"))
    graph, indices = reading = read(leg, unit)
    assert any("one leg with loops inside it and 2 actuators" in note for note in graph.report.notes)
    assert len({leg_.name for leg_ in graph.legs}) == 4 and graph.dof == 3
    assert_same(reading, read(sides, unit))
    _, _, anchor = mujoco_closed(leg)
    pin = anchor["pin"]
    itis = by_joint(graph, indices.iti_actuators)
    for k in (1, 2):
        assert itis[f"m{k}"] == pytest.approx(sine(anchor[f"e{k}"] - anchor[f"m{k}"], pin - anchor[f"e{k}"]), abs=1e-9)
    assert abs(itis["m1"] - itis["m2"]) > 1e-3  # (the sides told apart)
    assert 0 < float(indices.f_o[1]) < float(indices.lmti)


def test_the_same_whatever_the_tree_and_the_order_of_the_file(tmp_path):
    readings = []
    for name, options in (("as_drawn", {}), ("reversed", {"reverse": True}), ("on_leg_3", {"spine": "dist3"}),
                          ("on_leg_3_reversed", {"spine": "dist3", "reverse": True})):
        path = tmp_path / f"{name}.xml"
        path.write_text(five_bar_leg(**options))
        readings.append(read(path))
        assert readings[-1][0].actuators == readings[0][0].actuators  # (named after the bodies the motors turn)
    for reading in readings[1:]:
        assert_same(readings[0], reading)


@pytest.mark.parametrize("variant", sorted(MJCF_WORLDS))
def test_a_leg_redundant_inside_reads_as_a_serial_leg_of_two_actuators_beside_the_other_side(tmp_path, variant):
    """The first elbow driven as well: three actuators in the leg for its two motions of P. Each wrench is still the
    one reciprocal to the leg with that actuator alone locked; the same as the first side read as a serial chain
    with two actuated joints (m1, e1) closed onto the platform."""
    leg, unit = mjcf_variant(tmp_path, "leg", variant, lambda *a: five_bar_leg(*a, driven_elbow=True))
    sides, _ = mjcf_variant(tmp_path, "sides", variant,
                            lambda *a: five_bar_leg(*a, driven_elbow=True, closed_on="platform"))
    graph, indices = reading = read(leg, unit)
    assert len(graph.actuators) == 5
    assert_same(reading, read(sides, unit))
    serial = load(sides, output="platform", length_unit=unit)  # (the serial reading: chain m1 of two actuators)
    assert sorted(serial.actuator_names) == ["m1:e1", "m1:m1", "m2:m2", "m3:m3", "m4:m4"]
    assert_same(reading, (serial, indices_at_pose(serial, serial.home_pose)), cti=False)
    _, _, anchor = mujoco_closed(leg)
    itis = by_joint(graph, indices.iti_actuators)  # e1's wrench: along O1P (m1 free), on P (the joint after e1)
    assert itis["e1"] == pytest.approx(sine(anchor["pin"] - anchor["m1"], anchor["pin"] - anchor["e1"]), abs=1e-9)


def test_an_actuator_that_moves_with_the_platform_held_is_refused_naming_it(tmp_path):
    path = tmp_path / "six_bar.xml"
    path.write_text(five_bar_leg(six_bar=True))
    with pytest.raises(ImportError_, match=r"locking actuated joint 'm1' leaves the platform as free as before: a "
                                           r"motion inside its leg moves it with the platform held \(kinematic "
                                           r"redundancy; the leg's other actuated joints: m2\), so it has no actuation "
                                           r"wrench; --lock m1 holds it\.$"):
        read(path)
    held = graph_mechanism(read_closed_tree(path, output="platform", lock=("m1",)))  # as the message says
    itis = by_joint(held, held.indices().iti_actuators)
    _, _, anchor = mujoco_closed(path)
    assert sorted(itis) == ["m2", "m3", "m4"]
    assert itis["m2"] == pytest.approx(sine(anchor["e2"] - anchor["m2"], anchor["pin"] - anchor["e2"]), abs=1e-9)


def test_the_command_reads_the_leg_as_its_two_sides(tmp_path):
    leg, sides = tmp_path / "leg.xml", tmp_path / "sides.xml"
    leg.write_text(five_bar_leg(scale=1000.0))
    sides.write_text(five_bar_leg(closed_on="platform"))
    printed = []
    for path, unit in ((leg, ["--length-unit", "mm"]), (sides, [])):
        run = screwkit("analyze", path, "--output", "platform", *unit, "--json")
        assert run.returncode == 0, run.stderr
        printed.append(json.loads(run.stdout))
    itis = [{name.split(":")[1]: value for name, value in text["iti_actuators"].items()} for text in printed]
    assert itis[0] == pytest.approx(itis[1], abs=1e-12) and len(itis[0]) == 4
    assert printed[0]["lmti"] == pytest.approx(printed[1]["lmti"], abs=1e-12)
    assert printed[0]["f_o"] == pytest.approx(printed[1]["f_o"], abs=1e-12)


def test_poses_in_a_batch_read_as_the_two_sides_do(tmp_path):
    """The batched path (sweeps, maps, paths): at poses about the file's, every index as the two sides give it."""
    from screwkit.studies.poses import graph_indices_at_poses

    leg, sides = tmp_path / "leg.xml", tmp_path / "sides.xml"
    leg.write_text(five_bar_leg())
    sides.write_text(five_bar_leg(closed_on="platform"))
    rng = np.random.default_rng(7)
    poses = np.column_stack([rng.uniform(-0.07, -0.03, 12), rng.uniform(-0.37, -0.33, 12),
                             np.radians(rng.uniform(-10.0, 10.0, 12))])
    ours, theirs = (graph_indices_at_poses(graph_mechanism(read_closed_tree(path, output="platform")), poses,
                                           detail=True) for path in (leg, sides))
    assert ours.actuators == theirs.actuators and np.all(np.isfinite(ours.lmti))
    for name in ("iti_actuators", "iti", "lmti", "cti"):
        np.testing.assert_allclose(getattr(ours, name), getattr(theirs, name), atol=1e-12, err_msg=name)
    for j in ours.f_o:
        np.testing.assert_allclose(ours.f_o[j], theirs.f_o[j], atol=1e-12)
        np.testing.assert_allclose(ours.remaining_lmti[j], theirs.remaining_lmti[j], atol=1e-12)


def test_the_viewer_marks_the_side_of_the_failed_motor(tmp_path):
    """Each side of the five-bar leg drawn as its motor's: with m1 failed, side 1 is drawn failed and side 2 is not."""
    from screwkit.viewer.graph_drawing import graph_markers, solve_graph_frames

    path = tmp_path / "leg.xml"
    path.write_text(five_bar_leg())
    graph = graph_mechanism(read_closed_tree(path, output="platform"))
    frames = solve_graph_frames(graph, graph.home_pose[None], threshold=1e-6, strict=True)
    failed = graph.actuators.index("prox1:m1")
    markers = graph_markers(graph, frames, failed=(failed,))[0]
    drawn = {marker.path.split("/")[-1]: marker.failed for marker in markers if marker.kind == "joint"}
    assert drawn["e1"] and not drawn["e2"] and not drawn["m3"], drawn


def test_the_command_moves_the_leg_by_its_actuators(tmp_path):
    """``analyze --actuators`` (degrees, in the actuators' order) at the values a pose puts the four motors at: the
    indices of that pose, the five-bar leg's two motors driven with the others."""
    from screwkit.io.closed_tree import joint_value

    path = tmp_path / "leg.xml"
    path.write_text(five_bar_leg())
    graph = graph_mechanism(read_closed_tree(path, output="platform"))
    moved = graph.at_pose([-0.04, 0.0, -0.34], [0.0, np.radians(4.0), 0.0])
    values = [np.degrees(joint_value(graph.tree.model, leg.actuators[0], moved.q)) for leg in moved.legs]
    run = screwkit("analyze", path, "--output", "platform", "--actuators", " ".join(f"{v:.15g}" for v in values),
                   "--json")
    assert run.returncode == 0, run.stderr
    assert json.loads(run.stdout)["lmti"] == pytest.approx(float(moved.indices().lmti), abs=1e-9)
    assert moved.indices().lmti != pytest.approx(float(graph.indices().lmti), abs=1e-3)  # (a pose of its own)


def test_a_path_through_the_command_reads_as_the_two_sides_do(tmp_path):
    """``screwkit trajectory`` on the five-bar leg, its poses quoted with negative numbers: at every sample the
    indices of the two sides written as legs, computed in this process."""
    import csv

    from screwkit.studies.poses import graph_indices_at_poses

    leg, sides = tmp_path / "leg.xml", tmp_path / "sides.xml"
    leg.write_text(five_bar_leg())
    sides.write_text(five_bar_leg(closed_on="platform"))
    run = screwkit("trajectory", leg, "--output", "platform", "--line", "-0.06 -0.35 -3", "-0.04 -0.34 5",
                   "--samples", "9", "--out", tmp_path / "path.csv")
    assert run.returncode == 0, run.stderr
    rows = list(csv.DictReader((tmp_path / "path.csv").open()))
    assert len(rows) >= 9 and all(row["reachable"] == "True" for row in rows)
    poses = np.array([[float(row["x"]), float(row["z"]), np.radians(float(row["pitch"]))] for row in rows])
    theirs = graph_indices_at_poses(graph_mechanism(read_closed_tree(sides, output="platform")), poses, detail=True)
    np.testing.assert_allclose([float(row["lmti"]) for row in rows], theirs.lmti, atol=1e-12)
    np.testing.assert_allclose([float(row["f_o1"]) for row in rows], theirs.f_o[1], atol=1e-12)
    for k, name in enumerate(theirs.actuators):
        np.testing.assert_allclose([float(row[f"iti_actuator[{name}]"]) for row in rows],
                                   theirs.iti_actuators[:, k], atol=1e-12)


def paired_stewart(scale: float = 1.0, world=("0 0 0", "1 0 0 0"), *, pairs: bool = True, reverse: bool = False
                   ) -> str:
    """A 6-3 Stewart platform of R-S-S legs: six cranks on the base, their rods meeting two by two at three ball
    centres P0, P1, P2 of the platform, which hangs on rod 0a by its ball at P0. ``pairs``: each second rod closed
    onto the first at their common P (three legs with a loop inside and two actuators each); else onto the
    platform (six legs of one actuator)."""
    def at(v) -> str:
        return " ".join(repr(float(c) * scale) for c in v)

    points, cranks = paired_stewart_geometry()
    ball = f'<geom type="sphere" size="{0.004 * scale!r}"/>'
    platform = (f'<body name="platform" pos="{at(points[0] - cranks["0a"][1])}"><joint name="s_p" type="ball"/>'
                + ball + "".join(f'<site name="P{k}" pos="{at(points[k] - points[0])}"/>' for k in range(3))
                + "</body>")
    legs, closures = [], []
    for name, (motor, end, axis) in cranks.items():
        k = int(name[0])
        legs.append(f'<body name="crank_{name}" pos="{at(motor)}"><joint name="m_{name}" type="hinge" '
                    f'axis="{at(axis / scale)}"/>{ball}<body name="rod_{name}" pos="{at(end - motor)}">'
                    f'<joint name="b_{name}" type="ball"/>{ball}{platform if name == "0a" else ""}</body></body>')
        if name != "0a":
            onto = f"rod_{k}a" if pairs and name.endswith("b") else "platform"
            closures.append(f'<connect name="c_{name}" body1="rod_{name}" anchor="{at(points[k] - end)}" '
                            f'body2="{onto}"/>')
    motors = [f'<motor joint="m_{name}"/>' for name in cranks]
    if reverse:
        legs, closures, motors = legs[::-1], closures[::-1], motors[::-1]
    return ('<mujoco model="paired_stewart"><option><flag contact="disable"/></option><worldbody>'
            f'<body name="base" pos="{world[0]}" quat="{world[1]}">' + "".join(legs) + "</body></worldbody>"
            "<equality>" + "".join(closures) + "</equality><actuator>" + "".join(motors) + "</actuator></mujoco>")


def paired_stewart_geometry():
    """The platform's three ball centres and, per rod, its crank's motor point, crank end and axis (m)."""
    points = [np.array([0.12 * np.cos(t), 0.12 * np.sin(t), 0.30]) for t in np.radians([90.0, 215.0, 330.0])]
    cranks = {}
    for k, (first, second) in enumerate(((55.0, 128.0), (178.0, 250.0), (295.0, 8.0))):
        for side, angle in zip("ab", np.radians([first, second])):
            radial = np.array([np.cos(angle), np.sin(angle), 0.0])
            motor = 0.25 * radial
            end = motor + 0.06 * radial + np.array([0.0, 0.0, 0.02])
            cranks[f"{k}{side}"] = (motor, end, np.array([-np.sin(angle), np.cos(angle), 0.0]))
    return points, cranks


@pytest.mark.parametrize("variant", sorted(MJCF_WORLDS))
def test_a_stewart_platform_whose_rods_meet_in_pairs_reads_the_rod_lines(tmp_path, variant):
    """Spatial: each pair of rods meeting at one ball of the platform written as one leg with a loop inside and two
    motors. Every ITI |u . t| and OTI from the rods' lines (MuJoCo's placement of the balls, numpy alone), the same as
    the six legs written apart, in m, mm and a moved world, and with the file listed backwards."""
    path, unit = mjcf_variant(tmp_path, "pairs", variant, paired_stewart)
    graph, indices = reading = read(path, unit)
    assert len(graph.actuators) == 6 and graph.dof == 6
    assert any("one leg with loops inside it and 2 actuators" in note for note in graph.report.notes)
    model, data, anchor = mujoco_closed(path)
    joints = {model.joint(k).name: k for k in range(model.njnt)}
    ends = {name[2:]: data.site_xpos[model.site(f"P{name[2]}").id].copy() for name in joints if name[:2] == "b_"}
    itis, starts, tips = {}, [], []
    for name in sorted(ends):
        motor, start, axis = anchor[f"m_{name}"], anchor[f"b_{name}"], data.xaxis[joints[f"m_{name}"]]
        rod = (ends[name] - start) / np.linalg.norm(ends[name] - start)
        tangent = np.cross(axis, start - motor)
        itis[f"m_{name}"] = abs(rod @ tangent) / np.linalg.norm(tangent)
        starts.append(start)
        tips.append(ends[name])
    assert by_joint(graph, indices.iti_actuators) == pytest.approx(itis, abs=1e-9)
    otis = dict(zip((f"m_{name}" for name in sorted(ends)), leg_line_otis(starts, tips)))
    assert by_joint(graph, indices.oti_actuators[0]) == pytest.approx(otis, abs=1e-9)
    assert float(indices.lmti) == pytest.approx(min(otis.values()), abs=1e-9)
    apart, _ = mjcf_variant(tmp_path, "apart", variant, lambda *a: paired_stewart(*a, pairs=False))
    assert_same(reading, read(apart, unit))
    backwards, _ = mjcf_variant(tmp_path, "backwards", variant, lambda *a: paired_stewart(*a, reverse=True))
    assert_same(reading, read(backwards, unit))


@pytest.mark.parametrize("scale", [1e-3, 1e3])
def test_the_same_for_the_mechanisms_scaled(tmp_path, scale):
    """Every length times 1e-3 and 1e3, read in metres: the planar five-bar leg and the paired Stewart platform give
    the indices of their size-one selves."""
    for name, write in (("leg", five_bar_leg), ("pairs", paired_stewart)):
        one, scaled = tmp_path / f"{name}.xml", tmp_path / f"{name}_scaled.xml"
        one.write_text(write())
        scaled.write_text(write(scale))
        assert_same(read(one), read(scaled), wrenches=False)


def swapped(text: str, first: str, second: str) -> str:
    """The file with joints ``first`` and ``second`` renamed each as the other (their motors follow)."""
    for attribute in ("name", "joint"):
        text = text.replace(f'{attribute}="{first}"', f'{attribute}="@@"')
        text = text.replace(f'{attribute}="{second}"', f'{attribute}="{first}"')
        text = text.replace(f'{attribute}="@@"', f'{attribute}="{second}"')
    return text


def test_the_indices_follow_the_motors_renamed(tmp_path):
    """The five-bar leg's motors renamed each as the other (m1 <-> m2) and an R-R-R leg's (m3 <-> m4): each ITI, the
    worst fault and the LMTI left after each failure follow the joint, not the name."""
    plain, renamed = tmp_path / "leg.xml", tmp_path / "renamed.xml"
    plain.write_text(five_bar_leg())
    renamed.write_text(swapped(swapped(five_bar_leg(), "m1", "m2"), "m3", "m4"))
    (graph, indices), (other, theirs) = read(plain), read(renamed)
    names = {"m1": "m2", "m2": "m1", "m3": "m4", "m4": "m3"}
    ours = by_joint(graph, indices.iti_actuators)
    assert {names[joint]: value for joint, value in ours.items()} == pytest.approx(
        by_joint(other, theirs.iti_actuators), abs=1e-12)
    worst = {names[graph.actuators[k].split(":")[1]] for k in np.ravel(indices.worst_fault_indices[1])}
    assert worst == {other.actuators[k].split(":")[1] for k in np.ravel(theirs.worst_fault_indices[1])}
    left = {names[graph.actuators[failed[0]].split(":")[1]]: value
            for failed, value in zip(indices.failed_sets(1), indices.remaining_lmti[1])}
    assert left == pytest.approx({other.actuators[failed[0]].split(":")[1]: value
                                  for failed, value in zip(theirs.failed_sets(1), theirs.remaining_lmti[1])}, abs=1e-12)
    assert float(theirs.lmti) == pytest.approx(float(indices.lmti), abs=1e-12)
    assert ours["m1"] != pytest.approx(ours["m2"], abs=1e-3)  # (the swap is seen)


def test_a_stage_refusal_quotes_the_reason_its_refusal_carries_and_the_reason_crosses_processes():
    """The reason a leg of actuators in series cannot be read one at a time is the one its refusal carries, quoted
    whole whatever punctuation it holds (it was the refusal's first clause, cut out of its text), else the whole
    refusal; the copy's name is left out. A refusal pickled (a worker's) keeps its reason."""
    tree = SimpleNamespace(source="robot.xml")
    legs = [SimpleNamespace(of="hip"), SimpleNamespace(of="hip"), SimpleNamespace(of="arm")]
    advice = "; --lock h1 holds the stage"
    carried = ImportError_("robot.xml: actuated joint 'k' of leg 'shin' rides on the free joint 'f' (a floating "
                           "base): --lock f holds it.", reason="actuated joint 'k' of leg 'shin' rides on 'f' (free)")
    assert str(stage_refusal(tree, legs, {"hip": advice}, carried, "shin")) == (
        "robot.xml: leg 'hip' has loops inside it and 2 actuators, which screwkit does not read one at a time here "
        "(actuated joint 'k' rides on 'f' (free)); --lock h1 holds the stage.")
    bare = ImportError_("robot.xml: actuated joint 'k' of leg 'shin' is odd: see its notes.")
    assert "here (actuated joint 'k' is odd: see its notes); --lock" in str(
        stage_refusal(tree, legs, {"hip": advice}, bare, "shin"))
    again = pickle.loads(pickle.dumps(carried))
    assert (type(again), str(again), again.reason) == (ImportError_, str(carried), carried.reason)
