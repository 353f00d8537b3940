// The live layer (an SVG over the floor canvas): robots, formations, intersection grants and
// waits, and the selected order's remaining routes. Everything here is redrawn on each live
// update, so its cost is proportional to robots, grants and route waypoints, never to the
// floor. Each robot is a <g class="robot" data-robot-id data-x data-y data-state>, with
// data-x/data-y the map coordinates it was drawn at (what the browser test reads) and
// data-kind its kind (a four-wheel-steer robot is drawn as its footprint, rect.footprint).
"use strict";
window.WebMap = window.WebMap || {};

(function (WM) {
  const SVG = "http://www.w3.org/2000/svg";
  const STATE_COLOURS = {
    idle: "#9ca3af", moving: "#3b82f6", working: "#22c55e", charging: "#eab308",
    fault: "#ef4444", blocked: "#f97316", offline: "#1f2937",
  };
  const UNKNOWN_STATE = "#a855f7";
  const FORMATION = "#7c3aed";
  const STOP_ACTIONS = new Set(["pick", "drop", "park", "charge"]);  // marked on a route
  // A four-wheel-steer robot's rectangle, metres: the engine's default footprint
  // (engine/motion/footprint.h; the robots do not send theirs).
  const FOOTPRINT = { length: 0.8, width: 0.5 };

  function stateColour(state) { return STATE_COLOURS[state] || UNKNOWN_STATE; }

  // A robot's own colour (its id tag, its route, the intersections it holds): spread over
  // the hue circle by the golden angle from the number in its id, so R1..R18 differ.
  function robotColour(id, alpha = 1) {
    const m = /(\d+)\s*$/.exec(id);
    let n = m ? parseInt(m[1], 10) : 0;
    if (!m) for (const ch of String(id)) n = (n * 31 + ch.charCodeAt(0)) >>> 0;
    return `hsla(${Math.round((n * 137.508) % 360)}, 70%, 40%, ${alpha})`;
  }

  function el(tag, attrs, parent) {
    const e = document.createElementNS(SVG, tag);
    for (const [k, v] of Object.entries(attrs || {})) e.setAttribute(k, v);
    if (parent) parent.appendChild(e);
    return e;
  }

  function setAttrs(e, attrs) {
    for (const [k, v] of Object.entries(attrs)) {
      const s = String(v);
      if (e.getAttribute(k) !== s) e.setAttribute(k, s);
    }
  }

  const f1 = v => (Math.round(v * 10) / 10).toString();

  class LiveLayer {
    constructor(svg) {
      this.svg = svg;
      this.layers = {};
      for (const name of ["grants", "routes", "formations", "waits", "robots"]) {
        this.layers[name] = svg.querySelector("#" + name);
      }
      this.robotEls = new Map();  // robot id -> {g, body, heading, hold, tag, label, title}
      this.drawn = [];            // [{id, x, y, state}] as last drawn
    }

    // data: {view, floor, robots, intersections, formations: [{order, members}],
    //        selected: {robots: Set, routes: {robot: [waypoints]}} | null}
    render(data) {
      const v = data.view;
      this.svg.setAttribute("width", v.width); this.svg.setAttribute("height", v.height);
      const byId = new Map(data.robots.map(r => [r.id, r]));
      this.renderGrants(v, data.floor, data.intersections, byId);
      this.renderRoutes(v, data.selected, byId);
      this.renderFormations(v, data.formations, byId);
      this.renderRobots(v, data.robots, data.selected);
    }

    renderRobots(v, robots, selected) {
      const seen = new Set();
      const labels = robots.length <= 400;
      this.drawn = [];
      for (const r of robots) {
        if (!isFinite(r.x) || !isFinite(r.y)) continue;
        seen.add(r.id);
        let e = this.robotEls.get(r.id);
        if (!e) e = this.createRobot(r.id);
        const px = v.sx(r.x), py = v.sy(r.y);
        const radius = Math.max(5, ((r.diameter || 0.5) / 2) * v.scale);
        const state = r.connected === false && r.state !== "offline" ? "offline" : (r.state || "unknown");
        const classes = ["robot", "state-" + state];
        if (r.held) classes.push("held");
        if (selected && selected.robots.has(r.id)) classes.push("selected");
        setAttrs(e.g, {
          class: classes.join(" "), "data-x": r.x, "data-y": r.y, "data-state": state,
          transform: `translate(${f1(px)},${f1(py)})`,
        });
        const h = Number(r.heading) || 0;  // radians, counter-clockwise from +x in map axes
        // A four-wheel-steer robot: its rectangular footprint, turned to its heading (it may
        // crab, so the heading is not where it drives); every other robot: a disc.
        const steer = r.kind === "four_wheel_steer";
        e.g.setAttribute("data-kind", r.kind || "unknown");
        e.body.style.display = steer ? "none" : "";
        e.footprint.style.display = steer ? "" : "none";
        setAttrs(e.body, { r: f1(radius), fill: stateColour(state) });
        if (steer) {
          const len = Math.max(10, FOOTPRINT.length * v.scale), wid = Math.max(6, FOOTPRINT.width * v.scale);
          setAttrs(e.footprint, { x: f1(-len / 2), y: f1(-wid / 2), width: f1(len), height: f1(wid),
            transform: `rotate(${f1(-h * 180 / Math.PI)})`, fill: stateColour(state) });
        }
        setAttrs(e.hold, { r: f1(radius + 3) });
        setAttrs(e.heading, { x2: f1(Math.cos(h) * radius), y2: f1(-Math.sin(h) * radius) });
        e.tag.style.display = labels ? "" : "none";
        setAttrs(e.tag, { transform: `translate(0,${f1(-radius - 3)})` });
        if (e.label.textContent !== r.id) e.label.textContent = r.id;
        const orders = (r.orders || []).join(", ") || "no order";
        const hold = r.held ? `\nheld: ${r.hold_reason || "(no reason given)"}` : "";
        const title = `${r.id}: ${state}, ${orders}${r.point ? " at " + (r.point.name || r.point.point_id) : ""}${hold}`;
        if (e.title.textContent !== title) e.title.textContent = title;
        this.drawn.push({ id: r.id, x: r.x, y: r.y, state });
      }
      for (const [id, e] of this.robotEls) {
        if (!seen.has(id)) { e.g.remove(); this.robotEls.delete(id); }
      }
    }

    createRobot(id) {
      const g = el("g", { class: "robot", "data-robot-id": id }, this.layers.robots);
      const title = el("title", {}, g);
      const body = el("circle", { class: "body", cx: 0, cy: 0, stroke: robotColour(id) }, g);
      const footprint = el("rect", { class: "footprint", rx: 1, stroke: robotColour(id) }, g);
      footprint.style.display = "none";
      const heading = el("line", { class: "heading", x1: 0, y1: 0 }, g);
      const hold = el("circle", { class: "hold-mark", cx: 0, cy: 0 }, g);
      const tag = el("g", { class: "tag" }, g);
      const w = 7 * id.length + 6;
      el("rect", { x: -w / 2, y: -13, width: w, height: 13, rx: 3, fill: robotColour(id) }, tag);
      const label = el("text", { x: 0, y: -3, "text-anchor": "middle" }, tag);
      const e = { g, body, footprint, heading, hold, tag, label, title };
      this.robotEls.set(id, e);
      return e;
    }

    // Formation orders in progress: their members joined by one hull with the order id.
    renderFormations(v, formations, byId) {
      const layer = this.layers.formations;
      layer.replaceChildren();
      for (const f of formations) {
        const members = f.members.map(id => byId.get(id)).filter(r => r && isFinite(r.x));
        if (members.length < 2) continue;
        const pts = members.map(r => ({ x: v.sx(r.x), y: v.sy(r.y) }));
        const pad = Math.max(9, 0.5 * v.scale * Math.max(...members.map(r => r.diameter || 0.5)) + 5);
        const hull = WM.Floor.paddedHull(pts, pad);  // around the robots' bodies, in pixels
        el("polygon", {
          class: "formation", points: hull.map(p => `${f1(p.x)},${f1(p.y)}`).join(" "),
          fill: FORMATION, stroke: FORMATION, "data-order-id": f.order,
        }, layer);
        // The order id under the hull, clear of the members' own id tags.
        const cx = pts.reduce((s, p) => s + p.x, 0) / pts.length, bottom = Math.max(...pts.map(p => p.y));
        el("text", { class: "formation-label", x: f1(cx), y: f1(bottom + pad + 12), "text-anchor": "middle" }, layer)
          .textContent = f.order;
      }
    }

    // Held intersections: the inner region in the (first) holder's colour; a dashed line from
    // each waiting robot to the region.
    renderGrants(v, floor, intersections, byId) {
      const grants = this.layers.grants, waits = this.layers.waits;
      grants.replaceChildren(); waits.replaceChildren();
      for (const i of intersections) {
        const holders = i.holders || [], waiting = i.waiting || [];
        if (!holders.length && !waiting.length) continue;
        const known = floor.intersections.get(String(i.id));
        const hull = known ? known.region
          : WM.Floor.paddedHull((i.inner || []).map(floor.ref).filter(Boolean), WM.Floor.REGION_PAD_M);
        if (!hull.length) continue;
        const cx = v.sx(hull.reduce((s, p) => s + p.x, 0) / hull.length);
        const cy = v.sy(hull.reduce((s, p) => s + p.y, 0) / hull.length);
        if (holders.length) {
          const colour = robotColour(holders[0]);
          el("polygon", {
            class: "grant", "data-intersection-id": i.id, "data-holders": holders.join(" "),
            points: hull.map(p => `${f1(v.sx(p.x))},${f1(v.sy(p.y))}`).join(" "),
            fill: colour,
          }, grants);
        }
        for (const id of waiting) {
          const r = byId.get(id);
          if (!r || !isFinite(r.x)) continue;
          el("line", { class: "wait", x1: f1(v.sx(r.x)), y1: f1(v.sy(r.y)), x2: f1(cx), y2: f1(cy) }, waits);
        }
      }
    }

    // The selected order's remaining waypoints per robot, from where the robot is now:
    // solid while released to the robot, dashed beyond the last release.
    renderRoutes(v, selected, byId) {
      const layer = this.layers.routes;
      layer.replaceChildren();
      if (!selected || !selected.routes) return;
      for (const [id, wps] of Object.entries(selected.routes)) {
        if (!Array.isArray(wps) || !wps.length) continue;
        const colour = robotColour(id), r = byId.get(id);
        const pts = skipPassed(r, wps.filter(w => isFinite(w.x) && isFinite(w.y)));
        const start = r && isFinite(r.x) ? [{ x: r.x, y: r.y, released: true }] : [];
        const all = start.concat(pts);
        const cut = all.reduce((k, w, j) => (w.released !== false ? j : k), 0);
        const line = (seg, cls) => {
          if (seg.length < 2) return;
          el("polyline", {
            class: cls, stroke: colour, "data-route-of": id,
            points: seg.map(w => `${f1(v.sx(w.x))},${f1(v.sy(w.y))}`).join(" "),
          }, layer);
        };
        line(all.slice(0, cut + 1), "route released");
        line(all.slice(cut), "route pending");
        for (const w of pts) {
          if (!STOP_ACTIONS.has(w.action)) continue;
          el("circle", { class: "route-stop", cx: f1(v.sx(w.x)), cy: f1(v.sy(w.y)), r: 4, stroke: colour }, layer)
            .appendChild(document.createElementNS(SVG, "title")).textContent = `${id}: ${w.action}`;
        }
      }
    }
  }

  // The route starts at the next waypoint to reach, but a robot's position can be a report
  // ahead of its last "waypoint reached" (more so at a high time scale): drop the leading
  // waypoints of segments the robot is already driving along, so the line never runs back.
  function skipPassed(robot, wps) {
    if (!robot || !isFinite(robot.x)) return wps;
    let k = 0;
    while (k + 1 < wps.length && k < 8 && onSegment(robot, wps[k], wps[k + 1])) k++;
    return k ? wps.slice(k) : wps;
  }

  function onSegment(p, a, b, tolerance = 0.3) {
    const dx = b.x - a.x, dy = b.y - a.y, len2 = dx * dx + dy * dy;
    if (len2 < 1e-9) return Math.hypot(p.x - a.x, p.y - a.y) < tolerance;
    const t = ((p.x - a.x) * dx + (p.y - a.y) * dy) / len2;
    if (t <= 0 || t > 1) return false;
    return Math.hypot(p.x - (a.x + t * dx), p.y - (a.y + t * dy)) < tolerance;
  }

  WM.Live = { LiveLayer, STATE_COLOURS, FORMATION, stateColour, robotColour };
})(window.WebMap);
