// The kinematics pages' plots on a canvas (/kinematics, /kinematics/motion): a framed x-y plot with
// ticks, axis labels and a title, and a legend box.  Units go in the labels; every plot has a legend.

// An x-y plot frame with ticks, labels and a title; returns the data -> pixel maps.
export function frame(ctx, box, xr, yr, o) {
  const [bx, by, bw, bh] = box;
  let [x0, x1] = xr, [y0, y1] = yr;
  if (o.equal) {  // one metre is as long across as up
    const s = Math.min(bw / (x1 - x0), bh / (y1 - y0));
    const cx = (x0 + x1) / 2, cy = (y0 + y1) / 2;
    x0 = cx - bw / s / 2; x1 = cx + bw / s / 2; y0 = cy - bh / s / 2; y1 = cy + bh / s / 2;
  }
  const ly = (v) => (o.logy ? Math.log10(v) : v);
  const X = (v) => bx + ((v - x0) / (x1 - x0)) * bw;
  const Y = (v) => by + bh - ((ly(v) - ly(y0)) / (ly(y1) - ly(y0))) * bh;
  ctx.save();
  ctx.strokeStyle = "#444"; ctx.lineWidth = 1; ctx.strokeRect(bx, by, bw, bh);
  ctx.fillStyle = "#111"; ctx.font = "11px sans-serif"; ctx.textAlign = "center";
  for (const t of ticks(x0, x1)) {
    ctx.fillText(fmt(t), X(t), by + bh + 13);
    ctx.beginPath(); ctx.moveTo(X(t), by + bh); ctx.lineTo(X(t), by + bh + 4); ctx.stroke();
  }
  ctx.textAlign = "right";
  const yt = o.logy ? logTicks(y0, y1) : ticks(y0, y1);
  for (const t of yt) {
    ctx.fillText(o.logy ? `1e${Math.round(Math.log10(t))}` : fmt(t), bx - 5, Y(t) + 4);
    ctx.beginPath(); ctx.moveTo(bx - 3, Y(t)); ctx.lineTo(bx, Y(t)); ctx.stroke();
  }
  ctx.textAlign = "center"; ctx.font = "12px sans-serif";
  ctx.fillText(o.xlabel, bx + bw / 2, by + bh + 30);
  ctx.font = "bold 12px sans-serif";
  ctx.fillText(o.title, bx + bw / 2, by - 6);
  ctx.font = "12px sans-serif";
  ctx.translate(bx - 42, by + bh / 2); ctx.rotate(-Math.PI / 2); ctx.fillText(o.ylabel, 0, 0);
  ctx.restore();
  return { X, Y, clip: () => { ctx.save(); ctx.beginPath(); ctx.rect(bx, by, bw, bh); ctx.clip(); } };
}

export function ticks(a, b) {
  const step = Math.pow(10, Math.floor(Math.log10((b - a) / 4)));
  const s = (b - a) / step > 20 ? step * 5 : (b - a) / step > 8 ? step * 2 : step;
  const out = [];
  for (let t = Math.ceil(a / s) * s; t <= b + 1e-12; t += s) out.push(Math.abs(t) < s / 1e6 ? 0 : t);
  return out;
}
export function logTicks(a, b) {
  const out = [];
  const step = Math.max(1, Math.ceil((Math.log10(b) - Math.log10(a)) / 8));
  for (let e = Math.ceil(Math.log10(a)); e <= Math.log10(b); e += step) out.push(Math.pow(10, e));
  return out;
}
export const fmt = (v) => (Math.abs(v) >= 10 ? v.toFixed(0) : +v.toFixed(3) + "");

// A legend box: items [[colour, label, kind]], kind "box" | "line" | "mark".
export function legend(ctx, x, y, items) {
  ctx.save();
  ctx.font = "11px sans-serif"; ctx.textAlign = "left";
  const w = Math.max(...items.map(([, l]) => ctx.measureText(l).width)) + 30;
  ctx.fillStyle = "rgba(255,255,255,0.9)"; ctx.strokeStyle = "#999";
  ctx.fillRect(x, y, w, items.length * 15 + 6); ctx.strokeRect(x, y, w, items.length * 15 + 6);
  items.forEach(([c, label, kind], i) => {
    const yy = y + 12 + i * 15;
    ctx.strokeStyle = c; ctx.fillStyle = c; ctx.lineWidth = 2;
    if (kind === "line") { ctx.beginPath(); ctx.moveTo(x + 4, yy - 4); ctx.lineTo(x + 22, yy - 4); ctx.stroke(); }
    else if (kind === "mark") { ctx.beginPath(); ctx.arc(x + 13, yy - 4, 4, 0, 7); ctx.fill(); }
    else { ctx.fillRect(x + 5, yy - 9, 16, 10); ctx.strokeStyle = "#999"; ctx.lineWidth = 1; ctx.strokeRect(x + 5, yy - 9, 16, 10); }
    ctx.fillStyle = "#111"; ctx.fillText(label, x + 26, yy);
  });
  ctx.restore();
}

// A rectangle [x0, x1, y0, y1] (data units) outlined in a frame `f`.
export function rect(ctx, f, [x0, x1, y0, y1], colour, width) {
  ctx.save(); ctx.strokeStyle = colour; ctx.lineWidth = width;
  ctx.strokeRect(f.X(x0), f.Y(y1), f.X(x1) - f.X(x0), f.Y(y0) - f.Y(y1)); ctx.restore();
}
