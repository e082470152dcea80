// Babylon.js (npm @babylonjs/core, pinned) loads the .env mirrorball bakes for it with its
// stock loader, in headless Chromium on WebGL2, and shows the world the right way round.
//
// How pixels are compared: image processing is off (no tone mapping, no gamma), so the
// canvas holds linear radiance in bytes. The environment is direction-coded (colour =
// ½ + ½·d in mirrorball's world), so the expected colour of a background pixel is that of
// its view ray and of a mirror-sphere pixel that of its reflected ray, both traced here
// from the camera Babylon is given, turned from Babylon's left-handed world into
// mirrorball's by (x, y, z) → (x, y, −z) (the convention `crates/bake/src/babylon.rs`
// states). A rough sphere's colour is scaled by Babylon's environment BRDF, the same in all
// three channels, so it is compared by channel ratios.
import test from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import path from 'node:path';
import { bake, browser, directionCoded, mirrorChecks, readPng, reflect, rgbdDecode, serve, sphereHit, tempDir, viewRay } from './lib.mjs';

const SIZE = 64;
const FOV = 0.7;

/// Babylon's world direction to mirrorball's.
const toMirrorball = (d) => [d[0], d[1], -d[2]];
const EYE = [0, 0, -4];
const ray = (px, py, w, h) => viewRay(px, py, w, h, FOV, 1);
const hit = (d) => sphereHit(EYE, d);
const pixel = (r, px, py) => [0, 1, 2].map((k) => r.pixels[(py * r.w + px) * 4 + k] / 255);

/// Reads a .env as Babylon's GetEnvInfo does: the magic, the NUL-ended manifest, the images.
function readEnv(bytes) {
  const buf = Buffer.from(bytes);
  assert.deepEqual([...buf.subarray(0, 8)], [0x86, 0x16, 0x87, 0x96, 0xf6, 0xd6, 0x96, 0x36]);
  const nul = buf.indexOf(0, 8);
  const manifest = JSON.parse(buf.toString('latin1', 8, nul));
  const data = buf.subarray(nul + 1);
  const images = manifest.specular.mipmaps.map((m) => readPng(data.subarray(m.position, m.position + m.length)));
  return { manifest, images };
}

test('Babylon.js loads the .env and shows it the right way round', async (t) => {
  const tmp = tempDir();
  const { server, url } = await serve(tmp.dir);
  const b = await browser();
  try {
    const input = directionCoded(path.join(tmp.dir, 'coded.exr'), 512);
    const files = bake('babylon', input, tmp.dir, SIZE);
    assert.ok(files.some((f) => f.endsWith('environment.env')), files.join(' '));
    const page = await b.newPage();
    const errors = [];
    page.on('pageerror', (e) => errors.push(e.message));
    await page.goto(`${url}/babylon.html`);
    await page.waitForFunction(() => window.ready === true, null, { timeout: 20000 });
    const envUrl = '/baked/environment.env';

    const mirror = await page.evaluate(([u, f]) => window.renderEnv(u, 0, f), [envUrl, FOV]);
    await page.screenshot({ path: path.join(tmp.dir, 'mirror.png') });
    assert.deepEqual(errors, []);
    // Babylon took the file's declared scale, and the default offset the shader adds (0).
    assert.equal(mirror.info.size, SIZE);
    assert.ok(Math.abs(mirror.info.lodGenerationScale - 0.8) < 1e-9, JSON.stringify(mirror.info));
    assert.equal(mirror.info.lodGenerationOffset, 0);
    assert.equal(mirror.info.linearSpecularLOD, false);
    assert.equal(mirror.info.gammaSpace, false, 'the .env loader marks its texture linear');

    const { w, h } = mirror;
    const checks = mirrorChecks(mirror, { eye: EYE, forward: 1, fov: FOV, toWorld: toMirrorball });
    for (const { what, got, want } of checks) {
      const err = Math.max(...got.map((g, k) => Math.abs(g - want[k])));
      t.diagnostic(`${what}: got ${got.map((v) => v.toFixed(3))} want ${want.map((v) => v.toFixed(3))}`);
      assert.ok(err < 0.035, `${what}: Babylon shows ${got.map((v) => v.toFixed(3))}, the world there is ${want.map((v) => v.toFixed(3))}`);
    }

    // A rough sphere: where its normal faces the camera the reflected ray R is (nearly)
    // mirrorball's +Z and the colour is s·(½ + ½k·R), s Babylon's environment BRDF (one
    // number for all three channels), k the mean of d·R under the lobe Babylon samples
    // there: k = (c_b − c_r)/(c_r R_z − c_b R_x) whatever s is. Babylon's shader picks
    // lod = log2(size·(r² + 0.0005))·0.8 (getLodFromAlphaG × lodGenerationScale), trilinear
    // between two of the file's levels; those are read here, decoded, at the centre of the
    // face that holds mirrorball's +Z (Babylon's −Z, face 5), and give the k to expect.
    const roughness = 0.5;
    const rough = await page.evaluate(([u, r, f]) => window.renderEnv(u, r, f), [envUrl, roughness, FOV]);
    await page.screenshot({ path: path.join(tmp.dir, 'rough.png') });
    const [cx, cy] = [Math.floor(w / 2), Math.floor(h / 2)];
    const dc = ray(cx, cy, w, h);
    const R = toMirrorball(reflect(dc, hit(dc)));
    const c = pixel(rough, cx, cy);
    const kOf = (col) => (col[2] - col[0]) / (col[0] * R[2] - col[2] * R[0]);
    const kSeen = kOf(c);
    const { images } = readEnv(readFileSync(path.join(tmp.dir, 'environment.env')));
    const faceCentre = (level) => {
      const img = images[level * 6 + 5];
      const s = img.width;
      const lo = Math.max(0, s / 2 - 1), hi = Math.min(s - 1, s / 2);
      const acc = [0, 0, 0];
      for (const y of [lo, hi]) for (const x of [lo, hi]) {
        const i = (y * s + x) * 4;
        rgbdDecode(img.data[i], img.data[i + 1], img.data[i + 2], img.data[i + 3]).forEach((v, k) => { acc[k] += v / 4; });
      }
      return acc;
    };
    const kLevel = (level) => { const q = faceCentre(level); return q[2] / q[0] - 1; };
    const lod = Math.log2(SIZE * (roughness * roughness + 0.0005)) * 0.8;
    const l0 = Math.floor(lod);
    const kWant = kLevel(l0) * (1 - (lod - l0)) + kLevel(l0 + 1) * (lod - l0);
    t.diagnostic(`rough centre ${c.map((v) => v.toFixed(3))}, R ${R.map((v) => v.toFixed(3))}: k = ${kSeen.toFixed(3)}; the file at lod ${lod.toFixed(2)}: k = ${kWant.toFixed(3)} (levels: ${[0, 1, 2, 3, 4, 5].map((i) => kLevel(i).toFixed(3))})`);
    assert.ok(Math.abs(kSeen - kWant) < 0.02, `rough centre: Babylon's k ${kSeen} against the file's ${kWant} at lod ${lod}`);
    // The levels either side are told apart at that tolerance.
    assert.ok(kLevel(l0) - kLevel(l0 + 1) > 0.1, 'the levels around the lod differ');

    // Babylon's own code on the loaded file: the spherical polynomial it sums itself from
    // the cube's level-0 pixels (CubeMapToSphericalPolynomialTools) against the one the file
    // declares; and the .env its writer (CreateEnvTextureAsync) makes of the texture it
    // loaded, image by image against ours. A reader-writer round trip keeps any orientation,
    // so this shows the file is what Babylon itself writes for that cube (RGBD bytes, level
    // and face order, manifest), not that the cube is the right way round: the renders
    // above show that.
    const trip = await page.evaluate((u) => window.babylonRoundTrip(u), envUrl);
    assert.deepEqual(errors, []);
    const names = ['x', 'y', 'z', 'xx', 'yy', 'zz', 'yz', 'zx', 'xy'];
    for (let i = 0; i < 9; i++) {
      for (let k = 0; k < 3; k++) {
        const [a, s] = [trip.declared[i][k], trip.fromPixels[i][k]];
        assert.ok(Math.abs(a - s) < 0.01, `polynomial ${names[i]}[${k}]: the file says ${a}, Babylon sums ${s}`);
      }
    }
    // The direction-coded world's linear terms, with their signs, are there to be checked.
    assert.ok(trip.declared[0][0] > 0.2 && trip.declared[1][1] > 0.2 && trip.declared[2][2] < -0.2, JSON.stringify(trip.declared));
    const theirs = readEnv(trip.env);
    const ours = readEnv(readFileSync(path.join(tmp.dir, 'environment.env')));
    assert.equal(theirs.manifest.width, SIZE);
    assert.equal(theirs.images.length, ours.images.length);
    assert.ok(Math.abs(theirs.manifest.specular.lodGenerationScale - 0.8) < 1e-9);
    let worst = 0;
    for (let i = 0; i < ours.images.length; i++) {
      const [a, z] = [ours.images[i], theirs.images[i]];
      assert.equal(a.width, z.width, `image ${i}`);
      for (let p = 0; p < a.width * a.width; p++) {
        const da = rgbdDecode(...a.data.subarray(p * 4, p * 4 + 4));
        const dz = rgbdDecode(...z.data.subarray(p * 4, p * 4 + 4));
        worst = Math.max(worst, ...da.map((v, k) => Math.abs(v - dz[k])));
      }
    }
    t.diagnostic(`Babylon's rewrite of the .env: largest texel difference ${worst.toFixed(4)}`);
    assert.ok(worst < 0.02, `Babylon's writer makes other texels of the same texture (${worst})`);
  } finally {
    await b.close();
    server.close();
    if (!process.env.KEEP) tmp.remove();
    else console.log(`kept ${tmp.dir}`);
  }
});
