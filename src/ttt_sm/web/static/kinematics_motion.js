// The trajectories and forces page (/kinematics/motion): one line drawn on the twin four ways, and the
// Jacobian, the velocity ellipses and the pen's contact force.  Everything is computed in Python
// (/api/kinematics/motion/<view>, web/kinematics_motion.py, the same documents as
// `ttt-sm kinematics trajectory|forces --json`); this file only draws.

import { role } from "./dom.js";
import { frame, legend, rect } from "./plot.js";

const COLOURS = { increment: "#1f77b4", step_fr_sw: "#d62728", cubic: "#2ca02c", quintic: "#9467bd" };
const NAMES = { increment: "increments (eq. 3.36)", step_fr_sw: "step, slow filter (fr_sw)",
  cubic: "cubic (WPI)", quintic: "quintic" };
const stats = { trajectory: null, forces: null, errors: 0, busy: 0 };
window.kinematicsMotion = stats;   // the tests read it
stats.idle = () => stats.busy === 0;

function status(text, isError) {
  const el = role("status");
  el.textContent = text;
  el.dataset.error = isError ? "true" : "false";
}

async function getJSON(view, params) {
  const r = await fetch(`/api/kinematics/motion/${view}?` + new URLSearchParams(params), { cache: "no-store" });
  const data = await r.json();
  if (!r.ok) throw new Error(data.error || `${view}: HTTP ${r.status}`);
  return data;
}

async function busy(fn) {
  stats.busy++;
  try { await fn(); status(""); } catch (e) { stats.errors++; status(String(e.message || e), true); }
  stats.busy--;
}

function polyline(ctx, f, xs, ys) {
  ctx.beginPath();
  let on = false;
  xs.forEach((x, i) => {
    const y = ys[i];
    if (y === null || Number.isNaN(y)) { on = false; return; }
    if (on) ctx.lineTo(f.X(x), f.Y(y)); else { ctx.moveTo(f.X(x), f.Y(y)); on = true; }
  });
  ctx.stroke();
}

const clear = (c) => { const ctx = c.getContext("2d"); ctx.clearRect(0, 0, c.width, c.height); return ctx; };
const fix = (v, k) => (v === null || v === undefined ? "–" : v.toFixed(k));

// ---- trajectories
function lineParams() {
  return { x0: role("x0").value, y0: role("y0").value, x1: role("x1").value, y1: role("y1").value,
    speed: role("speed").value };
}

async function runTrajectory() {
  await busy(async () => {
    const d = await getJSON("trajectory", lineParams());
    stats.trajectory = d;
    drawTrajectory(d);
  });
}

function drawTrajectory(d) {
  role("traj-table").tBodies[0].replaceChildren(...d.methods.map((m) => {
    const tr = document.createElement("tr");
    tr.dataset.method = m.method;
    tr.innerHTML = `<td><span style="color:${COLOURS[m.method]}">■</span> ${NAMES[m.method]}</td>`
      + `<td>${fix(m.move_s, 2)}</td><td>${m.arrive_s === null ? "never" : m.arrive_s.toFixed(2)}</td>`
      + `<td>${fix(m.max_following_rad * 1e3, 3)}</td><td>${fix(m.max_tip_lag_m * 1e3, 2)}</td>`
      + `<td>${fix(m.max_current_a, 3)}</td>`
      + `<td>${m.ink_max_off_line_m === null ? "–" : (m.ink_max_off_line_m * 1e3).toFixed(2)}</td>`;
    return tr;
  }));
  const items = d.methods.map((m) => [COLOURS[m.method], NAMES[m.method], "line"]);
  // ink on the board, mm
  let c = role("traj-ink"), ctx = clear(c);
  const pts = [d.a_m, d.b_m].concat(...d.methods.flatMap((m) => m.ink_m));
  const xs = pts.map((p) => p[0] * 1e3), ys = pts.map((p) => p[1] * 1e3);
  const pad = 4;
  let f = frame(ctx, [60, 24, c.width - 75, c.height - 70], [Math.min(...xs) - pad, Math.max(...xs) + pad],
    [Math.min(...ys) - pad, Math.max(...ys) + pad], { equal: true, xlabel: "x (mm)", ylabel: "y (mm)",
      title: "ink on the board" });
  f.clip();
  ctx.setLineDash([5, 4]); ctx.strokeStyle = "#000"; ctx.lineWidth = 1;
  polyline(ctx, f, [d.a_m[0] * 1e3, d.b_m[0] * 1e3], [d.a_m[1] * 1e3, d.b_m[1] * 1e3]);
  ctx.setLineDash([]);
  for (const m of d.methods) {
    ctx.strokeStyle = COLOURS[m.method]; ctx.lineWidth = 2;
    for (const s of m.ink_m) polyline(ctx, f, s.map((p) => p[0] * 1e3), s.map((p) => p[1] * 1e3));
  }
  ctx.restore();
  legend(ctx, 64, 30, [["#000", "the line asked for", "line"]].concat(items));
  // distance of the pen from its target, mm
  c = role("traj-lag"); ctx = clear(c);
  const tMax = Math.max(...d.methods.map((m) => m.t_s.at(-1)));
  const lags = d.methods.map((m) => m.tip_m.map((p, i) => Math.hypot(p[0] - m.target_m[i][0], p[1] - m.target_m[i][1],
    p[2] - m.target_m[i][2]) * 1e3));
  const lagMax = Math.max(2, ...d.methods.flatMap((m, i) => (m.method === "step_fr_sw" ? [] : lags[i])));
  f = frame(ctx, [60, 24, c.width - 75, c.height - 70], [0, tMax], [0, lagMax * 1.2],
    { xlabel: "time (s)", ylabel: "|pen tip − target| (mm)", title: "how far the pen is from its target" });
  f.clip();
  d.methods.forEach((m, i) => { ctx.strokeStyle = COLOURS[m.method]; ctx.lineWidth = 1.5; polyline(ctx, f, m.t_s, lags[i]); });
  ctx.restore();
  legend(ctx, c.width - 200, 30, items.concat([["#999", "(the step leaves the scale)", "box"]]));
  // currents of drives 2 and 3, A
  c = role("traj-current"); ctx = clear(c);
  const cur = d.methods.flatMap((m) => m.current_a.flatMap((r) => [r[1], r[2]]));
  f = frame(ctx, [60, 24, c.width - 75, c.height - 70], [0, tMax], [Math.min(0, ...cur), Math.max(...cur) * 1.15],
    { xlabel: "time (s)", ylabel: "motor current (A)", title: "motor currents: drive 2 solid, drive 3 dashed" });
  f.clip();
  for (const m of d.methods) {
    ctx.strokeStyle = COLOURS[m.method]; ctx.lineWidth = 1;
    polyline(ctx, f, m.t_s, m.current_a.map((r) => r[1]));
    ctx.setLineDash([4, 3]); polyline(ctx, f, m.t_s, m.current_a.map((r) => r[2])); ctx.setLineDash([]);
  }
  ctx.restore();
  legend(ctx, c.width - 200, 30, items);
}

// ---- forces and velocities
let boardMap = null, lastForces = null;

async function runForces(at) {
  await busy(async () => {
    const d = await getJSON("forces", Object.assign(lineParams(), at || {}));
    stats.forces = d;
    lastForces = d;
    drawForces(d);
  });
}

function drawForces(d) {
  const p = d.pose;
  role("pose").textContent = `x ${p.x_m.toFixed(3)} m, y ${p.y_m.toFixed(3)} m`;
  role("manip").textContent = p.manipulability.toExponential(3);
  const e = d.line.errors;
  role("force-error").textContent = e.mean_rel === null ? "not observable on this line"
    : `mean ${(e.mean_rel * 100).toFixed(1)} %, 95th percentile ${(e.p95_rel * 100).toFixed(1)} %`
      + ` (where both pitch drives turn: ${(e.observable_share * 100).toFixed(0)} % of the line)`;
  role("force-error").dataset.mean = String(e.mean_rel);
  role("jacobian").tBodies[0].replaceChildren(...p.jacobian.map((row, i) => {
    const tr = document.createElement("tr");
    tr.innerHTML = `<th>${["x", "y", "z", "phi"][i]}</th>` + row.map((v) => `<td>${(Math.abs(v) < 5e-5 ? 0 : v).toFixed(4)}</td>`).join("");
    return tr;
  }));
  // ellipses over the board, m
  let c = role("ellipses"), ctx = clear(c);
  const b = d.board_m;
  const f = frame(ctx, [60, 24, c.width - 75, c.height - 70], [b[0] - 0.01, b[1] + 0.01], [b[2] - 0.01, b[3] + 0.07],
    { equal: true, xlabel: "x (m)", ylabel: "y (m)", title: "tip velocity ellipses, pen vertical on the board" });
  boardMap = f;
  f.clip();
  rect(ctx, f, d.board_m, "#000", 1.5); rect(ctx, f, d.field_m, "#d62728", 1.5);
  const big = Math.max(...d.ellipses.map((q) => q.axes_m_per_rad[0]));
  const scale = 0.02 / big;   // the largest semi-axis drawn 2 cm long
  const px = f.X(1) - f.X(0);
  const ellipse = (q, fill) => {
    ctx.beginPath();
    ctx.ellipse(f.X(q.x_m), f.Y(q.y_m), q.axes_m_per_rad[0] * scale * px, q.axes_m_per_rad[1] * scale * px,
      -q.angle_rad, 0, 2 * Math.PI);
    ctx.fillStyle = fill; ctx.fill(); ctx.strokeStyle = "#1f77b4"; ctx.lineWidth = 1; ctx.stroke();
  };
  for (const q of d.ellipses) ellipse(q, "rgba(158,202,225,0.7)");
  ellipse(p, "rgba(255,127,14,0.6)");
  ctx.strokeStyle = "#ff7f0e"; ctx.lineWidth = 3;
  polyline(ctx, f, [d.line.a_m[0], d.line.b_m[0]], [d.line.a_m[1], d.line.b_m[1]]);
  ctx.restore();
  legend(ctx, 64, 30, [["#9ecae1", `tip velocity, unit joint speeds (1 m/s = ${(scale * 100).toFixed(1)} cm)`, "box"],
    ["#ff7f0e", "at the pen (click to move)", "box"], ["#ff7f0e", "line drawn for the force (right)", "line"],
    ["#000", "whiteboard", "line"], ["#d62728", "playing field", "line"]]);
  // the contact force, N
  c = role("force"); ctx = clear(c);
  const l = d.line;
  const g = frame(ctx, [60, 24, c.width - 75, c.height - 70], [0, l.t_s.at(-1)], [-1, 3.5],
    { xlabel: "time (s)", ylabel: "normal force on the pen (N)", title: "contact force: the twin's and the currents'" });
  g.clip();
  ctx.fillStyle = "#ddd"; ctx.beginPath();
  l.t_s.forEach((t, i) => (i ? ctx.lineTo(g.X(t), g.Y(1.1 * l.true_n[i])) : ctx.moveTo(g.X(t), g.Y(1.1 * l.true_n[i]))));
  for (let i = l.t_s.length - 1; i >= 0; i--) ctx.lineTo(g.X(l.t_s[i]), g.Y(0.9 * l.true_n[i]));
  ctx.fill();
  ctx.strokeStyle = "#000"; ctx.lineWidth = 2; polyline(ctx, g, l.t_s, l.true_n);
  ctx.strokeStyle = "rgba(31,119,180,0.45)"; ctx.lineWidth = 1; polyline(ctx, g, l.t_s, l.estimate_n);
  ctx.strokeStyle = "#1f77b4"; ctx.lineWidth = 2.5;
  polyline(ctx, g, l.t_s, l.estimate_n.map((v, i) => (l.observable[i] ? v : null)));
  ctx.restore();
  legend(ctx, 64, c.height - 46 - 4 * 15, [["#000", "true: the pen's spring on the twin", "line"],
    ["rgba(31,119,180,0.45)", "estimate J⁻ᵀ·τ from the motor currents", "line"],
    ["#1f77b4", "… where both pitch drives turn", "line"], ["#ddd", "±10 % of the true force", "box"]]);
}

// ---- wiring
async function start() {
  role("traj-go").addEventListener("click", async () => { await runTrajectory(); await runForces(at()); });
  role("ellipses").addEventListener("click", (ev) => {
    if (!boardMap) return;
    const c = role("ellipses"), r = c.getBoundingClientRect();
    const px = (ev.clientX - r.left) * (c.width / r.width), py = (ev.clientY - r.top) * (c.height / r.height);
    const x = (px - boardMap.X(0)) / (boardMap.X(1) - boardMap.X(0));
    const y = (py - boardMap.Y(0)) / (boardMap.Y(1) - boardMap.Y(0));
    runForces({ x: x.toFixed(3), y: y.toFixed(3) });
  });
  await runTrajectory();   // the empty inputs ask for the default line: show it in them
  const [x0, y0] = stats.trajectory.a_m, [x1, y1] = stats.trajectory.b_m;
  role("x0").value = x0.toFixed(3); role("y0").value = y0.toFixed(3);
  role("x1").value = x1.toFixed(3); role("y1").value = y1.toFixed(3);
  await runForces();
  document.body.dataset.ready = "true";
}

const at = () => (lastForces ? { x: String(lastForces.pose.x_m), y: String(lastForces.pose.y_m) } : {});

start().catch((e) => { stats.errors++; status(String(e.message || e), true); });
