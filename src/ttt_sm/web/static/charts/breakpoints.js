// Breakpoints: the session's list (each switched on and off, deleted here) and the forms that add
// one: a condition, an event, or a spec as `ttt-sm debug` writes it.  A click on the diagram adds
// one too (diagram.js).

import { $, button, drawList, fillSelect, onSubmit, role } from "../dom.js";

export class Breakpoints {
  constructor(link) {
    this.link = link;
    this.list = [];
    onSubmit("break-form", (form) => {
      const text = form.condition.value.trim();
      if (text) this.add(`when ${text}`);
    });
    onSubmit("event-break-form", (form) => {
      if (form.event.value) this.add(`event ${form.event.value}`);
    });
    onSubmit("spec-form", (form) => {
      const text = form.spec.value.trim();
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
    drawList("breakpoints", this.list, (bp) => this.item(bp), "none: click a state or a transition");
  }

  // One breakpoint: switched on and off, deleted, with its hits so far.
  item(bp) {
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
    return li;
  }
}
