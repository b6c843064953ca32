// Pane 2: the cell in 3D (three.js): the robot drawn along the UR5's Denavit-Hartenberg
// frames from the joint angles the stream carries, its gripper, the table, the parts the
// system believes are there (object symbols; a held part moves with the tool), each drawn as
// its class's boxes in its class's colour, the waypoints, SmartMove's candidates, and on
// request the RGB-D camera's point cloud. Drag to orbit, wheel to zoom.

import { useEffect, useRef, useState } from 'react';
import * as THREE from 'three';
import type { Believed } from '../model/belief';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import type { Api, CellState, ObjectShape } from '../api';
import { partLook } from '../model/parts';
import { position, ur5Frames } from '../model/kinematics';
import type { Candidate } from './ObjectsPane';

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
}

interface Scene {
  renderer: THREE.WebGLRenderer;
  scene: THREE.Scene;
  camera: THREE.PerspectiveCamera;
  controls: OrbitControls;
  robot: THREE.Group;
  parts: THREE.Group;
  waypoints: THREE.Group;
  candidates: THREE.Group;
  cloud: THREE.Group;
  render: () => void;
}

function cylinderBetween(a: THREE.Vector3, b: THREE.Vector3, radius: number, material: THREE.Material) {
  const length = a.distanceTo(b);
  const mesh = new THREE.Mesh(new THREE.CylinderGeometry(radius, radius, length, 16), material);
  mesh.position.copy(a).add(b).multiplyScalar(0.5);
  mesh.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), b.clone().sub(a).normalize());
  return mesh;
}

function matrixOf(frame: number[][]) {
  const m = new THREE.Matrix4();
  m.set(
    frame[0][0], frame[0][1], frame[0][2], frame[0][3],
    frame[1][0], frame[1][1], frame[1][2], frame[1][3],
    frame[2][0], frame[2][1], frame[2][2], frame[2][3],
    0, 0, 0, 1,
  );
  return m;
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

/** Where the 3D view looks from: close enough to tell the parts apart, the arm in view. */
const HOME_VIEW: [number, number, number] = [1.05, -0.95, 0.7];

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

export function View3D({ state, candidates, selectedWaypoint, api, pointCloudAvailable, shapes, believed }: Props) {
  const mount = useRef<HTMLDivElement>(null);
  const sceneRef = useRef<Scene | null>(null);
  const [error, setError] = useState<string | null>(null);
  const [cloudInfo, setCloudInfo] = useState<string>('');
  const [cloudTime, setCloudTime] = useState<number | null>(null);

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
    camera.position.set(...HOME_VIEW);
    const controls = new OrbitControls(camera, renderer.domElement);
    controls.target.set(0.35, -0.05, 0.12);
    scene.add(new THREE.HemisphereLight(0xffffff, 0x8899aa, 1.6));
    const sun = new THREE.DirectionalLight(0xffffff, 1.5);
    sun.position.set(1, -1, 2);
    scene.add(sun);
    const table = new THREE.Mesh(new THREE.BoxGeometry(1.4, 1.2, 0.04), new THREE.MeshLambertMaterial({ color: 0xc8b69a }));
    table.position.set(0.4, 0, -0.02);
    scene.add(table);
    const grid = new THREE.GridHelper(1.2, 12, 0x998877, 0xb0a08a);
    grid.rotation.x = Math.PI / 2;
    grid.position.set(0.4, 0, 0.001);
    scene.add(grid);
    const axes = new THREE.AxesHelper(0.15);
    scene.add(axes);
    const robot = new THREE.Group();
    const parts = new THREE.Group();
    const waypoints = new THREE.Group();
    const candidateGroup = new THREE.Group();
    const cloud = new THREE.Group();
    scene.add(robot, parts, waypoints, candidateGroup, cloud);
    const render = () => renderer.render(scene, camera);
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
    sceneRef.current = { renderer, scene, camera, controls, robot, parts, waypoints, candidates: candidateGroup, cloud, render };
    return () => {
      observer.disconnect();
      controls.dispose();
      renderer.dispose();
      element.removeChild(renderer.domElement);
      sceneRef.current = null;
    };
  }, []);

  // The robot, the parts and the waypoints follow the stream.
  useEffect(() => {
    const s = sceneRef.current;
    if (!s || !state) return;
    clear(s.robot);
    const joints = state.arm.joints;
    if (joints && joints.length === 6) {
      const frames = ur5Frames(joints);
      const points = frames.map((f) => new THREE.Vector3(...position(f)));
      const linkMaterial = new THREE.MeshLambertMaterial({ color: 0x4a90d9 });
      const jointMaterial = new THREE.MeshLambertMaterial({ color: 0x2c3e50 });
      for (let i = 0; i + 1 < points.length - 1; i++) {
        if (points[i].distanceTo(points[i + 1]) > 0.001) s.robot.add(cylinderBetween(points[i], points[i + 1], 0.04, linkMaterial));
        const ball = new THREE.Mesh(new THREE.SphereGeometry(0.05, 16, 12), jointMaterial);
        ball.position.copy(points[i]);
        s.robot.add(ball);
      }
      // The gripper: a palm and two fingers along the tool's y axis.
      const flange = matrixOf(frames[6]);
      const gripper = new THREE.Group();
      gripper.matrixAutoUpdate = false;
      gripper.matrix.copy(flange);
      const metal = new THREE.MeshLambertMaterial({ color: 0x555555 });
      const palm = new THREE.Mesh(new THREE.BoxGeometry(0.06, 0.1, 0.08), metal);
      palm.position.set(0, 0, 0.04);
      gripper.add(palm);
      const opening = state.gripper.open ? 0.085 : state.gripper.holding ? 0.04 : 0.01;
      for (const side of [-1, 1]) {
        const finger = new THREE.Mesh(new THREE.BoxGeometry(0.02, 0.012, 0.06), metal);
        finger.position.set(0, side * (opening / 2 + 0.006), 0.12);
        gripper.add(finger);
      }
      s.robot.add(gripper);
    }
    clear(s.parts);
    for (const object of state.objects) {
      const pose = believed?.poses.get(object.name) ?? object;
      const mesh = partMesh(object.class, shapes, object.color);
      mesh.position.set(...pose.p);
      mesh.quaternion.set(...pose.q);
      s.parts.add(mesh);
    }
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
  }, [state, selectedWaypoint, shapes, believed]);

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

  const look = (from: [number, number, number]) => {
    const s = sceneRef.current;
    if (!s) return;
    s.camera.position.set(...from);
    s.controls.target.set(0.35, -0.05, 0.12);
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
        <button type="button" className="small" onClick={() => look(HOME_VIEW)}>
          3D
        </button>
        <button type="button" className="small" onClick={() => look([0.35, -0.25, 2.2])}>
          Top
        </button>
        <button type="button" className="small" onClick={() => look([0.35, -2.0, 0.3])}>
          Side
        </button>
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
      {error ? <p className="empty">{error}</p> : <div className="view3d-canvas" ref={mount} />}
    </section>
  );
}
