#pragma once
// The Content-Security-Policy of the pages colorlabd serves (issue 27): whatever a campaign script or a client
// puts in a run (names, parameters, steps, units) and a page shows, no script runs but the console's own files.
namespace colorlab::daemon {

// The console: its scripts only from its own files (no inline script, no eval), requests only to this daemon.
// Inline styles stay allowed: a report opened from the console through an object URL (with a key) inherits
// this policy, and the report styles itself inline (its <style>, matplotlib's SVG attributes). Images: the
// daemon's, and the object URLs of photos fetched with a key.
inline constexpr const char* kConsolePolicy =
    "default-src 'self'; script-src 'self'; style-src 'self' 'unsafe-inline'; img-src 'self' blob: data:; "
    "connect-src 'self'; object-src 'none'; base-uri 'none'; form-action 'none'; frame-ancestors 'none'";

// A report (and its "making the report" page): a document with no script at all, its styles inline, its
// figures inline SVG or data: images.
inline constexpr const char* kReportPolicy =
    "default-src 'none'; style-src 'unsafe-inline'; img-src 'self' data:; base-uri 'none'; form-action 'none'; "
    "frame-ancestors 'none'";

}  // namespace colorlab::daemon
