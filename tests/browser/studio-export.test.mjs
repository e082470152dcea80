// The studio's downloads, clicked on the page as a person clicks them: the map in the
// viewport's conversion and the GGX chain it is lit by, each opened with `mirrorball info`,
// and the screenshot, which is the viewport's pixels.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync, writeFileSync } from 'node:fs';
import path from 'node:path';
import { browser, run, tempDir, readPng, studio, openStudio, viewportPixels, againstRender, sphereScene, onStudioPage, ROOT } from './lib.mjs';

let chromium;
let work;
const VENICE = path.join(ROOT, 'assets', 'env', 'venice.exr');

before(async () => {
  chromium = await browser();
  work = tempDir('mirrorball-studio-export-');
});
after(async () => {
  await chromium?.close();
  work?.remove();
});

/** Clicks `button` on `page` and saves the download under the name the page gave it. */
async function clickDownload(page, button) {
  const [d] = await Promise.all([page.waitForEvent('download', { timeout: 120000 }), page.click(button)]);
  const file = path.join(work.dir, d.suggestedFilename());
  await d.saveAs(file);
  return file;
}

test('the map, the GGX chain and the screenshot download from the page, and mirrorball info opens them', async () => {
  const s = await studio([VENICE]);
  const { page, logs } = await openStudio(chromium, `${s.url}&projection=cube&size=64&lightsize=16`);
  try {
    // The conversion the viewport shows, as OpenEXR (a cross: the CLI's default layout).
    await page.selectOption('#export-format', 'exr');
    const exr = await clickDownload(page, '#export-map');
    assert.equal(path.basename(exr), 'environment-cube.exr');
    const info = run(['info', exr]);
    assert.match(info, /container:\s+OpenEXR/);
    assert.match(info, /projection:\s+cube \(cube, hcross, recorded in the file\)/);
    assert.match(info, /size:\s+64x64 x 6 layers/);
    // As KTX2: a cube the GPU containers hold.
    await page.selectOption('#export-format', 'ktx2');
    const ktx2 = await clickDownload(page, '#export-map');
    assert.match(run(['info', ktx2]), /container:\s+KTX2/);
    // The chain, once the page is lit by it: every level in one KTX2.
    await page.selectOption('#material', 'ggx');
    await page.waitForFunction(() => window.studio.view.lighting !== null, null, { timeout: 120000 });
    const chain = await clickDownload(page, '#export-chain');
    assert.equal(path.basename(chain), 'ggx-16-linear.ktx2');
    const chainInfo = run(['info', chain]);
    assert.match(chainInfo, /container:\s+KTX2/);
    assert.match(chainInfo, /size:\s+16x16 x 6 layers/);
    assert.equal(readFileSync(chain).readUInt32LE(40), 5, 'levels 16² to 1²');
    // A container that cannot hold a chain is refused on the page with the reason.
    await page.selectOption('#export-format', 'png');
    await page.click('#export-chain');
    await page.waitForSelector('#messages .error', { timeout: 30000 });
    assert.match(await page.textContent('#messages .error'), /ktx2 or dds/);
    // The screenshot is the viewport's pixels.
    await page.evaluate(() => window.studio.redraw());
    const shot = await clickDownload(page, '#screenshot');
    assert.equal(path.basename(shot), 'mirrorball-viewport.png');
    const png = readPng(readFileSync(shot));
    const px = await viewportPixels(page);
    assert.equal(png.width, px.width);
    assert.equal(png.height, px.height);
    assert.equal(png.channels, 4);
    let differ = 0;
    for (let i = 0; i < px.data.length; i++) if (png.data[i] !== px.data[i]) differ++;
    assert.equal(differ, 0, `${differ} bytes of the screenshot differ from the viewport`);
  } catch (e) {
    throw new Error(`${e.stack}\n${logs.join('\n')}`);
  } finally {
    await page.close();
    s.stop();
  }
});

test('the scene exported from an orbited embed view renders with mirrorball render as the page draws it', async () => {
  const scene = path.join(work.dir, 'sphere.json');
  writeFileSync(
    scene,
    JSON.stringify({
      meshes: [{ mesh: 'sphere', tessellation: 12 }],
      camera: { eye: [0, 0.4, 3.2], target: [0, 0, 0], fov: 40, width: 160, height: 120 },
      // Relative to the scene file: the export names it absolutely.
      environment: { file: path.relative(work.dir, VENICE), projection: 'latlong', attach: 'world', filter: 'ewa' },
      material: { kind: 'mirror' },
      supersample: 2,
      background: true,
    }),
  );
  const s = await studio([scene]);
  try {
    const { page, logs } = await openStudio(chromium, `${s.url}&view=viewport&mode=2&yaw=0.6&pitch=0.35&distance=2.8`);
    const got = { ...(await viewportPixels(page)), file: await page.evaluate(() => window.studio.sceneFile()) };
    await page.close();
    assert.deepEqual(logs.filter((l) => /error/i.test(l)), []);
    assert.equal(got.file.indexing, 'vertex');
    assert.equal(got.file.supersample, 1);
    assert.ok(path.isAbsolute(got.file.environment.file));
    const exported = path.join(work.dir, 'exported.json');
    writeFileSync(exported, JSON.stringify(got.file));
    const out = path.join(work.dir, 'exported.png');
    run(['render', exported, '-o', out, '--quiet']);
    const cover = path.join(work.dir, 'cover.png');
    run(['render', exported, '-o', cover, '--quiet', '--no-background']);
    const cpu = readPng(readFileSync(out));
    const alpha = readPng(readFileSync(cover));
    assert.equal(cpu.width, got.width);
    assert.equal(cpu.height, got.height);
    // As studio.test.mjs compares the embed view with render.
    const { n, within, bg, bgWithin } = againstRender(got.data, cpu, alpha);
    console.log(`exported scene: ${((100 * within) / n).toFixed(2)}% of ${n} covered pixels within 2/255, background ${((100 * bgWithin) / bg).toFixed(2)}%`);
    assert.ok(n > 1000, `${n} covered pixels`);
    assert.ok(within / n >= 0.99);
    assert.ok(bgWithin / bg >= 0.99);
    // An environment opened on its own has no scene file to export.
    const other = await studio([VENICE]);
    try {
      const { page: p2 } = await openStudio(chromium, other.url);
      const message = await p2.evaluate(() => {
        try {
          window.studio.sceneFile();
          return null;
        } catch (e) {
          return e.message;
        }
      });
      await p2.close();
      assert.match(message ?? '', /no scene file/);
    } finally {
      other.stop();
    }
  } finally {
    s.stop();
  }
});

/** A mirror sphere's scene file over `env` (Venice unless told) with its `filter`. */
function sphereOver(name, filter = 'trilinear', env = { file: VENICE, projection: 'latlong' }) {
  return sphereScene(work.dir, name, { environment: { ...env, attach: 'world', filter }, supersample: 2 });
}

/** `mirrorball render` of `scene` with `flags`, and its coverage (`--no-background`). */
function rendered(scene, flags = []) {
  const out = path.join(work.dir, 'rendered.png');
  const cover = path.join(work.dir, 'rendered-cover.png');
  run(['render', scene, ...flags, '-o', out, '--quiet']);
  run(['render', scene, ...flags, '-o', cover, '--quiet', '--no-background']);
  return { full: readPng(readFileSync(out)), cover: readPng(readFileSync(cover)) };
}

test('the scene exported by the button from a mode-4 view is render cone with its filter; the pan blur is said, with its flag', async () => {
  // The file says mode 3: the orbited page shows mode 4 (its cones read the trilinear chain).
  await onStudioPage(chromium, [sphereOver('cones.json')], '&mode=4&yaw=0.6&pitch=0.35&distance=2.8', async ({ page, logs }) => {
    const check = async (what, flags) => {
      await page.evaluate(() => window.studio.redraw());
      const gpu = await viewportPixels(page);
      const file = await clickDownload(page, '#export-scene');
      assert.equal(path.basename(file), 'mirrorball-scene.json');
      const exported = JSON.parse(readFileSync(file, 'utf8'));
      assert.equal(exported.indexing, 'cone');
      assert.equal(exported.environment.filter, 'trilinear');
      const { full, cover } = rendered(file, flags);
      assert.equal(full.width, gpu.width);
      assert.equal(full.height, gpu.height);
      // As studio.test.mjs holds mode 4 with a trilinear environment to render: 99%.
      const { n, within, bg, bgWithin } = againstRender(gpu.data, full, cover);
      console.log(`${what}: ${((100 * within) / n).toFixed(2)}% of ${n} covered pixels within 2/255 of render ${flags.join(' ')}, background ${((100 * bgWithin) / bg).toFixed(2)}% of ${bg}`);
      assert.ok(n > 1000, `${n} covered pixels`);
      assert.ok(within / n >= 0.99);
      assert.ok(bgWithin / bg >= 0.99);
      return gpu;
    };
    const sharp = await check('mode 4 export', []);
    assert.equal(await page.locator('#messages .note', { hasText: 'pan blur' }).count(), 0);
    // The pan blur has no place in a scene file: the page says the flag that draws it.
    await page.locator('#pan-blur').fill('12');
    await page.waitForFunction(() => window.studio.view.panBlur === 12);
    const blurred = await check('mode 4 export with the pan blur', ['--pan-blur', '12']);
    const note = await page.textContent('#messages .note >> nth=0');
    assert.match(note, /mirrorball render mirrorball-scene\.json --pan-blur 12 /);
    let differ = 0;
    for (let i = 0; i < sharp.data.length; i++) if (sharp.data[i] !== blurred.data[i]) differ++;
    assert.ok(differ > sharp.data.length / 20, `the blur shows: ${differ} bytes differ`);
    assert.deepEqual(logs.filter((l) => /error/i.test(l)), []);
  });
  // A dual paraboloid drawn as the hardware did is no scene render draws: refused, said.
  const para = path.join(work.dir, 'venice-paraboloid.exr');
  run(['convert', VENICE, '--to', 'paraboloid', '--size', '64', para, '--quiet']);
  const p = await studio([sphereOver('paraboloid.json', 'bilinear', { file: para, projection: 'paraboloid' })]);
  try {
    const { page: hw } = await openStudio(chromium, `${p.url}&mode=3&paraboloid=hardware`);
    await hw.click('#export-scene');
    await hw.waitForSelector('#messages .error', { timeout: 30000 });
    assert.match(await hw.textContent('#messages .error'), /as the hardware did.*choose "exact"/);
    await hw.close();
  } finally {
    p.stop();
  }
});

test('the wheel and the + and - keys zoom (the distance the URL and the exported scene give); the arrow keys orbit', async () => {
  await onStudioPage(chromium, [sphereOver('zoom.json')], '', async ({ page, logs }) => {
    const now = async () => {
      await page.evaluate(() => window.studio.redraw());
      const url = new URLSearchParams(await page.evaluate(() => location.search));
      const file = JSON.parse(readFileSync(await clickDownload(page, '#export-scene'), 'utf8'));
      const d = Math.hypot(...file.camera.eye.map((e, k) => e - file.camera.target[k]));
      return { url: Number(url.get('distance')), yaw: Number(url.get('yaw')), file: d };
    };
    const d0 = Math.hypot(0, 0.4, 3.2);
    // The wheel over the viewport: exp(deltaY / 1000), deltaY as the page received it.
    await page.evaluate(() => {
      window.wheeled = 0;
      window.studio.canvas.addEventListener('wheel', (e) => (window.wheeled += e.deltaY));
    });
    const box = await page.locator('#viewport').boundingBox();
    await page.mouse.move(box.x + box.width / 2, box.y + box.height / 2);
    await page.mouse.wheel(0, 300);
    await page.waitForFunction(() => window.wheeled !== 0);
    const wheeled = await page.evaluate(() => window.wheeled);
    const out = await now();
    const want = d0 * Math.exp(wheeled / 1000);
    console.log(`wheel ${wheeled}: distance ${d0.toFixed(4)} -> URL ${out.url.toFixed(4)}, exported ${out.file.toFixed(4)} (want ${want.toFixed(4)})`);
    assert.ok(wheeled > 0);
    assert.ok(Math.abs(out.url - want) < 1e-6 * want);
    assert.ok(Math.abs(out.file - want) < 1e-5 * want);
    // '+' twice moves in by 0.9 each, '-' once back out by 1/0.9.
    await page.keyboard.press('+');
    await page.keyboard.press('+');
    const plus = await now();
    assert.ok(Math.abs(plus.url - want * 0.81) < 1e-6 * want, `after ++: ${plus.url}`);
    assert.ok(Math.abs(plus.file - want * 0.81) < 1e-5 * want);
    await page.keyboard.press('-');
    const minus = await now();
    assert.ok(Math.abs(minus.url - want * 0.9) < 1e-6 * want, `after -: ${minus.url}`);
    assert.ok(Math.abs(minus.file - want * 0.9) < 1e-5 * want);
    // The arrow keys orbit: the yaw turns, the distance stays.
    await page.keyboard.press('ArrowLeft');
    const orbited = await now();
    assert.ok(Math.abs(orbited.yaw - minus.yaw - 0.05) < 1e-9, `yaw ${minus.yaw} -> ${orbited.yaw}`);
    assert.equal(orbited.url, minus.url);
    console.log(`keys: ++ ${plus.url.toFixed(4)}, - ${minus.url.toFixed(4)}, ArrowLeft yaw +${(orbited.yaw - minus.yaw).toFixed(3)}, distance kept`);
    assert.deepEqual(logs.filter((l) => /error/i.test(l)), []);
  });
});
