"""The figure of a trajectory: the indices against arc length, and what each failure leaves uncontrollable.

:func:`trajectory_figure` draws a :class:`~screwkit.studies.trajectory.TrajectoryResult` (nothing is
computed here). matplotlib is imported inside the function.
"""

from __future__ import annotations

import numpy as np

from screwkit.plots.style import (
    BOLD,
    COLORMAP,
    F_IO_STYLE,
    LEGEND_SIZE,
    MANY,
    TITLE_SIZE,
    UNREACHABLE_COLOR,
    pyplot,
    wrap_text,
)

__all__ = ["trajectory_figure", "time_ticks", "trajectory_from_dataset"]

LOST_COLOR = "#D55E00"
"""Stretches where a failure leaves the platform below the level (Okabe-Ito vermilion)."""


def trajectory_from_dataset(dataset):
    """What :func:`trajectory_figure` draws, read back from the dataset of ``screwkit trajectory --out FILE.nc``
    (:meth:`~screwkit.studies.trajectory.TrajectoryResult.to_dataset`): the indices over ``sample`` with the
    ``arc_length`` (and ``t``) coordinates, and the JSON ``summary`` attribute (fault cases, worst failures,
    margins, events). Nothing is computed: the figure is the one ``trajectory --figure`` drew.

    Raises
    ------
    ValueError, KeyError
        The dataset lacks what the figure needs.
    """
    import json
    import re
    from types import SimpleNamespace

    from screwkit.studies.paths import ARC_LENGTH_NAMES  # the studies: for a file read back only
    from screwkit.studies.trajectory import FaultCase, Margin, PathEvent  # (likewise)

    summary = json.loads(dataset.attrs["summary"])

    def series(name: str) -> np.ndarray:
        return np.asarray(dataset[name].values, dtype=float)

    def number(value) -> float:
        return np.nan if value is None else float(value)

    faults = sorted(int(name[3:]) for name in dataset.data_vars if re.fullmatch(r"f_o\d+", str(name)))
    indices = SimpleNamespace(faults=faults, iti=series("iti"), lmti=series("lmti"),
                              f_o={j: series(f"f_o{j}") for j in faults}, f_io={j: series(f"f_io{j}") for j in faults})
    s = np.asarray(dataset["arc_length"].values, dtype=float)
    path = SimpleNamespace(arc_length=s, times=np.asarray(dataset["t"].values, dtype=float) if "t" in dataset else None,
                           samples=int(summary["samples"]), length=float(summary["length_m"]),
                           length_scale=float(summary["length_scale_m"]),
                           along_actuators=dataset["arc_length"].attrs.get("long_name") == ARC_LENGTH_NAMES[True])
    cases = tuple(FaultCase(int(c["j"]), tuple(c["failed"]), np.asarray(c["controllable_m"], float).reshape(-1, 2),
                            np.asarray(c["lost_m"], float).reshape(-1, 2), c["first_loss_m"], number(c["minimum"]),
                            number(c["at_m"]), tuple(c["singular_at_m"])) for c in summary["faults"])
    margins = {name: Margin(number(m["value"]), number(m["arc_length_m"]), m["sample"])
               for name, m in summary["margins"].items()}
    events = tuple(PathEvent(e["kind"], float(e["start_m"]), float(e["stop_m"]), tuple(e["samples"]), e["reason"])
                   for e in summary["events"])
    return SimpleNamespace(mechanism=summary["mechanism"], path=path, indices=indices, level=float(summary["level"]),
                           cases=cases, worst={int(j): tuple(tuple(t) for t in ties)
                                               for j, ties in summary["worst"].items()},
                           margins=margins, events=events,
                           mean={j: series(f"f_o_mean{j}") for j in faults if f"f_o_mean{j}" in dataset})


def _short(name: str) -> str:
    return name.rsplit(":", 1)[-1]


def time_ticks(s, times, *, spacing: float = 0.06) -> tuple[list[float], list[str]]:
    """Ticks of the time axis over arc length: positions (m of arc length) and labels (s).

    Round times within the path's own times (none before its first or after its last), each at the arc length
    where the path is at that time (linear between samples, as the path's times run between its samples). Where
    the platform dwells (consecutive samples at one arc length, so one position for a span of times), that
    position gets one tick labelled with the span, ``"t1–t2"`` (arrival–departure), and no round time inside the
    span is drawn; times are increasing, so no time lies at two arc lengths. A round-time tick closer than
    ``spacing`` (a fraction of the path's length) to a tick already placed (dwells first, then in time order) is
    left out, so labels do not overlap.
    """
    from matplotlib.ticker import MaxNLocator

    s, times = np.asarray(s, dtype=float), np.asarray(times, dtype=float)
    gap = spacing * max(float(s[-1] - s[0]), 1e-300)
    ticks: list[tuple[float, str]] = []
    dwells = []
    for k in np.flatnonzero(np.diff(s) <= 0):
        if dwells and dwells[-1][1] == times[k]:
            dwells[-1][1] = times[k + 1]
        else:
            dwells.append([times[k], times[k + 1], s[k]])
    for start, stop, at in dwells:
        ticks.append((float(at), f"{_time(start)}–{_time(stop)}"))
    candidates = MaxNLocator(nbins=8, steps=[1, 2, 2.5, 5, 10]).tick_values(times[0], times[-1])
    span = max(float(times[-1] - times[0]), 1e-300)
    for t in candidates:
        if not times[0] - 1e-9 * span <= t <= times[-1] + 1e-9 * span:
            continue
        if any(start <= t <= stop for start, stop, _ in dwells):
            continue
        at = float(np.interp(t, times, s))
        if all(abs(at - other) >= gap for other, _ in ticks):
            ticks.append((at, _time(t)))
    ticks.sort(key=lambda tick: tick[0])
    return [at for at, _ in ticks], [label for _, label in ticks]


def _time(t: float) -> str:
    return f"{float(np.round(t, 9)):g}"


def _series(ax, s, values, **style) -> None:
    """One index along the path: its line, and a dot at each reachable sample between two out of reach (or at an
    end of the path next to one), which a line alone does not draw."""
    values = np.asarray(values, dtype=float)
    ax.plot(s, values, **style)
    finite = np.isfinite(values)
    neighbours = np.zeros(len(values), dtype=bool)
    neighbours[1:] |= finite[:-1]
    neighbours[:-1] |= finite[1:]
    lone = finite & ~neighbours
    if lone.any() and len(values) > 1:
        dot = {key: value for key, value in style.items() if key in ("color", "zorder")}
        ax.plot(s[lone], values[lone], linestyle="none", marker=".", markersize=5, **dot)


def trajectory_figure(result):
    """Indices along the path and, for every number of faults j, the stretches each failure leaves uncontrollable.

    Panels, against arc length (m; when the path has times, a top axis marks the arc length where the path is at
    round times within its own, see :func:`time_ticks`):

    - (a) ITI, LMTI and, for every j, F_Oj (bold) and F_IOj (dashed), the level as a dotted line, unreachable
      stretches shaded grey;
    - one panel per j: a row per set of j failed actuators, shaded where the LMTI of the actuators left is
      below the level (control lost), the worst failures of the path named in bold, with the lowest value
      each row reaches.

    Parameters
    ----------
    result : TrajectoryResult

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = pyplot()
    samples = result.indices
    faults = samples.faults
    s = result.path.arc_length
    heights = [3.0] + [max(1.2, 0.22 * sum(c.faults == j for c in result.cases) + 0.6) for j in faults]
    figure, axes = plt.subplots(len(heights), 1, figsize=(9.5, 0.8 + sum(heights)), sharex=True,
                                layout="constrained", gridspec_kw={"height_ratios": heights})
    axes = np.atleast_1d(axes)
    ax = axes[0]
    colours = plt.get_cmap(COLORMAP)(np.linspace(0.15, 0.85, max(len(faults), 1)))
    _series(ax, s, samples.iti, label=f"ITI (min {np.nanmin(samples.iti):.3f})", color="0.45", linewidth=1.2)
    _series(ax, s, samples.lmti, label=f"LMTI (min {np.nanmin(samples.lmti):.3f})", color="0.2", linewidth=1.2,
            linestyle="--")
    for colour, j in zip(colours, faults):
        margin = result.margins.get(f"f_o{j}")
        shown = f" (min {margin.value:.3f})" if margin else ""
        _series(ax, s, samples.f_o[j], label=f"$F_{{O{j}}}${shown}", **{**BOLD, "color": colour})
        _series(ax, s, samples.f_io[j], label=f"$F_{{IO{j}}}$", **{**F_IO_STYLE, "color": colour, "linewidth": 1.0})
        if j in result.mean:
            _series(ax, s, result.mean[j], label=f"$F_{{O{j}}}$ mean", color=colour, linewidth=1.0, linestyle=":")
    ax.axhline(result.level, **{**MANY, "linestyle": ":", "color": "black"}, label=f"level {result.level:g}")
    for event in result.events:
        ax.axvspan(event.start, event.stop, color=UNREACHABLE_COLOR, zorder=0)
    ax.set_ylim(-0.02, 1.02)
    ax.set_ylabel("index")
    ax.legend(fontsize=LEGEND_SIZE, loc="center left", bbox_to_anchor=(1.01, 0.5), frameon=False)
    ax.set_title("(a) indices along the path" + ("; unreachable stretches shaded grey" if result.events else ""),
                 fontsize=TITLE_SIZE, loc="left")
    if result.path.times is not None:
        top = ax.secondary_xaxis("top", functions=(lambda x: x, lambda x: x))  # arc length, labelled with times
        positions, labels = time_ticks(s, result.path.times)
        top.set_xticks(positions, labels)
        top.set_xlabel("t (s)")
    worst_names = []
    for row, j in enumerate(faults, start=1):
        ax = axes[row]
        cases = [c for c in result.cases if c.faults == j]
        worst = set(result.worst.get(j, ()))
        for y, case in enumerate(cases):
            bars = [(start, stop - start) for start, stop in case.lost]
            ax.broken_barh(bars, (y - 0.38, 0.76), color=LOST_COLOR if case.failed in worst else "#E69F00",
                           alpha=0.9 if case.failed in worst else 0.55)
            if case.singular_at:  # one line of markers (a non-redundant mechanism's case has one at every sample)
                ax.plot(case.singular_at, [y] * len(case.singular_at), linestyle="none", marker="x", color="black",
                        markersize=4)
        labels = [f"{'+'.join(_short(n) for n in c.failed)}  (min {c.minimum:.2f})" for c in cases]
        ax.set_yticks(range(len(cases)), labels, fontsize=LEGEND_SIZE)
        for tick, case in zip(ax.get_yticklabels(), cases):
            if case.failed in worst:
                tick.set_fontweight("bold")
        ax.set_ylim(len(cases) - 0.5, -0.5)
        named = ", ".join("+".join(_short(n) for n in failed) for failed in result.worst.get(j, ()))
        worst_names.append(f"j={j}: {named or 'none'}")
        ax.set_title(wrap_text(f"({chr(ord('a') + row)}) {j} failure(s): shaded where the LMTI of the actuators "
                               f"left is below {result.level:g} (x: singular); worst for this path in bold: "
                               f"{named or 'none'}", 7.5, TITLE_SIZE), fontsize=TITLE_SIZE, loc="left")
    from screwkit.studies.paths import ARC_LENGTH_NAMES  # (the studies' words for the axis, as the file says them)

    axes[-1].set_xlabel(f"{ARC_LENGTH_NAMES[result.path.along_actuators]} (m; angles weighted by the length scale "
                        f"{result.path.length_scale:.4g} m/rad)")
    axes[-1].set_xlim(s[0], s[-1])
    figure.suptitle(wrap_text(f"{result.mechanism}: {result.path.samples} samples, {result.path.length:.4g} m of "
                              f"path; worst failure {'; '.join(worst_names)}", 9.0, TITLE_SIZE + 1),
                    fontsize=TITLE_SIZE + 1)
    return figure
