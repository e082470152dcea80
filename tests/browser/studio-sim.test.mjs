// The studio's simulator view in headless Chromium: the record pass's texture coordinates
// against `mirrorball render --aovs` (the CPU rasteriser's (u, v, layer) read, decoded by
// ffmpeg), the heat map's worst and mean against the same numbers from the CPU's channels,
// the texel under the cursor, and the view reopened from its URL. The server's directions
// of texture coordinates (what the heat map measures with) are first checked against the
// core's direction grid.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { writeFileSync } from 'node:fs';
import path from 'node:path';
import { browser, run, tempDir, studio, openStudio, viewportPixels, carried, directions, ROOT } from './lib.mjs';
import { heatOf, lookupsOf, angleDeg } from '../../crates/studio/web/sim.js';

let chromium;
let work;
const VENICE = path.join(ROOT, 'assets', 'env', 'venice.exr');

before(async () => {
  chromium = await browser();
  work = tempDir('mirrorball-studio-sim-');
});
after(async () => {
  await chromium?.close();
  work?.remove();
});

async function open(url) {
  const { page, logs } = await openStudio(chromium, url);
  const errors = await page.$$eval('#messages .error', (es) => es.map((e) => e.textContent));
  assert.deepEqual(errors, [], 'the page shows errors');
  assert.deepEqual(logs.filter((l) => /error/i.test(l)), []);
  return page;
}

/** Zimmons' door at 70° (the studio test's door), or the mirror sphere, as a scene file. */
function scene(name) {
  const bodies = {
    door: {
      meshes: [{ mesh: 'quad', tessellation: 1, model: [0.34202, 0, -0.93969, 0, 0, 1, 0, 0, 0.93969, 0, 0.34202, 0, 0, 0, 0, 1] }],
      camera: { eye: [0, 0, 2.2], target: [0, 0, 0], fov: 60, width: 128, height: 128 },
    },
    sphere: {
      meshes: [{ mesh: 'sphere', tessellation: 12 }],
      camera: { eye: [0, 0.4, 3.2], target: [0, 0, 0], fov: 40, width: 160, height: 120 },
    },
  };
  const file = path.join(work.dir, `${name}.json`);
  writeFileSync(
    file,
    JSON.stringify({
      ...bodies[name],
      environment: { file: VENICE, projection: 'latlong', attach: 'world', filter: 'bilinear' },
      material: { kind: 'mirror' },
      background: true,
    }),
  );
  return file;
}

/**
 * `mirrorball render SCENE --aovs` under `args`: its (u, v, layer) channel (out-st.exr,
 * decoded by ffmpeg to planar f32) as RGBA floats a pixel, top row first, alpha 1 where an
 * object read the environment (layer ≥ 0).
 */
function cpuSt(file, args) {
  const out = path.join(work.dir, `cpu-${Math.random().toString(36).slice(2)}.png`);
  run(['render', file, '-o', out, '--quiet', '--ss', '1', '--aovs', ...args]);
  const st = out.replace(/\.png$/, '-st.exr');
  const raw = execFileSync('ffmpeg', ['-v', 'error', '-i', st, '-f', 'rawvideo', '-pix_fmt', 'gbrpf32le', '-'], { maxBuffer: 1 << 28 });
  const f = new Float32Array(raw.buffer, raw.byteOffset, raw.length / 4);
  const n = f.length / 3;
  const rgba = new Float32Array(4 * n);
  for (let i = 0; i < n; i++) {
    // gbrp: the planes are G, B, R.
    rgba.set([f[2 * n + i], f[i], f[n + i], f[n + i] >= 0 ? 1 : 0], 4 * i);
  }
  return rgba;
}

test("the server's directions of texture coordinates are the core's grid directions, in every projection the viewport draws", async () => {
  const s = await studio();
  try {
    const specs = ['latlong', 'cube', 'sphere', 'sphere:look=+x', 'paraboloid', 'paraboloid:look=0,1,0', 'eac', 'continuous-cube', 'fisheye:fov=200:lens=equisolid:look=1,0,0', 'hammer', 'octahedral', 'perspective:hfov=120:vfov=80:yaw=30:pitch=-20:roll=10', 'pannini:d=2:hfov=200:vfov=100:yaw=-45'];
    for (const spec of specs) {
      const url = new URL(s.url);
      url.pathname = '/api/grid';
      url.searchParams.set('projection', spec);
      url.searchParams.set('n', '64');
      const b = await (await fetch(url)).arrayBuffer();
      const count = new DataView(b).getUint32(0, true);
      const values = new Float32Array(b, 56, 9 * count);
      // The grid's own points (u, v multiples of 1/64, exact in f32): the core made each
      // direction from them, so the server's direction of them is that direction to f32.
      const rows = [];
      for (let i = 0; i < count; i++) {
        const [u, v] = values.subarray(9 * i + 6, 9 * i + 8);
        if (Number.isInteger(u * 64) && Number.isInteger(v * 64)) rows.push(i);
      }
      const body = new Float32Array(3 * rows.length);
      rows.forEach((i, k) => body.set(values.subarray(9 * i + 6, 9 * i + 9), 3 * k));
      const { dirs } = await directions(s, spec, body);
      assert.equal(dirs.length, body.length);
      let worst = 0;
      rows.forEach((i, k) => {
        const d = Array.from(values.subarray(9 * i, 9 * i + 3));
        const got = Array.from(dirs.subarray(3 * k, 3 * k + 3));
        assert.ok(got.every(Number.isFinite), `${spec}: no direction for ${body.subarray(3 * k, 3 * k + 3)}`);
        worst = Math.max(worst, (angleDeg(got, d) * Math.PI) / 180);
      });
      console.log(`${spec}: ${rows.length} grid points, worst ${worst.toExponential(2)} rad from the grid's direction`);
      assert.ok(rows.length > 2000, `${spec}: ${rows.length} points`);
      assert.ok(worst <= 2e-7, `${spec}: worst ${worst} rad`);
    }
    // Texture coordinates with no direction: NaN, whatever is wrong with them.
    const { dirs } = await directions(s, 'cube', new Float32Array([0.5, 0.5, 6, 0.5, 0.5, -1, NaN, 0.5, 0, Infinity, 0.5, 0, 0.5, 0.5, 5]));
    assert.ok(dirs.subarray(0, 12).every(Number.isNaN), `${dirs}`);
    assert.deepEqual(Array.from(dirs.subarray(12), (x) => x + 0), [0, 0, -1], 'the centre of -Z');
    const off = await directions(s, 'sphere', new Float32Array([0.999, 0.999, 0]));
    assert.ok(off.dirs.every(Number.isNaN), 'a point off the sphere map disk');
    const bad = await directions(s, 'cube', new Uint8Array(13));
    assert.equal(bad.status, 400);
    assert.match(bad.text(), /f32 triples/);
    const unknown = await directions(s, 'nonsense', new Float32Array(3));
    assert.equal(unknown.status, 400);
    assert.match(unknown.text(), /projection/);
  } finally {
    s.stop();
  }
});

const LATLONG = ['--env-as', 'latlong', '--env-size', '256'];

test("the door at 70° under mode 1: the texels read and the heat map's worst and mean are the CPU renderer's", async () => {
  const file = scene('door');
  const s = await studio([file]);
  const page = await open(`${s.url}&mode=1&projection=latlong&size=256&heat=1`);
  try {
    const got = await page.evaluate(() => {
      const sim = window.studio.sim;
      const { worst, mean, count, invalid } = sim.heatStats;
      return { record: window.carry(sim.record), worst, mean, count, invalid, text: document.getElementById('sim-stats').textContent };
    });
    await page.screenshot({ path: path.join(process.env.STUDIO_SHOTS || work.dir, 'studio-sim-door-heat.png') });
    const gpu = carried(got.record, Float32Array);
    const st1 = cpuSt(file, ['--mode', '1', ...LATLONG]);
    const st3 = cpuSt(file, ['--mode', '3', ...LATLONG]);
    assert.equal(gpu.length, st1.length);
    // The texels read: the same (u, v) as the CPU's, within a texel, on the pixels both cover.
    let both = 0;
    let within = 0;
    for (let i = 0; i < gpu.length / 4; i++) {
      if (!(gpu[4 * i + 3] > 0 && st1[4 * i + 3] > 0)) continue;
      both++;
      if (Math.abs(gpu[4 * i] - st1[4 * i]) * 256 <= 1 && Math.abs(gpu[4 * i + 1] - st1[4 * i + 1]) * 128 <= 1) within++;
    }
    const { pixels, body } = lookupsOf(st1, st3);
    const cpu = heatOf(st1.length / 4, pixels, (await directions(s, 'latlong', body)).dirs);
    console.log(`door mode 1: ${within} of ${both} pixels read the CPU's texel (within one); page: ${got.text}`);
    console.log(`CPU channels: worst ${cpu.worst.toFixed(3)}°, mean ${cpu.mean.toFixed(3)}° over ${cpu.count} pixels`);
    assert.ok(both > 3000, `${both} covered pixels`);
    assert.ok(within / both >= 0.99, `${within} of ${both} within a texel`);
    assert.ok(cpu.worst > 10, `the door's mode-1 error is known to be large near the rim: ${cpu.worst}°`);
    assert.ok(Math.abs(got.worst - cpu.worst) <= 0.02 * cpu.worst, `worst ${got.worst}° against the CPU's ${cpu.worst}°`);
    assert.ok(Math.abs(got.mean - cpu.mean) <= 0.01 * cpu.mean, `mean ${got.mean}° against the CPU's ${cpu.mean}°`);
    assert.ok(Math.abs(got.count - cpu.count) <= 0.01 * cpu.count);
    assert.match(got.text, new RegExp(`worst ${got.worst.toFixed(3)}°, mean ${got.mean.toFixed(3)}°`));
  } finally {
    await page.close();
    s.stop();
  }
});

test("the heat map in a newer projection: the door under mode 2 on an equi-angular cube, worst and mean as the CPU renderer's", async () => {
  const file = scene('door');
  const s = await studio([file]);
  const page = await open(`${s.url}&mode=2&projection=eac&size=64&heat=1`);
  try {
    const got = await page.evaluate(() => {
      const { worst, mean, count, invalid } = window.studio.sim.heatStats;
      return { worst, mean, count, invalid, text: document.getElementById('sim-stats').textContent };
    });
    const EAC = ['--env-as', 'eac', '--env-size', '64'];
    const st2 = cpuSt(file, ['--mode', '2', ...EAC]);
    const st3 = cpuSt(file, ['--mode', '3', ...EAC]);
    const { pixels, body } = lookupsOf(st2, st3);
    const cpu = heatOf(st2.length / 4, pixels, (await directions(s, 'eac', body)).dirs);
    console.log(`door mode 2 on EAC: page ${got.text}; CPU channels: worst ${cpu.worst.toFixed(3)}°, mean ${cpu.mean.toFixed(3)}° over ${cpu.count} pixels`);
    assert.ok(cpu.count > 3000, `${cpu.count} covered pixels`);
    assert.equal(got.invalid, 0);
    assert.ok(cpu.worst > 0.5, `mode 2's error on the grazing door is known to be large: ${cpu.worst}°`);
    assert.ok(Math.abs(got.worst - cpu.worst) <= 0.02 * cpu.worst, `worst ${got.worst}° against the CPU's ${cpu.worst}°`);
    assert.ok(Math.abs(got.mean - cpu.mean) <= 0.01 * cpu.mean, `mean ${got.mean}° against the CPU's ${cpu.mean}°`);
    assert.ok(Math.abs(got.count - cpu.count) <= 0.01 * cpu.count);
  } finally {
    await page.close();
    s.stop();
  }
});

test('the texel under the cursor is ringed where the CPU read it, and moves with the cursor', async () => {
  const file = scene('sphere');
  const s = await studio([file]);
  const page = await open(`${s.url}&mode=3&projection=latlong&size=256`);
  try {
    const st3 = cpuSt(file, ['--mode', '3', ...LATLONG]);
    const box = await page.locator('#viewport').boundingBox();
    const seen = [];
    for (const [x, y] of [[80, 60], [70, 48], [95, 75]]) {
      await page.mouse.move(box.x + x + 0.5, box.y + y + 0.5);
      await page.waitForFunction(([x, y]) => window.studio.sim.hover?.pixel.join() === `${x},${y}`, [x, y]);
      const hv = await page.evaluate(() => window.studio.sim.hover);
      const i = 4 * (y * 160 + x);
      const want = [Math.floor(st3[i] * 256), Math.floor(st3[i + 1] * 128)];
      console.log(`pixel ${x},${y}: ring at texel ${hv.texel}, the CPU read ${want}; normal ${hv.normal.map((c) => c.toFixed(3))}`);
      assert.ok(st3[i + 3] > 0 && hv.texel, `pixel ${x},${y} is on the sphere`);
      const dx = Math.abs(hv.texel[0] - want[0]);
      assert.ok(Math.min(dx, 256 - dx) <= 1 && Math.abs(hv.texel[1] - want[1]) <= 1, `ring at ${hv.texel}, the CPU's texel ${want}`);
      assert.ok(Math.abs(Math.hypot(...hv.normal) - 1) < 1e-5);
      // The reflected vector drawn is the one whose texel is ringed.
      const r = (await directions(s, 'latlong', new Float32Array(hv.uvl))).dirs;
      const rl = Math.hypot(...hv.reflected);
      assert.ok(Math.acos(Math.min(1, hv.reflected.reduce((a, c, k) => a + c * r[k], 0) / rl)) < 1e-3);
      seen.push(hv.texel.join());
    }
    assert.equal(new Set(seen).size, 3, 'the ring did not move');
    await page.screenshot({ path: path.join(process.env.STUDIO_SHOTS || work.dir, 'studio-sim-hover.png') });
  } finally {
    await page.close();
    s.stop();
  }
});

test('a view set on the page reopens from its URL with the same pixels', async () => {
  const s = await studio([scene('sphere')]);
  const page = await open(`${s.url}&projection=cube&size=64`);
  try {
    await page.selectOption('#mode', '2');
    await page.click('#sim-heat');
    const box = await page.locator('#viewport').boundingBox();
    const [cx, cy] = [box.x + box.width / 2, box.y + box.height / 2];
    await page.mouse.move(cx, cy);
    await page.mouse.down();
    await page.mouse.move(cx - 40, cy + 15, { steps: 3 });
    await page.mouse.up();
    await page.evaluate(() => window.studio.redraw());
    const url = page.url();
    for (const k of ['mode=2', 'projection=cube', 'yaw=', 'pitch=', 'distance=', 'heat=1']) assert.ok(url.includes(k), `${url} lacks ${k}`);
    const a = (await viewportPixels(page)).data;
    const again = await open(url);
    try {
      const b = (await viewportPixels(again)).data;
      const same = await again.evaluate(() => [window.studio.view.mode, window.studio.view.projection, window.studio.sim.heat]);
      assert.deepEqual(same, [2, 'cube', true]);
      let differ = 0;
      for (let i = 0; i < a.length; i++) if (a[i] !== b[i]) differ++;
      assert.equal(differ, 0, `${differ} bytes differ`);
      const plain = await open(s.url);
      const c = (await viewportPixels(plain)).data;
      await plain.close();
      assert.ok(c.some((x, i) => x !== a[i]), 'the reopened view is the default one');
    } finally {
      await again.close();
    }
  } finally {
    await page.close();
    s.stop();
  }
});

test("the door's triangle edges in texture space enclose every texel it read (mode 1, straight; mode 2, curved)", async () => {
  const s = await studio([scene('door')]);
  try {
    for (const mode of [1, 2]) {
      const page = await open(`${s.url}&mode=${mode}&projection=latlong&size=256`);
      const r = await page.evaluate(() => {
        const sim = window.studio.sim;
        return { corners: sim.edgeLines.corners.map((c) => Array.from(c)), lines: sim.edgeLines.lines, record: window.carry(sim.record) };
      });
      r.record = carried(r.record, Float32Array);
      await page.close();
      assert.equal(r.corners.length, 2, 'the door is two triangles');
      if (mode === 1) {
        // Mode 1 makes (u, v) per vertex: the rasteriser interpolates them linearly, so every
        // pixel's (u, v) lies in one of the two uv triangles, and the edges are 6 straight lines.
        assert.equal(r.lines.length, 6);
        const inside = (p, c) => {
          const [a, b, d] = [0, 1, 2].map((k) => [c[3 * k], c[3 * k + 1]]);
          const x = (q, e, f) => (e[0] - q[0]) * (f[1] - q[1]) - (e[1] - q[1]) * (f[0] - q[0]);
          const s1 = x(p, a, b), s2 = x(p, b, d), s3 = x(p, d, a);
          const eps = 1e-6; // f32 (u, v) on an edge
          return (s1 >= -eps && s2 >= -eps && s3 >= -eps) || (s1 <= eps && s2 <= eps && s3 <= eps);
        };
        let n = 0;
        for (let i = 0; i < r.record.length / 4; i++) {
          if (!(r.record[4 * i + 3] > 0)) continue;
          n++;
          const p = [r.record[4 * i], r.record[4 * i + 1]];
          assert.ok(r.corners.some((c) => inside(p, c)), `pixel ${i}: (u, v) ${p} outside the corners' triangles`);
        }
        assert.ok(n > 3000);
      } else {
        // Mode 2 interpolates directions: each edge is a curve of 17 samples (or pieces of one).
        assert.ok(r.lines.length >= 6);
        const points = r.lines.reduce((a, l) => a + l.length, 0);
        assert.ok(points >= 6 * 17 - 6, `${points} points`);
      }
    }
  } finally {
    s.stop();
  }
});
