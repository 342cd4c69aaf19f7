// curve-vae's page: the vase (POST /revolve's OBJ mesh) read and drawn on a canvas, flat-shaded, no WebGL.
"use strict";

(() => {
  function parseObj(text) {
    const v = [], f = [];
    for (const line of text.split("\n")) {
      const p = line.trim().split(/\s+/);
      if (p[0] === "v") v.push(p.slice(1, 4).map(Number));
      else if (p[0] === "f") f.push(p.slice(1, 4).map((s) => Number(s.split("/")[0]) - 1));
    }
    return { vertices: v, faces: f };
  }

  // Flat-shaded triangles, painter's order, turned about the vertical axis and tilted towards the viewer.
  function draw(canvas, vase, turn) {
    const g = canvas.getContext("2d");
    g.clearRect(0, 0, canvas.width, canvas.height);
    if (!vase) return;
    const { vertices, faces } = vase;
    const t = (turn * Math.PI) / 180, tilt = 0.35;
    const c = [0, 1, 2].map((k) => vertices.reduce((s, p) => s + p[k], 0) / vertices.length);
    const view = vertices.map(([x, y, z]) => {
      const X = (x - c[0]) * Math.cos(t) + (z - c[2]) * Math.sin(t);
      const Z = -(x - c[0]) * Math.sin(t) + (z - c[2]) * Math.cos(t);
      const Y = y - c[1];
      return [X, Y * Math.cos(tilt) - Z * Math.sin(tilt), Y * Math.sin(tilt) + Z * Math.cos(tilt)];
    });
    const size = Math.max(...view.map((p) => Math.max(Math.abs(p[0]), Math.abs(p[1])))) || 1;
    const s = (0.45 * Math.min(canvas.width, canvas.height)) / size;
    const tris = faces.map((f) => {
      const [a, b, d] = f.map((i) => view[i]);
      const n = [(b[1] - a[1]) * (d[2] - a[2]) - (b[2] - a[2]) * (d[1] - a[1]),
        (b[2] - a[2]) * (d[0] - a[0]) - (b[0] - a[0]) * (d[2] - a[2]),
        (b[0] - a[0]) * (d[1] - a[1]) - (b[1] - a[1]) * (d[0] - a[0])];
      const len = Math.hypot(...n) || 1;
      return { pts: [a, b, d], depth: (a[2] + b[2] + d[2]) / 3, light: Math.abs(n[2] / len) };
    }).sort((p, q) => p.depth - q.depth);
    for (const tri of tris) {
      const shade = Math.round(90 + 150 * tri.light);
      g.fillStyle = `rgb(${shade}, ${Math.round(shade * 0.8)}, ${Math.round(shade * 0.6)})`;
      g.beginPath();
      tri.pts.forEach(([x, y], i) => {
        const X = canvas.width / 2 + s * x, Y = canvas.height / 2 - s * y;
        if (i) g.lineTo(X, Y); else g.moveTo(X, Y);
      });
      g.closePath();
      g.fill();
    }
  }

  window.curveVase = { parseObj, draw };
})();
