// The chart cockpit (/charts): draws the session's frames on the charts' diagrams and sends commands.
//
// A view only: every decision (pacing, breakpoints, replay, coverage, the text of
// every value) is the session's (ttt_sm.web.session); this page keeps what it was
// last told and draws it.  Each part of the page is a small object of its own
// (charts/*.js): the diagram, the data watch and the signals, breakpoints, events,
// the trace, the time slider, the timeline, coverage.  This module routes the
// session's messages to them, keeps the frames in order and draws the header.

import { $, $$, button, role } from "./dom.js";
import { addDrive1Stop, addSafety, addSpeed, drawDrive1, drawSafety, drawSpeed } from "./page.js";
import { SessionLink } from "./session.js";
import { Breakpoints } from "./charts/breakpoints.js";
import { CoverageView } from "./charts/coverage.js";
import { DiagramView } from "./charts/diagram.js";
import { Events } from "./charts/events.js";
import { TimeSlider } from "./charts/slider.js";
import { Timeline } from "./charts/timeline.js";
import { Trace } from "./charts/trace.js";
import { DataWatch, Signals } from "./charts/watch.js";

function say(text, isError = false, kind = "") {
  const status = role("status");
  status.textContent = text;
  status.dataset.error = isError ? "true" : "";
  status.dataset.kind = kind;
}

const link = new SessionLink(onMessage, (text) => say(text, text.startsWith("disconnected")));
const coverage = new CoverageView(link, say);
const diagram = new DiagramView(link, say, () => coverage.draw(),
  (el, chart) => coverage.menuItems(el, chart, diagram.charts[chart]));
const watch = new DataWatch(link, say);
const signals = new Signals();
const breakpoints = new Breakpoints(link);
const events = new Events(link);
const trace = new Trace(say);
const slider = new TimeSlider(link);
const timeline = new Timeline(link);
// The frames in order: a page draws a frame only once it has joined (its full frame), and never an older one.
const frames = { seq: -1, joined: false };

// -- messages -------------------------------------------------------------------------

function onMessage(m) {
  switch (m.type) {
    case "session": return onSession(m.info);
    case "frame": return onFrame(m);
    case "reply": return coverage.takeReply(m) || say(m.text || "ok");
    case "error": return say(m.error, true);
    case "coverage": return coverage.take(m);
    case "coverage_suggestion": return coverage.takeSuggestion(m);
    case "timeline": return timeline.draw(m);
    default: return undefined;
  }
}

function onSession(info) {
  diagram.setCharts(info.charts);
  signals.describe(info.signals);
  const tabs = role("chart-tabs");
  tabs.replaceChildren();
  for (const c of info.charts) {
    const b = button(c.name, () => showChart(c.name));
    b.title = `${c.name}: ${c.doc}`;
    b.dataset.chart = c.name;
    tabs.append(b);
  }
  events.describe(info.charts);
  breakpoints.describe(info.charts);
  coverage.describe(info.scenarios);
  const shown = diagram.chart;
  // a page opens on the first chart, DriveInit1 on the robot: the one the tutorial starts with (docs/tutorial.md)
  showChart(shown && diagram.charts[shown] ? shown : info.charts[0].name);
}

function onFrame(f) {
  if (f.full) {
    frames.joined = true;
  } else if (!frames.joined || f.seq <= frames.seq) {
    return;
  }
  frames.seq = f.seq;
  drawHeader(f);
  diagram.take(f);
  watch.take(f);
  signals.take(f);
  breakpoints.take(f);
  events.take(f);
  trace.take(f);
  slider.take(f);
  if ((f.transitions || []).length) {
    const seq = f.seq;
    requestAnimationFrame(() => link.ack(seq));
  }
}

// -- the header --------------------------------------------------------------------------

function drawHeader(f) {
  role("sim-time").textContent = f.t.toFixed(4);
  role("tick").textContent = String(f.tick);
  const mode = role("mode");
  mode.textContent = f.mode;
  mode.dataset.mode = f.mode;
  drawSpeed(role("speed"), f.speed);
  drawPace(f);
  if ("safety" in f) drawSafety(f.safety);
  if ("drive1" in f) drawDrive1(f.drive1);
  if (f.stop) say(f.stop.text, false, f.stop.kind);
  if (f.error) say(f.error, true);
}

// How the simulation keeps its pace.  An overrun (a control period begun a whole period late) is
// expected when the run is not paced to the wall clock or its periods are shorter than the machine's
// bursts of steps (as fast as it goes; x2 and above): it is said in words, not coloured.  Only a slip
// matters (the paced run fell more than 0.25 s behind and gave that time up): then the line is
// coloured (data-alarm).
const OVERRUNS_EXPECTED_AT = 2;

function drawPace(f) {
  const p = f.pace;
  const expected = f.speed === "max" || f.speed >= OVERRUNS_EXPECTED_AT;
  const parts = [];
  if (f.mode === "running") parts.push(`x${p.realtime_factor.toFixed(1)} real time`);
  if (f.speed !== "max") parts.push(`behind by ${p.lag_ms.toFixed(1)} ms (max ${p.lag_max_ms.toFixed(1)} ms)`);
  if (p.overruns) parts.push(`${p.overruns} overrun${p.overruns === 1 ? "" : "s"}${expected ? " (expected)" : ""}`);
  if (p.slips) parts.push(`${p.slips} slip${p.slips === 1 ? "" : "s"}, ${p.lost_s.toFixed(2)} s lost`);
  if (f.latency.p95_ms !== null) parts.push(`frame latency p95 ${f.latency.p95_ms.toFixed(0)} ms`);
  const pace = role("pace");
  pace.textContent = parts.join(" · ") || (f.speed === "max" ? "not paced" : "on time");
  pace.dataset.overruns = String(p.overruns);
  pace.dataset.alarm = String(f.speed !== "max" && p.slips > 0);
  const speed = f.speed === "max" ? "as fast as it goes" : `at x${f.speed}`;
  pace.title = "How the simulation keeps its pace to the wall clock."
    + ` Overruns: control periods (1 ms of simulated time) begun a whole period late; ${speed}`
    + (expected ? " they are expected (the steps run in bursts between sleeps) and cost nothing."
      : " a few are harmless.")
    + " Slips: times the run fell more than 0.25 s behind and gave that time up instead of racing to"
    + " catch up; at a paced speed they mean the machine could not keep it, and the line turns orange.";
}

// -- the chart shown -------------------------------------------------------------------

function showChart(name) {
  const chart = diagram.charts[name];
  if (!chart) return;
  for (const b of $$("button", role("chart-tabs"))) b.setAttribute("aria-pressed", String(b.dataset.chart === name));
  role("data-chart").textContent = `of ${name}`;
  coverage.show(name);
  timeline.show(name);
  diagram.show(name);
  watch.show(chart);
  askTimeline();
}

// The timeline of the shown chart: asked for when a chart is shown and once a second while the page is open.
function askTimeline() {
  if (frames.joined) timeline.ask();
}
setInterval(askTimeline, 1000);

// -- the toolbar ---------------------------------------------------------------------------

// Keyboard shortcuts for the toolbar, each its command's first letter (docs/gui.md "Keys"): a key
// presses its button, as a click does.  Never while typing (an input, a text area, a list box has
// the focus) nor with Ctrl, Alt or Meta (the browser's own shortcuts).
const SHORTCUTS = { r: "run", p: "pause", s: "step", t: "tick", n: "next" };

const TEXT_INPUTS = ["text", "search", "number", "email", "url", "password", "tel"];

// Whether `el` takes typed letters: a text box, a text area, a list box (its letters pick an option).
// The time slider and the check boxes do not: a key works again once one of them is used.
function typing(el) {
  if (!el) return false;
  if (el.isContentEditable || el.tagName === "TEXTAREA" || el.tagName === "SELECT") return true;
  return el.tagName === "INPUT" && TEXT_INPUTS.includes(el.type);
}

function addShortcuts() {
  for (const [key, cmd] of Object.entries(SHORTCUTS)) {
    const b = $(`[data-cmd="${cmd}"]`);
    b.setAttribute("aria-keyshortcuts", key);
    b.title = `${b.title} (key ${key})`;
  }
  document.addEventListener("keydown", (e) => {
    if (e.ctrlKey || e.altKey || e.metaKey || typing(e.target) || typing(document.activeElement)) return;
    const cmd = SHORTCUTS[e.key];
    if (!cmd || (e.repeat && (cmd === "run" || cmd === "pause"))) return;
    e.preventDefault();
    $(`[data-cmd="${cmd}"]`).click();
  });
}

for (const b of $$("[data-cmd]")) {
  b.addEventListener("click", () => link.send({ type: b.dataset.cmd }));
}
addShortcuts();
addSafety($("header"), link);
addDrive1Stop($(".safety-group"), link);
addSpeed(role("speed"), link);

link.connect();
