// What every browser test shares: a static server on 127.0.0.1 over this folder (so pages
// import node_modules/three/… and node_modules/@babylonjs/core/…) and a folder of files
// baked for the test, and headless Chromium (Debian's package) with WebGL2 on SwiftShader.
import { createServer } from 'node:http';
import { readFile, stat } from 'node:fs/promises';
import { execFileSync } from 'node:child_process';
import { mkdtempSync, rmSync, existsSync } from 'node:fs';
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
    args: ['--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist'],
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

/// Builds the bake crate's examples once (`cargo build -p mirrorball-bake --examples`).
let built = false;
function buildExamples() {
  if (built) return;
  execFileSync('cargo', ['build', '-q', '-p', 'mirrorball-bake', '--examples'], { cwd: ROOT, stdio: 'inherit' });
  built = true;
}

/// Writes the direction-coded lat-long EXR (colour = ½ + ½·d) to `file`.
export function directionCoded(file, width = 1024) {
  buildExamples();
  execFileSync(path.join(EXAMPLES, 'direction_coded'), [file, String(width)], { stdio: 'inherit' });
  return file;
}

/// Bakes `input` for `engine` into `dir` (level 0 `size`²); returns the files written.
export function bake(engine, input, dir, size = 64) {
  buildExamples();
  const out = execFileSync(path.join(EXAMPLES, 'bake'), [engine, input, dir, String(size)], { encoding: 'utf8' });
  return out.split('\n').filter(Boolean);
}

/// The library's own GGX prefilter of the lat-long `input` at perceptual `roughness`, about
/// each direction in `dirs` (the bake crate's example `prefiltered`): `[[r, g, b], …]`.
export function prefiltered(input, roughness, dirs) {
  buildExamples();
  const args = [input, String(roughness), ...dirs.map((d) => d.join(','))];
  return JSON.parse(execFileSync(path.join(EXAMPLES, 'prefiltered'), args, { encoding: 'utf8' }));
}
