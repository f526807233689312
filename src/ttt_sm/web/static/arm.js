// The arm drawn live: a side view (global y-z) and a top view (global x-y, over the board's ink).
//
// A view, as every page: each frame's "arm" part (ttt_sm.web.arm_view) carries the
// points along the arm that the server's forward kinematics gave for the twin's true
// joint angles, in mm, and the sponge's pad; this draws them and computes no kinematics.
// The scene (board, field, link lengths) comes once in the session's info ("arm").
// In both views one SVG user unit is one millimetre: top view (x, -y), side view (y, -z).

const SVG = "http://www.w3.org/2000/svg";

function el(name, attrs, parent) {
  const e = document.createElementNS(SVG, name);
  for (const [k, v] of Object.entries(attrs || {})) e.setAttribute(k, v);
  if (parent) parent.appendChild(e);
  return e;
}

// The parts of one projection: which two coordinates, how the second is flipped.
const VIEWS = {
  top: { label: "the arm from above", a: 0, b: 1 },   // x right, y up
  side: { label: "the arm from the side", a: 1, b: 2 }, // y right, z up
};

export class ArmViews {
  // host: an element to draw into; scene: the session info's "arm" part.
  constructor(host, scene) {
    this.host = host;
    this.scene = scene;
    this.views = {};
    host.innerHTML = "";
    for (const name of ["side", "top"]) this.views[name] = this.build(name);
    this.ink = new InkPicture(this.views.top.ink);
    this.note = document.createElement("p");
    this.note.className = "arm-note";
    this.note.dataset.role = "arm-note";
    host.appendChild(this.note);
  }

  build(name) {
    const s = this.scene, v = VIEWS[name];
    const [bx0, bx1, by0, by1] = s.board;
    const L1 = s.links[0];
    const figure = document.createElement("figure");
    figure.className = `arm-view arm-${name}`;
    // What the arm reaches in a game (and the power-on pose below the board's plane), mm.
    let box;
    if (name === "top") {  // x beyond the board's sides, y from behind the column to the board's far edge
      const x0 = bx0 - 150, x1 = bx1 + 150, y0 = -130, y1 = by1 + 30;
      box = [x0, -y1, x1 - x0, y1 - y0];
    } else {  // y from behind the column to beyond the board, z from below the board to above the shoulder
      const y0 = -200, y1 = by1 + 50, z0 = -230, z1 = L1 + 200;
      box = [y0, -z1, y1 - y0, z1 - z0];
    }
    const svg = el("svg", { viewBox: box.join(" "), role: "img", "aria-label": v.label,
                            "data-role": `arm-${name}`, preserveAspectRatio: "xMidYMid meet" });
    figure.appendChild(svg);
    const caption = document.createElement("figcaption");
    caption.textContent = name === "top" ? "from above (x right, y away from the robot), with the ink"
                                         : "from the side (y right, z up)";
    figure.appendChild(caption);
    this.host.appendChild(figure);
    const parts = { svg };
    if (name === "top") {
      el("rect", { x: bx0, y: -by1, width: bx1 - bx0, height: by1 - by0, class: "board" }, svg);
      parts.ink = el("image", { x: bx0, y: -by1, width: bx1 - bx0, height: by1 - by0,
                                preserveAspectRatio: "none", class: "ink", "data-role": "arm-ink" }, svg);
      const [fx0, fx1, fy0, fy1] = s.field;
      const grid = el("g", { class: "field" }, svg);
      for (let i = 0; i <= s.cells; i++) {
        const x = fx0 + (fx1 - fx0) * i / s.cells, y = fy0 + (fy1 - fy0) * i / s.cells;
        el("line", { x1: x, y1: -fy0, x2: x, y2: -fy1 }, grid);
        el("line", { x1: fx0, y1: -y, x2: fx1, y2: -y }, grid);
      }
    } else {
      el("line", { x1: box[0], y1: -s.surface_z, x2: box[0] + box[2], y2: -s.surface_z, class: "ground" }, svg);
      el("rect", { x: by0, y: -s.surface_z, width: by1 - by0, height: 12, class: "board" }, svg);
    }
    parts.sponge = el("polygon", { class: "sponge", "data-role": "sponge" }, svg);
    parts.links = el("polyline", { class: "links" }, svg);
    parts.pen = el("line", { class: "pen", "data-role": "pen" }, svg);
    parts.joints = ["shoulder", "elbow", "wrist"].map((j) => el("circle", { r: 6, class: `joint ${j}` }, svg));
    parts.tip = el("circle", { r: 4, class: "tip", "data-role": "tip" }, svg);
    return parts;
  }

  // One point [x, y, z] mm in a view's user units.
  at(name, p) {
    const v = VIEWS[name];
    return [p[v.a], -p[v.b]];
  }

  draw(arm) {
    if (!arm) {
      this.note.textContent = "The arm is no simulation: its true joint angles are not known, nothing is drawn.";
      return;
    }
    const q = arm.q_deg.map((a) => a.toFixed(1));
    this.note.textContent = `q1 ${q[0]}°, q2 ${q[1]}°, q3 ${q[2]}°, q4 ${q[3]}°; ` +
      `the ${arm.tool} in use` + (arm.touching ? `, the ${arm.touching} on the board` : "");
    this.host.dataset.tool = arm.tool;
    this.host.dataset.touching = arm.touching || "";
    const P = arm.points;
    for (const [name, parts] of Object.entries(this.views)) {
      const pt = (p) => this.at(name, p);
      const chain = [P.foot, P.shoulder, P.elbow, P.wrist].map(pt);
      parts.links.setAttribute("points", chain.map((c) => c.join(",")).join(" "));
      const [wx, wy] = pt(P.wrist), [tx, ty] = pt(P.tip);
      parts.pen.setAttribute("x1", wx); parts.pen.setAttribute("y1", wy);
      parts.pen.setAttribute("x2", tx); parts.pen.setAttribute("y2", ty);
      parts.tip.setAttribute("cx", tx); parts.tip.setAttribute("cy", ty);
      ["shoulder", "elbow", "wrist"].forEach((j, i) => {
        const [cx, cy] = pt(P[j]);
        parts.joints[i].setAttribute("cx", cx); parts.joints[i].setAttribute("cy", cy);
      });
      parts.sponge.setAttribute("points", arm.sponge.map((c) => pt(c).join(",")).join(" "));
      for (const part of [parts.pen, parts.tip, parts.sponge]) {
        const tool = part === parts.sponge ? "sponge" : "pen";
        part.dataset.inUse = arm.tool === tool ? "true" : "false";
        part.dataset.touching = arm.touching === tool ? "true" : "false";
      }
    }
    this.ink.show(arm.ink);
  }

  // A full frame (a page that joins, a replay): the ink is fetched again whatever its key.
  resync() { this.ink.resync(); }
}

// The whiteboard's ink seen from above (/api/arm/ink.png) in an SVG <image>: fetched again when a frame's
// ink key changes; one request at a time, the latest key wins.
export class InkPicture {
  constructor(image) {
    this.image = image;
    this.key = null;
    this.busy = false;
    this.again = false;
    this.url = null;
  }

  // A frame's arm.ink: the picture is fetched when it is not the one shown.
  show(ink) {
    const key = ink.join(":");
    if (key === this.key) return;
    this.key = key;
    this.load();
  }

  resync() { this.key = null; }

  async load() {
    if (this.busy) { this.again = true; return; }
    this.busy = true;
    const key = this.key;
    try {
      const response = await fetch(`/api/arm/ink.png?k=${encodeURIComponent(key)}`, { cache: "no-store" });
      if (response.ok) {
        const url = URL.createObjectURL(await response.blob());
        this.image.setAttribute("href", url);
        this.image.dataset.key = key;
        if (this.url) URL.revokeObjectURL(this.url);
        this.url = url;
      }
    } catch (e) {
      // the server went away: the next frame (if any) asks again
    } finally {
      this.busy = false;
      if (this.again) { this.again = false; setTimeout(() => this.load(), 150); }
    }
  }
}
