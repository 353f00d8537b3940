// The REST API's bodies are the proto3 JSON mapping of operator.proto and orders.proto
// (proto field names, enums by name, 64-bit integers as strings, absent optional fields left
// out). This turns them into what the drawing and the panels use: lower-case state names,
// robots with a flat x/y/heading, stops with name/x/y. One function per message.
"use strict";
window.WebMap = window.WebMap || {};

(function (WM) {
  const lower = (s, prefix) => (typeof s === "string" ? s.replace(prefix, "").toLowerCase() : "unknown");
  const orderState = s => lower(s, /^ORDER_STATE_/);
  const robotState = s => lower(s, /^ROBOT_STATE_/);
  const number = v => (v == null ? NaN : Number(v));  // "Infinity", 64-bit integers as strings
  const list = v => (Array.isArray(v) ? v : []);

  // ResolvedStop
  const stop = s => (s ? { point_id: s.point_id, name: s.point_name, x: s.position && s.position.x, y: s.position && s.position.y } : null);

  // RobotInfo
  function robot(j) {
    const pose = j.pose || {};
    return {
      id: j.id, state: robotState(j.state), kind: lower(j.kind, /^ROBOT_KIND_/), connected: j.connected,
      x: pose.x, y: pose.y, heading: pose.theta,
      orders: list(j.order_ids), held: !!j.held, hold_reason: j.hold_reason || "",
      formation: j.formation_order_id || null, point: stop(j.point), battery: j.battery ?? null,
      paused_by: j.paused_by || "", out_of_service_by: j.out_of_service_by || "", off_floor: !!j.off_floor,
      sent_to: stop(j.sent_to),
    };
  }

  // Session: who the token is.
  const session = j => ({ name: j.name || "", role: j.role || "", robot_commands: !!j.robot_commands,
    tokens_required: !!j.tokens_required });

  // Order
  function order(j) {
    return {
      id: j.id, client_id: j.client_order_id, state: orderState(j.state), robots: list(j.robot_ids),
      priority: j.priority, picks: list(j.picks).map(stop), drop: stop(j.drop), formation: !!j.formation,
      work_time: j.work_time, created_time: j.created_time, finished_time: j.finished_time ?? null,
      reason: j.reason || "", distance: j.distance || 0,
    };
  }

  // Bid
  const bid = b => ({
    robot: b.robot_id, reachable: b.reachable, queue_full: b.queue_full === true, priced: b.priced, t_t: number(b.total_time), t_d: number(b.travel_time),
    t_w: number(b.work_time), flow: number(b.traffic_flow), bid: number(b.total),
  });

  // AllocationExplanation
  function allocation(a) {
    if (!a) return null;
    return {
      strategy: a.strategy, alpha: a.alpha, beta: a.beta, zeta: a.zeta, time: a.time, reason: a.reason,
      winners: list(a.winner_ids), bids: list(a.bids).map(bid), companion_bids: list(a.companion_bids).map(bid),
      bids_total: a.bids_total, companion_bids_total: a.companion_bids_total,
    };
  }

  // OrderDetail: the order with its allocation and its routes (robot -> waypoints left).
  function detail(j) {
    const o = order(j.order || {});
    o.allocation = allocation(j.allocation);
    o.routes = {};
    for (const [id, route] of Object.entries(j.routes || {})) {
      o.routes[id] = list(route.waypoints).map(w => ({
        seq: number(w.sequence), x: w.position && w.position.x, y: w.position && w.position.y,
        action: lower(w.action, /^WAYPOINT_ACTION_/), released: !!w.released,
      }));
    }
    return o;
  }

  // ZoneState: polygon as [[x, y], ...] (as the map file has it).
  const zone = z => ({ id: z.id, polygon: list(z.polygon).map(v => [v.x, v.y]), area: z.area, density: z.density, robots: list(z.robot_ids) });

  // IntersectionState
  const intersection = i => ({ id: i.id, inner: list(i.inner), approach: list(i.approach), holders: list(i.holder_ids), waiting: list(i.waiting_ids) });

  // ServiceState: counters as numbers.
  function status(s) {
    const t = s.traffic || {};
    const m = t.min_robot_distance;
    return {
      map: s.map_name, map_version: s.map_version, time: s.time, time_scale: s.time_scale, orders: s.orders || {},
      robots: s.robots, traffic: {
        control: t.control, grants: number(t.grants), holds: number(t.holds), replans: number(t.replans),
        deadlocks_resolved: number(t.deadlocks_resolved),
        min_robot_distance: m ? { distance: m.distance, robots: list(m.robot_ids), time: m.time } : null,
      },
    };
  }

  WM.Api = { robot, order, detail, allocation, zone, intersection, status, session, orderState, robotState };
})(window.WebMap);
