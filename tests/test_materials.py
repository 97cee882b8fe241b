import re

import numpy as np
import pytest

from nylonflex.materials import (
    NYLON_PARAMETERS,
    SILICONE_KINDS,
    SILICONE_PARAMETERS,
    nylon_parameters,
    shear_modulus_range_text,
    silicone_parameters,
)


@pytest.mark.parametrize("name,mu0", [
    # docs/model.md section 9, column mu_0 (printed to 3 digits from rounded mu, alpha)
    ("tc5005", 22.9e3), ("ecoflex_00_30", 17.3e3), ("dragon_skin_10", 50.1e3),
    ("elastosil_m4601", 220e3)])
def test_initial_shear_modulus_matches_model_table(name, mu0):
    assert silicone_parameters(name).initial_shear_modulus == pytest.approx(mu0, rel=5e-3)


def test_every_value_has_a_source():
    for name, p in SILICONE_PARAMETERS.items():
        assert set(p["sources"]) >= {"mu", "alpha"}, name
    for name, p in NYLON_PARAMETERS.items():
        numeric = {k for k, v in p.items() if k not in ("description", "sources")}
        assert numeric <= set(p["sources"]), (name, numeric - set(p["sources"]))
        # each source carries its tag S/D/P/K (docs/model.md section 9)
        assert all(s.split(":")[0].strip("/ ")[0] in "SDPK" for s in p["sources"].values())


def test_override_field_by_field():
    s = silicone_parameters({"set": "tc5005", "mu": [50e3, 10e3]})
    assert s.mu == (50e3, 10e3) and s.alpha == (0.2975, 2.770)
    assert s.name == "tc5005+override"
    n = nylon_parameters("silver_nylon66", fibre_diameter=0.3e-3)
    assert n.fibre_diameter == 0.3e-3 and n.t_max == pytest.approx(423.15)


@pytest.mark.parametrize("call,match", [
    (lambda: silicone_parameters("rubber"), r"silicone: unknown set 'rubber'; accepted"),
    (lambda: nylon_parameters("kevlar"), r"nylon: unknown set 'kevlar'"),
    (lambda: silicone_parameters("tc5005", shore=3), r"silicone.shore: unknown field"),
    (lambda: silicone_parameters("tc5005", mu=[-1e3, 0]), r"silicone.mu: initial shear"),
    (lambda: nylon_parameters("silver_nylon66", fibre_diameter=-1),
     r"nylon.fibre_diameter: must be > 0"),
    (lambda: nylon_parameters("silver_nylon66", stroke_max_table=(0.1, 0.2, 1.3, 0.4)),
     r"nylon.stroke_max_table"),
])
def test_bad_material_names_the_field(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_silicone_stiffness_in_kpa_is_caught_as_a_unit_slip():
    # the README's old table listed mu in kPa; a config or a call that copies 56.19, 10.49
    # gives mu_0 = 22.9 Pa, a thousand times softer than any silicone
    with pytest.raises(ValueError, match=r"silicone.mu: .* 22.88.. Pa is implausible for a "
                                         r"shore_00 silicone; must be in \[2000, 200000\] Pa.*"
                                         r"look like kPa"):
        silicone_parameters("tc5005", mu=[56.19, 10.49])
    import nylonflex as nf
    from conftest import EXAMPLE_2

    with pytest.raises(ValueError, match=r"silicone.mu: .*look like kPa"):
        nf.evaluate(**EXAMPLE_2, silicone={"set": "tc5005", "mu": [[56.19, 10.49]] * 2})
    with pytest.raises(ValueError, match=r"silicone.mu: .*look like kPa"):
        nf.design_limits(**EXAMPLE_2, silicone={"set": "tc5005", "mu": [56.19, 10.49]})


def test_radius_in_mm_is_caught_as_a_unit_slip(example_2):
    import nylonflex as nf

    with pytest.raises(ValueError, match=r"radius: must be .* 7.5 looks like mm"):
        nf.design_limits(**dict(example_2, radius=7.5))


# ---------------------------------------------------------------------------- issue 25
@pytest.mark.parametrize("name", sorted(SILICONE_PARAMETERS))
@pytest.mark.parametrize("factor, slip", [
    (1e-3, r"1000 times below .* look like kPa typed as Pa"),
    (1e-2, r"100 times below .* misplaced decimal point"),
    (1e2, r"100 times above .* misplaced decimal point"),
    (1e3, r"1000 times above"),
])
def test_a_hundredfold_slip_of_any_named_set_is_refused_and_named(name, factor, slip):
    # every kind's range spans a factor of 100 around its sets (materials.SILICONE_KINDS),
    # so the set's own mu scaled by 100 or 1000 either way leaves it
    p = SILICONE_PARAMETERS[name]
    lo, hi = SILICONE_KINDS[p["kind"]]["range"]
    assert hi / lo <= 100 and lo < silicone_parameters(name).initial_shear_modulus < hi
    mu = [m * factor for m in p["mu"]]
    bounds = re.escape(f"[{lo:g}, {hi:g}]")
    with pytest.raises(ValueError, match=rf"silicone.mu: .* implausible for a {p['kind']} "
                                         rf"silicone; must be in {bounds} Pa; it is {slip}"):
        silicone_parameters(name, mu=mu)


def test_elastosil_in_kpa_typed_as_pa_is_refused_everywhere():
    # issue 25: mu: [220, 0] gave a 56,115 deg bend; elastosil's kind is shore_a
    import nylonflex as nf
    from conftest import EXAMPLE_2

    bad = {"set": "elastosil_m4601", "mu": [220, 0]}
    for call in (lambda: silicone_parameters(bad),
                 lambda: nf.design_limits(**EXAMPLE_2, silicone=bad),
                 lambda: nf.evaluate(**EXAMPLE_2, silicone=dict(bad, mu=[[220, 0]] * 2))):
        with pytest.raises(ValueError, match=r"220 Pa is implausible for a shore_a silicone; "
                                             r"must be in \[20000, 2e\+06\] Pa; it is 1000 "
                                             r"times below elastosil_m4601's own"):
            call()


def test_kind_widens_the_range_on_request_and_is_checked():
    stiff = {"set": "tc5005", "mu": [220e3, 0], "alpha": [2, 1]}
    with pytest.raises(ValueError, match=r"give silicone.kind, one of shore_00, shore_a"):
        silicone_parameters(stiff)
    assert silicone_parameters(dict(stiff, kind="shore_a")).initial_shear_modulus == 220e3
    with pytest.raises(ValueError, match=r"silicone.kind: must be one of shore_00, shore_a, any"):
        silicone_parameters(dict(stiff, kind="rubber"))


def test_readme_docs_and_messages_quote_the_registrys_bounds():
    # the bounds are stated once (SILICONE_KINDS); docs/model_brief.md (once the README) and
    # docs/model.md print them
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    for doc in ("docs/model_brief.md", "docs/model.md"):
        text = " ".join((root / doc).read_text().split())  # a quote may wrap a line
        for kind in SILICONE_KINDS:
            assert f"`{kind}` {shear_modulus_range_text(kind)}" in text, (doc, kind)
        assert "100 Pa is refused" not in text and "[1 kPa, 100 MPa]" not in text


@pytest.mark.parametrize("kind, field, bad, match", [
    ("nylon", "fibre_diameter", -1e-4, r"^nylon\.fibre_diameter: must be > 0, got -0\.0001"),
    ("nylon", "t_g", 900.0, r"^nylon\.t_g: must be finite and in \[150, 700\] K, got 900"),
    ("nylon", "t_max", 250.0, r"^nylon\.t_max: must be above nylon\.t_amb"),
    ("nylon", "heat_loss_per_length", 0.0, r"^nylon\.heat_loss_per_length: must be > 0, got 0"),
    ("silicone", "mu", [2e9, 1e4], r"^silicone\.mu: each term must be finite and in"),
    ("silicone", "alpha", [0.0, 2.0], r"^silicone\.alpha: each term must be finite, non-zero"),
])
def test_one_validator_for_a_named_set_and_for_arrays_of_designs(kind, field, bad, match):
    # issue 28: a set is the one-row case of the arrays nf.evaluate takes; both paths run
    # materials.check_nylon / check_silicone and refuse with the same line
    import nylonflex as nf
    from nylonflex.materials import nylon_parameters, silicone_parameters

    base = {"set": "silver_nylon66" if kind == "nylon" else "tc5005"}
    with pytest.raises(ValueError, match=match):
        (nylon_parameters if kind == "nylon" else silicone_parameters)({**base, field: bad})
    good = getattr(nylon_parameters() if kind == "nylon" else silicone_parameters(), field)
    rows = np.array([np.asarray(good, float), np.asarray(bad, float)])  # a good and a bad row
    with pytest.raises(ValueError, match=match):
        nf.evaluate(np.array([10e-3, 12e-3]), 2e-3, 70e-3, 1.3, 0.14,
                    **{kind: {**base, field: rows}})
