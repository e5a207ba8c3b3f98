// What the page's headless-Chromium tests share: the site served by web/tools/serve.mjs on a
// random loopback port, Debian's chromium (CHROMIUM overrides its path) in a fresh profile, and
// the page opened until its core is ready (window.mcplayDebug.ready).
import { spawn } from 'node:child_process';
import { mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

const here = dirname(fileURLToPath(import.meta.url));

async function waitForServer(url) {
  for (let i = 0; i < 100; ++i) {
    try {
      const r = await fetch(url);
      if (r.ok) return;
    } catch { /* not up yet */ }
    await new Promise((r) => setTimeout(r, 100));
  }
  throw new Error(`the playground server did not answer at ${url}`);
}

/**
 * Serves `site` and opens the playground: {url, context, page, close()}. `onContext(context)`
 * runs before the page opens (e.g. to record every request); `onPageError(message)` hears the
 * page's uncaught errors (they are printed either way). `isolation: false` serves the site
 * without the cross-origin isolation headers (serve.mjs's MCPLAY_NO_ISOLATION=1), as a plain
 * static host does.
 */
export async function openPlayground({ site, viewport, profilePrefix = 'mcplay-chromium-', onContext, onPageError, isolation = true }) {
  const port = 20000 + Math.floor(Math.random() * 20000);
  const url = `http://127.0.0.1:${port}/`;
  const server = spawn(process.execPath, [join(here, '..', 'tools', 'serve.mjs'), site], {
    env: { ...process.env, PORT: String(port), HOST: '127.0.0.1', MCPLAY_NO_ISOLATION: isolation ? '' : '1' },
    stdio: ['ignore', 'pipe', 'inherit'],
  });
  let context, profile;
  const close = async () => {
    await context?.close();
    server.kill();
    if (profile) rmSync(profile, { recursive: true, force: true });
  };
  try {
    await waitForServer(url);
    profile = mkdtempSync(join(tmpdir(), profilePrefix));
    context = await chromium.launchPersistentContext(profile, {
      executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium',
      headless: true,
      args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
        '--disable-background-networking', '--disable-component-update', '--disable-sync'],
      viewport,
    });
    onContext?.(context);
    const page = context.pages()[0] ?? (await context.newPage());
    page.on('pageerror', (e) => {
      console.error('page error:', e.message);
      onPageError?.(e.message);
    });
    await page.goto(url);
    await page.waitForFunction(() => window.mcplayDebug !== undefined, null, { timeout: 20000 });
    await page.evaluate(() => window.mcplayDebug.ready);
    return { url, context, page, close };
  } catch (e) {
    await close();
    throw e;
  }
}
