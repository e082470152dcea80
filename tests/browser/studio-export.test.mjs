// The studio's downloads, clicked on the page as a person clicks them: the map in the
// viewport's conversion and the GGX chain it is lit by, each opened with `mirrorball info`,
// and the screenshot, which is the viewport's pixels.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync, writeFileSync } from 'node:fs';
import path from 'node:path';
import { browser, run, tempDir, readPng, studio, openStudio, viewportPixels, againstRender, ROOT } from './lib.mjs';

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
