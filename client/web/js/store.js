// The console's picture of the lab, kept current from the event stream. Every list is bounded so a page
// left open all night holds the same amount of memory at dawn as at dusk.
export const LIMITS = { events: 300, finished: 30, readings: 400 };

const TERMINAL = new Set(["finished_ok", "finished_error", "aborted", "interrupted"]);
export const isTerminal = status => TERMINAL.has(status);

export class Store {
  constructor() {
    this.instruments = new Map();
    this.executions = new Map();   // id → execution (unfinished, and the last few finished)
    this.requests = new Map();     // id → open operator request
    this.queue = null;
    this.recent = [];              // the last LIMITS.events events, newest last
    this.seen = [];                // seqs handled, bounded like recent: the tests compare them with /v1/events
    this.progressAt = new Map();   // execution id → {t0, p0}: the first progress seen, for the ETA
    this.listeners = new Set();
    this.clockSkewMs = 0;          // server time − local time, from the events' own timestamps
  }

  subscribe(fn) { this.listeners.add(fn); return () => this.listeners.delete(fn); }
  _emit(what) { for (const fn of this.listeners) fn(what); }

  applySnapshot(s) {
    this.instruments = new Map((s.instruments || []).map(i => [i.id, i]));
    const keepFinished = [...this.executions.values()].filter(e => isTerminal(e.status));
    this.executions = new Map(keepFinished.map(e => [e.id, e]));
    for (const e of s.executions || []) this.executions.set(e.id, e);
    this.requests = new Map((s.requests || []).map(r => [r.id, r]));
    this.queue = s.queue || null;
    this._emit({ kind: "snapshot" });
  }

  applyEvent(ev) {
    this.recent.push(ev);
    this.seen.push(ev.seq);
    if (this.recent.length > LIMITS.events) this.recent.splice(0, this.recent.length - LIMITS.events);
    if (this.seen.length > LIMITS.events * 4) this.seen.splice(0, this.seen.length - LIMITS.events * 4);
    const t = Date.parse(ev.time);
    if (!Number.isNaN(t)) this.clockSkewMs = t - Date.now();
    const p = ev.payload || {};
    switch (ev.topic) {
      case "execution": this._execution(p); break;
      case "progress": this._progress(p); break;
      case "operator": this._operator(p); break;
      case "queue": this._queue(p); break;
      case "instrument": this._instrument(p); break;
    }
    this._emit({ kind: "event", event: ev });
  }

  _execution(p) {
    if (p.id && p.campaign) {           // "created": the whole execution
      this.executions.set(p.id, { ...p });
    } else if (p.execution_id) {
      const e = this.executions.get(p.execution_id) || { id: p.execution_id, run_id: p.run_id, progress: 0 };
      if (p.status) e.status = p.status;
      if ("reason" in p) e.reason = p.reason;
      // A suspension carries the failure it waits out (problem+json): the operator needs its hint.
      if (p.status) e.problem = p.problem || p.error || null;
      // Why a suspended run waits (the crash-loop guard adds when it retries); gone once it runs again.
      if (p.status) e.suspension = p.suspension || null;
      if (p.requested) e.requested = p.requested;
      if (p.status && isTerminal(p.status)) {
        e.finished_at = Date.now();
        if (p.status === "finished_ok") e.progress = 1;
        this.progressAt.delete(e.id);
      }
      this.executions.set(e.id, e);
    }
    this._trimFinished();
  }

  _progress(p) {
    const e = this.executions.get(p.execution_id) || { id: p.execution_id, run_id: p.run_id, status: "running" };
    e.progress = p.progress;
    e.step = p.step;
    e.measurements = p.measurements;
    if (!this.progressAt.has(e.id)) this.progressAt.set(e.id, { t0: Date.now(), p0: p.progress });
    this.executions.set(e.id, e);
  }

  _operator(p) {
    const r = p.request;
    if (!r) return;
    if (p.event === "posted") this.requests.set(r.id, { ...r, received_at: Date.now() });
    else this.requests.delete(r.id);
  }

  // Queue events name the item that changed but not its new position among the others: the page
  // re-reads GET /v1/queue instead of guessing (see main.js).
  _queue() { this.queueDirty = true; }

  _instrument(p) {
    if (p.event === "removed") {
      const i = this.instruments.get(p.id);
      if (i) i.state = "disconnected";
    } else if (p.id && !this.instruments.has(p.id)) {
      this.instruments.set(p.id, { id: p.id, kind: p.kind, port: p.port, state: "initialising" });
    }
  }

  _trimFinished() {
    const finished = [...this.executions.values()].filter(e => isTerminal(e.status))
      .sort((a, b) => (a.finished_at || 0) - (b.finished_at || 0));
    while (finished.length > LIMITS.finished) this.executions.delete(finished.shift().id);
  }

  // Seconds left, from the rate seen since the first progress event this page witnessed.
  eta(e) {
    const start = this.progressAt.get(e.id);
    if (!start || !(e.progress > start.p0)) return null;
    const rate = (e.progress - start.p0) / (Date.now() - start.t0);
    return rate > 0 ? (1 - e.progress) / rate / 1000 : null;
  }

  serverNow() { return Date.now() + this.clockSkewMs; }
}
