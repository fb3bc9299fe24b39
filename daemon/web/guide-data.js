// The assembly guide's data: the structure's panels read from
// structure.obj, a coarse copy of them to draw while the view moves, and
// the holes two panels of the manifest share.

// structure.obj: each panel's vertices, then its faces under `g panel-N`.
export function parseStructure(text) {
  const positions = [];
  const index = [];
  const ranges = new Map();  // panel id -> [first vertex, end vertex)
  const triangles = new Map();  // panel id -> [first index, end index)
  let panel = null;
  let panelFirst = 0;
  let trianglesFirst = 0;
  let lineStart = 0;
  let vertices = 0;
  const close = () => {
    ranges.set(panel, [panelFirst, vertices]);
    triangles.set(panel, [trianglesFirst, index.length]);
    panel = null;
    panelFirst = vertices;
  };
  while (lineStart < text.length) {
    let lineEnd = text.indexOf('\n', lineStart);
    if (lineEnd < 0) lineEnd = text.length;
    const line = text.slice(lineStart, lineEnd);
    lineStart = lineEnd + 1;
    if (line.startsWith('v ')) {
      if (panel !== null) close();
      const parts = line.split(' ');
      positions.push(Number(parts[1]), Number(parts[2]), Number(parts[3]));
      vertices += 1;
    } else if (line.startsWith('g panel-')) {
      if (panel !== null) close();
      panel = Number(line.slice(8));
      trianglesFirst = index.length;
    } else if (line.startsWith('f ')) {
      const corners = line.split(' ').slice(1).map((word) => Number(word.split('/')[0]) - 1);
      for (let k = 1; k + 1 < corners.length; k += 1) index.push(corners[0], corners[k], corners[k + 1]);
    }
  }
  if (panel !== null) close();
  return { positions, index, ranges, triangles };
}

// A panel drawn coarsely while the view moves: its outline, simplified by
// Douglas-Peucker to a tenth of its size, as a fan from its middle. A
// browser without a graphics card (software WebGL) draws the bunny's
// 180,000 triangles a few times a second; these, many times fewer, fast.
export function coarseStructure(structure) {
  const positions = [];
  const index = [];
  const ranges = new Map();
  const point = (v) => [structure.positions[3 * v], structure.positions[3 * v + 1], structure.positions[3 * v + 2]];
  const distance = (a, b) => Math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
  const offLine = (p, a, b) => {
    const ab = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    const ap = [p[0] - a[0], p[1] - a[1], p[2] - a[2]];
    const length = Math.hypot(...ab);
    if (length === 0) return Math.hypot(...ap);
    const cross = [ab[1] * ap[2] - ab[2] * ap[1], ab[2] * ap[0] - ab[0] * ap[2], ab[0] * ap[1] - ab[1] * ap[0]];
    return Math.hypot(...cross) / length;
  };
  const simplify = (loop, from, to, tolerance, kept) => {
    let worst = -1;
    let far = 0;
    for (let k = from + 1; k < to; k += 1) {
      const d = offLine(loop[k], loop[from], loop[to % loop.length]);
      if (d > far) {
        far = d;
        worst = k;
      }
    }
    if (worst < 0 || far <= tolerance) return;
    simplify(loop, from, worst, tolerance, kept);
    kept.push(worst);
    simplify(loop, worst, to, tolerance, kept);
  };
  for (const [id, [first, end]] of structure.triangles) {
    const [v0, v1] = structure.ranges.get(id);
    const count = v1 - v0;
    // The boundary: the edges of one triangle only, in the triangles' direction.
    const used = new Map();
    for (let t = first; t < end; t += 3) {
      for (let k = 0; k < 3; k += 1) {
        const a = structure.index[t + k] - v0;
        const b = structure.index[t + ((k + 1) % 3)] - v0;
        const key = Math.min(a, b) * count + Math.max(a, b);
        used.set(key, used.has(key) ? null : [a, b]);
      }
    }
    const next = new Map();
    for (const edge of used.values()) if (edge) next.set(edge[0], edge[1]);
    let longest = [];
    const seen = new Set();
    for (const start of next.keys()) {
      if (seen.has(start)) continue;
      const loop = [];
      for (let v = start; v !== undefined && !seen.has(v); v = next.get(v)) {
        seen.add(v);
        loop.push(v);
      }
      if (loop.length > longest.length) longest = loop;
    }
    if (longest.length < 3) continue;
    const loop = longest.map((v) => point(v + v0));
    let size = 0;
    let opposite = 0;
    for (let k = 1; k < loop.length; k += 1) {
      const d = distance(loop[0], loop[k]);
      if (d > size) {
        size = d;
        opposite = k;
      }
    }
    const kept = [0];
    simplify(loop, 0, opposite, size / 6, kept);
    kept.push(opposite);
    simplify(loop, opposite, loop.length, size / 6, kept);
    if (kept.length < 3) continue;
    const firstVertex = positions.length / 3;
    const middle = [0, 0, 0];
    for (const k of kept) for (let axis = 0; axis < 3; axis += 1) middle[axis] += loop[k][axis] / kept.length;
    positions.push(...middle);
    for (const k of kept) positions.push(...loop[k]);
    for (let k = 0; k < kept.length; k += 1) {
      index.push(firstVertex, firstVertex + 1 + k, firstVertex + 1 + ((k + 1) % kept.length));
    }
    ranges.set(id, [firstVertex, positions.length / 3]);
  }
  return { positions, index, ranges };
}

// The holes two panels share: by edge, those on both.
export function sharedHoles(panel, other) {
  const count = (holes) => {
    const counts = new Map();
    for (const hole of holes || []) {
      if (hole.edge !== undefined) counts.set(hole.edge, (counts.get(hole.edge) || 0) + 1);
    }
    return counts;
  };
  const mine = count(panel.holes);
  const theirs = count(other.holes);
  const shared = [];
  for (const [edge, n] of mine) {
    if (theirs.has(edge)) shared.push({ edge, count: Math.min(n, theirs.get(edge)) });
  }
  return shared;
}
