// The study page's words on real render studies from the native CLI (MCPLAY_NATIVE, default
// build/mcplay): Veach's scene, whose MIS weights and solid-angle contributions are bounded, must
// keep its lesson (orders, tail words, the equal-time comparison), and the same records with the
// core's heavy_tail raised to warning must lose it (the rule judged both ways); the Cornell box's
// uniform and power choice of its one light must agree, as the tour says.
import test from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { existsSync, readFileSync } from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { orderClaim, tailText, equalTimeClaim, timeSlopeClaim, infiniteVariance, relativeMseText,
  referenceFloorOf } from '../src/claims.js';
import { varianceSeries } from '../src/series.js';

const ROOT = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../..');
const NATIVE = path.resolve(ROOT, process.env.MCPLAY_NATIVE || 'build/mcplay');

function study(scene, args) {
  if (!existsSync(NATIVE)) throw new Error(`native CLI not found: ${NATIVE}. Build it with \`make build\` or set MCPLAY_NATIVE`);
  const out = execFileSync(NATIVE, ['run', path.join(ROOT, 'scenes', `${scene}.json`), '--format', 'json', '--quiet',
    '--seed', '1', ...args], { encoding: 'utf8', maxBuffer: 1 << 28 });
  const result = JSON.parse(out);
  return { result, records: Object.fromEntries(result.estimators.map((e) => [e.name, e])),
    order: result.estimators.map((e) => e.name) };
}

function raised(r) {
  const warnings = r.warnings.filter((w) => w.code !== 'heavy_tail');
  warnings.push({ code: 'heavy_tail', severity: 'warning', message: 'raised by the test' });
  return { ...r, warnings };
}

const MIS = ['mis_balance', 'mis_power'];

test('veach_mis on the CLI: bounded estimators keep their order, tail words and place at equal time', { timeout: 300000 }, () => {
  const v = study('veach_mis', ['--n-max', '32']);
  const floor = referenceFloorOf(v.result);
  assert.ok(floor > 0, 'the result reports the reference\'s relative-MSE floor');
  const bounded = v.order.filter((n) => v.records[n].contribution_bound && v.records[n].contribution_bound.bounded);
  for (const n of [...MIS, 'light_solid_angle']) assert.ok(bounded.includes(n), `${n} is bounded on Veach's scene`);
  for (const name of bounded) {
    const r = v.records[name];
    assert.equal(infiniteVariance(r), false, `${name}: the core raises no heavy_tail at warning`);
    const order = orderClaim(r, { nName: 'spp', measure: 'relative MSE' });
    assert.doesNotMatch(order.text, /infinite/, `${name}: ${order.text}`);
    const last = r.levels[r.levels.length - 1];
    assert.doesNotMatch(tailText(r, last), /^heavy: infinite/, name);
    assert.doesNotMatch(timeSlopeClaim(r, { measure: 'variance', measureName: 'relative MSE', nName: 'spp' }).text, /infinite/, name);
    // its band stays: a finite relative MSE
    const [s] = varianceSeries(v.records, [name], null).series;
    assert.equal(s.infinite, false, name);
  }
  // MIS has an order on this scene (the lesson: good everywhere)
  for (const name of MIS) {
    const c = orderClaim(v.records[name], { nName: 'spp', measure: 'relative MSE' });
    assert.notEqual(c.number, null, `${name}: ${c.text}`);
  }
  const verdict = equalTimeClaim(v.records, v.order, { render: true, nName: 'spp', referenceFloor: floor });
  assert.doesNotMatch(verdict.text, /Fewer than two/);
  for (const name of MIS) assert.ok(verdict.ranked.some((x) => x.name === name), `${name} is compared at equal time`);
  assert.ok(!verdict.left.some((x) => /infinite/.test(x.why)), verdict.text);
  // The images' timing noise is reported, so the leaders' difference can be tested (which one
  // leads depends on the machine's timing: not asserted).
  for (const x of verdict.ranked.slice(0, 2)) assert.ok(x.se > 0, `${x.name}: an uncertainty at equal time`);
  assert.doesNotMatch(verdict.text, /cannot be tested/, verdict.text);
  // A level at the reference's noise is words in the tables, never its number.
  for (const name of v.order) {
    for (const l of v.records[name].levels) {
      const text = relativeMseText(l.variance, { floor, below: l.below_reference_noise });
      if (l.below_reference_noise) assert.match(text, /^at the reference's noise \(below /, `${name} at ${l.n} spp`);
      else assert.doesNotMatch(text, /reference/);
    }
  }

  // The same records with heavy_tail at warning: no order, infinite words, left out, no band.
  const flagged = Object.fromEntries(v.order.map((n) => [n, MIS.includes(n) ? raised(v.records[n]) : v.records[n]]));
  for (const name of MIS) {
    assert.equal(orderClaim(flagged[name], { nName: 'spp', measure: 'relative MSE' }).number, null, name);
    assert.match(timeSlopeClaim(flagged[name], { measure: 'variance', measureName: 'relative MSE' }).text, /relative MSE is infinite/);
    const heavy = { ...flagged[name].levels[flagged[name].levels.length - 1], tail_index: 1.5 };
    assert.match(tailText(flagged[name], heavy), /^heavy: infinite variance/);
    const [s] = varianceSeries(flagged, [name], null).series;
    assert.ok(s.lo.every((x) => x === null), `${name}: no band`);
  }
  const lost = equalTimeClaim(flagged, v.order, { render: true, nName: 'spp', referenceFloor: floor });
  for (const name of MIS) assert.ok(lost.left.some((x) => x.name === name && /infinite/.test(x.why)), name);
});

test('cornell_box on the CLI: one light, so uniform and power choice agree, as the tour says', { timeout: 300000 }, () => {
  const tour = JSON.parse(readFileSync(path.join(ROOT, 'web', 'tour.json'), 'utf8'));
  const look = tour.groups.flatMap((g) => g.scenes).find((s) => s.name === 'cornell_box').look;
  assert.doesNotMatch(look, /costs variance/);
  assert.match(look, /one light/);
  const c = study('cornell_box', ['--estimators', 'light_area,light_area_uniform_choice', '--n-max', '16', '--reps', '8']);
  const [a, b] = ['light_area', 'light_area_uniform_choice'].map((n) => c.records[n]);
  assert.equal(a.levels.length, b.levels.length);
  // Each level's relative MSE, a mean over 8 images, with the t interval of that mean
  // (t_0.975,7 = 2.365): the two agree within 3 combined standard errors at every spp, as one
  // estimator drawn twice must.
  a.levels.forEach((la, i) => {
    const lb = b.levels[i];
    const se = (l) => (l.variance_ci95[1] - l.variance_ci95[0]) / (2 * 2.365);
    const z = Math.abs(la.variance - lb.variance) / Math.hypot(se(la), se(lb));
    assert.ok(z < 3, `spp ${la.n}: ${la.variance} against ${lb.variance} (z = ${z.toFixed(2)})`);
  });
});
