// The server's panels: prefiltered lighting (`/api/lighting`, lighting.rs). The chain is a
// cube with mip levels, read with textureLod at the level the header's `levelOf` table gives
// for the slider's roughness (the filter crate's `RoughnessMapping::level`, computed on the
// server: the page has no copy of the rule); the diffuse term is the SH9 of E/π, its
// coefficients times the basis's constants (`shConstants`, sh.rs `CONSTANTS`).

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

/** The slider's step: the header's `levelOf` has one entry a step from roughness 0 to 1. */
export function roughnessStep(header) {
  return 1 / (header.levelOf.length - 1);
}

/** The level the page reads for `roughness` (rounded to the slider's step): `levelOf`'s entry. */
export function levelOf(header, roughness) {
  const steps = header.levelOf.length - 1;
  const r = Math.min(1, Math.max(0, Number.isFinite(roughness) ? roughness : 0));
  return header.levelOf[Math.round(r * steps)];
}

/** lighting.glsl's `uSh`: each coefficient times its basis constant, 27 floats. */
export function shUniform(header) {
  const out = new Float32Array(27);
  header.sh9.forEach((c, i) => out.set(c.map((x) => x * header.shConstants[i]), 3 * i));
  return out;
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
