"""A pose reached past a configuration where a chain's joints are singular is said to be so.

A square four-bar (every link as long: Genesis's ``four_bar_linkage.xml`` is one, here rewritten) has a change point
at the crank's 90 deg: the crank's end lands on the rocker's pivot, and the parallelogram assembly meets the folded
one. A chain closed by damped Newton keeps the reference's working-mode sign of its joint-twist determinant, which
past that point is the folded assembly (the crank held at 90 deg while the rocker turns), not the parallelogram a
motion through it may continue into. ``analyze --pose`` now says where the way from the reference pose meets such
a configuration. The closed form: with the ground pivot A at the origin and the rocker's pivot D a side above it,
the crank's end B = A + side (cos t, sin t) lands on D at t = 90 deg, where the rocker's angle phi is 90 deg too
(the parallelogram keeps the rocker parallel to the crank) and A, B = D and C = D + side (0, 1) are on one line.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from helpers import one_line_error, random_rotation, screwkit
from screwkit.closure.on_the_way import singular_on_the_way, singular_on_the_ways
from screwkit.io.loader import load
from screwkit.studies.sweep import sweep

SIDE = 4.0


def square_four_bar(scale: float = 1.0, world=None) -> str:
    """A square four-bar in MJCF as Genesis writes it (hinges about x, the loop closed by a ``<connect>``), sides
    ``SIDE`` times ``scale``, its ground link placed by ``world`` (rotation, translation) in the world."""
    side = SIDE * scale
    return genesis_four_bar(side, side, side, 0.125 * side, 0.0, 0.05 * side, ("hinge_1", "hinge_2"), world)


def genesis_four_bar(crank: float, coupler: float, rocker: float, offset: float, anchor_x: float, thickness: float,
                     motors: tuple[str, ...], world=None) -> str:
    """A four-bar in MJCF as Genesis's ``four_bar_linkage.xml`` writes it: from the ground link, the crank along y,
    the coupler along z, the rocker along -y, hinges about x (each drawn ``offset`` along it), the rocker's end
    ``<connect>``-ed back to the ground at ``anchor_x`` along x; ``motors`` driven; the ground link placed by
    ``world`` (rotation, translation)."""
    rotation, shift = (np.eye(3), np.zeros(3)) if world is None else world
    w, x, y, z = _quaternion(rotation)

    def at(*values):
        return " ".join(repr(float(v)) for v in values)

    actuators = "".join(f'\n    <motor joint="{motor}"/>' for motor in motors)
    return f"""<mujoco>
  <worldbody>
    <body name="link_1" pos="{at(*shift)}" quat="{at(w, x, y, z)}">
      <geom type="capsule" fromto="0 0 0 0 0 {coupler}" size="{thickness}"/>
      <body name="link_2" pos="{at(offset, 0, 0)}">
        <joint name="hinge_1" pos="0 0 0" axis="1 0 0"/>
        <geom type="capsule" fromto="0 0 0 0 {crank} 0" size="{thickness}"/>
        <body name="link_3" pos="{at(-offset, crank, 0)}">
          <joint name="hinge_2" pos="0 0 0" axis="1 0 0"/>
          <geom type="capsule" fromto="0 0 0 0 0 {coupler}" size="{thickness}"/>
          <body name="link_4" pos="{at(offset, 0, coupler)}">
            <joint name="hinge_3" pos="0 0 0" axis="1 0 0"/>
            <geom type="capsule" fromto="0 0 0 0 {-rocker} 0" size="{thickness}"/>
          </body>
        </body>
      </body>
    </body>
  </worldbody>
  <equality>
    <connect name="kinematic_link1" body1="link_1" body2="link_4" anchor="{at(anchor_x, crank - rocker, coupler)}"/>
  </equality>
  <actuator>{actuators}
  </actuator>
</mujoco>
"""


def _quaternion(rotation) -> tuple[float, float, float, float]:
    from scipy.spatial.transform import Rotation

    x, y, z, w = Rotation.from_matrix(rotation).as_quat()
    return w, x, y, z


def test_the_square_four_bar_s_change_point_is_found_where_the_closed_form_puts_it():
    a, d = np.zeros(2), np.array([0.0, SIDE])
    b = a + SIDE * np.array([np.cos(np.pi / 2), np.sin(np.pi / 2)])
    c = b + (d - a)  # the parallelogram at the crank's 90 deg: its rocker at 90 deg too
    along, across = b - a, c - a
    assert np.allclose(b, d) and abs(along[0] * across[1] - along[1] * across[0]) < 1e-12  # A, B, C on one line


WORLDS = {"as written": None, "moved": (random_rotation(np.random.default_rng(3)), np.array([0.7, -1.2, 2.0]))}


@pytest.mark.parametrize(("scale", "unit", "world"), [(1.0, None, "as written"), (1.0, None, "moved"),
                                                      (1e3, "mm", "moved"), (1e-3, None, "moved")])
def test_a_pose_past_the_change_point_names_the_chain_and_where(tmp_path, world, scale, unit):
    """Each scale in the moved world (as written at 1 too): the change point's chain and pose the same."""
    path = tmp_path / "square.xml"
    path.write_text(square_four_bar(scale, WORLDS[world]))
    mechanism = load(path, output="link_4", length_unit=unit)
    assert mechanism.task_coordinates == ("phi",)
    (passed,) = singular_on_the_way(mechanism, np.radians([90.2]))  # analyze's one pose, its way sampled alone
    assert passed[0] == "hinge_1"
    assert np.degrees(passed[1][0]) == pytest.approx(90.0, abs=1e-3)
    assert singular_on_the_way(mechanism, np.radians([89.9])) == []
    beyond, before = [200.0, 120.0, 91.0, 90.2, 300.0], [80.0, 89.0, 89.9, -60.0, 0.0]  # (300: past 269.5 deg, where
    ((name, past, where),) = singular_on_the_ways(mechanism, np.radians(beyond + before)[:, None])  # it does not close)
    assert name == "hinge_1"
    np.testing.assert_array_equal(past, [True] * 5 + [False] * 5)
    np.testing.assert_allclose(np.degrees(where[:5, 0]), 90.0, atol=1e-3)


def test_analyze_says_so_on_the_command_line_and_in_json(tmp_path):
    path = tmp_path / "square.xml"
    path.write_text(square_four_bar())
    run = screwkit("analyze", path, "--output", "link_4", "--pose", "200")
    assert run.returncode == 0, run.stderr
    (note,) = [line for line in run.stdout.splitlines() if "NOTE:" in line]
    assert "chain hinge_1's joints are singular at phi = 90: two of its assemblies meet there" in note
    assert "--initial JOINT VALUE on each actuator" in note
    run = screwkit("analyze", path, "--output", "link_4", "--pose", "200", "--json")
    assert run.returncode == 0, run.stderr
    (passed,) = json.loads(run.stdout)["singular_on_the_way"]
    assert passed["chain"] == "hinge_1" and passed["pose"]["phi"] == pytest.approx(90.0, abs=1e-3)
    for pose in ("80", "-60"):
        run = screwkit("analyze", path, "--output", "link_4", "--pose", pose, "--json")
        assert run.returncode == 0, run.stderr
        assert "singular_on_the_way" not in json.loads(run.stdout)
    run = screwkit("analyze", path, "--output", "link_4")  # the reference pose itself: no way to pass
    assert run.returncode == 0 and "NOTE:" not in run.stdout
    run = screwkit("info", path, "--output", "link_4")  # the ground pin's chain: its loop alone, passive
    assert run.returncode == 0, run.stderr
    assert "kinematic_link1: kinematic_link1_loop (passive); loop kinematic_link1_loop (revolute)" in run.stdout
    assert "chain kinematic_link1: no joint but its loop, loop revolute (closure kinematic_link1)" in run.stdout


def test_a_chain_of_its_closure_alone_is_named_so_when_it_locks_the_platform(tmp_path):
    """The four-bar welded to its ground instead of pinned: a structure; leaving out either chain frees it."""
    path = tmp_path / "welded.xml"
    text = square_four_bar()
    connect = text[text.index("<connect "):text.index("/>", text.index("<connect ")) + 2]
    path.write_text(text.replace(connect, '<weld name="kinematic_link1" body1="link_1" body2="link_4"/>'))
    run = screwkit("analyze", path, "--output", "link_3")
    one_line_error(run, "any one chain left out, the others would let it move", "kinematic_link1 (its closure's joint)")


def test_initial_values_that_still_assemble_a_dead_centre_are_told_to_give_more_joints(tmp_path):
    """--initial hinge_1 200 alone closes the loop from the file's other values onto the kite where the coupler's end
    falls on the crank's pivot (hinge_1 and hinge_3 coaxial): refused, now saying which joints to give as well; with
    the coupler's value too, the parallelogram at 200 deg opens."""
    path = tmp_path / "square.xml"
    path.write_text(square_four_bar())
    run = screwkit("analyze", path, "--output", "link_4", "--initial", "hinge_1", "200")
    one_line_error(run, "the platform body's own path (joints hinge_1, hinge_2, hinge_3) is stretched or folded",
                   "the values given (--initial hinge_1 200) assemble it so: give values to more of its joints "
                   "(hinge_2, hinge_3) to start from another assembly.")
    run = screwkit("analyze", path, "--output", "link_4", "--initial", "hinge_1", "200", "--initial", "hinge_2",
                   "-200", "--json")
    assert run.returncode == 0, run.stderr
    values = {name: entry["value"] for name, entry in json.loads(run.stdout)["configuration"].items()}
    assert values["hinge_1:hinge_1"] % 360 == pytest.approx(200.0)  # held where given
    assert values["hinge_1:hinge_2"] % 360 == pytest.approx(160.0)


@pytest.mark.parametrize("samples", [201, 64])
def test_a_path_through_the_change_point_reports_it_where_the_closed_form_puts_it(tmp_path, samples):
    """A path of the rocker from 0 to 200 deg: one "singular" event, at 90 deg of it (0.45 of its length), whether
    90 deg is a sample (201) or between two (64); a path from 0 to 80 deg has none."""
    from screwkit.studies.paths import line_path
    from screwkit.studies.trajectory import trajectory

    path = tmp_path / "square.xml"
    path.write_text(square_four_bar(1e3, WORLDS["moved"]))
    mechanism = load(path, output="link_4", length_unit="mm")
    result = trajectory(mechanism, line_path(mechanism, np.radians([0.0]), np.radians([200.0]), samples))
    (event,) = [e for e in result.events if e.kind == "singular"]
    assert event.start / result.path.length == pytest.approx(0.45, abs=1e-6)
    assert "chain hinge_1's joints are singular here" in event.reason
    first, last = event.samples
    assert result.path.arc_length[first] <= event.start <= result.path.arc_length[last]
    shorter = trajectory(mechanism, line_path(mechanism, np.radians([0.0]), np.radians([80.0]), samples))
    assert not [e for e in shorter.events if e.kind == "singular"]


def test_the_trajectory_command_says_so(tmp_path):
    path = tmp_path / "square.xml"
    path.write_text(square_four_bar())
    run = screwkit("trajectory", path, "--output", "link_4", "--line", "0", "200", "--samples", "101", "--out",
                   tmp_path / "t.csv")
    assert run.returncode == 0, run.stderr
    (line,) = [line for line in run.stderr.splitlines() if line.startswith("  SINGULAR at ")]
    assert "chain hinge_1's joints are singular here" in line


def test_actuator_values_past_the_change_point_are_refused_saying_the_pose_may_be_on_another_assembly(tmp_path):
    """The parallelogram at 100 deg (crank 100, coupler -100: the loop closes exactly) is not reached from the start
    poses --pose gives, which keep the reference's sign past 90 deg; with --initial on both it is."""
    path = tmp_path / "square.xml"
    path.write_text(square_four_bar())
    run = screwkit("analyze", path, "--output", "link_4", "--actuators", "100", "-100")
    one_line_error(run, "the pose may lie on another assembly, past a singular configuration from the start",
                   "--initial on each actuator")
    run = screwkit("analyze", path, "--output", "link_4", "--initial", "hinge_1", "100", "--initial", "hinge_2",
                   "-100", "--json")
    assert run.returncode == 0, run.stderr
    assert json.loads(run.stdout)["configuration"]["hinge_1:hinge_1"]["value"] == pytest.approx(100.0)


def test_joints_renamed_and_motors_listed_the_other_way_name_the_renamed_chain_at_the_same_pose(tmp_path):
    text = square_four_bar()
    for old, new in (("hinge_1", "crank_pin"), ("hinge_2", "coupler_pin"), ("hinge_3", "rocker_pin")):
        text = text.replace(f'"{old}"', f'"{new}"')
    text = text.replace('<motor joint="crank_pin"/>\n    <motor joint="coupler_pin"/>',
                        '<motor joint="coupler_pin"/>\n    <motor joint="crank_pin"/>')
    path = tmp_path / "renamed.xml"
    path.write_text(text)
    mechanism = load(path, output="link_4")
    assert sorted(name.split(":")[1] for name in mechanism.actuator_names) == ["coupler_pin", "crank_pin"]
    (passed,) = singular_on_the_way(mechanism, np.radians([200.0]))
    assert passed[0] == "crank_pin" and np.degrees(passed[1][0]) == pytest.approx(90.0, abs=1e-3)
    run = screwkit("trajectory", path, "--output", "link_4", "--line", "0", "200", "--samples", "51", "--json")
    assert run.returncode == 0, run.stderr
    (event,) = json.loads(run.stdout)["events"]
    assert event["kind"] == "singular" and "chain crank_pin's joints" in event["reason"]
    assert event["start_m"] / json.loads(run.stdout)["length_m"] == pytest.approx(0.45, abs=1e-6)


SWEPT = np.array([-100.0, -60.0, 0.0, 45.0, 80.0, 89.0, 90.5, 91.0, 120.0, 200.0])


@pytest.mark.parametrize(("scale", "unit", "world"), [(1.0, None, "as written"), (1.0, None, "moved"),
                                                      (1e3, "mm", "moved"), (1e-3, None, "moved")])
def test_a_sweep_marks_the_poses_past_the_change_point(tmp_path, world, scale, unit):
    """The sweep's poses all lie on one line through the reference pose (phi from 0): the line is sampled once; the
    poses past 90 deg and past -90 deg, and only those, are marked, with the chain, whatever the unit and the world
    frame (each scale in the moved world, as written at 1 too). (At -90 deg the parallelogram lies flat: C on A,
    every joint on one line, the joints singular too.)"""
    path = tmp_path / "square.xml"
    path.write_text(square_four_bar(scale, WORLDS[world]))
    mechanism = load(path, output="link_4", length_unit=unit)
    dataset = sweep(mechanism, mechanism.home_pose, "phi", np.radians(SWEPT))
    assert list(dataset["singular_chain"].values) == ["hinge_1"]
    np.testing.assert_array_equal(dataset["past_singular"].values[:, 0], np.abs(SWEPT) > 90.0)


def test_the_ways_sampled_once_on_their_line_agree_with_each_way_sampled_alone(tmp_path):
    """singular_on_the_ways samples one line for poses on a line through the reference pose, and each way apart
    otherwise (analyze's single pose): both find the same poses past the change point, at the same place."""
    path = tmp_path / "square.xml"
    path.write_text(square_four_bar())
    mechanism = load(path, output="link_4")
    ((name, passed, where),) = singular_on_the_ways(mechanism, np.radians(SWEPT)[:, None])
    assert name == "hinge_1"
    np.testing.assert_array_equal(passed, np.abs(SWEPT) > 90.0)
    for degrees, past, at in zip(SWEPT, passed, where):
        alone = singular_on_the_way(mechanism, np.radians([degrees]))
        assert past == bool(alone)
        if past:
            assert np.degrees(at[0]) == pytest.approx(np.degrees(alone[0][1][0]), abs=1e-3)
            assert np.degrees(at[0]) == pytest.approx(np.sign(degrees) * 90.0, abs=1e-3)
        else:
            assert np.isnan(at).all()


def test_the_sweep_command_says_so_and_writes_the_mark(tmp_path):
    path = tmp_path / "square.xml"
    path.write_text(square_four_bar())
    run = screwkit("sweep", path, "--output", "link_4", "--sweep", "phi:0:200:20", "--out", tmp_path / "s.csv")
    assert run.returncode == 0, run.stderr
    (note,) = [line for line in run.stderr.splitlines() if line.startswith("NOTE:")]
    assert "at phi = 100, 120, 140, 160, 180 (5 of 10 values)" in note
    assert "chain hinge_1's joints are singular" in note and "--initial JOINT VALUE" in note
    rows = (tmp_path / "s.csv").read_text().splitlines()
    column = rows[0].split(",").index("past_singular[hinge_1]")
    assert [row.split(",")[column] for row in rows[1:]] == ["False"] * 5 + ["True"] * 5
    quiet = screwkit("sweep", path, "--output", "link_4", "--sweep", "phi:0:200:20", "--out", tmp_path / "q.csv",
                     "--quiet")
    assert quiet.returncode == 0 and quiet.stderr == "", quiet.stderr
    plain = screwkit("sweep", "planar_5rrr", "--phi", "0:40:10", "--out", tmp_path / "p.csv")
    assert plain.returncode == 0 and "NOTE:" not in plain.stderr  # (no chain keeps a sign: nothing to mark)
    assert "past_singular" not in (tmp_path / "p.csv").read_text().splitlines()[0]


def crank_rocker(crank: float, coupler: float, rocker: float) -> str:
    """A four-bar as Genesis writes it with the crank, coupler and rocker lengths given (ground 1, the pivots on the
    y axis): a Grashof crank-rocker for (1, 4, 3), whose chain is singular only where it is stretched out, at the edge
    of its workspace."""
    return genesis_four_bar(crank, coupler, rocker, 0.5, 0.5, 0.05, ("hinge_1",))


@pytest.mark.parametrize("stop", [6.0, 6.25, 6.5, 7.0])
def test_the_edge_of_the_workspace_is_not_taken_for_a_singular_configuration_on_the_way(tmp_path, stop):
    """Swept past the edge of its workspace, where the chain is stretched out (singular) and closes no more beyond:
    no pose is marked, whichever way the samples fall (a dip beside samples that never close again is the edge,
    not a configuration the way passes); the poses beyond are out of reach."""
    path = tmp_path / "crank_rocker.xml"
    path.write_text(crank_rocker(1.0, 4.0, 3.0))
    mechanism = load(path, output="link_4")
    assert mechanism.task_coordinates == ("y",)
    values = np.arange(4.0, stop, 0.25)
    dataset = sweep(mechanism, mechanism.home_pose, "y", values)
    assert not dataset["past_singular"].values.any()
    assert not dataset["reachable"].values[values >= 5.0].any() and dataset["reachable"].values[values < 4.9].all()
    assert all(singular_on_the_way(mechanism, np.array([y])) == [] for y in (5.0, stop))


def test_the_sweep_figure_hatches_the_poses_past_the_change_point(tmp_path):
    """Drawn, the poses past 90 deg (where F_O1 reads 0 on the folded assembly) are hatched in every panel, the
    legend naming the chain; the poses before are not."""
    from screwkit.plots import sweep_figure

    path = tmp_path / "square.xml"
    path.write_text(square_four_bar())
    mechanism = load(path, output="link_4")
    dataset = sweep(mechanism, mechanism.home_pose, "phi", np.radians(np.arange(0.0, 200.0, 10.0)))
    figure = sweep_figure(dataset)
    for ax in figure.axes:
        hatched = [patch for patch in ax.patches if patch.get_hatch() == "//"]
        assert len(hatched) == 1, ax.get_title("left")
        left, right = hatched[0].get_x(), hatched[0].get_x() + hatched[0].get_width()
        assert (left, right) == pytest.approx((95.0, 195.0))  # the poses 100 ... 190 deg, half a step either side
        labels = [text.get_text() for text in ax.get_legend().get_texts()]
        assert any(label.startswith("past a singular configuration of chain hinge_1") for label in labels)
