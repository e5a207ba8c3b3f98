// Assembles the npm package "mcplay" and packs it:
//   node npm/tools/stage.mjs [--wasm-dir build-wasm] [--out build-wasm/npm-package] [--no-pack]
// The package is npm/'s own files (package.json "files"), web/core.js and web/render_core.js
// (shipped as they are: the page and the package run the same wrappers) and the four files of
// the wasm build (mcplay_web.mjs/.wasm, mcplay_render_web.mjs/.wasm). It is written to --out
// (emptied first), checked (every shipped module's imports resolve inside the package, the
// version is CMake's project version), then `npm pack` writes mcplay-<version>.tgz into
// --wasm-dir. What it did goes to stderr; stdout is the tarball's path alone.
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const NPM_DIR = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');
const ROOT = path.dirname(NPM_DIR);
const FROM_WEB = ['core.js', 'render_core.js'];
const FROM_WASM = ['mcplay_web.mjs', 'mcplay_web.wasm', 'mcplay_render_web.mjs', 'mcplay_render_web.wasm'];
// Fields of npm/package.json that concern working on the package, not using it.
const DEV_FIELDS = ['scripts', 'devDependencies'];

function fail(message) {
  console.error(`stage: ${message}`);
  process.exit(1);
}

function parseArgs(argv) {
  const args = { wasmDir: 'build-wasm', out: null, pack: true };
  for (let i = 0; i < argv.length; i++) {
    const a = argv[i];
    if (a === '--no-pack') args.pack = false;
    else if ((a === '--wasm-dir' || a === '--out') && i + 1 < argv.length) {
      args[a === '--out' ? 'out' : 'wasmDir'] = argv[++i];
    } else fail(`unknown argument ${a} (usage: stage.mjs [--wasm-dir DIR] [--out DIR] [--no-pack])`);
  }
  args.wasmDir = path.resolve(ROOT, args.wasmDir);
  args.out = path.resolve(ROOT, args.out ?? path.join(args.wasmDir, 'npm-package'));
  return args;
}

// The version of CMakeLists.txt's project(): the C API's mcp_version() returns it.
function cmakeVersion() {
  const text = fs.readFileSync(path.join(ROOT, 'CMakeLists.txt'), 'utf8');
  const m = /^project\(\s*mcplay\s+VERSION\s+([0-9.]+)/m.exec(text);
  if (!m) fail('no "project(mcplay VERSION x.y.z" line in CMakeLists.txt');
  return m[1];
}

// The module specifiers a shipped file imports (static and dynamic imports, re-exports), in
// its code: lines that are comments (usage examples) are left out.
function importsOf(source) {
  const text = source.split('\n').filter((line) => !/^\s*(\/\/|\/\*|\*)/.test(line)).join('\n');
  const specs = [];
  const re = /(?:^|[;\s])(?:import|export)\s[^'"]*?\sfrom\s*['"]([^'"]+)['"]|(?:^|[;\s])import\s*['"]([^'"]+)['"]|\bimport\(\s*['"]([^'"]+)['"]\s*\)/gm;
  for (const m of text.matchAll(re)) specs.push(m[1] ?? m[2] ?? m[3]);
  return specs;
}

// Every import of every shipped module is a relative path to a file the package ships (no
// package, no builtin: the modules run in pages and workers too, and the page's own imports
// stay outside web/core.js and web/render_core.js).
function checkImports(out, files) {
  const shipped = new Set(files);
  const problems = [];
  for (const file of files.filter((f) => /\.m?js$/.test(f))) {
    for (const spec of importsOf(fs.readFileSync(path.join(out, file), 'utf8'))) {
      if (!spec.startsWith('./') || !shipped.has(spec.slice(2))) {
        problems.push(`${file} imports ${spec}, which the package does not ship`);
      }
    }
  }
  if (problems.length) fail(`imports that break outside the repository:\n  ${problems.join('\n  ')}`);
}

const args = parseArgs(process.argv.slice(2));
const pkg = JSON.parse(fs.readFileSync(path.join(NPM_DIR, 'package.json'), 'utf8'));
if (pkg.version !== cmakeVersion()) {
  fail(`npm/package.json version ${pkg.version} differs from CMakeLists.txt's ${cmakeVersion()}`);
}
const sources = new Map();
for (const f of FROM_WEB) sources.set(f, path.join(ROOT, 'web', f));
for (const f of FROM_WASM) sources.set(f, path.join(args.wasmDir, f));
for (const f of pkg.files) if (!sources.has(f)) sources.set(f, path.join(NPM_DIR, f));
for (const f of sources.keys()) if (!pkg.files.includes(f)) fail(`${f} is missing from npm/package.json "files"`);
for (const [f, from] of sources) {
  if (!fs.existsSync(from)) {
    fail(`missing ${path.relative(ROOT, from)}${FROM_WASM.includes(f) ? ': run `make build-wasm`' : ''}`);
  }
}

fs.rmSync(args.out, { recursive: true, force: true });
fs.mkdirSync(args.out, { recursive: true });
for (const [f, from] of sources) {
  fs.copyFileSync(from, path.join(args.out, f));
  fs.chmodSync(path.join(args.out, f), 0o644); // the wasm linker leaves its output executable
}
const shippedPkg = Object.fromEntries(Object.entries(pkg).filter(([k]) => !DEV_FIELDS.includes(k)));
fs.writeFileSync(path.join(args.out, 'package.json'), `${JSON.stringify(shippedPkg, null, 2)}\n`);
checkImports(args.out, pkg.files);
console.error(`stage: ${path.relative(ROOT, args.out)}: ${sources.size + 1} files, version ${pkg.version}`);

if (args.pack) {
  const packed = JSON.parse(execFileSync('npm', ['pack', '--json', '--ignore-scripts', '--pack-destination',
    args.wasmDir], { cwd: args.out, encoding: 'utf8', stdio: ['ignore', 'pipe', 'inherit'] }));
  const { filename, files, size } = packed[0];
  const inTarball = files.map((f) => f.path).sort();
  const expected = [...sources.keys(), 'package.json'].sort();
  if (JSON.stringify(inTarball) !== JSON.stringify(expected)) {
    fail(`the tarball holds ${inTarball.join(', ')}; expected ${expected.join(', ')}`);
  }
  console.error(`stage: packed ${files.length} files, ${(size / 1024).toFixed(0)} KB`);
  console.log(path.join(args.wasmDir, filename));
}
