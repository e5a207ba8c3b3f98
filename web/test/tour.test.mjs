// Tests of the teaching path: web/tour.json names every scene of scenes/ exactly once, starts
// with an integral, and build-site's orderByTour refuses a tour that disagrees with the folder.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { orderByTour, manifestEntry } from '../tools/build-site.mjs';

const ROOT = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..', '..');

test('web/tour.json lists every scene of scenes/ once, an integral first, with what to look for', () => {
  const files = fs.readdirSync(path.join(ROOT, 'scenes')).filter((f) => f.endsWith('.json'));
  const manifest = files.map((f) => manifestEntry(f, JSON.parse(fs.readFileSync(path.join(ROOT, 'scenes', f), 'utf8'))));
  const tour = JSON.parse(fs.readFileSync(path.join(ROOT, 'web', 'tour.json'), 'utf8'));
  const ordered = orderByTour(manifest, tour);
  assert.equal(ordered.length, manifest.length);
  assert.equal(ordered[0].kind, 'integral');
  // Warp scenes (the sampler lab's examples) need no stop of the tour; those it leaves out come last.
  for (const m of ordered.filter((e) => !(e.warp && !e.group))) {
    assert.ok(m.group, `${m.name}: no group`);
    assert.ok(m.look && m.look.length > 40, `${m.name}: no text of what to look for`);
  }
});

test('the warp scenes that are studies have a stop of the tour, each pointing to the lab\'s warp test', () => {
  const files = fs.readdirSync(path.join(ROOT, 'scenes')).filter((f) => f.startsWith('warp_') && f.endsWith('.json'));
  const tour = JSON.parse(fs.readFileSync(path.join(ROOT, 'web', 'tour.json'), 'utf8'));
  const stops = new Map(tour.groups.flatMap((g) => g.scenes.map((s) => [s.name, { ...s, group: g.title }])));
  const studies = files.map((f) => JSON.parse(fs.readFileSync(path.join(ROOT, 'scenes', f), 'utf8'))).filter((s) => s.f !== undefined);
  assert.ok(studies.length >= 7, `${studies.length} warp studies`);
  for (const s of studies) {
    const stop = stops.get(s.name);
    assert.ok(stop, `${s.name}: not in the tour`);
    assert.match(stop.group, /Warps/, s.name);
    assert.ok(stop.look.includes(`warp test (example ${s.name})`), `${s.name}: the look does not point to the lab's warp test`);
  }
});

test('orderByTour: the tour order, and every disagreement with the folder named', () => {
  const m = (name) => ({ name, kind: 'integral' });
  const tour = { groups: [{ title: 'B', scenes: [{ name: 'b', look: 'x' }] }, { title: 'A', scenes: [{ name: 'a' }] }] };
  assert.deepEqual(orderByTour([m('a'), m('b')], tour).map((e) => [e.name, e.group, e.look]), [['b', 'B', 'x'], ['a', 'A', '']]);
  assert.throws(() => orderByTour([m('a'), m('b'), m('c')], tour), /scenes in no group of the tour: c/);
  assert.throws(() => orderByTour([m('a')], tour), /the tour names 'b', which is not a scene/);
  // a warp scene the tour does not name comes last, without a group; one it names keeps its place
  const w = (name) => ({ name, kind: 'warp', warp: true });
  assert.deepEqual(orderByTour([w('w'), m('a'), m('b')], tour).map((e) => [e.name, e.group ?? null]), [['b', 'B'], ['a', 'A'], ['w', null]]);
  const withW = { groups: [...tour.groups, { title: 'W', scenes: [{ name: 'w' }] }] };
  assert.deepEqual(orderByTour([w('w'), m('a'), m('b')], withW).map((e) => e.group), ['B', 'A', 'W']);
  const twice = { groups: [{ title: 'A', scenes: [{ name: 'a' }, { name: 'a' }] }] };
  assert.throws(() => orderByTour([m('a')], twice), /names 'a' twice/);
});
