// Live map: vehicles (icon pointing along the heading, trail), waypoints and loiter polygon, on local x/y metres.
// SVG user units are metres with y flipped (north up); no tiles, so it works offline.
"use strict";

const LiveMap = {
  vehicles: new Map(),  // name -> {icon, label, trail, row, points, data}
  bounds: null,         // [minX, minY, maxX, maxY] in metres
  overlays: {waypoints: [], polygon: [], mode: null},

  init() {
    Liaison.on("map", (msg) => this.update(msg));
  },

  update(msg) {
    if (msg.full) {
      for (const v of this.vehicles.values()) { v.icon.remove(); v.label.remove(); v.trail.remove(); v.row.remove(); }
      this.vehicles.clear();
    }
    if (msg.waypoints !== undefined) this.setOverlays(msg);
    for (const data of msg.vehicles || []) this.updateVehicle(data, msg.full);
    if (msg.health !== undefined) this.setHealth(msg.health);
    for (const [name, age] of Object.entries(msg.ages || {})) {
      const v = this.vehicles.get(name);
      if (v) v.row.children[5].textContent = String(age);
    }
  },

  // Each vehicle's last HealthStatus: state, its time of day (time2 carries only that), age since it arrived (sim s).
  setHealth(rows) {
    const clock = (s) => [Math.floor(s / 3600), Math.floor(s / 60) % 60, s % 60].map((n) => String(n).padStart(2, "0")).join(":");
    document.querySelector("#health-table tbody").replaceChildren(...rows.map((h) => {
      const row = el("tr", {"data-vehicle": h.vehicle});
      for (const text of [h.vehicle, h.state, clock(h.time_of_day), String(h.age)]) {
        const cell = el("td");
        cell.textContent = text;
        row.append(cell);
      }
      row.children[1].className = h.state === "GOOD" ? "state-acknowledged" : "state-failed";
      return row;
    }));
  },

  setOverlays(msg) {
    this.overlays = {waypoints: msg.waypoints, polygon: msg.polygon, mode: msg.mode};
    const text = (pts) => pts.map(([x, y]) => `${x},${-y}`).join(" ");
    const wpt = document.getElementById("map-waypoints");
    const poly = document.getElementById("map-polygon");
    wpt.setAttribute("points", text(msg.waypoints));
    poly.setAttribute("points", text(msg.polygon));
    wpt.classList.toggle("active", msg.mode === "waypoints");
    poly.classList.toggle("active", msg.mode === "polygon");
    document.getElementById("map-mode").textContent = msg.mode || "unknown";
    for (const [x, y] of msg.waypoints.concat(msg.polygon)) this.include(x, y);
  },

  updateVehicle(data, full) {
    let v = this.vehicles.get(data.name);
    if (!v) {
      v = {icon: svg("path", {class: "vehicle", "data-name": data.name}),
           label: svg("text", {class: "label"}),
           trail: svg("polyline", {class: "trail", "data-name": data.name}),
           row: el("tr", {"data-vehicle": data.name}), points: []};
      v.label.textContent = data.name;
      for (let i = 0; i < 6; i++) v.row.append(el("td"));
      document.getElementById("map-trails").append(v.trail);
      document.getElementById("map-vehicles").append(v.icon, v.label);
      document.querySelector("#vehicle-table tbody").append(v.row);
      this.vehicles.set(data.name, v);
    }
    v.data = data;
    const added = data.trail || data.append || [];
    if (data.trail) v.points = [];
    for (const p of added) v.points.push(p);
    if (v.points.length > 5000) v.points.splice(0, v.points.length - 5000);
    v.trail.setAttribute("points", v.points.map(([x, y]) => `${x},${-y}`).join(" "));
    this.include(data.x, data.y);
    this.place(v);
    const cells = v.row.children;
    cells[0].textContent = data.name + (data.type ? ` (${data.type})` : "");
    cells[1].textContent = data.x.toFixed(1);
    cells[2].textContent = data.y.toFixed(1);
    cells[3].textContent = `${data.heading.toFixed(0)}°`;
    cells[4].textContent = data.speed.toFixed(2);
  },

  place(v) {
    const size = this.iconSize();
    const d = v.data;
    // An arrowhead pointing north, rotated clockwise by the compass heading (SVG rotates clockwise with y down).
    v.icon.setAttribute("d", `M 0 ${-size} L ${size * 0.6} ${size * 0.8} L 0 ${size * 0.4} L ${-size * 0.6} ${size * 0.8} Z`);
    v.icon.setAttribute("transform", `translate(${d.x} ${-d.y}) rotate(${d.heading})`);
    v.label.setAttribute("x", d.x + size * 1.2);
    v.label.setAttribute("y", -d.y - size * 1.2);
    v.label.setAttribute("font-size", size * 1.4);
  },

  iconSize() {
    if (!this.bounds) return 10;
    const [x0, y0, x1, y1] = this.bounds;
    return Math.max(x1 - x0, y1 - y0) * 0.015;
  },

  // Grow the view (never shrink: the picture should not jump) to include a point, with a margin.
  include(x, y) {
    const margin = 50;
    const b = this.bounds;
    if (b && x >= b[0] && x <= b[2] && y >= b[1] && y <= b[3]) return;
    this.bounds = b ? [Math.min(b[0], x - margin), Math.min(b[1], y - margin), Math.max(b[2], x + margin), Math.max(b[3], y + margin)]
      : [x - 200, y - 200, x + 200, y + 200];
    const [x0, y0, x1, y1] = this.bounds;
    const span = Math.max(x1 - x0, y1 - y0);
    const cx = (x0 + x1) / 2, cy = (y0 + y1) / 2;
    document.getElementById("map").setAttribute("viewBox", `${cx - span / 2} ${-cy - span / 2} ${span} ${span}`);
    this.drawGrid(cx - span / 2, cy - span / 2, span);
    for (const v of this.vehicles.values()) if (v.data) this.place(v);
  },

  drawGrid(x0, y0, span) {
    const step = [10, 20, 50, 100, 200, 500, 1000, 2000, 5000].find((s) => span / s <= 12) || 10000;
    document.getElementById("map-grid-step").textContent = step;
    const grid = document.getElementById("map-grid");
    const lines = [];
    for (let x = Math.ceil(x0 / step) * step; x <= x0 + span; x += step) {
      lines.push(svg("line", {class: x === 0 ? "axis" : "grid-line", x1: x, x2: x, y1: -(y0 + span), y2: -y0}));
    }
    for (let y = Math.ceil(y0 / step) * step; y <= y0 + span; y += step) {
      lines.push(svg("line", {class: y === 0 ? "axis" : "grid-line", y1: -y, y2: -y, x1: x0, x2: x0 + span}));
    }
    grid.replaceChildren(...lines);
  },
};
