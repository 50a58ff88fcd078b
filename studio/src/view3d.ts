// 3D view: the field, each camera as a frustum at its pose, the ball track (BALL.csv) coloured by
// time, flights (FLIGHTS.json: origin, apex, landing), the rays from the cameras to the ball at
// the time of the slider, and the ball's height over time (uPlot). A benchmark button renders a
// 10,000-point track while turning the view and reports frames per second.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import uPlot from 'uplot';
import 'uplot/dist/uPlot.min.css';
import * as api from './api';
import { el, fileSelect, optionsSelect, labelled, status, rampColour } from './ui';

interface BallData {
  samples: number[][]; // frame, time_s, x, y, z, n_cams, err_px
}

interface Flight {
  t_start_s: number;
  t_end_s: number;
  origin: number[];
  landing: number[];
  apex: number[];
}

export async function view3dPage(root: HTMLElement): Promise<void> {
  const [list, info] = await Promise.all([api.files(), api.info()]);
  const ball = fileSelect('v3-ball', list, ['csv']);
  const flights = fileSelect('v3-flights', list, ['json'], true);
  const field = optionsSelect('v3-field', info.fields, 'robocup-msl');
  const cameraBoxes = el('div', { id: 'v3-camera-files', class: 'checks' });
  for (const f of list.filter((f) => f.kind === 'camera')) {
    cameraBoxes.append(el('label', {}, el('input', { type: 'checkbox', value: f.path, checked: '' }), f.path));
  }
  const guess = list.find((f) => f.kind === 'csv' && /ball/i.test(f.path));
  if (guess) ball.value = guess.path;
  const guessFlights = list.find((f) => f.kind === 'json' && /flight/i.test(f.path) && !/truth|synth/i.test(f.path));
  if (guessFlights) flights.value = guessFlights.path;
  const load = el('button', { id: 'v3-load', text: 'Show' });
  const bench = el('button', { id: 'v3-bench', text: 'Benchmark: 10,000-point track' });
  const time = el('input', { id: 'v3-time', type: 'range', min: '0', max: '0', value: '0', step: '1' });
  const timeLabel = el('span', { id: 'v3-time-label' });
  const msg = el('div', { id: 'v3-status', class: 'status' });
  const cameraList = el('ul', { id: 'v3-cameras' });
  const flightList = el('ul', { id: 'v3-flight-list' });
  const canvas = el('canvas', { id: 'v3-canvas' });
  const chart = el('div', { id: 'v3-chart' });
  root.replaceChildren(
    el('section', { class: 'controls' }, labelled('Ball track', ball), labelled('Flights', flights), labelled('Field', field), load, bench),
    el('div', { class: 'workspace' },
      el('div', { class: 'main-view' }, canvas, el('div', {}, labelled('Time', el('span', {}, time, timeLabel))), chart, msg),
      el('div', { class: 'side' }, el('h3', { text: 'Camera files' }), cameraBoxes, el('h3', { text: 'Cameras shown' }), cameraList,
        el('h3', { text: 'Flights' }), flightList,
        el('p', { class: 'hint', text: 'Drag to turn, wheel to zoom, right-drag to pan. Track colour: time (blue → red).' }))),
  );

  const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
  const width = canvas.parentElement!.clientWidth || 900;
  const height = Math.round(width * 0.55);
  renderer.setSize(width, height);
  renderer.setPixelRatio(1);
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0x1d2630);
  const view = new THREE.PerspectiveCamera(45, width / height, 0.1, 1000);
  view.up.set(0, 0, 1);
  view.position.set(-14, -18, 12);
  const controls = new OrbitControls(view, canvas);
  const render = () => renderer.render(scene, view);
  controls.addEventListener('change', render);
  scene.add(new THREE.AmbientLight(0xffffff, 1.0));

  let dynamic = new THREE.Group();
  let ballMarker: THREE.Mesh | null = null;
  let rays: THREE.LineSegments | null = null;
  let samples: number[][] = [];
  let cams: api.CameraJson[] = [];
  let plot: uPlot | null = null;

  function fieldGroup(f: api.FieldModel): THREE.Group {
    const g = new THREE.Group();
    const L = f.length_m + 2 * f.surround_m;
    const W = f.width_m + 2 * f.surround_m;
    const ground = new THREE.Mesh(new THREE.PlaneGeometry(L, W), new THREE.MeshBasicMaterial({ color: f.surface === 'court' ? 0x9a6b45 : 0x2e6b31 }));
    g.add(ground);
    const pts: number[] = [];
    for (const s of f.segments) pts.push(s.a[0], s.a[1], 0.01, s.b[0], s.b[1], 0.01);
    for (const a of f.arcs) {
      const n = Math.max(8, Math.ceil((a.end_rad - a.start_rad) * a.radius_m * 5));
      for (let i = 0; i < n; ++i) {
        const t0 = a.start_rad + ((a.end_rad - a.start_rad) * i) / n;
        const t1 = a.start_rad + ((a.end_rad - a.start_rad) * (i + 1)) / n;
        pts.push(a.centre[0] + a.radius_m * Math.cos(t0), a.centre[1] + a.radius_m * Math.sin(t0), 0.01,
          a.centre[0] + a.radius_m * Math.cos(t1), a.centre[1] + a.radius_m * Math.sin(t1), 0.01);
      }
    }
    const geo = new THREE.BufferGeometry();
    geo.setAttribute('position', new THREE.Float32BufferAttribute(pts, 3));
    g.add(new THREE.LineSegments(geo, new THREE.LineBasicMaterial({ color: 0xffffff })));
    return g;
  }

  // World point of a pixel at depth `d` metres in front of the camera.
  function pixelAt(c: api.CameraJson, u: number, v: number, d: number): THREE.Vector3 {
    const r = c.cam_from_world_rotation!;
    const xc = [((u - c.cx) / c.fx) * d, ((v - c.cy) / c.fy) * d, d];
    const p = c.position_m!;
    return new THREE.Vector3(
      p[0] + r[0] * xc[0] + r[3] * xc[1] + r[6] * xc[2],
      p[1] + r[1] * xc[0] + r[4] * xc[1] + r[7] * xc[2],
      p[2] + r[2] * xc[0] + r[5] * xc[1] + r[8] * xc[2]);
  }

  function frustum(c: api.CameraJson, colour: THREE.Color): THREE.LineSegments {
    const o = new THREE.Vector3(...(c.position_m as [number, number, number]));
    const k = [[0, 0], [c.width, 0], [c.width, c.height], [0, c.height]].map(([u, v]) => pixelAt(c, u - 0.5, v - 0.5, 1.5));
    const pts: THREE.Vector3[] = [];
    for (let i = 0; i < 4; ++i) pts.push(o, k[i], k[i], k[(i + 1) % 4]);
    return new THREE.LineSegments(new THREE.BufferGeometry().setFromPoints(pts), new THREE.LineBasicMaterial({ color: colour }));
  }

  function trackPoints(s: number[][]): THREE.Points {
    const pos = new Float32Array(3 * s.length);
    const col = new Float32Array(3 * s.length);
    const t0 = s.length ? s[0][1] : 0;
    const span = s.length > 1 ? s[s.length - 1][1] - t0 : 1;
    s.forEach((row, i) => {
      pos.set([row[2], row[3], row[4]], 3 * i);
      col.set(rampColour((row[1] - t0) / span), 3 * i);
    });
    const geo = new THREE.BufferGeometry();
    geo.setAttribute('position', new THREE.BufferAttribute(pos, 3));
    geo.setAttribute('color', new THREE.BufferAttribute(col, 3));
    return new THREE.Points(geo, new THREE.PointsMaterial({ size: 0.2, vertexColors: true }));
  }

  function setTime(i: number) {
    if (!samples.length) return;
    const s = samples[Math.min(i, samples.length - 1)];
    timeLabel.textContent = ` t = ${s[1].toFixed(3)} s (frame ${s[0]}), ball at (${s[2].toFixed(2)}, ${s[3].toFixed(2)}, ${s[4].toFixed(2)}) m, ${s[5]} cameras`;
    ballMarker?.position.set(s[2], s[3], s[4]);
    if (rays) {
      const pts: THREE.Vector3[] = [];
      for (const c of cams) pts.push(new THREE.Vector3(...(c.position_m as [number, number, number])), new THREE.Vector3(s[2], s[3], s[4]));
      rays.geometry.dispose();
      rays.geometry = new THREE.BufferGeometry().setFromPoints(pts);
    }
    plot?.setCursor({ left: plot.valToPos(s[1], 'x'), top: 10 });
    render();
  }

  async function show() {
    try {
      status(msg, 'loading…');
      const checked = [...cameraBoxes.querySelectorAll<HTMLInputElement>('input:checked')].map((b) => b.value);
      const [f, b, fl, cs] = await Promise.all([
        api.get<api.FieldModel>('/api/field', { name: field.value }),
        api.get<BallData>('/api/ball', { path: ball.value }),
        flights.value ? api.get<Flight[]>('/api/json', { path: flights.value }) : Promise.resolve([] as Flight[]),
        Promise.all(checked.map((p) => api.get<api.CameraJson>('/api/camera', { path: p }).then((c) => ({ ...c, path: p })))),
      ]);
      scene.remove(dynamic);
      dynamic = new THREE.Group();
      dynamic.add(fieldGroup(f));
      cams = cs.filter((c) => c.has_pose);
      cameraList.replaceChildren();
      cams.forEach((c, i) => {
        const colour = new THREE.Color().setHSL(i / Math.max(1, cams.length), 0.8, 0.6);
        dynamic.add(frustum(c, colour));
        const p = c.position_m!.map((v) => v.toFixed(2)).join(', ');
        cameraList.append(el('li', { style: `color:#${colour.getHexString()}`, text: `${c.name || (c as { path?: string }).path} at (${p}) m, ${c.width}x${c.height}` }));
      });
      samples = b.samples;
      dynamic.add(trackPoints(samples));
      ballMarker = new THREE.Mesh(new THREE.SphereGeometry(0.15, 16, 12), new THREE.MeshBasicMaterial({ color: 0xff8800 }));
      dynamic.add(ballMarker);
      rays = new THREE.LineSegments(new THREE.BufferGeometry(), new THREE.LineBasicMaterial({ color: 0xffff88, transparent: true, opacity: 0.6 }));
      dynamic.add(rays);
      flightList.replaceChildren();
      const fa = Array.isArray(fl) ? fl : [];
      const marker = (p: number[], colour: number) => {
        const m = new THREE.Mesh(new THREE.SphereGeometry(0.1, 12, 8), new THREE.MeshBasicMaterial({ color: colour }));
        m.position.set(p[0], p[1], p[2]);
        dynamic.add(m);
      };
      fa.forEach((fl, i) => {
        marker(fl.origin, 0x33ff66);
        marker(fl.landing, 0xff3333);
        marker(fl.apex, 0xffffff);
        flightList.append(el('li', { text: `${i + 1}: ${fl.t_start_s.toFixed(2)}–${fl.t_end_s.toFixed(2)} s, apex ${fl.apex[2].toFixed(2)} m, lands at (${fl.landing[0].toFixed(2)}, ${fl.landing[1].toFixed(2)}) m` }));
      });
      scene.add(dynamic);
      time.max = String(Math.max(0, samples.length - 1));
      time.value = '0';
      drawChart(fa);
      setTime(0);
      status(msg, `${samples.length} ball positions, ${cams.length} cameras, ${fa.length} flights`);
      canvas.dataset.ready = '1';
    } catch (e) {
      status(msg, (e as Error).message, true);
    }
  }

  function drawChart(fl: Flight[]) {
    plot?.destroy();
    const t = samples.map((s) => s[1]);
    const z = samples.map((s) => s[4]);
    plot = new uPlot({
      width: canvas.clientWidth || width, height: 170,
      series: [{ label: 't (s)' }, { label: 'ball height z (m)', stroke: '#f80', width: 1.5, points: { show: false } }],
      axes: [{ label: 'time (s)', stroke: '#ccc' }, { label: 'z (m)', stroke: '#ccc' }],
      scales: { x: { time: false } },
      hooks: {
        draw: [(u: uPlot) => {
          const ctx = u.ctx;
          ctx.fillStyle = 'rgba(80, 160, 255, 0.15)';
          for (const f of fl) {
            const x0 = u.valToPos(f.t_start_s, 'x', true);
            const x1 = u.valToPos(f.t_end_s, 'x', true);
            ctx.fillRect(x0, u.bbox.top, x1 - x0, u.bbox.height);
          }
        }],
      },
    }, [t, z], chart);
  }

  time.addEventListener('input', () => setTime(Number(time.value)));
  load.onclick = () => void show();
  bench.onclick = async () => {
    // A synthetic 10,000-point track, rendered every animation frame for 3 s while turning.
    const n = 10000;
    const s: number[][] = [];
    for (let i = 0; i < n; ++i) {
      const t = i / 100;
      s.push([i, t, 8 * Math.cos(t / 7), 5 * Math.sin(t / 5), Math.abs(3 * Math.sin(t)), 2, 0.5]);
    }
    const pts = trackPoints(s);
    scene.add(pts);
    let frames = 0;
    const start = performance.now();
    await new Promise<void>((done) => {
      const step = () => {
        controls.object.position.applyAxisAngle(new THREE.Vector3(0, 0, 1), 0.01);
        controls.update();
        render();
        ++frames;
        if (performance.now() - start < 3000) requestAnimationFrame(step);
        else done();
      };
      requestAnimationFrame(step);
    });
    const fps = (frames * 1000) / (performance.now() - start);
    scene.remove(pts);
    render();
    status(msg, `benchmark: ${n} points, ${fps.toFixed(1)} frames/s over 3 s`);
    msg.dataset.fps = fps.toFixed(1);
  };
  render();
  if (ball.value) await show();
}
