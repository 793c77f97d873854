"""``screwkit trajectory``: every index along a path, and what each actuator failure leaves controllable."""

from __future__ import annotations

import json
import os
from dataclasses import dataclass

import click
import numpy as np

from screwkit.cli.options import (
    GreedyOption,
    Outputs,
    analysis_options,
    check_average,
    echo_error,
    fail,
    json_option,
    load_mechanism,
    mechanism_argument,
    option_group,
    outputs_options,
    parse_pose,
    quiet_option,
    reading_options,
)
from screwkit.studies.actuator_paths import read_actuator_path
from screwkit.studies.files import write_dataset
from screwkit.studies.path_mechanisms import check_path_size, path_mechanism
from screwkit.studies.paths import PathFileError, checked_tolerance, circle_path, line_path, read_path, through_path
from screwkit.studies.tables import wide_csv
from screwkit.studies.trajectory import trajectory as run_trajectory

__all__ = ["trajectory", "generated_path", "print_summary", "PathSource", "FaultOptions", "line_option",
           "circle_option", "through_option", "samples_option"]

DEFAULT_SAMPLES = 201


def _poses(mechanism, words: list[str], count: int, option: str, label: str | None = None) -> list[np.ndarray]:
    """``count`` poses from words: named poses, or ``count`` times every task coordinate (m, deg); ``label``, what a
    single pose is called in a message (``option``'s first pose, second pose, ... by default)."""
    ordinals = ("first pose", "second pose") if count == 2 else [f"pose {i + 1}" for i in range(count)]
    labels = [label or option] if count == 1 else [f"{option}'s {ordinal}" for ordinal in ordinals]
    if len(words) == count and not any(_number(word) for word in words):
        return [parse_pose(mechanism, word, label) for word, label in zip(words, labels)]
    n = mechanism.n_task
    if len(words) != count * n or not all(_number(word) for word in words):
        units = _units(mechanism)
        raise fail(f"Expected {option} with {count} named pose(s) or {count} x {n} numbers ({units}) for "
                   f"{mechanism.name!r}, got {' '.join(words) or 'nothing'}.")
    return [parse_pose(mechanism, " ".join(words[i * n:(i + 1) * n]), labels[i]) for i in range(count)]


def _units(mechanism) -> str:
    """The task coordinates with the units a pose is given in on the command line: ``x (m), y (m), phi (deg)``."""
    return ", ".join(f"{c} ({'deg' if a else 'm'})" for c, a in zip(mechanism.task_coordinates, mechanism.angular))


def _number(word: str) -> bool:
    try:
        float(word)
    except ValueError:
        return False
    return True


def generated_path(mechanism, source: PathSource):
    """``--line A B``, ``--circle CENTRE RADIUS`` or ``--through POSE POSE ...`` with ``--samples``, as a
    :class:`~screwkit.studies.paths.Path`."""
    samples = source.samples
    try:
        if source.line is not None:
            start, stop = _poses(mechanism, source.line.split(), 2, "--line")
            return line_path(mechanism, start, stop, samples)
        if source.through is not None:
            return through_path(mechanism, _through(mechanism, source.through.split()), samples)
        words = source.circle.split()
        if len(words) < 2 or not _number(words[-1]):
            raise fail(f"Expected --circle CENTRE RADIUS (a named pose or every task coordinate, then the radius in "
                       f"m), got {source.circle!r}.")
        n = mechanism.n_task
        if all(_number(word) for word in words) and len(words) != n + 1:
            units = _units(mechanism)
            raise fail(f"Expected --circle with the centre's {n} task coordinates ({units}) then the radius (m), "
                       f"{n + 1} numbers, got {len(words)}{' (no radius)' if len(words) == n else ''}: "
                       f"{source.circle}.")
        (centre,) = _poses(mechanism, words[:-1], 1, "--circle", "--circle's centre")
        radius = float(words[-1])
        if not (np.isfinite(radius) and radius > 0):
            raise fail(f"Expected --circle's radius > 0 (m), got {words[-1]}.")
        return circle_path(mechanism, centre, radius, samples)
    except ValueError as error:
        raise fail(str(error)) from None


def _through(mechanism, words: list[str]) -> list[np.ndarray]:
    """The poses of ``--through``: named poses, or every task coordinate of each pose in turn; at least two."""
    n = mechanism.n_task
    numbers = any(_number(word) for word in words)
    count = len(words) // n if numbers else len(words)
    if count < 2 or (numbers and len(words) % n):
        units = _units(mechanism)
        raise fail(f"Expected --through with at least 2 poses (named poses, or {n} numbers each: {units}) for "
                   f"{mechanism.name!r}, got {' '.join(words) or 'nothing'}.")
    return _poses(mechanism, words, count, "--through")


def print_summary(summary: dict) -> None:
    """The summary of a trajectory on stderr: margins, every failure's lost stretches, worst failures, events."""
    echo_error(f"{summary['mechanism']}: {summary['samples']} samples, {summary['length_m']:.6g} m of path "
               f"{summary['arc_length']} (angles weighted by {summary['length_scale_m']:.6g} m/rad), "
               f"{summary['reachable_samples']} "
               f"reachable; level {summary['level']:g}, tolerance {summary['tolerance_m']:.3g} m")
    for event in summary["events"]:
        if event["kind"] == "branch":
            echo_error(f"  BRANCH CHANGE: {event['reason']}")
            continue
        if event["kind"] == "singular":
            echo_error(f"  SINGULAR at {event['start_m']:.6g} m: {event['reason']}")
            continue
        echo_error(f"  {'UNREACHABLE' if event['kind'] == 'closure' else 'JOINT LIMIT'} from "
                   f"{event['start_m']:.6g} m to {event['stop_m']:.6g} m (samples {event['samples'][0]}-"
                   f"{event['samples'][1]}): {event['reason']}")
    for name, margin in summary["margins"].items():
        where = f"sample {margin['sample']}" if margin["sample"] is not None else "refined between samples"
        echo_error(f"  min {name:<11s} {margin['value']:.4f} at {margin['arc_length_m']:.6g} m ({where})")
    for case in summary["faults"]:
        if case["actuators_left"] < summary["dof"]:  # F_Oj = 0 at every pose by definition: no sample list
            left = case["actuators_left"]
            echo_error(f"  fail {'+'.join(case['failed'])}: uncontrolled all along (the {left} actuator"
                       f"{'s' * (left != 1)} left cannot hold the {summary['dof']} DOF, so F_O{case['j']} = 0)")
            continue
        lost = ", ".join(f"[{a:.6g}, {b:.6g}]" for a, b in case["lost_m"]) or "never"
        first = "" if case["first_loss_m"] is None else f", first at {case['first_loss_m']:.6g} m"
        singular = "" if not case["singular_at_m"] else \
            ", singular at " + ", ".join(f"{z:.6g}" for z in case["singular_at_m"]) + " m"
        minimum = "n/a" if case["minimum"] is None else f"{case['minimum']:.4f}"
        echo_error(f"  fail {'+'.join(case['failed'])}: min {minimum}; lost {lost}{first}{singular}")
    for j, ties in summary["worst"].items():
        echo_error(f"  worst {j} failure(s) for this path: " + ("; ".join("+".join(t) for t in ties) or "none"))


@dataclass(frozen=True)
class PathSource:
    """Where the path comes from: a file (PATH: poses, or actuator values with ``--actuators``), or ``--line``,
    ``--circle`` or ``--through`` with ``--samples``."""

    path_file: str | None = None
    line: str | None = None
    circle: str | None = None
    through: str | None = None
    samples: int = DEFAULT_SAMPLES
    actuators: bool = False
    file_option: str = "PATH"  # (how the command names the file: `view` takes it as --path)

    def check(self) -> None:
        """Exactly one source, and a file that exists, before the mechanism is even loaded."""
        given = [name for name, value in (("PATH", self.path_file), ("--line", self.line), ("--circle", self.circle),
                                          ("--through", self.through)) if value]
        if len(given) != 1:
            raise fail("Expected exactly one of PATH (a .csv or .nc file), --line A B, --circle CENTRE RADIUS or "
                       f"--through POSE POSE ..., got {', '.join(given) or 'none'}.")
        if self.actuators and self.path_file is None:
            raise fail(f"--actuators says that {self.file_option} holds actuator values: give {self.file_option} a "
                       f"file, not {given[0]}.")
        if self.path_file is not None and not os.path.isfile(self.path_file):
            raise fail(f"{self.path_file}: "
                       f"{'is a folder, not a path file' if os.path.isdir(self.path_file) else 'no such file'}.")

    def read(self, mechanism):
        """The :class:`~screwkit.studies.paths.Path` (a one-line error naming the file if it cannot be used)."""
        if self.path_file is None:
            return generated_path(mechanism, self)
        try:
            if self.actuators:
                return read_actuator_path(mechanism, self.path_file)
            return read_path(mechanism, self.path_file)
        except PathFileError as error:
            raise fail(str(error)) from None


@dataclass(frozen=True)
class FaultOptions:
    """What counts as controllable after failures, and how closely it is located (the average case is
    ``--aggregate``, an analysis option as in ``analyze``, ``sweep`` and ``map``)."""

    level: float = 0.4
    tolerance: float | None = None

    def keywords(self) -> dict:
        return dict(level=self.level, tolerance=self.tolerance)


line_option = click.option(
    "--line", cls=GreedyOption, metavar="A B",
    help="A straight path from pose A to pose B: two named poses, or every task coordinate of A then of B (m, deg).")
circle_option = click.option(
    "--circle", cls=GreedyOption, metavar="CENTRE RADIUS",
    help="A full circle in the x-y plane: the centre (a named pose or every task coordinate, m and deg) and the "
         "radius (m); the other coordinates stay at the centre's.")
through_option = click.option(
    "--through", cls=GreedyOption, metavar="POSE POSE ...",
    help="A piecewise-linear path through two or more poses (named poses, or every task coordinate of each in "
         "turn, m and deg): straight in task coordinates between consecutive poses, --samples evenly spaced in arc "
         "length plus every pose given.")
samples_option = click.option(
    "--samples", type=click.IntRange(min=2), default=DEFAULT_SAMPLES, show_default=True,
    help="Samples of a --line, --circle or --through path, both ends included.")
path_source_options = option_group(
    "source", PathSource,
    click.argument("path_file", metavar="[PATH]", required=False, type=click.Path(dir_okay=True)),
    line_option, circle_option, through_option, samples_option,
    click.option("--actuators", is_flag=True,
                 help="PATH holds actuator values (a column per actuator, named by its chain or chain:joint; deg, "
                      "m; optionally t): the platform poses come from forward kinematics along the path, from the "
                      "reference assembly; its arc length is along the actuators (angles times the length scale), "
                      "wherever the file places the mechanism."))
fault_options = option_group(
    "faults", FaultOptions,
    click.option("--level", type=click.FloatRange(min=0, max=1, min_open=True), default=0.4, show_default=True,
                 help="The LMTI the actuators left after a failure must keep for the platform to count as "
                      "controllable."),
    click.option("--tolerance", type=click.FloatRange(min=0, min_open=True),
                 help="How closely crossings of the level and singular points are located, in m of arc length, "
                      "from 64 units in the last place of the path's arc length to below its length (default 1e-6 "
                      "times the mechanism's length scale, at most a thousandth of a shorter path)."))


@click.command("trajectory")
@mechanism_argument
@path_source_options
@fault_options
@outputs_options()
@analysis_options(average=True)
@reading_options
@json_option
@quiet_option
def trajectory(mechanism, source: PathSource, faults: FaultOptions, outputs: Outputs, analysis, reading, as_json,
               quiet) -> None:
    """Every index along a path, and the stretches each actuator failure leaves uncontrollable.

    PATH is a CSV file with a column per task coordinate (m, deg; `screwkit info MECHANISM` names them) and
    optionally t (s), or a netCDF file with such variables (with --actuators, a column per actuator instead); or
    the path is generated with --line, --circle or --through (straight in task coordinates between poses).
    Crossings of --level and singular points between samples are refined to --tolerance. The indices go to
    --out (.nc or .csv; with neither --out, --figure nor --json, to stdout as CSV), the summary to stderr
    (or stdout with --json). A mechanism whose legs have loops inside them is closed at each sample by
    continuation from its file's configuration, or, with --actuators, from the sample before.
    """
    source.check()
    outputs.check(quiet or as_json)
    keywords = faults.keywords()
    loaded = load_mechanism(mechanism, reading, limits=analysis.limits, graphs=True)
    check_average(analysis, loaded)
    sized = _sized(loaded, analysis)
    if source.path_file is None:  # a generated path, before it is generated
        sized(source.samples, f"--samples {source.samples}: the path")
    path = source.read(loaded)
    try:
        if source.path_file is not None:
            sized(path.samples, f"{source.path_file}: the path")
        if faults.tolerance is not None:  # what the refinement can honour on this path, named as given
            checked_tolerance(path, faults.tolerance, "--tolerance")
        result = run_trajectory(loaded, path, analysis=analysis, aggregate=analysis.aggregate,
                                probabilities=analysis.probabilities, **keywords)
    except ValueError as error:
        raise fail(str(error)) from None
    summary = result.summary()
    if as_json:
        click.echo(json.dumps(summary))
    elif not quiet:
        print_summary(summary)
    _write(result, outputs, quiet or as_json, to_stdout=not as_json)


def _sized(mechanism, analysis):
    """``check(samples, where)``: a path of that many samples refused in one line if it would not fit in memory."""
    try:
        along = path_mechanism(mechanism, analysis, {})
    except ValueError as error:  # what a graph cannot be asked (closed forms, link faults)
        raise fail(str(error)) from None

    def check(samples: int, where: str) -> None:
        try:
            check_path_size(along, samples, where)
        except ValueError as error:
            raise fail(str(error)) from None

    return check


def _write(result, outputs: Outputs, quiet: bool, to_stdout: bool) -> None:
    """The data file and the figure (checked before the computation); with neither, the CSV table on stdout."""
    if outputs.out:
        write_dataset(result.plain_dataset(), outputs.out)  # netCDF or CSV, without xarray
        if not quiet:
            echo_error(f"wrote {outputs.out}")
    if outputs.figure:
        from screwkit.plots import save_figure, trajectory_figure  # matplotlib only when a figure is asked for

        save_figure(trajectory_figure(result), outputs.figure)
        if not quiet:
            echo_error(f"wrote {outputs.figure}")
    if not outputs.out and not outputs.figure and to_stdout:
        click.echo(wide_csv(result.plain_dataset()), nl=False)
