"""``screwkit design-search FAMILY``: search a parametric family (one objective or a Pareto front)."""

from __future__ import annotations

import json
import math
import shlex

import click
import numpy as np

from screwkit.cli.map_command import grid_spec
from screwkit.cli.options import echo_error, fail
from screwkit.common.units import is_angular
from screwkit.studies.design.families import Family
from screwkit.studies.design.objectives import METRICS, default_region, region_maps
from screwkit.studies.design.optimise import Constraint, StateError, Study, run_study
from screwkit.studies.tasks import ClusterError

__all__ = ["parse_assignments", "parse_bounds", "region_of", "search_family", "STUDY_KEYS", "read_study"]

STUDY_KEYS = {"family": "mechanism", "legs": "legs", "objectives": "objectives", "constraints": "constraints",
              "free": "free", "set": "assignments", "start": "starts", "bounds": "bound_texts", "budget": "budget",
              "seed": "seed", "popsize": "popsize", "radius": "radius", "step": "step", "phi_step": "phi_step",
              "grid": "grids", "over": "overs", "layers": "layers", "index": "region_index", "level": "level"}
"""Keys of a study file and the option each stands for (``set``, ``start``: name -> value; ``bounds``:
name -> [lower, upper]; ``objectives``, ``constraints``, ``free``, ``grid``, ``over``: lists)."""


def read_study(path: str) -> dict:
    """A study file (YAML or JSON) as option values: {option destination: value as the option gives it}."""
    import yaml

    try:
        with open(path, encoding="utf-8") as file:
            content = yaml.safe_load(file)
    except OSError as error:
        raise fail(f"Cannot read the study file {path}: {error.strerror}.") from None
    except yaml.YAMLError as error:
        raise fail(f"Cannot read the study file {path}: {str(error).splitlines()[0]}.") from None
    if not isinstance(content, dict):
        raise fail(f"Expected the study file {path} to hold a mapping of keys ({', '.join(STUDY_KEYS)}).")
    out = {}
    for key, value in content.items():
        if key not in STUDY_KEYS:
            raise fail(f"Unknown key {key!r} in the study file {path}; keys: {', '.join(STUDY_KEYS)}.")
        if key in ("set", "start", "bounds"):
            if not isinstance(value, dict):
                raise fail(f"Expected {key!r} in the study file {path} to map parameter names to values.")
            value = tuple(f"{name}={':'.join(map(str, v)) if isinstance(v, (list, tuple)) else v}"
                          for name, v in value.items())
        elif key in ("objectives", "constraints", "free", "grid", "over"):
            value = tuple(str(v) for v in (value if isinstance(value, (list, tuple)) else [value]))
        out[STUDY_KEYS[key]] = value
    return out


def parse_assignments(family: Family, texts, option: str) -> dict[str, float]:
    """``NAME=VALUE`` options -> {name: value} (checked against the family's bounds)."""
    values = {}
    for text in texts:
        name, equals, value = text.partition("=")
        if not equals:
            raise fail(f"Expected {option} NAME=VALUE, got {text!r}.")
        try:
            values[name.strip()] = family.parameter(name.strip()).check(float(value), option)
        except ValueError as error:
            raise fail(f"{option} {text}: {error}") from None
    return values


def parse_bounds(family: Family, texts) -> dict[str, tuple[float, float]]:
    """``NAME=LOWER:UPPER`` options -> {name: (lower, upper)}."""
    bounds = {}
    for text in texts:
        name, equals, rest = text.partition("=")
        lower, colon, upper = rest.partition(":")
        try:
            if not (equals and colon):
                raise ValueError("expected NAME=LOWER:UPPER")
            family.parameter(name.strip())
            bounds[name.strip()] = (float(lower), float(upper))
        except ValueError as error:
            raise fail(f"--bounds {text}: {error}") from None
    return bounds


def _spec(mechanism, text: str, option: str) -> tuple[str, tuple[float, float, float]]:
    name, _ = grid_spec(mechanism, text, option, True)  # the checks and messages of screwkit map
    start, stop, step = (float(part) for part in text.split(":")[1:])
    return name, (start, stop, step)


def region_of(family: Family, start_mechanism, radius, step, phi_step, grids, overs, layers, index, level):
    """The search's region: the family's default, changed by the region options."""
    changes = {"index": index, "level": level}
    if radius is not None or step is not None or phi_step is not None:
        if not family.planar:
            raise fail("--radius, --step and --phi-step map a planar family's disc; give --grid and --over.")
        disc = family.region["disc"]
        changes["disc"] = (disc[0] if radius is None else radius, disc[1] if step is None else step,
                           disc[2] if phi_step is None else phi_step)
    if grids or overs or layers:  # each given part replaces the family's default, the others stay
        if family.planar:
            raise fail("A planar family's region is a disc (--radius, --step, --phi-step), not --grid/--over.")
        if grids:
            if len(grids) != 2:
                raise fail("Expected exactly two --grid options (the region's map).")
            changes["grid"] = dict(_spec(start_mechanism, g, "--grid") for g in grids)
        if overs:
            changes["over"] = dict(_spec(start_mechanism, o, "--over") for o in overs)
        if layers:
            changes["layers"] = _spec(start_mechanism, layers, "--layers")
    try:
        return default_region(family, **changes)
    except ValueError as error:
        raise fail(str(error)) from None


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


def _write_outputs(result, urdf_path, table_path, figure_path, front_figure_path, vmin, vmax, summary, start_name):
    from screwkit.plots import design_comparison_figure, pareto_figure, save_figure  # matplotlib: on use only
    from screwkit.studies.files import atomic_text, write_dataset  # netCDF writers: on use only

    study, best = result.study, result.best[0]
    if urdf_path:
        atomic_text(urdf_path, study.family.urdf(best["values"], f"{study.family.name}_{study.family.legs}_best"))
        summary["files"].append(urdf_path)
    if table_path:
        write_dataset(_table(result), table_path)
        summary["files"].append(table_path)
    if figure_path:
        region = study.region
        layer = 0 if not region.layers else region.layers[1].size // 2  # with layers: the middle one
        grids = [region_maps(study.family.mechanism(r["values"]), region)[region.index][layer]
                 for r in (result.start, best)]
        step = float(region.grid[0][1][1] - region.grid[0][1][0])
        units = {name: "rad" if is_angular(name) else "m" for name, _ in region.grid}
        figure = design_comparison_figure(*grids, step, region.level, start_name, vmin=vmin,
                                          vmax=vmax, index=region.index, over=region.orientations,
                                          axes_labels=[f"{name} ({unit})" for name, unit in units.items()],
                                          area_unit=region.unit("area").replace("^2", "\u00b2"),
                                          coordinates=None if region.mask is not None else
                                          [values for _, values in region.grid])
        save_figure(figure, figure_path)
        summary["files"].append(figure_path)
    if front_figure_path:
        save_figure(pareto_figure(result), front_figure_path)
        summary["files"].append(front_figure_path)


def search_family(family: Family, region, *, objectives, constraints, free, fixed, initial, bounds, budget, seed,
                  popsize, state, scheduler, connect_timeout, urdf_path, table_path, figure_path, front_figure_path,
                  vmin, vmax, as_json, quiet, start_name=None, top=12) -> None:
    """Run the search and report it (the body of ``design-search FAMILY``)."""
    try:
        study = Study(family, region, tuple(objectives) or ("area",), free=tuple(free) or None, fixed=fixed,
                      initial=initial, bounds=bounds, constraints=tuple(Constraint.parse(c) for c in constraints),
                      budget=budget, seed=seed, popsize=popsize)
    except ValueError as error:
        raise fail(str(error)) from None
    if front_figure_path and len(study.objectives) < 2:
        raise fail("--front-figure needs two or more --objective.")
    if not quiet:
        echo_error(f"{family.name} ({family.legs} legs): {budget} evaluations of {', '.join(study.free)}; "
                   f"region {region.describe()}")
    try:
        result = run_study(study, scheduler=scheduler, progress=False if quiet else None, state=state,
                           connect_timeout=connect_timeout, notify=None if quiet else echo_error)
    except (StateError, ClusterError) as error:
        raise fail(str(error)) from None
    if not result.best:
        start = result.start["metrics"]
        raise fail(f"No evaluated design meets {', '.join(map(str, study.constraints))}; the start has "
                   + ", ".join(f"{c.metric} = {start[c.metric]:g}" for c in study.constraints) + ".")
    map_options = region.map_arguments(family.mechanism(result.best[0]["values"]))
    summary = {"family": family.name, "legs": family.legs, "objectives": list(study.objectives),
               "constraints": [str(c) for c in study.constraints], "free": list(study.free), "seed": seed,
               "budget": budget, "region": region.describe(),
               "map_commands": [f"screwkit map {shlex.quote(str(urdf_path or 'BEST.urdf'))} {shlex.join(options)}"
                                for options in map_options],
               "evaluations": len(result.evaluations), "computed": result.computed, "replayed": result.replayed,
               "start": _record(result.start), "best": [_record(r) for r in result.best], "files": []}
    _write_outputs(result, urdf_path, table_path, figure_path, front_figure_path, vmin, vmax, summary,
                   start_name or f"{family.name} start")
    if as_json:
        click.echo(json.dumps(summary))
    else:
        _print(summary, study, top)
    if not quiet:
        for path in summary["files"]:
            echo_error(f"wrote {path}")


def _print(summary: dict, study: Study, top: int) -> None:
    def line(record):
        values = ", ".join(f"{name} = {record['values'][name]:.4g}" for name in study.free)
        scores = ", ".join(f"{name} = {_shown(record['metrics'][name])}" for name in study.objectives)
        return f"{values} -> {scores}"

    click.echo(f"{summary['family']} ({summary['legs']} legs), {summary['evaluations']} evaluations "
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
