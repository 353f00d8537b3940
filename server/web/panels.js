// The side panels and the header: status line, fetch problems, the order list, the selected
// order's details (its robots, remaining waypoints and allocation explanation: the bids
// table and the reason), the held intersections and the legend. Plain DOM; each panel is
// rebuilt only when its content changed.
"use strict";
window.WebMap = window.WebMap || {};

(function (WM) {
  const $ = id => document.getElementById(id);
  const esc = s => String(s ?? "").replace(/[&<>"']/g, c => ({ "&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;", "'": "&#39;" }[c]));
  const num = (v, digits = 1) => (typeof v === "number" && isFinite(v) ? v.toFixed(digits) : "–");
  const STATES = ["accepted", "assigned", "in_progress", "completed", "cancelled", "failed"];
  const ACTIVE = new Set(["accepted", "assigned", "in_progress"]);
  const MAX_FINISHED_LISTED = 100;

  function setHtml(node, html) { if (node._html !== html) { node.innerHTML = html; node._html = html; } }

  function robotTag(id) {
    return `<span class="rtag" style="background:${WM.Live.robotColour(id)}">${esc(id)}</span>`;
  }
  const stateBadge = s => `<span class="badge state-${esc(s)}">${esc(String(s || "?").replace("_", " "))}</span>`;

  // ---- header -----------------------------------------------------------------------------
  function renderStatus(s) {
    const parts = [];
    parts.push(`<b>${esc(s.map || "?")}</b>`);
    parts.push(`t ${num(s.time)} s${s.time_scale && s.time_scale !== 1 ? ` (×${esc(s.time_scale)})` : ""}`);
    const o = s.orders || {};
    const counts = STATES.filter(k => o[k]).map(k => `${o[k]} ${k.replace("_", " ")}`);
    parts.push(`orders: ${counts.length ? counts.join(", ") : "none"}`);
    if (s.robots) parts.push(`robots ${esc(s.robots.connected)}/${esc(s.robots.total)} connected`);
    const t = s.traffic || {};
    const m = t.min_robot_distance;
    parts.push(m ? `min distance ${num(m.distance, 2)} m (${(m.robots || []).map(esc).join("–")}, t ${num(m.time)} s)`
      : "min distance –");
    if (t.control === false) parts.push("traffic control off");
    else parts.push(`grants ${esc(t.grants ?? "–")} · holds ${esc(t.holds ?? "–")} · replans ${esc(t.replans ?? "–")}` +
      ` · deadlocks resolved ${esc(t.deadlocks_resolved ?? "–")}`);
    setHtml($("status"), parts.join('<span class="sep">·</span>'));
  }

  // problems: Map source -> {message, network}
  function renderProblems(problems) {
    const node = $("problems");
    if (!problems.size) { node.hidden = true; setHtml(node, ""); return; }
    const all = [...problems.values()];
    const head = all.every(p => p.network) ? "server unreachable, retrying…" : "some requests fail, retrying…";
    const bySymptom = new Map();  // message -> sources, one line each
    for (const [src, p] of problems) bySymptom.set(p.message, (bySymptom.get(p.message) || []).concat(src));
    const lines = [...bySymptom].map(([msg, srcs]) => `<li>${srcs.map(s => `<code>${esc(s)}</code>`).join(", ")}: ${esc(msg)}</li>`);
    node.hidden = false;
    setHtml(node, `<b>${head}</b><ul>${lines.join("")}</ul>`);
  }

  // ---- orders -----------------------------------------------------------------------------
  // finishedTotal: how many finished orders the server has (it lists only the newest).
  function renderOrders(orders, selectedId, finishedTotal) {
    const active = orders.filter(o => ACTIVE.has(o.state)).sort((a, b) => String(a.id).localeCompare(String(b.id)));
    const done = orders.filter(o => !ACTIVE.has(o.state))
      .sort((a, b) => (b.finished_time ?? 0) - (a.finished_time ?? 0) || String(b.id).localeCompare(String(a.id)));
    const shown = active.concat(done.slice(0, MAX_FINISHED_LISTED));
    const items = shown.map(o => {
      const robots = (o.robots || []).map(robotTag).join("");
      return `<li class="order${o.id === selectedId ? " selected" : ""}" data-order-id="${esc(o.id)}" tabindex="0">` +
        `<span class="oid">${esc(o.id)}</span>${stateBadge(o.state)}<span class="fmark"${o.formation ? ' title="formation">▲' : ">"}</span>` +
        `<span class="client">${esc(o.client_id)}</span><span class="robots">${robots}</span></li>`;
    });
    const finished = Math.max(done.length, finishedTotal ?? 0);
    if (finished > MAX_FINISHED_LISTED) items.push(`<li class="more">… ${finished - Math.min(done.length, MAX_FINISHED_LISTED)} older finished orders</li>`);
    if (!items.length) items.push('<li class="more">no orders yet</li>');
    setHtml($("orders"), items.join(""));
    setHtml($("order-counts"), `${active.length} active, ${finished} finished`);
  }

  // ---- the selected order -----------------------------------------------------------------
  function renderDetail(o) {
    $("detail-panel").hidden = !o;
    if (!o) return;
    setHtml($("detail-title"), esc(o.id));
    const stop = s => (s ? esc(s.name || s.point_id || `(${num(s.x)}, ${num(s.y)})`) : "?");
    const rows = [
      ["state", stateBadge(o.state) + (o.reason ? ` <span class="muted">${esc(o.reason)}</span>` : "")],
      ["client id", esc(o.client_id)],
      ["robots", (o.robots || []).map(robotTag).join("") || "–"],
      ["route", `${(o.picks || []).map(stop).join(" → ")} ⇒ ${stop(o.drop)}`],
      ["kind", `${o.formation ? "formation" : "single robot"}, priority ${esc(o.priority ?? 0)}, work ${num(o.work_time)} s`],
      ["times", `created ${num(o.created_time)} s${o.finished_time != null ? `, finished ${num(o.finished_time)} s` : ""}`],
    ];
    if (o.distance) rows.push(["distance", `${num(o.distance)} m`]);
    if (o.routes && typeof o.routes === "object") {
      const left = Object.entries(o.routes).map(([id, w]) => `${robotTag(id)} ${Array.isArray(w) ? w.length : 0}`);
      rows.push(["waypoints left", left.join(" ") || "none"]);
    }
    let html = `<table class="facts">${rows.map(([k, v]) => `<tr><th>${k}</th><td>${v}</td></tr>`).join("")}</table>`;
    html += allocationHtml(o.allocation);
    setHtml($("detail"), html);
  }

  function allocationHtml(a) {
    if (!a) return '<p class="muted">No allocation explanation yet (the order has not been allocated).</p>';
    // A formation's explanation has leader bids and companion bids; winners[0] is the leader.
    const companions = a.companion_bids && a.companion_bids.length ? a.companion_bids : null;
    const all = a.winners || [];
    let html = `<h3>Allocation <span class="muted">${esc(a.strategy || "")} · α ${esc(a.alpha ?? "–")} · ` +
      `β ${esc(a.beta ?? "–")} · ζ ${esc(a.zeta ?? "–")} · t ${num(a.time)} s</span></h3>`;
    html += `<p class="reason">${esc(a.reason || "no reason given")}</p>`;
    html += bidsTable(a.bids || [], a.bids_total, new Set(companions ? all.slice(0, 1) : all),
                      companions ? "leader bids" : "bids");
    if (companions) {
      html += bidsTable(companions, a.companion_bids_total, new Set(all.slice(1)),
                        "companion bids (cost to reach the first pick)");
    }
    return html;
  }

  // `total`: how many there were (the explanation keeps the winners' and the lowest others').
  function bidsTable(bids, total, winners, caption) {
    const key = b => (b.reachable === false || b.priced === false ? Infinity : b.bid ?? Infinity);
    const sorted = [...bids].sort((x, y) => key(x) - key(y));
    const rows = sorted.map(b => {
      const win = winners.has(b.robot);
      const note = b.queue_full ? "queue full" : b.reachable === false ? "unreachable" : b.priced === false ? "not priced" : "";
      return `<tr class="bid${win ? " winner" : ""}${note ? " excluded" : ""}" data-robot="${esc(b.robot)}">` +
        `<td>${robotTag(b.robot)}</td><td>${num(b.t_t)}</td><td>${num(b.t_d)}</td><td>${num(b.t_w)}</td>` +
        `<td>${num(b.flow, 4)}</td><td>${note ? `<span class="muted">${note}</span>` : num(b.bid, 2)}</td>` +
        `<td class="win">${win ? "✔" : ""}</td></tr>`;
    });
    const count = total && total > bids.length ? `the lowest ${bids.length} of ${total}` : `${bids.length}`;
    return `<table class="bids"><caption>${esc(caption)} (${count})</caption>` +
      `<thead><tr><th>robot</th><th title="total time">T<sub>t</sub></th><th title="driving time">T<sub>d</sub></th>` +
      `<th title="waiting time">T<sub>w</sub></th><th title="traffic flow term">F</th><th>bid</th><th title="winner">win</th></tr></thead>` +
      `<tbody>${rows.join("")}</tbody></table>`;
  }

  // ---- intersections ----------------------------------------------------------------------
  function renderIntersections(list) {
    const busy = list.filter(i => (i.holders && i.holders.length) || (i.waiting && i.waiting.length));
    const held = busy.filter(i => i.holders && i.holders.length).length;
    const waiting = busy.reduce((n, i) => n + (i.waiting ? i.waiting.length : 0), 0);
    setHtml($("grant-count"), `${held} held, ${waiting} waiting`);
    const items = busy.sort((a, b) => String(a.id).localeCompare(String(b.id))).map(i =>
      `<li data-intersection-id="${esc(i.id)}"><span class="iid">${esc(i.id)}</span>` +
      `<span class="holders">${(i.holders || []).map(robotTag).join("") || '<span class="muted">free</span>'}</span>` +
      ((i.waiting || []).length ? `<span class="waiting">waiting ${i.waiting.map(robotTag).join("")}</span>` : "") + "</li>");
    setHtml($("intersections"), items.join("") || '<li class="more">no grants held</li>');
  }

  // ---- legend -----------------------------------------------------------------------------
  function renderLegend(heatMax) {
    const C = WM.Floor.COLOURS;
    const sw = (style, label, cls = "sw") => `<span class="item"><span class="${cls}" style="${style}"></span>${label}</span>`;
    const states = Object.entries(WM.Live.STATE_COLOURS).map(([s, c]) => sw(`background:${c}`, s, "sw dot"));
    const grad = [0, 0.25, 0.5, 0.75, 1].map(t => WM.Floor.heatColour(t)).join(",");
    const html = [
      `<div class="row"><b>robots</b> ${states.join("")}` +
        `<span class="item"><span class="rtag" style="background:${WM.Live.robotColour("R7")}">R7</span>own colour (ring, route, grant)</span>` +
        sw("", "held", "sw dot heldsw") +
        sw("background:#9ca3af;border:1.5px solid #374151;width:16px;height:10px;border-radius:1px", "four-wheel steer (footprint)") +
        "</div>",
      `<div class="row"><b>floor</b> ${sw(`border-top:2px solid ${C.oneWay}`, "one-way lane →", "sw line")}` +
        sw(`border-top:2px dashed ${C.bidirectional}`, "bidirectional lane ↔", "sw line") +
        sw(`background:${C.pick};transform:rotate(45deg) scale(.8)`, "pick") + sw(`background:${C.drop}`, "drop") +
        sw(`background:${C.park}`, "park", "sw dot") + sw(`background:${C.charge}`, "charge", "sw dot") +
        sw(`background:${C.shelf};border:1px solid ${C.shelfEdge}`, "shelf") +
        sw(`background:${C.intersection}`, "intersection") + sw(`border:1px dashed ${C.zone}`, "zone") + "</div>",
      `<div class="row"><b>live</b> ${sw(`background:${WM.Live.FORMATION}33;border:1px solid ${WM.Live.FORMATION}`, "formation (one agent)")}` +
        sw(`background:${WM.Live.robotColour("R7", 0.5)}`, "intersection held (holder's colour)") +
        sw("border-top:2px dashed #555", "waiting for it", "sw line") +
        sw(`border-top:3px solid ${WM.Live.robotColour("R7")}`, "route released", "sw line") +
        sw(`border-top:3px dotted ${WM.Live.robotColour("R7")}`, "route not yet released", "sw line") + "</div>",
      `<div class="row"><b>zone density</b> <span class="heat" style="background:linear-gradient(90deg,${grad})"></span>` +
        `<span class="muted">0 … ${heatMax.toFixed(3)} robots/m²</span></div>`,
    ].join("");
    setHtml($("legend"), html);
  }

  WM.Panels = { renderStatus, renderProblems, renderOrders, renderDetail, renderIntersections, renderLegend };
})(window.WebMap);
