// Benchmark (not a test): time from pressing Run to the first plotted point, in headless
// Chromium, on one scene or on every scene of the site (the run is cancelled once the point is
// drawn). Render scenes use the reference the site ships (the page renders none).
// Usage: node web/e2e/first_plot.bench.mjs SITE_DIR [scene|all] [runs]
import { spawn } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

const here = dirname(fileURLToPath(import.meta.url));
const site = resolve(process.argv[2] ?? 'build/site');
const which = process.argv[3] ?? 'exp_1d';
const manifest = JSON.parse(readFileSync(join(site, 'scenes', 'manifest.json'), 'utf8'));
const scenes = which === 'all' ? manifest.map((m) => m.name) : [which];
const kindOf = Object.fromEntries(manifest.map((m) => [m.name, m.kind]));
const runs = Number(process.argv[4] ?? 5);
const port = 20000 + Math.floor(Math.random() * 20000);
const url = `http://127.0.0.1:${port}/`;

const server = spawn(process.execPath, [join(here, '..', 'tools', 'serve.mjs'), site], {
  env: { ...process.env, PORT: String(port) }, stdio: 'ignore' });
const profile = mkdtempSync(join(tmpdir(), 'mcplay-bench-'));
try {
  for (let i = 0; i < 100; ++i) {
    try { if ((await fetch(url)).ok) break; } catch { /* starting */ }
    await new Promise((r) => setTimeout(r, 100));
  }
  const context = await chromium.launchPersistentContext(profile, {
    executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium', headless: true,
    args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
      '--disable-background-networking', '--disable-component-update', '--disable-sync'] });
  const page = context.pages()[0] ?? (await context.newPage());
  const rows = [];
  for (const scene of scenes) {
    const times = [];
    for (let r = 0; r < runs; ++r) {
      await page.goto(`${url}?scene=${scene}`);
      await page.waitForFunction(() => window.mcplayDebug !== undefined);
      await page.evaluate(() => window.mcplayDebug.ready);
      await page.selectOption('#scene', scene);
      await page.waitForFunction(() => !document.querySelector('#run').disabled);
      // Measured inside the page: click, then the first animation frame after a level arrived.
      const ms = await page.evaluate(() => new Promise((done) => {
        const t0 = performance.now();
        document.querySelector('#run').click();
        const poll = () => {
          const s = window.mcplayDebug.state();
          const est = Array.isArray(s.estimators) ? s.estimators : Object.values(s.estimators ?? {});
          if (est.some((e) => (e.levels ?? []).length > 0)) {
            requestAnimationFrame(() => done(performance.now() - t0));
          } else {
            requestAnimationFrame(poll);
          }
        };
        poll();
      }));
      times.push(ms);
      // the run may end on its own meanwhile: click Cancel only while it is enabled
      await page.evaluate(() => { const b = document.querySelector('#cancel'); if (!b.disabled) b.click(); });
      await page.waitForFunction(() => /^(done|cancelled|error)/.test(document.querySelector('#status').textContent),
        null, { timeout: 120000 });
    }
    times.sort((a, b) => a - b);
    rows.push({ scene, kind: kindOf[scene], median: times[Math.floor(runs / 2)], min: times[0], max: times[runs - 1] });
    if (scenes.length === 1) {
      console.log(`first plot after Run (${scene}, ${runs} page loads): median ${times[Math.floor(runs / 2)].toFixed(0)} ms, ` +
        `min ${times[0].toFixed(0)} ms, max ${times[runs - 1].toFixed(0)} ms (target: under 1000 ms)`);
    }
  }
  if (scenes.length > 1) {
    console.log(`first plot after Run, ${runs} page loads per scene (ms; target: under 1000 ms)`);
    console.log(`${'scene'.padEnd(28)} ${'kind'.padEnd(9)} ${'median'.padStart(7)} ${'min'.padStart(7)} ${'max'.padStart(7)}`);
    for (const r of rows) {
      console.log(`${r.scene.padEnd(28)} ${r.kind.padEnd(9)} ${r.median.toFixed(0).padStart(7)} ${r.min.toFixed(0).padStart(7)} ${r.max.toFixed(0).padStart(7)}`);
    }
    const over = rows.filter((r) => r.median >= 1000).map((r) => r.scene);
    const all = rows.map((r) => r.median).sort((a, b) => a - b);
    console.log(`${rows.length} scenes: median of medians ${all[Math.floor(all.length / 2)].toFixed(0)} ms, largest ${all[all.length - 1].toFixed(0)} ms; ` +
      `over 1000 ms: ${over.length ? over.join(', ') : 'none'}`);
  }
  await context.close();
} finally {
  server.kill();
  rmSync(profile, { recursive: true, force: true });
}
