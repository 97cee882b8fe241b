"""Named, cited material parameter sets (docs/model.md section 9).

Each set is a plain dict of SI values beside a ``sources`` dict that says where every
value comes from, tagged as docs/model.md does:

- ``S`` read in a source,
- ``D`` derived,
- ``P`` a proposal,
- ``K`` calibrated.

A config or a caller picks a set by name and may override any field
(:func:`silicone_parameters`, :func:`nylon_parameters`). The returned parameters are
frozen :class:`Silicone` and :class:`Nylon` objects that the physics functions take.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import Any, Mapping

import numpy as np

from .units import short

ZERO_CELSIUS = 273.15  # [K]

__all__ = [
    "NYLON_PARAMETERS",
    "COOLING_PARAMETERS",
    "Cooling",
    "cooling_parameters",
    "SILICONE_PARAMETERS",
    "WALL_STRETCH_RANGE",
    "Nylon",
    "FIELD_UNITS",
    "SHEAR_MODULUS_RANGE",
    "SILICONE_KINDS",
    "Silicone",
    "NYLON_POSITIVE",
    "NYLON_RANGES",
    "NYLON_TABLES",
    "SILICONE_RANGES",
    "check_nylon",
    "check_shear_modulus",
    "check_silicone",
    "silicone_kind",
    "nylon_parameters",
    "silicone_parameters",
]

#: Stretch range [-] the actuators' walls reach, the window a silicone fit is made over by
#: default (``nylonflex fit silicone``). D: the paper's two worked examples stretch the top
#: fibre of the wall to about 1.2 (a = 20 mm) and 1.6 (a = 7.5 mm) at full stroke
#: (docs/model.md s. 5); 2 leaves a margin above the stiffer of them.
WALL_STRETCH_RANGE = (1.0, 2.0)

#: Ogden sets in the paper's convention (eq. 5): W = sum mu_i/alpha_i (l1^a + l2^a + l3^a - 3).
#: ``mu`` [Pa], ``alpha`` [-].
SILICONE_PARAMETERS: dict[str, dict[str, Any]] = {
    "tc5005": {
        "mu": (56.19e3, 10.49e3),
        "alpha": (0.2975, 2.770),
        "description": "BJB TC-5005 (the paper's silicone), stand-in fit",
        "kind": "shore_00",
        "stretch_range": (1.0, 4.0),
        "sources": {
            "stretch_range": "D: the fit's data window, stretch <= 4",
            "mu": "D/P: no TC-5005 data is published; Ogden N=2 fit (stretch <= 4) to the raw "
            "tensile data of Ecoflex 00-50, the nearest hardness class, Marechal et al., "
            "Soft Robotics 2021 (Soft-Robotics-Materials-Database)",
            "alpha": "D/P: same fit",
        },
    },
    "ecoflex_00_30": {
        "mu": (16.11e3, -0.3231e3),
        "alpha": (1.977, -8.149),
        "description": "Smooth-On Ecoflex 00-30",
        "kind": "shore_00",
        "stretch_range": (1.0, 4.0),
        "sources": {
            "stretch_range": "P: the fit's window is not recorded; taken as tc5005's "
            "stretch <= 4",
            "mu": "D: Ogden N=2 fit to Marechal et al., Soft Robotics 2021 database",
            "alpha": "D: same fit",
        },
    },
    "dragon_skin_10": {
        "mu": (30.30e3, -1.620e3),
        "alpha": (2.970, -6.266),
        "description": "Smooth-On Dragon Skin 10",
        "kind": "shore_a",
        "stretch_range": (1.0, 4.0),
        "sources": {
            "stretch_range": "P: the fit's window is not recorded; taken as tc5005's "
            "stretch <= 4",
            "mu": "D: Ogden N=2 fit to Marechal et al., Soft Robotics 2021 database",
            "alpha": "D: same fit",
        },
    },
    "elastosil_m4601": {
        "mu": (220e3, 0.0),
        "alpha": (2.0, 1.0),
        "description": "Wacker Elastosil M4601 (neo-Hookean)",
        "kind": "shore_a",
        "stretch_range": (1.0, 2.0),
        "sources": {
            "stretch_range": "P: a small-strain neo-Hookean equivalent of a Yeoh fit; trusted "
            "to stretch 2 only",
            "mu": "D: neo-Hookean equal to Yeoh C1 = 0.11 MPa, Polygerinos et al., "
            "IEEE T-RO 31(3):778, 2015",
            "alpha": "D: neo-Hookean (alpha = 2)",
        },
    },
}

#: Self-coiled silver-coated nylon 6,6 thread, SI units (temperatures in K). ``alpha`` keeps
#: the paper's eq. (2) convention of a temperature in degC; it cancels from the stroke.
NYLON_PARAMETERS: dict[str, dict[str, Any]] = {
    "silver_nylon66": {
        "fibre_diameter": 0.34e-3,
        "stroke_reference": 0.10,
        "alpha": -0.04341,
        "gamma": 1.951e-4,
        "beta": 0.04944,
        "t_g": 118.6 + ZERO_CELSIUS,
        "sigma_g": 41.3,
        "t_amb": 25.0 + ZERO_CELSIUS,
        "t_max": 150.0 + ZERO_CELSIUS,
        "resistance_per_length": 150.0,
        "heat_capacity_per_length": 0.45,
        "heat_loss_per_length": 0.03,
        "stiffness": 16.0,
        "damping": 0.1,
        "thermal_force_coefficient": 2e-3,
        "coil_index_table": (1.1, 1.3, 1.5, 1.7),
        "stroke_max_table": (0.054, 0.068, 0.083, 0.097),
        "tensile_strength_table": (100e6, 85e6, 73e6, 65e6),
        "resistance_coil_index": 1.7,
        "description": "silver-coated nylon 6,6 sewing thread, self-coiled",
        "sources": {
            "fibre_diameter": "S: Sun et al., Soft Robotics 2021 (Shieldex 4-ply after twisting)",
            "stroke_reference": "P: 10 % for self-coiled conductive thread (Yip & Niemeyer "
            "2015; Haines et al. 2014, movie S4)",
            "alpha": "D: fit of the eq. (2) form to coiled-nylon stroke data (Kianzad et al., "
            "SPIE 2015), scaled to stroke_reference",
            "gamma": "D: same fit",
            "beta": "D: same fit",
            "t_g": "D: same fit; an effective activation centre, not the DSC glass transition",
            "sigma_g": "D: same fit",
            "t_amb": "P: room temperature",
            "t_max": "P: below the 160-200 degC annealing temperature",
            "resistance_per_length": "S: the paper, 0.15 ohm/mm, which its 12 V, 160 mA supply "
            "of the 0.503 m muscle of its second example (C = 1.7) confirms (75 ohm)",
            "resistance_coil_index": "D: the coil index of the paper's driven actuator (its "
            "second example); at another C, r' scales with the thread per length of a "
            "close-wound coil, sqrt((pi C)^2 + 1) (docs/model.md s. 9)",
            "heat_capacity_per_length": "D: rho = 1300 kg/m3, c_p = 1267 J/(kg K) (Sun et al., "
            "IROS 2018) for a coiled 4-ply thread",
            "heat_loss_per_length": "K: back-calculated from the paper's operating point, its "
            "12 V supply (160 mA, 1.92 W) on the 0.503 m muscle of its second example held "
            "near t_max: 1.92 W / (0.503 m x 125 K) = 0.0305 (151.5 degC at 0.03); "
            "free convection in still air gives 3.1 times more (set silver_nylon66_still_air, "
            "docs/model.md s. 9)",
            "stiffness": "P: order of magnitude for a 60 mm self-coiled thread",
            "damping": "P: same",
            "thermal_force_coefficient": "P: same",
            "stroke_max_table": "K: calibrated on the paper's two worked examples (section 4), "
            "linear in coil index between 1.1 and 1.7",
            "tensile_strength_table": "P: about 100 MPa at C = 1.1 (1 kg on a 0.34 mm thread, "
            "Cho et al. via Sun et al. 2021), falling as 1/C",
            "coil_index_table": "P: the coil indices the paper discusses (1.1-1.7), docs/model.md "
            "section 9",
        },
    },
}

#: The same muscle in still air, its heat loss from first principles (docs/model.md s. 9).
NYLON_PARAMETERS["silver_nylon66_still_air"] = {
    **NYLON_PARAMETERS["silver_nylon66"],
    "heat_loss_per_length": 0.0924,
    "description": "silver-coated nylon 6,6 sewing thread, self-coiled, in still air",
    "sources": {
        **NYLON_PARAMETERS["silver_nylon66"]["sources"],
        "heat_loss_per_length": "D: free convection from a horizontal cylinder in still air "
        "(Churchill & Chu, Int. J. Heat Mass Transfer 18:1049, 1975) of the muscle's outer "
        "diameter d_f (C + 1) at C = 1.4 (0.816 mm), T_s = t_max, T_amb = t_amb, air at the "
        "film temperature (Incropera Table A.4): Nu_D = 0.955, lambda' = pi k Nu_D; "
        "0.0879-0.0968 over C = 1.1-1.7; radiation left out (silver surface)",
    },
}

#: Cooling environments of the muscle (docs/model.md s. 9): the fluid around it and its
#: speed across it [m/s] (0: free convection). The heat loss per length lambda' is computed
#: from the cited correlation at the muscle's outer diameter d_f (C + 1), linearised at the
#: operating point T_s = t_max (``physics/thermal.py::convection_loss_per_length``). A
#: config picks one by name (``cooling: still_air``) or overrides the speed
#: (``cooling: {set: forced_air, speed: 5}``); without ``cooling:`` the nylon set's own
#: ``heat_loss_per_length`` holds.
COOLING_PARAMETERS: dict[str, dict[str, Any]] = {
    "still_air": {
        "fluid": "air", "speed": 0.0,
        "description": "still air at 1 atm, free convection",
        "sources": {"speed": "D: free convection from a horizontal cylinder, Churchill & Chu, "
                    "Int. J. Heat Mass Transfer 18:1049-1053, 1975; air, Incropera et al. "
                    "6th ed. Table A.4"},
    },
    "forced_air": {
        "fluid": "air", "speed": 2.0,
        "description": "air at 1 atm blown across the muscle at 2 m/s (a desk fan)",
        "sources": {"speed": "P: 2 m/s, a desk fan; D: cross flow over a cylinder, Churchill & "
                    "Bernstein, J. Heat Transfer 99:300-306, 1977; air, Incropera Table A.4"},
    },
    "still_water": {
        "fluid": "water", "speed": 0.0,
        "description": "still water, free convection (the surface must stay below boiling)",
        "sources": {"speed": "D: Churchill & Chu 1975 as for still air; saturated water, "
                    "Incropera et al. 6th ed. Table A.6"},
    },
}


@dataclass(frozen=True)
class Cooling:
    """A cooling environment (docs/model.md s. 9).

    Attributes
    ----------
    fluid : str
        ``"air"`` or ``"water"`` (the property tables of ``physics/thermal.py``).
    speed : float
        Speed of the fluid across the muscle [m/s], >= 0; 0 is free convection.
    """

    fluid: str
    speed: float
    name: str = "custom"
    description: str = ""
    sources: Mapping[str, str] = field(default_factory=dict, compare=False)

    def to_dict(self) -> dict:
        """The set's name, fluid and speed (for YAML provenance and the config hash)."""
        return {"name": self.name, "fluid": self.fluid, "speed": self.speed}

    @property
    def label(self) -> str:
        """The set's name, with its speed where that is not the named set's own
        (``"forced_air 5 m/s"``): the coordinate of a cube of several cooling sets."""
        own = COOLING_PARAMETERS.get(self.name, {}).get("speed")
        if own is not None and float(own) == self.speed:
            return self.name
        return f"{self.name} {self.speed:g} m/s"


def cooling_parameters(cooling) -> Cooling:
    """The named cooling environment, or ``{"set": name, "speed": m/s}`` (speed overridden).

    Raises
    ------
    ValueError
        Unknown set or field, or a speed outside [0, 100] m/s.
    """
    if isinstance(cooling, Cooling):
        return cooling
    over, field = {}, "cooling"
    if isinstance(cooling, Mapping):
        over = {k: v for k, v in cooling.items() if k != "set"}
        cooling, field = cooling.get("set"), "cooling.set"
    if not isinstance(cooling, str) or cooling not in COOLING_PARAMETERS:
        raise ValueError(f"{field}: must be one of {', '.join(COOLING_PARAMETERS)}, "
                         f"got {short(cooling)}")
    p = {**COOLING_PARAMETERS[cooling]}
    for key, value in over.items():
        if key != "speed":
            raise ValueError(f"cooling.{key}: unknown field; a cooling set takes set and speed")
        if isinstance(value, bool) or not isinstance(value, (int, float)) or \
                not (np.isfinite(value) and 0.0 <= value <= 100.0):
            raise ValueError(f"cooling.speed: must be a number in [0, 100] m/s, got "
                             f"{short(value)}")
        p["speed"] = float(value)
    return Cooling(p["fluid"], float(p["speed"]), name=cooling,
                   description=p.get("description", ""), sources=dict(p.get("sources", {})))


#: Unit of every field of a material set, as the code (and a config override) takes it.
FIELD_UNITS = {
    "mu": "Pa", "alpha": "1",
    "fibre_diameter": "m", "stroke_reference": "1", "gamma": "1/K", "beta": "1",
    "t_g": "K", "sigma_g": "K", "t_amb": "K", "t_max": "K",
    "resistance_per_length": "ohm/m", "heat_capacity_per_length": "J/(K m)",
    "heat_loss_per_length": "W/(K m)", "stiffness": "N/m", "damping": "N s/m",
    "thermal_force_coefficient": "N/K", "coil_index_table": "1", "stroke_max_table": "1",
    "tensile_strength_table": "Pa", "resistance_coil_index": "1",
    "speed": "m/s",
}


#: Plausible initial shear modulus mu_0 = 1/2 sum mu_i alpha_i [Pa] of each kind of silicone,
#: stated here once: every named set has a ``kind``, the messages quote these ranges, and the
#: README and docs/model.md print this table (tests/test_materials.py checks they agree).
#: ``shore_00`` and ``shore_a`` each span a factor of 100, so a named set's stiffness typed
#: 100 times too small or too large (kPa typed as Pa is 1000 times) always falls outside
#: its kind's range. ``any`` is for a set of no stated kind (a fitted file, a custom set).
SILICONE_KINDS = {
    "shore_00": {"range": (2e3, 200e3), "description":
                 "soft platinum silicones, Shore 00-10 to 00-50 (Ecoflex; tc5005's stand-in)"},
    "shore_a": {"range": (20e3, 2e6), "description":
                "Shore A silicones, about A 5 to A 45 (Dragon Skin 10, Elastosil M4601, "
                "Sylgard 184)"},
    "any": {"range": (100.0, 100e6), "description":
            "a silicone of no stated kind: the softest gels to stiff rubbers"},
}
#: The widest plausible range [Pa] (kind ``any``).
SHEAR_MODULUS_RANGE = SILICONE_KINDS["any"]["range"]


def silicone_kind(silicone) -> str:
    """The kind (a key of :data:`SILICONE_KINDS`) of a silicone argument: a mapping's own
    ``kind``, else its named set's, else ``"any"``."""
    if isinstance(silicone, Mapping):
        if "kind" in silicone:
            return _kind_name(silicone["kind"])
        silicone = silicone.get("set")
    if isinstance(silicone, str) and silicone in SILICONE_PARAMETERS:
        return SILICONE_PARAMETERS[silicone].get("kind", "any")
    return "any"


def _kind_name(kind) -> str:
    if not isinstance(kind, str) or kind not in SILICONE_KINDS:
        raise ValueError(f"silicone.kind: must be one of {', '.join(SILICONE_KINDS)}, "
                         f"got {short(kind)}")
    return kind


def shear_modulus_range_text(kind) -> str:
    """``"[2 kPa, 200 kPa]"``: a kind's plausible mu_0 range as the docs print it."""
    def k(x):
        for factor, unit in ((1e6, "MPa"), (1e3, "kPa")):
            if x >= factor:
                return f"{x / factor:g} {unit}"
        return f"{x:g} Pa"
    lo, hi = SILICONE_KINDS[kind]["range"]
    return f"[{k(lo)}, {k(hi)}]"


def _slip(got, own, name) -> str:
    """What a mu_0 of ``got`` [Pa] against its set's ``own`` [Pa] most likely is."""
    p = int(np.round(np.log10(got / own)))
    if p == 0:
        return ""
    times = f"{10.0 ** abs(p):g} times {'below' if p < 0 else 'above'} {name}'s own " \
            f"{own:g} Pa"
    hint = {-3: "the mu values look like kPa typed as Pa: the code takes Pa",
            -6: "the mu values look like MPa typed as Pa: the code takes Pa",
            3: "a value in Pa converted from kPa once more?",
            -2: "a misplaced decimal point?", 2: "a misplaced decimal point?"}.get(p, "")
    return f"; it is {times}" + (f" ({hint})" if hint else "")


def check_shear_modulus(mu0, field="silicone.mu", kind="any", name=None):
    """Refuse an initial shear modulus no silicone of its kind has, naming the likely slip.

    Parameters
    ----------
    mu0 : float or array
        Initial shear modulus 1/2 sum mu_i alpha_i [Pa].
    field : str
        The parameter to name in the message.
    kind : str
        A key of :data:`SILICONE_KINDS`: the accepted range [Pa].
    name : str, optional
        The named set the values override (the message compares with its own mu_0).

    Raises
    ------
    ValueError
        One line: the field, the accepted range [Pa], the value and the likely slip.
    """
    arr = np.asarray(mu0, dtype=float)
    lo, hi = SILICONE_KINDS[_kind_name(kind)]["range"]
    bad = ~(arr > 0)
    if np.any(bad):
        raise ValueError(f"{field}: initial shear modulus 1/2 sum mu_i alpha_i = "
                         f"{arr[bad].flat[0]:g} Pa; must be > 0")
    bad = (arr < lo) | (arr > hi)
    if np.any(bad):
        got = float(arr[bad].flat[0])
        of = "a silicone" if kind == "any" else f"a {kind} silicone"
        msg = (f"{field}: initial shear modulus 1/2 sum mu_i alpha_i = {got:g} Pa is "
               f"implausible for {of}; must be in [{lo:g}, {hi:g}] Pa")
        if name in SILICONE_PARAMETERS:
            own = SILICONE_PARAMETERS[name]
            msg += _slip(got, 0.5 * sum(m * a for m, a in zip(own["mu"], own["alpha"])),
                         name)
            if kind != "any":
                msg += (f"; for a silicone of another kind give silicone.kind, one of "
                        f"{', '.join(SILICONE_KINDS)}")
        else:
            for factor, unit in ((1e3, "kPa"), (1e6, "MPa")):
                if got < lo and lo <= got * factor <= hi:
                    msg += (f"; the mu values look like {unit}: the code takes Pa "
                            f"(mu_0 would be {got * factor:g} Pa)")
                    break
        raise ValueError(msg)


@dataclass(frozen=True)
class Silicone:
    """Incompressible Ogden silicone, paper's eq. (5) convention.

    Attributes
    ----------
    mu : tuple of float
        Ogden moduli mu_i [Pa].
    alpha : tuple of float
        Ogden exponents alpha_i [-].
    name : str
        Name of the set it came from (with overrides, ``"<set>+override"``).
    """

    mu: tuple[float, ...]
    alpha: tuple[float, ...]
    name: str = "custom"
    description: str = ""
    sources: Mapping[str, str] = field(default_factory=dict, compare=False)
    stretch_range: tuple[float, float] = (0.0, float("inf"))

    @property
    def initial_shear_modulus(self) -> float:
        """Initial shear modulus mu_0 = 1/2 sum mu_i alpha_i [Pa]."""
        return 0.5 * sum(m * a for m, a in zip(self.mu, self.alpha))

    def arrays(self) -> tuple[np.ndarray, np.ndarray]:
        """``(mu, alpha)`` as float64 arrays, the form the formula functions take."""
        return np.asarray(self.mu, dtype=float), np.asarray(self.alpha, dtype=float)

    def to_dict(self) -> dict:
        """The set's name and values, lists for tuples (for YAML provenance)."""
        return _values(self)


@dataclass(frozen=True)
class Nylon:
    """Coiled nylon muscle parameters (docs/model.md section 9), SI except the eq. (2) shape.

    Attributes
    ----------
    fibre_diameter : float
        Diameter of the (twisted) fibre d_f [m].
    stroke_reference : float
        Nominal free stroke of the reference shape at ``t_max`` [-].
    alpha, gamma, beta : float
        Reference eq. (2) constants [-], [1/K], [-] (``alpha`` for a temperature in degC).
    t_g, sigma_g : float
        Effective activation centre [K] and width [K] of eq. (2).
    t_amb, t_max : float
        Ambient and highest safe temperature [K].
    resistance_per_length : float
        Electrical resistance per muscle length r' [ohm/m].
    heat_capacity_per_length : float
        Heat capacity per muscle length c' [J/(K m)].
    heat_loss_per_length : float
        Heat loss coefficient per muscle length lambda' [W/(K m)].
    stiffness, damping, thermal_force_coefficient : float
        Eq. (1) constants k [N/m], b_d [N s/m], c [N/K].
    coil_index_table, stroke_max_table, tensile_strength_table : tuple of float
        Coil index C [-], its maximum stroke s_max [-] and tensile strength sigma_u [Pa].
    resistance_coil_index : float
        Coil index C_r [-] at which ``resistance_per_length`` holds; at another C, r' scales
        by sqrt((pi C)^2 + 1) / sqrt((pi C_r)^2 + 1) (docs/model.md s. 9). 0: r' is the
        same at every coil index.
    """

    fibre_diameter: float
    stroke_reference: float
    alpha: float
    gamma: float
    beta: float
    t_g: float
    sigma_g: float
    t_amb: float
    t_max: float
    resistance_per_length: float
    heat_capacity_per_length: float
    heat_loss_per_length: float
    stiffness: float
    damping: float
    thermal_force_coefficient: float
    coil_index_table: tuple[float, ...]
    stroke_max_table: tuple[float, ...]
    tensile_strength_table: tuple[float, ...]
    resistance_coil_index: float = 0.0
    name: str = "custom"
    description: str = ""
    sources: Mapping[str, str] = field(default_factory=dict, compare=False)

    @property
    def fibre_area(self) -> float:
        """Fibre cross-section A_f = pi d_f^2 / 4 [m^2]."""
        return np.pi * self.fibre_diameter**2 / 4.0

    @property
    def coil_index_range(self) -> tuple[float, float]:
        """Smallest and largest coil index of the table [-]."""
        return self.coil_index_table[0], self.coil_index_table[-1]

    def to_dict(self) -> dict:
        """The set's name and values, lists for tuples (for YAML provenance)."""
        return _values(self)


def _values(material) -> dict:
    # stretch_range is the fit's provenance, like its sources: not part of the config hash;
    # resistance_coil_index 0 (r' the same at every C, as before issue 30) is left out so
    # that such a set hashes as it did
    return {f.name: (list(v) if isinstance(v, tuple) else v)
            for f in fields(material) if f.name not in ("description", "sources",
                                                        "stretch_range")
            for v in (getattr(material, f.name),)
            if not (f.name == "resistance_coil_index" and v == 0.0)}


def _resolve(kind, table, value, overrides):
    if isinstance(value, (Silicone, Nylon)):
        if overrides:
            raise ValueError(f"{kind}: overrides need a set name, not an object")
        return value
    if isinstance(value, Mapping):
        value = dict(value)
        if "file" in value:  # a fitted material file (nylonflex.calibration), as a set
            from .files.material_files import read_material_set

            if "set" in value:
                raise ValueError(f"{kind}: give 'file' or 'set', not both")
            known = {f.name for f in fields(Nylon)} - {"name", "description", "sources"}
            value["set"], params = read_material_set(kind, value.pop("file"), table, known)
            table = {**table, value["set"]: params}
        overrides = {**{k: v for k, v in value.items() if k != "set"}, **(overrides or {})}
        value = value.get("set")
        if value is None:
            raise ValueError(f"{kind}: a mapping needs 'set', one of {sorted(table)}")
    if not isinstance(value, str) or value not in table:
        raise ValueError(f"{kind}: unknown set {value!r}; accepted: {', '.join(sorted(table))}")
    params = dict(table[value])
    name = value
    if overrides:
        cls = Silicone if kind == "silicone" else Nylon
        known = {f.name for f in fields(cls)} - {"name", "description", "sources"}
        if kind == "silicone":
            known |= {"kind"}  # the plausible stiffness range (SILICONE_KINDS)
        for key in overrides:
            if key not in known:
                raise ValueError(
                    f"{kind}.{key}: unknown field; accepted: {', '.join(sorted(known))}"
                )
        params.update(overrides)
        name = f"{value}+override"
    return name, params


def _terms(key, value) -> tuple[float, ...]:
    """A list of 1 to 6 Ogden constants as floats (bounded: never a huge array)."""
    if isinstance(value, (list, tuple)) and not 1 <= len(value) <= 6 or \
            isinstance(value, np.ndarray) and not 1 <= value.size <= 6:
        raise ValueError("silicone.mu/alpha: need the same number (1 to 6) of terms")
    items = value if isinstance(value, (list, tuple, np.ndarray)) else [value]
    if any(isinstance(x, bool) for x in items):
        raise ValueError(f"silicone.{key}: must be numbers, got a boolean")
    if not all(isinstance(x, (int, float, np.number)) or
               isinstance(x, str) and len(x) < 64 for x in items):
        raise ValueError("silicone.mu/alpha: must be lists of numbers [Pa] and [-]")
    try:
        out = tuple(float(x) for x in items)
    except (TypeError, ValueError):
        raise ValueError("silicone.mu/alpha: must be lists of numbers [Pa] and [-]") from None
    if not 1 <= len(out) <= 6:
        raise ValueError("silicone.mu/alpha: need the same number (1 to 6) of terms")
    return out


def silicone_parameters(silicone="tc5005", **overrides) -> Silicone:
    """The named Ogden set, with fields overridden.

    Parameters
    ----------
    silicone : str, dict or Silicone
        A name of :data:`SILICONE_PARAMETERS`, a mapping ``{"set": name, field: value}``
        or a ready :class:`Silicone` (returned as is).
    **overrides
        Fields to replace: ``mu`` [Pa], ``alpha`` [-]; ``kind`` (a key of
        :data:`SILICONE_KINDS`) sets the plausible range of the initial shear modulus.

    Raises
    ------
    ValueError
        Unknown set or field, or Ogden constants that are not a valid material.
    """
    resolved = _resolve("silicone", SILICONE_PARAMETERS, silicone, overrides)
    if isinstance(resolved, Silicone):
        return resolved
    name, p = resolved
    mu, alpha = _terms("mu", p["mu"]), _terms("alpha", p["alpha"])
    base = silicone.get("set") if isinstance(silicone, Mapping) else silicone
    check_silicone(mu, alpha, kind=_kind_name(p.get("kind", "any")),
                   name=base if isinstance(base, str) else None)
    stretch_range = p.get("stretch_range", (0.0, float("inf")))
    try:
        lo, hi = (float(x) for x in stretch_range)
    except (TypeError, ValueError):
        raise ValueError("silicone.stretch_range: must be two stretches [lo, hi], got "
                         f"{stretch_range!r}") from None
    if not 0.0 <= lo < hi:
        raise ValueError(f"silicone.stretch_range: must be 0 <= lo < hi, got [{lo:g}, {hi:g}]")
    return Silicone(
        mu=mu,
        alpha=alpha,
        name=name,
        description=p.get("description", ""),
        sources=dict(p.get("sources", {})),
        stretch_range=(lo, hi),
    )


#: Physically plausible range of every nylon field, SI (lo, hi, unit for messages); a value
#: outside it (or not finite) is refused: tiny or huge values make the model's arithmetic
#: overflow or give NaN (a 1e-300 m fibre, a 1 Pa strength).
NYLON_RANGES = {
    "fibre_diameter": (1e-6, 0.01, "m"),
    "stroke_reference": (1e-4, 0.9, ""),
    "alpha": (-100.0, 100.0, ""),
    "gamma": (-1.0, 1.0, "1/K"),
    "beta": (-100.0, 100.0, ""),
    "t_g": (150.0, 700.0, "K"),
    "sigma_g": (0.01, 500.0, "K"),
    "t_amb": (150.0, 500.0, "K"),
    "t_max": (150.0, 800.0, "K"),
    "resistance_per_length": (1e-6, 1e9, "ohm/m"),
    "heat_capacity_per_length": (1e-9, 1e6, "J/(K m)"),
    "heat_loss_per_length": (1e-9, 1e6, "W/(K m)"),
    "stiffness": (1e-6, 1e9, "N/m"),
    "damping": (0.0, 1e9, "N s/m"),
    "thermal_force_coefficient": (-1e6, 1e6, "N/K"),
    "coil_index_table": (1.0, 50.0, ""),
    "stroke_max_table": (1e-4, 0.9, ""),
    "tensile_strength_table": (1e6, 1e10, "Pa"),
    "resistance_coil_index": (0.0, 50.0, ""),
}
#: Accepted Ogden constants: each |mu_i| [Pa], each |alpha_i| [-] (non-zero), and the
#: initial shear modulus 1/2 sum mu_i alpha_i [Pa].
SILICONE_RANGES = {"mu": 1e9, "alpha": 50.0, "mu0": SHEAR_MODULUS_RANGE}


#: Nylon fields that must be strictly positive (a zero fibre or heat capacity divides).
NYLON_POSITIVE = ("fibre_diameter", "stroke_reference", "sigma_g", "resistance_per_length",
                  "heat_capacity_per_length", "heat_loss_per_length")
#: The nylon set's per-coil-index tables (one row a coil index; columns last in an array).
NYLON_TABLES = ("coil_index_table", "stroke_max_table", "tensile_strength_table")


def _first(values, bad) -> str:
    return f"{np.asarray(values)[np.broadcast_to(bad, np.shape(values))].flat[0]:g}"


def check_nylon(values) -> None:
    """The one validator of a nylon set's numbers: scalars, or arrays of one value a design
    (a named set is the one-row case); each table's entries on its last axis.

    ``values`` maps every numeric field of :class:`Nylon` (SI) to a number or an array.
    The rules: :data:`NYLON_POSITIVE` > 0, every field inside :data:`NYLON_RANGES` (and
    finite), t_max above t_amb, the coil-index table increasing with one s_max in (0, 1) and
    one strength > 0 a row.

    Raises
    ------
    ValueError
        The first rule broken, one line naming the field and its accepted range.
    """
    v = {k: np.asarray(values[k], dtype=float) for k in (*NYLON_RANGES, "t_max", "t_amb")
         if k in values}
    for key in NYLON_POSITIVE:
        bad = ~(v[key] > 0)  # NaN is not > 0
        if np.any(bad):
            raise ValueError(f"nylon.{key}: must be > 0, got {_first(v[key], bad)}")
    for key, (lo, hi, unit) in NYLON_RANGES.items():
        bad = ~((v[key] >= lo) & (v[key] <= hi))
        if np.any(bad):
            raise ValueError(f"nylon.{key}: must be finite and in [{lo:g}, {hi:g}]"
                             f"{' ' + unit if unit else ''}, got {_first(v[key], bad)}")
    if np.any(~(v["t_max"] > v["t_amb"])):
        raise ValueError("nylon.t_max: must be above nylon.t_amb")
    c, smax, su = (np.atleast_1d(v[k]) for k in NYLON_TABLES)
    if not (c.shape[-1] == smax.shape[-1] == su.shape[-1] >= 1) or \
            np.any(np.diff(c, axis=-1) <= 0):
        raise ValueError("nylon.coil_index_table: must increase, one s_max and sigma_u a row")
    if np.any((smax <= 0) | (smax >= 1)):
        raise ValueError("nylon.stroke_max_table: each s_max must be in (0, 1)")
    if np.any(~(su > 0)):
        raise ValueError("nylon.tensile_strength_table: each sigma_u must be > 0 Pa")


def check_silicone(mu, alpha, kind="any", name=None) -> None:
    """The one validator of Ogden constants: ``mu`` [Pa] and ``alpha`` [-] of shape
    (..., terms) (a named set: one row), the same 1 to 6 terms, each term inside
    :data:`SILICONE_RANGES` (alpha non-zero), and the initial shear modulus of each row in
    its kind's range (:func:`check_shear_modulus`).

    Raises
    ------
    ValueError
        One line naming the field and its accepted range.
    """
    mu, alpha = np.asarray(mu, dtype=float), np.asarray(alpha, dtype=float)
    if mu.ndim == 0 or alpha.ndim == 0 or mu.shape[-1] != alpha.shape[-1] or \
            not 1 <= mu.shape[-1] <= 6:
        raise ValueError("silicone.mu/alpha: need the same number (1 to 6) of terms")
    if not np.all(np.abs(mu) <= SILICONE_RANGES["mu"]):  # NaN fails
        raise ValueError(f"silicone.mu: each term must be finite and in "
                         f"[-{SILICONE_RANGES['mu']:g}, {SILICONE_RANGES['mu']:g}] Pa")
    if not np.all((np.abs(alpha) > 0) & (np.abs(alpha) <= SILICONE_RANGES["alpha"])):
        raise ValueError(f"silicone.alpha: each term must be finite, non-zero and in "
                         f"[-{SILICONE_RANGES['alpha']:g}, {SILICONE_RANGES['alpha']:g}]")
    check_shear_modulus(0.5 * np.sum(mu * alpha, axis=-1), kind=kind, name=name)


def nylon_parameters(nylon="silver_nylon66", **overrides) -> Nylon:
    """The named nylon muscle set, with fields overridden.

    Parameters
    ----------
    nylon : str, dict or Nylon
        A name of :data:`NYLON_PARAMETERS`, a mapping ``{"set": name, field: value}`` or a
        ready :class:`Nylon`.
    **overrides
        Fields of :class:`Nylon` to replace, SI.

    Raises
    ------
    ValueError
        Unknown set or field, or a value outside its physical range.
    """
    resolved = _resolve("nylon", NYLON_PARAMETERS, nylon, overrides)
    if isinstance(resolved, Nylon):
        return resolved
    name, p = resolved
    kwargs = {}
    for f in fields(Nylon):
        if f.name in ("name", "description", "sources"):
            continue
        v = p.get(f.name, f.default) if f.name == "resistance_coil_index" else p[f.name]
        try:
            if f.name.endswith("_table"):
                kwargs[f.name] = tuple(float(x) for x in v)
            else:
                kwargs[f.name] = float(v)
        except (TypeError, ValueError):
            raise ValueError(f"nylon.{f.name}: must be a number, got {short(v)}") from None
        if isinstance(v, bool) or (f.name.endswith("_table") and
                                   any(isinstance(x, bool) for x in v)):
            raise ValueError(f"nylon.{f.name}: must be a number, got {str(v).lower()}")
    check_nylon(kwargs)
    return Nylon(name=name, description=p.get("description", ""),
                 sources=dict(p.get("sources", {})), **kwargs)
