// curve-vae's page: the list of the drawing's curves beside the board — each one's name and colour (for life), how
// close the model read it, whether it is one of the two (three) mixed, shown or hidden, and its delete — and the
// names of the mixed curves where the weights are set.
"use strict";

function renderCurveList() {
  const list = $("curve-list");
  list.replaceChildren();
  $("curves-empty").hidden = state.items.length > 0;
  const mixed = mixIndices();
  state.items.forEach((c, i) => {
    const li = document.createElement("li");
    li.className = `curve-row${state.selected === i ? " selected" : ""}${c.hidden ? " hidden-curve" : ""}`;
    li.dataset.name = c.name;
    const pick = document.createElement("input");
    pick.type = "checkbox";
    pick.className = "mix-pick";
    pick.checked = mixed.includes(i);
    pick.disabled = c.hidden;
    pick.title = `Mix ${c.name} (tick two curves, three in triplet mode)`;
    pick.setAttribute("aria-label", `mix ${c.name}`);
    pick.addEventListener("change", () => { remember(); toggleMix(i); curvesChanged({ keepVase: false }); });
    const name = document.createElement("button");
    name.type = "button";
    name.className = "curve-name";
    name.title = `Select ${c.name}: its control points become handles, its neighbours show`;
    name.innerHTML = `<svg viewBox="0 0 20 10" aria-hidden="true"><path d="M1,5 L19,5" stroke="${c.color}" stroke-width="4"/></svg>`;
    name.append(c.name);
    name.addEventListener("click", () => select(state.selected === i ? null : i));
    const near = document.createElement("span");
    near.className = "closeness";
    near.textContent = c.recon ? closenessWords(c.recon) : c.hidden ? "hidden" : "…";
    near.title = "How far the model's reading is from the curve, as shares of the curve's size (its bounding box's " +
      "diagonal): on average (RMS) and at the farthest point";
    const eye = document.createElement("button");
    eye.type = "button";
    eye.className = "icon show";
    eye.textContent = c.hidden ? "show" : "hide";
    eye.title = c.hidden ? `Show ${c.name}` : `Hide ${c.name} (it stays in the drawing and its files)`;
    eye.addEventListener("click", () => { remember(); c.hidden = !c.hidden; curvesChanged(); });
    const del = document.createElement("button");
    del.type = "button";
    del.className = "icon remove";
    del.textContent = "×";
    del.title = `Delete ${c.name}`;
    del.setAttribute("aria-label", `delete ${c.name}`);
    del.addEventListener("click", () => deleteCurve(i));
    li.append(pick, name, near, eye, del);
    list.appendChild(li);
  });
}

// The mixed curves' names where the weights are set: the slider's and the triangle's corners.
function renderMixLabels() {
  const names = mixNames();
  $("weight-of").textContent = names[1] || "the second curve";
  $("weight-from").textContent = names[0] || "";
  renderTriangle();
}

function deleteCurve(index) {
  remember();
  const name = state.items[index].name;
  state.items.splice(index, 1);
  if (state.mixOf) state.mixOf = state.mixOf.filter((n) => n !== name);
  if (state.selected === index) state.selected = null;
  else if (state.selected !== null && state.selected > index) state.selected -= 1;
  state.result = null;
  state.neighbours = null;
  renderNeighbours();
  curvesChanged();
}
