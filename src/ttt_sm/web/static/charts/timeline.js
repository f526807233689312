// The timeline of the shown chart: when each of its states was active in the last 20 simulated
// seconds, asked of the session when a chart is shown and once a second while the page is visible.

import { role } from "../dom.js";

//: The simulated seconds a timeline covers.
const SECONDS = 20;

export class Timeline {
  constructor(link) {
    this.link = link;
    this.chart = null;
  }

  show(chart) {
    this.chart = chart;
  }

  ask() {
    if (this.chart && document.visibilityState === "visible") {
      this.link.send({ type: "timeline", chart: this.chart, seconds: SECONDS });
    }
  }

  // The session's "timeline" message.
  draw(m) {
    if (m.chart !== this.chart) return;
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
}
