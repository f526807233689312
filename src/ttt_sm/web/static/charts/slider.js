// The time slider: back to any chart tick the run has passed (a replay from power-on, same seed,
// same inputs), or forward as far as it has been.  The inputs given after that tick are kept and
// applied again when the run reaches them, or dropped when "drop my later inputs" is ticked.

import { role } from "../dom.js";

export class TimeSlider {
  constructor(link) {
    this.link = link;
    this.tick = 0;
    this.furthest = 0;
    const slider = role("slider");
    const form = role("slider-form");
    const replay = () => {
      form.dataset.dragging = "false";
      link.send({ type: "replay", tick: Number(slider.value), drop: role("replay-drop").checked });
    };
    slider.addEventListener("input", (e) => {
      form.dataset.dragging = "true";
      role("slider-value").textContent = e.target.value;
    });
    form.addEventListener("submit", (e) => {
      e.preventDefault();
      replay();
    });
    slider.addEventListener("change", replay);
  }

  take(f) {
    this.tick = f.tick;
    this.furthest = f.furthest_tick;
    this.draw();
  }

  // The slider's range is the run so far; its knob follows the tick unless a person holds it.
  draw() {
    const slider = role("slider");
    slider.max = String(this.furthest);
    if (document.activeElement !== slider && role("slider-form").dataset.dragging !== "true") {
      slider.value = String(this.tick);
      role("slider-value").textContent = String(this.tick);
    }
  }
}
