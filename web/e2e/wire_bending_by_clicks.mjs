// End-to-end test of the editor on the iiwa with the 3-finger gripper and the bending jig
// (iiwa-3f-sim, sim/scenes/wire_bending.json): the paper's blind wire bending
// (examples/iiwa/wire_bending.xml) built by clicks from an empty tree, every UI action counted
// (the plan's name and Run included), run on the simulator and judged from its true state as
// `costar trials --judge wire_bending` judges it: every bend within 5 degrees of the jig's
// drawing, the wire let go and never pulled out of the fingers, no pin moved.
//
//   node web/e2e/wire_bending_by_clicks.mjs [--costar build/cli/costar] [--artifacts build/test-artifacts]

import fs from 'node:fs';
import path from 'node:path';
import { actionCounter, api, artifacts, costar, groundTruth, launchBrowser, makeLog, openPage, root, runScript, startServer, waitForRunEnd } from './lib.mjs';

const MAX_ACTIONS = 40;
const { log, check } = makeLog('wire');
let server;
let browser;

async function main() {
  check(fs.existsSync(costar), `the costar executable exists (${costar})`);
  check(fs.existsSync(path.join(root, 'web/dist/index.html')), 'the page is built (web/dist)');
  server = await startServer({ workcell: 'iiwa-3f-sim', scene: 'sim/scenes/wire_bending.json', waypoints: 'examples/iiwa/wire_waypoints.json', pace: 0 });
  const { url, open, token } = server;
  browser = await launchBrowser();
  const pageErrors = [];
  const { page } = await openPage(browser, open, pageErrors);
  await page.waitForSelector('.palette-item[data-node-type="Move"]');

  const counter = actionCounter(page, log);
  const { act, palette, choose, dropOnEdge } = counter;
  const fill = (what, selector, value) => act(what, () => page.fill(selector, value));
  const dropAfter = (type, target, n) =>
    dropOnEdge(type, `.tree-node[data-node-type="${target}"] >> nth=${n}`, 'after', `drag ${type} onto the trailing edge of ${target} #${n + 1}`);
  const along = (prefix) => act(`a Move to each waypoint of the path ${prefix}…`, () => page.selectOption('select[aria-label="along a path"]', prefix));
  /** The index among the boxes of a type of the one lowest in the pane, of those furthest right. */
  const deepestLowest = (type) =>
    page.$$eval(`.tree-node[data-node-type="${type}"]`, (nodes) => {
      const boxes = nodes.map((n) => n.getBoundingClientRect());
      const right = Math.max(...boxes.map((b) => b.left));
      let best = -1;
      boxes.forEach((b, i) => {
        if (b.left === right && (best < 0 || b.top > boxes[best].top)) best = i;
      });
      return best;
    });

  // Take the wire's end in Pinch mode.
  await palette('Open');
  await palette('PinchMode');
  await palette('Move');
  await choose('waypoint', 'wire_above_end');
  await palette('Move');
  await choose('waypoint', 'wire_grip');
  await fill('type the speed 0.2 (a fraction of the top speed)', '#port-speed', '0.2');
  await palette('Close');
  await fill('type the force 20 N', '#port-force', '20');
  await palette('CheckPredicate');
  await choose('predicate', 'gripper_holding');
  // Around pin B, then pin A: a Move to each waypoint of the taught arcs, slowly.
  await palette('Sequence');
  await palette('Move');
  await fill('type the speed 0.15', '#port-speed', '0.15');
  const offered = await page.$$eval('select[aria-label="along a path"] option', (o) => o.map((x) => x.textContent));
  check(offered.some((p) => /^bend_b_… \(11: bend_b_10 → bend_b_done\)/.test(p)), `the taught arcs are offered whole: ${offered.slice(1).join('; ')}`);
  await along('bend_b_');
  await dropAfter('Sequence', 'Sequence', await deepestLowest('Sequence'));
  await palette('Move');
  await fill('type the speed 0.15', '#port-speed', '0.15');
  await along('bend_a_');
  // Let go part way, up, home.
  await dropAfter('Open', 'Sequence', await deepestLowest('Sequence'));
  await fill('type the opening 0.2', '#port-position', '0.2');
  await palette('Move');
  await choose('waypoint', 'wire_above_done');
  await fill('type the speed 0.2', '#port-speed', '0.2');
  await palette('Home');
  await page.screenshot({ path: path.join(artifacts, 'wire_bending_built_1600x1000.png') });

  await fill('type the plan name', 'input[aria-label="plan name"]', 'wire_bending');
  await act('click Run (saves the plan first)', () => page.click('button.run'));
  const actions = counter.actions;
  check(actions <= MAX_ACTIONS, `the wire bending plan took ${actions} UI actions (at most ${MAX_ACTIONS}), its name and Run included`);
  fs.writeFileSync(path.join(artifacts, 'actions_wire_bending.txt'), `${actions}\n`);
  await page.waitForSelector('.run-label:text-matches("^Run #1")', { timeout: 30000 }).catch(async () => {
    throw new Error(`the run did not start: ${await page.textContent('.status-line')}`);
  });

  // The plan is the example's: its structure and every Move's waypoint and speed in order.
  const savedPlan = await api(url, token, 'GET', '/api/plans/wire_bending');
  const outline = (n) => `${n.id}${n.children.length ? `(${n.children.map(outline).join(' ')})` : ''}`;
  const moves = (n) => [...(n.id === 'Move' ? [Object.fromEntries(n.attributes)] : []), ...n.children.flatMap(moves)];
  const built = savedPlan.json.plan.trees[0].root;
  const elevens = Array(11).fill('Move').join(' ');
  check(outline(built) === `Sequence(Open PinchMode Move Move Close CheckPredicate Sequence(${elevens}) Sequence(${elevens}) Open Move Home)`, `the tree is the example's: ${outline(built)}`);
  const example = fs.readFileSync(path.join(root, 'examples/iiwa/wire_bending.xml'), 'utf8');
  const exampleMoves = [...example.matchAll(/<Move [^>]*waypoint="([^"]+)"(?: speed="([^"]+)")?/g)].map((m) => `${m[1]}@${m[2] ?? 'default'}`);
  const builtMoves = moves(built).map((m) => `${m.waypoint}@${m.speed ?? 'default'}`);
  check(JSON.stringify(builtMoves) === JSON.stringify(exampleMoves), `every Move goes where the example's does, as fast: ${builtMoves.length} Moves`);

  const { result, label } = await waitForRunEnd(page, 600);
  check(result === 'SUCCESS', `the run ended with ${result}: ${label}`);
  // The wire settles; then the judge of costar trials --judge wire_bending, on the true state.
  let truth = await groundTruth(url, token);
  for (let i = 0; i < 100 && truth.wire.speed >= 0.005; i += 1) {
    await page.waitForTimeout(100);
    truth = await groundTruth(url, token);
  }
  const { wire } = truth;
  check(wire.speed < 0.005, `the wire is at rest (${(wire.speed * 1000).toFixed(1)} mm/s)`);
  const bends = wire.bends.map((b) => `${b.angle_deg.toFixed(1)}° (drawing ${b.target_deg}°, ${b.out_of_plane_deg.toFixed(1)}° out of plane)`);
  check(wire.bends.length === 2 && wire.bends.every((b) => Math.abs(b.angle_deg - b.target_deg) <= 5 && Math.abs(b.out_of_plane_deg) <= 5), `every bend within 5° of the drawing: ${bends.join(', ')}`);
  check(wire.holds >= 1 && wire.releases >= 1 && wire.pulled_out === 0 && !wire.held, `the gripper held the wire, let go of it, never pulled it out (${JSON.stringify({ holds: wire.holds, releases: wire.releases, pulled_out: wire.pulled_out })})`);
  check(wire.pin_slipped < 1e-4, `no pin moved (${(wire.pin_slipped * 1000).toFixed(2)} mm)`);
  check(pageErrors.length === 0, `no page errors (${pageErrors.join('; ')})`);
}

await runScript('wire', main, { log, artifacts, shot: 'wire_bending_failure.png', resources: () => ({ browser, server }) });
