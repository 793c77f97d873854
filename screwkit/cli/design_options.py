"""The option groups ``screwkit design-search``'s subcommands share, their records, and their parsing.

Each group is defined once and handed to a subcommand as one record: what a search varies and how
it goes (:class:`SearchOptions`), the region whose fault-tolerant part is measured
(:class:`RegionOptions`), the files written (:class:`DesignOutputs`), what is printed (:class:`Report`);
where the designs are evaluated is :func:`screwkit.cli.options.execution_options`. A study file
(``--study``) stands for options not given on the command line.
"""

from __future__ import annotations

import functools
import re
from dataclasses import dataclass

import click
from click.core import ParameterSource

from screwkit.cli.map_command import grid_spec
from screwkit.cli.options import (
    GreedyOption,
    check_colour_scale,
    check_outputs,
    check_probabilities,
    colour_scale_options,
    fail,
    json_option,
    option_group,
    overwrite_option,
    parse_probabilities,
    quiet_option,
)
from screwkit.indices.average import MEAN_NAME, is_mean_column
from screwkit.studies.design.families import Family
from screwkit.studies.design.objectives import (
    METRICS,
    check_region_size,
    check_turn_count,
    default_region,
    region_index_record,
)
from screwkit.studies.design.optimise import MAX_SEED
from screwkit.studies.files import DATA_SUFFIXES, FIGURE_SUFFIXES

__all__ = ["SearchOptions", "RegionOptions", "DesignOutputs", "Report", "search_options", "region_options",
           "design_outputs_options", "report_options", "study_option", "STUDY_KEYS", "read_study",
           "parse_assignments", "parse_bounds", "region_of", "check_region_against", "check_weighting_a_mean",
           "check_failures", "check_phi_step", "SEED_RANGE"]


# -- records -----------------------------------------------------------------------------------------

@dataclass(frozen=True)
class SearchOptions:
    """What a family search varies and how it goes, as the options give them (``NAME=VALUE`` texts
    are parsed against the family by :func:`parse_assignments` and :func:`parse_bounds`)."""

    objectives: tuple[str, ...] = ()
    constraints: tuple[str, ...] = ()
    free: tuple[str, ...] = ()
    assignments: tuple[str, ...] = ()
    starts: tuple[str, ...] = ()
    bounds: tuple[str, ...] = ()
    budget: int | None = None
    maxiter: int | None = None
    seed: int = 0
    popsize: int = 8
    state: str | None = None

    def check(self) -> None:
        if self.maxiter is not None and self.budget is not None:
            raise fail("Give --budget or --maxiter, not both.")

    def evaluations(self, varied: int) -> int:
        """The budget: ``--budget`` (default 384), or ``--maxiter`` generations of ``varied`` parameters."""
        if self.maxiter is not None:
            return self.popsize * varied * (self.maxiter + 1)
        return 384 if self.budget is None else self.budget


@dataclass(frozen=True)
class RegionOptions:
    """The region options of a search as given; None or empty: the family's default."""

    radius: float | None = None
    step: float | None = None
    phi_step: float | None = None
    grids: tuple[str, ...] = ()
    overs: tuple[str, ...] = ()
    layers: str | None = None
    index: str | None = None
    level: float | None = None
    probabilities: str | None = None

    @property
    def spatial(self) -> bool:
        """Whether a spatial region's grid, orientation set or layers are given."""
        return bool(self.grids or self.overs or self.layers)


@dataclass(frozen=True)
class DesignOutputs:
    """The files a search writes (``--urdf``, ``--table``, ``--figure``, ``--front-figure``), the ends of
    the figure's colour scale, and whether existing files are replaced."""

    urdf: str | None = None
    table: str | None = None
    figure: str | None = None
    front_figure: str | None = None
    vmin: float | None = None
    vmax: float | None = None
    overwrite: bool = False

    def check(self, quiet: bool, state: str | None) -> None:
        """Every output checked before any computation, and none the same file as the ``state``."""
        check_outputs({"--urdf": (self.urdf, (".urdf",)), "--table": (self.table, DATA_SUFFIXES),
                       "--figure": (self.figure, FIGURE_SUFFIXES),
                       "--front-figure": (self.front_figure, FIGURE_SUFFIXES)},
                      self.overwrite, quiet, others={"--state": state})
        check_colour_scale(self.vmin, self.vmax)


@dataclass(frozen=True)
class Report:
    """What a search prints: one JSON object or text (``--json``), the designs listed (``--top``), and
    whether stderr stays silent (``--quiet``)."""

    as_json: bool = False
    quiet: bool = False
    top: int = 12


# -- option groups -------------------------------------------------------------------------------------

SEED_RANGE = click.IntRange(0, MAX_SEED)
"""The seeds of a search, from ``--seed`` or a study file (those of numpy's and scipy's generators)."""


def check_phi_step(phi_step: float | None) -> None:
    """``--phi-step`` in (0, 360] deg, giving at most 10^8 angles of the full turn (refused before any array is
    built)."""
    if phi_step is None:
        return
    if not 0 < phi_step <= 360:
        raise fail(f"Expected 0 < --phi-step <= 360 (deg), got {phi_step:g}.")
    try:
        check_turn_count(phi_step, "--phi-step")
    except ValueError as error:
        raise fail(str(error)) from None


class IndexName(click.ParamType):
    """``--index``: a region's index by column name, checked as the region will check it (a study file's ``index``
    too, so that its refusal names the file and the key)."""

    name = "index"

    def convert(self, value, param, ctx):
        try:
            region_index_record(str(value).strip())
        except ValueError as error:
            self.fail(str(error), param, ctx)
        return str(value).strip()


def _region(radius, step, phi_step, grids, overs, layers, region_index, level, probabilities=None) -> RegionOptions:
    check_phi_step(phi_step)
    layers = (layers,) if isinstance(layers, str) else tuple(layers or ())
    if len(layers) > 1:
        raise fail(f"Expected one --layers (the coordinate the maps are stacked along), got {len(layers)}: "
                   + " ".join(f"--layers {text}" for text in layers) + ".")
    return RegionOptions(radius, step, phi_step, tuple(grids), tuple(overs), layers[0] if layers else None,
                         region_index, level, probabilities)


search_options = option_group(
    "search", SearchOptions,
    click.option("--objective", "objectives", multiple=True, type=click.Choice(list(METRICS)),
                 help="Metric to optimise (repeat for a Pareto front; default: area). See docs/design.md."),
    click.option("--constraint", "constraints", multiple=True, metavar="METRIC>=VALUE|METRIC<=VALUE",
                 help="A bound every design kept must meet, e.g. footprint<=1.2 (repeatable)."),
    click.option("--free", multiple=True, metavar="NAME",
                 help="A parameter to vary (repeatable; default: the family's)."),
    click.option("--set", "assignments", multiple=True, metavar="NAME=VALUE", help="Fix a parameter (repeatable)."),
    click.option("--start", "starts", multiple=True, metavar="NAME=VALUE",
                 help="Starting value of a varied parameter (repeatable; default: the family's default)."),
    click.option("--bounds", "bounds", multiple=True, metavar="NAME=LOWER:UPPER",
                 help="Narrow a varied parameter's bounds (repeatable)."),
    click.option("--budget", type=click.IntRange(min=0), help="Designs evaluated (count; default: 384)."),
    click.option("--maxiter", type=click.IntRange(min=1),
                 help="One objective: generations of differential evolution (sets the budget to popsize x "
                      "parameters x (maxiter + 1))."),
    click.option("--seed", type=SEED_RANGE, default=0, show_default=True,
                 help="Seed of the search (same seed, same run)."),
    click.option("--popsize", type=click.IntRange(min=2), default=8, show_default=True,
                 help="Population size per varied parameter (count)."),
    click.option("--state", type=click.Path(dir_okay=False),
                 help="Evaluation log: written as the search goes; run again with it to resume an interrupted "
                      "search."))
"""The search options, as ``search``, a :class:`SearchOptions`."""

region_options = option_group(
    "region", _region,
    click.option("--radius", type=float, help="Planar region: radius of the disc (m; default 0.6)."),
    click.option("--step", type=float, default=None, help="Planar region: grid step of the disc (m; default 0.05)."),
    click.option("--phi-step", type=float, default=None, help="Planar region: step of the full rotation (deg; "
                                                              "default 5)."),
    click.option("--grid", "grids", multiple=True, metavar="COORDINATE:START:STOP:STEP",
                 help="Spatial region: a map coordinate, stop included (twice), as screwkit map --grid."),
    click.option("--over", "overs", multiple=True, metavar="COORDINATE:START:STOP:STEP",
                 help="Spatial region: the orientation set, stop excluded, as screwkit map --over (repeatable)."),
    click.option("--layers", multiple=True, metavar="COORDINATE:START:STOP:STEP",
                 help="Spatial region: stack maps along a third coordinate for a volume, the stop excluded as "
                      "screwkit map --over (once)."),
    click.option("--index", "region_index", default=None, metavar="f_o1|f_io1|f_o_mean1|...", type=IndexName(),
                 help="Index whose minimum over the orientation set makes a point fault tolerant (default f_o1; "
                      "f_o_mean<j>: the mean over the sets of j failed actuators instead of the worst, screwkit's "
                      "extension of Eq. 12)."),
    click.option("--level", type=click.FloatRange(min=0, max=1), default=None,
                 help="The index level that makes a point fault tolerant (default: the family's, 0.4 planar)."),
    click.option("--probabilities", cls=GreedyOption, metavar="P1 P2 ...",
                 help="With --index f_o_mean<j>: each actuator's failure probability (in the order `screwkit info` "
                      "lists the actuators of a design), weighting the mean by the probability of each set of "
                      "failures."))
"""The region options, as ``region``, a :class:`RegionOptions`."""


def _outputs(urdf, table, figure, front_figure, overwrite, vmin=None, vmax=None) -> DesignOutputs:
    return DesignOutputs(urdf, table, figure, front_figure, vmin, vmax, overwrite)


design_outputs_options = option_group(
    "outputs", _outputs,
    click.option("--urdf", type=click.Path(dir_okay=False),
                 help="Write the best design here (.urdf; several objectives: the front's best in the first)."),
    click.option("--table", type=click.Path(dir_okay=False),
                 help="Every evaluation, its parameters and metrics, the best flagged (.nc or .csv)."),
    click.option("--figure", type=click.Path(dir_okay=False),
                 help="Maps of the start and the best design side by side (.png, .pdf or .svg)."),
    click.option("--front-figure", "front_figure", type=click.Path(dir_okay=False),
                 help="Several objectives: the Pareto front over every evaluation (.png, .pdf or .svg)."),
    colour_scale_options,
    overwrite_option)
"""The files of a search, as ``outputs``, a :class:`DesignOutputs`."""

report_options = option_group(
    "report", Report,
    click.option("--top", type=click.IntRange(min=2), default=12, show_default=True,
                 help="Designs listed: the ranking of permutations, or the Pareto front (evenly spread along it) "
                      "(count)."),
    json_option,
    quiet_option)
"""``--top``, ``--json`` and ``--quiet``, as ``report``, a :class:`Report`."""


# -- study files -----------------------------------------------------------------------------------------

STUDY_KEYS = {"family": "family_name", "legs": "legs", "objectives": "objectives", "constraints": "constraints",
              "free": "free", "set": "assignments", "start": "starts", "bounds": "bounds", "budget": "budget",
              "seed": "seed", "popsize": "popsize", "radius": "radius", "step": "step", "phi_step": "phi_step",
              "grid": "grids", "over": "overs", "layers": "layers", "index": "region_index", "level": "level",
              "probabilities": "probabilities"}
"""Keys of a study file and the option each stands for (``set``, ``start``: name -> value; ``bounds``:
name -> [lower, upper]; ``objectives``, ``constraints``, ``free``, ``grid``, ``over``, ``probabilities``: lists)."""


_LISTS = ("objectives", "constraints", "free", "grid", "over", "probabilities")
"""Study keys whose value is a list (or one item of it)."""


def read_study(path: str, parameters: dict[str, click.Parameter] | None = None) -> dict:
    """A study file (YAML or JSON) as option values: {option destination: value as the option gives it}.

    With ``parameters`` (the command's, by destination), each value goes through its option's conversion and
    range check, as the same text on the command line would (``seed``: 0 to 2**32 - 1); a value refused is one
    line naming the file and the key."""
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
        elif parameters is not None and STUDY_KEYS[key] in parameters:
            value = _converted(path, key, value, parameters[STUDY_KEYS[key]])
        elif key in _LISTS:
            value = tuple(str(v) for v in (value if isinstance(value, (list, tuple)) else [value]))
        if key == "probabilities":  # as --probabilities gives them: joined by spaces
            value = " ".join(str(v) for v in value)
        out[STUDY_KEYS[key]] = value
    return out


def _converted(path: str, key: str, value, parameter: click.Parameter):
    """A study value as its option reads the same text: a tuple of items for a list key, else the one value."""
    kind = SEED_RANGE if key == "seed" else parameter.type
    if key in _LISTS:
        items = list(value) if isinstance(value, (list, tuple)) else [value]
    elif isinstance(value, (list, tuple, dict)):
        raise fail(f"{path}: {key}: expected one value, got {value!r}.")
    else:
        items = [value]
    converted = []
    for item in items:
        try:
            if item is None or isinstance(item, (list, tuple, dict)):
                raise click.BadParameter("not a value")
            converted.append(kind.convert(str(item), parameter, click.get_current_context(silent=True)))
        except click.BadParameter:
            raise fail(f"{path}: {key}: expected {_expected(kind, parameter)}, got {item!r}.") from None
    return tuple(converted) if key in _LISTS or parameter.multiple else converted[0]


def _expected(kind: click.ParamType, parameter: click.Parameter) -> str:
    """What an option of type ``kind`` takes, in words: ``an integer >= 0``, ``one of area, volume, ...``."""
    if isinstance(kind, click.Choice):
        return f"one of {', '.join(map(str, kind.choices))}"
    if isinstance(kind, (click.types.IntParamType, click.types.FloatParamType)):
        words = "an integer" if isinstance(kind, click.types.IntParamType) else "a number"
        low, high = getattr(kind, "min", None), getattr(kind, "max", None)
        if low is not None and high is not None:
            return f"{words} in {low}..{high}"
        if low is not None:
            return f"{words} {'>' if kind.min_open else '>='} {low}"
        if high is not None:
            return f"{words} {'<' if kind.max_open else '<='} {high}"
        return words
    return parameter.metavar or "a text"


def study_option(function):
    """``--study FILE``: its keys stand for the options not given on the command line.

    Put it first (right below the command's decorator), so that the study's values are in place
    before the option groups make their records. Each value is converted and checked as its option's.
    """

    @functools.wraps(function)
    def command(*args, study_path=None, **values):
        if study_path:
            context = click.get_current_context()
            parameters = {parameter.name: parameter for parameter in context.command.params}
            for name, value in read_study(study_path, parameters).items():
                if context.get_parameter_source(name) in (ParameterSource.DEFAULT, None):
                    values[name] = value
        return function(*args, **values)

    return click.option(
        "--study", "study_path", type=click.Path(dir_okay=False),
        help="A study file (.yaml or .json) whose keys stand for this command's options (family, legs, objectives, "
             "constraints, free, set, start, bounds, budget, seed, popsize, radius, step, phi_step, grid, over, "
             "layers, index, level, probabilities); options given on the command line win.")(command)


# -- parsing against a family --------------------------------------------------------------------------

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
    """``COORDINATE:START:STOP:STEP`` checked as ``screwkit map`` checks it (the same function): ``--grid`` includes
    its stop, ``--over`` and ``--layers`` exclude it."""
    name, _ = grid_spec(mechanism, text, option, option == "--grid")
    start, stop, step = (float(part) for part in text.split(":")[1:])
    return name, (start, stop, step)


def _numbers(text: str):
    """``COORDINATE:START:STOP:STEP`` -> (coordinate, (start, stop, step)) unchecked, to count a region before
    building it; None if it is not four parts (:func:`_spec` then says why)."""
    name, _, rest = text.partition(":")
    try:
        start, stop, step = (float(part) for part in rest.split(":"))
    except ValueError:
        return None
    return name, (start, stop, step)


def _once(texts, option: str) -> None:
    """Each coordinate given once among ``texts`` of ``option``."""
    seen = {}
    for text in texts:
        name = text.partition(":")[0]
        if name in seen:
            if option == "--grid":  # the message of screwkit map
                raise fail(f"Expected two different coordinates in --grid, got {' '.join(texts)}.")
            raise fail(f"{option} {name} given twice ({seen[name]}, {text}): give each coordinate once.")
        seen[name] = text


def _check_size(family: Family, changes: dict, options: RegionOptions) -> None:
    """The region's poses per design counted from the options' numbers, before any of their values is listed."""
    rough = dict(changes)
    specs = {"grid": options.grids if len(options.grids) == 2 else (), "over": options.overs,
             "layers": (options.layers,) if options.layers else ()}
    for key, texts in specs.items():
        parsed = [_numbers(text) for text in texts]
        if any(p is None for p in parsed):
            return
        if parsed:
            rough[key] = parsed[0] if key == "layers" else dict(parsed)
    try:
        check_region_size(family, **rough)
    except ValueError as error:
        raise fail(str(error)) from None


def _check_metrics(region, search: SearchOptions | None) -> None:
    """The objectives and constraints of ``search`` against what ``region`` defines: one that is NaN for every design
    (``inscribed`` on a grid mixing a length and an angle) refused before any work."""
    if search is None:
        return
    undefined = region.undefined_metrics
    for name in search.objectives or ("area",):
        if name in undefined:
            raise fail(f"The objective {name} {undefined[name]}.")
    for text in search.constraints:
        name = re.split(r"[<>=]", text, maxsplit=1)[0].strip()
        if name in undefined:
            raise fail(f"The constraint {text} is never met: {name} {undefined[name]}.")


def _probabilities(options: RegionOptions) -> tuple[float, ...] | None:
    """``--probabilities`` as numbers, given with an ``f_o_mean<j>`` region index (its count is checked against a
    design's actuators by :func:`check_region_against`)."""
    values = parse_probabilities(options.probabilities)
    if values is None:
        return None
    if not values:
        raise fail("Expected a failure probability per actuator after --probabilities.")
    check_weighting_a_mean(options.index or "f_o1")
    return values


def check_weighting_a_mean(index: str) -> None:
    """``--probabilities`` weight the mean: a one-line error unless ``index`` is ``f_o_mean<j>``."""
    if not is_mean_column(index):
        raise fail(f"--probabilities weight the mean over the sets of failed actuators: give --index {MEAN_NAME}<j> "
                   f"(the index is {index}).")


def check_failures(index: str, faults: int | None, actuators: int, dof: int, holder: str) -> None:
    """At most a - n actuators may fail: a one-line error naming ``index`` and ``holder`` (what has the ``actuators``)
    when its ``faults`` are more."""
    if faults is not None and faults > actuators - dof:
        raise fail(f"--index {index}: {holder} {actuators} actuators for {dof} DoF, so at most {actuators - dof} may "
                   f"fail (j in 1..{actuators - dof}), not {faults}.")


def check_region_against(region, mechanism) -> None:
    """The region's index and failure probabilities against the actuators of ``mechanism`` (a design of the family
    searched; every design has as many): the j of an index per fault at most a - n, one probability in [0, 1] per
    actuator. One line before any work."""
    actuators = len(mechanism.actuator_names)
    check_failures(region.index, region.failures, actuators, mechanism.dof, "the designs have")
    check_probabilities(region.probabilities, actuators)


def region_of(family: Family, start_mechanism, options: RegionOptions, search: SearchOptions | None = None):
    """The search's region: the family's default, changed by the region options (a spatial region's
    coordinates are checked against ``start_mechanism``, the start design); ``search``'s objectives and constraints
    checked against it."""
    changes = {"index": options.index, "level": options.level, "probabilities": _probabilities(options)}
    if options.radius is not None or options.step is not None or options.phi_step is not None:
        if not family.planar:
            raise fail("--radius, --step and --phi-step map a planar family's disc; give --grid and --over.")
        disc = family.region["disc"]
        changes["disc"] = (disc[0] if options.radius is None else options.radius,
                           disc[1] if options.step is None else options.step,
                           disc[2] if options.phi_step is None else options.phi_step)
    if options.spatial:  # each given part replaces the family's default, the others stay
        if family.planar:
            raise fail("A planar family's region is a disc (--radius, --step, --phi-step), not --grid/--over.")
        if options.grids and len(options.grids) != 2:
            raise fail("Expected exactly two --grid options (the region's map).")
        _once(options.grids, "--grid")
        _once(options.overs, "--over")
        _check_size(family, changes, options)
        if options.grids:
            changes["grid"] = dict(_spec(start_mechanism, g, "--grid") for g in options.grids)
        if options.overs:
            changes["over"] = dict(_spec(start_mechanism, o, "--over") for o in options.overs)
        if options.layers:
            changes["layers"] = _spec(start_mechanism, options.layers, "--layers")
    try:
        region = default_region(family, **changes)
    except ValueError as error:
        raise fail(str(error)) from None
    _check_metrics(region, search)
    return region
