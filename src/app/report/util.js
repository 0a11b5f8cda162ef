"use strict";
// Shared helpers of the report page. This file is the first script, so that it can catch
// the errors of every later one: they are listed at the top of the page (a broken viewer
// should say so, not look empty) and read back by the self-test.

const pageErrors = [];

function recordPageError(text) {
  pageErrors.push(String(text));
  const list = document.getElementById("page-errors");
  const item = document.createElement("li");
  item.textContent = String(text);
  list.appendChild(item);
  list.hidden = false;
}

window.addEventListener("error", (e) => recordPageError("error: " + e.message));
window.addEventListener("unhandledrejection", (e) => recordPageError("rejection: " + e.reason));
{
  const original = console.error.bind(console);
  console.error = (...args) => {
    recordPageError("console.error: " + args.join(" "));
    original(...args);
  };
}

// Creates an element with attributes and children (strings become text nodes).
function el(tag, attributes = {}, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attributes)) {
    if (k === "class") e.className = v;
    else if (k.startsWith("on")) e.addEventListener(k.slice(2), v);
    else e.setAttribute(k, v);
  }
  for (const c of children) e.append(c);
  return e;
}

const svgNs = "http://www.w3.org/2000/svg";

function svgEl(tag, attributes = {}) {
  const e = document.createElementNS(svgNs, tag);
  for (const [k, v] of Object.entries(attributes)) e.setAttribute(k, v);
  return e;
}

// The pixel planes are little-endian float32 written by lvox; every platform a browser
// runs on is little-endian, so the bytes are viewed directly.
function decodeFloats(base64) {
  const text = atob(base64);
  const bytes = new Uint8Array(text.length);
  for (let i = 0; i < text.length; ++i) bytes[i] = text.charCodeAt(i);
  return new Float32Array(bytes.buffer);
}

// A number for a readout: six significant digits, as the EXR holds more than the eye needs.
function formatValue(v) {
  if (typeof v !== "number") return String(v);
  if (!Number.isFinite(v)) return Number.isNaN(v) ? "nan" : v > 0 ? "inf" : "-inf";
  return Number(v.toPrecision(6)).toString();
}

// A number for a table: four significant digits, thousands grouped for large counts.
function formatShort(v) {
  if (typeof v !== "number") return String(v);
  if (!Number.isFinite(v)) return formatValue(v);
  if (Number.isInteger(v) && Math.abs(v) >= 1e4) return v.toLocaleString("en-US");
  return Number(v.toPrecision(4)).toString();
}

function formatBytes(bytes) {
  if (bytes >= 1e9) return formatShort(bytes / 1e9) + " GB";
  if (bytes >= 1e6) return formatShort(bytes / 1e6) + " MB";
  if (bytes >= 1e3) return formatShort(bytes / 1e3) + " kB";
  return bytes + " B";
}

// The sRGB transfer curve of a linear value in [0, 1], to 8 bits.
function srgbByte(linear) {
  const x = Math.min(Math.max(linear, 0), 1);
  const s = x <= 0.0031308 ? 12.92 * x : 1.055 * Math.pow(x, 1 / 2.4) - 0.055;
  return Math.round(Math.min(Math.max(s, 0), 1) * 255);
}

// The display of an HDR value at a linear exposure factor. "lvox" is the curve of the
// PNG previews lvox writes (1 - exp(-k x), never clips); "clip" is plain scaling.
function toneMapByte(x, exposure, curve) {
  if (!(x > 0)) return 0;
  return srgbByte(curve === "clip" ? x * exposure : 1 - Math.exp(-exposure * x));
}

// The error ramp (viridis-like, as `lvox compare --heatmap`): position t in [0, 1].
const rampStops = [
  [68, 1, 84],
  [59, 82, 139],
  [33, 145, 140],
  [94, 201, 98],
  [253, 231, 37],
];

function rampColour(t) {
  const f = Math.min(Math.max(t, 0), 1) * 4;
  const i = Math.min(3, Math.floor(f));
  const u = f - i;
  return rampStops[i].map((c, k) => Math.round(c * (1 - u) + rampStops[i + 1][k] * u));
}

// Position of a relative error on the log colour scale [lo, hi].
function errorPosition(e, lo, hi) {
  const l = Math.log10(Math.max(e, 1e-12));
  return (l - Math.log10(lo)) / (Math.log10(hi) - Math.log10(lo));
}

function percentLabel(fraction) {
  return formatShort(fraction * 100) + " %";
}

// How HDR values and errors are displayed, shared by the viewer and the thumbnails: the
// exposure factor (2^EV), the tone curve and the error colour scale [errorLo, errorHi].
const display = { exposure: 1, curve: "lvox", errorLo: 1e-3, errorHi: 1, listeners: [] };

function displayChanged() {
  for (const f of display.listeners) f();
}

// Fills ImageData from HDR planes (r, g, b may be the same plane for grey).
function toneMapInto(imageData, r, g, b) {
  const d = imageData.data;
  for (let i = 0, j = 0; i < r.length; ++i, j += 4) {
    d[j] = toneMapByte(r[i], display.exposure, display.curve);
    d[j + 1] = toneMapByte(g[i], display.exposure, display.curve);
    d[j + 2] = toneMapByte(b[i], display.exposure, display.curve);
    d[j + 3] = 255;
  }
}

// Fills ImageData with the false colours of a relative-error plane.
function errorColoursInto(imageData, error) {
  const d = imageData.data;
  for (let i = 0, j = 0; i < error.length; ++i, j += 4) {
    const c = rampColour(errorPosition(error[i], display.errorLo, display.errorHi));
    d[j] = c[0];
    d[j + 1] = c[1];
    d[j + 2] = c[2];
    d[j + 3] = 255;
  }
}
