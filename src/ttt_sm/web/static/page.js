// What every page shows alike: the header of /game and /operate, the Safety chart on every page,
// the mode and the simulated time.  Drawn from the session's frames (session.js), as every view.

import { $, role } from "./dom.js";

// The header of a page beside the chart cockpit (/game, /operate): the page's own controls are
// the <header>'s children in its HTML; this puts the title before them and, after them, the clock,
// the Safety chart's state and Reset, and a link to the charts.
export function pageHeader(link) {
  const header = $("header");
  const h1 = document.createElement("h1");
  const home = document.createElement("a");
  home.href = "/";
  home.title = "all pages";
  home.textContent = "ttt_sm";
  h1.append(home, ` ${header.dataset.title}`);
  header.prepend(h1);
  const clock = document.createElement("div");
  clock.className = "clock";
  clock.setAttribute("aria-live", "off");
  clock.innerHTML = '<span class="label">t =</span> <span data-role="sim-time"'
    + ' title="simulated time since power-on, seconds">0.0</span> s <span data-role="mode" class="mode">connecting</span>';
  header.append(clock);
  addSafety(header, link);
  const nav = document.createElement("nav");
  nav.className = "pages";
  nav.setAttribute("aria-label", "pages");
  nav.innerHTML = '<a href="/charts" target="_blank">the charts, live</a>';
  header.append(nav);
}

// The Safety chart (docs/safety.md) on every page: its state and a Reset button (taken only while
// the chart holds the arm: it sends the chart's `reset` event through the session, an input the
// debugger records), and, under the header, a banner that says why it tripped.
export function addSafety(header, link) {
  const group = document.createElement("div");
  group.className = "safety-group";
  group.setAttribute("role", "group");
  group.setAttribute("aria-label", "Safety chart");
  const state = document.createElement("span");
  state.className = "safety-state";
  state.dataset.role = "safety-state";
  state.dataset.state = "";
  state.textContent = "Safety: –";
  const reset = document.createElement("button");
  reset.type = "button";
  reset.dataset.role = "safety-reset";
  reset.textContent = "Reset";
  reset.disabled = true;
  reset.title = "the Safety chart's reset: once the cause is removed, the drives are initialised again";
  reset.addEventListener("click", () => link.send({ type: "safety_reset" }));
  group.append(state, reset);
  header.append(group);
  const banner = document.createElement("p");
  banner.className = "safety-banner";
  banner.dataset.role = "safety";
  banner.setAttribute("role", "alert");
  banner.setAttribute("aria-label", "safety");
  banner.hidden = true;
  header.after(banner);
}

// Drive 1's stop (thesis section 3.1.2: "a non-zero value stops the first drive"), on the chart
// cockpit and the Operational page: a toggle that sets the DriveInit1 chart's `stop` input through
// the session (an input the debugger records) and releases it again.
export function addDrive1Stop(after, link) {
  const button = document.createElement("button");
  button.type = "button";
  button.dataset.role = "drive1-stop";
  button.setAttribute("aria-pressed", "false");
  button.textContent = "Stop drive 1";
  button.title = "drive 1's stop input (DriveInit1.stop, thesis section 3.1.2): the base stops where it is;"
    + " press again to release it";
  button.addEventListener("click", () => {
    link.send({ type: "drive1_stop", stop: button.getAttribute("aria-pressed") !== "true" });
  });
  after.after(button);
}

// The speeds a page offers, times real time (the session takes 0.1 .. 10, or "max": as fast as it goes).
const SPEEDS = [["0.1", "x0.1"], ["0.25", "x0.25"], ["0.5", "x0.5"], ["1", "x1 (real time)"], ["2", "x2"],
  ["5", "x5"], ["10", "x10"], ["max", "as fast as it goes"]];

// A speed list (its options: SPEEDS, x1 chosen) sets the session's speed; drawSpeed follows the
// session's, which another page may change (not while the list is being used).
export function addSpeed(select, link) {
  for (const [value, text] of SPEEDS) select.add(new Option(text, value, value === "1", value === "1"));
  select.addEventListener("change", () => {
    const v = select.value;
    link.send({ type: "speed", value: v === "max" ? "max" : Number(v) });
  });
}

export function drawSpeed(select, speed) {
  if (document.activeElement !== select) select.value = String(speed);
}

// A frame's `drive1` part: whether drive 1's stop is set (the toggle pressed) and its chart stopped.
export function drawDrive1(d) {
  const button = role("drive1-stop");
  if (!button) return;
  button.setAttribute("aria-pressed", String(d.stop));
  button.textContent = d.stop ? "Release drive 1" : "Stop drive 1";
  button.dataset.stopped = String(d.stopped);
}

const SAFETY_STATES = {
  monitoring: "Safety: monitoring",
  tripped: "Safety: stopped",
  reinitialising: "Safety: re-initialising",
};

// A frame's `safety` part: the chart's outputs tripped, reason, trips and reinit.
export function drawSafety(s) {
  const phase = s.tripped ? "tripped" : s.reinitialising ? "reinitialising" : "monitoring";
  const state = role("safety-state");
  state.dataset.state = phase;
  state.textContent = SAFETY_STATES[phase];
  state.title = s.trips ? `tripped ${s.trips} time${s.trips === 1 ? "" : "s"} since power-on; the last: ${s.reason}`
    : "it has not tripped since power-on";
  role("safety-reset").disabled = !s.tripped;
  const banner = role("safety");
  banner.hidden = phase === "monitoring";
  banner.dataset.error = s.tripped ? "true" : "false";
  banner.dataset.state = phase;
  banner.textContent = s.tripped ? `Safety stop: ${s.reason}`
    : phase === "reinitialising" ? `The drives are initialised again after the safety stop (${s.reason}).` : "";
}

// What /game and /operate draw of every frame alike: the mode (Run off while running), the
// simulated time, the Safety chart.
export function drawCommon(f) {
  if (f.mode !== undefined) {
    const mode = role("mode");
    mode.textContent = f.mode;
    mode.dataset.mode = f.mode;
    $('[data-cmd="run"]').disabled = f.mode === "running";
  }
  if (f.t !== undefined) role("sim-time").textContent = f.t.toFixed(1);
  if ("safety" in f) drawSafety(f.safety);
  if ("drive1" in f) drawDrive1(f.drive1);
}

// The answer to the page's last command (a reply, or an error in red), in its data-role="reply" box.
export function sayReply(text, isError) {
  const box = role("reply");
  box.textContent = text;
  box.dataset.error = isError ? "true" : "false";
}
