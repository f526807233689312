// The chart cockpit: draws the session's frames on the charts' diagrams and sends commands.
//
// A view only: every decision (pacing, breakpoints, replay, coverage, the text of
// every value) is the session's (ttt_sm.web.session); this page keeps what it was
// last told and draws it.  The diagrams are the server's Graphviz SVG, loaded once
// per picture; a frame only toggles attributes on them (data-active,
// data-taken-count, a "flash" class on each transition taken, removed when its
// animation ends), it never redraws a diagram.

import { addSafety, drawSafety, SessionLink } from "./session.js";

const $ = (sel, root = document) => root.querySelector(sel);
const $$ = (sel, root = document) => Array.from(root.querySelectorAll(sel));
const role = (name) => $(`[data-role="${name}"]`);

const TRACE_ROWS = 300;

const S = {
  info: null,
  charts: {},          // name -> chart description (states, transitions, data, events, views)
  chart: null,         // the chart shown
  view: "overview",
  opened: [],          // sub-charts open in place in the overview
  active: {},          // chart -> Set of active state ids
  data: {},            // chart -> {datum: text}
  changed: {},         // chart -> Set of data changed in the last frame that changed any
  signals: {},
  changedSignals: new Set(),
  taken: {},           // chart -> {index: count}
  breakpoints: [],
  actions: [],
  forced: [],
  stop: null,
  trace: [],
  coverage: null,
  seq: -1,
  joined: false,
  tick: 0,
  furthest: 0,
  mode: "",
  svgSeq: 0,
};

const link = new SessionLink(onMessage, (text) => say(text, text.startsWith("disconnected")));

// -- messages -------------------------------------------------------------------------

function onMessage(m) {
  switch (m.type) {
    case "session": return onSession(m.info);
    case "frame": return onFrame(m);
    case "reply": return say(m.text || "ok");
    case "error": return say(m.error, true);
    case "coverage": return onCoverage(m);
    case "timeline": return onTimeline(m);
    default: return undefined;
  }
}

function onSession(info) {
  S.info = info;
  S.charts = {};
  for (const c of info.charts) {
    c.byIndex = new Map(c.transitions.map((t) => [t.index, t]));
    c.byId = new Map(c.states.map((s) => [s.id, s]));
    S.charts[c.name] = c;
  }
  const tabs = role("chart-tabs");
  tabs.replaceChildren();
  for (const c of info.charts) {
    const b = button(c.name, () => showChart(c.name));
    b.title = `${c.name}: ${c.doc}`;
    b.dataset.chart = c.name;
    tabs.append(b);
  }
  fillEventSelects();
  const files = $('select[name="files"]', role("coverage-form"));
  files.replaceChildren(...info.scenarios.map((f) => new Option(f, f)));
  showChart(S.chart && S.charts[S.chart] ? S.chart : info.charts[info.charts.length - 1].name);
}

function onFrame(f) {
  if (f.full) {
    S.joined = true;
    S.trace = (f.trace || []).slice().reverse();
    S.taken = {};
    S.data = {};
  } else if (!S.joined || f.seq <= S.seq) {
    return;
  }
  S.seq = f.seq;
  S.tick = f.tick;
  S.furthest = f.furthest_tick;
  S.mode = f.mode;
  S.active = Object.fromEntries(Object.entries(f.active).map(([k, v]) => [k, new Set(v)]));
  if (f.data) {
    const any = Object.keys(f.data).length > 0;
    for (const [chart, values] of Object.entries(f.data)) {
      S.data[chart] = { ...(S.data[chart] || {}), ...values };
    }
    if (any && !f.full) S.changed = Object.fromEntries(Object.entries(f.data).map(([k, v]) => [k, new Set(Object.keys(v))]));
    if (f.full) S.changed = {};
  }
  if (f.signals) {
    if (Object.keys(f.signals).length && !f.full) S.changedSignals = new Set(Object.keys(f.signals));
    if (f.full) S.changedSignals = new Set();
    S.signals = { ...S.signals, ...f.signals };
  }
  if (f.taken) {
    for (const [chart, counts] of Object.entries(f.taken)) {
      S.taken[chart] = { ...(S.taken[chart] || {}), ...counts };
    }
  }
  for (const key of ["breakpoints", "actions", "forced"]) {
    if (f[key] !== undefined) S[key] = f[key];
  }
  if (f.stop !== undefined) S.stop = f.stop;
  for (const t of f.transitions || []) S.trace.unshift(t);
  if (S.trace.length > TRACE_ROWS) S.trace.length = TRACE_ROWS;

  drawHeader(f);
  drawDiagramState(f.transitions || [], f.full);
  drawWatch();
  drawSignals();
  drawBreakpoints();
  drawActions();
  drawTrace(f.transitions_total - (f.transitions || []).length);
  drawSlider();
  if ((f.transitions || []).length) {
    const seq = f.seq;
    requestAnimationFrame(() => link.ack(seq));
  }
}

function onCoverage(m) {
  S.coverage = m.cleared ? null : m;
  drawCoverage();
  say(m.cleared ? "coverage cleared" : `coverage shown: ${role("coverage-summary").textContent}`);
}

function onTimeline(m) {
  drawTimeline(m);
}

// -- the header --------------------------------------------------------------------------

function drawHeader(f) {
  role("sim-time").textContent = f.t.toFixed(4);
  role("tick").textContent = String(f.tick);
  const mode = role("mode");
  mode.textContent = f.mode;
  mode.dataset.mode = f.mode;
  const speed = role("speed");
  if (document.activeElement !== speed) speed.value = String(f.speed);
  const p = f.pace;
  const parts = [];
  if (f.mode === "running") parts.push(`x${p.realtime_factor.toFixed(1)} real time`);
  if (f.speed !== "max") parts.push(`behind by ${p.lag_ms.toFixed(1)} ms (max ${p.lag_max_ms.toFixed(1)} ms)`);
  parts.push(`${p.overruns} overrun${p.overruns === 1 ? "" : "s"}`);
  if (p.slips) parts.push(`${p.slips} slip${p.slips === 1 ? "" : "s"}, ${p.lost_s.toFixed(2)} s lost`);
  if (f.latency.p95_ms !== null) parts.push(`frame latency p95 ${f.latency.p95_ms.toFixed(0)} ms`);
  const pace = role("pace");
  pace.textContent = parts.join(" · ");
  pace.dataset.overruns = String(p.overruns);
  if ("safety" in f) drawSafety(f.safety);
  if (f.stop) say(f.stop.text, false, f.stop.kind);
  if (f.error) say(f.error, true);
}

function say(text, isError = false, kind = "") {
  const status = role("status");
  status.textContent = text;
  status.dataset.error = isError ? "true" : "";
  status.dataset.kind = kind;
}

// -- the diagram -------------------------------------------------------------------------

function showChart(name) {
  const chart = S.charts[name];
  if (!chart) return;
  if (S.chart !== name) {
    S.chart = name;
    S.view = chart.subcharts.length ? "overview" : "whole";
    S.opened = [];
    S.changed = {};
  }
  for (const b of $$("button", role("chart-tabs"))) b.setAttribute("aria-pressed", String(b.dataset.chart === name));
  role("data-chart").textContent = `of ${name}`;
  drawViewBar();
  loadDiagram();
  buildWatch();
  drawCoverageSummary();
  askTimeline();
}

function setView(view, opened = []) {
  S.view = view;
  S.opened = opened;
  drawViewBar();
  loadDiagram();
}

function drawViewBar() {
  const chart = S.charts[S.chart];
  const bar = role("view-bar");
  bar.replaceChildren();
  if (!chart.subcharts.length) { bar.append(fitButton()); return; }
  const overview = button("Overview", () => setView("overview", []));
  overview.title = "all sub-charts closed";
  overview.setAttribute("aria-pressed", String(S.view === "overview" && !S.opened.length));
  bar.append(overview);
  for (const sub of chart.subcharts) {
    const isOpen = S.view === "overview" && S.opened.includes(sub);
    const inPlace = button(`${isOpen ? "▾" : "▸"} ${sub}`, () => {
      const opened = isOpen ? S.opened.filter((x) => x !== sub) : [...S.opened, sub];
      setView("overview", opened);
    }, `${isOpen ? "close" : "open"} sub-chart ${sub} in place`);
    inPlace.setAttribute("aria-pressed", String(isOpen));
    const alone = button("⤢", () => setView(sub, []), `open sub-chart ${sub} on its own`);
    alone.setAttribute("aria-pressed", String(S.view === sub));
    alone.classList.add("alone");
    const group = document.createElement("span");
    group.className = "sub";
    group.append(inPlace, alone);
    bar.append(group);
  }
  const whole = button("Whole chart", () => setView("whole", []));
  whole.title = "every sub-chart open, nested";
  whole.setAttribute("aria-pressed", String(S.view === "whole"));
  bar.append(whole);
  bar.append(fitButton());
}

function fitButton() {
  const box = role("diagram");
  const fit = button(box.dataset.fit === "true" ? "Actual size" : "Fit to width", () => {
    box.dataset.fit = box.dataset.fit === "true" ? "false" : "true";
    drawViewBar();
  }, "zoom the diagram: fit it to the page's width, or draw it at its actual size");
  fit.classList.add("fit");
  return fit;
}

async function loadDiagram() {
  const seq = ++S.svgSeq;
  const params = new URLSearchParams({ view: S.view });
  if (S.opened.length) params.set("open", S.opened.join(","));
  const box = role("diagram");
  box.dataset.loading = "true";
  let text;
  try {
    const res = await fetch(`/api/diagram/${encodeURIComponent(S.chart)}?${params}`);
    text = await res.text();
    if (!res.ok) throw new Error(text);
  } catch (err) {
    if (seq === S.svgSeq) say(`diagram: ${err.message}`, true);
    return;
  }
  if (seq !== S.svgSeq) return;  // another picture was asked for meanwhile
  box.innerHTML = text;
  box.dataset.chart = S.chart;
  box.dataset.view = S.view + (S.opened.length ? "+" + S.opened.join("+") : "");
  for (const el of $$("[data-state], [data-transition], [data-stub]", box)) {
    el.addEventListener("click", onDiagramClick);
    el.addEventListener("contextmenu", onDiagramClick);
    el.addEventListener("keydown", (e) => { if (e.key === "Enter" || e.key === " ") onDiagramClick(e); });
  }
  for (const el of $$("[data-transition]", box)) {  // a flash is cleared when its animation has run
    el.addEventListener("animationend", () => el.classList.remove("flash"));
  }
  for (const el of $$("[data-subchart]", box)) {
    el.addEventListener("dblclick", (e) => {
      e.preventDefault();
      setView("overview", [...new Set([...S.opened, el.dataset.subchart])]);
    });
  }
  drawDiagramState([], true);
  drawCoverage();
  delete box.dataset.loading;
}

function drawDiagramState(transitions, all) {
  const box = role("diagram");
  if (box.dataset.chart !== S.chart) return;
  const active = S.active[S.chart] || new Set();
  for (const el of $$("[data-state-id]", box)) {
    const on = active.has(el.dataset.stateId) ? "true" : "false";
    if (el.dataset.active !== on) el.dataset.active = on;
  }
  const taken = S.taken[S.chart] || {};
  const flashed = new Set(transitions.filter((t) => t.chart === S.chart && t.index !== null).map((t) => t.index));
  for (const el of $$("[data-index]", box)) {
    const indices = el.dataset.index.split(" ").map(Number);
    if (all || indices.some((i) => String(i) in taken || flashed.has(i))) {
      const count = indices.reduce((sum, i) => sum + (taken[i] || 0), 0);
      el.dataset.takenCount = String(count);
    }
    if (indices.some((i) => flashed.has(i))) {
      el.classList.remove("flash");
      void el.getBoundingClientRect();  // restart the animation
      el.classList.add("flash");
    }
  }
}

// -- clicking on the diagram: breakpoints, sub-charts --------------------------------------------

function onDiagramClick(event) {
  event.preventDefault();
  event.stopPropagation();
  const el = event.currentTarget;
  const chart = S.chart;
  const items = [];
  if (el.dataset.stub) {
    const [, ...path] = el.dataset.stub.split(".");
    items.push([`Open the picture of ${el.dataset.stub}`, () => setView(el.dataset.view, [])]);
    const id = path[path.length - 1];
    items.push([`Break on entering ${el.dataset.stub}`, () => addBreak(`enter ${chart}.${id}`)]);
  } else if (el.dataset.stateId) {
    const id = el.dataset.stateId;
    const q = el.dataset.state;
    if (el.dataset.subchart) {
      items.push([`Open ${id} in place`, () => setView("overview", [...new Set([...S.opened, id])])]);
      items.push([`Open ${id} on its own`, () => setView(id, [])]);
    }
    items.push([`Break on entering ${q}`, () => addBreak(`enter ${chart}.${id}`)]);
    items.push([`Break on leaving ${q}`, () => addBreak(`exit ${chart}.${id}`)]);
  } else if (el.dataset.transition) {
    for (const name of el.dataset.transition.split(" ")) {
      const arrow = name.slice(chart.length + 1);
      items.push([`Break when ${name} is taken`, () => addBreak(`transition ${chart} ${arrow}`)]);
    }
  }
  openMenu(items, event);
}

function addBreak(spec) {
  link.send({ type: "break", spec });
}

function openMenu(items, event) {
  const menu = role("menu");
  menu.replaceChildren();
  for (const [label, action] of items) {
    const b = button(label, () => { closeMenu(); action(); });
    b.setAttribute("role", "menuitem");
    menu.append(b);
  }
  const cancel = button("Cancel", closeMenu);
  cancel.setAttribute("role", "menuitem");
  menu.append(cancel);
  const r = event.currentTarget.getBoundingClientRect();
  const x = event.clientX || r.left + r.width / 2;
  const y = event.clientY || r.top + r.height / 2;
  menu.style.left = `${Math.min(x + window.scrollX, window.scrollX + window.innerWidth - 320)}px`;
  menu.style.top = `${y + window.scrollY}px`;
  menu.hidden = false;
  menu.querySelector("button").focus();
}

function closeMenu() {
  role("menu").hidden = true;
}

document.addEventListener("click", (e) => {
  if (!role("menu").contains(e.target)) closeMenu();
});
document.addEventListener("keydown", (e) => { if (e.key === "Escape") closeMenu(); });

// -- the data watch ------------------------------------------------------------------------------

function buildWatch() {
  const chart = S.charts[S.chart];
  const body = $("tbody", role("watch"));
  body.replaceChildren();
  for (const d of chart.data) {
    const tr = document.createElement("tr");
    tr.dataset.datum = `${chart.name}.${d.name}`;
    tr.dataset.kind = d.kind;
    const kind = cell(d.kind, "kind");
    const name = cell(d.name, "name");
    name.title = d.doc;
    const value = cell("", "value");
    const text = document.createElement("span");
    text.dataset.role = "value";
    value.append(text);
    const doc = document.createElement("div");
    doc.className = "doc";
    doc.textContent = d.doc + (d.unit && d.unit !== "1" ? ` [${d.unit}]` : "");
    name.append(doc);
    const set = value;
    if (d.kind === "input") {
      const form = document.createElement("form");
      form.className = "set";
      const input = document.createElement("input");
      input.name = "value";
      input.size = 7;
      input.setAttribute("aria-label", `value for ${chart.name}.${d.name}`);
      input.placeholder = d.unit === "bool" ? "1 / 0" : d.unit === "rad" ? "90deg" : d.unit === "m" ? "20mm" : "";
      const doSet = button("Set", () => sendSet(d.name, input.value, false), `Set ${chart.name}.${d.name}`);
      const doForce = button("Force", () => sendSet(d.name, input.value, true), `Force ${chart.name}.${d.name}`);
      const doRelease = button("Release", () => link.send({ type: "release", chart: chart.name, name: d.name }),
        `Release ${chart.name}.${d.name}`);
      doRelease.dataset.role = "release";
      form.addEventListener("submit", (e) => { e.preventDefault(); sendSet(d.name, input.value, false); });
      form.append(input, doSet, doForce, doRelease);
      set.append(form);
    }
    tr.append(kind, name, value);
    body.append(tr);
  }
  drawWatch();
}

function sendSet(name, value, force) {
  if (!value.trim()) {
    say(`type a value for ${S.chart}.${name} first`, true);
    return;
  }
  link.send({ type: "set", chart: S.chart, name, value: value.trim(), force });
}

function drawWatch() {
  const chart = S.chart;
  const values = S.data[chart] || {};
  const changed = S.changed[chart] || new Set();
  const forced = new Set(S.forced);
  for (const tr of $$("tbody tr", role("watch"))) {
    const name = tr.dataset.datum.slice(chart.length + 1);
    const v = $('[data-role="value"]', tr);
    const text = values[name] ?? "";
    if (v.textContent !== text) v.textContent = text;
    tr.dataset.changed = changed.has(name) ? "true" : "false";
    tr.dataset.forced = forced.has(tr.dataset.datum) ? "true" : "false";
  }
}

function drawSignals() {
  const body = $("tbody", role("signals"));
  if (!S.info) return;
  if (body.children.length !== S.info.signals.length) {
    body.replaceChildren();
    for (const s of S.info.signals) {
      const tr = document.createElement("tr");
      tr.dataset.signal = s.name;
      const name = cell(s.name, "name");
      name.title = s.doc;
      const doc = document.createElement("div");
      doc.className = "doc";
      doc.textContent = s.doc;
      name.append(doc);
      if (s.simulation_only) {
        const badge = document.createElement("span");
        badge.className = "badge";
        badge.textContent = "simulation only";
        name.prepend(badge);
      }
      const value = cell("", "value");
      value.dataset.role = "value";
      tr.append(name, value);
      body.append(tr);
    }
  }
  for (const tr of $$("tr", body)) {
    const text = S.signals[tr.dataset.signal] ?? "";
    const v = $('[data-role="value"]', tr);
    if (v.textContent !== text) v.textContent = text;
    tr.dataset.changed = S.changedSignals.has(tr.dataset.signal) ? "true" : "false";
  }
}

// -- breakpoints, inputs and events ---------------------------------------------------------------

function drawBreakpoints() {
  const list = role("breakpoints");
  const key = JSON.stringify(S.breakpoints);
  if (list.dataset.key === key) return;
  list.dataset.key = key;
  list.replaceChildren();
  for (const bp of S.breakpoints) {
    const li = document.createElement("li");
    li.dataset.breakpoint = String(bp.id);
    li.dataset.hits = String(bp.hits);
    const on = document.createElement("input");
    on.type = "checkbox";
    on.checked = bp.enabled;
    on.setAttribute("aria-label", `breakpoint ${bp.id} enabled`);
    on.addEventListener("change", () => link.send({ type: "break_enable", breakpoint: bp.id, enabled: on.checked }));
    const text = document.createElement("span");
    text.textContent = `${bp.id}: ${bp.spec} — ${bp.hits} hit${bp.hits === 1 ? "" : "s"}`;
    const del = button("Delete", () => link.send({ type: "break_delete", breakpoint: bp.id }), `Delete breakpoint ${bp.id}`);
    li.append(on, text, del);
    list.append(li);
  }
  if (!S.breakpoints.length) {
    const li = document.createElement("li");
    li.className = "none";
    li.textContent = "none: click a state or a transition";
    list.append(li);
  }
}

function drawActions() {
  const list = role("actions");
  const key = JSON.stringify(S.actions);
  if (list.dataset.key === key) return;
  list.dataset.key = key;
  list.replaceChildren(...S.actions.slice(-8).map((a) => {
    const li = document.createElement("li");
    li.textContent = a;
    return li;
  }));
}

function fillEventSelects() {
  const post = $('select[name="event"]', role("post-form"));
  const brk = $('select[name="event"]', role("event-break-form"));
  const opts = [];
  for (const c of S.info.charts) {
    for (const e of c.events) opts.push([`${c.name}.${e}`, `${c.name} ${e}`]);
  }
  post.replaceChildren(...opts.map(([v, t]) => new Option(t, v)));
  const brkOpts = [];
  for (const c of S.info.charts) {
    for (const e of ["tick", ...c.events]) brkOpts.push([`${c.name}.${e}`, `${c.name}.${e}`]);
  }
  brk.replaceChildren(...brkOpts.map(([v, t]) => new Option(t, v)));
}

role("break-form").addEventListener("submit", (e) => {
  e.preventDefault();
  const text = e.target.condition.value.trim();
  if (text) addBreak(`when ${text}`);
});
role("event-break-form").addEventListener("submit", (e) => {
  e.preventDefault();
  if (e.target.event.value) addBreak(`event ${e.target.event.value}`);
});
role("spec-form").addEventListener("submit", (e) => {
  e.preventDefault();
  const text = e.target.spec.value.trim();
  if (text) addBreak(text);
});
role("post-form").addEventListener("submit", (e) => {
  e.preventDefault();
  const [chart, event] = e.target.event.value.split(".");
  if (!chart) return;
  const data = {};
  for (const item of e.target.data.value.trim().split(/\s+/).filter(Boolean)) {
    const [k, ...rest] = item.split("=");
    data[k] = rest.join("=");
  }
  link.send({ type: "post", chart, event, data });
});

// -- trace, slider, timeline -----------------------------------------------------------------------

function drawTrace(leftOut) {
  const body = $("tbody", role("trace"));
  const rows = S.trace.slice(0, 100);
  const key = rows.length ? `${rows.length}:${rows[0].chart}:${rows[0].tick}:${rows[0].source}:${S.seq}` : "";
  if (body.dataset.key === key) return;
  body.dataset.key = key;
  body.replaceChildren(...rows.map((t) => {
    const tr = document.createElement("tr");
    for (const v of [t.tick, t.time_s === null ? "" : t.time_s.toFixed(3), t.chart, t.source, t.target ?? "(stays)", t.trigger]) {
      tr.append(cell(String(v)));
    }
    return tr;
  }));
  if (leftOut > 0) say(`${leftOut} transitions in the last frame were too many to list (the trace file has them all)`);
}

function drawSlider() {
  const slider = role("slider");
  slider.max = String(S.furthest);
  if (document.activeElement !== slider && role("slider-form").dataset.dragging !== "true") {
    slider.value = String(S.tick);
    role("slider-value").textContent = String(S.tick);
  }
}

role("slider").addEventListener("input", (e) => {
  role("slider-form").dataset.dragging = "true";
  role("slider-value").textContent = e.target.value;
});
role("slider-form").addEventListener("submit", (e) => {
  e.preventDefault();
  role("slider-form").dataset.dragging = "false";
  link.send({ type: "replay", tick: Number(role("slider").value) });
});
role("slider").addEventListener("change", () => {
  role("slider-form").dataset.dragging = "false";
  link.send({ type: "replay", tick: Number(role("slider").value) });
});

function drawTimeline(m) {
  if (m.chart !== S.chart) return;
  const box = role("timeline");
  const secs = ((m.last - m.first) * m.period_s).toFixed(1);
  role("timeline-chart").textContent = `of ${m.chart}: the last ${secs} s (chart ticks ${m.first} to ${m.last})`;
  box.replaceChildren();
  if (!m.rows) return;
  const span = Math.max(1, m.last - m.first);
  for (const row of m.rows) {
    const line = document.createElement("div");
    line.className = "tl-row";
    line.dataset.timelineState = row.qname;  // not data-state: that names a state drawn in the diagram
    const label = document.createElement("span");
    label.className = "tl-label";
    label.textContent = row.state;
    const track = document.createElement("span");
    track.className = "tl-track";
    for (const [a, b] of row.intervals) {
      const bar = document.createElement("span");
      bar.className = "tl-bar";
      bar.style.left = `${(100 * (a - m.first)) / span}%`;
      bar.style.width = `${Math.max(0.3, (100 * ((b ?? m.last) - a)) / span)}%`;
      bar.title = `${row.state}: ticks ${a}..${b ?? "now"}`;
      track.append(bar);
    }
    line.append(label, track);
    box.append(line);
  }
}

// -- coverage ----------------------------------------------------------------------------------------

function drawCoverage() {
  const box = role("diagram");
  const cov = S.coverage && S.coverage.charts[S.chart];
  box.dataset.coverage = cov ? "on" : "off";
  for (const el of $$("[data-state-id]", box)) {
    const id = el.dataset.stateId;
    if (cov && cov.entered.includes(id)) el.dataset.coverage = "entered";
    else if (cov && cov.missing_states.includes(id)) el.dataset.coverage = "never";
    else delete el.dataset.coverage;  // no coverage shown, or a history pseudo-state
  }
  for (const el of $$("[data-index]", box)) {
    if (!cov) { delete el.dataset.coverage; continue; }
    const indices = el.dataset.index.split(" ").map(Number);
    el.dataset.coverage = indices.some((i) => cov.taken.includes(i)) ? "taken" : "never";
  }
  drawCoverageSummary();
}

function drawCoverageSummary() {
  const p = role("coverage-summary");
  if (!S.coverage) { p.textContent = "no coverage shown"; return; }
  const cov = S.coverage.charts[S.chart];
  const lines = [];
  if (cov) lines.push(`${S.chart}: states ${cov.states}, transitions ${cov.transitions} (green: entered / taken; red: never)`);
  else lines.push(`${S.chart}: not in the coverage`);
  if (S.coverage.scenarios) {
    const passed = S.coverage.scenarios.filter((s) => s.passed).length;
    lines.push(`${passed} of ${S.coverage.scenarios.length} scenarios passed`);
  }
  p.textContent = lines.join("; ");
}

const covForm = role("coverage-form");
covForm.addEventListener("submit", (e) => {
  e.preventDefault();
  const files = Array.from(covForm.files.selectedOptions).map((o) => o.value);
  if (!files.length) { say("pick one or more scenario files first", true); return; }
  link.send({ type: "coverage_run", files });
});
covForm.scenario.addEventListener("change", async () => {
  const file = covForm.scenario.files[0];
  if (file) link.send({ type: "coverage_scenario", name: file.name, text: await file.text() });
});
covForm.report.addEventListener("change", async () => {
  const file = covForm.report.files[0];
  if (!file) return;
  let report;
  try {
    report = JSON.parse(await file.text());
  } catch (err) {
    say(`${file.name} is not JSON: ${err.message}`, true);
    return;
  }
  link.send({ type: "coverage_load", report });
});
role("coverage-clear").addEventListener("click", () => link.send({ type: "coverage_clear" }));

// -- helpers and the toolbar ---------------------------------------------------------------------------

function button(text, onClick, label) {
  const b = document.createElement("button");
  b.type = "button";
  b.textContent = text;
  if (label) b.setAttribute("aria-label", label);
  if (label) b.title = label;
  b.addEventListener("click", (e) => { e.preventDefault(); onClick(e); });
  return b;
}

function cell(text, cls) {
  const td = document.createElement("td");
  td.textContent = text;
  if (cls) td.className = cls;
  return td;
}

for (const b of $$("[data-cmd]")) {
  b.addEventListener("click", () => link.send({ type: b.dataset.cmd }));
}
addSafety(document.querySelector("header"), link);
role("speed").addEventListener("change", (e) => {
  const v = e.target.value;
  link.send({ type: "speed", value: v === "max" ? "max" : Number(v) });
});

// The timeline of the shown chart: asked for when a chart is shown and once a second while the page is open.
function askTimeline() {
  if (S.chart && S.joined && document.visibilityState === "visible") {
    link.send({ type: "timeline", chart: S.chart, seconds: 20 });
  }
}
setInterval(askTimeline, 1000);

link.connect();
