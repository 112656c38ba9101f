// The aeroexec console page: draws what the server pushes over the WebSocket, sends the operator's commands.
"use strict";

const token = new URLSearchParams(location.search).get("token") || "";
const $ = (id) => document.getElementById(id);
const ENDINGS = new Set(["GOAL_ACHIEVED", "TIME_OUT", "WRONG_PROGRESS", "INTERRUPTED", "FAILED_PRECONDITIONS"]);
const BAD = new Set(["TIME_OUT", "WRONG_PROGRESS", "failed_preconditions", "rejected", "mission_failed",
                     "FAILED_PRECONDITIONS"]);
const GOOD = new Set(["GOAL_ACHIEVED", "mission_completed"]);
const COLORS = ["#1565c0", "#d81b60", "#2e7d32", "#ef6c00", "#6a1b9a", "#00838f", "#5d4037", "#c0ca33"];
const MAX_TRAIL = 4000, MAX_EVENTS = 300;

const model = { world: null, drones: {}, order: [], selected: null, readOnly: false, replay: null };
let socket = null, nextId = 1, lastQuestion = "";

function drone(name) {
  if (!model.drones[name]) {
    model.drones[name] = { snapshot: null, events: [], trail: [], color: COLORS[model.order.length % COLORS.length] };
    model.order.push(name);
    const option = document.createElement("option");
    option.value = option.textContent = name;
    $("drone").appendChild(option);
    if (!model.selected) model.selected = name;
  }
  return model.drones[name];
}

function update(name, snapshot, events) {
  const d = drone(name);
  if (snapshot) {
    d.snapshot = snapshot;
    const p = snapshot.telemetry && snapshot.telemetry.position;
    const last = d.trail[d.trail.length - 1];
    if (p && (!last || Math.hypot(p[0] - last[0], p[1] - last[1]) > 0.05)) d.trail.push(p);
    if (d.trail.length > MAX_TRAIL) d.trail.splice(0, d.trail.length - MAX_TRAIL);
  }
  for (const e of events || []) d.events.push(e);
  if (d.events.length > MAX_EVENTS) d.events.splice(0, d.events.length - MAX_EVENTS);
}

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

// -- the side panels ---------------------------------------------------------------------------------------
function text(id, value) { $(id).textContent = value; }

function drawPanels() {
  const d = model.drones[model.selected];
  const s = d && d.snapshot;
  if (!s) return;
  const state = $("state");
  state.textContent = model.replay ? "replay" : s.state;
  state.className = `state ${model.replay ? "replay" : s.state}`;
  state.title = model.replay ? `the run, at this time: ${s.state}` : "";
  text("time", s.time.toFixed(1));
  const t = s.telemetry || {};
  text("altitude", t.position ? `${t.position[2].toFixed(1)} m` : "-");
  text("speed", t.speed !== undefined && t.speed !== null ? `${t.speed.toFixed(1)} m/s` : "-");
  text("battery", t.battery !== undefined && t.battery !== null ? `${Math.round(t.battery)} %` : "-");
  text("flight", [t.landed, t.mode, t.armed ? "armed" : ""].filter(Boolean).join(" "));
  const mission = $("mission");
  mission.replaceChildren();
  if (s.mission && s.mission.kind === "tree") {
    text("mission-name", s.mission.name || "");
    for (const n of s.mission.nodes) {
      const row = document.createElement("div");
      row.className = "node";
      row.dataset.uid = n.uid;
      row.dataset.name = n.name;
      row.dataset.status = n.status;
      row.style.marginLeft = `${n.depth * 14}px`;
      row.textContent = `${n.name}  ${n.status}`;
      mission.appendChild(row);
    }
  } else if (s.mission) {
    text("mission-name", "(python)");
    const line = document.createElement("code");
    line.id = "python-line";
    line.textContent = s.mission.line;
    mission.appendChild(line);
  }
  const body = $("active").querySelector("tbody");
  body.replaceChildren();
  for (const a of s.active || []) {
    const row = body.insertRow();
    row.dataset.behavior = a.name;
    for (const v of [a.name, a.priority || "", a.source || "", a.left !== null && a.left !== undefined ? `${a.left} s` : "-"]) {
      row.insertCell().textContent = v;
    }
  }
  const filter = $("belief-filter").value.trim().toLowerCase();
  const list = $("beliefs");
  list.replaceChildren();
  for (const b of s.beliefs || []) {
    if (filter && !b.toLowerCase().includes(filter)) continue;
    const li = document.createElement("li");
    li.textContent = b;
    list.appendChild(li);
  }
  text("belief-count", s.belief_count !== undefined ? `(${s.belief_count})` : "");
  const events = $("events");
  events.replaceChildren();
  for (const e of d.events.slice(-120)) {
    const li = document.createElement("li");
    li.dataset.kind = e.kind;
    li.className = BAD.has(e.kind) ? "bad" : GOOD.has(e.kind) ? "good" : e.kind === "operator_command" ? "operator" : "";
    li.textContent = `[${e.time.toFixed(1)}] ${e.kind}${e.behavior ? " " + e.behavior : ""}${e.detail ? ": " + e.detail : ""}`;
    events.appendChild(li);
  }
  events.scrollTop = events.scrollHeight;
  askQuestion(s.questions || []);
}

function askQuestion(questions) {
  const dialog = $("question-dialog");
  if (!questions.length || model.readOnly) {
    if (dialog.open) dialog.close();
    lastQuestion = "";
    return;
  }
  const q = questions[0];
  if (dialog.open && lastQuestion === q.question) return;
  lastQuestion = q.question;
  text("question-text", q.question);
  const answers = $("question-answers");
  answers.replaceChildren();
  for (const a of q.answers) {
    const b = document.createElement("button");
    b.className = "answer";
    b.textContent = a;
    b.onclick = () => { send("answer", a); dialog.close(); };
    answers.appendChild(b);
  }
  if (!dialog.open) dialog.showModal();
}

function draw() { drawMap(); drawPanels(); }

// -- commands ----------------------------------------------------------------------------------------------
function send(command, argument = "") {
  if (!socket || socket.readyState !== WebSocket.OPEN || model.readOnly) {
    text("message", model.readOnly ? "a replay takes no commands" : "not connected");
    return;
  }
  socket.send(JSON.stringify({ id: nextId++, drone: model.selected, command, argument }));
}

function wire() {
  $("pause").onclick = () => send("pause");
  $("resume").onclick = () => send("resume");
  $("abort").onclick = () => { if (confirm("Abort the mission and land?")) send("abort"); };
  $("inhibit").onclick = () => send("inhibit", $("inhibit-name").value.trim());
  $("add-belief").onclick = () => send("add", $("belief-text").value.trim());
  $("remove-belief").onclick = () => send("remove", $("belief-text").value.trim());
  $("ask").onclick = () => send("query", $("query").value.trim());
  $("query").onkeydown = (e) => { if (e.key === "Enter") $("ask").click(); };
  $("belief-filter").oninput = drawPanels;
  $("drone").onchange = (e) => { model.selected = e.target.value; draw(); };
  $("question-form").onsubmit = () => { const v = $("question-free").value.trim(); if (v) send("answer", v); };
}

function result(message) {
  if (message.command === "query") {
    const lines = (message.data && message.data.answers || []).map((a) => Object.entries(a).map(([k, v]) => `${k} = ${v}`).join(", "));
    $("query-result").textContent = `${message.message}${lines.length ? "\n" + lines.join("\n") : ""}`;
    return;
  }
  text("message", `${message.command}: ${message.message}`);
}

// -- replay of a finished run ------------------------------------------------------------------------------
function replayAt(time) {
  const r = model.replay;
  for (const name of Object.keys(r.drones)) {
    const records = r.drones[name];
    const d = drone(name);
    d.trail = []; d.events = [];
    let telemetry = null, beliefs = new Set(), nodes = new Map(), active = new Map(), state = "running";
    for (const rec of records) {
      if (rec.time > time) break;
      if (rec.kind === "state") {
        const v = rec.velocity || [0, 0, 0];
        telemetry = { position: rec.position, yaw: rec.yaw, battery: rec.battery, landed: rec.landed_state, armed: rec.armed, mode: "",
                      speed: Math.hypot(v[0], v[1], v[2] || 0) };
        d.trail.push(rec.position);
      } else if (rec.kind === "belief_added") beliefs.add(rec.belief);
      else if (rec.kind === "belief_removed") beliefs.delete(rec.belief);
      else if (rec.kind === "node_status") {
        const data = rec.data || {};
        nodes.set(data.uid, { uid: data.uid, depth: data.depth || 0, name: data.node, status: data.new });
      } else if (rec.kind !== "log_started" && rec.kind !== "log_closed") {
        if (rec.kind === "activated") active.set(rec.behavior, { name: rec.behavior, priority: "", source: "", left: null });
        if (ENDINGS.has(rec.kind)) active.delete(rec.behavior);
        if (rec.kind === "mission_completed") state = "ended";
        if (rec.kind === "mission_failed") state = "failed";
        if (rec.kind === "operator_command" && rec.data && rec.data.command === "pause") state = "paused";
        if (rec.kind === "operator_command" && rec.data && rec.data.command === "resume") state = "running";
        d.events.push({ time: rec.time, kind: rec.kind, behavior: rec.behavior || "", detail: rec.reason || rec.detail || "" });
      }
    }
    const sorted = [...nodes.values()].sort((a, b) => a.uid - b.uid);
    d.snapshot = { time, state, telemetry: telemetry || {}, active: [...active.values()],
                   beliefs: [...beliefs].sort(), belief_count: beliefs.size, questions: [],
                   mission: sorted.length ? { kind: "tree", name: r.mission || "", nodes: sorted }
                                          : { kind: "python", line: r.mission || "" } };
  }
  text("replay-time", `${time.toFixed(1)} s`);
  draw();
}

function startReplay() {
  const r = model.replay;
  $("replay-bar").hidden = false;
  $("controls-panel").hidden = true;
  text("replay-mission", r.mission || "a finished run");
  text("link", "finished run: read-only");
  $("link").className = "link replay";
  const slider = $("slider");
  slider.max = r.end;
  slider.value = r.end;
  slider.oninput = () => replayAt(parseFloat(slider.value));
  let timer = null;
  $("play").onclick = () => {
    if (timer) { clearInterval(timer); timer = null; $("play").textContent = "play"; return; }
    if (parseFloat(slider.value) >= r.end) slider.value = 0;
    $("play").textContent = "pause";
    timer = setInterval(() => {
      const v = Math.min(r.end, parseFloat(slider.value) + 0.5);
      slider.value = v;
      replayAt(v);
      if (v >= r.end) { clearInterval(timer); timer = null; $("play").textContent = "play"; }
    }, 100);
  };
  replayAt(r.end);
}

// -- the socket -------------------------------------------------------------------------------------------
function connect() {
  const scheme = location.protocol === "https:" ? "wss" : "ws";
  socket = new WebSocket(`${scheme}://${location.host}/ws?token=${encodeURIComponent(token)}`);
  socket.onopen = () => { if (!model.replay) { text("link", "online"); $("link").className = "link online"; } };
  socket.onclose = () => { if (!model.replay) { text("link", "offline"); $("link").className = "link"; } };
  socket.onmessage = (event) => {
    const message = JSON.parse(event.data);
    if (message.type === "hello") {
      model.world = message.world;
      model.readOnly = message.read_only;
      for (const name of message.drones) {
        const latest = (message.latest || {})[name] || {};
        update(name, latest.snapshot, latest.events);
      }
      if (message.replay) { model.replay = message.replay; startReplay(); return; }
      draw();
    } else if (message.type === "update") {
      update(message.drone, message.snapshot, message.events);
      draw();
    } else if (message.type === "result") {
      result(message);
    }
  };
}

wire();
connect();
window.addEventListener("resize", () => drawMap());
