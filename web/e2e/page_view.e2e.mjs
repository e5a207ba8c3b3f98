// The page as a class sees it projected (issue 38, item 9), in headless Chromium: readable scene
// titles with the identifier beside them, quasi-Monte Carlo scenes starting with their QMC
// estimators and drawing one randomization, an estimator list that cuts no entry (desktop and
// phone), the footer's words, the time plot's guide labels apart on a phone, identical curves
// told apart, a shared link that restores its view and runs, and Run one Tab away.
// Usage (make test-e2e): MCPLAY_SITE=SITE_DIR MCPLAY_NATIVE=NATIVE_MCPLAY MCPLAY_SHOTS=SHOT_DIR
// node --test web/e2e/page_view.e2e.mjs
import { mkdirSync } from 'node:fs';
import { join, resolve, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';
import { test, after, before } from 'node:test';
import assert from 'node:assert/strict';
import { openPlayground } from './harness.mjs';

const here = dirname(fileURLToPath(import.meta.url));
const site = resolve(process.env.MCPLAY_SITE ?? 'build/site');
const shots = resolve(process.env.MCPLAY_SHOTS ?? 'build/e2e');

let browser, url, context, page;

before(async () => {
  mkdirSync(shots, { recursive: true });
  browser = await openPlayground({ site, viewport: { width: 1280, height: 800 } });
  ({ url, context, page } = browser);
});

after(async () => {
  await browser?.close();
});

const done = (p = page) => p.waitForFunction(() => document.querySelector('#status')?.textContent.startsWith('done'), null, { timeout: 90000 });

async function open(p, query) {
  await p.goto(`${url}${query}`);
  await p.waitForFunction(() => window.mcplayDebug !== undefined);
  await p.evaluate(() => window.mcplayDebug.ready);
}

async function chooseScene(p, name) {
  await p.selectOption('#scene', name);
  await p.waitForFunction((n) => {
    const s = window.mcplayDebug.state();
    return s.sceneInfo?.name === n && !s.sceneInfo.provisional;
  }, name, { timeout: 20000 });
}

/** Every label of the estimator list against the list's visible box: [name, 'in' | 'out' | 'cut'],
 *  and whether the list scrolls. */
async function listEntries(p) {
  return p.evaluate(() => {
    const list = document.getElementById('estimator-list');
    const box = list.getBoundingClientRect();
    const entries = [...list.querySelectorAll('label')].map((l) => {
      const r = l.getBoundingClientRect();
      const where = r.top >= box.top - 0.5 && r.bottom <= box.bottom + 0.5 ? 'in'
        : r.bottom <= box.top + 0.5 || r.top >= box.bottom - 0.5 ? 'out' : 'cut';
      return [l.textContent.trim(), where];
    });
    return { entries, scrolls: list.scrollHeight > list.clientHeight + 1 };
  });
}

test('scene names: a readable title in the list, the identifier beside it for the CLI', async () => {
  await open(page, '?scene=stiff_peak_1e-8');
  const label = await page.$eval('#scene option[value="stiff_peak_1e-8"]', (o) => o.textContent);
  assert.equal(label, 'Stiff peak 1e-8 (1D)');
  const labels = await page.$$eval('#scene option', (os) => os.map((o) => o.textContent));
  assert.ok(labels.every((t) => !/_/.test(t) || /^custom|^your file/.test(t)), `identifiers in the list: ${labels.filter((t) => /_/.test(t))}`);
  const id = await page.textContent('#scene-id');
  assert.match(id, /identifier stiff_peak_1e-8/);
  assert.match(id, /mcplay run scenes\/stiff_peak_1e-8\.json/);
});

test('a quasi-Monte Carlo scene starts with its QMC estimators, and draws one randomization of K', async () => {
  await chooseScene(page, 'genz_gaussian_32d');
  const checked = await page.$$eval('#estimator-list input:checked', (bs) => bs.map((b) => b.dataset.estimator));
  for (const n of ['sobol', 'halton', 'lattice']) assert.ok(checked.includes(n), `${n} not selected: ${checked}`);
  await page.waitForFunction(() => window.mcplayDebug.state().samples.status === 'ready'
    && document.querySelector('.sample-card[data-estimator="sobol"]'), null, { timeout: 30000 });
  const card = page.locator('.sample-card[data-estimator="sobol"]');
  assert.equal(await card.getAttribute('data-randomizations'), '16');
  assert.equal(await card.getAttribute('data-shown'), '16');
  assert.equal(await card.getAttribute('data-points'), '16', 'one randomization drawn: 16 of the 256 points');
  const text = await card.textContent();
  assert.match(text, /16 of 256 points: one randomization of 16/);
  assert.match(text, /randomization 1 of 16: its 16 points \(the run of N = 256 averages 16 such sets\); grey: 4 × 4 cells, one point in each/);
  // 1024 points: 64 in the first randomization
  await page.selectOption('#samples-n', '1024');
  await page.waitForFunction(() => document.querySelector('.sample-card[data-estimator="sobol"]')?.dataset.shown === '64', null, { timeout: 30000 });
  // the square panels are drawn square and at least 240 CSS pixels wide on a desktop
  const size = await card.locator('.pair canvas').first().boundingBox();
  assert.ok(Math.abs(size.width - size.height) < 1.5 && size.width >= 240, `u panel ${size.width} x ${size.height}`);
  assert.match(await page.textContent('#samples-note'), /draws the first randomization only/);
  await card.screenshot({ path: join(shots, 'qmc_one_randomization.png') });
  await page.selectOption('#samples-n', '256');
});

for (const [name, viewport] of [['desktop', { width: 1280, height: 800 }], ['phone', { width: 390, height: 844 }]]) {
  test(`the estimator list cuts no entry (${name} ${viewport.width}x${viewport.height})`, async () => {
    const p = await context.newPage();
    try {
      await p.setViewportSize(viewport);
      // the integrals with the longest lists: their own estimators, then the presets offered
      for (const scene of ['exp_1d', 'mis_peak_and_plateau_1d', 'genz_gaussian_32d']) {
        await open(p, `?scene=${scene}`);
        const { entries, scrolls } = await listEntries(p);
        assert.ok(entries.length >= 8, `${scene}: ${entries.length} entries`);
        assert.deepEqual(entries.filter(([, w]) => w !== 'in'), [], `${scene}: entries not wholly shown`);
        assert.equal(scrolls, false, `${scene}: the list scrolls`);
      }
      await p.locator('fieldset.estimators').screenshot({ path: join(shots, `estimator_list_${name}.png`) });
    } finally {
      await p.close();
    }
  });
}

test('the footer names Web Workers, never a service worker', async () => {
  const footer = await page.textContent('footer');
  assert.doesNotMatch(footer, /service worker/i);
  assert.match(footer, /Web Worker/);
});

test('identical curves: a density equal to another is dashed over it and named in the legend', async () => {
  await open(page, '?scene=exp_1d&n_max=1024&reps=8');
  await page.waitForFunction(() => document.querySelector('#plot-overlay')?.dataset.drawn === 'true', null, { timeout: 30000 });
  // uniform and stratified both sample p = 1; importance and stratified_importance share their p
  const same = await page.$$eval('#legend-overlay li[data-same]', (lis) => lis.map((li) => [li.dataset.overlay, li.dataset.same, li.textContent]));
  const byName = Object.fromEntries(same.map(([n, of, t]) => [n, [of, t]]));
  assert.equal(byName.stratified?.[0], 'uniform', JSON.stringify(same));
  assert.match(byName.stratified[1], /same density as uniform \(dashed over it\)/);
  assert.equal(byName.stratified_importance?.[0], 'importance', JSON.stringify(same));
  assert.equal(await page.$('#legend-overlay li[data-overlay="uniform"][data-same]'), null, 'the first of a group is not marked');
  await page.locator('#overlay-title >> xpath=../..').screenshot({ path: join(shots, 'overlay_identical.png') });
});

test('a phone: the time plot\'s guide labels t^-1/2 and t^-1 do not overlap', async () => {
  const p = await context.newPage();
  try {
    await p.setViewportSize({ width: 390, height: 844 });
    for (const scene of ['exp_1d', 'gaussian_peak_1d']) {
      await open(p, `?scene=${scene}&n_max=4096&reps=8`);
      await p.click('#run');
      await done(p);
      await p.waitForFunction(() => window.mcplayDebug.guideLabels().length === 2, null, { timeout: 10000 });
      const labels = await p.evaluate(() => window.mcplayDebug.guideLabels());
      const [a, b] = labels;
      assert.ok(Math.abs(a.y - b.y) >= a.height, `${scene}: ${JSON.stringify(labels)}`);
      console.log(`# ${scene}: guide labels at ${labels.map((l) => `${l.label} y=${l.y.toFixed(1)} (wanted ${l.wanted.toFixed(1)})`).join(', ')}`);
    }
    await p.locator('#time-title >> xpath=../..').screenshot({ path: join(shots, 'phone_time_guides.png') });
  } finally {
    await p.close();
  }
});

test('a shared link carries the view, and opens with its study run and its view restored', async () => {
  await open(page, '?scene=exp_1d&estimators=uniform,stratified,importance&n_min=16&n_max=1024&reps=8&seed=3');
  await page.click('#run');
  await done();
  await page.locator('#legend-variance li[data-series="stratified"]').click();
  await page.selectOption('#calibration-level', '256');
  await page.selectOption('#samples-n', '64');
  await page.fill('#race-runs', '12');
  await page.fill('#race-rel', '1e-4');
  const link = await page.evaluate(() => window.mcplayDebug.shareUrl());
  assert.match(link, /[?&]hide=stratified(&|$)/);
  assert.match(link, /[?&]cal=256(&|$)/);
  assert.match(link, /[?&]points=64(&|$)/);
  assert.match(link, /[?&]race_runs=12(&|$)/);
  assert.match(link, /[?&]race_rel=1e-4(&|$)/);
  assert.match(link, /[?&]run=1$/);
  // Copy link gives the same (or says it, where the clipboard is refused)
  await context.grantPermissions(['clipboard-read', 'clipboard-write'], { origin: url.replace(/\/$/, '') }).catch(() => {});
  await page.click('#copy-link');
  await page.waitForFunction(() => /link/.test(document.querySelector('#notice').textContent));
  const copied = await page.evaluate(async () => {
    const n = document.querySelector('#notice').textContent;
    if (n.startsWith('link: ')) return n.slice(6);
    return navigator.clipboard.readText();
  });
  assert.equal(copied, link);

  const p = await context.newPage();
  try {
    await p.goto(link);
    await p.waitForFunction(() => window.mcplayDebug !== undefined);
    await p.evaluate(() => window.mcplayDebug.ready);
    await done(p);
    const s = await p.evaluate(() => window.mcplayDebug.state());
    assert.equal(s.scene, 'exp_1d');
    assert.deepEqual(s.selected, ['uniform', 'stratified', 'importance']);
    assert.deepEqual([s.params.n_max, s.params.reps, s.params.seed], [1024, 8, 3]);
    assert.equal(s.run.status, 'done');
    assert.deepEqual(await p.evaluate(() => window.mcplayDebug.hidden()), ['stratified']);
    assert.match(await p.getAttribute('#legend-variance li[data-series="stratified"]', 'class'), /off/);
    assert.equal(await p.inputValue('#calibration-level'), '256');
    assert.equal(await p.inputValue('#samples-n'), '64');
    assert.equal(await p.inputValue('#race-runs'), '12');
    assert.equal(await p.inputValue('#race-rel'), '1e-4');
    assert.ok(await p.$('#plot-variance canvas'), 'the variance plot is drawn');
    assert.ok(await p.$('#plot-calibration canvas'), 'the z histogram is drawn');
    assert.match(await p.textContent('#notice'), /Running this link's study/);
    await p.screenshot({ path: join(shots, 'shared_link_opened.png') });
  } finally {
    await p.close();
  }
});

test('the keyboard: one Tab from page load reaches the link to Run, Enter moves to Run, Enter runs', async () => {
  // the bare address (a link with a scene focuses Run by itself)
  await open(page, '');
  assert.notEqual(await page.evaluate(() => document.activeElement?.id), 'run');
  let tabs = 0;
  while (tabs < 40) {
    await page.keyboard.press('Tab');
    tabs += 1;
    const id = await page.evaluate(() => document.activeElement?.id);
    if (id === 'run' || id === 'skip-to-run') break;
  }
  const at = await page.evaluate(() => document.activeElement?.id);
  console.log(`# ${tabs} Tab press(es) from page load to ${at}`);
  assert.ok(tabs <= 5, `${tabs} Tab presses`);
  assert.ok(await page.isVisible('#skip-to-run'), 'the skip link shows when focused');
  await page.screenshot({ path: join(shots, 'skip_link.png') });
  if (at === 'skip-to-run') await page.keyboard.press('Enter');
  assert.equal(await page.evaluate(() => document.activeElement?.id), 'run');
  await page.keyboard.press('Enter');
  await done();
});

test('accessibility: axe-core finds no serious or critical WCAG 2 A/AA violation (QMC cards, link, titles)', async () => {
  await open(page, '?scene=genz_gaussian_32d&n_max=1024&reps=8');
  await page.click('#run');
  await done();
  await page.waitForFunction(() => document.querySelector('.sample-card[data-estimator="sobol"]'), null, { timeout: 30000 });
  await page.keyboard.press('Tab'); // the skip link shown
  await page.addScriptTag({ path: join(here, '..', 'node_modules', 'axe-core', 'axe.min.js') });
  const result = await page.evaluate(() => window.axe.run(document, { runOnly: { type: 'tag', values: ['wcag2a', 'wcag2aa'] } }));
  const serious = result.violations.filter((v) => v.impact === 'serious' || v.impact === 'critical');
  assert.deepEqual(serious.map((v) => `${v.id}: ${v.help} (${v.nodes.map((n) => n.target.join(' ')).slice(0, 3).join('; ')})`), []);
  console.log(`# axe: ${result.passes.length} rules passed, ${result.violations.length} minor or moderate violations`);
});
