// The console's map (console.js draws the rest): the world and the drones from above, in screen pixels.
"use strict";

// -- the map ---------------------------------------------------------------------------------------------
// Drawn in screen pixels: world coordinates (m, east and north) are projected onto the panel, so lines, labels,
// the grid, the scale bar and the north arrow keep their sizes whether the flight spans 10 m or several km.
const SVG = "http://www.w3.org/2000/svg";
const AROUND = [[8, 4], [-8, 4], [0, -10], [0, 16], [8, -8], [-8, -8], [8, 16], [-8, 16], [16, 4], [-16, 4]];
function el(tag, attrs, parent) {
  const node = document.createElementNS(SVG, tag);
  for (const [k, v] of Object.entries(attrs)) node.setAttribute(k, v);
  if (parent) parent.appendChild(node);
  return node;
}

function niceStep(rough) {
  if (!(rough > 0)) return 1;
  const power = Math.pow(10, Math.floor(Math.log10(rough)));
  return [5, 2, 1].map((m) => m * power).find((v) => v <= rough) || power;
}

function distanceText(m, km) { return km ? `${+(m / 1000).toFixed(3)} km` : `${+m.toFixed(2)} m`; }

// What the view must show: the world's bounds and home, every drone's trail, position and planned path.
function extent() {
  const xs = [0], ys = [0];
  const w = model.world;
  if (w) { xs.push(w.bounds.lower[0], w.bounds.upper[0]); ys.push(w.bounds.lower[1], w.bounds.upper[1]); }
  for (const name of model.order) {
    const d = model.drones[name], s = d.snapshot;
    for (const p of d.trail) { xs.push(p[0]); ys.push(p[1]); }
    const p = s && s.telemetry && s.telemetry.position;
    if (p) { xs.push(p[0]); ys.push(p[1]); }
    for (const a of (s && s.active) || []) for (const q of a.path || []) { xs.push(q[0]); ys.push(q[1]); }
  }
  if (!w) { xs.push(-20, 20); ys.push(-20, 20); }
  return [Math.min(...xs), Math.max(...xs), Math.min(...ys), Math.max(...ys)];
}

class Labels {  // labels placed where they overlap no other label, mark or the map's edge; the rest left off
  constructor(svg, width, height) { this.svg = svg; this.width = width; this.height = height; this.taken = []; }
  reserve(box, pad = 2) { this.taken.push({ x: box.x - pad, y: box.y - pad, width: box.width + 2 * pad, height: box.height + 2 * pad }); }
  free(b) {
    if (b.x < 2 || b.y < 2 || b.x + b.width > this.width - 2 || b.y + b.height > this.height - 2) return false;
    return !this.taken.some((t) => b.x < t.x + t.width && t.x < b.x + b.width && b.y < t.y + t.height && t.y < b.y + b.height);
  }
  place(text, x, y, cls, offsets = AROUND) {
    const node = el("text", { class: `label ${cls || ""}` }, this.svg);
    node.textContent = text;
    for (const [dx, dy] of offsets) {
      node.setAttribute("x", x + dx);
      node.setAttribute("y", y + dy);
      node.setAttribute("text-anchor", dx > 0 ? "start" : dx < 0 ? "end" : "middle");
      const b = node.getBBox();
      if (this.free(b)) { this.reserve(b); return node; }
    }
    node.remove();
    return null;
  }
}

function drawMap() {
  const svg = $("map");
  svg.replaceChildren();
  const width = svg.clientWidth || 600, height = svg.clientHeight || 500;
  svg.setAttribute("viewBox", `0 0 ${width} ${height}`);
  const [x0, x1, y0, y1] = extent();
  const margin = 36;
  const scale = Math.min((width - 2 * margin) / Math.max(x1 - x0, 10), (height - 2 * margin) / Math.max(y1 - y0, 10));
  const mx = (x0 + x1) / 2, my = (y0 + y1) / 2;
  const px = (x) => width / 2 + (x - mx) * scale, py = (y) => height / 2 - (y - my) * scale;
  const points = (list) => list.map((p) => `${px(p[0]).toFixed(1)},${py(p[1]).toFixed(1)}`).join(" ");
  const labels = new Labels(svg, width, height);
  // grid, every round step, labelled along the left and bottom edges
  const spanM = Math.max(width, height) / scale, km = spanM > 2000;
  const step = niceStep(spanM / 8);
  const left = mx - width / 2 / scale, right = mx + width / 2 / scale;
  const bottom = my - height / 2 / scale, top = my + height / 2 / scale;
  const gridTexts = [];
  for (let x = Math.ceil(left / step) * step; x <= right; x += step) {
    el("line", { class: "grid", x1: px(x), y1: 0, x2: px(x), y2: height }, svg);
    gridTexts.push([distanceText(x, km), px(x) + 3, height - 8]);
  }
  for (let y = Math.ceil(bottom / step) * step; y <= top; y += step) {
    el("line", { class: "grid", x1: 0, y1: py(y), x2: width, y2: py(y) }, svg);
    gridTexts.push([distanceText(y, km), 4, py(y) - 3]);
  }
  const w = model.world;
  if (w) {
    const lo = w.bounds.lower, hi = w.bounds.upper;
    el("rect", { class: "bounds", x: px(lo[0]), y: py(hi[1]), width: (hi[0] - lo[0]) * scale, height: (hi[1] - lo[1]) * scale }, svg);
  }
  const names = [];  // [text, x, y, class]: placed once every mark is down
  if (w) {
    for (const o of w.obstacles) {
      if (o.shape === "cylinder") {
        el("circle", { class: "obstacle", cx: px(o.center[0]), cy: py(o.center[1]), r: Math.max(o.radius * scale, 2) }, svg);
        names.push([o.name, px(o.center[0]), py(o.center[1]), "obstacle-label"]);
      } else {
        el("rect", { class: "obstacle", x: px(o.lower[0]), y: py(o.upper[1]), width: Math.max((o.upper[0] - o.lower[0]) * scale, 2),
                     height: Math.max((o.upper[1] - o.lower[1]) * scale, 2) }, svg);
        names.push([o.name, px((o.lower[0] + o.upper[0]) / 2), py((o.lower[1] + o.upper[1]) / 2), "obstacle-label"]);
      }
    }
    if (w.platform && w.platform.path.length > 1) el("polyline", { class: "platform-path", points: points(w.platform.path) }, svg);
    for (const m of w.markers) {
      const box = { x: px(m.position[0]) - 4, y: py(m.position[1]) - 4, width: 8, height: 8 };
      el("rect", { class: "marker", ...box }, svg);
      labels.reserve(box);
      names.push([`#${m.id}`, px(m.position[0]), py(m.position[1]), "marker-label"]);
    }
    for (const o of w.objects) {
      el("circle", { cx: px(o.position[0]), cy: py(o.position[1]), r: 5, fill: o.color, stroke: "#333", "stroke-width": 1 }, svg);
      labels.reserve({ x: px(o.position[0]) - 5, y: py(o.position[1]) - 5, width: 10, height: 10 });
      names.push([o.name, px(o.position[0]), py(o.position[1]), "object-label"]);
    }
  }
  const droneLabels = [];
  for (const name of model.order) {
    const d = model.drones[name], s = d.snapshot;
    if (d.trail.length > 1) el("polyline", { class: "trail", stroke: d.color, points: points(d.trail) }, svg);
    if (!s || !s.telemetry || !s.telemetry.position) continue;
    for (const a of s.active || []) {
      if (a.path && a.path.length) el("polyline", { class: "planned", stroke: d.color, points: points([s.telemetry.position, ...a.path]) }, svg);
    }
    const [x, y] = s.telemetry.position;
    const g = el("g", { id: `drone-${name}`, class: "drone-marker", "data-x": x, "data-y": y,
                        transform: `translate(${px(x)} ${py(y)}) rotate(${-(90 - (s.telemetry.yaw || 0))})` }, svg);
    el("polygon", { class: "drone", fill: d.color, points: "11,0 -7,6.5 -3.5,0 -7,-6.5" }, g);
    labels.reserve({ x: px(x) - 11, y: py(y) - 11, width: 22, height: 22 });
    droneLabels.push([name, px(x), py(y)]);
  }
  drawScaleBar(svg, labels, scale, width, height, km);
  drawNorthArrow(svg, labels, width);
  for (const [name, x, y] of droneLabels) labels.place(name, x, y, "drone-label", [[16, -8], [-16, -8], [16, 20], [-16, 20], [0, -16], [0, 28]]);
  const home = (model.replay && model.replay.home) || (w && w.home);
  if (home) {
    const t = el("text", { class: "home-label", x: width - 8, y: height - 8, "text-anchor": "end" }, svg);
    t.textContent = `home ${Math.abs(home[0]).toFixed(6)}° ${home[0] >= 0 ? "N" : "S"}, ${Math.abs(home[1]).toFixed(6)}° ${home[1] >= 0 ? "E" : "W"}`;
    labels.reserve(t.getBBox());
  }
  for (const [text, x, y, cls] of names) labels.place(text, x, y, cls);
  for (const [text, x, y] of gridTexts) labels.place(text, x, y, "grid-label", [[0.01, 0]]);
}

function drawScaleBar(svg, labels, scale, width, height, km) {
  const length = niceStep(width / 5 / scale), barPx = length * scale;
  const x = 14, y = height - 40;
  el("rect", { class: "scale-box", x: x - 6, y: y - 18, width: barPx + 12, height: 30, rx: 3 }, svg);
  el("line", { class: "scale-bar", x1: x, y1: y + 4, x2: x + barPx, y2: y + 4 }, svg);
  const t = el("text", { class: "scale-label", x: x + barPx / 2, y: y - 4, "text-anchor": "middle" }, svg);
  t.textContent = distanceText(length, km);
  labels.reserve({ x: x - 6, y: y - 18, width: barPx + 12, height: 30 });
}

function drawNorthArrow(svg, labels, width) {
  const x = width - 24, y = 14;
  el("rect", { class: "north-box", x: x - 13, y: y - 6, width: 26, height: 46, rx: 3 }, svg);
  el("polygon", { class: "north-arrow", points: `${x},${y} ${x - 7},${y + 16} ${x},${y + 12} ${x + 7},${y + 16}` }, svg);
  const t = el("text", { class: "north-label", x, y: y + 34, "text-anchor": "middle" }, svg);
  t.textContent = "N";
  labels.reserve({ x: x - 13, y: y - 6, width: 26, height: 46 });
}
