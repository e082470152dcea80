// The studio's "Greene live" panel (crates/studio/web/greene.js) in headless Chromium: the
// cube captured from the mirror sphere's centre against the server's own cube conversion of
// the same environment (the core's faces and orientations), a moving object where it should
// be in the capture and in the sphere's reflection (and gone when it has moved), the sphere
// absent from its own capture (with the negative control that draws it there), the Omnimax
// view's per-pixel directions against the core's fisheye, and the panel opened by its button
// and by `greene=1`, its frames a function of t alone.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import path from 'node:path';
import { browser, studio, openStudio, carried, directions, sphereHit, reflect, ROOT } from './lib.mjs';
import { OBJECTS, centreAt, cameraAt, SPHERE, OMNIMAX_SPEC, OMNIMAX_FRAME, OMNIMAX_PARAMS } from '../../crates/studio/web/greene.js';

const VENICE = path.join(ROOT, 'assets', 'env', 'venice.exr');
// The capture's edge in these tests: small enough to read back and compare quickly, large
// enough that the objects span many texels.
const N = 64;

let chromium;
let s;
let page;
let logs;
let cubeDirs; // the core's direction of every capture texel's centre (f32 triples, face by face, row t = 0 first)

before(async () => {
  chromium = await browser();
  s = await studio([VENICE]);
  ({ page, logs } = await openStudio(chromium, `${s.url}&greene=1&greene-size=${N}`));
  await page.evaluate(async () => {
    await window.studio.greene.ready;
    window.studio.greene.pause();
  });
  const body = new Float32Array(6 * N * N * 3);
  for (let l = 0; l < 6; l++) for (let j = 0; j < N; j++) for (let i = 0; i < N; i++) body.set([(i + 0.5) / N, (j + 0.5) / N, l], 3 * ((l * N + j) * N + i));
  cubeDirs = (await directions(s, 'cube', body)).dirs;
});
after(async () => {
  await page?.close();
  await chromium?.close();
  s?.stop();
});

function api(p) {
  const url = new URL(s.url);
  const [pathname, query] = p.split('?');
  url.pathname = pathname;
  for (const [k, v] of new URLSearchParams(query || '')) url.searchParams.set(k, v);
  return fetch(url);
}

/** An environment payload (texture.rs): header and f32 texels. */
function parseTexture(buffer) {
  const n = new DataView(buffer).getUint32(4, true);
  const header = JSON.parse(new TextDecoder().decode(new Uint8Array(buffer, 8, n)));
  return { header, data: new Float32Array(buffer, 8 + n) };
}

/** Draws the frame of time t (objects shown or not) and reads the capture back. */
async function captureAt(t, { hide = false, self = false } = {}) {
  const b64 = await page.evaluate(
    ([t, hide, self]) => {
      const g = window.studio.greene;
      g.hideObjects = hide;
      g.selfVisible = self;
      try {
        g.renderAt(t);
      } finally {
        g.hideObjects = false;
        g.selfVisible = false;
      }
      const c = g.readCapture();
      return window.carry(c.data);
    },
    [t, hide, self],
  );
  return carried(b64, Float32Array);
}

async function viewAt(t, hide = false) {
  const b64 = await page.evaluate(
    ([t, hide]) => {
      const g = window.studio.greene;
      g.hideObjects = hide;
      try {
        g.renderAt(t);
      } finally {
        g.hideObjects = false;
      }
      return window.carry(g.viewPixels().data);
    },
    [t, hide],
  );
  return carried(b64);
}

const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const norm = (a) => {
  const l = Math.hypot(...a);
  return a.map((x) => x / l);
};
const angle = (a, b) => Math.atan2(Math.hypot(a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]), dot(a, b));
const quantile = (xs, q) => {
  const a = Float64Array.from(xs).sort();
  return a[Math.min(a.length - 1, Math.floor(q * a.length))];
};

/** The radius of the ball about an object's centre that holds it all. */
function bound(o) {
  return { cube: Math.sqrt(3), octahedron: 1, torus: 1.38 }[o.shape] * o.size;
}

/** Whether direction d from the sphere's centre misses every object at time t, by `margin` rad. */
function clearOf(d, t, margin) {
  return OBJECTS.every((o) => {
    const c = centreAt(o, t);
    const dist = Math.hypot(...c);
    return angle(d, c) > Math.asin(Math.min(1, bound(o) / dist)) + margin;
  });
}

test("the capture is a GL cube map of the world: the server's cube conversion of the same environment, texel by texel", async () => {
  const cap = await captureAt(0, { hide: true });
  const r = await api(`/api/environment?projection=cube&size=${N}&precision=float`);
  assert.equal(r.status, 200);
  const { header, data } = parseTexture(await r.arrayBuffer());
  assert.equal(header.projection, 'cube');
  assert.equal(header.width, N);
  const intensity = await page.evaluate(() => window.studio.view.state.scene.environment.intensity);
  const [tw, th] = [header.texelWidth, header.texelHeight];
  const server = (l, i, j) => {
    const at = 4 * ((l * th + j + 1) * tw + i + 1);
    return [0, 1, 2].map((k) => intensity * data[at + k]);
  };
  // The difference of texel (l, i, j) against the server's texel (l, mi(i), j), relative to
  // the server's brightest channel there (floored at 1% of the map's mean, so that near-black
  // texels do not dominate).
  let mean = 0;
  for (let l = 0; l < 6; l++) for (let j = 0; j < N; j++) for (let i = 0; i < N; i++) mean += Math.max(...server(l, i, j));
  mean /= 6 * N * N;
  const diffs = (mi) => {
    const out = new Float64Array(6 * N * N);
    for (let l = 0; l < 6; l++) {
      for (let j = 0; j < N; j++) {
        for (let i = 0; i < N; i++) {
          const at = 4 * ((l * N + j) * N + i);
          const want = server(l, mi(i), j);
          const e = Math.max(...[0, 1, 2].map((k) => Math.abs(cap[at + k] - want[k])));
          out[(l * N + j) * N + i] = e / Math.max(Math.max(...want), 0.01 * mean);
          assert.equal(cap[at + 3], 1, 'the background is alpha 1');
        }
      }
    }
    return out;
  };
  const d = diffs((i) => i);
  const [median, p99, worst] = [quantile(d, 0.5), quantile(d, 0.99), quantile(d, 1)];
  const close = d.filter((e) => e <= 2e-3).length / d.length;
  // The faces mirrored left to right: what a face drawn the wrong way round would give.
  const flipped = diffs((i) => N - 1 - i);
  const fMedian = quantile(flipped, 0.5);
  console.log(
    `capture ${N}² vs the server's cube ${N}²: relative difference median ${median.toExponential(2)}, ${(100 * close).toFixed(1)}% within 2e-3, 99th percentile ${p99.toExponential(2)}, worst ${worst.toFixed(3)}; faces mirrored: median ${fMedian.toExponential(2)}`,
  );
  // The capture reads venice (512×256 lat-long) bilinearly at each texel's centre, into half
  // floats (2^-11 relative). The server (core resample.rs) reads one bilinear lookup at the
  // centre too where a texel's footprint is under 4 source texels (BILINEAR_MAX_RATIO), as
  // over most of a 64² face: there the two agree to the half floats' rounding. Where the
  // footprint is larger (about the face centres, where a 64² texel spans up to 2×2 source
  // texels, and about the poles) it integrates over the footprint: there they differ by up
  // to the local contrast at the picture's sharp edges (the 99th percentile).
  assert.ok(median < 1e-3, `median ${median}`);
  assert.ok(close > 0.6, `${close} within 2e-3`);
  assert.ok(p99 < 0.35, `99th percentile ${p99}`);
  assert.ok(fMedian > 5 * median && fMedian > 0.05, `mirrored faces would pass: ${fMedian}`);
});

test("over the server's own cube of the same size, the capture is that cube texel for texel (to the half floats' rounding)", async () => {
  // The viewport shows the environment converted to a 64² cube: the panel reads it through
  // cube.glsl at its own texels' centres, so every capture texel is one texel of it, read at
  // its centre (the bilinear weights 1e-6 off), rounded to a half float: a face drawn
  // mirrored, turned or swapped would be off by the picture's contrast.
  const p = await openStudio(chromium, `${s.url}&projection=cube&size=${N}&greene=1&greene-size=${N}`);
  try {
    const b64 = await p.page.evaluate(async () => {
      const g = window.studio.greene;
      await g.ready;
      g.pause();
      g.hideObjects = true;
      g.renderAt(0);
      return window.carry(g.readCapture().data);
    });
    const cap = carried(b64, Float32Array);
    const { header, data } = parseTexture(await (await api(`/api/environment?projection=cube&size=${N}&precision=float`)).arrayBuffer());
    const [tw, th] = [header.texelWidth, header.texelHeight];
    let worst = 0;
    for (let l = 0; l < 6; l++) {
      for (let j = 0; j < N; j++) {
        for (let i = 0; i < N; i++) {
          const at = 4 * ((l * th + j + 1) * tw + i + 1);
          const mine = 4 * ((l * N + j) * N + i);
          const want = [0, 1, 2].map((k) => data[at + k]);
          const e = Math.max(...[0, 1, 2].map((k) => Math.abs(cap[mine + k] - want[k]))) / Math.max(...want, 1e-6);
          worst = Math.max(worst, e);
        }
      }
    }
    console.log(`capture ${N}² over the server's cube ${N}²: worst relative difference ${worst.toExponential(2)} (a half float's rounding: ${(2 ** -11).toExponential(2)})`);
    assert.ok(worst < 1e-3, `worst ${worst}`);
    assert.deepEqual(p.logs.filter((l) => /error/i.test(l)), []);
  } finally {
    await p.page.close();
  }
});

test('a moving object shows in the capture and in the reflection where it should, and not once it has moved', async () => {
  const k = 0;
  const o = OBJECTS[k];
  // A time when the red cube is to the camera's side (its reflection well inside the
  // sphere's disk, the cube itself well outside it), no other object is in the way, and its
  // direction is off every axis and face diagonal plane's symmetry (each component at least
  // 0.15 of the largest and the two smaller unequal), so that a face drawn mirrored or turned
  // would put it elsewhere.
  let t0 = null;
  for (let t = 0; t < 30 && t0 === null; t += 0.05) {
    const c = centreAt(o, t);
    const m = c.map(Math.abs).sort((x, y) => x - y);
    if (m[0] < 0.15 * m[2] || m[1] - m[0] < 0.1 * m[2]) continue;
    const cam = cameraAt(t);
    const a = angle(c, cam.eye);
    const others = OBJECTS.filter((_, j) => j !== k);
    const clear = others.every((q) => angle(c, centreAt(q, t)) > Math.asin(bound(q) / Math.hypot(...centreAt(q, t))) + Math.asin(bound(o) / Math.hypot(...c)) + 0.1);
    if (a > 0.8 && a < 1.4 && clear) t0 = t;
  }
  assert.ok(t0 !== null, 'no time found');
  const d = norm(centreAt(o, t0));
  const dist = Math.hypot(...centreAt(o, t0));
  const inner = Math.asin(o.inner / dist);
  const outer = Math.asin(bound(o) / dist);
  const cap = await captureAt(t0);
  const marker = 2 + k;
  let best = -2;
  let bestAt = -1;
  let inside = 0;
  for (let i = 0; i < 6 * N * N; i++) {
    const dir = cubeDirs.subarray(3 * i, 3 * i + 3);
    const c = dot(dir, d);
    if (c > best) [best, bestAt] = [c, i];
    const a = angle(dir, d);
    const alpha = cap[4 * i + 3];
    // Texels well inside the ball the cube surely holds show it; none beyond its bounding
    // ball (a texel's half-diagonal of slack) does.
    if (a < inner - 0.03) {
      inside++;
      assert.equal(alpha, marker, `texel ${i} at ${a.toFixed(3)} rad from the cube's centre shows ${alpha}`);
    }
    if (a > outer + 0.04) assert.notEqual(alpha, marker, `texel ${i} at ${a.toFixed(3)} rad from the cube's centre shows the cube`);
  }
  assert.ok(inside > 10, `${inside} texels inside`);
  const rgb = Array.from(cap.subarray(4 * bestAt, 4 * bestAt + 3));
  assert.equal(cap[4 * bestAt + 3], marker);
  assert.ok(angle(rgb, o.colour) < 0.01, `the capture's colour ${rgb} is not ${o.colour}'s`);

  // The mirror: the pixel whose reflected ray is nearest to d (the capture is the world seen
  // from the centre: the reflected direction alone picks the texel).
  const mirrorPixel = (t) => {
    const cam = cameraAt(t);
    let bestPx = null;
    let bestA = Infinity;
    const within = [];
    for (let py = 0; py < cam.height; py++) {
      for (let px = 0; px < cam.width; px++) {
        const x = ((2 * (px + 0.5)) / cam.width - 1) * cam.ty * cam.aspect;
        const y = (1 - (2 * (py + 0.5)) / cam.height) * cam.ty;
        const ray = norm([0, 1, 2].map((q) => cam.forward[q] + x * cam.right[q] + y * cam.up[q]));
        const n = sphereHit(cam.eye, ray); // the unit sphere at the origin: SPHERE
        if (!n) continue;
        const a = angle(reflect(ray, n), d);
        if (a < bestA) [bestA, bestPx] = [a, [px, py]];
        if (a < inner - 0.05) within.push([px, py]);
      }
    }
    return { bestA, bestPx, within, width: cam.width };
  };
  assert.deepEqual([SPHERE.centre, SPHERE.radius], [[0, 0, 0], 1]);
  const px0 = mirrorPixel(t0);
  const view0 = await viewAt(t0);
  const at = ([x, y], v, w) => Array.from(v.subarray(4 * (y * w + x), 4 * (y * w + x) + 3));
  const red = ([r, g, b]) => r >= 90 && r > 2.5 * g && r > 2.5 * b;
  assert.ok(px0.bestA < 0.05, `no sphere pixel reflects d (best ${px0.bestA} rad)`);
  assert.ok(red(at(px0.bestPx, view0, px0.width)), `the mirror's pixel ${px0.bestPx} shows ${at(px0.bestPx, view0, px0.width)}`);
  assert.ok(px0.within.length >= 3, `${px0.within.length} mirror pixels`);
  for (const p of px0.within) assert.ok(red(at(p, view0, px0.width)), `the mirror's pixel ${p} shows ${at(p, view0, px0.width)}`);
  console.log(`t = ${t0.toFixed(2)} s: the red cube along ${d.map((x) => x.toFixed(3))}, ${inside} capture texels inside it, the mirror's pixel ${px0.bestPx} (${px0.bestA.toFixed(4)} rad off) shows ${at(px0.bestPx, view0, px0.width)}, ${px0.within.length} mirror pixels all red`);

  // Later, with nothing along d any more: the capture there is the background's (the frame
  // with the objects hidden), bit for bit, and so is the mirror's pixel reflecting d.
  let t1 = null;
  for (let t = t0 + 1.5; t < t0 + 30 && t1 === null; t += 0.05) if (clearOf(d, t, 0.15)) t1 = t;
  assert.ok(t1 !== null);
  const cap1 = await captureAt(t1);
  const bg1 = await captureAt(t1, { hide: true });
  for (let i = 0; i < 6 * N * N; i++) {
    if (angle(cubeDirs.subarray(3 * i, 3 * i + 3), d) > outer) continue;
    assert.notEqual(cap1[4 * i + 3], marker, `the cube is still at texel ${i}`);
    for (let q = 0; q < 4; q++) assert.equal(cap1[4 * i + q], bg1[4 * i + q], `texel ${i}`);
  }
  const px1 = mirrorPixel(t1);
  const view1 = await viewAt(t1);
  const hidden1 = await viewAt(t1, true);
  const a1 = at(px1.bestPx, view1, px1.width);
  assert.ok(!red(a1), `the mirror still shows the cube: ${a1}`);
  assert.deepEqual(a1, at(px1.bestPx, hidden1, px1.width));
});

test('the sphere cannot see itself: no texel of the capture is the sphere (and drawn there, every texel would be)', async () => {
  const marker = await page.evaluate(() => window.studio.greene.SELF_MARKER.alpha);
  for (const t of [0, 1.7, 4.2]) {
    const cap = await captureAt(t);
    const alphas = new Map();
    for (let i = 0; i < 6 * N * N; i++) alphas.set(cap[4 * i + 3], (alphas.get(cap[4 * i + 3]) || 0) + 1);
    assert.ok(!alphas.has(marker), `t = ${t}: ${alphas.get(marker)} texels of the sphere`);
    for (const a of alphas.keys()) assert.ok([1, 2, 3, 4, 5].includes(a), `t = ${t}: a texel of alpha ${a}`);
    assert.ok(alphas.size >= 3, `t = ${t}: only ${[...alphas.keys()]} seen`);
  }
  // The negative control: the sphere drawn into its own capture encloses its centre.
  const self = await captureAt(1.7, { self: true });
  let marked = 0;
  for (let i = 0; i < 6 * N * N; i++) if (self[4 * i + 3] === marker) marked++;
  assert.equal(marked, 6 * N * N);
});

test("the Omnimax view's per-pixel directions are the core's fisheye's (180°, looking up)", async () => {
  // The panel's frame and uParams are the server's for the spec.
  const g = await (await api(`/api/grid?projection=${encodeURIComponent(OMNIMAX_SPEC)}&n=2`)).arrayBuffer();
  const frame = Array.from(new Float32Array(g, 4, 9));
  const params = Array.from(new Float32Array(g, 40, 4));
  frame.forEach((x, i) => assert.ok(Math.abs(x - OMNIMAX_FRAME[i]) < 1e-7, `frame ${frame}`));
  params.forEach((x, i) => assert.ok(Math.abs(x - OMNIMAX_PARAMS[i]) < 1e-6, `params ${params}`));
  const got = await page.evaluate(() => {
    const gr = window.studio.greene;
    gr.renderAt(2);
    return { w: gr.OMNI.width, h: gr.OMNI.height, dirs: window.carry(gr.omniDirections()), px: window.carry(gr.omniPixels().data) };
  });
  const dirs = carried(got.dirs, Float32Array);
  const px = carried(got.px);
  const { w, h } = got;
  const body = new Float32Array(3 * w * h);
  for (let y = 0; y < h; y++) for (let x = 0; x < w; x++) body.set([(x + 0.5) / w, (y + 0.5) / h, 0], 3 * (y * w + x));
  const core = (await directions(s, OMNIMAX_SPEC, body)).dirs;
  let worst = 0;
  let inDisk = 0;
  for (let i = 0; i < w * h; i++) {
    const c = core.subarray(3 * i, 3 * i + 3);
    const mine = dirs.subarray(4 * i, 4 * i + 3);
    if (!c.every(Number.isFinite)) {
      assert.equal(dirs[4 * i + 3], 0, `pixel ${i}: a direction off the disk`);
      assert.equal(px[4 * i + 3], 0, `pixel ${i}: drawn off the disk`);
      continue;
    }
    inDisk++;
    assert.equal(dirs[4 * i + 3], 1, `pixel ${i}: no direction in the disk`);
    assert.equal(px[4 * i + 3], 255, `pixel ${i}: not drawn in the disk`);
    worst = Math.max(worst, angle(Array.from(mine), Array.from(c)));
  }
  console.log(`Omnimax ${w}×${h}: ${inDisk} pixels in the disk, worst ${worst.toExponential(2)} rad from the core's fisheye`);
  // The disk's share of the square, π/4.
  assert.ok(Math.abs(inDisk / (w * h) - Math.PI / 4) < 0.01);
  assert.ok(worst < 1e-4, `worst ${worst} rad`);
  // The disk's centre looks up, its top (row 1: θ = 88.9°) towards +Z.
  assert.ok(angle(Array.from(dirs.subarray(4 * ((h / 2) * w + w / 2), 4 * ((h / 2) * w + w / 2) + 3)), [0, 1, 0]) < 0.01);
  assert.ok(angle(Array.from(dirs.subarray(4 * (1 * w + w / 2), 4 * (1 * w + w / 2) + 3)), [0, 0, 1]) < 0.03);
});

test('the panel opens from its button and from greene=1; a paused frame is a function of t', async () => {
  assert.equal(await page.isHidden('#greene'), false, 'greene=1 opened it');
  const frame = (t) =>
    page.evaluate((t) => {
      const g = window.studio.greene;
      g.renderAt(t);
      return window.carry(g.viewPixels().data) + '|' + window.carry(g.omniPixels().data);
    }, t);
  const a = await frame(3.25);
  const b = await frame(3.25);
  const c = await frame(3.75);
  assert.ok(a === b, 'the same t drew different pixels');
  assert.ok(a !== c, 'another t drew the same pixels');
  // The panel paused stays paused: no animation frame redraws it.
  await page.waitForTimeout(300);
  assert.equal(await page.evaluate(() => window.studio.greene.t), 3.75);

  const other = await chromium.newPage({ deviceScaleFactor: 1 });
  const otherLogs = [];
  other.on('pageerror', (e) => otherLogs.push(String(e)));
  try {
    await other.goto(s.url);
    await other.waitForFunction(() => window.studio?.greene, null, { timeout: 60000 });
    await other.evaluate(() => window.studio.ready);
    assert.equal(await other.isHidden('#greene'), true, 'closed without greene=1');
    await other.click('#greene-toggle');
    await other.evaluate(() => window.studio.greene.ready);
    assert.equal(await other.isHidden('#greene'), false, 'the button opened it');
    assert.match(await other.evaluate(() => location.search), /greene=1/);
    // It animates: t advances.
    await other.waitForFunction(() => window.studio.greene.t > 0.2, null, { timeout: 60000 });
    const timing = await other.evaluate(() => {
      const g = window.studio.greene;
      g.pause();
      const frames = [];
      for (let k = 0; k < 5; k++) frames.push(g.renderAt(1 + k / 10));
      return { size: g.size, frames, stats: document.getElementById('greene-stats').textContent };
    });
    const mean = (key) => timing.frames.reduce((x, f) => x + f[key], 0) / timing.frames.length;
    console.log(`SwiftShader, capture 6×${timing.size}²: ${mean('totalMs').toFixed(1)} ms a frame (capture ${mean('captureMs').toFixed(1)}, view ${mean('viewMs').toFixed(1)}, Omnimax ${mean('omniMs').toFixed(1)})`);
    assert.match(timing.stats, /frame [\d.]+ ms: capture \(6 × 128²\)/);
    await other.click('#greene-toggle');
    assert.equal(await other.isHidden('#greene'), true, 'the button closed it');
    // The viewport still draws.
    const px = await other.evaluate(() => Array.from(window.studio.pixels().data.slice(0, 4)));
    assert.equal(px[3], 255);
    if (process.env.STUDIO_SHOTS) {
      await page.screenshot({ path: path.join(process.env.STUDIO_SHOTS, 'studio-greene.png'), fullPage: true });
    }
    assert.deepEqual(otherLogs, []);
  } finally {
    await other.close();
  }
  assert.deepEqual(logs.filter((l) => /error/i.test(l)), []);
});
