// The render images' scale factors (web/src/images.js): whole factors only, so that every
// pixel is a square of equal size, never smoothed and never scaled down.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { imageScale, zoomScale } from '../src/images.js';

test('images are scaled up by a whole factor to at least 256 px, never down', () => {
  for (const w of [1, 16, 32, 48, 64, 100, 255, 256, 257, 1024]) {
    const k = imageScale(w);
    assert.ok(Number.isInteger(k) && k >= 1, `${w}: ${k}`);
    assert.ok(w * k >= 256 || k === 1, `${w} px shown at ${w * k}`);
    if (k > 1) assert.ok(w * (k - 1) < 256, `${w}: a smaller factor already reaches 256 px`);
  }
  assert.equal(imageScale(48), 6);
  assert.equal(imageScale(300), 1);
});

test('the enlarged view uses the largest whole factor that fits its box', () => {
  assert.equal(zoomScale(48, 48, 1260, 720), 15);
  assert.equal(zoomScale(64, 48, 1260, 720), 15);
  assert.equal(zoomScale(320, 240, 600, 400), 1); // larger than the box: shown at 1x
  assert.equal(zoomScale(0, 0, 100, 100), 100);
});
