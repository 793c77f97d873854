"""Invariance under relabelling: every index is a property of the mechanism, not of how its legs are listed.

Permuting the legs (chains) of a mechanism, the actuators within a leg, or renaming the legs changes no
index -- ITI, LMTI, every F_Oj and F_IOj, the CTI and every F_Cj, the instantaneous DOF -- and the
per-actuator and per-set values, the worst faults (with their ties) and the limiting actuators follow the
names; so do the average-case F_Oj (equal weights, and weighted by failure probabilities that follow the
actuators' names). Checked at two levels:

* the core (:func:`screwkit.indices.analysis.analyze` on chain screws), where the chains are analysed in the
  order given: every bundled mechanism and random designs of every family (planar n-RRR, UPS and RSS
  hexapods, Deltas, 3-PRS + UPS), under random permutations of the chains and of the actuators within a
  chain, and random renamings, to 1e-12;
* the file: the same URDF with its ``<loop>`` and ``<transmission>`` elements listed in another order
  gives the same report, and with its legs renamed the same report under the new names.

Values are compared by name, never by position.
"""

from __future__ import annotations

import json
import re
import xml.etree.ElementTree as ElementTree
from itertools import combinations

import numpy as np
import pytest

from helpers import random_reachable_poses, screwkit
from screwkit.closure import chain_screws, solve
from screwkit.indices.analysis import analyze
from screwkit.indices.average import mean_remaining_lmti
from screwkit.io.loader import bundled_names, bundled_path, load, load_text
from screwkit.screw.chain_screws import ChainScrews
from screwkit.studies.design.families import family
from screwkit.studies.poses import analyze_solution, output_points

TOLERANCE = 1e-12
ACTUATOR_OTI_TOLERANCE = 1e-11
"""Per-actuator OTIs inside a submechanism (a detail, not one of the indices): the determinant and the cofactor
vector behind them are summed in the order of the actuators, and for the two-arm system's ill-conditioned
6 x 6 wrench matrices that rounding moves a non-limiting actuator's OTI by up to 3.2e-12 (measured over the
cases below); each submechanism's OTI, its lowest, moves by at most 1.7e-14."""
COUNT = 24


def failure_probability(actuator: str) -> float:
    """A failure probability in [0.05, 0.95] that belongs to the actuator's name (so it follows any relabelling)."""
    return 0.05 + 0.9 * (sum(actuator.encode()) % 101) / 100


def by_name(result, renamed: dict[str, str] | None = None) -> dict:
    """Every value of a batch of results keyed by actuator names (``renamed`` maps the result's chain names
    back to the reference's), so that two results of differently ordered or named legs can be compared."""
    renamed = renamed or {}

    def name(actuator: str) -> str:
        chain, _, joint = actuator.partition(":")
        return f"{renamed.get(chain, chain)}:{joint}"

    names = [name(actuator) for actuator in result.actuators]
    values = {"iti": result.iti, "lmti": result.lmti, "dof": result.dof}
    for k, actuator in enumerate(names):
        values[("iti", actuator)] = result.iti_actuators[..., k]
        values[("mutual", actuator)] = result.mutual_interference[..., k]
    for s, members in enumerate(result.submechanisms):
        key = frozenset(names[k] for k in members)
        values[("oti", key)] = result.oti_submechanisms[..., s]
        for slot, k in enumerate(members):
            values[("oti_k", key, names[k])] = result.oti_actuators[..., s, slot]
        if result.cti_submechanisms is not None:
            values[("cti", key)] = result.cti_submechanisms[..., s]
    probabilities = [failure_probability(actuator) for actuator in names]
    for j in result.faults:
        values[("f_o", j)], values[("f_io", j)] = result.f_o[j], result.f_io[j]
        left = {j: result.remaining_lmti[j]}
        values[("f_o_mean", j)] = mean_remaining_lmti(left, len(names))[j]
        values[("f_o_mean weighted", j)] = mean_remaining_lmti(left, len(names), probabilities)[j]
        values[("f_c", j)] = result.f_c[j]
        for failed, column in zip(result.failed_sets(j), np.moveaxis(result.remaining_lmti[j], -1, 0)):
            values[("left", j, frozenset(names[k] for k in failed))] = column
        values[("worst", j)] = [frozenset(frozenset(name(a) for a in case) for case in result.at(i).worst_fault_ties(j))
                                for i in range(result.batch_shape[0])]
    for i in range(min(4, result.batch_shape[0])):  # the limiting actuators a report names, by name
        detail = result.at(i).to_dict()["lmti_detail"]
        best = [detail["submechanism"], *detail["tied_submechanisms"]]
        values[("best", i)] = [frozenset(frozenset(name(a) for a in sub) for sub in best)]
        if len(best) == 1:
            values[("limiting", i)] = [frozenset(name(a) for a in detail["limiting"])]
    values["cti"] = result.cti
    values["instantaneous_dof"] = result.instantaneous_dof
    values["constraint_singular"] = result.constraint_singular
    return values


def assert_same_by_name(reference: dict, other: dict) -> None:
    assert reference.keys() == other.keys()
    for key, value in reference.items():
        if isinstance(value, list) or (isinstance(value, np.ndarray) and value.dtype == bool):
            assert np.array_equal(np.asarray(other[key], dtype=object), np.asarray(value, dtype=object)), key
        elif value is None or isinstance(value, int):
            assert other[key] == value, key
        else:
            tolerance = ACTUATOR_OTI_TOLERANCE if isinstance(key, tuple) and key[0] == "oti_k" else TOLERANCE
            np.testing.assert_allclose(other[key], value, rtol=0, atol=tolerance, err_msg=str(key))


def relabelled(chains: list[ChainScrews], rng: np.random.Generator, rename: bool):
    """The chains in a random order, each with its actuators listed in a random order and, with ``rename``,
    a new name; returns the chains, their order and the map from new names to old ones."""
    order = rng.permutation(len(chains))
    names = {}
    out = []
    for position, index in enumerate(order):
        chain = chains[index]
        actuated = tuple(int(k) for k in rng.permutation(list(chain.actuated)))
        name = f"renamed_{rng.integers(10**6)}_{position}" if rename else chain.name
        names[name] = chain.name
        out.append(ChainScrews(chain.twists, chain.points, actuated, name, joint_names=chain.joint_names))
    return out, order, names


def analyze_chains(mechanism, solution, chains):
    """``analyze`` on chain screws in the order given, with the mechanism's output (point outputs included)."""
    options = {"dof": mechanism.dof, "detail": True}
    points = output_points(mechanism, solution.full_poses)
    if points is not None:
        options.update(output_point=points, planar=mechanism.rotation_world_base[:, 2] if mechanism.is_planar
                       else False)
    return analyze(chains, **options)


def random_designs():
    """One random design of each family (legs and parameters drawn with a fixed seed)."""
    rng = np.random.default_rng(2026)
    designs = []
    for name, legs in (("planar_rrr", 5), ("planar_rrr", 4), ("ups_hexapod", 8), ("ups_hexapod", 7),
                       ("rss_hexapod", 7), ("delta", 4), ("delta", 5), ("prs_ups", 4)):
        kind = family(name, legs)
        for _attempt in range(20):
            values = {p.name: rng.uniform(p.lower, p.upper) for p in kind.parameters
                      if p.name in kind.free}
            try:
                mechanism = kind.mechanism(values, name=f"random_{name}_{legs}")
            except ValueError:
                continue
            designs.append(mechanism)
            break
    return designs


CASES = [(name, None) for name in bundled_names()] + [("design", index) for index in range(8)]


@pytest.fixture(scope="module")
def designs():
    return random_designs()


@pytest.mark.parametrize("name, design", CASES)
def test_every_index_follows_the_names_under_any_order_of_legs_and_actuators(name, design, designs):
    if design is not None:
        assert len(designs) == 8, "a random design of every family"
        mechanism = designs[design]
    else:
        mechanism = load(name)
    rng = np.random.default_rng(sum(mechanism.name.encode()))
    poses = random_reachable_poses(mechanism, rng, COUNT, spread=0.5)
    solution = solve(mechanism, poses)
    chains = list(chain_screws(mechanism, solution))
    reference = by_name(analyze_chains(mechanism, solution, chains))
    for trial in range(3):
        permuted, _, names = relabelled(chains, rng, rename=trial > 0)
        other = analyze_chains(mechanism, solution, permuted)
        assert_same_by_name(reference, by_name(other, names))


def test_at_a_stretched_leg_every_index_follows_the_names_under_any_order_of_legs_and_actuators():
    """At an input singularity (a five_bar_3 leg stretched) the actuation wrench is the limit of the least-norm one
    (found in the span of the chain's twists and the motion space); every index, worst fault and flag still
    follows the legs listed in another order and renamed."""
    mechanism = load("five_bar_3")
    solution = solve(mechanism, np.array([[0.3, 0.3], [-0.2, 0.35], [0.2, 0.4], [-0.2, 0.4]]))
    chains = list(chain_screws(mechanism, solution))
    reference = by_name(analyze_chains(mechanism, solution, chains))
    assert np.all(reference["lmti"] > 0.9)  # not the zero the stretched leg's wrench gave before
    rng = np.random.default_rng(3)
    for trial in range(4):
        permuted, _, names = relabelled(chains, rng, rename=trial > 0)
        assert_same_by_name(reference, by_name(analyze_chains(mechanism, solution, permuted), names))


def test_the_delta_cti_is_the_same_whichever_leg_is_listed_first():
    """The case that was order-dependent: a 4-leg Delta whose four constraint couples have rank three."""
    from screwkit.model.delta_writer import delta_urdf
    from screwkit.robots.generate import DELTA_4

    values = []
    for start in (0.0, 90.0, 180.0, 270.0):
        parameters = dict(DELTA_4, leg_angles_deg=tuple((start + 90.0 * k) % 360.0 for k in range(4)))
        mechanism = load_text(delta_urdf("delta_rotated_listing", parameters), "delta_rotated_listing")
        pose = np.array([0.05, 0.159, -0.7])
        result = analyze_solution(mechanism, solve(mechanism, pose[None]), detail=True)
        values.append([result.cti[0], result.f_c[1][0], result.lmti[0], result.f_o[1][0]])
    values = np.array(values)
    assert np.ptp(values, axis=0).max() <= TOLERANCE
    assert 0.0 < values[0, 0] < 1.0


# -- the file --------------------------------------------------------------------------------------------


def listed_otherwise(text: str, rng: np.random.Generator, rename: bool) -> tuple[str, dict[str, str]]:
    """The URDF with its ``<loop>`` and ``<transmission>`` elements in a random order and, with ``rename``, its
    chains renamed (the loops' ``chain`` attribute); returns the text and the map from new names to old."""
    root = ElementTree.fromstring(text)
    names = {}
    for tag in ("loop", "transmission"):
        elements = root.findall(tag)
        for element in elements:
            root.remove(element)
        for index in rng.permutation(len(elements)):
            element = elements[index]
            if tag == "loop" and rename:
                old = element.get("chain") or element.get("name")
                new = f"{'zyxwvutsrqponm'[len(names)]}_{old}"
                names[new] = old
                element.set("chain", new)
            root.append(element)
    return ElementTree.tostring(root, encoding="unicode"), names


@pytest.mark.parametrize("name", bundled_names())
def test_a_file_with_its_legs_listed_otherwise_gives_the_same_report(name, tmp_path):
    rng = np.random.default_rng(len(name))
    text = bundled_path(name).read_text()
    mechanism = load(name)
    pose = random_reachable_poses(mechanism, rng, 1, spread=0.5)[0]
    reference = by_name(analyze_solution(mechanism, solve(mechanism, pose[None]), detail=True))
    for rename in (False, True):
        other_text, names = listed_otherwise(text, rng, rename)
        other = load_text(other_text, f"{name}_listed_otherwise")
        if not rename:
            assert other.actuator_names == mechanism.actuator_names  # chains are ordered by name
        result = analyze_solution(other, solve(other, pose[None]), detail=True)
        assert_same_by_name(reference, by_name(result, names))


def test_analyze_prints_the_same_report_for_any_order_of_the_legs(tmp_path):
    rng = np.random.default_rng(5)
    for name, pose in (("planar_5rrr", "paper_fig_2a"), ("delta_4", "off_centre")):
        path = tmp_path / f"{name}.urdf"
        path.write_text(listed_otherwise(bundled_path(name).read_text(), rng, rename=False)[0])
        runs = [screwkit("analyze", source, "--pose", pose, "--json") for source in (name, path)]
        for run in runs:
            assert run.returncode == 0, run.stderr
        first, second = (json.loads(run.stdout) for run in runs)
        for report in (first, second):
            report.pop("mechanism")
        assert re.sub(r"\d\.\d{9}\d*", "#", json.dumps(first)) == re.sub(r"\d\.\d{9}\d*", "#", json.dumps(second))
        np.testing.assert_allclose([first["lmti"], first["iti"], *first["f_o"].values()],
                                   [second["lmti"], second["iti"], *second["f_o"].values()], rtol=0, atol=TOLERANCE)


def test_every_set_of_the_reduction_is_listed_once():
    """``failed_sets`` and ``remaining_lmti`` agree with the definition: LMTI of the set left (Eq. 11)."""
    mechanism = load("planar_5rrr")
    result = analyze_solution(mechanism, solve(mechanism, mechanism.named_pose("paper_fig_2a")[None]), detail=True)
    for j in result.faults:
        failed = result.failed_sets(j)
        assert len(set(failed)) == len(failed) == len(list(combinations(range(5), j)))
        for column, gone in enumerate(failed):
            left = [k for k in range(5) if k not in gone]
            assert result.remaining_lmti[j][0, column] == result.lmti_of(left)[0]
