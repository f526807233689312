// The Operational page (/operate): the thesis' fig. 3.36 over the session's robot.
//
// A view, as every page: Run_simulation, Trigger and Stop_simulation send commands
// (run, operate_trigger, operate_stop; declared and handled by ttt_sm.web.commands.operate
// over ttt_sm.web.operate), and each frame's "operate" part (the status message, whether
// Trigger is taken and why not, the last drawing's precision) and "plot" part (the
// graphs' samples, taken in simulated time by the session) are drawn.  The graphs
// are plain canvases drawn here; their data live in a ring buffer of fixed size.

import { InkPicture } from "./arm.js";
import { $, role } from "./dom.js";
import { addDrive1Stop, addSpeed, drawCommon, drawSpeed, pageHeader, sayReply as say } from "./page.js";
import { SessionLink } from "./session.js";

//: Samples kept per column (2 minutes at 25 a simulated second); the oldest are overwritten.
const CAPACITY = 3000;
//: The graphs show the last this many simulated seconds.
const WINDOW_S = 20;

//: minSpan: the least span of a graph's vertical axis, in its unit: an idle arm's noise (a few µm,
//: a few mA) is drawn as the flat line it is, not blown up to fill the graph (1 mm; 0.2 A; 0.5 deg,
//: about 0.01 rad).  Desired and measured share one axis.
const GRAPHS = [
  { id: "x_axis", title: "X axis", unit: "mm", minSpan: 1, series: [["x_desired_mm", "desired", "#1f4e9c"], ["x_fk_mm", "FK of the encoders", "#d33"]] },
  { id: "y_axis", title: "Y axis", unit: "mm", minSpan: 1, series: [["y_desired_mm", "desired", "#1f4e9c"], ["y_fk_mm", "FK of the encoders", "#d33"]] },
  { id: "z_axis", title: "Z axis", unit: "mm", minSpan: 1, series: [["z_desired_mm", "desired", "#1f4e9c"], ["z_fk_mm", "FK of the encoders", "#d33"]] },
  { id: "first_drive", title: "First drive", unit: "A", minSpan: 0.2, series: [["current_1_a", "motor current", "#1d7a1d"]] },
  { id: "second_drive", title: "Second drive", unit: "A", minSpan: 0.2, series: [["current_2_a", "motor current", "#1d7a1d"]] },
  { id: "third_drive", title: "Third drive", unit: "A", minSpan: 0.2, series: [["current_3_a", "motor current", "#1d7a1d"]] },
  { id: "following_error", title: "Following error", unit: "deg", minSpan: 0.5, series: [["following_error_1_deg", "drive 1", "#1f4e9c"], ["following_error_2_deg", "drive 2", "#d33"], ["following_error_3_deg", "drive 3", "#1d7a1d"]] },
];

const MEANS = { X: "the X's side", O: "the O's diameter", sine: "the sine wave's peak to peak", staircase: "" };

const state = { op: null, speedRange: [5, 30], toAck: [], dirty: false };
// What the graphs received, for the tests and the bench: points, redraws, simulated time covered.
const stats = { points: 0, redraws: 0, firstT: null, lastT: null };
window.operateStats = stats;

// -- the ring buffer ------------------------------------------------------------------------

class Ring {
  constructor(columns, capacity) {
    this.columns = columns;
    this.index = Object.fromEntries(columns.map((c, i) => [c, i]));
    this.data = columns.map(() => new Float64Array(capacity));
    this.capacity = capacity;
    this.n = 0;      // rows held
    this.next = 0;   // where the next row goes
  }
  push(row) {
    for (let i = 0; i < this.data.length; i++) {
      const v = row[i];
      this.data[i][this.next] = v === null || v === undefined ? NaN : v;
    }
    this.next = (this.next + 1) % this.capacity;
    this.n = Math.min(this.n + 1, this.capacity);
  }
  // The k-th row held, oldest first: column `c`'s value.
  at(c, k) {
    return this.data[c][(this.next - this.n + k + this.capacity) % this.capacity];
  }
  get lastT() {
    return this.n ? this.at(0, this.n - 1) : -Infinity;
  }
}

let ring = new Ring(["t_s"], CAPACITY);

function takePlot(plot) {
  if (plot.reset) {
    ring = new Ring(plot.columns, CAPACITY);
  }
  for (const row of plot.rows) {
    if (!(row[0] > ring.lastT)) continue; // a joining page may get a sample twice
    ring.push(row);
    stats.points++;
    if (stats.firstT === null) stats.firstT = row[0];
    stats.lastT = row[0];
  }
  state.dirty = true;
}

// -- the graphs -----------------------------------------------------------------------------

function buildGraphs() {
  const box = role("graphs");
  for (const g of GRAPHS) {
    const fig = document.createElement("figure");
    fig.className = "graph";
    fig.dataset.graph = g.id;
    const cap = document.createElement("figcaption");
    const title = document.createElement("b");
    title.textContent = `${g.title}, ${g.unit}`;
    const legend = document.createElement("span");
    legend.className = "legend";
    for (const [, label, colour] of g.series) {
      const i = document.createElement("i");
      i.style.background = colour;
      legend.append(i, label);
    }
    const csv = document.createElement("button");
    csv.type = "button";
    csv.textContent = "CSV";
    csv.setAttribute("aria-label", `${g.title} CSV`);
    csv.title = "download this graph's data (every sample held) as CSV";
    csv.addEventListener("click", () => download(g));
    cap.append(title, legend, csv);
    const canvas = document.createElement("canvas");
    canvas.setAttribute("role", "img");
    canvas.setAttribute("aria-label", `${g.title}: ${g.series.map((s) => s[1]).join(", ")}, ${g.unit}, the last ${WINDOW_S} s`);
    fig.append(cap, canvas);
    box.append(fig);
    g.canvas = canvas;
  }
}

// The vertical axis of a graph: the data's range, at least `minSpan` wide (centred on the data), with
// a margin, and ticks at a round step whose labels differ ("159.5 / 160 / 160.5", never "160 / 160 / 160").
function axisRange(lo, hi, minSpan) {
  if (!Number.isFinite(lo) || !Number.isFinite(hi)) { lo = -minSpan / 2; hi = minSpan / 2; }
  if (hi - lo < minSpan) {
    const mid = (lo + hi) / 2;
    lo = mid - minSpan / 2;
    hi = mid + minSpan / 2;
  }
  const pad = (hi - lo) * 0.08;
  lo -= pad;
  hi += pad;
  // the largest round step (1, 2 or 5 times a power of ten) that puts at least three ticks on the axis
  let base = Math.pow(10, Math.ceil(Math.log10(hi - lo))), step = base;
  for (let k = 0; k < 40; k++) {
    step = base * [1, 0.5, 0.2][k % 3];
    if (Math.floor(hi / step) - Math.ceil(lo / step) + 1 >= 3) break;
    if (k % 3 === 2) base /= 10;
  }
  const decimals = Math.max(0, -Math.floor(Math.log10(step) + 1e-9));
  const ticks = [];
  for (let v = Math.ceil(lo / step) * step; v <= hi + step * 1e-9; v += step) ticks.push(v);
  return { lo, hi, ticks, labels: ticks.map((v) => (Math.abs(v) < step / 1e6 ? 0 : v).toFixed(decimals)) };
}

function drawGraph(g) {
  const canvas = g.canvas;
  const dpr = window.devicePixelRatio || 1;
  const w = canvas.clientWidth, h = canvas.clientHeight;
  if (canvas.width !== Math.round(w * dpr) || canvas.height !== Math.round(h * dpr)) {
    canvas.width = Math.round(w * dpr);
    canvas.height = Math.round(h * dpr);
  }
  const ctx = canvas.getContext("2d");
  ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
  ctx.clearRect(0, 0, w, h);
  const left = 52, right = 6, top = 6, bottom = 18;
  const cols = g.series.map(([name]) => ring.index[name]).filter((c) => c !== undefined);
  const tEnd = ring.n ? ring.lastT : WINDOW_S;
  const tStart = tEnd - WINDOW_S;
  let first = ring.n;
  while (first > 0 && ring.at(0, first - 1) >= tStart) first--;
  let lo = Infinity, hi = -Infinity;
  for (const c of cols) {
    for (let k = first; k < ring.n; k++) {
      const v = ring.at(c, k);
      if (v < lo) lo = v;
      if (v > hi) hi = v;
    }
  }
  const axis = axisRange(lo, hi, g.minSpan);
  lo = axis.lo;
  hi = axis.hi;
  canvas.dataset.yTicks = axis.labels.join(" / ");
  canvas.dataset.yRange = `${lo} ${hi}`;
  const x = (t) => left + ((t - tStart) / WINDOW_S) * (w - left - right);
  const y = (v) => top + (1 - (v - lo) / (hi - lo)) * (h - top - bottom);
  ctx.strokeStyle = "#ddd";
  ctx.fillStyle = "#666";
  ctx.font = "11px sans-serif";
  ctx.lineWidth = 1;
  ctx.textAlign = "right";
  ctx.textBaseline = "middle";
  axis.ticks.forEach((v, i) => {
    ctx.beginPath();
    ctx.moveTo(left, y(v));
    ctx.lineTo(w - right, y(v));
    ctx.stroke();
    ctx.fillText(axis.labels[i], left - 4, y(v));
  });
  ctx.textAlign = "center";
  ctx.textBaseline = "top";
  for (let s = Math.ceil(tStart / 5) * 5; s <= tEnd; s += 5) {
    ctx.fillText(`${s} s`, x(s), h - bottom + 3);
  }
  g.series.forEach(([name, , colour]) => {
    const c = ring.index[name];
    if (c === undefined) return;
    ctx.strokeStyle = colour;
    ctx.lineWidth = 1.5;
    ctx.beginPath();
    let pen = false;
    for (let k = first; k < ring.n; k++) {
      const v = ring.at(c, k);
      if (Number.isNaN(v)) {
        pen = false;
        continue;
      }
      const px = x(ring.at(0, k)), py = y(v);
      if (pen) ctx.lineTo(px, py);
      else ctx.moveTo(px, py);
      pen = true;
    }
    ctx.stroke();
  });
}

function redraw() {
  if (state.dirty) {
    state.dirty = false;
    for (const g of GRAPHS) drawGraph(g);
    drawTip();
    stats.redraws++;
  }
  // The frames are drawn: acknowledged for the latency figures (the session's clock).
  for (const seq of state.toAck) link.ack(seq);
  state.toAck = [];
  requestAnimationFrame(redraw);
}

function csvText(g) {
  const names = ["t_s", ...g.series.map(([name]) => name)];
  const cols = names.map((n) => ring.index[n]);
  const lines = [names.join(",")];
  for (let k = 0; k < ring.n; k++) {
    lines.push(cols.map((c) => (c === undefined || Number.isNaN(ring.at(c, k)) ? "" : String(ring.at(c, k)))).join(","));
  }
  return lines.join("\n") + "\n";
}

function download(g) {
  const url = URL.createObjectURL(new Blob([csvText(g)], { type: "text/csv" }));
  const a = document.createElement("a");
  a.href = url;
  a.download = `${g.id}.csv`;
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(url), 10_000);
}

// -- what was drawn, X-Y ----------------------------------------------------------------------
// The whiteboard seen from above in the X, Y of the graphs (mm): the board, the field, the ink on
// it (the board's own picture, /api/arm/ink.png, fetched again when the frame's arm.ink key
// changes) and the pen tip where the encoders put it.  It holds what is on the board, whenever it
// was drawn: it does not scroll away with the graphs' 20 s.

const SVG = "http://www.w3.org/2000/svg";
const xy = { svg: null, ink: null, tip: null };

function svgEl(name, attrs, parent) {
  const e = document.createElementNS(SVG, name);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, v);
  parent.appendChild(e);
  return e;
}

function buildXY(scene) {
  if (xy.svg || !scene) return;
  const [bx0, bx1, by0, by1] = scene.board;
  const m = 16;  // room for the axis labels, mm
  const fig = document.createElement("figure");
  fig.className = "graph xy";
  fig.dataset.graph = "xy";
  const cap = document.createElement("figcaption");
  const title = document.createElement("b");
  title.textContent = "What was drawn, X-Y, mm";
  const legend = document.createElement("span");
  legend.className = "legend";
  legend.textContent = "the ink on the whiteboard, seen from above; red: the pen tip (FK of the encoders)";
  cap.append(title, legend);
  fig.append(cap);
  // the board and beyond it the waiting pose (beside the board's near corner), where the tip idles
  const svg = svgEl("svg", { viewBox: `${bx0 - m} ${-by1 - 4} ${bx1 - bx0 + 2 * m} ${by1 - by0 + m + 12}`,
                             role: "img", "data-role": "xy-view", preserveAspectRatio: "xMidYMid meet",
                             "aria-label": "what was drawn: the whiteboard's ink from above, X right, Y up, mm" },
                     fig);
  svgEl("rect", { x: bx0, y: -by1, width: bx1 - bx0, height: by1 - by0, class: "board" }, svg);
  xy.ink = new InkPicture(svgEl("image", { x: bx0, y: -by1, width: bx1 - bx0, height: by1 - by0,
                                           preserveAspectRatio: "none", "data-role": "xy-ink" }, svg));
  const [fx0, fx1, fy0, fy1] = scene.field;
  const grid = svgEl("g", { class: "field" }, svg);
  for (let i = 0; i <= scene.cells; i++) {
    const x = fx0 + ((fx1 - fx0) * i) / scene.cells, y = fy0 + ((fy1 - fy0) * i) / scene.cells;
    svgEl("line", { x1: x, y1: -fy0, x2: x, y2: -fy1 }, grid);
    svgEl("line", { x1: fx0, y1: -y, x2: fx1, y2: -y }, grid);
  }
  const axis = svgEl("g", { class: "axis" }, svg);
  const step = 50;
  for (let x = Math.ceil(bx0 / step) * step; x <= bx1; x += step) {
    svgEl("line", { x1: x, y1: -by0, x2: x, y2: -by0 + 2 }, axis);
    svgEl("text", { x, y: -by0 + 9, "text-anchor": "middle" }, axis).textContent = String(x);
  }
  for (let y = Math.ceil(by0 / step) * step; y <= by1; y += step) {
    svgEl("line", { x1: bx0 - 2, y1: -y, x2: bx0, y2: -y }, axis);
    svgEl("text", { x: bx0 - 3, y: -y + 2.5, "text-anchor": "end" }, axis).textContent = String(y);
  }
  xy.tip = svgEl("circle", { r: 1.8, cx: 0, cy: 0, class: "tip", visibility: "hidden", "data-role": "xy-tip" }, svg);
  xy.svg = svg;
  role("graphs").prepend(fig);
}

function drawXY(arm) {
  if (!xy.svg || !arm) return;
  xy.ink.show(arm.ink);
}

function drawTip() {
  if (!xy.tip || !ring.n || ring.index.x_fk_mm === undefined) return;
  const x = ring.at(ring.index.x_fk_mm, ring.n - 1), y = ring.at(ring.index.y_fk_mm, ring.n - 1);
  if (!Number.isFinite(x) || !Number.isFinite(y)) return;
  xy.tip.setAttribute("cx", x);
  xy.tip.setAttribute("cy", -y);
  xy.tip.setAttribute("visibility", "visible");
}

// -- the controls ---------------------------------------------------------------------------

// A slider and its number box: the box takes a typed value only inside the slider's range;
// outside it the value is refused, said, and left in the box as typed (never clamped).
function pair(name, unit, sliderRole, boxRole, onChange) {
  const slider = role(sliderRole), box = role(boxRole);
  const lo = Number(slider.min), hi = Number(slider.max);
  slider.addEventListener("input", () => {
    box.value = slider.value;
    box.setAttribute("aria-invalid", "false");
    check();
    onChange();
  });
  box.addEventListener("input", () => {
    const v = box.valueAsNumber;
    const ok = box.value !== "" && Number.isFinite(v) && v >= lo && v <= hi;
    box.setAttribute("aria-invalid", ok ? "false" : "true");
    if (ok) slider.value = String(v);
    check();
    onChange();
  });
  return {
    name, unit, lo, hi, slider, box,
    valid: () => box.getAttribute("aria-invalid") !== "true",
    // What Trigger sends: the value as typed (the session checks it too).
    value: () => (box.value === "" || !Number.isFinite(box.valueAsNumber) ? box.value : box.valueAsNumber),
  };
}

let magnitude, speed;

function check() {
  const bad = [magnitude, speed].filter((p) => !p.valid());
  const box = role("check");
  box.textContent = bad.map((p) => `${p.name} ${p.box.value === "" ? "(empty)" : p.box.value} is refused: it must be a number`
    + ` from ${p.lo} to ${p.hi}${p.unit}; the slider stays at ${p.slider.value}${p.unit}`).join(" ");
  box.dataset.error = bad.length ? "true" : "false";
}

function describeSettings() {
  const staircase = role("symbol").value === "staircase";
  role("staircase-options").hidden = !staircase;
  role("magnitude-field").hidden = staircase;
  role("speed-field").hidden = staircase;
  role("magnitude-means").textContent = MEANS[role("symbol").value];
  const s = speed.valid() ? Number(speed.slider.value) : NaN;
  const [lo, hi] = state.speedRange;
  role("speed-mm-s").textContent = Number.isFinite(s) ? `${(lo + ((hi - lo) * s) / 5).toFixed(1)} mm/s` : "";
}

function drawOperate(op) {
  state.op = op;
  if (op.speed_mm_s_range) state.speedRange = op.speed_mm_s_range;
  role("status").textContent = op.status;
  const trigger = $('[data-cmd="trigger"]');
  trigger.disabled = !op.trigger;
  role("why").textContent = op.trigger ? "" : `Trigger is off: ${op.why}`;
  $('[data-cmd="stop"]').disabled = op.turning_off;
  const p = op.precision;
  const cell = (key) => role("precision").querySelector(`[data-key="${key}"]`);
  if (p && p.symbol === "staircase") {
    drawStaircase(p);
  } else if (p) {
    const what = { X: "an X", O: "an O", sine: "a sine wave" }[p.symbol];
    cell("what").textContent = `${what}, ${p.magnitude_cm} cm, speed ${p.speed} (${p.speed_mm_s} mm/s)`;
    const mm = (v) => (v === null || v === undefined ? "–" : `${v.toFixed(3)} mm`);
    cell("rms_error_mm").textContent = p.error ? p.error : mm(p.rms_error_mm);
    cell("max_error_mm").textContent = mm(p.max_error_mm);
    cell("closure_gap_mm").textContent = mm(p.closure_gap_mm);
    cell("fk_vs_true_max_mm").textContent = mm(p.fk_vs_true_max_mm);
    cell("duration_s").textContent = `${p.duration_s.toFixed(1)} s of simulated time`;
  }
  describeSettings();
}

// The last staircase's three comparisons (the largest static and dynamic error over its stairs, mm).
function drawStaircase(p) {
  const table = role("staircase");
  const fig = p.thesis_figure ? `, as fig. ${p.thesis_figure}` : "";
  table.querySelector('[data-key="staircase-what"]').textContent =
    `along ${p.axis.toUpperCase()}, ${p.stairs} ${p.steps} stairs of ${p.step_mm} mm${fig}`;
  const mm = (v) => (v === null || v === undefined ? "–" : `${v.toFixed(3)} mm`);
  for (const row of table.querySelectorAll("[data-comparison]")) {
    const s = p.summary ? p.summary[row.dataset.comparison] : null;
    row.querySelector('[data-key="static"]').textContent = p.error ? p.error : mm(s && s.max_static_mm);
    row.querySelector('[data-key="dynamic"]').textContent = mm(s && s.max_dynamic_mm);
  }
  table.title = (p.reading || []).join("\n");
}

function drawFrame(f) {
  drawCommon(f);
  if (f.speed !== undefined) drawSpeed(role("sim-speed"), f.speed);
  if (f.operate) drawOperate(f.operate);
  if (f.plot) takePlot(f.plot);
  if (f.full && xy.ink) xy.ink.resync();  // a page that joins, a replay: the ink is fetched again whatever its key
  if ("arm" in f) drawXY(f.arm);
  if (f.error) say(f.error, true);
}

function onMessage(m) {
  if (m.type === "session") {
    buildXY(m.info.arm);
  } else if (m.type === "frame") {
    drawFrame(m);
    state.toAck.push(m.seq);
  } else if (m.type === "reply") {
    say(m.text || "", false);
  } else if (m.type === "error") {
    say(m.error, true);
  }
}

const link = new SessionLink(onMessage, (status) => {
  if (status !== "connected") role("mode").textContent = status;
});

pageHeader(link);
addDrive1Stop($('[data-cmd="stop"]'), link);
buildGraphs();
magnitude = pair("Magnitude", " cm", "magnitude", "magnitude-box", describeSettings);
speed = pair("Speed", "", "speed", "speed-box", describeSettings);
role("symbol").addEventListener("change", describeSettings);
describeSettings();
$('[data-cmd="run"]').addEventListener("click", () => link.send({ type: "run" }));
addSpeed(role("sim-speed"), link);
$('[data-cmd="stop"]').addEventListener("click", () => link.send({ type: "operate_stop" }));
$('[data-cmd="trigger"]').addEventListener("click", () => {
  const symbol = role("symbol").value;
  if (symbol === "staircase") {  // the staircase has no magnitude or speed of its own
    link.send({ type: "operate_trigger", symbol, magnitude_cm: 0, speed: 0, axis: role("axis").value, steps: role("steps").value });
  } else {
    link.send({ type: "operate_trigger", symbol, magnitude_cm: magnitude.value(), speed: speed.value() });
  }
});
link.connect();
requestAnimationFrame(redraw);
