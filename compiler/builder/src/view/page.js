// lensc view: draws one job's backplot and simulated error map on a 2-D
// canvas with our own orthographic projection (no library, no network),
// fills in the acceptance figures and the set-up from the build's report
// and set-up sheet, and writes a status record (#lensc-status) for the
// tests: script errors, segments drawn, canvas pixels drawn, the figures
// shown.
"use strict";

const status = {
  errors: [],
  segments_drawn: 0,
  pixels_drawn: 0,
  map_cells_drawn: 0,
  frame_ms: 0,
  figures: null,
  moves: null,
};

function writeStatus() {
  const el = document.getElementById("lensc-status");
  if (el) el.textContent = JSON.stringify(status);
}

window.onerror = function (message, source, line, column) {
  status.errors.push(String(message) + " at line " + line + ":" + column);
  writeStatus();
  return false;
};

const D = JSON.parse(document.getElementById("lensc-data").textContent);
const $ = (id) => document.getElementById(id);

// ---- numbers as the page shows them -----------------------------------

function sig(v, digits) {
  if (v === null || v === undefined || !isFinite(v)) return "—";
  if (v === 0) return "0";
  const d = Math.max(0, digits - 1 - Math.floor(Math.log10(Math.abs(v))));
  return v.toFixed(Math.min(d, 9));
}

function duration(s) {
  if (s === null || s === undefined || !isFinite(s)) return "—";
  const h = Math.floor(s / 3600), m = Math.floor((s - 3600 * h) / 60);
  const rest = s - 3600 * h - 60 * m;
  const parts = [];
  if (h > 0) parts.push(h + " h");
  if (h > 0 || m > 0) parts.push(m + " min");
  parts.push(rest.toFixed(1) + " s");
  return parts.join(" ");
}

function plural(n, word) {
  return n.toLocaleString("en") + " " + word + (n === 1 ? "" : "s");
}

function unitText(u) {
  return { nm: "nm", mm2: "mm²", fraction: "of the area", s: "s" }[u] || u;
}

function quantity(v, unit) {
  if (unit === "s") return duration(v);
  if (unit === "fraction") return v === null ? "—" : sig(100 * v, 3) + " %";
  return sig(v, 3) + " " + unitText(unit);
}

// ---- the figures and the set-up ----------------------------------------

function fillFigures() {
  const f = D.figures;
  $("title").textContent = D.job + ": toolpath and simulated part";
  $("subtitle").textContent =
    D.program.file + " (" + D.program.dialect + ", " + D.program.lines.toLocaleString("en") +
    " lines), from " + D.source;
  const verdict = $("verdict");
  const word = f.mode === "none" ? "not judged (accept: none)" : f.passed ? "passed" : "FAILED";
  verdict.textContent = "Verdict: " + word;
  verdict.className = f.passed ? "pass" : "fail";
  const body = $("criteria").querySelector("tbody");
  const shown = {};
  for (const c of f.criteria) {
    const tr = document.createElement("tr");
    const cells = [
      c.criterion.replace(/_/g, " "),
      c.measured === null ? "not measured" : quantity(c.measured, c.unit),
      quantity(c.limit, c.unit) + (c.source === "stated" ? "" : " (default)"),
      c.passed ? "✓" : "✗",
    ];
    for (const text of cells) {
      const td = document.createElement("td");
      td.textContent = text;
      tr.appendChild(td);
    }
    tr.lastChild.className = c.passed ? "pass" : "fail";
    body.appendChild(tr);
    shown[c.criterion] = { measured: c.measured, limit: c.limit, unit: c.unit, passed: c.passed };
  }
  $("judged").textContent = "Judged: " + f.judged + ".";
  const setup = $("setup").querySelector("tbody");
  for (const [label, text] of D.setup) {
    const tr = document.createElement("tr");
    const a = document.createElement("td"), b = document.createElement("td");
    a.textContent = label;
    b.textContent = text;
    tr.appendChild(a);
    tr.appendChild(b);
    setup.appendChild(tr);
  }
  const tr = document.createElement("tr");
  const a = document.createElement("td"), b = document.createElement("td");
  a.textContent = "cutting time";
  b.textContent = duration(f.cutting_time_s) + " (the report's, at the programmed feeds)";
  tr.appendChild(a);
  tr.appendChild(b);
  setup.appendChild(tr);
  status.figures = {
    passed: f.passed,
    judged: f.judged,
    cutting_time_s: f.cutting_time_s,
    criteria: shown,
    setup_rows: D.setup.length,
  };
}

// ---- the scene ----------------------------------------------------------

function decode(b64) {
  const s = atob(b64);
  const a = new Uint8Array(s.length);
  for (let i = 0; i < s.length; i++) a[i] = s.charCodeAt(i);
  return a;
}

const P = D.path;
const reached = decode(P.reached);
const npoints = reached.length;
const pts = new Float64Array(3 * npoints);
{
  const bytes = decode(P.points);
  const dv = new DataView(bytes.buffer);
  for (let i = 0; i < 3 * npoints; i++) {
    const k = i % 3;
    pts[i] = P.lo[k] + (dv.getUint16(2 * i, true) / 65535) * (P.hi[k] - P.lo[k]);
  }
}
const passes = P.passes;

// Viridis, low to high, at nine stops.
const VIRIDIS = [
  [68, 1, 84], [71, 44, 122], [59, 81, 139], [44, 113, 142], [33, 144, 141],
  [39, 173, 129], [92, 200, 99], [170, 220, 50], [253, 231, 37],
];
function colour(t) {
  t = Math.min(1, Math.max(0, t)) * (VIRIDIS.length - 1);
  const i = Math.min(VIRIDIS.length - 2, Math.floor(t)), f = t - i;
  const a = VIRIDIS[i], b = VIRIDIS[i + 1];
  return "rgb(" + [0, 1, 2].map((k) => Math.round(a[k] + f * (b[k] - a[k]))).join(",") + ")";
}

const UNCUT = "rgb(150,150,150)";

// The error map as quads: four corners (x, y, z) and the error (nm).
const quads = [];
let mapRange = null;
function buildMap() {
  const M = D.map;
  const note = $("map-note");
  if (M.kind === "none") {
    note.textContent = "No error map: " + M.why + ".";
    return;
  }
  let lo = Infinity, hi = -Infinity;
  if (M.kind === "revolved") {
    const n = M.radii.length, A = 72;
    for (let i = 0; i + 1 < n; i++) {
      const e = Math.abs(M.error_nm[i]) >= Math.abs(M.error_nm[i + 1]) ? M.error_nm[i] : M.error_nm[i + 1];
      lo = Math.min(lo, e);
      hi = Math.max(hi, e);
      for (let j = 0; j < A; j++) {
        const t0 = (2 * Math.PI * j) / A, t1 = (2 * Math.PI * (j + 1)) / A;
        const r0 = M.radii[i], r1 = M.radii[i + 1], z0 = M.design[i], z1 = M.design[i + 1];
        quads.push({
          c: [r0 * Math.cos(t0), r0 * Math.sin(t0), z0, r1 * Math.cos(t0), r1 * Math.sin(t0), z1,
              r1 * Math.cos(t1), r1 * Math.sin(t1), z1, r0 * Math.cos(t1), r0 * Math.sin(t1), z0],
          e: e,
        });
      }
    }
    note.textContent =
      "The profile's form error (cut − design, nm; positive where material is left) revolved about the spindle on the design surface: " +
      n + " rings, each the error of largest magnitude among the " + M.samples.toLocaleString("en") +
      " simulated radii it stands for.";
  } else {
    const b = M.block;
    const err = new Float32Array(decode(M.error_nm).buffer), design = new Float32Array(decode(M.design).buffer);
    const uncut = decode(M.uncut);
    const z = (k) => (M.flat ? 0 : design[k]);
    const ok = (k) => !isNaN(err[k]) && !isNaN(z(k)) && !uncut[k];
    // A block holding an uncut cell of the part is drawn grey, whatever
    // else it holds.
    for (let k = 0; k < uncut.length; k++) {
      if (!uncut[k] || isNaN(z(k))) continue;
      const x0 = M.x0 + (k % M.nx) * b, y0 = M.y0 + Math.floor(k / M.nx) * b;
      quads.push({ c: [x0, y0, z(k), x0 + b, y0, z(k), x0 + b, y0 + b, z(k), x0, y0 + b, z(k)], e: null });
    }
    let cells = 0;
    for (let k = 0; k < err.length; k++) {
      if (!ok(k)) continue;
      cells++;
      lo = Math.min(lo, err[k]);
      hi = Math.max(hi, err[k]);
    }
    // Neighbours along a row in the same one of 64 colour levels are drawn
    // as one quad (its ends at their own heights).
    const level = (e) => Math.min(63, Math.floor((64 * (e - lo)) / (hi - lo || 1)));
    for (let by = 0; by < M.ny; by++) {
      let bx = 0;
      while (bx < M.nx) {
        const k = by * M.nx + bx;
        if (!ok(k)) { bx++; continue; }
        let end = bx + 1;
        while (end < M.nx && ok(k + end - bx) && level(err[k + end - bx]) === level(err[k]) && end - bx < 16) end++;
        let e = err[k];
        for (let j = k; j < k + end - bx; j++) if (Math.abs(err[j]) > Math.abs(e)) e = err[j];
        const x0 = M.x0 + bx * b, x1 = M.x0 + end * b, y0 = M.y0 + by * b, za = z(k), zb = z(k + end - bx - 1);
        quads.push({ c: [x0, y0, za, x1, y0, zb, x1, y0 + b, zb, x0, y0 + b, za], e: e });
        bx = end;
      }
    }
    note.textContent =
      "The simulated form error (cut − design, nm; positive where material is left, negative a gouge) over the whole simulated part, " +
      M.nx + " × " + M.ny + " blocks " + sig(1000 * b, 3) + " µm square (" + cells.toLocaleString("en") +
      " hold cut cells), each the error of largest magnitude among the grid cells in it" +
      (M.flat ? "; drawn flat at z = 0 in " + M.x_axis + " and " + M.y_axis + " (the part unrolled)." : ", drawn at the design's height at its centre.") +
      " Blocks with no cell of the part are not drawn" +
      (M.uncut_blocks > 0 ? "; grey: the " + M.uncut_blocks + " blocks holding a cell of the part the program leaves uncut." : "; nothing of the part is left uncut.");
  }
  if (lo > hi) return;
  if (lo === hi) {
    lo -= 0.5;
    hi += 0.5;
  }
  mapRange = [lo, hi];
}

let drag = null;
const canvas = $("view");
const ctx = canvas.getContext("2d");
const view = { yaw: -0.7, pitch: 0.75, zoom: 1, panX: 0, panY: 0, zexp: 0 };
let centre = [0, 0, 0], extent = 1;

function zfactor() {
  return Math.pow(10, view.zexp / 5);
}

// Fits the scene (path and map, Z scaled) in the canvas.
function fit() {
  const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  const add = (x, y, z) => {
    lo[0] = Math.min(lo[0], x); hi[0] = Math.max(hi[0], x);
    lo[1] = Math.min(lo[1], y); hi[1] = Math.max(hi[1], y);
    lo[2] = Math.min(lo[2], z); hi[2] = Math.max(hi[2], z);
  };
  for (let i = 0; i < npoints; i++) add(pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]);
  for (const q of quads) for (let k = 0; k < 4; k++) add(q.c[3 * k], q.c[3 * k + 1], q.c[3 * k + 2]);
  if (lo[0] > hi[0]) return;
  const f = zfactor();
  centre = [(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2];
  extent = Math.max(hi[0] - lo[0], hi[1] - lo[1], f * (hi[2] - lo[2]), 1e-6);
}

// The Z scale that makes a flat scene's relief visible: its height (the
// map's and the path's) at least a tenth of its width, at most 100×.
function autoZ() {
  let zlo = Infinity, zhi = -Infinity, xlo = Infinity, xhi = -Infinity;
  const add = (x, z) => {
    zlo = Math.min(zlo, z); zhi = Math.max(zhi, z);
    xlo = Math.min(xlo, x); xhi = Math.max(xhi, x);
  };
  for (const q of quads) for (let k = 0; k < 4; k++) add(q.c[3 * k], q.c[3 * k + 2]);
  for (let i = 0; i < npoints; i++) add(pts[3 * i], pts[3 * i + 2]);
  if (!(zhi > zlo) || !(xhi > xlo)) return 0;
  let e = 0;
  while (e < 10 && Math.pow(10, e / 5) * (zhi - zlo) < 0.1 * (xhi - xlo)) e++;
  return e;
}

function projector() {
  const W = canvas.width, H = canvas.height, f = zfactor();
  const s = (view.zoom * 0.85 * Math.min(W, H)) / extent;
  const cy = Math.cos(view.yaw), sy = Math.sin(view.yaw), cp = Math.cos(view.pitch), sp = Math.sin(view.pitch);
  return function (x, y, z, out) {
    x -= centre[0]; y -= centre[1]; z = (z - centre[2]) * f;
    const x1 = cy * x - sy * y, y1 = sy * x + cy * y;
    out[0] = W / 2 + view.panX + s * x1;
    out[1] = H / 2 + view.panY - s * (z * cp + y1 * sp);
    out[2] = y1 * cp - z * sp;
  };
}

const controls = {
  pass: $("pass"), upto: $("upto"), zscale: $("zscale"), showPath: $("show-path"), showMap: $("show-map"),
};

function draw() {
  const t0 = performance.now();
  const W = canvas.width, H = canvas.height;
  ctx.fillStyle = "#ffffff";
  ctx.fillRect(0, 0, W, H);
  const proj = projector();
  const p = [0, 0, 0];
  let cellsDrawn = 0;
  // While the view turns, a large map is left out (drawn again on release).
  const quick = drag !== null && quads.length > 20000;
  if (controls.showMap.checked && mapRange && !quick) {
    const order = quads.map((q, i) => {
      let d = 0;
      for (let k = 0; k < 4; k++) { proj(q.c[3 * k], q.c[3 * k + 1], q.c[3 * k + 2], p); d += p[2]; }
      return [d, i];
    });
    order.sort((a, b) => b[0] - a[0]);
    const [lo, hi] = mapRange;
    for (const [, i] of order) {
      const q = quads[i];
      ctx.beginPath();
      for (let k = 0; k < 4; k++) {
        proj(q.c[3 * k], q.c[3 * k + 1], q.c[3 * k + 2], p);
        if (k === 0) ctx.moveTo(p[0], p[1]); else ctx.lineTo(p[0], p[1]);
      }
      ctx.closePath();
      const c = q.e === null ? UNCUT : colour((q.e - lo) / (hi - lo));
      ctx.fillStyle = c;
      ctx.strokeStyle = c;
      ctx.lineWidth = 0.6;
      ctx.fill();
      ctx.stroke();
      cellsDrawn++;
    }
  }
  let segments = 0;
  if (controls.showPath.checked && npoints > 0) {
    const upto = Number(controls.upto.value);
    const pass = Number(controls.pass.value);
    const from = pass > 0 ? passes[pass - 1] : -1;
    const to = pass > 0 ? (pass < passes.length ? passes[pass] : npoints - 1) : -1;
    const rapid = new Path2D(), feed = new Path2D(), chosen = new Path2D();
    const q = [0, 0, 0];
    proj(pts[0], pts[1], pts[2], q);
    for (let i = 1; i <= upto && i < npoints; i++) {
      const r = reached[i];
      proj(pts[3 * i], pts[3 * i + 1], pts[3 * i + 2], p);
      if (r !== 0) {
        const path = r === 1 ? rapid : i > from && i <= to ? chosen : feed;
        path.moveTo(q[0], q[1]);
        path.lineTo(p[0], p[1]);
        segments++;
      }
      q[0] = p[0]; q[1] = p[1];
    }
    // Many passes are drawn thin and see-through, so the map shows
    // between them.
    const dense = passes.length > 50 || P.revolution_stride > 1 || npoints > 20000;
    ctx.lineWidth = dense ? 0.6 : 1.5;
    ctx.strokeStyle = "rgba(214,39,40," + (pass > 0 ? 0.2 : dense ? 0.3 : 1) + ")";
    ctx.stroke(feed);
    ctx.setLineDash([5, 4]);
    ctx.lineWidth = dense ? 0.6 : 1;
    ctx.strokeStyle = "rgba(230,85,13," + (dense ? 0.35 : 0.9) + ")";
    ctx.stroke(rapid);
    ctx.setLineDash([]);
    ctx.lineWidth = 2.5;
    ctx.strokeStyle = "rgb(0,0,0)";
    ctx.stroke(chosen);
  }
  drawAxes(proj);
  status.segments_drawn = segments;
  status.map_cells_drawn = cellsDrawn;
  status.frame_ms = Math.round(performance.now() - t0);
}

// A small triad at the lower left: the machine's X, Y, Z directions.
function drawAxes(proj) {
  const o = [0, 0, 0], p = [0, 0, 0];
  proj(centre[0], centre[1], centre[2], o);
  const names = ["X", "Y", "Z"], colours = ["#b00020", "#176b2c", "#1f3fb4"];
  const L = 0.12 * extent;
  for (let k = 0; k < 3; k++) {
    const d = [centre[0], centre[1], centre[2]];
    d[k] += k === 2 ? L / zfactor() : L;
    proj(d[0], d[1], d[2], p);
    const x0 = 40, y0 = canvas.height - 40, dx = p[0] - o[0], dy = p[1] - o[1];
    const n = Math.hypot(dx, dy) || 1, len = 28 * Math.min(1, n / 28 + 0.2);
    ctx.strokeStyle = colours[k];
    ctx.fillStyle = colours[k];
    ctx.lineWidth = 2;
    ctx.beginPath();
    ctx.moveTo(x0, y0);
    ctx.lineTo(x0 + (len * dx) / n, y0 + (len * dy) / n);
    ctx.stroke();
    ctx.font = "12px sans-serif";
    ctx.fillText(names[k], x0 + ((len + 8) * dx) / n - 4, y0 + ((len + 8) * dy) / n + 4);
  }
}

function drawScale() {
  const c = $("scale"), g = c.getContext("2d");
  g.fillStyle = "#fafafa";
  g.fillRect(0, 0, c.width, c.height);
  if (!mapRange) return;
  const [lo, hi] = mapRange, w = c.width - 20;
  for (let i = 0; i < w; i++) {
    g.fillStyle = colour(i / (w - 1));
    g.fillRect(10 + i, 4, 1, 18);
  }
  g.fillStyle = "#111";
  g.font = "12px sans-serif";
  g.textAlign = "left";
  g.fillText(sig(lo, 3) + " nm", 10, 38);
  g.textAlign = "right";
  g.fillText(sig(hi, 3) + " nm", 10 + w, 38);
  g.textAlign = "center";
  g.fillText("form error, cut − design (nm)", c.width / 2, 52);
}

function labels() {
  const pass = Number(controls.pass.value);
  $("pass-label").textContent = pass === 0 ? "all " + passes.length.toLocaleString("en") : pass + " of " + passes.length.toLocaleString("en");
  $("upto-label").textContent = Number(controls.upto.value).toLocaleString("en") + " of " + (npoints - 1).toLocaleString("en") + " points";
  $("zscale-label").textContent = "×" + sig(zfactor(), 2);
}

function setup() {
  fillFigures();
  buildMap();
  controls.pass.max = String(passes.length);
  controls.upto.max = String(Math.max(0, npoints - 1));
  controls.upto.value = String(Math.max(0, npoints - 1));
  view.zexp = autoZ();
  controls.zscale.value = String(view.zexp);
  fit();
  $("legend").innerHTML =
    '<span><i style="border-color:rgb(214,39,40)"></i>cutting moves</span>' +
    '<span><i style="border-color:rgb(230,85,13);border-top-style:dashed"></i>rapids</span>' +
    '<span><i style="border-color:#000;border-top-width:3px"></i>the pass chosen</span>';
  const drawn = P.segments, made = P.rapids + P.feeds;
  $("thinning").textContent =
    "The program as the controller reads it (the reader of lensc verify): " + made.toLocaleString("en") + " moves (" +
    plural(P.rapids, "rapid") + ", " + plural(P.feeds, "cutting move") + "), " +
    (P.revolution_stride > 1
      ? "one spindle revolution in " + P.revolution_stride + " drawn (the others lie between them, microns apart), "
      : "") +
    (P.step_mm > 0
      ? "drawn as " + drawn.toLocaleString("en") + " segments: every rapid and every pass's first and last point kept, the cutting moves between them thinned to points at least " +
        sig(1000 * P.step_mm, 3) + " µm apart along the path."
      : "every one drawn (" + drawn.toLocaleString("en") + " segments, arcs in short pieces).") +
    (P.truncated ? " The program is longer than the page draws: its end is not shown." : "") +
    " Coordinates as programmed" + (P.lathe ? " (X a radius, turned by C)." : ".");
  status.moves = { rapids: P.rapids, feeds: P.feeds, step_mm: P.step_mm, revolution_stride: P.revolution_stride, truncated: P.truncated, points: npoints, passes: passes.length };
  labels();
  drawScale();
}

function countPixels() {
  const img = ctx.getImageData(0, 0, canvas.width, canvas.height).data;
  let n = 0;
  for (let i = 0; i < img.length; i += 4) {
    if (img[i] !== 255 || img[i + 1] !== 255 || img[i + 2] !== 255) n++;
  }
  return n;
}

// ---- interaction --------------------------------------------------------

canvas.addEventListener("mousedown", (e) => {
  drag = { x: e.clientX, y: e.clientY, pan: e.shiftKey || e.button === 2 };
  canvas.style.cursor = "grabbing";
});
canvas.addEventListener("contextmenu", (e) => e.preventDefault());
window.addEventListener("mouseup", () => {
  if (drag === null) return;
  drag = null;
  canvas.style.cursor = "grab";
  redraw();
});
let pending = false;
function redraw() {
  if (pending) return;
  pending = true;
  requestAnimationFrame(() => {
    pending = false;
    draw();
  });
}
window.addEventListener("mousemove", (e) => {
  if (!drag) return;
  const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
  drag.x = e.clientX;
  drag.y = e.clientY;
  if (drag.pan) {
    view.panX += dx;
    view.panY += dy;
  } else {
    view.yaw -= dx * 0.01;
    view.pitch = Math.min(Math.PI / 2, Math.max(-Math.PI / 2, view.pitch + dy * 0.01));
  }
  redraw();
});
canvas.addEventListener("wheel", (e) => {
  e.preventDefault();
  view.zoom *= Math.exp(-e.deltaY * 0.0015);
  redraw();
}, { passive: false });
for (const el of [controls.pass, controls.upto, controls.showPath, controls.showMap]) {
  el.addEventListener("input", () => { labels(); redraw(); });
}
controls.zscale.addEventListener("input", () => {
  view.zexp = Number(controls.zscale.value);
  fit();
  labels();
  redraw();
});
$("reset").addEventListener("click", () => {
  Object.assign(view, { yaw: -0.7, pitch: 0.75, zoom: 1, panX: 0, panY: 0 });
  redraw();
});

setup();
draw();
status.pixels_drawn = countPixels();
writeStatus();
