// The studio's downloads, clicked on the page as a person clicks them: the map in the
// viewport's conversion and the GGX chain it is lit by, each opened with `mirrorball info`,
// and the screenshot, which is the viewport's pixels.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import path from 'node:path';
import { browser, run, tempDir, readPng, studio, openStudio, ROOT } from './lib.mjs';

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
    const px = await page.evaluate(() => {
      const p = window.studio.pixels();
      return { width: p.width, height: p.height, data: Array.from(p.data) };
    });
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
