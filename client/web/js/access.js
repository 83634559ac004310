// What may this browser do? GET /v1/control says whose the control lock is and — where the daemon reports
// it — the asker's own scope. Without that field the console asks the way a control request would be judged: a dry run without a campaign needs the control scope, stores
// nothing and moves nothing. 400 (the body is incomplete) means the access check passed; 401/403/409 are the
// access answers themselves, with the daemon's explanation. A server whose GET /v1 says read_only (colorlab-central)
// controls nothing for anyone: no lock or control request is asked about. The answer carries GET /v1 (`server`).
import { get, post, ApiError } from "./api.js";
import { getKey } from "./key.js";

export async function probeAccess() {
  const key = getKey();
  let server;
  try {
    server = await get("/v1");
  } catch (e) {
    if (e instanceof ApiError && e.status === 401) {
      return { control: false, read: false, why: key ? `the key was refused: ${e.message}` :
        "this listener needs an API key even to read: enter one above" };
    }
    return { control: false, read: false, why: `the daemon cannot be reached: ${e.message}` };
  }
  if (server && server.read_only) {
    return { control: false, read: true, server, why: `read-only: ${server.server || "this server"} serves the runs ` +
      "the benches shipped and changes nothing; control a bench at its own URL" };
  }
  return { ...(await probeControl(key)), server };
}

async function probeControl(key) {
  let lock = null;
  try { lock = await get("/v1/control"); } catch { /* an older daemon without the lock: probe below */ }
  if (lock && lock.held && !lock.yours) {
    return { control: false, read: true, why: `read-only: ${lock.holder || "another client"} holds the control lock` };
  }
  if (lock && typeof lock.scope === "string") {
    const control = lock.scope === "control" || lock.scope === "admin";
    return { control, read: true, why: control ? "" : key
      ? `read-only: this key has the '${lock.scope}' scope, control needs 'control'`
      : "read-only: controlling the lab needs an API key with the control scope" };
  }
  try {
    await post("/v1/executions", { dry_run: true });
    return { control: true, read: true, why: "" };
  } catch (e) {
    if (!(e instanceof ApiError)) return { control: false, read: true, why: `access unknown: ${e.message}` };
    if (e.status === 400 || e.status === 404) return { control: true, read: true, why: "" };
    if (e.status === 401) {
      return { control: false, read: true, why: key ? `read-only: the key was refused (${e.code})` :
        "read-only: controlling the lab needs an API key with the control scope" };
    }
    if (e.status === 403) {
      return { control: false, read: true,
               why: `read-only: this key has the '${e.problem.scope || "read"}' scope, control needs 'control'` };
    }
    if (e.status === 409) {
      return { control: false, read: true, why: `read-only: ${e.problem.holder || "another client"} holds the control lock` };
    }
    return { control: false, read: true, why: `access unknown: ${e.message}` };
  }
}
