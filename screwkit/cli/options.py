"""What every command shares: options, parsing of poses and ranges, loading, errors, outputs.

Conventions of the command line: lengths in metres and angles in degrees; data on stdout,
progress and summaries on stderr; every error one line (``Error: ...``, or ``{"error": ...}``
on stdout with ``--json``) and exit status 1; outputs checked before any computation.
"""

from __future__ import annotations

import contextlib
import errno
import functools
import inspect
import json
import sys
from dataclasses import dataclass, replace
from typing import Callable

import click
import numpy as np

from screwkit.cli.option_checks import execution_record, finite_threshold
from screwkit.cli.reading import FILE_OPTIONS, Reading, grouped_notes, reading_record
from screwkit.closure.assembly import NOT_OPEN_LOOPS
from screwkit.common.compiling import (
    INDEX_KERNELS,
    compile_ahead,
    silence,
)
from screwkit.common.decimals import decimal_range
from screwkit.common.tolerances import SINGULARITY_THRESHOLD
from screwkit.common.units import LENGTH_UNITS, angle_beyond_limit, angle_limit, is_angular
from screwkit.indices.average import AGGREGATES, failure_weights
from screwkit.io.loader import bundled_graph_names, bundled_path, load
from screwkit.studies.options import AnalysisOptions
from screwkit.studies.tasks import CONNECT_TIMEOUT, ClusterError, Execution, connect, disconnect

__all__ = [
    "check_average",
    "check_probabilities",
    "parse_probabilities",
    "GreedyOption",
    "ScrewkitGroup",
    "mechanism_argument",
    "length_unit_option",
    "reading_options",
    "Reading",
    "threshold_option",
    "fault_option",
    "ignore_limits_option",
    "json_option",
    "quiet_option",
    "overwrite_option",
    "colour_scale_options",
    "option_group",
    "analysis_options",
    "execution_options",
    "outputs_options",
    "Outputs",
    "load_mechanism",
    "parse_pose",
    "parse_range",
    "check_outputs",
    "check_colour_scale",
    "connected",
    "fail",
    "echo_error",
    "report_error",
]


class ScrewkitGroup(click.Group):
    """The command group: errors become one line (JSON on stdout when the command got ``--json``)."""

    def main(self, args=None, prog_name=None, complete_var=None, standalone_mode=True, **extra):
        arguments = list(sys.argv[1:] if args is None else args)
        if "--quiet" in arguments or "--json" in arguments:  # stderr stays empty: no compile notice either
            silence()
        try:
            result = super().main(arguments, prog_name, complete_var, standalone_mode=False, **extra)
        except click.exceptions.Exit as stop:
            if standalone_mode:
                sys.exit(stop.exit_code)
            raise
        except click.exceptions.NoArgsIsHelpError as error:  # a command given no arguments: its help
            error.show()
            if standalone_mode:
                sys.exit(error.exit_code)
            raise
        except click.ClickException as error:
            message = error.format_message()
            if isinstance(error, click.UsageError) and error.ctx is not None:  # one line, not click's usage block
                message = f"{message} See '{error.ctx.command_path} --help'."
            report_error(message, arguments)
            if standalone_mode:
                sys.exit(1)
            raise
        except OSError as error:  # a write that failed (disk full, quota, read-only), of a file or of stdout
            from screwkit.studies.files import WriteError  # the output files' module: loaded by commands writing one

            if not isinstance(error, WriteError) and error.errno not in _WRITE_FAILURES:
                raise
            report_error(str(error) if isinstance(error, WriteError) else
                         f"Cannot write {error.filename or 'to stdout'}: {error.strerror}.", arguments)
            if standalone_mode:
                sys.exit(1)
            raise
        except click.Abort:
            click.echo("Aborted.", err=True)
            if standalone_mode:
                sys.exit(1)
            raise
        if standalone_mode:
            sys.exit(result if isinstance(result, int) else 0)
        return result


_WRITE_FAILURES = {errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EROFS}
"""What a write that fails says: no space left, quota exceeded, file too large, read-only file system."""


def report_error(message: str, arguments: list[str]) -> None:
    """An error as one line: ``Error: ...`` on stderr, or ``{"error": ...}`` on stdout with ``--json`` (stderr if
    stdout cannot be written)."""
    if "--json" in arguments:
        try:
            click.echo(json.dumps({"error": message}))
            return
        except OSError:
            pass
    click.echo(f"Error: {message}", err=True)


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
    """A value, not an option: a number, or numbers quoted together (``--line "-0.06 -0.35 -3" "-0.04 -0.34 5"``)."""
    try:
        return bool([float(word) for word in token.split()])
    except ValueError:
        return False


def fail(message: str) -> click.ClickException:
    """The one-line error of a command."""
    return click.ClickException(message)


def echo_error(message: str) -> None:
    """A warning or note on stderr."""
    click.echo(message, err=True)


# -- options shared by several commands ----------------------------------------------------------

def mechanism_argument(function: Callable) -> Callable:
    return click.argument("mechanism", metavar="MECHANISM")(function)


def length_unit_option(function: Callable) -> Callable:
    return click.option("--length-unit", type=click.Choice(list(LENGTH_UNITS)), default=None,
                        help="Length unit the MECHANISM file is written in (default: its <units length=...>, else m); "
                             "everything shown is in m.")(function)


def reading_options(function: Callable) -> Callable:
    """``--length-unit``, ``--output FRAME``, ``--output-type``, ``--lock``, ``--actuate``: how MECHANISM is read, as
    ``reading``, a :class:`Reading` (the options :func:`screwkit.io.read_mechanism_file` and ``screwkit convert``
    take)."""
    return option_group("reading", reading_record, length_unit_option, *FILE_OPTIONS)(function)


def threshold_option(function: Callable) -> Callable:
    return click.option("--threshold", type=float, default=SINGULARITY_THRESHOLD, show_default=True,
                        callback=finite_threshold, help="Singularity threshold p on the moment arm (m).")(function)


def fault_option(function: Callable) -> Callable:
    return click.option("--fault", "fault_type", type=click.Choice(["free-swinging", "link"]), default="free-swinging",
                        show_default=True,
                        help="What a failed actuator does: becomes a passive joint (free-swinging, the paper's FSJF) "
                             "or takes its chain away with its constraint wrenches (link, LF).")(function)


def ignore_limits_option(function: Callable) -> Callable:
    return click.option("--ignore-limits", is_flag=True,
                        help="Ignore the joints' position limits of the file "
                             "(the purely geometric workspace).")(function)


def json_option(function: Callable) -> Callable:
    return click.option("--json", "as_json", is_flag=True,
                        help="Print one JSON object on stdout (errors too: {\"error\": ...}).")(function)


def quiet_option(function: Callable) -> Callable:
    return click.option("--quiet", is_flag=True, help="No progress or summary on stderr.")(function)


def overwrite_option(function: Callable) -> Callable:
    return click.option("--overwrite", is_flag=True, help="Replace output files that exist.")(function)


def colour_scale_options(function: Callable) -> Callable:
    """``--vmin`` and ``--vmax``: the ends of a map figure's colour scale (:func:`check_colour_scale`)."""
    function = click.option("--vmax", type=float, default=None,
                            help="Upper end of the figure's colour scale (index value; default 1).")(function)
    return click.option("--vmin", type=float, default=None,
                        help="Lower end of the figure's colour scale (index value; default 0).")(function)


# -- option groups: options that travel together, handed to the command as one record ---------------

def option_group(name: str, build: Callable, *options: Callable) -> Callable:
    """Decorate a command with ``options`` and hand it their values as one argument, ``name``.

    ``build`` takes the options' values by their destinations (those of its parameters that the
    command has: a group may leave one out) and returns the record the command receives instead,
    so that a command takes a few records rather than every option one by one. A group's options
    are defined once and shared by every command that has them.
    """
    keys = tuple(inspect.signature(build).parameters)

    def decorate(function: Callable) -> Callable:
        @functools.wraps(function)
        def command(*args, **values):
            values[name] = build(**{key: values.pop(key) for key in keys if key in values})
            return function(*args, **values)

        for option in reversed(options):
            command = option(command)
        return command

    return decorate


def _quiet() -> bool:
    context = click.get_current_context(silent=True)
    return bool(context and context.params.get("quiet"))


def _analysis(threshold: float, fault_type: str, ignore_limits: bool, closed_forms: bool = False,
              aggregate: str = "min", probabilities: str | None = None) -> AnalysisOptions:
    if probabilities is not None and aggregate != "mean":
        raise fail("--probabilities weight the mean: give --aggregate mean with them.")
    weights = parse_probabilities(probabilities)
    return AnalysisOptions(threshold=threshold, fault_type=fault_type, closed_forms=closed_forms,
                           limits=not ignore_limits, aggregate=aggregate, probabilities=weights)


aggregate_option = click.option(
    "--aggregate", type=click.Choice(AGGREGATES), default="min", show_default=True,
    help="min: the paper's worst case over the sets of j failed actuators (F_Oj, Eq. 12); mean: also their mean "
         "(f_o_mean<j>, screwkit's extension of Eq. 12).")
probabilities_option = click.option(
    "--probabilities", cls=GreedyOption, metavar="P1 P2 ...",
    help="With --aggregate mean: each actuator's failure probability (in the order `screwkit info` lists the "
         "actuators), weighting the mean by the probability of each set of failures.")


def analysis_options(*, closed_forms: bool = True, average: bool = False) -> Callable:
    """``--threshold``, ``--fault``, ``--closed-forms`` (unless not ``closed_forms``), ``--ignore-limits`` and with
    ``average`` ``--aggregate`` and ``--probabilities``: what is computed at every pose, as ``analysis``, an
    :class:`~screwkit.studies.options.AnalysisOptions`."""
    closed = click.option("--closed-forms", is_flag=True,
                          help="Use the paper's planar closed forms instead of the generic path.")
    return option_group("analysis", _analysis, threshold_option, fault_option, *((closed,) if closed_forms else ()),
                        ignore_limits_option, *((aggregate_option, probabilities_option) if average else ()))


def parse_probabilities(text: str | None) -> tuple[float, ...] | None:
    """``--probabilities`` as the numbers they are (a one-line error if some is not); None if not given."""
    try:
        return None if text is None else tuple(float(p) for p in text.split())
    except ValueError:
        raise fail(f"Expected numbers after --probabilities, got {text!r}.") from None


def check_probabilities(probabilities, actuators: int) -> None:
    """One failure probability in [0, 1] per actuator, if given (a one-line error before any work)."""
    if probabilities is not None:
        try:
            failure_weights(actuators, 1, probabilities)
        except ValueError as error:
            raise fail(f"--probabilities: {error}") from None


def check_average(analysis: AnalysisOptions, mechanism) -> None:
    """One failure probability per actuator of ``mechanism`` (a one-line error before any work)."""
    check_probabilities(analysis.probabilities, len(mechanism.actuator_names))


def _execution(scheduler: str | None, connect_timeout: float, task_size: int | None = None) -> Execution:
    return execution_record(scheduler, connect_timeout, task_size, quiet=_quiet())  # checked: one line otherwise


def execution_options(*, task_size: bool = False) -> Callable:
    """``--scheduler``, ``--connect-timeout`` (and ``--task-size``): where the tasks run, as ``execution``, a
    :class:`~screwkit.studies.tasks.Execution` (a progress bar when stderr is a terminal, unless ``--quiet``);
    :func:`connected` connects to its scheduler."""
    options = [
        click.option("--scheduler", metavar="ADDRESS",
                     help="Address of a running dask.distributed scheduler, tcp://HOST:PORT or tls://HOST:PORT, e.g. "
                          "tcp://host:8786 (default: local threads)."),
        click.option("--connect-timeout", type=float, default=CONNECT_TIMEOUT, show_default=True,
                     help="Seconds to wait for the --scheduler to answer (at most 86,400: a day)."),
    ]
    if task_size:
        options.append(click.option(
            "--task-size", type=click.IntRange(min=1),
            help="Configurations (grid points x orientations) per task (default: at most 131,072 and at least "
                 "16,384, and 16 tasks per core of this machine where the map is large enough)."))
    return option_group("execution", _execution, *options)


@dataclass(frozen=True)
class Outputs:
    """The files a command writes: its data (``--out``), its figure (``--figure``, with the ends of its
    colour scale), and whether existing files are replaced (``--overwrite``)."""

    out: str | None = None
    figure: str | None = None
    vmin: float | None = None
    vmax: float | None = None
    overwrite: bool = False

    def check(self, quiet: bool) -> None:
        """Every output checked before any computation (:func:`check_outputs`, :func:`check_colour_scale`)."""
        from screwkit.studies.files import DATA_SUFFIXES, FIGURE_SUFFIXES  # the output files: commands writing them

        check_outputs({"--out": (self.out, DATA_SUFFIXES), "--figure": (self.figure, FIGURE_SUFFIXES)},
                      self.overwrite, quiet)
        check_colour_scale(self.vmin, self.vmax)


def _outputs(out: str | None, figure_path: str | None, overwrite: bool, vmin: float | None = None,
             vmax: float | None = None) -> Outputs:
    return Outputs(out=out, figure=figure_path, vmin=vmin, vmax=vmax, overwrite=overwrite)


def outputs_options(*, colour_scale: bool = False) -> Callable:
    """``--out``, ``--figure`` (with ``--vmin``, ``--vmax`` if ``colour_scale``), ``--overwrite``: ``outputs``."""
    return option_group(
        "outputs", _outputs,
        click.option("--out", type=click.Path(dir_okay=False), help="Data file: .nc (netCDF) or .csv."),
        click.option("--figure", "figure_path", type=click.Path(dir_okay=False),
                     help="Figure file: .png, .pdf or .svg."),
        *((colour_scale_options,) if colour_scale else ()),
        overwrite_option)


# -- parsing ---------------------------------------------------------------------------------------

def load_mechanism(name: str, reading: Reading | str | None = None, *, indices: bool = True, graphs: bool = False,
                   limits: bool = True, batches: bool = True):
    """Load MECHANISM (a bundled name or a file) as ``reading`` says (a :class:`Reading`, or just a length unit);
    a one-line error if it cannot be loaded.

    ``indices``: the command computes indices, so a first run says at once that the index kernel
    is about to be compiled, and starts compiling it (before Pinocchio is even imported); ``batches`` False: the
    command computes a few poses only, fewer than the chunks the lower-mobility kernels serve
    (:data:`~screwkit.indices.stages.SPACES_COMPILED_FROM`), so those are not compiled ahead. ``graphs``: a file
    whose legs have loops inside them is returned as a :class:`~screwkit.io.GraphMechanism` (analysed at the
    file's configuration) instead of refused. ``limits`` False (``--ignore-limits``): a reference assembly outside
    a joint's limits is read all the same, and said on stderr."""
    if indices:
        compile_ahead(*INDEX_KERNELS)
    reading = reading if isinstance(reading, Reading) else Reading(length_unit=reading)
    length_unit = reading.length_unit
    try:
        mechanism = load(name, length_unit=length_unit, limits=limits, output=reading.output,
                         output_type=reading.output_type, lock=reading.lock, actuate=reading.actuate,
                         initial=reading.initial)
    except ValueError as error:
        from screwkit.io import LegWithLoops, graph_mechanism, read_closed_tree  # readers of other tools: when used
        from screwkit.io.sdformat import with_chosen_base  # (idem)

        if not isinstance(error, LegWithLoops) or not graphs:
            raise fail(with_chosen_base(name, str(error))) from None
        try:
            source = bundled_path(name) if name in bundled_graph_names() else name
            graph = graph_mechanism(read_closed_tree(source, output=reading.output, output_type=reading.output_type,
                                                     lock=reading.lock, actuate=reading.actuate,
                                                     initial=reading.initial, length_unit=length_unit))
            said = graph.reading_notes(limits=limits)  # as a serial mechanism's, on every command
        except ValueError as graph_error:
            raise fail(with_chosen_base(name, str(error.refusal(graph_error)))) from None
        if said and not _quiet():
            echo_error(f"{name}: " + "; ".join(said))
        return graph
    opened = [note for note in mechanism.assembly_notes if not note.startswith(NOT_OPEN_LOOPS)]
    ignored = [note for note in mechanism.assembly_notes if note.startswith(NOT_OPEN_LOOPS)]
    if opened and not _quiet():
        # a file whose loops are open as written describes another mechanism than the one analysed: say so
        echo_error(f"{name}: loops open at the file's own joint values were closed at loading: " + "; ".join(opened))
    if ignored and not _quiet():
        echo_error(f"{name}: " + "; ".join(grouped_notes(ignored)))
    if indices:  # the kernels of this mechanism's chains, compiled while the command goes on
        from screwkit.studies.kernels import mechanism_kernels  # the closures and indices: commands computing them

        compile_ahead(*mechanism_kernels(mechanism, batches=batches))
    return mechanism


def parse_pose(mechanism, text: str | None, option: str = "--pose") -> np.ndarray:
    """A pose from the command line: a named pose of the mechanism, or every task coordinate (m, deg).

    ``None`` gives the home pose (the reference assembly of the file).
    """
    if text is None:
        return mechanism.home_pose
    words = text.split()
    if len(words) == 1 and not _is_number(words[0]):
        try:
            return mechanism.named_pose(words[0])
        except ValueError as error:
            raise fail(str(error)) from None
    try:
        numbers = [float(word) for word in words]
    except ValueError:
        raise fail(f"Expected numbers or a named pose after {option}, got {text!r}.") from None
    if len(numbers) != mechanism.n_task:
        units = ", ".join(f"{name} ({'deg' if is_angular(name) else 'm'})" for name in mechanism.task_coordinates)
        named = f" or a named pose ({', '.join(mechanism.named_poses)})" if mechanism.named_poses else ""
        raise fail(f"Expected {option} with {mechanism.n_task} values ({units}){named} for mechanism "
                   f"{mechanism.name!r}, got {len(numbers)}: {text}.")
    for word, number, name in zip(words, numbers, mechanism.task_coordinates):  # named as given on the line
        if not np.isfinite(number):
            raise fail(f"Expected finite values in {option}, got {word} for {name}.")
    try:
        return mechanism.poses_from_degrees(numbers, where=option)
    except ValueError as error:
        raise fail(str(error)) from None


def parse_range(text: str, option: str, *, include_stop: bool = False, angular: bool = False) -> np.ndarray:
    """``START:STOP:STEP`` -> START, START+STEP, ... up to STOP (included only if ``include_stop``).

    The stop is compared with a tolerance of a millionth of a step. Angles are given in degrees
    (within :func:`~screwkit.common.units.angle_limit`) and returned in radians when ``angular``.
    """
    parts = str(text).split(":")
    try:
        start, stop, step = (float(p) for p in parts)
    except ValueError:
        raise fail(f"Expected {option} as START:STOP:STEP (three numbers), got {text!r}.") from None
    for end in (start, stop) if angular else ():
        if abs(end) > angle_limit(degrees=True):
            raise fail(str(angle_beyond_limit(option, end, degrees=True)))
    from screwkit.studies.maps import range_values  # the maps' module: only for a command taking ranges

    try:
        values = range_values(start, stop, step, include_stop=include_stop)
    except ValueError as error:
        raise fail(f"Expected {option} with {error}, got {text!r}.") from None
    exact = decimal_range(parts[0], parts[2], len(values))
    values = values if exact is None else exact
    return np.deg2rad(values) if angular else values


def check_outputs(outputs: dict[str, tuple[str | None, tuple[str, ...]]], overwrite: bool, quiet: bool,
                  others: dict[str, str | None] | None = None) -> None:
    """Check every output path before any computation (suffix, folder, existing file), and that no two
    outputs, nor an output and one of the ``others`` files the command reads or keeps (``--state``), are
    the same file."""
    from screwkit.studies.files import check_distinct, check_output  # the output files: commands writing them

    try:
        check_distinct({**{option: path for option, (path, _) in outputs.items()}, **(others or {})})
    except ValueError as error:
        raise fail(str(error)) from None
    for option, (path, suffixes) in outputs.items():
        if path is None:
            continue
        try:
            removed = check_output(path, suffixes, overwrite=overwrite, what=option)
        except ValueError as error:
            raise fail(f"{option} {error}") from None
        if removed and not quiet:
            echo_error(f"removed {', '.join(removed)}: temporary file(s) left by an earlier run killed while writing "
                       f"{path}")


def check_colour_scale(vmin: float | None, vmax: float | None) -> None:
    """``--vmin`` / ``--vmax``, checked before any computation as the figure will check them."""
    from screwkit.plots import colour_scale  # the figures' package: only for a command that draws one

    try:
        colour_scale(vmin, vmax)
    except ValueError:
        low, high = colour_scale(None, None)
        shown = [f"{option} {value:g}" if value is not None else f"{option} {default:g} (default)"
                 for option, value, default in (("--vmin", vmin, low), ("--vmax", vmax, high))]
        raise fail(f"Expected finite --vmin < --vmax (the ends of the colour scale, index values), got "
                   f"{' '.join(shown)}.") from None


@contextlib.contextmanager
def connected(execution: Execution):
    """``--scheduler``: the execution with its scheduler's client, connected and its handshake made before any
    work (no ``--scheduler``: local threads, as it is)."""
    if execution.scheduler is None:
        yield execution
        return
    try:
        client = connect(execution.scheduler, execution.connect_timeout)
    except ClusterError as error:
        raise fail(str(error)) from None
    try:
        yield replace(execution, scheduler=client)
    finally:
        disconnect(client, execution.connect_timeout)
