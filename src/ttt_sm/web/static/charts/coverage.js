// Coverage on the diagram: the states entered and the transitions taken by scenario runs (green),
// and what they never reached (red), from scenario files run by the session or a report loaded.

import { $$, fillSelect, role } from "../dom.js";

export class CoverageView {
  constructor(link, say) {
    this.link = link;
    this.say = say;
    this.coverage = null;   // the session's "coverage" message, or null: none shown
    this.chart = null;      // the chart shown
    const form = role("coverage-form");
    form.addEventListener("submit", (e) => {
      e.preventDefault();
      const files = Array.from(form.files.selectedOptions).map((o) => o.value);
      if (!files.length) { say("pick one or more scenario files first", true); return; }
      link.send({ type: "coverage_run", files });
    });
    form.scenario.addEventListener("change", async () => {
      const file = form.scenario.files[0];
      if (file) link.send({ type: "coverage_scenario", name: file.name, text: await file.text() });
    });
    form.report.addEventListener("change", async () => {
      const file = form.report.files[0];
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
  }

  // The scenario files the session may run (its "session" message).
  describe(scenarios) {
    fillSelect(role("coverage-form").files, scenarios.map((f) => [f, f]));
  }

  show(chart) {
    this.chart = chart;
    this.drawSummary();
  }

  // The session's "coverage" message.
  take(m) {
    this.coverage = m.cleared ? null : m;
    this.draw();
    this.say(m.cleared ? "coverage cleared" : `coverage shown: ${role("coverage-summary").textContent}`);
  }

  // Colour the diagram's states and transitions (or take the colours off).
  draw() {
    const box = role("diagram");
    const cov = this.coverage && this.coverage.charts[this.chart];
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
    this.drawSummary();
  }

  drawSummary() {
    const p = role("coverage-summary");
    if (!this.coverage) { p.textContent = "no coverage shown"; return; }
    const cov = this.coverage.charts[this.chart];
    const lines = [];
    if (cov) lines.push(`${this.chart}: states ${cov.states}, transitions ${cov.transitions} (green: entered / taken; red: never)`);
    else lines.push(`${this.chart}: not in the coverage`);
    if (this.coverage.scenarios) {
      const passed = this.coverage.scenarios.filter((s) => s.passed).length;
      lines.push(`${passed} of ${this.coverage.scenarios.length} scenarios passed`);
    }
    p.textContent = lines.join("; ");
  }
}
