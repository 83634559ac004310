// Runs: the stored runs, newest first, cursor-paged as the API pages them; one run with its measurements
// (paged too), its kept frames as previews, downloads, exports and — where the daemon has one — its report.
// On colorlab-central (GET /v1 lists "benches") the runs of every bench: a bench column and filter, each bench's
// shipping lag, and no campaign list, script or preview, which only a bench has.
import { get, authHeaders } from "../api.js";
import { getKey } from "../key.js";
import { h, replace, badge, errorBox, fmtTime, fmtNumber, fmtBytes, fmtDuration, short } from "../dom.js";
import { image, download, revokeAll } from "../files.js";

const RUNS_PAGE = 25, MEAS_PAGE = 50;

export function mount(section, ctx) {
  const listView = h("div", { id: "runs-list" });
  const detailView = h("div", { id: "run-detail" });
  section.append(h("h2", {}, "Runs"), listView, detailView);

  // Paging keeps the cursors of the pages before, so "Newer" needs no cursor the API does not give.
  let cursors = [null], page = 0, filter = { campaign: "", status: "", bench: "" };

  async function showList() {
    detailView.hidden = true;
    listView.hidden = false;
    revokeAll();
    const fCampaign = h("input", { id: "filter-campaign", type: "search", value: filter.campaign, placeholder: "e.g. luminance-spot",
      list: "campaign-names" });
    const names = h("datalist", { id: "campaign-names" });
    if (ctx.has("campaigns")) {
      get("/v1/campaigns").then(c => replace(names, (c.items || []).filter(i => i.kind !== "sequence").map(i => h("option", { value: i.name })))).catch(() => {});
    }
    const benches = ctx.has("benches");
    const fBench = benches ? h("select", { id: "filter-bench" }, h("option", { value: "" }, "any")) : null;
    const lag = benches ? h("div", { id: "bench-lag", class: "muted" }) : null;
    if (benches) {
      get("/v1/benches").then(b => {
        const items = b.items || [];
        replace(fBench, h("option", { value: "" }, "any"),
          items.map(x => h("option", { value: x.id, selected: x.id === filter.bench }, x.name === x.id ? x.id : `${x.name} (${x.id})`)));
        replace(lag, items.length ? h("p", {}, items.map((x, i) => [i ? " · " : "", benchLag(x)])) : "No bench has shipped yet.");
      }).catch(e => replace(lag, errorBox(e)));
    }
    const fStatus = h("select", { id: "filter-status" }, ["", "running", "finished_ok", "finished_error", "aborted", "interrupted"]
      .map(s => h("option", { value: s, selected: s === filter.status }, s || "any")));
    const table = h("div", { class: "table-wrap" }, h("p", { class: "muted" }, "…"));
    const pager = h("div", { class: "buttons pager" });
    // The daemon filters (GET /v1/runs?campaign=&status=), so every page is of matching runs.
    const apply = async () => {
      filter = { campaign: fCampaign.value.trim(), status: fStatus.value, bench: fBench ? fBench.value : "" };
      cursors = [null];
      page = 0;
      await refresh();
    };
    fCampaign.addEventListener("change", apply);
    fStatus.addEventListener("change", apply);
    if (fBench) fBench.addEventListener("change", apply);
    replace(listView,
      lag,
      h("div", { class: "filters" },
        fBench ? h("div", { class: "field" }, h("label", { for: "filter-bench" }, "bench"), fBench) : null,
        h("div", { class: "field" }, h("label", { for: "filter-campaign" }, "campaign"), fCampaign, names),
        h("div", { class: "field" }, h("label", { for: "filter-status" }, "status"), fStatus)),
      table, pager);

    let runs = [], next = null;
    async function fetchPage() {
      const cursor = cursors[page];
      const q = new URLSearchParams({ limit: String(RUNS_PAGE) });
      if (cursor) q.set("cursor", cursor);
      if (filter.campaign) q.set("campaign", filter.campaign);
      if (filter.status) q.set("status", filter.status);
      if (filter.bench) q.set("bench", filter.bench);
      const r = await get(`/v1/runs?${q}`);
      runs = r.items;
      next = r.next_cursor;
    }
    function load() {
      const shown = runs;
      const cols = ["run", ...(benches ? ["bench"] : []), "campaign", "status", "data", "started", "finished"];
      replace(table, shown.length ? h("table", { class: "runs" },
        h("thead", {}, h("tr", {}, cols.map(c => h("th", { scope: "col" }, c)))),
        h("tbody", {}, shown.map(r => h("tr", {},
          h("td", {}, h("a", { href: `#runs/${r.id}`, class: "mono" }, short(r.id))),
          benches ? h("td", { class: "bench" }, benchName(r.bench)) : null,
          h("td", {}, r.campaign), h("td", {}, badge(r.status)),
          h("td", {}, r.simulated ? h("span", { class: "tag sim" }, "SIMULATED") : h("span", { class: "tag real" }, "real")),
          h("td", {}, fmtTime(r.started_at || r.created_at)), h("td", {}, fmtTime(r.finished_at))))))
        : h("p", { class: "muted" }, filter.campaign || filter.status || filter.bench ? "No run matches." : "No runs stored yet."));
      replace(pager,
        h("button", { type: "button", id: "runs-newer", disabled: page === 0, onclick: async () => { page--; await refresh(); } }, "← Newer"),
        h("span", { class: "muted" }, `page ${page + 1}`),
        h("button", { type: "button", id: "runs-older", disabled: !next, onclick: async () => { cursors[page + 1] = next; page++; await refresh(); } }, "Older →"));
    }
    async function refresh() {
      try { await fetchPage(); load(); } catch (e) { replace(table, errorBox(e)); }
    }
    listRefresh = refresh;
    await refresh();
  }
  let listRefresh = null;

  async function showRun(id) {
    listView.hidden = true;
    detailView.hidden = false;
    revokeAll();
    replace(detailView, h("p", { class: "muted" }, "…"));
    let run;
    try { run = await get(`/v1/runs/${id}`); } catch (e) { replace(detailView, h("p", {}, h("a", { href: "#runs" }, "← all runs")), errorBox(e)); return; }
    const meas = h("div", { id: "measurements" });
    const blobs = h("div", { id: "blobs" });
    const report = h("span", { id: "report-link" });
    const base = `/v1/runs/${id}`;
    const name = `${run.campaign}-${id}`;
    const summary = run.summary && run.summary.measurements ? Object.entries(run.summary.measurements) : [];
    replace(detailView,
      h("p", {}, h("a", { href: "#runs" }, "← all runs")),
      h("h3", {}, `${run.campaign} `, h("span", { class: "mono muted" }, id)),
      run.bench ? h("p", { id: "run-bench" }, "bench ", h("strong", {}, benchName(run.bench)),
        h("span", { class: "muted" }, " — shipped to central; the bench keeps its own copy")) : null,
      h("p", {}, badge(run.status), " ", run.simulated ? h("span", { class: "tag sim" }, "SIMULATED data") : h("span", { class: "tag real" }, "real instruments"),
        ` · started ${fmtTime(run.started_at || run.created_at)} · finished ${fmtTime(run.finished_at)} · ${run.measurement_count ?? "?"} measurements`),
      run.error ? h("p", { class: "error" }, run.error.detail || run.error.title || JSON.stringify(run.error)) : null,
      h("details", {}, h("summary", {}, "parameters"), h("pre", {}, JSON.stringify(run.params, null, 2))),
      summary.length ? h("table", { class: "summary" },
        h("thead", {}, h("tr", {}, ["quantity", "count", "mean", "stdev", "min", "max", "unit"].map(c => h("th", { scope: "col" }, c)))),
        h("tbody", {}, summary.map(([q, s]) => h("tr", {}, h("td", {}, q), h("td", {}, String(s.count)),
          ["mean", "stdev", "min", "max"].map(k => h("td", {}, fmtNumber(s[k]))), h("td", {}, s.unit || ""))))) : null,
      h("p", { class: "buttons downloads" }, "Export: ",
        download(`${base}/export?format=csv`, "CSV", `${name}.csv`), " ",
        download(`${base}/export?format=json`, "JSON", `${name}.json`), " ",
        // .ti3 exists only for patch readings (422 otherwise): offered where the summary shows some.
        summary.some(([q]) => q === "reflectance_spectrum" || q === "camera_rgb")
          ? [download(`${base}/export?format=ti3`, ".ti3", `${name}.ti3`), " "] : null,
        ctx.has("run-script") ? [download(`${base}/script`, "script", `${name}.lua`), " "] : null, report),
      h("h4", {}, "Measurements"), meas,
      h("h4", {}, "Frames"), blobs);

    // An ended run has a report (the daemon makes it on first request: 202 until it is there).
    if (run.links && run.links.report) replace(report, reportLink(run.links.report, id));

    const mCursors = [null];
    let mPage = 0;
    async function loadMeasurements() {
      try {
        const c = mCursors[mPage];
        const r = await get(`${base}/measurements?limit=${MEAS_PAGE}${c ? `&cursor=${encodeURIComponent(c)}` : ""}`);
        replace(meas,
          h("div", { class: "table-wrap" }, h("table", { class: "measurements" },
            h("thead", {}, h("tr", {}, ["seq", "step", "instrument", "quantity", "value", "unit", "measured"].map(x => h("th", { scope: "col" }, x)))),
            h("tbody", {}, r.items.map(m => h("tr", {},
              h("td", {}, String(m.seq)), h("td", {}, m.step), h("td", {}, m.instrument_id, m.simulated ? " (sim)" : ""),
              h("td", {}, m.quantity), h("td", { class: "num" }, m.value === null || m.value === undefined ? "—" : String(m.value)), h("td", {}, m.unit || ""),
              h("td", {}, fmtTime(m.measured_at))))))),
          h("div", { class: "buttons pager" },
            h("button", { type: "button", id: "meas-prev", disabled: mPage === 0, onclick: () => { mPage--; loadMeasurements(); } }, "← Previous"),
            h("span", { class: "muted" }, `page ${mPage + 1}`),
            h("button", { type: "button", id: "meas-next", disabled: !r.next_cursor,
                          onclick: () => { mCursors[mPage + 1] = r.next_cursor; mPage++; loadMeasurements(); } }, "Next →")));
      } catch (e) { replace(meas, errorBox(e)); }
    }
    loadMeasurements();

    try {
      const b = await get(`${base}/blobs`);
      // A preview where the server renders one (central does not: its blob items have no preview link).
      const preview = x => x.links ? x.links.preview : `/v1/blobs/${x.sha256}/preview.png`;
      replace(blobs, b.items.length ? h("div", { class: "cards" }, b.items.map(x => h("figure", { class: "card blob" },
        preview(x) ? image(preview(x), `${x.name} preview`) : h("p", { class: "muted" }, "no preview here"),
        h("figcaption", {}, `${x.name} · ${x.kind} · ${fmtBytes(x.size)} `,
          download(`/v1/blobs/${x.sha256}`, "download", x.name.split("/").pop())))))
        : h("p", { class: "muted" }, "This run kept no frames."));
    } catch (e) { replace(blobs, errorBox(e)); }
  }

  return {
    show(arg) { if (arg) showRun(arg); else showList(); },
    hide() { revokeAll(); listView.hidden = true; },
    // The first page follows the lab: a run started or ended shows up without a reload (later pages stay put,
    // so reading them is not disturbed). One re-read per burst of events.
    update(what) {
      const ev = what.event;
      if (!ev || ev.topic !== "execution" || listView.hidden || page !== 0 || !listRefresh) return;
      clearTimeout(this.timer);
      this.timer = setTimeout(() => listRefresh(), 500);
    },
  };
}

function benchName(b) {
  if (!b) return "—";
  return b.name && b.name !== b.id ? `${b.name} (${b.id})` : b.id;
}

// One bench of GET /v1/benches: what it holds here and what it has not shipped yet.
function benchLag(b) {
  const l = b.lag || {};
  const waiting = l.unshipped_runs === null || l.unshipped_runs === undefined ? "lag not reported"
    : l.unshipped_runs === 0 ? "nothing waiting"
    : `${l.unshipped_runs} run(s) waiting, the oldest ${fmtDuration(l.age_s)}`;
  return h("span", { class: "bench-lag", dataset: { bench: b.id } }, h("strong", {}, benchName(b)), `: ${b.runs} runs here, ${waiting}`);
}

// Without a key the link is followed as it is: the daemon's "making the report" page reloads itself until
// the report is there. With a key (which a link cannot carry) the report is fetched, waiting out the 202s,
// and opened from an object URL.
function reportLink(path, id) {
  const a = h("a", { href: path, id: "report", target: "_blank", rel: "noopener" }, "report");
  a.addEventListener("click", async ev => {
    if (!getKey()) return;
    ev.preventDefault();
    const tab = window.open("", "_blank");
    for (let tries = 0; tries < 300; ++tries) {
      const res = await fetch(path, { headers: authHeaders({ Accept: "text/html" }), cache: "no-store" });
      if (res.status === 202) { await new Promise(r => setTimeout(r, 2000)); continue; }
      if (!res.ok) { a.after(h("span", { class: "error" }, ` report: ${res.status}`)); if (tab) tab.close(); return; }
      const url = URL.createObjectURL(await res.blob());
      if (tab) tab.location = url; else window.location = url;
      setTimeout(() => URL.revokeObjectURL(url), 60000);
      return;
    }
  });
  return a;
}
