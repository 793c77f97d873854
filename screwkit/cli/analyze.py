"""``screwkit analyze``: every index at one pose."""

from __future__ import annotations

import json

import click

from screwkit.cli.options import (
    GreedyOption,
    fail,
    ignore_limits_option,
    json_option,
    length_unit_option,
    load_mechanism,
    mechanism_argument,
    parse_pose,
    threshold_option,
)
from screwkit.studies import indices_at_pose

__all__ = ["analyze", "print_report"]


def print_report(report: dict) -> None:
    """The indices at one pose as text (from :meth:`screwkit.results.Indices.to_dict`)."""
    pose = ", ".join(f"{k} = {v:g}" for k, v in report["pose"].items())
    click.echo(f"{report['mechanism']}: {len(report['actuators'])} actuators, {report['dof']} DOF, at {pose}")
    click.echo("")
    click.echo("ITI per actuator (Eq. 6)")
    lowest = min(report["iti_actuators"], key=report["iti_actuators"].get)
    for name, value in report["iti_actuators"].items():
        click.echo(f"  {name:<32s} {value:.4f}{'  <- lowest' if name == lowest else ''}")
    click.echo(f"ITI  (Eq. 7)                        {report['iti']:.4f}")
    click.echo(f"LMTI (Eq. 11, all actuators)        {report['lmti']:.4f}")
    if not report["f_o"]:
        click.echo("No redundancy (a = n): no fault-tolerance index is defined.")
    for j in report["f_o"]:
        worst = ", ".join(report["worst_faults"].get(j, []))
        click.echo(f"F_O{j:<2s}(Eq. 12) {report['f_o'][j]:.4f}   F_IO{j:<2s}(Eq. 14) {report['f_io'][j]:.4f}"
                   f"   worst fault: {worst}")
    if report["not_mutual_interference"]:
        click.echo("Not mutual-interference actuators (every F_Oj is 0): "
                   + ", ".join(report["not_mutual_interference"]))
    else:
        click.echo("All actuators are mutual-interference actuators.")


@click.command()
@mechanism_argument
@click.option("--pose", cls=GreedyOption, metavar="VALUES|NAME",
              help="Platform pose: x y phi (planar) or x y z roll pitch yaw, in m and deg, or a named pose "
                   "(screwkit info lists them). Default: the file's home pose.")
@threshold_option
@ignore_limits_option
@length_unit_option
@json_option
def analyze(mechanism: str, pose, threshold: float, ignore_limits: bool, length_unit, as_json: bool) -> None:
    """Every index (ITI, LMTI, F_Oj, F_IOj, worst faults) of MECHANISM at one pose."""

    loaded = load_mechanism(mechanism, length_unit)
    target = parse_pose(loaded, pose)
    try:
        result = indices_at_pose(loaded, target, threshold=threshold, limits=not ignore_limits)
    except ValueError as error:
        raise fail(str(error)) from None
    report = result.to_dict()
    if as_json:
        click.echo(json.dumps(report))
    else:
        print_report(report)
