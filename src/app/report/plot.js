"use strict";
// Log-log line plots as SVG: one curve per series, points that name themselves on hover,
// and an optional Pareto front (dashed line, circled points).

const plotSize = { width: 560, height: 380, left: 64, right: 16, top: 28, bottom: 48 };

// Decades covering [lo, hi]; a range inside one decade also gets 2 and 5 ticks.
function logTicks(lo, hi) {
  const ticks = [];
  for (let k = Math.floor(Math.log10(lo)); k <= Math.ceil(Math.log10(hi)); ++k) {
    const mantissas = Math.log10(hi / lo) < 1.5 ? [1, 2, 5] : [1];
    for (const m of mantissas) {
      const v = m * Math.pow(10, k);
      if (v >= lo * 0.999 && v <= hi * 1.001) ticks.push(v);
    }
  }
  return ticks;
}

function tickLabel(v) {
  const k = Math.log10(v);
  if (Math.abs(k - Math.round(k)) < 1e-9 && (k > 3 || k < -2)) return "1e" + Math.round(k);
  return formatShort(v);
}

// A log axis mapping [lo, hi] to pixels [a, b], widened to keep every point inside.
function logScale(values, a, b) {
  let lo = Math.min(...values), hi = Math.max(...values);
  if (!(hi > lo)) {
    lo /= 2;
    hi *= 2;
  }
  lo /= 1.25;
  hi *= 1.25;
  const map = (v) => a + ((Math.log10(v) - Math.log10(lo)) / (Math.log10(hi) - Math.log10(lo))) * (b - a);
  return { lo, hi, map };
}

function drawAxes(svg, xs, ys, xLabel, yLabel) {
  const s = plotSize;
  const bottom = s.height - s.bottom, right = s.width - s.right;
  svg.append(svgEl("rect", { x: s.left, y: s.top, width: right - s.left, height: bottom - s.top, class: "frame" }));
  for (const v of logTicks(xs.lo, xs.hi)) {
    const x = xs.map(v);
    svg.append(svgEl("line", { x1: x, x2: x, y1: s.top, y2: bottom, class: "grid" }));
    const t = svgEl("text", { x, y: bottom + 16, class: "tick", "text-anchor": "middle" });
    t.textContent = tickLabel(v);
    svg.append(t);
  }
  for (const v of logTicks(ys.lo, ys.hi)) {
    const y = ys.map(v);
    svg.append(svgEl("line", { x1: s.left, x2: right, y1: y, y2: y, class: "grid" }));
    const t = svgEl("text", { x: s.left - 6, y: y + 4, class: "tick", "text-anchor": "end" });
    t.textContent = tickLabel(v);
    svg.append(t);
  }
  const xl = svgEl("text", { x: (s.left + right) / 2, y: s.height - 10, class: "label", "text-anchor": "middle" });
  xl.textContent = xLabel;
  const yl = svgEl("text", { x: 14, y: (s.top + bottom) / 2, class: "label", "text-anchor": "middle",
    transform: `rotate(-90 14 ${(s.top + bottom) / 2})` });
  yl.textContent = yLabel;
  svg.append(xl, yl);
}

function showTooltip(lines, event) {
  const tip = document.getElementById("tooltip");
  tip.replaceChildren(...lines.map((l) => el("div", {}, l)));
  tip.hidden = false;
  tip.style.left = event.pageX + 14 + "px";
  tip.style.top = event.pageY + 10 + "px";
}

function hideTooltip() {
  document.getElementById("tooltip").hidden = true;
}

// series: [{name, colour, bold, points: [{x, y, tip: [lines], front: bool}]}], drawn in
// order (bold ones last, on top). Returns the <svg>.
function logPlot({ title, xLabel, yLabel, series }) {
  const s = plotSize;
  const svg = svgEl("svg", { viewBox: `0 0 ${s.width} ${s.height}`, width: s.width, height: s.height, class: "plot" });
  const all = series.flatMap((c) => c.points);
  if (!all.length) return el("p", { class: "caption" }, `${title}: no point with a finite value`);
  const xs = logScale(all.map((p) => p.x), s.left, s.width - s.right);
  const ys = logScale(all.map((p) => p.y), s.height - s.bottom, s.top);
  const heading = svgEl("text", { x: s.left, y: 18, class: "title" });
  heading.textContent = title;
  svg.append(heading);
  drawAxes(svg, xs, ys, xLabel, yLabel);
  const front = all.filter((p) => p.front).sort((p, q) => p.x - q.x || p.y - q.y);
  if (front.length) {
    const d = front.map((p, i) => `${i ? "L" : "M"}${xs.map(p.x).toFixed(1)},${ys.map(p.y).toFixed(1)}`).join("");
    svg.append(svgEl("path", { d, class: "front" }));
  }
  const ordered = [...series].sort((a, b) => Number(a.bold) - Number(b.bold));
  for (const c of ordered) drawSeries(svg, c, xs, ys);
  return svg;
}

function drawSeries(svg, c, xs, ys) {
  const g = svgEl("g", { class: "series" + (c.bold ? " bold" : ""), "data-name": c.name });
  const pts = [...c.points].sort((p, q) => p.x - q.x);
  g.append(svgEl("polyline", {
    points: pts.map((p) => `${xs.map(p.x).toFixed(1)},${ys.map(p.y).toFixed(1)}`).join(" "),
    stroke: c.colour, class: "curve",
  }));
  for (const p of pts) {
    const cx = xs.map(p.x).toFixed(1), cy = ys.map(p.y).toFixed(1);
    if (p.front) g.append(svgEl("circle", { cx, cy, r: c.bold ? 9 : 8, class: "front-mark" }));
    const dot = svgEl("circle", { cx, cy, r: c.bold ? 5 : 4, fill: c.colour, class: "point" });
    dot.addEventListener("mouseenter", (e) => showTooltip(p.tip, e));
    dot.addEventListener("mouseleave", hideTooltip);
    g.append(dot);
  }
  svg.append(g);
}

// A legend: one swatch per series.
function legend(series) {
  return el("div", { class: "legend" },
    ...series.map((c) => el("span", { class: c.bold ? "bold" : "" },
      el("i", { style: `background:${c.colour}` }), c.name)));
}

// Distinct colours for up to 12 curves (tab20-like); "auto" is always black.
const curveColours = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b",
  "#e377c2", "#7f7f7f", "#bcbd22", "#17becf", "#aec7e8", "#ffbb78"];
