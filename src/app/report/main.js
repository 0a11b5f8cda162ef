"use strict";
// Reads the data lvox embedded in the page and builds each section; then, for
// report.html#selftest, runs the self-check.

function renderHeader(data) {
  const inputs = [];
  if (data.images.length) inputs.push(`${data.images.length} image(s)`);
  if (data.sweeps.length) inputs.push(`${data.sweeps.length} sweep(s)`);
  if (data.convergence.length) inputs.push(`${data.convergence.length} convergence curve(s)`);
  if (data.reports.length) inputs.push(`${data.reports.length} render report(s)`);
  document.getElementById("inputs").textContent = "From " + (inputs.join(", ") || "nothing") + ".";
  document.getElementById("notes").append(...data.notes.map((n) => el("li", {}, n)));
  const toc = document.getElementById("toc");
  for (const section of document.querySelectorAll("main > section"))
    if (!section.hidden) toc.append(el("a", { href: "#" + section.id }, section.querySelector("h2").textContent));
}

function main() {
  const data = JSON.parse(document.getElementById("lvox-data").textContent);
  // A section that fails is reported on the page; the others are still built.
  for (const render of [renderImageSection, renderSpeedSection, renderCostSection, renderHeader]) {
    try {
      render(data);
    } catch (e) {
      recordPageError(`${render.name}: ${e.message}`);
    }
  }
  if (location.hash.startsWith("#selftest")) runSelfTest(new URLSearchParams(location.hash.slice(9)));
}

main();
