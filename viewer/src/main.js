// The trm viewer: renders a `trm-scene` document (crates/trm-view) embedded in the page as
// <script id="trm-scene" type="application/json">. The robot as it looks (its URDF visuals, in
// their colours) or its collision shapes, the objects it holds, link poses per frame (play,
// pause, scrub), world objects (primitives, meshes, point clouds; moving ones posed per frame),
// roadmap points and edges coloured by cost (black where a frame says they are blocked; click a
// point to see its posture), a task-space path. After the first render it writes what it drew,
// as JSON, into <script id="trm-report" type="application/json"> (not shown) so that a headless
// browser test can check it.
// URL parameters: ?frame=N opens paused at frame N; ?play=1 starts playing; ?pick=I shows map
// point I's posture as a click on it does.

import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { ConvexGeometry } from 'three/addons/geometries/ConvexGeometry.js';
import { toCreasedNormals } from 'three/addons/utils/BufferGeometryUtils.js';

const BACKGROUND = 0xf4f4f4;
const scene3 = new THREE.Scene();
scene3.background = new THREE.Color(BACKGROUND);
const data = JSON.parse(document.getElementById('trm-scene').textContent);
const params = new URLSearchParams(window.location.search);

// ---- page layout -------------------------------------------------------------------------
document.body.style.cssText = 'margin:0;overflow:hidden;font:13px sans-serif;';
const panel = document.createElement('div');
panel.style.cssText =
  'position:absolute;top:8px;left:8px;background:rgba(255,255,255,.9);padding:8px 10px;' +
  'border:1px solid #bbb;border-radius:4px;max-width:340px;';
document.body.appendChild(panel);
const heading = document.createElement('div');
heading.style.cssText = 'font-weight:bold;margin-bottom:4px;';
heading.textContent = data.title;
panel.appendChild(heading);
const info = document.createElement('div');
info.id = 'trm-info';
info.style.cssText = 'margin-top:6px;color:#333;';
const report = document.createElement('script');
report.id = 'trm-report';
report.type = 'application/json';
document.body.appendChild(report);

function toggle(label, initial, onChange) {
  const row = document.createElement('label');
  row.style.cssText = 'display:block;';
  const box = document.createElement('input');
  box.type = 'checkbox';
  box.checked = initial;
  box.addEventListener('change', () => onChange(box.checked));
  row.appendChild(box);
  row.appendChild(document.createTextNode(' ' + label));
  panel.appendChild(row);
  return box;
}

// ---- shapes ------------------------------------------------------------------------------
// a triangle mesh, shaded smooth within 30 degrees and sharp across creases (CAD parts)
function meshGeometry(s) {
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(s.vertices.flat()), 3));
  g.setIndex(s.triangles.flat());
  return toCreasedNormals(g, Math.PI / 6);
}

// shapes as trm-collision writes them: {"Box": {"size": [...]}}, cylinders and capsules along z
function geometry(shape) {
  const [kind, s] = Object.entries(shape)[0];
  switch (kind) {
    case 'Sphere':
      return new THREE.SphereGeometry(s.radius, 24, 16);
    case 'Box':
      return new THREE.BoxGeometry(s.size[0], s.size[1], s.size[2]);
    case 'Cylinder':
      return new THREE.CylinderGeometry(s.radius, s.radius, s.length, 24).rotateX(Math.PI / 2);
    case 'Capsule':
      return new THREE.CapsuleGeometry(s.radius, s.length, 8, 16).rotateX(Math.PI / 2);
    case 'Convex':
      return new ConvexGeometry(s.points.map((p) => new THREE.Vector3(p[0], p[1], p[2])));
    case 'Mesh':
      return meshGeometry(s);
    default:
      throw new Error('unknown shape ' + kind);
  }
}

function setPose(object, p) {
  object.position.set(p[0], p[1], p[2]);
  object.quaternion.set(p[3], p[4], p[5], p[6]);
}

function poseMatrix(p) {
  return new THREE.Matrix4().compose(
    new THREE.Vector3(p[0], p[1], p[2]),
    new THREE.Quaternion(p[3], p[4], p[5], p[6]),
    new THREE.Vector3(1, 1, 1),
  );
}

// ---- robot -------------------------------------------------------------------------------
const robot = new THREE.Group();
scene3.add(robot);
// each link: what it looks like, its collision shapes, what it holds (each part toggled apart)
const linkGroups = data.links.map(() => {
  const g = new THREE.Group();
  robot.add(g);
  return g;
});
const parts = { look: [], collision: [], held: [] }; // per kind, the group on each link (sparse)
function partOf(kind, slot) {
  if (!parts[kind][slot]) {
    parts[kind][slot] = new THREE.Group();
    linkGroups[slot].add(parts[kind][slot]);
  }
  return parts[kind][slot];
}
const HELD_COLOR = 0xd9822b;
let meshes = 0;
let heldBodies = 0;
data.bodies.forEach((b) => {
  const held = b.held !== undefined && b.held !== null;
  const color = held ? new THREE.Color(HELD_COLOR) : new THREE.Color().setHSL((b.link * 0.137) % 1, 0.45, 0.55);
  const material = new THREE.MeshStandardMaterial({ color, roughness: 0.7, transparent: !held, opacity: held ? 1 : 0.85 });
  const mesh = new THREE.Mesh(geometry(b.shape), material);
  setPose(mesh, b.local);
  mesh.name = b.name;
  partOf(held ? 'held' : 'collision', b.link).add(mesh);
  meshes += 1;
  if (held) heldBodies += 1;
});
const visuals = data.visuals || [];
const missingVisuals = data.missing_visuals || [];
let visualTriangles = 0;
visuals.forEach((v) => {
  const [r, g, b, a] = v.color;
  const material = new THREE.MeshStandardMaterial({
    color: new THREE.Color(r, g, b),
    roughness: 0.55,
    metalness: 0.05,
    transparent: a < 1,
    opacity: a,
  });
  const mesh = new THREE.Mesh(geometry(v.shape), material);
  setPose(mesh, v.local);
  partOf('look', v.link).add(mesh);
  if (v.shape.Mesh) visualTriangles += v.shape.Mesh.triangles.length;
});
// the robot as it looks when all its visuals loaded; else its collision shapes
const showLook = visuals.length > 0 && missingVisuals.length === 0;
function showPart(kind, on) {
  parts[kind].forEach((g) => { g.visible = on; });
}
showPart('look', showLook);
showPart('collision', !showLook);

// forward kinematics of the tree for a joint vector (root at `base`): world matrix of every link
function forward(joints, base) {
  const world = [base ? poseMatrix(base) : new THREE.Matrix4()];
  data.kinematics.joints.forEach((j) => {
    const m = world[j.parent].clone().multiply(poseMatrix(j.origin));
    if (j.coordinate !== null && j.kind !== 'fixed') {
      const v = joints[j.coordinate];
      const axis = new THREE.Vector3(j.axis[0], j.axis[1], j.axis[2]);
      if (j.kind === 'prismatic') {
        m.multiply(new THREE.Matrix4().makeTranslation(axis.multiplyScalar(v)));
      } else {
        m.multiply(new THREE.Matrix4().makeRotationAxis(axis, v));
      }
    }
    world.push(m);
  });
  return world;
}

function showJoints(joints) {
  const world = forward(joints);
  data.link_index.forEach((l, slot) => {
    world[l].decompose(linkGroups[slot].position, linkGroups[slot].quaternion, new THREE.Vector3());
  });
}

// the page's kinematics against the scene's (computed by trm): largest position difference
function fkError() {
  if (data.frames.length === 0) return 0;
  const f = data.frames[0];
  const world = forward(f.joints, f.base);
  let worst = 0;
  data.link_index.forEach((l, slot) => {
    const p = new THREE.Vector3();
    const q = new THREE.Quaternion();
    world[l].decompose(p, q, new THREE.Vector3());
    const e = f.poses[slot];
    worst = Math.max(worst, Math.abs(p.x - e[0]), Math.abs(p.y - e[1]), Math.abs(p.z - e[2]));
    const dot = Math.abs(q.x * e[3] + q.y * e[4] + q.z * e[5] + q.w * e[6]);
    worst = Math.max(worst, 1 - Math.min(1, dot));
  });
  return worst;
}

// ---- world -------------------------------------------------------------------------------
const world = new THREE.Group();
scene3.add(world);
// a point cloud: its points coloured by height (as RViz does), 3 pixels wide at any distance
// (their collision radius is a few millimetres: a pixel or less)
let cloudPoints = 0;
function cloud(s) {
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(s.points.flat()), 3));
  // (a loop: spreading a camera's hundreds of thousands of points as arguments overflows)
  let [lo, hi] = [Infinity, -Infinity];
  s.points.forEach((p) => { lo = Math.min(lo, p[2]); hi = Math.max(hi, p[2]); });
  const colors = new Float32Array(3 * s.points.length);
  s.points.forEach((p, i) => {
    const u = hi > lo ? (p[2] - lo) / (hi - lo) : 0.5;
    const c = new THREE.Color().setHSL(0.7 - 0.6 * u, 0.75, 0.45);
    colors.set([c.r, c.g, c.b], 3 * i);
  });
  g.setAttribute('color', new THREE.BufferAttribute(colors, 3));
  cloudPoints += s.points.length;
  return new THREE.Points(g, new THREE.PointsMaterial({ size: 3, sizeAttenuation: false, vertexColors: true }));
}
data.world.forEach((o) => {
  const object = o.shape.Points
    ? cloud(o.shape.Points)
    : new THREE.Mesh(
      geometry(o.shape),
      new THREE.MeshStandardMaterial({
        color: 0x8a8a8a,
        transparent: true,
        opacity: 0.45,
        side: o.shape.Mesh ? THREE.DoubleSide : THREE.FrontSide,
      }),
    );
  setPose(object, o.pose);
  object.name = o.name;
  world.add(object);
});
const worldMeshes = world.children.slice();

// ---- map ---------------------------------------------------------------------------------
const map = data.map;
let mapPoints = null;
let mapEdges = null;
let costRange = [0, 1];
function costColor(c) {
  const [lo, hi] = costRange;
  const u = hi > lo ? (c - lo) / (hi - lo) : 0.5;
  return new THREE.Color().setHSL((1 - u) * 0.66, 0.85, 0.5); // blue (low) to red (high)
}
if (map && map.points.length > 0) {
  costRange = [Math.min(...map.cost), Math.max(...map.cost)];
  const positions = new Float32Array(map.points.length * 3);
  const colors = new Float32Array(map.points.length * 3);
  map.points.forEach((p, i) => {
    positions.set(p, 3 * i);
    const c = costColor(map.cost[i]);
    colors.set([c.r, c.g, c.b], 3 * i);
  });
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(positions, 3));
  g.setAttribute('color', new THREE.BufferAttribute(colors, 3));
  mapPoints = new THREE.Points(g, new THREE.PointsMaterial({ size: 6, sizeAttenuation: false, vertexColors: true }));
  scene3.add(mapPoints);
  const ep = new Float32Array(map.edges.length * 6);
  const ec = new Float32Array(map.edges.length * 6);
  map.edges.forEach(([a, b], i) => {
    ep.set(map.points[a], 6 * i);
    ep.set(map.points[b], 6 * i + 3);
    ec.set(colors.subarray(3 * a, 3 * a + 3), 6 * i);
    ec.set(colors.subarray(3 * b, 3 * b + 3), 6 * i + 3);
  });
  const eg = new THREE.BufferGeometry();
  eg.setAttribute('position', new THREE.BufferAttribute(ep, 3));
  eg.setAttribute('color', new THREE.BufferAttribute(ec, 3));
  mapEdges = new THREE.LineSegments(eg, new THREE.LineBasicMaterial({ vertexColors: true, transparent: true, opacity: 0.5 }));
  scene3.add(mapEdges);
}
// a map in a moving world (a scenario's frames): points and edges that exist yet, blocked ones black
const blockedColor = new THREE.Color(0x202020); // black: the cost colours run blue to red
// points drawn in the blocked colour (for the report)
function countBlocked() {
  const pc = mapPoints.geometry.getAttribute('color');
  let n = 0;
  for (let i = 0; i < Math.min(pc.count, mapPoints.geometry.drawRange.count); i += 1) {
    const near = (a, b) => Math.abs(a - b) < 1e-6; // the attribute holds 32-bit floats
    if (near(pc.getX(i), blockedColor.r) && near(pc.getY(i), blockedColor.g) && near(pc.getZ(i), blockedColor.b)) n += 1;
  }
  return n;
}
function showMapState(state) {
  if (!mapPoints || !state) return;
  const pc = mapPoints.geometry.getAttribute('color');
  const ec = mapEdges.geometry.getAttribute('color');
  map.points.forEach((_, i) => {
    const c = costColor(map.cost[i]);
    pc.setXYZ(i, c.r, c.g, c.b);
  });
  state.blocked.forEach((i) => pc.setXYZ(i, blockedColor.r, blockedColor.g, blockedColor.b));
  map.edges.forEach(([a, b], i) => {
    ec.setXYZ(2 * i, pc.getX(a), pc.getY(a), pc.getZ(a));
    ec.setXYZ(2 * i + 1, pc.getX(b), pc.getY(b), pc.getZ(b));
  });
  state.blocked_edges.forEach((i) => {
    ec.setXYZ(2 * i, blockedColor.r, blockedColor.g, blockedColor.b);
    ec.setXYZ(2 * i + 1, blockedColor.r, blockedColor.g, blockedColor.b);
  });
  pc.needsUpdate = true;
  ec.needsUpdate = true;
  mapPoints.geometry.setDrawRange(0, state.nodes);
  mapEdges.geometry.setDrawRange(0, 2 * state.edges);
}

// ---- path --------------------------------------------------------------------------------
let path = null;
if (data.path.length > 1) {
  const g = new THREE.BufferGeometry().setFromPoints(data.path.map((p) => new THREE.Vector3(p[0], p[1], p[2])));
  path = new THREE.Line(g, new THREE.LineBasicMaterial({ color: 0xe07000 }));
  scene3.add(path);
}

// ---- lights, grid, camera ------------------------------------------------------------------
scene3.add(new THREE.HemisphereLight(0xffffff, 0x667788, 2.2));
const sun = new THREE.DirectionalLight(0xffffff, 1.6);
sun.position.set(2, -3, 4);
scene3.add(sun);
const grid = new THREE.GridHelper(2, 20, 0xaaaaaa, 0xdddddd);
grid.rotateX(Math.PI / 2);
scene3.add(grid);

const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio || 1);
renderer.setSize(window.innerWidth, window.innerHeight);
document.body.appendChild(renderer.domElement);
const camera = new THREE.PerspectiveCamera(45, window.innerWidth / window.innerHeight, 0.01, 100);
camera.up.set(0, 0, 1);
const controls = new OrbitControls(camera, renderer.domElement);

// ---- frames and playback -----------------------------------------------------------------
const frames = data.frames;
let current = 0;
let playing = params.get('play') === '1' && frames.length > 1;
function showFrame(i) {
  current = Math.max(0, Math.min(frames.length - 1, i));
  const f = frames[current];
  if (!f) return;
  f.poses.forEach((p, slot) => setPose(linkGroups[slot], p));
  if (f.world) {
    f.world.forEach((p, k) => {
      worldMeshes[k].visible = p !== null;
      if (p !== null) setPose(worldMeshes[k], p);
    });
  }
  showMapState(f.map);
  slider.value = String(current);
  timeLabel.textContent = `frame ${current + 1}/${frames.length}, t = ${f.t.toFixed(2)} s`;
}
const controlsRow = document.createElement('div');
controlsRow.style.cssText = 'margin:4px 0;';
const playButton = document.createElement('button');
playButton.textContent = playing ? 'pause' : 'play';
playButton.disabled = frames.length < 2;
const slider = document.createElement('input');
slider.type = 'range';
slider.min = '0';
slider.max = String(Math.max(0, frames.length - 1));
slider.style.cssText = 'width:180px;vertical-align:middle;';
const timeLabel = document.createElement('div');
controlsRow.appendChild(playButton);
controlsRow.appendChild(slider);
panel.appendChild(controlsRow);
panel.appendChild(timeLabel);
let clock = 0;
playButton.addEventListener('click', () => {
  playing = !playing;
  playButton.textContent = playing ? 'pause' : 'play';
  if (playing && current >= frames.length - 1) showFrame(0);
  clock = frames[current] ? frames[current].t : 0;
});
slider.addEventListener('input', () => {
  playing = false;
  playButton.textContent = 'play';
  showFrame(Number(slider.value));
});

if (visuals.length) toggle('robot as it looks', showLook, (v) => showPart('look', v));
toggle('collision shapes', !showLook, (v) => showPart('collision', v));
if (heldBodies) toggle(`held objects (${heldBodies} shape${heldBodies > 1 ? 's' : ''})`, true, (v) => showPart('held', v));
if (missingVisuals.length) {
  const note = document.createElement('div');
  note.style.cssText = 'color:#8a4b00;margin:2px 0;';
  note.textContent = `${missingVisuals.length} visual${missingVisuals.length > 1 ? 's' : ''} not loaded: collision shapes shown`;
  note.title = missingVisuals.join('\n');
  panel.appendChild(note);
}
if (data.world.length) toggle(`world (${data.world.length} objects)`, true, (v) => { world.visible = v; });
if (mapPoints) {
  toggle(`map points (${map.points.length})`, true, (v) => { mapPoints.visible = v; });
  toggle(`map edges (${map.edges.length})`, true, (v) => { mapEdges.visible = v; });
  const legend = document.createElement('div');
  legend.style.cssText = 'margin-top:4px;';
  legend.innerHTML =
    '<div>point cost</div><div style="height:10px;width:180px;background:linear-gradient(to right,' +
    'hsl(240,85%,50%),hsl(120,85%,50%),hsl(0,85%,50%))"></div>' +
    `<div style="width:180px;display:flex;justify-content:space-between"><span>${costRange[0].toPrecision(3)}</span>` +
    `<span>${costRange[1].toPrecision(3)}</span></div>` +
    (frames.some((f) => f.map) ? '<div>black: blocked in this frame</div>' : '') +
    '<div>click a point to see its posture</div>';
  panel.appendChild(legend);
}
if (path) toggle(`path (${data.path.length} points)`, true, (v) => { path.visible = v; });
panel.appendChild(info);

// ---- picking map points ------------------------------------------------------------------
const raycaster = new THREE.Raycaster();
let downAt = null;
renderer.domElement.addEventListener('pointerdown', (e) => { downAt = [e.clientX, e.clientY]; });
renderer.domElement.addEventListener('pointerup', (e) => {
  if (!mapPoints || !mapPoints.visible || !downAt) return;
  if (Math.hypot(e.clientX - downAt[0], e.clientY - downAt[1]) > 4) return; // a drag, not a click
  const ndc = new THREE.Vector2((e.clientX / window.innerWidth) * 2 - 1, -(e.clientY / window.innerHeight) * 2 + 1);
  raycaster.setFromCamera(ndc, camera);
  raycaster.params.Points.threshold = 0.01 * camera.position.distanceTo(controls.target);
  const hit = raycaster.intersectObject(mapPoints)[0];
  if (hit !== undefined) pick(hit.index);
});

// show map point i's posture (a click, or ?pick=i)
function pick(i) {
  playing = false;
  playButton.textContent = 'play';
  showJoints(map.joints[i]);
  const p = map.points[i];
  info.textContent = `map point ${i}: cost ${map.cost[i].toPrecision(4)}, at (${p.map((v) => v.toFixed(3)).join(', ')})`;
}

// ---- camera fit, first render, report ----------------------------------------------------
const box = new THREE.Box3();
// fit the camera to the robot at the first, middle and last frames, the map and the world
[frames.length - 1, Math.floor(frames.length / 2), 0].forEach((i) => {
  if (i >= 0) showFrame(i);
  box.expandByObject(robot);
});
if (mapPoints) box.expandByObject(mapPoints);
box.expandByObject(world);
const centre = box.getCenter(new THREE.Vector3());
const radius = Math.max(0.3, box.getSize(new THREE.Vector3()).length() / 2);
controls.target.copy(centre);
camera.position.copy(centre).add(new THREE.Vector3(-1.6, -1.9, 1.1).multiplyScalar(radius));
controls.update();

const start = params.has('frame') ? Number(params.get('frame')) : 0;
showFrame(start);
renderer.render(scene3, camera);

function drawnPixels() {
  const gl = renderer.getContext();
  const w = gl.drawingBufferWidth;
  const h = gl.drawingBufferHeight;
  const pixels = new Uint8Array(w * h * 4);
  gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, pixels);
  const [r, g, b] = [(BACKGROUND >> 16) & 255, (BACKGROUND >> 8) & 255, BACKGROUND & 255];
  let n = 0;
  for (let i = 0; i < pixels.length; i += 4) {
    if (Math.abs(pixels[i] - r) > 8 || Math.abs(pixels[i + 1] - g) > 8 || Math.abs(pixels[i + 2] - b) > 8) n += 1;
  }
  return { n, w, h };
}
const drawn = drawnPixels();
// mean time of a few full renders (software WebGL in headless tests: an upper bound)
const timed = performance.now();
for (let k = 0; k < 5; k += 1) renderer.render(scene3, camera);
renderer.getContext().finish();
const renderMs = (performance.now() - timed) / 5;
const picked = {};
if (map && params.has('pick')) {
  const i = Number(params.get('pick'));
  pick(i);
  renderer.render(scene3, camera);
  const last = linkGroups[linkGroups.length - 1].position;
  Object.assign(picked, { picked: i, picked_last_link: [last.x, last.y, last.z] });
}
report.textContent = JSON.stringify({
  ...picked,
  format: data.format,
  version: data.version,
  bodies: meshes,
  held: heldBodies,
  visuals: visuals.length,
  visual_triangles: visualTriangles,
  look_shown: parts.look.some((g) => g && g.visible),
  collision_shown: parts.collision.some((g) => g && g.visible),
  cloud_points: cloudPoints,
  links: linkGroups.length,
  world: data.world.length,
  points: map ? map.points.length : 0,
  edges: map ? map.edges.length : 0,
  path: data.path.length,
  frames: frames.length,
  frame: current,
  fk_error: fkError(),
  objects_shown: worldMeshes.filter((m) => m.visible).length,
  points_shown: mapPoints ? Math.min(mapPoints.geometry.drawRange.count, map.points.length) : 0,
  points_blocked: mapPoints ? countBlocked() : 0,
  pixels: drawn.n,
  width: drawn.w,
  height: drawn.h,
  render_ms: Math.round(renderMs * 10) / 10,
  three: THREE.REVISION,
});
document.body.dataset.ready = '1';

let last = performance.now();
function animate(now) {
  const dt = (now - last) / 1000;
  last = now;
  if (playing && frames.length > 1) {
    clock += dt;
    let i = current;
    while (i + 1 < frames.length && frames[i + 1].t <= clock) i += 1;
    if (i !== current) showFrame(i);
    if (i >= frames.length - 1) {
      playing = false;
      playButton.textContent = 'play';
    }
  }
  controls.update();
  renderer.render(scene3, camera);
  requestAnimationFrame(animate);
}
requestAnimationFrame(animate);
window.addEventListener('resize', () => {
  camera.aspect = window.innerWidth / window.innerHeight;
  camera.updateProjectionMatrix();
  renderer.setSize(window.innerWidth, window.innerHeight);
});
