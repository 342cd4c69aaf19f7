// curve-vae's page: the board's view and its gestures. Zoom with the wheel, two fingers or the buttons, pan with the
// middle button, Space and a drag, or two fingers; fit the view to the drawing. The view changes what is shown, never
// the curves, and is no step of the history (as in tldraw). A selected curve's control points are handles: dragging
// one edits the curve (the spline's points become the curve's), which is then read again.
"use strict";

const MIN_ZOOM = 0.2, MAX_ZOOM = 40;

function applyView() {
  const v = state.view;
  $("board").setAttribute("viewBox", `${round(v.x)} ${round(v.y)} ${round(v.w)} ${round(v.h)}`);
  $("zoom-level").textContent = `${Math.round((100 * W) / v.w)}%`;
}

// The view scaled by `factor` about a board point (the pointer's, or the view's centre), within the zoom's bounds.
function zoomAt(factor, [x, y] = [state.view.x + state.view.w / 2, state.view.y + state.view.h / 2]) {
  const v = state.view;
  const w = Math.min(W / MIN_ZOOM, Math.max(W / MAX_ZOOM, v.w / factor));
  const f = v.w / w;
  state.view = { x: x - (x - v.x) / f, y: y - (y - v.y) / f, w, h: (w * H) / W };
  saveView();
  render();
}

// The view around every curve shown (with a margin), or the whole board where there is none.
function fitView() {
  const pts = state.items.filter((c) => !c.hidden).flatMap((c) => c.points.map(toBoard));
  if (!pts.length) { state.view = { x: 0, y: 0, w: W, h: H }; saveView(); render(); return; }
  const xs = pts.map((p) => p[0]), ys = pts.map((p) => p[1]);
  const [x0, x1, y0, y1] = [Math.min(...xs), Math.max(...xs), Math.min(...ys), Math.max(...ys)];
  const w = Math.min(W / MIN_ZOOM, Math.max(W / MAX_ZOOM, 1.15 * Math.max(x1 - x0, ((y1 - y0) * W) / H)));
  state.view = { x: (x0 + x1) / 2 - w / 2, y: (y0 + y1) / 2 - (w * H) / W / 2, w, h: (w * H) / W };
  saveView();
  render();
}

function panBy(dx, dy) {
  state.view = { ...state.view, x: state.view.x - dx, y: state.view.y - dy };
  saveView();
  render();
}

// The view is kept for the next visit beside the drawing, but outside its history.
function saveView() {
  try { localStorage.setItem(VIEW_STORE, JSON.stringify(state.view)); } catch (e) { /* nothing kept */ }
}
function loadView() {
  try {
    const v = JSON.parse(localStorage.getItem(VIEW_STORE) || "null");
    if (v && ["x", "y", "w", "h"].every((k) => Number.isFinite(v[k])) && v.w > 0) state.view = v;
  } catch (e) { /* the first view */ }
}
const VIEW_STORE = "curve-vae-view";

// ------------------------------------------------------------------------------------------ editing a curve

// The drag of a handle under way: which curve, which control point, the spline as it is being moved.
let editing = null;

// A clamped B-spline (the API's { control_points, knots, degree, params }) at parameters `us` (de Boor).
function splineAt(spline, us) {
  const { control_points: c, knots: t, degree: p } = spline, n = c.length;
  return us.map((u) => {
    let s = p;
    while (s < n - 1 && u >= t[s + 1]) s++;
    const d = [];
    for (let j = 0; j <= p; j++) d.push(c[s - p + j].slice());
    for (let r = 1; r <= p; r++) {
      for (let j = p; j >= r; j--) {
        const i = s - p + j, den = t[i + p - r + 1] - t[i];
        const a = den > 0 ? (u - t[i]) / den : 0;
        d[j] = [(1 - a) * d[j - 1][0] + a * d[j][0], (1 - a) * d[j - 1][1] + a * d[j][1]];
      }
    }
    return d[p];
  });
}

function drawEdit(board) {
  const pts = splineAt(editing.spline, editing.spline.params).map(toBoard);
  el("path", { d: pathOf(pts), fill: "none", stroke: state.items[editing.index].color, "stroke-width": 3,
    id: "edited", class: "edited" }, board);
}

function startEdit(ev) {
  const index = state.selected, c = state.items[index];
  const spline = JSON.parse(JSON.stringify(c.recon.spline));
  if (!spline.params || spline.params.length < 4) spline.params = Array.from({ length: N_POINTS }, (_, i) => i / (N_POINTS - 1));
  editing = { index, k: Number(ev.target.dataset.k), spline, moved: false };
}

function moveEdit(ev) {
  editing.spline.control_points[editing.k] = toApi(boardPoint(ev));
  editing.moved = true;
  render();
}

// The edited spline's points become the curve's (undoable), and the curve is read again.
function finishEdit() {
  const e = editing;
  editing = null;
  if (!e.moved) { render(); return; }
  remember();
  const c = state.items[e.index];
  c.points = splineAt(e.spline, e.spline.params);
  c.recon = null;
  curvesChanged();
}

// ------------------------------------------------------------------------------------------ the board's gestures

const pointers = new Map();  // the pointers down on the board: two make a pinch
let panning = null, pinch = null, spaceDown = false;

$("board").addEventListener("pointerdown", (ev) => {
  ev.preventDefault();
  $("board").setPointerCapture(ev.pointerId);
  pointers.set(ev.pointerId, [ev.clientX, ev.clientY]);
  if (pointers.size === 2) {  // two fingers: zoom and pan, and no stroke
    stroke = null;
    const [a, b] = [...pointers.values()];
    pinch = { d: Math.hypot(a[0] - b[0], a[1] - b[1]), mid: [(a[0] + b[0]) / 2, (a[1] + b[1]) / 2] };
    render();
    return;
  }
  if (ev.button === 1 || spaceDown) { panning = [ev.clientX, ev.clientY]; return; }
  if (ev.button !== 0) return;
  if (ev.target.classList && ev.target.classList.contains("handle") && state.selected !== null) { startEdit(ev); return; }
  startStroke(ev);
});

$("board").addEventListener("pointermove", (ev) => {
  if (pointers.has(ev.pointerId)) pointers.set(ev.pointerId, [ev.clientX, ev.clientY]);
  const r = $("board").getBoundingClientRect(), scale = state.view.w / r.width;
  if (pinch && pointers.size === 2) {
    const [a, b] = [...pointers.values()];
    const d = Math.hypot(a[0] - b[0], a[1] - b[1]), mid = [(a[0] + b[0]) / 2, (a[1] + b[1]) / 2];
    panBy((mid[0] - pinch.mid[0]) * scale, (mid[1] - pinch.mid[1]) * scale);
    zoomAt(d / pinch.d, boardPoint({ clientX: mid[0], clientY: mid[1] }));
    pinch = { d, mid };
    return;
  }
  if (panning) {
    panBy((ev.clientX - panning[0]) * scale, (ev.clientY - panning[1]) * scale);
    panning = [ev.clientX, ev.clientY];
    return;
  }
  if (editing) { moveEdit(ev); return; }
  moveStroke(ev);
});

function pointerEnd(ev, cancelled) {
  pointers.delete(ev.pointerId);
  if (pinch) { if (pointers.size < 2) pinch = null; return; }
  if (panning) { panning = null; return; }
  if (editing) { if (cancelled) { editing = null; render(); } else finishEdit(); return; }
  if (cancelled) { stroke = null; render(); return; }
  if (stroke) finishStroke();
}
$("board").addEventListener("pointerup", (ev) => pointerEnd(ev, false));
$("board").addEventListener("pointercancel", (ev) => pointerEnd(ev, true));

// The wheel zooms about the pointer (a trackpad's pinch arrives as a wheel with Ctrl); Shift+wheel pans sideways.
$("board").addEventListener("wheel", (ev) => {
  ev.preventDefault();
  if (ev.shiftKey && !ev.ctrlKey) {
    const scale = state.view.w / $("board").getBoundingClientRect().width;
    panBy(-(ev.deltaY || ev.deltaX) * scale, 0);
    return;
  }
  zoomAt(Math.exp(-ev.deltaY * (ev.ctrlKey ? 0.01 : 0.0015)), boardPoint(ev));
}, { passive: false });

document.addEventListener("keydown", (ev) => {
  if (ev.code === "Space" && !(ev.target instanceof HTMLInputElement) && !(ev.target instanceof HTMLButtonElement)) {
    spaceDown = true;
    $("board").classList.add("panning");
    ev.preventDefault();
  }
});
document.addEventListener("keyup", (ev) => {
  if (ev.code === "Space") { spaceDown = false; $("board").classList.remove("panning"); }
});

$("zoom-in").addEventListener("click", () => zoomAt(1.25));
$("zoom-out").addEventListener("click", () => zoomAt(0.8));
$("zoom-fit").addEventListener("click", fitView);
