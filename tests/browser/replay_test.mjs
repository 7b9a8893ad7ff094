// Browser test of `safecass viewer --replay`, in headless Chromium (Debian's /usr/bin/chromium)
// driven by playwright-core (web/package.json):
//   1. a bad log: the viewer says file:line and the reason, and serves nothing (exit 2);
//   2. the robodoc story is run and recorded (history + inputs); the viewer replays the inputs
//      through robodoc; the page's graph has one node per component and one edge per connection;
//      scrubbing the slider to a time (forwards and backwards) shows, for every state on the page,
//      the state the recorded history has at that time; "Next transition" stops at the history's
//      next transition; play moves the clock and pause stops it;
//   3. selecting SERVO while the force fault holds highlights the hop path of its cause in the
//      graph: the hops the read model's explain gives, JR3 → CONTROL → SERVO over ForceData and
//      Command.
// Screenshot: OUT/viewer-replay.png.
//
// usage: node replay_test.mjs SAFECASS SOURCE_DIR OUT_DIR

import { spawn, spawnSync, execFileSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';

import { launchChromium, rawExchange } from './chromium.mjs';

const [safecass, root, out] = process.argv.slice(2);
if (!safecass || !root || !out) {
  console.error('usage: node replay_test.mjs SAFECASS SOURCE_DIR OUT_DIR');
  process.exit(2);
}

const kDeadlineMs = 80000;

let viewer = null;
let context = null;
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

/** The history file's records. */
function readHistory(file) {
  return fs.readFileSync(file, 'utf8').split('\n').filter((l) => l.trim() !== '').map((l) => JSON.parse(l));
}

/** Every machine's and component's state at time t by the history: Normal, then each transition's "to". */
function statesAt(history, t) {
  const states = new Map();
  for (const r of history) {
    if (r.t > t + 1e-9) continue;
    if (r.kind === 'transition') states.set(r.machine, r.to);
    if (r.kind === 'component-transition') states.set(r.component, r.to);
  }
  return states;
}

function startViewer(args) {
  return new Promise((resolve, reject) => {
    viewer = spawn(safecass, ['viewer', ...args, '--port', '0'], { cwd: root, stdio: ['ignore', 'pipe', 'pipe'] });
    let text = '';
    const timer = setTimeout(() => reject(new Error(`the viewer printed no URL within 15 s:\n${text}`)), 15000);
    viewer.stdout.on('data', (chunk) => {
      text += chunk.toString();
      const url = /open (http:\/\/127\.0\.0\.1:\d+\/)\n/.exec(text);
      if (url !== null) {
        clearTimeout(timer);
        resolve({ url: url[1], printed: () => text });
      }
    });
    viewer.stderr.on('data', (chunk) => { text += chunk.toString(); });
    viewer.on('exit', (code) => reject(new Error(`the viewer exited (${code}) before serving:\n${text}`)));
  });
}

function testBadLog() {
  const r = spawnSync(safecass, ['viewer', '--replay', 'tests/data/replay/non_monotonic.csv', '--system',
    'tests/data/replay/arm.json', '--port', '0'], { cwd: root, encoding: 'utf8', timeout: 20000 });
  check(r.status === 2, `a bad log: the viewer exits 2 (exit ${r.status})`);
  check(/non_monotonic\.csv:4: time 0\.001 s is before the previous row's 0\.002 s/.test(r.stderr),
    `a bad log: file:line and the reason (${r.stderr.trim()})`);
  check(!/open http/.test(r.stdout), 'a bad log: nothing is served');
  const w = spawnSync(safecass, ['viewer', '--replay', 'tests/data/replay/arm_ok.csv', '--system',
    'tests/data/replay/arm.json', '--port', '0', '--allow-write'], { cwd: root, encoding: 'utf8', timeout: 20000 });
  check(w.status === 2 && /read-only/.test(w.stderr), `a replay refuses --allow-write (${w.stderr.trim()})`);
}

/** The state of every machine and component the page shows (the model's state chips). */
async function pageStates(page) {
  return page.evaluate(() => {
    const out = {};
    for (const el of document.querySelectorAll('#model .state[data-address]')) {
      const a = el.dataset.address;
      if (a.startsWith('coordinator:') || a.includes('.s_S.')) continue;  // derived, no records of their own
      out[a] = el.dataset.state;
    }
    return out;
  });
}

/** Moves the slider to t as a person does (input, then change) and waits until the replay is there. */
async function scrubTo(page, t) {
  await page.evaluate((time) => {
    const slider = document.getElementById('replay-slider');
    slider.value = String(time);
    slider.dispatchEvent(new Event('input', { bubbles: true }));
    slider.dispatchEvent(new Event('change', { bubbles: true }));
  }, t);
  await page.waitForFunction((time) => {
    const bar = document.getElementById('replay-bar');
    const now = Number(bar.dataset.t);
    return bar.dataset.busy === '' && now <= time + 1e-9 && now > time - 0.001 - 1e-9;
  }, t, { timeout: 10000 });
  return page.evaluate(() => Number(document.getElementById('replay-bar').dataset.t));
}

async function testReplay() {
  fs.mkdirSync(out, { recursive: true });
  const historyFile = path.join(out, 'replay-story.jsonl');
  execFileSync(safecass, ['run', '--scenario', 'examples/robodoc/story.json', '--record', historyFile],
    { cwd: root, stdio: ['ignore', 'ignore', 'inherit'], timeout: 20000 });
  const inputs = historyFile.replace(/\.jsonl$/, '.inputs');
  check(fs.existsSync(inputs), `the run recorded its inputs next to its history (${inputs})`);
  const history = readHistory(historyFile);
  const transitions = [...new Set(history.filter((r) => r.kind === 'transition' || r.kind === 'component-transition').map((r) => r.t))];

  const { url, printed } = await startViewer(['--replay', inputs, '--system', 'examples/robodoc/robodoc.json']);
  check(/read-only: a replay/.test(printed()), 'the viewer says a replay is read-only');
  const page = await context.newPage();
  await page.goto(url);
  await page.waitForSelector('#connection.online', { timeout: 10000 });
  await page.waitForSelector('#replay-bar:not([hidden])', { timeout: 10000 });
  check(await page.isHidden('#write-panel'), 'no write panel in a replay');

  // The graph: one node per component, one edge per connection of robodoc.json, laid out by dagre.
  // (The system file may hold // comment lines, which the spec loader accepts.)
  const systemText = fs.readFileSync(path.join(root, 'examples/robodoc/robodoc.json'), 'utf8');
  const system = JSON.parse(systemText.split('\n').filter((l) => !/^\s*\/\//.test(l)).join('\n'));
  const nodes = await page.locator('#graph .gnode').count();
  const edges = await page.locator('#graph .gedge').count();
  check(nodes === system.components.length, `the graph has a node per component (${nodes})`);
  check(edges === system.connections.length, `the graph has an edge per connection (${edges})`);
  const boxes = await page.evaluate(() => [...document.querySelectorAll('#graph .gnode')].map((g) => g.getAttribute('transform')));
  check(new Set(boxes).size === boxes.length, 'the layout puts every node in its own place');

  // Scrubbing: at, between and after transitions, forwards then backwards.
  const mid = transitions[Math.floor(transitions.length / 2)];
  const targets = [transitions[0], transitions[1] + 0.0004, mid, transitions[transitions.length - 1], 1.999,
    transitions[2], 0.0004, mid + 0.0003];
  let compared = 0;
  let mismatches = [];
  for (const t of targets) {
    const at = await scrubTo(page, t);
    const expected = statesAt(history, at);
    const shown = await pageStates(page);
    for (const [address, state] of Object.entries(shown)) {
      const want = expected.get(address) ?? 'Normal';
      compared += 1;
      if (state !== want) mismatches.push(`${address} at t=${at}: page ${state}, history ${want}`);
    }
    for (const address of expected.keys()) {
      if (!(address in shown)) mismatches.push(`${address} at t=${at}: not on the page`);
    }
    const graphShown = await page.evaluate(() => Object.fromEntries([...document.querySelectorAll('#graph .gnode')].map((g) => [g.dataset.component, g.dataset.state])));
    for (const [component, state] of Object.entries(graphShown)) {
      if (state !== (expected.get(component) ?? 'Normal')) mismatches.push(`graph node ${component} at t=${at}: ${state}`);
    }
  }
  check(mismatches.length === 0 && compared > 100,
    `scrubbed to ${targets.length} times: the page's ${compared} states equal the history's${mismatches.length ? ': ' + mismatches.slice(0, 5).join('; ') : ''}`);

  // Next transition: from the start, each click stops at the history's next transition time.
  await scrubTo(page, 0);
  let nextOk = true;
  for (const expected of transitions.filter((t) => t > 0).slice(0, 4)) {
    await page.click('#replay-next');
    await page.waitForFunction((time) => {
      const bar = document.getElementById('replay-bar');
      return bar.dataset.busy === '' && Math.abs(Number(bar.dataset.t) - time) < 1e-6;
    }, expected, { timeout: 10000 }).catch(() => { nextOk = false; });
  }
  check(nextOk, `"Next transition" stops at the history's transitions (${transitions.slice(1, 5).join(', ')})`);

  // Play and pause.
  const before = await page.evaluate(() => Number(document.getElementById('replay-bar').dataset.t));
  await page.selectOption('#replay-speed', '0.5');
  await page.click('#replay-play');
  await page.waitForSelector('#replay-bar[data-playing="true"]', { timeout: 5000 });
  await page.waitForTimeout(400);
  await page.click('#replay-play');
  await page.waitForSelector('#replay-bar[data-playing="false"]', { timeout: 5000 });
  const paused = await page.evaluate(() => Number(document.getElementById('replay-bar').dataset.t));
  await page.waitForTimeout(300);
  const later = await page.evaluate(() => Number(document.getElementById('replay-bar').dataset.t));
  check(paused > before && later === paused, `play moves the replay (${before} → ${paused} s) and pause holds it (${later} s)`);

  // The force fault: the first time SERVO is in Error, select it; the graph highlights its path.
  const servoError = history.find((r) => r.kind === 'component-transition' && r.component === 'SERVO' && r.to === 'Error');
  check(servoError !== undefined, 'the history has SERVO in Error');
  await scrubTo(page, servoError.t);
  await page.click('#graph .gnode[data-component="SERVO"]');
  await page.waitForSelector('#graph-path[data-hops]', { timeout: 5000 });
  const hops = JSON.parse(await page.getAttribute('#graph-path', 'data-hops'));
  const [explained] = await rawExchange(page, ['{"op":"explain","address":"SERVO"}']);
  const outstanding = (explained.conditions ?? []).find((c) => c.outstanding) ?? (explained.conditions ?? [])[0];
  check(outstanding !== undefined && JSON.stringify(hops) === JSON.stringify(outstanding.path),
    `the highlighted path is the read model's hop path of SERVO's cause (${hops.join(' -> ')})`);
  check(outstanding !== undefined && outstanding.root_event === 'EVT_FORCE_ERROR' && outstanding.root_origin === 'JR3.s_A',
    'its root is the force fault: JR3.s_A EVT_FORCE_ERROR');
  check(JSON.stringify(hops) === JSON.stringify(['JR3.s_A', 'JR3.s_S.ForceData', 'CONTROL.s_R.ForceData', 'CONTROL.s_S.Command', 'SERVO.s_R.Command']),
    'the hops are JR3.s_A -> JR3.s_S.ForceData -> CONTROL.s_R.ForceData -> CONTROL.s_S.Command -> SERVO.s_R.Command');
  const lit = await page.evaluate(() => ({
    nodes: [...document.querySelectorAll('#graph .gnode.on-path')].map((g) => g.dataset.component).sort(),
    edges: [...document.querySelectorAll('#graph .gedge.on-path')].map((e) => `${e.dataset.provided}->${e.dataset.required}`).sort(),
  }));
  check(JSON.stringify(lit.nodes) === JSON.stringify(['CONTROL', 'JR3', 'SERVO']), `highlighted nodes: ${lit.nodes.join(', ')}`);
  check(JSON.stringify(lit.edges) === JSON.stringify(['CONTROL.Command->SERVO.Command', 'JR3.ForceData->CONTROL.ForceData']),
    `highlighted edges: ${lit.edges.join(', ')}`);
  check(/JR3\.s_A → JR3\.s_S\.ForceData → CONTROL\.s_R\.ForceData → CONTROL\.s_S\.Command → SERVO\.s_R\.Command/.test(await page.textContent('#graph-path')),
    'the page names the hops under the graph');
  check(/^t = \d+\.\d{3} s$/.test((await page.textContent('#clock')).trim()), 'a replay shows scenario seconds');
  await page.screenshot({ path: path.join(out, 'viewer-replay.png'), fullPage: true })
    .catch((e) => console.log(`note: no screenshot (${e.message.split('\n')[0]})`));

  // A replay is read-only: writes are refused whatever they carry.
  const [write] = await rawExchange(page, ['{"op":"generate","event":"EVT_CONTROL_FORCE_FREEZE","target":"CONTROL.s_A","token":"x"}']);
  check(write.type === 'error' && /read-only/.test(write.error), `a write to a replay is refused (${write.error})`);

  const exited = new Promise((resolve) => viewer.on('exit', (code) => resolve(code)));
  process.kill(viewer.pid, 'SIGTERM');
  check(await exited === 0, 'the viewer stops cleanly on SIGTERM');
  await page.close();
}

try {
  testBadLog();
  ({ context, userDataDir } = await launchChromium(root));
  await testReplay();
} catch (e) {
  console.log(`FAILED: ${e.stack ?? e}`);
  failures += 1;
} finally {
  await cleanup();
  clearTimeout(deadline);
}
console.log(failures === 0 ? 'replay browser test passed' : `replay browser test: ${failures} check(s) failed`);
process.exit(failures === 0 ? 0 : 1);
