// three.js r187 (npm, pinned) in headless Chromium takes what `bake three` writes through
// its stock loaders, as the bake's README.md says (DDSLoader for the PMREM, wrapped as a
// CompressedCubeTexture; HDRCubeTextureLoader for the plain cube), and shows a
// direction-coded environment (colour = ½ + ½·d) the right way round; its shaders read the
// PMREM's rough levels at the roughness mirrorball prefiltered them for.
//
// Pixels are read linear: three renders into a float render target, where it applies
// neither tone mapping nor an output colour transform (NoToneMapping and a linear output
// are set as well for the screenshots).
import test from 'node:test';
import assert from 'node:assert/strict';
import path from 'node:path';
import { bake, browser, directionCoded, prefiltered, serve, tempDir } from './lib.mjs';

// PMREM levels 128…8 (three's LOD_MIN = 3): maxLod 4, so roughness 0.5 is exactly level 3.
const SIZE = 128;
const MAX_LOD = 4;

// Sphere pixels well inside its silhouette (radius ~78 px about 128, 128) and background
// pixels well outside it: left, right, up, down and the diagonals.
const SPHERE_PX = [[128, 128], [78, 128], [178, 128], [128, 78], [128, 178], [93, 93], [163, 163], [93, 163], [163, 93]];
const BACKGROUND_PX = [[10, 128], [246, 128], [128, 10], [128, 246], [20, 20], [236, 236], [20, 236], [236, 20]];

const colour = (d) => d.map((c) => 0.5 + 0.5 * c);
const worst = (got, want) => Math.max(...got.map((g, i) => Math.abs(g - want[i])));
const fmt = (v) => v.map((c) => c.toFixed(4)).join(' ');

test('three.js r187 loads the bake as its PMREM and a cube, right way round, rough levels as prefiltered', async () => {
  const tmp = tempDir();
  const input = directionCoded(path.join(tmp.dir, 'dc.exr'), 512);
  const out = path.join(tmp.dir, 'three');
  const files = bake('three', input, out, SIZE);
  for (const f of ['pmrem.dds', 'README.md', ...['px', 'nx', 'py', 'ny', 'pz', 'nz'].map((n) => `cube/${n}.hdr`)]) {
    assert.ok(files.some((g) => g.endsWith(f)), `${f} among ${files.join(', ')}`);
  }
  const { server, url } = await serve(out);
  const b = await browser();
  try {
    const page = await b.newPage({ viewport: { width: 256, height: 256 } });
    page.on('pageerror', (e) => console.log(`[page error] ${e}`));
    await page.goto(`${url}/three.html`);
    await page.waitForFunction(() => window.ready === true);
    assert.equal(await page.evaluate(() => window.three.revision), '187');
    assert.ok(await page.evaluate(() => window.three.bptc()), 'EXT_texture_compression_bptc, for the BC6H PMREM');
    const render = (c) => page.evaluate((c) => window.three.render(c), { base: `${url}/baked`, ...c });
    const shot = (name) => page.screenshot({ path: path.join(process.env.SHOTS ?? tmp.dir, `three-${name}.png`) });

    // 1. A mirror sphere lit by the PMREM in front of the plain cube. Tolerance 0.02: RGBE
    // keeps 8 mantissa bits (≤ 0.004 here), BC6H on level 0, and three never reads a pure
    // mirror (roughness ≥ 0.045 + the geometry's, so a little of level 1 and of the diffuse
    // level mixes in); measured ≤ 0.007. Seen mirrored in x (or y, or z), the off-centre
    // points would be ≥ 0.15 off, which the second check shows.
    const mirror = await render({ roughness: 0, pixels: [...SPHERE_PX, ...BACKGROUND_PX] });
    await shot('mirror');
    assert.deepEqual(mirror.pmrem, { levels: [128, 64, 32, 16, 8], isCube: true, cube: true });
    for (const p of mirror.pixels) {
      const d = p.kind === 'sphere' ? p.reflected : p.view;
      const want = colour(d);
      const err = worst(p.rgb, want);
      assert.equal(p.kind, SPHERE_PX.some(([x, y]) => x === p.x && y === p.y) ? 'sphere' : 'background');
      assert.ok(err < 0.02, `${p.kind} (${p.x}, ${p.y}) shows ${fmt(p.rgb)}, direction ${fmt(d)} is ${fmt(want)}: off by ${err.toFixed(4)}`);
      for (const axis of [0, 1]) {
        if (Math.abs(d[axis]) < 0.3) continue;
        const flipped = d.map((c, i) => (i === axis ? -c : c));
        assert.ok(worst(p.rgb, colour(flipped)) > 0.15, `${p.kind} (${p.x}, ${p.y}) would also pass mirrored in ${'xy'[axis]}`);
      }
    }

    // 2. Which level three reads at which roughness: a PMREM whose level lod is the constant
    // lod, as the background blurred by three's lodToRoughness(lod): each reads exactly lod.
    for (let lod = 0; lod <= MAX_LOD; lod++) {
      const r = await page.evaluate(([l, m]) => window.three.lodToRoughness(l, m), [lod, MAX_LOD]);
      const coded = await render({ withSphere: false, background: 'lod', blurriness: r, pixels: BACKGROUND_PX.slice(0, 2) });
      for (const p of coded.pixels) assert.ok(worst(p.rgb, [lod, lod, lod]) < 2e-3, `roughness ${r}: level ${fmt(p.rgb)}, not ${lod}`);
    }

    // 3. The PMREM's roughness-0.5 level as three reads it (the background blurred 0.5, a
    // pure radiance read) against the library's own GGX prefilter at 0.5. Tolerance 0.025:
    // that level is 16×16 BC6H, which holds one colour line per block subset while this map
    // turns in all three channels (crates/bake/tests/three.rs: mean ≈ 0.01, worst 0.075 over
    // the sphere); at these points measured ≤ 0.015, and the blocks show in the screenshot. three's own PMREM of the plain
    // cube (PMREMGenerator) comes within about 0.01 of the library for this environment too:
    // a linear environment cannot tell two correct GGX filters apart, only a wrong level.
    const blur = await render({ withSphere: false, background: 'pmrem', blurriness: 0.5, pixels: BACKGROUND_PX });
    await shot('blur');
    const own = await render({ withSphere: false, background: 'cube', blurriness: 0.5, pixels: BACKGROUND_PX });
    // The library's values, for these directions and the sphere's centre (check 4) at once.
    const centre = [SPHERE_PX[0]];
    const rough = await render({ roughness: 0.5, pixels: centre });
    await shot('rough');
    const back = rough.pixels[0].view.map((c) => -c);
    const dirs = [...blur.pixels.map((p) => p.view), back];
    const lib = prefiltered(input, 0.5, dirs);
    const lib1 = prefiltered(input, 1, dirs);
    blur.pixels.forEach((p, i) => {
      const err = worst(p.rgb, lib[i]);
      console.log(`blurred 0.5 at ${fmt(p.view)}: ${fmt(p.rgb)}, library ${fmt(lib[i])} (${err.toFixed(4)}), three's own PMREM ${fmt(own.pixels[i].rgb)} (${worst(own.pixels[i].rgb, lib[i]).toFixed(4)})`);
      assert.ok(err < 0.025, `blurred background at ${fmt(p.view)}: ${fmt(p.rgb)}, library ${fmt(lib[i])}`);
      assert.ok(worst(p.rgb, lib1[i]) > 0.05, 'roughness 0.5 and 1 differ measurably here');
    });

    // 4. A roughness-0.5 sphere at its centre, where the normal and the reflected direction
    // are both the view direction back: three gives S·(level read at 0.5) + M·(its diffuse,
    // last level), with S and M measured by rendering the same sphere lit by PMREMs that are
    // 1 on the radiance levels and 0 on the last, and the reverse. Tolerance 0.025, as above.
    const [s] = (await render({ roughness: 0.5, environment: 'radiance', pixels: centre })).pixels;
    const [m] = (await render({ roughness: 0.5, environment: 'diffuse', pixels: centre })).pixels;
    const [p] = rough.pixels;
    const [g05, g1] = [lib.at(-1), lib1.at(-1)];
    const want = g05.map((g, i) => s.rgb[i] * g + m.rgb[i] * g1[i]);
    console.log(`rough sphere centre: ${fmt(p.rgb)}, S ${fmt(s.rgb)}, M ${fmt(m.rgb)}, expected ${fmt(want)}`);
    assert.ok(worst(p.rgb, want) < 0.025, `rough sphere centre ${fmt(p.rgb)}, expected ${fmt(want)}`);
  } finally {
    await b.close();
    server.close();
    tmp.remove();
  }
});
