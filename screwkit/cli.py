"""The ``screwkit`` command line.

Every command takes a MECHANISM: the name of a bundled robot (``screwkit list``) or the path
of a URDF file following docs/urdf-convention.md. Lengths are metres and angles degrees.
Errors are one line (``Error: ...``) with exit status 1.
"""

from __future__ import annotations

import json
import os
import sys

import click
import numpy as np

from screwkit.transmission import DEFAULT_THRESHOLD


class GreedyOption(click.Option):
    """An option taking every value up to the next option: ``--pose -0.2 0 45``.

    Negative numbers are values, not options. The values arrive joined by spaces.
    """

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("multiple", False)
        super().__init__(*args, **kwargs)
        self._previous_process = None

    def add_to_parser(self, parser, ctx):
        def process(value, state):
            values = [value]
            while state.rargs:
                token = state.rargs[0]
                if token.startswith("--") or (token.startswith("-") and not _is_number(token)):
                    break
                values.append(state.rargs.pop(0))
            self._previous_process(" ".join(values), state)

        result = super().add_to_parser(parser, ctx)
        for name in self.opts:
            our_parser = parser._long_opt.get(name) or parser._short_opt.get(name)
            if our_parser:
                self._previous_process = our_parser.process
                our_parser.process = process
        return result


def _is_number(token: str) -> bool:
    try:
        float(token)
    except ValueError:
        return False
    return True


def _load(name: str):
    from screwkit.mechanism import load

    try:
        return load(name)
    except ValueError as error:
        raise click.ClickException(str(error)) from None


def _floats(values, what: str) -> list[float]:
    try:
        return [float(v) for v in values]
    except ValueError:
        raise click.ClickException(f"Expected numbers after {what}, got {' '.join(values)}.") from None


def _pose(mechanism, values) -> np.ndarray:
    from screwkit.analysis import poses_from_degrees

    if values is None:  # the reference assembly of the file
        return np.asarray(mechanism.home_pose, dtype=float)
    values = values.split()
    numbers = _floats(values, "--pose")
    if len(numbers) != mechanism.n_task:
        raise click.ClickException(
            f"Expected --pose with {mechanism.n_task} values ({', '.join(mechanism.task_coordinates)}) for "
            f"mechanism {mechanism.name!r}, got {len(numbers)}: {' '.join(values)}.")
    try:
        return poses_from_degrees(mechanism, numbers)
    except ValueError as error:
        raise click.ClickException(str(error)) from None


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="screwkit")
def app() -> None:
    """Screw-theory transmission and fault-tolerance indices of redundantly actuated parallel robots."""


@app.command("list")
def list_command() -> None:
    """List the bundled mechanisms."""
    from screwkit.mechanism import bundled_names

    for name in bundled_names():
        click.echo(name)


def pose_report(mechanism, pose, result) -> dict:
    """The indices at one pose as a JSON-ready dictionary."""
    names = [f"{chain}:{joint}" for chain, joint in mechanism.actuators]
    angular = {"phi", "roll", "pitch", "yaw"}
    return {
        "mechanism": mechanism.name,
        "pose": {name: float(np.rad2deg(value)) + 0.0 if name in angular else float(value) + 0.0
                 for name, value in zip(mechanism.task_coordinates, pose)},
        "dof": result.dof,
        "actuators": names,
        "iti": float(result.iti),
        "iti_actuators": {name: float(v) for name, v in zip(names, result.iti_actuators)},
        "lmti": float(result.lmti),
        "f_o": {str(j): float(v) for j, v in result.f_o.items()},
        "f_io": {str(j): float(v) for j, v in result.f_io.items()},
        "worst_faults": {str(j): [names[i] for i in np.atleast_1d(v)] for j, v in result.worst_faults.items()},
        "not_mutual_interference": [name for name, ok in zip(names, result.mutual_interference) if not ok],
        "threshold_m": result.threshold,
    }


def _print_report(report: dict) -> None:
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


@app.command()
@click.argument("mechanism")
@click.option("--pose", cls=GreedyOption,
              help="Platform pose: x y phi (planar) or x y z roll pitch yaw; m and deg. Default: the file's home pose.")
@click.option("--threshold", type=float, default=DEFAULT_THRESHOLD, show_default=True,
              help="Singularity threshold p on the moment arm (m).")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object instead of the report.")
def analyze(mechanism: str, pose, threshold: float, as_json: bool) -> None:
    """Every index (ITI, LMTI, F_Oj, F_IOj) of MECHANISM at one pose."""
    from screwkit.analysis import analyze_pose

    loaded = _load(mechanism)
    target = _pose(loaded, pose)
    try:
        result = analyze_pose(loaded, target, threshold=threshold)
    except ValueError as error:
        raise click.ClickException(str(error)) from None
    report = pose_report(loaded, target, result)
    if as_json:
        click.echo(json.dumps(report))
    else:
        _print_report(report)


@app.command()
@click.argument("mechanism")
@click.option("--samples", type=click.IntRange(min=1), default=10_000, show_default=True,
              help="Random reachable configurations to compare.")
@click.option("--seed", type=int, default=0, show_default=True)
def verify(mechanism: str, samples: int, seed: int) -> None:
    """Compare the generic screw path with the paper's planar closed forms on random poses."""
    from screwkit.analysis import _closed_form_result, planar_points
    from screwkit.transmission import analyze as analyze_screws

    loaded = _load(mechanism)
    if not loaded.is_planar:
        raise click.ClickException(f"verify compares with the planar closed forms; {loaded.name!r} is spatial.")
    rng = np.random.default_rng(seed)
    home = np.asarray(loaded.home_pose, dtype=float)
    poses = home + np.column_stack([rng.uniform(-0.5, 0.5, samples * 4), rng.uniform(-0.5, 0.5, samples * 4),
                                    rng.uniform(-np.pi, np.pi, samples * 4)])
    solution = loaded.solve(poses)
    keep = np.flatnonzero(solution.reachable)[:samples]
    if keep.size == 0:
        raise click.ClickException("No reachable pose among the samples.")
    solution = loaded.solve(poses[keep])
    try:
        planar_points(loaded, solution)
    except ValueError as error:
        raise click.ClickException(str(error)) from None
    generic = analyze_screws(loaded.chain_screws(solution))
    closed = _closed_form_result(loaded, solution, DEFAULT_THRESHOLD, None, None)
    rows = [("ITI per actuator", generic.iti_actuators, closed.iti_actuators),
            ("OTI per submechanism", generic.oti_submechanisms, closed.oti_submechanisms),
            ("LMTI", generic.lmti, closed.lmti)]
    rows += [(f"F_O{j}", generic.f_o[j], closed.f_o[j]) for j in generic.f_o]
    rows += [(f"F_IO{j}", generic.f_io[j], closed.f_io[j]) for j in generic.f_io]
    click.echo(f"{loaded.name}: generic screw path vs closed forms (Eqs. 23, 34-38, A4) on {keep.size} poses")
    worst = 0.0
    for label, first, second in rows:
        deviation = float(np.max(np.abs(first - second)))
        worst = max(worst, deviation)
        click.echo(f"  {label:<22s} largest deviation {deviation:.2e}")
    click.echo(f"largest deviation: {worst:.2e}")
    if worst > 1e-9:
        sys.exit(1)


from screwkit.viewer import view  # noqa: E402  (light: meshcat and Pinocchio load when it runs)

app.add_command(view)


def main() -> None:
    """Console entry point: run the command, then end the process without the interpreter's teardown.

    Tearing down numba's compiler, Pinocchio and Dask takes about 0.3 s after every command,
    although each command has written, closed and flushed its results when it returns. The
    process then ends at once with the command's exit status, unless a Meshcat server started
    by ``view`` is still to be stopped by its finaliser (a normal exit runs it).
    """
    try:
        app()
        code = 0
    except SystemExit as stop:
        code = stop.code
    from screwkit.viewer import servers_to_stop

    if servers_to_stop():
        sys.exit(code)
    if code is not None and not isinstance(code, int):
        print(code, file=sys.stderr)
        code = 1
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code or 0)


def _write_outputs(dataset, out, figure_path, figure_function, quiet: bool = False) -> None:
    from screwkit.maps import write_dataset
    from screwkit.plots import save_figure

    if out:
        try:
            write_dataset(dataset, out)
        except ValueError as error:
            raise click.ClickException(str(error)) from None
        if not quiet:
            click.echo(f"wrote {out}", err=True)
    if figure_path:
        save_figure(figure_function(dataset), figure_path)
        if not quiet:
            click.echo(f"wrote {figure_path}", err=True)


def _range(text: str, name: str, angular: bool) -> np.ndarray:
    from screwkit.sweep import parse_range

    try:
        values = parse_range(text, name)
    except ValueError as error:
        raise click.ClickException(str(error)) from None
    return np.deg2rad(values) if angular else values


def _fixed_pose(mechanism, at) -> np.ndarray:
    """``--at``: all task coordinates, or for a planar mechanism just x y (phi from the home pose)."""
    home = np.asarray(mechanism.home_pose, dtype=float)
    if at is None:
        return home
    values = at.split()
    if mechanism.is_planar and len(values) == 2:
        values = values + [str(np.rad2deg(home[2]))]
    return _pose(mechanism, " ".join(values))


@app.command()
@click.argument("mechanism")
@click.option("--at", cls=GreedyOption, help="Fixed pose: all task coordinates (m, deg), or x y for a planar mechanism.")
@click.option("--phi", "phi_range", help="Planar shorthand for --sweep phi:START:STOP:STEP (deg).")
@click.option("--sweep", "sweep_spec", help="COORDINATE:START:STOP:STEP, e.g. yaw:0:360:1 (m or deg; stop exclusive).")
@click.option("--out", type=click.Path(dir_okay=False), help="Data file: .nc (netCDF) or .csv.")
@click.option("--figure", "figure_path", type=click.Path(dir_okay=False), help="Figure file (.png, .pdf, .svg).")
@click.option("--threshold", type=float, default=DEFAULT_THRESHOLD, show_default=True, help="Singularity threshold p (m).")
@click.option("--closed-forms", is_flag=True, help="Use the paper's planar closed forms instead of the generic path.")
def sweep(mechanism, at, phi_range, sweep_spec, out, figure_path, threshold, closed_forms) -> None:
    """Sweep one pose coordinate: every series of the paper's Figure 4 along it."""
    from screwkit.analysis import angular_coordinates
    from screwkit.plots import sweep_figure
    from screwkit.sweep import sweep as run_sweep

    loaded = _load(mechanism)
    if (phi_range is None) == (sweep_spec is None):
        raise click.ClickException("Expected exactly one of --phi START:STOP:STEP or --sweep COORDINATE:START:STOP:STEP.")
    if phi_range is not None:
        coordinate, text = "phi", phi_range
    else:
        coordinate, _, text = sweep_spec.partition(":")
    if coordinate not in loaded.task_coordinates:
        raise click.ClickException(f"Unknown coordinate {coordinate!r} to sweep; {loaded.name!r} has "
                                   f"{', '.join(loaded.task_coordinates)}.")
    angular = bool(angular_coordinates(loaded.task_coordinates)[loaded.task_coordinates.index(coordinate)])
    values = _range(text, "--phi" if phi_range else "--sweep", angular)
    try:
        dataset = run_sweep(loaded, _fixed_pose(loaded, at), coordinate, values, threshold=threshold,
                            closed_forms=closed_forms)
    except ValueError as error:
        raise click.ClickException(str(error)) from None
    reachable = dataset["reachable"].values
    click.echo(f"{loaded.name}: swept {coordinate} over {values.size} values ({int(reachable.sum())} reachable)")
    for name in ["iti", "lmti"] + [v for v in dataset.data_vars if v.startswith("f_o") or v.startswith("f_io")]:
        series = dataset[name].values
        if np.any(np.isfinite(series)):
            at_min = dataset[coordinate].values[np.nanargmin(series)]
            click.echo(f"  min {name:<6s} {np.nanmin(series):.4f} at {coordinate} = {at_min:g}")
    _write_outputs(dataset, out, figure_path, sweep_figure)


def _grid_spec(loaded, text: str):
    from screwkit.analysis import angular_coordinates

    name, _, rest = text.partition(":")
    if name not in loaded.task_coordinates:
        raise click.ClickException(f"Unknown coordinate {name!r} in {text!r}; {loaded.name!r} has "
                                   f"{', '.join(loaded.task_coordinates)}.")
    angular = bool(angular_coordinates(loaded.task_coordinates)[loaded.task_coordinates.index(name)])
    return name, _range(rest, text, angular)


@app.command("map")
@click.argument("mechanism")
@click.option("--radius", type=float, help="Planar: radius of the disc about the home position (m).")
@click.option("--step", type=float, help="Planar: grid step in x and y (m).")
@click.option("--phi-step", type=float, default=1.0, show_default=True, help="Planar: step of the full turn (deg).")
@click.option("--grid", "grids", multiple=True, help="Spatial: COORDINATE:START:STOP:STEP, given twice (x axis, y axis).")
@click.option("--over", "overs", multiple=True, help="Spatial: orientation set COORDINATE:START:STOP:STEP, repeatable.")
@click.option("--at", cls=GreedyOption, help="Spatial: the other coordinates (all task coordinates; default home).")
@click.option("--out", type=click.Path(dir_okay=False), help="netCDF file (.nc) or .csv.")
@click.option("--figure", "figure_path", type=click.Path(dir_okay=False), help="Figure file.")
@click.option("--threshold", type=float, default=DEFAULT_THRESHOLD, show_default=True, help="Singularity threshold p (m).")
@click.option("--closed-forms", is_flag=True, help="Use the paper's planar closed forms instead of the generic path.")
@click.option("--scheduler", help="Address of a running dask.distributed scheduler (default: local threads).")
@click.option("--quiet", is_flag=True, help="No progress output.")
def map_command(mechanism, radius, step, phi_step, grids, overs, at, out, figure_path, threshold, closed_forms,
                scheduler, quiet) -> None:
    """Minimum of every index over an orientation set at each point of a grid (Fig. 5).

    Planar: --radius R --step S --phi-step D maps a disc about the home position with phi
    over a full turn. Spatial: --grid x:-0.2:0.2:0.02 --grid y:-0.2:0.2:0.02
    --over yaw:0:360:15 [--over roll:-10:10:5] [--at x y z roll pitch yaw].
    """
    from screwkit.maps import index_map, planar_disc_map
    from screwkit.plots import map_figure

    loaded = _load(mechanism)
    progress = False if quiet else None
    start = __import__("time").perf_counter()
    try:
        if radius is not None or step is not None:
            if radius is None or step is None or grids or overs:
                raise click.ClickException("A planar map takes --radius and --step (and --phi-step), not --grid/--over.")
            dataset = planar_disc_map(loaded, radius, step, phi_step, threshold=threshold, closed_forms=closed_forms,
                                      scheduler=scheduler, progress=progress, as_dataset=False)
        else:
            if len(grids) != 2:
                raise click.ClickException("Expected --radius/--step (planar) or exactly two --grid options.")
            grid = dict(_grid_spec(loaded, g) for g in grids)
            over = dict(_grid_spec(loaded, o) for o in overs)
            dataset = index_map(loaded, grid, over, _fixed_pose(loaded, at), threshold=threshold,
                                closed_forms=closed_forms, scheduler=scheduler, progress=progress, as_dataset=False)
    except ValueError as error:
        raise click.ClickException(str(error)) from None
    elapsed = __import__("time").perf_counter() - start
    if not quiet:
        click.echo(f"{loaded.name}: {dataset.attrs['configurations']:,} configurations in {elapsed:.2f} s "
                   f"({dataset.attrs['method']})", err=True)
    _write_outputs(dataset, out, figure_path, map_figure, quiet)


@app.command("design-search")
@click.argument("mechanism")
@click.option("--permutations", "search_permutations", is_flag=True,
              help="Rank every assignment of platform slots to chains in both working modes (the paper's selection).")
@click.option("--optimise", is_flag=True, help="Maximise the fault-tolerant area over platform radius and arm lengths.")
@click.option("--phi-step", type=float, default=1.0, show_default=True, help="Step of the full rotation (deg).")
@click.option("--top", type=click.IntRange(min=1), default=12, show_default=True, help="Designs listed (report only).")
@click.option("--level", type=float, default=0.4, show_default=True, help="--optimise: F_O1 level of the area.")
@click.option("--maxiter", type=click.IntRange(min=1), default=15, show_default=True, help="--optimise: generations.")
@click.option("--popsize", type=click.IntRange(min=2), default=8, show_default=True, help="--optimise: population factor.")
@click.option("--step", type=float, default=0.05, show_default=True, help="--optimise: grid step of the area (m).")
@click.option("--urdf", "urdf_path", type=click.Path(dir_okay=False), help="--optimise: write the best design here.")
@click.option("--figure", "figure_path", type=click.Path(dir_okay=False), help="--optimise: maps of both designs.")
@click.option("--closed-forms", is_flag=True, help="--permutations: score with the planar closed forms.")
@click.option("--scheduler", help="Address of a running dask.distributed scheduler (default: local threads).")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object.")
@click.option("--quiet", is_flag=True, help="No progress output.")
def design_search(mechanism, search_permutations, optimise, phi_step, top, level, maxiter, popsize, step, urdf_path,
                  figure_path, closed_forms, scheduler, as_json, quiet) -> None:
    """Search planar n-RRR designs for fault tolerance (score: min of F_O1 over a full rotation at the centre)."""
    from screwkit import design as search

    loaded = _load(mechanism)
    if search_permutations == optimise:
        raise click.ClickException("Expected exactly one of --permutations or --optimise.")
    try:
        template = search.planar_design(loaded)
    except ValueError as error:
        raise click.ClickException(str(error)) from None
    current = tuple(int(s) for s in search.slots_of(template))
    if search_permutations:
        ranked = search.permutation_search(template, phi_step_degrees=phi_step, closed_forms=closed_forms,
                                           scheduler=scheduler, progress=False if quiet else None)
        best = ranked[0].score
        rows = [{"permutation": list(d.permutation), "working_mode": d.working_mode, "score": d.score,
                 "rank": 1 + sum(round(o.score, 9) > round(d.score, 9) for o in ranked if np.isfinite(o.score)),
                 "rotation_class": list(search.rotation_class(d.permutation))} for d in ranked]
        if as_json:
            click.echo(json.dumps({"mechanism": loaded.name, "current": list(current), "phi_step_deg": phi_step,
                                   "designs": rows}))
            return
        click.echo(f"{loaded.name}: {len(ranked)} designs (slot permutations x 2 working modes); score = min F_O1 "
                   f"over a full rotation at the centre, {phi_step:g} deg steps")
        click.echo(f"{'rank':>4s}  {'permutation':<18s} {'mode':>4s}  {'score':>7s}")
        for row in rows[:top]:
            mark = "  <- this file's design" if tuple(row["permutation"]) == current and row["working_mode"] == int(
                template.working_mode[0]) else ""
            click.echo(f"{row['rank']:>4d}  {str(row['permutation']):<18s} {row['working_mode']:>+4d}  "
                       f"{row['score']:.4f}{mark}")
        mine = next(r for r in rows if tuple(r["permutation"]) == current and r["working_mode"] == int(template.working_mode[0]))
        click.echo(f"this file's design {list(current)} ranks {mine['rank']} (best score {best:.4f})")
        return
    design, area, result = search.optimise_design(template, current, level=level, step=step, maxiter=maxiter,
                                                  popsize=popsize, phi_step_degrees=5.0)
    reference_area, reference_grid = search.fault_tolerant_area(template, level=level, step=step)
    _, best_grid = search.fault_tolerant_area(design, level=level, step=step)
    summary = {"mechanism": loaded.name, "level": level, "permutation": list(current),
               "reference": {"platform_radius": float(np.mean(np.linalg.norm(template.platform, axis=-1))),
                             "upper": float(template.upper[0]), "lower": float(template.lower[0]), "area_m2": reference_area},
               "optimised": {"platform_radius": float(result.x[0]), "upper": float(result.x[1]),
                             "lower": float(result.x[2]), "area_m2": area},
               "evaluations": int(result.nfev)}
    if urdf_path:
        from screwkit.robots.generate import planar_rrr_urdf

        text = planar_rrr_urdf(f"{loaded.name}_optimised", design.base, design.platform, design.upper, design.lower,
                               design.working_mode, comment=f" Optimised by screwkit design-search (optimise) "
                               f"(F_O1 >= {level} area {area:.4f} m^2) from {loaded.name} ")
        from screwkit.maps import _atomic_text

        _atomic_text(urdf_path, text)
        summary["urdf"] = urdf_path
    if figure_path:
        _design_figure(reference_grid, best_grid, step, level, loaded.name, figure_path)
        summary["figure"] = figure_path
    if as_json:
        click.echo(json.dumps(summary))
        return
    ref, opt = summary["reference"], summary["optimised"]
    click.echo(f"area where min F_O1 over a full rotation >= {level} (grid step {step} m):")
    click.echo(f"  {loaded.name}: g = {ref['platform_radius']:.3f} m, a = {ref['upper']:.3f} m, l = {ref['lower']:.3f} m"
               f" -> {ref['area_m2']:.4f} m^2")
    click.echo(f"  optimised: g = {opt['platform_radius']:.3f} m, a = {opt['upper']:.3f} m, l = {opt['lower']:.3f} m"
               f" -> {opt['area_m2']:.4f} m^2  ({summary['evaluations']} evaluations)")


def _design_figure(reference, optimised, step, level, name, path) -> None:
    from screwkit.plots import _pyplot, save_figure

    plt = _pyplot()
    figure, axes = plt.subplots(1, 2, figsize=(8, 3.6), constrained_layout=True)
    extent = step * (reference.shape[0] // 2)
    for ax, grid, title in ((axes[0], reference, name), (axes[1], optimised, "optimised")):
        image = ax.imshow(np.ma.masked_invalid(grid), origin="lower", extent=(-extent, extent, -extent, extent),
                          cmap="jet", vmin=0, vmax=1)
        ax.contour(np.linspace(-extent, extent, grid.shape[1]), np.linspace(-extent, extent, grid.shape[0]),
                   np.nan_to_num(grid), levels=[level], colors="white", linewidths=1.2)
        ax.set_title(f"{title}: min F_O1 over rotation", fontsize=9)
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
    figure.colorbar(image, ax=axes, shrink=0.8)
    save_figure(figure, path)


if __name__ == "__main__":  # python -m screwkit.cli
    main()
