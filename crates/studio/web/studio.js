// The studio page: the viewport (WebGL2) over what the server has loaded, its controls, file
// picker and drop target, orbit and zoom. `?view=viewport`: the viewport alone, at the scene
// camera's size. `mode`, `projection`, `size` in the URL choose the indexing mode (1-4) and
// the projection the environment is converted to; `material` (mirror, ggx, lambert) and
// `roughness` the objects' material, the prefiltered ones lit by the server's chain (level 0
// `lightsize`² a face) and SH9 (panels.js, lighting.glsl); `paraboloid=hardware` draws a
// dual paraboloid as the hardware did (two textures, the alpha choosing: paraboloid_hw.glsl);
// `tessellation=N` re-tessellates the built-in objects (the slider); `object=NAME` shows a
// built-in or the bundled bunny in place of the scene's objects (the server's `/api/object`;
// a mesh file opened by the picker too); `attach=world|eye` attaches the map to the world or
// to the eye whatever the scene says; `twin=1` draws the same view with the map attached the
// other way beside the viewport (Zimmons' figure 18, view dependence); `panblur=DEG` blurs
// the background as a camera panning that far since the last frame (Greene §9, as `render
// --pan-blur DEG`; viewport.frag `sweep`). The GPU's limits are read here (MAX_TEXTURE_SIZE,
// MAX_CUBE_MAP_TEXTURE_SIZE) and the server sends a map that fits them, resampled by the
// core where it would not (said on the page); `max-texture=N` lowers the first, to see what
// a smaller GPU shows. `window.studio` is the page's handle for tests and later views
// (simulator, overlays) to plug into.

const params = new URLSearchParams(location.search);
const token = params.get('token') || '';
const G = await import(`./gl.js?token=${encodeURIComponent(token)}`);
const P = await import(`./panels.js?token=${encodeURIComponent(token)}`);

const embed = params.get('view') === 'viewport';
if (embed) {
  document.body.classList.add('embed');
  document.getElementById('controls').hidden = true;
  document.getElementById('messages').hidden = true;
  document.querySelector('main').style.padding = '0';
}

const canvas = document.getElementById('viewport');
const gl = canvas.getContext('webgl2', {
  antialias: false,
  alpha: true,
  premultipliedAlpha: false,
  preserveDrawingBuffer: true,
});

/**
 * The GPU's limits: the largest edge of a 2D or array texture (the environment's layers,
 * each padded, its mip chain in an atlas beside level 0) and of a cube map's face (the
 * prefiltered lighting, Greene's capture); `max-texture=N` in the link lowers the first.
 */
const limits = (() => {
  if (!gl) return { texture: 0, cube: 0 };
  const texture = gl.getParameter(gl.MAX_TEXTURE_SIZE);
  const asked = Number(params.get('max-texture'));
  return {
    texture: Number.isInteger(asked) && asked > 0 ? Math.min(asked, texture) : texture,
    cube: gl.getParameter(gl.MAX_CUBE_MAP_TEXTURE_SIZE),
  };
})();

/** The query `/api/environment` is asked with for the view (`mips` for mode 4's chain). */
function environmentQuery(mips) {
  let q = `projection=${encodeURIComponent(view.projection)}&precision=float&mips=${mips ? 1 : 0}&limit=${limits.texture}`;
  if (view.size) q += `&size=${view.size}`;
  return q;
}

/** What the page says of a map the server resampled to fit the GPU (the header's `fitted`). */
function fittedNote(h) {
  const f = h.fitted;
  if (!f) return null;
  return (
    `the map is ${f.from[0]}×${f.from[1]}, more than this GPU's textures hold (${f.limit} texels on a side` +
    `${f.limit < gl.getParameter(gl.MAX_TEXTURE_SIZE) ? ', as the link asks' : ', MAX_TEXTURE_SIZE'}; ` +
    `each layer is padded by a texel${h.levels.length > 1 ? ' and its mip chain laid beside it' : ''}): ` +
    `the viewport draws it resampled on the server to ${h.width}×${h.height} (antialiased, as mirrorball convert shrinks)`
  );
}

const view = {
  state: null,
  mode: null,
  projection: params.get('projection') || 'native',
  size: params.get('size') ? Number(params.get('size')) : null,
  paraboloid: params.get('paraboloid') === 'hardware' ? 'hardware' : 'exact',
  // The map's attachment (null: the scene's), and the other one drawn beside (`twin`).
  attach: ['world', 'eye'].includes(params.get('attach')) ? params.get('attach') : null,
  twin: params.get('twin') === '1',
  // Greene §9's motion blur of the background: the degrees the camera panned (about its up
  // axis, positive to the left) since the previous frame, as `render --pan-blur` (0: none).
  panBlur: Number.isFinite(Number(params.get('panblur'))) ? Math.max(-90, Math.min(90, Number(params.get('panblur')))) : 0,
  // The built-in objects' tessellation (null: the scene's).
  tessellation: params.get('tessellation') ? Number(params.get('tessellation')) : null,
  env: null, // { header, texture, halves (a dual paraboloid's two 2D textures) }
  material: G.MATERIALS[params.get('material')] !== undefined ? params.get('material') : 'mirror',
  roughness: params.get('roughness') !== null && Number.isFinite(Number(params.get('roughness'))) ? Number(params.get('roughness')) : 0.5,
  // The prefiltered lighting of the loaded environment: { header, texture, sh }, or null
  // until the server has made it (the objects are drawn as mirrors meanwhile).
  lighting: null,
  lightingPending: null,
  // The chain's level-0 face edge (`lightsize`: a power of two, 8 to 512; the server says
  // what it refuses).
  // (At most the GPU's cube face: MAX_CUBE_MAP_TEXTURE_SIZE.)
  lightSize: Math.min(Number(params.get('lightsize') || 128), limits.cube || Infinity),
  // What the page says of the environment as the GPU takes it (`fittedNote`).
  envNote: null,
  lightingGeneration: -1,
  meshes: [], // { vao, count }
  programs: new Map(),
  // The orbit: null until the person moves the camera (then the view matrix is made here).
  orbit: null,
  generation: 0,
};

function show(messages) {
  const m = document.getElementById('messages');
  m.replaceChildren(
    ...messages.map(([cls, text]) => {
      const p = document.createElement('p');
      p.className = cls;
      p.textContent = text;
      return p;
    }),
  );
}

/** What the URL asked for that could not be done. */
const linkNotes = [];
/** What the last scene export needs said (the flags render needs beside the file). */
let exportNote = null;

function report(error) {
  const notes = [
    ...linkNotes,
    ...(view.envNote ? [view.envNote] : []),
    ...(exportNote ? [exportNote] : []),
    ...(view.state?.scene?.notes || []),
  ];
  const errors = view.state?.errors || [];
  const message = error ? String(error.message || error) : null;
  show([
    ...errors.map((e) => ['error', e]),
    ...(message && !errors.includes(message) ? [['error', message]] : []),
    ...notes.map((n) => ['note', n]),
  ]);
}

/** The map's attachment now: the page's choice, or the scene's. */
function attachNow() {
  return view.attach ?? view.state?.scene.environment?.attach ?? 'world';
}

/** The object selector: the server's choices, and what it shows now. */
function showObjects() {
  const st = view.state;
  const select = document.getElementById('object');
  const names = [...st.objectChoices];
  if (st.object && !names.includes(st.object)) names.push(st.object);
  const label = (n) => (n === 'scene' ? "the scene's" : n === 'quad' ? 'quad (door)' : n);
  select.replaceChildren(
    ...names.map((n) => {
      const o = document.createElement('option');
      o.value = n;
      o.textContent = label(n);
      return o;
    }),
  );
  select.value = st.object ?? 'scene';
}

/**
 * The projection menu: "as loaded", then every projection of the core's table as the server
 * lists it (state.rs `projections`), its description as the title.
 */
function showProjections() {
  const select = document.getElementById('projection');
  const native = select.querySelector('option[value="native"]');
  select.replaceChildren(
    native,
    ...view.state.projections.map((p) => {
      const o = document.createElement('option');
      o.value = p.name;
      o.textContent = p.name;
      o.title = p.gpu ? p.about : `${p.about} (drawn from its lat-long conversion)`;
      return o;
    }),
  );
  select.value = view.projection;
}

/** What the server shows, the controls that depend on it and the objects' meshes. */
async function loadObjects() {
  view.state = await (await G.api('/api/state')).json();
  document.getElementById('scene-name').textContent = view.state.scene.name;
  document.getElementById('attach').value = attachNow();
  document.getElementById('twin').checked = view.twin;
  document.getElementById('pan-blur').value = String(view.panBlur);
  document.getElementById('pan-blur-value').textContent = `${view.panBlur}°`;
  showObjects();
  showProjections();
  showTessellation();
  await loadMeshes();
}

async function loadState() {
  await loadObjects();
  const s = view.state.scene;
  if (view.mode === null) view.mode = Number(params.get('mode') || s.mode);
  document.getElementById('mode').value = String(view.mode);
  document.getElementById('projection').value = view.projection;
  document.getElementById('material').value = view.material;
  document.getElementById('roughness').value = String(view.roughness);
  document.getElementById('paraboloid').value = view.paraboloid;
  canvas.width = s.camera.width;
  canvas.height = s.camera.height;
  canvas.style.width = `${s.camera.width}px`;
  canvas.style.height = `${s.camera.height}px`;
  await loadEnvironment();
  report();
}

/** What the lighting panel says: the material's level, or the server's progress. */
function lightingNote(text) {
  document.getElementById('roughness-value').textContent = view.roughness.toFixed(2);
  document.getElementById('lighting-status').textContent = text;
}

/**
 * Asks the server for the loaded environment's prefiltered lighting when a prefiltered
 * material is chosen and it is not here yet, showing the server's progress; resolves when
 * it is here (the page keeps drawing meanwhile: the objects as mirrors).
 */
function ensureLighting() {
  if (view.material === 'mirror' || view.lighting || !view.state?.scene.environment) {
    lightingNote(view.lighting ? levelNote() : '');
    return Promise.resolve();
  }
  if (!view.lightingPending) {
    const generation = view.generation;
    view.lightingGeneration = generation;
    view.lightingPending = P.fetchLighting(G.api, { size: view.lightSize }, (done, total) => {
      if (total) lightingNote(`prefiltering on the server: ${Math.round((100 * done) / total)}%`);
    })
      .then((l) => {
        if (generation !== view.generation) return;
        view.lighting = { header: l.header, texture: P.lightingTexture(gl, l), sh: P.shUniform(l.header) };
        const slider = document.getElementById('roughness');
        slider.step = String(P.roughnessStep(l.header));
        lightingNote(levelNote());
      })
      .catch((e) => {
        lightingNote('');
        report(e);
      })
      .finally(() => (view.lightingPending = null));
    lightingNote('prefiltering on the server…');
  }
  // A request for the environment before an upload is followed by one for the new one.
  const asked = view.lightingGeneration;
  return view.lightingPending.then(() => (asked === view.generation ? redraw() : ensureLighting()));
}

/** The chain's level the material reads, for the panel. */
function levelNote() {
  if (!view.lighting || view.material === 'mirror') return '';
  const h = view.lighting.header;
  if (view.material === 'lambert') return 'E/π from SH9';
  return `level ${P.levelOf(h, view.roughness).toFixed(2)} of ${h.levels} (${h.mapping}: ${h.roughnessToLevel})`;
}

/** The material the objects are drawn with now: a prefiltered one once its lighting is here. */
function materialNow() {
  return view.lighting ? view.material : 'mirror';
}

/** Forgets the lighting (a new environment was loaded). */
function dropLighting() {
  if (view.lighting) gl.deleteTexture(view.lighting.texture);
  view.lighting = null;
  view.generation++;
}

/** The slider, for scenes with built-in objects: up to the least of their largest levels. */
function showTessellation() {
  const builtins = view.state.scene.objects.filter((o) => o.builtin);
  const label = document.getElementById('tessellation-label');
  label.hidden = builtins.length === 0;
  if (label.hidden) return;
  const input = document.getElementById('tessellation');
  input.max = String(Math.min(256, ...builtins.map((o) => o.maxTessellation)));
  input.value = String(view.tessellation ?? builtins[0].tessellation);
  document.getElementById('tessellation-value').textContent = input.value;
}

async function loadMeshes() {
  for (const m of view.meshes) gl.deleteVertexArray(m.vao);
  view.meshes = [];
  for (const o of view.state.scene.objects) {
    const q = o.builtin && view.tessellation ? `?tessellation=${view.tessellation}` : '';
    const mesh = G.parseMesh(await (await G.api(`/api/mesh/${o.mesh}${q}`)).arrayBuffer());
    const vao = gl.createVertexArray();
    gl.bindVertexArray(vao);
    const b = gl.createBuffer();
    gl.bindBuffer(gl.ARRAY_BUFFER, b);
    gl.bufferData(gl.ARRAY_BUFFER, G.triangleVertices(mesh), gl.STATIC_DRAW);
    const stride = G.ATTRIBUTES.length * 12;
    G.ATTRIBUTES.forEach((_, loc) => {
      gl.enableVertexAttribArray(loc);
      gl.vertexAttribPointer(loc, 3, gl.FLOAT, false, stride, 12 * loc);
    });
    gl.bindVertexArray(null);
    view.meshes.push({ vao, vertices: mesh.indices.length, material: o.material });
  }
}

async function loadEnvironment() {
  if (view.env) for (const t of [view.env.texture, ...(view.env.halves || [])]) gl.deleteTexture(t);
  view.env = null;
  view.envNote = null;
  if (!view.state.scene.environment) return;
  // Mode 4 reads the mip chain (texture.rs `encode_mips`).
  const mips = view.mode === 4;
  const parsed = G.parseTexture(await (await G.api(`/api/environment?${environmentQuery(mips)}`)).arrayBuffer());
  view.envNote = fittedNote(parsed.header);
  const halves = parsed.header.projection === 'paraboloid' ? G.paraboloidTextures(gl, parsed) : null;
  view.env = { header: parsed.header, texture: G.environmentTexture(gl, parsed), halves };
}

async function program(background) {
  const h = view.env.header;
  const kind = h.projection;
  const material = background ? 'mirror' : materialNow();
  const paraboloid = view.paraboloid;
  const filter = view.state.scene.environment.filter;
  const panBlur = background && view.panBlur !== 0;
  const key = `${kind} ${h.layers} ${view.mode} ${background} ${material} ${paraboloid} ${filter} ${panBlur}`;
  if (!view.programs.has(key)) {
    view.programs.set(
      key,
      await G.viewportProgram(gl, { kind, layers: h.layers, mode: view.mode, background, material, paraboloid, filter, panBlur }),
    );
  }
  return view.programs.get(key);
}

/** gluLookAt(eye, target, up), column-major: mirrorball-render's camera.rs `Camera::view`. */
function lookAt(eye, target, up) {
  const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
  const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  const norm = (a) => {
    const l = Math.hypot(...a);
    return a.map((x) => x / l);
  };
  const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const f = norm(sub(target, eye));
  const s = norm(cross(f, up));
  const u = cross(s, f);
  return [s[0], u[0], -f[0], 0, s[1], u[1], -f[1], 0, s[2], u[2], -f[2], 0, -dot(s, eye), -dot(u, eye), dot(f, eye), 1];
}

/**
 * The previous frame's camera of a pan by `degrees` (render's camera.rs `Camera::panned`):
 * the target turned about the eye by the angle about the camera's up axis, then looked at
 * with the scene's up, as the CPU makes it. Its view matrix.
 */
function pannedView(eye, view3, degrees) {
  const c = view.state.scene.camera;
  const a = (degrees * Math.PI) / 180;
  const k = [view3[1], view3[5], view3[9]]; // the camera's up
  const v = [c.target[0] - eye[0], c.target[1] - eye[1], c.target[2] - eye[2]];
  // Rodrigues: v cos a + (k x v) sin a + k (k.v)(1 - cos a).
  const kxv = [k[1] * v[2] - k[2] * v[1], k[2] * v[0] - k[0] * v[2], k[0] * v[1] - k[1] * v[0]];
  const kv = k[0] * v[0] + k[1] * v[1] + k[2] * v[2];
  const t = [0, 1, 2].map((i) => eye[i] + v[i] * Math.cos(a) + kxv[i] * Math.sin(a) + k[i] * kv * (1 - Math.cos(a)));
  return lookAt(eye, t, c.up);
}

/** The camera now: the scene's, or the orbited one. */
function camera() {
  const c = view.state.scene.camera;
  if (!view.orbit) return { eye: c.eye, view: c.view };
  const { yaw, pitch, distance } = view.orbit;
  const t = c.target;
  const eye = [
    t[0] + distance * Math.cos(pitch) * Math.sin(yaw),
    t[1] + distance * Math.sin(pitch),
    t[2] + distance * Math.cos(pitch) * Math.cos(yaw),
  ];
  return { eye, view: lookAt(eye, t, c.up) };
}

/**
 * Draws the scene; `pass` (the simulator's, sim.js) may draw it into `framebuffer` with
 * `program(background)` instead of the viewport's, clear to `clear`, leave the background
 * out (`background: false`), draw each mesh itself (`drawMesh(mesh)`) and attach the map
 * otherwise (`attach`: 'world' or 'eye').
 */
async function draw(pass = {}) {
  const s = view.state.scene;
  const c = s.camera;
  gl.bindFramebuffer(gl.FRAMEBUFFER, pass.framebuffer ?? null);
  gl.viewport(0, 0, canvas.width, canvas.height);
  gl.clearColor(...(pass.clear ?? [0, 0, 0, 0]));
  gl.clearDepth(1);
  gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
  if (!view.env) return;
  const cam = camera();
  const v = cam.view;
  // Rows of the view matrix: right, up, back (camera.rs `Camera::basis`).
  const right = [v[0], v[4], v[8]];
  const up = [v[1], v[5], v[9]];
  const forward = [-v[2], -v[6], -v[10]];
  const persp = c.fov !== null;
  const aspect = c.width / c.height;
  const ty = persp ? Math.tan((c.fov * Math.PI) / 360) : c.orthoHalfHeight;
  const env = s.environment;
  const h = view.env.header;
  const tone = { clamp: 0, reinhard: 1, aces: 2 }[s.tone];
  const setCommon = (p) => {
    gl.useProgram(p);
    const u = (n) => gl.getUniformLocation(p, n);
    gl.uniformMatrix4fv(u('uView'), false, new Float32Array(v));
    gl.uniformMatrix4fv(u('uProj'), false, new Float32Array(c.projection));
    gl.uniform3fv(u('uEye'), cam.eye);
    gl.uniform1i(u('uPersp'), persp ? 1 : 0);
    gl.uniform3fv(u('uForward'), forward);
    gl.uniform1i(u('uAttachEye'), (pass.attach ?? attachNow()) === 'eye' ? 1 : 0);
    if (h.frame) gl.uniformMatrix3fv(u('uFrame'), false, new Float32Array(h.frame));
    if (h.params) gl.uniform4fv(u('uParams'), new Float32Array(h.params));
    gl.activeTexture(gl.TEXTURE0);
    gl.bindTexture(gl.TEXTURE_2D_ARRAY, view.env.texture);
    gl.uniform1i(u('uEnv'), 0);
    gl.uniform2i(u('uEnvSize'), h.width, h.height);
    gl.uniform1i(u('uLevelCount'), h.levels.length);
    gl.uniform4iv(u('uLevels'), new Int32Array(h.levels.flat()));
    if (view.env.halves) {
      view.env.halves.forEach((t, i) => {
        gl.activeTexture(gl.TEXTURE1 + i);
        gl.bindTexture(gl.TEXTURE_2D, t);
      });
      gl.uniform1i(u('uFront'), 1);
      gl.uniform1i(u('uBack'), 2);
      gl.uniformMatrix4fv(u('uParaMatrix'), false, G.paraboloidTextureMatrices(h.frame));
      gl.activeTexture(gl.TEXTURE0);
    }
    gl.uniform1f(u('uIntensity'), env.intensity);
    gl.uniform1f(u('uExposureScale'), Math.pow(2, s.exposure));
    gl.uniform1i(u('uTone'), tone);
    gl.uniform3fv(u('uRayRight'), right.map((x) => x * ty * aspect));
    gl.uniform3fv(u('uRayUp'), up.map((x) => x * ty));
    gl.uniform2f(u('uViewportSize'), canvas.width, canvas.height);
    if (view.panBlur) {
      const pv = pannedView(cam.eye, v, view.panBlur);
      gl.uniform3fv(u('uPrevForward'), [-pv[2], -pv[6], -pv[10]]);
      gl.uniform3fv(u('uPrevRayRight'), [pv[0], pv[4], pv[8]].map((x) => x * ty * aspect));
      gl.uniform3fv(u('uPrevRayUp'), [pv[1], pv[5], pv[9]].map((x) => x * ty));
    }
    if (view.lighting) {
      gl.activeTexture(gl.TEXTURE1);
      gl.bindTexture(gl.TEXTURE_CUBE_MAP, view.lighting.texture);
      gl.uniform1i(u('uChain'), 1);
      gl.uniform1f(u('uLevel'), P.levelOf(view.lighting.header, view.roughness));
      gl.uniform3fv(u('uSh'), view.lighting.sh);
      gl.activeTexture(gl.TEXTURE0);
    }
    return u;
  };
  const programOf = pass.program ?? program;
  if (s.background && pass.background !== false) {
    gl.disable(gl.DEPTH_TEST);
    setCommon(await programOf(true));
    gl.bindVertexArray(null);
    gl.drawArrays(gl.TRIANGLES, 0, 3);
  }
  gl.enable(gl.DEPTH_TEST);
  gl.depthFunc(gl.LESS);
  const u = setCommon(await programOf(false));
  for (const m of view.meshes) {
    gl.uniform3fv(u('uTint'), m.material.tint);
    gl.bindVertexArray(m.vao);
    if (pass.drawMesh) pass.drawMesh(m);
    else gl.drawArrays(gl.TRIANGLES, 0, m.vertices);
  }
  gl.bindVertexArray(null);
  gl.bindFramebuffer(gl.FRAMEBUFFER, null);
}

/** Called after each redraw of the viewport (the simulator's update). */
const afterDraw = [];

let drawing = null;
/** Draws (one draw at a time; a request while drawing draws again after it). */
function redraw() {
  drawing = (drawing || Promise.resolve())
    .then(async () => {
      await draw();
      for (const f of afterDraw) await f();
    })
    .catch(report);
  return drawing;
}

/** The pixels of the framebuffer bound for reading, RGBA, top row first. */
function readRgba() {
  const w = canvas.width;
  const h = canvas.height;
  const raw = new Uint8Array(w * h * 4);
  gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, raw);
  const out = new Uint8Array(w * h * 4);
  for (let y = 0; y < h; y++) out.set(raw.subarray((h - 1 - y) * w * 4, (h - y) * w * 4), y * w * 4);
  return { width: w, height: h, data: out };
}

/** The viewport's pixels, RGBA, top row first. */
function pixels() {
  return readRgba();
}

/**
 * The twin beside the viewport: the same view drawn with the map attached the other way
 * into a target of the viewport's size and format (RGBA8, a depth buffer), shown on a 2D
 * canvas. `twin.last` keeps its pixels (RGBA, top row first) for tests.
 */
const twin = { target: null, last: null };
async function drawTwin() {
  const figure = document.getElementById('twin-figure');
  const caption = document.getElementById('viewport-caption');
  const on = view.twin && !embed && view.env;
  figure.hidden = !on;
  caption.hidden = !on;
  if (!on) return;
  const w = canvas.width;
  const h = canvas.height;
  let t = twin.target;
  if (!t || t.w !== w || t.h !== h) {
    if (t) {
      gl.deleteFramebuffer(t.fb);
      gl.deleteTexture(t.color);
      gl.deleteRenderbuffer(t.depth);
    }
    const color = gl.createTexture();
    gl.bindTexture(gl.TEXTURE_2D, color);
    gl.texStorage2D(gl.TEXTURE_2D, 1, gl.RGBA8, w, h);
    const depth = gl.createRenderbuffer();
    gl.bindRenderbuffer(gl.RENDERBUFFER, depth);
    gl.renderbufferStorage(gl.RENDERBUFFER, gl.DEPTH_COMPONENT24, w, h);
    const fb = gl.createFramebuffer();
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, color, 0);
    gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.DEPTH_ATTACHMENT, gl.RENDERBUFFER, depth);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    t = twin.target = { fb, color, depth, w, h };
  }
  const mine = attachNow();
  const other = mine === 'eye' ? 'world' : 'eye';
  await draw({ framebuffer: t.fb, attach: other });
  gl.bindFramebuffer(gl.FRAMEBUFFER, t.fb);
  twin.last = readRgba();
  gl.bindFramebuffer(gl.FRAMEBUFFER, null);
  const c = document.getElementById('twin-canvas');
  c.width = w;
  c.height = h;
  c.getContext('2d').putImageData(new ImageData(new Uint8ClampedArray(twin.last.data.buffer), w, h), 0, 0);
  const says = (a) => (a === 'eye' ? 'attached to the eye (it turns with the camera)' : 'attached to the world (it stays as the camera moves)');
  caption.textContent = `the viewport, the map ${says(mine)}`;
  document.getElementById('twin-caption').textContent = `beside it, the map ${says(other)}`;
}

/** Shows `name` (`scene`, a built-in or a bundled mesh) in place of the scene's objects. */
async function chooseObject(name) {
  await G.api(`/api/object?name=${encodeURIComponent(name)}`, { method: 'POST' });
  view.tessellation = null;
  await loadObjects();
}

/** Whether `name` is a scene file's (as the CLI tells them: by the extension). */
const isScene = (name) => /\.(json|toml)$/i.test(name);

/**
 * Uploads the files picked or dropped together: with a scene among them, the others first,
 * held by the server for it (`alongside=1`: the only files an uploaded scene may name
 * besides the built-ins and the bundled bunny), then the scene; without one, each file in
 * turn (an environment, a mesh).
 */
async function upload(list) {
  const files = Array.from(list);
  if (!files.length) return;
  const scenes = files.filter((f) => isScene(f.name));
  const send = (f, q = '') => G.api(`/api/upload?name=${encodeURIComponent(f.name)}${q}`, { method: 'POST', body: f });
  try {
    if (scenes.length > 1) throw new Error(`${scenes.map((f) => f.name).join(', ')}: open one scene at a time`);
    if (scenes.length) {
      for (const f of files) if (f !== scenes[0]) await send(f, '&alongside=1');
      await send(scenes[0]);
      // A new scene: its own camera, mode, tessellation and attachment.
      Object.assign(view, { orbit: null, mode: null, tessellation: null, attach: null });
      params.delete('mode');
    } else {
      for (const f of files) await send(f);
    }
    view.programs.clear();
    dropLighting();
    await loadState();
    await redraw();
    await ensureLighting();
  } catch (e) {
    view.state = await (await G.api('/api/state')).json();
    report(e);
  }
}

document.getElementById('file').addEventListener('change', (e) => upload(e.target.files));
for (const t of ['dragenter', 'dragover']) {
  document.addEventListener(t, (e) => {
    e.preventDefault();
    document.body.id = 'drop';
  });
}
document.addEventListener('dragleave', () => (document.body.id = ''));
document.addEventListener('drop', (e) => {
  e.preventDefault();
  document.body.id = '';
  upload(e.dataTransfer.files);
});
document.getElementById('mode').addEventListener('change', async (e) => {
  view.mode = Number(e.target.value);
  if (view.mode === 4 && view.env && view.env.header.levels.length === 1 && view.env.header.width * view.env.header.height > 1) {
    try {
      await loadEnvironment();
      report();
    } catch (err) {
      report(err);
    }
  }
  redraw();
});
document.getElementById('tessellation').addEventListener('input', (e) => {
  document.getElementById('tessellation-value').textContent = e.target.value;
});
document.getElementById('tessellation').addEventListener('change', async (e) => {
  view.tessellation = Number(e.target.value);
  try {
    await loadMeshes();
    report();
  } catch (err) {
    report(err);
  }
  redraw();
});
document.getElementById('object').addEventListener('change', async (e) => {
  try {
    await chooseObject(e.target.value);
    report();
  } catch (err) {
    report(err);
  }
  redraw();
});
document.getElementById('pan-blur').addEventListener('input', (e) => {
  view.panBlur = Number(e.target.value);
  document.getElementById('pan-blur-value').textContent = `${view.panBlur}°`;
  redraw();
});
document.getElementById('attach').addEventListener('change', (e) => {
  view.attach = e.target.value;
  redraw();
});
document.getElementById('twin').addEventListener('change', (e) => {
  view.twin = e.target.checked;
  redraw();
});
document.getElementById('paraboloid').addEventListener('change', (e) => {
  view.paraboloid = e.target.value;
  redraw();
});
document.getElementById('material').addEventListener('change', (e) => {
  view.material = e.target.value;
  lightingNote(levelNote());
  redraw();
  ensureLighting();
});
document.getElementById('roughness').addEventListener('input', (e) => {
  view.roughness = Number(e.target.value);
  lightingNote(levelNote());
  redraw();
});
document.getElementById('projection').addEventListener('change', async (e) => {
  view.projection = e.target.value;
  try {
    await loadEnvironment();
    report();
  } catch (err) {
    report(err);
  }
  redraw();
});

/** Hands `blob` to the browser as a download called `name`. */
function download(blob, name) {
  const a = document.createElement('a');
  a.href = URL.createObjectURL(blob);
  a.download = name;
  document.body.appendChild(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(a.href), 60000);
}

/**
 * Downloads what the server writes (`/api/export`): the map as the viewport shows it (its
 * projection and size) or the GGX chain it is lit by, in the chosen container.
 */
async function exportFile(what) {
  const format = document.getElementById('export-format').value;
  let q = `what=${what}&format=${format}`;
  if (what === 'map') {
    q += `&projection=${encodeURIComponent(view.projection)}`;
    if (view.size) q += `&size=${view.size}`;
  }
  try {
    const r = await G.api(`/api/export?${q}`);
    const name = /filename="([^"]+)"/.exec(r.headers.get('content-disposition') || '')?.[1] || `export.${format}`;
    download(await r.blob(), name);
    report();
  } catch (e) {
    report(e);
  }
}

/**
 * The scene as a scene file (docs/render-scene.md) that `mirrorball render FILE` (with
 * `sceneFlags()`) draws as the viewport does: the file the scene was read from (the server
 * made its paths absolute; an uploaded scene's as it wrote them) with the camera now
 * (orbited or not), the mode (render's names: texgen, vertex, pixel, cone), one sample a
 * pixel and the filter the viewport reads with (modes 1-3 bilinear; mode 4 the scene's
 * trilinear, else EWA, which the viewport approximates). Refused, with the reason, where
 * neither a scene file nor render's flags can say what the viewport shows.
 */
function sceneFile() {
  const s = view.state.scene;
  if (!s.source) {
    throw new Error('the scene came from no scene file, its environment was replaced, or a mesh file is shown in place of its objects: only a scene opened from a file exports (its meshes and environment are named by path)');
  }
  if (view.projection !== 'native') {
    throw new Error(`the viewport shows the environment converted to ${view.projection}, which a scene file cannot say (render's --env-as): choose "as loaded" to export the scene`);
  }
  if (materialNow() !== 'mirror') {
    throw new Error('the prefiltered materials have no scene-file form: choose the mirror to export the scene');
  }
  if (view.paraboloid === 'hardware' && view.env?.header.projection === 'paraboloid') {
    throw new Error('the viewport draws the dual paraboloid as the hardware did (two textures, the alpha test), which mirrorball render does not (it reads the map exactly): choose "exact" to export the scene');
  }
  const out = JSON.parse(JSON.stringify(s.source));
  const c = s.camera;
  const cam = camera();
  out.camera = Object.assign({}, out.camera, { eye: cam.eye, target: c.target, up: c.up, width: c.width, height: c.height });
  const indexing = ['texgen', 'vertex', 'pixel', 'cone'][view.mode - 1];
  if (!indexing) throw new Error(`mode ${view.mode} has no scene-file name`);
  out.indexing = indexing;
  out.supersample = 1;
  if (out.environment) {
    out.environment.filter = view.mode === 4 ? (s.environment?.filter === 'trilinear' ? 'trilinear' : 'ewa') : 'bilinear';
    out.environment.attach = attachNow();
  }
  // The slider's tessellation, for the built-ins (the server names them in `meshes`).
  if (view.tessellation && out.meshes) {
    out.meshes.forEach((m, i) => {
      if (s.objects[i]?.builtin) m.tessellation = view.tessellation;
    });
  }
  return out;
}

/**
 * What `mirrorball render` needs besides the scene file to draw what the viewport shows:
 * the pan blur, which scene files do not hold (`--pan-blur DEG`).
 */
function sceneFlags() {
  return view.panBlur ? ['--pan-blur', String(view.panBlur)] : [];
}

document.getElementById('export-scene').addEventListener('click', () => {
  try {
    const file = sceneFile();
    const flags = sceneFlags();
    download(new Blob([JSON.stringify(file, null, 2)], { type: 'application/json' }), 'mirrorball-scene.json');
    exportNote = flags.length
      ? `the pan blur has no place in a scene file: mirrorball render mirrorball-scene.json ${flags.join(' ')} draws what the viewport shows`
      : null;
    report();
  } catch (e) {
    exportNote = null;
    report(e);
  }
});
document.getElementById('export-map').addEventListener('click', () => exportFile('map'));
document.getElementById('export-chain').addEventListener('click', () => exportFile('chain'));
document.getElementById('screenshot').addEventListener('click', async () => {
  await drawing;
  canvas.toBlob((b) => download(b, 'mirrorball-viewport.png'), 'image/png');
});

function startOrbit() {
  if (view.orbit) return;
  const c = view.state.scene.camera;
  const d = [c.eye[0] - c.target[0], c.eye[1] - c.target[1], c.eye[2] - c.target[2]];
  const distance = Math.hypot(...d);
  view.orbit = { yaw: Math.atan2(d[0], d[2]), pitch: Math.asin(d[1] / distance), distance };
}
function orbitBy(dyaw, dpitch, zoom = 1) {
  if (embed) return;
  startOrbit();
  const o = view.orbit;
  o.yaw += dyaw;
  o.pitch = Math.max(-1.55, Math.min(1.55, o.pitch + dpitch));
  o.distance = Math.max(0.05, o.distance * zoom);
  redraw();
}
let dragging = null;
canvas.addEventListener('pointerdown', (e) => {
  dragging = [e.clientX, e.clientY];
  canvas.setPointerCapture(e.pointerId);
});
canvas.addEventListener('pointermove', (e) => {
  if (!dragging) return;
  const [x, y] = dragging;
  dragging = [e.clientX, e.clientY];
  orbitBy(-(e.clientX - x) * 0.01, (e.clientY - y) * 0.01);
});
canvas.addEventListener('pointerup', () => (dragging = null));
canvas.addEventListener('wheel', (e) => {
  e.preventDefault();
  orbitBy(0, 0, Math.exp(e.deltaY * 0.001));
});
document.addEventListener('keydown', (e) => {
  const k = { ArrowLeft: [0.05, 0], ArrowRight: [-0.05, 0], ArrowUp: [0, 0.05], ArrowDown: [0, -0.05] }[e.key];
  if (k) orbitBy(k[0], k[1]);
  if (e.key === '+' || e.key === '=') orbitBy(0, 0, 0.9);
  if (e.key === '-') orbitBy(0, 0, 1 / 0.9);
});

const ready = (async () => {
  if (!gl) throw new Error('this browser has no WebGL2');
  // A link decides the object: the one it names, else what was opened (the scene's own
  // objects, or the mesh file opened last), never what an earlier link or the menu chose
  // (the server keeps that for every page).
  const asked = params.get('object');
  const st = await (await G.api('/api/state')).json();
  const want = asked ?? st.baseObject;
  if ((st.object ?? 'scene') !== want) {
    if (st.objectChoices.includes(want)) await G.api(`/api/object?name=${encodeURIComponent(want)}`, { method: 'POST' });
    else linkNotes.push(`the link showed the object ${want}, which is not here: open its file again`);
  }
  await loadState();
  await redraw();
  await ensureLighting();
})();
ready.catch(report);

afterDraw.push(drawTwin);
const handle = { ready, redraw, pixels, view, gl, G, P, draw, camera, afterDraw, canvas, embed, program, ensureLighting, sceneFile, sceneFlags, twin, attachNow, chooseObject, limits, environmentQuery };
// The simulator panel and the view state in the URL (sim.js); `ready` waits for both.
const sim = await import(`./sim.js?token=${encodeURIComponent(token)}`);
handle.sim = sim.attach(handle);
handle.ready = ready.then(() => handle.sim.ready);
// The analysis panel (analysis.js), measured once the view is ready when the URL asks.
const analysis = await import(`./analysis.js?token=${encodeURIComponent(token)}`);
handle.analysis = analysis.attach(handle);
const greene = await import(`./greene.js?token=${encodeURIComponent(token)}`);
handle.greene = greene.attach(handle);
window.studio = handle;
