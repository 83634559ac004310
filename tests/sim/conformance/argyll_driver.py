#!/usr/bin/env python3
"""Drives ArgyllCMS spotread/chartread against a running colorlab-sim Spectrolino.

Argyll needs a tty on stdin and, on machines without /dev/bus/usb, a private /dev (instrument-protocols
§5.2/5.3): the tool runs under `unshare -m` with a small tmpfs /dev whose ttyS7 links to our pty. Prompts
are answered by pressing keys; between prompts the simulated head is moved through the control socket.
Prints one JSON line with what it saw. Exit status 0 when the run completed.
With --trace, the tool runs under strace so a benchmark can time every byte it sends and receives
(bench/drivers/serial/serial_timeline.py reads that log).
"""
import argparse
import json
import os
import pty
import re
import select
import socket
import sys
import time

NAMESPACE_SCRIPT = r'''
F=$(mktemp -d); mount -t tmpfs tmpfs $F
mkdir -p $F/bus/usb/001 $F/pts $F/shm
for n in null zero random urandom tty full; do touch $F/$n; mount --bind /dev/$n $F/$n; done
mount --bind /dev/pts $F/pts; mount --bind /dev/shm $F/shm; ln -s pts/ptmx $F/ptmx
ln -s /proc/self/fd $F/fd
ln -s "$COLORLAB_PTY" $F/ttyS7
mount --rbind $F /dev
cd "$COLORLAB_WORKDIR"
exec "$@"
'''


def control(sock_path, cmd):
    s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    s.connect(sock_path)
    s.sendall((json.dumps(cmd) + "\n").encode())
    buf = b""
    while not buf.endswith(b"\n"):
        chunk = s.recv(65536)
        if not chunk:
            break
        buf += chunk
    s.close()
    return json.loads(buf)


class Session:
    def __init__(self, argv, pty_path, workdir, log):
        env = dict(os.environ, COLORLAB_PTY=pty_path, COLORLAB_WORKDIR=workdir)
        self.pid, self.fd = pty.fork()
        if self.pid == 0:
            os.execvpe("unshare", ["unshare", "-m", "--propagation", "private", "sh", "-c", NAMESPACE_SCRIPT,
                                   "sh"] + argv, env)
        self.out = ""
        self.transcript = ""  # everything the tool printed: tells whether it reacted to a key
        self.log = log

    def expect(self, pattern, timeout):
        rx = re.compile(pattern, re.S)
        deadline = time.time() + timeout
        while True:
            m = rx.search(self.out)
            if m:
                self.out = self.out[m.end():]
                return m
            left = deadline - time.time()
            if left <= 0:
                raise TimeoutError("waiting for %r; last output: %r" % (pattern, self.out[-800:]))
            r, _, _ = select.select([self.fd], [], [], min(left, 0.5))
            if r:
                try:
                    data = os.read(self.fd, 4096).decode(errors="replace")
                except OSError:
                    data = ""
                if not data:
                    m = rx.search(self.out)
                    if m:
                        return m
                    raise EOFError("tool exited; last output: %r" % self.out[-800:])
                self.log.write(data)
                self.out += data
                self.transcript += data

    def send(self, keys):
        os.write(self.fd, keys.encode())

    def wait(self, timeout):
        deadline = time.time() + timeout
        while time.time() < deadline:
            pid, status = os.waitpid(self.pid, os.WNOHANG)
            if pid:
                return os.waitstatus_to_exitcode(status)
            try:
                r, _, _ = select.select([self.fd], [], [], 0.2)
                if r:
                    data = os.read(self.fd, 4096).decode(errors="replace")
                    self.log.write(data)
            except OSError:
                time.sleep(0.1)
        os.kill(self.pid, 9)
        return None


def lines_answered(sock_path):
    return control(sock_path, {"cmd": "truth"})["spectrolino"]["lines_answered"]


# Argyll prints a prompt, then empties the console's input, then waits for a key (instappsup.c:
# printf; empty_con_chars(); next_con_char()). A key that lands between the prompt and the emptying is
# thrown away and the tool waits for ever: on a loaded machine that window is wide. So a key is pressed
# again, but only while the tool has provably not acted on it: it printed nothing and sent the
# instrument no line since the key went in (an acted-on key always does one or the other).
QUIET_BEFORE_PRESSING_AGAIN = 5.0


def press(s, keys, pattern, timeout, control_sock):
    deadline = time.time() + timeout
    while True:
        printed, answered = len(s.transcript), lines_answered(control_sock)
        s.send(keys)
        while True:
            try:
                return s.expect(pattern, max(0.1, min(QUIET_BEFORE_PRESSING_AGAIN, deadline - time.time())))
            except TimeoutError:
                if time.time() >= deadline:
                    raise
                # The terminal's echo of the key itself is not a reaction.
                reaction = s.transcript[printed:].translate({ord(c): None for c in keys + "\r\n "})
                if not reaction and lines_answered(control_sock) == answered:
                    break  # the key was lost: press it again


def tool_argv(a, argv):
    if not a.trace:
        return argv
    # -ttt: epoch timestamps comparable with time.time(); -T: time inside the call; seccomp-bpf stops the tool only on the traced calls.
    return ["strace", "-f", "--seccomp-bpf", "-ttt", "-T", "-s", "1024", "-e", "trace=openat,read,write,close",
            "-o", a.trace] + argv


def run_spotread(a, log):
    control(a.control, {"cmd": "place", "target": "white_tile"})
    s = Session(tool_argv(a, ["spotread", "-v", "-c", "1", "-s"]), a.port, a.workdir, log)
    result = {}
    m = s.expect(r"Device:\s*(\S+)\s+Serial No:\s*(\S+)", 60)
    result["device"] = m.group(1)
    result["serial"] = m.group(2)
    # Calibration prompt for a stand-alone instrument: the head is already on the tile.
    s.expect(r"white reference.*?(hit any key|continue).*?abort: ", 60)
    press(s, " ", r"Place instrument on spot to be measured", 60, a.control)
    result["calibrated"] = True
    control(a.control, {"cmd": "place", "target": "patch", "patch": a.patch})
    m = press(s, " ", r"Result is XYZ: *([-\d.]+) +([-\d.]+) +([-\d.]+)", 60, a.control)
    result["xyz"] = [float(m.group(i)) for i in (1, 2, 3)]
    truth = control(a.control, {"cmd": "truth"})
    result["last_spectrum"] = truth["spectrolino"].get("last_spectrum")
    result["true_spectrum"] = truth["spectrolino"]["true_spectrum"]
    s.expect(r"Place instrument on spot to be measured", 30)
    s.send("q")
    time.sleep(0.3)
    s.send("q")
    result["exit"] = s.wait(30)
    return result


def make_chart(a, log):
    """A SpectroScan chart of a.patches patches made by Argyll itself (targen + printtarg) on page a.page.

    On A4 up to 39 patches lie in one pass; a custom page such as 160x122 (mm) makes 10 passes of 14,
    the ColorChecker SG's grid."""
    import subprocess
    base = os.path.join(a.workdir, a.basename)
    for argv in (["targen", "-v0", "-d2", "-f", str(a.patches), base],
                 ["printtarg", "-i", "SS", "-p", a.page, base]):
        r = subprocess.run(argv, cwd=a.workdir, capture_output=True, text=True)
        log.write(r.stdout + r.stderr)
        if r.returncode != 0:
            raise EOFError("%s failed: %s" % (argv[0], r.stderr[-400:]))


def read_ti3(path):
    fields, rows, in_data = [], [], False
    for line in open(path):
        t = line.split()
        if not t:
            continue
        if t[0] == "BEGIN_DATA_FORMAT":
            fields = None
            continue
        if fields is None:
            fields = [x for x in t]
            continue
        if t[0] == "BEGIN_DATA":
            in_data = True
            continue
        if t[0] == "END_DATA":
            in_data = False
            continue
        if in_data:
            rows.append(t)
    loc = fields.index("SAMPLE_LOC")
    spec = [i for i, f in enumerate(fields) if f.startswith("SPEC_")]
    return {r[loc].strip('"'): [float(r[i]) / 100.0 for i in spec] for r in rows}


def run_chartread(a, log):
    make_chart(a, log)
    # Where the "operator" puts the sight for each patch chartread asks for: by name (--locate), or the
    # first and the last patch in the order asked (a one-pass chart).
    by_name = {}
    for item in a.locate:
        name, xy = item.split("=", 1)
        by_name[name] = [float(v) for v in xy.split(",")]
    in_order = [[float(v) for v in a.first.split(",")], [float(v) for v in a.last.split(",")]]
    t_start = time.time()
    s = Session(tool_argv(a, ["chartread", "-v", "-c", "1", a.basename]), a.port, a.workdir, log)
    result = {}
    times = {"start": t_start}
    m = s.expect(r"Device:\s*(SpectroScan\S*)", 60)
    result["table"] = m.group(1)
    s.expect(r"place sheet 1 of 1 on table.*?hit return", 60)
    times["sheet_prompt"] = time.time()
    pending = "\r"
    located = []
    for i in range(len(by_name) if by_name else len(in_order)):
        m = press(s, pending, r"locate patch (\S+) with the sight", 60, a.control)
        located.append(m.group(1))
        if by_name and m.group(1) not in by_name:
            raise EOFError("chartread asks for patch %s; --locate gives %s" % (m.group(1), sorted(by_name)))
        xy = by_name[m.group(1)] if by_name else in_order[i]
        control(a.control, {"cmd": "place", "x_mm": xy[0], "y_mm": xy[1]})
    result["located"] = located
    times["located"] = time.time()
    press(s, pending, r"Sheet 1 of 1 read OK", a.read_timeout, a.control)
    times["read_ok"] = time.time()
    result["exit"] = s.wait(30)
    times["exit"] = time.time()
    result["times"] = times
    result["patches"] = read_ti3(os.path.join(a.workdir, a.basename + ".ti3"))
    return result


def main():
    p = argparse.ArgumentParser()
    p.add_argument("mode", choices=["spotread", "chartread"])
    p.add_argument("--port", required=True)
    p.add_argument("--control", required=True)
    p.add_argument("--patch", default="D4")
    p.add_argument("--workdir", default=os.getcwd())
    p.add_argument("--basename", default="chart")
    p.add_argument("--patches", type=int, default=12)
    p.add_argument("--first", default="30,20", help="x,y mm of the strip's first patch")
    p.add_argument("--last", default="250,20", help="x,y mm of the strip's last patch")
    p.add_argument("--locate", action="append", default=[], metavar="PATCH=X,Y",
                   help="where the sight goes when chartread asks for PATCH (repeat; replaces --first/--last)")
    p.add_argument("--page", default="A4", help="printtarg page size: A4, or WWWxHHH in mm")
    p.add_argument("--log", default="-")
    p.add_argument("--read-timeout", type=float, default=120, help="seconds allowed for reading the sheet")
    p.add_argument("--trace", default="", help="run the tool under strace, writing its log here")
    a = p.parse_args()
    log = sys.stderr if a.log == "-" else open(a.log, "w")
    try:
        result = run_spotread(a, log) if a.mode == "spotread" else run_chartread(a, log)
        result["ok"] = True
    except (TimeoutError, EOFError) as e:
        result = {"ok": False, "error": str(e)}
    print(json.dumps(result))
    return 0 if result["ok"] else 1


if __name__ == "__main__":
    sys.exit(main())
