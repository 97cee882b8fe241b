"""``nylonflex explore`` in a real headless browser: the served page and the offline file.

Chromium comes from the system's packages (``.ci/run`` installs it) and is driven through
Playwright; Playwright never downloads a browser. The value the page shows (``#nf-readout``'s
``data-value``, display units) is compared with ``ds.sel`` of the fig12 cube to 3
significant figures.
"""

import contextlib
import math
import os
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

CHROMIUM = "/usr/bin/chromium"
ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
        "--disable-component-update", "--disable-sync", "--no-first-run"]
ROOT = Path(__file__).resolve().parents[1]

if not os.path.exists(CHROMIUM):
    pytest.skip(f"no Chromium at {CHROMIUM} (.ci/run installs it with apt-get)",
                allow_module_level=True)
# a real browser and a server: about a minute, run with the slow checks (.ci/run)
pytestmark = pytest.mark.slow

sync_api = pytest.importorskip("playwright.sync_api")
pytest.importorskip("bokeh")

# The page opens on the paper's second worked example: radius 7.5 mm, wall 2 mm, length
# 70 mm, C 1.7, psi 8 deg (issue 46); the tests move the length slider one grid step up
# (70 -> 90 mm) and pick bend_angle_max.
DESIGN = {"radius": 7.5e-3, "wall_thickness": 2e-3, "length": 90e-3, "coil_index": 1.7,
          "wrap_angle": math.radians(8.0)}


@pytest.fixture(scope="module")
def cube(tmp_path_factory):
    import nylonflex as nf

    path = tmp_path_factory.mktemp("explore_browser") / "cube.h5"
    nf.run_sweep(nf.load_config(ROOT / "configs" / "fig12.yaml"), out=path).close()
    return path


@pytest.fixture(scope="module")
def browser():
    with sync_api.sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, args=ARGS)
        yield b
        b.close()


def _free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _expected(cube, name, at):
    from nylonflex.storage import open_cube
    from nylonflex.variables import to_display

    with open_cube(cube) as ds:
        return float(to_display(name, ds[name].sel(at, method="nearest").values))


def _readout(page):
    el = page.locator("#nf-readout")
    return el.get_attribute("data-variable"), float(el.get_attribute("data-value"))


def _wait_for(page, variable, timeout=20.0):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if _readout(page)[0] == variable:
            return _readout(page)
        page.wait_for_timeout(200)
    raise AssertionError(f"the page never showed {variable}: {_readout(page)}")


def _move_length_up(page):
    """Focus the length slider's handle (the third slider) and step it up once."""
    handle = page.locator(".noUi-handle").nth(2)
    handle.focus()
    page.keyboard.press("ArrowRight")
    end = time.monotonic() + 20
    while time.monotonic() < end and "length 90 mm" not in page.locator(
            "#nf-readout").inner_text():
        page.wait_for_timeout(200)


def _drive(page, cube, select_label):
    page.wait_for_selector("#nf-readout", timeout=60_000)
    var, value = _wait_for(page, "tip_force_max")
    at70 = {**DESIGN, "length": 70e-3}
    assert value == pytest.approx(_expected(cube, "tip_force_max", at70), rel=5e-4)
    _move_length_up(page)
    var, value = _readout(page)
    assert value == pytest.approx(_expected(cube, "tip_force_max", DESIGN), rel=5e-4)
    page.locator("select").first.select_option(label=select_label)
    var, value = _wait_for(page, "bend_angle_max")
    assert value == pytest.approx(_expected(cube, "bend_angle_max", DESIGN), rel=5e-4)
    assert "length 90 mm" in page.locator("#nf-readout").inner_text()
    # the read-out says the design's validity by flag name (issue 25); the cube's value
    bits = _expected(cube, "validity", DESIGN)
    shown = page.locator("#nf-validity")
    assert float(shown.get_attribute("data-value")) == bits
    assert ("valid" if bits == 0 else "self contact") in shown.inner_text()
    # "copy as config": the selected design's grid values, as a sweep config takes them
    import re

    config = page.locator("#nf-config").text_content()
    assert re.search(r"length:\s+values: \[90(\.0)?\]", config), config


@contextlib.contextmanager
def _serve_page(cube, browser):
    """Serve the cube on a free loopback port; yield a page showing it."""
    port = _free_port()
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH",
                                                                               ""))
    proc = subprocess.Popen([sys.executable, "-m", "nylonflex", "explore", str(cube),
                             "--port", str(port), "--no-browser"], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        page = browser.new_page(viewport={"width": 1300, "height": 1000})
        end = time.monotonic() + 60
        while True:
            try:
                page.goto(f"http://127.0.0.1:{port}/")
                break
            except sync_api.Error:
                if proc.poll() is not None or time.monotonic() > end:
                    raise AssertionError(proc.stdout.read())
                time.sleep(0.3)
        yield page
    finally:
        proc.terminate()
        proc.wait(timeout=10)


def test_served_page_follows_slider_and_variable(cube, browser, tmp_path):
    with _serve_page(cube, browser) as page:
        _drive(page, cube, "maximum bend angle [deg]")
        page.screenshot(path=str(tmp_path / "served.png"), full_page=True)


def test_served_map_click_picks_the_nearest_grid_point(cube, browser):
    with _serve_page(cube, browser) as page:
        page.wait_for_selector("#nf-readout", timeout=60_000)
        _click_map_and_check(page, cube)


def _click_map_and_check(page, cube):
    import re

    box = page.locator("canvas").first.bounding_box()  # the design map comes first
    page.mouse.click(box["x"] + 0.3 * box["width"], box["y"] + 0.45 * box["height"])
    page.wait_for_selector(".nf-snap", timeout=20_000)
    text = page.locator("#nf-readout").inner_text()
    assert "between grid points" in text and "no values between grid points" in text
    m = re.search(r"design: radius ([\d.]+) mm, wall_thickness ([\d.]+) mm", text)
    at = {**DESIGN, "length": 70e-3, "radius": float(m[1]) * 1e-3,
          "wall_thickness": float(m[2]) * 1e-3}
    assert (float(m[1]), float(m[2])) != (7.5, 2.0)
    assert _readout(page)[1] == pytest.approx(_expected(cube, "tip_force_max", at), rel=5e-4)


def test_exported_file_works_offline(cube, browser, tmp_path):
    out = tmp_path / "fig12.html"
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH",
                                                                               ""))
    subprocess.run([sys.executable, "-m", "nylonflex", "explore", str(cube), "--html",
                    str(out)], env=env, check=True, capture_output=True)
    context = browser.new_context(offline=True, viewport={"width": 1300, "height": 1000})
    page = context.new_page()
    requests = []
    page.on("request", lambda r: requests.append(r.url))
    page.goto(out.as_uri())
    _drive(page, cube, "maximum bend angle [deg]")
    page.screenshot(path=str(tmp_path / "exported.png"), full_page=True)
    assert [u for u in requests if not u.startswith(("file:", "data:", "blob:"))] == []
    context.close()


def test_exported_map_click_picks_the_nearest_grid_point(cube, browser, tmp_path):
    out = tmp_path / "fig12.html"
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH",
                                                                               ""))
    subprocess.run([sys.executable, "-m", "nylonflex", "explore", str(cube), "--html",
                    str(out)], env=env, check=True, capture_output=True)
    page = browser.new_page(viewport={"width": 1300, "height": 1000})
    page.goto(out.as_uri())
    page.wait_for_selector("#nf-readout")
    _click_map_and_check(page, cube)


# ---------------------------------------------------------------------------- issue 25
# Every view of the selected design is drawn from one state: after each of 20 rapid map
# clicks, slider drags and bursts of key presses, the read-out, the map's marker and every
# curve show the same design, and each shows the cube's own numbers for it (ds.isel, read
# here, not by the page). A key press is never lost: a burst of k presses moves a slider k
# grid steps (up to its end).
_SNAPSHOT = """() => {
  const doc = Bokeh.documents[0], get = (n) => doc.get_model_by_name(n);
  const out = {readout: get("nf-readout").text, star: get("nf-star").data, curves: {},
               sliders: {}};
  for (const n of ["nylon_force", "bend_angle", "tip_force"]) {
    const m = get("nf-curve-" + n);
    if (m) out.curves[n] = {y: Array.from(m.data.y), design: Array.from(m.data.design)};
  }
  for (const a of AXES) out.sliders[a] = get("nf-slider-" + a).value;
  out.star = {x: Array.from(out.star.x), y: Array.from(out.star.y),
              design: Array.from(out.star.design)};
  return out;
}"""
AXES_JS = "const AXES = ['radius', 'wall_thickness', 'length', 'coil_index', 'wrap_angle'];"


def _snapshot(page):
    return page.evaluate("() => { " + AXES_JS + " return (" + _SNAPSHOT + ")(); }")


def _check_one_design(ds, snap, variable="tip_force_max"):
    """The views of one snapshot agree with each other and with the cube."""
    import re

    import numpy as np

    from nylonflex.explore import validity_names
    from nylonflex.variables import AXES, to_display

    design = re.search(r'data-design="([\d,]+)"', snap["readout"])[1]
    ix = dict(zip(AXES, map(int, design.split(","))))
    assert ix == {a: round(v) for a, v in snap["sliders"].items()}, (ix, snap["sliders"])
    assert snap["star"]["design"] == [design], (design, snap["star"])
    point = ds.isel(ix)
    assert snap["star"]["x"][0] == pytest.approx(float(point["radius"]) * 1e3, rel=1e-6)
    assert snap["star"]["y"][0] == pytest.approx(float(point["wall_thickness"]) * 1e3,
                                                 rel=1e-6)
    for name, curve in snap["curves"].items():
        assert set(curve["design"]) == {design}, name
        want = to_display(name, point[name].values.astype(float))
        np.testing.assert_allclose(curve["y"], want, rtol=1e-6, err_msg=name)
    value = float(re.search(r'data-value="([^"]+)"', snap["readout"])[1])
    assert value == pytest.approx(float(to_display(variable, float(point[variable]))),
                                  rel=1e-6)
    bits = float(point["validity"])
    assert f'id="nf-validity" data-value="{bits:g}"' in snap["readout"]
    assert f"validity: <b>{validity_names(ds, bits)}</b>" in snap["readout"]
    return ix


def _rapid(page, cube):
    """20 actions as fast as the browser takes them, each checked at once."""
    import random

    from nylonflex.storage import open_cube

    page.wait_for_selector("#nf-readout", timeout=60_000)
    rng = random.Random(25)
    handles = page.locator(".noUi-handle")
    box = page.locator("canvas").first.bounding_box()
    with open_cube(cube) as ds:
        ix = _check_one_design(ds, _snapshot(page))
        for k in range(20):
            kind = k % 3
            if kind == 0:  # a click somewhere on the map
                page.mouse.click(box["x"] + rng.uniform(0.1, 0.8) * box["width"],
                                 box["y"] + rng.uniform(0.1, 0.85) * box["height"])
                ix = _check_one_design(ds, _snapshot(page))
            elif kind == 1:  # a burst of key presses on one slider, none lost
                j = rng.randrange(5)
                axis = list(ix)[j]
                key, step = rng.choice((("ArrowRight", 1), ("ArrowLeft", -1)))
                presses = rng.randint(2, 4)
                handles.nth(j).focus()
                for _ in range(presses):
                    page.keyboard.press(key)
                new = _check_one_design(ds, _snapshot(page))
                end = ds.sizes[axis] - 1
                assert new[axis] == min(end, max(0, ix[axis] + step * presses)), \
                    (axis, key, presses, ix[axis], new[axis])
                ix = new
            else:  # a drag of a slider's handle to somewhere along its track
                j = rng.randrange(5)
                h = handles.nth(j).bounding_box()
                track = page.locator(".noUi-target").nth(j).bounding_box()
                page.mouse.move(h["x"] + h["width"] / 2, h["y"] + h["height"] / 2)
                page.mouse.down()
                page.mouse.move(track["x"] + rng.uniform(0, 1) * track["width"],
                                h["y"] + h["height"] / 2, steps=4)
                page.mouse.up()
                ix = _check_one_design(ds, _snapshot(page))


def test_served_page_every_view_shows_one_design(cube, browser, tmp_path):
    with _serve_page(cube, browser) as page:
        _rapid(page, cube)
        page.screenshot(path=str(tmp_path / "served_rapid.png"), full_page=True)


def test_offline_file_every_view_shows_one_design(cube, browser, tmp_path):
    out = tmp_path / "fig12.html"
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH",
                                                                               ""))
    subprocess.run([sys.executable, "-m", "nylonflex", "explore", str(cube), "--html",
                    str(out)], env=env, check=True, capture_output=True)
    context = browser.new_context(offline=True, viewport={"width": 1300, "height": 1000})
    page = context.new_page()
    page.goto(out.as_uri())
    _rapid(page, cube)
    context.close()


def test_where_table_sorts_and_picks_a_design(cube, browser, tmp_path):
    # explore --where: the matching designs in a table; a column's title sorts it, a row
    # picks its design for every view
    out = tmp_path / "where.html"
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH",
                                                                               ""))
    subprocess.run([sys.executable, "-m", "nylonflex", "explore", str(cube), "--html",
                    str(out), "--where", "tip_force_max >= 0.5 N", "--where",
                    "wall_thickness >= 4 mm"], env=env, check=True, capture_output=True)
    page = browser.new_page(viewport={"width": 1300, "height": 1000})
    page.goto(out.as_uri())
    page.wait_for_selector("#nf-readout")
    rows = page.evaluate("() => Bokeh.documents[0].get_model_by_name('nf-where-rows')"
                         ".data.tip_force_max")
    assert min(rows) >= 0.5
    page.locator(".slick-header-column", has_text="maximum tip force").click()
    page.locator(".slick-row").first.click()
    from nylonflex.storage import open_cube

    with open_cube(cube) as ds:
        snap = _snapshot(page)
        ix = _check_one_design(ds, snap)
        assert float(ds["wall_thickness"].isel(wall_thickness=ix["wall_thickness"])) >= 4e-3
    value = float(page.locator("#nf-readout").get_attribute("data-value"))
    assert value == pytest.approx(min(rows), rel=1e-6)  # the smallest, first once sorted


# ---------------------------------------------------------------------------- issue 46
def test_first_view_is_a_valid_design_named_right_and_fits_1280_px(cube, browser, tmp_path):
    # the page opened on a self-contacting design (443 deg, flagged) it called the paper's
    # second worked example; its fixed 1,600 px layout cut the right panels off in a 1,280
    # px window; bokeh logged "could not set initial ranges" 12 times
    from nylonflex.storage import open_cube
    from nylonflex.variables import AXES

    out = tmp_path / "fig12.html"
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH",
                                                                               ""))
    subprocess.run([sys.executable, "-m", "nylonflex", "explore", str(cube), "--html",
                    str(out), "--where", "tip_force_max >= 1 N"], env=env, check=True,
                   capture_output=True)
    page = browser.new_page(viewport={"width": 1280, "height": 900})
    messages = []
    page.on("console", lambda m: messages.append((m.type, m.text)))
    page.on("pageerror", lambda e: messages.append(("error", str(e))))
    page.goto(out.as_uri())
    page.wait_for_selector("#nf-readout", timeout=60_000)
    page.wait_for_timeout(1000)
    # the first view: the paper's second example (7.5/2/70 mm, C 1.7, 8 deg), valid
    snap = _snapshot(page)
    with open_cube(cube) as ds:
        ix = _check_one_design(ds, snap)
        point = ds.isel(ix)
        got = {a: float(point[a]) for a in AXES}
        assert got == pytest.approx({**DESIGN, "length": 70e-3}, rel=1e-9)
        assert float(point["validity"]) == 0
        assert float(point["bend_angle_max"]) * 180 / math.pi < 360
        # the colour scale of the bend map: the valid designs of the slice only
        page.locator("select").first.select_option(label="maximum bend angle [deg]")
        _wait_for(page, "bend_angle_max")
        cells = page.evaluate("() => { const d = Bokeh.documents[0].get_model_by_name("
                              "'nf-map').data; return {z: Array.from(d.z), zc: Array.from("
                              "d.zc.map(v => isFinite(v) ? v : null)), vf: Array.from(d.vf)};"
                              " }")
        high = page.evaluate("() => Bokeh.documents[0].get_model_by_name('nf-map-figure')"
                             ".renderers[0].glyph.fill_color.transform.high")
    flagged = [z for z, vf in zip(cells["z"], cells["vf"]) if vf != "valid"]
    assert flagged and max(flagged) > high  # the flagged designs bend furthest ...
    assert all(zc is None for zc, vf in zip(cells["zc"], cells["vf"]) if vf != "valid")
    assert high == pytest.approx(max(z for z, vf in zip(cells["z"], cells["vf"])
                                     if vf == "valid"), rel=1e-6)  # ... and set no colour
    opened = page.locator("#nf-opened")
    assert "the paper's second worked example" in opened.inner_text()
    assert "a 7.5 mm, t 2 mm, L 70 mm, C 1.7" in opened.inner_text()
    assert opened.get_attribute("data-design") == ",".join(str(ix[a]) for a in AXES)
    # fits 1,280 px: no horizontal overflow, every panel inside the window
    assert page.evaluate("document.documentElement.scrollWidth") <= 1280
    for name in ("nf-map-figure", "nf-lines-figure"):
        box = page.evaluate(_BOX, name)
        assert box is not None and box[0] >= 0 and box[1] <= 1280, (name, box)
    for canvas in page.locator("canvas").all():
        b = canvas.bounding_box()
        assert b["x"] >= 0 and b["x"] + b["width"] <= 1280 + 0.5, b
    # the table headers: every title whole
    for header in page.locator(".slick-header-column").all():
        name = header.locator(".slick-column-name")
        assert name.evaluate("e => e.scrollWidth <= e.clientWidth + 1"), name.inner_text()
    page.screenshot(path=str(tmp_path / "first_view_1280.png"), full_page=True)
    bad = [m for m in messages if m[0] in ("error", "warning")]
    assert bad == [], bad


_BOX = """(n) => {
  function walk(view) {
    if (view.model && view.model.name == n) { const r = view.el.getBoundingClientRect();
                                               return [r.left, r.right]; }
    for (const c of (view.child_views || [])) { const f = walk(c); if (f) return f; }
    return null;
  }
  for (const v of Bokeh.index.values ? Bokeh.index.values() : Object.values(Bokeh.index)) {
    const f = walk(v); if (f) return f;
  }
  return null;
}"""
