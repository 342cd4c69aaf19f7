// curve-vae's page: the controls. Buttons, keys (Ctrl+Z, Ctrl+Shift+Z or Ctrl+Y, Delete, Esc), the weights, files
// in and out, the vase; then the page starts with the drawing kept from the last visit.
"use strict";

$("weight").addEventListener("input", () => {
  state.weight = Number($("weight").value);
  $("weight-value").textContent = state.weight.toFixed(2);
  mixChanged();
});

for (const mode of ["pair", "triplet"]) {
  $(`mode-${mode}`).addEventListener("change", () => {
    remember();
    setMode(mode);
    curvesChanged();
  });
}
$("show-ctrl").addEventListener("change", () => { save(); render(); });
$("fit-closely").addEventListener("change", () => curvesChanged({ keepVase: true }));

$("undo").addEventListener("click", undo);
$("redo").addEventListener("click", redo);
$("delete").addEventListener("click", deleteSelected);
function deleteSelected() {
  if (state.selected !== null) deleteCurve(state.selected);
}

// Clear: an empty drawing, a step like any other (Undo brings the curves back, after a reload too).
$("clear").addEventListener("click", () => {
  if (state.items.length) remember();
  Object.assign(state, { items: [], mixOf: null, result: null, strip: [], stripWeights: [], stripValid: [],
    vase: null, lastRequest: null, selected: null, neighbours: null });
  $("curl").textContent = "";
  for (const id of ["board-error", "mix-error", "strip-error", "vase-error", "around-error"]) $(id).textContent = "";
  renderNeighbours();
  curvesChanged();
});

document.addEventListener("keydown", (ev) => {
  const typing = ev.target instanceof HTMLInputElement && !["range", "radio", "checkbox"].includes(ev.target.type);
  if (typing || ev.target instanceof HTMLSelectElement) return;
  const mod = ev.ctrlKey || ev.metaKey, key = ev.key.toLowerCase();
  if (mod && key === "z" && !ev.shiftKey) { ev.preventDefault(); undo(); }
  else if (mod && ((key === "z" && ev.shiftKey) || key === "y")) { ev.preventDefault(); redo(); }
  else if ((ev.key === "Delete" || ev.key === "Backspace") && state.selected !== null) { ev.preventDefault(); deleteSelected(); }
  else if (ev.key === "Escape" && state.selected !== null) select(null);
});

// Samples: two (three) new curves side by side across the view, the ones mixed next.
$("sample").addEventListener("click", async () => {
  try {
    const k = needed(), v = state.view, size = Math.min((0.8 * v.w) / k, 0.75 * v.h);
    const body = { count: k, n_points: N_POINTS, frame: { center: [0, 0], size } };
    if ($("prior").value) body.prior = $("prior").value;
    const r = await api("/sample", body, $("board-error"));
    remember();
    const names = r.curves.map((c, i) => {
      const at = toApi([v.x + (v.w * (i + 0.5)) / k, v.y + v.h / 2]);
      return state.items[addCurve(placed(c, at, [v.w / k, v.h]))].name;
    });
    state.mixOf = names;
    state.selected = null;
    await curvesChanged();
  } catch (e) { /* shown next to the board */ }
});

// The curve moved so that its bounding box is centred on `center`, and scaled down where it would not fit `box`.
function placed(curve, center, box) {
  const xs = curve.map((p) => p[0]), ys = curve.map((p) => p[1]);
  const [x0, x1, y0, y1] = [Math.min(...xs), Math.max(...xs), Math.min(...ys), Math.max(...ys)];
  const s = Math.min(1, (0.9 * box[0]) / (x1 - x0 || 1), (0.9 * box[1]) / (y1 - y0 || 1));
  return curve.map(([x, y]) => [center[0] + s * (x - (x0 + x1) / 2), center[1] + s * (y - (y0 + y1) / 2)]);
}

// The barycentric triangle of the mixed curves: the first at the top, the second bottom left, the third bottom right,
// each corner in its curve's colour and name.
const TRI = [[110, 22], [16, 185], [204, 185]];
function renderTriangle() {
  const svg = $("triangle");
  svg.replaceChildren();
  el("path", { d: pathOf(TRI) + " Z", fill: "#f4f6fb", stroke: "#889" }, svg);
  const mixed = mixIndices().map((i) => state.items[i]);
  TRI.forEach(([x, y], i) => {
    const c = mixed[i];
    el("text", { x: x + [0, -2, 2][i], y: y + [-6, 20, 20][i], "text-anchor": ["middle", "start", "end"][i],
      fill: c ? c.color : "#889", "font-size": 18, "font-weight": 600, class: "corner" }, svg)
      .textContent = c ? c.name : "?";
  });
  const [x, y] = [0, 1].map((k) => state.bary.reduce((s, w, i) => s + w * TRI[i][k], 0));
  el("circle", { cx: x, cy: y, r: 7, fill: MIX_COLOR, id: "bary-dot" }, svg);
  $("bary-value").textContent = state.bary.map((w, i) => `${mixed[i] ? mixed[i].name : "?"} ${Math.round(100 * w)}%`)
    .join(", ");
}
function pickBary(ev) {
  const r = $("triangle").getBoundingClientRect();
  const p = [((ev.clientX - r.left) / r.width) * 220, ((ev.clientY - r.top) / r.height) * 200];
  const [a, b, c] = TRI;
  const det = (b[1] - c[1]) * (a[0] - c[0]) + (c[0] - b[0]) * (a[1] - c[1]);
  let wa = ((b[1] - c[1]) * (p[0] - c[0]) + (c[0] - b[0]) * (p[1] - c[1])) / det;
  let wb = ((c[1] - a[1]) * (p[0] - c[0]) + (a[0] - c[0]) * (p[1] - c[1])) / det;
  wa = Math.max(0, wa); wb = Math.max(0, wb);
  const wc = Math.max(0, 1 - wa - wb);
  const s = wa + wb + wc;
  state.bary = [wa / s, wb / s, wc / s];
  renderTriangle();
  mixChanged();
}
let picking = false;
$("triangle").addEventListener("pointerdown", (ev) => { picking = true; $("triangle").setPointerCapture(ev.pointerId); pickBary(ev); });
$("triangle").addEventListener("pointermove", (ev) => { if (picking) pickBary(ev); });
$("triangle").addEventListener("pointerup", () => { picking = false; });

// ------------------------------------------------------------------------------------------ files out

function download(name, type, data) {
  const a = document.createElement("a");
  a.href = URL.createObjectURL(new Blob([data], { type }));
  a.download = name;
  document.body.appendChild(a);
  a.click();
  setTimeout(() => { URL.revokeObjectURL(a.href); a.remove(); }, 1000);
}
const TYPES = { json: "application/json", csv: "text/csv", svg: "image/svg+xml", dxf: "image/vnd.dxf" };
for (const format of Object.keys(TYPES)) {
  $(`download-${format}`).addEventListener("click", () => {
    download(`curves.${format}`, TYPES[format], curveFiles.write(format, drawing()));
  });
}
$("download-sheet").addEventListener("click", () => {
  const sweep = drawing().filter((c) => c.role === "interpolant" && c.name !== "mix");
  if (!sweep.length) { $("strip-error").textContent = "No in-betweens yet: draw two curves (three in triplet mode)."; return; }
  download("sweep.svg", TYPES.svg, curveFiles.sheet(sweep));
});
$("copy-curl").addEventListener("click", async () => {
  showCurl();
  try { await navigator.clipboard.writeText($("curl").textContent); } catch (e) { /* shown above anyway */ }
});

// ------------------------------------------------------------------------------------------ files in

// Curves from a file picked or dropped on the board (files.js reads them here, in the browser): its inputs (a file
// of this page's or the command line's marks them; derived curves are not made inputs), each a new curve of the
// drawing, the last two (three) of them mixed.
async function openFile(file) {
  $("board-error").textContent = "";
  let read;
  try {
    const binary = /\.np[yz]$/i.test(file.name);
    read = curveFiles.parse(file.name, binary ? await file.arrayBuffer() : await file.text());
  } catch (e) {
    $("board-error").textContent = e.message;
    return;
  }
  remember();
  const curves = onBoard(read.curves);
  if (curves.length === 3) setMode("triplet");
  else if (curves.length === 2) setMode("pair");
  state.mixOf = null;
  curves.forEach(addCurve);
  const done = curvesChanged();
  $("hint").textContent = [`${file.name}: its ${curves.length} curve(s) opened.`, ...read.notes].join(" ");
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

$("vase").addEventListener("click", showVase);
for (const format of ["obj", "stl"]) {
  $(`download-${format}`).addEventListener("click", async () => {
    try {
      const r = await revolve(format);
      if (r) download(`vase.${format}`, format === "obj" ? "model/obj" : "model/stl", await r.blob());
    } catch (e) { /* shown next to the vase */ }
  });
}
$("turn").addEventListener("input", drawVase);

// The key lives for this browser tab only.
$("api-key").value = sessionStorage.getItem("curve-vae-api-key") || "";
$("api-key").addEventListener("change", () => {
  sessionStorage.setItem("curve-vae-api-key", $("api-key").value);
  listPriors();
});

// ------------------------------------------------------------------------------------------ start

$("board").addEventListener("mousedown", (ev) => { if (ev.button === 1) ev.preventDefault(); });  // no autoscroll
loadView();
renderTriangle();
if (load()) curvesChanged();
else { render(); updateHint(); }
updateUndoButtons();
watchReady();
listPriors();
