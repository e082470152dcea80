// The studio's GPU side in headless Chromium (SwiftShader): every projection's shader
// (web/glsl/, direction -> texture coordinates) against the core on a dense grid of its
// texture coordinates, edges, seams and rims included.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import path from 'node:path';
import { browser, studio, run, tempDir, readPng, againstRender, carrying, viewportPixels, sphereScene } from './lib.mjs';


let chromium;
let work;
before(async () => {
  chromium = await browser();
  work = tempDir('mirrorball-studio-gpu-');
});
after(async () => {
  await chromium?.close();
  work?.remove();
});

// [kind, spec]: the parameters the shaders take from the server (frames, lenses, fields of
// view); every kind the server lists with a shader is checked at its defaults too
// (`withDefaults`), so a new projection is checked without a line here.
const SPECS = [
  ['continuous-cube', 'continuous-cube'],
  ['eac', 'eac'],
  ['mercator', 'mercator'],
  ['mercator', 'mercator:max-lat=60'],
  ['angular', 'angular'],
  ['angular', 'angular:look=0,1,0'],
  ['fisheye', 'fisheye'],
  ['fisheye', 'fisheye:fov=200:lens=equisolid:look=1,0,0'],
  ['fisheye', 'fisheye:fov=170:lens=stereographic'],
  ['fisheye', 'fisheye:fov=150:lens=orthographic:look=0,-1,0'],
  ['octahedral', 'octahedral'],
  ['equal-area-octahedral', 'equal-area-octahedral'],
  ['cylindrical', 'cylindrical'],
  ['cylindrical-equal-area', 'cylindrical-equal-area'],
  ['half-equirect', 'half-equirect'],
  ['hammer', 'hammer'],
  ['sinusoidal', 'sinusoidal'],
  ['perspective', 'perspective'],
  ['perspective', 'perspective:hfov=120:vfov=80:yaw=30:pitch=-20:roll=10'],
  ['pannini', 'pannini'],
  ['pannini', 'pannini:d=2:hfov=200:vfov=100:yaw=-45'],
];

/** The server's projections (state.rs `projections`: the core's table) that have a shader. */
async function drawnProjections(s) {
  const page = await chromium.newPage();
  try {
    await page.goto(s.url);
    await page.waitForFunction(() => window.studio, null, { timeout: 60000 });
    await page.evaluate(() => window.studio.ready);
    const listed = await page.evaluate(() => window.studio.view.state.projections);
    return listed.filter((p) => p.gpu).map((p) => p.name);
  } finally {
    await page.close();
  }
}

/** SPECS with every drawn kind at its defaults added. */
function withDefaults(kinds) {
  const specs = [...SPECS];
  for (const k of kinds) if (!specs.some(([, spec]) => spec === k)) specs.push([k, k]);
  return specs;
}

test("every projection's shader gives the core's texture coordinates on a dense grid", async () => {
  const s = await studio();
  const page = await chromium.newPage();
  const logs = [];
  page.on('pageerror', (e) => logs.push(String(e)));
  try {
    await page.goto(s.url);
    await page.waitForFunction(() => window.studio, null, { timeout: 60000 });
    await page.evaluate(() => window.studio.ready);
    const kinds = await drawnProjections(s);
    assert.ok(kinds.length >= 19, `${kinds.length} projections drawn`);
    for (const [kind] of SPECS) assert.ok(kinds.includes(kind), kind);
    const menu = await page.$$eval('#projection option', (o) => o.map((x) => x.value));
    for (const k of kinds) assert.ok(menu.includes(k), `the projection menu lacks ${k}`);
    const failures = [];
    for (const [kind, spec] of withDefaults(kinds)) {
      const r = await page.evaluate(
        ([kind, spec]) => {
          const c = document.createElement('canvas');
          const gl = c.getContext('webgl2');
          return window.studio.G.checkProjection(gl, { kind, spec, n: 128 });
        },
        [kind, spec],
      );
      console.log(`${spec}: ${r.count} directions, worst ${r.worst.toExponential(2)}, ${r.seams} on seams, ${r.failed} failed`);
      if (r.count <= 10000 || r.failed > 0 || r.worst > 1e-4) {
        failures.push(`${spec}: ${r.count} directions, ${r.failed} failed ${JSON.stringify(r.failures.slice(0, 3))}`);
      }
    }
    assert.deepEqual(failures, [], logs.join('\n'));
  } finally {
    await page.close();
    s.stop();
  }
});

// The mirror sphere in mode 3 with the environment converted to each newer projection: the
// embed view's pixels against `mirrorball render` of the same scene (the pattern of
// studio.test.mjs, at a smaller size): 99% of the covered pixels away from the silhouette
// within 2/255, the background (black where a view or fisheye does not reach) likewise.
test('the embed view draws the mirror sphere as mirrorball render does in every projection it has a shader for (mode 3)', async () => {
  const scene = sphereScene(work.dir, 'sphere.json', {
    camera: { eye: [0, 0.4, 3.2], target: [0, 0, 0], fov: 40, width: 96, height: 72 },
  });
  const s = await studio([scene]);
  const bad = [];
  try {
    for (const proj of await drawnProjections(s)) {
      const size = 128;
      const page = await chromium.newPage({ deviceScaleFactor: 1 });
      await carrying(page);
      await page.goto(`${s.url}&view=viewport&mode=3&projection=${proj}&size=${size}`);
      await page.waitForFunction(() => window.studio, null, { timeout: 60000 });
      await page.evaluate(() => window.studio.ready);
      const gpu = (await viewportPixels(page)).data;
      await page.close();
      const png = (extra) => {
        const out = path.join(work.dir, `cpu-${proj}-${extra.length}.png`);
        run(['render', scene, '-o', out, '--quiet', '--ss', '1', '--mode', '3', '--env-as', proj, '--env-size', String(size), ...extra]);
        return readPng(readFileSync(out));
      };
      const full = png([]);
      const cover = png(['--no-background']);
      assert.equal(gpu.length, 4 * full.width * full.height);
      const { n, within, bg, bgWithin } = againstRender(gpu, full, cover);
      console.log(`${proj}: ${((100 * within) / n).toFixed(2)}% of ${n} covered pixels within 2/255, background ${((100 * bgWithin) / bg).toFixed(2)}%`);
      if (n < 200 || within / n < 0.99 || bgWithin / bg < 0.99) bad.push(`${proj}: ${within}/${n} covered, ${bgWithin}/${bg} background`);
    }
  } finally {
    s.stop();
  }
  assert.deepEqual(bad, []);
});
