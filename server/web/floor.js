// The static floor: the map model (GET /api/v1/map, engine/io/map_format.md), the view
// transform (map metres, y up -> screen pixels, y down) and the floor drawing. The floor is
// drawn once per view (load, resize, zoom, pan) on its own canvas, so the live layers never
// redraw lanes: a grid floor of 40,000 points and 150,000 paths costs one batched stroke per
// style, not one per frame. Only the heat layer under it (the floor rectangle and one polygon
// per zone) is redrawn live.
"use strict";
window.WebMap = window.WebMap || {};

(function (WM) {
  const COLOURS = {
    floor: "#fbfbfc", floorEdge: "#9aa5b1",
    zone: "#7b8794", shelf: "#cdb89a", shelfEdge: "#a68c67",
    freeSpace: "rgba(165, 214, 167, 0.45)", freeSpaceEdge: "#2e7d32",
    oneWay: "#8896a6", oneWayArrow: "#52606d", bidirectional: "#d97706",
    intersection: "rgba(120, 132, 148, 0.22)", lanePoint: "#9aa5b1",
    pick: "#16a34a", drop: "#dc2626", park: "#2563eb", charge: "#ca8a04",
  };

  // ---- the map model ---------------------------------------------------------------------
  // Points are referred to by their id (a string in the map file); other endpoints may send
  // a point's index instead, so ref() accepts both.
  function buildFloor(json) {
    const points = (json.points || []).filter(p => isFinite(p.x) && isFinite(p.y));
    const byId = new Map(points.map(p => [String(p.id), p]));
    const ref = r => (typeof r === "number" ? points[r] : byId.get(String(r))) || null;
    const floorBox = json.floor || {};
    const bounds = floorBox.min && floorBox.max
      ? { minX: floorBox.min[0], minY: floorBox.min[1], maxX: floorBox.max[0], maxY: floorBox.max[1] }
      : boundsOf(points);
    const intersections = new Map();
    for (const i of json.intersections || []) {
      const inner = (i.inner || []).map(ref).filter(Boolean);
      intersections.set(String(i.id), { id: String(i.id), inner, region: paddedHull(inner, REGION_PAD_M) });
    }
    return {
      name: json.name || "", bounds, points, ref, intersections,
      paths: (json.paths || []).map(p => ({ a: ref(p.from), b: ref(p.to), bidirectional: !!p.bidirectional }))
        .filter(p => p.a && p.b),
      zones: (json.zones || []).filter(z => Array.isArray(z.polygon) && z.polygon.length >= 3),
      shelves: (json.shelves || []).filter(s => s.min && s.max),
      freeSpaces: (json.free_space || []).filter(f => Array.isArray(f.polygon) && f.polygon.length >= 3),
      stations: (json.stations || []).map(s => ({ id: s.id, point: ref(s.point), capacity: s.capacity }))
        .filter(s => s.point),
    };
  }

  function boundsOf(points) {
    const b = { minX: Infinity, minY: Infinity, maxX: -Infinity, maxY: -Infinity };
    for (const p of points) {
      b.minX = Math.min(b.minX, p.x); b.maxX = Math.max(b.maxX, p.x);
      b.minY = Math.min(b.minY, p.y); b.maxY = Math.max(b.maxY, p.y);
    }
    if (!isFinite(b.minX)) return { minX: 0, minY: 0, maxX: 10, maxY: 10 };
    return { minX: b.minX - 1, minY: b.minY - 1, maxX: b.maxX + 1, maxY: b.maxY + 1 };
  }

  // The convex hull of the points grown by `pad` metres (an octagon around a single point):
  // an intersection's inner region as drawn.
  const REGION_PAD_M = 0.35;
  function paddedHull(pts, pad) {
    const grown = [];
    for (const p of pts) {
      for (let k = 0; k < 8; k++) {
        const a = (k + 0.5) * Math.PI / 4;
        grown.push({ x: p.x + pad * Math.cos(a), y: p.y + pad * Math.sin(a) });
      }
    }
    return convexHull(grown);
  }

  // Andrew's monotone chain; points are {x, y}. Fewer than 3 distinct points come back as-is.
  function convexHull(pts) {
    const p = [...pts].sort((a, b) => a.x - b.x || a.y - b.y);
    if (p.length < 3) return p;
    const cross = (o, a, b) => (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
    const lower = [], upper = [];
    for (const q of p) {
      while (lower.length >= 2 && cross(lower[lower.length - 2], lower[lower.length - 1], q) <= 0) lower.pop();
      lower.push(q);
    }
    for (let k = p.length - 1; k >= 0; k--) {
      const q = p[k];
      while (upper.length >= 2 && cross(upper[upper.length - 2], upper[upper.length - 1], q) <= 0) upper.pop();
      upper.push(q);
    }
    return lower.slice(0, -1).concat(upper.slice(0, -1));
  }

  // ---- the view: map metres (y up) <-> CSS pixels (y down) -------------------------------
  class View {
    constructor() { this.scale = 1; this.ox = 0; this.oy = 0; this.width = 1; this.height = 1; }
    fit(bounds, width, height, margin = 16) {
      this.width = width; this.height = height;
      const w = bounds.maxX - bounds.minX, h = bounds.maxY - bounds.minY;
      this.scale = Math.max(1e-6, Math.min((width - 2 * margin) / w, (height - 2 * margin) / h));
      this.ox = (width - w * this.scale) / 2 - bounds.minX * this.scale;
      this.oy = (height + h * this.scale) / 2 + bounds.minY * this.scale;
    }
    resize(width, height) {  // keeps the map point at the centre where it is
      this.ox += (width - this.width) / 2; this.oy += (height - this.height) / 2;
      this.width = width; this.height = height;
    }
    sx(x) { return this.ox + x * this.scale; }
    sy(y) { return this.oy - y * this.scale; }
    zoomAt(px, py, factor) {
      this.ox = px - (px - this.ox) * factor; this.oy = py - (py - this.oy) * factor;
      this.scale *= factor;
    }
    pan(dx, dy) { this.ox += dx; this.oy += dy; }
  }

  // ---- drawing ----------------------------------------------------------------------------
  function prepare(canvas, view) {
    const dpr = window.devicePixelRatio || 1;
    const w = Math.round(view.width * dpr), h = Math.round(view.height * dpr);
    if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; }
    const ctx = canvas.getContext("2d");
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    ctx.clearRect(0, 0, view.width, view.height);
    return ctx;
  }

  function polygonPath(ctx, view, poly) {  // poly: [[x, y], ...]
    ctx.moveTo(view.sx(poly[0][0]), view.sy(poly[0][1]));
    for (let k = 1; k < poly.length; k++) ctx.lineTo(view.sx(poly[k][0]), view.sy(poly[k][1]));
    ctx.closePath();
  }

  function drawFloor(canvas, view, floor) {
    const ctx = prepare(canvas, view);
    const s = view.scale, b = floor.bounds;
    // The floor itself stays transparent: the heat layer under this canvas paints it.
    ctx.strokeStyle = COLOURS.floorEdge; ctx.lineWidth = 1;
    ctx.strokeRect(view.sx(b.minX), view.sy(b.maxY), (b.maxX - b.minX) * s, (b.maxY - b.minY) * s);

    // Zones: dashed outlines with their id (the heat layer fills them).
    ctx.setLineDash([6, 4]); ctx.strokeStyle = COLOURS.zone; ctx.lineWidth = 1;
    ctx.beginPath();
    for (const z of floor.zones) polygonPath(ctx, view, z.polygon);
    ctx.stroke(); ctx.setLineDash([]);
    if (floor.zones.length <= 200) {
      ctx.fillStyle = COLOURS.zone; ctx.font = "12px sans-serif"; ctx.textBaseline = "top";
      for (const z of floor.zones) {
        const x = Math.min(...z.polygon.map(v => v[0])), y = Math.max(...z.polygon.map(v => v[1]));
        ctx.fillText(z.id, view.sx(x) + 4, view.sy(y) + 3);
      }
    }

    // Free-space regions (narrow areas for four-wheel-steer robots): dashed green.
    if (floor.freeSpaces.length) {
      ctx.fillStyle = COLOURS.freeSpace; ctx.strokeStyle = COLOURS.freeSpaceEdge;
      ctx.setLineDash([6, 4]); ctx.lineWidth = 1.5;
      for (const f of floor.freeSpaces) {
        ctx.beginPath();
        f.polygon.forEach((v, k) => k ? ctx.lineTo(view.sx(v[0]), view.sy(v[1])) : ctx.moveTo(view.sx(v[0]), view.sy(v[1])));
        ctx.closePath(); ctx.fill(); ctx.stroke();
      }
      ctx.setLineDash([]); ctx.lineWidth = 1;
    }

    ctx.fillStyle = COLOURS.shelf; ctx.strokeStyle = COLOURS.shelfEdge;
    ctx.beginPath();
    for (const sh of floor.shelves) {
      ctx.rect(view.sx(sh.min[0]), view.sy(sh.max[1]), (sh.max[0] - sh.min[0]) * s, (sh.max[1] - sh.min[1]) * s);
    }
    ctx.fill(); if (s > 4) ctx.stroke();

    ctx.fillStyle = COLOURS.intersection;
    ctx.beginPath();
    for (const i of floor.intersections.values()) hullPath(ctx, view, i.region);
    ctx.fill();

    drawPaths(ctx, view, floor.paths);
    drawPoints(ctx, view, floor);
  }

  function hullPath(ctx, view, hull) {
    if (!hull.length) return;
    ctx.moveTo(view.sx(hull[0].x), view.sy(hull[0].y));
    for (const q of hull) ctx.lineTo(view.sx(q.x), view.sy(q.y));
    ctx.closePath();
  }

  // One stroke per lane style; arrows only where a lane is long enough on screen to carry one.
  function drawPaths(ctx, view, paths) {
    const oneWay = new Path2D(), both = new Path2D(), arrows = new Path2D(), bothArrows = new Path2D();
    const arrow = Math.min(6, Math.max(3, 0.25 * view.scale));
    const W = view.width, H = view.height;
    for (const p of paths) {
      const x1 = view.sx(p.a.x), y1 = view.sy(p.a.y), x2 = view.sx(p.b.x), y2 = view.sy(p.b.y);
      if ((x1 < 0 && x2 < 0) || (y1 < 0 && y2 < 0) || (x1 > W && x2 > W) || (y1 > H && y2 > H)) continue;
      const line = p.bidirectional ? both : oneWay;
      line.moveTo(x1, y1); line.lineTo(x2, y2);
      const len = Math.hypot(x2 - x1, y2 - y1);
      if (len < 4 * arrow) continue;
      const ux = (x2 - x1) / len, uy = (y2 - y1) / len;
      const mx = (x1 + x2) / 2, my = (y1 + y2) / 2;
      if (p.bidirectional) {
        chevron(bothArrows, mx + ux * arrow, my + uy * arrow, ux, uy, arrow);
        chevron(bothArrows, mx - ux * arrow, my - uy * arrow, -ux, -uy, arrow);
      } else {
        // Shifted to the right of travel, so the arrows of two opposite one-way arcs on the
        // same pair of points sit side by side (right-hand traffic).
        chevron(arrows, mx - uy * arrow * 0.7, my + ux * arrow * 0.7, ux, uy, arrow);
      }
    }
    ctx.lineCap = "butt"; ctx.lineJoin = "miter";
    ctx.strokeStyle = COLOURS.oneWay; ctx.lineWidth = 1.2; ctx.stroke(oneWay);
    ctx.strokeStyle = COLOURS.bidirectional; ctx.lineWidth = 2.2; ctx.setLineDash([5, 3]);
    ctx.stroke(both); ctx.setLineDash([]);
    ctx.lineWidth = 1.3;
    ctx.strokeStyle = COLOURS.oneWayArrow; ctx.stroke(arrows);
    ctx.strokeStyle = COLOURS.bidirectional; ctx.stroke(bothArrows);
  }

  function chevron(path, tipX, tipY, ux, uy, size) {
    const bx = tipX - ux * size, by = tipY - uy * size, nx = -uy * size * 0.6, ny = ux * size * 0.6;
    path.moveTo(bx + nx, by + ny); path.lineTo(tipX, tipY); path.lineTo(bx - nx, by - ny);
  }

  function drawPoints(ctx, view, floor) {
    const r = Math.min(6, Math.max(2, 0.22 * view.scale));
    const byKind = { lane: new Path2D(), pick: new Path2D(), drop: new Path2D(), park: new Path2D(), charge: new Path2D() };
    const showLanes = view.scale >= 14;
    for (const p of floor.points) {
      const x = view.sx(p.x), y = view.sy(p.y);
      if (x < -r || y < -r || x > view.width + r || y > view.height + r) continue;
      switch (p.kind) {
        case "pick": byKind.pick.moveTo(x, y - r); byKind.pick.lineTo(x + r, y); byKind.pick.lineTo(x, y + r);
          byKind.pick.lineTo(x - r, y); byKind.pick.closePath(); break;
        case "drop": byKind.drop.rect(x - r, y - r, 2 * r, 2 * r); break;
        case "park": case "charge": byKind[p.kind].moveTo(x + r * 1.2, y); byKind[p.kind].arc(x, y, r * 1.2, 0, 2 * Math.PI); break;
        case "lane": if (showLanes) { byKind.lane.moveTo(x + 1.3, y); byKind.lane.arc(x, y, 1.3, 0, 2 * Math.PI); } break;
        default: break;
      }
    }
    for (const kind of Object.keys(byKind)) { ctx.fillStyle = COLOURS[kind === "lane" ? "lanePoint" : kind]; ctx.fill(byKind[kind]); }
    if (view.scale >= 10 && floor.stations.length <= 500) {
      ctx.fillStyle = COLOURS.park; ctx.font = "10px sans-serif"; ctx.textBaseline = "middle";
      for (const st of floor.stations) {
        ctx.fillText(`${st.id}×${st.capacity}`, view.sx(st.point.x) + r * 1.6, view.sy(st.point.y));
      }
    }
  }

  // Zone density heat: t = density / scaleMax in [0, 1], pale yellow -> red.
  function heatColour(t) {
    const c = Math.max(0, Math.min(1, t));
    return `hsla(${Math.round(55 - 55 * c)}, 95%, 50%, ${(0.08 + 0.34 * c).toFixed(2)})`;
  }

  // The layer under the floor drawing: the floor rectangle, and each zone tinted by its
  // density, so lanes, shelves and points stay crisp on top.
  function drawHeat(canvas, view, bounds, zones, scaleMax) {
    const ctx = prepare(canvas, view);
    if (bounds) {
      ctx.fillStyle = COLOURS.floor;
      ctx.fillRect(view.sx(bounds.minX), view.sy(bounds.maxY), (bounds.maxX - bounds.minX) * view.scale,
        (bounds.maxY - bounds.minY) * view.scale);
    }
    for (const z of zones) {
      if (!(z.density > 0) || !Array.isArray(z.polygon) || z.polygon.length < 3) continue;
      ctx.fillStyle = heatColour(z.density / scaleMax);
      ctx.beginPath(); polygonPath(ctx, view, z.polygon); ctx.fill();
    }
  }

  WM.Floor = { COLOURS, REGION_PAD_M, buildFloor, convexHull, paddedHull, View, drawFloor, drawHeat, heatColour };
})(window.WebMap);
