// End-to-end test: every simulated cell drawn as it is (Debian's Chromium, headless, driven by
// playwright-core, against `costar serve --workcell CELL`): the arm and its gripper built from
// the URDF the planner reads (GET /api/robot), the tool centre point as drawn within 5 mm and 1°
// of the arm's own `endpoint` symbol (at home and after jogging a joint), the jog pane with the cell's
// joints (J1-J6 on the UR5, J1-J7 on the iiwa) and a live tool pose and joint readout, the
// 3-finger gripper's fingers drawn from its reading (closing them changes the drawing).
// Screenshots at 1280x800 of each cell after a detection.
//
//   node web/e2e/cells.mjs [--costar build/cli/costar] [--artifacts build/test-artifacts]
//                          [--cells ur5-sim,iiwa-sim,iiwa-3f-sim,panda-sim] [--docs-screenshots docs]
// (--docs-screenshots: each cell's screenshot there as editor_CELL_1280x800.png)

import fs from 'node:fs';
import path from 'node:path';
import { api, args, artifacts, launchBrowser, makeLog, openPage, runScript, startServer } from './lib.mjs';

const { log, check } = makeLog('cells');
// Every simulated cell (workcells/*.json) with its arm's joint count (robots/ROBOT/ROBOT.json): a new cell is tried here
// with no list to edit.
const CELLS = Object.fromEntries(
  fs
    .readdirSync('workcells')
    .filter((file) => file.endsWith('.json'))
    .sort()
    .map((file) => {
      const robot = JSON.parse(fs.readFileSync(path.join('workcells', file), 'utf8')).robot;
      const joints = JSON.parse(fs.readFileSync(path.join('robots', robot, `${robot}.json`), 'utf8')).joints.length;
      return [file.replace(/\.json$/, ''), joints];
    }),
);
const MAX_ERROR_MM = 5;
const MAX_ERROR_DEG = 1;
let server;
let browser;

async function waitOperation(url, token, page, id) {
  for (let i = 0; i < 600; i++) {
    const status = (await api(url, token, 'GET', `/api/runs/${id}`)).json;
    if (status && status.active === false) return status;
    await page.waitForTimeout(100);
  }
  throw new Error(`operation ${id} did not end`);
}

/** The angle between two quaternions [x, y, z, w] (degrees; normalised first: the stream rounds). */
function angleDegrees(a, b) {
  const norm = (q) => Math.hypot(...q);
  const dot = Math.abs(a.reduce((sum, v, i) => sum + v * b[i], 0)) / (norm(a) * norm(b));
  return (2 * Math.acos(Math.min(1, dot)) * 180) / Math.PI;
}

/**
 * The drawn tool centre point against the arm's endpoint symbol, once the page has caught up:
 * the position (mm) and the orientation (degrees).
 */
async function drawnError(page, url, token) {
  let error = Infinity;
  let angle = Infinity;
  let drawn = [];
  let endpoint = [];
  for (let i = 0; i < 30; i++) {
    const pose = (await api(url, token, 'GET', '/api/state')).json.arm.endpoint;
    endpoint = pose.p;
    await page.waitForTimeout(200);
    drawn = ((await page.getAttribute('.view3d-canvas', 'data-drawn-tool')) ?? '').split(',').map(Number);
    const drawnQ = ((await page.getAttribute('.view3d-canvas', 'data-drawn-tool-q')) ?? '').split(',').map(Number);
    if (drawn.length === 3 && drawnQ.length === 4) {
      const e = 1000 * Math.hypot(...drawn.map((v, i) => v - endpoint[i]));
      if (e < error) {
        error = e;
        angle = angleDegrees(drawnQ, pose.q);
      }
    }
    if (error < MAX_ERROR_MM && angle < MAX_ERROR_DEG) break;
  }
  return { error, angle, drawn, endpoint };
}

async function cell(name, joints, figures) {
  server = await startServer({ workcell: name, scene: 'sim/scenes/assembly.json', pace: 0 });
  const { url, open, token } = server;
  const errors = [];
  const { page, context } = await openPage(browser, open, errors, { width: 1280, height: 800 });
  await page.waitForSelector(`.view3d-canvas[data-robot]:not([data-robot=""])`, { timeout: 30000 });
  const robot = (await api(url, token, 'GET', '/api/robot')).json;
  check((await page.getAttribute('.view3d-canvas', 'data-robot')) === robot.name, `${name}: the 3D view draws the cell's robot (${robot.label}) from its URDF`);

  const home = await drawnError(page, url, token);
  check(
    home.error < MAX_ERROR_MM && home.angle < MAX_ERROR_DEG,
    `${name}: at home the drawn tool centre point is ${home.error.toFixed(2)} mm and ${home.angle.toFixed(3)}° from the arm's endpoint symbol (${home.endpoint.map((v) => v.toFixed(3))})`,
  );

  const shown = await page.$$eval('.jog-grid.joints .jog-pair', (p) => p.map((x) => x.textContent?.trim().slice(0, 2)));
  check(shown.length === joints && shown[joints - 1] === `J${joints}`, `${name}: the jog pane has the cell's ${joints} joints (${shown.join(' ')})`);
  const state = (await api(url, token, 'GET', '/api/state')).json;
  const readoutX = Number(((await page.textContent('[data-readout="X"]')) ?? '').replace(/[^-\d.]/g, ''));
  check(Math.abs(readoutX - state.arm.endpoint.p[0] * 1000) < 0.15, `${name}: the tool readout shows X ${readoutX} mm (the endpoint: ${(state.arm.endpoint.p[0] * 1000).toFixed(1)})`);

  // Jog a joint from the pane: the drawing follows.
  await page.click(`button[aria-label="jog J${joints === 7 ? 4 : 2} plus"]`);
  await page.waitForFunction(() => /^JogJoint: SUCCESS/.test(document.querySelector('.status-line .message')?.textContent ?? ''), null, { timeout: 30000 });
  const jogged = await drawnError(page, url, token);
  const moved = 1000 * Math.hypot(...jogged.endpoint.map((v, i) => v - home.endpoint[i]));
  check(
    moved > 5 && jogged.error < MAX_ERROR_MM && jogged.angle < MAX_ERROR_DEG,
    `${name}: jogged ${moved.toFixed(0)} mm, the drawn tool is ${jogged.error.toFixed(2)} mm and ${jogged.angle.toFixed(3)}° from the endpoint`,
  );
  figures[name] = {
    home_mm: Number(home.error.toFixed(3)),
    home_deg: Number(home.angle.toFixed(3)),
    jogged_mm: Number(jogged.error.toFixed(3)),
    jogged_deg: Number(jogged.angle.toFixed(3)),
    joints,
  };

  if (robot.gripper.kind === 'adaptive') {
    check(Number(await page.getAttribute('.view3d-canvas', 'data-finger-boxes')) === 9, `${name}: the 3 fingers are drawn, 3 phalanges each`);
    const before = (await api(url, token, 'GET', '/api/state')).json.gripper.reading.positions;
    const closing = await api(url, token, 'POST', '/api/operations', { node: 'Close' });
    await waitOperation(url, token, page, closing.json.run);
    const after = (await api(url, token, 'GET', '/api/state')).json.gripper.reading;
    check(after.names.join(',') === 'finger_middle,finger_1,finger_2' && after.positions.every((p, i) => p > before[i] + 0.5), `${name}: Close closes every finger (reading ${before} → ${after.positions})`);
    await page.waitForTimeout(400);
    await page.screenshot({ path: path.join(artifacts, `cell_${name}_closed_1280x800.png`) });
    const opening = await api(url, token, 'POST', '/api/operations', { node: 'Open' });
    await waitOperation(url, token, page, opening.json.run);
  } else {
    check(Number(await page.getAttribute('.view3d-canvas', 'data-finger-boxes')) === 4, `${name}: the 2 fingers are drawn (a link and a pad each)`);
  }

  // The cell with its parts, as a technician sees it.
  await page.click('.menu button:text-is("Detect objects")');
  await page.waitForFunction(() => document.querySelectorAll('.objects-table tbody tr').length >= 3, null, { timeout: 60000 });
  await page.waitForTimeout(800);
  const shot = path.join(artifacts, `editor_${name}_1280x800.png`);
  await page.screenshot({ path: shot });
  if (args['docs-screenshots']) fs.copyFileSync(shot, path.join(path.resolve(args['docs-screenshots']), `editor_${name}_1280x800.png`));
  check(errors.length === 0, `${name}: no errors in the page${errors.length ? ': ' + errors.join('; ') : ''}`);
  await context.close();
  server.stop();
  server = undefined;
}

async function main() {
  browser = await launchBrowser();
  const figures = {};
  const names = (args.cells ?? Object.keys(CELLS).join(',')).split(',');
  for (const name of names) await cell(name, CELLS[name], figures);
  fs.writeFileSync(path.join(artifacts, 'cells_drawn_vs_endpoint.json'), JSON.stringify(figures, null, 2));
  log('drawn tool centre point against the endpoint symbol (mm, degrees):', JSON.stringify(figures));
}

await runScript('cells', main, { log, artifacts, shot: 'cells_failure.png', resources: () => ({ browser, server }) });
