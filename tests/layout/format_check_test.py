#!/usr/bin/env python3
"""Issue 24: scripts/format_check.py, which the lead trusts to say that applying .clang-format moved only
whitespace (`scripts/format.sh --verify`) and made no row over 120 columns (`--check-long`). Planted changes must be
caught: a literal or a token altered, a braced list joined into one long row; whitespace moves must pass."""
from __future__ import annotations

import os
import shutil
import sys
import tempfile
import unittest
from pathlib import Path

SOURCE = Path(sys.argv.pop(1) if len(sys.argv) > 1 else Path(__file__).resolve().parents[2])
sys.path.insert(0, str(SOURCE / "scripts"))
import format_check  # noqa: E402


def texts(tokens):
  return [t[1] for t in tokens]


class Lexer(unittest.TestCase):
  def test_literals_stay_whole(self):
    src = 'auto a = R"lua(x = "q"\n  y)lua"; char c = \'"\'; auto s = u8"a  b" "c";'
    self.assertEqual(texts(format_check.lex(src)),
                     ["auto", "a", "=", 'R"lua(x = "q"\n  y)lua"', ";", "char", "c", "=", "'\"'", ";", "auto", "s",
                      "=", 'u8"a  b"', '"c"', ";"])

  def test_numbers_splices_and_comments(self):
    src = "int n = 1'000'000 >> 2; // a\n#define X \\\n  (n)\n/* b\n c */"
    self.assertEqual(texts(format_check.lex(src)),
                     ["int", "n", "=", "1'000'000", ">>", "2", ";", "// a", "#", "define", "X", "(", "n", ")",
                      "/* b\n c */"])


class Compare(unittest.TestCase):
  def verdict(self, before, after):
    return format_check.compare(format_check.lex(before), format_check.lex(after))

  def test_whitespace_and_realigned_comments_pass(self):
    problems, added, removed, _ = self.verdict("f(a,\n  b);   // why\n", "f(a, b);  // why\n")
    self.assertEqual((problems, added, removed), ([], [], []))

  def test_changed_literal_fails(self):
    self.assertTrue(self.verdict('f("a  b");', 'f("a b");')[0])

  def test_changed_token_fails(self):
    self.assertTrue(self.verdict("x = a == b;", "x = a != b;")[0])

  def test_added_comment_is_listed_not_failed(self):
    problems, added, _, _ = self.verdict("namespace x {\n}\n", "namespace x {\n}  // namespace x\n")
    self.assertEqual(problems, [])
    self.assertEqual(texts(added), ["// namespace x"])


@unittest.skipUnless(shutil.which("clang-format"), "clang-format is not installed (scripts/setup.sh installs it)")
class WithClangFormat(unittest.TestCase):
  """Runs the project's .clang-format on planted files (copied beside it, so --style=file finds it)."""

  def examine(self, code):
    with tempfile.TemporaryDirectory() as d:
      shutil.copy(SOURCE / ".clang-format", d)
      path = os.path.join(d, "planted.cpp")
      Path(path).write_text(code)
      return format_check.examine(path, "clang-format")

  ROW = ('  json j{{"client", r.client}, {"done", r.done}, {"why", r.why}, {"load_before", r.load_before},\n'
         '         {"load_after", r.load_after}, {"init_s", r.init}, {"read_s", r.read}}%s;\n')

  def test_a_joined_braced_list_is_reported(self):
    r = self.examine("void f() {\n" + self.ROW % "" + "}\n")
    self.assertEqual([(first, last) for _, first, last, _, _ in r["long"]], [(2, 3)])

  def test_a_trailing_comma_keeps_it_one_element_a_line(self):
    r = self.examine("void f() {\n" + (self.ROW % "").replace("r.read}}", "r.read},}") + "}\n")
    self.assertEqual((r["long"], r["joined"], r["problems"]), ([], [], []))

  def test_a_comment_pushed_past_the_limit_is_reported(self):
    code = ("struct S {\n  double a = 0;  // " + "x" * 90 + "\n"
            "  std::optional<std::filesystem::path> some_long_member_name;  // y\n};\n")
    r = self.examine(code)
    self.assertEqual([first for _, first, _, _, _ in r["long"]], [2])


if __name__ == "__main__":
  unittest.main()
