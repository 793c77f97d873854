"""A closed-loop graph whose hinges are parallel to the file's rounding only moves as drawn.

Published da Vinci PSM files close their parallelograms by hinges written ``-1 0 0`` by hand, while every exported
hinge reads ``-1 -0 -3e-06``: 3 microradians apart. Read exactly, a four-bar of hinges not quite parallel is a
spatial 4R loop, which does not move, and the graph reading refused the arm as rigid. The graph reading now makes
axes within the file's rounding parallel, as the serial reading does (``screwkit.io.graph_rounding``).

The linkage is ``test_idle_dyad``'s parallelogram with a dyad on its rocker (read as a graph), its tree hinges
written 3e-6 rad off the closing hinges (each written as two connects on its axis): its indices are those of the
linkage written exactly (ITI = LMTI = 1, CTI = |sin(BC, DC)| from MuJoCo's placement of the exact file's pins), in
metres, millimetres and a turned world, listed either way round, at the file's configuration and along a sweep.
"""

from __future__ import annotations

import numpy as np
import pytest
from test_idle_dyad import B, C, D, linkage

from helpers import MJCF_WORLDS, mjcf_variant, mujoco_closed, mujoco_rows, sine
from screwkit.io import ImportError_, read_closed_tree
from screwkit.io.closed_tree import closure_gaps
from screwkit.io.graph import graph_mechanism
from screwkit.io.graph_rounding import _joint_model, drawn_tree
from screwkit.studies.sweep import sweep

ROUNDED = 3e-6
"""How far the tree's hinge axes are written from the closing hinges' (rad), as in the published files."""


def rounded(scale=1.0, world=("0 0 0", "1 0 0 0"), tilt=ROUNDED, which=None, reverse=False) -> str:
    """:func:`test_idle_dyad.linkage` with a dyad on the rocker and the axes of the tree hinges ``which`` (all when
    None) written ``0 1 tilt`` (the closing connects stay along y)."""
    text = linkage(scale, world, dyad="rocker", reverse=reverse)
    for name in ("crank", "bpin", "rocker", "fpin", "gpin"):
        if which is None or name in which:
            text = text.replace(f'name="{name}" type="hinge" axis="0 1 0"',
                                f'name="{name}" type="hinge" axis="0 1 {tilt!r}"')
    return text


def _written(path, text: str):
    path.write_text(text)
    return path


def _indices(path, unit=None, output="coupler", initial=()):
    result = graph_mechanism(read_closed_tree(path, output=output, length_unit=unit, initial=initial)).indices()
    return float(result.iti), float(result.lmti), float(result.cti)


@pytest.mark.parametrize("variant", sorted(MJCF_WORLDS))
@pytest.mark.parametrize("which", [None, ("rocker",), ("crank", "gpin")])
@pytest.mark.parametrize("reverse", [False, True])
def test_hinges_parallel_to_the_rounding_read_as_the_exact_linkage(tmp_path, variant, which, reverse):
    exact, unit = mjcf_variant(tmp_path, "exact", variant, lambda s, w: linkage(s, w, dyad="rocker", reverse=reverse))
    model, data, anchor = mujoco_closed(exact)
    assert model.nv - np.linalg.matrix_rank(mujoco_rows(model, data), tol=1e-9) == 1  # the exact file moves
    rocker = model.body("rocker").id
    c = data.xpos[rocker] + data.xmat[rocker].reshape(3, 3) @ model.eq_data[model.equality("cpin0").id][:3]
    expected = sine(c - anchor["bpin"], c - anchor["rocker"])
    assert expected == pytest.approx(sine(C - B, C - D), abs=1e-12)
    path, _ = mjcf_variant(tmp_path, "rounded", variant, lambda s, w: rounded(s, w, which=which, reverse=reverse))
    assert _indices(path, unit) == pytest.approx((1.0, 1.0, expected), abs=1e-5)


def test_the_rounded_file_is_rigid_as_written(tmp_path):
    """The check that the test above tests something: MuJoCo's own constraint rows of the rounded file leave it no
    motion (its hinges closed by connects not quite on the tree hinges' axes)."""
    path = tmp_path / "rounded.xml"
    path.write_text(rounded())
    model, data, _ = mujoco_closed(path)
    singular = np.linalg.svd(mujoco_rows(model, data), compute_uv=False)
    assert model.nv - int(np.sum(singular > 1e-12 * singular[0])) == 0  # rigid as written, by a margin of rounding
    assert singular[model.nv - 1] < 1e-4 * singular[0]


def test_axes_apart_by_more_than_the_rounding_are_read_as_written(tmp_path):
    path = tmp_path / "tilted.xml"
    path.write_text(rounded(tilt=1e-3))
    with pytest.raises(ImportError_, match="cannot move"):
        graph_mechanism(read_closed_tree(path, output="coupler"))


def test_the_report_says_which_axis_turned(tmp_path):
    path = tmp_path / "rounded.xml"
    path.write_text(rounded(which=("rocker",)))
    notes = graph_mechanism(read_closed_tree(path, output="coupler")).report.notes
    said = [note for note in notes if note.startswith("joint axes that agree to the file's rounding")]
    assert len(said) == 1 and "rad" in said[0], notes
    exact = tmp_path / "exact.xml"
    exact.write_text(linkage(dyad="rocker"))
    notes = graph_mechanism(read_closed_tree(exact, output="coupler")).report.notes
    assert not [note for note in notes if "rounding written parallel" in note], notes


def test_the_turned_tree_keeps_every_frame_and_closure_where_the_assembly_put_them(tmp_path):
    """:func:`drawn_tree` turns axes about where the joints are: at the assembly, every joint frame is where it was
    (Pinocchio's forward kinematics of both models) and the closures stay closed."""
    import pinocchio as pin

    from screwkit.io.closed_tree import assemble

    path = tmp_path / "rounded.xml"
    path.write_text(rounded())
    tree = read_closed_tree(path, output="coupler")
    q, _ = assemble(tree)
    drawn = drawn_tree(tree, q)
    assert drawn is not tree and drawn.model is not tree.model
    frames = []
    for model in (tree.model, drawn.model):
        data = model.createData()
        pin.forwardKinematics(model, data, q)
        frames.append(np.array([data.oMi[j].homogeneous for j in range(model.njoints)]))
    assert np.max(np.abs(frames[0] - frames[1])) < 1e-12
    assert max(closure_gaps(drawn, q).values()) < 1e-9
    axes = [frames[1][j][:3, :3] @ np.asarray(drawn.model.joints[j].extract().axis)
            for j in range(1, drawn.model.njoints)]
    assert max(np.linalg.norm(np.cross(axes[0], axis)) for axis in axes) < 1e-12


@pytest.mark.parametrize("unbounded", [False, True])
def test_a_turned_joint_moves_about_its_new_axis(unbounded):
    """The joint models :func:`drawn_tree` writes (Pinocchio's bindings set an unbounded hinge's axis only through
    a file): the joint's twist in a one-joint model is the unit axis asked."""
    import pinocchio as pin

    axis = np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])
    model = pin.Model()
    written = pin.JointModelRUBZ() if unbounded else pin.JointModelRZ()
    joint = model.addJoint(0, written, pin.SE3.Identity(), "j")
    made = _joint_model(model.joints[joint], "revolute", axis)
    assert made.nq == (2 if unbounded else 1) and (made.id, made.idx_q, made.idx_v) == (joint, 0, 0)
    model.joints[joint] = made
    data = model.createData()
    q = pin.neutral(model)
    pin.computeJointJacobians(model, data, q)
    jacobian = np.asarray(pin.getJointJacobian(model, data, joint, pin.ReferenceFrame.WORLD)).reshape(6, -1)
    assert jacobian[3:, 0] == pytest.approx(axis, abs=1e-15)
    assert jacobian[:3, 0] == pytest.approx(np.zeros(3), abs=1e-15)


def test_the_rounded_linkage_sweeps_as_the_exact_one(tmp_path):
    exact, rounded_path = tmp_path / "exact.xml", tmp_path / "rounded.xml"
    exact.write_text(linkage(dyad="rocker"))
    rounded_path.write_text(rounded())
    sweeps = []
    for path in (exact, rounded_path):
        graph = graph_mechanism(read_closed_tree(path, output="coupler"))
        coordinate = graph.task_coordinates[0]
        home = graph.home_pose
        values = home[0] + np.linspace(-0.02, 0.02, 5)
        sweeps.append(sweep(graph, home, coordinate, values, as_dataset=False))
    for name in ("iti", "lmti", "cti"):
        first, second = (np.asarray(s.variables[name][1]) for s in sweeps)
        assert np.all(np.isfinite(first)) and np.max(np.abs(first - second)) < 1e-5, name


def _rocker_turned_by(angle_text: str) -> str:
    """The dyad linkage with the rocker's frame turned half a turn about x, written ``angle_text`` (rad), and every
    position in it and in the links it carries written as if that were pi exactly (``x -y -z``): the rocker, its
    dyad and their pins turn by the angle's rounding of pi about the rocker's pivot, its hinge and the line of its
    closing connects (in its frame) together, out of parallel with the crank's and the coupler's."""
    from xml.etree import ElementTree

    root = ElementTree.fromstring(linkage(dyad="rocker"))
    root.insert(0, ElementTree.Element("compiler", angle="radian"))

    def flipped(text: str) -> str:
        x, y, z = (float(v) for v in text.split())
        return f"{x!r} {-y!r} {-z!r}"

    rocker = next(body for body in root.iter("body") if body.get("name") == "rocker")
    rocker.set("euler", f"{angle_text} 0 0")
    carried = {body.get("name") for body in rocker.iter("body")}
    for body in rocker.iter("body"):
        if body is not rocker:
            body.set("pos", flipped(body.get("pos")))
    for connect in root.iter("connect"):
        if connect.get("body1") in carried:
            connect.set("anchor", flipped(connect.get("anchor")))
    return ElementTree.tostring(root, encoding="unicode")


def test_a_hinge_off_by_an_angle_written_rounded_is_made_parallel_as_the_serial_reading_makes_it(tmp_path):
    """A half turn written rounded (``3.14``) turns the rocker's hinge 1.6e-3 rad off the others: more than the
    rounding of numbers, and what the serial reading allows for angles written so (``screwkit.io.written_angles``);
    the graph reading allows it too, and says the angle. Written with pi to 17 digits, the file is the exact
    linkage; with ``3.1``, 0.042 rad off and no rounding of pi to one decimal, it is refused as rigid."""
    exact = tmp_path / "exact.xml"
    exact.write_text(linkage(dyad="rocker"))
    expected = _indices(exact)
    path = tmp_path / "half_turn.xml"
    path.write_text(_rocker_turned_by("3.14"))
    graph = graph_mechanism(read_closed_tree(path, output="coupler"))
    result = graph.indices()
    assert (float(result.iti), float(result.lmti), float(result.cti)) == pytest.approx(expected, abs=1e-5)
    [note] = [note for note in graph.report.notes if "rounding written parallel" in note]
    assert "3.14 for pi" in note, note
    assert _rocker_turned_by(repr(np.pi)) != linkage(dyad="rocker")
    assert _indices(_written(tmp_path / "pi.xml", _rocker_turned_by(repr(np.pi)))) == pytest.approx(expected, abs=1e-12)
    path.write_text(_rocker_turned_by("3.1"))  # (0.042 rad: not a rounding of pi to its written decimals)
    with pytest.raises(ImportError_, match="cannot move"):
        graph_mechanism(read_closed_tree(path, output="coupler"))


def _rsur(tilt: float = ROUNDED, swap: bool = False) -> str:
    """An R-S-U-R loop that moves as written whatever ``tilt`` (its crank's axis ``0 1 tilt``): the rocker closed to
    the world by a hinge written as two connects, the second with its bodies in the order ``swap`` says."""
    a, b, c, d, lift = (np.array(p, dtype=float) for p in ((0, 0, 0), (0.1, 0.05, 0.2), (0.35, 0.02, 0.25),
                                                           (0.4, 0, 0), (0, 0.04, 0)))

    def at(v) -> str:
        return " ".join(repr(float(x)) for x in v)

    second = (f'<connect name="h1" body1="rocker" body2="world" anchor="{at(d + lift - c)}"/>' if swap else
              f'<connect name="h1" body1="world" body2="rocker" anchor="{at(d + lift)}"/>')
    ball = '<geom type="sphere" size="0.01"/>'
    return ('<mujoco model="rsur"><option><flag contact="disable"/></option><worldbody>'
            f'<body name="crank" pos="{at(a)}"><joint name="crank" type="hinge" axis="0 1 {tilt!r}"/>{ball}'
            f'<body name="coupler" pos="{at(b - a)}"><joint name="b" type="ball"/>{ball}'
            f'<body name="rocker" pos="{at(c - b)}"><joint name="cx" type="hinge" axis="1 0 0"/>'
            f'<joint name="cz" type="hinge" axis="0 0 1"/>{ball}</body></body></body></worldbody><equality>'
            f'<connect name="h0" body1="world" body2="rocker" anchor="{at(d)}"/>{second}</equality>'
            '<actuator><motor name="m" joint="crank"/></actuator></mujoco>')


def test_a_hinge_whose_connects_name_their_bodies_in_either_order_reads_the_same(tmp_path):
    """Its second point is turned on each body in that body's own frame (turned in the other's, the loop no longer
    closed and the file, which moved as written, was refused)."""
    readings = []
    for swap in (False, True):
        path = _written(tmp_path / f"rsur_{swap}.xml", _rsur(swap=swap))
        model, data, _ = mujoco_closed(path)
        assert model.nv - np.linalg.matrix_rank(mujoco_rows(model, data), tol=1e-9) == 1  # it moves as written
        readings.append(_indices(path, output="rocker"))
    assert readings[0] == pytest.approx(readings[1], abs=1e-9)
    assert readings[0] == pytest.approx(_indices(_written(tmp_path / "exact.xml", _rsur(0.0)), output="rocker"),
                                        abs=1e-5)


@pytest.mark.parametrize("crank", [0.0, 20.0, -40.0])
def test_the_listing_and_the_joints_values_leave_the_rounded_reading_as_the_exact_one(tmp_path, crank):
    """Assembled with the crank away from zero (each turned joint's frame kept where the assembly puts it at its own
    value), listed either way round: the same indices to 1e-9, the exact linkage's to the rounding."""
    start = (("crank", crank),)
    readings = [_indices(_written(tmp_path / f"r_{reverse}.xml", rounded(reverse=reverse)), initial=start)
                for reverse in (False, True)]
    assert readings[0] == pytest.approx(readings[1], abs=1e-9)
    exact = _indices(_written(tmp_path / "exact.xml", linkage(dyad="rocker")), initial=start)
    assert readings[0] == pytest.approx(exact, abs=1e-6)


def test_unbounded_hinges_closed_by_gazebo_joints_are_turned(tmp_path):
    """The dyad linkage as a URDF of continuous joints (Pinocchio's unbounded hinges) written ``0 1 3e-06``, its loops
    Gazebo revolute joints along y: the CTI is the exact linkage's |sin(BC, DC)|."""
    f, g, e = D + (C - D) / 2, np.array([0.48, 0.0, 0.33]), np.array([0.25, 0.0, 0.35])

    def at(v) -> str:
        return " ".join(repr(float(x)) for x in v)

    inertial = '<inertial><mass value="0.1"/><inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/>' \
        '</inertial>'
    links = "".join(f'<link name="{n}">{inertial}</link>' for n in ("base", "crank", "coupler", "rocker", "l1", "l2"))
    joints = "".join(f'<joint name="{n}" type="continuous"><parent link="{p}"/><child link="{c}"/>'
                     f'<origin xyz="{at(x)}"/><axis xyz="0 1 {ROUNDED!r}"/></joint>'
                     for n, p, c, x in (("crank", "base", "crank", np.zeros(3)), ("bpin", "crank", "coupler", B),
                                        ("rocker", "base", "rocker", D), ("fpin", "rocker", "l1", f - D),
                                        ("gpin", "l1", "l2", g - f)))
    loops = "".join(f'<joint name="{n}" type="revolute"><parent>{p}</parent><child>coupler</child>'
                    f'<pose>{at(x - B)} 0 0 0</pose><axis><xyz>0 1 0</xyz></axis></joint>'
                    for n, p, x in (("cpin", "rocker", C), ("epin", "l2", e)))
    path = _written(tmp_path / "continuous.urdf", f'<robot name="para">{links}{joints}<gazebo>{loops}</gazebo>'
                    '<transmission name="t"><type>transmission_interface/SimpleTransmission</type><joint name="crank">'
                    '<hardwareInterface>EffortJointInterface</hardwareInterface></joint><actuator name="m">'
                    '<mechanicalReduction>1</mechanicalReduction></actuator></transmission></robot>')
    tree = read_closed_tree(path, output="coupler")
    assert {tree.model.joints[j].shortname() for j in range(1, tree.model.njoints)} == {
        "JointModelRevoluteUnboundedUnaligned"}
    assert _indices(path) == pytest.approx((1.0, 1.0, sine(C - B, C - D)), abs=1e-5)


@pytest.mark.parametrize("scale", [1e-3, 1e3])
def test_the_rounded_linkage_reads_as_the_exact_one_at_any_size(tmp_path, scale):
    """Every length times 1e-3 or 1e3, read in metres: the axes' rounding is an angle, the same at any size."""
    exact = _indices(_written(tmp_path / "exact.xml", linkage(scale, dyad="rocker")))
    assert exact == pytest.approx((1.0, 1.0, sine(C - B, C - D)), abs=1e-9)
    assert _indices(_written(tmp_path / "rounded.xml", rounded(scale))) == pytest.approx(exact, abs=1e-5)
