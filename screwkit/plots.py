"""Figures in the style of the paper: sweeps like Fig. 4, workspace maps like Fig. 5.

matplotlib is imported inside the functions (Agg backend when no display).
"""

from __future__ import annotations

import os

import numpy as np

__all__ = ["sweep_figure", "map_figure", "save_figure"]

BOLD = {"color": "black", "linewidth": 2.2}
THIN = {"linewidth": 0.7, "alpha": 0.8}


def _pyplot():
    import matplotlib

    if not os.environ.get("DISPLAY") and matplotlib.get_backend().lower() not in ("agg", "module://matplotlib_inline.backend_inline"):
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def sweep_figure(dataset):
    """One panel per index along a sweep (bold: the index; thin: its components), like Fig. 4.

    Panels: (a) ITI of each actuator and overall; (b) OTI of every non-redundant
    submechanism and the LMTI; (c) for one fault, the LMTI of the set without the last
    actuator with the OTIs of its submechanisms; then for every j, the LMTI of each set left
    after j faults and F_Oj.
    """
    plt = _pyplot()
    coordinate = dataset.attrs.get("swept", list(dataset.dims)[0])
    x = dataset[coordinate].values
    faults = sorted(int(name[3:]) for name in dataset.data_vars if name.startswith("f_o") and name[3:].isdigit())
    panels = 2 + (1 if faults else 0) + len(faults)
    figure, axes = plt.subplots(panels, 1, figsize=(7, 2.2 * panels), sharex=True, constrained_layout=True)
    axes = np.atleast_1d(axes)
    ax = axes[0]
    for name in dataset["actuator"].values:
        ax.plot(x, dataset["iti_actuator"].sel(actuator=name), **THIN)
    ax.plot(x, dataset["iti"], label="ITI", **BOLD)
    ax.set_ylabel("ITI")
    ax.set_title("(a) ITI (bold) and ITI of each actuator", loc="left", fontsize=9)
    ax = axes[1]
    if "oti_submechanism" in dataset:
        for label in dataset["submechanism"].values:
            ax.plot(x, dataset["oti_submechanism"].sel(submechanism=label), **THIN)
    ax.plot(x, dataset["lmti"], **BOLD)
    ax.set_ylabel("LMTI")
    ax.set_title("(b) LMTI (bold) and OTI of each non-redundant submechanism", loc="left", fontsize=9)
    row = 2
    if faults and "oti_submechanism" in dataset:
        ax = axes[row]
        remaining = dataset["remaining1"].values[0]  # the set without the last actuator (combination order)
        members = [label for label in dataset["submechanism"].values if set(label.split("-")) <= set(remaining.split("-"))]
        for label in members:
            ax.plot(x, dataset["oti_submechanism"].sel(submechanism=label), **THIN)
        ax.plot(x, dataset["lmti_remaining1"].sel(remaining1=remaining), **BOLD)
        ax.set_ylabel(f"LMTI {remaining}")
        ax.set_title(f"(c) LMTI of actuators {remaining} (bold) and OTI of its submechanisms", loc="left", fontsize=9)
        row += 1
    for j in faults:
        ax = axes[row]
        key = f"lmti_remaining{j}"
        if key in dataset:
            for label in dataset[f"remaining{j}"].values:
                ax.plot(x, dataset[key].sel({f"remaining{j}": label}), **THIN)
        ax.plot(x, dataset[f"f_o{j}"], **BOLD)
        ax.set_ylabel(f"F_O{j}")
        ax.set_title(f"({chr(ord('a') + row)}) F_O{j} (bold) and LMTI of each set left after {j} fault(s)",
                     loc="left", fontsize=9)
        row += 1
    for ax in axes:
        ax.set_ylim(0, 1.02)
        ax.grid(alpha=0.3)
    unit = dataset[coordinate].attrs.get("units", "")
    axes[-1].set_xlabel(f"{coordinate} ({unit})" if unit else coordinate)
    figure.suptitle(f"{dataset.attrs.get('mechanism', '')}: {dataset.attrs.get('fixed_pose', '')}", fontsize=9)
    return figure


def map_figure(dataset, variables=None, reference=None):
    """Colour maps of the minimum over the orientation set of each index, like Fig. 5.

    Parameters
    ----------
    dataset : xarray.Dataset or screwkit.maps.GridMap
        From :func:`screwkit.maps.index_map`, with two grid coordinates.
    variables : sequence of str, optional
        Default: ``iti``, ``lmti`` and every ``f_o{j}``.
    reference : xarray.Dataset or GridMap, optional
        A second map drawn in a row below (e.g. the paper's design beside an optimised one).
    """
    plt = _pyplot()
    dataset, reference = (d.to_dataset() if hasattr(d, "to_dataset") else d for d in (dataset, reference))
    if variables is None:
        variables = ["iti", "lmti"] + sorted(v for v in dataset.data_vars if v.startswith("f_o"))
    rows = [dataset] + ([reference] if reference is not None else [])
    figure, axes = plt.subplots(len(rows), len(variables), figsize=(3.2 * len(variables), 3.0 * len(rows)),
                                squeeze=False, constrained_layout=True)
    x_name, y_name = list(dataset[variables[0]].dims)[1], list(dataset[variables[0]].dims)[0]
    image = None
    for r, data in enumerate(rows):
        for c, name in enumerate(variables):
            ax = axes[r, c]
            values = data[name].values
            image = ax.pcolormesh(data[x_name].values, data[y_name].values, np.ma.masked_invalid(values),
                                  cmap="jet", vmin=0.0, vmax=1.0, shading="nearest")
            ax.set_aspect("equal")
            ax.set_title(f"{data.attrs.get('label', data.attrs.get('mechanism', ''))}: min {name}", fontsize=9)
            ax.set_xlabel(f"{x_name} (m)")
            ax.set_ylabel(f"{y_name} (m)")
    figure.colorbar(image, ax=axes, shrink=0.8, label="index (minimum over the orientation set)")
    return figure


def save_figure(figure, path) -> None:
    """Save atomically (temporary file, then rename)."""
    path = os.fspath(path)
    root, extension = os.path.splitext(path)
    temporary = f"{root}.tmp-{os.getpid()}{extension}"
    figure.savefig(temporary, dpi=130)
    os.replace(temporary, path)
