"""Hinges a file closes by two ball closures a few millimetres apart, written rounded, read along the hinges they are
drawn parallel to.

An MJCF file (a CAD exporter's, for MuJoCo) closes a hinge by two ``<connect>``\\ s on its axis. Written to 6
decimals, two points 6 mm apart give an axis known to sqrt(3) x 1e-6 / 6e-3 = 2.9e-4 rad, thirty times the
rounding a joint's axis written as a direction is held to. ``test_compound_legs``'s parallelogram Delta written so,
turned in the world, read **1 DOF and LMTI 0.9500 where the exact file reads 2 DOF and 0.9938**, with only a note
that the DOF was decided at the file's rounding: each closing hinge, 1.7e-5 to 1.2e-4 rad off its parallelogram's
other hinges, made the four-bar a spatial 4R loop. Such a hinge is now written along the hinges parallel to it
within what its points' rounding allows (``screwkit.io.graph_rounding.drawn_pairs``), in the serial and the graph
readings alike; a pair further off than its rounding can give is read as written.

Every check is against the exact drawing: the pressure angles of the exact tree (Gepetto's form of the same Delta)
closed by Pinocchio at the actuator values screwkit solved, and for the graph reading the parallelogram's closed-form
sine, which MuJoCo's own placement of the exact file gives (``test_graph_rounding``).
"""

from __future__ import annotations

import json
import re
from decimal import Decimal

import numpy as np
import pytest
from test_compound_legs import delta_gepetto, delta_points, poses_near_home, tree_pressure_angles_at, write
from test_idle_dyad import B, C, D, linkage
from test_rounded_convention import rounded

from helpers import mujoco_closed, mujoco_rows, random_rotation, screwkit, sine
from screwkit.io import ImportError_, read_closed_tree
from screwkit.io.graph import graph_mechanism
from screwkit.io.loader import converted_mechanism, load
from screwkit.studies.poses import indices_at_poses

FOLLOWED = "hinges closed by two ball closures whose axis the file's rounding knows only over their points' spacing"


def delta_connects(rotation: np.ndarray, size: float, spacing: float) -> str:
    """``test_compound_legs``'s parallelogram Delta in MJCF, turned by ``rotation``, each closing hinge written as two
    connects on its axis ``spacing`` times ``size`` apart (every number with all its digits)."""
    points = {name: rotation @ (size * np.append(point, 0.0)) for name, point in delta_points().items()}
    axis = rotation @ np.array([0.0, 0.0, 1.0])

    def text(vector) -> str:
        return " ".join(repr(float(v)) for v in vector)

    def body(name, position, joint, inner="") -> str:
        return (f'<body name="{name}" pos="{text(position)}"><joint name="{joint}" type="hinge" axis="{text(axis)}"/>'
                f'<geom type="sphere" size="0.005"/>{inner}</body>')

    effector = body("eff", points["E0"] - points["A1"], "free2_rod1",
                    f'<site name="effector" pos="{text(points["effector"] - points["E0"])}"/>')
    rod1 = body("a1", points["A0"], "mot1_rod1", body("a2", points["A1"] - points["A0"], "free1_rod1", effector))
    rod2 = body("b1", points["B0"], "mot1_rod2", body("b2", points["B1"] - points["B0"], "free1_rod2"))
    rod3 = body("c1", points["C0"], "free1_rod3", body("c2", points["C1"] - points["C0"], "free2_rod3",
                                                         body("c3", points["P"] - points["C1"], "free3_rod3")))
    origin = {"b2": points["B1"], "c2": points["C1"], "c3": points["P"]}  # (the bodies' frames keep the world's axes)
    connects = [f'<connect name="c{k}{j}" body1="{first}" body2="{second}" '
                f'anchor="{text(points[pin] - origin[first] + off * axis)}"/>'
                for k, (first, second, pin) in enumerate([("b2", "eff", "E0"), ("c2", "b2", "B1"), ("c3", "eff", "E1")])
                for j, off in enumerate((0.0, spacing * size))]
    return ('<mujoco model="delta"><compiler angle="radian"/><worldbody>' + rod1 + rod2 + rod3 + '</worldbody>'
            '<equality>' + "".join(connects) + '</equality><actuator><motor name="mot1_rod1" joint="mot1_rod1"/>'
            '<motor name="mot1_rod2" joint="mot1_rod2"/></actuator></mujoco>')


def against_the_exact_tree(mechanism, exact, poses) -> float:
    """The largest difference between the indices of ``mechanism`` at ``poses`` and the pressure angles of the exact
    tree of ``exact`` (URDF + yaml) closed by Pinocchio at the same actuator values."""
    result, angles = tree_pressure_angles_at(mechanism, exact, poses)
    names = [name.split(":")[-1] for name in mechanism.actuator_names]
    order = [names.index("mot1_rod1"), names.index("mot1_rod2")]
    return max(max(float(np.max(np.abs(result.iti_actuators[k][order] - iti))), abs(float(result.lmti[k]) - oti))
               for k, (iti, oti) in enumerate(angles))


@pytest.mark.parametrize(("seed", "size", "spacing"), [(2, 0.3, 0.02), (4, 0.5, 0.01), (1, 0.05, 0.1)])
def test_a_rounded_delta_closed_by_connect_pairs_has_the_exact_tree_s_dof_and_pressure_angles(tmp_path, seed, size,
                                                                                                spacing):
    """Read 1 DOF before (a silently wrong LMTI: 0.9500 against 0.9938 for the first); now 2 DOF, planar, within
    the rounding over the parallelograms' shortest sides of the exact tree at poses about its home (2e-5 / size, as
    ``test_rounded_compound``), the note saying which hinge turned and how far its axis was known."""
    rotation = random_rotation(np.random.default_rng(seed))
    (tmp_path / "exact").mkdir()
    exact = write(tmp_path / "exact", *delta_gepetto(rotation, size))
    path = tmp_path / "delta.xml"
    path.write_text(rounded(delta_connects(rotation, size, spacing), 6))
    _, report, mechanism = converted_mechanism(path, output="effector")
    assert mechanism.dof == 2 and mechanism.is_planar, mechanism.assembly_notes
    [note] = [note for note in report.notes if note.startswith(FOLLOWED)]
    assert "(3 hinges;" in note
    poses = poses_near_home(load(exact), spread=0.03 * size)
    assert against_the_exact_tree(mechanism, exact, poses) < 2e-5 / size


def only_anchors_rounded(text: str) -> str:
    """The MJCF text with its connects' anchors written to 6 decimals and every other number with all its digits."""
    return re.sub(r'anchor="([^"]*)"', lambda m: 'anchor="' + rounded(m.group(1), 6) + '"', text)


def with_extra_digits(text: str) -> str:
    """The rounded MJCF text with a comment, a visual geom and an inertial written with ten decimals."""
    extra = '<geom type="sphere" size="0.005" pos="0.0123456789 0 0"/><inertial pos="0.0000123456 0 0" mass="1" ' \
        'diaginertia="1 1 1"/>'
    return text.replace('<geom type="sphere" size="0.005"/>', extra, 1).replace(
        "<worldbody>", '<worldbody><!-- drawn at pos="0.123456789 0 0" -->', 1)


@pytest.mark.parametrize("variant", [only_anchors_rounded, with_extra_digits])
def test_a_pair_is_known_to_the_numbers_that_place_it(tmp_path, variant):
    """The step of a pair's rounding is its anchors' (bodies written with all their digits, the anchors to 6
    decimals), and numbers that place no joint (a comment, a geom's and an inertial's positions written with ten
    decimals) do not make the file finer: read 1 DOF before, now 2 DOF within 2e-5 / size of the exact tree."""
    rotation = random_rotation(np.random.default_rng(2))
    (tmp_path / "exact").mkdir()
    exact = write(tmp_path / "exact", *delta_gepetto(rotation, 0.3))
    text = delta_connects(rotation, 0.3, 0.02)
    path = tmp_path / "delta.xml"
    path.write_text(variant(text if variant is only_anchors_rounded else rounded(text, 6)))
    assert variant(text) != text
    _, report, mechanism = converted_mechanism(path, output="effector")
    assert mechanism.dof == 2 and any(note.startswith(FOLLOWED) for note in report.notes), report.notes
    assert against_the_exact_tree(mechanism, exact, poses_near_home(load(exact), spread=0.009)) < 2e-5 / 0.3


def shifted(text: str, digits: int) -> str:
    """The MJCF text with every length (positions, anchors) times 10 ** ``digits``, written with as many decimals
    fewer (in decimal: the same numbers, not binary products)."""
    return re.sub(r'(pos|anchor)="([^"]*)"', lambda m: f'{m.group(1)}="' + " ".join(
        str((Decimal(v) * Decimal(10) ** digits).normalize()) for v in m.group(2).split()) + '"', text)


def test_the_connect_pair_delta_reads_alike_in_any_unit_size_and_order(tmp_path):
    """The same rounded drawing in millimetres (read with the unit given), at a thousandth and a thousand times its
    size (poses scaled with it), with each pair's two connects and the pairs listed the other way, hung in a turned and
    moved world, and with its motors renamed: the same note and the same indices per actuator, to 1e-9."""
    text = rounded(delta_connects(random_rotation(np.random.default_rng(2)), 0.3, 0.02), 6)
    connects = re.findall(r"<connect [^>]*/>", text)
    swapped = text.replace("".join(connects), "".join(reversed(connects)))  # (each pair's two, and the pairs)
    assert swapped != text and sorted(re.findall(r"<connect [^>]*/>", swapped)) == sorted(connects)
    moved = text.replace("<worldbody>", '<worldbody><body name="held" pos="0.4 -1.3 2.1" euler="0.7 -1.1 2.3">', 1
                         ).replace("</worldbody>", "</body></worldbody>", 1)
    renamed = text.replace('"mot1_rod1"', '"drive_a"').replace('"mot1_rod2"', '"drive_b"')
    variants = {"m": (text, None, 1.0), "mm": (shifted(text, 3), "mm", 1.0), "small": (shifted(text, -3), None, 1e-3),
                "large": (shifted(text, 3), None, 1e3), "swapped": (swapped, None, 1.0), "world": (moved, None, 1.0),
                "renamed": (renamed, None, 1.0)}
    read, said = {}, {}
    for name, (variant, unit, factor) in variants.items():
        path = tmp_path / f"{name}.xml"
        path.write_text(variant)
        _, report, mechanism = converted_mechanism(path, output="effector", length_unit=unit)
        poses = poses_near_home(mechanism, spread=0.009 * factor)
        result = indices_at_poses(mechanism, poses, detail=True)
        home = indices_at_poses(mechanism, mechanism.home_pose[None], detail=True)
        order = np.argsort(mechanism.actuator_names)
        read[name] = (home.iti_actuators[:, order], home.lmti, mechanism.home_pose / factor,
                      result.iti_actuators[:, order], result.lmti)
        [said[name]] = [note for note in report.notes if note.startswith(FOLLOWED)]
    assert len(set(said.values())) == 1, said
    for name in ("mm", "small", "large", "swapped", "world", "renamed"):  # (in a moved world, its home only: its
        for mine, theirs in list(zip(read[name], read["m"]))[:2 if name == "world" else None]:  # task axes turn)
            np.testing.assert_allclose(mine, theirs, atol=1e-9, rtol=0, err_msg=name)


def nudged_linkage(steps: int) -> str:
    """``test_idle_dyad``'s parallelogram (read as a graph: a dyad on its rocker) written to 6 decimals, its closing
    hinge's two connects 4 mm apart, the second moved ``steps`` of the last decimal across the hinge."""
    text = rounded(linkage(1.0, dyad="rocker", spacing=0.004), 6)
    found = re.search(r'<connect name="cpin1"[^>]*anchor="([^"]*)"', text)
    x, y, z = (Decimal(v) for v in found.group(1).split())
    moved = f"{x + Decimal(steps) / 10 ** 6} {y} {z}"
    return text.replace(found.group(0), found.group(0).replace(found.group(1), moved))


def test_the_graph_reading_takes_a_connect_pair_along_its_hinges_within_its_rounding_only(tmp_path):
    """One step of the last decimal across a hinge whose two points are 4 mm apart (2.5e-4 rad, within the 4.3e-4 its
    rounding allows): as written MuJoCo finds the linkage rigid, and the graph reading refused it; it now gives the
    parallelogram's indices (ITI = LMTI = 1, CTI the closed-form sine to the rounding). Two steps (5e-4 rad, more
    than rounding can give) are read as written: rigid, refused."""
    path = tmp_path / "one.xml"
    path.write_text(nudged_linkage(1))
    model, data, _ = mujoco_closed(path)
    singular = np.linalg.svd(mujoco_rows(model, data), compute_uv=False)
    assert model.nv - int(np.sum(singular > 1e-12 * singular[0])) == 0  # rigid as written
    graph = graph_mechanism(read_closed_tree(path, output="coupler"))
    result = graph.indices()
    assert (float(result.iti), float(result.lmti)) == pytest.approx((1.0, 1.0), abs=1e-9)
    assert float(result.cti) == pytest.approx(sine(C - B, C - D), abs=1e-5)
    assert any(note.startswith(FOLLOWED) for note in graph.report.notes)
    path.write_text(nudged_linkage(2))
    with pytest.raises(ImportError_, match="cannot move"):
        graph_mechanism(read_closed_tree(path, output="coupler"))


def test_the_command_reads_the_connect_pair_delta_with_two_dof_and_says_so(tmp_path):
    """``screwkit analyze`` of the rounded Delta (6-mm pairs): two task coordinates, the note, and the LMTI of the
    library's reading at the same pose."""
    path = tmp_path / "delta.xml"
    path.write_text(rounded(delta_connects(random_rotation(np.random.default_rng(2)), 0.3, 0.02), 6))
    _, _, mechanism = converted_mechanism(path, output="effector")
    pose = mechanism.home_pose
    run = screwkit("analyze", path, "--output", "effector", "--pose", *(repr(float(v)) for v in pose), "--json")
    assert run.returncode == 0, run.stderr
    assert FOLLOWED in run.stdout + run.stderr
    read = json.loads(run.stdout)
    assert len(pose) == 2
    assert abs(read["lmti"] - float(indices_at_poses(mechanism, pose[None]).lmti[0])) < 1e-12
