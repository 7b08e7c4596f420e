// Commander: a form built from the message's schema (DCCL bounds applied), checked here and again on the server.
"use strict";

const INT_KINDS = ["int", "uint", "int64", "uint64"];
const NUMBER_KINDS = INT_KINDS.concat(["float", "double"]);
const SENT_COLUMNS = 8;  // #, time, type, sent to, message, state, acknowledgements, comment

// The value DCCL carries for `number` in a field of step `step` (its precision), as its codec quantizes it
// (gateway/goby/dccl/arith.py): integers take the remainder toward zero, then go up a step from half a step;
// reals go to the nearest multiple, halves up.
function dcclQuantize(number, step, integer) {
  if (integer) {
    if (!(step > 1) || !Number.isInteger(step)) return number;
    const rem = number % step;  // toward zero, as C++
    return number - rem + (rem >= step / 2 ? step : 0);
  }
  if (step >= 1) return Math.floor(number / step + 0.5) * step;
  const inverse = 1 / step;
  return Math.floor(number * inverse + 0.5) / inverse;
}

// A number as DCCL's step shows it (no binary fraction noise: 0.30000000000000004 -> 0.3).
function stepText(number, step) {
  const places = step < 1 ? Math.min(12, Math.ceil(-Math.log10(step) - 1e-9)) : 0;
  return String(Number(number.toFixed(places)));
}

const Commander = {
  types: [],
  current: null,
  sent: new Map(),  // id -> <tr>
  roundings: [],    // the values of the form being sent that DCCL's precision changes
  notes: new Map(), // sent id -> those changes, said in its log row (this page's commands)

  init() {
    const head = document.querySelector("#sent-table thead tr");
    if (head && head.children.length < SENT_COLUMNS) head.append(el("th", {text: "Comment"}));
    Liaison.on("commands", (msg) => this.setTypes(msg.types));
    Liaison.on("sent", (msg) => this.showSent(msg.entries, msg.full));
    Liaison.on("accepted", (msg) => {
      const changed = this.roundings.splice(0);
      if (changed.length) this.notes.set(msg.id, changed);
      while (this.notes.size > 200) this.notes.delete(this.notes.keys().next().value);  // the server keeps 200
      this.status(`sent #${msg.id} to ${msg.target}` + (changed.length ? `; ${changed.join("; ")}` : ""));
      this.clearErrors();
    });
    Liaison.on("refused", (msg) => this.showError(msg.error, msg.field, "refused by the server: "));
    Liaison.on("notify", (msg) => this.notify(msg.items));
    Liaison.on("error", (msg) => { if (msg.op_failed === "send") this.showError(msg.error, "", "refused by the server: "); });
    document.getElementById("command-type").addEventListener("change", (e) => this.choose(e.target.value));
    document.getElementById("command-form").addEventListener("submit", (e) => { e.preventDefault(); this.submit(); });
  },

  setTypes(types) {
    this.types = types;
    const select = document.getElementById("command-type");
    const previous = select.value;
    select.replaceChildren(...types.map((t) => el("option", {value: t.name, text: t.name})));
    if (!types.length) {
      document.getElementById("command-fields").replaceChildren(
        el("p", {text: "No message types are configured (pb_commander_config { load_protobuf { ... } })."}));
      return;
    }
    const chosen = types.some((t) => t.name === previous) ? previous : types[0].name;
    select.value = chosen;
    this.choose(chosen);
  },

  choose(name) {
    this.current = this.types.find((t) => t.name === name);
    const targets = document.getElementById("command-target");
    targets.replaceChildren(...this.current.targets.map((t) => el("option", {value: String(t.index), text: t.label})));
    const container = document.getElementById("command-fields");
    container.replaceChildren(this.renderMessage(this.current.schema, ""));
    this.clearErrors();
  },

  // ---------------------------------------------------------------------------------------- form
  renderMessage(schema, prefix) {
    const box = el("div", {class: "message"});
    for (const field of schema.fields) box.append(this.renderField(field, prefix + field.name));
    return box;
  },

  renderField(field, path) {
    if (field.kind === "message" && field.label !== "repeated") {
      const fieldset = el("fieldset", {"data-path": path}, el("legend", {text: path + (field.label === "required" ? " *" : "")}));
      const inner = this.renderMessage(field.message, path + ".");
      if (field.label === "optional") {
        const include = el("input", {type: "checkbox", "data-include": path});
        include.addEventListener("change", () => { inner.hidden = !include.checked; });
        inner.hidden = true;
        fieldset.append(el("label", {}, include, " include"));
      }
      fieldset.append(inner);
      return fieldset;
    }
    if (field.label === "repeated") {
      const wrap = el("fieldset", {"data-path": path}, el("legend", {text: `${path} (repeated, up to ${field.max_repeat})`}));
      const count = el("input", {type: "number", min: field.min_repeat || 0, max: field.max_repeat, value: field.min_repeat || 0, "data-count": path});
      const items = el("div", {class: "items"});
      const redraw = () => {
        const n = Math.max(0, Math.min(field.max_repeat, parseInt(count.value || "0", 10) || 0));
        while (items.children.length > n) items.lastChild.remove();
        while (items.children.length < n) {
          const index = items.children.length;
          const element = Object.assign({}, field, {label: "required"});
          items.append(field.kind === "message" ? this.renderMessage(field.message, `${path}[${index}].`)
            : this.renderField(element, `${path}[${index}]`));
        }
      };
      count.addEventListener("input", redraw);
      wrap.append(el("label", {}, "count ", count), items);
      redraw();
      return wrap;
    }
    const input = this.input(field, path);
    const hint = this.hint(field);
    const rounding = el("strong", {class: "rounding", "data-rounding": path, role: "status"});
    if (this.roundingOf(field)) {
      input.addEventListener("input", () => {
        const note = this.roundingNote(input);
        rounding.textContent = note ? ` — ${note}` : "";
      });
    }
    return el("div", {class: "field"},
      el("label", {htmlFor: `f-${path}`}, path, field.label === "required" ? el("span", {class: "req", text: " *"}) : null),
      input, el("span", {class: "hint"}, hint, rounding));
  },

  // The step DCCL rounds this field's values to, or null when it carries every value as typed.
  roundingOf(field) {
    if (!field.dccl_bounds || !field.step || field.auto_time) return null;
    if (INT_KINDS.includes(field.kind) && field.step <= 1) return null;
    return field.step;
  },

  // "polygon_radius: 405 is sent as 410 (DCCL precision: steps of 10)", or null if the typed value goes as it is.
  roundingNote(input) {
    const field = input._field;
    const step = this.roundingOf(field);
    const number = Number(input.value.trim());
    if (step === null || input.value.trim() === "" || !isFinite(number)) return null;
    const sent = dcclQuantize(number, step, INT_KINDS.includes(field.kind));
    if (Math.abs(sent - number) <= Math.abs(number) * 1e-12) return null;
    return `${input.dataset.path}: ${input.value.trim()} is sent as ${stepText(sent, step)} ` +
      `(DCCL precision: steps of ${stepText(step, step)})`;
  },

  input(field, path) {
    let input;
    if (field.kind === "enum" || field.kind === "bool") {
      const values = field.kind === "enum" ? field.enum : ["true", "false"];
      const first = field.default !== null && field.default !== undefined ? `(default: ${field.default})`
        : field.label === "required" ? "(choose)" : "";
      input = el("select", {}, el("option", {value: "", text: first}), ...values.map((v) => el("option", {value: v, text: v})));
    } else if (NUMBER_KINDS.includes(field.kind) && !["int64", "uint64"].includes(field.kind)) {
      input = el("input", {type: "number"});
      if (field.min !== undefined) input.min = field.min;
      if (field.max !== undefined) input.max = field.max;
      input.step = field.step !== undefined ? field.step : "any";
      if (field.default !== null && field.default !== undefined) input.placeholder = `default ${field.default}`;
    } else {
      input = el("input", {type: "text"});
      if (field.max_length) input.maxLength = field.max_length;
      if (field.kind === "bytes") input.placeholder = "hex, e.g. 0a1b";
      if (["int64", "uint64"].includes(field.kind)) input.placeholder = "whole number";
    }
    input.id = `f-${path}`;
    input.name = path;
    input.dataset.path = path;
    input.dataset.kind = field.kind;
    if (field.auto_time) { input.disabled = true; input.placeholder = "auto: the time of sending"; input.value = ""; }
    if (field.static_value !== undefined) { input.disabled = true; input.value = field.static_value; }
    if (field.label === "required") input.required = true;
    input._field = field;
    input.addEventListener("input", () => input.classList.remove("invalid"));
    return input;
  },

  hint(field) {
    const parts = [field.kind];
    if (field.auto_time) parts.push("DCCL time: filled when sent");
    if (field.dccl_bounds) {
      parts.push(`DCCL [${field.min}, ${field.max}]` + (field.step !== 1 ? ` step ${field.step}` : ""));
      if (this.roundingOf(field)) parts.push(`values are rounded to a multiple of ${field.step}`);
    }
    if (field.max_length) parts.push(`at most ${field.max_length} characters`);
    if (field.oneof) parts.push(`oneof ${field.oneof}`);
    if (field.description) parts.push(field.description);
    return parts.join("; ");
  },

  // ---------------------------------------------------------------------------------- validation
  // The value of one input, or throws {field, message}.
  valueOf(input) {
    const field = input._field;
    const path = input.dataset.path;
    const raw = input.value.trim();
    const fail = (message) => { throw {field: path, message: `${path}: ${message}`}; };
    if (raw === "") {
      if (field.label === "required" && !field.auto_time && field.static_value === undefined) fail("is required");
      return undefined;
    }
    if (field.kind === "enum") return raw;
    if (field.kind === "bool") return raw === "true";
    if (field.kind === "string") return raw;
    if (field.kind === "bytes") {
      if (!/^([0-9a-fA-F]{2})*$/.test(raw)) fail(`${JSON.stringify(raw)} is not hex (pairs of 0-9, a-f)`);
      return raw;
    }
    if (["int64", "uint64"].includes(field.kind)) {
      if (!/^[+-]?\d+$/.test(raw)) fail(`${JSON.stringify(raw)} is not a whole number`);
      if (field.kind === "uint64" && raw.startsWith("-")) fail("must not be negative");
      return raw;
    }
    const number = Number(raw);
    if (!isFinite(number)) fail(`${JSON.stringify(raw)} is not a number`);
    if (INT_KINDS.includes(field.kind) && !Number.isInteger(number)) fail(`${raw} is not a whole number`);
    if (field.min !== undefined && field.max !== undefined) {
      const step = field.dccl_bounds && field.step ? field.step : null;
      const sent = step ? dcclQuantize(number, step, INT_KINDS.includes(field.kind)) : number;  // DCCL rounds, then checks
      if (sent < field.min || sent > field.max) {
        const range = `[${field.min}, ${field.max}]` + (step && step !== 1 ? `, in steps of ${step}` : "");
        fail(`${raw} is outside its ${field.dccl_bounds ? "DCCL bounds" : "range"} ${range}`);
      }
      const note = this.roundingNote(input);
      if (note) this.roundings.push(note);
    }
    return number;
  },

  // The form's values as an object shaped like the message; throws {field, message}.
  collect(container, schema, prefix) {
    const out = {};
    for (const field of schema.fields) {
      const path = prefix + field.name;
      if (field.label === "repeated") {
        const count = parseInt(container.querySelector(`[data-count="${CSS.escape(path)}"]`).value || "0", 10);
        const list = [];
        for (let i = 0; i < count; i++) {
          if (field.kind === "message") {
            list.push(this.collect(container, field.message, `${path}[${i}].`));
          } else {
            const input = container.querySelector(`[data-path="${CSS.escape(`${path}[${i}]`)}"]`);
            const value = this.valueOf(input);
            if (value === undefined) throw {field: `${path}[${i}]`, message: `${path}[${i}]: empty value`};
            list.push(value);
          }
        }
        if (list.length) out[field.name] = list;
      } else if (field.kind === "message") {
        const include = container.querySelector(`[data-include="${CSS.escape(path)}"]`);
        if (field.label === "required" || (include && include.checked)) {
          out[field.name] = this.collect(container, field.message, path + ".");
        }
      } else if (!field.auto_time) {
        const value = this.valueOf(container.querySelector(`[data-path="${CSS.escape(path)}"]`));
        if (value !== undefined) out[field.name] = value;
      }
    }
    return out;
  },

  submit() {
    this.clearErrors();
    if (!this.current) return;
    this.roundings = [];
    let values;
    try {
      values = this.collect(document.getElementById("command-fields"), this.current.schema, "");
    } catch (error) {
      if (error && error.message) { this.showError(error.message, error.field, "not sent: "); return; }
      throw error;
    }
    const request = {op: "send", type: this.current.name, target: Number(document.getElementById("command-target").value),
      values: values, comment: document.getElementById("command-comment").value};
    if (Liaison.send(request)) this.status("sending…");
    else this.showError("not connected to goby-liaison", "", "not sent: ");
  },

  clearErrors() {
    document.getElementById("command-error").textContent = "";
    for (const bad of document.querySelectorAll("#command-fields .invalid")) bad.classList.remove("invalid");
  },

  showError(message, field, prefix) {
    document.getElementById("command-error").textContent = prefix + message;
    this.status("");
    if (field) {
      const input = document.querySelector(`#command-fields [data-path="${CSS.escape(field)}"]`);
      if (input) { input.classList.add("invalid"); input.setAttribute("aria-invalid", "true"); input.focus(); }
    }
  },

  status(text) { document.getElementById("send-status").textContent = text; },

  // ------------------------------------------------------------------------------------- the log
  showSent(entries, full) {
    const body = document.querySelector("#sent-table tbody");
    if (full) { body.replaceChildren(); this.sent.clear(); }
    for (const entry of entries) {
      let tr = this.sent.get(entry.id);
      if (!tr) {
        tr = el("tr", {"data-sent-id": String(entry.id)});
        for (let i = 0; i < SENT_COLUMNS; i++) tr.append(el("td"));
        body.prepend(tr);
        this.sent.set(entry.id, tr);
      }
      const cells = tr.children;
      cells[0].textContent = entry.id;
      cells[1].textContent = timeText(entry.time);
      cells[2].textContent = entry.type;
      cells[3].textContent = entry.target;
      const notes = this.notes.get(entry.id);
      cells[4].textContent = entry.text + (notes ? `\n(${notes.join("; ")})` : "");
      cells[5].textContent = entry.state + (entry.error ? `: ${entry.error}` : "");
      cells[5].className = `state state-${entry.state}`;
      cells[6].textContent = entry.acks.join("\n");
      cells[7].textContent = entry.comment;
      cells[7].className = "comment";
    }
  },

  notify(items) {
    const list = document.getElementById("notifications");
    for (const item of items) {
      list.prepend(el("li", {text: `${item.type}/${item.group} @ ${timeText(item.time)}: ${item.value}`}));
    }
    while (list.children.length > 50) list.lastChild.remove();
  },
};
