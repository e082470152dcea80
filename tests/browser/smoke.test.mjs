// The harness itself: Chromium starts, WebGL2 renders, pixels come back.
import test from 'node:test';
import assert from 'node:assert/strict';
import { browser, serve, tempDir } from './lib.mjs';

test('headless Chromium draws with WebGL2 and gives its pixels back', async () => {
  const tmp = tempDir();
  const { server, url } = await serve(tmp.dir);
  const b = await browser();
  try {
    const page = await b.newPage();
    await page.goto(`${url}/smoke.html`);
    const px = await page.evaluate(() => {
      const c = document.createElement('canvas');
      c.width = c.height = 4;
      const gl = c.getContext('webgl2');
      if (!gl) return null;
      gl.clearColor(1, 0.5, 0, 1);
      gl.clear(gl.COLOR_BUFFER_BIT);
      const out = new Uint8Array(4);
      gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, out);
      return [...out, gl.getExtension('EXT_texture_compression_bptc') ? 1 : 0];
    });
    assert.ok(px, 'WebGL2 is available');
    assert.deepEqual(px.slice(0, 4), [255, 128, 0, 255]);
    console.log(`EXT_texture_compression_bptc: ${px[4] ? 'yes' : 'no'}`);
  } finally {
    await b.close();
    server.close();
    tmp.remove();
  }
});
