// curve-vae's page: draw curves, reconstruct and interpolate them through the REST API, take the result away.
// Plain JavaScript, no build step, no CDN. Everything it shows comes from the same endpoints any front-end uses;
// `?api=https://host:port` points it at a service on another origin (which must allow it with CORS).
"use strict";

const API = new URLSearchParams(location.search).get("api") || "";
const W = 1000, H = 700;  // the board's viewBox; API coordinates are the board's with y pointing up
const COLORS = ["#1f77b4", "#2ca02c", "#9467bd"];
const NAMES = ["A", "B", "C"];
const N_POINTS = 100;
const FIT_STEPS = 10;  // "fit closely": the `refine` of every call that encodes the drawn curves
const refine = () => ($("fit-closely").checked ? FIT_STEPS : 0);

// Everything the page shows, in API coordinates; window.curveVae for tests and the console.
const state = {
  curves: [], recon: [], mode: "pair", weight: 0.5, bary: [1 / 3, 1 / 3, 1 / 3],
  result: null, strip: [], lastRequest: null, vase: null,
};
window.curveVae = state;

const $ = (id) => document.getElementById(id);
let stroke = null;  // the points of the stroke being drawn, in board coordinates
const toApi = ([x, y]) => [x, H - y];
const toBoard = ([x, y]) => [x, H - y];
const round = (v) => Math.round(v * 1000) / 1000;

// ------------------------------------------------------------------------------------------ API

// The API key the user typed, as the header the service reads.
const keyHeader = () => ($("api-key").value ? { "X-API-Key": $("api-key").value } : {});

async function api(path, body, errorEl, { raw = false } = {}) {
  errorEl.textContent = "";
  state.lastRequest = { path, body };
  showCurl();
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

// ------------------------------------------------------------------------------------------ drawing

const SVG_NS = "http://www.w3.org/2000/svg";
function el(name, attrs, parent) {
  const e = document.createElementNS(SVG_NS, name);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, v);
  if (parent) parent.appendChild(e);
  return e;
}
const pathOf = (pts) => pts.map((p, i) => `${i ? "L" : "M"}${round(p[0])},${round(p[1])}`).join(" ");

function render() {
  const board = $("board");
  board.replaceChildren();
  // the drawn strokes as pale bands, so that the dashed reconstructions drawn over them stay in sight
  state.curves.forEach((c, i) => {
    el("path", { d: pathOf(c.map(toBoard)), fill: "none", stroke: COLORS[i], "stroke-width": 6, "stroke-opacity": 0.3,
      "stroke-linecap": "round", "stroke-linejoin": "round", class: "input" }, board);
  });
  placeLabels(state.curves).forEach(([x, y], i) => {
    el("text", { x, y, fill: COLORS[i], "font-size": 22, "font-weight": "bold", class: "label" }, board)
      .textContent = NAMES[i];
  });
  state.recon.forEach((r, i) => {
    if (!r) return;
    el("path", { d: pathOf(r.points.map(toBoard)), fill: "none", stroke: COLORS[i], "stroke-width": 2,
      "stroke-dasharray": "7 4", class: "reconstruction" }, board);
    if ($("show-ctrl").checked && r.spline) drawControl(board, r.spline, COLORS[i]);
  });
  if (state.result) {
    el("path", { d: pathOf(state.result.points.map(toBoard)), fill: "none", stroke: "#d62728", "stroke-width": 3.5,
      id: "interpolant", class: "interpolant" }, board);
    if ($("show-ctrl").checked && state.result.spline) drawControl(board, state.result.spline, "#d62728");
  }
  if (stroke) drawStroke();  // a stroke in progress survives a redraw by an answer arriving meanwhile
  renderStrip();
  renderMetrics();
}

// Where each curve's name goes: beside its start, else its end or middle, the first place at least LABEL_GAP from
// the names placed before it (curves drawn from one point, or samples near each other, would stack them).
const LABEL_GAP = 34;
function placeLabels(curves) {
  const placed = [];
  for (const c of curves) {
    const spots = [c[0], c[c.length - 1], c[Math.floor(c.length / 2)]].map(toBoard)
      .flatMap(([x, y]) => [[x + 8, y - 8], [x + 8, y + 26], [x - 26, y - 8], [x - 26, y + 26]]);
    const far = (p) => placed.every((q) => Math.hypot(p[0] - q[0], p[1] - q[1]) >= LABEL_GAP);
    let spot = spots.find(far);
    for (let k = 1; !spot; k++) spot = spots.map(([x, y]) => [x + LABEL_GAP * k, y]).find(far);
    placed.push(spot);
  }
  return placed;
}

function drawStroke() {
  const path = $("stroke") || el("path", { id: "stroke", fill: "none", stroke: "#555", "stroke-width": 2 }, $("board"));
  path.setAttribute("d", pathOf(stroke));
}

function drawControl(board, spline, color) {
  const pts = spline.control_points.map(toBoard);
  el("path", { d: pathOf(pts), fill: "none", stroke: color, "stroke-width": 1, opacity: 0.6, class: "control-polygon" },
    board);
  for (const [x, y] of pts) el("circle", { cx: x, cy: y, r: 3.5, fill: color, opacity: 0.6 }, board);
}

function renderStrip() {
  // pair: one row; triplet: the barycentric grid as a triangle, row k holding the k+1 mixes with A's weight (n-k)/n
  const strip = $("strip");
  strip.replaceChildren();
  const rows = [];
  if (state.mode === "triplet") {
    for (let k = 0, i = 0; i < state.strip.length; k++) { rows.push(state.strip.slice(i, i + k + 1)); i += k + 1; }
  } else if (state.strip.length) rows.push(state.strip);
  strip.classList.toggle("triangle-grid", state.mode === "triplet");
  for (const row of rows) {
    const div = document.createElement("div");
    div.className = "strip-row";
    strip.appendChild(div);
    for (const curve of row) thumbnail(div, curve);
  }
}

function thumbnail(parent, curve) {
  const xs = curve.map((p) => p[0]), ys = curve.map((p) => p[1]);
  const pad = 10, x0 = Math.min(...xs) - pad, y0 = Math.min(...ys) - pad;
  const w = Math.max(...xs) - x0 + pad, h = Math.max(...ys) - y0 + pad;
  const svg = el("svg", { viewBox: `${x0} ${-(y0 + h)} ${w} ${h}`, class: "thumb" }, parent);
  el("path", { d: pathOf(curve.map(([x, y]) => [x, -y])), fill: "none", stroke: "#d62728",
    "stroke-width": Math.max(w, h) / 60 }, svg);
}

function renderMetrics() {
  const dl = $("metrics");
  dl.replaceChildren();
  const rows = [];
  // how close each reconstruction came, relative to its curve's size (the answer's closeness)
  state.recon.forEach((r, i) => {
    if (!r || !r.closeness) return;
    const c = r.closeness, pct = (v) => (v === null ? "–" : `${(100 * v).toFixed(2)}%`);
    rows.push([`${"ABC"[i]} reconstructed within`,
      `RMS ${pct(c.rms)}, worst ${pct(c.max)} of its size${r.repaired ? " (untangled)" : ""}`]);
  });
  const m = state.result && state.result.metrics;
  if (m) {
    rows.push(
      ["mix roughness", `${m.smoothness.roughness.toFixed(3)}°`],
      ["mix sharpest turn", `${m.smoothness.max_turn.toFixed(1)}°`],
      ["mix self-intersects", m.self_intersects ? "yes" : "no"],
      ["mix control points", state.result.spline ? state.result.spline.control_points.length : "–"],
    );
  }
  for (const [k, v] of rows) {
    const dt = document.createElement("dt"); dt.textContent = k; dl.appendChild(dt);
    const dd = document.createElement("dd"); dd.textContent = v; dd.dataset.metric = k; dl.appendChild(dd);
  }
}

// Pointer events cover mouse, pen and touch alike.
function boardPoint(ev) {
  const r = $("board").getBoundingClientRect();
  return [((ev.clientX - r.left) / r.width) * W, ((ev.clientY - r.top) / r.height) * H];
}
$("board").addEventListener("pointerdown", (ev) => {
  ev.preventDefault();
  $("board").setPointerCapture(ev.pointerId);
  stroke = [boardPoint(ev)];
  drawStroke();
});
$("board").addEventListener("pointermove", (ev) => {
  if (!stroke) return;
  const p = boardPoint(ev), q = stroke[stroke.length - 1];
  if (Math.hypot(p[0] - q[0], p[1] - q[1]) < 3) return;
  stroke.push(p);
  drawStroke();
});
$("board").addEventListener("pointerup", () => finishStroke());
$("board").addEventListener("pointercancel", () => { stroke = null; render(); });

function finishStroke() {
  const pts = stroke;
  stroke = null;
  if (!pts || pts.length < 4) {
    $("board-error").textContent = "Too short: draw a longer stroke (at least 4 points).";
    render();
    return;
  }
  $("board-error").textContent = "";
  addCurve(pts.map(toApi));
  curvesChanged();
}

// A new curve (API coordinates) in place of the oldest once the mode's two or three are there.
function addCurve(curve) {
  if (state.curves.length >= needed()) { state.curves.shift(); state.recon.shift(); }
  state.curves.push(curve);
  state.recon.push(null);
}

// ------------------------------------------------------------------------------------------ model calls

async function reconstructAll() {
  if (!state.curves.length) return;
  const body = { curves: state.curves, n_points: N_POINTS, output: "both", refine: refine() };
  const r = await api("/reconstruct", body, $("board-error"));
  state.recon = r.curves.map((points, i) => ({ points, spline: r.splines[i], mse: r.mse[i], refine: body.refine,
    closeness: r.closeness[i], repaired: r.repaired[i] }));
}

function needed() { return state.mode === "triplet" ? 3 : 2; }

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
  if (state.curves.length < needed()) { state.strip = []; return; }
  const steps = state.mode === "triplet" ? 4 : 5;  // pair: 5 evenly spaced; triplet: the grid of paper Fig. 8
  const body = { curves: state.curves.slice(0, needed()), steps, n_points: 60, refine: refine() };
  const r = await api("/interpolate", body, $("strip-error"));
  state.strip = r.curves;
}

let busy = Promise.resolve();
function curvesChanged() {
  render();
  $("hint").textContent = state.curves.length < needed()
    ? `Draw ${needed() - state.curves.length} more curve(s).` : "Move the weights; draw again to replace the oldest curve.";
  busy = busy.then(async () => {
    try { await reconstructAll(); await updateStrip(); await updateMix(); } catch (e) { render(); }
  });
  return busy;
}

let mixTimer = null;
function mixChanged() {
  clearTimeout(mixTimer);
  mixTimer = setTimeout(() => { busy = busy.then(() => updateMix().catch(() => render())); }, 40);
}

// ------------------------------------------------------------------------------------------ controls

$("weight").addEventListener("input", () => {
  state.weight = Number($("weight").value);
  $("weight-value").textContent = state.weight.toFixed(2);
  mixChanged();
});

function setMode(mode) {
  state.mode = mode;
  $(`mode-${mode}`).checked = true;
  $("pair-controls").hidden = mode !== "pair";
  $("triplet-controls").hidden = mode !== "triplet";
  state.curves = state.curves.slice(-needed());
  state.recon = state.recon.slice(-needed());
}
for (const mode of ["pair", "triplet"]) {
  $(`mode-${mode}`).addEventListener("change", () => { setMode(mode); curvesChanged(); });
}

$("show-ctrl").addEventListener("change", render);
$("fit-closely").addEventListener("change", curvesChanged);
$("clear").addEventListener("click", () => {
  Object.assign(state, { curves: [], recon: [], result: null, strip: [], vase: null, lastRequest: null });
  $("curl").textContent = "";
  for (const id of ["board-error", "mix-error", "strip-error", "vase-error"]) $(id).textContent = "";
  drawVase();
  curvesChanged();
});
$("sample").addEventListener("click", async () => {
  try {
    const k = needed(), size = Math.min((0.8 * W) / k, 0.75 * H);
    const body = { count: k, n_points: N_POINTS, frame: { center: [0, 0], size } };
    if ($("prior").value) body.prior = $("prior").value;
    const r = await api("/sample", body, $("board-error"));
    // side by side, each in its own slot of the board, not all about its centre
    state.curves = r.curves.map((c, i) => placed(c, [(W * (i + 0.5)) / k, H / 2]));
    state.recon = r.curves.map(() => null);
    await curvesChanged();
  } catch (e) { /* shown next to the board */ }
});

// The curve moved so that its bounding box is centred on `center`, and scaled down where it would not fit `box`.
function placed(curve, center, box = [W / needed(), H]) {
  const xs = curve.map((p) => p[0]), ys = curve.map((p) => p[1]);
  const [x0, x1, y0, y1] = [Math.min(...xs), Math.max(...xs), Math.min(...ys), Math.max(...ys)];
  const s = Math.min(1, (0.9 * box[0]) / (x1 - x0 || 1), (0.9 * box[1]) / (y1 - y0 || 1));
  return curve.map(([x, y]) => [center[0] + s * (x - (x0 + x1) / 2), center[1] + s * (y - (y0 + y1) / 2)]);
}

// The barycentric triangle: A at the top, B bottom left, C bottom right.
const TRI = [[110, 12], [12, 185], [208, 185]];
function renderTriangle() {
  const svg = $("triangle");
  svg.replaceChildren();
  el("path", { d: pathOf(TRI) + " Z", fill: "#f4f4ff", stroke: "#888" }, svg);
  TRI.forEach(([x, y], i) => {
    el("text", { x: x + (i === 1 ? -10 : i === 2 ? 2 : 6), y: y + (i ? 12 : 2), fill: COLORS[i], "font-size": 14 }, svg)
      .textContent = NAMES[i];
  });
  const [x, y] = [0, 1].map((k) => state.bary.reduce((s, w, i) => s + w * TRI[i][k], 0));
  el("circle", { cx: x, cy: y, r: 6, fill: "#d62728", id: "bary-dot" }, svg);
  $("bary-value").textContent = state.bary.map((w) => w.toFixed(2)).join(", ");
}
function pickBary(ev) {
  const r = $("triangle").getBoundingClientRect();
  const p = [((ev.clientX - r.left) / r.width) * 220, ((ev.clientY - r.top) / r.height) * 200];
  const [a, b, c] = TRI;
  const det = (b[1] - c[1]) * (a[0] - c[0]) + (c[0] - b[0]) * (a[1] - c[1]);
  let wa = ((b[1] - c[1]) * (p[0] - c[0]) + (c[0] - b[0]) * (p[1] - c[1])) / det;
  let wb = ((c[1] - a[1]) * (p[0] - c[0]) + (a[0] - c[0]) * (p[1] - c[1])) / det;
  wa = Math.max(0, wa); wb = Math.max(0, wb);
  let wc = Math.max(0, 1 - wa - wb);
  const s = wa + wb + wc;
  state.bary = [wa / s, wb / s, wc / s];
  renderTriangle();
  mixChanged();
}
let picking = false;
$("triangle").addEventListener("pointerdown", (ev) => { picking = true; $("triangle").setPointerCapture(ev.pointerId); pickBary(ev); });
$("triangle").addEventListener("pointermove", (ev) => { if (picking) pickBary(ev); });
$("triangle").addEventListener("pointerup", () => { picking = false; });

// ------------------------------------------------------------------------------------------ take it away

function download(name, type, data) {
  const a = document.createElement("a");
  a.href = URL.createObjectURL(new Blob([data], { type }));
  a.download = name;
  document.body.appendChild(a);
  a.click();
  setTimeout(() => { URL.revokeObjectURL(a.href); a.remove(); }, 1000);
}
function exported() {
  const curves = state.curves.map((c, i) => ({ name: NAMES[i], role: "input", points: c }));
  if (state.result) {
    curves.push({ name: "mix", role: "interpolant", weights: state.result.weights, points: state.result.points,
      spline: state.result.spline });
  }
  return curves;
}
$("download-json").addEventListener("click", () => {
  download("curves.json", "application/json", JSON.stringify({ curves: exported() }, null, 1));
});
$("download-csv").addEventListener("click", () => {
  const rows = ["curve,role,index,x,y"];
  for (const c of exported()) c.points.forEach(([x, y], i) => rows.push(`${c.name},${c.role},${i},${x},${y}`));
  download("curves.csv", "text/csv", rows.join("\n") + "\n");
});
$("download-svg").addEventListener("click", () => {
  const svg = $("board").cloneNode(true);
  svg.setAttribute("xmlns", SVG_NS);
  svg.setAttribute("width", W);
  svg.setAttribute("height", H);
  download("curves.svg", "image/svg+xml", new XMLSerializer().serializeToString(svg));
});
// DXF for CAD: the drawn curves as polylines, the reconstructions and the mix as SPLINE entities, exactly.
$("download-dxf").addEventListener("click", () => {
  const items = state.curves.map((points, i) => ({ layer: `input-${NAMES[i]}`, points }));
  state.recon.forEach((r, i) => { if (r && r.spline) items.push({ layer: `reconstruction-${NAMES[i]}`, spline: r.spline }); });
  if (state.result && state.result.spline) items.push({ layer: "interpolant", spline: state.result.spline });
  download("curves.dxf", "image/vnd.dxf", curveFiles.dxf(items));
});
$("copy-curl").addEventListener("click", async () => {
  showCurl();
  try { await navigator.clipboard.writeText($("curl").textContent); } catch (e) { /* shown below anyway */ }
});

// ------------------------------------------------------------------------------------------ open a file

// Curves from a file picked or dropped on the board (JSON, CSV, SVG, DAT; files.js reads them here, in the
// browser): up to three, in pair or triplet mode as many as there are; one joins the drawn curves.
async function openFile(file) {
  $("board-error").textContent = "";
  let read;
  try {
    read = curveFiles.parse(file.name, await file.text());
  } catch (e) {
    $("board-error").textContent = e.message;
    return;
  }
  const curves = onBoard(read.curves.slice(0, 3));
  if (curves.length > 1) {
    setMode(curves.length === 3 ? "triplet" : "pair");
    Object.assign(state, { curves: [], recon: [] });
  }
  curves.forEach(addCurve);
  const done = curvesChanged();
  $("hint").textContent = [`${file.name}: ${curves.length} of its ${read.curves.length} curve(s) opened.`,
    ...read.notes].join(" ");
  await done;
}

// Curves as they are where they lie on the board (the page's own exports); else scaled and centred onto it.
function onBoard(curves) {
  const all = curves.flat();
  const xs = all.map((p) => p[0]), ys = all.map((p) => p[1]);
  const [x0, x1, y0, y1] = [Math.min(...xs), Math.max(...xs), Math.min(...ys), Math.max(...ys)];
  if (x0 >= 0 && x1 <= W && y0 >= 0 && y1 <= H) return curves;
  const s = Math.min((0.8 * W) / (x1 - x0 || 1), (0.8 * H) / (y1 - y0 || 1));
  return curves.map((c) => c.map(([x, y]) => [W / 2 + s * (x - (x0 + x1) / 2), H / 2 + s * (y - (y0 + y1) / 2)]));
}

$("open-file").addEventListener("change", () => {
  const file = $("open-file").files[0];
  $("open-file").value = "";  // the same file picked again is read again
  if (file) openFile(file);
});
$("board").addEventListener("dragover", (ev) => ev.preventDefault());
$("board").addEventListener("drop", (ev) => {
  ev.preventDefault();
  const file = ev.dataTransfer.files[0];
  if (file) openFile(file);
});

// ------------------------------------------------------------------------------------------ the vase

function profile() { return state.result ? state.result.points : state.curves[0]; }

async function revolve(format) {
  const curve = profile();
  if (!curve) { $("vase-error").textContent = "Draw a curve first: the mix (or curve A) is the profile."; return null; }
  return api("/revolve", { curve, segments: 48, format }, $("vase-error"), { raw: true });
}

$("vase").addEventListener("click", async () => {
  try {
    const r = await revolve("obj");
    if (!r) return;
    state.vase = curveVase.parseObj(await r.text());
    state.vase.faces_header = Number(r.headers.get("X-Mesh-Faces"));
    drawVase();
  } catch (e) { /* shown next to the vase */ }
});
for (const format of ["obj", "stl"]) {
  $(`download-${format}`).addEventListener("click", async () => {
    try {
      const r = await revolve(format);
      if (r) download(`vase.${format}`, format === "obj" ? "model/obj" : "model/stl", await r.blob());
    } catch (e) { /* shown next to the vase */ }
  });
}
$("turn").addEventListener("input", drawVase);

// The vase's mesh, drawn by vase.js at the slider's turn (a blank canvas without one).
function drawVase() { curveVase.draw($("vase-view"), state.vase, Number($("turn").value)); }

// The key lives for this browser tab only.
$("api-key").value = sessionStorage.getItem("curve-vae-api-key") || "";
$("api-key").addEventListener("change", () => {
  sessionStorage.setItem("curve-vae-api-key", $("api-key").value);
  listPriors();
});

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

renderTriangle();
render();
listPriors();
