// Why a suspended execution waits (its `suspension`: category, problem, and from the crash-loop guard its
// back-off), said in one line for the Now and Queue pages. Built with text nodes only (dom.js h), never
// HTML: a reason may quote a campaign's own step names.
import { h } from "./dom.js";

const CATEGORY = {
  "crash-loop": "crash loop",
  storage: "storage",
  instrument: "instrument",
  lamp: "lamp",
  shutdown: "colorlabd stopped",
};

// When the guard retries it by itself, on the browser's clock corrected by the server's (serverNow).
export function suspensionSummary(s, serverNow) {
  if (!s || typeof s !== "object") return null;
  const category = CATEGORY[s.category] || String(s.category || "suspended");
  const parts = [h("strong", { class: "suspension-category" }, category)];
  if (s.category === "crash-loop") {
    const at = Date.parse(s.retry_at);
    const left = Number.isNaN(at) ? null : Math.max(0, Math.round((at - serverNow) / 1000));
    parts.push(` — colorlabd retries it by itself ${left === null ? "later" : `in ${left} s`}` +
      ` (retry ${s.retry} of ${s.retries}, back-off ${s.backoff_s} s), or resume it now`);
  }
  const hint = s.problem && s.problem.hint;
  if (hint) parts.push(h("span", { class: "hint" }, ` — ${hint}`));
  return h("span", { class: "suspension", dataset: { category: String(s.category || "") } }, parts);
}
