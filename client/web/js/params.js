// A form from a campaign's declared parameters, checked here against the same declaration the daemon
// validates with (type, min/max, values, items, min_items/max_items), so a typo is caught before submit;
// the daemon's own 400 still has the last word.
import { h } from "./dom.js";

function fieldId(campaign, name) { return `p-${campaign}-${name}`.replace(/[^A-Za-z0-9_-]/g, "_"); }

function inputFor(campaign, name, d) {
  const id = fieldId(campaign, name);
  const common = { id, name, "aria-describedby": `${id}-help ${id}-err` };
  if (d.type === "boolean") {
    return h("input", { ...common, type: "checkbox", checked: d.default === true });
  }
  if (d.values && d.type !== "array") {
    return h("select", common, d.values.map(v => h("option", { value: String(v), selected: v === d.default }, String(v))));
  }
  if (d.type === "integer" || d.type === "number") {
    return h("input", { ...common, type: "text", inputmode: d.type === "integer" ? "numeric" : "decimal",
                        value: d.default === null || d.default === undefined ? "" : String(d.default) });
  }
  if (d.type === "array") {
    return h("input", { ...common, type: "text", value: Array.isArray(d.default) ? d.default.join(", ") : "" });
  }
  return h("input", { ...common, type: "text", value: d.default === null || d.default === undefined ? "" : String(d.default) });
}

function describe(d) {
  const parts = [d.description || ""];
  const range = [];
  if (d.min !== undefined && d.min !== null) range.push(`≥ ${d.min}`);
  if (d.max !== undefined && d.max !== null) range.push(`≤ ${d.max}`);
  if (range.length) parts.push(`(${range.join(", ")})`);
  if (d.type === "array") parts.push(`— comma-separated ${d.items || "values"}${d.values ? ` from ${d.values.join(", ")}` : ""}`);
  return parts.filter(Boolean).join(" ");
}

export function paramForm(campaign) {
  const params = campaign.parameters || {};
  const names = Object.keys(params).sort();
  const rows = names.map(name => {
    const d = params[name];
    const id = fieldId(campaign.name, name);
    return h("div", { class: "field" },
      h("label", { for: id }, name, d.unit ? h("span", { class: "unit" }, ` (${d.unit})`) : null),
      inputFor(campaign.name, name, d),
      h("small", { id: `${id}-help`, class: "help" }, describe(d)),
      h("small", { id: `${id}-err`, class: "field-error", "aria-live": "polite" }));
  });
  return rows.length ? rows : [h("p", { class: "muted" }, "This campaign takes no parameters.")];
}

function number(raw, d, errors, name) {
  const v = Number(raw);
  if (raw.trim() === "" || !Number.isFinite(v)) { errors[name] = "a number is needed"; return undefined; }
  if (d.type === "integer" && !Number.isInteger(v)) { errors[name] = "a whole number is needed"; return undefined; }
  if (d.min !== undefined && d.min !== null && v < d.min) { errors[name] = `at least ${d.min}`; return undefined; }
  if (d.max !== undefined && d.max !== null && v > d.max) { errors[name] = `at most ${d.max}`; return undefined; }
  return v;
}

// → {params, errors}. Every shown field is sent (the run then records what the operator saw), except an
// empty number whose default is unset: that one means "as configured".
export function readParams(campaign, form) {
  const params = {}, errors = {};
  for (const [name, d] of Object.entries(campaign.parameters || {})) {
    const input = form.querySelector(`#${fieldId(campaign.name, name)}`);
    if (!input) continue;
    if (d.type === "boolean") { params[name] = input.checked; continue; }
    const raw = input.value;
    if (d.type === "integer" || d.type === "number") {
      if (raw.trim() === "" && (d.default === null || d.default === undefined)) continue;  // unset = as configured
      const v = number(raw, d, errors, name);
      if (v !== undefined) params[name] = v;
    } else if (d.type === "array") {
      const parts = raw.split(",").map(s => s.trim()).filter(s => s !== "");
      const out = [];
      for (const p of parts) {
        if (d.items === "number" || d.items === "integer") {
          const v = number(p, { ...d, type: d.items }, errors, name);
          if (v === undefined) break;
          out.push(v);
        } else {
          if (d.values && !d.values.includes(p)) { errors[name] = `"${p}" is not one of ${d.values.join(", ")}`; break; }
          out.push(p);
        }
      }
      if (d.min_items !== undefined && out.length < d.min_items) errors[name] ??= `at least ${d.min_items} item(s)`;
      if (d.max_items !== undefined && out.length > d.max_items) errors[name] ??= `at most ${d.max_items} item(s)`;
      if (!errors[name]) params[name] = out;
    } else {
      if (d.values && !d.values.map(String).includes(raw)) { errors[name] = `one of ${d.values.join(", ")}`; continue; }
      params[name] = raw;
    }
  }
  for (const name of Object.keys(campaign.parameters || {})) {
    const err = form.querySelector(`#${fieldId(campaign.name, name)}-err`);
    const input = form.querySelector(`#${fieldId(campaign.name, name)}`);
    if (err) err.textContent = errors[name] || "";
    if (input) input.setAttribute("aria-invalid", errors[name] ? "true" : "false");
  }
  return { params, errors };
}
