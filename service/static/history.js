// curve-vae's page: undo and redo of every change to the drawing (its curves, their names and colours, which are
// mixed, the mode and the weights), kept with the drawing in this browser (localStorage), so that a reload brings
// back the drawing and its history; Clear is a step like any other. The view is not a step (view.js keeps it).
"use strict";

const STORE = "curve-vae-drawing";
const KEEP = 60;  // steps of undo and redo kept
const STORED_BYTES = 2_000_000;  // the history kept across reloads gives up its oldest steps beyond this
const undoStack = { past: [], future: [] };

const drawingNow = () => ({
  items: state.items.map(({ name, color, points, hidden }) => ({ name, color, points, hidden })),
  made: state.made, mixOf: state.mixOf, mode: state.mode, weight: state.weight, bary: state.bary,
});
const snapshot = () => JSON.stringify(drawingNow());

// Call before a change: the drawing as it was becomes the step Undo goes back to.
function remember() {
  undoStack.past.push(snapshot());
  if (undoStack.past.length > KEEP) undoStack.past.shift();
  undoStack.future = [];
  updateUndoButtons();
}

// A drawing (a snapshot's, or the kept one's) put on the page; false where it is not one.
function put(s) {
  if (!drawingFine(s)) return false;
  setMode(s.mode);
  state.items = s.items.map((c) => ({ name: c.name, color: c.color, points: c.points, hidden: !!c.hidden, recon: null }));
  state.made = Math.max(s.made || 0, state.items.length);
  state.mixOf = Array.isArray(s.mixOf) ? s.mixOf.filter((n) => typeof n === "string") : null;
  state.result = null;
  state.neighbours = null;
  state.selected = null;
  setWeights(Number.isFinite(s.weight) ? s.weight : 0.5,
    Array.isArray(s.bary) && s.bary.length === 3 ? s.bary : [1 / 3, 1 / 3, 1 / 3]);
  return true;
}

const isCurve = (c) => Array.isArray(c) && c.length >= 4 && c.every((p) => p.length === 2 && p.every(Number.isFinite));
function drawingFine(s) {
  return s && ["pair", "triplet"].includes(s.mode) && Array.isArray(s.items)
    && s.items.every((c) => c && typeof c.name === "string" && typeof c.color === "string" && isCurve(c.points));
}

function restore(text) {
  put(JSON.parse(text));
  curvesChanged();
}

function undo() {
  if (!undoStack.past.length) return;
  undoStack.future.push(snapshot());
  restore(undoStack.past.pop());
}

function redo() {
  if (!undoStack.future.length) return;
  undoStack.past.push(snapshot());
  restore(undoStack.future.pop());
}

function updateUndoButtons() {
  $("undo").disabled = !undoStack.past.length;
  $("redo").disabled = !undoStack.future.length;
  $("delete").disabled = state.selected === null;
}

function setWeights(weight, bary) {
  state.weight = weight;
  state.bary = bary;
  $("weight").value = weight;
  $("weight-value").textContent = weight.toFixed(2);
  renderTriangle();
}

// The drawing, its settings and its history, as they are now, for the next visit: the oldest steps go first where
// the whole would not fit.
function save() {
  const kept = { ...drawingNow(), fitClosely: $("fit-closely").checked, showControl: $("show-ctrl").checked,
    history: { past: undoStack.past.slice(), future: undoStack.future.slice() } };
  for (;;) {
    const text = JSON.stringify(kept);
    if (text.length <= STORED_BYTES || (!kept.history.past.length && !kept.history.future.length)) {
      try { localStorage.setItem(STORE, text); } catch (e) { /* private mode or full: nothing kept */ }
      return;
    }
    if (kept.history.past.length) kept.history.past.shift(); else kept.history.future.shift();
  }
}

// The drawing kept from the last visit, with its history, if any (a broken entry is dropped, not shown as an error).
function load() {
  let kept;
  try { kept = JSON.parse(localStorage.getItem(STORE) || "null"); } catch (e) { kept = null; }
  if (!kept || !put(kept)) { try { localStorage.removeItem(STORE); } catch (e) { /* nothing kept */ } return false; }
  $("fit-closely").checked = !!kept.fitClosely;
  $("show-ctrl").checked = !!kept.showControl;
  const steps = (list) => (Array.isArray(list) ? list.filter((t) => typeof t === "string").slice(-KEEP) : []);
  undoStack.past = steps(kept.history && kept.history.past);
  undoStack.future = steps(kept.history && kept.history.future);
  return state.items.length > 0 || undoStack.past.length > 0;
}
