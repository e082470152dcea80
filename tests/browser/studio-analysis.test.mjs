// The studio's analysis panel in headless Chromium: the projection shown, measured and drawn
// by the server, against what `mirrorball analyze --projection P --size N` writes of it (the
// same numbers and the same SVG documents), the camera's frustum share against its closed
// form, a measurement again when the projection changes, and a refused size on the page.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import path from 'node:path';
import { browser, run, tempDir, studio, openStudio, ROOT } from './lib.mjs';

let chromium;
let work;
const VENICE = path.join(ROOT, 'assets', 'env', 'venice.exr');

before(async () => {
  chromium = await browser();
  work = tempDir('mirrorball-studio-analysis-');
});
after(async () => {
  await chromium?.close();
  work?.remove();
});

const FIGURES = ['analysis-solid-angle-heatmaps', 'analysis-anisotropy-heatmaps', 'analysis-zimmons-1d'];

test('the analysis panel shows what mirrorball analyze writes of the projection shown', async () => {
  const s = await studio([VENICE]);
  const { page, logs } = await openStudio(chromium, `${s.url}&projection=eac&analysis=1&analysis-size=32`);
  try {
    const got = await page.evaluate(async () => {
      await window.studio.analysis.ready;
      const imgs = Array.from(document.querySelectorAll('#analysis img')).map((i) => [i.closest('figure').id, i.naturalWidth]);
      return { a: window.studio.analysis.last, text: document.getElementById('analysis').textContent, imgs, url: location.search };
    });
    const cli = path.join(work.dir, 'eac');
    run(['analyze', '--projection', 'eac', '--size', '32', '--out', cli]);
    const report = JSON.parse(readFileSync(path.join(cli, 'report.json'), 'utf8'));
    assert.equal(got.a.projection, 'eac');
    assert.deepEqual(got.a.entry.stats, report.projections[0].stats);
    assert.deepEqual(got.a.entry.profile, report.projections[0].profile);
    for (const id of FIGURES) {
      const f = got.a.figures.find((x) => x.id === id);
      assert.ok(f, `no ${id}`);
      assert.equal(f.svg, readFileSync(path.join(cli, `${id}.svg`), 'utf8'), `${id} differs from analyze's`);
    }
    assert.deepEqual(got.imgs.map(([id]) => id), FIGURES);
    for (const [id, w] of got.imgs) assert.ok(w > 100, `${id} is not drawn (${w} px wide)`);
    const st = report.projections[0].stats;
    assert.ok(got.text.includes(`${st.full.ratio.toFixed(4)} (full texels)`), got.text);
    assert.match(got.url, /analysis=1/);
    // The frustum of the default camera (40°, 4:3): its share of the sphere is the closed
    // form 4 asin(sin a sin b) / 4pi; the share of the EAC's texels is near it (the map is
    // close to equal-area).
    const f = got.a.frustum;
    const b = (f.vertical_fov_deg * Math.PI) / 360;
    const a = Math.atan(f.aspect * Math.tan(b));
    assert.ok(Math.abs(f.sphere_share - Math.asin(Math.sin(a) * Math.sin(b)) / Math.PI) < 1e-12);
    assert.ok(f.texels > 0 && Math.abs(f.texel_share / f.sphere_share - 1) < 0.15, JSON.stringify(f));
    console.log(`eac at 6x32²: frustum ${f.horizontal_fov_deg.toFixed(1)}x${f.vertical_fov_deg.toFixed(1)}°, ${(100 * f.texel_share).toFixed(2)}% of the texels, ${(100 * f.sphere_share).toFixed(2)}% of the sphere`);
    if (process.env.STUDIO_SHOTS) await page.screenshot({ path: path.join(process.env.STUDIO_SHOTS, 'studio-analysis.png'), fullPage: true });
    // Another projection chosen while the panel is open is measured in its turn.
    await page.selectOption('#projection', 'sphere');
    await page.waitForFunction(() => window.studio.analysis.last?.projection === 'sphere', null, { timeout: 60000 });
    const sphere = await page.evaluate(() => window.studio.analysis.last.entry.stats);
    assert.equal(sphere.projection, 'sphere');
    // The sphere map's crossover at 1/(2 sqrt 2) (Zimmons).
    assert.ok(Math.abs(sphere.crossover.radius_uv - 0.5 / Math.SQRT2) < 1e-9);
    assert.deepEqual(logs.filter((l) => /error/i.test(l)), []);
  } finally {
    await page.close();
    s.stop();
  }
});

test('a size the server will not measure is said on the panel, and the page keeps working', async () => {
  const s = await studio([VENICE]);
  const { page } = await openStudio(chromium, `${s.url}&projection=cube&analysis=1&analysis-size=4096`);
  try {
    await page.waitForSelector('#analysis .error', { timeout: 30000 });
    assert.match(await page.textContent('#analysis .error'), /size 4096: .* texels of cube, over the \d+ one request measures/);
    await page.evaluate(() => window.studio.redraw());
    const px = await page.evaluate(() => Array.from(window.studio.pixels().data.slice(0, 4)));
    assert.equal(px[3], 255, 'the viewport still draws');
  } finally {
    await page.close();
    s.stop();
  }
});
