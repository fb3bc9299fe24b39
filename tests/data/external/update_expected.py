#!/usr/bin/env python3
"""Recompute (or check) the "expected" objects of the external-mesh manifests.

    python3 tests/data/external/update_expected.py           # rewrite expected values
    python3 tests/data/external/update_expected.py --check   # exit 1 on any difference

Manifests: meshes.json (files: "path" is repo-relative, or absolute for a file
a Debian package installs) and meshes-cgal.json (members of a tarball that a
Debian package installs: "archive" + "member"). Each entry's expected value
is exactly what `python3 tools/meshcheck.py FILE` prints for that file.
With --check, a missing file counts as a failure.
"""
import json
import os
import sys
import tarfile
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import meshcheck  # noqa: E402

MANIFESTS = ["meshes.json", "meshes-cgal.json"]


def resolve(entry, tmp):
    """Local file for an entry, or None when it is not there."""
    if "archive" in entry:
        archive = entry["archive"]
        if not os.path.exists(archive):
            return None
        out = os.path.join(tmp, entry["member"])
        if not os.path.exists(out):
            with tarfile.open(archive) as tf:
                try:
                    member = tf.getmember(entry["member"])
                except KeyError:
                    return None
                src = tf.extractfile(member)
                os.makedirs(os.path.dirname(out), exist_ok=True)
                with open(out, "wb") as fh:
                    fh.write(src.read())
        return out
    path = entry["path"]
    path = path if os.path.isabs(path) else os.path.join(ROOT, path)
    return path if os.path.exists(path) else None


def label(entry):
    return entry["archive"] + ":" + entry["member"] if "archive" in entry else entry["path"]


def main(argv):
    check = "--check" in argv[1:]
    total = bad = 0
    with tempfile.TemporaryDirectory() as tmp:
        for name in MANIFESTS:
            manifest = os.path.join(HERE, name)
            with open(manifest) as fh:
                entries = json.load(fh)
            for e in entries:
                total += 1
                path = resolve(e, tmp)
                if path is None:
                    print("MISSING  %s (package %s)" % (label(e), e["package"]))
                    bad += 1
                    continue
                got = meshcheck.check(path)
                if e.get("expected") != got:
                    bad += 1
                    print("%s %s\n  was: %s\n  now: %s" % ("DIFF    " if check else "UPDATED ", label(e),
                                                           json.dumps(e.get("expected")), json.dumps(got)))
                    e["expected"] = got
            if not check:
                with open(manifest, "w") as fh:
                    fh.write(format_manifest(entries))
    if check:
        print("%d passed, %d failed" % (total - bad, bad))
        return 1 if bad else 0
    return 0


def format_manifest(entries):
    """One block per entry, the expected object on one line: easy to diff."""
    out = ["["]
    for i, e in enumerate(entries):
        fields = ['    %s: %s' % (json.dumps(k), json.dumps(v, separators=(",", ":")) if k == "expected" else json.dumps(v))
                  for k, v in e.items()]
        out.append("  {\n" + ",\n".join(fields) + "\n  }" + ("," if i + 1 < len(entries) else ""))
    out.append("]")
    return "\n".join(out) + "\n"


if __name__ == "__main__":
    sys.exit(main(sys.argv))
