"""``screwkit design-search``: searching a parametric family, the paper's permutation selection, and the
planar family from a file's design, as three subcommands sharing their option groups
(:mod:`screwkit.cli.design_options`)."""

from __future__ import annotations

import json

import click
import numpy as np

from screwkit.cli.design_options import (
    RegionOptions,
    Report,
    SearchOptions,
    check_failures,
    check_phi_step,
    check_region_against,
    check_weighting_a_mean,
    design_outputs_options,
    parse_assignments,
    parse_bounds,
    region_of,
    region_options,
    report_options,
    search_options,
    study_option,
)
from screwkit.cli.family_search import run_search
from screwkit.cli.options import (
    GreedyOption,
    check_probabilities,
    connected,
    echo_error,
    execution_options,
    fail,
    load_mechanism,
    mechanism_argument,
    parse_probabilities,
    reading_options,
)
from screwkit.common.compiling import compile_ahead
from screwkit.common.memory import keep_freed_memory
from screwkit.indices.average import MEAN_NAME, is_mean_column
from screwkit.indices.registry import column_record
from screwkit.studies.design.families import FAMILIES, Family, family
from screwkit.studies.design.optimise import Constraint, Study
from screwkit.studies.design.permutations import (
    family_values,
    permutation_search,
    planar_design,
    rotation_class,
    slots_of,
)
from screwkit.studies.tasks import ClusterError

__all__ = ["design_search", "SUBCOMMANDS"]

SUBCOMMANDS = ("family", "permutations", "optimise")
"""The subcommands, in the order ``--help`` lists them."""

LEGACY_FLAGS = {"--permutations": "permutations", "--optimise": "optimise"}
"""The flags of the flat form (``design-search MECHANISM --permutations``) and the subcommand each became."""


class DesignSearchGroup(click.Group):
    """The subcommands; the flat form of earlier releases (``design-search FAMILY|MECHANISM [--permutations |
    --optimise] ...``) is still read, for one release, as its subcommand, with a note on stderr."""

    def list_commands(self, ctx: click.Context) -> list[str]:
        return list(SUBCOMMANDS)

    def parse_args(self, ctx: click.Context, args: list[str]) -> list[str]:
        if args and args[0] not in self.commands and args[0] not in ctx.help_option_names:
            args = _from_flat_form(args)
        return super().parse_args(ctx, args)


def _from_flat_form(args: list[str]) -> list[str]:
    """``design-search X --permutations ...`` -> ``permutations X ...`` (``--optimise``: ``optimise``, neither:
    ``family``), said on stderr unless ``--quiet``."""
    flags = [arg for arg in args if arg in LEGACY_FLAGS]
    if len(set(flags)) > 1:
        raise fail("Expected one of --permutations or --optimise, not both (they are the subcommands "
                   "design-search permutations and design-search optimise).")
    subcommand = LEGACY_FLAGS[flags[0]] if flags else "family"
    rest = [arg for arg in args if arg not in LEGACY_FLAGS]
    if "--quiet" not in rest:
        old = f"design-search MECHANISM {flags[0]}" if flags else "design-search FAMILY"
        new = f"design-search {subcommand} {'FAMILY' if subcommand == 'family' else 'MECHANISM'}"
        echo_error(f"Deprecated: `{old}` is now `{new}` (the flat form goes in the next release).")
    return [subcommand, *rest]


@click.group("design-search", cls=DesignSearchGroup)
def design_search() -> None:
    """Search designs for fault tolerance.

    family FAMILY: vary a parametric family's parameters (planar_rrr, ups_hexapod, rss_hexapod, delta,
    prs_ups) to optimise one or more metrics of the fault-tolerant region of a map (differential evolution, or
    NSGA-II for a Pareto front), e.g. design-search family ups_hexapod --objective area --budget 200, or
    design-search family --study study.yaml. permutations MECHANISM (a planar n-RRR): rank every slot
    assignment (the paper's selection). optimise MECHANISM: search the planar_rrr family from a planar n-RRR's
    design.
    """
    keep_freed_memory()  # one design after another reuses the pages the last one freed (screwkit.common.memory)


def _check(search_options: SearchOptions, outputs, report: Report) -> None:
    """What a search checks before any work: its options, and its outputs (no file written yet)."""
    search_options.check()  # (a seed is read by its option's type, from the command line or a study file)
    outputs.check(report.quiet, search_options.state)


def _run(chosen: Family, fixed: dict, initial: dict, options: SearchOptions, region: RegionOptions, outputs,
         execution, report: Report, start_name: str | None = None) -> None:
    """Search ``chosen`` from ``fixed`` and ``initial`` values over the region, then report."""
    try:
        start_mechanism = chosen.mechanism({**fixed, **initial}) if region.spatial else None
    except ValueError as error:
        raise fail(f"The start design: {error}") from None
    where = region_of(chosen, start_mechanism, region, options)
    if start_mechanism is None:  # a planar family's start: only to check the region against its actuators
        try:
            start_mechanism = chosen.mechanism({**fixed, **initial})
        except ValueError:
            start_mechanism = None  # (a start that does not build scores 0, as any such design)
    if start_mechanism is not None:
        check_region_against(where, start_mechanism)
        from screwkit.studies.kernels import constraint_kernels  # a design's region takes them (compiled_chunks)

        compile_ahead(*constraint_kernels(start_mechanism))  # compiled while the search starts, on a first run
    free = options.free or _varied(chosen, fixed)
    try:
        study = Study(chosen, where, tuple(options.objectives) or ("area",), free=tuple(free), fixed=fixed,
                      initial=initial, bounds=parse_bounds(chosen, options.bounds),
                      constraints=tuple(Constraint.parse(c) for c in options.constraints),
                      budget=options.evaluations(len(free)), seed=options.seed, popsize=options.popsize)
    except ValueError as error:
        raise fail(str(error)) from None
    with connected(execution) as execution:  # the handshake before any work
        run_search(study, options.state, execution, outputs, report, start_name)


def _varied(chosen: Family, fixed: dict) -> list[str]:
    """The parameters varied without --free: the family's that are not fixed (every one of them fixed: its other
    parameters that are not)."""
    return ([name for name in chosen.free if name not in fixed]
            or [parameter.name for parameter in chosen.parameters if parameter.name not in fixed])


@design_search.command("family", short_help="Search a parametric family: one objective or a Pareto front.")
@study_option
@click.argument("family_name", metavar="[FAMILY]", required=False)
@click.option("--legs", type=click.IntRange(min=1), help="Number of legs (default: 5 planar, 8 hexapods).")
@search_options
@region_options
@design_outputs_options
@execution_options()
@report_options
def family_search(family_name, legs, search, region, outputs, execution, report) -> None:
    """Search a parametric FAMILY for the largest fault-tolerant region (or a Pareto front).

    FAMILY is planar_rrr, ups_hexapod, rss_hexapod, delta or prs_ups (docs/design.md): its parameters
    vary to optimise one or more metrics of the fault-tolerant region of a map, by differential evolution
    (one objective) or NSGA-II (a Pareto front), seeded and resumable (--state), e.g.
    design-search family ups_hexapod --objective area --budget 200, or design-search family --study study.yaml.
    """
    if family_name is None:
        raise fail("Expected a FAMILY argument (or a study file with a family).")
    if family_name not in FAMILIES:
        raise fail(f"Expected a family ({', '.join(FAMILIES)}), got {family_name!r}; a planar n-RRR's design is "
                   "searched with design-search permutations MECHANISM or design-search optimise MECHANISM.")
    _check(search, outputs, report)
    try:
        chosen = family(family_name, legs)
    except ValueError as error:
        raise fail(str(error)) from None
    fixed, initial = parse_assignments(chosen, search.assignments, "--set"), parse_assignments(chosen, search.starts,
                                                                                             "--start")
    _run(chosen, fixed, initial, search, region, outputs, execution, report)


def _planar_design(mechanism: str, reading):
    if mechanism in FAMILIES:
        raise fail(f"{mechanism} is a family: design-search family {mechanism} searches it; this subcommand takes "
                   "a mechanism (planar_5rrr, a file).")
    loaded = load_mechanism(mechanism, reading)
    try:
        return loaded, planar_design(loaded)
    except ValueError as error:
        raise fail(str(error)) from None


@design_search.command("optimise", short_help="Search the planar_rrr family from a planar n-RRR's design.")
@mechanism_argument
@search_options
@region_options
@design_outputs_options
@execution_options()
@reading_options
@report_options
def optimise(mechanism, search, region, outputs, execution, reading, report) -> None:
    """Search the planar_rrr family from the design of MECHANISM, a planar n-RRR.

    The family's start is the file's platform radius and arm lengths (base, slots and working mode kept);
    the options are those of design-search family.
    """
    _check(search, outputs, report)
    loaded, template = _planar_design(mechanism, reading)
    try:
        count, values = family_values(template)
    except ValueError as error:
        raise fail(f"design-search optimise: {error}") from None
    chosen = family("planar_rrr", count)
    varied = search.free or chosen.free
    fixed = {name: value for name, value in values.items() if name not in varied}
    fixed.update(parse_assignments(chosen, search.assignments, "--set"))
    initial = {name: values[name] for name in varied if name not in fixed}
    initial.update(parse_assignments(chosen, search.starts, "--start"))
    _run(chosen, fixed, initial, search, region, outputs, execution, report, start_name=loaded.name)


@design_search.command("permutations", short_help="Rank the slot permutations of a planar n-RRR (the paper).")
@mechanism_argument
@click.option("--phi-step", type=float, default=1.0, show_default=True,
              help="Step of the full rotation at the centre the designs are scored over (deg).")
@click.option("--closed-forms", is_flag=True, help="Score with the paper's planar closed forms.")
@click.option("--index", "score_index", default="f_o1", show_default=True, metavar="f_o<j>|f_o_mean<j>",
              help="The index whose minimum over the rotation scores a design: F_Oj, the worst over the sets of j "
                   "failed actuators (the paper), or f_o_mean<j>, their mean (screwkit's extension of Eq. 12).")
@click.option("--probabilities", cls=GreedyOption, metavar="P1 P2 ...",
              help="With --index f_o_mean<j>: each chain's actuator failure probability (in the order `screwkit "
                   "info` lists the actuators), weighting the mean by the probability of each set of failures.")
@execution_options()
@reading_options
@report_options
def permutations(mechanism, phi_step, closed_forms, score_index, probabilities, execution, reading,
                 report: Report) -> None:
    """Rank every assignment of platform slots to the chains of MECHANISM (a planar n-RRR), in both working
    modes: the paper's design selection, each scored by the minimum F_O1 over a full rotation at the centre
    (--index: F_Oj, or its mean over the sets of failed actuators)."""
    check_phi_step(phi_step)
    aggregate, faults = _score_index(score_index)
    loaded, template = _planar_design(mechanism, reading)
    weights = parse_probabilities(probabilities)
    if weights is not None:
        check_weighting_a_mean(score_index)
        check_probabilities(weights, template.chain_count)
    check_failures(score_index, faults, template.chain_count, 3, f"{loaded.name} has")
    current = tuple(int(s) for s in slots_of(template))
    with connected(execution) as execution:  # the handshake before any work
        try:
            ranked = permutation_search(template, phi_step_degrees=phi_step, closed_forms=closed_forms,
                                        execution=execution, faults=faults, aggregate=aggregate,
                                        probabilities=weights)
        except ClusterError as error:
            raise fail(str(error)) from None
    _print_ranking(loaded, template, current, phi_step, ranked, report, score_index, weights)


def _score_index(text: str) -> tuple[str, int]:
    """``--index`` of the permutations: (aggregate, j) of ``f_o<j>`` or ``f_o_mean<j>``."""
    mean = is_mean_column(text)
    try:
        record, faults = column_record("f_o" + text[len(MEAN_NAME):] if mean else text)
    except ValueError:
        record, faults = None, None
    if record is None or record.name != "f_o" or faults is None:
        raise fail(f"Expected --index f_o<j> or {MEAN_NAME}<j> (j >= 1), got {text!r}.")
    return ("mean" if mean else "min"), faults


def _print_ranking(loaded, template, current, phi_step, ranked, report: Report, index: str = "f_o1",
                   probabilities=None) -> None:
    best = ranked[0].score
    rows = [{"permutation": list(d.permutation), "working_mode": d.working_mode, "score": d.score,
             "rank": 1 + sum(round(o.score, 9) > round(d.score, 9) for o in ranked if np.isfinite(o.score)),
             "rotation_class": list(rotation_class(d.permutation))} for d in ranked]
    mode = int(template.working_mode[0])
    mine = next(r for r in rows if tuple(r["permutation"]) == current and r["working_mode"] == mode)
    if report.as_json:
        click.echo(json.dumps({"mechanism": loaded.name, "current": list(current), "phi_step_deg": phi_step,
                               "index": index, "probabilities": None if probabilities is None else list(probabilities),
                               "designs": rows}))
        return
    weighted = "" if probabilities is None else f" (failure probabilities {' '.join(f'{p:g}' for p in probabilities)})"
    click.echo(f"{loaded.name}: {len(ranked)} designs (slot permutations x 2 working modes); score = min "
               f"{index}{weighted} over a full rotation at the centre, {phi_step:g} deg steps")
    click.echo(f"{'rank':>4s}  {'permutation':<18s} {'mode':>4s}  {'score':>7s}")
    for row in rows[:report.top]:
        mark = "  <- this file's design" if row is mine else ""
        click.echo(f"{row['rank']:>4d}  {str(row['permutation']):<18s} {row['working_mode']:>+4d}  "
                   f"{row['score']:.4f}{mark}")
    click.echo(f"this file's design {list(current)} ranks {mine['rank']} (best score {best:.4f})")
