"""``screwkit verify``: the generic screw path against the paper's planar closed forms."""

from __future__ import annotations

import json
import sys

import click
import numpy as np

from screwkit.cli.options import (
    fail,
    json_option,
    load_mechanism,
    mechanism_argument,
    reading_options,
)
from screwkit.closure import solve
from screwkit.common.compiling import INDEX_KERNELS, compile_ahead
from screwkit.indices.stages import SPACES_COMPILED_FROM
from screwkit.studies.closed_form_poses import closed_form_indices, planar_points
from screwkit.studies.kernels import mechanism_kernels
from screwkit.studies.poses import analyze_solution

__all__ = ["verify"]


@click.command()
@mechanism_argument
@click.option("--samples", type=click.IntRange(min=1, max=10**7), default=10_000, show_default=True,
              help="Random reachable configurations to compare (count).")
@click.option("--seed", type=int, default=0, show_default=True, help="Seed of the random poses.")
@reading_options
@json_option
def verify(mechanism: str, samples: int, seed: int, reading, as_json: bool) -> None:
    """Compare the generic screw path with the paper's planar closed forms on random poses.

    Exit status 1 when some index differs by more than 1e-9.
    """

    loaded = load_mechanism(mechanism, reading, indices=False)  # nothing compiled before the refusal below
    if not loaded.is_planar:
        raise fail(f"verify compares with the planar closed forms; {loaded.name!r} is spatial.")
    compile_ahead(*INDEX_KERNELS, *mechanism_kernels(loaded, batches=samples >= SPACES_COMPILED_FROM))
    rng = np.random.default_rng(seed)
    home = loaded.home_pose
    spread = np.where(loaded.angular, np.pi, 0.5 * loaded.length_scale)  # a turn, or half the length scale
    poses = home + rng.uniform(-1.0, 1.0, (samples * 4, loaded.n_task)) * spread
    solution = solve(loaded, poses)
    keep = np.flatnonzero(solution.reachable)[:samples]
    if keep.size == 0:
        raise fail("No reachable pose among the samples.")
    solution = solve(loaded, poses[keep])
    try:
        planar_points(loaded, solution)
    except ValueError as error:
        raise fail(str(error)) from None
    try:
        generic = analyze_solution(loaded, solution, detail=True)
        closed = closed_form_indices(loaded, solution)
    except ValueError as error:
        raise fail(str(error)) from None
    rows = [("ITI per actuator", generic.iti_actuators, closed.iti_actuators),
            ("OTI per submechanism", generic.oti_submechanisms, closed.oti_submechanisms),
            ("LMTI", generic.lmti, closed.lmti)]
    rows += [(f"F_O{j}", generic.f_o[j], closed.f_o[j]) for j in generic.faults]
    rows += [(f"F_IO{j}", generic.f_io[j], closed.f_io[j]) for j in generic.faults]
    deviations = {label: float(np.max(np.abs(first - second))) for label, first, second in rows}
    differing = {f"worst faults j={j}":
                 int(np.sum(np.any(generic.worst_fault_indices[j] != closed.worst_fault_indices[j], axis=-1)))
                 for j in generic.faults}
    differing["mutual interference"] = int(np.sum(np.any(generic.mutual_interference != closed.mutual_interference,
                                                         axis=-1)))
    worst = max(deviations.values())
    if as_json:
        click.echo(json.dumps({"mechanism": loaded.name, "poses": int(keep.size), "largest_deviation": worst,
                               "deviations": deviations, "differing_poses": differing}))
    else:
        forms = ("textbook pressure angles of legs meeting at the output point (Eqs. 21, 23)"
                 if loaded.output_point is not None else "closed forms (Eqs. 23, 34-38, A4)")
        click.echo(f"{loaded.name}: generic screw path vs {forms} on {keep.size} poses")
        for label, deviation in deviations.items():
            click.echo(f"  {label:<22s} largest deviation {deviation:.2e}")
        for label, count in differing.items():
            click.echo(f"  {label:<22s} differs at {count} poses")
        click.echo(f"largest deviation: {worst:.2e}")
    if worst > 1e-9 or any(differing.values()):
        sys.exit(1)
