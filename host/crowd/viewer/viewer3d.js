// The crowd viewer's 3D view (three.js, embedded before this script): every
// character as capsules between its displayed joints on a ground grid with
// shadows, an orbit camera and a follow camera, the selection (shared with
// the top-down view and the timeline) ringed, planted and locked feet marked
// on the ground, the selected character's desired and achieved trajectories.
//
// viewer.js owns the recording and the state; this file only draws them,
// through the hooks it is given (create() below). World space as in
// recording.hpp: Y-up, metres, the ground at y = 0.
'use strict';
window.MmvkView3d = (function () {
  // Capsule radii, metres: limbs, and the head's sphere.
  const kLimb = 0.045, kHead = 0.11;
  // Orbit bounds: never under the ground, never straight down (the up
  // vector would flip), never closer than half a metre.
  const kMinPitch = 0.05, kMaxPitch = 1.5, kMinDist = 0.5, kMaxDist = 2000;

  // A MeshLambertMaterial whose colour is multiplied by a per-instance
  // attribute `instColor` (r111's InstancedMesh has no instance colours).
  function instanceColoured(base) {
    const material = new THREE.MeshLambertMaterial({ color: base });
    material.onBeforeCompile = (shader) => {
      shader.vertexShader = 'attribute vec3 instColor;\nvarying vec3 vInstColor;\n' +
        shader.vertexShader.replace('#include <begin_vertex>', '#include <begin_vertex>\n\tvInstColor = instColor;');
      shader.fragmentShader = 'varying vec3 vInstColor;\n' +
        shader.fragmentShader.replace('vec4 diffuseColor = vec4( diffuse, opacity );',
          'vec4 diffuseColor = vec4( diffuse * vInstColor, opacity );');
    };
    return material;
  }

  function instanced(geometry, material, count, colours) {
    geometry.setAttribute('instColor', new THREE.InstancedBufferAttribute(colours, 3));
    const mesh = new THREE.InstancedMesh(geometry, material, Math.max(count, 1));
    mesh.count = count;
    mesh.castShadow = true;
    mesh.receiveShadow = true;
    mesh.frustumCulled = false;  // the instances, not the geometry, say where it is
    return mesh;
  }

  function line(color, width) {
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(3 * 512), 3));
    geometry.setDrawRange(0, 0);
    const l = new THREE.Line(geometry, new THREE.LineBasicMaterial({ color, linewidth: width }));
    l.frustumCulled = false;
    return l;
  }

  function setLine(l, pts, y) {
    const a = l.geometry.attributes.position, n = Math.min(pts.length, a.count);
    for (let i = 0; i < n; i++) a.setXYZ(i, pts[i][0], y, pts[i][1]);
    a.needsUpdate = true;
    l.geometry.setDrawRange(0, n);
  }

  // The renderer, the camera, the lights and the ground with its grids.
  function makeStage(canvas, D) {
    const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
    renderer.shadowMap.enabled = true;
    renderer.shadowMap.type = THREE.PCFSoftShadowMap;
    renderer.setClearColor(0x14171c);
    const scene = new THREE.Scene();
    scene.fog = new THREE.Fog(0x14171c, 60, 400);
    const camera = new THREE.PerspectiveCamera(45, 1, 0.05, 3000);
    scene.add(new THREE.HemisphereLight(0xdde6ff, 0x202428, 0.55));
    const sun = new THREE.DirectionalLight(0xffffff, 0.75);
    sun.castShadow = true;
    sun.shadow.mapSize.set(2048, 2048);
    scene.add(sun, sun.target);
    const [x0, z0, x1, z1] = D.bounds, span = Math.max(x1 - x0, z1 - z0, 10);
    const ground = new THREE.Mesh(new THREE.PlaneGeometry(span * 4, span * 4),
      // Pushed back in depth, so the grid on it wins at any distance.
      new THREE.MeshLambertMaterial({ color: 0x3a414c, polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 4 }));
    ground.rotation.x = -Math.PI / 2;
    ground.position.set((x0 + x1) / 2, 0, (z0 + z1) / 2);
    ground.receiveShadow = true;
    scene.add(ground);
    // Ground grids: 10 m over the whole crowd, and 1 m around the point
    // looked at (1 m lines over a hundred metres only make a moire).
    const coarse = Math.ceil(span * 2 / 10) * 10;
    const grid = new THREE.GridHelper(coarse, coarse / 10, 0x8a93a3, 0x8a93a3);
    grid.position.set(Math.round((x0 + x1) / 20) * 10, 0.003, Math.round((z0 + z1) / 20) * 10);
    const fine = new THREE.GridHelper(30, 30, 0x6b7380, 0x6b7380);
    scene.add(grid, fine);
    const cam = { target: new THREE.Vector3((x0 + x1) / 2, 0, (z0 + z1) / 2), dist: span * 0.8, yaw: 0.6, pitch: 0.6, height: 0.9 };
    return { renderer, scene, camera, sun, fine, span, cam };
  }

  // Bones: one capsule (a cylinder, its ends rounded by the joints'
  // spheres) per joint with a parent; joints: one sphere each; every
  // character in its hue.
  function makeBodies(D, hooks, scene) {
    const bones = [];
    for (let j = 0; j < D.J; j++) if (D.parents[j] >= 0) bones.push(j);
    const head = D.names.findIndex((n) => /head/i.test(n));
    const boneColours = new Float32Array(D.N * bones.length * 3), jointColours = new Float32Array(D.N * D.J * 3);
    const colour = new THREE.Color();
    for (let a = 0; a < D.N; a++) {
      colour.setHSL(hooks.hue(a) / 360, 0.6, 0.55);
      for (let i = 0; i < bones.length; i++) colour.toArray(boneColours, 3 * (a * bones.length + i));
      for (let j = 0; j < D.J; j++) colour.toArray(jointColours, 3 * (a * D.J + j));
    }
    const cylinder = new THREE.CylinderBufferGeometry(1, 1, 1, 8, 1, true);
    cylinder.translate(0, 0.5, 0);  // from its base (the parent joint) along +Y
    const boneMesh = instanced(cylinder, instanceColoured(0xffffff), D.N * bones.length, boneColours);
    const jointMesh = instanced(new THREE.SphereBufferGeometry(1, 8, 6), instanceColoured(0xffffff), D.N * D.J, jointColours);
    scene.add(boneMesh, jointMesh);
    return { bones, head, boneMesh, jointMesh };
  }

  // Feet on the ground: planted (dim) and locked (bright, where foot IK
  // holds it), left a disc, right a square, as in the top-down view; the
  // selection's ring and trails.
  function makeMarks(D, hooks, scene) {
    const footGeometry = [new THREE.CircleBufferGeometry(0.07, 16), new THREE.PlaneBufferGeometry(0.12, 0.12)];
    footGeometry.forEach((g) => g.rotateX(-Math.PI / 2));
    const markMaterial = (color, opacity) => new THREE.MeshBasicMaterial({ color, transparent: true, opacity, depthWrite: false });
    const feet = [];  // [state][foot]: planted, locked
    for (const [color, opacity] of [[0x7dff8a, 0.35], [0x7dff8a, 0.95]]) {
      feet.push(footGeometry.map((g) => {
        const m = new THREE.InstancedMesh(g, markMaterial(color, opacity), Math.max(D.N, 1));
        m.frustumCulled = false; m.count = 0; scene.add(m); return m;
      }));
    }
    const ring = new THREE.Mesh(new THREE.RingBufferGeometry(0.46, 0.5, 48).rotateX(-Math.PI / 2),
      new THREE.MeshBasicMaterial({ color: 0xffffff, transparent: true, opacity: 0.7, depthWrite: false }));
    scene.add(ring);
    const trails = { past: line(0xc8c8c8), achieved: line(hooks.colors.achieved), desired: line(hooks.colors.desired) };
    Object.values(trails).forEach((l) => scene.add(l));
    // The toes of a leg_joints list of knee, ankle and toe per leg (left,
    // then right: the skeleton's order), where the planted marks go.
    const toes = D.L === 6 ? [D.legJoints[2], D.legJoints[5]] : null;
    return { feet, ring, trails, toes };
  }

  // Scratch for the per-frame matrices (the page draws one view at a time).
  const m = new THREE.Matrix4(), q = new THREE.Quaternion(), up = new THREE.Vector3(0, 1, 0);
  const from = new THREE.Vector3(), to = new THREE.Vector3(), dir = new THREE.Vector3(), scale = new THREE.Vector3();
  const hidden = new THREE.Matrix4().makeScale(0, 0, 0);

  function placeBody(v, a, pose) {
    const { D } = v, { bones, head, boneMesh, jointMesh } = v.bodies;
    for (let i = 0; i < bones.length; i++) {
      const j = bones[i], p = D.parents[j], k = a * bones.length + i;
      if (!pose) { boneMesh.setMatrixAt(k, hidden); continue; }
      from.fromArray(pose, 3 * p); to.fromArray(pose, 3 * j);
      dir.subVectors(to, from);
      const length = dir.length();
      if (length < 0.01) { boneMesh.setMatrixAt(k, hidden); continue; }
      q.setFromUnitVectors(up, dir.divideScalar(length));
      m.compose(from, q, scale.set(kLimb, length, kLimb));
      boneMesh.setMatrixAt(k, m);
    }
    for (let j = 0; j < D.J; j++) {
      const k = a * D.J + j;
      if (!pose) { jointMesh.setMatrixAt(k, hidden); continue; }
      const r = j === head ? kHead : kLimb;
      m.makeScale(r, r, r).setPosition(from.fromArray(pose, 3 * j));
      jointMesh.setMatrixAt(k, m);
    }
  }

  function placeFeet(v, a, pose, counts) {
    const feet = v.hooks.feetAt(a, v.state.t), { toes } = v.marks;
    if (!feet) return;
    for (let foot = 0; foot < 2; foot++) {
      let x, z, kind;
      if (feet.state & (4 << foot)) {
        kind = 1; x = feet.anchor[3 * foot]; z = feet.anchor[3 * foot + 2];
      } else if ((feet.state & (1 << foot)) && toes && pose) {
        kind = 0; x = pose[3 * toes[foot]]; z = pose[3 * toes[foot] + 2];
      } else {
        continue;
      }
      m.makeTranslation(x, 0.004 + 0.002 * kind, z);
      v.marks.feet[kind][foot].setMatrixAt(counts[kind][foot]++, m);
    }
  }

  function placeTrails(v, a) {
    const { D } = v, { trails, ring } = v.marks;
    const p = v.hooks.sampleAt(a, v.state.t), past = [], ahead = [[p.x, p.z]], desired = [];
    for (let s = Math.max(0, p.s0 - Math.round(2 * D.rate)); s <= p.s0; s++) past.push([D.rootX[a * D.S + s], D.rootZ[a * D.S + s]]);
    past.push([p.x, p.z]);
    const horizon = D.times.length ? D.times[D.times.length - 1] : 1;
    for (let s = p.s1; s < D.S && s <= p.s0 + Math.ceil(horizon * D.rate); s++) ahead.push([D.rootX[a * D.S + s], D.rootZ[a * D.S + s]]);
    desired.push([D.rootX[a * D.S + p.s0], D.rootZ[a * D.S + p.s0]]);
    for (let k = 0; k < D.K; k++) desired.push([D.desX[(a * D.S + p.s0) * D.K + k], D.desZ[(a * D.S + p.s0) * D.K + k]]);
    setLine(trails.past, past, 0.015);
    setLine(trails.achieved, ahead, 0.02);
    setLine(trails.desired, desired, 0.025);
    ring.position.set(p.x, 0.008, p.z);
  }

  function placeCamera(v, w, h) {
    const { cam, camera, sun, fine, span } = v.stage, state = v.state;
    if (state.follow && state.selected >= 0) {
      const p = v.hooks.sampleAt(state.selected, state.t);
      cam.target.set(p.x, cam.height, p.z);
    }
    cam.dist = Math.min(kMaxDist, Math.max(kMinDist, cam.dist));
    cam.pitch = Math.min(kMaxPitch, Math.max(kMinPitch, cam.pitch));
    fine.position.set(Math.round(cam.target.x), 0.002, Math.round(cam.target.z));
    fine.visible = cam.dist < 40;
    const cp = Math.cos(cam.pitch);
    camera.position.set(cam.target.x + cam.dist * cp * Math.sin(cam.yaw), cam.target.y + cam.dist * Math.sin(cam.pitch),
      cam.target.z + cam.dist * cp * Math.cos(cam.yaw));
    camera.lookAt(cam.target);
    camera.aspect = w / Math.max(h, 1);
    camera.near = Math.max(0.05, cam.dist / 400);
    camera.far = Math.max(3000, cam.dist * 4);
    camera.updateProjectionMatrix();
    // The shadows cover what the camera looks at, more finely up close.
    const reach = Math.min(Math.max(cam.dist * 1.2, 6), span * 1.5);
    sun.position.set(cam.target.x + reach * 0.6, reach * 1.5 + 5, cam.target.z + reach * 0.4);
    sun.target.position.copy(cam.target);
    Object.assign(sun.shadow.camera, { left: -reach, right: reach, top: reach, bottom: -reach, near: 0.1, far: reach * 4 + 20 });
    sun.shadow.camera.updateProjectionMatrix();
  }

  // Draws the current time; returns the planted and locked marks drawn,
  // [[planted left, right], [locked left, right]].
  function draw(v) {
    const { D, state, canvas } = v, { renderer, scene, camera } = v.stage, marks = v.marks;
    const w = canvas.clientWidth, h = canvas.clientHeight;
    renderer.setPixelRatio(window.devicePixelRatio || 1);
    renderer.setSize(w, h, false);
    const counts = [[0, 0], [0, 0]];
    for (let a = 0; a < D.N; a++) {
      const pose = v.hooks.worldPose(a, state.t);
      placeBody(v, a, pose);
      placeFeet(v, a, pose, counts);
    }
    v.bodies.boneMesh.instanceMatrix.needsUpdate = true;
    v.bodies.jointMesh.instanceMatrix.needsUpdate = true;
    for (let kind = 0; kind < 2; kind++) {
      for (let foot = 0; foot < 2; foot++) { marks.feet[kind][foot].count = counts[kind][foot]; marks.feet[kind][foot].instanceMatrix.needsUpdate = true; }
    }
    const selected = state.selected >= 0;
    marks.ring.visible = selected;
    Object.values(marks.trails).forEach((l) => { l.visible = selected; });
    if (selected) placeTrails(v, state.selected);
    placeCamera(v, w, h);
    renderer.render(scene, camera);
    return counts;
  }

  // Where agent a's hips are on the canvas, CSS px [x, y] (after a draw).
  function project(v, a) {
    const p = v.hooks.sampleAt(a, v.state.t), s = new THREE.Vector3(p.x, 0.9, p.z).project(v.stage.camera);
    return [(s.x + 1) / 2 * v.canvas.clientWidth, (1 - s.y) / 2 * v.canvas.clientHeight, s.z];
  }

  // The character nearest the pointer on screen (its hips), within 24 px.
  function pick(v, mx, my) {
    let best = -1, bestD = 24 * 24;
    for (let a = 0; a < v.D.N; a++) {
      const [x, y, z] = project(v, a);
      if (z > 1) continue;  // behind the camera
      const dd = (x - mx) ** 2 + (y - my) ** 2;
      if (dd < bestD) { bestD = dd; best = a; }
    }
    return best;
  }

  // Left drag orbits, right (or shift) drag pans, the wheel zooms, a click
  // selects.
  function installControls(v) {
    const { canvas, state } = v, cam = v.stage.cam;
    let drag = null;
    canvas.addEventListener('contextmenu', (e) => e.preventDefault());
    canvas.addEventListener('mousedown', (e) => { drag = { x: e.offsetX, y: e.offsetY, pan: e.button === 2 || e.shiftKey, moved: false }; });
    window.addEventListener('mouseup', (e) => {
      if (drag && !drag.moved && e.target === canvas) {
        const a = pick(v, e.offsetX, e.offsetY);
        if (a >= 0) v.hooks.select(a);
      }
      drag = null;
    });
    canvas.addEventListener('mousemove', (e) => {
      if (!drag) return;
      const dx = e.offsetX - drag.x, dy = e.offsetY - drag.y;
      if (Math.abs(dx) + Math.abs(dy) > 3) drag.moved = true;
      if (!drag.moved) return;
      if (drag.pan) {
        const k = cam.dist / canvas.clientHeight, c = Math.cos(cam.yaw), s = Math.sin(cam.yaw);
        cam.target.x -= (c * dx + s * dy) * k; cam.target.z -= (-s * dx + c * dy) * k;
      } else {
        cam.yaw -= dx * 0.008; cam.pitch += dy * 0.006;
      }
      drag.x = e.offsetX; drag.y = e.offsetY; state.dirty = true;
    });
    canvas.addEventListener('wheel', (e) => {
      e.preventDefault();
      cam.dist *= Math.exp(e.deltaY * 0.0015); state.dirty = true;
    }, { passive: false });
  }

  // hooks: { D, state, worldPose(a, t) -> Float32Array [J*3] world or null,
  //          sampleAt(a, t), feetAt(a, t), hue(a), colors, select(a) }
  function create(canvas, hooks) {
    const D = hooks.D, stage = makeStage(canvas, D);
    const v = { D, state: hooks.state, hooks, canvas, stage, bodies: makeBodies(D, hooks, stage.scene),
                marks: makeMarks(D, hooks, stage.scene) };
    installControls(v);
    const cam = stage.cam;
    return {
      draw: () => draw(v),
      project: (a) => project(v, a).slice(0, 2),
      // Hides the characters and their marks, leaving the empty ground (a
      // test compares the two).
      showCharacters(on) {
        const { bodies, marks } = v;
        for (const object of [bodies.boneMesh, bodies.jointMesh, marks.ring, ...marks.feet.flat(), ...Object.values(marks.trails)]) {
          object.layers.set(on ? 0 : 1);
        }
      },
      // ?cam=DIST,YAW,PITCH[,HEIGHT] (metres, radians; HEIGHT: of the
      // point looked at, 0.9 m by default): a known camera.
      setCamera(dist, yaw, pitch, height) {
        if (Number.isFinite(dist)) cam.dist = dist;
        if (Number.isFinite(yaw)) cam.yaw = yaw;
        if (Number.isFinite(pitch)) cam.pitch = pitch;
        if (Number.isFinite(height)) cam.height = height;
      },
      lookAtSelected() {
        if (hooks.state.selected < 0) return;
        const p = hooks.sampleAt(hooks.state.selected, hooks.state.t);
        cam.target.set(p.x, cam.height, p.z);
      },
    };
  }

  return { create };
})();
