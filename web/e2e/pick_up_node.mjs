// End-to-end test of the task editor in a real browser (Debian's Chromium, headless, driven by
// playwright-core): start `costar serve` on the simulated UR5 cell, build the "pick up node"
// plan through clicks alone (Open -> Move above_pick -> Move pick -> Close -> Move above_pick),
// save it, run it, see every node turn green, check from the simulator's true state (a TEST
// ONLY endpoint, on only with --test-endpoints) that the part was lifted, take a screenshot,
// and run the saved plan's XML with `costar run` to show it is the file the CLI runs.
//
//   node web/e2e/pick_up_node.mjs [--costar build/cli/costar] [--artifacts build/test-artifacts]
//                                 [--chromium /usr/bin/chromium] [--docs-screenshot docs/editor.png]

import { spawn, spawnSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../..');
const args = Object.fromEntries(
  process.argv.slice(2).reduce((pairs, arg, i, all) => (arg.startsWith('--') ? [...pairs, [arg.slice(2), all[i + 1]]] : pairs), []),
);
const costar = path.resolve(args.costar ?? path.join(root, 'build/cli/costar'));
const artifacts = path.resolve(args.artifacts ?? path.join(root, 'build/test-artifacts'));
const chromiumPath = args.chromium ?? '/usr/bin/chromium';
fs.mkdirSync(artifacts, { recursive: true });

const work = fs.mkdtempSync(path.join(os.tmpdir(), 'costar-e2e-'));
const waypoints = path.join(work, 'waypoints.json');
fs.copyFileSync(path.join(root, 'examples/ur5/blind_waypoints.json'), waypoints);
const tokenFile = path.join(work, 'token');
const scene = path.join(root, 'sim/scenes/one_node.json');

let server;
let browser;
const log = (...m) => console.log('e2e:', ...m);
function check(condition, message) {
  if (!condition) throw new Error(message);
  log('ok -', message);
}

async function startServer() {
  server = spawn(
    costar,
    ['serve', '--port', '0', '--scene', scene, '--waypoints', waypoints, '--store', path.join(work, 'editor.sqlite'),
      '--token-file', tokenFile, '--web-root', path.join(root, 'web/dist'), '--pace', '2', '--test-endpoints'],
    { stdio: ['ignore', 'pipe', 'pipe'] },
  );
  server.stderr.on('data', (d) => process.stderr.write(`serve: ${d}`));
  const url = await new Promise((resolve, reject) => {
    let text = '';
    const timer = setTimeout(() => reject(new Error('costar serve did not start within 60 s')), 60000);
    server.stdout.on('data', (d) => {
      text += d;
      const match = /listening on (http:\/\/\S+)/.exec(text);
      if (match) {
        clearTimeout(timer);
        resolve(match[1]);
      }
    });
    server.on('exit', (code) => reject(new Error(`costar serve exited with ${code}`)));
  });
  return { url, token: fs.readFileSync(tokenFile, 'utf8').trim() };
}

async function groundTruth(url, token) {
  const response = await fetch(`${url}api/test/ground_truth`, { headers: { Authorization: `Bearer ${token}` } });
  if (!response.ok) throw new Error(`ground truth: ${response.status}`);
  return response.json();
}

async function main() {
  check(fs.existsSync(costar), `the costar executable exists (${costar})`);
  check(fs.existsSync(path.join(root, 'web/dist/index.html')), 'the page is built (web/dist)');
  const { url, token } = await startServer();
  log('server at', url);

  browser = await chromium.launch({
    executablePath: chromiumPath,
    args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
      '--disable-background-networking', '--disable-component-update', '--disable-sync',
      '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
  });
  const context = await browser.newContext({ viewport: { width: 1600, height: 1000 } });
  const page = await context.newPage();
  const pageErrors = [];
  page.on('pageerror', (e) => pageErrors.push(e.message));
  await page.goto(`${url}#token=${token}`);
  await page.waitForSelector('.connection.on', { timeout: 30000 });
  await page.waitForSelector('[data-node-type="Move"].palette-item');
  await page.waitForSelector('tr[data-waypoint="above_pick"]');

  // Build the plan with clicks: the root Sequence is selected in a new plan.
  const pick = (type) => page.click(`.palette-item[data-node-type="${type}"]`);
  const chooseWaypoint = (name) => page.selectOption('#port-waypoint', name);
  await pick('Open');
  await page.click('text=Add child');
  await pick('Move');
  await page.click('text=Add sibling');
  await chooseWaypoint('above_pick');
  await pick('Move');
  await page.click('text=Add sibling');
  await chooseWaypoint('pick');
  await pick('Close');
  await page.click('text=Add sibling');
  await pick('Move');
  await page.click('text=Add sibling');
  await chooseWaypoint('above_pick');
  const types = await page.$$eval('.tree-node', (nodes) => nodes.map((n) => n.getAttribute('data-node-type')));
  check(JSON.stringify(types) === JSON.stringify(['Sequence', 'Open', 'Move', 'Move', 'Close', 'Move']),
    `the tree built by clicks is ${types.join(' > ')}`);

  await page.click('button:text-is("Undo")');
  const undone = await page.$$eval('.tree-node', (nodes) => nodes.length);
  await page.click('button:text-is("Redo")');
  const redone = await page.$$eval('.tree-node', (nodes) => nodes.length);
  check(undone === 6 && redone === 6, 'undo and redo of the last edit (the waypoint choice) keep the tree');
  await page.click('.tree-node[data-node-type="Close"]');
  await page.click('button:text-is("Delete")');
  check((await page.$$eval('.tree-node', (n) => n.length)) === 5, 'delete removes the selected node');
  await page.click('button:text-is("Undo")');
  const restored = await page.$$eval('.tree-node', (nodes) => nodes.map((n) => n.getAttribute('data-node-type')));
  check(restored.join() === 'Sequence,Open,Move,Move,Close,Move', 'undo brings it back in its place');

  await page.fill('input[aria-label="plan name"]', 'pick_up_node');
  await page.click('button:has-text("Save")');
  await page.waitForSelector('text=Saved pick_up_node version 1', { timeout: 15000 });
  check(true, 'saved as pick_up_node version 1');

  const before = await groundTruth(url, token);
  const z0 = before.parts[0].p[2];

  await page.click('button:has-text("Run")');
  // Watch it run: the running node is highlighted, then every node turns green.
  let sawRunning = false;
  const deadline = Date.now() + 180000;
  while (Date.now() < deadline) {
    const states = await page.$$eval('.tree-node', (nodes) =>
      nodes.map((n) => ({ status: n.getAttribute('data-status'), running: n.getAttribute('data-running') })));
    if (states.some((s) => s.running === 'true')) sawRunning = true;
    const result = await page.getAttribute('.run-label', 'data-run-result');
    if (result) break;
    await page.waitForTimeout(100);
  }
  const result = await page.getAttribute('.run-label', 'data-run-result');
  check(result === 'SUCCESS', `the run ended with ${result}`);
  check(sawRunning, 'the running node was highlighted while it ran');
  const statuses = await page.$$eval('.tree-node', (nodes) => nodes.map((n) => n.getAttribute('data-status')));
  check(statuses.every((s) => s === 'SUCCESS'), `every node is green (SUCCESS): ${statuses.join(', ')}`);
  const colour = await page.$eval('.tree-node[data-node-type="Close"]', (n) => getComputedStyle(n).backgroundColor);
  check(colour === 'rgb(207, 238, 215)', `a finished node is drawn green (${colour})`);

  const after = await groundTruth(url, token);
  const z1 = after.parts[0].p[2];
  check(z1 - z0 > 0.08, `the part was lifted in the simulator: z ${z0.toFixed(3)} -> ${z1.toFixed(3)} m`);

  // Replay: pick the run from the run log and scrub through its transitions.
  await page.waitForFunction(() => document.querySelectorAll('select[aria-label="past run"] option').length > 1);
  const runId = await page.$eval('select[aria-label="past run"] option:nth-child(2)', (o) => o.value);
  await page.selectOption('select[aria-label="past run"]', runId);
  await page.waitForSelector('text=replaying run');
  const slider = 'input[aria-label="replay position"]';
  const total = Number(await page.getAttribute(slider, 'max'));
  const statusesAt = async (index) => {
    await page.fill(slider, String(index));
    return page.$$eval('.tree-node', (nodes) => nodes.map((n) => n.getAttribute('data-status')));
  };
  const atStart = await statusesAt(0);
  const atMiddle = await statusesAt(Math.floor(total / 2));
  const atEnd = await statusesAt(total);
  check(total > 10 && atStart.every((s) => s === 'IDLE'), `replay of run #${runId} starts with every node idle (${total} transitions)`);
  check(atMiddle.includes('SUCCESS') && !atMiddle.every((s) => s === 'SUCCESS'), `half way some nodes are done: ${atMiddle.join(', ')}`);
  check(atEnd.every((s) => s === 'SUCCESS'), 'at the end of the replay every node is green');
  await page.click('button:text-is("Back to editing")');

  await page.locator('.tree-node[data-node-type="Move"]').nth(1).click(); // show a Move's parameters
  await page.waitForTimeout(500); // let the 3D view draw the last state
  const shot = path.join(artifacts, 'editor_pick_up_node.png');
  await page.screenshot({ path: shot });
  log('screenshot', shot);
  if (args['docs-screenshot']) fs.copyFileSync(shot, path.resolve(args['docs-screenshot']));

  // The saved plan is the file the CLI runs.
  const xml = await (await fetch(`${url}api/plans/pick_up_node/xml`)).text();
  const file = path.join(work, 'pick_up_node.xml');
  fs.writeFileSync(file, xml);
  fs.copyFileSync(file, path.join(artifacts, 'pick_up_node.xml'));
  const cli = spawnSync(costar, ['run', file, '--scene', scene, '--waypoints', waypoints, '-q'], { encoding: 'utf8' });
  check(cli.status === 0, `costar run on the exported plan succeeds: ${cli.stdout.trim()}`);

  check(pageErrors.length === 0, `no errors in the page${pageErrors.length ? ': ' + pageErrors.join('; ') : ''}`);
}

let failed = false;
try {
  await main();
  log('PASSED');
} catch (error) {
  failed = true;
  console.error('e2e: FAILED -', error.message);
  try {
    const pages = browser?.contexts()[0]?.pages() ?? [];
    if (pages[0]) await pages[0].screenshot({ path: path.join(artifacts, 'editor_failure.png') });
  } catch {
    // no screenshot
  }
} finally {
  await browser?.close();
  server?.kill('SIGTERM');
  fs.rmSync(work, { recursive: true, force: true });
}
process.exit(failed ? 1 : 0);
