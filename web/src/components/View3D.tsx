// Pane 2: the cell in 3D (three.js): the robot the cell has, drawn from the URDF its planner
// reads (GET /api/robot, model/drawnRobot.ts) with the joint angles the stream carries and
// the fingers from the gripper's reading, the table, the parts the system believes are there,
// the person's hand and forearm where the camera sees the hand
// (object symbols; a held part moves with the tool), each drawn as its class's boxes in its
// class's colour, the waypoints, SmartMove's candidates, and on request the RGB-D camera's
// point cloud, the trajectories recorded by hand guiding as lines, and a grasp (the one taught
// last, or chosen under the waypoints) as the open gripper on every part of its class, with its
// name and the gripper mode it needs; over it, with a person in the cell, the speed and separation
// monitor's reading (SafetyStrip). During a replay it shows
// the run's logged snapshots, not the cell now. Drag to orbit, wheel to zoom; grab the tool's
// handle (the sphere at the tool) and drag to guide the arm by hand (free-drive, model/handGuide.ts:
// the arm moves while the pointer is held and stops when it is let go).

import { useEffect, useRef, useState } from 'react';
import * as THREE from 'three';
import type { Believed } from '../model/belief';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import type { Api, ApiError, CellState, ObjectShape } from '../api';
import { partLook } from '../model/parts';
import { DrawnRobot } from '../model/drawnRobot';
import type { RobotDescription } from '../model/robot';
import type { Candidate } from './ObjectsPane';
import { ForceStrip } from './ForceStrip';
import { SafetyStrip } from './SafetyStrip';
import { handForce, HAND_PERIOD_MS, type Vec3 } from '../model/handGuide';
import { graspCaption, graspOnParts, type GraspPose, type PlacedGrasp } from '../model/graspDrawing';

interface Props {
  state: CellState | null;
  candidates: Candidate[];
  selectedWaypoint: string | null;
  api: Api;
  pointCloudAvailable: boolean;
  /** Each object class's boxes and colours (GET /api/choices). */
  shapes?: Record<string, ObjectShape>;
  /** Where the system believes each part is (a held part moves with the tool). */
  believed?: Believed;
  /** The cell's robot (GET /api/robot); null until it is read, or for a cell without one. */
  robot: RobotDescription | null;
  /** Replaying a run: what the view shows then (e.g. "run #3 at t = 12.4 s"). */
  replayLabel?: string;
  /** Free-drive: starts FreeDrive when the tool's handle is grabbed (false: refused, with its
   * reason shown by the page); absent: the handle cannot be grabbed (a replay, no arm). */
  onGrab?: () => Promise<boolean>;
  /** Recorded trajectories' kept points in the world, drawn as lines. */
  trajectoryLines?: Record<string, { points: [number, number, number][] }>;
  /** A grasp drawn on every part of its class: the open gripper where SmartGrasp would hold it. */
  grasp?: { objectClass: string; name: string; pose: GraspPose };
}

interface Scene {
  renderer: THREE.WebGLRenderer;
  scene: THREE.Scene;
  camera: THREE.PerspectiveCamera;
  controls: OrbitControls;
  robot: THREE.Group;
  table: THREE.Mesh;
  grid: THREE.GridHelper;
  parts: THREE.Group;
  waypoints: THREE.Group;
  candidates: THREE.Group;
  cloud: THREE.Group;
  trajectories: THREE.Group;
  grasps: THREE.Group;
  handle: THREE.Mesh;
  render: () => void;
}

function clear(group: THREE.Group) {
  for (const child of [...group.children]) {
    group.remove(child);
    child.traverse((o) => {
      const mesh = o as THREE.Mesh;
      mesh.geometry?.dispose?.();
      const material = mesh.material as THREE.Material | THREE.Material[] | undefined;
      if (Array.isArray(material)) material.forEach((m) => m.dispose());
      else material?.dispose?.();
    });
  }
}

/** The directions the 3D view looks from (toward the cell): 3D, from above, from the side. */
const VIEWS: Record<'3D' | 'Top' | 'Side', [number, number, number]> = {
  '3D': [1.05, -0.95, 0.6],
  Top: [0, -0.12, 1],
  Side: [0, -1, 0.12],
};

/** A part: its class's boxes in the object frame, in the colour perception saw on it (else its class's). */
function partMesh(objectClass: string, shapes: Record<string, ObjectShape> | undefined, seen: unknown) {
  const look = partLook(objectClass, shapes, seen);
  const material = new THREE.MeshLambertMaterial({ color: new THREE.Color(...look.rgb) });
  const group = new THREE.Group();
  for (const box of look.boxes) {
    const mesh = new THREE.Mesh(new THREE.BoxGeometry(...box.size), material);
    mesh.position.set(...box.center);
    group.add(mesh);
  }
  return group;
}

/** The open gripper at a grasp, in the tool centre point's frame (z along the approach, the
 *  fingers closing along y): two pads either side of the tool centre point, the palm behind them
 *  and the way the arm comes in, in teal. */
function graspMarker(placed: PlacedGrasp) {
  const material = new THREE.MeshLambertMaterial({ color: 0x0f9d9a, transparent: true, opacity: 0.75 });
  const group = new THREE.Group();
  group.name = placed.part;
  for (const side of [-1, 1]) {
    const pad = new THREE.Mesh(new THREE.BoxGeometry(0.022, 0.006, 0.04), material);
    pad.position.set(0, side * 0.035, 0);
    group.add(pad);
  }
  const palm = new THREE.Mesh(new THREE.BoxGeometry(0.022, 0.076, 0.008), material);
  palm.position.set(0, 0, -0.024);
  group.add(palm);
  const tcp = new THREE.Mesh(new THREE.SphereGeometry(0.004, 10, 8), material);
  group.add(tcp);
  const approach = new THREE.BufferGeometry().setFromPoints([new THREE.Vector3(0, 0, -0.028), new THREE.Vector3(0, 0, -0.1)]);
  group.add(new THREE.Line(approach, new THREE.LineBasicMaterial({ color: 0x0f9d9a })));
  group.position.set(...placed.p);
  group.quaternion.set(...placed.q);
  return group;
}

export function View3D({ state, candidates, selectedWaypoint, api, pointCloudAvailable, shapes, believed, robot, replayLabel, onGrab, trajectoryLines, grasp }: Props) {
  const mount = useRef<HTMLDivElement>(null);
  const sceneRef = useRef<Scene | null>(null);
  const [drawn, setDrawn] = useState<DrawnRobot | null>(null);
  const [drawnTool, setDrawnTool] = useState('');
  const [drawnToolQ, setDrawnToolQ] = useState('');
  // Where the person's hand is drawn (x,y,z, m), '' when the camera does not see it.
  const [handDrawn, setHandDrawn] = useState('');
  const framed = useRef(false);
  const [error, setError] = useState<string | null>(null);
  const [cloudInfo, setCloudInfo] = useState<string>('');
  const [cloudTime, setCloudTime] = useState<number | null>(null);
  const [toolScreen, setToolScreen] = useState('');
  const [partScreens, setPartScreens] = useState('{}');
  const [graspScreens, setGraspScreens] = useState('{}');
  const [graspText, setGraspText] = useState('');
  const [guiding, setGuiding] = useState(false);
  /** Why free-drive holds the tool back while it is guided (the server's answer to each push). */
  const [heldBack, setHeldBack] = useState('');
  const grabRef = useRef(onGrab);
  grabRef.current = onGrab;
  const apiRef = useRef(api);
  apiRef.current = api;

  useEffect(() => {
    const element = mount.current;
    if (!element) return;
    let renderer: THREE.WebGLRenderer;
    try {
      renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    } catch (e) {
      setError(`3D view unavailable: ${(e as Error).message}`);
      return;
    }
    renderer.setPixelRatio(window.devicePixelRatio);
    element.appendChild(renderer.domElement);
    const scene = new THREE.Scene();
    scene.background = new THREE.Color(0xf4f6fa);
    const camera = new THREE.PerspectiveCamera(45, 1, 0.01, 20);
    camera.up.set(0, 0, 1);
    camera.position.set(...VIEWS['3D']);
    const controls = new OrbitControls(camera, renderer.domElement);
    controls.target.set(0.35, -0.05, 0.12);
    scene.add(new THREE.HemisphereLight(0xffffff, 0x8899aa, 1.6));
    const sun = new THREE.DirectionalLight(0xffffff, 1.5);
    sun.position.set(1, -1, 2);
    scene.add(sun);
    // The table: resized to the cell's once its description is read.
    const table = new THREE.Mesh(new THREE.BoxGeometry(1, 1, 1), new THREE.MeshLambertMaterial({ color: 0xc8b69a }));
    table.scale.set(1.4, 1.2, 0.04);
    table.position.set(0.4, 0, -0.02);
    scene.add(table);
    const grid = new THREE.GridHelper(1.2, 12, 0x998877, 0xb0a08a);
    grid.rotation.x = Math.PI / 2;
    grid.position.set(0.4, 0, 0.001);
    scene.add(grid);
    const axes = new THREE.AxesHelper(0.15);
    scene.add(axes);
    const robotGroup = new THREE.Group();
    const parts = new THREE.Group();
    const waypoints = new THREE.Group();
    const candidateGroup = new THREE.Group();
    const cloud = new THREE.Group();
    const trajectories = new THREE.Group();
    const grasps = new THREE.Group();
    // The tool's handle: what the user grabs to guide the arm.
    const handle = new THREE.Mesh(
      new THREE.SphereGeometry(0.03, 16, 12),
      new THREE.MeshLambertMaterial({ color: 0x7a4fd6, transparent: true, opacity: 0.35, depthWrite: false }),
    );
    handle.visible = false;
    scene.add(robotGroup, parts, waypoints, candidateGroup, cloud, trajectories, grasps, handle);
    const render = () => {
      renderer.render(scene, camera);
      // Where the tool and the parts are drawn (canvas pixels): what a user aims at.
      const rect = renderer.domElement.getBoundingClientRect();
      const onScreen = (v: THREE.Vector3) => {
        const p = v.clone().project(camera);
        return [Number((((p.x + 1) / 2) * rect.width).toFixed(1)), Number((((1 - p.y) / 2) * rect.height).toFixed(1))];
      };
      if (handle.visible) setToolScreen(onScreen(handle.position).join(','));
      setPartScreens(JSON.stringify(Object.fromEntries(parts.children.map((part) => [part.name, onScreen(part.position)]))));
      setGraspScreens(JSON.stringify(Object.fromEntries(grasps.children.map((g) => [g.name, onScreen(g.position)]))));
    };
    controls.addEventListener('change', render);
    const resize = () => {
      const width = element.clientWidth || 400;
      const height = element.clientHeight || 300;
      renderer.setSize(width, height);
      camera.aspect = width / height;
      camera.updateProjectionMatrix();
      render();
    };
    const observer = new ResizeObserver(resize);
    observer.observe(element);
    resize();
    sceneRef.current = { renderer, scene, camera, controls, robot: robotGroup, table, grid, parts, waypoints, candidates: candidateGroup, cloud, trajectories, grasps, handle, render };

    // Grabbing the handle: the pointer holds the tool on the plane through it facing the camera;
    // every 50 ms the page sends the hand's push toward where the pointer holds it.
    let grab: { plane: THREE.Plane; target: THREE.Vector3; timer: number; pointer: number } | null = null;
    const ray = new THREE.Raycaster();
    const pointerRay = (event: PointerEvent) => {
      const rect = renderer.domElement.getBoundingClientRect();
      ray.setFromCamera(
        new THREE.Vector2(((event.clientX - rect.left) / rect.width) * 2 - 1, -((event.clientY - rect.top) / rect.height) * 2 + 1),
        camera,
      );
      return ray;
    };
    const letGo = () => {
      if (!grab) return;
      window.clearInterval(grab.timer);
      grab = null;
      controls.enabled = true;
      setGuiding(false);
      setHeldBack('');
      apiRef.current.drag({ release: true }).catch(() => undefined);
    };
    const onDown = async (event: PointerEvent) => {
      if (!grabRef.current || !handle.visible || event.button !== 0) return;
      if (pointerRay(event).intersectObject(handle).length === 0) return;
      event.stopPropagation();
      controls.enabled = false;
      const normal = camera.getWorldDirection(new THREE.Vector3());
      const plane = new THREE.Plane().setFromNormalAndCoplanarPoint(normal, handle.position);
      grab = { plane, target: handle.position.clone(), timer: 0, pointer: event.pointerId };
      renderer.domElement.setPointerCapture(event.pointerId);
      setGuiding(true);
      const started = await grabRef.current();
      if (!started || !grab) {
        letGo();
        return;
      }
      let rearming = false;
      grab.timer = window.setInterval(() => {
        if (!grab) return;
        const tool = handle.position;
        const force = handForce([tool.x, tool.y, tool.z] as Vec3, [grab.target.x, grab.target.y, grab.target.z] as Vec3);
        apiRef.current.drag({ force }).then((answer) => {
          if (grab) setHeldBack(answer.blocked ?? '');
        }, (e) => {
          // The server's dead-man lapsed (a push came late) while the pointer is still held:
          // free-drive again, as a hand still on the button would.
          if ((e as ApiError).status === 409 && grab && !rearming && grabRef.current) {
            rearming = true;
            grabRef.current().finally(() => (rearming = false));
          }
        });
      }, HAND_PERIOD_MS);
    };
    const onMove = (event: PointerEvent) => {
      if (!grab) return;
      pointerRay(event).ray.intersectPlane(grab.plane, grab.target);
    };
    renderer.domElement.addEventListener('pointerdown', onDown, { capture: true });
    renderer.domElement.addEventListener('pointermove', onMove);
    renderer.domElement.addEventListener('pointerup', letGo);
    renderer.domElement.addEventListener('pointercancel', letGo);
    window.addEventListener('blur', letGo);
    return () => {
      letGo();
      window.removeEventListener('blur', letGo);
      observer.disconnect();
      controls.dispose();
      renderer.dispose();
      element.removeChild(renderer.domElement);
      sceneRef.current = null;
    };
  }, []);

  // The robot the cell has, built once its description is read; the table it stands by.
  useEffect(() => {
    const s = sceneRef.current;
    if (!s || !robot) return;
    if (robot.table) {
      s.table.scale.set(...robot.table.size);
      s.table.position.set(...robot.table.centre);
      s.grid.position.set(robot.table.centre[0], robot.table.centre[1], robot.table.centre[2] + robot.table.size[2] / 2 + 0.001);
    }
    let built: DrawnRobot;
    try {
      built = new DrawnRobot(robot);
    } catch (e) {
      setError(`the robot cannot be drawn: ${(e as Error).message}`);
      return;
    }
    // The scene's fixtures (a workpiece, a tool stand), where the planner avoids them.
    const fixtures = new THREE.Group();
    for (const f of robot.fixtures ?? []) {
      const box = new THREE.Mesh(new THREE.BoxGeometry(...f.size), new THREE.MeshStandardMaterial({ color: new THREE.Color(...f.rgb) }));
      box.position.set(...f.p);
      box.quaternion.set(...f.q);
      box.name = f.name;
      fixtures.add(box);
    }
    s.robot.add(fixtures);
    s.robot.add(built.object);
    setDrawn(built);
    framed.current = false;
    return () => {
      s.robot.remove(fixtures);
      fixtures.traverse((o) => o instanceof THREE.Mesh && (o.geometry.dispose(), (o.material as THREE.Material).dispose()));
      s.robot.remove(built.object);
      built.dispose();
      setDrawn(null);
    };
  }, [robot]);

  // The robot, the parts and the waypoints follow the stream (or the replayed run).
  useEffect(() => {
    const s = sceneRef.current;
    if (!s || !state) return;
    if (drawn) {
      drawn.update(state.arm.joints, state.gripper.reading, state.gripper.mode, state.tool?.held ?? false);
      const tool = drawn.toolPose();
      s.handle.visible = !!onGrab;
      s.handle.position.copy(tool.position);
      s.handle.quaternion.copy(tool.quaternion);
      setDrawnTool([tool.position.x, tool.position.y, tool.position.z].map((v) => v.toFixed(5)).join(','));
      setDrawnToolQ([tool.quaternion.x, tool.quaternion.y, tool.quaternion.z, tool.quaternion.w].map((v) => v.toFixed(6)).join(','));
      if (!framed.current) {
        framed.current = true; // the robot as it stands: frame the cell around it once
        look('3D');
      }
    }
    clear(s.parts);
    for (const object of state.objects) {
      const pose = believed?.poses.get(object.name) ?? object;
      const mesh = partMesh(object.class, shapes, object.color);
      mesh.name = object.name;
      mesh.position.set(...pose.p);
      mesh.quaternion.set(...pose.q);
      s.parts.add(mesh);
    }
    clear(s.grasps);
    if (grasp) {
      const poses = state.objects.map((object) => {
        const pose = believed?.poses.get(object.name) ?? object;
        return { name: object.name, class: object.class, p: pose.p, q: pose.q };
      });
      const placed = graspOnParts(poses, grasp.objectClass, grasp.pose);
      for (const g of placed) s.grasps.add(graspMarker(g));
      setGraspText(graspCaption(grasp.name, grasp.pose, placed));
    } else {
      setGraspText('');
    }
    // The person's hand as the camera sees it (the frame hand_1), drawn as the boxes SmartMove
    // plans around: the hand on its frame, the forearm behind it (docs/PERSON.md).
    const hand = state.frames.find((f) => f.name === 'hand_1');
    if (hand) {
      const skin = new THREE.MeshLambertMaterial({ color: 0xd9a27e, transparent: true, opacity: 0.8 });
      const person = new THREE.Group();
      person.name = 'hand_1';
      for (const [size, x] of [[[0.26, 0.12, 0.08], 0], [[0.3, 0.1, 0.1], -0.28]] as const) {
        const box = new THREE.Mesh(new THREE.BoxGeometry(...size), skin);
        box.position.set(x, 0, 0);
        person.add(box);
      }
      person.position.set(...hand.p);
      person.quaternion.set(...hand.q);
      s.parts.add(person);
    }
    setHandDrawn(hand ? hand.p.map((v) => v.toFixed(3)).join(',') : '');
    clear(s.waypoints);
    for (const waypoint of state.waypoints) {
      if (!waypoint.p) continue;
      const selected = waypoint.name === selectedWaypoint;
      const ball = new THREE.Mesh(
        new THREE.SphereGeometry(selected ? 0.018 : 0.012, 12, 8),
        new THREE.MeshLambertMaterial({ color: selected ? 0xff6600 : 0xf0ad4e }),
      );
      ball.position.set(...waypoint.p);
      s.waypoints.add(ball);
      if (waypoint.q) {
        const direction = new THREE.Vector3(0, 0, 1).applyQuaternion(new THREE.Quaternion(...waypoint.q));
        s.waypoints.add(new THREE.ArrowHelper(direction, ball.position, 0.06, 0xf0ad4e));
      }
    }
    s.render();
  }, [state, selectedWaypoint, shapes, believed, drawn, onGrab, grasp]);

  useEffect(() => {
    const s = sceneRef.current;
    if (!s) return;
    clear(s.trajectories);
    for (const line of Object.values(trajectoryLines ?? {})) {
      if (line.points.length < 2) continue;
      const geometry = new THREE.BufferGeometry().setFromPoints(line.points.map((p) => new THREE.Vector3(...p)));
      s.trajectories.add(new THREE.Line(geometry, new THREE.LineBasicMaterial({ color: 0x7a4fd6 })));
    }
    s.render();
  }, [trajectoryLines]);

  useEffect(() => {
    const s = sceneRef.current;
    if (!s) return;
    clear(s.candidates);
    for (const c of candidates) {
      const ball = new THREE.Mesh(
        new THREE.SphereGeometry(c.chosen ? 0.012 : 0.007, 10, 8),
        new THREE.MeshLambertMaterial({ color: c.chosen ? 0x22aa22 : c.rejected ? 0xcc3333 : 0x3366cc }),
      );
      ball.position.set(...c.goal);
      s.candidates.add(ball);
    }
    s.render();
  }, [candidates]);

  /** Looks at the whole cell (the table and the robot) from a direction, as close as the pane allows. */
  const look = (view: keyof typeof VIEWS) => {
    const s = sceneRef.current;
    if (!s) return;
    s.scene.updateMatrixWorld(true);
    // The corners of the table's middle (where the parts lie; its edges may leave the view) and
    // of the robot's box (not of one box round both: its far corners would stand in empty air).
    const table = new THREE.Box3().setFromObject(s.table);
    const middle = table.clone().expandByVector(table.getSize(new THREE.Vector3()).multiply(new THREE.Vector3(-0.2, -0.2, 0)));
    const boxes = [middle, new THREE.Box3().setFromObject(s.robot)].filter((b) => !b.isEmpty());
    const corners = boxes.flatMap((b) =>
      [b.min.x, b.max.x].flatMap((x) => [b.min.y, b.max.y].flatMap((y) => [b.min.z, b.max.z].map((z) => new THREE.Vector3(x, y, z)))),
    );
    const centre = boxes.reduce((box, b) => box.union(b), new THREE.Box3()).getCenter(new THREE.Vector3());
    // The nearest camera along `view` that has every corner in the frustum.
    const back = new THREE.Vector3(...VIEWS[view]).normalize();
    const right = new THREE.Vector3(0, 0, 1).cross(back).normalize();
    const up = back.clone().cross(right);
    const vertical = Math.tan(THREE.MathUtils.degToRad(s.camera.fov) / 2);
    const horizontal = vertical * s.camera.aspect;
    let distance = 0;
    for (const corner of corners) {
      const p = corner.clone().sub(centre);
      const towards = p.dot(back);
      distance = Math.max(distance, towards + Math.abs(p.dot(right)) / horizontal, towards + Math.abs(p.dot(up)) / vertical);
    }
    s.camera.position.copy(centre).addScaledVector(back, distance * 1.04);
    s.controls.target.copy(centre);
    s.controls.update();
    s.render();
  };

  const loadCloud = async () => {
    const s = sceneRef.current;
    if (!s) return;
    setCloudInfo('capturing…');
    try {
      const cloud = await api.pointCloud(30000);
      clear(s.cloud);
      const geometry = new THREE.BufferGeometry();
      geometry.setAttribute('position', new THREE.Float32BufferAttribute(cloud.points, 3));
      if (cloud.colors.length === cloud.points.length) {
        geometry.setAttribute('color', new THREE.Float32BufferAttribute(cloud.colors.map((c) => c / 255), 3));
      }
      s.cloud.add(new THREE.Points(geometry, new THREE.PointsMaterial({ size: 0.004, vertexColors: cloud.colors.length > 0 })));
      s.render();
      setCloudInfo(`${cloud.points.length / 3} points`);
      setCloudTime(cloud.t ?? state?.t ?? null);
    } catch (e) {
      setCloudInfo((e as Error).message);
    }
  };

  return (
    <section className="pane view3d" aria-label="3D view">
      <h2>
        <span className="pane-number">2</span> Cell
        {(Object.keys(VIEWS) as (keyof typeof VIEWS)[]).map((view) => (
          <button key={view} type="button" className="small" onClick={() => look(view)}>
            {view}
          </button>
        ))}
        {pointCloudAvailable && (
          <>
            <button type="button" className="small" onClick={loadCloud}>
              Point cloud
            </button>
            <button
              type="button"
              className="small"
              onClick={() => {
                if (sceneRef.current) {
                  clear(sceneRef.current.cloud);
                  sceneRef.current.render();
                }
                setCloudInfo('');
                setCloudTime(null);
              }}
            >
              Hide
            </button>
            <span className="dim">{cloudInfo}</span>
            {cloudTime !== null && state && (
              <span className={`pointcloud-age ${state.t - cloudTime > 5 ? 'stale' : ''}`} title="The point cloud is a snapshot: capture it again to see the cell now">
                taken {Math.max(0, state.t - cloudTime).toFixed(0)} s ago
              </span>
            )}
          </>
        )}
      </h2>
      {replayLabel && <div className="view3d-replay">{replayLabel}</div>}
      {guiding && heldBack && (
        <div className="view3d-held-back" role="status">
          Held back: {heldBack}
        </div>
      )}
      {graspText && (
        <div className="view3d-grasp" role="note" title="the open gripper drawn where SmartGrasp puts the tool centre point on each part of the class">
          {graspText}
        </div>
      )}
      <SafetyStrip state={state} />
      <ForceStrip state={state} />
      {error ? (
        <p className="empty">{error}</p>
      ) : (
        <div
          className={`view3d-canvas${guiding ? ' guiding' : ''}`}
          ref={mount}
          data-tool-screen={toolScreen}
          data-part-screens={partScreens}
          data-trajectories={Object.keys(trajectoryLines ?? {}).length}
          data-grasp-screens={graspScreens}
          data-drawn-tool={drawnTool} data-drawn-tool-q={drawnToolQ} data-robot={robot?.name ?? ''} data-hand={handDrawn} data-finger-boxes={drawn?.fingerBoxes() ?? 0} />
      )}
    </section>
  );
}
