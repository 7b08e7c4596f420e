// The operator's map (pMarineViewer as the anchor), drawn on a canvas in local x/y metres, north up, offline.
// Messages only change state and mark the picture dirty; it is redrawn on the next animation frame, once.
// Zoom: wheel, +/- keys, buttons; pan: drag, arrow keys; F fits. Tools: measure (range/bearing between two
// clicks) and polygon (a click sets the radius from the helm's loiter centre). Replay draws a log's vehicles.
"use strict";

const MAP_COLORS = {USV: "#c0392b", AUV: "#1f618d", other: "#6c3483"};
const ZOOM_STEP = 1.25;
const STALE_S = 30;  // a vehicle whose last report is older is drawn greyed

const LiveMap = {
  canvas: null, ctx: null,
  view: {cx: 0, cy: 0, scale: 0.5},  // scale: pixels per metre
  fitted: false,          // the view follows the data until the operator moves it
  vehicles: new Map(),    // name -> {data, points, row, age, health}
  overlays: {waypoints: [], polygon: [], polygon_source: "config", mode: null, views: [], geo: null},
  clock: null, trailShown: 300, trailMax: 600,
  follow: "", rings: false, tool: "pan",
  measure: [], polygonDraft: null, command: null, lastCommand: null,
  replay: null,           // {summary, frame} while a log is replayed
  background: null, backgroundImage: null,
  cursor: null, drag: null, dirty: false,
  drawn: {extent: null, polygon: [], vehicles: {}},  // what the last frame showed (read by the browser tests)

  init() {
    this.canvas = document.getElementById("map");
    this.ctx = this.canvas.getContext("2d");
    Liaison.on("map", (msg) => this.update(msg));
    Liaison.on("sent", (msg) => this.showCommand(msg.entries));
    Liaison.on("accepted", (msg) => this.commandStatus(`sent #${msg.id}: ${msg.text}`));
    Liaison.on("refused", (msg) => this.commandStatus(`refused: ${msg.error}`, true));
    Liaison.on("error", (msg) => {
      if (msg.op_failed === "send") this.commandStatus(`refused: ${msg.error}`, true);
      else if (msg.op_failed && msg.op_failed.startsWith("replay")) this.replayStatus(msg.error, true);
    });
    Liaison.on("replay_list", (msg) => this.showLogs(msg));
    Liaison.on("replay_opened", (msg) => this.replayOpened(msg));
    Liaison.on("replay_frame", (msg) => { if (this.replay) { this.replay.frame = msg; this.replayTime(msg.t); this.redraw(); } });
    Liaison.on("replay_error", (msg) => this.replayStatus(msg.error, true));
    Liaison.on("replay_closed", () => this.replayStatus("live"));
    this.bindInput();
    this.bindControls();
    new ResizeObserver(() => this.resize()).observe(this.canvas);
    this.resize();
  },

  // ------------------------------------------------------------------------------------------ messages
  update(msg) {
    if (msg.full) {
      for (const v of this.vehicles.values()) v.row.remove();
      this.vehicles.clear();
      if (msg.trail_points) {
        this.trailMax = msg.trail_points;
        const slider = document.getElementById("map-trail");
        slider.max = msg.trail_points;
        if (this.trailShown > msg.trail_points) { this.trailShown = msg.trail_points; slider.value = msg.trail_points; }
      }
      if (msg.command !== undefined) this.setCommand(msg.command);
      if (msg.background !== undefined) this.setBackground(msg.background);
      document.getElementById("replay-panel").hidden = !msg.replay;
    }
    if (msg.waypoints !== undefined) this.setOverlays(msg);
    for (const data of msg.vehicles || []) this.updateVehicle(data);
    if (msg.ages) this.showAges(msg.ages);
    if (msg.health) this.showHealth(msg.health);
    if (typeof msg.clock === "number") {
      this.clock = msg.clock;
      document.getElementById("map-clock").textContent = timeText(msg.clock).substring(0, 8);
    }
    this.redraw();
  },

  setOverlays(msg) {
    this.overlays = {waypoints: msg.waypoints, polygon: msg.polygon, polygon_source: msg.polygon_source,
                     mode: msg.mode, mode_source: msg.mode_source, views: msg.views || [], geo: msg.geo || null};
    const mode = msg.mode ? msg.mode.toUpperCase() : "not known here (no helm, no initial_mode, no command yet)";
    const from = {helm: "the helm's DEPLOY_STATE", config: "the mission's initial state",
                  command: "the last command: the helm is not read here"}[msg.mode_source] || "";
    document.getElementById("map-mode").textContent = from ? `${mode} (from ${from})` : mode;
    const source = {helm: "the helm's VIEW_POLYGON", config: "the mission's configuration",
                    command: "the last command, modelled (the helm's own is not visible here)"}[msg.polygon_source];
    document.getElementById("map-polygon-source").textContent = source || "";
    document.getElementById("map-polygon-legend").hidden = !msg.polygon.length;
  },

  updateVehicle(data) {
    let v = this.vehicles.get(data.name);
    if (!v) {
      v = {row: el("tr", {"data-vehicle": data.name}), points: [], age: 0, health: null};
      for (let i = 0; i < 8; i++) v.row.append(el("td"));
      v.row.addEventListener("click", () => this.setFollow(data.name));
      document.querySelector("#vehicle-table tbody").append(v.row);
      this.vehicles.set(data.name, v);
      this.followOptions();
    }
    v.data = data;
    if (data.trail) v.points = data.trail.slice();
    for (const p of data.append || []) v.points.push(p);
    if (v.points.length > this.trailMax) v.points.splice(0, v.points.length - this.trailMax);
    const cells = v.row.children;
    cells[0].textContent = data.name + (data.type ? ` (${data.type})` : "");
    cells[1].textContent = data.x.toFixed(1);
    cells[2].textContent = data.y.toFixed(1);
    cells[3].textContent = `${data.heading.toFixed(0)}°`;
    cells[4].textContent = data.speed.toFixed(2);
    this.showLastCommand();
  },

  showAges(ages) {
    for (const [name, age] of Object.entries(ages)) {
      const v = this.vehicles.get(name);
      if (!v) continue;
      v.age = age;
      v.row.children[5].textContent = String(age);
      v.row.classList.toggle("stale", age > STALE_S);
    }
  },

  showHealth(rows) {
    document.querySelector("#health-table tbody").replaceChildren(...rows.map((h) => {
      const row = el("tr", {"data-vehicle": h.vehicle});
      for (const text of [h.vehicle, h.state, clockText(h.time_of_day), String(h.age)]) row.append(el("td", {text}));
      row.children[1].className = h.state === "GOOD" ? "state-acknowledged" : "state-failed";
      return row;
    }));
    for (const h of rows) {
      const v = this.vehicles.get(h.vehicle);
      if (!v) continue;
      const cell = v.row.children[6];
      cell.textContent = `${h.state} (${h.age} s ago)`;
      cell.className = h.state === "GOOD" ? "state-acknowledged" : "state-failed";
    }
  },

  // The commander's USVCommand goes to the USV: its last command's state is shown on the USV's row.
  showCommand(entries) {
    const mine = (entries || []).filter((e) => this.command && e.type === this.command.type);
    if (!mine.length) return;
    const last = mine[mine.length - 1];
    if (this.lastCommand && last.id < this.lastCommand.id) return;
    this.lastCommand = last;
    this.showLastCommand();
    this.commandStatus(`#${last.id} ${last.text}: ${last.state}${last.acks.length ? " (" + last.acks[last.acks.length - 1] + ")" : ""}`,
                       ["refused", "failed", "expired"].includes(last.state));
  },

  showLastCommand() {
    if (!this.lastCommand) return;
    const usv = [...this.vehicles.values()].find((v) => v.data && v.data.type === "USV") ||
      (this.vehicles.size === 1 ? [...this.vehicles.values()][0] : null);
    if (!usv) return;
    const cell = usv.row.children[7];
    cell.textContent = `#${this.lastCommand.id} ${this.lastCommand.text}: ${this.lastCommand.state}`;
    cell.className = `state-${this.lastCommand.state}`;
  },

  setBackground(bg) {
    this.background = bg;
    if (!bg) { this.backgroundImage = null; return; }
    const img = new Image();
    img.onload = () => { this.backgroundImage = img; this.redraw(); };
    img.src = bg.url;
  },

  // ------------------------------------------------------------------------------------------ view
  resize() {
    const dpr = window.devicePixelRatio || 1;
    const rect = this.canvas.getBoundingClientRect();
    this.canvas.width = Math.max(1, Math.round(rect.width * dpr));
    this.canvas.height = Math.max(1, Math.round(rect.height * dpr));
    this.dpr = dpr;
    this.redraw();
  },

  size() { return [this.canvas.width / this.dpr, this.canvas.height / this.dpr]; },
  toScreen(x, y) {
    const [w, h] = this.size();
    return [w / 2 + (x - this.view.cx) * this.view.scale, h / 2 - (y - this.view.cy) * this.view.scale];
  },
  toLocal(px, py) {
    const [w, h] = this.size();
    return [this.view.cx + (px - w / 2) / this.view.scale, this.view.cy - (py - h / 2) / this.view.scale];
  },
  extent() {
    const [w, h] = this.size();
    const [x0, y1] = this.toLocal(0, 0), [x1, y0] = this.toLocal(w, h);
    return [x0, y0, x1, y1];
  },

  zoom(factor, px, py) {
    const [w, h] = this.size();
    const at = px === undefined ? [w / 2, h / 2] : [px, py];
    const [x, y] = this.toLocal(...at);
    this.view.scale = Math.min(200, Math.max(1e-4, this.view.scale * factor));
    const [x2, y2] = this.toLocal(...at);  // keep the point under the cursor where it was
    this.view.cx += x - x2; this.view.cy += y - y2;
    this.fitted = true;
    this.redraw();
  },

  pan(dxPx, dyPx) {
    this.view.cx -= dxPx / this.view.scale;
    this.view.cy += dyPx / this.view.scale;
    this.fitted = true;
    if (this.follow) this.setFollow("");
    this.redraw();
  },

  // The view that holds everything known (vehicles, trails, overlays), with a margin.
  fit() {
    const xs = [], ys = [];
    const add = (p) => { xs.push(p[0]); ys.push(p[1]); };
    for (const v of this.shownVehicles()) { add([v.data.x, v.data.y]); v.points.forEach(add); }
    this.overlays.waypoints.forEach(add);
    this.overlays.polygon.forEach(add);
    for (const view of this.overlays.views) view.points.forEach(add);
    if (!xs.length) return;
    const [w, h] = this.size();
    const x0 = Math.min(...xs), x1 = Math.max(...xs), y0 = Math.min(...ys), y1 = Math.max(...ys);
    this.view.cx = (x0 + x1) / 2; this.view.cy = (y0 + y1) / 2;
    this.view.scale = Math.min(w / Math.max(x1 - x0 + 100, 200), h / Math.max(y1 - y0 + 100, 200)) * 0.9;
  },

  shownVehicles() {
    if (this.replay && this.replay.frame) {
      return this.replay.frame.vehicles.map((d) => ({data: d, points: d.trail, age: 0}));
    }
    return [...this.vehicles.values()].filter((v) => v.data);
  },

  setFollow(name) {
    this.follow = name;
    document.getElementById("map-follow").value = name;
    this.redraw();
  },

  followOptions() {
    const select = document.getElementById("map-follow");
    const names = [...this.vehicles.keys()].sort();
    select.replaceChildren(el("option", {value: "", text: "nobody"}), ...names.map((n) => el("option", {value: n, text: n})));
    select.value = this.follow;
  },

  redraw() {
    if (this.dirty) return;
    this.dirty = true;
    requestAnimationFrame(() => { this.dirty = false; this.draw(); });
  },

  // ------------------------------------------------------------------------------------------ drawing
  draw() {
    const ctx = this.ctx;
    const [w, h] = this.size();
    if (!this.fitted) this.fit();
    if (this.follow) {
      const v = this.shownVehicles().find((s) => s.data.name === this.follow);
      if (v) { this.view.cx = v.data.x; this.view.cy = v.data.y; }
    }
    ctx.setTransform(this.dpr, 0, 0, this.dpr, 0, 0);
    ctx.fillStyle = "#eef6fb";
    ctx.fillRect(0, 0, w, h);
    this.drawBackground(ctx);
    const step = this.gridStep();
    this.drawGrid(ctx, step, w, h);
    this.drawOverlays(ctx);
    if (this.rings) this.drawRings(ctx, step);
    const drawnVehicles = {};
    for (const v of this.shownVehicles()) {
      this.drawTrail(ctx, v);
      this.drawVehicle(ctx, v);
      drawnVehicles[v.data.name] = [v.data.x, v.data.y];
    }
    this.drawMeasure(ctx);
    this.drawDraft(ctx);
    this.drawScale(ctx, step, w, h);
    const extent = this.extent();
    this.canvas.dataset.extent = extent.map((v) => v.toFixed(1)).join(" ");
    this.drawn = {extent, polygon: this.overlays.polygon, vehicles: drawnVehicles};
  },

  gridStep() {
    const span = this.size()[0] / this.view.scale;
    const steps = [1, 2, 5];
    for (let p = 0; ; p++) {
      for (const s of steps) { const step = s * 10 ** p; if (span / step <= 10) return step; }
    }
  },

  drawBackground(ctx) {
    const bg = this.background, img = this.backgroundImage;
    if (!bg || !img) return;
    const [x0, y0] = this.toScreen(bg.west, bg.north), [x1, y1] = this.toScreen(bg.east, bg.south);
    ctx.globalAlpha = 0.9;
    ctx.drawImage(img, x0, y0, x1 - x0, y1 - y0);
    ctx.globalAlpha = 1;
  },

  drawGrid(ctx, step, w, h) {
    const [x0, y0, x1, y1] = this.extent();
    ctx.lineWidth = 1;
    ctx.font = "11px system-ui, sans-serif";
    ctx.fillStyle = "#7f8c8d";
    for (let x = Math.ceil(x0 / step) * step; x <= x1; x += step) {
      const [px] = this.toScreen(x, 0);
      ctx.strokeStyle = x === 0 ? "#95a5a6" : "#d0dde6";
      ctx.beginPath(); ctx.moveTo(px, 0); ctx.lineTo(px, h); ctx.stroke();
      ctx.fillText(`${x}`, px + 2, h - 4);
    }
    for (let y = Math.ceil(y0 / step) * step; y <= y1; y += step) {
      const [, py] = this.toScreen(0, y);
      ctx.strokeStyle = y === 0 ? "#95a5a6" : "#d0dde6";
      ctx.beginPath(); ctx.moveTo(0, py); ctx.lineTo(w, py); ctx.stroke();
      ctx.fillText(`${y}`, 2, py - 2);
    }
  },

  path(ctx, points, close) {
    ctx.beginPath();
    points.forEach(([x, y], i) => { const [px, py] = this.toScreen(x, y); if (i) ctx.lineTo(px, py); else ctx.moveTo(px, py); });
    if (close) ctx.closePath();
  },

  drawOverlays(ctx) {
    const o = this.overlays;
    if (o.waypoints.length) {
      ctx.setLineDash([6, 4]);
      ctx.strokeStyle = "#2874a6";
      ctx.lineWidth = o.mode === "waypoints" ? 2.5 : 1;
      this.path(ctx, o.waypoints, false);
      ctx.stroke();
      ctx.setLineDash([]);
      ctx.fillStyle = "#2874a6";
      for (const [x, y] of o.waypoints) { const [px, py] = this.toScreen(x, y); ctx.fillRect(px - 2, py - 2, 4, 4); }
    }
    if (o.polygon.length) {
      ctx.fillStyle = "rgba(241, 196, 15, 0.15)";
      ctx.strokeStyle = "#b7950b";
      ctx.lineWidth = o.mode === "polygon" ? 2.5 : 1;
      if (o.polygon_source === "command") ctx.setLineDash([3, 3]);
      this.path(ctx, o.polygon, true);
      ctx.fill(); ctx.stroke();
      ctx.setLineDash([]);
      const c = centre(o.polygon);
      const [px, py] = this.toScreen(...c);
      ctx.strokeStyle = "#7d6608";
      ctx.beginPath(); ctx.moveTo(px - 5, py); ctx.lineTo(px + 5, py); ctx.moveTo(px, py - 5); ctx.lineTo(px, py + 5); ctx.stroke();
    }
    ctx.font = "11px system-ui, sans-serif";
    for (const view of o.views) {
      ctx.strokeStyle = "#d35400"; ctx.fillStyle = "#d35400"; ctx.lineWidth = 1.5;
      if (view.kind === "point") {
        const [px, py] = this.toScreen(...view.points[0]);
        ctx.beginPath(); ctx.arc(px, py, 5, 0, 2 * Math.PI); ctx.stroke();
        ctx.beginPath(); ctx.moveTo(px - 8, py); ctx.lineTo(px + 8, py); ctx.moveTo(px, py - 8); ctx.lineTo(px, py + 8); ctx.stroke();
        ctx.fillText(view.label, px + 8, py - 6);
      } else {
        if (view.kind === "seglist") ctx.setLineDash([4, 3]);
        this.path(ctx, view.points, view.kind === "polygon");
        ctx.stroke();
        ctx.setLineDash([]);
        const [px, py] = this.toScreen(...view.points[0]);
        ctx.fillText(view.label, px + 4, py - 4);
      }
    }
  },

  drawRings(ctx, step) {
    const v = this.shownVehicles().find((s) => s.data.name === this.follow) ||
      this.shownVehicles().find((s) => s.data.type === "USV");
    const [cx, cy] = v ? [v.data.x, v.data.y] : [this.view.cx, this.view.cy];
    const [px, py] = this.toScreen(cx, cy);
    ctx.strokeStyle = "rgba(44, 62, 80, 0.5)"; ctx.fillStyle = "#2c3e50"; ctx.lineWidth = 1;
    ctx.font = "11px system-ui, sans-serif";
    for (let k = 1; k <= 5; k++) {
      const r = k * step * this.view.scale;
      ctx.beginPath(); ctx.arc(px, py, r, 0, 2 * Math.PI); ctx.stroke();
      ctx.fillText(`${k * step} m`, px + r * 0.707 + 2, py - r * 0.707 - 2);
    }
  },

  drawTrail(ctx, v) {
    const pts = v.points.slice(-this.trailShown).concat([[v.data.x, v.data.y]]);
    if (pts.length < 2) return;
    const color = MAP_COLORS[v.data.type] || MAP_COLORS.other;
    const chunks = 8;  // older chunks fainter: a fading trail in eight strokes
    const size = Math.ceil((pts.length - 1) / chunks);
    ctx.strokeStyle = color; ctx.lineWidth = 1.5;
    for (let c = 0; c * size < pts.length - 1; c++) {
      ctx.globalAlpha = 0.1 + 0.6 * (c + 1) / Math.ceil((pts.length - 1) / size);
      this.path(ctx, pts.slice(c * size, (c + 1) * size + 1), false);
      ctx.stroke();
    }
    ctx.globalAlpha = 1;
  },

  drawVehicle(ctx, v) {
    const d = v.data;
    const [px, py] = this.toScreen(d.x, d.y);
    const stale = v.age > STALE_S;
    ctx.save();
    ctx.translate(px, py);
    ctx.rotate(d.heading * Math.PI / 180);
    ctx.fillStyle = stale ? "#aab7b8" : (MAP_COLORS[d.type] || MAP_COLORS.other);
    ctx.strokeStyle = "#1b2631"; ctx.lineWidth = 1;
    ctx.beginPath();
    if (d.type === "AUV") {  // a torpedo with a tail fin
      ctx.ellipse(0, 0, 4, 11, 0, 0, 2 * Math.PI);
      ctx.moveTo(-5, 11); ctx.lineTo(5, 11); ctx.lineTo(0, 7); ctx.closePath();
    } else if (d.type === "USV") {  // a boat: pointed bow, square stern
      ctx.moveTo(0, -13); ctx.lineTo(6, -3); ctx.lineTo(6, 10); ctx.lineTo(-6, 10); ctx.lineTo(-6, -3); ctx.closePath();
    } else {  // anything else: an arrowhead
      ctx.moveTo(0, -12); ctx.lineTo(7, 9); ctx.lineTo(0, 5); ctx.lineTo(-7, 9); ctx.closePath();
    }
    ctx.fill(); ctx.stroke();
    ctx.restore();
    ctx.font = "12px system-ui, sans-serif";
    ctx.fillStyle = "#1b2631";
    ctx.fillText(d.name, px + 14, py - 6);
    ctx.font = "11px system-ui, sans-serif";
    ctx.fillStyle = "#4d5656";
    ctx.fillText(`${d.heading.toFixed(0)}° ${d.speed.toFixed(1)} m/s${stale ? ` (${v.age} s old)` : ""}`, px + 14, py + 7);
  },

  drawMeasure(ctx) {
    if (!this.measure.length) return;
    const [a, b] = [this.measure[0], this.measure[1] || this.cursor];
    if (!b) return;
    const [ax, ay] = this.toScreen(...a), [bx, by] = this.toScreen(...b);
    ctx.strokeStyle = "#117a65"; ctx.lineWidth = 2;
    ctx.beginPath(); ctx.moveTo(ax, ay); ctx.lineTo(bx, by); ctx.stroke();
    const text = rangeBearing(a, b);
    ctx.font = "12px system-ui, sans-serif"; ctx.fillStyle = "#0e6251";
    ctx.fillText(text, (ax + bx) / 2 + 6, (ay + by) / 2 - 6);
    document.getElementById("map-measure").textContent = text;
  },

  drawDraft(ctx) {
    const d = this.polygonDraft;
    if (!d) return;
    ctx.setLineDash([8, 4]); ctx.strokeStyle = "#8e44ad"; ctx.lineWidth = 2;
    this.path(ctx, radialRing(d.cx, d.cy, d.radius, d.sides), true);
    ctx.stroke(); ctx.setLineDash([]);
  },

  drawScale(ctx, step, w, h) {  // bottom right, clear of the grid's labels
    const len = step * this.view.scale;
    const x0 = w - len - 80, y = h - 30;
    ctx.fillStyle = "rgba(255,255,255,0.85)"; ctx.fillRect(x0 - 8, y - 16, len + 80, 28);
    ctx.strokeStyle = "#1b2631"; ctx.lineWidth = 2;
    ctx.beginPath(); ctx.moveTo(x0, y); ctx.lineTo(x0 + len, y);
    ctx.moveTo(x0, y - 6); ctx.lineTo(x0, y + 6); ctx.moveTo(x0 + len, y - 6); ctx.lineTo(x0 + len, y + 6); ctx.stroke();
    ctx.fillStyle = "#1b2631"; ctx.font = "12px system-ui, sans-serif";
    ctx.fillText(step >= 1000 ? `${step / 1000} km` : `${step} m`, x0 + len + 6, y + 4);
    document.getElementById("map-grid-step").textContent = step;
  },

  // ------------------------------------------------------------------------------------------ input
  bindInput() {
    const c = this.canvas;
    c.addEventListener("wheel", (e) => {
      e.preventDefault();
      const r = c.getBoundingClientRect();
      this.zoom(Math.pow(ZOOM_STEP, -Math.sign(e.deltaY)), e.clientX - r.left, e.clientY - r.top);
    }, {passive: false});
    c.addEventListener("mousedown", (e) => { this.drag = {x: e.clientX, y: e.clientY, moved: false}; });
    window.addEventListener("mouseup", (e) => {
      const drag = this.drag;
      this.drag = null;
      if (drag && !drag.moved && e.target === c) {
        const r = c.getBoundingClientRect();
        this.click(this.toLocal(e.clientX - r.left, e.clientY - r.top));
      }
    });
    c.addEventListener("mousemove", (e) => {
      const r = c.getBoundingClientRect();
      this.cursor = this.toLocal(e.clientX - r.left, e.clientY - r.top);
      this.showCursor();
      if (this.drag) {
        const dx = e.clientX - this.drag.x, dy = e.clientY - this.drag.y;
        if (this.drag.moved || Math.abs(dx) + Math.abs(dy) > 3) {
          this.drag.moved = true;
          this.drag.x = e.clientX; this.drag.y = e.clientY;
          this.pan(dx, dy);
        }
      }
      if (this.tool !== "pan") this.redraw();
    });
    document.addEventListener("keydown", (e) => {
      if (["INPUT", "SELECT", "TEXTAREA"].includes(e.target.tagName) || e.ctrlKey || e.metaKey || e.altKey) return;
      const pan = 80;
      const keys = {"+": () => this.zoom(ZOOM_STEP), "=": () => this.zoom(ZOOM_STEP), "-": () => this.zoom(1 / ZOOM_STEP),
                    ArrowLeft: () => this.pan(pan, 0), ArrowRight: () => this.pan(-pan, 0),
                    ArrowUp: () => this.pan(0, pan), ArrowDown: () => this.pan(0, -pan),
                    f: () => { this.fitted = false; this.redraw(); }, Escape: () => this.setTool("pan")};
      const action = keys[e.key];
      if (action) { e.preventDefault(); action(); }
    });
  },

  bindControls() {
    const on = (id, event, fn) => document.getElementById(id).addEventListener(event, fn);
    on("map-zoom-in", "click", () => this.zoom(ZOOM_STEP));
    on("map-zoom-out", "click", () => this.zoom(1 / ZOOM_STEP));
    on("map-fit", "click", () => { this.fitted = false; this.redraw(); });
    on("map-rings", "change", (e) => { this.rings = e.target.checked; this.redraw(); });
    on("map-follow", "change", (e) => this.setFollow(e.target.value));
    on("map-trail", "input", (e) => { this.trailShown = Number(e.target.value); this.redraw(); });
    on("map-measure-tool", "click", () => this.setTool(this.tool === "measure" ? "pan" : "measure"));
    on("map-polygon-tool", "click", () => this.setTool(this.tool === "polygon" ? "pan" : "polygon"));
    on("map-sides", "input", () => this.draftChanged());
    on("map-radius", "input", () => this.draftChanged());
    on("map-send-polygon", "click", () => this.sendPolygon());
    on("map-send-waypoints", "click", () => this.sendCommand({desired_state: "WAYPOINTS"}));
    on("replay-refresh", "click", () => Liaison.send({op: "replay_list"}));
    on("replay-open", "click", () => {
      const name = document.getElementById("replay-log").value;
      if (name) { Liaison.send({op: "replay_open", name}); this.replayStatus(`opening ${name}…`); }
    });
    on("replay-live", "click", () => { this.replay = null; Liaison.send({op: "replay_close"}); this.fitted = false; this.redraw(); });
    on("replay-slider", "input", (e) => this.seek(Number(e.target.value)));
    Liaison.on("open", () => { if (!document.getElementById("replay-panel").hidden) Liaison.send({op: "replay_list"}); });
  },

  setTool(tool) {
    this.tool = tool;
    this.measure = [];
    document.getElementById("map-measure-tool").classList.toggle("on", tool === "measure");
    document.getElementById("map-polygon-tool").classList.toggle("on", tool === "polygon");
    this.canvas.classList.toggle("picking", tool !== "pan");
    if (tool !== "measure") document.getElementById("map-measure").textContent = "";
    this.redraw();
  },

  click(point) {
    if (this.tool === "measure") {
      if (this.measure.length >= 2) this.measure = [];
      this.measure.push(point);
    } else if (this.tool === "polygon") {
      const c = this.overlays.polygon.length ? centre(this.overlays.polygon) : [0, 0];
      document.getElementById("map-radius").value = Math.round(Math.hypot(point[0] - c[0], point[1] - c[1]) / 10) * 10;
      this.draftChanged();
    }
    this.redraw();
  },

  showCursor() {
    if (!this.cursor) return;
    const [x, y] = this.cursor;
    let text = `x ${x.toFixed(1)} m, y ${y.toFixed(1)} m`;
    const geo = this.overlays.geo;
    if (geo) {
      const [lat, lon] = localToGeo(geo, x, y);
      text += `; ${lat.toFixed(6)}°, ${lon.toFixed(6)}°`;
    }
    document.getElementById("map-cursor").textContent = text;
  },

  // ------------------------------------------------------------------------------------------ command
  setCommand(command) {
    this.command = command;
    document.getElementById("map-command").hidden = !command;
    if (!command) return;
    const sides = document.getElementById("map-sides"), radius = document.getElementById("map-radius");
    [sides.min, sides.max] = command.sides; [radius.min, radius.max] = command.radius;
    document.getElementById("map-command-bounds").textContent =
      `sides ${command.sides[0]}–${command.sides[1]}, radius ${command.radius[0]}–${command.radius[1]} m (DCCL bounds); to ${command.targets[0].label}`;
  },

  draftChanged() {
    const sides = Number(document.getElementById("map-sides").value);
    const radius = Number(document.getElementById("map-radius").value);
    const c = this.overlays.polygon.length ? centre(this.overlays.polygon) : [0, 0];
    this.polygonDraft = sides >= 3 && sides <= 360 && radius > 0 ? {cx: c[0], cy: c[1], sides, radius} : null;
    this.redraw();
  },

  sendPolygon() {
    const sides = document.getElementById("map-sides").value, radius = document.getElementById("map-radius").value;
    this.sendCommand({desired_state: "POLYGON", polygon_sides: sides, polygon_radius: radius});
  },

  sendCommand(values) {
    if (!this.command) return;
    const request = {op: "send", type: this.command.type, target: this.command.targets[0].index, values,
                     comment: "from the map"};
    if (Liaison.send(request)) this.commandStatus("sending…");
    this.polygonDraft = null;
    this.setTool("pan");
  },

  commandStatus(text, bad) {
    const status = document.getElementById("map-command-status");
    status.textContent = text;
    status.classList.toggle("error", !!bad);
  },

  // ------------------------------------------------------------------------------------------ replay
  showLogs(msg) {
    const select = document.getElementById("replay-log");
    select.replaceChildren(...msg.logs.map((l) => el("option", {value: l.name, text: `${l.name} (${(l.size / 1e6).toFixed(1)} MB)`})));
    this.replayStatus(msg.logs.length ? `${msg.logs.length} log(s)` : `no .goby logs in ${msg.folders.join(", ")}`);
  },

  replayOpened(msg) {
    this.replay = {summary: msg, frame: null};
    const slider = document.getElementById("replay-slider");
    slider.min = msg.t0; slider.max = msg.t1; slider.step = 0.5; slider.value = msg.t0;
    slider.disabled = false;
    const dropped = msg.dropped ? `; ${msg.dropped} samples past the limit not loaded` : "";
    this.replayStatus(`replaying ${msg.name}: ${msg.vehicles.join(", ")}, ${msg.samples} samples${dropped}`);
    this.fitted = false;
    this.seek(msg.t0);
  },

  seek(t) {
    if (!this.replay) return;
    Liaison.send({op: "replay_seek", t, trail_s: this.trailShown * 2});
  },

  replayTime(t) {
    const s = this.replay.summary;
    document.getElementById("replay-time").textContent = `${timeText(t).substring(0, 8)} (+${(t - s.t0).toFixed(0)} s)`;
  },

  replayStatus(text, bad) {
    const status = document.getElementById("replay-status");
    status.textContent = text;
    status.classList.toggle("error", !!bad);
  },
};

function centre(points) {
  const xs = points.map((p) => p[0]), ys = points.map((p) => p[1]);
  return [(Math.min(...xs) + Math.max(...xs)) / 2, (Math.min(...ys) + Math.max(...ys)) / 2];
}

// MOOS-IvP's radial polygon (launch/usv/geometry.py radial_polygon): vertex k at bearing delta/2 + k*delta.
function radialRing(cx, cy, radius, sides) {
  const delta = 360 / sides;
  return Array.from({length: sides}, (_, k) => {
    const b = (delta / 2 + k * delta) * Math.PI / 180;
    return [cx + radius * Math.sin(b), cy + radius * Math.cos(b)];
  });
}

// Range (m) and compass bearing (deg) from a to b.
function rangeBearing(a, b) {
  const dx = b[0] - a[0], dy = b[1] - a[1];
  const bearing = (Math.atan2(dx, dy) * 180 / Math.PI + 360) % 360;
  return `${Math.hypot(dx, dy).toFixed(1)} m at ${bearing.toFixed(1)}°`;
}

// The server's second-order polynomial of the project's UTM projection (map_model.geo_polynomial).
function localToGeo(geo, x, y) {
  const terms = [1, x, y, x * x, x * y, y * y];
  const apply = (c) => c.reduce((sum, k, i) => sum + k * terms[i], 0);
  return [apply(geo.lat_terms), apply(geo.lon_terms)];
}

function clockText(secondsOfDay) {
  const s = Math.floor(secondsOfDay);
  const pad = (n) => String(n).padStart(2, "0");
  return `${pad(Math.floor(s / 3600) % 24)}:${pad(Math.floor(s / 60) % 60)}:${pad(s % 60)}`;
}
