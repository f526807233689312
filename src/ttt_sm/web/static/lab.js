// The lab page (/lab): your chart live while you write it (ttt-sm gui --lab DIR).
//
// A view only: the server watches your file, reloads it, rebuilds the robot and runs
// the checks (ttt_sm.web.lab_watch); it sends a numbered "lab" message whenever any of
// that changes.  This page draws the newest one: the error of the last save (file:line),
// the class running, each check as it comes, and the diagram, fetched again whenever a
// new chart has loaded.  The frames only mark the states active now.

import { fitReadable } from "./charts/diagram.js";
import { role } from "./dom.js";
import { SessionLink } from "./session.js";

const shown = { version: -1, loads: -1, slot: null, active: [] };

function say(text, isError = false) {
  const status = role("status");
  status.textContent = text;
  status.dataset.error = isError ? "true" : "";
}

const link = new SessionLink(onMessage, (text) => say(text, text.startsWith("disconnected")));

function onMessage(m) {
  switch (m.type) {
    case "lab": return take(m);
    case "frame": return onFrame(m);
    case "error": return say(m.error, true);
    default: return undefined;
  }
}

// -- the lab's state ------------------------------------------------------------------------

async function ask() {
  try {
    const response = await fetch("/api/lab", { cache: "no-store" });
    if (response.ok) take(await response.json());
  } catch (err) {
    // the server is gone: the socket says so
  }
}

function take(lab) {
  if (lab.version < shown.version) return;
  shown.version = lab.version;
  shown.slot = lab.slot;
  role("title").textContent = `${lab.title} — slot ${lab.slot}, ${lab.file}`;
  role("running").textContent = `running: ${lab.running}`;
  const error = role("error");
  error.hidden = !lab.error;
  error.textContent = lab.error || "";
  drawChecks(lab.checks);
  if (lab.loads !== shown.loads) loadDiagram(lab.slot, lab.loads);
}

function drawChecks(checks) {
  const status = role("checks-status");
  status.dataset.status = checks.status;
  status.textContent = {
    none: "no checks yet: your chart has not loaded",
    running: `running the checks of chart ${checks.of} ...`,
    done: `the checks of chart ${checks.of} are done`,
    error: checks.error || "the checks stopped",
  }[checks.status] || checks.status;
  const score = role("score");
  if (checks.score) {
    score.textContent = `${checks.score.passed}/${checks.score.total}`;
    score.dataset.passed = String(checks.score.passed === checks.score.total);
  } else {
    score.textContent = "";
    delete score.dataset.passed;
  }
  const list = role("checks");
  list.replaceChildren(...checks.results.map((c) => {
    const li = document.createElement("li");
    li.dataset.passed = String(c.passed);
    li.dataset.check = c.name;
    const verdict = document.createElement("span");
    verdict.className = "verdict";
    verdict.textContent = c.passed ? "PASS" : "FAIL";
    const kind = document.createElement("span");
    kind.className = "kind";
    kind.textContent = `${c.kind}: `;
    li.append(verdict, kind, document.createTextNode(c.name));
    if (!c.passed && c.reason) {
      const reason = document.createElement("div");
      reason.className = "reason";
      reason.textContent = c.reason;
      li.append(reason);
    }
    return li;
  }));
}

async function loadDiagram(slot, loads) {
  shown.loads = loads;
  const box = role("diagram");
  box.dataset.loading = "true";
  const response = await fetch(`/api/diagram/${encodeURIComponent(slot)}?view=overview&v=${loads}`,
    { cache: "no-store" });
  const text = await response.text();
  if (shown.loads !== loads) return; // a newer chart loaded meanwhile
  if (!response.ok) {
    say(text.trim(), true);
    return;
  }
  box.innerHTML = text;
  fitReadable(box);
  box.dataset.version = String(loads);
  box.dataset.loading = "false";
  markActive();
}

// -- the frames: the header and the active states ------------------------------------------------

function onFrame(f) {
  role("sim-time").textContent = f.t.toFixed(4);
  const mode = role("mode");
  mode.textContent = f.mode;
  mode.dataset.mode = f.mode;
  if (f.full) ask(); // joined (or the robot was built again): what the lab is now
  if (f.error) say(f.error, true);
  if (shown.slot && f.active && f.active[shown.slot]) {
    shown.active = f.active[shown.slot];
    markActive();
  }
}

function markActive() {
  const active = new Set(shown.active);
  for (const el of role("diagram").querySelectorAll("[data-state-id]")) {
    const on = String(active.has(el.dataset.stateId));
    if (el.getAttribute("data-active") !== on) el.setAttribute("data-active", on);
  }
}

setInterval(ask, 2000); // a safety net: a message missed while joining is caught up within seconds
link.connect();
