"""Draw the README's picture, docs/fig12b.png, with the real commands: the main job's sweep
(``nylonflex sweep configs/fig12.yaml``) and its chart ``fig12b``, then stored as a
128-colour palette PNG (about a third of matplotlib's truecolour bytes; the lines and
text look the same) so that the README stays light. Run from the repository root:
``python docs/tools/readme_figure.py``."""

import subprocess
import sys
import tempfile
from pathlib import Path

from PIL import Image

ROOT = Path(__file__).resolve().parents[2]


def main() -> int:
    with tempfile.TemporaryDirectory() as tmp:
        cube = Path(tmp) / "fig12" / "cube.h5"
        subprocess.run(["nylonflex", "sweep", str(ROOT / "configs" / "fig12.yaml"),
                        "--out", str(cube), "--no-charts", "--quiet"], check=True)
        subprocess.run(["nylonflex", "chart", str(cube), "--figure", "fig12b",
                        "--out", tmp, "--quiet"], check=True)
        img = Image.open(Path(tmp) / "fig12b.png").convert("RGB")
        out = ROOT / "docs" / "fig12b.png"
        img.quantize(colors=128, method=Image.Quantize.MEDIANCUT).save(out, optimize=True)
    print(f"{out}  {out.stat().st_size / 1e3:.0f} kB")
    return 0


if __name__ == "__main__":
    sys.exit(main())
