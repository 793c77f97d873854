"""Sweeps like the paper's Fig. 4: :func:`sweep_figure`, one panel per index along one swept coordinate.

matplotlib is imported inside the functions.
"""

from __future__ import annotations

import numpy as np

from screwkit.plots.style import (
    BOLD,
    COLORMAP,
    F_IO_STYLE,
    INDEX_RANGE,
    LEGEND_SIZE,
    LINESTYLES,
    MANY,
    MAX_LABELLED_CURVES,
    PAST_SINGULAR_COLOR,
    THIN,
    TITLE_SIZE,
    UNREACHABLE_COLOR,
    axis_label,
    coordinate_unit,
    fault_levels,
    fixed_coordinates,
    index_label,
    pyplot,
    require_dataset,
    wrap_text,
)


def _set_subscript(label: str) -> str:
    """``"1-2-3-4"`` -> ``"1234"`` as in the paper; with two-digit numbers, runs as ranges (``"1-11,13"``)."""
    parts = str(label).split("-")
    if all(len(p) == 1 for p in parts):
        return "".join(parts)
    if not all(p.isdigit() for p in parts):
        return ",".join(parts)
    numbers, runs = [int(p) for p in parts], []
    for number in numbers:
        if runs and number == runs[-1][1] + 1:
            runs[-1][1] = number
        else:
            runs.append([number, number])
    return ",".join(f"{a}" if a == b else f"{a},{b}" if b == a + 1 else f"{a}-{b}" for a, b in runs)


def _minimum(values) -> float | None:
    values = np.asarray(values, dtype=float)
    return float(np.nanmin(values)) if np.isfinite(values).any() else None


def _with_minimum(label: str, values) -> str:
    low = _minimum(values)
    return label if low is None else f"{label} (min {low:.3f})"


def _thin_curves(ax, x, curves, description: str, header: str) -> list:
    """Draw the thin component curves of a panel; return their legend entries.

    Up to :data:`MAX_LABELLED_CURVES` curves each get a colour sampled from :data:`COLORMAP`
    (and a line style once there are more than six) and a legend entry, after a header line
    ``header`` saying what they are. More curves are drawn in light grey behind one legend
    entry, ``description``, giving their number.
    """
    import matplotlib as mpl
    from matplotlib.lines import Line2D

    if not curves:
        return []
    if len(curves) <= MAX_LABELLED_CURVES:
        colours = mpl.colormaps[COLORMAP](np.linspace(0.0, 0.85, len(curves)))
        entries = [Line2D([], [], linestyle="none", label=header)]
        for i, ((label, values), colour) in enumerate(zip(curves, colours)):
            style = LINESTYLES[i % len(LINESTYLES)] if len(curves) > 6 else "-"
            entries += ax.plot(x, values, color=colour, linestyle=style, label=label, **THIN)
        return entries
    for _, values in curves:
        ax.plot(x, values, **MANY)
    style = {k: v for k, v in MANY.items() if k != "zorder"}
    return [Line2D([], [], label=f"{description}\n({len(curves)} curves, not labelled)", **style)]


def _legend(ax, handles) -> None:
    """One legend right of the panel (outside the axes, so it hides no curve)."""
    columns = 1 if len(handles) <= 11 else 2
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0,
              fontsize=LEGEND_SIZE, frameon=False, ncol=columns, handlelength=2.6, columnspacing=1.2)


def _bold(ax, x, values, label: str, **style):
    (line,) = ax.plot(x, values, label=_with_minimum(label, values), **{**BOLD, **style})
    return line


def _bands(ax, x, mask, label: str, **style) -> list:
    """Bands over the runs of poses where ``mask`` holds; their legend entry, if any."""
    mask = np.asarray(mask, dtype=bool)
    if not mask.any() or x.size == 0:
        return []
    half = np.diff(x).min() / 2 if x.size > 1 else 0.5
    padded = np.concatenate([[False], mask, [False]]).astype(int)
    starts, stops = np.flatnonzero(np.diff(padded) == 1), np.flatnonzero(np.diff(padded) == -1) - 1
    spans = [ax.axvspan(x[start] - half, x[stop] + half, zorder=0, **style) for start, stop in zip(starts, stops)]
    spans[0].set_label(label)
    return spans[:1]


def _shade_unreachable(ax, x, reachable) -> list:
    """Grey bands where the pose is unreachable (indices are NaN there); their legend entry, if any."""
    return _bands(ax, x, ~np.asarray(reachable, dtype=bool), "unreachable pose", color=UNREACHABLE_COLOR)


def _hatch_past_singular(ax, x, dataset) -> list:
    """Hatched bands over the poses whose way from the reference pose passes a configuration where a chain's joints
    are singular (``past_singular``: the assembly there keeps the reference's sign); their legend entry, if any."""
    if "past_singular" not in dataset.data_vars:
        return []
    past = dataset["past_singular"].values
    chains = [str(name) for name, any_past in zip(dataset["singular_chain"].values, past.any(axis=0)) if any_past]
    return _bands(ax, x, past.any(axis=1), f"past a singular configuration of chain {', '.join(chains)} (the "
                  "reference's sign kept)", facecolor="none", edgecolor=PAST_SINGULAR_COLOR, hatch="//", linewidth=0.0)


def _short_names(names: list[str]) -> list[str]:
    """Actuator names ``chain:joint`` shortened to the joint (unique in a URDF) when that keeps them distinct."""
    short = [name.rsplit(":", 1)[-1] for name in names]
    return short if len(set(short)) == len(short) else list(names)


def sweep_figure(dataset):
    """Every series of the paper's Fig. 4 along one swept coordinate, one panel per index.

    In every panel the bold black curve is the index and the thin curves are the components
    it is taken from; the legend (right of the panel) gives the minimum of the index along
    the sweep.

    The panels, lettered in order:

    - ITI (bold, the minimum) and the ITI of each actuator, named ``k: joint`` where ``k`` is
      the number used in the set labels of the other panels (``1-2-3``: actuators 1, 2, 3);
    - LMTI (bold, the maximum) and the OTI of every non-redundant submechanism;
    - the paper's panel (c), only when the dataset has the sets left after one fault and the
      set without the last actuator is still redundant (more than one submechanism): its LMTI
      (the paper's :math:`{}^4LMTI_{1234}`) and the OTI of its submechanisms. With one
      actuator more than degrees of freedom that set is non-redundant and its LMTI is just one
      OTI of the previous panel, so the panel is left out;
    - for every number of faults j: F_Oj (bold, the minimum), F_IOj = min(ITI, F_Oj) (dashed)
      and the LMTI of each actuator set left after j faults.

    A non-redundant mechanism (as many actuators as degrees of freedom) has no fault
    variables and gets the first two panels only. Panels with more than
    :data:`MAX_LABELLED_CURVES` thin curves (e.g. the 28 submechanisms of an 8-actuator
    hexapod) draw them in grey with one legend entry giving their number: a legend with more
    entries cannot be matched to the curves by colour. Unreachable poses are shaded grey, and poses past a
    singular configuration of a chain on the way from the reference pose (``past_singular``) hatched.
    The x axis is labelled with the swept coordinate and its unit; the suptitle names the
    mechanism, the other (fixed) coordinates as the dataset records them, and the method.

    Parameters
    ----------
    dataset : xarray.Dataset
        As returned by :func:`screwkit.sweep.sweep`: one dimension named after the swept
        coordinate (its ``units`` attribute gives the unit; otherwise deg for phi, roll,
        pitch, yaw and m for the others), variables ``iti``, ``iti_actuator`` (over
        ``actuator``), ``lmti``, ``oti_submechanism`` (over ``submechanism``), and for each j
        ``lmti_remaining{j}`` (over ``remaining{j}``), ``f_o{j}``, ``f_io{j}``; optionally
        ``reachable``. Attributes ``swept``, ``mechanism``, ``fixed_pose`` and ``method`` are
        used for the title when present.

    Returns
    -------
    matplotlib.figure.Figure
        The figure (constrained layout; save it with :func:`save_figure`).

    Raises
    ------
    ValueError
        If the dataset has no ``iti`` or ``lmti`` variable along one dimension.
    """
    require_dataset(dataset, "sweep_figure", "a sweep (the xarray.Dataset of screwkit.studies.sweep.sweep)")
    plt = pyplot()
    for name in ("iti", "lmti"):
        if name not in dataset.data_vars or dataset[name].ndim != 1:
            raise ValueError(f"Expected a sweep dataset with a one-dimensional {name!r} variable, got variables "
                             f"{sorted(dataset.data_vars)}.")
    coordinate = dataset.attrs.get("swept") or dataset["iti"].dims[0]
    x = np.asarray(dataset[coordinate].values, dtype=float)
    faults = fault_levels(dataset)
    has_subs = "oti_submechanism" in dataset.data_vars and "submechanism" in dataset.coords
    # Panel (c) needs the sets left after one fault, and is worth a panel only while the set without the
    # last actuator is still redundant (more than one submechanism): otherwise its LMTI is one OTI of (b).
    one_fault_sets = ("lmti_remaining1" in dataset.data_vars and dataset.sizes.get("remaining1", 0) > 0
                      and 1 in faults and has_subs
                      and sum(set(str(s).split("-")) <= set(str(dataset["remaining1"].values[0]).split("-"))
                              for s in dataset["submechanism"].values) > 1)
    panels = ["iti", "lmti"] + (["lmti_without"] if one_fault_sets else []) + [f"fault{j}" for j in faults]
    width = 9.5
    figure, axes = plt.subplots(len(panels), 1, figsize=(width, 0.8 + 2.3 * len(panels)), sharex=True,
                                layout="constrained")
    axes = np.atleast_1d(axes)
    actuators = [str(a) for a in dataset["actuator"].values] if "actuator" in dataset.coords else []
    reachable = dataset["reachable"].values if "reachable" in dataset.data_vars else None

    for row, (ax, panel) in enumerate(zip(axes, panels)):
        letter = f"({chr(ord('a') + row)})"
        thin = []
        if panel == "iti":
            if "iti_actuator" in dataset.data_vars:
                thin = _thin_curves(ax, x, [(f"{k}: {name}", dataset["iti_actuator"].isel(actuator=k - 1).values)
                                            for k, name in enumerate(_short_names(actuators), start=1)],
                                    "ITI of each actuator", "ITI of actuator k (joint):")
            bold = [_bold(ax, x, dataset["iti"].values, "ITI")]
            ax.set_ylabel("ITI")
            title = f"{letter} ITI (bold) = minimum of the ITI of each actuator (thin)"
        elif panel == "lmti":
            count = dataset.sizes.get("submechanism", 0) if has_subs else 0
            if has_subs:
                thin = _thin_curves(ax, x, [(str(label), dataset["oti_submechanism"].isel(submechanism=k).values)
                                            for k, label in enumerate(dataset["submechanism"].values)],
                                    "OTI of each submechanism", "OTI of submechanism (actuators k):")
            bold = [_bold(ax, x, dataset["lmti"].values, "LMTI")]
            ax.set_ylabel("LMTI")
            title = (f"{letter} LMTI of all actuators (bold) = maximum of the OTI of the {count} non-redundant "
                     f"submechanisms (thin)") if count else f"{letter} LMTI of all actuators"
        elif panel == "lmti_without":
            remaining = str(dataset["remaining1"].values[0])  # combination order: the set without the last actuator
            members = set(remaining.split("-"))
            removed = sorted(set(str(k) for k in range(1, len(actuators) + 1)) - members, key=int)
            subs = [(k, str(label)) for k, label in enumerate(dataset["submechanism"].values)
                    if set(str(label).split("-")) <= members]
            thin = _thin_curves(ax, x, [(label, dataset["oti_submechanism"].isel(submechanism=k).values)
                                        for k, label in subs],
                                "OTI of each of its submechanisms", "OTI of submechanism (actuators k):")
            name = rf"$^{{{len(members)}}}\mathrm{{LMTI}}_{{{_set_subscript(remaining)}}}$"
            bold = [_bold(ax, x, dataset["lmti_remaining1"].isel(remaining1=0).values, name)]
            ax.set_ylabel(name)
            without = f" (without actuator {', '.join(removed)})" if removed else ""
            title = (f"{letter} {name} (bold): LMTI of actuators {remaining}{without} = maximum of the OTI "
                     f"of its {len(subs)} submechanisms (thin)")
        else:
            j = int(panel[5:])
            key, dimension = f"lmti_remaining{j}", f"remaining{j}"
            sets = dataset.sizes.get(dimension, 0) if key in dataset.data_vars else 0
            if sets:
                thin = _thin_curves(ax, x, [(str(label), dataset[key].isel({dimension: k}).values)
                                            for k, label in enumerate(dataset[dimension].values)],
                                    f"LMTI of each set left after {j} fault{'s' if j > 1 else ''}",
                                    "LMTI of the actuators k left:")
            name = index_label(f"f_o{j}")
            bold = [_bold(ax, x, dataset[f"f_o{j}"].values, name)]
            if f"f_io{j}" in dataset.data_vars:
                bold.append(_bold(ax, x, dataset[f"f_io{j}"].values, f"{index_label(f'f_io{j}')} = min(ITI, {name})",
                                  **F_IO_STYLE))
            ax.set_ylabel(name)
            counted = f"the {sets} sets" if sets else "the sets"
            title = (f"{letter} {name} (bold) = minimum of the LMTI of {counted} of actuators left after {j} "
                     f"fault{'s' if j > 1 else ''} (thin); {index_label(f'f_io{j}')} dashed")
        if reachable is not None:
            bold += _shade_unreachable(ax, x, reachable)
        bold += _hatch_past_singular(ax, x, dataset)
        ax.set_title(wrap_text(title, width - 1.2, TITLE_SIZE), loc="left", fontsize=TITLE_SIZE)
        ax.set_ylim(INDEX_RANGE[0] - 0.03, INDEX_RANGE[1] + 0.05)
        ax.grid(alpha=0.3)
        _legend(ax, bold + thin)

    if x.size > 1:
        axes[-1].set_xlim(x.min(), x.max())
    if coordinate_unit(dataset, coordinate) == "deg":
        from matplotlib.ticker import MaxNLocator

        axes[-1].xaxis.set_major_locator(MaxNLocator(nbins=9, steps=[1, 1.5, 3, 4.5, 5, 10]))
    axes[-1].set_xlabel(axis_label(dataset, coordinate))
    mechanism = dataset.attrs.get("mechanism", "")
    lines = [f"{mechanism + ': ' if mechanism else ''}indices along {coordinate} "
             f"({coordinate_unit(dataset, coordinate)})"]
    fixed = fixed_coordinates(dataset.attrs.get("fixed_pose", ""), coordinate)
    details = [f"other coordinates fixed at {fixed}" if fixed else "", str(dataset.attrs.get("method", ""))]
    if any(details):
        lines.append("; ".join(d for d in details if d))
    figure.suptitle(wrap_text("\n".join(lines), width - 0.5, TITLE_SIZE + 1), fontsize=TITLE_SIZE + 1)
    return figure
