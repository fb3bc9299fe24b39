#!/usr/bin/env python3
"""Independent mesh checker for Rotafab (Python 3 standard library only).

    python3 tools/meshcheck.py MESH [--details]

Reads OBJ (v/f, `f a/b/c` forms, negative indices, groups ignored), OFF
(OFF/COFF/NOFF/CNOFF/STOFF... or no keyword at all, '#' comments anywhere,
extra per-vertex and per-face values ignored; not 4OFF or binary OFF), PLY
(ascii, binary little/big endian; `vertex` x/y/z and the `face`
`vertex_indices`/`vertex_index` list, other elements skipped) and STL (ascii,
and binary even when its header starts with "solid"), cleans the mesh the way
docs/CONTRACT.md ("inspect") says `rotafab inspect` does, and prints the
`inspect --json` object:

    {"vertices":V,"edges":E,"faces":F,"boundary_loops":B,"components":C,
     "euler":X,"genus":G,"orientable":bool,"manifold":bool}

Cleaning (in this order):
  1. every coordinate is rounded to a 32-bit float (the C++ side reads through
     Assimp, which stores floats);
  2. vertices at identical positions (exact equality of the rounded
     coordinates) are welded;
  3. in every face, consecutive repeated vertices (cyclically) are collapsed;
     a face left with fewer than 3 distinct vertices is dropped;
  4. vertices no face references are dropped.

Definitions:
  edges           undirected vertex pairs that are consecutive in some face.
  boundary edge   an edge used by exactly one face side.
  boundary_loops  boundary edges are linked when they meet at a vertex within
                  the same fan of face corners around that vertex (corners at a
                  vertex are in one fan when joined by edges at that vertex that
                  are used more than once); loops = connected groups of linked
                  boundary edges. On a manifold mesh this is the ordinary
                  number of boundary cycles; a bow-tie vertex (two fans) splits
                  loops, as a half-edge walk around the boundary would.
  components      connected components of the vertex/edge graph (two pieces
                  touching at a single vertex are one component).
  euler           V - E + F of the cleaned mesh (no capping).
  manifold        every edge used by 1 or 2 face sides, and the face corners
                  at every vertex form a single fan (joined through the edges at
                  that vertex used by 2 face sides). Corners, not faces: a face
                  that visits a vertex twice (a keyhole polygon whose bridge edge
                  is used twice by that face) is judged by its real topology.
  orientable      face orientations can be chosen so that every edge used by
                  exactly 2 face sides is traversed in opposite directions
                  (breadth-first over those edges); the file's own orientation
                  may be inconsistent.
  genus           sum over components of (2 - chi)/2 where chi = V - E + F + B
                  of the component (each boundary loop capped by one face);
                  null unless the mesh is an orientable manifold.

--details prints more facts (consistent orientation as stored, counts of
non-manifold edges/vertices, what cleaning removed) to stderr.
--selftest checks the checker on small hand-made meshes (tetrahedron, quad
cube, open square, Moebius strips, tori, keyhole polygon, bow-ties, an edge
of three faces) and on one solid written in every format; it prints
"N passed, N failed" and exits 1 on a failure.
"""

import json
import os
import struct
import sys
from collections import defaultdict, deque


class MeshError(Exception):
    pass


def f32(x):
    """Round a Python float to the nearest 32-bit float."""
    try:
        return struct.unpack("<f", struct.pack("<f", x))[0]
    except OverflowError:
        raise MeshError("coordinate %r does not fit a 32-bit float" % (x,))


def parse_number(tok, what):
    try:
        return float(tok)
    except ValueError:
        raise MeshError("%s: not a number: %r" % (what, tok))


def parse_int(tok, what):
    try:
        return int(tok)
    except ValueError:
        try:
            v = float(tok)
        except ValueError:
            raise MeshError("%s: not an integer: %r" % (what, tok))
        if v != int(v):
            raise MeshError("%s: not an integer: %r" % (what, tok))
        return int(v)


def decode_text(data):
    """Text of a file, honouring a UTF-8/UTF-16 byte-order mark."""
    if data.startswith(b"\xef\xbb\xbf"):
        return data[3:].decode("utf-8", errors="replace")
    if data.startswith(b"\xff\xfe") or data.startswith(b"\xfe\xff"):
        return data.decode("utf-16", errors="replace")
    return data.decode("utf-8", errors="replace")


# --------------------------------------------------------------------- OBJ

def read_obj(data):
    text = decode_text(data)
    # join continuation lines ("\" at end of line)
    text = text.replace("\\\r\n", " ").replace("\\\n", " ")
    verts = []
    faces = []
    for lineno, line in enumerate(text.splitlines(), 1):
        hash_at = line.find("#")
        if hash_at >= 0:
            line = line[:hash_at]
        toks = line.split()
        if not toks:
            continue
        where = "line %d" % lineno
        if toks[0] == "v":
            if len(toks) < 4:
                raise MeshError("%s: vertex needs 3 coordinates" % where)
            verts.append(tuple(parse_number(t, where) for t in toks[1:4]))
        elif toks[0] == "f":
            if len(toks) < 4:
                # Assimp reads 1- and 2-vertex faces as points/lines; they
                # have fewer than 3 distinct vertices and are dropped anyway.
                continue
            face = []
            for t in toks[1:]:
                s = t.split("/")[0]
                i = parse_int(s, where)
                if i > 0:
                    i -= 1
                elif i < 0:
                    i = len(verts) + i
                else:
                    raise MeshError("%s: face index 0" % where)
                if not 0 <= i < len(verts):
                    raise MeshError("%s: face index %s out of range" % (where, s))
                face.append(i)
            faces.append(face)
    return verts, faces


# --------------------------------------------------------------------- OFF

def read_off(data):
    text = decode_text(data)
    lines = []
    for lineno, line in enumerate(text.splitlines(), 1):
        hash_at = line.find("#")
        if hash_at >= 0:
            line = line[:hash_at]
        toks = line.split()
        if toks:
            lines.append((lineno, toks))
    if not lines:
        raise MeshError("empty OFF file")
    pos = 0
    lineno, toks = lines[pos]
    head = toks[0]
    if head.endswith("OFF"):
        prefix = head[:-3]
        rest = toks[1:]
    else:
        # the OFF keyword is optional (geomview): the counts come first
        try:
            int(head)
        except ValueError:
            raise MeshError("line %d: OFF header expected, got %r" % (lineno, head))
        prefix = ""
        rest = toks
    dim = 3
    if "4" in prefix:
        raise MeshError("4OFF (homogeneous coordinates) not supported")
    if rest and rest[0].upper() == "BINARY":
        raise MeshError("binary OFF not supported")
    if prefix.endswith("n"):
        # nOFF: dimension given next
        if not rest:
            pos += 1
            rest = lines[pos][1]
        dim = parse_int(rest[0], "OFF dimension")
        rest = rest[1:]
    if not rest:
        pos += 1
        if pos >= len(lines):
            raise MeshError("OFF: missing counts line")
        lineno, rest = lines[pos]
    if len(rest) < 2:
        raise MeshError("line %d: OFF counts line needs vertex and face counts" % lineno)
    nv = parse_int(rest[0], "line %d" % lineno)
    nf = parse_int(rest[1], "line %d" % lineno)
    pos += 1
    verts = []
    for k in range(nv):
        if pos >= len(lines):
            raise MeshError("OFF: file ends after %d of %d vertices" % (k, nv))
        lineno, t = lines[pos]
        pos += 1
        if len(t) < min(dim, 3):
            raise MeshError("line %d: vertex needs %d coordinates" % (lineno, dim))
        c = [parse_number(x, "line %d" % lineno) for x in t[:min(dim, 3)]]
        while len(c) < 3:
            c.append(0.0)
        verts.append(tuple(c))
    faces = []
    for k in range(nf):
        if pos >= len(lines):
            raise MeshError("OFF: file ends after %d of %d faces" % (k, nf))
        lineno, t = lines[pos]
        pos += 1
        n = parse_int(t[0], "line %d" % lineno)
        if len(t) < n + 1:
            raise MeshError("line %d: face needs %d indices" % (lineno, n))
        face = []
        for x in t[1:n + 1]:
            i = parse_int(x, "line %d" % lineno)
            if not 0 <= i < nv:
                raise MeshError("line %d: face index %d out of range" % (lineno, i))
            face.append(i)
        # anything after the indices (colour) is ignored
        faces.append(face)
    return verts, faces


# --------------------------------------------------------------------- PLY

PLY_TYPES = {
    "char": "b", "int8": "b", "uchar": "B", "uint8": "B",
    "short": "h", "int16": "h", "ushort": "H", "uint16": "H",
    "int": "i", "int32": "i", "uint": "I", "uint32": "I",
    "float": "f", "float32": "f", "double": "d", "float64": "d",
}


def read_ply(data):
    end_marker = b"end_header"
    idx = data.find(end_marker)
    if idx < 0:
        raise MeshError("PLY: no end_header")
    nl = data.find(b"\n", idx)
    if nl < 0:
        nl = len(data) - 1
    header = data[:idx].decode("ascii", errors="replace").splitlines()
    body = data[nl + 1:]
    if not header or header[0].strip() != "ply":
        raise MeshError("PLY: missing 'ply' magic")
    fmt = None
    elements = []  # (name, count, [props]) ; prop = (name, type) or (name, 'list', ctype, itype)
    for line in header[1:]:
        t = line.split()
        if not t or t[0] in ("comment", "obj_info"):
            continue
        if t[0] == "format":
            fmt = t[1]
        elif t[0] == "element":
            elements.append((t[1], int(t[2]), []))
        elif t[0] == "property":
            if not elements:
                raise MeshError("PLY: property before element")
            if t[1] == "list":
                elements[-1][2].append((t[4], "list", t[2], t[3]))
            else:
                elements[-1][2].append((t[2], t[1]))
    if fmt not in ("ascii", "binary_little_endian", "binary_big_endian"):
        raise MeshError("PLY: unknown format %r" % fmt)
    for _, _, props in elements:
        for p in props:
            for ty in ([p[1]] if p[1] != "list" else [p[2], p[3]]):
                if ty not in PLY_TYPES:
                    raise MeshError("PLY: unknown type %r" % ty)

    verts = []
    faces = []

    if fmt == "ascii":
        toks = body.decode("ascii", errors="replace").split()
        pos = 0

        def take():
            nonlocal pos
            if pos >= len(toks):
                raise MeshError("PLY: file ends early")
            pos += 1
            return toks[pos - 1]

        for name, count, props in elements:
            for _ in range(count):
                rec = {}
                for p in props:
                    if p[1] == "list":
                        n = parse_int(take(), "PLY list count")
                        rec[p[0]] = [take() for _ in range(n)]
                    else:
                        rec[p[0]] = take()
                _store_ply(name, rec, verts, faces)
    else:
        end = "<" if fmt == "binary_little_endian" else ">"
        pos = 0
        for name, count, props in elements:
            # fast path: all scalar properties -> one struct per record
            if all(p[1] != "list" for p in props):
                st = struct.Struct(end + "".join(PLY_TYPES[p[1]] for p in props))
                names = [p[0] for p in props]
                if pos + st.size * count > len(body):
                    raise MeshError("PLY: file ends early in element %s" % name)
                for vals in st.iter_unpack(body[pos:pos + st.size * count]):
                    _store_ply(name, dict(zip(names, vals)), verts, faces)
                pos += st.size * count
                continue
            for _ in range(count):
                rec = {}
                for p in props:
                    if p[1] == "list":
                        cs = struct.Struct(end + PLY_TYPES[p[2]])
                        if pos + cs.size > len(body):
                            raise MeshError("PLY: file ends early in element %s" % name)
                        (n,) = cs.unpack_from(body, pos)
                        pos += cs.size
                        isz = struct.calcsize(PLY_TYPES[p[3]])
                        if pos + isz * n > len(body):
                            raise MeshError("PLY: file ends early in element %s" % name)
                        rec[p[0]] = list(struct.unpack_from(end + PLY_TYPES[p[3]] * n, body, pos))
                        pos += isz * n
                    else:
                        s = struct.Struct(end + PLY_TYPES[p[1]])
                        if pos + s.size > len(body):
                            raise MeshError("PLY: file ends early in element %s" % name)
                        (rec[p[0]],) = s.unpack_from(body, pos)
                        pos += s.size
                _store_ply(name, rec, verts, faces)

    nv = len(verts)
    for face in faces:
        for i in face:
            if not 0 <= i < nv:
                raise MeshError("PLY: face index %d out of range" % i)
    return verts, faces


def _store_ply(name, rec, verts, faces):
    if name == "vertex":
        try:
            verts.append((float(rec["x"]), float(rec["y"]), float(rec["z"])))
        except KeyError:
            raise MeshError("PLY: vertex without x, y, z")
        except ValueError as e:
            raise MeshError("PLY: bad vertex coordinate: %s" % e)
    elif name == "face":
        lst = rec.get("vertex_indices", rec.get("vertex_index"))
        if lst is None:
            raise MeshError("PLY: face without vertex_indices/vertex_index")
        faces.append([parse_int(x, "PLY face") if isinstance(x, str) else int(x) for x in lst])


# --------------------------------------------------------------------- STL

def read_stl(data):
    if len(data) >= 84:
        (n,) = struct.unpack_from("<I", data, 80)
        if len(data) == 84 + 50 * n or not data.lstrip()[:5].lower() == b"solid":
            return _read_stl_binary(data, n)
    return _read_stl_ascii(data)


def _read_stl_binary(data, n):
    if len(data) < 84 + 50 * n:
        raise MeshError("binary STL: %d triangles announced, file too short" % n)
    verts = []
    faces = []
    st = struct.Struct("<12fH")
    for k in range(n):
        vals = st.unpack_from(data, 84 + 50 * k)
        base = len(verts)
        verts.append(vals[3:6])
        verts.append(vals[6:9])
        verts.append(vals[9:12])
        faces.append([base, base + 1, base + 2])
    return verts, faces


def _read_stl_ascii(data):
    toks = data.decode("ascii", errors="replace").split()
    verts = []
    faces = []
    cur = None
    i = 0
    while i < len(toks):
        t = toks[i].lower()
        if t == "facet":
            cur = []
        elif t == "vertex":
            if i + 3 >= len(toks):
                raise MeshError("ASCII STL: vertex needs 3 coordinates")
            if cur is None:
                raise MeshError("ASCII STL: vertex outside facet")
            cur.append(len(verts))
            verts.append(tuple(parse_number(x, "ASCII STL vertex") for x in toks[i + 1:i + 4]))
            i += 3
        elif t == "endfacet":
            if cur is None:
                raise MeshError("ASCII STL: endfacet without facet")
            faces.append(cur)
            cur = None
        i += 1
    return verts, faces


# --------------------------------------------------------------------- clean

def clean(verts, faces, info):
    key_to_new = {}
    remap = []
    pos = []
    for v in verts:
        k = (f32(v[0]), f32(v[1]), f32(v[2]))
        j = key_to_new.get(k)
        if j is None:
            j = len(pos)
            key_to_new[k] = j
            pos.append(k)
        remap.append(j)
    info["input_vertices"] = len(verts)
    info["input_faces"] = len(faces)
    info["welded_away"] = len(verts) - len(pos)
    out = []
    dropped = 0
    collapsed = 0
    for face in faces:
        f = [remap[i] for i in face]
        g = []
        for i in f:
            if not g or g[-1] != i:
                g.append(i)
        while len(g) > 1 and g[-1] == g[0]:
            g.pop()
        if len(g) != len(f):
            collapsed += 1
        if len(set(g)) < 3:
            dropped += 1
            continue
        out.append(g)
    info["faces_collapsed"] = collapsed
    info["faces_dropped"] = dropped
    used = sorted({i for f in out for i in f})
    renum = {old: new for new, old in enumerate(used)}
    info["unreferenced_dropped"] = len(pos) - len(used)
    faces2 = [[renum[i] for i in f] for f in out]
    return len(used), faces2


# --------------------------------------------------------------------- analysis

class DSU:
    def __init__(self, n):
        self.p = list(range(n))

    def find(self, x):
        p = self.p
        while p[x] != x:
            p[x] = p[p[x]]
            x = p[x]
        return x

    def union(self, a, b):
        a = self.find(a)
        b = self.find(b)
        if a != b:
            self.p[a] = b


def analyse(nv, faces, info):
    nf = len(faces)
    # Face sides of every undirected edge. Side k of face fi runs from corner
    # (fi, k) to corner (fi, k+1); direction +1 when it goes u->v with u<v.
    edge_sides = defaultdict(list)  # (u, v) -> [(fi, k, direction)]
    corner_id = {}  # (fi, k) -> corner number
    corner_vertex = []
    for fi, f in enumerate(faces):
        n = len(f)
        for k in range(n):
            corner_id[(fi, k)] = len(corner_vertex)
            corner_vertex.append(f[k])
            a, b = f[k], f[(k + 1) % n]
            if a < b:
                edge_sides[(a, b)].append((fi, k, 1))
            else:
                edge_sides[(b, a)].append((fi, k, -1))
    ne = len(edge_sides)

    def side_corners(fi, k):
        """Corners of a face side at its two ends: (corner at f[k], corner at f[k+1])."""
        n = len(faces[fi])
        return corner_id[(fi, k)], corner_id[(fi, (k + 1) % n)]

    def corner_at(fi, k, v):
        c0, c1 = side_corners(fi, k)
        return c0 if corner_vertex[c0] == v else c1

    bad_edges = sum(1 for s in edge_sides.values() if len(s) > 2)
    repeated_vertex_faces = sum(1 for f in faces if len(set(f)) != len(f))

    # Fans: the corners at a vertex, joined where two face sides share an
    # edge. `fan` joins through every edge used more than once (used to link
    # boundary edges into loops); `fan2` only through edges used exactly twice
    # (the manifold test: one fan per vertex).
    nc = len(corner_vertex)
    fan = DSU(nc)
    fan2 = DSU(nc)
    for (a, b), s in edge_sides.items():
        if len(s) < 2:
            continue
        for v in (a, b):
            first = corner_at(s[0][0], s[0][1], v)
            for fi, k, _ in s[1:]:
                fan.union(first, corner_at(fi, k, v))
            if len(s) == 2:
                fan2.union(first, corner_at(s[1][0], s[1][1], v))
    fans_at = defaultdict(set)
    for c in range(nc):
        fans_at[corner_vertex[c]].add(fan2.find(c))
    bad_vertices = sum(1 for v in range(nv) if len(fans_at[v]) > 1)

    # Boundary loops: boundary edges meeting at a vertex within one fan are
    # consecutive on the same loop.
    boundary_edges = [e for e, s in edge_sides.items() if len(s) == 1]
    bidx = {e: k for k, e in enumerate(boundary_edges)}
    bdsu = DSU(len(boundary_edges))
    by_fan = {}
    for e in boundary_edges:
        fi, k, _ = edge_sides[e][0]
        for c in side_corners(fi, k):
            r = fan.find(c)
            if r in by_fan:
                bdsu.union(by_fan[r], bidx[e])
            else:
                by_fan[r] = bidx[e]
    boundary_loops = len({bdsu.find(k) for k in range(len(boundary_edges))})

    manifold = bad_edges == 0 and bad_vertices == 0

    # components of the vertex/edge graph
    vd = DSU(nv)
    for a, b in edge_sides:
        vd.union(a, b)
    comp_of_vertex = [vd.find(v) for v in range(nv)]
    comps = sorted(set(comp_of_vertex))
    components = len(comps)

    # orientability: BFS over faces through edges used by exactly 2 face sides
    adj = defaultdict(list)  # face -> (other face, same_direction?)
    for s in edge_sides.values():
        if len(s) == 2:
            (f1, _, d1), (f2, _, d2) = s
            # consistent when d1 == -d2 for equal orientation signs
            adj[f1].append((f2, d1 == d2))
            if f2 != f1:
                adj[f2].append((f1, d1 == d2))
    sign = [0] * nf
    orientable = True
    consistent = True
    for start in range(nf):
        if sign[start]:
            continue
        sign[start] = 1
        q = deque([start])
        while q:
            f = q.popleft()
            for g, same_dir in adj[f]:
                want = -sign[f] if same_dir else sign[f]
                if same_dir:
                    consistent = False
                if sign[g] == 0:
                    sign[g] = want
                    q.append(g)
                elif sign[g] != want:
                    orientable = False

    # genus per component, each boundary loop capped by one face
    genus = None
    if manifold and orientable:
        cv = defaultdict(int)
        ce = defaultdict(int)
        cf = defaultdict(int)
        cb = defaultdict(int)
        for v in range(nv):
            cv[comp_of_vertex[v]] += 1
        for a, b in edge_sides:
            ce[comp_of_vertex[a]] += 1
        for f in faces:
            cf[comp_of_vertex[f[0]]] += 1
        loop_roots = {}
        for e in boundary_edges:
            r = bdsu.find(bidx[e])
            loop_roots[r] = comp_of_vertex[e[0]]
        for c in loop_roots.values():
            cb[c] += 1
        genus = 0
        for c in comps:
            chi = cv[c] - ce[c] + cf[c] + cb[c]
            if chi % 2:
                raise MeshError("internal: odd capped Euler characteristic %d" % chi)
            genus += (2 - chi) // 2

    info["boundary_edges"] = len(boundary_edges)
    info["nonmanifold_edges"] = bad_edges
    info["nonmanifold_vertices"] = bad_vertices
    info["faces_with_repeated_vertex"] = repeated_vertex_faces
    info["consistently_oriented_as_stored"] = consistent
    sizes = defaultdict(int)
    for f in faces:
        sizes[len(f)] += 1
    info["face_sizes"] = dict(sorted(sizes.items()))

    return {
        "vertices": nv,
        "edges": ne,
        "faces": nf,
        "boundary_loops": boundary_loops,
        "components": components,
        "euler": nv - ne + nf,
        "genus": genus,
        "orientable": orientable,
        "manifold": manifold,
    }


# --------------------------------------------------------------------- self test

def _torus_obj(n, m, dx=0.0, skip=()):
    import math
    lines = []
    for i in range(n):
        for j in range(m):
            u = 2 * math.pi * i / n
            w = 2 * math.pi * j / m
            lines.append("v %r %r %r" % ((2 + math.cos(w)) * math.cos(u) + dx,
                                         (2 + math.cos(w)) * math.sin(u), math.sin(w)))
    for i in range(n):
        for j in range(m):
            if (i, j) in skip:
                continue
            q = (i * m + j, ((i + 1) % n) * m + j, ((i + 1) % n) * m + (j + 1) % m, i * m + (j + 1) % m)
            lines.append("f %d %d %d %d" % tuple(k + 1 for k in q))
    return "\n".join(lines) + "\n"


def _mobius_obj(n=6):
    import math
    lines = []
    for i in range(n):
        t = 2 * math.pi * i / n
        for s in (-0.3, 0.3):
            r = 1 + s * math.cos(t / 2)
            lines.append("v %r %r %r" % (r * math.cos(t), r * math.sin(t), s * math.sin(t / 2)))
    for i in range(n):
        j = (i + 1) % n
        b0, b1 = 2 * j, 2 * j + 1
        if j == 0:
            b0, b1 = b1, b0  # the half twist
        lines.append("f %d %d %d %d" % (2 * i + 1, b0 + 1, b1 + 1, 2 * i + 2))
    return "\n".join(lines) + "\n"


TET = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
SELFTEST = [
    # name, reader, text, expected (V, E, F, B, C, euler, genus, orientable, manifold)
    ("tetrahedron", read_obj, TET + "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n",
     (4, 6, 4, 0, 1, 2, 0, True, True)),
    ("tetrahedron, one face flipped", read_obj, TET + "f 1 2 3\nf 1 2 4\nf 2 3 4\nf 3 1 4\n",
     (4, 6, 4, 0, 1, 2, 0, True, True)),
    ("cube of quads, COFF, comments, colours", read_off,
     "# c\nCOFF\n# counts\n8 6 12\n0 0 0 1 0 0 1\n1 0 0 1 0 0 1\n1 1 0 1 0 0 1\n0 1 0 1 0 0 1\n"
     "0 0 1 1 0 0 1\n1 0 1 1 0 0 1\n1 1 1 1 0 0 1\n0 1 1 1 0 0 1\n4 0 3 2 1 1 0 0\n4 4 5 6 7 # top\n"
     "4 0 1 5 4 255 255 0 255\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n",
     (8, 12, 6, 0, 1, 2, 0, True, True)),
    ("open square, v/vt/vn and negative indices, degenerate faces, unused vertex", read_obj,
     "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1/1/1 2/2/1 3/3/1\nf -4//1 -2//1 -1//1\n"
     "v 5 5 5\nf 1 1 2 2 1\nf 2 2 2\n",
     (4, 5, 2, 1, 1, 1, 0, True, True)),
    ("weld at equal 32-bit floats", read_obj,
     "v 0.1 0 0\nv 0 1 0\nv 0 0 1\nv 0.1000000001 0 0\nv 0 0 -1\nv 0 1.0 0\nf 1 2 3\nf 4 5 6\n",
     (4, 5, 2, 1, 1, 1, 0, True, True)),
    ("Moebius strip", read_obj, _mobius_obj(), (12, 18, 6, 1, 1, 0, None, False, True)),
    ("Moebius band from one self-glued face", read_obj,
     "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 1 2 4\n", (4, 5, 1, 1, 1, 0, None, False, True)),
    ("torus of quads", read_obj, _torus_obj(8, 6), (48, 96, 48, 0, 1, 0, 1, True, True)),
    ("torus with two holes", read_obj, _torus_obj(8, 6, skip=((0, 0), (4, 3))),
     (48, 96, 46, 2, 1, -2, 1, True, True)),
    ("two tori", read_obj, _torus_obj(8, 6) + "".join(
        l + "\n" if l.startswith("v") else "f " + " ".join(str(int(k) + 48) for k in l.split()[1:]) + "\n"
        for l in _torus_obj(8, 6, dx=10).splitlines()),
     (96, 192, 96, 0, 2, 0, 2, True, True)),
    ("keyhole polygon (annulus as one face)", read_obj,
     "v 0 0 0\nv 3 0 0\nv 3 3 0\nv 0 3 0\nv 1 1 0\nv 1 2 0\nv 2 2 0\nv 2 1 0\nf 1 2 3 4 1 5 6 7 8 5\n",
     (8, 9, 1, 2, 1, 0, 0, True, True)),
    ("two tetrahedra sharing a vertex (bow-tie)", read_obj,
     TET + "v -1 0 0\nv 0 -1 0\nv 0 0 -1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n"
     "f 1 5 6\nf 1 6 7\nf 1 7 5\nf 5 7 6\n",
     (7, 12, 8, 0, 1, 3, None, True, False)),
    ("two triangles sharing a vertex", read_obj,
     "v 0 0 0\nv 1 0 0\nv 0 1 0\nv -1 0 0\nv 0 -1 0\nf 1 2 3\nf 1 4 5\n",
     (5, 6, 2, 2, 1, 1, None, True, False)),
    ("three triangles on one edge", read_obj,
     "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n",
     (5, 7, 3, 1, 1, 1, None, True, False)),
]


def selftest():
    keys = ("vertices", "edges", "faces", "boundary_loops", "components", "euler", "genus",
            "orientable", "manifold")
    passed = failed = 0
    for name, reader, text, want in SELFTEST:
        verts, faces = reader(text.encode())
        nv, faces = clean(verts, faces, {})
        got = analyse(nv, faces, {})
        want = dict(zip(keys, want))
        if got == want:
            passed += 1
        else:
            failed += 1
            print("FAIL %s\n  want %s\n  got  %s" % (name, json.dumps(want), json.dumps(got)))
    # the same solid through every reader
    tet = (TET + "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n").encode()
    verts, faces = read_obj(tet)
    ref = analyse(*clean(verts, faces, {}), {})
    tris = [[verts[i] for i in f] for f in faces]
    ply_head = ("ply\nformat %s 1.0\ncomment c\nelement vertex 4\nproperty double x\nproperty double y\n"
                "property double z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n")
    variants = {
        "ascii PLY": (ply_head % "ascii").encode()
        + "".join("%r %r %r\n" % v for v in verts).encode()
        + "".join("3 %d %d %d\n" % tuple(f) for f in faces).encode(),
        "binary little-endian PLY": (ply_head % "binary_little_endian").encode()
        + b"".join(struct.pack("<3d", *v) for v in verts)
        + b"".join(struct.pack("<B3i", 3, *f) for f in faces),
        "binary big-endian PLY": (ply_head % "binary_big_endian").encode()
        + b"".join(struct.pack(">3d", *v) for v in verts)
        + b"".join(struct.pack(">B3i", 3, *f) for f in faces),
        "ascii STL": ("solid t\n" + "".join(
            "facet normal 0 0 0\nouter loop\n" + "".join("vertex %r %r %r\n" % p for p in t)
            + "endloop\nendfacet\n" for t in tris) + "endsolid t\n").encode(),
        "binary STL, header starting with solid": b"solid".ljust(80, b" ") + struct.pack("<I", len(tris))
        + b"".join(struct.pack("<12fH", 0, 0, 0, *[c for p in t for c in p], 0) for t in tris),
        "OFF without keyword": ("4 4 0\n" + "".join("%r %r %r\n" % v for v in verts)
                                + "".join("3 %d %d %d\n" % tuple(f) for f in faces)).encode(),
        "UTF-16 OBJ": "\ufeff".encode("utf-16-be") + tet.decode().encode("utf-16-be"),
    }
    readers = {"PLY": read_ply, "STL": read_stl, "OFF": read_off, "OBJ": read_obj}
    for name, data in variants.items():
        reader = next(r for k, r in readers.items() if k in name)
        verts2, faces2 = reader(data)
        got = analyse(*clean(verts2, faces2, {}), {})
        if got == ref:
            passed += 1
        else:
            failed += 1
            print("FAIL %s\n  want %s\n  got  %s" % (name, json.dumps(ref), json.dumps(got)))
    print("%d passed, %d failed" % (passed, failed))
    return 1 if failed else 0


# --------------------------------------------------------------------- main

READERS = {".obj": read_obj, ".off": read_off, ".ply": read_ply, ".stl": read_stl}


def check(path, info=None):
    if info is None:
        info = {}
    with open(path, "rb") as fh:
        data = fh.read()
    ext = os.path.splitext(path)[1].lower()
    reader = READERS.get(ext)
    if reader is None:
        head = data[:16].lstrip()
        if head.startswith(b"ply"):
            reader = read_ply
        elif head[:4].endswith(b"OFF") or head.startswith(b"OFF"):
            reader = read_off
        else:
            raise MeshError("unknown mesh format (extension %r)" % ext)
    verts, faces = reader(data)
    nv, faces = clean(verts, faces, info)
    return analyse(nv, faces, info)


def main(argv):
    if argv[1:] == ["--selftest"]:
        return selftest()
    args = [a for a in argv[1:] if not a.startswith("--")]
    details = "--details" in argv[1:]
    if len(args) != 1:
        sys.stderr.write("usage: meshcheck.py MESH [--details] | meshcheck.py --selftest\n")
        return 2
    info = {}
    try:
        result = check(args[0], info)
    except (MeshError, OSError) as e:
        sys.stderr.write("%s: %s\n" % (args[0], e))
        return 1
    print(json.dumps(result, separators=(",", ":")))
    if details:
        sys.stderr.write(json.dumps(info, sort_keys=True) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
