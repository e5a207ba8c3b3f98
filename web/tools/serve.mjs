#!/usr/bin/env node
// A tiny static server for the built playground (node:http only, no dependencies):
//   PORT=8000 node web/tools/serve.mjs [DIR]          (DIR: the built site, default build/site)
// Serves DIR on 127.0.0.1 with the MIME types the page needs (.wasm as application/wasm, so
// the browser compiles it while it streams) and cross-origin isolation headers (finer timers),
// never a file outside DIR. MCPLAY_NO_ISOLATION=1 leaves out COOP/COEP/CORP: the page is then
// served as a plain static host (GitHub Pages) serves it, with the browser's coarse clock.
import http from 'node:http';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

// DIR from the current directory; by default the repository's build/site.
const REPO = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..', '..');
const ROOT = process.argv[2] ? path.resolve(process.argv[2]) : path.join(REPO, 'build', 'site');
const PORT = Number(process.env.PORT || 8000);
const HOST = '127.0.0.1';
const ISOLATION = !['1', 'true', 'yes'].includes(String(process.env.MCPLAY_NO_ISOLATION || '').toLowerCase());

const MIME = {
  '.html': 'text/html; charset=utf-8',
  '.js': 'text/javascript; charset=utf-8',
  '.mjs': 'text/javascript; charset=utf-8',
  '.css': 'text/css; charset=utf-8',
  '.json': 'application/json; charset=utf-8',
  '.wasm': 'application/wasm',
  '.png': 'image/png',
  '.svg': 'image/svg+xml',
  '.ico': 'image/x-icon',
  '.txt': 'text/plain; charset=utf-8',
  '.csv': 'text/csv; charset=utf-8',
};

if (!fs.existsSync(path.join(ROOT, 'index.html'))) {
  console.error(`serve: ${ROOT} has no index.html (build the site first: node web/tools/build-site.mjs)`);
  process.exit(1);
}
if (!Number.isInteger(PORT) || PORT < 0 || PORT > 65535) {
  console.error(`serve: PORT must be a port number, got ${process.env.PORT}`);
  process.exit(1);
}

function send(res, status, text) {
  res.writeHead(status, { 'Content-Type': 'text/plain; charset=utf-8', 'Content-Length': Buffer.byteLength(text) });
  res.end(text);
}

// The file a URL path names inside ROOT, or null (outside ROOT, NUL bytes, bad escapes).
function resolve(urlPath) {
  let rel;
  try {
    rel = decodeURIComponent(urlPath.split('?')[0].split('#')[0]);
  } catch {
    return null;
  }
  if (rel.includes('\0')) return null;
  const file = path.resolve(ROOT, `.${path.posix.normalize(`/${rel}`)}`);
  if (file !== ROOT && !file.startsWith(ROOT + path.sep)) return null;
  return file;
}

const server = http.createServer((req, res) => {
  if (req.method !== 'GET' && req.method !== 'HEAD') {
    res.setHeader('Allow', 'GET, HEAD');
    send(res, 405, 'method not allowed\n');
    return;
  }
  let file = resolve(req.url || '/');
  if (!file) {
    send(res, 403, 'forbidden\n');
    return;
  }
  fs.stat(file, (err, st) => {
    if (!err && st.isDirectory()) {
      file = path.join(file, 'index.html');
      st = fs.existsSync(file) ? fs.statSync(file) : null;
    }
    // Symbolic links must not lead out of ROOT either.
    let real = null;
    try {
      real = st && st.isFile() ? fs.realpathSync(file) : null;
    } catch {
      real = null;
    }
    const rootReal = fs.realpathSync(ROOT);
    if (err || !real || (real !== rootReal && !real.startsWith(rootReal + path.sep))) {
      send(res, 404, 'not found\n');
      return;
    }
    res.writeHead(200, {
      'Content-Type': MIME[path.extname(file).toLowerCase()] || 'application/octet-stream',
      'Content-Length': st.size,
      'Cache-Control': 'no-cache',
      'X-Content-Type-Options': 'nosniff',
      // Cross-origin isolation: browsers then time with performance.now() at ~5 us instead of
      // 100 us, which the wasm core's per-estimate timings (time_mean_s) need at small N.
      ...(ISOLATION ? {
        'Cross-Origin-Opener-Policy': 'same-origin',
        'Cross-Origin-Embedder-Policy': 'require-corp',
        'Cross-Origin-Resource-Policy': 'same-origin',
      } : {}),
    });
    if (req.method === 'HEAD') {
      res.end();
      return;
    }
    fs.createReadStream(file).on('error', () => res.destroy()).pipe(res);
  });
});

server.on('error', (e) => {
  console.error(`serve: ${e.message}`);
  process.exit(1);
});
server.listen(PORT, HOST, () => {
  console.log(`mcplay playground: http://localhost:${server.address().port}/${ISOLATION ? '' : ' (not cross-origin isolated: MCPLAY_NO_ISOLATION)'}`);
});
