// curve-vae's page: curve files in and out, read and written in the browser (nothing is uploaded to read them).
// In: JSON (an API body, a list of curves, this page's export), CSV/TSV (x,y rows or a header naming x and y; a
// `curve` column groups rows), airfoil .dat files (Selig or Lednicer, headers, remarks, notes after the
// coordinates, Fortran exponents) and SVG (paths, polylines, polygons, transforms applied). Out: DXF, points as
// LWPOLYLINEs and B-splines as SPLINE entities with their knots. The same formats as the command line's reader
// (curve_vae/curvefiles); curves are in API coordinates, y up.
"use strict";

(() => {
  const MIN_POINTS = 4;
  const NUM = "[+-]?(?:\\d+\\.?\\d*|\\.\\d+)(?:[eEdD][+-]?\\d+)?";
  const IS_NUM = new RegExp(`^${NUM}$`);
  // two numbers at a line's start (apart by spaces or a comma, or abutting where the second has its sign); the
  // rest is a remark unless it is a third number
  const PAIR = new RegExp(`^\\s*(${NUM})(?:[\\s,]+|(?=[+-]))(${NUM})(?![\\d.])[\\s,]*(.*)$`);
  const LEADING_NUM = new RegExp(`^${NUM}(?:\\s|,|$)`);

  class CurveFileError extends Error {}

  const number = (s) => (IS_NUM.test(s.trim()) ? Number(s.trim().replace(/[dD]/, "e")) : null);

  function checked(curves, name) {
    const out = curves.filter((c) => c.length);
    out.forEach((c, i) => {
      if (!Array.isArray(c) || c.some((p) => !Array.isArray(p) || p.length !== 2 || !p.every(Number.isFinite))) {
        throw new CurveFileError(`${name}: curve ${i + 1} must be a list of [x, y] pairs of numbers`);
      }
      if (c.length < MIN_POINTS) {
        throw new CurveFileError(`${name}: curve ${i + 1} has ${c.length} points; a curve needs at least ${MIN_POINTS}`);
      }
    });
    if (!out.length) throw new CurveFileError(`${name}: no curve in this file`);
    return out;
  }

  function fromJson(text, name) {
    let data;
    try { data = JSON.parse(text); } catch (e) { throw new CurveFileError(`${name}: not JSON (${e.message})`); }
    if (data && !Array.isArray(data) && typeof data === "object") {
      if (Array.isArray(data.curves)) data = data.curves;
      else if (data.curve) data = [data.curve];
      else throw new CurveFileError(`${name}: a JSON object needs a "curves" list`);
    }
    if (!Array.isArray(data)) throw new CurveFileError(`${name}: JSON of curves is a list or an object`);
    if (data.length && Array.isArray(data[0]) && typeof data[0][0] === "number") data = [data];  // one curve
    return checked(data.map((c, i) => {
      if (c && !Array.isArray(c) && typeof c === "object") {
        if (!Array.isArray(c.points)) throw new CurveFileError(`${name}: curves[${i}] is an object without "points"`);
        return c.points;
      }
      return c;
    }), name);
  }

  function cells(line, delimiter) {
    return delimiter ? line.split(delimiter).map((c) => c.trim().replace(/^"(.*)"$/, "$1")) : line.trim().split(/\s+/);
  }

  function fromCsv(text, name) {
    const lines = text.split(/\r?\n/);
    const first = lines.findIndex((l) => l.trim());
    if (first < 0) throw new CurveFileError(`${name}: no curve in this file (it is empty)`);
    const delimiter = ["\t", ",", ";"].find((d) => lines[first].includes(d)) || null;
    const head = cells(lines[first], delimiter);
    const header = head.some((c) => number(c) === null);
    const names = head.map((c) => c.toLowerCase());
    let [x, y, key] = [0, 1, -1];
    if (header && names.includes("x") && names.includes("y")) {
      [x, y] = [names.indexOf("x"), names.indexOf("y")];
      key = ["curve", "name", "id"].map((k) => names.indexOf(k)).find((i) => i >= 0) ?? -1;
    } else if (header && names.length !== 2) {
      throw new CurveFileError(`${name}:${first + 1}: a header row needs columns named x and y`);
    }
    const curves = [[]];
    let last = null;
    const began = new Map();  // each curve name's first row (1-based)
    for (let i = first + (header ? 1 : 0); i < lines.length; i++) {
      if (!lines[i].trim()) {  // a blank line starts the next curve; where a column names the curves, the names do
        if (key < 0) curves.push([]);
        continue;
      }
      const row = cells(lines[i], delimiter);
      const [px, py] = [number(row[x] ?? ""), number(row[y] ?? "")];
      if (px === null || py === null || (!header && row.length !== 2)) {
        const what = !header || head.length === 2 ? "two numbers x,y" : "numbers in the columns named x and y";
        throw new CurveFileError(`${name}:${i + 1}: expected ${what}, got "${lines[i].trim()}"`);
      }
      if (key >= 0) {
        if (row[key] === undefined) throw new CurveFileError(`${name}:${i + 1}: no column '${head[key]}' in '${lines[i].trim()}'`);
        if (row[key] !== last) {
          if (began.has(row[key])) {  // joined or kept apart, either guess could be wrong: the file says which
            throw new CurveFileError(`${name}:${i + 1}: curve '${row[key]}' again after other curves (its rows begin at row ` +
              `${began.get(row[key])}): list each curve's rows one after another, or name the pieces apart`);
          }
          began.set(row[key], i + 1);
          curves.push([]);
          last = row[key];
        }
      }
      curves[curves.length - 1].push([px, py]);
    }
    return checked(curves, name);
  }

  // One airfoil in Selig order, and what was skipped, as notes.
  function fromDat(text, name) {
    const rows = [], notes = [];
    let end = null, remarks = 0;
    const lines = text.split(/\r?\n/);
    for (let i = 0; i < lines.length; i++) {
      if (!lines[i].trim()) continue;
      const m = lines[i].match(PAIR);
      if (!m || LEADING_NUM.test(m[3])) {
        if (rows.length) { end = [i + 1, lines[i].trim()]; break; }
        continue;  // the title and header lines
      }
      rows.push([number(m[1]), number(m[2])]);
      if (m[3].trim()) remarks++;
    }
    if (!rows.length) throw new CurveFileError(`${name}: no coordinates in this file (expected lines of two numbers x y)`);
    const counts = rows[0][0] >= 2 && rows[0][1] >= 2 && Number.isInteger(rows[0][0]) && Number.isInteger(rows[0][1]);
    const wanted = counts ? 1 + rows[0][0] + rows[0][1] : MIN_POINTS;
    if (end && rows.length < wanted) throw new CurveFileError(`${name}:${end[0]}: expected two numbers x y, got "${end[1]}"`);
    if (remarks) notes.push(`${name}: remarks after the numbers skipped on ${remarks} line(s)`);
    if (end) notes.push(`${name}:${end[0]}: the coordinates end here; the lines from here on are skipped`);
    let pts = rows;
    if (counts) {
      const [upper, lower] = rows[0];
      if (rows.length - 1 !== upper + lower) {
        throw new CurveFileError(`${name}: Lednicer counts ${upper} + ${lower}, but ${rows.length - 1} points follow`);
      }
      const up = rows.slice(1, 1 + upper), lo = rows.slice(1 + upper);
      const same = Math.hypot(lo[0][0] - up[0][0], lo[0][1] - up[0][1]) < 1e-9;
      pts = [...up.reverse(), ...(same ? lo.slice(1) : lo)];
    }
    return { curves: checked([pts], name), notes };
  }

  const SAMPLES = 120;  // points along a drawing's curved path (straight ones, polylines and polygons keep their vertices)

  // The vertices of a path of straight segments only (M, L, H, V, Z), or null where it has curved ones.
  function vertices(d) {
    const tokens = d.match(/[A-Za-z]|[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?/g) || [];
    if (tokens.some((t) => /[CcSsQqTtAa]/.test(t))) return null;
    const pts = [];
    let cmd = "M", x = 0, y = 0, start = [0, 0];
    for (let i = 0; i < tokens.length;) {
      if (/[A-Za-z]/.test(tokens[i])) {
        cmd = tokens[i++];
        if (cmd === "Z" || cmd === "z") { [x, y] = start; pts.push([x, y]); continue; }
      }
      const rel = cmd === cmd.toLowerCase(), c = cmd.toUpperCase();
      const a = Number(tokens[i++]);
      if (c === "H") x = rel ? x + a : a;
      else if (c === "V") y = rel ? y + a : a;
      else {
        const b = Number(tokens[i++]);
        [x, y] = rel ? [x + a, y + b] : [a, b];
      }
      if (c === "M") { start = [x, y]; cmd = rel ? "l" : "L"; }  // pairs after a move are lines
      pts.push([x, y]);
    }
    return pts.map(([px, py]) => ({ x: px, y: py }));
  }

  // The drawing's paths, polylines and polygons in its viewBox's units, y up from the viewBox's bottom (the page's
  // own SVG export comes back where it was drawn). Of the page's own export, its drawn strokes (class "input").
  function fromSvg(text, name) {
    const parsed = new DOMParser().parseFromString(text, "image/svg+xml");
    if (parsed.querySelector("parsererror") || parsed.documentElement.localName !== "svg") {
      throw new CurveFileError(`${name}: not an SVG drawing`);
    }
    const holder = document.createElement("div");
    holder.style.cssText = "position:absolute;left:-10000px;top:0;width:100px;height:100px;visibility:hidden";
    const svg = document.importNode(parsed.documentElement, true);
    holder.appendChild(svg);
    document.body.appendChild(holder);
    try {
      let shapes = [...svg.querySelectorAll("path, polyline, polygon")];
      if (shapes.some((s) => s.classList.contains("input"))) shapes = shapes.filter((s) => s.classList.contains("input"));
      const vb = svg.viewBox && svg.viewBox.baseVal;
      const bottom = vb && vb.height ? vb.y + vb.height : 0;
      const toRoot = svg.getScreenCTM().inverse();
      return checked(shapes.map((s) => {
        const m = toRoot.multiply(s.getScreenCTM());
        let pts;
        if (s.localName === "path") {
          const length = s.getTotalLength();
          pts = vertices(s.getAttribute("d") || "")
            || Array.from({ length: SAMPLES }, (_, i) => s.getPointAtLength((length * i) / (SAMPLES - 1)));
        } else {
          pts = [...s.points];
          if (s.localName === "polygon" && pts.length) pts.push(pts[0]);
        }
        return pts.map((p) => new DOMPoint(p.x, p.y).matrixTransform(m)).map((p) => [p.x, bottom - p.y]);
      }), name);
    } finally {
      holder.remove();
    }
  }

  // { curves, notes } of a file's text, by its extension (anything else is read as JSON).
  function parse(name, text) {
    const ext = (name.match(/\.([^.]+)$/) || ["", ""])[1].toLowerCase();
    if (ext === "dat" || ext === "txt") return fromDat(text, name);
    if (ext === "svg") return { curves: fromSvg(text, name), notes: [] };
    if (ext === "csv" || ext === "tsv") return { curves: fromCsv(text, name), notes: [] };
    return { curves: fromJson(text, name), notes: [] };
  }

  // A DXF (AutoCAD 2000, ASCII) of the items: {layer, points} as an LWPOLYLINE, {layer, spline} as a SPLINE with
  // the spline's degree, knots and control points exactly. API coordinates: DXF's y points up too.
  function dxf(items) {
    const out = ["0", "SECTION", "2", "HEADER", "9", "$ACADVER", "1", "AC1015", "0", "ENDSEC",
      "0", "SECTION", "2", "ENTITIES"];
    let handle = 0x100;
    const head = (type, layer, subclass) => out.push("0", type, "5", (handle++).toString(16).toUpperCase(),
      "100", "AcDbEntity", "8", layer, "100", subclass);
    for (const item of items) {
      if (item.spline) {
        const { control_points: ctrl, knots, degree } = item.spline;
        head("SPLINE", item.layer, "AcDbSpline");
        out.push("210", "0", "220", "0", "230", "1", "70", "8", "71", String(degree), "72", String(knots.length),
          "73", String(ctrl.length), "74", "0");
        for (const k of knots) out.push("40", String(k));
        for (const [x, y] of ctrl) out.push("10", String(x), "20", String(y), "30", "0");
      } else {
        head("LWPOLYLINE", item.layer, "AcDbPolyline");
        out.push("90", String(item.points.length), "70", "0");
        for (const [x, y] of item.points) out.push("10", String(x), "20", String(y));
      }
    }
    out.push("0", "ENDSEC", "0", "EOF");
    return out.join("\n") + "\n";
  }

  window.curveFiles = { parse, dxf, CurveFileError };
})();
