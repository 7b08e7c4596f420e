// Scope: one row per (group, type, scheme), updated from the server's coalesced updates.
"use strict";

// Goby's liaison matches a filter against the whole name (regex_match), and so does this page; the page says so.
const WHOLE_NAME_HINT = "Expressions match the whole name, as in Goby's liaison: \"state\" finds only a name that " +
  "is exactly \"state\"; \".*state.*\" finds every name containing it.";
const MATCH_ALL = ["", ".*"];

// The expression that finds names containing what `expression` matches: `state` -> `.*state.*`.
function containing(expression) {
  if (expression.startsWith(".*") && expression.endsWith(".*")) return expression;
  return expression.includes("|") ? `.*(?:${expression}).*` : `.*${expression}.*`;
}

const Scope = {
  rows: new Map(),      // id -> {tr, cells, data, key}
  filters: {group: ".*", type: ".*"},  // what the server applies (its last "hello" or "filter" reply)
  synced: false,        // a full update for the current filters has arrived
  histories: new Map(), // id -> history <tr>
  paused: false,
  received: 0,

  init() {
    const form = document.getElementById("scope-filters");
    for (const what of ["group", "type"]) {
      const input = document.getElementById(`${what}-filter`);
      input.placeholder = "whole name, e.g. .*state.*";
      input.title = `Regular expression (RE2) for the ${what} name. ${WHOLE_NAME_HINT}`;
    }
    const hint = el("div", {id: "filter-hint", class: "status", text: WHOLE_NAME_HINT});
    const empty = el("div", {id: "filter-empty", class: "status", role: "status", hidden: true});
    document.getElementById("filter-error").after(hint, empty);
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
      this.applied(msg.filters.group, msg.filters.type);
      this.showPaused(msg.start_paused);
    });
    Liaison.on("scope", (msg) => this.update(msg));
    Liaison.on("filter", (msg) => {
      document.getElementById("filter-error").textContent = "";
      this.applied(msg.group, msg.type);
    });
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

  applied(group, type) {
    this.filters = {group, type};
    this.synced = false;  // until the full update for these filters
    this.status();
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
    if (msg.full) this.synced = true;
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
    this.showEmpty(shown === 0 && this.synced);
  },

  // When the filters leave no row: say why that may be (whole-name matching) and offer the `.*x.*` form.
  showEmpty(empty) {
    const line = document.getElementById("filter-empty");
    const narrowing = ["group", "type"].filter((what) => !MATCH_ALL.includes(this.filters[what]));
    if (!line || !empty || !narrowing.length) { if (line) line.hidden = true; return; }
    const parts = narrowing.map((what) => `${what} ${JSON.stringify(this.filters[what])}`);
    const suggestion = narrowing.map((what) => JSON.stringify(containing(this.filters[what]))).join(" / ");
    const button = el("button", {type: "button", id: "filter-containing", text: `Use ${suggestion}`});
    button.addEventListener("click", () => {
      for (const what of narrowing) document.getElementById(`${what}-filter`).value = containing(this.filters[what]);
      this.setFilter();
    });
    line.replaceChildren(`No name matches ${parts.join(" and ")} as a whole (names are matched whole, as in ` +
      `Goby's liaison), or nothing matching has been published yet. To find names containing it, try ` +
      `${suggestion}. `, button);
    line.hidden = false;
  },
};
