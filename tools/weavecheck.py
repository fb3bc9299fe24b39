#!/usr/bin/env python3
"""Independent checker of a woven job's manifest (Python 3 standard library only).

    python3 tools/weavecheck.py OUT_DIR_OR_MANIFEST [--allow-glue] [--json]

Reads the `manifest.json` that `rotafab make --structure weave` writes
(docs/CONTRACT.md, "manifest.json (version 1)") and checks, from what it
says alone and without any of Rotafab's code, what the builders of a
plain-woven structure (the dissertation, ch. IV) rely on:

  labels     every edge number k is etched `up` once, on panel k (or a piece
             of it), and `down` twice (IV.4; panel k itself may be one of
             the two, where a single thread goes round a leaf face of its
             tree and under, then over, one edge); every panel has one
             underlined neighbour number (`neighbor`), naming one of its
             neighbours (IV.4, Figure 42).
  holes      each crossing (edge) has its holes on the three panels that meet
             there: 3 or 6 in all, as many on each panel (two of the three
             may be one panel, with twice as many); none is missing unless
             --allow-glue (a crossing with no holes is glued); every hole is
             inside its part's outline, its centre at least a diameter from
             it.
  aligned    where a crossing has two holes on each of its panels, they are
             the same two points of the surface on each: unfolding keeps
             lengths, so the two holes are as far apart on every panel, within
             1% (and 0.01 in). A panel and the pieces cut off it share one
             frame; a panel that is two of the three holds two pairs.
  outlines   every part's outline is a simple polygon (no two of its sides
             cross), and no two parts on a sheet overlap once placed
             (`placement`: turn about the origin, then move).

Prints one line per problem (the first 20 of each kind, then a count) and a
summary line; exits 1 when there is a problem, 2 when the manifest cannot
be read. --json prints {"panels", "crossings", "glued", "problems": {kind:
count}} instead of the summary.
--selftest checks the checker on small hand-made manifests.
"""

import json
import math
import os
import sys
from collections import defaultdict

TOLERANCE = 2e-4  # the outline as written is within 0.0002 in of the planned one


def parts_of(panel):
    """The panel and the pieces cut off it, each with its outline, holes and labels."""
    parts = [(str(panel["id"]), panel)]
    for piece in panel.get("pieces", []):
        parts.append((str(piece.get("name", "%s piece" % panel["id"])), piece))
    return parts


def distance_to_segment(px, py, ax, ay, bx, by):
    dx, dy = bx - ax, by - ay
    length2 = dx * dx + dy * dy
    t = 0.0 if length2 == 0 else max(0.0, min(1.0, ((px - ax) * dx + (py - ay) * dy) / length2))
    return math.hypot(px - (ax + t * dx), py - (ay + t * dy))


def distance_to_outline(outline, x, y):
    n = len(outline)
    return min(distance_to_segment(x, y, *outline[i], *outline[(i + 1) % n]) for i in range(n))


def inside(outline, x, y):
    crossings = 0
    n = len(outline)
    for i in range(n):
        (ax, ay), (bx, by) = outline[i], outline[(i + 1) % n]
        if (ay > y) != (by > y) and x < ax + (y - ay) * (bx - ax) / (by - ay):
            crossings += 1
    return crossings % 2 == 1


def orientation(ax, ay, bx, by, cx, cy):
    v = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
    return 0 if abs(v) < 1e-12 else (1 if v > 0 else -1)


def segments_cross(a, b, c, d):
    """Whether segments ab and cd cross properly (touching at an end is not crossing)."""
    o1 = orientation(*a, *b, *c)
    o2 = orientation(*a, *b, *d)
    o3 = orientation(*c, *d, *a)
    o4 = orientation(*c, *d, *b)
    return o1 * o2 < 0 and o3 * o4 < 0


def bucketed_segments(polygons, cell):
    """Segments of each polygon (index, i) bucketed on a grid of `cell`."""
    grid = defaultdict(list)
    for p, outline in enumerate(polygons):
        n = len(outline)
        for i in range(n):
            (ax, ay), (bx, by) = outline[i], outline[(i + 1) % n]
            for gx in range(int(math.floor(min(ax, bx) / cell)), int(math.floor(max(ax, bx) / cell)) + 1):
                for gy in range(int(math.floor(min(ay, by) / cell)), int(math.floor(max(ay, by) / cell)) + 1):
                    grid[(gx, gy)].append((p, i))
    return grid


def crossing_pairs(polygons, cell=0.5):
    """Pairs of sides that cross: ((p, i), (q, j)), each pair once."""
    grid = bucketed_segments(polygons, cell)
    seen = set()
    for members in grid.values():
        for a in range(len(members)):
            for b in range(a + 1, len(members)):
                (p, i), (q, j) = members[a], members[b]
                key = (min(members[a], members[b]), max(members[a], members[b]))
                if key in seen:
                    continue
                seen.add(key)
                if p == q:
                    n = len(polygons[p])
                    if abs(i - j) in (0, 1, n - 1):
                        continue  # neighbouring sides share a corner
                pi, qj = polygons[p], polygons[q]
                if segments_cross(pi[i], pi[(i + 1) % len(pi)], qj[j], qj[(j + 1) % len(qj)]):
                    yield key


def crossing_spans(on, panel_of_part):
    """How far apart a crossing's two holes are on each of its panels, [(span, panel)]: a panel (with the
    pieces cut off it, in its frame) holds a pair, or two pairs where it is two of the three panels, paired
    as the other panel's pair says. Empty when no panel holds a single pair to go by."""
    per_panel = defaultdict(list)
    for name, hs in on.items():
        per_panel[panel_of_part[name]] += hs
    span = lambda p, q: math.hypot(p[0] - q[0], p[1] - q[1])
    pairs = {pid: span(*hs) for pid, hs in per_panel.items() if len(hs) == 2}
    if not pairs:
        return []
    reference = next(iter(pairs.values()))
    spans = [(d, pid) for pid, d in pairs.items()]
    for pid, hs in per_panel.items():
        if len(hs) == 4:
            pairing = min(([(0, 1), (2, 3)], [(0, 2), (1, 3)], [(0, 3), (1, 2)]),
                          key=lambda ps: sum(abs(span(hs[i], hs[j]) - reference) for i, j in ps))
            spans += [(span(hs[i], hs[j]), pid) for i, j in pairing]
    return spans


def interior_point(outline):
    """A point strictly inside a simple polygon: the middle of the widest run inside it along a line across
    the middle of its box."""
    x0, y0, x1, y1 = box(outline)
    for fraction in (0.5, 0.37, 0.63, 0.21, 0.79):
        y = y0 + fraction * (y1 - y0)
        xs = []
        n = len(outline)
        for i in range(n):
            (ax, ay), (bx, by) = outline[i], outline[(i + 1) % n]
            if (ay > y) != (by > y):
                xs.append(ax + (y - ay) * (bx - ax) / (by - ay))
        xs.sort()
        runs = [(xs[k + 1] - xs[k], (xs[k] + xs[k + 1]) / 2) for k in range(0, len(xs) - 1, 2)]
        if runs:
            return max(runs)[1], y
    return outline[0]


def placed(outline, placement):
    turn = math.radians(placement.get("rotation", 0.0))
    c, s = math.cos(turn), math.sin(turn)
    x0, y0 = placement.get("x", 0.0), placement.get("y", 0.0)
    return [(c * x - s * y + x0, s * x + c * y + y0) for x, y in outline]


def box(outline):
    xs = [p[0] for p in outline]
    ys = [p[1] for p in outline]
    return min(xs), min(ys), max(xs), max(ys)


class Report:
    def __init__(self):
        self.problems = defaultdict(list)

    def add(self, kind, text):
        self.problems[kind].append(text)

    def count(self):
        return sum(len(v) for v in self.problems.values())


def check(manifest, allow_glue=False):
    report = Report()
    panels = manifest["panels"]
    n = len(panels)
    ids = {p["id"] for p in panels}
    up, down = defaultdict(list), defaultdict(list)
    holes = defaultdict(lambda: defaultdict(list))  # edge -> part name -> [(x, y, diameter)]
    panel_of_part = {}
    for panel in panels:
        pid = panel["id"]
        neighbours = []
        for name, part in parts_of(panel):
            panel_of_part[name] = pid
            outline = [tuple(p) for p in part["outline"]]
            for label in part.get("labels", []):
                role, edge = label.get("role"), label.get("edge")
                if role == "up":
                    up[edge].append(pid)
                elif role == "down":
                    down[edge].append(pid)
                elif role == "neighbor":
                    neighbours.append(edge)
            for hole in part.get("holes", []):
                x, y = hole["xy"]
                d = hole["diameter"]
                if not inside(outline, x, y):
                    report.add("holes", "part %s: the hole of edge %s at (%.4f, %.4f) is outside its outline"
                               % (name, hole["edge"], x, y))
                elif distance_to_outline(outline, x, y) < d - TOLERANCE:
                    report.add("holes", "part %s: the hole of edge %s is %.4f in from its outline, less than its "
                               "diameter %.4f" % (name, hole["edge"], distance_to_outline(outline, x, y), d))
                if hole["edge"] != 0:
                    holes[hole["edge"]][name].append((x, y, d))
        if len(neighbours) != 1:
            report.add("labels", "panel %d: %d underlined neighbour numbers, want 1" % (pid, len(neighbours)))
        elif neighbours[0] not in panel.get("neighbors", []):
            report.add("labels", "panel %d: its underlined number %s is not one of its neighbours %s"
                       % (pid, neighbours[0], panel.get("neighbors")))
    if sorted(ids) != list(range(1, n + 1)):
        report.add("labels", "the panels are not numbered 1 to %d" % n)
    glued = 0
    for edge in range(1, n + 1):
        if up[edge] != [edge]:
            report.add("labels", "edge %d: `up` on panels %s, want on panel %d alone" % (edge, up[edge], edge))
        if len(down[edge]) != 2:
            report.add("labels", "edge %d: `down` on panels %s, want two" % (edge, down[edge]))
        on = holes.get(edge, {})
        total = sum(len(v) for v in on.values())
        if total == 0:
            glued += 1
            if not allow_glue:
                report.add("holes", "edge %d: its crossing has no holes (glued)" % edge)
            continue
        per_panel = defaultdict(int)
        for name, hs in on.items():
            per_panel[panel_of_part[name]] += len(hs)
        counts = sorted(per_panel.values())
        even = (len(counts) == 3 and counts[0] == counts[2]) or (len(counts) == 2 and counts[1] == 2 * counts[0])
        if total not in (3, 6) or not even:
            report.add("holes", "edge %d: holes per panel %s, want as many on each of three panels (3 or 6 in all)"
                       % (edge, dict(per_panel)))
        if total == 6:
            spans = crossing_spans(on, panel_of_part)
            if spans:
                longest = max(s for s, _ in spans)
                shortest = min(s for s, _ in spans)
                if longest - shortest > max(0.01, 0.01 * longest):
                    report.add("aligned", "edge %d: its two holes are %s apart on its panels, not the same points"
                               % (edge, ", ".join("%.4f in on panel %s" % s for s in sorted(spans))))
    # Outlines: simple, and apart on their sheet.
    by_sheet = defaultdict(list)
    for panel in panels:
        for name, part in parts_of(panel):
            outline = [tuple(p) for p in part["outline"]]
            for (p, i), (q, j) in crossing_pairs([outline]):
                report.add("outlines", "part %s: its outline crosses itself (sides %d and %d)" % (name, i, j))
                break
            sheet = part.get("sheet", panel.get("sheet"))
            by_sheet[sheet].append((name, placed(outline, part.get("placement", {}))))
    for sheet, placed_parts in sorted(by_sheet.items(), key=lambda kv: str(kv[0])):
        outlines = [o for _, o in placed_parts]
        reported = set()
        for (p, i), (q, j) in crossing_pairs(outlines):
            if p != q and (p, q) not in reported:
                reported.add((p, q))
                report.add("outlines", "sheet %s: parts %s and %s overlap" % (sheet, placed_parts[p][0],
                                                                             placed_parts[q][0]))
        # One part wholly inside another crosses no side: test a corner.
        boxes = [box(o) for o in outlines]
        interiors = [interior_point(o) for o in outlines]
        order = sorted(range(len(outlines)), key=lambda k: boxes[k][0])
        for a_index, a in enumerate(order):
            for b in order[a_index + 1:]:
                if boxes[b][0] > boxes[a][2]:
                    break
                if (a, b) in reported or (b, a) in reported:
                    continue
                if boxes[b][1] > boxes[a][3] or boxes[a][1] > boxes[b][3]:
                    continue
                if inside(outlines[a], *interiors[b]) or inside(outlines[b], *interiors[a]):
                    reported.add((a, b))
                    report.add("outlines", "sheet %s: parts %s and %s overlap" % (sheet, placed_parts[a][0],
                                                                                 placed_parts[b][0]))
    return report, n, glued


def selftest():
    def square(x, y, s):
        return [[x, y], [x + s, y], [x + s, y + s], [x, y + s]]

    def panel(pid, neighbour, ups, downs, holes, outline=None, placement=None):
        labels = [{"role": "up", "edge": e} for e in ups] + [{"role": "down", "edge": e} for e in downs]
        labels.append({"role": "neighbor", "edge": neighbour})
        return {"id": pid, "sheet": 1, "outline": outline or square(0, 0, 2), "labels": labels,
                "neighbors": [1, 2, 3], "placement": placement or {"x": 3 * pid, "y": 0, "rotation": 0},
                "holes": [{"edge": e, "xy": xy, "diameter": 0.125} for e, xy in holes]}

    def woven(glue=False, misaligned=False, overlap=False, twisted=False, near=False):
        h = [(0.5, 1.0), (1.5, 1.0)]
        far = (1.0, 1.3) if misaligned else (1.5, 1.0)
        panels = []
        for pid in (1, 2, 3):
            holes = []
            for e in (1, 2, 3):
                if glue and e == 3:
                    continue
                second = far if (misaligned and pid == 2 and e == 1) else h[1]
                first = (0.05, 1.0) if (near and pid == 1 and e == 1) else h[0]
                holes += [(e, first), (e, second)]
            others = [e for e in (1, 2, 3) if e != pid]
            outline = [[0, 0], [2, 2], [2, 0], [0, 2]] if (twisted and pid == 3) else None
            placement = {"x": 1, "y": 0.5, "rotation": 0} if (overlap and pid == 2) else None
            panels.append(panel(pid, others[0], [pid], others, holes, outline, placement))
        if overlap:
            panels[0]["placement"] = {"x": 0, "y": 0, "rotation": 0}
        return {"structure": "weave", "panels": panels}

    cases = [
        ("a good weave", woven(), {}),
        ("a glued crossing", woven(glue=True), {"holes": 1}),
        ("holes not aligned", woven(misaligned=True), {"aligned": 1}),
        ("two panels overlapping", woven(overlap=True), {"outlines": 1}),
        ("an outline crossing itself", woven(twisted=True), {"outlines": 1}),
        ("a hole near its outline", woven(near=True), {"holes": 1, "aligned": 1}),
    ]
    turned = woven()
    # Panel 2 turned a quarter about its origin: [0, 2] x [0, 2] goes to [-2, 0] x [0, 2], then moved by 4: onto panel 1.
    turned["panels"][1]["placement"] = {"x": 4.5, "y": 0, "rotation": 90}
    cases.append(("a turned panel overlapping another", turned, {"outlines": 1}))
    nested = woven()
    nested["panels"][1]["outline"] = square(0.5, 0.5, 1)
    nested["panels"][1]["holes"] = [{"edge": e, "xy": xy, "diameter": 0.05} for e, xy in
                                    [(1, (0.75, 1.0)), (1, (1.25, 1.0)), (2, (0.75, 1.2)), (2, (1.25, 1.2)),
                                     (3, (0.75, 0.8)), (3, (1.25, 0.8))]]
    nested["panels"][1]["placement"] = {"x": 3, "y": 0, "rotation": 0}
    cases.append(("a panel wholly inside another", nested, {"outlines": 1, "aligned": 3}))
    bad_labels = woven()
    bad_labels["panels"][0]["labels"] = [l for l in bad_labels["panels"][0]["labels"] if l["role"] != "up"]
    cases.append(("an up number missing", bad_labels, {"labels": 1}))
    failed = 0
    for name, manifest, want in cases:
        report, _, _ = check(manifest)
        got = {k: len(v) for k, v in report.problems.items() if v}
        if got != want:
            failed += 1
            print("FAIL %s: want %s, got %s" % (name, want, dict(report.problems)))
    print("%d passed, %d failed" % (len(cases) - failed, failed))
    return 1 if failed else 0


def main(argv):
    if "--selftest" in argv:
        return selftest()
    args = [a for a in argv if not a.startswith("--")]
    unknown = [a for a in argv if a.startswith("--") and a not in ("--allow-glue", "--json")]
    if len(args) != 1 or unknown:
        print("usage: weavecheck.py OUT_DIR_OR_MANIFEST [--allow-glue] [--json] | --selftest", file=sys.stderr)
        return 2
    path = args[0]
    if os.path.isdir(path):
        path = os.path.join(path, "manifest.json")
    try:
        with open(path) as f:
            manifest = json.load(f)
        if manifest.get("structure") != "weave":
            raise ValueError("its structure is %r, not \"weave\"" % manifest.get("structure"))
        report, panels, glued = check(manifest, allow_glue="--allow-glue" in argv)
    except (OSError, ValueError, KeyError, TypeError, IndexError, AttributeError) as e:
        print("weavecheck: %s: cannot read the manifest: %s" % (path, e), file=sys.stderr)
        return 2
    if "--json" in argv:
        print(json.dumps({"panels": panels, "crossings": panels, "glued": glued,
                          "problems": {k: len(v) for k, v in report.problems.items()}}))
    else:
        for kind, lines in report.problems.items():
            for line in lines[:20]:
                print("%s: %s" % (kind, line))
            if len(lines) > 20:
                print("%s: ... and %d more" % (kind, len(lines) - 20))
        print("%s: %d panels, %d crossings glued, %d problems" % (path, panels, glued, report.count()))
    return 1 if report.count() else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
