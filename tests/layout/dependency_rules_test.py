#!/usr/bin/env python3
"""Issue 24: the dependency rules docs/ARCHITECTURE.md states, checked on the source tree so the map cannot drift.
Reads both what a file #includes (resolved to the folder whose include/ directory holds the header) and what a
target links (every target_link_libraries line, each target resolved to the folder whose CMake file defines it):

- sim/ uses the wire codecs (drivers/wire/) and never a driver folder;
- analysis/ does no networking: no Asio, Beast or socket headers, no link to Boost, colorlab_asio, daemon/ or
  drivers/ targets, no include of their headers;
- core/ depends on nothing else in the project, links nothing, and includes only the standard library, the two
  header-only parsers it is built on and four of the C library's POSIX headers (CORE_LIBC_HEADERS);
- drivers/ never links or includes daemon/ (the daemon drives the drivers, not the other way);
- colorlabd's production targets (everything its link lines reach) link no sim/ target and their code includes no
  sim/ header, except what EMBEDDED_LAB_NEEDS names with its reason: the simulated lab stays out of the daemon.

Any violation that must wait for a move is listed once, in KNOWN_EXCEPTIONS, so that a new one fails; today there
are none."""
from __future__ import annotations

import re
import sys
import unittest
from pathlib import Path

SOURCE = Path(sys.argv.pop(1) if len(sys.argv) > 1 else Path(__file__).resolve().parents[2]).resolve()
# Not the project's own code: build trees, tests' fixtures, the vendored nothing.
SKIP_DIRS = {".git", "build", "build-release", "build-asan", "build-fuzz", "build-tsan", "node_modules"}
CODE = {".cpp", ".hpp", ".h", ".cc", ".c"}

# Violations waiting for a move (issue 24 moved the LS-110 and HID relay codecs into drivers/wire/, emptying it).
# Nothing may be added here.
KNOWN_EXCEPTIONS: set[tuple[str, str, str]] = set()

# sim/ targets colorlabd may link because its embedded simulated lab needs them, each with the reason. Empty: the
# embedded lab is colorlab-sim run as a child process (daemon/core/src/embedded_sim.cpp) reached over its sockets,
# and the simulated DSLR the daemon drives is SimDslrCamera, a socket client in drivers/camera. The in-process
# SimulatedCamera is its own target (colorlab::drivers_simulated_camera) for tests and benches.
EMBEDDED_LAB_NEEDS: dict[str, str] = {}
PRODUCTION_ROOT = "colorlabd"

NETWORK_HEADERS = re.compile(r"^(boost/asio|boost/beast|asio\.hpp|asio/|sys/socket\.h|netinet/|arpa/|netdb\.h|sys/un\.h)")
CORE_EXTERNAL_HEADERS = {"nlohmann/json.hpp", "toml++/toml.h"}  # header-only; no library behind them
# The C library's POSIX headers core/ may use: they add no library to a link line (every program links libc), and
# a thread's name and CPU priority (core/thread_priority.hpp, shared by the daemon, campaigns and drivers) and its
# own account of its time (core/thread_account.hpp: its CPU clock, its schedstat file kept open) need them.
CORE_LIBC_HEADERS = {"fcntl.h", "pthread.h", "sys/resource.h", "sys/syscall.h", "time.h", "unistd.h"}
INCLUDE = re.compile(r'^\s*#\s*include\s*([<"])([^>"]+)[>"]', re.M)


def files(top: str, suffixes: set[str] | None = None, names: set[str] | None = None):
    for p in sorted((SOURCE / top).rglob("*")):
        if any(part in SKIP_DIRS for part in p.relative_to(SOURCE).parts) or not p.is_file():
            continue
        if (suffixes and p.suffix in suffixes) or (names and p.name in names):
            yield p


def rel(p: Path) -> str:
    return p.relative_to(SOURCE).as_posix()


def owner_folder(path: str) -> str:
    """The folder a rule speaks of: drivers/<sub> for drivers (wire is one of them), else the top folder."""
    parts = path.split("/")
    return "/".join(parts[:2]) if parts[0] in ("drivers", "daemon", "client") and len(parts) > 1 else parts[0]


def header_owners() -> dict[str, set[str]]:
    """'colorlab/drivers/x.hpp' -> the folders whose include/ directory holds it."""
    owners: dict[str, set[str]] = {}
    for p in files(".", CODE):
        parts = p.relative_to(SOURCE).parts
        if "include" in parts:
            i = parts.index("include")
            owners.setdefault("/".join(parts[i + 1:]), set()).add(owner_folder("/".join(parts[:i])))
    return owners


def cmake_text(p: Path) -> str:
    return re.sub(r"#[^\n]*", "", p.read_text())  # comments, which may name targets in prose


def target_files() -> tuple[dict[str, str], dict[str, set[str]], dict[str, str]]:
    """{alias or name: real target name}, {target: its source files and include directories (repo-relative)},
    {target: the folder of the CMake file that defines it}."""
    real: dict[str, str] = {}
    owned: dict[str, set[str]] = {}
    home: dict[str, str] = {}
    for p in files(".", names={"CMakeLists.txt"}):
        text, here = cmake_text(p), p.parent
        for m in re.finditer(r"\badd_(library|executable)\s*\(\s*([^\s)]+)([^)]*)\)", text):
            name, rest = m.group(2), m.group(3).split()
            if len(rest) >= 2 and rest[0] == "ALIAS":
                real[name] = rest[1]
                continue
            real.setdefault(name, name)
            home[name] = rel(here) if here != SOURCE else "."
            owned.setdefault(name, set()).update(source_paths(here, rest))
        for m in re.finditer(r"\btarget_(?:sources|include_directories)\s*\(\s*([^\s)]+)([^)]*)\)", text):
            owned.setdefault(m.group(1), set()).update(source_paths(here, m.group(2).split()))
    return real, owned, home


def source_paths(here: Path, words: list[str]) -> set[str]:
    out = set()
    for w in words:
        w = w.replace("${CMAKE_CURRENT_SOURCE_DIR}", str(here)).replace("${PROJECT_SOURCE_DIR}", str(SOURCE))
        if "$" in w or w.isupper():
            continue  # keywords (PRIVATE, STATIC, SYSTEM) and variables we do not evaluate
        path = (here / w).resolve()
        if path.exists() and SOURCE in path.parents:
            out.add(rel(path))
    return out


def targets() -> tuple[dict[str, str], list[tuple[str, str, str]]]:
    """{target or alias: defining folder}, [(target, linked item, file)] from every target_link_libraries."""
    defined: dict[str, str] = {}
    links: list[tuple[str, str, str]] = []
    for p in files(".", {".txt", ".cmake"}):
        if p.suffix == ".txt" and p.name != "CMakeLists.txt":
            continue
        text, where = cmake_text(p), owner_folder(rel(p.parent)) if p.parent != SOURCE else "."
        for m in re.finditer(r"\badd_(?:library|executable)\s*\(\s*([^\s)]+)([^)]*)\)", text):
            name, rest = m.group(1), m.group(2).split()
            if len(rest) >= 2 and rest[0] == "ALIAS":
                defined[name] = defined.get(rest[1], where)
            else:
                defined[name] = where
        for m in re.finditer(r"\btarget_link_libraries\s*\(([^)]*)\)", text):
            words = m.group(1).split()
            for item in words[1:]:
                if item not in ("PUBLIC", "PRIVATE", "INTERFACE"):
                    links.append((words[0], item, rel(p)))
    # Aliases defined before their target in the same pass resolve now.
    for p in files(".", {".txt", ".cmake"}):
        for m in re.finditer(r"\badd_library\s*\(\s*([^\s)]+)\s+ALIAS\s+([^\s)]+)", cmake_text(p)):
            if m.group(2) in defined:
                defined[m.group(1)] = defined[m.group(2)]
    return defined, links


class DependencyRules(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.headers = header_owners()
        cls.defined, cls.links = targets()
        # Not vacuous: the parsers found the targets and headers this test was written against.
        for t in ("colorlab_sim_ls110", "colorlab::drivers_ls110", "colorlab::wire_protocols", "colorlab_analysis",
                  "colorlab_core"):
            assert t in cls.defined, f"no CMake file defines {t}: the parser needs a look"
        assert cls.headers.get("colorlab/wire/spectrolino_protocol.hpp") == {"drivers/wire"}, cls.headers.get("colorlab/wire/spectrolino_protocol.hpp")
        cls.seen_exceptions: set[tuple[str, str, str]] = set()

    @classmethod
    def tearDownClass(cls):
        for e in sorted(KNOWN_EXCEPTIONS - cls.seen_exceptions):
            print(f"NOTE: known exception {e} no longer occurs: remove it from KNOWN_EXCEPTIONS", flush=True)

    def includes(self, top: str):
        for p in files(top, CODE):
            for m in INCLUDE.finditer(p.read_text(errors="replace")):
                yield rel(p), m.group(1), m.group(2)

    def links_of(self, top: str):
        for target, item, cmake in self.links:
            if self.defined.get(target, "").split("/")[0] == top:
                yield target, item, cmake

    def violations(self, found: list[tuple[str, str, str]]) -> list[str]:
        out = []
        for v in found:
            if v in KNOWN_EXCEPTIONS:
                self.seen_exceptions.add(v)
            else:
                out.append(" ".join(v))
        return out

    def test_sim_uses_the_wire_codecs_not_driver_folders(self):
        found = []
        for path, _, header in self.includes("sim"):
            owners = self.headers.get(header, set())
            if any(o.startswith("drivers/") and o != "drivers/wire" for o in owners):
                found.append(("include", path, header))
        for target, item, _ in self.links_of("sim"):
            folder = self.defined.get(item, "")
            if folder.startswith("drivers/") and folder != "drivers/wire":
                found.append(("link", target, item))
        self.assertEqual(self.violations(found), [],
                         "sim/ depends on a driver folder; shared codecs belong in drivers/wire/ (issue 24)")

    def test_analysis_does_no_networking_and_knows_no_daemon_or_driver(self):
        found = []
        for path, _, header in self.includes("analysis"):
            owners = self.headers.get(header, set())
            if NETWORK_HEADERS.match(header) or any(o.split("/")[0] in ("daemon", "drivers") for o in owners):
                found.append(("include", path, header))
        for target, item, _ in self.links_of("analysis"):
            folder = self.defined.get(item, "")
            if item.startswith("Boost::") or item == "colorlab_asio" or folder.split("/")[0] in ("daemon", "drivers"):
                found.append(("link", target, item))
        self.assertEqual(self.violations(found), [], "analysis/ is pure colour science: no I/O stack, no daemon")

    def test_core_depends_on_nothing(self):
        found = []
        for path, kind, header in self.includes("core"):
            owners = self.headers.get(header, set())
            if owners:
                if owners != {"core"}:
                    found.append(("include", path, header))
            elif kind == '"':
                if not (SOURCE / path).parent.joinpath(header).exists():
                    found.append(("include", path, header))
            elif ("/" in header or "." in header) and header not in CORE_EXTERNAL_HEADERS | CORE_LIBC_HEADERS:
                found.append(("include", path, header))  # a system or third-party library's header
        for target, item, _ in self.links_of("core"):
            found.append(("link", target, item))
        self.assertEqual(self.violations(found), [], "core/ is the bottom of the house: it depends on nothing")


    def production(self) -> set[str]:
        """Every project target colorlabd's link lines reach, by real name."""
        real, _, _ = target_files()
        edges: dict[str, set[str]] = {}
        for target, item, _ in self.links:
            edges.setdefault(real.get(target, target), set()).add(real.get(item, item))
        seen, todo = {PRODUCTION_ROOT}, [PRODUCTION_ROOT]
        while todo:
            for nxt in edges.get(todo.pop(), ()):
                if nxt in real and nxt not in seen:
                    seen.add(nxt)
                    todo.append(nxt)
        return seen

    def test_drivers_never_depend_on_the_daemon(self):
        found = []
        for path, _, header in self.includes("drivers"):
            if any(o.split("/")[0] == "daemon" for o in self.headers.get(header, set())):
                found.append(("include", path, header))
        for target, item, _ in self.links_of("drivers"):
            if self.defined.get(item, "").split("/")[0] == "daemon":
                found.append(("link", target, item))
        self.assertEqual(self.violations(found), [], "drivers/ must not know the daemon that drives them")

    def test_colorlabd_carries_no_simulator_beyond_what_the_embedded_lab_needs(self):
        real, owned, home = target_files()
        production = self.production()
        # Not vacuous: the walk reached the daemon's stack down to the camera driver.
        for t in ("colorlab_api", "colorlab_daemon", "colorlab_campaigns", "colorlab_drivers_camera", "colorlab_core"):
            assert t in production, f"{t} not reached from {PRODUCTION_ROOT}: the link parser needs a look"
        found = []
        for t in sorted(production):
            if home.get(t, "").split("/")[0] == "sim" and t not in EMBEDDED_LAB_NEEDS:
                found.append(("link", PRODUCTION_ROOT, t))
        # The code of those targets: their folders, less the files other targets defined there own (a test-only
        # target such as drivers/camera's simulated one may share its folder with a production target).
        others = set().union(*(owned.get(t, set()) for t in home if t not in production))
        others -= set().union(*(owned.get(t, set()) for t in production))
        allowed_headers = {h for h, owners in self.headers.items() if owners & {home.get(t) for t in EMBEDDED_LAB_NEEDS}}
        for folder in sorted({home[t] for t in production if t in home and home[t] != "."}):
            for p in files(folder, CODE):
                path = rel(p)
                if path in others or any(path.startswith(o + "/") for o in others):
                    continue
                for m in INCLUDE.finditer(p.read_text(errors="replace")):
                    owners = self.headers.get(m.group(2), set())
                    if any(o.split("/")[0] == "sim" for o in owners) and m.group(2) not in allowed_headers:
                        found.append(("include", path, m.group(2)))
        self.assertEqual(self.violations(found), [],
                         "colorlabd's targets carry the simulator: move the simulated device into its own target "
                         "(as colorlab::drivers_simulated_camera), or name what the embedded lab needs, and why, "
                         "in EMBEDDED_LAB_NEEDS")


if __name__ == "__main__":
    unittest.main(verbosity=2)
