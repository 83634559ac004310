// Images and downloads that also work where the listener needs a key: <img src> and <a href> cannot send an
// Authorization header, so with a key set the bytes are fetched and shown through an object URL — revoked
// as soon as the element is gone, so browsing a hundred runs does not keep a hundred images in memory.
import { authHeaders, ApiError } from "./api.js";
import { getKey } from "./key.js";
import { h } from "./dom.js";

const live = new Set();

export function revokeAll() {
  for (const url of live) URL.revokeObjectURL(url);
  live.clear();
}

async function fetchBlob(path) {
  const res = await fetch(path, { headers: authHeaders(), cache: "no-store" });
  if (!res.ok) {
    let problem = null;
    try { problem = await res.json(); } catch { /* not JSON */ }
    throw new ApiError(res.status, problem);
  }
  return res.blob();
}

export function image(path, alt) {
  const img = h("img", { alt, loading: "lazy", decoding: "async" });
  if (!getKey()) { img.src = path; return img; }
  fetchBlob(path).then(b => {
    const url = URL.createObjectURL(b);
    live.add(url);
    img.src = url;
  }).catch(e => { img.alt = `${alt} (${e.message})`; });
  return img;
}

export function download(path, label, filename) {
  const a = h("a", { href: path, download: filename || "", class: "download" }, label);
  a.addEventListener("click", async ev => {
    if (!getKey()) return;
    ev.preventDefault();
    try {
      const b = await fetchBlob(path);
      const url = URL.createObjectURL(b);
      const tmp = h("a", { href: url, download: filename || path.split("/").pop() });
      document.body.append(tmp);
      tmp.click();
      tmp.remove();
      setTimeout(() => URL.revokeObjectURL(url), 10000);
    } catch (e) {
      a.after(h("span", { class: "error" }, ` ${e.message}`));
    }
  });
  return a;
}
