"""The one-design path of ``nylonflex.evaluate`` and ``design_limits`` (issue 49): float
inputs with two named sets and no cooling set take float checks, records made once a
process and the kernel's compiled entry; everything else takes the general path. The two
must give the same bits and the same refusals: a 0-d array (not a float) takes the general
path, so each test compares a float call with the same call of 0-d arrays."""

import math
import threading

import numba
import numpy as np
import pytest

import nylonflex as nf
from naive import random_designs
from nylonflex.engine import one_design
from nylonflex.engine.pointwise import MODELS
from nylonflex.physics import check_input, float_in_range, input_range
from nylonflex.variables import DESIGN

AXES = ("radius", "wall_thickness", "length", "coil_index", "wrap_angle")
ONE = dict(radius=7.5e-3, wall_thickness=2e-3, length=70e-3, coil_index=1.7,
           wrap_angle=0.1396)


def _general(values: dict) -> dict:
    """The same inputs as 0-d arrays: what the one-design path leaves to the general one."""
    return {k: v if v is None or isinstance(v, str) else np.asarray(v)
            for k, v in values.items()}


def _same_bits(fast: dict, slow: dict, shape=()) -> None:
    assert list(fast) == list(slow) == list(DESIGN)
    for name in DESIGN:
        a, b = fast[name], slow[name]
        assert type(a) is type(b) and a.dtype == b.dtype and a.shape == b.shape == shape, name
        assert a.tobytes() == b.tobytes(), name


def _same_outcome(fast, slow) -> None:
    """The same refusal, or the same bits."""
    assert type(fast) is type(slow)
    if isinstance(slow, str):
        assert fast == slow
    else:
        _same_bits(fast, slow, np.shape(slow["limit"]))


def _outcome(call):
    try:
        return call()
    except ValueError as exc:
        return f"ValueError: {exc}"


def _cases(n: int = 48):
    """Random designs over the accepted range, each model, with and without a supply, a
    base thickness, chamber coefficients and the other named sets."""
    d = random_designs(n, seed=49)
    sets = [("tc5005", "silver_nylon66"), ("ecoflex_00_30", "silver_nylon66_still_air"),
            ("dragon_skin_10", "silver_nylon66"), ("elastosil_m4601", "silver_nylon66")]
    for i in range(n):
        values = {k: float(v[i]) for k, v in d.items()}
        silicone, nylon = sets[i % len(sets)]
        kw = dict(model=MODELS[i % len(MODELS)], silicone=silicone, nylon=nylon)
        if i % 3 == 1:
            kw["supply_voltage"] = 24.0 + 10.0 * i
        if i % 5 == 2:
            values["base_thickness"] = min(0.05, 1.4 * values["wall_thickness"])
        if i % 7 == 3:
            kw["chamber"] = [1.1, 0.2, 0.9, 0.1, 0.05, 0.01, 0.3]
        if i % 4 == 0:
            values = {k: np.float64(v) for k, v in values.items()}
        yield values, kw


def test_the_one_design_path_gives_the_general_paths_bits():
    taken = 0
    for values, kw in _cases():
        fast = _outcome(lambda: nf.evaluate(**values, **kw))
        slow = _outcome(lambda: nf.evaluate(**_general(values), **kw))
        if isinstance(slow, str):  # a supply too low for the muscle: the same refusal
            assert fast == slow
            continue
        _same_bits(fast, slow)
        taken += 1
    assert taken > 30


def test_design_limits_one_design_gives_the_floats_of_the_general_path():
    for values, kw in _cases(24):
        kw.pop("chamber", None)
        args = [values[k] for k in AXES]
        fast = _outcome(lambda: nf.design_limits(*args, values.get("base_thickness"), **kw))
        slow = _outcome(lambda: nf.design_limits(*(np.asarray(x) for x in args),
                                                 values.get("base_thickness"), **kw))
        assert type(fast) is type(slow)
        if isinstance(slow, dict):
            assert list(fast) == list(slow)
            assert all(type(fast[k]) is type(slow[k]) for k in slow)
            assert {k: repr(v) for k, v in fast.items()} == {k: repr(v) for k, v in slow.items()}
        else:
            assert fast == slow


def test_coil_indices_on_the_table_nodes_and_ends():
    for c in (1.1, 1.3, 1.5, 1.7, math.nextafter(1.1, 2.0), math.nextafter(1.7, 0.0)):
        values = {**ONE, "coil_index": c}
        _same_bits(nf.evaluate(**values), nf.evaluate(**_general(values)))


@pytest.mark.parametrize("name", [*AXES, "base_thickness"])
def test_a_bad_scalar_gets_the_general_paths_refusal(name):
    # (True, [1.0] and 1 are not floats: the general path takes them, and may accept them)
    bad = [math.nan, math.inf, -math.inf, -1.0, -0.0, 0.0, 1e-300, 5.0, 7.5, 80.0, 1e9, 2.5,
           "x", True, [1.0], 1]
    refused = 0
    for value in bad:
        values = {**ONE, name: value}
        fast = _outcome(lambda: nf.evaluate(**values))
        _same_outcome(fast, _outcome(lambda: nf.evaluate(**_general(values))))
        if isinstance(fast, str):
            refused += 1
            assert fast.startswith(f"ValueError: {name}: must be")
            limits = _outcome(lambda: nf.design_limits(*(values[k] for k in AXES),
                                                       values.get("base_thickness")))
            assert limits == fast
    assert refused >= 11


@pytest.mark.parametrize("kw", [
    dict(supply_voltage=0.0), dict(supply_voltage=-1.0), dict(supply_voltage=math.nan),
    dict(supply_voltage=1001.0), dict(supply_voltage="twelve"), dict(supply_voltage=1e-3),
    dict(model="magic"), dict(silicone="nope"), dict(nylon="nope"), dict(chamber=[1.0, 2.0]),
    dict(chamber={"k0": 1.0}), dict(chamber=[1.0] * 6 + [math.inf]),
])
def test_a_bad_option_gets_the_general_paths_refusal(kw):
    fast = _outcome(lambda: nf.evaluate(**ONE, **kw))
    assert isinstance(fast, str)
    assert fast == _outcome(lambda: nf.evaluate(**_general(ONE), **kw))


def test_refusals_come_in_the_general_paths_order():
    # a bad radius before an unknown set, an unknown set before a bad coil index, a bad
    # coil index before bad chamber coefficients
    for values, kw in [({**ONE, "radius": math.nan}, dict(silicone="nope")),
                       ({**ONE, "coil_index": 9.0}, dict(silicone="nope")),
                       ({**ONE, "coil_index": 9.0}, dict(chamber=[1.0]))]:
        fast = _outcome(lambda: nf.evaluate(**values, **kw))
        assert fast == _outcome(lambda: nf.evaluate(**_general(values), **kw))


def test_float_in_range_is_check_inputs_test_of_a_float():
    for name in ("radius", "wall_thickness", "base_thickness", "length", "wrap_angle",
                 "supply_voltage"):
        lo, hi, _, _ = input_range(name)
        for value in (lo, hi, math.nextafter(lo, -1.0), math.nextafter(hi, 2 * hi), 0.5 * hi,
                      np.float64(0.5 * hi), math.nan, math.inf, -math.inf, 0.0):
            try:
                check_input(name, value)
                accepted = True
            except ValueError:
                accepted = False
            assert float_in_range(value, *input_range(name)) == accepted, (name, value)
    assert not float_in_range(1, 0.0, 2.0) and not float_in_range(np.asarray(1.0), 0.0, 2.0)


def test_threads_each_get_their_own_design():
    # the one-design path's arrays are a thread's own: designs evaluated at once on four
    # threads are each what one thread alone gives
    d = random_designs(64, seed=5)
    batch = nf.evaluate(**d)
    got, errors = {}, []

    def work(k):
        try:
            for i in range(k, 64, 4):
                got[i] = nf.evaluate(**{name: float(v[i]) for name, v in d.items()})
        except Exception as exc:  # noqa: BLE001 - reported below
            errors.append(exc)

    threads = [threading.Thread(target=work, args=(k,)) for k in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors
    for i in range(64):
        for name in DESIGN:
            np.testing.assert_array_equal(got[i][name], batch[name][i], err_msg=name)


@pytest.mark.skipif(numba.config.DISABLE_JIT, reason="reads Numba's compiled entry")
def test_the_one_design_path_calls_one_compiled_signature_straight(monkeypatch):
    # every argument tuple the path makes (each model, supply, chamber and set) has the
    # Numba types of the entry it calls: the entry checks none (kernels.compiled_entry)
    from nylonflex.kernels import design as kernels

    made = []
    call = one_design._point_call
    monkeypatch.setattr(one_design, "_point_call", lambda args: (made.append(args), call(args)))
    for values, kw in _cases(16):
        _outcome(lambda: nf.evaluate(**values, **kw))
    signatures = {tuple(numba.typeof(a) for a in args) for args in made}
    assert len(made) >= 16 and len(signatures) == 1
    assert signatures <= set(kernels.design_points.signatures)
    entry = one_design._ENTRY["one"]
    assert entry is not kernels.design_points
    assert entry is kernels.points_entry(made[0])


def test_the_one_design_table_value_is_numpys_interp_bit_for_bit():
    # every named set's tables, at random coil indices over the table, at each node and
    # its neighbours, and at the ends
    rng = np.random.default_rng(49)
    for nylon in nf.materials.NYLON_PARAMETERS:
        sets = one_design._one_design_sets("tc5005", nylon)
        xs = sets.coil_index
        points = [*xs, *(math.nextafter(x, 0.0) for x in xs[1:]),
                  *(math.nextafter(x, 9.0) for x in xs[:-1]),
                  *rng.uniform(xs[0], xs[-1], 20_000).tolist()]
        for ys in (sets.stroke_max, sets.strength):
            got = np.array([one_design._table_value(x, xs, ys) for x in points])
            want = np.interp(points, np.array(xs), np.array(ys))
            assert got.tobytes() == want.tobytes()
            assert all(one_design._table_value(x, xs, ys) == np.interp(x, xs, ys)
                       for x in points[:50])
