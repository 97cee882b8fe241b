// nylonflex explore: a click on the map, or a row of the matching-designs table, picks a
// design by setting the sliders (and the model); update.js then draws every view from them.
const i = cb_obj.indices;
if (!i.length) return;
const k = i[0];
const ix = {};
for (const a of AXES) ix[a] = Math.round(sliders[a].value);
let m = model ? model.active : 0;
let text = "";
if (rows === null) {  // the map: cell k of the axes the map shows
  const X = map_x.value, Y = map_y.value, nx = sizes[AXES.indexOf(X)];
  if (X == Y) return;
  ix[X] = k % nx; ix[Y] = Math.floor(k / nx);
  text = "picked on the map: the cell of grid point " + X + " " + labels[X][ix[X]] + ", " + Y +
    " " + labels[Y][ix[Y]] + " (the cube holds no values between grid points)";
} else {              // a row of the table (its index in the source, whatever the sort)
  for (const a of AXES) ix[a] = rows.data["i_" + a][k];
  if (model) m = rows.data.i_model[k];
}
const design = AXES.map(a => ix[a]).join(",") + (model ? "," + m : "");
note.tags = text ? [text, design] : [];
// one redraw for the whole pick: update.js runs on the last change only
hold.tags = ["picking"];
for (const a of AXES) sliders[a].value = ix[a];
if (model) model.active = m;
hold.tags = [];
cb_obj.indices = [];
update.execute(hold);
