// The pages' few DOM helpers, one copy for every page: find an element, make a button or a cell.
//
// An element a script draws into or reads is named by its data-role attribute
// (<p data-role="status">), never by its place in the page: role("status").

// The first element that matches a CSS selector (under `root`), or null.
export const $ = (sel, root = document) => root.querySelector(sel);

// Every element that matches a CSS selector (under `root`), as an array.
export const $$ = (sel, root = document) => Array.from(root.querySelectorAll(sel));

// The element whose data-role is `name` (under `root`).
export const role = (name, root = document) => $(`[data-role="${name}"]`, root);

// A <button type="button"> that calls onClick; `label`, when given, is its accessible name and tooltip.
export function button(text, onClick, label) {
  const b = document.createElement("button");
  b.type = "button";
  b.textContent = text;
  if (label) b.setAttribute("aria-label", label);
  if (label) b.title = label;
  b.addEventListener("click", (e) => { e.preventDefault(); onClick(e); });
  return b;
}

// A table cell <td> holding `text`, of class `cls` when given.
export function cell(text, cls) {
  const td = document.createElement("td");
  td.textContent = text;
  if (cls) td.className = cls;
  return td;
}

// Whether `el` shows something other than `value` (compared as JSON with its data-key), noting `value` as
// what it shows: a list is drawn again only when what it lists has changed.
export function showsOther(el, value) {
  const key = JSON.stringify(value);
  if (el.dataset.key === key) return false;
  el.dataset.key = key;
  return true;
}

// Handle the submit of the form whose data-role is `name` here, as handle(form): the page stays.
export function onSubmit(name, handle) {
  role(name).addEventListener("submit", (e) => { e.preventDefault(); handle(e.target); });
}

// Draw list `name` again, an <li> from item(x) for each of `items` (when there are none: one <li class="none">
// saying `none`, if given), unless it already shows them (showsOther).
export function drawList(name, items, item, none) {
  const list = role(name);
  if (!showsOther(list, items)) return;
  list.replaceChildren(...items.map(item));
  if (!items.length && none) {
    const li = document.createElement("li");
    li.className = "none";
    li.textContent = none;
    list.append(li);
  }
}

// Replace the options of a <select> by `options`, [value, text] pairs.
export function fillSelect(select, options) {
  select.replaceChildren(...options.map(([value, text]) => new Option(text, value)));
}
