#!/usr/bin/env python3
"""Lists functions over 100 lines and files over 800 lines in src/ (STYLE.md's limits).

A file or function may exceed them when a comment containing "size:" within the three lines
above its `fn` (or at the file's top) says why. Exits 1 when anything is listed, so .ci/run can
call it. Counting is by braces after the `fn` line, which is enough for rustfmt'd code.
"""
import pathlib
import re
import sys

FN_LIMIT, FILE_LIMIT = 100, 800
root = pathlib.Path(__file__).resolve().parent.parent
fn_re = re.compile(r"^\s*(pub(\([a-z]+\))?\s+)?(const\s+)?(unsafe\s+)?fn\s+(\w+)")
found = []
for path in sorted((root / "src").rglob("*.rs")):
    lines = path.read_text(encoding="utf-8").split("\n")
    rel = path.relative_to(root)
    if len(lines) > FILE_LIMIT and not any("size:" in l for l in lines[:15]):
        found.append(f"{rel}: {len(lines)} lines")
    i = 0
    while i < len(lines):
        m = fn_re.match(lines[i])
        if not m:
            i += 1
            continue
        depth, started, j = 0, False, i
        while j < len(lines):
            code = re.sub(r"//.*", "", lines[j])
            code = re.sub(r"'(\\.|[^\\'])'", "", code)
            code = re.sub(r'"(\\.|[^"\\])*"', "", code)
            depth += code.count("{") - code.count("}")
            started = started or "{" in code
            if started and depth <= 0:
                break
            if not started and code.rstrip().endswith(";"):
                break
            j += 1
        length = j - i + 1
        excused = any("size:" in l for l in lines[max(0, i - 3):i])
        if started and length > FN_LIMIT and not excused:
            found.append(f"{rel}:{i + 1}: fn {m.group(5)} {length} lines")
        i += 1
for f in found:
    print(f)
sys.exit(1 if found else 0)
