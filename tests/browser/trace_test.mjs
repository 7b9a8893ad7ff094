// Browser test of the hazard trace report (`safecass trace --html`), in headless Chromium
// (Debian's /usr/bin/chromium) driven by playwright-core (web/package.json):
//   1. robodoc with its three scenarios: one matrix body per hazard (H-2 … H-6) with its rows, the
//      gap markers of the page's gap table, a timeline excerpt drawn (bars) for each hazard, and no
//      error-severity gap; the page printed to PDF by Chromium has every hazard id (pdftotext).
//   2. a system with a hazard that nothing detects: its row carries the ERROR marker.
// Screenshot: OUT/trace.png (the first screen: header and matrix); the PDF: OUT/trace.pdf.
//
// usage: node trace_test.mjs SAFECASS SOURCE_DIR OUT_DIR

import { execFileSync, spawnSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';

import { launchChromium } from './chromium.mjs';

const [safecass, root, out] = process.argv.slice(2);
if (!safecass || !root || !out) {
  console.error('usage: node trace_test.mjs SAFECASS SOURCE_DIR OUT_DIR');
  process.exit(2);
}
fs.mkdirSync(out, { recursive: true });

let context = null;
let userDataDir = '';
let failures = 0;
const deadline = setTimeout(() => { console.log('FAILED: deadline (60 s) passed'); process.exit(1); }, 60000);

function check(condition, what) {
  console.log(`${condition ? 'ok' : 'FAILED'}: ${what}`);
  if (!condition) failures += 1;
}

/** Runs `safecass trace ... --html FILE`; returns its exit code. */
function trace(args, html) {
  const r = spawnSync(safecass, ['trace', ...args, '--html', html], { cwd: root, encoding: 'utf8', timeout: 30000 });
  if (r.error) throw r.error;
  return r.status;
}

async function testRobodoc() {
  const html = path.join(out, 'trace.html');
  const code = trace(['examples/robodoc/robodoc.json', '--scenarios', 'examples/robodoc/story.json',
    'examples/robodoc/injection.json', 'examples/robodoc/warnings.json', 'examples/robodoc/overload.json'], html);
  check(code === 0, `safecass trace on robodoc exits 0 (no error-severity gap), got ${code}`);
  const page = await context.newPage();
  await page.setViewportSize({ width: 1280, height: 900 });
  const errors = [];
  page.on('pageerror', (e) => errors.push(String(e)));
  await page.goto('file://' + path.resolve(html));
  await page.waitForSelector('body[data-drawn]', { timeout: 10000 });
  const hazards = await page.locator('#matrix-table tbody.hazard').evaluateAll(
    (bodies) => bodies.map((b) => ({ id: b.dataset.hazard, rows: b.rows.length })));
  const ids = hazards.map((h) => h.id);
  check(['H-3', 'H-5', 'H-6'].every((id) => ids.includes(id)), `the matrix has H-3, H-5 and H-6 (${ids.join(' ')})`);
  check(hazards.every((h) => h.rows >= 2 || h.id === ''), 'each hazard has a row per event × filter (onset and completion at least)');
  const h3 = await page.locator('tbody[data-hazard="H-3"] tr').evaluateAll(
    (rows) => rows.map((r) => `${r.dataset.event}/${r.dataset.filter}`));
  check(h3.includes('EVT_FORCE_ERROR/force_limit'), `H-3 traces EVT_FORCE_ERROR to force_limit (${h3.join(', ')})`);
  check(await page.locator('#matrix-table tbody[data-hazard="H-3"]').innerText().then((t) => t.includes('threshold 30')),
    'H-3 shows the threshold of force_limit');
  // Gap markers: every gap of the table is marked in the matrix with its severity, none is an error.
  const gapRows = await page.locator('#gap-table tr.gap').evaluateAll(
    (rows) => rows.map((r) => ({ kind: r.dataset.kind, severity: r.dataset.severity })));
  check(gapRows.every((g) => g.severity !== 'error'), `no gap of error severity (${gapRows.length} gaps)`);
  const matrixMarkers = await page.locator('#matrix-table .marker-gap').count();
  check(matrixMarkers >= gapRows.filter((g) => g.kind !== 'scenario-failed').length,
    `the matrix marks every gap (${matrixMarkers} markers for ${gapRows.length} gaps)`);
  check(await page.locator('#matrix-table .marker-gap.error').count() === 0, 'no ERROR marker in the matrix');
  check((await page.locator('#verdict').innerText()).includes('No gap of error severity'), 'the header says: no error-severity gap');
  // Header: system, a SHA-256 per spec file, the tool version and the date.
  check((await page.locator('#system-name').innerText()) === 'robodoc', 'the header names the system');
  const hashes = await page.locator('#file-table td.hash').allTextContents();
  check(hashes.length === 6 && hashes.every((h) => /^[0-9a-f]{64}$/.test(h)), `a SHA-256 for each of the 6 spec files (${hashes.length})`);
  check(/safecass \d+\.\d+\.\d+/.test(await page.locator('#tool-version').innerText()), 'the header has the tool version');
  check(/\d{4}-\d\d-\d\d/.test(await page.locator('#report-date').innerText()), 'the header has the date');
  // Timeline excerpts: drawn by the timeline's renderer, with bars, for each hazard.
  const figures = await page.locator('figure.excerpt').evaluateAll((fs) => fs.map((f) => ({
    id: f.dataset.hazard, bars: f.querySelectorAll('rect.bar').length, errors: f.querySelectorAll('rect.bar.state-Error').length })));
  check(figures.length === hazards.filter((h) => h.id !== '').length, `one excerpt per hazard (${figures.length})`);
  check(figures.every((f) => f.bars > 0), `every excerpt draws bars (${figures.map((f) => `${f.id}:${f.bars}`).join(' ')})`);
  const h3fig = figures.find((f) => f.id === 'H-3');
  check(h3fig !== undefined && h3fig.errors > 0, 'the H-3 excerpt shows the Error state');
  check((await page.locator('#coverage-table tr').count()) === 5, 'the coverage summary has its five rows');
  check(errors.length === 0, `no script error (${errors.join('; ')})`);
  await page.screenshot({ path: path.join(out, 'trace.png') })
    .catch((e) => console.log(`note: no screenshot (${e.message.split('\n')[0]})`));  // the header and the matrix's start

  // Printed to PDF by Chromium: every hazard id is in the text.
  const pdf = path.join(out, 'trace.pdf');
  await page.emulateMedia({ media: 'print' });
  await page.pdf({ path: pdf, format: 'A4', landscape: true, printBackground: true, preferCSSPageSize: true });
  const text = execFileSync('pdftotext', ['-layout', pdf, '-'], { encoding: 'utf8' });
  const missing = ids.filter((id) => id !== '' && !text.includes(id));
  check(text.length > 0 && missing.length === 0, `the PDF has every hazard id (${missing.length ? 'missing ' + missing.join(' ') : ids.join(' ')})`);
  check(text.includes('Traceability matrix') && text.includes('force_limit'), 'the PDF has the matrix');
  await page.close();
}

async function testUndetected() {
  const html = path.join(out, 'trace-undetected.html');
  const code = trace(['tests/data/trace/undetected.json'], html);
  check(code === 1, `a hazard that nothing detects makes trace exit 1, got ${code}`);
  const page = await context.newPage();
  await page.goto('file://' + path.resolve(html));
  await page.waitForSelector('body[data-drawn]', { timeout: 10000 });
  const marker = page.locator('tbody[data-hazard="H-9"] .marker-gap.error[data-gap="hazard-undetected"]');
  check(await marker.count() === 1, 'H-9 carries the ERROR marker "no detecting filter"');
  check(await page.locator('#gap-table tr.gap-error[data-kind="hazard-undetected"]').count() === 2,
    'the gap table lists H-8 and H-9 as undetected');
  check((await page.locator('#verdict').getAttribute('class')).includes('fail'), 'the header shows the failure');
  await page.close();
}

try {
  ({ context, userDataDir } = await launchChromium(root));
  await testRobodoc();
  await testUndetected();
} catch (e) {
  console.log(`FAILED: ${e.stack ?? e}`);
  failures += 1;
} finally {
  if (context) await context.close();
  if (userDataDir) fs.rmSync(userDataDir, { recursive: true, force: true });
  clearTimeout(deadline);
}
console.log(failures === 0 ? 'trace browser test passed' : `trace browser test: ${failures} check(s) failed`);
process.exit(failures === 0 ? 0 : 1);
