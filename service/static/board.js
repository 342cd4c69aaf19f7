// curve-vae's page: what the board shows (the curves, their reconstructions, the mix, names placed off the curves,
// the selection), the closeness of each curve, and drawing on it with mouse, pen or touch.
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
  if (!state.curves.length && !stroke) {
    el("text", { x: W / 2, y: H / 2, "text-anchor": "middle", class: "first-run" }, board)
      .textContent = "Draw a curve here: press, move, release";
    el("text", { x: W / 2, y: H / 2 + 34, "text-anchor": "middle", class: "first-run small" }, board)
      .textContent = "or take random samples, or open a file (drop it here)";
  }
  // the drawn strokes as pale bands, so that the dashed reconstructions drawn over them stay in sight
  state.curves.forEach((c, i) => {
    const selected = state.selected === i;
    el("path", { d: pathOf(c.map(toBoard)), fill: "none", stroke: COLORS[i], "stroke-width": selected ? 12 : 6,
      "stroke-opacity": selected ? 0.45 : 0.3, "stroke-linecap": "round", "stroke-linejoin": "round",
      class: selected ? "input selected" : "input", "data-name": NAMES[i] }, board);
  });
  state.recon.forEach((r, i) => {
    if (!r) return;
    el("path", { d: pathOf(r.points.map(toBoard)), fill: "none", stroke: COLORS[i], "stroke-width": 2,
      "stroke-dasharray": "7 4", class: "reconstruction", "data-of": NAMES[i] }, board);
    if ($("show-ctrl").checked && r.spline) drawControl(board, r.spline, COLORS[i]);
  });
  if (state.result) {
    el("path", { d: pathOf(state.result.points.map(toBoard)), fill: "none", stroke: MIX_COLOR, "stroke-width": 3.5,
      id: "interpolant", class: "interpolant" }, board);
    if ($("show-ctrl").checked && state.result.spline) drawControl(board, state.result.spline, MIX_COLOR);
  }
  const named = state.curves.map((c, i) => ({ curve: c, text: NAMES[i], color: COLORS[i] }));
  if (state.result) named.push({ curve: state.result.points, text: "mix", color: MIX_COLOR });
  placeLabels(named).forEach(([x, y], i) => {
    el("text", { x, y, fill: named[i].color, class: "label", "text-anchor": "middle", "dominant-baseline": "middle" },
      board).textContent = named[i].text;
  });
  if (stroke) drawStroke();  // a stroke in progress survives a redraw by an answer arriving meanwhile
  renderStrip();
  renderMetrics();
}

// Where each name goes: near its curve's start (else its end or middle), at the first spot clear of every curve on
// the board and of the names placed before it; the spot farthest from the curves where none is clear.
const LABEL_CLEAR = 16, LABEL_GAP = 34;
function placeLabels(items) {
  const all = [...state.curves, ...state.recon.filter(Boolean).map((r) => r.points),
    ...(state.result ? [state.result.points] : [])].map((c) => c.map(toBoard));
  const clearance = ([x, y]) => Math.min(...all.map((c) => Math.min(...c.map(([px, py]) => Math.hypot(px - x, py - y)))));
  const placed = [];
  for (const { curve } of items) {
    const anchors = [curve[0], curve[curve.length - 1], curve[Math.floor(curve.length / 2)]].map(toBoard);
    const spots = anchors.flatMap(([x, y]) => [22, 36, 52].flatMap((r) => [0, 1, 2, 3, 4, 5, 6, 7].map((k) =>
      [x + r * Math.cos((k * Math.PI) / 4), y + r * Math.sin((k * Math.PI) / 4)])))
      .filter(([x, y]) => x > 14 && x < W - 14 && y > 14 && y < H - 10)
      .filter((p) => placed.every((q) => Math.hypot(p[0] - q[0], p[1] - q[1]) >= LABEL_GAP));
    let best = spots.find((p) => clearance(p) >= LABEL_CLEAR);
    if (!best) best = spots.reduce((a, p) => (!a || clearance(p) > clearance(a) ? p : a), null) || anchors[0];
    placed.push(best);
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

function renderMetrics() {
  const dl = $("metrics");
  dl.replaceChildren();
  const rows = [];
  // how close each reconstruction came, relative to its curve's size (the answer's closeness)
  // [key, shown name, value]: each curve's row says which curve it is about
  state.recon.forEach((r, i) => {
    if (!r || !r.closeness) return;
    const c = r.closeness, pct = (v) => (v === null ? "–" : `${(100 * v).toFixed(2)}%`);
    rows.push([`${NAMES[i]} reconstructed within`, `${NAMES[i]} within`,
      `RMS ${pct(c.rms)}, worst ${pct(c.max)} of its size${r.repaired ? " (untangled)" : ""}`]);
  });
  const m = state.result && state.result.metrics;
  if (m) {
    const ctrl = state.result.spline ? state.result.spline.control_points.length : "–";
    rows.push(
      ["mix roughness", "mix roughness", `${m.smoothness.roughness.toFixed(3)}°`],
      ["mix sharpest turn", "sharpest turn", `${m.smoothness.max_turn.toFixed(1)}°`],
      ["mix shape", "shape", `${m.self_intersects ? "crosses itself" : "no self-crossing"}, ${ctrl} control points`],
    );
  }
  for (const [key, name, value] of rows) {
    const dt = document.createElement("dt"); dt.textContent = name; dl.appendChild(dt);
    const dd = document.createElement("dd"); dd.textContent = value; dd.dataset.metric = key; dl.appendChild(dd);
  }
}

// The input curve within reach of a board point (the nearest, within REACH board units), or null.
const REACH = 14;
function curveAt([x, y]) {
  let best = null, bestD = REACH;
  state.curves.forEach((c, i) => {
    const d = Math.min(...c.map(toBoard).map(([px, py]) => Math.hypot(px - x, py - y)));
    if (d < bestD) { best = i; bestD = d; }
  });
  return best;
}

// Pointer events cover mouse, pen and touch alike; a press released where it began is a click (select).
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
