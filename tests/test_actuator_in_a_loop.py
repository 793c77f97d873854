"""An excavator's bucket linkage: the cylinder drives a loop that closes on the base, and that loop drives the rest.

The cylinder is pivoted on the base (the arm) at I and pushes the H link at J; the H link is pinned to the base at K,
and carries at J' the side link that turns the bucket, pinned to the base at M, at L (a published MuJoCo excavator,
KennyVilella/excavator_simulator_mujoco, writes its bucket so). Read as a graph with the bucket as output, the
cylinder's leg (barrel, rod, H link, side link) gave ITI = |cos| of the side link to the cylinder, two bodies that
never push on each other (0.6886 here; the published file read 0.9570 where the cylinder's own pressure angle is
0.6987): the cylinder's twist lies in the leg's twist system (a planar leg allows every planar twist), which is all
that was checked. Now an actuated joint must move with its leg's other joints held (``drives_rigidly``): this one
cannot, and the leg is refused. The H link taken as the output reads the cylinder's own transmission: ITI 1 (the
force along the cylinder) and OTI |sin(IJ, KJ)|, here from MuJoCo's placement of the joints, in m, mm and a turned
world.
"""

from __future__ import annotations

import json

import mujoco
import numpy as np
import pytest

from helpers import MJCF_WORLDS, mjcf_variant, mujoco_closed, mujoco_rows, one_line_error, screwkit, sine
from screwkit.io import ImportError_, read_closed_tree
from screwkit.io.graph import graph_mechanism
from screwkit.io.loader import load
from screwkit.studies import indices_at_pose

I, J, K = np.array([0.0, 0.0, 0.0]), np.array([0.25, 0.17, 0.0]), np.array([0.3, 0.05, 0.0])
JP, M, L = np.array([0.32, 0.2, 0.0]), np.array([0.5, -0.1, 0.0]), np.array([0.55, 0.15, 0.0])
"""The cylinder's pivot I, its rod's end J on the H link, the H link's pivot K, the side link's pin J' on the H link,
the bucket's pivot M, the side link's pin L on the bucket (the plane z = 0, every hinge along z)."""


def bucket_linkage(scale: float = 1.0, world=("0 0 0", "1 0 0 0"), reverse: bool = False) -> str:
    """The linkage's MJCF text, every length times ``scale``, its base placed by ``world`` (``pos``, ``quat``);
    ``reverse``: the bucket's branch and the second closure written first."""
    def at(point) -> str:
        return " ".join(repr(float(v) * scale) for v in point)

    ball = f'<geom type="sphere" size="{0.005 * scale!r}"/>'
    ram = (J - I) / np.linalg.norm(J - I)
    cylinder = (f'<body name="barrel" pos="{at(I)}"><joint name="pivot" type="hinge" axis="0 0 1"/>{ball}'
                f'<body name="rod"><joint name="ram" type="slide" axis="{" ".join(repr(float(v)) for v in ram)}"/>'
                f'{ball}<body name="hlink" pos="{at(J - I)}"><joint name="hpin" type="hinge" axis="0 0 1"/>{ball}'
                '</body></body></body>')
    bucket = (f'<body name="bucket" pos="{at(M)}"><joint name="bpivot" type="hinge" axis="0 0 1"/>{ball}'
              f'<body name="side" pos="{at(L - M)}"><joint name="sidepin" type="hinge" axis="0 0 1"/>{ball}'
              '</body></body>')
    closures = [f'<connect name="hpivot" body1="hlink" body2="base" anchor="{at(K - J)}"/>',
                f'<connect name="side_end" body1="side" body2="hlink" anchor="{at(JP - L)}"/>']
    branches = [cylinder, bucket]
    if reverse:
        branches, closures = branches[::-1], closures[::-1]
    return (f'<mujoco model="bucket_linkage"><worldbody><body name="base" pos="{world[0]}" quat="{world[1]}">'
            + "".join(branches) + '</body></worldbody><equality>' + "".join(closures)
            + '</equality><actuator><motor name="m" joint="ram"/></actuator></mujoco>')


@pytest.fixture(params=sorted(MJCF_WORLDS))
def linkage(request, tmp_path):
    return mjcf_variant(tmp_path, "bucket", request.param, bucket_linkage)



def _mujoco_points(path) -> dict[str, np.ndarray]:
    """I, J and K as MuJoCo places them at the file's configuration (closed: its connects' residuals are zero)."""
    model, data, anchor = mujoco_closed(path)
    assert model.nv - np.linalg.matrix_rank(mujoco_rows(model, data), tol=1e-9) == 1  # one motion
    hlink = model.body("hlink").id
    pivot = data.xpos[hlink] + data.xmat[hlink].reshape(3, 3) @ model.eq_data[0][:3]  # the connect's point on it
    return {"I": anchor["pivot"], "J": anchor["hpin"], "K": pivot}


def test_the_bucket_is_refused_as_driven_through_a_loop(linkage):
    path, unit = linkage
    with pytest.raises(ImportError_, match="'ram' moves inside a loop of leg 'barrel' \\(with the other joints of "
                                           "its path to the platform held it cannot move"):
        graph_mechanism(read_closed_tree(path, output="bucket", length_unit=unit))


def test_the_h_link_reads_the_cylinders_own_transmission(linkage):
    path, unit = linkage
    mechanism = load(path, output="hlink", length_unit=unit)  # (serial legs: the H link's pivot, the cylinder)
    result = indices_at_pose(mechanism, mechanism.home_pose)
    points = _mujoco_points(path)
    assert float(result.iti) == pytest.approx(1.0, abs=1e-9)  # the force along the cylinder, on its own slide
    assert float(result.lmti) == pytest.approx(sine(points["J"] - points["I"], points["J"] - points["K"]), abs=1e-9)
    assert sine(J - I, J - K) == pytest.approx(0.97959, abs=1e-5)


def test_the_reading_does_not_turn_on_the_order_the_file_lists_things_in(tmp_path):
    path = tmp_path / "reversed.xml"
    path.write_text(bucket_linkage(reverse=True))
    with pytest.raises(ImportError_, match="'ram' moves inside a loop"):
        graph_mechanism(read_closed_tree(path, output="bucket"))
    mechanism = load(path, output="hlink")
    result = indices_at_pose(mechanism, mechanism.home_pose)
    assert (float(result.iti), float(result.lmti)) == pytest.approx((1.0, sine(J - I, J - K)), abs=1e-9)


def test_the_command_refuses_the_bucket_and_reads_the_h_link(tmp_path):
    path = tmp_path / "bucket.xml"
    path.write_text(bucket_linkage())
    one_line_error(screwkit("analyze", path, "--output", "bucket"), "--output")
    read = screwkit("analyze", path, "--output", "hlink", "--json")
    assert read.returncode == 0, read.stderr
    result = json.loads(read.stdout)
    assert (result["iti"], result["lmti"]) == pytest.approx((1.0, sine(J - I, J - K)), abs=1e-9)


def doubled_crank(distal_on: str) -> str:
    """A five-bar whose second crank A2-B2 is doubled by a parallelogram (coupler B2-B3, crank A3-B3 on the base), its
    distal link B2-P hinged on the crank itself (``distal_on="crank"``) or on the coupler, at B2 too."""
    def at(point) -> str:
        return " ".join(repr(float(v)) for v in point)

    ball = '<geom type="sphere" size="0.005"/>'
    a2, b2, a3, b3, p, b1 = (np.array(v, dtype=float) for v in ((0.2, 0, 0), (0.17, 0.1, 0), (0.25, 0, 0),
                                                                  (0.22, 0.1, 0), (0.1, 0.2, 0), (0.03, 0.1, 0)))
    distal = f'<body name="distal2" pos="{at(b2 - a2)}"><joint name="p2" type="hinge" axis="0 0 1"/>{ball}</body>'
    inner = f'<body name="distal2"><joint name="p2" type="hinge" axis="0 0 1"/>{ball}</body>'
    coupler = (f'<body name="coupler" pos="{at(b2 - a2)}"><joint name="c2" type="hinge" axis="0 0 1"/>{ball}'
               + (inner if distal_on == "coupler" else "") + "</body>")
    return (f'<mujoco model="doubled"><worldbody><body name="base">'
            f'<body name="crank1"><joint name="m1" type="hinge" axis="0 0 1"/>{ball}'
            f'<body name="distal1" pos="{at(b1)}"><joint name="p1" type="hinge" axis="0 0 1"/>{ball}</body></body>'
            f'<body name="crank2" pos="{at(a2)}"><joint name="m2" type="hinge" axis="0 0 1"/>{ball}{coupler}'
            + (distal if distal_on == "crank" else "") + '</body>'
            f'<body name="crank3" pos="{at(a3)}"><joint name="m3" type="hinge" axis="0 0 1"/>{ball}</body>'
            '</body></worldbody><equality>'
            f'<connect name="para" body1="crank3" body2="coupler" anchor="{at(b3 - a3)}"/>'
            f'<connect name="pin" body1="distal2" body2="distal1" anchor="{at(p - b2)}"/>'
            '</equality><actuator><motor joint="m1"/><motor joint="m2"/></actuator></mujoco>')


def test_a_crank_doubled_by_a_parallelogram_off_its_path_drives_its_leg(tmp_path):
    """The parallelogram off the crank's path to the platform follows it and carries none of the load (its coupler
    and third crank are two-force members that cannot balance each other at B3): the leg's input is the crank's,
    ITI = |sin(A2B2, B2P)|, the textbook five-bar's, as before. Drawn with the distal link on the coupler, at the
    same pin B2, the loop runs through the crank's path and the leg is refused (where the coupler carries the distal
    link elsewhere than the crank's tip, the load is shared and the old reading was wrong)."""
    a2, b2, p = np.array([0.2, 0.0, 0.0]), np.array([0.17, 0.1, 0.0]), np.array([0.1, 0.2, 0.0])
    path = tmp_path / "doubled.xml"
    path.write_text(doubled_crank("crank"))
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    assert model.nv - np.linalg.matrix_rank(mujoco_rows(model, data), tol=1e-9) == 2  # closed, 2 DOF
    result = graph_mechanism(read_closed_tree(path, output="distal1")).indices()
    assert float(np.ravel(result.iti_actuators)[1]) == pytest.approx(sine(b2 - a2, p - b2), abs=1e-9)
    path.write_text(doubled_crank("coupler"))
    with pytest.raises(ImportError_, match="'m2' moves inside a loop"):
        graph_mechanism(read_closed_tree(path, output="distal1"))


def test_the_command_reads_the_doubled_crank(tmp_path):
    """The serial reading cannot write that leg ("its twists leave the plane of motion") and refused it; it now hands
    it to the graph reading, which reads it: ITI = |sin(A2B2, B2P)| for the doubled crank. Drawn with the distal link
    on the coupler, the graph's reason is given, not the serial writer's (the leg's balls leave the plane, the
    mechanism does not)."""
    a2, b2, p = np.array([0.2, 0.0, 0.0]), np.array([0.17, 0.1, 0.0]), np.array([0.1, 0.2, 0.0])
    path = tmp_path / "doubled.xml"
    path.write_text(doubled_crank("crank"))
    read = screwkit("analyze", path, "--output", "distal1", "--json")
    assert read.returncode == 0, read.stderr
    result = json.loads(read.stdout)
    assert result["iti_actuators"]["crank2:m2"] == pytest.approx(sine(b2 - a2, p - b2), abs=1e-9)
    path.write_text(doubled_crank("coupler"))
    one_line_error(screwkit("analyze", path, "--output", "distal1"), "'m2' moves inside a loop of leg 'crank2'")


def test_the_h_link_read_as_a_graph_equals_its_serial_reading(linkage):
    """The H link is pinned to the base by a closure alone (no joint of its own between): a passive leg of no joint,
    whose twist system is the pin's. The graph reading left it out (it joins no body of a leg) and refused the H
    link as moving with the cylinder locked, "2 motions"; it reads the serial reading's numbers now."""
    path, unit = linkage
    graph = graph_mechanism(read_closed_tree(path, output="hlink", length_unit=unit)).indices()
    points = _mujoco_points(path)
    assert float(graph.iti) == pytest.approx(1.0, abs=1e-9)
    assert float(graph.lmti) == pytest.approx(sine(points["J"] - points["I"], points["J"] - points["K"]), abs=1e-9)


def bucket_along_path(scale: float = 1.0, world=("0 0 0", "1 0 0 0"), reverse: bool = False) -> str:
    """The same linkage written along the bucket's path: barrel, rod, H link, side link, bucket, one chain from the
    base; the H link's pivot K and the bucket's pivot M closed on the base (``reverse``: the bucket's first)."""
    def at(point) -> str:
        return " ".join(repr(float(v) * scale) for v in point)

    ball = f'<geom type="sphere" size="{0.005 * scale!r}"/>'
    ram = " ".join(repr(float(v)) for v in (J - I) / np.linalg.norm(J - I))
    hinge = '<joint name="{}" type="hinge" axis="0 0 1"/>' + ball
    closures = [f'<connect name="hpivot" body1="hlink" body2="base" anchor="{at(K - J)}"/>',
                f'<connect name="bpivot" body1="bucket" body2="base" anchor="{at(M - L)}"/>']
    return (f'<mujoco model="bucket_along_path"><worldbody><body name="base" pos="{world[0]}" quat="{world[1]}">'
            f'<body name="barrel" pos="{at(I)}">{hinge.format("pivot")}'
            f'<body name="rod"><joint name="ram" type="slide" axis="{ram}"/>{ball}'
            f'<body name="hlink" pos="{at(J - I)}">{hinge.format("hpin")}'
            f'<body name="side" pos="{at(JP - J)}">{hinge.format("sidepin")}'
            f'<body name="bucket" pos="{at(L - JP)}">{hinge.format("lpin")}'
            '</body></body></body></body></body></body></worldbody><equality>'
            + "".join(closures[::-1] if reverse else closures)
            + '</equality><actuator><motor name="m" joint="ram"/></actuator></mujoco>')


@pytest.mark.parametrize("variant", sorted(MJCF_WORLDS))
def test_the_bucket_on_its_own_path_is_refused_as_driven_through_a_loop(tmp_path, variant):
    """Written along the bucket's path, the cylinder's leg is the platform's own path (its spine), which
    ``drives_rigidly`` did not check: the bucket was refused as moving with the cylinder locked (the bucket's pivot,
    a closure alone, was no leg) and the command called the path "a motion no actuator drives". Now the cylinder is
    refused as moving inside a loop, as in the linkage's other drawing, and the H link reads its transmission."""
    path, unit = mjcf_variant(tmp_path, "along", variant, bucket_along_path)
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    assert model.nv - np.linalg.matrix_rank(mujoco_rows(model, data), tol=1e-9) == 1  # MuJoCo: one motion
    with pytest.raises(ImportError_, match="'ram' moves inside a loop of leg 'barrel' \\(with the other joints of "
                                           "its path to the platform held it cannot move"):
        graph_mechanism(read_closed_tree(path, output="bucket", length_unit=unit))
    result = graph_mechanism(read_closed_tree(path, output="hlink", length_unit=unit)).indices()  # (bucket beyond)
    points = _mujoco_points(path)
    assert (float(result.iti), float(result.lmti)) == pytest.approx(
        (1.0, sine(points["J"] - points["I"], points["J"] - points["K"])), abs=1e-9)


def test_the_command_refuses_the_bucket_on_its_own_path_and_reads_its_h_link(tmp_path):
    path = tmp_path / "along.xml"
    path.write_text(bucket_along_path())
    one_line_error(screwkit("analyze", path, "--output", "bucket"), "'ram' moves inside a loop", "--output")
    read = screwkit("analyze", path, "--output", "hlink", "--json")
    assert read.returncode == 0, read.stderr
    result = json.loads(read.stdout)
    assert (result["iti"], result["lmti"]) == pytest.approx((1.0, sine(J - I, J - K)), abs=1e-9)


def test_the_bucket_on_its_own_path_reads_the_same_with_its_closures_listed_the_other_way_round(tmp_path):
    path = tmp_path / "reversed.xml"
    path.write_text(bucket_along_path(reverse=True))
    with pytest.raises(ImportError_, match="'ram' moves inside a loop of leg 'barrel'"):
        graph_mechanism(read_closed_tree(path, output="bucket"))
    result = graph_mechanism(read_closed_tree(path, output="hlink")).indices()
    assert (float(result.iti), float(result.lmti)) == pytest.approx((1.0, sine(J - I, J - K)), abs=1e-9)
