// The simulator view (Zimmons' simulators) beside the viewport, the difference heat map and
// the view state in the URL. After each viewport draw (studio.js `afterDraw`) the scene is
// drawn again by the viewport's own shaders into float targets: the record pass
// (glsl/sim-record.glsl: each pixel's (u, v, layer) read) and the surface pass
// (glsl/sim-surface.frag: position and normal). The map picture (glsl/sim-map.frag) shows
// the environment in its layout, the texels the frame read marked pink, the texel under the
// cursor ringed; the viewport's overlay draws that pixel's normal (green) and reflected
// vector (red). The heat map: per covered pixel, the angle between the direction the mode
// looked up and mode 3's exact reflected direction, each the core's direction of the texel
// read (the server's `/api/directions`: the page holds no inverse of any projection).

/** The most triangles whose texture-space edges the map shows (the first ones drawn). */
const EDGE_TRIANGLES = 4096;

/**
 * The layout of an environment payload's picture: grid (columns, rows), cell per layer, as
 * the server gives it from the core's layouts (state.rs `layout_of`: six layers as the
 * horizontal cross, two side by side, one alone), so every projection's every layer shows.
 */
export function layoutOf(header) {
  return header.layout;
}

/** The angle between unit vectors a and b in degrees (atan2 of |a x b| and a.b: exact near 0). */
export function angleDeg(a, b) {
  const c = [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  return (Math.atan2(Math.hypot(...c), a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) * 180) / Math.PI;
}

/**
 * The (u, v, layer) of the pixels covered in the exact record pass (RGBA floats, one pixel
 * each), the mode's first and then the exact pass's, as f32 triples: what the server turns
 * into directions (`POST /api/directions`, the core's uv_to_dir). Returns them with the
 * pixels' indices.
 */
export function lookupsOf(mode, exact) {
  const pixels = [];
  for (let i = 0; i < exact.length / 4; i++) if (exact[4 * i + 3] > 0) pixels.push(i);
  const m = pixels.length;
  const body = new Float32Array(6 * m);
  pixels.forEach((i, k) => {
    body.set(mode.subarray(4 * i, 4 * i + 3), 3 * k);
    body.set(exact.subarray(4 * i, 4 * i + 3), 3 * (m + k));
  });
  return { pixels, body };
}

/**
 * The heat map's numbers: `n` pixels, of which `pixels` are covered, `dirs` the directions of
 * their mode's texels then of their exact texels (f32 triples, NaN where a texel has none).
 * Per covered pixel the angle between the two; `invalid` counts covered pixels whose mode
 * read nothing. Returns the angles (NaN where not compared), worst, mean and the count.
 */
export function heatOf(n, pixels, dirs) {
  const m = pixels.length;
  const angles = new Float32Array(n).fill(NaN);
  let worst = 0;
  let sum = 0;
  let count = 0;
  let invalid = 0;
  pixels.forEach((i, k) => {
    const a = dirs.subarray(3 * k, 3 * k + 3);
    const b = dirs.subarray(3 * (m + k), 3 * (m + k) + 3);
    if (!a.every(Number.isFinite) || !b.every(Number.isFinite)) {
      invalid++;
      return;
    }
    const e = angleDeg(a, b);
    angles[i] = e;
    worst = Math.max(worst, e);
    sum += e;
    count++;
  });
  return { angles, worst, mean: count ? sum / count : 0, count, invalid };
}

/** A colour for t in [0, 1]: dark blue, through green and yellow, to white (the legend's). */
function ramp(t) {
  const stops = [
    [0, [20, 20, 90]],
    [0.35, [30, 150, 120]],
    [0.7, [240, 220, 40]],
    [1, [255, 255, 255]],
  ];
  t = Math.max(0, Math.min(1, t));
  for (let k = 1; k < stops.length; k++) {
    const [t1, c1] = stops[k];
    const [t0, c0] = stops[k - 1];
    if (t <= t1) {
      const f = (t - t0) / (t1 - t0);
      return c0.map((c, j) => Math.round(c + f * (c1[j] - c)));
    }
  }
  return stops[stops.length - 1][1];
}

/** (x, y) in the window of `view` and `proj` (column-major), row 0 at the top. */
function project(view, proj, p, w, h) {
  const mul = (m, v) => [0, 1, 2, 3].map((r) => m[r] * v[0] + m[4 + r] * v[1] + m[8 + r] * v[2] + m[12 + r] * v[3]);
  const c = mul(proj, mul(view, [p[0], p[1], p[2], 1]));
  return [(c[0] / c[3] * 0.5 + 0.5) * w, (1 - (c[1] / c[3] * 0.5 + 0.5)) * h];
}

/** The URL's view settings: numbers that are finite, or null. */
function urlNumber(params, name) {
  const s = params.get(name);
  if (s === null) return null;
  const x = Number(s);
  return Number.isFinite(x) ? x : null;
}

/** Plugs the simulator into the studio page's handle (studio.js); returns its own handle. */
export function attach(studio) {
  const { gl, G, view, canvas } = studio;
  const params = new URLSearchParams(location.search);
  const sim = {
    marks: params.get('marks') !== '0',
    heat: params.get('heat') === '1',
    edges: params.get('edges') !== '0',
    edgeLines: null, // { corners, lines } of the last frame, modes 1-2
    record: null, // the last record pass: Float32Array, bottom row first
    heatStats: null,
    hover: null,
    map: null, // { key, width, height, image, cells, grid }
    programs: new Map(),
    targets: null,
    heatOf,
  };
  // The view in the URL: the orbit (yaw, pitch, distance), read once.
  const yaw = urlNumber(params, 'yaw');
  const pitch = urlNumber(params, 'pitch');
  const distance = urlNumber(params, 'distance');
  const fromUrl = yaw !== null && pitch !== null && distance !== null && distance > 0;

  let panel = null;
  if (!studio.embed) {
    panel = document.getElementById('sim');
    panel.hidden = false;
    panel.innerHTML = `
      <div class="sim-controls">
        <label><input id="sim-marks" type="checkbox"> texels read</label>
        <label><input id="sim-edges" type="checkbox"> triangle edges (modes 1, 2)</label>
        <label><input id="sim-heat" type="checkbox"> error vs mode 3</label>
      </div>
      <canvas id="sim-map"></canvas>
      <p id="sim-hover" class="note"></p>
      <canvas id="sim-heatmap" hidden></canvas>
      <p id="sim-stats" class="note"></p>`;
    const wrap = document.createElement('div');
    wrap.style.position = 'relative';
    canvas.replaceWith(wrap);
    wrap.appendChild(canvas);
    const overlay = document.createElement('canvas');
    overlay.id = 'sim-overlay';
    overlay.style.cssText = 'position:absolute;left:0;top:0;pointer-events:none';
    wrap.appendChild(overlay);
    sim.overlay = overlay;
    const marks = document.getElementById('sim-marks');
    const heat = document.getElementById('sim-heat');
    const edgeBox = document.getElementById('sim-edges');
    edgeBox.checked = sim.edges;
    edgeBox.addEventListener('change', () => {
      sim.edges = edgeBox.checked;
      studio.redraw();
    });
    marks.checked = sim.marks;
    heat.checked = sim.heat;
    marks.addEventListener('change', () => {
      sim.marks = marks.checked;
      studio.redraw();
    });
    heat.addEventListener('change', () => {
      sim.heat = heat.checked;
      studio.redraw();
    });
    canvas.addEventListener('pointermove', (e) => {
      if (e.buttons) return;
      sim.hoverAt(Math.floor(e.offsetX), Math.floor(e.offsetY));
    });
  }

  async function recordProgram(mode, kind, layers) {
    const key = `record ${kind} ${layers} ${mode} ${view.state.scene.environment.filter}`;
    if (!sim.programs.has(key)) {
      const cone = `#define CONE_READ ${G.coneRead(view.state.scene.environment.filter)}\n`;
      const defines = `#define MODE ${mode}\n#define TEXGEN ${G.texgenOf(kind, layers)}\n#define BACKGROUND 0\n`;
      const proj = await G.projectionSource(kind);
      const vs = G.HEADER + defines + proj + '\n' + (await G.glsl('texgen.glsl')) + '\n' + (await G.glsl('viewport.vert'));
      const fs = [G.HEADER + defines + cone + proj];
      for (const f of ['bilinear.glsl', 'display.glsl', 'interpolate.glsl', 'sim-record.glsl', 'cone.glsl', 'viewport.frag']) fs.push(await G.glsl(f));
      sim.programs.set(key, G.link(gl, vs, fs.join('\n')));
    }
    return sim.programs.get(key);
  }

  /**
   * viewport.vert under `mode`, its per-vertex values (vC0, vC1, vC2: what the rasteriser
   * interpolates) captured by transform feedback: the corners of each triangle's edges.
   */
  async function cornerProgram(mode, kind, layers) {
    const key = `corners ${kind} ${layers} ${mode}`;
    if (!sim.programs.has(key)) {
      const defines = `#define MODE ${mode}\n#define TEXGEN ${G.texgenOf(kind, layers)}\n#define BACKGROUND 0\n`;
      const proj = await G.projectionSource(kind);
      const vs = G.HEADER + defines + proj + '\n' + (await G.glsl('texgen.glsl')) + '\n' + (await G.glsl('viewport.vert'));
      const p = G.link(gl, vs, G.HEADER + 'out vec4 o;\nvoid main() { o = vec4(0.0); }\n');
      gl.transformFeedbackVaryings(p, ['vC0', 'vC1', 'vC2'], gl.INTERLEAVED_ATTRIBS);
      gl.linkProgram(p);
      if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(`program: ${gl.getProgramInfoLog(p)}`);
      sim.programs.set(key, p);
    }
    return sim.programs.get(key);
  }

  /**
   * The triangles' edges on the map picture for modes 1-2: polylines of picture positions.
   * Where the vertex stage makes (u, v) (mode 1 with a sphere map or a single-layer map) the
   * rasteriser interpolates them linearly, so an edge is the straight line between its
   * corners' texels, straight through the picture even across the lat-long seam (Zimmons'
   * artefact); where it makes directions, each point of the edge is envUv of the
   * interpolated direction (samples run through the shader's own envUv, G.envUvOnGpu), and
   * the edge breaks where consecutive samples land in different layers or jump the seam.
   */
  async function edges(mode) {
    const h = view.env.header;
    const layers = [];
    const tf = gl.createTransformFeedback();
    const buffers = [];
    await studio.draw({
      framebuffer: sim.targets.record.fb,
      background: false,
      program: () => cornerProgram(mode, h.projection, h.layers),
      drawMesh: (m) => {
        const count = Math.min(m.vertices, 3 * EDGE_TRIANGLES);
        const b = gl.createBuffer();
        gl.bindBuffer(gl.TRANSFORM_FEEDBACK_BUFFER, b);
        gl.bufferData(gl.TRANSFORM_FEEDBACK_BUFFER, count * 36, gl.STREAM_READ);
        gl.bindTransformFeedback(gl.TRANSFORM_FEEDBACK, tf);
        gl.bindBufferBase(gl.TRANSFORM_FEEDBACK_BUFFER, 0, b);
        gl.enable(gl.RASTERIZER_DISCARD);
        gl.beginTransformFeedback(gl.TRIANGLES);
        gl.drawArrays(gl.TRIANGLES, 0, count);
        gl.endTransformFeedback();
        gl.disable(gl.RASTERIZER_DISCARD);
        gl.bindBufferBase(gl.TRANSFORM_FEEDBACK_BUFFER, 0, null);
        gl.bindTransformFeedback(gl.TRANSFORM_FEEDBACK, null);
        buffers.push([b, count]);
      },
    });
    const corners = [];
    for (const [b, count] of buffers) {
      const out = new Float32Array(count * 9);
      gl.bindBuffer(gl.TRANSFORM_FEEDBACK_BUFFER, b);
      gl.getBufferSubData(gl.TRANSFORM_FEEDBACK_BUFFER, 0, out);
      gl.deleteBuffer(b);
      // Each vertex carries its triangle's three corners: one vertex a triangle suffices.
      for (let t = 0; t < count; t += 3) corners.push(out.subarray(9 * t, 9 * t + 9));
    }
    gl.bindBuffer(gl.TRANSFORM_FEEDBACK_BUFFER, null);
    gl.deleteTransformFeedback(tf);
    const uvMade = mode === 1 && G.texgenOf(h.projection, h.layers) !== 1;
    const m = sim.map;
    const at = (uvl) => {
      const cell = m.cells[Math.round(uvl[2])];
      return cell ? [(cell[0] + uvl[0]) * m.texel[0], (cell[1] + uvl[1]) * m.texel[1]] : null;
    };
    if (uvMade) {
      for (const c of corners) {
        for (let k = 0; k < 3; k++) {
          const a = [c[3 * k], c[3 * k + 1], 0];
          const b = [c[3 * ((k + 1) % 3)], c[3 * ((k + 1) % 3) + 1], 0];
          if ([...a, ...b].every(Number.isFinite)) layers.push([at(a), at(b)]);
        }
      }
      return { corners, lines: layers };
    }
    const steps = 16;
    const dirs = new Float32Array(corners.length * 3 * (steps + 1) * 3);
    let o = 0;
    for (const c of corners) {
      for (let k = 0; k < 3; k++) {
        const j = (k + 1) % 3;
        for (let s = 0; s <= steps; s++) {
          const f = s / steps;
          for (let q = 0; q < 3; q++) dirs[o++] = (1 - f) * c[3 * k + q] + f * c[3 * j + q];
        }
      }
    }
    // Mode 2's corners are world directions; attached to the eye, the environment's
    // direction is the view's rotation of it (viewport.frag `attach`). Mode 1's are already
    // the environment's. envUv is scale-invariant: no normalising needed.
    if (mode === 2 && view.state.scene.environment.attach === 'eye') {
      const v = studio.camera().view;
      for (let i = 0; i < dirs.length; i += 3) {
        const [x, y, z] = [dirs[i], dirs[i + 1], dirs[i + 2]];
        dirs[i] = v[0] * x + v[4] * y + v[8] * z;
        dirs[i + 1] = v[1] * x + v[5] * y + v[9] * z;
        dirs[i + 2] = v[2] * x + v[6] * y + v[10] * z;
      }
    }
    const uv = dirs.length ? await G.envUvOnGpu(gl, h.projection, h.frame, h.params, dirs) : new Float32Array(0);
    for (let e = 0; e < dirs.length / 3 / (steps + 1); e++) {
      let line = [];
      let last = null;
      for (let s = 0; s <= steps; s++) {
        const i = 4 * (e * (steps + 1) + s);
        const uvl = [uv[i], uv[i + 1], uv[i + 2]];
        const p = uvl[2] >= 0 && Number.isFinite(uvl[0]) ? at(uvl) : null;
        if (!p || (last && (last[2] !== uvl[2] || Math.abs(last[0] - uvl[0]) > 0.5))) {
          if (line.length > 1) layers.push(line);
          line = [];
        }
        if (p) line.push(p);
        last = p ? uvl : null;
      }
      if (line.length > 1) layers.push(line);
    }
    return { corners, lines: layers };
  }

  async function surfaceProgram(kind, layers) {
    const key = `surface ${kind} ${layers}`;
    if (!sim.programs.has(key)) {
      const defines = `#define MODE 3\n#define TEXGEN ${G.texgenOf(kind, layers)}\n#define BACKGROUND 0\n`;
      const proj = await G.projectionSource(kind);
      const vs = G.HEADER + defines + proj + '\n' + (await G.glsl('texgen.glsl')) + '\n' + (await G.glsl('viewport.vert'));
      const fs = G.HEADER + (await G.glsl('interpolate.glsl')) + '\n' + (await G.glsl('sim-surface.frag'));
      sim.programs.set(key, G.link(gl, vs, fs));
    }
    return sim.programs.get(key);
  }

  async function mapProgram(kind) {
    const key = `map ${kind}`;
    if (!sim.programs.has(key)) {
      const vs =
        G.HEADER +
        'void main() { vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2)) * 2.0 - 1.0; gl_Position = vec4(p, 0.0, 1.0); }\n';
      const fs = G.HEADER + (await G.glsl('bilinear.glsl')) + '\n' + (await G.glsl('display.glsl')) + '\n' + (await G.glsl('sim-map.frag'));
      sim.programs.set(key, G.link(gl, vs, fs));
    }
    return sim.programs.get(key);
  }

  function floatTarget(w, h, attachments) {
    const fb = gl.createFramebuffer();
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
    const textures = [];
    for (let k = 0; k < attachments; k++) {
      const t = gl.createTexture();
      gl.bindTexture(gl.TEXTURE_2D, t);
      gl.texStorage2D(gl.TEXTURE_2D, 1, gl.RGBA32F, w, h);
      gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0 + k, gl.TEXTURE_2D, t, 0);
      textures.push(t);
    }
    const depth = gl.createRenderbuffer();
    gl.bindRenderbuffer(gl.RENDERBUFFER, depth);
    gl.renderbufferStorage(gl.RENDERBUFFER, gl.DEPTH_COMPONENT24, w, h);
    gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.DEPTH_ATTACHMENT, gl.RENDERBUFFER, depth);
    gl.drawBuffers(textures.map((_, k) => gl.COLOR_ATTACHMENT0 + k));
    const status = gl.checkFramebufferStatus(gl.FRAMEBUFFER);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    if (status !== gl.FRAMEBUFFER_COMPLETE) throw new Error(`the simulator's float target is incomplete (${status})`);
    return { fb, textures, depth, w, h };
  }

  function targets() {
    const [w, h] = [canvas.width, canvas.height];
    if (sim.targets && sim.targets.w === w && sim.targets.h === h) return sim.targets;
    if (!gl.getExtension('EXT_color_buffer_float')) throw new Error('the simulator needs EXT_color_buffer_float');
    if (sim.targets) {
      for (const t of [sim.targets.record, sim.targets.exact, sim.targets.surface]) {
        t.textures.forEach((x) => gl.deleteTexture(x));
        gl.deleteRenderbuffer(t.depth);
        gl.deleteFramebuffer(t.fb);
      }
    }
    sim.targets = { w, h, record: floatTarget(w, h, 1), exact: floatTarget(w, h, 1), surface: floatTarget(w, h, 2) };
    return sim.targets;
  }

  function readFloats(target, attachment, x, y, w, h) {
    const out = new Float32Array(w * h * 4);
    gl.bindFramebuffer(gl.FRAMEBUFFER, target.fb);
    gl.readBuffer(gl.COLOR_ATTACHMENT0 + attachment);
    gl.readPixels(x, y, w, h, gl.RGBA, gl.FLOAT, out);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    return out;
  }

  /** Draws the scene's (u, v, layer) reads under `mode` into `target`; returns them, top row first. */
  async function recordInto(target, mode) {
    const h = view.env.header;
    await studio.draw({
      framebuffer: target.fb,
      clear: [0, 0, -2, 0],
      background: false,
      program: () => recordProgram(mode, h.projection, h.layers),
    });
    return topFirst(readFloats(target, 0, 0, 0, target.w, target.h), target.w, target.h);
  }

  /** Four floats a pixel read bottom row first, turned top row first. */
  function topFirst(raw, w, h) {
    const out = new Float32Array(raw.length);
    const row = 4 * w;
    for (let y = 0; y < h; y++) out.set(raw.subarray((h - 1 - y) * row, (h - y) * row), y * row);
    return out;
  }

  /**
   * Each viewport pixel's world position and unit normal as the viewport interpolates them
   * (the surface pass), top row first, four floats a pixel (alpha 1 where an object is):
   * `{ width, height, position, normal }`.
   */
  sim.surface = async () => {
    const t = targets();
    const h = view.env.header;
    await studio.draw({
      framebuffer: t.surface.fb,
      clear: [0, 0, 0, 0],
      background: false,
      program: () => surfaceProgram(h.projection, h.layers),
    });
    return {
      width: t.w,
      height: t.h,
      position: topFirst(readFloats(t.surface, 0, 0, 0, t.w, t.h), t.w, t.h),
      normal: topFirst(readFloats(t.surface, 1, 0, 0, t.w, t.h), t.w, t.h),
    };
  };

  /** The map picture of the loaded environment (one pixel a texel), made once per environment. */
  async function mapPicture() {
    const h = view.env.header;
    if (sim.map && sim.map.texture === view.env.texture) return sim.map;
    const { grid, cells } = layoutOf(h);
    const [pw, ph] = [grid[0] * h.width, grid[1] * h.height];
    const t = gl.createTexture();
    gl.bindTexture(gl.TEXTURE_2D, t);
    gl.texStorage2D(gl.TEXTURE_2D, 1, gl.RGBA8, pw, ph);
    const fb = gl.createFramebuffer();
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, t, 0);
    const p = await mapProgram(h.projection);
    gl.useProgram(p);
    const u = (n) => gl.getUniformLocation(p, n);
    const s = view.state.scene;
    gl.activeTexture(gl.TEXTURE0);
    gl.bindTexture(gl.TEXTURE_2D_ARRAY, view.env.texture);
    gl.uniform1i(u('uEnv'), 0);
    gl.uniform2i(u('uEnvSize'), h.width, h.height);
    gl.uniform1f(u('uIntensity'), s.environment.intensity);
    gl.uniform1f(u('uExposureScale'), Math.pow(2, s.exposure));
    gl.uniform1i(u('uTone'), { clamp: 0, reinhard: 1, aces: 2 }[s.tone]);
    gl.uniform2i(u('uGrid'), grid[0], grid[1]);
    gl.uniform2iv(u('uCells'), new Int32Array([...cells.flat(), ...new Array(12 - 2 * cells.length).fill(-1)]));
    gl.uniform1i(u('uLayers'), h.layers);
    gl.disable(gl.DEPTH_TEST);
    gl.viewport(0, 0, pw, ph);
    gl.bindVertexArray(null);
    gl.drawArrays(gl.TRIANGLES, 0, 3);
    const pixels = new Uint8ClampedArray(pw * ph * 4);
    gl.readPixels(0, 0, pw, ph, gl.RGBA, gl.UNSIGNED_BYTE, pixels);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    gl.deleteFramebuffer(fb);
    gl.deleteTexture(t);
    sim.map = { texture: view.env.texture, width: pw, height: ph, pixels, grid, cells, texel: [h.width, h.height] };
    return sim.map;
  }

  /** Picture position (x, y) of the texel holding (u, v) of `layer`, or null. */
  function texelOf(uvl) {
    const m = sim.map;
    const [u, v, layer] = uvl;
    const cell = m.cells[Math.round(layer)];
    if (!(layer >= 0) || !cell || !Number.isFinite(u) || !Number.isFinite(v)) return null;
    const [tw, th] = m.texel;
    const tx = Math.min(tw - 1, Math.max(0, Math.floor(u * tw)));
    const ty = Math.min(th - 1, Math.max(0, Math.floor(v * th)));
    return [cell[0] * tw + tx, cell[1] * th + ty];
  }

  function paintMap() {
    if (!panel || !sim.map) return;
    const m = sim.map;
    const image = new ImageData(new Uint8ClampedArray(m.pixels), m.width, m.height);
    if (sim.marks && sim.record) {
      const r = sim.record;
      for (let i = 0; i < r.length / 4; i++) {
        if (!(r[4 * i + 3] > 0)) continue;
        const at = texelOf(r.subarray(4 * i, 4 * i + 3));
        if (at) image.data.set([255, 80, 200, 255], 4 * (at[1] * m.width + at[0]));
      }
    }
    const mapCanvas = document.getElementById('sim-map');
    const zoom = Math.max(1, Math.ceil(512 / m.width));
    mapCanvas.width = m.width * zoom;
    mapCanvas.height = m.height * zoom;
    mapCanvas.style.width = '512px';
    const ctx = mapCanvas.getContext('2d');
    const off = new OffscreenCanvas(m.width, m.height);
    off.getContext('2d').putImageData(image, 0, 0);
    ctx.imageSmoothingEnabled = false;
    ctx.drawImage(off, 0, 0, mapCanvas.width, mapCanvas.height);
    if (sim.edgeLines) {
      ctx.strokeStyle = 'rgba(120, 255, 255, 0.8)';
      ctx.lineWidth = 1;
      ctx.beginPath();
      for (const line of sim.edgeLines.lines) {
        ctx.moveTo(line[0][0] * zoom, line[0][1] * zoom);
        for (const p of line.slice(1)) ctx.lineTo(p[0] * zoom, p[1] * zoom);
      }
      ctx.stroke();
    }
    if (sim.hover?.texel) {
      const [x, y] = sim.hover.texel;
      // Yellow on black, to stand out from the pink marks around it.
      for (const [colour, width] of [['#000', 4], ['#ffe040', 2]]) {
        ctx.strokeStyle = colour;
        ctx.lineWidth = width;
        ctx.beginPath();
        ctx.arc((x + 0.5) * zoom, (y + 0.5) * zoom, Math.max(6, 2 * zoom), 0, 2 * Math.PI);
        ctx.stroke();
      }
    }
  }

  function paintOverlay() {
    if (!sim.overlay) return;
    const o = sim.overlay;
    o.width = canvas.width;
    o.height = canvas.height;
    const ctx = o.getContext('2d');
    ctx.clearRect(0, 0, o.width, o.height);
    const hv = sim.hover;
    if (!hv?.position) return;
    const cam = studio.camera();
    const proj = view.state.scene.camera.projection;
    const len = 0.25 * Math.hypot(...[0, 1, 2].map((k) => hv.position[k] - cam.eye[k]));
    const from = project(cam.view, proj, hv.position, o.width, o.height);
    for (const [vec, colour] of [[hv.normal, '#40e040'], [hv.reflected, '#ff4040']]) {
      const to = project(cam.view, proj, hv.position.map((p, k) => p + len * vec[k]), o.width, o.height);
      ctx.strokeStyle = colour;
      ctx.lineWidth = 2;
      ctx.beginPath();
      ctx.moveTo(...from);
      ctx.lineTo(...to);
      ctx.stroke();
    }
  }

  function paintHeat() {
    if (!panel) return;
    const c = document.getElementById('sim-heatmap');
    const stats = document.getElementById('sim-stats');
    const hs = sim.heatStats;
    c.hidden = !hs;
    if (!hs) {
      stats.textContent = sim.heat && view.mode === 3 ? 'mode 3 is the reference: choose mode 1 or 2' : '';
      return;
    }
    const [w, h] = [canvas.width, canvas.height];
    const legend = 24;
    c.width = w;
    c.height = h + legend;
    const ctx = c.getContext('2d');
    const image = ctx.createImageData(w, h);
    const top = Math.max(1, Math.ceil(hs.worst));
    for (let i = 0; i < w * h; i++) {
      const e = hs.angles[i];
      image.data.set(Number.isNaN(e) ? [0, 0, 0, 0] : [...ramp(e / top), 255], 4 * i);
    }
    ctx.putImageData(image, 0, 0);
    for (let x = 0; x < w; x++) {
      ctx.fillStyle = `rgb(${ramp(x / (w - 1)).join(',')})`;
      ctx.fillRect(x, h + 2, 1, 10);
    }
    ctx.fillStyle = '#ddd';
    ctx.font = '10px sans-serif';
    ctx.fillText('0°', 1, h + legend - 1);
    ctx.fillText(`${top}°`, w - 24, h + legend - 1);
    stats.textContent =
      `mode ${view.mode} against mode 3: worst ${hs.worst.toFixed(3)}°, mean ${hs.mean.toFixed(3)}° over ${hs.count} covered pixels` +
      (hs.invalid ? ` (${hs.invalid} read nothing)` : '');
  }

  function writeUrl() {
    if (studio.embed) return;
    const p = new URLSearchParams(location.search);
    p.set('mode', String(view.mode));
    p.set('projection', view.projection);
    p.set('material', view.material);
    p.set('roughness', String(view.roughness));
    p.set('lightsize', String(view.lightSize));
    p.set('paraboloid', view.paraboloid);
    if (view.tessellation) p.set('tessellation', String(view.tessellation));
    else p.delete('tessellation');
    // Always named, `scene` too: a link decides the object whatever the server shows.
    p.set('object', view.state?.object ?? 'scene');
    if (view.attach) p.set('attach', view.attach);
    else p.delete('attach');
    p.set('twin', view.twin ? '1' : '0');
    if (view.panBlur) p.set('panblur', String(view.panBlur));
    else p.delete('panblur');
    if (view.size) p.set('size', String(view.size));
    if (view.orbit) {
      p.set('yaw', String(view.orbit.yaw));
      p.set('pitch', String(view.orbit.pitch));
      p.set('distance', String(view.orbit.distance));
    } else {
      for (const k of ['yaw', 'pitch', 'distance']) p.delete(k);
    }
    p.set('marks', sim.marks ? '1' : '0');
    p.set('heat', sim.heat ? '1' : '0');
    p.set('edges', sim.edges ? '1' : '0');
    history.replaceState(null, '', `${location.pathname}?${p}`);
  }

  /** The simulator's passes and pictures for the frame just drawn. */
  sim.update = async () => {
    writeUrl();
    if (studio.embed || !view.env) return;
    const t = targets();
    const h = view.env.header;
    sim.record = await recordInto(t.record, view.mode);
    await studio.draw({
      framebuffer: t.surface.fb,
      clear: [0, 0, 0, 0],
      background: false,
      program: () => surfaceProgram(h.projection, h.layers),
    });
    sim.heatStats = null;
    if (sim.heat && view.mode !== 3) {
      const exact = await recordInto(t.exact, 3);
      const { pixels, body } = lookupsOf(sim.record, exact);
      const r = await G.api(`/api/directions?projection=${encodeURIComponent(view.projection)}`, { method: 'POST', body });
      sim.heatStats = heatOf(exact.length / 4, pixels, new Float32Array(await r.arrayBuffer()));
    }
    await mapPicture();
    sim.edgeLines = sim.edges && view.mode !== 3 ? await edges(view.mode) : null;
    if (sim.hover) sim.hoverAt(...sim.hover.pixel);
    paintMap();
    paintHeat();
  };

  /**
   * What viewport pixel (x, y) (row 0 at the top) shows: the (u, v, layer) it read, that
   * texel's place on the map picture, its world position, normal and exact reflected vector;
   * one pixel of each target is read back.
   */
  sim.hoverAt = (x, y) => {
    const t = sim.targets;
    if (!t || x < 0 || y < 0 || x >= t.w || y >= t.h) return null;
    const gy = t.h - 1 - y;
    const rec = readFloats(t.record, 0, x, gy, 1, 1);
    const pos = readFloats(t.surface, 0, x, gy, 1, 1);
    const nrm = readFloats(t.surface, 1, x, gy, 1, 1);
    const hv = { pixel: [x, y], uvl: null, texel: null, position: null, normal: null, reflected: null };
    if (rec[3] > 0 && pos[3] > 0) {
      hv.uvl = Array.from(rec.subarray(0, 3));
      hv.texel = texelOf(hv.uvl);
      hv.position = Array.from(pos.subarray(0, 3));
      hv.normal = Array.from(nrm.subarray(0, 3));
      const cam = studio.camera();
      const c = view.state.scene.camera;
      let d = c.fov !== null ? hv.position.map((p, k) => p - cam.eye[k]) : [-cam.view[2], -cam.view[6], -cam.view[10]];
      const l = Math.hypot(...d);
      d = d.map((q) => q / l);
      const k = 2 * (d[0] * hv.normal[0] + d[1] * hv.normal[1] + d[2] * hv.normal[2]);
      hv.reflected = d.map((q, i) => q - k * hv.normal[i]);
    }
    sim.hover = hv;
    paintMap();
    paintOverlay();
    if (panel) {
      document.getElementById('sim-hover').textContent = hv.uvl
        ? `pixel ${x}, ${y}: (u, v) = (${hv.uvl[0].toFixed(4)}, ${hv.uvl[1].toFixed(4)}), layer ${hv.uvl[2]}`
        : `pixel ${x}, ${y}: no object`;
    }
    return hv;
  };

  studio.afterDraw.push(sim.update);
  sim.ready = studio.ready.then(async () => {
    if (fromUrl) {
      view.orbit = { yaw, pitch, distance };
      await studio.redraw();
    } else if (!studio.embed) {
      await studio.redraw();
    }
  });
  return sim;
}
