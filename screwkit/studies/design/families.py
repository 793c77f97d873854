"""Parametric mechanism families: named parameters with bounds and units, and a writer of the mechanism.

A :class:`Family` is what a design search varies: a tuple of :class:`Parameter` (continuous or
integer, bounds in the parameter's own unit) and a function that writes the mechanism for given
values through the library's URDF writers, so that every candidate is an ordinary file that
every other command opens. A family also states its size measures (footprint, longest link) and
the region its fault-tolerant workspace is measured on by default.

Bundled families (:data:`FAMILIES`, built for a leg count by :func:`family`):

* ``planar_rrr``: planar n-RRR, n >= 4 (the paper's Sec. 4; n = 5 at its defaults is Table 2);
* ``ups_hexapod``: a-UPS hexapod, a >= 7 (a = 8 at its defaults is the bundled ``ups_hexapod_8``);
* ``rss_hexapod``: a-RSS hexapod, a >= 7 (a = 8 at its defaults is the bundled ``rss_hexapod_8``);
* ``delta``: Delta robot, a >= 4 legs (3 DOF; a = 4 at its defaults is the bundled ``delta_4``);
* ``prs_ups``: 3-PRS made redundant by a UPS leg (3 DOF: z, roll, pitch; the bundled ``prs_3_ups``).

A new family is a :class:`Family` built from its parameters and a writer ``values -> URDF text``;
see ``docs/design.md``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

import numpy as np

from screwkit.model.delta_writer import delta_document
from screwkit.model.hexapod_writer import hexapod_points, rss_hexapod_document, slot_angles, ups_hexapod_document
from screwkit.model.pinocchio_bridge import model_from_description
from screwkit.model.prs_writer import prs_document
from screwkit.model.urdf_document import UrdfDocument
from screwkit.model.urdf_writer import planar_rrr_document

__all__ = ["Parameter", "Family", "FAMILIES", "family", "permutation_rank", "permutation_of_rank"]


@dataclass(frozen=True)
class Parameter:
    """One design parameter: ``lower <= value <= upper`` in ``unit``; ``integer`` for choices."""

    name: str
    lower: float
    upper: float
    default: float
    unit: str
    description: str
    integer: bool = False

    def __post_init__(self):
        if not self.lower <= self.default <= self.upper:
            raise ValueError(f"Parameter {self.name!r}: default {self.default} outside [{self.lower}, {self.upper}].")

    def check(self, value: float, source: str = "value") -> float:
        """``value`` as a float, or a ValueError naming the parameter, its bounds and unit."""
        value = float(value)
        if not math.isfinite(value) or not self.lower - 1e-12 <= value <= self.upper + 1e-12:
            raise ValueError(f"Expected {self.name} in [{self.lower:g}, {self.upper:g}] {self.unit}".rstrip()
                             + f", got {value:g} ({source}).")
        if self.integer and value != round(value):
            raise ValueError(f"Expected an integer {self.name}, got {value:g} ({source}).")
        return float(round(value)) if self.integer else value


@dataclass(frozen=True)
class Family:
    """A parametric mechanism family.

    Attributes
    ----------
    name : str
        Family name; a candidate is written as ``{name}_{legs}``.
    legs : int
        Number of legs (fixed for one family; each leg is actuated).
    parameters : tuple of Parameter
    free : tuple of str
        The parameters a search varies unless told otherwise (the others keep their defaults).
    writer : callable
        ``writer(legs, values, name) -> UrdfDocument`` (or a URDF text), values in the parameters' units:
        the bundled families build :class:`~screwkit.model.urdf_document.UrdfDocument` records with the
        library's writers, from which the model is built directly and the file of a kept design written.
    measures : callable
        ``measures(legs, values) -> dict`` of ``footprint`` (m: radius of the circle holding every
        base joint, and crank tip at the home pose) and ``link_length`` (m: the longest link or leg in the reference
        assembly).
    planar : bool
        Planar family (its workspace region is a disc, evaluated with the closed forms).
    region : dict
        The default region of a search (:func:`screwkit.studies.design.objectives.default_region`):
        ``disc`` (radius m, step m, phi step deg) or ``grid`` and ``over`` ((start, stop, step) per
        coordinate, m or deg, as ``screwkit map --grid`` and ``--over`` read them), and ``level``.
    """

    name: str
    legs: int
    parameters: tuple[Parameter, ...]
    free: tuple[str, ...]
    writer: Callable = field(repr=False)
    measures: Callable = field(repr=False)
    planar: bool = False
    description: str = ""
    region: dict = field(default_factory=dict, compare=False)

    def parameter(self, name: str) -> Parameter:
        for parameter in self.parameters:
            if parameter.name == name:
                return parameter
        raise ValueError(f"Unknown parameter {name!r} of family {self.name!r}; it has "
                         f"{', '.join(p.name for p in self.parameters)}.")

    def defaults(self) -> dict[str, float]:
        return {p.name: p.default for p in self.parameters}

    def values(self, values: Mapping[str, float] | None = None) -> dict[str, float]:
        """Every parameter's value: the defaults updated by ``values`` (each checked against its bounds)."""
        out = self.defaults()
        for name, value in (values or {}).items():
            out[name] = self.parameter(name).check(value, f"family {self.name}")
        return out

    def document(self, values: Mapping[str, float] | None = None, name: str | None = None) -> UrdfDocument | str:
        """What the writer makes of the candidate with ``values`` (others at their defaults): a
        :class:`~screwkit.model.urdf_document.UrdfDocument` (the bundled families), or a URDF text."""
        return self.writer(self.legs, self.values(values), name or f"{self.name}_{self.legs}")

    def urdf(self, values: Mapping[str, float] | None = None, name: str | None = None) -> str:
        """The URDF text of the candidate with ``values`` (others at their defaults), for a design that is kept."""
        written = self.document(values, name)
        return written if isinstance(written, str) else written.text()

    def mechanism(self, values: Mapping[str, float] | None = None, name: str | None = None):
        """The loaded :class:`~screwkit.model.Mechanism` of the candidate with ``values``.

        Built from the writer's document directly (its description and the Pinocchio model made from it:
        no text is written or parsed); equal to loading :meth:`urdf` (``tests/test_design_direct.py``).
        A writer that returns a URDF text is loaded from the text."""
        from screwkit.io.loader import load_text, mechanism_from_description  # import on use keeps this light

        written, source = self.document(values, name), f"family {self.name} {self.values(values)}"
        if isinstance(written, str):
            return load_text(written, source=source)
        description = written.description(source)
        return mechanism_from_description(description, model=model_from_description(description))

    def size(self, values: Mapping[str, float] | None = None) -> dict[str, float]:
        """The family's size measures of a candidate (``footprint``, ``link_length``, m)."""
        return self.measures(self.legs, self.values(values))


def permutation_of_rank(count: int, rank: int) -> tuple[int, ...]:
    """The ``rank``-th permutation of ``0..count-1`` in lexicographic order (rank 0: the identity)."""
    items, out, rank = list(range(count)), [], int(rank)
    for position in range(count, 0, -1):
        block = math.factorial(position - 1)
        index, rank = divmod(rank, block)
        out.append(items.pop(index))
    return tuple(out)


def permutation_rank(permutation) -> int:
    """Inverse of :func:`permutation_of_rank`."""
    items, rank = sorted(permutation), 0
    for position, value in enumerate(permutation):
        index = items.index(value)
        rank += index * math.factorial(len(permutation) - 1 - position)
        items.pop(index)
    return rank


def _slots_parameter(legs: int, default: tuple[int, ...]) -> Parameter:
    return Parameter("slots", 0, math.factorial(legs) - 1, permutation_rank(default), "",
                     f"platform slot of each leg: rank of the permutation in lexicographic order "
                     f"(rank {permutation_rank(default)} = {default})", integer=True)


# ---------------------------------------------------------------------------------------------
# planar n-RRR
# ---------------------------------------------------------------------------------------------


def _planar_slots(legs: int) -> tuple[int, ...]:
    """The paper's Table 2 assignment for 5 legs (slot 3 (i - 1) mod n); the identity otherwise."""
    return tuple(3 * i % legs for i in range(legs)) if math.gcd(3, legs) == 1 else tuple(range(legs))


def _planar_points(legs: int, values: Mapping[str, float]):
    angles = 2 * math.pi * np.arange(legs) / legs
    base = values["base_radius"] * np.column_stack([np.cos(angles), np.sin(angles)])
    slots = np.asarray(permutation_of_rank(legs, values["slots"]))
    platform_angles = slots * 2 * math.pi / legs
    platform = values["platform_radius"] * np.column_stack([np.cos(platform_angles), np.sin(platform_angles)])
    return base, platform


def _planar_writer(legs: int, values: Mapping[str, float], name: str) -> UrdfDocument:
    base, platform = _planar_points(legs, values)
    mode = -1.0 if values["mirrored"] else 1.0
    for i in range(legs):  # the reference assembly must exist: the arms reach the platform joint
        reach = float(np.linalg.norm(platform[i] - base[i]))
        if not abs(values["upper"] - values["lower"]) < reach < values["upper"] + values["lower"]:
            raise ValueError(f"Family planar_rrr: leg {i + 1} cannot reach its platform joint at the home pose "
                             f"(distance {reach:.4g} m, arms {values['upper']:g} and {values['lower']:g} m).")
    summary = ", ".join(f"{k} = {v:g}" for k, v in values.items())
    return planar_rrr_document(name, base, platform, values["upper"], values["lower"], mode,
                           comment=f" Planar {legs}-RRR of the family planar_rrr: {summary} ")


def _planar_measures(legs: int, values: Mapping[str, float]) -> dict[str, float]:
    return {"footprint": float(values["base_radius"]), "link_length": float(max(values["upper"], values["lower"]))}


def _region(region: dict, legs: int, dof: int) -> dict:
    """A family's default region; without redundancy (``legs == dof``) F_O1 is zero everywhere, so the region is
    where the LMTI (the OTI of the one submechanism) reaches the level."""
    return region if legs > dof else {**region, "index": "lmti"}


def _check_legs(family: str, legs: int, dof: int) -> None:
    if legs < dof:
        raise ValueError(f"Family {family} needs at least {dof} legs ({dof} DOF), got {legs}.")


def planar_rrr(legs: int = 5) -> Family:
    _check_legs("planar_rrr", legs, 3)
    return Family(
        "planar_rrr", legs,
        (Parameter("base_radius", 0.5, 2.0, 1.0, "m", "radius e of the circle of base joints (the scale)"),
         Parameter("platform_radius", 0.05, 0.4, 0.1, "m", "radius g of the circle of platform joints"),
         Parameter("upper", 0.5, 1.5, 1.0, "m", "length a of every proximal (upper) arm"),
         Parameter("lower", 0.5, 1.5, 1.0, "m", "length l of every distal (lower) arm"),
         _slots_parameter(legs, _planar_slots(legs)),
         Parameter("mirrored", 0, 1, 0, "", "working mode: 0 elbows on the +u_perp side, 1 mirrored", integer=True)),
        ("platform_radius", "upper", "lower"), _planar_writer, _planar_measures, planar=True,
        region=_region({"disc": (0.6, 0.05, 5.0), "level": 0.4}, legs, 3),
        description="planar n-RRR: base joints on a circle at uniform angles, platform joints at uniform slots "
                    "assigned by a permutation, identical arms, base joints actuated")


# ---------------------------------------------------------------------------------------------
# a-UPS and a-RSS hexapods
# ---------------------------------------------------------------------------------------------

UPS_SLOTS = {8: (0, 4, 2, 7, 5, 3, 1, 6)}
RSS_SLOTS = {8: (1, 0, 3, 5, 2, 7, 4, 6)}


def _default_slots(table: dict, legs: int) -> tuple[int, ...]:
    """The bundled assignment, or one drawn with a fixed seed (uniform slots with a constant shift
    would make the leg lines span only 3 dimensions)."""
    return table.get(legs) or tuple(int(s) for s in np.random.default_rng(0).permutation(legs))


def _hexapod_geometry(legs: int, values: Mapping[str, float]):
    return hexapod_points(legs, values["base_radius"], values["platform_radius"],
                          permutation_of_rank(legs, values["slots"]),
                          base_spread=math.radians(values["base_spread"]),
                          platform_spread=math.radians(values["platform_spread"]))


def _hexapod_comment(kind: str, legs: int, values: Mapping[str, float]) -> str:
    summary = ", ".join(f"{k} = {v:g}" for k, v in values.items())
    return (f" {legs}-{kind} hexapod of the family {kind.lower()}_hexapod: {summary} (lengths m, spreads deg); "
            f"platform slots {permutation_of_rank(legs, values['slots'])} ")


def _ups_writer(legs: int, values: Mapping[str, float], name: str) -> UrdfDocument:
    base, platform = _hexapod_geometry(legs, values)
    return ups_hexapod_document(name, base, platform, values["height"], _hexapod_comment("UPS", legs, values))


def _ups_measures(legs: int, values: Mapping[str, float]) -> dict[str, float]:
    base, platform = _hexapod_geometry(legs, values)
    legs_length = np.linalg.norm(platform + [0, 0, values["height"]] - base, axis=-1)
    return {"footprint": float(values["base_radius"]), "link_length": float(np.max(legs_length))}


def _rss_writer(legs: int, values: Mapping[str, float], name: str) -> UrdfDocument:
    base, platform = _hexapod_geometry(legs, values)
    return rss_hexapod_document(name, base, platform, values["height"], values["crank"],
                            _hexapod_comment("RSS", legs, values))


def _rss_measures(legs: int, values: Mapping[str, float]) -> dict[str, float]:
    base, platform = _hexapod_geometry(legs, values)
    radial = base / np.linalg.norm(base, axis=-1, keepdims=True)
    rods = np.linalg.norm(platform + [0, 0, values["height"]] - (base + values["crank"] * radial), axis=-1)
    return {"footprint": float(values["base_radius"] + values["crank"]),
            "link_length": float(max(np.max(rods), values["crank"]))}


def _hexapod_parameters(legs: int, height: float, slots: tuple[int, ...]) -> tuple[Parameter, ...]:
    widest = round(0.8 * 360 / legs, 6)
    return (Parameter("base_radius", 0.5, 1.5, 1.0, "m", "radius of the circle of base joints (the footprint)"),
            Parameter("platform_radius", 0.2, 0.9, 0.5, "m", "radius of the circle of platform joints"),
            Parameter("height", 0.5, 1.5, height, "m", "height of the platform above the base at the home pose"),
            Parameter("base_spread", 0.0, widest, 0.0, "deg",
                      "base slots gathered in pairs: even slots turned by +spread/2, odd ones by -spread/2"),
            Parameter("platform_spread", 0.0, widest, 0.0, "deg", "the same for the platform slots"),
            _slots_parameter(legs, slots))


def ups_hexapod(legs: int = 8) -> Family:
    _check_legs("ups_hexapod", legs, 6)
    return Family("ups_hexapod", legs, _hexapod_parameters(legs, 1.0, _default_slots(UPS_SLOTS, legs)),
                  ("platform_radius", "height", "base_spread", "platform_spread"), _ups_writer, _ups_measures,
                  region=_region({"grid": {"x": (-0.3, 0.3, 0.05), "y": (-0.3, 0.3, 0.05)},
                                  "over": {"yaw": (-30, 40, 10)}, "level": 0.35}, legs, 6),
                  description="a-UPS hexapod: U joints on the base circle, actuated sliders, S joints on the "
                              "platform circle; slots at uniform angles, optionally gathered in pairs")


def rss_hexapod(legs: int = 8) -> Family:
    _check_legs("rss_hexapod", legs, 6)
    parameters = _hexapod_parameters(legs, 0.9, _default_slots(RSS_SLOTS, legs))
    crank = Parameter("crank", 0.2, 0.6, 0.4, "m", "length of every actuated crank (radial at the home pose)")
    return Family("rss_hexapod", legs, parameters[:1] + (crank,) + parameters[1:],
                  ("crank", "platform_radius", "height", "base_spread", "platform_spread"), _rss_writer,
                  _rss_measures,
                  region=_region({"grid": {"x": (-0.1, 0.1, 0.025), "y": (-0.1, 0.1, 0.025)},
                                  "over": {"yaw": (-10, 15, 5)}, "level": 0.3}, legs, 6),
                  description="a-RSS hexapod: actuated cranks with axes tangent to the base circle, rods with "
                              "U and S joints to the platform circle")


# ---------------------------------------------------------------------------------------------
# Delta robots with a legs (3 DOF, translational)
# ---------------------------------------------------------------------------------------------


def _delta_parameters(legs: int, values: Mapping[str, float]) -> dict:
    return {"leg_angles_deg": tuple(np.degrees(slot_angles(legs, math.radians(values["spread"])))),
            "base_radius": values["base_radius"], "platform_radius": values["platform_radius"],
            "arm": values["arm"], "rod": values["rod"], "home": (0.0, 0.0, -values["depth"])}


def _delta_writer(legs: int, values: Mapping[str, float], name: str) -> UrdfDocument:
    summary = ", ".join(f"{k} = {v:g}" for k, v in values.items())
    return delta_document(name, _delta_parameters(legs, values),
                      f" Delta robot with {legs} legs of the family delta (R-U-U forearms): {summary} "
                      "(lengths m, spread deg) ")


def _delta_measures(legs: int, values: Mapping[str, float]) -> dict[str, float]:
    return {"footprint": float(values["base_radius"] + values["arm"]),
            "link_length": float(max(values["arm"], values["rod"]))}


def delta(legs: int = 4) -> Family:
    _check_legs("delta", legs, 3)
    widest = round(0.8 * 360 / legs, 6)
    return Family(
        "delta", legs,
        (Parameter("base_radius", 0.1, 0.4, 0.2, "m", "distance of the actuated axes from the centre"),
         Parameter("platform_radius", 0.02, 0.15, 0.05, "m", "distance of the rod ends from the platform centre"),
         Parameter("arm", 0.2, 0.6, 0.35, "m", "upper arm length"),
         Parameter("rod", 0.5, 1.2, 0.8, "m", "forearm (rod) length"),
         Parameter("depth", 0.4, 1.1, 0.75, "m", "depth of the platform below the base at the home pose"),
         Parameter("spread", 0.0, widest, 0.0, "deg", "legs gathered in pairs: even legs turned by +spread/2, "
                   "odd ones by -spread/2")),
        ("arm", "rod", "depth"), _delta_writer, _delta_measures,
        region=_region({"grid": {"x": (-0.4, 0.4, 0.05), "y": (-0.4, 0.4, 0.05)}, "over": {}, "level": 0.5}, legs, 3),
        description="Delta robot with a legs at uniform angles (optionally in pairs): actuated arms about axes "
                    "tangent to the base circle, parallelogram forearms modelled as R-U-U legs")


# ---------------------------------------------------------------------------------------------
# 3-PRS + UPS (3 DOF: z, roll, pitch)
# ---------------------------------------------------------------------------------------------


def _prs_parameters(values: Mapping[str, float]) -> dict:
    return {"base_radius": values["base_radius"], "platform_radius": values["platform_radius"],
            "link": values["link"], "prs_angles_deg": (90.0, 210.0, 330.0), "ups_angle_deg": values["ups_angle"],
            "ups_base_radius": values["ups_base_radius"], "stroke": (-0.15, 0.15)}


def _prs_writer(legs: int, values: Mapping[str, float], name: str) -> UrdfDocument:
    summary = ", ".join(f"{k} = {v:g}" for k, v in values.items())
    return prs_document(name, _prs_parameters(values), True,
                    f" 3-PRS + UPS of the family prs_ups (chains at 90, 210, 330 deg): {summary} (lengths m, angle "
                    "deg) ", task_coordinates=("z", "roll", "pitch"))


def _prs_measures(legs: int, values: Mapping[str, float]) -> dict[str, float]:
    return {"footprint": float(max(values["base_radius"], values["ups_base_radius"])),
            "link_length": float(values["link"])}


def prs_ups(legs: int = 4) -> Family:
    if legs != 4:
        raise ValueError(f"Family prs_ups has 4 legs (three P-R-S and one U-P-S), got {legs}.")
    return Family(
        "prs_ups", 4,
        (Parameter("base_radius", 0.1, 0.35, 0.2, "m", "distance of the vertical actuated sliders from the axis"),
         Parameter("platform_radius", 0.05, 0.25, 0.13, "m", "distance of the S centres from the platform centre"),
         Parameter("link", 0.12, 0.4, 0.22, "m", "length of the P-R-S links (R to S)"),
         Parameter("ups_base_radius", 0.1, 0.4, 0.26, "m", "distance of the UPS leg's U joint from the axis"),
         Parameter("ups_angle", 0.0, 359.0, 270.0, "deg", "angle of the UPS leg about the axis (the PRS chains sit "
                   "at 90, 210 and 330 deg)")),
        ("platform_radius", "link", "ups_base_radius", "ups_angle"), _prs_writer, _prs_measures,
        region={"grid": {"roll": (-30, 30, 5), "pitch": (-30, 30, 5)}, "over": {}, "level": 0.5},
        description="3-PRS (vertical actuated sliders, tangential R axes, S joints on the platform circle) made "
                    "redundant by a fourth, actuated U-P-S leg; its workspace is a region of orientations")


FAMILIES: dict[str, Callable[[int], Family]] = {"planar_rrr": planar_rrr, "ups_hexapod": ups_hexapod,
                                                 "rss_hexapod": rss_hexapod, "delta": delta, "prs_ups": prs_ups}
"""Bundled families by name: each builds the :class:`Family` for a leg count."""

DEFAULT_LEGS = {"planar_rrr": 5, "ups_hexapod": 8, "rss_hexapod": 8, "delta": 4, "prs_ups": 4}


def family(name: str, legs: int | None = None) -> Family:
    """The bundled family ``name`` with ``legs`` legs (default: 5 planar, 8 hexapod)."""
    if name not in FAMILIES:
        raise ValueError(f"Unknown family {name!r}; the bundled families are {', '.join(FAMILIES)}.")
    return FAMILIES[name](DEFAULT_LEGS[name] if legs is None else int(legs))

