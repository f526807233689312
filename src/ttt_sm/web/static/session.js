// The pages' link to the one running session: a WebSocket, commands out, frames in.
//
// A page is a view: it sends commands ({type, ...fields}, checked by the server's
// ttt_sm.web.protocol) and draws what comes back: "session" (what runs, once),
// "frame" (the state now and the transitions since the last frame; one "full"
// frame first), "reply" and "error" (to a command), "coverage".  Nothing here
// decides anything about the robot.

export class SessionLink {
  constructor(onMessage, onStatus) {
    this.onMessage = onMessage;
    this.onStatus = onStatus || (() => {});
    this.nextId = 1;
    this.ws = null;
    this.closedByPage = false;
  }

  connect() {
    const scheme = location.protocol === "https:" ? "wss:" : "ws:";
    const ws = new WebSocket(`${scheme}//${location.host}/ws`);
    this.ws = ws;
    ws.onopen = () => {
      this.onStatus("connected");
      this.send({ type: "hello", page: document.body.dataset.page || "charts" });
    };
    ws.onmessage = (event) => {
      let message;
      try {
        message = JSON.parse(event.data);
      } catch (err) {
        this.onStatus(`unreadable message from the session: ${err}`);
        return;
      }
      this.onMessage(message);
    };
    ws.onclose = () => {
      this.onStatus("disconnected: the session is gone (stopped with Ctrl-C?); retrying ...");
      if (!this.closedByPage) setTimeout(() => this.connect(), 2000);
    };
  }

  // Send a command; returns its id (echoed in the reply or error).
  send(command) {
    const id = this.nextId++;
    if (this.ws && this.ws.readyState === WebSocket.OPEN) {
      this.ws.send(JSON.stringify({ ...command, id }));
    }
    return id;
  }

  // The page has drawn frame `seq` (its transitions highlighted): the latency figure.
  ack(seq) {
    if (this.ws && this.ws.readyState === WebSocket.OPEN) {
      this.ws.send(JSON.stringify({ type: "ack", frame: seq }));
    }
  }
}

// -- what every page shows ---------------------------------------------------------------

const byRole = (name) => document.querySelector(`[data-role="${name}"]`);

// The header of a page beside the chart cockpit (/game, /operate): the page's own controls are
// the <header>'s children in its HTML; this puts the title before them and, after them, the clock,
// the Safety chart's state and Reset, and a link to the charts.
export function pageHeader(link) {
  const header = document.querySelector("header");
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

const SAFETY_STATES = {
  monitoring: "Safety: monitoring",
  tripped: "Safety: stopped",
  reinitialising: "Safety: re-initialising",
};

// A frame's `safety` part: the chart's outputs tripped, reason, trips and reinit.
export function drawSafety(s) {
  const phase = s.tripped ? "tripped" : s.reinitialising ? "reinitialising" : "monitoring";
  const state = byRole("safety-state");
  state.dataset.state = phase;
  state.textContent = SAFETY_STATES[phase];
  state.title = s.trips ? `tripped ${s.trips} time${s.trips === 1 ? "" : "s"} since power-on; the last: ${s.reason}`
    : "it has not tripped since power-on";
  byRole("safety-reset").disabled = !s.tripped;
  const banner = byRole("safety");
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
    const mode = byRole("mode");
    mode.textContent = f.mode;
    mode.dataset.mode = f.mode;
    document.querySelector('[data-cmd="run"]').disabled = f.mode === "running";
  }
  if (f.t !== undefined) byRole("sim-time").textContent = f.t.toFixed(1);
  if ("safety" in f) drawSafety(f.safety);
}
