// A screenshot of `qem view` for the docs (docs/figures/): starts `qem view ARGS --port 0`, opens
// the page in headless Chromium, ticks the given panel toggles, waits for the page to settle and
// saves a PNG. Usage:
//   node tests/view/screenshot.mjs OUT.png [--width 900 --height 480] [--check seams,uv-checker]
//        [--pause] [--fold] -- MESH...     (--fold: fold the panel to its title)
// Env: QEM (default build/qem), CHROMIUM (default /usr/bin/chromium).
import { spawn } from 'node:child_process';
import { mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { createRequire } from 'node:module';

const here = dirname(fileURLToPath(import.meta.url));
const { chromium } = createRequire(join(here, '..', '..', 'web', 'package.json'))('playwright-core');
const argv = process.argv.slice(2), sep = argv.indexOf('--');
if (argv.length < 1 || sep < 0) { console.error('usage: node screenshot.mjs OUT.png [options] -- MESH...'); process.exit(2); }
const opts = argv.slice(1, sep), meshes = argv.slice(sep + 1);
const opt = (name, dflt) => { const i = opts.indexOf(name); return i >= 0 ? opts[i + 1] : dflt; };
const width = Number(opt('--width', 900)), height = Number(opt('--height', 480));
const toggles = opt('--check', '').split(',').filter(Boolean);

const qem = spawn(resolve(process.env.QEM || 'build/qem'), ['view', ...meshes, '--port', '0'], { stdio: ['ignore', 'pipe', 'inherit'] });
const url = await new Promise((res, rej) => {
  let out = '';
  qem.stdout.on('data', (d) => { out += d; const m = out.match(/http:\/\/127\.0\.0\.1:\d+\//); if (m) res(m[0]); });
  qem.on('exit', (code) => rej(new Error(`qem view exited with ${code}`)));
});
const profile = mkdtempSync(join(tmpdir(), 'qem-shot-'));
try {
  const browser = await chromium.launchPersistentContext(profile, {
    executablePath: process.env.CHROMIUM || '/usr/bin/chromium', headless: true, viewport: { width, height },
    args: ['--no-sandbox', '--disable-gpu', '--enable-unsafe-swiftshader', '--no-first-run'],
  });
  const page = await browser.newPage();
  await page.goto(url);
  await page.waitForFunction(() => window.qemViewer && (window.qemViewer.ready || window.qemViewer.error), null, { timeout: 60000 });
  const error = await page.evaluate(() => window.qemViewer.error);
  if (error) throw new Error(error);
  for (const id of toggles) await page.locator(`#${id}`).check();
  if (opts.includes('--fold')) await page.locator('#panel-toggle').click();
  if (opts.includes('--pause')) await page.evaluate(() => window.qemViewer.setPlaying(false));
  await page.waitForTimeout(500);
  await page.screenshot({ path: argv[0] });
  await browser.close();
  console.log(`wrote ${argv[0]}`);
} finally {
  qem.kill('SIGTERM');
  rmSync(profile, { recursive: true, force: true });
}
