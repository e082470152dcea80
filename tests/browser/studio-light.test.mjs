// The studio's prefiltered lighting in headless Chromium: the embed view's lit sphere (and the
// bundled bunny, a loaded mesh) against
// `mirrorball prefilter` of the same environment, read back here (its KTX2 chain: each
// pixel's reflected direction looked up bilinearly at the slider's level, trilinearly
// between two; its SH JSON: E/π at each pixel's normal), and the page's panel (progress,
// the slider, the URL).
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync, writeFileSync } from 'node:fs';
import path from 'node:path';
import { browser, run, tempDir, studio, openStudio, viewportPixels, carried, ROOT } from './lib.mjs';

let chromium;
let work;
const VENICE = path.join(ROOT, 'assets', 'env', 'venice.exr');
// Level 0's face edge: seven levels, 64² to 1².
const SIZE = 64;

before(async () => {
  chromium = await browser();
  work = tempDir('mirrorball-studio-light-');
});
after(async () => {
  await chromium?.close();
  work?.remove();
});

/** A KTX2 cube of RGBA16F or RGBA32F, uncompressed: `{ size, levels: [[face Float32Array × 6]] }`. */
function readKtx2Cube(bytes) {
  const b = Buffer.from(bytes);
  assert.equal(b.toString('latin1', 1, 7), 'KTX 20');
  const vkFormat = b.readUInt32LE(12);
  const size = b.readUInt32LE(20);
  const faces = b.readUInt32LE(36);
  const count = b.readUInt32LE(40);
  assert.equal(b.readUInt32LE(44), 0, 'supercompressed');
  assert.equal(faces, 6);
  const half = { 97: true, 109: false }[vkFormat];
  assert.notEqual(half, undefined, `vkFormat ${vkFormat}`);
  const levels = [];
  for (let m = 0; m < count; m++) {
    const at = Number(b.readBigUInt64LE(80 + 24 * m));
    const s = Math.max(1, size >> m);
    const level = [];
    for (let f = 0; f < 6; f++) {
      const face = new Float32Array(4 * s * s);
      for (let i = 0; i < 4 * s * s; i++) {
        face[i] = half ? halfToFloat(b.readUInt16LE(at + 2 * (f * 4 * s * s + i))) : b.readFloatLE(at + 4 * (f * 4 * s * s + i));
      }
      level.push(face);
    }
    levels.push(level);
  }
  return { size, levels, half };
}

/** IEEE binary16 to a number. */
function halfToFloat(h) {
  const e = (h >> 10) & 31;
  const f = h & 1023;
  const sign = h & 0x8000 ? -1 : 1;
  if (e === 0) return sign * f * 2 ** -24;
  if (e === 31) return f ? NaN : sign * Infinity;
  return sign * (1 + f / 1024) * 2 ** (e - 15);
}

/**
 * The OpenGL cube face and (s, t) of direction d (OpenGL 4.6 §8.13, table 8.19), written here
 * from the specification.
 */
function cubeFace(d) {
  const [x, y, z] = d;
  const [ax, ay, az] = d.map(Math.abs);
  let face, sc, tc, ma;
  if (ax >= ay && ax >= az) [face, sc, tc, ma] = x > 0 ? [0, -z, -y, ax] : [1, z, -y, ax];
  else if (ay >= az) [face, sc, tc, ma] = y > 0 ? [2, x, z, ay] : [3, x, -z, ay];
  else [face, sc, tc, ma] = z > 0 ? [4, x, -y, az] : [5, -x, -y, az];
  return { face, s: (sc / ma + 1) / 2, t: (tc / ma + 1) / 2 };
}

/**
 * Level `m` of the chain bilinearly at direction d, within one face; null where the four
 * texels are not all on the face (the GPU filters across the seam there).
 */
function bilinear(chain, m, d) {
  const s = Math.max(1, chain.size >> m);
  const { face, s: u, t: v } = cubeFace(d);
  const x = u * s - 0.5;
  const y = v * s - 0.5;
  const x0 = Math.floor(x);
  const y0 = Math.floor(y);
  if (s > 1 && (x0 < 0 || y0 < 0 || x0 + 1 > s - 1 || y0 + 1 > s - 1)) return null;
  const data = chain.levels[m][face];
  const at = (i, j) => {
    const k = 4 * (Math.min(s - 1, Math.max(0, j)) * s + Math.min(s - 1, Math.max(0, i)));
    return [data[k], data[k + 1], data[k + 2]];
  };
  const fx = x - x0;
  const fy = y - y0;
  const [a, b, c, e] = [at(x0, y0), at(x0 + 1, y0), at(x0, y0 + 1), at(x0 + 1, y0 + 1)];
  return [0, 1, 2].map((k) => {
    const top = a[k] + fx * (b[k] - a[k]);
    const bottom = c[k] + fx * (e[k] - c[k]);
    return top + fy * (bottom - top);
  });
}

/** The chain trilinearly at fractional level `lod` (null across a seam of either level). */
function trilinear(chain, lod, d) {
  const m0 = Math.floor(lod);
  const f = lod - m0;
  const a = bilinear(chain, m0, d);
  if (f === 0 || !a) return a;
  const b = bilinear(chain, m0 + 1, d);
  return b && a.map((x, k) => x + f * (b[k] - x));
}

/**
 * Linear radiance as `mirrorball render` writes it to a PNG (render's tone.rs): times
 * 2^exposure, the tone curve (clamp, Reinhard x/(1 + x), Narkowicz's ACES fit), then 8-bit
 * sRGB (IEC 61966-2-1).
 */
function display(c, exposure, tone) {
  const curve = {
    clamp: (x) => Math.min(x, 1),
    reinhard: (x) => x / (1 + x),
    aces: (x) => Math.min(1, Math.max(0, (x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14))),
  }[tone];
  assert.ok(curve, `tone ${tone}`);
  return c.map((x) => {
    const l = Math.min(1, Math.max(0, curve(Number.isFinite(x) ? Math.max(0, x * 2 ** exposure) : 0)));
    const e = l <= 0.0031308 ? 12.92 * l : 1.055 * l ** (1 / 2.4) - 0.055;
    return Math.round(255 * e);
  });
}

/** E/π at unit normal n from nine [r, g, b] coefficients: the basis as the SH JSON's `basis` states it. */
function shEval(c, n) {
  const [x, y, z] = n;
  const y9 = [
    0.282095,
    0.488603 * y,
    0.488603 * z,
    0.488603 * x,
    1.092548 * x * y,
    1.092548 * y * z,
    0.315392 * (3 * z * z - 1),
    1.092548 * x * z,
    0.546274 * (x * x - y * y),
  ];
  return [0, 1, 2].map((k) => y9.reduce((acc, yi, i) => acc + yi * c[i][k], 0));
}

const SCENE = {
  meshes: [{ mesh: 'sphere', tessellation: 32 }],
  camera: { eye: [0, 0.4, 3.2], target: [0, 0, 0], fov: 40, width: 160, height: 120 },
  environment: { file: VENICE, projection: 'latlong', attach: 'world', filter: 'bilinear' },
  material: { kind: 'mirror' },
  background: false,
};

/** The embed view's pixels and the page's own surface (positions, normals) and camera. */
async function embedded(url) {
  const { page, logs } = await openStudio(chromium, url);
  try {
    const got = await page.evaluate(async () => {
      const st = window.studio;
      const p = st.pixels();
      const surf = await st.sim.surface();
      const s = st.view.state.scene;
      return {
        width: p.width,
        height: p.height,
        data: window.carry(p.data),
        position: window.carry(surf.position),
        normal: window.carry(surf.normal),
        eye: st.camera().eye,
        tint: s.objects[0].material.tint,
        exposure: s.exposure,
        tone: s.tone,
        intensity: s.environment.intensity,
        level: st.view.lighting && st.P.levelOf(st.view.lighting.header, st.view.roughness),
        header: st.view.lighting && st.view.lighting.header,
      };
    });
    return {
      ...got,
      data: carried(got.data),
      position: carried(got.position, Float32Array),
      normal: carried(got.normal, Float32Array),
    };
  } catch (e) {
    throw new Error(`${e}\n${logs.join('\n')}`);
  } finally {
    await page.close();
  }
}

/** Each covered pixel's page value against `reference(n, r)` (linear RGB or null): the shares within 1 and 2 of 255. */
function compare(got, reference) {
  const { width: w, height: h } = got;
  let n = 0;
  let within1 = 0;
  let within2 = 0;
  let worst = 0;
  let skipped = 0;
  for (let i = 0; i < w * h; i++) {
    if (got.normal[4 * i + 3] !== 1) continue;
    const nrm = got.normal.slice(4 * i, 4 * i + 3);
    const pos = got.position.slice(4 * i, 4 * i + 3);
    let v = pos.map((p, k) => p - got.eye[k]);
    const l = Math.hypot(...v);
    v = v.map((x) => x / l);
    const dot = v[0] * nrm[0] + v[1] * nrm[1] + v[2] * nrm[2];
    const r = v.map((x, k) => x - 2 * dot * nrm[k]);
    const ref = reference(nrm, r);
    if (!ref) {
      skipped++;
      continue;
    }
    const want = display(ref.map((x, k) => x * got.tint[k] * got.intensity), got.exposure, got.tone);
    const d = Math.max(...[0, 1, 2].map((k) => Math.abs(got.data[4 * i + k] - want[k])));
    n++;
    if (d <= 1) within1++;
    if (d <= 2) within2++;
    worst = Math.max(worst, d);
  }
  return { n, skipped, within1: within1 / n, within2: within2 / n, worst };
}

test("the lit sphere's pixels are mirrorball prefilter's chain and SH9 of the same environment", async () => {
  const scene = path.join(work.dir, 'sphere.json');
  writeFileSync(scene, JSON.stringify(SCENE));
  const chainFile = path.join(work.dir, 'ggx.ktx2');
  run(['prefilter', VENICE, chainFile, '--lobe', 'ggx', '--size', String(SIZE), '--mapping', 'linear', '--precision', 'half', '--no-preview', '--quiet']);
  const chain = readKtx2Cube(readFileSync(chainFile));
  assert.equal(chain.levels.length, 7);
  const shFile = path.join(work.dir, 'lambert.ktx2');
  run(['prefilter', VENICE, shFile, '--lobe', 'lambert', '--no-preview', '--quiet']);
  const sh = JSON.parse(readFileSync(path.join(work.dir, 'lambert.sh.json'), 'utf8'));
  assert.equal(sh.window, 'none');
  const s = await studio([scene]);
  try {
    const base = `${s.url}&view=viewport&mode=3&lightsize=${SIZE}`;
    // The chain the server made is prefilter's, texel for texel.
    {
      const { page } = await openStudio(chromium, `${base}&material=ggx&roughness=0`);
      const levels = await page.evaluate(async () => {
        const l = window.studio.P.parseLighting(await (await window.studio.G.api(`/api/lighting?size=64&mapping=linear`)).arrayBuffer());
        return l.levels.map((x) => window.carry(x));
      }).then((ls) => ls.map((x) => carried(x, Uint16Array)));
      await page.close();
      let worst = 0;
      levels.forEach((bits, m) => {
        const s2 = Math.max(1, SIZE >> m) ** 2;
        for (let i = 0; i < bits.length; i++) {
          const f = Math.floor(i / (4 * s2));
          const want = chain.levels[m][f][i % (4 * s2)];
          const got = halfToFloat(bits[i]);
          worst = Math.max(worst, Math.abs(got - want) / Math.max(1e-3, Math.abs(want)));
        }
      });
      console.log(`the server's chain against prefilter's KTX2: worst relative difference ${worst.toExponential(2)}`);
      assert.ok(worst <= 2e-3, `the server's chain is not prefilter's: ${worst}`);
    }
    // Levels 0 to 4 and between them (64² to 4²); on the 2² and 1² levels every read
    // crosses a face edge, where the GPU filters seamlessly and this reference does not go.
    for (const roughness of [0, 0.5, 0.25, 0.6]) {
      const got = await embedded(`${base}&material=ggx&roughness=${roughness}`);
      assert.equal(got.header.levels, 7);
      assert.equal(got.level, roughness * 6, 'the level is not linear mapping\'s r·(L − 1)');
      const r = compare(got, (n, dir) => trilinear(chain, got.level, dir));
      console.log(
        `GGX roughness ${roughness} (level ${got.level}): ${(100 * r.within1).toFixed(2)}% of ${r.n} pixels within 1/255, ${(100 * r.within2).toFixed(2)}% within 2/255, worst ${r.worst}; ${r.skipped} beside a face edge left out`,
      );
      assert.ok(r.n > 3000, `only ${r.n} pixels compared`);
      // The texels are the same halves (checked above) and the reference filters as the GPU
      // does, so what is left is the GPU's filter weights (a few bits of sub-texel precision)
      // and the rounding to 8 bits: within 1/255, 2 at worst. Neighbouring levels miss by
      // tens of levels (a wrong level or direction fails).
      assert.ok(r.within1 >= 0.995, `roughness ${roughness}: ${(100 * r.within1).toFixed(2)}% within 1/255`);
      assert.ok(r.worst <= 2, `roughness ${roughness}: worst ${r.worst}/255`);
    }
    const got = await embedded(`${base}&material=lambert`);
    const r = compare(got, (n) => shEval(sh.irradiance_over_pi, n));
    console.log(`Lambert SH9: ${(100 * r.within1).toFixed(2)}% of ${r.n} pixels within 1/255, ${(100 * r.within2).toFixed(2)}% within 2/255, worst ${r.worst}`);
    // The page's SH sum is in f32 against the test's f64 with the JSON's six-digit basis
    // constants: far below 1/255 but for the rounding to 8 bits.
    assert.ok(r.n > 3000);
    assert.ok(r.within1 >= 0.995, `${(100 * r.within1).toFixed(2)}% within 1/255`);
    assert.ok(r.worst <= 2, `worst ${r.worst}/255`);
  } finally {
    s.stop();
  }
});

test("the lit bunny's pixels are prefilter's chain and SH9 too: the lighting on a loaded mesh", async () => {
  const scene = path.join(work.dir, 'bunny.json');
  const BUNNY = path.join(ROOT, 'assets', 'meshes', 'bunny.obj');
  writeFileSync(
    scene,
    JSON.stringify({
      ...SCENE,
      meshes: [{ mesh: BUNNY, normalize: true }],
      camera: { ...SCENE.camera, eye: [0, 0.3, 2.2], width: 200, height: 150 },
    }),
  );
  const chainFile = path.join(work.dir, 'bunny-ggx.ktx2');
  run(['prefilter', VENICE, chainFile, '--lobe', 'ggx', '--size', String(SIZE), '--mapping', 'linear', '--precision', 'half', '--no-preview', '--quiet']);
  const chain = readKtx2Cube(readFileSync(chainFile));
  const shFile = path.join(work.dir, 'bunny-lambert.ktx2');
  run(['prefilter', VENICE, shFile, '--lobe', 'lambert', '--no-preview', '--quiet']);
  const sh = JSON.parse(readFileSync(path.join(work.dir, 'bunny-lambert.sh.json'), 'utf8'));
  const s = await studio([scene]);
  try {
    const base = `${s.url}&view=viewport&mode=3&lightsize=${SIZE}`;
    for (const roughness of [0.25, 0.5]) {
      const got = await embedded(`${base}&material=ggx&roughness=${roughness}`);
      const r = compare(got, (n, dir) => trilinear(chain, got.level, dir));
      console.log(
        `bunny, GGX roughness ${roughness}: ${(100 * r.within1).toFixed(2)}% of ${r.n} pixels within 1/255, ${(100 * r.within2).toFixed(2)}% within 2/255, worst ${r.worst}; ${r.skipped} beside a face edge left out`,
      );
      assert.ok(r.n > 3000, `only ${r.n} pixels compared`);
      assert.ok(r.within1 >= 0.995, `bunny, roughness ${roughness}: ${(100 * r.within1).toFixed(2)}% within 1/255`);
      assert.ok(r.worst <= 2, `bunny, roughness ${roughness}: worst ${r.worst}/255`);
    }
    const got = await embedded(`${base}&material=lambert`);
    const r = compare(got, (n) => shEval(sh.irradiance_over_pi, n));
    console.log(`bunny, Lambert SH9: ${(100 * r.within1).toFixed(2)}% of ${r.n} pixels within 1/255, ${(100 * r.within2).toFixed(2)}% within 2/255, worst ${r.worst}`);
    assert.ok(r.n > 3000);
    assert.ok(r.within1 >= 0.995, `bunny: ${(100 * r.within1).toFixed(2)}% within 1/255`);
    assert.ok(r.worst <= 2, `bunny: worst ${r.worst}/255`);
  } finally {
    s.stop();
  }
});

test('the lighting panel shows the progress, the slider moves the level, the URL keeps the material', async () => {
  const scene = path.join(work.dir, 'panel.json');
  writeFileSync(scene, JSON.stringify({ ...SCENE, background: true }));
  const s = await studio([scene]);
  const { page, logs } = await openStudio(chromium, `${s.url}&lightsize=32`);
  try {
    const seen = [];
    const watch = setInterval(async () => {
      try {
        seen.push(await page.textContent('#lighting-status'));
      } catch {
        /* the page is closing */
      }
    }, 50);
    const mirror = (await viewportPixels(page)).data;
    await page.selectOption('#material', 'ggx');
    await page.waitForFunction(() => window.studio.view.lighting !== null, null, { timeout: 120000 });
    await page.evaluate(() => window.studio.redraw());
    clearInterval(watch);
    assert.ok(seen.some((t) => /prefiltering on the server/.test(t)), `no progress shown: ${JSON.stringify(seen.slice(0, 5))}`);
    const status = await page.textContent('#lighting-status');
    assert.match(status, /^level 2\.50 of 6 \(linear: level = roughness \* \(levels - 1\)\)$/);
    const lit = (await viewportPixels(page)).data;
    await page.evaluate(() => {
      const slider = document.getElementById('roughness');
      slider.value = '1';
      slider.dispatchEvent(new Event('input'));
      return window.studio.redraw();
    });
    assert.match(await page.textContent('#lighting-status'), /^level 5\.00 of 6/);
    const rough = (await viewportPixels(page)).data;
    const meanDiff = (a, b) => a.reduce((acc, v, i) => acc + Math.abs(v - b[i]), 0) / a.length;
    assert.ok(meanDiff(mirror, lit) > 0.5, 'the GGX material draws as the mirror');
    assert.ok(meanDiff(lit, rough) > 0.2, 'the slider does not change the picture');
    const url = new URL(page.url());
    assert.equal(url.searchParams.get('material'), 'ggx');
    assert.equal(url.searchParams.get('roughness'), '1');
    await page.screenshot({ path: path.join(process.env.STUDIO_SHOTS || work.dir, 'studio-lighting-panel.png') });
  } catch (e) {
    throw new Error(`${e}\n${logs.join('\n')}`);
  } finally {
    await page.close();
    s.stop();
  }
});
