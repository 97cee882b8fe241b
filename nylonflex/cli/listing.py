"""``nylonflex list [TOPIC]``: what a config, a chart or a query can name."""

from __future__ import annotations

import re
import sys
import textwrap

from ..units import json_text

HELP = "list the material sets, model variants, charts or cube variables (with units)"

#: Each topic and the line ``nylonflex list`` (no topic) says about it.
TOPICS = {
    "materials": "silicone, nylon and cooling sets, each field with its unit and source",
    "models": "the model variants (model:), what each adds, where it is measured to hold, "
              "when to use it",
    "charts": "the charts a config's charts: or 'nylonflex chart --figure' can draw",
    "variables": "every cube coordinate and variable (query --where/--sort), SI unit and "
                 "display unit",
}


def add_arguments(p):
    p.add_argument("topic", nargs="?", choices=tuple(TOPICS),
                   help=f"one of: {', '.join(TOPICS)} (none: the topics)")
    p.add_argument("--format", choices=["text", "json"], default="text",
                   help="text, or json (one object; units are SI where values are numbers)")


def _plain(text: str) -> str:
    """A docstring's line without reStructuredText: ``x`` -> x, :func:`y` -> y."""
    text = re.sub(r":[a-z]+:`~?([^`]+)`", r"\1", text)
    return text.replace("``", "").replace("`", "")


def _first_line(doc) -> str:
    return _plain((doc or "").strip().splitlines()[0].rstrip(".")) if doc else ""


def _materials_data():
    from ..materials import (COOLING_PARAMETERS, FIELD_UNITS, NYLON_PARAMETERS,
                             SILICONE_PARAMETERS, cooling_parameters, nylon_parameters,
                             silicone_parameters)

    out = {}
    for kind, table, build in (("silicone", SILICONE_PARAMETERS, silicone_parameters),
                               ("nylon", NYLON_PARAMETERS, nylon_parameters)):
        out[kind] = {}
        for name in table:
            m = build(name)
            fields = {f: {"value": v, "units": FIELD_UNITS.get(f, "1"),
                          "source": m.sources.get(f, "")}
                      for f, v in m.to_dict().items() if f != "name"}
            rec = {"description": m.description, "fields": fields}
            if kind == "silicone":
                rec["initial_shear_modulus"] = m.initial_shear_modulus
            out[kind][name] = rec
    out["cooling"] = {}
    for name in COOLING_PARAMETERS:
        env = cooling_parameters(name)
        out["cooling"][name] = {"description": env.description, "fluid": env.fluid,
                                "speed": env.speed, "speed_units": "m/s",
                                "source": env.sources.get("speed", "")}
    return out


def _materials(out):
    data = _materials_data()

    def show(value):
        if isinstance(value, (tuple, list)):
            return ", ".join(f"{x:g}" for x in value)
        return f"{value:g}"

    for kind in ("silicone", "nylon"):
        print(f"{kind} sets (config key '{kind}:'; override a field with "
              f"{{set: NAME, FIELD: VALUE}} in the unit shown):", file=out)
        for name, rec in data[kind].items():
            extra = f", initial shear modulus {rec['initial_shear_modulus']:.4g} Pa" \
                if kind == "silicone" else ""
            print(f"  {name}: {rec['description']}{extra}", file=out)
            for field, f in rec["fields"].items():
                unit = "" if f["units"] == "1" else f" [{f['units']}]"
                print(f"    {field + unit:<34} {show(f['value']):<28} {f['source']}", file=out)
        print(file=out)
    print("cooling sets (config key 'cooling:'; {set: NAME, speed: VALUE} in m/s; without "
          "it the nylon set's heat_loss_per_length holds):", file=out)
    for name, env in data["cooling"].items():
        print(f"  {name}: {env['description']}; fluid {env['fluid']}, speed "
              f"{env['speed']:g} m/s  {env['source']}", file=out)
    print(file=out)


def _models_data():
    from ..variants import MEASURED_SPACE, describe

    return {"models": describe(), "measured_space": MEASURED_SPACE,
            "note": "the validity flags check the model's own assumptions (self contact, "
                    "the silicone's fitted stretch, turns of the wrap), not whether a design "
                    "lies inside the measured space: a design outside it is 'valid' and "
                    "unmeasured (nylonflex verify CUBE measures it)"}


def _models(out):
    data = _models_data()
    print("model variants (config key 'model:', one name or a list; docs/model.md s. 16, "
          "docs/fidelity.md):", file=out)
    for rec in data["models"]:
        default = " (the default)" if rec["default"] else ""
        print(f"  {rec['name']}{default}: {rec['short']}  [docs/model.md {rec['section']}]",
              file=out)
        for key in ("adds", "holds", "use"):
            if rec[key]:  # "10 %" kept on one line
                text = textwrap.fill(rec[key].replace(" %", "\u00a0%"), 92,
                                     initial_indent=f"    {key + ':':<7}",
                                     subsequent_indent=" " * 11)
                print(text.replace("\u00a0", " "), file=out)
    print(textwrap.fill(f"measured over: {data['measured_space']}; {data['note']}.", 94,
                        initial_indent="  ", subsequent_indent="  "), file=out)


def _charts_data():
    from ..config.charts import CHART_REGISTRY

    out = {}
    for name, chart in CHART_REGISTRY.items():
        needs = [f"2+ values of {' and '.join(chart.needs)}"] if chart.needs else []
        needs += [chart.needs_text] if chart.needs_text else []
        out[name] = {"description": _first_line(chart.load().__doc__), "needs": needs}
    return out


def _charts(out):
    print("charts (config 'charts:' list, 'nylonflex chart CUBE --figure NAME'):", file=out)
    charts = _charts_data()
    width = max(map(len, charts))
    for name, chart in charts.items():
        print(f"  {name:<{width}} {chart['description']} (needs "
              f"{', '.join(chart['needs'])})", file=out)


def _variable_tables():
    """(JSON key, heading, registry table) of each group of variables."""
    from ..variables import COORDS, CURVES, DESIGN, INPUTS, SPREAD, TRACKING, UNCERTAIN

    return (("axes", "axes and curve coordinates", COORDS),
            ("design", "design variables (query --where/--sort)", DESIGN),
            ("curves", "curves", CURVES),
            ("uncertainty", "with uncertainty or requirements: (docs/uncertainty.md)",
             {k: v for k, v in UNCERTAIN.items() if k == "feasibility"}),
            ("tracking", "with tracking: (docs/model.md s. 19; query --where/--sort)",
             TRACKING),
            ("spread", "model spread (a sweep with 'fidelity: spread'; query --where/--sort)",
             SPREAD),
            ("inputs", "other inputs", INPUTS))


def _variables_data():
    return {key: {v.name: {"units": v.units, "display": v.display, "long_name": v.long_name,
                           "description": v.description, "dims": list(v.dims)}
                  for v in table.values()} for key, _, table in _variable_tables()}


def _variables(out):
    for key, title, table in _variable_tables():
        print(f"{title}:", file=out)
        w = max(18, *(len(n) for n in table))
        for v in table.values():
            units = f"[{v.units}]" + (f", shown in {v.display}" if v.display != v.units
                                      else "")
            print(f"  {v.name:<{w}} {units:<22} {v.long_name}: {v.description}", file=out)
            if v.dims and tuple(v.dims) != (v.name,):
                print(f"  {'':<{w}} {'':<22} over ({', '.join(v.dims)})", file=out)
        if key == "uncertainty":
            print(f"  {'<variable>_quantile':<{w}} {'':<22} quantiles of each float design "
                  "variable, over (..., quantile)", file=out)
        print(file=out)


_TEXT = {"materials": _materials, "models": _models, "charts": _charts,
         "variables": _variables}
_DATA = {"materials": _materials_data, "models": _models_data, "charts": _charts_data,
         "variables": _variables_data}


def run(args) -> int:
    if args.format == "json":
        sys.stdout.write(json_text(_DATA[args.topic]() if args.topic else {"topics": TOPICS}))
        return 0
    if args.topic is None:
        print("nylonflex list TOPIC (--format json for a script):")
        for name, what in TOPICS.items():
            print(f"  {name:<10} {what}")
        return 0
    _TEXT[args.topic](sys.stdout)
    return 0
