// Scene files opened on the page, by the file picker and by dropping, as a person opens them:
// the scene with the files it names picked or dropped together (the only files, besides
// the built-ins and the bundled bunny, that an uploaded scene may name) draws what the
// same scene opened on the command line draws; a scene naming any other file, even one
// that exists and the studio could read, is refused with a message naming the scene and
// the path, and the studio keeps serving.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync, writeFileSync, mkdirSync } from 'node:fs';
import path from 'node:path';
import { browser, tempDir, studio, openStudio, onStudioPage, viewportPixels, ROOT } from './lib.mjs';

let chromium;
let work;
const VENICE = path.join(ROOT, 'assets', 'env', 'venice.exr');
const DOOR = path.join(ROOT, 'examples', 'scenes', 'zimmons-door.json');

before(async () => {
  chromium = await browser();
  work = tempDir('mirrorball-studio-scenes-');
});
after(async () => {
  await chromium?.close();
  work?.remove();
});

const onPage = (files, body) => onStudioPage(chromium, files, '', body);

/** The page's state, once the scene called `name` is shown with its environment. */
async function shown(page, name) {
  await page.waitForFunction((n) => window.studio.view.state?.scene.name === n && window.studio.view.env !== null, name, { timeout: 60000 });
  await page.evaluate(() => window.studio.redraw());
  return page.evaluate(() => window.studio.view.state);
}

/** How many bytes of two viewports' RGBA differ (their sizes must agree). */
function differing(a, b) {
  assert.equal(a.width, b.width);
  assert.equal(a.height, b.height);
  let n = 0;
  for (let i = 0; i < a.data.length; i++) if (a.data[i] !== b.data[i]) n++;
  return n;
}

/** The viewport of `scene` opened on the command line (`mirrorball studio SCENE`). */
async function fromCommandLine(scene) {
  const s = await studio([scene]);
  try {
    const { page } = await openStudio(chromium, s.url);
    const state = await page.evaluate(() => window.studio.view.state);
    await page.evaluate(() => window.studio.redraw());
    const px = await viewportPixels(page);
    await page.close();
    return { state, px };
  } finally {
    s.stop();
  }
}

test('a scene picked with the environment it names draws as the same scene opened on the command line', async () => {
  const want = await fromCommandLine(DOOR);
  await onPage([], async ({ page }) => {
    // zimmons-door.json names ../../assets/env/venice.exr: picked together, it is that file.
    await page.setInputFiles('#file', [DOOR, VENICE]);
    const state = await shown(page, 'zimmons-door.json');
    assert.equal(await page.locator('#messages .error').count(), 0, await page.textContent('#messages'));
    assert.equal(state.scene.camera.width, 320);
    assert.equal(state.scene.objects.length, 1);
    assert.equal(state.scene.objects[0].builtin, 'quad');
    assert.equal(state.scene.environment.attach, 'eye');
    assert.equal(state.scene.environment.width, want.state.scene.environment.width);
    assert.equal(await page.evaluate(() => window.studio.view.mode), 1, "the scene's indexing, texgen");
    // The exported scene keeps the path as the scene wrote it.
    assert.equal(state.scene.source.environment.file, '../../assets/env/venice.exr');
    const px = await viewportPixels(page);
    const d = differing(px, want.px);
    let lit = 0;
    for (let i = 3; i < px.data.length; i += 4) if (px.data[i] > 0) lit++;
    console.log(`picked door: ${d} of ${px.data.length} bytes differ from the command line's; ${lit} pixels drawn`);
    assert.ok(lit > 1000, `${lit} pixels drawn`);
    assert.equal(d, 0);
  });
});

test('a TOML scene dropped with its environment, naming the bundled bunny, draws as on the command line', async () => {
  const scene = (env) => `indexing = "pixel"
[camera]
eye = [0.8, 0.4, 3.0]
target = [0, 0, 0]
fov = 40
width = 160
height = 120
[environment]
file = "${env}"
projection = "latlong"
[material]
kind = "mirror"
[[meshes]]
mesh = "../../assets/meshes/bunny.obj"
[[meshes]]
mesh = "sphere"
tessellation = 16
model = [0.3, 0, 0, 0,  0, 0.3, 0, 0,  0, 0, 0.3, 0,  0.9, 0.3, 0, 1]
`;
  // On disk, for the command line: the bunny where the scene's relative path finds it.
  const dir = path.join(work.dir, 'examples', 'scenes');
  mkdirSync(dir, { recursive: true });
  const onDisk = path.join(dir, 'pair.toml');
  writeFileSync(onDisk, scene(VENICE).replace('../../assets/meshes/bunny.obj', path.join(ROOT, 'assets', 'meshes', 'bunny.obj')));
  const want = await fromCommandLine(onDisk);
  await onPage([], async ({ page }) => {
    // Dropped as a person drops files from a file manager: one drop event carrying both.
    const files = [
      { name: 'pair.toml', b64: Buffer.from(scene('maps/venice.exr')).toString('base64') },
      { name: 'venice.exr', b64: readFileSync(VENICE).toString('base64') },
    ];
    await page.evaluate((files) => {
      const dt = new DataTransfer();
      for (const f of files) dt.items.add(new File([Uint8Array.from(atob(f.b64), (c) => c.charCodeAt(0))], f.name));
      document.body.dispatchEvent(new DragEvent('dragenter', { dataTransfer: dt, bubbles: true, cancelable: true }));
      document.body.dispatchEvent(new DragEvent('drop', { dataTransfer: dt, bubbles: true, cancelable: true }));
    }, files);
    const state = await shown(page, 'pair.toml');
    assert.equal(await page.locator('#messages .error').count(), 0, await page.textContent('#messages'));
    assert.equal(await page.evaluate(() => document.body.id), '', 'the drop highlight is cleared');
    assert.equal(state.scene.objects.length, 2);
    assert.equal(state.scene.objects[0].triangles, want.state.scene.objects[0].triangles, 'the bundled bunny');
    assert.equal(state.scene.objects[1].builtin, 'sphere');
    assert.equal(await page.evaluate(() => window.studio.view.mode), 3);
    const px = await viewportPixels(page);
    const d = differing(px, want.px);
    console.log(`dropped TOML scene: ${d} of ${px.data.length} bytes differ from the command line's; bunny ${state.scene.objects[0].triangles} triangles`);
    assert.equal(d, 0);
  });
});

test('an uploaded scene naming a file not uploaded with it is refused with the scene and the path, even a readable one', async () => {
  await onPage([VENICE], async ({ s, page }) => {
    const before = await (await fetch(s.url.replace('/?', '/api/state?'))).json();
    // The path exists and the studio's user may read it: the studio still must not.
    const scene = path.join(work.dir, 'sneaky.json');
    writeFileSync(scene, JSON.stringify({ meshes: [{ mesh: 'sphere' }], environment: { file: VENICE } }));
    await page.setInputFiles('#file', scene);
    await page.waitForSelector('#messages .error', { timeout: 30000 });
    const message = await page.textContent('#messages .error');
    console.log(`refused: ${message}`);
    assert.ok(message.startsWith('sneaky.json: '), message);
    assert.ok(message.includes(VENICE), message);
    assert.match(message, /may not read/);
    // A mesh by a path outside the bundle likewise (its file name is not the bunny's).
    const mesh = path.join(work.dir, 'mesh.json');
    writeFileSync(mesh, JSON.stringify({ meshes: [{ mesh: '/etc/hostname.obj' }] }));
    await page.setInputFiles('#file', mesh);
    const second = await page.waitForFunction(
      () => Array.from(document.querySelectorAll('#messages .error')).find((p) => p.textContent.startsWith('mesh.json: '))?.textContent,
      null,
      { timeout: 30000 },
    );
    assert.ok((await second.jsonValue()).includes('/etc/hostname.obj'));
    // The studio keeps serving what it showed: the default scene with the environment.
    const state = await (await fetch(s.url.replace('/?', '/api/state?'))).json();
    assert.equal(state.scene.name, before.scene.name);
    assert.deepEqual(state.scene.environment, before.scene.environment, 'the environment is still loaded');
    await page.evaluate(() => window.studio.redraw());
    const px = await viewportPixels(page);
    assert.equal(px.data[3], 255, 'the background is still drawn');
    // And a scene with its file picked together still opens after the refusals.
    await page.setInputFiles('#file', [DOOR, VENICE]);
    await shown(page, 'zimmons-door.json');
  });
});
