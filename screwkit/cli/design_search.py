"""``screwkit design-search``: the paper's permutation selection, and searching a parametric family."""

from __future__ import annotations

import json

import click
import numpy as np
from click.core import ParameterSource

from screwkit.cli.family_search import parse_assignments, parse_bounds, read_study, region_of, search_family
from screwkit.cli.options import (
    check_colour_scale,
    check_outputs,
    fail,
    json_option,
    length_unit_option,
    load_mechanism,
    overwrite_option,
    quiet_option,
    scheduler_client,
)
from screwkit.studies.design import permutations as search
from screwkit.studies.design.families import FAMILIES, family
from screwkit.studies.design.objectives import METRICS
from screwkit.studies.files import DATA_SUFFIXES, FIGURE_SUFFIXES
from screwkit.studies.tasks import CONNECT_TIMEOUT, ClusterError

__all__ = ["design_search"]


def _permutations(loaded, template, current, phi_step, closed_forms, scheduler, connect_timeout, top, as_json, quiet):

    ranked = search.permutation_search(template, phi_step_degrees=phi_step, closed_forms=closed_forms,
                                       scheduler=scheduler, progress=False if quiet else None,
                                       connect_timeout=connect_timeout)
    best = ranked[0].score
    rows = [{"permutation": list(d.permutation), "working_mode": d.working_mode, "score": d.score,
             "rank": 1 + sum(round(o.score, 9) > round(d.score, 9) for o in ranked if np.isfinite(o.score)),
             "rotation_class": list(search.rotation_class(d.permutation))} for d in ranked]
    mode = int(template.working_mode[0])
    mine = next(r for r in rows if tuple(r["permutation"]) == current and r["working_mode"] == mode)
    if as_json:
        click.echo(json.dumps({"mechanism": loaded.name, "current": list(current), "phi_step_deg": phi_step,
                               "designs": rows}))
        return
    click.echo(f"{loaded.name}: {len(ranked)} designs (slot permutations x 2 working modes); score = min F_O1 "
               f"over a full rotation at the centre, {phi_step:g} deg steps")
    click.echo(f"{'rank':>4s}  {'permutation':<18s} {'mode':>4s}  {'score':>7s}")
    for row in rows[:top]:
        mark = "  <- this file's design" if row is mine else ""
        click.echo(f"{row['rank']:>4d}  {str(row['permutation']):<18s} {row['working_mode']:>+4d}  "
                   f"{row['score']:.4f}{mark}")
    click.echo(f"this file's design {list(current)} ranks {mine['rank']} (best score {best:.4f})")


@click.command("design-search")
@click.argument("mechanism", metavar="FAMILY|MECHANISM", required=False)
@click.option("--study", "study_path", type=click.Path(dir_okay=False),
              help="A study file (.yaml or .json) whose keys stand for this command's options (family, objectives, "
                   "constraints, free, set, start, bounds, budget, seed, popsize, radius, step, phi_step, grid, over, "
                   "layers, index, level); options given on the command line win.")
@click.option("--permutations", "search_permutations", is_flag=True,
              help="MECHANISM: rank every assignment of platform slots to chains in both working modes "
                   "(the paper's selection).")
@click.option("--optimise", is_flag=True,
              help="MECHANISM: search the planar_rrr family from this planar n-RRR (its platform radius and arm "
                   "lengths; base, slots and working mode kept).")
@click.option("--legs", type=click.IntRange(min=1), help="FAMILY: number of legs (default: 5 planar, 8 hexapods).")
@click.option("--objective", "objectives", multiple=True, type=click.Choice(list(METRICS)),
              help="Metric to optimise (repeat for a Pareto front; default: area). See docs/design.md.")
@click.option("--constraint", "constraints", multiple=True, metavar="METRIC>=VALUE|METRIC<=VALUE",
              help="A bound every design kept must meet, e.g. footprint<=1.2 (repeatable).")
@click.option("--free", multiple=True, metavar="NAME", help="A parameter to vary (repeatable; default: the family's).")
@click.option("--set", "assignments", multiple=True, metavar="NAME=VALUE", help="Fix a parameter (repeatable).")
@click.option("--start", "starts", multiple=True, metavar="NAME=VALUE",
              help="Starting value of a varied parameter (repeatable; default: the family's default).")
@click.option("--bounds", "bound_texts", multiple=True, metavar="NAME=LOWER:UPPER",
              help="Narrow a varied parameter's bounds (repeatable).")
@click.option("--budget", type=click.IntRange(min=0), help="Designs evaluated (count; default: 384).")
@click.option("--seed", type=int, default=0, show_default=True, help="Seed of the search (same seed, same run).")
@click.option("--state", type=click.Path(dir_okay=False),
              help="Evaluation log: written as the search goes; run again with it to resume an interrupted search.")
@click.option("--radius", type=float, help="Planar region: radius of the disc (m; default 0.6).")
@click.option("--grid", "grids", multiple=True, metavar="COORDINATE:START:STOP:STEP",
              help="Spatial region: a map coordinate, stop included (twice), as screwkit map --grid.")
@click.option("--over", "overs", multiple=True, metavar="COORDINATE:START:STOP:STEP",
              help="Spatial region: the orientation set, stop excluded, as screwkit map --over (repeatable).")
@click.option("--layers", metavar="COORDINATE:START:STOP:STEP",
              help="Spatial region: stack maps along a third coordinate (stop excluded) for a volume.")
@click.option("--index", "region_index", default=None, metavar="f_o1|f_io1|...",
              help="Index whose minimum over the orientation set makes a point fault tolerant (default f_o1).")
@click.option("--phi-step", type=float, default=None,
              help="Step of the full rotation (deg; --permutations: 1, planar region: 5).")
@click.option("--top", type=click.IntRange(min=2), default=12, show_default=True,
              help="Designs listed: --permutations ranks, the Pareto front (evenly spread along it) (count).")
@click.option("--level", type=float, default=None,
              help="The index level that makes a point fault tolerant (default: the family's, 0.4 planar).")
@click.option("--maxiter", type=click.IntRange(min=1),
              help="One objective: generations of differential evolution (sets the budget to popsize x parameters x "
                   "(maxiter + 1)).")
@click.option("--popsize", type=click.IntRange(min=2), default=8, show_default=True,
              help="Population size per varied parameter (count).")
@click.option("--step", type=float, default=None, help="Planar region: grid step of the disc (m; default 0.05).")
@click.option("--urdf", "urdf_path", type=click.Path(dir_okay=False),
              help="Write the best design here (.urdf; several objectives: the front's best in the first).")
@click.option("--table", "table_path", type=click.Path(dir_okay=False),
              help="Every evaluation, its parameters and metrics, the best flagged (.nc or .csv).")
@click.option("--figure", "figure_path", type=click.Path(dir_okay=False),
              help="Maps of the start and the best design side by side (.png, .pdf or .svg).")
@click.option("--front-figure", "front_figure_path", type=click.Path(dir_okay=False),
              help="Several objectives: the Pareto front over every evaluation (.png, .pdf or .svg).")
@click.option("--vmin", type=float, default=None, help="--figure: lower end of the colour scale (index value).")
@click.option("--vmax", type=float, default=None, help="--figure: upper end of the colour scale (index value).")
@click.option("--closed-forms", is_flag=True, help="--permutations: score with the planar closed forms.")
@click.option("--scheduler", metavar="ADDRESS",
              help="Address of a running dask.distributed scheduler, e.g. tcp://host:8786 (default: local threads).")
@click.option("--connect-timeout", type=click.FloatRange(min=0, min_open=True), default=CONNECT_TIMEOUT,
              show_default=True,
              help="Seconds to wait for the --scheduler to answer.")
@length_unit_option
@json_option
@overwrite_option
@quiet_option
@click.pass_context
def design_search(context, study_path, **options) -> None:
    """Search designs for fault tolerance.

    FAMILY (planar_rrr, ups_hexapod, rss_hexapod, delta, prs_ups): vary the family's parameters to optimise one
    or more metrics of the fault-tolerant region of a map (differential evolution, or NSGA-II for
    a Pareto front), e.g. design-search ups_hexapod --objective area --budget 200, or
    design-search --study study.yaml. MECHANISM (a planar n-RRR): --permutations ranks every slot
    assignment (the paper's selection); --optimise searches the planar_rrr family from it.
    """
    if study_path:
        for name, value in read_study(study_path).items():
            given = context.get_parameter_source(name) not in (ParameterSource.DEFAULT, None)
            if not given:
                options[name] = value
    if options["mechanism"] is None:
        raise fail("Expected a FAMILY or MECHANISM argument (or a study file with a family).")
    _design_search(**options)


def _design_search(mechanism, search_permutations, optimise, legs, objectives, constraints, free, assignments, starts,
                   bound_texts, budget, seed, state, radius, grids, overs, layers, region_index, phi_step, top, level,
                   maxiter, popsize, step, urdf_path, table_path, figure_path, front_figure_path, vmin, vmax,
                   closed_forms, scheduler, connect_timeout, length_unit, as_json, overwrite, quiet) -> None:
    family_mode = mechanism in FAMILIES
    if family_mode and (search_permutations or optimise):
        raise fail(f"{mechanism} is a family: --permutations and --optimise take a mechanism (planar_5rrr, a file).")
    if not family_mode and search_permutations == optimise:
        raise fail(f"Expected a family ({', '.join(FAMILIES)}), or a mechanism with exactly one of --permutations "
                   "or --optimise.")
    if phi_step is not None and not 0 < phi_step <= 360:
        raise fail(f"Expected 0 < --phi-step <= 360 (deg), got {phi_step:g}.")
    if search_permutations and (urdf_path or figure_path or table_path or front_figure_path):
        raise fail("--urdf, --table, --figure and --front-figure go with a family search or --optimise.")
    searched = {"--objective": objectives, "--constraint": constraints, "--free": free, "--set": assignments,
                "--start": starts, "--bounds": bound_texts, "--budget": budget, "--state": state, "--grid": grids,
                "--over": overs, "--layers": layers, "--index": region_index, "--level": level, "--radius": radius,
                "--step": step, "--maxiter": maxiter}
    if search_permutations and any(value not in (None, ()) for value in searched.values()):
        raise fail(f"{', '.join(k for k, v in searched.items() if v not in (None, ()))} go with a family search or "
                   "--optimise, not --permutations.")
    if maxiter is not None and budget is not None:
        raise fail("Give --budget or --maxiter, not both.")
    check_outputs({"--urdf": (urdf_path, (".urdf",)), "--table": (table_path, DATA_SUFFIXES),
                   "--figure": (figure_path, FIGURE_SUFFIXES), "--front-figure": (front_figure_path, FIGURE_SUFFIXES)},
                  overwrite, quiet, others={"--state": state})
    check_colour_scale(vmin, vmax)
    if family_mode:
        try:
            chosen = family(mechanism, legs)
        except ValueError as error:
            raise fail(str(error)) from None
        fixed, initial = parse_assignments(chosen, assignments, "--set"), parse_assignments(chosen, starts, "--start")
    else:
        if legs is not None:
            raise fail("--legs goes with a family.")
        loaded = load_mechanism(mechanism, length_unit)
        try:
            template = search.planar_design(loaded)
        except ValueError as error:
            raise fail(str(error)) from None
        if search_permutations:
            current = tuple(int(s) for s in search.slots_of(template))
            with scheduler_client(scheduler, connect_timeout) as client:  # the handshake before any work
                try:
                    _permutations(loaded, template, current, 1.0 if phi_step is None else phi_step, closed_forms,
                                  client, connect_timeout, top, as_json, quiet)
                except ClusterError as error:
                    raise fail(str(error)) from None
            return
        try:
            count, values = search.family_values(template)
        except ValueError as error:
            raise fail(f"--optimise: {error}") from None
        chosen = family("planar_rrr", count)
        varied = free or chosen.free
        fixed = {name: value for name, value in values.items() if name not in varied}
        fixed.update(parse_assignments(chosen, assignments, "--set"))
        initial = {name: values[name] for name in varied if name not in fixed}
        initial.update(parse_assignments(chosen, starts, "--start"))
    try:
        start_mechanism = chosen.mechanism({**fixed, **initial}) if (grids or overs or layers) else None
    except ValueError as error:
        raise fail(f"The start design: {error}") from None
    region = region_of(chosen, start_mechanism, radius, step, phi_step, grids, overs, layers, region_index, level)
    varied_count = len(free or [n for n in chosen.free if n not in fixed])
    if maxiter is not None:
        budget = popsize * varied_count * (maxiter + 1)
    with scheduler_client(scheduler, connect_timeout) as client:  # the handshake before any work
        search_family(chosen, region, objectives=objectives, constraints=constraints,
                      free=free or [n for n in chosen.free if n not in fixed], fixed=fixed, initial=initial,
                      bounds=parse_bounds(chosen, bound_texts), budget=384 if budget is None else budget, seed=seed,
                      popsize=popsize, state=state, scheduler=client, connect_timeout=connect_timeout,
                      urdf_path=urdf_path, table_path=table_path, figure_path=figure_path,
                      front_figure_path=front_figure_path, vmin=vmin, vmax=vmax, as_json=as_json, quiet=quiet,
                      start_name=None if family_mode else loaded.name, top=top)
