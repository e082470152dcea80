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
import { bake, directionCoded, readPng, tempDir } from './lib.mjs';

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
