// The page's text sizes and axis titles in headless Chromium (issue 48, item 6). Usage:
// MCPLAY_SITE=SITE_DIR MCPLAY_SHOTS=SHOT_DIR node --test web/e2e/layout.e2e.mjs
// At 1024 x 768 (a projector) the large-text toggle says what it does, is remembered, and with it
// no visible text of the study (a run, its tables and a race), the live view or the lab is below
// 16 px: every text node (by its element's computed font size), every SVG text (times its scale
// on screen) and every text drawn on a canvas (the font it was drawn with, times the canvas's
// scale on screen; fillText is recorded from the page's first script on). Without the mode the
// same measure finds small text (it can fail). At 390 x 844 (a phone), in either mode, no text
// drawn on a canvas, the axis titles included, reaches past its canvas (its bounding box from
// measureText and the transform it was drawn with), and no SVG text past its SVG.
import { mkdirSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { test, after, before } from 'node:test';
import assert from 'node:assert/strict';
import { openPlayground } from './harness.mjs';

const site = resolve(process.env.MCPLAY_SITE ?? 'build/site');
const shots = resolve(process.env.MCPLAY_SHOTS ?? 'build/e2e');
const MIN_PX = 16;

let browser, page;
const pageErrors = [];

// Runs in the page before its scripts: every canvas's texts since its last full clear.
function recordCanvasText() {
  const texts = new WeakMap();
  const canvases = new Set();
  const P = CanvasRenderingContext2D.prototype;
  const covers = (ctx, x, y, w, h) => {
    const t = ctx.getTransform();
    const c = ctx.canvas;
    return t.a * x + t.e <= 0 && t.d * y + t.f <= 0 && t.a * (x + w) + t.e >= c.width && t.d * (y + h) + t.f >= c.height;
  };
  for (const name of ['clearRect', 'fillRect']) {
    const orig = P[name];
    P[name] = function wrapped(x, y, w, h) {
      if (covers(this, x, y, w, h)) texts.set(this.canvas, []);
      return orig.call(this, x, y, w, h);
    };
  }
  const fillText = P.fillText;
  P.fillText = function wrapped(text, x, y, maxWidth) {
    const m = this.measureText(text);
    const t = this.getTransform();
    const right = maxWidth === undefined ? m.actualBoundingBoxRight : Math.min(m.actualBoundingBoxRight, maxWidth - m.actualBoundingBoxLeft);
    const local = [[x - m.actualBoundingBoxLeft, y - m.actualBoundingBoxAscent], [x + right, y - m.actualBoundingBoxAscent],
      [x - m.actualBoundingBoxLeft, y + m.actualBoundingBoxDescent], [x + right, y + m.actualBoundingBoxDescent]];
    const pts = local.map(([u, v]) => [t.a * u + t.c * v + t.e, t.b * u + t.d * v + t.f]);
    const px = Number((/(\d+(?:\.\d+)?)px/.exec(this.font) || [])[1]);
    const list = texts.get(this.canvas) || [];
    list.push({ text: String(text), px: px * Math.hypot(t.a, t.b), box: [Math.min(...pts.map((p) => p[0])), Math.min(...pts.map((p) => p[1])),
      Math.max(...pts.map((p) => p[0])), Math.max(...pts.map((p) => p[1]))] });
    texts.set(this.canvas, list);
    canvases.add(new WeakRef(this.canvas));
    return fillText.call(this, text, x, y, maxWidth);
  };
  window.canvasTexts = () => {
    const out = [];
    for (const ref of canvases) {
      const c = ref.deref();
      if (!c || !c.isConnected || !c.checkVisibility()) continue;
      const r = c.getBoundingClientRect();
      if (!(r.width > 0)) continue;
      const where = c.closest('[id]')?.id ?? c.tagName;
      for (const e of texts.get(c) || []) out.push({ ...e, where, css: (e.px * r.width) / c.width, w: c.width, h: c.height });
    }
    return out;
  };
}

/** Every visible text below `min` CSS px within `root`: DOM text (its element's font size), SVG
 *  text (times its scale on screen), form controls, canvas text (as drawn, scaled on screen). */
function smallTexts({ root, min }) {
  const out = [];
  const seen = new Set();
  const visible = (e) => e.checkVisibility({ checkVisibilityCSS: true }) && e.getClientRects().length &&
    e.getBoundingClientRect().width > 1 && e.getBoundingClientRect().height > 1;
  const name = (e) => `${e.tagName.toLowerCase()}${e.id ? `#${e.id}` : ''}${e.className && typeof e.className === 'string' ? `.${e.className.split(' ')[0]}` : ''}`;
  const scope = document.querySelector(root);
  const walker = document.createTreeWalker(scope, NodeFilter.SHOW_TEXT);
  for (let n = walker.nextNode(); n; n = walker.nextNode()) {
    const e = n.parentElement;
    if (!e || !n.textContent.trim() || seen.has(e) || e.closest('script, style, option, template')) continue;
    seen.add(e);
    if (!visible(e)) continue;
    let size = parseFloat(getComputedStyle(e).fontSize);
    if (e instanceof SVGElement) {
      const m = e.getScreenCTM();
      size *= m ? Math.hypot(m.a, m.b) : 1;
    }
    if (size < min - 0.01) out.push(`${name(e)} "${n.textContent.trim().slice(0, 40)}": ${size.toFixed(1)} px`);
  }
  for (const e of scope.querySelectorAll('input:not([type=checkbox]):not([type=radio]):not([type=range]), select, textarea')) {
    if (!visible(e)) continue;
    const size = parseFloat(getComputedStyle(e).fontSize);
    if (size < min - 0.01) out.push(`${name(e)} (a control): ${size.toFixed(1)} px`);
  }
  for (const t of window.canvasTexts()) {
    if (!scope.contains(document.getElementById(t.where)) && t.where !== scope.id) continue;
    if (t.css < min - 0.01) out.push(`canvas in #${t.where} "${t.text.slice(0, 40)}": ${t.css.toFixed(1)} px`);
  }
  return out;
}

/** Every canvas text reaching past its canvas, and every SVG text past its SVG (1 px slack). */
function clippedTexts() {
  const out = [];
  for (const t of window.canvasTexts()) {
    const [x0, y0, x1, y1] = t.box;
    if (x0 < -1 || y0 < -1 || x1 > t.w + 1 || y1 > t.h + 1) {
      out.push(`canvas in #${t.where} "${t.text.slice(0, 50)}": [${t.box.map((v) => Math.round(v)).join(', ')}] in ${t.w} x ${t.h}`);
    }
  }
  for (const e of document.querySelectorAll('svg text')) {
    if (!e.checkVisibility()) continue;
    const s = e.ownerSVGElement.getBoundingClientRect();
    const r = e.getBoundingClientRect();
    if (r.left < s.left - 1 || r.top < s.top - 1 || r.right > s.right + 1 || r.bottom > s.bottom + 1) {
      out.push(`svg text "${e.textContent.slice(0, 40)}"`);
    }
  }
  return out;
}

before(async () => {
  mkdirSync(shots, { recursive: true });
  browser = await openPlayground({ site, viewport: { width: 1024, height: 768 }, profilePrefix: 'mcplay-layout-chromium-',
    onPageError: (message) => pageErrors.push(message) });
  ({ page } = browser);
  // the recorder in place before the page's first script: added, then the page loaded again
  await browser.context.addInitScript(recordCanvasText);
  await reload();
});

async function reload() {
  await page.reload();
  await page.waitForFunction(() => window.mcplayDebug !== undefined);
  await page.evaluate(() => window.mcplayDebug.ready);
  assert.equal(await page.evaluate(() => typeof window.canvasTexts), 'function');
}

after(async () => {
  await browser?.close();
});

const frames = () => page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));

async function studyTab() {
  if (!(await page.isVisible('#study-view'))) await page.click('#tab-study');
  await page.waitForSelector('#study-view', { state: 'visible' });
}

async function runStudy() {
  await studyTab();
  await page.click('#run');
  await page.waitForFunction(() => document.querySelector('#status')?.textContent.startsWith('done'), null, { timeout: 120000 });
  // the race card too (its time axis is an SVG): a short race of the scene's estimators
  if (await page.isVisible('#race-start')) {
    await page.fill('#race-rel', '1e-2');
    await page.fill('#race-abs', '');
    await page.fill('#race-runs', '4');
    await page.fill('#race-seconds', '5');
    await page.click('#race-start');
    await page.waitForFunction(() => ['done', 'error', 'cancelled'].includes(window.mcplayDebug.state().race.status), null, { timeout: 120000 });
  }
  // the tables of levels too
  await page.evaluate(() => document.querySelectorAll('#study-view details').forEach((d) => { d.open = true; }));
  await frames();
}

async function runLive() {
  await studyTab();
  await page.selectOption('#scene', 'veach_mis');
  await page.waitForSelector('#live-section', { state: 'visible' });
  await page.waitForFunction(() => document.querySelectorAll('#live-estimators input:checked').length > 0);
  await page.selectOption('#live-max', '64');
  await page.click('#live-start');
  // a loaded machine predicts a long wait after the first pass and pauses: go on
  const drawn = () => Number(document.getElementById('live-plot-spp').dataset.points) > 0;
  for (let i = 0; i < 4; ++i) {
    await page.waitForFunction(() => ['error', 'paused', 'done'].includes(window.mcplayDebug.live().status) ||
      Number(document.getElementById('live-plot-spp').dataset.points) > 0, null, { timeout: 120000 });
    if ((await page.evaluate(() => window.mcplayDebug.live().status)) !== 'paused' || (await page.evaluate(drawn))) break;
    await page.click('#live-pause');
  }
  assert.ok(await page.evaluate(drawn), await page.evaluate(() => JSON.stringify({ ...window.mcplayDebug.live(), canvases: null })));
  await page.click('#live-cancel');
  await frames();
}

async function runLab() {
  await page.click('#tab-lab');
  await page.waitForSelector('#lab-view', { state: 'visible' });
  await page.click('#lab-tab-warp');
  await page.waitForSelector('#warp-run', { state: 'visible' });
  await page.click('#warp-run');
  await page.waitForFunction(() => ['done', 'error'].includes(window.mcplayDebug.lab().warp.status), null, { timeout: 60000 });
  await frames();
}

async function runLabPoints() {
  await page.click('#lab-tab-points');
  await page.waitForSelector('#lab-points', { state: 'visible' });
  await page.click('#points-run');
  await page.waitForFunction(() => ['done', 'error'].includes(window.mcplayDebug.lab().points.status), null, { timeout: 60000 });
  await page.click('#curve-run');
  await page.waitForFunction(() => ['done', 'error'].includes(window.mcplayDebug.lab().curve.status), null, { timeout: 120000 });
  await frames();
}

test('the large-text toggle says what it gives, and is remembered', async () => {
  const label = await page.textContent('label[for="large-text"], label:has(#large-text)');
  assert.match(label, /16 px/);
  assert.equal(await page.isChecked('#large-text'), false);
  // the rule judged the other way: without the mode, the page has text below 16 px (so the
  // measure below can fail)
  assert.ok((await page.evaluate(smallTexts, { root: 'body', min: MIN_PX })).length > 0);
  await page.check('#large-text');
  assert.equal(await page.evaluate(() => document.documentElement.classList.contains('large-text')), true);
  await reload();
  assert.equal(await page.isChecked('#large-text'), true);
  assert.equal(await page.evaluate(() => document.documentElement.classList.contains('large-text')), true);
});

test('1024 x 768, large text: no visible text of the study below 16 px, canvas ticks included', async () => {
  await runStudy();
  const small = await page.evaluate(smallTexts, { root: 'body', min: MIN_PX });
  await page.screenshot({ path: join(shots, 'large-text-study.png'), fullPage: true });
  assert.deepEqual(small, []);
  // the plots drew their ticks and the race its axis: they were measured
  assert.ok((await page.evaluate(() => window.canvasTexts().filter((t) => t.where === 'plot-variance').length)) > 3);
  assert.ok((await page.$$('#race-card svg text')).length > 1);
});

test('1024 x 768, large text: the live view', async () => {
  await runLive();
  const small = await page.evaluate(smallTexts, { root: '#live-section', min: MIN_PX });
  await page.screenshot({ path: join(shots, 'large-text-live.png'), fullPage: true });
  assert.deepEqual(small, []);
  assert.ok((await page.evaluate(() => window.canvasTexts().filter((t) => t.where === 'live-plot-spp').length)) > 3);
});

test('1024 x 768, large text: the lab (warp test, point sets, curves)', async () => {
  await runLab();
  assert.deepEqual(await page.evaluate(smallTexts, { root: '#lab-view', min: MIN_PX }), []);
  await runLabPoints();
  await page.screenshot({ path: join(shots, 'large-text-lab.png'), fullPage: true });
  assert.deepEqual(await page.evaluate(smallTexts, { root: '#lab-view', min: MIN_PX }), []);
  await page.click('#tab-study');
  await page.waitForSelector('#study-view', { state: 'visible' });
});

for (const large of [true, false]) {
  test(`390 x 844 (a phone), ${large ? 'large' : 'normal'} text: no canvas or SVG text reaches past its canvas`, async () => {
    await page.setViewportSize({ width: 390, height: 844 });
    await page.setChecked('#large-text', large);
    await studyTab();
    await page.selectOption('#scene', 'exp_1d');
    await runStudy();
    const clipped = await page.evaluate(clippedTexts);
    await runLive();
    clipped.push(...(await page.evaluate(clippedTexts)));
    await runLab();
    clipped.push(...(await page.evaluate(clippedTexts)));
    await runLabPoints();
    clipped.push(...(await page.evaluate(clippedTexts)));
    await page.screenshot({ path: join(shots, `phone-${large ? 'large' : 'normal'}-lab.png`), fullPage: true });
    assert.deepEqual([...new Set(clipped)], []);
    await page.click('#tab-study');
    await page.waitForSelector('#study-view', { state: 'visible' });
  });
}

test('the page threw nothing', () => {
  assert.deepEqual(pageErrors, []);
});
