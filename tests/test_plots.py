"""Figures: colour map, colour scale, layout (nothing clipped), legends and axis names.

The datasets are built by hand in the format of ``screwkit.sweep.sweep`` and
``screwkit.maps.GridMap.to_dataset`` so that these tests depend on screwkit.plots only.
"""

from __future__ import annotations

from itertools import combinations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
import xarray as xr  # noqa: E402
from matplotlib.collections import QuadMesh  # noqa: E402
from matplotlib.colors import same_color  # noqa: E402
from matplotlib.text import Text  # noqa: E402

from screwkit import plots  # noqa: E402
from screwkit.plots import (  # noqa: E402
    COLORMAP,
    INDEX_RANGE,
    MAX_LABELLED_CURVES,
    MapGrid,
    design_comparison_figure,
    map_figure,
    save_figure,
    sweep_figure,
)


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


# --------------------------------------------------------------------------------------------
# Hand-made datasets in the modules' formats
# --------------------------------------------------------------------------------------------

def set_label(actuators) -> str:
    return "-".join(str(i + 1) for i in actuators)


def sweep_dataset(coordinate="phi", *, actuators=5, dof=3, points=37, units="deg", values=None,
                  unreachable=(), names=None, fixed_pose=None):
    """A dataset shaped like ``screwkit.sweep.sweep``'s (same variables, dimensions and attrs)."""
    shown = np.linspace(0.0, 360.0, points) if values is None else np.asarray(values, float)
    phase = np.linspace(0, 2 * np.pi, shown.size)
    rng = np.random.default_rng(0)
    names = names or [f"chain_{i + 1}:chain_{i + 1}_joint_b" for i in range(actuators)]
    iti_actuator = 0.75 + 0.2 * np.sin(phase[:, None] + rng.uniform(0, 6, actuators))
    subs = list(combinations(range(actuators), dof))
    oti = np.abs(np.sin(phase[:, None] + rng.uniform(0, 6, len(subs))))

    def lmti_of(chosen):
        members = [s for s, sub in enumerate(subs) if set(sub) <= set(chosen)]
        return oti[:, members].max(axis=-1)

    reachable = np.ones(shown.size, bool)
    reachable[list(unreachable)] = False
    iti = iti_actuator.min(axis=1)
    data = {
        "reachable": ((coordinate,), reachable),
        "iti": ((coordinate,), iti, {"long_name": "ITI (Eq. 7)"}),
        "iti_actuator": ((coordinate, "actuator"), iti_actuator, {"long_name": "ITI per actuator (Eq. 6)"}),
        "lmti": ((coordinate,), lmti_of(range(actuators)), {"long_name": "LMTI of all actuators (Eq. 11)"}),
        "oti_submechanism": ((coordinate, "submechanism"), oti,
                             {"long_name": "OTI of each non-redundant submechanism (Eq. 9)"}),
    }
    coords = {coordinate: (coordinate, shown, {"units": units} if units else {}),
              "actuator": ("actuator", names), "submechanism": ("submechanism", [set_label(s) for s in subs])}
    for j in range(1, actuators - dof + 1):
        remaining = list(combinations(range(actuators), actuators - j))
        coords[f"remaining{j}"] = (f"remaining{j}", [set_label(e) for e in remaining])
        stacked = np.stack([lmti_of(e) for e in remaining], axis=-1)
        data[f"lmti_remaining{j}"] = ((coordinate, f"remaining{j}"), stacked,
                                      {"long_name": f"LMTI of each actuator set left after {j} fault(s)"})
        data[f"f_o{j}"] = ((coordinate,), stacked.min(axis=-1), {"long_name": f"F_O{j} (Eq. 12)"})
        data[f"f_io{j}"] = ((coordinate,), np.minimum(iti, stacked.min(axis=-1)), {"long_name": f"F_IO{j} (Eq. 14)"})
    for key, value in data.items():
        if key != "reachable":
            value[1][~reachable] = np.nan
    dataset = xr.Dataset({k: xr.Variable(*v) for k, v in data.items()}, coords=coords)
    dataset.attrs.update(mechanism="test_mechanism", swept=coordinate, threshold_m=1e-6,
                         fixed_pose=fixed_pose or f"x=0, y=0, {coordinate}=0", method="generic screw path")
    return dataset


def map_dataset(x_name="x", y_name="y", *, x_unit="m", y_unit="m", size=11, faults=(1, 2), low=0.2, high=0.8,
                unreachable_corner=False, mechanism="test_map"):
    """A dataset shaped like ``screwkit.maps.GridMap.to_dataset()``'s, values within [low, high] on a disc."""
    x_values = np.linspace(-0.5, 0.5, size)
    y_values = np.linspace(-0.5, 0.5, size) if y_unit == "m" else np.linspace(-30, 30, size)
    xx, yy = np.meshgrid(np.linspace(-1, 1, size), np.linspace(-1, 1, size))
    inside = xx**2 + yy**2 <= 1.0
    base = low + (high - low) * (1 - np.clip(np.hypot(xx, yy), 0, 1))
    variables = {"reachable_fraction": np.where(inside, 1.0, np.nan)}
    keys = ["iti", "lmti"] + [f"{p}{j}" for j in faults for p in ("f_o", "f_io")]
    for k, key in enumerate(keys):
        variables[key] = np.where(inside, low + (base - low) * (1 - 0.1 * k), np.nan)
    if unreachable_corner:
        variables["reachable_fraction"][size // 2, size // 2] = 0.5
        for key in keys:
            variables[key][size // 2, size // 2] = np.nan
    dataset = xr.Dataset({key: ((y_name, x_name), values) for key, values in variables.items()},
                         coords={x_name: (x_name, x_values, {"units": x_unit}),
                                 y_name: (y_name, y_values, {"units": y_unit})})
    for key in keys:
        dataset[key].attrs["long_name"] = f"minimum of {key} over the orientation set"
    dataset.attrs.update(mechanism=mechanism, threshold_m=1e-6, method="generic screw path",
                         orientation_set="phi: 36 values from 0 to 350 deg", fixed_pose="", configurations=3000)
    return dataset


def design_grids(size=21, step=0.05):
    offsets = step * (np.arange(size) - size // 2)
    x, y = np.meshgrid(offsets, offsets)
    radius = np.hypot(x, y)
    inside = radius <= step * (size // 2)
    reference = np.where(inside, 0.7 - radius, np.nan)
    optimised = np.where(inside, 0.8 - 0.8 * radius, np.nan)
    optimised[size // 2, size // 2 + 1] = np.nan  # unreachable inside the disc
    return reference, optimised, step


# --------------------------------------------------------------------------------------------
# Helpers
# --------------------------------------------------------------------------------------------

def index_meshes(figure):
    """The colour-mapped images of the indices (not the grey 'unreachable' layers nor the colour bars)."""
    meshes = [c for ax in figure.axes for c in ax.collections if isinstance(c, QuadMesh)]
    bar_axes = {m.colorbar.ax for m in meshes if m.colorbar is not None}
    return [m for m in meshes if m.axes not in bar_axes and m.get_cmap().name != "unreachable"]


def colorbars(figure):
    return list({id(c.colorbar): c.colorbar for c in index_meshes(figure) if c.colorbar is not None}.values())


def all_texts(figure):
    return [t.get_text() for t in figure.findobj(Text) if t.get_text()]


def assert_texts_inside(figure, tmp_path, name):
    """After saving, every title, colour-bar label and legend text lies within the figure."""
    save_figure(figure, tmp_path / f"{name}.png", dpi=40)  # the layout, not the resolution, is checked
    figure.canvas.draw()
    renderer = figure.canvas.get_renderer()
    box = figure.bbox
    checked = []
    for text in figure.findobj(Text):
        if not text.get_text() or not text.get_visible() or (text.axes is not None and not text.axes.get_visible()):
            continue
        extent = text.get_window_extent(renderer)
        assert (extent.x0 >= box.x0 - 1 and extent.y0 >= box.y0 - 1 and extent.x1 <= box.x1 + 1
                and extent.y1 <= box.y1 + 1), f"{text.get_text()!r} at {extent} outside the figure {box}"
        checked.append(text.get_text())
    titles = [ax.get_title(loc) for ax in figure.axes for loc in ("center", "left", "right") if ax.get_title(loc)]
    bar_labels = [bar.ax.get_ylabel() for bar in colorbars(figure)]
    assert titles and set(titles) <= set(checked)
    assert set(bar_labels) <= set(checked)
    return titles, bar_labels


# --------------------------------------------------------------------------------------------
# Colour map and colour scale
# --------------------------------------------------------------------------------------------

def test_one_perceptually_uniform_colormap():
    assert COLORMAP in ("viridis", "cividis")
    figures = [map_figure(map_dataset()), map_figure(map_dataset(), reference=map_dataset(mechanism="other")),
               design_comparison_figure(*design_grids()[:2], 0.05, 0.4, "reference")]
    for figure in figures:
        meshes = index_meshes(figure)
        assert meshes
        assert {m.get_cmap().name for m in meshes} == {COLORMAP}
        assert all(bar.mappable.get_cmap().name == COLORMAP for bar in colorbars(figure))


def test_colour_scale_defaults_to_the_index_range_and_is_shared():
    dataset = map_dataset(low=0.2, high=0.8)  # data range narrower than [0, 1]
    for figure in (map_figure(dataset), design_comparison_figure(*design_grids()[:2], 0.05, 0.4, "ref")):
        meshes = index_meshes(figure)
        assert len(meshes) >= 2
        assert {(m.norm.vmin, m.norm.vmax) for m in meshes} == {INDEX_RANGE}
        assert len(colorbars(figure)) == 1  # one scale, one colour bar for all panels


def test_vmin_vmax_are_honoured():
    reference, optimised, step = design_grids()
    figures = [map_figure(map_dataset(), vmin=0.3, vmax=0.7),
               map_figure(map_dataset(), reference=map_dataset(), vmin=0.3, vmax=0.7),
               design_comparison_figure(reference, optimised, step, 0.4, "ref", vmin=0.3, vmax=0.7)]
    for figure in figures:
        assert {(m.norm.vmin, m.norm.vmax) for m in index_meshes(figure)} == {(0.3, 0.7)}
        (bar,) = colorbars(figure)
        assert bar.extend == "both"  # the data go past both ends: arrows on the colour bar
    figure = map_figure(map_dataset(), vmax=0.9)
    assert {(m.norm.vmin, m.norm.vmax) for m in index_meshes(figure)} == {(0.0, 0.9)}


@pytest.mark.parametrize("vmin, vmax", [(0.5, 0.5), (0.8, 0.2), (np.nan, 1.0)])
def test_bad_colour_scale_is_refused(vmin, vmax):
    with pytest.raises(ValueError, match="vmin"):
        map_figure(map_dataset(), vmin=vmin, vmax=vmax)
    with pytest.raises(ValueError, match="vmin"):
        design_comparison_figure(*design_grids(), 0.4, "ref", vmin=vmin, vmax=vmax)


# --------------------------------------------------------------------------------------------
# Nothing clipped
# --------------------------------------------------------------------------------------------

def test_titles_and_colorbar_labels_inside_the_figure(tmp_path):
    reference, optimised, step = design_grids()
    cases = {  # (the sweep figures are checked in the sweep tests)
        "map": map_figure(map_dataset("x", "yaw", y_unit="deg")),
        "map_reference": map_figure(map_dataset(), ["iti", "f_o1", "f_o2"], reference=map_dataset(faults=(1,))),
        "design": design_comparison_figure(reference, optimised, step, 0.4, "planar_5rrr"),
    }
    for name, figure in cases.items():
        titles, bar_labels = assert_texts_inside(figure, tmp_path, name)
        assert len(bar_labels) == 1 and bar_labels[0], name


# --------------------------------------------------------------------------------------------
# Sweeps
# --------------------------------------------------------------------------------------------

def legend_texts(ax):
    legend = ax.get_legend()
    assert legend is not None, ax.get_title("left")
    return [t.get_text() for t in legend.get_texts()]


def thin_lines(ax):
    return [line for line in ax.get_lines() if line.get_linewidth() < plots.BOLD["linewidth"]
            and not same_color(line.get_color(), plots.F_IO_STYLE["color"])]


def check_every_curve_named(figure):
    for ax in figure.axes:
        texts = legend_texts(ax)
        thin = thin_lines(ax)
        if len(thin) <= MAX_LABELLED_CURVES:
            assert all(line.get_label() in texts for line in thin), (ax.get_title("left"), texts)
        else:
            assert any(f"{len(thin)} curves" in t for t in texts), texts
        assert any(t.startswith(ax.get_ylabel()) for t in texts)  # the bold index


def test_sweep_over_yaw_names_yaw_and_labels_every_curve(tmp_path):
    dataset = sweep_dataset("yaw", actuators=8, dof=6, points=21, values=np.linspace(-30, 30, 21),
                            names=[f"leg_{i}:leg_{i}_joint_slider" for i in range(1, 9)],
                            fixed_pose="x=0, y=0, z=1, roll=0, pitch=-0, yaw=0")
    figure = sweep_figure(dataset)
    assert figure.axes[-1].get_xlabel() == "yaw (deg)"
    assert not any("phi" in text for text in all_texts(figure))
    suptitle = figure.get_suptitle()
    assert "yaw" in suptitle and "yaw=0" not in suptitle and "pitch=0" in suptitle
    check_every_curve_named(figure)
    # 8 actuators are named; the 28 submechanisms and 28 sets left after 2 faults are counted.
    first = legend_texts(figure.axes[0])
    assert all(any(f"{i}: leg_{i}_joint_slider" == t for t in first) for i in range(1, 9))
    assert any("28 curves" in t for t in legend_texts(figure.axes[1]))
    assert any("28 curves" in t for t in legend_texts(figure.axes[-1]))
    assert_texts_inside(figure, tmp_path, "yaw")


def test_sweep_over_phi_is_the_paper_figure(tmp_path):
    figure = sweep_figure(sweep_dataset("phi"))
    assert figure.axes[-1].get_xlabel() == "phi (deg)"
    assert "phi (deg)" in figure.get_suptitle()
    check_every_curve_named(figure)
    # (a) ITI, (b) LMTI, (c) the set without actuator 5, (d) F_O1, (e) F_O2
    titles = [ax.get_title("left") for ax in figure.axes]
    assert len(titles) == 5
    assert titles[2].startswith("(c)") and "1234" in titles[2] and "without actuator 5" in titles[2]
    assert "{O}1" in titles[3] and "{O}2" in titles[4]
    assert len(thin_lines(figure.axes[2])) == 4  # OTI of the 4 submechanisms of 1-2-3-4
    actuators = legend_texts(figure.axes[0])
    assert all(f"{i}: chain_{i}_joint_b" in actuators for i in range(1, 6))
    # F_IO drawn and named in every fault panel
    assert all(any(t.startswith("$F_{\\mathrm{IO}") for t in legend_texts(ax)) for ax in figure.axes[3:])


@pytest.mark.parametrize("coordinate, units, expected", [("x", None, "x (m)"), ("roll", None, "roll (deg)"),
                                                         ("z", "mm", "z (mm)")])
def test_sweep_unit_from_attrs_or_inferred(coordinate, units, expected):
    figure = sweep_figure(sweep_dataset(coordinate, units=units, points=11, values=np.linspace(0, 1, 11)))
    assert figure.axes[-1].get_xlabel() == expected


def test_no_fault_panels_for_a_non_redundant_mechanism():
    dataset = sweep_dataset(actuators=3, dof=3, points=11)
    assert not any(name.startswith("f_o") for name in dataset.data_vars)
    figure = sweep_figure(dataset)
    assert len(figure.axes) == 2
    assert [ax.get_ylabel() for ax in figure.axes] == ["ITI", "LMTI"]
    assert not any("fault" in text or "F_" in text for text in all_texts(figure))
    check_every_curve_named(figure)


def test_no_panel_c_when_one_fault_leaves_a_non_redundant_set():
    figure = sweep_figure(sweep_dataset(actuators=4, dof=3, points=11))
    assert [ax.get_title("left")[:3] for ax in figure.axes] == ["(a)", "(b)", "(c)"]
    assert "LMTI}_" not in figure.axes[2].get_title("left") and "{O}1" in figure.axes[2].get_title("left")


def test_unreachable_poses_are_shaded_and_named():
    figure = sweep_figure(sweep_dataset(points=19, unreachable=(4, 5, 6)))
    assert all("unreachable pose" in legend_texts(ax) for ax in figure.axes)


# --------------------------------------------------------------------------------------------
# Maps
# --------------------------------------------------------------------------------------------

def test_map_axes_name_the_grid_coordinates_with_units():
    figure = map_figure(map_dataset())
    panels = [ax for ax in figure.axes if ax.get_title()]
    assert len(panels) == 4  # iti, lmti, f_o1, f_o2
    assert all(ax.get_xlabel() == "x (m)" and ax.get_ylabel() == "y (m)" for ax in panels)
    assert all(ax.get_aspect() == 1.0 for ax in panels)
    figure = map_figure(map_dataset("x", "yaw", y_unit="deg"), ["iti"])
    (ax,) = [ax for ax in figure.axes if ax.get_title()]
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("x (m)", "yaw (deg)")
    assert ax.get_aspect() == "auto"  # metres against degrees: no equal scaling


def test_map_reference_row_and_missing_variable():
    figure = map_figure(map_dataset(mechanism="six"), ["iti", "f_o2"],
                        reference=map_dataset(faults=(1,), mechanism="five"))
    titles = [ax.get_title() for ax in figure.axes if ax.get_title()]
    assert titles[0].startswith("(a) six") and titles[2].startswith("(c) five")
    assert any("f_o2: not in five" in text for text in all_texts(figure))
    with pytest.raises(ValueError, match="Unknown map variable 'f_o9'"):
        map_figure(map_dataset(), ["f_o9"])


def test_map_marks_unreachable_points_grey():
    figure = map_figure(map_dataset(unreachable_corner=True), ["iti"])
    greys = [c for ax in figure.axes for c in ax.collections
             if isinstance(c, QuadMesh) and c.get_cmap().name == "unreachable"]
    assert len(greys) == 1 and greys[0].get_array().count() == 1
    assert "unreachable" in figure.get_suptitle()


def test_map_accepts_anything_with_to_dataset():
    class GridMapLike:
        def to_dataset(self):
            return map_dataset()

    assert len(index_meshes(map_figure(GridMapLike(), ["iti", "lmti"]))) == 2


# --------------------------------------------------------------------------------------------
# Design comparison
# --------------------------------------------------------------------------------------------

def test_design_comparison_contour_and_area():
    reference, optimised, step = design_grids()
    figure = design_comparison_figure(reference, optimised, step, 0.4, "planar_5rrr")
    panels = [ax for ax in figure.axes if ax.get_title()]
    assert len(panels) == 2
    assert panels[0].get_title().startswith("(a) planar_5rrr") and panels[1].get_title().startswith("(b) optimised")
    for ax, grid in zip(panels, (reference, optimised)):
        area = np.sum(grid[np.isfinite(grid)] >= 0.4) * step**2
        assert f"{area:.4f} m" in ax.get_title()
        assert len(ax.collections) >= 2  # map and contour
        assert any("= 0.4" in t.get_text() for t in ax.get_legend().get_texts())
    assert any(t.get_text() == "unreachable" for t in panels[1].get_legend().get_texts())


# --------------------------------------------------------------------------------------------
# Files
# --------------------------------------------------------------------------------------------

def small_figure():
    figure, ax = plt.subplots(figsize=(2, 1.5), layout="constrained")
    ax.plot([0, 1], [0, 1])
    ax.set_title("small")
    return figure


def test_save_figure_writes_a_figure_of_this_module(tmp_path):
    path = tmp_path / "map.png"
    save_figure(map_figure(map_dataset(size=5), ["iti"]), path)
    assert path.read_bytes().startswith(b"\x89PNG")


@pytest.mark.parametrize("suffix, magic", [(".png", b"\x89PNG"), (".pdf", b"%PDF"), (".svg", b"<?xml"),
                                           (".PNG", b"\x89PNG")])
def test_save_figure_formats(tmp_path, suffix, magic):
    path = tmp_path / f"figure{suffix}"
    save_figure(small_figure(), path)
    assert path.read_bytes().startswith(magic)
    assert [p.name for p in tmp_path.iterdir()] == [path.name]  # no temporary file left


@pytest.mark.parametrize("name", ["figure.jpg", "figure", "figure.png.txt"])
def test_save_figure_refuses_other_suffixes(tmp_path, name):
    path = tmp_path / name
    with pytest.raises(ValueError, match=r"the figure file must end in \.png, \.pdf, \.svg \(any case\)") as error:
        save_figure(small_figure(), path)
    assert str(error.value).startswith(f"{path}: ")
    assert not list(tmp_path.iterdir())


def test_design_comparison_on_a_rectangular_grid_of_angles():
    """Given coordinates (unequal steps, off the origin), the axes follow them and each area is the
    count at the level times dx dy, in the unit given."""
    roll, pitch = np.linspace(0.0, 0.4, 5), np.linspace(-0.3, 0.3, 4)
    rng = np.random.default_rng(1)
    grids = [rng.uniform(0, 1, (4, 5)) for _ in range(2)]
    grids[1][0, 0] = np.nan
    layout = MapGrid(1.0, coordinates=(roll, pitch), axes_labels=("roll (rad)", "pitch (rad)"), area_unit="rad\u00b2")
    figure = design_comparison_figure(*grids, layout, 0.5, "start", index="f_io1", over="yaw")
    panels = [ax for ax in figure.axes if ax.get_title()]
    for ax, grid in zip(panels, grids):
        area = np.sum(grid[np.isfinite(grid)] >= 0.5) * 0.1 * 0.2
        assert f"{area:.4f} rad\u00b2" in ax.get_title() and "mathrm{IO}1" in ax.get_title()
        assert ax.get_xlabel() == "roll (rad)" and ax.get_ylabel() == "pitch (rad)"
        assert ax.get_xlim()[0] < 0.0 < 0.4 < ax.get_xlim()[1] and ax.get_ylim()[0] < -0.3
    assert any(t.get_text() == "unreachable" for t in panels[1].get_legend().get_texts())
