// Tests of web/src/plot/guide_labels.js: the time plot's guide-line names (t^-1/2, t^-1) never
// overlap, even where the two lines end a few pixels apart (a phone's short plot).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { placeGuideLabels } from '../src/plot/guide_labels.js';

const BOX = { height: 13, gap: 1, top: 10, bottom: 250 };
const overlap = (a, b) => Math.abs(a - b) < BOX.height;

test('labels far apart stay where they want to be', () => {
  const ys = placeGuideLabels([{ x: 300, y: 60, width: 20 }, { x: 300, y: 200, width: 20 }], BOX);
  assert.deepEqual(ys, [60, 200]);
});

test('labels at the same x a few pixels apart: the upper one moves up, clear of the other', () => {
  // t^-1/2 ends at y = 120, t^-1 at y = 126 (the order the plot gives them in: t^-1 first)
  const ys = placeGuideLabels([{ x: 300, y: 126, width: 22 }, { x: 300, y: 120, width: 24 }], BOX);
  assert.equal(ys[0], 126, 'the lower label keeps its place');
  assert.ok(!overlap(ys[0], ys[1]), `baselines ${ys}`);
  assert.ok(ys[1] < ys[0], 'the upper label stays above');
  // the same baseline exactly
  const same = placeGuideLabels([{ x: 300, y: 100, width: 22 }, { x: 300, y: 100, width: 24 }], BOX);
  assert.ok(!overlap(same[0], same[1]), `baselines ${same}`);
});

test('labels that do not meet across are left alone', () => {
  const ys = placeGuideLabels([{ x: 300, y: 120, width: 20 }, { x: 200, y: 122, width: 20 }], BOX);
  assert.deepEqual(ys, [120, 122]);
});

test('at the top of the plot the upper label goes below instead; nothing leaves the plot', () => {
  const ys = placeGuideLabels([{ x: 300, y: 18, width: 20 }, { x: 300, y: 14, width: 20 }], BOX);
  assert.ok(!overlap(ys[0], ys[1]), `baselines ${ys}`);
  for (const y of ys) assert.ok(y >= BOX.top + BOX.height && y <= BOX.bottom, `baseline ${y}`);
  // a line ending below the plot: its label is kept inside
  const low = placeGuideLabels([{ x: 300, y: 400, width: 20 }, { x: 300, y: 380, width: 20 }], BOX);
  for (const y of low) assert.ok(y <= BOX.bottom, `baseline ${y}`);
  assert.ok(!overlap(low[0], low[1]), `baselines ${low}`);
});
