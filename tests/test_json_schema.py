"""Every ``--json`` output validates against the published JSON Schema of its command (``docs/schema/``).

The commands run as users run them, in a subprocess, on redundant and non-redundant mechanisms, lower-mobility
ones with constraint wrenches, point outputs, a converted MJCF file, a file whose loops are open as written,
link faults, and errors. The schemas forbid unknown keys, so a new key in a report must be documented in its
schema first.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

from helpers import screwkit

jsonschema = pytest.importorskip("jsonschema")

SCHEMAS = Path(__file__).resolve().parents[1] / "docs" / "schema"
sys.path.insert(0, str(Path(__file__).resolve().parent))


def validate(command: str, arguments: list, schema: str | None = None) -> dict:
    completed = screwkit(command, *arguments, "--json")
    report = json.loads(completed.stdout)
    name = "error" if completed.returncode else (schema or command)
    jsonschema.validate(report, json.loads((SCHEMAS / f"{name}.schema.json").read_text()))
    return report


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    from test_io import five_bar_mjcf

    folder = tmp_path_factory.mktemp("json")
    (folder / "five_bar.xml").write_text(five_bar_mjcf(legs=2))
    text = (Path(__file__).resolve().parents[1] / "robots" / "planar_5rrr.urdf").read_text()
    opened = text.replace('<child link="chain_1_link_l" />\n    <origin xyz="1 0 0"',
                          '<child link="chain_1_link_l" />\n    <origin xyz="1.05 0 0"')
    assert opened != text
    (folder / "open.urdf").write_text(opened)
    return folder


@pytest.mark.parametrize("arguments", [
    ["planar_5rrr", "--pose", "paper_fig_2a"],
    ["planar_5rrr", "--pose", "paper_fig_2a", "--fault", "link"],
    ["planar_5rrr", "--pose", "paper_fig_2a", "--aggregate", "mean", "--probabilities", "0.1", "0.2", "0", "0.3", "1"],
    ["five_bar"],
    ["ups_stewart_6", "--pose", "0.02", "0", "1", "3", "-2", "10"],
    ["delta_4", "--pose", "off_centre"],
    ["prs_3_ups"],
    ["coop_arms"],
    ["schoenflies_5"],
])
def test_analyze_reports_validate(arguments):
    report = validate("analyze", arguments)
    assert report["reachable"] and set(report["iti_actuators"]) == set(report["actuators"])


def test_analyze_of_converted_and_open_files_validates(files):
    converted = validate("analyze", [files / "five_bar.xml"])
    assert converted["converted"] and converted["redundancy"] == 0
    opened = validate("analyze", [files / "open.urdf"])
    assert len(opened["assembly"]) == 1 and "chain_1_joint_d" in opened["assembly"][0]


def test_unreachable_and_bad_input_give_the_error_schema(files):
    for arguments in (["planar_5rrr", "--pose", "5", "5", "0"], ["no/such/file.urdf"], ["planar_5rrr", "--fault", "x"]):
        report = validate("analyze", arguments)
        assert set(report) == {"error"}


@pytest.mark.parametrize("name", ["delta_4", "five_bar_3", "ups_stewart_6"])
def test_info_validates(name):
    report = validate("info", [name])
    assert all(chain["working_mode"] for chain in report["chains"])


def test_list_verify_convert_and_design_search_validate(files, tmp_path):
    validate("list", [])
    assert validate("verify", ["five_bar", "--samples", "50"])["largest_deviation"] < 1e-9
    validate("convert", [files / "five_bar.xml", tmp_path / "five_bar.urdf"])
    validate("design-search", ["permutations", "planar_5rrr", "--phi-step", "60", "--quiet"])
    ranked = validate("design-search", ["permutations", "planar_5rrr", "--phi-step", "60", "--quiet", "--index",
                                        "f_o_mean2", "--probabilities", "0.1", "0.2", "0.1", "0.1", "0.3"])
    assert ranked["index"] == "f_o_mean2" and ranked["probabilities"] == [0.1, 0.2, 0.1, 0.1, 0.3]
    validate("design-search", ["family", "planar_rrr", "--budget", "4", "--quiet", "--step", "0.2", "--phi-step", "30"])


def test_trajectory_validates(tmp_path):
    """A path leaving the workspace (an event), with the mean: every key of the summary is in the schema."""
    report = validate("trajectory", ["planar_5rrr", "--line", "0", "0", "0", "0", "1.5", "0", "--samples", "16",
                                     "--aggregate", "mean"])
    assert report["events"] and "f_o_mean1" in report["margins"]
    assert "missing.csv: no such file" in validate("trajectory", ["planar_5rrr", tmp_path / "missing.csv"])["error"]
    graph = validate("trajectory", ["delta_rods_4", "--line", "0", "0", "-0.75", "0", "0", "-0.3", "--samples", "6",
                                    "--aggregate", "mean"])  # legs with loops inside them, leaving the workspace
    assert graph["events"][0]["kind"] == "closure" and "f_o_mean1" in graph["margins"]


def test_every_command_with_json_has_a_schema():
    from screwkit.cli import COMMANDS

    with_json = {name for name, command in COMMANDS.items() if "--json" in command_options(name)}
    assert with_json == {path.name.removesuffix(".schema.json") for path in SCHEMAS.glob("*.schema.json")} - {"error"}


def command_options(name: str) -> set[str]:
    import click

    from screwkit.cli import app

    command = app.get_command(click.Context(app), name)
    commands = [command, *getattr(command, "commands", {}).values()]  # a group: its subcommands' options too
    return {option for each in commands for parameter in each.params for option in getattr(parameter, "opts", ())}


def test_a_mechanism_whose_legs_have_loops_inside_reports_valid_json(tmp_path):
    """A Delta of ball-jointed rods (a graph, at the file's configuration): its report follows the schema."""
    from delta_rods import delta_rods_mjcf

    path = tmp_path / "delta_rods.xml"
    path.write_text(delta_rods_mjcf())
    report = validate("analyze", [path])
    assert report["dof"] == 3 and set(report["pose"]) == {"x", "y", "z"} and len(report["actuators"]) == 4
    assert any("graph" in line for line in report["converted"])
    info = validate("info", [path])
    assert info["dof"] == 3 and [c["name"] for c in info["task_coordinates"]] == ["x", "y", "z"]
    assert [chain["loop_type"] for chain in info["chains"]] == ["graph"] * 4


def test_a_pose_past_a_chain_s_singular_configuration_validates(tmp_path):
    from test_singular_on_the_way import square_four_bar

    path = tmp_path / "square.xml"
    path.write_text(square_four_bar())
    report = validate("analyze", [path, "--output", "link_4", "--pose", "200"])
    assert [passed["chain"] for passed in report["singular_on_the_way"]] == ["hinge_1"]


def test_a_path_past_a_chain_s_singular_configuration_validates(tmp_path):
    from test_singular_on_the_way import square_four_bar

    path = tmp_path / "square.xml"
    path.write_text(square_four_bar())
    report = validate("trajectory", [path, "--output", "link_4", "--line", "0", "200", "--samples", "51"])
    assert [event["kind"] for event in report["events"]] == ["singular"]
