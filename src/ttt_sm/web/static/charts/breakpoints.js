// Breakpoints: the session's list (each switched on and off, deleted here) and the forms that add
// one: a condition, an event, or a spec as `ttt-sm debug` writes it.  A click on the diagram adds
// one too (diagram.js).

import { $, button, fillSelect, role, showsOther } from "../dom.js";

export class Breakpoints {
  constructor(link) {
    this.link = link;
    this.list = [];
    role("break-form").addEventListener("submit", (e) => {
      e.preventDefault();
      const text = e.target.condition.value.trim();
      if (text) this.add(`when ${text}`);
    });
    role("event-break-form").addEventListener("submit", (e) => {
      e.preventDefault();
      if (e.target.event.value) this.add(`event ${e.target.event.value}`);
    });
    role("spec-form").addEventListener("submit", (e) => {
      e.preventDefault();
      const text = e.target.spec.value.trim();
      if (text) this.add(text);
    });
  }

  add(spec) {
    this.link.send({ type: "break", spec });
  }

  // The events a breakpoint may wait for: every chart's tick and events (the session's charts).
  describe(charts) {
    const events = charts.flatMap((c) => ["tick", ...c.events].map((e) => `${c.name}.${e}`));
    fillSelect($('select[name="event"]', role("event-break-form")), events.map((v) => [v, v]));
  }

  take(f) {
    if (f.breakpoints !== undefined) this.list = f.breakpoints;
    this.draw();
  }

  draw() {
    const list = role("breakpoints");
    if (!showsOther(list, this.list)) return;
    list.replaceChildren();
    for (const bp of this.list) {
      const li = document.createElement("li");
      li.dataset.breakpoint = String(bp.id);
      li.dataset.hits = String(bp.hits);
      const on = document.createElement("input");
      on.type = "checkbox";
      on.checked = bp.enabled;
      on.setAttribute("aria-label", `breakpoint ${bp.id} enabled`);
      on.addEventListener("change", () => this.link.send({ type: "break_enable", breakpoint: bp.id, enabled: on.checked }));
      const text = document.createElement("span");
      text.textContent = `${bp.id}: ${bp.spec} — ${bp.hits} hit${bp.hits === 1 ? "" : "s"}`;
      const del = button("Delete", () => this.link.send({ type: "break_delete", breakpoint: bp.id }), `Delete breakpoint ${bp.id}`);
      li.append(on, text, del);
      list.append(li);
    }
    if (!this.list.length) {
      const li = document.createElement("li");
      li.className = "none";
      li.textContent = "none: click a state or a transition";
      list.append(li);
    }
  }
}
