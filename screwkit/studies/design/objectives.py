"""What a design search measures: the fault-tolerant region of a map and the metrics drawn from it.

A :class:`Region` is a map as ``screwkit map`` computes it (two grid coordinates, optionally
stacked along a third in layers, the minimum of every index over an orientation set at each grid
point), an index (``f_o1``, ``f_io1``, ..., or the average case ``f_o_mean1``, ...) and a level: the
fault-tolerant region is where the minimum of that index over the orientation set is at least the level.
:func:`region_metrics` evaluates a mechanism on it and returns every metric of :data:`METRICS`; each is
reproduced by a fresh ``screwkit map`` of the candidate's file with :meth:`Region.map_arguments` (one per layer).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from screwkit.common.tolerances import SINGULARITY_THRESHOLD
from screwkit.common.units import is_angular
from screwkit.indices.average import MEAN_NAME, averaging, is_mean_column
from screwkit.indices.registry import column_record
from screwkit.indices.stages import compiled_chunks
from screwkit.model import Mechanism
from screwkit.studies.maps import (
    MapBlock,
    disc_grid,
    disc_point_count,
    map_block,
    orientation_set,
    range_count,
    range_values,
)
from screwkit.studies.options import AnalysisOptions

__all__ = ["METRICS", "MAXIMISED", "UNITS", "MAX_CONFIGURATIONS_PER_DESIGN", "Region", "disc_region", "grid_region",
           "default_region", "region_size", "check_region_size", "turn_count", "check_turn_count", "check_disc",
           "real_number", "region_maps", "region_metrics", "inscribed_radius"]

MAX_CONFIGURATIONS_PER_DESIGN = 10**8
"""Poses a design may be evaluated at (grid points x orientations x layers); a larger region is refused from
its counts, before any array is built."""

METRICS = {
    "area": "area of the fault-tolerant region of the map (m^2 on a grid of two lengths, rad^2 on a grid of two "
            "angles, m rad on a mixed one; summed over layers)",
    "volume": "volume of the fault-tolerant region: area of each layer times the layer step (m^3; needs layers)",
    "inscribed": "radius of the largest disc (ball with layers) about a grid point that holds no grid point "
                 "outside the fault-tolerant region nor beyond the map (m, or rad on a grid of angles; NaN on a "
                 "grid that mixes lengths and angles)",
    "cylinder": "radius of the largest disc about a grid point whose points are fault tolerant in every layer: "
                "the largest vertical cylinder through the layers (unit and NaN as inscribed; without layers the "
                "inscribed disc)",
    "worst": "minimum of the index over the whole map (an unreachable point counts 0)",
    "mean": "mean of the index over the whole map (an unreachable point counts 0)",
    "iti_floor": "minimum of the ITI over the whole map (an unreachable point counts 0)",
    "lmti_floor": "minimum of the LMTI over the whole map (an unreachable point counts 0)",
    "footprint": "radius of the circle holding every base joint (and crank tip) (m, the family's measure)",
    "link_length": "longest link or leg at the home pose (m, the family's measure)",
}
"""Every metric of a candidate, with its meaning and unit."""

UNITS = {"area": "m^2", "volume": "m^3", "inscribed": "m", "cylinder": "m", "footprint": "m", "link_length": "m"}
"""Units of the metrics that have one (the others are index values)."""

MAXIMISED = {"area": True, "volume": True, "inscribed": True, "cylinder": True, "worst": True, "mean": True,
             "iti_floor": True, "lmti_floor": True, "footprint": False, "link_length": False}
"""The sense in which each metric is better: larger (True) or smaller (False)."""



def region_index_record(index: str, probabilities=None):
    """The registry record and j of a region's index (``f_o1``, ``f_io2``, ``f_o_mean1``, ...; any registered
    index); a ValueError naming the indices when there is none such."""
    if not is_mean_column(index):
        return column_record(index)
    with averaging(probabilities):
        return column_record(index)

@dataclass(frozen=True)
class Region:
    """A map and the fault-tolerant level on it.

    Attributes
    ----------
    grid : tuple of (str, ndarray)
        The two grid coordinates and their values (m, rad).
    over : tuple of (str, ndarray)
        The orientation set's coordinates and values (rad); the set is their product.
    mask : ndarray of bool (len(y), len(x)), optional
        Grid points mapped (a disc); all when None.
    layers : (str, ndarray), optional
        A third coordinate stacking maps (volume); values in m.
    index : str
        ``f_o1``, ``f_io1``, ``f_o2``, ... (the index whose minimum over the orientation set is
        compared with ``level``), or ``f_o_mean1``, ``f_o_mean2``, ...: the average case of Eq. 12 over the
        sets of failed actuators (:mod:`screwkit.indices.average`, screwkit's extension).
    level : float
    closed_forms : bool
        Evaluate with the paper's planar closed forms (planar families).
    map_options : tuple of str
        ``screwkit map`` options that compute the same map (without the layer's ``--at``).
    probabilities : tuple of float, optional
        With an ``f_o_mean<j>`` index: each actuator's failure probability, weighting the mean
        (:func:`~screwkit.indices.average.failure_weights`); equal weights without.
    steps : tuple of float, optional
        The step of each grid coordinate (m, rad): the cell is their product, also on an axis of one value
        (a disc of one point). Default: the spacing of the values (an axis of one value needs it).
    layer_step : float, optional
        The layers' step (m): each layer is that thick, however many layers there are. Default: the spacing
        of the layers' values (a single layer needs it).
    """

    grid: tuple
    over: tuple
    index: str = "f_o1"
    level: float = 0.4
    mask: NDArray[np.bool_] | None = field(default=None, compare=False)
    layers: tuple | None = None
    closed_forms: bool = False
    threshold: float = SINGULARITY_THRESHOLD
    map_options: tuple[str, ...] = ()
    probabilities: tuple[float, ...] | None = None
    steps: tuple[float, ...] | None = None
    layer_step: float | None = None

    def __post_init__(self):
        if self.steps is None:
            object.__setattr__(self, "steps", tuple(_step(name, values) for name, values in self.grid))
        if self.layers and self.layer_step is None:
            object.__setattr__(self, "layer_step", _step(*self.layers))
        if len(self.steps) != len(self.grid) or not all(math.isfinite(s) and s > 0 for s in self.steps):
            raise ValueError(f"Expected a step > 0 per grid coordinate, got {self.steps}.")
        if self.probabilities is not None:
            if not self.average:
                raise ValueError(f"Failure probabilities weight the mean over the sets of failed actuators: give "
                                 f"the region an index {MEAN_NAME}<j>, not {self.index!r}.")
            object.__setattr__(self, "probabilities", tuple(float(p) for p in self.probabilities))
        record, _ = self._record()  # any registered index (screwkit.indices.registry), with j if per fault
        low, high = record.bounds or (-math.inf, math.inf)
        if not low <= real_number(self.level, "region level") <= high:  # (NaN too)
            raise ValueError(f"Expected a region level in [{low:g}, {high:g}] (a value of {self.index}), got "
                             f"{self.level}.")

    @property
    def average(self) -> bool:
        """Whether the region's index is the average case of Eq. 12 (``f_o_mean<j>``)."""
        return is_mean_column(self.index)

    def _record(self):
        """The index's registry record and its j (the average case registered for the look-up)."""
        return region_index_record(self.index, self.probabilities)

    @property
    def analysis(self) -> AnalysisOptions:
        """What the region's maps compute at every pose: the j of its index, the mean too for ``f_o_mean<j>``."""
        return AnalysisOptions(threshold=self.threshold, faults=(self.faults,), closed_forms=self.closed_forms,
                               aggregate="mean" if self.average else "min", probabilities=self.probabilities)

    @property
    def cell(self) -> float:
        """Area of one grid cell, in :meth:`unit` ``("area")`` (m^2, rad^2 or m rad)."""
        return float(np.prod(self.steps))

    @property
    def length_unit(self) -> str:
        """Unit of the grid's distances: ``m``, ``rad``, or ``""`` when the grid mixes lengths and angles."""
        kinds = {is_angular(name) for name, _ in self.grid}
        return "" if len(kinds) > 1 else ("rad" if kinds.pop() else "m")

    def unit(self, metric: str) -> str:
        """Unit of ``metric`` on this region (``index`` for index values)."""
        if metric in ("area", "volume"):
            units = [("rad" if is_angular(name) else "m") for name, _ in self.grid]
            area = f"{units[0]}^2" if units[0] == units[1] else "m rad"
            return area if metric == "area" else f"{area} m"
        if metric in ("inscribed", "cylinder"):
            return self.length_unit or "mixed"
        return UNITS.get(metric, "index")

    @property
    def undefined_metrics(self) -> dict[str, str]:
        """The metrics this region leaves undefined (NaN for every design), each with what it needs (a phrase
        following the metric's name: ``volume needs a region with layers``)."""
        out = {} if self.layers else {"volume": "needs a region with layers"}
        names = ", ".join(name for name, _ in self.grid)
        if not self.length_unit:
            out.update(dict.fromkeys(("inscribed", "cylinder"), f"needs distances on the grid: give a grid of two "
                                                                 f"lengths or two angles, not {names}"))
        elif self.layers and self.length_unit != "m":
            out.update(dict.fromkeys(("inscribed", "cylinder"), f"needs distances across the layers: give a grid "
                                                                 f"of two lengths with layers, not {names}"))
        return out

    @property
    def configurations(self) -> int:
        """Poses a design is evaluated at: grid points (in the mask) x orientations x layers."""
        points = int(np.count_nonzero(self.mask)) if self.mask is not None else int(np.prod(
            [values.size for _, values in self.grid]))
        orientations = int(np.prod([values.size for _, values in self.over])) if self.over else 1
        return points * orientations * (self.layers[1].size if self.layers else 1)

    @property
    def faults(self) -> int:
        """The number of faults the region's index needs (1 for one without j: the map computes F_O1 anyway)."""
        return self.failures or 1

    @property
    def failures(self) -> int | None:
        """The j of the region's index (``f_o2``: 2), None for an index without one (``lmti``)."""
        return self._record()[1]

    @property
    def orientations(self) -> str:
        """The orientation set in words."""
        words = []
        for name, values in self.over:
            step = math.degrees(float(values[1] - values[0])) if values.size > 1 else 0.0
            full = is_angular(name) and values.size > 1 and abs(values.size * step - 360) < 1e-6
            words.append(f"a full turn of {name} ({step:g} deg steps)" if full else _span(name, values))
        return "; ".join(words) or "the home orientation"

    def describe(self) -> str:
        layers = f", layers {_span(*self.layers)}" if self.layers else ""
        grid = " x ".join(_span(name, values) for name, values in self.grid)
        return f"{self.index} >= {self.level:g} over {self.orientations}, on {grid}{layers}"

    def map_arguments(self, mechanism: Mechanism) -> list[list[str]]:
        """The ``screwkit map`` options computing the same map, one list per layer."""
        options = list(self.map_options)
        if self.average:
            options += ["--aggregate", "mean"]
            if self.probabilities is not None:
                options += ["--probabilities", *(repr(p) for p in self.probabilities)]
        if not self.layers:
            return [options]
        name, values = self.layers
        home = mechanism.home_pose
        out = []
        for value in values:
            at = [value if coordinate == name else home[i] for i, coordinate in enumerate(mechanism.task_coordinates)]
            shown = [math.degrees(v) if is_angular(c) else v for c, v in zip(mechanism.task_coordinates, at)]
            out.append([*options, "--at", *(repr(float(v)) for v in shown)])
        return out


def _step(name: str, values: NDArray) -> float:
    """The spacing of evenly spaced ``values``; a single value has none: its step must be given."""
    if values.size < 2:
        raise ValueError(f"Expected the step of {name!r}, which has a single value in the region.")
    return float(values[1] - values[0])


def _count(spec, include_stop: bool) -> int | None:
    """How many values ``(start, stop, step)`` gives (as :func:`~screwkit.studies.maps.range_values` counts them),
    without listing them; None for a spec it refuses (its own message then says why)."""
    try:
        start, stop, step = (float(v) for v in spec)
    except (TypeError, ValueError):
        return None
    if not (math.isfinite(start) and math.isfinite(stop) and math.isfinite(step)) or not step > 0 or not stop > start:
        return None
    return range_count(start, stop, step, include_stop=include_stop)


def _disc_points(radius: float, step: float) -> int | None:
    """:func:`~screwkit.studies.maps.disc_point_count`; None for a radius or step it refuses."""
    if not (math.isfinite(radius) and math.isfinite(step) and radius > 0 and step > 0):
        return None
    return disc_point_count(radius, step)


def turn_count(phi_step_degrees: float) -> int | None:
    """Angles of a full turn in ``phi_step_degrees`` steps (None for a step that is not > 0)."""
    if not (math.isfinite(phi_step_degrees) and phi_step_degrees > 0):
        return None
    return max(1, math.ceil((360.0 - 1e-9) / phi_step_degrees))


def check_turn_count(phi_step_degrees: float, name: str = "`phi_step_degrees`") -> int:
    """:func:`turn_count`, refused (ValueError naming ``name``) for a step that is not in (0, 360] (a larger one
    would score the single angle 0 as a full turn) or that makes more than :data:`MAX_CONFIGURATIONS_PER_DESIGN`
    angles, before any angle is listed."""
    phi_step_degrees = real_number(phi_step_degrees, name)
    turns = turn_count(phi_step_degrees)
    if turns is None or phi_step_degrees > 360:
        raise ValueError(f"Expected 0 < {name} <= 360 (deg), got {phi_step_degrees!r}.")
    if turns > MAX_CONFIGURATIONS_PER_DESIGN:
        raise ValueError(f"{name} {phi_step_degrees:g} makes {turns:,} angles of the full turn per design, more than "
                         "10^8: use a larger step.")
    return turns


def real_number(value, name: str) -> float:
    """``value`` as a float, or a TypeError naming ``name`` for what is not a real number (a string, a bool, an
    array)."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise TypeError(f"Expected {name} to be a number, got {type(value).__name__} {value!r:.60}.")
    return float(value)


def check_disc(radius: float, step: float, phi_step_degrees: float) -> int:
    """The turns of a disc of ``radius`` and grid ``step`` (m) turned in ``phi_step_degrees`` steps, each refused
    in one line naming it when it is not a finite number > 0 (and the step within a turn), or the disc when it
    has more than :data:`MAX_CONFIGURATIONS_PER_DESIGN` configurations, before any grid is built."""
    for name, value in (("radius", radius), ("step", step)):
        value = real_number(value, f"`{name}`")
        if not (math.isfinite(value) and value > 0):
            raise ValueError(f"Expected `{name}` > 0 (m), got {value!r}.")
    turns = check_turn_count(phi_step_degrees)
    _check_size(_disc_points(float(radius), float(step)), turns)
    return turns


def _check_size(*counts: int | None) -> None:
    """A region of more than :data:`MAX_CONFIGURATIONS_PER_DESIGN` poses refused from its ``counts`` (grid points,
    orientations, layers; None: not known, a spec refused later with its own message)."""
    if any(c is None for c in counts):
        return
    configurations = math.prod(counts)
    if configurations > MAX_CONFIGURATIONS_PER_DESIGN:
        raise ValueError(f"The region has {configurations:,} configurations per design (grid points x orientations "
                         f"x layers), more than 10^8: use larger steps.")


def _span(name: str, values: NDArray) -> str:
    unit, scale = ("deg", 180 / math.pi) if is_angular(name) else ("m", 1.0)
    return f"{name} {values[0] * scale:g}..{values[-1] * scale:g} {unit} ({values.size} values)"


def disc_region(radius: float, step: float, phi_step_degrees: float, *, index: str = "f_o1", level: float = 0.4,
                closed_forms: bool = True, centre=(0.0, 0.0), probabilities=None) -> Region:
    """The paper's Fig. 5 region of a planar mechanism: a disc about ``centre``, phi over a full turn
    (``probabilities``: :attr:`Region.probabilities`)."""
    _check_size(_disc_points(radius, step), turn_count(phi_step_degrees))
    x_values, y_values, mask = disc_grid(radius, step, centre)
    phi = np.deg2rad(np.arange(0.0, 360.0 - 1e-9, phi_step_degrees))
    options = ("--radius", repr(float(radius)), "--step", repr(float(step)), "--phi-step",
               repr(float(phi_step_degrees))) + (("--closed-forms",) if closed_forms else ())
    return Region((("x", x_values), ("y", y_values)), (("phi", phi),), index, level, mask, None, closed_forms,
                  map_options=options, probabilities=probabilities, steps=(float(step), float(step)))


def _range(name: str, spec, include_stop: bool) -> tuple[NDArray, str]:
    """Values (m, rad) and ``screwkit map`` text of ``(start, stop, step)`` (deg for angles)."""
    try:
        start, stop, step = (float(v) for v in spec)
    except (TypeError, ValueError):
        raise ValueError(f"Expected (start, stop, step) for {name} in the region, got {spec!r}.") from None
    try:
        values = range_values(start, stop, step, include_stop=include_stop)
    except ValueError as error:
        raise ValueError(f"Expected {name} in the region with {error}, got {spec!r}.") from None
    return (np.deg2rad(values) if is_angular(name) else values), f"{name}:{start!r}:{stop!r}:{step!r}"


def _spec_step(name: str, spec) -> float:
    """The step of a checked ``(start, stop, step)`` (m, rad)."""
    step = float(spec[2])
    return math.radians(step) if is_angular(name) else step


def grid_region(grid: dict, over: dict, *, layers: tuple | None = None, index: str = "f_o1",
                level: float = 0.4, probabilities=None) -> Region:
    """A spatial region, each coordinate as ``(start, stop, step)`` in m or deg, as ``screwkit map``
    reads them: the two ``grid`` coordinates include their stop, the ``over`` (orientation set)
    coordinates and ``layers`` (name, (start, stop, step)) exclude it (``probabilities``:
    :attr:`Region.probabilities`)."""
    if len(grid) != 2:
        raise ValueError(f"Expected a region grid of exactly two coordinates, got {list(grid)}.")
    if set(grid) & set(over):  # the message of screwkit map
        raise ValueError("A coordinate cannot be both on the grid and in the orientation set: "
                         f"{set(grid) & set(over)}.")
    if layers is not None and layers[0] in {*grid, *over}:
        where = "on the grid" if layers[0] in grid else "in the orientation set"
        raise ValueError(f"The layers' coordinate {layers[0]!r} is also {where}: a coordinate is on the grid, in the "
                         "orientation set or in the layers, once.")
    _check_size(*_grid_counts(grid, over, layers))
    options, axes, orientations = [], [], []
    for name, spec in grid.items():
        values, text = _range(name, spec, True)
        axes.append((name, values))
        options += ["--grid", text]
    for name, spec in over.items():
        values, text = _range(name, spec, False)
        orientations.append((name, values))
        options += ["--over", text]
    layer_step = None
    if layers is not None:
        name, spec = layers
        if is_angular(name):
            raise ValueError(f"Expected a length coordinate for the region's layers, got {name!r}.")
        layers, layer_step = (name, _range(name, spec, False)[0]), _spec_step(name, spec)
    return Region(tuple(axes), tuple(orientations), index, level, None, layers, False, map_options=tuple(options),
                  probabilities=probabilities, steps=tuple(_spec_step(name, spec) for name, spec in grid.items()),
                  layer_step=layer_step)


def _grid_counts(grid: dict, over: dict, layers) -> list[int | None]:
    """Values of each grid coordinate, each orientation coordinate and the layers, counted from their specs."""
    return [*(_count(spec, True) for spec in grid.values()), *(_count(spec, False) for spec in over.values()),
            *(() if layers is None else (_count(layers[1], False),))]


def _merged(family, changes: dict) -> dict:
    spec = {**family.region, **{k: v for k, v in changes.items() if v is not None}}
    if changes.get("grid") is not None:
        spec.pop("disc", None)
    return spec


def region_size(family, **changes) -> int | None:
    """Poses per design of :func:`default_region` ``(family, **changes)``, counted from the specs alone (no
    array built); None when a spec is not valid (:func:`default_region` says why)."""
    spec = _merged(family, changes)
    try:
        if "disc" in spec:
            radius, step, phi_step = (float(v) for v in spec["disc"])
            counts = [_disc_points(radius, step), turn_count(phi_step)]
        else:
            counts = _grid_counts(dict(spec.get("grid", {})), dict(spec.get("over", {})), spec.get("layers"))
    except (TypeError, ValueError):
        return None
    return None if not counts or any(c is None for c in counts) else math.prod(counts)


def check_region_size(family, **changes) -> None:
    """:func:`region_size` of more than :data:`MAX_CONFIGURATIONS_PER_DESIGN` poses refused (ValueError)."""
    _check_size(region_size(family, **changes))


def default_region(family, **changes) -> Region:
    """The family's default region (:attr:`~screwkit.studies.design.families.Family.region`) with ``changes``
    (``disc``, ``grid``, ``over``, ``layers``, ``index``, ``level``, ``closed_forms``, ``probabilities``).

    A region of more than :data:`MAX_CONFIGURATIONS_PER_DESIGN` poses is refused (ValueError) from its counts,
    before any array is built."""
    spec = _merged(family, changes)
    index, level = spec.get("index", "f_o1"), spec.get("level", 0.4)
    if "disc" in spec:
        if spec.get("layers"):
            raise ValueError("A disc region has no layers.")
        radius, step, phi_step = spec["disc"]
        return disc_region(radius, step, phi_step, index=index, level=level,
                           closed_forms=spec.get("closed_forms", True), probabilities=spec.get("probabilities"))
    if "grid" not in spec:
        raise ValueError(f"Family {family.name!r} has no default region: give its grid.")
    return grid_region(spec["grid"], spec.get("over", {}), layers=spec.get("layers"), index=index, level=level,
                       probabilities=spec.get("probabilities"))


def inscribed_radius(inside: NDArray[np.bool_], spacing) -> float:
    """Largest distance from a grid point of ``inside`` to the nearest grid point outside it, the
    grid's border counting as outside (m): a disc (ball) of any smaller radius about that point holds
    no outside point. 0 when ``inside`` is empty."""
    from scipy.ndimage import distance_transform_edt  # scipy.ndimage is only needed here

    if not inside.any():
        return 0.0
    padded = np.pad(inside, 1, constant_values=False)
    return float(np.max(distance_transform_edt(padded, sampling=spacing)))


def region_maps(mechanism: Mechanism, region: Region) -> dict[str, NDArray]:
    """The map's variables (layers, y, x) of ``mechanism`` on ``region``: NaN outside its mask."""
    names = mechanism.task_coordinates
    (x_name, x_values), (y_name, y_values) = region.grid
    for name in [x_name, y_name, *(n for n, _ in region.over), *((region.layers[0],) if region.layers else ())]:
        if name not in names:
            raise ValueError(f"The region uses {name!r}; mechanism {mechanism.name!r} has {', '.join(names)}.")
    shape = (y_values.size, x_values.size)
    mask = np.ones(shape, dtype=bool) if region.mask is None else region.mask
    over_axes = tuple(names.index(name) for name, _ in region.over)
    over_values = orientation_set(dict(region.over))
    layer_values = region.layers[1] if region.layers else [None]
    analysis = region.analysis
    out: dict[str, NDArray] = {}
    for k, value in enumerate(layer_values):
        at = mechanism.home_pose.copy()
        if value is not None:
            at[names.index(region.layers[0])] = value
        block = MapBlock(at, names.index(x_name), x_values, names.index(y_name), y_values, mask, over_axes, over_values)
        with compiled_chunks():  # a design's region is small, and a search evaluates hundreds
            values = map_block(mechanism, block, analysis)
        for key, column in values.items():
            grid = out.setdefault(key, np.full((len(layer_values),) + shape, np.nan))
            grid[k][mask] = column
    return out


def region_metrics(mechanism: Mechanism, region: Region, size: dict[str, float] | None = None) -> dict[str, float]:
    """Every metric of :data:`METRICS` (footprint and link length from ``size``, NaN without it)."""
    maps = region_maps(mechanism, region)
    if region.index not in maps:
        raise ValueError(f"Unknown region index {region.index!r}; the map has {', '.join(sorted(maps))}.")
    mask = np.broadcast_to(np.ones(maps["iti"].shape[1:], bool) if region.mask is None else region.mask,
                           maps["iti"].shape)
    index = np.where(mask, np.nan_to_num(maps[region.index], nan=0.0), np.nan)
    inside = index >= region.level
    layer_step = region.layer_step if region.layers else None
    area = float(np.sum(inside) * region.cell)
    spacing = list(region.steps)[::-1]
    if not region.length_unit or (layer_step and region.length_unit != "m"):  # distances across units: none
        radius = cylinder = math.nan
    else:
        radius = inscribed_radius(inside, [layer_step, *spacing]) if layer_step else inscribed_radius(inside[0],
                                                                                                      spacing)
        cylinder = inscribed_radius(inside.all(axis=0), spacing)
    metrics = {"area": area, "volume": area * layer_step if layer_step else math.nan, "inscribed": radius,
               "cylinder": cylinder,
               "worst": float(np.nanmin(index)), "mean": float(np.nanmean(index)),
               "iti_floor": float(np.nanmin(np.where(mask, np.nan_to_num(maps["iti"], nan=0.0), np.nan))),
               "lmti_floor": float(np.nanmin(np.where(mask, np.nan_to_num(maps["lmti"], nan=0.0), np.nan)))}
    size = size or {}
    metrics.update(footprint=float(size.get("footprint", math.nan)), link_length=float(size.get("link_length",
                                                                                                  math.nan)))
    return metrics
