#!/usr/bin/env python3
"""Issue 24: docs/ARCHITECTURE.md against the code, so the map cannot drift without a test noticing.

- the code map's table: every folder it names exists, every target it names is defined by a CMake file, every
  library or program the project defines (outside tests/ and bench/) lives in a folder the table names, and what
  each row's targets link of the project is within the folders its "may depend on" column names;
- the newcomer's types: each is declared (class, struct or function) in a project header;
- invariant 4, threads and locks: every daemon class that owns a std::thread or a std::mutex is named there, and the
  number of mutexes it states is the number the code has;
- every check an invariant cites exists: each `ctest -R` alternative matches a defined test, each Suite.Name a TEST;
- README.md's "Layout" line names existing folders, and every top-level folder that builds something."""
from __future__ import annotations

import fnmatch
import re
import sys
import unittest
from pathlib import Path

SOURCE = Path(sys.argv.pop(1) if len(sys.argv) > 1 else Path(__file__).resolve().parents[2]).resolve()
DOC = SOURCE / "docs" / "ARCHITECTURE.md"
SKIP_DIRS = {".git", "build", "build-release", "build-asan", "build-fuzz", "build-tsan", "node_modules"}
NUMBERS = {"one": 1, "two": 2, "three": 3, "four": 4, "five": 5, "six": 6, "seven": 7, "eight": 8, "nine": 9, "ten": 10}


def project_files(pattern: str):
    for p in sorted(SOURCE.rglob(pattern)):
        if not any(part in SKIP_DIRS for part in p.relative_to(SOURCE).parts):
            yield p


def section(text: str, heading: str) -> str:
    m = re.search(rf"^## {re.escape(heading)}\n(.*?)(?=^## |\Z)", text, re.M | re.S)
    assert m, f"docs/ARCHITECTURE.md has no '## {heading}' section"
    return m.group(1)


def cmake_files():
    for p in project_files("*"):
        if p.name == "CMakeLists.txt" or p.suffix == ".cmake":
            yield p


def cmake_targets() -> dict[str, str]:
    """{library or executable: repo-relative folder of its CMake file}."""
    out = {}
    for p in cmake_files():
        text = re.sub(r"#[^\n]*", "", p.read_text())
        for m in re.finditer(r"\badd_(?:library|executable)\s*\(\s*([^\s)$]+)(\s+ALIAS)?", text):
            if not m.group(2):
                out[m.group(1)] = p.parent.relative_to(SOURCE).as_posix()
    return out


def cmake_links() -> tuple[dict[str, str], list[tuple[str, str]]]:
    """{alias: real target}, [(target, linked item)] from every target_link_libraries line."""
    aliases, links = {}, []
    for p in cmake_files():
        text = re.sub(r"#[^\n]*", "", p.read_text())
        for m in re.finditer(r"\badd_library\s*\(\s*([^\s)]+)\s+ALIAS\s+([^\s)]+)", text):
            aliases[m.group(1)] = m.group(2)
        for m in re.finditer(r"\btarget_link_libraries\s*\(([^)]*)\)", text):
            words = m.group(1).split()
            links += [(words[0], w) for w in words[1:] if w not in ("PUBLIC", "PRIVATE", "INTERFACE")]
    return aliases, links


def cmake_tests() -> set[str]:
    names = set()
    for p in cmake_files():
        if p.is_file():
            names.update(re.findall(r"\b(?:add_test|colorlab_add_gtest)\s*\(\s*NAME\s+([^\s)]+)", p.read_text()))
    return names


class ArchitectureMap(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.doc = DOC.read_text()
        cls.targets = cmake_targets()
        assert "colorlabd" in cls.targets and "colorlab_core" in cls.targets, "the CMake parser needs a look"

    def code_map_rows(self) -> list[tuple[list[str], list[str]]]:
        rows = []
        for line in section(self.doc, "Code map").splitlines():
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            if line.startswith("| `") and len(cells) >= 2:
                rows.append((re.findall(r"`([^`]+)`", cells[0]), re.findall(r"`([^`]+)`", cells[1])))
        self.assertGreater(len(rows), 10, "the code map's table was not found")
        return rows

    def test_code_map_folders_and_targets_exist(self):
        missing = []
        for folders, targets in self.code_map_rows():
            for f in folders:
                pattern = re.sub(r"<[^>]+>", "*", f.rstrip("/"))
                if not [p for p in SOURCE.glob(pattern) if p.is_dir()]:
                    missing.append(f"folder {f}")
            for t in targets:
                if not fnmatch.filter(self.targets, t):
                    missing.append(f"target {t}")
        self.assertEqual(missing, [], "docs/ARCHITECTURE.md's code map names what the tree does not have")

    def test_each_rows_targets_link_only_what_its_row_allows(self):
        aliases, links = cmake_links()
        rows = []
        for line in section(self.doc, "Code map").splitlines():
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            if line.startswith("| `") and len(cells) >= 4:
                rows.append((re.findall(r"`([^`]+)`", cells[0]), re.findall(r"`([^`]+)`", cells[1]), cells[3]))
        wrong = []
        for folders, targets, deps in rows:
            if not targets or "anything" in deps:
                continue
            own = [re.sub(r"<[^>]+>", "*", f.rstrip("/")) for f in folders]
            allowed = list(own)
            for word in re.findall(r"[a-z][\w/-]*", re.sub(r"\([^)]*\)", "", deps)):
                for cand in (word, f"daemon/{word}", f"drivers/{word}"):
                    if (SOURCE / cand).is_dir():
                        allowed.append(cand)
                        break
            mine = {t for pat in targets for t in fnmatch.filter(self.targets, pat)}
            for target, item in links:
                if aliases.get(target, target) not in mine:
                    continue
                home = self.targets.get(aliases.get(item, item))
                if home is None or home.split("/")[0] == "cmake":
                    continue  # a system library or an imported dependency
                if not any(fnmatch.fnmatch(home, a) or fnmatch.fnmatch(home, a + "/*") for a in allowed):
                    wrong.append(f"{target} links {item} ({home}); its row allows: {deps}")
        self.assertEqual(sorted(set(wrong)), [], "docs/ARCHITECTURE.md's 'may depend on' column is out of date")

    def test_every_target_lives_in_a_mapped_folder(self):
        folders = [re.sub(r"<[^>]+>", "*", f.rstrip("/")) for fs, _ in self.code_map_rows() for f in fs]
        unmapped = []
        for target, home in sorted(self.targets.items()):
            if home.split("/")[0] in ("tests", "bench", "cmake"):  # cmake/: imported dependencies, not ours
                continue
            if not any(fnmatch.fnmatch(home, f) or fnmatch.fnmatch(home, f + "/*") for f in folders):
                unmapped.append(f"{target} ({home})")
        self.assertEqual(unmapped, [], "targets in folders docs/ARCHITECTURE.md's code map does not name: add a row")

    def test_the_newcomers_types_are_declared(self):
        m = re.search(r"\*\*Types a newcomer meets first\*\*:(.*?)\n\n", self.doc, re.S)
        self.assertIsNotNone(m, "no 'Types a newcomer meets first' paragraph")
        names = {n.split("::")[-1].rstrip("()") for n in re.findall(r"`([A-Za-z_:]+(?:\(\))?)`", m.group(1))}
        headers = "\n".join(p.read_text(errors="replace") for p in project_files("*.hpp"))
        undeclared = [n for n in sorted(names)
                      if not re.search(rf"\b(class|struct)\s+{n}\b|\b{n}\s*\(", headers)]
        self.assertEqual(undeclared, [], "types the map names that no header declares")

    def test_threads_and_mutexes_of_the_daemon_are_the_ones_invariant_4_names(self):
        inv = re.search(r"^4\. \*\*Threads and locks.*?(?=^\d+\. \*\*)", self.doc, re.M | re.S)
        self.assertIsNotNone(inv, "invariant 4 (threads and locks) not found")
        text = inv.group(0)
        owners: dict[str, set[str]] = {"mutex": set(), "thread": set()}
        for p in project_files("*.hpp"):
            if p.relative_to(SOURCE).parts[0] != "daemon":
                continue
            cls = None
            for line in p.read_text().splitlines():
                c = re.match(r"(?:class|struct)\s+(\w+)\b[^;]*$", line)
                if c:
                    cls = c.group(1)
                for kind, pat in (("mutex", r"\bstd::(?:shared_)?mutex\s+\w+"), ("thread", r"\bstd::(?:j)?thread\s+\w+")):
                    if re.search(pat, line) and cls:
                        owners[kind].add(cls)
        self.assertTrue(owners["mutex"] and owners["thread"], "no std::mutex or std::thread member found: parser")
        unnamed = sorted(c for c in owners["mutex"] | owners["thread"] if not re.search(rf"`{c}`", text))
        self.assertEqual(unnamed, [], "daemon classes owning a thread or a mutex that invariant 4 does not name")
        count = re.search(r"\b(\w+) mutexes\b", text)
        self.assertIsNotNone(count, "invariant 4 does not say how many mutexes")
        stated = NUMBERS.get(count.group(1).lower(), count.group(1))
        self.assertEqual(stated, len(owners["mutex"]), f"invariant 4 says '{count.group(0)}'; the daemon's "
                         f"classes with a mutex: {sorted(owners['mutex'])}")

    def test_the_checks_the_invariants_cite_exist(self):
        tests = cmake_tests()
        self.assertIn("layout_dependency_rules", tests, "the CMake test parser needs a look")
        gtests = set()
        for p in project_files("*.cpp"):
            if p.relative_to(SOURCE).parts[0] == "tests":
                gtests.update(f"{a}.{b}" for a, b in re.findall(r"^TEST(?:_F|_P)?\((\w+),\s*(\w+)\)", p.read_text(), re.M))
        body = section(self.doc, "Invariants, and how each is checked")
        missing = []
        for expr in re.findall(r"ctest --preset \w+\s+-R\s+'?([^'`\s]+)'?", body):
            for alt in expr.split("|"):
                if not any(re.search(alt, t) for t in tests):
                    missing.append(f"ctest -R {alt}")
        for name in re.findall(r"`(\w+_tests?)`", body):
            if name not in tests:
                missing.append(name)
        for suite, case in re.findall(r"`([A-Z]\w+)\.([A-Z]\w*)(?:…)?`", body):
            if not any(g == f"{suite}.{case}" or g.startswith(f"{suite}.{case}") for g in gtests):
                missing.append(f"{suite}.{case}")
        self.assertEqual(missing, [], "docs/ARCHITECTURE.md cites checks that do not exist")

    def test_the_readmes_layout_line_names_the_top_level_folders(self):
        readme = (SOURCE / "README.md").read_text()
        m = re.search(r"^## Layout\n(.*?)(?=^## |\Z)", readme, re.M | re.S)
        self.assertIsNotNone(m, "README.md has no '## Layout' section")
        named = {f.rstrip("/") for f in re.findall(r"`([a-z][\w-]*/)`", m.group(1))}
        missing = sorted(f for f in named if not (SOURCE / f).is_dir())
        building = {p.relative_to(SOURCE).parts[0] for p in cmake_files()
                    if len(p.relative_to(SOURCE).parts) > 1 and p.relative_to(SOURCE).parts[0] != "cmake"}
        unnamed = sorted(building - named)
        self.assertEqual((missing, unnamed), ([], []),
                         "README.md's Layout line: (folders that do not exist, top-level folders it does not name)")


if __name__ == "__main__":
    unittest.main(verbosity=2)
