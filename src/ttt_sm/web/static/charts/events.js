// Events posted to a chart from the page, and the list of the user's actions (inputs set, events
// posted; the session keeps them all, a replay applies them again).

import { $, fillSelect, role, showsOther } from "../dom.js";

export class Events {
  constructor(link) {
    this.link = link;
    this.actions = [];
    role("post-form").addEventListener("submit", (e) => {
      e.preventDefault();
      const [chart, event] = e.target.event.value.split(".");
      if (!chart) return;
      const data = {};
      for (const item of e.target.data.value.trim().split(/\s+/).filter(Boolean)) {
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
    this.draw();
  }

  draw() {
    const list = role("actions");
    if (!showsOther(list, this.actions)) return;
    list.replaceChildren(...this.actions.slice(-8).map((a) => {
      const li = document.createElement("li");
      li.textContent = a;
      return li;
    }));
  }
}
