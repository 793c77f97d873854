"""``screwkit design-search family`` and ``optimise``: run a search of a parametric family and report it
(one objective or a Pareto front)."""

from __future__ import annotations

import json
import math
import shlex

import click
import numpy as np

from screwkit.cli.design_options import DesignOutputs, Report
from screwkit.cli.options import echo_error, fail
from screwkit.common.units import is_angular
from screwkit.studies.design.objectives import METRICS, region_maps
from screwkit.studies.design.optimise import EvaluationError, StateError, Study, run_study
from screwkit.studies.tasks import ClusterError, Execution

__all__ = ["run_search"]


def _clean(value):
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def _record(record: dict) -> dict:
    return {"values": record["values"], "metrics": {k: _clean(v) for k, v in record["metrics"].items()}}


def _table(result):
    """Every evaluation as a dataset (dimension ``evaluation``)."""
    import xarray as xr

    study = result.study
    front = {id(r) for r in result.best}
    records = result.evaluations
    data = {name: ("evaluation", [r["values"][name] for r in records]) for name in study.family.defaults()}
    data.update({name: ("evaluation", [r["metrics"][name] for r in records]) for name in METRICS})
    data["feasible"] = ("evaluation", np.array([r["feasible"] for r in records], dtype=np.int8))
    data["best"] = ("evaluation", np.array([id(r) in front for r in records], dtype=np.int8))
    dataset = xr.Dataset(data, coords={"evaluation": np.arange(len(records))})
    for name in study.family.defaults():
        dataset[name].attrs.update(units=study.family.parameter(name).unit,
                                   long_name=study.family.parameter(name).description)
    for name, meaning in METRICS.items():
        dataset[name].attrs.update(long_name=meaning)
    dataset.attrs.update(family=study.family.name, legs=study.family.legs, objectives=", ".join(study.objectives),
                         constraints=", ".join(map(str, study.constraints)) or "none", region=study.region.describe(),
                         seed=study.seed, budget=study.budget)
    return dataset


def _comparison(result, outputs: DesignOutputs, start_name: str):
    """The figure of the start's and the best design's maps (a start that cannot be built: reachable nowhere)."""
    from screwkit.plots import MapGrid, design_comparison_figure  # matplotlib: on use

    study = result.study
    region = study.region
    layer = 0 if not region.layers else region.layers[1].size // 2  # with layers: the middle one
    best = region_maps(study.family.mechanism(result.best[0]["values"]), region)[region.index][layer]
    if "error" in result.start["metrics"]:
        start, start_name = np.full_like(best, np.nan), f"{start_name} (cannot be built)"
    else:
        start = region_maps(study.family.mechanism(result.start["values"]), region)[region.index][layer]
    step = float(region.steps[0])
    units = {name: "rad" if is_angular(name) else "m" for name, _ in region.grid}
    layout = MapGrid(step, coordinates=None if region.mask is not None else [values for _, values in region.grid],
                     axes_labels=[f"{name} ({unit})" for name, unit in units.items()],
                     area_unit=region.unit("area").replace("^2", "\u00b2"))
    return design_comparison_figure(start, best, layout, region.level, start_name, vmin=outputs.vmin,
                                    vmax=outputs.vmax, index=region.index, over=region.orientations)


def _write_outputs(result, outputs: DesignOutputs, summary: dict, start_name: str) -> None:
    """Every output made first, then written: a failure while making one writes none."""
    from screwkit.plots import pareto_figure, save_figure  # matplotlib: on use
    from screwkit.studies.files import atomic_text, write_dataset  # netCDF writers: on use only

    study, best = result.study, result.best[0]
    urdf = study.family.urdf(best["values"], f"{study.family.name}_{study.family.legs}_best") if outputs.urdf else None
    table = _table(result) if outputs.table else None
    figure = _comparison(result, outputs, start_name) if outputs.figure else None
    front = pareto_figure(result) if outputs.front_figure else None
    writes = ((outputs.urdf, lambda path: atomic_text(path, urdf)),
              (outputs.table, lambda path: write_dataset(table, path)),
              (outputs.figure, lambda path: save_figure(figure, path)),
              (outputs.front_figure, lambda path: save_figure(front, path)))
    for path, write in writes:
        if path:
            write(path)
            summary["files"].append(path)


def run_search(study: Study, state: str | None, execution: Execution, outputs: DesignOutputs, report: Report,
               start_name: str | None = None) -> None:
    """Run the search and report it (the body of ``design-search family`` and ``design-search optimise``)."""
    family, region = study.family, study.region
    if outputs.front_figure and len(study.objectives) < 2:
        raise fail("--front-figure needs two or more --objective.")
    if not report.quiet:
        planned = study.planned_evaluations
        if not study.budget:
            searched = f"the start design alone ({', '.join(study.free)} not varied, --budget 0)"
        else:
            rounded = (f" (--budget {study.budget} in whole generations of {study.generation})"
                       if planned != study.budget else "")
            searched = f"up to {planned} evaluations{rounded} of {', '.join(study.free)}"
        echo_error(f"{family.name} ({family.legs} legs): {searched}; region {region.describe()}")
    try:
        result = run_study(study, execution=execution, state=state, notify=None if report.quiet else echo_error)
    except (StateError, ClusterError, EvaluationError) as error:
        raise fail(str(error)) from None
    if not result.best:
        raise fail(_nothing_found(result))
    map_options = region.map_arguments(family.mechanism(result.best[0]["values"]))
    summary = {"family": family.name, "legs": family.legs, "objectives": list(study.objectives),
               "constraints": [str(c) for c in study.constraints], "free": list(study.free), "seed": study.seed,
               "budget": study.budget, "region": region.describe(),
               "map_commands": [f"screwkit map {shlex.quote(str(outputs.urdf or 'BEST.urdf'))} {shlex.join(options)}"
                                for options in map_options],
               "evaluations": len(result.evaluations), "computed": result.computed, "replayed": result.replayed,
               "start": _record(result.start), "best": [_record(r) for r in result.best], "files": []}
    _write_outputs(result, outputs, summary, start_name or f"{family.name} start")
    if report.as_json:
        click.echo(json.dumps(summary))
    else:
        _print(summary, study, report.top)
    if not report.quiet:
        for path in summary["files"]:
            echo_error(f"wrote {path}")


def _nothing_found(result) -> str:
    """Why a search has no best design: none of its designs can be built, or none meets the constraints."""
    study, start = result.study, result.start["metrics"]
    count = len(result.evaluations)
    if all("error" in r["metrics"] for r in result.evaluations):
        evaluated = "the start alone evaluated" if count == 1 else f"{count} evaluated"
        return f"No design evaluated can be built ({evaluated}); the start: {start['error']}"
    had = (f"cannot be built: {start['error']}" if "error" in start else "has " + ", ".join(
        f"{c.metric} = {start[c.metric]:g}" for c in study.constraints) + ".")
    return f"No evaluated design meets {', '.join(map(str, study.constraints))}; the start {had}"


def _print(summary: dict, study: Study, top: int) -> None:
    def line(record):
        values = ", ".join(f"{name} = {record['values'][name]:.4g}" for name in study.free)
        scores = ", ".join(f"{name} = {_shown(record['metrics'][name])}" for name in study.objectives)
        return f"{values} -> {scores}" + (" (cannot be built)" if "error" in record["metrics"] else "")

    count = summary["evaluations"]
    click.echo(f"{summary['family']} ({summary['legs']} legs), {count} evaluation{'' if count == 1 else 's'} "
               f"({summary['computed']} computed, {summary['replayed']} from the state file), seed {summary['seed']}")
    click.echo(f"  start: {line(summary['start'])}")
    if len(study.objectives) == 1:
        click.echo(f"  best:  {line(summary['best'][0])}")
    else:
        front = summary["best"]
        shown = front if len(front) <= top else [front[round(i * (len(front) - 1) / (top - 1))] for i in range(top)]
        more = f", {len(shown)} of them shown: all in --json and --table" if len(shown) < len(front) else ""
        click.echo(f"  Pareto front ({len(front)} designs{more}):")
        for record in shown:
            click.echo(f"    {line(record)}")
    click.echo("  the best design's map: " + summary["map_commands"][0])


def _shown(value) -> str:
    return "n/a" if value is None else f"{value:.4g}"
