// Render Mermaid diagrams in this page and report what a reader sees in each.
//
// Load after node_modules/mermaid/dist/mermaid.min.js; then
// `await renderMermaid(["stateDiagram-v2 ...", ...])` returns, per diagram, either
// {error: "Parse error on line 3 ..."} or {boxes, edgeLabels}: `boxes` are the drawn
// states, composite states and notes, each with its label lines in drawing order
// (a state's title first) and its rectangle on the page (`rect`: left, top, right,
// bottom), so that a test can tell which composite state a box is drawn in;
// `edgeLabels` are the texts drawn on transitions.  Only text with a size on the page
// counts: what Mermaid laid out but did not draw is left out.

function drawnTexts(root) {
  const texts = [];
  for (const label of root.querySelectorAll("foreignObject, text")) {
    const box = label.getBoundingClientRect();
    if (box.width <= 0 || box.height <= 0) continue;
    const text = label.tagName === "text"
      ? [...label.querySelectorAll("tspan")].map((t) => t.textContent).join(" ") || label.textContent
      : [...label.children].map((html) => html.innerText).join("\n");
    if (text.trim()) texts.push(text.trim());
  }
  return texts;
}

function rectOf(element) {
  const outline = element.classList.contains("statediagram-cluster")
    ? element.querySelector("rect.outer") || element : element;
  const { left, top, right, bottom } = outline.getBoundingClientRect();
  return { left, top, right, bottom };
}

function boxKind(element) {
  if (element.classList.contains("statediagram-cluster")) return "composite";
  if (element.classList.contains("statediagram-note")) return "note";
  return "state";
}

window.renderMermaid = async function renderMermaid(diagrams) {
  mermaid.initialize({ startOnLoad: false });
  const results = [];
  for (const [i, code] of diagrams.entries()) {
    const host = document.createElement("div");
    document.body.appendChild(host);
    try {
      await mermaid.parse(code);
      const { svg } = await mermaid.render(`diagram${i}`, code);
      host.innerHTML = svg;
    } catch (error) {
      results.push({ error: String((error && error.message) || error) });
      continue;
    }
    const boxes = [...host.querySelectorAll("g.node, g.statediagram-cluster")].map((element) => ({
      kind: boxKind(element),
      id: element.getAttribute("data-id") || element.id,
      rect: rectOf(element),
      texts: drawnTexts(element.classList.contains("statediagram-cluster")
        ? element.querySelector(".cluster-label") || element : element),
    }));
    const edgeLabels = [...host.querySelectorAll("g.edgeLabel")].flatMap(drawnTexts);
    results.push({ boxes, edgeLabels });
  }
  return results;
};
