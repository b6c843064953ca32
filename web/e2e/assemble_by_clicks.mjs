// End-to-end test of the task editor in a real browser (Debian's Chromium, headless, driven by
// playwright-core), as a technician would use it: start `costar serve` on the simulated UR5
// cell with the paper's assembly scene, open the address it prints (the token is in it), build
// the structure assembly (examples/ur5/assemble_structure.xml) by clicks and keys alone,
// counting every UI action, save it, run it, and judge it from the simulator's true state (a
// TEST ONLY endpoint, on only with --test-endpoints): a node on the table left of centre, a
// link on it, a node on the link. No coordinates or names are typed but the plan's name.
// Then: replay the run, sign in through the sign-in box, the help overlay, screenshots at
// 1600x1000 and 1280x800, and the saved plan's XML run by `costar run`.
//
//   node web/e2e/assemble_by_clicks.mjs [--costar build/cli/costar] [--artifacts build/test-artifacts]
//                                       [--chromium /usr/bin/chromium] [--docs-screenshot docs/editor.png]
// (--docs-screenshot: the finished run at 1600x1000 there, and at 1280x800 beside it as
// NAME_1280x800.png)

import { spawnSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import { actionCounter, args, artifacts, costar, groundTruth, launchBrowser, makeLog, openPage, readability, root, runScript, startServer, waitForRunEnd } from './lib.mjs';

const MAX_ACTIONS = 30;
const scene = 'sim/scenes/assembly.json';
const { log, check } = makeLog('e2e');
let server;
let browser;

// The judge of `costar trials --judge assembly` (trials/judge.cpp), on the simulator's true state.
const NODE_HALF = 0.025;
const LINK_HALF = 0.0125;
function judgeAssembly(parts, still) {
  const xy = (a, b) => Math.hypot(a.p[0] - b.p[0], a.p[1] - b.p[1]);
  for (const base of parts.filter((p) => p.class === 'node' && p.p[1] > 0.02 && Math.abs(p.p[2] - NODE_HALF) < 0.005 && still(p))) {
    for (const link of parts.filter((p) => p.class === 'link' && still(p) && xy(p, base) < 0.02 && Math.abs(p.p[2] - 2 * NODE_HALF - LINK_HALF) < 0.006)) {
      for (const top of parts.filter((p) => p.class === 'node' && p.name !== base.name && still(p) && xy(p, link) < 0.02 &&
        Math.abs(p.p[2] - 2 * NODE_HALF - 2 * LINK_HALF - NODE_HALF) < 0.006)) {
        return `${base.name} / ${link.name} / ${top.name}`;
      }
    }
  }
  return null;
}

// How many of these boxes the tree pane shows whole (run in the page).
function wholeInPane(nodes) {
  const pane = document.querySelector('.tree-canvas').getBoundingClientRect();
  return nodes.filter((n) => {
    const b = n.getBoundingClientRect();
    return b.top >= pane.top && b.bottom <= pane.bottom && b.left >= pane.left && b.right <= pane.right;
  }).length;
}

async function main() {
  check(fs.existsSync(costar), `the costar executable exists (${costar})`);
  check(fs.existsSync(path.join(root, 'web/dist/index.html')), 'the page is built (web/dist)');
  // At the real pace (--pace 1), as a person sees it: the page follows a held part from the
  // live snapshots (20 a second), which at --pace 0 are far apart in simulated time (the tool
  // moves 10 cm between two), too sparse to say where a part was let go.
  server = await startServer({ scene, waypoints: 'examples/ur5/blind_waypoints.json', pace: 1 });
  const { url, open, token } = server;
  check(open === `${url}#token=${token}`, `costar serve --token-file prints the address with the token (${open.replace(token, '…')})`);

  browser = await launchBrowser();
  const pageErrors = [];
  const { context, page } = await openPage(browser, open, pageErrors);
  await page.waitForSelector('[data-node-type="SmartRelease"].palette-item');
  check((await page.$('[role="dialog"][aria-label="Sign in"]')) === null, 'the printed address signs in: no sign-in box');

  // --- build the structure assembly: every UI action is counted ---------------------------
  const counter = actionCounter(page, log);
  const { act, palette, choose, condition, node, clickNode, key } = counter;

  // The new plan's root Sequence is selected: each operation clicked goes after the last one.
  await palette('Open');
  await palette('Home');
  await palette('DetectObjects');
  await palette('SmartGrasp');
  await choose('object_class', 'node');
  await condition('right_of');
  await palette('SmartRelease');
  await act('click Check', () => page.click('button:text-is("Check")'));
  const problem = await page.locator('.tree-node.problem[data-node-type="SmartRelease"]').textContent();
  check(/give target_class/.test(problem ?? ''), `Check shows what is missing on the node itself: "${problem}"`);
  const targets = await page.$$eval('#port-target option', (o) => o.map((x) => x.value));
  check(targets.includes('table') && targets.includes('table_center'), `SmartRelease's target offers 'table' beside the frames (${targets.filter(Boolean).join(', ')})`);
  await choose('target', 'table');
  await condition('left_of');
  // The other two pick-and-place steps: copy Home..SmartRelease, paste twice, change what differs.
  await clickNode('Home', 0);
  await clickNode('SmartRelease', 0, ['Shift']);
  await key('Control+c');
  await key('Control+v');
  await clickNode('SmartGrasp', 1);
  await choose('object_class', 'link');
  const grasps = await page.$$eval('#port-grasp option', (o) => o.map((x) => x.value).filter(Boolean));
  check(!grasps.includes('top') && grasps.includes('middle'), `a link is offered only the grasps taught for links (${grasps.join(', ')})`);
  await clickNode('SmartRelease', 1);
  await choose('target_class', 'node');
  check((await page.inputValue('#port-target')) === '', 'choosing target_class clears target (they cannot be given together)');
  await key('Control+v');
  await clickNode('SmartRelease', 2);
  await choose('target_class', 'link');
  await palette('Home');

  const types = await page.$$eval('.tree-node', (nodes) => nodes.map((n) => n.getAttribute('data-node-type')));
  const expected = ['Sequence', 'Open', 'Home', 'DetectObjects', 'SmartGrasp', 'SmartRelease', 'Home', 'DetectObjects',
    'SmartGrasp', 'SmartRelease', 'Home', 'DetectObjects', 'SmartGrasp', 'SmartRelease', 'Home'];
  check(JSON.stringify(types) === JSON.stringify(expected), `the tree built by clicks is ${types.join(' > ')}`);
  const rows = await page.$$eval('.tree-node[data-node-type="SmartRelease"] .node-summary', (n) => n.map((x) => x.textContent));
  check(rows.join(' | ') === 'at table  left_of(table_center) | on node  left_of(table_center) | on link  left_of(table_center)',
    `the three SmartReleases tell apart in the tree: ${rows.join(' | ')}`);

  await page.click('.tree-node[data-node-type="Sequence"]'); // not counted: a look at the whole tree
  await page.screenshot({ path: path.join(artifacts, 'editor_built_1600x1000.png') });

  await act('type the plan name', () => page.fill('input[aria-label="plan name"]', 'assemble_structure'));
  await act('click Save', () => page.click('button:has-text("Save")'));
  await page.waitForSelector('text=Saved assemble_structure version 1', { timeout: 15000 });
  await act('click Run', () => page.click('button:has-text("Run")'));
  const actions = counter.actions;
  check(actions <= MAX_ACTIONS, `the whole task took ${actions} UI actions (at most ${MAX_ACTIONS}), save and run included`);
  fs.writeFileSync(path.join(artifacts, 'actions_assembly.txt'), `${actions}\n`);

  const { result, label, sawRunning } = await waitForRunEnd(page);
  check(result === 'SUCCESS', `the run ended with ${result}: ${label}`);
  check(/^Run #1 \(assemble_structure v1\) on ur5-sim: SUCCESS/.test(label ?? ''), `plan runs are numbered by plan runs only, and name their plan and cell: "${label}"`);
  check(sawRunning, 'the running node was highlighted while it ran');
  const statuses = await page.$$eval('.tree-node', (nodes) => nodes.map((n) => n.getAttribute('data-status')));
  check(statuses.every((s) => s === 'SUCCESS'), `every node is green (SUCCESS): ${statuses.join(', ')}`);
  check(!(await page.textContent('.status-line')).includes('started.'), 'the status line no longer says the run started');

  // Judged from the simulator's true state, twice half a second apart (the parts at rest).
  const first = await groundTruth(url, token);
  await page.waitForTimeout(500);
  const second = await groundTruth(url, token);
  const still = (p) => {
    const q = first.parts.find((x) => x.name === p.name);
    return q && Math.hypot(...p.p.map((v, i) => v - q.p[i])) < 0.002;
  };
  const structure = judgeAssembly(second.parts, still);
  check(structure !== null, `the simulator's true state holds the structure (base / link / top): ${structure ?? second.parts.map((p) => `${p.name} ${p.p.map((v) => v.toFixed(3))}`).join('; ')}`);

  // The world the page believes: the top part was put down after the last detection, so only
  // the page's belief (it moved with the tool while held) has it on the structure.
  const top = second.parts.find((p) => p.name === structure.split(' / ')[2]);
  const putDown = await page.$$eval('.objects-table tbody tr', (rows) => rows.map((r) => r.textContent).filter((t) => t.includes('(put down)')));
  const believedAt = putDown.map((t) => /(-?\d+\.\d+), (-?\d+\.\d+), (-?\d+\.\d+)/.exec(t).slice(1).map(Number));
  const off = Math.min(...believedAt.map((p) => Math.hypot(...p.map((v, i) => v - top.p[i]))));
  check(putDown.length === 1 && off < 0.05, `the Objects pane shows the top part where it was put down, ${(off * 100).toFixed(1)} cm from where it is: ${putDown.join('; ')}`);

  // Each part drawn in the colour perception saw on it: the Objects pane's swatches name the
  // nearest of the class's colours, which must be the simulator's material of each part.
  const swatches = await page.$$eval('.objects-table tbody tr', (rows) =>
    rows.map((r) => ({ cls: r.children[1]?.textContent?.trim() ?? '', title: r.querySelector('.swatch')?.getAttribute('title') ?? '' })),
  );
  const seenColours = swatches.map((s) => `${/^the colour DetectObjects saw on it \(nearest of the class's colours: (\w+)\)$/.exec(s.title)?.[1] ?? '?'} ${s.cls}`).sort();
  const trueColours = second.parts.map((p) => `${p.color} ${p.class}`).sort();
  check(
    JSON.stringify(seenColours) === JSON.stringify(trueColours),
    `each part is drawn in the colour seen on it: ${seenColours.join(', ')} (the simulator's: ${trueColours.join(', ')})`,
  );

  // Screenshots of the finished run at both sizes: select a SmartRelease to show its candidates.
  await node('SmartRelease', 1).click();
  await page.waitForTimeout(600);
  await page.screenshot({ path: path.join(artifacts, 'editor_run_1600x1000.png') });
  if (args['docs-screenshot']) fs.copyFileSync(path.join(artifacts, 'editor_run_1600x1000.png'), path.resolve(args['docs-screenshot']));
  await page.setViewportSize({ width: 1280, height: 800 });
  await page.waitForTimeout(600);
  await page.screenshot({ path: path.join(artifacts, 'editor_run_1280x800.png') });
  if (args['docs-screenshot']) fs.copyFileSync(path.join(artifacts, 'editor_run_1280x800.png'), path.resolve(args['docs-screenshot']).replace(/\.png$/, '_1280x800.png'));
  const visible = await page.$$eval('.tree-node', wholeInPane);
  const readable = await page.evaluate(readability);
  log(`at 1280x800: ${visible} of 15 boxes whole; smallest text in the tree ${readable.smallest.toFixed(2)} px (${readable.smallestWhat}) at zoom ${readable.zoom}`);
  fs.writeFileSync(path.join(artifacts, 'readability_1280x800.json'), JSON.stringify({ visible, ...readable }, null, 2));
  check(readable.smallest >= 11, `at 1280x800 the tree's smallest text is ${readable.smallest.toFixed(2)} px (at least 11)`);
  check(readable.problems.length === 0, `at 1280x800 no element overflows its pane or clips its text${readable.problems.length ? ': ' + readable.problems.join('; ') : ''}`);
  const menuHeight = await page.$eval('.menu', (m) => m.getBoundingClientRect().height);
  const buttonHeight = await page.$eval('.menu button', (b) => b.getBoundingClientRect().height);
  check(menuHeight < 2 * buttonHeight, `the menu bar is one row at 1280x800 (${menuHeight} px high, buttons ${buttonHeight} px)`);
  check(visible >= 9, `at 1280x800 the tree shows ${visible} of 15 nodes whole at a readable zoom (the rest a scroll away)`);

  // Undo, redo, keyboard help.
  await page.keyboard.press('?');
  await page.waitForSelector('[role="dialog"][aria-label="Keyboard shortcuts"]');
  await page.screenshot({ path: path.join(artifacts, 'editor_help_1280x800.png') });
  await page.keyboard.press('Escape');
  check((await page.$('[role="dialog"][aria-label="Keyboard shortcuts"]')) === null, 'the help overlay lists the keys and closes with Escape');
  // The larger tree (M): the cell, the waypoints and the runs fold away; the whole tree shows.
  await page.keyboard.press('m');
  await page.waitForTimeout(600);
  await page.screenshot({ path: path.join(artifacts, 'editor_run_1280x800_larger_tree.png') });
  const whole = await page.$$eval('.tree-node', wholeInPane);
  const large = await page.evaluate(readability);
  check(whole === 15 && large.smallest >= 11, `with the larger tree (M) at 1280x800 all ${whole} of 15 nodes show whole, smallest text ${large.smallest.toFixed(2)} px`);
  await node('Home', 3).click();
  await page.keyboard.press('Delete');
  check((await page.$$('.tree-node')).length === 14, 'Delete removes the selected node');
  await page.keyboard.press('Control+z');
  check((await page.$$('.tree-node')).length === 15, 'Ctrl+Z brings it back');
  await page.keyboard.press('m');
  check(await page.isVisible('.view3d'), 'M again brings the cell back');

  // Replay: pick the run from the run log and scrub through its transitions.
  await page.setViewportSize({ width: 1600, height: 1000 });
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
  const cellAt = async () => ({
    objects: await page.$$eval('.objects-table tbody tr', (rows) => rows.length),
    tool: await page.getAttribute('.view3d-canvas', 'data-drawn-tool'),
    label: await page.textContent('.view3d-replay').catch(() => ''),
  });
  const atStart = await statusesAt(0);
  await page.waitForTimeout(300);
  const cellAtStart = await cellAt();
  // The arm as replayed at eight points of the run: it moves (it is home at the start and at
  // the end, and at each Home in between).
  const tools = new Set();
  for (let k = 1; k < 8; k++) {
    await statusesAt(Math.floor((k * total) / 8));
    await page.waitForTimeout(150);
    tools.add((await cellAt()).tool);
  }
  const atMiddle = await statusesAt(Math.floor(total / 2));
  const atEnd = await statusesAt(total);
  await page.waitForTimeout(300);
  const cellAtEnd = await cellAt();
  check(total > 20 && atStart.every((s) => s === 'IDLE'), `replay of run #${runId} starts with every node idle (${total} transitions)`);
  check(atMiddle.includes('SUCCESS') && !atMiddle.every((s) => s === 'SUCCESS'), 'half way some nodes are done');
  check(atEnd.every((s) => s === 'SUCCESS'), 'at the end of the replay every node is green');
  const parts = second.parts.length;
  tools.delete(cellAtStart.tool);
  check(
    cellAtStart.objects === 0 && cellAtEnd.objects === parts && tools.size >= 3 && /replay/.test(cellAtEnd.label ?? ''),
    `the replay drives the Objects pane and the 3D view from the run's log: ${cellAtStart.objects} parts at the start, ${cellAtEnd.objects} of ${parts} at the end; the tool drawn at ${tools.size} other places of 7 along the run ("${cellAtEnd.label}")`,
  );
  await page.click('button:text-is("Back to editing")');

  // Reloaded, a new plan shows no status of the plan that ran.
  await page.reload();
  await page.waitForSelector('.connection.on', { timeout: 30000 });
  await page.waitForSelector('.tree-node[data-node-type="Sequence"]');
  await page.waitForTimeout(300);
  const fresh = await page.$$eval('.tree-node', (nodes) => nodes.map((n) => n.getAttribute('data-status')));
  check(fresh.every((s) => s === 'IDLE'), `after a reload the new plan is not painted with the last run's statuses (${fresh.join(', ')})`);

  // Signing in: a tab without the token shows the sign-in box; a wrong token is refused.
  const other = await context.newPage();
  other.on('pageerror', (e) => pageErrors.push(e.message));
  await other.goto(url);
  await other.waitForSelector('[role="dialog"][aria-label="Sign in"]', { timeout: 15000 });
  await other.fill('input[aria-label="token"]', 'not-the-token');
  await other.click('button:text-is("Sign in")');
  await other.waitForSelector('text=The server refused this token', { timeout: 15000 });
  await other.screenshot({ path: path.join(artifacts, 'editor_signin_1600x1000.png') });
  await other.fill('input[aria-label="token"]', open);
  await other.click('button:text-is("Sign in")');
  await other.waitForTimeout(1500);
  check((await other.$('[role="dialog"][aria-label="Sign in"]')) === null, 'the sign-in box takes the printed address and lets the technician in');
  await other.close();

  // The saved plan is the file the CLI runs.
  const xml = await (await fetch(`${url}api/plans/assemble_structure/xml`)).text();
  const file = path.join(server.work, 'assemble_structure.xml');
  fs.writeFileSync(file, xml);
  fs.copyFileSync(file, path.join(artifacts, 'assemble_structure.xml'));
  const cli = spawnSync(costar, ['run', file, '--scene', path.join(root, scene), '--waypoints', server.waypointFile, '-q'], { encoding: 'utf8' });
  check(cli.status === 0, `costar run on the saved plan succeeds: ${cli.stdout.trim()} ${cli.stderr.trim()}`);

  check(pageErrors.length === 0, `no errors in the page${pageErrors.length ? ': ' + pageErrors.join('; ') : ''}`);
}

await runScript('e2e', main, { log, artifacts, shot: 'editor_failure.png', resources: () => ({ browser, server }) });
