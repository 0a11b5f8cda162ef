"use strict";
// report.html#selftest&x=X&y=Y&ev=EV: drives the page as a user would (slider, exposure,
// layer, error map, cursor over pixel (X, Y), hover on plot points) and writes what it
// measured as JSON into the element pre#selftest-result. It judges nothing itself: the test
// that opened the page compares the numbers with the EXR files it wrote.

function setControl(id, value, type = "input") {
  const control = document.getElementById(id);
  control.value = value;
  control.dispatchEvent(new Event(type));
}

function panePixel(paneIndex, x, y) {
  const pane = viewer.panes[paneIndex];
  const p = clientPointOf(paneIndex, x, y);
  const r = pane.getBoundingClientRect();
  const data = pane.getContext("2d").getImageData(Math.floor(p.x - r.left), Math.floor(p.y - r.top), 1, 1).data;
  return [data[0], data[1], data[2]];
}

function distinctColours(canvas) {
  const d = canvas.getContext("2d").getImageData(0, 0, canvas.width, canvas.height).data;
  const seen = new Set();
  for (let i = 0; i < d.length; i += 4) seen.add((d[i] << 16) | (d[i + 1] << 8) | d[i + 2]);
  return seen.size;
}

// Moves the cursor over pixel (x, y) of pane 0 and returns the readout's lines.
function hover(x, y) {
  const p = clientPointOf(0, x, y);
  viewer.panes[0].dispatchEvent(new MouseEvent("mousemove", { clientX: p.x, clientY: p.y, bubbles: true }));
  return ["readout-pixel", "readout-a", "readout-b"].map((id) => document.getElementById(id).textContent);
}

function checkViewer(params) {
  const x = Number(params.get("x") ?? 0), y = Number(params.get("y") ?? 0), ev = Number(params.get("ev") ?? 1);
  const r = { sources: viewer.sources.map((s) => s.label), a: viewer.sources[viewer.a].label, b: viewer.sources[viewer.b].label };
  setControl("mode", "side", "change");
  r.sidePanes = viewer.panes.length;
  setControl("mode", "slider", "change");
  fitView();
  r.distinctColours = distinctColours(viewer.panes[0]);
  zoomAt(x, y, 8);
  setControl("split", 1000);
  r.sliderAtA = panePixel(0, x, y);
  setControl("split", 0);
  r.sliderAtB = panePixel(0, x, y);
  setControl("exposure", ev);
  r.exposure = { ev, text: document.getElementById("exposure-value").textContent, atB: panePixel(0, x, y) };
  setControl("split", 1000);
  r.exposure.atA = panePixel(0, x, y);
  r.readout = hover(x, y);
  setControl("mode", "flip", "change");
  zoomAt(x, y, 8);
  r.flip = [panePixel(0, x, y)];
  document.getElementById("flip").click();
  r.flip.push(panePixel(0, x, y));
  setControl("mode", "slider", "change");
  zoomAt(x, y, 8);
  r.layers = [...document.getElementById("layer").options].map((o) => {
    setControl("layer", o.value, "change");
    return { value: o.value, atA: panePixel(0, x, y), readout: hover(x, y)[1] };
  });
  setControl("layer", "rgb:", "change");
  const errorSource = viewer.sources.findIndex((s) => s.kind === "error" && s.image === viewer.sources[viewer.a].image);
  if (errorSource >= 0) {
    setControl("source-a", String(errorSource), "change");
    r.errorMap = { atA: panePixel(0, x, y), readout: hover(x, y)[1] };
  }
  return r;
}

function checkPlots() {
  return [...document.querySelectorAll("#speed .sweep")].map((box) => {
    const plots = [...box.querySelectorAll("svg.plot")].map((svg) => {
      const first = svg.querySelector("circle.point");
      if (first) first.dispatchEvent(new MouseEvent("mouseenter", { clientX: 10, clientY: 10 }));
      const tip = document.getElementById("tooltip");
      const plot = {
        points: svg.querySelectorAll("circle.point").length,
        front: svg.querySelectorAll("circle.front-mark").length,
        bold: svg.querySelectorAll("g.series.bold circle.point").length,
        tooltip: tip.hidden ? "" : tip.textContent,
      };
      hideTooltip();
      return plot;
    });
    const thumbs = [...box.querySelectorAll("canvas.thumb")];
    return { title: box.querySelector("h3").textContent, plots, thumbs: thumbs.length,
      thumbColours: thumbs.map(distinctColours) };
  });
}

function tableText(selector) {
  const table = document.querySelector(selector);
  return table ? [...table.rows].map((row) => [...row.cells].map((c) => c.textContent)) : null;
}

function runSelfTest(params) {
  const result = { errors: pageErrors };
  try {
    if (viewer.panes.length) result.viewer = checkViewer(params);
    result.plots = checkPlots();
    result.metrics = tableText("#metrics-table");
    result.times = tableText('table[data-group="times"]');
    result.memory = tableText('table[data-group="memory"]');
  } catch (e) {
    recordPageError("selftest: " + e.message);
  }
  document.body.append(el("pre", { id: "selftest-result" }, JSON.stringify(result)));
}
