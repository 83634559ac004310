#!/usr/bin/env python3
"""Issue 24: campaigns/ is three rooms with one arrow, engine -> lab -> procedures. Only the engine knows Lua: the
lab and the procedures include no Lua header and no engine header, the procedures no lab header, and neither
target links Lua or the engine (read from the #includes and campaigns/CMakeLists.txt)."""
from __future__ import annotations

import re
import sys
import unittest
from pathlib import Path

SOURCE = Path(sys.argv.pop(1) if len(sys.argv) > 1 else Path(__file__).resolve().parents[2])
CAMPAIGNS = SOURCE / "campaigns"
INCLUDE = re.compile(r'^\s*#\s*include\s*[<"]([^>"]+)[>"]', re.M)


def headers_of(room: str) -> set[str]:
    return {p.name for p in (CAMPAIGNS / room / "include" / "colorlab" / "campaigns").glob("*.hpp")}


def includes_in(room: str):
    for p in sorted((CAMPAIGNS / room).rglob("*")):
        if p.suffix in (".cpp", ".hpp"):
            for m in INCLUDE.finditer(p.read_text()):
                yield p.relative_to(SOURCE).as_posix(), m.group(1)


def links_of(target: str) -> list[str]:
    text = re.sub(r"#[^\n]*", "", (CAMPAIGNS / "CMakeLists.txt").read_text())
    m = re.search(r"target_link_libraries\(\s*" + re.escape(target) + r"\b([^)]*)\)", text)
    assert m, f"campaigns/CMakeLists.txt links nothing to {target}: the parser needs a look"
    return m.group(1).split()


class CampaignRooms(unittest.TestCase):
    def setUp(self):
        self.engine, self.lab = headers_of("engine"), headers_of("lab")
        self.assertIn("engine.hpp", self.engine)
        self.assertIn("lab_calls.hpp", self.lab)
        self.assertGreater(len(list(includes_in("lab"))), 20, "the include parser found too little: it needs a look")

    def test_only_the_engine_knows_lua(self):
        found = []
        for room, forbidden in (("lab", self.engine), ("procedures", self.engine | self.lab)):
            for path, header in includes_in(room):
                name = header.rsplit("/", 1)[-1]
                if header.startswith("lua") or (header.startswith("colorlab/campaigns/") and name in forbidden):
                    found.append(f"{path} includes {header}")
        self.assertEqual(found, [], "the arrow is engine -> lab -> procedures")

    def test_the_targets_link_down_only(self):
        for target, forbidden in (("colorlab_campaign_lab", {"PkgConfig::LUA", "colorlab::campaigns"}),
                                  ("colorlab_campaign_procedures",
                                   {"PkgConfig::LUA", "colorlab::campaigns", "colorlab::campaign_lab"})):
            self.assertEqual(sorted(set(links_of(target)) & forbidden), [], target)


if __name__ == "__main__":
    unittest.main(verbosity=2)
