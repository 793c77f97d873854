"""``screwkit analyze``: every index at one pose."""

from __future__ import annotations

import json

import click
import numpy as np

from screwkit.cli.options import (
    GreedyOption,
    fail,
    fault_option,
    ignore_limits_option,
    json_option,
    length_unit_option,
    load_mechanism,
    mechanism_argument,
    parse_pose,
    threshold_option,
)
from screwkit.closure import forward
from screwkit.studies import indices_at_pose

__all__ = ["analyze", "print_report"]


def print_report(report: dict) -> None:
    """The indices at one pose as text (from :meth:`screwkit.results.Indices.to_dict`)."""
    pose = ", ".join(f"{k} = {v:g}" for k, v in report["pose"].items())
    click.echo(f"{report['mechanism']}: {len(report['actuators'])} actuators, {report['dof']} DOF, at {pose}")
    if report.get("dependent"):
        click.echo("  dependent (parasitic) coordinates: "
                   + ", ".join(f"{k} = {v:.6g}" for k, v in report["dependent"].items()))
    if report.get("constraint_singular"):
        click.echo(f"  CONSTRAINT SINGULARITY: {report['instantaneous_dof']} instantaneous DOF at this pose, "
                   f"mobility {report['dof']}")
    click.echo("")
    click.echo("ITI per actuator (Eq. 6)")
    lowest = min(report["iti_actuators"], key=report["iti_actuators"].get)
    for name, value in report["iti_actuators"].items():
        click.echo(f"  {name:<32s} {value:.4f}{'  <- lowest' if name == lowest else ''}")
    click.echo(f"ITI  (Eq. 7)                        {report['iti']:.4f}")
    click.echo(f"LMTI (Eq. 11, all actuators)        {report['lmti']:.4f}")
    if len(report["actuators"]) == report["dof"]:
        click.echo("No redundancy (a = n): one failed actuator leaves the platform uncontrolled, so F_O1 = F_IO1 = 0.")
    elif report["fault_type"] != "free-swinging":
        click.echo(f"Faults: {report['fault_type']} failures")
    for j in report["f_o"]:
        worst = ", ".join(report["worst_faults"].get(j, []))
        click.echo(f"F_O{j:<2s}(Eq. 12) {report['f_o'][j]:.4f}   F_IO{j:<2s}(Eq. 14) {report['f_io'][j]:.4f}"
                   f"   worst fault: {worst}")
    if report["cti"] == "not applicable":
        click.echo("CTI  not applicable: no constraint wrench is held by one chain alone")
    else:
        click.echo(f"CTI  (constraint transmission)      {report['cti']:.4f}")
        for j, value in report.get("f_c", {}).items():
            click.echo(f"F_C{j:<2s}(worst CTI, {j} fault(s))      {value:.4f}")
    if report["not_mutual_interference"]:
        click.echo("Not mutual-interference actuators (every F_Oj is 0): "
                   + ", ".join(report["not_mutual_interference"]))
    else:
        click.echo("All actuators are mutual-interference actuators.")


def pose_from_actuators(mechanism, text: str, start):
    """The task pose where every actuator has the value given (deg or m), found from ``start``."""
    names = mechanism.actuator_names
    try:
        values = [float(word) for word in text.split()]
    except ValueError:
        raise fail(f"Expected numbers after --actuators, got {text!r}.") from None
    if len(values) != len(names):
        raise fail(f"Expected --actuators with {len(names)} values (one per actuator: {', '.join(names)}), "
                   f"got {len(values)}.")
    positions = mechanism.actuator_positions()
    values = [value if mechanism.chains[c].prismatic[k] else float(np.deg2rad(value))
              for value, (c, k) in zip(values, positions)]
    solution = forward(mechanism, values, start)
    if not bool(np.asarray(solution.reachable).reshape(-1)[0]):
        raise fail(f"No closed pose of {mechanism.name!r} has these actuator values near the start pose "
                   "(redundant actuators must agree with one another; give another start with --pose).")
    return np.asarray(solution.poses).reshape(-1)


@click.command()
@mechanism_argument
@click.option("--pose", cls=GreedyOption, metavar="VALUES|NAME",
              help="Platform pose: x y phi (planar) or x y z roll pitch yaw, in m and deg, or a named pose "
                   "(screwkit info lists them). Default: the file's home pose.")
@click.option("--actuators", "actuator_values", cls=GreedyOption, metavar="VALUES",
              help="Pose given by every actuator's value instead (deg for revolute, m for prismatic, in the order "
                   "screwkit info lists them): forward kinematics from --pose (default home), whose working mode "
                   "it keeps.")
@threshold_option
@fault_option
@ignore_limits_option
@length_unit_option
@json_option
def analyze(mechanism: str, pose, actuator_values, threshold: float, fault_type: str, ignore_limits: bool, length_unit,
            as_json: bool) -> None:
    """Every index (ITI, LMTI, F_Oj, F_IOj, worst faults, CTI) of MECHANISM at one pose."""

    loaded = load_mechanism(mechanism, length_unit)
    target = parse_pose(loaded, pose)
    if actuator_values is not None:
        target = pose_from_actuators(loaded, actuator_values, target)
    try:
        result = indices_at_pose(loaded, target, threshold=threshold, limits=not ignore_limits, fault_type=fault_type)
    except ValueError as error:
        raise fail(str(error)) from None
    report = result.to_dict()
    if loaded.import_report:  # a file of another tool: which body and which point the indices are for
        report["converted"] = list(loaded.import_report)
    if as_json:
        click.echo(json.dumps(report))
    else:
        print_report(report)
        for line in loaded.import_report[:1]:
            click.echo(f"(converted from {line})", err=True)
