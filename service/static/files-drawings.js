// curve-vae's page: drawings read in the browser, with the command line's file model (curve_vae/curvefiles): SVG
// (paths, polylines, polygons, transforms and <use> applied) and DXF (LWPOLYLINE, POLYLINE, SPLINE, inserted blocks),
// added to files.js's readers (loaded before it); the DXF application name, for files-out.js's writer.
"use strict";

(() => {
  const { CurveFileError, ROLES, _shared } = window.curveFiles;
  const { drawn, roleOf, weightsOf, readers } = _shared;

  // ---------------------------------------------------------------------------------------------- SVG in

  const SEGMENT_SAMPLES = 16;  // points along a curved segment (cubic, quadratic, arc), as the command line samples them
  const SVG_NUM = /[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?/y;
  const mul = (m, n) => [m[0] * n[0] + m[2] * n[1], m[1] * n[0] + m[3] * n[1], m[0] * n[2] + m[2] * n[3],
    m[1] * n[2] + m[3] * n[3], m[0] * n[4] + m[2] * n[5] + m[4], m[1] * n[4] + m[3] * n[5] + m[5]];
  const ID = [1, 0, 0, 1, 0, 0];

  // An SVG transform attribute as [a, b, c, d, e, f].
  function transformOf(text) {
    let m = ID;
    for (const [, kind, args] of (text || "").matchAll(/(matrix|translate|scale|rotate|skewX|skewY)\s*\(([^)]*)\)/g)) {
      const v = (args.match(/[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?/g) || []).map(Number);
      const r = ((v[0] || 0) * Math.PI) / 180;
      let t;
      if (kind === "matrix") t = v.length === 6 ? v : ID;
      else if (kind === "translate") t = [1, 0, 0, 1, v[0] || 0, v[1] || 0];
      else if (kind === "scale") t = [v[0] ?? 1, 0, 0, v[1] ?? v[0] ?? 1, 0, 0];
      else if (kind === "skewX") t = [1, 0, Math.tan(r), 1, 0, 0];
      else if (kind === "skewY") t = [1, Math.tan(r), 0, 1, 0, 0];
      else {
        const [cx, cy] = [v[1] || 0, v[2] || 0];
        t = mul(mul([1, 0, 0, 1, cx, cy], [Math.cos(r), Math.sin(r), -Math.sin(r), Math.cos(r), 0, 0]), [1, 0, 0, 1, -cx, -cy]);
      }
      m = mul(m, t);
    }
    return m;
  }

  function arcPoints([x1, y1], rx, ry, phiDeg, large, sweep, [x2, y2]) {
    if (x1 === x2 && y1 === y2) return [];
    if (!rx || !ry) return [[x2, y2]];
    [rx, ry] = [Math.abs(rx), Math.abs(ry)];
    const phi = (phiDeg * Math.PI) / 180, cos = Math.cos(phi), sin = Math.sin(phi);
    const dx = (x1 - x2) / 2, dy = (y1 - y2) / 2;
    const xp = cos * dx + sin * dy, yp = -sin * dx + cos * dy;
    const lambda = (xp * xp) / (rx * rx) + (yp * yp) / (ry * ry);
    if (lambda > 1) [rx, ry] = [rx * Math.sqrt(lambda), ry * Math.sqrt(lambda)];
    const num = rx * rx * ry * ry - rx * rx * yp * yp - ry * ry * xp * xp;
    const coef = (large !== sweep ? 1 : -1) * Math.sqrt(Math.max(0, num / (rx * rx * yp * yp + ry * ry * xp * xp)));
    const cxp = (coef * rx * yp) / ry, cyp = (-coef * ry * xp) / rx;
    const cx = cos * cxp - sin * cyp + (x1 + x2) / 2, cy = sin * cxp + cos * cyp + (y1 + y2) / 2;
    const angle = (ux, uy, vx, vy) => Math.atan2(ux * vy - uy * vx, ux * vx + uy * vy);
    const t1 = angle(1, 0, (xp - cxp) / rx, (yp - cyp) / ry);
    let dt = angle((xp - cxp) / rx, (yp - cyp) / ry, (-xp - cxp) / rx, (-yp - cyp) / ry);
    if (!sweep && dt > 0) dt -= 2 * Math.PI;
    if (sweep && dt < 0) dt += 2 * Math.PI;
    return Array.from({ length: SEGMENT_SAMPLES }, (_, k) => {
      const t = t1 + (dt * (k + 1)) / SEGMENT_SAMPLES;
      return k === SEGMENT_SAMPLES - 1 ? [x2, y2]
        : [cx + rx * cos * Math.cos(t) - ry * sin * Math.sin(t), cy + rx * sin * Math.cos(t) + ry * cos * Math.sin(t)];
    });
  }

  function bezierPoints(p) {  // p: 3 or 4 control points
    return Array.from({ length: SEGMENT_SAMPLES }, (_, k) => {
      const s = (k + 1) / SEGMENT_SAMPLES, u = 1 - s;
      const w = p.length === 4 ? [u * u * u, 3 * s * u * u, 3 * s * s * u, s * s * s] : [u * u, 2 * s * u, s * s];
      return [0, 1].map((j) => w.reduce((acc, wi, i) => acc + wi * p[i][j], 0));
    });
  }

  // Each subpath's points of a path's d: the vertices of lines, samples of curved segments.
  function subpaths(d) {
    const out = [];
    let i = 0, cmd = null, cur = [0, 0], start = [0, 0], ctrl = null, prev = "";
    const skip = () => { while (i < d.length && /[\s,]/.test(d[i])) i++; };
    const num = () => {
      skip();
      SVG_NUM.lastIndex = i;
      const m = SVG_NUM.exec(d);
      if (!m) throw new Error("bad path");
      i += m[0].length;
      return Number(m[0]);
    };
    const flag = () => { skip(); if (d[i] !== "0" && d[i] !== "1") throw new Error("bad flag"); return d[i++] === "1"; };
    const add = (pts) => { if (out.length) out[out.length - 1].push(...pts); };
    try {
      for (skip(); i < d.length; skip()) {
        if (/[A-Za-z]/.test(d[i])) cmd = d[i++];
        else if (!cmd) break;
        const c = cmd.toUpperCase(), rel = cmd !== c;
        const pt = () => { const [x, y] = [num(), num()]; return rel ? [cur[0] + x, cur[1] + y] : [x, y]; };
        if (c === "Z") {
          add([start]);
          cur = start;
          cmd = null;
        } else if (c === "M") {
          cur = start = pt();
          out.push([cur]);
          cmd = rel ? "l" : "L";  // pairs after a move are lines
        } else if (c === "L") {
          cur = pt();
          add([cur]);
        } else if (c === "H" || c === "V") {
          const v = num();
          cur = c === "H" ? [rel ? cur[0] + v : v, cur[1]] : [cur[0], rel ? cur[1] + v : v];
          add([cur]);
        } else if (c === "C" || c === "S") {
          const c1 = c === "C" ? pt() : (ctrl && "CS".includes(prev) ? [2 * cur[0] - ctrl[0], 2 * cur[1] - ctrl[1]] : cur);
          const c2 = pt(), end = pt();
          add(bezierPoints([cur, c1, c2, end]));
          [ctrl, cur] = [c2, end];
        } else if (c === "Q" || c === "T") {
          const c1 = c === "Q" ? pt() : (ctrl && "QT".includes(prev) ? [2 * cur[0] - ctrl[0], 2 * cur[1] - ctrl[1]] : cur);
          const end = pt();
          add(bezierPoints([cur, c1, end]));
          [ctrl, cur] = [c1, end];
        } else if (c === "A") {
          const [rx, ry, phi, large, sweep] = [num(), num(), num(), flag(), flag()];
          const end = pt();
          add(arcPoints(cur, rx, ry, phi, large, sweep, end));
          cur = end;
        } else break;
        prev = c;
      }
    } catch (e) { /* a path draws up to its first error, as browsers draw it */ }
    // a point again where it already is (a close onto the last point) adds nothing
    return out.map((pts) => pts.filter((p, k) => !k || p[0] !== pts[k - 1][0] || p[1] !== pts[k - 1][1]));
  }

  const NOT_DRAWN = new Set(["defs", "clipPath", "mask", "marker", "pattern", "symbol", "metadata", "title", "desc",
    "style", "script", "text", "foreignObject"]);

  // The drawing's paths, polylines and polygons in its user units (the root's viewBox), a point (x, y) of the file
  // read as (x, -y): the command line's convention, so the page's own SVG opens where it was drawn.
  function fromSvg(text, name) {
    const doc = new DOMParser().parseFromString(text, "image/svg+xml");
    if (doc.querySelector("parsererror") || doc.documentElement.localName !== "svg") {
      throw new CurveFileError(`${name}: not an SVG drawing`);
    }
    const found = [];
    const walk = (el, m, depth) => {
      const tag = el.localName;
      if (NOT_DRAWN.has(tag) || depth > 32) return;
      m = mul(m, transformOf(el.getAttribute("transform")));
      if (tag === "use") {
        const ref = (el.getAttribute("href") || el.getAttributeNS("http://www.w3.org/1999/xlink", "href") || "").slice(1);
        const target = ref && [...doc.getElementsByTagName("*")].find((e) => e.getAttribute("id") === ref);
        const at = [1, 0, 0, 1, Number(el.getAttribute("x")) || 0, Number(el.getAttribute("y")) || 0];
        if (target) (target.localName === "symbol" ? [...target.children] : [target]).forEach((t) => walk(t, mul(m, at), depth + 1));
        return;
      }
      if (tag === "path" || tag === "polyline" || tag === "polygon") {
        let paths;
        if (tag === "path") paths = subpaths(el.getAttribute("d") || "");
        else {
          const v = (el.getAttribute("points") || "").match(/[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?/g) || [];
          const pts = Array.from({ length: Math.floor(v.length / 2) }, (_, k) => [Number(v[2 * k]), Number(v[2 * k + 1])]);
          if (tag === "polygon" && pts.length) pts.push(pts[0]);
          paths = [pts.filter((p, k) => !k || p[0] !== pts[k - 1][0] || p[1] !== pts[k - 1][1])];
        }
        const id = el.getAttribute("id");
        for (const pts of paths) {
          found.push({
            label: id ? `${tag}#${id}` : tag, name: el.getAttribute("data-name") ?? undefined,
            role: roleOf(el.getAttribute("class")), of: el.getAttribute("data-of") ?? undefined,
            weights: weightsOf(el.getAttribute("data-weights")),
            points: pts.map(([x, y]) => [m[0] * x + m[2] * y + m[4], -(m[1] * x + m[3] * y + m[5])]),
          });
        }
        return;
      }
      for (const child of el.children) walk(child, m, depth);
    };
    for (const child of doc.documentElement.children) walk(child, ID, 0);
    return drawn(found, name, "path, polyline or polygon of 4 points or more");
  }

  // ---------------------------------------------------------------------------------------------- DXF in

  const APPID = "CURVE_VAE";
  const SAMPLES_PER_CONTROL_POINT = 8;  // points along a SPLINE per control point, at least 64: as the command line

  // A point of a B-spline (homogeneous control points [x*w, y*w, w]) at t, by de Boor's algorithm.
  function deBoor(t, p, knots, ctrl) {
    let k = p;
    while (k < ctrl.length - 1 && t >= knots[k + 1]) k++;
    const d = Array.from({ length: p + 1 }, (_, j) => ctrl[j + k - p].slice());
    for (let r = 1; r <= p; r++) {
      for (let j = p; j >= r; j--) {
        const lo = knots[j + k - p], span = knots[j + 1 + k - r] - lo;
        const a = span ? (t - lo) / span : 0;
        d[j] = d[j].map((v, c) => (1 - a) * d[j - 1][c] + a * v);
      }
    }
    return d[p];
  }

  // Points along a spline {degree, knots, control_points, weights?}, evenly in its parameter.
  function splinePoints({ degree: p, knots, control_points: cp, weights }) {
    const n = Math.max(64, SAMPLES_PER_CONTROL_POINT * cp.length);
    const ctrl = cp.map(([x, y], i) => { const w = weights && weights.length === cp.length ? weights[i] : 1; return [x * w, y * w, w]; });
    const [t0, t1] = [knots[p], knots[cp.length]];
    return Array.from({ length: n }, (_, i) => {
      const [x, y, w] = deBoor(t0 + ((t1 - t0) * i) / (n - 1), p, knots, ctrl);
      return [x / w, y / w];
    });
  }

  function dxfEntities(tags) {  // a section's tags, as entities: { type, tags (before XDATA), xdata }
    const out = [];
    for (const [code, value] of tags) {
      if (code === 0) out.push({ type: value, tags: [], xdata: [] });
      else if (out.length) (code >= 1000 || out[out.length - 1].xdata.length ? out[out.length - 1].xdata : out[out.length - 1].tags).push([code, value]);
    }
    return out;
  }

  // A closed polyline (flag 1) is a loop: it ends where it starts.
  const closed = (pts, flags) => ((Number(flags) & 1) && pts.length && (pts[0][0] !== pts[pts.length - 1][0] ||
    pts[0][1] !== pts[pts.length - 1][1]) ? [...pts, pts[0]] : pts);

  function fromDxf(text, name) {
    if (text.startsWith("AutoCAD Binary DXF")) throw new CurveFileError(`${name}: a binary DXF; save it as an ASCII DXF to open it here`);
    const lines = text.split(/\r?\n/);
    const tags = [];
    for (let i = 0; i + 1 < lines.length; i += 2) {
      const code = lines[i].trim();
      if (!/^-?\d+$/.test(code)) throw new CurveFileError(`${name}:${i + 1}: not a DXF drawing (a group code, got "${code}")`);
      tags.push([Number(code), lines[i + 1].trim()]);
    }
    const sections = {};
    for (let i = 0; i < tags.length; i++) {
      if (tags[i][0] === 0 && tags[i][1] === "SECTION" && tags[i + 1] && tags[i + 1][0] === 2) {
        const end = tags.findIndex((t, j) => j > i && t[0] === 0 && t[1] === "ENDSEC");
        sections[tags[i + 1][1]] = tags.slice(i + 2, end < 0 ? tags.length : end);
      }
    }
    if (!sections.ENTITIES) throw new CurveFileError(`${name}: not a DXF drawing (no ENTITIES section)`);
    const blocks = {};
    let block = null;
    for (const e of dxfEntities(sections.BLOCKS || [])) {
      if (e.type === "BLOCK") {
        const get = (c) => (e.tags.find((t) => t[0] === c) || [0, "0"])[1];
        block = { entities: [], base: [Number(get(10)), Number(get(20))] };
        blocks[get(2)] = block;
      } else if (e.type === "ENDBLK") block = null;
      else if (block) block.entities.push(e);
    }
    const found = [], notes = [];
    const visit = (entities, m, depth, inBlock) => {
      for (let i = 0; i < entities.length; i++) {
        const e = entities[i];
        const all = (c) => e.tags.filter((t) => t[0] === c).map((t) => t[1]);
        const one = (c, dflt) => { const v = all(c); return v.length ? v[0] : dflt; };
        if (one(67, "0") === "1") continue;  // paper space
        const at = ([x, y]) => [m[0] * x + m[2] * y + m[4], m[1] * x + m[3] * y + m[5]];
        const xy = (cx, cy) => all(cx).map((x, k) => [Number(x), Number(all(cy)[k])]);
        const label = inBlock ? `${e.type} of a block` : `${e.type} #${one(5, "")}`;
        let points = null, spline;
        if (e.type === "INSERT") {
          const b = blocks[one(2, "")];
          if (!b || depth > 16) continue;
          const r = (Number(one(50, "0")) * Math.PI) / 180;
          const [sx, sy] = [Number(one(41, "1")), Number(one(42, "1"))];
          const t = mul(mul([1, 0, 0, 1, Number(one(10, "0")), Number(one(20, "0"))],
            [Math.cos(r) * sx, Math.sin(r) * sx, -Math.sin(r) * sy, Math.cos(r) * sy, 0, 0]), [1, 0, 0, 1, -b.base[0], -b.base[1]]);
          visit(b.entities, mul(m, t), depth + 1, true);
          continue;
        } else if (e.type === "LWPOLYLINE") {
          points = closed(xy(10, 20), one(70, "0"));
          if (all(42).some((b) => Number(b))) notes.push(`${name}: ${label}: its arcs (bulges) read as straight lines`);
        } else if (e.type === "POLYLINE") {
          points = [];
          while (entities[i + 1] && entities[i + 1].type === "VERTEX") {
            const v = entities[++i].tags;
            points.push([10, 20].map((c) => Number((v.find((t) => t[0] === c) || [0, "0"])[1])));
          }
          points = closed(points, one(70, "0"));
        } else if (e.type === "SPLINE") {
          const ctrl = xy(10, 20);
          if (!ctrl.length) { notes.push(`${name}: ${label}: a spline by fit points only; skipped`); continue; }
          const s = { degree: Number(one(71, "3")), knots: all(40).map(Number), control_points: ctrl.map(at) };
          const w = all(41).map(Number);
          points = splinePoints({ ...s, weights: w });
          if (!w.length) spline = s;
        } else continue;
        if (e.type !== "SPLINE") points = points.map(at);
        const marks = {};
        let ours = false;
        for (const [code, value] of e.xdata) {
          if (code === 1001) ours = value === APPID;
          else if (ours && code === 1000) { const k = value.indexOf("="); if (k > 0) marks[value.slice(0, k)] = value.slice(k + 1); }
        }
        const layer = one(8, "0");
        const role = ROLES.includes(marks.role) ? marks.role : (ROLES.includes(layer.split("-")[0]) ? layer.split("-")[0] : null);
        const fromLayer = layer.includes("-") ? layer.slice(layer.indexOf("-") + 1) : undefined;
        found.push({ label, name: marks.name ?? fromLayer, role, of: marks.of, weights: weightsOf(marks.weights), points, spline });
      }
    };
    visit(dxfEntities(sections.ENTITIES), ID, 0, false);
    return drawn(found, name, "LWPOLYLINE, POLYLINE or SPLINE of 4 points", notes);
  }

  readers.svg = fromSvg;
  readers.dxf = fromDxf;
  _shared.APPID = APPID;
})();
