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
  const safety = $("safety");
  safety.hidden = !s.safety;
  if (s.safety) {
    safety.textContent = s.safety.summary;
    safety.title = s.safety.summary;  // the whole line, when the header cuts it
    safety.className = `safety ${s.safety.level}`;
  }
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
    li.className = BAD.has(e.kind) ? "bad" : GOOD.has(e.kind) ? "good" : e.kind === "operator_command" || e.kind === "mission_change" ? "operator" : "";
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
  $("suspend").onclick = () => { if (confirm("Suspend the mission and land? aeroexec run --resume goes on from here.")) send("suspend"); };
  $("inhibit").onclick = () => send("inhibit", $("inhibit-name").value.trim());
  $("add-belief").onclick = () => send("add", $("belief-text").value.trim());
  $("remove-belief").onclick = () => send("remove", $("belief-text").value.trim());
  $("ask").onclick = () => send("query", $("query").value.trim());
  $("query").onkeydown = (e) => { if (e.key === "Enter") $("ask").click(); };
  $("belief-filter").oninput = drawPanels;
  $("drone").onchange = (e) => { model.selected = e.target.value; draw(); };
  $("question-form").onsubmit = () => { const v = $("question-free").value.trim(); if (v) send("answer", v); };
  $("skip").onclick = () => send("skip");
  $("change").onclick = () => send($("change-command").value, $("change-argument").value.trim());
}

function result(message) {
  if (message.command === "query") {
    const lines = (message.data && message.data.answers || []).map((a) => Object.entries(a).map(([k, v]) => `${k} = ${v}`).join(", "));
    $("query-result").textContent = `${message.message}${lines.length ? "\n" + lines.join("\n") : ""}`;
    return;
  }
  const problems = (message.data && message.data.problems || []).slice(1);
  text("message", `${message.command}: ${message.message}${problems.length ? " · " + problems.join(" · ") : ""}`);
}

// -- replay of a finished run ------------------------------------------------------------------------------
function replayAt(time) {
  const r = model.replay;
  for (const name of Object.keys(r.drones)) {
    const records = r.drones[name];
    const d = drone(name);
    d.trail = []; d.events = [];
    let telemetry = null, beliefs = new Set(), nodes = new Map(), active = new Map(), state = "running";
    const safety = { rules: null, violated: new Map(), due: new Map(), inEffect: null };
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
        if (rec.kind.startsWith("safety_")) replaySafety(safety, rec);
        d.events.push({ time: rec.time, kind: rec.kind, behavior: rec.behavior || "", detail: rec.reason || rec.detail || "" });
      }
    }
    const sorted = [...nodes.values()].sort((a, b) => a.uid - b.uid);
    d.snapshot = { time, state, telemetry: telemetry || {}, active: [...active.values()], safety: safetyStatus(safety),
                   beliefs: [...beliefs].sort(), belief_count: beliefs.size, questions: [],
                   mission: sorted.length ? { kind: "tree", name: r.mission || "", nodes: sorted }
                                          : { kind: "python", line: r.mission || "" } };
  }
  text("replay-time", `${time.toFixed(1)} s`);
  draw();
}

// the safety rules' status at a moment of a replay, from their events (as SafetyStatus says it live)
function replaySafety(safety, rec) {
  const data = rec.data || {};
  if (rec.kind === "safety_watch") safety.rules = (data.rules || []).length;
  else if (rec.kind === "safety_violated") {
    safety.violated.set(data.rule, rec.time);
    safety.due.delete(data.rule);
    if (data.action && !data.action.startsWith("the contingency of")) safety.inEffect = [data.rule, data.contingency, data.action];
  } else if (rec.kind === "safety_restored") safety.violated.delete(data.rule);
  else if (rec.kind === "safety_triggered") {
    if (data.due !== undefined) safety.due.set(data.rule, data.due);
    if (data.action && !data.action.startsWith("the contingency of")) safety.inEffect = [data.rule, data.contingency, data.action];
  } else if (rec.kind === "safety_met") { safety.due.delete(data.rule); safety.violated.delete(data.rule); }
}

function safetyStatus(safety) {
  if (safety.rules === null) return null;
  const parts = [];
  if (safety.violated.size) parts.push("violated " + [...safety.violated].map(([r, t]) => `${r} (t=${t.toFixed(1)} s)`).join(", "));
  if (safety.inEffect) parts.push(`in effect: ${safety.inEffect[0]} ${safety.inEffect[1]}, ${safety.inEffect[2]}`);
  if (safety.due.size) parts.push("due: " + [...safety.due].map(([r, t]) => `${r} by t=${t.toFixed(1)} s`).join(", "));
  const level = safety.violated.size || safety.inEffect ? "violated" : safety.due.size ? "due" : "held";
  const summary = level === "held" ? `safety: ${safety.rules} rule${safety.rules === 1 ? "" : "s"} held` : `safety: ${parts.join("; ")}`;
  return { rules: safety.rules, level, summary };
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
