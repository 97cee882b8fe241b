"""``nylonflex list materials|charts|variables``: what a config, a chart or a query can name."""

from __future__ import annotations

import sys

HELP = "list the material sets, charts or cube variables (with units)"

TOPICS = ("materials", "charts", "variables")


def add_arguments(p):
    p.add_argument("topic", choices=TOPICS, help=f"one of: {', '.join(TOPICS)}")


def _first_line(doc) -> str:
    return (doc or "").strip().splitlines()[0].rstrip(".") if doc else ""


def _materials(out):
    from ..materials import (FIELD_UNITS, NYLON_PARAMETERS, SILICONE_PARAMETERS,
                             nylon_parameters, silicone_parameters)

    def show(value):
        if isinstance(value, (tuple, list)):
            return ", ".join(f"{x:g}" for x in value)
        return f"{value:g}"

    for kind, table, build in (("silicone", SILICONE_PARAMETERS, silicone_parameters),
                               ("nylon", NYLON_PARAMETERS, nylon_parameters)):
        print(f"{kind} sets (config key '{kind}:'; override a field with "
              f"{{set: NAME, FIELD: VALUE}} in the unit shown):", file=out)
        for name in table:
            m = build(name)
            extra = f", initial shear modulus {m.initial_shear_modulus:.4g} Pa" \
                if kind == "silicone" else ""
            print(f"  {name}: {m.description}{extra}", file=out)
            for field, value in m.to_dict().items():
                if field == "name":
                    continue
                unit = FIELD_UNITS.get(field, "1")
                unit = "" if unit == "1" else f" [{unit}]"
                source = m.sources.get(field, "")
                print(f"    {field + unit:<34} {show(value):<28} {source}", file=out)
        print(file=out)
    from ..materials import COOLING_PARAMETERS, cooling_parameters

    print("cooling sets (config key 'cooling:'; {set: NAME, speed: VALUE} in m/s; without "
          "it the nylon set's heat_loss_per_length holds):", file=out)
    for name in COOLING_PARAMETERS:
        env = cooling_parameters(name)
        print(f"  {name}: {env.description}; fluid {env.fluid}, speed {env.speed:g} m/s  "
              f"{env.sources.get('speed', '')}", file=out)
    print(file=out)


def _charts(out):
    from ..config.charts import CHART_REGISTRY

    print("charts (config 'charts:' list, 'nylonflex chart CUBE --figure NAME'):", file=out)
    for name, chart in CHART_REGISTRY.items():
        needs = [f"2+ values of {' and '.join(chart.needs)}"] if chart.needs else []
        needs += [chart.needs_text] if chart.needs_text else []
        print(f"  {name:<11} {_first_line(chart.load().__doc__)} (needs {', '.join(needs)})",
              file=out)


def _variables(out):
    from ..variables import COORDS, CURVES, DESIGN, INPUTS, SPREAD

    for title, table in (("axes and curve coordinates", COORDS), ("design variables "
                         "(query --where/--sort)", DESIGN), ("curves", CURVES),
                         ("other inputs", INPUTS),
                         ("model spread (a sweep with 'fidelity: spread'; query "
                          "--where/--sort)", SPREAD)):
        print(f"{title}:", file=out)
        w = max(18, *(len(n) for n in table))
        for v in table.values():
            units = f"[{v.units}]" + (f", shown in {v.display}" if v.display != v.units
                                      else "")
            print(f"  {v.name:<{w}} {units:<22} {v.long_name}: {v.description}", file=out)
            if v.dims and tuple(v.dims) != (v.name,):
                print(f"  {'':<{w}} {'':<22} over ({', '.join(v.dims)})", file=out)
        print(file=out)


def run(args) -> int:
    {"materials": _materials, "charts": _charts, "variables": _variables}[args.topic](
        sys.stdout)
    return 0
