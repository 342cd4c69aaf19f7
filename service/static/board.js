// curve-vae's page: what the board shows (the curves, their reconstructions, the mix, names placed off the curves,
// the selected curve's control points), the mix's measures in words, and drawing on the board with mouse, pen or
// touch (view.js turns the wheel, two fingers and the middle button into zoom and pan).
"use strict";

const SVG_NS = "http://www.w3.org/2000/svg";
function el(name, attrs, parent) {
  const e = document.createElementNS(SVG_NS, name);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, v);
  if (parent) parent.appendChild(e);
  return e;
}
const pathOf = (pts) => pts.map((p, i) => `${i ? "L" : "M"}${round(p[0])},${round(p[1])}`).join(" ");

let stroke = null;  // the points of the stroke being drawn, in board coordinates

function render() {
  const board = $("board");
  board.replaceChildren();
  applyView();
  const zoom = W / state.view.w;  // board units a screen unit of the first view: names and dots keep their size
  if (!state.items.length && !stroke) {
    el("text", { x: W / 2, y: H / 2, "text-anchor": "middle", class: "first-run" }, board)
      .textContent = "Draw a curve here: press, move, release";
    el("text", { x: W / 2, y: H / 2 + 34, "text-anchor": "middle", class: "first-run small" }, board)
      .textContent = "or take random samples, or open a file (drop it here)";
  }
  const mixed = mixIndices();
  // the drawn strokes as pale bands, so that the dashed reconstructions drawn over them stay in sight
  state.items.forEach((c, i) => {
    if (c.hidden) return;
    const selected = state.selected === i;
    el("path", { d: pathOf(c.points.map(toBoard)), fill: "none", stroke: c.color, "stroke-width": selected ? 12 : 6,
      "stroke-opacity": selected ? 0.45 : 0.3, "stroke-linecap": "round", "stroke-linejoin": "round",
      class: `input${selected ? " selected" : ""}${mixed.includes(i) ? " mixed" : ""}`, "data-name": c.name }, board);
  });
  state.items.forEach((c, i) => {
    if (c.hidden || !c.recon) return;
    el("path", { d: pathOf(c.recon.points.map(toBoard)), fill: "none", stroke: c.color, "stroke-width": 2,
      "stroke-dasharray": "7 4", class: "reconstruction", "data-of": c.name }, board);
    if (($("show-ctrl").checked || state.selected === i) && c.recon.spline) {
      drawControl(board, c.recon.spline, c.color, { handles: state.selected === i, zoom });
    }
  });
  if (state.result) {
    el("path", { d: pathOf(state.result.points.map(toBoard)), fill: "none", stroke: MIX_COLOR, "stroke-width": 3.5,
      id: "interpolant", class: "interpolant" }, board);
    if ($("show-ctrl").checked && state.result.spline) drawControl(board, state.result.spline, MIX_COLOR, { zoom });
  }
  const named = state.items.filter((c) => !c.hidden).map((c) => ({ curve: c.points, text: c.name, color: c.color }));
  if (state.result) named.push({ curve: state.result.points, text: "mix", color: MIX_COLOR });
  placeLabels(named, zoom).forEach(([x, y], i) => {
    el("text", { x, y, fill: named[i].color, class: "label", "text-anchor": "middle", "dominant-baseline": "middle",
      "font-size": 22 / zoom, "stroke-width": 5 / zoom }, board).textContent = named[i].text;
  });
  if (editing) drawEdit(board, zoom);
  if (stroke) drawStroke();  // a stroke in progress survives a redraw by an answer arriving meanwhile
  renderCurveList();
  renderMixLabels();
  renderStrip();
  renderMetrics();
}

// Where each name goes: near its curve's start (else its end or middle), at the first spot clear of every curve on
// the board and of the names placed before it; the spot farthest from the curves where none is clear. Distances in
// board units of the first view, so names keep their place on screen as the view zooms.
const LABEL_CLEAR = 16, LABEL_GAP = 34;
function placeLabels(items, zoom) {
  const shown = state.items.filter((c) => !c.hidden);
  const all = [...shown.map((c) => c.points), ...shown.filter((c) => c.recon).map((c) => c.recon.points),
    ...(state.result ? [state.result.points] : [])].map((c) => c.map(toBoard));
  const clearance = ([x, y]) => Math.min(...all.map((c) => Math.min(...c.map(([px, py]) => Math.hypot(px - x, py - y)))));
  const v = state.view, placed = [];
  for (const { curve } of items) {
    const anchors = [curve[0], curve[curve.length - 1], curve[Math.floor(curve.length / 2)]].map(toBoard);
    const spots = anchors.flatMap(([x, y]) => [22, 36, 52].flatMap((r) => [0, 1, 2, 3, 4, 5, 6, 7].map((k) =>
      [x + (r / zoom) * Math.cos((k * Math.PI) / 4), y + (r / zoom) * Math.sin((k * Math.PI) / 4)])))
      .filter(([x, y]) => x > v.x + 14 / zoom && x < v.x + v.w - 14 / zoom && y > v.y + 14 / zoom && y < v.y + v.h - 10 / zoom)
      .filter((p) => placed.every((q) => Math.hypot(p[0] - q[0], p[1] - q[1]) >= LABEL_GAP / zoom));
    let best = spots.find((p) => clearance(p) >= LABEL_CLEAR / zoom);
    if (!best) best = spots.reduce((a, p) => (!a || clearance(p) > clearance(a) ? p : a), null) || anchors[0];
    placed.push(best);
  }
  return placed;
}

function drawStroke() {
  const path = $("stroke") || el("path", { id: "stroke", fill: "none", stroke: "#555", "stroke-width": 2 }, $("board"));
  path.setAttribute("d", pathOf(stroke));
}

// A spline's control polygon; with `handles`, its points as handles to drag (view.js), the curve then read again.
function drawControl(board, spline, color, { handles = false, zoom = 1 } = {}) {
  const pts = spline.control_points.map(toBoard);
  el("path", { d: pathOf(pts), fill: "none", stroke: color, "stroke-width": 1, opacity: 0.6, class: "control-polygon" },
    board);
  pts.forEach(([x, y], k) => {
    el("circle", { cx: x, cy: y, r: (handles ? 6 : 3.5) / zoom, fill: handles ? "#fff" : color, stroke: color,
      "stroke-width": 2, opacity: handles ? 0.95 : 0.6, class: handles ? "handle" : "control-point",
      "data-k": k }, board);
  });
}

// A small drawing of a curve (API coordinates) in `parent`, its caption under it; returns the figure.
function thumbnail(parent, curve, { caption = "", color = MIX_COLOR, title = "" } = {}) {
  const fig = document.createElement("button");
  fig.type = "button";
  fig.className = "thumb";
  if (title) fig.title = title;
  const xs = curve.map((p) => p[0]), ys = curve.map((p) => p[1]);
  const pad = 10, x0 = Math.min(...xs) - pad, y0 = Math.min(...ys) - pad;
  const w = Math.max(...xs) - x0 + pad, h = Math.max(...ys) - y0 + pad;
  const svg = el("svg", { viewBox: `${x0} ${-(y0 + h)} ${w} ${h}`, "aria-hidden": "true" }, fig);
  el("path", { d: pathOf(curve.map(([x, y]) => [x, -y])), fill: "none", stroke: color,
    "stroke-width": Math.max(w, h) / 45 }, svg);
  if (caption) {
    const span = document.createElement("span");
    span.className = "caption";
    span.textContent = caption;
    fig.appendChild(span);
  }
  parent.appendChild(fig);
  return fig;
}

const pct = (v) => (v === null || v === undefined ? "–" : `${(100 * v).toFixed(2)}%`);
// How close a reconstruction came, in words: its RMS distance and its largest, as shares of the curve's size.
const closenessWords = (r) => (r && r.closeness
  ? `${pct(r.closeness.rms)} off, ${pct(r.closeness.max)} at most${r.repaired ? " (untangled)" : ""}`
  : "");

// The mix's measures in plain words, with their units.
function renderMetrics() {
  const dl = $("metrics");
  dl.replaceChildren();
  const m = state.result && state.result.metrics;
  if (!m) return;
  const ctrl = state.result.spline ? state.result.spline.control_points.length : "–";
  const rows = [
    ["mix smoothness", "turning",
      `${m.smoothness.roughness.toFixed(2)}° a point on average, ${m.smoothness.max_turn.toFixed(1)}° at the sharpest`],
    ["mix shape", "shape", `${m.self_intersects ? "crosses itself" : "no self-crossing"}; ${ctrl} control points`],
  ];
  for (const [key, name, value] of rows) {
    const dt = document.createElement("dt"); dt.textContent = name; dl.appendChild(dt);
    const dd = document.createElement("dd"); dd.textContent = value; dd.dataset.metric = key; dl.appendChild(dd);
  }
}

// The curve shown within reach of a board point (the nearest, within REACH screen units), or null.
const REACH = 14;
function curveAt([x, y]) {
  let best = null, bestD = REACH * (state.view.w / W);
  state.items.forEach((c, i) => {
    if (c.hidden) return;
    const d = Math.min(...c.points.map(toBoard).map(([px, py]) => Math.hypot(px - x, py - y)));
    if (d < bestD) { best = i; bestD = d; }
  });
  return best;
}

// A pointer's place on the board, in board units, through the view (view.js).
function boardPoint(ev) {
  const r = $("board").getBoundingClientRect(), v = state.view;
  return [v.x + ((ev.clientX - r.left) / r.width) * v.w, v.y + ((ev.clientY - r.top) / r.height) * v.h];
}

// Drawing: a press, moves and a release; a press released where it began is a click (select). The view's own
// gestures (view.js: the middle button, Space, two fingers) and the handles come first.
function startStroke(ev) {
  stroke = [boardPoint(ev)];
  drawStroke();
}
function moveStroke(ev) {
  if (!stroke) return;
  const p = boardPoint(ev), q = stroke[stroke.length - 1];
  if (Math.hypot(p[0] - q[0], p[1] - q[1]) < 3 * (state.view.w / W)) return;
  stroke.push(p);
  drawStroke();
}

function finishStroke() {
  const pts = stroke;
  stroke = null;
  if (pts && pts.length <= 2) {  // a click: select the curve under it, or let go of the selection
    $("board-error").textContent = "";
    select(curveAt(pts[pts.length - 1]));
    return;
  }
  if (!pts || pts.length < 4) {
    $("board-error").textContent = "Too short: draw a longer stroke (at least 4 points).";
    render();
    return;
  }
  $("board-error").textContent = "";
  remember();
  addCurve(pts.map(toApi));
  curvesChanged();
}
