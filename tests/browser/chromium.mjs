// What the browser tests share: Debian's Chromium driven headless by playwright-core (from
// web/node_modules, never a downloaded browser), a fresh profile per run, and a raw WebSocket
// exchange with the viewer from inside its page.

import { createRequire } from 'node:module';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';

export const kChromium = '/usr/bin/chromium';
export const kFlags = ['--headless', '--no-sandbox', '--disable-gpu', '--disable-background-networking',
  '--disable-component-update', '--disable-sync', '--no-first-run'];

/** Starts Chromium with a fresh --user-data-dir; returns the context and the directory to remove. */
export async function launchChromium(sourceDir) {
  const require = createRequire(path.join(sourceDir, 'web', 'package.json'));
  const { chromium } = require('playwright-core');
  const userDataDir = fs.mkdtempSync(path.join(os.tmpdir(), 'safecass-chromium-'));
  const context = await chromium.launchPersistentContext(userDataDir, {
    executablePath: kChromium, headless: true, args: kFlags, viewport: { width: 1280, height: 800 },
  });
  return { context, userDataDir };
}

/** Sends raw messages over a second WebSocket of the page and returns the replies. */
export async function rawExchange(page, messages) {
  return page.evaluate(async (msgs) => {
    const ws = new WebSocket(`ws://${location.host}/ws`);
    const replies = [];
    await new Promise((resolve, reject) => {
      ws.onerror = () => reject(new Error('websocket error'));
      ws.onmessage = (e) => {
        const m = JSON.parse(e.data);
        if (m.type === 'hello') {
          for (const x of msgs) ws.send(x);
          return;
        }
        if (m.type === 'reply' || m.type === 'error') {
          replies.push(m);
          if (replies.length === msgs.length) resolve();
        }
      };
    });
    ws.close();
    return replies;
  }, messages);
}
