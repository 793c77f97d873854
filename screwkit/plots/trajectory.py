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

__all__ = ["trajectory_figure"]

LOST_COLOR = "#D55E00"
"""Stretches where a failure leaves the platform below the level (Okabe-Ito vermilion)."""


def _short(name: str) -> str:
    return name.rsplit(":", 1)[-1]


def trajectory_figure(result):
    """Indices along the path and, for every number of faults j, the stretches each failure leaves uncontrollable.

    Panels, against arc length (m; the time of the samples on a top axis when the path has times):

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
    ax.plot(s, samples.iti, label=f"ITI (min {np.nanmin(samples.iti):.3f})", color="0.45", linewidth=1.2)
    ax.plot(s, samples.lmti, label=f"LMTI (min {np.nanmin(samples.lmti):.3f})", color="0.2", linewidth=1.2,
            linestyle="--")
    for colour, j in zip(colours, faults):
        margin = result.margins.get(f"f_o{j}")
        shown = f" (min {margin.value:.3f})" if margin else ""
        ax.plot(s, samples.f_o[j], label=f"$F_{{O{j}}}${shown}", **{**BOLD, "color": colour})
        ax.plot(s, samples.f_io[j], label=f"$F_{{IO{j}}}$", **{**F_IO_STYLE, "color": colour, "linewidth": 1.0})
        if j in result.mean:
            ax.plot(s, result.mean[j], label=f"$F_{{O{j}}}$ mean", color=colour, linewidth=1.0, linestyle=":")
    ax.axhline(result.level, **{**MANY, "linestyle": ":", "color": "black"}, label=f"level {result.level:g}")
    for event in result.events:
        ax.axvspan(event.start, event.stop, color=UNREACHABLE_COLOR, zorder=0)
    ax.set_ylim(-0.02, 1.02)
    ax.set_ylabel("index")
    ax.legend(fontsize=LEGEND_SIZE, loc="center left", bbox_to_anchor=(1.01, 0.5), frameon=False)
    ax.set_title("(a) indices along the path" + ("; unreachable stretches shaded grey" if result.events else ""),
                 fontsize=TITLE_SIZE, loc="left")
    if result.path.times is not None:
        top = ax.secondary_xaxis("top", functions=(lambda x: np.interp(x, s, result.path.times),
                                                   lambda t: np.interp(t, result.path.times, s)))
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
            for z in case.singular_at:
                ax.plot([z], [y], marker="x", color="black", markersize=4)
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
    axes[-1].set_xlabel("arc length (m; angles weighted by the length scale "
                        f"{result.path.length_scale:.4g} m/rad)")
    axes[-1].set_xlim(s[0], s[-1])
    figure.suptitle(wrap_text(f"{result.mechanism}: {result.path.samples} samples, {result.path.length:.4g} m of "
                              f"path; worst failure {'; '.join(worst_names)}", 9.0, TITLE_SIZE + 1),
                    fontsize=TITLE_SIZE + 1)
    return figure
