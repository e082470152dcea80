// The server's panels: prefiltered lighting (`/api/lighting`, lighting.rs). The chain is a
// cube with mip levels, read with textureLod at level `mapping.level(roughness)` (the rule
// the header's `roughnessToLevel` states, prefilter's); the diffuse term is the SH9 of E/π
// (sh.rs `basis`: the constants below are its K0, K1, K2, K20, K22).

const LEVEL = {
  linear: (r, n) => r * (n - 1),
  ue4: (r, n) => n - 2 + 1.2 * Math.log2(Math.max(r, 1e-3)),
  filament: (r, n) => (n - 1) * r * (2 - r),
};

/** Parses the `MBLT` payload: `{ header, levels: [Uint16Array per level (6 faces)] }`. */
export function parseLighting(buf) {
  const dv = new DataView(buf);
  const magic = String.fromCharCode(...new Uint8Array(buf, 0, 4));
  if (magic !== 'MBLT') throw new Error(`lighting: not a lighting payload (${magic})`);
  const n = dv.getUint32(4, true);
  const header = JSON.parse(new TextDecoder().decode(new Uint8Array(buf, 8, n)));
  const levels = [];
  let o = 8 + n;
  for (let m = 0; m < header.levels; m++) {
    const s = Math.max(1, header.size >> m);
    levels.push(new Uint16Array(buf, o, 6 * s * s * 4));
    o += 6 * s * s * 8;
  }
  return { header, levels };
}

/** The chain as a cube texture with its mip levels (RGBA16F, trilinear). */
export function lightingTexture(gl, { header, levels }) {
  const t = gl.createTexture();
  gl.bindTexture(gl.TEXTURE_CUBE_MAP, t);
  gl.pixelStorei(gl.UNPACK_FLIP_Y_WEBGL, false);
  levels.forEach((data, m) => {
    const s = Math.max(1, header.size >> m);
    for (let f = 0; f < 6; f++) {
      const face = data.subarray(f * s * s * 4, (f + 1) * s * s * 4);
      gl.texImage2D(gl.TEXTURE_CUBE_MAP_POSITIVE_X + f, m, gl.RGBA16F, s, s, 0, gl.RGBA, gl.HALF_FLOAT, face);
    }
  });
  gl.texParameteri(gl.TEXTURE_CUBE_MAP, gl.TEXTURE_MIN_FILTER, gl.LINEAR_MIPMAP_LINEAR);
  gl.texParameteri(gl.TEXTURE_CUBE_MAP, gl.TEXTURE_MAG_FILTER, gl.LINEAR);
  gl.texParameteri(gl.TEXTURE_CUBE_MAP, gl.TEXTURE_MAX_LEVEL, levels.length - 1);
  return t;
}

/** The level the page reads for `roughness` (prefilter's `roughness_to_level`). */
export function levelOf(header, roughness) {
  const rule = LEVEL[header.mapping];
  const r = Math.min(1, Math.max(0, roughness));
  return Math.min(header.levels - 1, Math.max(0, rule(r, header.levels)));
}

/**
 * Fetches the prefiltered lighting through `api`, calling `progress(done, total)` while the
 * server works (the page keeps drawing: the fetch is asynchronous).
 */
export async function fetchLighting(api, { size = 128, mapping = 'linear' } = {}, progress = () => {}) {
  const pending = api(`/api/lighting?size=${size}&mapping=${mapping}`);
  let finished = false;
  pending.finally(() => (finished = true)).catch(() => {});
  (async () => {
    while (!finished) {
      const p = await (await api('/api/lighting/progress')).json();
      progress(p.done, p.total);
      await new Promise((ok) => setTimeout(ok, 200));
    }
  })().catch(() => {});
  return parseLighting(await (await pending).arrayBuffer());
}
