"use strict";
// The image viewer: two sources A and B (renders, the reference, or their error maps)
// side by side, as a slider or as a flip, sharing one zoom and pan down to single pixels;
// any layer or channel of the EXRs at an exposure on the HDR values; the values under
// the cursor.

const viewer = {
  images: [], // decoded: {name, path, width, height, planes, layers, isReference, error}
  reference: null,
  sources: [], // {label, image, kind: "image" | "error"}
  a: 0,
  b: 0,
  mode: "slider", // "side" | "slider" | "flip"
  flipped: false,
  split: 0.5, // slider position, a fraction of the pane's width
  view: "", // "rgb:LAYER" or "ch:CHANNEL"
  scale: 1, // screen pixels per image pixel
  cx: 0, // image coordinates at the panes' centre
  cy: 0,
  panes: [],
  cache: new Map(), // source index -> {key, canvas}
};

const paneHeight = 440;

function decodeImage(im, isReference) {
  const planes = {};
  for (const [name, data] of Object.entries(im.channels)) planes[name] = decodeFloats(data);
  return { name: im.name, path: im.path, width: im.width, height: im.height, planes, layers: im.layers, isReference, error: null };
}

// The planes a view shows for an image: three for an RGB layer, one (as grey) for a
// channel; null when the image lacks them.
function viewPlanes(image, view) {
  if (view.startsWith("rgb:")) {
    const layer = view.slice(4);
    const prefix = layer ? layer + "." : "";
    const names = ["R", "G", "B"].map((c) => prefix + c);
    return names.every((n) => image.planes[n]) ? { names, planes: names.map((n) => image.planes[n]) } : null;
  }
  const name = view.slice(3);
  const p = image.planes[name];
  return p ? { names: [name], planes: [p, p, p] } : null;
}

// The colour planes of an image, as `lvox compare` reads them (RGB, else Y as grey).
function colourPlanes(image) {
  return (viewPlanes(image, "rgb:") || viewPlanes(image, "ch:Y") || { planes: null }).planes;
}

// Relative absolute error against the reference, |A - B| / (|B| + 0.01) averaged over
// R, G, B: the same map as `lvox compare --heatmap`.
function errorPlane(image) {
  if (image.error) return image.error;
  const a = colourPlanes(image), b = colourPlanes(viewer.reference);
  const n = image.width * image.height;
  const e = new Float32Array(n);
  for (let i = 0; i < n; ++i) {
    let sum = 0;
    for (let c = 0; c < 3; ++c) sum += Math.abs(a[c][i] - b[c][i]) / (Math.abs(b[c][i]) + 0.01);
    e[i] = sum / 3;
  }
  image.error = e;
  return e;
}

function viewOptions() {
  const options = [];
  const seen = new Set();
  const add = (value, label) => {
    if (!seen.has(value)) options.push([value, label]);
    seen.add(value);
  };
  for (const image of viewer.images)
    for (const layer of image.layers) {
      const prefix = layer.name ? layer.name + "." : "";
      if (["R", "G", "B"].every((c) => layer.channels.includes(prefix + c)))
        add("rgb:" + layer.name, (layer.name || "colour") + " (RGB)");
      for (const ch of layer.channels) add("ch:" + ch, ch);
    }
  return options;
}

function buildSources() {
  for (const image of viewer.images)
    viewer.sources.push({ label: image.name + (image.isReference ? " (reference)" : ""), image, kind: "image" });
  for (const image of viewer.images)
    if (viewer.reference && !image.isReference && colourPlanes(image) &&
        image.width === viewer.reference.width && image.height === viewer.reference.height)
      viewer.sources.push({ label: image.name + ": error map", image, kind: "error" });
}

// The source's pixels at the current display settings, redrawn only when they change.
function sourceCanvas(index) {
  const s = viewer.sources[index];
  const key = [viewer.view, display.exposure, display.curve, display.errorLo, display.errorHi].join("|");
  const cached = viewer.cache.get(index);
  if (cached && cached.key === key) return cached.canvas;
  const canvas = document.createElement("canvas");
  canvas.width = s.image.width;
  canvas.height = s.image.height;
  const ctx = canvas.getContext("2d");
  const data = ctx.createImageData(canvas.width, canvas.height);
  if (s.kind === "error") errorColoursInto(data, errorPlane(s.image));
  else {
    const v = viewPlanes(s.image, viewer.view);
    if (v) toneMapInto(data, ...v.planes);
    else data.data.fill(40); // this image has no such layer: dark grey
  }
  ctx.putImageData(data, 0, 0);
  viewer.cache.set(index, { key, canvas });
  return canvas;
}

function drawSource(ctx, index, pane) {
  ctx.imageSmoothingEnabled = false;
  ctx.setTransform(viewer.scale, 0, 0, viewer.scale,
    pane.width / 2 - viewer.cx * viewer.scale, pane.height / 2 - viewer.cy * viewer.scale);
  ctx.drawImage(sourceCanvas(index), 0, 0);
  ctx.setTransform(1, 0, 0, 1, 0, 0);
}

// Which source each pane shows (the slider pane shows both).
function paneSources() {
  if (viewer.mode === "side") return [viewer.a, viewer.b];
  if (viewer.mode === "flip") return [viewer.flipped ? viewer.b : viewer.a];
  return [viewer.a];
}

function drawPanes() {
  const sources = paneSources();
  viewer.panes.forEach((pane, i) => {
    const ctx = pane.getContext("2d");
    ctx.fillStyle = "#202020";
    ctx.fillRect(0, 0, pane.width, pane.height);
    if (viewer.mode !== "slider") {
      drawSource(ctx, sources[i], pane);
      return;
    }
    // Slider: B everywhere, A left of the split.
    const x = Math.round(viewer.split * pane.width);
    drawSource(ctx, viewer.b, pane);
    ctx.save();
    ctx.beginPath();
    ctx.rect(0, 0, x, pane.height);
    ctx.clip();
    ctx.fillRect(0, 0, x, pane.height);
    drawSource(ctx, viewer.a, pane);
    ctx.restore();
    ctx.fillStyle = "#ffffff";
    ctx.fillRect(x - 1, 0, 1, pane.height);
  });
  document.getElementById("pane-captions").textContent = paneCaption();
}

function paneCaption() {
  const a = viewer.sources[viewer.a].label, b = viewer.sources[viewer.b].label;
  if (viewer.mode === "side") return `left: ${a}    right: ${b}`;
  if (viewer.mode === "flip") return `showing ${viewer.flipped ? "B: " + b : "A: " + a} (press f or the flip button)`;
  return `left of the line: A, ${a}    right: B, ${b}`;
}

function layoutPanes() {
  const box = document.getElementById("panes");
  const count = viewer.mode === "side" ? 2 : 1;
  const width = Math.max(200, Math.floor((box.clientWidth - 8 * (count - 1)) / count));
  viewer.panes = [];
  box.replaceChildren();
  for (let i = 0; i < count; ++i) {
    const pane = el("canvas", { width, height: paneHeight, class: "pane", "data-pane": i });
    attachPointer(pane);
    viewer.panes.push(pane);
    box.append(pane);
  }
  drawPanes();
}

function fitView() {
  const image = viewer.sources[viewer.a].image;
  const pane = viewer.panes[0];
  viewer.scale = Math.min(pane.width / image.width, pane.height / image.height);
  viewer.cx = image.width / 2;
  viewer.cy = image.height / 2;
  drawPanes();
}

// Centres pixel (x, y) at `scale` screen pixels per image pixel.
function zoomAt(x, y, scale) {
  viewer.scale = scale;
  viewer.cx = x + 0.5;
  viewer.cy = y + 0.5;
  drawPanes();
}

function imagePoint(pane, offsetX, offsetY) {
  return {
    x: (offsetX - pane.width / 2) / viewer.scale + viewer.cx,
    y: (offsetY - pane.height / 2) / viewer.scale + viewer.cy,
  };
}

// Client coordinates of the centre of pixel (x, y) in a pane (for the self-test).
function clientPointOf(paneIndex, x, y) {
  const pane = viewer.panes[paneIndex];
  const r = pane.getBoundingClientRect();
  return {
    x: r.left + (x + 0.5 - viewer.cx) * viewer.scale + pane.width / 2,
    y: r.top + (y + 0.5 - viewer.cy) * viewer.scale + pane.height / 2,
  };
}

function sourceValues(index, i) {
  const s = viewer.sources[index];
  if (s.kind === "error") {
    const e = errorPlane(s.image)[i];
    return `error=${formatValue(e)} (${formatShort(e * 100)} %)`;
  }
  const v = viewPlanes(s.image, viewer.view);
  if (!v) return "no such layer";
  return v.names.map((n, c) => `${n.slice(n.lastIndexOf(".") + 1)}=${formatValue(v.planes[c][i])}`).join("  ");
}

function updateReadout(x, y) {
  const rows = document.getElementById("readout");
  const inside = (s) => x >= 0 && y >= 0 && x < s.image.width && y < s.image.height;
  const line = (tag, index) => {
    const s = viewer.sources[index];
    return `${tag} ${s.label}: ` + (inside(s) ? sourceValues(index, y * s.image.width + x) : "outside");
  };
  rows.querySelector("#readout-pixel").textContent = `pixel (${x}, ${y})`;
  rows.querySelector("#readout-a").textContent = line("A", viewer.a);
  rows.querySelector("#readout-b").textContent = line("B", viewer.b);
}

// The pointer in pane pixels (from client coordinates, which synthetic events have too).
function panePoint(pane, e) {
  const r = pane.getBoundingClientRect();
  return { x: e.clientX - r.left, y: e.clientY - r.top };
}

function attachPointer(pane) {
  let drag = null;
  pane.addEventListener("mousedown", (e) => {
    const p = panePoint(pane, e);
    const nearSplit = viewer.mode === "slider" && Math.abs(p.x - viewer.split * pane.width) < 6;
    drag = { x: e.clientX, y: e.clientY, split: nearSplit };
    e.preventDefault();
  });
  window.addEventListener("mouseup", () => (drag = null));
  pane.addEventListener("mousemove", (e) => {
    const q = panePoint(pane, e);
    const p = imagePoint(pane, q.x, q.y);
    updateReadout(Math.floor(p.x), Math.floor(p.y));
    if (!drag || !(e.buttons & 1)) return;
    if (drag.split) {
      setSplit(q.x / pane.width);
    } else {
      viewer.cx -= (e.clientX - drag.x) / viewer.scale;
      viewer.cy -= (e.clientY - drag.y) / viewer.scale;
      drag.x = e.clientX;
      drag.y = e.clientY;
      drawPanes();
    }
  });
  pane.addEventListener("wheel", (e) => {
    e.preventDefault();
    const q = panePoint(pane, e);
    const p = imagePoint(pane, q.x, q.y);
    const scale = Math.min(256, Math.max(0.05, viewer.scale * (e.deltaY < 0 ? 1.25 : 0.8)));
    // Keep the image point under the cursor where it is.
    viewer.cx = p.x - (q.x - pane.width / 2) / scale;
    viewer.cy = p.y - (q.y - pane.height / 2) / scale;
    viewer.scale = scale;
    drawPanes();
  }, { passive: false });
}

function setSplit(fraction) {
  viewer.split = Math.min(1, Math.max(0, fraction));
  document.getElementById("split").value = Math.round(viewer.split * 1000);
  drawPanes();
}
