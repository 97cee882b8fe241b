"""Flagged designs never look best (issue 46): on every chart family a design with a
validity flag (docs/model.md s. 17: self contact, stretch beyond the fit, ...) is greyed or
hatched, never drawn in a colour of the scale; scales are set by valid designs of the whole
cube; coil colours do not change with ``--coil-index``; a chart of an incomplete cube says
so. The cubes are small versions of configs/fig12.yaml and configs/fig12_tracking.yaml."""

from pathlib import Path

import numpy as np
import pytest
import yaml
from helpers import write_cube

from nylonflex import charts
from nylonflex.storage import open_cube
from nylonflex.variables import to_display

CONFIGS = Path(__file__).resolve().parents[1] / "configs"
#: a small fig12 cube: thin walls (1 mm) self-contact at C 1.7 (docs/model.md s. 17)
SMALL_GRID = {"radius": {"start": 5, "stop": 25, "num": 9, "units": "mm"},
              "wall_thickness": {"values": [1, 2, 4, 6], "units": "mm"},
              "length": {"values": [70, 90], "units": "mm"},
              "coil_index": {"values": [1.1, 1.7]},
              "wrap_angle": {"values": [8, 20], "units": "deg"}}


def _small(name, **extra):
    raw = yaml.safe_load((CONFIGS / name).read_text())
    raw["grid"] = dict(SMALL_GRID)
    raw["curves"]["stroke"]["num"] = 11
    raw["curves"]["pressure"]["num"] = 11
    raw.pop("charts", None)
    raw.update(extra)
    return raw


@pytest.fixture(scope="module")
def ds(tmp_path_factory):
    raw = _small("fig12.yaml", requirements=["bend_angle_max >= 30 deg",
                                             "range_fraction >= 1"])
    cube = write_cube(tmp_path_factory.mktemp("flagged"), raw)
    ds = open_cube(cube)
    assert int((ds["validity"] != 0).sum()) > 10  # the cube has flagged designs
    yield ds
    ds.close()


@pytest.fixture(scope="module")
def tracked(tmp_path_factory):
    """The tracking cube of configs/fig12_tracking.yaml, small and short."""
    raw = _small("fig12_tracking.yaml")
    raw["grid"].update({"radius": {"start": 5, "stop": 25, "num": 5, "units": "mm"},
                        "wall_thickness": {"values": [1, 2, 4], "units": "mm"},
                        "length": {"values": [90], "units": "mm"},
                        "wrap_angle": {"values": [8], "units": "deg"}})
    raw["tracking"].update({"duration": "30 s", "rms_from": "5 s"})
    cube = write_cube(tmp_path_factory.mktemp("tracked"), raw)
    ds = open_cube(cube)
    yield ds
    ds.close()


def _pixels(fig):
    """The figure drawn: an (h, w, 3) RGB array in [0, 1]."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    return np.asarray(canvas.buffer_rgba())[..., :3] / 255.0, canvas


def _colour_at(fig, rgb, ax, x, y):
    """The median RGB of a 5 x 5 pixel patch at data point (x, y) of ``ax``."""
    px, py = ax.transData.transform((x, y))
    h = rgb.shape[0]
    r, c = int(round(h - py)), int(round(px))
    return np.median(rgb[r - 2:r + 3, c - 2:c + 3].reshape(-1, 3), axis=0)


def _saturation(rgb):
    return float(np.max(rgb) - np.min(rgb))


def _inward(values, i):
    """Grid value ``i`` moved a quarter cell towards the middle of the axis: inside its
    own cell and inside the axes, clear of contour lines through the grid point."""
    if len(values) < 2:
        return values[i]
    j = i + 1 if i < len(values) // 2 else i - 1
    return values[i] + 0.25 * (values[j] - values[i])


def _check_map(fig, ds, cut_validity, axes, xname="radius", yname="wall_thickness"):
    """Every flagged cell of each panel is grey (unsaturated) in the image; returns the
    counts of grey flagged cells and of coloured clean ones (so the check can fail)."""
    rgb, _ = _pixels(fig)
    xs = to_display(xname, ds[xname].values)
    ys = to_display(yname, ds[yname].values)
    grey, coloured = 0, 0
    for ax, v in zip(axes, cut_validity):
        for j in range(len(ys)):
            for i in range(len(xs)):
                s = _saturation(_colour_at(fig, rgb, ax, _inward(xs, i), _inward(ys, j)))
                if v[j, i] != 0:
                    assert s < 0.12, (ax.get_title(), xs[i], ys[j], s)
                    grey += 1
                else:
                    coloured += s > 0.12
    return grey, coloured


def _legend_texts(fig):
    texts = []
    for leg in [*fig.legends, *(ax.get_legend() for ax in fig.axes)]:
        if leg is not None:
            texts += [t.get_text() for t in leg.get_texts()]
    return " ".join(texts)


def test_design_map_greys_flagged_cells_and_scales_from_valid_designs(ds):
    fig = charts.design_map(ds, length=90e-3, wrap_angle=np.radians(8))
    cut = ds["validity"].sel(length=90e-3, wrap_angle=np.radians(8))
    panels = [ax for ax in fig.axes if ax.get_title().startswith("C =")]
    vs = [cut.sel(coil_index=c).transpose("wall_thickness", "radius").values
          for c in ds["coil_index"].values]
    grey, coloured = _check_map(fig, ds, vs, panels)
    assert grey > 0 and coloured > 0
    assert "flagged design" in _legend_texts(fig)
    # the colour scale: the largest valid tip force of the whole cube, not a flagged one
    top = float(to_display("tip_force_max", ds["tip_force_max"]
                           .where(ds["validity"] == 0).max()))
    cbar = [ax for ax in fig.axes if "tip force" in ax.get_ylabel() and not
            ax.get_title()][0]
    assert cbar.get_ylim()[1] >= top and cbar.get_ylim()[1] < top * 1.5


def test_design_map_scale_and_coil_colours_do_not_change_with_the_slice(ds):
    whole = charts.design_map(ds)
    one = charts.design_map(ds, coil_index=[1.7])
    lims = [[ax.get_ylim() for ax in f.axes if "tip force" in ax.get_ylabel()
             and not ax.get_title()][0] for f in (whole, one)]
    assert lims[0] == lims[1]
    all_b = charts.fig12b(ds)
    one_b = charts.fig12b(ds, coil_index=[1.7])

    def colour_of(fig, text):
        leg = fig.legends[0]
        for handle, t in zip(leg.legend_handles, leg.get_texts()):
            if t.get_text() == text:
                return handle.get_color()

    assert colour_of(all_b, "C = 1.7") == colour_of(one_b, "C = 1.7")


def test_feasibility_map_never_paints_a_flagged_design_green(ds):
    fig = charts.feasibility_map(ds, length=90e-3, wrap_angle=np.radians(8))
    cut = ds["validity"].sel(length=90e-3, wrap_angle=np.radians(8))
    feasible = ds["feasibility"].sel(length=90e-3, wrap_angle=np.radians(8))
    # the self-contacting designs bend 30 deg and more: the nominal check calls them
    # feasible, which a red-green map drew in its greenest green
    assert float(feasible.where(cut != 0).max()) == 1.0
    panels = [ax for ax in fig.axes if ax.get_title().startswith("C =")]
    coils = [float(ax.get_title().split("= ")[1]) for ax in panels]
    vs = [cut.sel(coil_index=c, method="nearest").transpose("wall_thickness", "radius")
          .values for c in coils]
    grey, _ = _check_map(fig, ds, vs, panels)
    assert grey > 0
    assert "flagged design" in _legend_texts(fig)


def _coloured_lines(ax, colour):
    from matplotlib.colors import to_rgb

    return [ln for ln in ax.lines if ln.get_gid() != "nf-flagged"
            and to_rgb(ln.get_color()) == to_rgb(colour)]


@pytest.mark.parametrize("name", ["fig12b", "fig12c"])
def test_fig12_lines_are_grey_where_the_design_is_flagged(ds, name):
    from nylonflex.charts._common import _coil_colour

    fig = getattr(charts, name)(ds, length=90e-3)
    panels = [ax for ax in fig.axes if ax.get_title().startswith("wall thickness")]
    var = {"fig12b": "torque_max", "fig12c": "bend_angle_max"}[name]
    x = to_display("radius", ds["radius"].values)
    checked = 0
    for ax in panels:
        t = float(ax.get_title().split("= ")[1].split()[0]) * 1e-3
        cut = ds[[var, "validity"]].sel(wall_thickness=t, length=90e-3, method="nearest")
        for c in ds["coil_index"].values:
            values = to_display(var, cut[var].sel(coil_index=c).transpose("wrap_angle",
                                                                         "radius").values)
            valid = cut["validity"].sel(coil_index=c).transpose("wrap_angle",
                                                                "radius").values == 0
            for line in _coloured_lines(ax, _coil_colour(ds, c)):
                y = np.asarray(line.get_ydata(), float)
                for i in np.flatnonzero(np.isfinite(y)):
                    # every coloured point is a valid design's value at that radius
                    hit = np.isclose(values[:, i], y[i], rtol=1e-9) & valid[:, i]
                    assert hit.any(), (c, x[i], y[i])
                    checked += 1
    assert checked > 0
    assert "flagged design" in _legend_texts(fig)
    flagged = [ln for ax in panels for ln in ax.lines if ln.get_gid() == "nf-flagged"]
    assert flagged  # the flagged designs are drawn, grey


def test_fig12c_range_row_is_grey_where_flagged(ds):
    from nylonflex.charts._common import _coil_colour

    fig = charts.fig12c(ds, length=90e-3, wrap_angle=np.radians(8))
    bottoms = [ax for ax in fig.axes if ax.get_title().startswith("range of motion")]
    tops = [ax for ax in fig.axes if ax.get_title().startswith("wall thickness")]
    seen = 0
    for top, ax in zip(tops, bottoms):
        t = float(top.get_title().split("= ")[1].split()[0]) * 1e-3
        for c in ds["coil_index"].values:
            v = ds["validity"].sel(wall_thickness=t, length=90e-3, coil_index=c,
                                   wrap_angle=np.radians(8), method="nearest").values
            for line in _coloured_lines(ax, _coil_colour(ds, c)):
                y = np.asarray(line.get_ydata(), float)
                assert not np.isfinite(y[v != 0]).any()
                seen += int((v != 0).sum())
    assert seen > 0


def test_fig6_marks_bends_past_self_contact(ds):
    fig = charts.fig6(ds, radius=10e-3, wall_thickness=1e-3)
    top = max(float(np.nanmax(ln.get_ydata())) for ax in fig.axes for ln in ax.lines
              if ln.get_gid() != "nf-flagged" and len(ln.get_ydata()) > 1)
    assert top <= 360.0  # no coloured curve past the tip meeting the base
    assert any(ln.get_gid() == "nf-flagged" for ax in fig.axes for ln in ax.lines)
    assert all(ax.get_ylim()[1] <= 450.0 for ax in fig.axes)
    text = " ".join(t.get_text() for ax in fig.axes for t in ax.texts)
    assert "self-contact" in text


def test_tracking_map_greys_the_flagged_designs_it_would_call_best(tracked):
    fig = charts.tracking_map(tracked, coil_index=1.7, length=90e-3,
                              wrap_angle=np.radians(8))
    ax = fig.axes[0]
    fixed = dict(coil_index=1.7, length=90e-3, wrap_angle=np.radians(8))
    v = tracked["validity"].sel(**fixed, method="nearest").transpose("wall_thickness",
                                                                     "radius").values
    err = tracked["tracking_rms_error"].sel(**fixed, method="nearest") \
        .transpose("wall_thickness", "radius").values
    # the loop of a flagged design tracks best: viridis_r would paint it brightest
    assert (v != 0).any() and np.nanmin(err[v != 0]) <= np.nanmin(err[v == 0])
    rgb, _ = _pixels(fig)
    xs = to_display("radius", tracked["radius"].values)
    ys = to_display("wall_thickness", tracked["wall_thickness"].values)
    for j, i in zip(*np.nonzero(v)):
        colour = _colour_at(fig, rgb, ax, _inward(xs, i), _inward(ys, j))
        assert _saturation(colour) < 0.12, (xs[i], ys[j])
    assert "flagged design" in _legend_texts(fig)
    # the scale: the valid designs of the whole cube
    lo = float(to_display("tracking_rms_error", tracked["tracking_rms_error"]
                          .where(tracked["validity"] == 0).min()))
    cbar = fig.axes[-1]
    assert cbar.get_ylim()[0] == pytest.approx(lo)


def test_cycle_rate_lines_and_force_rate_keep_flagged_designs_grey(tracked):
    from nylonflex.charts._common import _coil_colour

    fig = charts.cycle_rate_lines(tracked, wall_thickness=1e-3)
    ax = fig.axes[0]
    v = tracked["validity"].sel(wall_thickness=1e-3, length=90e-3, wrap_angle=np.radians(8),
                                coil_index=1.7, method="nearest").values
    assert (v != 0).any()
    for line in _coloured_lines(ax, _coil_colour(tracked, 1.7)):
        if len(line.get_ydata()) == len(v):
            assert not np.isfinite(np.asarray(line.get_ydata(), float)[v != 0]).any()
    fig = charts.force_rate(tracked)
    ax = fig.axes[0]
    front = [ln for ln in ax.lines if "largest force" in ln.get_label()][0]
    best_valid = float(to_display("tip_force_max", tracked["tip_force_max"]
                                  .where(tracked["validity"] == 0).max()))
    assert float(np.nanmax(front.get_ydata())) == pytest.approx(best_valid)


def test_incomplete_cube_is_marked_on_every_chart(ds, tmp_path):
    import h5py

    src = Path(ds.encoding["source"])
    part = tmp_path / "part.h5"
    part.write_bytes(src.read_bytes())
    with h5py.File(part, "r+") as f:
        f.attrs["complete"] = "false"
        f["slab_done"][5:] = 0
    with pytest.warns(UserWarning, match="incomplete"):
        cut = open_cube(part)
    try:
        for name in ("fig12b", "design_map", "fig6", "feasibility_map"):
            fig = charts.CHARTS[name](cut)
            title = fig.get_suptitle()
            assert title.startswith("incomplete: 5 of 9 slabs"), name
            # and in the image: the title is inside the canvas
            rgb, canvas = _pixels(fig)
            box = fig._suptitle.get_window_extent(canvas.get_renderer())
            assert box.y1 <= rgb.shape[0] + 0.5 and box.x0 >= -0.5, name
        fig = charts.CHARTS["design_map"](ds)
        assert "incomplete" not in fig.get_suptitle()
    finally:
        cut.close()
