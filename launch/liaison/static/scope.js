// Scope: one row per (group, type, scheme), updated from the server's coalesced updates.
"use strict";

const Scope = {
  rows: new Map(),      // id -> {tr, cells, data, key}
  histories: new Map(), // id -> history <tr>
  paused: false,
  received: 0,

  init() {
    const form = document.getElementById("scope-filters");
    form.addEventListener("submit", (e) => { e.preventDefault(); this.setFilter(); });
    document.getElementById("filter-clear").addEventListener("click", () => {
      document.getElementById("group-filter").value = ".*";
      document.getElementById("type-filter").value = ".*";
      this.setFilter();
    });
    document.getElementById("pause").addEventListener("click", () => this.setPaused(!this.paused));
    Liaison.on("hello", (msg) => {
      document.getElementById("group-filter").value = msg.filters.group;
      document.getElementById("type-filter").value = msg.filters.type;
      this.showPaused(msg.start_paused);
    });
    Liaison.on("scope", (msg) => this.update(msg));
    Liaison.on("filter", () => { document.getElementById("filter-error").textContent = ""; });
    Liaison.on("paused", (msg) => this.showPaused(msg.paused));
    Liaison.on("history", (msg) => this.showHistory(msg.id, msg.items));
    Liaison.on("error", (msg) => {
      if (msg.op_failed === "filter") document.getElementById("filter-error").textContent = msg.error;
    });
  },

  setFilter() {
    const group = document.getElementById("group-filter").value;
    const type = document.getElementById("type-filter").value;
    for (const [what, expression] of [["group", group], ["type", type]]) {
      try { new RegExp(expression); } catch (e) {
        document.getElementById("filter-error").textContent =
          `${what} filter ${JSON.stringify(expression)} is not a valid regular expression: ${e.message}`;
        return;
      }
    }
    Liaison.send({op: "filter", group: group, type: type});
  },

  setPaused(paused) {
    this.showPaused(paused);
    Liaison.send({op: paused ? "pause" : "resume"});
  },

  showPaused(paused) {
    this.paused = paused;
    const button = document.getElementById("pause");
    button.textContent = paused ? "Play" : "Pause";
    document.getElementById("view-scope").classList.toggle("paused", paused);
    this.status();
  },

  key(row) { return `${row.group}\u0000${row.type}\u0000${row.scheme}`; },

  update(msg) {
    if (this.paused && !msg.full) return;  // updates already in flight when the page paused
    if (msg.full) {
      const keep = new Set(msg.rows.map((r) => r.id));
      for (const id of [...this.rows.keys()]) if (!keep.has(id)) this.remove(id);
    }
    for (const row of msg.rows) this.upsert(row);
    this.received += msg.rows.length;
    this.status();
  },

  upsert(row) {
    let entry = this.rows.get(row.id);
    if (!entry) {
      const cells = {};
      const tr = el("tr", {class: "row", "data-id": String(row.id)});
      for (const name of ["group", "type", "scheme", "value", "time", "count", "rate"]) {
        cells[name] = el("td", {class: name + (["count", "rate"].includes(name) ? " num" : "")});
        tr.append(cells[name]);
      }
      tr.addEventListener("click", () => this.toggle(row.id));
      entry = {tr, cells, data: {}, key: this.key(row)};
      this.rows.set(row.id, entry);
      this.insertSorted(entry);
    }
    Object.assign(entry.data, row);
    const d = entry.data;
    entry.cells.group.textContent = d.group;
    entry.cells.type.textContent = d.type;
    entry.cells.scheme.textContent = d.scheme;
    entry.cells.value.textContent = d.value;
    entry.cells.value.title = d.value;
    entry.cells.time.textContent = timeText(d.time);
    entry.cells.count.textContent = d.count;
    entry.cells.rate.textContent = (d.rate || 0).toFixed(1);
  },

  insertSorted(entry) {
    const body = document.querySelector("#scope-table tbody");
    let before = null;
    for (const other of this.rows.values()) {
      if (other !== entry && other.tr.parentNode && other.key > entry.key && (!before || other.key < before.key)) {
        before = other;
      }
    }
    body.insertBefore(entry.tr, before ? before.tr : null);
  },

  remove(id) {
    const entry = this.rows.get(id);
    if (entry) entry.tr.remove();
    this.rows.delete(id);
    const history = this.histories.get(id);
    if (history) history.remove();
    this.histories.delete(id);
  },

  toggle(id) {
    if (this.histories.has(id)) {
      this.histories.get(id).remove();
      this.histories.delete(id);
      Liaison.send({op: "collapse", id: id});
    } else {
      const entry = this.rows.get(id);
      const tr = el("tr", {class: "history", "data-history-of": String(id)}, el("td", {colSpan: 7, text: "loading…"}));
      entry.tr.after(tr);
      this.histories.set(id, tr);
      Liaison.send({op: "expand", id: id});
    }
  },

  showHistory(id, items) {
    const tr = this.histories.get(id);
    if (!tr || (this.paused && tr.dataset.filled)) return;
    tr.dataset.filled = "1";
    const text = items.map((item) => `${timeText(item.time)}  ${item.value.trim()}`).join("\n");
    tr.firstChild.textContent = `last ${items.length} value(s), newest first:\n${text}`;
  },

  status() {
    const shown = this.rows.size;
    document.getElementById("scope-status").textContent =
      `${shown} row(s)${this.paused ? " — paused" : ""}`;
  },
};
