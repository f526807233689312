// The menu a click on the diagram opens: what can be done with that state or transition.

import { button, role } from "../dom.js";

// Open the menu where `event` happened: `items` are [label, action] or [label, action, tooltip]
// (a breakpoint's: the spec it adds, as the breakpoint list shows it), then Cancel.
export function openMenu(items, event) {
  const menu = role("menu");
  menu.replaceChildren();
  for (const [label, action, tip] of items) {
    const b = button(label, () => { closeMenu(); action(); });
    b.setAttribute("role", "menuitem");
    if (tip) b.title = `adds the breakpoint: ${tip}`;
    menu.append(b);
  }
  const cancel = button("Cancel", closeMenu);
  cancel.setAttribute("role", "menuitem");
  menu.append(cancel);
  const r = event.currentTarget.getBoundingClientRect();
  const x = event.clientX || r.left + r.width / 2;
  const y = event.clientY || r.top + r.height / 2;
  menu.style.left = `${Math.min(x + window.scrollX, window.scrollX + window.innerWidth - 320)}px`;
  menu.style.top = `${y + window.scrollY}px`;
  menu.hidden = false;
  menu.querySelector("button").focus();
}

export function closeMenu() {
  role("menu").hidden = true;
}

document.addEventListener("click", (e) => {
  if (!role("menu").contains(e.target)) closeMenu();
});
document.addEventListener("keydown", (e) => { if (e.key === "Escape") closeMenu(); });
