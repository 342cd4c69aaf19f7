// curve-vae's page: draw curves, reconstruct and interpolate them through the REST API, take the result away.
// Plain JavaScript, no build step, no CDN: app.js (the drawing, the API, the model calls), board.js (what the board
// shows, drawing on it), view.js (zoom, pan, fit; the control points dragged), history.js (undo, redo, the drawing
// and its history kept across reloads), explore.js (in-betweens, the sweep, the neighbours of a curve), curves.js
// (the list of curves), controls.js (the buttons and keys), files.js and vase.js. Everything it shows comes from
// the same endpoints any front-end uses; `?api=https://host:port` points it at a service on another origin.
"use strict";

const API = new URLSearchParams(location.search).get("api") || "";
const W = 1000, H = 700;  // the board's own units (its first view); API coordinates are the board's with y up
const MIX_COLOR = "#d62728";
const N_POINTS = 100;
const FIT_STEPS = 10;  // "fit closely": the `refine` of every call that encodes the drawn curves
const refine = () => ($("fit-closely").checked ? FIT_STEPS : 0);

// The drawing: its curves, each with a name and a colour for life (A, B, …: curveFiles.curveName and PALETTE, the
// command line's too), in the order they were made; which two or three are mixed, and the weights. Everything else
// is the model's answers. API coordinates; window.curveVae for tests and the console.
const state = {
  items: [], made: 0, mixOf: null, mode: "pair", weight: 0.5, bary: [1 / 3, 1 / 3, 1 / 3],
  result: null, strip: [], stripWeights: [], stripValid: [], lastRequest: null, vase: null, selected: null,
  neighbours: null, view: { x: 0, y: 0, w: W, h: H }, warming: false,
};
// the curves' points and their reconstructions, in the drawing's order (what the tests and the exports read)
Object.defineProperty(state, "curves", { enumerable: true, get: () => state.items.map((c) => c.points) });
Object.defineProperty(state, "recon", { enumerable: true, get: () => state.items.map((c) => c.recon || null) });
Object.defineProperty(state, "names", { enumerable: true, get: () => state.items.map((c) => c.name) });
window.curveVae = state;

const $ = (id) => document.getElementById(id);
const toApi = ([x, y]) => [x, H - y];
const toBoard = ([x, y]) => [x, H - y];
const round = (v) => Math.round(v * 1000) / 1000;
const needed = () => (state.mode === "triplet" ? 3 : 2);

// ------------------------------------------------------------------------------------------ API

// The API key the user typed, as the header the service reads.
const keyHeader = () => ($("api-key").value ? { "X-API-Key": $("api-key").value } : {});

async function api(path, body, errorEl, { raw = false, quiet = false } = {}) {
  errorEl.textContent = "";
  if (!quiet) { state.lastRequest = { path, body }; showCurl(); }
  let response;
  const headers = { "Content-Type": "application/json", ...keyHeader() };
  try {
    response = await fetch(API + path, { method: "POST", headers, body: JSON.stringify(body) });
  } catch (e) {
    errorEl.textContent = `The service did not answer (${e.message}). Is it running, and does it allow this page's origin?`;
    throw e;
  }
  if (!response.ok) {
    let detail = `${response.status} ${response.statusText}`;
    try { detail = (await response.json()).detail || detail; } catch (e) { /* not JSON */ }
    errorEl.textContent = response.status === 401 ? `${detail} (type it in the API key field at the top)` : `${path}: ${detail}`;
    throw new Error(detail);
  }
  return raw ? response : response.json();
}

function showCurl() {
  const r = state.lastRequest;
  if (!r) return;
  const origin = API || location.origin;
  $("curl").textContent = `curl -s ${origin}${r.path} -H 'Content-Type: application/json' \\\n  -d '${JSON.stringify(r.body)}'`;
}

// Whether the service is warming up (its first start compiles the reading's kernels): said above the board while
// GET /health says so (a 200, which no browser logs as an error); the page can be drawn on meanwhile, and its
// requests are answered once it is ready.
async function watchReady() {
  for (;;) {
    let r;
    try { r = await fetch(API + "/health", { headers: keyHeader() }); } catch (e) { return; }
    let body = {};
    try { body = await r.json(); } catch (e) { /* not JSON */ }
    state.warming = body.status === "warming up";
    $("status").hidden = !state.warming;
    if (!state.warming) return;
    $("status").textContent = "The service is warming up: it compiles the reading's kernels on its first start " +
      "(up to half a minute). Draw meanwhile; the answers come once it is ready.";
    await new Promise((done) => setTimeout(done, 1000));
  }
}

// ------------------------------------------------------------------------------------------ the curves

// A curve made now: the next name and colour, never reused (a deleted curve's name is not given again).
function newItem(points) {
  const k = state.made++;
  const name = curveFiles.curveName(k);
  return { name, color: curveFiles.colourOf(name), points, hidden: false, recon: null };
}

// A stroke, an in-between or a neighbour taken, a file opened: a curve added to the drawing, nothing dropped.
function addCurve(points) {
  state.items.push(newItem(points));
  return state.items.length - 1;
}

const indexOf = (name) => state.items.findIndex((c) => c.name === name);

// The curves mixed, as indices: the ones the user picked (`mixOf`, by name) where they are all there, else the last
// two (three) drawn that are shown, the picks first.
function mixIndices() {
  const picked = (state.mixOf || []).map(indexOf).filter((i) => i >= 0);
  const rest = state.items.map((c, i) => i).filter((i) => !state.items[i].hidden && !picked.includes(i));
  return [...picked, ...rest.slice(-Math.max(0, needed() - picked.length))].slice(0, needed());
}
const mixNames = () => mixIndices().map((i) => state.items[i].name);

// Pick a curve for the mix (or put it back): the picks are kept by name; picking beyond two (three) lets go of the
// earliest pick.
function toggleMix(index) {
  const name = state.items[index].name;
  const now = mixNames();
  const picked = now.includes(name) ? now.filter((n) => n !== name) : [...now, name].slice(-needed());
  state.mixOf = picked;
}

function select(index) {
  state.selected = index;
  state.neighbours = null;
  state.confirm = null;
  render();
  updateHint();
  updateUndoButtons();
  if (index !== null) updateNeighbours();
  else renderNeighbours();
}

function updateHint() {
  const missing = needed() - mixIndices().length;
  const sel = state.selected !== null ? state.items[state.selected] : null;
  $("hint").textContent = sel
    ? `${sel.name} selected: drag its control points to edit it, Delete to remove it, or take one of its neighbours. Esc to let go.`
    : missing > 0 ? `Draw ${missing} more curve(s): press, move, release.`
      : "Every stroke adds a curve. Tick two (three) in the list to mix them; scroll to zoom, drag with the middle button or Space to pan.";
}

// ------------------------------------------------------------------------------------------ model calls

async function reconstructAll() {
  if (!state.items.length) return;
  const items = state.items.slice();
  const body = { curves: items.map((c) => c.points), n_points: N_POINTS, output: "both", refine: refine() };
  const r = await api("/reconstruct", body, $("board-error"));
  items.forEach((c, i) => {
    c.recon = { points: r.curves[i], spline: r.splines[i], mse: r.mse[i], refine: body.refine,
      closeness: r.closeness[i], repaired: r.repaired[i] };
  });
}

function mixWeights() {
  return state.mode === "triplet" ? [state.bary.slice()] : [[1 - state.weight, state.weight]];
}

async function updateMix() {
  const mixed = mixIndices();
  if (mixed.length < needed()) { state.result = null; render(); return; }
  // the same curves as every move before: the server reads them from its encoding cache, so a move costs one
  // decode of the mixed latent (GET /metrics: curve_vae_graph_rows)
  const body = { curves: mixed.map((i) => state.items[i].points), weights: mixWeights(),
    n_points: N_POINTS, output: "both", metrics: true, refine: refine() };
  const r = await api("/interpolate", body, $("mix-error"));
  state.result = { points: r.curves[0], spline: r.splines[0], metrics: r.metrics[0], weights: r.weights[0],
    valid: r.valid[0], of: mixed.map((i) => state.items[i].name), body };
  render();
}

async function updateStrip() {
  const mixed = mixIndices();
  if (mixed.length < needed()) { state.strip = []; state.stripWeights = []; state.stripValid = []; return; }
  const steps = state.mode === "triplet" ? 4 : 5;  // pair: 5 evenly spaced; triplet: the grid of paper Fig. 8
  const body = { curves: mixed.map((i) => state.items[i].points), steps, n_points: 60, refine: refine() };
  const r = await api("/interpolate", body, $("strip-error"));
  state.strip = r.curves;
  state.stripWeights = r.weights;
  state.stripValid = r.valid;
  state.stripOf = mixed.map((i) => state.items[i].name);
}

let busy = Promise.resolve();
// After any change of the curves: the stored drawing, then the model's answers. `keepVase`: the vase shown (if any)
// is revolved again from the new mix rather than put away ("fit closely" changes the mix, not the drawing).
function curvesChanged({ keepVase = false } = {}) {
  const revolveAgain = keepVase && state.vase !== null;
  if (!keepVase) { state.vase = null; drawVase(); }
  if (state.selected !== null && state.selected >= state.items.length) state.selected = null;
  save();
  render();
  updateHint();
  updateUndoButtons();
  busy = busy.then(async () => {
    try { await reconstructAll(); await updateStrip(); await updateMix(); } catch (e) { render(); }
    if (state.selected !== null) await updateNeighbours();
    if (revolveAgain) await showVase();
  });
  return busy;
}

let mixTimer = null;
function mixChanged() {
  clearTimeout(mixTimer);
  save();
  mixTimer = setTimeout(() => { busy = busy.then(() => updateMix().catch(() => render())); }, 40);
}

function setMode(mode) {
  state.mode = mode;
  $(`mode-${mode}`).checked = true;
  $("pair-controls").hidden = mode !== "pair";
  $("triplet-controls").hidden = mode !== "triplet";
  if (state.mixOf) state.mixOf = state.mixOf.slice(-needed());
}

// ------------------------------------------------------------------------------------------ the vase

function profile() {
  if (state.result) return state.result.points;
  const shown = state.items.filter((c) => !c.hidden);
  return shown.length ? shown[shown.length - 1].points : null;
}

async function revolve(format) {
  const curve = profile();
  if (!curve) { $("vase-error").textContent = "Draw a curve first: the mix (or the last curve) is the profile."; return null; }
  return api("/revolve", { curve, segments: 48, format }, $("vase-error"), { raw: true });
}

async function showVase() {
  try {
    const r = await revolve("obj");
    if (!r) return;
    state.vase = curveVase.parseObj(await r.text());
    state.vase.faces_header = Number(r.headers.get("X-Mesh-Faces"));
    drawVase();
  } catch (e) { /* shown next to the vase */ }
}

// The vase's mesh, drawn by vase.js at the slider's turn; the canvas hidden until there is one.
function drawVase() {
  $("vase-view").hidden = !state.vase;
  curveVase.draw($("vase-view"), state.vase, Number($("turn").value));
}

// The priors this server offers (GET /model): the learned one where the model ships it, the standard N(0, I), and
// those fitted to users' own curves. Without an answer the menu keeps the server's default.
async function listPriors() {
  let info;
  try {
    const response = await fetch(API + "/model", { headers: keyHeader() });
    if (!response.ok) return;
    info = await response.json();
  } catch (e) { return; }
  const names = [...(info.prior ? ["learned"] : []), "standard", ...Object.keys(info.priors || {})];
  $("prior").replaceChildren(...names.map((name) => {
    const option = document.createElement("option");
    option.value = name;
    option.textContent = name;
    return option;
  }));
}
