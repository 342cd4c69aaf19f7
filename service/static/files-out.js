// curve-vae's page: curve files written in the browser, with the command line's file model (curve_vae/curvefiles).
// This file holds the writers and adds them onto window.curveFiles (files.js, loaded right before it, holds the
// readers and the file model): write(format, drawing) gives a drawing's file as text, sheet(drawing) the in-betweens
// as an SVG grid. A drawing is a list of curves { name, role, of, weights, points, spline } in API coordinates (y up).
// Out (write): JSON {"curves": [...]}, CSV `curve,role,of,weights,index,x,y`, SVG (a path per curve, its class the
// role, data-name/-of/-weights; a point (x, y) at (x, -y) in user units) and DXF (an LWPOLYLINE or a SPLINE per
// curve on the layer `<role>-<name>`, role, name, of and weights as XDATA of the application CURVE_VAE).
"use strict";

(() => {
  const { CurveFileError, ROLES, colourOf, nameIndex, _shared: { item, weightsText, APPID } } = window.curveFiles;

  const item0 = (c) => item({ ...c, role: c.role || "input" });
  const csvCell = (s) => (/[",\n]/.test(s) ? `"${s.replace(/"/g, '""')}"` : s);

  function toCsv(drawing) {
    const rows = ["curve,role,of,weights,index,x,y"];
    for (const c of drawing.map(item0)) {
      const key = [c.name ?? "", c.role, c.of ?? "", weightsText(c.weights)].map((s) => csvCell(String(s))).join(",");
      c.points.forEach(([x, y], i) => rows.push(`${key},${i},${x},${y}`));
    }
    return rows.join("\n") + "\n";
  }

  // SVG as the command line writes it (curve_vae/curvefiles/svg.py): the curves' own coordinates in the viewBox, a
  // point (x, y) at (x, -y), DISPLAY_PX on the longer side, a STROKE_PX stroke at any scale.
  const DISPLAY_PX = 800, STROKE_PX = 1.5;
  const INTERPOLANT = "#d62728";
  const STYLES = {
    input: 'stroke-width="6" stroke-opacity="0.3" stroke-linecap="round" stroke-linejoin="round"',
    reconstruction: 'stroke-dasharray="6 4"',
    interpolant: "",
  };
  const DESC = "curve-vae: each path is a curve in its own coordinates, y up: its point (x, y) is drawn at (x, -y), SVG's y " +
    "pointing down. A path's class is its role (input, reconstruction, interpolant); data-name names it, data-of " +
    "names a reconstruction's input, data-weights an interpolant's weights by input.";
  const fmt = (v) => String(Number(v.toPrecision(10)));
  const esc = (s) => String(s).replace(/&/g, "&amp;").replace(/</g, "&lt;").replace(/>/g, "&gt;").replace(/"/g, "&quot;");
  const rank = (c) => { const r = ROLES.indexOf(c.role); return r < 0 ? ROLES.length : r; };

  function pathOf(c, id) {
    const attrs = [`id="${id}"`, `class="${esc(c.role)}"`, `data-name="${esc(c.name ?? "")}"`];
    if (c.of !== undefined) attrs.push(`data-of="${esc(c.of)}"`);
    if (c.weights) attrs.push(`data-weights="${esc(weightsText(c.weights))}"`);
    const colour = c.role === "interpolant" ? INTERPOLANT : colourOf(c.of ?? c.name);
    attrs.push(`stroke="${colour}"`, STYLES[c.role] ?? "", 'vector-effect="non-scaling-stroke"');
    const d = "M" + c.points.map(([x, y]) => `${fmt(x)},${fmt(-y)}`).join(" L");
    return `<path ${attrs.filter(Boolean).join(" ")} d="${d}"/>`;
  }

  function toSvg(drawing) {
    const items = drawing.map(item0).map((c, i) => [c, i]).sort((a, b) => rank(a[0]) - rank(b[0]) || a[1] - b[1]);
    const all = items.flatMap(([c]) => c.points);
    const xs = all.map((p) => p[0]), ys = all.map((p) => p[1]);
    const [lx, hx, ly, hy] = [Math.min(...xs), Math.max(...xs), Math.min(...ys), Math.max(...ys)];
    const pad = 0.05 * Math.max(hx - lx, hy - ly, 1e-9);
    const [x0, y0, w, h] = [lx - pad, -hy - pad, hx - lx + 2 * pad, hy - ly + 2 * pad];
    const px = DISPLAY_PX / Math.max(w, h);
    return ['<?xml version="1.0" encoding="UTF-8"?>',
      `<svg xmlns="http://www.w3.org/2000/svg" width="${Math.round(w * px)}px" height="${Math.max(Math.round(h * px), 1)}px" ` +
      `viewBox="${fmt(x0)} ${fmt(y0)} ${fmt(w)} ${fmt(h)}">`,
      `<desc>${DESC}</desc>`,
      `<g fill="none" stroke-width="${STROKE_PX}">`,
      ...items.map(([c, i]) => pathOf(c, `curve-${i}`)),
      "</g>", "</svg>", ""].join("\n");
  }

  // The in-betweens (interpolants) as a sheet: each in its cell of a grid at one scale, its weights written under it.
  function sheet(drawing) {
    const items = drawing.map(item0).filter((c) => c.role === "interpolant");
    if (!items.length) throw new CurveFileError("no in-between to put on a sheet");
    const CELL = 200, LABEL = 28, cols = Math.ceil(Math.sqrt(items.length)), rows = Math.ceil(items.length / cols);
    const boxes = items.map((c) => {
      const xs = c.points.map((p) => p[0]), ys = c.points.map((p) => p[1]);
      return [Math.min(...xs), Math.max(...xs), Math.min(...ys), Math.max(...ys)];
    });
    const s = (0.85 * (CELL - LABEL)) / Math.max(...boxes.map(([a, b, c, d]) => Math.max(b - a, d - c)), 1e-9);
    const words = (w) => Object.entries(w || {}).map(([k, v]) => `${Number(v.toFixed(3))} ${k}`).join(" + ");
    const cells = items.map((c, i) => {
      const [a, b, lo, hi] = boxes[i], [cx, cy] = [(i % cols + 0.5) * CELL, Math.floor(i / cols) * CELL + (CELL - LABEL) / 2];
      return [`<g transform="translate(${fmt(cx)},${fmt(cy)}) scale(${fmt(s)}) translate(${fmt(-(a + b) / 2)},${fmt((lo + hi) / 2)})">`,
        pathOf(c, `in-between-${i}`), "</g>",
        `<text x="${fmt(cx)}" y="${fmt(Math.floor(i / cols) * CELL + CELL - LABEL / 2)}" text-anchor="middle" ` +
        `font-family="sans-serif" font-size="13" fill="#333">${esc(words(c.weights) || c.name || "")}</text>`].join("\n");
    });
    return ['<?xml version="1.0" encoding="UTF-8"?>',
      `<svg xmlns="http://www.w3.org/2000/svg" width="${cols * CELL}px" height="${rows * CELL}px" viewBox="0 0 ${cols * CELL} ${rows * CELL}">`,
      `<desc>${DESC} A sheet of in-betweens: one a cell, all at one scale, each with its weights under it.</desc>`,
      `<g fill="none" stroke-width="${STROKE_PX}">`, ...cells, "</g>", "</svg>", ""].join("\n");
  }

  // DXF (AutoCAD 2000, ASCII): a SPLINE per curve with a spline (its degree, knots and control points exactly), an
  // LWPOLYLINE per other curve, each on the layer `<role>-<name>` (what AutoCAD refuses in a layer's name as "_")
  // with its role, name, input and weights as XDATA strings of the application CURVE_VAE. DXF's y points up too.
  const NOT_IN_LAYERS = /[<>/\\":;?*|,=`]/g;
  const PALETTE_ACI = [5, 3, 6, 30, 4, 34, 221, 52, 8, 176];  // AutoCAD's nearest to each of PALETTE (roles.py)
  const layerName = (c) => `${c.role}-${c.name ?? ""}`.replace(NOT_IN_LAYERS, "_");

  function toDxf(drawing) {
    const items = drawing.map(item0);
    let handle = 0x100;
    const next = () => (handle++).toString(16).toUpperCase();
    const out = ["0", "SECTION", "2", "HEADER", "9", "$ACADVER", "1", "AC1015", "0", "ENDSEC", "0", "SECTION", "2", "TABLES"];
    const table = (type, names, entry) => {
      const own = next();
      out.push("0", "TABLE", "2", type, "5", own, "330", "0", "100", "AcDbSymbolTable", "70", String(names.length));
      for (const n of names) out.push("0", type, "5", next(), "330", own, "100", "AcDbSymbolTableRecord", ...entry(n));
      out.push("0", "ENDTAB");
    };
    table("APPID", ["ACAD", APPID], (n) => ["100", "AcDbRegAppTableRecord", "2", n, "70", "0"]);
    const layers = [...new Set(["0", ...items.map(layerName)])];
    const colour = (layer) => {
      const c = items.find((i) => layerName(i) === layer);
      const k = c ? nameIndex(c.of ?? c.name) : null;
      return !c ? 7 : c.role === "interpolant" ? 1 : k === null ? 7 : PALETTE_ACI[k % PALETTE_ACI.length];
    };
    table("LAYER", layers, (n) => ["100", "AcDbLayerTableRecord", "2", n, "70", "0", "62", String(colour(n)), "6", "Continuous"]);
    out.push("0", "ENDSEC", "0", "SECTION", "2", "ENTITIES");
    for (const c of items) {
      const head = (type, subclass) => out.push("0", type, "5", next(), "100", "AcDbEntity", "8", layerName(c), "100", subclass);
      if (c.spline) {
        const { control_points: ctrl, knots, degree } = c.spline;
        head("SPLINE", "AcDbSpline");
        out.push("210", "0", "220", "0", "230", "1", "70", "8", "71", String(degree), "72", String(knots.length),
          "73", String(ctrl.length), "74", "0");
        for (const k of knots) out.push("40", String(k));
        for (const [x, y] of ctrl) out.push("10", String(x), "20", String(y), "30", "0");
      } else {
        head("LWPOLYLINE", "AcDbPolyline");
        out.push("90", String(c.points.length), "70", "0");
        for (const [x, y] of c.points) out.push("10", String(x), "20", String(y));
      }
      out.push("1001", APPID, "1000", `role=${c.role}`, "1000", `name=${c.name ?? ""}`);
      if (c.of !== undefined) out.push("1000", `of=${c.of}`);
      if (c.weights) out.push("1000", `weights=${weightsText(c.weights)}`);
    }
    out.push("0", "ENDSEC", "0", "EOF");
    return out.join("\n") + "\n";
  }

  // A drawing as a file's text: "json", "csv", "svg" or "dxf".
  function write(format, drawing) {
    if (format === "json") return JSON.stringify({ curves: drawing.map(item0) }, null, 1) + "\n";
    if (format === "csv") return toCsv(drawing);
    if (format === "svg") return toSvg(drawing);
    if (format === "dxf") return toDxf(drawing);
    throw new CurveFileError(`no writer for ${format}: json, csv, svg or dxf`);
  }

  Object.assign(window.curveFiles, { write, sheet });
})();
