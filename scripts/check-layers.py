#!/usr/bin/env python3
"""The layering rule of ARCHITECTURE.md: a module of src/ may use only modules before it in the
data-flow order below, never one after it. Exits 1 naming every `crate::` path that breaks it.

Comments are ignored; grouped imports (`use crate::{a::X, b::Y}`) count each group member. A
top-level module missing from ORDER is reported (add it where it belongs) but does not fail,
so a helper's new module can land before its row does.
"""
import pathlib
import re
import sys

# Data-flow order: frames in, results out, front ends last (STYLE.md, ARCHITECTURE.md).
ORDER = [
    "test_skip", "atomic_file", "input_file", "camera", "stats", "kernels", "frame", "lut", "classify", "blobs", "sensors", "geometry",
    "model", "sim", "import", "formats",
    "recognition", "overhead", "ssl_vision", "session", "wmd", "pipeline", "overlay", "annotate", "eval", "streams", "sources",
    "live", "workspace", "app_options", "cli", "app",
]

root = pathlib.Path(__file__).resolve().parent.parent / "src"


def strip_comments(text):
    text = re.sub(r"/\*.*?\*/", "", text, flags=re.S)
    text = re.sub(r'"(\\.|[^"\\])*"', '""', text)
    return re.sub(r"//[^\n]*", "", text)


def used_modules(text):
    """Top-level modules named by `crate::` paths, with their line numbers."""
    out = []
    for m in re.finditer(r"\bcrate::(\{|[a-z_][a-z0-9_]*)", text):
        line = text.count("\n", 0, m.start()) + 1
        if m.group(1) != "{":
            out.append((m.group(1), line))
            continue
        depth, i, start = 1, m.end(), m.end()
        while i < len(text) and depth:
            depth += {"{": 1, "}": -1}.get(text[i], 0)
            i += 1
        group, depth, member = text[start:i - 1], 0, ""
        for ch in group + ",":
            if ch == "{":
                depth += 1
            elif ch == "}":
                depth -= 1
            if ch == "," and depth == 0:
                name = re.match(r"\s*([a-z_][a-z0-9_]*)", member)
                if name:
                    out.append((name.group(1), line))
                member = ""
            else:
                member += ch
    return out


modules = sorted({p.relative_to(root).parts[0].removesuffix(".rs")
                  for p in root.rglob("*.rs")} - {"lib", "main"})
failed = False
for module in modules:
    if module not in ORDER:
        print(f"layers: src/{module} is not in scripts/check-layers.py's ORDER; add it",
              file=sys.stderr)
        continue
    rank = ORDER.index(module)
    base = root / module
    files = sorted(base.rglob("*.rs")) if base.is_dir() else [root / f"{module}.rs"]
    for f in files:
        for used, line in used_modules(strip_comments(f.read_text(encoding="utf-8"))):
            if used in ORDER and ORDER.index(used) > rank:
                print(f"{f.relative_to(root.parent)}:{line}: {module} uses crate::{used}, "
                      "which comes later in the data-flow order")
                failed = True
sys.exit(1 if failed else 0)
