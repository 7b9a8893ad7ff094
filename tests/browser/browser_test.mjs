// Browser test of the web pages, in headless Chromium (Debian's /usr/bin/chromium) driven by
// playwright-core (web/package.json):
//   1. `safecass viewer` on robodoc with tests/browser/force_spike.json: CONTROL turns Error when
//      the force crosses 30 N, pushed by the first update after it; clicking it shows the cause
//      (JR3.s_A EVT_FORCE_ERROR, filter force_limit); bad messages and writes without (or with a
//      wrong) token are refused and change nothing; a write with the token is applied.
//   2. `safecass timeline` of the robodoc story: the page draws Normal/Warning/Error bars.
// Screenshots: OUT/viewer.png and OUT/timeline.png.
//
// usage: node browser_test.mjs SAFECASS SOURCE_DIR OUT_DIR

import { spawn, execFileSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';

import { launchChromium, rawExchange } from './chromium.mjs';

const [safecass, root, out] = process.argv.slice(2);
if (!safecass || !root || !out) {
  console.error('usage: node browser_test.mjs SAFECASS SOURCE_DIR OUT_DIR');
  process.exit(2);
}

const kDeadlineMs = 55000;

let viewer = null;        // the child process
let context = null;       // the browser
let userDataDir = '';
let failures = 0;

function check(condition, what) {
  if (condition) {
    console.log(`ok: ${what}`);
  } else {
    console.log(`FAILED: ${what}`);
    failures += 1;
  }
}

async function cleanup() {
  if (context !== null) {
    await context.close().catch(() => {});
    context = null;
  }
  if (viewer !== null && viewer.exitCode === null && viewer.signalCode === null) {
    try { process.kill(viewer.pid, 'SIGTERM'); } catch { /* already gone */ }
  }
  if (userDataDir !== '') fs.rmSync(userDataDir, { recursive: true, force: true });
}

const deadline = setTimeout(async () => {
  console.log(`FAILED: the test did not finish within ${kDeadlineMs / 1000} s`);
  if (viewer !== null) { try { process.kill(viewer.pid, 'SIGKILL'); } catch { /* gone */ } }
  await cleanup();
  process.exit(1);
}, kDeadlineMs);

/** Starts the viewer and resolves with its URL and token file when it has printed them. */
function startViewer() {
  return new Promise((resolve, reject) => {
    viewer = spawn(safecass, ['viewer', '--scenario', 'tests/browser/force_spike.json', '--port', '0',
      '--allow-write', '--speed', '1'], { cwd: root, stdio: ['ignore', 'pipe', 'pipe'] });
    let text = '';
    const timer = setTimeout(() => reject(new Error(`the viewer printed no URL within 15 s:\n${text}`)), 15000);
    const onData = (chunk) => {
      text += chunk.toString();
      const url = /open (http:\/\/127\.0\.0\.1:\d+\/)\n/.exec(text);
      const token = /the token is in (\S+) \(mode 0600\)/.exec(text);
      if (url !== null && token !== null) {
        clearTimeout(timer);
        resolve({ url: url[1], tokenFile: token[1], printed: () => text });
      }
    };
    viewer.stdout.on('data', onData);
    viewer.stderr.on('data', (chunk) => { text += chunk.toString(); });
    viewer.on('exit', (code) => reject(new Error(`the viewer exited (${code}) before serving:\n${text}`)));
  });
}


async function testViewer() {
  const { url, tokenFile, printed } = await startViewer();
  const stat = fs.statSync(tokenFile);
  check((stat.mode & 0o777) === 0o600, `token file ${tokenFile} has mode 0600`);
  const token = fs.readFileSync(tokenFile, 'utf8').trim();
  check(/^[0-9a-f]{64}$/.test(token), 'the token file holds a token');
  check(!printed().includes(token), 'the token itself is never printed (the output lands in logs)');

  const page = await context.newPage();
  const updates = [];
  let hello = null;
  page.on('websocket', (ws) => ws.on('framereceived', (frame) => {
    try {
      const m = JSON.parse(frame.payload);
      if (m.type === 'update') updates.push(m);
      if (m.type === 'hello' && hello === null) hello = m;
    } catch { /* not ours */ }
  }));
  await page.goto(url);
  await page.waitForSelector('#connection.online', { timeout: 10000 });
  check(await page.isHidden('#write-panel') === false, 'the write panel is shown (--allow-write)');

  // The force crosses 25 N (warning) at about t = 4.79 s and 30 N (error) at about t = 4.93 s.
  await page.waitForSelector('.component-name[data-address="JR3"].state-Warning, .component-name[data-address="JR3"].state-Error', { timeout: 10000 });
  await page.waitForSelector('.component-name[data-address="CONTROL"].state-Error', { timeout: 10000 });
  check(await page.getAttribute('[data-address="CONTROL.s_R.ForceData"]', 'data-state') === 'Error',
    'CONTROL.s_R.ForceData is Error');
  check(await page.getAttribute('[data-address="JR3.s_A"]', 'data-state') === 'Error', 'JR3.s_A is Error');
  check(await page.getAttribute('[data-address="SYSTEM"]', 'data-state') === 'Error', 'SYSTEM is Error');

  // The transition is pushed by the first poll that runs the system past it: the update that
  // carries it is the first whose clock is at or after the transition's time. How late that is
  // (the update's clock minus the transition's time) is the poll period plus how late the machine
  // ran the poll: printed, not bounded (a latency is a benchmark's figure, not a test's).
  // A page that connected after the transition got it in its hello (the recent transitions), not
  // pushed: then this check cannot be made, and says so.
  const controlToError = (x) => x.kind === 'component-transition' && x.component === 'CONTROL' && x.to === 'Error';
  const inHello = hello !== null && hello.recent.some(controlToError);
  const carrying = updates.findIndex((u) => u.records.some(controlToError));
  const r = carrying < 0 ? null : updates[carrying].records.find(controlToError);
  const earlier = carrying < 0 ? -1 : updates.slice(0, carrying).findIndex((u) => u.t >= r.t);
  const lag = r === null ? null : updates[carrying].t - r.t;
  check(r !== null && lag >= 0 && earlier < 0,
    `CONTROL's transition to Error pushed by the first update after it (${r !== null
      ? (earlier >= 0 ? `update ${earlier} at t = ${updates[earlier].t} s left it out`
        : `lag ${(lag * 1000).toFixed(1)} ms of simulated time at speed 1`)
      : inHello ? 'not pushed: the page connected after it, which came in the hello'
        : 'not pushed'})`);
  const listed = await page.textContent('#transitions');
  check(/CONTROL/.test(listed) && /Normal → Error/.test(listed), 'the side list shows the transitions');

  // Clicking CONTROL shows its cause chain.
  await page.click('.component-name[data-address="CONTROL"]');
  await page.waitForFunction(() => /EVT_FORCE_ERROR/.test(document.getElementById('cause').textContent), null, { timeout: 5000 });
  const cause = await page.textContent('#cause');
  check(/EVT_SERVICE_FAILURE/.test(cause), 'the cause names the mirrored EVT_SERVICE_FAILURE');
  check(/root cause: EVT_FORCE_ERROR at JR3\.s_A/.test(cause), 'the cause names the root: JR3.s_A EVT_FORCE_ERROR');
  check(/filter force_limit/.test(cause) && /JR3\.ForceNorm = /.test(cause), 'the cause names the filter, signal and value');
  check(/JR3\.s_A → .*CONTROL\.s_R\.ForceData/.test(cause), 'the cause shows the hop path');
  // The graph: every component coloured by its state, and the path of CONTROL's cause lit.
  check(await page.getAttribute('#graph .gnode[data-component="CONTROL"]', 'data-state') === 'Error',
    'the graph shows CONTROL in Error');
  check(await page.getAttribute('#graph .gnode[data-component="BMM"]', 'data-state') === 'Normal',
    'the graph shows BMM Normal');
  await page.waitForSelector('#graph-path[data-hops]', { timeout: 5000 });
  const lit = await page.evaluate(() => [...document.querySelectorAll('#graph .gedge.on-path')].map((e) => `${e.dataset.provided}->${e.dataset.required}`));
  check(lit.join(' ') === 'JR3.ForceData->CONTROL.ForceData', `the graph lights the path of CONTROL's cause (${lit.join(' ')})`);
  // A scenario run in-process: scenario seconds, and no replay controls.
  check(/^t = \d+\.\d{3} s/.test((await page.textContent('#clock')).trim()), 'the clock shows scenario seconds');
  check(await page.isHidden('#replay-bar'), 'no replay controls on a running system');
  fs.mkdirSync(out, { recursive: true });
  await page.screenshot({ path: path.join(out, 'viewer.png'), fullPage: true })
    .catch((e) => console.log(`note: no screenshot (${e.message.split('\n')[0]})`));

  // Bad messages get an error reply.
  const bad = await rawExchange(page, ['not json', '[1]', '{"op":"explode"}', '{"op":"explain"}',
    '{"op":"explain","address":"NOPE.s_A"}', '{"op":"generate","event":"EVT_CONTROL_FORCE_FREEZE","target":"CONTROL.s_A","extra":1}']);
  check(bad.length === 6 && bad.every((m) => m.type === 'error'), 'six bad messages get six error replies');
  check(/not JSON/.test(bad[0].error) && /unknown op/.test(bad[2].error) && /missing key 'address'/.test(bad[3].error),
    `the errors say what is wrong (${bad.map((m) => m.error).join(' | ')})`);

  // Writes: refused without a token and with a wrong one (nothing changes), applied with it.
  const before = await page.getAttribute('[data-address="CONTROL.s_A"]', 'data-state');
  await page.fill('#generate-event', 'EVT_CONTROL_FORCE_FREEZE');
  await page.fill('#generate-target', 'CONTROL.s_A');
  await page.click('#generate-form button');
  await page.waitForSelector('#write-result.error', { timeout: 5000 });
  check(/refused: a write needs the token/.test(await page.textContent('#write-result')), 'a write without the token is refused');
  const wrong = await rawExchange(page, ['{"op":"generate","event":"EVT_CONTROL_FORCE_FREEZE","target":"CONTROL.s_A","token":"0000"}']);
  check(wrong[0].type === 'error' && /refused: wrong token/.test(wrong[0].error), 'a write with a wrong token is refused');
  await page.waitForTimeout(100);
  check(before === 'Normal' && await page.getAttribute('[data-address="CONTROL.s_A"]', 'data-state') === 'Normal',
    'refused writes changed nothing (CONTROL.s_A still Normal)');

  await page.fill('#token', token);
  await page.click('#generate-form button');
  await page.waitForSelector('#write-result.ok', { timeout: 5000 });
  check(/generated EVT_CONTROL_FORCE_FREEZE on CONTROL\.s_A/.test(await page.textContent('#write-result')),
    'a write with the token is accepted');
  await page.waitForSelector('[data-address="CONTROL.s_A"].state-Error', { timeout: 5000 });
  check(/EVT_CONTROL_FORCE_FREEZE/.test(await page.textContent('[data-address="CONTROL.s_A"]')),
    'the generated event shows on CONTROL.s_A');

  // The hazards panel: a shallow injection into the filter that detects excessive force leaves
  // H-3 uncovered, marked with why (`analyze now`).
  check(await page.isVisible('#hazards li.hazard[data-hazard="H-3"]'), 'the hazards panel lists H-3');
  await page.fill('#inject-target', 'force_limit');
  await page.fill('#inject-samples', Array(200).fill('5').join('; '));
  await page.click('#inject-form button');
  await page.waitForSelector('#hazards li.hazard.uncovered[data-hazard="H-3"]', { timeout: 5000 });
  check(/filter force_limit judges injected samples/.test(await page.textContent('#hazards li.hazard[data-hazard="H-3"]')),
    'an uncovered hazard is marked with what leaves it undetected');

  // Stop the viewer by PID: it exits 0 and removes its token file.
  const exited = new Promise((resolve) => viewer.on('exit', (code, signal) => resolve({ code, signal })));
  process.kill(viewer.pid, 'SIGTERM');
  const { code } = await exited;
  check(code === 0, `the viewer stops cleanly on SIGTERM (exit ${code})`);
  check(!fs.existsSync(tokenFile), 'the token file is removed when the viewer stops');
  await page.close();
}

async function testTimeline() {
  const history = path.join(out, 'robodoc-history.jsonl');
  const html = path.join(out, 'timeline.html');
  execFileSync(safecass, ['run', '--scenario', 'examples/robodoc/story.json', '--record', history],
    { cwd: root, stdio: ['ignore', 'ignore', 'inherit'], timeout: 20000 });
  execFileSync(safecass, ['timeline', history, '--html', html], { cwd: root, stdio: 'inherit', timeout: 20000 });
  const page = await context.newPage();
  await page.setViewportSize({ width: 1280, height: 900 });
  await page.goto('file://' + path.resolve(html));
  await page.waitForSelector('rect.bar.state-Error', { timeout: 10000 });
  const count = async (sel) => page.locator(sel).count();
  const errors = await count('rect.bar.state-Error');
  const warnings = await count('rect.bar.state-Warning');
  const normals = await count('rect.bar.state-Normal');
  check(errors >= 5 && warnings >= 1 && normals >= 5, `the timeline draws bars (${normals} Normal, ${warnings} Warning, ${errors} Error)`);
  const labels = await page.locator('text.lane-label').allTextContents();
  check(['JR3.s_A', 'CONTROL.s_R.ForceData', 'BMM.s_A', 'JR3.s_F'].every((l) => labels.some((x) => x.includes(l))),
    'the timeline has a lane for JR3.s_A, CONTROL.s_R.ForceData, BMM.s_A and JR3.s_F');
  check(await count('.marker rect.marker-reset') >= 1, 'the timeline marks the reset of BMM');
  // The page draws the bars of its model: one rectangle per bar, and CONTROL.s_R.ForceData is in
  // Error twice (the force above 30 N, then the stale sensor).
  const model = await page.evaluate(() => JSON.parse(document.getElementById('timeline-model').textContent));
  const lanes = model.groups.flatMap((g) => g.lanes);
  const bars = lanes.reduce((n, lane) => n + lane.bars.length, 0);
  check(bars === normals + warnings + errors, `one drawn bar per bar of the model (${bars})`);
  const forceData = lanes.find((lane) => lane.address === 'CONTROL.s_R.ForceData');
  const states = forceData === undefined ? [] : forceData.bars.map((b) => b.state);
  check(states.join(' ') === 'Normal Error Normal Error Normal', `CONTROL.s_R.ForceData: ${states.join(' ')}`);
  await page.screenshot({ path: path.join(out, 'timeline.png'), fullPage: true })
    .catch((e) => console.log(`note: no screenshot (${e.message.split('\n')[0]})`));
  await page.close();
}

try {
  ({ context, userDataDir } = await launchChromium(root));
  await testViewer();
  await testTimeline();
} catch (e) {
  console.log(`FAILED: ${e.stack ?? e}`);
  failures += 1;
} finally {
  await cleanup();
  clearTimeout(deadline);
}
console.log(failures === 0 ? 'browser test passed' : `browser test: ${failures} check(s) failed`);
process.exit(failures === 0 ? 0 : 1);
