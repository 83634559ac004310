// Wires the pieces: the key form, the access probe, the event stream into the store, and hash routing
// between the four pages (#lab, #queue, #now, #runs[/RUN_ID]) — one page, so the stream stays open. What the
// server serves comes from GET /v1 (its features, read_only): on colorlab-central only the Runs page is there,
// across benches, with no stream and no control (docs/fleet.md, "Console on central").
import { EventStream } from "./events.js";
import { Store } from "./store.js";
import { probeAccess } from "./access.js";
import { getKey, setKey, remembered } from "./key.js";
import { get } from "./api.js";
import { h } from "./dom.js";
import * as lab from "./pages/lab.js";
import * as queue from "./pages/queue.js";
import * as now from "./pages/now.js";
import * as runs from "./pages/runs.js";

const store = new Store();
const ctx = {
  store,
  access: { control: false, read: true, why: "checking access…" },
  toast,
  // A control request refused for access reasons means what we knew about the key is stale: ask again.
  accessChanged(e) { if (e && [401, 403, 409].includes(e.status)) checkAccess(); },
  refreshQueue: null,
  // GET /v1 as last read (null until then: a bench is assumed, as the console always did).
  server: null,
  has(feature) {
    const f = ctx.server && ctx.server.features;
    return !Array.isArray(f) || f.includes(feature);
  },
};
// The feature of GET /v1 each page needs: the pages a server cannot fill are not offered.
const PAGE_NEEDS = { lab: "instruments", queue: "queue", now: "executions", runs: "runs" };
const served = name => ctx.has(PAGE_NEEDS[name]);

const pages = {
  lab: lab.mount(document.getElementById("page-lab"), ctx),
  queue: queue.mount(document.getElementById("page-queue"), ctx),
  now: now.mount(document.getElementById("page-now"), ctx),
  runs: runs.mount(document.getElementById("page-runs"), ctx),
};
let currentPage = null;

function route() {
  const home = served("now") ? "now" : "runs";
  const [name, arg] = (location.hash.replace(/^#/, "") || home).split("/");
  const page = pages[name] && served(name) ? name : home;
  if (currentPage && currentPage !== page) pages[currentPage].hide();
  for (const [n] of Object.entries(pages)) {
    document.getElementById(`page-${n}`).hidden = n !== page;
    const link = document.querySelector(`nav a[href="#${n}"]`);
    link.hidden = !served(n);
    if (n === page) link.setAttribute("aria-current", "page"); else link.removeAttribute("aria-current");
  }
  currentPage = page;
  pages[page].show(arg ? decodeURIComponent(arg) : undefined);
  document.title = `colorlab${ctx.has("benches") && ctx.server ? " central" : ""} · ${page}`;
}
window.addEventListener("hashchange", route);

function toast(text, bad = false) {
  const box = document.getElementById("toasts");
  const t = h("p", { class: bad ? "toast bad" : "toast", role: bad ? "alert" : "status" }, text);
  box.append(t);
  while (box.children.length > 4) box.firstChild.remove();
  setTimeout(() => t.remove(), 6000);
}

async function checkAccess() {
  ctx.access = await probeAccess();
  // An unreachable or refusing server leaves what was known of it.
  if (ctx.access.server) {
    const changed = JSON.stringify(ctx.access.server.features) !== JSON.stringify(ctx.server && ctx.server.features);
    ctx.server = ctx.access.server;
    applyServer();
    if (changed && currentPage) route();
  }
  const note = document.getElementById("access-note");
  document.body.classList.toggle("read-only", !ctx.access.control);
  note.textContent = ctx.access.control ? "control: this console may start, pause, abort and answer" : ctx.access.why;
  note.className = ctx.access.control ? "access ok" : "access ro";
  document.getElementById("access-word").textContent = ctx.access.control ? "CONTROL" : ctx.access.read ? "READ-ONLY" : "NO ACCESS";
  for (const p of Object.values(pages)) p.update({ kind: "access" });
  // A lock held by someone else is let go sooner or later (release, lease): look again while it is the reason.
  clearTimeout(accessTimer);
  if (/control lock/.test(ctx.access.why)) accessTimer = setTimeout(checkAccess, 30000);
}
let accessTimer = null;

// Queue events arrive in bursts (enqueued, started, done…): one re-read per burst is enough.
let queueTimer = null;
function queueChanged() {
  clearTimeout(queueTimer);
  queueTimer = setTimeout(async () => {
    try { store.queue = await get("/v1/queue"); store.queueDirty = false; } catch { return; }
    for (const p of Object.values(pages)) p.update({ kind: "event", event: { topic: "queue" } });
  }, 200);
}

const conn = document.getElementById("conn");
const stream = new EventStream({
  onSnapshot: s => store.applySnapshot(s),
  onEvent: ev => store.applyEvent(ev),
  onStatus: (state, why) => {
    if (!ctx.has("event-stream")) return;  // a late word from a stream stopped because the server has none
    conn.textContent = state === "live" ? "LIVE" : state.toUpperCase();
    conn.className = `conn conn-${state}`;
    conn.title = why || "";
  },
});

// A server without the live stream (colorlab-central: runs the benches shipped, nothing happening here) is
// not asked for it; one with it gets it opened once, reopened later only by a new key.
let streamOpened = false;
function applyServer() {
  document.body.classList.toggle("central", !!ctx.server && ctx.has("benches"));
  if (ctx.has("event-stream")) {
    if (!streamOpened) { streamOpened = true; stream.start(); }
    return;
  }
  streamOpened = false;
  stream.stop();
  const central = ctx.has("benches");
  conn.textContent = central ? "CENTRAL" : "NOT LIVE";
  conn.className = "conn conn-central";
  conn.title = central ? `${ctx.server.server || "central"}: the runs the benches shipped; nothing live to follow here`
    : "this server has no live event stream";
}
store.subscribe(what => {
  const topic = what.event && what.event.topic;
  if (topic === "queue") queueChanged();
  // The lock taken or given back, a key revoked: what this page may do may have changed with it.
  if (topic === "control" || topic === "access") checkAccess();
  for (const p of Object.values(pages)) p.update(what);
});

// The key form: applied at once (access re-probed, stream reopened with the key from where it was).
const keyInput = document.getElementById("key");
const keyRemember = document.getElementById("key-remember");
keyInput.value = getKey();
// Open while there is no key yet (the first visit); folded away once one is set, which keeps a phone's
// first screen for the lab.
document.getElementById("key-box").open = !getKey();
keyRemember.checked = remembered();
document.getElementById("key-form").addEventListener("submit", ev => {
  ev.preventDefault();
  setKey(keyInput.value, keyRemember.checked);
  keyChanged();
});
document.getElementById("key-clear").addEventListener("click", () => {
  keyInput.value = "";
  setKey("", false);
  keyChanged();
});
// After the probe: a key may be what let GET /v1 say which server this is (and whether it has a stream).
async function keyChanged() {
  await checkAccess();
  if (ctx.has("event-stream")) stream.restart();
}

// For the tests and for curious operators: the live figures, read-only.
window.colorlabConsole = {
  stream, store,
  get access() { return ctx.access; },
  seen: () => store.seen.slice(),
};

// A browser gives one host six HTTP/1.1 connections; each console tab's stream holds one. A tab left in
// the background gives its connection back after a minute, and a page being left (or frozen in the
// back/forward cache) at once; coming back resumes from the last seq, so nothing is missed.
let hiddenTimer = null;
document.addEventListener("visibilitychange", () => {
  clearTimeout(hiddenTimer);
  if (document.hidden) hiddenTimer = setTimeout(() => stream.stop(), 60000);
  else if (ctx.has("event-stream")) stream.start();
});
window.addEventListener("pagehide", () => stream.stop());
window.addEventListener("pageshow", ev => { if (ev.persisted && ctx.has("event-stream")) stream.start(); });

// GET /v1 first (it is in the access probe): which pages there are, and whether there is a stream to open.
await checkAccess();
route();
applyServer();
