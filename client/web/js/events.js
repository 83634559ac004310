// The live event stream, read with fetch rather than EventSource: EventSource cannot send the
// Authorization header a key needs. On any drop it reconnects with Last-Event-ID = the last seq it handled,
// so the daemon replays exactly what was missed (from its log on disk, across its own restarts too); only the
// very first connection asks for a snapshot.
import { authHeaders } from "./api.js";

export class EventStream {
  constructor({ onSnapshot, onEvent, onStatus }) {
    this.onSnapshot = onSnapshot;
    this.onEvent = onEvent;
    this.onStatus = onStatus || (() => {});
    this.lastSeq = null;       // null until the snapshot: then every connection resumes after it
    this.retryMs = 2000;
    this.controller = null;
    this.stopped = true;
    this.generation = 0;       // a stop() then start() must not leave two loops reading
    this.stats = { connects: 0, drops: 0, events: 0, duplicates: 0, gaps: 0 };
  }

  start() {
    if (!this.stopped) return;
    this.stopped = false;
    this._loop(++this.generation);
  }

  stop() {
    this.stopped = true;
    if (this.controller) this.controller.abort();
  }

  // Drops the current connection as a network failure would; the loop reconnects by itself.
  drop() {
    if (this.controller) this.controller.abort();
  }

  // A new key: the stream must be reopened with it at once (no retry pause), resuming where it was.
  restart() {
    if (this.stopped) { this.start(); return; }
    this.immediate = true;
    this.drop();
  }

  async _loop(generation) {
    const current = () => !this.stopped && generation === this.generation;
    while (current()) {
      this.controller = new AbortController();
      const headers = authHeaders({ Accept: "text/event-stream" });
      if (this.lastSeq !== null) headers["Last-Event-ID"] = String(this.lastSeq);
      try {
        this.onStatus("connecting");
        const res = await fetch("/v1/events/stream", { headers, signal: this.controller.signal, cache: "no-store" });
        if (res.status === 401 || res.status === 403) {
          // Retrying cannot help until the key changes (restart() comes with a new one).
          this.stopped = true;
          this.onStatus("refused", `the stream needs a valid key (${res.status})`);
          return;
        }
        if (!res.ok || !res.body) throw new Error(`stream answered ${res.status}`);
        this.stats.connects++;
        this.onStatus("live");
        await this._read(res.body.getReader());
        if (current()) this.onStatus("reconnecting", "the daemon closed the stream");
      } catch (e) {
        if (!current()) break;
        this.onStatus("reconnecting", e.name === "AbortError" ? "connection dropped" : e.message);
      }
      this.stats.drops++;
      const wait = this.immediate ? 0 : this.retryMs;
      this.immediate = false;
      if (current()) await new Promise(r => setTimeout(r, wait));
    }
    if (generation === this.generation) this.onStatus(this.stopped ? "paused" : "stopped");
  }

  async _read(reader) {
    const decoder = new TextDecoder();
    let buffer = "";
    let event = { id: null, type: "message", data: [] };
    for (;;) {
      const { value, done } = await reader.read();
      if (done) return;
      buffer += decoder.decode(value, { stream: true });
      let nl;
      while ((nl = buffer.search(/\r\n|\r|\n/)) >= 0) {
        const line = buffer.slice(0, nl);
        buffer = buffer.slice(nl + (buffer.startsWith("\r\n", nl) ? 2 : 1));
        if (line === "") {
          if (event.data.length) this._dispatch(event);
          event = { id: null, type: "message", data: [] };
          continue;
        }
        if (line.startsWith(":")) continue;  // keep-alive
        const colon = line.indexOf(":");
        const field = colon < 0 ? line : line.slice(0, colon);
        let val = colon < 0 ? "" : line.slice(colon + 1);
        if (val.startsWith(" ")) val = val.slice(1);
        if (field === "data") event.data.push(val);
        else if (field === "event") event.type = val;
        else if (field === "id") event.id = val;
        else if (field === "retry" && /^\d+$/.test(val)) this.retryMs = Number(val);
      }
    }
  }

  _dispatch(ev) {
    let data;
    try { data = JSON.parse(ev.data.join("\n")); } catch { return; }
    if (ev.type === "snapshot") {
      // A snapshot on a resumed stream would mean the daemon forgot our position; trust it and start over.
      this.lastSeq = Number(data.last_seq ?? ev.id ?? 0);
      this.onSnapshot(data);
      return;
    }
    const seq = Number(data.seq ?? ev.id);
    if (this.lastSeq !== null && seq <= this.lastSeq) { this.stats.duplicates++; return; }
    if (this.lastSeq !== null && seq !== this.lastSeq + 1) this.stats.gaps++;
    this.lastSeq = seq;
    this.stats.events++;
    this.onEvent(data);
  }
}
