// End-to-end test of teaching by demonstration in the editor (docs/TEACHING.md) on the UR5
// (ur5-sim; --cell another simulated cell: scripts/test.sh runs iiwa-3f-sim too) at 1280x800: the tool guided by hand in the 3D view (its handle grabbed and dragged,
// the top view to bring it over a part, the side view to lower it), a waypoint taught above the
// part relative to it, a grasp taught there, a short stroke recorded while guiding, and a plan
// built from them by clicks (Move, SmartGrasp with the taught grasp, FollowTrajectory of the
// stroke, Open), run on the simulator and judged from its true state: the part picked where it
// lay, carried along the stroke and let go where the stroke ended. Every UI action is counted:
// the actions to teach the pick from scratch (detect, guide, teach the waypoint and the grasp)
// and for the whole task (the stroke and the plan, its name and Run included).
//
//   node web/e2e/teach_by_demonstration.mjs [--costar build/cli/costar] [--artifacts build/test-artifacts]
//                                           [--cell ur5-sim|iiwa-sim|iiwa-3f-sim|panda-sim]

import fs from 'node:fs';
import path from 'node:path';
import { actionCounter, api, args, artifacts, costar, groundTruth, launchBrowser, makeLog, openPage, root, runScript, startServer, waitForRunEnd } from './lib.mjs';

/** The simulated cell (workcells/NAME.json): the UR5's unless asked. */
const CELL = args.cell ?? 'ur5-sim';
const MAX_PICK_ACTIONS = 21;
const MAX_ACTIONS = 35;
const { log, check } = makeLog('teach');
let server;
let browser;

const sub = (a, b) => a.map((v, i) => v - b[i]);
/** The heading (degrees) of the x axis of an orientation [x, y, z, w] (the page's and the truth's order). */
const heading = ([x, y, z, w]) => (Math.atan2(2 * (x * y + w * z), 1 - 2 * (y * y + z * z)) * 180) / Math.PI;
/** `degrees` as the nearest turn of a square part's symmetry: -45 to 45. */
const quarter = (degrees) => ((((degrees + 45) % 90) + 90) % 90) - 45;
const norm = (v) => Math.hypot(...v);

async function main() {
  check(fs.existsSync(costar), `the costar executable exists (${costar})`);
  check(fs.existsSync(path.join(root, 'web/dist/index.html')), 'the page is built (web/dist)');
  // Real time: the page's pushes come every 50 ms of wall time, as a person's hand would.
  server = await startServer({ workcell: CELL, pace: 1 });
  log(`the cell: ${CELL}`);
  const { url, open, token } = server;
  browser = await launchBrowser();
  const pageErrors = [];
  const { page } = await openPage(browser, open, pageErrors, { width: 1280, height: 800 });
  const view = page.locator('.view3d-canvas');
  await page.waitForSelector('.view3d-canvas[data-tool-screen]:not([data-tool-screen=""])');
  const counter = actionCounter(page, log);
  const { act, palette, choose, click, fill } = counter;
  const truth = () => groundTruth(url, token);

  // --- detect the parts ------------------------------------------------------------------------
  await click('click Detect objects', '.menu button:text("Detect objects")');
  await page.waitForFunction(() => Object.keys(JSON.parse(document.querySelector('.view3d-canvas')?.getAttribute('data-part-screens') ?? '{}')).length > 0, null, { timeout: 60000 });
  const state = (await api(url, token, 'GET', '/api/state')).json;
  const start = await truth();
  // The node nearest the tool: its name as detected, and where it truly lies.
  const nodes = state.objects.filter((o) => o.class === 'node');
  check(nodes.length > 0, `DetectObjects found the nodes: ${nodes.map((n) => n.name).join(', ')}`);
  const tcp0 = start.tcp.p;
  log(`the fingers open ${(start.finger_opening * 1000).toFixed(1)} mm`);
  const target = nodes.reduce((a, b) => (norm(sub(a.p.slice(0, 2), tcp0.slice(0, 2))) <= norm(sub(b.p.slice(0, 2), tcp0.slice(0, 2))) ? a : b));
  const part = start.parts.reduce((a, b) => (norm(sub(a.p, target.p)) <= norm(sub(b.p, target.p)) ? a : b));
  check(norm(sub(part.p, target.p)) < 0.02, `${target.name} is seen where the simulator has ${part.name} (${(norm(sub(part.p, target.p)) * 1000).toFixed(1)} mm)`);

  /**
   * One drag of the tool's handle: the pointer pressed on the handle, moved as a person watching
   * the tool would (toward where it should be, in the view's pixels, a little at a time) until
   * the tool is within `tolerance` of `goal` on the axes the view shows, then let go. `axes`:
   * the world axes the view's screen x and y show (top: x and y; side: x and z).
   */
  const held = [];
  const guide = (what, goal, axes, tolerance = 0.004) =>
    act(what, async () => {
      const box = await view.boundingBox();
      const onPage = async () => (await view.getAttribute('data-tool-screen')).split(',').map(Number);
      let [sx, sy] = await onPage();
      await page.mouse.move(box.x + sx, box.y + sy);
      await page.mouse.down();
      // Pixels per metre of the tool's motion, measured as it moves (first guess: 300).
      let scale = 300;
      let last = null;
      let error = [];
      let heldBack = null;
      for (let i = 0; i < 60; i += 1) {
        const tcp = (await truth()).tcp.p;
        error = axes.map((a) => goal[a] - tcp[a]);
        const [tx, ty] = await onPage();
        if (last) {
          const moved = norm(axes.map((a) => tcp[a] - last.tcp[a]));
          const pixels = norm([tx - last.screen[0], ty - last.screen[1]]);
          if (moved > 0.01) scale = pixels / moved;
        }
        if (norm(error) < tolerance) break;
        heldBack = (await page.textContent('.view3d-held-back', { timeout: 50 }).catch(() => null)) ?? heldBack;
        last = { tcp, screen: [tx, ty] };
        // Screen y grows downward: up in the view is +y (top) or +z (side).
        const step = Math.min(1, 0.05 / norm(error));
        sx = tx + error[0] * step * scale;
        sy = ty - error[1] * step * scale;
        await page.mouse.move(box.x + sx, box.y + sy, { steps: 3 });
        await page.waitForTimeout(500);
      }
      await page.mouse.up();
      await page.waitForTimeout(500);
      log(`  ${what}: ${(norm(error) * 1000).toFixed(1)} mm from where it should be${heldBack ? ` (the view said: ${heldBack})` : ''}`);
      held.push(heldBack);
    });

  // --- guide the tool above the part (top view: it keeps its height and orientation) -----------
  await click('click Top', '.view3d button:text("Top")');
  await click('click Translate (the tool keeps its orientation)', '.hand-guiding button:text("Translate")');
  await act('tick lock z (it keeps its height)', () => page.check('input[aria-label="lock z"]'));
  const above = [part.p[0], part.p[1], tcp0[2]];
  await guide(`drag the tool's handle over ${target.name} (top view)`, above, [0, 1]);
  const over = (await truth()).tcp.p;
  check(norm(sub(over.slice(0, 2), part.p.slice(0, 2))) < 0.01, `the tool is over ${part.name}: ${(norm(sub(over.slice(0, 2), part.p.slice(0, 2))) * 1000).toFixed(1)} mm off, at the height it had (${(Math.abs(over[2] - tcp0[2]) * 1000).toFixed(1)} mm)`);
  await page.screenshot({ path: path.join(artifacts, 'teach_guided_over_the_part_1280x800.png') });

  // --- the fingers turned square to the part: the yaw jogged 10 degrees at a time ----------------
  // (the handle pulls the tool by its centre point: a drag moves it, the jog buttons turn it)
  for (let i = 0; i < 6; i += 1) {
    const now = await truth();
    const turn = quarter(heading(part.q) - heading(now.tcp.q));
    if (Math.abs(turn) <= 5) break;
    await click(`click jog yaw ${turn > 0 ? 'plus' : 'minus'} (the fingers ${turn.toFixed(0)} degrees off the part's faces)`, `button[aria-label="jog yaw ${turn > 0 ? 'plus' : 'minus'}"]`);
    await page.waitForSelector('button[aria-label="jog yaw plus"]:not([disabled])', { timeout: 30000 });
    await page.waitForTimeout(300);
  }
  const squared = quarter(heading(part.q) - heading((await truth()).tcp.q));
  check(Math.abs(squared) <= 5, `the fingers close square to ${part.name}'s faces: ${squared.toFixed(1)} degrees off`);

  // --- a waypoint above the part, relative to it ------------------------------------------------
  await fill('type the waypoint name above_part', 'input[aria-label="waypoint name"]', 'above_part');
  await choose2('relative to', `in ${target.name}`);
  async function choose2(label, text) {
    await act(`choose ${label} = ${text}`, () => page.selectOption(`select[aria-label="${label}"]`, { label: text }));
  }
  await click('click Teach here', '.waypoints button:text("Teach here")');
  await page.waitForFunction(() => [...document.querySelectorAll('.waypoint-table td')].some((td) => td.textContent.includes('above_part')), null, { timeout: 30000 });

  // --- lower the tool around the part (side view) and teach the grasp --------------------------
  await act('untick lock z', () => page.uncheck('input[aria-label="lock z"]'));
  await act('tick lock y (the side view shows x and z)', () => page.check('input[aria-label="lock y"]'));
  await click('click Side', '.view3d button:text("Side")');
  const grasp = [part.p[0], part.p[1], part.p[2] + 0.005];
  await guide(`drag the tool's handle down around ${target.name} (side view)`, grasp, [0, 2]);
  const lowered = (await truth()).tcp.p;
  log(`the tool at ${lowered.map((v) => v.toFixed(3)).join(', ')}; the part at ${part.p.map((v) => v.toFixed(3)).join(', ')}`);
  await page.screenshot({ path: path.join(artifacts, 'teach_guided_down_1280x800.png') });
  await choose2('grasp class', 'node');
  await fill('type the grasp name taught', 'input[aria-label="grasp name"]', 'taught');
  await click('click Teach grasp', '.hand-guiding button:text("Teach grasp")');
  for (let i = 0; i < 100 && !((await api(url, token, 'GET', '/api/choices')).json.grasp.node ?? []).includes('taught'); i += 1) await page.waitForTimeout(200);
  const pickActions = counter.actions;
  check(pickActions <= MAX_PICK_ACTIONS, `a pick taught from scratch in ${pickActions} UI actions (at most ${MAX_PICK_ACTIONS}): detect, guide the tool there, teach the waypoint and the grasp`);
  fs.writeFileSync(path.join(artifacts, 'actions_teach_pick.txt'), `${pickActions}\n`);
  const choices = (await api(url, token, 'GET', '/api/choices')).json;
  check((choices.grasp.node ?? []).includes('taught'), `the grasp is offered for nodes: ${(choices.grasp.node ?? []).join(', ')}`);
  const taught = choices.grasp_pose?.node?.taught;
  log(`the grasp taught: the tool centre point ${taught ? taught.p.map((v) => (v * 1000).toFixed(1)).join(', ') : '?'} mm from the node's centre (data/grasps.json's: 0, 0, 5)`);
  // The taught grasp drawn on the part in the 3D view: the open gripper at the tool centre point.
  await page.waitForFunction((name) => name in JSON.parse(document.querySelector('.view3d-canvas')?.getAttribute('data-grasp-screens') ?? '{}'), target.name, { timeout: 30000 });
  const caption = await page.textContent('.view3d-grasp');
  check(caption.includes("grasp 'taught'") && caption.includes(target.name), `the 3D view draws the taught grasp on the part: "${caption}"`);
  const drawnAt = JSON.parse(await view.getAttribute('data-grasp-screens'))[target.name];
  const partAt = JSON.parse(await view.getAttribute('data-part-screens'))[target.name];
  check(norm(sub(drawnAt, partAt)) < 20, `the grasp is drawn on ${target.name}: ${norm(sub(drawnAt, partAt)).toFixed(1)} px from the part's centre on the screen`);
  await page.screenshot({ path: path.join(artifacts, 'teach_grasp_drawn_1280x800.png') });

  // --- record a stroke: up and across (side view) -----------------------------------------------
  await fill('type the trajectory name carry', 'input[aria-label="trajectory name"]', 'carry');
  const strokeEnd = [lowered[0] + 0.1, lowered[1], lowered[2] + 0.08];
  await guide('drag the tool up and across (recorded)', strokeEnd, [0, 2], 0.008);
  await page.waitForFunction(() => [...document.querySelectorAll('select[aria-label="trajectory"] option')].some((o) => o.value === 'carry'), null, { timeout: 30000 });
  const recorded = (await api(url, token, 'GET', '/api/choices')).json.trajectory_line?.carry?.points ?? [];
  check(recorded.length >= 2, `the stroke is recorded as 'carry' (${recorded.length} poses kept) and drawn as a line`);
  await page.screenshot({ path: path.join(artifacts, 'teach_recorded_1280x800.png') });

  // --- the plan by clicks ---------------------------------------------------------------------
  await palette('Move');
  await choose('waypoint', 'above_part');
  await palette('SmartGrasp');
  await choose('object_class', 'node');
  await choose('grasp', 'taught');
  await palette('FollowTrajectory');
  await choose('trajectory', 'carry');
  await palette('Open');
  await fill('type the plan name', 'input[aria-label="plan name"]', 'taught_pick');
  const before = await truth();
  await click('click Run (saves the plan first)', 'button.run');
  const actions = counter.actions;
  check(actions <= MAX_ACTIONS, `the whole task took ${actions} UI actions (at most ${MAX_ACTIONS})`);
  fs.writeFileSync(path.join(artifacts, 'actions_teach.txt'), `${actions}\n`);
  await page.screenshot({ path: path.join(artifacts, 'teach_plan_1280x800.png') });
  const { result, label } = await waitForRunEnd(page, 300);
  check(result === 'SUCCESS', `the run ended with ${result}: ${label}`);
  await page.screenshot({ path: path.join(artifacts, 'teach_ran_1280x800.png') });

  // --- judged from the simulator's true state ---------------------------------------------------
  const after = await truth();
  const moved = after.parts.find((p) => p.name === part.name);
  const startOf = before.parts.find((p) => p.name === part.name);
  const shift = sub(moved.p, startOf.p);
  log(`${part.name} moved ${shift.map((v) => (v * 1000).toFixed(0)).join(', ')} mm`);
  check(Math.abs(shift[0] - (strokeEnd[0] - lowered[0])) < 0.03 && Math.abs(shift[1]) < 0.03, `${part.name} was carried along the stroke: ${(shift[0] * 1000).toFixed(0)} mm along x (the stroke ${((strokeEnd[0] - lowered[0]) * 1000).toFixed(0)} mm), ${(shift[1] * 1000).toFixed(0)} mm across`);
  check(after.arm_table_contact_steps === start.arm_table_contact_steps, 'the arm never touched the table');
  check(pageErrors.length === 0, `no page errors (${pageErrors.join('; ')})`);
}

await runScript('teach', main, { log, artifacts, shot: 'teach_failure.png', resources: () => ({ browser, server }) });
