// Greene live (Greene 1986, "Environment Mapping and Other Applications of World
// Projections"): a small animated scene over the loaded environment, captured every frame
// into a cube map from the centre of a mirror sphere (the six faces rendered, 90° each, in
// the OpenGL spec's cube-map orientations, so the capture is a standard GL cube map; the
// sphere is not drawn into it: it cannot see itself), the scene seen from an orbiting camera
// with the sphere reflecting the capture per pixel (samplerCube along the reflected ray), and
// beside it an Omnimax frame of the same capture: an equidistant fisheye, 180°, looking up.
// Opened by the header's button or `greene=1` in the URL (`greene-size=N`: the capture's
// edge, 128 unless told).
//
// The panel draws in a WebGL2 context of its own (the viewport's and the simulator's state is
// never touched): the environment is the one the viewport shows (`view.env`'s payload,
// fetched again for this context when the viewport loads another), read through the
// projection's own GLSL (G.projectionSource: one home per formula) with bilinear.glsl's read,
// shown through display.glsl with the scene's exposure and tone.
//
// Time is a parameter: `renderAt(t)` draws the frame of time t seconds (the same t, the same
// pixels); the panel animates it with requestAnimationFrame until paused.

/** The capture's faces, layers +X −X +Y −Y +Z −Z: OpenGL 4.6 §8.13 table 8.19 (core
 * projection/cube.rs, glsl/cubeface.glsl): face L's direction at (s, t) is
 * F + (2s − 1) S + (2t − 1) T (F the major axis, S and T the directions sc and tc grow
 * along). Each (S, T, −F) is a right-handed camera frame, so a face is drawn by the camera
 * whose right is S, up T and forward F with a 90° frustum: window (x, y) is texel (s, t)·N. */
export const FACES = [
  { F: [1, 0, 0], S: [0, 0, -1], T: [0, -1, 0] }, // +X: sc = −z, tc = −y
  { F: [-1, 0, 0], S: [0, 0, 1], T: [0, -1, 0] }, // −X: sc = +z, tc = −y
  { F: [0, 1, 0], S: [1, 0, 0], T: [0, 0, 1] }, // +Y: sc = +x, tc = +z
  { F: [0, -1, 0], S: [1, 0, 0], T: [0, 0, -1] }, // −Y: sc = +x, tc = −z
  { F: [0, 0, 1], S: [1, 0, 0], T: [0, -1, 0] }, // +Z: sc = +x, tc = −y
  { F: [0, 0, -1], S: [-1, 0, 0], T: [0, -1, 0] }, // −Z: sc = −x, tc = −y
];

/** The Omnimax frame's columns (right, up, forward): the dome looks straight up, along +Y
 * (a real Omnimax dome is tilted forward of the zenith; here the axis is +Y itself), its
 * picture's top towards +Z and right towards +X: the core's `Frame::looking_along(+Y)`, the
 * frame of the spec `fisheye:fov=180:look=+y`. */
export const OMNIMAX_FRAME = [1, 0, 0, 0, 0, 1, 0, 1, 0];
/** Its uParams (state.rs `params_of`): the equidistant lens, k = θ_max = 90°, cos θ_max. */
export const OMNIMAX_PARAMS = [0, Math.PI / 2, Math.cos(Math.PI / 2), 0];
/** The core's name for it (what the test asks the server's directions of). */
export const OMNIMAX_SPEC = 'fisheye:fov=180:look=+y';

/** The mirror sphere: it sits at the world's origin, radius 1. */
export const SPHERE = { centre: [0, 0, 0], radius: 1, tint: [0.95, 0.95, 0.95] };
/** Its colour and alpha when drawn into its own capture (the negative control only). */
const SELF_MARKER = { colour: [1, 0, 1], alpha: 0.5 };

/**
 * The moving objects: each orbits the sphere's centre in its own tilted plane (angle
 * `phase + speed t`, radius `orbit`, the plane turned `tilt` about X then `node` about Y)
 * and spins about `axis`; `inner` is the radius of the ball about its centre that it
 * surely contains (the direction of its centre from the sphere's meets it). Linear colours.
 */
export const OBJECTS = [
  { name: 'red cube', shape: 'cube', colour: [1.0, 0.09, 0.05], size: 0.36, inner: 0.36, orbit: 2.5, speed: 0.7, phase: 0.0, tilt: 0.25, node: 0.0, axis: [1, 1, 0], spin: 1.3 },
  { name: 'green octahedron', shape: 'octahedron', colour: [0.08, 0.85, 0.15], size: 0.55, inner: 0.55 / Math.sqrt(3), orbit: 2.9, speed: -0.45, phase: 2.1, tilt: -0.45, node: 0.8, axis: [0, 1, 0], spin: 0.9 },
  { name: 'blue torus', shape: 'torus', colour: [0.15, 0.3, 1.0], size: 0.42, inner: 0, orbit: 2.2, speed: 0.55, phase: 4.0, tilt: 0.9, node: -0.6, axis: [1, 0, 1], spin: 1.1 },
  { name: 'yellow cube', shape: 'cube', colour: [1.0, 0.78, 0.08], size: 0.24, inner: 0.24, orbit: 3.4, speed: 0.32, phase: 1.0, tilt: -1.1, node: 2.0, axis: [0, 0, 1], spin: 1.7 },
];

/** The light the objects are shaded by (a direction, world space). */
const LIGHT = normalize([0.4, 0.8, 0.35]);

/** The panel's two views: the camera's and the Omnimax disk's, side by side on one canvas. */
const VIEW = { width: 320, height: 240, fov: 50 };
const OMNI = { width: 240, height: 240 };

function normalize(a) {
  const l = Math.hypot(...a);
  return a.map((x) => x / l);
}
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];

/** Column-major 4×4 product a·b. */
function mul(a, b) {
  const o = new Array(16).fill(0);
  for (let c = 0; c < 4; c++) for (let r = 0; r < 4; r++) for (let k = 0; k < 4; k++) o[4 * c + r] += a[4 * k + r] * b[4 * c + k];
  return o;
}

/** The view matrix of a camera at `eye` with right `s`, up `u`, forward `f` (orthonormal). */
function viewOf(eye, s, u, f) {
  return [s[0], u[0], -f[0], 0, s[1], u[1], -f[1], 0, s[2], u[2], -f[2], 0, -dot(s, eye), -dot(u, eye), dot(f, eye), 1];
}

/** gluPerspective with the vertical half-angle's tangent `ty`. */
function perspective(ty, aspect, near, far) {
  return [1 / (ty * aspect), 0, 0, 0, 0, 1 / ty, 0, 0, 0, 0, (far + near) / (near - far), -1, 0, 0, (2 * far * near) / (near - far), 0];
}

/** Rotation by `angle` about unit `axis` (Rodrigues), column-major 4×4, times scale `k`, then moved to `at`. */
function model(axis, angle, k, at) {
  const [x, y, z] = normalize(axis);
  const c = Math.cos(angle);
  const s = Math.sin(angle);
  const t = 1 - c;
  const r = [t * x * x + c, t * x * y + s * z, t * x * z - s * y, t * x * y - s * z, t * y * y + c, t * y * z + s * x, t * x * z + s * y, t * y * z - s * x, t * z * z + c];
  return [r[0] * k, r[1] * k, r[2] * k, 0, r[3] * k, r[4] * k, r[5] * k, 0, r[6] * k, r[7] * k, r[8] * k, 0, at[0], at[1], at[2], 1];
}

/** Object `o`'s centre at time `t`. */
export function centreAt(o, t) {
  const a = o.phase + o.speed * t;
  const [x, y0, z0] = [o.orbit * Math.cos(a), 0, o.orbit * Math.sin(a)];
  const [y, z] = [y0 * Math.cos(o.tilt) - z0 * Math.sin(o.tilt), y0 * Math.sin(o.tilt) + z0 * Math.cos(o.tilt)];
  const [cn, sn] = [Math.cos(o.node), Math.sin(o.node)];
  return [SPHERE.centre[0] + cn * x + sn * z, SPHERE.centre[1] + y, SPHERE.centre[2] - sn * x + cn * z];
}

/** The panel camera at time `t`: orbiting the sphere slowly, a little above it. */
export function cameraAt(t) {
  const yaw = 0.6 + 0.12 * t;
  const pitch = 0.32;
  const distance = 6.5;
  const c = SPHERE.centre;
  const eye = [c[0] + distance * Math.cos(pitch) * Math.sin(yaw), c[1] + distance * Math.sin(pitch), c[2] + distance * Math.cos(pitch) * Math.cos(yaw)];
  const forward = normalize([c[0] - eye[0], c[1] - eye[1], c[2] - eye[2]]);
  const right = normalize(cross(forward, [0, 1, 0]));
  const up = cross(right, forward);
  const ty = Math.tan((VIEW.fov * Math.PI) / 360);
  return { eye, right, up, forward, ty, aspect: VIEW.width / VIEW.height, width: VIEW.width, height: VIEW.height };
}

/** Triangles (6 floats a vertex: position, normal) of the shapes, unit sized. */
function shape(kind) {
  const out = [];
  const tri = (a, b, c, n) => {
    n = n ?? normalize(cross([b[0] - a[0], b[1] - a[1], b[2] - a[2]], [c[0] - a[0], c[1] - a[1], c[2] - a[2]]));
    for (const p of [a, b, c]) out.push(...p, ...n);
  };
  if (kind === 'cube') {
    for (let axis = 0; axis < 3; axis++) {
      for (const sgn of [1, -1]) {
        const n = [0, 0, 0];
        n[axis] = sgn;
        const u = [0, 0, 0];
        const v = [0, 0, 0];
        u[(axis + 1) % 3] = 1;
        v[(axis + 2) % 3] = sgn;
        const p = (a, b) => [0, 1, 2].map((k) => n[k] + a * u[k] + b * v[k]);
        tri(p(-1, -1), p(1, -1), p(1, 1), n);
        tri(p(-1, -1), p(1, 1), p(-1, 1), n);
      }
    }
  } else if (kind === 'octahedron') {
    for (const sx of [1, -1]) {
      for (const sy of [1, -1]) {
        for (const sz of [1, -1]) {
          const [a, b, c] = [[sx, 0, 0], [0, sy, 0], [0, 0, sz]];
          // Wound outwards.
          if (sx * sy * sz > 0) tri(a, b, c);
          else tri(a, c, b);
        }
      }
    }
  } else {
    // A torus about Y: ring radius 1, tube 0.38, smooth normals.
    const [ring, tube, nu, nv] = [1, 0.38, 36, 16];
    const at = (i, j) => {
      const [a, b] = [(2 * Math.PI * i) / nu, (2 * Math.PI * j) / nv];
      const n = [Math.cos(b) * Math.cos(a), Math.sin(b), Math.cos(b) * Math.sin(a)];
      return [[(ring + tube * Math.cos(b)) * Math.cos(a), tube * Math.sin(b), (ring + tube * Math.cos(b)) * Math.sin(a)], n];
    };
    for (let i = 0; i < nu; i++) {
      for (let j = 0; j < nv; j++) {
        const [p00, n00] = at(i, j);
        const [p10, n10] = at(i + 1, j);
        const [p01, n01] = at(i, j + 1);
        const [p11, n11] = at(i + 1, j + 1);
        for (const [p, n] of [[p00, n00], [p01, n01], [p11, n11], [p00, n00], [p11, n11], [p10, n10]]) out.push(...p, ...n);
      }
    }
  }
  return new Float32Array(out);
}

const FULLSCREEN =
  'void main() { vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2)) * 2.0 - 1.0; gl_Position = vec4(p, 0.0, 1.0); }\n';

/** Plugs the panel into the studio page's handle (studio.js); returns its own handle. */
export function attach(studio) {
  const { G, view } = studio;
  const params = new URLSearchParams(location.search);
  const panel = document.getElementById('greene');
  const button = document.getElementById('greene-toggle');
  const size = Number(params.get('greene-size'));
  const gr = {
    open: false,
    paused: false,
    // The capture's edge in texels.
    size: Number.isInteger(size) && size >= 4 && size <= 1024 ? size : 128,
    // Test hooks: the moving objects left out; the sphere drawn into its own capture.
    hideObjects: false,
    selfVisible: false,
    t: 0,
    last: null, // the last frame's { t, captureMs, viewMs, omniMs, totalMs }
    times: [],
    gl: null,
    FACES,
    OBJECTS,
    SPHERE,
    SELF_MARKER,
    OMNIMAX_FRAME,
    OMNIMAX_PARAMS,
    OMNIMAX_SPEC,
    VIEW,
    OMNI,
    cameraAt,
    centreAt,
  };
  let gl = null;
  let canvas = null;
  const programs = new Map();
  const meshes = {};
  let env = null; // { source (the view.env it copies), header, texture }
  let envLoading = null;
  let capture = null; // { size, cube, depth, fb }
  let dirTarget = null;
  let clock = null; // { start (performance.now), t0 }
  let raf = 0;

  function writeUrl() {
    const p = new URLSearchParams(location.search);
    if (gr.open) p.set('greene', '1');
    else p.delete('greene');
    history.replaceState(null, '', `${location.pathname}?${p}`);
  }

  function build() {
    if (gl) return;
    panel.innerHTML = `
      <h3>Greene live</h3>
      <canvas id="greene-canvas" width="${VIEW.width + OMNI.width}" height="${VIEW.height}" style="cursor:default"></canvas>
      <p class="note" id="greene-caption">Left: the scene from an orbiting camera; the mirror sphere reflects, per pixel, the
      cube map captured from its centre this frame (six 90° faces, OpenGL's orientations; the sphere is not in its own capture).
      Right: the Omnimax frame of the same capture, an equidistant fisheye of 180° looking straight up (+Y), +Z at the top.</p>
      <div><button id="greene-pause" type="button">pause</button> <span class="note">t = <output id="greene-t">0.00</output> s</span></div>
      <p class="note" id="greene-stats"></p>
      <p class="error" id="greene-error" hidden></p>`;
    panel.style.maxWidth = `${VIEW.width + OMNI.width}px`;
    canvas = document.getElementById('greene-canvas');
    gl = canvas.getContext('webgl2', { antialias: false, alpha: true, premultipliedAlpha: false, preserveDrawingBuffer: true });
    if (!gl) throw new Error('Greene live needs WebGL2');
    if (!gl.getExtension('EXT_color_buffer_float')) throw new Error('Greene live needs EXT_color_buffer_float (a half-float cube to render into)');
    gr.gl = gl;
    for (const kind of ['cube', 'octahedron', 'torus']) {
      const data = shape(kind);
      const vao = gl.createVertexArray();
      gl.bindVertexArray(vao);
      const b = gl.createBuffer();
      gl.bindBuffer(gl.ARRAY_BUFFER, b);
      gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW);
      gl.enableVertexAttribArray(0);
      gl.vertexAttribPointer(0, 3, gl.FLOAT, false, 24, 0);
      gl.enableVertexAttribArray(1);
      gl.vertexAttribPointer(1, 3, gl.FLOAT, false, 24, 12);
      gl.bindVertexArray(null);
      meshes[kind] = { vao, count: data.length / 6 };
    }
    document.getElementById('greene-pause').addEventListener('click', () => (gr.paused ? gr.play() : gr.pause()));
  }

  /** The environment the viewport shows, as a texture of this context (fetched when it changes). */
  function ensureEnv() {
    if (env?.source === view.env || envLoading?.source === view.env) return envLoading?.promise ?? Promise.resolve();
    const source = view.env;
    // None while the viewport loads another (or the scene has none): the last one stays.
    if (!source) return Promise.resolve();
    const promise = (async () => {
      const parsed = G.parseTexture(await (await G.api(`/api/environment?${studio.environmentQuery(false)}`)).arrayBuffer());
      await programsFor(parsed.header);
      if (envLoading?.source !== source) return;
      if (env) gl.deleteTexture(env.texture);
      env = { source, header: parsed.header, texture: G.environmentTexture(gl, parsed) };
      envLoading = null;
    })();
    promise.catch(() => {
      if (envLoading?.source === source) envLoading = null;
    });
    envLoading = { source, promise };
    return promise;
  }

  async function programsFor(header) {
    const key = `${header.projection} ${header.layers}`;
    if (programs.has(key)) return programs.get(key);
    const frag = async (name, defines, pre) => G.HEADER + 'precision highp samplerCube;\n' + defines + pre + '\n' + (await G.glsl(name));
    const vs = G.HEADER + (await G.glsl('greene-object.vert'));
    const full = G.HEADER + FULLSCREEN;
    const proj = await G.projectionSource(header.projection);
    const bil = await G.glsl('bilinear.glsl');
    const disp = await G.glsl('display.glsl');
    const math = await G.glsl('math.glsl');
    const inv = await G.glsl('greene-fisheye-inverse.glsl');
    const p = {
      bgCapture: G.link(gl, full, await frag('greene-background.frag', '#define CAPTURE 1\n', `${proj}\n${bil}\n${disp}`)),
      bgView: G.link(gl, full, await frag('greene-background.frag', '#define CAPTURE 0\n', `${proj}\n${bil}\n${disp}`)),
      objCapture: G.link(gl, vs, await frag('greene-object.frag', '#define CAPTURE 1\n', disp)),
      objView: G.link(gl, vs, await frag('greene-object.frag', '#define CAPTURE 0\n', disp)),
      mirrorCapture: G.link(gl, vs, await frag('greene-mirror.frag', '#define CAPTURE 1\n', disp)),
      mirrorView: G.link(gl, vs, await frag('greene-mirror.frag', '#define CAPTURE 0\n', disp)),
      omni: G.link(gl, full, await frag('greene-omnimax.frag', '#define DIRS 0\n', `${math}\n${inv}\n${disp}`)),
      omniDirs: G.link(gl, full, await frag('greene-omnimax.frag', '#define DIRS 1\n', `${math}\n${inv}\n${disp}`)),
    };
    programs.set(key, p);
    return p;
  }

  function captureTarget() {
    if (capture && capture.size === gr.size) return capture;
    if (capture) {
      gl.deleteTexture(capture.cube);
      gl.deleteRenderbuffer(capture.depth);
      gl.deleteFramebuffer(capture.fb);
    }
    const n = gr.size;
    const cube = gl.createTexture();
    gl.bindTexture(gl.TEXTURE_CUBE_MAP, cube);
    gl.texStorage2D(gl.TEXTURE_CUBE_MAP, 1, gl.RGBA16F, n, n);
    for (const [p, v] of [[gl.TEXTURE_MIN_FILTER, gl.LINEAR], [gl.TEXTURE_MAG_FILTER, gl.LINEAR], [gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE], [gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE]]) {
      gl.texParameteri(gl.TEXTURE_CUBE_MAP, p, v);
    }
    const depth = gl.createRenderbuffer();
    gl.bindRenderbuffer(gl.RENDERBUFFER, depth);
    gl.renderbufferStorage(gl.RENDERBUFFER, gl.DEPTH_COMPONENT24, n, n);
    const fb = gl.createFramebuffer();
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
    gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.DEPTH_ATTACHMENT, gl.RENDERBUFFER, depth);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_CUBE_MAP_POSITIVE_X, cube, 0);
    const status = gl.checkFramebufferStatus(gl.FRAMEBUFFER);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    if (status !== gl.FRAMEBUFFER_COMPLETE) throw new Error(`the capture's cube face is not renderable (${status})`);
    capture = { size: n, cube, depth, fb };
    return capture;
  }

  function uniforms(p) {
    gl.useProgram(p);
    const u = (n) => gl.getUniformLocation(p, n);
    const s = view.state?.scene;
    gl.uniform1f(u('uExposureScale'), Math.pow(2, s?.exposure ?? 0));
    gl.uniform1i(u('uTone'), { clamp: 0, reinhard: 1, aces: 2 }[s?.tone] ?? 0);
    return u;
  }

  /** The background (the environment along each pixel's ray) into the bound target. */
  function background(p, forward, right, up, origin, size) {
    if (!env) return;
    const h = env.header;
    const u = uniforms(p);
    gl.activeTexture(gl.TEXTURE0);
    gl.bindTexture(gl.TEXTURE_2D_ARRAY, env.texture);
    gl.uniform1i(u('uEnv'), 0);
    gl.uniform2i(u('uEnvSize'), h.width, h.height);
    gl.uniform1f(u('uIntensity'), view.state?.scene.environment?.intensity ?? 1);
    gl.uniform1i(u('uLevelCount'), 1);
    if (h.frame) gl.uniformMatrix3fv(u('uFrame'), false, new Float32Array(h.frame));
    if (h.params) gl.uniform4fv(u('uParams'), new Float32Array(h.params));
    gl.uniform3fv(u('uForward'), forward);
    gl.uniform3fv(u('uRayRight'), right);
    gl.uniform3fv(u('uRayUp'), up);
    gl.uniform2f(u('uOrigin'), ...origin);
    gl.uniform2f(u('uSize'), ...size);
    gl.disable(gl.DEPTH_TEST);
    gl.bindVertexArray(null);
    gl.drawArrays(gl.TRIANGLES, 0, 3);
  }

  /** The moving objects at time t with `viewProj`, into the bound target. */
  function objects(p, viewProj, t) {
    if (gr.hideObjects) return;
    const u = uniforms(p);
    gl.enable(gl.DEPTH_TEST);
    gl.uniformMatrix4fv(u('uViewProj'), false, new Float32Array(viewProj));
    gl.uniform3fv(u('uLight'), LIGHT);
    OBJECTS.forEach((o, k) => {
      gl.uniformMatrix4fv(u('uModel'), false, new Float32Array(model(o.axis, o.spin * t, o.size, centreAt(o, t))));
      gl.uniform3fv(u('uColour'), o.colour);
      gl.uniform1f(u('uMarker'), 2 + k);
      gl.bindVertexArray(meshes[o.shape].vao);
      gl.drawArrays(gl.TRIANGLES, 0, meshes[o.shape].count);
    });
    gl.bindVertexArray(null);
  }

  /** The mirror sphere's bounding box: the mirror program's proxy. */
  function sphereBox(p, viewProj, extra) {
    const u = uniforms(p);
    gl.enable(gl.DEPTH_TEST);
    gl.uniformMatrix4fv(u('uViewProj'), false, new Float32Array(viewProj));
    gl.uniformMatrix4fv(u('uModel'), false, new Float32Array(model([0, 1, 0], 0, SPHERE.radius, SPHERE.centre)));
    extra(u);
    gl.bindVertexArray(meshes.cube.vao);
    gl.drawArrays(gl.TRIANGLES, 0, meshes.cube.count);
    gl.bindVertexArray(null);
  }

  /** The six faces of the cube seen from the sphere's centre at time t (the sphere left out). */
  function captureAt(t, p) {
    const c = captureTarget();
    const n = c.size;
    gl.bindFramebuffer(gl.FRAMEBUFFER, c.fb);
    gl.viewport(0, 0, n, n);
    const proj = perspective(1, 1, 0.05, 100);
    FACES.forEach((f, layer) => {
      gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_CUBE_MAP_POSITIVE_X + layer, c.cube, 0);
      gl.clearColor(0, 0, 0, 1);
      gl.clearDepth(1);
      gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
      background(p.bgCapture, f.F, f.S, f.T, [0, 0], [n, n]);
      const vp = mul(proj, viewOf(SPHERE.centre, f.S, f.T, f.F));
      objects(p.objCapture, vp, t);
      if (gr.selfVisible) {
        sphereBox(p.mirrorCapture, vp, (u) => {
          gl.uniform3fv(u('uTint'), SELF_MARKER.colour);
          gl.uniform1f(u('uMarker'), SELF_MARKER.alpha);
        });
      }
    });
  }

  function cameraMatrices(t) {
    const cam = cameraAt(t);
    const vp = mul(perspective(cam.ty, cam.aspect, 0.1, 100), viewOf(cam.eye, cam.right, cam.up, cam.forward));
    return { cam, vp };
  }

  /** The panel camera's view at time t into the canvas's left part. */
  function viewAt(t, p) {
    const { cam, vp } = cameraMatrices(t);
    gl.viewport(0, 0, VIEW.width, VIEW.height);
    const k = cam.ty;
    background(p.bgView, cam.forward, cam.right.map((x) => x * k * cam.aspect), cam.up.map((x) => x * k), [0, 0], [VIEW.width, VIEW.height]);
    objects(p.objView, vp, t);
    sphereBox(p.mirrorView, vp, (u) => {
      gl.activeTexture(gl.TEXTURE1);
      gl.bindTexture(gl.TEXTURE_CUBE_MAP, capture.cube);
      gl.uniform1i(u('uCube'), 1);
      gl.uniform3fv(u('uEye'), cam.eye);
      gl.uniform3fv(u('uCentre'), SPHERE.centre);
      gl.uniform1f(u('uRadius'), SPHERE.radius);
      gl.uniform3fv(u('uTint'), SPHERE.tint);
    });
  }

  /** The Omnimax disk (or its directions, `dirs`) into the bound target at `origin`. */
  function omniAt(p, origin) {
    const u = uniforms(p);
    gl.viewport(origin[0], origin[1], OMNI.width, OMNI.height);
    gl.disable(gl.DEPTH_TEST);
    gl.activeTexture(gl.TEXTURE1);
    gl.bindTexture(gl.TEXTURE_CUBE_MAP, captureTarget().cube);
    gl.uniform1i(u('uCube'), 1);
    gl.uniformMatrix3fv(u('uFrame'), false, new Float32Array(OMNIMAX_FRAME));
    gl.uniform4fv(u('uParams'), new Float32Array(OMNIMAX_PARAMS));
    gl.uniform2f(u('uOrigin'), ...origin);
    gl.uniform2f(u('uSize'), OMNI.width, OMNI.height);
    gl.bindVertexArray(null);
    gl.drawArrays(gl.TRIANGLES, 0, 3);
  }

  /** Waits for the GPU (a one-texel read of the bound target). */
  function fence(float) {
    if (float) gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.FLOAT, new Float32Array(4));
    else gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));
  }

  function currentPrograms() {
    return programs.get(env ? `${env.header.projection} ${env.header.layers}` : [...programs.keys()][0]);
  }

  /**
   * Draws the frame of time `t` seconds: the capture, the camera's view and the Omnimax
   * frame; returns the milliseconds each took (each waited for) and their sum.
   */
  gr.renderAt = (t) => {
    const p = currentPrograms();
    if (!p) throw new Error('Greene live is not ready');
    gr.t = t;
    const t0 = performance.now();
    captureAt(t, p);
    fence(true);
    const t1 = performance.now();
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    gl.viewport(0, 0, canvas.width, canvas.height);
    gl.clearColor(0, 0, 0, 0);
    gl.clearDepth(1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    viewAt(t, p);
    fence(false);
    const t2 = performance.now();
    omniAt(p.omni, [VIEW.width, 0]);
    fence(false);
    const t3 = performance.now();
    gr.last = { t, captureMs: t1 - t0, viewMs: t2 - t1, omniMs: t3 - t2, totalMs: t3 - t0 };
    gr.times.push(gr.last);
    if (gr.times.length > 30) gr.times.shift();
    const mean = (k) => gr.times.reduce((a, f) => a + f[k], 0) / gr.times.length;
    document.getElementById('greene-t').textContent = t.toFixed(2);
    document.getElementById('greene-stats').textContent =
      `frame ${mean('totalMs').toFixed(1)} ms: capture (6 × ${capture.size}²) ${mean('captureMs').toFixed(1)} ms, ` +
      `view ${mean('viewMs').toFixed(1)} ms, Omnimax ${mean('omniMs').toFixed(1)} ms (mean of the last ${gr.times.length} frames)`;
    return gr.last;
  };

  function tick(now) {
    raf = 0;
    if (!gr.open || gr.paused) return;
    ensureEnv().catch(showError);
    try {
      gr.renderAt(clock.t0 + (now - clock.start) / 1000);
    } catch (e) {
      showError(e);
      return;
    }
    raf = requestAnimationFrame(tick);
  }

  function showError(e) {
    const p = document.getElementById('greene-error');
    if (!p) return;
    p.hidden = false;
    p.textContent = `Greene live: ${e.message || e}`;
  }

  gr.pause = () => {
    gr.paused = true;
    if (raf) cancelAnimationFrame(raf);
    raf = 0;
    const b = document.getElementById('greene-pause');
    if (b) b.textContent = 'play';
  };
  gr.play = () => {
    gr.paused = false;
    clock = { start: performance.now(), t0: gr.t };
    const b = document.getElementById('greene-pause');
    if (b) b.textContent = 'pause';
    if (gr.open && !raf) raf = requestAnimationFrame(tick);
  };

  /** Opens the panel; resolves once its first frame is drawn. */
  gr.show = () => {
    gr.open = true;
    writeUrl();
    panel.hidden = false;
    gr.ready = (async () => {
      try {
        build();
        await ensureEnv();
        if (!currentPrograms()) await programsFor({ projection: 'latlong', layers: 1 });
        gr.renderAt(gr.t);
        if (!gr.paused) gr.play();
      } catch (e) {
        showError(e);
        throw e;
      }
    })();
    return gr.ready;
  };
  gr.close = () => {
    gr.open = false;
    writeUrl();
    panel.hidden = true;
    if (raf) cancelAnimationFrame(raf);
    raf = 0;
  };
  /** The capture's edge (a new target from the next frame). */
  gr.setSize = (n) => {
    gr.size = n;
  };

  /** The capture's six faces as RGBA floats: face by face (+X … −Z), row t = 0 first. */
  gr.readCapture = () => {
    const c = captureTarget();
    const n = c.size;
    const out = new Float32Array(6 * n * n * 4);
    gl.bindFramebuffer(gl.FRAMEBUFFER, c.fb);
    for (let layer = 0; layer < 6; layer++) {
      gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_CUBE_MAP_POSITIVE_X + layer, c.cube, 0);
      gl.readPixels(0, 0, n, n, gl.RGBA, gl.FLOAT, out.subarray(layer * n * n * 4, (layer + 1) * n * n * 4));
    }
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    return { size: n, data: out };
  };

  /** The canvas's pixels in x0..x0+w, RGBA8, top row first. */
  function region(x0, w, h) {
    const raw = new Uint8Array(w * h * 4);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    gl.readPixels(x0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, raw);
    const out = new Uint8Array(w * h * 4);
    for (let y = 0; y < h; y++) out.set(raw.subarray((h - 1 - y) * w * 4, (h - y) * w * 4), y * w * 4);
    return { width: w, height: h, data: out };
  }
  /** The camera view's pixels of the last frame (RGBA8, top row first). */
  gr.viewPixels = () => region(0, VIEW.width, VIEW.height);
  /** The Omnimax view's pixels of the last frame (RGBA8, top row first; alpha 0 off the disk). */
  gr.omniPixels = () => region(VIEW.width, OMNI.width, OMNI.height);

  /** The Omnimax view's direction of each pixel (RGBA32F, top row first; alpha 1 in the disk). */
  gr.omniDirections = () => {
    const p = currentPrograms();
    if (!dirTarget) {
      const tex = gl.createTexture();
      gl.bindTexture(gl.TEXTURE_2D, tex);
      gl.texStorage2D(gl.TEXTURE_2D, 1, gl.RGBA32F, OMNI.width, OMNI.height);
      const fb = gl.createFramebuffer();
      gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
      gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, tex, 0);
      dirTarget = { tex, fb };
    }
    gl.bindFramebuffer(gl.FRAMEBUFFER, dirTarget.fb);
    gl.clearColor(0, 0, 0, 0);
    gl.clear(gl.COLOR_BUFFER_BIT);
    omniAt(p.omniDirs, [0, 0]);
    const [w, h] = [OMNI.width, OMNI.height];
    const raw = new Float32Array(w * h * 4);
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.FLOAT, raw);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    const out = new Float32Array(w * h * 4);
    for (let y = 0; y < h; y++) out.set(raw.subarray((h - 1 - y) * w * 4, (h - y) * w * 4), y * w * 4);
    return out;
  };

  button.addEventListener('click', () => (gr.open ? gr.close() : gr.show().catch(() => {})));
  gr.ready = studio.ready.then(() => (!studio.embed && params.get('greene') === '1' ? gr.show() : null));
  return gr;
}
