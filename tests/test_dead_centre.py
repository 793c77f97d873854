"""Files written at a dead centre, and ``--initial``: the joint values the assembly starts from and holds.

A crank-rocker four-bar written as MuJoCo files often are, every joint at zero, with its crank and rod on one line
and the rocker (the platform, a foot) square to them: the foot is at the end of its travel and cannot move there
(the loop's joints move, the foot does not, to first order), and which way it goes from there is not decided. It
was read as "DOF 0" (the rod taken for an idle joint of a leg whose twists were dependent), or with a point output
as "<output type='point'>: the output point cannot move", naming an element of the text converted in memory. Now
the leg is named as stretched or folded, with the way out: ``--initial crank 20`` holds the crank at 20 degrees while
the loops close, and the indices are the four-bar's pressure angles, in any unit and world frame.

Independent references: the four-bar's closed form (the rocker angle from the rod's length by bisection; ITI =
|rod direction . the crank pin's direction of motion|, OTI = |rod direction . the rocker pin's|), and MuJoCo's own
reading of the file at the configuration screwkit assembled (its connect closed, its crank where it was held). The
same for a published file drawn so: Pinocchio's copy of Cassie (``tests/data/gallery/published``), whose plantar
rods are in line with their foot cranks, the pressure angles computed from MuJoCo's joint axes and anchors.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import mujoco
import numpy as np
import pytest
from scipy.optimize import brentq

from helpers import one_line_error, screwkit
from screwkit.io import graph_mechanism, read_closed_tree, read_mechanism_file
from screwkit.io.closed_tree import ImportError_
from screwkit.io.loader import load
from screwkit.studies import indices_at_poses
from screwkit.studies.graph_source import cached_graph, graph_source

CRANK, ROD, ROCKER = 0.05, 0.3, 0.05
PIVOT = np.array([0.35, -0.05])  # the rocker's pivot D; the crank's is the origin A
"""At zero the crank's pin B = (0.05, 0), the rod's end C = (0.35, 0) on the rocker's pin: A, B, C on one line, DC
square to it."""

TURN = ("0.1 -0.2 0.3", "0.9238795 0.2209424 0.3314136 0.1767767")  # a moved and turned world (pos, quat)


def four_bar(scale: float = 1.0, world=None, keyframe: str = "") -> str:
    """The four-bar's MJCF text, lengths times ``scale``, its bodies in a frame placed by ``world`` (pos, quat)."""
    def n(*values):
        return " ".join(repr(float(v) * scale) for v in values)

    bodies = f"""
    <body name="crank" pos="0 0 0">
      <joint name="crank" type="hinge" axis="0 0 1"/>
      <geom type="capsule" fromto="0 0 0 {n(CRANK)} 0 0" size="{n(0.005)}"/>
      <body name="rod" pos="{n(CRANK, 0, 0)}">
        <joint name="rod" type="hinge" axis="0 0 1"/>
        <geom type="capsule" fromto="0 0 0 {n(ROD)} 0 0" size="{n(0.005)}"/>
        <site name="rod_end" pos="{n(ROD, 0, 0)}"/>
      </body>
    </body>
    <body name="foot" pos="{n(*PIVOT, 0)}">
      <joint name="foot" type="hinge" axis="0 0 1"/>
      <geom type="capsule" fromto="0 0 0 0 {n(ROCKER)} 0" size="{n(0.005)}"/>
      <site name="foot_pin" pos="0 {n(ROCKER)} 0"/>
    </body>"""
    if world is not None:
        bodies = f'<body name="frame" pos="{n(*map(float, world[0].split()))}" quat="{world[1]}">{bodies}</body>'
    return f"""<mujoco model="four_bar">
  <worldbody>{bodies}
  </worldbody>
  <equality><connect site1="rod_end" site2="foot_pin"/></equality>
  <actuator><motor joint="crank"/></actuator>{keyframe}
</mujoco>
"""


def slider_crank(scale: float = 1.0) -> str:
    """A slider-crank written at its dead centre (crank and rod along the slide): the slider is the platform."""
    def n(*values):
        return " ".join(repr(float(v) * scale) for v in values)

    return f"""<mujoco model="slider_crank">
  <worldbody>
    <body name="crank"><joint name="crank" type="hinge" axis="0 0 1"/>
      <geom type="sphere" size="{n(0.01)}"/>
      <body name="rod" pos="{n(CRANK, 0, 0)}"><joint name="rod" type="hinge" axis="0 0 1"/>
        <geom type="sphere" size="{n(0.01)}"/><site name="rod_end" pos="{n(0.2, 0, 0)}"/></body>
    </body>
    <body name="slider"><joint name="slider" type="slide" axis="1 0 0"/>
      <geom type="box" size="{n(0.01, 0.01, 0.01)}"/><site name="pin" pos="{n(0.25, 0, 0)}"/></body>
  </worldbody>
  <equality><connect site1="rod_end" site2="pin"/></equality>
  <actuator><motor joint="crank"/></actuator>
</mujoco>
"""


def four_bar_closed_form(crank_deg: float) -> dict:
    """The four-bar with its crank at ``crank_deg``, on the branch next to the drawing: rocker angle, rod end C and
    the pressure-angle indices."""
    t = np.radians(crank_deg)
    b = CRANK * np.array([np.cos(t), np.sin(t)])

    def pin(f):
        return PIVOT + ROCKER * np.array([-np.sin(f), np.cos(f)])

    f = brentq(lambda f: np.linalg.norm(pin(f) - b) - ROD, 1e-12, np.pi / 2, xtol=1e-15)
    c = pin(f)
    u = (c - b) / ROD
    along_b = np.array([-b[1], b[0]]) / CRANK
    along_c = np.array([-(c - PIVOT)[1], (c - PIVOT)[0]]) / ROCKER
    return {"rocker": f, "c": c, "iti": abs(u @ along_b), "oti": abs(u @ along_c)}


def indices_at_home(mechanism):
    return indices_at_poses(mechanism, mechanism.home_pose[None], detail=True)


def written(tmp_path, text: str, name: str = "four_bar.xml"):
    path = tmp_path / name
    path.write_text(text)
    return path


@pytest.mark.parametrize("output_type", [None, "point", "frame"])
@pytest.mark.parametrize("scale, unit, world", [(1.0, None, None), (1000.0, "mm", None), (1e-3, "km", TURN)])
def test_a_file_at_its_dead_centre_is_refused_naming_the_stretched_leg_and_the_way_out(tmp_path, output_type, scale,
                                                                                      unit, world):
    path = written(tmp_path, four_bar(scale, world))
    with pytest.raises(ImportError_) as refusal:
        load(path, output="foot", output_type=output_type, length_unit=unit)
    message = str(refusal.value)
    assert message.startswith(f"{path}: the leg closed by 'connect_1' (joints crank, rod) is stretched or folded at "
                              "the assembly"), message
    assert "--initial JOINT VALUE" in message and "a keyframe named 'home'" in message
    assert "<" not in message  # no element of the text converted in memory (it named <output type='point'>)


@pytest.mark.parametrize("crank", [20.0, -35.0])
@pytest.mark.parametrize("scale, unit, world", [(1.0, None, None), (1000.0, "mm", None), (1e-3, "km", TURN)])
def test_an_initial_crank_is_held_and_gives_the_four_bar_pressure_angles(tmp_path, crank, scale, unit, world):
    expected = four_bar_closed_form(crank)
    path = written(tmp_path, four_bar(scale, world))
    for output_type in ("point", "frame"):
        mechanism = load(path, output="foot", output_type=output_type, length_unit=unit, initial=[("crank", crank)])
        result = indices_at_home(mechanism)
        assert result.iti[0] == pytest.approx(expected["iti"], abs=1e-9)
        assert result.lmti[0] == pytest.approx(expected["oti"], abs=1e-9)
        assert np.all(result.reachable)
        report = "\n".join(mechanism.import_report)
        assert f"joint values given (--initial): crank {crank:g} deg" in report
        assert "nearest to the joint values given (--initial)" in report
        configuration = dict(zip(mechanism.chains[0].joint_names, mechanism.chains[0].reference_values))
        assert np.degrees(configuration["crank"]) == pytest.approx(crank, abs=1e-9)  # held, not slid back
    if world is None:
        assert mechanism.home_pose.size == 1  # the frame's phi: the rocker turned from its drawing
        point = load(path, output="foot", output_type="point", length_unit=unit, initial=[("crank", crank)])
        assert point.home_pose[0] == pytest.approx(expected["c"][0], abs=1e-9)


def test_the_legs_listed_the_other_way_and_renamed_give_the_same_indices(tmp_path):
    """The four-bar with its rocker's body written before the crank's and every joint renamed: refused at its dead
    centre naming the renamed leg, and with the renamed crank given, the same closed-form pressure angles."""
    text = four_bar()
    crank = text[text.index('    <body name="crank"'):text.index('    <body name="foot"')]
    foot = text[text.index('    <body name="foot"'):text.index("  </worldbody>")]
    moved = text.replace(crank + foot, foot.rstrip("\n") + "\n" + crank.rstrip("\n") + "\n")
    for old, name in (("crank", "driver"), ("rod", "coupler"), ("foot", "rocker")):
        moved = moved.replace(f'<joint name="{old}"', f'<joint name="{name}"').replace(f'<motor joint="{old}"',
                                                                                     f'<motor joint="{name}"')
    assert moved.index('<body name="foot"') < moved.index('<body name="crank"') and 'joint name="driver"' in moved
    path = written(tmp_path, moved, "relabelled.xml")
    with pytest.raises(ImportError_, match=r"\(joints driver, coupler\) is stretched or folded at the assembly"):
        load(path, output="foot")
    expected = four_bar_closed_form(20.0)
    result = indices_at_home(load(path, output="foot", output_type="frame", initial=[("driver", 20.0)]))
    assert result.iti[0] == pytest.approx(expected["iti"], abs=1e-9)
    assert result.lmti[0] == pytest.approx(expected["oti"], abs=1e-9)


def test_mujoco_reads_the_configuration_assembled_as_closed(tmp_path):
    """MuJoCo's own reading: the joint values screwkit assembled (crank held at 20 deg) close the file's connect,
    and the rocker is where the closed form puts it."""
    path = written(tmp_path, four_bar())
    text, _ = read_mechanism_file(path, output="foot", output_type="frame", initial=[("crank", 20.0)])
    values = {m.group(1): float(m.group(2)) for m in re.finditer(r'<joint name="(\w+)" value="([^"]+)"', text)}
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    for name in ("crank", "rod", "foot"):
        data.qpos[model.joint(name).qposadr[0]] = values[name]
    mujoco.mj_forward(model, data)
    assert np.abs(data.site("rod_end").xpos - data.site("foot_pin").xpos).max() < 1e-12
    assert np.degrees(values["crank"]) == pytest.approx(20.0, abs=1e-12)
    assert values["foot"] == pytest.approx(four_bar_closed_form(20.0)["rocker"], abs=1e-9)


@pytest.mark.parametrize("scale, unit", [(1.0, None), (1000.0, "mm")])
def test_an_initial_slide_is_in_metres_whatever_the_file_s_unit(tmp_path, scale, unit):
    """Started slide and crank together close the loop only if the slide's metres reach the file's numbers right."""
    crank = 30.0
    t = np.radians(crank)
    pin = CRANK * np.cos(t) + np.sqrt(0.2**2 - (CRANK * np.sin(t)) ** 2)
    path = written(tmp_path, slider_crank(scale), "slider_crank.xml")
    with pytest.raises(ImportError_, match="stretched or folded"):
        load(path, output="slider", length_unit=unit)
    mechanism = load(path, output="slider", length_unit=unit, initial=[("crank", crank), ("slider", pin - 0.25)])
    result = indices_at_home(mechanism)
    b = CRANK * np.array([np.cos(t), np.sin(t)])
    u = (np.array([pin, 0.0]) - b) / 0.2
    assert result.iti[0] == pytest.approx(abs(u @ np.array([-np.sin(t), np.cos(t)])), abs=1e-9)
    assert result.lmti[0] == pytest.approx(abs(u[0]), abs=1e-9)
    with pytest.raises(ImportError_, match=r"the loops cannot be closed with --initial crank 30, --initial slider "
                                           r"0\.01 held \(the file's values for the other joints\)"):
        load(path, output="slider", length_unit=unit, initial=[("crank", crank), ("slider", 0.01)])
    tree = read_closed_tree(path, output="slider", length_unit=unit, initial=[("slider", 0.01)])  # a graph's reading
    slide = tree.model.joints[tree.model.getJointId("slider")].idx_q
    assert tree.unit == "m" and tree.q_reference[slide] == pytest.approx(0.01, abs=1e-15)  # the file in metres


def test_a_file_in_screwkits_convention_at_its_dead_centre_names_the_stretched_chain(tmp_path):
    """The same four-bar written in screwkit's convention at its dead centre: converted at 20 deg, then its
    reference configuration set back to zero and its platform frame turned back with the rocker."""
    text, _ = read_mechanism_file(written(tmp_path, four_bar()), output="foot", output_type="frame",
                                  initial=[("crank", 20.0)])
    rocker = four_bar_closed_form(20.0)["rocker"]
    platform = '<origin xyz="0.35 -0.05 0" rpy="0 0 0" />\n    <axis xyz="0 0 1" />\n  </joint>\n  <link name="crank'
    assert text.count(platform) == 1
    text = text.replace(platform, platform.replace('rpy="0 0 0"', f'rpy="0 0 {-rocker!r}"'))
    text, count = re.subn(r'(<joint name="(crank|rod|foot)" value=")[^"]+"', r'\g<1>0"', text)
    assert count == 3
    path = tmp_path / "dead.urdf"
    path.write_text(text)
    with pytest.raises(ValueError) as refusal:
        load(path)
    assert str(refusal.value) == (
        f"{path}: <robot name='four_bar'>: the reference assembly is a singular configuration: chain crank is "
        "stretched or folded there (its joints' twists span less than at joint values near it: a dead centre, such "
        "as a crank and its rod on one line), where the platform moves less than the mechanism does elsewhere and "
        "the working mode is not decided; write its <reference_configuration> away from it.")


@pytest.mark.parametrize("leg, turn_deg", [(1, 70.0), (2, 110.0)])
def test_a_five_bar_in_screwkits_convention_drawn_with_a_leg_stretched_is_refused_not_read_as_one_dof(tmp_path, leg,
                                                                                                     turn_deg):
    """The bundled five-bar (2 DOF) with its output point written 0.5 m from a leg's base joint, the sum of its
    links, and that leg written straight: the platform moves along one line there only, and it was read as a
    redundant 1-DOF mechanism, every fault-tolerance figure of another mechanism (or refused for its task
    coordinates x y, 'not 1 independent coordinates'). It is refused naming the stretched chain, the first or the
    second."""
    from screwkit.io.loader import bundled_path

    text = bundled_path("five_bar").read_text()
    turn = np.radians(turn_deg)  # the leg from A_k = (-+0.1, 0) along turn: P = A_k + 0.5 (cos, sin)
    base_joint = np.array([-0.1 if leg == 1 else 0.1, 0.0])
    point = [float(v) for v in base_joint + 0.5 * np.array([np.cos(turn), np.sin(turn)])]
    other = np.array([0.1 if leg == 1 else -0.1, 0.0])
    assert np.linalg.norm(np.subtract(point, other)) < 0.5  # the other leg reaches it
    written_text = text.replace('<origin xyz="0 0.35 0" rpy="0 0 0" />', f'<origin xyz="{point[0]!r} {point[1]!r} 0" '
                                'rpy="0 0 0" />')
    base = float(re.search(rf'name="chain_{leg}_joint_b".*?rpy="0 0 ([^"]+)"', text, re.S).group(1))
    elbow = float(re.search(rf'name="chain_{leg}_joint_c".*?rpy="0 0 ([^"]+)"', text, re.S).group(1))
    straight = f"""  <reference_configuration>
    <joint name="chain_{leg}_joint_b" value="{float(turn) - base!r}" />
    <joint name="chain_{leg}_joint_c" value="{-elbow!r}" />
  </reference_configuration>
  <output type="point" />"""
    written_text = written_text.replace('  <output type="point" />', straight)
    assert written_text.count(repr(float(point[0]))) == 1 and "<reference_configuration>" in written_text
    for declared in (True, False):
        path = tmp_path / f"stretched_{declared}.urdf"
        path.write_text(written_text if declared else re.sub(r"\s*<task_coordinates[^>]*/>", "", written_text))
        with pytest.raises(ValueError, match=rf"the reference assembly is a singular configuration: chain chain_{leg} "
                                             r"is stretched or folded there .* where the platform moves less than "
                                             r"the mechanism does elsewhere"):
            load(path)
    assert load("five_bar").dof == 2


def test_initial_values_are_checked_before_anything_is_assembled(tmp_path):
    path = written(tmp_path, four_bar())
    for start, message in (([("nope", 1.0)], "--initial nope 1: no joint of that name; the joints that can be given "
                                             "one (revolute or prismatic) are crank, rod, foot."),
                           ([("crank", 1.0), ("crank", 2.0)], "--initial crank: given twice."),
                           ([("crank", float("nan"))], "--initial crank nan: expected a finite number"),
                           ([("crank", "x")], "--initial crank 'x': expected a finite number"),
                           ([("crank", True)], "--initial crank True: expected a finite number"),
                           ("crank", "--initial: expected pairs of a joint name and a value, got str 'crank'"),
                           ([("crank",)], "--initial: expected pairs of a joint name and a value, got ('crank',)"),
                           ([(3, 1.0)], "--initial: expected a joint name, got 3")):
        with pytest.raises(ImportError_) as refusal:
            read_closed_tree(path, output="foot", initial=start)
        assert str(refusal.value) == f"{path}: {message}" or str(refusal.value).startswith(f"{path}: {message}")
    with pytest.raises(ValueError, match="locked, actuated or initial joints named apart from the file"):
        load("planar_5rrr", initial=[("chain_1_joint_b", 10.0)])


def test_a_ball_joint_cannot_be_given_an_initial_value(tmp_path):
    text = four_bar().replace('<joint name="foot" type="hinge" axis="0 0 1"/>', '<joint name="foot" type="ball"/>')
    path = written(tmp_path, text)
    with pytest.raises(ImportError_, match=r"--initial foot 5: a joint of 3 DoF \(JointModelSpherical\), not a 1-DoF "
                                           r"joint; the joints that can be given one \(revolute or prismatic\) are "
                                           r"crank, rod\."):
        read_closed_tree(path, output="foot", initial=[("foot", 5.0)])


def test_lock_holds_a_joint_at_its_initial_value(tmp_path):
    """--lock after --initial: the crank merged into the base where --initial put it, so the rod hangs from the
    crank's pin at 20 deg (at 0 deg before --initial was taken into account)."""
    path = written(tmp_path, four_bar())
    tree = read_closed_tree(path, output="foot", initial=[("crank", 20.0)], lock=["crank"], actuate=["rod"])
    model = tree.model
    assert "crank" not in [str(name) for name in model.names]
    assert tree.initial == (("crank", 20.0),) and tree.initial_joints() == []
    hinge = np.asarray(model.jointPlacements[model.getJointId("rod")].translation)[:2]
    assert hinge == pytest.approx(CRANK * np.array([np.cos(np.radians(20.0)), np.sin(np.radians(20.0))]), abs=1e-12)
    assert any("locked at their values in the file (crank at its --initial value) (--lock)" in note
               for note in tree.notes)


def test_an_idle_joint_beside_a_dead_centre_does_not_hide_it(tmp_path):
    """A second hinge coaxial with the rod's (an idle joint, dependent at every configuration) on the four-bar at its
    dead centre: the leg's twists span less there than near it, so it is refused as stretched (it was locked down to
    the dead centre's rank and refused as "DOF 0"); given the crank, only the idle hinge is locked."""
    path = written(tmp_path, four_bar().replace('<joint name="rod" type="hinge" axis="0 0 1"/>',
                                                '<joint name="rod" type="hinge" axis="0 0 1"/><joint name="rod2" '
                                                'type="hinge" axis="0 0 1"/>'))
    for output_type in ("point", "frame"):
        with pytest.raises(ImportError_, match=r"the leg closed by 'connect_1' \(joints crank, rod, rod2\) is "
                                               r"stretched or folded at the assembly"):
            load(path, output="foot", output_type=output_type)
    mechanism = load(path, output="foot", output_type="frame", initial=[("crank", 20.0)])
    assert mechanism.chains[0].joint_names == ("crank", "rod", "crank_loop")
    assert indices_at_home(mechanism).iti[0] == pytest.approx(four_bar_closed_form(20.0)["iti"], abs=1e-9)


def test_the_platform_body_s_own_path_stretched_is_named_so(tmp_path):
    """The coupler's tip hinged at the rod's end, carrying the connect and the output: the platform's own path (crank,
    rod, wrist) is the stretched one, named as such (it was "the leg closed by ''")."""
    path = written(tmp_path, four_bar().replace('<site name="rod_end" pos="0.3 0.0 0.0"/>',
                                                '<body name="tip" pos="0.3 0.0 0.0"><joint name="wrist" type="hinge" '
                                                'axis="0 0 1"/><geom type="sphere" size="0.01"/><site name="rod_end" '
                                                'pos="0 0 0"/></body>'))
    assert 'name="wrist"' in path.read_text()
    with pytest.raises(ImportError_, match=r"the platform body's own path \(joints crank, rod, wrist\) is stretched or "
                                           r"folded at the assembly"):
        load(path, output="tip", output_type="frame")


def test_a_graph_rebuilt_elsewhere_keeps_its_initial_values(tmp_path):
    """A closed-loop graph read with --initial, rebuilt where a map's task runs (its GraphSource), assembles as read."""
    from rod_ankle import rod_ankle_mjcf

    path = written(tmp_path, rod_ankle_mjcf(), "ankle.xml")
    graph = graph_mechanism(read_closed_tree(path, output="foot", initial=[("motor_1", 12.0)]))
    plain = graph_mechanism(read_closed_tree(path, output="foot"))
    model = graph.tree.model
    motor = model.joints[model.getJointId("motor_1")].idx_q
    assert np.degrees(graph.q[motor]) == pytest.approx(12.0, abs=1e-12)
    assert abs(np.degrees(plain.q[motor]) - 12.0) > 1.0
    source = graph_source(graph)
    assert source.initial == (("motor_1", 12.0),)
    again = cached_graph(source)
    assert np.array_equal(again.q, graph.q)
    assert graph.indices().lmti == pytest.approx(again.indices().lmti, abs=0.0)


def test_the_command_line_takes_initial_values_converts_and_refuses_in_one_line(tmp_path):
    path = written(tmp_path, four_bar())
    refused = screwkit("info", path, "--output", "foot")
    one_line_error(refused, "four_bar.xml: the leg closed by 'connect_1' (joints crank, rod) is stretched or folded",
                   "--initial JOINT VALUE")
    analysed = screwkit("analyze", path, "--output", "foot", "--initial", "crank", "20", "--json")
    assert analysed.returncode == 0, analysed.stderr
    report = json.loads(analysed.stdout)
    expected = four_bar_closed_form(20.0)
    assert report["iti"] == pytest.approx(expected["iti"], abs=1e-9)
    assert report["lmti"] == pytest.approx(expected["oti"], abs=1e-9)
    assert any("joint values given (--initial): crank 20 deg" in line for line in report["converted"])
    out = tmp_path / "four_bar.urdf"
    converted = screwkit("convert", path, out, "--output", "foot", "--initial", "crank", "20")
    assert converted.returncode == 0, converted.stderr
    assert indices_at_home(load(out)).iti[0] == pytest.approx(expected["iti"], abs=1e-9)
    wrong = screwkit("analyze", path, "--output", "foot", "--initial", "crank", "80")
    one_line_error(wrong, "the loops cannot be closed with --initial crank 80 held")
    limited = written(tmp_path, four_bar().replace('name="foot" type="hinge"', 'name="foot" type="hinge" '
                                                   'range="5 40"'), "limited.xml")
    hint = ("--initial JOINT VALUE on this joint (5 to 40 deg) or on the one driving it, in place of another value "
            "given, starts the assembly inside them")
    one_line_error(screwkit("analyze", limited, "--output", "foot", "--initial", "crank", "20"),
                   "<joint name='foot'>: the reference assembly puts the joint at 0.0702626, outside its limits", hint)
    refused = one_line_error(screwkit("convert", limited, tmp_path / "limited.urdf", "--output", "foot", "--initial",
                                      "crank", "20"), "<joint name='foot'>: the reference assembly", hint)
    assert not (tmp_path / "limited.urdf").exists() and "<output" not in refused
    opened = screwkit("analyze", limited, "--output", "foot", "--initial", "crank", "60", "--json")
    assert opened.returncode == 0, opened.stderr


PINOCCHIO_CASSIE = Path(__file__).parent / "data/gallery/published/pinocchio_closed_chain/closed_chain.xml"
CASSIE_LEFT_ANKLE = {"output": "left-foot", "actuate": ["left-foot-crank"],
                     "lock": ["cassie-pelvis_free", "left-hip-roll", "left-hip-yaw", "left-hip-pitch", "left-knee",
                              "left-shin", "left-tarsus"]}
"""The plantar four-bar of the left leg: the crank drives the foot through the plantar rod (the joints the
refusals name locked, the crank named as the actuator: the file has none)."""


def test_pinocchio_s_cassie_drawn_at_its_plantar_dead_centre_opens_with_its_crank_given():
    """Pinocchio's copy of Cassie, every joint at zero: its plantar rod in line with the foot crank. Refused naming
    the leg (it was "DOF 0"); with the crank given, its indices are the four-bar's pressure angles as MuJoCo places
    its joints at the configuration screwkit assembled (the connect closed there, as MuJoCo measures it)."""
    with pytest.raises(ImportError_, match=r"closed_chain\.xml: the leg closed by 'connect_1' \(joints "
                                           r"left-foot-crank, left-plantar-rod\) is stretched or folded at the "
                                           r"assembly"):
        load(PINOCCHIO_CASSIE, **CASSIE_LEFT_ANKLE)
    for crank, output_type in ((-60.0, "point"), (-45.0, "frame")):
        options = dict(CASSIE_LEFT_ANKLE, initial=[("left-foot-crank", crank)], output_type=output_type)
        result = indices_at_home(load(PINOCCHIO_CASSIE, **options))
        text, _ = read_mechanism_file(PINOCCHIO_CASSIE, **options)
        values = {m.group(1): float(m.group(2)) for m in re.finditer(r'<joint name="([\w-]+)" value="([^"]+)"', text)}
        model = mujoco.MjModel.from_xml_path(str(PINOCCHIO_CASSIE))
        data = mujoco.MjData(model)
        for name, value in values.items():
            data.qpos[model.joint(name).qposadr[0]] = value
        mujoco.mj_forward(model, data)
        assert np.degrees(values["left-foot-crank"]) == pytest.approx(crank, abs=1e-12)
        rod = model.body("left-plantar-rod").id
        pin = data.xpos[rod] + data.xmat[rod].reshape(3, 3) @ np.array([0.35012, 0.0, 0.0])  # the connect's anchor
        foot = model.body("left-foot").id
        anchor_on_foot = data.xpos[foot] + data.xmat[foot].reshape(3, 3) @ model.eq_data[0][3:6]
        assert np.linalg.norm(pin - anchor_on_foot) < 1e-9  # MuJoCo's connect residual
        crank_pin = data.xanchor[model.joint("left-plantar-rod").id]
        along = (pin - crank_pin) / np.linalg.norm(pin - crank_pin)
        assert result.iti[0] == pytest.approx(abs(along @ moving(model, data, "left-foot-crank", crank_pin)), abs=1e-9)
        assert result.lmti[0] == pytest.approx(abs(along @ moving(model, data, "left-foot", pin)), abs=1e-9)
        assert 0.3 < result.iti[0] < 1.0 and 0.3 < result.lmti[0] < 1.0


def moving(model, data, joint: str, point):
    """The unit direction ``point`` moves in when MuJoCo's hinge ``joint`` turns (its axis and anchor in the world)."""
    index = model.joint(joint).id
    moved = np.cross(data.xaxis[index], point - data.xanchor[index])
    return moved / np.linalg.norm(moved)


def test_a_rod_delta_drawn_with_a_forearm_in_line_with_its_arm_opens_with_that_motor_given(tmp_path):
    """A Delta of ball-jointed rods (a closed-loop graph) drawn with leg 4's rods in line with its arm: refused as
    written at a singular configuration of that leg, now with the way out; given motor_4 at -10 deg, the graph
    assembles there (MuJoCo's own reading: every connect closed, the motor where it was given) and its leg 4
    transmits again."""
    from delta_rods import ARM, BASE, PLATFORM, ROD, delta_rods_mjcf
    from test_gallery import mujoco_residuals
    from test_gallery_published import mujoco_qpos

    turn = np.radians(105.0)  # leg 4 (azimuth 0) stretched, the arm pointing down and inwards
    centre = (BASE - PLATFORM + (ARM + ROD) * np.cos(turn), 0.0, -(ARM + ROD) * np.sin(turn))
    path = written(tmp_path, delta_rods_mjcf(centre), "delta.xml")
    with pytest.raises(ImportError_, match=r"delta\.xml: locking actuated joint 'motor_4' leaves the platform of leg "
                                           r"'arm_4' as free as before at the file's joint values, .* singular "
                                           r"configuration of the leg .*--initial JOINT VALUE"):
        graph_mechanism(read_closed_tree(path))
    graph = graph_mechanism(read_closed_tree(path, initial=[("motor_4", -10.0)]))
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    data.qpos[:] = mujoco_qpos(graph.tree, model, graph.q)
    mujoco.mj_kinematics(model, data)
    assert max(np.abs(gap).max() for gap in mujoco_residuals(model, data).values()) < 1e-9
    assert data.qpos[model.joint("motor_4").qposadr[0]] == pytest.approx(np.radians(-10.0), abs=1e-12)
    result = graph.indices()
    assert graph.dof == 3 and result.iti_actuators[3] > 0.05
