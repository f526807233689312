// The trace: the newest transitions of every chart, newest first (the whole trace is
// /api/trace.jsonl, or the trace file).

import { $, cell, role } from "../dom.js";

//: Transitions kept by the page; the table shows the newest 100.
const TRACE_ROWS = 300;

export class Trace {
  constructor(say) {
    this.say = say;
    this.rows = [];
  }

  // A frame: a full one brings the newest of the session's trace, every frame the transitions since the last.
  take(f) {
    if (f.full) this.rows = (f.trace || []).slice().reverse();
    for (const t of f.transitions || []) this.rows.unshift(t);
    if (this.rows.length > TRACE_ROWS) this.rows.length = TRACE_ROWS;
    this.draw(f.seq, f.transitions_total - (f.transitions || []).length);
  }

  draw(seq, leftOut) {
    const body = $("tbody", role("trace"));
    const rows = this.rows.slice(0, 100);
    const key = rows.length ? `${rows.length}:${rows[0].chart}:${rows[0].tick}:${rows[0].source}:${seq}` : "";
    if (body.dataset.key === key) return;
    body.dataset.key = key;
    body.replaceChildren(...rows.map((t) => {
      const tr = document.createElement("tr");
      for (const v of [t.tick, t.time_s === null ? "" : t.time_s.toFixed(3), t.chart, t.source, t.target ?? "(stays)", t.trigger]) {
        tr.append(cell(String(v)));
      }
      return tr;
    }));
    if (leftOut > 0) this.say(`${leftOut} transitions in the last frame were too many to list (the trace file has them all)`);
  }
}
