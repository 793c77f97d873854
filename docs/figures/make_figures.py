"""Regenerate the figures of the documentation (docs/figures/*.png).

Run from the repository root:

    python docs/figures/make_figures.py

It computes the paper's Fig. 4 sweep (x = y = 0, phi in 0.1 deg steps) and Fig. 5 map
(disc of radius 0.6 m, 0.02 m grid, phi in 1 deg steps) of the bundled ``planar_5rrr`` through
the generic screw path, prints the numbers quoted in docs/paper.md and writes the PNGs
(about a minute on two cores).
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from screwkit.io.loader import load  # noqa: E402
from screwkit.plots import COLORMAP, map_figure, save_figure, sweep_figure  # noqa: E402
from screwkit.studies.maps import planar_disc_map  # noqa: E402
from screwkit.studies.sweep import sweep  # noqa: E402
from screwkit.studies.tasks import Execution  # noqa: E402

FOLDER = Path(__file__).resolve().parent


def inscribed_radius(dataset, name: str, level: float) -> tuple[float, float]:
    """Largest grid radius r such that every grid position within r has ``name >= level``.

    Returns ``(r, r_fail)``: r is the radius of the farthest grid point inside the disc that
    is entirely at or above the level, r_fail the radius of the nearest grid point below it
    (the boundary lies between the two).
    """
    x, y = np.meshgrid(dataset["x"].values, dataset["y"].values)
    radius = np.hypot(x, y)
    values = dataset[name].values
    inside = radius <= dataset.attrs.get("radius_m", np.inf) + 1e-9
    failing = inside & ~(values >= level)  # NaN (unreachable) counts as failing
    r_fail = float(radius[failing].min()) if failing.any() else np.inf
    return float(radius[inside & (radius < r_fail)].max()), r_fail


def outer_radius(dataset, name: str, level: float) -> float:
    """Radius of the farthest grid point of the region ``name >= level`` that contains the centre."""
    from scipy import ndimage

    x, y = np.meshgrid(dataset["x"].values, dataset["y"].values)
    radius = np.hypot(x, y)
    labels, _ = ndimage.label(dataset[name].values >= level)
    centre = labels[np.unravel_index(np.argmin(radius), radius.shape)]
    return float(radius[labels == centre].max()) if centre else 0.0


def main() -> None:
    mechanism = load("planar_5rrr")

    fig4 = sweep(mechanism, [0.0, 0.0, 0.0], "phi", np.deg2rad(np.arange(0.0, 360.0, 0.1)), faults=1)
    minimum = int(np.argmin(fig4["f_o1"].values))
    print(f"Fig. 4: min F_O1 {float(fig4['f_o1'][minimum]):.4f} at phi = {float(fig4['phi'][minimum]):.1f} deg "
          "(0.1 deg)")
    coarse = fig4.isel(phi=slice(0, None, 10))
    print(f"Fig. 4: min F_O1 {float(coarse['f_o1'].min()):.4f} (1 deg)")
    figure = sweep_figure(fig4)
    save_figure(figure, FOLDER / "fig4_sweep.png", dpi=90)
    plt.close(figure)

    fig5 = planar_disc_map(mechanism, 0.6, 0.02, 1.0, execution=Execution(progress=False))
    figure = map_figure(fig5, ["iti", "lmti", "f_o1"])
    save_figure(figure, FOLDER / "map_5rrr.png")
    plt.close(figure)

    figure, axes = plt.subplots(1, 2, figsize=(8.2, 3.8), constrained_layout=True)
    for ax, (name, level, text_radius, label) in zip(axes, (("iti", 0.5, 0.5, "ITI"), ("f_o1", 0.4, 0.2, "F_O1"))):
        inner, failing = inscribed_radius(fig5, name, level)
        outer = outer_radius(fig5, name, level)
        print(f"Fig. 5: min {label} >= {level}: every grid position within r = {inner:.3f} m "
              f"(nearest failing point at {failing:.3f} m); the region reaches {outer:.3f} m along some rays; "
              f"the paper's text: {text_radius} m")
        image = ax.pcolormesh(fig5["x"], fig5["y"], np.ma.masked_invalid(fig5[name].values), cmap=COLORMAP,
                              vmin=0, vmax=1, shading="nearest")
        ax.contour(fig5["x"], fig5["y"], np.nan_to_num(fig5[name].values), levels=[level], colors="white",
                   linewidths=1.4)
        circle = np.linspace(0, 2 * np.pi, 200)
        ax.plot(inner * np.cos(circle), inner * np.sin(circle), color="black", linewidth=1.4,
                label=f"computed: r = {inner:.2f} m")
        ax.plot(text_radius * np.cos(circle), text_radius * np.sin(circle), color="black", linestyle="--",
                linewidth=1.2, label=f"paper's text: r = {text_radius} m")
        ax.set_aspect("equal")
        ax.set_title(f"min {label} over a turn; white: {label} = {level}", fontsize=9)
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
        ax.legend(loc="lower left", fontsize=7, framealpha=0.9)
    figure.colorbar(image, ax=axes, shrink=0.8)
    save_figure(figure, FOLDER / "fig5_radii.png")
    plt.close(figure)


if __name__ == "__main__":
    main()
