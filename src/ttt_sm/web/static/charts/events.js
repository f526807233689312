// Events posted to a chart from the page, and the list of the user's actions (inputs set, events
// posted; the session keeps them all, a replay applies them again).

import { $, drawList, fillSelect, onSubmit, role } from "../dom.js";

export class Events {
  constructor(link) {
    this.link = link;
    this.actions = [];
    onSubmit("post-form", (form) => {
      const [chart, event] = form.event.value.split(".");
      if (!chart) return;
      const data = {};
      for (const item of form.data.value.trim().split(/\s+/).filter(Boolean)) {
        const [k, ...rest] = item.split("=");
        data[k] = rest.join("=");
      }
      this.link.send({ type: "post", chart, event, data });
    });
  }

  // The events a page may post: every chart's (the session's charts).
  describe(charts) {
    const events = charts.flatMap((c) => c.events.map((e) => [`${c.name}.${e}`, `${c.name} ${e}`]));
    fillSelect($('select[name="event"]', role("post-form")), events);
  }

  take(f) {
    if (f.actions !== undefined) this.actions = f.actions;
    drawList("actions", this.actions.slice(-8), (a) => {
      const li = document.createElement("li");
      li.textContent = a;
      return li;
    });
  }
}
