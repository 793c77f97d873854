"""``screwkit info``: what a mechanism is, as screwkit read it."""

from __future__ import annotations

import json

import click
import numpy as np

from screwkit.cli.options import (
    ignore_limits_option,
    json_option,
    load_mechanism,
    mechanism_argument,
    reading_options,
)
from screwkit.closure import working_modes
from screwkit.closure.assembly import MODES_MEET
from screwkit.common.units import unit_of
from screwkit.io import GraphMechanism
from screwkit.model.mechanism import SPATIAL_TASK_COORDINATES
from screwkit.studies.coordinates import shown_number

__all__ = ["info", "mechanism_info", "graph_info"]


def _tidy(value: float) -> float:
    """A placement's number without round-off noise (a rotation's 6e-17 is 0)."""
    return 0.0 if abs(value) < 1e-12 else float(value)


def graph_info(graph: GraphMechanism) -> dict:
    """:func:`mechanism_info` of a closed-loop graph: its legs (joints, closures), the platform and task coordinates
    inferred from the graph, how poses are solved."""
    model = graph.tree.model
    mode = ("the one reached from the file's configuration by moving the platform straight to the pose "
            "(continuation)")
    return {
        "mechanism": graph.name, "file": str(graph.tree.source), "length_unit": graph.tree.length_unit or "m",
        "dof": graph.dof,
        "task_coordinates": [{"name": name, "unit": unit_of(name)} for name in graph.task_coordinates],
        "task_coordinates_source": "declared" if graph.tree.task_coordinates else "inferred",
        "dependent_coordinates": [{"name": name, "unit": unit_of(name)} for name in SPATIAL_TASK_COORDINATES
                                  if name not in graph.task_coordinates], "held_coordinates": [],
        "instantaneous_dof_at_home": graph.dof, "output": "frame",
        "platform": {"link": graph.platform_body, "joint": model.names[graph.platform], "base_link": "world",
                     "planar": False, "base_in_world": {"origin_m": [0.0] * 3, "axes": np.eye(3).tolist()}},
        "actuators": list(graph.actuators),
        "chains": [{"name": leg.name, "joints": [model.names[j] for j in leg.joints],
                    "actuated": [model.names[j] for j in leg.actuators],
                    "loop": ", ".join(closure.name for closure in leg.closures), "loop_type": "graph",
                    "solver": "graph", "why": "a leg with loops inside it: every closure of the mechanism solved at "
                                              "once, batched (screwkit.io.graph_kinematics)",
                    "working_mode": mode} for leg in graph.legs],
        "named_poses": {}, "length_scale_m": graph.scale, "assembly_notes": list(graph.tree.notes),
        "import_report": graph.report.lines(),
    }


def mechanism_info(mechanism) -> dict:
    """A JSON-ready description of a mechanism: DOF, task coordinates, chains, solvers, actuators, named poses."""
    if isinstance(mechanism, GraphMechanism):
        return graph_info(mechanism)

    def shown(pose):  # in m and deg as written, without round-off noise (a pose through a tilted base frame)
        return {name: shown_number(name, value, mechanism.length_scale)
                for name, value in zip(mechanism.task_coordinates, pose)}

    modes = working_modes(mechanism)
    return {
        "mechanism": mechanism.name,
        "file": mechanism.path,
        "length_unit": mechanism.length_unit,
        "dof": mechanism.dof,
        "task_coordinates": [{"name": name, "unit": unit_of(name)} for name in mechanism.task_coordinates],
        "task_coordinates_source": mechanism.task_source,
        "dependent_coordinates": [{"name": mechanism.pose_coordinates[i],
                                   "unit": unit_of(mechanism.pose_coordinates[i])}
                                  for i in mechanism.dependent_indices],
        "held_coordinates": [mechanism.pose_coordinates[i] for i in mechanism.held_axes],
        "instantaneous_dof_at_home": mechanism.instantaneous_dof,
        "output": "frame" if mechanism.output_point is None else "point",
        "platform": {"link": mechanism.platform_link, "joint": mechanism.platform_joint,
                     "base_link": mechanism.base_link, "planar": mechanism.is_planar,
                     "base_in_world": {"origin_m": [_tidy(v) for v in mechanism.translation_world_base],
                                       "axes": [[_tidy(v) for v in axis] for axis in mechanism.rotation_world_base.T]}},
        "actuators": list(mechanism.actuator_names),
        "chains": [{"name": chain.name, "joints": list(chain.joint_names),
                    "actuated": [chain.joint_names[k] for k in chain.actuated], "loop": chain.loop_name,
                    "loop_type": chain.loop_type, "solver": chain.solver, "why": chain.solver_reason,
                    "working_mode": modes[chain.name]}
                   for chain in mechanism.chains],
        "named_poses": {name: shown(pose) for name, pose in mechanism.named_poses.items()},
        "length_scale_m": mechanism.length_scale,
        "assembly_notes": list(mechanism.assembly_notes),
        "import_report": list(mechanism.import_report),
    }


@click.command()
@mechanism_argument
@reading_options
@ignore_limits_option
@json_option
def info(mechanism: str, reading, ignore_limits: bool, as_json: bool) -> None:
    """What MECHANISM is: DOF, task coordinates (with units), chains and the solver each uses and why,
    actuators, named poses (m, deg)."""
    loaded = load_mechanism(mechanism, reading, indices=False, limits=not ignore_limits, graphs=True)
    report = mechanism_info(loaded)
    if as_json:
        click.echo(json.dumps(report))
        return
    click.echo(f"{report['mechanism']} ({report['file']}, lengths in {report['length_unit']} in the file)")
    coordinates = ", ".join(f"{c['name']} ({c['unit']})" for c in report["task_coordinates"])
    source = {"all": "full mobility", "declared": "declared in the file", "inferred": "inferred from the motion space"}
    click.echo(f"  DOF {report['dof']}; task coordinates: {coordinates} "
               f"({source.get(report['task_coordinates_source'], report['task_coordinates_source'])})")
    solved = [c["name"] for c in report["dependent_coordinates"] if c["name"] not in report["held_coordinates"]]
    if solved:
        click.echo("  dependent (parasitic) coordinates, solved with the closure: " + ", ".join(solved))
    if report["held_coordinates"]:
        click.echo("  dependent coordinates held at home (the operation mode followed does not turn the platform): "
                   + ", ".join(report["held_coordinates"]))
    if report["instantaneous_dof_at_home"] > report["dof"]:
        click.echo(f"  the home pose is a constraint singularity: {report['instantaneous_dof_at_home']} "
                   "instantaneous DOF")
    modes = [note for note in report["assembly_notes"] if note.startswith(MODES_MEET)]
    for note in modes:  # where operation modes meet there: which is followed
        click.echo(f"  {note}")
    if report["output"] == "point":
        click.echo("  output: the platform frame's origin, a point (rotations about it are idle)")
    kind = "planar" if loaded.is_planar else "a leg's body" if isinstance(loaded, GraphMechanism) else "floating"
    click.echo(f"  platform {report['platform']['link']!r} on {report['platform']['joint']!r} "
               f"({kind}) from {report['platform']['base_link']!r}")
    placed = report["platform"]["base_in_world"]
    if placed["origin_m"] != [0.0] * 3 or placed["axes"] != np.eye(3).tolist():  # poses are not in world coordinates
        axes = ", ".join(f"{name} along ({', '.join(f'{v:.6g}' for v in axis)})"
                         for name, axis in zip("xyz", placed["axes"]))
        click.echo(f"  task frame: base {report['platform']['base_link']!r}, origin ("
                   f"{', '.join(f'{v:.6g}' for v in placed['origin_m'])}) m in the world; its {axes} in the world's"
                   + (" (the plane of motion is its x-y plane)" if loaded.is_planar else ""))
    count = len(report['actuators'])
    click.echo(f"  {count} actuator{'' if count == 1 else 's'}: {', '.join(report['actuators'])}")
    click.echo("  chains:")
    for chain in report["chains"]:
        actuated = f"actuated: {', '.join(chain['actuated'])}" if chain["actuated"] else "passive"
        loop = chain["loop"] or "none, the platform body's own path"  # (a graph leg that ends on the platform)
        click.echo(f"    {chain['name']}: {' - '.join(chain['joints']) or 'no joint but its loop'} ({actuated}); "
                   f"loop {loop} ({chain['loop_type']})")
        click.echo(f"      solver {chain['solver']}: {chain['why']}")
        click.echo(f"      working mode: {chain['working_mode']}")
    for note in (note for note in report["assembly_notes"] if note not in modes):
        click.echo(f"  assembled: {note}")
    if report["import_report"]:
        click.echo("  converted from " + report["import_report"][0])
        for line in report["import_report"][1:]:
            click.echo(f"  {line}")
    if report["named_poses"]:
        click.echo("  named poses (m, deg):")
    for name, pose in report["named_poses"].items():
        click.echo(f"    {name}: " + ", ".join(f"{k} = {v:.6g}" for k, v in pose.items()))
