"""Unit spellings that other tools read otherwise are refused with the spelling to write
(issue 50). pint and UDUNITS read ``C`` as the coulomb, know no ``Nm`` or ``Nmm`` (``nm``
is the nanometre) and are case-sensitive (``Ohm``); nylonflex once took all four as
aliases, so a config that said ``C`` meant something else to every other reader."""

import pytest

from nylonflex.units import InputError, parse_quantity, to_si


@pytest.mark.parametrize("unit, spelling", [("C", "degC"), ("Nm", "N m"), ("Nmm", "N mm"),
                                            ("mNm", "mN m"), ("Ohm", "ohm")])
def test_the_ambiguous_spelling_is_refused_with_the_one_to_write(unit, spelling):
    with pytest.raises(InputError, match=rf"^field: unit '{unit}': write '{spelling}' \("):
        to_si(1.0, unit, "field")
    # and the spelling it names is accepted
    assert to_si(1.0, spelling, "field") == pytest.approx(
        {"degC": 274.15, "N m": 1.0, "N mm": 1e-3, "mN m": 1e-3, "ohm": 1.0}[spelling])


def test_a_typed_quantity_names_its_field():
    with pytest.raises(InputError, match=r"^tracking\.initial_temperature: unit 'C': "
                                         r"write 'degC' \(C is the coulomb"):
        parse_quantity("25 C", "tracking.initial_temperature", "temperature", "degC")
    assert parse_quantity("25 degC", "t", "temperature", "degC") == pytest.approx(298.15)


def test_spellings_pint_reads_the_same_stay_accepted():
    assert to_si(2.0, "N*m", "f", "torque") == 2.0
    assert to_si(3.0, "\u03a9", "f", "resistance") == 3.0
