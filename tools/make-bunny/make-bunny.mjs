// Builds the fovea test meshes assets/bunny-low.glb and assets/bunny-high.glb
// from the Stanford bunny in the npm package `bunny`.
//
//   bunny-low.glb : meshopt-simplified to exactly 292 triangles
//   bunny-high.glb: meshopt-simplified to exactly 1242 triangles, then one
//                   step of Loop subdivision (1-to-4 split) -> 4968 triangles
//
// Both meshes are welded/indexed, checked to be closed 2-manifolds, and placed
// with Y up, the bounding box centred on x = z = 0, the lowest point at y = 0
// and a height of exactly 1.0. Output is a hand-written glTF 2.0 binary (GLB).
// The script is deterministic: rerunning it reproduces the same bytes.
//
// Usage: cd tools/make-bunny && npm ci && node make-bunny.mjs

import { createRequire } from 'node:module';
import { mkdirSync, readFileSync, writeFileSync } from 'node:fs';
import { dirname, join, relative } from 'node:path';
import { fileURLToPath } from 'node:url';
import { MeshoptSimplifier } from 'meshoptimizer';

const require = createRequire(import.meta.url);
const bunny = require('bunny');

const HERE = dirname(fileURLToPath(import.meta.url));
const ASSETS = join(HERE, '..', '..', 'assets');
const GENERATOR = 'fovea tools/make-bunny';

const LOW_TRIANGLES = 292;
const HIGH_BASE_TRIANGLES = 1242; // x4 by subdivision = 4968
const HIGH_TRIANGLES = HIGH_BASE_TRIANGLES * 4;

// ---------------------------------------------------------------------------
// Mesh helpers. A mesh is { positions: Float64Array (xyz...), indices: Uint32Array }.

/** Weld vertices with bit-identical float32 positions, drop degenerate
 *  triangles and unreferenced vertices. Vertex order = first use. */
function weld(positions, indices) {
  const f32 = new Float32Array(positions);
  const key = (v) => `${f32[3 * v]},${f32[3 * v + 1]},${f32[3 * v + 2]}`;
  const canonical = new Map(); // position key -> new index
  const outPos = [];
  const remap = new Int32Array(positions.length / 3).fill(-1);
  const mapVertex = (v) => {
    if (remap[v] < 0) {
      const k = key(v);
      let n = canonical.get(k);
      if (n === undefined) {
        n = outPos.length / 3;
        canonical.set(k, n);
        outPos.push(positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]);
      }
      remap[v] = n;
    }
    return remap[v];
  };
  const outIdx = [];
  for (let t = 0; t < indices.length; t += 3) {
    const a = mapVertex(indices[t]);
    const b = mapVertex(indices[t + 1]);
    const c = mapVertex(indices[t + 2]);
    if (a !== b && b !== c && c !== a) outIdx.push(a, b, c);
  }
  // Vertices only referenced by degenerate triangles would be left unused;
  // compact again so every vertex is referenced.
  return compact(Float64Array.from(outPos), Uint32Array.from(outIdx));
}

/** Remove unreferenced vertices; vertex order = first use in the index buffer. */
function compact(positions, indices) {
  const remap = new Int32Array(positions.length / 3).fill(-1);
  const outPos = [];
  const outIdx = new Uint32Array(indices.length);
  for (let i = 0; i < indices.length; i++) {
    const v = indices[i];
    if (remap[v] < 0) {
      remap[v] = outPos.length / 3;
      outPos.push(positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]);
    }
    outIdx[i] = remap[v];
  }
  return { positions: Float64Array.from(outPos), indices: outIdx };
}

const edgeKey = (a, b) => (a < b ? a * 0x100000 + b : b * 0x100000 + a);

/** Topology statistics: boundary / non-manifold edges, degenerate and
 *  duplicate triangles, inconsistent orientation, Euler characteristic. */
function topology(mesh) {
  const { indices } = mesh;
  const vertexCount = mesh.positions.length / 3;
  const edgeUse = new Map(); // undirected edge -> triangle count
  const directed = new Map(); // directed edge -> count
  const triSet = new Set();
  let degenerate = 0;
  let duplicateTriangles = 0;
  for (let t = 0; t < indices.length; t += 3) {
    const tri = [indices[t], indices[t + 1], indices[t + 2]];
    if (tri[0] === tri[1] || tri[1] === tri[2] || tri[2] === tri[0]) degenerate++;
    const sorted = [...tri].sort((x, y) => x - y).join(',');
    if (triSet.has(sorted)) duplicateTriangles++;
    triSet.add(sorted);
    for (let e = 0; e < 3; e++) {
      const a = tri[e];
      const b = tri[(e + 1) % 3];
      const k = edgeKey(a, b);
      edgeUse.set(k, (edgeUse.get(k) || 0) + 1);
      const dk = a * 0x100000 + b;
      directed.set(dk, (directed.get(dk) || 0) + 1);
    }
  }
  let boundaryEdges = 0;
  let nonManifoldEdges = 0;
  for (const n of edgeUse.values()) {
    if (n === 1) boundaryEdges++;
    else if (n > 2) nonManifoldEdges++;
  }
  let inconsistentEdges = 0; // same directed edge used twice => flipped neighbour
  for (const n of directed.values()) if (n > 1) inconsistentEdges++;
  const used = new Set(indices);
  return {
    triangles: indices.length / 3,
    vertices: vertexCount,
    unusedVertices: vertexCount - used.size,
    edges: edgeUse.size,
    boundaryEdges,
    nonManifoldEdges,
    inconsistentEdges,
    degenerate,
    duplicateTriangles,
    euler: vertexCount - edgeUse.size + indices.length / 3,
  };
}

function isCleanClosedManifold(s) {
  return (
    s.boundaryEdges === 0 &&
    s.nonManifoldEdges === 0 &&
    s.inconsistentEdges === 0 &&
    s.degenerate === 0 &&
    s.duplicateTriangles === 0 &&
    s.unusedVertices === 0
  );
}

function bounds(positions) {
  const min = [Infinity, Infinity, Infinity];
  const max = [-Infinity, -Infinity, -Infinity];
  for (let i = 0; i < positions.length; i += 3) {
    for (let c = 0; c < 3; c++) {
      min[c] = Math.min(min[c], positions[i + c]);
      max[c] = Math.max(max[c], positions[i + c]);
    }
  }
  return { min, max };
}

/** Signed volume (positive for outward-facing counter-clockwise winding). */
function signedVolume(mesh) {
  const p = mesh.positions;
  const ix = mesh.indices;
  let v = 0;
  for (let t = 0; t < ix.length; t += 3) {
    const a = 3 * ix[t];
    const b = 3 * ix[t + 1];
    const c = 3 * ix[t + 2];
    v +=
      p[a] * (p[b + 1] * p[c + 2] - p[b + 2] * p[c + 1]) -
      p[a + 1] * (p[b] * p[c + 2] - p[b + 2] * p[c]) +
      p[a + 2] * (p[b] * p[c + 1] - p[b + 1] * p[c]);
  }
  return v / 6;
}

// ---------------------------------------------------------------------------
// Decimation to an exact triangle count.

/** Simplify with meshopt until exactly `targetTriangles` remain and the result
 *  is still a clean closed manifold. meshopt may stop a little below or above
 *  the requested index count, so we scan the requested target upwards from the
 *  exact value (and then downwards), and try a few flag sets. The first
 *  acceptable result in this fixed search order wins, so the choice is
 *  deterministic. */
function simplifyExact(mesh, targetTriangles, label) {
  const pos32 = new Float32Array(mesh.positions);
  const flagSets = [[], ['Regularize'], ['Prune'], ['Permissive']];
  const targetError = 1.0; // relative error budget large enough never to be the limit
  const offsets = [];
  for (let d = 0; d <= 200; d++) offsets.push(d);
  for (let d = 1; d <= 200; d++) offsets.push(-d);
  const tried = [];
  for (const flags of flagSets) {
    for (const d of offsets) {
      const requested = targetTriangles + d;
      if (requested <= 0 || requested * 3 > mesh.indices.length) continue;
      const [out, error] = MeshoptSimplifier.simplify(
        mesh.indices,
        pos32,
        3,
        requested * 3,
        targetError,
        flags,
      );
      const got = out.length / 3;
      if (got !== targetTriangles) {
        if (tried.length < 8) tried.push(`${requested}->${got}`);
        continue;
      }
      const result = compact(mesh.positions, out);
      const stats = topology(result);
      if (!isCleanClosedManifold(stats)) {
        tried.push(`${requested}->${got} (not clean: ${JSON.stringify(stats)})`);
        continue;
      }
      console.log(
        `${label}: meshopt simplify target_index_count=${requested * 3} ` +
          `(${requested} tris) target_error=${targetError} flags=[${flags.join(',')}] ` +
          `-> ${got} triangles, error=${error.toExponential(3)}`,
      );
      if (tried.length) console.log(`${label}:   earlier attempts: ${tried.join(', ')}`);
      return result;
    }
  }
  throw new Error(`${label}: could not reach exactly ${targetTriangles} triangles; tried ${tried.join(', ')}`);
}

// ---------------------------------------------------------------------------
// Loop subdivision (1-to-4 split with shared edge midpoints, Loop weights).

function loopSubdivide(mesh) {
  const P = mesh.positions;
  const I = mesh.indices;
  const nv = P.length / 3;

  // Edge -> opposite vertices; vertex -> neighbour set.
  const edges = new Map(); // key -> { a, b, opp: [] , id }
  const neighbours = Array.from({ length: nv }, () => new Set());
  const edgeOrder = [];
  for (let t = 0; t < I.length; t += 3) {
    for (let e = 0; e < 3; e++) {
      const a = I[t + e];
      const b = I[t + ((e + 1) % 3)];
      const c = I[t + ((e + 2) % 3)];
      const k = edgeKey(a, b);
      let rec = edges.get(k);
      if (!rec) {
        rec = { a: Math.min(a, b), b: Math.max(a, b), opp: [], id: nv + edgeOrder.length };
        edges.set(k, rec);
        edgeOrder.push(rec);
      }
      rec.opp.push(c);
      neighbours[a].add(b);
      neighbours[b].add(a);
    }
  }

  const boundaryNeighbours = Array.from({ length: nv }, () => []);
  for (const rec of edgeOrder) {
    if (rec.opp.length !== 2) {
      boundaryNeighbours[rec.a].push(rec.b);
      boundaryNeighbours[rec.b].push(rec.a);
    }
  }

  const out = new Float64Array(3 * (nv + edgeOrder.length));

  // Even (original) vertices.
  for (let v = 0; v < nv; v++) {
    const bn = boundaryNeighbours[v];
    for (let c = 0; c < 3; c++) {
      let value;
      if (bn.length === 2) {
        value = 0.75 * P[3 * v + c] + 0.125 * (P[3 * bn[0] + c] + P[3 * bn[1] + c]);
      } else if (bn.length > 0) {
        value = P[3 * v + c]; // corner / non-manifold: keep fixed
      } else {
        const ring = [...neighbours[v]].sort((x, y) => x - y);
        const n = ring.length;
        const w = 0.375 + 0.25 * Math.cos((2 * Math.PI) / n);
        const beta = (0.625 - w * w) / n;
        let sum = 0;
        for (const u of ring) sum += P[3 * u + c];
        value = (1 - n * beta) * P[3 * v + c] + beta * sum;
      }
      out[3 * v + c] = value;
    }
  }

  // Odd (edge) vertices.
  for (const rec of edgeOrder) {
    for (let c = 0; c < 3; c++) {
      let value;
      if (rec.opp.length === 2) {
        value =
          0.375 * (P[3 * rec.a + c] + P[3 * rec.b + c]) +
          0.125 * (P[3 * rec.opp[0] + c] + P[3 * rec.opp[1] + c]);
      } else {
        value = 0.5 * (P[3 * rec.a + c] + P[3 * rec.b + c]);
      }
      out[3 * rec.id + c] = value;
    }
  }

  // 1-to-4 split, preserving winding.
  const idx = new Uint32Array(I.length * 4);
  let o = 0;
  for (let t = 0; t < I.length; t += 3) {
    const a = I[t];
    const b = I[t + 1];
    const c = I[t + 2];
    const ab = edges.get(edgeKey(a, b)).id;
    const bc = edges.get(edgeKey(b, c)).id;
    const ca = edges.get(edgeKey(c, a)).id;
    idx.set([a, ab, ca, ab, b, bc, ca, bc, c, ab, bc, ca], o);
    o += 12;
  }
  // Reorder vertices by first use so the index buffer reads nicely.
  return compact(out, idx);
}

// ---------------------------------------------------------------------------
// Placement: Y up, bbox centred on x/z, min y = 0, height 1.

function normalize(mesh) {
  const { min, max } = bounds(mesh.positions);
  const height = max[1] - min[1];
  const cx = 0.5 * (min[0] + max[0]);
  const cz = 0.5 * (min[2] + max[2]);
  const p = new Float64Array(mesh.positions.length);
  for (let i = 0; i < p.length; i += 3) {
    p[i] = (mesh.positions[i] - cx) / height;
    p[i + 1] = (mesh.positions[i + 1] - min[1]) / height;
    p[i + 2] = (mesh.positions[i + 2] - cz) / height;
  }
  return { positions: p, indices: mesh.indices };
}

// ---------------------------------------------------------------------------
// GLB writer / reader.

const GLB_MAGIC = 0x46546c67; // "glTF"
const CHUNK_JSON = 0x4e4f534a; // "JSON"
const CHUNK_BIN = 0x004e4942; // "BIN\0"

function pad4(n) {
  return (n + 3) & ~3;
}

function writeGlb(mesh, name) {
  const pos = new Float32Array(mesh.positions);
  const idx = new Uint32Array(mesh.indices);
  const vertexCount = pos.length / 3;
  const min = [Infinity, Infinity, Infinity];
  const max = [-Infinity, -Infinity, -Infinity];
  for (let i = 0; i < pos.length; i += 3) {
    for (let c = 0; c < 3; c++) {
      min[c] = Math.min(min[c], pos[i + c]);
      max[c] = Math.max(max[c], pos[i + c]);
    }
  }

  const posBytes = pos.byteLength; // multiple of 4
  const idxBytes = idx.byteLength; // multiple of 4
  const binLength = posBytes + idxBytes;

  const gltf = {
    asset: { version: '2.0', generator: GENERATOR },
    scene: 0,
    scenes: [{ nodes: [0] }],
    nodes: [{ mesh: 0, name }],
    meshes: [{ name, primitives: [{ attributes: { POSITION: 0 }, indices: 1, mode: 4 }] }],
    accessors: [
      { bufferView: 0, byteOffset: 0, componentType: 5126, count: vertexCount, type: 'VEC3', min, max },
      { bufferView: 1, byteOffset: 0, componentType: 5125, count: idx.length, type: 'SCALAR' },
    ],
    bufferViews: [
      { buffer: 0, byteOffset: 0, byteLength: posBytes, target: 34962 },
      { buffer: 0, byteOffset: posBytes, byteLength: idxBytes, target: 34963 },
    ],
    buffers: [{ byteLength: binLength }],
  };

  const jsonRaw = Buffer.from(JSON.stringify(gltf), 'utf8');
  const jsonLen = pad4(jsonRaw.length);
  const binLen = pad4(binLength);
  const total = 12 + 8 + jsonLen + 8 + binLen;
  const out = Buffer.alloc(total, 0);
  let o = 0;
  out.writeUInt32LE(GLB_MAGIC, o); o += 4;
  out.writeUInt32LE(2, o); o += 4;
  out.writeUInt32LE(total, o); o += 4;
  out.writeUInt32LE(jsonLen, o); o += 4;
  out.writeUInt32LE(CHUNK_JSON, o); o += 4;
  jsonRaw.copy(out, o);
  out.fill(0x20, o + jsonRaw.length, o + jsonLen); // pad JSON with spaces
  o += jsonLen;
  out.writeUInt32LE(binLen, o); o += 4;
  out.writeUInt32LE(CHUNK_BIN, o); o += 4;
  Buffer.from(pos.buffer, pos.byteOffset, posBytes).copy(out, o);
  Buffer.from(idx.buffer, idx.byteOffset, idxBytes).copy(out, o + posBytes);
  // remaining BIN padding (if any) is already zero
  return out;
}

/** Parse a GLB produced above and return { json, positions, indices }. Throws on
 *  any structural problem. */
function readGlb(buf) {
  const fail = (msg) => {
    throw new Error(`GLB check failed: ${msg}`);
  };
  if (buf.length < 28) fail('too short');
  if (buf.readUInt32LE(0) !== GLB_MAGIC) fail('bad magic');
  if (buf.readUInt32LE(4) !== 2) fail('bad version');
  if (buf.readUInt32LE(8) !== buf.length) fail('length mismatch');
  const jsonLen = buf.readUInt32LE(12);
  if (buf.readUInt32LE(16) !== CHUNK_JSON) fail('first chunk is not JSON');
  if (jsonLen % 4) fail('JSON chunk not 4-byte aligned');
  const json = JSON.parse(buf.subarray(20, 20 + jsonLen).toString('utf8'));
  const binHeader = 20 + jsonLen;
  const binLen = buf.readUInt32LE(binHeader);
  if (buf.readUInt32LE(binHeader + 4) !== CHUNK_BIN) fail('second chunk is not BIN');
  if (binLen % 4) fail('BIN chunk not 4-byte aligned');
  if (binHeader + 8 + binLen !== buf.length) fail('trailing bytes');
  const bin = buf.subarray(binHeader + 8, binHeader + 8 + binLen);
  if (json.asset?.version !== '2.0') fail('asset.version');
  if (json.buffers.length !== 1 || json.buffers[0].byteLength > binLen) fail('buffer length');

  const prim = json.meshes[json.nodes[json.scenes[json.scene].nodes[0]].mesh].primitives[0];
  if (prim.mode !== 4) fail('primitive mode');
  const view = (accessorIndex, componentType, type, Ctor, comps) => {
    const acc = json.accessors[accessorIndex];
    if (acc.componentType !== componentType || acc.type !== type) fail(`accessor ${accessorIndex} type`);
    const bv = json.bufferViews[acc.bufferView];
    const start = bv.byteOffset + (acc.byteOffset || 0);
    const n = acc.count * comps;
    if (start % 4 || start + n * 4 > bv.byteOffset + bv.byteLength) fail(`accessor ${accessorIndex} range`);
    const copy = Buffer.from(bin.subarray(start, start + n * 4));
    return { acc, bv, data: new Ctor(copy.buffer, copy.byteOffset, n) };
  };
  const p = view(prim.attributes.POSITION, 5126, 'VEC3', Float32Array, 3);
  const ix = view(prim.indices, 5125, 'SCALAR', Uint32Array, 1);
  if (p.bv.target !== 34962 || ix.bv.target !== 34963) fail('bufferView targets');
  if (ix.data.length % 3) fail('index count not a multiple of 3');
  for (const i of ix.data) if (i >= p.acc.count) fail('index out of range');
  const b = bounds(p.data);
  for (let c = 0; c < 3; c++) {
    if (p.acc.min[c] !== b.min[c] || p.acc.max[c] !== b.max[c]) fail('POSITION min/max mismatch');
  }
  return { json, positions: p.data, indices: ix.data };
}

// ---------------------------------------------------------------------------

function describe(label, file, buf, expectedTriangles) {
  const back = readGlb(buf);
  const mesh = { positions: Float64Array.from(back.positions), indices: back.indices };
  const s = topology(mesh);
  const b = bounds(back.positions);
  if (s.triangles !== expectedTriangles) {
    throw new Error(`${label}: read back ${s.triangles} triangles, expected ${expectedTriangles}`);
  }
  if (!isCleanClosedManifold(s)) throw new Error(`${label}: not a clean closed manifold: ${JSON.stringify(s)}`);
  const vol = signedVolume(mesh);
  if (!(vol > 0)) throw new Error(`${label}: non-positive signed volume ${vol} (winding inverted?)`);
  if (b.min[1] !== 0 || b.max[1] !== 1) throw new Error(`${label}: y range is [${b.min[1]}, ${b.max[1]}]`);
  const fmt = (v) => v.map((x) => x.toFixed(6)).join(', ');
  console.log(
    `${label}: ${relative(process.cwd(), file)}  ${buf.length} bytes  ` +
      `${s.triangles} triangles  ${s.vertices} vertices  ${s.edges} edges  ` +
      `boundary edges ${s.boundaryEdges}  non-manifold edges ${s.nonManifoldEdges}  ` +
      `euler ${s.euler}  volume ${vol.toFixed(6)}\n` +
      `${label}:   bbox min [${fmt(b.min)}]  max [${fmt(b.max)}]`,
  );
}

async function main() {
  await MeshoptSimplifier.ready;

  // Source: bunny package. Its up axis is +Y already (ears at max y), so no
  // rotation is applied.
  const srcPositions = Float64Array.from(bunny.positions.flat());
  const srcIndices = Uint32Array.from(bunny.cells.flat());
  const source = weld(srcPositions, srcIndices);
  const ss = topology(source);
  console.log(
    `source: bunny package ${bunny.positions.length} vertices / ${bunny.cells.length} triangles; ` +
      `after weld ${ss.vertices} vertices / ${ss.triangles} triangles, ` +
      `boundary edges ${ss.boundaryEdges}, non-manifold edges ${ss.nonManifoldEdges}, euler ${ss.euler}`,
  );
  if (!isCleanClosedManifold(ss)) throw new Error(`source is not a clean closed manifold: ${JSON.stringify(ss)}`);
  // Ensure outward-facing (CCW) winding, as glTF expects.
  if (signedVolume(source) < 0) {
    for (let t = 0; t < source.indices.length; t += 3) {
      const tmp = source.indices[t + 1];
      source.indices[t + 1] = source.indices[t + 2];
      source.indices[t + 2] = tmp;
    }
    console.log('source: winding flipped to counter-clockwise (outward normals)');
  }

  const low = normalize(simplifyExact(source, LOW_TRIANGLES, 'low'));
  const highBase = simplifyExact(source, HIGH_BASE_TRIANGLES, 'high');
  const high = normalize(loopSubdivide(highBase));
  console.log(`high: Loop subdivision ${highBase.indices.length / 3} -> ${high.indices.length / 3} triangles`);

  mkdirSync(ASSETS, { recursive: true });
  for (const [label, mesh, fileName, expected] of [
    ['low', low, 'bunny-low.glb', LOW_TRIANGLES],
    ['high', high, 'bunny-high.glb', HIGH_TRIANGLES],
  ]) {
    const file = join(ASSETS, fileName);
    const buf = writeGlb(mesh, fileName.replace(/\.glb$/, ''));
    writeFileSync(file, buf);
    describe(label, file, readFileSync(file), expected);
  }
}

main().catch((err) => {
  console.error(err);
  process.exit(1);
});
