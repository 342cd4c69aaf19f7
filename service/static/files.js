// curve-vae's page: curve files read in the browser (nothing is uploaded to read them), with the command line's file
// model (curve_vae/curvefiles). This file holds the readers of lists and .npy: window.curveFiles = { parse,
// CurveFileError, ROLES }; files-drawings.js, loaded right after it, adds the readers of drawings (SVG, DXF), and
// files-out.js the writers (write, sheet), onto the same object.
// A drawing is a list of curves in API coordinates (y up), each { name, role, of, weights, points, spline }: role
// "input" (drawn or opened), "reconstruction" (of the input named by `of`) or "interpolant" (the mix and each
// in-between, `weights` by input name); a spline where it has one.
// In (parse): JSON, CSV/TSV, airfoil .dat (Selig or Lednicer, headers, remarks, notes after the coordinates, Fortran
// exponents), SVG (paths, polylines, polygons, transforms and <use> applied), DXF (LWPOLYLINE, POLYLINE, SPLINE,
// inserted blocks) and .npy. Where a file marks roles and holds inputs, its inputs are its curves and the others come
// back as `derived`, with a note; where it marks roles but holds no input, and where it marks none, every curve is a
// curve.
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
  const isPoints = (c) => Array.isArray(c) && c.every((p) => Array.isArray(p) && p.length === 2 && p.every(Number.isFinite));

  function checked(curves, name) {
    const out = curves.filter((c) => c.length);
    out.forEach((c, i) => {
      if (!isPoints(c)) throw new CurveFileError(`${name}: curve ${i + 1} must be a list of [x, y] pairs of numbers`);
      if (c.length < MIN_POINTS) {
        throw new CurveFileError(`${name}: curve ${i + 1} has ${c.length} points; a curve needs at least ${MIN_POINTS}`);
      }
    });
    if (!out.length) throw new CurveFileError(`${name}: no curve in this file`);
    return out;
  }

  // ---------------------------------------------------------------------------------------------- roles

  const ROLES = ["input", "reconstruction", "interpolant"];
  const roleOf = (marks) => (marks || "").split(/\s+/).find((w) => ROLES.includes(w)) || null;
  const weightsText = (w) => Object.entries(w || {}).map(([k, v]) => `${k}=${v}`).join(" ");
  function weightsOf(text) {
    const out = {};
    for (const [k, v] of (text || "").split(/\s+/).map((t) => t.split("="))) if (k && v !== undefined && number(v) !== null) out[k] = number(v);
    return Object.keys(out).length ? out : undefined;
  }

  // A curve of a file as the page keeps it: { name, role, of, weights, points, spline }, the fields it has.
  function item(f) {
    const out = { name: f.name, role: f.role };
    if (f.of !== undefined && f.of !== null && f.of !== "") out.of = String(f.of);
    if (f.weights && Object.keys(f.weights).length) out.weights = f.weights;
    out.points = f.points;
    if (f.spline) out.spline = f.spline;
    return out;
  }

  // The file's curves by the rule above: { picked (those read as curves), derived (items), notes }.
  function chosen(found, name, notes = []) {
    const inputs = found.filter((f) => f.role === "input");
    if (!inputs.length) return { picked: found, derived: [], notes };
    const others = found.filter((f) => f.role !== "input");
    if (others.length) {
      notes.push(`${name}: its ${inputs.length} input curve(s) read; ${others.length} derived curve(s) ` +
        "(reconstructions, interpolants) not read as inputs");
    }
    const derived = others.filter((f) => ROLES.includes(f.role) && isPoints(f.points) && f.points.length > 1).map(item);
    return { picked: inputs, derived, notes };
  }

  // A list's curves (JSON, CSV): the rule, then each curve checked.
  function listed(found, name) {
    const { picked, derived, notes } = chosen(found, name);
    return { curves: checked(picked.map((f) => f.points), name), derived, notes };
  }

  // A drawing's curves (SVG, DXF): the rule, then one of fewer than MIN_POINTS points skipped with a note naming it.
  function drawn(found, name, kinds, notes = []) {
    const { picked, derived } = chosen(found, name, notes);
    const curves = [];
    for (const f of picked) {
      if (f.points.length < MIN_POINTS) notes.push(`${name}: ${f.label}: ${f.points.length} points, not a curve; skipped`);
      else curves.push(f.points);
    }
    if (!curves.length) throw new CurveFileError(`${name}: no curve in this drawing (no ${kinds})`);
    return { curves, derived, notes };
  }

  // ---------------------------------------------------------------------------------------------- JSON, CSV

  function marked(c, points) {
    const f = { name: typeof c.name === "string" ? c.name : undefined, role: typeof c.role === "string" && c.role ? c.role : null, points };
    if (c.of !== undefined && c.of !== null) f.of = String(c.of);
    if (c.weights && typeof c.weights === "object") f.weights = c.weights;
    if (c.spline && typeof c.spline === "object" && Array.isArray(c.spline.control_points)) f.spline = c.spline;
    return f;
  }

  function fromJson(text, name) {
    let data;
    try { data = JSON.parse(text); } catch (e) { throw new CurveFileError(`${name}: not JSON (${e.message})`); }
    if (data && !Array.isArray(data) && typeof data === "object") {
      if (Array.isArray(data.curves)) data = data.curves;
      else if (data.curve) data = [data.curve];
      else if (data.points) data = [data];
      else throw new CurveFileError(`${name}: a JSON object needs a "curves" list`);
    }
    if (!Array.isArray(data)) throw new CurveFileError(`${name}: JSON of curves is a list or an object`);
    if (data.length && Array.isArray(data[0]) && typeof data[0][0] === "number") data = [data];  // one curve
    return listed(data.map((c, i) => {
      if (c && !Array.isArray(c) && typeof c === "object") {
        if (!Array.isArray(c.points)) throw new CurveFileError(`${name}: curves[${i}] is an object without "points"`);
        return marked(c, c.points);
      }
      return { role: null, points: c };
    }), name);
  }

  // A row's cells: apart by the delimiter (a cell in double quotes may hold it), or by spaces.
  function cells(line, delimiter) {
    if (!delimiter) return line.trim().split(/\s+/);
    const out = [];
    let cell = "", quoted = false;
    for (let i = 0; i < line.length; i++) {
      const ch = line[i];
      if (quoted) {
        if (ch !== '"') cell += ch;
        else if (line[i + 1] === '"') { cell += '"'; i++; } else quoted = false;
      } else if (ch === '"' && !cell) quoted = true;
      else if (ch === delimiter) { out.push(cell.trim()); cell = ""; } else cell += ch;
    }
    out.push(cell.trim());
    return out;
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
    const named = header && names.includes("x") && names.includes("y");
    if (named) {
      [x, y] = [names.indexOf("x"), names.indexOf("y")];
      key = ["curve", "name", "id"].map((k) => names.indexOf(k)).find((i) => i >= 0) ?? -1;
    } else if (header && names.length !== 2) {
      throw new CurveFileError(`${name}:${first + 1}: a header row needs columns named x and y`);
    }
    const [role, of, weights] = ["role", "of", "weights"].map((k) => (named ? names.indexOf(k) : -1));
    const found = [{ role: null, points: [] }];
    let last = null;
    const began = new Map();  // each curve name's first row (1-based)
    for (let i = first + (header ? 1 : 0); i < lines.length; i++) {
      if (!lines[i].trim()) {  // a blank line starts the next curve; where a column names the curves, the names do
        if (key < 0) found.push({ role: null, points: [] });
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
          found.push({ name: row[key], role: null, points: [] });
          last = row[key];
        }
      }
      const f = found[found.length - 1];
      if (!f.points.length) {
        if (role >= 0) f.role = row[role] || null;
        if (of >= 0 && row[of]) f.of = row[of];
        if (weights >= 0) f.weights = weightsOf(row[weights]);
      }
      f.points.push([px, py]);
    }
    return listed(found.filter((f) => f.points.length), name);
  }

  // ---------------------------------------------------------------------------------------------- airfoil .dat

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
    return { curves: checked([pts], name), derived: [], notes };
  }

  // ---------------------------------------------------------------------------------------------- .npy in

  // An .npy array (n, 2) or (N, n, 2) of floats or integers (format versions 1 to 3), as curves.
  function fromNpy(data, name) {
    if (typeof data === "string") throw new CurveFileError(`${name}: a numpy file is read as bytes (an ArrayBuffer), not as text`);
    const bytes = new Uint8Array(data.buffer ? data.buffer.slice(data.byteOffset, data.byteOffset + data.byteLength) : data);
    const view = new DataView(bytes.buffer);
    const magic = String.fromCharCode(...bytes.slice(0, 6));
    if (magic !== "\x93NUMPY" || bytes.length < 10) throw new CurveFileError(`${name}: not a numpy file (no .npy header)`);
    const major = bytes[6];
    if (major < 1 || major > 3) throw new CurveFileError(`${name}: a numpy file of format version ${major}; the page reads versions 1 to 3`);
    const long = major >= 2;
    const size = long ? view.getUint32(8, true) : view.getUint16(8, true);
    const at = (long ? 12 : 10) + size;
    const header = new TextDecoder(major === 3 ? "utf-8" : "latin1").decode(bytes.slice(long ? 12 : 10, at));
    const descr = (header.match(/'descr'\s*:\s*'([^']*)'/) || [])[1];
    const fortran = /'fortran_order'\s*:\s*True/.test(header);
    const shapeText = (header.match(/'shape'\s*:\s*\(([^)]*)\)/) || [])[1];
    if (descr === undefined || shapeText === undefined) throw new CurveFileError(`${name}: not a numpy file (its header has no descr or shape)`);
    const shape = shapeText.split(",").map((s) => s.trim()).filter(Boolean).map(Number);
    const shown = `(${shape.join(", ")}${shape.length === 1 ? "," : ""})`;
    const m = descr.match(/^([<>|=]?)([fiu])(\d+)$/);
    const readers = { f4: "getFloat32", f8: "getFloat64", i1: "getInt8", i2: "getInt16", i4: "getInt32", i8: "getBigInt64",
      u1: "getUint8", u2: "getUint16", u4: "getUint32", u8: "getBigUint64" };
    const reader = m && readers[m[2] + m[3]];
    if (!reader) throw new CurveFileError(`${name}: an array of ${descr}; curves are numbers (float32, float64 or integers)`);
    if (!(shape.length === 2 || shape.length === 3) || shape[shape.length - 1] !== 2) {
      throw new CurveFileError(`${name}: an array of shape ${shown}; curves are (n, 2) or (N, n, 2)`);
    }
    const [count, n] = shape.length === 2 ? [1, shape[0]] : shape;
    const width = Number(m[3]), little = m[1] !== ">";
    if (bytes.length < at + count * n * 2 * width) throw new CurveFileError(`${name}: the file ends before its ${shown} array does`);
    const value = (k, j, c) => {  // element [k, j, c] in C order, or Fortran's
      const flat = fortran ? k + count * (j + n * c) : (k * n + j) * 2 + c;
      return Number(view[reader](at + flat * width, little));
    };
    const curves = Array.from({ length: count }, (_, k) => Array.from({ length: n }, (_, j) => [value(k, j, 0), value(k, j, 1)]));
    return { curves: checked(curves, name), derived: [], notes: [] };
  }

  // { curves (the inputs' points), derived (items), notes } of a file: its text, or for .npy an ArrayBuffer, by its
  // extension (anything else is read as JSON).
  function parse(name, data) {
    const ext = (name.match(/\.([^.]+)$/) || ["", ""])[1].toLowerCase();
    if (ext === "npz") {
      throw new CurveFileError(`${name}: the page opens .npy, not .npz: save the curves as one array with numpy.save("curves.npy", ` +
        `curves), or read the .npz with the command line (curve-vae reconstruct ${name})`);
    }
    if (ext === "npy") return fromNpy(data, name);
    const text = typeof data === "string" ? data : new TextDecoder().decode(data);
    return (readers[ext] || fromJson)(text, name);
  }

  // Readers by extension: files-drawings.js adds SVG and DXF.
  const readers = { dat: fromDat, txt: fromDat, csv: fromCsv, tsv: fromCsv };

  // What files-drawings.js (the drawings' readers) and files-out.js (the writers) share with this file: a curve as the
  // page keeps it, weights as text and back, the rule for a drawing's curves, the readers by extension.
  const _shared = { item, weightsText, weightsOf, roleOf, drawn, readers };

  // A curve's name by the order it was made (A, B, …, Z, AA, …) and its colour for life, the command line's
  // (curve_vae/curvefiles/roles.py: PALETTE, curve_name; a test keeps the two equal).
  const PALETTE = ["#1f77b4", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf", "#8c564b", "#e377c2", "#bcbd22", "#7f7f7f", "#393b79"];
  function curveName(k) {
    let name = "";
    for (let n = k + 1; n > 0; n = Math.floor((n - 1) / 26)) name = String.fromCharCode(65 + ((n - 1) % 26)) + name;
    return name;
  }
  function nameIndex(name) {
    if (!/^[A-Z]+$/.test(name || "")) return null;
    return [...name].reduce((k, c) => 26 * k + c.charCodeAt(0) - 64, 0) - 1;
  }
  const colourOf = (name) => { const k = nameIndex(name); return k === null ? PALETTE[0] : PALETTE[k % PALETTE.length]; };

  window.curveFiles = { parse, CurveFileError, ROLES, PALETTE, curveName, nameIndex, colourOf, _shared };
})();
