// End-to-end test of the editor with a person in the cell (docs/PERSON.md) on the iiwa with the
// 3-finger gripper (iiwa-3f-sim, sim/scenes/collaborative_assembly.json, the person of seed 10012:
// takes both nodes): the paper's collaborative assembly (examples/iiwa/collaborative_assembly.xml)
// loaded as a stored plan, opened from the Plans dialog, its gesture and hand-over nodes checked
// against what the palette offers, run on the simulator and judged from its true state as
// `costar trials --judge collaborative_assembly` judges it (every node from the right is the
// person's or in the assembly area, none elsewhere; no separation violation, no contact with the
// person outside the hand). While it runs, the speed and separation monitor's reading is watched
// on every change the 3D view renders: the separation, the protective distance and the speed
// scale, and collaborative mode while the plan asks for it; the 3D view draws the person's hand
// where the camera sees it.
//
//   node web/e2e/collaborative_assembly.mjs [--costar build/cli/costar] [--artifacts build/test-artifacts]

import fs from 'node:fs';
import path from 'node:path';
import { api, artifacts, costar, groundTruth, launchBrowser, makeLog, openPage, root, runScript, startServer, waitForRunEnd } from './lib.mjs';

const NODE_HALF = 0.025;
const { log, check } = makeLog('collaborative');
let server;
let browser;

async function main() {
  check(fs.existsSync(costar), `the costar executable exists (${costar})`);
  check(fs.existsSync(path.join(root, 'web/dist/index.html')), 'the page is built (web/dist)');
  server = await startServer({ workcell: 'iiwa-3f-sim', scene: 'sim/scenes/collaborative_assembly.json', pace: 0, extra: ['--seed', '10012'] });
  const { url, open, token } = server;
  const xml = fs.readFileSync(path.join(root, 'examples/iiwa/collaborative_assembly.xml'), 'utf8');
  check((await api(url, token, 'PUT', '/api/plans/collaborative_assembly', { xml })).status === 201, 'examples/iiwa/collaborative_assembly.xml is stored as the plan collaborative_assembly, version 1');
  const initial = await groundTruth(url, token);
  const inputNodes = initial.parts.filter((p) => p.class === 'node' && p.p[1] < 0);
  check(inputNodes.length === 2, `two nodes lie in the input area (right of centre): ${inputNodes.map((p) => p.name).join(', ')}`);

  browser = await launchBrowser();
  const errors = [];
  const { page } = await openPage(browser, open, errors);
  await page.waitForSelector('.palette-item[data-node-type="Collaborate"]');
  const offered = await page.$$eval('.palette-item', (items) => items.map((i) => i.getAttribute('data-node-type')));
  check(['Collaborate', 'SmartGrasp', 'SmartRelease', 'Timeout', 'RetryUntilSuccessful', 'CheckPredicate'].every((id) => offered.includes(id)), 'the palette offers Collaborate and every node the plan is built of');

  // Before the run: the person stands by the table; the strip over the 3D view shows the monitor.
  await page.waitForSelector('.safety-strip', { timeout: 30000 });
  const before = await page.textContent('.safety-strip');
  check(/^person \d+ cm away, protective distance \d+ cm, speed \d+ %/.test(before), `the 3D view shows the separation and the speed scale: "${before}"`);

  await page.click('button:text-is("Plans…")');
  await page.click('.plan-list button[data-plan="collaborative_assembly"]');
  await page.click('tr[data-version="1"] button:text-is("Open")');
  await page.waitForSelector('.tree-node[data-node-type="Collaborate"]');
  check((await page.inputValue('input[aria-label="plan name"]')) === 'collaborative_assembly', 'the Plans dialog opens the plan');
  await page.click('.tree-node[data-node-type="CheckPredicate"] >> nth=0');
  const predicates = await page.$$eval('#port-predicate option', (o) => o.map((x) => x.value));
  check(['gesture', 'in_zone'].every((p) => predicates.includes(p)) && (await page.inputValue('#port-predicate')) === 'gesture', `CheckPredicate offers gesture and in_zone, and shows the plan's gesture (${predicates.length} predicates)`);
  const words = async (n) => page.$$eval(`#port-args-${n} option`, (o) => o.map((x) => x.value).filter((v) => v !== ''));
  const gestureWords = await words(1);
  check(gestureWords.join() === 'offer' && (await page.inputValue('#port-args-1')) === 'offer', `gesture's second argument is chosen from the words it takes: ${gestureWords.join(', ')}`);
  await page.click('.tree-node[data-node-type="CheckPredicate"] >> nth=1');
  const zones = await words(1);
  check(zones.includes('handover') && (await page.inputValue('#port-args-1')) === 'handover' && (await page.$$('.unknown-choice')).length === 0, `in_zone's zone is chosen from the hand component's zones: ${zones.join(', ')}`);
  await page.screenshot({ path: path.join(artifacts, 'collaborative_opened_1600x1000.png') });

  // Every change of the strip is recorded (the simulation runs faster than real time).
  await page.evaluate(() => {
    window.safetySeen = { states: {}, minScale: 100, maxScale: 0, minSeparation: Infinity, collaborativeText: null, handDrawn: null };
    const record = () => {
      const strip = document.querySelector('.safety-strip');
      if (!strip) return;
      const seen = window.safetySeen;
      const state = strip.getAttribute('data-state');
      const scale = Number(strip.getAttribute('data-speed-scale'));
      seen.states[state] = (seen.states[state] ?? 0) + 1;
      seen.minScale = Math.min(seen.minScale, scale);
      seen.maxScale = Math.max(seen.maxScale, scale);
      seen.minSeparation = Math.min(seen.minSeparation, Number(strip.getAttribute('data-separation')));
      if (state === 'collaborative' && !seen.collaborativeText) seen.collaborativeText = strip.textContent;
      const hand = document.querySelector('.view3d-canvas')?.getAttribute('data-hand');
      if (hand) seen.handDrawn = hand;
    };
    new MutationObserver(record).observe(document.body, { subtree: true, childList: true, attributes: true, characterData: true });
  });
  await page.click('button.run');
  await page.waitForSelector('.run-label:text-matches("^Run #1")', { timeout: 30000 }).catch(async () => {
    throw new Error(`the run did not start: ${await page.textContent('.status-line')}`);
  });
  // A screenshot while the arm works beside the person in collaborative mode.
  await page.waitForSelector('.safety-strip[data-state="collaborative"]', { timeout: 60000 }).catch(() => {});
  await page.waitForSelector('.tree-node[data-node-type="SmartRelease"][data-running="true"]', { timeout: 240000 }).catch(() => {});
  await page.screenshot({ path: path.join(artifacts, 'collaborative_running_1600x1000.png') });

  const { result, label } = await waitForRunEnd(page, 600);
  check(result === 'SUCCESS', `the run ended with ${result}: ${label}`);
  const seen = await page.evaluate(() => window.safetySeen);
  log(`the strip while it ran: ${JSON.stringify(seen)}`);
  check(seen.collaborativeText !== null && /hand-over mode: at most 0.2 m\/s/.test(seen.collaborativeText), `the strip shows collaborative mode while the plan asks for it: "${seen.collaborativeText}"`);
  check(Number.isFinite(seen.minSeparation) && seen.minSeparation < 0.3, `the separation fell to ${(seen.minSeparation * 100).toFixed(0)} cm (below 0: the monitor's enclosing capsules overlap) as the node was handed over`);
  check(seen.handDrawn !== null, `the 3D view drew the person's hand where the camera saw it (at ${seen.handDrawn})`);
  await page.waitForSelector('.safety-strip:not([data-state="collaborative"])', { timeout: 30000 });
  check(true, `after Collaborate on=false the strip leaves collaborative mode: "${await page.textContent('.safety-strip')}"`);

  // Judged from the simulator's true state, as the trials' judge does.
  const truth = await groundTruth(url, token);
  const placed = [];
  const handed = [];
  for (const start of inputNodes) {
    const node = truth.parts.find((p) => p.name === start.name);
    const onTableLeft = node.p[1] > 0 && Math.abs(node.p[2] - NODE_HALF) < 0.005 && node.p[0] > -0.3 && node.p[0] < 1.1 && node.p[1] < 0.6;
    const offTheTable = node.p[2] > NODE_HALF + 0.02 || node.p[1] > 0.6 + 0.6;  // in the hand, or carried away beyond the table's edge
    if (onTableLeft) placed.push(node.name);
    else if (offTheTable) handed.push(node.name);
    else throw new Error(`${node.name} is neither the person's nor in the assembly area: at ${node.p.map((v) => v.toFixed(3)).join(', ')}`);
  }
  check(handed.length + placed.length === 2, `every node from the input area is the person's (${handed.join(', ') || 'none'}) or in the assembly area (${placed.join(', ') || 'none'})`);
  check(handed.length >= 1, 'the person who offers took at least one node by hand');
  const separation = truth.separation;
  check(separation && separation.violation_steps === 0 && separation.contact_steps === 0, `no separation violation, no contact with the person outside the hand (${JSON.stringify(separation)})`);
  await page.screenshot({ path: path.join(artifacts, 'collaborative_done_1600x1000.png') });
  check(errors.length === 0, `no errors in the page${errors.length ? ': ' + errors.join('; ') : ''}`);
}

await runScript('collaborative', main, { log, artifacts, shot: 'collaborative_failure.png', resources: () => ({ browser, server }) });
