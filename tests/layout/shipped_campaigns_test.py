#!/usr/bin/env python3
"""Issue 24: the campaign lists a newcomer reads (README.md's "Shipped" table, docs/campaigns.md's "The campaigns
colorlab ships" table and its sequences) agree with what ships — campaigns/scripts/, which the daemon's catalogue
reads as its "shipped" directory (campaigns/engine/src/catalogue.cpp: NAME.lua is campaign NAME, NAME.sequence.lua
sequence NAME) — names and the instruments each `needs`. A script added, renamed or removed without its row fails
here, naming it."""
from __future__ import annotations

import re
import sys
import unittest
from pathlib import Path

SOURCE = Path(sys.argv.pop(1) if len(sys.argv) > 1 else Path(__file__).resolve().parents[2])
SCRIPTS = SOURCE / "campaigns" / "scripts"
SEQUENCE = ".sequence.lua"

# The roles scripts declare in `needs`, in the words the tables use (campaigns/lab/src/roles.cpp's role names).
ROLE_WORDS = {"luminance_meter": "luminance meter", "spectrophotometer": "spectrophotometer", "table": "table",
              "lamps": "lamps", "dimmer": "dimmer", "camera": "camera"}


def shipped() -> tuple[dict[str, set[str]], set[str]]:
    """{campaign: needs as table words}, {sequence names}."""
    campaigns, sequences = {}, set()
    for f in sorted(SCRIPTS.glob("*.lua")):
        if f.name.endswith(SEQUENCE):
            sequences.add(f.name[: -len(SEQUENCE)])
            continue
        text = f.read_text()
        m = re.search(r"\bneeds\s*=\s*\{([^}]*)\}", text)
        needs = set(re.findall(r'"([a-z_]+)"', m.group(1))) if m else set()
        unknown = needs - ROLE_WORDS.keys()
        if unknown:
            raise AssertionError(f"{f.name} needs {sorted(unknown)}, roles this test does not know: add them above")
        campaigns[f.stem] = {ROLE_WORDS[n] for n in needs}
    return campaigns, sequences


def table_after(text: str, heading: str, source: str) -> list[list[str]]:
    """The rows (cells stripped) of the first Markdown table after the line starting with `heading`."""
    lines = text.splitlines()
    start = next((n for n, line in enumerate(lines) if line.startswith(heading)), None)
    if start is None:
        raise AssertionError(f"{source} has no line starting {heading!r}: the test reads the campaign table after it")
    rows, in_table = [], False
    for line in lines[start + 1:]:
        if line.startswith("|"):
            in_table = True
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            if not re.fullmatch(r"-+", cells[0].replace(":", "")):
                rows.append(cells)
        elif in_table:
            break
    if len(rows) < 2:
        raise AssertionError(f"{source}: no table after {heading!r}")
    return rows[1:]  # without the header


def parse_rows(rows: list[list[str]], source: str) -> tuple[dict[str, set[str]], set[str]]:
    campaigns, sequences = {}, set()
    for cells in rows:
        m = re.fullmatch(r"`([a-z0-9-]+)`( \(sequence\))?", cells[0])
        if not m:
            raise AssertionError(f"{source}: a row's first cell is not `NAME` or `NAME` (sequence): {cells[0]!r}")
        if m.group(2):
            sequences.add(m.group(1))
        else:
            campaigns[m.group(1)] = {w.strip() for w in cells[-1].split(",") if w.strip()}
    return campaigns, sequences


class ShippedCampaignLists(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.campaigns, cls.sequences = shipped()
        # Not vacuous: the seven campaigns and the study this test was written against are still a floor.
        assert len(cls.campaigns) >= 7 and "dissertation" in cls.sequences, (cls.campaigns, cls.sequences)

    def check(self, listed: dict[str, set[str]], source: str):
        self.assertEqual(sorted(set(self.campaigns) - set(listed)), [], f"shipped but not listed in {source}")
        self.assertEqual(sorted(set(listed) - set(self.campaigns)), [], f"listed in {source} but not shipped")
        for name, needs in self.campaigns.items():
            self.assertEqual(listed[name], needs, f"{source}: {name}'s needs disagree with its script's `needs`")

    def test_readme(self):
        text = (SOURCE / "README.md").read_text()
        listed, sequences = parse_rows(table_after(text, "Shipped (", "README.md"), "README.md")
        self.check(listed, "README.md")
        self.assertEqual(sequences, self.sequences, "README.md's sequences disagree with campaigns/scripts/*.sequence.lua")
        for stale in ("Shipped today", "come next"):
            self.assertNotIn(stale, text, "README.md: the old 'what ships' sentence is back")

    def test_campaigns_doc(self):
        text = (SOURCE / "docs" / "campaigns.md").read_text()
        listed, _ = parse_rows(table_after(text, "## The campaigns colorlab ships", "docs/campaigns.md"),
                               "docs/campaigns.md")
        self.check(listed, "docs/campaigns.md")
        for name in self.sequences:
            self.assertIn(f"**`{name}`**", text, f"docs/campaigns.md does not describe the shipped sequence {name}")


if __name__ == "__main__":
    unittest.main(verbosity=2)
