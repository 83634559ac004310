// Queue: start a campaign (now, or as the night's next item) from its declared parameters, see its dry run
// first, and steer what is running. Every control button is a real <button>, disabled while the key lacks
// the control scope.
import { get, post, del } from "../api.js";
import { h, replace, badge, errorBox, fmtDuration, fmtBytes, fmtTime, short } from "../dom.js";
import { paramForm, readParams } from "../params.js";
import { isTerminal } from "../store.js";
import { suspensionSummary } from "../suspension.js";

function dryRunReport(r) {
  const est = r.estimate || {};
  return h("section", { class: "dry-run", "aria-label": "dry run" },
    h("h4", {}, "Dry run: ", badge(r.ok ? "ok" : "problems")),
    h("dl", {},
      h("dt", {}, "estimated duration"), h("dd", { class: "estimate" }, fmtDuration(est.wall_seconds),
        est.lab_seconds !== undefined ? ` (lab time ${fmtDuration(est.lab_seconds)}, time scale ${est.time_scale})` : ""),
      h("dt", {}, "measurements"), h("dd", {}, String(r.measurements ?? "—")),
      h("dt", {}, "lab calls"), h("dd", {}, String(r.calls ?? "—")),
      h("dt", {}, "operator actions"), h("dd", {}, (r.operator_actions || []).length
        ? h("ul", { class: "plain" }, r.operator_actions.map(a => h("li", {}, `${a.prompt} (${a.options.join(" / ")}, default ${a.default} after ${fmtDuration(a.timeout_s)}) × ${a.count}`)))
        : "none"),
      h("dt", {}, "storage"), h("dd", {}, r.storage ? `${fmtBytes(r.storage.estimated_bytes)} of ${fmtBytes(r.storage.available_bytes)} free` : "—"),
      h("dt", {}, "instruments"), h("dd", {}, (r.instruments || []).map(i => `${i.role}: ${i.instrument} (${i.state}${i.simulated ? ", simulated" : ""})`).join("; ") || "—")),
    (r.problems || []).length ? h("ul", { class: "problems" }, r.problems.map(p => h("li", {}, h("strong", {}, p.kind), `: ${p.message}`))) : null);
}

export function mount(section, ctx) {
  const select = h("select", { id: "campaign", name: "campaign" });
  const fields = h("div", { class: "fields" });
  const onFailure = h("select", { id: "on-failure" }, h("option", { value: "stop" }, "stop the queue"),
    h("option", { value: "continue" }, "go on with the next item"));
  const result = h("div", { class: "result", "aria-live": "polite" });
  const btnDry = h("button", { type: "button", id: "dry-run", class: "control" }, "Dry run");
  const btnStart = h("button", { type: "submit", id: "start", class: "control primary" }, "Start now");
  const btnEnqueue = h("button", { type: "button", id: "enqueue", class: "control" }, "Add to queue");
  const form = h("form", { id: "start-form", novalidate: true },
    h("div", { class: "field" }, h("label", { for: "campaign" }, "campaign"), select,
      h("small", { class: "help", id: "campaign-help" })),
    fields,
    h("div", { class: "field" }, h("label", { for: "on-failure" }, "if a queued item fails"), onFailure),
    h("div", { class: "buttons" }, btnDry, btnStart, btnEnqueue), result);
  const executions = h("div", { id: "executions" });
  const queueBox = h("div", { id: "queue" });
  const recentBox = h("div", { id: "recent-executions", class: "table-wrap" });  // scrolls inside itself on a phone
  section.append(h("h2", {}, "Queue"),
    h("section", { class: "panel" }, h("h3", {}, "Start a campaign"), form),
    h("section", { class: "panel" }, h("h3", {}, "Executions"), executions),
    h("section", { class: "panel" }, h("h3", {}, "The night's queue"), queueBox),
    h("section", { class: "panel" }, h("h3", {}, "Recent executions"), recentBox));

  let campaigns = [];
  const current = () => campaigns.find(c => c.name === select.value);

  async function loadCampaigns() {
    try {
      const r = await get("/v1/campaigns");
      campaigns = r.items.filter(c => c.kind !== "sequence");  // a sequence is queued whole: colorlab run NAME
      const keep = select.value;
      replace(select, campaigns.map(c => h("option", { value: c.name }, c.name)));
      if (campaigns.some(c => c.name === keep)) select.value = keep;
      showFields();
    } catch (e) { replace(result, errorBox(e)); }
  }

  function showFields() {
    const c = current();
    if (!c) return;
    document.getElementById("campaign-help").textContent =
      `${c.description || ""}${c.needs && c.needs.length ? ` — needs ${c.needs.join(", ")}` : ""}`;
    replace(fields, paramForm(c));
    result.replaceChildren();
  }
  select.addEventListener("change", showFields);

  function validated() {
    const c = current();
    const { params, errors } = readParams(c, form);
    const bad = Object.keys(errors);
    if (bad.length) {
      replace(result, h("p", { class: "error", role: "alert" }, `Check ${bad.join(", ")}: ${bad.map(k => errors[k]).join("; ")}`));
      form.querySelector(`[aria-invalid="true"]`)?.focus();
      return null;
    }
    return { campaign: c.name, params };
  }

  async function act(fn) {
    const body = validated();
    if (!body) return;
    replace(result, h("p", { class: "muted" }, "…"));
    try { await fn(body); } catch (e) { replace(result, errorBox(e)); ctx.accessChanged(e); }
  }

  btnDry.addEventListener("click", () => act(async body => {
    const r = await post("/v1/executions", { ...body, dry_run: true });
    replace(result, dryRunReport(r));
  }));
  form.addEventListener("submit", ev => { ev.preventDefault(); act(async body => {
    const e = await post("/v1/executions", body);
    replace(result, h("p", { class: "ok" }, `Started ${e.campaign} — execution ${short(e.id)}, `,
      h("a", { href: "#now" }, "follow it on Now")));
    ctx.store.executions.set(e.id, { ...e, ...(ctx.store.executions.get(e.id) || {}) });
    render();
  }); });
  btnEnqueue.addEventListener("click", () => act(async body => {
    const item = await post("/v1/queue", { ...body, on_failure: onFailure.value });
    replace(result, h("p", { class: "ok" }, `Queued ${item.campaign} at position ${item.position}.`));
    refreshQueue();
  }));

  async function control(path, label) {
    try { await post(path); ctx.toast(`${label}: sent`); }
    catch (e) { ctx.toast(`${label}: ${e.message}`, true); ctx.accessChanged(e); }
  }

  function executionRow(e) {
    const running = !isTerminal(e.status);
    const can = ctx.access.control;
    return h("li", { class: "row", dataset: { execution: e.id } },
      h("span", { class: "name" }, e.campaign || "execution", " ", h("span", { class: "mono muted" }, short(e.id))),
      badge(e.status),
      h("span", { class: "progress-text" }, `${Math.round((e.progress || 0) * 100)} %`),
      e.step ? h("span", { class: "muted" }, e.step) : null,
      e.reason ? h("span", { class: "reason" }, e.reason) : null,
      e.status === "suspended" && e.suspension ? suspensionSummary(e.suspension, ctx.store.serverNow()) : null,
      running ? h("span", { class: "buttons" },
        h("button", { type: "button", class: "control", dataset: { focus: `pause-${e.id}` }, disabled: !can || e.status === "paused",
                      onclick: () => control(`/v1/executions/${e.id}/pause`, "pause") }, "Pause"),
        h("button", { type: "button", class: "control", dataset: { focus: `resume-${e.id}` }, disabled: !can || (e.status !== "paused" && e.status !== "suspended"),
                      onclick: () => control(`/v1/executions/${e.id}/resume`, "resume") }, "Resume"),
        h("button", { type: "button", class: "control danger", dataset: { focus: `abort-${e.id}` }, disabled: !can,
                      onclick: () => { if (confirm(`Abort ${e.campaign || e.id}?`)) control(`/v1/executions/${e.id}/abort`, "abort"); } }, "Abort"))
        : (e.run_id ? h("a", { href: `#runs/${e.run_id}` }, "open run") : null));
  }

  function render() {
    const list = [...ctx.store.executions.values()]
      .sort((a, b) => (isTerminal(a.status) - isTerminal(b.status)) || String(b.id).localeCompare(String(a.id)));
    replace(executions, list.length ? h("ul", { class: "rows" }, list.map(executionRow))
      : h("p", { class: "muted" }, "Nothing running or finished since this page opened."));
    renderQueue();
    for (const b of section.querySelectorAll("button.control")) if (!ctx.access.control) b.disabled = true;
    if (ctx.access.control) for (const b of form.querySelectorAll("button.control")) b.disabled = false;
  }

  function renderQueue() {
    const q = ctx.store.queue;
    if (!q) { replace(queueBox, h("p", { class: "muted" }, "…")); return; }
    const can = ctx.access.control;
    replace(queueBox,
      h("p", {}, "state ", badge(q.state), q.halted ? [" ", badge("halted")] : null, q.reason ? ` — ${q.reason}` : "",
        q.waiting_for ? ` — waiting for execution ${short(q.waiting_for.id || q.waiting_for)}` : ""),
      // The running item's execution on hold: the queue waits for it (or for its on_failure once it ends).
      q.current && q.current.execution_suspension ? h("p", { class: "held" }, `item ${q.current.campaign} is suspended: `,
        suspensionSummary(q.current.execution_suspension, ctx.store.serverNow())) : null,
      h("div", { class: "buttons" },
        h("button", { type: "button", class: "control", id: "queue-start", disabled: !can || q.state === "running",
                      onclick: async () => { await control("/v1/queue/start", "start queue"); refreshQueue(); } }, "Start queue"),
        h("button", { type: "button", class: "control", id: "queue-stop", disabled: !can || q.state === "stopped",
                      onclick: async () => { await control("/v1/queue/stop", "stop queue"); refreshQueue(); } }, "Stop queue")),
      (q.items || []).length ? h("ol", { class: "rows" }, q.items.map(i => h("li", { class: "row" },
        h("span", { class: "name" }, i.campaign), badge(i.state),
        h("span", { class: "muted mono" }, JSON.stringify(i.params)),
        i.state === "queued" ? h("span", { class: "buttons" },
          h("button", { type: "button", class: "control", dataset: { focus: `up-${i.id}` }, disabled: !can || i.position <= 1,
                        "aria-label": `move ${i.campaign} up`, onclick: () => move(i, i.position - 1) }, "↑ Earlier"),
          h("button", { type: "button", class: "control", dataset: { focus: `down-${i.id}` },
                        disabled: !can || i.position >= queuedCount(q), "aria-label": `move ${i.campaign} down`,
                        onclick: () => move(i, i.position + 1) }, "↓ Later"),
          h("button", { type: "button", class: "control", dataset: { focus: `rm-${i.id}` }, disabled: !can,
            onclick: async () => { try { await del(`/v1/queue/${i.id}`); } catch (e) { ctx.toast(e.message, true); } refreshQueue(); } }, "Remove"))
          : null)))
        : h("p", { class: "muted" }, "The queue is empty."),
      (q.history || []).length ? h("details", {}, h("summary", {}, `history (${q.history.length})`),
        h("ul", { class: "rows" }, q.history.map(i => h("li", { class: "row" }, h("span", { class: "name" }, i.campaign), badge(i.state),
          i.reason ? h("span", { class: "reason" }, i.reason) : null)))) : null);
  }

  const queuedCount = q => (q.items || []).filter(i => i.state === "queued").length;

  async function move(item, position) {
    try { await post(`/v1/queue/${item.id}/move`, { position }); } catch (e) { ctx.toast(e.message, true); ctx.accessChanged(e); }
    refreshQueue();
  }

  // From the store (GET /v1/executions), so what ran before this page opened is listed too. "ended" is the
  // last change of a terminal execution.
  const RECENT = 20;
  async function refreshRecent() {
    try {
      const r = await get(`/v1/executions?limit=${RECENT}`);
      replace(recentBox, r.items.length ? h("table", { class: "executions" },
        h("thead", {}, h("tr", {}, ["campaign", "status", "started", "ended", "run"].map(c => h("th", { scope: "col" }, c)))),
        h("tbody", {}, r.items.map(e => h("tr", { dataset: { execution: e.id } },
          h("td", {}, e.campaign), h("td", {}, badge(e.status)), h("td", {}, fmtTime(e.created_at)),
          h("td", {}, isTerminal(e.status) ? fmtTime(e.updated_at) : "—"),
          h("td", {}, h("a", { href: `#runs/${e.run_id}`, class: "mono" }, short(e.run_id)))))))
        : h("p", { class: "muted" }, "No executions stored yet."));
    } catch (e) { replace(recentBox, errorBox(e)); }
  }

  async function refreshQueue() {
    try { ctx.store.queue = await get("/v1/queue"); ctx.store.queueDirty = false; renderQueue(); }
    catch (e) { replace(queueBox, errorBox(e)); }
  }
  ctx.refreshQueue = refreshQueue;

  // A hidden page does not redraw on every event of a busy night: show() draws it whole.
  let visible = false;
  return {
    show() { visible = true; loadCampaigns(); refreshQueue(); refreshRecent(); render(); },
    hide() { visible = false; },
    update(what) {
      if (!visible) return;
      const t = what.event && what.event.topic;
      if (what.kind === "snapshot" || what.kind === "access" || t === "execution" || t === "progress" || t === "queue") render();
      // Progress events are many: the stored list is read again only when an execution changes state.
      if (what.kind === "snapshot" || t === "execution") refreshRecent();
    },
  };
}
