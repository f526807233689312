// The diagram of the chart shown: the server's Graphviz SVG, one picture per view, live.
//
// A picture (overview, a sub-chart on its own, the whole chart; sub-charts opened in
// place) is loaded once; a frame only toggles attributes on it (data-active,
// data-taken-count, a "flash" class on each transition taken, removed when its
// animation ends), it never redraws it.  A click on a state or a transition opens a
// menu: breakpoints on it, or its sub-chart.

import { $$, button, role } from "../dom.js";
import { openMenu } from "./menu.js";

// Room left around an active state scrolled into view, CSS pixels.
const REVEAL_MARGIN_PX = 24;
// The smallest a label may be drawn, in CSS pixels: "fit to width" shrinks a picture no further
// (a quarter pixel to spare: the page's layout rounds the picture's width).
const MIN_LABEL_PX = 11.25;

export class DiagramView {
  // link: the SessionLink; say(text, isError): the page's status line;
  // onLoaded(): called when a picture is in place (the coverage colours it);
  // moreItems(el, chart): menu items others add to a click on `el` (the coverage's suggestions).
  constructor(link, say, onLoaded, moreItems = () => []) {
    this.link = link;
    this.say = say;
    this.onLoaded = onLoaded;
    this.moreItems = moreItems;
    this.charts = {};     // name -> chart description (states, transitions, subcharts)
    this.chart = null;    // the chart shown
    this.view = "overview";
    this.opened = [];     // sub-charts open in place in the overview
    this.active = {};     // chart -> Set of active state ids
    this.taken = {};      // chart -> {index: count}
    this.loads = 0;       // pictures asked for: only the last one asked is shown
    this.box = role("diagram");
  }

  // The session's charts (its "session" message).
  setCharts(charts) {
    this.charts = Object.fromEntries(charts.map((c) => [c.name, c]));
  }

  // Show chart `name`: its overview (or its one picture) when it was not shown already.
  show(name) {
    const chart = this.charts[name];
    if (this.chart !== name) {
      this.chart = name;
      this.view = chart.subcharts.length ? "overview" : "whole";
      this.opened = [];
      this.loadLegend(name);
    }
    this.drawViewBar();
    this.load();
  }

  setView(view, opened = []) {
    this.view = view;
    this.opened = opened;
    this.drawViewBar();
    this.load();
  }

  // A frame: the active states and the transitions taken (counted; those of this frame flash).
  take(f) {
    if (f.full) this.taken = {};
    this.active = Object.fromEntries(Object.entries(f.active).map(([k, v]) => [k, new Set(v)]));
    for (const [chart, counts] of Object.entries(f.taken || {})) {
      this.taken[chart] = { ...(this.taken[chart] || {}), ...counts };
    }
    this.draw(f.transitions || [], f.full);
  }

  drawViewBar() {
    const chart = this.charts[this.chart];
    const bar = role("view-bar");
    bar.replaceChildren();
    if (!chart.subcharts.length) { bar.append(this.fitButton()); return; }
    const overview = button("Overview", () => this.setView("overview", []));
    overview.title = "all sub-charts closed";
    overview.setAttribute("aria-pressed", String(this.view === "overview" && !this.opened.length));
    bar.append(overview);
    for (const sub of chart.subcharts) {
      const isOpen = this.view === "overview" && this.opened.includes(sub);
      const inPlace = button(`${isOpen ? "▾" : "▸"} ${sub}`, () => {
        const opened = isOpen ? this.opened.filter((x) => x !== sub) : [...this.opened, sub];
        this.setView("overview", opened);
      }, `${isOpen ? "close" : "open"} sub-chart ${sub} in place`);
      inPlace.setAttribute("aria-pressed", String(isOpen));
      const alone = button("⤢", () => this.setView(sub, []), `open sub-chart ${sub} on its own`);
      alone.setAttribute("aria-pressed", String(this.view === sub));
      alone.classList.add("alone");
      const group = document.createElement("span");
      group.className = "sub";
      group.append(inPlace, alone);
      bar.append(group);
    }
    const whole = button("Whole chart", () => this.setView("whole", []));
    whole.title = "every sub-chart open, nested";
    whole.setAttribute("aria-pressed", String(this.view === "whole"));
    bar.append(whole);
    bar.append(this.fitButton());
  }

  fitButton() {
    const box = this.box;
    const fit = button(box.dataset.fit === "true" ? "Actual size" : "Fit to width", () => {
      box.dataset.fit = box.dataset.fit === "true" ? "false" : "true";
      this.drawViewBar();
    }, "zoom the diagram: fit it to the page's width, or draw it at its actual size");
    fit.classList.add("fit");
    return fit;
  }

  async load() {
    const seq = ++this.loads;
    const params = new URLSearchParams({ view: this.view });
    if (this.opened.length) params.set("open", this.opened.join(","));
    const box = this.box;
    box.dataset.loading = "true";
    let text;
    try {
      const res = await fetch(`/api/diagram/${encodeURIComponent(this.chart)}?${params}`);
      text = await res.text();
      if (!res.ok) throw new Error(text);
    } catch (err) {
      if (seq === this.loads) this.say(`diagram: ${err.message}`, true);
      return;
    }
    if (seq !== this.loads) return;  // another picture was asked for meanwhile
    box.innerHTML = text;
    this.readable();
    box.dataset.chart = this.chart;
    box.dataset.view = this.view + (this.opened.length ? "+" + this.opened.join("+") : "");
    const onClick = (e) => this.onClick(e);
    for (const el of $$("[data-state], [data-transition], [data-stub]", box)) {
      el.addEventListener("click", onClick);
      el.addEventListener("contextmenu", onClick);
      el.addEventListener("keydown", (e) => { if (e.key === "Enter" || e.key === " ") onClick(e); });
    }
    for (const el of $$("[data-transition]", box)) {  // a flash is cleared when its animation has run
      el.addEventListener("animationend", () => el.classList.remove("flash"));
    }
    for (const el of $$("[data-subchart]", box)) {
      el.addEventListener("dblclick", (e) => {
        e.preventDefault();
        this.setView("overview", [...new Set([...this.opened, el.dataset.subchart])]);
      });
    }
    this.draw([], true);
    this.reveal();
    this.onLoaded();
    delete box.dataset.loading;
  }

  // Mark the active states and the transitions' counts; flash `transitions` (all: recount every edge).
  draw(transitions, all) {
    const box = this.box;
    if (box.dataset.chart !== this.chart) return;
    const active = this.active[this.chart] || new Set();
    for (const el of $$("[data-state-id]", box)) {
      const on = active.has(el.dataset.stateId) ? "true" : "false";
      if (el.dataset.active !== on) el.dataset.active = on;
    }
    const taken = this.taken[this.chart] || {};
    const flashed = new Set(transitions.filter((t) => t.chart === this.chart && t.index !== null).map((t) => t.index));
    for (const el of $$("[data-index]", box)) {
      const indices = el.dataset.index.split(" ").map(Number);
      if (all || indices.some((i) => String(i) in taken || flashed.has(i))) {
        const count = indices.reduce((sum, i) => sum + (taken[i] || 0), 0);
        el.dataset.takenCount = String(count);
        drawCount(el, count);
      }
      if (indices.some((i) => flashed.has(i))) {
        el.classList.remove("flash");
        void el.getBoundingClientRect();  // restart the animation
        el.classList.add("flash");
      }
    }
  }

  readable() {
    fitReadable(this.box);
  }

  // A picture larger than its box opens scrolled to its first active state, not to an empty corner:
  // as little as it takes to show that state whole, so the picture's title (top left) stays in view
  // whenever the state and the title fit in the box together.
  reveal() {
    const box = this.box;
    const active = box.querySelector('[data-state-id][data-active="true"]:not(.cluster)')
      || box.querySelector('[data-state-id][data-active="true"]');
    if (!active || (box.scrollWidth <= box.clientWidth && box.scrollHeight <= box.clientHeight)) return;
    const a = active.getBoundingClientRect();
    const b = box.getBoundingClientRect();
    box.scrollLeft = nearestScroll(box.scrollLeft, a.left - b.left - box.clientLeft, a.width, box.clientWidth);
    box.scrollTop = nearestScroll(box.scrollTop, a.top - b.top - box.clientTop, a.height, box.clientHeight);
  }

  // The legend of what the chart's pictures use: once on the page (collapsible), not in every picture.
  async loadLegend(name) {
    const box = role("diagram-legend");
    if (!box) return;
    try {
      const res = await fetch(`/api/diagram/${encodeURIComponent(name)}?view=legend`);
      if (res.ok && this.chart === name) box.innerHTML = await res.text();
    } catch (err) {
      // the legend is a help only: the diagram's own load reports a broken link
    }
  }

  // What a clicked state or transition does, its actions' whole texts (a picture may summarise them with "…").
  showDetail(el) {
    const panel = role("diagram-detail");
    if (!panel) return;
    panel.textContent = el.dataset.detail || "";
    panel.hidden = !el.dataset.detail;
  }

  // A click on a state, a transition or a stub: its menu (breakpoints, sub-charts).  A breakpoint's
  // item names the state or transition as the breakpoint list and `ttt-sm debug` name it (its spec:
  // `enter DriveInit1.turn_back`, `transition DriveInit1 turn_fwd->turn_back`), not by its path.
  onClick(event) {
    event.preventDefault();
    event.stopPropagation();
    const el = event.currentTarget;
    this.showDetail(el);
    const chart = this.chart;
    const items = [];
    const addBreak = (label, spec) => items.push([label, () => this.link.send({ type: "break", spec }), spec]);
    if (el.dataset.stub) {
      const [, ...path] = el.dataset.stub.split(".");
      const id = path[path.length - 1];
      items.push([`Open the picture of ${el.dataset.stub}`, () => this.setView(el.dataset.view, [])]);
      addBreak(`Break on entering ${chart}.${id}`, `enter ${chart}.${id}`);
    } else if (el.dataset.stateId) {
      const id = el.dataset.stateId;
      if (el.dataset.subchart) {
        items.push([`Open ${id} in place`, () => this.setView("overview", [...new Set([...this.opened, id])])]);
        items.push([`Open ${id} on its own`, () => this.setView(id, [])]);
      }
      addBreak(`Break on entering ${chart}.${id}`, `enter ${chart}.${id}`);
      addBreak(`Break on leaving ${chart}.${id}`, `exit ${chart}.${id}`);
    } else if (el.dataset.transition) {
      for (const name of el.dataset.transition.split(" ")) {
        const arrow = name.slice(chart.length + 1);
        addBreak(`Break when ${chart} ${arrow} is taken`, `transition ${chart} ${arrow}`);
      }
      items.push(...this.moreItems(el, chart));
    }
    openMenu(items, event);
  }
}

const SVG_NS = "http://www.w3.org/2000/svg";

// The picture in `box` fits the page's width only as far as its smallest label stays MIN_LABEL_PX
// high: a large chart is then wider than the page, and the box scrolls (the cockpit, the lab page),
// its title pinned at the left.
export function fitReadable(box) {
  const svg = box.querySelector("svg");
  const view = svg && svg.viewBox.baseVal;
  if (!view || !view.width) return;
  pinTitle(box, svg);
  const sizes = [...svg.querySelectorAll("text")]
    .map((t) => parseFloat(t.getAttribute("font-size"))).filter((x) => x > 0);
  if (!sizes.length) return;
  svg.style.minWidth = `${Math.ceil((view.width * MIN_LABEL_PX) / Math.min(...sizes))}px`;
}

// The picture's title (Graphviz's graph label, drawn at its top left) as a caption above it that
// stays in view while a picture wider than the box is scrolled sideways.
function pinTitle(box, svg) {
  const title = svg.querySelector("g.graph > text");
  if (!title) return;
  const caption = document.createElement("div");
  caption.className = "diagram-title";
  caption.dataset.role = "diagram-title";
  caption.textContent = title.textContent;
  title.remove();
  box.prepend(caption);
}

// The scroll offset nearest the start (0) that shows a thing `size` long, now at `at` from the view's
// start (scrolled by `scroll`), whole with REVEAL_MARGIN_PX around it in a view `view` long; a thing
// longer than the view shows its start.
function nearestScroll(scroll, at, size, view) {
  const start = scroll + at - REVEAL_MARGIN_PX;
  const end = scroll + at + size + REVEAL_MARGIN_PX;
  return Math.max(0, Math.min(start, end - view));
}

// How often an edge was taken, drawn beside its label ("×3"; at the middle of an edge without one).
function drawCount(edge, count) {
  let mark = edge.querySelector(":scope > text.taken-count");
  if (!count) {
    if (mark) mark.remove();
    return;
  }
  if (!mark) {
    mark = document.createElementNS(SVG_NS, "text");
    mark.setAttribute("class", "taken-count");
    const label = edge.querySelector("text");
    const path = edge.querySelector("path");
    if (label) {
      const b = label.getBBox();
      mark.setAttribute("x", String(b.x + b.width + 4));
      mark.setAttribute("y", label.getAttribute("y"));
      mark.setAttribute("font-size", label.getAttribute("font-size") || "9");
    } else if (path) {
      const p = path.getPointAtLength(path.getTotalLength() / 2);
      mark.setAttribute("x", String(p.x + 4));
      mark.setAttribute("y", String(p.y));
      mark.setAttribute("font-size", "9");
    }
    mark.setAttribute("font-family", "Helvetica,sans-Serif");
    edge.append(mark);
  }
  mark.textContent = `×${count}`;
}
