"""The live page (``GET /``): the run page's world figure, moved by what ``GET /state`` says.

The page is built once by the run page's own code (:func:`experiments.report.page.page`, plotly
inlined: it works offline, no CDN) around :func:`experiments.report.world_figure.world_figure`
drawn at the session's start.  Its script polls ``/state`` and moves the figure's traces — the
path the robot follows (trace 1), its trail (3), the robot (4), the people (5) — opens and closes
the doors (the layout's shapes after the obstacles), writes the time, the roles and the hazards
in the title, and fills the queue: every agent with its role, FSM state and the schedule
parameters of its last report (what Alg. 2 compares), and the harmoniser's last decision.  Forms
request a task, post a world event, change or terminate a task and stop the session, through the
same API as any client (with the page's ``?token=`` when the session has one).
"""

from __future__ import annotations

import html
import json
from typing import TYPE_CHECKING

from experiments.report.page import figure_div, page
from experiments.report.world_figure import world_figure

if TYPE_CHECKING:
    from robot.spec import WorldSpec

POLL_MS = 300
"""How often the page asks for ``/state``."""

COLUMNS = ("", "agent", "task", "args", "role", "FSM state", "cost", "cps", "cTime [s]", "deadline [s]", "priority",
           "requested at [s]", "ended")
"""The queue's columns (the script fills its rows in this order): a live task's controls come first,
so that they stay in sight however long its arguments or another task's end are."""

_STYLE = """<style>
#status{font-family:monospace;background:#f4f4f4;padding:4px 8px}
#queue{border-collapse:collapse;font-size:.9em} #queue th,#queue td{padding:2px 5px;vertical-align:top}
#queue td{white-space:nowrap} #queue td.args,#queue td.end{white-space:normal;overflow-wrap:anywhere;min-width:9em;
max-width:16em} #queue .ended td{color:#999} #queue .exeDA td{background:#eaf2fb}
form{margin:.4em 0} input,select,textarea{font:inherit;margin:0 .3em} .err{color:#c0392b} .ok{color:#2a7a2a}
</style>"""

_FORMS = """
<h2>Request a task</h2>
<form id="request-form">
<label>task <select id="task"></select></label>
<label>args <input id="args" size="60" placeholder='{"person": "john", "destination": "john_destination"}'></label>
<label>priority <input id="priority" size="4"></label>
<label>deadline [s] <input id="deadline" size="6"></label>
<button type="submit">request</button> <span id="request-said"></span>
</form>
<p class="note" id="task-args"></p>
<h2>The world</h2>
<form id="world-form">
<label>event <input id="world-event" size="60" placeholder='{"posture": ["peter", "fallen"], "note": "Peter falls"}'>
</label><button type="submit">post</button> <span id="world-said"></span>
</form>
<form id="stop-form"><button type="submit">stop the session</button> <span id="stop-said"></span>
<span class="note">writes the run folder and session.toml ('tasker run' replays it)</span></form>
"""

_SCRIPT = """
const TOKEN = new URLSearchParams(location.search).get("token");
const DOORS = __DOORS__;
const esc = s => String(s ?? "").replace(/[&<>"']/g, c => ({"&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;",
  "'": "&#39;"}[c]));
const given = args => Object.fromEntries(Object.entries(args).filter(([k, v]) => v !== null));
const num = v => (typeof v === "number") ? (Math.abs(v) >= 1000 ? v.toFixed(0) : v.toPrecision(4)) : (v ?? "–");
async function api(method, path, body) {
  const headers = {"Content-Type": "application/json"};
  if (TOKEN) headers["Authorization"] = "Bearer " + TOKEN;
  const r = await fetch(path, {method, headers, body: body === undefined ? undefined : JSON.stringify(body)});
  return {status: r.status, body: await r.json().catch(() => null)};
}
function said(id, r) {
  const el = document.getElementById(id);
  const ok = r.status < 300;
  el.className = ok ? "ok" : "err";
  el.textContent = ok ? JSON.stringify(r.body) : (r.body && r.body.detail) || ("HTTP " + r.status);
}
let types = null;
function fillTypes(s) {
  if (types || !s.task_types) return;
  types = s.task_types;
  const sel = document.getElementById("task");
  // a type the world cannot take is listed, disabled, saying why; the form starts on the first it can take
  sel.innerHTML = types.map(t => `<option value="${esc(t.name)}"${t.example ? "" : " disabled"}` +
    ` title="${esc(t.refused || "")}">${esc(t.name)}${t.example ? "" : " (not in this world)"}</option>`).join("");
  const first = types.find(t => t.example);
  if (first) sel.value = first.name;
  const show = () => {
    const t = types.find(t => t.name === sel.value);
    document.getElementById("task-args").textContent = t ? "arguments: " + t.args.map(
      a => a.name + (a.required ? "" : "?") + ": " + a.type).join(", ") + (t.refused ? " · " + t.refused : "") : "";
    document.getElementById("args").value = t && t.example ? JSON.stringify(t.example) : "";
  };
  sel.onchange = show; show();
}
function draw(s) {
  const st = document.getElementById("status");
  if (s.status === "starting") { st.textContent = "starting: building the robot and its world…"; return; }
  fillTypes(s);
  st.textContent = `${s.status} · t = ${s.t.toFixed(1)} s · speed ×${s.speed} · ` +
    `behind the clock ${s.lag_s.toFixed(1)} s · mode ${s.mode} · ${s.events} trace events` +
    (s.stop_reason ? " · " + s.stop_reason : "");
  const p = s.robot.pose, path = s.robot.path, trail = s.robot.trail;
  const hx = [p[0], p[0] + 0.45 * Math.cos(p[2])], hy = [p[1], p[1] + 0.45 * Math.sin(p[2])];
  Plotly.restyle("world", {
    x: [path.map(q => q[0]), trail.map(q => q[0]).concat([null], hx), [p[0]], s.people.map(q => q.pose[0])],
    y: [path.map(q => q[1]), trail.map(q => q[1]).concat([null], hy), [p[1]], s.people.map(q => q.pose[1])],
  }, [1, 3, 4, 5]);
  const names = s.people.map(q => q.name + (q.posture === "standing" ? "" : ` (${q.posture})`));
  Plotly.restyle("world", {text: [names]}, [5]);
  const on = s.hazards.filter(h => h.agent).map(h => `${h.name} ${h.fact.slice(1).join(" ")} (${h.agent})`);
  const nobodys = s.hazards.length - on.length;  // e.g. doors open in the world file: nobody's to attend
  if (nobodys) on.push(`${nobodys} nobody owns`);
  const lay = {"title.text": `t = ${s.t.toFixed(1)} s · exeDA: ${s.exeDA || "–"} · irrDA: ${s.irrDA || "–"} · ` +
    `idleDA: ${s.idleDA.join(", ") || "–"} · ` +
    `<span style='color:#c0392b'>hazards on: ${esc(on.join(", ") || "none")}</span>`};
  for (const [name, k] of Object.entries(DOORS)) {
    const open = s.doors[name];
    lay[`shapes[${k}].fillcolor`] = open ? "rgba(0,0,0,0)" : "#7a4f2a";
    lay[`shapes[${k}].line.dash`] = open ? "dash" : "solid";
  }
  Plotly.relayout("world", lay);
  const rows = s.agents.map(a => {
    const q = a.params || {};
    const end = a.ended ? `${esc(a.ended.cause)} at ${num(a.ended.t)}: ${esc(a.ended.reason)}` : "";
    const act = a.ended ? "" : `<button data-term="${esc(a.id)}">terminate</button> ` +
      `<button data-change="${esc(a.id)}">change…</button>`;
    return `<tr class="${a.ended ? "ended" : esc(a.role || "")}"><td class="act">${act}</td>` +
      `<td>${esc(a.id)}</td><td>${esc(a.task)}</td><td class="args">${esc(JSON.stringify(given(a.args)))}</td>` +
      `<td>${esc(a.role || "–")}</td>` +
      `<td>${esc(a.superstate)} / ${esc(a.state)}</td>` +
      `<td class="num">${num(q.cost)}</td><td class="num">${num(q.cps)}</td><td class="num">${num(q.c_time)}</td>` +
      `<td class="num">${num(q.deadline)}</td><td class="num">${num(q.priority)}</td>` +
      `<td class="num">${num(a.requested_at)}</td><td class="end">${end}</td></tr>`;
  });
  document.getElementById("queue-body").innerHTML = rows.join("") ||
    '<tr><td colspan="13">no task yet: request one below</td></tr>';
  document.getElementById("decision").textContent = s.decision ? JSON.stringify(s.decision, null, 1) : "none yet";
}
async function poll() {
  try {
    const r = await api("GET", "/state");
    if (r.status === 200) draw(r.body);
    else document.getElementById("status").textContent = (r.body && r.body.detail) || "HTTP " + r.status;
  } catch (e) {
    document.getElementById("status").textContent = "the session is not answering (stopped?)";
  }
  setTimeout(poll, __POLL__);
}
document.getElementById("queue-body").addEventListener("click", async ev => {
  const t = ev.target.dataset;
  if (t.term) { await api("DELETE", "/requests/" + t.term); }
  if (t.change) {
    const body = prompt(`change ${t.change}: JSON, e.g. {"priority": 3} or {"deadline": 300}`, '{"priority": 1}');
    if (body) {
      let parsedBody;
      try { parsedBody = JSON.parse(body); } catch (e) { alert("not JSON: " + e.message); return; }
      const r = await api("PATCH", "/requests/" + t.change, parsedBody);
      if (r.status >= 300) alert((r.body && r.body.detail) || "HTTP " + r.status); }
  }
});
function parsed(id) { const v = document.getElementById(id).value.trim(); return v ? JSON.parse(v) : undefined; }
document.getElementById("request-form").onsubmit = async ev => {
  ev.preventDefault();
  const body = {task: document.getElementById("task").value};
  try {
    const args = parsed("args"), pr = parsed("priority"), dl = parsed("deadline");
    if (args !== undefined) body.args = args;
    if (pr !== undefined) body.priority = pr;
    if (dl !== undefined) body.deadline = dl;
  } catch (e) { said("request-said", {status: 400, body: {detail: "not JSON: " + e.message}}); return; }
  said("request-said", await api("POST", "/requests", body));
};
document.getElementById("world-form").onsubmit = async ev => {
  ev.preventDefault();
  let body;
  try { body = parsed("world-event"); } catch (e) {
    said("world-said", {status: 400, body: {detail: "not JSON: " + e.message}}); return; }
  said("world-said", await api("POST", "/world", body));
};
document.getElementById("stop-form").onsubmit = async ev => {
  ev.preventDefault();
  if (confirm("Stop the session? It writes the run folder and session.toml, then the server exits."))
    said("stop-said", await api("POST", "/stop"));
};
poll();
"""


def live_page(world: WorldSpec, *, title: str) -> str:
    """The page's HTML for a session in ``world`` (a :class:`robot.spec.WorldSpec`)."""
    fig = world_figure(world, [(0.0, *world.robot.pose)], {}, [], [])
    fig["frames"] = []
    layout = fig["layout"]
    for key in ("sliders", "updatemenus"):
        layout.pop(key, None)
    layout["margin"] = {"t": 60, "r": 10, "b": 40}
    layout["uirevision"] = "live"  # zoom and pan survive the updates
    path = fig["data"][1]
    path.update(name="path it follows", opacity=0.8, line={"color": "#1f5fbf", "width": 1.5, "dash": "dot"}, x=[], y=[])
    doors = {name: len(world.obstacles) + k for k, name in enumerate(world.doors)}
    script = _SCRIPT.replace("__DOORS__", json.dumps(doors)).replace("__POLL__", str(POLL_MS))
    sections = [_STYLE, '<p id="status">connecting…</p>', figure_div(fig, "world"),
                "<h2>Queue</h2>",
                '<p class="note">Every agent: its role, its FSM state (Fig. 5) and the schedule parameters of its '
                "last report, as Alg. 2 reads them; the live ones first, ended ones below them in grey.</p>",
                '<table id="queue"><thead><tr>' + "".join(f"<th>{html.escape(h)}</th>" for h in COLUMNS)
                + '</tr></thead><tbody id="queue-body"></tbody></table>',
                "<h2>The harmoniser's last decision</h2>", '<pre id="decision">none yet</pre>',
                _FORMS, f"<script>{script}</script>"]
    return page(title, sections)
