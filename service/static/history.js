// curve-vae's page: undo and redo of every change to the drawing (its curves, mode and weights), and the drawing
// with its settings kept in this browser (localStorage) so that a reload brings it back; Clear starts afresh.
"use strict";

const STORE = "curve-vae-drawing";
const KEEP = 100;  // steps of undo
const undoStack = { past: [], future: [] };

const snapshot = () => JSON.stringify({ curves: state.curves, mode: state.mode, weight: state.weight, bary: state.bary });

// Call before a change: the drawing as it was becomes the step Undo goes back to.
function remember() {
  undoStack.past.push(snapshot());
  if (undoStack.past.length > KEEP) undoStack.past.shift();
  undoStack.future = [];
  updateUndoButtons();
}

function restore(text) {
  const s = JSON.parse(text);
  setMode(s.mode);
  state.curves = s.curves;
  state.recon = s.curves.map(() => null);
  state.result = null;
  state.neighbours = null;
  setWeights(s.weight, s.bary);
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

// The drawing and its settings, as they are now, for the next visit.
function save() {
  const kept = { curves: state.curves, mode: state.mode, weight: state.weight, bary: state.bary,
    fitClosely: $("fit-closely").checked, showControl: $("show-ctrl").checked };
  try { localStorage.setItem(STORE, JSON.stringify(kept)); } catch (e) { /* private mode or full: nothing kept */ }
}

// The drawing kept from the last visit, if any (a broken entry is dropped, not shown as an error).
function load() {
  let kept;
  try { kept = JSON.parse(localStorage.getItem(STORE) || "null"); } catch (e) { kept = null; }
  const fine = kept && Array.isArray(kept.curves) && ["pair", "triplet"].includes(kept.mode)
    && kept.curves.every((c) => Array.isArray(c) && c.length >= 4 && c.every((p) => p.length === 2 && p.every(Number.isFinite)));
  if (!fine) { localStorage.removeItem(STORE); return false; }
  $("fit-closely").checked = !!kept.fitClosely;
  $("show-ctrl").checked = !!kept.showControl;
  setMode(kept.mode);
  state.curves = kept.curves.slice(-needed());
  state.recon = state.curves.map(() => null);
  setWeights(Number.isFinite(kept.weight) ? kept.weight : 0.5,
    Array.isArray(kept.bary) && kept.bary.length === 3 ? kept.bary : [1 / 3, 1 / 3, 1 / 3]);
  return state.curves.length > 0;
}

function forget() {
  try { localStorage.removeItem(STORE); } catch (e) { /* nothing kept */ }
}
