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

The figures of sweeps are in :mod:`screwkit.plots.sweeps`, that of a trajectory in
:mod:`screwkit.plots.trajectory`, those of maps and designs in
:mod:`screwkit.plots.maps`, the style they share in :mod:`screwkit.plots.style`; every name is
imported from here.
"""

from __future__ import annotations

from screwkit.plots.maps import MapGrid, design_comparison_figure, map_figure, pareto_figure
from screwkit.plots.style import ANGULAR_COORDINATES as ANGULAR_COORDINATES
from screwkit.plots.style import BOLD as BOLD
from screwkit.plots.style import COLORMAP, INDEX_RANGE, colour_scale
from screwkit.plots.style import F_IO_STYLE as F_IO_STYLE
from screwkit.plots.style import LEGEND_SIZE as LEGEND_SIZE
from screwkit.plots.style import LINESTYLES as LINESTYLES
from screwkit.plots.style import MANY as MANY
from screwkit.plots.style import MAX_LABELLED_CURVES as MAX_LABELLED_CURVES
from screwkit.plots.style import THIN as THIN
from screwkit.plots.style import TITLE_SIZE as TITLE_SIZE
from screwkit.plots.style import UNREACHABLE_COLOR as UNREACHABLE_COLOR
from screwkit.plots.sweeps import sweep_figure
from screwkit.plots.trajectory import trajectory_figure
from screwkit.studies.files import FORMATS, save_figure  # re-exported: figures are saved from here

__all__ = ["COLORMAP", "INDEX_RANGE", "FORMATS", "sweep_figure", "trajectory_figure", "map_figure",
           "design_comparison_figure", "MapGrid",
           "pareto_figure", "save_figure", "colour_scale"]
