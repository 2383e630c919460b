// drivedyn 3-D viewer: draws the scene written by drivedyn.viewer.html (JSON in the page,
// arrays as base64) with three.js. Every body is a THREE.Group moved by its node's pose at
// the current frame; rigid meshes are its children; beams and flexible parts are rebuilt
// each frame from their vertex data and the deformation scale factor.
(function () {
  "use strict";
  const D = JSON.parse(document.getElementById("scene-data").textContent);

  function b64(s, Type) {
    const bin = atob(s);
    const buf = new ArrayBuffer(bin.length);
    const u8 = new Uint8Array(buf);
    for (let i = 0; i < bin.length; i++) u8[i] = bin.charCodeAt(i);
    return new Type(buf);
  }
  const F32 = Float32Array, U32 = Uint32Array;
  const nf = D.nf, nn = D.nodes.length;
  const time = b64(D.time, F32), pos = b64(D.position, F32), quat = b64(D.quaternion, F32);

  // ---- renderer, camera, lights -------------------------------------------------------
  const view = document.getElementById("view");
  const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  renderer.localClippingEnabled = false;
  view.appendChild(renderer.domElement);
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0xf4f5f7);
  const L = D.length;
  const camera = new THREE.PerspectiveCamera(35, 1, L * 1e-3, L * 1e3);
  camera.up.set(0, 0, 1);
  scene.add(new THREE.HemisphereLight(0xffffff, 0x667788, 0.75));
  const sun = new THREE.DirectionalLight(0xffffff, 0.6);
  camera.add(sun);
  sun.position.set(1, 1, 2);
  scene.add(camera);
  const controls = new THREE.OrbitControls(camera, renderer.domElement);
  controls.addEventListener("change", () => { if (el("section").checked) updateSection(); else render(); });

  // ---- bodies -------------------------------------------------------------------------
  const groups = D.nodes.map((n) => { const g = new THREE.Group(); g.name = n; scene.add(g); return g; });
  const ground = new THREE.Group(); ground.name = "ground"; scene.add(ground);
  const parentOf = (i) => (i < 0 ? ground : groups[i]);
  const solid = [], ghosts = [], roads = [];
  for (const m of D.meshes) {
    const geo = new THREE.BufferGeometry();
    geo.setAttribute("position", new THREE.BufferAttribute(b64(m.vertices, F32), 3));
    geo.setIndex(new THREE.BufferAttribute(b64(m.triangles, U32), 1));
    geo.computeVertexNormals();
    const transparent = m.opacity < 1;
    const mat = new THREE.MeshStandardMaterial({
      color: new THREE.Color(m.colour[0], m.colour[1], m.colour[2]), metalness: 0.25,
      roughness: 0.55, flatShading: m.role === "gear" || m.role === "body",
      transparent: transparent, opacity: m.opacity, depthWrite: !transparent,
      side: THREE.DoubleSide,  // sections show the inside of cut shells
    });
    const mesh = new THREE.Mesh(geo, mat);
    mesh.name = m.name;
    mesh.renderOrder = transparent ? 2 : 0;
    parentOf(m.node).add(mesh);
    (m.role === "road" ? roads : transparent ? ghosts : solid).push(mesh);
  }

  // frames drawn on request: markers (small) and joint axes (larger)
  function triads(list, size) {
    const out = [];
    for (const m of list) {
      const a = new THREE.AxesHelper(size);
      a.position.set(m.position[0], m.position[1], m.position[2]);
      const r = m.rotation;
      a.setRotationFromMatrix(new THREE.Matrix4().set(r[0], r[1], r[2], 0, r[3], r[4], r[5], 0,
        r[6], r[7], r[8], 0, 0, 0, 0, 1));
      a.visible = false;
      a.name = m.name;
      parentOf(m.node).add(a);
      out.push(a);
    }
    return out;
  }
  const markerTriads = triads(D.markers, 0.04 * L);
  const jointTriads = triads(D.joints, 0.12 * L);

  // ---- force arrows (global frame, per frame): one scale for all, the largest = 0.4 L ----
  const arrows = [];
  let fmax = 0;
  for (const a of D.arrows) {
    const o = b64(a.origin, F32), v = b64(a.vector, F32);
    for (let i = 0; i < v.length; i += 3) fmax = Math.max(fmax, Math.hypot(v[i], v[i + 1], v[i + 2]));
    const h = new THREE.ArrowHelper(new THREE.Vector3(0, 0, 1), new THREE.Vector3(), 1, 0xd62728);
    h.name = a.name;
    // forces act inside the parts (pitch points, bores): drawn over them, not hidden
    for (const m of [h.line.material, h.cone.material]) { m.depthTest = false; m.transparent = true; }
    h.renderOrder = 10;
    ground.add(h);
    arrows.push({ helper: h, origin: o, vector: v });
  }
  const forceScale = fmax > 0 ? 0.4 * L / fmax : 0;

  // ---- shafts between bodies: a unit cylinder (along y) placed and stretched per frame;
  // coil springs: a helical tube along y, reshaped when its length changes --------------
  const links = [];
  const unitCylinder = new THREE.CylinderGeometry(1, 1, 1, 16, 1, false);
  const COIL_SEG = 20, WIRE_SEG = 8;  // segments per turn of a coil, around its wire
  function coilGeometry(turns) {
    const nh = Math.max(2, Math.round(turns * COIL_SEG) + 1);
    const geo = new THREE.BufferGeometry();
    geo.setAttribute("position", new THREE.BufferAttribute(new Float32Array(nh * WIRE_SEG * 3), 3));
    const idx = [];
    for (let i = 0; i < nh - 1; i++) {
      for (let j = 0; j < WIRE_SEG; j++) {
        const a = i * WIRE_SEG + j, b = i * WIRE_SEG + (j + 1) % WIRE_SEG;
        idx.push(a, a + WIRE_SEG, b, b, a + WIRE_SEG, b + WIRE_SEG);
      }
    }
    geo.setIndex(idx);
    geo.userData.nh = nh;
    return geo;
  }
  // the helix of radius r and `turns` turns from y = 0 to y = len, a wire of radius w
  function shapeCoil(geo, len, r, turns, w) {
    const P = geo.attributes.position.array, nh = geo.userData.nh;
    const rise = len / (2 * Math.PI * turns);  // dy / dtheta
    let k = 0;
    for (let i = 0; i < nh; i++) {
      const f = i / (nh - 1), th = 2 * Math.PI * turns * f, c = Math.cos(th), s = Math.sin(th);
      let tx = -r * s, ty = rise, tz = r * c;  // tangent
      const tn = Math.hypot(tx, ty, tz); tx /= tn; ty /= tn; tz /= tn;
      const nx = -c, nz = -s;  // normal, towards the axis; binormal t x n
      const bx = ty * nz, by = tz * nx - tx * nz, bz = -ty * nx;
      for (let j = 0; j < WIRE_SEG; j++) {
        const ph = 2 * Math.PI * j / WIRE_SEG, cp = w * Math.cos(ph), sp = w * Math.sin(ph);
        P[k++] = r * c + cp * nx + sp * bx; P[k++] = len * f + sp * by; P[k++] = r * s + cp * nz + sp * bz;
      }
    }
    geo.attributes.position.needsUpdate = true;
    geo.computeVertexNormals();
    geo.computeBoundingSphere();
  }
  for (const k of D.links) {
    const coil = k.turns > 0;
    const mesh = new THREE.Mesh(coil ? coilGeometry(k.turns) : unitCylinder,
      new THREE.MeshStandardMaterial({ color: new THREE.Color(k.colour[0], k.colour[1], k.colour[2]),
        metalness: 0.3, roughness: 0.5, side: coil ? THREE.DoubleSide : THREE.FrontSide }));
    mesh.name = k.name;
    mesh.frustumCulled = false;
    scene.add(mesh);
    links.push({ mesh: mesh, a: b64(k.a, F32), b: b64(k.b, F32), r: k.radius, turns: k.turns,
      wire: k.wire, len: -1 });
  }

  // ---- tyre footprints on the road: a unit square (in xy) placed per frame ---------------
  const footprints = [];
  const unitSquare = new THREE.PlaneGeometry(1, 1);
  for (const fp of D.footprints) {
    const mesh = new THREE.Mesh(unitSquare, new THREE.MeshBasicMaterial({
      color: 0xd9480f, side: THREE.DoubleSide, polygonOffset: true, polygonOffsetFactor: -4,
      polygonOffsetUnits: -4 }));
    mesh.name = fp.name;
    mesh.renderOrder = 3;
    mesh.frustumCulled = false;
    scene.add(mesh);
    footprints.push({ mesh: mesh, c: b64(fp.centre, F32), hd: b64(fp.heading, F32),
      len: b64(fp.length, F32), w: fp.width });
  }

  // ---- colour map (turbo-like, 0..1) ----------------------------------------------------
  const CMAP = [[0.19, 0.07, 0.23], [0.27, 0.42, 0.94], [0.10, 0.80, 0.82], [0.36, 0.98, 0.40],
    [0.89, 0.86, 0.21], [0.98, 0.50, 0.13], [0.80, 0.16, 0.04], [0.48, 0.02, 0.01]];
  function cmap(x, out, k) {
    x = Math.min(1, Math.max(0, x)) * (CMAP.length - 1);
    const i = Math.min(CMAP.length - 2, Math.floor(x)), f = x - i;
    for (let c = 0; c < 3; c++) out[k + c] = CMAP[i][c] * (1 - f) + CMAP[i + 1][c] * f;
  }
  let smax = 0;

  // ---- beams: tubes through the nodes -----------------------------------------------------
  const RING = 12;
  const beams = [];
  for (const b of D.beams) {
    const nb = b.nodes.length;
    const geo = new THREE.BufferGeometry();
    const P = new Float32Array(nb * RING * 3), C = new Float32Array(nb * RING * 3);
    geo.setAttribute("position", new THREE.BufferAttribute(P, 3));
    geo.setAttribute("color", new THREE.BufferAttribute(C, 3));
    const idx = [];
    for (let j = 0; j < nb - 1; j++) for (let k = 0; k < RING; k++) {
      const a = j * RING + k, c = j * RING + (k + 1) % RING, d = a + RING, e = c + RING;
      idx.push(a, c, e, a, e, d);
    }
    geo.setIndex(idx);
    const mesh = new THREE.Mesh(geo, new THREE.MeshStandardMaterial({ vertexColors: true, metalness: 0.2, roughness: 0.6 }));
    mesh.name = b.name;
    mesh.frustumCulled = false;
    scene.add(mesh);
    const stress = b64(b.stress, F32);
    for (let i = 0; i < stress.length; i++) if (stress[i] === stress[i]) smax = Math.max(smax, stress[i]);
    beams.push({ b: b, mesh: mesh, rigid: b64(b.rigid, F32), stress: stress, ref: null });
  }

  // ---- meshed flexible parts ---------------------------------------------------------------
  const parts = [];
  for (const p of D.parts) {
    const pts = b64(p.points, F32), ns = pts.length / 3;
    const geo = new THREE.BufferGeometry();
    geo.setAttribute("position", new THREE.BufferAttribute(new Float32Array(pts), 3));
    geo.setAttribute("color", new THREE.BufferAttribute(new Float32Array(ns * 3), 3));
    geo.setIndex(new THREE.BufferAttribute(b64(p.triangles, U32), 1));
    const mesh = new THREE.Mesh(geo, new THREE.MeshStandardMaterial({ vertexColors: true, metalness: 0.1, roughness: 0.7 }));
    mesh.name = p.name;
    mesh.frustumCulled = false;
    parentOf(p.node).add(mesh);
    const stress = b64(p.stress, F32);
    for (let i = 0; i < stress.length; i++) if (stress[i] === stress[i]) smax = Math.max(smax, stress[i]);
    parts.push({ mesh: mesh, pts: pts, disp: b64(p.displacement, F32), stress: stress, ns: ns });
  }

  // ---- state and controls -------------------------------------------------------------------
  const el = (id) => document.getElementById(id);
  const slider = el("time"), label = el("tlabel");
  slider.max = String(nf - 1);
  let frame = 0, playing = false, scale = 1, last = null, tplay = time[0];

  function nodePose(i, f, out) {
    const o = (f * nn + i);
    out.position.set(pos[3 * o], pos[3 * o + 1], pos[3 * o + 2]);
    out.quaternion.set(quat[4 * o], quat[4 * o + 1], quat[4 * o + 2], quat[4 * o + 3]);
  }
  const v1 = new THREE.Vector3(), v2 = new THREE.Vector3(), tq = new THREE.Quaternion();

  function updateBeam(B, f) {
    const b = B.b, nb = b.nodes.length, P = B.mesh.geometry.attributes.position.array;
    const C = B.mesh.geometry.attributes.color.array;
    const X = [];
    for (let j = 0; j < nb; j++) {
      const o = 3 * (f * nn + b.nodes[j]), r = 3 * (f * nb + j);
      X.push(new THREE.Vector3(
        B.rigid[r] + scale * (pos[o] - B.rigid[r]),
        B.rigid[r + 1] + scale * (pos[o + 1] - B.rigid[r + 1]),
        B.rigid[r + 2] + scale * (pos[o + 2] - B.rigid[r + 2])));
    }
    if (B.ref === null) {  // a section direction fixed in each node's frame, from frame 0
      B.ref = [];
      for (let j = 0; j < nb; j++) {
        const t = X[Math.min(j + 1, nb - 1)].clone().sub(X[Math.max(j - 1, 0)]).normalize();
        const e = Math.abs(t.z) < 0.9 ? new THREE.Vector3(0, 0, 1) : new THREE.Vector3(1, 0, 0);
        e.sub(t.clone().multiplyScalar(e.dot(t))).normalize();
        const o = 4 * (0 * nn + b.nodes[j]);
        tq.set(quat[o], quat[o + 1], quat[o + 2], quat[o + 3]).invert();
        B.ref.push(e.applyQuaternion(tq));
      }
    }
    for (let j = 0; j < nb; j++) {
      const t = X[Math.min(j + 1, nb - 1)].clone().sub(X[Math.max(j - 1, 0)]).normalize();
      const o = 4 * (f * nn + b.nodes[j]);
      tq.set(quat[o], quat[o + 1], quat[o + 2], quat[o + 3]);
      const u = B.ref[j].clone().applyQuaternion(tq);
      u.sub(t.clone().multiplyScalar(u.dot(t))).normalize();
      const w = v2.copy(t).cross(u);
      const s = B.stress[f * nb + j];
      for (let k = 0; k < RING; k++) {
        const th = 2 * Math.PI * k / RING, c = Math.cos(th) * b.radius, sn = Math.sin(th) * b.radius;
        const q = 3 * (j * RING + k);
        P[q] = X[j].x + u.x * c + w.x * sn; P[q + 1] = X[j].y + u.y * c + w.y * sn; P[q + 2] = X[j].z + u.z * c + w.z * sn;
        if (s === s && smax > 0) cmap(s / smax, C, q); else { C[q] = 0.55; C[q + 1] = 0.57; C[q + 2] = 0.62; }
      }
    }
    B.mesh.geometry.attributes.position.needsUpdate = true;
    B.mesh.geometry.attributes.color.needsUpdate = true;
    B.mesh.geometry.computeVertexNormals();
  }

  function updatePart(Q, f) {
    const P = Q.mesh.geometry.attributes.position.array, C = Q.mesh.geometry.attributes.color.array;
    const o = 3 * f * Q.ns;
    for (let i = 0; i < 3 * Q.ns; i++) P[i] = Q.pts[i] + scale * Q.disp[o + i];
    for (let i = 0; i < Q.ns; i++) {
      const s = Q.stress[f * Q.ns + i];
      if (s === s && smax > 0) cmap(s / smax, C, 3 * i); else { C[3 * i] = 0.65; C[3 * i + 1] = 0.65; C[3 * i + 2] = 0.7; }
    }
    Q.mesh.geometry.attributes.position.needsUpdate = true;
    Q.mesh.geometry.attributes.color.needsUpdate = true;
    Q.mesh.geometry.computeVertexNormals();
  }

  function setFrame(f) {
    frame = Math.max(0, Math.min(nf - 1, f | 0));
    for (let i = 0; i < nn; i++) nodePose(i, frame, groups[i]);
    for (const B of beams) updateBeam(B, frame);
    for (const Q of parts) updatePart(Q, frame);
    const showF = el("forces").checked;
    const dir = new THREE.Vector3();
    for (const a of arrows) {
      const k = 3 * frame;
      dir.set(a.vector[k], a.vector[k + 1], a.vector[k + 2]);
      const len = dir.length() * forceScale;
      a.helper.visible = showF && len > 1e-3 * L;
      if (a.helper.visible) {
        a.helper.position.set(a.origin[k], a.origin[k + 1], a.origin[k + 2]);
        a.helper.setDirection(dir.normalize());
        a.helper.setLength(len, Math.min(0.3 * len, 0.04 * L), Math.min(0.15 * len, 0.02 * L));
      }
    }
    const yAxis = new THREE.Vector3(0, 1, 0);
    for (const K of links) {
      const k = 3 * frame;
      v1.set(K.a[k], K.a[k + 1], K.a[k + 2]);
      dir.set(K.b[k] - v1.x, K.b[k + 1] - v1.y, K.b[k + 2] - v1.z);
      const len = dir.length();
      K.mesh.visible = len > 0;
      if (len > 0 && K.turns > 0) {
        K.mesh.position.copy(v1);
        K.mesh.quaternion.setFromUnitVectors(yAxis, dir.divideScalar(len));
        if (len !== K.len) { shapeCoil(K.mesh.geometry, len, K.r, K.turns, K.wire); K.len = len; }
      } else if (len > 0) {
        K.mesh.position.copy(v1).addScaledVector(dir, 0.5);
        K.mesh.quaternion.setFromUnitVectors(yAxis, dir.divideScalar(len));
        K.mesh.scale.set(K.r, len, K.r);
      }
    }
    const showRoad = el("road").checked;
    for (const P of footprints) {
      const k = 3 * frame, len = P.len[frame];
      P.mesh.visible = showRoad && len > 0;
      P.mesh.position.set(P.c[k], P.c[k + 1], P.c[k + 2]);
      P.mesh.rotation.set(0, 0, Math.atan2(P.hd[k + 1], P.hd[k]));
      P.mesh.scale.set(Math.max(len, 1e-9), P.w, 1);
    }
    slider.value = String(frame);
    label.textContent = "t = " + time[frame].toFixed(4) + " s   (frame " + (frame + 1) + " / " + nf + ")";
    render();
  }

  // ---- camera presets -------------------------------------------------------------------------
  const box = new THREE.Box3();
  function fit(dir) {
    box.makeEmpty();
    // the shapes only: arrows and (hidden) triads would inflate the box
    for (const m of [...solid, ...ghosts, ...beams.map((B) => B.mesh), ...parts.map((Q) => Q.mesh)]) box.expandByObject(m);
    if (box.isEmpty()) box.setFromCenterAndSize(new THREE.Vector3(), new THREE.Vector3(L, L, L));
    const c = box.getCenter(new THREE.Vector3()), r = 0.5 * box.getSize(new THREE.Vector3()).length();
    const d = dir.clone().normalize().multiplyScalar(1.05 * r / Math.sin(camera.fov * Math.PI / 360));
    camera.position.copy(c).add(d);
    camera.near = r * 1e-3; camera.far = r * 100; camera.updateProjectionMatrix();
    controls.target.copy(c);
    controls.update();
    sectionCentre = c; sectionRange = r;
    updateSection();
  }
  // the camera's up is +z: a view straight down z is tilted a little to stay defined
  const PRESETS = { iso: [1, -1.2, 0.8], front: [0, -1, 0], side: [1, 0, 0], top: [0, -0.02, 1] };
  for (const k of Object.keys(PRESETS)) {
    const b = el("cam-" + k);
    if (b) b.addEventListener("click", () => fit(new THREE.Vector3(...PRESETS[k])));
  }

  // ---- section plane ----------------------------------------------------------------------------
  let sectionCentre = new THREE.Vector3(), sectionRange = L;
  const plane = new THREE.Plane(new THREE.Vector3(1, 0, 0), 0);
  function updateSection() {
    const on = el("section").checked;
    const ax = el("section-axis").value;
    const n = new THREE.Vector3(ax === "x" ? 1 : 0, ax === "y" ? 1 : 0, ax === "z" ? 1 : 0);
    const off = parseFloat(el("section-offset").value) / 100 * sectionRange;
    // cut away the half on the camera's side: the kept side faces away from the camera
    const side = Math.sign(n.dot(v1.copy(camera.position).sub(sectionCentre))) || 1;
    plane.setFromNormalAndCoplanarPoint(n.clone().multiplyScalar(-side),
      v2.copy(sectionCentre).addScaledVector(n, off));
    renderer.clippingPlanes = on ? [plane] : [];
    render();
  }
  for (const id of ["section", "section-axis", "section-offset"]) el(id).addEventListener("input", updateSection);

  // ---- controls ------------------------------------------------------------------------------
  slider.addEventListener("input", () => { playing = false; el("play").textContent = "play"; setFrame(parseInt(slider.value, 10)); tplay = time[frame]; });
  el("play").addEventListener("click", () => {
    playing = !playing; el("play").textContent = playing ? "pause" : "play";
    if (playing && frame >= nf - 1) { frame = 0; tplay = time[0]; }
    last = null; if (playing) requestAnimationFrame(tick);
  });
  el("scale").addEventListener("input", () => { const s = parseFloat(el("scale").value); if (s === s) { scale = s; setFrame(frame); } });
  el("forces").addEventListener("input", () => setFrame(frame));
  el("markers").addEventListener("input", () => { for (const a of markerTriads) a.visible = el("markers").checked; render(); });
  el("joints").addEventListener("input", () => { for (const a of jointTriads) a.visible = el("joints").checked; render(); });
  el("ghost").addEventListener("input", () => { for (const g of ghosts) g.visible = el("ghost").checked; render(); });
  el("road").addEventListener("input", () => { for (const g of roads) g.visible = el("road").checked; setFrame(frame); });
  const duration = Math.max(time[nf - 1] - time[0], 1e-12);
  function tick(now) {
    if (!playing) return;
    if (last !== null) {
      const speed = parseFloat(el("speed").value);  // simulated seconds per second of play at 1x: the run in 10 s
      tplay += (now - last) / 1000 * speed * duration / 10;
      if (tplay >= time[nf - 1]) { tplay = time[nf - 1]; playing = false; el("play").textContent = "play"; }
      let f = frame;
      while (f < nf - 1 && time[f + 1] <= tplay) f++;
      if (f !== frame) setFrame(f);
    }
    last = now;
    if (playing) requestAnimationFrame(tick);
  }

  // ---- legend and layout ------------------------------------------------------------------------
  if (smax > 0) {
    el("legend").style.display = "block";
    el("legend-max").textContent = (smax / 1e6).toPrecision(3) + " MPa";
  }
  if (D.road.length) {  // the road's friction values, coloured as the lanes
    const box = el("road-legend");
    box.style.display = "block";
    for (const r of D.road) {
      const row = document.createElement("div");
      const sw = document.createElement("span");
      sw.className = "swatch";
      sw.style.background = "rgb(" + r.colour.map((c) => Math.round(255 * c)).join(",") + ")";
      row.appendChild(sw);
      row.appendChild(document.createTextNode("mu " + r.mu + ": " + r.tyres.join(", ")));
      box.appendChild(row);
    }
  } else {
    el("road-toggle").style.display = "none";
  }
  el("info").textContent = D.summary;
  function resize() {
    const w = view.clientWidth, h = view.clientHeight;
    renderer.setSize(w, h);
    camera.aspect = w / Math.max(h, 1);
    camera.updateProjectionMatrix();
    render();
  }
  function render() { renderer.render(scene, camera); }
  window.addEventListener("resize", resize);
  setFrame(0);
  resize();
  fit(new THREE.Vector3(...PRESETS.iso));
  window.drivedynViewer = { ready: true, frames: nf, setFrame: setFrame, frame: () => frame, scene: scene };
})();
