// How fast `mirrorball studio` is, as a person meets it (issue 18's speed item), in one run:
//
//   1. the viewport's frame time at 1280×720 (`?view=viewport`, the bunny in a lat-long
//      environment) in headless Chromium's SwiftShader WebGL2, for each indexing mode 1-4:
//      median and worst over FRAMES draws, each timed from the page's `window.studio.draw()`
//      to `gl.finish()` and a one-pixel `readPixels` (which waits for the frame to be done);
//      then the viewport with its twin (side by side) redrawn, and a Greene live frame (the
//      six-face capture, the view, the Omnimax frame) at 6×128² and 6×256²;
//   2. the server's time to deliver a 1024² cube from a 4096×2048 EXR
//      (`GET /api/environment?projection=cube&size=1024&precision=half`, from node's fetch,
//      to the last byte): cold (the server keeps only its last conversion, so a tiny one is
//      asked for in between) and cached;
//   3. the page's responsiveness meanwhile: a requestAnimationFrame loop drawing the viewport
//      each frame, its longest interval while the page itself asks for that cube (the
//      issue's target: no frame over 100 ms), beside the longest with the server idle.
//
//     cargo build -p mirrorball-cli && node bench/studio_speed.mjs
//
// It runs target/release/mirrorball if built, else target/debug/mirrorball ($MIRRORBALL
// overrides), and says which; Chromium is /usr/bin/chromium ($CHROMIUM overrides).
import { existsSync, writeFileSync } from 'node:fs';
import { execFileSync } from 'node:child_process';
import path from 'node:path';
import { loadavg } from 'node:os';
import { browser, studio, openStudio, tempDir, ROOT } from '../tests/browser/lib.mjs';

const FRAMES = Number(process.env.FRAMES || 30);
const COLD = Number(process.env.COLD || 3);

if (!process.env.MIRRORBALL) {
  const release = path.join(ROOT, 'target', 'release', 'mirrorball');
  const debug = path.join(ROOT, 'target', 'debug', 'mirrorball');
  process.env.MIRRORBALL = existsSync(release) ? release : debug;
}
const BINARY = process.env.MIRRORBALL;
if (!existsSync(BINARY)) {
  console.error(`bench/studio_speed.mjs: no ${BINARY}: run \`cargo build -p mirrorball-cli\` first`);
  process.exit(1);
}
const BUILD = /[\\/]release[\\/]/.test(BINARY) ? 'release' : /[\\/]debug[\\/]/.test(BINARY) ? 'debug' : 'custom';

const median = (xs) => {
  const s = [...xs].sort((a, b) => a - b);
  return s.length % 2 ? s[(s.length - 1) / 2] : (s[s.length / 2 - 1] + s[s.length / 2]) / 2;
};
const ms = (x) => `${x.toFixed(1)} ms`;

/// The bunny scene of examples/scenes/bunny-cones.json at `width`×`height` in `env`, written
/// to `dir`.
function scene(dir, name, env, [width, height] = [1280, 720]) {
  const file = path.join(dir, name);
  writeFileSync(file, JSON.stringify({
    meshes: [{ mesh: path.join(ROOT, 'assets', 'meshes', 'bunny.obj'), normalize: true }],
    camera: { eye: [0.8, 0.4, 3.0], target: [0, 0, 0], fov: 40, width, height },
    environment: { file: env, projection: 'latlong', attach: 'world', filter: 'ewa' },
    material: { kind: 'mirror' },
    indexing: 'cone',
    supersample: 1,
  }, null, 2));
  return file;
}

/// GET `what` from the studio at `url` as the page asks (its token header; node's fetch names
/// the server in `Host` and sends no `Origin`, as guard.rs wants); resolves to
/// `{ ms, bytes }` once the whole body is here.
async function timedGet(url, what) {
  const u = new URL(url);
  const t0 = performance.now();
  const r = await fetch(new URL(what, u.origin), { headers: { 'x-mirrorball-token': u.searchParams.get('token') } });
  const body = await r.arrayBuffer();
  const t = performance.now() - t0;
  if (!r.ok) throw new Error(`${what}: ${r.status} ${new TextDecoder().decode(body)}`);
  return { ms: t, bytes: body.byteLength };
}

const CUBE = '/api/environment?projection=cube&size=1024&precision=half';
const EVICT = '/api/environment?projection=cube&size=8&precision=half';

const loadBefore = loadavg()[0];
const tmp = tempDir('mirrorball-studio-speed-');
const chromium = await browser();
const rows = [];
try {
  // 1. Frame time per indexing mode, the bunny in venice.exr (512×256).
  const small = scene(tmp.dir, 'bunny-venice.json', path.join(ROOT, 'assets', 'env', 'venice.exr'));
  const s1 = await studio([small]);
  try {
    for (const mode of [1, 2, 3, 4]) {
      const { page, logs } = await openStudio(chromium, `${s1.url}&view=viewport&mode=${mode}`);
      await page.setViewportSize({ width: 1280, height: 720 });
      const times = await page.evaluate(async (n) => {
        const { draw, gl } = window.studio;
        const px = new Uint8Array(4);
        const once = async () => {
          const t0 = performance.now();
          await draw();
          gl.finish();
          gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, px);
          return performance.now() - t0;
        };
        for (let i = 0; i < 3; i++) await once(); // warm: programs compiled, textures resident
        const out = [];
        for (let i = 0; i < n; i++) out.push(await once());
        return out;
      }, FRAMES);
      const size = await page.evaluate(() => [window.studio.canvas.width, window.studio.canvas.height]);
      if (size[0] !== 1280 || size[1] !== 720) throw new Error(`mode ${mode}: the viewport is ${size.join('×')}, not 1280×720`);
      if (logs.length) console.error(`mode ${mode}: the page said: ${logs.join(' | ')}`);
      rows.push([`viewport frame, mode ${mode} (1280×720, ${FRAMES} draws)`, ms(median(times)), ms(Math.max(...times))]);
      await page.close();
    }
    // The viewport with its twin (side by side: the same view drawn again, the map attached
    // the other way, read back and shown on a 2D canvas), mode 3.
    {
      const { page, logs } = await openStudio(chromium, `${s1.url}&mode=3&twin=1&marks=0&edges=0`);
      const times = await page.evaluate(async (n) => {
        const { redraw, view } = window.studio;
        const out = [];
        for (let i = 0; i < 3 + n; i++) {
          const t0 = performance.now();
          await redraw();
          if (i >= 3) out.push(performance.now() - t0);
        }
        return { out, size: [view.state.scene.camera.width, view.state.scene.camera.height] };
      }, FRAMES);
      if (logs.length) console.error(`twin: the page said: ${logs.join(' | ')}`);
      rows.push([`viewport + twin + simulator, mode 3 (${times.size.join('×')}, ${FRAMES} redraws)`, ms(median(times.out)), ms(Math.max(...times.out))]);
      await page.close();
    }
    // Greene live: the capture (6 faces), the view and the Omnimax frame, each waited for.
    for (const size of [128, 256]) {
      const { page, logs } = await openStudio(chromium, `${s1.url}&greene=1&greene-size=${size}`);
      const t = await page.evaluate(async (n) => {
        const g = window.studio.greene;
        await g.ready;
        g.pause();
        const out = [];
        for (let i = 0; i < 3 + n; i++) {
          const f = g.renderAt(0.1 * i);
          if (i >= 3) out.push(f);
        }
        return out;
      }, FRAMES);
      if (logs.length) console.error(`Greene live: the page said: ${logs.join(' | ')}`);
      const part = (k) => ms(median(t.map((f) => f[k])));
      rows.push([`Greene live frame, 6×${size}² capture (capture ${part('captureMs')}, view ${part('viewMs')}, Omnimax ${part('omniMs')}; ${FRAMES} frames)`, ms(median(t.map((f) => f.totalMs))), ms(Math.max(...t.map((f) => f.totalMs)))]);
      await page.close();
    }
  } finally {
    s1.stop();
  }

  // 2. and 3. A 4096×2048 lat-long EXR (venice.exr upscaled), the studio on it.
  const big = path.join(tmp.dir, 'venice-4096.exr');
  execFileSync(BINARY, ['convert', path.join(ROOT, 'assets', 'env', 'venice.exr'), big, '--to', 'latlong', '--size', '4096', '--quiet'], { stdio: 'inherit' });
  // The responsiveness page draws at 320×180, so that its own frame (SwiftShader's cost, part
  // 1) stays under the 100 ms it is held to and a long interval is the server's doing.
  const s2 = await studio([scene(tmp.dir, 'bunny-4096.json', big, [320, 180])]);
  try {
    const colds = [];
    let bytes = 0;
    for (let i = 0; i < COLD; i++) {
      await timedGet(s2.url, EVICT);
      const r = await timedGet(s2.url, CUBE);
      colds.push(r.ms);
      bytes = r.bytes;
    }
    const cached = await timedGet(s2.url, CUBE);
    rows.push([`GET cube 1024² half from 4096×2048, cold (${COLD} runs; ${(bytes / 2 ** 20).toFixed(1)} MiB)`, ms(median(colds)), ms(Math.max(...colds))]);
    rows.push(['GET cube 1024² half, cached (the last conversion kept)', ms(cached.ms), '']);

    // The page draws every animation frame (mode 1, 320×180; its own environment a 256²
    // cube, so its load is quick), first with the server idle, then while it asks for the
    // 1024² cube, COLD times (the server asked for a tiny cube before each, from node).
    const { page, logs } = await openStudio(chromium, `${s2.url}&view=viewport&mode=1&projection=cube&size=256`);
    const r = await page.evaluate(async ({ cube, evict, rounds }) => {
      const { draw, G } = window.studio;
      const intervals = [];
      let last = null;
      let running = true;
      const loop = new Promise((done) => {
        const tick = async (t) => {
          if (last !== null) intervals.push(t - last);
          last = t;
          await draw();
          if (running) requestAnimationFrame(tick);
          else done();
        };
        requestAnimationFrame(tick);
      });
      await new Promise((ok) => setTimeout(ok, 3000));
      const idle = intervals.splice(0);
      const busy = [];
      const requests = [];
      for (let i = 0; i < rounds; i++) {
        await (await G.api(evict)).arrayBuffer();
        intervals.splice(0);
        const t0 = performance.now();
        await (await G.api(cube)).arrayBuffer();
        requests.push(performance.now() - t0);
        busy.push(...intervals.splice(0));
      }
      running = false;
      await loop;
      return { idle, busy, request: Math.max(...requests) };
    }, { cube: CUBE, evict: EVICT, rounds: COLD });
    if (logs.length) console.error(`responsiveness page said: ${logs.join(' | ')}`);
    rows.push([`rAF interval at 320×180, server idle (${r.idle.length} frames)`, ms(median(r.idle)), ms(Math.max(...r.idle))]);
    rows.push([`rAF interval at 320×180 during the page's cold cube requests (${COLD}, longest ${ms(r.request)}; ${r.busy.length} frames)`, ms(median(r.busy)), ms(Math.max(...r.busy))]);
    await page.close();
  } finally {
    s2.stop();
  }
} finally {
  await chromium.close();
  tmp.remove();
}

const head = ['measure', 'median', 'worst'];
const width = head.map((h, i) => Math.max(h.length, ...rows.map((r) => r[i].length)));
const line = (r) => `| ${r.map((c, i) => c.padEnd(width[i])).join(' | ')} |`;
console.log(`mirrorball studio speed: ${BUILD} build (${path.relative(ROOT, BINARY) || BINARY}), Chromium SwiftShader WebGL2; load average ${loadBefore.toFixed(2)} before, ${loadavg()[0].toFixed(2)} after`);
console.log(line(head));
console.log(`|${width.map((w) => '-'.repeat(w + 2)).join('|')}|`);
for (const r of rows) console.log(line(r));
