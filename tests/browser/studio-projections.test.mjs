// Every projection the server lists (state.rs `projections`: the core's table, not a list
// here) in the studio: the menu offers it, the viewport draws the mirror sphere with it
// (mode 3: at least a fifth of the frame not black), and the simulator's map picture shows every layer of the map drawn, each in its
// own cell, none blank.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { browser, studio, tempDir, openStudio, viewportPixels, sphereScene } from './lib.mjs';

let chromium;
let work;
before(async () => {
  chromium = await browser();
  work = tempDir('mirrorball-studio-projections-');
});
after(async () => {
  await chromium?.close();
  work?.remove();
});

test('the viewport draws every projection the server lists and the simulator shows every layer of it', async () => {
  const scene = sphereScene(work.dir, 'sphere.json', {
    camera: { eye: [0, 0.4, 3.2], target: [0, 0, 0], fov: 40, width: 96, height: 72 },
  });
  const s = await studio([scene]);
  const bad = [];
  try {
    const first = await openStudio(chromium, s.url);
    const listed = await first.page.evaluate(() => window.studio.view.state.projections);
    const menu = await first.page.$$eval('#projection option', (o) => o.map((x) => x.value));
    await first.page.close();
    assert.ok(listed.length >= 19, `${listed.length} projections listed`);
    for (const p of listed) {
      assert.ok(menu.includes(p.name), `the menu lacks ${p.name}`);
    }
    for (const p of listed) {
      const { page, logs } = await openStudio(chromium, `${s.url}&mode=3&projection=${p.name}&size=32`);
      try {
        const errors = await page.$$eval('#messages .error', (es) => es.map((e) => e.textContent));
        if (errors.length) bad.push(`${p.name}: ${errors.join('; ')}`);
        const pageErrors = logs.filter((l) => /error/i.test(l));
        if (pageErrors.length) bad.push(`${p.name}: ${pageErrors.join('; ')}`);
        // The viewport: the environment shows, on the sphere or behind it (a view or a
        // fisheye covers part of the sphere of directions: black elsewhere, as render draws).
        const { width, height, data } = await viewportPixels(page);
        let lit = 0;
        for (let i = 0; i < width * height; i++) {
          if (data[4 * i] + data[4 * i + 1] + data[4 * i + 2] > 6) lit++;
        }
        if (lit < 0.2 * width * height) bad.push(`${p.name}: ${lit} of ${width * height} pixels drawn`);
        // The simulator's map picture: every layer of the map sent, a cell each, not blank.
        const m = await page.evaluate(() => {
          const s = window.studio.sim;
          const h = window.studio.view.env.header;
          const map = s.map;
          const lit = map.cells.map(([cx, cy]) => {
            let count = 0;
            const [tw, th] = map.texel;
            for (let y = cy * th; y < (cy + 1) * th; y++) {
              for (let x = cx * tw; x < (cx + 1) * tw; x++) {
                // readPixels' rows run bottom up.
                const i = 4 * ((map.height - 1 - y) * map.width + x);
                if (map.pixels[i] + map.pixels[i + 1] + map.pixels[i + 2] > 6) count++;
              }
            }
            return count / (tw * th);
          });
          return { layers: h.layers, drawn: h.projection, cells: map.cells, grid: map.grid, lit };
        });
        const expected = p.gpu ? p.layers : 1;
        if (m.cells.length !== m.layers || m.layers !== expected) {
          bad.push(`${p.name}: ${m.cells.length} cells for ${m.layers} layers (${expected} expected)`);
        }
        if (new Set(m.cells.map((c) => c.join())).size !== m.cells.length) bad.push(`${p.name}: layers share a cell`);
        for (const [c, r] of m.cells) {
          if (!(c < m.grid[0] && r < m.grid[1])) bad.push(`${p.name}: cell ${c},${r} outside ${m.grid}`);
        }
        m.lit.forEach((f, i) => {
          if (f < 0.3) bad.push(`${p.name}: layer ${i} is ${(100 * f).toFixed(0)}% drawn in the simulator`);
        });
        console.log(`${p.name}: drawn as ${m.drawn}, ${m.layers} layers in a ${m.grid.join('x')} grid, lit ${m.lit.map((f) => f.toFixed(2)).join(' ')}`);
      } finally {
        await page.close();
      }
    }
  } finally {
    s.stop();
  }
  assert.deepEqual(bad, []);
});
