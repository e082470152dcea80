// The README's pictures of `mirrorball studio`, taken as a person sees the page: the studio
// started on a bundled scene, the page opened in headless Chromium (SwiftShader WebGL2) at a
// given view (the URL holds it), a screenshot of the whole page saved under docs/img/.
//
//     cargo build -p mirrorball-cli && node tests/browser/screenshots.mjs [FILE.png…]
//
// (only the named pictures when some are named).
//
// Not a test (the tests hold the pixels to the CPU renderer); a picture maker.
import path from 'node:path';
import { browser, studio, openStudio, ROOT } from './lib.mjs';

// [file, scene, URL keys beyond the token, page size]: each view of the page the README shows.
const VIEWS = [
  ['studio-simulator.png', 'examples/scenes/zimmons-door.json', 'mode=1&marks=1&edges=1', [1100, 460]],
  ['studio-heatmap.png', 'examples/scenes/zimmons-door.json', 'mode=1&heat=1&marks=0&edges=0', [1100, 780]],
  ['studio-lighting.png', 'examples/scenes/chrome-pair.json', 'mode=3&material=ggx&roughness=0.45', [1100, 580]],
  ['studio-cones.png', 'examples/scenes/bunny-cones.json', 'mode=4', [1100, 580]],
  ['studio-analysis.png', 'examples/scenes/zimmons-door.json', 'mode=3&projection=eac&analysis=1&analysis-size=256&marks=0&edges=0', [1100, 1290]],
  ['studio-greene.png', 'examples/scenes/chrome-pair.json', 'mode=3&greene=1&marks=0&edges=0', [1100, 1000]],
  ['studio-twin.png', 'examples/scenes/zimmons-door.json', 'mode=3&object=teapot&twin=1&attach=world&yaw=0.5&pitch=0.3&distance=3.0&marks=0&edges=0', [1100, 760]],
];
const only = process.argv.slice(2);

const chromium = await browser();
try {
  for (const [file, scene, keys, [width, height]] of VIEWS) {
    if (only.length && !only.includes(file)) continue;
    // Named as from the repository's root (the studio runs there): the page shows the name.
    const s = await studio([scene]);
    try {
      const { page, logs } = await openStudio(chromium, `${s.url}&${keys}`);
      await page.setViewportSize({ width, height });
      // The lighting arrives from the server after the first frame: wait for its note.
      if (keys.includes('material=')) {
        await page.waitForFunction(() => /level/.test(document.getElementById('lighting-status')?.textContent ?? ''), null, { timeout: 120000 });
      }
      await page.evaluate(() => window.studio.ready);
      await page.evaluate(() => window.studio.analysis.ready);
      await page.waitForTimeout(1500);
      // Greene live animates: one frame of a fixed time, the loop paused.
      if (keys.includes('greene=1')) {
        await page.evaluate(async () => {
          await window.studio.greene.ready;
          window.studio.greene.pause();
          await window.studio.greene.renderAt(2.6);
        });
      }
      const out = path.join(ROOT, 'docs', 'img', file);
      await page.screenshot({ path: out });
      console.log(`${out}${logs.length ? ` (page said: ${logs.join(' | ')})` : ''}`);
      await page.close();
    } finally {
      s.stop();
    }
  }
} finally {
  await chromium.close();
}
