// Tests of web/src/palette.js: ten estimator colours, never black, none too light for a line on
// white, and every pair apart under normal vision and simulated dichromacy [Machado09], measured
// as the CIE 1976 colour difference in L*a*b*.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { PALETTE, colorAt } from '../src/palette.js';

// Machado, Oliveira and Fernandes (2009), severity 1, on linear sRGB.
const VISION = {
  normal: [[1, 0, 0], [0, 1, 0], [0, 0, 1]],
  protanopia: [[0.152286, 1.052583, -0.204868], [0.114503, 0.786281, 0.099216], [-0.003882, -0.048116, 1.051998]],
  deuteranopia: [[0.367322, 0.860646, -0.227968], [0.280085, 0.672501, 0.047413], [-0.011820, 0.042940, 0.968881]],
  tritanopia: [[1.255528, -0.076749, -0.178779], [-0.078411, 0.930809, 0.147602], [0.004733, 0.691367, 0.303900]],
};

function toLab(hex, m = VISION.normal) {
  const n = parseInt(hex.slice(1), 16);
  const linear = (c) => { const v = c / 255; return v <= 0.04045 ? v / 12.92 : ((v + 0.055) / 1.055) ** 2.4; };
  const rgb = [(n >> 16) & 255, (n >> 8) & 255, n & 255].map(linear);
  const [r, g, b] = m.map((row) => Math.min(1, Math.max(0, row[0] * rgb[0] + row[1] * rgb[1] + row[2] * rgb[2])));
  const x = (0.4124 * r + 0.3576 * g + 0.1805 * b) / 0.95047;
  const y = 0.2126 * r + 0.7152 * g + 0.0722 * b;
  const z = (0.0193 * r + 0.1192 * g + 0.9505 * b) / 1.08883;
  const f = (t) => (t > 216 / 24389 ? Math.cbrt(t) : ((24389 / 27) * t + 16) / 116);
  return [116 * f(y) - 16, 500 * (f(x) - f(y)), 200 * (f(y) - f(z))];
}

test('ten distinct colours, none black, none too light for a line on white', () => {
  assert.equal(PALETTE.length, 10);
  assert.equal(new Set(PALETTE).size, 10);
  for (const c of PALETTE) {
    const [L] = toLab(c);
    assert.ok(L > 20, `${c}: L* = ${L.toFixed(0)} is too near black (the reference curves' colour)`);
    assert.ok(L < 75, `${c}: L* = ${L.toFixed(0)} is too light on white`);
  }
  assert.equal(colorAt(10), colorAt(0));
  assert.equal(colorAt(-1), colorAt(9));
});

test('every pair stays apart under normal vision and the three dichromacies', () => {
  for (const [vision, m] of Object.entries(VISION)) {
    const lab = PALETTE.map((c) => toLab(c, m));
    for (let i = 0; i < lab.length; ++i) {
      for (let j = i + 1; j < lab.length; ++j) {
        const d = Math.hypot(lab[i][0] - lab[j][0], lab[i][1] - lab[j][1], lab[i][2] - lab[j][2]);
        assert.ok(d >= 12, `${vision}: ${PALETTE[i]} and ${PALETTE[j]} differ by only ΔE = ${d.toFixed(1)}`);
      }
    }
  }
});
