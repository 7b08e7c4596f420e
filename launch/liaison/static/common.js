// goby-liaison page: the WebSocket connection shared by every view, and small helpers.
"use strict";

const Liaison = {
  ws: null,
  handlers: {},          // op -> [function(msg)]
  views: [],             // views this page subscribes to
  connected: false,
  retryMs: 500,

  on(op, fn) { (this.handlers[op] = this.handlers[op] || []).push(fn); },

  send(obj) {
    if (this.ws && this.ws.readyState === WebSocket.OPEN) { this.ws.send(JSON.stringify(obj)); return true; }
    return false;
  },

  connect() {
    const proto = location.protocol === "https:" ? "wss:" : "ws:";
    const ws = new WebSocket(`${proto}//${location.host}/ws`);
    this.ws = ws;
    ws.onopen = () => {
      this.connected = true; this.retryMs = 500;
      setConnection("connected", true);
      this.send({op: "subscribe", views: this.views});
      for (const fn of this.handlers.open || []) fn();
    };
    ws.onmessage = (event) => {
      let msg;
      try { msg = JSON.parse(event.data); } catch (e) { console.error("bad message from server", e); return; }
      for (const fn of this.handlers[msg.op] || []) fn(msg);
    };
    ws.onclose = (event) => {
      this.connected = false;
      setConnection(`disconnected${event.reason ? ": " + event.reason : ""}; retrying`, false);
      setTimeout(() => this.connect(), this.retryMs);
      this.retryMs = Math.min(this.retryMs * 2, 5000);
    };
  },
};

function setConnection(text, ok) {
  const el = document.getElementById("connection");
  el.textContent = text;
  el.className = "conn " + (ok ? "ok" : "bad");
}

function el(tag, attrs, ...children) {
  const node = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs || {})) {
    if (k === "class") node.className = v;
    else if (k === "text") node.textContent = v;
    else if (k.startsWith("data-")) node.setAttribute(k, v);
    else node[k] = v;
  }
  for (const child of children) if (child !== null && child !== undefined) node.append(child);
  return node;
}

function svg(tag, attrs) {
  const node = document.createElementNS("http://www.w3.org/2000/svg", tag);
  for (const [k, v] of Object.entries(attrs || {})) node.setAttribute(k, v);
  return node;
}

// Seconds since the epoch -> "HH:MM:SS.mmm" (UTC, as Goby prints times).
function timeText(seconds) {
  if (typeof seconds !== "number" || !isFinite(seconds)) return "";
  return new Date(seconds * 1000).toISOString().substring(11, 23);
}

Liaison.on("hello", (msg) => {
  document.getElementById("title").textContent = msg.title;
  document.title = msg.title;
});
Liaison.on("error", (msg) => { console.warn("server:", msg.error); });
