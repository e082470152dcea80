// The glTF file mirrorball bakes with EXT_lights_image_based passes the Khronos glTF
// validator (npm gltf-validator, pinned), its images read through the validator's
// externalResourceFunction.
//
// What the validator says of the extension: it lists it under info.extensionsUsed, and it
// cannot validate it ("UNSUPPORTED_EXTENSION", an Information: 2.0.0-dev.3.10 knows no
// EXT_lights_image_based), so it does not follow the light's image references either and
// calls every specular image "UNUSED_OBJECT" (Information). The test asserts exactly that
// (no errors, no warnings, no other issue), checks the light against the extension's schema
// (KhronosGroup/glTF extensions/2.0/Vendor/EXT_lights_image_based/schema/light.schema.json
// and scene.EXT_lights_image_based.schema.json) here, and checks each image as the validator
// read it (size per level, RGBA 8-bit).
import test from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import path from 'node:path';
import validator from 'gltf-validator';
import { bake, browser, directionCoded, mirrorChecks, readPng, serve, tempDir } from './lib.mjs';

const EXT = 'EXT_lights_image_based';
const SIZE = 64;

test('the EXT_lights_image_based glTF passes the Khronos validator', async (t) => {
  const tmp = tempDir();
  try {
    const input = directionCoded(path.join(tmp.dir, 'coded.exr'), 256);
    const files = bake('gltf', input, tmp.dir, SIZE);
    const gltfFile = files.find((f) => f.endsWith('.gltf'));
    assert.ok(gltfFile, files.join(' '));
    const asked = [];
    const report = await validator.validateBytes(new Uint8Array(readFileSync(gltfFile)), {
      uri: path.basename(gltfFile),
      format: 'gltf',
      maxIssues: 0,
      externalResourceFunction: async (uri) => {
        asked.push(uri);
        return new Uint8Array(readFileSync(path.join(path.dirname(gltfFile), decodeURIComponent(uri))));
      },
    });
    const { issues, info } = report;
    const other = issues.messages.filter((m) => !(m.code === 'UNSUPPORTED_EXTENSION' || m.code === 'UNUSED_OBJECT'));
    t.diagnostic(`validator: ${issues.numErrors} errors, ${issues.numWarnings} warnings, ${issues.numInfos} infos, ${issues.numHints} hints; codes ${[...new Set(issues.messages.map((m) => m.code))].join(', ')}`);
    assert.equal(issues.numErrors, 0, JSON.stringify(issues.messages.slice(0, 5)));
    assert.equal(issues.numWarnings, 0, JSON.stringify(issues.messages.slice(0, 5)));
    assert.deepEqual(other, []);
    assert.deepEqual(info.extensionsUsed, [EXT]);
    assert.ok(info.hasDefaultScene);

    const gltf = JSON.parse(readFileSync(gltfFile, 'utf8'));
    const unsupported = issues.messages.filter((m) => m.code === 'UNSUPPORTED_EXTENSION');
    assert.deepEqual(unsupported.map((m) => m.pointer), ['/extensionsUsed/0']);
    assert.match(unsupported[0].message, new RegExp(EXT));
    const unused = issues.messages.filter((m) => m.code === 'UNUSED_OBJECT').map((m) => m.pointer).sort();
    const light = gltf.extensions[EXT].lights[0];
    const referenced = light.specularImages.flat().map((i) => `/images/${i}`).sort();
    assert.deepEqual(unused, referenced, 'the only objects the validator cannot see used are the light\'s images');

    // The light against light.schema.json: required properties and their shapes.
    for (const key of ['irradianceCoefficients', 'specularImages', 'specularImageSize']) assert.ok(key in light, key);
    assert.equal(light.irradianceCoefficients.length, 9);
    assert.ok(light.irradianceCoefficients.every((c) => c.length === 3 && c.every(Number.isFinite)));
    assert.ok(Number.isInteger(light.specularImageSize) && light.specularImageSize >= 1);
    assert.equal(light.specularImageSize, SIZE);
    assert.ok(light.specularImages.length >= 1);
    assert.ok(light.specularImages.every((l) => l.length === 6 && l.every((i) => Number.isInteger(i) && i >= 0 && i < gltf.images.length)));
    assert.equal(light.rotation.length, 4);
    assert.ok(light.rotation.every((q) => q >= -1 && q <= 1));
    assert.ok(light.intensity >= 0);
    // The scene's reference (scene.EXT_lights_image_based.schema.json), from the default scene.
    assert.equal(gltf.scenes[gltf.scene].extensions[EXT].light, 0);

    // Each image as the validator read it: the level's size, RGBA 8-bit (RGBD, the README's
    // "4-channel PNG"); the last level 16² (roughness 1, the README's "say, 16x16").
    const byPointer = new Map(info.resources.map((r) => [r.pointer, r]));
    light.specularImages.forEach((faces, level) => {
      for (const i of faces) {
        const r = byPointer.get(`/images/${i}`);
        assert.ok(r, `image ${i} read by the validator`);
        assert.equal(r.mimeType, 'image/png');
        assert.deepEqual([r.image.width, r.image.height, r.image.format, r.image.bits], [SIZE >> level, SIZE >> level, 'rgba', 8], `image ${i}`);
      }
    });
    assert.equal(SIZE >> (light.specularImages.length - 1), 16);
    assert.equal(asked.length, gltf.images.length);
    // And our own decoder agrees with the validator on the first image.
    const first = readPng(readFileSync(path.join(path.dirname(gltfFile), gltf.images[0].uri)));
    assert.deepEqual([first.width, first.channels], [SIZE, 4]);
  } finally {
    tmp.remove();
  }
});

// The same light in Babylon.js: its glTF loader's EXT_lights_image_based path (see
// babylon.html's loadGltfLight: Babylon's own RawCubeTexture.updateRGBDAsync and
// SphericalHarmonics/SphericalPolynomial, the loader's few lines of glue transcribed, as
// @babylonjs/loaders has no release matching the pinned core), in a right-handed scene
// where the glTF world is the scene's: a mirror sphere and the background right way round,
// compared as babylon.test.mjs compares (linear output, traced directions), and the
// polynomial Babylon makes from the coefficients against the one it sums from the pixels.
//
// Babylon's loader leaves the RawCubeTexture's gammaSpace at its default, true, so its
// shader takes the decoded radiance for gamma-encoded and linearises it once more
// (GAMMAREFLECTION, Materials/materialHelper.functions.js:756: toLinearSpace, x^2.2): the
// light comes out as radiance^2.2, darker. That is Babylon's, not the file's (the extension
// says a four-channel PNG is RGBD HDR, linear); the comparison applies the same x^2.2 and
// asserts the flag, so a Babylon that fixes it shows here.
test('Babylon.js shows the glTF light the right way round', async (t) => {
  const tmp = tempDir();
  const { server, url } = await serve(tmp.dir);
  const b = await browser();
  try {
    const input = directionCoded(path.join(tmp.dir, 'coded.exr'), 512);
    bake('gltf', input, tmp.dir, SIZE);
    const page = await b.newPage();
    const errors = [];
    page.on('pageerror', (e) => errors.push(e.message));
    await page.goto(`${url}/babylon.html`);
    await page.waitForFunction(() => window.ready === true, null, { timeout: 20000 });
    const fov = 0.7;
    const r = await page.evaluate(([u, f]) => window.renderEnv(u, 0, f), ['/baked/lighting.gltf', fov]);
    await page.screenshot({ path: path.join(tmp.dir, 'gltf-mirror.png') });
    assert.deepEqual(errors, []);
    assert.ok(Math.abs(r.info.lodGenerationScale - 2 / 6) < 1e-9, JSON.stringify(r.info.lodGenerationScale));
    assert.equal(r.info.gammaSpace, true, 'Babylon now takes the light as linear: drop the x^2.2 below');
    for (const check of mirrorChecks(r, { eye: [0, 0, 4], forward: -1, fov, toWorld: (d) => d })) {
      const { what, got } = check;
      const want = check.want.map((v) => Math.pow(v, 2.2));
      const err = Math.max(...got.map((g, k) => Math.abs(g - want[k])));
      t.diagnostic(`${what}: got ${got.map((v) => v.toFixed(3))} want ${want.map((v) => v.toFixed(3))}`);
      assert.ok(err < 0.035, `${what}: Babylon shows ${got.map((v) => v.toFixed(3))}, the world there is ${want.map((v) => v.toFixed(3))}`);
    }
    for (let i = 0; i < 9; i++) {
      for (let k = 0; k < 3; k++) {
        const [a, s] = [r.info.declared[i][k], r.info.summed[i][k]];
        assert.ok(Math.abs(a - s) < 0.01, `polynomial term ${i}[${k}]: from the coefficients ${a}, Babylon sums ${s}`);
      }
    }
    assert.ok(r.info.declared[0][0] > 0.2 && r.info.declared[1][1] > 0.2 && r.info.declared[2][2] < -0.2, JSON.stringify(r.info.declared));
  } finally {
    await b.close();
    server.close();
    if (!process.env.KEEP) tmp.remove();
    else console.log(`kept ${tmp.dir}`);
  }
});
