// End-to-end test of the sampler lab in headless Chromium (Debian's chromium, driven by
// playwright-core). Usage: MCPLAY_SITE=SITE_DIR MCPLAY_SHOTS=SHOT_DIR node --test web/e2e/lab.e2e.mjs
// Serves SITE_DIR on a loopback port, opens the lab from the page's tabs (it tests its first
// example at once, with its "what to look for"), tests the wrong polar disk warp (fails, says
// where the mass is wrong, residuals on a fixed scale) and the right one (passes, pale map, no
// bin list), opens a warp scene's study (it runs and is scrolled to), a named warp with a parameter (GGX, alpha 0.3),
// analyses Sobol' points (spectrum and measures) and a renderer's Sobol' pixel (64 spp),
// uploads a CSV with a value outside [0, 1) (the core's error line shown), draws discrepancy
// curves, checks the URL round trip and runs axe-core on the lab; saves screenshots.
import { mkdirSync } from 'node:fs';
import { join, resolve, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';
import { test, after, before } from 'node:test';
import assert from 'node:assert/strict';
import { openPlayground } from './harness.mjs';

const here = dirname(fileURLToPath(import.meta.url));
const site = resolve(process.env.MCPLAY_SITE ?? 'build/site');
const shots = resolve(process.env.MCPLAY_SHOTS ?? 'build/e2e');

let browser, page;
const pageErrors = [];

before(async () => {
  mkdirSync(shots, { recursive: true });
  browser = await openPlayground({ site, viewport: { width: 1300, height: 1000 },
    profilePrefix: 'mcplay-lab-chromium-', onPageError: (message) => pageErrors.push(message) });
  ({ page } = browser);
});

after(async () => {
  await browser?.close();
});

// The lab's state, read after two animation frames: the view draws a state on the next frame,
// so the page's text then shows (at least) the state read.
const lab = () => page.evaluate(() => new Promise((resolve) => {
  requestAnimationFrame(() => requestAnimationFrame(() => resolve(window.mcplayDebug.lab())));
}));

async function warpTest(g) {
  await page.selectOption('#warp-example', 'typed');
  await page.evaluate(() => { document.getElementById('warp-typed').open = true; });
  await page.selectOption('#warp-named', '');
  await page.selectOption('#warp-domain', 'disk');
  await page.fill('#warp-params', '"radius": 1');
  await page.fill('#warp-g1', g[0]);
  await page.fill('#warp-g2', g[1]);
  await page.fill('#warp-g3', '');
  await page.fill('#warp-p', '1/pi');
  await page.selectOption('#warp-samples', '100000');
  // seed 2: seed 1 is one of the 1% of seeds at which a level-0.01 test rejects the right disk
  // warp with the 12 x 12 bins of 1e5 samples (p = 6e-4)
  await page.fill('#warp-seed', '2');
  const before = (await lab()).warp;
  await page.click('#warp-run');
  await page.waitForFunction((was) => {
    const w = window.mcplayDebug.lab().warp;
    return (w.status === 'done' || w.status === 'error') && w.result !== was;
  }, before.result, { timeout: 60000 });
  return (await lab()).warp;
}

test('the lab opens from the page\'s tabs, by keyboard too, and puts itself in the URL', async () => {
  assert.equal(await page.isVisible('#lab-view'), false);
  await page.focus('#tab-study');
  await page.keyboard.press('ArrowRight');
  await page.waitForSelector('#lab-view', { state: 'visible' });
  assert.equal(await page.getAttribute('#tab-lab', 'aria-selected'), 'true');
  assert.equal(await page.isVisible('#study-view'), false);
  await page.waitForFunction(() => window.location.search.startsWith('?view=lab&lab=warp'));
  // the site's warp scenes are the examples
  const examples = (await lab()).examples;
  assert.ok(examples.includes('warp_disk_polar_wrong'), examples.join(', '));
  await page.click('#tab-study');
  await page.waitForSelector('#study-view', { state: 'visible' });
  assert.doesNotMatch(new URL(page.url()).search, /view=lab/);
  await page.click('#tab-lab');
  await page.waitForSelector('#lab-view', { state: 'visible' });
});

// The residual map's pixels: the share whose every channel is above `pale` (|r| under about 2
// on the fixed scale), and the colour at a point (x, y in [0, 1] of the canvas, y down).
const residualPixels = (x, y) => page.$eval('#warp-residual', (c, [px, py]) => {
  const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
  let pale = 0;
  for (let i = 0; i < d.length; i += 4) if (Math.min(d[i], d[i + 1], d[i + 2]) > 190) pale++;
  const k = (Math.floor(py * (c.height - 1)) * c.width + Math.floor(px * (c.width - 1))) * 4;
  return { paleShare: pale / (d.length / 4), at: [d[k], d[k + 1], d[k + 2]] };
}, [x, y]);

test('the lab opens on a running example, with its "what to look for"; the verdict says where the mass is wrong', async () => {
  // opened by the first test: the first example (the wrong polar disk) is tested without a click
  await page.waitForFunction(() => window.mcplayDebug.lab().warp.status === 'done', null, { timeout: 60000 });
  const w = (await lab()).warp;
  assert.equal(w.example, 'warp_disk_polar_wrong');
  assert.equal(w.result.outcome, 'failed', w.result.verdict);
  assert.equal(await page.isVisible('#warp-look'), true);
  assert.match(await page.textContent('#warp-look'), /^What to look for: r = u₁ crowds the centre/);
  const verdict = await page.textContent('#warp-verdict');
  assert.match(verdict, /^Failed: .*too many samples near the centre \(.*in every direction/);
  assert.equal(w.result.where.startsWith('too many samples near the centre'), true, w.result.where);
  // a failed test lists the bins farthest from the density
  assert.equal(await page.isVisible('#warp-worst'), true);
  // the residual map on its fixed scale: the centre's column (left) full red
  assert.match(await page.textContent('#warp-residual-text'), /fixed scale: −5 and below \(full blue\).*\+5 and above \(full red\)/);
  assert.deepEqual((await residualPixels(0.01, 0.5)).at, [178, 24, 43]);
  await page.screenshot({ path: join(shots, 'lab-opens-on-example.png'), fullPage: true });
});

test('warp test: the wrong polar disk (r = u1) fails, the right one (r = sqrt(u1)) passes', async () => {
  const wrong = await warpTest(['u1*cos(2*pi*u2)', 'u1*sin(2*pi*u2)']);
  assert.equal(wrong.status, 'done', wrong.message);
  assert.equal(wrong.result.passed, false);
  assert.match(await page.textContent('#warp-verdict'), /^Failed/);
  assert.equal(await page.isVisible('#warp-maps'), true);
  assert.ok(await page.$$eval('#warp-worst tbody tr', (rows) => rows.length) > 0);
  const facts = await page.textContent('#warp-facts');
  for (const word of ['chi-square statistic', 'degrees of freedom', 'p-value', 'Šidák level']) assert.ok(facts.includes(word), word);
  await page.screenshot({ path: join(shots, 'lab-warp-wrong.png'), fullPage: true });
  const right = await warpTest(['sqrt(u1)*cos(2*pi*u2)', 'sqrt(u1)*sin(2*pi*u2)']);
  assert.equal(right.status, 'done', right.message);
  assert.equal(right.result.passed, true, right.result.verdict);
  assert.match(await page.textContent('#warp-verdict'), /^Passed/);
  assert.doesNotMatch(await page.textContent('#warp-verdict'), /too many|too few/);
  // a passed test lists no bins; its residual map is pale noise (|r| < 2 in ~95% of the bins)
  assert.equal(await page.isVisible('#warp-worst'), false);
  assert.equal(await page.isVisible('#warp-look'), false, 'a typed warp has no "what to look for"');
  const { paleShare } = await residualPixels(0.5, 0.5);
  assert.ok(paleShare > 0.85, `pale share ${paleShare}`);
  // the typed warp is in the link
  const q = new URLSearchParams(new URL(page.url()).search);
  assert.equal(q.get('warp'), 'typed');
  assert.equal(q.get('g1'), 'sqrt(u1)*cos(2*pi*u2)');
});

test('a named warp with parameters: GGX visible normals with alpha 0.3 passes; an alpha out of range gets the core\'s line', async () => {
  await page.selectOption('#warp-example', 'typed');
  await page.evaluate(() => { document.getElementById('warp-typed').open = true; });
  await page.selectOption('#warp-named', 'ggx_visible_normals');
  // the chosen name's fields, labelled, the docs' defaults as placeholders
  await page.waitForSelector('#warp-np-alpha', { state: 'visible' });
  assert.equal(await page.getAttribute('#warp-np-wo', 'placeholder'), '[0.6, 0, 0.8]');
  assert.match(await page.textContent('label[for=warp-np-alpha]'), /alpha/);
  assert.equal(await page.isDisabled('#warp-g1'), true);
  await page.selectOption('#warp-samples', '100000');
  const run = async () => {
    const before = (await lab()).warp;
    // Enter in a field of the typed warp tests it
    await page.focus('#warp-np-alpha');
    await page.keyboard.press('Enter');
    await page.waitForFunction((was) => {
      const w = window.mcplayDebug.lab().warp;
      return (w.status === 'done' || w.status === 'error') && (w.result !== was.result || w.message !== was.message);
    }, before, { timeout: 60000 });
    return (await lab()).warp;
  };
  await page.fill('#warp-np-alpha', '30');
  const bad = await run();
  assert.equal(bad.status, 'error');
  const line = 'scene.warp: ggx_visible_normals: alpha must be in [0.001, 10], got 30';
  assert.equal(bad.message, line);
  await page.waitForFunction(() => document.getElementById('warp-error').textContent !== '');
  assert.equal(await page.textContent('#warp-error'), line);
  await page.fill('#warp-np-alpha', '0.3');
  const ggx = await run();
  assert.equal(ggx.status, 'done', ggx.message);
  assert.equal(ggx.example, 'typed');
  assert.equal(ggx.result.passed, true, ggx.result.verdict);
  await page.waitForFunction(() => document.getElementById('warp-error').textContent === '');
  assert.match(await page.textContent('#warp-verdict'), /^Passed/);
  const q = new URLSearchParams(new URL(page.url()).search);
  assert.equal(q.get('named'), 'ggx_visible_normals');
  assert.equal(q.get('wp.alpha'), '0.3');
  await page.screenshot({ path: join(shots, 'lab-warp-ggx.png'), fullPage: true });
});

test('"Open its study" runs the warp scene\'s study and scrolls to it', async () => {
  await page.selectOption('#warp-example', 'warp_disk_polar');
  await page.waitForSelector('#warp-study', { state: 'visible' });
  // the example's own "what to look for"
  assert.match(await page.textContent('#warp-look'), /^What to look for: The fix, r = √u₁/);
  await page.click('#warp-study');
  await page.waitForSelector('#study-view', { state: 'visible' });
  await page.waitForFunction(() => window.mcplayDebug.state().sceneInfo?.name === 'warp_disk_polar', null, { timeout: 20000 });
  // it runs without a press of Run, and its first plot is brought into view
  await page.waitForFunction(() => ['running', 'done'].includes(window.mcplayDebug.state().run.status), null, { timeout: 20000 });
  const top = await page.$eval('#plot-variance', (e) => e.closest('figure').getBoundingClientRect().top);
  assert.ok(Math.abs(top) < 50, `the variance plot's figure at ${top} px from the top`);
  await page.waitForFunction(() => window.mcplayDebug.state().run.status !== 'running', null, { timeout: 120000 });
  assert.equal((await page.evaluate(() => window.mcplayDebug.state())).run.status, 'done');
  await page.click('#tab-lab');
  await page.waitForSelector('#lab-view', { state: 'visible' });
});

test('point sets: Sobol\' points analysed (spectrum drawn, discrepancies shown), and a link restores the inputs', async () => {
  await page.click('#lab-tab-points');
  await page.waitForSelector('#lab-points', { state: 'visible' });
  await page.check('input[name=points-source][value=sampler]');
  await page.selectOption('#points-sampler', 'sobol');
  await page.fill('#points-n', '1024');
  await page.fill('#points-dim', '2');
  await page.click('#points-run');
  await page.waitForFunction(() => ['done', 'error'].includes(window.mcplayDebug.lab().points.status), null, { timeout: 60000 });
  const p = (await lab()).points;
  assert.equal(p.status, 'done', p.message);
  assert.equal(p.analysis.n, 1024);
  assert.ok(p.analysis.l2_star_discrepancy < p.analysis.expected_iid.l2_star_discrepancy);
  assert.equal(p.rows, 1024);
  assert.equal(await page.getAttribute('#points-spectrum', 'data-drawn'), 'true');
  // the spectrum canvas holds an image (not blank)
  const lit = await page.$eval('#points-spectrum', (c) => {
    const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
    let n = 0;
    for (let i = 0; i < d.length; i += 4) if (d[i] > 0) n++;
    return n;
  });
  assert.ok(lit > 1000, `${lit} lit pixels`);
  const measures = await page.textContent('#points-measures');
  assert.match(measures, /L2-star discrepancy/);
  assert.match(measures, /wrap-around L2 discrepancy/);
  assert.match(await page.$eval('#points-measures tr[data-measure="l2_star_discrepancy"] td', (td) => td.textContent), /\d/);
  // discrepancy curves of several samplers
  await page.click('#curve-run');
  await page.waitForFunction(() => ['done', 'error'].includes(window.mcplayDebug.lab().curve.status), null, { timeout: 60000 });
  const c = (await lab()).curve;
  assert.equal(c.status, 'done', c.message);
  assert.ok(c.result.curves.length >= 2);
  assert.match(await page.textContent('#lab-points'), /up to log factors/);
  await page.screenshot({ path: join(shots, 'lab-points.png'), fullPage: true });
  // the link brings the same inputs back
  const link = page.url();
  await page.goto(link);
  await page.evaluate(() => window.mcplayDebug.ready);
  const back = await lab();
  assert.equal(back.view, 'lab');
  assert.equal(back.tab, 'points');
  assert.equal(await page.inputValue('#points-n'), '1024');
  assert.equal(await page.inputValue('#points-sampler'), 'sobol');
});

test('the renderer\'s pixel samplers: a Sobol\' pixel of 64 spp analysed (measures shown); 48 spp gets the core\'s line', async () => {
  await page.click('#lab-tab-points');
  await page.check('input[name=points-source][value=sampler]');
  await page.selectOption('#points-sampler', 'pixel_sobol');
  assert.equal(await page.isVisible('#points-pixel-note'), true);
  assert.equal(await page.isDisabled('#points-sets'), true);
  await page.fill('#points-dim', '2');
  const analyse = async (n) => {
    await page.fill('#points-n', n);
    const was = (await lab()).points;
    await page.click('#points-run');
    await page.waitForFunction((w) => {
      const p = window.mcplayDebug.lab().points;
      return (p.status === 'done' || p.status === 'error') && (p.analysis !== w.analysis || p.message !== w.message);
    }, was, { timeout: 60000 });
    return (await lab()).points;
  };
  const bad = await analyse('48');
  assert.equal(bad.status, 'error');
  const line = 'request.spp: the \'sobol\' pixel sampler needs a power-of-two spp, got 48 (the nearest are 32 and 64)';
  assert.equal(bad.message, line);
  await page.waitForFunction(() => document.getElementById('points-error').textContent !== '');
  assert.equal(await page.textContent('#points-error'), line);
  const p = await analyse('64');
  assert.equal(p.status, 'done', p.message);
  assert.equal(p.analysis.n, 64);
  assert.equal(p.analysis.dim, 2);
  assert.equal(p.rows, 64);
  assert.ok(p.analysis.l2_star_discrepancy > 0 && p.analysis.l2_star_discrepancy < p.analysis.expected_iid.l2_star_discrepancy,
    `a Sobol' pixel ${p.analysis.l2_star_discrepancy} against independent points ${p.analysis.expected_iid.l2_star_discrepancy}`);
  assert.match(await page.$eval('#points-measures tr[data-measure="l2_star_discrepancy"] td', (td) => td.textContent), /\d/);
  assert.match(await page.$eval('#points-measures tr[data-measure="min_distance"] td', (td) => td.textContent), /\d/);
  assert.equal(await page.isVisible('#points-measures'), true);
  await page.waitForFunction(() => document.getElementById('points-error').textContent === '');
  assert.match(new URL(page.url()).search, /sampler=pixel_sobol&n=64/);
  await page.screenshot({ path: join(shots, 'lab-points-pixel-sobol.png'), fullPage: true });
});

test('a CSV with a value outside [0, 1) shows the core\'s error line as it is', async () => {
  const csv = ['x,y', ...Array.from({ length: 10 }, (_, i) => `${(i + 0.5) / 10},0.5`), '0.3,1.2', '0.1,0.1'].join('\n');
  await page.setInputFiles('#points-file', { name: 'bad.csv', mimeType: 'text/csv', buffer: Buffer.from(csv) });
  await page.waitForFunction(() => window.mcplayDebug.lab().points.status === 'error', null, { timeout: 30000 });
  // The state changes at once, the view on the next frame: wait for the line to be drawn.
  await page.waitForFunction(() => document.getElementById('points-error').textContent !== '');
  const text = await page.textContent('#points-error');
  assert.equal(text, 'request.csv: row 12, column 2: \'1.2\' is outside [0, 1)');
  assert.equal(await page.isVisible('#points-error'), true);
  // a good file is analysed
  await page.setInputFiles('#points-file', { name: 'good.json', mimeType: 'application/json', buffer: Buffer.from('[[0.1,0.2],[0.6,0.7],[0.35,0.9]]') });
  await page.waitForFunction(() => window.mcplayDebug.lab().points.status === 'done', null, { timeout: 30000 });
  assert.equal((await lab()).points.analysis.n, 3);
  assert.equal(await page.textContent('#points-error'), '');
});

test('accessibility: axe-core finds no serious or critical WCAG 2 A/AA violation in the lab', async () => {
  await page.addScriptTag({ path: join(here, '..', 'node_modules', 'axe-core', 'axe.min.js') });
  for (const tab of ['#lab-tab-points', '#lab-tab-warp']) {
    await page.click(tab);
    const result = await page.evaluate(() => window.axe.run(document, { runOnly: { type: 'tag', values: ['wcag2a', 'wcag2aa'] } }));
    const serious = result.violations.filter((v) => v.impact === 'serious' || v.impact === 'critical');
    assert.deepEqual(serious.map((v) => `${v.id}: ${v.help} (${v.nodes.map((n) => n.target.join(' ')).slice(0, 3).join('; ')})`), [], tab);
    console.log(`# axe (${tab}): ${result.passes.length} rules passed, ${result.violations.length} minor or moderate violations`);
  }
  assert.deepEqual(pageErrors, []);
});
