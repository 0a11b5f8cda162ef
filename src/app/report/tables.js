"use strict";
// Tables: the error of each image against the reference, and where the time and memory
// of each render went (`lvox render --report` files), side by side with bars.

function metricsTable(images) {
  const measured = images.filter((im) => im.metrics);
  if (!measured.length) return el("p", { class: "caption" }, "No reference: no errors to measure.");
  const keys = [["delta_percent", "delta (%)"], ["relmse", "relMSE"], ["rmse", "RMSE"],
    ["psnr_db", "PSNR (dB)"], ["max_abs", "max abs"], ["mean_ratio", "mean A/B"]];
  // The settings lvox writes into its EXRs, where any image has them.
  const settings = ["lvox.mode", "lvox.spp", "lvox.method", "lvox.parameter"]
    .filter((k) => measured.some((im) => im.metadata[k] !== undefined));
  return el("table", { class: "data", id: "metrics-table" },
    el("tr", {}, el("th", {}, "image"), el("th", {}, "size"), ...keys.map(([, label]) => el("th", {}, label)),
      ...settings.map((k) => el("th", {}, k.slice(5)))),
    ...measured.map((im) => el("tr", {},
      el("td", { title: im.path }, im.name),
      el("td", {}, `${im.source_width}x${im.source_height}`),
      ...keys.map(([k]) => el("td", {}, formatShort(im.metrics[k]))),
      ...settings.map((k) => el("td", {}, im.metadata[k] ?? "")))));
}

// Keys of one group ("times", "counts", "memory") over all reports, "total" last.
function groupKeys(reports, group) {
  const keys = new Set();
  for (const r of reports) for (const k of Object.keys(r[group])) keys.add(k);
  return [...keys].sort((a, b) => (a === "total") - (b === "total") || a.localeCompare(b));
}

// One row per key, one column per report; each cell has a bar scaled to the row's largest
// value, so the same phase compares across renders at a glance.
function barTable(reports, group, format) {
  const keys = groupKeys(reports, group);
  if (!keys.length) return el("p", { class: "caption" }, `no ${group}`);
  return el("table", { class: "data bars", "data-group": group },
    el("tr", {}, el("th", {}, group), ...reports.map((r) => el("th", { title: r.path }, r.name))),
    ...keys.map((k) => {
      const values = reports.map((r) => r[group][k]);
      const max = Math.max(...values.filter((v) => typeof v === "number"), 0);
      return el("tr", {}, el("th", {}, k), ...values.map((v) => barCell(v, max, format)));
    }));
}

function barCell(v, max, format) {
  if (typeof v !== "number") return el("td", { class: "missing" }, "-");
  const width = max > 0 ? (100 * v) / max : 0;
  return el("td", {}, el("div", { class: "bar", style: `width:${width.toFixed(1)}%` }), el("span", {}, format(v)));
}

// Each render's phases as one stacked bar of its total, in the same colour per phase.
function phaseShares(reports) {
  const phases = groupKeys(reports, "times").filter((k) => k !== "total");
  const colour = (i) => curveColours[i % curveColours.length];
  const rows = reports.map((r) => {
    const total = r.times.total || phases.reduce((s, p) => s + (r.times[p] || 0), 0);
    const parts = phases.map((p, i) => {
      const share = total > 0 ? (100 * (r.times[p] || 0)) / total : 0;
      return el("i", { style: `width:${share.toFixed(2)}%;background:${colour(i)}`, title: `${p}: ${formatShort(r.times[p] || 0)} s` });
    });
    return el("div", { class: "share-row" }, el("span", {}, r.name), el("div", { class: "share" }, ...parts));
  });
  const key = el("div", { class: "legend" }, ...phases.map((p, i) => el("span", {}, el("i", { style: `background:${colour(i)}` }), p)));
  return el("div", { class: "shares" }, el("h4", {}, "share of each render's total time"), ...rows, key);
}

function settingsTable(reports) {
  const keys = groupKeys(reports, "settings");
  return el("details", {}, el("summary", {}, "settings"),
    el("table", { class: "data" },
      el("tr", {}, el("th", {}, "setting"), ...reports.map((r) => el("th", {}, r.name))),
      ...keys.map((k) => {
        const values = reports.map((r) => r.settings[k] ?? "-");
        const differs = new Set(values).size > 1;
        return el("tr", { class: differs ? "differs" : "" }, el("th", {}, k), ...values.map((v) => el("td", {}, String(v))));
      })));
}

function renderCostSection(data) {
  const reports = data.reports;
  if (!reports.length) return;
  document.getElementById("costs").hidden = false;
  const box = document.getElementById("reports");
  box.append(el("h3", {}, "time per phase"), barTable(reports, "times", (v) => formatShort(v) + " s"));
  box.append(phaseShares(reports));
  box.append(el("h3", {}, "counts"), barTable(reports, "counts", formatShort));
  box.append(el("h3", {}, "memory"), barTable(reports, "memory", formatBytes));
  box.append(settingsTable(reports));
  const warnings = reports.flatMap((r) => r.warnings.map((w) => `${r.name}: ${w}`));
  if (warnings.length) box.append(el("h3", {}, "warnings"), el("ul", {}, ...warnings.map((w) => el("li", {}, w))));
}
