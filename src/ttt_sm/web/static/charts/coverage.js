// Coverage on the diagram: the states entered and the transitions taken by scenario runs (green),
// and what they never reached (red), from scenario files run by the session or a report loaded.
// A click on a red transition offers the shortest generated scenario that takes it: the session
// searches (ttt_sm.web.coverage, the generator of `ttt-sm scenario generate`), this page shows the
// YAML it sends, to copy or save.

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
      this.asked.add(link.send({ type: "coverage_load", report }));
    });
    role("coverage-clear").addEventListener("click", () => link.send({ type: "coverage_clear" }));
    role("suggestion-copy").addEventListener("click", () => this.copy());
    role("suggestion-close").addEventListener("click", () => this.closeSuggestion());
    this.saveUrl = null;    // the object URL of the Save link, revoked when another replaces it
    this.asked = new Set(); // ids of the reports this page loaded: their replies say what is shown
  }

  // A reply to this page's command: true when it is a report's "loaded", which the status line says as
  // the coverage shown of the chart shown (it comes after the colours), so that it follows the tabs.
  takeReply(m) {
    if (!this.asked.delete(m.id) || !this.coverage) return false;
    this.sayShown(true);
    return true;
  }

  // The menu items of a click on transition edge `el` of chart `chart` (described as in the session's
  // "session" message): one per transition it draws that the coverage shown never took.
  menuItems(el, chart, description) {
    const cov = this.coverage && this.coverage.charts[chart];
    if (!cov || !el.dataset.index) return [];
    return el.dataset.index.split(" ").map(Number)
      .filter((i) => cov.missing_transitions.includes(i))
      .map((i) => {
        const t = description && description.transitions.find((d) => d.index === i);
        const label = t ? t.label : `transition ${i}`;
        return [`Suggest a scenario that takes ${label}`,
          () => this.link.send({ type: "coverage_suggest", chart, transition: i })];
      });
  }

  // The session's "coverage_suggestion" message: a scenario's YAML, or why there is none.
  takeSuggestion(m) {
    const panel = role("suggestion");
    const save = role("suggestion-save");
    if (this.saveUrl) URL.revokeObjectURL(this.saveUrl);
    this.saveUrl = null;
    panel.dataset.chart = m.chart;
    panel.dataset.index = String(m.index);
    role("suggestion-yaml").textContent = m.yaml || "";
    role("suggestion-copy").hidden = !m.yaml;
    save.hidden = !m.yaml;
    if (m.yaml) {
      role("suggestion-about").textContent = `The shortest generated scenario that takes ${m.chart}: ${m.transition}`
        + ` (run it with ttt-sm scenario run ${m.file}).`;
      this.saveUrl = URL.createObjectURL(new Blob([m.yaml], { type: "application/yaml" }));
      save.href = this.saveUrl;
      save.download = m.file;
    } else {
      role("suggestion-about").textContent = `No generated scenario takes ${m.chart}: ${m.transition}: ${m.reason}`;
      save.removeAttribute("href");
      save.download = "";
    }
    panel.hidden = false;
    this.say(m.yaml ? `scenario suggested for ${m.chart}: ${m.transition}` : `${m.chart}: ${m.transition}: ${m.reason}`);
  }

  async copy() {
    const text = role("suggestion-yaml").textContent;
    try {
      await navigator.clipboard.writeText(text);
      this.say("scenario copied");
    } catch {
      // no clipboard (a page not served as localhost or https): select the text for Ctrl+C
      const range = document.createRange();
      range.selectNodeContents(role("suggestion-yaml"));
      getSelection().removeAllRanges();
      getSelection().addRange(range);
      this.say("the clipboard is not available here: the YAML is selected, press Ctrl+C");
    }
  }

  closeSuggestion() {
    role("suggestion").hidden = true;
  }

  // The scenario files the session may run (its "session" message).
  describe(scenarios) {
    fillSelect(role("coverage-form").files, scenarios.map((f) => [f, f]));
  }

  show(chart) {
    this.chart = chart;
    this.drawSummary();
    this.sayShown(false);
  }

  // The status line's word on the coverage shown follows the chart shown: it names that chart's
  // states and transitions (when the status line still holds it, not a later message).
  sayShown(fresh) {
    if (!this.coverage || !(fresh || role("status").dataset.kind === "coverage")) return;
    this.say(`coverage shown: ${role("coverage-summary").textContent}`, false, "coverage");
  }

  // The session's "coverage" message.
  take(m) {
    this.coverage = m.cleared ? null : m;
    this.draw();
    if (m.cleared) this.say("coverage cleared");
    else this.sayShown(true);
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
