// The live map's controller: polls the REST API (robots, intersections and zones every 200 ms,
// status every 500 ms, orders and the selected order every second, who the token is every
// 2 s and when it is changed; the map once and again when its version changes), keeps the
// latest answers, and redraws the live layers once per animation frame after new data (the
// answers' proto JSON turned into views by api.js). Fetch failures are shown in the page and
// retried. Operator commands on the selected robot are POSTed from the robots panel.
// window.dispatchMap = {robots(): [{id, x, y, state}] as drawn, frames: live updates applied}.
"use strict";

(function (WM) {
  const $ = id => document.getElementById(id);
  const API = "api/v1/";  // relative, so the page also works behind a path prefix
  const REQUEST_TIMEOUT_MS = 3000;
  const MAP_TIMEOUT_MS = 30000;  // an imported floor's map is megabytes
  const RETRY_MS = 1000;

  const state = {
    floor: null, mapVersion: null, view: new WM.Floor.View(), autoFit: true,
    robots: [], intersections: [], zones: [], orders: [], ordersById: new Map(),
    selectedId: null, detail: null, heatMax: 0.01, frames: 0, robotsFresh: false, finishedTotal: null,
    problems: new Map(), session: null, selectedRobot: null, commandNote: null,
  };
  const live = new WM.Live.LiveLayer($("live"));
  // The bearer token typed into the header (dispatchd --auth-tokens): in this page's memory
  // only, never stored, sent with every API request.
  let token = "";
  $("token").addEventListener("change", e => {
    token = e.target.value.trim();
    state.session = null;  // until the server says who the new token is
    renderRobots();
    refreshSession();
  });
  const EMPTY_FLOOR = { intersections: new Map(), ref: () => null };

  // ---- fetching ---------------------------------------------------------------------------
  async function getJson(path, timeoutMs = REQUEST_TIMEOUT_MS, post = null) {
    let res;
    try {
      const headers = token ? { Authorization: "Bearer " + token } : {};
      const init = { cache: "no-store", headers, signal: AbortSignal.timeout(timeoutMs) };
      if (post) {
        init.method = "POST";
        headers["Content-Type"] = "application/json";
        init.body = JSON.stringify(post);
      }
      res = await fetch(API + path, init);
    } catch (err) {
      const e = new Error(err.name === "TimeoutError" ? `no answer within ${timeoutMs / 1000} s` : "server unreachable");
      e.network = true;
      throw e;
    }
    const text = await res.text();
    let body = null;
    try { body = text ? JSON.parse(text) : null; } catch (_) { /* reported below */ }
    if (!res.ok) throw new Error(`HTTP ${res.status}${body && body.error ? ": " + body.error : ""}`);
    if (body === null) throw new Error("answer is not JSON");
    return body;
  }

  function problem(source, err) {
    if (err) state.problems.set(source, { message: err.message || String(err), network: !!err.network });
    else if (!state.problems.delete(source)) return;
    WM.Panels.renderProblems(state.problems);
    $("map").classList.toggle("stale", state.problems.has("robots"));  // positions not live
  }

  // Polls path() every intervalMs (measured from the start of the previous request; never two
  // requests of one poller at a time). path() returning null skips a round. Only fetch
  // failures are caught: a bug in apply() stays an uncaught error, and the polling goes on.
  function poll(source, path, intervalMs, apply) {
    const tick = async () => {
      const started = performance.now();
      let wait = intervalMs, data;
      const p = path();
      try {
        if (p !== null) {
          try {
            data = await getJson(p);
            problem(source, null);
          } catch (err) {
            problem(source, err);
            wait = Math.max(intervalMs, RETRY_MS);
          }
          if (data !== undefined) apply(data, p);
        }
      } finally {
        setTimeout(tick, Math.max(0, wait - (performance.now() - started)));
      }
    };
    tick();
  }

  // ---- robots and operator commands ---------------------------------------------------------
  function renderRobots() {
    const stations = state.floor && state.floor.stations ? state.floor.stations.map(s => s.id) : [];
    WM.Commands.renderRobots(state.robots, state.selectedRobot, state.session, stations, state.commandNote);
  }

  let sessionAsked = 0;  // answers to older questions (an earlier token) are dropped
  function refreshSession() {
    const asked = ++sessionAsked;
    getJson("session").then(j => {
      if (asked !== sessionAsked) return;
      problem("session", null);
      state.session = WM.Api.session(j);
      renderRobots();
    }, err => {
      if (asked !== sessionAsked) return;
      problem("session", err);
      state.session = null;
      renderRobots();
    });
  }

  function selectRobot(id) {
    state.selectedRobot = id === state.selectedRobot ? null : id;
    state.commandNote = null;
    renderRobots();
  }

  async function command(kind) {
    const id = state.selectedRobot, spec = WM.Commands.COMMANDS[kind];
    if (!id || !spec) return;
    const body = kind === "send" ? { station: $("send-station").value } : {};
    try {
      const r = WM.Api.robot(await getJson(`robots/${encodeURIComponent(id)}/${spec.path}`, REQUEST_TIMEOUT_MS, body));
      state.robots = state.robots.map(x => (x.id === r.id ? r : x));  // shown at once, not at the next poll
      state.commandNote = { ok: true, text: `${spec.label.toLowerCase()}: done` };
    } catch (err) {
      state.commandNote = { ok: false, text: `${spec.label.toLowerCase()} failed: ${err.message}` };
    }
    renderRobots();
  }

  // ---- drawing ----------------------------------------------------------------------------
  let floorDirty = true, liveQueued = false;

  function scheduleDraw() {
    if (liveQueued) return;
    liveQueued = true;
    requestAnimationFrame(draw);
  }

  function draw() {
    liveQueued = false;
    if (state.autoFit) fitView();
    if (floorDirty && state.floor) drawFloorLayer(performance.now() < interactingUntil);
    WM.Floor.drawHeat($("heat"), state.view, state.floor && state.floor.bounds, state.zones, state.heatMax);
    live.render({
      view: state.view, floor: state.floor || EMPTY_FLOOR, robots: state.robots,
      intersections: state.intersections, formations: formations(), selected: selection(),
    });
    if (state.robotsFresh) { state.frames++; state.robotsFresh = false; }
  }

  // The floor canvas is redrawn when the view changed. A floor that is slow to draw (a big
  // imported grid) is only moved with a CSS transform while the user zooms or pans, and
  // redrawn once the gesture pauses.
  const SLOW_FLOOR_MS = 30, SETTLE_MS = 150;
  let floorShows = null, floorCostMs = 0, settleTimer = 0, interactingUntil = 0;

  function drawFloorLayer(interactive) {
    const canvas = $("floor"), v = state.view;
    if (interactive && floorCostMs > SLOW_FLOOR_MS && floorShows && floorShows.width === v.width &&
        floorShows.height === v.height) {
      const k = v.scale / floorShows.scale;
      canvas.style.transform = `matrix(${k},0,0,${k},${v.ox - floorShows.ox * k},${v.oy - floorShows.oy * k})`;
      clearTimeout(settleTimer);
      settleTimer = setTimeout(() => { floorDirty = true; scheduleDraw(); }, SETTLE_MS);
      return;
    }
    const started = performance.now();
    WM.Floor.drawFloor(canvas, v, state.floor);
    floorCostMs = performance.now() - started;
    canvas.style.transform = "";
    floorShows = { scale: v.scale, ox: v.ox, oy: v.oy, width: v.width, height: v.height };
    floorDirty = false;
  }

  function interacted() {
    state.autoFit = false;
    interactingUntil = performance.now() + SETTLE_MS;
    floorDirty = true;
    scheduleDraw();
  }

  function fitView() {
    const box = $("map").getBoundingClientRect();
    const bounds = state.floor ? state.floor.bounds : robotBounds();
    if (!bounds || box.width < 10 || box.height < 10) return;
    const before = [state.view.scale, state.view.ox, state.view.oy, state.view.width, state.view.height].join();
    state.view.fit(bounds, box.width, box.height);
    if ([state.view.scale, state.view.ox, state.view.oy, state.view.width, state.view.height].join() !== before) floorDirty = true;
  }

  function robotBounds() {  // before (or without) a map: frame the robots
    const pts = state.robots.filter(r => isFinite(r.x) && isFinite(r.y));
    if (!pts.length) return null;
    const xs = pts.map(r => r.x), ys = pts.map(r => r.y);
    return { minX: Math.min(...xs) - 3, maxX: Math.max(...xs) + 3, minY: Math.min(...ys) - 3, maxY: Math.max(...ys) + 3 };
  }

  // Formation orders in progress with their members: from the robots' "formation" field when
  // the server sends it, else from the order list.
  function formations() {
    const groups = new Map();
    if (state.robots.some(r => "formation" in r)) {
      for (const r of state.robots) {
        if (r.formation == null) continue;
        const o = state.ordersById.get(r.formation);
        if (o && o.state !== "in_progress") continue;
        if (!groups.has(r.formation)) groups.set(r.formation, []);
        groups.get(r.formation).push(r.id);
      }
    } else {
      for (const o of state.orders) {
        if (o.formation && o.state === "in_progress" && (o.robots || []).length > 1) groups.set(o.id, o.robots);
      }
    }
    return [...groups].map(([order, members]) => ({ order, members }));
  }

  function selection() {
    if (!state.selectedId) return null;
    const o = state.detail && state.detail.id === state.selectedId ? state.detail : state.ordersById.get(state.selectedId);
    return { robots: new Set((o && o.robots) || []), routes: (o && o.routes) || null };
  }

  // ---- data -------------------------------------------------------------------------------
  function applyMap(json) {
    state.floor = WM.Floor.buildFloor(json);
    state.autoFit = true;
    floorDirty = true;
    $("map-note").hidden = true;
    renderRobots();  // the stations to send robots to
    scheduleDraw();
  }

  function loadMap() {
    getJson("map", MAP_TIMEOUT_MS).then(json => { problem("map", null); applyMap(json); }, err => {
      problem("map", err);
      $("map-note").textContent = `no floor map (${err.message}); retrying`;
      setTimeout(loadMap, RETRY_MS * 2);
    });
  }

  function start() {
    loadMap();
    poll("robots", () => "robots", 200, j => {
      state.robots = (Array.isArray(j.robots) ? j.robots : []).map(WM.Api.robot);
      state.robotsFresh = true;
      renderRobots();
      scheduleDraw();
    });
    refreshSession();
    setInterval(refreshSession, 2000);
    poll("intersections", () => "intersections?active=1", 200, j => {
      state.intersections = (Array.isArray(j.intersections) ? j.intersections : []).map(WM.Api.intersection);
      WM.Panels.renderIntersections(state.intersections);
      scheduleDraw();
    });
    poll("zones", () => "zones", 200, j => {
      state.zones = (Array.isArray(j.zones) ? j.zones : []).map(WM.Api.zone);
      const peak = Math.max(0, ...state.zones.map(z => (isFinite(z.density) ? z.density : 0)));
      if (peak > state.heatMax) { state.heatMax = peak; WM.Panels.renderLegend(state.heatMax); }
      scheduleDraw();
    });
    poll("status", () => "status", 500, j => {
      const s = WM.Api.status(j);
      WM.Panels.renderStatus(s);
      if (s.map_version && state.mapVersion && s.map_version !== state.mapVersion) loadMap();
      if (s.map_version) state.mapVersion = s.map_version;
    });
    poll("orders", () => "orders", 1000, j => {
      state.orders = (Array.isArray(j.orders) ? j.orders : []).map(WM.Api.order);
      state.ordersById = new Map(state.orders.map(o => [o.id, o]));
      state.finishedTotal = Number.isFinite(j.finished_total) ? j.finished_total : null;
      WM.Panels.renderOrders(state.orders, state.selectedId, state.finishedTotal);
    });
    poll("order", () => (state.selectedId ? "orders/" + encodeURIComponent(state.selectedId) : null), 1000, (j, path) => {
      if (!state.selectedId || path !== "orders/" + encodeURIComponent(state.selectedId)) return;  // selection changed meanwhile
      const o = WM.Api.detail(j);
      state.detail = o;
      WM.Panels.renderDetail(o);
      scheduleDraw();
    });
  }

  function select(id) {
    state.selectedId = id;
    state.detail = null;
    WM.Panels.renderOrders(state.orders, id, state.finishedTotal);
    WM.Panels.renderDetail(id ? state.ordersById.get(id) || { id } : null);
    if (!id) problem("order", null);
    scheduleDraw();
    if (id) {  // at once, not at the next poll
      getJson("orders/" + encodeURIComponent(id)).then(j => {
        if (state.selectedId !== id) return;
        const o = WM.Api.detail(j);
        state.detail = o; WM.Panels.renderDetail(o); scheduleDraw();
      }, err => problem("order", err));
    }
  }

  // ---- interaction ------------------------------------------------------------------------
  function bindUi() {
    $("orders").addEventListener("click", e => {
      const li = e.target.closest("li[data-order-id]");
      if (li) select(li.dataset.orderId === state.selectedId ? null : li.dataset.orderId);
    });
    $("orders").addEventListener("keydown", e => {
      const li = e.target.closest("li[data-order-id]");
      if (li && (e.key === "Enter" || e.key === " ")) { e.preventDefault(); select(li.dataset.orderId); }
    });
    $("detail-close").addEventListener("click", () => select(null));
    $("robot-list").addEventListener("click", e => {
      const li = e.target.closest("li[data-robot-id]");
      if (li) selectRobot(li.dataset.robotId);
    });
    $("robot-list").addEventListener("keydown", e => {
      const li = e.target.closest("li[data-robot-id]");
      if (li && (e.key === "Enter" || e.key === " ")) { e.preventDefault(); selectRobot(li.dataset.robotId); }
    });
    $("robot-commands").addEventListener("click", e => {
      const b = e.target.closest("button[data-command]");
      if (b) command(b.dataset.command);
    });

    const map = $("map");
    map.addEventListener("wheel", e => {
      e.preventDefault();
      const box = map.getBoundingClientRect();
      state.view.zoomAt(e.clientX - box.left, e.clientY - box.top, Math.pow(1.0015, -e.deltaY));
      interacted();
    }, { passive: false });
    let drag = null;
    map.addEventListener("pointerdown", e => { drag = { x: e.clientX, y: e.clientY }; map.setPointerCapture(e.pointerId); });
    map.addEventListener("pointermove", e => {
      if (!drag) return;
      state.view.pan(e.clientX - drag.x, e.clientY - drag.y);
      drag = { x: e.clientX, y: e.clientY };
      interacted();
    });
    map.addEventListener("pointerup", () => { drag = null; });
    map.addEventListener("dblclick", () => { state.autoFit = true; scheduleDraw(); });
    new ResizeObserver(() => {
      const box = map.getBoundingClientRect();
      if (!state.autoFit) state.view.resize(box.width, box.height);
      floorDirty = true; scheduleDraw();
    }).observe(map);
  }

  window.dispatchMap = {
    robots: () => live.drawn.map(r => ({ ...r })),
    get frames() { return state.frames; },
    get problems() { return [...state.problems].map(([source, p]) => `${source}: ${p.message}`); },
    select,
    get session() { return state.session; },
  };

  WM.Panels.renderLegend(state.heatMax);
  bindUi();
  start();
})(window.WebMap);
