// nylonflex explore: draw every view of the page from one state (nylonflex/explore/page.py).
//
// The state is read once, at the top, from the widgets: the variable, the model, the map's
// two axes and one grid index per axis. Every view below (map and its marker, figure 12
// lines, the three curves, the read-out and the design table) is drawn from `st` alone, in
// one synchronous pass, so no view can show another design than the read-out. The served
// page and the offline file run this same code; nothing is computed on a server.
if (hold.tags.length) return;  // pick.js sets several widgets, then draws once
const N = sizes;
const nd = N[0] * N[1] * N[2] * N[3] * N[4];
const st = {v: Number(variable.value), m: model ? model.active : 0,
            x: map_x.value, y: map_y.value, ix: {}};
for (const k of AXES) st.ix[k] = Math.max(0, Math.min(N[AXES.indexOf(k)] - 1,
                                                      Math.round(sliders[k].value)));
const off = st.m * nd;
function flat(ix) {
  let i = 0;
  for (let j = 0; j < AXES.length; j++) i = i * N[j] + ix[AXES[j]];
  return i + off;
}
function flagtext(bits) {
  if (!isFinite(bits)) return "unknown";
  const on = flags.filter(f => (bits & f[0]) != 0).map(f => f[1]);
  return on.length ? on.join(", ") : "valid";
}
const arr = data[st.v];
const sel = flat(st.ix);
const mname = model ? ", model " + model.labels[st.m] : "";
const held = (ks) => ks.map(k => names[k] + " = " + labels[k][st.ix[k]]).join(", ");

// ---- the map: st.v over axes st.x (across) and st.y (up), the others held
const X = st.x, Y = st.y, nx = N[AXES.indexOf(X)], ny = N[AXES.indexOf(Y)];
const cols = {left: [], right: [], bottom: [], top: [], z: [], h: [], lc: [], fa: [], vf: [],
              xv: [], yv: []};
const mx = [], my = [];
let lo = Infinity, hi = -Infinity, alo = Infinity, ahi = -Infinity;
if (X != Y) {
  const ix = Object.assign({}, st.ix);
  for (let b = 0; b < ny; b++) for (let a = 0; a < nx; a++) {
    ix[X] = a; ix[Y] = b;
    const i = flat(ix), z = arr[i];
    const bad = validity && validity[i] != 0;
    cols.left.push(edges[X][a]); cols.right.push(edges[X][a + 1]);
    cols.bottom.push(edges[Y][b]); cols.top.push(edges[Y][b + 1]);
    cols.xv.push(gx[X][a]); cols.yv.push(gx[Y][b]);
    cols.z.push(z);
    if (isFinite(z)) {
      alo = Math.min(alo, z); ahi = Math.max(ahi, z);
      if (!bad) { lo = Math.min(lo, z); hi = Math.max(hi, z); }
    }
    cols.h.push(limit && limit[i] == 1 ? "x" : " ");
    cols.lc.push(bad ? "#D55E00" : null);
    cols.fa.push(bad ? 0.35 : 1.0);
    cols.vf.push(flagtext(validity ? validity[i] : 0));
    if (match && match[i]) { mx.push(gx[X][a]); my.push(gx[Y][b]); }
  }
}
// the colour scale: clean designs only (flagged ones, drawn faded, do not set it)
if (!isFinite(lo)) { lo = alo; hi = ahi; }
if (!isFinite(lo)) { lo = 0; hi = 1; }
if (!(hi > lo)) { hi = lo + 1; }
mapper.low = lo; mapper.high = hi;
map_src.data = cols;
match_src.data = {x: mx, y: my};
colorbar.title = vlabels[st.v];
hover.tooltips = [[vlabels[st.v], "@z{0.000}"], [alabels[X], "@xv"], [alabels[Y], "@yv"],
                  ["validity", "@vf"]];
if (X != Y) {
  map_fig.x_range.start = edges[X][0]; map_fig.x_range.end = edges[X][nx];
  map_fig.y_range.start = edges[Y][0]; map_fig.y_range.end = edges[Y][ny];
  map_xaxis.axis_label = alabels[X]; map_yaxis.axis_label = alabels[Y];
  star.data = {x: [gx[X][st.ix[X]]], y: [gx[Y][st.ix[Y]]],
               design: [AXES.map(k => st.ix[k]).join(",")]};
  map_fig.title.text = vshort[st.v] + " at " + held(AXES.filter(k => k != X && k != Y)) + mname;
} else {
  star.data = {x: [], y: [], design: []};
  map_fig.title.text = "choose two different axes for the map (both are " + X + ")";
}

// ---- figure 12 style lines: st.v against radius, one line per coil index
const R = AXES.indexOf("radius"), C = AXES.indexOf("coil_index");
for (let c = 0; c < N[C]; c++) {
  const all = [], solid = [];
  const ix = Object.assign({}, st.ix);
  ix.coil_index = c;
  for (let r = 0; r < N[R]; r++) {
    ix.radius = r;
    const i = flat(ix);
    all.push(arr[i]); solid.push(limit && limit[i] == 1 ? NaN : arr[i]);
  }
  line_srcs[c].data = {x: gx.radius, y: all};
  solid_srcs[c].data = {x: gx.radius, y: solid};
}
lines_fig.title.text = "Figure 12 style at " +
  held(["wall_thickness", "length", "wrap_angle"]) + mname;
lines_yaxis.axis_label = vlabels[st.v];

// ---- the curves of the selected design; each source names the design it shows
const design = AXES.map(k => st.ix[k]).join(",") + (model ? "," + st.m : "");
for (const name in curve_srcs) {
  const c = curves[name], dims = c.dims, P = c.n;
  let i = 0;
  for (const d of dims) i = i * (d == "model" ? (model ? model.labels.length : 1) : N[AXES.indexOf(d)]) +
    (d == "model" ? st.m : st.ix[d]);
  const y = [];
  for (let p = 0; p < P; p++) y.push(c.values[i * P + p]);
  curve_srcs[name].data = {x: c.x, y: y, design: y.map(() => design)};
}
if (flim_span) flim_span.location = flim[st.ix.coil_index];

// ---- the read-out and the table of every design variable
const fmt = (v) => isFinite(v) ? Number(v.toPrecision(4)).toString() : "nan";
const v = arr[sel];
const bits = validity ? validity[sel] : 0;
let text = '<div id="nf-readout" class="nf-readout" data-variable="' + vnames[st.v] +
  '" data-value="' + v + '" data-unit="' + vunits[st.v] + '" data-design="' + design +
  '" style="font-size:15px">' + vshort[st.v] + ' of the selected design: <b>' + fmt(v) +
  (vunits[st.v] == "1" ? "" : " " + vunits[st.v]) + '</b><br><span style="color:#555">design: ' +
  AXES.map(k => k + " " + labels[k][st.ix[k]]).join(", ") + mname + '</span>' +
  '<br><span id="nf-validity" data-value="' + bits + '">validity: <b>' + flagtext(bits) +
  '</b></span>';
// a model spread: the shown variable's range over the variants (explore/model_spread.py)
const band = bands[st.v];
if (band) {
  const blo = data[band[0]][sel], bhi = data[band[1]][sel];
  text += '<br><span id="nf-spread" data-lo="' + blo + '" data-hi="' + bhi + '">models: <b>' +
    fmt(blo) + ' .. ' + fmt(bhi) + (vunits[st.v] == "1" ? "" : " " + vunits[st.v]) +
    '</b> <span style="color:#555">(' + spreadnote + ')</span></span>';
}
if (vany) text += '<br><span id="nf-validity-any" data-value="' + vany[sel] +
  '">validity of any model: <b>' + flagtext(vany[sel]) + '</b></span>';
// a map pick's note belongs to the design it picked (a later move makes it stale)
if (note.tags.length == 2 && note.tags[1] == design) {
  text += '<br><span class="nf-snap" style="color:#a0522d">' + note.tags[0] + '</span>';
}
if (config) {
  let yaml = config;
  for (const k of AXES) yaml = yaml.replace("'@" + k + "@'", cfgvals[k][st.ix[k]]);
  text += '<details style="font-size:12px"><summary>copy as config (a sweep of this design)' +
    '</summary><pre id="nf-config">' + yaml + '</pre></details>';
}
readout.text = text + '</div>';
let rows = '';
for (let j = 0; j < vnames.length; j++) {
  const x = data[j][sel];
  rows += '<tr data-name="' + vnames[j] + '" data-value="' + x + '"><td>' + vlabels[j] +
    '</td><td style="text-align:right"><b>' + fmt(x) + '</b></td></tr>';
}
table.text = '<table id="nf-design" data-design="' + design +
  '" style="border-collapse:collapse;font-size:13px">' +
  '<tr><th style="text-align:left">every design variable of the selected design</th>' +
  '<th>value</th></tr>' + rows + '</table>' +
  '<div style="font-size:12px;color:#555">limit: 0 stroke-limited (full range of motion), ' +
  '1 strength-limited (the nylon breaks first)</div>';
