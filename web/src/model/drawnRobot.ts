// The cell's robot as a three.js object: the URDF the planner reads (GET /api/robot: the arm's
// with the gripper's mounted on the flange), built by urdf-loader from its collision primitives
// (no meshes needed), placed where the cell stands it, its joints set by name from the stream,
// and the fingers drawn from the gripper's reading in place of the URDF's finger links (which
// cover the fingers' whole travel for the planner). A power tool the gripper holds is drawn at the
// tool centre point, where its grasp puts it.

import * as THREE from 'three';
import URDFLoader from 'urdf-loader';
import type { URDFRobot } from 'urdf-loader';
import { adaptiveFingerBoxes, baseMatrix, FingerReading, jointValues, parallelFingerBoxes, RobotDescription } from './robot';

const ARM_COLOUR = 0x4a90d9;
const GRIPPER_COLOUR = 0x55595f;
const FINGER_COLOUR = 0x33363a;

export class DrawnRobot {
  /** Add this to the scene: the robot at its base in the world. */
  readonly object = new THREE.Group();
  private readonly robot: URDFRobot;
  private readonly fingers = new THREE.Group();
  private readonly fingerMaterial = new THREE.MeshLambertMaterial({ color: FINGER_COLOUR });
  private readonly materials: THREE.Material[] = [];
  private fingerKey = '';
  /** The power tool as held, under the tool centre point's link; shown while the tool reads held. */
  private readonly heldTool = new THREE.Group();

  constructor(readonly description: RobotDescription) {
    const loader = new URDFLoader();
    // The arm's shapes are drawn from the URDF's visuals, in the colours its description gives
    // (robots/generate_models.py writes each collision solid again as a coloured visual); a link
    // with no visual (the gripper's) is drawn from its collision shapes in the gripper's grey.
    loader.parseVisual = true;
    loader.parseCollision = true;
    this.robot = loader.parse(description.urdf);
    const base = baseMatrix(description);
    this.object.matrixAutoUpdate = false;
    this.object.matrix.copy(base);
    this.object.add(this.robot);
    // The gripper's links: the flange's subtree beyond the arm (the mounted URDF adds them there).
    const gripperLinks = new Set<string>();
    const flange = this.robot.links[description.flange_link];
    flange?.traverse((o) => {
      const link = o as THREE.Object3D & { isURDFLink?: boolean; urdfName?: string };
      if (link.isURDFLink && link !== flange && link.urdfName) gripperLinks.add(link.urdfName);
    });
    const armMaterial = new THREE.MeshLambertMaterial({ color: ARM_COLOUR });
    const gripperMaterial = new THREE.MeshLambertMaterial({ color: GRIPPER_COLOUR });
    this.materials.push(armMaterial, gripperMaterial, this.fingerMaterial);
    for (const [name, link] of Object.entries(this.robot.links)) {
      const hidden = description.gripper.finger_links.includes(name);
      const shapes = link.children as (THREE.Object3D & { isURDFCollider?: boolean; isURDFVisual?: boolean })[];
      const coloured = shapes.some((child) => child.isURDFVisual);
      for (const child of shapes) {
        if (!child.isURDFCollider && !child.isURDFVisual) continue;
        child.visible = !hidden && (coloured ? !!child.isURDFVisual : true);
        if (child.isURDFVisual) {
          child.traverse((o) => {
            const mesh = o as THREE.Mesh;
            if (mesh.isMesh) this.materials.push(mesh.material as THREE.Material);
          });
          continue;
        }
        child.traverse((o) => {
          const mesh = o as THREE.Mesh;
          if (!mesh.isMesh) return;
          (mesh.material as THREE.Material).dispose();
          // The flange carries the gripper's mount (mountUrdf adds its shapes there).
          mesh.material = gripperLinks.has(name) || name === description.flange_link ? gripperMaterial : armMaterial;
        });
      }
    }
    flange?.add(this.fingers);
    const tool = description.power_tool;
    if (tool) {
      const toolMaterial = new THREE.MeshLambertMaterial({ color: new THREE.Color(...tool.rgb) });
      this.materials.push(toolMaterial);
      for (const box of tool.boxes) {
        const mesh = new THREE.Mesh(new THREE.BoxGeometry(...box.size), toolMaterial);
        mesh.position.set(...box.centre);
        this.heldTool.add(mesh);
      }
      this.heldTool.name = tool.name;
      this.heldTool.position.set(...tool.held_in_tcp.p);
      this.heldTool.quaternion.set(...tool.held_in_tcp.q).normalize();
      this.heldTool.visible = false;
      (this.robot.links[description.tcp_link] ?? flange)?.add(this.heldTool);
    }
  }

  /** Joint angles (the description's order, rad), the fingers' reading, the gripper's mode and whether the power
   * tool is in the gripper (drawn there while it is). */
  update(joints: number[] | undefined, reading: FingerReading | undefined, mode: string | undefined, toolHeld = false) {
    this.heldTool.visible = toolHeld && this.heldTool.children.length > 0;
    this.robot.setJointValues(jointValues(this.description, joints));
    const key = JSON.stringify([reading?.positions, mode]);
    if (key !== this.fingerKey) {
      this.fingerKey = key;
      this.drawFingers(reading, mode);
    }
    this.object.updateMatrixWorld(true);
  }

  private drawFingers(reading: FingerReading | undefined, mode: string | undefined) {
    for (const child of [...this.fingers.children]) {
      this.fingers.remove(child);
      (child as THREE.Mesh).geometry.dispose();
    }
    const gripper = this.description.gripper;
    const boxes =
      gripper.kind === 'adaptive' && gripper.description
        ? adaptiveFingerBoxes(gripper.description, mode, reading)
        : parallelFingerBoxes(this.description, reading?.positions[0] ?? gripper.max_opening ?? 0);
    for (const box of boxes) {
      const mesh = new THREE.Mesh(new THREE.BoxGeometry(...box.size), this.fingerMaterial);
      mesh.matrixAutoUpdate = false;
      mesh.matrix.copy(box.matrix);
      this.fingers.add(mesh);
    }
  }

  /** The tool centre point as drawn, in the world (m). */
  toolPosition(): THREE.Vector3 {
    return this.toolPose().position;
  }

  /** The tool centre point's frame as drawn, in the world: position (m) and orientation. */
  toolPose(): { position: THREE.Vector3; quaternion: THREE.Quaternion } {
    const tcp = this.robot.links[this.description.tcp_link] ?? this.robot.links[this.description.flange_link];
    this.object.updateMatrixWorld(true);
    const position = new THREE.Vector3();
    const quaternion = new THREE.Quaternion();
    tcp.matrixWorld.decompose(position, quaternion, new THREE.Vector3());
    return { position, quaternion };
  }

  /** The held power tool's frame as drawn, in the world (null: none drawn in the hand now). */
  heldToolPose(): { position: THREE.Vector3; quaternion: THREE.Quaternion } | null {
    if (!this.heldTool.visible) return null;
    this.object.updateMatrixWorld(true);
    const position = new THREE.Vector3();
    const quaternion = new THREE.Quaternion();
    this.heldTool.matrixWorld.decompose(position, quaternion, new THREE.Vector3());
    return { position, quaternion };
  }

  /** How many of the gripper's finger boxes are drawn (tests). */
  fingerBoxes(): number {
    return this.fingers.children.length;
  }

  dispose() {
    this.object.traverse((o) => (o as THREE.Mesh).geometry?.dispose?.());
    this.materials.forEach((m) => m.dispose());
  }
}
