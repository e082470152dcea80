// The studio's WebGL2 machinery, shared by the page (studio.js) and the browser tests: the
// server's payloads (crates/studio/src/texture.rs, geometry.rs, grid.rs), the programs
// assembled from the .glsl files (each formula's one home), the projection check.

const token = new URLSearchParams(location.search).get('token') || '';

/** fetch() of the studio's own `path`, with the token. */
export async function api(path, options = {}) {
  const headers = Object.assign({ 'x-mirrorball-token': token }, options.headers || {});
  const r = await fetch(path, Object.assign({}, options, { headers }));
  if (!r.ok) {
    let message = `${r.status} ${r.statusText}`;
    try {
      const j = await r.json();
      if (j.error) message = j.error;
    } catch (_) {
      /* not JSON */
    }
    throw new Error(message);
  }
  return r;
}

const sources = new Map();
/** The embedded shader file `name` (under web/glsl/). */
export async function glsl(name) {
  if (!sources.has(name)) {
    sources.set(name, api(`/web/glsl/${name}`).then((r) => r.text()));
  }
  return sources.get(name);
}

/**
 * The GLSL of projection `kind`'s envUv: its file `glsl/projections/KIND.glsl` (KIND the
 * core's name; the server says `gpu: true` for exactly the kinds that have one, state.rs
 * `gpu_kind`), after math.glsl and the shared machines it names on its `// needs:` lines
 * (cube faces, the disks' radius and lenses, ...: files under glsl/, each with its own needs),
 * each file once and after what it needs: one home per formula.
 */
export async function projectionSource(kind) {
  const order = [];
  const seen = new Set();
  const visit = async (name, chain) => {
    if (seen.has(name)) return;
    if (chain.includes(name)) throw new Error(`the shaders' needs go round: ${[...chain, name].join(' -> ')}`);
    let text;
    try {
      text = await glsl(`${name}.glsl`);
    } catch (e) {
      throw new Error(name.startsWith('projections/') ? `the viewport does not draw ${kind} maps` : `${name}.glsl: ${e.message}`);
    }
    for (const line of text.matchAll(/^\/\/ needs:(.*)$/gm)) {
      for (const need of line[1].trim().split(/\s+/).filter(Boolean)) await visit(need, [...chain, name]);
    }
    seen.add(name);
    order.push(text);
  };
  await visit('math', []);
  await visit(`projections/${kind}`, []);
  return order.join('\n');
}

/** An environment payload (texture.rs): its JSON header and texels. */
export function parseTexture(buffer) {
  const bytes = new Uint8Array(buffer);
  const magic = String.fromCharCode(...bytes.subarray(0, 4));
  if (magic !== 'MBTX') throw new Error('not an environment payload');
  const n = new DataView(buffer).getUint32(4, true);
  const header = JSON.parse(new TextDecoder().decode(bytes.subarray(8, 8 + n)));
  const at = 8 + n;
  const data =
    header.precision === 'float' ? new Float32Array(buffer, at) : new Uint16Array(buffer, at);
  return { header, data };
}

/** The texture array of a parsed environment payload. */
export function environmentTexture(gl, { header, data }) {
  const t = gl.createTexture();
  gl.bindTexture(gl.TEXTURE_2D_ARRAY, t);
  const float = header.precision === 'float';
  gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
  gl.texImage3D(
    gl.TEXTURE_2D_ARRAY,
    0,
    float ? gl.RGBA32F : gl.RGBA16F,
    header.texelWidth,
    header.texelHeight,
    header.layers,
    0,
    gl.RGBA,
    float ? gl.FLOAT : gl.HALF_FLOAT,
    data,
  );
  for (const p of [gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER]) {
    gl.texParameteri(gl.TEXTURE_2D_ARRAY, p, gl.NEAREST);
  }
  for (const p of [gl.TEXTURE_WRAP_S, gl.TEXTURE_WRAP_T]) {
    gl.texParameteri(gl.TEXTURE_2D_ARRAY, p, gl.CLAMP_TO_EDGE);
  }
  return t;
}

/**
 * A dual paraboloid's two halves as the hardware held them (paraboloid_hw.glsl): two RGBA32F
 * 2D textures, level 0's padded layers of the payload, each texel's alpha 1 where its centre
 * lies in the unit disk (a = 2u - 1, b = 1 - 2v, a² + b² ≤ 1) and 0 outside (the padding
 * included); the colours are the payload's (outside the disk, the rim's).
 */
export function paraboloidTextures(gl, { header, data }) {
  const [x0, y0, w, h] = header.levels[0];
  const [pw, ph] = [w + 2, h + 2];
  const aw = header.texelWidth;
  const ah = header.texelHeight;
  return [0, 1].map((layer) => {
    const texels = new Float32Array(pw * ph * 4);
    for (let py = 0; py < ph; py++) {
      for (let px = 0; px < pw; px++) {
        const at = 4 * ((layer * ah + y0 + py) * aw + x0 + px);
        const o = 4 * (py * pw + px);
        for (let k = 0; k < 3; k++) texels[o + k] = data[at + k];
        const a = (2 * (px - 0.5)) / w - 1;
        const b = 1 - (2 * (py - 0.5)) / h;
        texels[o + 3] = a * a + b * b <= 1 ? 1 : 0;
      }
    }
    const t = gl.createTexture();
    gl.bindTexture(gl.TEXTURE_2D, t);
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32F, pw, ph, 0, gl.RGBA, gl.FLOAT, texels);
    for (const p of [gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER]) gl.texParameteri(gl.TEXTURE_2D, p, gl.NEAREST);
    for (const p of [gl.TEXTURE_WRAP_S, gl.TEXTURE_WRAP_T]) gl.texParameteri(gl.TEXTURE_2D, p, gl.CLAMP_TO_EDGE);
    return t;
  });
}

/**
 * The two halves' texture matrices (paraboloid_hw.glsl), column-major, from the map's frame
 * `frame` (9 numbers, columns right, up, forward of the front half): with l = (right·r,
 * up·r, forward·r), the front's (s, t, 0, q) = ((q + l.x)/2, (q − l.y)/2, 0, 1 + l.z) and the
 * back's, in its frame (−l.x, l.y, −l.z), ((q − l.x)/2, (q − l.y)/2, 0, 1 − l.z).
 */
export function paraboloidTextureMatrices(frame) {
  const right = frame.slice(0, 3);
  const up = frame.slice(3, 6);
  const fwd = frame.slice(6, 9);
  const half = (sx, sz) => {
    // Rows: s, t, 0, q, each a linear form of r plus a constant.
    const q = [sz * fwd[0], sz * fwd[1], sz * fwd[2], 1];
    const s = [0, 1, 2].map((k) => 0.5 * (q[k] + sx * right[k])).concat(0.5);
    const t = [0, 1, 2].map((k) => 0.5 * (q[k] - up[k])).concat(0.5);
    const rows = [s, t, [0, 0, 0, 0], q];
    const m = new Float32Array(16);
    for (let c = 0; c < 4; c++) for (let r = 0; r < 4; r++) m[4 * c + r] = rows[r][c];
    return m;
  };
  const out = new Float32Array(32);
  out.set(half(1, 1), 0);
  out.set(half(-1, -1), 16);
  return out;
}

/** A mesh payload (geometry.rs). */
export function parseMesh(buffer) {
  const v = new DataView(buffer);
  const n = v.getUint32(0, true);
  const t = v.getUint32(4, true);
  return {
    positions: new Float32Array(buffer, 8, 3 * n),
    normals: new Float32Array(buffer, 8 + 12 * n, 3 * n),
    indices: new Uint32Array(buffer, 8 + 24 * n, 3 * t),
  };
}

/** A grid payload (grid.rs): count, the frame, the parameters, and nine floats a direction. */
export function parseGrid(buffer) {
  const count = new DataView(buffer).getUint32(0, true);
  const frame = Array.from(new Float32Array(buffer, 4, 9));
  const params = Array.from(new Float32Array(buffer, 40, 4));
  return { count, frame, params, values: new Float32Array(buffer, 56, 9 * count) };
}

/** The viewport's vertex attributes, in the order of `triangleVertices`' floats. */
export const ATTRIBUTES = ['aPos', 'aP0', 'aP1', 'aP2', 'aN0', 'aN1', 'aN2'];

/**
 * A parsed mesh as the viewport draws it: three vertices a triangle, each with its own
 * position and its triangle's three corners' positions and normals (viewport.vert):
 * `ATTRIBUTES.length` × 3 floats a vertex.
 */
export function triangleVertices(mesh) {
  const { positions: p, normals: n, indices } = mesh;
  const stride = ATTRIBUTES.length * 3;
  const out = new Float32Array((indices.length / 3) * 3 * stride);
  let o = 0;
  for (let t = 0; t < indices.length; t += 3) {
    const corners = [indices[t], indices[t + 1], indices[t + 2]];
    for (const own of corners) {
      out.set(p.subarray(3 * own, 3 * own + 3), o);
      o += 3;
      for (const k of corners) {
        out.set(p.subarray(3 * k, 3 * k + 3), o);
        o += 3;
      }
      for (const k of corners) {
        out.set(n.subarray(3 * k, 3 * k + 3), o);
        o += 3;
      }
    }
  }
  return out;
}

export const HEADER = '#version 300 es\nprecision highp float;\nprecision highp int;\nprecision highp sampler2DArray;\n';

function compile(gl, type, source) {
  const s = gl.createShader(type);
  gl.shaderSource(s, source);
  gl.compileShader(s);
  if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) {
    const log = gl.getShaderInfoLog(s);
    const numbered = source
      .split('\n')
      .map((l, i) => `${i + 1}: ${l}`)
      .join('\n');
    throw new Error(`shader: ${log}\n${numbered}`);
  }
  return s;
}

/** A linked program of vertex and fragment sources. */
export function link(gl, vs, fs) {
  const p = gl.createProgram();
  gl.attachShader(p, compile(gl, gl.VERTEX_SHADER, vs));
  gl.attachShader(p, compile(gl, gl.FRAGMENT_SHADER, fs));
  ATTRIBUTES.forEach((name, i) => gl.bindAttribLocation(p, i, name));
  gl.linkProgram(p);
  if (!gl.getProgramParameter(p, gl.LINK_STATUS)) {
    throw new Error(`program: ${gl.getProgramInfoLog(p)}`);
  }
  return p;
}

/**
 * What mode 1 generates for a map of `kind` with `layers` layers (mirrorball-render's
 * render/texgen.rs, `Texgen::of`): 0 GL_SPHERE_MAP's (s, t) for a sphere map, 2 a
 * single-layer map's own (u, v), 1 GL_REFLECTION_MAP's direction otherwise.
 */
export function texgenOf(kind, layers) {
  if (kind === 'sphere') return 0;
  return layers === 1 ? 2 : 1;
}

/** The materials the viewport draws objects with (viewport.frag `MATERIAL`). */
export const MATERIALS = { mirror: 0, ggx: 1, lambert: 2 };

/**
 * Whether a map of `kind` under `mode` is drawn as the hardware drew a dual paraboloid
 * (`paraboloid: 'hardware'`: two textures, the alpha choosing; paraboloid_hw.glsl).
 */
export function paraboloidHardware(kind, mode, paraboloid) {
  return kind === 'paraboloid' && paraboloid === 'hardware' && mode <= 3;
}

/**
 * Mode 4's read (cone.glsl) for the environment's `filter` (state.rs): the trilinear one for
 * a trilinear environment, as `mirrorball render` filters it; anisotropic taps for the rest,
 * which the CPU filters by EWA.
 */
export function coneRead(filter) {
  return filter === 'trilinear' ? 'coneRead' : 'coneReadAnisotropic';
}

/**
 * The viewport's program for `kind`, indexing `mode` (1–4), objects or the background, the
 * objects in `material` (a name of `MATERIALS`; the prefiltered ones add lighting.glsl);
 * `paraboloid: 'hardware'` draws a dual paraboloid from its two textures; `filter` is the
 * environment's (mode 4: `coneRead`); `panBlur` makes the background's program blur along
 * the pan (viewport.frag `sweep`: a program of its own, because SwiftShader pays for the
 * sweep's loop even where a uniform skips it, 2.5 times the sharp frame).
 */
export async function viewportProgram(gl, { kind, layers, mode, background, material = 'mirror', paraboloid, filter, panBlur = false }) {
  const m = MATERIALS[material];
  if (m === undefined) throw new Error(`material '${material}' is not ${Object.keys(MATERIALS).join(', ')}`);
  const hw = paraboloidHardware(kind, mode, paraboloid);
  const defines =
    `#define MODE ${mode}\n#define TEXGEN ${texgenOf(kind, layers)}\n` +
    `#define BACKGROUND ${background ? 1 : 0}\n#define MATERIAL ${background ? 0 : m}\n` +
    `#define CONE_READ ${coneRead(filter)}\n` +
    (hw ? '#define PARA_HW 1\n' : '') +
    (background && panBlur ? '#define PAN_BLUR 1\n' : '');
  const proj = await projectionSource(kind);
  const vs = HEADER + defines + proj + '\n' + (await glsl('texgen.glsl')) + '\n' + (await glsl('viewport.vert'));
  const fs =
    HEADER +
    defines +
    proj +
    '\n' +
    (await glsl('bilinear.glsl')) +
    '\n' +
    (m && !background ? (await glsl('lighting.glsl')) + '\n' : '') +
    (await glsl('display.glsl')) +
    '\n' +
    (await glsl('interpolate.glsl')) +
    '\n' +
    (await glsl('cone.glsl')) +
    '\n' +
    (hw ? (await glsl('paraboloid_hw.glsl')) + '\n' : '') +
    (await glsl('viewport.frag'));
  return link(gl, vs, fs);
}

/**
 * Runs projection `kind`'s envUv (frame `frame`: 9 numbers, column-major; `params`: its
 * uParams, 4 numbers) on `dirs` (3 floats each) in a float render target; returns
 * (u, v, layer) per direction.
 */
export async function envUvOnGpu(gl, kind, frame, params, dirs) {
  if (!gl.getExtension('EXT_color_buffer_float')) throw new Error('no EXT_color_buffer_float');
  const count = dirs.length / 3;
  const width = Math.min(count, 1024);
  const height = Math.ceil(count / width);
  const input = new Float32Array(width * height * 4);
  for (let i = 0; i < count; i++) input.set(dirs.subarray(3 * i, 3 * i + 3), 4 * i);
  const tex = (data) => {
    const t = gl.createTexture();
    gl.bindTexture(gl.TEXTURE_2D, t);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32F, width, height, 0, gl.RGBA, gl.FLOAT, data);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
    return t;
  };
  const src = tex(input);
  const dst = tex(null);
  const fb = gl.createFramebuffer();
  gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
  gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, dst, 0);
  const vs =
    HEADER +
    'void main() { vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2)) * 2.0 - 1.0; gl_Position = vec4(p, 0.0, 1.0); }\n';
  const fs =
    HEADER +
    (await projectionSource(kind)) +
    '\nuniform highp sampler2D uDirs;\nout vec4 outUv;\n' +
    'void main() { vec3 d = texelFetch(uDirs, ivec2(gl_FragCoord.xy), 0).xyz; outUv = vec4(envUv(d), 1.0); }\n';
  const p = link(gl, vs, fs);
  gl.useProgram(p);
  gl.activeTexture(gl.TEXTURE0);
  gl.bindTexture(gl.TEXTURE_2D, src);
  gl.uniform1i(gl.getUniformLocation(p, 'uDirs'), 0);
  if (frame) gl.uniformMatrix3fv(gl.getUniformLocation(p, 'uFrame'), false, new Float32Array(frame));
  if (params) gl.uniform4fv(gl.getUniformLocation(p, 'uParams'), new Float32Array(params));
  gl.viewport(0, 0, width, height);
  gl.drawArrays(gl.TRIANGLES, 0, 3);
  const out = new Float32Array(width * height * 4);
  gl.readPixels(0, 0, width, height, gl.RGBA, gl.FLOAT, out);
  gl.bindFramebuffer(gl.FRAMEBUFFER, null);
  return out;
}

/**
 * Checks projection `spec`'s shader against the core on the server's grid of `n` cells a
 * side: each direction's (u, v, layer) must be the core's, or (on a seam, where two are
 * right) the one the direction was made from, within `tolerance` in u and v, or else name
 * the direction itself (the core's uv_to_dir of it within 2π·`tolerance` rad).
 */
export async function checkProjection(gl, { kind, spec, n = 64, tolerance = 1e-4 }) {
  const buf = await (await api(`/api/grid?projection=${encodeURIComponent(spec)}&n=${n}`)).arrayBuffer();
  const { count, frame, params, values } = parseGrid(buf);
  const dirs = new Float32Array(3 * count);
  for (let i = 0; i < count; i++) dirs.set(values.subarray(9 * i, 9 * i + 3), 3 * i);
  const got = await envUvOnGpu(gl, kind, frame, params, dirs);
  let worst = 0;
  let worstAt = null;
  let seams = 0;
  let failed = 0;
  const failures = [];
  const apart = [];
  for (let i = 0; i < count; i++) {
    const g = got.subarray(4 * i, 4 * i + 3);
    const err = (k) => {
      const r = values.subarray(9 * i + k, 9 * i + k + 3);
      if (r[2] !== g[2]) return Infinity;
      if (r[2] < 0) return 0;
      return Math.max(Math.abs(r[0] - g[0]), Math.abs(r[1] - g[1]));
    };
    const e0 = err(3);
    const e = Math.min(e0, err(6));
    if (e < e0) seams++;
    if (e > tolerance) {
      apart.push(i);
    } else if (e > worst) {
      worst = e;
      worstAt = { dir: Array.from(dirs.subarray(3 * i, 3 * i + 3)), got: Array.from(g), core: Array.from(values.subarray(9 * i + 3, 9 * i + 9)) };
    }
  }
  // Coordinates apart from both of the core's may still name the direction: a point of an
  // edge the picture holds twice (a tetrahedron's top edge, folded at its middle). The core
  // turns them back into directions (`/api/directions`), which must be the one asked for
  // within the angle `tolerance` spans across a whole map.
  if (apart.length) {
    const body = new Float32Array(3 * apart.length);
    apart.forEach((i, k) => body.set(got.subarray(4 * i, 4 * i + 3), 3 * k));
    const r = await api(`/api/directions?projection=${encodeURIComponent(spec)}`, { method: 'POST', body });
    const back = new Float32Array(await r.arrayBuffer());
    apart.forEach((i, k) => {
      const d = dirs.subarray(3 * i, 3 * i + 3);
      const b = back.subarray(3 * k, 3 * k + 3);
      const len = Math.hypot(...d);
      const cross = Math.hypot(d[1] * b[2] - d[2] * b[1], d[2] * b[0] - d[0] * b[2], d[0] * b[1] - d[1] * b[0]);
      const angle = Math.atan2(cross, d[0] * b[0] + d[1] * b[1] + d[2] * b[2]);
      if (len > 0 && angle <= 2 * Math.PI * tolerance) {
        seams++;
        return;
      }
      failed++;
      if (failures.length < 10) {
        failures.push({ dir: Array.from(d), got: Array.from(got.subarray(4 * i, 4 * i + 3)), core: Array.from(values.subarray(9 * i + 3, 9 * i + 9)), back: Array.from(b) });
      }
    });
  }
  return { count, worst, worstAt, seams, failed, failures };
}
