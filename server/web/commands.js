// The robots panel: every robot with its state and the operator commands in force (paused,
// out of service, cleared off the floor, sent to a station), and, for the selected robot, the
// commands themselves when the token's role may send them (GET /api/v1/session): pause or
// resume, take out of service or return, clear (an offline robot), send to a station. Each
// command is a POST /api/v1/robots/{id}/... (issue 18 §4); its answer or error shows below the
// buttons. Plain DOM, rebuilt only when its content changed.
"use strict";
window.WebMap = window.WebMap || {};

(function (WM) {
  const $ = id => document.getElementById(id);
  const esc = s => String(s ?? "").replace(/[&<>"']/g, c => ({ "&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;", "'": "&#39;" }[c]));
  function setHtml(node, html) { if (node._html !== html) { node.innerHTML = html; node._html = html; } }

  // What an operator should see first about a robot.
  function marks(r) {
    const out = [];
    if (r.out_of_service_by) out.push(`out of service (${esc(r.out_of_service_by)})`);
    if (r.paused_by) out.push(`paused by ${esc(r.paused_by)}`);
    if (r.off_floor) out.push("cleared off the floor");
    if (r.sent_to) out.push(`→ ${esc(r.sent_to.name)}`);
    return out;
  }

  // The POST path and body of each command button (data-command).
  const COMMANDS = {
    pause: { label: "Pause", path: "pause" },
    resume: { label: "Resume", path: "resume" },
    out_of_service: { label: "Take out of service", path: "out-of-service" },
    return_to_service: { label: "Return to service", path: "return-to-service" },
    clear: { label: "Clear off the floor", path: "clear" },
    send: { label: "Send", path: "send" },
  };

  // robots: WM.Api.robot views; session: WM.Api.session or null (not known yet); stations: the
  // floor's station names; note: {ok, text} of the last command, or null.
  function renderRobots(robots, selectedId, session, stations, note) {
    const sorted = [...robots].sort((a, b) => String(a.id).localeCompare(String(b.id), undefined, { numeric: true }));
    const items = sorted.map(r => {
      const m = marks(r);
      return `<li class="robot${r.id === selectedId ? " selected" : ""}" data-robot-id="${esc(r.id)}" tabindex="0">` +
        `<span class="rtag" style="background:${WM.Live.robotColour(r.id)}">${esc(r.id)}</span>` +
        `<span class="rstate">${esc(r.connected ? r.state : "offline")}</span>` +
        `<span class="rmarks">${m.join(" · ")}</span></li>`;
    });
    setHtml($("robot-list"), items.join("") || '<li class="more">no robots yet</li>');
    setHtml($("robot-count"), `${robots.filter(r => r.connected).length}/${robots.length} connected`);

    const box = $("robot-commands");
    const r = robots.find(x => x.id === selectedId);
    box.hidden = !r;
    if (!r) return;
    let html = `<div class="rtitle">${esc(r.id)} <span class="muted">${marks(r).join(" · ") || "no commands in force"}</span></div>`;
    if (!session) {
      html += '<p class="muted">checking what this token may do…</p>';
    } else if (!session.robot_commands) {
      html += `<p class="muted">robot commands need an operator or admin token (this one: ${esc(session.role)}` +
        `${session.name ? " " + esc(session.name) : ""})</p>`;
    } else {
      const button = k => `<button type="button" data-command="${k}">${COMMANDS[k].label}</button>`;
      const buttons = [button(r.paused_by ? "resume" : "pause"),
        button(r.out_of_service_by ? "return_to_service" : "out_of_service")];
      if (!r.connected && !r.off_floor) buttons.push(button("clear"));
      html += `<div class="buttons">${buttons.join("")}</div>`;
      const options = stations.map(s => `<option value="${esc(s)}">${esc(s)}</option>`).join("");
      if (options) {
        html += `<div class="buttons"><label>station <select id="send-station">${options}</select></label>${button("send")}</div>`;
      }
    }
    if (note) html += `<p class="note ${note.ok ? "ok" : "failed"}">${esc(note.text)}</p>`;
    // Keep the chosen station across redraws.
    const chosen = $("send-station") ? $("send-station").value : null;
    setHtml(box, html);
    if (chosen && $("send-station")) $("send-station").value = chosen;
  }

  WM.Commands = { renderRobots, COMMANDS };
})(window.WebMap);
