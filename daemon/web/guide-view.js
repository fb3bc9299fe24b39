// The assembly guide in 3D (three.js, the global THREE): the structure with
// its panels coloured as placed, next or to come, the view turned to each
// next panel, and the panel's sheet, neighbours and holes told beside it.

import { $, element } from './dom.js';
import { coarseStructure, sharedHoles } from './guide-data.js';

const colours = {
  placed: [0.79, 0.66, 0.42],
  next: [1.0, 0.42, 0.0],
  later: [0.78, 0.8, 0.83],
};

export class Guide {
  constructor(container) {
    this.container = container;
    this.views = [];
    this.showing = false;
    this.frames = 0;
    this.spin = 0;
    this.loop = this.loop.bind(this);
    // Without WebGL (or three.js) the steps are still told, in words.
    try {
      if (typeof THREE === 'undefined') throw new Error('three.js is not installed (Debian package libjs-three)');
      this.renderer = new THREE.WebGLRenderer({ antialias: false });
    } catch (failure) {
      this.renderer = null;
      container.replaceChildren(element('p', { class: 'no-3d' },
        `No 3D view in this browser (${failure.message || failure}); the steps, panels and holes are told beside it.`));
      return;
    }
    this.renderer.setClearColor(0xf0f2f4);
    container.append(this.renderer.domElement);
    this.scene = new THREE.Scene();
    this.camera = new THREE.PerspectiveCamera(40, 1, 0.01, 1e5);
    this.controls = new THREE.OrbitControls(this.camera, this.renderer.domElement);
    this.controls.enableDamping = true;
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x667788, 0.8));
    this.light = new THREE.DirectionalLight(0xffffff, 0.6);
    this.scene.add(this.light);
    new ResizeObserver(() => this.resize()).observe(container);
  }

  resize() {
    const width = this.container.clientWidth;
    const height = this.container.clientHeight;
    if (!width || !height) return;
    this.renderer.setSize(width, height);
    this.camera.aspect = width / height;
    this.camera.updateProjectionMatrix();
    this.dirty = true;
  }

  visible(on) {
    if (!this.renderer) return;
    const was = this.showing;
    this.showing = on;
    if (on && !was) {
      this.resize();
      requestAnimationFrame(this.loop);
    }
  }

  loop() {
    if (!this.showing) return;
    requestAnimationFrame(this.loop);
    if (this.spin) {
      // For the frame-rate measure: orbit without a hand on the mouse.
      this.controls.autoRotate = true;
      this.controls.autoRotateSpeed = this.spin;
    }
    if (this.goal) {
      // Towards the next panel, a fifth of the way each frame.
      this.controls.target.lerp(this.goal.target, 0.2);
      this.camera.position.lerp(this.goal.position, 0.2);
      if (this.camera.position.distanceTo(this.goal.position) < this.goal.near) this.goal = null;
    }
    const moved = this.controls.update();
    // Coarse while the view moves and a few frames after; the panels
    // themselves once it rests. Nothing is drawn while nothing changes.
    if (moved) this.moving = 6;
    const inMotion = this.moving > 0;
    const coarse = inMotion && this.views.length > 1;
    if (this.moving > 0) this.moving -= 1;
    if (!moved && !this.dirty && !inMotion && this.drewFull) return;
    // Half the pixels each way while it moves (software WebGL fills
    // pixels slowly), all of them once it rests.
    const ratio = (window.devicePixelRatio || 1) * (inMotion ? 0.5 : 1);
    if (this.renderer.getPixelRatio() !== ratio) this.renderer.setPixelRatio(ratio);
    this.views.forEach((view, k) => { view.mesh.visible = k === (coarse ? 1 : 0); });
    this.light.position.copy(this.camera.position);
    this.renderer.render(this.scene, this.camera);
    this.frames += 1;
    this.drewFull = !inMotion;
    this.dirty = false;
  }

  // A mesh of the structure, its colours kept per vertex and its panels' vertex ranges.
  makeView(structure) {
    const geometry = new THREE.BufferGeometry();
    const vertexCount = structure.positions.length / 3;
    const IndexArray = vertexCount > 65535 ? Uint32Array : Uint16Array;
    geometry.setIndex(new THREE.BufferAttribute(new IndexArray(structure.index), 1));
    geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(structure.positions), 3));
    const colour = new Float32Array(vertexCount * 3);
    geometry.setAttribute('color', new THREE.BufferAttribute(colour, 3));
    geometry.computeVertexNormals();
    geometry.computeBoundingSphere();
    const material = new THREE.MeshLambertMaterial({ vertexColors: THREE.VertexColors, side: THREE.DoubleSide });
    const mesh = new THREE.Mesh(geometry, material);
    this.scene.add(mesh);
    return { mesh, colour, ranges: structure.ranges };
  }

  load(structure, manifest) {
    // Assembly order, as manifest.txt's steps: a panel's id is its step
    // (the flood fill's order; `order` is where it comes in the cutting).
    this.panels = [...manifest.panels].sort((a, b) => a.id - b.id);
    this.byId = new Map(manifest.panels.map((panel) => [panel.id, panel]));
    this.step = 0;
    if (!this.renderer) {
      this.goTo(1);
      return;
    }
    for (const view of this.views) {
      this.scene.remove(view.mesh);
      view.mesh.geometry.dispose();
    }
    this.views = [this.makeView(structure)];
    // Small structures are drawn whole even while they move.
    if (structure.index.length / 3 > 20000) this.views.push(this.makeView(coarseStructure(structure)));
    const sphere = this.views[0].mesh.geometry.boundingSphere;
    this.controls.target.copy(sphere.center);
    this.camera.near = sphere.radius / 100;
    this.camera.far = sphere.radius * 100;
    this.camera.position.copy(this.wholeView().position);
    this.camera.updateProjectionMatrix();
    this.controls.update();
    this.paint(0, this.panels.length, 'later');
    this.goTo(1);
  }

  // Colours the panels at steps [from, to) (0-based) as `kind`, in every view.
  paint(from, to, kind) {
    const [r, g, b] = colours[kind];
    for (const view of this.views) {
      for (let k = from; k < to; k += 1) {
        const range = view.ranges.get(this.panels[k].id);
        if (!range) continue;
        for (let v = range[0]; v < range[1]; v += 1) {
          view.colour[3 * v] = r;
          view.colour[3 * v + 1] = g;
          view.colour[3 * v + 2] = b;
        }
      }
      view.mesh.geometry.attributes.color.needsUpdate = true;
    }
    this.dirty = true;
  }

  goTo(step) {
    step = Math.max(1, Math.min(this.panels.length, step));
    const before = this.step;
    // Only the panels whose colour changes are painted again.
    if (step > before) {
      this.paint(Math.max(0, before - 1), step - 1, 'placed');
    } else if (before > 0) {
      this.paint(step, before, 'later');
    }
    this.paint(step - 1, step, 'next');
    this.step = step;
    if (this.renderer && $('guide-follow').checked) this.focusOn(this.panels[step - 1].id);
    this.describe();
  }

  // The whole structure in view, from the front and a little above.
  wholeView() {
    const sphere = this.views[0].mesh.geometry.boundingSphere;
    const position = sphere.center.clone()
      .add(new THREE.Vector3(0.4, 0.5, 1).normalize().multiplyScalar(sphere.radius * 3));
    return { target: sphere.center.clone(), position, near: sphere.radius / 100 };
  }

  showWhole() {
    if (!this.renderer || !this.views.length) return;
    this.goal = this.wholeView();
    this.dirty = true;
  }

  // The view turned to face the panel from outside the structure, close
  // enough to see it and its neighbours.
  focusOn(id) {
    const range = this.views[0].ranges.get(id);
    if (!range) return;
    const geometry = this.views[0].mesh.geometry;
    const position = geometry.attributes.position.array;
    const normal = geometry.attributes.normal.array;
    const centre = new THREE.Vector3();
    const facing = new THREE.Vector3();
    for (let v = range[0]; v < range[1]; v += 1) {
      centre.x += position[3 * v];
      centre.y += position[3 * v + 1];
      centre.z += position[3 * v + 2];
      facing.x += normal[3 * v];
      facing.y += normal[3 * v + 1];
      facing.z += normal[3 * v + 2];
    }
    centre.divideScalar(range[1] - range[0]);
    let size = 0;
    for (let v = range[0]; v < range[1]; v += 1) {
      size = Math.max(size, centre.distanceTo(new THREE.Vector3(position[3 * v], position[3 * v + 1], position[3 * v + 2])));
    }
    const sphere = geometry.boundingSphere;
    const outwards = centre.clone().sub(sphere.center);
    if (facing.lengthSq() === 0) facing.copy(outwards);
    if (facing.dot(outwards) < 0) facing.negate();
    facing.normalize();
    const distance = Math.min(Math.max(size * 12, sphere.radius * 0.5), sphere.radius * 3);
    this.goal = { target: centre, position: centre.clone().addScaledVector(facing, distance), near: distance / 200 };
    this.dirty = true;
  }

  describe() {
    const panel = this.panels[this.step - 1];
    $('guide-step').textContent = String(this.step);
    $('guide-steps').textContent = String(this.panels.length);
    $('guide-panel-number').textContent = String(panel.id);
    $('guide-panel-sheet').textContent = panel.sheet ? String(panel.sheet) : '–';
    const placedBefore = (other) => other.id < panel.id;
    const neighbours = (panel.neighbors || []).map((id) => this.byId.get(id)).filter(Boolean);
    $('guide-panel-neighbours').textContent = neighbours.length
      ? neighbours.map((other) => `${other.id}${placedBefore(other) ? ' (placed)' : ''}`).join(', ')
      : '–';
    const holes = $('guide-panel-holes');
    holes.replaceChildren();
    for (const other of neighbours) {
      const shared = sharedHoles(panel, other);
      if (!shared.length) continue;
      holes.append(element('li', {}, `with ${other.id}: ${shared.map((s) => `edge ${s.edge} (${s.count} hole${s.count === 1 ? '' : 's'})`).join(', ')}`));
    }
    if (this.renderer) this.renderer.domElement.setAttribute('data-highlighted', String(panel.id));
  }

  // The panel whose vertices are painted as the next one, read from what is drawn.
  highlighted() {
    if (!this.renderer) return [];
    const [r, g, b] = colours.next;
    const found = [];
    const { colour, ranges } = this.views[0];
    for (const [id, range] of ranges) {
      const v = range[0];
      if (range[1] > v && colour[3 * v] === Math.fround(r) && colour[3 * v + 1] === Math.fround(g) &&
          colour[3 * v + 2] === Math.fround(b)) {
        found.push(id);
      }
    }
    return found;
  }

  // Frames drawn per second over `milliseconds`, orbiting.
  measure(milliseconds) {
    return new Promise((resolve) => {
      this.spin = 30;
      const start = performance.now();
      const frames = this.frames;
      setTimeout(() => {
        const rate = ((this.frames - frames) * 1000) / (performance.now() - start);
        this.spin = 0;
        this.controls.autoRotate = false;
        resolve(rate);
      }, milliseconds);
    });
  }
}
