"use strict";
// Speed against error: the plots of each `lvox sweep` (error against wall time and
// against medium evaluations), its points' thumbnails, and Monte Carlo convergence curves.

// Values below these floors are drawn at the floor, as in sweep.png: an error of 0 (an
// image identical to the reference) has no place on a log axis.
const floors = { seconds: 1e-3, medium_evals: 1, delta_percent: 1e-4, spp: 1 };

function plotValue(row, key) {
  const v = Number(row[key]);
  return Number.isFinite(v) ? Math.max(v, floors[key]) : NaN;
}

// The rule of `lvox sweep`: a row is on the front when no other row is at most as costly
// and as wrong, and strictly better in one of the two.
function paretoFlags(rows, cost) {
  return rows.map((r) => !rows.some((o) => o !== r &&
    cost(o) <= cost(r) && o.delta_percent <= r.delta_percent &&
    (cost(o) < cost(r) || o.delta_percent < r.delta_percent)));
}

function pointTip(r, front) {
  return [
    `${r.method}  ${r.parameter} = ${formatValue(r.value)}`,
    `time ${formatValue(r.seconds)} s`,
    `evaluations ${formatShort(r.medium_evals)}`,
    `delta ${formatValue(r.delta_percent)} %`,
    ...(front ? ["on the Pareto front"] : []),
  ];
}

function methodSeries(rows, key, flags) {
  const methods = [...new Set(rows.map((r) => r.method))].sort();
  return methods.map((m, i) => ({
    name: m,
    colour: m === "auto" ? "#000000" : curveColours[i % curveColours.length],
    bold: m === "auto" || m === "mc",
    points: rows.flatMap((r, j) => {
      const x = plotValue(r, key), y = plotValue(r, "delta_percent");
      if (r.method !== m || !Number.isFinite(x) || !Number.isFinite(y)) return [];
      return [{ x, y, front: flags[j], tip: pointTip(r, flags[j]) }];
    }),
  }));
}

function sweepTable(sweep) {
  const columns = sweep.columns;
  return el("details", {},
    el("summary", {}, `all ${sweep.rows.length} points`),
    el("table", { class: "data" },
      el("tr", {}, ...columns.map((c) => el("th", {}, c))),
      ...sweep.rows.map((r) => el("tr", {}, ...columns.map((c) => el("td", {}, formatShort(r[c])))))));
}

function renderSweep(sweep) {
  const rows = sweep.rows;
  const byTime = paretoFlags(rows, (r) => r.seconds);
  const byEvals = paretoFlags(rows, (r) => r.medium_evals);
  const timeSeries = methodSeries(rows, "seconds", byTime);
  const box = el("div", { class: "sweep" }, el("h3", {}, sweep.name));
  box.append(el("div", { class: "plots" },
    logPlot({ title: "error against time", xLabel: "wall time (s)", yLabel: "delta vs reference (%)", series: timeSeries }),
    logPlot({ title: "error against evaluations", xLabel: "medium evaluations", yLabel: "delta vs reference (%)",
      series: methodSeries(rows, "medium_evals", byEvals) })));
  box.append(legend(timeSeries));
  box.append(el("p", { class: "caption" },
    "Circled points are on the Pareto front (dashed): nothing else is both cheaper and more accurate. " +
    "auto is drawn in black. Hover a point for its method, parameter, time, evaluations and error."));
  if (sweep.thumbs) box.append(thumbnailGrid(sweep));
  box.append(sweepTable(sweep));
  return box;
}

// A canvas showing HDR planes at the page's exposure, or an error plane in false colour.
function planeCanvas(width, height, fill) {
  const canvas = el("canvas", { width, height, class: "thumb" });
  const draw = () => {
    const ctx = canvas.getContext("2d");
    const data = ctx.createImageData(width, height);
    fill(data);
    ctx.putImageData(data, 0, 0);
  };
  draw();
  display.listeners.push(draw);
  return canvas;
}

function rgbThumb(t, planes) {
  const [r, g, b] = planes.map(decodeFloats);
  return planeCanvas(t.width, t.height, (d) => toneMapInto(d, r, g, b));
}

function errorThumb(t, plane) {
  const e = decodeFloats(plane);
  return planeCanvas(t.width, t.height, (d) => errorColoursInto(d, e));
}

function thumbnailGrid(sweep) {
  const t = sweep.thumbs;
  const grid = el("div", { class: "thumbs" });
  if (t.reference) grid.append(el("figure", {}, rgbThumb(t, t.reference.rgb), el("figcaption", {}, "reference")));
  sweep.rows.forEach((r, i) => {
    const p = t.points[i];
    if (!p) return;
    const pictures = [rgbThumb(t, p.rgb)];
    if (p.error) pictures.push(errorThumb(t, p.error));
    grid.append(el("figure", {}, ...pictures,
      el("figcaption", {}, `${r.method} ${r.parameter}=${formatValue(r.value)}: ${formatShort(r.delta_percent)} %, ${formatShort(r.seconds)} s`)));
  });
  return el("div", {}, el("h4", {}, `every point's image and error map (${t.width}x${t.height} thumbnails; exposure and error scale as in the viewer)`), grid);
}

function renderConvergence(curves) {
  const series = (key) => curves.map((c, i) => ({
    name: c.name,
    colour: curveColours[i % curveColours.length],
    bold: false,
    points: c.rows.flatMap((r) => {
      const x = plotValue(r, key), y = plotValue(r, "delta_percent");
      if (!Number.isFinite(x) || !Number.isFinite(y)) return [];
      return [{ x, y, front: false, tip: [c.name, `${formatShort(r.spp)} spp`, `time ${formatValue(r.seconds)} s`, `delta ${formatValue(r.delta_percent)} %`] }];
    }),
  }));
  const bySeconds = series("seconds");
  return el("div", { class: "sweep convergence" },
    el("h3", {}, "Monte Carlo convergence"),
    el("div", { class: "plots" },
      logPlot({ title: "error against time", xLabel: "wall time (s)", yLabel: "delta vs reference (%)", series: bySeconds }),
      logPlot({ title: "error against samples", xLabel: "samples per pixel", yLabel: "delta vs reference (%)", series: series("spp") })),
    legend(bySeconds));
}

function renderSpeedSection(data) {
  if (!data.sweeps.length && !data.convergence.length) return;
  document.getElementById("speed").hidden = false;
  const box = document.getElementById("sweeps");
  for (const s of data.sweeps) box.append(renderSweep(s));
  if (data.convergence.length) document.getElementById("convergence").append(renderConvergence(data.convergence));
}
