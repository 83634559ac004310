// Lab: every instrument as the daemon sees it. Instrument state changes are not events (only added and
// removed are), so the page re-reads GET /v1/instruments while it is shown.
import { get } from "../api.js";
import { h, replace, badge, errorBox } from "../dom.js";

const POLL_MS = 5000;

function calibration(list) {
  if (!list || !list.length) return h("span", { class: "muted" }, "no calibration needed");
  return h("ul", { class: "plain" }, list.map(c => h("li", {},
    badge(c.valid ? "valid" : "invalid"), ` ${c.type || "calibration"}`,
    c.readings_left !== undefined ? ` · ${c.readings_left} readings left` : "",
    c.valid_until_unix_ms !== undefined ? expiry(c.valid_until_unix_ms) : "")));
}

function expiry(ms) {
  const left = (ms - Date.now()) / 1000;
  return ` · ${left > 0 ? "expires" : "expired"} ${new Date(ms).toLocaleString()}`;
}

function card(i) {
  const lampish = (i.capabilities || []).some(c => c === "lamp_switching" || c === "dimmer");
  return h("article", { class: "card instrument", dataset: { instrument: i.id } },
    h("header", {}, h("h3", {}, i.id), badge(i.state),
      h("span", { class: i.simulated ? "tag sim" : "tag real" }, i.simulated ? "SIMULATED" : "real")),
    h("dl", {},
      h("dt", {}, "model"), h("dd", {}, i.model || i.kind || "—"),
      h("dt", {}, "port"), h("dd", { class: "mono" }, i.port || "—"),
      i.serial ? [h("dt", {}, "serial"), h("dd", {}, i.serial)] : null,
      i.firmware ? [h("dt", {}, "firmware"), h("dd", {}, i.firmware)] : null,
      h("dt", {}, "can"), h("dd", {}, (i.capabilities || []).join(", ") || "—"),
      h("dt", {}, "calibration"), h("dd", {}, calibration(i.calibration)),
      lampish ? [h("dt", {}, "lamps, dimmer"), h("dd", {}, lampState(i))] : null),
    // An absent instrument (configured, not up) carries its reason; its problem would repeat it.
    i.reason ? h("p", { class: "error reason" }, `absent: ${i.reason}`)
      : i.problem ? h("p", { class: "error" }, typeof i.problem === "string" ? i.problem : (i.problem.detail || JSON.stringify(i.problem))) : null);
}

// GET /v1/instruments' `lab`: {lamps: {name: lit}, levels: {name: percent}, dimmer: percent of the lit lamp}.
function lampState(i) {
  const lab = i.lab || i.status || {};
  if (!lab.lamps && lab.dimmer === undefined) return h("span", { class: "muted" }, "levels not reported by the daemon");
  return h("span", {},
    lab.lamps ? Object.entries(lab.lamps).map(([k, v]) =>
      `${k}: ${v ? "on" : "off"}${lab.levels && lab.levels[k] !== undefined && v ? ` (${lab.levels[k]} %)` : ""}`).join(", ") : "",
    lab.dimmer !== undefined ? ` · dimmer ${lab.dimmer} %` : "");
}

export function mount(section, ctx) {
  const list = h("div", { class: "cards", id: "instruments" });
  const status = h("p", { class: "muted", "aria-live": "polite" });
  section.append(h("h2", {}, "Lab"), status, list);
  let timer = null;

  async function refresh() {
    try {
      const r = await get("/v1/instruments");
      for (const i of r.items) ctx.store.instruments.set(i.id, i);
      render();
      status.textContent = `${r.items.length} instruments · read ${new Date().toLocaleTimeString()}`;
    } catch (e) {
      replace(status, errorBox(e));
    }
  }

  function render() {
    replace(list, [...ctx.store.instruments.values()].map(card));
  }

  return {
    show() { refresh(); timer = setInterval(refresh, POLL_MS); },
    hide() { clearInterval(timer); timer = null; },
    update(what) {
      if (what.kind === "snapshot") render();
      else if (what.event && what.event.topic === "instrument") refresh();
    },
  };
}
