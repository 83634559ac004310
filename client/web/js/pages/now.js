// Now: what the lab is doing this minute — the running step, progress and ETA, the readings as they are
// committed, why anything is paused or suspended, and what the campaigns ask the operator.
import { get, post } from "../api.js";
import { h, replace, badge, fmtDuration, fmtNumber, short, errorBox } from "../dom.js";
import { lineChart } from "../chart.js";
import { isTerminal, LIMITS } from "../store.js";
import { suspensionSummary } from "../suspension.js";

export function mount(section, ctx) {
  const requestsBox = h("div", { id: "requests" });
  const running = h("div", { id: "running" });
  const chartBox = h("div", { id: "readings" });
  section.append(h("h2", {}, "Now"),
    h("section", { class: "panel" }, h("h3", {}, "Operator requests"), requestsBox),
    h("section", { class: "panel" }, h("h3", {}, "Executions"), running),
    h("section", { class: "panel" }, h("h3", {}, "Live readings"), chartBox));

  // Readings of one run only (the one being watched), fetched incrementally with the measurements'
  // keyset cursor (the last seq) and capped, so a 10 000-reading night costs a few hundred points here.
  let readings = { runId: null, cursor: null, points: [], quantity: null, unit: "" };
  let fetching = false, again = false, visible = false;

  function watched() {
    const list = [...ctx.store.executions.values()];
    return list.find(e => e.status === "running") || list.find(e => !isTerminal(e.status))
      || list.filter(e => isTerminal(e.status)).sort((a, b) => (b.finished_at || 0) - (a.finished_at || 0))[0];
  }

  async function fetchReadings() {
    const e = watched();
    if (!e || !e.run_id) return;
    if (readings.runId !== e.run_id) readings = { runId: e.run_id, cursor: null, points: [], quantity: null, unit: "" };
    if (fetching) { again = true; return; }
    fetching = true;
    try {
      do {
        again = false;
        for (let pages = 0; pages < 5; pages++) {
          const q = `/v1/runs/${readings.runId}/measurements?limit=1000${readings.cursor ? `&cursor=${encodeURIComponent(readings.cursor)}` : ""}`;
          const r = await get(q);
          for (const m of r.items) {
            readings.cursor = String(m.seq);
            if (typeof m.value !== "number") continue;
            if (readings.quantity && m.quantity !== readings.quantity) continue;
            readings.quantity = m.quantity;
            readings.unit = m.unit;
            readings.points.push({ x: m.seq, y: m.value });
          }
          if (readings.points.length > LIMITS.readings) readings.points.splice(0, readings.points.length - LIMITS.readings);
          if (!r.next_cursor) break;
        }
      } while (again);
      renderChart();
    } catch (err) {
      replace(chartBox, errorBox(err));
    } finally {
      fetching = false;
    }
  }

  function renderChart() {
    const last = readings.points[readings.points.length - 1];
    replace(chartBox,
      readings.runId ? h("p", {}, `run ${short(readings.runId)}: `,
        h("span", { id: "reading-count" }, `${readings.points.length}`), ` ${readings.quantity || "numeric"} readings shown`,
        last ? [", last ", h("strong", { id: "last-reading" }, `${fmtNumber(last.y)} ${readings.unit}`)] : "",
        " · ", h("a", { href: `#runs/${readings.runId}` }, "open run")) : h("p", { class: "muted" }, "No run to show."),
      lineChart(readings.points, { label: readings.quantity || "", unit: readings.unit }));
  }

  function executionCard(e) {
    const pct = Math.round((e.progress || 0) * 100);
    const eta = isTerminal(e.status) ? null : ctx.store.eta(e);
    return h("article", { class: "card execution", dataset: { execution: e.id } },
      h("header", {}, h("h4", {}, e.campaign || "execution"), badge(e.status),
        h("span", { class: "mono muted" }, short(e.id))),
      h("div", { class: "progress-line" },
        h("progress", { max: 100, value: pct, "aria-label": `progress of ${e.campaign || e.id}` }),
        h("span", { class: "progress-text" }, `${pct} %`)),
      h("dl", {},
        h("dt", {}, "step"), h("dd", { class: "step" }, e.step || "—"),
        h("dt", {}, "ETA"), h("dd", {}, isTerminal(e.status) ? "ended" : e.status === "paused" || e.status === "suspended"
          ? `on hold (${e.status})` : eta === null ? "estimating…" : fmtDuration(eta)),
        e.status === "suspended" && e.suspension
          ? [h("dt", {}, "waiting out"), h("dd", { class: "suspension-line" }, suspensionSummary(e.suspension, ctx.store.serverNow()))] : null,
        e.reason ? [h("dt", {}, e.status === "suspended" ? "suspended because" : "reason"), h("dd", { class: "reason" }, e.reason)] : null,
        e.problem ? [h("dt", {}, "problem"), h("dd", {}, e.problem.detail || e.problem.title || "",
          e.problem.hint ? h("span", { class: "hint" }, ` — ${e.problem.hint}`) : null)] : null),
      e.status === "suspended" || e.status === "paused" ? h("div", { class: "buttons" },
        h("button", { type: "button", class: "control resume", dataset: { focus: `now-resume-${e.id}` }, disabled: !ctx.access.control,
                      onclick: () => resume(e) }, "Resume now")) : null,
      e.run_id ? h("a", { href: `#runs/${e.run_id}` }, "open run") : null);
  }

  async function resume(e) {
    try { await post(`/v1/executions/${e.id}/resume`); ctx.toast("resume: sent"); }
    catch (err) { ctx.toast(`resume: ${err.message}`, true); ctx.accessChanged(err); }
  }

  function renderRunning() {
    const list = [...ctx.store.executions.values()];
    const live = list.filter(e => !isTerminal(e.status));
    const ended = list.filter(e => isTerminal(e.status)).sort((a, b) => (b.finished_at || 0) - (a.finished_at || 0)).slice(0, 3);
    replace(running,
      live.length ? h("div", { class: "cards" }, live.map(executionCard)) : h("p", { class: "muted" }, "Nothing is running."),
      ended.length ? [h("h4", {}, "Just ended"), h("div", { class: "cards" }, ended.map(executionCard))] : null);
  }

  async function answer(r, option, buttons) {
    for (const b of buttons) b.disabled = true;
    try {
      await post(`/v1/requests/${r.id}`, { answer: option, by: "console" });
      ctx.toast(`answered "${option}"`);
    } catch (e) {
      ctx.toast(`answer failed: ${e.message}`, true);
      ctx.accessChanged(e);
      for (const b of buttons) b.disabled = !ctx.access.control;
    }
  }

  function remaining(r) {
    const deadline = Date.parse(r.deadline);
    return Number.isNaN(deadline) ? null : (deadline - ctx.store.serverNow()) / 1000;
  }

  function renderRequests() {
    const list = [...ctx.store.requests.values()];
    if (!list.length) { replace(requestsBox, h("p", { class: "muted" }, "No campaign is waiting for the operator.")); return; }
    replace(requestsBox, list.map(r => {
      const buttons = [];
      const card = h("article", { class: "card request", dataset: { request: r.id } },
        h("header", {}, h("h4", {}, r.action), badge("needs_operator")),
        h("p", { class: "prompt" }, r.prompt),
        h("p", {}, "default ", h("strong", {}, String(r.default)), " in ",
          h("span", { class: "countdown", dataset: { deadline: r.deadline } }, fmtDuration(remaining(r)))),
        h("div", { class: "buttons" }, (r.options || []).map(o => {
          const b = h("button", { type: "button", class: "control answer", dataset: { focus: `ans-${r.id}-${o}`, option: o },
                                  disabled: !ctx.access.control }, String(o));
          b.addEventListener("click", () => answer(r, o, buttons));
          buttons.push(b);
          return b;
        })),
        r.execution_id ? h("p", { class: "muted" }, `for execution ${short(r.execution_id)}`) : null);
      return card;
    }));
  }

  // The countdowns tick without re-rendering the buttons (which would steal a keyboard user's focus).
  setInterval(() => {
    if (!visible) return;
    for (const el of requestsBox.querySelectorAll(".countdown")) {
      const left = (Date.parse(el.dataset.deadline) - ctx.store.serverNow()) / 1000;
      el.textContent = fmtDuration(left);
    }
  }, 1000);

  return {
    show() { visible = true; renderRequests(); renderRunning(); fetchReadings(); renderChart(); },
    hide() { visible = false; },
    update(what) {
      if (!visible) return;
      const t = what.event && what.event.topic;
      if (what.kind === "snapshot" || what.kind === "access" || t === "operator") renderRequests();
      if (what.kind === "snapshot" || t === "execution" || t === "progress") { renderRunning(); fetchReadings(); }
      // A key given while a run waits suspended must enable its Resume at once, not at the run's next event.
      else if (what.kind === "access") renderRunning();
    },
  };
}
