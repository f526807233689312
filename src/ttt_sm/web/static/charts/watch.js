// The values the charts declare and the robot's signals, as the session words them, live.
//
// DataWatch: the shown chart's inputs, outputs and local data (a row each, with its
// unit and doc; an input can be set, forced and released here).  Signals: the
// scheduler's signals between the charts and the arm.  A value that changed in the
// last frame that changed any is marked (data-changed), a forced input too.

import { $, $$, button, cell, role } from "../dom.js";

export class DataWatch {
  constructor(link, say) {
    this.link = link;
    this.say = say;
    this.chart = null;    // the shown chart's description
    this.data = {};       // chart -> {datum: text}
    this.changed = {};    // chart -> Set of data changed in the last frame that changed any
    this.forced = [];     // "Chart.name" of the inputs forced
  }

  // Show chart `chart` (its description): a row per datum.
  show(chart) {
    if (!this.chart || this.chart.name !== chart.name) this.changed = {};
    this.chart = chart;
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
      if (d.kind === "input") value.append(this.setForm(chart.name, d));
      tr.append(kind, name, value);
      body.append(tr);
    }
    this.draw();
  }

  // Set, Force and Release for input `d` of chart `chartName`.
  setForm(chartName, d) {
    const form = document.createElement("form");
    form.className = "set";
    const input = document.createElement("input");
    input.name = "value";
    input.size = 7;
    input.setAttribute("aria-label", `value for ${chartName}.${d.name}`);
    input.placeholder = d.placeholder ?? "";  // a typical value with its unit (the session's, from the declaration)
    if (d.title) input.title = d.title;
    const doSet = button("Set", () => this.sendSet(d.name, input.value, false), `Set ${chartName}.${d.name}`);
    const doForce = button("Force", () => this.sendSet(d.name, input.value, true), `Force ${chartName}.${d.name}`);
    const doRelease = button("Release", () => this.link.send({ type: "release", chart: chartName, name: d.name }),
      `Release ${chartName}.${d.name}`);
    doRelease.dataset.role = "release";
    form.addEventListener("submit", (e) => { e.preventDefault(); this.sendSet(d.name, input.value, false); });
    form.append(input, doSet, doForce, doRelease);
    return form;
  }

  sendSet(name, value, force) {
    const chart = this.chart.name;
    if (!value.trim()) {
      this.say(`type a value for ${chart}.${name} first`, true);
      return;
    }
    this.link.send({ type: "set", chart, name, value: value.trim(), force });
  }

  // A frame: the data that changed (all of them in a full frame), the inputs forced.
  take(f) {
    if (f.full) this.data = {};
    if (f.data) {
      const any = Object.keys(f.data).length > 0;
      for (const [chart, values] of Object.entries(f.data)) {
        this.data[chart] = { ...(this.data[chart] || {}), ...values };
      }
      if (any && !f.full) this.changed = Object.fromEntries(Object.entries(f.data).map(([k, v]) => [k, new Set(Object.keys(v))]));
      if (f.full) this.changed = {};
    }
    if (f.forced !== undefined) this.forced = f.forced;
    this.draw();
  }

  draw() {
    if (!this.chart) return;
    const chart = this.chart.name;
    const values = this.data[chart] || {};
    const changed = this.changed[chart] || new Set();
    const forced = new Set(this.forced);
    for (const tr of $$("tbody tr", role("watch"))) {
      const name = tr.dataset.datum.slice(chart.length + 1);
      const v = $('[data-role="value"]', tr);
      const text = values[name] ?? "";
      if (v.textContent !== text) drawValue(v, text);
      tr.dataset.changed = changed.has(name) ? "true" : "false";
      tr.dataset.forced = forced.has(tr.dataset.datum) ? "true" : "false";
    }
  }
}

// A value's text in `el`, in pieces that each stay on one line: a quantity and the same in other units
// ("-0.000232926 rad", "(-0.01 deg)") break only between them, so the column wraps there instead of
// being cut at the side bar's edge (1280x720).  A piece longer than a line (a text, a vector) wraps anywhere.
const KEEP_WHOLE = 24;

function drawValue(el, text) {
  // split with the spaces kept (odd items): the text drawn is the session's, character for character
  const pieces = text.split(/(\s+(?=\())/);
  el.replaceChildren(...pieces.map((piece, i) => {
    if (i % 2) return document.createTextNode(piece);
    const span = document.createElement("span");
    span.className = piece.length <= KEEP_WHOLE ? "piece whole" : "piece";
    span.textContent = piece;
    return span;
  }));
}

export class Signals {
  constructor() {
    this.described = [];      // the session's signals: name, doc, simulation_only
    this.values = {};         // name -> text
    this.changed = new Set(); // changed in the last frame that changed any
  }

  // The session's signals (its "session" message).
  describe(signals) {
    this.described = signals;
  }

  take(f) {
    if (f.signals) {
      if (Object.keys(f.signals).length && !f.full) this.changed = new Set(Object.keys(f.signals));
      if (f.full) this.changed = new Set();
      this.values = { ...this.values, ...f.signals };
    }
    this.draw();
  }

  draw() {
    const body = $("tbody", role("signals"));
    if (body.children.length !== this.described.length) {
      body.replaceChildren();
      for (const s of this.described) {
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
      const text = this.values[tr.dataset.signal] ?? "";
      const v = $('[data-role="value"]', tr);
      if (v.textContent !== text) drawValue(v, text);
      tr.dataset.changed = this.changed.has(tr.dataset.signal) ? "true" : "false";
    }
  }
}
