"""Workspace maps like the paper's Fig. 5 (:func:`map_figure`), two designs side by side
(:func:`design_comparison_figure`) and the Pareto front of a design search (:func:`pareto_figure`).

matplotlib is imported inside the functions.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from screwkit.plots.style import (
    COLORMAP,
    LEGEND_SIZE,
    TITLE_SIZE,
    UNREACHABLE_COLOR,
    axis_label,
    colour_scale,
    coordinate_unit,
    fault_levels,
    fixed_coordinates,
    index_label,
    pyplot,
    require_dataset,
    wrap_text,
)


def _extend(arrays, low: float, high: float) -> str:
    """Colour-bar arrows for values outside the scale (``neither``, ``min``, ``max`` or ``both``)."""
    finite = [a[np.isfinite(a)] for a in (np.asarray(a, dtype=float) for a in arrays)]
    below = any(a.size and a.min() < low for a in finite)
    above = any(a.size and a.max() > high for a in finite)
    return {(False, False): "neither", (True, False): "min", (False, True): "max", (True, True): "both"}[(below, above)]


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
    plt = pyplot()
    low, high = colour_scale(vmin, vmax)
    dataset, reference = _as_dataset(dataset), _as_dataset(reference)
    for data in (dataset, reference) if reference is not None else (dataset,):
        require_dataset(data, "map_figure", "a map (the xarray.Dataset or GridMap of screwkit.studies.maps.index_map)")
    rows = [dataset] + ([reference] if reference is not None else [])
    if variables is None:
        variables = [v for v in ("iti", "lmti") if v in dataset.data_vars]
        variables += [f"f_o{j}" for j in fault_levels(dataset)]
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
        if coordinate_unit(dataset, x_name) == coordinate_unit(dataset, y_name):
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
                ax.set_title(wrap_text(f"{letter} {prefix}min {index_label(name)}", 2.9, TITLE_SIZE),
                             fontsize=TITLE_SIZE)
                ax.text(0.5, 0.5, wrap_text(f"{name}: not in {label or 'this dataset'}", 2.4, LEGEND_SIZE + 1),
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
            if coordinate_unit(data, x_name) == coordinate_unit(data, y_name):
                ax.set_aspect("equal")
            ax.set_title(wrap_text(f"{letter} {prefix}min {index_label(name)}", 2.9, TITLE_SIZE), fontsize=TITLE_SIZE)
            ax.set_xlabel(axis_label(data, x_name))
            ax.set_ylabel(axis_label(data, y_name))
    if image is not None:
        bar = figure.colorbar(image, ax=axes.ravel().tolist(), shrink=0.85, fraction=0.04, pad=0.02,
                              extend=_extend(drawn, low, high))
        bar.set_label("index value\n(minimum over the orientation set)", fontsize=TITLE_SIZE)
    lines = ["Minimum of each index over the orientation set"]
    for data, label in zip(rows, labels):
        parts = [str(data.attrs[k]) for k in ("orientation_set",) if data.attrs.get(k)]
        if data.attrs.get("fixed_pose"):
            parts.append(f"fixed {fixed_coordinates(data.attrs['fixed_pose'], None)}")
        if label or parts:
            lines.append(f"{label}{': ' if label and parts else ''}{'; '.join(parts)}")
    if any_grey:
        lines.append("light grey: unreachable at some orientation of the set")
    figure.suptitle(wrap_text("\n".join(lines), width - 0.4, TITLE_SIZE + 1), fontsize=TITLE_SIZE + 1)
    return figure


@dataclass(frozen=True)
class MapGrid:
    """Where the grids of :func:`design_comparison_figure` lie (its ``layout``)."""

    step: float
    coordinates: tuple | None = None
    axes_labels: tuple[str, str] = ("x (m)", "y (m)")
    area_unit: str = "m\u00b2"


def design_comparison_figure(reference_grid, optimised_grid, layout, level, name, *, vmin=None, vmax=None,
                             index="f_o1", over="a full rotation"):
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
    layout : float or MapGrid
        The spacing (m) of a square grid centred on the origin, or a :class:`MapGrid`: that ``step``,
        or the x and y values of a rectangular grid (``coordinates``: evenly spaced, every NaN point
        unreachable, ``step`` unused), the labels of its axes and the unit of its areas (rad² for angles).
    level : float
        The contour and area threshold of F_O1.
    name : str
        Name of the reference design (the left panel's title).
    vmin, vmax : float, optional
        Ends of the shared colour scale. ``None`` means the end of :data:`INDEX_RANGE`
        ([0, 1], not the data range), so both designs and other figures compare.
    index, over : str
        The index mapped (``f_o1``, ``f_io2``, ...) and the orientation set, for the labels.

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

    plt = pyplot()
    low, high = colour_scale(vmin, vmax)
    layout = layout if isinstance(layout, MapGrid) else MapGrid(layout)
    step, level = float(layout.step), float(level)
    if not (np.isfinite(step) and step > 0):
        raise ValueError(f"Expected `step` > 0, got {step!r}.")
    grids = [np.asarray(g, dtype=float) for g in (reference_grid, optimised_grid)]
    for g in grids:
        if g.ndim != 2:
            raise ValueError(f"Expected two-dimensional grids, got shape {g.shape}.")
    label = index_label(index)
    figure, axes = plt.subplots(1, 2, figsize=(8.6, 4.3), layout="compressed")
    halo = [effects.Stroke(linewidth=2.8, foreground="black"), effects.Normal()]
    image = None
    for ax, grid, title, letter in ((axes[0], grids[0], f"{name} (reference)", "(a)"),
                                    (axes[1], grids[1], "optimised", "(b)")):
        if layout.coordinates is None:
            x = step * (np.arange(grid.shape[1]) - grid.shape[1] // 2)
            y = step * (np.arange(grid.shape[0]) - grid.shape[0] // 2)
            inscribed = step * min(grid.shape[0] // 2, grid.shape[1] // 2)
            grey = ~np.isfinite(grid) & (np.hypot(*np.meshgrid(x, y)) <= inscribed * (1 + 1e-9))
            cell = step**2
        else:
            x, y = (np.asarray(values, dtype=float) for values in layout.coordinates)
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
        ax.set_title(wrap_text(f"{letter} {title}\narea where min {label} \u2265 {level:g}: "
                           f"{area:.4f} {layout.area_unit}", 3.8, TITLE_SIZE), fontsize=TITLE_SIZE)
        ax.set_aspect("equal")
        ax.set_xlabel(layout.axes_labels[0])
        ax.set_ylabel(layout.axes_labels[1])
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
    plt = pyplot()
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
