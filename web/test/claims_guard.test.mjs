// Keeps the class of issue 38 from coming back: the views draw the words of web/src/claims.js
// and never make their own from a result (a fitted order, a flag code, an "exact" or "by design"
// label, a verdict), and never show a core code where words belong.
import test from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync, readdirSync } from 'node:fs';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';

const src = join(dirname(fileURLToPath(import.meta.url)), '..', 'src');
const views = [
  ...readdirSync(join(src, 'plot')).map((f) => join('plot', f)),
  ...readdirSync(join(src, 'ui')).map((f) => join('ui', f)),
  'report.js', 'images.js', 'plot.js', 'main.js',
].filter((f) => f.endsWith('.js'));

// What a view may not call or write: claims.js says these.
const FORBIDDEN = [
  [/\bfitText\s*\(/, 'a fitted order without its goodness of fit: use orderClaim'],
  [/\bFLAG_TITLES\b/, 'flag words: use flagTitle / flagShort from claims.js'],
  [/\bequalTimeVerdict\b/, 'the equal-time verdict: use equalTimeClaim'],
  [/\bconservativeErrorBars\b/, '"by design": use conservativeClaim'],
  [/exact_to_roundoff/, 'exactness: use levelExactness / recordExactness'],
  [/by design/, 'a fixed "by design" label: conservativeClaim says it only where the run shows it'],
  [/,\s*w\.code\s*\)/, 'a flag code as text: use flagShort / flagTitle (the code goes in data-code or a <code> detail)'],
  [/\$\{\s*\w+\.pdf\s*\}/, 'the core\'s pdf notation as words: use densityWords'],
  [/tail index[^'`]*\$\{\s*fmt\(/, 'a raw Hill number: use tailWords'],
  [/p = \$\{\s*fmt\(/, 'a p-value that can print "p = 0": use pWords'],
];

test('views take their words from claims.js', () => {
  const problems = [];
  for (const f of views) {
    const text = readFileSync(join(src, f), 'utf8');
    text.split('\n').forEach((line, i) => {
      if (/^\s*(\/\/|\*)/.test(line)) return; // comments may name what they do not do
      for (const [re, why] of FORBIDDEN) {
        // <code> details carry the code on purpose
        if (re.source.includes('w\\.code') && /el\('code'/.test(line)) continue;
        if (re.test(line)) problems.push(`${f}:${i + 1}: ${why}\n    ${line.trim()}`);
      }
    });
  }
  assert.deepEqual(problems, [], `\n${problems.join('\n')}`);
});

test('the guard sees what it forbids', () => {
  // the patterns match the lines they were written against
  const samples = ['el(\'span\', {}, w.code)', 'el(\'span\', {}, fitText(r.fit))', '`${r.pdf}`', '`p = ${fmt(p, 3)}`'];
  for (const s of samples) assert.ok(FORBIDDEN.some(([re]) => re.test(s)), s);
});
