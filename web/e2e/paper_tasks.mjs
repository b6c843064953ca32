// End-to-end test: the paper's first two UR5 tasks built by clicks in the editor, every UI action
// counted (the third, the structure assembly, is assemble_by_clicks.mjs), each saved, run in the
// simulated cell and judged from the simulator's true state as `costar trials` judges it:
//   1. pick up a node (examples/ur5/pick_up_node.xml): a node held 5 cm above the table;
//   2. move two nodes from the right to the left (examples/ur5/move_nodes_right_to_left.xml):
//      both rest on the table left of centre.
// Between the two, Reset scene puts the parts back (not counted: it is not part of the task).
// The counts are written to build/test-artifacts/actions_*.txt (docs/EDITOR.md quotes them).
//
//   node web/e2e/paper_tasks.mjs [--costar build/cli/costar] [--artifacts build/test-artifacts]

import fs from 'node:fs';
import path from 'node:path';
import { actionCounter, artifacts, groundTruth, launchBrowser, makeLog, openPage, runScript, shownRunId, startServer, waitForRunEnd } from './lib.mjs';

const { log, check } = makeLog('paper tasks');
const NODE_HALF = 0.025;
let server;
let browser;

async function fresh(page) {
  await page.click('.menu button:text-is("New")');
  await page.waitForFunction(() => document.querySelectorAll('.tree-node').length === 1);
}

async function main() {
  server = await startServer({ scene: 'sim/scenes/assembly.json', pace: 0 });
  const { url, open, token } = server;
  browser = await launchBrowser();
  const errors = [];
  const { page } = await openPage(browser, open, errors);
  page.on('dialog', (d) => d.accept());
  await page.waitForSelector('.palette-item[data-node-type="SmartGrasp"]');

  // --- 1. pick up a node ---------------------------------------------------------------------------
  const pick = actionCounter(page, log);
  await pick.palette('Home');
  await pick.palette('Open');
  await pick.palette('DetectObjects');
  await pick.palette('SmartGrasp');
  await pick.choose('object_class', 'node');
  await pick.palette('MoveRelative');
  await pick.fill('type 150 in the offset\'s z (mm)', '[data-pose-field="z"]', '150');
  const offset = await page.$eval('.tree-node[data-node-type="MoveRelative"] .node-summary', (n) => n.textContent).catch(() => '');
  await pick.fill('type the plan name', 'input[aria-label="plan name"]', 'pick_up_node');
  await pick.click('click Save', '.menu button:has-text("Save")');
  await page.waitForSelector('text=Saved pick_up_node version 1');
  await pick.click('click Run', '.menu button.run');
  const picked = await waitForRunEnd(page);
  check(picked.result === 'SUCCESS', `pick up: ${picked.label}`);
  const xml = await (await fetch(`${url}api/plans/pick_up_node/xml`)).text();
  check(/<MoveRelative offset="0;0;0.15"\/>/.test(xml) && offset === 'offset 0, 0, 150 mm', `the offset entered as z = 150 mm is written 0;0;0.15 (m), and the tree says "${offset}"`);
  const lifted = (await groundTruth(url, token)).parts.filter((p) => p.class === 'node' && p.p[2] > NODE_HALF + 0.05);
  check(lifted.length === 1, `judged as \`costar trials --judge lift\`: ${lifted.map((p) => `${p.name} ${(p.p[2] * 1000 - 25).toFixed(0)} mm above the table`).join(', ')}`);
  check(pick.actions <= 10, `pick up a node took ${pick.actions} UI actions (name, Save and Run included)`);
  fs.writeFileSync(path.join(artifacts, 'actions_pick_up.txt'), `${pick.actions}\n`);

  // --- 2. right to left --------------------------------------------------------------------------------
  await page.click('.menu button:text-is("Reset scene")');
  await page.waitForSelector('text=Scene reset');
  await fresh(page);
  const initial = (await groundTruth(url, token)).parts;
  const r2l = actionCounter(page, log);
  await r2l.palette('Open');
  await r2l.palette('Repeat');
  await r2l.fill('type 2 in num_cycles', '#port-num_cycles', '2');
  await r2l.palette('Sequence');
  await r2l.palette('Home');
  await r2l.palette('DetectObjects');
  await r2l.palette('SmartGrasp');
  await r2l.choose('object_class', 'node');
  await r2l.condition('right_of');
  await r2l.palette('SmartRelease');
  await r2l.choose('target', 'table');
  await r2l.condition('left_of');
  await r2l.clickNode('Repeat', 0);
  await r2l.palette('Home');
  const types = await page.$$eval('.tree-node', (n) => n.map((x) => x.getAttribute('data-node-type')));
  // Listed level by level (the layout's order): the root, its children, the Repeat's Sequence, its children.
  check(types.join(' ') === 'Sequence Open Repeat Home Sequence Home DetectObjects SmartGrasp SmartRelease', `the tree built by clicks, level by level: ${types.join(' · ')}`);
  await r2l.fill('type the plan name', 'input[aria-label="plan name"]', 'move_nodes_right_to_left');
  await r2l.click('click Save', '.menu button:has-text("Save")');
  await page.waitForSelector('text=Saved move_nodes_right_to_left version 1');
  const before = await shownRunId(page);
  await r2l.click('click Run', '.menu button.run');
  const moved = await waitForRunEnd(page, 400, before);
  check(moved.result === 'SUCCESS', `right to left: ${moved.label}`);
  const first = await groundTruth(url, token);
  await page.waitForTimeout(500);
  const second = await groundTruth(url, token);
  const atRest = (p) => Math.hypot(...p.p.map((v, i) => v - first.parts.find((q) => q.name === p.name).p[i])) < 0.002;
  const left = second.parts.filter((p) => {
    const start = initial.find((q) => q.name === p.name);
    return p.class === 'node' && start && start.p[1] < 0 && p.p[1] > 0.02 && Math.abs(p.p[2] - NODE_HALF) < 0.005 && atRest(p);
  });
  check(left.length >= 2, `judged as \`costar trials --judge right_to_left\`: ${left.length} nodes moved from the right to the left (${left.map((p) => p.name).join(', ')})`);
  check(r2l.actions <= 17, `right to left took ${r2l.actions} UI actions (name, Save and Run included)`);
  fs.writeFileSync(path.join(artifacts, 'actions_right_to_left.txt'), `${r2l.actions}\n`);
  check(errors.length === 0, `no errors in the page${errors.length ? ': ' + errors.join('; ') : ''}`);
}

await runScript('paper tasks', main, { log, artifacts, shot: 'paper_tasks_failure.png', resources: () => ({ browser, server }) });
