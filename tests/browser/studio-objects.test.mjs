// The studio's objects and attachment, used as a person uses them: an object chosen by the
// selector and the map attached to the eye by its selector, drawn as `mirrorball render`
// draws the exported scene; the side-by-side view of the two attachments (Zimmons' figure
// 18: attached to the eye, the picture of a sphere does not change as the camera orbits it;
// attached to the world, it does); a mesh file opened by the picker in place of the
// objects, the bundled bunny, a broken mesh refused on the page, and bad requests; the
// background's pan blur (Greene §9) against `mirrorball render --pan-blur`.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync, writeFileSync } from 'node:fs';
import path from 'node:path';
import { browser, run, tempDir, readPng, studio, openStudio, viewportPixels, againstRender, carried, sphereScene, ROOT } from './lib.mjs';

let chromium;
let work;
const VENICE = path.join(ROOT, 'assets', 'env', 'venice.exr');
const BUNNY = path.join(ROOT, 'assets', 'meshes', 'bunny.obj');

before(async () => {
  chromium = await browser();
  work = tempDir('mirrorball-studio-objects-');
});
after(async () => {
  await chromium?.close();
  work?.remove();
});

/** A scene file of one sphere over Venice, `extra` merged in; its path. */
const sceneFile = (name, extra = {}) => sphereScene(work.dir, name, extra);

/** Waits until the page's state says `object` is shown (null: the scene's), then draws. */
async function shown(page, object) {
  await page.waitForFunction((o) => window.studio.view.state?.object === o, object, { timeout: 60000 });
  await page.evaluate(() => window.studio.redraw());
}

/** Bytes of `a` and `b` (same length) that differ by more than `tolerance`. */
function differing(a, b, tolerance = 0) {
  let n = 0;
  for (let i = 0; i < a.length; i++) if (Math.abs(a[i] - b[i]) > tolerance) n++;
  return n;
}

test('an object chosen by the selector, with the map attached to the eye, draws as mirrorball render draws the exported scene', async () => {
  const s = await studio([sceneFile('sphere.json')]);
  const { page, logs } = await openStudio(chromium, s.url);
  try {
    const choices = await page.$$eval('#object option', (o) => o.map((x) => x.value));
    assert.deepEqual(choices, ['scene', 'sphere', 'torus', 'cube', 'quad', 'teapot', 'bunny']);
    await page.selectOption('#object', 'teapot');
    await shown(page, 'teapot');
    await page.selectOption('#attach', 'eye');
    // Orbit as a person does: drag across the viewport.
    const box = await page.locator('#viewport').boundingBox();
    await page.mouse.move(box.x + 80, box.y + 60);
    await page.mouse.down();
    await page.mouse.move(box.x + 110, box.y + 45, { steps: 3 });
    await page.mouse.up();
    await page.evaluate(() => window.studio.redraw());
    const st = await page.evaluate(() => window.studio.view.state);
    assert.equal(st.scene.objects.length, 1);
    assert.equal(st.scene.objects[0].builtin, 'teapot');
    assert.equal(st.scene.objects[0].tessellation, 8);
    // The slider is the teapot's now.
    assert.equal(await page.isVisible('#tessellation-label'), true);
    assert.equal(await page.inputValue('#tessellation'), '8');
    const got = { ...(await viewportPixels(page)), file: await page.evaluate(() => window.studio.sceneFile()) };
    const url = new URL(await page.evaluate(() => location.href));
    assert.equal(url.searchParams.get('object'), 'teapot');
    assert.equal(url.searchParams.get('attach'), 'eye');
    assert.ok(url.searchParams.get('yaw'));
    assert.deepEqual(got.file.meshes, [{ mesh: 'teapot', tessellation: 8, material: { kind: 'mirror' } }]);
    assert.equal(got.file.environment.attach, 'eye');
    const exported = path.join(work.dir, 'teapot.json');
    writeFileSync(exported, JSON.stringify(got.file));
    const out = path.join(work.dir, 'teapot.png');
    const cover = path.join(work.dir, 'teapot-cover.png');
    run(['render', exported, '-o', out, '--quiet']);
    run(['render', exported, '-o', cover, '--quiet', '--no-background']);
    const { n, within, bg, bgWithin } = againstRender(got.data, readPng(readFileSync(out)), readPng(readFileSync(cover)));
    console.log(`teapot, eye-attached, orbited: ${((100 * within) / n).toFixed(2)}% of ${n} covered pixels within 2/255, background ${((100 * bgWithin) / bg).toFixed(2)}% of ${bg}`);
    assert.ok(n > 1000, `${n} covered pixels`);
    assert.ok(within / n >= 0.99);
    assert.ok(bgWithin / bg >= 0.99);
    // The world-attached picture of the same view is another picture: the attachment took.
    await page.selectOption('#attach', 'world');
    await page.evaluate(() => window.studio.redraw());
    const world = await viewportPixels(page);
    assert.ok(differing(world.data, got.data, 8) > got.data.length / 10, 'attaching to the world changes the picture');
    // The scene's own objects again, and a link to this view reopens it.
    await page.selectOption('#object', 'scene');
    await shown(page, null);
    const back = await page.evaluate(() => window.studio.view.state.scene.objects.map((o) => [o.builtin, o.tessellation]));
    assert.deepEqual(back, [['sphere', 12]]);
    assert.deepEqual(logs.filter((l) => /error/i.test(l)), []);
  } catch (e) {
    throw new Error(`${e.stack}\n${logs.join('\n')}`);
  } finally {
    await page.close();
    s.stop();
  }
});

test('side by side: attached to the eye the sphere looks the same from every side, attached to the world it does not', async () => {
  const s = await studio([sceneFile('round.json', { meshes: [{ mesh: 'sphere', tessellation: 256 }] })]);
  const { page, logs } = await openStudio(chromium, `${s.url}&twin=1`);
  try {
    const grab = async () => {
      const r = await page.evaluate(async () => {
        await window.studio.redraw();
        return { view: window.carry(window.studio.pixels().data), twin: window.carry(window.studio.twin.last.data) };
      });
      return { view: carried(r.view), twin: carried(r.twin) };
    };
    assert.equal(await page.isVisible('#twin-canvas'), true);
    assert.match(await page.textContent('#twin-caption'), /attached to the eye/);
    const a = await grab();
    // Orbit by the keyboard: 0.3 rad about the sphere.
    for (let i = 0; i < 6; i++) await page.keyboard.press('ArrowLeft');
    const b = await grab();
    const px = a.view.length / 4;
    const changed = (x, y) => {
      let n = 0;
      for (let i = 0; i < px; i++) if ([0, 1, 2].some((c) => Math.abs(x[4 * i + c] - y[4 * i + c]) > 2)) n++;
      return n / px;
    };
    const eye = changed(a.twin, b.twin);
    const world = changed(a.view, b.view);
    console.log(`orbit 0.3 rad: eye-attached ${(100 * eye).toFixed(2)}% of pixels changed, world-attached ${(100 * world).toFixed(2)}%`);
    assert.ok(eye <= 0.01, `eye-attached: ${eye}`);
    assert.ok(world >= 0.3, `world-attached: ${world}`);
    // The twin is the viewport drawn the other way: swapping the attachment swaps them exactly.
    await page.selectOption('#attach', 'eye');
    const c = await grab();
    assert.equal(differing(c.view, b.twin), 0, 'the viewport attached to the eye is the twin it showed');
    assert.equal(differing(c.twin, b.view), 0, 'the twin attached to the world is the viewport it was');
    assert.match(await page.textContent('#twin-caption'), /attached to the world/);
    await page.screenshot({ path: path.join(process.env.STUDIO_SHOTS || work.dir, 'studio-twin.png') });
    await page.uncheck('#twin');
    await page.evaluate(() => window.studio.redraw());
    assert.equal(await page.isVisible('#twin-canvas'), false);
    assert.deepEqual(logs.filter((l) => /error/i.test(l)), []);
  } catch (e) {
    throw new Error(`${e.stack}\n${logs.join('\n')}`);
  } finally {
    await page.close();
    s.stop();
  }
});

test('a mesh picked on the page replaces the objects, the bundled bunny is offered, and a broken mesh or a bad request is refused', async () => {
  const s = await studio([VENICE]);
  const { page, logs } = await openStudio(chromium, s.url);
  try {
    const faces = readFileSync(BUNNY, 'utf8').split('\n').filter((l) => l.startsWith('f ')).length;
    const before = await page.evaluate(() => window.studio.view.state.scene.objects.map((o) => o.triangles));
    await page.setInputFiles('#file', BUNNY);
    await shown(page, 'bunny.obj');
    const objects = await page.evaluate(() => window.studio.view.state.scene.objects);
    assert.equal(objects.length, 1);
    assert.equal(objects[0].triangles, faces);
    assert.equal(objects[0].builtin, null);
    assert.equal(await page.isVisible('#tessellation-label'), false);
    assert.equal(await page.inputValue('#object'), 'bunny.obj');
    const view = await viewportPixels(page);
    // The bunny is drawn: framed to unit size at the origin, as render frames mesh files.
    const cover = await page.evaluate(async () => {
      await window.studio.draw({ background: false });
      const p = window.studio.pixels().data;
      let n = 0;
      for (let i = 3; i < p.length; i += 4) if (p[i] > 0) n++;
      await window.studio.redraw();
      return n;
    });
    console.log(`bunny.obj: ${faces} triangles, ${cover} covered pixels of ${view.width * view.height}`);
    assert.ok(cover > 0.05 * view.width * view.height, `${cover} covered pixels`);
    // A broken mesh: the CLI's message on the page, and the bunny stays.
    const broken = path.join(work.dir, 'broken.obj');
    writeFileSync(broken, 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n');
    await page.setInputFiles('#file', broken);
    await page.waitForSelector('#messages .error', { timeout: 30000 });
    assert.match(await page.textContent('#messages .error'), /^broken\.obj/);
    let cli = '';
    try {
      run(['render', '--object', broken, '--env', VENICE, '-o', path.join(work.dir, 'x.png'), '--quiet']);
    } catch (e) {
      cli = String(e.message);
    }
    assert.match(cli, /broken\.obj/);
    assert.equal(await page.evaluate(async () => (await (await window.studio.G.api('/api/state')).json()).object), 'bunny.obj');
    // The bundled bunny is the same mesh.
    await page.selectOption('#object', 'bunny');
    await shown(page, 'bunny');
    assert.equal(await page.evaluate(() => window.studio.view.state.scene.objects[0].triangles), faces);
    // Back to the scene's own sphere.
    await page.selectOption('#object', 'scene');
    await shown(page, null);
    assert.deepEqual(await page.evaluate(() => window.studio.view.state.scene.objects.map((o) => o.triangles)), before);
    // Bad requests: an unknown object and a tessellation out of range, each a 400 that says why.
    const api = (q) => page.evaluate(async (q) => {
      const token = new URLSearchParams(location.search).get('token');
      const r = await fetch(`/api/object?${q}`, { method: 'POST', headers: { 'x-mirrorball-token': token } });
      return [r.status, await r.text()];
    }, q);
    const [s1, t1] = await api('name=dragon');
    assert.equal(s1, 400);
    // The mesh file picked above stays a choice (what a link naming no object shows).
    assert.match(t1, /unknown 'dragon' \(known: scene, sphere, torus, cube, quad, teapot, bunny, bunny\.obj\)/);
    const [s2, t2] = await api('name=sphere&tessellation=0');
    assert.equal(s2, 400);
    assert.match(t2, /tessellation: 0 is outside 1\.\.=/);
    assert.deepEqual(logs.filter((l) => /pageerror|TypeError|ReferenceError/.test(l)), []);
  } catch (e) {
    throw new Error(`${e.stack}\n${logs.join('\n')}`);
  } finally {
    await page.close();
    s.stop();
  }
});

test("the pan blur (Greene §9) draws the background as mirrorball render --pan-blur does", async () => {
  const scene = sceneFile('pan.json', { meshes: [{ mesh: 'sphere', tessellation: 48 }] });
  const s = await studio([scene]);
  try {
    const grab = async (keys) => {
      const { page, logs } = await openStudio(chromium, `${s.url}&view=viewport&${keys}`);
      const px = await viewportPixels(page);
      await page.close();
      assert.deepEqual(logs.filter((l) => /error/i.test(l)), []);
      return px;
    };
    const sharp = await grab('panblur=0');
    for (const deg of [12, -4]) {
      const got = await grab(`panblur=${deg}`);
      const out = path.join(work.dir, `pan${deg}.png`);
      const cover = path.join(work.dir, `pan${deg}-cover.png`);
      run(['render', scene, '--ss', '1', '--pan-blur', String(deg), '-o', out, '--quiet']);
      run(['render', scene, '--ss', '1', '--pan-blur', String(deg), '-o', cover, '--quiet', '--no-background']);
      const { n, within, bg, bgWithin } = againstRender(got.data, readPng(readFileSync(out)), readPng(readFileSync(cover)));
      const blurred = differing(got.data, sharp.data, 2) / got.data.length;
      console.log(`pan blur ${deg}°: background ${((100 * bgWithin) / bg).toFixed(2)}% of ${bg} within 2/255 of render, objects ${((100 * within) / n).toFixed(2)}% of ${n}; ${(100 * blurred).toFixed(1)}% of bytes differ from the sharp frame`);
      assert.ok(bgWithin / bg >= 0.99);
      assert.ok(within / n >= 0.99);
      assert.ok(blurred > 0.1, 'the blur shows');
    }
  } finally {
    s.stop();
  }
});
