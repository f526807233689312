// The Tic-tac-toe page (/game): the thesis' fig. 3.35 over the session's game.
//
// A view, as every page: the buttons send commands (run, game_symbol, game_cell,
// game_play, game_stop; declared and handled by ttt_sm.web.commands.game)
// and each frame's "game" part (sent when it changed) is drawn.  A click on a cell
// asks the simulated hand to draw there; the board shows what the game has read
// through the camera, never what the page guessed.

import { ArmViews } from "./arm.js";
import { $, role } from "./dom.js";
import { drawCommon, pageHeader, sayReply as say } from "./page.js";
import { SessionLink } from "./session.js";

const state = { game: null, photos: -1, arm: null };

// Fill `host` with the field's 5 rows (role="row", laid out by the host's grid), each of 5 cells made by
// cell(row, column), both counted from 1.
function fieldRows(host, cell) {
  for (let r = 1; r <= 5; r++) {
    const row = document.createElement("div");
    row.setAttribute("role", "row");
    row.style.display = "contents";
    for (let c = 1; c <= 5; c++) row.appendChild(cell(r, c));
    host.appendChild(row);
  }
}

function cellButtons() {
  fieldRows(role("board"), (r, c) => {
    const b = document.createElement("button");
    b.type = "button";
    b.setAttribute("role", "gridcell");
    b.setAttribute("aria-label", `row ${r}, column ${c}`);
    b.dataset.row = r;
    b.dataset.column = c;
    b.addEventListener("click", () => link.send({ type: "game_cell", row: r, column: c }));
    return b;
  });
  makeReading(role("reading"));
  makeReading(role("feed-reading"));
}

// A 5x5 table of what a detector read: each cell's ink percentage and symbol.
function makeReading(reading) {
  fieldRows(reading, (r, c) => {
    const cell = document.createElement("div");
    cell.setAttribute("role", "cell");
    cell.dataset.row = r;
    cell.dataset.column = c;
    cell.textContent = "–";
    return cell;
  });
}

function drawReading(reading, percentages, read) {
  for (const cell of reading.querySelectorAll('[role="cell"]')) {
    const i = 5 * (cell.dataset.row - 1) + (cell.dataset.column - 1);
    const pct = percentages[i];
    const sym = read ? read[i] : "?";
    cell.innerHTML = "";
    const b = document.createElement("b");
    b.textContent = sym === "." ? "" : sym;
    cell.append(b, `${pct.toFixed(1)} %`);
    cell.dataset.occupied = sym !== "." ? "true" : "false";
    cell.dataset.read = sym;
    cell.title = `row ${cell.dataset.row}, column ${cell.dataset.column}: ${pct.toFixed(1)} % ink, read ${sym === "." ? "empty" : sym}`;
  }
}

// The camera outside the simulation (ttt-sm gui --camera): its newest picture and what was read in it.
function drawCamera(c) {
  const panel = role("feed-panel");
  panel.hidden = !c;
  if (!c) return;
  role("feed-source").textContent = `— ${c.kind} ${c.name}: ${c.source}`;
  const status = role("feed-status");
  status.textContent = c.error || (c.percentages ? `grab ${c.n}: read` : "");
  status.dataset.error = c.error ? "true" : "false";
  if (c.percentages) drawReading(role("feed-reading"), c.percentages, c.read);
  const img = role("feed-photo");
  if (c.has_image && img.dataset.grab !== String(c.n)) {
    img.src = `/api/camera/frame.png?n=${c.n}`;
    img.alt = `the camera's picture: ${c.source}`;
    img.dataset.grab = c.n;
    img.dataset.source = c.source;
    img.hidden = false;
  }
  if (!c.has_image) img.hidden = true;
}

function drawGame(g) {
  state.game = g;
  if (!g) {
    role("text-box2").textContent = "This session plays no game: start it with `ttt-sm gui --game`.";
    return;
  }
  role("text-box1").textContent = g.text_box1;
  role("text-box2").textContent = g.message;
  role("robot-symbol").textContent = g.robot_symbol;
  role("person-symbol").textContent = g.person_symbol;
  role("legend-robot").textContent = g.robot_symbol;
  role("legend-person").textContent = g.person_symbol;
  role("legend-drawn").textContent = g.person_symbol;
  // who won stays shown until a new game (Text box2 moves on to erasing and turning off)
  role("result").textContent = g.result ? `Result: ${g.result}.` : "";
  // What the game told the person besides Text box2's messages (the robot's move, a refused view).
  const told = g.told.length ? g.told[g.told.length - 1] : "";
  const toldBox = role("told");
  toldBox.textContent = g.error ? `${told} (the game cannot go on: ${g.error})` : told;
  toldBox.dataset.error = g.error ? "true" : "false";
  const symbolButton = $('[data-cmd="symbol"]');
  symbolButton.disabled = g.symbol_locked || !g.plays_here;
  symbolButton.dataset.locked = g.symbol_locked ? "true" : "false";
  const drawn = new Set(g.drawn.map(([r, c]) => `${r},${c}`));
  for (const b of role("board").querySelectorAll("button")) {
    const i = 5 * (b.dataset.row - 1) + (b.dataset.column - 1);
    const read = g.board[i], there = g.truth[i];
    let by = "", shown = "";
    if (read !== ".") {
      by = read === g.robot_symbol && there === g.robot_symbol ? "robot" : "person";
      shown = read;
    }
    if (there !== "." && (read === "." || drawn.has(`${b.dataset.row},${b.dataset.column}`))) {
      by = read === "." ? "drawn" : by;
      shown = read === "." ? there : read;
    }
    b.textContent = shown;
    b.dataset.by = by;
    b.disabled = !(g.plays_here && g.awaiting === "draw") || there !== ".";  // the hand cannot wipe a mark
    b.title = by === "drawn" ? "drawn; the camera reads it when you click Play" : "";
  }
  drawWinningLine(g.winning_line);
  $('[data-cmd="play"]').disabled = !(g.plays_here && g.awaiting);
  const engine = role("engine");
  engine.value = g.engine;
  engine.disabled = g.engine_locked || !g.plays_here;
  $('[data-cmd="new"]').disabled = !(g.plays_here && g.can_start_over);
  role("record").textContent = g.record
    ? `The game's record: ${g.record}` + (g.record_ended ? ` (ended: ${g.record_ended})` : " (written as the game goes)")
    : "This game's record is kept in memory only.";
  $('[data-cmd="stop"]').disabled = !g.plays_here || g.ended;
  if (g.photos !== state.photos) {
    state.photos = g.photos;
    const img = role("photo");
    if (g.photos > 0) {
      img.src = `/api/game/photo.png?n=${g.photos}`;
      img.alt = `the board as the simulated camera sees it, photo ${g.photos}`;
      img.hidden = false;
      img.dataset.photo = g.photos;
      role("photo-count").textContent = `photo ${g.photos}, taken after the last move`;
    }
  }
  if (g.percentages) drawReading(role("reading"), g.percentages, g.read);
}

// The four in a row the game ended on: its cells marked (data-win) and a line drawn through them.
function drawWinningLine(line) {
  const board = role("board");
  const win = new Set((line || []).map(([r, c]) => `${r},${c}`));
  for (const b of board.querySelectorAll("button")) {
    const on = win.has(`${b.dataset.row},${b.dataset.column}`);
    b.dataset.win = on ? "true" : "false";
    if (on) b.title = "part of the winning four in a row";
  }
  board.dataset.winningLine = line ? line.map(([r, c]) => `${r},${c}`).join(" ") : "";
  let svg = board.querySelector("svg.win-line");
  if (!line) {
    if (svg) svg.remove();
    return;
  }
  if (!svg) {
    svg = document.createElementNS("http://www.w3.org/2000/svg", "svg");
    svg.setAttribute("class", "win-line");
    svg.setAttribute("viewBox", "0 0 5 5");
    svg.setAttribute("preserveAspectRatio", "none");
    svg.setAttribute("aria-hidden", "true");
    svg.appendChild(document.createElementNS("http://www.w3.org/2000/svg", "line"));
    board.appendChild(svg);
  }
  const [[r0, c0], [r1, c1]] = [line[0], line[line.length - 1]];
  const l = svg.firstChild;
  l.setAttribute("x1", c0 - 0.5); l.setAttribute("y1", r0 - 0.5);
  l.setAttribute("x2", c1 - 0.5); l.setAttribute("y2", r1 - 0.5);
}

function drawFrame(f) {
  drawCommon(f);
  if ("game" in f) drawGame(f.game);
  if ("camera" in f) drawCamera(f.camera);
  if (state.arm) {
    if (f.full) state.arm.resync();
    if ("arm" in f) state.arm.draw(f.arm);
  }
  if (f.stop && f.stop.kind === "game") say(f.stop.text, true);
  if (f.error) say(f.error, true);
}

function onMessage(m) {
  if (m.type === "session") {
    state.arm = new ArmViews(role("arm"), m.info.arm);
  } else if (m.type === "frame") {
    drawFrame(m);
    link.ack(m.seq);
  } else if (m.type === "reply") {
    say(m.text || "", false);
  } else if (m.type === "error") {
    say(m.error.replace(/^game_\w+: /, ""), true);  // the page's words, not the protocol's command name
    if (m.command === "game_engine" && state.game) role("engine").value = state.game.engine;
  }
}

const link = new SessionLink(onMessage, (status) => {
  if (status !== "connected") role("mode").textContent = status;
});

pageHeader(link);
cellButtons();
$('[data-cmd="run"]').addEventListener("click", () => link.send({ type: "run" }));
$('[data-cmd="symbol"]').addEventListener("click", () => {
  const now = state.game ? state.game.robot_symbol : "O";
  link.send({ type: "game_symbol", symbol: now === "X" ? "O" : "X" });
});
$('[data-cmd="play"]').addEventListener("click", () => link.send({ type: "game_play" }));
$('[data-cmd="stop"]').addEventListener("click", () => link.send({ type: "game_stop" }));
role("engine").addEventListener("change", (e) => link.send({ type: "game_engine", engine: e.target.value }));
$('[data-cmd="new"]').addEventListener("click", () => link.send({ type: "game_new" }));
link.connect();
