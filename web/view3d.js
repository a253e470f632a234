// The 3-D view: a tube of the job's radius around each component of the
// polygon, the struts inside it as rods from p to q sized and coloured by
// force, and one strut highlighted on demand.  It renders on demand (after
// a change or a camera move), not in a loop, to stay cheap while idle.

import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';

export const COMPONENT_COLOURS = ['#2f6fde', '#e0742b', '#2a9d62', '#c23b8f', '#8a6d1f', '#5b4fc7', '#1b9aaa', '#c0392b'];
const BACKGROUND = 0xf7f8fa;
const RADIAL = 14;

// Force colour ramp: blue (slack) through green and yellow to red.
const RAMP = ['#3b6fd8', '#27a3a0', '#8cc63f', '#f2c12e', '#e4572e'];
export function forceColour(f) {
    const x = Math.max(0, Math.min(1, Number.isFinite(f) ? f : 0)) * (RAMP.length - 1);
    const i = Math.min(RAMP.length - 2, Math.floor(x));
    const a = new THREE.Color(RAMP[i]), b = new THREE.Color(RAMP[i + 1]);
    return a.lerp(b, x - i);
}
export const rampCss = `linear-gradient(to right, ${RAMP.join(', ')})`;

// The view for the container: the 3-D one, or where the browser offers no
// WebGL 2 (blocked, switched off, no usable driver) a stand-in that says so
// and leaves the rest of the page working.
export function createView(container) {
    const canvas = document.createElement('canvas');
    let why = '';
    canvas.addEventListener('webglcontextcreationerror', (e) => { why = e.statusMessage || ''; });
    // preserveDrawingBuffer lets the picture be read back (tests, saving).
    const gl = canvas.getContext('webgl2', {
        alpha: true, depth: true, stencil: false, antialias: true,
        premultipliedAlpha: true, preserveDrawingBuffer: true,
    });
    return gl ? new View3D(container, canvas, gl) : new NoView3D(container, why);
}

export class NoView3D {
    constructor(container, why) {
        this.unavailable = true;
        const p = document.createElement('p');
        p.className = 'view3d-message';
        p.setAttribute('role', 'status');
        p.textContent = 'No 3-D view: this browser does not provide WebGL 2, which the view needs. ' +
            'The figures, tables, chart and contact map work without it.';
        if (why) p.title = why.trim();
        container.append(p);
    }

    render() {}
    renderNow() {}
    setOpacity() {}
    setShowStruts() {}
    clear() {}
    setCurve() {}
    setStruts() {}
    setConstraints() {}
    highlight() {}
    clearHighlight() {}
    fit() {}
}

export class View3D {
    constructor(container, canvas, context) {
        this.container = container;
        this.renderer = new THREE.WebGLRenderer({ canvas, context, antialias: true, preserveDrawingBuffer: true });
        this.renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
        this.renderer.setClearColor(BACKGROUND, 1);
        container.appendChild(this.renderer.domElement);

        this.scene = new THREE.Scene();
        this.camera = new THREE.PerspectiveCamera(40, 1, 0.01, 1e5);
        this.camera.position.set(0, -10, 6);
        this.camera.up.set(0, 0, 1);
        this.controls = new OrbitControls(this.camera, this.renderer.domElement);
        this.controls.addEventListener('change', () => this.render());

        this.scene.add(new THREE.HemisphereLight(0xffffff, 0x9098a8, 2.2));
        const key = new THREE.DirectionalLight(0xffffff, 2.0);
        key.position.set(1, -1, 2);
        this.camera.add(key);
        this.scene.add(this.camera);

        this.tubeGroup = new THREE.Group();
        this.strutGroup = new THREE.Group();
        this.highlightGroup = new THREE.Group();
        this.constraintGroup = new THREE.Group();
        this.scene.add(this.strutGroup, this.tubeGroup, this.highlightGroup, this.constraintGroup);

        this.tubes = [];      // per component: { mesh, line, n, closed }
        this.radius = 0.5;
        this.opacity = 0.4;
        this.struts = [];
        this.showStruts = true;
        this.pending = false;

        new ResizeObserver(() => this.resize()).observe(container);
        this.resize();
    }

    resize() {
        const w = Math.max(1, this.container.clientWidth), h = Math.max(1, this.container.clientHeight);
        this.renderer.setSize(w, h, false);
        this.camera.aspect = w / h;
        this.camera.updateProjectionMatrix();
        this.render();
    }

    render() {
        if (this.pending) return;
        this.pending = true;
        requestAnimationFrame(() => {
            this.pending = false;
            this.renderer.render(this.scene, this.camera);
        });
    }

    // The picture as a PNG blob (rendered now: the canvas read back).
    png() {
        this.renderer.render(this.scene, this.camera);
        return new Promise((res) => this.renderer.domElement.toBlob(res, 'image/png'));
    }

    // Renders now; callers reading the canvas back want the current picture.
    renderNow() {
        this.renderer.render(this.scene, this.camera);
    }

    setOpacity(a) {
        this.opacity = a;
        for (const t of this.tubes) {
            t.mesh.material.opacity = a;
            t.mesh.material.transparent = a < 1;
            t.mesh.material.depthWrite = a >= 1;
            t.mesh.visible = a > 0;
            t.mesh.material.needsUpdate = true;
        }
        this.render();
    }

    setShowStruts(on) {
        this.showStruts = on;
        this.strutGroup.visible = on;
        this.render();
    }

    clear() {
        for (const t of this.tubes) {
            t.mesh.geometry.dispose(); t.mesh.material.dispose();
            t.line.geometry.dispose(); t.line.material.dispose();
        }
        this.tubeGroup.clear();
        this.tubes = [];
        this.setStruts([]);
        this.render();
    }

    // comps: [{ points: Float64Array, closed }].  The meshes are reused while
    // the layout stays the same, which is what makes the replay cheap.
    setCurve(comps, radius) {
        const sameLayout = this.tubes.length === comps.length && radius === this.radius &&
            comps.every((c, i) => c.points.length / 3 === this.tubes[i].n && c.closed === this.tubes[i].closed);
        if (!sameLayout) {
            for (const t of this.tubes) {
                t.mesh.geometry.dispose(); t.mesh.material.dispose();
                t.line.geometry.dispose(); t.line.material.dispose();
            }
            this.tubeGroup.clear();
            this.tubes = [];
            this.radius = radius;
            comps.forEach((c, i) => {
                const n = c.points.length / 3;
                const geom = tubeGeometry(n, c.closed);
                const colour = new THREE.Color(COMPONENT_COLOURS[i % COMPONENT_COLOURS.length]);
                const mat = new THREE.MeshStandardMaterial({
                    color: colour, roughness: 0.45, metalness: 0.05,
                    transparent: this.opacity < 1, opacity: this.opacity, depthWrite: this.opacity >= 1,
                    // Back faces drawn through a translucent tube read as
                    // stray fins, so only the outside is drawn.
                    side: THREE.FrontSide,
                });
                const mesh = new THREE.Mesh(geom, mat);
                mesh.visible = this.opacity > 0;
                const lgeom = new THREE.BufferGeometry();
                lgeom.setAttribute('position', new THREE.BufferAttribute(new Float32Array(3 * n), 3));
                const line = c.closed
                    ? new THREE.LineLoop(lgeom, new THREE.LineBasicMaterial({ color: colour.clone().multiplyScalar(0.6) }))
                    : new THREE.Line(lgeom, new THREE.LineBasicMaterial({ color: colour.clone().multiplyScalar(0.6) }));
                this.tubeGroup.add(mesh, line);
                this.tubes.push({ mesh, line, n, closed: c.closed });
            });
        }
        comps.forEach((c, i) => {
            const t = this.tubes[i];
            fillTube(t.mesh.geometry, c.points, c.closed, radius);
            const lp = t.line.geometry.attributes.position;
            lp.array.set(c.points);
            lp.needsUpdate = true;
            t.line.geometry.computeBoundingSphere();
        });
        this.render();
    }

    // struts: the API's strut objects; their force sets colour and girth.
    setStruts(struts) {
        for (const m of this.strutGroup.children) { m.geometry.dispose(); m.material.dispose(); }
        this.strutGroup.clear();
        this.struts = struts;
        this.clearHighlight();
        if (!struts.length) { this.render(); return; }
        const fmax = Math.max(1e-300, ...struts.map((s) => (Number.isFinite(s.force) ? s.force : 0)));
        const geom = new THREE.CylinderGeometry(1, 1, 1, 8, 1);
        const mat = new THREE.MeshStandardMaterial({ roughness: 0.6 });
        const mesh = new THREE.InstancedMesh(geom, mat, struts.length);
        const m = new THREE.Matrix4();
        struts.forEach((s, i) => {
            const f = (Number.isFinite(s.force) ? s.force : 0) / fmax;
            rodMatrix(m, s.p, s.q, this.radius * (0.04 + 0.12 * Math.sqrt(f)));
            mesh.setMatrixAt(i, m);
            mesh.setColorAt(i, forceColour(f));
        });
        mesh.instanceMatrix.needsUpdate = true;
        if (mesh.instanceColor) mesh.instanceColor.needsUpdate = true;
        this.strutGroup.add(mesh);
        this.strutGroup.visible = this.showStruts;
        this.render();
    }

    // constraints: the API's constraints ({comp, vertex, constraint: the
    // --constrain text}); comps as setCurve's.  A constrained vertex is a
    // dark ball; its plane a translucent square four diameters across
    // about it, its line a rod through it, its point a cube.
    setConstraints(constraints, comps) {
        for (const m of this.constraintGroup.children) { m.geometry.dispose(); m.material.dispose(); }
        this.constraintGroup.clear();
        const d = 2 * this.radius;
        for (const c of constraints || []) {
            const pts = comps[c.comp]?.points;
            const m = /=(\w+)(?::(.*))?$/.exec(c.constraint);
            if (!pts || !m || 3 * c.vertex + 2 >= pts.length) continue;
            const at = new THREE.Vector3(pts[3 * c.vertex], pts[3 * c.vertex + 1], pts[3 * c.vertex + 2]);
            const x = (m[2] || '').split(',').map(Number);
            const ball = new THREE.Mesh(new THREE.SphereGeometry(0.35 * d, 16, 12),
                new THREE.MeshStandardMaterial({ color: 0x222831, roughness: 0.5 }));
            ball.position.copy(at);
            this.constraintGroup.add(ball);
            const faint = new THREE.MeshStandardMaterial({ color: 0x7a4cc2, transparent: true, opacity: 0.3,
                side: THREE.DoubleSide, depthWrite: false });
            if (m[1] === 'plane' && x.length === 4) {
                const sheet = new THREE.Mesh(new THREE.PlaneGeometry(4 * d, 4 * d), faint);
                sheet.position.copy(at);
                sheet.quaternion.setFromUnitVectors(new THREE.Vector3(0, 0, 1),
                    new THREE.Vector3(x[0], x[1], x[2]).normalize());
                this.constraintGroup.add(sheet);
            } else if (m[1] === 'line' && x.length === 6) {
                const rod = new THREE.Mesh(new THREE.CylinderGeometry(0.06 * d, 0.06 * d, 6 * d, 8), faint);
                rod.position.copy(at);
                rod.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0),
                    new THREE.Vector3(x[3], x[4], x[5]).normalize());
                this.constraintGroup.add(rod);
            } else if (m[1] === 'point') {
                const cube = new THREE.Mesh(new THREE.BoxGeometry(d, d, d), faint);
                cube.position.copy(at);
                this.constraintGroup.add(cube);
            }
        }
        this.render();
    }

    highlight(index) {
        this.clearHighlight();
        const s = this.struts[index];
        if (!s) return;
        const r = this.radius * 0.2;
        const mat = new THREE.MeshStandardMaterial({ color: 0xff1f8f, emissive: 0x550022, roughness: 0.4, depthTest: false });
        const rod = new THREE.Mesh(new THREE.CylinderGeometry(1, 1, 1, 10, 1), mat);
        rodMatrix(rod.matrix, s.p, s.q, r);
        rod.matrixAutoUpdate = false;
        rod.renderOrder = 10;
        this.highlightGroup.add(rod);
        for (const x of [s.p, s.q]) {
            const ball = new THREE.Mesh(new THREE.SphereGeometry(r * 1.8, 16, 12), mat.clone());
            ball.position.set(x[0], x[1], x[2]);
            ball.renderOrder = 10;
            this.highlightGroup.add(ball);
        }
        this.render();
    }

    clearHighlight() {
        for (const m of this.highlightGroup.children) { m.geometry.dispose(); m.material.dispose(); }
        this.highlightGroup.clear();
        this.render();
    }

    // Puts the camera where the whole tube is in view, keeping its direction.
    fit() {
        const box = new THREE.Box3();
        for (const t of this.tubes) {
            t.line.geometry.computeBoundingBox();
            box.union(t.line.geometry.boundingBox);
        }
        if (box.isEmpty()) return;
        // The sphere about the box's centre through the farthest vertex is
        // tighter than the box's own bounding sphere.
        const sphere = new THREE.Sphere(box.getCenter(new THREE.Vector3()), 0);
        const v = new THREE.Vector3();
        for (const t of this.tubes) {
            const a = t.line.geometry.attributes.position;
            for (let i = 0; i < a.count; i++) {
                const d = v.fromBufferAttribute(a, i).distanceTo(sphere.center);
                if (d > sphere.radius) sphere.radius = d;
            }
        }
        const r = sphere.radius + this.radius;
        const fov = (this.camera.fov * Math.PI) / 180;
        const fovMin = Math.min(fov, 2 * Math.atan(Math.tan(fov / 2) * this.camera.aspect));
        const dist = (r / Math.sin(fovMin / 2)) * 1.02;
        const dir = this.camera.position.clone().sub(this.controls.target);
        if (dir.lengthSq() < 1e-12) dir.set(0, -1, 0.6);
        dir.normalize();
        this.controls.target.copy(sphere.center);
        this.camera.position.copy(sphere.center).addScaledVector(dir, dist);
        this.camera.near = Math.max(dist / 1000, 1e-3);
        this.camera.far = dist * 20;
        this.camera.updateProjectionMatrix();
        this.controls.update();
        this.render();
    }
}

// A rod of the given radius from a to b (a unit cylinder along y, moved).
function rodMatrix(m, a, b, radius) {
    const pa = new THREE.Vector3(...a), pb = new THREE.Vector3(...b);
    const dir = pb.clone().sub(pa);
    const len = dir.length();
    const q = new THREE.Quaternion();
    if (len > 0) q.setFromUnitVectors(new THREE.Vector3(0, 1, 0), dir.clone().divideScalar(len));
    m.compose(pa.add(pb).multiplyScalar(0.5), q, new THREE.Vector3(radius, Math.max(len, 1e-9), radius));
    return m;
}

// The index structure of a tube of n rings of RADIAL vertices each; the
// positions and normals are filled by fillTube.
function tubeGeometry(n, closed) {
    const geom = new THREE.BufferGeometry();
    const ring = RADIAL + 1; // a seam vertex keeps the normals per ring simple
    geom.setAttribute('position', new THREE.BufferAttribute(new Float32Array(3 * ring * n), 3));
    geom.setAttribute('normal', new THREE.BufferAttribute(new Float32Array(3 * ring * n), 3));
    const segs = closed ? n : n - 1;
    const idx = [];
    for (let i = 0; i < segs; i++) {
        const a = i * ring, b = ((i + 1) % n) * ring;
        for (let j = 0; j < RADIAL; j++) {
            // counter-clockwise seen from outside, so the outside is the front
            idx.push(a + j, a + j + 1, b + j, a + j + 1, b + j + 1, b + j);
        }
    }
    geom.setIndex(n * ring > 65535 ? new THREE.Uint32BufferAttribute(idx, 1) : new THREE.Uint16BufferAttribute(idx, 1));
    return geom;
}

// Rings around each vertex, perpendicular to the bisecting tangent, with a
// frame carried along by parallel transport (double reflection); on a closed
// curve the frame's twist on return is spread evenly so the tube has no seam.
function fillTube(geom, pts, closed, radius) {
    const n = pts.length / 3;
    const P = (i) => {
        const j = closed ? ((i % n) + n) % n : Math.max(0, Math.min(n - 1, i));
        return new THREE.Vector3(pts[3 * j], pts[3 * j + 1], pts[3 * j + 2]);
    };
    const T = [];
    for (let i = 0; i < n; i++) {
        const prev = P(i).sub(P(i - 1)), next = P(i + 1).sub(P(i));
        const t = new THREE.Vector3();
        if (prev.lengthSq() > 0) t.add(prev.normalize());
        if (next.lengthSq() > 0) t.add(next.normalize());
        if (t.lengthSq() < 1e-20) t.copy(next.lengthSq() > 0 ? next : new THREE.Vector3(1, 0, 0));
        T.push(t.normalize());
    }
    const N = new Array(n);
    N[0] = anyPerpendicular(T[0]);
    const transport = (r, i, j) => {
        const v1 = P(j).sub(P(i));
        const c1 = v1.dot(v1);
        if (c1 < 1e-30) return r.clone();
        const rL = r.clone().addScaledVector(v1, (-2 / c1) * v1.dot(r));
        const tL = T[i].clone().addScaledVector(v1, (-2 / c1) * v1.dot(T[i]));
        const v2 = T[j].clone().sub(tL);
        const c2 = v2.dot(v2);
        if (c2 < 1e-30) return rL;
        return rL.addScaledVector(v2, (-2 / c2) * v2.dot(rL)).normalize();
    };
    for (let i = 0; i + 1 < n; i++) N[i + 1] = transport(N[i], i, i + 1);
    if (closed && n > 2) {
        const back = transport(N[n - 1], n - 1, 0);
        const B0 = new THREE.Vector3().crossVectors(T[0], N[0]);
        const twist = Math.atan2(back.dot(B0), back.dot(N[0]));
        for (let i = 1; i < n; i++) N[i].applyAxisAngle(T[i], (-twist * i) / n);
    }
    const pos = geom.attributes.position.array, nor = geom.attributes.normal.array;
    const ring = RADIAL + 1;
    const b = new THREE.Vector3(), d = new THREE.Vector3();
    for (let i = 0; i < n; i++) {
        const c = P(i);
        b.crossVectors(T[i], N[i]);
        for (let j = 0; j < ring; j++) {
            const a = (2 * Math.PI * j) / RADIAL;
            d.copy(N[i]).multiplyScalar(Math.cos(a)).addScaledVector(b, Math.sin(a));
            const k = 3 * (i * ring + j);
            pos[k] = c.x + radius * d.x; pos[k + 1] = c.y + radius * d.y; pos[k + 2] = c.z + radius * d.z;
            nor[k] = d.x; nor[k + 1] = d.y; nor[k + 2] = d.z;
        }
    }
    geom.attributes.position.needsUpdate = true;
    geom.attributes.normal.needsUpdate = true;
    geom.computeBoundingSphere();
}

function anyPerpendicular(t) {
    const a = Math.abs(t.x) < 0.9 ? new THREE.Vector3(1, 0, 0) : new THREE.Vector3(0, 1, 0);
    return a.sub(t.clone().multiplyScalar(a.dot(t))).normalize();
}
