// curve-vae's page: exploring. The in-betweens with their weights (click one to take it as a new curve), the sweep
// animated, and around a selected curve the grid of its neighbours along the directions the data varies most
// (POST /explore), one taken as a new curve. One that crosses itself is marked, and taken only when clicked again.
"use strict";

// "0.75 A + 0.25 B": a row of weights by the names of the curves they weigh (zero weights left out).
function weightsLabel(weights, names) {
  return weights.map((w, i) => [w, names[i]]).filter(([w]) => Math.abs(w) > 1e-9)
    .map(([w, name]) => `${Number(w.toFixed(2))} ${name}`).join(" + ");
}
// "A 75% · B 25%": the same, short enough to sit under a thumbnail.
function shortLabel(weights, names) {
  return weights.map((w, i) => [w, names[i]]).filter(([w]) => Math.abs(w) > 1e-9)
    .map(([w, name]) => `${name} ${Math.round(100 * w)}%`).join(", ");
}
const byName = (weights, names) => Object.fromEntries(weights.map((w, i) => [names[i], w]));

function renderStrip() {
  // pair: one row; triplet: the barycentric grid as a triangle, row k holding the k+1 mixes with A's weight (n-k)/n
  const strip = $("strip");
  strip.replaceChildren();
  const rows = [];
  const names = state.stripOf || [];
  const items = state.strip.map((curve, k) => ({ curve, k, weights: state.stripWeights[k] || [] }));
  if (state.mode === "triplet") {
    for (let r = 0, i = 0; i < items.length; r++) { rows.push(items.slice(i, i + r + 1)); i += r + 1; }
  } else if (items.length) rows.push(items);
  strip.classList.toggle("triangle-grid", state.mode === "triplet");
  for (const row of rows) {
    const div = document.createElement("div");
    div.className = "strip-row";
    strip.appendChild(div);
    for (const { curve, k, weights } of row) {
      const label = weightsLabel(weights, names);
      const valid = state.stripValid[k] !== false;
      const fig = thumbnail(div, curve, { caption: shortLabel(weights, names),
        title: valid ? `${label}: take it as a new curve` : `${label}: crosses itself (click twice to take it anyway)` });
      fig.dataset.weights = JSON.stringify(weights);
      if (!valid) fig.classList.add("invalid");
      fig.addEventListener("click", () => takeChecked(curve, valid, `in-between ${label}`, $("strip-error")));
    }
  }
  $("sweep-caption").hidden = state.strip.length < 2;
  renderSweep();
}

// A curve that crosses itself is taken on a second click only, the first saying why.
function takeChecked(curve, valid, what, errorEl) {
  if (!valid && state.confirm !== curve) {
    state.confirm = curve;
    errorEl.textContent = `The ${what} crosses itself: click it again to take it anyway.`;
    return false;
  }
  state.confirm = null;
  errorEl.textContent = "";
  take(curve);
  return true;
}

// An in-between or a neighbour becomes a new curve of the drawing, with the next name; nothing else changes.
function take(curve) {
  remember();
  addCurve(curve.map((p) => p.slice()));
  curvesChanged();
}

// The in-betweens one after another and back, as one path whose outline is animated (SVG <animate>, no script).
function renderSweep() {
  const svg = $("sweep-preview");
  svg.replaceChildren();
  const curves = state.mode === "pair" ? state.strip : state.strip.filter((_, k) => {
    const w = state.stripWeights[k] || [];
    return w.length === 3 && w.some((v) => Math.abs(v) < 1e-9);  // triplet: around the triangle's edge
  });
  svg.style.display = curves.length < 2 ? "none" : "";
  if (curves.length < 2) return;
  const all = curves.flat(), xs = all.map((p) => p[0]), ys = all.map((p) => p[1]);
  const pad = 10, x0 = Math.min(...xs) - pad, y0 = Math.min(...ys) - pad;
  const w = Math.max(...xs) - x0 + pad, h = Math.max(...ys) - y0 + pad;
  svg.setAttribute("viewBox", `${x0} ${-(y0 + h)} ${w} ${h}`);
  const ds = curves.map((c) => pathOf(c.map(([x, y]) => [x, -y])));
  const loop = state.mode === "pair" ? [...ds, ...ds.slice(1, -1).reverse(), ds[0]] : [...ds, ds[0]];
  const path = el("path", { d: ds[0], fill: "none", stroke: MIX_COLOR, "stroke-width": Math.max(w, h) / 60 }, svg);
  el("animate", { attributeName: "d", dur: `${0.6 * loop.length}s`, repeatCount: "indefinite",
    values: loop.join(";") }, path);
}

async function updateNeighbours() {
  const i = state.selected;
  if (i === null || !state.items[i]) { state.neighbours = null; renderNeighbours(); return; }
  const of = state.items[i].name;
  const body = { curves: [state.items[i].points], steps: 3, directions: 2, n_points: 60, refine: refine() };
  try {
    const r = await api("/explore", body, $("around-error"), { quiet: true });
    if (state.selected === i) state.neighbours = { of, curves: r.curves, offsets: r.offsets, valid: r.valid };
  } catch (e) { state.neighbours = null; }
  renderNeighbours();
}

function renderNeighbours() {
  const box = $("neighbours"), n = state.neighbours;
  $("around").hidden = state.selected === null;
  box.replaceChildren();
  if (state.selected === null) return;
  const of = state.items[state.selected];
  $("around-title").textContent = `Around ${of.name}`;
  if (!n) return;
  n.curves.forEach((curve, k) => {
    const [a, b] = n.offsets[k];
    const middle = a === 0 && b === 0;
    const fig = thumbnail(box, curve, { color: of.color, caption: middle ? "itself" : `${sign(a)} ${sign(b)}`,
      title: middle ? "the curve as the model reads it" : `${sign(a)}σ along the first direction, ${sign(b)}σ along the second` });
    if (!n.valid[k]) { fig.classList.add("invalid"); fig.title += " (crosses itself: click twice to take it anyway)"; }
    fig.addEventListener("click", () => {
      const keep = indexOf(n.of);
      if (takeChecked(curve, n.valid[k], `neighbour of ${n.of}`, $("around-error"))) select(keep);
    });
  });
}
const sign = (v) => (v > 0 ? `+${v}` : v < 0 ? `−${-v}` : "0");

// The drawing as a list of named curves with their roles, the one file model of every export (files.js).
function drawing() {
  const items = state.items.map((c) => ({ name: c.name, role: "input", points: c.points }));
  state.items.forEach((c) => {
    if (c.recon) items.push({ name: `${c.name} reconstructed`, role: "reconstruction", of: c.name, points: c.recon.points,
      ...(c.recon.spline ? { spline: c.recon.spline } : {}) });
  });
  if (state.result) {
    items.push({ name: "mix", role: "interpolant", weights: byName(state.result.weights, state.result.of),
      points: state.result.points, ...(state.result.spline ? { spline: state.result.spline } : {}) });
  }
  const names = state.stripOf || [];
  state.strip.forEach((points, k) => {
    const w = state.stripWeights[k];
    if (w) items.push({ name: weightsLabel(w, names), role: "interpolant", weights: byName(w, names), points });
  });
  return items;
}
