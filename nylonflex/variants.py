"""The model variants (``model:``) described for a designer: what each adds, where it is
measured to hold, and when to use it. ``nylonflex list models`` prints this table; the
physics is docs/model.md s. 16 and 21, the measurements docs/fidelity.md.

One record per name of :data:`nylonflex.variables.MODELS` (tests/test_list.py checks that
every variant has one): a new variant adds its record here, beside its name there.

This module is the bottom layer with :mod:`nylonflex.variables`: it imports nothing else.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

from .variables import MODELS

__all__ = ["MEASURED_SPACE", "VARIANTS", "Variant", "describe"]


@dataclass(frozen=True)
class Variant:
    """A model variant for a designer.

    Attributes
    ----------
    name : str
        The ``model:`` name (:data:`nylonflex.variables.MODELS`).
    short : str
        A few words, for a table's legend (``nylonflex fe``).
    adds : str
        What it changes against ``paper``, in a sentence.
    holds : str
        Where it is measured to hold: its bend angle over the FE twin's (docs/fidelity.md),
        or "not measured" and why.
    use : str
        The recommendation: when to choose it.
    section : str
        Where docs/model.md derives it.
    """

    name: str
    short: str
    adds: str
    holds: str
    use: str
    section: str


#: The space the FE twin measured the variants over (docs/fidelity.md, "Across the design
#: space"): a design outside it gets the same numbers and flags, but no measurement backs
#: them. The validity flags check the model's own assumptions, not this.
MEASURED_SPACE = ("radius 5-25 mm, wall 1-6 mm, length 50-150 mm, base = wall, silicone "
                  "tc5005, bends 17-51 deg (nylonflex fit fe); the fig12 grid to 231 deg "
                  "(nylonflex verify)")

_FIG12 = "the fig12 grid (nylonflex verify, 24 designs): model / FE bend angle"

VARIANTS = {v.name: v for v in [
    Variant("paper", "the paper's balance",
            "the paper's moment balance (Polygerinos), eqs. 1-16 as coded; the "
            "default, bit for bit",
            f"bends too little: {_FIG12} 0.69 (0.42-0.97) at half of p*, 0.64 (0.31-0.89) at "
            "p*, 2 of 38 within 10 %; over the fit-fe space 0.69 (0.32-1.06), 10 of 96",
            "to reproduce the paper's figures; for a designer's angle use fe_calibrated",
            "s. 1-8"),
    Variant("coupled_muscle", "the muscle as a load line",
            "the muscle as a load line (eq. 1): it pulls F_b(T)(1 - "
            "s/s_free), so a stiff chamber stops it short (limit 3, load-limited)",
            "not measured against the FE twin (it changes the muscle's side only); its "
            "thermal_force_coefficient 2 mN/K is a proposal, which says these muscles cannot "
            "drive the paper's chambers",
            "to ask whether the muscle can drive the chamber at all; fit the coefficient "
            "(nylonflex fit muscle) before trusting its numbers", "s. 16"),
    Variant("paper_eq10", "the paper's eqs. 10-12 literally",
            "the paper's eqs. 10-12 literally (radial stretch (1-s)^-2) in the "
            "wrap's tension instead of plane strain; changes F_n and the stroke limit only",
            "the angles are paper's; not measured separately",
            "to check a result against the paper's text; otherwise paper", "s. 16"),
    Variant("incompressible_wall", "the wall's area conserved",
            "the silicone's area is conserved as the wrap shrinks: "
            "the chamber's volume falls faster, the pressure rises and the chamber can close "
            "(validity bit 8, chamber_closes)",
            "the pressure law is not measured (the FE twin takes the pressure as given); the "
            "angles at a pressure are paper's",
            "for thick walls, where the wall's own area is a large part of the section; "
            "combine its stroke limit with fe_calibrated's angle by hand", "s. 16"),
    Variant("cauchy_moment", "the wall's moment from the Cauchy (true) stress",
            "the wall's moment integrates the Cauchy (true) stress "
            "lambda S(lambda) over the undeformed section instead of the nominal stress S; "
            "equal at small strain, stiffer at large bends",
            f"bends least of all: {_FIG12} 0.63 (0.40-0.77) at half of p*, 0.52 (0.28-0.67) "
            "at p*, 0 of 38 within 10 %",
            "not for design: a check of the stress measure (the FE twin sides with the "
            "nominal stress of paper, and bends further still)", "s. 6, 16"),
    Variant("lateral_pressure", "the pressure on the wall and floor added",
            "the chamber's pressure on its wall and floor in the moment "
            "balance (a confining stress falling linearly through the wall); bends further "
            "and pushes harder blocked",
            f"{_FIG12} 1.06 (0.98-1.25) at half of p*, 15 of 22 within 10 %; 1.06 "
            "(0.84-1.20) at p*, 8 of 16; over the fit-fe space 1.035 (0.83-1.22), 64 of 96",
            "near full stroke (bends past about 60 deg), where fe_calibrated extrapolates; "
            "its moment and tip force are fe_calibrated's too", "s. 18"),
    Variant("fe_calibrated", "lateral_pressure corrected by the FE twin",
            "lateral_pressure's angle times a correction fitted to the FE "
            "twin (of t/a, L/a and the wall's hoop stress over mu0); the same pressure, "
            "moment and tip force",
            "0.999 (0.88-1.18) of the FE over its training space, each design left out, 88 "
            f"of 96 within 10 %; {_FIG12} 0.99 (0.81-1.05) at half of p*, 19 of 22 within 10 "
            "%, 0.88 (0.67-1.07) at p* (past its training), 7 of 16",
            "the designer's choice for the bend at a known (measured) pressure, up to about "
            "60 deg inside the measured space; outside it (another silicone, base != wall, "
            "L/a beyond 2-30), run nylonflex verify on the cube. Its full-stroke answers "
            "take eq. 8's pressure, 3-10x the sealed FE twin's (see sealed_chamber)",
            "s. 21"),
    Variant("sealed_chamber", "the sealed chamber as built, fitted to the sealed FE twin",
            "the chamber's real pressure when the wrap squeezes the sealed air: Boyle with a "
            "compliant chamber that rounds out, (p0 + p)(v_free(s) + p/K) = p0, instead of "
            "eq. 8's rigid section; lateral_pressure's balance at that pressure plus the "
            "wall's squeeze bend c_sq s L / h; held straight, the higher pressure of a "
            "chamber that cannot lengthen by bending",
            "against the stroke-driven, sealed FE twin at full stroke (docs/fidelity.md), 48 "
            "designs, each left out of the fit: bend 1.02 (0.83-1.15), 47 of 48 within 15 % "
            "(paper 2 of 48, fe_calibrated 0); blocked force 1.01 (0.78-1.13), 45 of 48 "
            "within 15 % (paper 4); on 24 new fig12 designs bend 23 and blocked force 22 "
            "within 15 %",
            "the full-stroke bend, range of motion, which limit binds and the blocked force, "
            "as the FE twin driven as built sees them. Fitted on tc5005 with b = t on the "
            "coarse mesh: for your own actuator settle it on the bench (docs/bench.md, "
            "nylonflex fit chamber)",
            "s. 22"),
]}


def describe() -> list[dict]:
    """Every variant of :data:`nylonflex.variables.MODELS` (in its order) as a dict, with
    ``default`` true for ``paper``; a name without a record says so."""
    out = []
    for name in MODELS:
        v = VARIANTS.get(name)
        rec = asdict(v) if v is not None else {"name": name, "short": name,
                                               "adds": "(not described yet)", "holds": "",
                                               "use": "", "section": ""}
        rec["default"] = name == MODELS[0]
        out.append(rec)
    return out
