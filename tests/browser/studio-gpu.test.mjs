// The studio's GPU side in headless Chromium (SwiftShader): every projection's shader
// (web/glsl/, direction -> texture coordinates) against the core on a dense grid of its
// texture coordinates, edges, seams and rims included.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { browser, studio } from './lib.mjs';


let chromium;
before(async () => {
  chromium = await browser();
});
after(async () => {
  await chromium?.close();
});

// [kind, spec]: each kind of the core (ProjectionKind::ALL) at its defaults, and the
// parameters the shaders take from the server (frames, lenses, fields of view).
const SPECS = [
  ['continuous-cube', 'continuous-cube'],
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

test("every projection's shader gives the core's texture coordinates on a dense grid", async () => {
  const s = await studio();
  const page = await chromium.newPage();
  const logs = [];
  page.on('pageerror', (e) => logs.push(String(e)));
  try {
    await page.goto(s.url);
    await page.waitForFunction(() => window.studio, null, { timeout: 60000 });
    await page.evaluate(() => window.studio.ready);
    const kinds = await page.evaluate(() => window.studio.G.KINDS);
    for (const [kind] of SPECS) assert.ok(kinds.includes(kind), kind);
    const menu = await page.$$eval('#projection option', (o) => o.map((x) => x.value));
    for (const k of kinds) assert.ok(menu.includes(k), `the projection menu lacks ${k}`);
    const failures = [];
    for (const [kind, spec] of SPECS) {
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
