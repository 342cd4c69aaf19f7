// curve-vae's page: draw curves, reconstruct and interpolate them through the REST API, take the result away.
// Plain JavaScript, no build step, no CDN: app.js (state, the API, the model calls), board.js (what the board
// shows), history.js (undo, redo, the drawing kept across reloads), explore.js (in-betweens, the sweep, the
// neighbours of a curve), controls.js (the buttons and keys), files.js and vase.js. Everything it shows comes from
// the same endpoints any front-end uses; `?api=https://host:port` points it at a service on another origin.
"use strict";

const API = new URLSearchParams(location.search).get("api") || "";
const W = 1000, H = 700;  // the board's viewBox; API coordinates are the board's with y pointing up
const COLORS = ["#1f77b4", "#2ca02c", "#9467bd"];
const MIX_COLOR = "#d62728";
const NAMES = ["A", "B", "C"];
const N_POINTS = 100;
const FIT_STEPS = 10;  // "fit closely": the `refine` of every call that encodes the drawn curves
const refine = () => ($("fit-closely").checked ? FIT_STEPS : 0);

// Everything the page shows, in API coordinates; window.curveVae for tests and the console.
const state = {
  curves: [], recon: [], mode: "pair", weight: 0.5, bary: [1 / 3, 1 / 3, 1 / 3],
  result: null, strip: [], stripWeights: [], lastRequest: null, vase: null, selected: null, neighbours: null,
};
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

// ------------------------------------------------------------------------------------------ curves

// A new curve (API coordinates): in place of the selected one, else the newest, the oldest leaving once the mode's
// two or three are there.
function addCurve(curve) {
  if (state.selected !== null && state.selected < state.curves.length) {
    state.curves[state.selected] = curve;
    state.recon[state.selected] = null;
    state.selected = null;
    return;
  }
  if (state.curves.length >= needed()) { state.curves.shift(); state.recon.shift(); }
  state.curves.push(curve);
  state.recon.push(null);
}

function select(index) {
  state.selected = index;
  state.neighbours = null;
  render();
  updateHint();
  updateUndoButtons();
  if (index !== null) updateNeighbours();
  else renderNeighbours();
}

function updateHint() {
  const missing = needed() - state.curves.length;
  $("hint").textContent = state.selected !== null
    ? `${NAMES[state.selected]} selected: draw to redraw it, Delete to remove it, or take one of its neighbours. Esc to let go.`
    : missing > 0 ? `Draw ${missing} more curve(s): press, move, release.`
      : "Move the weights; click a curve to select it; draw again to replace the oldest curve.";
}

// ------------------------------------------------------------------------------------------ model calls

async function reconstructAll() {
  if (!state.curves.length) return;
  const body = { curves: state.curves, n_points: N_POINTS, output: "both", refine: refine() };
  const r = await api("/reconstruct", body, $("board-error"));
  state.recon = r.curves.map((points, i) => ({ points, spline: r.splines[i], mse: r.mse[i], refine: body.refine,
    closeness: r.closeness[i], repaired: r.repaired[i] }));
}

function mixWeights() {
  return state.mode === "triplet" ? [state.bary.slice()] : [[1 - state.weight, state.weight]];
}

async function updateMix() {
  if (state.curves.length < needed()) { state.result = null; render(); return; }
  // the same curves as every move before: the server reads them from its encoding cache, so a move costs one
  // decode of the mixed latent (GET /metrics: curve_vae_graph_rows)
  const body = { curves: state.curves.slice(0, needed()), weights: mixWeights(),
    n_points: N_POINTS, output: "both", metrics: true, refine: refine() };
  const r = await api("/interpolate", body, $("mix-error"));
  state.result = { points: r.curves[0], spline: r.splines[0], metrics: r.metrics[0], weights: r.weights[0], body };
  render();
}

async function updateStrip() {
  if (state.curves.length < needed()) { state.strip = []; state.stripWeights = []; return; }
  const steps = state.mode === "triplet" ? 4 : 5;  // pair: 5 evenly spaced; triplet: the grid of paper Fig. 8
  const body = { curves: state.curves.slice(0, needed()), steps, n_points: 60, refine: refine() };
  const r = await api("/interpolate", body, $("strip-error"));
  state.strip = r.curves;
  state.stripWeights = r.weights;
}

let busy = Promise.resolve();
// After any change of the curves: the vase is stale, the stored drawing is not; then the model's answers.
function curvesChanged() {
  state.vase = null;
  drawVase();
  if (state.selected !== null && state.selected >= state.curves.length) state.selected = null;
  save();
  render();
  updateHint();
  updateUndoButtons();
  busy = busy.then(async () => {
    try { await reconstructAll(); await updateStrip(); await updateMix(); } catch (e) { render(); }
    if (state.selected !== null) await updateNeighbours();
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
  state.curves = state.curves.slice(-needed());
  state.recon = state.recon.slice(-needed());
  state.selected = null;
}

// ------------------------------------------------------------------------------------------ the vase

function profile() { return state.result ? state.result.points : state.curves[0]; }

async function revolve(format) {
  const curve = profile();
  if (!curve) { $("vase-error").textContent = "Draw a curve first: the mix (or curve A) is the profile."; return null; }
  return api("/revolve", { curve, segments: 48, format }, $("vase-error"), { raw: true });
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
