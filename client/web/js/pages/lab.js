// Lab: every instrument as the daemon sees it. Instrument state changes are not events (only added and
// removed are), so the page re-reads GET /v1/instruments while it is shown; with shipping on, also what
// colorlab-ship has not shipped yet and its last error (GET /v1/shipping, read from the bench's own files).
import { get } from "../api.js";
import { h, replace, badge, errorBox, fmtDuration, fmtTime, short } from "../dom.js";

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

// GET /v1/shipping as one card; nothing when the bench does not ship (no [ship] section, no agent seen).
function shippingCard(s) {
  if (!s || (!s.enabled && !s.agent)) return null;
  const lag = s.lag || {};
  const waiting = lag.unshipped_runs || 0;
  const agent = s.agent;
  const err = s.last_error;
  return h("article", { class: "card shipping", id: "shipping" },
    h("header", {}, h("h3", {}, "Shipping"),
      badge(waiting === 0 ? "shipped" : "waiting"),
      agent ? badge(agent.ok ? "agent_ok" : "agent_failing") : badge("no_agent")),
    h("dl", {},
      h("dt", {}, "not shipped"), h("dd", { id: "shipping-lag" }, waiting === 0 ? "every ended run has shipped"
        : `${waiting} ended run(s); the oldest ${short(lag.oldest_unshipped_run)} (${lag.oldest_unshipped_status}) waits ${fmtDuration(lag.age_s)}`),
      h("dt", {}, "position"), h("dd", { class: "mono" }, `${s.shipped_position} of ${s.last_event}`),
      h("dt", {}, "agent"), h("dd", {}, agent ? `last cycle ${agent.ok ? "ok" : "failed"}, ${fmtDuration(s.agent_seen_s_ago)} ago`
        : "no cycle recorded yet (is colorlab-ship running?)")),
    err ? h("p", { class: "error", id: "shipping-error" }, `last error (${fmtTime(err.at)}): ${err.message}`,
      err.hint ? h("span", { class: "hint" }, ` — ${err.hint}`) : null) : null);
}

export function mount(section, ctx) {
  const list = h("div", { class: "cards", id: "instruments" });
  const status = h("p", { class: "muted", "aria-live": "polite" });
  const shipping = h("div", { class: "cards", id: "shipping-box" });
  section.append(h("h2", {}, "Lab"), status, shipping, list);
  let timer = null;

  async function refreshShipping() {
    try {
      replace(shipping, shippingCard(await get("/v1/shipping")));
    } catch (e) {
      // An older daemon without the route: nothing to show.
      if (e && e.status === 404) replace(shipping);
      else replace(shipping, errorBox(e));
    }
  }

  async function refresh() {
    refreshShipping();
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
