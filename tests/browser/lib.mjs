// What every browser test shares: a static server on 127.0.0.1 over this folder (so pages
// import node_modules/three/… and node_modules/@babylonjs/core/…) and a folder of files
// baked for the test, and headless Chromium (Debian's package) with WebGL2 on SwiftShader.
import { createServer } from 'node:http';
import { readFile, stat } from 'node:fs/promises';
import { execFileSync, spawn } from 'node:child_process';
import { createInterface } from 'node:readline';
import { inflateSync } from 'node:zlib';
import { mkdtempSync, rmSync, existsSync, readdirSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

export const HERE = path.dirname(fileURLToPath(import.meta.url));
export const ROOT = path.resolve(HERE, '..', '..');

const TYPES = {
  '.html': 'text/html', '.js': 'text/javascript', '.mjs': 'text/javascript',
  '.json': 'application/json', '.png': 'image/png', '.jpg': 'image/jpeg',
  '.ktx2': 'application/octet-stream', '.env': 'application/octet-stream',
  '.hdr': 'application/octet-stream', '.exr': 'application/octet-stream',
  '.gltf': 'model/gltf+json', '.bin': 'application/octet-stream', '.wasm': 'application/wasm',
};

/// Serves `/` from this folder and `/baked/` from `bakedDir`; resolves to its base URL.
export async function serve(bakedDir) {
  const server = createServer(async (req, res) => {
    const url = new URL(req.url, 'http://127.0.0.1');
    const rel = decodeURIComponent(url.pathname);
    const file = rel.startsWith('/baked/')
      ? path.join(bakedDir, rel.slice('/baked/'.length))
      : path.join(HERE, rel);
    const base = rel.startsWith('/baked/') ? bakedDir : HERE;
    if (!path.resolve(file).startsWith(path.resolve(base))) {
      res.writeHead(403).end();
      return;
    }
    try {
      if (!(await stat(file)).isFile()) throw new Error('not a file');
      res.writeHead(200, { 'content-type': TYPES[path.extname(file)] ?? 'application/octet-stream' });
      res.end(await readFile(file));
    } catch {
      res.writeHead(404).end();
    }
  });
  await new Promise((ok) => server.listen(0, '127.0.0.1', ok));
  return { server, url: `http://127.0.0.1:${server.address().port}` };
}

/// Headless Chromium with WebGL2 through SwiftShader.
export async function browser() {
  return chromium.launch({
    executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium',
    // --ignore-gpu-blocklist gives WebGL2 on SwiftShader, and with it Skia's accelerated 2D
    // canvas on SwiftShader too, which Chromium never picks for a software renderer itself:
    // there the studio's map panel (a 2D canvas) held the next WebGL read back 15-50 s a
    // frame. The 2D canvases stay in software, as on a machine without a GPU.
    args: ['--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist', '--disable-accelerated-2d-canvas'],
  });
}

/// The mirrorball binary the tests run: $MIRRORBALL, or the workspace's build.
export function mirrorball() {
  if (process.env.MIRRORBALL) return process.env.MIRRORBALL;
  for (const p of ['target/debug/mirrorball', 'target/release/mirrorball']) {
    const f = path.join(ROOT, p);
    if (existsSync(f)) return f;
  }
  throw new Error('no mirrorball binary: run `cargo build -p mirrorball-cli` (or set MIRRORBALL)');
}

/// A fresh temporary folder, removed by the returned function.
export function tempDir(prefix = 'mirrorball-browser-') {
  const dir = mkdtempSync(path.join(tmpdir(), prefix));
  return { dir, remove: () => rmSync(dir, { recursive: true, force: true }) };
}

/// Runs `mirrorball ARGS…`, failing the test with its standard error if it fails.
export function run(args) {
  try {
    return execFileSync(mirrorball(), args, { cwd: ROOT, encoding: 'utf8', stdio: ['ignore', 'pipe', 'pipe'] });
  } catch (e) {
    throw new Error(`mirrorball ${args.join(' ')} failed:\n${e.stderr ?? e}`);
  }
}

const EXAMPLES = path.join(ROOT, 'target', 'debug', 'examples');

/// Builds the workspace's examples once (the bake crate's are used here). The whole workspace
/// rather than `-p mirrorball-bake`: its dependencies then have the features `cargo test
/// --workspace` built them with, so after the README's test command (CI) nothing is
/// rebuilt; one crate alone would unify them otherwise and rebuild them (a minute in CI).
let built = false;
function buildExamples() {
  if (built) return;
  execFileSync('cargo', ['build', '-q', '--workspace', '--examples'], { cwd: ROOT, stdio: 'inherit' });
  built = true;
}

/// Writes the direction-coded lat-long EXR (colour = ½ + ½·d) to `file`.
export function directionCoded(file, width = 1024) {
  buildExamples();
  execFileSync(path.join(EXAMPLES, 'direction_coded'), [file, String(width)], { stdio: 'inherit' });
  return file;
}

/// Bakes `input` for `engine` into `dir` (level 0 `size`²) with `mirrorball bake`, as a
/// user runs it; returns every file then in `dir` (with its subfolders).
export function bake(engine, input, dir, size = 64) {
  run(['bake', input, '--for', engine, dir, '--size', String(size), '--quiet']);
  const walk = (d) => readdirSync(d, { withFileTypes: true })
    .flatMap((e) => (e.isDirectory() ? walk(path.join(d, e.name)) : [path.join(d, e.name)]));
  return walk(dir);
}

/// The library's own GGX prefilter of the lat-long `input` at perceptual `roughness`, about
/// each direction in `dirs` (the bake crate's example `prefiltered`): `[[r, g, b], …]`.
export function prefiltered(input, roughness, dirs) {
  buildExamples();
  const args = [input, String(roughness), ...dirs.map((d) => d.join(','))];
  return JSON.parse(execFileSync(path.join(EXAMPLES, 'prefiltered'), args, { encoding: 'utf8' }));
}

/// Decodes an 8-bit, non-interlaced PNG (greyscale, RGB or RGBA) from its bytes, exactly:
/// no colour management or premultiplication (a 2D canvas would premultiply RGBD's alpha).
/// Returns `{ width, height, channels, data }`, `data` the samples, top row first.
export function readPng(bytes) {
  const buf = Buffer.from(bytes);
  const SIG = [0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a];
  if (!SIG.every((b, i) => buf[i] === b)) throw new Error('not a PNG');
  let pos = 8, width = 0, height = 0, channels = 0;
  const idat = [];
  while (pos < buf.length) {
    const len = buf.readUInt32BE(pos);
    const type = buf.toString('latin1', pos + 4, pos + 8);
    const body = buf.subarray(pos + 8, pos + 8 + len);
    if (type === 'IHDR') {
      width = body.readUInt32BE(0);
      height = body.readUInt32BE(4);
      const [depth, colour, , , interlace] = body.subarray(8, 13);
      channels = { 0: 1, 2: 3, 6: 4 }[colour];
      if (depth !== 8 || !channels || interlace) throw new Error(`unsupported PNG (depth ${depth}, colour ${colour}, interlace ${interlace})`);
    } else if (type === 'IDAT') idat.push(body);
    else if (type === 'IEND') break;
    pos += 12 + len;
  }
  const raw = inflateSync(Buffer.concat(idat));
  const stride = width * channels;
  const data = new Uint8Array(height * stride);
  for (let y = 0; y < height; y++) {
    const filter = raw[y * (stride + 1)];
    const line = raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1));
    for (let x = 0; x < stride; x++) {
      const a = x >= channels ? data[y * stride + x - channels] : 0;
      const b = y > 0 ? data[(y - 1) * stride + x] : 0;
      const c = x >= channels && y > 0 ? data[(y - 1) * stride + x - channels] : 0;
      const p = a + b - c;
      const pa = Math.abs(p - a), pb = Math.abs(p - b), pc = Math.abs(p - c);
      const paeth = pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
      const pred = [0, a, b, (a + b) >> 1, paeth][filter];
      if (pred === undefined) throw new Error(`PNG filter ${filter}`);
      data[y * stride + x] = (line[x] + pred) & 0xff;
    }
  }
  return { width, height, channels, data };
}

/// Babylon.js's `fromRGBD` (helperFunctions.fx): `toLinearSpace(rgb) / D`, gamma 2.2.
export function rgbdDecode(r, g, b, d) {
  const k = d / 255;
  return [r, g, b].map((v) => (k ? Math.pow(v / 255, 2.2) / k : 0));
}

/// The unit view ray through pixel (px, py) (row 0 at the top) of a w×h picture from a
/// camera with vertical field of view `fov` (radians), +X right and +Y up on the screen,
/// looking along `forward`·Z (+1: a left-handed camera as Babylon's default, −1: OpenGL's).
export function viewRay(px, py, w, h, fov, forward) {
  const t = Math.tan(fov / 2);
  const x = ((2 * (px + 0.5)) / w - 1) * t * (w / h);
  const y = (1 - (2 * (py + 0.5)) / h) * t;
  const n = Math.hypot(x, y, 1);
  return [x / n, y / n, forward / n];
}

/// Where the ray from `origin` along unit `d` first meets the unit sphere at the origin (its
/// outward normal there), or null.
export function sphereHit(origin, d) {
  const b = origin[0] * d[0] + origin[1] * d[1] + origin[2] * d[2];
  const disc = b * b - (origin[0] ** 2 + origin[1] ** 2 + origin[2] ** 2 - 1);
  if (disc < 0) return null;
  const s = -b - Math.sqrt(disc);
  return [0, 1, 2].map((k) => origin[k] + s * d[k]);
}

/// `d` reflected about unit normal `n`.
export function reflect(d, n) {
  const k = 2 * (d[0] * n[0] + d[1] * n[1] + d[2] * n[2]);
  return [0, 1, 2].map((i) => d[i] - k * n[i]);
}

/// The right-way-round checks of a picture (`{ w, h, pixels }`, RGBA bytes, top row first,
/// linear) of a unit mirror sphere at the origin in front of a direction-coded background
/// (colour ½ + ½·d), seen from `eye` along `forward`·Z with vertical field of view `fov`:
/// per point (background left, right, up, down and two corners; the sphere's centre and
/// five points off it) what the picture shows and the colour of the direction seen there,
/// `toWorld` turning the scene's direction into the environment's.
export function mirrorChecks(r, { eye, forward, fov, toWorld }) {
  const points = [
    [0.06, 0.5, 'background left'], [0.94, 0.5, 'background right'],
    [0.5, 0.06, 'background up'], [0.5, 0.94, 'background down'],
    [0.1, 0.1, 'background up-left'], [0.9, 0.9, 'background down-right'],
    [0.5, 0.5, 'mirror centre'], [0.34, 0.5, 'mirror left'], [0.66, 0.5, 'mirror right'],
    [0.5, 0.34, 'mirror up'], [0.5, 0.66, 'mirror down'], [0.4, 0.6, 'mirror down-left'],
  ];
  return points.map(([fx, fy, what]) => {
    const [px, py] = [Math.floor(fx * r.w), Math.floor(fy * r.h)];
    const d = viewRay(px, py, r.w, r.h, fov, forward);
    const n = sphereHit(eye, d);
    if ((n !== null) !== what.startsWith('mirror')) throw new Error(`${what}: the ray ${n ? 'hits' : 'misses'} the sphere`);
    const seen = toWorld(n ? reflect(d, n) : d);
    const got = [0, 1, 2].map((k) => r.pixels[(py * r.w + px) * 4 + k] / 255);
    return { what, got, want: seen.map((c) => 0.5 + 0.5 * c) };
  });
}

/// Writes `dir/name`, a scene file of one mirror sphere (tessellation 12) over Venice
/// (bilinear, attached to the world), mode 3, 160×120, `extra` merged in; returns its path.
export function sphereScene(dir, name, extra = {}) {
  const file = path.join(dir, name);
  writeFileSync(
    file,
    JSON.stringify({
      meshes: [{ mesh: 'sphere', tessellation: 12 }],
      camera: { eye: [0, 0.4, 3.2], target: [0, 0, 0], fov: 40, width: 160, height: 120 },
      environment: { file: path.join(ROOT, 'assets', 'env', 'venice.exr'), projection: 'latlong', attach: 'world', filter: 'bilinear' },
      material: { kind: 'mirror' },
      indexing: 'pixel',
      background: true,
      ...extra,
    }),
  );
  return file;
}

/// Starts `mirrorball studio --no-open --port 0 FILES…` as a person starts it; resolves to
/// the URL it prints first, a stop and its standard error so far.
export async function studio(files = []) {
  const proc = spawn(mirrorball(), ['studio', '--no-open', '--port', '0', ...files], {
    cwd: ROOT,
    stdio: ['ignore', 'pipe', 'pipe'],
  });
  let stderr = '';
  proc.stderr.on('data', (d) => (stderr += d));
  const url = await new Promise((ok, fail) => {
    const lines = createInterface({ input: proc.stdout });
    lines.once('line', ok);
    proc.once('exit', (code) => fail(new Error(`studio exited (${code}): ${stderr}`)));
  });
  return { url, stop: () => proc.kill('SIGTERM'), stderr: () => stderr };
}

/// `POST /api/directions?projection=PROJECTION` to studio `s` (as [`studio`] starts it)
/// with `body` (a Float32Array of (u, v, layer) triples): the response, and its body as
/// f32 direction triples when it succeeded.
export async function directions(s, projection, body) {
  const url = new URL(s.url);
  url.pathname = '/api/directions';
  url.searchParams.set('projection', projection);
  const r = await fetch(url, { method: 'POST', body });
  const bytes = new Uint8Array(await r.arrayBuffer());
  return { status: r.status, text: () => new TextDecoder().decode(bytes), dirs: r.ok ? new Float32Array(bytes.buffer) : null };
}

/// A new page of `chromium` at the studio's `url`, once the page is ready; `logs` collects
/// its console messages and errors.
export async function openStudio(chromium, url) {
  const page = await chromium.newPage({ deviceScaleFactor: 1 });
  await carrying(page);
  const logs = [];
  page.on('console', (m) => logs.push(m.text()));
  page.on('pageerror', (e) => logs.push(String(e)));
  await page.goto(url);
  await page.waitForFunction(() => window.studio, null, { timeout: 60000 });
  await page.evaluate(() => window.studio.ready);
  return { page, logs };
}

/// Starts the studio with `files`, opens its page in `chromium` (the URL with `query`
/// added) and runs `body({ s, page, logs })`; a failure carries the page's console; the
/// page and the studio are closed after.
export async function onStudioPage(chromium, files, query, body) {
  const s = await studio(files);
  const { page, logs } = await openStudio(chromium, `${s.url}${query}`);
  try {
    await body({ s, page, logs });
  } catch (e) {
    throw new Error(`${e.stack}\n${logs.join('\n')}`);
  } finally {
    await page.close();
    s.stop();
  }
}

/// `window.carry(typed)` on every document `page` opens: a typed array's bytes as base64.
/// Playwright carries a plain array out of a page number by number (15 s for one 640×480
/// RGBA picture); a string crosses at once. [`carried`] turns it back into numbers.
export async function carrying(page) {
  await page.addInitScript(() => {
    window.carry = (a) => {
      const u = new Uint8Array(a.buffer, a.byteOffset, a.byteLength);
      let s = '';
      for (let i = 0; i < u.length; i += 0x8000) s += String.fromCharCode.apply(null, u.subarray(i, i + 0x8000));
      return btoa(s);
    };
  });
}

/// The typed array (`Type`, Uint8Array unless told) that `window.carry` made `b64` of.
export function carried(b64, Type = Uint8Array) {
  const bytes = new Uint8Array(Buffer.from(b64, 'base64'));
  return new Type(bytes.buffer, 0, bytes.length / Type.BYTES_PER_ELEMENT);
}

/// The studio viewport's pixels on `page` (opened by [`openStudio`] or made [`carrying`]):
/// `{ width, height, data }`, RGBA8, top row first.
export async function viewportPixels(page) {
  const p = await page.evaluate(() => {
    const p = window.studio.pixels();
    return { width: p.width, height: p.height, data: window.carry(p.data) };
  });
  return { ...p, data: carried(p.data) };
}

/// A studio viewport's RGBA8 pixels `gpu` against `mirrorball render`'s picture `full` of
/// the same scene, `cover` the same rendered with `--no-background` (its alpha: the
/// objects' coverage): over the covered pixels whose eight neighbours are covered too (the
/// silhouette's coverage is each rasteriser's own business) and over the background, how
/// many there are and how many are within 2/255 in every channel.
export function againstRender(gpu, full, cover) {
  const { width: w, height: h } = full;
  const covered = (x, y) => cover.data[4 * (y * w + x) + 3] > 0;
  let n = 0;
  let within = 0;
  let bg = 0;
  let bgWithin = 0;
  for (let y = 1; y < h - 1; y++) {
    for (let x = 1; x < w - 1; x++) {
      const i = y * w + x;
      const d = Math.max(...[0, 1, 2].map((c) => Math.abs(gpu[4 * i + c] - full.data[4 * i + c])));
      let inner = true;
      for (let dy = -1; dy <= 1; dy++) for (let dx = -1; dx <= 1; dx++) inner &&= covered(x + dx, y + dy);
      if (inner) {
        n++;
        if (d <= 2) within++;
      } else if (!covered(x, y)) {
        bg++;
        if (d <= 2) bgWithin++;
      }
    }
  }
  return { n, within, bg, bgWithin };
}
