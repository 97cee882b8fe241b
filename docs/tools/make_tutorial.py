"""Write docs/tutorial.ipynb (unexecuted) from the cells below; the docs build executes it
(myst-nb, every build). Edit here, then ``python docs/tools/make_tutorial.py``."""

from pathlib import Path

import nbformat
from nbformat.v4 import new_code_cell, new_markdown_cell, new_notebook

CELLS = [
    ("md", """# Tutorial: from a sweep to a chosen design

The paper's design question (its section 4): a robotics designer wants **the largest tip
force with a full range of motion**, with a chamber radius of at most 20 mm, a wall of at
most 6 mm, at length 90 mm, coil index 1.1 and wrap angle 8 deg. This notebook sweeps the
paper's figure-12 design space, asks the cube, lets `nylonflex design` pick the design,
saves the interactive explorer, and checks the answer against the finite-element twin.

Everything inside nylonflex is SI (metres, radians, pascals); configs and the command
line take mm, deg and kPa. It needs the `fe` and `explore` extras
(`pip install "nylonflex[fe,explore]"`)."""),
    ("code", """import tempfile
from importlib.resources import files
from pathlib import Path

import numpy as np

import nylonflex as nf
from nylonflex.query import query_cube

work = Path(tempfile.mkdtemp(prefix="nylonflex-tutorial-"))
out = Path("tutorial_output")        # what this notebook keeps: the explorer page
out.mkdir(exist_ok=True)"""),
    ("md", """## 1. Sweep the design space

`configs/fig12.yaml` (`nylonflex init` writes it; it also ships inside the package) spans
radius 5-25 mm, wall 1-6 mm, three lengths, four coil indices and four wrap angles:
11,808 designs, each evaluated exactly. `nylonflex sweep configs/fig12.yaml` does the same
from the shell, and draws the charts."""),
    ("code", """cfg = nf.load_config(files("nylonflex.examples") / "fig12.yaml")
cube_path = work / "fig12" / "cube.h5"
nf.run_sweep(cfg, cube_path).close()    # a cube file, as `nylonflex sweep` writes
ds = nf.open_cube(cube_path)
ds"""),
    ("md", """## 2. Ask the cube

Which designs give at least 0.5 N with a full range of motion, smallest first? The
conditions are the grammar of `nylonflex query --where`, with units."""),
    ("code", """result = query_cube(ds, sort="radius", limit=5,
                    where=["tip_force_max >= 0.5 N", "range_fraction == 1"])
result"""),
    ("md", """## 3. Let `nylonflex design` answer the specification

The specification is `configs/design_force.yaml`: maximise the tip force under the
constraints, then refine the best grid design off the grid with the exact model (the
answer is re-checked)."""),
    ("code", """spec = {
    "name": "design_force",
    "cube": str(cube_path),
    "objectives": [{"max": "tip_force_max"}],
    "constraints": ["range_fraction >= 1",
                    "radius <= 20 mm", "wall_thickness <= 6 mm",
                    "length == 90 mm", "coil_index == 1.1",
                    "wrap_angle == 8 deg"],
    "refine": True,
}
design = nf.run_design(spec)
design"""),
    ("code", """best = design.designs[0]
print(f"radius {best['radius'] * 1e3:.2f} mm, "
      f"wall {best['wall_thickness'] * 1e3:.2f} mm: "
      f"tip force {best['tip_force_max']:.3f} N, "
      f"largest bend {np.degrees(best['bend_angle_max']):.0f} deg")"""),
    ("md", """The paper reads 1.2 N off its figure 12(b) for this question, and so does nylonflex: the
answer is the largest radius and wall the constraints allow (20 mm, 6 mm), where the
muscle's stroke, not its strength, still sets the limit (`limit`: stroke), so the design
keeps its full range of motion. Refinement found nothing better off the grid (`source`:
grid).

## 4. Explore it

The explorer page (`nylonflex explore CUBE --html page.html`) is one self-contained file:
sliders for every axis, a design map and the picked design's curves, offline."""),
    ("code", """from nylonflex.explore.page import build_html

page = out / "fig12_explorer.html"
page.write_text(build_html(ds, source="fig12"), encoding="utf-8")
print(f"{page}: {page.stat().st_size / 1e6:.1f} MB")"""),
    ("md", """In the documentation site this page is <a href="fig12_explorer.html">fig12_explorer.html</a>.

## 5. Check it against the finite-element twin

The paper's moment balance lets the chamber pressure act on the end caps only; the FE twin
(FElupe, the `fe` extra) models the whole body. `fe_calibrated` is the balance corrected by
a fit to the FE twin (docs/fidelity.md). One pressure on the coarse mesh keeps this to
seconds; `nylonflex verify CUBE` does the same for a sample of a cube's designs."""),
    ("code", """a, t, L = best["radius"], best["wall_thickness"], best["length"]
p = 5e3  # [Pa]
fe = nf.fe_bend(a, t, L, [p], mesh="coarse")
for model in ("paper", "lateral_pressure", "fe_calibrated"):
    angle = float(nf.bend_angle(p, a, t, L, model=model))
    print(f"{model:17s} {np.degrees(angle):6.1f} deg")
error = fe["discretisation_error"][0]
print(f"{'FE (coarse mesh)':17s} {np.degrees(fe['bend_angle'][0]):6.1f} deg "
      f"(discretisation error about {error:.0%})")"""),
    ("md", """The paper's model bends less than the FE twin (it misses the pressure on the wall and
floor); `fe_calibrated` is close to it. For a design decision, sweep with
`model: fe_calibrated` (or `model: [paper, fe_calibrated]` to keep both) and check your
region with `nylonflex verify`."""),
    ("code", """ds.close()"""),
]


def main():
    nb = new_notebook()
    nb.cells = [new_markdown_cell(src) if kind == "md" else new_code_cell(src)
                for kind, src in CELLS]
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3",
                                 "language": "python"}
    path = Path(__file__).resolve().parents[1] / "tutorial.ipynb"
    nbformat.write(nb, path)
    print(path)


if __name__ == "__main__":
    main()
