// reconfcheck report viewer: reads the inlined JSON (#reconfcheck-data),
// builds the summary, tables, curves and the 3D replay, and writes its
// state into #status (read by tests/browser.rs). Loads nothing.
(function () {
  'use strict';
  const t0 = performance.now();
  const D = JSON.parse(document.getElementById('reconfcheck-data').textContent);
  const app = document.getElementById('app');
  const statusEl = document.getElementById('status');

  function el(tag, attrs, ...kids) {
    const e = document.createElement(tag);
    for (const [k, v] of Object.entries(attrs || {})) {
      if (k === 'class') e.className = v; else if (k.startsWith('on')) e.addEventListener(k.slice(2), v); else e.setAttribute(k, v);
    }
    for (const k of kids) if (k !== null && k !== undefined) e.append(k instanceof Node ? k : String(k));
    return e;
  }
  function section(title, id) {
    const s = el('section', { id }, el('h2', {}, title));
    app.append(s);
    return s;
  }
  function table(head, rows) {
    return el('table', {}, el('thead', {}, el('tr', {}, ...head.map(h => el('th', {}, h)))),
      el('tbody', {}, ...rows.map(r => el('tr', {}, ...r.map(c => el('td', {}, c))))));
  }
  function fmt(x) {
    if (x === null || x === undefined) return '–';
    if (!isFinite(x)) return String(x);
    return Math.abs(x) >= 1000 || (Math.abs(x) < 1e-3 && x !== 0) ? x.toExponential(3) : (+x.toFixed(4)).toString();
  }
  const SVGNS = 'http://www.w3.org/2000/svg';
  function svgEl(tag, attrs) {
    const e = document.createElementNS(SVGNS, tag);
    for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, v);
    return e;
  }
  // A line chart of series [{name, points: [[x, y]], colour}], axes labelled.
  function chart(title, xlabel, series, opts) {
    const W = 640, H = 260, L = 60, R = 12, T = 24, B = 36;
    const pts = series.flatMap(s => s.points).filter(p => p[1] !== null && isFinite(p[1]));
    const svg = svgEl('svg', { viewBox: `0 0 ${W} ${H}`, class: 'chart', role: 'img' });
    const t = svgEl('text', { x: L, y: 16, class: 'ctitle' }); t.textContent = title; svg.append(t);
    if (!pts.length) return svg;
    let [x0, x1] = [Math.min(...pts.map(p => p[0])), Math.max(...pts.map(p => p[0]))];
    let [y0, y1] = [Math.min(0, ...pts.map(p => p[1])), Math.max(...pts.map(p => p[1]))];
    if (opts && opts.hline !== undefined) y1 = Math.max(y1, opts.hline * 1.05);
    if (x1 === x0) x1 = x0 + 1; if (y1 === y0) y1 = y0 + 1;
    const sx = x => L + (x - x0) / (x1 - x0) * (W - L - R), sy = y => H - B - (y - y0) / (y1 - y0) * (H - T - B);
    svg.append(svgEl('rect', { x: L, y: T, width: W - L - R, height: H - T - B, class: 'frame' }));
    for (let k = 0; k <= 4; k++) {
      const y = y0 + (y1 - y0) * k / 4, x = x0 + (x1 - x0) * k / 4;
      const ty = svgEl('text', { x: L - 4, y: sy(y) + 4, class: 'tick', 'text-anchor': 'end' }); ty.textContent = fmt(y); svg.append(ty);
      const tx = svgEl('text', { x: sx(x), y: H - B + 14, class: 'tick', 'text-anchor': 'middle' }); tx.textContent = fmt(Math.round(x * 100) / 100); svg.append(tx);
    }
    const xl = svgEl('text', { x: (L + W - R) / 2, y: H - 4, class: 'tick', 'text-anchor': 'middle' }); xl.textContent = xlabel; svg.append(xl);
    if (opts && opts.hline !== undefined) svg.append(svgEl('line', { x1: L, x2: W - R, y1: sy(opts.hline), y2: sy(opts.hline), class: 'limit' }));
    series.forEach((s, i) => {
      const d = s.points.filter(p => p[1] !== null && isFinite(p[1])).map(p => `${sx(p[0]).toFixed(1)},${sy(p[1]).toFixed(1)}`).join(' ');
      svg.append(svgEl('polyline', { points: d, fill: 'none', stroke: s.colour, 'stroke-width': 1.5 }));
      if (s.marks) for (const p of s.points) if (p[1] !== null) svg.append(svgEl('circle', { cx: sx(p[0]), cy: sy(p[1]), r: 3, fill: s.colour }));
      const lg = svgEl('text', { x: W - R - 4, y: T + 14 + 14 * i, 'text-anchor': 'end', fill: s.colour, class: 'tick' }); lg.textContent = s.name; svg.append(lg);
    });
    return svg;
  }
  // Down-samples a per-step series to at most n points, keeping each bin's maximum.
  function maxBins(values, n) {
    const out = [];
    const bin = Math.max(1, Math.ceil(values.length / n));
    for (let i = 0; i < values.length; i += bin) {
      let best = null, at = i;
      for (let j = i; j < Math.min(values.length, i + bin); j++) if (values[j] !== null && (best === null || values[j] > best)) { best = values[j]; at = j; }
      out.push([at + 1, best]);
    }
    return out;
  }

  // ---- b-study: its result is the page's summary, so it comes first ------
  if (D.study) {
    const st = D.study;
    const s = section(`Branch-length study: ${st.family}`, 'study');
    s.append(el('p', { class: 'verdict' }, `largest safe b: ${st.b_max}`));
    s.append(el('p', {}, `model ${st.model}, pressure ${fmt(st.pressure_kpa)} kPa, bending ${st.bending}; closed form: b ≤ ${st.closed_b_max}`));
    if (D.note) s.append(el('p', { id: 'note' }, D.note));
    s.append(chart('max utilisation against b', 'b', [
      { name: 'max utilisation', colour: '#d62728', marks: true, points: st.rows.map(r => [r.b, r.max_utilisation]) },
      { name: 'closed form', colour: '#1f77b4', marks: true, points: st.rows.map(r => [r.b, r.closed_utilisation]) }], { hline: 1 }));
    s.append(chart('minimum pressure (kPa) against b', 'b', [
      { name: 'rigid hinge', colour: '#2ca02c', marks: true, points: st.rows.map(r => [r.b, r.min_pressure_rigid_hinge / 1e3]) },
      { name: 'elastic', colour: '#9467bd', marks: true, points: st.rows.map(r => [r.b, r.min_pressure_elastic / 1e3]) }], { hline: st.pressure_kpa }));
    s.append(table(['b', 'steps', 'lattice violations', 'max utilisation', 'critical step', 'critical connector', 'min pressure rigid (kPa)', 'min pressure elastic (kPa)'],
      st.rows.map(r => [r.b, r.steps, r.lattice_violations, (r.max_utilisation_at_least ? '≥ ' : '') + fmt(r.max_utilisation), r.critical_step, r.critical_connector, fmt(r.min_pressure_rigid_hinge / 1e3), fmt(r.min_pressure_elastic / 1e3)])));
    if (st.unplanned && st.unplanned.length) s.append(table(['b', 'not planned because'], st.unplanned.map(u => [u.b, u.reason])));
  }

  // ---- Summary (of the replayed b, on a study page) --------------------------------------------------
  const S = D.summary;
  if (S) {
    const s = section(D.study ? 'The replayed schedule' : 'Summary', 'summary');
    s.append(el('p', { class: S.certified ? 'verdict ok' : 'verdict bad' }, S.certified ? 'CERTIFIED' : 'NOT CERTIFIED'));
    s.append(table(['schedule', 'lattice', 'modules (start → end)', 'steps', 'moves', 'violations', 'warnings'],
      [[S.schedule, S.lattice, `${S.modules} → ${S.final_modules}`, S.steps, S.moves, D.violations.length < 5000 ? D.violations.length : '≥ 5000', D.warnings_total]]));
    s.append(el('ul', { class: 'coverage' },
      ...S.checked.map(c => el('li', { class: 'checked' }, 'checked: ' + c)),
      ...S.not_checked.map(c => el('li', { class: 'notchecked' }, 'NOT checked: ' + c))));
    if (S.stopped_at) s.append(el('p', { class: 'bad' }, `stopped after step ${S.stopped_at}: the state is undefined from there on`));
  }

  // ---- 3D replay --------------------------------------------------------
  let viewer = null;
  if (D.replay && window.THREE) viewer = buildViewer(D.replay);

  function buildViewer(R) {
    const THREE = window.THREE;
    const s = section('Replay', 'replay');
    const P = R.replay;
    const ints = b64 => { const b = atob(b64); const u = new Uint8Array(b.length); for (let i = 0; i < b.length; i++) u[i] = b.charCodeAt(i); return new Int32Array(u.buffer); };
    const initial = ints(P.initial), moves = ints(P.moves), jumps = ints(P.jumps), enters = ints(P.enters), leaves = ints(P.leaves);
    const ms = ints(P.move_start), js = ints(P.jump_start), es = ints(P.enter_start), ls = ints(P.leave_start);
    const N = P.ids.length, steps = P.steps, last = steps + 1;
    const cell = new Int32Array(3 * N), present = new Uint8Array(N), fixed = new Uint8Array(N);
    cell.set(initial);
    for (let i = 0; i < initial.length / 3; i++) present[i] = 1;
    for (const i of P.fixed) fixed[i] = 1;
    const index = new Map(P.ids.map((id, i) => [id, i]));
    const SQ = Math.SQRT1_2;
    const centre = R.lattice === 'fcc'
      ? (x, y, z) => { const p = ((z % 2) + 2) % 2 * 0.5; return [x + p, y + p, z * SQ]; }
      : R.lattice === 'square' ? (x, y) => [x, y, 0] : (x, y, z) => [x, y, z];

    // Controls.
    const slider = el('input', { type: 'range', min: 0, max: last, value: 0, id: 'step', 'aria-label': 'step' });
    const label = el('span', { id: 'steplabel' });
    const play = el('button', { id: 'play' }, '▶ play');
    const prev = el('button', { id: 'prev' }, '◀');
    const next = el('button', { id: 'next' }, '▶');
    const speed = el('input', { type: 'number', min: 1, max: 200, value: steps > 500 ? 30 : 4, id: 'speed', title: 'steps per second' });
    const loadBox = el('input', { type: 'checkbox', id: 'loadmap', checked: '' });
    const loadSteps = new Map(D.load_maps.map(m => [m.step, m]));
    // A load map's connectors, unpacked on first use (see LoadMapData):
    // [x, y, z, nx, ny, nz, utilisation] each.
    function loadLinks(m) {
      if (m.unpacked) return m.unpacked;
      const w = ints(m.links), out = new Array(m.connectors);
      for (let j = 0; j < m.connectors; j++) {
        const a = w[3 * j], b = w[3 * j + 1], c = w[3 * j + 2];
        out[j] = [((a << 16) >> 16) / 32, (a >> 16) / 32, ((b << 16) >> 16) / 32,
          ((b << 8) >> 24) / 127, (b >> 24) / 127, ((c << 24) >> 24) / 127, ((c >>> 8) & 0xffffff) / 1048576];
      }
      return (m.unpacked = out);
    }
    const jumpSel = el('select', { id: 'jump' }, el('option', { value: '' }, 'go to…'),
      ...[...new Set(D.violations.map(v => v.step))].slice(0, 500).map(k => el('option', { value: k }, `violation at step ${k}`)),
      ...D.load_maps.filter(m => m.why !== 'spread').map(m => el('option', { value: m.step }, `load map at step ${m.step} (${m.why})`)));
    const legend = el('div', { class: 'legend' },
      ...[['fixed', '#8a8f98'], ['static', '#4a90d9'], ['moving', '#f5a623'], ['entering', '#2ecc71'], ['violation bodies', '#e0002a'], ['blocking cells, witness', '#ff00ff']]
        .map(([n, c]) => el('span', {}, el('i', { style: `background:${c}` }), n)));
    const canvasBox = el('div', { class: 'canvas' });
    const info = el('div', { class: 'stepinfo', id: 'stepinfo' });
    s.append(el('div', { class: 'controls' }, prev, play, next, slider, label,
      el('label', {}, speed, ' steps/s'), el('label', {}, loadBox, ' load map'), jumpSel), legend,
      el('div', { class: 'viewer' }, canvasBox, info),
      el('p', { class: 'hint' }, 'Drag to orbit, wheel to zoom, shift-drag to pan. Step k shows the configuration after step k: its movers orange, its new modules green, its findings marked. Keys: ← → step, space play.'));

    const width = Math.max(320, Math.min(1100, app.clientWidth || 960) - 300), height = 560;
    const renderer = new THREE.WebGLRenderer({ antialias: N < 5000, preserveDrawingBuffer: true });
    renderer.setPixelRatio(Math.min(2, window.devicePixelRatio || 1));
    renderer.setSize(width, height);
    canvasBox.append(renderer.domElement);
    const scene = new THREE.Scene();
    scene.background = new THREE.Color(0xf4f6f8);
    const camera = new THREE.PerspectiveCamera(40, width / height, 0.05, 5000);
    camera.up.set(0, 0, 1);
    scene.add(new THREE.HemisphereLight(0xffffff, 0x445566, 1.0));
    const sun = new THREE.DirectionalLight(0xffffff, 0.9);
    scene.add(sun);

    let geo;
    if (R.catom) {
      geo = new THREE.BufferGeometry();
      geo.setAttribute('position', new THREE.Float32BufferAttribute(R.body[0], 3));
      geo.setAttribute('normal', new THREE.Float32BufferAttribute(R.body[1], 3));
      geo.setIndex(R.body[2]);
    } else {
      geo = new THREE.BoxGeometry(0.92, 0.92, R.lattice === 'square' ? 0.3 : 0.92);
    }
    const material = new THREE.MeshLambertMaterial({ transparent: true, opacity: 1 });
    const mesh = new THREE.InstancedMesh(geo, material, Math.max(1, N));
    mesh.instanceMatrix.setUsage(THREE.DynamicDrawUsage);
    mesh.frustumCulled = false;
    scene.add(mesh);
    const COL = { fixed: new THREE.Color(0x8a8f98), static: new THREE.Color(0x4a90d9), moving: new THREE.Color(0xf5a623), entering: new THREE.Color(0x2ecc71), bad: new THREE.Color(0xe0002a) };
    const m4 = new THREE.Matrix4(), hidden = new THREE.Matrix4().makeScale(0, 0, 0);
    for (let i = 0; i < N; i++) mesh.setColorAt(i, fixed[i] ? COL.fixed : COL.static);

    // Ground and bounds.
    const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    const grow = p => { for (let a = 0; a < 3; a++) { lo[a] = Math.min(lo[a], p[a]); hi[a] = Math.max(hi[a], p[a]); } };
    for (let i = 0; i < initial.length; i += 3) grow(centre(initial[i], initial[i + 1], initial[i + 2]));
    for (let i = 0; i < enters.length; i += 4) grow(centre(enters[i + 1], enters[i + 2], enters[i + 3]));
    // Every cell a module reaches, so that a run which grows by moves (a
    // branch from one entry cell) is framed whole: the replay played to
    // the end and back (apply() is exact), growing by each step's movers.
    for (let i = 0; i < jumps.length; i += 7) grow(centre(jumps[i + 4], jumps[i + 5], jumps[i + 6]));
    for (let k = 1; k <= steps; k++) {
      apply(k, 1);
      for (let r = ms[k - 1]; r < ms[k]; r++) { const m = moves[2 * r]; grow(centre(cell[3 * m], cell[3 * m + 1], cell[3 * m + 2])); }
    }
    for (let k = steps; k >= 1; k--) apply(k, -1);
    if (!isFinite(lo[0])) { lo.fill(-1); hi.fill(1); }
    const mid = lo.map((v, a) => (v + hi[a]) / 2), span = Math.max(2, ...hi.map((v, a) => v - lo[a]));
    if (R.ground !== null && R.ground !== undefined) {
      const g = new THREE.Mesh(new THREE.PlaneGeometry(span * 1.6, span * 1.6), new THREE.MeshBasicMaterial({ color: 0xe4dfd3 }));
      g.position.set(mid[0], mid[1], R.ground);
      scene.add(g);
    }

    // Orbit (drag), zoom (wheel), pan (shift-drag).
    const target = new THREE.Vector3(...mid);
    let radius = span * 1.9, theta = -Math.PI / 3.2, phi = Math.PI / 3;
    function placeCamera() {
      camera.position.set(target.x + radius * Math.sin(phi) * Math.cos(theta), target.y + radius * Math.sin(phi) * Math.sin(theta), target.z + radius * Math.cos(phi));
      camera.lookAt(target);
      sun.position.copy(camera.position).add(new THREE.Vector3(span, -span, 2 * span));
    }
    let drag = null;
    renderer.domElement.addEventListener('pointerdown', e => { drag = { x: e.clientX, y: e.clientY, pan: e.shiftKey }; renderer.domElement.setPointerCapture(e.pointerId); });
    renderer.domElement.addEventListener('pointerup', () => { drag = null; });
    renderer.domElement.addEventListener('pointermove', e => {
      if (!drag) return;
      const dx = e.clientX - drag.x, dy = e.clientY - drag.y; drag.x = e.clientX; drag.y = e.clientY;
      if (drag.pan) {
        const right = new THREE.Vector3().subVectors(camera.position, target).cross(camera.up).normalize();
        target.addScaledVector(right, dx * radius / height).addScaledVector(camera.up, dy * radius / height);
      } else { theta -= dx * 0.008; phi = Math.min(3.1, Math.max(0.05, phi - dy * 0.008)); }
      placeCamera(); draw();
    });
    renderer.domElement.addEventListener('wheel', e => { e.preventDefault(); radius *= Math.exp(e.deltaY * 0.001); placeCamera(); draw(); }, { passive: false });

    // Markers of the findings and the load map, rebuilt per step.
    const markers = new THREE.Group();
    scene.add(markers);
    // The load map's plates: one instanced mesh for every step, sized for
    // the largest map, so that playing allocates nothing per step.
    const plates = new THREE.InstancedMesh(new THREE.BoxGeometry(0.3, 0.3, 0.05), new THREE.MeshBasicMaterial(),
      Math.max(1, D.load_maps.reduce((n, m) => Math.max(n, m.connectors), 0)));
    plates.count = 0;
    plates.frustumCulled = false;
    plates.instanceMatrix.setUsage(THREE.DynamicDrawUsage);
    scene.add(plates);
    const plateQ = new THREE.Quaternion(), plateZ = new THREE.Vector3(0, 0, 1), plateN = new THREE.Vector3(), plateP = new THREE.Vector3(), plateOne = new THREE.Vector3(1, 1, 1), plateM = new THREE.Matrix4();
    // Transparent (at full opacity) so that they are drawn in the same pass
    // as the bodies, after them (renderOrder), and without a depth test:
    // always in view.
    const markMat = new THREE.MeshBasicMaterial({ color: 0xff00ff, depthTest: false, transparent: true });
    const cellMat = new THREE.LineBasicMaterial({ color: 0xff00ff, depthTest: false, transparent: true });
    const cellGeo = new THREE.EdgesGeometry(new THREE.BoxGeometry(0.8, 0.8, 0.8));
    const witnessGeo = new THREE.SphereGeometry(0.09, 16, 12);
    const byStep = new Map();
    for (const v of D.violations.concat(D.warnings)) { if (!byStep.has(v.step)) byStep.set(v.step, []); byStep.get(v.step).push(v); }
    function utilColour(u) {
      if (u > 1 + 1e-9) return new THREE.Color(150 / 255, 0, 200 / 255);
      u = Math.min(1, Math.max(0, u));
      return u < 0.5 ? new THREE.Color(2 * u, 180 / 255, 0) : new THREE.Color(1, 180 / 255 * (2 - 2 * u), 0);
    }

    // Replay state: `shown` steps applied.
    let shown = 0;
    function apply(k, sign) { // applies (sign 1) or undoes (sign -1) step k (1-based)
      const i = k - 1;
      if (sign > 0) {
        for (let r = ms[i]; r < ms[i + 1]; r++) { const m = moves[2 * r], p = moves[2 * r + 1]; cell[3 * m] += (p & 1023) - 512; cell[3 * m + 1] += ((p >> 10) & 1023) - 512; cell[3 * m + 2] += ((p >> 20) & 1023) - 512; }
        for (let r = js[i]; r < js[i + 1]; r++) { const m = jumps[7 * r]; cell.set(jumps.subarray(7 * r + 4, 7 * r + 7), 3 * m); }
        for (let r = es[i]; r < es[i + 1]; r++) { const m = enters[4 * r]; cell.set(enters.subarray(4 * r + 1, 4 * r + 4), 3 * m); present[m] = 1; }
        for (let r = ls[i]; r < ls[i + 1]; r++) present[leaves[r]] = 0;
      } else {
        for (let r = ls[i]; r < ls[i + 1]; r++) present[leaves[r]] = 1;
        for (let r = es[i]; r < es[i + 1]; r++) present[enters[4 * r]] = 0;
        for (let r = js[i]; r < js[i + 1]; r++) { const m = jumps[7 * r]; cell.set(jumps.subarray(7 * r + 1, 7 * r + 4), 3 * m); }
        for (let r = ms[i]; r < ms[i + 1]; r++) { const m = moves[2 * r], p = moves[2 * r + 1]; cell[3 * m] -= (p & 1023) - 512; cell[3 * m + 1] -= ((p >> 10) & 1023) - 512; cell[3 * m + 2] -= ((p >> 20) & 1023) - 512; }
      }
    }
    let tinted = [];
    function setInstance(m) {
      if (present[m]) { const c = centre(cell[3 * m], cell[3 * m + 1], cell[3 * m + 2]); m4.makeTranslation(c[0], c[1], c[2]); mesh.setMatrixAt(m, m4); } else mesh.setMatrixAt(m, hidden);
    }
    for (let m = 0; m < N; m++) setInstance(m);
    const state = { step: 0, highlighted: 0, markers: 0, loadmap: 0 };
    function goTo(k) {
      k = Math.max(0, Math.min(last, k | 0));
      const target = Math.min(k, steps);
      const touched = new Set();
      const touch = (i) => {
        for (let r = ms[i]; r < ms[i + 1]; r++) touched.add(moves[2 * r]);
        for (let r = js[i]; r < js[i + 1]; r++) touched.add(jumps[7 * r]);
        for (let r = es[i]; r < es[i + 1]; r++) touched.add(enters[4 * r]);
        for (let r = ls[i]; r < ls[i + 1]; r++) touched.add(leaves[r]);
      };
      while (shown < target) { shown++; apply(shown, 1); touch(shown - 1); }
      while (shown > target) { apply(shown, -1); touch(shown - 1); shown--; }
      for (const m of touched) setInstance(m);
      // Colours: undo the last tint, then tint this step's roles.
      for (const m of tinted) mesh.setColorAt(m, fixed[m] ? COL.fixed : COL.static);
      tinted = [];
      const tint = (m, c) => { mesh.setColorAt(m, c); tinted.push(m); };
      if (k >= 1 && k <= steps) {
        const i = k - 1;
        for (let r = ms[i]; r < ms[i + 1]; r++) tint(moves[2 * r], COL.moving);
        for (let r = js[i]; r < js[i + 1]; r++) tint(jumps[7 * r], COL.moving);
        for (let r = es[i]; r < es[i + 1]; r++) tint(enters[4 * r], COL.entering);
      }
      for (const c of markers.children) if (c.geometry !== cellGeo && c.geometry !== witnessGeo) c.geometry.dispose();
      markers.clear();
      const found = byStep.get(k) || [];
      let highlighted = 0;
      for (const v of found) {
        const bad = v.severity === 'error';
        if (bad) highlighted++;
        for (const id of v.modules) { const m = index.get(id); if (m !== undefined && bad) tint(m, COL.bad); }
        for (const c of v.cells) { const l = new THREE.LineSegments(cellGeo, cellMat); l.position.set(...c); l.renderOrder = 2; markers.add(l); }
        for (const w of v.witness) { const b = new THREE.Mesh(witnessGeo, markMat); b.position.set(...w); b.renderOrder = 3; markers.add(b); }
        if (v.witness.length === 2) { const l = new THREE.Line(new THREE.BufferGeometry().setFromPoints(v.witness.map(w => new THREE.Vector3(...w))), cellMat); l.renderOrder = 3; markers.add(l); }
      }
      // Load map: connectors as small plates coloured by utilisation.
      const lm = loadSteps.get(k);
      const showLoad = lm && loadBox.checked;
      material.opacity = showLoad ? 0.18 : 1;
      material.depthWrite = !showLoad;
      plates.count = 0;
      if (showLoad) {
        const links = loadLinks(lm);
        links.forEach((l, j) => {
          plateQ.setFromUnitVectors(plateZ, plateN.set(l[3], l[4], l[5]).normalize());
          plates.setMatrixAt(j, plateM.compose(plateP.set(l[0], l[1], l[2]), plateQ, plateOne));
          plates.setColorAt(j, utilColour(l[6]));
        });
        plates.count = links.length;
        plates.instanceMatrix.needsUpdate = true;
        if (plates.instanceColor) plates.instanceColor.needsUpdate = true;
      }
      mesh.instanceMatrix.needsUpdate = true;
      if (mesh.instanceColor) mesh.instanceColor.needsUpdate = true;
      slider.value = k;
      label.textContent = k === 0 ? `initial (0 / ${steps})` : k === last ? `final (${steps} / ${steps})` : `step ${k} / ${steps}`;
      info.replaceChildren(...[el('h3', {}, label.textContent),
        showLoad ? el('p', {}, `load map: max utilisation ${fmt(lm.max_utilisation)} over ${lm.connectors} connectors`)
          : D.load_maps.length && !lm ? el('p', { class: 'hint' }, `no load map at this step: ${D.load_maps.length} of ${D.load_maps_of} steps have one (the page's size budget; steps outside a --steps span have none)`) : null,
        found.length ? el('ul', {}, ...found.slice(0, 50).map(v => el('li', { class: v.severity }, `${v.severity} ${v.kind}: ${v.message}`))) : el('p', {}, 'no findings at this step'),
        found.length > 50 ? el('p', {}, `… ${found.length - 50} more`) : null].filter(x => x));
      state.step = k; state.highlighted = highlighted; state.markers = markers.children.length; state.loadmap = showLoad ? lm.connectors : 0;
      draw();
      report();
    }
    function draw() { renderer.render(scene, camera); }
    slider.addEventListener('input', () => goTo(+slider.value));
    prev.addEventListener('click', () => goTo(state.step - 1));
    next.addEventListener('click', () => goTo(state.step + 1));
    loadBox.addEventListener('change', () => goTo(state.step));
    jumpSel.addEventListener('change', () => { if (jumpSel.value !== '') goTo(+jumpSel.value); });
    let timer = null;
    play.addEventListener('click', () => {
      if (timer) { clearInterval(timer); timer = null; play.textContent = '▶ play'; return; }
      if (state.step >= last) goTo(0);
      play.textContent = '❚❚ pause';
      timer = setInterval(() => { if (state.step >= last) { clearInterval(timer); timer = null; play.textContent = '▶ play'; } else goTo(state.step + 1); }, 1000 / Math.max(1, +speed.value || 4));
    });
    document.addEventListener('keydown', e => {
      if (e.target.tagName === 'INPUT' && e.target.type === 'number') return;
      if (e.key === 'ArrowRight') goTo(state.step + 1); else if (e.key === 'ArrowLeft') goTo(state.step - 1); else if (e.key === ' ') { e.preventDefault(); play.click(); }
    });
    placeCamera();
    // A digest of the shown scene, for the browser test: changes whenever a module moves, enters or leaves.
    function digest() {
      let h = 0, n = 0;
      for (let m = 0; m < N; m++) if (present[m]) { n++; h = (h * 31 + cell[3 * m] * 7 + cell[3 * m + 1] * 13 + cell[3 * m + 2] * 17 + m) | 0; }
      return `${n}:${(h >>> 0).toString(16)}`;
    }
    return { goTo, state, digest, last, renderer };
  }

  // ---- Findings ------------------------------------------------------------
  if (S) {
    const s = section('Findings', 'findings');
    s.append(el('h3', {}, 'Violations by kind'));
    s.append(D.violation_counts.length ? table(['kind', 'count'], D.violation_counts) : el('p', {}, 'none'));
    s.append(el('h3', {}, 'Warnings by kind'));
    s.append(D.warning_counts.length ? table(['kind', 'severity', 'count'], D.warning_counts) : el('p', {}, 'none'));
    if (D.violations.length) {
      s.append(el('h3', {}, 'Violations'));
      const rows = D.violations.slice(0, 200).map(v => [
        viewer ? el('a', { href: '#step=' + v.step, onclick: e => { e.preventDefault(); viewer.goTo(v.step); document.getElementById('replay').scrollIntoView(); } }, v.step) : v.step,
        v.kind, v.modules.join(', '), v.message]);
      s.append(table(['step', 'kind', 'modules', 'message'], rows));
      if (D.violations.length > 200) s.append(el('p', {}, `… and ${D.violations.length - 200} more (see the JSON report)`));
    }
  }

  // ---- Per-step maxima -----------------------------------------------------
  if (D.metrics.length) {
    const s = section('Per-step maxima', 'metrics');
    const lowest = k => k.startsWith('load_factor');
    const rows = D.metrics.map(([k, vals]) => {
      let best = null, at = 0;
      vals.forEach((v, i) => { if (v !== null && (best === null || (lowest(k) ? v < best : v > best))) { best = v; at = i + 1; } });
      return [k, lowest(k) ? 'lowest' : 'highest', fmt(best), at];
    });
    s.append(table(['metric', 'worst is', 'value', 'at step'], rows));
    const colours = ['#d62728', '#1f77b4', '#2ca02c', '#9467bd', '#ff7f0e'];
    D.metrics.forEach(([k, vals], i) => s.append(chart(k + ' per step', 'step', [{ name: k, colour: colours[i % colours.length], points: maxBins(vals, 1500) }], k.includes('utilisation') ? { hline: 1 } : undefined)));
  }

  app.append(el('footer', {}, `${D.generator}; three.js r160 (MIT) inlined; this page loads nothing from the network.`));

  // ---- Status for people and for tests/browser.rs --------------------------
  const hash = new URLSearchParams(location.hash.slice(1));
  function report() {
    const parts = ['ready'];
    if (viewer) parts.push(`step=${viewer.state.step}`, `last=${viewer.last}`, `scene=${viewer.digest()}`, `highlighted=${viewer.state.highlighted}`, `markers=${viewer.state.markers}`, `loadmap=${viewer.state.loadmap}`);
    parts.push(`errors=${window.__errors.length}`, `ready_ms=${readyMs === null ? (performance.now() - t0).toFixed(0) : readyMs}`);
    if (playMs !== null) parts.push(`play_ms_per_step=${playMs.toFixed(1)}`);
    if (window.__errors.length) parts.push('first_error=' + JSON.stringify(window.__errors[0]));
    statusEl.textContent = parts.join(' ');
  }
  let readyMs = null, playMs = null;
  if (D.replay && !window.THREE) console.error('three.js did not load');
  if (viewer) viewer.goTo(hash.has('step') ? +hash.get('step') : (D.summary && D.summary.window ? D.summary.window.first : 0));
  readyMs = (performance.now()).toFixed(0);
  report();
  // `#play=N`: step forward N times as the play button does, each step
  // drawn and the GPU waited for, and report the mean time per step (how
  // smoothly the page plays; read by the measurements in docs/report.md).
  if (viewer && hash.has('play')) {
    const n = Math.max(1, Math.min(+hash.get('play') || 1, viewer.last - viewer.state.step));
    const t = performance.now();
    for (let i = 0; i < n; i++) viewer.goTo(viewer.state.step + 1);
    viewer.renderer.getContext().finish();
    playMs = (performance.now() - t) / n;
    report();
  }
  window.addEventListener('hashchange', () => { const h = new URLSearchParams(location.hash.slice(1)); if (viewer && h.has('step')) viewer.goTo(+h.get('step')); });
})();
