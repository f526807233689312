// Events posted to a chart from the page, and the list of the user's actions (inputs set, events
// posted; the session keeps them all, a replay applies them again).

import { $, role } from "../dom.js";

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
    const opts = [];
    for (const c of charts) {
      for (const e of c.events) opts.push([`${c.name}.${e}`, `${c.name} ${e}`]);
    }
    $('select[name="event"]', role("post-form")).replaceChildren(...opts.map(([v, t]) => new Option(t, v)));
  }

  take(f) {
    if (f.actions !== undefined) this.actions = f.actions;
    this.draw();
  }

  draw() {
    const list = role("actions");
    const key = JSON.stringify(this.actions);
    if (list.dataset.key === key) return;
    list.dataset.key = key;
    list.replaceChildren(...this.actions.slice(-8).map((a) => {
      const li = document.createElement("li");
      li.textContent = a;
      return li;
    }));
  }
}
