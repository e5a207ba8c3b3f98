// The installed npm package in a browser with no bundler: a page and a module Worker import
// node_modules/mcplay/index.js and render.js by URL from a static server, so the package's
// non-Node path (the .wasm fetched from beside the module, new URL(..., import.meta.url)) runs
// in headless Chromium. `make test-npm` runs it in the folder the tarball was installed into:
//   cd <that folder> && MCPLAY_ROOT=<repository> node --test <repository>/npm/test/browser.test.mjs
// playwright-core comes from web/node_modules (make deps-web), Chromium from make deps
// (CHROMIUM overrides its path). A missing one fails the test, naming what to install.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import http from 'node:http';
import { createRequire } from 'node:module';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const HERE = path.dirname(fileURLToPath(import.meta.url));
const ROOT = path.resolve(process.env.MCPLAY_ROOT ?? path.join(HERE, '..', '..'));
const INSTALLED = process.cwd(); // holds node_modules/mcplay
const CHROMIUM = process.env.CHROMIUM ?? '/usr/bin/chromium';
const MIME = { '.html': 'text/html', '.js': 'text/javascript', '.mjs': 'text/javascript',
  '.json': 'application/json', '.gltf': 'model/gltf+json', '.wasm': 'application/wasm' };

// The page: a study in the page and the same study in a module Worker, and a render. Its title
// ends as "OK <json>" or "FAIL <message>".
const STUDY_ARGS = [{ f: 'x1^2 * x2 + 3 * x3' }, { n_min: 16, n_max: 64, reps: 4, seed: 7, estimators: ['uniform', 'sobol'] }];
const STUDY = STUDY_ARGS.map((a) => JSON.stringify(a)).join(', ');
const PAGE = `<!doctype html><meta charset="utf-8"><title>loading</title>
<script type="module">
import { load, McplayError } from './node_modules/mcplay/index.js';
import { load as loadRender } from './node_modules/mcplay/render.js';
try {
  const core = await load();
  const study = core.runStudy(${STUDY});
  let error = null;
  try { core.runStudy({ f: 'x1 +* 2' }); } catch (e) { error = e instanceof McplayError ? e.message : String(e); }
  const scene = await (await fetch('scenes/quad_light_floor.json')).json();
  scene.render.gltf = await (await fetch('scenes/' + scene.render.gltf)).json();
  const image = (await loadRender()).renderImage(scene,
    { estimator: 'light_area', spp: 1, width: 16, height: 12, outputs: ['png'] });
  const worker = new Worker('./worker.js', { type: 'module' });
  const inWorker = await new Promise((resolve, reject) => {
    worker.onmessage = (e) => resolve(e.data);
    worker.onerror = (e) => reject(new Error('worker: ' + e.message));
  });
  document.title = 'OK ' + JSON.stringify({ version: core.version(), study, inWorker, error, png: image.images.png });
} catch (e) {
  document.title = 'FAIL ' + (e && e.message);
}
</script>`;
const WORKER = `import { load } from './node_modules/mcplay/index.js';
const core = await load();
self.postMessage(core.runStudy(${STUDY}));
`;

// A static server on a loopback port: the page, the installed package, the repository's scenes.
function serve(files) {
  const server = http.createServer((req, res) => {
    const url = new URL(req.url, 'http://localhost');
    const rel = decodeURIComponent(url.pathname).replace(/^\/+/, '');
    let body = files[rel] ?? null;
    if (body === null && !rel.split('/').includes('..')) {
      const base = rel.startsWith('scenes/') ? ROOT : INSTALLED;
      const file = path.join(base, rel);
      if (fs.existsSync(file) && fs.statSync(file).isFile()) body = fs.readFileSync(file);
    }
    if (body === null) {
      res.writeHead(404).end();
      return;
    }
    res.writeHead(200, { 'content-type': MIME[path.extname(rel)] ?? 'application/octet-stream' }).end(body);
  });
  return new Promise((resolve) => server.listen(0, '127.0.0.1', () => resolve(server)));
}

function playwright() {
  const requireFromWeb = createRequire(path.join(ROOT, 'web', 'package.json'));
  try {
    return requireFromWeb('playwright-core');
  } catch {
    throw new Error('playwright-core not found in web/node_modules: run `make deps-web`');
  }
}

test('a page and a module Worker load the installed package by URL and run the core', async (t) => {
  assert.ok(fs.existsSync(path.join(INSTALLED, 'node_modules', 'mcplay', 'index.js')),
    `no node_modules/mcplay in ${INSTALLED}: run this where the tarball was installed`);
  assert.ok(fs.existsSync(CHROMIUM), `no Chromium at ${CHROMIUM}: run \`make deps\` or set CHROMIUM`);
  const { chromium } = playwright();
  const server = await serve({ 'index.html': PAGE, 'worker.js': WORKER });
  t.after(() => server.close());
  const profile = fs.mkdtempSync(path.join(os.tmpdir(), 'mcplay-npm-chromium-'));
  t.after(() => fs.rmSync(profile, { recursive: true, force: true }));
  const context = await chromium.launchPersistentContext(profile, {
    executablePath: CHROMIUM, headless: true,
    args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
      '--disable-background-networking', '--disable-component-update', '--disable-sync'],
  });
  t.after(() => context.close());
  const page = await context.newPage();
  const wasmRequests = [];
  page.on('request', (r) => { if (r.url().endsWith('.wasm')) wasmRequests.push(new URL(r.url()).pathname); });
  await page.goto(`http://127.0.0.1:${server.address().port}/index.html`);
  await page.waitForFunction(() => /^(OK|FAIL) /.test(document.title), null, { timeout: 60000 });
  const title = await page.title();
  assert.ok(title.startsWith('OK '), title);
  const got = JSON.parse(title.slice(3));
  const pkg = JSON.parse(fs.readFileSync(path.join(INSTALLED, 'node_modules', 'mcplay', 'package.json'), 'utf8'));
  assert.equal(got.version, pkg.version);
  // the wasm came from beside the modules, the integration module twice (page and worker)
  assert.deepEqual(wasmRequests.sort(), ['/node_modules/mcplay/mcplay_render_web.wasm',
    '/node_modules/mcplay/mcplay_web.wasm', '/node_modules/mcplay/mcplay_web.wasm']);
  // the same study in the page and in the worker: the same numbers
  assert.deepEqual(got.inWorker.estimators.map((e) => e.levels.map((l) => l.replicates)),
    got.study.estimators.map((e) => e.levels.map((l) => l.replicates)));
  assert.deepEqual(got.study.estimators.map((e) => e.levels.length), [3, 3]);
  // and the ones the package gives under Node
  const { load } = await import(path.join(INSTALLED, 'node_modules', 'mcplay', 'index.js'));
  const inNode = (await load()).runStudy(...STUDY_ARGS);
  assert.deepEqual(got.study.estimators.map((e) => e.levels.map((l) => l.replicates)),
    inNode.estimators.map((e) => e.levels.map((l) => l.replicates)));
  assert.match(got.error, /expression/);
  const png = Buffer.from(got.png, 'base64');
  assert.deepEqual([png.subarray(1, 4).toString('latin1'), png.readUInt32BE(16), png.readUInt32BE(20)], ['PNG', 16, 12]);
});
