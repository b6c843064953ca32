// End-to-end test of the editor as the cell's control panel (Debian's Chromium, headless, driven
// by playwright-core, against `costar serve` on the simulated UR5 cell):
//   - a `Repeat -1` plan runs; the page is reloaded: it shows the running run (plan, version,
//     node, cell), Run and the jog buttons are disabled saying why, Pause shows the node PAUSED,
//     and Stop stops it; a second browser (another context) stops the next run;
//   - a waypoint renamed in the cell: Check flags the plan on its Move node, the status line
//     offers to rename it in the plan, and then Check passes;
//   - versions: compare v1 with the open plan (a tree diff), restore v1, open v2;
//   - the palette offers the modes the cell's gripper has; Check knows the cell's gripper
//     (an imported ScissorMode on a 2-finger gripper) and offers the cure
//     for a structural problem (a Repeat with two children: wrap them in a Sequence);
//   - Reset scene: the moved part back where the scene puts it; refused while a run is active;
//   - the server stopped: the page says "not connected" and disables Run, saying why.
//
//   node web/e2e/control_panel.mjs [--costar build/cli/costar] [--artifacts build/test-artifacts]

import path from 'node:path';
import { api, artifacts, groundTruth, launchBrowser, makeLog, openPage, runScript, startServer } from './lib.mjs';

const { log, check } = makeLog('control panel');
let server;
let browser;

// Back and forth between two waypoints for ever: only Stop ends it.
const FOREVER = `<root BTCPP_format="4" main_tree_to_execute="main"><BehaviorTree ID="main">
  <Repeat num_cycles="-1"><Sequence name="shuttle">
    <Move name="to the pick" waypoint="above_pick"/><Move name="to the place" waypoint="above_place"/>
  </Sequence></Repeat></BehaviorTree></root>`;

async function runLabel(page) {
  return (await page.textContent('.run-label')) ?? '';
}

async function waitFor(page, what, predicate, seconds = 60) {
  const deadline = Date.now() + seconds * 1000;
  while (Date.now() < deadline) {
    if (await predicate()) return true;
    await page.waitForTimeout(100);
  }
  throw new Error(`timed out waiting for ${what}`);
}

async function main() {
  server = await startServer({ scene: 'sim/scenes/one_node.json', waypoints: 'examples/ur5/blind_waypoints.json', pace: 1 });
  const { url, open, token } = server;
  const initial = await groundTruth(url, token);
  check((await api(url, token, 'PUT', '/api/plans/forever', { xml: FOREVER })).status === 201, 'the plan `forever` (Repeat -1) is saved as version 1');

  browser = await launchBrowser();
  const errors = [];
  const { context, page } = await openPage(browser, open, errors);
  page.on('dialog', (d) => d.accept());
  await page.waitForSelector('.palette-item[data-node-type="Move"]');

  // --- open version 1 from the Plans dialog and run it -------------------------------------------
  await page.click('button:text-is("Plans…")');
  await page.click('.plan-list button[data-plan="forever"]');
  await page.click('tr[data-version="1"] button:text-is("Open")');
  await page.waitForSelector('.tree-node[data-node-type="Repeat"]');
  check((await page.inputValue('input[aria-label="plan name"]')) === 'forever', 'the Plans dialog opens version 1 of forever');
  await page.click('button:has-text("Run")');
  await waitFor(page, 'the run to start', async () => (await page.$('.tree-node[data-running="true"]')) !== null);
  const runId = /Run #(\d+)/.exec(await runLabel(page))?.[1];
  check(!!runId, `run #${runId} started: ${await runLabel(page)}`);

  // --- reload during the run -------------------------------------------------------------------------
  await page.reload();
  await page.waitForSelector('.connection.on', { timeout: 30000 });
  await waitFor(page, 'the running node after the reload', async () => (await page.$('.tree-node[data-running="true"]')) !== null, 20);
  const afterReload = await runLabel(page);
  check(
    new RegExp(`^Run #${runId} \\(forever v1\\) on ur5-sim: RUNNING at Move “to the (pick|place)”`).test(afterReload),
    `after a reload the page shows the running run, its plan, version, node and cell: "${afterReload}"`,
  );
  check((await page.inputValue('input[aria-label="plan name"]')) === 'forever', 'the reloaded page opened the running plan');
  const runButton = page.locator('.menu button.run');
  check(await runButton.isDisabled(), 'Run is disabled while the run goes on');
  check((await runButton.getAttribute('title')) === `run #${runId} is active: stop it or wait for it to end`, `Run says why: "${await runButton.getAttribute('title')}"`);
  const jog = page.locator('button[aria-label="jog J1 plus"]');
  check((await jog.isDisabled()) && /is active/.test((await jog.getAttribute('title')) ?? ''), 'the jog buttons are disabled and say why');
  const reset = page.locator('.menu button:text-is("Reset scene")');
  check((await reset.isDisabled()) && /before resetting the scene/.test((await reset.getAttribute('title')) ?? ''), 'Reset scene is refused while the run is active, saying why');
  check(!(await page.locator('.menu button.stop').isDisabled()), 'Stop is enabled on the reloaded page');

  // Pause: the running node shows PAUSED, not RUNNING; the cell stands still.
  await page.click('.menu button:text-is("Pause")');
  await waitFor(page, 'the pause', async () => (await page.$('.tree-node[data-paused="true"]')) !== null, 10);
  const badges = await page.$$eval('.tree-node[data-paused="true"] .badge', (b) => b.map((x) => x.textContent));
  check(badges.includes('PAUSED') && !badges.includes('RUNNING'), `a paused node shows PAUSED (${badges.join(', ')})`);
  check(/PAUSED/.test(await runLabel(page)), `the status line says PAUSED: "${await runLabel(page)}"`);
  const t0 = (await groundTruth(url, token)).t;
  await page.waitForTimeout(1000);
  const t1 = (await groundTruth(url, token)).t;
  check(t1 === t0, `while paused the simulated clock stands still (t = ${t0} s, a second later ${t1} s)`);
  await page.screenshot({ path: path.join(artifacts, 'control_paused_1600x1000.png') });
  await page.click('.menu button:text-is("Resume")');
  await waitFor(page, 'the run to go on', async () => /RUNNING/.test(await runLabel(page)), 10);

  await page.click('.menu button.stop');
  await waitFor(page, 'the stop', async () => (await page.getAttribute('.run-label', 'data-run-result')) === 'STOPPED', 20);
  check(true, `the reloaded page stopped the run: "${await runLabel(page)}"`);
  check(!(await runButton.isDisabled()) && (await page.locator('.menu button.stop').isDisabled()), 'then Run is enabled again and Stop disabled');

  // --- a second browser stops the next run -------------------------------------------------------
  await page.click('button:has-text("Run")');
  await waitFor(page, 'the second run', async () => /RUNNING/.test(await runLabel(page)), 20);
  const second = await openPage(browser, open, errors);
  const other = second.page;
  await waitFor(other, 'the second browser to see the run', async () => /RUNNING/.test(await runLabel(other)), 20);
  check(/^Run #\d+ \(forever v1\) on ur5-sim: RUNNING/.test(await runLabel(other)), `a second browser shows the run: "${await runLabel(other)}"`);
  await other.click('.menu button.stop');
  await waitFor(page, 'the stop from the second browser', async () => (await page.getAttribute('.run-label', 'data-run-result')) === 'STOPPED', 20);
  check(true, `the second browser stopped it; the first page says so: "${await runLabel(page)}"`);
  await second.context.close();

  // --- a waypoint renamed in the cell ---------------------------------------------------------------
  await page.click('tr[data-waypoint="above_pick"] button:text-is("Rename")');
  await page.fill('tr[data-waypoint="above_pick"] input[aria-label="new name"]', 'over_pick');
  await page.click('tr[data-waypoint="above_pick"] button:text-is("OK")');
  await page.waitForSelector('tr[data-waypoint="over_pick"]', { timeout: 20000 });
  await page.waitForSelector('.status-line .offer', { timeout: 10000 });
  const offer = await page.textContent('.status-line .offer');
  check(offer === 'Rename it in this plan (1)', `the rename offers to update the open plan: "${offer}"`);
  await page.click('button:text-is("Check")');
  await page.waitForSelector('.tree-node.problem[data-node-type="Move"]', { timeout: 10000 });
  const flagged = await page.textContent('.tree-node.problem[data-node-type="Move"]');
  check(/no waypoint 'above_pick' in this cell now/.test(flagged ?? ''), `Check flags the plan's Move on the old name: "${flagged}"`);
  const moveEditor = page.locator('.tree-node[data-node-type="Move"]').first();
  await moveEditor.click();
  const offered = await page.$$eval('#port-waypoint option', (o) => o.map((x) => x.textContent));
  check(offered.includes('over_pick') && offered.some((t) => /above_pick \(not in the cell now\)/.test(t ?? '')), `the Move offers the new name and marks the old one (${offered.join(', ')})`);
  check((await page.textContent('.status-line .offer')) === offer, 'the offer stands beside Check\'s message');
  await page.click('.status-line .offer');
  await page.click('button:text-is("Check")');
  await waitFor(page, 'Check to pass', async () => /is valid for ur5-sim/.test((await page.textContent('.status-line .message')) ?? ''), 10);
  await moveEditor.click();
  check((await page.inputValue('#port-waypoint')) === 'over_pick', `the offer renamed it in the plan; Check passes: "${await page.textContent('.status-line .message')}"`);

  // --- versions: save v2, compare v1, restore v1, open v2 ----------------------------------------
  await page.click('.menu button:has-text("Save")');
  await page.waitForSelector('text=Saved forever version 2');
  await page.click('button:text-is("Plans…")');
  await page.click('.plan-list button[data-plan="forever"]');
  await page.waitForSelector('tr[data-version="2"]');
  await page.click('tr[data-version="1"] button:text-is("Compare")');
  await page.waitForSelector('.comparison li');
  const diff = await page.$$eval('.comparison li', (l) => l.map((x) => x.textContent));
  check(diff.length === 1 && /^~ Repeat › Sequence “shuttle” › Move “to the pick”: waypoint: above_pick → over_pick$/.test(diff[0]), `v1 compared with the open plan: ${diff.join(' | ')}`);
  await page.click('button:text-is("Show on the tree")');
  await page.waitForSelector('.tree-node[data-change="changed"]');
  check((await page.$$('.tree-node[data-change="changed"]')).length === 1, 'the tree marks the changed node');
  await page.screenshot({ path: path.join(artifacts, 'control_compare_1600x1000.png') });
  await page.click('button:text-is("Stop comparing")');
  await page.click('button:text-is("Plans…")');
  await page.click('.plan-list button[data-plan="forever"]');
  await page.click('tr[data-version="1"] button:text-is("Restore")');
  await page.waitForSelector('text=Restored forever version 1 as version 3');
  const restored = await (await fetch(`${url}api/plans/forever`)).json();
  check(restored.version === 3 && /waypoint="above_pick"/.test(restored.xml), 'Restore saved version 1 again as version 3 (the newest), and the editor opened it');
  await page.click('button:text-is("Plans…")');
  await page.click('.plan-list button[data-plan="forever"]');
  await page.click('tr[data-version="2"] button:text-is("Open")');
  await page.waitForSelector('text=Opened forever version 2');
  await page.locator('.tree-node[data-node-type="Move"]').first().click();
  check((await page.inputValue('#port-waypoint')) === 'over_pick', 'an older version (2) opens in the editor');

  // --- Check knows the gripper; structural problems come with their cure --------------------------
  // The palette offers only the modes the cell's gripper has; a plan with another is flagged.
  check((await page.$('.palette-item[data-node-type="ScissorMode"]')) === null, 'the palette does not offer ScissorMode on the 2-finger cell');
  const note = await page.textContent('.palette .unavailable');
  check(/^Not on this cell: BasicMode, ScissorMode, WideMode \(a parallel 2-finger gripper has only Pinch mode/.test(note ?? ''), `it says which and why: "${note}"`);
  const scissorPlan = `<root BTCPP_format="4" main_tree_to_execute="main"><BehaviorTree ID="main"><Sequence><Open/><ScissorMode/></Sequence></BehaviorTree></root>`;
  await page.setInputFiles('.file-button input', { name: 'scissor.xml', mimeType: 'application/xml', buffer: Buffer.from(scissorPlan) });
  await page.waitForSelector('.tree-node.problem[data-node-type="ScissorMode"]');
  const scissor = await page.textContent('.status-line .message');
  check(/1 problem\(s\): ScissorMode: a parallel 2-finger gripper has only Pinch mode/.test(scissor ?? ''), `an imported plan's ScissorMode is flagged on the 2-finger cell: "${scissor}"`);
  const twoChildren = `<root BTCPP_format="4" main_tree_to_execute="main"><BehaviorTree ID="main"><Repeat num_cycles="2"><Open/><Close/></Repeat></BehaviorTree></root>`;
  await page.setInputFiles('.file-button input', { name: 'two_children.xml', mimeType: 'application/xml', buffer: Buffer.from(twoChildren) });
  await page.waitForSelector('.status-line .offer');
  const cure = await page.textContent('.status-line .offer');
  check(cure === 'Wrap the 2 children in a Sequence', `"Repeat needs exactly one child" offers its cure: "${cure}"`);
  await page.click('.status-line .offer');
  await page.click('button:text-is("Check")');
  await waitFor(page, 'the cured plan to pass Check', async () => /is valid/.test((await page.textContent('.status-line .message')) ?? ''), 10);
  const cured = await page.$$eval('.tree-node', (n) => n.map((x) => x.getAttribute('data-node-type')));
  check(cured.join(' ') === 'Repeat Sequence Open Close', `the children are wrapped in a Sequence and Check passes (${cured.join(' > ')})`);

  // --- Reset scene -------------------------------------------------------------------------------------
  const before = initial;
  for (const step of [{ node: 'Open' }, { node: 'Move', attributes: { waypoint: 'above_place' } }]) {
    const started = await api(url, token, 'POST', '/api/operations', step);
    await waitFor(page, `${step.node} to end`, async () => (await api(url, token, 'GET', `/api/runs/${started.json.run}`)).json.active === false, 30);
  }
  const moved = await groundTruth(url, token);
  check(Math.hypot(...moved.tcp.p.map((v, i) => v - before.tcp.p[i])) > 0.05, 'the arm moved away');
  await page.click('.menu button:text-is("Reset scene")');
  await page.waitForSelector('text=Scene reset');
  const after = await groundTruth(url, token);
  const tcpBack = Math.hypot(...after.tcp.p.map((v, i) => v - before.tcp.p[i]));
  const partBack = Math.hypot(...after.parts[0].p.map((v, i) => v - before.parts[0].p[i]));
  check(tcpBack < 0.002 && partBack < 0.002, `Reset scene: the arm home (${(tcpBack * 1000).toFixed(1)} mm off) and the part where the scene puts it (${(partBack * 1000).toFixed(1)} mm)`);
  const runs = (await api(url, token, 'GET', '/api/runs')).json;
  check(runs.every((r) => r.workcell === 'ur5-sim'), `every run is labelled with its cell (${runs.map((r) => `#${r.id} ${r.workcell}`).join(', ')})`);

  // --- the server goes away: not connected, Run disabled with the reason -----------------------------
  await page.screenshot({ path: path.join(artifacts, 'control_panel_1600x1000.png') });
  server.stop();
  server = undefined;
  await page.waitForSelector('.connection.off', { timeout: 20000 });
  check(await runButton.isDisabled(), 'disconnected: Run is disabled');
  check(/not connected/.test((await runButton.getAttribute('title')) ?? ''), `disconnected: Run says why ("${await runButton.getAttribute('title')}")`);
  check(await page.locator('button[aria-label="jog J1 plus"]').isDisabled(), 'disconnected: the jog buttons are disabled');
  check((await page.textContent('.connection')) === 'not connected', 'the menu says "not connected"');
  void context;
  check(errors.length === 0, `no errors in the pages${errors.length ? ': ' + errors.join('; ') : ''}`);
}

await runScript('control panel', main, { log, artifacts, shot: 'control_panel_failure.png', resources: () => ({ browser, server }) });
