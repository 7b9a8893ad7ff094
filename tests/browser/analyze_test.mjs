// Browser test of the safety analysis report (`safecass analyze --html/--pdf`), in headless
// Chromium (Debian's /usr/bin/chromium) driven by playwright-core (web/package.json):
//   1. robodoc: one FMEA row per failure mode, a table of cut sets per top event, the GSN diagram
//      drawn by dagre (an SVG node per goal structure node, a diamond under each undeveloped
//      goal), and the PDF printed by the product's own --pdf (Chromium), with the FMEA, the fault
//      trees, the diagram's goals and every hazard id in its text (pdftotext);
//   2. a system whose onset misses its hazard's reaction: exit 1, its row marked ERROR.
// Screenshot: OUT/analysis-gsn.png (the diagram); the PDF: OUT/analysis.pdf.
//
// usage: node analyze_test.mjs SAFECASS SOURCE_DIR OUT_DIR

import { execFileSync, spawnSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';

import { launchChromium } from './chromium.mjs';

const [safecass, root, out] = process.argv.slice(2);
if (!safecass || !root || !out) {
  console.error('usage: node analyze_test.mjs SAFECASS SOURCE_DIR OUT_DIR');
  process.exit(2);
}
fs.mkdirSync(out, { recursive: true });

let context = null;
let userDataDir = '';
let failures = 0;
const deadline = setTimeout(() => { console.log('FAILED: deadline (80 s) passed'); process.exit(1); }, 80000);

function check(condition, what) {
  console.log(`${condition ? 'ok' : 'FAILED'}: ${what}`);
  if (!condition) failures += 1;
}

/** Runs `safecass analyze ...`; returns its exit code. */
function analyze(args) {
  const r = spawnSync(safecass, ['analyze', ...args], { cwd: root, encoding: 'utf8', timeout: 60000 });
  if (r.error) throw r.error;
  if (r.status === 2) console.log(r.stderr);
  return r.status;
}

/** The same analysis as JSON (`--format json`). */
function analysisJson(args) {
  const r = spawnSync(safecass, ['analyze', ...args, '--format', 'json'], { cwd: root, encoding: 'utf8', timeout: 60000 });
  return JSON.parse(r.stdout);
}

async function testRobodoc() {
  const html = path.join(out, 'analysis.html');
  const pdf = path.join(out, 'analysis.pdf');
  fs.rmSync(pdf, { force: true });
  const args = ['examples/robodoc/robodoc.json', '--scenarios', 'examples/robodoc/story.json'];
  const code = analyze([...args, '--html', html, '--pdf', pdf]);
  check(code === 0, `safecass analyze on robodoc exits 0 (no error-severity gap), got ${code}`);
  const json = analysisJson(args);
  const page = await context.newPage();
  await page.setViewportSize({ width: 1400, height: 1000 });
  const errors = [];
  page.on('pageerror', (e) => errors.push(String(e)));
  await page.goto('file://' + path.resolve(html));
  await page.waitForSelector('body[data-gsn]', { timeout: 10000 });
  check(await page.locator('body').getAttribute('data-gsn') === 'drawn', 'the GSN diagram is drawn (dagre)');
  const rows = await page.locator('#fmea-table tbody tr').count();
  check(rows === json.fmea.length, `one FMEA row per failure mode (${rows} of ${json.fmea.length})`);
  const tops = await page.locator('div.top').count();
  check(tops === json.fault_trees.tops.length, `a cut-set table per top event (${tops})`);
  const cutSets = await page.locator('tr.cut-set').count();
  const expected = json.fault_trees.tops.reduce((n, t) => n + t.cut_sets.length, 0);
  check(cutSets === expected, `every cut set is listed (${cutSets} of ${expected})`);
  const nodes = await page.locator('#gsn-figure svg g.node').count();
  check(nodes === json.safety_case.nodes.length, `an SVG node per GSN node (${nodes} of ${json.safety_case.nodes.length})`);
  const undeveloped = json.safety_case.nodes.filter((n) => n.undeveloped).length;
  check(await page.locator('#gsn-figure svg g.node.undeveloped polygon.diamond').count() === undeveloped,
    `a diamond under each undeveloped goal (${undeveloped})`);
  check(await page.locator('#gsn-figure svg polyline.edge').count() > 0, 'the diagram draws its links');
  const stroke = await page.locator('#gsn-figure svg g.node rect').first().evaluate((r) => getComputedStyle(r).stroke);
  check(stroke !== 'none' && stroke !== '', `its shapes are outlined (stroke ${stroke})`);
  check(!(await page.content()).includes('{{'), 'every part of the page template is filled');
  check(errors.length === 0, `no script error (${errors.join('; ')})`);
  await page.locator('#gsn-figure').screenshot({ path: path.join(out, 'analysis-gsn.png') })
    .catch((e) => console.log(`note: no screenshot (${e.message.split('\n')[0]})`));
  await page.close();

  check(fs.existsSync(pdf), 'safecass analyze --pdf printed the report');
  const text = fs.existsSync(pdf) ? execFileSync('pdftotext', ['-layout', pdf, '-'], { encoding: 'utf8' }) : '';
  check(text.includes('FMEA') && text.includes('Fault trees') && text.includes('Safety case'), 'the PDF has the three documents');
  check(text.includes('EVT_FORCE_ERROR@JR3.s_A') && text.includes('TOP1'), 'the PDF has the FMEA rows and the tops');
  const hazards = json.safety_case.nodes.filter((n) => /^G1\.\d+$/.test(n.id)).map((n) => n.text.split(' ')[0]);
  const missing = hazards.filter((h) => !text.includes(h));
  check(hazards.length === 5 && missing.length === 0, `the PDF names every hazard (${missing.length ? 'missing ' + missing.join(' ') : hazards.join(' ')})`);
  check(/G1\.1\.1/.test(text), 'the PDF has the diagram\'s goals');
}

async function testReactionMissed() {
  const html = path.join(out, 'analysis-level-rule.html');
  const code = analyze(['tests/data/verify/level_rule.json', '--html', html]);
  check(code === 1, `an onset that misses its reaction makes analyze exit 1, got ${code}`);
  const page = await context.newPage();
  await page.goto('file://' + path.resolve(html));
  await page.waitForSelector('body[data-gsn]', { timeout: 10000 });
  const marker = page.locator('#fmea-table tr.gap-error .marker-gap.error[data-gap="reaction-missed"]');
  check(await marker.count() === 1, 'the row of EVT_FORCE carries the ERROR marker reaction-missed');
  check((await page.locator('#verdict').getAttribute('class')).includes('fail'), 'the header shows the failure');
  await page.close();
}

try {
  ({ context, userDataDir } = await launchChromium(root));
  await testRobodoc();
  await testReactionMissed();
} catch (e) {
  console.log(`FAILED: ${e.stack ?? e}`);
  failures += 1;
} finally {
  if (context) await context.close();
  if (userDataDir) fs.rmSync(userDataDir, { recursive: true, force: true });
  clearTimeout(deadline);
}
console.log(failures === 0 ? 'analyze browser test passed' : `analyze browser test: ${failures} check(s) failed`);
process.exit(failures === 0 ? 0 : 1);
