// The API key lives in the browser only. sessionStorage by default (gone with the tab, safer on a shared
// machine); "remember" moves it to localStorage for the operator's own phone.
const NAME = "colorlab.key";

export function getKey() {
  return sessionStorage.getItem(NAME) || localStorage.getItem(NAME) || "";
}

export function setKey(key, remember) {
  sessionStorage.removeItem(NAME);
  localStorage.removeItem(NAME);
  const k = (key || "").trim();
  if (!k) return;
  (remember ? localStorage : sessionStorage).setItem(NAME, k);
}

export function remembered() {
  return !!localStorage.getItem(NAME);
}
