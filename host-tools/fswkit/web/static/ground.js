// The web ground station's page: one WebSocket carries every decoded frame
// (arrays of messages), the link's figures twice a second and the command
// history; commands go by POST /api/command after a confirmation.
"use strict";

const COLORS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf", "#8c564b", "#e377c2"];
const STATE_COLORS = ["#4e79a7", "#f28e2b", "#59a14f", "#e15759", "#76b7b2", "#edc948", "#b07aa1", "#9c755f",
                      "#bab0ac", "#ff9da7"];
const MAX_POINTS = 200000;
const TIMELINE_KEPT = 500;    // each machine's latest state changes kept in its timeline (band and list)

let layout = null;
let perSecond = 1000;
const values = {};           // element -> last value
const series = { t: [] };    // time (s) and one array per element sampled
let chart = null;
let picked = [];
let paused = false;
let dirty = false;
const states = {};           // S element -> {current, since, segments: [[t0, t1, id]], list: []}
// frame-to-page latency: seconds from the frame's bytes reaching the station
// to its message reaching this page (the same host's clock), last 10,000
window.fswLatency = [];
window.fswSeqs = [];
let lastTime = null;
let lastSeq = null;           // the last sample frame's number

function $(id) { return document.getElementById(id); }
function el(tag, attrs, text) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs || {})) e.setAttribute(k, v);
  if (text !== undefined) e.textContent = text;
  return e;
}

function fmt(v) {
  if (v === null || v === undefined) return "—";
  if (typeof v === "boolean") return v ? "true" : "false";
  if (typeof v === "number" && !Number.isInteger(v)) return v.toPrecision(6).replace(/\.?0+$/, "");
  return String(v);
}

function stateName(elem, id) {
  const names = layout.elements.find(e => e.name === elem).states || {};
  return names[String(id)] || String(id);
}

async function start() {
  layout = await (await fetch("/api/layout")).json();
  perSecond = layout.time_unit === "us" ? 1e6 : 1e3;
  $("title").textContent = `${layout.title} — ${layout.name} (schema ${layout.schema})`;
  document.title = `${layout.name}: fsw ground`;
  buildValueTable();
  buildPicker();
  buildCommands();
  for (const s of layout.state_elements) states[s] = { current: null, since: null, segments: [], list: [] };
  buildTimeline();
  buildHealth();
  if (layout.has_params) { $("parameters").hidden = false; $("param-refresh").addEventListener("click", readParams);
                           readParams(); }
  connect();
  setInterval(draw, 200);
}

function buildValueTable() {
  const body = $("value-table").tBodies[0];
  for (const e of layout.elements) {
    const tr = el("tr");
    tr.append(el("td", {}, e.name), el("td", { id: `value-${e.name}` }, "—"));
    body.append(tr);
  }
}

// every element but the time is plotted: bools (0/1) and states (their ids) as steps
function plotted(e) { return e.name !== layout.elements[0].name; }
function stepped(e) { return e.kind === "bool" || !!e.states; }

function buildPicker() {
  const box = $("picker");
  const candidates = layout.elements.filter(plotted);
  const first = candidates.filter(e => !stepped(e)).slice(0, 2).map(e => e.name);
  candidates.forEach(e => {
    const cb = el("input", { type: "checkbox", id: `pick-${e.name}` });
    cb.checked = first.includes(e.name);
    cb.addEventListener("change", () => { picked = candidates.filter(c => $(`pick-${c.name}`).checked)
      .map(c => c.name); makeChart(); });
    const lab = el("label");
    lab.append(cb, " " + e.name);
    box.append(lab);
  });
  picked = first;
  $("pause").addEventListener("click", () => {
    paused = !paused;
    $("pause").textContent = paused ? "Resume" : "Pause";
    dirty = true;
  });
  $("window").addEventListener("change", () => { dirty = true; });
  makeChart();
}

function makeChart() {
  if (chart) chart.destroy();
  const opts = {
    width: Math.max(300, $("chart").clientWidth || 700), height: 280,
    scales: { x: { time: false } },
    axes: [{ label: "time (s)" }, {}],
    series: [{ label: "t (s)" }].concat(picked.map((n, i) => {
      const e = layout.elements.find(x => x.name === n);
      const s = { label: n, stroke: COLORS[i % COLORS.length], width: 1.5 };
      if (stepped(e)) s.paths = uPlot.paths.stepped({ align: 1 });
      return s;
    })),
    cursor: { drag: { x: true, y: false } },
  };
  chart = new uPlot(opts, [[]].concat(picked.map(() => [])), $("chart"));
  dirty = true;
}

function draw() {
  if (!chart || paused || !dirty) return;
  dirty = false;
  const t = series.t;
  const win = Number($("window").value);
  let from = 0;
  if (win > 0 && t.length) {
    const lo = t[t.length - 1] - win;
    while (from < t.length && t[from] < lo) from++;
  }
  const data = [t.slice(from)].concat(picked.map(n => (series[n] || []).slice(from)));
  chart.setData(data);
}

function addSamples(msg) {
  window.fswSeqs.push(msg.seq);  // what the page received, for the tests and the bench
  if (window.fswSeqs.length > 100000) window.fswSeqs.shift();
  if (msg.host) {
    window.fswLatency.push(Date.now() / 1000 - msg.host);
    if (window.fswLatency.length > 10000) window.fswLatency.shift();
  }
  const idx = {};
  msg.names.forEach((n, i) => { idx[n] = i + 1; });
  // the frame counter went back (the station numbers frames by the target's counter): the target restarted
  if (lastSeq !== null && msg.seq < lastSeq && msg.rows.length) restarted(msg.rows[0][0] / perSecond);
  lastSeq = msg.seq;
  for (const row of msg.rows) {
    const ts = row[0] / perSecond;
    lastTime = ts;
    msg.names.forEach((n, i) => { values[n] = row[i + 1]; });
    // one time column for all: an element not in this region repeats its last value
    series.t.push(ts);
    for (const e of layout.elements) {
      if (!plotted(e)) continue;
      const v = values[e.name];
      (series[e.name] = series[e.name] || []).push(v === undefined ? null : typeof v === "boolean" ? +v : v);
    }
    for (const s of layout.state_elements) if (idx[s] !== undefined) noteState(s, row[idx[s]], ts);
  }
  if (series.t.length > MAX_POINTS) {
    const cut = series.t.length - MAX_POINTS;
    for (const k of Object.keys(series)) series[k].splice(0, cut);
  }
  for (const n of msg.names) {
    const c = $(`value-${n}`);
    if (c) c.textContent = layout.state_elements.includes(n) ? `${values[n]} (${stateName(n, values[n])})`
                                                             : fmt(values[n]);
  }
  dirty = true;
}

// the target restarted (a reset, a reflash; the station's note says why). The plot
// and the state bands start again on its new time, the transitions list says so: the old samples are not
// drawn over the new ones (the archive keeps them all)
function restarted(ts) {
  for (const k of Object.keys(series)) series[k].length = 0;
  for (const elem of layout.state_elements) {
    const s = states[elem];
    s.segments = [];
    if (s.current !== null) s.list.push(`${ts.toFixed(2)} s  (the target restarted)`);
    s.current = null;
    s.since = null;
  }
}

function noteState(elem, id, ts) {
  const s = states[elem];
  if (s.current === id) return;
  if (s.current !== null) {
    s.segments.push([s.since, ts, s.current]);
    s.list.push(`${ts.toFixed(2)} s  ${stateName(elem, s.current)} → ${stateName(elem, id)}`);
  } else {
    s.list.push(`${ts.toFixed(2)} s  ${stateName(elem, id)}`);
  }
  // the latest changes only: a machine that changes often over a long session is not drawn whole at each tick
  if (s.segments.length > TIMELINE_KEPT) s.segments.splice(0, s.segments.length - TIMELINE_KEPT);
  if (s.list.length > TIMELINE_KEPT) s.list.splice(0, s.list.length - TIMELINE_KEPT);
  s.current = id;
  s.since = ts;  // drawn at the link's next tick (twice a second), not at every change
}

function buildTimeline() {
  for (const s of layout.state_elements) {
    const box = el("div", { class: "machine" });
    box.append(el("strong", {}, s), el("div", { class: "band", id: `band-${s}` }),
               el("ol", { class: "transitions", id: `transitions-${s}` }));
    $("timeline").append(box);
  }
}

function drawTimeline(elem) {
  const s = states[elem];
  const band = $(`band-${elem}`);
  const segs = s.segments.concat(s.current !== null ? [[s.since, lastTime, s.current]] : []);
  if (!segs.length) return;
  const t0 = segs[0][0], t1 = Math.max(segs[segs.length - 1][1], t0 + 1e-6);
  band.replaceChildren(...segs.map(([a, b, id]) => {
    const d = el("div", { class: "seg", title: `${stateName(elem, id)} ${a.toFixed(2)}–${b.toFixed(2)} s` },
                 stateName(elem, id));
    d.style.left = `${(100 * (a - t0)) / (t1 - t0)}%`;
    d.style.width = `${Math.max(0.2, (100 * (b - a)) / (t1 - t0))}%`;
    d.style.background = STATE_COLORS[(id - 1) % STATE_COLORS.length];
    return d;
  }));
  const list = $(`transitions-${elem}`);
  list.replaceChildren(...s.list.map(x => el("li", {}, x)));
  list.scrollTop = list.scrollHeight;
}

function showLink(msg) {
  const pill = $("link-status");
  if (msg.age === null) {
    pill.className = "pill waiting";
    pill.textContent = "waiting for the target";
  } else if (msg.stale) {
    pill.className = "pill stale";
    pill.textContent = `stale: last frame ${msg.age.toFixed(1)} s ago`;
  } else {
    pill.className = "pill live";
    pill.textContent = "live";
  }
  $("link-figures").textContent = `${msg.frames} frames`;
  if (msg.note && msg.note !== $("link-note").textContent) showNote(msg.note, !msg.stale);
  const ms = medianLatency();
  $("link-latency").textContent = ms === null ? "" : `latency ${ms < 10 ? ms.toFixed(1) : ms.toFixed(0)} ms`;
  if (lastTime !== null) for (const s of layout.state_elements) drawTimeline(s);
}

// the station's latest word on its link ("reconnected: …", "the target restarted: reset cause power-on")
function showNote(text, up) {
  const box = $("link-note");
  box.textContent = text;
  box.className = up ? "note" : "note down";
  box.title = `the station's latest note on its link (this page had it at ${new Date().toLocaleTimeString()})`;
}

// the rolling median of the frame-to-page latency (ms) over the last 200 frames, null before any
function medianLatency() {
  const last = window.fswLatency.slice(-200).sort((a, b) => a - b);
  if (!last.length) return null;
  const m = last.length >> 1;
  return 1000 * (last.length % 2 ? last[m] : (last[m - 1] + last[m]) / 2);
}

// The link and task tables have their rows from the start, a dash in each
// value until the first health frame: the layout names every row (the
// fixed counters, each pyro channel, each sensor part, each task), so a
// frame fills cells in place and nothing below moves under the operator's
// click (a Set button of the parameters, say) as the frames arrive.
const HEALTH_ROWS = [["reset cause", "reset_words"], ["cycles", "cycles"], ["late starts", "late"],
                     ["frames sent", "frames"], ["frames dropped (busy)", "dropped"],
                     ["commands applied", "rx_ok"], ["CRC errors", "rx_crc"], ["malformed", "rx_malformed"],
                     ["refused", "rx_refused"], ["replayed", "rx_replayed"]];
const TASK_CELLS = ["mode_name", "faults", "overruns", "worst_us"];

function buildHealth() {
  const labels = HEALTH_ROWS.map(([k]) => k).concat(layout.pyro.map(n => `pyro ${n}`),
                                                   layout.sensors.map(n => `sensor ${n}`));
  $("link-table").tBodies[0].replaceChildren(...labels.map((k, i) => {
    const tr = el("tr"); tr.append(el("th", {}, k), el("td", { id: `health-${i}` }, "—")); return tr; }));
  $("task-table").tBodies[0].replaceChildren(...layout.tasks.map(t => {
    const tr = el("tr", { id: `task-${t.name}` });
    tr.append(el("td", {}, t.name), el("td", {}, t.kind));
    for (const k of TASK_CELLS) tr.append(el("td", { class: `task-${k}` }, "—"));
    return tr;
  }));
}

function showHealth(info) {
  const cells = HEALTH_ROWS.map(([, k]) => info[k]).concat((info.pyro || []).map(p => p.words),
                                                          (info.sensors || []).map(s => s.words));
  cells.forEach((v, i) => { const td = $(`health-${i}`); if (td) td.textContent = fmt(v); });
  for (const t of info.tasks) {
    const tr = $(`task-${t.name}`);
    if (tr) TASK_CELLS.forEach((k, j) => { tr.cells[2 + j].textContent = fmt(t[k]); });
  }
}

// a command and the target's answer: applied, refused (the target said no, and why), or none came
// (status null: the station's words say whether it was sent — lost, or applied with its answer lost — or not)
function addHistory(entry) {
  const answered = entry.status !== null && entry.status !== undefined;
  const kind = entry.ok ? "ok" : answered ? "refused" : "lost";
  const words = entry.ok ? "applied" : answered ? `refused: ${entry.words}` : entry.words;
  const li = el("li", { class: kind }, `${entry.text} — ${words} (${entry.who})`);
  $("history").prepend(li);
}

// ---- commands ---------------------------------------------------------------

function checkValue(e, text) {
  const v = text.trim();
  if (e.kind === "bool") return ["true", "false", "1", "0"].includes(v.toLowerCase()) ? null
    : "true, false, 1 or 0";
  if (e.kind === "float") {
    const limit = e.type === "F32" ? 3.4028235e38 : Number.MAX_VALUE;
    if (/^[-+]?inf(inity)?$/i.test(v)) return null;
    const x = Number(v);
    if (v === "" || Number.isNaN(x)) return "a number";
    if (Math.abs(x) > limit) return `a number within ±${limit}, or inf`;
    return null;
  }
  if (!/^[-+]?(0x[0-9a-f]+|\d+)$/i.test(v)) return "a whole number";
  const n = BigInt(v.replace(/^\+/, ""));
  if (n < BigInt(e.lo) || n > BigInt(e.hi)) return `a whole number in ${e.lo}..${e.hi}`;
  return null;
}

function ask(text) {
  return new Promise(resolve => {
    const d = $("confirm");
    $("confirm-text").textContent = text;
    d.addEventListener("close", () => resolve(d.returnValue === "yes"), { once: true });
    d.showModal();
  });
}

async function send(kind, target, value, errBox) {
  errBox.textContent = "";
  if (!(await ask(`Send to the target: ${kind} ${target} ${kind === "set" ? "= " : ""}${value}?`))) return;
  const r = await fetch("/api/command", { method: "POST", headers: { "Content-Type": "application/json" },
                                          body: JSON.stringify({ kind, target, value }) });
  const answer = await r.json();
  if (!r.ok) errBox.textContent = answer.words;
}

function buildCommands() {
  const panel = $("command-panel");
  if (!layout.has_uplink) { panel.textContent = "This application has no uplink task."; return; }
  for (const e of layout.elements.filter(x => x.writable)) {
    const row = el("div", { class: "cmd" });
    const input = el("input", { id: `cmd-${e.name}`, placeholder: e.type, size: 10 });
    const btn = el("button", { id: `send-${e.name}`, type: "button" }, "Set");
    const err = el("span", { class: "err", id: `err-${e.name}` });
    btn.addEventListener("click", () => {
      const bad = checkValue(e, input.value);
      if (bad) { err.textContent = `${e.name} is ${e.type}: give ${bad}`; return; }
      send("set", e.name, input.value.trim(), err);
    });
    row.append(el("label", { for: `cmd-${e.name}` }, `${e.name} (${e.type})`), input, btn, err);
    panel.append(row);
  }
  for (const t of layout.tasks) {
    const row = el("div", { class: "cmd" });
    const sel = el("select", { id: `mode-${t.name}` });
    for (const m of ["enabled", "safed", "disabled"]) sel.append(el("option", { value: m }, m));
    const btn = el("button", { id: `send-mode-${t.name}`, type: "button" }, "Mode");
    const err = el("span", { class: "err" });
    btn.addEventListener("click", () => send("mode", t.name, sel.value, err));
    row.append(el("label", {}, `task ${t.name}`), sel, btn, err);
    panel.append(row);
  }
}

// ---- parameters (docs/parameters.md) -------------------------------------------

const SOURCES = ["no parameters", "defaults", "bank A", "bank B"];
let paramState = null;  // the store state byte of the last hello or health frame
let paramTimer = null;

// The target's parameters may have changed under the page: another client
// set, loaded or saved them through the station, or the target restarted.
// They are read again (once for a burst of such news).
function paramsChanged() {
  if (!layout.has_params) return;
  clearTimeout(paramTimer);
  paramTimer = setTimeout(readParams, 300);
}

function watchParams(msg) {
  if (msg.t === "ack") {
    if (msg.info.status === 0 && ["param_set", "param_commit", "param_save"].includes(msg.info.op_name)) paramsChanged();
  } else if (msg.info.params !== undefined) {  // hello, health: the store's source, unsaved changes, writing
    if (paramState !== null && msg.info.params !== paramState) paramsChanged();
    paramState = msg.info.params;
  }
}

async function readParams() {
  clearTimeout(paramTimer);
  $("param-err").textContent = "";
  const r = await (await fetch("/api/params")).json();
  if (!r.ok) { $("param-err").textContent = r.words; return; }
  if (r.note) $("param-err").textContent = r.note;  // an uploaded machine runs: its values reach the generated one only
  const i = r.info;
  $("param-state").textContent = `${SOURCES[i.source]}${i.source >= 2 ? ", sequence " + i.seq : ""}` +
    `${i.dirty ? ", unsaved changes" : ""}${i.writing ? ", writing" : ""}`;
  const body = $("param-table").tBodies[0];
  const shown = Array.from(body.rows, tr => tr.id);
  if (shown.length === r.params.length && r.params.every((p, k) => shown[k] === `param-${p.name}`)) {
    // the same table: its values again, and what the operator is typing kept
    for (const p of r.params) $(`pval-${p.name}`).textContent = `${fmt(p.value)}${p.unit ? " " + p.unit : ""}`;
    return;
  }
  body.replaceChildren(...r.params.map(p => {
    const tr = el("tr", { id: `param-${p.name}` });
    const input = el("input", { id: `pset-${p.name}`, size: 8, placeholder: p.type });
    const btn = el("button", { type: "button", id: `psend-${p.name}` }, "Set");
    btn.addEventListener("click", () => setParam(p, input.value.trim()));
    const cells = [p.name, `${fmt(p.value)}${p.unit ? " " + p.unit : ""}`, p.range, p.when.join(" ")];
    cells.forEach((c, k) => tr.append(el("td", k === 1 ? { id: `pval-${p.name}` } : {}, c)));
    const a = el("td"); a.append(input); const b = el("td"); b.append(btn);
    tr.append(a, b);
    return tr;
  }));
}

async function setParam(p, text) {
  $("param-err").textContent = "";
  if (!(await ask(`Set parameter ${p.name} = ${text}${p.unit ? " " + p.unit : ""} on the target (live, until saved)?`))) return;
  const r = await fetch("/api/params", { method: "POST", headers: { "Content-Type": "application/json" },
                                         body: JSON.stringify({ values: { [p.name]: text } }) });
  const answer = await r.json();
  await readParams();
  if (!r.ok || !answer.ok) $("param-err").textContent = answer.words;
}

// ---- the feed ---------------------------------------------------------------

function handle(msg) {
  switch (msg.t) {
    case "samples": addSamples(msg); break;
    case "health": showHealth(msg.info); watchParams(msg); break;
    case "hello": watchParams(msg); break;
    case "ack": watchParams(msg); break;
    case "link": showLink(msg); break;
    case "note": showNote(msg.text, msg.up); break;
    case "command": addHistory(msg); break;
    case "history": msg.commands.forEach(addHistory); break;
  }
}

function connect() {
  const ws = new WebSocket(`ws://${location.host}/ws`);
  ws.onmessage = ev => {
    const data = JSON.parse(ev.data);
    (Array.isArray(data) ? data : [data]).forEach(handle);
  };
  ws.onclose = () => {
    const pill = $("link-status");
    pill.className = "pill stale";
    pill.textContent = "the station is gone: reconnecting";
    setTimeout(connect, 1000);
  };
}

window.addEventListener("load", start);
