// The live readings as an SVG polyline: a few hundred points at most (the store bounds them), redrawn whole.
const NS = "http://www.w3.org/2000/svg";

function el(tag, attrs) {
  const e = document.createElementNS(NS, tag);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, String(v));
  return e;
}

export function lineChart(points, { label = "", unit = "" } = {}) {
  const W = 600, H = 200, L = 56, R = 8, T = 10, B = 24;
  const svg = el("svg", { viewBox: `0 0 ${W} ${H}`, class: "chart", role: "img",
                          "aria-label": `${label}: ${points.length} readings` });
  if (!points.length) {
    const t = el("text", { x: W / 2, y: H / 2, "text-anchor": "middle", class: "chart-empty" });
    t.textContent = "no readings yet";
    svg.append(t);
    return svg;
  }
  const xs = points.map(p => p.x), ys = points.map(p => p.y);
  let [x0, x1] = [Math.min(...xs), Math.max(...xs)];
  let [y0, y1] = [Math.min(...ys), Math.max(...ys)];
  if (x1 === x0) x1 = x0 + 1;
  if (y1 === y0) { y0 -= Math.abs(y0) * 0.01 || 1; y1 += Math.abs(y1) * 0.01 || 1; }
  const sx = x => L + (x - x0) / (x1 - x0) * (W - L - R);
  const sy = y => T + (1 - (y - y0) / (y1 - y0)) * (H - T - B);
  svg.append(el("line", { x1: L, y1: H - B, x2: W - R, y2: H - B, class: "axis" }));
  svg.append(el("line", { x1: L, y1: T, x2: L, y2: H - B, class: "axis" }));
  for (const [y, v] of [[T + 4, y1], [H - B, y0]]) {
    const t = el("text", { x: L - 4, y, "text-anchor": "end", class: "tick" });
    t.textContent = Number(v.toPrecision(5)).toString();
    svg.append(t);
  }
  const caption = el("text", { x: W - R, y: H - 6, "text-anchor": "end", class: "tick" });
  caption.textContent = `${label} (${unit}) · seq ${x0}–${xs[xs.length - 1]}`;
  svg.append(caption);
  svg.append(el("polyline", { points: points.map(p => `${sx(p.x).toFixed(1)},${sy(p.y).toFixed(1)}`).join(" "),
                              class: "series" }));
  const last = points[points.length - 1];
  svg.append(el("circle", { cx: sx(last.x), cy: sy(last.y), r: 3, class: "series-dot" }));
  return svg;
}
