#!/usr/bin/env python3
"""Recompute (or check) the "expected" objects of tests/data/external/meshes.json.

    python3 tests/data/external/update_expected.py           # rewrite expected values
    python3 tests/data/external/update_expected.py --check   # exit 1 on any difference

Each entry's expected value is exactly what `python3 tools/meshcheck.py PATH`
prints. Relative paths are relative to the repository root; absolute paths are
files installed by Debian packages (see README.md). With --check, a missing
Debian file is reported and counts as a failure.
"""
import json
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import meshcheck  # noqa: E402

MANIFEST = os.path.join(HERE, "meshes.json")


def main(argv):
    check = "--check" in argv[1:]
    with open(MANIFEST) as fh:
        entries = json.load(fh)
    bad = 0
    for e in entries:
        path = e["path"] if os.path.isabs(e["path"]) else os.path.join(ROOT, e["path"])
        if not os.path.exists(path):
            print("MISSING  %s (package %s)" % (e["path"], e["package"]))
            bad += 1
            continue
        got = meshcheck.check(path)
        if e.get("expected") != got:
            bad += 1
            print("%s %s\n  was: %s\n  now: %s" % ("DIFF    " if check else "UPDATED ", e["path"],
                                                   json.dumps(e.get("expected")), json.dumps(got)))
            e["expected"] = got
    if check:
        print("%d passed, %d failed" % (len(entries) - bad, bad))
        return 1 if bad else 0
    with open(MANIFEST, "w") as fh:
        fh.write(format_manifest(entries))
    return 0


def format_manifest(entries):
    """One entry per line block, expected object on one line: easy to diff."""
    out = ["["]
    for i, e in enumerate(entries):
        fields = ['    %s: %s' % (json.dumps(k), json.dumps(v, separators=(",", ":")) if k == "expected" else json.dumps(v))
                  for k, v in e.items()]
        out.append("  {\n" + ",\n".join(fields) + "\n  }" + ("," if i + 1 < len(entries) else ""))
    out.append("]")
    return "\n".join(out) + "\n"


if __name__ == "__main__":
    sys.exit(main(sys.argv))
