// Benchmark (not a test): the live view of a render scene in headless Chromium, 2 workers, the
// scene's default estimators (live/model.js defaultEstimators) at the default size. For each of
// three page loads (the page opened with ?scene=SCENE&live_workers=2, Start pressed as soon as
// the live view shows), the time from pressing Start to the first full image drawn (every band of one
// estimator at 1 spp, on its canvas) and to 64 spp of every estimator (drawn); prints the
// medians as one line per scene:
//   SCENE: first image WxH at T ms; 64 spp at T ms (rendering T ms of it: ...)
// where rendering is the passes' own seconds summed over the images and divided by the workers:
// the wall the view would take if the workers did nothing but render, all of them busy.
// A scene predicted to take long is paused by the page after its first passes: the bench
// presses Resume at once (the line then says "(paused: predicted N s)").
// Usage: node web/e2e/live_view.bench.mjs SITE_DIR SCENE|all [loads=3] [workers=2]
import { readFileSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { openPlayground } from './harness.mjs';

const site = resolve(process.argv[2] ?? 'build/site');
const which = process.argv[3] ?? 'veach_mis';
const loads = Number(process.argv[4] ?? 3);
const workers = Number(process.argv[5] ?? 2);
const manifest = JSON.parse(readFileSync(join(site, 'scenes', 'manifest.json'), 'utf8'));
const renders = manifest.filter((m) => m.kind === 'render').map((m) => m.name);
const scenes = which === 'all' ? renders : [which];
if (!scenes.every((s) => renders.includes(s))) {
  console.error(`live_view.bench: '${which}' is not a render scene of ${site} (${renders.join(', ')})`);
  process.exit(2);
}

const median = (xs) => [...xs].sort((a, b) => a - b)[Math.floor(xs.length / 2)];
const browser = await openPlayground({ site, viewport: { width: 1300, height: 1000 }, profilePrefix: 'mcplay-live-bench-' });
const { page, url } = browser;
try {
  for (const scene of scenes) {
    const first = [];
    const full = [];
    const work = [];
    let size = null;
    let paused = null;
    for (let r = 0; r < loads; ++r) {
      await page.goto(`${url}?scene=${encodeURIComponent(scene)}&live_workers=${workers}`);
      await page.waitForFunction(() => window.mcplayDebug !== undefined);
      await page.evaluate(() => window.mcplayDebug.ready);
      await page.waitForSelector('#live-section', { state: 'visible' });
      // measured inside the page: Start pressed, then the animation frames after the images were drawn
      const t = await page.evaluate(() => new Promise((done, fail) => {
        const t0 = performance.now();
        document.getElementById('live-start').click();
        let firstMs = null;
        let pausedFor = null;
        const poll = () => {
          const v = window.mcplayDebug.live();
          if (v.status === 'error') {
            fail(new Error(v.message));
            return;
          }
          if (v.status === 'paused') {
            pausedFor = v.notice;
            document.getElementById('live-pause').click(); // Resume
          }
          const drawn = [...document.querySelectorAll('#live-images canvas.live-canvas')].filter((c) => c.dataset.live !== 'reference' && c.dataset.spp);
          if (firstMs === null && drawn.length) firstMs = performance.now() - t0;
          if (v.order.length && v.order.every((n) => v.estimators[n].spp >= 64)
              && drawn.length === v.order.length && drawn.every((c) => Number(c.dataset.spp) >= 64)) {
            // the passes' own seconds over the workers: the wall a view would take with
            // nothing but rendering, every worker busy
            const work = v.order.reduce((a, n) => a + v.estimators[n].seconds, 0) * 1000;
            done({ first: firstMs, full: performance.now() - t0, work, size: v.size, paused: pausedFor });
            return;
          }
          requestAnimationFrame(poll);
        };
        requestAnimationFrame(poll);
      }));
      first.push(t.first);
      full.push(t.full);
      work.push(t.work);
      size = t.size;
      paused = paused || t.paused;
      await page.click('#live-cancel').catch(() => {});
    }
    const predicted = paused ? /64 spp will take about (.+?)\. /.exec(paused) : null;
    console.log(`${scene}: first image ${size.width}x${size.height} at ${median(first).toFixed(0)} ms; 64 spp at ${median(full).toFixed(0)} ms` +
      ` (rendering ${median(work).toFixed(0)} ms of it: the passes' seconds over the workers)` +
      (paused ? ` (paused: predicted ${predicted ? predicted[1] : 'long'})` : ''));
  }
} finally {
  await browser.close();
}
