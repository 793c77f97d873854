"""``screwkit convert``: a closed-loop robot of another tool, written in screwkit's URDF convention."""

from __future__ import annotations

import json
from pathlib import Path

import click

from screwkit.cli.options import fail, json_option, overwrite_option, quiet_option
from screwkit.io import ImportError_, read_mechanism_file
from screwkit.loader import load_text
from screwkit.studies.files import check_output

__all__ = ["convert"]


@click.command()
@click.argument("source", type=click.Path(dir_okay=False, path_type=Path))
@click.argument("out", type=click.Path(dir_okay=False, path_type=Path))
@click.option("--output", "output_frame", default=None, metavar="FRAME",
              help="The frame (MJCF: site or body) whose body is the platform; default a frame named effector, "
                   "end_effector, eff, ee, tool, tcp, foot or platform.")
@click.option("--output-type", type=click.Choice(["point", "frame"]), default=None,
              help="A point output (where the chains meet) or the output frame; default: the point when every "
                   "closure meets the platform at one point, else the frame.")
@overwrite_option
@quiet_option
@json_option
def convert(source: Path, out: Path, output_frame, output_type, overwrite: bool, quiet: bool, as_json: bool) -> None:
    """Write SOURCE (an MJCF file, or a URDF tree with a Gepetto robot.yaml beside it) to OUT in screwkit's
    URDF convention: loops, transmissions and the assembled reference configuration (lengths in m)."""
    if not source.is_file():
        raise fail(f"{source}: no such file.")
    if source.suffix.lower() not in (".xml", ".mjcf", ".urdf"):
        raise fail(f"{source}: expected an MJCF file (.xml, .mjcf) or a URDF with a robot.yaml beside it.")
    try:
        check_output(out, (".urdf",), overwrite=overwrite)
    except ValueError as error:
        raise fail(str(error)) from None
    try:
        text, report = read_mechanism_file(source, output=output_frame, output_type=output_type)
        mechanism = load_text(text, str(out))  # what is written must load
    except (ImportError_, ValueError) as error:
        raise fail(str(error)) from None
    out.write_text(text, encoding="utf-8")
    summary = {"source": str(source), "written": str(out), "format": report.file_format,
               "platform_body": report.platform_body, "output": report.output, "planar": report.planar,
               "dof": mechanism.dof, "task_coordinates": list(mechanism.task_coordinates),
               "actuators": list(mechanism.actuator_names), "chains": report.chains, "locked_joints": report.locked,
               "left_out_joints": report.dropped,
               "closure_gaps_m": {name: {"file": report.gaps_before[name], "assembled": report.gaps_after[name]}
                                  for name in report.gaps_before}}
    if as_json:
        click.echo(json.dumps(summary, indent=2))
    elif not quiet:
        for line in report.lines():
            click.echo(line, err=True)
        click.echo(f"wrote {out}: {mechanism.dof} DOF ({' '.join(mechanism.task_coordinates)}), "
                   f"{len(mechanism.actuators)} actuators", err=True)
