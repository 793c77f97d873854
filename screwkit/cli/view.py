"""``screwkit view``: a mechanism in a Meshcat viewer, coloured by its indices."""

from __future__ import annotations

import contextlib
import math
import signal
import threading
import time
from dataclasses import dataclass

import click
import numpy as np

from screwkit.cli.option_checks import given as option_given
from screwkit.cli.options import (
    GreedyOption,
    check_outputs,
    echo_error,
    fail,
    ignore_limits_option,
    load_mechanism,
    mechanism_argument,
    option_group,
    overwrite_option,
    parse_pose,
    parse_range,
    quiet_option,
    reading_options,
    threshold_option,
)
from screwkit.cli.trajectory import PathSource, circle_option, line_option, samples_option, through_option
from screwkit.viewer import animate_sweep, export_html, show
from screwkit.viewer.markers import actuator_pairs, chain_names

__all__ = ["view"]


MAX_FRAMES = 500
"""A path of more samples is animated at this many (one keyframe each), evenly spaced in time when it has a time
column, else in arc length; a ``--sweep-phi`` of more angles at this many, evenly spaced from its first angle to
its last."""


@dataclass(frozen=True)
class Motion:
    """What is animated: ``--sweep-phi``, or a path (``--path``, ``--line``, ``--circle``, ``--through``), or nothing
    (one pose); and the keyframes per second."""

    sweep_phi: str | None
    path: PathSource | None
    frame_rate: float


def _motion(sweep_phi: str | None, frame_rate: float, path_file: str | None, line: str | None, circle: str | None,
            through: str | None, samples: int, actuators: bool = False) -> Motion:
    """The :class:`Motion`: at most one of its sources, a path file that exists (checked before anything loads)."""
    given = [name for name, value in (("--sweep-phi", sweep_phi), ("--path", path_file), ("--line", line),
                                      ("--circle", circle), ("--through", through)) if value]
    if len(given) > 1:
        raise fail(f"Expected at most one of --sweep-phi, --path, --line, --circle and --through, got "
                   f"{', '.join(given)}.")
    if not (math.isfinite(frame_rate) and frame_rate > 0):  # (click's range lets nan and inf through)
        raise fail(f"Expected --frame-rate a finite number > 0 (keyframes per second), got {frame_rate:g}.")
    if option_given("samples") and not (line or circle or through):
        raise fail("--samples is the number of samples of a --line, --circle or --through path, and there is none: "
                   "give one of them, or leave --samples out.")
    if option_given("frame_rate") and not given:
        raise fail("--frame-rate is the pace of an animation (--sweep-phi or a path), and there is none: give one, "
                   "or leave --frame-rate out.")
    source = None
    if given and given[0] != "--sweep-phi":
        source = PathSource(path_file=path_file, line=line, circle=circle, through=through, samples=samples,
                            actuators=actuators, file_option="--path")
        source.check()
    elif actuators:
        raise fail("--actuators says that --path holds actuator values, and there is no --path: give one, or leave "
                   "--actuators out.")
    return Motion(sweep_phi, source, frame_rate)


@dataclass(frozen=True)
class Colouring:
    """What the chains are coloured by, the singularity threshold of the indices (m), and whether the joints'
    limits count (``--ignore-limits``: a file drawn beyond them is read all the same, a pose beyond them drawn)."""

    color_by: str
    threshold: float
    ignore_limits: bool = False

    def __post_init__(self):
        if not self.threshold >= 0:  # (as `analyze` takes it: inf allowed)
            raise fail(f"Expected --threshold >= 0 (a length, m), got {self.threshold:g}.")


def _animated_poses(mechanism, motion: Motion, target: np.ndarray, quiet: bool, resampled: list | None = None):
    """The poses of ``--sweep-phi`` or of the path (at most :data:`MAX_FRAMES`) and their times (a path's time
    column, else None), or None (one pose); ``resampled`` gets True when they are not the path's own samples."""
    if motion.sweep_phi is not None:
        if not mechanism.is_planar:
            raise fail(f"--sweep-phi sweeps a planar mechanism; {mechanism.name!r} is spatial.")
        coordinates = list(getattr(mechanism, "task_coordinates", ()))
        if "phi" not in coordinates:
            raise fail(f"--sweep-phi sweeps phi; {mechanism.name!r} has {', '.join(coordinates)}.")
        angles = parse_range(motion.sweep_phi, "--sweep-phi", angular=True)
        if angles.size > MAX_FRAMES:
            if not quiet:
                echo_error(f"--sweep-phi gives {angles.size} angles: animating {MAX_FRAMES} evenly spaced from the "
                           "first to the last.")
            angles = np.linspace(angles[0], angles[-1], MAX_FRAMES)
        poses = np.repeat(target[None], angles.size, axis=0)
        poses[:, coordinates.index("phi")] = angles
        return poses, None
    if motion.path is None:
        return None
    if motion.path.actuators:
        from screwkit.io.graph import GraphMechanism  # (with --actuators only: legs with loops are refused)

        if isinstance(mechanism, GraphMechanism):  # (animated by poses, each closed again)
            raise fail(f"--actuators animates the poses the actuators drive, closed again frame by frame: the legs of "
                       f"{mechanism.name!r} have loops inside them, its task coordinates may fold, and a pose past a "
                       "fold may close elsewhere; `screwkit trajectory --actuators` follows such a path in joint "
                       "space.")
    path = motion.path.read(mechanism)
    if path.times is not None and not quiet:
        echo_error(f"Animated at the path's own times: {path.times[-1] - path.times[0]:g} s.")
    if path.samples <= MAX_FRAMES:
        return path.poses, path.times
    if resampled is not None:
        resampled.append(True)
    if path.times is None:
        if not quiet:
            echo_error(f"{path.samples} samples: animating {MAX_FRAMES} evenly spaced in arc length.")
        return path.at(np.linspace(0.0, path.length, MAX_FRAMES)), None
    if not quiet:
        echo_error(f"{path.samples} samples: animating {MAX_FRAMES} evenly spaced in time.")
    times = np.linspace(path.times[0], path.times[-1], MAX_FRAMES)
    return path.at(np.interp(times, path.times, path.arc_length)), times


def _runs(indices: np.ndarray) -> list[tuple[int, int]]:
    """Consecutive runs ``(first, last)`` of sorted indices."""
    breaks = np.flatnonzero(np.diff(indices) > 1)
    return list(zip(indices[np.r_[0, breaks + 1]].tolist(), indices[np.r_[breaks, indices.size - 1]].tolist()))


def _echo_skipped(scene, poses: np.ndarray, times, what: str) -> None:
    """One line on stderr naming the unreachable poses an animation skipped, as stretches of ``what`` (samples,
    frames of a resampled path, or angles of ``--sweep-phi``), with their times or angles."""
    asked = poses.shape[0]
    missing = np.setdiff1d(np.arange(asked), scene.kept)
    if not missing.size:
        return
    sweep = what == "angles"
    parts = []
    for first, last in _runs(missing):
        where = f"{first}" if first == last else f"{first}-{last}"
        if sweep:
            phi = np.degrees(poses[[first, last], list(scene.mechanism.task_coordinates).index("phi")])
            where += f" (phi {phi[0]:g} deg)" if first == last else f" (phi {phi[0]:g}..{phi[1]:g} deg)"
        elif times is not None:
            where += f" (t {times[first]:g} s)" if first == last else f" (t {times[first]:g}..{times[last]:g} s)"
        parts.append(where)
    one = what[:-1]
    inside = np.any((missing > scene.kept[0]) & (missing < scene.kept[-1]))
    how = ["moves straight across a skipped stretch"] if inside else []
    if scene.kept[0] > 0:
        how.append(f"waits at {one} {scene.kept[0]} (the first reachable) from the start until its time")
    if scene.kept[-1] < asked - 1:
        how.append(f"ends at {one} {scene.kept[-1]} (the last reachable)")
    echo_error(f"UNREACHABLE {what}, skipped: {', '.join(parts)} ({missing.size} of {asked}); the animation keeps "
               f"the {what}' times: it {', '.join(how)}.")


def _echo_legend(scene) -> None:
    """The chains' values and the drawn twists (stdout: the data of the picture)."""
    mechanism = scene.mechanism
    frames = scene.poses.shape[0]
    what = "lowest ITI of its working actuators" if scene.color_by == "iti" else "OTI of its best working submechanism"
    extra = f" (first of {frames} frames, then the lowest over them)" if frames > 1 else ""
    click.echo(f"{mechanism.name}: chains coloured by the {what}{extra}; viridis 0 purple .. 1 yellow")
    names = mechanism.actuator_names
    pairs = actuator_pairs(mechanism)
    for index, chain in enumerate(chain_names(mechanism)):
        values = scene.chain_values[:, index]
        failed = [names[i] for i in scene.failed if pairs[i][0] == chain]
        note = f"  failed: {', '.join(failed)}" if failed else ""
        shown = "-" if np.isnan(values[0]) else f"{values[0]:.4f}"
        if frames > 1:
            shown += "  -" if np.all(np.isnan(values)) else f"  {np.nanmin(values):.4f}"
        click.echo(f"  {chain:<24s} {shown}{note}")
    best = scene.best_submechanisms[0]
    if scene.visualizer is None:
        click.echo("Legs with loops inside them: bodies drawn as rods between their joints; no screw drawn.")
    elif best is None:
        click.echo("No working submechanism: no output twist drawn.")
    else:
        click.echo("Output twists of the best working submechanism: " + ", ".join(names[i] for i in best))


class Stopped(BaseException):
    """SIGTERM or SIGHUP received (a `kill`, a service manager, the terminal closed): raised where the command is,
    like Ctrl+C's KeyboardInterrupt, so that the Meshcat server is stopped on the way out (not an ``Exception``:
    nothing on the way catches it)."""

    def __init__(self, signum: int):
        super().__init__(signum)
        self.name = signal.Signals(signum).name


STOP_SIGNALS = tuple(getattr(signal, name) for name in ("SIGTERM", "SIGHUP") if hasattr(signal, name))
"""Signals that end ``view`` as Ctrl+C does, from its start: the Meshcat server is started while drawing."""


def _stop(signum, frame) -> None:
    """The first SIGTERM/SIGHUP raises :class:`Stopped`; later ones are ignored while the server is stopped (the
    server's own watchdog ends it if the process dies anyway)."""
    for number in STOP_SIGNALS:
        signal.signal(number, signal.SIG_IGN)
    raise Stopped(signum)


@contextlib.contextmanager
def _stopped_by_signals():
    """SIGTERM and SIGHUP raise :class:`Stopped` inside the block (in the main thread only), as before after it."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {number: signal.signal(number, _stop) for number in STOP_SIGNALS}
    try:
        yield
    finally:
        for number, handler in previous.items():
            signal.signal(number, handler)


def _say(message: str) -> None:
    """A note on stderr that may find no terminal (SIGHUP: it was closed)."""
    with contextlib.suppress(OSError):
        echo_error(message)


@click.command("view")
@mechanism_argument
@click.option("--pose", cls=GreedyOption, metavar="VALUES|NAME",
              help="Platform pose: x y phi (planar) or x y z roll pitch yaw, in m and deg, or a named pose. "
                   "Default: the file's home pose.")
@click.option("--failed", "failed", multiple=True, metavar="NAME_OR_INDEX",
              help="A failed actuator: 0-based index, CHAIN:JOINT, joint or chain name. Repeatable.")
@click.option("--html", "html_path", type=click.Path(dir_okay=False),
              help="Write a self-contained offline HTML file (.html) and exit instead of serving.")
@option_group(
    "motion", _motion,
    click.option("--sweep-phi", "sweep_phi", metavar="START:STOP:STEP",
                 help="Animate a planar sweep of phi (deg; the stop is excluded) at the x y of --pose."),
    click.option("--path", "path_file", type=click.Path(dir_okay=True), metavar="PATH",
                 help="Animate the platform along a path: a CSV or netCDF file of task coordinates, as `screwkit "
                      f"trajectory` reads it, played at its time column's times if it has one (more than {MAX_FRAMES} "
                      f"samples: {MAX_FRAMES} frames evenly spaced in time, else in arc length); the chains' colours "
                      "follow their index frame by frame."),
    click.option("--actuators", is_flag=True,
                 help="--path holds actuator values (as `screwkit trajectory --actuators` reads them): the platform "
                      "is animated through the poses they drive (mechanisms of serial legs)."),
    line_option, circle_option, through_option, samples_option,
    click.option("--frame-rate", type=click.FloatRange(min=0, min_open=True), default=10.0, show_default=True,
                 help="--sweep-phi and paths: keyframes per second (1/s); a path with a time column plays at "
                      "its own times instead."))
@option_group(
    "colouring", Colouring,
    click.option("--color-by", type=click.Choice(["iti", "oti"]), default="iti", show_default=True,
                 help="Colour chains by their lowest ITI or by the OTI of their best working submechanism."),
    threshold_option, ignore_limits_option)
@reading_options
@click.option("--open", "open_browser", is_flag=True, help="Open the viewer in the default browser.")
@overwrite_option
@quiet_option
def view(mechanism: str, pose, failed, html_path, motion: Motion, colouring: Colouring, reading,
         open_browser, overwrite, quiet) -> None:
    """Show MECHANISM in a Meshcat viewer (served on 127.0.0.1), coloured by its indices.

    Chains are coloured by index (viridis: 0 purple, 1 yellow), actuation wrench lines are
    orange, output twist axes and instantaneous centres of the best submechanism magenta,
    failed actuators red. --sweep-phi, or a path (--path, --line, --circle or --through, as
    `screwkit trajectory` takes them), animates the platform, its screws and the chains' colours
    frame by frame. The legend goes to stdout, the server's address to stderr.
    """

    check_outputs({"--html": (html_path, (".html", ".htm"))}, overwrite, quiet)
    if open_browser and html_path is not None:
        raise fail("--open opens the served viewer, and --html writes a file instead of serving: open the file, or "
                   "leave --html out.")
    if pose is not None and motion.path is not None:
        raise fail("--pose is the pose of one view (or the x y of --sweep-phi), and a path gives its own poses: leave "
                   "--pose out.")
    serving = []  # [True] from the moment the URL is about to be shown
    with _stopped_by_signals():  # from the start: the Meshcat server is started while drawing
        try:
            _view(mechanism, pose, failed, html_path, motion, colouring, reading, open_browser, quiet, serving)
        except (KeyboardInterrupt, Stopped) as stop:  # the scene's server was stopped on the way here
            if serving:
                _say("Stopped.")
                return
            what = "no HTML written" if html_path is not None else "nothing served"
            name = stop.name if isinstance(stop, Stopped) else "SIGINT"
            raise fail(f"Stopped by {name} before the view was ready; {what}.") from None


def _view(mechanism, pose, failed, html_path, motion: Motion, colouring: Colouring, reading, open_browser,
          quiet, serving: list) -> None:
    """The command once its outputs are checked: returns once the HTML is written; serves until the server stops
    (an error) or a signal ends it (``serving`` gets True just before the URL is shown)."""
    limits = not colouring.ignore_limits
    loaded = load_mechanism(mechanism, reading, graphs=True, limits=limits)
    target = parse_pose(loaded, pose)
    failures = list(failed)  # indices or names, see screwkit.viewer.resolve_actuators
    resampled = []
    animated = _animated_poses(loaded, motion, target, quiet, resampled)
    try:
        if animated is not None:
            poses, times = animated
            scene = animate_sweep(loaded, poses, failed=failures, threshold=colouring.threshold,
                                  color_by=colouring.color_by, frame_rate=motion.frame_rate, times=times,
                                  limits=limits)
        else:
            scene = show(loaded, target, failed=failures, threshold=colouring.threshold, color_by=colouring.color_by,
                         limits=limits)
    except (ValueError, RuntimeError) as error:
        raise fail(str(error)) from None
    with scene:  # whatever ends the command from here (an error, Ctrl+C, SIGTERM, SIGHUP) stops the server
        if animated is not None:  # (a warning: said even with --quiet)
            _echo_skipped(scene, *animated, "angles" if motion.sweep_phi else "frames" if resampled else "samples")
        _echo_legend(scene)
        if html_path is not None:
            try:
                written = export_html(scene, html_path)
            except (ValueError, OSError) as error:
                raise fail(str(error)) from None
            if not quiet:
                echo_error(f"wrote {written}")
            return
        serving.append(True)  # before the line: a signal sent once it is read finds the view served
        echo_error(f"Serving at {scene.url} (127.0.0.1 only); press Ctrl+C to stop.")
        if open_browser:
            scene.viewer.open()
        while scene.server.running:
            time.sleep(0.5)
        raise fail(f"The Meshcat server stopped unexpectedly (exit code {scene.server.process.returncode}).")
