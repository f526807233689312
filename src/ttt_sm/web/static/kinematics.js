// The kinematics page (/kinematics): the pen tip's reachable workspace, the DH table with its frames,
// and five IK methods raced on one target.  Everything is computed in Python (/api/kinematics/<view>,
// web/kinematics.py, the same documents as `ttt-sm kinematics ... --json`); this file only draws.

import { $$, role } from "./dom.js";
import { frame, legend, rect } from "./plot.js";

const CODE_COLOURS = ["#ffffff", "#9ecae1", "#fdae6b", "#a1d99b"];
const METHOD_COLOURS = { lm_fixed: "#1f77b4", dls_adaptive: "#ff7f0e", analytic_up: "#2ca02c",
  analytic_down: "#d62728", twist: "#9467bd" };
const AXIS_COLOURS = ["#d62728", "#2ca02c", "#1f77b4"];
const stats = { redraws: [], workspace: null, race: null, dh: null, errors: 0 };
window.kinematics = stats;   // the tests and the benchmark read it

function status(text, isError) {
  const el = role("status");
  el.textContent = text;
  el.dataset.error = isError ? "true" : "false";
}

async function getJSON(view, params) {
  const r = await fetch(`/api/kinematics/${view}?` + new URLSearchParams(params), { cache: "no-store" });
  const data = await r.json();
  if (!r.ok) throw new Error(data.error || `${view}: HTTP ${r.status}`);
  return data;
}

function grid(ctx, f, xs, ys, codes) {
  f.clip();
  const dx = (xs[1] - xs[0]) / 2, dy = (ys[1] - ys[0]) / 2;
  for (let i = 0; i < ys.length; i++) {
    for (let j = 0; j < xs.length; j++) {
      const c = codes[i][j];
      if (!c) continue;
      ctx.fillStyle = CODE_COLOURS[c];
      const x0 = f.X(xs[j] - dx), y0 = f.Y(ys[i] + dy);
      ctx.fillRect(x0, y0, f.X(xs[j] + dx) - x0 + 0.5, f.Y(ys[i] - dy) - y0 + 0.5);
    }
  }
  ctx.restore();
}

// ---- workspace
let wsPending = null, wsBusy = false, topMap = null, lastWs = null;
const packaged = {};
stats.idle = () => !wsBusy && wsPending === null;

function wsParams() {
  return { tool: role("tool").value, L2: role("L2").value, q2_max_deg: role("q2max").value,
    q3_max_deg: role("q3max").value, cells: role("cells").value, cell_m: "0.03" };
}

async function redrawWorkspace(t0) {
  if (wsBusy) { wsPending = t0; return; }
  wsBusy = true;
  try {
    const data = await getJSON("workspace", wsParams());
    drawWorkspace(data);
    stats.workspace = data;
    stats.redraws.push(performance.now() - t0);
    status("");
  } catch (e) { stats.errors++; status(String(e.message || e), true); }
  wsBusy = false;
  if (wsPending !== null) { const t = wsPending; wsPending = null; redrawWorkspace(t); }
}

function drawWorkspace(d) {
  lastWs = d;
  for (const k of ["L2", "q2max", "q3max"]) role(`${k}-value`).textContent = role(k).value;
  const top = role("ws-top"), ctx = top.getContext("2d");
  ctx.clearRect(0, 0, top.width, top.height);
  const t = d.top;
  const f = frame(ctx, [60, 24, top.width - 75, top.height - 70], [t.x_m[0], t.x_m.at(-1)], [t.y_m[0], t.y_m.at(-1)],
    { equal: true, xlabel: "x (m)", ylabel: "y (m)", title: `top view, board plane (${d.tool.replace("_", " ")})` });
  topMap = f;
  grid(ctx, f, t.x_m, t.y_m, t.code);
  rect(ctx, f, d.board_m, "#000", 1.5);
  rect(ctx, f, d.field_m, "#d62728", 1.5);
  if (d.camera_field_m) {  // what the game's camera sees of the board (a trapezoid: it looks at a slant)
    ctx.save(); ctx.strokeStyle = "#1f77b4"; ctx.lineWidth = 1.5; ctx.setLineDash([6, 4]); ctx.beginPath();
    d.camera_field_m.forEach(([x, y], i) => (i ? ctx.lineTo(f.X(x), f.Y(y)) : ctx.moveTo(f.X(x), f.Y(y))));
    ctx.closePath(); ctx.stroke(); ctx.restore();
  }
  const [fx0, fx1, fy0] = d.field_m, n = d.cells.length, cs = (fx1 - fx0) / n;
  ctx.font = "10px sans-serif"; ctx.textAlign = "center"; ctx.fillStyle = "#111";
  d.cells.forEach((row, i) => row.forEach((c, j) => {
    ctx.fillText(c === "elbow up" ? "U" : c === "elbow down" ? "D" : "×", f.X(fx0 + (j + 0.5) * cs), f.Y(fy0 + (i + 0.5) * cs) + 4);
  }));
  ctx.fillStyle = "#000"; ctx.beginPath(); ctx.arc(f.X(-d.geometry.l_f), f.Y(0), 4, 0, 7); ctx.fill();
  legend(ctx, 64, top.height - 46 - 9 * 15, [[CODE_COLOURS[0], "unreachable"], [CODE_COLOURS[1], "elbow up only"],
    [CODE_COLOURS[2], "elbow down only"], [CODE_COLOURS[3], "both configurations"],
    ["#000", "whiteboard", "line"], ["#d62728", "playing field (U/D: needs)", "line"],
    ["#1f77b4", "the camera's field (dashed)", "line"], ["#000", "base axis", "mark"]]);
  const side = role("ws-side"), sc = side.getContext("2d");
  sc.clearRect(0, 0, side.width, side.height);
  const s = d.side;
  const g = frame(sc, [60, 24, side.width - 75, side.height - 70], [s.r_m[0], s.r_m.at(-1)], [s.z_m[0], s.z_m.at(-1)],
    { equal: true, xlabel: "reach r in the arm's plane (m)", ylabel: "z (m)", title: "side view, arm's plane" });
  grid(sc, g, s.r_m, s.z_m, s.code);
  sc.strokeStyle = "#000"; sc.lineWidth = 2; sc.beginPath(); sc.moveTo(g.X(0), g.Y(0)); sc.lineTo(g.X(s.r_m.at(-1)), g.Y(0)); sc.stroke();
  sc.fillStyle = "#000"; sc.beginPath(); sc.arc(g.X(0), g.Y(d.geometry.L1), 4, 0, 7); sc.fill();
  legend(sc, side.width - 190, side.height - 80, [["#000", "board surface z = 0", "line"], ["#000", "shoulder axis", "mark"]]);
  const down = [], none = [];
  d.cells.forEach((row, i) => row.forEach((c, j) => {
    if (c === "elbow down") down.push(`(${i},${j})`);
    if (c === "unreachable") none.push(`(${i},${j})`);
  }));
  role("fits").textContent = `${n} x ${n} ${d.fits ? "fits" : "does not fit"}`;
  role("fits").dataset.fits = String(d.fits);
  role("elbow-down").textContent = down.length ? down.join(" ") : "none";
  role("unreachable").textContent = none.length ? none.join(" ") : "none";
}

// ---- DH table and frames
async function redrawDH() {
  const q = ["q1", "q2", "q3", "q4"].map((k) => role(k).value).join(",");
  try {
    const d = await getJSON("dh", { q_deg: q });
    stats.dh = d;
    const body = role("dh-table").tBodies[0];
    body.replaceChildren(...d.rows.map((r, i) => {
      const tr = document.createElement("tr");
      tr.innerHTML = `<td>${i + 1}</td>` + r.map((v) => `<td>${v.toFixed(4)}</td>`).join("");
      return tr;
    }));
    role("dh-fk").textContent = d.fk.slice(0, 3).map((v) => v.toFixed(4)).join(", ");
    const c = role("dh-arm"), ctx = c.getContext("2d");
    ctx.clearRect(0, 0, c.width, c.height);
    const views = [["top view", 0, 1, "x (m)", "y (m)"], ["side view", 1, 2, "y (m)", "z (m)"]];
    views.forEach(([title, a, b, xl, yl], k) => {
      const pts = d.arm_m.concat(d.frames.map((fr) => fr.origin_m));
      const xs = pts.map((p) => p[a]), ys = pts.map((p) => p[b]);
      const pad = 0.08;
      const f = frame(ctx, [60 + k * (c.width / 2), 24, c.width / 2 - 80, c.height - 70],
        [Math.min(...xs) - pad, Math.max(...xs) + pad], [Math.min(...ys) - pad, Math.max(...ys) + pad],
        { equal: true, xlabel: xl, ylabel: yl, title: `DH frames on the arm, ${title}` });
      f.clip();
      ctx.strokeStyle = "#888"; ctx.lineWidth = 5; ctx.lineCap = "round"; ctx.beginPath();
      d.arm_m.forEach((p, i) => (i ? ctx.lineTo(f.X(p[a]), f.Y(p[b])) : ctx.moveTo(f.X(p[a]), f.Y(p[b]))));
      ctx.stroke();
      d.frames.forEach((fr, i) => {
        const o = fr.origin_m;
        fr.axes.forEach((ax, m) => {
          ctx.strokeStyle = AXIS_COLOURS[m]; ctx.lineWidth = 2; ctx.beginPath();
          ctx.moveTo(f.X(o[a]), f.Y(o[b])); ctx.lineTo(f.X(o[a] + 0.04 * ax[a]), f.Y(o[b] + 0.04 * ax[b])); ctx.stroke();
        });
        ctx.fillStyle = "#111"; ctx.font = "11px sans-serif"; ctx.fillText(String(i), f.X(o[a]) + 4, f.Y(o[b]) - 4);
      });
      ctx.restore();
      if (k === 0) legend(ctx, 64, c.height - 46 - 4 * 15, [["#888", "arm (links)", "line"], [AXIS_COLOURS[0], "x_i (4 cm)", "line"],
        [AXIS_COLOURS[1], "y_i", "line"], [AXIS_COLOURS[2], "z_i (joint axis i+1)", "line"]]);
    });
  } catch (e) { stats.errors++; status(String(e.message || e), true); }
}

// ---- IK race
async function runRace() {
  try {
    const d = await getJSON("race", { x: role("tx").value, y: role("ty").value });
    stats.race = d;
    drawRace(d);
    status("");
  } catch (e) { stats.errors++; status(String(e.message || e), true); }
}

function drawRace(d) {
  const body = role("race-table").tBodies[0];
  body.replaceChildren(...d.methods.map((m) => {
    const tr = document.createElement("tr");
    tr.dataset.method = m.method; tr.dataset.converged = String(m.converged);
    const e = m.errors_m.at(-1);
    tr.innerHTML = `<td><span style="color:${METHOD_COLOURS[m.method]}">■</span> ${m.method}</td><td>${m.reason}</td>`
      + `<td>${m.iterations}</td><td>${e === null ? "–" : e.toExponential(1)}</td>`
      + `<td>${m.min_abs_det === null ? "–" : m.min_abs_det.toExponential(1)}</td><td>${(m.seconds * 1e6).toFixed(1)}</td>`;
    return tr;
  }));
  const c = role("race-error"), ctx = c.getContext("2d");
  ctx.clearRect(0, 0, c.width, c.height);
  const n = Math.max(...d.methods.map((m) => m.errors_m.length));
  const f = frame(ctx, [66, 24, c.width - 80, c.height - 70], [0, Math.max(1, n - 1)], [1e-17, 10],
    { logy: true, xlabel: "iteration", ylabel: "tip position error (m)", title: "error vs iteration" });
  f.clip();
  ctx.setLineDash([4, 4]); ctx.strokeStyle = "#888"; ctx.beginPath(); ctx.moveTo(f.X(0), f.Y(1e-5)); ctx.lineTo(f.X(n), f.Y(1e-5)); ctx.stroke();
  ctx.setLineDash([]);
  for (const m of d.methods) {
    ctx.strokeStyle = METHOD_COLOURS[m.method]; ctx.lineWidth = 1.5; ctx.beginPath();
    let started = false;
    m.errors_m.forEach((e, i) => {
      if (e === null) return;
      const y = f.Y(Math.max(e, 1e-17));
      if (started) ctx.lineTo(f.X(i), y); else { ctx.moveTo(f.X(i), y); started = true; }
    });
    ctx.stroke();
  }
  ctx.restore();
  legend(ctx, c.width - 200, 30, d.methods.map((m) => [METHOD_COLOURS[m.method], `${m.method}: ${m.reason}`, "line"])
    .concat([["#888", "tolerance 1e-5 m", "line"]]));
  const a = role("race-arm"), ax = a.getContext("2d");
  ax.clearRect(0, 0, a.width, a.height);
  const ws = lastWs;
  const b = ws ? ws.board_m : [-0.15, 0.15, 0.13, 0.37];
  const g = frame(ax, [60, 24, a.width - 75, a.height - 70], [b[0] - 0.25, b[1] + 0.05], [-0.06, b[3] + 0.04],
    { equal: true, xlabel: "x (m)", ylabel: "y (m)", title: "iterations drawn on the arm, top view" });
  g.clip();
  if (ws) { rect(ax, g, ws.board_m, "#000", 1); rect(ax, g, ws.field_m, "#d62728", 1); }
  for (const m of d.methods) {
    const col = METHOD_COLOURS[m.method];
    if (m.arm_m) {
      ax.globalAlpha = 0.5; ax.strokeStyle = col; ax.lineWidth = 4; ax.beginPath();
      m.arm_m.forEach((p, i) => (i ? ax.lineTo(g.X(p[0]), g.Y(p[1])) : ax.moveTo(g.X(p[0]), g.Y(p[1])))); ax.stroke();
      ax.globalAlpha = 1;
    }
    ax.strokeStyle = col; ax.fillStyle = col; ax.lineWidth = 1;
    ax.beginPath();
    m.tips_m.forEach((p, i) => (i ? ax.lineTo(g.X(p[0]), g.Y(p[1])) : ax.moveTo(g.X(p[0]), g.Y(p[1])))); ax.stroke();
    for (const p of m.tips_m) { ax.beginPath(); ax.arc(g.X(p[0]), g.Y(p[1]), 2, 0, 7); ax.fill(); }
  }
  ax.fillStyle = "#000"; ax.font = "16px sans-serif"; ax.textAlign = "center";
  ax.fillText("✚", g.X(d.target[0]), g.Y(d.target[1]) + 6);
  ax.restore();
  legend(ax, 64, a.height - 46 - 7 * 15, d.methods.map((m) => [METHOD_COLOURS[m.method], `${m.method} (tip per iteration, m)`, "line"])
    .concat([["#000", "target ✚", "mark"], ["#000", "whiteboard", "line"]]));
}

// ---- wiring
function reset() {
  for (const [k, v] of Object.entries(packaged)) role(k).value = v;
}

async function start() {
  const d = await getJSON("workspace", { resolution: "8" });
  Object.assign(packaged, { L2: String(d.geometry.L2), q2max: String(Math.round(d.q_max_deg[1])),
    q3max: String(Math.round(d.q_max_deg[2])), cells: "5", tool: "pen_vertical" });
  reset();
  for (const el of $$("[data-role=L2], [data-role=q2max], [data-role=q3max]")) {
    el.addEventListener("input", () => redrawWorkspace(performance.now()));
  }
  for (const k of ["tool", "cells"]) role(k).addEventListener("change", () => redrawWorkspace(performance.now()));
  role("ws-reset").addEventListener("click", () => { reset(); redrawWorkspace(performance.now()); });
  for (const k of ["q1", "q2", "q3", "q4"]) role(k).addEventListener("change", redrawDH);
  role("race-go").addEventListener("click", runRace);
  role("race-corner").addEventListener("click", () => {
    const b = lastWs.board_m;
    role("tx").value = b[1].toFixed(3); role("ty").value = b[3].toFixed(3); runRace();
  });
  role("ws-top").addEventListener("click", (ev) => {
    if (!topMap) return;
    const c = role("ws-top"), r = c.getBoundingClientRect();
    const px = (ev.clientX - r.left) * (c.width / r.width), py = (ev.clientY - r.top) * (c.height / r.height);
    const t = lastWs.top, xs = t.x_m, ys = t.y_m;
    // invert the frame's linear maps from two points
    const x = xs[0] + (px - topMap.X(xs[0])) * (xs.at(-1) - xs[0]) / (topMap.X(xs.at(-1)) - topMap.X(xs[0]));
    const y = ys[0] + (py - topMap.Y(ys[0])) * (ys.at(-1) - ys[0]) / (topMap.Y(ys.at(-1)) - topMap.Y(ys[0]));
    role("tx").value = x.toFixed(3); role("ty").value = y.toFixed(3);
    runRace();
    document.getElementById("race").scrollIntoView();
  });
  await redrawWorkspace(performance.now());
  await Promise.all([redrawDH(), runRace()]);
  document.body.dataset.ready = "true";
}

start().catch((e) => status(String(e.message || e), true));
