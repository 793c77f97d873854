"""``screwkit design-search``: the paper's permutation selection, and optimising a planar n-RRR."""

from __future__ import annotations

import json

import click
import numpy as np

from screwkit.cli.options import (
    check_outputs,
    echo_error,
    fail,
    json_option,
    length_unit_option,
    load_mechanism,
    mechanism_argument,
    overwrite_option,
    quiet_option,
)
from screwkit.model.urdf_writer import planar_rrr_urdf
from screwkit.plots import design_comparison_figure, save_figure
from screwkit.studies import design as search
from screwkit.studies.files import atomic_text
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


def _optimise(loaded, template, current, level, step, maxiter, popsize, urdf_path, figure_path, vmin, vmax, as_json,
              quiet):

    design, area, result = search.optimise_design(template, current, level=level, step=step, maxiter=maxiter,
                                                  popsize=popsize, phi_step_degrees=5.0)
    reference_area, reference_grid = search.fault_tolerant_area(template, level=level, step=step)
    _, best_grid = search.fault_tolerant_area(design, level=level, step=step)
    summary = {"mechanism": loaded.name, "level": level, "permutation": list(current),
               "parameters": {"platform_radius": "radius g of the circle of platform joints (m)",
                              "upper": "length a of every proximal (upper) arm (m)",
                              "lower": "length l of every distal (lower) arm (m)"},
               "reference": {"platform_radius": float(np.mean(np.linalg.norm(template.platform, axis=-1))),
                             "upper": float(template.upper[0]), "lower": float(template.lower[0]),
                             "area_m2": reference_area},
               "optimised": {"platform_radius": float(result.x[0]), "upper": float(result.x[1]),
                             "lower": float(result.x[2]), "area_m2": area},
               "evaluations": int(result.nfev), "files": []}
    if urdf_path:
        text = planar_rrr_urdf(f"{loaded.name}_optimised", design.base, design.platform, design.upper, design.lower,
                               design.working_mode, comment=f" Optimised by screwkit design-search (optimise) "
                               f"(F_O1 >= {level} area {area:.4f} m^2) from {loaded.name} ")
        atomic_text(urdf_path, text)
        summary["files"].append(urdf_path)
    if figure_path:
        save_figure(design_comparison_figure(reference_grid, best_grid, step, level, loaded.name, vmin=vmin, vmax=vmax),
                    figure_path)
        summary["files"].append(figure_path)
    if as_json:
        click.echo(json.dumps(summary))
    else:
        ref, opt = summary["reference"], summary["optimised"]
        click.echo(f"area where the minimum of F_O1 over a full rotation is >= {level} (grid step {step} m), over the "
                   "platform radius g, the proximal arm length a and the distal arm length l:")
        click.echo(f"  {loaded.name}: g = {ref['platform_radius']:.3f} m, a = {ref['upper']:.3f} m, "
                   f"l = {ref['lower']:.3f} m -> {ref['area_m2']:.4f} m^2")
        click.echo(f"  optimised: g = {opt['platform_radius']:.3f} m, a = {opt['upper']:.3f} m, "
                   f"l = {opt['lower']:.3f} m -> {opt['area_m2']:.4f} m^2  ({summary['evaluations']} evaluations)")
    if not quiet:
        for path in summary["files"]:
            echo_error(f"wrote {path}")


@click.command("design-search")
@mechanism_argument
@click.option("--permutations", "search_permutations", is_flag=True,
              help="Rank every assignment of platform slots to chains in both working modes (the paper's selection).")
@click.option("--optimise", is_flag=True,
              help="Maximise the fault-tolerant area over the platform radius and the proximal and distal arm lengths.")
@click.option("--phi-step", type=float, default=1.0, show_default=True, help="Step of the full rotation (deg).")
@click.option("--top", type=click.IntRange(min=1), default=12, show_default=True, help="Designs listed (count).")
@click.option("--level", type=float, default=0.4, show_default=True,
              help="--optimise: the F_O1 level that makes a position fault tolerant (index value).")
@click.option("--maxiter", type=click.IntRange(min=1), default=15, show_default=True,
              help="--optimise: generations of differential evolution (count).")
@click.option("--popsize", type=click.IntRange(min=2), default=8, show_default=True,
              help="--optimise: population size per parameter (count).")
@click.option("--step", type=float, default=0.05, show_default=True, help="--optimise: grid step of the area (m).")
@click.option("--urdf", "urdf_path", type=click.Path(dir_okay=False),
              help="--optimise: write the best design here (.urdf).")
@click.option("--figure", "figure_path", type=click.Path(dir_okay=False),
              help="--optimise: maps of both designs (.png, .pdf or .svg).")
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
def design_search(mechanism, search_permutations, optimise, phi_step, top, level, maxiter, popsize, step, urdf_path,
                  figure_path, vmin, vmax, closed_forms, scheduler, connect_timeout, length_unit, as_json, overwrite,
                  quiet) -> None:
    """Search planar n-RRR designs for fault tolerance (score: min of F_O1 over a full rotation at the centre)."""

    if search_permutations == optimise:
        raise fail("Expected exactly one of --permutations or --optimise.")
    if not 0 < phi_step <= 360:
        raise fail(f"Expected 0 < --phi-step <= 360 (deg), got {phi_step:g}.")
    if search_permutations and (urdf_path or figure_path):
        raise fail("--urdf and --figure go with --optimise.")
    check_outputs({"--urdf": (urdf_path, (".urdf",)), "--figure": (figure_path, (".png", ".pdf", ".svg"))},
                  overwrite, quiet)
    loaded = load_mechanism(mechanism, length_unit)
    try:
        template = search.planar_design(loaded)
    except ValueError as error:
        raise fail(str(error)) from None
    current = tuple(int(s) for s in search.slots_of(template))
    if search_permutations:

        try:
            _permutations(loaded, template, current, phi_step, closed_forms, scheduler, connect_timeout, top, as_json,
                          quiet)
        except ClusterError as error:
            raise fail(str(error)) from None
    else:
        _optimise(loaded, template, current, level, step, maxiter, popsize, urdf_path, figure_path, vmin, vmax,
                  as_json, quiet)
