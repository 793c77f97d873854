"""Figures in the style of the paper: sweeps like Fig. 4, workspace maps like Fig. 5.

The figures take plain data: the ``xarray.Dataset`` of a sweep (:func:`sweep_figure`), of a
map (:func:`map_figure`), or two numpy grids (:func:`design_comparison_figure`); nothing
here computes an index.

Conventions shared by every figure:

- Colour maps use :data:`COLORMAP` (``viridis``: perceptually uniform, readable with the
  common colour-vision deficiencies and in greyscale). Curves that a legend names are
  coloured by sampling the same map.
- Every index lies in [0, 1], so colour scales default to that full range
  (:data:`INDEX_RANGE`): a colour means the same value in every panel and in every figure.
  ``vmin`` / ``vmax`` narrow it to stretch the contrast; all panels of one figure share one
  scale and one colour bar.
- Figures use constrained layout and :func:`save_figure` saves with a tight bounding box, so
  titles, legends and colour-bar labels stay inside the image.

matplotlib is imported inside the functions (the Agg backend when there is no display).
"""

from __future__ import annotations

import math
import os
import re
import textwrap

import numpy as np

from screwkit.studies.files import FORMATS, save_figure  # re-exported: figures are saved from here

__all__ = ["COLORMAP", "INDEX_RANGE", "FORMATS", "sweep_figure", "map_figure", "design_comparison_figure",
           "pareto_figure", "save_figure", "colour_scale"]

COLORMAP = "viridis"
"""The colour map of every figure (perceptually uniform and colour-blind safe; never ``jet``)."""

INDEX_RANGE = (0.0, 1.0)
"""Default colour scale and y range: the range every transmission and fault-tolerance index lives in."""


MAX_LABELLED_CURVES = 12
"""Most thin curves a sweep panel names in its legend; beyond that colours cannot be matched to entries."""

ANGULAR_COORDINATES = ("phi", "roll", "pitch", "yaw")

BOLD = {"color": "black", "linewidth": 2.2, "zorder": 4}
THIN = {"linewidth": 1.0, "alpha": 0.9, "zorder": 2}
MANY = {"color": "0.55", "linewidth": 0.6, "alpha": 0.6, "zorder": 1}
F_IO_STYLE = {"color": "#D55E00", "linewidth": 1.4, "linestyle": (0, (4, 2)), "zorder": 5}  # Okabe-Ito vermilion
UNREACHABLE_COLOR = "0.82"
LINESTYLES = ("-", "--", "-.", ":")
TITLE_SIZE = 9
LEGEND_SIZE = 7


def _pyplot():
    import matplotlib

    usable = ("agg", "module://matplotlib_inline.backend_inline")  # backends that need no display
    if not os.environ.get("DISPLAY") and matplotlib.get_backend().lower() not in usable:
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


# --------------------------------------------------------------------------------------------
# Names and units
# --------------------------------------------------------------------------------------------

def _unit(dataset, name: str) -> str:
    """Unit of a coordinate: its ``units`` attribute, else deg for angles and m for the rest."""
    if name in dataset.coords and dataset[name].attrs.get("units"):
        return str(dataset[name].attrs["units"])
    return "deg" if name in ANGULAR_COORDINATES else "m"


def _axis_label(dataset, name: str) -> str:
    return f"{name} ({_unit(dataset, name)})"


def _index_name(name: str) -> str:
    """How the paper writes a variable: ``f_o1`` -> F_O1 (mathtext), ``iti`` -> ITI."""
    if name in ("iti", "lmti"):
        return name.upper()
    for prefix, letters in (("f_io", "IO"), ("f_o", "O")):
        if name.startswith(prefix) and name[len(prefix):].isdigit():
            return rf"$F_{{\mathrm{{{letters}}}{name[len(prefix):]}}}$"
    if name == "reachable_fraction":
        return "reachable fraction"
    return name


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


def _fault_levels(dataset) -> list[int]:
    """The numbers of faults j with an ``f_o{j}`` variable, in increasing order."""
    return sorted(int(name[3:]) for name in dataset.data_vars if name.startswith("f_o") and name[3:].isdigit())


def _wrap(text: str, width_inches: float, fontsize: float) -> str:
    """Wrap text to fit a width (an average glyph is about 0.6 em wide).

    Mathtext (``$...$``) is measured by the characters it shows and never split.
    """
    characters = max(20, int(width_inches * 72 / (0.6 * fontsize)))
    segments = re.findall(r"\$[^$]*\$", text)
    for i, segment in enumerate(segments):
        shown = max(1, len(re.sub(r"\\[a-z]+|[{}_^$\\]", "", segment)))
        text = text.replace(segment, chr(0xE000 + i) * shown, 1)
    lines = "\n".join(textwrap.fill(line, characters, break_long_words=False, break_on_hyphens=False)
                      for line in text.split("\n"))
    for i, segment in enumerate(segments):
        lines = re.sub(chr(0xE000 + i) + "+", lambda _, segment=segment: segment, lines, count=1)
    return lines


def _minimum(values) -> float | None:
    values = np.asarray(values, dtype=float)
    return float(np.nanmin(values)) if np.isfinite(values).any() else None


def _with_minimum(label: str, values) -> str:
    low = _minimum(values)
    return label if low is None else f"{label} (min {low:.3f})"


def colour_scale(vmin: float | None = None, vmax: float | None = None) -> tuple[float, float]:
    """The colour scale of a map: ``None`` -> the end of :data:`INDEX_RANGE`; checked finite and increasing.

    Raises
    ------
    ValueError
        If an end is not finite or ``vmin >= vmax``.
    """
    low = INDEX_RANGE[0] if vmin is None else float(vmin)
    high = INDEX_RANGE[1] if vmax is None else float(vmax)
    if not (np.isfinite(low) and np.isfinite(high) and low < high):
        raise ValueError(f"Expected finite `vmin` < `vmax`, got vmin={vmin!r}, vmax={vmax!r}.")
    return low, high


def _extend(arrays, low: float, high: float) -> str:
    """Colour-bar arrows for values outside the scale (``neither``, ``min``, ``max`` or ``both``)."""
    finite = [a[np.isfinite(a)] for a in (np.asarray(a, dtype=float) for a in arrays)]
    below = any(a.size and a.min() < low for a in finite)
    above = any(a.size and a.max() > high for a in finite)
    return {(False, False): "neither", (True, False): "min", (False, True): "max", (True, True): "both"}[(below, above)]


# --------------------------------------------------------------------------------------------
# Sweeps (Fig. 4)
# --------------------------------------------------------------------------------------------

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


def _shade_unreachable(ax, x, reachable) -> list:
    """Grey bands where the pose is unreachable (indices are NaN there); their legend entry, if any."""
    reachable = np.asarray(reachable, dtype=bool)
    if reachable.all() or x.size == 0:
        return []
    half = np.diff(x).min() / 2 if x.size > 1 else 0.5
    padded = np.concatenate([[False], ~reachable, [False]]).astype(int)
    starts, stops = np.flatnonzero(np.diff(padded) == 1), np.flatnonzero(np.diff(padded) == -1) - 1
    spans = [ax.axvspan(x[start] - half, x[stop] + half, color=UNREACHABLE_COLOR, zorder=0)
             for start, stop in zip(starts, stops)]
    spans[0].set_label("unreachable pose")
    return spans[:1]


def _short_names(names: list[str]) -> list[str]:
    """Actuator names ``chain:joint`` shortened to the joint (unique in a URDF) when that keeps them distinct."""
    short = [name.rsplit(":", 1)[-1] for name in names]
    return short if len(set(short)) == len(short) else list(names)


def _fixed_coordinates(text: str, swept: str | None) -> str:
    """The ``fixed_pose`` attribute without the swept coordinate (its fixed value means nothing); -0 -> 0."""
    kept = []
    for part in str(text).split(","):
        name, _, value = part.strip().partition("=")
        if not name or name.strip() == swept:
            continue
        try:
            value = f"{float(value) + 0.0:g}"
        except ValueError:
            pass
        kept.append(f"{name.strip()}={value.strip()}" if value else name.strip())
    return ", ".join(kept)


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
    entries cannot be matched to the curves by colour. Unreachable poses are shaded grey.
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
    plt = _pyplot()
    for name in ("iti", "lmti"):
        if name not in dataset.data_vars or dataset[name].ndim != 1:
            raise ValueError(f"Expected a sweep dataset with a one-dimensional {name!r} variable, got variables "
                             f"{sorted(dataset.data_vars)}.")
    coordinate = dataset.attrs.get("swept") or dataset["iti"].dims[0]
    x = np.asarray(dataset[coordinate].values, dtype=float)
    faults = _fault_levels(dataset)
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
            name = _index_name(f"f_o{j}")
            bold = [_bold(ax, x, dataset[f"f_o{j}"].values, name)]
            if f"f_io{j}" in dataset.data_vars:
                bold.append(_bold(ax, x, dataset[f"f_io{j}"].values, f"{_index_name(f'f_io{j}')} = min(ITI, {name})",
                                  **F_IO_STYLE))
            ax.set_ylabel(name)
            counted = f"the {sets} sets" if sets else "the sets"
            title = (f"{letter} {name} (bold) = minimum of the LMTI of {counted} of actuators left after {j} "
                     f"fault{'s' if j > 1 else ''} (thin); {_index_name(f'f_io{j}')} dashed")
        if reachable is not None:
            bold += _shade_unreachable(ax, x, reachable)
        ax.set_title(_wrap(title, width - 1.2, TITLE_SIZE), loc="left", fontsize=TITLE_SIZE)
        ax.set_ylim(INDEX_RANGE[0] - 0.03, INDEX_RANGE[1] + 0.05)
        ax.grid(alpha=0.3)
        _legend(ax, bold + thin)

    if x.size > 1:
        axes[-1].set_xlim(x.min(), x.max())
    if _unit(dataset, coordinate) == "deg":
        from matplotlib.ticker import MaxNLocator

        axes[-1].xaxis.set_major_locator(MaxNLocator(nbins=9, steps=[1, 1.5, 3, 4.5, 5, 10]))
    axes[-1].set_xlabel(_axis_label(dataset, coordinate))
    mechanism = dataset.attrs.get("mechanism", "")
    lines = [f"{mechanism + ': ' if mechanism else ''}indices along {coordinate} ({_unit(dataset, coordinate)})"]
    fixed = _fixed_coordinates(dataset.attrs.get("fixed_pose", ""), coordinate)
    details = [f"other coordinates fixed at {fixed}" if fixed else "", str(dataset.attrs.get("method", ""))]
    if any(details):
        lines.append("; ".join(d for d in details if d))
    figure.suptitle(_wrap("\n".join(lines), width - 0.5, TITLE_SIZE + 1), fontsize=TITLE_SIZE + 1)
    return figure


# --------------------------------------------------------------------------------------------
# Maps (Fig. 5)
# --------------------------------------------------------------------------------------------

def _as_dataset(data):
    return data.to_dataset() if hasattr(data, "to_dataset") else data


def _grey_layer(ax, x, y, mask) -> None:
    """Paint the grid cells where ``mask`` is true in :data:`UNREACHABLE_COLOR` (under the index map)."""
    from matplotlib.colors import ListedColormap

    ax.pcolormesh(x, y, np.ma.masked_where(~mask, np.ones(mask.shape)), shading="nearest", vmin=0, vmax=1,
                  cmap=ListedColormap([UNREACHABLE_COLOR], name="unreachable"), rasterized=True)


def _grid_names(data, variable: str) -> tuple[str, str]:
    """(x, y) coordinate names of a map variable stored over (y, x)."""
    dims = data[variable].dims
    if len(dims) != 2:
        raise ValueError(f"Expected map variable {variable!r} over two grid coordinates, got dimensions {dims}.")
    return dims[1], dims[0]


def map_figure(dataset, variables=None, reference=None, *, vmin=None, vmax=None, columns=4):
    """Colour maps of the minimum over the orientation set of each index, like the paper's Fig. 5.

    One panel per variable (at most ``columns`` per row), all on one colour scale with one
    colour bar, in :data:`COLORMAP`. Grid points where the map was evaluated but some
    orientation of the set is unreachable (the index is NaN, ``reachable_fraction`` is not)
    are light grey; points outside the evaluated region (e.g. outside the disc) are blank.
    Axes are equal-scaled when both grid coordinates have the same unit.

    Parameters
    ----------
    dataset : xarray.Dataset or GridMap
        From :func:`screwkit.maps.index_map` or :func:`screwkit.maps.planar_disc_map`:
        variables over (y, x), grid coordinates with a ``units`` attribute (otherwise deg for
        phi, roll, pitch, yaw and m for the others). Anything with a ``to_dataset()`` method
        is converted first.
    variables : sequence of str, optional
        Variables to draw. Default: ``iti``, ``lmti`` and every ``f_o{j}`` (by increasing j).
    reference : xarray.Dataset or GridMap, optional
        A second map (e.g. another design) drawn below the first with the same variables
        and the same colour scale; a variable it lacks leaves a labelled empty panel.
    vmin, vmax : float, optional
        Ends of the colour scale shared by all panels. ``None`` means the end of
        :data:`INDEX_RANGE`, i.e. the full index range [0, 1] (not the data range), so that
        colours compare across panels and figures; pass e.g. the data range to stretch the
        contrast. Values outside the scale get an arrow on the colour bar.
    columns : int
        Most panels per row.

    Returns
    -------
    matplotlib.figure.Figure
        The figure (compressed constrained layout; save it with :func:`save_figure`).

    Raises
    ------
    ValueError
        If a requested variable is in neither dataset, a variable is not two-dimensional,
        or ``vmin >= vmax``.
    """
    plt = _pyplot()
    low, high = colour_scale(vmin, vmax)
    dataset, reference = _as_dataset(dataset), _as_dataset(reference)
    rows = [dataset] + ([reference] if reference is not None else [])
    if variables is None:
        variables = [v for v in ("iti", "lmti") if v in dataset.data_vars]
        variables += [f"f_o{j}" for j in _fault_levels(dataset)]
    variables = list(variables)
    if not variables:
        raise ValueError(f"Expected at least one variable to draw; the dataset has {sorted(dataset.data_vars)}.")
    for name in variables:
        if not any(name in data.data_vars for data in rows):
            raise ValueError(f"Unknown map variable {name!r}; the dataset has {sorted(dataset.data_vars)}.")
    columns = max(1, min(int(columns), len(variables)))
    block = math.ceil(len(variables) / columns)
    # Size the figure to the panels (equal-aspect panels as wide as their data), so that the
    # "compressed" layout packs panels and colour bar without wide gaps.
    panel_height, ratio = 2.6, 1.0
    first = next((v for v in variables if v in dataset.data_vars), None)
    if first is not None:
        x_name, y_name = _grid_names(dataset, first)
        if _unit(dataset, x_name) == _unit(dataset, y_name):
            spans = [float(np.ptp(dataset[n].values)) if dataset[n].size > 1 else 0.0 for n in (x_name, y_name)]
            ratio = float(np.clip(spans[0] / spans[1], 0.4, 2.0)) if min(spans) > 0 else 1.0
    width = columns * (panel_height * ratio + 0.8) + 1.3
    height = block * len(rows) * (panel_height + 0.75) + 0.35 + 0.2 * (len(rows) + 1)
    figure, axes = plt.subplots(block * len(rows), columns, figsize=(width, height), squeeze=False,
                                layout="compressed")
    image, drawn, any_grey, panel = None, [], False, 0
    labels = [str(d.attrs.get("label", d.attrs.get("mechanism", ""))) for d in rows]
    for r, (data, label) in enumerate(zip(rows, labels)):
        for c in range(block * columns):
            ax = axes[r * block + c // columns, c % columns]
            if c >= len(variables):
                ax.set_visible(False)
                continue
            name = variables[c]
            letter = f"({chr(ord('a') + panel)})"
            panel += 1
            prefix = f"{label}: " if len(rows) > 1 and label else ""
            if name not in data.data_vars:
                ax.set_axis_off()
                ax.set_title(_wrap(f"{letter} {prefix}min {_index_name(name)}", 2.9, TITLE_SIZE), fontsize=TITLE_SIZE)
                ax.text(0.5, 0.5, _wrap(f"{name}: not in {label or 'this dataset'}", 2.4, LEGEND_SIZE + 1),
                        ha="center", va="center", transform=ax.transAxes, fontsize=LEGEND_SIZE + 1)
                continue
            x_name, y_name = _grid_names(data, name)
            x, y = data[x_name].values, data[y_name].values
            values = np.asarray(data[name].values, dtype=float)
            if "reachable_fraction" in data.data_vars:
                evaluated = np.isfinite(np.asarray(data["reachable_fraction"].transpose(y_name, x_name).values, float))
                grey = evaluated & ~np.isfinite(values)
                if grey.any():
                    any_grey = True
                    _grey_layer(ax, x, y, grey)
            image = ax.pcolormesh(x, y, np.ma.masked_invalid(values), cmap=COLORMAP, vmin=low, vmax=high,
                                  shading="nearest", rasterized=True)
            drawn.append(values)
            if _unit(data, x_name) == _unit(data, y_name):
                ax.set_aspect("equal")
            ax.set_title(_wrap(f"{letter} {prefix}min {_index_name(name)}", 2.9, TITLE_SIZE), fontsize=TITLE_SIZE)
            ax.set_xlabel(_axis_label(data, x_name))
            ax.set_ylabel(_axis_label(data, y_name))
    if image is not None:
        bar = figure.colorbar(image, ax=axes.ravel().tolist(), shrink=0.85, fraction=0.04, pad=0.02,
                              extend=_extend(drawn, low, high))
        bar.set_label("index value\n(minimum over the orientation set)", fontsize=TITLE_SIZE)
    lines = ["Minimum of each index over the orientation set"]
    for data, label in zip(rows, labels):
        parts = [str(data.attrs[k]) for k in ("orientation_set",) if data.attrs.get(k)]
        if data.attrs.get("fixed_pose"):
            parts.append(f"fixed {_fixed_coordinates(data.attrs['fixed_pose'], None)}")
        if label or parts:
            lines.append(f"{label}{': ' if label and parts else ''}{'; '.join(parts)}")
    if any_grey:
        lines.append("light grey: unreachable at some orientation of the set")
    figure.suptitle(_wrap("\n".join(lines), width - 0.4, TITLE_SIZE + 1), fontsize=TITLE_SIZE + 1)
    return figure


def design_comparison_figure(reference_grid, optimised_grid, step, level, name, *, vmin=None, vmax=None,
                             index="f_o1", over="a full rotation", axes_labels=("x (m)", "y (m)"), area_unit="m\u00b2",
                             coordinates=None):
    """Side-by-side maps of the minimum of ``index`` (F_O1) over ``over`` for a reference and an optimised design.

    Each panel shows one grid (centred on the origin) in :data:`COLORMAP` on a shared colour
    scale, with the contour F_O1 = ``level`` (white with a black edge, readable on any colour)
    and, in its title, the area where the minimum reaches ``level`` (grid points at or above
    it, times ``step**2``, as :func:`screwkit.design.fault_tolerant_area` counts it). NaN
    points within the inscribed disc of the grid are light grey (unreachable at some angle);
    those beyond are blank.

    Parameters
    ----------
    reference_grid, optimised_grid : array_like, shape (k, k)
        Minimum of F_O1 over the rotation at each grid point, rows along y, columns along x,
        with the origin at the centre; NaN outside the disc or where unreachable.
    step : float
        Grid spacing (m).
    level : float
        The contour and area threshold of F_O1.
    name : str
        Name of the reference design (the left panel's title).
    vmin, vmax : float, optional
        Ends of the shared colour scale. ``None`` means the end of :data:`INDEX_RANGE`
        ([0, 1], not the data range), so both designs and other figures compare.
    index, over : str
        The index mapped (``f_o1``, ``f_io2``, ...) and the orientation set, for the labels.
    axes_labels, area_unit : str
        Labels of the grid's axes and the unit of its areas (a grid of angles: rad, rad²).
    coordinates : (array_like, array_like), optional
        The grid's x and y values (a rectangular map, evenly spaced; ``step`` is then unused and
        every NaN point is unreachable). Default: a grid of ``step`` centred on the origin.

    Returns
    -------
    matplotlib.figure.Figure
        The figure (compressed constrained layout; save it with :func:`save_figure`).

    Raises
    ------
    ValueError
        If a grid is not two-dimensional, ``step`` is not positive, or ``vmin >= vmax``.
    """
    import matplotlib.patheffects as effects
    from matplotlib.lines import Line2D

    plt = _pyplot()
    low, high = colour_scale(vmin, vmax)
    step, level = float(step), float(level)
    if not (np.isfinite(step) and step > 0):
        raise ValueError(f"Expected `step` > 0, got {step!r}.")
    grids = [np.asarray(g, dtype=float) for g in (reference_grid, optimised_grid)]
    for g in grids:
        if g.ndim != 2:
            raise ValueError(f"Expected two-dimensional grids, got shape {g.shape}.")
    label = _index_name(index)
    figure, axes = plt.subplots(1, 2, figsize=(8.6, 4.3), layout="compressed")
    halo = [effects.Stroke(linewidth=2.8, foreground="black"), effects.Normal()]
    image = None
    for ax, grid, title, letter in ((axes[0], grids[0], f"{name} (reference)", "(a)"),
                                    (axes[1], grids[1], "optimised", "(b)")):
        if coordinates is None:
            x = step * (np.arange(grid.shape[1]) - grid.shape[1] // 2)
            y = step * (np.arange(grid.shape[0]) - grid.shape[0] // 2)
            inscribed = step * min(grid.shape[0] // 2, grid.shape[1] // 2)
            grey = ~np.isfinite(grid) & (np.hypot(*np.meshgrid(x, y)) <= inscribed * (1 + 1e-9))
            cell = step**2
        else:
            x, y = (np.asarray(values, dtype=float) for values in coordinates)
            grey = ~np.isfinite(grid)
            cell = abs((x[1] - x[0]) * (y[1] - y[0])) if x.size > 1 and y.size > 1 else 0.0
        if grey.any():
            _grey_layer(ax, x, y, grey)
        image = ax.pcolormesh(x, y, np.ma.masked_invalid(grid), cmap=COLORMAP, vmin=low, vmax=high,
                              shading="nearest", rasterized=True)
        below = np.where(np.isfinite(grid), grid, min(low, level) - 1.0)  # NaN counts as below the level
        finite = grid[np.isfinite(grid)]
        if finite.size and finite.max() >= level and (below < level).any():
            ax.contour(x, y, below, levels=[level], colors="white", linewidths=1.4).set(path_effects=halo)
        area = float(np.sum(finite >= level) * cell)
        ax.set_title(_wrap(f"{letter} {title}\narea where min {label} \u2265 {level:g}: "
                           f"{area:.4f} {area_unit}", 3.8, TITLE_SIZE), fontsize=TITLE_SIZE)
        ax.set_aspect("equal")
        ax.set_xlabel(axes_labels[0])
        ax.set_ylabel(axes_labels[1])
        handles = [Line2D([], [], color="white", linewidth=1.4, path_effects=halo, label=f"{label} = {level:g}")]
        if grey.any():
            from matplotlib.patches import Patch

            handles.append(Patch(color=UNREACHABLE_COLOR, label="unreachable"))
        ax.legend(handles=handles, loc="lower left", fontsize=LEGEND_SIZE, framealpha=0.9)
    bar = figure.colorbar(image, ax=list(axes), shrink=0.85, extend=_extend(grids, low, high))
    bar.set_label(f"min {label} over {over}", fontsize=TITLE_SIZE)
    figure.suptitle(f"Minimum of {label} over {over} at each position", fontsize=TITLE_SIZE + 1)
    return figure


def pareto_figure(result):
    """The objectives of every evaluation of a design search, the Pareto front and the start.

    ``result`` is a :class:`screwkit.studies.design.optimise.StudyResult` with two or more objectives;
    the first two are plotted (grey: every evaluation, red: infeasible, blue line: the front)."""
    plt = _pyplot()
    first, second = result.study.objectives[:2]
    figure, ax = plt.subplots(figsize=(5.2, 4.2), layout="constrained")
    for records, style in ((result.evaluations, dict(color="0.7", s=10, label="evaluated")),
                           ([r for r in result.evaluations if not r["feasible"]], dict(color="tab:red", s=10,
                                                                                         label="infeasible"))):
        if records:
            ax.scatter([r["metrics"][first] for r in records], [r["metrics"][second] for r in records], **style)
    ax.plot([r["metrics"][first] for r in result.best], [r["metrics"][second] for r in result.best], "o-",
            color="tab:blue", markersize=4, label=f"Pareto front ({len(result.best)})")
    ax.plot(result.start["metrics"][first], result.start["metrics"][second], "*", color="black", markersize=11,
            label="start")
    def label(name):
        return f"{name} ({result.study.region.unit(name)})".replace("^2", "\u00b2").replace("^3", "\u00b3")

    ax.set(xlabel=label(first), ylabel=label(second),
           title=f"{result.study.family.name}: {len(result.evaluations)} evaluations")
    ax.legend(fontsize=LEGEND_SIZE)
    return figure
