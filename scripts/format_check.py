#!/usr/bin/env python3
"""What `scripts/format.sh --apply` would do to a file, judged token by token (docs/TESTING.md, "Layout and lint").

Each file is lexed before and after clang-format into C++ tokens (string, character and raw-string literals whole,
comments whole, line splices as whitespace). Because clang-format only moves whitespace, the two token streams
must match one for one; that match maps every output line back to the input lines its tokens came from.

  --verify      fail unless every file's tokens are unchanged (comments compared with their whitespace collapsed;
                a comment clang-format adds, such as `// namespace x` after a namespace, is listed, not failed);
                with --against REV it compares the files now with the same files at REV (after an apply)
  --check-long  list the lines the apply would make longer than the limit that were not that long before, and the
                lines it would make by joining three or more input lines; fail if there is any
"""
import argparse
import concurrent.futures
import os
import re
import subprocess
import sys

LIMIT = 120
JOIN = 3  # an output line built from this many input lines is a row joined out of a laid-out list

PUNCTUATORS = sorted(
    """>>= <<= <=> ->* ... :: -> ++ -- << >> <= >= == != && || += -= *= /= %= &= |= ^= ## .*
       { } [ ] ( ) ; : , . ? ~ ! + - * / % ^ & | = < > #""".split(), key=len, reverse=True)
ENCODING_PREFIXES = {"u8", "u", "U", "L", "R", "u8R", "uR", "UR", "LR"}
IDENT = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
NUMBER = re.compile(r"\.?[0-9](?:'[0-9A-Za-z_]|[eEpP][+-]|[0-9A-Za-z_.])*")


class LexError(Exception):
  pass


def lex(text):
  """Tokens of C++ source as (kind, text, line), kind one of 'tok', 'lit', 'comment'; line numbers from 1."""
  tokens, i, line, n = [], 0, 1, len(text)
  while i < n:
    c = text[i]
    if c == "\n":
      line += 1
      i += 1
    elif c in " \t\r\f\v":
      i += 1
    elif c == "\\" and text.startswith("\n", i + 1):  # line splice
      line += 1
      i += 2
    elif text.startswith("//", i):
      j = i
      while True:  # a comment ending in a line splice goes on
        k = text.find("\n", j)
        k = n if k < 0 else k
        if k > i and text[k - 1] == "\\" and k < n:
          j = k + 1
          continue
        break
      tokens.append(("comment", text[i:k], line))
      line += text.count("\n", i, k)
      i = k
    elif text.startswith("/*", i):
      k = text.find("*/", i + 2)
      if k < 0:
        raise LexError(f"line {line}: unterminated /* comment")
      k += 2
      tokens.append(("comment", text[i:k], line))
      line += text.count("\n", i, k)
      i = k
    elif c == '"' or c == "'":
      k = _quoted_end(text, i, line)
      tokens.append(("lit", text[i:k], line))
      i = k
    elif IDENT.match(c):
      m = IDENT.match(text, i)
      word, k = m.group(), m.end()
      if word in ENCODING_PREFIXES and k < n and text[k] in "\"'":
        if word.endswith("R") and text[k] == '"':
          k = _raw_end(text, k, line)
        else:
          k = _quoted_end(text, k, line)
        tokens.append(("lit", text[i:k], line))
        line += text.count("\n", i, k)
      else:
        tokens.append(("tok", word, line))
      i = k
    elif c.isdigit() or (c == "." and i + 1 < n and text[i + 1].isdigit()):
      m = NUMBER.match(text, i)
      tokens.append(("tok", m.group(), line))
      i = m.end()
    else:
      for p in PUNCTUATORS:
        if text.startswith(p, i):
          tokens.append(("tok", p, line))
          i += len(p)
          break
      else:
        tokens.append(("tok", c, line))  # '@', '$', '`' or a non-ASCII character outside a literal
        i += 1
  return tokens


def _quoted_end(text, i, line):
  quote, k = text[i], i + 1
  while k < len(text) and text[k] != quote:
    if text[k] == "\n":
      raise LexError(f"line {line}: newline in a {quote}-literal")
    k += 2 if text[k] == "\\" else 1
  if k >= len(text):
    raise LexError(f"line {line}: unterminated {quote}-literal")
  return k + 1


def _raw_end(text, i, line):
  k = text.find("(", i)
  if k < 0:
    raise LexError(f"line {line}: raw string without '('")
  end = ")" + text[i + 1:k] + '"'
  e = text.find(end, k)
  if e < 0:
    raise LexError(f"line {line}: unterminated raw string")
  return e + len(end)


def _squash(comment):
  return " ".join(comment.split())


def compare(before, after):
  """(problems, added comments, removed comments, pairs) for two token lists; pairs maps after-index to before-index."""
  problems, added, removed, pairs = [], [], [], {}
  i = j = 0
  while i < len(before) or j < len(after):
    a = before[i] if i < len(before) else None
    b = after[j] if j < len(after) else None
    if a and b and a[0] == b[0] and (a[1] == b[1] or (a[0] == "comment" and _squash(a[1]) == _squash(b[1]))):
      pairs[j] = i
      i += 1
      j += 1
    elif b and b[0] == "comment":
      added.append(b)
      j += 1
    elif a and a[0] == "comment":
      removed.append(a)
      i += 1
    else:
      where = f"line {a[2]}" if a else "end of file"
      problems.append(f"{where}: {a[1] if a else '(end)'!r} became {b[1] if b else '(end)'!r}"
                      f"{f' (output line {b[2]})' if b else ''}")
      break
  return problems, added, removed, pairs


def clang_format(path, exe):
  return subprocess.run([exe, "--style=file", path], check=True, capture_output=True, text=True).stdout


def examine(path, exe, against=None):
  """The file as clang-format would leave it against the file now or, with `against` (a git revision), the file
  now (already formatted) against the file at that revision."""
  with open(path, encoding="utf-8") as f:
    now = f.read()
  if against:
    shown = subprocess.run(["git", "show", f"{against}:{path}"], capture_output=True, text=True)
    if shown.returncode != 0:  # a file new since REV has nothing to compare with
      return {"path": path, "changed": False, "problems": [f"not in {against}: {shown.stderr.strip()}"],
              "added": [], "removed": [], "long": [], "joined": [], "long_before": 0, "long_after": 0}
    before_text, after_text = shown.stdout, now
  else:
    before_text, after_text = now, clang_format(path, exe)
  result = {"path": path, "changed": before_text != after_text, "problems": [], "added": [], "removed": [],
            "long": [], "joined": [], "long_before": 0, "long_after": 0}
  before_lines, after_lines = before_text.split("\n"), after_text.split("\n")
  result["long_before"] = sum(len(l) > LIMIT for l in before_lines)
  result["long_after"] = sum(len(l) > LIMIT for l in after_lines)
  if not result["changed"]:
    return result
  try:
    before, after = lex(before_text), lex(after_text)
  except LexError as e:
    result["problems"].append(f"cannot lex: {e}")
    return result
  problems, added, removed, pairs = compare(before, after)
  result.update(problems=problems, added=added, removed=removed)
  if problems:
    return result
  sources = {}  # output line -> the input lines its tokens came from
  for j, i in pairs.items():  # a token spanning lines (a raw string, a block comment) maps its first and last
    inner = before[i][1].count("\n")
    sources.setdefault(after[j][2], set()).add(before[i][2])
    sources.setdefault(after[j][2] + inner, set()).add(before[i][2] + inner)
  for out_no, src in sorted(sources.items()):
    text = after_lines[out_no - 1]
    widest = max(len(before_lines[s - 1]) for s in src)
    if len(text) > LIMIT and (widest <= LIMIT or len(src) > 1):
      result["long"].append((out_no, min(src), max(src), len(text), text))
    elif len(src) >= JOIN and max(src) - min(src) + 1 >= JOIN:
      result["joined"].append((out_no, min(src), max(src), len(text), text))
  return result


def main():
  parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
  mode = parser.add_mutually_exclusive_group(required=True)
  mode.add_argument("--verify", dest="mode", action="store_const", const="--verify")
  mode.add_argument("--check-long", dest="mode", action="store_const", const="--check-long")
  parser.add_argument("--against", metavar="REV",
                      help="with --verify: compare the files as they are now with the same files at REV")
  parser.add_argument("files", nargs="+")
  parser.add_argument("--jobs", type=int, default=2)
  args = parser.parse_args()
  exe = os.environ.get("CLANG_FORMAT", "clang-format")
  with concurrent.futures.ThreadPoolExecutor(args.jobs) as pool:
    results = list(pool.map(lambda p: examine(p, exe, args.against), args.files))

  bad = 0
  if args.mode == "--verify":
    changed = [r for r in results if r["changed"]]
    for r in results:
      for p in r["problems"]:
        print(f"{r['path']}: {p}")
        bad += 1
      for kind, toks in (("adds", r["added"]), ("removes", r["removed"])):
        for t in toks:
          print(f"{r['path']}:{t[2]}: clang-format {kind} a comment: {t[1]}")
    comments = sum(len(r["added"]) + len(r["removed"]) for r in results)
    print(f"format_check --verify: {len(changed)} of {len(results)} file(s) change; {bad} change a token or a "
          f"literal; {comments} comment(s) added or removed (listed above)")
  else:
    for r in results:
      for p in r["problems"]:
        print(f"{r['path']}: {p}")
        bad += 1
      for out_no, first, last, width, text in r["long"]:
        what = f"lines {first}-{last} joined" if last > first else f"line {first}"
        print(f"{r['path']}:{first}: {what} become {width} columns: {text.strip()[:100]}")
        bad += 1
      for out_no, first, last, width, text in r["joined"]:
        print(f"{r['path']}:{first}: lines {first}-{last} joined into one row of {width} columns: {text.strip()[:100]}")
        bad += 1
    before = sum(r["long_before"] for r in results)
    after = sum(r["long_after"] for r in results)
    print(f"format_check --check-long: {bad} line(s) the apply would make over {LIMIT} columns or join from "
          f"{JOIN}+ lines; lines over {LIMIT} columns: {before} before, {after} after")
  return 1 if bad else 0


if __name__ == "__main__":
  sys.exit(main())
