// The page's archive browser (the Archive tab): the sessions of the
// station's archive, and for the one chosen a plot of its elements — the
// station thins each to at most a few thousand points of the range shown
// and sends a zoomed range anew — its state transitions, its commands and
// its notes. Uses ground.js's helpers ($, el, fmt, COLORS). docs/ground.md.
"use strict";

const MARK_COLORS = { command: "#20262e", note: "#c0392b" };
const arch = {
  loaded: false,     // the sessions list asked for once
  session: null,     // the chosen session's id
  info: null,        // its header and elements (GET /api/archive/ID)
  picked: [],
  chart: null,
  view: null,        // [from, to] shown, s from the session's start
  whole: true,       // the view is the whole session (a live one's grows at each reload)
  events: null,      // its transitions, commands and notes
  asked: 0,          // the number of the newest request for samples: older answers are dropped
};

const pad2 = n => String(n).padStart(2, "0");

// a host time (s since the epoch) in this browser's local time, as `fsw archive list` writes it
function clock(t) {
  if (t === null || t === undefined) return "—";
  const d = new Date(t * 1000);
  return `${d.getFullYear()}-${pad2(d.getMonth() + 1)}-${pad2(d.getDate())} ` +
         `${pad2(d.getHours())}:${pad2(d.getMinutes())}:${pad2(d.getSeconds())}`;
}

function hms(s) {
  s = Math.max(0, Math.round(s));
  return `${Math.floor(s / 3600)}:${pad2(Math.floor(s / 60) % 60)}:${pad2(s % 60)}`;
}

// GET a JSON answer; an Error with the station's words when it refuses
async function askJSON(url) {
  const r = await fetch(url);
  let body = null;
  try { body = await r.json(); } catch (e) { body = null; }
  if (!r.ok || !body || body.ok === false) {
    throw new Error(body && body.words ? body.words : `${url}: ${r.status} ${r.statusText}`);
  }
  return body;
}

function archiveError(text) { $("archive-err").textContent = text || ""; }

// ---- tabs ---------------------------------------------------------------------

function showTab(name) {
  $("live").hidden = name !== "live";
  $("archive").hidden = name !== "archive";
  $("tab-live").className = name === "live" ? "on" : "";
  $("tab-archive").className = name === "archive" ? "on" : "";
  if (name === "archive" && !arch.loaded) loadSessions();
}

function fromHash() {
  // #archive, or #archive/ID: the archive tab (with session ID chosen)
  const m = /^#archive(?:\/(.*))?$/.exec(location.hash);
  if (!m) { showTab("live"); return; }
  showTab("archive");
  if (m[1] !== undefined && m[1] !== String(arch.session)) openSession(decodeURIComponent(m[1]));
}

// ---- the sessions ---------------------------------------------------------------

async function loadSessions() {
  arch.loaded = true;
  archiveError("");
  let r;
  try { r = await askJSON("/api/archive/sessions"); } catch (e) { archiveError(e.message); return; }
  const body = $("session-table").tBodies[0];
  if (r.archive === null) {
    $("archive-where").textContent = r.words;
    body.replaceChildren();
    return;
  }
  const n = r.sessions.length;
  $("archive-where").textContent = `${r.archive}: ${n} session${n === 1 ? "" : "s"}` +
    (n ? "; choose one to see it" : "");
  body.replaceChildren(...r.sessions.slice().reverse().map(s => {
    const tr = el("tr", { id: `session-${s.id}`, class: s.id === arch.session ? "chosen" : "" });
    const id = el("td", {}, String(s.id));
    if (s.live) id.append(el("span", { class: "pill live", title: "the session the station is writing now" }, "live"));
    const ended = s.live ? "running" : s.ended === null ? "not ended" : clock(s.ended);
    for (const c of [id, s.project, s.port, clock(s.started), ended, hms(s.duration), s.frames, s.commands]) {
      tr.append(c instanceof Node ? c : el("td", {}, String(c)));
    }
    tr.addEventListener("click", () => { location.hash = `#archive/${s.id}`; });
    return tr;
  }));
}

// ---- one session ------------------------------------------------------------------

function element(name) { return arch.info.elements.find(e => e.name === name); }
function isStepped(e) { return e.kind === "bool" || !!e.states; }

async function openSession(id) {
  archiveError("");
  let r;
  try { r = await askJSON(`/api/archive/${encodeURIComponent(id)}`); } catch (e) {
    archiveError(e.message);
    return;
  }
  arch.session = r.session.id;
  arch.info = r.session;
  arch.view = null;
  arch.events = null;
  for (const tr of $("session-table").tBodies[0].rows) tr.classList.toggle("chosen", tr.id === `session-${arch.session}`);
  for (const s of ["archive-view", "archive-transitions", "archive-commands", "archive-notes"]) $(s).hidden = false;
  const i = arch.info;
  $("archive-title").textContent = `Session ${i.id}${i.live ? " (live)" : ""}: ${i.project} on ${i.port}, ` +
    `${clock(i.started)}, ${hms(i.span)} — ${i.name} (schema ${i.schema})`;
  $("archive-reload").hidden = !i.live;
  const base = `/api/archive/${i.id}/export`;
  $("archive-csv").href = `${base}.csv`;
  $("archive-parquet").href = `${base}.parquet`;
  buildArchivePicker();
  makeArchiveChart();
  await Promise.all([loadRange(null), loadEvents()]);
}

function buildArchivePicker() {
  const box = $("archive-picker");
  const candidates = arch.info.elements.slice(1);  // all but the time
  const first = candidates.filter(e => !isStepped(e)).slice(0, 2).map(e => e.name)
    .concat(candidates.filter(isStepped).slice(0, 1).map(e => e.name));
  box.replaceChildren(...candidates.map(e => {
    const cb = el("input", { type: "checkbox", id: `apick-${e.name}` });
    cb.checked = first.includes(e.name);
    cb.addEventListener("change", () => {
      arch.picked = candidates.filter(c => $(`apick-${c.name}`).checked).map(c => c.name);
      makeArchiveChart();
      loadRange(arch.whole ? null : arch.view);
    });
    const lab = el("label");
    lab.append(cb, " " + e.name);
    return lab;
  }));
  arch.picked = first;
}

function stateLabel(e, v) {
  if (v === null || v === undefined) return "—";
  if (e.states) return e.states[String(v)] || String(v);
  if (e.kind === "bool") return v ? "true" : "false";
  return fmt(v);
}

function makeArchiveChart() {
  if (arch.chart) arch.chart.destroy();
  const els = arch.picked.map(element);
  const anyStep = els.some(isStepped), anyLine = els.some(e => !isStepped(e));
  // bools (0, 1) and state ids on their own axis, at the right when numbers take the left: a state's
  // name for each id when one state element is drawn
  const steps = els.filter(isStepped);
  const top = Math.max(1, ...steps.map(e => e.states ? Math.max(...Object.keys(e.states).map(Number)) : 1));
  const named = steps.length === 1 ? steps[0] : null;
  const axes = [{ label: "time from the session's start (s)" }];
  if (anyLine) axes.push({ scale: "y" });
  if (anyStep) {
    axes.push({ scale: "step", side: anyLine ? 1 : 3, grid: { show: !anyLine }, size: named && named.states ? 120 : 50,
                splits: () => Array.from({ length: top + 1 }, (_, i) => i),
                values: (u, splits) => splits.map(v => named ? stateLabel(named, v) : String(v)) });
  }
  const opts = {
    width: Math.max(300, $("archive-chart").clientWidth || 900), height: 300,
    scales: {
      x: { time: false, range: (u, lo, hi) => arch.view || [lo ?? 0, hi ?? 1] },
      step: { range: () => [-0.3, top + 0.3] },
    },
    axes,
    series: [{ label: "t (s)", value: (u, v) => v === null || v === undefined ? "—" : v.toFixed(3) }]
      .concat(els.map((e, i) => {
        const s = { label: e.name, stroke: COLORS[i % COLORS.length], width: 1.5, scale: isStepped(e) ? "step" : "y",
                    value: (u, v) => stateLabel(e, v) };
        if (isStepped(e)) s.paths = uPlot.paths.stepped({ align: 1 });
        return s;
      })),
    cursor: {
      drag: { x: true, y: false, setScale: false },  // a drag asks the station for that range (setSelect)
      bind: { dblclick: () => () => { loadRange(null); return null; } },
    },
    hooks: {
      setSelect: [u => {
        if (u.select.width < 3) return;
        const a = u.posToVal(u.select.left, "x"), b = u.posToVal(u.select.left + u.select.width, "x");
        u.setSelect({ left: 0, top: 0, width: 0, height: 0 }, false);
        loadRange([a, b]);
      }],
      draw: [drawMarks],
    },
  };
  arch.chart = new uPlot(opts, [[]].concat(els.map(() => [])), $("archive-chart"));
}

// the commands and the station's notes as vertical lines across the plot
function drawMarks(u) {
  if (!arch.events) return;
  const { ctx } = u;
  const top = u.bbox.top, height = u.bbox.height;
  ctx.save();
  ctx.lineWidth = 1;
  for (const [kind, list] of [["command", arch.events.commands], ["note", arch.events.notes]]) {
    ctx.strokeStyle = MARK_COLORS[kind];
    ctx.setLineDash(kind === "note" ? [2, 3] : [6, 3]);
    for (const m of list) {
      if (m.t < u.scales.x.min || m.t > u.scales.x.max) continue;
      const x = Math.round(u.valToPos(m.t, "x", true));
      ctx.beginPath();
      ctx.moveTo(x, top);
      ctx.lineTo(x, top + height);
      ctx.stroke();
    }
  }
  ctx.restore();
}

// asks for the chosen elements over `range` ([from, to] in s; null: the whole session)
async function loadRange(range) {
  const asked = ++arch.asked;
  const id = arch.session;
  const w = $("archive-chart").clientWidth || 900;
  const points = Math.max(200, Math.min(5000, Math.round(2 * w * (window.devicePixelRatio || 1))));
  let q = `elements=${encodeURIComponent(arch.picked.join(","))}&points=${points}`;
  if (range) q += `&from=${range[0]}&to=${range[1]}`;
  $("archive-range").textContent = "asking the station…";
  let r;
  try { r = await askJSON(`/api/archive/${id}?${q}`); } catch (e) {
    if (asked === arch.asked) { archiveError(e.message); $("archive-range").textContent = ""; }
    return;
  }
  if (asked !== arch.asked || id !== arch.session) return;  // a newer question is on its way
  archiveError("");
  arch.info = r.session;
  arch.view = [r.from, r.to];
  arch.whole = range === null;
  const tables = r.series.map(s => [s.x, s.y]);
  const data = tables.length ? uPlot.join(tables) : [[r.from, r.to]];
  arch.chart.setData(data);
  const drawn = r.series.reduce((n, s) => n + s.x.length, 0);
  $("archive-chart").dataset.points = String(drawn);
  const whole = r.from <= 0 && r.to >= r.session.span;
  const counts = r.series.map(s => s.thinned ? `${s.name} ${s.x.length} of ${s.total} samples`
                                             : `${s.name} ${s.total} samples`);
  $("archive-range").textContent = `${r.from.toFixed(2)}–${r.to.toFixed(2)} s` +
    (whole ? " (the whole session)" : ` of ${r.session.span.toFixed(2)} s`) +
    (counts.length ? `: ${counts.join(", ")}` : ": tick an element to plot it") +
    (r.series.some(s => s.thinned) ? " (thinned: the least and greatest value of each span a pixel wide)" : "");
  $("archive-part").hidden = whole;
  const part = `from=${r.from}&to=${r.to}`;
  $("archive-csv-range").href = `/api/archive/${id}/export.csv?${part}`;
  $("archive-parquet-range").href = `/api/archive/${id}/export.parquet?${part}`;
}

async function loadEvents() {
  const id = arch.session;
  let r;
  try { r = await askJSON(`/api/archive/${id}/events`); } catch (e) { archiveError(e.message); return; }
  if (id !== arch.session) return;
  arch.events = r;
  const at = t => `${t.toFixed(2)} s`;
  const zoomTo = (li, t) => {
    li.dataset.t = String(t);
    li.title = "click: the plot around it";
    li.addEventListener("click", () => loadRange([Math.max(0, t - 5), Math.min(arch.info.span, t + 5)]));
    return li;
  };
  const more = n => n ? [el("li", {}, `and ${n} more`)] : [];
  const tr = r.transitions.map(x => zoomTo(el("li", {},
    `${at(x.t)}  ${x.machine}: ${x.from === null ? "starts in " + x.to : x.from + " → " + x.to}`), x.t));
  $("archive-transition-list").replaceChildren(...(tr.length ? tr : [el("li", {}, "none")]), ...more(r.more.transitions));
  const body = $("archive-command-table").tBodies[0];
  body.replaceChildren(...r.commands.map(c => {
    const row = el("tr");
    const answer = c.status === null ? c.words : c.ok ? `applied (${(1000 * c.acked).toFixed(0)} ms)`
      : `refused: ${c.words}`;
    row.append(el("td", {}, at(c.t)), el("td", {}, c.who), el("td", {}, c.text),
               el("td", { class: c.ok ? "ok" : "refused" }, answer));
    row.addEventListener("click", () => loadRange([Math.max(0, c.t - 5), Math.min(arch.info.span, c.t + 5)]));
    return row;
  }));
  if (r.more.commands) {
    const row = el("tr");
    row.append(el("td", { colspan: 4 }, `and ${r.more.commands} more`));
    body.append(row);
  }
  const notes = r.notes.map(n => zoomTo(el("li", {}, `${at(n.t)}  (${clock(arch.info.started + n.t)})  ${n.text}`), n.t));
  $("archive-note-list").replaceChildren(...(notes.length ? notes : [el("li", {}, "none")]), ...more(r.more.notes));
  if (arch.chart) arch.chart.redraw(false);
}

function startArchive() {
  $("tab-live").addEventListener("click", () => { location.hash = ""; });
  $("tab-archive").addEventListener("click", () => {
    location.hash = arch.session === null ? "#archive" : `#archive/${arch.session}`;
  });
  $("archive-refresh").addEventListener("click", loadSessions);
  $("archive-whole").addEventListener("click", () => loadRange(null));
  $("archive-reload").addEventListener("click", () => { loadRange(arch.whole ? null : arch.view); loadEvents();
                                                           loadSessions(); });
  window.addEventListener("hashchange", fromHash);
  fromHash();
}

window.addEventListener("load", startArchive);
