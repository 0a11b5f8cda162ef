"use strict";
// The viewer's controls: which sources, how they are compared, the layer, the exposure,
// the tone curve, the error scale and the zoom; and the error colour bar.

function selectOf(id, options, value, onChange) {
  const s = el("select", { id }, ...options.map(([v, label]) => el("option", { value: v }, label)));
  s.value = value;
  s.addEventListener("change", () => onChange(s.value));
  return s;
}

function labelled(text, control) {
  return el("label", {}, text + " ", control);
}

const errorScales = [["1e-4:1e-1", "0.01 % .. 10 %"], ["1e-3:1", "0.1 % .. 100 %"], ["1e-2:10", "1 % .. 1000 %"]];

function buildControls() {
  const sources = viewer.sources.map((s, i) => [String(i), s.label]);
  const redraw = () => {
    drawPanes();
    displayChanged();
  };
  const exposureText = el("span", { id: "exposure-value" });
  const exposure = el("input", { id: "exposure", type: "range", min: -10, max: 10, step: 0.1, value: 0 });
  const setExposure = () => {
    const ev = Number(exposure.value);
    display.exposure = Math.pow(2, ev);
    exposureText.textContent = `${ev >= 0 ? "+" : ""}${ev.toFixed(1)} EV`;
    redraw();
  };
  exposure.addEventListener("input", setExposure);
  const split = el("input", { id: "split", type: "range", min: 0, max: 1000, step: 1, value: 500 });
  split.addEventListener("input", () => setSplit(Number(split.value) / 1000));
  const flip = el("button", { id: "flip", type: "button" }, "flip A/B");
  flip.addEventListener("click", () => {
    viewer.flipped = !viewer.flipped;
    drawPanes();
  });
  document.addEventListener("keydown", (e) => {
    if (e.key === "f" && !(e.target instanceof HTMLInputElement)) flip.click();
  });
  const zoom = (label, id, action) => {
    const b = el("button", { type: "button", id }, label);
    b.addEventListener("click", action);
    return b;
  };
  const box = document.getElementById("viewer-controls");
  box.append(
    el("div", {},
      labelled("A", selectOf("source-a", sources, String(viewer.a), (v) => { viewer.a = Number(v); drawPanes(); })),
      labelled("B", selectOf("source-b", sources, String(viewer.b), (v) => { viewer.b = Number(v); drawPanes(); })),
      labelled("compare", selectOf("mode", [["side", "side by side"], ["slider", "slider"], ["flip", "flip"]], viewer.mode,
        (v) => { viewer.mode = v; layoutPanes(); })),
      flip,
      labelled("split", split)),
    el("div", {},
      labelled("layer", selectOf("layer", viewOptions(), viewer.view, (v) => { viewer.view = v; drawPanes(); })),
      labelled("exposure", exposure), exposureText,
      labelled("curve", selectOf("curve", [["lvox", "lvox preview (1 - e^-x)"], ["clip", "linear, clipped"]], display.curve,
        (v) => { display.curve = v; redraw(); })),
      labelled("error scale", selectOf("error-scale", errorScales, "1e-3:1", (v) => {
        [display.errorLo, display.errorHi] = v.split(":").map(Number);
        drawColourBar();
        redraw();
      })),
      zoom("fit", "zoom-fit", fitView),
      zoom("1:1", "zoom-1", () => { viewer.scale = 1; drawPanes(); }),
      zoom("zoom in", "zoom-in", () => { viewer.scale = Math.min(256, viewer.scale * 2); drawPanes(); }),
      zoom("zoom out", "zoom-out", () => { viewer.scale = Math.max(0.05, viewer.scale / 2); drawPanes(); })));
  setExposure();
}

function drawColourBar() {
  const box = document.getElementById("colour-bar");
  const width = 360;
  const canvas = el("canvas", { width, height: 14, id: "colour-bar-canvas" });
  const ctx = canvas.getContext("2d");
  for (let x = 0; x < width; ++x) {
    const c = rampColour(x / (width - 1));
    ctx.fillStyle = `rgb(${c[0]},${c[1]},${c[2]})`;
    ctx.fillRect(x, 0, 1, 14);
  }
  const ticks = el("div", { class: "ticks", style: `width:${width}px` });
  for (let e = display.errorLo; e <= display.errorHi * 1.0001; e *= 10) {
    const left = errorPosition(e, display.errorLo, display.errorHi) * 100;
    ticks.append(el("span", { style: `left:${left.toFixed(1)}%` }, percentLabel(e)));
  }
  box.replaceChildren(
    el("div", {}, "error maps: relative absolute error |A - ref| / (|ref| + 0.01), mean of R, G, B; log scale"),
    canvas, ticks);
}

function renderImageSection(data) {
  if (!data.images.length) return;
  document.getElementById("images").hidden = false;
  viewer.images = data.images.map((im, i) => decodeImage(im, i === data.reference));
  viewer.reference = data.reference === null ? null : viewer.images[data.reference];
  buildSources();
  // A is the first render, B the reference (or the second image).
  viewer.a = viewer.images.findIndex((im) => !im.isReference);
  if (viewer.a < 0) viewer.a = 0;
  viewer.b = data.reference ?? Math.min(1, viewer.images.length - 1);
  const options = viewOptions();
  viewer.view = options.some(([v]) => v === "rgb:") ? "rgb:" : options[0][0];
  document.getElementById("readout").append(
    el("div", { id: "readout-pixel" }, "move the cursor over the image"), el("div", { id: "readout-a" }), el("div", { id: "readout-b" }));
  document.getElementById("panes").after(el("div", { id: "pane-captions", class: "caption" }));
  buildControls();
  layoutPanes();
  fitView();
  drawColourBar();
  document.getElementById("image-metrics").append(metricsTable(data.images));
}
