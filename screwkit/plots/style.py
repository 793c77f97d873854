"""The style every figure shares: colour map and scale, line styles, font sizes, names and units.

Also the small helpers the sweeps and the maps both use: :func:`pyplot` (matplotlib with a
backend that needs no display), axis labels with units, how the paper writes each index, text
wrapped to a width. matplotlib is imported inside the functions.
"""

from __future__ import annotations

import os
import re
import textwrap

import numpy as np

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
PAST_SINGULAR_COLOR = "#CC79A7"  # Okabe-Ito reddish purple: the hatching of poses past a singular configuration
LINESTYLES = ("-", "--", "-.", ":")
TITLE_SIZE = 9
LEGEND_SIZE = 7


def pyplot():
    """``matplotlib.pyplot``, switched to the Agg backend first when there is no display."""
    import matplotlib

    usable = ("agg", "module://matplotlib_inline.backend_inline")  # backends that need no display
    if not os.environ.get("DISPLAY") and matplotlib.get_backend().lower() not in usable:
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def require_dataset(data, function: str, takes: str) -> None:
    """A TypeError saying what ``function`` takes (``takes``) when ``data`` is no xarray Dataset (a file's path:
    open it first)."""
    if hasattr(data, "data_vars"):
        return
    opened = ": open the file first, xarray.open_dataset(path)" if isinstance(data, (str, os.PathLike)) else ""
    raise TypeError(f"{function} expects {takes}, got {type(data).__name__} {data!r:.60}{opened}.")


# --------------------------------------------------------------------------------------------
# Names and units
# --------------------------------------------------------------------------------------------

def coordinate_unit(dataset, name: str) -> str:
    """Unit of a coordinate: its ``units`` attribute, else deg for angles and m for the rest."""
    if name in dataset.coords and dataset[name].attrs.get("units"):
        return str(dataset[name].attrs["units"])
    return "deg" if name in ANGULAR_COORDINATES else "m"


def axis_label(dataset, name: str) -> str:
    """An axis label: the coordinate and its unit, ``x (m)``."""
    return f"{name} ({coordinate_unit(dataset, name)})"


def index_label(name: str) -> str:
    """How the paper writes an index variable: ``f_o1`` -> F_O1 (mathtext), ``iti`` -> ITI."""
    if name in ("iti", "lmti"):
        return name.upper()
    for prefix, letters in (("f_io", "IO"), ("f_o", "O")):
        if name.startswith(prefix) and name[len(prefix):].isdigit():
            return rf"$F_{{\mathrm{{{letters}}}{name[len(prefix):]}}}$"
    if name == "reachable_fraction":
        return "reachable fraction"
    return name


def fault_levels(dataset) -> list[int]:
    """The numbers of faults j with an ``f_o{j}`` variable, in increasing order."""
    return sorted(int(name[3:]) for name in dataset.data_vars if name.startswith("f_o") and name[3:].isdigit())


def wrap_text(text: str, width_inches: float, fontsize: float) -> str:
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


def fixed_coordinates(text: str, swept: str | None) -> str:
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
