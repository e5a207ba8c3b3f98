// Tests of web/index.html's own words and order: the workers are Web Workers (no "service
// worker" anywhere on the page), and the first thing a Tab reaches is the link to Run.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const ROOT = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..', '..');
const HTML = fs.readFileSync(path.join(ROOT, 'web', 'index.html'), 'utf8');

test('the page never calls its Web Workers a service worker', () => {
  assert.doesNotMatch(HTML, /service[\s-]+worker/i);
  const footer = HTML.slice(HTML.indexOf('<footer'), HTML.indexOf('</footer>'));
  assert.match(footer, /Web Worker/);
});

test('the first focusable element of the page is a link to Run', () => {
  const body = HTML.slice(HTML.indexOf('<body'));
  const first = body.match(/<(a|button|input|select|textarea|summary)\b[^>]*>/);
  assert.ok(first, 'no focusable element');
  assert.match(first[0], /^<a\b[^>]*href="#run"/);
});
