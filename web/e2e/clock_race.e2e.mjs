// The clock and the race card in headless Chromium (issue 38, items 6 and 8). Usage:
// MCPLAY_SITE=SITE_DIR MCPLAY_SHOTS=SHOT_DIR node --test web/e2e/clock_race.e2e.mjs
//  (i) the site served with cross-origin isolation (serve.mjs's default): the run worker's clock
//      is fine and no banner shows; exp_1d's race (uniform, stratified, latin_hypercube; relative
//      1e-3, 6 runs) names latin_hypercube's stop on its conservative error bar with its actual
//      error, and no row or verdict contradicts the data;
// (ii) the same site served as a plain static host serves it (MCPLAY_NO_ISOLATION=1): the banner
//      says the clock's 0.1 ms step, and neither the race verdict nor #time-verdict names a
//      winner whose times are under 20 clock steps; no "did not reach" for rows that met it.
// The checks recompute what the data allow from window.mcplayDebug.state() (the stopping
// result, the levels, the clock), independently of web/src/claims/.
import { mkdirSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { test, after } from 'node:test';
import assert from 'node:assert/strict';
import { openPlayground } from './harness.mjs';

const site = resolve(process.env.MCPLAY_SITE ?? 'build/site');
const shots = resolve(process.env.MCPLAY_SHOTS ?? 'build/e2e');
mkdirSync(shots, { recursive: true });

const STEPS = 20; // times under this many clock steps are not compared (the page's promise)
const RACE = ['uniform', 'stratified', 'latin_hypercube'];

const open = [];
after(async () => {
  for (const b of open) await b.close();
});

async function page(isolation) {
  const b = await openPlayground({ site, viewport: { width: 1400, height: 1000 }, isolation,
    profilePrefix: `mcplay-clock-${isolation ? 'iso' : 'plain'}-` });
  open.push(b);
  await b.page.waitForFunction(() => window.mcplayDebug.state().clock.step !== null
    || window.mcplayDebug.state().clock.isolated !== null, null, { timeout: 20000 });
  return b.page;
}

async function configure(p, scene, estimators, { nMin, nMax, reps, seed }) {
  if ((await p.evaluate(() => window.mcplayDebug.state().sceneInfo?.name)) !== scene) await p.selectOption('#scene', scene);
  await p.waitForFunction((name) => {
    const s = window.mcplayDebug.state();
    return s.sceneInfo?.name === name && !s.sceneInfo.provisional;
  }, scene, { timeout: 20000 });
  await p.waitForSelector(`input[data-estimator="${estimators[0]}"]`, { state: 'attached' });
  const names = await p.$$eval('input[type=checkbox][data-estimator]', (boxes) => boxes.map((b) => b.getAttribute('data-estimator')));
  for (const name of names) {
    const box = p.locator(`input[type=checkbox][data-estimator="${name}"]`);
    if ((await box.isChecked()) !== estimators.includes(name)) await box.click();
  }
  await p.fill('#n-min', String(nMin));
  await p.fill('#n-max', String(nMax));
  await p.fill('#reps', String(reps));
  await p.fill('#seed', String(seed));
}

async function race(p, shot) {
  await configure(p, 'exp_1d', RACE, { nMin: 16, nMax: 4096, reps: 8, seed: 1 });
  await p.fill('#race-rel', '1e-3');
  await p.fill('#race-abs', '');
  await p.fill('#race-runs', '6');
  await p.fill('#race-seconds', '5');
  await p.click('#race-start');
  await p.waitForFunction(() => window.mcplayDebug.state().race.status === 'done', null, { timeout: 240000 });
  await p.locator('#race-card').screenshot({ path: join(shots, shot) });
  const state = await p.evaluate(() => window.mcplayDebug.state());
  const verdict = (await p.textContent('#race-verdict')).trim();
  const rows = await p.$$eval('#race-table tbody tr', (trs) => trs.map((tr) => ({
    winner: tr.classList.contains('winner'),
    cells: [...tr.children].map((c) => c.textContent.trim()),
  })));
  // the rows' notes, under the table: "name: note; note."
  const notes = await p.$$eval('#race-table .race-notes li', (lis) => lis.map((li) => li.textContent.trim()));
  return { state, verdict, rows, notes };
}

// ---------------------------------------------------------------------------------------------
// What the data allow, computed here from the stopping result.

function median(sorted) {
  const n = sorted.length;
  const h = Math.floor(n / 2);
  return n % 2 ? sorted[h] : (sorted[h - 1] === Infinity ? Infinity : (sorted[h - 1] + sorted[h]) / 2);
}

/** Largest k with P(Binomial(n, 0.05) >= k) >= 0.1, by summing the pmf. */
function allowance(n) {
  const pmf = (k) => {
    let c = 1;
    for (let i = 1; i <= k; ++i) c *= (n - k + i) / i;
    return c * 0.05 ** k * 0.95 ** (n - k);
  };
  let k = 0;
  for (;;) {
    let tail = 0;
    for (let j = k + 1; j <= n; ++j) tail += pmf(j);
    if (k >= n || tail < 0.1) return k;
    ++k;
  }
}

function raceFacts(state) {
  const exact = state.sceneInfo.exact;
  const stop = state.race.result.stopping || {};
  const tol = Math.max(stop.abs_tol || 0, (stop.rel_tol || 0) * Math.abs(exact));
  const step = state.clock.step;
  const floor = step > 0 ? (STEPS * step) / 1000 : null;
  const facts = {};
  for (const e of state.race.result.estimators) {
    const times = e.runs.map((r) => (r.met ? r.seconds : Infinity)).sort((a, b) => a - b);
    const met = e.runs.filter((r) => r.met);
    const errors = met.map((r) => Math.abs(r.estimate - exact)).sort((a, b) => a - b);
    facts[e.name] = {
      median: median(times),
      met: met.length,
      runs: e.runs.length,
      misses: met.filter((r) => Math.abs(r.estimate - exact) > tol).length,
      error: errors.length ? median(errors) : null,
      conservative: e.error_bars_conservative === true,
    };
  }
  return { facts, floor, tol, step };
}

const names = (text) => text.split(/,\s*|\s+and\s+/).map((s) => s.trim()).filter(Boolean);
/** A number shown to two significant digits (or a whole ratio >= 10) against the data's. */
const close = (shown, actual, rel = 0.06) => Math.abs(shown / actual - 1) <= rel;

/** Asserts that nothing the card says contradicts the data; returns the winner named, if any. */
function checkRace({ state, verdict, rows, notes }) {
  const { facts, floor } = raceFacts(state);
  const all = Object.keys(facts);
  const fastest = all.reduce((a, b) => (facts[a].median <= facts[b].median ? a : b));
  // A winner: the fastest, timed above the clock's floor, its answers within what chance allows.
  let winner = verdict.match(/(\S+) reaches the target first/)?.[1] ?? null;
  if (!winner) {
    const one = verdict.match(/(?:^|\. )(\S+) reached the target in \d+ of \d+ runs\./);
    if (one && all.length === 1) winner = one[1];
  }
  if (winner) {
    assert.ok(all.includes(winner), `winner ${winner} is not raced`);
    assert.equal(winner, fastest, `${winner} named, ${fastest} has the smallest median`);
    assert.ok(floor !== null && facts[winner].median >= floor,
      `${winner} named with a median of ${facts[winner].median} s under the floor ${floor} s`);
    assert.ok(facts[winner].misses <= allowance(facts[winner].met),
      `${winner} named though ${facts[winner].misses} of its ${facts[winner].met} answers missed the target`);
  }
  // "did not (reach)": only of estimators whose median is infinite (most runs ran out).
  for (const m of verdict.matchAll(/\(([^()]*?) did not\)/g)) {
    const said = names(m[1].replace(/\s*and the others$/, ''));
    const others = /and the others$/.test(m[1]) ? all.filter((n) => n !== winner) : [];
    for (const n of [...said, ...others]) assert.equal(facts[n]?.median, Infinity, `"${n} did not" but it met the target in ${facts[n]?.met} of ${facts[n]?.runs}`);
  }
  for (const m of verdict.matchAll(/([\w, ]+?) did not reach it in most runs/g)) {
    for (const n of names(m[1]).filter((x) => all.includes(x))) assert.equal(facts[n].median, Infinity, `"${n} did not reach it"`);
  }
  for (const n of all) {
    if (facts[n].met * 2 > facts[n].runs) assert.doesNotMatch(verdict, new RegExp(`only one to reach it[^.]*\\b${n}\\b`), `${n} met the target`);
  }
  // A ratio: the medians' ratio, both timed above the floor.
  const ratio = verdict.match(/([\d.]+)× faster than the next, (\S+) \(/);
  if (ratio) {
    const [, shown, next] = ratio;
    assert.ok(facts[next].median >= floor && facts[winner].median >= floor, 'a ratio of times the clock can compare');
    assert.ok(close(Number(shown), facts[next].median / facts[winner].median), `ratio ${shown} against ${facts[next].median / facts[winner].median}`);
  }
  // Conservative error bars said to stop late: the actual error is far under the tolerance.
  for (const text of [verdict, ...notes]) {
    for (const m of text.matchAll(/(\S+?):? stops on its own conservative error bar[^:]*:(?: at N = \d+)? its actual error was ([\d.e+-]+), ([\d.e+-]+)× under the tolerance; ([^.]*)/g)) {
      const [, who, err, times, where] = m;
      const f = facts[who] ?? facts[text.split(':')[0]];
      assert.ok(f && f.conservative, `${who}: said to be conservative`);
      assert.ok(close(Number(err), f.error, 0.06), `${who}: actual error ${err} against ${f.error}`);
      assert.ok(Number(times) >= 10, `${who}: ${times}× is not "far under"`);
      if (/is last/.test(where)) {
        const name = f === facts[who] ? who : text.split(':')[0];
        assert.ok(all.every((n) => facts[n].median <= facts[name].median), `${name} said last`);
      }
    }
  }
  // Rows: reached counts in numbers and reasons in words; no ratio or winner under the floor.
  const body = rows;
  assert.deepEqual(body.map((r) => r.cells[0]).sort(), all.slice().sort(), 'one row per estimator');
  for (const r of body) {
    const f = facts[r.cells[0]];
    const reached = r.cells[3];
    assert.ok(reached.startsWith(`${f.met}/${f.runs}`), `${r.cells[0]}: reached ${reached}`);
    if (f.met < f.runs) assert.match(reached, /\((ran out of|no error bar|its error bar)/, `${r.cells[0]}: why, in words`);
    assert.doesNotMatch(reached, /_/, 'no reason code');
    if (floor === null || f.median < floor) {
      assert.doesNotMatch(r.cells[r.cells.length - 1], /×/, `${r.cells[0]}: a ratio under the floor`);
      assert.ok(!r.winner, `${r.cells[0]}: marked the winner under the floor`);
    }
  }
  return { winner, facts, floor };
}

// ---------------------------------------------------------------------------------------------
// (i) cross-origin isolated

test('isolated: the run worker measures a fine clock, and no banner shows', async () => {
  const p = await page(true);
  const { clock } = await p.evaluate(() => window.mcplayDebug.state());
  assert.equal(clock.isolated, true);
  assert.ok(clock.step > 0 && clock.step <= 0.02, `step ${clock.step} ms`);
  assert.equal(await p.isVisible('#clock-banner'), false);
  const timeNote = await p.textContent('#time-clock-note');
  const raceNote = await p.textContent('#race-clock-note');
  assert.match(timeNote, /steps by [\d.]+ µs here \(this page is cross-origin isolated\)/);
  assert.match(raceNote, /steps by [\d.]+ µs here/);
  assert.doesNotMatch(timeNote + raceNote, /few microseconds|5 µs to 0\.1 ms/);
});

test('isolated: exp_1d race names latin_hypercube\'s conservative stop with its actual error; nothing contradicts the data', async () => {
  const p = open[0].page;
  const out = await race(p, 'clock_race_isolated.png');
  console.log(`# verdict: ${out.verdict}`);
  const { facts } = checkRace(out);
  assert.match(out.verdict, /Target: relative 0\.001/);
  const said = [out.verdict, ...out.notes].join(' ');
  const m = said.match(/latin_hypercube:? stops on its own conservative error bar \(the iid formula[^)]*\): at N = (\d+) its actual error was ([\d.e+-]+)/);
  assert.ok(m, `no conservative stop named for latin_hypercube: ${said}`);
  assert.ok(close(Number(m[2]), facts.latin_hypercube.error), `actual error ${m[2]} against ${facts.latin_hypercube.error}`);
  const ns = (await p.evaluate(() => window.mcplayDebug.state())).race.result.estimators
    .find((e) => e.name === 'latin_hypercube').runs.filter((r) => r.met).map((r) => r.n).sort((a, b) => a - b);
  assert.equal(Number(m[1]), median(ns), 'its median N');
});

// ---------------------------------------------------------------------------------------------
// (ii) a plain static host: no cross-origin isolation

let plain = null;

test('non-isolated: the banner is visible and says the clock\'s 0.1 ms step', async () => {
  plain = await page(false);
  const { clock } = await plain.evaluate(() => window.mcplayDebug.state());
  assert.equal(clock.isolated, false);
  assert.ok(clock.step >= 0.05, `Chromium without isolation steps by 0.1 ms, measured ${clock.step} ms`);
  assert.equal(await plain.isVisible('#clock-banner'), true);
  assert.equal(await plain.getAttribute('#clock-banner', 'role'), 'status');
  const banner = await plain.textContent('#clock-banner');
  assert.match(banner, /not cross-origin isolated/);
  assert.match(banner, /steps by 0\.1 ms/);
  assert.match(banner, /under 2 ms/);
  assert.match(await plain.textContent('#race-clock-note'), /0\.1 ms here \(this page is not cross-origin isolated\)/);
  await plain.locator('#clock-banner').screenshot({ path: join(shots, 'clock_banner.png') });
});

test('non-isolated: the race names no winner under the floor and no "did not reach" for rows that met it', async () => {
  const out = await race(plain, 'clock_race_plain.png');
  console.log(`# verdict: ${out.verdict}`);
  const { winner, facts, floor } = checkRace(out);
  assert.ok(floor >= 1e-3, `floor ${floor} s`);
  if (winner) assert.ok(facts[winner].median >= floor);
  for (const n of Object.keys(facts)) {
    if (facts[n].median < floor) assert.doesNotMatch(out.verdict, new RegExp(`${n} reaches the target first`));
  }
  assert.doesNotMatch(out.verdict, /∞|Infinity/);
});

test('non-isolated: time verdict names no winner under the floor', async () => {
  const estimators = ['uniform', 'stratified', 'importance', 'latin_hypercube'];
  // N up to 4096: every estimator's time per estimate is under 2 ms here, so no winner may be named
  await configure(plain, 'exp_1d', estimators, { nMin: 16, nMax: 4096, reps: 16, seed: 1 });
  await plain.click('#run');
  await plain.waitForFunction(() => document.querySelector('#status')?.textContent.startsWith('done'), null, { timeout: 120000 });
  const s = await plain.evaluate(() => window.mcplayDebug.state());
  const floor = (STEPS * s.clock.step) / 1000;
  const verdict = (await plain.textContent('#time-verdict')).trim();
  console.log(`# time verdict: ${verdict}`);
  // each estimator's time at the largest N it reached (the median, else the mean), as plotted
  const time = Object.fromEntries(s.estimators.map((e) => {
    const l = e.levels[e.levels.length - 1];
    return [e.name, l.time_median_s > 0 ? l.time_median_s : l.time_mean_s];
  }));
  console.log(`# times at the largest N (floor ${floor} s): ${JSON.stringify(time)}`);
  const named = [];
  for (const re of [/winner[^:]*:\s*(\S+?),/i, /Most efficient[^:]*:\s*(\S+?),/i, /^(\S+) (?:is|wins)\b(?! exact)/]) {
    const m = verdict.match(re);
    if (m && estimators.includes(m[1])) named.push(m[1]);
  }
  if (/\bno winner\b|no significant difference/i.test(verdict)) named.length = 0;
  for (const n of named) {
    assert.ok(time[n] >= floor, `#time-verdict names ${n}, whose time ${time[n]} s is under ${STEPS} clock steps (${floor} s)`);
  }
  // With every time under the floor nothing can be compared (the banner says so): no ratio, no z.
  if (estimators.every((n) => time[n] < floor)) {
    assert.doesNotMatch(verdict, /\d×|\bz = /, '#time-verdict compares times under the clock\'s floor');
  }
});
