// What the editor's end-to-end tests share: starting `costar serve` on a simulated cell (its
// token in a private file, a store, a waypoint file and a state folder of its own), Debian's Chromium driven by
// playwright-core, checks that log what they proved, counting UI actions, the simulator's true
// state (a TEST ONLY endpoint), and the readability check at a screen size.

import { spawn } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

export const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../..');

/** --name value pairs of the command line. */
export function parseArgs(argv = process.argv.slice(2)) {
  return Object.fromEntries(argv.reduce((pairs, arg, i, all) => (arg.startsWith('--') ? [...pairs, [arg.slice(2), all[i + 1]]] : pairs), []));
}

export const args = parseArgs();
export const costar = path.resolve(args.costar ?? path.join(root, 'build/cli/costar'));
export const artifacts = path.resolve(args.artifacts ?? path.join(root, 'build/test-artifacts'));
export const chromiumPath = args.chromium ?? '/usr/bin/chromium';
fs.mkdirSync(artifacts, { recursive: true });

export function makeLog(name) {
  const log = (...m) => console.log(`${name}:`, ...m);
  const check = (condition, message) => {
    if (!condition) throw new Error(message);
    log('ok -', message);
  };
  return { log, check };
}

/**
 * Starts `costar serve` in a fresh folder: resolves with its URL, the address it prints (with
 * the token), the token, and a stop function.
 */
export async function startServer({ workcell = 'ur5-sim', scene, waypoints, pace = 1, extra = [] } = {}) {
  const work = fs.mkdtempSync(path.join(os.tmpdir(), 'costar-e2e-'));
  const waypointFile = path.join(work, 'waypoints.json');
  if (waypoints) fs.copyFileSync(path.join(root, waypoints), waypointFile);
  const tokenFile = path.join(work, 'token');
  const argv = ['serve', '--workcell', workcell, '--port', '0', '--waypoints', waypointFile, '--store', path.join(work, 'editor.sqlite'),
    '--token-file', tokenFile, '--web-root', path.join(root, 'web/dist'), '--pace', String(pace), '--test-endpoints', ...extra];
  if (scene) argv.push('--scene', path.join(root, scene));
  // Its own state folder too: the grasps TeachGrasp saves go there, not into the user's.
  const server = spawn(costar, argv, { stdio: ['ignore', 'pipe', 'pipe'], env: { ...process.env, XDG_STATE_HOME: path.join(work, 'state') } });
  server.stderr.on('data', (d) => process.stderr.write(`serve: ${d}`));
  const started = await new Promise((resolve, reject) => {
    let text = '';
    const timer = setTimeout(() => reject(new Error('costar serve did not start within 90 s')), 90000);
    server.stdout.on('data', (d) => {
      text += d;
      const listening = /listening on (http:\/\/\S+)/.exec(text);
      if (listening) {
        clearTimeout(timer);
        resolve({ url: listening[1], open: /open the editor at (\S+)/.exec(text)?.[1] ?? '' });
      }
    });
    server.on('exit', (code) => reject(new Error(`costar serve exited with ${code}`)));
  });
  const token = fs.readFileSync(tokenFile, 'utf8').trim();
  return {
    ...started,
    token,
    work,
    waypointFile,
    stop: () => {
      server.kill('SIGTERM');
      fs.rmSync(work, { recursive: true, force: true });
    },
  };
}

export async function launchBrowser() {
  return chromium.launch({
    executablePath: chromiumPath,
    args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
      '--disable-background-networking', '--disable-component-update', '--disable-sync',
      '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
  });
}

/** A page of a new browser context at this size, its errors collected in `errors`. */
export async function openPage(browser, address, errors, viewport = { width: 1600, height: 1000 }) {
  const context = await browser.newContext({ viewport });
  const page = await context.newPage();
  page.on('pageerror', (e) => errors.push(e.message));
  await page.goto(address);
  await page.waitForSelector('.connection.on', { timeout: 30000 });
  return { context, page };
}

/** Counts every UI action a task takes. */
export function actionCounter(page, log) {
  const counter = { actions: 0 };
  counter.act = async (what, fn) => {
    counter.actions += 1;
    await fn();
    log(`action ${counter.actions}: ${what}`);
  };
  counter.palette = (type) => counter.act(`click ${type} in the operations`, () => page.click(`.palette-item[data-node-type="${type}"]`));
  counter.choose = (port, value) => counter.act(`choose ${port} = ${value}`, () => page.selectOption(`#port-${port}`, value));
  counter.condition = (name) => counter.act(`add condition ${name}(part, …)`, () => page.selectOption('select[aria-label="add condition"]', name));
  counter.node = (type, n) => page.locator(`.tree-node[data-node-type="${type}"]`).nth(n);
  counter.clickNode = (type, n, modifiers) =>
    counter.act(`${modifiers ? 'shift+' : ''}click ${type} #${n + 1} in the tree`, () => counter.node(type, n).click({ modifiers }));
  counter.key = (combo) => counter.act(`press ${combo}`, () => page.keyboard.press(combo));
  counter.fill = (what, selector, value) => counter.act(what, () => page.fill(selector, value));
  counter.click = (what, selector) => counter.act(what, () => page.click(selector));
  // The tree pans to keep the selected node in view: a drag waits until its target stands still.
  counter.still = async (selector) => {
    let last = '';
    for (let i = 0; i < 50; i += 1) {
      const box = JSON.stringify(await page.locator(selector).boundingBox());
      if (box === last) return box;
      last = box;
      await page.waitForTimeout(100);
    }
    return last;
  };
  /**
   * Drags a palette item onto a tree box's leading ('before') or trailing ('after') edge. The
   * point is a fraction of the box as drawn: the tree zooms out below 1 on a large plan, and a
   * point in pixels of the unzoomed box lands on the box below it (inside its parent).
   */
  counter.dropOnEdge = async (type, selector, edge, what) => {
    const { height } = JSON.parse(await counter.still(selector));
    const y = edge === 'before' ? Math.max(1, height * 0.1) : Math.min(height - 1, height * 0.9);
    await counter.act(what, () => page.dragAndDrop(`.palette-item[data-node-type="${type}"]`, selector, { targetPosition: { x: 40, y } }));
  };
  return counter;
}

export async function groundTruth(url, token) {
  const response = await fetch(`${url}api/test/ground_truth`, { headers: { Authorization: `Bearer ${token}` } });
  if (!response.ok) throw new Error(`ground truth: ${response.status}`);
  return response.json();
}

export async function api(url, token, method, pathname, body) {
  const response = await fetch(`${url}${pathname.replace(/^\//, '')}`, {
    method,
    headers: { Authorization: `Bearer ${token}`, ...(body ? { 'Content-Type': 'application/json' } : {}) },
    body: body ? JSON.stringify(body) : undefined,
  });
  const text = await response.text();
  return { status: response.status, json: text ? JSON.parse(text) : null };
}

/** The run the page's status line names (0: none yet). */
export async function shownRunId(page) {
  return Number(/^(?:Run|Last run:) #(\d+)/.exec((await page.textContent('.run-label')) ?? '')?.[1] ?? 0);
}

/**
 * Waits until the page's run label says a run after `after` (a run id) ended; returns its
 * result and text (a result shown before the new run's start reached the page is not it).
 */
export async function waitForRunEnd(page, seconds = 240, after = 0) {
  const deadline = Date.now() + seconds * 1000;
  let sawRunning = false;
  while (Date.now() < deadline) {
    if (await page.$('.tree-node[data-running="true"]')) sawRunning = true;
    // The result and the run it belongs to read at once: read apart, a new run's id could be
    // paired with the result the label still showed for the run before it.
    const shown = await page.evaluate(() => {
      const label = document.querySelector('.run-label');
      return { result: label?.getAttribute('data-run-result') ?? '', text: label?.textContent ?? '' };
    });
    const id = Number(/^(?:Run|Last run:) #(\d+)/.exec(shown.text)?.[1] ?? 0);
    if (shown.result && id > after) return { result: shown.result, label: shown.text, sawRunning };
    await page.waitForTimeout(100);
  }
  return { result: '', label: await page.textContent('.run-label'), sawRunning };
}

/**
 * The readability check (run in the page): the smallest text drawn in the tree pane (font size
 * times the canvas zoom, px), and every element that overflows its pane or clips its text
 * (a scrolling list or the tree's canvas may hold more than shows: that is not overflow).
 */
export function readability() {
  const viewport = document.querySelector('.react-flow__viewport');
  const zoom = Number(/scale\(([\d.]+)\)/.exec(viewport?.style.transform ?? '')?.[1] ?? 1);
  let smallest = Infinity;
  let smallestWhat = '';
  for (const element of document.querySelectorAll('.tree-node *')) {
    if (!element.childNodes.length || ![...element.childNodes].some((n) => n.nodeType === 3 && n.textContent.trim())) continue;
    const size = parseFloat(getComputedStyle(element).fontSize) * zoom;
    if (size < smallest) {
      smallest = size;
      smallestWhat = `${element.className}: ${element.textContent.trim().slice(0, 30)}`;
    }
  }
  const problems = [];
  // Inside a list that scrolls up and down, or the tree's canvas (a pan area): more than shows
  // is not overflow. A pane that scrolls sideways is (nothing is meant to be wider than its pane).
  const scrolls = (element) => {
    for (let e = element.parentElement; e; e = e.parentElement) {
      if (e.classList.contains('react-flow')) return true;
      const style = getComputedStyle(e);
      if (/(auto|scroll)/.test(style.overflowY) && e.scrollHeight > e.clientHeight + 1 && e.scrollWidth <= e.clientWidth + 1) return true;
    }
    return false;
  };
  for (const pane of document.querySelectorAll('.pane, .menu, .status-line')) {
    const box = pane.getBoundingClientRect();
    if (pane.scrollWidth > pane.clientWidth + 1) problems.push(`${pane.className.split(' ')[0] || pane.tagName} is wider than itself: it scrolls sideways`);
    for (const element of pane.querySelectorAll('*')) {
      const style = getComputedStyle(element);
      if (style.display === 'none' || style.visibility === 'hidden' || element.closest('option, .react-flow__minimap, .react-flow__controls')) continue;
      // The content of a folded <details> is not shown (Chromium still lays it out).
      const folded = element.closest('details:not([open])');
      if (folded && folded !== element && !element.closest('summary')) continue;
      const b = element.getBoundingClientRect();
      if (b.width === 0 || b.height === 0) continue;
      const name = `${element.tagName.toLowerCase()}.${String(element.className).split(' ')[0]} "${(element.textContent ?? '').trim().slice(0, 30)}"`;
      if (!scrolls(element) && (b.left < box.left - 1 || b.right > box.right + 1 || b.top < box.top - 1 || b.bottom > box.bottom + 1)) {
        problems.push(`${name} overflows its pane (${pane.className.split(' ')[0] || pane.tagName})`);
      }
      // Text cut by its own box (ellipsis or hidden overflow), but not in the tree's canvas (a
      // pan area whose boxes end long parameters in an ellipsis, shown whole in their tooltip
      // and pane 5) nor in a field (its text scrolls as it is typed).
      const field = ['INPUT', 'SELECT', 'TEXTAREA'].includes(element.tagName);
      if (!field && !element.closest('.react-flow') && element.scrollWidth > element.clientWidth + 1 && /(hidden|clip)/.test(style.overflowX) && element.clientWidth > 0) {
        problems.push(`${name} clips its text`);
      }
    }
  }
  return { smallest, smallestWhat, zoom, problems };
}

/**
 * Runs an end-to-end script's `main` and ends the process: PASSED, or FAILED with the reason
 * and a screenshot of the first page open (`shot`, in `artifacts`); the browser and the server
 * that `resources()` returns are closed either way.
 */
export async function runScript(label, main, { log, artifacts, shot, resources }) {
  let failed = false;
  try {
    await main();
    log('PASSED');
  } catch (error) {
    failed = true;
    console.error(`${label}: FAILED -`, error.message);
    try {
      const pages = resources().browser?.contexts().flatMap((c) => c.pages()) ?? [];
      if (pages[0]) await pages[0].screenshot({ path: path.join(artifacts, shot) });
    } catch {
      // no screenshot
    }
  } finally {
    const { browser, server } = resources();
    await browser?.close();
    server?.stop();
  }
  process.exit(failed ? 1 : 0);
}
